//! The typed model of a pack as the engines see it: a shaft and its disc couplings.

use crate::clutch::{DrumModel, StackModel};
use crate::drive::Shaft;
use crate::law::ToothLaw;
use crate::spline::SplineGeometry;
use crate::spring::SpringDamper;
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
    /// Whether the disc may move radially on its spline (MODEL.md section 5): its joint to the
    /// shaft frees the two radial translations and only the teeth hold it (involute teeth
    /// push it back towards the axis under load). Default `false`: the radial translations
    /// are locked (a concentric disc, or an eccentric one with [`Self::initial_offset_m`]).
    #[serde(default)]
    pub radial_float: bool,
    /// Circumferential spacing error of each tooth pair at the pitch circle, in m, one per
    /// tooth (`n` values) or empty for none (the default). Tooth `k` sits at the angle
    /// `2 pi k / n` from the shaft frame's `+x` axis. Positive: the shaft's tooth `k` sits
    /// ahead of its nominal place in the positive rotation, so it closes the shaft-leads gap
    /// of that tooth pair and opens its disc-leads gap by this much at the pitch circle (by
    /// `e_k cos(alpha)` along the line of action).
    #[serde(default)]
    pub tooth_spacing_errors_m: Vec<f64>,
    /// Offset `(x, y)` of the disc's centre from the shaft axis at t = 0, in m, in the shaft's
    /// frame (which is the world frame at t = 0: the shaft starts at angle 0). Default
    /// `[0, 0]`. With [`Self::radial_float`] it is where the floating disc starts (moving
    /// with the shaft); without, the disc runs eccentric, held at this offset in the shaft's
    /// frame.
    #[serde(default)]
    pub initial_offset_m: [f64; 2],
}

impl DiscModel {
    /// Whether the disc is concentric with rigid, error-free teeth: no radial float, no
    /// offset, no spacing error. Then every tooth carries the same load and one rotational
    /// degree of freedom with the lumped law (MODEL.md sections 1-3) describes it exactly;
    /// otherwise only a per-tooth engine can (MODEL.md section 5).
    pub fn is_concentric(&self) -> bool {
        !self.radial_float
            && self.initial_offset_m == [0.0, 0.0]
            && self.tooth_spacing_errors_m.iter().all(|&e| e == 0.0)
    }

    /// The half free play in which the body may start with no tooth in contact, rad (>= 0):
    /// the half play `g0` less, along the line of action, the law's engagement offset (the
    /// film `h_o`, 0 for dry), the largest spacing error's `max|e_k| cos(alpha)` and the
    /// centre's offset `|e|`, divided by `Rb` (MODEL.md section 5). The one rule: the scene's
    /// validation refuses `|phi0|` at or beyond it, and ensembles place members inside it
    /// ([`ensemble_angle_rad`]).
    pub fn start_free_play_rad(&self) -> f64 {
        let rb = self.spline.base_radius_m();
        let worst = self
            .tooth_spacing_errors_m
            .iter()
            .fold(0f64, |m, e| m.max(e.abs()));
        let offset = self.initial_offset_m[0].hypot(self.initial_offset_m[1]);
        let reach_m =
            self.law.engagement_offset_m() + worst * self.spline.pressure_angle_rad.cos() + offset;
        (self.spline.half_play_rad() - reach_m / rb).max(0.0)
    }

    /// Spacing error of tooth `k` as an angle at the pitch circle, rad (`e_k / R`; 0 when
    /// the disc has no spacing errors).
    pub fn tooth_phase_error_rad(&self, k: usize) -> f64 {
        self.tooth_spacing_errors_m
            .get(k)
            .map_or(0.0, |e| e / self.spline.pitch_radius_m)
    }
}

/// Where member `k` of an evenly spread ensemble of `count` starts, rad: the fraction
/// `-1 + (2k + 1) / count` of 90 % of the body's [`DiscModel::start_free_play_rad`], so that
/// members are spread evenly and none starts in contact (`sweep --ensemble` and a study's
/// `initial_positions = "spread"` both use it).
pub fn ensemble_angle_rad(d: &DiscModel, k: u64, count: u64) -> f64 {
    let frac = -1.0 + (2 * k + 1) as f64 / count as f64;
    frac * 0.9 * d.start_free_play_rad()
}

