//! The engine a scene runs on, chosen once, with the reason.

use crate::{Error, Result};
use clutchpack_model::{Engine, PackModel};
use clutchpack_reference::{ReferenceEngine, Scheme};
use clutchpack_scene::{EngineChoice, Scene, SchemeChoice};

/// A validated scene and the engine that runs it. The engine is the one asked for, else the
/// scene's `simulation.engine`, else the reference engine for a torsional pack and the
/// multibody engine for one with per-tooth effects (`Scene::engine`); an engine that cannot
/// run the scene is bad input, refused here before any work.
pub struct Simulation {
    scene: Scene,
    engine: Box<dyn Engine + Send>,
    line: String,
}

impl Simulation {
    /// The engine for `scene` (`asked`: an explicit choice, e.g. `--engine`).
    pub fn new(scene: Scene, asked: Option<EngineChoice>) -> Result<Simulation> {
        if scene.network.is_some() {
            return Err(crate::Error::BadInput(format!(
                "{} is a network scene ([[bodies]]): `clutchpack run`, `check`, `fmu` and \
                 Python's `run` and `Simulation` take it; sweeps and studies take pack scenes \
                 only, for now",
                scene.name
            )));
        }
        let choice = scene.engine(asked, &scene.name)?;
        let why = scene.engine_reason(asked);
        let sim = &scene.simulation;
        let (engine, line): (Box<dyn Engine + Send>, String) = match choice {
            EngineChoice::Reference => {
                let scheme = match sim.scheme {
                    SchemeChoice::Shared => Scheme::Monolithic,
                    SchemeChoice::Auto | SchemeChoice::Multirate => Scheme::Multirate,
                };
                let engine = ReferenceEngine::new(
                    scene.pack.clone(),
                    clutchpack_reference::ReferenceOptions {
                        tolerance: sim.tolerance,
                        max_step_s: sim.max_step_s,
                        record_rate_hz: sim.record_rate_hz,
                    },
                )
                .with_scheme(scheme)
                .with_thermal(scene.thermal.clone());
                if sim.scheme == SchemeChoice::Multirate && engine.is_whole() {
                    return Err(Error::BadInput(format!(
                        "{}: simulation.scheme = \"multirate\": the reference engine runs a \
                         whole pack (plates, a drum or a stack) in one step sequence; use \
                         \"auto\" or \"shared\"",
                        scene.name
                    )));
                }
                let line = format!("engine: reference ({}), {why}", engine.describe());
                (Box::new(engine), line)
            }
            EngineChoice::Multibody => {
                let options = clutchpack_multibody::MultibodyOptions {
                    scheme: match sim.scheme {
                        SchemeChoice::Auto => clutchpack_multibody::Scheme::Auto,
                        SchemeChoice::Shared => clutchpack_multibody::Scheme::Shared,
                        SchemeChoice::Multirate => clutchpack_multibody::Scheme::Multirate,
                    },
                    ..clutchpack_multibody::MultibodyOptions::with_settings(
                        sim.record_rate_hz,
                        sim.max_step_s,
                        sim.record_per_tooth,
                    )
                };
                let engine =
                    clutchpack_multibody::MultibodyEngine::new(scene.pack.clone(), options)
                        .map_err(|e| Error::BadInput(format!("{}: {e}", scene.name)))?
                        .with_thermal(scene.thermal.clone());
                let line = format!("engine: multibody ({}), {why}", engine.scheme_explanation());
                (Box::new(engine), line)
            }
        };
        Ok(Simulation {
            scene,
            engine,
            line,
        })
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The engine's name (`reference` or `multibody`).
    pub fn engine_name(&self) -> &'static str {
        self.engine.name()
    }

    /// One line saying which engine and scheme run and why, e.g. `engine: reference
    /// (multirate: ...), the default for a torsional pack (...)`.
    pub fn engine_line(&self) -> &str {
        &self.line
    }

    /// The bodies whose teeth are loaded, in the engines' order: the friction discs, then the
    /// separator plates.
    pub fn body_names(&self) -> Vec<String> {
        self.engine.disc_names()
    }

    /// The engine (to start sessions from).
    pub(crate) fn engine(&self) -> &(dyn Engine + Send) {
        self.engine.as_ref()
    }

    /// The engine itself (for callers that drive it with their own observer).
    pub fn engine_mut(&mut self) -> &mut (dyn Engine + Send) {
        self.engine.as_mut()
    }
}

/// An engine configuration for a pack built in code rather than read from a scene (the
/// benchmarks' packs), with the engines' default settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PackEngine {
    /// The reference engine with `scheme`, the independent discs on threads when `parallel`.
    Reference {
        /// Monolithic or multirate.
        scheme: Scheme,
        /// Independent discs on worker threads.
        parallel: bool,
    },
    /// The multibody engine, recording at `record_rate_hz` (Hz).
    Multibody {
        /// Sample rate, Hz.
        record_rate_hz: f64,
    },
}

impl PackEngine {
    /// The engine for `pack`; a pack the multibody engine cannot build is bad input.
    pub fn build(self, pack: PackModel) -> Result<Box<dyn Engine + Send>> {
        Ok(match self {
            PackEngine::Reference { scheme, parallel } => Box::new(
                ReferenceEngine::new(pack, clutchpack_reference::ReferenceOptions::default())
                    .with_scheme(scheme)
                    .with_parallel(parallel),
            ),
            PackEngine::Multibody { record_rate_hz } => Box::new(
                clutchpack_multibody::MultibodyEngine::new(
                    pack,
                    clutchpack_multibody::MultibodyOptions::default()
                        .with_record_rate(record_rate_hz),
                )
                .map_err(|e| Error::BadInput(e.to_string()))?,
            ),
        })
    }
}
