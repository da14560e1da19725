//! A run of a scene, a pack or a network ([`Simulation::run`]), and what it gave: one
//! [`Outcome`], a pack's [`RunOutcome`] or a network's [`NetworkOutcome`], with one
//! [`Summary`] that serialises as either's own.

use crate::{
    Error, NetworkOutcome, NetworkSummary, Result, RunOutcome, RunRequest, RunSummary, Simulation,
};
use clutchpack_analysis::DiscCycles;
use clutchpack_record::RecordError;
use serde::Serialize;
use std::path::Path;

/// What a run of a scene gave ([`Simulation::run`]): a pack's outcome or a network's.
// a pack's outcome is the larger, and the common one: boxing it would cost every pack run
#[allow(clippy::large_enum_variant)]
pub enum Outcome {
    /// A pack scene's run.
    Pack(RunOutcome),
    /// A network scene's run (`[[bodies]]`).
    Network(NetworkOutcome),
}

/// A run's summary (what `--summary-json` writes): a pack's or a network's, serialised as
/// the summary itself (untagged: the JSON of either kind is its summary's own).
#[derive(Debug, Serialize)]
#[serde(untagged)]
pub enum Summary {
    /// A pack scene's summary.
    Pack(RunSummary),
    /// A network scene's summary.
    Network(NetworkSummary),
}

impl Outcome {
    /// The scene's name.
    pub fn scene(&self) -> &str {
        match self {
            Outcome::Pack(o) => &o.scene,
            Outcome::Network(o) => &o.summary.scene,
        }
    }

    /// The engine that ran (`reference` or `multibody`).
    pub fn engine(&self) -> &'static str {
        match self {
            Outcome::Pack(o) => o.engine,
            Outcome::Network(o) => o.summary.engine,
        }
    }

    /// The simulated time the run reached, s; a pack's engine failure as [`Error::Engine`]
    /// ([`RunOutcome::stats`]; a network's came back from [`Simulation::run`]).
    pub fn simulated_s(&self) -> Result<f64> {
        match self {
            Outcome::Pack(o) => Ok(o.stats()?.simulated_s),
            Outcome::Network(o) => Ok(o.summary.simulated_s),
        }
    }

    /// Whether the run stopped before its duration (a stop flag, or a pack's failed
    /// recording).
    pub fn stopped_early(&self) -> bool {
        match self {
            Outcome::Pack(o) => o.stopped_early(),
            Outcome::Network(o) => o.summary.stopped,
        }
    }

    /// What went wrong without stopping the run (a pack's; a network's problems come back
    /// from [`Simulation::run`]).
    pub fn warnings(&self) -> &[String] {
        match self {
            Outcome::Pack(o) => &o.warnings,
            Outcome::Network(_) => &[],
        }
    }

    /// The finished recording's path, or why a pack's could not be finished (a network's
    /// came back from [`Simulation::run`]); `None`: not asked.
    pub fn recording(&self) -> Option<std::result::Result<&Path, &RecordError>> {
        match self {
            Outcome::Pack(o) => o.recording.as_ref().map(|r| r.as_deref()),
            Outcome::Network(o) => o.recording.as_deref().map(Ok),
        }
    }

    /// Why a pack's impacts CSV could not be finished (a network's came back from
    /// [`Simulation::run`]).
    pub fn impacts_csv_error(&self) -> Option<&Error> {
        match self {
            Outcome::Pack(o) => o.impacts_csv.as_ref().and_then(|r| r.as_ref().err()),
            Outcome::Network(_) => None,
        }
    }

    /// The run's summary; a pack's engine failure is an error ([`RunOutcome::summary`]).
    pub fn summary(&self) -> Result<Summary> {
        Ok(match self {
            Outcome::Pack(o) => Summary::Pack(o.summary()?),
            Outcome::Network(o) => Summary::Network(o.summary.clone()),
        })
    }

    /// Every body's counted load cycles and spectra (`run --fatigue-json`, kept when
    /// [`RunRequest::keep_cycles`] asked for them): a pack's discs and plates, or every
    /// resolved pack's on a network ([`NetworkOutcome::cycles`]).
    pub fn cycles(&self) -> Vec<DiscCycles> {
        match self {
            Outcome::Pack(o) => o.cycles(),
            Outcome::Network(o) => o.cycles.clone(),
        }
    }

    /// A pack's outcome; a network's is bad input naming the scene.
    pub fn into_pack(self) -> Result<RunOutcome> {
        match self {
            Outcome::Pack(o) => Ok(o),
            Outcome::Network(o) => Err(Error::BadInput(format!(
                "{} is a network scene ([[bodies]]), not a pack",
                o.summary.scene
            ))),
        }
    }

    /// A network's outcome; a pack's is bad input naming the scene.
    pub fn into_network(self) -> Result<NetworkOutcome> {
        match self {
            Outcome::Network(o) => Ok(o),
            Outcome::Pack(o) => Err(crate::simulation::not_a_network(&o.scene)),
        }
    }
}

impl Simulation {
    /// Runs the scene, a pack or a network, for its `simulation.duration_s` as `request`
    /// asks. Outputs that cannot be created (the impacts CSV, the recording) are errors
    /// before any work; after that, whatever ends the run, every output is complete up to
    /// there. A pack's outcome holds an engine failure ([`RunOutcome::result`]); a network's
    /// is an [`Error::Engine`], its recording and impacts CSV finished first.
    pub fn run(&mut self, request: RunRequest<'_>) -> Result<Outcome> {
        crate::windows::check(request.windows_s, self.scene().simulation.duration_s)?;
        match self.network_engine() {
            Some(engine) => {
                crate::network::run(self.scene(), engine, request).map(Outcome::Network)
            }
            None => self.run_engine(request).map(Outcome::Pack),
        }
    }

    /// [`Simulation::run`] for a caller that takes pack scenes only: a network scene is
    /// refused before any work ([`Simulation::pack_only`]).
    pub fn run_pack(&mut self, request: RunRequest<'_>) -> Result<RunOutcome> {
        self.pack_only()?;
        self.run(request)?.into_pack()
    }
}
