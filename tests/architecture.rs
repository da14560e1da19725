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
