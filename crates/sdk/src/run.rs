//! One run of a scene, a pack or a network, and its outcome, either kind (`Outcome`); a pack's
//! run: the engine on the caller's thread feeding the collector, the recording (if asked) on
//! its own thread, both finished whatever stops the run (a network's: `network.rs`).

use crate::collector::RunCollector;
use crate::summary::{friction_interfaces, run_info, RunSummary};
use crate::{Error, NetworkOutcome, NetworkSummary, Result, Simulation};
use clutchpack_analysis::{DiscCycles, DiscFatigue, DiscStats};
use clutchpack_model::{
    DiscSample, Engine, EngineError, ImpactEvent, InterfaceSample, Observer, RunStats, Sample,
};
use clutchpack_record::{RecordError, RecordOptions, Recorder, Replace, ThreadedRecorder};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Where and how a run is recorded (MCAP).
#[derive(Debug, Clone)]
pub struct RecordingRequest {
    /// The recording's path; written as a `.partial` sibling and renamed when complete.
    pub path: PathBuf,
    /// Whether an existing file at `path` is replaced.
    pub replace: Replace,
    /// What is recorded (per-tooth loads, contact samples, determinism).
    pub options: RecordOptions,
    /// The scene file the run was loaded from (its name goes into the recording).
    pub scene_path: Option<PathBuf>,
}

/// What a run keeps and writes besides its statistics (the peak statistics, the interfaces'
/// figures and the teeth's fatigue as running sums are always kept, in bounded memory).
#[derive(Default)]
pub struct RunRequest<'a> {
    /// Keep every sample's per-tooth load and every impact (for a plot); memory grows with
    /// the run.
    pub keep_history: bool,
    /// Keep every counted load cycle (for the cycle spectra of `--fatigue-json`); memory
    /// grows with the run.
    pub keep_cycles: bool,
    /// Write one CSV row per impact to this file as the impacts close.
    pub impacts_csv: Option<PathBuf>,
    /// Record the run.
    pub recording: Option<RecordingRequest>,
    /// Stops the run cleanly (at the engine's next progress poll, within milliseconds) once
    /// set; the outcome then holds the run up to there.
    pub stop: Option<&'a AtomicBool>,
    /// Also the figures window by window, of this length in s (`None`: none;
    /// [`RunOutcome::windows`]).
    pub windows_s: Option<f64>,
    /// Called at the engine's progress polls with the simulated time reached, s.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
}

/// What a run gave: the engine's result and everything kept, complete up to where the run
/// ended (its end, a stop or a failure).
pub struct RunOutcome {
    /// The scene's name.
    pub scene: String,
    /// The engine that ran.
    pub engine: &'static str,
    /// The engine's statistics, or why it failed (the other fields hold what came before).
    pub result: std::result::Result<RunStats, EngineError>,
    /// Wall-clock time of the run, s.
    pub wall_time_s: f64,
    /// CPU time of the engine's thread during the run, s.
    pub engine_cpu_s: f64,
    /// CPU time of the recording thread, s (0 without a recording).
    pub recorder_cpu_s: f64,
    /// The bodies' names, in the engines' order (discs, then plates).
    pub body_names: Vec<String>,
    /// What was kept.
    pub collector: RunCollector,
    /// The impacts CSV: written, or why not (`None`: not asked).
    pub impacts_csv: Option<Result<PathBuf>>,
    /// The finished recording's path, or why it could not be finished (`None`: not asked).
    pub recording: Option<std::result::Result<PathBuf, RecordError>>,
    /// The figures window by window, when [`RunRequest::windows_s`] asked for them (the last
    /// window ends at the run's end).
    pub windows: Vec<crate::WindowRow>,
    /// What went wrong without stopping the run (to be shown to the user).
    pub warnings: Vec<String>,
}

impl RunOutcome {
    /// The engine's statistics; an engine failure as [`Error::Engine`], naming the scene, the
    /// engine and the impacts kept before it.
    pub fn stats(&self) -> Result<&RunStats> {
        self.result.as_ref().map_err(|e| Error::Engine {
            context: format!(
                "{} engine on {} ({} impacts kept before the failure)",
                self.engine,
                self.scene,
                self.collector.impact_count()
            ),
            source: e.clone(),
        })
    }

    /// Whether the run stopped before its duration (a stop flag, or a failed recording).
    pub fn stopped_early(&self) -> bool {
        self.result.as_ref().is_ok_and(|s| s.stopped_early)
    }

    /// The per-body statistics of the impacts.
    pub fn body_stats(&self) -> Result<Vec<DiscStats>> {
        self.collector.disc_stats(&self.body_names)
    }

