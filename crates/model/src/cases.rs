//! Named test cases with known answers, built in code (independent of the scene parser), so
//! that every engine's tests, benches and the CLI's benchmark run the same definitions: the
//! paper case (MODEL.md section 4), the closed-form free impact, the benchmark disc of
//! `scenes/bench-8-disc.toml`, the staggered N-disc pack of issue 9 and the two inertias
//! joined by a spring-damper (MODEL.md section 8).
//!
//! Every value here is either from Hu et al. Table 2, from MODEL.md section 4's assumed
//! values, or from `scenes/bench-8-disc.toml`; each function says which.

use crate::clutch::{DrumModel, FrictionCurve, OpenGap, Piston, PressureProfile, StackModel};
use crate::drive::{Shaft, ShaftExcitation, SpeedProfile};
use crate::law::{Hertz, LawKind, OilFilm, ToothLaw};
use crate::pack::{DiscModel, PackModel};
use crate::pack::{PackBody, PackCoupling, PackCouplingKind};
use crate::spline::{Flank, SplineGeometry};
use crate::spring::SpringDamper;

mod packs;
pub use packs::{
    engaging_clutch, pack_as_network, prescribed_clutch, prescribed_clutch_against_closed_form,
    wet_clutch, PrescribedClutchObserver, PRESCRIBED_CLUTCH_ACCEL_RAD_S2,
    PRESCRIBED_CLUTCH_DURATION_S, PRESCRIBED_CLUTCH_J_KG_M2, PRESCRIBED_CLUTCH_TORQUE_N_M,
    PRESCRIBED_CLUTCH_W0_RAD_S,
};

/// Mean shaft speed of the paper case, rad/s (MODEL.md section 4, assumed).
pub const PAPER_OMEGA0_RAD_S: f64 = 200.0;
/// Fluctuation amplitude `A` of the paper case, rad/s (Table 2).
pub const PAPER_AMPLITUDE_RAD_S: f64 = 4.378;
/// Fluctuation frequency `f` of the paper case, Hz (Table 2).
pub const PAPER_FREQUENCY_HZ: f64 = 104.0;
/// Disc inertia `J2` of the paper case, kg m^2 (MODEL.md section 4, assumed: a steel annulus
/// 0.231 to 0.290 m, 3 mm thick).
pub const PAPER_INERTIA_KG_M2: f64 = 0.156;
/// Oil drag `C2` on the paper case's disc, N m s/rad (MODEL.md section 4, assumed).
pub const PAPER_DRAG_N_M_S_RAD: f64 = 0.01;

/// The spline of Hu et al. Table 2: `n = 154`, `R = 0.231 m`, `alpha = 20 deg`,
/// `d = 0.75 mm`.
pub fn paper_spline() -> SplineGeometry {
    SplineGeometry {
        teeth: 154,
        pitch_radius_m: 0.231,
        pressure_angle_rad: 20f64.to_radians(),
        backlash_m: 0.75e-3,
    }
}

/// The paper's tooth law of kind `kind` with film thickness `h_o_m` (m): Table 2's `E`,
/// `eta`, `beta`, and MODEL.md section 4's assumed `r = 1.75 mm`, `p = 0.8 s/m`,
/// `B = L = 3 mm`, `v_floor = 0.01 m/s` (and `h_min = 1 um` for the squeeze law).
pub fn paper_law(kind: LawKind, h_o_m: f64) -> ToothLaw {
    ToothLaw {
        kind,
        hertz: Hertz {
            modulus_pa: 210e9,
            curvature_radius_m: 1.75e-3,
            loss_coefficient_s_m: 0.8,
        },
        oil: OilFilm {
            thickness_m: h_o_m,
            viscosity_pa_s: 289.1,
            leakage_coefficient: 0.421,
            width_m: 3e-3,
            length_m: 3e-3,
            v_floor_m_s: 0.01,
            h_min_m: 1e-6,
        },
    }
}

/// The paper's drive, eq (3): `omega = 200 + 4.378 sin(2 pi 104 t)` rad/s.
pub fn paper_drive() -> SpeedProfile {
    SpeedProfile::sine(
        PAPER_OMEGA0_RAD_S,
        PAPER_AMPLITUDE_RAD_S,
        PAPER_FREQUENCY_HZ,
    )
}

