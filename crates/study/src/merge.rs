//! Merging the parts of a study: completeness, the results table (CSV and Parquet) and the
//! per-design-point summary.
//!
//! # The results table (`results.parquet`, `results.csv`)
//! One row per case, in case order; columns:
//!
//! | column | Parquet type | meaning |
//! | --- | --- | --- |
//! | `case` | INT64 | case id, 0..cases |
//! | `design_point` | INT64 | design point, `case / members` |
//! | `member` | INT64 | ensemble member, `case % members` |
//! | one per study column | DOUBLE | each design factor's level, each random key's draw, `initial_fraction`, `drive.phase_deg`: in the key's unit |
//! | `<disc>.<stat>` | DOUBLE, nullable (`impacts`: INT64) | per disc (scene names, scene order) and kept statistic: `peak_abs_n` (N, the larger of `max_positive_n` and `-max_negative_n`), `max_positive_n` (N, >= 0), `max_negative_n` (N, <= 0), `p99_abs_n` (N), `mean_top10_abs_n` (N), `impacts` (count), the teeth's fatigue as `clutchpack run` assesses it: `damage_rate_per_h` (1/h), `life_h` (h; null when unlimited), `eq_load_range_n` (N); null for a failed case |
//! | `steps` | INT64 | accepted engine steps (0 if failed) |
//! | `rejected_steps` | INT64 | rejected engine steps |
//! | `simulated_s` | DOUBLE | simulated time reached, s |
//! | `error` | UTF8 string, nullable | why the case failed; null if it ran |
//!
//! Loads are per tooth in N, negative when the shaft leads (clutchpack_analysis).

use crate::part::{array_syntax, read_part, CaseRecord, PartError, StudyHeader};
use crate::stats::Summary;
use clutchpack_analysis::{csv_field, DiscStats};
use std::path::{Path, PathBuf};

/// A complete study: its header and every case's record, in case order.
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    /// The study.
    pub header: StudyHeader,
    /// Every case, ascending.
    pub records: Vec<CaseRecord>,
    /// Disc names (of the case with the most discs).
    pub discs: Vec<String>,
}

/// Why parts cannot be merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No part in the folder.
    #[error("{}: no study parts (part-*-of-*.json) in this folder{}", dir.display(), damaged_note(set_aside))]
    NoParts {
        /// The folder.
        dir: PathBuf,
        /// Damaged parts moved aside: (new path, why they did not parse).
        set_aside: Vec<(PathBuf, String)>,
    },
    /// A part file could not be read.
    #[error(transparent)]
    Part(#[from] PartError),
    /// Parts of different studies or shard counts.
    #[error("{}: parts of different studies or shard counts: {detail}", dir.display())]
    Mixed {
        /// The folder.
        dir: PathBuf,
        /// Which.
        detail: String,
    },
    /// Shards missing or unfinished.
    #[error("{} of {count} shards missing or unfinished: {} (resubmit with --array={})", missing.len(), array_syntax(missing), array_syntax(missing))]
    Missing {
        /// Number of shards.
        count: u64,
        /// Indexes of the missing or incomplete shards, ascending.
        missing: Vec<u64>,
        /// Damaged parts moved aside (their shards are among `missing`): (new path, why they
        /// did not parse).
        set_aside: Vec<(PathBuf, String)>,
    },
}

/// `" (damaged parts moved aside: X.damaged)"`, or nothing.
fn damaged_note(set_aside: &[(PathBuf, String)]) -> String {
    if set_aside.is_empty() {
        return String::new();
    }
    let names: Vec<String> = set_aside
        .iter()
        .map(|(p, _)| p.display().to_string())
        .collect();
    format!(" (damaged parts moved aside: {})", names.join(", "))
}

