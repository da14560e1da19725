//! Shards and their part files: which cases shard `I` of `N` runs, running them on `J`
//! threads with a clean stop, and the part file each shard writes atomically.
//!
//! A part is one JSON document `DIR/part-IIIII-of-NNNNN.json` holding the study's hash and the
//! finished cases of the shard. It is written to a temporary file in the same folder and
//! renamed over the old one (atomic on POSIX file systems), every few seconds while the shard
//! runs and when it ends, so that a part on disk is always complete and valid, whatever stops
//! the shard. A rerun of the shard reads it and runs only the cases it lacks.

use crate::spec::Study;
use clutchpack_analysis::DiscStats;
use clutchpack_scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The format tag of part files.
pub const PART_FORMAT: &str = "clutchpack-study-part/1";

/// Shard `index` of `count` runs the cases `k` with `k % count == index` (round robin: run
/// time that follows a factor is spread over the shards).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// `0..count`.
    pub index: u64,
    /// Number of shards, >= 1.
    pub count: u64,
}

impl Shard {
    /// The case ids of this shard, ascending.
    pub fn cases(&self, total: u64) -> impl Iterator<Item = u64> + '_ {
        (self.index..total).step_by(self.count as usize)
    }

    /// `part-00003-of-00004.json`.
    pub fn file_name(&self) -> String {
        format!("part-{:05}-of-{:05}.json", self.index, self.count)
    }
}

/// The fatigue of one disc's (coupling's) spline teeth in one case, as `clutchpack run`
/// computes it (MODEL.md section 7; `clutchpack_analysis::DiscFatigue`, its lumped figures).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CaseFatigue {
    /// Miner damage per hour of the simulated duty, 1/h (>= 0).
    pub damage_rate_per_h: f64,
    /// Life at that duty, h; `None` when the rate is 0 (unlimited).
    pub life_h: Option<f64>,
    /// Damage-equivalent load range for one hour of duty at the knee's cycle count, N.
    pub eq_load_range_n: f64,
}

/// What an engine gives for one case.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseOutput {
    /// Per-disc statistics, discs in scene order.
    pub discs: Vec<DiscStats>,
    /// Per-disc fatigue, discs in scene order (empty when not assessed).
    pub fatigue: Vec<CaseFatigue>,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// Simulated time reached, s.
    pub simulated_s: f64,
}

/// One finished case, as parts store it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseRecord {
    /// Case id.
    pub case: u64,
    /// Design point.
    pub design_point: u64,
    /// Ensemble member.
    pub member: u64,
    /// Values of the study's columns ([`Study::columns`]).
    pub values: Vec<f64>,
    /// Per-disc statistics (empty for a failed case).
    pub discs: Vec<DiscStats>,
    /// Per-disc fatigue (empty for a failed case, and in parts written before it was kept).
    #[serde(default)]
    pub fatigue: Vec<CaseFatigue>,
    /// Accepted engine steps (0 for a failed case).
    pub steps: u64,
    /// Rejected engine steps.
    pub rejected_steps: u64,
    /// Simulated time reached, s.
    pub simulated_s: f64,
    /// Wall time of the engine's run of the case, s (not part of the results table: it depends
    /// on the machine).
    pub wall_s: f64,
    /// Why the case failed; `None` for a case that ran.
    pub error: Option<String>,
}

/// The header every part carries: enough for `merge` to build the tables without the study
/// file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyHeader {
    /// Study name.
    pub name: String,
    /// Study hash ([`Study::hash`]).
    pub hash: String,
    /// Number of cases of the whole study.
    pub cases: u64,
    /// Ensemble members per design point.
    pub members: u64,
    /// Column names of [`CaseRecord::values`].
    pub columns: Vec<String>,
    /// How many of the first columns are design factors.
    pub design_factors: usize,
    /// Per-disc statistics kept.
    pub outputs: Vec<String>,
}

impl StudyHeader {
    /// The header of `study`.
    pub fn of(study: &Study) -> StudyHeader {
        StudyHeader {
            name: study.name.clone(),
            hash: study.hash.clone(),
            cases: study.cases(),
            members: study.members,
            columns: study.columns(),
            design_factors: study.factors.len(),
            outputs: study.outputs.clone(),
        }
    }
}

