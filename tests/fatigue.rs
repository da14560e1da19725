//! Fatigue of the spline teeth end to end (issue 12, MODEL.md section 7): the counts and
//! damage against an independent Python implementation, the physics of the oil film, bad
//! material data, and the outputs of replay, compare and plot --spectrum.

use super::{bin, python_reader, run, scratch, stderr, stdout};
use serde_json::Value;
use std::path::Path;

/// Runs a scene (None: the built-in paper case) with a recording, `--summary-json` and
/// `--fatigue-json` into `dir`, and returns the three paths.
fn run_with_outputs(
    dir: &Path,
    tag: &str,
    scene: Option<&str>,
) -> (std::path::PathBuf, std::path::PathBuf, std::path::PathBuf) {
    let (mcap, sum, cyc) = (
        dir.join(format!("{tag}.mcap")),
        dir.join(format!("{tag}-summary.json")),
        dir.join(format!("{tag}-cycles.json")),
    );
    let mut c = bin();
    c.arg("run");
    if let Some(s) = scene {
        c.arg(s);
    }
    c.arg("--out")
        .arg(&mcap)
        .arg("--summary-json")
        .arg(&sum)
        .arg("--fatigue-json")
        .arg(&cyc);
    let o = c.output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    (mcap, sum, cyc)
}

/// On the recorded lumped history of the paper case and the lumped and per-tooth (154
/// teeth) histories of scenes/eccentric-disc.toml, the PyPI `rainflow` package counts
/// exactly the (range, count) pairs clutchpack counted (same residue rule: half cycles), the
/// largest range is the history's peak-to-valley span, and a numpy Miner sum over the
/// Python counts with the scene's tooth form and material gives each disc's and each
/// tooth's damage to 1e-12 relative (a few roundings of pow and a sum in another order; the
/// recording stores the loads as doubles, so the histories are the same numbers).
/// tests/python/fatigue_check.py rebuilds the histories from the recording alone.
#[test]
fn counts_and_damage_equal_an_independent_python_computation() {
    let dir = scratch("fatigue_python");
    let py = python_reader();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (tag, scene, file) in [
        ("paper", None, "scenes/hu-table2.toml"),
        (
            "eccentric",
            Some("scenes/eccentric-disc.toml"),
            "scenes/eccentric-disc.toml",
        ),
    ] {
        let (mcap, sum, cyc) = run_with_outputs(&dir, tag, scene);
        let o = std::process::Command::new(&py)
            .arg(root.join("tests/python/fatigue_check.py"))
            .args([&mcap, &cyc, &sum])
            .arg(root.join(file))
            .output()
            .unwrap();
        assert!(o.status.success(), "{tag}: {}", stderr(&o));
        let out = stdout(&o);
        assert!(out.starts_with("ok:"), "{out}");
        if tag == "eccentric" {
            assert!(out.contains("154 teeth"), "{out}");
        }
    }
}

/// The paper case (MODEL.md section 4) with 8-member ensembles: the mean damage rate of the
/// teeth falls strictly from 0 to 100 um of oil film, as the peak loads do (the film cushions
/// the impacts), and the life is D_crit over the mean rate.
#[test]
fn paper_case_mean_damage_rate_falls_with_the_film() {
    let dir = scratch("fatigue_film");
    let json = dir.join("sweep.json");
    let o = run(&[
        "sweep",
        "scenes/hu-table2.toml",
        "--param",
        "defaults.oil.film_thickness_m",
        "--values",
        "0,25e-6,50e-6,75e-6,100e-6",
        "--ensemble",
        "8",
        "--summary-json",
        json.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("life [h]"), "{}", stdout(&o));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rates: Vec<f64> = v["fatigue"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["discs"][0]["damage_rate_per_h"]["mean"].as_f64().unwrap())
        .collect();
    assert_eq!(rates.len(), 5);
    assert!(rates[0] > 0.0);
    for w in rates.windows(2) {
        assert!(w[1] < w[0], "mean damage rates per hour {rates:?}");
    }
    for c in v["fatigue"].as_array().unwrap() {
        let d = &c["discs"][0];
        let mean = d["damage_rate_per_h"]["mean"].as_f64().unwrap();
        let life = d["life_at_mean_rate_h"].as_f64().unwrap();
        assert!((life * mean - 1.0).abs() < 1e-12, "{d}");
    }
}

/// Bad tooth-form or material data: exit 2, one line naming the key, the value and the rule.
#[test]
fn bad_material_or_tooth_form_exits_2() {
    for (set, expect) in [
        (
            "defaults.material.endurance_amplitude_pa=-1",
            "defaults.material.endurance_amplitude_pa = -1: must be > 0",
        ),
        (
            "discs[0].fatigue.stress_correction_factor=0.5",
            "discs[0].fatigue.stress_correction_factor = 0.5: must be in [1, 10]",
        ),
        (
            "defaults.material.miner_rule=\"basquin\"",
            "defaults.material.miner_rule = \"basquin\": must be one of",
        ),
    ] {
        let o = run(&["run", "--no-record", "--set", set]);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains(expect), "{set}: {err}");
        assert!(!err.contains("panicked"));
    }
}

