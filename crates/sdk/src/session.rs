//! A steppable run of a scene (co-simulation: the FMU, Python's `Simulation`): the engine's
//! session advanced call by call with inputs held between calls, feeding the same collector
//! and recording as [`Simulation::run`], finished into the same [`RunOutcome`].

use crate::collector::RunCollector;
use crate::request::RecordingRequest;
use crate::run::{finish_recording, RunObserver, RunOutcome};
use crate::summary::{friction_interfaces, run_info};
use crate::{Error, Result, Simulation};
use clutchpack_model::session::{Advance, Driven, Inputs, Snapshot};
use clutchpack_model::{EngineError, RunStats};
use clutchpack_record::{Recorder, ThreadedRecorder};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// How a steppable run starts.
#[derive(Debug, Clone, Default)]
pub struct SessionRequest {
    /// The inputs the caller drives (the others follow the scene's profiles); none: the
    /// scene's own inputs, and a run split into calls is the run bit for bit.
    pub driven: Driven,
    /// The time the run will not be advanced beyond, s (steps land on it); `None`: the
    /// scene's `simulation.duration_s` is not a limit, the caller decides.
    pub stop_time_s: Option<f64>,
    /// Record the run (MCAP), as [`crate::RunRequest::recording`].
    pub recording: Option<RecordingRequest>,
    /// Keep every sample's load and every impact (memory grows with the run).
    pub keep_history: bool,
}

/// A run in progress: [`Session::advance_to`] one communication point after another, then
/// [`Session::finish`].
pub struct Session {
    scene: String,
    engine: &'static str,
    body_names: Vec<String>,
    n_discs: usize,
    inner: Box<dyn clutchpack_model::session::Session>,
    collector: RunCollector,
    recorder: Option<ThreadedRecorder>,
    /// Why the engine failed, once it has (the session then only finishes).
    failure: Option<EngineError>,
    stopped: bool,
    started: Instant,
    /// The inputs set so far, each call's merged over the calls before (`None`: none set
    /// yet): a call that changes nothing is not passed to the engine ([`Session::set_inputs`]).
    held: Option<Inputs>,
}

/// A saved state of a [`Session`] ([`Session::save`]), restored by [`Session::restore`] any
/// number of times.
pub struct SessionState {
    inner: Box<dyn clutchpack_model::session::Session>,
    collector: RunCollector,
    held: Option<Inputs>,
}

impl Simulation {
    /// Starts a steppable run at t = 0 as `request` asks. Bad input (an input the pack does
    /// not have, a recording that cannot be created) is an error before any work.
    pub fn start(&self, request: SessionRequest) -> Result<Session> {
        let scene = self.scene();
        let names = self.body_names()?;
        let mut inner = self
            .engine()?
            .start(request.driven)
            .map_err(|e| Error::BadInput(format!("{}: {e}", scene.name)))?;
        if let Some(t) = request.stop_time_s {
            inner.set_stop_time(t);
        }
        let collector = RunCollector::new(names.len(), request.keep_history)
            .with_interfaces(friction_interfaces(scene).into_iter().map(|f| f.name()))
            .with_fatigue(scene, false);
        let recorder = match &request.recording {
            Some(r) => {
                let mut info = run_info(scene, self.engine_name(), r.scene_path.as_deref());
                let driven: Vec<String> = crate::cosim::driven_names(&request.driven)
                    .into_iter()
                    .map(String::from)
                    .collect();
                co_simulation_params(&mut info.params, &driven, request.stop_time_s);
                Some(ThreadedRecorder::start(Recorder::create_output(
                    &r.path, r.replace, &info, &r.options,
                )?))
            }
            None => None,
        };
        Ok(Session {
            scene: scene.name.clone(),
            engine: self.engine_name(),
            body_names: names,
            n_discs: scene.pack.discs.len(),
            inner,
            collector,
            recorder,
            failure: None,
            stopped: false,
            started: Instant::now(),
            held: None,
        })
    }
}

/// What a co-simulated run's recording says of how it was made (`clutchpack.params`): not the
/// scene's `duration_s` (the caller decides where the run ends: `stop_time_s` if it was
/// given; the stored statistics say where it ended) and which inputs the caller drove, by
/// their public names. A pack's session and a network's run advanced call by call both write
/// it.
pub(crate) fn co_simulation_params(
    params: &mut std::collections::BTreeMap<String, String>,
    driven: &[String],
    stop_time_s: Option<f64>,
) {
    params.remove("duration_s");
    params.insert("co_simulation".into(), "true".into());
    if let Some(t) = stop_time_s {
        params.insert("stop_time_s".into(), t.to_string());
    }
    params.insert(
        "driven_inputs".into(),
        if driven.is_empty() {
            "none (the scene's profiles)".into()
        } else {
            driven.join(", ")
        },
    );
}

impl Session {
    /// The time the run stands at, s.
    pub fn time_s(&self) -> f64 {
        self.inner.time_s()
    }

