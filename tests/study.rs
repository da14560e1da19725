//! `clutchpack study`: sharded runs merge into the same table as one run, a stopped shard
//! resumes, bad study files exit 2 naming key, value and rule.

use super::{bin, scratch, stderr, stdout};
use std::path::{Path, PathBuf};
use std::process::Output;

/// A study file in `dir`: the paper case shortened to `duration` s, 3 film thicknesses x
/// `members` members (spread placement, random drive phase), a random drag.
pub fn small_study(dir: &Path, duration: f64, members: u32) -> PathBuf {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hu-table2.toml");
    let text = format!(
        r#"[study]
name = "ci-small"
scene = "{}"
engine = "reference"
seed = 2024
outputs = ["max_positive_n", "max_negative_n", "impacts"]

[ensemble]
members = {members}
initial_positions = "spread"
drive_phase = "random"

[set]
"simulation.duration_s" = {duration}

[[factor]]
key = "defaults.oil.film_thickness_m"
values = [0, 25e-6, 50e-6]

[[random]]
key = "defaults.drag_n_m_s_rad"
dist = "truncated_normal"
mean = 0.01
std = 0.002
low = 0.005
high = 0.015
"#,
        scene.display()
    );
    let p = dir.join("ci-small.toml");
    std::fs::write(&p, text).unwrap();
    p
}

pub fn study(args: &[&str], extra: &[&Path]) -> Output {
    let mut c = bin();
    c.arg("study").args(args);
    c.args(extra);
    c.output().expect("the binary runs")
}

fn ok(o: &Output, what: &str) {
    assert!(
        o.status.success(),
        "{what}: exit {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status.code(),
        stdout(o),
        stderr(o)
    );
}

/// Runs the whole study on one machine with `--jobs 1` and merges it; returns its folder.
pub fn one_machine(dir: &Path, study_file: &Path) -> PathBuf {
    let out = dir.join("one");
    let o = study(&["run", "--jobs", "1", "--out"], &[&out, study_file]);
    ok(&o, "study run");
    ok(&study(&["merge"], &[&out]), "study merge");
    out
}

/// The same study run as one shard on 1 thread, and as 3 shards on 2 threads, merges into
/// the same results table and summary, byte for byte: case k is a function of the file and k
/// only (the draws, the phase, the placement, the engine's numbers). Both Parquet files and
/// the main-effects plot are written.
#[test]
fn three_shards_merge_to_the_unsharded_table() {
    let dir = scratch("study-shards");
    let s = small_study(&dir, 0.03, 4);
    let one = one_machine(&dir, &s);
    let three = dir.join("three");
    for i in 0..3 {
        let shard = format!("{i}/3");
        let o = study(
            &["run", "--jobs", "2", "--shard", &shard, "--out"],
            &[&three, &s],
        );
        ok(&o, &shard);
    }
    let m = study(&["merge"], &[&three]);
    ok(&m, "merge of 3 shards");
    assert!(stdout(&m).contains("12 cases (0 failed)"), "{}", stdout(&m));
    let read = |d: &Path, f: &str| std::fs::read(d.join(f)).unwrap();
    let csv = read(&one, "results.csv");
    assert_eq!(csv, read(&three, "results.csv"));
    assert_eq!(read(&one, "summary.csv"), read(&three, "summary.csv"));
    let text = String::from_utf8(csv).unwrap();
    assert_eq!(text.lines().count(), 13, "{text}");
    // the runs are real: every case has impacts and steps
    let head: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert!(f[col("disc.impacts")].parse::<u64>().unwrap() > 0, "{line}");
        assert!(f[col("steps")].parse::<u64>().unwrap() > 0, "{line}");
        assert_eq!(f[col("error")], "", "{line}");
    }
    for d in [&one, &three] {
        assert!(std::fs::metadata(d.join("results.parquet")).unwrap().len() > 100);
        assert!(std::fs::metadata(d.join("main-effects.png")).unwrap().len() > 1000);
    }
}

