//! `--set KEY=VALUE` overrides, applied to the parsed TOML document before validation.
//!
//! `KEY` is a dotted path as in the file; items of an array of tables are picked by index,
//! counted from 0: `discs[1].oil.film_thickness_m`. Absent tables on the way are created
//! (`--set shaft.mode=inertial` works without a `[shaft]` table); an index past the end of an
//! array is an error. `VALUE` is read as a TOML value (`50e-6`, `true`, `"x"`,
//! `{ teeth = 3 }`); if it is not valid TOML it is taken as a string, so `--set
//! drive.kind=sine` needs no quotes. The key must exist in the scene schema.

use crate::catalog;
use crate::error::Problem;
use std::fmt;
use std::str::FromStr;
use toml::{Table, Value};

/// One `--set KEY=VALUE` override: `key` is a dotted key path (`discs[1].inertia_kg_m2`),
/// `value` the text after the first `=` (TOML syntax, else taken as a string). The value's
/// unit is the one named by the key's suffix.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Override {
    /// Dotted key path, array items by index: `discs[1].oil.film_thickness_m`.
    pub key: String,
    /// The value as typed, in TOML syntax or a bare string; unit as in the key's suffix.
    pub value: String,
}

/// Why a `--set` argument is not `KEY=VALUE`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OverrideError {
    /// No `=` in the argument.
    #[error("--set expects KEY=VALUE, got {0:?} (no '=')")]
    NoEquals(String),
    /// Nothing before the `=`.
    #[error("--set expects KEY=VALUE, got {0:?} (empty key)")]
    EmptyKey(String),
}

impl FromStr for Override {
    type Err = OverrideError;

    /// Splits at the first `=`; surrounding spaces of the key are dropped.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (key, value) = s
            .split_once('=')
            .ok_or_else(|| OverrideError::NoEquals(s.to_string()))?;
        let key = key.trim();
        if key.is_empty() {
            return Err(OverrideError::EmptyKey(s.to_string()));
        }
        Ok(Override {
            key: key.to_string(),
            value: value.to_string(),
        })
    }
}

impl fmt::Display for Override {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.key, self.value)
    }
}

/// One step of a key path.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Segment {
    Key(String),
    Index(usize),
}

/// `discs[1].oil.h_min_m` -> `[Key(discs), Index(1), Key(oil), Key(h_min_m)]`.
fn parse_path(path: &str) -> Result<Vec<Segment>, String> {
    let mut segs = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = match part.find('[') {
            Some(i) => part.split_at(i),
            None => (part, ""),
        };
        let name = name.trim();
        if name.is_empty() || name.contains(']') {
            return Err(format!(
                "invalid key path given with --set: {part:?} is not a key name"
            ));
        }
        segs.push(Segment::Key(name.to_string()));
        while !rest.is_empty() {
            let close = rest.find(']').ok_or_else(|| {
                format!("invalid key path given with --set: missing ']' in {part:?}")
            })?;
            let index: usize = rest[1..close].trim().parse().map_err(|_| {
                format!(
                    "invalid key path given with --set: {:?} is not an index (0, 1, ...)",
                    &rest[1..close]
                )
            })?;
            segs.push(Segment::Index(index));
            rest = &rest[close + 1..];
            if !rest.is_empty() && !rest.starts_with('[') {
                return Err(format!(
                    "invalid key path given with --set: unexpected {rest:?} after ']'"
                ));
            }
        }
    }
    Ok(segs)
}

