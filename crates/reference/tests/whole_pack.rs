//! The reference engine on whole packs (issue 21): separator plates on the housing, the open
//! stack's oil gaps, and the energy they must account for.

use clutchpack_model::cases::paper_disc;
use clutchpack_model::*;
use clutchpack_reference::{ReferenceEngine, ReferenceOptions};

/// An undriven inertial shaft at 100 rad/s, 2 dry lossless discs without drag, 3 plates on
/// the housing, open gaps between them: the gaps' heat is the only loss.
fn open_brake() -> PackModel {
    let disc = |name: &str, j: f64| {
        let mut d = paper_disc(0.0);
        d.name = name.into();
        d.law.kind = LawKind::Dry;
        d.law.hertz.loss_coefficient_s_m = 0.0;
        d.drag_n_m_s_rad = 0.0;
        d.inertia_kg_m2 = j;
        d
    };
    let mut pack = PackModel::new(
        Shaft::Inertial {
            inertia_kg_m2: 2.0,
            damping_n_m_s_rad: 0.0,
            excitation: ShaftExcitation::Profile(SpeedProfile::sine(100.0, 0.0, 1.0)),
        },
        vec![disc("d0", 0.156), disc("d1", 0.156)],
    );
    pack.plates = vec![disc("p0", 0.1), disc("p1", 0.12), disc("p2", 0.14)];
    pack.stack = Some(StackModel {
        face_friction: Vec::new(),
        face_inner_radius_m: 0.235,
        face_outer_radius_m: 0.29,
        friction: FrictionCurve::constant(0.1),
        piston: Piston {
            area_m2: 0.01,
            pressure: PressureProfile::Constant { pressure_pa: 0.0 },
            return_spring_n: 0.0,
        },
        // a thin gap: a strong drag, so the plates rattle and the heat is large
        open_gap: Some(OpenGap {
            viscosity_pa_s: 0.05,
            gap_m: 0.1e-3,
        }),
        spline_friction: 0.1,
    });
    pack
}

/// Kinetic energy plus the teeth's potential (`n 2/5 K s^2.5` per coupling), J.
fn mechanical_energy(pack: &PackModel, s: &Sample) -> f64 {
    let mut e = 0.5 * 2.0 * s.shaft_speed_rad_s.powi(2);
    for (d, b) in pack.discs.iter().chain(&pack.plates).zip(&s.discs) {
        e += 0.5 * d.inertia_kg_m2 * b.speed_rad_s.powi(2);
        if b.engaged && b.penetration_m > 0.0 {
            e += d.spline.teeth as f64 * 0.4 * b.stiffness * b.penetration_m.powf(2.5);
        }
    }
    e
}

/// Energy: the mechanical energy the pack loses is the heat of its gaps, sample by sample,
/// to 1e-9 of that heat (issue 21 asks 1e-6) at tolerance 1e-10, while the
/// plates rattle against the housing and the discs against the shaft (measured 3.8e-7 J of
/// 4865 J, 8e-11; bound 1e-9).
#[test]
fn open_gaps_heat_is_the_mechanical_energy_lost() {
    let pack = open_brake();
    let settings = ReferenceOptions {
        tolerance: 1e-10,
        ..ReferenceOptions::default()
    };
    let mut c = Collector::default();
    ReferenceEngine::new(pack.clone(), settings)
        .run(0.05, &mut c)
        .unwrap();
    assert_eq!(c.samples.len(), c.interfaces.len());
    let plates_hit = c.impacts.iter().filter(|e| e.disc >= 2).count();
    assert!(plates_hit >= 6, "the plates rattle: {plates_hit} impacts");
    let e0 = mechanical_energy(&pack, &c.samples[0]);
    let mut worst: f64 = 0.0;
    let mut heat_end = 0.0;
    for (s, (t, faces)) in c.samples.iter().zip(&c.interfaces) {
        assert_eq!(s.t_s, *t);
        let heat: f64 = faces.iter().map(|f| f.dissipated_j).sum();
        let lost = e0 - mechanical_energy(&pack, s);
        worst = worst.max((lost - heat).abs());
        heat_end = heat;
        // the open gaps drag: torque against the slip, no clamp
        for f in faces {
            assert!(f.torque_n_m * f.slip_rad_s <= 0.0 && f.clamp_n == 0.0 && !f.locked);
        }
    }
    assert!(heat_end > 1.0, "{heat_end} J");
    println!("heat {heat_end} J, worst energy mismatch {worst} J");
    assert!(worst <= 1e-9 * heat_end, "{worst} J of {heat_end} J");
}

