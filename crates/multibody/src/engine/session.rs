//! [`MultibodySession`]: the engine's run as a steppable session (`clutchpack_model::session`),
//! the loops of both schemes made resumable; `Engine::run` is one session advanced once.
//!
//! # Where a call stops
//! - **Driven by nothing** ([`Driven::NONE`], the scene's inputs): the steps are those of
//!   `Engine::run`, never shortened by a call's boundary, so any split of a run into calls
//!   takes the same steps and sends the same outputs bit for bit. A call stops at the first
//!   step that reaches its time `t`: the session then stands at [`Session::time_s`] `>= t`,
//!   and the snapshot is the state there (no interpolation). Free-flight steps land on the
//!   record grid, so `time_s() == t` for a `t` on the grid outside contacts; else the session
//!   stands past `t` by less than one step (a contact step, or up to the free-flight step off
//!   the grid). A run's own end lands exactly: [`MultibodySession::set_end`] declares it (what
//!   `Engine::run` does with its duration), and steps then land on it as `run`'s land on its
//!   duration (the contact steps just before it are shortened alike).
//! - **Driven** (any [`Driven`] flag): every call's time is a communication point where an
//!   input may change, and `time_s() == t` after every call. A call's time on a grid point
//!   but for rounding lands on that point, as the whole run's steps do; a step that would
//!   pass it is shortened to land on it exactly, or, in a session started through
//!   `Engine::start` on adaptive steps, passes it as the whole run's does and is stepped again
//!   to it should an input change there or the run finish (`calls.rs`, issue 46).
//!
//! # Inputs
//! A driven input is held (zero-order hold) from the session's start at the scene's value at
//! t = 0, then from each [`Session::set_inputs`] at the value set, and acts from
//! [`Session::time_s`] on. The prescribed shaft's speed becomes
//! `SpeedProfile::Held { t0_s: t, angle0_rad: the shaft's angle at t, speed }` (the angle
//! continuous, the speed and so every disc's relative speed against the shaft jumping); the
//! inertial shaft's drive torque `ShaftExcitation::Held`; the drum's load its
//! `load_torque_n_m`; the piston's pressure `PressureProfile::Constant`. The state at `t` is
//! re-evaluated with the new input (tooth loads, clamp forces, kicks), and the torques, which
//! the engine integrates along a step, are integrated exactly as held values: the step ending
//! at `t` with the value before, the next with the new one (`forces.rs`, `drive_switch`).
//!
//! # Clone
//! [`Session::boxed_clone`] copies the whole state: the run (rapier's world with fresh
//! pipelines, `World`'s `Clone`; the couplings' contact memories, the kicks' histories, the
//! impact trackers, the energy audit) and the loop's counters. The model is shared (`Arc`)
//! until an input changes it. A copy advanced as the original gives the same outputs bit
//! for bit (`tests/session.rs`).

use super::carriers::Motion;
use super::energy::EnergyAudit;
use super::scheme_state::SessionBuffers;
use super::state::Run;
use super::substep::{split_remainder, Counts, Prescribed, WorldStep};
use super::thermal::Thermal;
use crate::options::{AdaptiveStepping, MultibodyOptions, Stepping};
use crate::world::SHAFT;
use clutchpack_model::session::{hold_inputs, Advance, Driven, Inputs, Session, Snapshot};
use clutchpack_model::thermal::ThermalModel;
use clutchpack_model::{EngineError, Observer, RunStats};
use std::sync::Arc;

mod calls;
mod inputs;

/// How often the observer's `progress` is polled by the shared step: every this many steps
/// of one coupled body (a step of `n` discs and plates counts `n`: every 1000 steps of one
/// disc, every step of a pack of 1000 or more). A body-step costs a few microseconds,
/// so a stop acts within milliseconds whatever the pack's size; the multirate scheme polls at
/// every world step.
const PROGRESS_BODY_STEPS: u64 = 1000;

/// Which loop the session runs.
#[derive(Debug, Clone, Copy)]
enum Loop {
    /// The shared step (`run_shared` before sessions).
    Shared,
    /// The multirate scheme with its stepping.
    Multirate(AdaptiveStepping),
}

