//! `clutchpack fit`: a least-squares fit of scene keys to measured series
//! (`clutchpack_sdk::fit`), with a progress bar, a stop on Ctrl-C that keeps the best point so
//! far, the table of fitted values with their 95 % intervals and correlations, and the fitted
//! scene written beside the input.

use crate::common::{self, BadInput};
use crate::outputs::Output;
use anyhow::{Context, Result};
use clap::Args;
use clutchpack_sdk::fit::{
    CoverageRequest, CoverageResult, FitOptions, FitResult, IDENTIFIABILITY_CORRELATION,
};
use clutchpack_sdk::scene::Override;
use clutchpack_sdk::{EngineChoice, Fit, FitParam, FitRequest, FitSignal};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `clutchpack fit SCENE --data TRACE.csv --param KEY[=START][:LO:HI][:log] ... --match
/// SIGNAL[=COLUMN][:WEIGHT] ...`
#[derive(Args, Debug)]
#[command(after_help = "\
Example (docs/calibration.md):
  clutchpack fit scenes/coupled-clutches.toml --data trace.csv \\
    --param 'couplings[*].mu=0.35:0.05:2:log' --param 'couplings[*].peak=1.43:1:3' \\
    --param 'couplings[1].force.start_s=0.52:0.1:0.8' \\
    --param 'couplings[2].force.start_s=0.63:0.5:1.3' \\
    --match J1=w1 --match J2=w2 --match J3=w3 --match J4=w4")]
pub struct FitArgs {
    /// Scene file (TOML) whose keys are fitted: a pack or a network scene.
    pub scene: PathBuf,
    /// The measured series: a CSV file with a header row, a time column (`--time-column`,
    /// s, strictly increasing, within the run) and one column per matched signal. With
    /// `--variant KEY`, one row per variant of the scene instead (a column named KEY). Or a
    /// network scene's recording (`RUN.mcap`, `clutchpack run --out`), whose series are
    /// named as the signals (`J1.speed_rad_s`, `clutch1.torque_n_m`).
    #[arg(long, value_name = "TRACE.csv", required_unless_present = "coverage")]
    pub data: Option<PathBuf>,
    /// The data's time column.
    #[arg(long, value_name = "NAME", default_value = "time_s")]
    pub time_column: String,
    /// A fitted parameter: `KEY[=START][:LO:HI][:log]`. KEY is a scene key as `--set` takes
    /// it (`couplings[1].force.start_s`); `[*]` stands for every item of an array that sets
    /// the key and several keys joined by `,` take one value (`couplings[*].mu`: one mu for
    /// every clutch). START defaults to the scene's value, LO:HI to the key's own rule;
    /// `:log` fits ln(KEY) (bounds > 0). Repeatable.
    #[arg(
        long = "param",
        value_name = "KEY[=START][:LO:HI][:log]",
        required = true
    )]
    pub params: Vec<FitParam>,
    /// A signal of the run matched to a data column: `SIGNAL[=COLUMN][:WEIGHT]`. A network's
    /// signals: `BODY` or `BODY.speed_rad_s`, `BODY.angle_rad`, `COUPLING.torque_n_m`; a
    /// pack's: its co-simulation outputs (`drum.speed_rad_s`, `pack.carrier_torque_n_m`,
    /// `interfaces[1].torque_n_m`, `discs[2].speed_rad_s`, ...); with `--variant`, a body's
    /// impact peaks over the run: `BODY.max_positive_n`, `BODY.max_negative_n`,
    /// `BODY.p99_abs_n`, `BODY.mean_top10_abs_n`. COLUMN defaults to SIGNAL, WEIGHT (> 0;
    /// 1/sigma of the measurement) to 1. Repeatable.
    #[arg(
        long = "match",
        value_name = "SIGNAL[=COLUMN][:WEIGHT]",
        required = true
    )]
    pub signals: Vec<FitSignal>,
    /// The data's rows are variants of the scene: each sets KEY (dotted; `[*]` and `,` as
    /// in --param) to its value in the data's column named KEY; the signals are then one
    /// value per run (impact peaks).
    #[arg(long, value_name = "KEY")]
    pub variant: Option<String>,
    /// With --variant: each variant's statistics are the mean of N runs from starts spread
    /// over the free play (as `sweep --ensemble`): a rattle's peak is chaotic, one run one
    /// sample of it.
    #[arg(long, value_name = "N", default_value_t = 1, requires = "variant")]
    pub ensemble: u64,
    /// A coverage study instead of a fit: N synthetic traces of the scene at its own values
    /// (the truth) with normal noise (`--noise`), each fitted from the --param starts; the
    /// count of 95 % intervals holding the truth (expected near 95 %). The traces' rows are
    /// --data's (its values unused), else the run's record-rate grid.
    #[arg(long, value_name = "N")]
    pub coverage: Option<usize>,
    /// The coverage study's noise: standard deviation relative to each signal's RMS.
    #[arg(long, value_name = "SD", default_value_t = 0.01, requires = "coverage")]
    pub noise: f64,
    /// The coverage study's noise seed.
    #[arg(long, value_name = "SEED", default_value_t = 1, requires = "coverage")]
    pub seed: u64,
    /// Engine: `reference` or `multibody`; default: the scene's `simulation.engine`, else
    /// `reference`.
    #[arg(long, value_parser = common::engine_parser())]
    pub engine: Option<EngineChoice>,
    /// Override a scene key, held fixed during the fit (`--set KEY=VALUE`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<Override>,
    /// Most solver iterations.
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub max_iterations: usize,
    /// Relative forward-difference step of the Jacobian.
    #[arg(long, value_name = "H", default_value_t = 1e-6)]
    pub fd_step: f64,
    /// Where the fitted scene goes (TOML; default: `<scene>.fitted.toml` beside the scene,
    /// never the scene itself; an existing FILE is replaced).
    #[arg(long, value_name = "FILE")]
    pub fitted_scene: Option<PathBuf>,
    /// Write the result as JSON (values, errors, intervals, correlations, residuals per
    /// signal, runs, wall time, warnings; an existing FILE is replaced).
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// Plot measured against fitted, one panel per signal (PNG or SVG by extension).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
}

