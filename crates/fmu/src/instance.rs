//! One FMU instance as plain Rust: FMI 2.0's co-simulation state machine (instantiated,
//! initialisation, stepping, terminated) and the host's communication points over
//! `clutchpack_sdk::CoSimulation` (the variable table, the inputs held, the outputs), which
//! Python's `Simulation` shares. The C functions (`ffi.rs`) only translate pointers and
//! statuses; every FMI rule and its message is here, testable without a host. Every refusal
//! is an [`FmiError`] (FMI's state machine, an argument, the resources, or the sdk's typed
//! `Error` as it comes), which the C functions log after their name and answer with
//! `fmi2Error`.

use clutchpack_sdk::cosim::{Stage, Variable};
use clutchpack_sdk::scene::Scene;
use clutchpack_sdk::{CoSimulation, RunOutcome};
use std::path::{Path, PathBuf};

/// A saved FMU state (`fmi2GetFMUstate`): the sdk's, which belongs to the run that saved it.
pub type SavedState = clutchpack_sdk::SavedCoSimulation;

/// Why an FMI call fails: each C function (`ffi.rs`) logs it after its own name through the
/// host's logger and answers `fmi2Error`. Every message names the argument, variable or file
/// and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum FmiError {
    /// The sdk's co-simulation refused the call (an input past its bound, an output set, an
    /// unknown value reference, a state of another run) or its run failed (the engine's
    /// reason; the instance is then [`Phase::Failed`]).
    #[error(transparent)]
    Sdk(#[from] clutchpack_sdk::Error),
    /// A call FMI's state machine does not allow in the instance's phase
    /// (`fmi2DoStep` before `fmi2ExitInitializationMode`, ...).
    #[error("{0}")]
    Phase(String),
    /// An argument out of what the FMU takes: a time, a step size, the type of FMU, a null
    /// pointer, a string that is not UTF-8, a resource location that is not a `file:` URI.
    #[error("{0}")]
    Argument(String),
    /// A file of the FMU's resources could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The FMU's resources are not this FMU's (another build's GUID, a scene changed since
    /// the build, or not a scene).
    #[error("{0}")]
    Resources(String),
    /// What this FMU does not provide (serialized states, directional derivatives, output
    /// derivatives, asynchronous steps), as its model description says.
    #[error("{0}")]
    Unsupported(&'static str),
}

/// What an FMI call gives: its value, or why not.
pub type FmiResult<T> = Result<T, FmiError>;

/// Where an instance is in FMI's state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After `fmi2Instantiate` (or `fmi2Reset`): parameters and inputs may be set.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// Stepping (`fmi2DoStep`).
    Stepping,
    /// After `fmi2Terminate`: the final outputs may be read.
    Terminated,
    /// An engine failure or a bad call that leaves the run unusable: only reading,
    /// terminating, resetting and freeing.
    Failed,
}

/// One FMU instance.
pub struct Instance {
    co: CoSimulation,
    /// Whether `fmi2EnterInitializationMode` was called (before the run starts).
    initializing: bool,
    stop_time_s: Option<f64>,
}

/// The files of the FMU the host extracted, whose resources are in `resources`: its scene,
/// GUID, model description, and its binaries (the shared library the host has loaded: a
/// recording written over it would make the next instance fail to load). No output of an
/// instance may name any of them.
pub fn own_files(resources: &std::path::Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = ["scene.json", "scene.toml", "guid.txt"]
        .iter()
        .map(|f| resources.join(f))
        .collect();
    if let Some(root) = resources.parent() {
        files.push(root.join("modelDescription.xml"));
        // binaries/<platform>/<model identifier>.<so, dll, dylib>: one level of folders
        let entries = |dir: &std::path::Path| -> Vec<PathBuf> {
            std::fs::read_dir(dir)
                .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
                .unwrap_or_default()
        };
        for platform in entries(&root.join("binaries")) {
            files.extend(entries(&platform).into_iter().filter(|p| p.is_file()));
        }
    }
    files
}

/// Reads the scene an FMU carries: `resources/scene.json` (the validated scene, written by
/// `clutchpack fmu`), checking `resources/guid.txt` against the host's GUID.
pub fn load_resources(resources: &Path, guid: &str) -> FmiResult<Scene> {
    let read = |name: &str| {
        let path = resources.join(name);
        std::fs::read_to_string(&path).map_err(|source| FmiError::Io { path, source })
    };
    let own = read("guid.txt")?;
    if own.trim() != guid {
        return Err(FmiError::Resources(format!(
            "the GUID {guid:?} from the model description is not this FMU's ({:?}): the \
             model description and the resources come from different builds",
            own.trim()
        )));
    }
    let text = read("scene.json")?;
    // the scene was validated when the FMU was built, and the GUID is a hash of its text:
    // a scene edited since (a record rate of 1e300 Hz, ...) is refused, never run unchecked
    if crate::package::guid(&text) != own.trim() {
        return Err(FmiError::Resources(format!(
            "{}: changed since the FMU was built (it does not hash to the FMU's GUID); \
             build the FMU again from the scene file with `clutchpack fmu`, which checks it",
            resources.join("scene.json").display()
        )));
    }
    serde_json::from_str(&text).map_err(|e| {
        FmiError::Resources(format!(
            "{}: not a scene written by clutchpack fmu: {e}",
            resources.join("scene.json").display()
        ))
    })
}