    /// The bodies' names in output order (the discs, then the plates).
    pub fn body_names(&self) -> &[String] {
        &self.body_names
    }

    /// How many of the bodies are friction discs (the rest are plates).
    pub fn disc_count(&self) -> usize {
        self.n_discs
    }

    /// Sets inputs from [`Session::time_s`] on (held until changed); bad input names the
    /// input and why.
    ///
    /// A call that changes nothing (every value set the one already held, no derivative set
    /// now or before) is not passed to the engine: a host sets every input at every
    /// communication point (`CoSimulation`, the FMU), and re-holding an unchanged input
    /// restarted the engine's integration there (the reference engine's step controller and
    /// its first derivative, the multibody engine's drive) and cloned the pack at every
    /// frame. The held input is the same function of time either way (issue 46).
    pub fn set_inputs(&mut self, inputs: &Inputs) -> Result<()> {
        if self.held.as_ref().is_some_and(|h| unchanged(h, inputs)) {
            return Ok(());
        }
        self.inner
            .set_inputs(inputs)
            .map_err(|e| Error::BadInput(format!("{}: {e}", self.scene)))?;
        self.held = Some(merged(self.held.as_ref(), inputs));
        Ok(())
    }

    /// Advances to `t_s`, feeding the statistics and the recording; `stop` (checked at the
    /// engine's progress polls) ends the call early. After an engine failure the session only
    /// finishes (everything before the failure is kept).
    pub fn advance_to(&mut self, t_s: f64, stop: Option<&AtomicBool>) -> Result<Advance> {
        self.advance_polled(t_s, stop, None)
    }

    /// [`Session::advance_to`] with `progress` called at the engine's progress polls with the
    /// simulated time reached, s: a front end's own check for a stop on the calling thread
    /// (Python's signals, polled as a whole run polls them), so that a call needs no second
    /// thread to stay interruptible.
    pub fn advance_polled<'a>(
        &mut self,
        t_s: f64,
        stop: Option<&'a AtomicBool>,
        progress: Option<&'a mut dyn FnMut(f64)>,
    ) -> Result<Advance> {
        if let Some(e) = &self.failure {
            return Err(self.engine_error(e.clone()));
        }
        let mut obs = RunObserver {
            collector: &mut self.collector,
            recorder: self.recorder.as_mut(),
            stop,
            progress,
        };
        match self.inner.advance_to(t_s, &mut obs) {
            Ok(a) => {
                self.stopped |= a == Advance::Stopped;
                Ok(a)
            }
            Err(EngineError::Unsupported(why)) => {
                Err(Error::BadInput(format!("{}: {why}", self.scene)))
            }
            Err(e) => {
                self.failure = Some(e.clone());
                Err(self.engine_error(e))
            }
        }
    }

    fn engine_error(&self, source: EngineError) -> Error {
        Error::Engine {
            context: format!("{} engine on {} (co-simulation)", self.engine, self.scene),
            source,
        }
    }

    /// The pack's state at [`Session::time_s`].
    pub fn snapshot(&self) -> Snapshot {
        self.inner.snapshot()
    }

    /// A thermal run's latest temperatures, K: the bodies (discs, then plates), then the oil
    /// (sent at t = 0, at every thermal window's end and at the run's end; empty for an
    /// isothermal run).
    pub fn temperatures_k(&self) -> &[f64] {
        &self.collector.temperatures_k
    }

    /// Impacts closed so far.
    pub fn impact_count(&self) -> usize {
        self.collector.impact_count()
    }

    /// The impact that closed last, if any (the recording and the statistics have them all).
    pub fn last_impact(&self) -> Option<clutchpack_model::ImpactEvent> {
        self.collector.last_impact
    }

    /// Each body's largest impact load so far, N (the largest `|F|` per tooth of its
    /// impacts' peaks; 0 before its first impact), in body order.
    pub fn max_loads_n(&self) -> Vec<f64> {
        (0..self.body_names.len())
            .map(|i| self.collector.peaks.max_abs_n(i))
            .collect()
    }

    /// Each body's teeth's fatigue damage so far (Miner sum over the duty that ran,
    /// dimensionless; 1 = the predicted life used up), in body order (MODEL.md section 7).
    pub fn damage(&self) -> Vec<f64> {
        self.collector
            .assess_fatigue(&self.body_names, self.time_s())
            .iter()
            .map(|f| f.lumped.damage)
            .collect()
    }

    /// Saves the whole state (the engine's and what is kept); a run being recorded cannot
    /// save (a file cannot be rewound).
    pub fn save(&self) -> Result<SessionState> {
        if self.recorder.is_some() {
            return Err(Error::BadInput(format!(
                "{}: a recorded run cannot save its state (the recording cannot be rewound); \
                 run without the recording to roll back",
                self.scene
            )));
        }
        Ok(SessionState {
            inner: self.inner.boxed_clone(),
            collector: self.collector.try_clone()?,
            held: self.held,
        })
    }

    /// Restores a state saved by [`Session::save`] of this session. A recorded run refuses
    /// every restore: its recording cannot be rewound.
    pub fn restore(&mut self, state: &SessionState) -> Result<()> {
        if self.recorder.is_some() {
            return Err(Error::BadInput(format!(
                "{}: a recorded run cannot be rewound (its recording holds the samples and \
                 impacts already written); run without the recording to roll back",
                self.scene
            )));
        }
        self.inner = state.inner.boxed_clone();
        self.collector = state.collector.try_clone()?;
        self.held = state.held;
        self.failure = None;
        Ok(())
    }

    /// Ends the run at [`Session::time_s`]: closes the open contact events, finishes the
    /// recording, and gives what a whole run gives.
    pub fn finish(mut self) -> RunOutcome {
        let (result, recording, warnings, recorder_cpu_s) = self.conclude_here();
        RunOutcome {
            scene: std::mem::take(&mut self.scene),
            engine: self.engine,
            result,
            wall_time_s: self.started.elapsed().as_secs_f64(),
            engine_cpu_s: 0.0,
            recorder_cpu_s,
            body_names: std::mem::take(&mut self.body_names),
            collector: std::mem::replace(&mut self.collector, RunCollector::new(0, false)),
            impacts_csv: None,
            recording,
            windows: Vec::new(),
            warnings,
        }
    }

    /// [`Session::finish`] in place: the open contact events closed, the recording (taken)
    /// finished; the run's result, the recording's, the warnings and the recorder's CPU
    /// time, s.
    #[allow(clippy::type_complexity)]
    fn conclude_here(
        &mut self,
    ) -> (
        std::result::Result<RunStats, EngineError>,
        Option<std::result::Result<std::path::PathBuf, clutchpack_record::RecordError>>,
        Vec<String>,
        f64,
    ) {
        let result = match self.failure.take() {
            Some(e) => Err(e),
            None => {
                let mut obs = RunObserver {
                    collector: &mut self.collector,
                    recorder: self.recorder.as_mut(),
                    stop: None,
                    progress: None,
                };
                let mut stats: RunStats = self.inner.finish(&mut obs);
                stats.stopped_early = self.stopped;
                Ok(stats)
            }
        };
        let mut warnings = Vec::new();
        let mut recorder_cpu_s = 0.0;
        let recording = self.recorder.take().map(|rec| {
            let (r, cpu) = finish_recording(rec, &result, &self.collector, &mut warnings);
            recorder_cpu_s = cpu;
            r
        });
        (result, recording, warnings, recorder_cpu_s)
    }
}

