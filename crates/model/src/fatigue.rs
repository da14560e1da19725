//! Fatigue of the spline teeth (MODEL.md section 7): tooth-root bending stress, flank
//! pressure, the S-N curve with its knee and the three Miner rules, damage and the
//! damage-equivalent load. Pure functions of numbers; the cycle counting that feeds them is in
//! `clutchpack_analysis::cycles`.
//!
//! # Theory
//! - **Load.** A tooth load `F` (N, per tooth, signed by flank as in eq (6)) acts along the line
//!   of action. Its tangential component at the pitch circle is `F_t = |F| cos(alpha)` (the
//!   torque `n F Rb = n F R cos(alpha)` of eq (5) is carried by `F_t` at `R`).
//! - **Root stress** (ISO 6336-3, method B, nominal stress times the factors, applied to the
//!   spline tooth): `sigma_F = F_t / (b m) Y_F Y_S K_l` with the module `m = 2 R / n`, the
//!   engaged face width `b`, the form factor `Y_F`, the stress correction factor `Y_S` and the
//!   axial load distribution factor `K_l`. It is linear in `|F|`: [`stress_per_newton`] gives
//!   the factor in Pa/N, so a load range `dF` is a stress range `c dF`.
//! - **Flank pressure** (DIN 5466-1, Dudley's spline formula): `p = F_t / (b h_w)` with the
//!   working depth `h_w` (the radial height over which the flanks touch).
//! - **S-N curve** (Basquin with a knee at `(N_D, S_D)`), `S` the stress amplitude of a cycle:
//!   `N(S) = N_D (S_D / S)^k` for `S >= S_D`; below the knee
//!   Miner original: `N = infinity` (no damage),
//!   Miner elementary: `N = N_D (S_D / S)^k` (the same line),
//!   Miner-Haibach: `N = N_D (S_D / S)^(2k - 1)` (a shallower line).
//!   For `k > 1` and `S < S_D` the lives order `N_elementary <= N_Haibach < N_original`, so
//!   the damages order **elementary >= Haibach >= original** on any history.
//! - **Damage** (Palmgren-Miner): `D = sum_i n_i / N(S_i)`, failure at `D = D_crit`.
//! - **Damage-equivalent load** of counted ranges `S_i` with counts `n_i`:
//!   `S_eq = (sum_i n_i S_i^m / N_eq)^(1/m)`: the constant range that, applied `N_eq` times,
//!   does the damage of the counted ones on a single-slope curve of exponent `m`.
//!
//! # Mean stress
//! No mean-stress correction: the S-N curve is in stress amplitude, taken from pulsating
//! (R = 0) tooth tests, and applied as it is to both kinds of counted cycles: one-flank hits
//! (pulsating, R = 0, amplitude `sigma_F / 2`) and alternating-flank hits (reversed bending at
//! each root fillet, R = -1, amplitude `sigma_F`). For R = -1 this is conservative: ISO 6336-3
//! allows reversed bending 0.7 times the pulsating *peak* stress, i.e. 1.4 times its amplitude.
//! See docs/DECISIONS.md, "Fatigue".

use crate::spline::SplineGeometry;
use serde::{Deserialize, Serialize};

/// Default form factor `Y_F` (ASSUMED; see [`ToothForm::form_factor`]).
pub const DEFAULT_FORM_FACTOR: f64 = 2.1;
/// Default stress correction factor `Y_S` (ASSUMED; see [`ToothForm::stress_correction`]).
pub const DEFAULT_STRESS_CORRECTION: f64 = 2.0;
/// Default axial load distribution factor `K_l` (see [`ToothForm::load_distribution`]).
pub const DEFAULT_LOAD_DISTRIBUTION: f64 = 1.0;
/// Default engaged face width `b` in m (the paper's 3 mm disc).
pub const DEFAULT_FACE_WIDTH_M: f64 = 3e-3;
/// Default working depth `h_w` in m (ASSUMED; see [`ToothForm::working_depth_m`]).
pub const DEFAULT_WORKING_DEPTH_M: f64 = 2.7e-3;
/// Default endurance limit `S_D` as a stress amplitude in Pa (ASSUMED; see
/// [`Material::endurance_amplitude_pa`]).
pub const DEFAULT_ENDURANCE_AMPLITUDE_PA: f64 = 315e6;
/// Default cycles at the knee `N_D` (see [`Material::knee_cycles`]).
pub const DEFAULT_KNEE_CYCLES: f64 = 3e6;
/// Default Basquin exponent `k` (ASSUMED; see [`Material::slope`]).
pub const DEFAULT_SLOPE: f64 = 6.2;
/// Default rule below the knee (see [`Material::rule`]).
pub const DEFAULT_MINER_RULE: MinerRule = MinerRule::Haibach;
/// Default damage sum at failure `D_crit` (see [`Material::critical_damage`]).
pub const DEFAULT_CRITICAL_DAMAGE: f64 = 1.0;

