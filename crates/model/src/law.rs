//! Tooth force laws (MODEL.md section 2): Hertz contact with impact damping (Hu et al. eqs 1,
//! 2, 6), the paper's oil film in series with the Hertz stiffness (eqs 7-10), and a Reynolds
//! squeeze-film damper in parallel with Hertz (Brancati, Rocca and Russo).
//!
//! All functions return the **magnitude** of the per-tooth load in N (never negative: a contact
//! never pulls). The sign of the load comes from the flank ([`crate::Flank::load_sign`]).

use crate::spline::{Flank, ToothKinematics};
use serde::{Deserialize, Serialize};

/// Hertz stiffness coefficient `H = (4/3) E sqrt(r)` in N/m^1.5 (Hu et al. eq (2)).
///
/// `modulus_pa` is the equivalent modulus `E` as the paper writes it (Pa), `curvature_radius_m`
/// the equivalent curvature radius `r` (m).
#[inline]
pub fn hertz_coefficient(modulus_pa: f64, curvature_radius_m: f64) -> f64 {
    // Hu et al. eq (2)
    4.0 / 3.0 * modulus_pa * curvature_radius_m.sqrt()
}

/// Oil film stiffness `K_w = 3 beta eta B^3 L dv / h_o^4` in N/m^1.5 (Hu et al. eq (8)).
///
/// `dv_m_s` is the closing speed held for the contact event (m/s, > 0), `film_m` the film
/// thickness `h_o` (m, > 0). Used as a stiffness of the `s^1.5` law, as the paper does in eq (10).
pub fn film_stiffness(
    leakage_coefficient: f64,
    viscosity_pa_s: f64,
    width_m: f64,
    length_m: f64,
    film_m: f64,
    dv_m_s: f64,
) -> f64 {
    // Hu et al. eq (8)
    3.0 * leakage_coefficient * viscosity_pa_s * width_m.powi(3) * length_m * dv_m_s
        / film_m.powi(4)
}

/// Series combination `K = 1 / (1/K_w + 1/H)` (Hu et al. eq (9)), in N/m^1.5.
pub fn series_stiffness(film_stiffness: f64, hertz: f64) -> f64 {
    // Hu et al. eq (9); written to stay exact when K_w is infinite (h_o = 0).
    if film_stiffness.is_infinite() {
        hertz
    } else {
        film_stiffness * hertz / (film_stiffness + hertz)
    }
}

/// Impact damping factor `max(0, 1 + p v_n)` (Hu et al. eq (1)), dimensionless.
///
/// `p` is the impact energy loss coefficient in s/m, `v_n` the closing speed in m/s. The clamp
/// at zero keeps the law from pulling during fast separation.
#[inline]
pub fn damping_factor(loss_coefficient_s_m: f64, v_n_m_s: f64) -> f64 {
    (1.0 + loss_coefficient_s_m * v_n_m_s).max(0.0)
}

/// Hertz load magnitude with impact damping, `max(0, 1 + p v_n) k s^1.5` for `s > 0`, else 0
/// (Hu et al. eqs (1), (6), (10)). `k` in N/m^1.5, `s` in m, result in N.
#[inline]
pub fn hertz_load(k: f64, s_m: f64, loss_coefficient_s_m: f64, v_n_m_s: f64) -> f64 {
    if s_m <= 0.0 {
        return 0.0;
    }
    // Hu et al. eq (6) / (10)
    damping_factor(loss_coefficient_s_m, v_n_m_s) * k * s_m * s_m.sqrt()
}

/// Reynolds squeeze-film load `W = beta eta B^3 L v_n / h^3` (Hu et al. eq (7) with
/// `dh/dt = -v_n`), in N; zero while separating (the film cavitates rather than pulls).
/// `gap_m` is the metal gap, floored at `h_min_m`.
pub fn squeeze_load(oil: &OilFilm, gap_m: f64, v_n_m_s: f64) -> f64 {
    if v_n_m_s <= 0.0 {
        return 0.0;
    }
    let h = gap_m.max(oil.h_min_m);
    // Hu et al. eq (7)
    oil.leakage_coefficient * oil.viscosity_pa_s * oil.width_m.powi(3) * oil.length_m * v_n_m_s
        / (h * h * h)
}

