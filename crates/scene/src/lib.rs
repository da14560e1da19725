//! # clutchpack_scene
//!
//! TOML scene files -> validated, typed parameters ([`Scene`]) for the engines.
//!
//! What this crate does:
//! - reads a scene file ([`load`]) or text ([`parse`]), applies `--set KEY=VALUE` overrides
//!   ([`Override`]), and checks every value and every rule between values;
//! - reports **every** problem at once ([`SceneError`], [`Problem`]), each as
//!   `<file>: <key path> = <bad value>: <rule>`;
//! - reads the CSV tables of tabulated drives;
//! - documents every key for `--help` ([`keys_doc`]).
//!
//! What it does not do: run anything, choose an engine when the scene does not, or decide
//! physics (the laws live in `clutchpack_model`).
//!
//! # The file format
//! Keys are SI with a unit suffix; angles are in degrees only in keys ending `_deg` (converted
//! to rad here), everything else is SI as named. Every number must be finite (TOML's `nan`
//! and `inf` are rejected); an integer is accepted wherever a number is expected.
//!
//! ```toml
//! name = "hu-table2"            # default: the file name without extension
//! description = "Hu et al. Table 2"
//!
//! [simulation]
//! duration_s = 0.3              # required
//! engine = "reference"          # optional: "reference" | "multibody"
//! record_rate_hz = 10000.0      # optional (every optional key has a default: keys_doc)
//! tolerance = 1e-9              # optional
//! max_step_s = 1e-4             # optional
//! record_per_tooth = false     # optional
//! record_contact_samples = true # optional
//!
//! [shaft]
//! mode = "prescribed"           # default; or "inertial" with inertia_kg_m2 (required),
//!                               # damping_n_m_s_rad (default 0)
//!
//! [drive]
//! kind = "sine"                 # "sine" | "harmonics" | "speed_table" | "torque_table"
//! omega0_rad_s = 200.0
//! amplitude_rad_s = 4.378
//! frequency_hz = 104.0
//! phase_deg = 0.0               # default 0
//!
//! [defaults]                    # disc parameters shared by all discs
//! inertia_kg_m2 = 0.156
//! drag_n_m_s_rad = 0.01
//! radial_float = false          # default false: radial translations locked (multibody only)
//! tooth_spacing_errors_m = []   # m at the pitch circle, one per tooth or empty (default)
//! initial_offset_m = [0.0, 0.0] # m, the centre's offset from the axis at t = 0 (default)
//! [defaults.spline]
//! teeth = 154
//! pitch_radius_m = 0.231
//! pressure_angle_deg = 20.0
//! backlash_m = 0.75e-3
//! [defaults.contact]
//! law = "paper"
//! modulus_pa = 210e9
//! curvature_radius_m = 1.75e-3
//! loss_coefficient_s_m = 0.8
//! [defaults.oil]
//! film_thickness_m = 25e-6
//! viscosity_pa_s = 289.1
//! leakage_coefficient = 0.421
//! width_m = 3e-3
//! length_m = 3e-3
//!
//! [[discs]]                     # at least one; any [defaults] key may be overridden
//! name = "disc-1"
//! [[discs]]
//! name = "disc-2"
//! [discs.oil]
//! film_thickness_m = 75e-6
//! ```
//!
//! A whole pack (MODEL.md section 5; both engines) adds separator plates, an output drum and
//! the clamped stack:
//!
//! ```toml
//! [plate_defaults]              # the same keys as [defaults], for the plates; plates do not
//! inertia_kg_m2 = 0.12          # inherit [defaults] (their spline is the carrier's)
//! [[plates]]                    # N + 1 plates for N discs with a [stack]: plate, disc, ...
//! name = "plate-1"
//!
//! [drum]                        # a clutch: the plates sit on the drum (else on the housing)
//! inertia_kg_m2 = 0.5
//! load_torque_n_m = -20.0       # default 0; drag_n_m_s_rad, initial_speed_rad_s default 0
//!
//! [stack]
//! face_inner_radius_m = 0.235   # the friction faces' annulus
//! face_outer_radius_m = 0.290
//! piston_area_m2 = 0.012
//! return_spring_n = 800.0       # default 0
//! spline_friction_coefficient = 0.1   # default 0
//! [stack.friction]              # kind = "stribeck" (default): static_mu, kinetic_mu,
//! static_mu = 0.10              #   stribeck_speed_m_s, viscous_slope_s_m; or kind = "table"
//! kinetic_mu = 0.13             #   with arrays slip_m_s (from 0) and mu
//! [stack.pressure]              # kind = "constant" (pressure_pa) | "ramp" (start_s, rise_s,
//! kind = "ramp"                 #   pressure_pa) | "table" (arrays times_s, values_pa)
//! rise_s = 0.02
//! pressure_pa = 8e5
//! [stack.open_gap]              # optional: viscous drag across the gaps of an open pack
//! viscosity_pa_s = 0.02
//! gap_m = 0.1e-3
//! ```
//!
//! Drives: `sine` is Hu et al. eq (3) with a phase, mapped to one harmonic; `harmonics` takes
//! `omega0_rad_s` and one `[[drive.harmonics]]` table per term (`amplitude_rad_s`,
//! `frequency_hz`, `phase_deg`); `speed_table` and `torque_table` take `file`, a CSV file
//! (relative to the scene file's folder) with a header row and columns `time_s` and
//! `speed_rad_s` or `torque_n_m`. A torque table drives an inertial shaft only and needs
//! `shaft.initial_speed_rad_s`. [`keys_doc`] lists every key with its unit, rule and default.
//!
//! Disc parameters resolve as: the disc's own value, else `[defaults]`, else the built-in
//! default, else a "missing" problem at the disc's key path (`discs[1].spline.teeth`). The oil
//! parameters (`viscosity_pa_s`, `leakage_coefficient`, `width_m`, `length_m`) are required
//! only when the film carries load (`film_thickness_m > 0` and `law` not `"dry"`); otherwise
//! absent ones are 0. With an oil law the film must be thinner than half the free play along
//! the line of action (`h_o < g0 Rb`), and every disc must start inside the free play
//! (`|phi0| Rb < g0 Rb - h_o`, `h_o` taken as 0 for the dry law); with spacing errors or an
//! offset every tooth must (`|phi0| Rb + max|e_k| cos(alpha) + |offset| < g0 Rb - h_o`).
//! `tooth_spacing_errors_m` holds one number per tooth (`spline.teeth` of them) or none.
//! Radial float, offsets and spacing errors are per-tooth effects (MODEL.md section 5): only
//! the multibody engine runs them ([`clutchpack_model::PackModel::is_torsional`]).
//!
//! # Overrides
//! `--set KEY=VALUE` overrides any key by its dotted path, array items by index from 0:
//! `--set discs[2].oil.film_thickness_m=50e-6`. VALUE is TOML (`50e-6`, `"x"`, `{ a = 1 }`),
//! or a string if it is not valid TOML (`--set drive.kind=sine`). Overrides apply to the
//! parsed document in order, before validation; a key outside the schema, or an index past the
//! end of an array, is a problem that names the key and says it came from `--set`.
//!
//! # Errors
//! [`SceneError::Invalid`] displays one problem per line:
//! ```text
//! scenes/x.toml: discs[2].inertia_kg_m2 = -0.1: must be > 0
//! scenes/x.toml: discs[1].spline.teeth: missing (required; set it in [discs.spline] or [defaults.spline])
//! scenes/x.toml: discs[0].oil.thicknes_m: unknown key (expected one of: film_thickness_m, ...)
//! scenes/x.toml: line 3 column 14: <TOML syntax message>
//! ```
//!
//! # Architecture
//! Each key is defined once, in `keys` (its table, name, unit, kind and range rule, default
//! and meaning); that one definition makes the raw serde struct of its table, drives its
//! check in the validation, the "expected one of" lists, the `--set` key check,
//! [`keys_doc`] (`clutchpack check --keys`) and [`keys_markdown`] (docs/scene-keys.md's table). Two
//! stages: the raw structs mirror the file (tables typed, values kept as written; unknown keys
//! collected with `serde_ignored`), then `validate` (one module per section: simulation,
//! drive and shaft, bodies, stack and drum, thermal) converts them to the typed model, collecting
//! every problem. [`Scene::engine`] says which engine runs a scene, refusing a choice that
//! cannot run it.