/// Reads every part in `dir` and checks that they are the shards `0..N` of one study, all
/// complete.
pub fn collect(dir: &Path) -> Result<Merged, MergeError> {
    let mut parts = Vec::new();
    let rd = std::fs::read_dir(dir).map_err(|source| PartError::Io {
        path: dir.into(),
        source,
    })?;
    let mut paths: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let n = p
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned();
            n.starts_with("part-") && n.ends_with(".json")
        })
        .collect();
    paths.sort();
    let mut set_aside = Vec::new();
    for p in &paths {
        match read_part(p) {
            Ok(part) => parts.push(part),
            // a damaged part is moved aside: its shard is then missing and runs again
            Err(PartError::Damaged { reason, .. }) => {
                set_aside.push((crate::part::set_aside(p)?, reason));
            }
            Err(e) => return Err(e.into()),
        }
    }
    let Some(first) = parts.first() else {
        return Err(MergeError::NoParts {
            dir: dir.into(),
            set_aside,
        });
    };
    let (header, count) = (first.study.clone(), first.shard.count);
    for p in &parts {
        if p.study.hash != header.hash || p.shard.count != count {
            return Err(MergeError::Mixed {
                dir: dir.into(),
                detail: format!(
                    "shard {}/{} of study {} ({}) and shard {}/{} of study {} ({})",
                    first.shard.index,
                    count,
                    header.name,
                    header.hash,
                    p.shard.index,
                    p.shard.count,
                    p.study.name,
                    p.study.hash
                ),
            });
        }
    }
    let missing: Vec<u64> = (0..count)
        .filter(|i| !parts.iter().any(|p| p.shard.index == *i && p.complete))
        .collect();
    if !missing.is_empty() {
        return Err(MergeError::Missing {
            count,
            missing,
            set_aside,
        });
    }
    let mut records: Vec<CaseRecord> = parts.into_iter().flat_map(|p| p.records).collect();
    records.sort_by_key(|r| r.case);
    records.dedup_by_key(|r| r.case);
    let discs = records
        .iter()
        .map(|r| &r.discs)
        .max_by_key(|d| d.len())
        .map(|d| d.iter().map(|s| s.name.clone()).collect())
        .unwrap_or_default();
    Ok(Merged {
        header,
        records,
        discs,
    })
}

/// The value of statistic `stat` ([`crate::spec::STATS`]) of disc `disc` in case `r`;
/// `None` when the case has no such value (a failed case, an unlimited life, a part written
/// before fatigue was kept).
pub fn stat_value(r: &CaseRecord, disc: usize, stat: &str) -> Option<f64> {
    if let Some(f) = r.fatigue.get(disc) {
        match stat {
            "damage_rate_per_h" => return Some(f.damage_rate_per_h),
            "life_h" => return f.life_h,
            "eq_load_range_n" => return Some(f.eq_load_range_n),
            _ => {}
        }
    }
    let d: &DiscStats = r.discs.get(disc)?;
    match stat {
        "peak_abs_n" => Some(d.max_positive_n.max(-d.max_negative_n)),
        "max_positive_n" => Some(d.max_positive_n),
        "max_negative_n" => Some(d.max_negative_n),
        "p99_abs_n" => Some(d.p99_abs_n),
        "mean_top10_abs_n" => Some(d.mean_top10_abs_n),
        "impacts" => Some(d.impacts as f64),
        _ => None,
    }
}

/// A cell of the results table.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// An integer.
    Int(i64),
    /// A number.
    Float(f64),
    /// Text.
    Text(String),
    /// No value (a failed case's statistics, a case's absent error).
    Null,
}

/// The kind of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// INT64.
    Int,
    /// DOUBLE.
    Float,
    /// UTF8.
    Text,
}

impl Merged {
    /// Column names and kinds of the results table (see the module doc).
    pub fn schema(&self) -> Vec<(String, Kind)> {
        let mut s: Vec<(String, Kind)> = ["case", "design_point", "member"]
            .iter()
            .map(|c| (c.to_string(), Kind::Int))
            .collect();
        s.extend(self.header.columns.iter().map(|c| (c.clone(), Kind::Float)));
        for d in &self.discs {
            for st in &self.header.outputs {
                let kind = if st == "impacts" {
                    Kind::Int
                } else {
                    Kind::Float
                };
                s.push((format!("{d}.{st}"), kind));
            }
        }
        s.push(("steps".into(), Kind::Int));
        s.push(("rejected_steps".into(), Kind::Int));
        s.push(("simulated_s".into(), Kind::Float));
        s.push(("error".into(), Kind::Text));
        s
    }

