//! The reference engine against closed forms and the independent figures of MODEL.md
//! section 4.

use clutchpack_model::cases::{
    free_impact, paper_disc, paper_pack, PAPER_FIRST_CONTACT_0UM_MS, PAPER_FIRST_IMPACTS_0UM,
    PAPER_FIRST_IMPACTS_25UM,
};
use clutchpack_model::*;
use clutchpack_reference::{ReferenceEngine, ReferenceOptions};

fn run(pack: PackModel, duration: f64, tol: f64, rate: f64) -> Collector {
    let mut e = ReferenceEngine::new(
        pack,
        ReferenceOptions {
            tolerance: tol,
            max_step_s: 1e-4,
            record_rate_hz: rate,
        },
    );
    let mut c = Collector::default();
    e.run(duration, &mut c).unwrap();
    c
}

/// The deterministic start of the paper case: each of the first five peaks within 0.2 % and
/// its time within 1 us of MODEL.md (whose figures are rounded to 5-6 digits, i.e. about
/// 0.002 % and 0.005 us); the first contact of the dry case also starts and ends where
/// MODEL.md says (1.08545 ms, 1.16034 ms).
#[test]
fn first_impacts_match_the_independent_solver() {
    for (h_o, expected) in [
        (0.0, PAPER_FIRST_IMPACTS_0UM),
        (25e-6, PAPER_FIRST_IMPACTS_25UM),
    ] {
        let c = run(paper_pack(h_o), 0.0095, 1e-9, 1000.0);
        assert_eq!(c.impacts.len(), 5, "h_o = {h_o}: {:?}", c.impacts);
        for (e, (peak, t_ms)) in c.impacts.iter().zip(expected) {
            let rel = (e.peak_n - peak).abs() / peak.abs();
            assert!(
                rel < 2e-3,
                "h_o = {h_o}: peak {} vs {peak} ({rel:e})",
                e.peak_n
            );
            let dt = (e.t_peak_s - t_ms * 1e-3).abs();
            assert!(
                dt < 1e-6,
                "h_o = {h_o}: peak time {} vs {t_ms} ms",
                e.t_peak_s * 1e3
            );
            assert_eq!(e.flank == Flank::ShaftLeads, peak < 0.0);
        }
        if h_o == 0.0 {
            let (t_on_ms, t_off_ms) = PAPER_FIRST_CONTACT_0UM_MS;
            assert!((c.impacts[0].t_on_s - t_on_ms * 1e-3).abs() < 1e-8);
            assert!((c.impacts[0].t_off_s - t_off_ms * 1e-3).abs() < 1e-8);
        }
    }
}

/// One free impact: no drive, no drag, p = 0, the disc arriving at closing speed v0 on the
/// shaft-leads flank. The closed form (MODEL.md section 4, `K` in place of `H` for the oil
/// law with dv = v0) gives the peak; the contact is conservative so the disc leaves at v0.
/// Tolerance 0.1 % on both, as the issue asks (the integrator reaches ~1e-7).
#[test]
fn free_impact_matches_the_closed_form() {
    for (kind, h_o) in [
        (LawKind::Dry, 0.0),
        (LawKind::Paper, 25e-6),
        (LawKind::Paper, 50e-6),
    ] {
        for v0 in [0.25, 0.5, 1.0, 2.0] {
            let case = free_impact(kind, h_o, v0);
            let (k, m_eff) = (case.stiffness, case.m_eff_kg);
            let c = run(case.pack, 2e-4 / v0.min(1.0), 1e-9, 1e6);
            assert_eq!(c.impacts.len(), 1, "{kind:?} {h_o} {v0}");
            let peak = c.impacts[0].peak_n;
            let expected = free_impact_peak_n(k, m_eff, v0);
            let rel = (peak.abs() - expected).abs() / expected;
            assert!(
                rel < 1e-3,
                "{kind:?} h_o={h_o} v0={v0}: {peak} vs {expected} ({rel:e})"
            );
            assert!(peak < 0.0, "the shaft leads");
            let last = c.samples.last().unwrap();
            let rebound = -last.discs[0].closing_speed_m_s;
            let rel_v = (rebound - v0).abs() / v0;
            assert!(
                rel_v < 1e-3,
                "{kind:?} h_o={h_o} v0={v0}: rebound {rebound} ({rel_v:e})"
            );
        }
    }
}

/// Convergence: the first ten impacts at tolerance 1e-9 and 1e-11 agree to 1e-4 relative
/// (MODEL.md section 6: two correct solvers agree to 5 digits over the first ~0.1 s).
#[test]
fn tolerance_refinement_converges() {
    let a = run(paper_pack(50e-6), 0.03, 1e-9, 100.0);
    let b = run(paper_pack(50e-6), 0.03, 1e-11, 100.0);
    assert!(a.impacts.len() >= 10);
    for (x, y) in a.impacts.iter().zip(&b.impacts).take(10) {
        assert!(
            (x.peak_n - y.peak_n).abs() < 1e-4 * y.peak_n.abs(),
            "{x:?} {y:?}"
        );
        assert!((x.t_on_s - y.t_on_s).abs() < 1e-8);
    }
}