#![warn(missing_docs)]

mod catalog;
mod csv;
mod engine;
mod error;
mod keys;
mod overrides;
mod raw;
mod schema;
mod validate;

pub use catalog::{keys_doc, keys_markdown};
pub use csv::{parse_columns, read_columns, Columns};
pub use error::{Problem, SceneError};
pub use keys::{MAX_NORMAL_FORCE_N, MAX_PRESSURE_PA, MAX_SPEED_RAD_S, MAX_TORQUE_N_M};
pub use overrides::{
    apply_to_text, expand_wildcards, number_in_text, numeric_key, NumericKey, Override,
    OverrideError,
};

use std::path::Path;
use toml::{Table, Value};

use clutchpack_model::PackModel;
use serde::{Deserialize, Serialize};

/// Which engine runs a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EngineChoice {
    /// The reduced torsional engine (`clutchpack_reference`).
    Reference,
    /// The rapier3d multibody engine (`clutchpack_multibody`).
    Multibody,
}

/// How an engine steps a pack's bodies (key `simulation.scheme`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SchemeChoice {
    /// Multirate where the engine can (each coupling sub-steps its own contacts), one shared
    /// step otherwise; the engine says which ran and why.
    #[default]
    Auto,
    /// One step sequence for every body: the multibody engine's shared step, the reference
    /// engine's monolithic scheme (the oracle).
    Shared,
    /// The multirate scheme, or bad input for a pack the engine cannot run so.
    Multirate,
}

