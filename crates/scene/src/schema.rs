//! The list of every key a scene file may hold, with a one-line reference for each.
//!
//! This is the single source of truth for three things: the key reference printed by `--help`
//! ([`keys_doc`]), the "expected one of" lists of unknown-key errors, and the check that a
//! `--set` key exists. The raw structs in [`crate::raw`] must hold exactly these keys (a unit
//! test checks that every key here deserializes without being reported as unknown).
//!
//! Paths are written as in the file, with `[]` standing for any index of an array of tables:
//! `discs[].spline.teeth`.

use std::sync::OnceLock;

/// One key of the file and its reference line (unit, rule, default).
struct Key {
    path: &'static str,
    doc: &'static str,
}

const fn key(path: &'static str, doc: &'static str) -> Key {
    Key { path, doc }
}

/// Keys outside the disc parameters.
const SCENE_KEYS: &[Key] = &[
    key(
        "name",
        "string; default: the file name without its extension",
    ),
    key("description", "string; default: empty"),
    key("simulation.duration_s", "s, required, > 0"),
    key(
        "simulation.engine",
        "\"reference\" | \"multibody\"; optional (the CLI chooses if absent)",
    ),
    key("simulation.record_rate_hz", "Hz, > 0; default 10000"),
    key(
        "simulation.tolerance",
        "relative tolerance of the adaptive integrator, in [1e-14, 1e-3]; default 1e-9",
    ),
    key("simulation.max_step_s", "s, > 0; default 1e-4"),
    key(
        "simulation.record_per_tooth",
        "true | false; record per-tooth loads where the engine resolves teeth; default false",
    ),
    key("shaft.mode", "\"prescribed\" (default) | \"inertial\""),
    key(
        "shaft.inertia_kg_m2",
        "kg m^2, > 0; required if inertial, an error if prescribed",
    ),
    key(
        "shaft.damping_n_m_s_rad",
        "N m s/rad, >= 0; default 0; inertial only",
    ),
    key(
        "shaft.initial_speed_rad_s",
        "rad/s; required with drive.kind = \"torque_table\", an error otherwise",
    ),
    key(
        "drive.kind",
        "required: \"sine\" | \"harmonics\" | \"speed_table\" | \"torque_table\"",
    ),
    key(
        "drive.omega0_rad_s",
        "rad/s, mean shaft speed; required for sine and harmonics",
    ),
    key("drive.amplitude_rad_s", "rad/s; sine: required"),
    key("drive.frequency_hz", "Hz, > 0; sine: required"),
    key("drive.phase_deg", "deg; sine: default 0"),
    key(
        "drive.harmonics[].amplitude_rad_s",
        "rad/s; harmonics: one [[drive.harmonics]] per term, at least one; required",
    ),
    key("drive.harmonics[].frequency_hz", "Hz, > 0; required"),
    key("drive.harmonics[].phase_deg", "deg; default 0"),
    key(
        "drive.file",
        "CSV with a header row, relative to the scene file's folder; speed_table: columns \
         time_s, speed_rad_s; torque_table: columns time_s, torque_n_m (needs shaft.mode = \
         \"inertial\")",
    ),
    key(
        "discs[].name",
        "string; default \"disc-<i+1>\"; unique (only in [[discs]], not in [defaults])",
    ),
    key(
        "plates[].name",
        "string; default \"plate-<j+1>\"; unique among discs and plates (only in [[plates]])",
    ),
    key(
        "drum.inertia_kg_m2",
        "kg m^2, > 0; required with [drum] (a clutch: the plates sit on the drum, else on \
         the housing)",
    ),
    key(
        "drum.load_torque_n_m",
        "N m, on the drum about the axis (negative brakes it); default 0",
    ),
    key("drum.drag_n_m_s_rad", "N m s/rad, >= 0; default 0"),
    key("drum.initial_speed_rad_s", "rad/s; default 0"),
    key(
        "stack.face_inner_radius_m",
        "m, > 0; required with [stack] (friction faces, inner radius)",
    ),
    key(
        "stack.face_outer_radius_m",
        "m, > face_inner_radius_m; required with [stack]",
    ),
    key(
        "stack.spline_friction_coefficient",
        "dimensionless, >= 0; default 0 (axial spline friction holds back mu n |F| per body)",
    ),
    key("stack.piston_area_m2", "m^2, > 0; required with [stack]"),
    key(
        "stack.return_spring_n",
        "N, >= 0; default 0 (piston force = p A - return spring, never < 0)",
    ),
    key("stack.friction.kind", "\"stribeck\" (default) | \"table\""),
    key(
        "stack.friction.static_mu",
        "stribeck: mu at zero slip, > 0; required",
    ),
    key(
        "stack.friction.kinetic_mu",
        "stribeck: mu beyond the Stribeck speed, > 0; default static_mu",
    ),
    key(
        "stack.friction.stribeck_speed_m_s",
        "stribeck: m/s, > 0; default 1",
    ),
    key(
        "stack.friction.viscous_slope_s_m",
        "stribeck: s/m, >= 0; default 0 (mu rises by this per m/s of slip)",
    ),
    key(
        "stack.friction.slip_m_s",
        "table: m/s, array increasing from 0; required",
    ),
    key(
        "stack.friction.mu",
        "table: array of mu > 0, one per slip_m_s; required",
    ),
    key(
        "stack.pressure.kind",
        "required with [stack]: \"constant\" | \"ramp\" | \"table\"",
    ),
    key(
        "stack.pressure.pressure_pa",
        "Pa, >= 0; constant and ramp (the final pressure): required",
    ),
    key("stack.pressure.start_s", "ramp: s, >= 0; default 0"),
    key("stack.pressure.rise_s", "ramp: s, > 0; required"),
    key(
        "stack.pressure.times_s",
        "table: s, array increasing; required",
    ),
    key(
        "stack.pressure.values_pa",
        "table: Pa, array >= 0, one per times_s; required",
    ),
    key(
        "stack.open_gap.viscosity_pa_s",
        "Pa s, > 0; required with [stack.open_gap] (oil in the open gaps)",
    ),
    key(
        "stack.open_gap.gap_m",
        "m, > 0; required with [stack.open_gap] (axial gap per open interface)",
    ),
];

