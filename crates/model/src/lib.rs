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
//! ## Two-sided elements: one sign convention
//! Every element that acts between two bodies (a spline coupling, a friction interface) has a
//! side **a** and a side **b**. The project's one convention, as the Modelica Standard
//! Library's for every two-sided element: the relative motion is **b minus a**
//! (`rel = theta_b - theta_a`, `rel' = omega_b - omega_a`), and the torque an element reports
//! is the torque **on b** (a receives the opposite). Each element's reported quantities in it:
//!
//! | element | side a | side b | reported relative motion | reported torque or load |
//! | --- | --- | --- | --- | --- |
//! | spline coupling ([`SplineGeometry`], [`DiscSample`]) | the carrier: shaft for a friction disc, housing or drum for a plate | the disc or plate | `phi = theta_a - theta_b = -rel` (the paper's eq 6 sign, kept so every load matches Hu et al.) | `spline_torque_n_m` on b `= -n F Rb`; per-tooth load `F` **positive when b leads** (`rel > g0`), negative when a leads |
//! | friction interface `m` ([`InterfaceSample`]) | stack body `m` (piston side, [`StackBody::at`]) | stack body `m + 1` | `slip_rad_s = omega_b - omega_a = rel'` | `torque_n_m` on b (opposes `slip` while it slips) |
//! | spring-damper ([`SpringDamper`], [`PackCoupling`]) | its `a` (the shaft in a one-pack scene) | its `b` (the drum) | `dtheta = theta_a - theta_b = -rel` (MODEL.md section 8's sign) | torque on b `k (dtheta - theta_0) + d dtheta'` |
//!
//! So the only exceptions to "b minus a" are the spline's `phi`, which keeps the paper's sign,
//! and the spring-damper's twist, which keeps MODEL.md section 8's;
//! their torques still follow the rule (reported on b). Heat is never negative:
//! `-torque_n_m * slip_rad_s >= 0` for a friction interface, and the coupling's film and
//! impact damping dissipate `>= 0` on either flank.
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
/// Consistency checks of an engine's output stream for the engines' tests (feature
/// `test-support`; not part of the product's interface).
#[cfg(any(test, feature = "test-support"))]
pub mod checks;
pub mod clutch;
pub mod drive;
pub mod fatigue;
pub mod impact;
pub mod law;
pub mod network;
pub mod pack;
pub mod session;
pub mod spline;
pub mod spring;
pub mod stream;
pub mod thermal;

pub use clutch::{
    DrumModel, Face, FrictionCurve, InterfaceSample, OpenGap, Piston, PressureProfile, StackBody,
    StackModel,
};
pub use drive::{Harmonic, LocalProfile, Shaft, ShaftExcitation, SpeedProfile, Table, TableError};
pub use fatigue::{FatigueParams, Material, MinerRule, ToothForm};
pub use impact::{detect_impacts, parabolic_peak, ImpactEvent, ImpactTracker};
pub use law::{ContactState, Engagement, Hertz, LawKind, OilFilm, ToothLaw};
pub use pack::{
    annulus_inner_radius_m, annulus_outer_radius_m, ensemble_angle_rad, BodyMotion, Carrier,
    CouplingLoads, DiscModel, NonTorsional, PackBody, PackCoupling, PackCouplingKind, PackModel,
};
pub use session::Engine;
pub use spline::{Flank, SplineGeometry, ToothKinematics};
pub use spring::SpringDamper;
pub use stream::{
    guard_state, Collector, DiscSample, EngineError, NullObserver, Observer, RunStats, Sample,
    RUNAWAY_SPEED_RAD_S, STALL_SPAN_S, STALL_STEPS,
};

/// A number for messages, the one format every front end echoes values in: Rust's shortest
/// round-trip `{}` for ordinary magnitudes (`|x|` in `[1e-5, 1e9)`, and 0), `{:e}` outside
/// (`1e300`, not 301 digits; `1e-300`, not 300 zeros; `5e-324`). Both forms read back as the
/// same `f64`, and both are valid TOML (a value echoed from `--set` can be pasted back).
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-5..1e9).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

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

/// `2 \int_0^1 dx / sqrt(1 - x^(5/2))`: the duration of a free Hertz impact in units of
/// `s_max / v0` (energy conservation `1/2 m s'^2 + 2/5 k s^(5/2) = 1/2 m v0^2` integrated over
/// the approach and the symmetric restitution).
pub const HERTZ_DURATION_FACTOR: f64 = 2.943_275_184;

/// Closed-form duration of one free, undamped impact in s (Hertz's impact theory):
/// `t_c = 2.9433 s_max / v0`, with `s_max` from [`free_impact_compression_m`], for stiffness
/// `k` (N/m^1.5), effective mass `m_eff` (kg) and closing speed `v0` (m/s, > 0). It shrinks as
/// `m_eff^(2/5) k^(-2/5) v0^(-1/5)`; the scene validation uses it to refuse a body and law an
/// engine cannot resolve.
pub fn free_impact_duration_s(k: f64, m_eff_kg: f64, v0_m_s: f64) -> f64 {
    HERTZ_DURATION_FACTOR * free_impact_compression_m(k, m_eff_kg, v0_m_s) / v0_m_s
}

#[cfg(test)]
mod tests {
    /// Huge and tiny numbers in e-notation, ordinary ones plain; every form reads back exactly
    /// (issue 36: 301-digit decimals were echoed for 1e300 and 1e-300).
    #[test]
    fn numbers_in_messages_are_short_and_exact() {
        for (x, want) in [
            (1e300, "1e300"),
            (1e-300, "1e-300"),
            (-1e300, "-1e300"),
            (0.0, "0"),
            (0.3, "0.3"),
            (25e-6, "0.000025"),
            (1e-6, "1e-6"),
            (10_000.0, "10000"),
            (1e9, "1e9"),
            (5e-324, "5e-324"),
        ] {
            let s = super::fmt_num(x);
            assert_eq!(s, want);
            assert_eq!(s.parse::<f64>().unwrap(), x);
        }
    }

    /// The closed-form duration against a direct integration of `m s'' = -k s^1.5` (RK4 with
    /// 1e5 steps over the contact).
    #[test]
    fn free_impact_duration_matches_integration() {
        let (k, m, v0) = (1.2e10_f64, 0.05_f64, 0.4_f64);
        let t_c = super::free_impact_duration_s(k, m, v0);
        let h = t_c / 1e5;
        let f = |s: f64| if s > 0.0 { -k * s.powf(1.5) / m } else { 0.0 };
        let (mut s, mut v, mut t) = (0.0_f64, v0, 0.0);
        loop {
            let (k1s, k1v) = (v, f(s));
            let (k2s, k2v) = (v + 0.5 * h * k1v, f(s + 0.5 * h * k1s));
            let (k3s, k3v) = (v + 0.5 * h * k2v, f(s + 0.5 * h * k2s));
            let (k4s, k4v) = (v + h * k3v, f(s + h * k3s));
            let s_next = s + h / 6.0 * (k1s + 2.0 * k2s + 2.0 * k3s + k4s);
            v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            if s_next <= 0.0 && t > 0.0 {
                // separation inside this step: interpolate linearly
                t += h * s / (s - s_next);
                break;
            }
            s = s_next;
            t += h;
        }
        // integration error of the located separation ~1e-5 relative; measured ~1e-6
        assert!(
            (t - t_c).abs() < 1e-4 * t_c,
            "integrated {t} s, closed form {t_c} s"
        );
        // and the rebound speed equals the closing speed (no loss)
        assert!((v + v0).abs() < 1e-4 * v0, "rebound {v} m/s");
    }
}
