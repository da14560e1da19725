//! ARCHITECTURE.md cannot drift (issue 22): every source file, every crate and every file over
//! 700 lines is named there, as `crates/scene/tests/keys_doc.rs` keeps docs/scene-keys.md's key table.

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

/// Whether `f` is a crate root (`lib.rs`, `main.rs`) or a folder's `mod.rs`: such a file
/// declares its modules and re-exports their items, which is not an import of them; it is
/// left out of the import graph (an import through its re-export reaches the defining file).
fn root_like(f: &Path) -> bool {
    f.file_name()
        .is_some_and(|n| n == "lib.rs" || n == "main.rs" || n == "mod.rs")
}

/// The folder holding the submodules of the module in `file`: a root's or a `mod.rs`'s own
/// folder, `x/` beside a file `x.rs`.
fn children_dir(file: &Path) -> PathBuf {
    if root_like(file) {
        file.parent().unwrap().to_path_buf()
    } else {
        file.with_extension("")
    }
}

/// The file of the module whose submodules live in `dir` (`dir/mod.rs`, `dir.rs`, or the
/// crate root `lib.rs`/`main.rs` when `dir` is the crate's source folder `src`).
fn dir_module(dir: &Path, src: &Path) -> Option<PathBuf> {
    let candidates = if dir == src {
        vec![src.join("lib.rs"), src.join("main.rs")]
    } else {
        vec![dir.join("mod.rs"), dir.with_extension("rs")]
    };
    candidates.into_iter().find(|p| p.is_file())
}

/// The parent module's file of the module in `file` (what `super` names there).
fn parent_module(file: &Path, src: &Path) -> Option<PathBuf> {
    let here = file.parent()?;
    let dir = if file.file_name().is_some_and(|n| n == "mod.rs") {
        here.parent()?
    } else {
        here
    };
    dir_module(dir, src)
}

