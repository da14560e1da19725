//! Study files: TOML -> a validated [`Study`], every problem at once; and the cases of a
//! study, case `k` a pure function of the file and `k` ([`Study::case`]).

use crate::rng::Stream;
use crate::tolerance::{self, PitchDistribution};
use clutchpack_scene::{EngineChoice, Override, Scene, SceneError};
use sha2::{Digest, Sha256};
use std::fmt;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// One problem of a study file: the key path, the value as written (if any) and the rule.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Key path in the study file (`factor[1].log`), or `line L column C` for a syntax error.
    pub key: String,
    /// The offending value in TOML syntax, `None` when missing or unknown.
    pub value: Option<String>,
    /// The rule broken.
    pub rule: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.value {
            Some(v) => write!(f, "{} = {}: {}", self.key, v, self.rule),
            None => write!(f, "{}: {}", self.key, self.rule),
        }
    }
}

/// Why a study file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file cannot be read.
    #[error("{}: cannot read the study file: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Every problem found, one per line, each prefixed with the file name.
    #[error("{}", lines(file, problems))]
    Invalid {
        /// The study file as named.
        file: String,
        /// The problems.
        problems: Vec<Problem>,
    },
}

fn lines(file: &str, problems: &[Problem]) -> String {
    problems
        .iter()
        .map(|p| format!("{file}: {p}"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Where the members of an ensemble start (initial relative angle of each disc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Placement {
    /// As in the scene.
    Scene,
    /// Member `m` of `M`: every disc at the fraction `-1 + (2m + 1) / M` of 90 % of its free
    /// play (members evenly spread, none in contact).
    Spread,
    /// Each disc at a uniform random fraction in `[-0.9, 0.9]` of its free play.
    Random,
}

/// The drive phase of ensemble members (`drive.phase_deg` of a sine drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// As in the scene.
    Scene,
    /// Member `m` of `M` at `360 m / M` deg.
    Spread,
    /// Uniform in `[0, 360)` deg.
    Random,
}

/// A random draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Distribution {
    /// Uniform in `[low, high)`.
    Uniform {
        /// Lower bound, in the key's unit.
        low: f64,
        /// Upper bound, in the key's unit.
        high: f64,
    },
    /// Normal.
    Normal {
        /// Mean, in the key's unit.
        mean: f64,
        /// Standard deviation, in the key's unit.
        std: f64,
    },
    /// Normal conditioned on `[low, high]`.
    TruncatedNormal {
        /// Mean of the untruncated normal.
        mean: f64,
        /// Its standard deviation.
        std: f64,
        /// Lower bound.
        low: f64,
        /// Upper bound.
        high: f64,
    },
}

/// A design factor: a scene key (or `spacing.grade`) and its levels.
#[derive(Debug, Clone, PartialEq)]
pub struct Factor {
    /// Scene key path (`--set` syntax) or `spacing.grade`.
    pub key: String,
    /// The levels, in the key's unit.
    pub levels: Vec<f64>,
}

/// A key drawn at random for every case.
#[derive(Debug, Clone, PartialEq)]
pub struct RandomFactor {
    /// Scene key path.
    pub key: String,
    /// The distribution.
    pub dist: Distribution,
}

/// Per-tooth spacing errors from an ISO 1328-1:2013 tolerance class ([`crate::tolerance`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Spacing {
    /// Tolerance class 1..=11 (a design factor `spacing.grade` overrides it).
    pub grade: u32,
    /// The discs (indexes from 0) whose splines get errors.
    pub discs: Option<Vec<usize>>,
    /// How single pitch deviations are spread in the tolerance.
    pub distribution: PitchDistribution,
}

/// The per-disc statistics a study can keep (from `clutchpack_analysis::DiscStats`, plus
/// `peak_abs_n`, the larger of the two peaks' magnitudes, always kept), and the teeth's
/// fatigue as `clutchpack run` assesses it: `damage_rate_per_h` (1/h), `life_h` (h, empty
/// when unlimited), `eq_load_range_n` (N).
pub const STATS: [&str; 9] = [
    "peak_abs_n",
    "max_positive_n",
    "max_negative_n",
    "p99_abs_n",
    "mean_top10_abs_n",
    "impacts",
    "damage_rate_per_h",
    "life_h",
    "eq_load_range_n",
];

/// A validated study.
#[derive(Debug, Clone)]
pub struct Study {
    /// Name (default: the file stem).
    pub name: String,
    /// The study file as named on the command line.
    pub file: String,
    /// The base scene file (resolved against the study file's folder).
    pub scene_path: PathBuf,
    /// Its text.
    pub scene_text: String,
    /// The engine the study names (`study.engine`), if it names one.
    pub engine: Option<EngineChoice>,
    /// Seed of every random draw.
    pub seed: u64,
    /// Ensemble members per design point.
    pub members: u64,
    /// Initial positions of the members.
    pub placement: Placement,
    /// Drive phase of the members.
    pub phase: Phase,
    /// Per-disc statistics kept ([`STATS`] names).
    pub outputs: Vec<String>,
    /// Fixed overrides of every case.
    pub set: Vec<Override>,
    /// Design factors (full factorial, the first varies slowest).
    pub factors: Vec<Factor>,
    /// Random draws.
    pub random: Vec<RandomFactor>,
    /// Spacing errors.
    pub spacing: Option<Spacing>,
    /// Hex SHA-256 (first 16 digits) of the study text and the scene text: parts carry it.
    pub hash: String,
}

/// One case: what it varies and how to build its scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Case id, `0..Study::cases()`.
    pub id: u64,
    /// Design point, `id / members`.
    pub design_point: u64,
    /// Ensemble member, `id % members`.
    pub member: u64,
    /// Values of [`Study::columns`], in order.
    pub values: Vec<f64>,
}