/// Whether setting `new` over the inputs `held` changes nothing: no derivative (a slope
/// restarts its ramp where it is set, so one set again is a new ramp), and every value `new`
/// sets is the one held.
fn unchanged(held: &Inputs, new: &Inputs) -> bool {
    let flat = |x: &Inputs| {
        [
            x.shaft_speed_slope_rad_s2,
            x.shaft_speed_curvature_rad_s3,
            x.shaft_torque_slope_n_m_s,
        ]
        .iter()
        .all(|d| d.is_none_or(|v| v == 0.0))
    };
    let same = |n: Option<f64>, h: Option<f64>| n.is_none_or(|v| h == Some(v));
    flat(held)
        && flat(new)
        && same(new.shaft_speed_rad_s, held.shaft_speed_rad_s)
        && same(new.shaft_torque_n_m, held.shaft_torque_n_m)
        && same(new.drum_load_n_m, held.drum_load_n_m)
        && same(new.piston_pressure_pa, held.piston_pressure_pa)
}

/// The inputs held after `new` is set over `held`: each value `new` sets, else the one held;
/// the derivatives `new`'s (they hold from where they are set).
fn merged(held: Option<&Inputs>, new: &Inputs) -> Inputs {
    let h = held.copied().unwrap_or_default();
    Inputs {
        shaft_speed_rad_s: new.shaft_speed_rad_s.or(h.shaft_speed_rad_s),
        shaft_torque_n_m: new.shaft_torque_n_m.or(h.shaft_torque_n_m),
        drum_load_n_m: new.drum_load_n_m.or(h.drum_load_n_m),
        piston_pressure_pa: new.piston_pressure_pa.or(h.piston_pressure_pa),
        ..*new
    }
}

/// A recorded run dropped without [`Session::finish`] (a Python `Simulation` collected, a
/// script that ends, an FMU instance freed) is finished as `finish` would: its recording
/// complete, with its statistics, under its own name (as a run stopped by a signal leaves
/// it), not left as a `.partial-` file that only a salvage reads.
impl Drop for Session {
    fn drop(&mut self) {
        if self.recorder.is_some() {
            let _ = self.conclude_here();
        }
    }
}