/// SIGTERM in the middle of a shard: exit 143 and a valid part with the cases finished so
/// far; `merge` names the unfinished shard; the same command again runs only the missing
/// cases, and the table equals an uninterrupted run's.
#[test]
fn sigterm_mid_shard_leaves_a_valid_part_and_the_rerun_finishes_it() {
    let dir = scratch("study-sigterm");
    // 3 x 4 cases of 3 s simulated: several seconds on one thread
    let s = small_study(&dir, 3.0, 4);
    let out = dir.join("out");
    let mut child = bin()
        .args(["study", "run", "--jobs", "1", "--out"])
        .arg(&out)
        .arg(&s)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // the progress lines on stderr: signal once the first case has finished
    let (tx, rx) = std::sync::mpsc::channel::<String>();
    let err = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        let mut all = String::new();
        for line in std::io::BufReader::new(err).lines().map_while(Result::ok) {
            let _ = tx.send(line.clone());
            all.push_str(&line);
            all.push('\n');
        }
        all
    });
    let first = rx
        .iter()
        .find(|l| l.contains(": 1/12 cases"))
        .expect("a progress line after the first case");
    assert!(
        child.try_wait().unwrap().is_none(),
        "the shard ended before the signal: make it longer ({first})"
    );
    let k = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    let status = child.wait().unwrap();
    let err = reader.join().unwrap();
    assert_eq!(status.code(), Some(143), "{err}");
    assert!(err.contains("stopped by SIGTERM"), "{err}");
    let part = out.join("part-00000-of-00001.json");
    let done = |p: &Path| -> usize {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
        v["records"].as_array().unwrap().len()
    };
    let kept = done(&part);
    assert!((1..12).contains(&kept), "{kept} cases in the part");
    let m = study(&["merge"], &[&out]);
    assert_eq!(m.status.code(), Some(3), "{}", stderr(&m));
    assert!(stdout(&m).contains("--array=0"), "{}", stdout(&m));
    let again = study(&["run", "--jobs", "2", "--out"], &[&out, &s]);
    ok(&again, "rerun");
    let want = format!("{kept} skipped (already done), {} run", 12 - kept);
    assert!(
        stderr(&again).contains(&want),
        "{want} in {}",
        stderr(&again)
    );
    ok(&study(&["merge"], &[&out]), "merge after the rerun");
    let whole = one_machine(&dir, &s);
    assert_eq!(
        std::fs::read(out.join("results.csv")).unwrap(),
        std::fs::read(whole.join("results.csv")).unwrap()
    );
}

