//! A pack session whose carriers are a driveline network's bodies (`crate::network`, MODEL.md
//! section 8): the network reads the shaft's and the drum's motion after each of its steps,
//! and before the next sets their speeds back to its own (another pack's reaction on the same
//! rigid group, a clutch locking) and their torques from the rest of the network.

use super::session::MultibodySession;
use crate::world::SHAFT;
use clutchpack_model::session::{Inputs, Session};
use clutchpack_model::EngineError;
use rapier3d_f64::prelude::Vector;

/// What a network sets on one inertial carrier of a pack session before a step: its speed
/// (rad/s) and the torque of the rest of the network on it (N m), both positive along the
/// positive rotation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Carried {
    /// Its speed from now on, rad/s.
    pub speed_rad_s: f64,
    /// The torque held on it from now on, N m: the shaft's drive, the drum's load.
    pub torque_n_m: f64,
}

impl MultibodySession {
    /// The shaft's (`drum` false) or the drum's unwrapped angle (rad) and speed (rad/s) now,
    /// positive along the positive rotation; `None` for a drum the pack does not have.
    pub fn carrier_motion(&self, drum: bool) -> Option<(f64, f64)> {
        let c = if drum { self.run.world.drum()? } else { SHAFT };
        Some(self.run.carrier_state(c))
    }

    /// Sets the inertial shaft's and the inertial drum's speeds and torques (`shaft` `None`
    /// for a prescribed shaft, `drum` `None` for plates on the housing) now, their angles and every disc's and plate's motion kept:
    /// the relative speeds of the bodies on a carrier jump, as at a prescribed shaft's driven
    /// speed jump, and the state is re-evaluated once (tooth loads, clamp forces). The shaft's
    /// torque is its drive input and the drum's its load input ([`Session::set_inputs`]: the
    /// session must drive them). The kinetic energy a speed jump adds is outside the
    /// session's energy audit (the network books it). Refused: a carrier that is not
    /// inertial, a drum the pack does not have, a value that is not finite.
    pub fn set_carriers(
        &mut self,
        shaft: Option<Carried>,
        drum: Option<Carried>,
    ) -> Result<(), EngineError> {
        let drum_index = self.run.world.drum();
        let mut targets: Vec<_> = shaft.map(|s| (SHAFT, s)).into_iter().collect();
        match (drum, drum_index) {
            (Some(d), Some(c)) => targets.push((c, d)),
            (None, _) => {}
            (Some(_), None) => {
                return Err(EngineError::Unsupported("the pack has no drum".into()));
            }
        }
        for &(c, to) in &targets {
            let k = &self.run.carriers[c];
            if !(to.speed_rad_s.is_finite() && to.torque_n_m.is_finite() && k.is_inertial()) {
                return Err(EngineError::Unsupported(format!(
                    "the {}'s speed and torque can be set only on an inertial carrier, to finite \
                     values ({to:?})",
                    k.name
                )));
            }
        }
        for &(c, to) in &targets {
            let (angle, before) = self.run.carrier_state(c);
            if let Some(th) = self.thermal.as_mut() {
                let j = 1.0 / self.run.carriers[c].inertia().0;
                th.carried(0.5 * j * (to.speed_rad_s - before) * (to.speed_rad_s + before));
            }
            self.run.set_carrier_state(c, angle, to.speed_rad_s);
            let handle = self.run.world.carriers[c].handle;
            self.run.world.physics.bodies[handle]
                .set_angvel(Vector::new(0.0, 0.0, to.speed_rad_s), false);
            self.run.carrier_jumped(c, to.speed_rad_s - before);
        }
        // the torques as driven inputs: re-evaluates the state once, with the jumps above
        self.set_inputs(&Inputs {
            shaft_torque_n_m: shaft.map(|s| s.torque_n_m),
            drum_load_n_m: drum.map(|d| d.torque_n_m),
            ..Inputs::default()
        })
    }

