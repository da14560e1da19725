//! [`MultibodyEngine`]: the run loop around the rapier world, the spline hook and the step
//! controller; samples, impact events and the energy audit.
//!
//! One module per job: `state` (the world and every body's state), `forces` (the hook at
//! `t`, the loads and kicks, the step handed to rapier), `events` (impact events), `energy`
//! (the energy audit), `control` (the step controller and the landing on contact onsets);
//! this module validates the pack and runs the loop.

mod accounting;
mod control;
mod energy;
mod events;
mod forces;
mod multirate;
mod state;

pub use energy::EnergyAudit;

use crate::options::{AdaptiveStepping, MultibodyOptions, Scheme, Stepping, ToothResolution};
use crate::world::World;
use clutchpack_model::{Engine, EngineError, LawKind, Observer, PackModel, RunStats};
use state::Run;

/// How often the observer's `progress` is polled by the shared step: every this many steps
/// of one coupled body (a step of `n` discs and plates counts `n`: every 1000 steps of one
/// disc, every step of a pack of 1000 or more). A body-step costs a few microseconds,
/// so a stop acts within milliseconds whatever the pack's size; the multirate scheme polls at
/// every world step.
const PROGRESS_BODY_STEPS: u64 = 1000;

/// The rapier3d-f64 multibody engine (see the crate docs).
#[derive(Debug, Clone)]
pub struct MultibodyEngine {
    pack: PackModel,
    options: MultibodyOptions,
    /// Why the multirate scheme does not run this pack (`None`: it does).
    multirate_refused: Option<&'static str>,
    /// Coupling sub-steps of the last multirate run.
    substeps: u64,
    energy: EnergyAudit,
    per_tooth: Vec<bool>,
}