/// Which tooth force law a coupling uses (MODEL.md section 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LawKind {
    /// Hertz contact with impact damping, no oil (Hu et al. eqs 1, 2, 6).
    Dry,
    /// The paper's oil film: compression `s = delta + h_o`, film stiffness (eq 8) with the
    /// closing speed held per contact event, in series with Hertz (eqs 9, 10). The default.
    Paper,
    /// Hertz metal contact in parallel with a Reynolds squeeze-film damper.
    Squeeze,
}

/// Hertz contact parameters of a tooth pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Hertz {
    /// Equivalent modulus `E` in Pa as the paper writes it (210 GPa for steel).
    pub modulus_pa: f64,
    /// Equivalent curvature radius `r` in m.
    pub curvature_radius_m: f64,
    /// Impact energy loss coefficient `p` in s/m (eq 1); 0 is a lossless contact.
    pub loss_coefficient_s_m: f64,
}

impl Hertz {
    /// `H` in N/m^1.5 (eq 2).
    #[inline]
    pub fn coefficient(&self) -> f64 {
        hertz_coefficient(self.modulus_pa, self.curvature_radius_m)
    }
}

/// Oil film between the flanks (eqs 7-10).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OilFilm {
    /// Film thickness `h_o` in m (>= 0). 0 means no film: the paper law is then the dry law.
    pub thickness_m: f64,
    /// Dynamic viscosity `eta` in Pa s.
    pub viscosity_pa_s: f64,
    /// Leakage coefficient `beta` (dimensionless; 0.421 for B/L = 1, after Cameron).
    pub leakage_coefficient: f64,
    /// Contact width `B` in m (axial length of the film in eq 7).
    pub width_m: f64,
    /// Contact length `L` in m (radial length of the film in eq 7).
    pub length_m: f64,
    /// Floor of the held closing speed `dv` in m/s (paper law), so that a grazing contact
    /// still has a finite film stiffness.
    pub v_floor_m_s: f64,
    /// Smallest film gap in the squeeze law, m, so that the damper stays finite once metal touches.
    pub h_min_m: f64,
}

/// A tooth force law with its parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToothLaw {
    /// Which law.
    pub kind: LawKind,
    /// Metal contact.
    pub hertz: Hertz,
    /// Oil film (ignored by the dry law).
    pub oil: OilFilm,
}

/// The memory of the paper law for one contact event: the flank and the closing speed held
/// from the instant the film engaged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Engagement {
    /// Flank in contact.
    pub flank: Flank,
    /// Closing speed `dv` held for the event, m/s, floored at `v_floor_m_s`.
    pub dv_m_s: f64,
    /// Stiffness `K` of the `s^1.5` law for this event, N/m^1.5 (eq 9; `H` for dry and squeeze).
    pub stiffness: f64,
    /// Film stiffness `K_w` of eq (8), N/m^1.5 (infinite without a film).
    pub film_stiffness: f64,
}

impl ToothLaw {
    /// Film thickness that shifts the start of contact, m: `h_o` for the oil laws, 0 for dry.
    #[inline]
    pub fn engagement_offset_m(&self) -> f64 {
        match self.kind {
            LawKind::Dry => 0.0,
            LawKind::Paper | LawKind::Squeeze => self.oil.thickness_m,
        }
    }

    /// Engagement depth in m: the compression `s = delta + h_o` (paper, squeeze) or `delta`
    /// (dry). A contact event lasts while this is positive; engines locate its zero crossings.
    #[inline]
    pub fn engagement_depth_m(&self, kin: &ToothKinematics) -> f64 {
        kin.delta_m + self.engagement_offset_m()
    }

