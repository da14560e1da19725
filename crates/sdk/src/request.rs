//! What a run of a scene, a pack or a network, keeps and writes besides its statistics
//! (`RunRequest`), and where and how it is recorded (`RecordingRequest`).

use clutchpack_record::{RecordOptions, Replace};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

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
    /// [`crate::RunOutcome::windows`]).
    pub windows_s: Option<f64>,
    /// Called at the engine's progress polls with the simulated time reached, s.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
}
