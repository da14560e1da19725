//! `clutchpack._clutchpack.Stepper`: a steppable run for controllers and co-simulation written
//! in Python, over the FMU's own instance (`clutchpack_fmu::Instance`), so its inputs, outputs
//! and their names are the FMU's (`discs[1].load_n`, ...). The Python half wraps it as
//! `clutchpack.Simulation`.

use crate::{check_outputs, engine_choice, interruptible, py_err, Scene};
use clutchpack_fmu::variables::{Causality, Kind, Quantity};
use clutchpack_fmu::Instance;
use clutchpack_model::session::Driven;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Mutex, MutexGuard};

/// A run advanced call by call: `advance_to(t)` with inputs set and held in between.
#[pyclass(name = "Stepper", module = "clutchpack")]
pub struct Stepper {
    /// A mutex makes the class `Sync` (free-threaded Python); calls take it in turn.
    inst: Mutex<Instance>,
}

/// A saved state of a [`Stepper`].
#[pyclass(name = "StepperState", module = "clutchpack")]
pub struct StepperState {
    state: Mutex<clutchpack_fmu::instance::SavedState>,
}

fn value_err(e: String) -> PyErr {
    PyValueError::new_err(e)
}

impl Stepper {
    fn inst(&self) -> MutexGuard<'_, Instance> {
        // a panic inside a call is a bug; the instance stays usable for reading
        self.inst.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn variable(&self, name: &str, kind: Kind) -> PyResult<u32> {
        let inst = self.inst();
        inst.variables()
            .iter()
            .find(|v| v.name == name && v.kind == kind)
            .map(|v| v.vr)
            .ok_or_else(|| {
                let inputs: Vec<&str> = inst
                    .variables()
                    .iter()
                    .filter(|v| v.causality == Causality::Input)
                    .map(|v| v.name.as_str())
                    .collect();
                PyValueError::new_err(format!(
                    "{name:?} is not an input of this simulation (its inputs: {})",
                    if inputs.is_empty() {
                        "none: it follows the scene's profiles".to_string()
                    } else {
                        inputs.join(", ")
                    }
                ))
            })
    }
}

#[pymethods]
impl Stepper {
    /// Starts the run of `scene` at t = 0 with the engine `engine` (else the scene's
    /// choice), the caller driving `drive` (of "shaft_speed", "shaft_torque", "drum_load",
    /// "piston_pressure"; the rest follow the scene), recording to `record` if given, steps
    /// landing on `stop_time` (s) if given.
    #[new]
    #[pyo3(signature = (scene, engine=None, drive=Vec::new(), record=None, stop_time=None))]
    fn new(
        scene: &Scene,
        engine: Option<&str>,
        drive: Vec<String>,
        record: Option<PathBuf>,
        stop_time: Option<f64>,
    ) -> PyResult<Stepper> {
        let mut driven = Driven::NONE;
        for d in &drive {
            match d.as_str() {
                "shaft_speed" => driven.shaft_speed = true,
                "shaft_torque" => driven.shaft_torque = true,
                "drum_load" => driven.drum_load = true,
                "piston_pressure" => driven.piston_pressure = true,
                other => {
                    return Err(PyValueError::new_err(format!(
                        "drive = {other:?}: expected any of \"shaft_speed\", \"shaft_torque\", \
                         \"drum_load\", \"piston_pressure\""
                    )))
                }
            }
        }
        driven
            .check(&scene.inner.pack)
            .map_err(|e| PyValueError::new_err(format!("{}: {e}", scene.inner.name)))?;
        check_outputs(&[("record =", record.as_deref())], scene)?;
        let mut inst = Instance::driving(scene.inner.clone(), driven)
            .map_err(value_err)?
            .reading(scene.path.iter().cloned().collect());
        let strings: Vec<(Quantity, u32)> = inst
            .variables()
            .iter()
            .filter(|v| v.kind == Kind::String)
            .map(|v| (v.quantity, v.vr))
            .collect();
        for (q, vr) in strings {
            match q {
                Quantity::Engine => {
                    if let Some(e) = engine_choice(engine)? {
                        inst.set_string(vr, e.name()).map_err(value_err)?;
                    }
                }
                Quantity::RecordingPath => {
                    if let Some(p) = &record {
                        inst.set_string(vr, &p.to_string_lossy())
                            .map_err(value_err)?;
                    }
                }
                _ => {}
            }
        }
        inst.setup_experiment(0.0, stop_time).map_err(value_err)?;
        inst.enter_initialization().map_err(value_err)?;
        inst.exit_initialization().map_err(value_err)?;
        Ok(Stepper {
            inst: Mutex::new(inst),
        })
    }

