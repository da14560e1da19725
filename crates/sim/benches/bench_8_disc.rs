//! The `bench-8-disc` case of issue 3: 8 identical friction discs on one shaft, 0.1 s.
//!
//! Each disc: a steel annulus (inner radius 0.231 m, outer 0.300 m, 3 mm, 7850 kg/m^3, so
//! `J = rho pi t (Ro^4 - Ri^4) / 2 = 0.1943 kg m^2`), dry law with `r = 5 mm`, `p = 0.5 s/m`,
//! spline `n = 154`, `R = 0.231 m`, `alpha = 20 deg`, `d = 0.75 mm`, no drag; the shaft
//! turns at `100 + 4.378 sin(2 pi 104 t)` rad/s. Target (issue 3): less wall time than about
//! 0.17 s for the 0.1 s run (MuJoCo at a fixed 1 us step with the law in a native callback).
//!
//! Besides criterion's timings, the bench prints each mode's steps, impacts, microseconds per
//! step and steps per impact once.

use clutchpack_model::{
    Collector, DiscModel, Engine, Hertz, LawKind, OilFilm, PackModel, Shaft, SpeedProfile,
    SplineGeometry, ToothLaw,
};
use clutchpack_sim::{AdaptiveStepping, MultibodyEngine, MultibodyOptions, Stepping};
use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Instant;

fn bench_pack() -> PackModel {
    let (ri, ro, t, rho) = (0.231f64, 0.300f64, 3e-3, 7850.0);
    let inertia = rho * std::f64::consts::PI * t * (ro.powi(4) - ri.powi(4)) / 2.0;
    let disc = |i: usize| DiscModel {
        name: format!("disc{}", i + 1),
        spline: SplineGeometry {
            teeth: 154,
            pitch_radius_m: 0.231,
            pressure_angle_rad: 20f64.to_radians(),
            backlash_m: 0.75e-3,
        },
        law: ToothLaw {
            kind: LawKind::Dry,
            hertz: Hertz {
                modulus_pa: 210e9,
                curvature_radius_m: 5e-3,
                loss_coefficient_s_m: 0.5,
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
        },
        inertia_kg_m2: inertia,
        drag_n_m_s_rad: 0.0,
        initial_rel_angle_rad: 0.0,
        initial_rel_speed_rad_s: 0.0,
    };
    PackModel {
        shaft: Shaft::Prescribed(SpeedProfile::sine(100.0, 4.378, 104.0)),
        discs: (0..8).map(disc).collect(),
    }
}

fn modes() -> Vec<(&'static str, Stepping)> {
    vec![
        ("adaptive", Stepping::Adaptive(AdaptiveStepping::default())),
        ("fixed 1us", Stepping::Fixed { dt_s: 1e-6 }),
    ]
}

fn run_once(stepping: Stepping) -> (u64, usize) {
    let mut e = MultibodyEngine::from_pack(
        bench_pack(),
        1e4,
        MultibodyOptions {
            stepping,
            ..Default::default()
        },
    )
    .expect("engine");
    let mut c = Collector::default();
    let stats = e.run(0.1, &mut c).expect("run");
    (stats.steps, c.impacts.len())
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("bench-8-disc 0.1 s");
    g.sample_size(10);
    for (name, stepping) in modes() {
        let start = Instant::now();
        let (steps, impacts) = run_once(stepping);
        let wall = start.elapsed().as_secs_f64();
        eprintln!(
            "{name}: {steps} steps, {impacts} impacts (all discs), {:.3} s, {:.2} us/step, {:.1} steps per impact",
            wall,
            wall / steps as f64 * 1e6,
            steps as f64 / impacts.max(1) as f64
        );
        g.bench_function(name, |b| b.iter(|| run_once(stepping)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