/// The paper case's disc (named `"disc"`) with the paper law at film thickness `h_o_m` (m),
/// centred in the backlash at the shaft's speed.
pub fn paper_disc(h_o_m: f64) -> DiscModel {
    DiscModel {
        name: "disc".into(),
        spline: paper_spline(),
        law: paper_law(LawKind::Paper, h_o_m),
        inertia_kg_m2: PAPER_INERTIA_KG_M2,
        drag_n_m_s_rad: PAPER_DRAG_N_M_S_RAD,
        initial_rel_angle_rad: 0.0,
        initial_rel_speed_rad_s: 0.0,
        radial_float: false,
        tooth_spacing_errors_m: Vec::new(),
        initial_offset_m: [0.0, 0.0],
    }
}

/// The paper case (MODEL.md section 4): [`paper_disc`] on a shaft prescribed by
/// [`paper_drive`], at film thickness `h_o_m` (m).
pub fn paper_pack(h_o_m: f64) -> PackModel {
    PackModel::new(Shaft::Prescribed(paper_drive()), vec![paper_disc(h_o_m)])
}

/// The first five impacts of the paper case at `h_o = 0` as MODEL.md section 4 gives them
/// (an independent solver at tight tolerance, rounded to 5-6 digits): `(signed per-tooth
/// peak N, time of the peak ms)`; a negative peak means the shaft leads.
pub const PAPER_FIRST_IMPACTS_0UM: [(f64, f64); 5] = [
    (-637.25, 1.11283),
    (505.69, 3.79487),
    (406.64, 5.24908),
    (223.43, 6.68250),
    (-742.83, 8.93890),
];

/// The first five impacts of the paper case at `h_o = 25 um` (MODEL.md section 4), as
/// [`PAPER_FIRST_IMPACTS_0UM`].
pub const PAPER_FIRST_IMPACTS_25UM: [(f64, f64); 5] = [
    (-562.01, 1.07505),
    (432.57, 3.80995),
    (344.31, 5.22235),
    (186.73, 6.59753),
    (-638.10, 8.89408),
];

/// Onset and separation of the first contact of the paper case at `h_o = 0`, ms (MODEL.md
/// section 4).
pub const PAPER_FIRST_CONTACT_0UM_MS: (f64, f64) = (1.08545, 1.16034);

/// The published peaks of the paper case (per tooth, N): `(h_o m, max positive, max
/// negative)` (MODEL.md section 4; a correct implementation lands within about 10 %).
pub const PAPER_PUBLISHED_PEAKS: [(f64, f64, f64); 3] = [
    (0.0, 945.39, -976.42),
    (25e-6, 867.6, -867.8),
    (50e-6, 503.1, -503.5),
];

/// One free, undamped impact with its closed-form answer (MODEL.md section 4).
#[derive(Debug, Clone, PartialEq)]
pub struct FreeImpact {
    /// The pack: the paper disc with no drag and `p = 0`, on a shaft at a constant
    /// 100 rad/s, starting 0.1 um (along the line of action) before engagement on the
    /// shaft-leads flank, closing at `v0`.
    pub pack: PackModel,
    /// Closing speed `v0` at engagement, m/s.
    pub v0_m_s: f64,
    /// Stiffness `K` of the event, N/m^1.5 (the law's, with `dv = v0`).
    pub stiffness: f64,
    /// Effective mass `m_eff = J2 / (n Rb^2)`, kg.
    pub m_eff_kg: f64,
    /// Closed-form peak per-tooth load magnitude, N: `K^(2/5) (5/4 m_eff v0^2)^(3/5)`. The
    /// shaft leads, so the engines report it negative.
    pub peak_n: f64,
    /// The flank struck.
    pub flank: Flank,
}

/// The free impact of the paper disc under law `kind` at film thickness `h_o_m` (m), closing
/// at `v0_m_s` (m/s): no drive fluctuation, no drag, no loss (`p = 0`). The contact is
/// conservative, so the disc leaves at `v0` too.
pub fn free_impact(kind: LawKind, h_o_m: f64, v0_m_s: f64) -> FreeImpact {
    let mut disc = paper_disc(h_o_m);
    disc.law = paper_law(kind, h_o_m);
    disc.law.hertz.loss_coefficient_s_m = 0.0;
    disc.drag_n_m_s_rad = 0.0;
    let rb = disc.spline.base_radius_m();
    let g0 = disc.spline.half_play_rad();
    // start 0.1 um (along the line of action) before engagement, closing at v0
    disc.initial_rel_angle_rad = g0 - (h_o_m + 1e-7) / rb;
    disc.initial_rel_speed_rad_s = v0_m_s / rb;
    let stiffness = disc
        .law
        .engage(&disc.spline.kinematics(g0, v0_m_s / rb))
        .stiffness;
    let m_eff_kg = disc.spline.effective_mass_kg(disc.inertia_kg_m2);
    FreeImpact {
        pack: PackModel::new(
            Shaft::Prescribed(SpeedProfile::sine(100.0, 0.0, 1.0)),
            vec![disc],
        ),
        v0_m_s,
        stiffness,
        m_eff_kg,
        peak_n: crate::free_impact_peak_n(stiffness, m_eff_kg, v0_m_s),
        flank: Flank::ShaftLeads,
    }
}

