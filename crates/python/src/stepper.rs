//! `clutchpack._clutchpack.Stepper`: a steppable run for controllers and co-simulation written
//! in Python, of a pack or a network scene alike, over the sdk's one co-simulation layer
//! (`clutchpack_sdk::CoSimulation`, which the FMU wraps too), so its inputs, outputs and their
//! names are the FMU's (`discs[1].load_n`, `piston.pressure_pa`,
//! `couplings.K2.normal_force_n`, `bodies.crank.speed_rad_s`, ...). The Python half wraps it
//! as `clutchpack.Simulation`.

use crate::{check_outputs, engine_choice, py_err, signal_poll, Scene};
use clutchpack_sdk::cosim::{Causality, Quantity};
use clutchpack_sdk::{CoSimulation, SavedCoSimulation, Summary};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Mutex, MutexGuard};

/// A run advanced call by call: `advance_to(t)` with inputs set and held in between.
#[pyclass(name = "Stepper", module = "clutchpack")]
pub struct Stepper {
    /// A mutex makes the class `Sync` (free-threaded Python); calls take it in turn.
    co: Mutex<CoSimulation>,
}

/// A saved state of a [`Stepper`].
#[pyclass(name = "StepperState", module = "clutchpack")]
pub struct StepperState {
    state: Mutex<SavedCoSimulation>,
}