/// Disc parameters: allowed in `[defaults]` and in each `[[discs]]` entry.
const DISC_KEYS: &[Key] = &[
    key("inertia_kg_m2", "kg m^2, > 0; required"),
    key("drag_n_m_s_rad", "N m s/rad, >= 0; default 0 (oil drag C2)"),
    key(
        "initial_rel_angle_rad",
        "rad, phi(0) = theta_shaft - theta_disc; default 0; must lie inside the free play",
    ),
    key(
        "initial_rel_speed_rad_s",
        "rad/s, omega_shaft(0) - omega_disc(0); default 0",
    ),
    key(
        "radial_float",
        "true | false; default false; the disc may move radially on its spline (multibody \
         engine only)",
    ),
    key(
        "tooth_spacing_errors_m",
        "m, array of n finite numbers (one per tooth, tooth k at 2 pi k / n from the shaft's \
         +x axis) or empty; default empty; circumferential spacing error at the pitch circle, \
         positive closes the shaft-leads gap (multibody engine only)",
    ),
    key(
        "initial_offset_m",
        "m, [x, y] in the shaft's frame; default [0, 0]; the disc centre's offset from the \
         axis at t = 0 (held there unless radial_float; multibody engine only)",
    ),
    key("spline.teeth", "integer >= 1; required"),
    key("spline.pitch_radius_m", "m, > 0; required"),
    key("spline.pressure_angle_deg", "deg, in (0, 90); required"),
    key(
        "spline.backlash_m",
        "m, > 0; required (total circumferential free play at the pitch circle)",
    ),
    key("contact.law", "\"paper\" (default) | \"dry\" | \"squeeze\""),
    key(
        "contact.modulus_pa",
        "Pa, > 0; required (equivalent modulus E)",
    ),
    key(
        "contact.curvature_radius_m",
        "m, > 0; required (equivalent curvature radius r)",
    ),
    key(
        "contact.loss_coefficient_s_m",
        "s/m, >= 0; default 0 (impact loss p)",
    ),
    key(
        "oil.film_thickness_m",
        "m, >= 0; default 0; below half the free play along the line of action",
    ),
    key(
        "oil.viscosity_pa_s",
        "Pa s, > 0; required if film_thickness_m > 0 and law is not dry",
    ),
    key(
        "oil.leakage_coefficient",
        "dimensionless, > 0; required like viscosity_pa_s (beta)",
    ),
    key("oil.width_m", "m, > 0; required like viscosity_pa_s (B)"),
    key("oil.length_m", "m, > 0; required like viscosity_pa_s (L)"),
    key("oil.v_floor_m_s", "m/s, > 0; default 0.01"),
    key("oil.h_min_m", "m, > 0; default 1e-6 (squeeze law)"),
];

/// Every key path of the schema, `[]` for array indices.
pub(crate) fn all_paths() -> &'static [String] {
    static PATHS: OnceLock<Vec<String>> = OnceLock::new();
    PATHS.get_or_init(|| {
        let mut v: Vec<String> = SCENE_KEYS.iter().map(|k| k.path.to_string()).collect();
        for prefix in ["defaults", "discs[]", "plate_defaults", "plates[]"] {
            v.extend(DISC_KEYS.iter().map(|k| format!("{prefix}.{}", k.path)));
        }
        v
    })
}

