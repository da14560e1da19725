//! `clutchpack run` of a network scene (issue 34): the table, `--summary-json` and `--plot` of
//! `scenes/coupled-clutches.toml`, and the pack-only options refused before any work.

use super::{read_json, run, scratch, stderr, stdout};

/// The summary holds every clutch's lock times (Modelica's reference results, as the engine's
/// own test checks them: within 2e-5 s), the final speeds and a closed energy balance; the
/// figure is written; a pack-only option or another command is bad input (exit 2) that
/// writes nothing.
#[test]
fn coupled_clutches_run_writes_summary_and_figure() {
    let d = scratch("network-run");
    let (json, png) = (d.join("cc.json"), d.join("cc.png"));
    let o = run(&[
        "run",
        "scenes/coupled-clutches.toml",
        "--summary-json",
        json.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("clutch mode changes:"),
        "{}",
        stdout(&o)
    );
    let s = read_json(&json);
    let locks = |k: usize| -> Vec<f64> {
        s["couplings"][k]["lock_times_s"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    // MAP-LIB reference results of CoupledClutches (crates/reference/tests/network.rs)
    let expect = [
        vec![0.791_658_284_320_25, 0.906_849_137_544_382],
        vec![0.709_621_463_832_881],
        vec![1.143_969_630_433_71],
    ];
    for (k, want) in expect.iter().enumerate() {
        let got = locks(k);
        assert_eq!(got.len(), want.len(), "{s}");
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 2e-5, "clutch {k}: {g} against {w}");
        }
    }
    let j1 = s["bodies"][0]["final_speed_rad_s"].as_f64().unwrap();
    assert!((j1 - 3.247_034_565).abs() < 5e-5 * 3.25, "{j1}");
    let e = &s["energy"];
    assert!(e["residual_j"].as_f64().unwrap().abs() < 1e-9, "{e}");
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);

    let csv = d.join("impacts.csv");
    let o = run(&[
        "run",
        "scenes/coupled-clutches.toml",
        "--impacts-csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--impacts-csv: not for a network scene"));
    assert!(!csv.exists());
    let o = run(&[
        "fmu",
        "scenes/coupled-clutches.toml",
        "--out",
        d.join("cc.fmu").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("network scene"), "{}", stderr(&o));
}
