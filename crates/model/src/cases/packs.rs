//! Cases of resolved packs with carriers of their own (MODEL.md sections 5 and 8): an engaging
//! clutch on an inertial shaft, a DCT's wet clutch, any pack with an inertial or a prescribed
//! shaft as the network that runs it (a network's run of it is the pack's own run), and a
//! prescribed body engaging a free one through a lumped clutch (its closed form).

use super::{bench_disc, paper_drive, staggered_brake, staggered_inertial};
use crate::clutch::{DrumModel, FrictionCurve, Piston, PressureProfile, StackModel};
use crate::drive::{Shaft, ShaftExcitation, SpeedProfile};
use crate::pack::PackModel;
use crate::spline::SplineGeometry;

/// An engaging clutch on an inertial shaft (MODEL.md sections 5 and 8): [`staggered_brake`]`(4)`
/// with its five plates on a drum instead of the housing and the shaft of
/// [`staggered_inertial`]; the drum (1.5 kg m^2, a load of -40 N m, drag 0.05 N m s/rad)
/// starts at 90 rad/s against the shaft's 100, and the piston's pressure ramps from 0 at 20 ms
/// to 120 kPa at 35 ms, so that the discs and plates rattle, the faces clamp and slip, and
/// the drum is pulled up to the shaft's speed and locks to it.
pub fn engaging_clutch() -> PackModel {
    let mut pack = staggered_brake(4);
    pack.shaft = staggered_inertial(4).shaft;
    pack.drum = Some(DrumModel {
        inertia_kg_m2: 1.5,
        load_torque_n_m: -40.0,
        drag_n_m_s_rad: 0.05,
        initial_speed_rad_s: 90.0,
    });
    for p in &mut pack.plates {
        p.initial_rel_speed_rad_s = 0.0;
    }
    let stack = pack.stack.as_mut().expect("the brake has a stack");
    stack.piston.pressure = PressureProfile::Ramp {
        start_s: 0.02,
        rise_s: 0.015,
        pressure_pa: 120e3,
    };
    pack
}

/// A dual-clutch transmission's wet clutch as a resolved pack (MODEL.md sections 5 and 8;
/// every value ASSUMED, of a DCT's clutch): `n` friction discs (`disc-1` ...; 0.004 kg m^2,
/// 40 teeth at 0.07 m, 20 deg, 0.3 mm backlash) and `n + 1` separator plates (`plate-1` ...;
/// 0.003 kg m^2, 48 teeth at 0.1 m, 30 deg, 0.3 mm), the dry Hertz law of the paper's
/// contact with `p = 0.5 s/m`, no drag, faces 0.075-0.095 m with a constant `mu = 0.1`, no
/// oil gap and no spline friction, so that every face is clamped by the piston's whole
/// `clamp_n` (N, constant) and the pack slips with `2 n mu F R_eff`. Its own shaft is the
/// paper's drive (a network's body replaces it).
pub fn wet_clutch(n: usize, clamp_n: f64) -> PackModel {
    // the benchmark disc's dry law with the paper's curvature: the paper's law, p = 0.5 s/m
    let body = |name: String, j: f64, spline: SplineGeometry| {
        let mut d = bench_disc(&name);
        d.law.hertz.curvature_radius_m = 1.75e-3;
        d.spline = spline;
        d.inertia_kg_m2 = j;
        d
    };
    let spline = |teeth: u32, r: f64, alpha_deg: f64| SplineGeometry {
        teeth,
        pitch_radius_m: r,
        pressure_angle_rad: alpha_deg.to_radians(),
        backlash_m: 0.3e-3,
    };
    let mut pack = PackModel::new(
        Shaft::Prescribed(paper_drive()),
        (1..=n)
            .map(|k| body(format!("disc-{k}"), 0.004, spline(40, 0.07, 20.0)))
            .collect(),
    );
    pack.plates = (1..=n + 1)
        .map(|k| body(format!("plate-{k}"), 0.003, spline(48, 0.1, 30.0)))
        .collect();
    pack.stack = Some(StackModel {
        face_friction: Vec::new(),
        face_inner_radius_m: 0.075,
        face_outer_radius_m: 0.095,
        friction: FrictionCurve::constant(0.1),
        piston: Piston {
            area_m2: 0.01,
            pressure: PressureProfile::Constant {
                pressure_pa: clamp_n / 0.01,
            },
            return_spring_n: 0.0,
        },
        open_gap: None,
        spline_friction: 0.0,
    });
    pack
}

