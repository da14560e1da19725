//! A simple planetary set (MODEL.md section 10) on both engines: Willis' equation as one
//! constraint row on three bodies (the model's `network/rows.rs`), against its closed forms.

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

/// Runs `scene` on `engine`: its summary.
fn summary(scene: &Path, engine: &str, dir: &Path) -> Value {
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
    for (from, to, key, why) in cases {
        assert!(text.contains(from), "{from}");
        let bad = d.join("bad.toml");
        std::fs::write(&bad, text.replace(from, to)).unwrap();
        let o = run(&["check", bad.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{to}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(key) && e.contains(why), "{to}: {e}");
    }
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
