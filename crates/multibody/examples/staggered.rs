//! Runs the staggered pack of issue 9 (`clutchpack_model::cases::staggered_pack`) once, as a
//! whole process, for timing it side by side with other engines and for profiling:
//!
//! ```text
//! cargo build --release -p clutchpack_multibody --example staggered
//! time target/release/examples/staggered 16            # 16 discs, 0.1 s, default scheme
//! target/release/examples/staggered 8 shared 0.05 20   # 8 discs, shared step, 50 ms, 20 runs
//! ```
//!
//! Arguments: discs (default 16), scheme `auto`, `multirate` or `shared` (default `auto`),
//! simulated time in s (default 0.1), runs (default 1). Prints the scheme that ran and why,
//! the counts of the last run and the wall time per run.

use clutchpack_model::cases::staggered_pack;
use clutchpack_model::{Collector, Engine};
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
    let start = Instant::now();
    let mut last = None;
    for _ in 0..runs {
        let mut e = MultibodyEngine::new(staggered_pack(n), options.clone()).expect("engine");
        let mut c = Collector::default();
        let stats = e.run(duration, &mut c).expect("run");
        last = Some((e, stats, c.impacts.len()));
    }
    let wall = start.elapsed().as_secs_f64() / runs.max(1) as f64;
    if let Some((e, stats, impacts)) = last {
        println!("{}", e.scheme_explanation());
        println!(
            "{n} discs, {duration} s: {} world steps, {} coupling sub-steps, {} tooth-law \
             evaluations, {impacts} impacts, \
             {:.2} ms wall per run",
            stats.steps,
            e.coupling_substeps(),
            stats.rhs_evals,
            wall * 1e3
        );
    }
}