/// The fatigue parameters of one body's spline teeth: tooth form and material. The scene
/// keys `fatigue.*` and `material.*` of a body (validated by `clutchpack_scene`, which holds
/// the rules of every value).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct FatigueParams {
    /// Tooth form (root stress and flank pressure factors).
    pub form: ToothForm,
    /// S-N curve and failure criterion.
    pub material: Material,
}

/// The tooth form of a spline coupling, as far as the root stress and flank pressure need it.
///
/// Defaults ([`ToothForm::default`]) are ASSUMED for the paper's disc (n = 154, R = 231 mm,
/// m = 3.0 mm, 3 mm thick): a nearly rack-like involute tooth of 20 deg pressure angle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ToothForm {
    /// Form factor `Y_F` (dimensionless, > 0). Default 2.1: ASSUMED, ISO 6336-3's `Y_F` of a
    /// standard 20 deg tooth without profile shift for a very large tooth count (rack-like;
    /// the paper's spline has 154 teeth).
    pub form_factor: f64,
    /// Stress correction factor `Y_S` (dimensionless, >= 1). Default 2.0: ASSUMED, ISO 6336-3's
    /// `Y_S` for the same tooth (root fillet of the basic rack, `rho_fP = 0.38 m`).
    pub stress_correction: f64,
    /// Axial load distribution factor `K_l` (dimensionless, >= 1): the peak line load over
    /// the face divided by its mean. Default 1 (MODEL.md section 7: an evenly loaded face).
    pub load_distribution: f64,
    /// Engaged face width `b` in m (> 0): the disc's thickness. Default 3e-3 (the paper's
    /// 3 mm disc; hu-table2.toml's oil film width).
    pub face_width_m: f64,
    /// Working depth `h_w` in m (> 0): the radial height of flank contact. Default 2.7e-3:
    /// ASSUMED, 0.9 m of the paper's 3.0 mm module (an involute spline's flanks touch over
    /// slightly less than one module each side of the pitch circle's reference).
    pub working_depth_m: f64,
}

impl Default for ToothForm {
    fn default() -> Self {
        ToothForm {
            form_factor: DEFAULT_FORM_FACTOR,
            stress_correction: DEFAULT_STRESS_CORRECTION,
            load_distribution: DEFAULT_LOAD_DISTRIBUTION,
            face_width_m: DEFAULT_FACE_WIDTH_M,
            working_depth_m: DEFAULT_WORKING_DEPTH_M,
        }
    }
}

/// Which Miner rule continues the S-N curve below its knee.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MinerRule {
    /// Miner original: amplitudes below the knee do no damage.
    Original,
    /// Miner elementary: the Basquin line of slope `k` continues below the knee.
    Elementary,
    /// Miner-Haibach: below the knee a line of slope `2k - 1`.
    Haibach,
}

impl MinerRule {
    /// All rules, in the order original, elementary, Haibach.
    pub const ALL: [MinerRule; 3] = [
        MinerRule::Original,
        MinerRule::Elementary,
        MinerRule::Haibach,
    ];

    /// The name used in scene files and tables (`original`, `elementary`, `haibach`).
    pub const fn name(self) -> &'static str {
        match self {
            MinerRule::Original => "original",
            MinerRule::Elementary => "elementary",
            MinerRule::Haibach => "haibach",
        }
    }
}