    /// The teeth's fatigue over the simulated time that ran.
    pub fn fatigue(&self) -> Vec<DiscFatigue> {
        let t = self.result.as_ref().map_or(0.0, |s| s.simulated_s);
        self.collector.assess_fatigue(&self.body_names, t)
    }

    /// Every body's counted load cycles and load spectra over the simulated time that ran
    /// (`run --fatigue-json`); its cycles are kept only when [`RunRequest::keep_cycles`]
    /// asked for them.
    pub fn cycles(&self) -> Vec<DiscCycles> {
        let t = self.result.as_ref().map_or(0.0, |s| s.simulated_s);
        let histories = self.collector.fatigue.clone().finish(self.body_names.len());
        self.body_names
            .iter()
            .zip(&histories)
            .map(|(n, h)| clutchpack_analysis::disc_cycles(n, h, t))
            .collect()
    }

    /// The run's summary (what `--summary-json` writes): statistics, interfaces, fatigue.
    /// An error when the engine failed.
    pub fn summary(&self) -> Result<RunSummary> {
        let stats = self.stats()?;
        let mut s = RunSummary::new(
            &self.scene,
            self.engine,
            stats,
            self.wall_time_s,
            self.body_stats()?,
        );
        s.interfaces = self.collector.interfaces.clone();
        s.fatigue = self.fatigue();
        s.windows = self.windows.clone();
        Ok(s)
    }
}

/// What a run of a scene gave ([`Simulation::run`]): a pack's outcome or a network's.
// a pack's outcome is the larger, and the common one: boxing it would cost every pack run
#[allow(clippy::large_enum_variant)]
pub enum Outcome {
    /// A pack scene's run.
    Pack(RunOutcome),
    /// A network scene's run (`[[bodies]]`).
    Network(NetworkOutcome),
}

/// A run's summary (what `--summary-json` writes): a pack's or a network's, serialised as
/// the summary itself (untagged: the JSON of either kind is its summary's own).
#[derive(Debug, Serialize)]
#[serde(untagged)]
pub enum Summary {
    /// A pack scene's summary.
    Pack(RunSummary),
    /// A network scene's summary.
    Network(NetworkSummary),
}

impl Outcome {
    /// The scene's name.
    pub fn scene(&self) -> &str {
        match self {
            Outcome::Pack(o) => &o.scene,
            Outcome::Network(o) => &o.summary.scene,
        }
    }

    /// The engine that ran (`reference` or `multibody`).
    pub fn engine(&self) -> &'static str {
        match self {
            Outcome::Pack(o) => o.engine,
            Outcome::Network(o) => o.summary.engine,
        }
    }

    /// The simulated time the run reached, s; a pack's engine failure as [`Error::Engine`]
    /// ([`RunOutcome::stats`]; a network's came back from [`Simulation::run`]).
    pub fn simulated_s(&self) -> Result<f64> {
        match self {
            Outcome::Pack(o) => Ok(o.stats()?.simulated_s),
            Outcome::Network(o) => Ok(o.summary.simulated_s),
        }
    }

    /// Whether the run stopped before its duration (a stop flag, or a pack's failed
    /// recording).
    pub fn stopped_early(&self) -> bool {
        match self {
            Outcome::Pack(o) => o.stopped_early(),
            Outcome::Network(o) => o.summary.stopped,
        }
    }

    /// What went wrong without stopping the run (a pack's; a network's problems come back
    /// from [`Simulation::run`]).
    pub fn warnings(&self) -> &[String] {
        match self {
            Outcome::Pack(o) => &o.warnings,
            Outcome::Network(_) => &[],
        }
    }

    /// The finished recording's path, or why a pack's could not be finished (a network's
    /// came back from [`Simulation::run`]); `None`: not asked.
    pub fn recording(&self) -> Option<std::result::Result<&Path, &RecordError>> {
        match self {
            Outcome::Pack(o) => o.recording.as_ref().map(|r| r.as_deref()),
            Outcome::Network(o) => o.recording.as_deref().map(Ok),
        }
    }

    /// Why a pack's impacts CSV could not be finished (a network's came back from
    /// [`Simulation::run`]).
    pub fn impacts_csv_error(&self) -> Option<&Error> {
        match self {
            Outcome::Pack(o) => o.impacts_csv.as_ref().and_then(|r| r.as_ref().err()),
            Outcome::Network(_) => None,
        }
    }

    /// The run's summary; a pack's engine failure is an error ([`RunOutcome::summary`]).
    pub fn summary(&self) -> Result<Summary> {
        Ok(match self {
            Outcome::Pack(o) => Summary::Pack(o.summary()?),
            Outcome::Network(o) => Summary::Network(o.summary.clone()),
        })
    }

    /// Every body's counted load cycles and spectra (`run --fatigue-json`, kept when
    /// [`RunRequest::keep_cycles`] asked for them): a pack's discs and plates, or every
    /// resolved pack's on a network ([`NetworkOutcome::cycles`]).
    pub fn cycles(&self) -> Vec<DiscCycles> {
        match self {
            Outcome::Pack(o) => o.cycles(),
            Outcome::Network(o) => o.cycles.clone(),
        }
    }

    /// A pack's outcome; a network's is bad input naming the scene.
    pub fn into_pack(self) -> Result<RunOutcome> {
        match self {
            Outcome::Pack(o) => Ok(o),
            Outcome::Network(o) => Err(Error::BadInput(format!(
                "{} is a network scene ([[bodies]]), not a pack",
                o.summary.scene
            ))),
        }
    }

    /// A network's outcome; a pack's is bad input naming the scene.
    pub fn into_network(self) -> Result<NetworkOutcome> {
        match self {
            Outcome::Network(o) => Ok(o),
            Outcome::Pack(o) => Err(crate::network::not_a_network(&o.scene)),
        }
    }
}

