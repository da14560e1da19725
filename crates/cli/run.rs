//! `clutchpack run`.

use crate::common::{self, EngineArg, RunCollector, RunSummary};
use anyhow::{Context, Result};
use clutchpack_analysis::{disc_stats, stats_table, TableFormat};
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, Observer, Sample};
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
    /// Write the counted cycles of each disc as JSON: exact (range, count) pairs, range
    /// histogram, range-mean matrix, exceedance spectrum, and per resolved tooth its ranges.
    #[arg(long, value_name = "FILE")]
    pub fatigue_json: Option<PathBuf>,
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
    /// No wall-clock data in the recording: the same run gives a byte-identical file. Chunks
    /// are then cut every 100 000 messages only, not every second of wall time, so a killed
    /// deterministic run can lose more than the last second.
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
    let mut collector = RunCollector::new(names.len(), a.plot.is_some())
        .with_interfaces(
            common::friction_interfaces(&scene)
                .into_iter()
                .map(|f| f.name()),
        )
        .with_fatigue(&scene);
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
        Some(
            Recorder::create(&path, &info, &opts)
                .with_context(|| format!("creating the recording {}", path.display()))?,
        )
    };
    // SIGINT, SIGTERM and SIGHUP stop the run cleanly (crate::signals).
    let interrupted = crate::signals::flag();
    let t0 = Instant::now();
    let done = run_recorded(engine.as_mut(), duration, collector, recorder, interrupted);
    let wall = t0.elapsed().as_secs_f64();
    pb.finish_and_clear();
    let (result, obs) = (done.result, done.collector);
    let stats = disc_stats(&names, &obs.impacts);
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
                "interrupted ({}) at t = {:.6} s: the outputs hold the run up to there",
                crate::signals::received_name(),
                s.simulated_s
            );
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
                obs.impacts.len()
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
    if run_stats.stopped_early {
        // 128 + signal, as a shell reports a command stopped by that signal
        return Ok(crate::signals::exit_code());
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
            let mut summary = rec.summary();
            if let Ok(s) = &result {
                rec.set_run_stats(s);
                // the teeth's fatigue over the duty that ran, beside the peak statistics
                let names: Vec<String> = summary.discs.iter().map(|d| d.name.clone()).collect();
                let fatigue = collector.assess_fatigue(&names, s.simulated_s);
                for (d, f) in summary.discs.iter_mut().zip(&fatigue) {
                    d.fatigue = Some(clutchpack_record::FatigueSummary::from(f));
                }
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

/// What the engine's thread hands to the recording thread.
enum ToRecorder {
    Sample(Sample),
    Impact(ImpactEvent),
    Interfaces(f64, Vec<InterfaceSample>),
}

/// Items per batch handed to the recording thread. Handing over every sample on its own
/// woke the recording thread 10 000 times per simulated second (a futex call each), which
/// slowed the engine's thread more than the encoding did. Measured with `clutchpack bench`
/// on a 3 s paper case: the engine thread's CPU time grew by 7 % with batches of 32 and by
/// 3.5 % with 256; a batch is at most 2.6 ms of simulated time at 10 kHz, and a slow engine
/// hands over what it has at each progress call (every 1024 steps) anyway.
const BATCH: usize = 256;

/// The recorder on its own thread: the engine's thread only copies each sample into a batch
/// and hands full batches over a bounded channel, so encoding, compressing and writing run
/// beside the simulation. Emptied batches come back on a second channel and their samples'
/// buffers are reused, so the engine's thread neither allocates nor frees per sample.
struct ThreadedRecorder {
    tx: std::sync::mpsc::SyncSender<Vec<ToRecorder>>,
    back: std::sync::mpsc::Receiver<Vec<ToRecorder>>,
    batch: Vec<ToRecorder>,
    /// items of `batch` in use; those beyond are spare buffers
    len: usize,
    failed: Arc<AtomicBool>,
    /// gives back the recorder and the thread's CPU time in s
    handle: std::thread::JoinHandle<(Recorder, f64)>,
}

/// Copies `src` into `dst` field by field, reusing `dst`'s buffers (a derived `clone_from`
/// would allocate anew). Destructured so that a new field of `Sample` fails to compile here.
fn copy_sample(dst: &mut Sample, src: &Sample) {
    let Sample {
        t_s,
        shaft_angle_rad,
        shaft_speed_rad_s,
        discs,
    } = src;
    dst.t_s = *t_s;
    dst.shaft_angle_rad = *shaft_angle_rad;
    dst.shaft_speed_rad_s = *shaft_speed_rad_s;
    dst.discs.truncate(discs.len());
    let n = dst.discs.len();
    for (d, s) in dst.discs.iter_mut().zip(discs) {
        let loads = std::mem::take(&mut d.tooth_loads_n);
        *d = DiscSample {
            tooth_loads_n: loads,
            ..*s
        };
        d.tooth_loads_n.clear();
        d.tooth_loads_n.extend_from_slice(&s.tooth_loads_n);
    }
    dst.discs.extend(discs[n..].iter().cloned());
}

impl ThreadedRecorder {
    fn start(mut rec: Recorder) -> ThreadedRecorder {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<ToRecorder>>(64);
        let (back_tx, back) = std::sync::mpsc::channel::<Vec<ToRecorder>>();
        let failed = Arc::new(AtomicBool::new(false));
        let flag = failed.clone();
        let worker = move || {
            let cpu = cpu_time::ThreadTime::try_now().ok();
            for batch in rx {
                let mut t_s = None;
                for m in &batch {
                    match m {
                        ToRecorder::Sample(s) => {
                            rec.sample(s);
                            t_s = Some(s.t_s);
                        }
                        ToRecorder::Impact(e) => rec.impact(e),
                        ToRecorder::Interfaces(t, i) => rec.interfaces(*t, i),
                    }
                }
                // the wall-clock flush is checked once per batch
                if rec.progress(t_s.unwrap_or(0.0)) {
                    flag.store(true, Ordering::SeqCst);
                }
                // the engine's thread may be gone already; the batch is then dropped here
                let _ = back_tx.send(batch);
            }
            let cpu_s = cpu
                .and_then(|c| c.try_elapsed().ok())
                .map_or(0.0, |d| d.as_secs_f64());
            (rec, cpu_s)
        };
        let handle = std::thread::Builder::new()
            .name("recorder".into())
            .spawn(worker)
            .expect("spawning the recorder thread");
        ThreadedRecorder {
            tx,
            back,
            batch: Vec::with_capacity(BATCH),
            len: 0,
            failed,
            handle,
        }
    }

    /// The next free slot of the batch: a spare one (to be overwritten) or a new one.
    fn slot(&mut self) -> Option<&mut ToRecorder> {
        let i = self.len;
        self.len += 1;
        self.batch.get_mut(i)
    }

    fn push_sample(&mut self, s: &Sample) {
        match self.slot() {
            Some(ToRecorder::Sample(dst)) => copy_sample(dst, s),
            Some(other) => *other = ToRecorder::Sample(s.clone()),
            None => self.batch.push(ToRecorder::Sample(s.clone())),
        }
        self.send_if_full();
    }

    fn push(&mut self, m: ToRecorder) {
        match self.slot() {
            Some(slot) => *slot = m,
            None => self.batch.push(m),
        }
        self.send_if_full();
    }

    fn send_if_full(&mut self) {
        if self.len >= BATCH {
            self.send();
        }
    }

    /// Hands the batch to the recording thread and takes a returned one (or a new one).
    fn send(&mut self) {
        if self.len == 0 {
            return;
        }
        self.batch.truncate(self.len);
        let next = self
            .back
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(BATCH));
        let full = std::mem::replace(&mut self.batch, next);
        self.len = 0;
        // A closed channel means the thread ended; join() reports why.
        let _ = self.tx.send(full);
    }

    /// Waits for everything pushed to be written and returns the recorder to finish it, and
    /// the recording thread's CPU time in s.
    fn join(mut self) -> (Recorder, f64) {
        self.send();
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
        if let Some(r) = &mut self.recorder {
            r.push_sample(s);
        }
    }
    fn impact(&mut self, e: &ImpactEvent) {
        self.collector.impact(e);
        if let Some(r) = &mut self.recorder {
            r.push(ToRecorder::Impact(*e));
        }
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.collector.interfaces(t_s, interfaces);
        if let Some(r) = &mut self.recorder {
            r.push(ToRecorder::Interfaces(t_s, interfaces.to_vec()));
        }
    }
    fn progress(&mut self, t_s: f64) -> bool {
        let mut stop = self.collector.progress(t_s);
        if let Some(r) = &mut self.recorder {
            // hand over what is pending, so a slow engine's samples reach the file (and its
            // wall-clock flush) without waiting for a full batch
            r.send();
            stop |= r.failed.load(Ordering::SeqCst);
        }
        stop || self.interrupted.load(Ordering::SeqCst)
    }
}