/// The S-N curve of the tooth root and the failure criterion.
///
/// Defaults ([`Material::default`]) are ASSUMED for a through-hardened alloy steel disc core
/// of about 300 HB, from ISO 6336-5 (bending endurance of through-hardened wrought steel,
/// quality MQ: `sigma_Flim` about 315 MPa, the nominal stress number of pulsating tests) and
/// ISO 6336-3 (life factor `Y_NT` of through-hardened steel: 1 at 3e6 cycles, 2.5 at 1e4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Endurance limit `S_D` as a root stress **amplitude** in Pa (> 0), at `N_D` cycles.
    /// Default 315e6: ASSUMED, `sigma_FE / 2 = sigma_Flim` (ISO 6336-5's pulsating peak
    /// `sigma_FE = 2 sigma_Flim = 630 MPa` at R = 0 has this amplitude).
    pub endurance_amplitude_pa: f64,
    /// Cycles at the knee `N_D` (> 0). Default 3e6 (ISO 6336-3: `Y_NT = 1` from 3e6 cycles on
    /// for through-hardened steel).
    pub knee_cycles: f64,
    /// Basquin exponent `k` above the knee (dimensionless, > 1). Default 6.2:
    /// `ln(3e6 / 1e4) / ln(2.5) = 6.22`, rounded, from ISO 6336-3's `Y_NT` line for
    /// through-hardened steel.
    pub slope: f64,
    /// The rule below the knee. Default [`MinerRule::Haibach`] (the FKM guideline's choice
    /// for a design; original is unsafe under spectra, elementary very conservative).
    pub rule: MinerRule,
    /// Damage sum at failure `D_crit` (dimensionless, > 0). Default 1 (Palmgren-Miner; test
    /// data scatter widely around it, FKM suggests 0.3 for steel under spectra).
    pub critical_damage: f64,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            endurance_amplitude_pa: DEFAULT_ENDURANCE_AMPLITUDE_PA,
            knee_cycles: DEFAULT_KNEE_CYCLES,
            slope: DEFAULT_SLOPE,
            rule: DEFAULT_MINER_RULE,
            critical_damage: DEFAULT_CRITICAL_DAMAGE,
        }
    }
}

impl Material {
    /// Cycles to failure `N(S)` at a stress amplitude `amplitude_pa` (Pa, >= 0); infinite for
    /// zero amplitude and, with Miner original, below the knee.
    pub fn cycles_to_failure(&self, amplitude_pa: f64) -> f64 {
        let s = amplitude_pa.abs();
        if s == 0.0 {
            return f64::INFINITY;
        }
        let ratio = self.endurance_amplitude_pa / s;
        let exponent = if s >= self.endurance_amplitude_pa {
            self.slope
        } else {
            match self.rule {
                MinerRule::Original => return f64::INFINITY,
                MinerRule::Elementary => self.slope,
                MinerRule::Haibach => 2.0 * self.slope - 1.0,
            }
        };
        // Basquin with a knee (MODEL.md section 7): N = N_D (S_D / S)^k
        self.knee_cycles * ratio.powf(exponent)
    }

    /// Damage of one full cycle of stress amplitude `amplitude_pa` (Pa): `1 / N(S)`.
    pub fn damage_per_cycle(&self, amplitude_pa: f64) -> f64 {
        let n = self.cycles_to_failure(amplitude_pa);
        if n.is_infinite() {
            0.0
        } else {
            1.0 / n
        }
    }

    /// The same material with another rule below the knee.
    pub fn with_rule(self, rule: MinerRule) -> Material {
        Material { rule, ..self }
    }
}

/// Module `m = 2 R / n` of a spline in m (MODEL.md section 7; the paper's 3.0 mm).
pub fn module_m(spline: &SplineGeometry) -> f64 {
    2.0 * spline.pitch_radius_m / spline.teeth as f64
}

/// Tangential load at the pitch circle `F_t = |F| cos(alpha)` in N (>= 0) of a per-tooth load
/// `load_n` (N, either sign) along the line of action.
pub fn tangential_load_n(load_n: f64, spline: &SplineGeometry) -> f64 {
    load_n.abs() * spline.pressure_angle_rad.cos()
}

/// Root stress per newton of per-tooth load along the line of action, Pa/N (> 0):
/// `cos(alpha) / (b m) Y_F Y_S K_l` (ISO 6336-3's nominal root stress with its factors).
pub fn stress_per_newton(spline: &SplineGeometry, form: &ToothForm) -> f64 {
    spline.pressure_angle_rad.cos() / (form.face_width_m * module_m(spline))
        * form.form_factor
        * form.stress_correction
        * form.load_distribution
}

