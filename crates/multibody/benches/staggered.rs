//! The staggered pack of issue 9 (`clutchpack_model::cases::staggered_pack`): N identical
//! benchmark discs (those of `scenes/bench-8-disc.toml`) on the benchmark's prescribed shaft,
//! disc `i` started at rest relative to the shaft at `phi_i = -0.8 g0 (2 (i + 1/2) / N - 1)`,
//! so that they strike out of step as the discs of a real pack do; 0.1 s simulated, samples at
//! 10 kHz, adaptive steps of at most 0.1 ms (the scene defaults).
//!
//! Before criterion's timings the bench prints, for N = 1, 4, 8 and 16 and both schemes
//! (multirate, the default here, and the shared step), the median wall time of a few runs, the
//! per-disc cost relative to one disc, world steps, coupling sub-steps and impacts.
//! `cargo bench -p clutchpack_multibody --bench staggered -- summary-only` prints the table alone
//! (no criterion group matches that filter).

use clutchpack_model::cases::staggered_pack;
use clutchpack_model::{Collector, Engine};
use clutchpack_multibody::{MultibodyEngine, MultibodyOptions, Scheme};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use std::time::Instant;

/// Simulated time of one run, s (issue 9).
const DURATION_S: f64 = 0.1;

/// What one run did: world steps, coupling sub-steps, impacts.
struct Counts {
    steps: u64,
    substeps: u64,
    impacts: usize,
}

fn run_once(n: usize, scheme: Scheme) -> Counts {
    let mut e = MultibodyEngine::new(
        staggered_pack(n),
        MultibodyOptions {
            scheme,
            ..MultibodyOptions::default()
        },
    )
    .expect("engine");
    let mut c = Collector::default();
    let stats = e.run(DURATION_S, &mut c).expect("run");
    Counts {
        steps: stats.steps,
        substeps: e.coupling_substeps(),
        impacts: c.impacts.len(),
    }
}

/// Median wall time of `runs` runs, s, and the last run's counts.
fn median_wall(n: usize, scheme: Scheme, runs: usize) -> (f64, Counts) {
    let mut walls = Vec::with_capacity(runs);
    let mut counts = None;
    for _ in 0..runs {
        let start = Instant::now();
        counts = Some(run_once(n, scheme));
        walls.push(start.elapsed().as_secs_f64());
    }
    walls.sort_by(f64::total_cmp);
    (walls[runs / 2], counts.expect("runs > 0"))
}

fn summary() {
    for (name, scheme) in [("multirate", Scheme::Multirate), ("shared", Scheme::Shared)] {
        let mut one_disc = None;
        for n in [1usize, 4, 8, 16] {
            let runs = if n <= 4 { 9 } else { 5 };
            let (wall, c) = median_wall(n, scheme, runs);
            let per_disc = wall / n as f64;
            let base = *one_disc.get_or_insert(per_disc);
            eprintln!(
                "staggered {n:2} discs, {name:9}: {:8.2} ms wall (median of {runs}), per disc \
                 {:.2}x one disc; {} world steps, {} coupling sub-steps, {} impacts, {:.0} \
                 sub-steps per impact",
                wall * 1e3,
                per_disc / base,
                c.steps,
                c.substeps,
                c.impacts,
                c.substeps.max(c.steps) as f64 / c.impacts.max(1) as f64,
            );
        }
    }
}

fn bench(c: &mut Criterion) {
    summary();
    let mut g = c.benchmark_group("staggered 0.1 s");
    g.sample_size(10);
    for n in [1usize, 8, 16] {
        for (name, scheme) in [("multirate", Scheme::Multirate), ("shared", Scheme::Shared)] {
            g.bench_with_input(BenchmarkId::new(name, n), &n, |b, &n| {
                b.iter(|| run_once(n, scheme))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
