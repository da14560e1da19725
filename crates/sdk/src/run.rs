//! One run of a pack scene: the engine on the caller's thread feeding the collector, the
//! recording (if asked) on its own thread, both finished whatever stops the run; its
//! `RunOutcome`.

use crate::collector::RunCollector;
use crate::summary::{friction_interfaces, run_info, RunSummary};
use crate::{Error, Result, RunRequest, Simulation};
use clutchpack_analysis::{DiscCycles, DiscFatigue, DiscStats};
use clutchpack_model::{
    DiscSample, Engine, EngineError, ImpactEvent, InterfaceSample, Observer, RunStats, Sample,
};
use clutchpack_record::{RecordError, Recorder, ThreadedRecorder};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

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

impl Simulation {
    /// A pack's run on its engine ([`Simulation::run`] of a pack scene).
    pub(crate) fn run_engine(&mut self, request: RunRequest<'_>) -> Result<RunOutcome> {
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