/// Bad study files and arguments exit 2 with the file, the key, the value and the rule, every
/// problem at once; nothing runs.
#[test]
fn bad_study_files_exit_2_naming_key_value_and_rule() {
    let dir = scratch("study-bad");
    let f = dir.join("bad.toml");
    std::fs::write(
        &f,
        r#"[study]
scene = "../../../scenes/hu-table2.toml"
engine = "fastest"
[ensemble]
members = 0
[[factor]]
key = "defaults.oil.film_thickness_m"
log = [0, 1e-4, 3]
[[random]]
key = "defaults.drag_n_m_s_rad"
dist = "gamma"
[spacing]
grade = 12
"#,
    )
    .unwrap();
    let o = study(&["run", "--out"], &[&dir.join("out"), &f]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    for want in [
        "bad.toml: study.engine = \"fastest\": must be one of: reference, multibody",
        "bad.toml: ensemble.members = 0: must be an integer in 1..=100000000",
        "bad.toml: factor[0].log = [0, 0.0001, 3]: a log range needs from > 0",
        "bad.toml: random[0].dist = \"gamma\": must be one of: uniform, normal, truncated_normal",
        "bad.toml: spacing.grade = 12: must be a tolerance class of ISO 1328-1:2013",
    ] {
        assert!(e.contains(want), "missing {want:?} in\n{e}");
    }
    assert!(!dir.join("out").exists(), "nothing runs");
    // a level the scene rejects names the factor, the value and the scene's rule
    let s = small_study(&dir, 0.01, 1);
    let text = std::fs::read_to_string(&s)
        .unwrap()
        .replace("values = [0, 25e-6, 50e-6]", "values = [0, -25e-6]");
    std::fs::write(&s, text).unwrap();
    let o = study(&["run", "--out"], &[&dir.join("out"), &s]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("factor[0].levels[1] (defaults.oil.film_thickness_m) = -0.000025"),
        "{}",
        stderr(&o)
    );
    // --shard auto never guesses N; a shard out of range; a syntax error names line and column
    let s = small_study(&dir, 0.01, 1);
    let o = study(&["run", "--shard", "auto", "--out"], &[&dir.join("o"), &s]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--shard auto needs --shards N"),
        "{}",
        stderr(&o)
    );
    let o = study(&["run", "--shard", "3/3", "--out"], &[&dir.join("o"), &s]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("shard 3 of 3"), "{}", stderr(&o));
    std::fs::write(&f, "[study]\nscene = \n").unwrap();
    let o = study(&["run", "--out"], &[&dir.join("o"), &f]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("bad.toml: line 2 column"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("o").exists());
}

/// `--shard auto` takes the index from the scheduler's environment (Slurm first, then
/// Kubernetes) and refuses an index outside 0..N.
#[test]
fn shard_auto_reads_the_array_index() {
    let dir = scratch("study-auto");
    let s = small_study(&dir, 0.01, 1);
    let out = dir.join("out");
    let o = bin()
        .args(["study", "run", "--shard", "auto", "--shards", "3", "--out"])
        .arg(&out)
        .arg(&s)
        .env("JOB_COMPLETION_INDEX", "2")
        .env_remove("SLURM_ARRAY_TASK_ID")
        .output()
        .unwrap();
    ok(&o, "k8s index");
    assert!(out.join("part-00002-of-00003.json").exists());
    let o = bin()
        .args(["study", "run", "--shard", "auto", "--shards", "3", "--out"])
        .arg(&out)
        .arg(&s)
        .env("SLURM_ARRAY_TASK_ID", "7")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("shard 7 of 3"), "{}", stderr(&o));
}

/// The Parquet table opens in pyarrow with the documented column names and types. Python:
/// `$CLUTCHPACK_PYTHON`, else the tests' environment (target/pyenv, which tests/python/setup.sh
/// installs with pyarrow); skipped loudly without pyarrow unless `CLUTCHPACK_REQUIRE_PYARROW=1`.
#[test]
fn parquet_opens_in_pyarrow() {
    let has = |py: &str| {
        std::process::Command::new(py)
            .args(["-c", "import pyarrow.parquet"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    let py = match std::env::var("CLUTCHPACK_PYTHON") {
        Ok(p) => p,
        Err(_) => crate::python_reader().display().to_string(),
    };
    if !has(&py) {
        eprintln!("SKIPPED: no pyarrow in {py} (set CLUTCHPACK_PYTHON to a python with pyarrow)");
        assert!(
            std::env::var("CLUTCHPACK_REQUIRE_PYARROW").as_deref() != Ok("1"),
            "CLUTCHPACK_REQUIRE_PYARROW=1 but {py} has no pyarrow"
        );
        return;
    }
    let dir = scratch("study-pyarrow");
    let s = small_study(&dir, 0.02, 2);
    let out = one_machine(&dir, &s);
    let script = r#"
import sys, pyarrow.parquet as pq
t = pq.read_table(sys.argv[1])
for f in t.schema:
    print(f"{f.name}:{f.type}:{f.nullable}")
print("rows", t.num_rows)
"#;
    let o = std::process::Command::new(&py)
        .args(["-c", script])
        .arg(out.join("results.parquet"))
        .output()
        .unwrap();
    ok(&o, "pyarrow");
    let text = stdout(&o);
    for want in [
        "case:int64:False",
        "design_point:int64:False",
        "member:int64:False",
        "defaults.oil.film_thickness_m:double:False",
        "defaults.drag_n_m_s_rad:double:False",
        "initial_fraction:double:False",
        "drive.phase_deg:double:False",
        "disc.peak_abs_n:double:True",
        "disc.max_positive_n:double:True",
        "disc.impacts:int64:True",
        "steps:int64:False",
        "simulated_s:double:False",
        "error:string:True",
        "rows 6",
    ] {
        assert!(text.contains(want), "{want} not in\n{text}");
    }
}

/// Issue 22: a study's cases carry the teeth's fatigue, and it is `clutchpack run`'s: for each
/// case of a two-level film study (one member, so the scene's own start), the merged table's
/// damage rate, life and damage-equivalent load equal those of `run --summary-json` of the
/// same scene with the same overrides, to the last printed digit (the same collector and
/// assessment; the CSV and JSON both print Rust's shortest round-trip form).
#[test]
fn study_fatigue_columns_equal_run() {
    let d = scratch("study-fatigue");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hu-table2.toml");
    let f = d.join("fatigue.toml");
    std::fs::write(
        &f,
        format!(
            r#"[study]
name = "fatigue"
scene = "{}"
engine = "reference"
[set]
"simulation.duration_s" = 0.05
[[factor]]
key = "defaults.oil.film_thickness_m"
values = [0, 25e-6]
"#,
            scene.display()
        ),
    )
    .unwrap();
    let out = one_machine(&d, &f);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 2);
    for (row, film) in rows.iter().zip(["0", "25e-6"]) {
        let summary = d.join(format!("run-{film}.json"));
        let o = super::run(&[
            "run",
            scene.to_str().unwrap(),
            "--no-record",
            "--engine",
            "reference",
            "--set",
            &format!("defaults.oil.film_thickness_m={film}"),
            "--set",
            "simulation.duration_s=0.05",
            "--summary-json",
            summary.to_str().unwrap(),
        ]);
        ok(&o, "run");
        let json = super::read_json(&summary);
        let fatigue = &json["fatigue"][0];
        for key in ["damage_rate_per_h", "life_h", "eq_load_range_n"] {
            let study: f64 = row[col(&format!("disc.{key}"))].parse().unwrap();
            let run = fatigue[key].as_f64().unwrap();
            assert!(run > 0.0 && run.is_finite(), "{key} = {run}");
            assert_eq!(study, run, "film {film}: {key}");
        }
    }
}
