//! # clutchpack_sdk: clutchpack as a library
//!
//! The one place that turns a validated scene into results: the command-line front end
//! (`clutchpack run`, `sweep`, `study`, `bench`), the FMU and the Python package are thin
//! callers of it. It owns the choice of engine, what a run keeps (the impacts' statistics,
//! the friction interfaces, the teeth's fatigue, the impacts CSV, the recording), the
//! summary of a run, ensembles and batches of runs, and the fatigue of a recording. It
//! prints nothing and never exits: problems are an [`Error`], bad input told from a failed
//! run by [`Error::is_bad_input`]. Reading a recording back: [`open_recording`] (the policy
//! for damaged files) and [`RecordedFatigue`]. Co-simulation (the FMU, Python's
//! `Simulation`): [`Session`], a run advanced call by call, and [`CoSimulation`], the same
//! as a table of named variables (parameters, inputs, outputs; module [`cosim`]).
//!
//! ```no_run
//! use clutchpack_sdk::{load_scene, RunRequest, Simulation};
//! let scene = load_scene(None, &[])?; // the paper's case, built in
//! let mut sim = Simulation::new(scene, None)?;
//! let outcome = sim.run_pack(RunRequest::default())?; // `run` takes a network too
//! let summary = outcome.summary()?;
//! println!("{}: largest + load {:.1} N", summary.scene, summary.discs[0].max_positive_n);
//! # Ok::<(), clutchpack_sdk::Error>(())
//! ```

mod batch;
mod collector;
pub mod cosim;
mod error;
mod fatigue;
pub mod fit;
mod network;
mod network_cosim;
mod network_keep;
mod outcome;
mod recording;
mod request;
mod run;
mod scene_file;
mod session;
pub mod shifts;
mod simulation;
mod study_run;
mod summary;
mod windows;

// The crates a front end needs types of, under one name (as ripgrep's `grep` facade does):
// the CLI, the FMU and the Python package depend on this crate alone.
pub use clutchpack_analysis as analysis;
pub use clutchpack_model as model;
pub use clutchpack_multibody as multibody;
pub use clutchpack_record as record;
pub use clutchpack_reference as reference;
pub use clutchpack_scene as scene;
pub use clutchpack_study as study;

pub use batch::{
    ensemble_fatigue, ensemble_member, run_case, run_cases, CaseRuns, MemberFatigue,
    MAX_BATCH_CASES,
};
/// A network run's sample (for figures of a network's history).
pub use clutchpack_model::network::NetworkSample;
/// The steppable engines' inputs and outputs (co-simulation).
pub use clutchpack_model::session::{Advance, Driven, Inputs, Snapshot};
pub use collector::{merge_peaks, RunCollector};
pub use cosim::{CoSimulation, SavedCoSimulation};
pub use error::{Error, Result};
pub use fatigue::{assess_fatigue, assess_histories, fatigue_params, RecordedFatigue};
pub use fit::{Fit, FitOptions, FitParam, FitRequest, FitResult, FitSignal};
pub use network::{
    multibody_step_s, BodySummary, CouplingSummary, EnergySummary, ModeChange, NetworkOutcome,
    NetworkRequest, NetworkSummary, PackBodySummary, MULTIBODY_NETWORK_STEP_S,
};
pub use network_cosim::{
    network_inputs, network_name_problems, network_outputs, NetworkSimulation, NetworkVariable,
    SavedNetworkSimulation,
};
pub use outcome::{Outcome, Summary};
pub use recording::open_recording;
pub use request::{RecordingRequest, RunRequest};
pub use run::RunOutcome;
pub use scene_file::{load_scene, DEFAULT_SCENE_NAME, DEFAULT_SCENE_TEXT};
pub use session::{Session, SessionRequest, SessionState};
pub use simulation::{PackEngine, Simulation};
pub use study_run::{merge_study, run_study_shard, MergedStudy, PART_FLUSH};
pub use summary::{friction_interfaces, run_info, BodyTemperature, RunSummary, ThermalSummary};
pub use windows::{BodyWindow, WindowRow};

/// The reference engine's integration schemes (for [`PackEngine::Reference`]).
pub use clutchpack_reference::Scheme;
/// Which engine runs a scene.
pub use clutchpack_scene::EngineChoice;
