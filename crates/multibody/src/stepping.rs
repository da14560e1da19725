//! The contact-aware step controller ([`crate::AdaptiveStepping`]).

use crate::hook::{CouplingForces, FLANKS};
use crate::options::AdaptiveStepping;
use clutchpack_model::law::damping_factor;
use clutchpack_model::{Flank, SpeedProfile, ToothKinematics, ToothLaw};

/// Hertz impact duration factor: `T = 2.943 (5 m / (4 K))^(2/5) v^(-1/5)` (Johnson, Contact
/// Mechanics, eq 11.24 for the `s^1.5` law).
const HERTZ_DURATION: f64 = 2.943;

/// Closing speed below which the impact duration is taken at this speed, m/s (a grazing
/// contact otherwise predicts an unbounded duration).
const V_MIN: f64 = 1e-4;

/// Predicted duration in s of an impact on `flank` at closing speed `v_m_s` of the per-tooth
/// law `law` with effective mass `m_kg` per tooth (`J / (n Rb^2)`).
pub(crate) fn contact_duration_s(law: &ToothLaw, flank: Flank, v_m_s: f64, m_kg: f64) -> f64 {
    let v = v_m_s.max(V_MIN);
    let e = law.engage(&ToothKinematics {
        flank,
        delta_m: 0.0,
        v_n_m_s: v,
    });
    let k = e.stiffness * damping_factor(law.hertz.loss_coefficient_s_m, v).max(1.0);
    HERTZ_DURATION * (1.25 * m_kg / k).powf(0.4) * v.powf(-0.2)
}

/// Largest shaft angular acceleration of a speed profile, rad/s^2 (a bound over all times).
pub(crate) fn profile_acceleration_bound(p: &SpeedProfile) -> f64 {
    match p {
        SpeedProfile::Harmonics { harmonics, .. } => harmonics
            .iter()
            .map(|h| h.amplitude_rad_s.abs() * std::f64::consts::TAU * h.frequency_hz.abs())
            .sum(),
        SpeedProfile::Table(tab) => tab
            .t_s
            .windows(2)
            .zip(tab.y.windows(2))
            .map(|(t, y)| ((y[1] - y[0]) / (t[1] - t[0])).abs())
            .fold(0.0, f64::max),
        SpeedProfile::Held { accel_rad_s2, .. } => accel_rad_s2.abs(),
    }
}

/// What the controller knows about one coupling at the start of a step.
pub(crate) struct CouplingView<'a> {
    /// The hook's result at the start of the step.
    pub forces: &'a CouplingForces,
    /// The tooth law.
    pub law: &'a ToothLaw,
    /// Relative angle and speed, rad and rad/s.
    pub phi: f64,
    /// See `phi`.
    pub dphi: f64,
    /// Half play `g0`, rad; base radius `Rb`, m.
    pub g0: f64,
    /// See `g0`.
    pub rb: f64,
    /// Effective mass per tooth, kg.
    pub m_eff_kg: f64,
    /// Bound of `|d dphi / dt|` in free flight, rad/s^2.
    pub rel_accel_bound: f64,
    /// Step of the contact event in progress, s (set at its onset).
    pub event_step_s: Option<f64>,
    /// How long the contact event in progress has lasted, s.
    pub event_age_s: Option<f64>,
}

