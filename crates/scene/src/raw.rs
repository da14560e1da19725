//! Stage one: structs that mirror the file, every field optional.
//!
//! Tables are typed (a `[simulation]` that is not a table is an error here), but every value
//! is kept as the [`toml::Value`] the user wrote: its type, range and cross-key rules are
//! checked in [`crate::validate`], which reports all problems at once with the value as
//! written. Unknown keys are not denied here but collected by `serde_ignored` (see
//! [`crate::parse`]), so that every misspelt key is reported, not only the first.
//!
//! Before deserializing, [`check_structure`] removes (and reports) every known table or array
//! of tables that has the wrong type, so that deserialization itself cannot fail and the rest
//! of the file is still checked.

use crate::error::Problem;
use crate::schema;
use serde::Deserialize;
use toml::{Table, Value};

/// Reports and removes each known table (`[simulation]`) or array of tables (`[[discs]]`)
/// whose value has another type; an item of an array of tables that is not a table becomes an
/// empty table (so later items keep their index). Leaves and unknown keys are left alone:
/// validation checks the types of leaves, and unknown keys are reported while deserializing.
/// Returns the key paths voided this way: "missing" problems under them are noise.
pub(crate) fn check_structure(doc: &mut Table, problems: &mut Vec<Problem>) -> Vec<String> {
    let mut voided = Vec::new();
    check_table(doc, "", problems, &mut voided);
    voided
}

/// `path` is the table's key path as written (`discs[1].oil`), `""` for the top level.
fn check_table(
    table: &mut Table,
    path: &str,
    problems: &mut Vec<Problem>,
    voided: &mut Vec<String>,
) {
    let mut wrong = Vec::new();
    for (key, value) in table.iter_mut() {
        let child = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        let norm = schema::normalize(&child);
        if schema::is_leaf(&norm) || !schema::is_known(&norm) {
            continue;
        }
        let section = norm.replace("[]", "");
        match value {
            Value::Array(items) if schema::is_array(&norm) => {
                for (i, item) in items.iter_mut().enumerate() {
                    let item_path = format!("{child}[{i}]");
                    if let Value::Table(t) = item {
                        check_table(t, &item_path, problems, voided);
                    } else {
                        let rule = format!("must be a table (an [[{section}]] entry)");
                        problems.push(Problem::new(&item_path, Some(item.to_string()), rule));
                        *item = Value::Table(Table::new());
                        voided.push(item_path);
                    }
                }
            }
            Value::Table(t) if !schema::is_array(&norm) => check_table(t, &child, problems, voided),
            _ => {
                let rule = if schema::is_array(&norm) {
                    format!("must be an array of tables: write [[{section}]] entries")
                } else {
                    format!("must be a table: write [{section}]")
                };
                wrong.push((key.clone(), child, rule));
            }
        }
    }
    for (key, child, rule) in wrong {
        let value = table.remove(&key).map(|v| v.to_string());
        problems.push(Problem::new(&child, value, rule));
        voided.push(child);
    }
}

/// The whole file.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawScene {
    pub name: Option<Value>,
    pub description: Option<Value>,
    pub simulation: Option<RawSimulation>,
    pub shaft: Option<RawShaft>,
    pub drive: Option<RawDrive>,
    pub discs: Option<Vec<RawDisc>>,
    /// Same keys as a disc except `name` (reported as unknown if present).
    pub defaults: Option<RawDisc>,
    /// Separator plates: the same keys as a disc.
    pub plates: Option<Vec<RawDisc>>,
    /// Shared plate parameters, like `defaults` for the discs.
    pub plate_defaults: Option<RawDisc>,
    pub drum: Option<RawDrum>,
    pub stack: Option<RawStack>,
}

/// `[drum]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawDrum {
    pub inertia_kg_m2: Option<Value>,
    pub load_torque_n_m: Option<Value>,
    pub drag_n_m_s_rad: Option<Value>,
    pub initial_speed_rad_s: Option<Value>,
}