/// The use trees starting at `s[*i]` (`a::b::{c, d::{e, f}}`, `a::b as c`, `a::f(`) as full
/// paths of identifiers, each after `prefix`: a tree ends where a path cannot go on (a
/// call's `(`, a generic's `<`, a `;`), a glob (`*`) names its module.
fn parse_tree(s: &[u8], i: &mut usize, mut prefix: Vec<String>, out: &mut Vec<Vec<String>>) {
    let skip_ws = |i: &mut usize| {
        while *i < s.len() && s[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    let ident = |i: &mut usize| {
        let start = *i;
        while *i < s.len() && (s[*i].is_ascii_alphanumeric() || s[*i] == b'_') {
            *i += 1;
        }
        String::from_utf8_lossy(&s[start..*i]).into_owned()
    };
    skip_ws(i);
    if s.get(*i) == Some(&b'{') {
        *i += 1;
        loop {
            skip_ws(i);
            match s.get(*i) {
                None => return,
                Some(b'}') => {
                    *i += 1;
                    return;
                }
                Some(b',') => *i += 1,
                _ => {
                    let before = *i;
                    parse_tree(s, i, prefix.clone(), out);
                    if *i == before {
                        *i += 1; // something a use tree does not hold: step over it
                    }
                }
            }
        }
    }
    let seg = ident(i);
    if seg.is_empty() {
        if s.get(*i) == Some(&b'*') {
            *i += 1;
        }
        if !prefix.is_empty() {
            out.push(prefix);
        }
        return;
    }
    prefix.push(seg);
    if s[*i..].starts_with(b"::") {
        *i += 2;
        parse_tree(s, i, prefix, out);
        return;
    }
    skip_ws(i);
    if s[*i..].starts_with(b"as ") {
        *i += 3;
        skip_ws(i);
        ident(i);
    }
    out.push(prefix);
}

/// The code of a file without its comments and its unit tests (from a top-level
/// `#[cfg(test)]` on: a test may take a fixture from a module that depends on this one).
fn code_of(text: &str) -> String {
    let text = text.split("\n#[cfg(test)]").next().unwrap_or(text);
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths a file names through `crate::` or `super::`, each as its segments (`use` trees
/// expanded: `use crate::{a, b::{c, d}}` gives `crate::a`, `crate::b::c`, `crate::b::d`), from
/// `use` declarations and paths in code (`crate::a::f()`).
fn named_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let b = code.as_bytes();
    for root in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(root) {
            let at = from + k;
            from = at + root.len();
            // not `$crate::` (macros) nor part of a longer identifier or path
            let before = code[..at].chars().last();
            if before.is_some_and(|c| c == '$' || c == ':' || c.is_alphanumeric() || c == '_') {
                continue;
            }
            let mut i = at;
            parse_tree(b, &mut i, Vec::new(), &mut out);
            from = from.max(i);
        }
    }
    out
}

/// What the `pub use` declarations of the module in `file` re-export: each re-exported name
/// with the path it stands for (relative to that module, as written).
fn reexports(file: &Path) -> Vec<(String, Vec<String>)> {
    let code = code_of(&std::fs::read_to_string(file).unwrap_or_default());
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(k) = code[from..].find("pub use ") {
        let mut i = from + k + "pub use ".len();
        let mut paths = Vec::new();
        parse_tree(code.as_bytes(), &mut i, Vec::new(), &mut paths);
        for p in paths {
            if let Some(last) = p.last() {
                out.push((last.clone(), p.clone()));
            }
        }
        from = i.max(from + k + 1);
    }
    out
}

/// The source file (of the crate whose source folder is `src`) that defines what `path`
/// names from the module in `file`: `crate::a::b::f`, `super::b`, `self::c` and (in a
/// re-export) a submodule's `c::X`, walked through the module folders and through the
/// re-exports (`pub use`) of the modules on the way; `None` for another crate's item.
fn resolve(src: &Path, file: &Path, path: &[String], depth: usize) -> Option<PathBuf> {
    let mut cur = file.to_path_buf();
    let mut segs = path;
    let mut relative = true;
    while let Some(first) = segs.first() {
        match first.as_str() {
            "crate" => cur = dir_module(src, src)?,
            "super" => cur = parent_module(&cur, src)?,
            "self" => {}
            _ => break,
        }
        relative = false;
        segs = &segs[1..];
    }
    for (n, seg) in segs.iter().enumerate() {
        let dir = children_dir(&cur);
        let as_file = dir.join(format!("{seg}.rs"));
        let as_dir = dir.join(seg).join("mod.rs");
        if as_file.is_file() {
            cur = as_file;
        } else if as_dir.is_file() {
            cur = as_dir;
        } else if relative && n == 0 {
            return None; // another crate (`use serde::X`)
        } else {
            // an item of `cur`: where it is defined, if `cur` re-exports it
            if depth < 8 {
                if let Some((_, target)) = reexports(&cur).into_iter().find(|(name, _)| name == seg)
                {
                    let mut rest = target;
                    rest.extend(segs[n + 1..].iter().cloned());
                    return resolve(src, &cur, &rest, depth + 1);
                }
            }
            return Some(cur);
        }
    }
    Some(cur)
}

/// The import graph of the crates' source files: an edge from each file to every other file
/// of its crate whose items it names through `crate::` or `super::` (roots and `mod.rs` files
/// apart: [`root_like`]).
fn import_graph() -> std::collections::BTreeMap<PathBuf, std::collections::BTreeSet<PathBuf>> {
    let mut graph =
        std::collections::BTreeMap::<PathBuf, std::collections::BTreeSet<PathBuf>>::new();
    for c in std::fs::read_dir(root().join("crates")).unwrap() {
        let c = c.unwrap().path();
        let src = if c.join("src").is_dir() {
            c.join("src")
        } else {
            c.clone()
        };
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        for f in files.iter().filter(|f| !root_like(f)) {
            let code = code_of(&std::fs::read_to_string(f).unwrap());
            let to = graph.entry(f.clone()).or_default();
            for p in named_paths(&code) {
                if let Some(t) = resolve(&src, f, &p, 0) {
                    if &t != f && !root_like(&t) {
                        to.insert(t);
                    }
                }
            }
        }
    }
    graph
}

/// The import cycles of `graph`, one per strongly connected component of more than one file
/// (Tarjan's algorithm), each as a shortest cycle through the component's first file:
/// `a.rs -> b.rs -> c.rs -> a.rs`.
fn import_cycles(
    graph: &std::collections::BTreeMap<PathBuf, std::collections::BTreeSet<PathBuf>>,
) -> Vec<Vec<PathBuf>> {
    use std::collections::{BTreeMap, BTreeSet, VecDeque};
    struct Tarjan<'a> {
        graph: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on_stack: BTreeSet<&'a PathBuf>,
        components: Vec<Vec<&'a PathBuf>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a PathBuf) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            self.on_stack.insert(v);
            for w in self.graph.get(v).into_iter().flatten() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let lw = self.low[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if self.on_stack.contains(w) {
                    let iw = self.index[w];
                    let lv = self.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
            if self.low[v] == self.index[v] {
                let mut comp = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on_stack.remove(w);
                    comp.push(w);
                    if w == v {
                        break;
                    }
                }
                self.components.push(comp);
            }
        }
    }
    let mut t = Tarjan {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        components: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    let mut cycles = Vec::new();
    for comp in t.components.iter().filter(|c| c.len() > 1) {
        let members: BTreeSet<&PathBuf> = comp.iter().copied().collect();
        let start = *members.iter().next().unwrap();
        // breadth first from `start` inside the component, back to `start`
        let mut came_from: BTreeMap<&PathBuf, &PathBuf> = BTreeMap::new();
        let mut queue = VecDeque::from([start]);
        let mut last = None;
        'search: while let Some(v) = queue.pop_front() {
            for w in graph.get(v).into_iter().flatten() {
                if w == start {
                    last = Some(v);
                    break 'search;
                }
                if members.contains(w) && !came_from.contains_key(w) {
                    came_from.insert(w, v);
                    queue.push_back(w);
                }
            }
        }
        let mut cycle = vec![start.clone()];
        let mut v = last.expect("a strongly connected component has a cycle");
        while v != start {
            cycle.push(v.clone());
            v = came_from[v];
        }
        cycle.push(start.clone());
        cycle.reverse();
        cycles.push(cycle);
    }
    cycles
}

/// No import cycle of any length between the files of a crate (issue 22 found pairs:
/// `cli/common.rs` and `outputs.rs`, `scene/src/keys.rs` and `schema.rs`; issue 44 found
/// longer ones the pair check missed: multibody `engine/state.rs` -> `scheme_state.rs` ->
/// `clamped.rs` -> `state.rs`, sdk `cosim/variables.rs` -> `network_cosim.rs` ->
/// `cosim/variables.rs` through `cosim`'s re-export). A crate root (`lib.rs`, `main.rs`) and a
/// folder's `mod.rs` declare their modules and are left out; an import through their
/// re-exports counts as an import of the file that defines the item.
#[test]
fn no_import_cycle_between_files() {
    let graph = import_graph();
    let edges: usize = graph.values().map(|s| s.len()).sum();
    // 100 or more today: a scan that finds fewer has stopped reading the imports
    assert!(
        edges > 100,
        "the scan found too few imports ({edges}): {graph:?}"
    );
    let rel = |p: &Path| p.strip_prefix(root()).unwrap().display().to_string();
    let cycles: Vec<String> = import_cycles(&graph)
        .iter()
        .map(|c| c.iter().map(|p| rel(p)).collect::<Vec<_>>().join(" -> "))
        .collect();
    assert!(
        cycles.is_empty(),
        "import cycles between files (break each by moving what two of its files share into \
         one that imports neither): {cycles:#?}"
    );
}

/// The cycle search on a made-up graph: a three-file cycle is found whole and a chain is not
/// a cycle.
#[test]
fn import_cycles_are_found_at_any_length() {
    let p = |s: &str| PathBuf::from(s);
    let mut g = std::collections::BTreeMap::new();
    let mut add = |a: &str, b: &str| {
        g.entry(p(a))
            .or_insert_with(std::collections::BTreeSet::new)
            .insert(p(b));
    };
    add("a.rs", "b.rs");
    add("b.rs", "c.rs");
    add("c.rs", "a.rs");
    add("c.rs", "d.rs");
    add("d.rs", "e.rs");
    let cycles = import_cycles(&g);
    assert_eq!(
        cycles,
        vec![vec![p("a.rs"), p("b.rs"), p("c.rs"), p("a.rs")]],
        "{cycles:?}"
    );
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

/// The project's text files (sources, documents, scenes, scripts) under `dir`, build
/// outputs and version control apart.
fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if p.is_dir() {
            if !["target", ".git", "__pycache__", "dist"].contains(&name.as_str()) {
                text_files(&p, out);
            }
        } else if ["rs", "md", "toml", "py", "sh", "c", "txt"]
            .iter()
            .any(|x| name.ends_with(&format!(".{x}")))
        {
            out.push(p);
        }
    }
}

