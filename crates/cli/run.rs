//! `clutchpack run`.

use crate::common::{self, EngineArg, RunCollector, RunSummary};
use crate::outputs::Output;
use anyhow::{Context, Result};
use clutchpack_analysis::{stats_table, TableFormat};
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, Observer, Sample};
use clutchpack_record::Replace;
use clutchpack_record::{RecordOptions, Recorder, ThreadedRecorder};
use clutchpack_scene::Override;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Arguments of `clutchpack run`.
#[derive(clap::Args, Debug)]
#[command(
    after_help = "Examples:\n  clutchpack run                                  # the paper's case, built in\n  clutchpack run scenes/pack-4-rattle.toml --plot pack.png\n  clutchpack run --set defaults.oil.film_thickness_m=50e-6 --summary-json out.json"
)]
pub struct RunArgs {
    /// Scene file (TOML). Without it, the paper's case `scenes/hu-table2.toml` (built in).
    pub scene: Option<PathBuf>,
    /// Engine; default: the scene's `simulation.engine`, else `reference`.
    #[arg(long, value_enum)]
    pub engine: Option<EngineArg>,
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
    /// (an existing FILE is replaced). Keeps every cycle in memory until the run ends.
    #[arg(long, value_name = "FILE")]
    pub fatigue_json: Option<PathBuf>,
    /// Write one CSV row per impact: disc,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n (an
    /// existing FILE is replaced). Written as the impacts close; a stopped or failed run
    /// leaves the rows up to there.
    #[arg(long, value_name = "FILE")]
    pub impacts_csv: Option<PathBuf>,
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
            value: d.to_string(),
        });
    }
    if let Some(r) = a.record_rate {
        sets.push(Override {
            key: "simulation.record_rate_hz".into(),
            value: r.to_string(),
        });
    }
    let scene = common::load_scene(a.scene.as_deref(), &sets)?;
    // Every output checked before any work (crate::outputs); the recording's folder is made.
    let record_path = (!a.no_record).then(|| {
        a.out.clone().unwrap_or_else(|| {
            clutchpack_record::default_path("recordings", &scene.name, std::time::SystemTime::now())
        })
    });
    let mut outs = Vec::new();
    for (flag, p) in [
        ("--out", record_path.as_deref()),
        ("--summary-json", a.summary_json.as_deref()),
        ("--fatigue-json", a.fatigue_json.as_deref()),
        ("--impacts-csv", a.impacts_csv.as_deref()),
        ("--plot", a.plot.as_deref()),
    ] {
        if let Some(path) = p {
            outs.push(if flag == "--plot" {
                Output::figure(flag, path)
            } else {
                Output::file(flag, path)
            });
        }
    }
    let inputs: Vec<&std::path::Path> = a.scene.as_deref().into_iter().collect();
    // the other outputs first, so that a refused one leaves no recording folder behind
    let others: Vec<Output> = outs.iter().filter(|o| o.flag != "--out").cloned().collect();
    crate::outputs::check_outputs(&others, &inputs)?;
    if let Some(p) = record_path.as_deref() {
        crate::outputs::create_folder("--out", p)?;
    }
    crate::outputs::check_outputs(&outs, &inputs)?;
    let (mut engine, engine_line) = common::choose_engine(&scene, a.engine)?;
    let names = engine.disc_names();
    let duration = scene.simulation.duration_s;
    let mut collector = RunCollector::new(names.len(), a.plot.is_some())
        .with_interfaces(
            common::friction_interfaces(&scene)
                .into_iter()
                .map(|f| f.name()),
        )
        .with_fatigue(&scene, a.fatigue_json.is_some());
    if let Some(path) = &a.impacts_csv {
        collector = collector.with_impacts_csv(path, &names)?;
    }
    let pb = common::time_progress(duration, &scene.name);
    collector.progress = Some(pb.clone());
    let recorder = if let Some(path) = record_path {
        // an explicit --out replaces an existing file (documented); a default name never does
        let replace = if a.out.is_some() {
            Replace::Existing
        } else {
            Replace::Never
        };
        let info = common::run_info(&scene, engine.name(), a.scene.as_deref());
        let opts = RecordOptions {
            deterministic: a.deterministic,
            per_tooth: a.per_tooth || scene.simulation.record_per_tooth,
            contact_samples: !a.no_contact_samples && scene.simulation.record_contact_samples,
            ..RecordOptions::default()
        };
        Some(
            Recorder::create_output(&path, replace, &info, &opts)
                .with_context(|| format!("creating the recording {}", path.display()))?,
        )
    } else {
        None
    };
    let t0 = Instant::now();
    let done = run_recorded(engine.as_mut(), duration, collector, recorder, interrupted);
    let wall = t0.elapsed().as_secs_f64();
    pb.finish_and_clear();
    let (result, mut obs) = (done.result, done.collector);
    // A recording that could not be finished is reported after the other outputs are written.
    let recording_error = match done.recording {
        Some(Ok(path)) => {
            eprintln!("recording: {}", path.display());
            None
        }
        Some(Err(e)) => Some(e),
        None => None,
    };

    // Write what we have even when the run failed, then report the failure.
    obs.finish_impacts_csv()?;
    let stats = obs.disc_stats(&names)?;
    if let Some(path) = &a.plot {
        let series: Vec<(String, Vec<(f64, f64)>)> = names
            .iter()
            .cloned()
            .zip(obs.histories_with_peaks())
            .collect();
        let title = format!("{}: per-tooth load ({} engine)", scene.name, engine.name());
        crate::outputs::write_with(path, |tmp| {
            clutchpack_analysis::plot_load_history(tmp, &title, &series)
                .with_context(|| format!("plotting {}", path.display()))
        })?;
    }
    let run_stats = match result {
        Ok(s) if s.stopped_early => {
            if crate::signals::received().is_none() && recording_error.is_some() {
                // the recorder failed (a full disk): the run stopped for that, not a signal
                eprintln!(
                    "stopped at t = {:.6} s because the recording failed (below): the other \
                     outputs hold the run up to there",
                    s.simulated_s
                );
            } else {
                eprintln!(
                    "interrupted ({}) at t = {:.6} s: the outputs hold the run up to there",
                    crate::signals::received_name(),
                    s.simulated_s
                );
            }
            s
        }
        Ok(s) => s,
        Err(e) => {
            if let Some(r) = recording_error {
                eprintln!("error: {r:#}");
            }
            return Err(anyhow::Error::new(e).context(format!(
                "{} engine on {} ({} impacts kept before the failure)",
                engine.name(),
                scene.name,
                obs.impact_count()
            )));
        }
    };
    let mut summary = RunSummary::new(&scene, engine.name(), &run_stats, wall, stats.clone());
    summary.interfaces = obs.interfaces.clone();
    summary.fatigue = obs.assess_fatigue(&names, run_stats.simulated_s);
    if let Some(path) = &a.fatigue_json {
        let histories = obs.fatigue.clone().finish(names.len());
        let cycles: Vec<_> = names
            .iter()
            .zip(&histories)
            .map(|(n, h)| clutchpack_analysis::disc_cycles(n, h, run_stats.simulated_s))
            .collect();
        common::write_json(path, &cycles)?;
    }
    if let Some(path) = &a.summary_json {
        common::write_json(path, &summary)?;
    }
    out!(
        "{}: {:.3} s simulated with the {} engine in {:.3} s wall ({} steps)",
        scene.name,
        run_stats.simulated_s,
        summary.engine,
        wall,
        run_stats.steps
    );
    out!("{engine_line}");
    out!("per-tooth impact loads (negative: the shaft leads; positive: the disc leads)");
    out!("{}", stats_table(&stats, TableFormat::Text).trim_end());
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
            clutchpack_analysis::fatigue_table(&summary.fatigue, TableFormat::Text).trim_end()
        );
    }
    if !obs.interfaces.is_empty() {
        out!("friction interfaces (from the piston side)");
        out!(
            "{}",
            clutchpack_analysis::interface_table(&obs.interfaces, TableFormat::Text).trim_end()
        );
    }
    if let Some(e) = recording_error {
        return Err(e);
    }
    if let Some((disc, what)) = summary
        .fatigue
        .iter()
        .find_map(|f| f.non_finite().map(|w| (&f.name, w)))
    {
        // every output is written; the figures that overflowed are not a result
        eprintln!(
            "error: the fatigue of {disc} overflowed ({what} is not finite): the loads or the \
             S-N curve are outside what the assessment can represent; check [fatigue] and \
             [material]"
        );
        return Ok(ExitCode::from(1));
    }
    if run_stats.stopped_early {
        // 128 + signal, as a shell reports a command stopped by that signal
        return Ok(crate::signals::exit_code());
    }
    Ok(ExitCode::SUCCESS)
}

