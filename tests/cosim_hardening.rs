//! Hardening 2 (issue 36): the co-simulation front ends keep the promises of `clutchpack run`.
//! The FMU misused as a host would misuse it, each case in a child process
//! (tests/python/fmu_misuse.py through FMPy): every misuse answers fmi2Error with a logged
//! reason, never a signal. `clutchpack fmu --out` keeps the output policy. Each test is named
//! after what it protects; no test times anything.

use super::{bin, python_reader, scratch, stderr};
use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// The misuse cases' results (tests/python/fmu_misuse.py), run once for all the tests here.
fn misuse() -> &'static Value {
    static R: std::sync::OnceLock<Value> = std::sync::OnceLock::new();
    R.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let work = scratch("fmu-misuse");
        let o = Command::new(python_reader())
            .arg(root.join("tests/python/fmu_misuse.py"))
            .args(["--bin", env!("CARGO_BIN_EXE_clutchpack")])
            .arg("--root")
            .arg(root)
            .arg("--work")
            .arg(&work)
            .output()
            .expect("python runs");
        assert!(
            o.status.success(),
            "fmu_misuse.py: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        serde_json::from_slice(&o.stdout).unwrap()
    })
}

/// The case `name` ended in its child process without a signal, its last FMI call answered
/// fmi2Error (FMPy raised), and the FMU logged a reason containing each of `words`.
fn refused(name: &str, words: &[&str]) {
    let r = &misuse()[name];
    assert_eq!(r["exit"].as_i64(), Some(0), "{name}: the host died: {r}");
    assert_eq!(r["status"], "error", "{name}: not refused: {r}");
    let log = r["log"].to_string();
    for w in words {
        assert!(log.contains(w), "{name}: the log lacks {w:?}: {r}");
    }
}

/// `fmi2FreeInstance` twice, and a call on the freed instance: no double free, no use after
/// free (the registry of live components); the call answers fmi2Error.
#[test]
fn freeing_an_fmu_instance_twice_does_not_crash_the_host() {
    refused("free_twice", &[]);
}

/// `fmi2SetFMUstate` and `fmi2FreeFMUstate` of a freed state answer fmi2Error with a reason.
#[test]
fn a_freed_fmu_state_is_refused_not_dereferenced() {
    refused("set_freed_state", &["not a live state"]);
    refused("free_state_twice", &["not a live state"]);
}

/// A state saved by another instance (unrecorded) would rewind a recorded run; a state of
/// another scene's FMU would run the wrong pack: both refused.
#[test]
fn fmu_states_belong_to_their_instance() {
    refused(
        "state_of_another_instance",
        &["another run", "restores only"],
    );
    refused("state_of_another_scene", &["not a live state"]);
}

/// `recording_path` on a folder, on /dev/null (a character device the rename would replace)
/// and on the FMU's own scene: fmi2Error at fmi2ExitInitializationMode naming the parameter,
/// and /dev/null is still a character device.
#[test]
fn fmu_recording_path_keeps_the_output_policy() {
    refused(
        "recording_path_is_a_folder",
        &["recording_path", "is a folder"],
    );
    refused(
        "recording_path_is_dev_null",
        &["recording_path", "not a regular file"],
    );
    refused(
        "recording_path_is_the_fmus_scene",
        &["recording_path", "is an input"],
    );
    assert_eq!(misuse()["dev_null_is_a_character_device"], true);
}

/// A shaft speed of 1e9 rad/s, a piston pressure of 1e15 Pa, and a slope that would carry
/// the speed past its bound within the step: fmi2Error naming the input and the scene key's
/// bound (1e9, never 301 digits), before any step.
#[test]
fn fmu_inputs_are_checked_against_their_scene_keys_bounds() {
    refused(
        "shaft_speed_out_of_bounds",
        &["shaft.speed_rad_s = 1e9 rad/s", "[-100000, 100000]"],
    );
    refused(
        "pressure_out_of_bounds",
        &[
            "piston.pressure_pa = 1e15 Pa",
            "[0, 100000000]",
            "stack.pressure.pressure_pa",
        ],
    );
    refused(
        "slope_out_of_bounds",
        &["shaft.speed_rad_s", "held with its derivatives"],
    );
}

/// `fmi2DoStep(NaN, h)` blames the communication point, not the step size.
#[test]
fn fmu_do_step_at_nan_blames_the_communication_point() {
    refused("do_step_at_nan", &["currentCommunicationPoint = NaN"]);
}

/// An FMU whose packed scene was edited after it was built (a record rate of 1e300 Hz, which
/// aborted the host on a 9 GB allocation) is refused at fmi2Instantiate with the reason.
#[test]
fn an_fmu_with_an_edited_scene_is_refused_at_instantiation() {
    refused("edited_scene", &["changed since the FMU was built"]);
}