/// One friction disc on a shaft turning steadily at 100 rad/s between two plates on a drum at
/// rest (no load, no drag), clamped from t = 0 by `F = p A - F_rs = 9500 N` with a constant
/// `mu = 0.1` and no spline friction.
fn engagement() -> PackModel {
    let body = |name: &str, j: f64| {
        let mut d = paper_disc(0.0);
        d.name = name.into();
        d.law.kind = LawKind::Dry;
        d.law.hertz.loss_coefficient_s_m = 0.5;
        d.drag_n_m_s_rad = 0.0;
        d.inertia_kg_m2 = j;
        d
    };
    let mut pack = PackModel::new(
        Shaft::Prescribed(SpeedProfile::Harmonics {
            omega0_rad_s: 100.0,
            harmonics: vec![],
        }),
        vec![body("disc", 0.156)],
    );
    pack.plates = vec![body("p0", 0.12), body("p1", 0.12)];
    pack.drum = Some(DrumModel {
        inertia_kg_m2: 0.3,
        load_torque_n_m: 0.0,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: 0.0,
    });
    pack.stack = Some(StackModel {
        face_friction: Vec::new(),
        face_inner_radius_m: 0.231,
        face_outer_radius_m: 0.290,
        friction: FrictionCurve::constant(0.1),
        piston: Piston {
            area_m2: 0.01,
            pressure: PressureProfile::Constant { pressure_pa: 1e6 },
            return_spring_n: 500.0,
        },
        open_gap: None,
        spline_friction: 0.0,
    });
    pack
}

/// The closed-form engagement (MODEL.md section 5): the two faces slip with `mu F R_eff` each
/// until the plates and the drum reach the disc's speed, so `(J_drum + 2 J_plate) omega0 =
/// 2 mu F R_eff t_lock` (the plates' tooth impacts on the drum are internal to that group),
/// and the faces turn `J omega0^2 / 2` into heat (the other half is the group's kinetic
/// energy). Both within 0.1 % (measured: lock time 2.3e-5, heat 4.7e-4: the plates. first strikes
/// on the drum's teeth take what the rest is). The lock is exact: no creep afterwards.
#[test]
fn engagement_locks_at_the_closed_form_time_with_the_closed_form_heat() {
    let pack = engagement();
    let stack = pack.stack.clone().unwrap();
    let settings = ReferenceOptions {
        tolerance: 1e-10,
        record_rate_hz: 1e5,
        ..ReferenceOptions::default()
    };
    let mut c = Collector::default();
    ReferenceEngine::new(pack.clone(), settings)
        .run(0.15, &mut c)
        .unwrap();
    let r_eff = stack.effective_radius_m();
    let j = 0.3 + 2.0 * 0.12;
    let torque = 2.0 * 0.1 * 9500.0 * r_eff;
    let t_lock = j * 100.0 / torque;
    let heat_expected = 0.5 * j * 100.0 * 100.0;
    let first_lock = |m: usize| {
        c.interfaces
            .iter()
            .find(|(_, f)| f[m].locked)
            .map(|(t, _)| *t)
            .expect("the face locks")
    };
    let (_, last) = c.interfaces.last().unwrap();
    let heat: f64 = last.iter().map(|f| f.dissipated_j).sum();
    println!(
        "lock {} / {} s (closed form {t_lock}), heat {heat} J (closed form {heat_expected})",
        first_lock(0),
        first_lock(1)
    );
    for (m, face) in last.iter().enumerate() {
        assert!(
            (first_lock(m) - t_lock).abs() <= 1e-3 * t_lock,
            "{}",
            first_lock(m)
        );
        assert!(face.locked && face.slip_rad_s.abs() < 1e-9);
        assert_eq!(face.clamp_n, 9500.0);
    }
    assert!(
        (heat - heat_expected).abs() <= 1e-3 * heat_expected,
        "{heat}"
    );
}

