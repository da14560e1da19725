//! The open brake pack of issues 20 and 21 (`cases::staggered_brake`, the pack
//! `bench/mujoco/brake.py` times in MuJoCo): N staggered discs on the prescribed shaft, N + 1
//! plates on the housing, the open gaps' drag between neighbours; 10 ms simulated with the default
//! settings, samples discarded. The open pack's multirate scheme (the default) for N = 1 and
//! 16, and the monolithic scheme (its oracle) at the same sizes. What to look for: time per
//! disc about constant in N for the multirate scheme, growing for the monolithic one.
//! `clutchpack bench --pack-only` times the same packs over 0.1 s for N = 1, 4, 8, 16.

use clutchpack_model::cases::staggered_brake;
use clutchpack_model::*;
use clutchpack_reference::{ReferenceEngine, ReferenceOptions, Scheme};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

/// Simulated time of one iteration, s.
const DURATION_S: f64 = 0.01;

/// Counts the impacts and discards the rest (the engine's cost alone).
struct Discard(usize);

impl Observer for Discard {
    fn impact(&mut self, _e: &ImpactEvent) {
        self.0 += 1;
    }
}

fn brake(c: &mut Criterion) {
    let mut g = c.benchmark_group("reference_brake_pack_10ms");
    g.sample_size(10);
    for (label, scheme) in [
        ("multirate", Scheme::Multirate),
        ("monolithic", Scheme::Monolithic),
    ] {
        for n in [1usize, 16] {
            // throughput in discs: criterion prints the time per disc
            g.throughput(Throughput::Elements(n as u64));
            g.bench_with_input(BenchmarkId::new(label, n), &n, |b, &n| {
                b.iter(|| {
                    let mut e =
                        ReferenceEngine::new(staggered_brake(n), ReferenceOptions::default())
                            .with_scheme(scheme);
                    let mut obs = Discard(0);
                    e.run(DURATION_S, &mut obs).expect("run");
                    obs.0
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, brake);
criterion_main!(benches);