/// `clutchpack fmu` keeps the output policy of `run --out`, before any work: its own scene,
/// a folder and a FIFO are refused (exit 2, naming `--out`), and each is left as it was.
#[test]
fn fmu_out_keeps_the_output_policy() {
    let d = scratch("fmu-out-policy");
    let scene = d.join("s.toml");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hu-table2.toml"),
        &scene,
    )
    .unwrap();
    let before = std::fs::read(&scene).unwrap();
    let folder = d.join("folder.fmu");
    std::fs::create_dir(&folder).unwrap();
    let fifo = d.join("fifo.fmu");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (out, why) in [
        (&scene, "is an input"),
        (&folder, "is a folder"),
        (&fifo, "not a regular file"),
    ] {
        let o = bin()
            .arg("fmu")
            .arg(&scene)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{}: {err}", out.display());
        assert!(err.contains("--out") && err.contains(why), "{err}");
    }
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    assert!(std::fs::read_dir(&folder).unwrap().next().is_none());
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    let left: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".partial-"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Every way a co-simulated run can end, recorded (FMPy's simulate_fmu, whose last step
/// lands 1.4e-17 s past the stop time; a host stepping exactly to the stop; an early
/// fmi2Terminate; fmi2FreeInstance without terminating): the recording is complete, its
/// impacts' peaks stay within the run's per-tooth loads (about 160 N on pack-6-engagement; the
/// bound 1 kN has a 6x margin, the absurd peaks were 3.8e10 to 5.4e10 N) and it names the
/// scene that made it, the inputs driven and the stop time instead of the scene's duration.
#[test]
fn co_simulated_runs_end_without_absurd_peaks_and_say_what_made_them() {
    let ends = &misuse()["ends"];
    for (name, r) in ends.as_object().unwrap() {
        assert_eq!(r["export_exit"], 0, "{name}: {r}");
        assert!(
            r["replay"].as_str().unwrap().contains("complete"),
            "{name}: {r}"
        );
        let n = r["impacts"].as_u64().unwrap();
        assert!(n > 50, "{name}: {n} impacts: {r}");
        let peak = r["max_abs_peak_n"].as_f64().unwrap();
        assert!(
            peak > 100.0 && peak < 1e3,
            "{name}: largest |peak| {peak} N: {r}"
        );
        assert_eq!(r["scene_file"], "pack-6-engagement.toml", "{name}: {r}");
        let atts = r["attachments"].to_string();
        assert!(atts.contains("pack-6-engagement.toml"), "{name}: {r}");
        let params = &r["params"];
        assert_eq!(params["co_simulation"], "true", "{name}: {r}");
        // an FMU drives every input its pack has (the host set the pressure; the others
        // held their start values), named by their one public name (issue 33)
        assert!(
            params["driven_inputs"].as_str().is_some_and(|d| {
                d.contains("piston.pressure_pa") && d.contains("shaft.speed_rad_s")
            }),
            "{name}: {r}"
        );
        assert!(params.get("duration_s").is_none(), "{name}: {r}");
    }
    assert_eq!(ends["exact_stop"]["params"]["stop_time_s"], "0.12");
    assert!(ends["early_terminate"]["params"]
        .get("stop_time_s")
        .is_none());
}

/// Hardening 3, item 6: `recording_path` over the FMU's own shared library (in the folder the
/// host extracted) replaced it, and the next instance failed to load. Refused at
/// fmi2ExitInitializationMode naming the parameter; the library is intact and a second
/// instance from the same folder runs a step.
#[test]
fn fmu_recording_path_over_its_own_binary_is_refused() {
    refused(
        "recording_path_is_the_fmus_binary",
        &[
            "recording_path",
            "is an input of this run",
            "second instance ran",
        ],
    );
}

/// Hardening 3, item 7: a network FMU's inputs were checked for finiteness only: a drive
/// torque of 1e30 N m set before fmi2ExitInitializationMode made the first 1 ms step run for
/// minutes, a normal force of 1e30 N took fmi2OK. Both answer fmi2Error at fmi2SetReal,
/// naming the input and the scene key's bound.
#[test]
fn network_fmu_inputs_are_checked_against_their_scene_keys_bounds() {
    refused(
        "network_drive_torque_out_of_bounds",
        &[
            "bodies.crank.drive_torque_n_m = 1e30 N m",
            "[-10000000, 10000000]",
            "bodies[].drive.value_n_m",
        ],
    );
    refused(
        "network_clutch_force_out_of_bounds",
        &[
            "couplings.K2.normal_force_n = 1e30 N",
            "[0, 100000000]",
            "couplings[].max_normal_force_n",
        ],
    );
}
