//! The elements of automatic transmissions (MODEL.md section 10) on both engines, against
//! closed forms and Modelica's published reference results: planetary sets (Willis' equation
//! as one constraint row on three bodies, the model's `network/rows.rs`) and one-way clutches
//! (a freewheel in parallel with a lumped clutch).

use super::{read_json, run, scratch, stderr};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The sun's, ring's and carrier's inertias (kg m^2) and the tooth counts of the sets below.
const J: [f64; 3] = [0.01, 0.05, 0.5];
const ZS: f64 = 30.0;
const ZR: f64 = 90.0;
/// The sun's drive, N m.
const DRIVE_N_M: f64 = 20.0;

/// A network scene of a 30/90 planetary set (sun driven by 20 N m, every member at 100 rad/s)
/// with the housing and `more` couplings, written into `dir`.
fn set_scene(dir: &Path, name: &str, more: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    let text = format!(
        r#"name = "{name}"
[simulation]
duration_s = 0.3
record_rate_hz = 1000.0
max_step_s = 1e-3

[[bodies]]
name = "sun"
inertia_kg_m2 = {js}
initial_speed_rad_s = 100.0
[bodies.drive]
kind = "constant"
value_n_m = {DRIVE_N_M}

[[bodies]]
name = "ring"
inertia_kg_m2 = {jr}
initial_speed_rad_s = 100.0

[[bodies]]
name = "carrier"
inertia_kg_m2 = {jc}
initial_speed_rad_s = 100.0

[[bodies]]
name = "housing"
fixed = true

[[couplings]]
name = "set"
kind = "planetary"
a = "sun"
b = "ring"
carrier = "carrier"
sun_teeth = {ZS}
ring_teeth = {ZR}
{more}"#,
        js = J[0],
        jr = J[1],
        jc = J[2],
    );
    std::fs::write(&path, text).unwrap();
    path
}

/// A clutch `name` from `a` to `b` applied fully by a step at `start_s`.
fn clutch(name: &str, a: &str, b: &str, start_s: f64) -> String {
    format!(
        r#"
[[couplings]]
name = "{name}"
kind = "clutch"
a = "{a}"
b = "{b}"
mu = 0.3
peak = 1.2
cgeo_m = 0.1
max_normal_force_n = 2000.0
[couplings.force]
kind = "step"
height = 1.0
start_s = {start_s}
"#
    )
}

/// The accelerations (rad/s^2) of the sun, ring and carrier under the torques `t` (N m) with
/// Willis' row `c = (z_S, z_R, -(z_S + z_R))` holding: `J a = T + c lambda`, `c . a = 0`.
fn willis_accelerations(t: [f64; 3]) -> [f64; 3] {
    let c = [ZS, ZR, -(ZS + ZR)];
    let num: f64 = (0..3).map(|i| c[i] * t[i] / J[i]).sum();
    let den: f64 = (0..3).map(|i| c[i] * c[i] / J[i]).sum();
    let lambda = -num / den;
    [0, 1, 2].map(|i| (t[i] + c[i] * lambda) / J[i])
}

