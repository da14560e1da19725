//! Network scenes from Python: `run_network`, a whole run (the summary, the sampled speeds and
//! torques, a recording), and `NetworkStepper`, a run advanced call by call over the sdk's
//! network co-simulation (`clutchpack_sdk::NetworkSimulation`), with the inputs and outputs by
//! their public names (`couplings.K2.normal_force_n`, `bodies.crank.speed_rad_s`). The Python
//! half's `clutchpack.Simulation` wraps the stepper for a network scene, as it wraps `Stepper`
//! for a pack.

use crate::{check_outputs, engine_choice, py_err, signal_poll, Scene};
use clutchpack_sdk::{NetworkSimulation, RecordingRequest, SavedNetworkSimulation};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Mutex, MutexGuard};

/// What one network run gave, for the Python half.
#[pyclass(name = "RawNetworkRun", module = "clutchpack", frozen, get_all)]
pub struct RawNetworkRun {
    /// `--summary-json`'s content for a network (JSON text).
    summary_json: String,
    /// Sample times, s.
    sample_t_s: Vec<f64>,
    /// Each body's speed at them, rad/s, by name.
    speed_rad_s: Vec<(String, Vec<f64>)>,
    /// Each coupling's torque on its body a at them, N m, by name.
    torque_n_m: Vec<(String, Vec<f64>)>,
    /// The recording's path, if one was asked.
    recording: Option<PathBuf>,
}

/// A network recording read back for `clutchpack.read`: the attached summary (the run's
/// `--summary-json`; the scene and engine alone if the run did not finish), the scene, and
/// the samples as the columns `run_network` gives.
pub fn raw_network_recording(
    reader: &clutchpack_sdk::record::RecordingReader,
    net: clutchpack_sdk::record::RecordedNetwork,
    warning: Option<String>,
) -> crate::RawRecording {
    let info = reader.run_info();
    let summary_json = net
        .summary_json
        .as_deref()
        .and_then(|j| String::from_utf8(j.to_vec()).ok())
        .unwrap_or_else(|| {
            serde_json::json!({
                "scene": info.as_ref().map(|i| i.scene_name.clone()),
                "engine": info.as_ref().map(|i| i.engine.clone()),
            })
            .to_string()
        });
    let column = |f: &dyn Fn(&clutchpack_sdk::NetworkSample) -> f64| -> Vec<f64> {
        net.samples.iter().map(f).collect()
    };
    let mut sample_columns = Vec::new();
    for (i, b) in net.bodies.iter().enumerate() {
        sample_columns.push((format!("{b}.speed_rad_s"), column(&|s| s.speed_rad_s[i])));
    }
    for (k, c) in net.couplings.iter().enumerate() {
        sample_columns.push((format!("{c}.torque_n_m"), column(&|s| s.torque_n_m[k])));
    }
    crate::RawRecording {
        summary_json,
        scene_text: info.as_ref().map(|i| i.scene_text.clone()),
        overrides: info.map(|i| i.overrides).unwrap_or_default(),
        // the events' `disc` indices are per pack: name each by its own name
        impacts: {
            let events: Vec<_> = net
                .impacts
                .iter()
                .enumerate()
                .map(|(i, (_, e))| clutchpack_sdk::model::ImpactEvent { disc: i, ..*e })
                .collect();
            let names: Vec<String> = net.impacts.iter().map(|(n, _)| n.clone()).collect();
            crate::ImpactColumns::of(&events, &names)
        },
        loads: Vec::new(),
        warning,
        sample_t_s: net.samples.iter().map(|s| s.t_s).collect(),
        sample_columns,
    }
}