/// Inertia of the benchmark disc, kg m^2: a steel annulus (7850 kg/m^3), inner radius
/// 0.231 m, outer 0.300 m, 3 mm thick (`scenes/bench-8-disc.toml`).
pub const BENCH_INERTIA_KG_M2: f64 = 0.194306;

/// The benchmark's drive: `omega = 100 + 4.378 sin(2 pi 104 t)` rad/s
/// (`scenes/bench-8-disc.toml`).
pub fn bench_drive() -> SpeedProfile {
    SpeedProfile::sine(100.0, PAPER_AMPLITUDE_RAD_S, PAPER_FREQUENCY_HZ)
}

/// The disc of `scenes/bench-8-disc.toml`, named `name`: the paper's spline, the dry law with
/// `E = 210 GPa`, `r = 5 mm`, `p = 0.5 s/m` (the oil fields are the paper's and unused),
/// [`BENCH_INERTIA_KG_M2`], no drag, centred in the backlash at the shaft's speed.
pub fn bench_disc(name: &str) -> DiscModel {
    let mut law = paper_law(LawKind::Dry, 0.0);
    law.hertz.curvature_radius_m = 5e-3;
    law.hertz.loss_coefficient_s_m = 0.5;
    DiscModel {
        name: name.into(),
        spline: paper_spline(),
        law,
        inertia_kg_m2: BENCH_INERTIA_KG_M2,
        drag_n_m_s_rad: 0.0,
        initial_rel_angle_rad: 0.0,
        initial_rel_speed_rad_s: 0.0,
        radial_float: false,
        tooth_spacing_errors_m: Vec::new(),
        initial_offset_m: [0.0, 0.0],
    }
}

/// `scenes/bench-8-disc.toml` with `n` discs (`disc-1` ... `disc-n`): all centred, so they
/// strike in step and cost what one disc costs (a case no real pack is in).
pub fn bench_pack(n: usize) -> PackModel {
    PackModel::new(
        Shaft::Prescribed(bench_drive()),
        (1..=n).map(|k| bench_disc(&format!("disc-{k}"))).collect(),
    )
}

/// Initial relative angle of disc `i` (0-based) of `n` staggered discs, rad, for a half play
/// `g0_rad` (rad): `phi_i = -0.8 g0 (2 (i + 1/2) / n - 1)`, evenly spread across +-0.8 of the
/// free play (issue 9).
pub fn staggered_rel_angle_rad(i: usize, n: usize, g0_rad: f64) -> f64 {
    -0.8 * g0_rad * (2.0 * (i as f64 + 0.5) / n as f64 - 1.0)
}

/// The open brake of issues 20 and 21: [`staggered_pack`]`(n)` with `n + 1` separator plates
/// on the fixed housing (`plate-1` ... `plate-(n+1)`: 0.1382 kg m^2, 132 teeth at 0.305 m, 30
/// deg, 0.5 mm backlash, the discs' dry law, no drag, centred at rest), stacked plate, disc,
/// plate, ..., plate, and the open stack's Couette drag between neighbours (0.01 Pa s across
/// 1 mm, faces 0.235-0.290 m; the piston released). The pack
/// `bench/mujoco/brake.py` times in MuJoCo.
pub fn staggered_brake(n: usize) -> PackModel {
    let mut pack = staggered_pack(n);
    pack.plates = (0..=n)
        .map(|j| {
            let mut p = bench_disc(&format!("plate-{}", j + 1));
            p.inertia_kg_m2 = 0.1382;
            p.spline = SplineGeometry {
                teeth: 132,
                pitch_radius_m: 0.305,
                pressure_angle_rad: 30f64.to_radians(),
                backlash_m: 0.5e-3,
            };
            p
        })
        .collect();
    pack.stack = Some(StackModel {
        face_friction: Vec::new(),
        face_inner_radius_m: 0.235,
        face_outer_radius_m: 0.290,
        friction: FrictionCurve::Stribeck {
            static_mu: 0.10,
            kinetic_mu: 0.13,
            stribeck_speed_m_s: 0.5,
            viscous_slope_s_m: 0.0,
        },
        piston: Piston {
            area_m2: 0.05,
            pressure: PressureProfile::Constant { pressure_pa: 0.0 },
            return_spring_n: 2000.0,
        },
        open_gap: Some(OpenGap {
            viscosity_pa_s: 0.01,
            gap_m: 1e-3,
        }),
        spline_friction: 0.0,
    });
    pack
}