/// A part of a pack that a torsional model (one rotational degree of freedom per friction
/// disc, identical teeth) does not describe: only a per-tooth, multibody engine runs it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NonTorsional {
    /// Disc `i` floats radially on its spline.
    RadialFloat(usize),
    /// Disc `i` starts off the axis.
    InitialOffset(usize),
    /// Disc `i` has tooth spacing errors.
    SpacingErrors(usize),
    /// Plate `j` floats radially, starts off the axis or has spacing errors.
    PlatePerTooth(usize),
}

/// A shaft and the discs coupled to it; in a whole pack (MODEL.md section 5) also the
/// separator plates, the output drum and the axial stack.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PackModel {
    /// The shaft.
    pub shaft: Shaft,
    /// The friction discs, each on its own spline coupling to the shaft.
    pub discs: Vec<DiscModel>,
    /// The separator plates, each on its own spline coupling to its carrier: the output drum
    /// when there is one (a clutch), else the fixed housing (a brake). Their `spline`, `law`,
    /// `initial_rel_angle_rad` (`theta_carrier - theta_plate`) and `initial_rel_speed_rad_s`
    /// refer to that carrier. Default none. With a [`Self::stack`] there are
    /// `discs.len() + 1` of them, alternating with the discs (`crate::clutch`).
    #[serde(default)]
    pub plates: Vec<DiscModel>,
    /// The output drum of a clutch (the plates' carrier); `None` (default): the plates sit on
    /// the housing (a brake).
    #[serde(default)]
    pub drum: Option<DrumModel>,
    /// The piston, the axial stack and the friction faces between discs and plates; `None`
    /// (default): no friction between them.
    #[serde(default)]
    pub stack: Option<StackModel>,
    /// Couplings between two of the pack's rotating bodies beyond the splines and the stack
    /// (MODEL.md section 8: a torsional spring-damper between the shaft and the drum), in
    /// scene order. Default none (and then not serialised, so that a pack without couplings
    /// writes what it wrote before they existed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub couplings: Vec<PackCoupling>,
}

/// A body of one pack that a [`PackCoupling`] can join: the bodies with a rotation of their
/// own besides the discs and plates. A driveline network names its bodies instead; here the
/// pack has these two.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PackBody {
    /// The shaft (prescribed or inertial, [`Shaft`]).
    Shaft,
    /// The output drum ([`PackModel::drum`]).
    Drum,
}

/// What a coupling does: one arm per kind (MODEL.md section 8; a lumped clutch and a gear
/// mesh are the next arms).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PackCouplingKind {
    /// A torsional spring-damper ([`SpringDamper`]).
    SpringDamper(SpringDamper),
}

/// A coupling between two bodies a and b of a pack (MODEL.md section 8): a term in both
/// bodies' equations, equal and opposite, in the crate's two-sided convention (the torque
/// reported is the one on b).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PackCoupling {
    /// Side a (receives the opposite of the reported torque).
    pub a: PackBody,
    /// Side b (receives the reported torque); not `a`.
    pub b: PackBody,
    /// The law.
    pub kind: PackCouplingKind,
}

/// The angle (rad) and speed (rad/s) of a body at one instant.
pub type BodyMotion = (f64, f64);

impl PackCoupling {
    /// The torque on b, N m, with a at `(theta_a, omega_a)` and b at `(theta_b, omega_b)`
    /// (rad, rad/s); a receives the opposite. Spring-damper: MODEL.md section 8,
    /// `k (theta_a - theta_b - theta_0) + d (omega_a - omega_b)`.
    pub fn torque_on_b_n_m(&self, a: BodyMotion, b: BodyMotion) -> f64 {
        match &self.kind {
            PackCouplingKind::SpringDamper(s) => s.torque_n_m(a.0 - b.0, a.1 - b.1),
        }
    }

    /// The energy the coupling stores at the angles `theta_a`, `theta_b` (rad), J (>= 0).
    pub fn potential_j(&self, theta_a: f64, theta_b: f64) -> f64 {
        match &self.kind {
            PackCouplingKind::SpringDamper(s) => s.potential_j(theta_a - theta_b),
        }
    }

    /// The power the coupling turns into heat at the speeds `omega_a`, `omega_b` (rad/s), W
    /// (>= 0).
    pub fn loss_rate_w(&self, omega_a: f64, omega_b: f64) -> f64 {
        match &self.kind {
            PackCouplingKind::SpringDamper(s) => s.loss_rate_w(omega_a - omega_b),
        }
    }