impl MultibodyEngine {
    /// Builds the engine for a pack model with `options` (samples at
    /// `options.record_rate_hz`). Fails with [`EngineError::Unsupported`] for a pack it cannot
    /// run (the squeeze-film law, lumped teeth where they are not exact, an inconsistent
    /// stack or drum) or options out of range.
    pub fn new(pack: PackModel, options: MultibodyOptions) -> Result<MultibodyEngine, EngineError> {
        let record_rate_hz = options.record_rate_hz;
        let bad = |m: String| Err(EngineError::Unsupported(m));
        if !(record_rate_hz > 0.0 && record_rate_hz.is_finite()) {
            return bad(format!("record rate {record_rate_hz} Hz: must be > 0"));
        }
        match options.stepping {
            Stepping::Fixed { dt_s } if !(dt_s > 0.0 && dt_s.is_finite()) => {
                return bad(format!("fixed step {dt_s} s: must be > 0"));
            }
            Stepping::Adaptive(a)
                if !(a.max_step_s > 0.0
                    && a.steps_per_contact > 1.0
                    && a.approach_fraction > 0.0
                    && a.approach_fraction < 1.0
                    && a.min_step_s > 0.0
                    && a.sustained_steps_per_period > std::f64::consts::PI
                    && a.sustained_after > 1.0) =>
            {
                return bad(format!("adaptive stepping {a:?}: needs max_step_s > 0, steps_per_contact > 1, approach_fraction in (0, 1), min_step_s > 0, sustained_steps_per_period > pi, sustained_after > 1"));
            }
            _ => {}
        }
        if let Some(st) = &pack.stack {
            if pack.discs.is_empty() || pack.plates.len() != pack.discs.len() + 1 {
                return bad(format!(
                    "a stack needs N friction discs and N + 1 separator plates ({} discs, {} \
                     plates)",
                    pack.discs.len(),
                    pack.plates.len()
                ));
            }
            let (ri, ro) = (st.face_inner_radius_m, st.face_outer_radius_m);
            let gap_ok = st
                .open_gap
                .is_none_or(|g| g.gap_m > 0.0 && g.viscosity_pa_s >= 0.0);
            let ok = ri > 0.0
                && ro > ri
                && st.piston.area_m2 > 0.0
                && st.spline_friction >= 0.0
                && gap_ok;
            if !ok {
                return bad(format!(
                    "stack: needs 0 < face_inner_radius_m < face_outer_radius_m, piston area \
                     > 0, spline friction >= 0, an open gap > 0 ({st:?})"
                ));
            }
        }
        if let Some(dr) = &pack.drum {
            if pack.plates.is_empty() || dr.inertia_kg_m2.is_nan() || dr.inertia_kg_m2 <= 0.0 {
                return bad(
                    "an output drum needs separator plates on it and an inertia > 0".into(),
                );
            }
        }
        let n_discs = pack.discs.len();
        let mut per_tooth = Vec::with_capacity(n_discs + pack.plates.len());
        for (j, d) in pack.discs.iter().chain(&pack.plates).enumerate() {
            let i = if j < n_discs {
                format!("discs[{j}]")
            } else {
                format!("plates[{}]", j - n_discs)
            };
            if d.law.kind == LawKind::Squeeze && d.law.oil.thickness_m > 0.0 {
                return bad(format!(
                    "{i}: the squeeze-film law is a damper with time constant m h^3 / (beta eta B^3 L) \
                     (nanoseconds near metal contact), too stiff for the explicit multibody step; \
                     use the reference engine"
                ));
            }
            if d.spline.teeth == 0 || d.inertia_kg_m2.is_nan() || d.inertia_kg_m2 <= 0.0 {
                return bad(format!("{i}: needs teeth > 0 and inertia > 0"));
            }
            if let Some(&e) = d.tooth_spacing_errors_m.iter().find(|e| !e.is_finite()) {
                return bad(format!("{i}: tooth spacing error {e} m: must be finite"));
            }
            if !d.tooth_spacing_errors_m.is_empty()
                && d.tooth_spacing_errors_m.len() != d.spline.teeth as usize
            {
                return bad(format!(
                    "{i}: {} tooth spacing errors for {} teeth: one per tooth or none",
                    d.tooth_spacing_errors_m.len(),
                    d.spline.teeth
                ));
            }
            per_tooth.push(match options.teeth {
                ToothResolution::PerTooth => true,
                // Concentric discs on a locked radial joint, no spacing errors: lumped is exact.
                ToothResolution::Auto => !d.is_concentric(),
                ToothResolution::Lumped if d.is_concentric() => false,
                ToothResolution::Lumped => {
                    return bad(format!(
                        "{i}: lumped teeth are exact only for a concentric disc without \
                         spacing errors (this one floats radially, is offset or has spacing \
                         errors): use per-tooth resolution"
                    ))
                }
            });
        }
        // Build once now so that a scene the world cannot hold fails here, not in `run`.
        World::build(&pack, &options.shapes, options.mount)?;
        let multirate_refused = match options.scheme {
            Scheme::Shared => Some("asked for"),
            Scheme::Auto | Scheme::Multirate => multirate::unsupported(&pack, &options, &per_tooth),
        };
        if let (Scheme::Multirate, Some(why)) = (options.scheme, multirate_refused) {
            return bad(format!("the multirate scheme cannot run this pack: {why}"));
        }
        Ok(MultibodyEngine {
            pack,
            multirate_refused,
            substeps: 0,
            options,
            energy: EnergyAudit::default(),
            per_tooth,
        })
    }

    /// Whether runs use the multirate scheme (crate docs, "Theory").
    pub fn is_multirate(&self) -> bool {
        self.multirate_refused.is_none()
    }