/// Tooth-root bending stress `sigma_F = F_t / (b m) Y_F Y_S K_l` in Pa (>= 0) under a
/// per-tooth load `load_n` (N, either sign; the fillet in tension is the loaded flank's).
pub fn root_stress_pa(load_n: f64, spline: &SplineGeometry, form: &ToothForm) -> f64 {
    // ISO 6336-3 eq (3) form: sigma_F0 = F_t / (b m_n) Y_F Y_S, times the load factors
    tangential_load_n(load_n, spline) / (form.face_width_m * module_m(spline))
        * form.form_factor
        * form.stress_correction
        * form.load_distribution
}

/// Flank pressure `p = F_t / (b h_w)` in Pa (>= 0) under a per-tooth load `load_n` (N, either
/// sign): DIN 5466-1 / Dudley's mean flank pressure of a spline tooth.
pub fn flank_pressure_pa(load_n: f64, spline: &SplineGeometry, form: &ToothForm) -> f64 {
    tangential_load_n(load_n, spline) / (form.face_width_m * form.working_depth_m)
}

/// Miner damage `D = sum n_i / N(S_i)` of counted cycles given as (stress amplitude in Pa,
/// count; a half cycle counts 0.5).
pub fn miner_damage(cycles: impl IntoIterator<Item = (f64, f64)>, material: &Material) -> f64 {
    cycles
        .into_iter()
        .map(|(s, n)| n * material.damage_per_cycle(s))
        .sum()
}