/// A part file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Part {
    /// [`PART_FORMAT`].
    pub format: String,
    /// The study.
    pub study: StudyHeader,
    /// Which shard.
    pub shard: Shard,
    /// True when every case of the shard is in `records`.
    pub complete: bool,
    /// Finished cases, ascending by case id.
    pub records: Vec<CaseRecord>,
}

/// Errors of parts and shards.
#[derive(Debug, thiserror::Error)]
pub enum PartError {
    /// I/O on a part file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// A part file that is not a part.
    #[error("{}: not a clutchpack study part: {reason}", path.display())]
    Bad {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// A part file that does not parse (cut short, overwritten): moved aside by
    /// [`set_aside`] and its cases run again.
    #[error("{}: damaged part file: {reason}", path.display())]
    Damaged {
        /// The file.
        path: PathBuf,
        /// Why it does not parse.
        reason: String,
    },
    /// A part of another study (other hash) where this one's should be.
    #[error("{}: a part of another study (hash {found}, this study's is {expected}); use another --out folder or delete it", path.display())]
    OtherStudy {
        /// The file.
        path: PathBuf,
        /// Its hash.
        found: String,
        /// The study's.
        expected: String,
    },
}

/// Reads a part file. A file that is not a regular file (a FIFO, a folder) is refused
/// before it is opened, so nothing blocks on it; a file that does not parse is
/// [`PartError::Damaged`].
pub fn read_part(path: &Path) -> Result<Part, PartError> {
    let io = |source| PartError::Io {
        path: path.into(),
        source,
    };
    if !std::fs::metadata(path).map_err(io)?.is_file() {
        return Err(PartError::Bad {
            path: path.into(),
            reason: "not a regular file".into(),
        });
    }
    let bytes = std::fs::read(path).map_err(io)?;
    let part: Part = serde_json::from_slice(&bytes).map_err(|e| PartError::Damaged {
        path: path.into(),
        reason: e.to_string(),
    })?;
    if part.format != PART_FORMAT {
        return Err(PartError::Bad {
            path: path.into(),
            reason: format!("format {:?}, expected {PART_FORMAT:?}", part.format),
        });
    }
    Ok(part)
}

/// Moves a damaged part aside to `<name>.damaged` (or `<name>.damaged.K`, never over an
/// earlier one) so that its shard runs again; returns the new path.
pub fn set_aside(path: &Path) -> Result<PathBuf, PartError> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let mut to = path.with_file_name(format!("{name}.damaged"));
    let mut k = 1;
    while to.exists() {
        to = path.with_file_name(format!("{name}.damaged.{k}"));
        k += 1;
    }
    std::fs::rename(path, &to).map_err(|source| PartError::Io {
        path: path.into(),
        source,
    })?;
    Ok(to)
}

/// Writes `value` as JSON to `path` atomically: a temporary file in the same folder, flushed
/// to disk, then renamed over `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), PartError> {
    use std::io::Write;
    let io = |source| PartError::Io {
        path: path.into(),
        source,
    };
    let tmp = path.with_extension(format!("tmp.{}", std::process::id()));
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        // a full disk or a lost folder: leave no temporary file behind
        let _ = std::fs::remove_file(&tmp);
    }
    written.map_err(io)
}

fn write_part(path: &Path, part: &Part) -> Result<(), PartError> {
    let text = serde_json::to_string(part).map_err(|e| PartError::Bad {
        path: path.into(),
        reason: e.to_string(),
    })?;
    write_atomic(path, text.as_bytes())
}

/// How a shard ended.
#[derive(Debug, Clone, PartialEq)]
pub struct ShardOutcome {
    /// The part file.
    pub path: PathBuf,
    /// Cases of the shard.
    pub cases: usize,
    /// Cases already in the part when the shard started (skipped).
    pub skipped: usize,
    /// Cases run now.
    pub ran: usize,
    /// Failed cases (now and before).
    pub failed: usize,
    /// True when every case of the shard is done.
    pub complete: bool,
    /// Sum of the cases' wall times run now, s (engine time, for the overhead figure).
    pub case_wall_s: f64,
    /// Wall time of the shard, s.
    pub wall_s: f64,
    /// A damaged part found at the start: where it was moved and why it did not parse (its
    /// cases ran again).
    pub set_aside: Option<(PathBuf, String)>,
}

