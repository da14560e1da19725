//! The paper case (MODEL.md section 4): 0.3 s simulated, one disc, h_o = 0 and 50 um, with
//! the default settings and samples at 20 kHz discarded. Target: under 30 ms per run on the
//! 2-core CI machine (release build).

use clutchpack_model::cases::paper_pack;
use clutchpack_model::*;
use clutchpack_reference::{ReferenceEngine, ReferenceOptions};
use criterion::{criterion_group, criterion_main, Criterion};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper_case_0.3s");
    g.sample_size(20);
    for h_o in [0.0, 50e-6] {
        g.bench_function(format!("h_o={:.0}um", h_o * 1e6), |b| {
            b.iter(|| {
                let mut e = ReferenceEngine::new(
                    paper_pack(h_o),
                    ReferenceOptions {
                        record_rate_hz: 20_000.0,
                        ..ReferenceOptions::default()
                    },
                );
                let mut obs = Collector::default();
                e.run(0.3, &mut obs).unwrap();
                obs.impacts.len()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
