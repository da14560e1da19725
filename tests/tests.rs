//! Integration tests of the `clutchpack` binary: the paper's table from a sweep, the CLI
//! outputs, and bad input. One test binary (as ripgrep does); each test states what it checks.

mod architecture;
mod automatics;
mod automatics_shift;
mod common;
mod cosim_hardening;
mod cross_engine;
mod fatigue;
mod fit;
mod fmu;
mod hardening;
mod hardening_networks;
mod locked_packs;
mod network;
mod network_engines;
mod prescribed_pack;
mod prescribed_speed;
mod python_package;
mod reliability;
mod salvage_and_messages;
mod session;
mod slurm;
mod study;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_clutchpack"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("the binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A fresh scratch folder under target/ for one test.
fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn read_json(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// The paper's published peaks (Hu et al., section "Numerical simulation"): h_o in m,
/// max positive and max negative per-tooth load in N.
const PAPER: [(f64, f64, f64); 3] = [
    (0.0, 945.39, -976.42),
    (25e-6, 867.6, -867.8),
    (50e-6, 503.1, -503.5),
];

/// Checks a sweep summary against the paper: each of the six published peaks within 10 %
/// (MODEL.md says a correct implementation lands within about 10 %; the rattle is chaotic, so
/// a single 0.3 s sample scatters by several per cent), and both peaks falling monotonically
/// from 25 to 100 um.
fn check_paper_table(summary: &Value) {
    let rows = summary["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 5);
    let mean = |r: &Value, k: &str| r[k]["mean"].as_f64().unwrap();
    for (h_o, pos, neg) in PAPER {
        let r = rows
            .iter()
            .find(|r| (r["value"].as_f64().unwrap() - h_o).abs() < 1e-12)
            .unwrap();
        let (p, n) = (mean(r, "max_positive"), mean(r, "max_negative"));
        assert!(
            (p - pos).abs() < 0.10 * pos,
            "h_o {h_o}: max + {p} vs {pos}"
        );
        assert!(
            (n - neg).abs() < 0.10 * neg.abs(),
            "h_o {h_o}: max - {n} vs {neg}"
        );
    }
    for w in rows[1..].windows(2) {
        assert!(
            mean(&w[1], "max_positive") < mean(&w[0], "max_positive"),
            "{w:?}"
        );
        assert!(
            mean(&w[1], "max_negative") > mean(&w[0], "max_negative"),
            "{w:?}"
        );
    }
    // The quadratic fit exists for the disc and is decreasing at 50 um for max +.
    let fit = &summary["fits"][0]["max_positive"]["coefficients"];
    let c1 = fit[1].as_f64().unwrap();
    let c2 = fit[2].as_f64().unwrap();
    assert!(c1 + 2.0 * c2 * 50e-6 < 0.0);
}

fn paper_sweep(extra: &[&str], dir: &Path) -> Value {
    let json = dir.join("sweep.json");
    let mut args = vec![
        "sweep",
        "scenes/hu-table2.toml",
        "--param",
        "defaults.oil.film_thickness_m",
        "--values",
        "0,25e-6,50e-6,75e-6,100e-6",
        "--summary-json",
        json.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    read_json(&json)
}

/// The paper's table, one case per film thickness (the command the README's table quotes).
#[test]
fn sweep_reproduces_the_paper_table() {
    let d = scratch("sweep_single");
    let s = paper_sweep(&["--plot", d.join("fig3.png").to_str().unwrap()], &d);
    check_paper_table(&s);
    assert!(std::fs::metadata(d.join("fig3.png")).unwrap().len() > 1000);
}

/// The same with 16-member ensembles: the ensemble means meet the same bounds.
#[test]
fn ensemble_means_reproduce_the_paper_table() {
    let d = scratch("sweep_ensemble");
    let s = paper_sweep(&["--ensemble", "16"], &d);
    check_paper_table(&s);
    let r0 = &s["rows"][0];
    assert_eq!(r0["max_positive"]["n"].as_u64(), Some(16));
    assert!(
        r0["max_positive"]["std"].as_f64().unwrap() > 0.0,
        "members differ"
    );
}

/// `run` writes the summary JSON with the documented fields and an impacts CSV whose rows
/// agree with it (max of the CSV peaks = the summary's max).
#[test]
fn run_writes_summary_and_impacts() {
    let d = scratch("run_outputs");
    let json = d.join("s.json");
    let csv = d.join("i.csv");
    let plot = d.join("loads.svg");
    let o = run(&[
        "run",
        "--duration",
        "0.05",
        "--summary-json",
        json.to_str().unwrap(),
        "--impacts-csv",
        csv.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("max + [N]"));
    let s = read_json(&json);
    for k in ["engine", "duration_s", "wall_time_s", "steps", "discs"] {
        assert!(s.get(k).is_some(), "missing {k}");
    }
    assert_eq!(s["engine"], "reference");
    assert!((s["duration_s"].as_f64().unwrap() - 0.05).abs() < 1e-12);
    let disc = &s["discs"][0];
    for k in [
        "name",
        "max_positive_n",
        "max_negative_n",
        "p99_abs_n",
        "impacts",
    ] {
        assert!(disc.get(k).is_some(), "missing discs[0].{k}");
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("disc,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n")
    );
    let peaks: Vec<f64> = lines
        .map(|l| l.split(',').nth(6).unwrap().parse().unwrap())
        .collect();
    assert_eq!(peaks.len() as u64, disc["impacts"].as_u64().unwrap());
    let maxp = peaks.iter().cloned().fold(0.0, f64::max);
    assert!((maxp - disc["max_positive_n"].as_f64().unwrap()).abs() < 1e-3);
    // the first impact is the one MODEL.md gives: shaft leads, -637.25 N
    assert!((peaks[0] + 637.25).abs() < 0.2, "{}", peaks[0]);
    assert!(std::fs::read_to_string(&plot).unwrap().contains("<svg"));
}

/// Every shipped scene is valid.
#[test]
fn shipped_scenes_check() {
    let mut args = vec!["check".to_string()];
    for e in std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            args.push(p.to_string_lossy().into_owned());
        }
    }
    assert!(args.len() >= 3);
    let o = bin().args(&args).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
}

const GOOD: &str = r#"
[simulation]
duration_s = 0.01
[drive]
kind = "sine"
omega0_rad_s = 200.0
amplitude_rad_s = 4.378
frequency_hz = 104.0
[defaults]
inertia_kg_m2 = 0.156
[defaults.spline]
teeth = 154
pitch_radius_m = 0.231
pressure_angle_deg = 20.0
backlash_m = 0.75e-3
[defaults.contact]
modulus_pa = 210e9
curvature_radius_m = 1.75e-3
[[discs]]
name = "d"
"#;

/// Runs `run` on `text` (written to a file) with `extra` arguments and expects exit code 2
/// with each of `needles` in stderr.
fn expect_bad(name: &str, text: &str, extra: &[&str], needles: &[&str]) {
    let d = scratch(&format!("bad_{name}"));
    let p = d.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    let mut args = vec!["run", p.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = run(&args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{name}: {err}");
    for n in needles {
        assert!(err.contains(n), "{name}: expected {n:?} in:\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// Bad input exits with code 2 and names the file, the key, the value and the rule.
#[test]
fn bad_scenes_exit_2_with_key_value_and_rule() {
    // the good scene is good
    let d = scratch("good");
    let p = d.join("good.toml");
    std::fs::write(&p, GOOD).unwrap();
    let o = run(&["run", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));

    let sub = |from: &str, to: &str| {
        assert!(GOOD.contains(from));
        GOOD.replace(from, to)
    };
    expect_bad(
        "negative_inertia",
        &sub("inertia_kg_m2 = 0.156", "inertia_kg_m2 = -0.156"),
        &[],
        &[
            "negative_inertia.toml",
            "defaults.inertia_kg_m2",
            "-0.156",
            "must be > 0",
        ],
    );
    expect_bad(
        "zero_teeth",
        &sub("teeth = 154", "teeth = 0"),
        &[],
        &["defaults.spline.teeth", "= 0", ">= 1"],
    );
    expect_bad(
        "missing_key",
        &sub("modulus_pa = 210e9\n", ""),
        &[],
        &["modulus_pa", "missing"],
    );
    expect_bad(
        "unknown_key",
        &sub("[[discs]]", "[[discs]]\nthickness_mm = 3"),
        &[],
        &["discs[0].thickness_mm", "unknown key"],
    );
    expect_bad(
        "nan",
        &sub("frequency_hz = 104.0", "frequency_hz = nan"),
        &[],
        &["drive.frequency_hz", "nan", "finite"],
    );
    expect_bad(
        "malformed",
        "[simulation\nduration_s = 1",
        &[],
        &["malformed.toml", "line 1"],
    );
    expect_bad(
        "zero_backlash",
        &sub("backlash_m = 0.75e-3", "backlash_m = 0.0"),
        &[],
        &["defaults.spline.backlash_m", "0", "must be > 0"],
    );
    expect_bad(
        "negative_backlash",
        &sub("backlash_m = 0.75e-3", "backlash_m = -1e-3"),
        &[],
        &["defaults.spline.backlash_m", "-0.001", "must be > 0"],
    );
    expect_bad(
        "unknown_set",
        GOOD,
        &["--set", "defaults.oil.film_thickness_um=25"],
        &["defaults.oil.film_thickness_um", "--set", "unknown key"],
    );
    // several problems: all listed at once
    let several = sub("inertia_kg_m2 = 0.156", "inertia_kg_m2 = -1.0")
        .replace("teeth = 154", "teeth = 0")
        .replace("frequency_hz = 104.0", "frequency_hz = nan")
        .replace("[[discs]]", "[[discs]]\nbogus = 1");
    expect_bad(
        "several",
        &several,
        &[],
        &[
            "defaults.inertia_kg_m2",
            "defaults.spline.teeth",
            "drive.frequency_hz",
            "discs[0].bogus",
        ],
    );
}

/// `check` on a bad scene exits 2 and lists its problems; on a good one exits 0.
#[test]
fn check_exit_codes() {
    let d = scratch("check");
    let good = d.join("good.toml");
    let bad = d.join("bad.toml");
    std::fs::write(&good, GOOD).unwrap();
    std::fs::write(&bad, GOOD.replace("teeth = 154", "teeth = -3")).unwrap();
    assert!(run(&["check", good.to_str().unwrap()]).status.success());
    let o = run(&["check", good.to_str().unwrap(), bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("defaults.spline.teeth"));
}

/// Bad command-line values are bad input too (exit 2), never a panic.
#[test]
fn bad_arguments_exit_2() {
    for args in [
        vec!["run", "no-such-scene.toml"],
        vec!["run", "--duration", "-1"],
        vec![
            "sweep",
            "scenes/hu-table2.toml",
            "--param",
            "defaults.oil.film_thickness_m",
            "--values",
            "0",
            "--ensemble",
            "0",
        ],
        vec![
            "sweep",
            "scenes/hu-table2.toml",
            "--param",
            "defaults.oil.nope",
            "--values",
            "0",
        ],
        vec!["run", "--engine", "warp"],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"));
    }
}

// ---------------------------------------------------------------------------------------
// Recordings (issue 4)

/// Records the paper case with `extra` arguments into `path` (deterministic, 0.3 s).
fn record(path: &Path, extra: &[&str]) {
    let mut args = vec!["run", "--deterministic", "--out", path.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `compare` of the paper case at h_o = 0 and 50 um reports the drop of both peaks that the
/// paper reports ("the extent of decrease is about 50 %": 945 -> 503 N, -47 %; 976 -> 504 N,
/// -48 %): each change within -40 % .. -60 %.
#[test]
fn compare_reports_the_papers_fifty_percent_drop() {
    let d = scratch("compare");
    let a = d.join("h0.mcap");
    let b = d.join("h50.mcap");
    record(&a, &[]);
    record(&b, &["--set", "defaults.oil.film_thickness_m=50e-6"]);
    let o = run(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows: Value = serde_json::from_slice(&o.stdout).unwrap();
    let second = &rows[1];
    for k in ["max_positive_change_pct", "max_negative_change_pct"] {
        let c = second[k].as_f64().unwrap();
        assert!((-60.0..=-40.0).contains(&c), "{k} = {c}");
    }
    let png = d.join("cmp.png");
    let o = run(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("-4"), "{}", stdout(&o));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

/// The same scene run twice with --deterministic gives byte-identical recordings; without it
/// the wall-clock metadata differs.
#[test]
fn deterministic_recordings_are_byte_identical() {
    let d = scratch("deterministic");
    let a = d.join("a.mcap");
    let b = d.join("b.mcap");
    record(
        &a,
        &[
            "--duration",
            "0.05",
            "--set",
            "defaults.oil.film_thickness_m=25e-6",
        ],
    );
    record(
        &b,
        &[
            "--duration",
            "0.05",
            "--set",
            "defaults.oil.film_thickness_m=25e-6",
        ],
    );
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

/// A network scene's recording is byte-identical between two --deterministic runs too (the
/// attached summary once kept the run's wall time), here an automatic with its shift status.
#[test]
fn deterministic_network_recordings_are_byte_identical() {
    let d = scratch("deterministic-network");
    let files: Vec<_> = ["a", "b"]
        .iter()
        .map(|n| {
            let f = d.join(format!("{n}.mcap"));
            let o = run(&[
                "run",
                "scenes/eight-speed.toml",
                "--duration",
                "1.3",
                "--deterministic",
                "--out",
                f.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            std::fs::read(f).unwrap()
        })
        .collect();
    assert!(
        files[0] == files[1],
        "two deterministic network recordings differ"
    );
}

/// A recording read back gives the same per-disc statistics as the run printed, and `plot`
/// and `export` work from it.
#[test]
fn recordings_round_trip_through_replay_plot_and_export() {
    let d = scratch("roundtrip");
    let f = d.join("pack.mcap");
    let json = d.join("s.json");
    let o = run(&[
        "run",
        "scenes/pack-4-rattle.toml",
        "--duration",
        "0.05",
        "--out",
        f.to_str().unwrap(),
        "--summary-json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = read_json(&json);
    let o = run(&[
        "compare",
        f.to_str().unwrap(),
        f.to_str().unwrap(),
        "--format",
        "json",
    ]);
    let rows: Value = serde_json::from_slice(&o.stdout).unwrap();
    for (i, disc) in s["discs"].as_array().unwrap().iter().enumerate() {
        assert_eq!(rows[i]["disc"], disc["name"]);
        assert_eq!(rows[i]["max_positive_n"], disc["max_positive_n"]);
        assert_eq!(rows[i]["impacts"], disc["impacts"]);
    }
    let o = run(&["replay", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    for needle in [
        "/tf",
        "foxglove.FrameTransforms",
        "/discs/disc-4-far/spline",
        "/impacts",
        "pack-4-rattle.toml",
    ] {
        assert!(text.contains(needle), "{needle} in {text}");
    }
    let fig = d.join("loads.png");
    assert!(
        run(&["plot", f.to_str().unwrap(), "-o", fig.to_str().unwrap()])
            .status
            .success()
    );
    assert!(std::fs::metadata(&fig).unwrap().len() > 1000);
    let csv = d.join("csv");
    assert!(run(&[
        "export",
        f.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap()
    ])
    .status
    .success());
    assert!(csv.join("impacts.csv").exists());
}

/// Truncated, bit-flipped (inside a chunk), empty and non-MCAP files: exit code 2 and a
/// one-line reason, from every reading command; never a panic.
#[test]
fn bad_recordings_exit_2_with_one_line() {
    let d = scratch("badfiles");
    let good = d.join("good.mcap");
    record(&good, &["--duration", "0.05"]);
    let bytes = std::fs::read(&good).unwrap();
    let truncated = d.join("truncated.mcap");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let flipped = d.join("flipped.mcap");
    let mut f = bytes.clone();
    // the first chunk starts right after the header; flip a byte well inside it
    f[200] ^= 0x5a;
    std::fs::write(&flipped, &f).unwrap();
    let empty = d.join("empty.mcap");
    std::fs::write(&empty, b"").unwrap();
    let text = d.join("text.mcap");
    std::fs::write(&text, b"name,value\n1,2\n").unwrap();
    for file in [&truncated, &flipped, &empty, &text] {
        for cmd in [
            vec!["replay", file.to_str().unwrap()],
            vec!["compare", good.to_str().unwrap(), file.to_str().unwrap()],
            vec!["plot", file.to_str().unwrap(), "-o", "x.png"],
        ] {
            let o = run(&cmd);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{cmd:?}: {err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{cmd:?}: {err}");
            assert!(
                err.contains(file.file_name().unwrap().to_str().unwrap()),
                "{err}"
            );
            assert!(!err.contains("panicked"));
        }
    }
}

/// Path of the independent reader's python (tests/python/setup.sh installs the official
/// `mcap` and `mcap-protobuf-support` packages into target/pyenv).
/// Also rainflow, numpy (tests/fatigue.rs), pyarrow (tests/study.rs) and the Rerun CLI
/// (rerun-sdk: [`rerun_cli`]). Installed once per
/// test run: the tests that need it wait for the first (two setup.sh at once would both
/// rebuild the environment).
fn python_reader() -> PathBuf {
    static PY: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    PY.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let o = Command::new("bash")
            .arg(root.join("tests/python/setup.sh"))
            .output()
            .expect("bash runs");
        assert!(o.status.success(), "setup.sh: {}", stderr(&o));
        PathBuf::from(String::from_utf8(o.stdout).unwrap().trim())
    })
    .clone()
}

fn read_independently(file: &Path, allow_truncated: bool) -> Value {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut c = Command::new(python_reader());
    c.arg(root.join("tests/python/read_mcap.py"))
        .arg(file)
        .arg("--json");
    if allow_truncated {
        c.arg("--allow-truncated");
    }
    let o = c.output().unwrap();
    assert!(
        o.status.success(),
        "read_mcap.py {}: {}",
        file.display(),
        stderr(&o)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Starts a long run of the four-disc pack (30 s simulated, several seconds of wall time),
/// waits `secs`, sends `signal` and returns the exit status and the recording.
fn signal_run(dir: &Path, signal: &str, secs: f64) -> (std::process::ExitStatus, PathBuf) {
    let f = dir.join(format!("{signal}.mcap"));
    let mut child = bin()
        .args([
            "run",
            "scenes/pack-4-rattle.toml",
            "--duration",
            "30",
            "--out",
        ])
        .arg(&f)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_secs_f64(secs));
    let still_running = child.try_wait().unwrap().is_none();
    assert!(
        still_running,
        "the run ended before the signal: make it longer"
    );
    let k = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    (child.wait().unwrap(), f)
}

/// Ctrl-C (SIGINT) stops the run cleanly: exit code 130 and a complete file with its
/// summary, which the independent reader decodes in full.
#[test]
fn sigint_leaves_a_complete_recording() {
    let d = scratch("sigint");
    let (status, f) = signal_run(&d, "-INT", 2.0);
    assert_eq!(status.code(), Some(130));
    let r = read_independently(&f, false);
    assert_eq!(r["complete"], true, "{r}");
    assert!(r["summary"].is_object(), "{r}");
    assert!(r["messages"].as_u64().unwrap() > 100);
    assert_eq!(r["topics"]["/tf"]["schema"], "foxglove.FrameTransforms");
    assert_eq!(r["topics"]["/scene"]["schema"], "foxglove.SceneUpdate");
    let o = run(&["replay", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// SIGKILL mid-way: the file is truncated, but the chunks flushed (at least once per second
/// of wall time) are there. The recording is written as `<stem>.partial-<pid>-<k>.mcap` and
/// renamed when complete (issue 10), so a killed run leaves nothing under the final name and
/// the partial file beside it. After 3.5 s the independent reader recovers and decodes every
/// message of the flushed chunks, from t = 0; our own reader refuses the file
/// (exit 2) unless --salvage, and with it gives the same count.
#[test]
fn sigkill_leaves_a_file_readable_up_to_the_last_flush() {
    let d = scratch("sigkill");
    let (status, target) = signal_run(&d, "-KILL", 3.5);
    assert_eq!(status.code(), None, "killed by a signal");
    assert!(!target.exists(), "nothing under the final name");
    let f = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().contains("-KILL.partial-"))
        .expect("the partial recording");
    let r = read_independently(&f, true);
    assert_eq!(r["complete"], false, "{r}");
    let n = r["messages"].as_u64().unwrap();
    assert!(n > 0, "{r}");
    let shaft = &r["topics"]["/shaft"];
    assert_eq!(shaft["first_log_time"].as_u64(), Some(0));
    let o = run(&["replay", f.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = run(&["replay", "--salvage", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains(&format!("{n} messages")),
        "{}",
        stdout(&o)
    );
}

/// A pack with a stack records one `/interfaces/<lower>__<upper>` topic per friction
/// interface (plate 1 | disc 1 | plate 2 | ... in stack order), every message of which the
/// independent reader decodes. The recorded fields hang together: while an interface slips
/// under clamp, its torque opposes the slip and is `mu F R_eff` (R_eff = slip_m_s /
/// slip_rad_s, the same on every face) within 1e-9: the multirate scheme's clamped stack
/// reports each face's torque at the sample itself (issue 20; measured 0 over 3857 slipping
/// samples; the shared step reports the torque of its last step against the current clamp,
/// which ramps and drops at each spline impact: median 8.5e-5, largest 4.2 %). Each interface's heat `dissipated_j` never
/// falls, and matches the trapezoidal integral of the sampled power `-torque slip` within 1 %
/// (two different paths: the engine sums each step's impulse times the step's mean slip;
/// measured within 0.3 % at 10 kHz). The engagement scene locks at 86 ms and stays locked
/// but for micro-slips: its faces are clamped right at their static capacity (DECISIONS,
/// "Whole packs in the reference engine"), and at the drive's peaks (every 9.6 ms) a face may
/// slip by 1e-5 to 1e-3 rad/s and re-lock within a millisecond. So from 90 ms on every
/// interface is locked in at least half the samples and gains less than 0.05 J of heat (of
/// the 3000 J or so each dissipates in the engagement). How much the faces micro-slip is
/// chaotic: over ten realisations of the run (the discs' inertia moved by -4.5e-12 to
/// 4.5e-12 of itself; issue 46) the least locked interface held in 68-100 % of the samples
/// from 90 ms on the reference engine (exact stick-slip events; median 74 %, at most
/// 1.05e-2 J since), 56-100 % on the multibody engine (median 80 %, at most 3.7e-2 J), and
/// 73-100 % before issue 46 took the kinks' floor at 1/8 for a coupling alone (median 95 %,
/// at most 7.2e-3 J). This run: interface 8 locked in 75 of 101 samples, 4.6e-3 J (84 and
/// 2.2e-3 J before; the shared step's velocity-level friction missed these micro-slips, all
/// 101 locked). `run` prints the interfaces' table.
#[test]
fn stack_recordings_carry_the_friction_interfaces() {
    let d = scratch("interfaces");
    let f = d.join("engagement.mcap");
    let o = run(&[
        "run",
        "scenes/pack-6-engagement.toml",
        "--duration",
        "0.1",
        "--deterministic",
        "--out",
        f.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("friction interfaces") && stdout(&o).contains("plate-1__disc-1"),
        "{}",
        stdout(&o)
    );
    let j = read_independently(&f, false);
    let topics = j["topics"].as_object().unwrap();
    let samples = topics["/shaft"]["count"].as_u64().unwrap();
    let interfaces: Vec<&String> = topics
        .keys()
        .filter(|t| t.starts_with("/interfaces/"))
        .collect();
    assert_eq!(
        interfaces.len(),
        12,
        "6 discs between 7 plates: {interfaces:?}"
    );
    for t in &interfaces {
        assert_eq!(topics[*t]["schema"], "clutchpack.InterfaceState", "{t}");
        assert_eq!(topics[*t]["count"].as_u64(), Some(samples), "{t}");
    }
    assert!(topics.contains_key("/interfaces/plate-1__disc-1"));
    assert!(topics.contains_key("/interfaces/disc-6__plate-7"));

    let r = clutchpack_record::open(&f).unwrap();
    let series = r.interface_series();
    assert_eq!(series.len(), 12);
    let mut errors = Vec::new();
    let mut r_eff = None;
    for (m, s) in series.iter().enumerate() {
        assert_eq!(s.index, m);
        let mut heat = 0.0;
        for w in s.states.windows(2) {
            assert!(
                w[1].dissipated_j >= w[0].dissipated_j,
                "interface {m}: heat fell"
            );
            let p = |x: &clutchpack_record::proto::InterfaceState| -x.torque_n_m * x.slip_rad_s;
            heat += 0.5 * (p(&w[0]) + p(&w[1])) * (w[1].t_s - w[0].t_s);
        }
        let last = s.states.last().unwrap().dissipated_j;
        assert!(
            (heat - last).abs() < 0.01 * last,
            "interface {m}: integrated power {heat} J vs dissipated {last} J"
        );
        let locked: Vec<_> = s.states.iter().filter(|x| x.t_s >= 0.09).collect();
        let held = locked.iter().filter(|x| x.locked).count();
        let gained = last - locked[0].dissipated_j;
        println!(
            "interface {m}: locked in {held} of {} samples from 90 ms, {gained:.2e} J since",
            locked.len()
        );
        assert!(
            held as f64 >= 0.5 * locked.len() as f64 && gained < 0.05,
            "interface {m}: locked in {held} of {} samples from 90 ms, {gained} J since",
            locked.len()
        );
        // stack body m is a plate for even m
        assert_eq!(
            s.lower.starts_with("plate"),
            m.is_multiple_of(2),
            "{}",
            s.lower
        );
        for x in &s.states {
            if x.slip_rad_s.abs() > 1e-6 {
                let r = x.slip_m_s / x.slip_rad_s;
                let r0 = *r_eff.get_or_insert(r);
                assert!((r - r0).abs() < 1e-12 * r0, "R_eff {r} vs {r0}");
            }
            if x.clamp_n > 5000.0 && !x.locked && x.slip_rad_s.abs() > 1e-3 {
                let want = x.mu * x.clamp_n * r_eff.unwrap();
                errors.push((x.torque_n_m.abs() - want).abs() / want);
                assert!(
                    x.torque_n_m * x.slip_rad_s < 0.0,
                    "interface {m} at {} s: friction opposes the slip",
                    x.t_s
                );
            }
        }
    }
    errors.sort_by(f64::total_cmp);
    let checked = errors.len();
    let (median, worst) = (errors[checked / 2], errors[checked - 1]);
    println!("torque vs mu F R_eff over {checked} slipping samples: median {median:.2e}, worst {worst:.2e}");
    assert!(
        median < 1e-9 && worst < 1e-9,
        "torque vs mu F R_eff: median {median:e}, worst {worst:e}"
    );
    assert!(checked > 500, "{checked} slipping samples checked");
}

/// A disc name holding a comma and a quote does not break the impacts CSV: the field is
/// quoted (RFC 4180, quotes doubled), so every row still has seven fields.
#[test]
fn impacts_csv_quotes_names() {
    let d = scratch("csv_names");
    let scene = d.join("odd-name.toml");
    let text = std::fs::read_to_string("scenes/hu-table2.toml")
        .unwrap()
        .replace("name = \"disc\"", "name = 'a,b \"c\"'");
    std::fs::write(&scene, text).unwrap();
    let csv = d.join("i.csv");
    let o = run(&[
        "run",
        scene.to_str().unwrap(),
        "--duration",
        "0.03",
        "--impacts-csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert!(!rows.is_empty(), "the run has impacts");
    for row in rows {
        let rest = row
            .strip_prefix("\"a,b \"\"c\"\"\",")
            .unwrap_or_else(|| panic!("name not quoted: {row}"));
        assert_eq!(rest.split(',').count(), 6, "{row}");
    }
}

/// The Rerun CLI of the `rerun-sdk` wheel (tests/python/requirements.txt) beside the
/// independent reader's python.
fn rerun_cli() -> PathBuf {
    let py = python_reader();
    py.with_file_name("rerun")
}

/// Rerun 0.41's own checks pass on fresh recordings of a clutch (plates, friction
/// interfaces: pack-6-engagement, reference engine) and of an eccentric disc (multibody
/// engine, radial float in `/tf`): `rerun mcap check --full` reports every topic `ok` with no
/// issue (timelines that disagree on row order, chunks out of order on a timeline), and the
/// `.rrd` that `rerun mcap convert` makes of the file passes `rerun rrd verify`.
#[test]
fn rerun_checks_our_recordings_clean() {
    let d = scratch("rerun_check");
    let rerun = rerun_cli();
    for (scene, duration) in [
        ("scenes/pack-6-engagement.toml", "0.05"),
        ("scenes/eccentric-disc.toml", "0.01"),
    ] {
        let name = Path::new(scene).file_stem().unwrap().to_str().unwrap();
        let mcap = d.join(format!("{name}.mcap"));
        record(&mcap, &[scene, "--duration", duration]);
        let o = Command::new(&rerun)
            .args(["mcap", "check", "--full"])
            .arg(&mcap)
            .output()
            .expect("rerun runs");
        let text = format!("{}{}", stdout(&o), stderr(&o));
        assert!(o.status.success(), "rerun mcap check {name}: {text}");
        // the table: "Status  ID  Chunks  Topic  Issues", a rule, one row per topic, up to the
        // first blank line (rerun's first run on a machine prints a welcome text after it)
        let rows: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("Status"))
            .skip(2)
            .take_while(|l| !l.trim().is_empty())
            .collect();
        // our own count: "<n> messages on <k> topics, t = ..."
        let info = stdout(&run(&["replay", mcap.to_str().unwrap()]));
        let topics: usize = info
            .split(" topics")
            .next()
            .and_then(|s| s.rsplit(' ').next())
            .and_then(|k| k.parse().ok())
            .unwrap_or_else(|| panic!("no topic count in: {info}"));
        assert!(topics >= 10, "{name}: {topics} topics");
        assert!(
            rows.len() >= topics,
            "{name}: {} rows for {topics} topics:\n{text}",
            rows.len()
        );
        for row in &rows {
            let cols: Vec<&str> = row.split_whitespace().collect();
            assert_eq!(cols.first(), Some(&"ok"), "{name}: {row}");
            assert_eq!(cols.last(), Some(&"—"), "{name}: {row}");
        }
        let rrd = d.join(format!("{name}.rrd"));
        let o = Command::new(&rerun)
            .args(["mcap", "convert"])
            .arg(&mcap)
            .arg("-o")
            .arg(&rrd)
            .output()
            .expect("rerun runs");
        assert!(
            o.status.success(),
            "rerun mcap convert {name}: {}",
            stderr(&o)
        );
        let o = Command::new(&rerun)
            .args(["rrd", "verify"])
            .arg(&rrd)
            .output()
            .expect("rerun runs");
        let text = format!("{}{}", stdout(&o), stderr(&o));
        assert!(
            o.status.success() && text.contains("verified without error"),
            "rerun rrd verify {name}: {text}"
        );
    }
}