/// What [`run_recorded`] gives back.
pub(crate) struct RecordedRun {
    /// The engine's result.
    pub result: Result<clutchpack_model::RunStats, clutchpack_model::EngineError>,
    /// The impacts (and histories) collected on the engine's thread.
    pub collector: RunCollector,
    /// The finished recording's path, or why it could not be finished (`None`: no recorder).
    pub recording: Option<Result<PathBuf>>,
    /// CPU time of the engine's thread during the run, s.
    pub engine_cpu_s: f64,
    /// CPU time of the recording thread, s (0 without a recorder).
    pub recorder_cpu_s: f64,
}

/// Runs `engine` for `duration_s` with `collector` on the engine's thread and `recorder` (if
/// any) on a recording thread, then finishes the recording: with the engine's statistics
/// when it ran, and in any case with everything recorded before a failure or a stop. Stops
/// early and cleanly when `interrupted` is set.
pub(crate) fn run_recorded(
    engine: &mut (dyn clutchpack_model::Engine + Send),
    duration_s: f64,
    collector: RunCollector,
    recorder: Option<Recorder>,
    interrupted: Arc<AtomicBool>,
) -> RecordedRun {
    let mut obs = RunObserver {
        collector,
        recorder: recorder.map(ThreadedRecorder::start),
        interrupted,
    };
    let cpu = cpu_time::ThreadTime::try_now().ok();
    let result = engine.run(duration_s, &mut obs);
    let engine_cpu_s = cpu
        .and_then(|c| c.try_elapsed().ok())
        .map_or(0.0, |d| d.as_secs_f64());
    let RunObserver {
        collector,
        recorder,
        ..
    } = obs;
    // Close the recording first: it holds everything before a failure or an interruption.
    let mut recorder_cpu_s = 0.0;
    let recording = match recorder {
        Some(rec) => {
            let (mut rec, cpu_s) = rec.join();
            recorder_cpu_s = cpu_s;
            // the file is finished even if the peaks kept on disk cannot be read back
            let mut summary = rec.summary().unwrap_or_else(|e| {
                eprintln!("warning: {e}; the recording's /summary has no impact statistics");
                clutchpack_record::RunSummary {
                    t_end_s: result.as_ref().map_or(0.0, |s| s.simulated_s),
                    discs: Vec::new(),
                    fatigue: Vec::new(),
                }
            });
            if let Ok(s) = &result {
                rec.set_run_stats(s);
                // the teeth's fatigue over the duty that ran, beside the peak statistics
                let names: Vec<String> = summary.discs.iter().map(|d| d.name.clone()).collect();
                let fatigue = collector.assess_fatigue(&names, s.simulated_s);
                summary.fatigue = fatigue
                    .iter()
                    .map(|f| Some(clutchpack_record::FatigueSummary::from(f)))
                    .collect();
            }
            Some(rec.finish(Some(summary)).context("finishing the recording"))
        }
        None => None,
    };
    RecordedRun {
        result,
        collector,
        recording,
        engine_cpu_s,
        recorder_cpu_s,
    }
}

