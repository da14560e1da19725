//! Time signals of a driveline network (MODEL.md section 8, "Inputs"): a drive torque, a
//! clutch's normalized normal force, a schedule. Each is a pure function of time with the
//! instants where it (or its slope) jumps, which the engines land their steps on.

use crate::drive::Table;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A signal `y(t)`; its unit is its owner's (N m for a torque, 1 for a normalized force).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Signal {
    /// `y = value`.
    Constant(f64),
    /// `y = offset` before `start_s`, `offset + height` from `start_s` on (Modelica's
    /// `Blocks.Sources.Step`).
    Step {
        /// Value before the step.
        offset: f64,
        /// Jump at `start_s`.
        height: f64,
        /// Instant of the jump, s.
        start_s: f64,
    },
    /// `y = offset` before `start_s`, then rising linearly by `height` over `duration_s`, then
    /// held (Modelica's `Blocks.Sources.Ramp`; a clutch's fill and apply).
    Ramp {
        /// Value before the ramp.
        offset: f64,
        /// Rise over the ramp (negative: a fall).
        height: f64,
        /// Start of the ramp, s.
        start_s: f64,
        /// Length of the ramp, s (> 0).
        duration_s: f64,
    },
    /// `y = offset + amplitude sin(2 pi f (t - start_s) + phase)` from `start_s` on, `offset`
    /// before (Modelica's `Blocks.Sources.Sine`).
    Sine {
        /// Mean value.
        offset: f64,
        /// Amplitude.
        amplitude: f64,
        /// Frequency, Hz (> 0).
        frequency_hz: f64,
        /// Phase at `start_s`, rad.
        phase_rad: f64,
        /// Start, s.
        start_s: f64,
    },
    /// A table of `(t, y)` rows, linear or held between them, held beyond its ends.
    Table(Table),
    /// The sum of several signals (a mean torque with firing-order harmonics).
    Sum(Vec<Signal>),
}

impl Signal {
    /// The value at `t` (s); right-continuous at a jump (a step's value at `start_s` is
    /// `offset + height`).
    pub fn value(&self, t: f64) -> f64 {
        match self {
            Signal::Constant(v) => *v,
            Signal::Step {
                offset,
                height,
                start_s,
            } => {
                if t >= *start_s {
                    offset + height
                } else {
                    *offset
                }
            }
            Signal::Ramp {
                offset,
                height,
                start_s,
                duration_s,
            } => {
                let x = ((t - start_s) / duration_s).clamp(0.0, 1.0);
                offset + height * x
            }
            Signal::Sine {
                offset,
                amplitude,
                frequency_hz,
                phase_rad,
                start_s,
            } => {
                if t < *start_s {
                    *offset
                } else {
                    offset + amplitude * (TAU * frequency_hz * (t - start_s) + phase_rad).sin()
                }
            }
            Signal::Table(table) => table.value(t),
            Signal::Sum(terms) => terms.iter().map(|s| s.value(t)).sum(),
        }
    }

    /// The instants (s) where the value or its slope jumps, in any order, with repeats: an
    /// engine lands a step on each, so that no step straddles a discontinuity.
    pub fn breakpoints(&self, out: &mut Vec<f64>) {
        match self {
            Signal::Constant(_) => {}
            Signal::Step { start_s, .. } | Signal::Sine { start_s, .. } => out.push(*start_s),
            Signal::Ramp {
                start_s,
                duration_s,
                ..
            } => {
                out.push(*start_s);
                out.push(start_s + duration_s);
            }
            Signal::Table(table) => out.extend_from_slice(&table.t_s),
            Signal::Sum(terms) => terms.iter().for_each(|s| s.breakpoints(out)),
        }
    }