/// `ValueError` with the sdk's message: what the constructor, `set_input`, `save` and
/// `restore` raise for any error (a bad value or call, and a run that cannot start).
fn value_err(e: clutchpack_sdk::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

impl Stepper {
    fn co(&self) -> MutexGuard<'_, CoSimulation> {
        // a panic inside a call is a bug; the run stays usable for reading
        self.co.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[pymethods]
impl Stepper {
    /// Starts the run of `scene` at t = 0 with the engine `engine` (else the scene's
    /// choice), the caller driving the inputs named in `drive` (the rest follow the scene):
    /// a pack's by their public names ("shaft.speed_rad_s", "shaft.drive_torque_n_m",
    /// "drum.load_torque_n_m", "piston.pressure_pa") or the older "shaft_speed",
    /// "shaft_torque", "drum_load", "piston_pressure"; a network's as
    /// "bodies.<body>.speed_rad_s" (a prescribed body), "bodies.<body>.drive_torque_n_m",
    /// "couplings.<clutch>.normal_force_n" or
    /// "couplings.<pack>.pressure_pa". Records to `record` if given; steps land on
    /// `stop_time` (s) if given (a network's run ends there).
    #[new]
    #[pyo3(signature = (scene, engine=None, drive=Vec::new(), record=None, stop_time=None))]
    fn new(
        scene: &Scene,
        engine: Option<&str>,
        drive: Vec<String>,
        record: Option<PathBuf>,
        stop_time: Option<f64>,
    ) -> PyResult<Stepper> {
        if let Some(t) = stop_time.filter(|t| !(t.is_finite() && *t > 0.0)) {
            return Err(PyValueError::new_err(format!(
                "stop_time = {t}: expected a finite number of seconds > 0"
            )));
        }
        check_outputs(&[("record =", record.as_deref())], scene)?;
        let mut co = CoSimulation::driving_named(scene.inner.clone(), &drive)
            .map_err(value_err)?
            .reading(scene.path.iter().cloned().collect())
            .loaded_from(scene.path.clone());
        if let Some(e) = engine_choice(engine)? {
            co.set_string_parameter(Quantity::Engine, e.name())
                .map_err(value_err)?;
        }
        if let Some(p) = &record {
            co.set_string_parameter(Quantity::RecordingPath, &p.to_string_lossy())
                .map_err(value_err)?;
        }
        co.start(stop_time).map_err(value_err)?;
        Ok(Stepper { co: Mutex::new(co) })
    }

    /// The time the run stands at, s.
    #[getter]
    fn time(&self) -> f64 {
        self.co().time_s()
    }

    /// `(name, causality, unit, description)` of every variable (the FMU's): the parameters,
    /// the driven inputs, the outputs.
    fn variables(&self) -> Vec<(String, String, String, String)> {
        self.co()
            .variables()
            .iter()
            .map(|v| {
                let c = match v.causality {
                    Causality::Parameter => "parameter",
                    Causality::Input => "input",
                    Causality::Output => "output",
                };
                (
                    v.name.clone(),
                    c.to_string(),
                    v.unit.unwrap_or("").to_string(),
                    v.description.clone(),
                )
            })
            .collect()
    }

    /// Sets the input `name` (e.g. "shaft.speed_rad_s"; an older name too) to `value`, held
    /// from now on; with `slope` (per s) and `curvature` (per s^2) as a first- or
    /// second-order hold (a pack's shaft; a network's inputs take none).
    #[pyo3(signature = (name, value, slope=None, curvature=None))]
    fn set_input(
        &mut self,
        name: &str,
        value: f64,
        slope: Option<f64>,
        curvature: Option<f64>,
    ) -> PyResult<()> {
        self.co()
            .set_input(name, value, [slope, curvature])
            .map_err(value_err)
    }

    /// Advances to `t` (s) with the GIL released; Ctrl-C stops it (the run then stands at
    /// an earlier time, everything before kept) and raises `KeyboardInterrupt`. Bad input (a
    /// held input carried past its bound) raises `ValueError`, an engine failure
    /// `RuntimeError`.
    fn advance_to(&mut self, py: Python<'_>, t: f64) -> PyResult<()> {
        let mut guard = self.co();
        let now = guard.time_s();
        if !(t.is_finite() && t >= now) {
            return Err(PyValueError::new_err(format!(
                "advance_to({t}): expected a finite time at or after the run's time {now} s"
            )));
        }
        // on this thread with the GIL released, Python's signals polled from the engine's
        // progress as a whole run polls them: a frame of a few microseconds costs no thread
        // (a worker thread per call cost 1.5-3x a host's 1 ms frames, issue 46)
        let stop = AtomicBool::new(false);
        let mut interrupt = None;
        let co = &mut *guard;
        let out = py.detach(|| {
            let mut poll = signal_poll(&stop, &mut interrupt);
            co.advance_polled(t, Some(&stop), Some(&mut poll))
        });
        if let Some(e) = interrupt {
            return Err(e);
        }
        out.map(|_| ()).map_err(py_err)
    }

    /// Every output's `(name, value)` now (the Integer ones as floats).
    fn outputs(&self) -> PyResult<Vec<(String, f64)>> {
        self.co().outputs().map_err(py_err)
    }

    /// Saves the whole state (not while recording: a recording cannot be rewound).
    fn save(&self) -> PyResult<StepperState> {
        self.co()
            .save()
            .map(|state| StepperState {
                state: Mutex::new(state),
            })
            .map_err(value_err)
    }

    /// Restores a state saved by `save` of this run.
    fn restore(&mut self, state: &StepperState) -> PyResult<()> {
        let saved = state.state.lock().unwrap_or_else(|p| p.into_inner());
        self.co().restore(&saved).map_err(value_err)
    }

    /// Ends the run (its recording finished) and returns its summary (`--summary-json`'s
    /// content, a pack's or a network's, JSON text).
    fn finish(&mut self) -> PyResult<String> {
        let mut co = self.co();
        // a pack's warnings (a recording's summary) are in its outcome; a network's run that
        // could not be finished comes back as a warning alone
        let warnings = co.finish();
        let summary = if let Some(outcome) = co.outcome() {
            if let Some(Err(e)) = &outcome.recording {
                return Err(PyRuntimeError::new_err(format!("the recording: {e}")));
            }
            Summary::Pack(outcome.summary().map_err(py_err)?)
        } else if let Some(outcome) = co.network_outcome() {
            Summary::Network(outcome.summary.clone())
        } else if warnings.is_empty() {
            return Err(PyRuntimeError::new_err("the run was never started"));
        } else {
            return Err(PyRuntimeError::new_err(warnings.join("; ")));
        };
        serde_json::to_string(&summary).map_err(|e| PyRuntimeError::new_err(e.to_string()))
    }
}