impl Simulation {
    /// Runs the scene, a pack or a network, for its `simulation.duration_s` as `request`
    /// asks. Outputs that cannot be created (the impacts CSV, the recording) are errors
    /// before any work; after that, whatever ends the run, every output is complete up to
    /// there. A pack's outcome holds an engine failure ([`RunOutcome::result`]); a network's
    /// is an [`Error::Engine`], its recording and impacts CSV finished first.
    pub fn run(&mut self, request: RunRequest<'_>) -> Result<Outcome> {
        crate::windows::check(request.windows_s, self.scene().simulation.duration_s)?;
        match self.network_engine() {
            Some(engine) => {
                crate::network::run(self.scene(), engine, request).map(Outcome::Network)
            }
            None => self.run_engine(request).map(Outcome::Pack),
        }
    }

    /// [`Simulation::run`] for a caller that takes pack scenes only: a network scene is
    /// refused before any work ([`Simulation::pack_only`]).
    pub fn run_pack(&mut self, request: RunRequest<'_>) -> Result<RunOutcome> {
        self.pack_only()?;
        self.run(request)?.into_pack()
    }

    /// A pack's run on its engine.
    fn run_engine(&mut self, request: RunRequest<'_>) -> Result<RunOutcome> {
        let names = self.body_names()?;
        let scene = self.scene();
        let mut collector = RunCollector::new(names.len(), request.keep_history)
            .with_interfaces(friction_interfaces(scene).into_iter().map(|f| f.name()))
            .with_fatigue(scene, request.keep_cycles);
        if let Some(path) = &request.impacts_csv {
            collector = collector.with_impacts_csv(path, &names)?;
        }
        if let Some(len_s) = request.windows_s {
            collector = collector.with_windows(len_s, &names);
        }
        let recorder = match &request.recording {
            Some(r) => {
                let info = run_info(scene, self.engine_name(), r.scene_path.as_deref());
                Some(Recorder::create_output(
                    &r.path, r.replace, &info, &r.options,
                )?)
            }
            None => None,
        };
        let duration = scene.simulation.duration_s;
        let scene_name = scene.name.clone();
        let engine_name = self.engine_name();
        let t0 = Instant::now();
        let done = run_recorded(
            self.engine_mut()?,
            duration,
            collector,
            recorder,
            request.stop,
            request.progress,
        );
        let wall_time_s = t0.elapsed().as_secs_f64();
        let mut collector = done.collector;
        let mut warnings = done.warnings;
        if let Some(e) = collector.fatigue.spill_error() {
            warnings.push(format!("{e}; the fatigue figures miss them"));
        }
        let impacts_csv = request
            .impacts_csv
            .map(|p| collector.finish_impacts_csv().map(|()| p));
        let t_end = done.result.as_ref().map_or_else(
            |_| collector.last_impact.map_or(0.0, |e| e.t_off_s),
            |s| s.simulated_s,
        );
        let windows = collector.finish_windows(t_end);
        Ok(RunOutcome {
            scene: scene_name,
            engine: engine_name,
            result: done.result,
            wall_time_s,
            engine_cpu_s: done.engine_cpu_s,
            recorder_cpu_s: done.recorder_cpu_s,
            body_names: names,
            collector,
            impacts_csv,
            recording: done.recording,
            windows,
            warnings,
        })
    }
}