/// Energy with a clamping stack: an undriven inertial shaft with 2 lossless discs and 3 plates
/// on a free drum, the piston ramping up over 20 ms from 5 ms with a rising friction curve
/// and spline friction: the faces slip, lock, and the mechanical energy the pack loses is
/// the heat of its faces and gaps to 1e-9 of it (issue 21 asks 1e-6).
#[test]
fn clamped_faces_heat_is_the_mechanical_energy_lost() {
    let mut pack = open_brake();
    pack.drum = Some(DrumModel {
        inertia_kg_m2: 0.8,
        load_torque_n_m: 0.0,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: 0.0,
    });
    if let Some(s) = pack.stack.as_mut() {
        s.piston.pressure = PressureProfile::Ramp {
            start_s: 0.005,
            rise_s: 0.02,
            pressure_pa: 2e6,
        };
        s.friction = FrictionCurve::Stribeck {
            static_mu: 0.10,
            kinetic_mu: 0.13,
            stribeck_speed_m_s: 0.5,
            viscous_slope_s_m: 0.0,
        };
    }
    let settings = ReferenceOptions {
        tolerance: 1e-10,
        ..ReferenceOptions::default()
    };
    let mut c = Collector::default();
    ReferenceEngine::new(pack.clone(), settings)
        .run(0.1, &mut c)
        .unwrap();
    let (_, last) = c.interfaces.last().unwrap();
    assert!(last.iter().all(|f| f.locked), "every face locks: {last:?}");
    // the drum's speed is not in the samples: angular momentum is conserved (no external
    // torque; the unit test of the right-hand side checks it exactly), so it is what the
    // shaft, discs and plates do not carry of the initial 2.0 * 100 + 2 * 0.156 * 100
    let momentum = |s: &Sample| {
        2.0 * s.shaft_speed_rad_s
            + pack
                .discs
                .iter()
                .chain(&pack.plates)
                .zip(&s.discs)
                .map(|(d, b)| d.inertia_kg_m2 * b.speed_rad_s)
                .sum::<f64>()
    };
    let l0 = momentum(&c.samples[0]);
    let drum_ke = |s: &Sample| {
        let omega_r = (l0 - momentum(s)) / 0.8;
        0.5 * 0.8 * omega_r * omega_r
    };
    let energy = |s: &Sample| mechanical_energy(&pack, s) + drum_ke(s);
    let (s0, s1) = (&c.samples[0], c.samples.last().unwrap());
    let heat: f64 = last.iter().map(|f| f.dissipated_j).sum();
    let lost = energy(s0) - energy(s1);
    println!("heat {heat} J, lost {lost} J");
    assert!(heat > 100.0);
    assert!((lost - heat).abs() <= 1e-9 * heat, "{lost} vs {heat}");
}

