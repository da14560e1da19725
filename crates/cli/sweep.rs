//! `clutchpack sweep`.

use crate::common::{self, BadInput};
use anyhow::{Context, Result};
use clutchpack_sdk::analysis::{
    fatigue_spread_table, sweep_fits, sweep_rows, sweep_table, DiscFatigueSpread, PolyFit,
    SweepCase, SweepRow, TableFormat,
};
use clutchpack_sdk::scene::{Override, Scene};
use clutchpack_sdk::{CaseRuns, EngineChoice, MemberFatigue, Simulation, MAX_BATCH_CASES};
use serde::Serialize;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `clutchpack sweep`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Example (the paper's Fig 3, with 16-member ensembles):\n  clutchpack sweep scenes/hu-table2.toml --param defaults.oil.film_thickness_m \\\n      --values 0,25e-6,50e-6,75e-6,100e-6 --ensemble 16 --plot fig3.png"
)]
pub struct SweepArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// The scene key to sweep, as a dotted path (`defaults.oil.film_thickness_m`).
    #[arg(long, value_name = "KEY")]
    pub param: String,
    /// Comma-separated values of the parameter, in its unit (`0,25e-6,50e-6`).
    #[arg(long, value_delimiter = ',', required = true, num_args = 1.., allow_negative_numbers = true)]
    pub values: Vec<f64>,
    /// Run each value as K cases whose discs start at K positions spread evenly across the
    /// free play (the rattle is chaotic: report a mean and a spread, not one sample). With
    /// K = 1 the scene's own initial positions are used.
    #[arg(long, value_name = "K", default_value_t = 1)]
    pub ensemble: usize,
    /// Cases run in parallel (default: the number of cores); at most the number of cases
    /// and [`MAX_JOBS`].
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
    /// Engine (`reference` or `multibody`); default: the scene's, else the reference engine
    /// for a torsional pack.
    #[arg(long, value_parser = common::engine_parser())]
    pub engine: Option<EngineChoice>,
    /// Further overrides applied to every case (`KEY=VALUE`, repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<Override>,
    /// Write the sweep table and fits as JSON (an existing FILE is replaced).
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// Plot the peaks against the parameter with quadratic fits (PNG or SVG; an existing FILE
    /// is replaced).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

#[derive(Serialize)]
struct FitJson {
    disc: String,
    /// Coefficients c0, c1, c2 of max positive peak (N) = c0 + c1 x + c2 x^2.
    max_positive: PolyFit,
    /// Same for the max negative peak (N).
    max_negative: PolyFit,
}

#[derive(Serialize)]
struct SweepSummary {
    scene: String,
    engine: String,
    param: String,
    values: Vec<f64>,
    ensemble: usize,
    jobs: usize,
    cases: usize,
    wall_time_s: f64,
    rows: Vec<SweepRow>,
    fits: Vec<FitJson>,
    /// Per value: each disc's damage rate over the members (mean, spread) and life.
    fatigue: Vec<FatigueJson>,
}

#[derive(Serialize)]
struct FatigueJson {
    value: f64,
    discs: Vec<DiscFatigueSpread>,
}

/// The most cases (values x members) one sweep runs: every case's statistics are held in
/// memory until the table is printed.
pub const MAX_SWEEP_CASES: usize = MAX_BATCH_CASES;

