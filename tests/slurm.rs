//! `clutchpack study submit --slurm` against a real Slurm: a 4-shard job array merged by its
//! dependent job equals `study run` on one machine, table for table; a shard cancelled with
//! `scancel` is reported missing by index and a resubmission of that index completes the
//! study.
//!
//! Needs a running cluster: `.ci/slurm-setup start` (as root) starts a one-node Slurm and
//! prints `export SLURM_CONF=...`; CI runs it before the tests. Without `sbatch`, or without a
//! cluster that answers, the test prints `SKIPPED: no slurm` and why, and passes, unless
//! `CLUTCHPACK_REQUIRE_SLURM=1` (set in CI), which turns the skip into a failure.

use super::study::{one_machine, small_study, study};
use super::{scratch, stderr, stdout};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The slurm.conf `.ci/slurm-setup` writes when CLUTCHPACK_SLURM_DIR is not set.
const SETUP_CONF: &str = "/tmp/clutchpack-slurm/etc/slurm.conf";

/// Every wait on the cluster is bounded by this (a shard of this test runs in seconds).
const LIMIT: Duration = Duration::from_secs(240);

/// The cluster's slurm.conf if Slurm is installed and the cluster answers; else why not.
fn cluster() -> Result<PathBuf, String> {
    let installed = Command::new("sbatch")
        .arg("--version")
        .env("SLURM_CONF", "/dev/null")
        .output();
    // (every Slurm client, even --version, wants a config; /dev/null makes it answer at once)
    if installed.is_err() {
        return Err("sbatch is not installed (run .ci/slurm-setup start as root)".into());
    }
    let conf = match std::env::var_os("SLURM_CONF") {
        Some(c) => PathBuf::from(c),
        None if Path::new(SETUP_CONF).exists() => PathBuf::from(SETUP_CONF),
        None => {
            return Err("SLURM_CONF is not set and .ci/slurm-setup has not run (no cluster)".into())
        }
    };
    if !conf.exists() {
        // clients retry for 60 s on a missing config: do not even try
        return Err(format!("SLURM_CONF = {} does not exist", conf.display()));
    }
    let o = Command::new("timeout")
        .args(["15", "sinfo", "-h", "-o", "%T"])
        .env("SLURM_CONF", &conf)
        .output()
        .map_err(|e| format!("sinfo: {e}"))?;
    if !o.status.success() {
        return Err(format!(
            "the cluster of {} does not answer: {}",
            conf.display(),
            String::from_utf8_lossy(&o.stderr).trim()
        ));
    }
    Ok(conf)
}

fn slurm(conf: &Path, cmd: &str, args: &[&str]) -> Output {
    Command::new("timeout")
        .arg("30")
        .arg(cmd)
        .args(args)
        .env("SLURM_CONF", conf)
        .output()
        .unwrap()
}

/// `study submit` with SLURM_CONF set, bounded by `timeout`.
fn submit(conf: &Path, study_file: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut c = Command::new("timeout");
    c.arg(LIMIT.as_secs().to_string())
        .arg(env!("CARGO_BIN_EXE_clutchpack"))
        .args([
            "study", "submit", "--slurm", "--shards", "4", "--time", "00:05:00",
        ])
        .args(["--merge-time", "00:05:00", "--out"])
        .arg(out)
        .args(extra)
        .arg(study_file)
        .env("SLURM_CONF", conf)
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    c.output().unwrap()
}

/// The job id after `prefix` in `submit`'s output (`... job array 12 (...`).
fn job_id(text: &str, prefix: &str) -> String {
    let at = text
        .find(prefix)
        .unwrap_or_else(|| panic!("{prefix:?} not in {text}"));
    text[at + prefix.len()..]
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .unwrap()
        .to_string()
}

