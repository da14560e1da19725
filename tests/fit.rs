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
use clutchpack_sdk::{load_scene, NetworkRequest, Simulation};
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
    let out = Simulation::new(scene, None)
        .unwrap()
        .run(NetworkRequest {
            keep_history: true,
            ..NetworkRequest::default()
        })
        .unwrap()
        .into_network()
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

const PACK: &str = "scenes/pack-6-engagement.toml";

/// The pack's co-simulated run (the fit's own route to a pack's signals, driving no input)
/// on the reference engine with the overrides `sets`: the outputs `names` at `times`.
fn pack_series(sets: &[&str], names: &[&str], times: &[f64]) -> Vec<Vec<f64>> {
    use clutchpack_sdk::cosim::Quantity;
    use clutchpack_sdk::{CoSimulation, Driven};
    let sets: Vec<clutchpack_sdk::scene::Override> =
        sets.iter().map(|s| s.parse().unwrap()).collect();
    let scene = load_scene(Some(Path::new(PACK)), &sets).unwrap();
    let mut co = CoSimulation::driving(scene, Driven::NONE).unwrap();
    co.set_string_parameter(Quantity::Engine, "reference")
        .unwrap();
    let vrs: Vec<u32> = names
        .iter()
        .map(|n| co.variables().iter().find(|v| v.name == *n).unwrap().vr)
        .collect();
    co.start(None).unwrap();
    let mut out = vec![Vec::new(); names.len()];
    for &t in times {
        if t > co.time_s() {
            assert!(co.advance_to(t, None).unwrap());
        }
        for (k, &vr) in vrs.iter().enumerate() {
            out[k].push(co.get_real(vr).unwrap());
        }
    }
    out
}

/// The pack's run cut to 0.1 s (the drum locks at 0.086 s), for a test in debug.
const PACK_SHORT: &str = "simulation.duration_s=0.1";

/// The true friction curve of the pack's trace: the scene's kinetic mu (0.13) and a viscous
/// slope of 2e-4 s/m (the scene's is 0, on its key's bound, where no interval means
/// anything).
const PACK_TRUTH: [(&str, f64); 2] = [
    ("stack.friction.kinetic_mu", 0.13),
    ("stack.friction.viscous_slope_s_m", 2e-4),
];

/// pack-6-engagement's trace at the true friction curve: columns `time_s`, `drum` (the
/// drum's speed, rad/s) and `torque` (the piston-side face's friction torque, N m), every
/// 1 ms from 0 to 0.1 s.
fn pack_trace(dir: &Path) -> PathBuf {
    let times: Vec<f64> = (0..=100).map(|i| i as f64 * 1e-3).collect();
    let slope = format!("{}={}", PACK_TRUTH[1].0, PACK_TRUTH[1].1);
    let y = pack_series(
        &[PACK_SHORT, &slope],
        &["drum.speed_rad_s", "interfaces[1].torque_n_m"],
        &times,
    );
    let mut text = String::from("time_s,drum,torque\n");
    for (i, t) in times.iter().enumerate() {
        text.push_str(&format!("{t:?},{:?},{:?}\n", y[0][i], y[1][i]));
    }
    let p = dir.join("pack-trace.csv");
    std::fs::write(&p, text).unwrap();
    p
}