/// A pack with an inertial or a prescribed shaft as a network (MODEL.md section 8): body
/// `shaft` (a prescribed shaft's profile as its motion; an inertial shaft's `J1`, `C1` as
/// drag, its drive torque: `J1 d(omega)/dt` of a harmonic speed profile as a sum of sines),
/// body `drum` (its inertia, load as a constant drive, drag and speed) or the fixed `housing`
/// when the plates sit on it, and the pack between them (its shaft and drum then unused).
/// `None` unless the shaft is prescribed, or inertial and driven by a harmonic speed profile,
/// and the pack has no couplings of its own. A network run of it is the pack's own run.
pub fn pack_as_network(pack: &PackModel) -> Option<crate::network::Network> {
    use crate::network::{Body, Motion};
    if !pack.couplings.is_empty() {
        return None;
    }
    let Shaft::Prescribed(profile) = &pack.shaft else {
        return inertial_pack_as_network(pack);
    };
    let shaft = Body {
        name: "shaft".into(),
        inertia_kg_m2: 0.0,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: profile.speed(0.0),
        motion: Motion::Prescribed(profile.clone()),
        drive: None,
        firing: None,
        road_load: None,
    };
    Some(with_carrier(pack, shaft))
}

/// [`pack_as_network`] of a pack on an inertial shaft.
fn inertial_pack_as_network(pack: &PackModel) -> Option<crate::network::Network> {
    use crate::network::{Body, Motion, Signal};
    let Shaft::Inertial {
        inertia_kg_m2,
        damping_n_m_s_rad,
        excitation: ShaftExcitation::Profile(SpeedProfile::Harmonics { harmonics, .. }),
    } = &pack.shaft
    else {
        return None;
    };
    // J1 d/dt (A sin(2 pi f t + phase)) = J1 A 2 pi f sin(2 pi f t + phase + pi / 2)
    let drive = Signal::Sum(
        harmonics
            .iter()
            .map(|h| Signal::Sine {
                offset: 0.0,
                amplitude: inertia_kg_m2
                    * h.amplitude_rad_s
                    * std::f64::consts::TAU
                    * h.frequency_hz,
                frequency_hz: h.frequency_hz,
                phase_rad: h.phase_rad + std::f64::consts::FRAC_PI_2,
                start_s: 0.0,
            })
            .collect(),
    );
    let shaft = Body {
        name: "shaft".into(),
        inertia_kg_m2: *inertia_kg_m2,
        drag_n_m_s_rad: *damping_n_m_s_rad,
        initial_speed_rad_s: pack.shaft.initial_speed_rad_s(),
        motion: Motion::Free,
        drive: Some(drive),
        firing: None,
        road_load: None,
    };
    Some(with_carrier(pack, shaft))
}

/// The network of body `shaft`, the pack's drum or the fixed housing, and the pack between
/// them ([`pack_as_network`]).
fn with_carrier(pack: &PackModel, shaft: crate::network::Body) -> crate::network::Network {
    use crate::network::{Body, Coupling, CouplingKind, Motion, Network, Signal};
    let carrier = match &pack.drum {
        Some(d) => Body {
            name: "drum".into(),
            inertia_kg_m2: d.inertia_kg_m2,
            drag_n_m_s_rad: d.drag_n_m_s_rad,
            initial_speed_rad_s: d.initial_speed_rad_s,
            motion: Motion::Free,
            drive: Some(Signal::Constant(d.load_torque_n_m)),
            firing: None,
            road_load: None,
        },
        None => Body {
            name: "housing".into(),
            inertia_kg_m2: 0.0,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 0.0,
            motion: Motion::Fixed,
            drive: None,
            firing: None,
            road_load: None,
        },
    };
    Network {
        pack_thermal: Default::default(),
        bodies: vec![shaft, carrier],
        couplings: vec![Coupling {
            name: "pack".into(),
            a: 0,
            b: 1,
            kind: CouplingKind::Pack(Box::new(pack.clone())),
        }],
    }
}

/// [`prescribed_clutch`]'s motor speed at t = 0, rad/s.
pub const PRESCRIBED_CLUTCH_W0_RAD_S: f64 = 20.0;
/// [`prescribed_clutch`]'s motor acceleration, rad/s^2.
pub const PRESCRIBED_CLUTCH_ACCEL_RAD_S2: f64 = 20.0;
/// [`prescribed_clutch`]'s load inertia, kg m^2.
pub const PRESCRIBED_CLUTCH_J_KG_M2: f64 = 0.5;
/// [`prescribed_clutch`]'s slipping torque `mu cgeo fn`, N m (its static limit 1.2 times it).
pub const PRESCRIBED_CLUTCH_TORQUE_N_M: f64 = 30.0;