/// Break-loose (issue 21's closed form): the engaged pack of [`engagement`] with a braking
/// preload of 20 N m on the drum from the start (it locks at about 0.11 s), and from 0.2 s a
/// load rising slowly (4,000 N m/s, held at every 1e-4 s communication point of a driven
/// session: steps of 0.4 N m) until the faces slip. The locked group (the two plates and the
/// disc) passes the load to the shaft; each face holds half of it, so the faces break loose
/// together when the load reaches `mu(0) F R_eff` summed over the two faces (497.07 N m).
/// Measured: 497.2 N m, the first 0.4 N m step past it (2.7e-4); bound 1e-3 as the issue asks.
///
/// Quasi-static only if the teeth stay in contact: with the shipped tooth damping (0.5 s/m)
/// the drum and the disc rattle in their backlash under the load, and an impact's torque
/// slips the faces first (measured: at 128 N m). So the teeth here are heavily damped (50
/// s/m: the contacts settle), and the preload keeps the drum's teeth on the plates' through
/// the lock (a load put on a drum coasting in its backlash makes the teeth strike).
#[test]
fn a_locked_pack_breaks_loose_at_the_faces_static_torque() {
    use clutchpack_model::session::{Driven, Inputs};
    let mut pack = engagement();
    for b in pack.discs.iter_mut().chain(pack.plates.iter_mut()) {
        b.law.hertz.loss_coefficient_s_m = 50.0;
    }
    let stack = pack.stack.clone().unwrap();
    let engine = ReferenceEngine::new(
        pack,
        ReferenceOptions {
            tolerance: 1e-10,
            ..ReferenceOptions::default()
        },
    );
    let mut s = engine
        .start(Driven {
            drum_load: true,
            ..Driven::NONE
        })
        .unwrap();
    let mut c = Collector::default();
    // the preload from the start, then the ramp
    let (h, preload, t_ramp, rate) = (1e-4, -20.0, 0.2, -4000.0);
    let expected = 2.0 * stack.friction.static_mu() * 9500.0 * stack.effective_radius_m();
    let mut broke = None;
    let mut k = 0;
    while broke.is_none() && k < 20_000 {
        let t = k as f64 * h;
        let load = preload + rate * (t - t_ramp).max(0.0);
        s.set_inputs(&Inputs {
            drum_load_n_m: Some(load),
            ..Inputs::default()
        })
        .unwrap();
        s.advance_to((k + 1) as f64 * h, &mut c).unwrap();
        let faces = s.snapshot().interfaces;
        if (t - t_ramp).abs() < 0.5 * h {
            assert!(
                faces.iter().all(|f| f.locked),
                "locked when the ramp starts"
            );
        }
        if t > t_ramp && faces.iter().any(|f| !f.locked) {
            broke = Some((t, -load, faces));
        }
        k += 1;
    }
    let (t, load, faces) = broke.expect("the faces break loose");
    // the load held over the step in which they slipped
    println!(
        "break-loose at t = {t} s under {load} N m (closed form {expected} N m): faces {:?}",
        faces.iter().map(|f| f.locked).collect::<Vec<_>>()
    );
    assert!(faces.iter().all(|f| !f.locked), "both faces together");
    assert!(
        (load - expected).abs() <= 1e-3 * expected,
        "{load} N m vs {expected} N m"
    );
}

/// A long call delivers its output as it goes, so that a long run's memory stays bounded: at
/// every progress report of a whole run (one call to the session), the samples up to within a
/// few milliseconds of the report's time have been delivered. Monolithic (a clamping whole
/// pack, `pack-6-engagement`) and the coupled scheme (an inertial shaft). Before the queue was
/// flushed during a call, the first report came with no sample delivered (lag = the report's
/// time) and the memory grew by 24 MB per simulated second on pack-6-engagement.
#[test]
fn long_calls_deliver_as_they_go() {
    struct Lag {
        last_sample_s: f64,
        worst_s: f64,
        reports: usize,
    }
    impl Observer for Lag {
        fn sample(&mut self, s: &Sample) {
            self.last_sample_s = s.t_s;
        }
        fn progress(&mut self, t_s: f64) -> bool {
            self.worst_s = self.worst_s.max(t_s - self.last_sample_s);
            self.reports += 1;
            false
        }
    }
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let engagement = clutchpack_scene::load(&path.join("../../scenes/pack-6-engagement.toml"), &[])
        .unwrap()
        .pack;
    let inertial = clutchpack_model::cases::staggered_inertial(4);
    for (label, pack) in [
        ("pack-6-engagement", engagement),
        ("inertial shaft", inertial),
    ] {
        let mut lag = Lag {
            last_sample_s: 0.0,
            worst_s: 0.0,
            reports: 0,
        };
        ReferenceEngine::new(pack, ReferenceOptions::default())
            .run(0.2, &mut lag)
            .unwrap();
        println!(
            "{label}: {} reports, worst lag {:.2e} s",
            lag.reports, lag.worst_s
        );
        assert!(lag.reports > 10, "{label}: {} reports", lag.reports);
        assert!(lag.worst_s < 5e-3, "{label}: lag {} s", lag.worst_s);
    }
}