/// Every file and its text (lossy), for the document checks below.
fn project_texts() -> Vec<(String, String)> {
    let mut files = Vec::new();
    text_files(root(), &mut files);
    files
        .iter()
        .map(|p| {
            let text = String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned();
            let rel = p.strip_prefix(root()).unwrap().display().to_string();
            (rel, text)
        })
        .collect()
}

/// Issue 44: a user who clones the project has the repository alone, so no file names a
/// path outside it (the README's MuJoCo comparison pointed at a folder beside the clone;
/// `bench/mujoco/brake.py` is the project's own now).
#[test]
fn no_file_names_a_path_outside_the_repository() {
    // joined at run time, so that neither this file nor its binary names them itself
    let outside = [
        ["..", "shared/"].join("/"),
        ["/work", "shared"].join("/"),
        ["/work", ".library"].join("/"),
    ];
    let found: Vec<String> = project_texts()
        .iter()
        .flat_map(|(f, text)| {
            outside
                .iter()
                .filter(|o| text.contains(o.as_str()))
                .map(move |o| format!("{f}: {o}"))
        })
        .collect();
    assert!(found.is_empty(), "paths outside the repository: {found:?}");
}

/// Issue 44: every section of docs/MODEL.md that a file cites ("MODEL.md section 8",
/// "MODEL.md sections 5 and 8") exists there (sections 8 and 9 were cited about 150 times
/// while the document stopped at 7).
#[test]
fn every_cited_model_section_exists() {
    let model = std::fs::read_to_string(root().join("docs/MODEL.md")).unwrap();
    let mut cited = std::collections::BTreeMap::<u32, String>::new();
    for (f, text) in project_texts() {
        let flat = text.replace(['\n', '/', '!'], " ");
        let flat = flat.split_whitespace().collect::<Vec<_>>().join(" ");
        for (i, _) in flat.match_indices("MODEL.md section") {
            let rest = flat[i + "MODEL.md section".len()..].trim_start_matches('s');
            // the numbers of `section 8`, `sections 1, 2 and 5` (not `section 8: 5000 N`)
            let mut words = rest.split_whitespace();
            while let Some(word) = words.next() {
                let Ok(n) = word
                    .trim_end_matches([',', ')', ';', ':', '.'])
                    .parse::<u32>()
                else {
                    break;
                };
                cited.entry(n).or_insert_with(|| f.clone());
                if !word.ends_with(',') && words.next() != Some("and") {
                    break;
                }
            }
        }
    }
    assert!(cited.len() >= 9, "too few cited sections found: {cited:?}");
    let missing: Vec<String> = cited
        .iter()
        .filter(|(n, _)| !model.contains(&format!("\n## {n}. ")))
        .map(|(n, f)| format!("section {n} (cited in {f})"))
        .collect();
    assert!(missing.is_empty(), "docs/MODEL.md lacks {missing:?}");
}

