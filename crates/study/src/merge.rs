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
//! | `<disc>.<stat>` | DOUBLE, nullable (`impacts`: INT64) | per disc (scene names, scene order) and kept statistic: `peak_abs_n` (N, the larger of `max_positive_n` and `-max_negative_n`), `max_positive_n` (N, >= 0), `max_negative_n` (N, <= 0), `p99_abs_n` (N), `mean_top10_abs_n` (N), `impacts` (count); null for a failed case |
//! | `steps` | INT64 | accepted engine steps (0 if failed) |
//! | `rejected_steps` | INT64 | rejected engine steps |
//! | `simulated_s` | DOUBLE | simulated time reached, s |
//! | `error` | UTF8 string, nullable | why the case failed; null if it ran |
//!
//! Loads are per tooth in N, negative when the shaft leads (clutchpack_analysis).

use crate::part::{array_syntax, read_part, CaseRecord, PartError, StudyHeader};
use crate::stats::Summary;
use clutchpack_analysis::DiscStats;
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
    #[error("{}: no study parts (part-*-of-*.json) in this folder", dir.display())]
    NoParts {
        /// The folder.
        dir: PathBuf,
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
    },
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
    for p in &paths {
        parts.push(read_part(p)?);
    }
    let Some(first) = parts.first() else {
        return Err(MergeError::NoParts { dir: dir.into() });
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
        return Err(MergeError::Missing { count, missing });
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

/// The value of statistic `stat` ([`crate::spec::STATS`]) of one disc.
pub fn stat_value(d: &DiscStats, stat: &str) -> f64 {
    match stat {
        "peak_abs_n" => d.max_positive_n.max(-d.max_negative_n),
        "max_positive_n" => d.max_positive_n,
        "max_negative_n" => d.max_negative_n,
        "p99_abs_n" => d.p99_abs_n,
        "mean_top10_abs_n" => d.mean_top10_abs_n,
        "impacts" => d.impacts as f64,
        _ => f64::NAN,
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
                            (Some(d), s) => Cell::Float(stat_value(d, s)),
                            (None, _) => Cell::Null,
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
            .filter_map(|r| r.discs.get(disc).map(|d| stat_value(d, stat)))
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
                        .filter_map(|r| r.discs.get(i).map(|d| stat_value(d, st)))
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

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}