    /// The period of its own oscillation between bodies of the inertias `j_a`, `j_b` (kg m^2;
    /// infinite for a body whose motion is given), s: the time scale a multirate scheme's
    /// coupling step resolves. Spring-damper: `2 pi / w_n`, its undamped natural frequency
    /// (`SpringDamper::natural_frequency_rad_s`).
    pub fn period_s(&self, j_a_kg_m2: f64, j_b_kg_m2: f64) -> f64 {
        match &self.kind {
            PackCouplingKind::SpringDamper(s) => {
                2.0 * std::f64::consts::PI / s.natural_frequency_rad_s(j_a_kg_m2, j_b_kg_m2)
            }
        }
    }
}

/// The couplings' effect on the pack's shaft and drum at one instant
/// ([`PackModel::coupling_loads`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CouplingLoads {
    /// Sum of the couplings' torques on the shaft, N m (positive along the positive rotation).
    pub shaft_n_m: f64,
    /// Sum of the couplings' torques on the drum, N m (positive along the positive rotation).
    pub drum_n_m: f64,
    /// Energy stored in the couplings, J (>= 0).
    pub potential_j: f64,
    /// Power the couplings turn into heat, W (>= 0).
    pub loss_rate_w: f64,
}

/// The body a spline coupling joins a friction disc or separator plate to (MODEL.md section
/// 5): the one statement of it for both engines ([`PackModel::carrier`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Carrier {
    /// The shaft (friction discs).
    Shaft,
    /// The output drum (separator plates of a clutch).
    Drum,
    /// The fixed housing (separator plates of a brake): angle and speed 0.
    Housing,
}

impl PackModel {
    /// The carrier of coupling `i` in the engines' order (the friction discs `0..N`, then the
    /// separator plates): the shaft for a disc; for a plate the drum when the pack has one,
    /// else the housing.
    pub fn carrier(&self, i: usize) -> Carrier {
        if i < self.discs.len() {
            Carrier::Shaft
        } else if self.drum.is_some() {
            Carrier::Drum
        } else {
            Carrier::Housing
        }
    }

    /// Whether a torsional model (one rotational degree of freedom per body: shaft, discs,
    /// plates, drum; the lumped tooth law; the stack's faces with exact stick and slip)
    /// describes the pack and the reference engine runs it: every disc and plate
    /// [`DiscModel::is_concentric`].
    /// Engines choose by it (the reference engine refuses a pack that is not).
    pub fn is_torsional(&self) -> bool {
        self.non_torsional_parts().is_empty()
    }

    /// Every body the pack's splines carry, in the engines' order: its friction discs, then
    /// its separator plates.
    pub fn bodies(&self) -> impl Iterator<Item = &DiscModel> {
        self.discs.iter().chain(&self.plates)
    }

    /// The names of [`Self::bodies`], in that order.
    pub fn body_names(&self) -> Vec<String> {
        self.bodies().map(|d| d.name.clone()).collect()
    }

    /// Whether the pack has separator plates, a drum, a stack or couplings (a whole pack,
    /// MODEL.md sections 5 and 8), beyond friction discs on a shaft.
    pub fn is_whole(&self) -> bool {
        !self.plates.is_empty()
            || self.drum.is_some()
            || self.stack.is_some()
            || !self.couplings.is_empty()
    }

    /// Every part of the pack that the torsional engine does not run (MODEL.md section 5), in
    /// order: per disc its radial float, offset and spacing errors, then each plate with any of
    /// them. Empty exactly when [`Self::is_torsional`]. The one statement of what the
    /// reference engine cannot run; the CLI's engine choice and `check --engine` read it.
    pub fn non_torsional_parts(&self) -> Vec<NonTorsional> {
        let mut out = Vec::new();
        for (i, d) in self.discs.iter().enumerate() {
            if d.radial_float {
                out.push(NonTorsional::RadialFloat(i));
            }
            if d.initial_offset_m != [0.0, 0.0] {
                out.push(NonTorsional::InitialOffset(i));
            }
            if d.tooth_spacing_errors_m.iter().any(|&e| e != 0.0) {
                out.push(NonTorsional::SpacingErrors(i));
            }
        }
        for (j, p) in self.plates.iter().enumerate() {
            if !p.is_concentric() {
                out.push(NonTorsional::PlatePerTooth(j));
            }
        }
        out
    }

    /// A pack of a shaft and friction discs only (no plates, drum, stack or couplings).
    pub fn new(shaft: Shaft, discs: Vec<DiscModel>) -> PackModel {
        PackModel {
            shaft,
            discs,
            plates: Vec::new(),
            drum: None,
            stack: None,
            couplings: Vec::new(),
        }
    }