/// Runs `scene` on `engine` without a recording: its summary (`--summary-json`, written into
/// `dir` as `<engine>.json`).
pub(super) fn summary(scene: &Path, engine: &str, dir: &Path) -> Value {
    let json = dir.join(format!("{engine}.json"));
    let o = run(&[
        "run",
        scene.to_str().unwrap(),
        "--engine",
        engine,
        "--no-record",
        "--summary-json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    read_json(&json)
}

fn speed(s: &Value, i: usize) -> f64 {
    s["bodies"][i]["final_speed_rad_s"].as_f64().unwrap()
}

/// The ring braked to the housing from 0.05 s (a first gear's brake): the set turns freely
/// with two degrees of freedom, then the brake slips (60 N m against the ring), the ring
/// comes to rest and locks, and the sun drives the carrier at a quarter of its speed. The
/// closed form, piecewise constant accelerations from Willis' row: the lock at
/// 0.140517241379310 s, the sun at 472.727 rad/s at 0.3 s. Measured: the reference engine's
/// lock 5e-14 s and its speeds 1e-14 relative from it, the multibody engine's 1e-16 s and
/// 3e-14 (the torques are constant between the events, where both schemes are exact); the
/// energy balance closes to 3e-10 J. The bounds: 1e-10 s, 1e-11 relative and 1e-8 J.
#[test]
fn a_braked_ring_locks_at_the_closed_form_instant_on_both_engines() {
    let d = scratch("planetary-brake");
    let scene = set_scene(&d, "brake", &clutch("brake", "ring", "housing", 0.05));
    // the closed form
    let mut w = [100.0; 3];
    let a1 = willis_accelerations([DRIVE_N_M, 0.0, 0.0]);
    (0..3).for_each(|i| w[i] += a1[i] * 0.05);
    // the brake slips against the ring's motion: mu cgeo fn = 60 N m
    let a2 = willis_accelerations([DRIVE_N_M, -60.0, 0.0]);
    let t_slip = -w[1] / a2[1];
    (0..3).for_each(|i| w[i] += a2[i] * t_slip);
    let lock = 0.05 + t_slip;
    // the ring held: the sun against its own inertia and the carrier's at z_S / (z_S + z_R)
    let g = ZS / (ZS + ZR);
    let sun_end = w[0] + DRIVE_N_M / (J[0] + J[2] * g * g) * (0.3 - lock);
    for engine in ["reference", "multibody"] {
        let s = summary(&scene, engine, &d);
        let locks = s["couplings"][1]["lock_times_s"].as_array().unwrap();
        assert_eq!(locks.len(), 1, "{engine}: {s}");
        let got = locks[0].as_f64().unwrap();
        assert!(
            (got - lock).abs() < 1e-10,
            "{engine}: lock {got} against {lock}"
        );
        let (ws, wr, wc) = (speed(&s, 0), speed(&s, 1), speed(&s, 2));
        assert!(
            (ws - sun_end).abs() < 1e-11 * sun_end,
            "{engine}: {ws} against {sun_end}"
        );
        assert_eq!(wr, 0.0, "{engine}: the braked ring");
        assert!(
            (wc - g * ws).abs() < 1e-11 * ws,
            "{engine}: carrier {wc}, sun {ws}"
        );
        // the sun's torque from the set at the end: J_S a_S - T
        let a_s = DRIVE_N_M / (J[0] + J[2] * g * g);
        let want = J[0] * a_s - DRIVE_N_M;
        let set = s["couplings"][0]["final_torque_n_m"].as_f64().unwrap();
        assert!(
            (set - want).abs() < 1e-9 * want.abs(),
            "{engine}: {set} against {want}"
        );
        let residual = s["energy"]["residual_j"].as_f64().unwrap();
        assert!(residual.abs() < 1e-8, "{engine}: {}", s["energy"]);
    }
}

/// A clutch locking the sun to the ring (a direct gear): with two members tied the set turns
/// as one body (the group of one degree of freedom holds a three-body row and a two-body
/// row), every member at `100 + T t / (J_S + J_R + J_C)`. Measured: both engines within
/// 1e-15 relative (constant torques); the bound 1e-12.
#[test]
fn a_direct_gear_turns_the_set_as_one_body_on_both_engines() {
    let d = scratch("planetary-direct");
    let scene = set_scene(&d, "direct", &clutch("direct", "sun", "ring", 0.0));
    let want = 100.0 + DRIVE_N_M * 0.3 / J.iter().sum::<f64>();
    for engine in ["reference", "multibody"] {
        let s = summary(&scene, engine, &d);
        for i in 0..3 {
            let w = speed(&s, i);
            assert!(
                (w - want).abs() < 1e-12 * want,
                "{engine}: body {i} {w} against {want}"
            );
        }
        assert_eq!(s["couplings"][1]["final_mode"], "locked", "{engine}: {s}");
    }
}

/// Gearing that cannot be built, a carrier that is not a third body, speeds that break
/// Willis' equation at t = 0 and a key of another kind are refused by `check`, exit 2, each
/// named at its key.
#[test]
fn a_planetary_set_that_cannot_be_built_is_named_at_its_key() {
    let d = scratch("planetary-bad");
    let good = set_scene(&d, "good", "");
    let text = std::fs::read_to_string(&good).unwrap();
    let cases = [
        (
            "ring_teeth = 90",
            "ring_teeth = 91",
            "couplings[0].ring_teeth",
            "odd",
        ),
        (
            "ring_teeth = 90",
            "ring_teeth = 20",
            "couplings[0].ring_teeth",
            "larger than the sun",
        ),
        (
            "carrier = \"carrier\"",
            "carrier = \"sun\"",
            "couplings[0].carrier",
            "third body",
        ),
        (
            "carrier = \"carrier\"",
            "carrier = \"axle\"",
            "couplings[0].carrier",
            "names no body",
        ),
        (
            "name = \"carrier\"\ninertia_kg_m2 = 0.5\ninitial_speed_rad_s = 100.0",
            "name = \"carrier\"\ninertia_kg_m2 = 0.5\ninitial_speed_rad_s = 90.0",
            "couplings[0].carrier",
            "Willis",
        ),
        (
            "ring_teeth = 90",
            "ring_teeth = 90\nratio = 2.0",
            "couplings[0].ratio",
            "ideal gear",
        ),
    ];
    refused_at_their_keys(&d, &text, &cases);
}

/// `scenes/simple-gear-shift.toml`, Modelica's `Rotational.Examples.SimpleGearShift`, against
/// the Modelica Association's published reference results (MODEL.md section 10: Dymola, DASSL
/// at a tolerance of 1e-6): the brake breaks loose at 2.04081626959156 s, the clutch locks at
/// 2.11079037915241 s, and the engine turns at 3.83512236655826, 11.248623325545,
/// 6.1899807525856 and 8.09002994377974 rad/s at 1, 2, 3 and 5 s. Measured on both engines:
/// the events within 8e-9 s and the speeds within 1.1e-6 relative (the reference's own
/// tolerance; the two engines agree with each other to 2e-9). Asserted: 5e-8 s and 5e-6.
#[test]
fn simple_gear_shift_matches_modelica_reference_results_on_both_engines() {
    let d = scratch("simple-gear-shift");
    let scene = Path::new("scenes/simple-gear-shift.toml");
    let speeds = [
        (1.0, 3.835_122_366_558_26),
        (2.0, 11.248_623_325_545),
        (3.0, 6.189_980_752_585_6),
        (5.0, 8.090_029_943_779_74),
    ];
    for engine in ["reference", "multibody"] {
        for (t, want) in speeds {
            let json = d.join(format!("{engine}-{t}.json"));
            let o = run(&[
                "run",
                scene.to_str().unwrap(),
                "--engine",
                engine,
                "--no-record",
                "--duration",
                &t.to_string(),
                "--summary-json",
                json.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            let s = read_json(&json);
            let w = speed(&s, 0);
            assert!(
                (w - want).abs() < 5e-6 * want,
                "{engine} at {t} s: {w} against {want}"
            );
            if t < 5.0 {
                continue;
            }
            let brake = &s["couplings"][2]["changes"][0];
            assert_eq!(
                (&brake["from"], &brake["to"]),
                (&"locked".into(), &"slip-".into())
            );
            let broke = brake["t_s"].as_f64().unwrap();
            assert!(
                (broke - 2.040_816_269_591_56).abs() < 5e-8,
                "{engine}: {broke}"
            );
            let locks = s["couplings"][1]["lock_times_s"].as_array().unwrap();
            let lock = locks[0].as_f64().unwrap();
            assert!(
                (lock - 2.110_790_379_152_41).abs() < 5e-8,
                "{engine}: {lock}"
            );
            assert_eq!(locks.len(), 1, "{engine}: {s}");
        }
    }
}

/// A double-pinion set (`double_pinion = true`: `z_S w_S - z_R w_R = (z_S - z_R) w_C`) with
/// its ring the housing turns its carrier backwards at `z_S / (z_S - z_R)` of the sun (-1/2
/// for 30/90), under the sun's drive at `T / (J_S + J_C / 4)`. Measured: both engines within
/// 2e-15 relative (constant torques); the bound 1e-12.
#[test]
fn a_double_pinion_set_reverses_its_carrier_on_both_engines() {
    let d = scratch("planetary-double");
    let scene = d.join("double.toml");
    let text = format!(
        r#"name = "double-pinion"
[simulation]
duration_s = 0.3
[[bodies]]
name = "sun"
inertia_kg_m2 = {js}
initial_speed_rad_s = 100.0
[bodies.drive]
kind = "constant"
value_n_m = {DRIVE_N_M}
[[bodies]]
name = "housing"
fixed = true
[[bodies]]
name = "carrier"
inertia_kg_m2 = {jc}
initial_speed_rad_s = -50.0
[[couplings]]
name = "set"
kind = "planetary"
a = "sun"
b = "housing"
carrier = "carrier"
sun_teeth = {ZS}
ring_teeth = {ZR}
double_pinion = true
"#,
        js = J[0],
        jc = J[2],
    );
    std::fs::write(&scene, text).unwrap();
    let g = ZS / (ZS - ZR);
    let sun_end = 100.0 + DRIVE_N_M * 0.3 / (J[0] + J[2] * g * g);
    for engine in ["reference", "multibody"] {
        let s = summary(&scene, engine, &d);
        let (ws, wc) = (speed(&s, 0), speed(&s, 2));
        assert!(
            (ws - sun_end).abs() < 1e-12 * sun_end,
            "{engine}: {ws} against {sun_end}"
        );
        assert!(
            (wc - g * ws).abs() < 1e-12 * ws,
            "{engine}: carrier {wc}, sun {ws}"
        );
    }
}

/// The mode changes of the first coupling of a summary: `(t_s, from, to)`.
fn changes(s: &Value) -> Vec<(f64, String, String)> {
    s["couplings"][0]["changes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let text = |k: &str| c[k].as_str().unwrap().to_string();
            (c["t_s"].as_f64().unwrap(), text("from"), text("to"))
        })
        .collect()
}

/// Drops a lock and its release less than 1e-5 s apart (a freewheel grazing zero slip).
fn without_grazes(c: Vec<(f64, String, String)>) -> Vec<(f64, String, String)> {
    let mut out: Vec<(f64, String, String)> = Vec::new();
    for e in c {
        let graze = out
            .last()
            .is_some_and(|p| p.2 == "locked" && e.0 - p.0 < 1e-5);
        if graze {
            out.pop();
        } else {
            out.push(e);
        }
    }
    out
}

/// Each case `(from, to, key, why)`: `text` with its first `from` replaced by `to`, written
/// into `d`, is refused by `check` with exit 2 and a message naming `key` and saying `why`.
fn refused_at_their_keys(d: &Path, text: &str, cases: &[(&str, &str, &str, &str)]) {
    for &(from, to, key, why) in cases {
        assert!(text.contains(from), "{from}");
        let bad = d.join("bad.toml");
        std::fs::write(&bad, text.replacen(from, to, 1)).unwrap();
        let o = run(&["check", bad.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{to}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(key) && e.contains(why), "{to}: {e}");
    }
}

/// Both engines' summaries of `scene`.
fn both(scene: &str, d: &Path) -> [Value; 2] {
    ["reference", "multibody"].map(|e| summary(Path::new(scene), e, d))
}

/// `scenes/one-way-clutch.toml`, Modelica's `Rotational.Examples.OneWayClutch`: the freewheel
/// first locks at `arccos(1 - 0.3 pi) / (6 pi)` (the driving inertia at -0.5 rad/s under
/// 10 sin(6 pi t) reaching the driven one at rest), the Modelica Association's reference at
/// 0.0802800431291476 s (MODEL.md section 10). Then it frees at 1/6 s, the clutch engaged at
/// 0.3 s slips forward and locks, holds both ways while engaged, frees at 0.95 s and so on.
/// Measured: the reference engine's first lock 3e-14 s from the closed form, the multibody
/// engine's 7.4e-9 (its sine held over each 1e-4 s step, second order), both 4.3e-8 s from
/// Modelica's (Dymola at 1e-6); the two engines' mode changes within 6e-9 s, their heat within
/// 4.3e-8 relative, the energy balance closed to 3e-14 J. At 1.5 s the driving inertia returns
/// exactly to the driven one's speed with no relative acceleration (a graze): the multibody
/// engine locks and frees it within 1e-6 s, the reference engine's event functions see no
/// crossing; the comparison drops that pair. Asserted: 1e-12 s and 5e-8 s from the closed
/// form, 1e-7 s from Modelica, 5e-8 s and 1e-6 between the engines, 1e-9 J.
#[test]
fn one_way_clutch_matches_modelica_and_its_closed_form_on_both_engines() {
    let d = scratch("one-way-clutch");
    let closed = (1.0 - 0.3 * std::f64::consts::PI).acos() / (6.0 * std::f64::consts::PI);
    let runs = both("scenes/one-way-clutch.toml", &d);
    for (s, bound) in runs.iter().zip([1e-12, 5e-8]) {
        let first = s["couplings"][0]["lock_times_s"][0].as_f64().unwrap();
        assert!((first - closed).abs() < bound, "{first} against {closed}");
        assert!((first - 0.080_280_043_129_147_6).abs() < 1e-7, "{first}");
        assert!(
            s["energy"]["residual_j"].as_f64().unwrap().abs() < 1e-9,
            "{s}"
        );
    }
    let (r, m) = (changes(&runs[0]), without_grazes(changes(&runs[1])));
    let kinds: Vec<(&str, &str)> = r.iter().map(|c| (c.1.as_str(), c.2.as_str())).collect();
    let want = [
        ("free", "locked"),
        ("locked", "free"),
        ("free", "slip+"),
        ("slip+", "locked"),
        ("locked", "free"),
        ("free", "locked"),
        ("locked", "free"),
        ("free", "slip+"),
        ("slip+", "locked"),
    ];
    assert_eq!(kinds, want, "{r:?}");
    assert_eq!(r.len(), m.len(), "{r:?}\n{m:?}");
    for (a, b) in r.iter().zip(&m) {
        assert!(
            (a.0 - b.0).abs() < 5e-8 && a.1 == b.1 && a.2 == b.2,
            "{a:?} {b:?}"
        );
    }
    let heat = |s: &Value| s["couplings"][0]["heat_j"].as_f64().unwrap();
    let (hr, hm) = (heat(&runs[0]), heat(&runs[1]));
    assert!(hr > 0.2 && (hr - hm).abs() < 1e-6 * hr, "{hr} {hm}");
}

/// `scenes/one-way-clutch-disengaged.toml`, Modelica's `OneWayClutchDisengaged`: the freewheel
/// alone. Its first lock is where `-0.3 t` (the loaded inertia) meets
/// `-0.5 + 0.3 t + (10 / (4 pi)) (1 - cos 4 pi t)` (the driven one), 0.0888614174 s by
/// bisection; Modelica's reference gives 0.0888616358955606 s, 2.2e-7 s later (Dymola at
/// 1e-6). Measured: the reference engine 5e-15 s from the closed form, the multibody engine
/// 3e-9; the two engines' eight mode changes within 2.1e-9 s and their final speeds within
/// 1.1e-7 relative. Asserted: 1e-12 and 2e-8 s from the closed form, 5e-7 s from Modelica,
/// 2e-8 s and 1e-6 between the engines.
#[test]
fn freewheel_matches_modelica_and_its_closed_form_on_both_engines() {
    let d = scratch("freewheel");
    let pi = std::f64::consts::PI;
    let rel =
        |t: f64| -0.3 * t - (-0.5 + 0.3 * t + 10.0 / (4.0 * pi) * (1.0 - (4.0 * pi * t).cos()));
    let (mut a, mut b) = (0.05, 0.1);
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if rel(a) * rel(mid) <= 0.0 {
            b = mid;
        } else {
            a = mid;
        }
    }
    let runs = both("scenes/one-way-clutch-disengaged.toml", &d);
    for (s, bound) in runs.iter().zip([1e-12, 2e-8]) {
        let first = s["couplings"][0]["lock_times_s"][0].as_f64().unwrap();
        assert!((first - a).abs() < bound, "{first} against {a}");
        assert!((first - 0.088_861_635_895_560_6).abs() < 5e-7, "{first}");
        assert!(
            s["couplings"][0]["heat_j"].as_f64().unwrap().abs() < 1e-12,
            "{s}"
        );
    }
    let (r, m) = (changes(&runs[0]), changes(&runs[1]));
    assert_eq!(r.len(), 8, "{r:?}");
    assert_eq!(r.len(), m.len(), "{r:?}\n{m:?}");
    for (x, y) in r.iter().zip(&m) {
        assert!(
            (x.0 - y.0).abs() < 2e-8 && x.1 == y.1 && x.2 == y.2,
            "{x:?} {y:?}"
        );
    }
    for i in 0..2 {
        let (x, y) = (speed(&runs[0], i), speed(&runs[1], i));
        assert!((x - y).abs() < 1e-6 * x.abs(), "body {i}: {x} {y}");
    }
}

/// A one-way clutch whose driven body starts slower than its driving one, and a freewheel
/// given a clutch's key, are refused by `check` at their keys, exit 2.
#[test]
fn a_one_way_clutch_that_starts_backwards_is_named_at_its_key() {
    let d = scratch("one-way-bad");
    let text = std::fs::read_to_string("scenes/one-way-clutch-disengaged.toml").unwrap();
    let cases = [
        (
            "initial_speed_rad_s = -0.5",
            "initial_speed_rad_s = 0.5",
            "couplings[0].b",
            "w_b >= w_a",
        ),
        (
            "kind = \"freewheel\"",
            "kind = \"freewheel\"\nmu = 0.3",
            "couplings[0].mu",
            "clutch",
        ),
    ];
    refused_at_their_keys(&d, &text, &cases);
}

/// `clutchpack check scenes/eight-speed.toml` prints every gear's ratio from the constraints
/// alone: the 8HP's exact fractions (MODEL.md section 10), printed to 6 decimals (the bound
/// 5e-7 is the printing's).
#[test]
fn eight_speed_check_prints_every_gears_exact_ratio() {
    let o = run(&["check", "scenes/eight-speed.toml"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = super::stdout(&o);
    let want = [
        ("R", -1744.0 / 529.0),
        ("1", 108.0 / 23.0),
        ("2", 72.0 / 23.0),
        ("3", 162.0 / 77.0),
        ("4", 5.0 / 3.0),
        ("5", 8826.0 / 6871.0),
        ("6", 1.0),
        ("7", 120.0 / 143.0),
        ("8", 2.0 / 3.0),
    ];
    for (gear, ratio) in want {
        let line = out
            .lines()
            .find(|l| l.contains("closed") && l.split_whitespace().next() == Some(gear))
            .unwrap_or_else(|| panic!("gear {gear}: {out}"));
        let got: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
        assert!(
            (got - ratio).abs() < 5e-7,
            "gear {gear}: {got} against {ratio}"
        );
    }
}

/// A gear that is no gear and the keys of `[transmission]` that name the wrong thing are
/// refused by `check`, exit 2, at their keys.
#[test]
fn a_gear_that_is_no_gear_is_named_at_its_key() {
    let d = scratch("eight-speed-bad");
    let text = std::fs::read_to_string("scenes/eight-speed.toml").unwrap();
    let first = "name = \"1\"\nclosed = [\"A\", \"B\", \"C\"]";
    let cases = [
        (
            first,
            "name = \"1\"\nclosed = [\"A\", \"B\"]",
            "transmission.gears[1].closed",
            "more than one degree of freedom",
        ),
        (
            first,
            "name = \"1\"\nclosed = [\"A\", \"B\", \"C\", \"D\"]",
            "transmission.gears[1].closed",
            "holds the input",
        ),
        (
            first,
            "name = \"1\"\nclosed = [\"A\", \"B\", \"PS1\"]",
            "transmission.gears[1].closed[2]",
            "not a shift element",
        ),
        (
            first,
            "name = \"1\"\nclosed = [\"A\", \"B\", \"F\"]",
            "transmission.gears[1].closed[2]",
            "names no coupling",
        ),
        (
            "name = \"2\"",
            "name = \"1\"",
            "transmission.gears[2].name",
            "names two gears",
        ),
        (
            "output = \"output\"",
            "output = \"wheel\"",
            "transmission.output",
            "names no body",
        ),
    ];
    refused_at_their_keys(&d, &text, &cases);
}

/// The upshifts 1 -> 2 at 1.0 s and 2 -> 3 at 2.0 s of `scenes/eight-speed.toml`, compiled from
/// `[[transmission.shifts]]` into the elements' forces: on both engines the on-coming E locks
/// once within the 1 -> 2 shift (at 1.136 s: the input's small inertia is pulled down before
/// the torque phase ends), C (off-going there) locks again as the 2 -> 3 shift's on-coming
/// (2.163 s), the run ends in 3rd (the output at 77/162 of the input), the energy balance
/// closes, and the two engines agree. Measured: the locks within 1e-6 s of each other, the
/// heat within 1e-6 relative, the balance to 5e-9 J of 1.8e5 J, the ratio to 1e-15. Asserted:
/// 1e-5 s, 1e-3, 1e-9 relative and 1e-9.
#[test]
fn an_eight_speed_shifts_up_clutch_to_clutch_on_both_engines() {
    let d = scratch("eight-speed-shifts");
    let runs = both("scenes/eight-speed.toml", &d);
    let element = |s: &Value, name: &str| -> Value {
        s["couplings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == name)
            .unwrap()
            .clone()
    };
    let locks = |s: &Value, name: &str| -> Vec<f64> {
        element(s, name)["lock_times_s"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    for s in &runs {
        let e = locks(s, "E");
        assert_eq!(e.len(), 1, "E: {e:?}");
        assert!(
            e[0] > 1.0 && e[0] < 1.45,
            "E locks within the 1-2 shift: {e:?}"
        );
        let c = locks(s, "C");
        assert!(
            c.len() == 2 && c[0] == 0.0 && c[1] > 2.0 && c[1] < 2.35,
            "C: {c:?}"
        );
        let (wi, wo) = (speed(s, 0), speed(s, 1));
        assert!((wo / wi - 77.0 / 162.0).abs() < 1e-9, "in 3rd: {wi} {wo}");
        let e = &s["energy"];
        let drive = e["drive_work_j"].as_f64().unwrap();
        assert!(
            e["residual_j"].as_f64().unwrap().abs() < 1e-9 * drive,
            "{e}"
        );
    }
    for s in &runs {
        let shifts = s["shifts"].as_array().unwrap();
        assert_eq!(shifts.len(), 2, "{s}");
        for sh in shifts {
            assert_eq!(
                (&sh["tie_up"], &sh["flare"]),
                (&false.into(), &false.into()),
                "{sh}"
            );
            let (tp, ip) = (
                sh["torque_phase_s"].as_f64().unwrap(),
                sh["inertia_phase_s"].as_f64().unwrap(),
            );
            assert!(tp > 0.05 && ip > 0.0, "{sh}");
        }
        // E slips only in the 1 -> 2 shift: its heat there from the 1 kHz samples is its whole
        // heat from the engine's counter (measured within 0.03 %; bound 0.5 %)
        let e_total = element(s, "E")["heat_j"].as_f64().unwrap();
        let e_shift = shifts[0]["on_coming_heat_j"].as_f64().unwrap();
        assert!(
            (e_shift - e_total).abs() < 5e-3 * e_total,
            "{e_shift} {e_total}"
        );
    }
    let (r, m) = (&runs[0], &runs[1]);
    for name in ["E", "C"] {
        for (a, b) in locks(r, name).iter().zip(locks(m, name)) {
            assert!((a - b).abs() < 1e-5, "{name}: {a} {b}");
        }
        let heat = |s: &Value| element(s, name)["heat_j"].as_f64().unwrap();
        assert!(
            heat(r) > 1.0 && (heat(r) - heat(m)).abs() < 1e-3 * heat(r),
            "{name}: {} {}",
            heat(r),
            heat(m)
        );
    }
}

/// A schedule that cannot be driven is refused by `check`, exit 2, at its key.
#[test]
fn a_shift_schedule_that_cannot_be_driven_is_named_at_its_key() {
    let d = scratch("eight-speed-bad-shifts");
    let text = std::fs::read_to_string("scenes/eight-speed.toml").unwrap();
    let cases = [
        (
            "to = \"2\"",
            "to = \"1\"",
            "transmission.shifts[0].to",
            "already engaged",
        ),
        (
            "to = \"2\"",
            "to = \"4\"",
            "transmission.shifts[0].to",
            "opens 2 and closes 2",
        ),
        (
            "to = \"2\"",
            "to = \"9\"",
            "transmission.shifts[0].to",
            "names no gear",
        ),
        (
            "at_s = 2.0",
            "at_s = 1.2",
            "transmission.shifts[1].to",
            "before the shift before it ends",
        ),
        (
            "name = \"E\"\nkind = \"clutch\"",
            "name = \"E\"\nkind = \"clutch\"\n[couplings.force]\nkind = \"constant\"\nvalue = 1.0",
            "couplings[8].force",
            "shift schedule",
        ),
        (
            "initial_gear = \"1\"\n",
            "",
            "transmission.shifts",
            "needs transmission.initial_gear",
        ),
    ];
    refused_at_their_keys(&d, &text, &cases);
}

/// The same 1 -> 2 shift with the on-coming element applied harder in the torque phase
/// (`torque_level` 0.5 instead of 0.1) fights the off-going one: the output torque falls to
/// about -190 N m from 1262 N m before (a tie-up, flagged), and the on-coming element takes
/// more heat (measured 5037 J against 3158 J: 1.59 times; asserted 1.3). `compare` of the two
/// runs' recordings names the harder shift as the one that heats its on-coming element most.
/// On the reference engine.
#[test]
fn a_harder_overlap_is_flagged_a_tie_up_and_heats_the_on_coming_element_more() {
    let d = scratch("eight-speed-tie-up");
    let shift = |level: &str, name: &str| -> Value {
        let (json, mcap) = (
            d.join(format!("{name}.json")),
            d.join(format!("{name}.mcap")),
        );
        let o = run(&[
            "run",
            "scenes/eight-speed.toml",
            "--out",
            mcap.to_str().unwrap(),
            "--duration",
            "1.9",
            "--set",
            &format!("transmission.shifts[0].torque_level={level}"),
            "--summary-json",
            json.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        read_json(&json)["shifts"][0].clone()
    };
    let (soft, hard) = (shift("0.1", "soft"), shift("0.5", "hard"));
    assert_eq!(soft["tie_up"], false, "{soft}");
    assert_eq!(hard["tie_up"], true, "{hard}");
    let heat = |s: &Value| s["on_coming_heat_j"].as_f64().unwrap();
    assert!(
        heat(&hard) > 1.3 * heat(&soft),
        "{} {}",
        heat(&hard),
        heat(&soft)
    );
    assert!(
        hard["output_torque_min_n_m"].as_f64().unwrap() < 0.0,
        "{hard}"
    );
    let o = run(&[
        "compare",
        d.join("soft.mcap").to_str().unwrap(),
        d.join("hard.mcap").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = super::stdout(&o);
    let verdict = out
        .lines()
        .find(|l| l.starts_with("the shift that heats its on-coming element most"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(
        verdict.contains("1 -> 2 (E)") && verdict.contains("hard.mcap"),
        "{out}"
    );
}

/// `scenes/eight-speed-drive.toml`: the 8-speed in a car (an engine with its firing harmonics
/// behind a damper, the final drive, the vehicle) shifting up through all eight gears over
/// 10 s. The two engines agree shift by shift and the run ends in 8th. Measured: the releases
/// and locks within 6.6e-8 s of each other, the on-coming elements' heat within 3.1e-5, the
/// vehicle's speed within 1.3e-7, the output at 1.5 times the input (8th: 2/3) to 2e-16, the
/// energy balance closed to 9e-10 of the engine's work. Asserted: 5e-7 s, 2e-4, 1e-6, 1e-9 and
/// 1e-8. (Its shifts are flagged as tie-ups: the output torque swings below half its level as
/// the shift rings the damper; the schedule is not tuned to this car.)
#[test]
fn an_eight_speed_in_a_car_shifts_through_all_gears_alike_on_both_engines() {
    let d = scratch("eight-speed-drive");
    let runs = both("scenes/eight-speed-drive.toml", &d);
    let speeds = |s: &Value| -> std::collections::HashMap<String, f64> {
        s["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                (
                    b["name"].as_str().unwrap().to_string(),
                    b["final_speed_rad_s"].as_f64().unwrap(),
                )
            })
            .collect()
    };
    for s in &runs {
        let w = speeds(s);
        assert!(
            (w["output"] / w["input"] - 1.5).abs() < 1e-9,
            "in 8th: {w:?}"
        );
        let e = &s["energy"];
        let drive = e["drive_work_j"].as_f64().unwrap();
        assert!(
            e["residual_j"].as_f64().unwrap().abs() < 1e-8 * drive,
            "{e}"
        );
        let shifts = s["shifts"].as_array().unwrap();
        assert_eq!(shifts.len(), 7, "{s}");
        assert!(
            shifts.iter().all(|sh| sh["on_coming_locked_s"].is_f64()),
            "{s}"
        );
    }
    let (r, m) = (
        runs[0]["shifts"].as_array().unwrap(),
        runs[1]["shifts"].as_array().unwrap(),
    );
    for (a, b) in r.iter().zip(m) {
        for key in ["off_going_released_s", "on_coming_locked_s"] {
            let (x, y) = (a[key].as_f64().unwrap(), b[key].as_f64().unwrap());
            assert!((x - y).abs() < 5e-7, "{key}: {x} {y}");
        }
        let (x, y) = (
            a["on_coming_heat_j"].as_f64().unwrap(),
            b["on_coming_heat_j"].as_f64().unwrap(),
        );
        assert!((x - y).abs() < 2e-4 * x, "heat: {x} {y}");
    }
    let (x, y) = (speeds(&runs[0])["vehicle"], speeds(&runs[1])["vehicle"]);
    assert!((x - y).abs() < 1e-6 * x, "{x} {y}");
}

/// `scenes/eight-speed-drive.toml`'s 1 -> 8 launch closes its energy balance shift by shift
/// (issue 45: "energy closed through every shift of the 1 -> 8 launch to 1e-6 of the work
/// in"): each shift's `energy_residual_j` in the summary, the balance from its start to the
/// next shift's start (the last one's to the run's end: the engine's balance at the two
/// instants, MODEL.md section 8 "Energy"), against its `work_in_j`, the engine's work over
/// that interval (65 to 112 kJ). Measured (2026-12-07): within 5.1e-10 of it on the reference
/// engine and 1.4e-9 on the multibody engine (5e-5 to 9e-5 J, the whole run's 2.9e-4 and
/// 6.1e-4 J spread over its shifts). Asserted 1e-8 (7x; the issue's 1e-6).
#[test]
fn every_shift_of_the_eight_speed_launch_closes_its_energy_on_both_engines() {
    let d = scratch("eight-speed-drive-balance");
    for engine in ["reference", "multibody"] {
        let s = summary(Path::new("scenes/eight-speed-drive.toml"), engine, &d);
        let shifts = s["shifts"].as_array().unwrap();
        assert_eq!(shifts.len(), 7, "{engine}: {s}");
        let mut worst = 0.0f64;
        for sh in shifts {
            let work = sh["work_in_j"].as_f64().unwrap();
            let residual = sh["energy_residual_j"].as_f64().unwrap();
            println!(
                "{engine}: {} -> {} at {} s: work in {work} J, residual {residual:e} J ({:.2e})",
                sh["from"],
                sh["to"],
                sh["start_s"],
                residual.abs() / work
            );
            assert!(work > 0.0, "{engine}: {sh}");
            worst = worst.max(residual.abs() / work);
        }
        println!("{engine}: worst {worst:.2e}; the run's {}", s["energy"]);
        assert!(
            worst < 1e-8,
            "{engine}: a shift's balance {worst:.3e} of its work"
        );
    }
}