/// `<dir>/<stem>.fitted.toml` beside the scene.
fn fitted_path(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    scene.with_file_name(format!("{stem}.fitted.toml"))
}

/// Runs `clutchpack fit`.
pub fn fit(a: FitArgs) -> Result<ExitCode> {
    if !(a.fd_step > 0.0 && a.fd_step < 0.1) {
        return Err(BadInput(format!("--fd-step {}: must be in (0, 0.1)", a.fd_step)).into());
    }
    if a.ensemble == 0 {
        return Err(BadInput("--ensemble 0: at least 1 run per variant".into()).into());
    }
    let mut inputs = vec![a.scene.as_path()];
    inputs.extend(a.data.as_deref());
    let mut outs = Vec::new();
    let fitted = a
        .fitted_scene
        .clone()
        .unwrap_or_else(|| fitted_path(&a.scene));
    if a.coverage.is_some() {
        if a.plot.is_some() || a.fitted_scene.is_some() {
            return Err(BadInput(
                "--coverage writes no figure and no fitted scene (--summary-json has its numbers)"
                    .into(),
            )
            .into());
        }
    } else {
        outs.push(Output::file("--fitted-scene", &fitted));
        if let Some(p) = &a.plot {
            outs.push(Output::figure("--plot", p));
        }
    }
    if let Some(p) = &a.summary_json {
        outs.push(Output::file("--summary-json", p));
    }
    crate::outputs::check_outputs(&outs, &inputs)?;
    let prepared = Fit::new(FitRequest {
        scene: a.scene.clone(),
        sets: a.sets.clone(),
        engine: a.engine,
        data: a.data.clone(),
        time_column: a.time_column.clone(),
        variant: a.variant.clone(),
        ensemble: a.ensemble,
        params: a.params.clone(),
        signals: a.signals.clone(),
        options: FitOptions {
            max_iterations: a.max_iterations,
            fd_step: a.fd_step,
            ..FitOptions::default()
        },
    })?;
    if let Some(traces) = a.coverage {
        return coverage(&prepared, traces, &a);
    }
    let stop = crate::signals::flag();
    let pb = indicatif::ProgressBar::new(a.max_iterations as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("fit [{bar:30}] {pos}/{len} iterations {msg}")
            .expect("static template")
            .progress_chars("=> "),
    );
    let keys = prepared.param_keys();
    let result = prepared.run(Some(&stop), &mut |s, values| {
        pb.set_position(s.iteration as u64);
        let shown: Vec<String> = keys
            .iter()
            .zip(values)
            .map(|(k, v)| format!("{k}={v:.6}"))
            .collect();
        pb.set_message(format!(
            "{} runs, SSR {:.4e}, {}",
            s.evaluations,
            s.ssr,
            shown.join(" ")
        ));
    });
    pb.finish_and_clear();
    let result = result?;
    print_result(&result, &a.scene);
    let text = prepared.fitted_scene_text(&result)?;
    crate::outputs::write_text(&fitted, &text)?;
    out!("fitted scene: {}", fitted.display());
    if let Some(p) = &a.summary_json {
        crate::outputs::write_json(p, &result)?;
    }
    if let Some(p) = &a.plot {
        plot(p, &result)?;
    }
    for w in &result.warnings {
        eprintln!("warning: {w}");
    }
    if result.stopped {
        eprintln!(
            "interrupted ({}): the values are the best so far",
            crate::signals::received_name()
        );
        return Ok(crate::signals::exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

/// The table of fitted values, the correlations and the residuals per signal.
fn print_result(r: &FitResult, scene: &Path) {
    let runs = if r.scene_runs == r.runs {
        format!("{} runs", r.runs)
    } else {
        format!(
            "{} evaluations of {} variants x {} members ({} runs)",
            r.runs,
            r.signals.first().map_or(0, |s| s.points),
            r.ensemble,
            r.scene_runs
        )
    };
    out!(
        "{} ({}, {} engine): {}, {} iterations, {:.2} s wall; {}",
        r.scene,
        scene.display(),
        r.engine,
        runs,
        r.iterations,
        r.wall_time_s,
        r.reason
    );
    let w = r
        .params
        .iter()
        .map(|p| p.key.len())
        .max()
        .unwrap_or(3)
        .max(9);
    out!(
        "{:<w$}  {:>14}  {:>14}  {:>11}  {:>29}  {}",
        "parameter",
        "start",
        "fitted",
        "std error",
        "95 % interval",
        "unit"
    );
    for p in &r.params {
        out!(
            "{:<w$}  {:>14.8}  {:>14.8}  {:>11.3e}  [{:>13.8}, {:>13.8}]  {}{}",
            p.key,
            p.start,
            p.value,
            p.std_error,
            p.ci95_low,
            p.ci95_high,
            p.unit,
            if p.at_bound { "  (on a bound)" } else { "" }
        );
    }
    if r.params.len() > 1 {
        out!("correlations:");
        for (i, p) in r.params.iter().enumerate() {
            let row: Vec<String> = r.correlation[i][..=i]
                .iter()
                .map(|c| {
                    let mark = if c.abs() > IDENTIFIABILITY_CORRELATION && c.abs() < 1.0 {
                        "!"
                    } else {
                        " "
                    };
                    format!("{c:>+8.4}{mark}")
                })
                .collect();
            out!("  {:<w$}  {}", p.key, row.join(" "));
        }
    }
    out!("signals (fitted minus measured, RMS):");
    for s in &r.signals {
        out!(
            "  {:<20} column {:<12} weight {:<8} {:>6} points  RMS {:.6e} (start {:.6e})",
            s.signal,
            s.column,
            s.weight,
            s.points,
            s.rms,
            s.rms_start
        );
    }
    out!(
        "weighted SSR {:.6e} over {} degrees of freedom",
        r.ssr,
        r.dof
    );
}

/// The figure: one panel per signal, measured and fitted against time.
fn plot(path: &Path, r: &FitResult) -> Result<()> {
    let panels: Vec<_> = r
        .series
        .iter()
        .map(|s| clutchpack_sdk::analysis::Panel {
            y_label: s.signal.clone(),
            series: vec![
                (
                    "measured".to_string(),
                    s.x.iter()
                        .copied()
                        .zip(s.measured.iter().copied())
                        .collect(),
                ),
                (
                    "fitted".to_string(),
                    s.x.iter().copied().zip(s.fitted.iter().copied()).collect(),
                ),
            ],
            markers_only: false,
        })
        .collect();
    let title = format!("{}: measured and fitted ({} runs)", r.scene, r.runs);
    let x_label = if r.rows == "time_s" {
        "t [s]".to_string()
    } else {
        r.rows.clone()
    };
    crate::outputs::write_with(path, |tmp| {
        clutchpack_sdk::analysis::plot_panels(tmp, &title, &x_label, &panels)
            .with_context(|| format!("plotting {}", path.display()))
    })
}

/// `fit --coverage N`: the study, its table and its JSON.
fn coverage(prepared: &Fit, traces: usize, a: &FitArgs) -> Result<ExitCode> {
    let stop = crate::signals::flag();
    let pb = indicatif::ProgressBar::new(traces as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("coverage [{bar:30}] {pos}/{len} traces fitted")
            .expect("static template")
            .progress_chars("=> "),
    );
    let bar = pb.clone();
    let r = prepared.coverage(
        &CoverageRequest {
            traces,
            noise: a.noise,
            seed: a.seed,
        },
        Some(&stop),
        &mut move |done| bar.set_position(done as u64),
    );
    pb.finish_and_clear();
    let r = r?;
    print_coverage(&r, &a.scene);
    if let Some(p) = &a.summary_json {
        crate::outputs::write_json(p, &r)?;
    }
    if r.stopped {
        eprintln!(
            "interrupted ({}): the counts are of the traces fitted before",
            crate::signals::received_name()
        );
        return Ok(crate::signals::exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

/// The coverage table: per parameter, the truth, the count of intervals holding it, the
/// spread of the fitted values against the mean reported standard error.
fn print_coverage(r: &CoverageResult, scene: &Path) {
    out!(
        "coverage of the 95 % intervals, {} ({}, {} engine): {} traces, noise {} x RMS \
         (seed {}), {} points each; {} runs, {:.2} s wall",
        r.scene,
        scene.display(),
        r.engine,
        r.traces,
        r.noise,
        r.seed,
        r.points,
        r.runs,
        r.wall_time_s
    );
    let w = r
        .params
        .iter()
        .map(|p| p.key.len())
        .max()
        .unwrap_or(3)
        .max(9);
    out!(
        "{:<w$}  {:>14}  {:>9}  {:>14}  {:>11}  {:>11}  unit",
        "parameter",
        "truth",
        "covered",
        "fitted mean",
        "fitted sd",
        "mean se"
    );
    for p in &r.params {
        out!(
            "{:<w$}  {:>14.8}  {:>5}/{:<3}  {:>14.8}  {:>11.3e}  {:>11.3e}  {}",
            p.key,
            p.truth,
            p.covered,
            r.traces,
            p.fitted_mean,
            p.fitted_sd,
            p.std_error_mean,
            p.unit
        );
    }
    out!(
        "every interval held its truth in {}/{} traces; {} fits failed or did not converge \
         (counted as not covering)",
        r.all_covered,
        r.traces,
        r.failed
    );
}