/// The staggered pack of issue 9: `n` benchmark discs ([`bench_disc`], `disc-1` ...
/// `disc-n`) on the benchmark's prescribed shaft, disc `i` started at
/// [`staggered_rel_angle_rad`] at rest relative to the shaft, so that they strike out of
/// step, as the discs of a real pack do. `scenes/staggered-8-disc.toml` and
/// `scenes/staggered-16-disc.toml` are this pack for 8 and 16 discs.
pub fn staggered_pack(n: usize) -> PackModel {
    let g0 = paper_spline().half_play_rad();
    PackModel::new(
        Shaft::Prescribed(bench_drive()),
        (0..n)
            .map(|i| {
                let mut d = bench_disc(&format!("disc-{}", i + 1));
                d.initial_rel_angle_rad = staggered_rel_angle_rad(i, n, g0);
                d
            })
            .collect(),
    )
}

/// [`staggered_pack`] on an inertial shaft (eq 4): `J1 = 2 kg m^2`, undamped, driven by the
/// torque `J1 d(omega)/dt` of [`bench_drive`] and starting at its speed (issue 20's
/// inertial-shaft pack).
pub fn staggered_inertial(n: usize) -> PackModel {
    let mut pack = staggered_pack(n);
    pack.shaft = Shaft::Inertial {
        inertia_kg_m2: 2.0,
        damping_n_m_s_rad: 0.0,
        excitation: crate::drive::ShaftExcitation::Profile(bench_drive()),
    };
    pack
}

/// Inertia of the shaft of [`spring_pair`], kg m^2.
pub const SPRING_PAIR_SHAFT_KG_M2: f64 = 0.5;
/// Inertia of the drum of [`spring_pair`], kg m^2.
pub const SPRING_PAIR_DRUM_KG_M2: f64 = 0.3;

/// Two inertias joined by a torsional spring-damper (MODEL.md section 8), released from a
/// twist: an inertial shaft of [`SPRING_PAIR_SHAFT_KG_M2`] (or, with `prescribed`, a shaft
/// held at its speed) and a drum of [`SPRING_PAIR_DRUM_KG_M2`], both at 100 rad/s, no drive,
/// load or drag; `spring` from the shaft (a) to the drum (b), its free angle the twist
/// (both start at angle 0). The splines are there only because a pack has them: one disc on
/// the shaft and one plate on the drum, 4 teeth with a half play of 0.3 rad, no drag, at
/// rest relative to their carriers, so that they never touch while the twist stays within
/// 0.3 rad (the closed forms hold: `SpringDamper::natural_frequency_rad_s` and
/// `SpringDamper::damping_ratio` of the two inertias, the shaft's infinite when prescribed).
pub fn spring_pair(spring: SpringDamper, prescribed: bool) -> PackModel {
    let omega0 = 100.0;
    let free = |name: &str, inertia: f64| {
        let mut d = paper_disc(0.0);
        d.name = name.into();
        d.spline.teeth = 4;
        // half play g0 = d / (2 R) = 0.3 rad, within half a pitch (pi / 4)
        d.spline.backlash_m = 2.0 * d.spline.pitch_radius_m * 0.3;
        d.inertia_kg_m2 = inertia;
        d.drag_n_m_s_rad = 0.0;
        d
    };
    let profile = SpeedProfile::sine(omega0, 0.0, 1.0);
    let shaft = if prescribed {
        Shaft::Prescribed(profile)
    } else {
        Shaft::Inertial {
            inertia_kg_m2: SPRING_PAIR_SHAFT_KG_M2,
            damping_n_m_s_rad: 0.0,
            excitation: ShaftExcitation::Profile(profile),
        }
    };
    let mut pack = PackModel::new(shaft, vec![free("disc", 0.156)]);
    pack.plates = vec![free("plate", 0.138)];
    pack.drum = Some(DrumModel {
        inertia_kg_m2: SPRING_PAIR_DRUM_KG_M2,
        load_torque_n_m: 0.0,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: omega0,
    });
    pack.couplings = vec![PackCoupling {
        a: PackBody::Shaft,
        b: PackBody::Drum,
        kind: PackCouplingKind::SpringDamper(spring),
    }];
    pack
}

