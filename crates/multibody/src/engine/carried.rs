//! A pack session whose carriers are a driveline network's bodies (`crate::network`, MODEL.md
//! section 8): the network reads the shaft's and the drum's motion at each of its steps and
//! sets their speeds back to its own when they differ (another pack's reaction on the same
//! rigid group, a clutch locking), between the session's calls.

use super::session::MultibodySession;
use crate::world::SHAFT;
use clutchpack_model::EngineError;
use rapier3d_f64::prelude::Vector;

impl MultibodySession {
    /// The carrier `drum` names (`false`: the shaft, `true`: the drum): its index in the
    /// run's table, `None` for a drum the pack does not have.
    fn carrier_index(&self, drum: bool) -> Option<usize> {
        if drum {
            self.run.world.drum()
        } else {
            Some(SHAFT)
        }
    }

    /// The shaft's (`drum` false) or the drum's unwrapped angle (rad) and speed (rad/s) now,
    /// positive along the positive rotation; `None` for a drum the pack does not have.
    pub fn carrier_motion(&self, drum: bool) -> Option<(f64, f64)> {
        self.carrier_index(drum).map(|c| self.run.carrier_state(c))
    }

    /// Sets the speed of the inertial shaft (`drum` false) or drum to `speed_rad_s` (rad/s)
    /// now, its angle and every disc's and plate's motion kept: the relative speeds of the
    /// bodies on it jump, as at a prescribed shaft's driven speed jump (the tooth loads and
    /// clamp forces re-evaluated at once). The kinetic energy this adds is outside the
    /// session's energy audit (the network books it). Refused for a carrier that is not
    /// inertial, a drum the pack does not have, or a speed that is not finite.
    pub fn set_carrier_speed(&mut self, drum: bool, speed_rad_s: f64) -> Result<(), EngineError> {
        let Some(c) = self.carrier_index(drum) else {
            return Err(EngineError::Unsupported("the pack has no drum".into()));
        };
        if !speed_rad_s.is_finite() || !self.run.carriers[c].is_inertial() {
            return Err(EngineError::Unsupported(format!(
                "the {}'s speed can be set only on an inertial carrier, to a finite value \
                 ({speed_rad_s} rad/s)",
                self.run.carriers[c].name
            )));
        }
        let (angle, before) = self.run.carrier_state(c);
        let jump = speed_rad_s - before;
        if jump == 0.0 {
            return Ok(());
        }
        self.run.set_carrier_state(c, angle, speed_rad_s);
        let handle = self.run.world.carriers[c].handle;
        self.run.world.physics.bodies[handle].set_angvel(Vector::new(0.0, 0.0, speed_rad_s), false);
        let multirate = self.is_multirate();
        self.run.input_changed(c, jump, multirate);
        Ok(())
    }
}
