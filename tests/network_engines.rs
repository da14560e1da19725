//! Both engines on `scenes/dct-upshift.toml`, the dual-clutch upshift with both clutches
//! resolved packs (issue 34's cross-engine must-show): the disc and plate impacts before the
//! shift one by one, every pack's lock times, the speeds and the heat at the end.

use super::common::{impacts_apart, network_impacts, Impact};
use super::{read_json, run, scratch, stderr};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// The largest relative difference of the bodies' final speeds of two network summaries.
fn speeds_apart(a: &Value, b: &Value) -> f64 {
    let speeds = |s: &Value| -> Vec<f64> {
        s["bodies"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["final_speed_rad_s"].as_f64().unwrap())
            .collect()
    };
    speeds(a)
        .iter()
        .zip(speeds(b))
        .map(|(x, y)| (x - y).abs() / x.abs())
        .fold(0.0, f64::max)
}

/// Runs the network scene `scene` on `engine` without a recording, with the options `more`:
/// its summary (written into `dir`).
fn summary_on(scene: &str, engine: &str, dir: &Path, more: &[&str]) -> Value {
    let json = dir.join(format!("{engine}.json"));
    let mut args = vec![
        "run",
        scene,
        "--engine",
        engine,
        "--no-record",
        "--summary-json",
        json.to_str().unwrap(),
    ];
    args.extend_from_slice(more);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    read_json(&json)
}

/// Runs `scenes/dct-upshift.toml` on `engine` into `dir`: its summary and its impacts.
fn dct_upshift(engine: &str, dir: &Path) -> (Value, BTreeMap<String, Vec<Impact>>) {
    let csv = dir.join(format!("{engine}.csv"));
    let more = ["--impacts-csv", csv.to_str().unwrap()];
    let s = summary_on("scenes/dct-upshift.toml", engine, dir, &more);
    (s, network_impacts(&csv))
}

/// The multibody engine (each pack's discs and plates rapier bodies, advanced inside the
/// network's 1e-4 s steps) against the reference engine (one DOPRI5 over the whole network)
/// on the whole shift. Measured (2026-11-27): over the first 30 ms, 39 impacts closed (K2's
/// discs and plates rattling, K1's clamped bodies carried on one flank), onsets within
/// 1.8e-6 s and peaks within 7.6e-4 (at a 2.5e-5 s network step: 1.5e-7 s and 8.4e-5, so the
/// difference is the multibody engine's step); the lock times within 1.3e-4 s (a lock is
/// timed to the network step that ends with the faces locked); the speeds at 1 s within
/// 4.1e-5; K2's heat within 3.9e-5. The bounds: the issue's (2 us, 0.5 %, 0.1 %), and 2e-4
/// on the speeds and heat (about 5x). K1's release rattle after 0.2 s is not compared one by
/// one (278 impacts against 331: the rattle of a pack being released is chaotic).
#[test]
fn dct_upshift_impacts_and_locks_agree_on_both_engines() {
    let d = scratch("network-engines");
    let (ref_sum, ref_imp) = dct_upshift("reference", &d);
    let (mb_sum, mb_imp) = dct_upshift("multibody", &d);
    // the impacts closed in the first 30 ms, one by one, on every body of both packs
    let (n, worst_on, worst_peak) = impacts_apart(&ref_imp, &mb_imp, 0.03);
    eprintln!(
        "first 30 ms: {n} impacts, onsets within {worst_on:.2e} s, peaks within {worst_peak:.2e}"
    );
    assert!(n >= 30, "{n} impacts in the first 30 ms");
    assert!(worst_on <= 2e-6, "onsets differ by {worst_on:.3e} s");
    assert!(worst_peak <= 5e-3, "peaks differ by {worst_peak:.3e}");
    // every pack's lock times
    let couplings = |s: &Value| s["couplings"].as_array().unwrap().clone();
    let (rc, mc) = (couplings(&ref_sum), couplings(&mb_sum));
    let mut locks = 0;
    for (r, m) in rc.iter().zip(&mc) {
        if r["kind"] != "pack" {
            continue;
        }
        let times = |c: &Value| -> Vec<f64> {
            c["lock_times_s"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| t.as_f64().unwrap())
                .collect()
        };
        let (tr, tm) = (times(r), times(m));
        assert_eq!(
            tr.len(),
            tm.len(),
            "{}: locks {tr:?} against {tm:?}",
            r["name"]
        );
        for (a, b) in tr.iter().zip(&tm) {
            eprintln!("{} locks at {a} s and {b} s", r["name"]);
            assert!(
                (a - b).abs() <= 1e-3 * a.max(1e-6),
                "{}: {a} against {b}",
                r["name"]
            );
            locks += 1;
        }
        let (hr, hm) = (r["heat_j"].as_f64().unwrap(), m["heat_j"].as_f64().unwrap());
        assert!(
            (hr - hm).abs() <= 2e-4 * hr,
            "{}: heat {hr} J against {hm} J",
            r["name"]
        );
    }
    assert_eq!(locks, 3, "K1 at 0 and again, K2 at the shift's end");
    let speeds = speeds_apart(&ref_sum, &mb_sum);
    assert!(speeds <= 2e-4, "the final speeds differ by {speeds:.3e}");
    // the network's balance with the packs' share as the carriers' work on them (measured
    // 6.1e-5 J of 78.4 kJ driven)
    let residual = mb_sum["energy"]["residual_j"].as_f64().unwrap();
    assert!(residual.abs() <= 1e-3, "energy residual {residual} J");
}