/// The step the coupling allows, s, and whether it is a contact step (the coupling is in
/// contact or will touch within it); contact steps are not shortened to land on sampling
/// times, since varying the step within a contact spoils the symplectic step's energy.
#[inline]
pub(crate) fn coupling_step(c: &CouplingView<'_>, a: &AdaptiveStepping) -> (f64, bool) {
    let n = a.steps_per_contact;
    let f = c.forces;
    if f.depth_m > 0.0 {
        // In contact: the event's step, and the local period of the linearised contact; a
        // sustained contact (longer than `sustained_after` predicted impacts) is resolved at
        // `sustained_steps_per_period` per local period instead.
        let mut dt = c.event_step_s.unwrap_or(a.max_step_s);
        let sustained = matches!(
            (c.event_step_s, c.event_age_s),
            (Some(step), Some(age)) if age > a.sustained_after * a.steps_per_contact * step
        );
        if f.stiffness > 0.0 {
            let damp = damping_factor(c.law.hertz.loss_coefficient_s_m, f.kin.v_n_m_s).max(1.0);
            if !sustained && period_cannot_bind(dt, n, 1.5 * f.stiffness * damp, f.depth_m, c) {
                return (dt, true);
            }
            let k_lin = 1.5 * f.stiffness * damp * f.depth_m.sqrt();
            if k_lin > 0.0 {
                let period = std::f64::consts::TAU / (k_lin / c.m_eff_kg).sqrt();
                dt = if sustained {
                    let per_period = a.sustained_steps_per_period.min(n);
                    (period / per_period).min(a.max_step_s)
                } else {
                    dt.min(period / n)
                };
            }
        }
        return (dt, true);
    }
    let a_lin = c.rel_accel_bound * c.rb;
    let offset = c.law.engagement_offset_m();
    let mut dt = a.max_step_s;
    let mut contact = false;
    for flank in FLANKS {
        let sigma = flank.phi_sign();
        // Worst-case gap to this flank's engagement and closing speed.
        let gap = -((sigma * c.phi - c.g0) * c.rb + offset) - f.gap_margin_m;
        let v = sigma * c.dphi * c.rb + f.speed_margin_m_s;
        // Largest tau with v tau + a tau^2 / 2 <= fraction * gap.
        let g = a.approach_fraction * gap.max(0.0);
        let den = v + (v * v + 2.0 * a_lin * g).sqrt();
        let tau = if den > 0.0 {
            2.0 * g / den
        } else {
            f64::INFINITY
        };
        if tau >= dt {
            // neither branch below can shorten the step (a contact step would need
            // `dt_contact >= tau >= dt`): skip the contact's duration (two powers)
            continue;
        }
        let v_hit = (v.max(0.0).powi(2) + 2.0 * a_lin * gap.max(0.0)).sqrt();
        let dt_contact = contact_duration_s(c.law, flank, v_hit, c.m_eff_kg) / n;
        if tau <= dt_contact {
            if dt_contact < dt {
                dt = dt_contact;
                contact = true;
            }
        } else if tau < dt {
            dt = tau;
            contact = false;
        }
    }
    (dt, contact)
}

/// Whether the local period of a contact, `2 pi / sqrt(k_lin / m)` with
/// `k_lin = k15 sqrt(depth)` (`k15 = 1.5 K (1 + p v)`, the linearised `s^1.5` law), is surely
/// longer than `n` steps of `dt`, so that [`coupling_step`]'s `dt.min(period / n)` is `dt` to
/// the bit: decided without its two square roots and three divisions (they were most of the
/// controller's time, which was a tenth of a pack's run), squared twice,
/// `m^2 > (n dt / 2 pi)^4 k15^2 depth`, with a relative margin of 1e-12 far above the
/// rounding of either side (a few ulps). `false` when unsure: the caller then computes the
/// period. Within an impact's step (the Hertz duration over `n`) the period at the deepest
/// point is still 1.6 times the duration (`2 pi / 1.369 s_max / v` against
/// `2.943 s_max / v`), so the check decides nearly every contact step.
fn period_cannot_bind(dt: f64, n: f64, k15: f64, depth_m: f64, c: &CouplingView<'_>) -> bool {
    let q = n * dt / std::f64::consts::TAU;
    let q2 = q * q;
    let m = c.m_eff_kg;
    q2 * q2 * (k15 * k15) * depth_m < (1.0 - 1e-12) * (m * m)
}

/// Whether a coupling's engagement depth going from `d0` to `d1` (m) over a step crosses the
/// contact's boundary: a separation for a coupling `engaged` at the step's start (depth falls
/// to 0 or below), an onset otherwise (depth rises above 0). The one rule the step controller
/// and both multirate schemes land their steps on.
pub(crate) fn crosses_contact(engaged: bool, d0: f64, d1: f64) -> bool {
    if engaged {
        d0 > 0.0 && d1 <= 0.0
    } else {
        d0 <= 0.0 && d1 > 0.0
    }
}