    /// What the [`Self::couplings`] do with the shaft at `shaft` and the drum at `drum`
    /// (angle in rad, speed in rad/s; the drum's ignored without couplings on it): the
    /// torques on each, the energy stored, the power lost. The one evaluation both engines
    /// use (MODEL.md section 8: each coupling's torque `T` on its b, `-T` on its a).
    pub fn coupling_loads(&self, shaft: BodyMotion, drum: BodyMotion) -> CouplingLoads {
        let mut out = CouplingLoads::default();
        let motion = |body: PackBody| match body {
            PackBody::Shaft => shaft,
            PackBody::Drum => drum,
        };
        for c in &self.couplings {
            let (a, b) = (motion(c.a), motion(c.b));
            let t = c.torque_on_b_n_m(a, b);
            for (body, torque) in [(c.a, -t), (c.b, t)] {
                match body {
                    PackBody::Shaft => out.shaft_n_m += torque,
                    PackBody::Drum => out.drum_n_m += torque,
                }
            }
            out.potential_j += c.potential_j(a.0, b.0);
            out.loss_rate_w += c.loss_rate_w(a.1, b.1);
        }
        out
    }
}

/// Outer radius in m of a flat annulus of inner radius `inner_m` (m), thickness
/// `thickness_m` (m) and density `density_kg_m3` whose inertia about its axis is
/// `inertia_kg_m2`: from `J = rho pi t (Ro^4 - Ri^4) / 2`,
/// `Ro = (Ri^4 + 2 J / (rho pi t))^(1/4)`. Used to give a disc of the scene's inertia a body
/// (the multibody engine's mass properties, the recordings' drawings).
pub fn annulus_outer_radius_m(
    inertia_kg_m2: f64,
    inner_m: f64,
    thickness_m: f64,
    density_kg_m3: f64,
) -> f64 {
    (inner_m.powi(4) + 2.0 * inertia_kg_m2 / (density_kg_m3 * std::f64::consts::PI * thickness_m))
        .powf(0.25)
}