/// Runs a network scene (`[[bodies]]`) on `engine` (else `simulation.engine`, else the
/// reference engine), as `clutchpack run` does: the summary and the sampled speeds and
/// torques, the recording at `record` and every tooth impact in the CSV file `impacts_csv`
/// (`run --impacts-csv`'s, through the same request) if given (each replaced if it exists).
/// The GIL is released while it runs; Ctrl-C stops it and raises `KeyboardInterrupt` (the
/// recording and the CSV then hold the run up to there).
#[pyfunction]
#[pyo3(signature = (scene, engine=None, record=None, deterministic=false, impacts_csv=None))]
pub fn run_network(
    py: Python<'_>,
    scene: &Scene,
    engine: Option<&str>,
    record: Option<PathBuf>,
    deterministic: bool,
    impacts_csv: Option<PathBuf>,
) -> PyResult<RawNetworkRun> {
    check_outputs(
        &[
            ("record =", record.as_deref()),
            ("impacts_csv =", impacts_csv.as_deref()),
        ],
        scene,
    )?;
    let recording = record.map(|path| RecordingRequest {
        path,
        replace: clutchpack_sdk::record::Replace::Existing,
        options: clutchpack_sdk::record::RecordOptions {
            deterministic,
            ..clutchpack_sdk::record::RecordOptions::default()
        },
        scene_path: scene.path.clone(),
    });
    let mut sim = clutchpack_sdk::Simulation::new(scene.inner.clone(), engine_choice(engine)?)
        .map_err(py_err)?;
    sim.network_only().map_err(py_err)?;
    let stop = AtomicBool::new(false);
    let mut interrupt: Option<PyErr> = None;
    let outcome = py.detach(|| {
        let mut progress = signal_poll(&stop, &mut interrupt);
        sim.run(clutchpack_sdk::NetworkRequest {
            keep_history: true,
            recording,
            stop: Some(&stop),
            progress: Some(&mut progress),
            impacts_csv,
            ..Default::default()
        })
        .and_then(clutchpack_sdk::Outcome::into_network)
    });
    let outcome = outcome.map_err(py_err)?;
    if let Some(e) = interrupt {
        return Err(e);
    }
    let h = &outcome.history;
    let s = &outcome.summary;
    let column = |f: &dyn Fn(&clutchpack_sdk::NetworkSample) -> f64| h.iter().map(f).collect();
    Ok(RawNetworkRun {
        summary_json: serde_json::to_string(s)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?,
        sample_t_s: h.iter().map(|x| x.t_s).collect(),
        speed_rad_s: s
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.clone(), column(&|x| x.speed_rad_s[i])))
            .collect(),
        torque_n_m: s
            .couplings
            .iter()
            .enumerate()
            .map(|(k, c)| (c.name.clone(), column(&|x| x.torque_n_m[k])))
            .collect(),
        recording: outcome.recording.clone(),
    })
}

/// A network run advanced call by call: `advance_to(t)` with the driven inputs set and held
/// in between.
#[pyclass(name = "NetworkStepper", module = "clutchpack")]
pub struct NetworkStepper {
    /// `None` once finished. A mutex makes the class `Sync` (free-threaded Python).
    sim: Mutex<Option<NetworkSimulation>>,
}

/// A saved state of a [`NetworkStepper`].
#[pyclass(name = "NetworkStepperState", module = "clutchpack")]
pub struct NetworkStepperState {
    state: Mutex<SavedNetworkSimulation>,
}