    /// Starts a contact event at the instant the engagement depth crosses zero (MODEL.md 2):
    /// holds `dv = max(v_n, v_floor)` and the stiffness `K` for the whole event.
    #[inline]
    pub fn engage(&self, kin: &ToothKinematics) -> Engagement {
        let h = self.hertz.coefficient();
        match self.kind {
            LawKind::Paper if self.oil.thickness_m > 0.0 => {
                let dv = kin.v_n_m_s.max(self.oil.v_floor_m_s);
                let kw = film_stiffness(
                    self.oil.leakage_coefficient,
                    self.oil.viscosity_pa_s,
                    self.oil.width_m,
                    self.oil.length_m,
                    self.oil.thickness_m,
                    dv,
                );
                Engagement {
                    flank: kin.flank,
                    dv_m_s: dv,
                    stiffness: series_stiffness(kw, h),
                    film_stiffness: kw,
                }
            }
            _ => Engagement {
                flank: kin.flank,
                dv_m_s: kin.v_n_m_s,
                stiffness: h,
                film_stiffness: f64::INFINITY,
            },
        }
    }

    /// Per-tooth load magnitude in N during a contact event (`engagement` from [`Self::engage`]).
    #[inline]
    pub fn load_magnitude(&self, kin: &ToothKinematics, engagement: &Engagement) -> f64 {
        let p = self.hertz.loss_coefficient_s_m;
        match self.kind {
            LawKind::Dry => hertz_load(engagement.stiffness, kin.delta_m, p, kin.v_n_m_s),
            // Hu et al. eq (10): s = delta + h_o, K from eq (9)
            LawKind::Paper => hertz_load(
                engagement.stiffness,
                kin.delta_m + self.oil.thickness_m,
                p,
                kin.v_n_m_s,
            ),
            LawKind::Squeeze => {
                let metal = hertz_load(engagement.stiffness, kin.delta_m, p, kin.v_n_m_s);
                let gap = -kin.delta_m;
                let film = if gap < self.oil.thickness_m {
                    squeeze_load(&self.oil, gap, kin.v_n_m_s)
                } else {
                    0.0
                };
                metal + film
            }
        }
    }

    /// Signed per-tooth load in N (eq 6 sign: negative when the shaft leads).
    #[inline]
    pub fn load_n(&self, kin: &ToothKinematics, engagement: &Engagement) -> f64 {
        engagement.flank.load_sign() * self.load_magnitude(kin, engagement)
    }
}

/// Contact state of one coupling for engines that step at fixed or adaptive times without
/// locating the engagement instant exactly: it engages the paper law's memory at the first
/// step with positive engagement depth and releases it when the depth falls back to zero.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactState {
    /// The current contact event, if any.
    pub engagement: Option<Engagement>,
}

