//! The stick/slip rule of a driveline's lumped clutches, once for both engines (MODEL.md
//! section 8; the rules of Modelica's `PartialFriction`, which its `Clutch` and `Brake`
//! extend): the mode each clutch enters at an event, and which locked clutch is released
//! when the torque that holds a rigid group exceeds a static limit. The engines differ only
//! in how they find the instant (the reference engine locates it as an event, the multibody
//! engine lands its step on it) and in how they compute the holding torques; the rule is
//! this.

use super::{ClutchMode, LumpedClutch, Network};

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
/// A one-way clutch ([`LumpedClutch::one_way`]) keeps `w_rel >= 0`: at or below its zero
/// (within the scale) it is tried locked whatever its normal force (the freewheel), above it
/// it slips forward under a normal force and is free without one.
pub fn entered_mode(
    clutch: &LumpedClutch,
    before: Option<ClutchMode>,
    normal_n: f64,
    w_rel_rad_s: f64,
    scale_rad_s: f64,
    slip_ended: bool,
) -> ClutchMode {
    if clutch.one_way {
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
/// [`LumpedClutch::margin_n_m`]), with the mode it is released to: slipping towards its
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
        let Some(cl) = net.couplings[k].clutch() else {
            continue;
        };
        let over = -cl.margin_n_m(torque_n_m[k], cl.normal_force_n(t));
        if over > 0.0 && worst.is_none_or(|(_, o)| over > o) {
            worst = Some((k, over));
        }
    }
    worst.map(|(k, _)| {
        let cl = net.couplings[k].clutch().expect("only clutches lock");
        let to = if cl.one_way && cl.normal_force_n(t) <= 0.0 {
            ClutchMode::Free
        } else if cl.one_way || torque_n_m[k] > 0.0 {
            ClutchMode::Slipping(1)
        } else {
            ClutchMode::Slipping(-1)
        };
        (k, to)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
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
            entered_mode(&c, Some(Free), 0.0, 1e-12, 1e-10, false),
            Locked
        );
        assert_eq!(entered_mode(&c, Some(Free), 0.0, 2.0, 1e-10, false), Free);
        assert_eq!(
            entered_mode(&c, Some(Free), 5.0, 2.0, 1e-10, false),
            Slipping(1)
        );
        assert_eq!(entered_mode(&c, None, 5.0, -2.0, 1e-10, false), Locked);
        assert_eq!(
            entered_mode(&c, Some(Locked), 0.0, 3.0, 1e-10, false),
            Locked
        );
        // the freewheel holds any torque <= 0 on a; the clutch up to its limit above it
        assert!(c.margin_n_m(-1e6, 0.0) > 0.0 && c.margin_n_m(1e-9, 0.0) < 0.0);
        assert!((c.margin_n_m(0.2, 1.0) - 0.3).abs() < 1e-15);
    }

    #[test]
    fn modes_follow_modelica_clutch() {
        let c = clutch(false);
        assert_eq!(entered_mode(&c, Some(Locked), 0.0, 1.0, 1e-10, false), Free);
        assert_eq!(
            entered_mode(&c, None, 5.0, -2.0, 1e-10, false),
            Slipping(-1)
        );
        assert_eq!(
            entered_mode(&c, Some(Free), 5.0, 1e-12, 1e-10, false),
            Locked
        );
        assert_eq!(
            entered_mode(&c, Some(Slipping(1)), 5.0, 2.0, 1e-10, false),
            Slipping(1)
        );
        assert_eq!(
            entered_mode(&c, Some(Slipping(1)), 5.0, 2.0, 1e-10, true),
            Locked
        );
        assert_eq!(
            entered_mode(&c, Some(Slipping(1)), 5.0, -1e-3, 1e-10, false),
            Locked
        );
        assert_eq!(
            entered_mode(&c, Some(Locked), 5.0, 3.0, 1e-10, false),
            Locked
        );
    }
}
