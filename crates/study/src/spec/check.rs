//! The checker of a study file's values: every problem collected with its key and value, in
//! the words the scene crate uses.

use super::*;

/// Reads a TOML value as written.
pub(super) fn shown(v: &Value) -> String {
    match v {
        Value::Table(_) => "{...}".to_string(),
        other => other.to_string(),
    }
}

/// Collects problems while walking the study document.
pub(super) struct Ck {
    pub(super) problems: Vec<Problem>,
}

impl Ck {
    pub(super) fn bad(&mut self, key: &str, value: Option<&Value>, rule: impl Into<String>) {
        self.problems.push(Problem {
            key: key.to_string(),
            value: value.map(shown),
            rule: rule.into(),
        });
    }

    pub(super) fn unknown(&mut self, prefix: &str, t: &Table, known: &[&str]) {
        for k in t.keys() {
            if !known.contains(&k.as_str()) {
                self.bad(
                    &join(prefix, k),
                    None,
                    format!("unknown key (expected one of: {})", known.join(", ")),
                );
            }
        }
    }

    pub(super) fn number(&mut self, key: &str, v: Option<&Value>) -> Option<f64> {
        match v {
            None => None,
            Some(Value::Float(f)) if f.is_finite() => Some(*f),
            Some(Value::Integer(i)) => Some(*i as f64),
            Some(other) => {
                self.bad(key, Some(other), "must be a finite number");
                None
            }
        }
    }

    pub(super) fn required_number(&mut self, key: &str, v: Option<&Value>) -> Option<f64> {
        if v.is_none() {
            self.bad(key, None, "missing (required number)");
        }
        self.number(key, v)
    }

    pub(super) fn string<'a>(&mut self, key: &str, v: Option<&'a Value>) -> Option<&'a str> {
        match v {
            None => None,
            Some(Value::String(s)) => Some(s),
            Some(other) => {
                self.bad(key, Some(other), "must be a string");
                None
            }
        }
    }

    pub(super) fn choice(
        &mut self,
        key: &str,
        v: Option<&Value>,
        options: &[&str],
    ) -> Option<usize> {
        let s = self.string(key, v)?;
        match options.iter().position(|o| *o == s) {
            Some(i) => Some(i),
            None => {
                self.bad(key, v, format!("must be one of: {}", options.join(", ")));
                None
            }
        }
    }

    /// A count in `min..=max` (bounded before anything is allocated from it).
    pub(super) fn count(
        &mut self,
        key: &str,
        v: Option<&Value>,
        min: u64,
        max: u64,
    ) -> Option<u64> {
        match v {
            None => None,
            Some(Value::Integer(i))
                if u64::try_from(*i).is_ok_and(|i| (min..=max).contains(&i)) =>
            {
                Some(*i as u64)
            }
            Some(other) => {
                self.bad(
                    key,
                    Some(other),
                    format!("must be an integer in {min}..={max}"),
                );
                None
            }
        }
    }

    pub(super) fn table<'a>(&mut self, key: &str, v: Option<&'a Value>) -> Option<&'a Table> {
        match v {
            None => None,
            Some(Value::Table(t)) => Some(t),
            Some(other) => {
                self.bad(key, Some(other), "must be a table");
                None
            }
        }
    }

    pub(super) fn tables<'a>(&mut self, key: &str, v: Option<&'a Value>) -> Vec<&'a Table> {
        match v {
            None => Vec::new(),
            Some(Value::Array(a)) => a
                .iter()
                .enumerate()
                .filter_map(|(i, x)| match x {
                    Value::Table(t) => Some(t),
                    other => {
                        self.bad(&format!("{key}[{i}]"), Some(other), "must be a table");
                        None
                    }
                })
                .collect(),
            Some(other) => {
                self.bad(key, Some(other), "must be an array of tables ([[...]])");
                Vec::new()
            }
        }
    }
}

pub(super) fn join(prefix: &str, k: &str) -> String {
    if prefix.is_empty() {
        k.to_string()
    } else {
        format!("{prefix}.{k}")
    }
}

impl Ck {
    pub(super) fn bad_text(&mut self, key: &str, value: Option<String>, rule: String) {
        self.problems.push(Problem {
            key: key.to_string(),
            value,
            rule,
        });
    }
}

/// The scene's problems as `key = value: rule` lines.
pub(super) fn scene_problems(e: &SceneError) -> Vec<String> {
    match e {
        SceneError::Invalid { problems, .. } => problems
            .iter()
            .map(|p| match &p.value {
                Some(v) => format!("{} = {}: {}", p.key, v, p.rule),
                None => format!("{}: {}", p.key, p.rule),
            })
            .collect(),
        other => vec![other.to_string()],
    }
}

/// `linear = [from, to, count]` or `log = [from, to, count]`.
pub(super) fn range(ck: &mut Ck, key: &str, v: &Value, log: bool) -> Option<Vec<f64>> {
    let a = match v.as_array() {
        Some(a) if a.len() == 3 => a,
        _ => {
            ck.bad(key, Some(v), "must be [from, to, count]");
            return None;
        }
    };
    let from = ck.number(&format!("{key}[0]"), Some(&a[0]));
    let to = ck.number(&format!("{key}[1]"), Some(&a[1]));
    let count = ck.count(&format!("{key}[2]"), Some(&a[2]), 1, MAX_LEVELS);
    let (from, to, count) = (from?, to?, count?);
    if log && (from <= 0.0 || to <= 0.0) {
        ck.bad(key, Some(v), "a log range needs from > 0 and to > 0");
        return None;
    }
    if count == 1 {
        return Some(vec![from]);
    }
    Some(
        (0..count)
            .map(|i| {
                let s = i as f64 / (count - 1) as f64;
                if log {
                    (from.ln() + s * (to.ln() - from.ln())).exp()
                } else {
                    from + s * (to - from)
                }
            })
            .collect(),
    )
}