/// Waits until none of `jobs` is queued or running.
fn wait_gone(conf: &Path, jobs: &[&str]) {
    let t0 = Instant::now();
    loop {
        let o = slurm(
            conf,
            "squeue",
            &["-h", "-o", "%i %T", "-j", &jobs.join(",")],
        );
        let text = stdout(&o);
        if text.trim().is_empty() || !o.status.success() {
            return;
        }
        assert!(
            t0.elapsed() < LIMIT,
            "jobs {jobs:?} still queued after {LIMIT:?}:\n{text}"
        );
        std::thread::sleep(Duration::from_millis(500));
    }
}

#[test]
fn slurm_array_study_equals_one_machine_and_resubmits_a_cancelled_shard() {
    let conf = match cluster() {
        Ok(c) => c,
        Err(why) => {
            eprintln!("SKIPPED: no slurm: {why}");
            println!("SKIPPED: no slurm: {why}");
            assert!(
                std::env::var("CLUTCHPACK_REQUIRE_SLURM").as_deref() != Ok("1"),
                "CLUTCHPACK_REQUIRE_SLURM=1 but no slurm: {why}"
            );
            return;
        }
    };
    let dir = scratch("slurm");
    // 3 design points x 4 members of 0.05 s: 12 short cases
    let s = small_study(&dir, 0.05, 4);
    let local = one_machine(&dir, &s);
    let want = std::fs::read(local.join("results.csv")).unwrap();

    // 1. the array of 4 shards and its dependent merge job, waited for
    let t0 = Instant::now();
    let a = dir.join("array");
    let o = submit(&conf, &s, &a, &["--wait"]);
    assert!(
        o.status.success(),
        "submit --wait: {:?}\n{}\n{}",
        o.status.code(),
        stdout(&o),
        stderr(&o)
    );
    let wall = t0.elapsed().as_secs_f64();
    eprintln!("slurm: 4-shard array + merge job of 12 cases: {wall:.1} s wall (submit to merged)");
    for i in 0..4 {
        assert!(a.join(format!("part-{i:05}-of-00004.json")).exists());
    }
    let merge_log = std::fs::read_dir(a.join("logs"))
        .unwrap()
        .filter_map(|e| e.ok())
        .any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with("ci-small-merge-")
        });
    assert!(merge_log, "the merge job wrote its log");
    assert_eq!(
        std::fs::read(a.join("results.csv")).unwrap(),
        want,
        "the Slurm study's table differs from the one-machine run"
    );
    assert_eq!(
        std::fs::read(a.join("summary.csv")).unwrap(),
        std::fs::read(local.join("summary.csv")).unwrap()
    );

    // 2. submitted held; shard 2 cancelled before it starts; the others released
    let t1 = Instant::now();
    let b = dir.join("cancelled");
    let o = submit(&conf, &s, &b, &["--hold"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    let text = stdout(&o);
    let (aid, mid) = (
        job_id(&text, "job array "),
        job_id(&text, "submitted merge as job "),
    );
    let c = slurm(&conf, "scancel", &[&format!("{aid}_2")]);
    assert!(c.status.success(), "scancel: {}", stderr(&c));
    let r = slurm(&conf, "scontrol", &["release", &aid]);
    assert!(r.status.success(), "scontrol release: {}", stderr(&r));
    // the merge job's afterok can no longer be met: Slurm cancels it
    wait_gone(&conf, &[&aid, &mid]);
    assert!(!b.join("results.csv").exists(), "no merge ran");
    let m = study(&["merge"], &[&b]);
    assert_eq!(m.status.code(), Some(3), "{}", stderr(&m));
    assert!(stdout(&m).contains("--array=2"), "{}", stdout(&m));
    assert!(
        stderr(&m).contains("1 of 4 shards missing or unfinished: 2"),
        "{}",
        stderr(&m)
    );

    // 3. resubmit index 2 only: its merge job completes the study
    let o = submit(&conf, &s, &b, &["--array", "2", "--wait"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert_eq!(std::fs::read(b.join("results.csv")).unwrap(), want);
    eprintln!(
        "slurm: held, scancel of shard 2, resubmission and merge: {:.1} s wall",
        t1.elapsed().as_secs_f64()
    );
}
