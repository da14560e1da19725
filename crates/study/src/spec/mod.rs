//! Study files: TOML -> a validated [`Study`], every problem at once; and the cases of a
//! study, case `k` a pure function of the file and `k` ([`Study::case`]).

mod check;
mod parse;
pub use parse::parse;

use crate::rng::Stream;
use crate::tolerance::{self, PitchDistribution};
use clutchpack_scene::{EngineChoice, Override, Scene, SceneError};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// One problem of a study file: the key path (`factor[1].log`, or `line L column C` for a
/// syntax error), the value as written (if any) and the rule; the scene crate's type, so that
/// a study's problems read as a scene's do.
pub use clutchpack_scene::Problem;

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
