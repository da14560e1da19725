//! The one error type of the sdk.

use clutchpack_model::EngineError;
use clutchpack_record::RecordError;
use clutchpack_scene::SceneError;
use std::path::PathBuf;

/// What can go wrong turning a scene into results. [`Error::is_bad_input`] tells the input's
/// fault (a scene, a key, a value: the CLI's exit 2, Python's `ValueError`) from a failure
/// of the run or of the machine (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene (a file, an override, a key) is invalid; each problem names its key.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// Other bad input: an engine that cannot run the pack, an ensemble size out of range.
    #[error("{0}")]
    BadInput(String),
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
        matches!(self, Error::Scene(_) | Error::BadInput(_))
    }

    /// [`Error::Io`] for `path`.
    pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |source| Error::Io { path, source }
    }
}

/// The sdk's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;