/// A run of the multibody engine in progress, owning its model and its rapier world (see the
/// module docs for where a call stops, how inputs act and how a copy is made).
#[derive(Clone)]
pub struct MultibodySession {
    pub(super) run: Run,
    options: MultibodyOptions,
    scheme: Loop,
    driven: Driven,
    /// A known end, s: steps land on it as `Engine::run`'s land on its duration
    /// (`f64::INFINITY`: none).
    end_s: f64,
    /// Index of the next sample time on the record grid.
    rec_index: u64,
    /// World steps taken.
    steps: u64,
    /// Fixed steps: grid points `k dt` reached (a driven step may land off the grid).
    fixed_index: u64,
    /// Shared step: half of the current step (samples go out at the step nearest the grid
    /// when steps do not land on it), s.
    half_step: f64,
    /// Time of the last state that evaluated without failure, s.
    t_last_good: f64,
    /// Simulated time at the start of the stall check's current block, s.
    stall_t0: f64,
    /// The multirate scheme's sub-step counts.
    counts: Counts,
    /// When the multirate scheme goes on with the clamped stack integrated as one system, s:
    /// the time before which the piston cannot push on the stack (`Piston::open_until_s`;
    /// `f64::INFINITY`: never).
    clamped_from_s: f64,
    /// Whether the outputs at t = 0 (the trackers' first update, the first sample) are sent.
    started: bool,
    /// Set when a call failed: the session must not be advanced again.
    failed: bool,
    /// The statistics once finished.
    finished: Option<RunStats>,
    /// The energy audit (complete once finished).
    energy: EnergyAudit,
    /// The temperatures of a thermal run (`thermal.rs`); `None`: isothermal.
    pub(super) thermal: Option<Box<Thermal>>,
    /// The loop's buffers, kept from one call to the next so that a frame allocates nothing
    /// of its own (issue 46).
    scratch: SessionBuffers,
    /// Whether a driven call lands on the grid point its time stands for (`calls.rs`).
    calls_on_grid: bool,
    /// The grid point the last call landed on and the call's time, s (`calls.rs`).
    called_s: (f64, f64),
    /// A driven shared step that passed the last call's time: the session before it, the
    /// call (`calls.rs`); what it produced waits in `held` for the next call.
    passed: Option<Box<calls::Passed>>,
    held: calls::Held,
}

impl MultibodySession {
    /// A session at t = 0 on `pack` (the state at t = 0 evaluated), running the shared step
    /// or the multirate scheme (`multirate`), its caller driving `driven` (checked by the
    /// engine), carrying the temperatures of `thermal` (`None`: isothermal).
    pub(super) fn new(
        pack: Arc<clutchpack_model::PackModel>,
        options: &MultibodyOptions,
        per_tooth: &[bool],
        multirate: Option<AdaptiveStepping>,
        driven: Driven,
        thermal: Option<ThermalModel>,
    ) -> Result<MultibodySession, EngineError> {
        let mut pack = pack;
        if driven.any() {
            // the driven inputs held at the scene's values until the caller sets them
            pack = Arc::new(hold_inputs(&pack, 0.0, &Inputs::of_scene(&pack, &driven, 0.0)).0);
        }
        // a thermal run starts with the parameters of its temperatures at t = 0
        let thermal = match thermal {
            Some(model) => {
                let (th, p) = Thermal::new(model, pack)?;
                pack = p;
                Some(Box::new(th))
            }
            None => None,
        };
        let mut run = Run::new(pack, options, per_tooth, multirate.is_some())?;
        // a driven drum load is integrated exactly as a held value (its kick
        // `L_before h1 / 2 + L h0 / 2`) rather than through the polynomial kick of the drum's
        // other loads (byte-identical runs need the latter for the scene's constant load)
        if let Some(d) = run.world.drum() {
            run.carriers[d].exact = driven.drum_load;
        }
        run.evaluate(0.0)?;
        let kinetic_j = run.kinetic_energy();
        run.energy.start(run.potential_j, kinetic_j);
        let clamped_from_s = run
            .pack
            .stack
            .as_ref()
            .map_or(f64::INFINITY, |s| s.piston.open_until_s());
        Ok(MultibodySession {
            run,
            options: options.clone(),
            scheme: multirate.map_or(Loop::Shared, Loop::Multirate),
            driven,
            end_s: f64::INFINITY,
            rec_index: 0,
            steps: 0,
            fixed_index: 0,
            half_step: match options.stepping {
                Stepping::Fixed { dt_s } => 0.5 * dt_s,
                Stepping::Adaptive(_) => 0.0,
            },
            t_last_good: 0.0,
            stall_t0: 0.0,
            counts: Counts::default(),
            clamped_from_s,
            started: false,
            failed: false,
            finished: None,
            energy: EnergyAudit::default(),
            thermal,
            scratch: SessionBuffers::default(),
            calls_on_grid: false,
            called_s: (0.0, 0.0),
            passed: None,
            held: calls::Held::default(),
        })
    }

