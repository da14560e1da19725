//! The `bench-8-disc` case of issue 3, read from `scenes/bench-8-disc.toml`: 8 identical
//! friction discs on one shaft, 0.1 s.
//!
//! Each disc: a steel annulus (inner radius 0.231 m, outer 0.300 m, 3 mm, 7850 kg/m^3, so
//! `J = rho pi t (Ro^4 - Ri^4) / 2 = 0.1943 kg m^2`), dry law with `r = 5 mm`, `p = 0.5 s/m`,
//! spline `n = 154`, `R = 0.231 m`, `alpha = 20 deg`, `d = 0.75 mm`, no drag; the shaft
//! turns at `100 + 4.378 sin(2 pi 104 t)` rad/s. Target (issue 3): less wall time than about
//! 0.17 s for the 0.1 s run (MuJoCo at a fixed 1 us step with the law in a native callback).
//!
//! Besides criterion's timings, the bench prints each mode's steps, impacts per disc,
//! microseconds per step and steps per impact once (the discs are identical and strike
//! together, so the steps per impact are per impact of the whole pack).
//!
//! What it measures: the eight discs start alike and strike in step, so they cost what one
//! disc costs on the shared step; no real pack rattles that way. The real pack, discs striking
//! out of step, is `benches/staggered.rs`. The adaptive modes here run the default scheme
//! (multirate on this prescribed-shaft pack), the fixed ones the shared step.

use clutchpack_model::{Collector, Engine};
use clutchpack_multibody::{
    AdaptiveStepping, DiscMount, MultibodyEngine, MultibodyOptions, Stepping,
};
use clutchpack_scene::Scene;
use criterion::{criterion_group, criterion_main, Criterion};
use std::path::Path;
use std::time::Instant;

/// The scene file of the benchmark (the bench runs from the repository).
fn bench_scene() -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/bench-8-disc.toml");
    clutchpack_scene::load(&path, &[])
        .unwrap_or_else(|e| panic!("the benchmark reads {}: {e}", path.display()))
}

pub fn modes(scene: &Scene) -> Vec<(&'static str, Stepping, DiscMount)> {
    let adaptive = Stepping::Adaptive(AdaptiveStepping {
        max_step_s: scene.simulation.max_step_s,
        ..Default::default()
    });
    let fixed = Stepping::Fixed { dt_s: 1e-6 };
    vec![
        ("adaptive, joints", adaptive, DiscMount::Joint),
        ("adaptive, locked axes", adaptive, DiscMount::LockedAxes),
        ("fixed 1us, joints", fixed, DiscMount::Joint),
        ("fixed 1us, locked axes", fixed, DiscMount::LockedAxes),
    ]
}

pub fn run_once(scene: &Scene, stepping: Stepping, mount: DiscMount) -> (u64, usize) {
    let mut e = MultibodyEngine::new(
        scene.pack.clone(),
        MultibodyOptions {
            record_rate_hz: scene.simulation.record_rate_hz,
            stepping,
            mount,
            ..Default::default()
        },
    )
    .expect("engine");
    let mut c = Collector::default();
    let stats = e.run(scene.simulation.duration_s, &mut c).expect("run");
    (stats.steps, c.impacts.len())
}

fn bench(c: &mut Criterion) {
    let scene = bench_scene();
    let discs = scene.pack.discs.len() as f64;
    let mut g = c.benchmark_group("bench-8-disc 0.1 s");
    g.sample_size(10);
    for (name, stepping, mount) in modes(&scene) {
        let start = Instant::now();
        let (steps, impacts) = run_once(&scene, stepping, mount);
        let wall = start.elapsed().as_secs_f64();
        // The 8 discs are identical and start alike, so they strike together: an impact of
        // the pack is 8 disc impacts in the same steps.
        let pack_impacts = impacts as f64 / discs;
        eprintln!(
            "{name}: {steps} steps, {pack_impacts} impacts per disc, {wall:.3} s, {:.2} us/step, {:.0} steps per impact",
            wall / steps as f64 * 1e6,
            steps as f64 / pack_impacts.max(1.0)
        );
        g.bench_function(name, |b| b.iter(|| run_once(&scene, stepping, mount)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