/// `discs[2].oil.h_min_m` -> `discs[].oil.h_min_m`: indices replaced by `[]`.
pub(crate) fn normalize(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    let mut in_index = false;
    for c in path.chars() {
        match c {
            '[' => {
                in_index = true;
                out.push_str("[]");
            }
            ']' => in_index = false,
            _ if in_index => {}
            _ => out.push(c),
        }
    }
    out
}

/// Whether a normalized path is a key of the schema or a table (or array) that holds keys.
pub(crate) fn is_known(norm: &str) -> bool {
    norm.is_empty()
        || all_paths().iter().any(|p| {
            p == norm
                || (p.starts_with(norm)
                    && matches!(p.as_bytes().get(norm.len()), Some(b'.' | b'[')))
        })
}

/// Whether a normalized path is a leaf key (holds a value, not keys).
pub(crate) fn is_leaf(norm: &str) -> bool {
    all_paths().iter().any(|p| p == norm)
}

/// Whether a normalized path is an array of tables (`discs`, `drive.harmonics`).
pub(crate) fn is_array(norm: &str) -> bool {
    let prefix = format!("{norm}[]");
    all_paths().iter().any(|p| p.starts_with(&prefix))
}

/// The keys directly inside the table at a normalized path (`""` is the top level), in
/// schema order.
pub(crate) fn children(parent_norm: &str) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    for p in all_paths() {
        let rest = if parent_norm.is_empty() {
            p.as_str()
        } else if let Some(r) = p
            .strip_prefix(parent_norm)
            .and_then(|r| r.strip_prefix('.'))
        {
            r
        } else {
            continue;
        };
        let end = rest.find(['.', '[']).unwrap_or(rest.len());
        let child = &rest[..end];
        if !out.contains(&child) {
            out.push(child);
        }
    }
    out
}

/// The "expected one of: ..." text for an unknown key whose parent table is `parent_norm`.
pub(crate) fn expected_text(parent_norm: &str) -> String {
    format!("expected one of: {}", children(parent_norm).join(", "))
}

/// A short reference of every scene key: unit, rule, default. Printed by `clutchpack --help`.
pub fn keys_doc() -> String {
    use std::fmt::Write;
    let width = SCENE_KEYS
        .iter()
        .chain(DISC_KEYS)
        .map(|k| k.path.len())
        .max()
        .unwrap_or(0)
        + 2;
    let mut s = String::new();
    s.push_str(
        "Scene file keys (TOML; SI units named by the key's suffix; angles only in keys ending \
         _deg):\n",
    );
    for k in SCENE_KEYS {
        let _ = writeln!(s, "  {:width$}{}", k.path, k.doc);
    }
    s.push_str(
        "Disc parameters, in [defaults] (shared by all discs) and in each [[discs]] entry \
         (overrides [defaults]); at least one [[discs]]. Separator plates take the same keys \
         in [plate_defaults] and [[plates]] (their spline and angles relative to their \
         carrier: the drum, else the housing):\n",
    );
    for k in DISC_KEYS {
        let _ = writeln!(s, "  {:width$}{}", k.path, k.doc);
    }
    s.push_str(
        "Override any key with --set KEY=VALUE (VALUE in TOML syntax, else a string), e.g. \
         --set discs[1].oil.film_thickness_m=50e-6\n",
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_replaces_indices() {
        assert_eq!(normalize("discs[12].oil.h_min_m"), "discs[].oil.h_min_m");
        assert_eq!(normalize("name"), "name");
    }

    #[test]
    fn known_paths_and_children() {
        assert!(is_known("discs[].oil"));
        assert!(is_known("discs"));
        assert!(is_known("defaults.spline.teeth"));
        assert!(!is_known("defaults.name"));
        assert!(!is_known("discs.name"));
        assert!(!is_known("simulation.duration"));
        assert!(is_leaf("simulation.duration_s"));
        assert!(is_array("discs") && is_array("drive.harmonics") && !is_array("drive"));
        assert_eq!(
            children(""),
            [
                "name",
                "description",
                "simulation",
                "shaft",
                "drive",
                "discs",
                "plates",
                "drum",
                "stack",
                "defaults",
                "plate_defaults"
            ]
        );
        assert!(children("discs[].oil").contains(&"film_thickness_m"));
        assert!(!children("defaults").contains(&"name"));
    }

    #[test]
    fn doc_lists_every_key() {
        let doc = keys_doc();
        for k in SCENE_KEYS.iter().chain(DISC_KEYS) {
            assert!(
                doc.contains(k.path),
                "{} missing from the key reference",
                k.path
            );
        }
    }
}
