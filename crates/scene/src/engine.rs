//! Which engine runs a scene, and whether it can: the engine asked for on the command line,
//! else by the scene (`simulation.engine`), else the reference engine for a torsional pack
//! and the multibody engine otherwise. What the reference engine cannot run is
//! [`PackModel::non_torsional_parts`]; a choice that cannot run the scene is bad input, found
//! before anything runs (`clutchpack check --engine`, `clutchpack run`), each part at its key.
//!
//! [`PackModel::non_torsional_parts`]: clutchpack_model::PackModel::non_torsional_parts

use crate::schema::fmt_num;
use crate::{EngineChoice, Problem, Scene, SceneError};
use clutchpack_model::NonTorsional;

impl EngineChoice {
    /// Every engine, in the order their names are listed in messages.
    pub const ALL: [EngineChoice; 2] = [EngineChoice::Reference, EngineChoice::Multibody];

    /// The engine named `name` (as in scenes, study files and on the command line).
    pub fn from_name(name: &str) -> Option<EngineChoice> {
        EngineChoice::ALL.into_iter().find(|e| e.name() == name)
    }

    /// Every engine's name, in [`EngineChoice::ALL`]'s order.
    pub fn names() -> [&'static str; 2] {
        EngineChoice::ALL.map(EngineChoice::name)
    }

    /// The engine's name as written in scenes and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EngineChoice::Reference => "reference",
            EngineChoice::Multibody => "multibody",
        }
    }
}

impl std::str::FromStr for EngineChoice {
    type Err = String;
    /// [`EngineChoice::from_name`], with a message listing the names.
    fn from_str(s: &str) -> Result<EngineChoice, String> {
        EngineChoice::from_name(s).ok_or_else(|| {
            format!(
                "{s:?} is not an engine: expected one of {}",
                EngineChoice::names().join(", ")
            )
        })
    }
}

impl Scene {
    /// The engine that runs this scene: `asked` (the command line), else the scene's
    /// `simulation.engine`, else the reference engine for a torsional pack and the multibody
    /// engine otherwise. An engine that cannot run the scene is an error naming every part it
    /// cannot run at its key, with `origin` (the scene file as named in messages).
    pub fn engine(
        &self,
        asked: Option<EngineChoice>,
        origin: &str,
    ) -> Result<EngineChoice, SceneError> {
        let parts = self.pack.non_torsional_parts();
        let (choice, why) = match (asked, self.simulation.engine) {
            (Some(e), _) => (e, format!("--engine {}", e.name())),
            (None, Some(e)) => (e, format!("simulation.engine = \"{}\"", e.name())),
            (None, None) if parts.is_empty() => return Ok(EngineChoice::Reference),
            (None, None) => return Ok(EngineChoice::Multibody),
        };
        if choice == EngineChoice::Multibody {
            return Ok(choice);
        }
        if parts.is_empty() {
            return Ok(choice);
        }
        let problems = parts
            .iter()
            .map(|part| self.reference_problem(*part, &why))
            .collect();
        Err(SceneError::Invalid {
            origin: origin.to_string(),
            problems,
        })
    }

    /// Why [`Scene::engine`] chooses what it does, for `run`'s engine line: "asked by
    /// --engine", "chosen by the scene (simulation.engine)", or the default's reason (a
    /// network's, a torsional pack's or a pack's with per-tooth effects).
    pub fn engine_reason(&self, asked: Option<EngineChoice>) -> &'static str {
        match (asked, self.simulation.engine) {
            (Some(_), _) => "asked by --engine",
            (None, Some(_)) => "chosen by the scene (simulation.engine)",
            (None, None) if self.network.is_some() => "the default for a driveline network",
            (None, None) if self.pack.non_torsional_parts().is_empty() => {
                "the default for a torsional pack (concentric bodies: discs, plates, drum, stack)"
            }
            (None, None) => "the only engine for per-tooth effects",
        }
    }

    /// `part` as a problem at its key: the reference engine (chosen by `why`) cannot run it.
    fn reference_problem(&self, part: NonTorsional, why: &str) -> Problem {
        let disc = |i: usize, k: &str| format!("discs[{i}].{k}");
        let per_tooth = format!(
            "the reference engine (chosen by {why}) runs concentric discs with identical \
             teeth only (one rotational degree of freedom per disc): use the multibody engine"
        );
        match part {
            NonTorsional::RadialFloat(i) => {
                Problem::new(disc(i, "radial_float"), Some("true".into()), per_tooth)
            }
            NonTorsional::InitialOffset(i) => {
                let e = self.pack.discs[i].initial_offset_m;
                let v = format!("[{}, {}]", fmt_num(e[0]), fmt_num(e[1]));
                Problem::new(disc(i, "initial_offset_m"), Some(v), per_tooth)
            }
            NonTorsional::SpacingErrors(i) => {
                let errors = &self.pack.discs[i].tooth_spacing_errors_m;
                let worst = errors.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let v = format!("[...max |e| = {}]", fmt_num(worst));
                Problem::new(disc(i, "tooth_spacing_errors_m"), Some(v), per_tooth)
            }
            NonTorsional::PlatePerTooth(j) => Problem::new(format!("plates[{j}]"), None, per_tooth),
        }
    }
}