/// The canonical text of a path: `discs[01].x` -> `discs[1].x`.
fn path_text(segs: &[Segment]) -> String {
    let mut s = String::new();
    for seg in segs {
        match seg {
            Segment::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Segment::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// Reads an override's value: TOML if it parses, else a number if Rust reads it as one (an
/// integer beyond TOML's 64-bit range, such as `10000000000000000000` from `--duration
/// 1e19`, is a float), else the text as a string.
fn parse_value(text: &str) -> Value {
    match format!("v = {text}").parse::<Table>() {
        Ok(mut t) if t.len() == 1 => t.remove("v").unwrap_or_else(|| Value::String(text.into())),
        _ => match text.trim().parse::<f64>() {
            Ok(x)
                if text
                    .trim()
                    .bytes()
                    .all(|b| b.is_ascii_digit() || b"+-.eE".contains(&b)) =>
            {
                Value::Float(x)
            }
            _ => Value::String(text.to_string()),
        },
    }
}

/// The rule text for a `--set` key that is not in the schema.
fn unknown_key_rule(norm: &str) -> String {
    // Find the deepest known table along the path, to say what it does take.
    let mut parent = norm;
    loop {
        let cut = parent.rfind(['.', '[']);
        parent = match cut {
            Some(i) => &parent[..i],
            None => "",
        };
        if catalog::is_known(parent) {
            break;
        }
    }
    if catalog::is_leaf(parent) {
        format!("unknown key given with --set ({parent} holds a value, not keys)")
    } else if catalog::is_array(parent) && !norm[parent.len()..].starts_with("[]") {
        format!(
            "unknown key given with --set ({parent} is an array of tables: pick an item by \
             index, e.g. {parent}[0].{})",
            catalog::children(&format!("{parent}[]"))
                .first()
                .unwrap_or(&"")
        )
    } else {
        format!(
            "unknown key given with --set ({})",
            catalog::expected_text(parent)
        )
    }
}

/// A numeric key of the schema, as a fit or a sweep varies it: its unit and its own range
/// rule (from its line in `keys.rs`), and its default if it has a number for one.
#[derive(Debug, Clone, Copy)]
pub struct NumericKey {
    /// The key's unit (`"s"`, `"N"`; `""` for none).
    pub unit: &'static str,
    /// The number an absent key means, if its default is a number.
    pub default: Option<f64>,
    rule: crate::schema::Rule,
}

impl NumericKey {
    /// `Ok` if `x` is finite and within the key's own rule, else the rule it breaks
    /// (`must be > 0`).
    pub fn check(&self, x: f64) -> Result<(), String> {
        if !x.is_finite() {
            return Err("must be a finite number".into());
        }
        self.rule.check(x, self.unit)
    }

    /// The key's rule as the reference prints it (`> 0`, `in [1, 100]`).
    pub fn rule_text(&self) -> String {
        self.rule.doc()
    }
}

/// The definition of the key at `path` (dotted, array items by index or `[]`:
/// `couplings[1].force.start_s`), if it is a single number; else why not (unknown, a table,
/// not a number), in the words `--set` uses.
pub fn numeric_key(path: &str) -> Result<NumericKey, String> {
    use crate::schema::{Dflt, Kind};
    let norm = catalog::normalize(path);
    let Some((_, key)) = catalog::all_keys().iter().find(|(p, _)| *p == norm) else {
        return Err(if catalog::is_known(&norm) {
            "a table, not a key holding a number".to_string()
        } else {
            unknown_key_rule(&norm).replace("given with --set ", "")
        });
    };
    match key.kind {
        Kind::Number(rule) => Ok(NumericKey {
            unit: key.unit,
            default: match key.default {
                Dflt::Num(x) => Some(x),
                _ => None,
            },
            rule,
        }),
        _ => Err("not a number key (a fit varies single real numbers)".to_string()),
    }
}

/// Applies every override to the document, in order. An override that cannot be applied is
/// reported (with its key and the word `--set`) and skipped; the others still apply.
/// Returns the canonical key path of each applied override, to mark later problems at those
/// keys as coming from `--set`.
pub(crate) fn apply(
    doc: &mut Table,
    overrides: &[Override],
    problems: &mut Vec<Problem>,
) -> Vec<String> {
    let mut applied = Vec::new();
    for o in overrides {
        let segs = match parse_path(&o.key) {
            Ok(s) => s,
            Err(rule) => {
                problems.push(Problem::new(&o.key, Some(o.value.clone()), rule));
                continue;
            }
        };
        let key = path_text(&segs);
        let norm = catalog::normalize(&key);
        if !catalog::is_known(&norm) {
            problems.push(Problem::new(key, None, unknown_key_rule(&norm)));
            continue;
        }
        let mut root = Value::Table(std::mem::take(doc));
        let result = set(&mut root, &segs, 0, parse_value(&o.value));
        if let Value::Table(t) = root {
            *doc = t;
        }
        match result {
            Ok(()) => applied.push(key),
            Err(rule) => problems.push(Problem::new(key, Some(o.value.clone()), rule)),
        }
    }
    applied
}

/// The value at the key path `key` (dotted, array items by index) in the TOML document
/// `doc`, if the document has it.
fn value_at<'a>(doc: &'a Table, segs: &[Segment]) -> Option<&'a Value> {
    let mut here: Option<&Value> = None;
    for (i, seg) in segs.iter().enumerate() {
        here = match (seg, here) {
            (Segment::Key(k), None) if i == 0 => doc.get(k),
            (Segment::Key(k), Some(Value::Table(t))) => t.get(k),
            (Segment::Index(n), Some(Value::Array(a))) => a.get(*n),
            _ => None,
        };
        here?;
    }
    here
}

/// The number the scene text `text` gives the key `key` (dotted, array items by index:
/// `couplings[1].force.start_s`): `Ok(None)` if the file does not set it, an error if the
/// text is not TOML, the path is malformed, or the value there is not a number.
pub fn number_in_text(text: &str, key: &str) -> Result<Option<f64>, String> {
    let doc: Table = text.parse().map_err(|e| format!("not TOML: {e}"))?;
    let segs = parse_path(key)?;
    match value_at(&doc, &segs) {
        None => Ok(None),
        Some(Value::Float(x)) => Ok(Some(*x)),
        Some(Value::Integer(i)) => Ok(Some(*i as f64)),
        Some(v) => Err(format!("{key} = {v} in the file is not a number")),
    }
}

/// `key` with every `[*]` replaced by each index of that array in the scene text `text`
/// whose item sets the rest of the path (`couplings[*].mu` -> `couplings[0].mu`,
/// `couplings[2].mu` when only those two items set `mu`); a key without `[*]` as it is. An
/// error if the text is not TOML, the path is malformed, or no item sets the key.
pub fn expand_wildcards(text: &str, key: &str) -> Result<Vec<String>, String> {
    if !key.contains("[*]") {
        return Ok(vec![key.to_string()]);
    }
    let doc: Table = text.parse().map_err(|e| format!("not TOML: {e}"))?;
    let mut keys = vec![String::new()];
    let parts: Vec<&str> = key.split("[*]").collect();
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        let mut next = Vec::new();
        for k in &keys {
            let prefix = format!("{k}{part}");
            if last {
                next.push(prefix);
                continue;
            }
            let segs = parse_path(&prefix)?;
            if let Some(Value::Array(items)) = value_at(&doc, &segs) {
                next.extend((0..items.len()).map(|n| format!("{prefix}[{n}]")));
            }
        }
        keys = next;
    }
    keys.retain(|k| parse_path(k).is_ok_and(|s| value_at(&doc, &s).is_some()));
    if keys.is_empty() {
        return Err(format!("no item of the scene sets {key}"));
    }
    Ok(keys)
}