pub fn sweep(a: SweepArgs) -> Result<ExitCode> {
    if a.ensemble == 0 || a.ensemble > MAX_SWEEP_CASES {
        return Err(BadInput(format!(
            "--ensemble {}: expected an integer in 1..={MAX_SWEEP_CASES}",
            a.ensemble
        ))
        .into());
    }
    match a.values.len().checked_mul(a.ensemble) {
        Some(n) if n <= MAX_SWEEP_CASES => {}
        _ => {
            return Err(BadInput(format!(
                "{} values x {} members: a sweep may have at most {MAX_SWEEP_CASES} cases \
                 (a study file runs more, in shards)",
                a.values.len(),
                a.ensemble
            ))
            .into())
        }
    }
    if a.values.iter().any(|v| !v.is_finite()) {
        return Err(BadInput(format!(
            "--values {:?}: every value must be finite",
            a.values
        ))
        .into());
    }
    let jobs = a.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    if jobs == 0 {
        return Err(BadInput("--jobs must be at least 1".into()).into());
    }
    // never more threads than cases (nor than a sane maximum)
    let jobs = jobs.min(a.values.len() * a.ensemble).clamp(1, MAX_JOBS);
    let mut outs = Vec::new();
    for (flag, p) in [
        ("--summary-json", a.summary_json.as_deref()),
        ("--plot", a.plot.as_deref()),
    ] {
        if let Some(path) = p {
            outs.push(if flag == "--plot" {
                crate::outputs::Output::figure(flag, path)
            } else {
                crate::outputs::Output::file(flag, path)
            });
        }
    }
    crate::outputs::check_outputs(&outs, &[a.scene.as_path()])?;
    // Load every case first, so that bad input is reported before any work.
    let mut scenes = Vec::new();
    for v in &a.values {
        let mut sets = a.sets.clone();
        sets.push(Override {
            key: a.param.clone(),
            value: format!("{v:e}"),
        });
        let scene = clutchpack_sdk::load_scene(Some(&a.scene), &sets).with_context(|| {
            format!("case {} = {}", a.param, clutchpack_sdk::model::fmt_num(*v))
        })?;
        scenes.push(scene);
    }
    // sweeps take pack scenes only: a network is refused before any case runs
    let sim = Simulation::new(scenes[0].clone(), a.engine)?;
    sim.pack_only()?;
    let engine_name = sim.engine_name().to_string();
    let show = indicatif::ProgressBar::new(0);
    show.set_style(
        indicatif::ProgressStyle::with_template("sweep [{bar:30}] {pos}/{len} cases, eta {eta}")
            .expect("static template")
            .progress_chars("=> "),
    );
    // SIGINT, SIGTERM and SIGHUP stop the sweep: the cases done so far are reported.
    let stop = crate::signals::flag();
    let CaseRuns {
        cases,
        fatigue,
        wall_s: wall,
        unfinished,
    } = clutchpack_sdk::run_cases(
        &scenes,
        &a.values,
        &a.param,
        a.ensemble,
        jobs,
        a.engine,
        &stop,
        &|done, total| {
            show.set_length(total as u64);
            show.set_position(done as u64);
        },
    )?;
    show.finish_and_clear();
    let n_cases = a.values.len() * a.ensemble;
    if unfinished > 0 {
        eprintln!(
            "interrupted ({}): {} of {n_cases} cases finished; the table and outputs hold those",
            crate::signals::received_name(),
            n_cases - unfinished
        );
    }
    // values whose every member was stopped are left out of the tables and the fits
    let kept: Vec<usize> = (0..cases.len())
        .filter(|&i| !cases[i].members.is_empty())
        .collect();
    let fatigue: MemberFatigue = kept.iter().map(|&i| fatigue[i].clone()).collect();
    let kept_scenes: Vec<&Scene> = kept.iter().map(|&i| &scenes[i]).collect();
    let cases: Vec<SweepCase> = kept.iter().map(|&i| cases[i].clone()).collect();
    let rows = sweep_rows(&cases);
    let degree = if cases.len() >= 3 {
        2
    } else {
        cases.len().saturating_sub(1)
    };
    let fits = if degree >= 1 {
        sweep_fits(&rows, degree).context("fitting the peaks")?
    } else {
        Vec::new()
    };

    out!(
        "{}: {} cases ({} values x {} members) with the {} engine in {:.2} s wall on {} threads",
        scenes[0].name,
        n_cases,
        a.values.len(),
        a.ensemble,
        engine_name,
        wall,
        jobs
    );
    out!(
        "per-tooth peak loads against {} (ensemble mean, std, min..max)",
        a.param
    );
    out!(
        "{}",
        sweep_table(&a.param, &rows, TableFormat::Text).trim_end()
    );
    for (disc, p, n) in &fits {
        out!(
            "{disc}: max + = {} (R^2 {:.3}); max - = {} (R^2 {:.3})",
            poly_text(p),
            p.r_squared,
            poly_text(n),
            n.r_squared
        );
    }
    let fatigue: Vec<(f64, Vec<DiscFatigueSpread>)> = cases
        .iter()
        .map(|c| c.value)
        .zip(clutchpack_sdk::ensemble_fatigue(&kept_scenes, &fatigue))
        .collect();
    out!("fatigue of the spline teeth against {} (damage rate per hour: ensemble mean, std, min..max; life at the mean rate, and at the largest..smallest rate)", a.param);
    out!(
        "{}",
        fatigue_spread_table(Some(&a.param), &fatigue, TableFormat::Text).trim_end()
    );
    if let Some(path) = &a.plot {
        crate::outputs::write_with(path, |tmp| {
            clutchpack_sdk::analysis::plot_sweep(tmp, &a.param, &rows, &fits)
                .with_context(|| format!("plotting {}", path.display()))
        })?;
    }
    if let Some(path) = &a.summary_json {
        let summary = SweepSummary {
            scene: scenes[0].name.clone(),
            engine: engine_name,
            param: a.param.clone(),
            values: a.values.clone(),
            ensemble: a.ensemble,
            jobs,
            cases: n_cases,
            wall_time_s: wall,
            rows,
            fatigue: fatigue
                .into_iter()
                .map(|(value, discs)| FatigueJson { value, discs })
                .collect(),
            fits: fits
                .into_iter()
                .map(|(disc, max_positive, max_negative)| FitJson {
                    disc,
                    max_positive,
                    max_negative,
                })
                .collect(),
        };
        crate::outputs::write_json(path, &summary)?;
    }
    if unfinished > 0 {
        // 128 + signal, as a shell reports a command stopped by that signal
        return Ok(crate::signals::exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

/// The most threads `sweep --jobs` starts (more only cost memory and start-up time).
pub const MAX_JOBS: usize = 256;

fn poly_text(p: &PolyFit) -> String {
    p.coefficients
        .iter()
        .enumerate()
        .map(|(i, c)| match i {
            0 => format!("{c:.4e}"),
            1 => format!("{c:+.4e} x"),
            _ => format!("{c:+.4e} x^{i}"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}
