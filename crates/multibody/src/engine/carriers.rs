//! The carriers of the spline couplings as data: one table of carrier bodies (the housing,
//! the shaft, the drum), each with how it moves (fixed, prescribed, inertial with its inertia
//! and damping), its external torque (a drive, a load, none) and its angle and speed; each
//! coupling names its carrier by an index into the table (`World::carrier_of`), and the
//! schemes iterate over the table instead of matching roles.

use crate::world::Carrier;
use clutchpack_model::{CouplingLoads, SpeedProfile};
use std::sync::Arc;

/// How a carrier body moves.
#[derive(Debug, Clone)]
pub(super) enum Motion {
    /// At rest (the housing): angle and speed 0.
    Fixed,
    /// Follows a speed profile exactly (the shaft, eq 3); shared (`Arc`) so that a loop can
    /// hold it while it writes the run's state.
    Prescribed(Arc<SpeedProfile>),
    /// A body: `J w' = T_ext(t) - C w - sum T_k` over the couplings it carries (the shaft, eq 4;
    /// the drum), `J` its inertia about the axis (kg m^2, > 0) and `C` its damping
    /// (N m s/rad, >= 0).
    Inertial { j: f64, damping: f64 },
}

/// The external torque on an inertial carrier, positive along the positive rotation, and
/// where the energy audit books its work.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum External {
    /// None.
    None,
    /// The pack's drive torque on an inertial shaft (Hu et al. eq 4, the pack's excitation,
    /// `Shaft::drive_torque_n_m`), a known function of time; its work is the drive's.
    Drive,
    /// A load held between inputs (the drum's), N m; its work is the load's.
    Load(f64),
}

/// One carrier body of a run: what the schemes read and write of it.
#[derive(Debug, Clone)]
pub(super) struct CarrierRun {
    /// How it moves.
    pub(super) motion: Motion,
    /// Its external torque.
    pub(super) external: External,
    /// Bound of the acceleration its profile (prescribed) or its drive (`External::Drive`)
    /// alone gives it, rad/s^2 (>= 0); 0 for the housing and for a carrier under a load, whose
    /// bound is the load over `J`, formed where it is used.
    pub(super) drive_bound: f64,
    /// Whether the shared step integrates its external torque exactly as a function of time
    /// (`Run::external_impulse`: a drive, a driven load) rather than through the polynomial
    /// kick of its other loads (a scene's constant load: byte-identical runs need that).
    pub(super) exact: bool,
    /// A driven external torque changed at this time, s, from this value, N m: the torque
    /// before it, for the past half of the kick of the step that ends there. `None`: the
    /// torque holds for all `t`.
    pub(super) switch: Option<(f64, f64)>,
    /// What it is called in messages.
    pub(super) name: &'static str,
    /// Unwrapped angle, rad, and speed at `t` (synchronised with the poses), rad/s; positive
    /// along the positive rotation.
    pub(super) angle: f64,
    pub(super) speed: f64,
}

impl CarrierRun {
    /// Its inverse inertia, 1/(kg m^2), and damping, N m s/rad: the model's (not rapier's
    /// inertia, which is 0 until its first step computes the body's mass properties). A
    /// carrier that is not inertial has neither.
    pub(super) fn inertia(&self) -> (f64, f64) {
        match self.motion {
            Motion::Inertial { j, damping } => (1.0 / j, damping),
            _ => unreachable!("not an inertial carrier"),
        }
    }

    /// Whether it is a body of its own (`Motion::Inertial`).
    pub(super) fn is_inertial(&self) -> bool {
        matches!(self.motion, Motion::Inertial { .. })
    }
}

/// The torque of the pack's couplings between bodies (MODEL.md section 8, `loads`) on the
/// carrier of role `role`, N m, positive along the positive rotation: they join the shaft and
/// the drum (`PackBody`), never the housing.
pub(super) fn joined_torque(loads: &CouplingLoads, role: Carrier) -> f64 {
    match role {
        Carrier::Shaft => loads.shaft_n_m,
        Carrier::Drum => loads.drum_n_m,
        Carrier::Housing => 0.0,
    }
}