/// Run settings of a scene (`[simulation]`). The rules and defaults of the keys are those of
/// [`keys_doc`] (`clutchpack check --keys`), defined once in the scene crate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Simulation {
    /// Simulated duration in s (> 0). Key `simulation.duration_s`.
    pub duration_s: f64,
    /// Engine asked for by the scene, if any. Key `simulation.engine`.
    pub engine: Option<EngineChoice>,
    /// How the engine steps the bodies. Key `simulation.scheme`.
    pub scheme: SchemeChoice,
    /// Rate at which samples are emitted, Hz (> 0). Key `simulation.record_rate_hz`.
    pub record_rate_hz: f64,
    /// Relative error tolerance of the adaptive integrators (dimensionless). Key
    /// `simulation.tolerance`.
    pub tolerance: f64,
    /// Largest step of the adaptive integrators in s (> 0). Key `simulation.max_step_s`.
    pub max_step_s: f64,
    /// Whether recordings store per-tooth loads where the engine resolves teeth. Key
    /// `simulation.record_per_tooth`.
    pub record_per_tooth: bool,
    /// Whether recordings store each disc's load at the engine's steps inside its contacts
    /// (`/discs/<disc>/load`). Key `simulation.record_contact_samples`.
    pub record_contact_samples: bool,
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
    /// The fatigue parameters of each body's spline teeth (keys `fatigue.*` and `material.*`
    /// of `[defaults]` and each `[[discs]]`, then of `[plate_defaults]` and each
    /// `[[plates]]`): one per disc, then one per plate, in the order engines number their
    /// couplings (`ImpactEvent::disc`).
    #[serde(default)]
    pub fatigue: Vec<clutchpack_model::FatigueParams>,
    /// The pack's thermal model (`[thermal]`, MODEL.md section 9); `None` for an isothermal
    /// scene (every scene without the section), which runs exactly as before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal: Option<clutchpack_model::thermal::ThermalModel>,
    /// The driveline network of a network scene (`[[bodies]]` and `[[couplings]]`, MODEL.md
    /// section 8); `None` for a pack scene. A network scene's `pack` is an empty placeholder
    /// that no pack engine runs (`clutchpack_sdk::Simulation` runs the network instead).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub network: Option<clutchpack_model::network::Network>,
    /// An automatic transmission's gears on the network (`[transmission]`, MODEL.md section
    /// 10); `None` without the section.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmission: Option<clutchpack_model::network::Transmission>,
    /// Every file this scene was read from: the scene file (when loaded from a path), the
    /// CSV tables it names, a network's pack files and theirs, in the order they were read.
    /// Outputs of a run are refused over any of them (`clutchpack_record::check_outputs`).
    /// Paths as found (relative to the working folder where the scene's path was); not
    /// stored with the scene (a recording or an FMU carries the scene's text, not its paths).
    #[serde(skip)]
    pub inputs: Vec<std::path::PathBuf>,
}