/// Feeds the collector and the recorder; stops the run on Ctrl-C or when recording failed.
struct RunObserver {
    collector: RunCollector,
    recorder: Option<ThreadedRecorder>,
    interrupted: Arc<AtomicBool>,
}

impl Observer for RunObserver {
    fn sample(&mut self, s: &Sample) {
        self.collector.sample(s);
        if let Some(r) = &mut self.recorder {
            r.push_sample(s);
        }
    }
    fn impact(&mut self, e: &ImpactEvent) {
        self.collector.impact(e);
        if let Some(r) = &mut self.recorder {
            r.push_impact(e);
        }
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.collector.interfaces(t_s, interfaces);
        if let Some(r) = &mut self.recorder {
            r.push_interfaces(t_s, interfaces);
        }
    }
    fn contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        self.collector.contact_sample(disc, t_s, state);
        if let Some(r) = &mut self.recorder {
            r.push_contact_sample(disc, t_s, state);
        }
    }
    fn wants_contact_samples(&self) -> bool {
        self.collector.wants_contact_samples()
            || self
                .recorder
                .as_ref()
                .is_some_and(ThreadedRecorder::wants_contact_samples)
    }
    fn progress(&mut self, t_s: f64) -> bool {
        let mut stop = self.collector.progress(t_s);
        if let Some(r) = &mut self.recorder {
            // hand over what is pending, so a slow engine's samples reach the file (and its
            // wall-clock flush) without waiting for a full batch
            r.send();
            stop |= r.failed();
        }
        stop || self.interrupted.load(Ordering::SeqCst)
    }
}
