//! The stick/slip rule of a driveline's lumped clutches, once for both engines (MODEL.md
//! section 8; the rules of Modelica's `PartialFriction`, which its `Clutch` and `Brake`
//! extend): the mode each clutch enters at an event, and which locked clutch is released
//! when the torque that holds a rigid group exceeds a static limit. The engines differ only
//! in how they find the instant (the reference engine locates it as an event, the multibody
//! engine lands its step on it) and in how they compute the holding torques; the rule is
//! this.

use super::{ClutchMode, Mode, Network, SlipEnd};

/// The mode a clutch (`one_way`: a one-way clutch) enters at an event from `before` under the
/// normal force `normal_n` (N), at the speeds `w_a`, `w_b` (rad/s), the slip's end found as
/// `end` (how each engine finds it): [`entered_mode`], with the engine's zero of slip `scale = 1e-10 (1 + |w_a| + |w_b|)`
/// rad/s. The reference engine ([`SlipEnd::Located`]) takes the slip as ended when the
/// clutch's guard crossed and the slip is the part of it that did (`s w_rel <= fn` while
/// slipping; a free one-way clutch's `w_rel` below its engagement); the multibody engine
/// ([`SlipEnd::Landed`]) when its step landed within the scale of the slip's zero.
pub fn settled_mode(
    one_way: bool,
    normal_n: f64,
    before: Mode,
    w_a_rad_s: f64,
    w_b_rad_s: f64,
    end: SlipEnd,
) -> ClutchMode {
    let w_rel = w_b_rad_s - w_a_rad_s;
    let scale = 1e-10 * (1.0 + w_a_rad_s.abs() + w_b_rad_s.abs());
    let f = normal_n;
    let slip_ended = match end {
        SlipEnd::Located { crossed } => {
            crossed
                && match before {
                    Some(ClutchMode::Slipping(s)) => f64::from(s) * w_rel <= f,
                    Some(ClutchMode::Free) => {
                        one_way && w_rel <= if f > 0.0 { -f } else { 1.0 + f.abs() }
                    }
                    _ => false,
                }
        }
        SlipEnd::Landed => {
            matches!(before, Some(ClutchMode::Slipping(s)) if f64::from(s) * w_rel <= scale)
        }
    };
    entered_mode(one_way, before, f, w_rel, scale, slip_ended)
}

/// The mode a clutch enters at an event at `t` from the mode `before` (`None` before its
/// first settling), under the normal force `normal_n` (N) at the relative speed `w_rel`
/// (`w_b - w_a`, rad/s):
/// - free while `fn <= 0`;
/// - a free clutch that engages slips in the sense of `w_rel` when `|w_rel| > scale`
///   (rad/s: the engine's zero of slip), and is tried locked otherwise;
/// - a slipping clutch is tried locked when `slip_ended` (the engine found its slip
///   `s w_rel` at zero: located, or within its scale) or its slip has changed sign, and
///   keeps slipping otherwise;
/// - a locked clutch stays locked (it is released by [`furthest_over`] when the torque that
///   holds it exceeds its static limit).
///
/// A one-way clutch (`one_way`, [`super::LumpedClutch::one_way`]) keeps `w_rel >= 0`: at or below its zero
/// (within the scale) it is tried locked whatever its normal force (the freewheel), above it
/// it slips forward under a normal force and is free without one.
pub fn entered_mode(
    one_way: bool,
    before: Option<ClutchMode>,
    normal_n: f64,
    w_rel_rad_s: f64,
    scale_rad_s: f64,
    slip_ended: bool,
) -> ClutchMode {
    if one_way {
        let at_zero =
            w_rel_rad_s <= scale_rad_s || slip_ended || before == Some(ClutchMode::Locked);
        return if at_zero {
            ClutchMode::Locked
        } else if normal_n > 0.0 {
            ClutchMode::Slipping(1)
        } else {
            ClutchMode::Free
        };
    }
    if normal_n <= 0.0 {
        return ClutchMode::Free;
    }
    match before {
        Some(ClutchMode::Free) | None => {
            if w_rel_rad_s.abs() > scale_rad_s {
                ClutchMode::Slipping(if w_rel_rad_s > 0.0 { 1 } else { -1 })
            } else {
                ClutchMode::Locked
            }
        }
        Some(ClutchMode::Slipping(s)) => {
            if slip_ended || f64::from(s) * w_rel_rad_s <= 0.0 {
                ClutchMode::Locked
            } else {
                ClutchMode::Slipping(s)
            }
        }
        Some(ClutchMode::Locked) => ClutchMode::Locked,
    }
}