impl Instance {
    /// An instance of `scene` (engine: the scene's choice, as `clutchpack run` makes it)
    /// driving every input the pack has, as an FMU does.
    pub fn new(scene: Scene) -> FmiResult<Instance> {
        Ok(Instance {
            co: CoSimulation::new(scene)?,
            initializing: false,
            stop_time_s: None,
        })
    }

    /// The files the run reads (the FMU's resources), which no output may name.
    pub fn reading(mut self, inputs: Vec<PathBuf>) -> Instance {
        self.co = self.co.reading(inputs);
        self
    }

    /// Back to the state after instantiation, every variable at its start value.
    pub fn reset(&mut self) {
        self.co.reset();
        self.initializing = false;
        self.stop_time_s = None;
    }

    /// Where the instance is.
    pub fn phase(&self) -> Phase {
        match self.co.stage() {
            Stage::Setup if self.initializing => Phase::Initialization,
            Stage::Setup => Phase::Instantiated,
            Stage::Running => Phase::Stepping,
            Stage::Failed => Phase::Failed,
            Stage::Ended => Phase::Terminated,
        }
    }

    /// The variables.
    pub fn variables(&self) -> &[Variable] {
        self.co.variables()
    }

    /// `fmi2SetupExperiment`: the run starts at t = 0; a stop time, if given, is where the
    /// steps land rather than pass.
    pub fn setup_experiment(&mut self, start_s: f64, stop_s: Option<f64>) -> FmiResult<()> {
        if self.phase() != Phase::Instantiated {
            return Err(FmiError::Phase(
                "fmi2SetupExperiment is allowed only after instantiation".into(),
            ));
        }
        if start_s != 0.0 {
            return Err(FmiError::Argument(format!(
                "startTime = {start_s} s: a pack's run starts at t = 0 (its initial state is \
                 the scene's)"
            )));
        }
        if let Some(stop) = stop_s {
            if !(stop.is_finite() && stop > 0.0) {
                return Err(FmiError::Argument(format!(
                    "stopTime = {stop} s: expected a positive time"
                )));
            }
        }
        self.stop_time_s = stop_s;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> FmiResult<()> {
        if self.phase() != Phase::Instantiated {
            return Err(FmiError::Phase(
                "fmi2EnterInitializationMode is allowed only after instantiation".into(),
            ));
        }
        self.initializing = true;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: starts the run with the parameters and inputs set.
    pub fn exit_initialization(&mut self) -> FmiResult<()> {
        if self.phase() != Phase::Initialization {
            return Err(FmiError::Phase(
                "fmi2ExitInitializationMode is allowed only in initialization".into(),
            ));
        }
        self.co.start(self.stop_time_s)?;
        self.initializing = false;
        Ok(())
    }

    /// `fmi2SetReal` of one variable.
    pub fn set_real(&mut self, vr: u32, value: f64) -> FmiResult<()> {
        Ok(self.co.set_real(vr, value)?)
    }

    /// `fmi2SetRealInputDerivatives` of one input (orders 1 and 2 for the shaft's speed, 1
    /// for its drive torque).
    pub fn set_real_derivative(&mut self, vr: u32, order: i32, value: f64) -> FmiResult<()> {
        Ok(self.co.set_real_derivative(vr, order, value)?)
    }

    /// `fmi2SetString` of one variable.
    pub fn set_string(&mut self, vr: u32, value: &str) -> FmiResult<()> {
        Ok(self.co.set_string(vr, value)?)
    }

    /// `fmi2GetString` of one variable.
    pub fn get_string(&self, vr: u32) -> FmiResult<&str> {
        Ok(self.co.get_string(vr)?)
    }

    /// `fmi2GetInteger` of one variable (the impacts so far, the last impact's body).
    pub fn get_integer(&self, vr: u32) -> FmiResult<i32> {
        Ok(self.co.get_integer(vr)?)
    }

    /// `fmi2GetReal` of one variable.
    pub fn get_real(&self, vr: u32) -> FmiResult<f64> {
        Ok(self.co.get_real(vr)?)
    }

    /// `fmi2DoStep`: holds the inputs from `t_s` and advances to `t_s + h_s`.
    pub fn do_step(&mut self, t_s: f64, h_s: f64) -> FmiResult<()> {
        if self.phase() != Phase::Stepping {
            return Err(FmiError::Phase(format!(
                "fmi2DoStep in {:?}: allowed only after fmi2ExitInitializationMode",
                self.phase()
            )));
        }
        let limit = self.co.duration_limit_s();
        let now = self.co.time_s();
        if !t_s.is_finite() {
            return Err(FmiError::Argument(format!(
                "currentCommunicationPoint = {t_s} s: expected a finite time (the FMU stands \
                 at {now} s)"
            )));
        }
        if (t_s - now).abs() > 1e-9 * now.max(1e-3) {
            return Err(FmiError::Argument(format!(
                "currentCommunicationPoint = {t_s} s, but the FMU stands at {now} s"
            )));
        }
        let end = t_s + h_s;
        if !(h_s > 0.0 && end.is_finite()) {
            return Err(FmiError::Argument(format!(
                "communicationStepSize = {h_s} s: expected > 0"
            )));
        }
        if end > limit * (1.0 + 1e-12) {
            return Err(FmiError::Argument(format!(
                "a step to {end} s passes duration_limit_s = {limit} s (set the parameter to \
                 run longer)"
            )));
        }
        self.co.advance_to(end.max(now), None)?;
        Ok(())
    }

    /// The time the run stands at, s (after `fmi2Terminate`: where it ended).
    pub fn time_s(&self) -> f64 {
        self.co.time_s()
    }

    /// `fmi2Terminate`: finishes the run (its recording too); the final outputs stay
    /// readable. Warnings of the finish (a recording's summary) come back as text.
    pub fn terminate(&mut self) -> Vec<String> {
        self.initializing = false;
        self.co.finish()
    }

    /// The finished run, after [`Instance::terminate`].
    pub fn outcome(&self) -> Option<&RunOutcome> {
        self.co.outcome()
    }

    /// `fmi2GetFMUstate`.
    pub fn save(&self) -> FmiResult<SavedState> {
        if self.phase() != Phase::Stepping {
            return Err(FmiError::Phase(
                "fmi2GetFMUstate is supported while stepping (after initialization)".into(),
            ));
        }
        Ok(self.co.save()?)
    }

    /// `fmi2SetFMUstate`: only a state this run saved (never another instance's, another
    /// scene's, or one from before a reset; a recorded run saves none, so it is never
    /// rewound).
    pub fn restore(&mut self, state: &SavedState) -> FmiResult<()> {
        Ok(self.co.restore(state)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_sdk::Error;

    fn instance() -> Instance {
        let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/hu-table2.toml");
        Instance::new(clutchpack_sdk::scene::load(&file, &[]).unwrap()).unwrap()
    }

    /// Each misuse comes back as its kind of [`FmiError`] (what `ffi.rs` logs after the
    /// function's name): FMI's state machine, an argument, or the sdk's typed refusal, with
    /// the message a host's log showed when these errors were strings.
    #[test]
    fn fmi_errors_are_typed_and_keep_their_messages() {
        let mut i = instance();
        let e = i.do_step(0.0, 1e-3).unwrap_err();
        assert!(matches!(e, FmiError::Phase(_)), "{e:?}");
        assert_eq!(
            e.to_string(),
            "fmi2DoStep in Instantiated: allowed only after fmi2ExitInitializationMode"
        );
        let e = i.setup_experiment(1.0, None).unwrap_err();
        assert!(matches!(e, FmiError::Argument(_)), "{e:?}");
        assert!(e.to_string().starts_with("startTime = 1 s"), "{e}");
        let speed = i
            .variables()
            .iter()
            .find(|v| v.name == "shaft.speed_rad_s")
            .unwrap()
            .vr;
        let e = i.set_real(speed, 1e9).unwrap_err();
        assert!(
            matches!(e, FmiError::Sdk(Error::InputOutOfBound { value, .. }) if value == 1e9),
            "{e:?}"
        );
        assert!(
            e.to_string().starts_with(
                "shaft.speed_rad_s = 1e9 rad/s: expected a value in [-100000, 100000] rad/s"
            ),
            "{e}"
        );
        let e = i.get_real(u32::MAX).unwrap_err();
        assert!(matches!(e, FmiError::Sdk(Error::Call(_))), "{e:?}");
        assert_eq!(
            e.to_string(),
            format!("no Real variable has the value reference {}", u32::MAX)
        );
        let e = load_resources(Path::new("/nonexistent-fmu/resources"), "g").unwrap_err();
        assert!(matches!(e, FmiError::Io { .. }), "{e:?}");
        assert!(
            e.to_string()
                .contains("/nonexistent-fmu/resources/guid.txt"),
            "{e}"
        );
    }
}
