//! The reference engine on whole packs (issue 21): separator plates on the housing, the open
//! stack's oil gaps, and the energy they must account for.

use clutchpack_model::cases::paper_disc;
use clutchpack_model::*;
use clutchpack_reference::{ReferenceEngine, Settings};

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
    let settings = Settings {
        tolerance: 1e-10,
        ..Settings::default()
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