    /// Declares the run's end, s: steps land on it exactly as `Engine::run`'s land on its
    /// duration (the contact steps just before it shortened alike), so that a session driven
    /// by nothing and advanced to `end_s` in any number of calls gives `run`'s outputs bit for
    /// bit. Without it (the default) nothing is known of the end and the last call may stop a
    /// step past its time (module docs).
    pub fn set_end(&mut self, end_s: f64) {
        self.end_s = end_s;
    }

    /// The energy audit: complete after [`Session::finish`], the work so far before.
    pub fn energy(&self) -> EnergyAudit {
        self.energy
    }

    /// Sub-steps the couplings took so far (multirate scheme; 0 on the shared step).
    pub fn coupling_substeps(&self) -> u64 {
        self.counts.substeps
    }

    /// Couplings on an inertial carrier (an inertial shaft, the drum) that touched within a
    /// world step the multirate scheme predicted them to fly through, so far (each integrated
    /// for the rest of that step against the carrier's motion without its reaction on it;
    /// crate docs, "Multirate on an inertial shaft"). 0 on the shared step and for couplings
    /// on a prescribed shaft or the housing.
    pub fn missed_contacts(&self) -> u64 {
        self.counts.missed
    }

    /// Whether the session runs the multirate scheme (with its clamped stack integrated as
    /// one system once the piston may push).
    pub fn is_multirate(&self) -> bool {
        matches!(self.scheme, Loop::Multirate(_))
    }

    /// The end the step control aims at from the current time, for a call to `t_s`: a driven
    /// session lands on every communication point; one driven by nothing only on a declared
    /// end still ahead.
    fn step_end(&self, t_s: f64) -> f64 {
        let end = if self.end_s > self.run.t {
            self.end_s
        } else {
            f64::INFINITY
        };
        if self.driven.any() {
            end.min(t_s)
        } else {
            end
        }
    }

    /// Time of record sample `j`, s: `j` times the period (as `run` always computed it, not
    /// `j / rate`, which rounds differently).
    fn rec_time(&self, j: u64) -> f64 {
        j as f64 * (1.0 / self.options.record_rate_hz)
    }

    /// How far apart a communication point and a point of the record grid (or of the fixed
    /// steps' grid, `interval_s`) may be and still be one point, s: a driven session's
    /// communication points `k T` and the grid's `j / rate` are the same instants but for
    /// rounding (9e-3 against 90 / 1e4 = 9.000000000000001e-3), and a step between two such
    /// would be 1e-18 s long. A billionth of the interval; 0 for a session driven by nothing,
    /// whose steps are `run`'s.
    fn slack(&self, interval_s: f64) -> f64 {
        if self.driven.any() {
            1e-9 * interval_s
        } else {
            0.0
        }
    }

    /// The next point of the record grid as a step's target aiming at `end` (s): `end`
    /// itself when the two are one point ([`Self::slack`]).
    fn grid_target(&self, end: f64) -> f64 {
        let grid = self.rec_time(self.rec_index);
        if (grid - end).abs() <= self.slack(1.0 / self.options.record_rate_hz) {
            end
        } else {
            grid
        }
    }

