//! ARCHITECTURE.md cannot drift (issue 22): every source file, every crate and every file over
//! 700 lines is named there, as `crates/scene/tests/readme.rs` keeps the README's key table.

use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.rs` file under `dir`, recursively.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The source files of the crates: `crates/<crate>/src/**` and the binary's `crates/cli/*.rs`,
/// relative to the repository root.
fn sources() -> Vec<String> {
    let mut files = Vec::new();
    for c in std::fs::read_dir(root().join("crates")).unwrap() {
        let c = c.unwrap().path();
        let src = c.join("src");
        if src.is_dir() {
            rust_files(&src, &mut files);
        } else if c.ends_with("cli") {
            rust_files(&c, &mut files);
        }
    }
    let mut v: Vec<String> = files
        .iter()
        .map(|p| {
            p.strip_prefix(root())
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    v.sort();
    v
}

/// The text of the section `## <title>` of ARCHITECTURE.md, up to the next `## `.
fn section<'a>(text: &'a str, title: &str) -> &'a str {
    let start = text
        .find(&format!("## {title}"))
        .unwrap_or_else(|| panic!("ARCHITECTURE.md has no section {title:?}"));
    let rest = &text[start + 3..];
    &rest[..rest.find("\n## ").unwrap_or(rest.len())]
}

#[test]
fn architecture_names_every_file_crate_and_long_file() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let map = section(&text, "Module map");
    let long = section(&text, "Files over ~700 lines");
    let files = sources();
    assert!(files.len() > 50, "{files:?}");
    let missing: Vec<&String> = files
        .iter()
        .filter(|f| !map.contains(&format!("`{f}`")))
        .collect();
    assert!(
        missing.is_empty(),
        "source files missing from ARCHITECTURE.md's module map: {missing:?}"
    );
    let unlisted_long: Vec<(String, usize)> = files
        .iter()
        .map(|f| {
            let n = std::fs::read_to_string(root().join(f))
                .unwrap()
                .lines()
                .count();
            (f.clone(), n)
        })
        .filter(|(f, n)| *n > 700 && !long.contains(&format!("`{f}`")))
        .collect();
    assert!(
        unlisted_long.is_empty(),
        "files over 700 lines not named (with why they are one concern) in ARCHITECTURE.md's \
         \"Files over ~700 lines\": {unlisted_long:?}"
    );
    for c in std::fs::read_dir(root().join("crates")).unwrap() {
        let toml = std::fs::read_to_string(c.unwrap().path().join("Cargo.toml"));
        let Ok(toml) = toml else { continue };
        let name = toml
            .lines()
            .find_map(|l| l.strip_prefix("name = \""))
            .map(|n| n.trim_end_matches('"'))
            .expect("a package name");
        assert!(
            text.contains(&format!("`{name}`")),
            "crate {name} missing from ARCHITECTURE.md"
        );
    }
}

/// The module (file) that `path` names from `file`'s module: `crate::a::b` and `super::b`
/// resolved to a source file of the same crate (`a/b.rs`, `a/b/mod.rs`, `a.rs`, `a/mod.rs`),
/// or `None` (another crate, or a crate root: roots declare their modules, which is not a
/// cycle).
fn module_file(src: &Path, file: &Path, path: &[&str]) -> Option<PathBuf> {
    let (mut dir, rest) = match path.first() {
        Some(&"crate") => (src.to_path_buf(), &path[1..]),
        Some(&"super") => {
            // the parent module's folder: a file `x/y.rs` is module y inside x's folder
            let here = file.parent()?.to_path_buf();
            let is_mod = file.file_name().is_some_and(|f| f == "mod.rs");
            (
                if is_mod {
                    here.parent()?.to_path_buf()
                } else {
                    here
                },
                &path[1..],
            )
        }
        _ => return None,
    };
    let mut found = None;
    for seg in rest {
        let as_file = dir.join(format!("{seg}.rs"));
        let as_dir = dir.join(seg).join("mod.rs");
        if as_file.is_file() {
            found = Some(as_file);
        } else if as_dir.is_file() {
            found = Some(as_dir);
        } else {
            break;
        }
        dir = dir.join(seg);
    }
    found
}

/// The paths a file names through `crate::` or `super::`, each as its segments, from `use`
/// trees (`use crate::{a, b::c}`) and paths in code (`crate::a::f()`); comments and the unit
/// tests (from a top-level `#[cfg(test)]` on: a test may take a fixture from a module that
/// depends on this one) skipped.
fn named_paths(text: &str) -> Vec<Vec<String>> {
    let text = text.split("\n#[cfg(test)]").next().unwrap_or(text);
    let code: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = Vec::new();
    for root in ["crate::", "super::"] {
        let mut rest = code.as_str();
        while let Some(i) = rest.find(root) {
            // not `$crate::` (macros) nor part of a longer identifier
            let before = rest[..i].chars().last();
            let after = &rest[i + root.len()..];
            rest = after;
            if before.is_some_and(|c| c == '$' || c.is_alphanumeric() || c == '_') {
                continue;
            }
            let head = root.trim_end_matches("::").to_string();
            if let Some(group) = after.strip_prefix('{') {
                // `use crate::{a, b::c, d::{e, f}}`: the first segment of each item
                let end = group.find('}').unwrap_or(group.len());
                for item in group[..end].split(',') {
                    let first = item.trim().split("::").next().unwrap_or("").trim();
                    if !first.is_empty() {
                        out.push(vec![head.clone(), first.to_string()]);
                    }
                }
                continue;
            }
            let segs: Vec<String> = after
                .split("::")
                .map_while(|s| {
                    let id: String = s
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    (!id.is_empty() && id.len() == s.len())
                        .then_some(id.clone())
                        .or({
                            // the last segment ends the path (`a::f(`, `a::{`)
                            None
                        })
                })
                .collect();
            let last: String = after
                .split("::")
                .nth(segs.len())
                .map(|s| {
                    s.chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect()
                })
                .unwrap_or_default();
            let mut p = vec![head.clone()];
            p.extend(segs);
            if !last.is_empty() {
                p.push(last);
            }
            out.push(p);
        }
    }
    out
}

/// Issue 22: no two files of a crate import each other (`cli/common.rs` and `outputs.rs`,
/// `scene/src/keys.rs` and `schema.rs`, `sim/src/engine/state.rs` with `events.rs` and
/// `energy.rs` did); a crate root (`lib.rs`, `main.rs`) and a folder's `mod.rs` declare their
/// modules and are left out.
#[test]
fn no_two_files_import_each_other() {
    let mut edges = std::collections::BTreeSet::new();
    for c in std::fs::read_dir(root().join("crates")).unwrap() {
        let c = c.unwrap().path();
        let src = if c.join("src").is_dir() {
            c.join("src")
        } else {
            c.clone()
        };
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for f in &files {
            let text = std::fs::read_to_string(f).unwrap();
            for p in named_paths(&text) {
                let segs: Vec<&str> = p.iter().map(String::as_str).collect();
                if let Some(to) = module_file(&src, f, &segs) {
                    let root_like = |x: &Path| {
                        x.file_name()
                            .is_some_and(|n| n == "lib.rs" || n == "main.rs" || n == "mod.rs")
                    };
                    if &to != f && !root_like(&to) && !root_like(f) {
                        edges.insert((f.clone(), to));
                    }
                }
            }
        }
    }
    assert!(
        edges.len() > 40,
        "the scan found too few imports: {edges:?}"
    );
    let pairs: Vec<String> = edges
        .iter()
        .filter(|(a, b)| a < b && edges.contains(&(b.clone(), a.clone())))
        .map(|(a, b)| {
            let rel = |p: &Path| p.strip_prefix(root()).unwrap().display().to_string();
            format!("{} <-> {}", rel(a), rel(b))
        })
        .collect();
    assert!(pairs.is_empty(), "files that import each other: {pairs:?}");
}

/// The `clutchpack_*` crates in the `[dependencies]` of a `Cargo.toml` (not the dev- or
/// build-dependencies), by their short names (`clutchpack_model` -> `model`).
fn our_dependencies(cargo_toml: &Path) -> std::collections::BTreeSet<String> {
    let text = std::fs::read_to_string(cargo_toml).unwrap();
    let mut inside = false;
    let mut out = std::collections::BTreeSet::new();
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line == "[dependencies]";
        } else if inside {
            if let Some(rest) = line.strip_prefix("clutchpack_") {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                out.insert(name);
            }
        }
    }
    out
}

/// The crates table's last column ("depends on (ours)") is what each crate's `Cargo.toml`
/// says (issue 33: the dependency column checked, not only written).
#[test]
fn the_crates_tables_dependencies_are_the_manifests() {
    let text = std::fs::read_to_string(root().join("ARCHITECTURE.md")).unwrap();
    let table = section(&text, "Crates");
    let mut rows = 0;
    for row in table.lines().filter(|l| l.starts_with("| `clutchpack")) {
        let cols: Vec<&str> = row.split('|').map(str::trim).collect();
        // "| crate | folder | what | deps |" splits into ["", crate, folder, what, deps, ""]
        let (folder, deps) = (cols[2], cols[cols.len() - 2]);
        let folder = folder.split('`').nth(1).expect("a folder in backticks");
        let manifest = if folder == "crates/cli" {
            root().join("Cargo.toml")
        } else {
            root().join(folder).join("Cargo.toml")
        };
        let known = [
            "model",
            "scene",
            "analysis",
            "reference",
            "multibody",
            "record",
            "study",
            "sdk",
            "fmu",
        ];
        let said: std::collections::BTreeSet<String> = deps
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|w| known.contains(w))
            .map(str::to_string)
            .collect();
        assert_eq!(
            said,
            our_dependencies(&manifest),
            "ARCHITECTURE.md's crates table, {folder}: the dependency column against {}",
            manifest.display()
        );
        rows += 1;
    }
    assert_eq!(rows, 11, "the crates table's rows");
}