/// A prescribed body engaging a free one (MODEL.md section 8): body `motor` (body 0) turns at
/// the prescribed `w_p = W + A t` ([`PRESCRIBED_CLUTCH_W0_RAD_S`] and
/// [`PRESCRIBED_CLUTCH_ACCEL_RAD_S2`], a speed table up to 1 s), body `load` (body 1, inertia
/// `J` = [`PRESCRIBED_CLUTCH_J_KG_M2`]) starts at rest, and a lumped clutch from the motor (a)
/// to the load (b), applied from t = 0, slips at `T` = [`PRESCRIBED_CLUTCH_TORQUE_N_M`]
/// (`mu` 0.3, `cgeo` 0.1 m, 1 kN; static limit 1.2 `T`). Closed form: the load accelerates at
/// `T / J`, the slip `W - (T / J - A) t` reaches 0 at `t_l = W / (T / J - A)` (0.5 s) and the
/// clutch locks; the load then follows the motor, held by `J A` (10 N m, below the limit).
/// The heat is `T W t_l / 2` (150 J), the motor's reaction `T` while slipping and `J A`
/// locked, its work `T (W t_l + A t_l^2 / 2)` then `J (w_p(t)^2 - w_p(t_l)^2) / 2`.
pub fn prescribed_clutch() -> crate::network::Network {
    use crate::network::{Body, Coupling, CouplingKind, LumpedClutch, Motion, Network, Signal};
    let (w0, a) = (PRESCRIBED_CLUTCH_W0_RAD_S, PRESCRIBED_CLUTCH_ACCEL_RAD_S2);
    let profile = SpeedProfile::Table(
        crate::drive::Table::new(vec![0.0, 1.0], vec![w0, w0 + a]).expect("two rows"),
    );
    let body = |name: &str, j: f64, w: f64, motion: Motion| Body {
        name: name.into(),
        inertia_kg_m2: j,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: w,
        motion,
        drive: None,
        firing: None,
        road_load: None,
    };
    Network {
        pack_thermal: Default::default(),
        bodies: vec![
            body("motor", 0.0, w0, Motion::Prescribed(profile)),
            body("load", PRESCRIBED_CLUTCH_J_KG_M2, 0.0, Motion::Free),
        ],
        couplings: vec![Coupling {
            name: "clutch".into(),
            a: 0,
            b: 1,
            kind: CouplingKind::Clutch(LumpedClutch {
                mu_table: vec![(0.0, 0.3)],
                peak: 1.2,
                cgeo_m: 0.1,
                fn_max_n: 1000.0,
                force: Signal::Constant(1.0),
                one_way: false,
            }),
        }],
    }
}

/// How long [`prescribed_clutch`] is run for its closed form, s (the lock at 0.5 s, then
/// 0.3 s locked).
pub const PRESCRIBED_CLUTCH_DURATION_S: f64 = 0.8;

/// The instants at which [`PrescribedClutchObserver`] reads the motor's reaction, s: slipping
/// (0.25 s) and locked (0.7 s).
const PRESCRIBED_CLUTCH_REACTIONS_AT_S: [f64; 2] = [0.25, 0.7];

/// What [`prescribed_clutch_against_closed_form`] reads of a run of [`prescribed_clutch`],
/// collected as the run goes (either engine's observer): the times the clutch locks after
/// t = 0, s, and the motor's (body 0's) reaction in the first sample within 1e-9 s of 0.25 s
/// (slipping) and of 0.7 s (locked), N m (`None` while no sample has come there).
#[derive(Debug, Clone, Default)]
pub struct PrescribedClutchObserver {
    /// The clutch's locks after t = 0, s.
    pub locks_s: Vec<f64>,
    /// The motor's reaction slipping and locked, N m ([`NetworkSample::reaction_n_m`]).
    ///
    /// [`NetworkSample::reaction_n_m`]: crate::network::NetworkSample::reaction_n_m
    pub reactions_n_m: [Option<f64>; 2],
}

impl crate::Observer for PrescribedClutchObserver {
    fn network_sample(&mut self, sample: &crate::network::NetworkSample) {
        for (at, r) in PRESCRIBED_CLUTCH_REACTIONS_AT_S
            .iter()
            .zip(self.reactions_n_m.iter_mut())
        {
            if r.is_none() && (sample.t_s - at).abs() < 1e-9 {
                *r = sample.reaction_n_m.first().copied();
            }
        }
    }