/// Inner radius in m of the same annulus given its outer radius `outer_m` (m): `Ri = (Ro^4 -
/// 2 J / (rho pi t))^(1/4)`; `None` when even a full disc of radius `outer_m` has less
/// inertia than `inertia_kg_m2`. Used for separator plates, whose spline is on the outside.
pub fn annulus_inner_radius_m(
    inertia_kg_m2: f64,
    outer_m: f64,
    thickness_m: f64,
    density_kg_m3: f64,
) -> Option<f64> {
    let r4 = outer_m.powi(4)
        - 2.0 * inertia_kg_m2 / (density_kg_m3 * std::f64::consts::PI * thickness_m);
    (r4 >= 0.0).then(|| r4.powf(0.25))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The two annulus radii invert each other, and give back the inertia of the closed form
    /// `J = rho pi t (Ro^4 - Ri^4) / 2` (MODEL.md section 4's disc: J2 = 0.156 kg m^2,
    /// Ri = 0.231 m, 3 mm of steel: Ro = 0.290 m).
    #[test]
    fn annulus_radii() {
        let (j, ri, t, rho) = (0.156, 0.231, 3e-3, 7850.0);
        let ro = annulus_outer_radius_m(j, ri, t, rho);
        assert!((ro - 0.290).abs() < 1e-3, "{ro}");
        let j_back = rho * std::f64::consts::PI * t * (ro.powi(4) - ri.powi(4)) / 2.0;
        assert!((j_back - j).abs() < 1e-12 * j);
        let ri_back = annulus_inner_radius_m(j, ro, t, rho).unwrap();
        assert!((ri_back - ri).abs() < 1e-12);
        assert_eq!(annulus_inner_radius_m(10.0, 0.1, t, rho), None);
    }
    use crate::drive::SpeedProfile;
    use crate::law::{Hertz, LawKind, OilFilm};

    fn disc() -> DiscModel {
        DiscModel {
            name: "d".into(),
            spline: SplineGeometry {
                teeth: 4,
                pitch_radius_m: 0.1,
                pressure_angle_rad: 0.3,
                backlash_m: 1e-3,
            },
            law: ToothLaw {
                kind: LawKind::Dry,
                hertz: Hertz {
                    modulus_pa: 210e9,
                    curvature_radius_m: 1e-3,
                    loss_coefficient_s_m: 0.0,
                },
                oil: OilFilm {
                    thickness_m: 0.0,
                    viscosity_pa_s: 0.0,
                    leakage_coefficient: 0.0,
                    width_m: 0.0,
                    length_m: 0.0,
                    v_floor_m_s: 0.01,
                    h_min_m: 1e-6,
                },
            },
            inertia_kg_m2: 0.1,
            drag_n_m_s_rad: 0.0,
            initial_rel_angle_rad: 0.0,
            initial_rel_speed_rad_s: 0.0,
            radial_float: false,
            tooth_spacing_errors_m: Vec::new(),
            initial_offset_m: [0.0, 0.0],
        }
    }

    /// Any radial float, offset or non-zero spacing error makes a disc non-concentric (and the
    /// pack non-torsional); all-zero spacing errors are no errors.
    #[test]
    fn concentric_means_no_per_tooth_effect() {
        let mut pack = PackModel {
            shaft: Shaft::Prescribed(SpeedProfile::sine(100.0, 1.0, 10.0)),
            discs: vec![disc()],
            plates: Vec::new(),
            drum: None,
            stack: None,
            couplings: Vec::new(),
        };
        assert!(pack.is_torsional());
        pack.discs[0].tooth_spacing_errors_m = vec![0.0; 4];
        assert!(pack.is_torsional());
        pack.discs[0].tooth_spacing_errors_m[2] = 2e-6;
        assert!(!pack.is_torsional());
        // 2 um at R = 0.1 m is 2e-5 rad
        assert_eq!(pack.discs[0].tooth_phase_error_rad(2), 2e-6 / 0.1);
        assert_eq!(pack.discs[0].tooth_phase_error_rad(1), 0.0);
        let mut d = disc();
        d.radial_float = true;
        assert!(!d.is_concentric());
        let mut d = disc();
        d.initial_offset_m = [0.0, -1e-6];
        assert!(!d.is_concentric());
    }

    /// A spring-damper from the shaft (a) to the drum (b): equal and opposite torques, `T`
    /// on the drum; its potential and loss; with a and b swapped, the same pair of torques
    /// for the opposite twist convention; its period between two inertias and against a
    /// prescribed body (the closed forms to rounding, 1e-12).
    #[test]
    fn coupling_loads_are_equal_and_opposite() {
        let spring = SpringDamper {
            stiffness_n_m_per_rad: 100.0,
            damping_n_m_s_per_rad: 2.0,
            free_angle_rad: 0.1,
        };
        let mut pack = PackModel::new(Shaft::Prescribed(SpeedProfile::sine(1.0, 0.0, 1.0)), vec![]);
        assert_eq!(
            pack.coupling_loads((1.0, 2.0), (0.0, 0.0)),
            CouplingLoads::default()
        );
        pack.couplings.push(PackCoupling {
            a: PackBody::Shaft,
            b: PackBody::Drum,
            kind: PackCouplingKind::SpringDamper(spring),
        });
        let l = pack.coupling_loads((0.3, 5.0), (0.1, 4.0));
        // k (0.3 - 0.1 - 0.1) + d (5 - 4) = 10 + 2
        assert!((l.drum_n_m - 12.0).abs() < 1e-12);
        assert_eq!(l.shaft_n_m, -l.drum_n_m);
        assert!((l.potential_j - 0.5).abs() < 1e-12);
        assert!((l.loss_rate_w - 2.0).abs() < 1e-12);
        pack.couplings[0].a = PackBody::Drum;
        pack.couplings[0].b = PackBody::Shaft;
        let l = pack.coupling_loads((0.3, 5.0), (0.1, 4.0));
        // k (0.1 - 0.3 - 0.1) + d (4 - 5) = -30 - 2 on the shaft
        assert!((l.shaft_n_m + 32.0).abs() < 1e-12);
        assert_eq!(l.drum_n_m, -l.shaft_n_m);
        // its period: 2 pi / sqrt(k (1/J_a + 1/J_b)), k = 100 N m/rad, J = 1 and 4 kg m^2
        // (sqrt(125) rad/s), and with a prescribed (infinite) a, sqrt(25) = 5 rad/s
        let c = &pack.couplings[0];
        let period = c.period_s(1.0, 4.0);
        assert!((period - 2.0 * std::f64::consts::PI / 125f64.sqrt()).abs() < 1e-12);
        let period = c.period_s(f64::INFINITY, 4.0);
        assert!((period - 2.0 * std::f64::consts::PI / 5.0).abs() < 1e-12);
    }
}