/// What [`run_recorded`] gives back.
struct RecordedRun {
    result: std::result::Result<RunStats, EngineError>,
    collector: RunCollector,
    recording: Option<std::result::Result<PathBuf, RecordError>>,
    engine_cpu_s: f64,
    recorder_cpu_s: f64,
    warnings: Vec<String>,
}

/// Runs `engine` for `duration_s` with `collector` on the engine's thread and `recorder` (if
/// any) on a recording thread, then finishes the recording: with the engine's statistics and
/// the teeth's fatigue when it ran, and in any case with everything recorded before a
/// failure or a stop.
fn run_recorded<'a>(
    engine: &mut (dyn Engine + Send),
    duration_s: f64,
    collector: RunCollector,
    recorder: Option<Recorder>,
    stop: Option<&'a AtomicBool>,
    progress: Option<&'a mut dyn FnMut(f64)>,
) -> RecordedRun {
    let mut collector = collector;
    let mut recorder = recorder.map(ThreadedRecorder::start);
    let cpu = cpu_time::ThreadTime::try_now().ok();
    let result = engine.run(
        duration_s,
        &mut RunObserver {
            collector: &mut collector,
            recorder: recorder.as_mut(),
            stop,
            progress,
        },
    );
    let engine_cpu_s = cpu
        .and_then(|c| c.try_elapsed().ok())
        .map_or(0.0, |d| d.as_secs_f64());
    // Close the recording first: it holds everything before a failure or a stop.
    let mut recorder_cpu_s = 0.0;
    let mut warnings = Vec::new();
    let recording = recorder.map(|rec| {
        let (recording, cpu_s) = finish_recording(rec, &result, &collector, &mut warnings);
        recorder_cpu_s = cpu_s;
        recording
    });
    RecordedRun {
        result,
        collector,
        recording,
        engine_cpu_s,
        recorder_cpu_s,
        warnings,
    }
}

/// Finishes a recording after its run ended with `result`: with the engine's statistics and
/// the teeth's fatigue when it ran (from `collector`), and in any case with everything
/// recorded before a failure or a stop. Returns the file (or why not) and the recording
/// thread's CPU time, s; problems that do not lose the file go to `warnings`.
pub(crate) fn finish_recording(
    rec: ThreadedRecorder,
    result: &std::result::Result<RunStats, EngineError>,
    collector: &RunCollector,
    warnings: &mut Vec<String>,
) -> (std::result::Result<PathBuf, RecordError>, f64) {
    let (mut rec, cpu_s) = rec.join();
    // the file is finished even if the peaks kept on disk cannot be read back: its
    // summary then has no impact statistics
    let mut summary = rec.summary().unwrap_or_else(|e| {
        warnings.push(format!(
            "{e}; the recording's /summary has no impact statistics"
        ));
        clutchpack_record::RecordedSummary {
            t_end_s: result.as_ref().map_or(0.0, |s| s.simulated_s),
            discs: Vec::new(),
            fatigue: Vec::new(),
        }
    });
    if let Ok(s) = result {
        rec.set_run_stats(s);
        // the teeth's fatigue over the duty that ran, beside the peak statistics
        let names: Vec<String> = summary.discs.iter().map(|d| d.name.clone()).collect();
        summary.fatigue = collector
            .assess_fatigue(&names, s.simulated_s)
            .iter()
            .map(|f| Some(clutchpack_record::FatigueSummary::from(f)))
            .collect();
    }
    (rec.finish(Some(summary)), cpu_s)
}

/// Feeds the collector and the recorder; stops the run when the stop flag is set or the
/// recording failed.
pub(crate) struct RunObserver<'c, 'a> {
    pub collector: &'c mut RunCollector,
    pub recorder: Option<&'c mut ThreadedRecorder>,
    pub stop: Option<&'a AtomicBool>,
    pub progress: Option<&'a mut dyn FnMut(f64)>,
}

impl Observer for RunObserver<'_, '_> {
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
    fn temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        self.collector.temperatures(t_s, bodies_k, oil_k);
        if let Some(r) = &mut self.recorder {
            r.push_temperatures(t_s, bodies_k, oil_k);
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
                .is_some_and(|r| r.wants_contact_samples())
    }
    fn progress(&mut self, t_s: f64) -> bool {
        if let Some(p) = &mut self.progress {
            p(t_s);
        }
        let mut stop = false;
        if let Some(r) = &mut self.recorder {
            // hand over what is pending, so a slow engine's samples reach the file (and its
            // wall-clock flush) without waiting for a full batch
            r.send();
            stop |= r.failed();
        }
        stop || self.stop.is_some_and(|s| s.load(Ordering::SeqCst))
    }
}
