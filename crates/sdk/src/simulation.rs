//! The engine a scene runs on, chosen once, with the reason: a pack scene's engine built,
//! or a network scene's engine chosen (its run builds it, `network.rs`).

use crate::{Error, Result};
use clutchpack_model::{Engine, PackModel};
use clutchpack_reference::{ReferenceEngine, Scheme};
use clutchpack_scene::{EngineChoice, Scene, SchemeChoice};

/// A validated scene, a pack or a driveline network (`[[bodies]]`), and the engine that runs
/// it. The engine is the one asked for, else the scene's `simulation.engine`, else the
/// reference engine for a torsional pack or a network and the multibody engine for a pack
/// with per-tooth effects (`Scene::engine`); an engine that cannot run the scene is bad
/// input, refused here before any work. [`Simulation::run`] runs either kind; what only a
/// pack has (its engine, its bodies, a steppable [`crate::Session`]) refuses a network
/// ([`Simulation::pack_only`]).
pub struct Simulation {
    scene: Scene,
    engine: Built,
    line: String,
}

/// What [`Simulation::new`] made of the scene.
enum Built {
    /// A pack scene's engine.
    Pack(Box<dyn Engine + Send>),
    /// A network scene's engine, chosen (a network's run builds its stepper).
    Network(EngineChoice),
}

impl Simulation {
    /// The engine for `scene` (`asked`: an explicit choice, e.g. `--engine`).
    pub fn new(scene: Scene, asked: Option<EngineChoice>) -> Result<Simulation> {
        let choice = scene.engine(asked, &scene.name)?;
        let why = scene.engine_reason(asked);
        if let Some(net) = &scene.network {
            let line = format!(
                "engine: {} (a driveline network of {} bodies and {} couplings), {why}",
                choice.name(),
                net.bodies.len(),
                net.couplings.len()
            );
            return Ok(Simulation {
                scene,
                engine: Built::Network(choice),
                line,
            });
        }
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
            engine: Built::Pack(engine),
            line,
        })
    }

    /// Whether the scene is a driveline network (`[[bodies]]`).
    pub fn is_network(&self) -> bool {
        matches!(self.engine, Built::Network(_))
    }

    /// Refuses a network scene, for the callers that take pack scenes only (sweeps, studies,
    /// ensembles, a fit's impact statistics, benchmarks of packs, a pack's engine or
    /// session): bad input naming the scene and what takes a network, before any work.
    pub fn pack_only(&self) -> Result<()> {
        self.engine().map(|_| ())
    }

    /// Refuses a pack scene, for the callers that take network scenes only: bad input naming
    /// the scene, before any work.
    pub fn network_only(&self) -> Result<()> {
        match self.engine {
            Built::Pack(_) => Err(not_a_network(&self.scene.name)),
            Built::Network(_) => Ok(()),
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The engine's name (`reference` or `multibody`).
    pub fn engine_name(&self) -> &'static str {
        match &self.engine {
            Built::Pack(e) => e.name(),
            Built::Network(choice) => choice.name(),
        }
    }

    /// The network scene's engine (`None` for a pack scene).
    pub(crate) fn network_engine(&self) -> Option<EngineChoice> {
        match self.engine {
            Built::Pack(_) => None,
            Built::Network(choice) => Some(choice),
        }
    }

    /// One line saying which engine and scheme run and why, e.g. `engine: reference
    /// (multirate: ...), the default for a torsional pack (...)`.
    pub fn engine_line(&self) -> &str {
        &self.line
    }

    /// A pack's bodies whose teeth are loaded, in the engines' order: the friction discs,
    /// then the separator plates. A network scene is refused ([`Simulation::pack_only`]; its
    /// resolved packs' bodies are in its outcome).
    pub fn body_names(&self) -> Result<Vec<String>> {
        Ok(self.engine()?.disc_names())
    }

    /// A pack's engine (to start sessions from); a network scene is refused.
    pub(crate) fn engine(&self) -> Result<&(dyn Engine + Send)> {
        match &self.engine {
            Built::Pack(e) => Ok(e.as_ref()),
            Built::Network(_) => Err(self.not_a_pack()),
        }
    }

    /// A pack's engine itself (for callers that drive it with their own observer); a network
    /// scene is refused ([`Simulation::pack_only`]).
    pub fn engine_mut(&mut self) -> Result<&mut (dyn Engine + Send)> {
        let refused = self.not_a_pack();
        match &mut self.engine {
            Built::Pack(e) => Ok(e.as_mut()),
            Built::Network(_) => Err(refused),
        }
    }

    /// The refusal of a network scene by what takes packs only: the scene, and what takes a
    /// network.
    fn not_a_pack(&self) -> Error {
        Error::BadInput(format!(
            "{} is a network scene ([[bodies]]): `clutchpack run`, `check`, `fmu` and \
             Python's `run` and `Simulation` take it; sweeps and studies take pack scenes \
             only, for now",
            self.scene.name
        ))
    }
}

/// A pack scene where a network was expected: bad input naming the scene.
pub(crate) fn not_a_network(scene: &str) -> Error {
    Error::BadInput(format!(
        "{scene} is a pack scene, not a network ([[bodies]])"
    ))
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