/// The RNG stream numbers of a case (see [`crate::rng`]).
const STREAM_RANDOM: u64 = 0;
const STREAM_PLACEMENT: u64 = 1 << 20;
const STREAM_PHASE: u64 = 2 << 20;
const STREAM_SPACING: u64 = 3 << 20;

/// The study key whose levels are spacing tolerance classes.
pub const GRADE_KEY: &str = "spacing.grade";

impl Study {
    /// Number of design points (product of the factors' level counts; 1 without factors).
    /// Saturates at `u64::MAX` (a parsed study has at most [`MAX_CASES`] cases).
    pub fn design_points(&self) -> u64 {
        self.factors
            .iter()
            .try_fold(1u64, |n, f| n.checked_mul(f.levels.len() as u64))
            .unwrap_or(u64::MAX)
    }

    /// Number of cases. Saturates at `u64::MAX` (a parsed study has at most [`MAX_CASES`]).
    pub fn cases(&self) -> u64 {
        self.design_points().saturating_mul(self.members)
    }

    /// The table columns that describe a case: the design factors, the random keys, then
    /// `initial_fraction` (with spread placement) and `drive.phase_deg` (when set).
    pub fn columns(&self) -> Vec<String> {
        let mut c: Vec<String> = self.factors.iter().map(|f| f.key.clone()).collect();
        c.extend(self.random.iter().map(|r| r.key.clone()));
        if self.placement == Placement::Spread {
            c.push("initial_fraction".into());
        }
        if self.phase != Phase::Scene {
            c.push("drive.phase_deg".into());
        }
        c
    }

    /// The level indexes of design point `p` (the last factor varies fastest).
    pub fn levels_of(&self, p: u64) -> Vec<usize> {
        let mut idx = vec![0; self.factors.len()];
        let mut rest = p;
        for (i, f) in self.factors.iter().enumerate().rev() {
            let n = f.levels.len() as u64;
            idx[i] = (rest % n) as usize;
            rest /= n;
        }
        idx
    }

    /// Case `id`: a pure function of the study and `id`.
    pub fn case(&self, id: u64) -> Case {
        let design_point = id / self.members;
        let member = id % self.members;
        let mut values: Vec<f64> = self
            .levels_of(design_point)
            .iter()
            .zip(&self.factors)
            .map(|(&l, f)| f.levels[l])
            .collect();
        let mut rng = Stream::new(self.seed, id, STREAM_RANDOM);
        for r in &self.random {
            values.push(match r.dist {
                Distribution::Uniform { low, high } => rng.uniform(low, high),
                Distribution::Normal { mean, std } => rng.normal(mean, std),
                Distribution::TruncatedNormal {
                    mean,
                    std,
                    low,
                    high,
                } => rng.truncated_normal(mean, std, low, high),
            });
        }
        if self.placement == Placement::Spread {
            values.push(-1.0 + (2 * member + 1) as f64 / self.members as f64);
        }
        match self.phase {
            Phase::Scene => {}
            Phase::Spread => values.push(360.0 * member as f64 / self.members as f64),
            Phase::Random => {
                values.push(Stream::new(self.seed, id, STREAM_PHASE).uniform(0.0, 360.0))
            }
        }
        Case {
            id,
            design_point,
            member,
            values,
        }
    }