    /// Sends the sample (and the stack's interfaces) at `t` if one is due.
    fn sample_if_due(&mut self, observer: &mut dyn Observer) {
        let run = &self.run;
        let slack = self.slack(1.0 / self.options.record_rate_hz);
        if self.rec_time(self.rec_index) <= run.t + self.half_step + slack {
            let sc = &mut self.scratch;
            run.sample_into(self.options.record_tooth_loads, &mut sc.sample);
            observer.sample(&sc.sample);
            if let Some(s) = &run.stack {
                s.samples_into(&mut sc.interfaces);
                observer.interfaces(run.t, &sc.interfaces);
            }
            while self.rec_time(self.rec_index) <= run.t + self.half_step + slack {
                self.rec_index += 1;
            }
        }
    }

    /// The shared step's loop from the current state to `t_s`: each step, then the state at
    /// its end evaluated, its events tracked, its sample sent.
    fn advance_shared(
        &mut self,
        t_s: f64,
        carry: bool,
        observer: &mut dyn Observer,
    ) -> Result<Advance, EngineError> {
        let steps_per_contact = match self.options.stepping {
            Stepping::Adaptive(a) => a.steps_per_contact,
            Stepping::Fixed { .. } => AdaptiveStepping::default().steps_per_contact,
        };
        // A step costs about the same per body: poll the stop every PROGRESS_BODY_STEPS
        // body-steps.
        let progress_every =
            (PROGRESS_BODY_STEPS / (self.run.couplings.len() as u64).max(1)).max(1);
        if !self.started {
            self.started = true;
            if let Some(th) = self.thermal.as_mut() {
                th.start(&self.run, observer);
            }
            self.run
                .track_events(steps_per_contact, steps_per_contact, observer);
            self.sample_if_due(observer);
        }
        while self.run.t < t_s {
            // a carried step ends where an undriven one does (`calls.rs`)
            let end = self.step_end(if carry { f64::INFINITY } else { t_s });
            let t = self.run.t;
            let t_next = match self.options.stepping {
                Stepping::Fixed { dt_s } => {
                    let grid = (self.fixed_index + 1) as f64 * dt_s;
                    if (grid - end).abs() <= self.slack(dt_s) {
                        self.fixed_index += 1;
                        end
                    } else if grid <= end {
                        self.fixed_index += 1;
                        grid
                    } else {
                        end
                    }
                }
                Stepping::Adaptive(a) => self.adaptive_step_end(&a, end)?,
            };
            // a step passing the call: the session kept before it, its outputs held
            let mut held = std::mem::take(&mut self.held);
            let obs: &mut dyn Observer = if carry && t_next > t_s {
                self.keep_before();
                &mut held
            } else {
                &mut *observer
            };
            // (Re)solve the stack for the step actually taken.
            let run = &mut self.run;
            let h = t_next - t;
            if run.stack.as_ref().is_some_and(|s| s.step_s() != h) {
                run.solve_stack(h);
            }
            run.apply_forces(t_next);
            run.advance(t_next);
            self.steps += 1;
            run.evaluate(self.t_last_good)?;
            self.t_last_good = run.t;
            run.track_events(steps_per_contact, steps_per_contact, obs);
            self.sample_if_due(obs);
            if let Some(th) = self.thermal.as_mut() {
                th.after_step(&mut self.run, obs)?;
            }
            self.held = held;
            let steps = self.steps;
            let stopped = steps.is_multiple_of(progress_every) && observer.progress(self.run.t);
            if steps.is_multiple_of(clutchpack_model::STALL_STEPS)
                && matches!(self.options.stepping, Stepping::Adaptive(_))
            {
                // adaptive steps far below any real pack's: stop rather than run for days
                let span = self.run.t - self.stall_t0;
                if span < clutchpack_model::STALL_SPAN_S {
                    return Err(EngineError::Diverged {
                        t_s: self.run.t,
                        reason: format!(
                            "{} steps advanced only {span:.3e} s: a coupling is stiffer, or the \
                             drive faster, than the engine can integrate (check the contact, oil \
                             and drive values)",
                            clutchpack_model::STALL_STEPS
                        ),
                    });
                }
                self.stall_t0 = self.run.t;
            }
            if stopped {
                return Ok(Advance::Stopped);
            }
        }
        Ok(Advance::Reached)
    }

