//! Reliability (issue 10): nothing lost, every signal honoured, impossible input refused.
//! Each test is named after what it protects; the reproducer numbers are the issue's.

use super::{bin, run, scratch, stderr, stdout};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// The binary run from `dir` (for default recording names, which go to `dir/recordings`).
fn bin_in(dir: &Path) -> Command {
    let mut c = bin();
    c.current_dir(dir);
    c
}

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// Waits for `child`, at most `limit` (a hang guard, not a speed assertion: it is minutes).
fn wait_at_most(child: &mut Child, limit: Duration) -> ExitStatus {
    let t0 = Instant::now();
    loop {
        if let Some(s) = child.try_wait().unwrap() {
            return s;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            panic!("the command did not stop within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn kill(child: &Child, signal: &str) {
    let k = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
}

fn recordings(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir.join("recordings"))
        .map(|r| r.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// Reproducer 1: runs one after the other, and two at once, with default names each leave
/// their own complete recording (millisecond names, collisions get `-2`, never a replace).
#[test]
fn default_recording_names_are_unique_per_run() {
    let d = scratch("rel-default-names");
    for h in ["0", "25e-6", "50e-6"] {
        let o = bin_in(&d)
            .args(["run", "--duration", "0.01", "--set"])
            .arg(format!("defaults.oil.film_thickness_m={h}"))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert_eq!(recordings(&d).len(), 3, "{:?}", recordings(&d));
    let spawn = || {
        bin_in(&d)
            .args(["run", "--duration", "0.01"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap()
    };
    let (mut a, mut b) = (spawn(), spawn());
    assert!(wait_at_most(&mut a, Duration::from_secs(300)).success());
    assert!(wait_at_most(&mut b, Duration::from_secs(300)).success());
    let files = recordings(&d);
    assert_eq!(files.len(), 5, "{files:?}");
    for f in &files {
        let o = run(&["replay", f.to_str().unwrap()]);
        assert!(o.status.success(), "{}: {}", f.display(), stderr(&o));
    }
}

/// Reproducer 2: an output naming the scene being run, or two outputs naming one file, are
/// refused before the run (exit 2, the flag named) and the scene is left as it was.
#[test]
fn outputs_never_overwrite_the_scene_or_each_other() {
    let d = scratch("rel-clobber");
    let scene = d.join("my.toml");
    std::fs::copy(repo("scenes/hu-table2.toml"), &scene).unwrap();
    let before = std::fs::read(&scene).unwrap();
    let o = bin_in(&d)
        .args(["run", "my.toml", "--duration", "0.01", "--out", "my.toml"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--out my.toml"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&scene).unwrap(),
        before,
        "the scene is untouched"
    );
    let o = bin_in(&d)
        .args(["run", "my.toml", "--duration", "0.01", "--out", "r.mcap"])
        .args(["--impacts-csv", "r.mcap"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("--impacts-csv r.mcap"),
        "{}",
        stderr(&o)
    );
    assert!(!d.join("r.mcap").exists(), "nothing was run");
}

/// Reproducers 5, 7 and 12: a FIFO, a device, a folder or a missing folder as an output is
/// refused before the simulation (a 1000 s run would otherwise take minutes): exit 2 naming
/// the flag and the path, nothing written.
#[test]
fn bad_output_paths_are_refused_before_the_run() {
    let d = scratch("rel-bad-outputs");
    let fifo = d.join("fifo.mcap");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let cases: [(&str, PathBuf); 4] = [
        ("--out", fifo.clone()),
        ("--impacts-csv", PathBuf::from("/dev/full")),
        ("--summary-json", d.clone()),
        ("--plot", d.join("no/such/folder/x.png")),
    ];
    for (flag, path) in cases {
        let mut c = bin();
        c.args(["run", "--duration", "1000", "--no-record"]);
        if flag == "--out" {
            c = bin();
            c.args(["run", "--duration", "1000"]);
        }
        let o = c.arg(flag).arg(&path).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{flag}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains(flag) && err.contains(&path.display().to_string()),
            "{err}"
        );
        assert!(!err.contains("panicked"));
    }
}

/// Starts a long run of the four-disc pack with its stdout captured.
fn long_run(out: &Path) -> Child {
    bin()
        .args([
            "run",
            "scenes/pack-4-rattle.toml",
            "--duration",
            "30",
            "--out",
        ])
        .arg(out)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Reproducer 3: SIGTERM (a scheduler's limit) and SIGHUP (a closed terminal), like SIGINT,
/// stop `run` with 128 + signal, the printed table, and a complete recording that the strict
/// reader accepts.
#[test]
fn sigterm_and_sighup_leave_a_complete_recording_and_the_table() {
    let d = scratch("rel-signals-run");
    for (signal, code) in [("-TERM", 143), ("-HUP", 129), ("-INT", 130)] {
        let f = d.join(format!("{signal}.mcap"));
        let mut child = long_run(&f);
        std::thread::sleep(Duration::from_secs(2));
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before the signal"
        );
        kill(&child, signal);
        let status = wait_at_most(&mut child, Duration::from_secs(120));
        let mut text = String::new();
        use std::io::Read as _;
        child
            .stdout
            .take()
            .unwrap()
            .read_to_string(&mut text)
            .unwrap();
        assert_eq!(status.code(), Some(code), "{signal}");
        assert!(text.contains("per-tooth impact loads"), "{signal}: {text}");
        let o = run(&["replay", f.to_str().unwrap()]);
        assert!(o.status.success(), "{signal}: {}", stderr(&o));
    }
}

/// Reproducer 6: a sweep stopped by SIGTERM or SIGINT prints the table of the cases that
/// finished and exits 128 + signal, with either engine.
#[test]
fn a_signal_stops_a_sweep_with_the_table_of_finished_cases() {
    // 48 cases of about 0.8 s wall each in a test build (the multirate engines run the
    // paper case at 25 and 10 simulated s per wall s): about 20 s on 2 threads, so the
    // signal at 3 s finds some cases finished and most still to come.
    let cases = [
        ("scenes/hu-table2.toml", "reference", "-TERM", 143, "20"),
        ("scenes/hu-table2.toml", "multibody", "-INT", 130, "8"),
    ];
    for (scene, engine, signal, code, duration) in cases {
        let mut child = bin()
            .args(["sweep", scene, "--engine", engine])
            .args(["--param", "defaults.oil.film_thickness_m"])
            .args([
                "--values",
                "0,25e-6,50e-6",
                "--ensemble",
                "16",
                "--jobs",
                "2",
            ])
            .arg("--set")
            .arg(format!("simulation.duration_s={duration}"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_secs(3));
        assert!(
            child.try_wait().unwrap().is_none(),
            "ended before the signal"
        );
        kill(&child, signal);
        let status = wait_at_most(&mut child, Duration::from_secs(120));
        let o = child.wait_with_output().unwrap();
        assert_eq!(status.code(), Some(code), "{engine}: {}", stderr(&o));
        assert!(
            stdout(&o).contains("per-tooth peak loads"),
            "{}",
            stdout(&o)
        );
        assert!(stderr(&o).contains("cases finished"), "{}", stderr(&o));
    }
}

/// Reproducer 7: `--jobs 100000` for two cases starts two threads.
#[test]
fn sweep_jobs_are_capped_to_the_cases() {
    let o = run(&[
        "sweep",
        "scenes/hu-table2.toml",
        "--param",
        "defaults.oil.film_thickness_m",
        "--values",
        "0,25e-6",
        "--jobs",
        "100000",
        "--set",
        "simulation.duration_s=0.01",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("on 2 threads"), "{}", stdout(&o));
}

/// Reproducer 8: `--salvage` that recovers no message is bad input, not a success.
#[test]
fn salvage_that_recovers_nothing_is_bad_input() {
    let d = scratch("rel-salvage-nothing");
    let f = d.join("r.mcap");
    let o = run(&["run", "--duration", "0.01", "--out", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&f).unwrap();
    let cut = d.join("cut.mcap");
    std::fs::write(&cut, &bytes[..40]).unwrap();
    let o = run(&["replay", "--salvage", cut.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("recovered no message"),
        "{}",
        stderr(&o)
    );
}

/// Reproducer 9: results that cannot be written to standard output (a full disk) fail the
/// command instead of exiting 0 with an empty file.
#[test]
fn stdout_write_errors_fail_the_command() {
    let d = scratch("rel-stdout-full");
    let f = d.join("r.mcap");
    let o = run(&["run", "--duration", "0.01", "--out", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let o = bin()
        .args(["compare", "--format", "json"])
        .arg(&f)
        .arg(&f)
        .stdout(full)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
}

/// Standard error that cannot be written (`2>/dev/full`) is no panic: the recorded run
/// still writes its table and a complete recording and exits 0; with standard output full
/// too, it fails with exit 1 (not 101, a panic, which `eprintln!` gave).
#[test]
fn stderr_write_errors_are_no_panic() {
    let d = scratch("rel-stderr-full");
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let f = d.join("r.mcap");
    let o = bin()
        .args(["run", "--duration", "0.01", "--out", f.to_str().unwrap()])
        .stderr(full())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert!(stdout(&o).contains("disc"), "{}", stdout(&o));
    let o = run(&["replay", f.to_str().unwrap()]);
    assert!(o.status.success(), "complete: {}", stderr(&o));
    let o = bin()
        .args(["run", "--duration", "0.01", "--out"])
        .arg(d.join("r2.mcap"))
        .stdout(full())
        .stderr(full())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
}

/// Reproducers 10 and 11 (rules on main, checked here end to end): a spline whose backlash
/// is not below the tooth pitch, a step or inertia no engine can use, a duration beyond the
/// bound, and a scene the chosen engine cannot run are refused before the run, exit 2 with
/// the key.
#[test]
fn impossible_or_mismatched_scenes_are_refused_with_the_key() {
    let cases: [(&[&str], &str); 6] = [
        (&["--set", "defaults.spline.teeth=10000"], "teeth"),
        (&["--set", "defaults.spline.backlash_m=10"], "backlash_m"),
        (&["--set", "simulation.max_step_s=1e-300"], "max_step_s"),
        (&["--set", "discs[0].inertia_kg_m2=5e-324"], "inertia_kg_m2"),
        (&["--duration", "1e19"], "duration_s"),
        (
            &["scenes/eccentric-disc.toml", "--engine", "reference"],
            "reference",
        ),
    ];
    for (args, key) in cases {
        let o = bin()
            .args(["run", "--no-record"])
            .args(args)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(key), "{args:?}: {}", stderr(&o));
    }
    let o = run(&[
        "check",
        "--engine",
        "reference",
        "scenes/eccentric-disc.toml",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// A small seeded generator (xorshift64*), so that the fuzz test is reproducible without a
/// dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// One mutation of a scene text: a value replaced by a hostile one, a line dropped or
/// doubled, or a key renamed.
fn mutate(text: &str, rng: &mut Rng) -> String {
    const VALUES: [&str; 28] = [
        "0",
        "-1",
        "1e308",
        "-1e308",
        "5e-324",
        "nan",
        "inf",
        "-inf",
        "4294967296",
        "1e19",
        "\"x\"",
        "\"\"",
        "true",
        "[]",
        "{}",
        "1e-300",
        "-0.0",
        "18446744073709551616",
        "0.5",
        "2",
        "1e6",
        "[1, 2]",
        // issue 25: tiny and huge physical values, counts at and past i64's end
        "1e-9",
        "1e9",
        "1e-308",
        "9223372036854775807",
        "4611686018427387905",
        "-9223372036854775808",
    ];
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let with_value: Vec<usize> = (0..lines.len())
        .filter(|&i| {
            let l = lines[i].trim_start();
            l.contains('=') && !l.starts_with('#')
        })
        .collect();
    if with_value.is_empty() {
        return text.to_string();
    }
    let i = with_value[rng.below(with_value.len())];
    match rng.below(8) {
        0 => {
            lines.remove(i);
        }
        1 => {
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        2 => {
            let l = lines[i].replacen('_', "", 1);
            lines[i] = l;
        }
        _ => {
            let key = lines[i].split('=').next().unwrap_or("").to_string();
            lines[i] = format!("{key}= {}", VALUES[rng.below(VALUES.len())]);
        }
    }
    lines.join("\n") + "\n"
}

/// `n` mutated scenes (one to three mutations each of `sources`' texts in turn, seeded by
/// `seed`) written into `dir` as `<prefix><k>.toml`.
pub(super) fn mutated_scenes(
    dir: &Path,
    sources: &[String],
    n: usize,
    seed: u64,
    prefix: &str,
) -> Vec<PathBuf> {
    let mut rng = Rng(seed);
    let mut files = Vec::new();
    for k in 0..n {
        let mut text = sources[k % sources.len()].clone();
        for _ in 0..1 + rng.below(3) {
            text = mutate(&text, &mut rng);
        }
        let f = dir.join(format!("{prefix}{k:04}.toml"));
        std::fs::write(&f, text).unwrap();
        files.push(f);
    }
    files
}

/// The files `check` accepts, checked `batch` at a time; every `check` exits 0 or 2 and
/// nothing panics.
pub(super) fn accepted_by_check(files: &[PathBuf], batch: usize) -> Vec<PathBuf> {
    let mut accepted = Vec::new();
    for chunk in files.chunks(batch) {
        let o = bin().arg("check").args(chunk).output().unwrap();
        let (out, err) = (stdout(&o), stderr(&o));
        assert!(
            matches!(o.status.code(), Some(0) | Some(2)),
            "check: {:?}: {err}",
            o.status
        );
        assert!(
            !err.contains("panicked") && !out.contains("panicked"),
            "{err}"
        );
        for f in chunk {
            if out.contains(&format!("{}: ok", f.display())) {
                accepted.push(f.clone());
            }
        }
    }
    accepted
}

/// `clutchpack run` with `args` then `file`, killed and failed after `limit` (a hang guard,
/// not a speed assertion). Nothing panics; the exit code is 0 or 2, or 1 saying the run
/// diverged (then `false` is returned: the known gap); a run that exits 0 prints no `inf`
/// or `NaN`.
pub(super) fn run_ends_cleanly(args: &[&str], file: &Path, limit: Duration) -> bool {
    let what = format!("run {args:?} {}", file.display());
    let mut child = bin()
        .arg("run")
        .args(args)
        .arg(file)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > limit {
            let _ = child.kill();
            panic!("{what}: did not end within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let o = child.wait_with_output().unwrap();
    let err = stderr(&o);
    assert!(!err.contains("panicked"), "{what}: {err}");
    if o.status.code() == Some(1) && err.contains(KNOWN_GAP) {
        return false;
    }
    assert!(
        matches!(o.status.code(), Some(0) | Some(2)),
        "{what}: {:?}: {err}",
        o.status
    );
    // issue 25: a result is finite or refused, never `inf` or `NaN` with exit 0
    if o.status.success() {
        let out = stdout(&o);
        let bad = out
            .split(|c: char| c.is_whitespace() || c == ',')
            .find(|w| matches!(w.to_ascii_lowercase().as_str(), "inf" | "-inf" | "nan"));
        assert!(bad.is_none(), "{what}: printed {bad:?}:\n{out}");
    }
    true
}

/// A bounded, seeded fuzz test: 3000 scenes, each one to three mutations of a shipped
/// scene, go through `check` (all in a few invocations) and, for those it accepts and a
/// sample of the others, a very short `run`. No panic, no crash: every exit code of `check`
/// is 0 or 2 (bad input), and so is every `run`'s, but for one known gap, listed and
/// printed: a scene the rules accept whose engine diverges (exit 1, "diverged"), e.g. a
/// loss coefficient of 1e19 s/m, which the engine's stall check stops within a second (the
/// contact values have no joint plausibility rule; docs/DECISIONS.md, "Plausibility bounds").
/// Issue 25 added tiny and huge physical values and counts at i64's ends to the values, and
/// that a run that exits 0 prints no `inf` or `NaN`.
#[test]
fn mutated_scenes_give_exit_0_or_2_and_never_a_panic() {
    let d = scratch("rel-fuzz");
    let sources: Vec<String> = [
        "hu-table2",
        "pack-4-rattle",
        "eccentric-disc",
        "pack-6-engagement",
    ]
    .iter()
    .map(|n| std::fs::read_to_string(repo(&format!("scenes/{n}.toml"))).unwrap())
    .collect();
    let files = mutated_scenes(&d, &sources, 3000, 0x5eed_1234_abcd_0001, "m");
    let accepted = accepted_by_check(&files, 500);
    assert!(!accepted.is_empty(), "some mutations are harmless");
    // a very short run of a sample of accepted and refused scenes
    let mut sample: Vec<&PathBuf> = accepted.iter().step_by(accepted.len() / 60 + 1).collect();
    sample.extend(files.iter().step_by(100));
    let mut diverged = Vec::new();
    for f in sample {
        let args = ["--no-record", "--duration", "0.002"];
        if !run_ends_cleanly(&args, f, Duration::from_secs(120)) {
            diverged.push(f.display().to_string());
        }
    }
    if !diverged.is_empty() {
        eprintln!("accepted but diverged at once (known gap): {diverged:?}");
    }
}

/// The one run failure the fuzz test tolerates (see its documentation).
const KNOWN_GAP: &str = "the simulation diverged";