/// The root of `f` in `[a, b]` given `fa = f(a)`, `fb = f(b)` of opposite signs (or zero),
/// by the Illinois variant of regula falsi, to `|f| <= tol` or a bracket of relative width
/// 1e-15. Returns the end of the final bracket on the side of `b`'s sign, so that `f` has
/// crossed (or reached) zero there.
pub(crate) fn bracketed_root(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut fa: f64,
    mut b: f64,
    mut fb: f64,
    tol: f64,
) -> f64 {
    let mut side = 0;
    for _ in 0..100 {
        if fb.abs() <= tol || (b - a).abs() <= 1e-15 * b.abs().max(a.abs()) {
            break;
        }
        let c = if fb != fa {
            b - fb * (b - a) / (fb - fa)
        } else {
            0.5 * (a + b)
        };
        let c = if c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hook::CouplingForces;
    use clutchpack_model::{free_impact_compression_m, Hertz, LawKind, OilFilm};

    /// The paper's steel teeth (E = 210 GPa, R = 1.75 mm) under the dry law, lossless.
    fn steel_dry_law() -> ToothLaw {
        ToothLaw {
            kind: LawKind::Dry,
            hertz: Hertz {
                modulus_pa: 210e9,
                curvature_radius_m: 1.75e-3,
                loss_coefficient_s_m: 0.0,
            },
            oil: OilFilm {
                thickness_m: 0.0,
                viscosity_pa_s: 0.0,
                leakage_coefficient: 0.421,
                width_m: 3e-3,
                length_m: 3e-3,
                v_floor_m_s: 0.01,
                h_min_m: 1e-6,
            },
        }
    }

    /// The predicted duration is the Hertz impact time: 2.943 s_max / v0 with
    /// s_max = (5/4 m v0^2 / H)^(2/5) (the same closed form written two ways; p = 0).
    #[test]
    fn duration_is_the_hertz_impact_time() {
        let law = steel_dry_law();
        let m = 0.156 / (154.0 * (0.231 * 20f64.to_radians().cos()).powi(2));
        let v0 = 0.3;
        let s = free_impact_compression_m(law.hertz.coefficient(), m, v0);
        let t = contact_duration_s(&law, Flank::ShaftLeads, v0, m);
        assert!((t - 2.943 * s / v0).abs() < 1e-12 * t);
        // the paper's impacts last 60-70 us
        assert!(t > 40e-6 && t < 100e-6, "{t}");
    }

    /// In contact the step is the event's step bounded by the local period over
    /// `steps_per_contact`; once the contact has outlasted `sustained_after` predicted
    /// impacts it is the local period over `sustained_steps_per_period` (and never more than
    /// `max_step_s`), whatever the event's step was.
    #[test]
    fn sustained_contacts_step_by_their_local_period() {
        let law = steel_dry_law();
        let h = law.hertz.coefficient();
        let (m, depth) = (0.02, 1e-6);
        let forces = CouplingForces {
            kin: ToothKinematics {
                flank: Flank::ShaftLeads,
                delta_m: depth,
                v_n_m_s: 0.0,
            },
            depth_m: depth,
            load_n: -h * depth.powf(1.5),
            force: [0.0; 2],
            moment: [0.0; 3],
            stiffness: h,
            potential_j: 0.0,
            gap_margin_m: 0.0,
            speed_margin_m_s: 0.0,
        };
        // local period of m s'' = -H s^1.5 linearised at s: 2 pi / sqrt(1.5 H sqrt(s) / m)
        let period = std::f64::consts::TAU / (1.5 * h * depth.sqrt() / m).sqrt();
        let a = AdaptiveStepping::default();
        let event_step = 1e-7;
        let view = |age: f64| CouplingView {
            forces: &forces,
            law: &law,
            phi: 0.0,
            dphi: 0.0,
            g0: 0.0,
            rb: 0.2,
            m_eff_kg: m,
            rel_accel_bound: 0.0,
            event_step_s: Some(event_step),
            event_age_s: Some(age),
        };
        let young = a.sustained_after * a.steps_per_contact * event_step * 0.99;
        let (dt, contact) = coupling_step(&view(young), &a);
        assert!(contact);
        assert_eq!(dt, event_step.min(period / a.steps_per_contact));
        let old = young / 0.99 * 1.01;
        let (dt, contact) = coupling_step(&view(old), &a);
        assert!(contact);
        assert!((dt - period / a.sustained_steps_per_period).abs() < 1e-15 * dt);
        assert!(dt > 3.0 * event_step, "{dt} vs {event_step}");
        let never = AdaptiveStepping {
            sustained_after: f64::INFINITY,
            ..a
        };
        assert_eq!(
            coupling_step(&view(1.0), &never).0,
            event_step.min(period / 128.0)
        );
    }
}
