//! `clutchpack run`.

use crate::common::{self, EngineArg, RunCollector, RunSummary};
use anyhow::{Context, Result};
use clutchpack_analysis::{disc_stats, stats_table, TableFormat};
use clutchpack_model::{ImpactEvent, Observer, Sample};
use clutchpack_record::{RecordOptions, Recorder};
use clutchpack_scene::Override;
use std::io::Write;
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
    /// Write the run summary as JSON.
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// Write one CSV row per impact: disc,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n.
    #[arg(long, value_name = "FILE")]
    pub impacts_csv: Option<PathBuf>,
    /// Plot the per-tooth load history of each disc (PNG or SVG by extension).
    #[arg(long, value_name = "FILE")]
    pub plot: Option<PathBuf>,
    /// The recording (MCAP); default `recordings/<scene>-<UTC time>.mcap`.
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
    /// No wall-clock data in the recording: the same run gives a byte-identical file.
    #[arg(long)]
    pub deterministic: bool,
}

pub fn run(a: RunArgs) -> Result<ExitCode> {
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
    let mut engine = common::make_engine(&scene, a.engine)?;
    let names = engine.disc_names();
    let duration = scene.simulation.duration_s;
    let mut collector = RunCollector::new(names.len(), a.plot.is_some());
    let pb = common::time_progress(duration, &scene.name);
    collector.progress = Some(pb.clone());
    let recorder = if a.no_record {
        None
    } else {
        let path = a.out.clone().unwrap_or_else(|| {
            clutchpack_record::default_path("recordings", &scene.name, std::time::SystemTime::now())
        });
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("creating the folder {}", dir.display()))?;
        }
        let info = common::run_info(&scene, engine.name(), a.scene.as_deref());
        let opts = RecordOptions {
            deterministic: a.deterministic,
            per_tooth: a.per_tooth || scene.simulation.record_per_tooth,
            ..RecordOptions::default()
        };
        Some(ThreadedRecorder::start(
            Recorder::create(&path, &info, &opts)
                .with_context(|| format!("creating the recording {}", path.display()))?,
        ))
    };
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        // A second Ctrl-C while the handler is installed still stops the run (the flag is
        // simply set again); failing to install it only loses the clean stop.
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let mut obs = RunObserver {
        collector,
        recorder,
        interrupted: interrupted.clone(),
    };
    let t0 = Instant::now();
    let result = engine.run(duration, &mut obs);
    let wall = t0.elapsed().as_secs_f64();
    pb.finish_and_clear();
    let RunObserver {
        collector: obs,
        recorder,
        ..
    } = obs;
    let stats = disc_stats(&names, &obs.impacts);
    // Close the recording first: it holds everything before a failure or an interruption.
    if let Some(rec) = recorder {
        let mut rec = rec.join();
        if let Ok(s) = &result {
            rec.set_run_stats(s);
        }
        let path = rec.finish(None).context("finishing the recording")?;
        eprintln!("recording: {}", path.display());
    }

    // Write what we have even when the run failed, then report the failure.
    if let Some(path) = &a.impacts_csv {
        write_impacts_csv(path, &names, &obs)?;
    }
    if let Some(path) = &a.plot {
        let series: Vec<(String, Vec<(f64, f64)>)> = names
            .iter()
            .cloned()
            .zip(obs.histories_with_peaks())
            .collect();
        let title = format!("{}: per-tooth load ({} engine)", scene.name, engine.name());
        clutchpack_analysis::plot_load_history(path, &title, &series)
            .with_context(|| format!("plotting {}", path.display()))?;
    }
    let run_stats = match result {
        Ok(s) if s.stopped_early => {
            eprintln!(
                "interrupted at t = {:.6} s: the outputs hold the run up to there",
                s.simulated_s
            );
            s
        }
        Ok(s) => s,
        Err(e) => {
            return Err(anyhow::Error::new(e).context(format!(
                "{} engine on {} ({} impacts kept before the failure)",
                engine.name(),
                scene.name,
                obs.impacts.len()
            )))
        }
    };
    let summary = RunSummary::new(&scene, engine.name(), &run_stats, wall, stats.clone());
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
    if run_stats.stopped_early {
        // 128 + SIGINT, as a shell reports a command stopped by Ctrl-C
        return Ok(ExitCode::from(130));
    }
    Ok(ExitCode::SUCCESS)
}

fn write_impacts_csv(path: &PathBuf, names: &[String], obs: &RunCollector) -> Result<()> {
    let f = std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
    let mut w = std::io::BufWriter::new(f);
    writeln!(w, "disc,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n")?;
    for e in &obs.impacts {
        writeln!(
            w,
            "{},{:.9},{:.9},{:.9},{},{:.6},{:.4}",
            names[e.disc],
            e.t_on_s,
            e.t_peak_s,
            e.t_off_s,
            e.flank.label(),
            e.v_on_m_s,
            e.peak_n
        )?;
    }
    w.flush()
        .with_context(|| format!("writing {}", path.display()))
}

/// What the engine's thread hands to the recording thread.
enum ToRecorder {
    Sample(Sample),
    Impact(ImpactEvent),
    Progress(f64),
}

/// The recorder on its own thread: the engine's thread only clones each sample into a bounded
/// channel, so encoding and writing the recording run beside the simulation instead of after
/// each step (measured: the recording's cost moves off the engine's thread; see the issue note).
struct ThreadedRecorder {
    tx: std::sync::mpsc::SyncSender<ToRecorder>,
    failed: Arc<AtomicBool>,
    handle: std::thread::JoinHandle<Recorder>,
}

impl ThreadedRecorder {
    fn start(mut rec: Recorder) -> ThreadedRecorder {
        let (tx, rx) = std::sync::mpsc::sync_channel::<ToRecorder>(8192);
        let failed = Arc::new(AtomicBool::new(false));
        let flag = failed.clone();
        let handle = std::thread::spawn(move || {
            for m in rx {
                let stop = match m {
                    ToRecorder::Sample(s) => {
                        rec.sample(&s);
                        // the wall-clock flush is checked on every message
                        rec.progress(s.t_s)
                    }
                    ToRecorder::Impact(e) => {
                        rec.impact(&e);
                        false
                    }
                    ToRecorder::Progress(t) => rec.progress(t),
                };
                if stop {
                    flag.store(true, Ordering::SeqCst);
                }
            }
            rec
        });
        ThreadedRecorder { tx, failed, handle }
    }

    fn send(&self, m: ToRecorder) {
        // A closed channel means the thread ended; join() reports why.
        let _ = self.tx.send(m);
    }

    /// Waits for everything sent to be written and returns the recorder to finish it.
    fn join(self) -> Recorder {
        drop(self.tx);
        match self.handle.join() {
            Ok(r) => r,
            Err(p) => std::panic::resume_unwind(p),
        }
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
        if let Some(r) = &self.recorder {
            r.send(ToRecorder::Sample(s.clone()));
        }
    }
    fn impact(&mut self, e: &ImpactEvent) {
        self.collector.impact(e);
        if let Some(r) = &self.recorder {
            r.send(ToRecorder::Impact(*e));
        }
    }
    fn progress(&mut self, t_s: f64) -> bool {
        let mut stop = self.collector.progress(t_s);
        if let Some(r) = &self.recorder {
            r.send(ToRecorder::Progress(t_s));
            stop |= r.failed.load(Ordering::SeqCst);
        }
        stop || self.interrupted.load(Ordering::SeqCst)
    }
}
