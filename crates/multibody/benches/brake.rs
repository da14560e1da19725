//! The real pack of issue 20 (`clutchpack_model::cases::staggered_brake`): N staggered
//! benchmark discs on the prescribed shaft and N + 1 separator plates on the fixed housing,
//! with the open gaps' Couette drag between neighbours (the pack `bench/mujoco/brake.py`
//! times in MuJoCo); 10 ms simulated, samples at 10 kHz, the engine's default scheme
//! (multirate: the bodies are independent within a world step but for the gaps' drag, held
//! over it). `clutchpack bench` times the same packs over 0.1 s for N = 1, 4, 8, 16 with the
//! per-disc growth.

use clutchpack_model::cases::staggered_brake;
use clutchpack_model::{Collector, Engine};
use clutchpack_multibody::{MultibodyEngine, MultibodyOptions};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

/// Simulated time of one iteration, s.
const DURATION_S: f64 = 0.01;

fn brake(c: &mut Criterion) {
    let mut g = c.benchmark_group("brake_pack_10ms");
    g.sample_size(10);
    for n in [1usize, 16] {
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, &n| {
            b.iter(|| {
                let mut e = MultibodyEngine::new(
                    staggered_brake(n),
                    MultibodyOptions::default().with_record_rate(1e4),
                )
                .expect("engine");
                let mut obs = Collector::default();
                e.run(DURATION_S, &mut obs).expect("run")
            })
        });
    }
    g.finish();
}

criterion_group!(benches, brake);
criterion_main!(benches);