    /// The end of the shared step's next adaptive step, aiming at `end` (s): the controller's
    /// step, free-flight steps landing on the sampling grid, every step landing on a contact
    /// onset or separation (the stack solved for it).
    fn adaptive_step_end(&mut self, a: &AdaptiveStepping, end: f64) -> Result<f64, EngineError> {
        let next_sample = self.grid_target(end);
        let run = &mut self.run;
        let t = run.t;
        let (want, contact) = run.desired_step(a);
        if want.is_nan() || want < a.min_step_s {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!("the step size collapsed to {want:.3e} s"),
            });
        }
        // Free-flight steps land on the sampling grid; contact steps keep their length (a
        // varying step spoils the symplectic step's energy).
        self.half_step = if contact { 0.5 * want } else { 0.0 };
        let target = if contact { end } else { next_sample.min(end) };
        let rem = target - t;
        let h = split_remainder(want, rem);
        // The stack's torques for this step enter the landing's prediction.
        run.solve_stack(h);
        // Never step over an onset or a separation: land on it.
        Ok(match run.landing(h, 1e-3 * h.min(want)) {
            Some(x) => {
                self.half_step = 0.5 * x;
                t + x
            }
            None if h == rem => target,
            None => t + h,
        })
    }

    /// The multirate loop from the current state to `t_s`: each world step with the
    /// couplings' sub-steps, its closed impacts and contact samples, its sample.
    fn advance_multirate(
        &mut self,
        t_s: f64,
        a: AdaptiveStepping,
        carry: bool,
        observer: &mut dyn Observer,
    ) -> Result<Advance, EngineError> {
        if !self.started {
            self.started = true;
            if let Some(th) = self.thermal.as_mut() {
                th.start(&self.run, observer);
            }
            self.run
                .track_events(a.steps_per_contact, a.alone().steps_per_contact, observer);
            self.sample_if_due(observer);
            if observer.progress(self.run.t) {
                return Ok(Advance::Stopped);
            }
        }
        let alone = a.alone();
        while self.run.t < t_s {
            // the piston may push from now on: the clamped stack integrated as one system
            // (`clamped.rs`)
            let clamped = self.run.t >= self.clamped_from_s;
            // a carried step ends where an undriven one does (`calls.rs`)
            let to = if carry { f64::INFINITY } else { t_s };
            let end = if clamped {
                self.step_end(to)
            } else {
                self.step_end(to).min(self.clamped_from_s)
            };
            let grid = self.grid_target(end);
            let t1 = world_step_end(self.run.t, a.max_step_s, grid, end);
            // a step passing the call: the session kept before it, its outputs held
            let mut held = std::mem::take(&mut self.held);
            let observer: &mut dyn Observer = if carry && t1 > t_s {
                self.keep_before();
                &mut held
            } else {
                &mut *observer
            };
            let run = &mut self.run;
            if clamped {
                // the clamped stack's world steps read rapier's poses
                run.catch_up_world();
            }
            run.read_relative_states();
            // the prescribed shaft over the step, expanded about its middle once for every
            // sub-step's stages
            let profile = match &run.carriers[SHAFT].motion {
                Motion::Prescribed(p) => Some(Arc::clone(p)),
                _ => None,
            };
            let (old, half) = (self.scratch.local.take(), 0.5 * (t1 - run.t));
            let local = (profile.as_deref()).and_then(|p| p.local_reusing(run.t + half, half, old));
            let mut ws = WorldStep {
                t1,
                a: &a,
                alone: &alone,
                drive: profile.as_deref().map(|profile| Prescribed {
                    profile,
                    local: local.as_ref(),
                }),
                counts: &mut self.counts,
                closed: &mut self.scratch.closed,
                contacts: &mut self.scratch.contacts,
            };
            if clamped {
                run.clamped_step(&mut ws)?;
            } else {
                run.multirate_step(&mut ws)?;
            }
            self.scratch.local = local;
            run.update_stack();
            // Events in the order they closed across the couplings.
            let sc = &mut self.scratch;
            sc.closed.sort_by(|x, y| x.t_off_s.total_cmp(&y.t_off_s));
            for e in sc.closed.drain(..) {
                observer.impact(&e);
            }
            // The sub-steps' contact samples, all in (t, t1], before the sample at t1; a
            // stable sort keeps each coupling's order and interleaves the couplings in time.
            sc.contacts.sort_by(|x, y| x.1.total_cmp(&y.1));
            for (i, t, s) in sc.contacts.drain(..) {
                observer.contact_sample(i, t, &s);
            }
            self.steps += 1;
            self.t_last_good = self.run.t;
            self.sample_if_due(observer);
            if let Some(th) = self.thermal.as_mut() {
                th.after_step(&mut self.run, observer)?;
            }
            let stopped = observer.progress(self.run.t);
            self.held = held;
            if stopped {
                return Ok(Advance::Stopped);
            }
        }
        Ok(Advance::Reached)
    }
}