    /// Which time-stepping scheme runs this pack and why, in one line of words for `run` to
    /// print, e.g. `multirate scheme (automatic: a prescribed shaft and concentric friction
    /// discs only, so the discs are independent within a world step): ...` or `shared step
    /// (automatic: an inertial shaft (eq 4) couples ...): ...`.
    pub fn scheme_explanation(&self) -> String {
        let shared = "every body advances with one contact-aware step, the shortest any \
                      coupling needs";
        match (self.multirate_refused, self.options.stepping) {
            (None, Stepping::Adaptive(a)) => {
                let how = match self.options.scheme {
                    Scheme::Multirate => "asked for",
                    _ => "automatic",
                };
                let bodies = if self.pack.plates.is_empty() {
                    "a prescribed shaft and concentric friction discs only, so the discs are \
                     independent within a world step"
                } else {
                    "a prescribed shaft, plates on the housing and an open stack, so the \
                     bodies are independent within a world step but for the gaps' drag, held \
                     over it"
                };
                format!(
                    "multirate scheme ({how}: {bodies}): the rapier world steps at up to {} s, \
                     each body's spline coupling sub-steps its own contacts ({} steps per \
                     contact, classical Runge-Kutta)",
                    a.max_step_s, a.steps_per_contact
                )
            }
            (Some(why), _) if self.options.scheme == Scheme::Shared => {
                format!("shared step ({why}): {shared}")
            }
            (why, _) => format!(
                "shared step (automatic: {}): {shared}",
                why.unwrap_or("fixed steps")
            ),
        }
    }

    /// Sub-steps the couplings took in the last multirate run (0 after a shared-step run,
    /// whose steps are in [`clutchpack_model::RunStats::steps`]).
    pub fn coupling_substeps(&self) -> u64 {
        self.substeps
    }

    /// The options in force.
    pub fn options(&self) -> &MultibodyOptions {
        &self.options
    }

    /// The energy audit of the last run.
    pub fn energy(&self) -> EnergyAudit {
        self.energy
    }
}

impl Engine for MultibodyEngine {
    fn name(&self) -> &'static str {
        "multibody"
    }

    fn model(&self) -> &PackModel {
        &self.pack
    }

    fn disc_names(&self) -> Vec<String> {
        self.pack
            .discs
            .iter()
            .chain(&self.pack.plates)
            .map(|d| d.name.clone())
            .collect()
    }

    fn run(
        &mut self,
        duration_s: f64,
        observer: &mut dyn Observer,
    ) -> Result<RunStats, EngineError> {
        match (self.multirate_refused, self.options.stepping) {
            (None, Stepping::Adaptive(a)) => self.run_multirate(duration_s, observer, a),
            _ => self.run_shared(duration_s, observer),
        }
    }
}