/// The scene text `text` with the overrides applied, as TOML (the file's comments are not
/// kept): what a fit writes as its fitted scene. `origin` names the text in errors; every
/// override that cannot be applied is a problem of the error.
pub fn apply_to_text(
    text: &str,
    origin: &str,
    overrides: &[Override],
) -> Result<String, crate::SceneError> {
    let invalid = |problems| crate::SceneError::Invalid {
        origin: origin.to_string(),
        problems,
    };
    let mut doc: Table = text
        .parse()
        .map_err(|e: toml::de::Error| invalid(vec![Problem::new("", None, e.to_string())]))?;
    let mut problems = Vec::new();
    apply(&mut doc, overrides, &mut problems);
    if !problems.is_empty() {
        return Err(invalid(problems));
    }
    toml::to_string(&doc).map_err(|e| invalid(vec![Problem::new("", None, e.to_string())]))
}

/// Sets `segs[at..]` inside `container` to `value`.
fn set(container: &mut Value, segs: &[Segment], at: usize, value: Value) -> Result<(), String> {
    let here = || path_text(&segs[..at]);
    let last = at + 1 == segs.len();
    match &segs[at] {
        Segment::Key(k) => {
            let Value::Table(table) = container else {
                return Err(format!("cannot set with --set: {} is not a table", here()));
            };
            if last {
                table.insert(k.clone(), value);
                return Ok(());
            }
            if !table.contains_key(k) {
                match segs[at + 1] {
                    Segment::Key(_) => {
                        table.insert(k.clone(), Value::Table(Table::new()));
                    }
                    Segment::Index(i) => {
                        return Err(format!(
                            "cannot set with --set: index {i} past the end ({} has no entries)",
                            path_text(&segs[..=at])
                        ))
                    }
                }
            }
            let child = table.get_mut(k).expect("present or just inserted");
            set(child, segs, at + 1, value)
        }
        Segment::Index(i) => {
            let Value::Array(items) = container else {
                return Err(format!("cannot set with --set: {} is not an array", here()));
            };
            let len = items.len();
            let Some(item) = items.get_mut(*i) else {
                return Err(format!(
                    "cannot set with --set: index {i} past the end ({} has {len} entries)",
                    here()
                ));
            };
            if last {
                *item = value;
                Ok(())
            } else {
                set(item, segs, at + 1, value)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn override_parses_key_value() {
        let o: Override = "discs[1].inertia_kg_m2=0.2".parse().unwrap();
        assert_eq!(o.key, "discs[1].inertia_kg_m2");
        assert_eq!(o.value, "0.2");
        assert_eq!(o.to_string(), "discs[1].inertia_kg_m2=0.2");
        let o: Override = "name=a=b".parse().unwrap();
        assert_eq!(o.value, "a=b");
        assert!(matches!(
            "x".parse::<Override>(),
            Err(OverrideError::NoEquals(_))
        ));
        assert!(matches!(
            "=3".parse::<Override>(),
            Err(OverrideError::EmptyKey(_))
        ));
    }

    #[test]
    fn paths_parse() {
        assert_eq!(
            parse_path("discs[1].oil.h_min_m").unwrap(),
            vec![
                Segment::Key("discs".into()),
                Segment::Index(1),
                Segment::Key("oil".into()),
                Segment::Key("h_min_m".into())
            ]
        );
        assert!(parse_path("discs[x].a").is_err());
        assert!(parse_path("a..b").is_err());
        assert!(parse_path("discs[1").is_err());
        assert_eq!(path_text(&parse_path("discs[01].a").unwrap()), "discs[1].a");
    }

    #[test]
    fn values_are_toml_or_strings() {
        assert_eq!(parse_value("50e-6"), Value::Float(50e-6));
        assert_eq!(parse_value("200"), Value::Integer(200));
        assert_eq!(parse_value("sine"), Value::String("sine".into()));
        assert_eq!(parse_value("\"sine\""), Value::String("sine".into()));
        assert!(parse_value("nan").as_float().unwrap().is_nan());
        assert_eq!(
            parse_value("10000000000000000000"),
            Value::Float(1e19),
            "beyond i64: a float, not a string"
        );
        assert_eq!(parse_value("1e"), Value::String("1e".into()));
    }

    #[test]
    fn set_creates_tables_and_checks_indices() {
        let mut doc: Table = "[[discs]]\nname = \"a\"\n".parse().unwrap();
        let mut problems = Vec::new();
        let overrides: Vec<Override> = [
            "shaft.mode=inertial",
            "discs[0].oil.h_min_m=2e-6",
            "discs[1].name=b",
        ]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect();
        let applied = apply(&mut doc, &overrides, &mut problems);
        assert_eq!(applied, ["shaft.mode", "discs[0].oil.h_min_m"]);
        assert_eq!(doc["shaft"]["mode"].as_str(), Some("inertial"));
        assert_eq!(doc["discs"][0]["oil"]["h_min_m"].as_float(), Some(2e-6));
        assert_eq!(problems.len(), 1);
        assert_eq!(problems[0].key, "discs[1].name");
        assert!(problems[0].rule.contains("past the end"), "{}", problems[0]);
    }

    #[test]
    fn wildcards_expand_to_the_items_that_set_the_key() {
        let text = "[[c]]\nmu = 0.5\n[[c]]\nx = 1\n[[c]]\nmu = 2\n[c.f]\ns = 0.4\n";
        assert_eq!(
            expand_wildcards(text, "c[*].mu").unwrap(),
            ["c[0].mu", "c[2].mu"]
        );
        assert_eq!(expand_wildcards(text, "c[*].f.s").unwrap(), ["c[2].f.s"]);
        assert!(expand_wildcards(text, "c[*].nope").is_err());
        assert_eq!(number_in_text(text, "c[2].f.s").unwrap(), Some(0.4));
        assert_eq!(number_in_text(text, "c[0].mu").unwrap(), Some(0.5));
        assert_eq!(number_in_text(text, "c[1].mu").unwrap(), None);
        let text = "[[couplings]]\nmu = 0.5\n";
        let out = apply_to_text(text, "t", &["couplings[0].mu=0.25".parse().unwrap()]).unwrap();
        assert_eq!(number_in_text(&out, "couplings[0].mu").unwrap(), Some(0.25));
        assert!(apply_to_text(text, "t", &["couplings[0].nope=1".parse().unwrap()]).is_err());
    }

    #[test]
    fn unknown_keys_name_what_is_expected() {
        assert!(unknown_key_rule("simulation.durration_s").contains("duration_s"));
        assert!(unknown_key_rule("discs.name").contains("discs[0].name"));
        assert!(unknown_key_rule("simulation.duration_s.x").contains("holds a value"));
        assert!(unknown_key_rule("nope").contains("simulation"));
    }
}
