//! The typed model of a pack as the engines see it: a shaft and its disc couplings.

use crate::drive::Shaft;
use crate::law::ToothLaw;
use crate::spline::SplineGeometry;
use serde::{Deserialize, Serialize};

/// One friction disc on the shaft spline (Hu et al. eq 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscModel {
    /// Name used in tables, plots and recordings.
    pub name: String,
    /// Spline of its coupling to the shaft.
    pub spline: SplineGeometry,
    /// Tooth force law of that coupling.
    pub law: ToothLaw,
    /// Rotational inertia `J2` in kg m^2 (> 0).
    pub inertia_kg_m2: f64,
    /// Oil drag `C2` in N m s/rad (>= 0): drag torque `-C2 omega_disc` (eq 5).
    pub drag_n_m_s_rad: f64,
    /// Initial relative angle `phi(0) = theta_s - theta_d` in rad (|phi| < g0 - h_o / Rb).
    pub initial_rel_angle_rad: f64,
    /// Initial relative speed `omega_s(0) - omega_d(0)` in rad/s.
    pub initial_rel_speed_rad_s: f64,
}

/// A shaft and the discs coupled to it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PackModel {
    /// The shaft.
    pub shaft: Shaft,
    /// The discs, each on its own spline coupling.
    pub discs: Vec<DiscModel>,
}