impl MultibodyEngine {
    /// The shared step: every body advances with one contact-aware step (the shortest any
    /// coupling needs), the teeth's kick integrated along it (`integrate.rs`).
    fn run_shared(
        &mut self,
        duration_s: f64,
        observer: &mut dyn Observer,
    ) -> Result<RunStats, EngineError> {
        let opts = &self.options;
        let mut run = Run::new(&self.pack, opts, &self.per_tooth)?;
        run.events
            .take_contact_samples(observer.wants_contact_samples());
        let period = 1.0 / opts.record_rate_hz;
        let rec_time = |j: u64| j as f64 * period;
        let mut rec_index: u64 = 0;
        // Half of the current step: samples are taken at the step nearest to the grid when
        // the step does not land on it (fixed steps, adaptive contact steps).
        let mut half_step = match opts.stepping {
            Stepping::Fixed { dt_s } => 0.5 * dt_s,
            Stepping::Adaptive(_) => 0.0,
        };
        let steps_per_contact = match opts.stepping {
            Stepping::Adaptive(a) => a.steps_per_contact,
            Stepping::Fixed { .. } => AdaptiveStepping::default().steps_per_contact,
        };
        let mut steps: u64 = 0;
        let mut stopped = false;
        let mut t_last_good = 0.0;
        // simulated time at the start of the stall check's current block, s
        let mut stall_t0 = 0.0;
        // A step costs about the same per body: poll the stop every PROGRESS_BODY_STEPS
        // body-steps.
        let progress_every = (PROGRESS_BODY_STEPS / (run.couplings.len() as u64).max(1)).max(1);
        loop {
            run.evaluate(t_last_good)?;
            t_last_good = run.t;
            if steps == 0 {
                let kinetic_j = run.kinetic_energy();
                run.energy.start(run.potential_j, kinetic_j);
            }
            run.track_events(steps_per_contact, observer);
            if rec_time(rec_index) <= run.t + half_step {
                observer.sample(&run.sample(opts.record_tooth_loads));
                if let Some(s) = &run.stack {
                    observer.interfaces(run.t, &s.samples());
                }
                while rec_time(rec_index) <= run.t + half_step {
                    rec_index += 1;
                }
            }
            if steps > 0 && steps.is_multiple_of(progress_every) && observer.progress(run.t) {
                stopped = true;
            }
            if steps > 0
                && steps.is_multiple_of(clutchpack_model::STALL_STEPS)
                && matches!(opts.stepping, Stepping::Adaptive(_))
            {
                // adaptive steps far below any real pack's: stop rather than run for days
                let span = run.t - stall_t0;
                if span < clutchpack_model::STALL_SPAN_S {
                    return Err(EngineError::Diverged {
                        t_s: run.t,
                        reason: format!(
                            "{} steps advanced only {span:.3e} s: a coupling is stiffer, or the \
                             drive faster, than the engine can integrate (check the contact, oil \
                             and drive values)",
                            clutchpack_model::STALL_STEPS
                        ),
                    });
                }
                stall_t0 = run.t;
            }
            if stopped || run.t >= duration_s {
                break;
            }
            let t = run.t;
            let t_next = match opts.stepping {
                Stepping::Fixed { dt_s } => ((steps + 1) as f64 * dt_s).min(duration_s),
                Stepping::Adaptive(a) => {
                    let (want, contact) = run.desired_step(&a);
                    if want.is_nan() || want < a.min_step_s {
                        return Err(EngineError::Diverged {
                            t_s: t,
                            reason: format!("the step size collapsed to {want:.3e} s"),
                        });
                    }
                    // Free-flight steps land on the sampling grid; contact steps keep their
                    // length (a varying step spoils the symplectic step's energy).
                    half_step = if contact { 0.5 * want } else { 0.0 };
                    let target = if contact {
                        duration_s
                    } else {
                        rec_time(rec_index).min(duration_s)
                    };
                    let rem = target - t;
                    let h = if want >= rem {
                        rem
                    } else if want > 0.5 * rem {
                        0.5 * rem
                    } else {
                        want
                    };
                    // The stack's torques for this step enter the landing's prediction.
                    run.solve_stack(h);
                    // Never step over an onset or a separation: land on it.
                    match run.landing(h, 1e-3 * h.min(want)) {
                        Some(x) => {
                            half_step = 0.5 * x;
                            t + x
                        }
                        None if h == rem => target,
                        None => t + h,
                    }
                }
            };
            // (Re)solve the stack for the step actually taken.
            let h = t_next - t;
            if run.stack.as_ref().is_some_and(|s| s.step_s() != h) {
                run.solve_stack(h);
            }
            run.apply_forces(t_next);
            run.advance(t_next);
            steps += 1;
        }
        for e in run.events.finish(run.t) {
            observer.impact(&e);
        }
        let kinetic_j = run.kinetic_energy();
        self.energy = run.energy.finish(run.potential_j, kinetic_j);
        Ok(RunStats {
            simulated_s: run.t,
            steps,
            rejected_steps: 0,
            rhs_evals: steps + 1,
            stopped_early: stopped,
        })
    }
}

