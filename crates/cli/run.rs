//! `clutchpack run`: one path for every scene, a pack or a driveline network (`[[bodies]]`):
//! the scene loaded, every output checked before any work, one [`Simulation`] run with the
//! progress bar and the stop signals, its recording, plots and JSON written, then the
//! outcome's tables printed (a pack's here, a network's in `network.rs`) and the exit code.

use crate::common::{self, BadInput};
use crate::outputs::Output;
use anyhow::{Context, Result};
use clutchpack_sdk::analysis::{stats_table, TableFormat};
use clutchpack_sdk::record::{RecordOptions, Replace};
use clutchpack_sdk::scene::{Override, Scene};
use clutchpack_sdk::{
    EngineChoice, Outcome, RecordingRequest, RunOutcome, RunRequest, RunSummary, Simulation,
    Summary,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `clutchpack run`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  clutchpack run                                  # the paper's case, built in\n  clutchpack run scenes/pack-4-rattle.toml --plot pack.png\n  clutchpack run --set defaults.oil.film_thickness_m=50e-6 --summary-json out.json"
)]
pub struct RunArgs {
    /// Scene file (TOML). Without it, the paper's case `scenes/hu-table2.toml` (built in).
    pub scene: Option<PathBuf>,
    /// Engine: `reference` (the reduced torsional engine, fast) or `multibody` (rapier3d,
    /// per tooth); default: the scene's `simulation.engine`, else `reference` for a torsional
    /// pack and `multibody` for one with per-tooth effects.
    #[arg(long, value_parser = common::engine_parser())]
    pub engine: Option<EngineChoice>,
    /// Override a scene key: `--set KEY=VALUE` with KEY the dotted path as in the file
    /// (`defaults.oil.film_thickness_m=25e-6`, `discs[1].inertia_kg_m2=0.2`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<Override>,
    /// Simulated duration in s (overrides `simulation.duration_s`).
    #[arg(long, value_name = "S")]
    pub duration: Option<f64>,
    /// Write the run summary as JSON (an existing FILE is replaced).
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// Write the counted cycles of each disc as JSON: exact (range, count) pairs, range
    /// histogram, range-mean matrix, exceedance spectrum, and per resolved tooth its ranges
    /// (an existing FILE is replaced). Keeps every cycle in memory until the run ends. A
    /// network scene gives every resolved pack's discs and plates, named
    /// `<pack>/discs/<disc>` and `<pack>/plates/<plate>`.
    #[arg(long, value_name = "FILE")]
    pub fatigue_json: Option<PathBuf>,
    /// Write one CSV row per impact: disc,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n (an
    /// existing FILE is replaced). Written as the impacts close; a stopped or failed run
    /// leaves the rows up to there. A network scene's first column is `name`: a gear mesh's
    /// name, or a pack's `<pack>/discs/<disc>` and `<pack>/plates/<plate>`.
    #[arg(long, value_name = "FILE")]
    pub impacts_csv: Option<PathBuf>,
    /// Also give the figures window by window, S seconds each: per window the impacts, the
    /// largest per-tooth peak and its body, the largest 99th percentile, the worst body's
    /// tooth damage rate and, in a thermal run, the oil's and the hottest body's temperature
    /// at its end (a table, and `windows` in `--summary-json`).
    #[arg(long, value_name = "S")]
    pub windows: Option<f64>,
    /// Plot the windows' figures against time (PNG or SVG by extension; an existing FILE is
    /// replaced): each body's largest peak per tooth and its damage rate (log10; the bodies
    /// whose largest peak is at least a tenth of the run's; of a network, each pack's worst
    /// body's) and, in a thermal run, the oil's and the hottest body's temperature. Needs
    /// `--windows`.
    #[arg(long, value_name = "FILE", requires = "windows")]
    pub windows_plot: Option<PathBuf>,
    /// Plot the per-tooth load history of each disc (PNG or SVG by extension; an existing
    /// FILE is replaced). Keeps every sample in memory until the run ends.
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// The recording (MCAP; its folder is created if missing, an existing FILE is replaced).
    /// Default: a new `recordings/<scene>-<UTC time to the ms>.mcap` (`-2`, `-3`, ... appended
    /// if taken; never replaces a file). It is written as `<stem>.partial-<pid>-<k>.mcap` and
    /// renamed when complete; a killed run leaves that file (read it with `--salvage`).
    /// Every output path is checked before the run: a folder, FIFO or device, two outputs
    /// naming one file, or an output naming the scene file is refused (exit 2).
    #[arg(long, value_name = "FILE", conflicts_with = "no_record")]
    pub out: Option<PathBuf>,
    /// Do not record.
    #[arg(long)]
    pub no_record: bool,
    /// Sample rate of the recording and the load history in Hz (overrides
    /// `simulation.record_rate_hz`).
    #[arg(long, value_name = "HZ")]
    pub record_rate: Option<f64>,
    /// Record per-tooth loads where the engine resolves teeth (overrides
    /// `simulation.record_per_tooth`).
    #[arg(long)]
    pub per_tooth: bool,
    /// Do not record the dense contact samples (`/discs/<disc>/load`: each disc's load at
    /// the samples and at the engine's steps inside every contact, the series whose plot
    /// reaches the impact peaks); overrides `simulation.record_contact_samples`.
    #[arg(long)]
    pub no_contact_samples: bool,
    /// No wall-clock data in the recording: the same run gives a byte-identical file. Chunks
    /// are then cut every 100 000 messages only, not every second of wall time, so a killed
    /// deterministic run can lose more than the last second.
    #[arg(long)]
    pub deterministic: bool,
}