/// `[stack]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawStack {
    pub face_inner_radius_m: Option<Value>,
    pub face_outer_radius_m: Option<Value>,
    pub spline_friction_coefficient: Option<Value>,
    pub piston_area_m2: Option<Value>,
    pub return_spring_n: Option<Value>,
    pub friction: Option<RawFriction>,
    pub pressure: Option<RawPressure>,
    pub open_gap: Option<RawOpenGap>,
}

/// `[stack.friction]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawFriction {
    pub kind: Option<Value>,
    pub static_mu: Option<Value>,
    pub kinetic_mu: Option<Value>,
    pub stribeck_speed_m_s: Option<Value>,
    pub viscous_slope_s_m: Option<Value>,
    pub slip_m_s: Option<Value>,
    pub mu: Option<Value>,
}

/// `[stack.pressure]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawPressure {
    pub kind: Option<Value>,
    pub pressure_pa: Option<Value>,
    pub start_s: Option<Value>,
    pub rise_s: Option<Value>,
    pub times_s: Option<Value>,
    pub values_pa: Option<Value>,
}

/// `[stack.open_gap]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawOpenGap {
    pub viscosity_pa_s: Option<Value>,
    pub gap_m: Option<Value>,
}

/// `[simulation]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawSimulation {
    pub duration_s: Option<Value>,
    pub engine: Option<Value>,
    pub record_rate_hz: Option<Value>,
    pub tolerance: Option<Value>,
    pub max_step_s: Option<Value>,
    pub record_per_tooth: Option<Value>,
}

/// `[shaft]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawShaft {
    pub mode: Option<Value>,
    pub inertia_kg_m2: Option<Value>,
    pub damping_n_m_s_rad: Option<Value>,
    pub initial_speed_rad_s: Option<Value>,
}

/// `[drive]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawDrive {
    pub kind: Option<Value>,
    pub omega0_rad_s: Option<Value>,
    pub amplitude_rad_s: Option<Value>,
    pub frequency_hz: Option<Value>,
    pub phase_deg: Option<Value>,
    pub harmonics: Option<Vec<RawHarmonic>>,
    pub file: Option<Value>,
}

/// One `[[drive.harmonics]]` entry.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawHarmonic {
    pub amplitude_rad_s: Option<Value>,
    pub frequency_hz: Option<Value>,
    pub phase_deg: Option<Value>,
}

/// One `[[discs]]` entry, or `[defaults]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawDisc {
    pub name: Option<Value>,
    pub inertia_kg_m2: Option<Value>,
    pub drag_n_m_s_rad: Option<Value>,
    pub initial_rel_angle_rad: Option<Value>,
    pub initial_rel_speed_rad_s: Option<Value>,
    pub radial_float: Option<Value>,
    pub tooth_spacing_errors_m: Option<Value>,
    pub initial_offset_m: Option<Value>,
    pub spline: Option<RawSpline>,
    pub contact: Option<RawContact>,
    pub oil: Option<RawOil>,
}

/// `[discs.spline]` / `[defaults.spline]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawSpline {
    pub teeth: Option<Value>,
    pub pitch_radius_m: Option<Value>,
    pub pressure_angle_deg: Option<Value>,
    pub backlash_m: Option<Value>,
}

/// `[discs.contact]` / `[defaults.contact]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawContact {
    pub law: Option<Value>,
    pub modulus_pa: Option<Value>,
    pub curvature_radius_m: Option<Value>,
    pub loss_coefficient_s_m: Option<Value>,
}

/// `[discs.oil]` / `[defaults.oil]`.
#[derive(Debug, Default, Deserialize)]
#[serde(expecting = "a table")]
pub(crate) struct RawOil {
    pub film_thickness_m: Option<Value>,
    pub viscosity_pa_s: Option<Value>,
    pub leakage_coefficient: Option<Value>,
    pub width_m: Option<Value>,
    pub length_m: Option<Value>,
    pub v_floor_m_s: Option<Value>,
    pub h_min_m: Option<Value>,
}