/// A contact never pulls and the sampled loads carry the flank's sign (a property of the
/// whole run, checked on every sample of 50 ms at h_o = 50 um).
#[test]
fn sampled_loads_have_the_flank_sign() {
    let c = run(paper_pack(50e-6), 0.05, 1e-9, 200_000.0);
    let mut engaged = 0;
    for s in &c.samples {
        let d = &s.discs[0];
        if d.engaged {
            engaged += 1;
            assert!(d.load_n * d.rel_angle_rad <= 0.0, "{d:?}");
        } else {
            assert_eq!(d.load_n, 0.0);
        }
        assert!((d.torque_n_m + 154.0 * d.load_n * 0.231 * 20f64.to_radians().cos()).abs() < 1e-9);
    }
    assert!(engaged > 100);
}

/// Inertial shaft (eq 4) with no drive torque, no damping and p = 0: the spline forces are
/// internal, so the total angular momentum J1 omega_s + J2 omega_d is conserved through
/// impacts (to the integration tolerance, checked to 1e-9 relative).
#[test]
fn inertial_shaft_conserves_angular_momentum() {
    let mut disc = paper_disc(25e-6);
    disc.law.hertz.loss_coefficient_s_m = 0.0;
    disc.drag_n_m_s_rad = 0.0;
    disc.initial_rel_speed_rad_s = 2.0;
    let j1 = 0.05;
    let pack = PackModel {
        shaft: Shaft::Inertial {
            inertia_kg_m2: j1,
            damping_n_m_s_rad: 0.0,
            excitation: ShaftExcitation::Profile(SpeedProfile::sine(100.0, 0.0, 1.0)),
        },
        discs: vec![disc],
        plates: Vec::new(),
        drum: None,
        stack: None,
        couplings: Vec::new(),
    };
    let c = run(pack, 0.02, 1e-10, 10_000.0);
    assert!(c.impacts.len() >= 3, "{}", c.impacts.len());
    let l0 = j1 * 100.0 + 0.156 * 98.0;
    for s in &c.samples {
        let l = j1 * s.shaft_speed_rad_s + 0.156 * s.discs[0].speed_rad_s;
        assert!((l - l0).abs() < 1e-9 * l0, "{l} vs {l0} at {}", s.t_s);
    }
}

/// MODEL.md section 5: radial float, an offset or tooth spacing errors make the teeth carry
/// different loads, which one rotational degree of freedom with the lumped law cannot
/// represent; the engine refuses such a disc (`Unsupported`, naming it) instead of running a
/// different model.
#[test]
fn per_tooth_effects_are_refused() {
    let cases: [fn(&mut DiscModel); 3] = [
        |d| d.radial_float = true,
        |d| d.initial_offset_m = [10e-6, 0.0],
        |d| {
            d.tooth_spacing_errors_m = vec![0.0; 154];
            d.tooth_spacing_errors_m[3] = 5e-6;
        },
    ];
    for set in cases {
        let mut pack = paper_pack(25e-6);
        set(&mut pack.discs[0]);
        let mut e = ReferenceEngine::new(pack, ReferenceOptions::default());
        let err = e.run(1e-3, &mut Collector::default()).unwrap_err();
        assert!(
            matches!(&err, EngineError::Unsupported(m) if m.contains("disc disc")),
            "{err}"
        );
    }
    // it runs plates and a stack, open or clamped (issue 21)
    let mut pack = paper_pack(25e-6);
    pack.plates = vec![pack.discs[0].clone(), pack.discs[0].clone()];
    pack.stack = Some(clutchpack_model::StackModel {
        face_friction: Vec::new(),
        face_inner_radius_m: 0.235,
        face_outer_radius_m: 0.29,
        friction: clutchpack_model::FrictionCurve::constant(0.1),
        piston: clutchpack_model::Piston {
            area_m2: 0.01,
            pressure: clutchpack_model::PressureProfile::Ramp {
                start_s: 0.0,
                rise_s: 1e-3,
                pressure_pa: 1e6,
            },
            return_spring_n: 100.0,
        },
        open_gap: None,
        spline_friction: 0.1,
    });
    let mut c = Collector::default();
    ReferenceEngine::new(pack, ReferenceOptions::default())
        .run(2e-3, &mut c)
        .unwrap();
    assert!(c
        .interfaces
        .last()
        .unwrap()
        .1
        .iter()
        .all(|f| f.clamp_n > 0.0));
    // all-zero spacing errors are no errors
    let mut pack = paper_pack(25e-6);
    pack.discs[0].tooth_spacing_errors_m = vec![0.0; 154];
    ReferenceEngine::new(pack, ReferenceOptions::default())
        .run(1e-3, &mut Collector::default())
        .unwrap();
}