/// The recording keeps the run's fatigue: replay prints it as run computed it, compare shows
/// the life and its change, and plot --spectrum draws the figure from the recording.
#[test]
fn recordings_carry_the_fatigue() {
    let dir = scratch("fatigue_recordings");
    let (a, sum, _) = run_with_outputs(&dir, "h0", None);
    let b = dir.join("h50.mcap");
    let o = run(&[
        "run",
        "--set",
        "defaults.oil.film_thickness_m=50e-6",
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&sum).unwrap()).unwrap();
    let life = s["fatigue"][0]["life_h"].as_f64().unwrap();
    let o = run(&["replay", a.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("fatigue of the spline teeth"), "{text}");
    assert!(text.contains(&format!("{life:.3e}")), "{life} in {text}");
    let o = run(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let rows: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(rows[0]["life_h"].as_f64(), Some(life));
    let longer = rows[1]["life_change_pct"].as_f64().unwrap();
    assert!(
        longer > 100.0,
        "50 um of film should more than double the life: {rows}"
    );
    let png = dir.join("spectrum.png");
    let o = run(&[
        "plot",
        a.to_str().unwrap(),
        "--spectrum",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

/// Issue 36, build item 4 ("A flat footprint"): what a run keeps does not grow with the
/// simulated time. pack-8-brake's nine plates come to rest on their flanks at about 0.16 s and
/// stay there, so their contacts close only at the end of the run; the fatigue collector held
/// every loaded sample of such a contact until then (its located peak goes in among them at
/// its time): 16 bytes per plate per sample at 10 kHz, 103 MB after 60 s simulated. Over
/// 1.5 s (each plate's open contact then spans some 13 000 samples, more than the bound) the
/// samples held in memory never exceed [`PENDING_IN_MEMORY`] per coupling, the older ones
/// waiting in the temporary file. Counts, not times or RSS: the bound is the run's whatever
/// its length.
#[test]
fn long_runs_keep_a_flat_memory() {
    use clutchpack_analysis::fatigue::{FatigueCollector, PENDING_IN_MEMORY};
    use clutchpack_model::{ImpactEvent, Observer, Sample};
    /// The collector, the most samples it held, and what it would hold if it held every
    /// loaded sample not yet claimed by an impact (per body: those since its last impact).
    struct Watch {
        collector: FatigueCollector,
        most_held: usize,
        unclaimed: Vec<usize>,
        most_unclaimed: usize,
    }
    impl Observer for Watch {
        fn sample(&mut self, s: &Sample) {
            self.collector.sample(s);
            self.most_held = self.most_held.max(self.collector.held_samples());
            for (u, d) in self.unclaimed.iter_mut().zip(&s.discs) {
                *u += usize::from(d.load_n != 0.0 && d.load_n.is_finite());
            }
            self.most_unclaimed = self.most_unclaimed.max(self.unclaimed.iter().sum());
        }
        fn impact(&mut self, e: &ImpactEvent) {
            self.collector.impact(e);
            self.unclaimed[e.disc] = 0;
        }
    }
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/pack-8-brake.toml");
    let scene = clutchpack_scene::load(&file, &[]).unwrap();
    let mut sim = clutchpack_sdk::Simulation::new(scene, None).unwrap();
    let bodies = sim.body_names().unwrap().len();
    let mut w = Watch {
        collector: FatigueCollector::new(),
        most_held: 0,
        unclaimed: vec![0; bodies],
        most_unclaimed: 0,
    };
    sim.engine_mut().unwrap().run(1.5, &mut w).unwrap();
    let bound = bodies * PENDING_IN_MEMORY;
    assert!(
        w.most_unclaimed > bound,
        "the run must outlast the bound: {} unclaimed samples at most",
        w.most_unclaimed
    );
    assert!(
        w.most_held <= bound,
        "samples held in memory: {} > {bound} ({bodies} bodies)",
        w.most_held
    );
    assert!(w.collector.spill_error().is_none());
    assert_eq!(
        w.collector.held_samples(),
        0,
        "the run's end claims them all"
    );
}
