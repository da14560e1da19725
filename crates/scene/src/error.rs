//! Errors of scene loading: every problem of a scene, each with its key path, the bad value
//! and the rule it breaks.

use std::fmt;
use std::path::PathBuf;

/// One problem found in a scene: where (`key`), what was written (`value`) and which rule it
/// breaks (`rule`). Displayed as `key = value: rule`, or `key: rule` without a value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Key path as written in the file, array items by index: `discs[2].inertia_kg_m2`. For a
    /// TOML syntax error, the position instead: `line 3 column 7`.
    pub key: String,
    /// The offending value in TOML syntax (`-0.1`, `"dri"`), or `None` when the key is missing
    /// or unknown.
    pub value: Option<String>,
    /// The rule broken, e.g. `must be > 0` or `missing (required; ...)`.
    pub rule: String,
}

impl Problem {
    /// A problem with the value as written.
    pub(crate) fn new(
        key: impl Into<String>,
        value: Option<String>,
        rule: impl Into<String>,
    ) -> Self {
        Problem {
            key: key.into(),
            value,
            rule: rule.into(),
        }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.value {
            Some(v) => write!(f, "{} = {}: {}", self.key, v, self.rule),
            None => write!(f, "{}: {}", self.key, self.rule),
        }
    }
}

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    ///
    /// The I/O error is part of the message and not a `source()`, so that a chain of causes
    /// (`anyhow`'s `{:#}`) does not print it twice in one line.
    #[error("{}: cannot read the scene file: {error}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The scene was read but is not valid: every problem found, in file order as far as
    /// possible. Displayed one problem per line, each prefixed with the file name.
    #[error("{}", ProblemLines { origin, problems })]
    Invalid {
        /// File name used in messages.
        origin: String,
        /// Every problem found (never empty).
        problems: Vec<Problem>,
    },
}

impl SceneError {
    /// Every problem of an invalid scene (empty if the file could not be read).
    pub fn problems(&self) -> &[Problem] {
        match self {
            SceneError::Read { .. } => &[],
            SceneError::Invalid { problems, .. } => problems,
        }
    }
}

/// Display helper: `origin: problem` per line.
struct ProblemLines<'a> {
    origin: &'a str,
    problems: &'a [Problem],
}

impl fmt::Display for ProblemLines<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, p) in self.problems.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{}: {}", self.origin, p)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_lists_every_problem_on_its_own_line() {
        let e = SceneError::Invalid {
            origin: "scenes/x.toml".into(),
            problems: vec![
                Problem::new("discs[2].inertia_kg_m2", Some("-0.1".into()), "must be > 0"),
                Problem::new("simulation.duration_s", None, "missing (required)"),
            ],
        };
        assert_eq!(
            e.to_string(),
            "scenes/x.toml: discs[2].inertia_kg_m2 = -0.1: must be > 0\n\
             scenes/x.toml: simulation.duration_s: missing (required)"
        );
        assert_eq!(e.problems().len(), 2);
    }
}
