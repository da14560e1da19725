//! The staggered pack of issue 9 (`cases::staggered_pack`, the pack of
//! `scenes/staggered-*-disc.toml`): N identical discs spread across +-0.8 of the free play,
//! so they strike out of step as a real pack's discs do; 0.1 s simulated with the default
//! settings, samples discarded. The multirate scheme (the default, and on one thread) for
//! N = 1, 8 and 64, and the monolithic scheme (its oracle) for N = 1 and 8 for comparison.
//! What to look for: time per disc roughly constant in N for the multirate scheme (issue 9:
//! at most 1.3x the 1-disc figure at 64 discs); the monolithic scheme's grows with N.

use clutchpack_model::cases::staggered_pack;
use clutchpack_model::*;
use clutchpack_reference::{ReferenceEngine, ReferenceOptions, Scheme};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

/// Discards everything (the engine's cost alone).
struct Discard(usize);

impl Observer for Discard {
    fn sample(&mut self, _s: &Sample) {}
    fn impact(&mut self, _e: &ImpactEvent) {
        self.0 += 1;
    }
}

fn run(n: usize, scheme: Scheme, parallel: bool) -> usize {
    let mut e = ReferenceEngine::new(staggered_pack(n), ReferenceOptions::default())
        .with_scheme(scheme)
        .with_parallel(parallel);
    let mut obs = Discard(0);
    e.run(0.1, &mut obs).unwrap();
    obs.0
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("staggered_0.1s");
    g.sample_size(10);
    let cases: [(&str, Scheme, bool, &[usize]); 3] = [
        ("multirate", Scheme::Multirate, true, &[1, 8, 64]),
        ("multirate_1_thread", Scheme::Multirate, false, &[1, 8, 64]),
        ("monolithic", Scheme::Monolithic, false, &[1, 8]),
    ];
    for (label, scheme, parallel, sizes) in cases {
        for &n in sizes {
            // throughput in discs: criterion prints the time per disc
            g.throughput(Throughput::Elements(n as u64));
            g.bench_with_input(BenchmarkId::new(label, n), &n, |b, &n| {
                b.iter(|| run(n, scheme, parallel))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