    /// Whether every number in the signal is finite and its lengths positive (the scene
    /// validation reports the key; this is the model's own guard).
    pub fn is_valid(&self) -> bool {
        match self {
            Signal::Constant(v) => v.is_finite(),
            Signal::Step {
                offset,
                height,
                start_s,
            } => [offset, height, start_s].iter().all(|v| v.is_finite()),
            Signal::Ramp {
                offset,
                height,
                start_s,
                duration_s,
            } => {
                [offset, height, start_s].iter().all(|v| v.is_finite())
                    && duration_s.is_finite()
                    && *duration_s > 0.0
            }
            Signal::Sine {
                offset,
                amplitude,
                frequency_hz,
                phase_rad,
                start_s,
            } => {
                [offset, amplitude, phase_rad, start_s]
                    .iter()
                    .all(|v| v.is_finite())
                    && frequency_hz.is_finite()
                    && *frequency_hz > 0.0
            }
            Signal::Table(_) => true,
            Signal::Sum(terms) => terms.iter().all(Signal::is_valid),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each kind's value at its defining instants, and its breakpoints.
    #[test]
    fn values_and_breakpoints() {
        let step = Signal::Step {
            offset: 0.0,
            height: 1.0,
            start_s: 0.4,
        };
        assert_eq!(step.value(0.399_999), 0.0);
        assert_eq!(step.value(0.4), 1.0);
        let ramp = Signal::Ramp {
            offset: 1.0,
            height: -1.0,
            start_s: 1.0,
            duration_s: 0.5,
        };
        assert_eq!(ramp.value(0.0), 1.0);
        assert_eq!(ramp.value(1.25), 0.5);
        assert_eq!(ramp.value(3.0), 0.0);
        // Modelica's CoupledClutches: sin2(amplitude = 1, f = 0.2, phase = pi/2) is zero at
        // t = 1.25 s
        let sine = Signal::Sine {
            offset: 0.0,
            amplitude: 1.0,
            frequency_hz: 0.2,
            phase_rad: std::f64::consts::FRAC_PI_2,
            start_s: 0.0,
        };
        assert_eq!(sine.value(0.0), 1.0);
        assert!(sine.value(1.25).abs() < 1e-15);
        let sum = Signal::Sum(vec![Signal::Constant(2.0), step.clone(), ramp.clone()]);
        assert_eq!(sum.value(1.25), 3.5);
        let mut bp = Vec::new();
        sum.breakpoints(&mut bp);
        assert_eq!(bp, vec![0.4, 1.0, 1.5]);
        assert!(sum.is_valid());
        assert!(!Signal::Constant(f64::NAN).is_valid());
    }

    /// A prescribed body's speed held at `t` (`NetworkInput::Speed`): its profile becomes
    /// `Held` from `t` at the body's angle there (the angle continuous, the speed the value,
    /// exactly); a free body, the fixed body and a value that is not finite are refused with
    /// the body named, the network unchanged.
    #[test]
    fn a_held_speed_keeps_the_angle_and_refuses_what_is_not_prescribed() {
        use crate::network::{Body, Motion, Network, NetworkInput};
        let body = |name: &str, motion| Body {
            name: name.into(),
            inertia_kg_m2: 1.0,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 0.0,
            motion,
            drive: None,
            firing: None,
            road_load: None,
        };
        let profile = crate::SpeedProfile::sine(100.0, 5.0, 30.0);
        let mut net = Network {
            bodies: vec![
                body("motor", Motion::Prescribed(profile.clone())),
                body("load", Motion::Free),
                body("housing", Motion::Fixed),
            ],
            ..Network::default()
        };
        let before = net.clone();
        let angles = [profile.angle(0.01), 0.0, 0.0];
        for (input, value, why) in [
            (
                NetworkInput::Speed(1),
                1.0,
                "body \"load\": its speed cannot be set: it is free",
            ),
            (
                NetworkInput::Speed(2),
                1.0,
                "body \"housing\": its speed cannot be set: it is fixed",
            ),
            (NetworkInput::Speed(0), f64::NAN, "expected a finite number"),
            (NetworkInput::Speed(9), 1.0, "body 9: no such body"),
        ] {
            let e = net.hold_input(input, value, 0.01, &angles).unwrap_err();
            assert!(e.to_string().contains(why), "{e}");
            assert_eq!(net, before);
        }
        net.hold_input(NetworkInput::Speed(0), 120.0, 0.01, &angles)
            .unwrap();
        let held = net.bodies[0].prescribed().unwrap();
        assert_eq!(held.speed(0.01), 120.0);
        assert_eq!(held.angle(0.01), angles[0]);
        assert_eq!(held.speed(0.5), 120.0);
        assert_eq!(held.angle(0.02), angles[0] + 120.0 * (0.02 - 0.01));
    }
}

/// An input of a network that a session's caller may set (MODEL.md section 8, "Inputs"): the
/// value is held from the instant it is set (a zero-order hold) and replaces the scene's
/// signal from then on ([`super::Network::hold_input`]). Both engines' steppers take it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NetworkInput {
    /// The drive torque on body `i`, N m (positive in its sense of rotation; its firing
    /// harmonics, if any, still add to it).
    Drive(usize),
    /// The normal force of the clutch that is coupling `k`, N (>= 0; 0: free).
    ClutchForce(usize),
    /// The piston pressure of the resolved pack that is coupling `k`, Pa (>= 0; its piston
    /// force is `p A - F_return`, MODEL.md section 5).
    PackPressure(usize),
    /// The speed of the prescribed body `i`, rad/s (positive in its sense of rotation): a
    /// one-pack scene's `shaft.speed_rad_s` for a network body (a test rig's motor). Held
    /// from the instant it is set as [`crate::SpeedProfile::Held`] from the body's angle
    /// there, so that its angle stays continuous and its speed jumps to the value.
    Speed(usize),
}

impl NetworkInput {
    /// Its place in a list of inputs: the bodies' (a prescribed body's speed, a drive), then
    /// the clutches' forces, then the packs' pressures (the co-simulation's order).
    pub fn rank(self) -> u8 {
        match self {
            NetworkInput::Drive(_) | NetworkInput::Speed(_) => 0,
            NetworkInput::ClutchForce(_) => 1,
            NetworkInput::PackPressure(_) => 2,
        }
    }
}

impl super::Network {
    /// Replaces the signal of `input` by the constant `value` from `t_s` (s) on (N m for a
    /// drive, N for a clutch's normal force, stored normalized by the clutch's `fn_max_n`,
    /// Pa for a pack's piston pressure, rad/s for a prescribed body's speed, held as
    /// [`crate::SpeedProfile::Held`] from `t_s` and the body's angle there, `angles_rad[i]`,
    /// rad, as [`crate::session::hold_inputs`] holds a pack's shaft): the engines'
    /// `set_input`, which then restart at that instant as at a signal's jump (a prescribed
    /// body's speed in their state set to the value, what follows it moved with it). A value
    /// that is not finite, a negative force, or an input naming a body or coupling that
    /// cannot take it (a speed for a free or fixed body) is refused, the network unchanged.
    pub fn hold_input(
        &mut self,
        input: NetworkInput,
        value: f64,
        t_s: f64,
        angles_rad: &[f64],
    ) -> Result<(), crate::EngineError> {
        let bad = |why: String| Err(crate::EngineError::Unsupported(why));
        if !value.is_finite() {
            return bad(format!("input value {value}: expected a finite number"));
        }
        match input {
            NetworkInput::Drive(i) => {
                let Some(b) = self.bodies.get_mut(i).filter(|b| b.is_free()) else {
                    return bad(format!("body {i}: no turning body takes a drive there"));
                };
                b.drive = Some(Signal::Constant(value));
            }
            NetworkInput::ClutchForce(k) => {
                let Some(super::CouplingKind::Clutch(cl)) =
                    self.couplings.get_mut(k).map(|c| &mut c.kind)
                else {
                    return bad(format!("coupling {k}: not a clutch"));
                };
                if value < 0.0 {
                    return bad(format!("normal force {value} N: expected >= 0"));
                }
                cl.force = Signal::Constant(value / cl.fn_max_n);
            }
            NetworkInput::PackPressure(k) => {
                let stack = match self.couplings.get_mut(k).map(|c| &mut c.kind) {
                    Some(super::CouplingKind::Pack(p)) => p.stack.as_mut(),
                    _ => return bad(format!("coupling {k}: not a resolved pack")),
                };
                let Some(stack) = stack else {
                    return bad(format!("coupling {k}: the pack has no [stack] (no piston)"));
                };
                if value < 0.0 {
                    return bad(format!("piston pressure {value} Pa: expected >= 0"));
                }
                stack.piston.pressure = crate::PressureProfile::Constant { pressure_pa: value };
            }
            NetworkInput::Speed(i) => {
                let Some(b) = self.bodies.get_mut(i) else {
                    return bad(format!("body {i}: no such body"));
                };
                let super::Motion::Prescribed(p) = &mut b.motion else {
                    let what = if b.is_fixed() { "fixed" } else { "free" };
                    return bad(format!(
                        "body \"{}\": its speed cannot be set: it is {what}, not prescribed \
                         (give it [bodies.speed])",
                        b.name
                    ));
                };
                *p = crate::SpeedProfile::Held {
                    t0_s: t_s,
                    angle0_rad: angles_rad.get(i).copied().unwrap_or_else(|| p.angle(t_s)),
                    speed_rad_s: value,
                    accel_rad_s2: 0.0,
                    jerk_rad_s3: 0.0,
                };
            }
        }
        Ok(())
    }
}