impl Session for MultibodySession {
    fn time_s(&self) -> f64 {
        self.call_time()
    }

    fn set_stop_time(&mut self, t_s: f64) {
        self.set_end(t_s);
    }

    fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), EngineError> {
        let undriven = inputs.undriven(&self.driven);
        if !undriven.is_empty() {
            return Err(EngineError::Unsupported(format!(
                "this session does not drive the {} (start it with those inputs driven)",
                undriven.join(", ")
            )));
        }
        if let Some((name, v)) = inputs.invalid() {
            return Err(EngineError::Unsupported(format!(
                "{name} = {}: must be finite (a pressure >= 0)",
                clutchpack_model::fmt_num(v)
            )));
        }
        if self.finished.is_some() || self.failed {
            return Err(EngineError::Unsupported(
                "the session is finished or failed: start a new one".into(),
            ));
        }
        if *inputs != Inputs::default() {
            self.rewind()?;
            self.apply_inputs(inputs);
        }
        Ok(())
    }

    fn advance_to(
        &mut self,
        t_s: f64,
        observer: &mut dyn Observer,
    ) -> Result<Advance, EngineError> {
        if self.finished.is_some() || self.failed {
            return Err(EngineError::Unsupported(
                "the session is finished or failed: start a new one".into(),
            ));
        }
        if t_s.is_nan() {
            return Err(EngineError::Unsupported("advance_to a time NaN".into()));
        }
        self.run
            .events
            .take_contact_samples(observer.wants_contact_samples());
        let to = self.landing(t_s);
        if self.resume(to, t_s, observer) {
            return Ok(Advance::Reached);
        }
        let out = match self.scheme {
            Loop::Shared => self.advance_shared(to, self.carries(), observer),
            Loop::Multirate(a) => self.advance_multirate(to, a, self.carries(), observer),
        };
        self.failed = out.is_err();
        self.landed(to, t_s);
        out
    }

    fn snapshot(&self) -> Snapshot {
        let run = &self.run;
        Snapshot {
            sample: run.sample(self.options.record_tooth_loads),
            interfaces: self.interfaces(),
            drum: run.world.drum().map(|d| run.carrier_state(d)),
        }
    }

    fn finish(&mut self, observer: &mut dyn Observer) -> RunStats {
        if let Some(stats) = &self.finished {
            return stats.clone();
        }
        // a step that passed the last call ended there, as the run ends at the call's time
        // (a failure to step again marks the session failed; the state is then the step's)
        if self.rewind().is_err() {
            self.failed = true;
        }
        self.held.send(observer);
        let run = &mut self.run;
        for e in run.events.finish(run.t) {
            observer.impact(&e);
        }
        let kinetic_j = run.kinetic_energy();
        self.energy = run.energy.finish(run.potential_j, kinetic_j);
        // the last (partial) window closes at the run's end
        let thermal = self.thermal.as_mut().map(|th| th.finish(run.t, observer));
        let stats = RunStats {
            simulated_s: run.t,
            steps: self.steps,
            rejected_steps: 0,
            // the multirate scheme's evaluations, and one per shared step (and at its start)
            rhs_evals: match self.scheme {
                Loop::Shared => self.steps + 1,
                Loop::Multirate(_) => self.counts.evals,
            },
            stopped_early: false,
            thermal,
        };
        self.finished = Some(stats.clone());
        stats
    }

    fn boxed_clone(&self) -> Box<dyn Session> {
        Box::new(self.clone())
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