/// `dct-upshift.toml` with K2 from `dct-k2-thermal.toml` (its temperatures carried, its oil's
/// viscosity by Walther's law) on both engines: every disc's and plate's final and largest
/// temperature within 0.05 K (measured 2026-11-27: 0.016 K, plate-2's peak, of a 24 K rise),
/// the oil's within 2e-3 K (3.1e-4 K), the faces' and the whole heat within 1e-3 (5.3e-4 and
/// 2.7e-4), both heat balances closed. The teeth's share is not compared: 4.9 J on the
/// reference engine against 2.4 J. It is the rattle's: with the gaps' thinner oil, K2's
/// discs and plates rattle differently from about 60 ms on (the multibody engine's onsets
/// 4.6 ms off by 0.2 s at its 1e-4 s network step, 0.19 ms at 2.5e-5 s, converging), so
/// they meet the torque phase on other flanks; isothermal, the two engines' packs' teeth
/// and drag losses agree within 0.05 J of 7.9 J.
#[test]
fn a_thermal_pack_on_the_shift_has_the_same_temperatures_on_both_engines() {
    let d = scratch("network-engines-thermal");
    let thermal = |engine: &str| {
        let hot = ["--set", "couplings[2].pack=dct-k2-thermal.toml"];
        let s = summary_on("scenes/dct-upshift.toml", engine, &d, &hot);
        s["couplings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == "K2")
            .unwrap()["thermal"]
            .clone()
    };
    let (r, m) = (thermal("reference"), thermal("multibody"));
    let num = |v: &Value, k: &str| v[k].as_f64().unwrap();
    let bodies = |v: &Value| v["bodies"].as_array().unwrap().clone();
    let mut worst = 0.0f64;
    for (a, b) in bodies(&r).iter().zip(&bodies(&m)) {
        for k in ["final_k", "max_k"] {
            worst = worst.max((num(a, k) - num(b, k)).abs());
        }
    }
    assert_eq!(bodies(&r).len(), 11);
    assert!(worst <= 0.05, "a body's temperature differs by {worst} K");
    let oil = (num(&r, "oil_final_k") - num(&m, "oil_final_k")).abs();
    assert!(oil <= 2e-3, "the oil's temperature differs by {oil} K");
    for k in ["friction_heat_j", "generated_j"] {
        let (a, b) = (num(&r, k), num(&m, k));
        assert!((a - b).abs() <= 1e-3 * a, "{k}: {a} J against {b} J");
    }
    for v in [&r, &m] {
        assert!(num(v, "balance_error_j").abs() <= 1e-6, "{v}");
    }
    eprintln!(
        "temperatures within {worst:.3e} K, oil {oil:.3e} K; teeth {} J against {} J",
        num(&r, "impact_heat_j"),
        num(&m, "impact_heat_j")
    );
}

/// A lumped clutch that locks a third body onto a pack's carrier changes the carrier's
/// inertia mid-run (its rigid group grows from the hub's 0.02 kg m^2 to 0.32): the multibody
/// engine's pack session takes the new inertia at the lock. `dct-k1.toml` clamped between an
/// engine (100 N m) and a hub, clutch C (200 N m) applied at 50 ms onto a slower body: on
/// both engines C locks at the same instant (measured 2026-11-27: 1.0e-8 s apart), the
/// speeds at 0.3 s (one rigid body by then: 2.4e-11) and C's heat agree, and K1's discs' and
/// plates' largest tooth loads.
#[test]
fn a_clutch_locking_onto_a_packs_carrier_agrees_on_both_engines() {
    let d = scratch("network-engines-lock");
    let scene = d.join("net.toml");
    let pack = std::fs::canonicalize("scenes/dct-k1.toml").unwrap();
    std::fs::write(
        &scene,
        format!(
            r#"
name = "pack-and-a-lock"
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
name = "extra"
inertia_kg_m2 = 0.3
initial_speed_rad_s = 250.0
[[couplings]]
name = "K1"
kind = "pack"
a = "hub"
b = "engine"
pack = "{}"
[[couplings]]
name = "C"
kind = "clutch"
a = "hub"
b = "extra"
mu = 0.5
peak = 1.1
cgeo_m = 0.1
max_normal_force_n = 4000.0
[couplings.force]
kind = "step"
height = 1.0
start_s = 0.05
"#,
            pack.display()
        ),
    )
    .unwrap();
    let go = |engine: &str| summary_on(scene.to_str().unwrap(), engine, &d, &[]);
    let (rs, ms) = (go("reference"), go("multibody"));
    let coupling = |s: &Value, name: &str| {
        s["couplings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == name)
            .unwrap()
            .clone()
    };
    let lock = |s: &Value| coupling(s, "C")["lock_times_s"][0].as_f64().unwrap();
    let (lr, lm) = (lock(&rs), lock(&ms));
    eprintln!("C locks at {lr} s and {lm} s");
    assert!((lr - lm).abs() <= 1e-4, "C locks at {lr} s against {lm} s");
    let heat = |s: &Value| coupling(s, "C")["heat_j"].as_f64().unwrap();
    let (hr, hm) = (heat(&rs), heat(&ms));
    assert!(
        (hr - hm).abs() <= 1e-3 * hr,
        "C's heat {hr} J against {hm} J"
    );
    let worst = speeds_apart(&rs, &ms);
    eprintln!("speeds at 0.3 s within {worst:.2e}");
    assert!(worst <= 2e-4, "speeds {worst}");
    // K1's bodies, carried on one flank from t = 0 (their contacts never close): each
    // body's largest load (measured 1.5e-7 apart) and K1's largest torque on the hub (the
    // multibody engine's is the mean over a network step: 2.4e-4)
    let bodies = |s: &Value| coupling(s, "K1")["pack_bodies"].as_array().unwrap().clone();
    let mut peak = 0.0f64;
    for (r, m) in bodies(&rs).iter().zip(&bodies(&ms)) {
        let (a, b) = (
            r["largest_peak_n"].as_f64().unwrap(),
            m["largest_peak_n"].as_f64().unwrap(),
        );
        peak = peak.max(((a - b) / a).abs());
    }
    assert_eq!(bodies(&rs).len(), 9);
    assert!(peak <= 1e-5, "K1's bodies' peaks {peak}");
    let torque = |s: &Value| coupling(s, "K1")["max_torque_n_m"].as_f64().unwrap();
    let (tr, tm) = (torque(&rs), torque(&ms));
    assert!(
        (tr - tm).abs() <= 1e-3 * tr,
        "K1's torque {tr} against {tm} N m"
    );
}