/// Modelica's `Rotational.Examples.CoupledClutches` (MSL 4.0) as a network (MODEL.md section
/// 8): four unit inertias in a row (`J1` at 10 rad/s, the others at rest), a torque
/// `10 sin(2 pi 5 t)` N m on `J1`, and three clutches between them (`mu = 0.5`, `peak = 1.1`,
/// `cgeo = 1`, `fn_max = 20` N) applied by `cos(2 pi 0.2 t)` (clutch1), a step to 1 at 0.4 s
/// (clutch2) and one at 0.9 s (clutch3). Its reference results are in
/// `crates/reference/tests/network.rs`.
pub fn coupled_clutches() -> crate::network::Network {
    use crate::network::{Body, Coupling, CouplingKind, LumpedClutch, Motion, Network, Signal};
    let body = |name: &str, w: f64, drive: Option<Signal>| Body {
        name: name.into(),
        inertia_kg_m2: 1.0,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: w,
        motion: Motion::Free,
        drive,
        firing: None,
        road_load: None,
    };
    let clutch = |name: &str, a: usize, force: Signal| Coupling {
        name: name.into(),
        a,
        b: a + 1,
        kind: CouplingKind::Clutch(LumpedClutch {
            mu_table: vec![(0.0, 0.5)],
            peak: 1.1,
            cgeo_m: 1.0,
            fn_max_n: 20.0,
            force,
            one_way: false,
        }),
    };
    let step = |start_s: f64| Signal::Step {
        offset: 0.0,
        height: 1.0,
        start_s,
    };
    Network {
        pack_thermal: Default::default(),
        bodies: vec![
            body(
                "J1",
                10.0,
                Some(Signal::Sine {
                    offset: 0.0,
                    amplitude: 10.0,
                    frequency_hz: 5.0,
                    phase_rad: 0.0,
                    start_s: 0.0,
                }),
            ),
            body("J2", 0.0, None),
            body("J3", 0.0, None),
            body("J4", 0.0, None),
        ],
        couplings: vec![
            clutch(
                "clutch1",
                0,
                Signal::Sine {
                    offset: 0.0,
                    amplitude: 1.0,
                    frequency_hz: 0.2,
                    phase_rad: std::f64::consts::FRAC_PI_2,
                    start_s: 0.0,
                },
            ),
            clutch("clutch2", 1, step(0.4)),
            clutch("clutch3", 2, step(0.9)),
        ],
    }
}

/// A dry steel gear mesh (MODEL.md section 8): base radii 30 and 90 mm, 0.1 mm of backlash,
/// one pair of teeth in contact, the section 2 Hertz law (210 GPa, 5 mm curvature, no loss),
/// no oil; at its free play's centre (`initial_offset_m` 0). `internal`: a ring gear.
pub fn dry_gear_mesh(internal: bool) -> crate::network::GearMesh {
    crate::network::GearMesh {
        base_radius_a_m: 0.03,
        base_radius_b_m: 0.09,
        internal,
        backlash_m: 1e-4,
        pairs: 1.0,
        initial_offset_m: 0.0,
        law: ToothLaw {
            kind: LawKind::Dry,
            hertz: Hertz {
                modulus_pa: 210e9,
                curvature_radius_m: 5e-3,
                loss_coefficient_s_m: 0.0,
            },
            oil: OilFilm {
                thickness_m: 0.0,
                viscosity_pa_s: 0.0,
                leakage_coefficient: 0.421,
                width_m: 1e-2,
                length_m: 1e-2,
                v_floor_m_s: 0.01,
                h_min_m: 1e-7,
            },
        },
    }
}

