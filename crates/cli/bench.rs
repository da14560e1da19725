//! `clutchpack bench`: speed figures as ratios and times, printed, never asserted.

use crate::common::{self, RunCollector};
use crate::sweep::run_cases;
use anyhow::Result;
use clutchpack_scene::Override;
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `clutchpack bench`.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Repetitions of the paper case (the median is reported).
    #[arg(long, default_value_t = 20)]
    pub runs: usize,
    /// Repetitions of each sweep timing (the best is reported).
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

pub fn bench(a: BenchArgs) -> Result<ExitCode> {
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    if cfg!(debug_assertions) {
        out!("warning: a debug build; run `cargo run --release -- bench` for meaningful figures");
    }
    out!("machine: {cores} cores available");

    // 1. The paper case, 0.3 s simulated, one disc, h_o = 0 (the built-in default scene).
    let scene = common::load_scene(None, &[])?;
    let mut times = Vec::new();
    let mut steps = 0;
    let mut impacts = 0;
    for _ in 0..a.runs.max(1) {
        let mut engine = common::make_engine(&scene, None)?;
        let mut obs = RunCollector::new(1, false);
        let t0 = Instant::now();
        let s = engine.run(scene.simulation.duration_s, &mut obs)?;
        times.push(t0.elapsed().as_secs_f64());
        steps = s.steps;
        impacts = obs.impacts.len();
    }
    let t = median(times);
    out!(
        "paper case (0.3 s, 1 disc): {:.2} ms per run (median of {}), {steps} steps, {impacts} impacts, {:.0} ns per step; target < 30 ms: {}",
        t * 1e3,
        a.runs.max(1),
        t / steps as f64 * 1e9,
        if t < 0.030 { "met" } else { "NOT met" }
    );

    // 2. A 16-case sweep (4 film thicknesses x 4 ensemble members), 1 thread vs 2.
    let values = [0.0, 25e-6, 50e-6, 75e-6];
    let param = "defaults.oil.film_thickness_m";
    let scenes = values
        .iter()
        .map(|v| {
            common::load_scene(
                None,
                &[Override {
                    key: param.into(),
                    value: format!("{v:e}"),
                }],
            )
        })
        .collect::<Result<Vec<_>>>()?;
    let mut best = [f64::INFINITY; 2];
    for _ in 0..a.repeats.max(1) {
        for (i, jobs) in [1usize, 2].into_iter().enumerate() {
            let (_, wall) = run_cases(&scenes, &values, param, 4, jobs, None, None)?;
            best[i] = best[i].min(wall);
        }
    }
    out!(
        "16-case sweep: --jobs 1 {:.1} ms, --jobs 2 {:.1} ms (best of {}): speed-up {:.2}x; target >= 1.7x: {}",
        best[0] * 1e3,
        best[1] * 1e3,
        a.repeats.max(1),
        best[0] / best[1],
        if best[0] / best[1] >= 1.7 { "met" } else { "NOT met" }
    );
    Ok(ExitCode::SUCCESS)
}