    /// The time the run stands at, s.
    #[getter]
    fn time(&self) -> f64 {
        self.inst().time_s()
    }

    /// `(name, causality, unit, description)` of every variable (the FMU's).
    fn variables(&self) -> Vec<(String, String, String, String)> {
        self.inst()
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

    /// Sets the input `name` (e.g. "shaft.speed_rad_s") to `value`, held from now on; with
    /// `slope` (per s) and `curvature` (per s^2) as a first- or second-order hold.
    #[pyo3(signature = (name, value, slope=None, curvature=None))]
    fn set_input(
        &mut self,
        name: &str,
        value: f64,
        slope: Option<f64>,
        curvature: Option<f64>,
    ) -> PyResult<()> {
        let vr = self.variable(name, Kind::Real)?;
        let mut inst = self.inst();
        inst.set_real(vr, value).map_err(value_err)?;
        for (order, v) in [(1, slope), (2, curvature)] {
            if let Some(v) = v {
                inst.set_real_derivative(vr, order, v).map_err(value_err)?;
            }
        }
        Ok(())
    }

    /// Advances to `t` (s) with the GIL released; Ctrl-C stops it (the run then stands at
    /// an earlier time, everything before kept) and raises `KeyboardInterrupt`.
    fn advance_to(&mut self, py: Python<'_>, t: f64) -> PyResult<()> {
        let mut guard = self.inst();
        let now = guard.time_s();
        if !(t.is_finite() && t >= now) {
            return Err(PyValueError::new_err(format!(
                "advance_to({t}): expected a finite time at or after the run's time {now} s"
            )));
        }
        let stop = AtomicBool::new(false);
        let inst = &mut *guard;
        interruptible(py, &stop, || inst.advance_to(t, Some(&stop)))?
            .map(|_| ())
            .map_err(PyRuntimeError::new_err)
    }

    /// Every output's `(name, value)` now (the Integer ones as floats).
    fn outputs(&self) -> PyResult<Vec<(String, f64)>> {
        let inst = self.inst();
        inst.variables()
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| {
                let x = match v.kind {
                    Kind::Real => inst.get_real(v.vr),
                    _ => inst.get_integer(v.vr).map(f64::from),
                };
                x.map(|x| (v.name.clone(), x))
                    .map_err(PyRuntimeError::new_err)
            })
            .collect()
    }

    /// Saves the whole state (not while recording: a recording cannot be rewound).
    fn save(&self) -> PyResult<StepperState> {
        self.inst()
            .save()
            .map(|state| StepperState {
                state: Mutex::new(state),
            })
            .map_err(value_err)
    }

    /// Restores a state saved by `save`.
    fn restore(&mut self, state: &StepperState) -> PyResult<()> {
        let saved = state.state.lock().unwrap_or_else(|p| p.into_inner());
        self.inst().restore(&saved).map_err(value_err)
    }

    /// Ends the run (its recording finished) and returns its summary (`--summary-json`'s
    /// content, JSON text).
    fn finish(&mut self) -> PyResult<String> {
        let mut inst = self.inst();
        let warnings = inst.terminate().map_err(PyRuntimeError::new_err)?;
        let outcome = inst
            .outcome()
            .ok_or_else(|| PyRuntimeError::new_err("the run was never started"))?;
        if let Some(Err(e)) = &outcome.recording {
            return Err(PyRuntimeError::new_err(format!("the recording: {e}")));
        }
        let _ = warnings;
        let summary = outcome.summary().map_err(py_err)?;
        serde_json::to_string(&summary).map_err(|e| PyRuntimeError::new_err(e.to_string()))
    }
}