    fn clutch_event(&mut self, event: &crate::network::ClutchEvent) {
        if event.to == crate::network::ClutchMode::Locked && event.t_s > 0.0 {
            self.locks_s.push(event.t_s);
        }
    }
}

/// [`prescribed_clutch`]'s run over [`PRESCRIBED_CLUTCH_DURATION_S`] against its closed form
/// (the formulas of [`prescribed_clutch`]), with what `seen` collected of it: one
/// `(quantity, got, closed form)` row each for the number of locks (1), the first lock's time
/// (s), the motor's and the load's speeds at the end (rad/s), the heat (J), the motor's
/// reaction while slipping (at 0.25 s) and locked (at 0.7 s; N m; NaN where no sample came),
/// its work (J) and the balance's residual (J), for each engine's test to bound.
pub fn prescribed_clutch_against_closed_form(
    run: &crate::network::NetworkRun,
    seen: &PrescribedClutchObserver,
) -> Vec<(&'static str, f64, f64)> {
    let (locks_s, reactions_n_m) = (
        &seen.locks_s,
        seen.reactions_n_m.map(|r| r.unwrap_or(f64::NAN)),
    );
    let (w0, a) = (PRESCRIBED_CLUTCH_W0_RAD_S, PRESCRIBED_CLUTCH_ACCEL_RAD_S2);
    let (j, t) = (PRESCRIBED_CLUTCH_J_KG_M2, PRESCRIBED_CLUTCH_TORQUE_N_M);
    let t_lock = w0 / (t / j - a);
    let w_end = w0 + a * PRESCRIBED_CLUTCH_DURATION_S;
    let work = t * (w0 * t_lock + a * t_lock * t_lock / 2.0)
        + j * (w_end.powi(2) - (w0 + a * t_lock).powi(2)) / 2.0;
    vec![
        ("locks", locks_s.len() as f64, 1.0),
        (
            "lock time s",
            locks_s.first().copied().unwrap_or(f64::NAN),
            t_lock,
        ),
        ("motor speed rad/s", run.last.speed_rad_s[0], w_end),
        ("load speed rad/s", run.last.speed_rad_s[1], w_end),
        ("heat J", run.heat_j[0], t * w0 * t_lock / 2.0),
        ("reaction slipping N m", reactions_n_m[0], t),
        ("reaction locked N m", reactions_n_m[1], j * a),
        ("prescribed work J", run.energy.prescribed_work_j, work),
        ("residual J", run.energy.residual_j(), 0.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The network of a pack drives its shaft with the pack's own torque: `J1 d(omega)/dt`.
    #[test]
    fn a_pack_as_network_drives_the_shaft_as_the_pack() {
        let pack = engaging_clutch();
        let net = pack_as_network(&pack).expect("an inertial shaft");
        assert!(net.problems().is_empty(), "{:?}", net.problems());
        for t in [0.0, 0.0013, 0.017, 0.04] {
            let (a, b) = (
                net.bodies[0].drive_torque_n_m(t, 0.0),
                pack.shaft.drive_torque_n_m(t),
            );
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{t}: {a} {b}");
        }
        assert_eq!(net.bodies[1].initial_speed_rad_s, 90.0);
    }

    /// A one-pack network is the pack scene it was made from (`Network::one_pack`, the
    /// inverse of [`pack_as_network`] for a prescribed shaft, on the housing or on a drum with
    /// a constant load); a network that is not (an inertial shaft, a drum with a road load) is
    /// none.
    #[test]
    fn a_one_pack_network_is_its_pack() {
        let mut pack = engaging_clutch();
        let inertial = pack_as_network(&pack).unwrap();
        assert_eq!(inertial.one_pack(), None, "an inertial shaft");
        pack.shaft = Shaft::Prescribed(SpeedProfile::sine(100.0, 2.0, 50.0));
        let mut net = pack_as_network(&pack).unwrap();
        assert!(net.problems().is_empty(), "{:?}", net.problems());
        assert_eq!(net.one_pack().as_ref(), Some(&pack), "on a drum");
        net.bodies[1].road_load = Some(crate::network::RoadLoad {
            constant_n_m: 1.0,
            linear_n_m_s_rad: 0.0,
            quadratic_n_m_s2_rad2: 0.0,
        });
        assert_eq!(net.one_pack(), None, "a drum with a road load");
        let brake = staggered_brake(4);
        assert!(matches!(brake.shaft, Shaft::Prescribed(_)) && brake.drum.is_none());
        let net = pack_as_network(&brake).unwrap();
        assert_eq!(net.one_pack().as_ref(), Some(&brake), "on the housing");
    }
}