/// A resolved pack's fit (issue 47): pack-6-engagement's friction curve, its kinetic mu and
/// its viscous slope (`mu = kinetic + slope v` over the slip, v from 52 m/s down to 0),
/// fitted on the reference engine to the drum's speed and the piston-side face's torque
/// from starting values 23 % and 150 % off (0.10, 5e-4 s/m), both on a log scale with a
/// forward-difference step of 1 % of ln x. The trace is the project's own run at the true
/// values (the route the fit takes: the scene's co-simulation read at the measured times).
/// The face's torque carries the rattle's chaos (its clamp force depends on the spline
/// friction of the rattling discs: a change of mu by 1e-3 moves it by 15 N m RMS where
/// a smooth response would move it by 1 N m), so it is weighted 1e-3 (1 / its scatter of
/// ~1000 N m over a 4 % change of mu), and the step is 1 % for the same reason. Measured:
/// kinetic mu 0.12967 (-0.25 %), slope 2.113e-4 s/m (+5.6 %), 35 runs; the bounds are 0.5 %
/// and 10 %. The fit ends where the chaos hides any better step (reported as converged on
/// the step size), and the fitted scene loads.
#[test]
fn pack_engagement_friction_curve_is_recovered_from_drum_speed_and_torque() {
    let d = scratch("fit-pack-engagement");
    let data = pack_trace(&d);
    let json = d.join("fit.json");
    let fitted = d.join("pack.fitted.toml");
    let o = run(&[
        "fit",
        PACK,
        "--data",
        data.to_str().unwrap(),
        "--engine",
        "reference",
        "--set",
        PACK_SHORT,
        "--param",
        "stack.friction.kinetic_mu=0.10:0.05:0.3:log",
        "--param",
        "stack.friction.viscous_slope_s_m=5e-4:1e-5:2e-3:log",
        "--fd-step",
        "1e-2",
        "--match",
        "drum.speed_rad_s=drum",
        "--match",
        "interfaces[1].torque_n_m=torque:1e-3",
        "--fitted-scene",
        fitted.to_str().unwrap(),
        "--summary-json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    println!("{}\n{}", stdout(&o), stderr(&o));
    let s = read_json(&json);
    println!(
        "pack fit: {} runs, {} iterations, {:.2} s wall",
        s["runs"], s["iterations"], s["wall_time_s"]
    );
    assert_eq!(s["converged"], true, "{s}");
    for ((key, truth), bound) in PACK_TRUTH.iter().zip([5e-3, 0.1]) {
        let k = if key.ends_with("kinetic_mu") { 0 } else { 1 };
        let value = s["params"][k]["value"].as_f64().unwrap();
        println!("{key}: {value} (true {truth})");
        assert!(
            (value - truth).abs() < bound * truth,
            "{key}: {value} vs {truth}"
        );
    }
    let o = run(&["check", fitted.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The paper's Table 2 peaks (Hu et al.; h_o = 0, 25, 50 um), one row per film thickness.
fn paper_table(dir: &Path) -> PathBuf {
    let p = dir.join("table2.csv");
    std::fs::write(
        &p,
        "defaults.oil.film_thickness_m,max_pos,max_neg\n\
         0,945.39,-976.42\n25e-6,867.6,-867.8\n50e-6,503.1,-503.5\n",
    )
    .unwrap();
    p
}

/// `fit` of the paper's two ASSUMED contact parameters to its Table 2 with `extra` args.
fn paper_fit(d: &Path, extra: &[&str]) -> (std::process::Output, PathBuf) {
    let json = d.join("paper.json");
    let table = paper_table(d);
    let mut args = vec![
        "fit",
        "scenes/hu-table2.toml",
        "--data",
        table.to_str().unwrap(),
        "--variant",
        "defaults.oil.film_thickness_m",
        "--param",
        "defaults.contact.curvature_radius_m:0.5e-3:5e-3:log",
        "--param",
        "defaults.contact.loss_coefficient_s_m:0.1:3:log",
        "--match",
        "disc.max_positive_n=max_pos:0.01",
        "--match",
        "disc.max_negative_n=max_neg:0.01",
        "--summary-json",
        json.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    (run(&args), json)
}

/// The paper's calibration as a fit over scene variants (issue 47): the two ASSUMED contact
/// parameters of hu-table2.toml (curvature radius, loss coefficient) fitted to the six peaks
/// of Table 2, each variant's peaks the mean of a 2-member ensemble here (32 in
/// docs/calibration.md; a rattle's peak is chaotic, one run one sample). The fit lowers the
/// residuals from the shipped values, reports finite intervals and a correlation short of
/// +-1 (the two are separately identifiable from three films), counts its runs as
/// evaluations x 3 variants x 2 members, and lands within 30 % of the shipped values (which
/// were calibrated by hand against the same table; measured: r 1.786 mm, p 0.810 s/m, 17
/// evaluations, 102 runs, correlation +0.46).
#[test]
fn paper_table_peaks_fit_the_contact_parameters_over_variants() {
    let d = scratch("fit-paper-table");
    let fitted = d.join("hu.fitted.toml");
    let (o, json) = paper_fit(
        &d,
        &[
            "--ensemble",
            "2",
            "--fd-step",
            "5e-2",
            "--fitted-scene",
            fitted.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    println!("{}\n{}", stdout(&o), stderr(&o));
    let s = read_json(&json);
    assert_eq!(s["rows"], "defaults.oil.film_thickness_m");
    assert_eq!(
        s["scene_runs"].as_u64().unwrap(),
        s["runs"].as_u64().unwrap() * 6
    );
    for (k, shipped) in [(0, 1.75e-3), (1, 0.8)] {
        let p = &s["params"][k];
        let v = p["value"].as_f64().unwrap();
        assert!(p["std_error"].as_f64().unwrap().is_finite(), "{p}");
        assert!((v - shipped).abs() < 0.3 * shipped, "{p}");
    }
    let c = s["correlation"][0][1].as_f64().unwrap();
    assert!(c.abs() < 0.99, "correlation {c}");
    for sig in s["signals"].as_array().unwrap() {
        assert!(
            sig["rms"].as_f64().unwrap() < sig["rms_start"].as_f64().unwrap(),
            "{sig}"
        );
    }
    let o = run(&["check", fitted.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Bad input of the variant route and of the pack's signals is refused before any run
/// (exit 2) naming the problem: a per-run statistic without --variant, a series with it, a
/// variant key that is not a number, a variant value outside its key's rule, a pack signal
/// that does not exist (the message lists the pack's outputs).
#[test]
fn bad_variant_and_pack_signal_input_is_refused_before_any_run() {
    let d = scratch("fit-bad-variant");
    let table = paper_table(&d);
    let neg = d.join("neg.csv");
    std::fs::write(
        &neg,
        "defaults.oil.film_thickness_m,max_pos\n-1e-6,900\n0,945\n",
    )
    .unwrap();
    let pack_data = d.join("pack.csv");
    std::fs::write(&pack_data, "time_s,drum\n0,0\n0.01,1\n").unwrap();
    let t = table.to_str().unwrap();
    let r = "defaults.contact.curvature_radius_m:0.5e-3:5e-3";
    let cases: [(&str, Vec<&str>, &[&str]); 5] = [
        (
            "scenes/hu-table2.toml",
            vec![
                "--data",
                t,
                "--param",
                r,
                "--match",
                "disc.max_positive_n=max_pos",
            ],
            &["one value per run", "--variant"],
        ),
        (
            "scenes/hu-table2.toml",
            vec![
                "--data",
                t,
                "--variant",
                "defaults.oil.film_thickness_m",
                "--param",
                r,
                "--match",
                "drum.speed_rad_s=max_pos",
            ],
            &["drum.speed_rad_s", "does not produce it"],
        ),
        (
            "scenes/hu-table2.toml",
            vec![
                "--data",
                t,
                "--variant",
                "defaults.contact.law",
                "--param",
                r,
                "--match",
                "disc.max_positive_n=max_pos",
            ],
            &["--variant defaults.contact.law", "not a number"],
        ),
        (
            "scenes/hu-table2.toml",
            vec![
                "--data",
                neg.to_str().unwrap(),
                "--variant",
                "defaults.oil.film_thickness_m",
                "--param",
                r,
                "--match",
                "disc.max_positive_n=max_pos",
            ],
            &[
                "neg.csv",
                "the variant defaults.oil.film_thickness_m = -1e-6",
                ">= 0",
            ],
        ),
        (
            PACK,
            vec![
                "--data",
                pack_data.to_str().unwrap(),
                "--param",
                "stack.friction.kinetic_mu:0.05:0.3",
                "--match",
                "drum.speed=drum",
            ],
            &["drum.speed", "drum.speed_rad_s", "interfaces[1].torque_n_m"],
        ),
    ];
    for (scene, args, needles) in cases {
        let fitted = d.join("x.fitted.toml");
        let mut all = vec!["fit", scene, "--fitted-scene", fitted.to_str().unwrap()];
        all.extend(args.iter().copied());
        let o = run(&all);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: expected {n:?} in: {err}");
        }
        assert!(!fitted.exists());
    }
}

/// A recording as the measured data (issue 47: `--data run.mcap`): CoupledClutches recorded
/// by `clutchpack run --out` at the true values, and mu fitted from 30 % off to J1..J4's
/// recorded speeds (the columns default to the signals' names, `J1` being J1's speed): the
/// recording holds the run's own samples, so mu comes back within 1e-6 relative (measured:
/// 0.5000000024 in 8 runs). A pack's recording and a series the recording lacks are refused (exit 2),
/// naming the file and listing its series.
#[test]
fn a_network_recording_is_measured_data() {
    let d = scratch("fit-mcap");
    let rec = d.join("cc.mcap");
    let o = run(&["run", SCENE, "--out", rec.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = d.join("fit.json");
    let fitted = d.join("cc.fitted.toml");
    let mut args = vec![
        "fit",
        SCENE,
        "--data",
        rec.to_str().unwrap(),
        "--param",
        "couplings[*].mu=0.35:0.05:2:log",
        "--fitted-scene",
        fitted.to_str().unwrap(),
        "--summary-json",
        json.to_str().unwrap(),
    ];
    for m in ["J1", "J2", "J3", "J4"] {
        args.extend(["--match", m]);
    }
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = read_json(&json);
    let mu = s["params"][0]["value"].as_f64().unwrap();
    println!("mu from the recording: {mu} ({} runs)", s["runs"]);
    assert!((mu - 0.5).abs() < 1e-6 * 0.5, "{mu}");
    let last = args.len() - 1;
    args[last] = "J4=J9";
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("cc.mcap") && err.contains("J9") && err.contains("J4.speed_rad_s"),
        "{err}"
    );
    let pack_rec = d.join("pack.mcap");
    let o = run(&[
        "run",
        "scenes/hu-table2.toml",
        "--duration",
        "0.01",
        "--out",
        pack_rec.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&[
        "fit",
        "scenes/hu-table2.toml",
        "--data",
        pack_rec.to_str().unwrap(),
        "--param",
        "defaults.contact.loss_coefficient_s_m:0.1:3",
        "--match",
        "discs[1].speed_rad_s",
        "--fitted-scene",
        fitted.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("clutchpack export"), "{}", stderr(&o));
}