impl MultibodyEngine {
    /// The multirate scheme (`multirate.rs`): the world steps at free-flight length, landing
    /// on the sampling grid, and every coupling sub-steps its own contacts within it.
    fn run_multirate(
        &mut self,
        duration_s: f64,
        observer: &mut dyn Observer,
        a: AdaptiveStepping,
    ) -> Result<RunStats, EngineError> {
        let opts = &self.options;
        let mut run = Run::new(&self.pack, opts, &self.per_tooth)?;
        run.events
            .take_contact_samples(observer.wants_contact_samples());
        let period = 1.0 / opts.record_rate_hz;
        let rec_time = |j: u64| j as f64 * period;
        let mut rec_index: u64 = 0;
        let mut counts = multirate::Counts::default();
        let mut closed = Vec::new();
        let mut contacts = Vec::new();
        let mut steps: u64 = 0;
        let mut stopped = false;
        // The state at t = 0, as the shared step reads it.
        run.evaluate(0.0)?;
        let kinetic_j = run.kinetic_energy();
        run.energy.start(run.potential_j, kinetic_j);
        run.track_events(a.steps_per_contact, observer);
        loop {
            if rec_time(rec_index) <= run.t {
                observer.sample(&run.sample(opts.record_tooth_loads));
                if let Some(s) = &run.stack {
                    observer.interfaces(run.t, &s.samples());
                }
                while rec_time(rec_index) <= run.t {
                    rec_index += 1;
                }
            }
            if observer.progress(run.t) {
                stopped = true;
            }
            if stopped || run.t >= duration_s {
                break;
            }
            let t1 = world_step_end(run.t, a.max_step_s, rec_time(rec_index), duration_s);
            run.read_relative_states();
            run.multirate_step(t1, &a, &mut counts, &mut closed, &mut contacts)?;
            run.update_stack();
            // Events in the order they closed across the couplings.
            closed.sort_by(|x, y| x.t_off_s.total_cmp(&y.t_off_s));
            for e in closed.drain(..) {
                observer.impact(&e);
            }
            // The sub-steps' contact samples, all in (t, t1], before the sample at t1; a
            // stable sort keeps each coupling's order and interleaves the couplings in time.
            contacts.sort_by(|x, y| x.1.total_cmp(&y.1));
            for (i, t, s) in contacts.drain(..) {
                observer.contact_sample(i, t, &s);
            }
            steps += 1;
        }
        for e in run.events.finish(run.t) {
            observer.impact(&e);
        }
        let kinetic_j = run.kinetic_energy();
        self.energy = run.energy.finish(run.potential_j, kinetic_j);
        self.substeps = counts.substeps;
        Ok(RunStats {
            simulated_s: run.t,
            steps,
            rejected_steps: 0,
            rhs_evals: counts.evals,
            stopped_early: stopped,
        })
    }
}

/// The end of the multirate scheme's next world step from `t` (s): a free-flight step of
/// `max_step_s`, landing exactly on the next sample time `grid_s` and on the end of the run
/// `end_s` when they come within it. "Within" allows a millionth of a step of rounding: taking
/// `t + max_step_s` a rounding error short of the grid would leave a world step of 1e-19 s,
/// and the impact tracker's parabola through samples that close is meaningless.
fn world_step_end(t: f64, max_step_s: f64, grid_s: f64, end_s: f64) -> f64 {
    let reach = t + max_step_s * (1.0 + 1e-6);
    if end_s <= reach && end_s <= grid_s {
        end_s
    } else if grid_s <= reach {
        grid_s
    } else {
        t + max_step_s
    }
}

#[cfg(test)]
mod tests {
    use super::world_step_end;

    /// The world step lands on the sampling grid and the end of the run, never a rounding
    /// error short of them.
    #[test]
    fn world_steps_land_on_the_grid_and_the_end() {
        // 21 steps of 1e-4 s add up to a hair under 21 * 1e-4
        let t = (0..21).fold(0.0, |t, _| t + 1e-4);
        let grid = 22.0 * 1e-4;
        assert_eq!(world_step_end(t, 1e-4, grid, 1.0), grid);
        assert_eq!(world_step_end(0.0, 1e-4, 5e-4, 1.0), 1e-4);
        assert_eq!(world_step_end(0.0, 1e-4, 5e-4, 0.5e-4), 0.5e-4);
        assert_eq!(world_step_end(0.0, 1e-4, 1e-4, 1e-4), 1e-4);
    }
}