/// Reads an input text file (a scene, a CSV table, a study file) whole. A path that is not a
/// regular file is refused before it is opened: a FIFO with no writer would block (and ignore
/// every stop signal), a device would never end.
pub fn read_input(path: &Path) -> std::io::Result<String> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            if meta.is_dir() {
                "a folder, not a file"
            } else {
                "not a regular file (a FIFO, a socket or a device)"
            },
        ));
    }
    std::fs::read_to_string(path)
}

/// Reads and validates the scene file at `path`, after applying `overrides` in order.
/// Messages name the file as `path` is written; relative CSV paths resolve against the file's
/// folder. The [`Scene`] holds SI values (degrees of `_deg` keys converted to rad).
pub fn load(path: &Path, overrides: &[Override]) -> Result<Scene, SceneError> {
    let text = read_input(path).map_err(|error| SceneError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    let base_dir = path.parent().unwrap_or(Path::new(""));
    let mut scene = parse(&text, &path.display().to_string(), base_dir, overrides)?;
    scene.inputs.insert(0, path.to_path_buf());
    Ok(scene)
}

/// Validates scene text. `origin` is the file name used in messages (its stem is the default
/// scene name), `base_dir` the folder against which relative CSV paths resolve, `overrides`
/// the `--set` overrides, applied in order before validation. The [`Scene`] holds SI values
/// (degrees of `_deg` keys converted to rad); on error, every problem found is returned.
pub fn parse(
    text: &str,
    origin: &str,
    base_dir: &Path,
    overrides: &[Override],
) -> Result<Scene, SceneError> {
    let invalid = |problems| SceneError::Invalid {
        origin: origin.to_string(),
        problems,
    };
    let mut doc: Table = text
        .parse()
        .map_err(|e: toml::de::Error| invalid(vec![syntax_problem(text, &e)]))?;

    let mut problems = Vec::new();
    let applied = overrides::apply(&mut doc, overrides, &mut problems);
    let voided = raw::check_structure(&mut doc, &mut problems);
    let raw = deserialize_raw(doc, &mut problems);

    let stem = Path::new(origin)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| origin.to_string());
    let mut ck = validate::Checker::default();
    let validated = raw.and_then(|raw| validate::validate(&raw, &stem, base_dir, &mut ck));
    problems.append(&mut ck.problems);

    // A table of the wrong type was reported once: its keys are not missing on top of that.
    problems.retain(|p| {
        !(p.value.is_none()
            && p.rule.starts_with("missing")
            && voided.iter().any(|v| is_under(&p.key, v)))
    });
    // Say which problems stem from a --set value.
    for p in &mut problems {
        let from_set = applied.iter().rev().find(|k| is_under(&p.key, k));
        if let Some(k) = from_set {
            p.rule.push_str(&format!(" (from --set {k}=...)"));
        }
    }

    match validated {
        Some(v) if problems.is_empty() => Ok(Scene {
            name: v.name,
            description: v.description,
            source_text: text.to_string(),
            overrides: overrides.iter().map(Override::to_string).collect(),
            simulation: v.simulation,
            pack: v.pack,
            fatigue: v.fatigue,
            thermal: v.thermal,
            network: v.network,
            transmission: v.transmission,
            inputs: std::mem::take(&mut ck.files),
        }),
        _ => {
            debug_assert!(
                !problems.is_empty(),
                "no model built but no problem reported"
            );
            Err(invalid(problems))
        }
    }
}

/// Whether `key` is `path` or a key inside it (`discs[1].oil.width_m` is under `discs[1]`).
fn is_under(key: &str, path: &str) -> bool {
    key.strip_prefix(path)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with(['.', '[']))
}

/// A TOML syntax error as `line L column C: message` (1-based, column in characters).
fn syntax_problem(text: &str, e: &toml::de::Error) -> Problem {
    let message = e.message().trim().replace('\n', " ");
    match e.span() {
        Some(span) => {
            let before = &text[..span.start.min(text.len())];
            let line = before.matches('\n').count() + 1;
            let column = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
            Problem::new(format!("line {line} column {column}"), None, message)
        }
        None => Problem::new("TOML", None, message),
    }
}

