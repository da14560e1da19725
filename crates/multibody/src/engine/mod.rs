//! [`MultibodyEngine`]: the run loop around the rapier world, the spline hook and the step
//! controller; samples, impact events and the energy audit.
//!
//! One module per job: `state` (the world and every body's state), `forces` (the hook at
//! `t`, the loads and kicks, the step handed to rapier), `events` (impact events), `energy`
//! (the energy audit), `control` (the step controller and the landing on contact onsets),
//! `session` (the resumable loops of both schemes: a run as a steppable session); this module
//! validates the pack and starts sessions.

mod accounting;
mod carried;
mod carriers;
mod clamped;
mod control;
mod energy;
mod events;
mod forces;
mod inertial;
mod landing;
mod multirate;
mod scheme_state;
mod session;
mod state;
mod substep;
mod thermal;

pub use carried::Carried;
pub use energy::EnergyAudit;
pub use session::MultibodySession;

use crate::options::{MultibodyOptions, Scheme, Stepping, ToothResolution};
use crate::world::World;
use clutchpack_model::session::{Advance, Driven, Session};
use clutchpack_model::thermal::ThermalModel;
use clutchpack_model::{Engine, EngineError, LawKind, Observer, PackModel, RunStats};
use std::sync::Arc;

/// The rapier3d-f64 multibody engine (see the crate docs).
#[derive(Debug, Clone)]
pub struct MultibodyEngine {
    /// The pack, shared with the sessions (each copies it when an input changes).
    pack: Arc<PackModel>,
    options: MultibodyOptions,
    /// Why the multirate scheme does not run this pack (`None`: it does).
    multirate_refused: Option<&'static str>,
    /// Coupling sub-steps of the last multirate run.
    substeps: u64,
    energy: EnergyAudit,
    per_tooth: Vec<bool>,
    /// The thermal model whose temperatures runs carry (`None`: isothermal).
    thermal: Option<ThermalModel>,
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
                    && a.alone_contact_fraction > 0.0
                    && a.alone_contact_fraction <= 1.0
                    && a.alone().steps_per_contact > 1.0
                    && a.approach_fraction > 0.0
                    && a.approach_fraction < 1.0
                    && a.min_step_s > 0.0
                    && a.sustained_steps_per_period > std::f64::consts::PI
                    && a.sustained_after > 1.0) =>
            {
                return bad(format!("adaptive stepping {a:?}: needs max_step_s > 0, steps_per_contact > 1, alone_contact_fraction in (0, 1] with steps_per_contact times it > 1, approach_fraction in (0, 1), min_step_s > 0, sustained_steps_per_period > pi, sustained_after > 1"));
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
        let multirate_refused = match options.scheme {
            Scheme::Shared => Some("asked for"),
            Scheme::Auto | Scheme::Multirate => multirate::unsupported(&pack, &options, &per_tooth),
        };
        // Build once now so that a scene the world cannot hold fails here, not in `run`.
        let mount = options.mount.for_scheme(multirate_refused.is_none());
        World::build(&pack, &options.shapes, mount)?;
        if let (Scheme::Multirate, Some(why)) = (options.scheme, multirate_refused) {
            return bad(format!("the multirate scheme cannot run this pack: {why}"));
        }
        Ok(MultibodyEngine {
            pack: Arc::new(pack),
            multirate_refused,
            substeps: 0,
            options,
            energy: EnergyAudit::default(),
            per_tooth,
            thermal: None,
        })
    }

    /// The same engine carrying the temperatures of `thermal` (MODEL.md section 9; `None`:
    /// isothermal): the heat of every world step booked by the faces' modes and the teeth's
    /// work, the temperatures advanced and the tooth films' and open gaps' viscosities swapped
    /// at the end of each thermal window (`thermal.rs`; docs/DECISIONS.md, "Thermal windows").
    pub fn with_thermal(mut self, thermal: Option<ThermalModel>) -> MultibodyEngine {
        self.thermal = thermal;
        self
    }

    /// Whether runs use the multirate scheme (crate docs, "Theory"); a pack whose piston
    /// starts to push integrates its clamped stack as one system from then (`clamped.rs`).
    pub fn is_multirate(&self) -> bool {
        self.multirate_refused.is_none()
    }

    /// Which time-stepping scheme runs this pack and why, in one line of words for `run` to
    /// print, e.g. `multirate scheme (automatic: a prescribed shaft and friction discs
    /// turning about the axis only, so the discs are independent within a world step): ...`,
    /// `multirate scheme (automatic: an inertial shaft and friction discs turning about the
    /// axis only: within a world step the shaft is integrated with the discs that may touch
    /// it ...): ...` or `shared step (automatic: a clamped stack ...): ...`.
    pub fn scheme_explanation(&self) -> String {
        let shared = "every body advances with one contact-aware step, the shortest any \
                      coupling needs";
        match (self.multirate_refused, self.options.stepping) {
            (None, Stepping::Adaptive(a)) => {
                let how = match self.options.scheme {
                    Scheme::Multirate => "asked for",
                    _ => "automatic",
                };
                let inertial = matches!(self.pack.shaft, clutchpack_model::Shaft::Inertial { .. });
                let shaft = if inertial {
                    "an inertial shaft (within a world step the shaft is integrated with the \
                     discs that may touch it, in contact or near it, as one system, which \
                     conserves the angular momentum exactly, and the others fly free against \
                     the shaft's motion so found)"
                } else {
                    "a prescribed shaft"
                };
                let plates = if self.pack.plates.is_empty() {
                    if inertial {
                        " and friction discs turning about the axis only".to_string()
                    } else {
                        " and friction discs turning about the axis only, so the discs are \
                         independent within a world step"
                            .to_string()
                    }
                } else {
                    let carrier = if self.pack.drum.is_some() {
                        "on a drum (integrated with the plates that may touch it as one \
                         system, the others flying free against its motion)"
                    } else {
                        "on the housing"
                    };
                    if self.pack.stack.is_some() {
                        format!(
                            ", plates {carrier} and an open stack, so the bodies pull on each \
                             other within a world step only through the gaps' drag, held over it"
                        )
                    } else {
                        format!(
                            ", plates {carrier} and no stack, so the bodies do not pull on each \
                             other"
                        )
                    }
                };
                let bodies = format!("{shaft}{plates}");
                let until = match &self.pack.stack {
                    Some(s) if s.piston.can_clamp() => format!(
                        "; from t = {} s, where the piston may start to clamp the stack, the \
                         stack's discs and plates{}{} are integrated together as one system \
                         (bodies locked by their faces as one body, the slipping faces' \
                         friction along the sub-steps, locks landed on)",
                        s.piston.open_until_s().max(0.0),
                        if inertial { ", the shaft" } else { "" },
                        if self.pack.drum.is_some() {
                            " and the drum"
                        } else {
                            ""
                        }
                    ),
                    _ => String::new(),
                };
                format!(
                    "multirate scheme ({how}: {bodies}): the rapier world steps at up to {} s, \
                     each body's spline coupling sub-steps its own contacts ({} steps per \
                     contact, {} for a body alone against a prescribed shaft or the housing, \
                     classical Runge-Kutta){until}",
                    a.max_step_s,
                    a.steps_per_contact,
                    a.alone().steps_per_contact
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

    /// [`MultibodyEngine::session`], its driven calls landing on the whole run's grid
    /// points ([`MultibodySession::land_calls_on_grid`]).
    fn start(&self, driven: Driven) -> Result<Box<dyn Session>, EngineError> {
        let mut session = self.session(driven)?;
        session.land_calls_on_grid();
        Ok(Box::new(session))
    }

    /// One session driven by nothing, its end declared ([`MultibodySession::set_end`]),
    /// advanced to `duration_s` in one call and finished; kept as an override to keep
    /// [`MultibodyEngine::energy`] and [`MultibodyEngine::coupling_substeps`] up to date.
    fn run(
        &mut self,
        duration_s: f64,
        observer: &mut dyn Observer,
    ) -> Result<RunStats, EngineError> {
        if clutchpack_model::session::held_table(&self.pack).is_some() {
            // its rows are communication points (the energy audit is not kept then)
            return clutchpack_model::session::run_engine(self, duration_s, observer);
        }
        let mut session = self.session(Driven::NONE)?;
        session.set_end(duration_s);
        let advance = session.advance_to(duration_s, observer)?;
        let mut stats = session.finish(observer);
        stats.stopped_early = advance == Advance::Stopped;
        self.energy = session.energy();
        self.substeps = session.coupling_substeps();
        Ok(stats)
    }
}

impl MultibodyEngine {
    /// Starts a steppable run at t = 0 whose caller drives `driven` (as [`Engine::start`],
    /// with the concrete type: [`MultibodySession::set_end`], the energy audit). Fails with
    /// [`EngineError::Unsupported`] for an input the pack does not have (a shaft speed on an
    /// inertial shaft, a shaft torque on a prescribed one, a drum load without a drum, a
    /// piston pressure without a stack). A driven piston pressure runs the multirate scheme
    /// like the scene's own: the stack open until a call sets a pressure over the return
    /// spring, clamped as one system from that call on.
    pub fn session(&self, driven: Driven) -> Result<MultibodySession, EngineError> {
        driven.check(&self.pack)?;
        let multirate = match (self.multirate_refused, self.options.stepping) {
            (None, Stepping::Adaptive(a)) => Some(a),
            _ => None,
        };
        MultibodySession::new(
            Arc::clone(&self.pack),
            &self.options,
            &self.per_tooth,
            multirate,
            driven,
            self.thermal.clone(),
        )
    }
}
