//! The one error type of the sdk.

use clutchpack_model::{fmt_num, EngineError};
use clutchpack_record::RecordError;
use clutchpack_scene::SceneError;
use std::path::PathBuf;

/// What can go wrong turning a scene into results. [`Error::is_bad_input`] tells the input's
/// fault (a scene, a key, a value, a co-simulation call: the CLI's exit 2, Python's
/// `ValueError`) from a failure of the run or of the machine (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene (a file, an override, a key) is invalid; each problem names its key.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Other bad input: an engine that cannot run the pack, an ensemble size out of range.
    #[error("{0}")]
    BadInput(String),
    /// A co-simulation input (the FMU's, Python's `Simulation`'s, a network run's) set, or
    /// held with its derivatives, outside the bound of the scene key it stands for (a drive
    /// torque of 1e30 N m made the first 1 ms step run for minutes). Its numbers are written
    /// as every message writes them (`clutchpack_model::fmt_num`).
    #[error(
        "{name} = {} {unit}{when}: expected a value in [{}, {}] {unit}, the bound of the scene \
         key it stands for ({key})",
        fmt_num(*value),
        fmt_num(*lo),
        fmt_num(*hi)
    )]
    InputOutOfBound {
        /// The input's public name (`piston.pressure_pa`, `couplings.K2.normal_force_n`).
        name: String,
        /// The value asked, in `unit`.
        value: f64,
        /// The input's unit as the message writes it (`rad/s`, `N.m`, `N m`, `N`, `Pa`).
        unit: &'static str,
        /// The lowest value allowed, in `unit`.
        lo: f64,
        /// The highest value allowed, in `unit`.
        hi: f64,
        /// The scene key whose bound it is (`stack.pressure.pressure_pa`).
        key: &'static str,
        /// When, if the value is a held one (` at 0.1 s (held with its derivatives)`), else
        /// empty.
        when: String,
    },
    /// A call a co-simulated run does not take (in its stage, or on that variable): an
    /// output set, a fixed parameter set after the start, an unknown value reference or input
    /// name, an advance before the start, a state restored into another run. The caller's
    /// sequence of calls is at fault, not a value; the run stays as it was.
    #[error("{0}")]
    Call(String),
    /// The engine failed (diverged, the step collapsed); what ran before is in the outputs.
    #[error("{context}: {source}")]
    Engine {
        /// The scene and the engine.
        context: String,
        /// The engine's reason.
        #[source]
        source: EngineError,
    },
    /// A recording could not be created or finished.
    #[error(transparent)]
    Recording(#[from] RecordError),
    /// A file could not be written or read back.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A study's part or table could not be read or written.
    #[error("{0}")]
    Study(String),
    /// A study's merge found shards missing or unfinished (which ones: the merge's error).
    #[error(transparent)]
    StudyIncomplete(clutchpack_study::MergeError),
    /// The worker threads of a batch could not be started.
    #[error("starting the worker threads: {0}")]
    Threads(String),
}

impl Error {
    /// True when the input is at fault (a scene, an argument), not the run or the machine.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            Error::Scene(_) | Error::BadInput(_) | Error::InputOutOfBound { .. } | Error::Call(_)
        )
    }

    /// [`Error::Io`] for `path`.
    pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |source| Error::Io { path, source }
    }
}

/// The sdk's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;
