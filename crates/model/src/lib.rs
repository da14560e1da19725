//! # clutchpack_model
//!
//! The physics of clutchpack as pure functions and plain types: spline geometry, tooth force
//! laws, shaft drives, impact events, and the engine interface. No engine, no I/O.
//!
//! # Conventions
//! - SI units everywhere: m, s, kg, N, rad, Pa. Names of quantities that cross a boundary
//!   carry their unit (`backlash_m`, `viscosity_pa_s`).
//! - All bodies rotate about the shaft axis (+z in the multibody engine); positive rotation is
//!   the shaft's running direction.
//! - `phi = theta_shaft - theta_disc` is the relative angle of a coupling; the free play is
//!   `|phi| <= g0 = d / (2R)`.
//! - Flanks: the **shaft leads** when `phi > g0`; the per-tooth load is then **negative** (the
//!   paper's "negative impact load"). The **disc leads** when `phi < -g0`; the load is
//!   **positive**. The torque on the disc is `-n F Rb`, on the shaft `+n F Rb`.
//! - Loads are **per tooth**: a coupling's `n` teeth carry `n F` along their lines of action.
//! - Penetration `delta` and closing speed `v_n` are measured along the line of action
//!   (tangent to the base circle `Rb = R cos(alpha)`); `v_n > 0` while closing.
//!
//! # References
//! - Hu Z., Wang S., Song M., Xu Y., Ning K., *The influence of oil film thickness on the gear
//!   impact dynamics of friction disc*. Eqs (1)-(2): Hertz law with impact damping; (3) drive;
//!   (4)-(5) shaft and disc; (6) the law in angles; (7)-(10) the oil film. Cited in code as
//!   `// Hu et al. eq (N)`.
//! - The project's MODEL.md (copied into `docs/MODEL.md`): the interpretation of the paper used
//!   here (film compression as a length, dv held per contact event, the parameters the paper
//!   omits).
//! - Brancati R., Rocca E., Russo R., gear-rattle squeeze-film model (the `squeeze` law).
//! - Cameron A., *Basic Lubrication Theory*: the leakage coefficient `beta`.

#![warn(missing_docs)]

pub mod cases;
pub mod clutch;
pub mod drive;
pub mod fatigue;
pub mod impact;
pub mod law;
pub mod pack;
pub mod spline;
pub mod stream;

pub use clutch::{
    DrumModel, FrictionCurve, InterfaceSample, OpenGap, Piston, PressureProfile, StackModel,
};
pub use drive::{Harmonic, Shaft, ShaftExcitation, SpeedProfile, Table, TableError};
pub use fatigue::{FatigueParams, Material, MinerRule, ToothForm};
pub use impact::{detect_impacts, parabolic_peak, ImpactEvent, ImpactTracker};
pub use law::{ContactState, Engagement, Hertz, LawKind, OilFilm, ToothLaw};
pub use pack::{
    annulus_inner_radius_m, annulus_outer_radius_m, DiscModel, NonTorsional, PackModel,
};
pub use spline::{Flank, SplineGeometry, ToothKinematics};
pub use stream::{
    Collector, DiscSample, Engine, EngineError, NullObserver, Observer, RunStats, Sample,
};

/// Closed-form peak load of one free, undamped impact (MODEL.md section 4):
/// `F_max = k^(2/5) (5/4 m_eff v0^2)^(3/5)` in N, for stiffness `k` (N/m^1.5), effective mass
/// `m_eff` (kg) and closing speed `v0` (m/s). The rebound speed equals `v0`.
pub fn free_impact_peak_n(k: f64, m_eff_kg: f64, v0_m_s: f64) -> f64 {
    k.powf(0.4) * (1.25 * m_eff_kg * v0_m_s * v0_m_s).powf(0.6)
}

/// Closed-form maximum compression of one free, undamped impact in m:
/// `s_max = (5/4 m_eff v0^2 / k)^(2/5)`.
pub fn free_impact_compression_m(k: f64, m_eff_kg: f64, v0_m_s: f64) -> f64 {
    (1.25 * m_eff_kg * v0_m_s * v0_m_s / k).powf(0.4)
}