    /// The scene of `case`, validated: the base scene with the study's `[set]`, the case's
    /// factor values and draws, its spacing errors and its initial positions.
    pub fn scene(&self, case: &Case) -> Result<Scene, SceneError> {
        let mut sets = self.set.clone();
        let mut grade = self.spacing.as_ref().map(|s| s.grade);
        for (key, &v) in self.columns().iter().zip(&case.values) {
            if key == GRADE_KEY {
                grade = Some(v as u32);
            } else if key != "initial_fraction" {
                sets.push(Override {
                    key: key.clone(),
                    value: number_text(v),
                });
            }
        }
        let base_dir = self.scene_path.parent().unwrap_or(Path::new(""));
        let origin = self.scene_path.display().to_string();
        let mut scene = clutchpack_scene::parse(&self.scene_text, &origin, base_dir, &sets)?;
        if let (Some(sp), Some(grade)) = (&self.spacing, grade) {
            for (i, d) in scene.pack.discs.iter().enumerate() {
                if sp.discs.as_ref().is_some_and(|l| !l.contains(&i)) {
                    continue;
                }
                let mut rng = Stream::new(self.seed, case.id, STREAM_SPACING + i as u64);
                let e = tolerance::spacing_errors_m(
                    grade,
                    d.spline.teeth,
                    d.spline.pitch_radius_m,
                    sp.distribution,
                    &mut rng,
                );
                let list: Vec<String> = e.iter().map(|x| number_text(*x)).collect();
                sets.push(Override {
                    key: format!("discs[{i}].tooth_spacing_errors_m"),
                    value: format!("[{}]", list.join(", ")),
                });
            }
            scene = clutchpack_scene::parse(&self.scene_text, &origin, base_dir, &sets)?;
        }
        match self.placement {
            Placement::Scene => {}
            Placement::Spread => {
                for d in scene.pack.discs.iter_mut() {
                    d.initial_rel_angle_rad =
                        clutchpack_model::ensemble_angle_rad(d, case.member, self.members);
                }
            }
            Placement::Random => {
                let mut rng = Stream::new(self.seed, case.id, STREAM_PLACEMENT);
                for d in scene.pack.discs.iter_mut() {
                    d.initial_rel_angle_rad = rng.uniform(-0.9, 0.9) * d.start_free_play_rad();
                }
            }
        }
        Ok(scene)
    }
}

/// A number as TOML: integers without a fraction (`154`), else the shortest round-trip form
/// (`0.2`, `2.5e-5` where the decimal form would be long).
pub fn number_text(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        let plain = format!("{v}");
        if plain.len() <= 12 {
            plain
        } else {
            format!("{v:e}")
        }
    }
}

