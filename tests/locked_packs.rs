//! A resolved pack whose two carriers are members of one rigid group (issue 44, item 3): a
//! planetary set's sun and carrier, the ring held by a lumped brake (one degree of freedom,
//! the sun at three times the carrier's speed), a pack `K` between the sun (its discs) and the
//! carrier (its plates). The brake releases and `K` is applied: a power-on upshift to direct
//! drive, `K` open and slipping across the locked set, then slipping with the set free (two
//! degrees of freedom), then locked.

use super::common::{impacts_apart, network_impacts};
use super::{read_json, run, scratch, stderr};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Writes the pack `k.toml` (`scenes/dct-k2.toml` with its piston applied from 20 ms: 0.45 MPa
/// at 50 ms, 1.05 MPa at 0.2 s) and the scene `net.toml` into `dir`: the planetary set (sun
/// 48, ring 96 teeth), the sun driven with 100 N m at 300 rad/s, the carrier (2 kg m^2, 20 N m
/// road load) at 100 rad/s, the brake `B` on the ring released over 20-50 ms, `K` between the
/// sun and the carrier. Returns the scene's path.
fn planetary_scene(dir: &Path) -> PathBuf {
    let pack = std::fs::read_to_string("scenes/dct-k2.toml")
        .unwrap()
        .replace(
            "times_s = [0.0, 0.2, 0.35, 0.7, 0.8]",
            "times_s = [0.0, 0.02, 0.05, 0.15, 0.2]",
        );
    assert!(pack.contains("times_s = [0.0, 0.02, 0.05, 0.15, 0.2]"));
    std::fs::write(dir.join("k.toml"), pack).unwrap();
    let scene = dir.join("net.toml");
    std::fs::write(
        &scene,
        r#"
name = "pack-across-a-planetary"
[simulation]
duration_s = 0.3
record_rate_hz = 2000.0
max_step_s = 1e-3
[[bodies]]
name = "sun"
inertia_kg_m2 = 0.05
initial_speed_rad_s = 300.0
[bodies.drive]
kind = "constant"
value_n_m = 100.0
[[bodies]]
name = "ring"
inertia_kg_m2 = 0.1
initial_speed_rad_s = 0.0
[[bodies]]
name = "carrier"
inertia_kg_m2 = 2.0
initial_speed_rad_s = 100.0
[bodies.road_load]
constant_n_m = 20.0
[[bodies]]
name = "housing"
fixed = true
[[couplings]]
name = "set"
kind = "planetary"
a = "sun"
b = "ring"
carrier = "carrier"
sun_teeth = 48
ring_teeth = 96
[[couplings]]
name = "B"
kind = "clutch"
a = "ring"
b = "housing"
mu = 0.1
peak = 1.2
cgeo_m = 0.1
max_normal_force_n = 40000.0
[couplings.force]
kind = "ramp"
offset = 1.0
height = -1.0
start_s = 0.02
duration_s = 0.03
[[couplings]]
name = "K"
kind = "pack"
a = "sun"
b = "carrier"
pack = "k.toml"
"#,
    )
    .unwrap();
    scene
}

/// Runs `scene` on `engine` with its impacts into `dir`: the summary, or the run's stderr.
fn run_on(scene: &Path, engine: &str, dir: &Path) -> Result<Value, String> {
    let json = dir.join(format!("{engine}.json"));
    let csv = dir.join(format!("{engine}.csv"));
    let o = run(&[
        "run",
        scene.to_str().unwrap(),
        "--engine",
        engine,
        "--no-record",
        "--summary-json",
        json.to_str().unwrap(),
        "--impacts-csv",
        csv.to_str().unwrap(),
    ]);
    if o.status.success() {
        Ok(read_json(&json))
    } else {
        Err(stderr(&o))
    }
}

/// The coupling named `name` of a network summary.
fn coupling(s: &Value, name: &str) -> Value {
    s["couplings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap()
        .clone()
}

/// How far apart two runs of one scene are: `(impacts closed before 30 ms, the largest onset
/// difference s, the largest relative peak difference)` over the impacts one by one, every
/// lock time's largest relative difference, the heat's relative difference of coupling `name`
/// and the bodies' final speeds' largest relative difference.
struct Apart {
    impacts: usize,
    onset_s: f64,
    peak: f64,
    lock: f64,
    heat: f64,
    speed: f64,
}

fn apart(d: &Path, r: &Value, m: &Value, name: &str) -> Apart {
    let (ri, mi) = (
        network_impacts(&d.join("reference.csv")),
        network_impacts(&d.join("multibody.csv")),
    );
    for (body, list) in &ri {
        assert_eq!(list.len(), mi[body].len(), "{body}: impacts");
    }
    let (n, onset_s, peak) = impacts_apart(&ri, &mi, 0.03);
    let times = |s: &Value| -> Vec<f64> {
        coupling(s, name)["lock_times_s"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t.as_f64().unwrap())
            .collect()
    };
    let (lr, lm) = (times(r), times(m));
    assert_eq!(lr.len(), lm.len(), "locks {lr:?} against {lm:?}");
    assert!(!lr.is_empty(), "{name} never locks");
    let lock = lr
        .iter()
        .zip(&lm)
        .map(|(a, b)| ((a - b) / a).abs())
        .fold(0.0, f64::max);
    let heat_of = |s: &Value| coupling(s, name)["heat_j"].as_f64().unwrap();
    let heat = ((heat_of(r) - heat_of(m)) / heat_of(r)).abs();
    let speeds = |s: &Value| -> Vec<f64> {
        s["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["final_speed_rad_s"].as_f64().unwrap())
            .collect()
    };
    let speed = speeds(r)
        .iter()
        .zip(speeds(m))
        .filter(|(a, _)| **a != 0.0)
        .map(|(a, b)| ((a - b) / a).abs())
        .fold(0.0, f64::max);
    let out = Apart {
        impacts: n,
        onset_s,
        peak,
        lock,
        heat,
        speed,
    };
    eprintln!(
        "{} impacts before 30 ms: onsets within {:.2e} s, peaks {:.2e}; locks {lr:?} against \
         {lm:?} ({:.2e}); heat {:.2e}; speeds {:.2e}",
        out.impacts, out.onset_s, out.peak, out.lock, out.heat, out.speed
    );
    out
}

/// Both engines' balances closed (measured 2026-12-07 at both steps: 4.8e-9 J and below of
/// 4.9 kJ driven; bound 1e-6 J).
fn balanced(r: &Value, m: &Value) {
    for s in [r, m] {
        let residual = s["energy"]["residual_j"].as_f64().unwrap();
        assert!(
            residual.abs() <= 1e-6,
            "{}: residual {residual} J",
            s["engine"]
        );
    }
}

/// Regression test of the multibody engine's refusal of a pack whose carriers are one rigid
/// group (`crates/multibody/src/network/packs.rs`, issue 44 item 3): the scene at its own step
/// (the multibody engine's network step 1e-4 s). Measured 2026-12-07: the reference engine's
/// balance 4.8e-9 J, the multibody engine's 5.3e-11 J; `K` locks at 0.11766, 0.13166 and
/// 0.14679 s on the reference engine, 0.1177, 0.1317 and 0.1468 s on the multibody engine
/// (a lock is timed to the network step: 3.2e-4 relative), its heat 3290 J within 1.4e-4; the
/// 25 impacts of the first 30 ms (the ring braked: the drum turning at a third of the shaft's
/// speed) one by one, onsets within 2.2e-6 s (slow contacts through the oil film, 4 ms long),
/// peaks within 2.4e-4; the speeds at 0.3 s within 5.2e-4 (the sun's, swinging against the
/// carrier on the locked pack's teeth). Bounds: the locks the issue's 1e-3; heat 3e-4, onsets
/// 6e-6 s, peaks 1e-3, speeds 1.5e-3 (2x to 4x).
#[test]
fn a_pack_across_one_rigid_group_runs_on_both_engines() {
    let d = scratch("locked-packs");
    let scene = planetary_scene(&d);
    let r = run_on(&scene, "reference", &d).unwrap();
    let m = run_on(&scene, "multibody", &d).unwrap();
    balanced(&r, &m);
    let k = coupling(&r, "K");
    let first = |s: &Value| coupling(s, "K")["lock_times_s"][0].as_f64().unwrap();
    assert!(
        (first(&r) - 0.1177).abs() <= 0.01,
        "K locks at {}",
        first(&r)
    );
    assert!(
        (first(&r) - first(&m)).abs() <= 1e-3 * first(&r),
        "K's first lock {} s against {} s",
        first(&r),
        first(&m)
    );
    let heat = k["heat_j"].as_f64().unwrap();
    assert!((3000.0..=3600.0).contains(&heat), "K's heat {heat} J");
    let a = apart(&d, &r, &m, "K");
    assert!(a.impacts >= 20, "{} impacts before 30 ms", a.impacts);
    assert!(a.onset_s <= 6e-6, "onsets {} s", a.onset_s);
    assert!(a.peak <= 1e-3, "peaks {}", a.peak);
    assert!(a.lock <= 1e-3, "locks {}", a.lock);
    assert!(a.heat <= 3e-4, "heat {}", a.heat);
    assert!(a.speed <= 1.5e-3, "speeds {}", a.speed);
}

/// The same at a network step of 2.5e-5 s (`simulation.max_step_s`): the engines converge
/// onto each other. Measured 2026-12-07: 25 impacts before 30 ms, onsets within 1.8e-7 s,
/// peaks within 1.2e-4; every lock within 1.1e-4 (relative); heat within 1.6e-5; speeds at
/// 0.3 s within 1.5e-4; both balances within 1.1e-10 J. Bounds: the issue's (2 us, 0.5 %,
/// 0.1 %), heat 1e-4 and speeds 3e-4 (2x and more).
#[test]
fn a_pack_across_one_rigid_group_agrees_impact_by_impact_at_a_short_step() {
    let d = scratch("locked-packs-short");
    let scene = planetary_scene(&d);
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(
        &scene,
        text.replace("max_step_s = 1e-3", "max_step_s = 2.5e-5"),
    )
    .unwrap();
    let r = run_on(&scene, "reference", &d).unwrap();
    let m = run_on(&scene, "multibody", &d).unwrap();
    balanced(&r, &m);
    let a = apart(&d, &r, &m, "K");
    assert!(a.impacts >= 20, "{} impacts before 30 ms", a.impacts);
    assert!(a.onset_s <= 2e-6, "onsets {} s", a.onset_s);
    assert!(a.peak <= 5e-3, "peaks {}", a.peak);
    assert!(a.lock <= 1e-3, "locks {}", a.lock);
    assert!(a.heat <= 1e-4, "heat {}", a.heat);
    assert!(a.speed <= 3e-4, "speeds {}", a.speed);
}

/// Runs `scenes/eight-speed-packs.toml` on both engines into `dir` with the options `more`:
/// the reference engine's summary and the multibody engine's.
fn eight_speed_packs(dir: &Path, more: &[&str]) -> (Value, Value) {
    let go = |engine: &str| {
        let json = dir.join(format!("{engine}.json"));
        let csv = dir.join(format!("{engine}.csv"));
        let mut args = vec![
            "run",
            "scenes/eight-speed-packs.toml",
            "--engine",
            engine,
            "--no-record",
            "--summary-json",
            json.to_str().unwrap(),
            "--impacts-csv",
            csv.to_str().unwrap(),
        ];
        args.extend_from_slice(more);
        let o = run(&args);
        assert!(o.status.success(), "{engine}: {}", stderr(&o));
        read_json(&json)
    };
    (go("reference"), go("multibody"))
}

/// The on-coming element's first lock, s.
fn first_lock(s: &Value, name: &str) -> f64 {
    coupling(s, name)["lock_times_s"][0].as_f64().unwrap()
}

/// The 8-speed's 1 -> 2 upshift with its off-going (C) and on-coming (E) elements resolved
/// packs, the schedule setting their pistons' pressures (issue 45, item 4's variant), at the
/// scene's own step (the multibody engine's network step 1e-4 s). Measured 2026-12-07: both
/// balances within 2.7e-8 J of 25.1 kJ driven (bound 1e-6 J); E locks at 0.25211 s on the
/// reference engine and 0.2522 s on the multibody engine (3.7e-4 relative; bound the issue's
/// 1e-3), its heat 2203 J within 6.0e-4 (bound 2e-3); the speeds at 0.4 s within 2.8e-4
/// (bound 1e-3); the 52 impacts of the first 30 ms (E open and slipping, its discs and plates
/// rattling slowly through the oil film, C clamped) one by one, onsets within 1.1e-4 s and
/// peaks within 2.6e-2 (bounds 3e-4 s and 6e-2; the next test quarters the step).
/// E's later re-locks are not compared: the faces stick and slip a few times as the locked
/// pack's teeth swing, and their count changes with either engine's step (the reference
/// engine's own: 2 at its 1e-3 s limit, 5 at 2.5e-5 s).
#[test]
fn the_eight_speeds_upshift_with_resolved_packs_agrees_on_both_engines() {
    let d = scratch("locked-packs-eight-speed");
    let (r, m) = eight_speed_packs(&d, &[]);
    balanced(&r, &m);
    let (lr, lm) = (first_lock(&r, "E"), first_lock(&m, "E"));
    eprintln!("E locks at {lr} s and {lm} s");
    assert!((lr - 0.2521).abs() <= 5e-3, "E locks at {lr} s");
    assert!(
        (lr - lm).abs() <= 1e-3 * lr,
        "E locks at {lr} s against {lm} s"
    );
    let heat = |s: &Value| coupling(s, "E")["heat_j"].as_f64().unwrap();
    let (hr, hm) = (heat(&r), heat(&m));
    assert!(
        (hr - hm).abs() <= 2e-3 * hr,
        "E's heat {hr} J against {hm} J"
    );
    let (n, onset, peak) = impacts_apart(
        &network_impacts(&d.join("reference.csv")),
        &network_impacts(&d.join("multibody.csv")),
        0.03,
    );
    eprintln!("{n} impacts before 30 ms: onsets within {onset:.2e} s, peaks {peak:.2e}");
    assert!(n >= 40, "{n} impacts before 30 ms");
    assert!(onset <= 3e-4, "onsets {onset} s");
    assert!(peak <= 6e-2, "peaks {peak}");
    let speeds = |s: &Value| -> Vec<f64> {
        s["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["final_speed_rad_s"].as_f64().unwrap())
            .collect()
    };
    let speed = speeds(&r)
        .iter()
        .zip(speeds(&m))
        .filter(|(a, _)| a.abs() > 1.0)
        .map(|(a, b)| ((a - b) / a).abs())
        .fold(0.0, f64::max);
    assert!(speed <= 1e-3, "speeds {speed}");
    // the shift as the run made it, read from the packs' faces: C lets go, E's lock is its
    // first (the faces' mode changes are those the summary's lock times come from), and its
    // heat from the samples' tau (w_b - w_a) while its faces slip is within 10 % of its faces'
    // counter (measured 3.6 % below on the reference engine: the discs' own inertia and
    // rattle are in the carriers' torque)
    for s in [&r, &m] {
        let sh = &s["shifts"][0];
        assert!(sh["off_going_released_s"].is_f64(), "{sh}");
        assert_eq!(
            sh["on_coming_locked_s"].as_f64(),
            Some(first_lock(s, "E")),
            "{sh}"
        );
        let from_samples = sh["on_coming_heat_j"].as_f64().unwrap();
        let counter = coupling(s, "E")["heat_j"].as_f64().unwrap();
        assert!(
            (from_samples - counter).abs() <= 0.1 * counter,
            "{from_samples} J against {counter} J"
        );
    }
    // in 2nd at the end: the input over the output at the gear's ratio 72/23 (the locked
    // pack's teeth swinging: measured 1.2e-3 off on both engines)
    for s in [&r, &m] {
        let w = speeds(s);
        let ratio = w[0] / w[1];
        assert!((ratio / (72.0 / 23.0) - 1.0).abs() <= 1e-2, "ratio {ratio}");
    }
}

/// The same at a network step of 2.5e-5 s: the first 30 ms converge impact by impact.
/// Measured 2026-12-07: 52 impacts, onsets within 5.3e-6 s (the slow rattle of the open pack,
/// contacts 9 ms long, against the dual clutch's 1.5e-7 s), peaks within 1.3e-3, E's first
/// lock 4e-6 relative apart. Bounds: onsets 1.5e-5 s, peaks 5e-3 (the issue's), the lock 1e-4.
#[test]
fn the_eight_speeds_upshift_with_resolved_packs_converges_at_a_short_step() {
    let d = scratch("locked-packs-eight-speed-short");
    let (r, m) = eight_speed_packs(&d, &["--set", "simulation.max_step_s=2.5e-5"]);
    balanced(&r, &m);
    let (lr, lm) = (first_lock(&r, "E"), first_lock(&m, "E"));
    assert!(
        (lr - lm).abs() <= 1e-4 * lr,
        "E locks at {lr} s against {lm} s"
    );
    let (n, onset, peak) = impacts_apart(
        &network_impacts(&d.join("reference.csv")),
        &network_impacts(&d.join("multibody.csv")),
        0.03,
    );
    eprintln!("{n} impacts before 30 ms: onsets within {onset:.2e} s, peaks {peak:.2e}");
    assert!(n >= 40, "{n} impacts before 30 ms");
    assert!(onset <= 1.5e-5, "onsets {onset} s");
    assert!(peak <= 5e-3, "peaks {peak}");
}

/// A gear's kinematics does not depend on whether its elements are lumped or resolved:
/// `check` prints the same nine ratios, speeds and slips for `eight-speed-packs.toml` as for
/// `eight-speed.toml` (a closed pack is a locked element).
#[test]
fn a_transmission_with_resolved_packs_has_the_lumped_ones_gears() {
    let gears = |scene: &str| {
        let o = run(&["check", scene]);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = super::stdout(&o);
        text.lines().skip(1).collect::<Vec<_>>().join("\n")
    };
    let (lumped, packs) = (
        gears("scenes/eight-speed.toml"),
        gears("scenes/eight-speed-packs.toml"),
    );
    assert!(lumped.contains("4.695652"), "{lumped}");
    assert_eq!(lumped, packs);
}

/// Regression test of a resolved pack as a shift element without a rated pressure: its pack
/// file's pressure never rises above 0, so the schedule has nothing to scale. Refused before
/// the run (exit 2), naming the coupling's key and the reason.
#[test]
fn a_pack_shift_element_without_pressure_is_refused_at_its_key() {
    let d = scratch("locked-packs-no-pressure");
    for f in ["eight-speed-packs.toml", "eight-speed-e.toml"] {
        std::fs::copy(format!("scenes/{f}"), d.join(f)).unwrap();
    }
    let c = std::fs::read_to_string("scenes/eight-speed-c.toml").unwrap();
    assert!(c.contains("pressure_pa = 2.0e6"));
    std::fs::write(
        d.join("eight-speed-c.toml"),
        c.replace("pressure_pa = 2.0e6", "pressure_pa = 0.0"),
    )
    .unwrap();
    let o = run(&["check", d.join("eight-speed-packs.toml").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("couplings[6].pack") && err.contains("rated pressure"),
        "{err}"
    );
}

/// Regression test of the multibody engine's refusal, at the step it happened, of a lumped
/// clutch locking a pack's two carriers into one rigid group (`follow_groups`): K1
/// (`scenes/dct-k1.toml`, clamped) between a hub geared 3:1 to a load and an engine, clutch C
/// (200 N m) applied beside it at 50 ms. Both engines run it; measured 2026-12-07: C locks
/// 6e-14 s apart, the speeds at 0.3 s (one rigid body by then) within 2.3e-10, K1's discs' and
/// plates' largest tooth loads within 1.8e-6, K1's largest torque within 4.5e-4 (the
/// multibody engine's is a mean over its network step), both balances within 1.8e-9 J. Bounds:
/// 1e-9 s, 1e-8, 1e-5, 1e-3, 1e-6 J.
#[test]
fn a_clutch_locking_a_packs_carriers_together_runs_on_both_engines() {
    let d = scratch("locked-packs-beside-a-lock");
    std::fs::copy("scenes/dct-k1.toml", d.join("k1.toml")).unwrap();
    let scene = d.join("net.toml");
    std::fs::write(
        &scene,
        r#"
name = "pack-beside-a-lock"
[simulation]
duration_s = 0.3
record_rate_hz = 2000.0
max_step_s = 1e-3
[[bodies]]
name = "engine"
inertia_kg_m2 = 0.1
initial_speed_rad_s = 300.0
[bodies.drive]
kind = "constant"
value_n_m = 100.0
[[bodies]]
name = "hub"
inertia_kg_m2 = 0.02
initial_speed_rad_s = 300.0
[[bodies]]
name = "load"
inertia_kg_m2 = 0.5
initial_speed_rad_s = 100.0
[bodies.road_load]
constant_n_m = 50.0
[[couplings]]
name = "K1"
kind = "pack"
a = "hub"
b = "engine"
pack = "k1.toml"
[[couplings]]
name = "G"
kind = "ideal_gear"
a = "hub"
b = "load"
ratio = 3.0
[[couplings]]
name = "C"
kind = "clutch"
a = "hub"
b = "engine"
mu = 0.5
peak = 1.1
cgeo_m = 0.1
max_normal_force_n = 4000.0
[couplings.force]
kind = "step"
height = 1.0
start_s = 0.05
"#,
    )
    .unwrap();
    let r = run_on(&scene, "reference", &d).unwrap();
    let m = run_on(&scene, "multibody", &d).unwrap();
    balanced(&r, &m);
    let (lr, lm) = (first_lock(&r, "C"), first_lock(&m, "C"));
    assert!((lr - 0.0502).abs() <= 1e-3, "C locks at {lr} s");
    assert!((lr - lm).abs() <= 1e-9, "C locks at {lr} s against {lm} s");
    let speeds = |s: &Value| -> Vec<f64> {
        s["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["final_speed_rad_s"].as_f64().unwrap())
            .collect()
    };
    for (a, b) in speeds(&r).iter().zip(speeds(&m)) {
        assert!((a - b).abs() <= 1e-8 * a.abs(), "speeds {a} against {b}");
    }
    let k1 = |s: &Value| coupling(s, "K1");
    let bodies = |s: &Value| k1(s)["pack_bodies"].as_array().unwrap().clone();
    assert_eq!(bodies(&r).len(), 9);
    for (a, b) in bodies(&r).iter().zip(&bodies(&m)) {
        let (pa, pb) = (
            a["largest_peak_n"].as_f64().unwrap(),
            b["largest_peak_n"].as_f64().unwrap(),
        );
        assert!(
            (pa - pb).abs() <= 1e-5 * pa.abs(),
            "{}: {pa} N against {pb} N",
            a["name"]
        );
    }
    let torque = |s: &Value| k1(s)["max_torque_n_m"].as_f64().unwrap();
    let (tr, tm) = (torque(&r), torque(&m));
    assert!(
        (tr - tm).abs() <= 1e-3 * tr,
        "K1's torque {tr} against {tm} N m"
    );
}