/// A spring-damper between two free inertias released from a twist (MODEL.md section 8): `a`
/// of 0.5 kg m^2 and `b` of 0.3 kg m^2 both at angle 0 and 1 rad/s, joined by `k` = 2000
/// N m/rad and `d` = 0.8 N m s/rad whose free angle is `-q0` (so the spring starts twisted by
/// [`RING_DOWN_TWIST_RAD`]). Its twist `theta_a - theta_b + q0` follows the damped
/// oscillator's closed form `q(t) = q0 e^(-zeta wn t) (cos wd t + zeta wn / wd sin wd t)` with
/// `wn^2 = k (1/J_a + 1/J_b)`, `2 zeta wn = d (1/J_a + 1/J_b)`.
pub fn spring_ring_down() -> crate::network::Network {
    use crate::network::{Body, Coupling, CouplingKind, Motion, Network};
    let body = |name: &str, j: f64| Body {
        name: name.into(),
        inertia_kg_m2: j,
        drag_n_m_s_rad: 0.0,
        // a body nothing moves is refused; a speed common to both changes nothing in the twist
        initial_speed_rad_s: 1.0,
        motion: Motion::Free,
        drive: None,
        firing: None,
        road_load: None,
    };
    Network {
        pack_thermal: Default::default(),
        bodies: vec![body("a", 0.5), body("b", 0.3)],
        couplings: vec![Coupling {
            name: "damper".into(),
            a: 0,
            b: 1,
            kind: CouplingKind::SpringDamper(SpringDamper {
                stiffness_n_m_per_rad: 2000.0,
                damping_n_m_s_per_rad: 0.8,
                free_angle_rad: -RING_DOWN_TWIST_RAD,
            }),
        }],
    }
}

/// The twist `q0` that [`spring_ring_down`] starts from, rad.
pub const RING_DOWN_TWIST_RAD: f64 = 0.02;

/// The twist of [`spring_ring_down`] at `t` (s) by the damped oscillator's closed form, rad.
pub fn spring_ring_down_twist_rad(t: f64) -> f64 {
    let net = spring_ring_down();
    let (j_a, j_b) = (net.bodies[0].inertia_kg_m2, net.bodies[1].inertia_kg_m2);
    let crate::network::CouplingKind::SpringDamper(sd) = net.couplings[0].kind else {
        unreachable!()
    };
    let inv = 1.0 / j_a + 1.0 / j_b;
    let wn = (sd.stiffness_n_m_per_rad * inv).sqrt();
    let zeta = sd.damping_n_m_s_per_rad * inv / (2.0 * wn);
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let q0 = RING_DOWN_TWIST_RAD;
    q0 * (-zeta * wn * t).exp() * ((wd * t).cos() + zeta * wn / wd * (wd * t).sin())
}

/// An engine alone on its firing harmonics (MODEL.md section 8; [`crate::network::Firing`]):
/// a four-stroke four-cylinder crank and flywheel of 0.25 kg m^2 at 100 rad/s, no mean torque,
/// no drag, the firing order's first two multiples (120 N m and 30 N m, phases 0.3 and -1.0
/// rad). Its torque is `-dV/dtheta`, so its speed is known at every angle:
/// `w(theta)^2 = w0^2 + 2 (V(0) - V(theta)) / J`.
pub fn firing_engine() -> crate::network::Network {
    use crate::network::{Body, Firing, Motion, Network};
    Network {
        pack_thermal: Default::default(),
        bodies: vec![Body {
            name: "engine".into(),
            inertia_kg_m2: 0.25,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 100.0,
            motion: Motion::Free,
            drive: None,
            firing: Some(Firing {
                cylinders: 4,
                strokes: 4,
                amplitudes_n_m: vec![120.0, 30.0],
                phases_rad: vec![0.3, -1.0],
            }),
            road_load: None,
        }],
        couplings: Vec::new(),
    }
}