impl ContactState {
    /// Advances the memory to the kinematics `kin` and returns the signed per-tooth load in N.
    pub fn update(&mut self, law: &ToothLaw, kin: &ToothKinematics) -> f64 {
        if law.engagement_depth_m(kin) <= 0.0 {
            self.engagement = None;
            return 0.0;
        }
        let e = match self.engagement {
            Some(e) if e.flank == kin.flank => e,
            _ => law.engage(kin),
        };
        self.engagement = Some(e);
        law.load_n(kin, &e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The paper's law (Table 2), one definition for every test ([`crate::cases::paper_law`]).
    fn law(kind: LawKind, h_o: f64) -> ToothLaw {
        crate::cases::paper_law(kind, h_o)
    }

    fn kin(delta: f64, v: f64) -> ToothKinematics {
        ToothKinematics {
            flank: Flank::ShaftLeads,
            delta_m: delta,
            v_n_m_s: v,
        }
    }

    #[test]
    fn hertz_coefficient_of_the_paper_case() {
        // (4/3) 210e9 sqrt(1.75e-3) = 1.17131...e10 N/m^1.5
        assert_relative_eq!(
            hertz_coefficient(210e9, 1.75e-3),
            4.0 / 3.0 * 210e9 * 0.0418330013267,
            max_relative = 1e-11
        );
    }

    /// A contact never pulls: the load is >= 0 for any penetration and closing speed, for
    /// every law (property test over a grid including fast separation, 1 + p v_n < 0).
    #[test]
    fn no_law_ever_pulls() {
        for kind in [LawKind::Dry, LawKind::Paper, LawKind::Squeeze] {
            for h_o in [0.0, 25e-6, 75e-6] {
                let l = law(kind, h_o);
                for i in -50..50 {
                    let delta = i as f64 * 1e-6;
                    for j in -40..40 {
                        let v = j as f64 * 0.1;
                        let k = kin(delta, v);
                        if l.engagement_depth_m(&k) <= 0.0 {
                            continue;
                        }
                        let e = l.engage(&kin(0.0, v.abs()));
                        let f = l.load_magnitude(&k, &e);
                        assert!(f >= 0.0 && f.is_finite(), "{kind:?} {delta} {v} -> {f}");
                    }
                }
            }
        }
    }

    /// With h_o = 0 the paper law is exactly the dry law (MODEL.md section 2).
    #[test]
    fn paper_law_without_film_is_dry() {
        let p = law(LawKind::Paper, 0.0);
        let d = law(LawKind::Dry, 0.0);
        let k = kin(3e-6, 0.2);
        let ep = p.engage(&k);
        let ed = d.engage(&k);
        assert_eq!(p.load_n(&k, &ep), d.load_n(&k, &ed));
        assert!(p.load_n(&k, &ep) < 0.0, "shaft leads: negative load");
    }

    /// The film softens the contact: K < H, and K -> H as the film thins (eq 9).
    #[test]
    fn film_is_in_series_with_hertz() {
        let h = law(LawKind::Paper, 0.0).hertz.coefficient();
        let mut last = 0.0;
        for h_o in [100e-6, 75e-6, 50e-6, 25e-6, 5e-6] {
            let e = law(LawKind::Paper, h_o).engage(&kin(-h_o, 0.1));
            assert!(e.stiffness < h);
            assert!(e.stiffness > last, "K grows as the film thins");
            last = e.stiffness;
        }
        assert!(last > 0.99 * h);
    }

    /// eq (8) by hand for h_o = 25 um, dv = 0.1 m/s.
    #[test]
    fn film_stiffness_by_hand() {
        let kw = film_stiffness(0.421, 289.1, 3e-3, 3e-3, 25e-6, 0.1);
        let by_hand = 3.0 * 0.421 * 289.1 * 8.1e-11 * 0.1 / 3.90625e-19;
        assert_relative_eq!(kw, by_hand, max_relative = 1e-12);
    }

    /// The held speed is floored: a grazing engagement still has a finite, positive stiffness.
    #[test]
    fn held_speed_is_floored() {
        let l = law(LawKind::Paper, 25e-6);
        let e = l.engage(&kin(-25e-6, -0.5));
        assert_eq!(e.dv_m_s, 0.01);
        assert!(e.stiffness > 0.0);
    }

    /// The squeeze film only pushes while closing and is bounded by h_min once metal touches.
    #[test]
    fn squeeze_film_cavitates_and_is_bounded() {
        let l = law(LawKind::Squeeze, 25e-6);
        let e = l.engage(&kin(-25e-6, 0.1));
        assert_eq!(l.load_magnitude(&kin(-10e-6, -0.1), &e), 0.0);
        let at_touch = l.load_magnitude(&kin(0.0, 0.1), &e);
        let expected = 0.421 * 289.1 * 8.1e-11 * 0.1 / 1e-18;
        assert_relative_eq!(at_touch, expected, max_relative = 1e-12);
    }

    /// The contact memory holds dv for the whole event and resets when the film opens.
    #[test]
    fn contact_state_holds_dv_per_event() {
        let l = law(LawKind::Paper, 25e-6);
        let mut c = ContactState::default();
        assert_eq!(c.update(&l, &kin(-30e-6, 0.2)), 0.0);
        c.update(&l, &kin(-20e-6, 0.2));
        let dv = c.engagement.unwrap().dv_m_s;
        c.update(&l, &kin(-10e-6, 0.01));
        assert_eq!(c.engagement.unwrap().dv_m_s, dv);
        c.update(&l, &kin(-26e-6, -0.2));
        assert!(c.engagement.is_none());
    }
}