/// Issue 44: a citation of docs/DECISIONS.md by name (`docs/DECISIONS.md, "Thermal cost"`,
/// `DECISIONS.md ("Studies")`) names one of its section titles (the part before the
/// parenthesis is enough) or one of its bold points, so that regrouping and retitling the
/// document cannot leave a citation pointing nowhere.
#[test]
fn every_decisions_citation_names_a_section_or_point() {
    let doc = std::fs::read_to_string(root().join("docs/DECISIONS.md")).unwrap();
    let titles: Vec<&str> = doc
        .lines()
        .filter_map(|l| l.strip_prefix("### ").or(l.strip_prefix("## ")))
        .collect();
    let bold: Vec<&str> = doc.split("**").skip(1).step_by(2).collect();
    let mut checked = 0;
    let mut bad = Vec::new();
    for (f, text) in project_texts() {
        // the document itself, and this file, which names it in code
        if f == "docs/DECISIONS.md" || f == "tests/architecture.rs" {
            continue;
        }
        let flat: String = text
            .lines()
            .map(|l| l.trim().trim_start_matches(['/', '!', '#']).trim())
            .collect::<Vec<_>>()
            .join(" ");
        for (i, _) in flat.match_indices("DECISIONS") {
            let after = &flat[i + "DECISIONS".len()..];
            let after = after.strip_prefix(".md").unwrap_or(after);
            // `, "A"`, ` ("A")`, `, "A" and "B"`: the quoted names right after the file
            let Some(start) = after.find('"') else {
                continue;
            };
            let lead = &after[..start];
            if lead.len() > 4 || lead.contains(['.', ';']) {
                continue;
            }
            let mut rest = &after[start..];
            while let Some(q) = rest.strip_prefix('"') {
                let Some(end) = q.find('"') else { break };
                let name = &q[..end];
                checked += 1;
                if !titles.iter().chain(&bold).any(|t| t.starts_with(name)) {
                    bad.push(format!("{f}: {name:?}"));
                }
                rest = q[end + 1..].trim_start();
                rest = rest
                    .strip_prefix("and ")
                    .or(rest.strip_prefix(", "))
                    .unwrap_or(rest)
                    .trim_start();
            }
        }
    }
    assert!(checked >= 30, "too few citations found ({checked})");
    assert!(
        bad.is_empty(),
        "citations of docs/DECISIONS.md that name no section or point: {bad:#?}"
    );
}