pub fn run(a: RunArgs) -> Result<ExitCode> {
    // SIGINT, SIGTERM and SIGHUP stop the run cleanly (crate::signals); installed first, so
    // that a signal while a large pack's engine and recording are being set up (about 1 s
    // of CPU for 2 000 discs) stops the run at its start with complete outputs instead of
    // killing the process with a half-made recording
    let interrupted = crate::signals::flag();
    let mut sets = a.sets.clone();
    if let Some(d) = a.duration {
        sets.push(Override {
            key: "simulation.duration_s".into(),
            // the one number format of messages: the value is echoed if refused
            value: clutchpack_sdk::model::fmt_num(d),
        });
    }
    if let Some(r) = a.record_rate {
        sets.push(Override {
            key: "simulation.record_rate_hz".into(),
            value: clutchpack_sdk::model::fmt_num(r),
        });
    }
    let scene = clutchpack_sdk::load_scene(a.scene.as_deref(), &sets)?;
    // Every output checked before any work (crate::outputs); the recording's folder is made.
    let record_path = (!a.no_record).then(|| {
        a.out.clone().unwrap_or_else(|| {
            clutchpack_sdk::record::default_path(
                "recordings",
                &scene.name,
                std::time::SystemTime::now(),
            )
        })
    });
    if scene.network.is_some() {
        let pack_only = [
            ("--per-tooth", a.per_tooth),
            ("--no-contact-samples", a.no_contact_samples),
        ];
        if let Some((flag, _)) = pack_only.iter().find(|(_, on)| *on) {
            return Err(BadInput(format!(
                "{flag}: not for a network scene ({} has [[bodies]]); a network run gives its \
                 table, its recording (--out), --summary-json, --impacts-csv, --fatigue-json, \
                 --windows, --windows-plot and --plot",
                scene.name
            ))
            .into());
        }
    }
    check_outputs(&a, &scene, record_path.as_deref())?;
    let mut sim = Simulation::new(scene, a.engine)?;
    let scene = sim.scene().clone();
    let recording = record_path.map(|path| RecordingRequest {
        // an explicit --out replaces an existing file (documented); a default name never does
        replace: if a.out.is_some() {
            Replace::Existing
        } else {
            Replace::Never
        },
        // a network's recording applies the determinism (and compression and chunks) alone
        options: RecordOptions {
            deterministic: a.deterministic,
            per_tooth: a.per_tooth || scene.simulation.record_per_tooth,
            contact_samples: !a.no_contact_samples && scene.simulation.record_contact_samples,
            ..RecordOptions::default()
        },
        scene_path: a.scene.clone(),
        path,
    });
    let pb = common::time_progress(scene.simulation.duration_s, &scene.name);
    let mut progress = |t: f64| common::show_time(&pb, t);
    let run = sim.run(RunRequest {
        keep_history: a.plot.is_some(),
        keep_cycles: a.fatigue_json.is_some(),
        impacts_csv: a.impacts_csv.clone(),
        recording,
        windows_s: a.windows,
        stop: Some(&*interrupted),
        progress: Some(&mut progress),
    });
    let done = match run {
        // a pack's run fails only before any work; a network's also when its engine fails
        // (the error names the scene and the engine, the recording finished first)
        Err(e) if !sim.is_network() => {
            return Err(anyhow::Error::new(e).context(format!("starting the run of {}", scene.name)))
        }
        run => run?,
    };
    pb.finish_and_clear();
    for w in done.warnings() {
        eprintln!("warning: {w}");
    }
    // A recording that could not be finished is reported after the other outputs are written.
    let recording_error = match done.recording() {
        Some(Ok(path)) => {
            eprintln!("recording: {}", path.display());
            None
        }
        Some(Err(e)) => Some(anyhow::anyhow!("finishing the recording: {e}")),
        None => None,
    };

    // Write what we have even when the run failed, then report the failure.
    if let Some(e) = done.impacts_csv_error() {
        return Err(anyhow::anyhow!("{e}"));
    }
    if let Some(path) = &a.plot {
        match &done {
            Outcome::Pack(o) => plot(path, o)?,
            Outcome::Network(o) => crate::network::plot(path, &scene, o)?,
        }
    }
    if let Some(path) = &a.windows_plot {
        let len = clutchpack_sdk::model::fmt_num(a.windows.unwrap_or(0.0));
        let (what, groups) = match &done {
            Outcome::Pack(o) => ("", vec![(None, o.windows.as_slice())]),
            Outcome::Network(o) => ("every pack ", crate::network::windows(&o.summary)),
        };
        let title = format!(
            "{}: {what}by window of {len} s ({} engine)",
            scene.name,
            done.engine()
        );
        crate::windows_plot::write(path, &title, &groups)?;
    }
    let simulated_s = match done.simulated_s() {
        Ok(t) => t,
        Err(e) => {
            if let Some(r) = recording_error {
                eprintln!("error: {r:#}");
            }
            return Err(e.into());
        }
    };
    if done.stopped_early() {
        if crate::signals::received().is_none() && recording_error.is_some() {
            // the recorder failed (a full disk): the run stopped for that, not a signal
            eprintln!(
                "stopped at t = {simulated_s:.6} s because the recording failed (below): the \
                 other outputs hold the run up to there"
            );
        } else {
            eprintln!(
                "interrupted ({}) at t = {simulated_s:.6} s: the outputs hold the run up to there",
                crate::signals::received_name(),
            );
        }
    }
    let summary = done.summary()?;
    if let Some(path) = &a.fatigue_json {
        crate::outputs::write_json(path, &done.cycles())?;
    }
    if let Some(path) = &a.summary_json {
        crate::outputs::write_json(path, &summary)?;
    }
    match &summary {
        Summary::Pack(s) => print(s, sim.engine_line()),
        Summary::Network(s) => crate::network::print(s),
    }
    if let Some(e) = recording_error {
        return Err(e);
    }
    if let Summary::Pack(s) = &summary {
        if let Some((disc, what)) = s
            .fatigue
            .iter()
            .find_map(|f| f.non_finite().map(|w| (&f.name, w)))
        {
            // every output is written; the figures that overflowed are not a result
            eprintln!(
                "error: the fatigue of {disc} overflowed ({what} is not finite): the loads or \
                 the S-N curve are outside what the assessment can represent; check [fatigue] \
                 and [material]"
            );
            return Ok(ExitCode::from(1));
        }
    }
    if done.stopped_early() {
        // 128 + signal, as a shell reports a command stopped by that signal
        return Ok(crate::signals::exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

/// Checks every output of `a` before any work (`crate::outputs`): the recording's
/// (`record`: `--out` or the default name) folder made once the others passed, so that a
/// refused one leaves no recording folder behind; no output may name the scene file or a
/// file it read (its tables, a network's pack files).
fn check_outputs(a: &RunArgs, scene: &Scene, record: Option<&Path>) -> Result<()> {
    let mut outs = Vec::new();
    for (flag, p) in [
        ("--out", record),
        ("--summary-json", a.summary_json.as_deref()),
        ("--fatigue-json", a.fatigue_json.as_deref()),
        ("--impacts-csv", a.impacts_csv.as_deref()),
        ("--plot", a.plot.as_deref()),
        ("--windows-plot", a.windows_plot.as_deref()),
    ] {
        if let Some(path) = p {
            outs.push(if flag == "--plot" || flag == "--windows-plot" {
                Output::figure(flag, path)
            } else {
                Output::file(flag, path)
            });
        }
    }
    let inputs: Vec<&Path> = a
        .scene
        .as_deref()
        .into_iter()
        .chain(scene.inputs.iter().map(|p| p.as_path()))
        .collect();
    let others: Vec<Output> = outs
        .iter()
        .filter(|o| o.label != "--out")
        .cloned()
        .collect();
    crate::outputs::check_outputs(&others, &inputs)?;
    if let Some(p) = record {
        crate::outputs::create_folder("--out", p)?;
    }
    crate::outputs::check_outputs(&outs, &inputs)
}

/// `--plot` of a pack: every body's per-tooth load against time, with its impacts' peaks.
fn plot(path: &Path, done: &RunOutcome) -> Result<()> {
    let series: Vec<(String, Vec<(f64, f64)>)> = done
        .body_names
        .iter()
        .cloned()
        .zip(done.collector.histories_with_peaks())
        .collect();
    let title = format!("{}: per-tooth load ({} engine)", done.scene, done.engine);
    crate::outputs::write_with(path, |tmp| {
        clutchpack_sdk::analysis::plot_load_history(tmp, &title, &series)
            .with_context(|| format!("plotting {}", path.display()))
    })
}

/// The tables of a pack's run: the run's line and the engine's, the bodies' impact
/// statistics, the teeth's fatigue, the friction interfaces, a thermal run's temperatures
/// and the windows.
fn print(summary: &RunSummary, engine_line: &str) {
    out!(
        "{}: {:.3} s simulated with the {} engine in {:.3} s wall ({} steps)",
        summary.scene,
        summary.duration_s,
        summary.engine,
        summary.wall_time_s,
        summary.steps
    );
    out!("{engine_line}");
    out!("per-tooth impact loads (negative: the shaft leads; positive: the disc leads)");
    let stats = &summary.discs;
    out!("{}", stats_table(stats, TableFormat::Text).trim_end());
    if let Some(worst) = stats.iter().max_by(|x, y| {
        x.max_positive_n
            .max(-x.max_negative_n)
            .total_cmp(&y.max_positive_n.max(-y.max_negative_n))
    }) {
        if stats.len() > 1 {
            out!(
                "hardest hit: {} ({:.1} N)",
                worst.name,
                worst.max_positive_n.max(-worst.max_negative_n)
            );
        }
    }
    if !summary.fatigue.is_empty() {
        out!(
            "fatigue of the spline teeth at this duty ({} rule below the knee; life at D = D_crit; MODEL.md section 7)",
            summary.fatigue[0].rule.name()
        );
        out!(
            "{}",
            clutchpack_sdk::analysis::fatigue_table(&summary.fatigue, TableFormat::Text).trim_end()
        );
    }
    if !summary.interfaces.is_empty() {
        out!("friction interfaces (from the piston side)");
        out!(
            "{}",
            clutchpack_sdk::analysis::interface_table(&summary.interfaces, TableFormat::Text)
                .trim_end()
        );
    }
    if let Some(th) = &summary.thermal {
        crate::tables::print_thermal(th);
    }
    crate::tables::print_windows(&summary.windows);
}