fn value_err(e: clutchpack_sdk::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

impl NetworkStepper {
    fn lock(&self) -> MutexGuard<'_, Option<NetworkSimulation>> {
        // a panic inside a call is a bug; the run stays usable for reading
        self.sim.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// The running simulation in `guard`, or the error of a finished one.
fn running(guard: &mut Option<NetworkSimulation>) -> PyResult<&mut NetworkSimulation> {
    guard
        .as_mut()
        .ok_or_else(|| PyValueError::new_err("the simulation has finished"))
}

#[pymethods]
impl NetworkStepper {
    /// Starts the network scene `scene` at t = 0 on `engine` (else the scene's choice, else
    /// the reference engine; either engine runs a network call by call), the caller driving the inputs named in
    /// `drive` (`bodies.<body>.drive_torque_n_m`, `couplings.<clutch>.normal_force_n`; the
    /// rest follow the scene), recording to `record` if given, the run ending at `stop_time`
    /// (s) if given.
    #[new]
    #[pyo3(signature = (scene, engine=None, drive=Vec::new(), record=None, stop_time=None))]
    fn new(
        scene: &Scene,
        engine: Option<&str>,
        drive: Vec<String>,
        record: Option<PathBuf>,
        stop_time: Option<f64>,
    ) -> PyResult<NetworkStepper> {
        check_outputs(&[("record =", record.as_deref())], scene)?;
        let recording = record.map(|path| RecordingRequest {
            path,
            replace: clutchpack_sdk::record::Replace::Existing,
            options: clutchpack_sdk::record::RecordOptions::default(),
            scene_path: scene.path.clone(),
        });
        let sim = NetworkSimulation::start(
            &scene.inner,
            engine_choice(engine)?,
            &drive,
            recording.as_ref(),
            stop_time,
        )
        .map_err(value_err)?;
        Ok(NetworkStepper {
            sim: Mutex::new(Some(sim)),
        })
    }

    /// The time the run stands at, s.
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(running(&mut self.lock())?.time_s())
    }

    /// `(name, causality, unit, description)` of every variable: the driven inputs, then the
    /// outputs.
    fn variables(&self) -> PyResult<Vec<(String, String, String, String)>> {
        Ok(running(&mut self.lock())?
            .variables()
            .into_iter()
            .map(|v| {
                (
                    v.name,
                    v.causality.to_string(),
                    v.unit.to_string(),
                    v.description,
                )
            })
            .collect())
    }

    /// Sets the driven input `name` to `value` (N m or N), held from now on. A network input
    /// takes no slope (a held value only).
    #[pyo3(signature = (name, value, slope=None, curvature=None))]
    fn set_input(
        &mut self,
        name: &str,
        value: f64,
        slope: Option<f64>,
        curvature: Option<f64>,
    ) -> PyResult<()> {
        if slope.is_some() || curvature.is_some() {
            return Err(PyValueError::new_err(format!(
                "slopes[{name:?}]: a network's input is held (zero-order); it takes no slope"
            )));
        }
        running(&mut self.lock())?
            .set_input(name, value)
            .map_err(value_err)
    }

    /// Advances to `t` (s) with the GIL released; Ctrl-C stops it (the run then stands at an
    /// earlier time, everything before kept) and raises `KeyboardInterrupt`.
    fn advance_to(&mut self, py: Python<'_>, t: f64) -> PyResult<()> {
        let mut guard = self.lock();
        let sim = running(&mut guard)?;
        // on this thread, Python's signals polled from the engine's progress (issue 46: a
        // worker thread per call cost a host's frames two wake-ups)
        let stop = AtomicBool::new(false);
        let mut interrupt = None;
        let out = py.detach(|| {
            let mut poll = signal_poll(&stop, &mut interrupt);
            sim.advance_polled(t, Some(&stop), Some(&mut poll))
        });
        if let Some(e) = interrupt {
            return Err(e);
        }
        out.map_err(value_err)
    }

    /// Every output's `(name, value)` now.
    fn outputs(&self) -> PyResult<Vec<(String, f64)>> {
        Ok(running(&mut self.lock())?.outputs())
    }

    /// Saves the whole state (not while recording: a recording cannot be rewound).
    fn save(&self) -> PyResult<NetworkStepperState> {
        let state = running(&mut self.lock())?.save().map_err(value_err)?;
        Ok(NetworkStepperState {
            state: Mutex::new(state),
        })
    }

    /// Restores a state saved by `save`.
    fn restore(&mut self, state: &NetworkStepperState) -> PyResult<()> {
        let saved = state.state.lock().unwrap_or_else(|p| p.into_inner());
        running(&mut self.lock())?
            .restore(&saved)
            .map_err(value_err)
    }

    /// Ends the run (its recording finished) and returns its summary (`--summary-json`'s
    /// content for a network, JSON text).
    fn finish(&mut self) -> PyResult<String> {
        let sim = self
            .lock()
            .take()
            .ok_or_else(|| PyValueError::new_err("the simulation has finished"))?;
        let outcome = sim
            .finish()
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        serde_json::to_string(&outcome.summary).map_err(|e| PyRuntimeError::new_err(e.to_string()))
    }
}