/// Reads and validates a study file.
pub fn load(path: &Path) -> Result<Study, SpecError> {
    let text = clutchpack_scene::read_input(path).map_err(|source| SpecError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse(
        &text,
        &path.display().to_string(),
        path.parent().unwrap_or(Path::new("")),
    )
}

/// Reads a TOML value as written.
fn shown(v: &Value) -> String {
    match v {
        Value::Table(_) => "{...}".to_string(),
        other => other.to_string(),
    }
}

/// Collects problems while walking the study document.
struct Ck {
    problems: Vec<Problem>,
}

impl Ck {
    fn bad(&mut self, key: &str, value: Option<&Value>, rule: impl Into<String>) {
        self.problems.push(Problem {
            key: key.to_string(),
            value: value.map(shown),
            rule: rule.into(),
        });
    }

    fn unknown(&mut self, prefix: &str, t: &Table, known: &[&str]) {
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

    fn number(&mut self, key: &str, v: Option<&Value>) -> Option<f64> {
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

    fn required_number(&mut self, key: &str, v: Option<&Value>) -> Option<f64> {
        if v.is_none() {
            self.bad(key, None, "missing (required number)");
        }
        self.number(key, v)
    }

    fn string<'a>(&mut self, key: &str, v: Option<&'a Value>) -> Option<&'a str> {
        match v {
            None => None,
            Some(Value::String(s)) => Some(s),
            Some(other) => {
                self.bad(key, Some(other), "must be a string");
                None
            }
        }
    }

    fn choice(&mut self, key: &str, v: Option<&Value>, options: &[&str]) -> Option<usize> {
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
    fn count(&mut self, key: &str, v: Option<&Value>, min: u64, max: u64) -> Option<u64> {
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

    fn table<'a>(&mut self, key: &str, v: Option<&'a Value>) -> Option<&'a Table> {
        match v {
            None => None,
            Some(Value::Table(t)) => Some(t),
            Some(other) => {
                self.bad(key, Some(other), "must be a table");
                None
            }
        }
    }

    fn tables<'a>(&mut self, key: &str, v: Option<&'a Value>) -> Vec<&'a Table> {
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

fn join(prefix: &str, k: &str) -> String {
    if prefix.is_empty() {
        k.to_string()
    } else {
        format!("{prefix}.{k}")
    }
}

/// What a study name may be: it names the Slurm jobs, the Kubernetes Jobs (a DNS label once
/// lowercased) and the default output folder, so it is an identifier, not text.
pub const NAME_RULE: &str =
    "1 to 63 letters, digits, '-', '_' or '.', not starting with '-' or '.'";

/// Whether `s` follows [`NAME_RULE`].
pub fn is_study_name(s: &str) -> bool {
    (1..=63).contains(&s.len())
        && !s.starts_with(['-', '.'])
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
}

/// The most cases a study may have (indexes are u64, but a table of more rows than this is not
/// what a study file is for).
pub const MAX_CASES: u64 = 100_000_000;

/// The most levels one factor may have (`linear`/`log` counts; the levels are held in memory).
pub const MAX_LEVELS: u64 = 1_000_000;

/// Validates study text. `file` names the file in messages, `dir` is the folder that the
/// scene path is relative to. Every problem is reported at once, including those the scene
/// finds with the factors' levels applied.
pub fn parse(text: &str, file: &str, dir: &Path) -> Result<Study, SpecError> {
    let invalid = |problems| SpecError::Invalid {
        file: file.to_string(),
        problems,
    };
    let doc: Table = text.parse().map_err(|e: toml::de::Error| {
        let key = match e.span() {
            Some(s) => {
                let before = &text[..s.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                format!("line {line} column {col}")
            }
            None => "file".to_string(),
        };
        invalid(vec![Problem {
            key,
            value: None,
            rule: e.message().to_string(),
        }])
    })?;
    let mut ck = Ck {
        problems: Vec::new(),
    };
    ck.unknown(
        "",
        &doc,
        &["study", "ensemble", "set", "factor", "random", "spacing"],
    );

    // [study]
    let empty = Table::new();
    let st = ck.table("study", doc.get("study")).unwrap_or(&empty);
    if doc.get("study").is_none() {
        ck.bad(
            "study",
            None,
            "missing (required table with at least `scene`)",
        );
    }
    ck.unknown("study", st, &["name", "scene", "engine", "seed", "outputs"]);
    let name = match ck.string("study.name", st.get("name")) {
        Some(n) => {
            if !is_study_name(n) {
                ck.bad("study.name", st.get("name"), format!("must be {NAME_RULE}"));
            }
            n.to_string()
        }
        None => {
            let stem = Path::new(file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "study".into());
            if st.get("name").is_none() && !is_study_name(&stem) {
                ck.bad(
                    "study.name",
                    None,
                    format!(
                        "missing, and the file name {stem:?} it defaults to is not a study \
                         name: set study.name ({NAME_RULE})"
                    ),
                );
            }
            stem
        }
    };
    let scene_rel = ck.string("study.scene", st.get("scene"));
    if st.get("scene").is_none() && doc.get("study").is_some() {
        ck.bad(
            "study.scene",
            None,
            "missing (required: the base scene file, relative to the study file)",
        );
    }
    let engine = ck
        .choice("study.engine", st.get("engine"), &EngineChoice::names())
        .map(|i| EngineChoice::ALL[i]);
    let seed = match st.get("seed") {
        None => 0,
        Some(Value::Integer(i)) if *i >= 0 => *i as u64,
        Some(other) => {
            ck.bad("study.seed", Some(other), "must be an integer >= 0");
            0
        }
    };
    let mut outputs: Vec<String> = STATS.iter().map(|s| s.to_string()).collect();
    if let Some(v) = st.get("outputs") {
        match v.as_array() {
            Some(a) => {
                let mut o = vec!["peak_abs_n".to_string()];
                for (i, x) in a.iter().enumerate() {
                    match x.as_str() {
                        Some(s) if STATS.contains(&s) => {
                            if !o.iter().any(|y| y == s) {
                                o.push(s.to_string())
                            }
                        }
                        _ => ck.bad(
                            &format!("study.outputs[{i}]"),
                            Some(x),
                            format!("must be one of: {}", STATS.join(", ")),
                        ),
                    }
                }
                outputs = o;
            }
            None => ck.bad(
                "study.outputs",
                Some(v),
                "must be an array of statistic names",
            ),
        }
    }

    // [ensemble]
    let en = ck.table("ensemble", doc.get("ensemble")).unwrap_or(&empty);
    ck.unknown(
        "ensemble",
        en,
        &["members", "initial_positions", "drive_phase"],
    );
    let members = ck
        .count("ensemble.members", en.get("members"), 1, MAX_CASES)
        .unwrap_or(1);
    let placement = match ck.choice(
        "ensemble.initial_positions",
        en.get("initial_positions"),
        &["scene", "spread", "random"],
    ) {
        Some(0) => Placement::Scene,
        Some(1) => Placement::Spread,
        Some(_) => Placement::Random,
        None if members > 1 && en.get("initial_positions").is_none() => Placement::Spread,
        None => Placement::Scene,
    };
    let phase = match ck.choice(
        "ensemble.drive_phase",
        en.get("drive_phase"),
        &["scene", "spread", "random"],
    ) {
        Some(1) => Phase::Spread,
        Some(2) => Phase::Random,
        _ => Phase::Scene,
    };

    // [set]
    let mut set = Vec::new();
    if let Some(t) = ck.table("set", doc.get("set")) {
        for (k, v) in t {
            set.push(Override {
                key: k.clone(),
                value: match v {
                    Value::String(s) => s.clone(),
                    other => other.to_string(),
                },
            });
        }
    }

    // [[factor]]
    let mut factors = Vec::new();
    for (i, f) in ck
        .tables("factor", doc.get("factor"))
        .into_iter()
        .enumerate()
    {
        let p = format!("factor[{i}]");
        ck.unknown(&p, f, &["key", "values", "linear", "log"]);
        let key = ck.string(&format!("{p}.key"), f.get("key"));
        if f.get("key").is_none() {
            ck.bad(
                &format!("{p}.key"),
                None,
                "missing (required: a scene key path or spacing.grade)",
            );
        }
        let given: Vec<&str> = ["values", "linear", "log"]
            .into_iter()
            .filter(|k| f.contains_key(*k))
            .collect();
        if given.len() != 1 {
            ck.bad(
                &p,
                None,
                format!(
                    "exactly one of values, linear, log is required (found {})",
                    if given.is_empty() {
                        "none".to_string()
                    } else {
                        given.join(", ")
                    }
                ),
            );
            continue;
        }
        let kind = given[0];
        let vkey = format!("{p}.{kind}");
        let v = &f[kind];
        let levels = match kind {
            "values" => match v.as_array() {
                Some(a) if !a.is_empty() => {
                    let mut out = Vec::new();
                    for (j, x) in a.iter().enumerate() {
                        if let Some(n) = ck.number(&format!("{vkey}[{j}]"), Some(x)) {
                            out.push(n)
                        }
                    }
                    (out.len() == a.len()).then_some(out)
                }
                _ => {
                    ck.bad(&vkey, Some(v), "must be a non-empty array of numbers");
                    None
                }
            },
            _ => range(&mut ck, &vkey, v, kind == "log"),
        };
        if let (Some(key), Some(levels)) = (key, levels) {
            if key == GRADE_KEY {
                for (j, g) in levels.iter().enumerate() {
                    if g.fract() != 0.0 || !(1..=11i64).contains(&(*g as i64)) {
                        ck.bad(
                            &format!("{vkey}[{j}]"),
                            Some(&Value::Float(*g)),
                            "a tolerance class of ISO 1328-1:2013 must be an integer in 1..=11",
                        );
                    }
                }
                if !doc.contains_key("spacing") {
                    ck.bad(
                        &format!("{p}.key"),
                        Some(&Value::String(key.into())),
                        "spacing.grade needs a [spacing] table (which discs, which distribution)",
                    );
                }
            }
            if factors.iter().any(|x: &Factor| x.key == key) {
                ck.bad(
                    &format!("{p}.key"),
                    Some(&Value::String(key.into())),
                    "each key may be a factor once",
                );
            }
            factors.push(Factor {
                key: key.to_string(),
                levels,
            });
        }
    }

    // [[random]]
    let mut random = Vec::new();
    for (i, r) in ck
        .tables("random", doc.get("random"))
        .into_iter()
        .enumerate()
    {
        let p = format!("random[{i}]");
        ck.unknown(&p, r, &["key", "dist", "low", "high", "mean", "std"]);
        let key = ck.string(&format!("{p}.key"), r.get("key"));
        if r.get("key").is_none() {
            ck.bad(
                &format!("{p}.key"),
                None,
                "missing (required: a scene key path)",
            );
        }
        let dk = format!("{p}.dist");
        if r.get("dist").is_none() {
            ck.bad(
                &dk,
                None,
                "missing (required: uniform, normal or truncated_normal)",
            );
        }
        let kind = ck.choice(
            &dk,
            r.get("dist"),
            &["uniform", "normal", "truncated_normal"],
        );
        let num = |ck: &mut Ck, k: &str| ck.required_number(&format!("{p}.{k}"), r.get(k));
        let dist = match kind {
            Some(0) => match (num(&mut ck, "low"), num(&mut ck, "high")) {
                (Some(low), Some(high)) if low < high => Some(Distribution::Uniform { low, high }),
                (Some(_), Some(_)) => {
                    ck.bad(&format!("{p}.high"), r.get("high"), "must be > low");
                    None
                }
                _ => None,
            },
            Some(1) => match (num(&mut ck, "mean"), num(&mut ck, "std")) {
                (Some(mean), Some(std)) if std > 0.0 => Some(Distribution::Normal { mean, std }),
                (Some(_), Some(_)) => {
                    ck.bad(&format!("{p}.std"), r.get("std"), "must be > 0");
                    None
                }
                _ => None,
            },
            Some(_) => {
                let (m, s, l, h) = (
                    num(&mut ck, "mean"),
                    num(&mut ck, "std"),
                    num(&mut ck, "low"),
                    num(&mut ck, "high"),
                );
                match (m, s, l, h) {
                    (Some(mean), Some(std), Some(low), Some(high)) => {
                        let mut ok = true;
                        if std <= 0.0 {
                            ck.bad(&format!("{p}.std"), r.get("std"), "must be > 0");
                            ok = false;
                        }
                        if low >= high {
                            ck.bad(&format!("{p}.high"), r.get("high"), "must be > low");
                            ok = false;
                        } else if std > 0.0 && (low - mean > 4.0 * std || mean - high > 4.0 * std) {
                            ck.bad(&format!("{p}.low"), r.get("low"), "the interval [low, high] must come within 4 std of the mean (else almost every draw is rejected)");
                            ok = false;
                        }
                        ok.then_some(Distribution::TruncatedNormal {
                            mean,
                            std,
                            low,
                            high,
                        })
                    }
                    _ => None,
                }
            }
            None => None,
        };
        if let (Some(key), Some(dist)) = (key, dist) {
            if factors.iter().any(|f| f.key == key)
                || random.iter().any(|x: &RandomFactor| x.key == key)
            {
                ck.bad(
                    &format!("{p}.key"),
                    Some(&Value::String(key.into())),
                    "each key may be a factor or a random draw once",
                );
            }
            random.push(RandomFactor {
                key: key.to_string(),
                dist,
            });
        }
    }

    // [spacing]
    let spacing = ck.table("spacing", doc.get("spacing")).map(|t| {
        ck.unknown(
            "spacing",
            t,
            &["standard", "grade", "discs", "distribution"],
        );
        if let Some(s) = t.get("standard") {
            if s.as_str() != Some("ISO 1328-1:2013") {
                ck.bad(
                    "spacing.standard",
                    Some(s),
                    "must be \"ISO 1328-1:2013\" (the only standard implemented)",
                );
            }
        }
        let grade_factor = factors.iter().any(|f| f.key == GRADE_KEY);
        let grade = match t.get("grade") {
            Some(Value::Integer(g)) if (1..=11i64).contains(g) => *g as u32,
            Some(other) => {
                ck.bad(
                    "spacing.grade",
                    Some(other),
                    "must be a tolerance class of ISO 1328-1:2013, an integer in 1..=11",
                );
                5
            }
            None if grade_factor => 5,
            None => {
                ck.bad(
                    "spacing.grade",
                    None,
                    "missing (required unless a factor varies spacing.grade)",
                );
                5
            }
        };
        let discs = t.get("discs").and_then(|v| match v.as_array() {
            Some(a) => {
                let mut out = Vec::new();
                for (j, x) in a.iter().enumerate() {
                    match x.as_integer() {
                        Some(i) if i >= 0 => out.push(i as usize),
                        _ => ck.bad(
                            &format!("spacing.discs[{j}]"),
                            Some(x),
                            "must be a disc index >= 0 (from 0, in scene order)",
                        ),
                    }
                }
                Some(out)
            }
            None => {
                ck.bad(
                    "spacing.discs",
                    Some(v),
                    "must be an array of disc indexes (default: every disc)",
                );
                None
            }
        });
        let distribution = match ck.choice(
            "spacing.distribution",
            t.get("distribution"),
            &["truncated_normal", "uniform"],
        ) {
            Some(1) => PitchDistribution::Uniform,
            _ => PitchDistribution::TruncatedNormal,
        };
        Spacing {
            grade,
            discs,
            distribution,
        }
    });

    let mut study = Study {
        name,
        file: file.to_string(),
        scene_path: scene_rel.map(|s| dir.join(s)).unwrap_or_default(),
        scene_text: String::new(),
        engine,
        seed,
        members,
        placement,
        phase,
        outputs,
        set,
        factors,
        random,
        spacing,
        hash: String::new(),
    };
    if study.cases() > MAX_CASES {
        let mut terms: Vec<String> = study
            .factors
            .iter()
            .map(|f| format!("{} ({})", f.levels.len(), f.key))
            .collect();
        terms.push(format!("{} (ensemble.members)", study.members));
        let total = match study.cases() {
            u64::MAX => "more than 2^64".to_string(),
            n => n.to_string(),
        };
        ck.bad(
            "factor",
            None,
            format!(
                "{} = {total} cases; a study may have at most {MAX_CASES}",
                terms.join(" x ")
            ),
        );
    }
    if scene_rel.is_some() {
        match clutchpack_scene::read_input(&study.scene_path) {
            Ok(t) => study.scene_text = t,
            Err(e) => ck.bad(
                "study.scene",
                st.get("scene"),
                format!("cannot read {}: {e}", study.scene_path.display()),
            ),
        }
    }
    if !ck.problems.is_empty() {
        return Err(invalid(ck.problems));
    }
    // The scene with each level of each factor (the others at their first level), member 0,
    // and with each random key at its distribution's centre: every key and value the scene
    // rejects is named here, before any case runs.
    let mut probes: Vec<(String, Option<String>, Case)> =
        vec![("study.scene".into(), None, study.case(0))];
    for (i, f) in study.factors.iter().enumerate() {
        for j in probe_levels(&f.levels) {
            let l = f.levels[j];
            let mut c = study.case(0);
            c.values[i] = l;
            probes.push((
                format!("factor[{i}].levels[{j}] ({})", f.key),
                Some(number_text(l)),
                c,
            ));
        }
    }
    // ... and the study's engine must be able to run each of them (`clutchpack check
    // --engine`'s rule): a study of spacing errors on the reference engine would only fail
    // every case.
    let engine = study.engine;
    let origin = study.scene_path.display().to_string();
    for (k, (p, value, case)) in probes.into_iter().enumerate() {
        let checked = study.scene(&case).and_then(|scene| {
            if k == 0 {
                spacing_discs_exist(&mut ck, &study, &scene);
            }
            scene.engine(engine, &origin).map(|_| ())
        });
        if let Err(e) = checked {
            for sp in scene_problems(&e) {
                ck.bad_text(&p, value.clone(), format!("the scene rejects it: {sp}"));
            }
        }
    }
    if !ck.problems.is_empty() {
        ck.problems.dedup();
        return Err(invalid(ck.problems));
    }
    let mut h = Sha256::new();
    h.update(text.as_bytes());
    h.update([0u8]);
    h.update(study.scene_text.as_bytes());
    study.hash = h.finalize()[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    Ok(study)
}

/// The most levels of one factor whose scenes the validation builds (each is parsed and
/// validated in full); a longer list is probed at this many evenly spaced levels, its
/// smallest and largest among them.
const MAX_PROBED_LEVELS: usize = 1000;

/// Indexes of the levels of one factor that the validation probes: all of them up to
/// [`MAX_PROBED_LEVELS`], else that many evenly spaced ones plus the smallest and the largest
/// (a scene's rules are bounds, which a range's extremes test).
fn probe_levels(levels: &[f64]) -> Vec<usize> {
    let n = levels.len();
    if n <= MAX_PROBED_LEVELS {
        return (0..n).collect();
    }
    let mut idx: Vec<usize> = (0..MAX_PROBED_LEVELS)
        .map(|k| k * (n - 1) / (MAX_PROBED_LEVELS - 1))
        .collect();
    let by = |a: &usize, b: &usize| levels[*a].total_cmp(&levels[*b]);
    idx.extend((0..n).min_by(by));
    idx.extend((0..n).max_by(by));
    idx.sort_unstable();
    idx.dedup();
    idx
}

/// `spacing.discs` must name discs of the scene.
fn spacing_discs_exist(ck: &mut Ck, study: &Study, scene: &Scene) {
    let n = scene.pack.discs.len();
    let Some(list) = study.spacing.as_ref().and_then(|sp| sp.discs.as_ref()) else {
        return;
    };
    for (j, &i) in list.iter().enumerate() {
        if i >= n {
            ck.bad_text(
                &format!("spacing.discs[{j}]"),
                Some(i.to_string()),
                format!(
                    "must be a disc index of the scene, 0..={} (it has {n} discs)",
                    n.saturating_sub(1)
                ),
            );
        }
    }
}

impl Ck {
    fn bad_text(&mut self, key: &str, value: Option<String>, rule: String) {
        self.problems.push(Problem {
            key: key.to_string(),
            value,
            rule,
        });
    }
}

/// The scene's problems as `key = value: rule` lines.
fn scene_problems(e: &SceneError) -> Vec<String> {
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
fn range(ck: &mut Ck, key: &str, v: &Value, log: bool) -> Option<Vec<f64>> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
    }

    fn study(text: &str) -> Result<Study, SpecError> {
        parse(text, "t.toml", &scene_dir())
    }

    #[test]
    fn factorial_order_ranges_and_members() {
        let s = study(
            r#"
[study]
scene = "hu-table2.toml"
seed = 5
[ensemble]
members = 3
[[factor]]
key = "defaults.oil.film_thickness_m"
values = [0, 25e-6]
[[factor]]
key = "drive.amplitude_rad_s"
log = [1.0, 100.0, 3]
[[random]]
key = "defaults.drag_n_m_s_rad"
dist = "uniform"
low = 0.005
high = 0.02
"#,
        )
        .unwrap();
        assert_eq!(s.design_points(), 6);
        assert_eq!(s.cases(), 18);
        assert!((s.factors[1].levels[1] - 10.0).abs() < 1e-12);
        // case 10: design point 3 = (film level 1, amplitude level 0), member 1
        let c = s.case(10);
        assert_eq!((c.design_point, c.member), (3, 1));
        assert_eq!(c.values[0], 25e-6);
        assert_eq!(c.values[1], 1.0);
        assert!((0.005..0.02).contains(&c.values[2]));
        // initial fraction of member 1 of 3: -1 + 3/3 = 0
        assert_eq!(c.values[3], 0.0);
        assert_eq!(s.case(10), s.case(10));
        assert_ne!(s.case(10).values[2], s.case(11).values[2]);
        let sc = s.scene(&s.case(17)).unwrap();
        assert_eq!(sc.pack.discs[0].law.oil.thickness_m, 25e-6);
    }

    #[test]
    fn every_problem_at_once_with_key_value_rule() {
        let e = study(
            r#"
[study]
scene = "hu-table2.toml"
engine = "fast"
[ensemble]
members = 0
[[factor]]
key = "defaults.oil.film_thickness_m"
log = [0, 1e-4, 3]
[[factor]]
key = "defaults.inertia_kg_m2"
values = [0.1, -0.2]
[[random]]
key = "drive.amplitude_rad_s"
dist = "normal"
mean = 4.0
std = -1
"#,
        )
        .unwrap_err()
        .to_string();
        for want in [
            "t.toml: study.engine = \"fast\": must be one of: reference, multibody",
            "ensemble.members = 0: must be an integer in 1..=100000000",
            "factor[0].log = [0, 0.0001, 3]: a log range needs from > 0",
            "random[0].std = -1: must be > 0",
        ] {
            assert!(e.contains(want), "missing {want:?} in:\n{e}");
        }
        // the scene's rule about a level, found before any case runs (after the study's own
        // problems are fixed)
        let e = study(
            "[study]\nscene = \"hu-table2.toml\"\n[[factor]]\nkey = \"defaults.inertia_kg_m2\"\nvalues = [0.1, -0.2]\n",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("factor[0].levels[1] (defaults.inertia_kg_m2) = -0.2"),
            "{e}"
        );
        assert!(e.contains("must be > 0"), "{e}");
    }

    #[test]
    fn spacing_errors_reach_the_scene() {
        let s = study(
            r#"
[study]
scene = "hu-table2.toml"
engine = "multibody"
[spacing]
grade = 8
[[factor]]
key = "spacing.grade"
values = [4, 9]
"#,
        )
        .unwrap();
        let e4 = s.scene(&s.case(0)).unwrap().pack.discs[0]
            .tooth_spacing_errors_m
            .clone();
        let e9 = s.scene(&s.case(1)).unwrap().pack.discs[0]
            .tooth_spacing_errors_m
            .clone();
        assert_eq!(e4.len(), 154);
        let rms = |e: &[f64]| (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
        // same stream, deviations scaled by sqrt(2)^5 and rounded tolerances: ratio ~ 5.7
        assert!(rms(&e9) > 4.0 * rms(&e4), "{} {}", rms(&e9), rms(&e4));
    }
}