/// What a case runner returns: `Ok(None)` when it was stopped by `stop` (the case is not
/// recorded and runs again on a rerun), `Err` for a failed case (recorded with the message).
pub type RunResult = Result<Option<CaseOutput>, String>;

/// Runs the cases of `shard` that its part in `out` lacks, on `jobs` threads, calling `run`
/// for each case's scene. Stops starting cases once `stop` is set; writes the part every
/// `flush` and at the end. `progress(done, total)` is called after each case.
#[allow(clippy::too_many_arguments)]
pub fn run_shard(
    study: &Study,
    out: &Path,
    shard: Shard,
    jobs: usize,
    stop: &AtomicBool,
    flush: Duration,
    run: &(dyn Fn(&Scene, &AtomicBool) -> RunResult + Sync),
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<ShardOutcome, PartError> {
    let t0 = Instant::now();
    std::fs::create_dir_all(out).map_err(|source| PartError::Io {
        path: out.into(),
        source,
    })?;
    let path = out.join(shard.file_name());
    let header = StudyHeader::of(study);
    let mut records = Vec::new();
    let mut set_aside_to = None;
    let old = if path.exists() {
        match read_part(&path) {
            Err(PartError::Damaged { reason, .. }) => {
                set_aside_to = Some((set_aside(&path)?, reason));
                None
            }
            other => Some(other?),
        }
    } else {
        None
    };
    if let Some(old) = old {
        if old.study.hash != header.hash {
            return Err(PartError::OtherStudy {
                path,
                found: old.study.hash,
                expected: header.hash,
            });
        }
        records = old.records;
    }
    let all: Vec<u64> = shard.cases(study.cases()).collect();
    let todo: Vec<u64> = all
        .iter()
        .copied()
        .filter(|k| {
            records
                .binary_search_by_key(k, |r: &CaseRecord| r.case)
                .is_err()
        })
        .collect();
    let skipped = all.len() - todo.len();
    let save = |records: &mut Vec<CaseRecord>| -> Result<(), PartError> {
        records.sort_by_key(|r| r.case);
        let part = Part {
            format: PART_FORMAT.into(),
            study: header.clone(),
            shard,
            complete: records.len() == all.len(),
            records: records.clone(),
        };
        write_part(&path, &part)
    };
    let last = Mutex::new(Instant::now());
    let done = AtomicUsize::new(skipped);
    let (records, ran, case_wall) =
        run_cases(study, &todo, records, jobs, stop, run, &|records| {
            progress(done.fetch_add(1, Ordering::SeqCst) + 1, all.len());
            let mut l = last.lock().expect("no panics hold it");
            if l.elapsed() >= flush {
                *l = Instant::now();
                save(records)
            } else {
                Ok(())
            }
        })?;
    let mut records = records;
    save(&mut records)?;
    let failed = records.iter().filter(|r| r.error.is_some()).count();
    Ok(ShardOutcome {
        path,
        cases: all.len(),
        skipped,
        ran,
        failed,
        complete: records.len() == all.len(),
        case_wall_s: case_wall,
        wall_s: t0.elapsed().as_secs_f64(),
        set_aside: set_aside_to,
    })
}

/// Runs the cases `todo` on `jobs` threads (each takes the next case as it finishes one),
/// appending a record per finished case to `records`; stops starting cases once `stop` is
/// set. `on_record` sees the records after each case (under a lock; an error from it ends
/// the run). Returns the records, the number run and the sum of their wall times in s.
pub fn run_cases<E: Send>(
    study: &Study,
    todo: &[u64],
    records: Vec<CaseRecord>,
    jobs: usize,
    stop: &AtomicBool,
    run: &(dyn Fn(&Scene, &AtomicBool) -> RunResult + Sync),
    on_record: &(dyn Fn(&mut Vec<CaseRecord>) -> Result<(), E> + Sync),
) -> Result<(Vec<CaseRecord>, usize, f64), E> {
    let state = Mutex::new(records);
    let next = AtomicUsize::new(0);
    let ran = AtomicUsize::new(0);
    let case_wall = Mutex::new(0.0f64);
    let first_error: Mutex<Option<E>> = Mutex::new(None);
    std::thread::scope(|s| {
        for _ in 0..jobs.max(1) {
            s.spawn(|| loop {
                if stop.load(Ordering::SeqCst) || first_error.lock().expect("no panics").is_some() {
                    break;
                }
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(&k) = todo.get(i) else { break };
                let Some(record) = run_case(study, k, stop, run) else {
                    continue; // stopped: not recorded, runs again on a rerun
                };
                *case_wall.lock().expect("no panics hold it") += record.wall_s;
                ran.fetch_add(1, Ordering::SeqCst);
                let mut st = state.lock().expect("no panics hold it");
                st.push(record);
                if let Err(e) = on_record(&mut st) {
                    first_error.lock().expect("no panics").get_or_insert(e);
                }
            });
        }
    });
    if let Some(e) = first_error.into_inner().expect("no panics") {
        return Err(e);
    }
    Ok((
        state.into_inner().expect("no panics"),
        ran.into_inner(),
        case_wall.into_inner().expect("no panics"),
    ))
}

/// Runs case `k`: `None` if `run` was stopped, else its record (an error or a panic of the
/// engine is a record with the message, not a crash).
pub fn run_case(
    study: &Study,
    k: u64,
    stop: &AtomicBool,
    run: &(dyn Fn(&Scene, &AtomicBool) -> RunResult + Sync),
) -> Option<CaseRecord> {
    let case = study.case(k);
    // the case's wall time is the engine's: building the scene counts as study overhead
    let mut t = Instant::now();
    let result = match study.scene(&case) {
        Ok(scene) => {
            t = Instant::now();
            match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(&scene, stop))) {
                Ok(r) => r,
                Err(p) => Err(format!(
                    "panic: {}",
                    p.downcast_ref::<String>()
                        .cloned()
                        .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                        .unwrap_or_default()
                )),
            }
        }
        Err(e) => Err(e.to_string().replace('\n', "; ")),
    };
    let wall_s = t.elapsed().as_secs_f64();
    let (out, error) = match result {
        Ok(None) => return None,
        Ok(Some(o)) => (o, None),
        Err(msg) => (
            CaseOutput {
                discs: Vec::new(),
                fatigue: Vec::new(),
                steps: 0,
                rejected_steps: 0,
                simulated_s: 0.0,
            },
            Some(msg),
        ),
    };
    Some(CaseRecord {
        case: k,
        design_point: case.design_point,
        member: case.member,
        values: case.values,
        discs: out.discs,
        fatigue: out.fatigue,
        steps: out.steps,
        rejected_steps: out.rejected_steps,
        simulated_s: out.simulated_s,
        wall_s,
        error,
    })
}

/// `--array` syntax of sorted indexes: `1,3-4`.
pub fn array_syntax(indexes: &[u64]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < indexes.len() {
        let mut j = i;
        while j + 1 < indexes.len() && indexes[j + 1] == indexes[j] + 1 {
            j += 1;
        }
        out.push(if j == i {
            indexes[i].to_string()
        } else {
            format!("{}-{}", indexes[i], indexes[j])
        });
        i = j + 1;
    }
    out.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_syntax_ranges() {
        assert_eq!(array_syntax(&[1, 3, 4]), "1,3-4");
        assert_eq!(array_syntax(&[0, 1, 2, 7]), "0-2,7");
        assert_eq!(array_syntax(&[5]), "5");
        assert_eq!(array_syntax(&[]), "");
    }

    #[test]
    fn shards_partition_the_cases() {
        let mut all: Vec<u64> = (0..4)
            .flat_map(|i| Shard { index: i, count: 4 }.cases(10).collect::<Vec<_>>())
            .collect();
        all.sort();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
        assert_eq!(
            Shard { index: 1, count: 4 }.cases(10).collect::<Vec<_>>(),
            vec![1, 5, 9]
        );
    }
}