/// Stage one: the document -> raw structs. Unknown keys become problems. Deserialization
/// cannot fail after [`raw::check_structure`]; should it, the failure is a problem too and
/// `None` is returned.
fn deserialize_raw(doc: Table, problems: &mut Vec<Problem>) -> Option<keys::RawScene> {
    let mut unknown = Vec::new();
    let mut collect = |path: serde_ignored::Path| unknown.push(ignored_path(&path));
    let de = serde_ignored::Deserializer::new(Value::Table(doc), &mut collect);
    let result: Result<keys::RawScene, _> = serde_path_to_error::deserialize(de);
    for key in unknown {
        let parent = key.rfind('.').map_or("", |i| &key[..i]);
        let rule = format!(
            "unknown key ({})",
            catalog::expected_text(&catalog::normalize(parent))
        );
        problems.push(Problem::new(key, None, rule));
    }
    match result {
        Ok(raw) => Some(raw),
        Err(e) => {
            let mut key = String::new();
            for seg in e.path().iter() {
                match seg {
                    serde_path_to_error::Segment::Seq { index } => {
                        key.push_str(&format!("[{index}]"))
                    }
                    serde_path_to_error::Segment::Map { key: k } => {
                        if !key.is_empty() {
                            key.push('.');
                        }
                        key.push_str(k);
                    }
                    _ => {}
                }
            }
            problems.push(Problem::new(key, None, e.inner().message().to_string()));
            None
        }
    }
}

/// A `serde_ignored` path as written in a scene file: `discs[0].oil.thicknes_m`.
fn ignored_path(path: &serde_ignored::Path) -> String {
    use serde_ignored::Path as P;
    match path {
        P::Root => String::new(),
        P::Seq { parent, index } => format!("{}[{index}]", ignored_path(parent)),
        P::Map { parent, key } => {
            let p = ignored_path(parent);
            if p.is_empty() {
                key.clone()
            } else {
                format!("{p}.{key}")
            }
        }
        P::Some { parent } | P::NewtypeStruct { parent } | P::NewtypeVariant { parent } => {
            ignored_path(parent)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Puts `1` at a schema path, creating tables and one-item arrays of tables on the way.
    fn insert(table: &mut Table, path: &str) {
        let (head, rest) = match path.split_once('.') {
            Some((h, r)) => (h, Some(r)),
            None => (path, None),
        };
        match (head.strip_suffix("[]"), rest) {
            (Some(name), Some(rest)) => {
                let items = table
                    .entry(name)
                    .or_insert_with(|| Value::Array(vec![Value::Table(Table::new())]));
                if let Some(Value::Table(item)) = items.as_array_mut().and_then(|a| a.first_mut()) {
                    insert(item, rest);
                }
            }
            (None, Some(rest)) => {
                let child = table
                    .entry(head)
                    .or_insert_with(|| Value::Table(Table::new()));
                insert(child.as_table_mut().expect("a table"), rest);
            }
            (_, None) => {
                table.insert(head.to_string(), Value::Integer(1));
            }
        }
    }

    /// Every key of the schema (and so of `--help` and the `--set` check) is a field of the raw
    /// structs: a document holding all of them deserializes with no unknown key.
    #[test]
    fn every_schema_key_is_read_by_the_raw_structs() {
        let mut doc = Table::new();
        for path in catalog::all_paths() {
            insert(&mut doc, path);
        }
        let mut problems = Vec::new();
        assert!(raw::check_structure(&mut doc, &mut problems).is_empty());
        assert!(deserialize_raw(doc, &mut problems).is_some());
        assert!(problems.is_empty(), "{problems:?}");
    }

    #[test]
    fn syntax_errors_are_located() {
        let text = "a = 1\nb = [1,\n";
        let e = text.parse::<Table>().unwrap_err();
        let p = syntax_problem(text, &e);
        assert!(p.key.starts_with("line "), "{p}");
        assert!(!p.rule.contains('\n'));
    }
}
