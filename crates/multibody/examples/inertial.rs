//! Runs the staggered pack of issue 9 on an inertial shaft (`J1 = 2 kg m^2`, driven by the
//! benchmark's sine as the torque `J1 d(profile)/dt`, eq 4) once, as a whole process, for
//! timing the multirate scheme on an inertial shaft against the shared step (issue 20):
//!
//! ```text
//! cargo build --release -p clutchpack_multibody --example inertial
//! target/release/examples/inertial 16                 # 16 discs, 0.1 s, default scheme
//! target/release/examples/inertial 8 shared 0.05 5    # 8 discs, shared step, 50 ms, 5 runs
//! ```
//!
//! Arguments as `examples/staggered.rs`: discs (default 16), scheme `auto`, `multirate` or
//! `shared` (default `auto`), simulated time in s (default 0.1), runs (default 1). Prints the
//! scheme that ran, the counts of the last run and the wall time per run (the least of the
//! runs).

use clutchpack_model::cases::{bench_drive, staggered_pack};
use clutchpack_model::{Collector, Engine, Shaft, ShaftExcitation};
use clutchpack_multibody::{MultibodyEngine, MultibodyOptions, Scheme};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| args.get(i).map(String::as_str);
    let n: usize = arg(0).map_or(16, |s| s.parse().expect("discs: a whole number"));
    let scheme = match arg(1).unwrap_or("auto") {
        "auto" => Scheme::Auto,
        "multirate" => Scheme::Multirate,
        "shared" => Scheme::Shared,
        other => panic!("scheme {other}: expected auto, multirate or shared"),
    };
    let duration: f64 = arg(2).map_or(0.1, |s| s.parse().expect("duration: seconds"));
    let runs: usize = arg(3).map_or(1, |s| s.parse().expect("runs: a whole number"));
    let options = MultibodyOptions {
        scheme,
        ..MultibodyOptions::default()
    };
    let mut pack = staggered_pack(n);
    pack.shaft = Shaft::Inertial {
        inertia_kg_m2: 2.0,
        damping_n_m_s_rad: 0.0,
        excitation: ShaftExcitation::Profile(bench_drive()),
    };
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = Instant::now();
        let mut e = MultibodyEngine::new(pack.clone(), options.clone()).expect("engine");
        let mut c = Collector::default();
        let stats = e.run(duration, &mut c).expect("run");
        best = best.min(start.elapsed().as_secs_f64());
        last = Some((e, stats, c.impacts.len()));
    }
    if let Some((e, stats, impacts)) = last {
        println!("{}", e.scheme_explanation());
        println!(
            "{n} discs, {duration} s: {} world steps, {} coupling sub-steps, {} tooth-law \
             evaluations, {impacts} impacts, {:.2} ms wall per run ({:.3} ms per disc)",
            stats.steps,
            e.coupling_substeps(),
            stats.rhs_evals,
            best * 1e3,
            best * 1e3 / n as f64
        );
    }
}
