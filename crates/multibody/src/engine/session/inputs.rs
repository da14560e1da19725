//! A driven [`MultibodySession`]'s inputs applied at its time (module docs of `session.rs`,
//! "Inputs"): the held shaft speed or drive torque, the drum's load, the piston's pressure.

use super::MultibodySession;
use crate::engine::carriers::{External, Motion};
use crate::engine::state::shaft_accel_bound;
use crate::world::SHAFT;
use clutchpack_model::session::Inputs;
use clutchpack_model::{PressureProfile, Shaft, ShaftExcitation, SpeedProfile};
use std::sync::Arc;

impl MultibodySession {
    /// Applies `inputs` (checked) at the current time and re-evaluates what they change.
    pub(in crate::engine) fn apply_inputs(&mut self, inputs: &Inputs) {
        let multirate = self.is_multirate();
        let run = &mut self.run;
        let t = run.t;
        let mut shaft_jump = 0.0;
        if inputs.shaft_speed_rad_s.is_some()
            || inputs.shaft_speed_slope_rad_s2.is_some()
            || inputs.shaft_speed_curvature_rad_s3.is_some()
        {
            let (angle, speed) = run.carrier_state(SHAFT);
            let w = inputs.shaft_speed_rad_s.unwrap_or(speed);
            let held = SpeedProfile::Held {
                t0_s: t,
                angle0_rad: angle,
                speed_rad_s: w,
                accel_rad_s2: inputs.shaft_speed_slope_rad_s2.unwrap_or(0.0),
                jerk_rad_s3: inputs.shaft_speed_curvature_rad_s3.unwrap_or(0.0),
            };
            Arc::make_mut(&mut run.pack).shaft = Shaft::Prescribed(held.clone());
            let shaft = &mut run.carriers[SHAFT];
            shaft.motion = Motion::Prescribed(Arc::new(held));
            shaft_jump = w - shaft.speed;
            shaft.speed = w;
        }
        if inputs.shaft_torque_n_m.is_some() || inputs.shaft_torque_slope_n_m_s.is_some() {
            let before = run.drive_torque(t);
            let torque = inputs.shaft_torque_n_m.unwrap_or(before);
            let shaft = &mut run.carriers[SHAFT];
            if shaft.switch.is_none_or(|(ts, _)| ts != t) {
                shaft.switch = Some((t, before));
            }
            if let Shaft::Inertial { excitation, .. } = &mut Arc::make_mut(&mut run.pack).shaft {
                let initial_speed_rad_s = excitation.initial_speed_rad_s();
                *excitation = ShaftExcitation::Held {
                    t0_s: t,
                    torque_n_m: torque,
                    rate_n_m_s: inputs.shaft_torque_slope_n_m_s.unwrap_or(0.0),
                    initial_speed_rad_s,
                };
            }
        }
        if let Some(load) = inputs.drum_load_n_m {
            if let Some(d) = run.world.drum() {
                let drum = &mut run.carriers[d];
                if let External::Load(before) = drum.external {
                    if drum.switch.is_none_or(|(ts, _)| ts != t) {
                        drum.switch = Some((t, before));
                    }
                }
                drum.external = External::Load(load);
            }
            if let Some(d) = Arc::make_mut(&mut run.pack).drum.as_mut() {
                d.load_torque_n_m = load;
            }
        }
        if let Some(pressure_pa) = inputs.piston_pressure_pa {
            let p = PressureProfile::Constant { pressure_pa };
            if let Some(st) = Arc::make_mut(&mut run.pack).stack.as_mut() {
                st.piston.pressure = p.clone();
                // A held pressure over the return spring may push from now on: the multirate
                // scheme integrates the clamped stack as one system from this call (and for
                // the rest of the run, as after a scene's ramp starts; a later release is the
                // clamped system's open faces). Below the spring the hand-over stays where it
                // was (never, or a call that pushed before).
                self.clamped_from_s = self.clamped_from_s.min(st.piston.open_until_s().max(t));
            }
            if let Some(s) = run.stack.as_mut() {
                s.set_pressure(p);
            }
        }
        run.carriers[SHAFT].drive_bound = shaft_accel_bound(&run.pack.shaft);
        run.input_changed(SHAFT, shaft_jump, multirate);
    }
}