    /// Sets the inertia of the inertial shaft (`drum` false) or drum to `j_kg_m2` (kg m^2,
    /// positive) from now on, its speed kept (a network's clutch locking another body onto the
    /// carrier's rigid group, or releasing one, changes the group's inertia): the pack's model,
    /// the carrier's motion and the couplings' effective masses (the step control's impact
    /// durations) follow. The kinetic energy this changes is outside the session's energy
    /// audit (the network books the lock). Refused: a carrier that is not inertial, a drum the
    /// pack does not have, an inertia that is not finite and > 0.
    pub fn set_carrier_inertia(&mut self, drum: bool, j_kg_m2: f64) -> Result<(), EngineError> {
        let c = if drum {
            self.run
                .world
                .drum()
                .ok_or_else(|| EngineError::Unsupported("the pack has no drum".into()))?
        } else {
            SHAFT
        };
        let super::carriers::Motion::Inertial { j, damping } = self.run.carriers[c].motion else {
            return Err(EngineError::Unsupported(format!(
                "the {} is not a body of its own: it has no inertia to set",
                self.run.carriers[c].name
            )));
        };
        if !(j_kg_m2.is_finite() && j_kg_m2 > 0.0) {
            return Err(EngineError::Unsupported(format!(
                "carrier inertia {j_kg_m2} kg m^2: must be finite and > 0"
            )));
        }
        if j_kg_m2 == j {
            return Ok(());
        }
        let w = self.run.carrier_state(c).1;
        if let Some(th) = self.thermal.as_mut() {
            th.carried(0.5 * (j_kg_m2 - j) * w * w);
        }
        self.run.carriers[c].motion = super::carriers::Motion::Inertial {
            j: j_kg_m2,
            damping,
        };
        let pack = std::sync::Arc::make_mut(&mut self.run.pack);
        if drum {
            if let Some(d) = pack.drum.as_mut() {
                d.inertia_kg_m2 = j_kg_m2;
            }
        } else if let clutchpack_model::Shaft::Inertial { inertia_kg_m2, .. } = &mut pack.shaft {
            *inertia_kg_m2 = j_kg_m2;
        }
        self.run.refresh_effective_masses();
        Ok(())
    }

    /// The drive's work since t = 0 up to now, J (a prescribed shaft's: the teeth's torque on
    /// the discs on its turn; the energy audit's `drive_work_j` as the run goes).
    pub fn drive_work_so_far_j(&self) -> f64 {
        self.run.energy.so_far().drive_work_j
    }

    /// Every tooth contact open now, as it would close at the session's time (its peak the
    /// largest so far; `disc` the coupling's index, discs then plates), left open.
    pub fn open_impacts(&self) -> Vec<clutchpack_model::ImpactEvent> {
        self.run.events.open(self.run.t).collect()
    }

    /// The stack's friction interfaces now (empty without a stack): what
    /// [`Session::snapshot`] holds of them, without the bodies' sample.
    pub fn interfaces(&self) -> Vec<clutchpack_model::InterfaceSample> {
        self.run.stack.as_ref().map_or(Vec::new(), |s| s.samples())
    }

    /// A thermal run's temperatures as at its last thermal window's end, K: every disc's,
    /// then every plate's, then the oil's (`None`: an isothermal run).
    pub fn temperatures_k(&self) -> Option<&[f64]> {
        self.thermal.as_ref().map(|th| th.temperatures_k())
    }

    /// Holds the piston's pressure at `pressure_pa` (Pa) from now on, in place of the pack's
    /// schedule (a network's input, `NetworkInput::PackPressure`): as a driven pressure of a
    /// pack session ([`Session::set_inputs`]), without the session having been started with
    /// it driven, so that the scene's schedule runs until the first value is held. Refused: a
    /// pack without a stack, a pressure that is not finite and >= 0.
    pub fn hold_pressure(&mut self, pressure_pa: f64) -> Result<(), EngineError> {
        if self.run.pack.stack.is_none() {
            return Err(EngineError::Unsupported(
                "the pack has no piston (no stack)".into(),
            ));
        }
        if !(pressure_pa.is_finite() && pressure_pa >= 0.0) {
            return Err(EngineError::Unsupported(format!(
                "piston pressure {pressure_pa} Pa: must be finite and >= 0"
            )));
        }
        self.apply_inputs(&Inputs {
            piston_pressure_pa: Some(pressure_pa),
            ..Inputs::default()
        });
        Ok(())
    }

    /// Holds the prescribed shaft's speed at `speed_rad_s` (rad/s) from now on, from its
    /// angle now, in place of its profile (a network's input, `NetworkInput::Speed`, on the
    /// body carrying the discs): as a driven shaft speed of a pack session
    /// ([`Session::set_inputs`]), without the session having been started with it driven, so
    /// that the profile runs until the first value is held. Refused: an inertial shaft, a
    /// speed that is not finite.
    pub fn hold_shaft_speed(&mut self, speed_rad_s: f64) -> Result<(), EngineError> {
        if !matches!(self.run.pack.shaft, clutchpack_model::Shaft::Prescribed(_)) {
            return Err(EngineError::Unsupported(
                "the pack's shaft is inertial: its speed cannot be held".into(),
            ));
        }
        if !speed_rad_s.is_finite() {
            return Err(EngineError::Unsupported(format!(
                "shaft speed {speed_rad_s} rad/s: must be finite"
            )));
        }
        self.apply_inputs(&Inputs {
            shaft_speed_rad_s: Some(speed_rad_s),
            ..Inputs::default()
        });
        Ok(())
    }
}