/// The ZF 8HP's structure (MODEL.md section 10: four simple planetary sets of the published
/// tooth counts S1/R1 48/96, S2/R2 48/96, S3/R3 69/111, S4/R4 23/85; S1 joined to S2, C1 to
/// R4, R2 to S3, R3 to S4; the input on C2, the output on C4) with its five shift elements
/// (brakes A on S1-S2 and B on R1, clutches C from the input to S4, D from C3 to the output,
/// E from S3 to S4), every body of unit inertia, and its gear table (1st ABC, 2nd ABE, 3rd BCE,
/// 4th BDE, 5th BCD, 6th CDE, 7th ACD, 8th ADE, reverse ABD). The elements are lumped clutches
/// without force: the kinematics need only which are closed.
pub fn eight_speed() -> (crate::network::Network, crate::network::Transmission) {
    use crate::network::{
        Body, Coupling, CouplingKind, Gear, LumpedClutch, Motion, Network, PlanetarySet, Signal,
        Transmission,
    };
    let names = [
        "input", "output", "S1S2", "R1", "C1R4", "R2S3", "R3S4", "C3", "housing",
    ];
    let bodies = names
        .iter()
        .map(|&name| Body {
            name: name.into(),
            inertia_kg_m2: 1.0,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 0.0,
            motion: if name == "housing" {
                Motion::Fixed
            } else {
                Motion::Free
            },
            drive: None,
            firing: None,
            road_load: None,
        })
        .collect();
    let set = |name: &str, sun: usize, ring: usize, carrier: usize, zs: u32, zr: u32| Coupling {
        name: name.into(),
        a: sun,
        b: ring,
        kind: CouplingKind::Planetary(PlanetarySet {
            sun_teeth: zs,
            ring_teeth: zr,
            carrier,
            double_pinion: false,
        }),
    };
    let element = |name: &str, a: usize, b: usize| Coupling {
        name: name.into(),
        a,
        b,
        kind: CouplingKind::Clutch(LumpedClutch {
            mu_table: vec![(0.0, 0.1)],
            peak: 1.0,
            cgeo_m: 0.1,
            fn_max_n: 1e4,
            force: Signal::Constant(0.0),
            one_way: false,
        }),
    };
    let couplings = vec![
        set("PS1", 2, 3, 4, 48, 96),
        set("PS2", 2, 5, 0, 48, 96),
        set("PS3", 5, 6, 7, 69, 111),
        set("PS4", 6, 4, 1, 23, 85),
        element("A", 2, 8),
        element("B", 3, 8),
        element("C", 0, 6),
        element("D", 7, 1),
        element("E", 5, 6),
    ];
    let table = [
        ("R", "ABD"),
        ("1", "ABC"),
        ("2", "ABE"),
        ("3", "BCE"),
        ("4", "BDE"),
        ("5", "BCD"),
        ("6", "CDE"),
        ("7", "ACD"),
        ("8", "ADE"),
    ];
    let gears = table
        .iter()
        .map(|(name, closed)| Gear {
            name: (*name).into(),
            closed: closed
                .chars()
                .map(|c| 4 + (c as usize - 'A' as usize))
                .collect(),
        })
        .collect();
    let net = Network {
        pack_thermal: Default::default(),
        bodies,
        couplings,
    };
    (
        net,
        Transmission {
            input: 0,
            output: 1,
            gears,
            initial_gear: None,
            shifts: Vec::new(),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The staggered angles are symmetric about 0, strictly decreasing, inside +-0.8 g0, and
    /// a single disc sits centred.
    #[test]
    fn staggered_angles_spread_across_the_play() {
        let g0 = paper_spline().half_play_rad();
        assert_eq!(staggered_rel_angle_rad(0, 1, g0), 0.0);
        let p = staggered_pack(8);
        let phi: Vec<f64> = p.discs.iter().map(|d| d.initial_rel_angle_rad).collect();
        assert!((phi[0] - -0.8 * g0 * (1.0 / 8.0 - 1.0)).abs() < 1e-18);
        for i in 0..8 {
            assert!((phi[i] + phi[7 - i]).abs() < 1e-18);
            assert!(phi[i].abs() < 0.8 * g0);
        }
        assert!(phi.windows(2).all(|w| w[1] < w[0]));
        assert_eq!(p.discs[7].name, "disc-8");
        assert!(p.is_torsional());
    }

    /// The free impact starts 0.1 um before engagement on the shaft-leads flank, and its
    /// closed form is the model crate's.
    #[test]
    fn free_impact_starts_just_before_contact() {
        let c = free_impact(LawKind::Dry, 0.0, 0.5);
        let d = &c.pack.discs[0];
        let kin = d
            .spline
            .kinematics(d.initial_rel_angle_rad, d.initial_rel_speed_rad_s);
        assert_eq!(kin.flank, Flank::ShaftLeads);
        assert!((d.law.engagement_depth_m(&kin) + 1e-7).abs() < 1e-15);
        assert!((kin.v_n_m_s - 0.5).abs() < 1e-15);
        assert_eq!(c.stiffness, d.law.hertz.coefficient());
    }
}
