//! Studies: a shard's cases run as `run` runs a scene ([`crate::run_case`]), and a study's
//! parts merged into its tables and figure.

use crate::{run_case, Error, Result};
use clutchpack_study::merge::Merged;
use clutchpack_study::{MergeError, Shard, ShardOutcome, Study};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// How often a running shard writes its part file (and at its end), wall time.
pub const PART_FLUSH: Duration = Duration::from_secs(5);

/// Runs the cases of `shard` of `study` that its part in `out` lacks, on `jobs` threads,
/// each with the study's engine (else the scene's choice); stops starting cases once `stop`
/// is set, the part complete up to there. `progress(done, total)` after each case. A part of
/// another study in `out`, or an `out` that is a file (or lies under one), is bad input.
pub fn run_study_shard(
    study: &Study,
    out: &Path,
    shard: Shard,
    jobs: usize,
    stop: &AtomicBool,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<ShardOutcome> {
    // a file where the folder (or one of its parents) should be: said as such, before the
    // folder is made (else only the operating system's "File exists" or "Not a directory")
    if let Some(file) = out.ancestors().find(|p| p.exists() && !p.is_dir()) {
        return Err(Error::BadInput(format!(
            "{}: the study's output folder (its parts go into it), but {} is a file, not a folder",
            out.display(),
            file.display()
        )));
    }
    let engine = study.engine;
    clutchpack_study::run_shard(
        study,
        out,
        shard,
        jobs,
        stop,
        PART_FLUSH,
        &|scene, stop| run_case(scene, engine, stop),
        progress,
    )
    .map_err(|e| match e {
        clutchpack_study::part::PartError::OtherStudy { .. } => Error::BadInput(e.to_string()),
        e => Error::Study(e.to_string()),
    })
}

/// A merged study and what was written.
pub struct MergedStudy {
    /// The merged table.
    pub merged: Merged,
    /// The main-effects figure, when a case succeeded.
    pub plot: Option<PathBuf>,
}

/// Merges the parts in `dir` (every shard's must be there) and writes `results.csv`,
/// `summary.csv`, `results.parquet` and, when a case succeeded, `main-effects.<plot_format>`
/// (`png` or `svg`), each whole or not at all. Missing shards are [`Error::StudyIncomplete`]
/// with the merge's reason (which shards), parts of different studies bad input.
pub fn merge_study(dir: &Path, plot_format: &str) -> Result<MergedStudy> {
    if !dir.is_dir() {
        return Err(Error::BadInput(format!(
            "{}: not a folder (expected the output folder of a study's run)",
            dir.display()
        )));
    }
    let m = clutchpack_study::collect(dir).map_err(|e| match e {
        e @ MergeError::Missing { .. } => Error::StudyIncomplete(e),
        e @ MergeError::Mixed { .. } => Error::BadInput(e.to_string()),
        e => Error::Study(e.to_string()),
    })?;
    let write = |name: &str, text: &str| -> Result<()> {
        let p = dir.join(name);
        clutchpack_study::part::write_atomic(&p, text.as_bytes())
            .map_err(|e| Error::Study(e.to_string()))
    };
    write("results.csv", &m.csv())?;
    write("summary.csv", &m.summary_csv())?;
    let pq = dir.join("results.parquet");
    let tmp = dir.join("results.parquet.tmp");
    let written = clutchpack_study::parquet::write_results(&tmp, &m)
        .map_err(|e| Error::Study(e.to_string()))
        .and_then(|()| std::fs::rename(&tmp, &pq).map_err(Error::io(&pq)));
    if written.is_err() {
        // a full disk: leave no temporary file behind
        let _ = std::fs::remove_file(&tmp);
    }
    written?;
    let failed = m.records.iter().filter(|r| r.error.is_some()).count();
    let plot = if failed < m.records.len() {
        let p = dir.join(format!("main-effects.{plot_format}"));
        // drawn at a temporary sibling (same extension: the format) and renamed into place,
        // as every other output: never half a figure, never opened at its final path
        let (pending, file) =
            clutchpack_record::PendingFile::create(&p, clutchpack_record::Replace::Existing)
                .map_err(Error::io(&p))?;
        drop(file);
        match clutchpack_study::plot::plot_main_effects(pending.tmp_path(), &m) {
            Ok(()) => {
                pending.commit().map_err(Error::io(&p))?;
            }
            Err(e) => {
                pending.discard();
                return Err(Error::Study(e.to_string()));
            }
        }
        Some(p)
    } else {
        None
    };
    Ok(MergedStudy { merged: m, plot })
}
