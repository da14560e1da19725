//! `clutchpack fit` (issue 47) on Modelica's CoupledClutches (`scenes/coupled-clutches.toml`):
//! the clutches' friction and the step times recovered from the bodies' speeds, an
//! unidentifiable pair said to be so, and bad input refused before any run.
//!
//! The measured trace is our own reference engine's run at the true values, not MAP-LIB's
//! CSV: the engine agrees with Modelica's published reference results of this model to about
//! 1e-5 (lock times within 2e-5 s, `crates/reference/tests/network.rs`), so our trace is an
//! honest stand-in for theirs (which the repository does not ship), and with it the true
//! values are known exactly. Noise (normal, seeded) is added where the intervals are checked.

use super::{read_json, run, scratch, stderr, stdout};
use clutchpack_sdk::{load_scene, run_network_scene, NetworkRequest};
use std::path::{Path, PathBuf};

const SCENE: &str = "scenes/coupled-clutches.toml";

/// A standard normal number from a counter (SplitMix64 into Box-Muller): reproducible noise
/// without a random crate.
fn normal(seed: u64, k: u64) -> f64 {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    let u = |x: u64| ((mix(x) >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let (u1, u2) = (u(seed ^ (2 * k)), u(seed ^ (2 * k + 1)));
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// The trace of J1..J4's speeds (columns `time_s,w1,w2,w3,w4`, rad/s) of the scene as
/// shipped, every sample (1 ms), with normal noise of standard deviation `sd` rad/s.
fn trace(dir: &Path, sd: f64, seed: u64) -> PathBuf {
    let scene = load_scene(Some(Path::new(SCENE)), &[]).unwrap();
    let out = run_network_scene(
        &scene,
        None,
        NetworkRequest {
            keep_history: true,
            ..NetworkRequest::default()
        },
    )
    .unwrap();
    let mut text = String::from("time_s,w1,w2,w3,w4\n");
    let mut last = f64::NEG_INFINITY;
    let mut k = 0;
    for s in &out.history {
        if s.t_s <= last {
            continue;
        }
        last = s.t_s;
        let w: Vec<String> = s
            .speed_rad_s
            .iter()
            .map(|w| {
                k += 1;
                format!("{:?}", w + sd * normal(seed, k))
            })
            .collect();
        text.push_str(&format!("{:?},{}\n", s.t_s, w.join(",")));
    }
    let p = dir.join("trace.csv");
    std::fs::write(&p, text).unwrap();
    p
}

/// The four parameters of issue 47 at 30 % from their true values, and their true values.
const PARAMS: [(&str, f64); 4] = [
    ("couplings[*].mu=0.35:0.05:2:log", 0.5),
    ("couplings[*].peak=1.43:1:3", 1.1),
    ("couplings[1].force.start_s=0.52:0.1:0.8", 0.4),
    ("couplings[2].force.start_s=0.63:0.5:1.3", 0.9),
];

/// `fit` with the speeds of J1..J4 matched at weight `weight` and `params`; the output and
/// the summary.
fn fit(d: &Path, data: &Path, params: &[&str], weight: f64) -> (std::process::Output, PathBuf) {
    let json = d.join("fit.json");
    let mut args: Vec<String> = vec![
        "fit".into(),
        SCENE.into(),
        "--data".into(),
        data.to_str().unwrap().into(),
        "--fitted-scene".into(),
        d.join("cc.fitted.toml").to_str().unwrap().into(),
        "--summary-json".into(),
        json.to_str().unwrap().into(),
        "--plot".into(),
        d.join("fit.svg").to_str().unwrap().into(),
    ];
    for p in params {
        args.extend(["--param".into(), p.to_string()]);
    }
    for j in 1..=4 {
        args.extend(["--match".into(), format!("J{j}=w{j}:{weight}")]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    (run(&args), json)
}

/// From starting values 30 % off (mu low, peak high, the step times one late and one early)
/// and the exact trace, the clutches' `mu` and `peak` and the step times of clutches 2 and 3
/// are recovered within 1e-3 relative (measured: within 1e-9), the fit converges with no
/// warning, the fitted scene is valid and holds the fitted values, and the figure is written.
#[test]
fn coupled_clutches_friction_and_step_times_are_recovered() {
    let d = scratch("fit-coupled-clutches");
    let data = trace(&d, 0.0, 0);
    let params: Vec<&str> = PARAMS.iter().map(|p| p.0).collect();
    let (o, json) = fit(&d, &data, &params, 1.0);
    assert!(o.status.success(), "{}", stderr(&o));
    println!("{}", stdout(&o));
    let s = read_json(&json);
    assert_eq!(s["converged"], true, "{s}");
    assert!(s["warnings"].as_array().unwrap().is_empty(), "{s}");
    for (k, (_, truth)) in PARAMS.iter().enumerate() {
        let value = s["params"][k]["value"].as_f64().unwrap();
        println!("{}: {value} (true {truth})", s["params"][k]["key"]);
        assert!(
            (value - truth).abs() < 1e-3 * truth,
            "{}: {value} vs {truth}",
            s["params"][k]["key"]
        );
    }
    println!(
        "CoupledClutches fit: {} runs, {} iterations, {:.2} s wall",
        s["runs"], s["iterations"], s["wall_time_s"]
    );
    let fitted = d.join("cc.fitted.toml");
    let o = run(&["check", fitted.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&fitted).unwrap();
    assert!(
        text.starts_with("# scenes/coupled-clutches.toml fitted"),
        "{text}"
    );
    // every clutch's mu set to the one fitted value
    let v0 = s["params"][0]["value"].as_f64().unwrap();
    let mu_lines = text
        .lines()
        .filter(|l| *l == format!("mu = {v0:?}"))
        .count();
    assert_eq!(mu_lines, 3, "{text}");
    assert!(std::fs::read_to_string(d.join("fit.svg"))
        .unwrap()
        .contains("<svg"));
}

/// The same fit on the trace with normal noise of 0.01 rad/s (weight 100 = 1/sigma; noise
/// seed 47, the first one tried): each true value lies inside its reported 95 % interval;
/// `mu` and the step times are still within 1e-3 relative (their intervals are narrower
/// than that: measured half-widths 1.3e-4 of mu, 2.0e-4 and 1.1e-4 of the step times), while
/// `peak` is honestly uncertain at this noise (measured 1.059, interval 0.91 to 1.20): the
/// static friction only acts at clutch 1's two breakaways (0.83 s and 1.00 s), which move
/// the speeds little. Each signal's RMS after the fit is the noise level within 10 %.
#[test]
fn coupled_clutches_intervals_hold_the_true_values_under_noise() {
    let d = scratch("fit-coupled-clutches-noise");
    let data = trace(&d, 0.01, 47);
    let params: Vec<&str> = PARAMS.iter().map(|p| p.0).collect();
    let (o, json) = fit(&d, &data, &params, 100.0);
    assert!(o.status.success(), "{}", stderr(&o));
    println!("{}", stdout(&o));
    let s = read_json(&json);
    assert_eq!(s["converged"], true, "{s}");
    for (k, (_, truth)) in PARAMS.iter().enumerate() {
        let p = &s["params"][k];
        let value = p["value"].as_f64().unwrap();
        let (lo, hi) = (
            p["ci95_low"].as_f64().unwrap(),
            p["ci95_high"].as_f64().unwrap(),
        );
        println!("{}: {value} [{lo}, {hi}] (true {truth})", p["key"]);
        assert!(
            lo <= *truth && *truth <= hi,
            "{}: {truth} outside [{lo}, {hi}]",
            p["key"]
        );
        if k != 1 {
            assert!(
                (value - truth).abs() < 1e-3 * truth,
                "{}: {value} vs {truth}",
                p["key"]
            );
        }
    }
    for sig in s["signals"].as_array().unwrap() {
        let rms = sig["rms"].as_f64().unwrap();
        assert!((0.009..0.011).contains(&rms), "{sig}");
    }
}

/// Fitted together, `mu` and `max_normal_force_n` are not separately identifiable (a
/// slipping clutch's torque is mu fn cgeo, a locked one's limit peak mu fn cgeo: only the
/// product enters): the fit says so with a correlation below -0.99, a warning in the result
/// and on the terminal, and intervals far wider than mu's alone (more than 100 times as wide
/// relative to the value).
#[test]
fn mu_and_normal_force_are_said_to_be_unidentifiable() {
    let d = scratch("fit-unidentifiable");
    let data = trace(&d, 0.01, 47);
    let (o, json) = fit(
        &d,
        &data,
        &[
            "couplings[*].mu=0.35:0.05:2:log",
            "couplings[*].max_normal_force_n=26:5:80:log",
        ],
        100.0,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    println!("{}\n{}", stdout(&o), stderr(&o));
    assert!(
        stderr(&o).contains("not separately identifiable"),
        "{}",
        stderr(&o)
    );
    let pair = read_json(&json);
    let c = pair["correlation"][0][1].as_f64().unwrap();
    assert!(c < -0.99, "correlation {c}");
    assert!(pair["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("not separately identifiable")));
    // the product is what the data fix: within 1e-3 of 0.5 x 20 N
    let v = |s: &serde_json::Value, k: usize| s["params"][k]["value"].as_f64().unwrap();
    assert!((v(&pair, 0) * v(&pair, 1) - 10.0).abs() < 1e-2, "{pair}");
    // an infinite end is `null` in JSON
    let width = |s: &serde_json::Value, k: usize| {
        let p = &s["params"][k];
        let end = |k: &str| p[k].as_f64().unwrap_or(f64::INFINITY);
        (end("ci95_high") - end("ci95_low")) / p["value"].as_f64().unwrap()
    };
    let (o, json) = fit(&d, &data, &["couplings[*].mu=0.35:0.05:2:log"], 100.0);
    assert!(o.status.success(), "{}", stderr(&o));
    let alone = read_json(&json);
    println!(
        "relative 95 % widths: mu alone {:.3e}, mu with fn {:.3e}, fn with mu {:.3e}",
        width(&alone, 0),
        width(&pair, 0),
        width(&pair, 1)
    );
    assert!(width(&pair, 0) > 100.0 * width(&alone, 0));
    assert!(width(&pair, 1) > 100.0 * width(&alone, 0));
}

/// Bad input is refused before any run (exit 2) with a message naming the problem: a key
/// that does not exist, one that is not numeric, bounds reversed, a bound outside the key's
/// own rule, a missing column, time not increasing, NaN in the data, a signal the scene does
/// not produce. No fitted scene is written.
#[test]
fn bad_fit_input_is_refused_before_any_run() {
    let d = scratch("fit-bad");
    let good = d.join("good.csv");
    std::fs::write(&good, "time_s,w1\n0,10\n0.001,10\n").unwrap();
    let back = d.join("back.csv");
    std::fs::write(&back, "time_s,w1\n0,10\n0.002,10\n0.001,10\n").unwrap();
    let nan = d.join("nan.csv");
    std::fs::write(&nan, "time_s,w1\n0,10\n0.001,NaN\n").unwrap();
    let g = good.to_str().unwrap();
    let cases: [(&str, &str, &str, &[&str]); 8] = [
        (
            "couplings[0].mux:0:1",
            "J1=w1",
            g,
            &["couplings[0].mux", "unknown key"],
        ),
        (
            "couplings[0].kind",
            "J1=w1",
            g,
            &["couplings[0].kind", "not a number"],
        ),
        ("couplings[0].mu:1:0.1", "J1=w1", g, &["reversed"]),
        (
            "couplings[0].peak:0.5:2",
            "J1=w1",
            g,
            &["lower bound 0.5", "in [1, 100]"],
        ),
        (
            "couplings[0].mu:0:1",
            "J1=speed1",
            g,
            &["no column \"speed1\""],
        ),
        (
            "couplings[0].mu:0:1",
            "J1=w1",
            back.to_str().unwrap(),
            &["line 4", "does not increase"],
        ),
        (
            "couplings[0].mu:0:1",
            "J1=w1",
            nan.to_str().unwrap(),
            &["line 3", "not finite"],
        ),
        (
            "couplings[0].mu:0:1",
            "J9=w1",
            g,
            &["J9", "does not produce", "J1.speed_rad_s"],
        ),
    ];
    for (param, signal, data, needles) in cases {
        let fitted = d.join("x.fitted.toml");
        let o = run(&[
            "fit",
            SCENE,
            "--data",
            data,
            "--param",
            param,
            "--match",
            signal,
            "--fitted-scene",
            fitted.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{param} {signal}: {err}");
        for n in needles {
            assert!(
                err.contains(n),
                "{param} {signal}: expected {n:?} in: {err}"
            );
        }
        assert!(!fitted.exists(), "{param}: nothing written");
    }
}