/// Damage-equivalent value `S_eq = (sum n_i S_i^m / N_eq)^(1/m)` of counted (value, count)
/// pairs, in the unit of the values (a load range in N, a stress amplitude in Pa); 0 without
/// cycles. `m` is the exponent (> 0), `n_eq` the equivalent cycle count (> 0).
pub fn damage_equivalent(cycles: impl IntoIterator<Item = (f64, f64)>, m: f64, n_eq: f64) -> f64 {
    let sum: f64 = cycles.into_iter().map(|(s, n)| n * s.abs().powf(m)).sum();
    (sum / n_eq).powf(1.0 / m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn paper() -> SplineGeometry {
        crate::cases::paper_spline()
    }

    /// MODEL.md section 7's numbers for the paper's disc: m = 2 x 0.231 / 154 = 3.0 mm, and
    /// ~950 N gives a root stress of 400-450 MPa (issue 12) with the default tooth form
    /// (Y_F Y_S = 4.2): 950 cos 20 / (3e-3 x 3e-3) x 4.2 = 416.7 MPa. Exact to rounding.
    #[test]
    fn paper_disc_module_and_root_stress() {
        let g = paper();
        let f = ToothForm::default();
        assert_relative_eq!(module_m(&g), 3.0e-3, max_relative = 1e-15);
        let s = root_stress_pa(-950.0, &g, &f);
        let expected = 950.0 * 20f64.to_radians().cos() / 9e-6 * 4.2;
        assert_relative_eq!(s, expected, max_relative = 1e-14);
        assert!((400e6..450e6).contains(&s), "{s}");
        // linear in |F|, sign-blind
        assert_relative_eq!(s, 950.0 * stress_per_newton(&g, &f), max_relative = 1e-14);
        assert_eq!(root_stress_pa(950.0, &g, &f), s);
        // flank pressure: F_t / (b h_w)
        let p = flank_pressure_pa(950.0, &g, &f);
        assert_relative_eq!(
            p,
            950.0 * 20f64.to_radians().cos() / (3e-3 * 2.7e-3),
            max_relative = 1e-14
        );
    }

    /// The curve is continuous at the knee for every rule, follows N_D (S_D/S)^k above it,
    /// and below it gives infinity (original), slope k (elementary) or 2k - 1 (Haibach).
    #[test]
    fn s_n_curve_with_knee() {
        let m = Material::default();
        for rule in MinerRule::ALL {
            let r = m.with_rule(rule);
            assert_relative_eq!(
                r.cycles_to_failure(m.endurance_amplitude_pa),
                m.knee_cycles,
                max_relative = 1e-14
            );
            assert_relative_eq!(
                r.cycles_to_failure(2.0 * m.endurance_amplitude_pa),
                m.knee_cycles * 0.5f64.powf(6.2),
                max_relative = 1e-14
            );
        }
        let s = 0.5 * m.endurance_amplitude_pa;
        assert_eq!(
            m.with_rule(MinerRule::Original).cycles_to_failure(s),
            f64::INFINITY
        );
        assert_eq!(m.with_rule(MinerRule::Original).damage_per_cycle(s), 0.0);
        assert_relative_eq!(
            m.with_rule(MinerRule::Elementary).cycles_to_failure(s),
            3e6 * 2f64.powf(6.2),
            max_relative = 1e-14
        );
        assert_relative_eq!(
            m.with_rule(MinerRule::Haibach).cycles_to_failure(s),
            3e6 * 2f64.powf(11.4),
            max_relative = 1e-14
        );
        assert_eq!(m.cycles_to_failure(0.0), f64::INFINITY);
    }

    /// Closed form of a constant-amplitude history: n cycles at S above the knee do
    /// D = n / (N_D (S_D / S)^k) under every rule; below the knee n / (N_D (S_D/S)^q) with
    /// q = k (elementary), 2k - 1 (Haibach), and 0 (original).
    #[test]
    fn constant_amplitude_damage_closed_form() {
        let m = Material::default();
        let (n, s) = (12345.0, 400e6);
        let d = n / (3e6 * (315e6f64 / 400e6).powf(6.2));
        for rule in MinerRule::ALL {
            let got = miner_damage([(s, n)], &m.with_rule(rule));
            assert_relative_eq!(got, d, max_relative = 1e-13);
        }
        let s = 250e6;
        let below = |q: f64| n / (3e6 * (315e6f64 / 250e6).powf(q));
        assert_relative_eq!(
            miner_damage([(s, n)], &m.with_rule(MinerRule::Elementary)),
            below(6.2),
            max_relative = 1e-13
        );
        assert_relative_eq!(
            miner_damage([(s, n)], &m.with_rule(MinerRule::Haibach)),
            below(11.4),
            max_relative = 1e-13
        );
        assert_eq!(
            miner_damage([(s, n)], &m.with_rule(MinerRule::Original)),
            0.0
        );
    }

    /// On any spectrum (here a fixed pseudo-random one straddling the knee) the damages order
    /// elementary >= Haibach >= original (equal where all amplitudes are above the knee).
    #[test]
    fn rules_order_elementary_haibach_original() {
        let m = Material::default();
        let mut x: u64 = 7;
        for _ in 0..200 {
            let cycles: Vec<(f64, f64)> = (0..20)
                .map(|_| {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let u = (x >> 11) as f64 / (1u64 << 53) as f64;
                    (
                        u * 2.0 * m.endurance_amplitude_pa,
                        if x & 1 == 0 { 1.0 } else { 0.5 },
                    )
                })
                .collect();
            let d = |r| miner_damage(cycles.iter().copied(), &m.with_rule(r));
            let (o, e, h) = (
                d(MinerRule::Original),
                d(MinerRule::Elementary),
                d(MinerRule::Haibach),
            );
            assert!(e >= h && h >= o && o >= 0.0, "{e} {h} {o}");
        }
    }

    /// S_eq of n equal ranges P is P (n / N_eq)^(1/m) (MODEL.md section 7's check), and a
    /// spectrum's S_eq reproduces its damage on a single-slope curve: N_eq cycles of S_eq do
    /// the damage of the spectrum under Miner elementary when every amplitude is counted.
    #[test]
    fn damage_equivalent_load() {
        let (p, n, m, n_eq) = (950.0, 400.0, 6.2, 3e6);
        assert_relative_eq!(
            damage_equivalent([(p, n)], m, n_eq),
            p * (n / n_eq).powf(1.0 / m),
            max_relative = 1e-14
        );
        assert_eq!(damage_equivalent(std::iter::empty(), m, n_eq), 0.0);
        let mat = Material::default().with_rule(MinerRule::Elementary);
        let spectrum = [(300e6, 10.0), (500e6, 3.5), (100e6, 1000.0)];
        let s_eq = damage_equivalent(spectrum, mat.slope, mat.knee_cycles);
        assert_relative_eq!(
            miner_damage([(s_eq, mat.knee_cycles)], &mat),
            miner_damage(spectrum, &mat),
            max_relative = 1e-12
        );
    }
}