/// The locked clutch furthest over its static limit `peak mu(0) cgeo fn` at `t` (s) under the
/// holding torques `torque_n_m` (N m, each coupling's on its body `a`;
/// [`super::ElementLaw::locked_margin_n_m`]), with the mode it is released to: slipping towards its
/// torque (`+1` when the torque on `a` is positive; a one-way clutch forward, or free without
/// a normal force); `None` when every locked clutch holds. The engines release it and solve again until none is over (Modelica's
/// startForward / startBackward, one at a time).
pub fn furthest_over(
    net: &Network,
    modes: &[Option<ClutchMode>],
    torque_n_m: &[f64],
    t: f64,
) -> Option<(usize, ClutchMode)> {
    let mut worst: Option<(usize, f64)> = None;
    for (k, mode) in modes.iter().enumerate() {
        if *mode != Some(ClutchMode::Locked) {
            continue;
        }
        let Some(margin) = net.couplings[k].law().locked_margin_n_m(t, torque_n_m[k]) else {
            continue;
        };
        let over = -margin;
        if over > 0.0 && worst.is_none_or(|(_, o)| over > o) {
            worst = Some((k, over));
        }
    }
    worst.and_then(|(k, _)| {
        let to = net.couplings[k].law().released_mode(t, torque_n_m[k])?;
        Some((k, to))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::LumpedClutch;
    use ClutchMode::{Free, Locked, Slipping};

    /// Modelica's transitions: free without force; engaging at speed slips, at zero slip
    /// locks; a slip that ends or reverses locks; a lock stays until released.
    fn clutch(one_way: bool) -> LumpedClutch {
        LumpedClutch {
            mu_table: vec![(0.0, 0.5)],
            peak: 1.0,
            cgeo_m: 1.0,
            fn_max_n: 1.0,
            force: crate::network::Signal::Constant(1.0),
            one_way,
        }
    }

    /// A one-way clutch (Modelica's `OneWayClutch`): at zero slip it locks even without a
    /// normal force (the freewheel); forward it slips under a force and is free without one;
    /// it never slips backwards.
    #[test]
    fn one_way_clutch_locks_at_zero_and_never_slips_backwards() {
        let c = clutch(true);
        assert_eq!(
            entered_mode(c.one_way, Some(Free), 0.0, 1e-12, 1e-10, false),
            Locked
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Free), 0.0, 2.0, 1e-10, false),
            Free
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Free), 5.0, 2.0, 1e-10, false),
            Slipping(1)
        );
        assert_eq!(
            entered_mode(c.one_way, None, 5.0, -2.0, 1e-10, false),
            Locked
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Locked), 0.0, 3.0, 1e-10, false),
            Locked
        );
        // the freewheel holds any torque <= 0 on a; the clutch up to its limit above it
        assert!(c.margin_n_m(-1e6, 0.0) > 0.0 && c.margin_n_m(1e-9, 0.0) < 0.0);
        assert!((c.margin_n_m(0.2, 1.0) - 0.3).abs() < 1e-15);
    }

    #[test]
    fn modes_follow_modelica_clutch() {
        let c = clutch(false);
        assert_eq!(
            entered_mode(c.one_way, Some(Locked), 0.0, 1.0, 1e-10, false),
            Free
        );
        assert_eq!(
            entered_mode(c.one_way, None, 5.0, -2.0, 1e-10, false),
            Slipping(-1)
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Free), 5.0, 1e-12, 1e-10, false),
            Locked
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Slipping(1)), 5.0, 2.0, 1e-10, false),
            Slipping(1)
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Slipping(1)), 5.0, 2.0, 1e-10, true),
            Locked
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Slipping(1)), 5.0, -1e-3, 1e-10, false),
            Locked
        );
        assert_eq!(
            entered_mode(c.one_way, Some(Locked), 5.0, 3.0, 1e-10, false),
            Locked
        );
    }
}
