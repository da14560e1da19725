//! # clutchpack_scene
//!
//! TOML scene files -> validated, typed parameters ([`Scene`]), in two stages: `raw` mirrors
//! the file (unknown keys are errors), then validation checks every rule and reports every
//! problem at once with its key path, the bad value and the rule. `--set KEY=VALUE` overrides
//! any key by the same dotted path as in the file (array items by index: `discs[2].oil.film_thickness_m`).
//!
//! (Implementation in progress: see the module docs once written.)

use clutchpack_model::PackModel;
use serde::{Deserialize, Serialize};

/// Which engine runs a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EngineChoice {
    /// The reduced torsional engine (`clutchpack_reference`).
    Reference,
    /// The rapier3d multibody engine (`clutchpack_sim`).
    Multibody,
}

/// Run settings of a scene (`[simulation]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    /// Simulated duration in s (> 0). Key `simulation.duration_s` (required).
    pub duration_s: f64,
    /// Engine asked for by the scene, if any. Key `simulation.engine`.
    pub engine: Option<EngineChoice>,
    /// Rate at which samples are emitted, Hz (> 0). Key `simulation.record_rate_hz`, default 10000.
    pub record_rate_hz: f64,
    /// Relative error tolerance of the adaptive reference integrator (dimensionless, in
    /// [1e-14, 1e-3]). Key `simulation.tolerance`, default 1e-9.
    pub tolerance: f64,
    /// Largest step of the adaptive integrators in s (> 0). Key `simulation.max_step_s`,
    /// default 1e-4.
    pub max_step_s: f64,
}

/// A validated scene: everything an engine needs, in SI units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// Scene name (key `name`, default: the file stem).
    pub name: String,
    /// Free text (key `description`).
    pub description: String,
    /// The scene file's text as read (before `--set` overrides), for recordings.
    pub source_text: String,
    /// The `--set` overrides applied, as `KEY=VALUE` strings, in order.
    pub overrides: Vec<String>,
    /// Run settings.
    pub simulation: Simulation,
    /// The physical model.
    pub pack: PackModel,
}
