//! The key catalogue, derived from the definitions in [`crate::keys`]: every key path of the
//! file, the "expected one of" lists, the `--set` key check, `check --keys` ([`keys_doc`])
//! and docs/scene-keys.md's table ([`keys_markdown`]).
//!
//! Paths are written as in the file, with `[]` standing for any index of an array of tables:
//! `discs[].spline.teeth`.

use crate::schema::{Key, RawTable};
use std::sync::OnceLock;

/// Every key path of the file (`[]` for array indices) with its definition, in file order.
/// A `name` belongs to the entries of an array of tables only (`discs[].name`), not to the
/// shared `[defaults]` tables that take the same body keys.
pub(crate) fn all_keys() -> &'static [(String, &'static Key)] {
    static PATHS: OnceLock<Vec<(String, &'static Key)>> = OnceLock::new();
    PATHS.get_or_init(|| {
        let mut v = Vec::new();
        <crate::keys::RawScene as RawTable>::paths("", &mut v);
        v.retain(|(p, k)| k.name != "name" || !p.contains('.') || p.ends_with("[].name"));
        v
    })
}

/// Every key path of the schema, `[]` for array indices.
pub(crate) fn all_paths() -> impl Iterator<Item = &'static str> {
    all_keys().iter().map(|(p, _)| p.as_str())
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
        || all_paths().any(|p| {
            p == norm
                || (p.starts_with(norm)
                    && matches!(p.as_bytes().get(norm.len()), Some(b'.' | b'[')))
        })
}

/// Whether a normalized path is a leaf key (holds a value, not keys).
pub(crate) fn is_leaf(norm: &str) -> bool {
    all_paths().any(|p| p == norm)
}

/// Whether a normalized path is an array of tables (`discs`, `drive.harmonics`).
pub(crate) fn is_array(norm: &str) -> bool {
    let prefix = format!("{norm}[]");
    all_paths().any(|p| p.starts_with(&prefix))
}

/// The keys directly inside the table at a normalized path (`""` is the top level), in
/// schema order.
pub(crate) fn children(parent_norm: &str) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    for p in all_paths() {
        let rest = if parent_norm.is_empty() {
            p
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

/// The tables of body keys: `[defaults]` and each `[[discs]]` for the friction discs,
/// `[plate_defaults]` and each `[[plates]]` for the separator plates.
const BODY_TABLES: [&str; 4] = ["defaults", "discs[]", "plate_defaults", "plates[]"];

/// The scene keys outside the body tables, with their full paths.
fn scene_keys() -> impl Iterator<Item = &'static (String, &'static Key)> {
    all_keys()
        .iter()
        .filter(|(p, _)| !BODY_TABLES.iter().any(|b| p.starts_with(&format!("{b}."))))
}

/// The body keys, relative to the body (`spline.teeth`, `name`), in definition order.
pub(crate) fn body_keys() -> &'static [(String, &'static Key)] {
    static KEYS: OnceLock<Vec<(String, &'static Key)>> = OnceLock::new();
    KEYS.get_or_init(|| {
        let mut v = Vec::new();
        <crate::keys::RawBody as RawTable>::paths("", &mut v);
        v
    })
}

/// The text before the body keys in the references.
const BODY_INTRO: &str = "Body parameters, in [defaults] (shared by all friction discs) and \
    in each [[discs]] entry (overrides [defaults]); at least one [[discs]]. Separator plates \
    take the same keys in [plate_defaults] and [[plates]] (their spline and angles relative to \
    their carrier: the drum, else the housing); `name` only in [[discs]] and [[plates]] \
    entries.";

/// A short reference of every scene key: unit, rule, default, meaning. Printed by
/// `clutchpack check --keys`; generated from the key definitions (`keys.rs`).
pub fn keys_doc() -> String {
    use std::fmt::Write;
    let body = body_keys();
    let width = scene_keys()
        .map(|(p, _)| p.len())
        .chain(body.iter().map(|(p, _)| p.len()))
        .max()
        .unwrap_or(0)
        + 2;
    let mut s = String::new();
    s.push_str(
        "Scene file keys (TOML; SI units named by the key's suffix; angles only in keys ending \
         _deg):\n",
    );
    for (p, k) in scene_keys() {
        let _ = writeln!(s, "  {p:width$}{}", k.doc_line());
    }
    s.push_str(BODY_INTRO);
    s.push('\n');
    for (p, k) in body {
        let _ = writeln!(s, "  {p:width$}{}", k.doc_line());
    }
    s.push_str(
        "Override any key with --set KEY=VALUE (VALUE in TOML syntax, else a string), e.g. \
         --set discs[1].oil.film_thickness_m=50e-6\n",
    );
    s
}

/// The scene-key table of docs/scene-keys.md (Markdown), generated from the same definitions
/// as [`keys_doc`]; printed by `clutchpack check --keys --markdown`. A test
/// (`tests/keys_doc.rs`) checks that the document holds exactly this text, so they cannot
/// drift.
pub fn keys_markdown() -> String {
    use std::fmt::Write;
    let cell = |t: &str| t.replace('|', "\\|");
    let mut s = String::new();
    let table = |s: &mut String, rows: &[(String, &Key)]| {
        s.push_str("| key | unit | rule | default | meaning |\n|---|---|---|---|---|\n");
        for (p, k) in rows {
            let (unit, rule, default) = k.columns();
            let _ = writeln!(
                s,
                "| `{p}` | {} | {} | {} | {} |",
                cell(&unit),
                cell(&rule),
                cell(&default),
                cell(k.doc.trim())
            );
        }
    };
    let scene: Vec<(String, &Key)> = scene_keys().map(|(p, k)| (p.clone(), *k)).collect();
    table(&mut s, &scene);
    s.push('\n');
    s.push_str(BODY_INTRO);
    s.push_str("\n\n");
    let body: Vec<(String, &Key)> = body_keys().iter().map(|(p, k)| (p.clone(), *k)).collect();
    table(&mut s, &body);
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
                "plate_defaults",
                "thermal",
                "bodies",
                "couplings",
                "transmission"
            ]
        );
        assert!(children("discs[]").contains(&"name"));
        assert!(children("discs[].oil").contains(&"film_thickness_m"));
        assert!(!children("defaults").contains(&"name"));
    }

    #[test]
    fn doc_lists_every_key() {
        let doc = keys_doc();
        let md = keys_markdown();
        for (p, _) in scene_keys() {
            assert!(
                doc.contains(p.as_str()),
                "{p} missing from the key reference"
            );
            assert!(md.contains(&format!("`{p}`")), "{p} missing from the table");
        }
        for (p, _) in body_keys() {
            assert!(
                doc.contains(p.as_str()),
                "{p} missing from the key reference"
            );
            assert!(md.contains(&format!("`{p}`")), "{p} missing from the table");
        }
    }
}
