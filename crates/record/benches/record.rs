//! Cost of recording: one sample of an 8-disc pack written with the default options (one
//! `/shaft`, eight `/discs/<d>/spline`, one `/tf` message, the scene colour updates and the
//! flushes), with and without per-tooth loads (24 teeth), and opening a recording.
//!
//! `cargo bench -p clutchpack_record`. Divide by the engine's cost per sample interval to
//! get the recording overhead of a run.

use clutchpack_model::{DiscSample, Sample};
use clutchpack_record::{open, DiscGeometry, RecordOptions, Recorder, RunInfo};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

const DISCS: usize = 8;

fn info() -> RunInfo {
    RunInfo {
        engine: "bench".into(),
        scene_name: "bench".into(),
        scene_text: "name = \"bench\"\n".into(),
        discs: (0..DISCS)
            .map(|i| DiscGeometry {
                name: format!("d{i}"),
                inner_radius_m: 0.03,
                outer_radius_m: 0.06,
                thickness_m: 0.002,
                z_m: 0.005 * i as f64,
                teeth: 24,
                teeth_outside: false,
            })
            .collect(),
        ..Default::default()
    }
}

fn sample(k: u64, teeth: usize) -> Sample {
    let t = k as f64 * 1e-5;
    Sample {
        t_s: t,
        shaft_angle_rad: 100.0 * t,
        shaft_speed_rad_s: 100.0,
        discs: (0..DISCS)
            .map(|i| {
                let load = if (k / 50 + i as u64).is_multiple_of(7) {
                    -400.0 * ((k % 50) as f64 / 50.0)
                } else {
                    0.0
                };
                DiscSample {
                    angle_rad: 100.0 * t - 1e-3 * (t * 3e3 + i as f64).sin(),
                    speed_rad_s: 100.0 + (t * 3e3).cos(),
                    rel_angle_rad: 1e-3 * (t * 3e3 + i as f64).sin(),
                    penetration_m: -1e-6,
                    closing_speed_m_s: 0.01 * (t * 3e3).cos(),
                    load_n: load,
                    torque_n_m: 0.1 * load,
                    engaged: load != 0.0,
                    stiffness: 3e9,
                    tooth_loads_n: vec![load; teeth],
                    center_offset_m: [0.0, 0.0],
                }
            })
            .collect(),
    }
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join("clutchpack_record_bench");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, per_tooth) in [
        ("write_sample_8_discs", false),
        ("write_sample_8_discs_per_tooth", true),
    ] {
        let opts = RecordOptions {
            per_tooth,
            ..Default::default()
        };
        let mut rec = Recorder::create(dir.join(format!("{name}.mcap")), &info(), &opts).unwrap();
        let samples: Vec<Sample> = (0..1000)
            .map(|k| sample(k, if per_tooth { 24 } else { 0 }))
            .collect();
        let mut k = 0usize;
        c.bench_function(name, |b| {
            b.iter(|| {
                let mut s = samples[k % samples.len()].clone();
                s.t_s += (k / samples.len()) as f64 * 1e-2;
                rec.write_sample(black_box(&s)).unwrap();
                k += 1;
            })
        });
        rec.finish(None).unwrap();
    }
    // a 0.2 s run at 100 kHz: 20 000 samples, 200 000 messages
    let path = dir.join("open.mcap");
    let mut rec = Recorder::create(&path, &info(), &RecordOptions::default()).unwrap();
    for k in 0..20_000 {
        rec.write_sample(&sample(k, 0)).unwrap();
    }
    rec.finish(None).unwrap();
    c.bench_function("open_200k_messages", |b| {
        b.iter(|| black_box(open(&path).unwrap().info().messages))
    });
    c.bench_function("load_histories_200k_messages", |b| {
        let r = open(&path).unwrap();
        b.iter(|| black_box(r.load_histories().len()))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