    /// The rows of the results table, cells in [`Merged::schema`] order.
    pub fn rows(&self) -> Vec<Vec<Cell>> {
        self.records
            .iter()
            .map(|r| {
                let mut row = vec![
                    Cell::Int(r.case as i64),
                    Cell::Int(r.design_point as i64),
                    Cell::Int(r.member as i64),
                ];
                row.extend(r.values.iter().map(|v| Cell::Float(*v)));
                for (i, _) in self.discs.iter().enumerate() {
                    for st in &self.header.outputs {
                        row.push(match (r.discs.get(i), st.as_str()) {
                            (Some(d), "impacts") => Cell::Int(d.impacts as i64),
                            _ => stat_value(r, i, st).map_or(Cell::Null, Cell::Float),
                        });
                    }
                }
                row.push(Cell::Int(r.steps as i64));
                row.push(Cell::Int(r.rejected_steps as i64));
                row.push(Cell::Float(r.simulated_s));
                row.push(match &r.error {
                    Some(e) => Cell::Text(e.clone()),
                    None => Cell::Null,
                });
                row
            })
            .collect()
    }

    /// The results table as CSV (RFC 4180 quoting; numbers in Rust's shortest round-trip
    /// form; empty cells for nulls).
    pub fn csv(&self) -> String {
        let mut out = String::new();
        let names: Vec<String> = self
            .schema()
            .into_iter()
            .map(|(n, _)| csv_field(&n))
            .collect();
        out.push_str(&names.join(","));
        out.push('\n');
        for row in self.rows() {
            let cells: Vec<String> = row
                .iter()
                .map(|c| match c {
                    Cell::Int(i) => i.to_string(),
                    Cell::Float(f) => f.to_string(),
                    Cell::Text(t) => csv_field(t),
                    Cell::Null => String::new(),
                })
                .collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
    }

    /// The successful records of design point `p`.
    fn ok_records(&self, p: Option<u64>) -> impl Iterator<Item = &CaseRecord> {
        self.records
            .iter()
            .filter(move |r| r.error.is_none() && p.is_none_or(|p| r.design_point == p))
    }

    /// Values of statistic `stat` of disc `disc` over the successful cases selected by `keep`.
    pub fn values(&self, disc: usize, stat: &str, keep: impl Fn(&CaseRecord) -> bool) -> Vec<f64> {
        self.records
            .iter()
            .filter(|r| r.error.is_none() && keep(r))
            .filter_map(|r| stat_value(r, disc, stat))
            .collect()
    }

    /// The disc with the largest mean `peak_abs_n` over all successful cases.
    pub fn hardest_disc(&self) -> Option<usize> {
        (0..self.discs.len())
            .filter_map(|i| {
                Summary::of(&self.values(i, "peak_abs_n", |_| true)).map(|s| (i, s.mean))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The per-design-point summary as CSV: one row per (design point, disc, statistic) with
    /// the design factors' levels, n, mean, std, min, max and the 95 % confidence interval of
    /// the mean (Student's t with n - 1 degrees of freedom), over the ensemble's successful
    /// cases.
    pub fn summary_csv(&self) -> String {
        let nf = self.header.design_factors;
        let mut out = String::from("design_point");
        for c in &self.header.columns[..nf] {
            out.push(',');
            out.push_str(&csv_field(c));
        }
        out.push_str(",disc,statistic,n,failed,mean,std,min,max,ci95_low,ci95_high\n");
        let points = self
            .records
            .iter()
            .map(|r| r.design_point)
            .max()
            .map_or(0, |m| m + 1);
        for p in 0..points {
            let Some(first) = self.records.iter().find(|r| r.design_point == p) else {
                continue;
            };
            let failed = self
                .records
                .iter()
                .filter(|r| r.design_point == p && r.error.is_some())
                .count();
            for (i, disc) in self.discs.iter().enumerate() {
                for st in &self.header.outputs {
                    let v: Vec<f64> = self
                        .ok_records(Some(p))
                        .filter_map(|r| stat_value(r, i, st))
                        .collect();
                    let mut line = p.to_string();
                    for x in &first.values[..nf] {
                        line.push_str(&format!(",{x}"));
                    }
                    line.push_str(&format!(",{},{st}", csv_field(disc)));
                    match Summary::of(&v) {
                        Some(s) => line.push_str(&format!(
                            ",{},{failed},{},{},{},{},{},{}",
                            s.n,
                            s.mean,
                            s.std,
                            s.min,
                            s.max,
                            s.mean - s.ci95_half,
                            s.mean + s.ci95_half
                        )),
                        None => line.push_str(&format!(",0,{failed},,,,,,")),
                    }
                    out.push_str(&line);
                    out.push('\n');
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::part::{read_part, run_shard, CaseOutput, RunResult, Shard};
    use crate::spec::{parse, Study};
    use clutchpack_scene::Scene;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::time::Duration;

    /// A study of 2 design points x 3 members with a random draw and spread placement.
    fn study() -> Study {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        parse(
            r#"
[study]
scene = "hu-table2.toml"
seed = 11
[ensemble]
members = 3
[[factor]]
key = "defaults.oil.film_thickness_m"
values = [0, 25e-6]
[[random]]
key = "defaults.drag_n_m_s_rad"
dist = "uniform"
low = 0.005
high = 0.02
"#,
            "fake.toml",
            &dir,
        )
        .unwrap()
    }

    /// A stand-in engine: statistics that are a pure function of the case's scene (film,
    /// drag, initial angle), so that two runs agree exactly only if their scenes do.
    fn fake(scene: &Scene, _stop: &AtomicBool) -> RunResult {
        let d = &scene.pack.discs[0];
        let peak = 1000.0 - 4e6 * d.law.oil.thickness_m
            + 1e4 * d.drag_n_m_s_rad
            + 1e5 * d.initial_rel_angle_rad;
        Ok(Some(CaseOutput {
            discs: vec![DiscStats {
                max_positive_n: peak,
                max_negative_n: -peak / 3.0,
                impacts: 7,
                ..DiscStats::empty(d.name.clone())
            }],
            fatigue: Vec::new(),
            steps: 100,
            rejected_steps: 1,
            simulated_s: scene.simulation.duration_s,
        }))
    }

    fn fresh(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("clutchpack_study_{}_{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    fn run(study: &Study, dir: &Path, shard: Shard, jobs: usize) -> crate::ShardOutcome {
        let stop = AtomicBool::new(false);
        run_shard(
            study,
            dir,
            shard,
            jobs,
            &stop,
            Duration::from_secs(60),
            &fake,
            &|_, _| {},
        )
        .unwrap()
    }

    /// Case k's numbers are a function of the study and k only: the table of the whole study
    /// run as one shard on 1 thread equals the table of 3 shards on 2 threads, byte for byte;
    /// and every random draw differs between cases (the streams are not shared).
    #[test]
    fn the_table_does_not_depend_on_shards_or_threads() {
        let s = study();
        let one = fresh("one");
        run(&s, &one, Shard { index: 0, count: 1 }, 1);
        let three = fresh("three");
        for i in 0..3 {
            run(&s, &three, Shard { index: i, count: 3 }, 2);
        }
        let (a, b) = (collect(&one).unwrap(), collect(&three).unwrap());
        assert_eq!(a.records.len(), 6);
        assert_eq!(a.csv(), b.csv());
        assert_eq!(a.summary_csv(), b.summary_csv());
        let drags: Vec<f64> = a.records.iter().map(|r| r.values[1]).collect();
        for (i, x) in drags.iter().enumerate() {
            assert!((0.005..0.02).contains(x));
            assert!(!drags[..i].contains(x), "draw {i} repeats: {drags:?}");
        }
        // the header line names the columns of the module doc, in order
        let head = a.csv().lines().next().unwrap().to_string();
        assert_eq!(
            head,
            "case,design_point,member,defaults.oil.film_thickness_m,defaults.drag_n_m_s_rad,\
             initial_fraction,disc.peak_abs_n,disc.max_positive_n,disc.max_negative_n,\
             disc.p99_abs_n,disc.mean_top10_abs_n,disc.impacts,disc.damage_rate_per_h,\
             disc.life_h,disc.eq_load_range_n,steps,rejected_steps,\
             simulated_s,error"
        );
        let _ = std::fs::remove_dir_all(one);
        let _ = std::fs::remove_dir_all(three);
    }

    /// A missing shard and an unfinished one are both reported, by index; parts of another
    /// study are refused.
    #[test]
    fn merge_names_missing_and_unfinished_shards() {
        let s = study();
        let dir = fresh("missing");
        for i in [0, 2, 3] {
            run(&s, &dir, Shard { index: i, count: 5 }, 1);
        }
        // shard 3's part loses a case: written but unfinished (as after a stop)
        let p3 = dir.join(Shard { index: 3, count: 5 }.file_name());
        let mut part = read_part(&p3).unwrap();
        part.records.clear();
        part.complete = false;
        std::fs::write(&p3, serde_json::to_string(&part).unwrap()).unwrap();
        match collect(&dir) {
            Err(MergeError::Missing { count, missing, .. }) => {
                assert_eq!((count, missing.clone()), (5, vec![1, 3, 4]));
                assert_eq!(array_syntax(&missing), "1,3-4");
            }
            other => panic!("expected missing shards, got {other:?}"),
        }
        // a part of another study (other seed, so other hash) in the same folder
        let mut other = s.clone();
        other.hash = "0123456789abcdef".into();
        run(&other, &dir, Shard { index: 1, count: 5 }, 1);
        assert!(matches!(collect(&dir), Err(MergeError::Mixed { .. })));
        assert!(matches!(
            collect(&fresh("empty-and-absent")),
            Err(MergeError::Part(_))
        ));
        let _ = std::fs::remove_dir_all(dir);
    }

    /// A stop after two cases leaves a valid, unfinished part with exactly the finished cases;
    /// the rerun runs only the others and the table equals an uninterrupted run's.
    #[test]
    fn a_stopped_shard_resumes_with_the_missing_cases_only() {
        let s = study();
        let dir = fresh("resume");
        let stop = AtomicBool::new(false);
        let calls = AtomicUsize::new(0);
        let stopping = |scene: &Scene, st: &AtomicBool| {
            if calls.fetch_add(1, Ordering::SeqCst) == 1 {
                stop.store(true, Ordering::SeqCst);
            }
            fake(scene, st)
        };
        let shard = Shard { index: 0, count: 1 };
        let o = run_shard(
            &s,
            &dir,
            shard,
            1,
            &stop,
            Duration::ZERO,
            &stopping,
            &|_, _| {},
        )
        .unwrap();
        assert_eq!((o.ran, o.complete), (2, false));
        let part = read_part(&dir.join(shard.file_name())).unwrap();
        assert_eq!(
            part.records.iter().map(|r| r.case).collect::<Vec<_>>(),
            [0, 1]
        );
        assert!(!part.complete);
        assert!(matches!(collect(&dir), Err(MergeError::Missing { .. })));
        let calls_before = calls.load(Ordering::SeqCst);
        stop.store(false, Ordering::SeqCst);
        let o = run_shard(
            &s,
            &dir,
            shard,
            2,
            &stop,
            Duration::ZERO,
            &stopping,
            &|_, _| {},
        )
        .unwrap();
        assert_eq!((o.skipped, o.ran, o.complete), (2, 4, true));
        assert_eq!(calls.load(Ordering::SeqCst) - calls_before, 4);
        let whole = fresh("resume-whole");
        run(&s, &whole, shard, 1);
        assert_eq!(collect(&dir).unwrap().csv(), collect(&whole).unwrap().csv());
        let _ = std::fs::remove_dir_all(dir);
        let _ = std::fs::remove_dir_all(whole);
    }

    /// A case whose engine fails or panics is a row with its error and null statistics; the
    /// shard goes on, and the summary counts it as failed.
    #[test]
    fn failed_cases_are_rows() {
        let s = study();
        let dir = fresh("failed");
        let flaky = |scene: &Scene, st: &AtomicBool| {
            let d = &scene.pack.discs[0];
            if d.initial_rel_angle_rad > 0.0 && d.law.oil.thickness_m > 0.0 {
                panic!("engine exploded");
            }
            if d.initial_rel_angle_rad < 0.0 && d.law.oil.thickness_m > 0.0 {
                return Err("diverged at t = 0.1 s".to_string());
            }
            fake(scene, st)
        };
        let stop = AtomicBool::new(false);
        let shard = Shard { index: 0, count: 1 };
        let o = run_shard(
            &s,
            &dir,
            shard,
            1,
            &stop,
            Duration::ZERO,
            &flaky,
            &|_, _| {},
        )
        .unwrap();
        assert_eq!((o.ran, o.failed, o.complete), (6, 2, true));
        let m = collect(&dir).unwrap();
        let csv = m.csv();
        let rows: Vec<&str> = csv.lines().collect();
        // case 3 = design point 1 member 0 (fraction -2/3): the error; case 5 the panic
        assert!(
            rows[4].ends_with(",0,0,0,diverged at t = 0.1 s"),
            "{}",
            rows[4]
        );
        assert!(rows[6].ends_with("panic: engine exploded"), "{}", rows[6]);
        assert!(rows[4].contains(",,,,,,"), "null statistics: {}", rows[4]);
        let summary = m.summary_csv();
        let line = summary
            .lines()
            .find(|l| l.starts_with("1,") && l.contains(",peak_abs_n,"))
            .unwrap();
        // design point 1: n = 1 (member 1 ran), failed = 2
        assert!(line.contains(",peak_abs_n,1,2,"), "{line}");
        let _ = std::fs::remove_dir_all(dir);
    }

    /// The summary's numbers by hand: design point 0's three peaks, their mean, sample std
    /// and t interval with 2 degrees of freedom (t = 4.302653).
    #[test]
    fn summary_rows_by_hand() {
        let s = study();
        let dir = fresh("summary");
        run(&s, &dir, Shard { index: 0, count: 1 }, 1);
        let m = collect(&dir).unwrap();
        let v: Vec<f64> = m
            .records
            .iter()
            .filter(|r| r.design_point == 0)
            .map(|r| r.discs[0].max_positive_n)
            .collect();
        assert_eq!(v.len(), 3);
        let mean = (v[0] + v[1] + v[2]) / 3.0;
        let std = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
        let half = 4.302653 * std / 3f64.sqrt();
        let summary = m.summary_csv();
        let line = summary
            .lines()
            .find(|l| l.starts_with("0,") && l.contains(",peak_abs_n,"))
            .unwrap();
        let f: Vec<&str> = line.split(',').collect();
        // design_point, film, disc, statistic, n, failed, mean, std, min, max, lo, hi
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        assert_eq!(f[4], "3");
        assert!((num(6) - mean).abs() < 1e-9 * mean);
        assert!((num(7) - std).abs() < 1e-9 * std);
        assert!((num(10) - (mean - half)).abs() < 1e-9 * mean);
        assert!((num(11) - (mean + half)).abs() < 1e-9 * mean);
        let _ = std::fs::remove_dir_all(dir);
    }
}
