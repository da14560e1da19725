//! A network body with a prescribed speed equals the pack scene it replaces (issue 44, item 1
//! and its must-show): `scenes/pack-8-brake.toml` (an open brake, its shaft prescribed by the
//! paper's drive, its plates on the housing) against the network of a prescribed shaft with
//! the scene's drive, the fixed housing and the scene's pack as a resolved pack element
//! between them (`cases::pack_as_network`), run through each engine's network stepper, impact
//! by impact.

use super::common::{apart, impacts, Impact};
use super::{run, scratch, stderr};
use clutchpack_model::network::NetworkRun;
use clutchpack_model::{ImpactEvent, Observer};
use std::collections::BTreeMap;
use std::path::Path;

/// The pack impacts of a network run, by body name (the pack's discs', then its plates'),
/// rounded as `--impacts-csv` writes them (times to 1e-9 s, peaks to 1e-4 N), so that they
/// compare with a pack run's CSV to the digit.
struct PackImpacts {
    names: Vec<String>,
    impacts: BTreeMap<String, Vec<Impact>>,
}

impl Observer for PackImpacts {
    fn pack_impact(&mut self, _coupling: usize, e: &ImpactEvent) {
        self.impacts
            .entry(self.names[e.disc].clone())
            .or_default()
            .push(Impact {
                t_on_s: format!("{:.9}", e.t_on_s).parse().unwrap(),
                t_off_s: format!("{:.9}", e.t_off_s).parse().unwrap(),
                peak_n: format!("{:.4}", e.peak_n).parse().unwrap(),
            });
    }
}

/// Runs `scenes/pack-8-brake.toml` as a network on `engine` (the sdk's settings of a network
/// scene: the reference engine at the scene's tolerance and longest step, the multibody
/// engine at its step, at most 1e-4 s): its pack impacts and the run.
fn as_network(engine: &str) -> (BTreeMap<String, Vec<Impact>>, NetworkRun) {
    let scene = clutchpack_scene::load(Path::new("scenes/pack-8-brake.toml"), &[]).unwrap();
    let net = clutchpack_model::cases::pack_as_network(&scene.pack).expect("a prescribed shaft");
    assert!(net.bodies[0].prescribed().is_some() && net.bodies[1].is_fixed());
    let sim = &scene.simulation;
    let mut obs = PackImpacts {
        names: (scene.pack.discs.iter().chain(&scene.pack.plates))
            .map(|d| d.name.clone())
            .collect(),
        impacts: BTreeMap::new(),
    };
    let run = if engine == "reference" {
        let options = clutchpack_reference::network::NetworkOptions {
            tolerance: sim.tolerance,
            max_step_s: sim.max_step_s,
            record_rate_hz: sim.record_rate_hz,
        };
        clutchpack_reference::network::run_network(&net, sim.duration_s, &options, &mut obs)
    } else {
        let options = clutchpack_multibody::network::NetworkStepOptions {
            step_s: sim.max_step_s.min(1e-4),
            record_rate_hz: sim.record_rate_hz,
        };
        clutchpack_multibody::network::run_network(&net, sim.duration_s, &options, &mut obs)
    }
    .unwrap();
    (obs.impacts, run)
}

/// The pack scene's own impacts on `engine` (`clutchpack run --impacts-csv`).
fn as_pack(engine: &str, dir: &Path) -> BTreeMap<String, Vec<Impact>> {
    let csv = dir.join(format!("{engine}.csv"));
    let o = run(&[
        "run",
        "scenes/pack-8-brake.toml",
        "--engine",
        engine,
        "--no-record",
        "--impacts-csv",
        csv.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    impacts(&csv)
}

/// Measured 2026-12-07 (0.3 s, the scene's settings):
/// - the multibody engine: the network's pack is the pack scene's session (its shaft
///   prescribed by the same profile, the plates on the housing, nothing set between the
///   network's steps): all 1945 impacts equal to the CSV's digit; the balance 3.6e-12 J of
///   14.3 kJ the prescribed shaft put in (its work the session's drive work to 3e-13 J).
///   Asserted: equal, and 1e-6 J.
/// - the reference engine: the network integrates the pack with the network's state in one
///   DOPRI5 (the pack scene runs its open pack's multirate scheme), so the rattle's chaos
///   parts them slowly: over the first 10 ms 51 impacts one by one, onsets within 2.2e-8 s and
///   peaks within 2.8e-4; 30 ms: 162, 5.9e-7 s, 3.7e-3; 0.1 s: 669, 8.7e-5 s, 5.2e-2, every
///   body's count the same; over the whole run 1946 impacts each, two bodies one apart (the
///   pairing then slides). The balance 1.7e-6 J; the prescribed work within 1.3e-3 of the
///   multibody engine's. Asserted (about 3x): 30 ms onsets 2e-6 s and peaks 1e-2; 0.1 s
///   counts equal, onsets 3e-4 s, peaks 0.15; whole run total within 0.5 % and every body
///   within 2; balance 2e-5 J; work 5e-3.
#[test]
fn a_network_body_with_a_prescribed_speed_equals_the_pack_scene_it_replaces() {
    let d = scratch("prescribed-pack");
    let count = |m: &BTreeMap<String, Vec<Impact>>| m.values().map(Vec::len).sum::<usize>();
    let mut work = Vec::new();
    for engine in ["multibody", "reference"] {
        let pack = as_pack(engine, &d);
        let (net, run) = as_network(engine);
        let e = run.energy;
        eprintln!(
            "{engine}: {} impacts as a pack, {} as a network; prescribed work {} J, residual {} J",
            count(&pack),
            count(&net),
            e.prescribed_work_j,
            e.residual_j()
        );
        for until in [0.01, 0.03, 0.1, 0.31] {
            eprintln!("  before {until} s: {:?}", apart(&pack, &net, until));
        }
        work.push(e.prescribed_work_j);
        if engine == "multibody" {
            assert_eq!(pack, net, "the multibody engine's impacts");
            assert!(e.residual_j().abs() <= 1e-6, "{}", e.residual_j());
            continue;
        }
        let early = apart(&pack, &net, 0.03);
        assert!(
            early.counts.is_empty() && early.compared >= 150,
            "{early:?}"
        );
        assert!(early.onset_s <= 2e-6 && early.peak <= 1e-2, "{early:?}");
        let mid = apart(&pack, &net, 0.1);
        assert!(mid.counts.is_empty() && mid.compared >= 600, "{mid:?}");
        assert!(mid.onset_s <= 3e-4 && mid.peak <= 0.15, "{mid:?}");
        let all = apart(&pack, &net, 1.0);
        let (a, b) = (count(&pack) as f64, count(&net) as f64);
        assert!((a - b).abs() <= 5e-3 * a, "{a} impacts against {b}");
        assert!(
            all.counts.iter().all(|(_, x, y)| x.abs_diff(*y) <= 2),
            "{:?}",
            all.counts
        );
        assert!(e.residual_j().abs() <= 2e-5, "{}", e.residual_j());
    }
    assert!(
        (work[0] - work[1]).abs() <= 5e-3 * work[0],
        "prescribed work {work:?}"
    );
}

/// `scenes/pack-8-brake.toml` written as a network scene: its settings, the shaft a body at
/// the scene's prescribed speed (`[bodies.speed]`, its `[drive]`), the fixed housing, and the
/// pack file itself as the one resolved pack between them. Returns its path in `dir`.
fn network_scene(dir: &Path) -> std::path::PathBuf {
    let pack = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/pack-8-brake.toml");
    let text = format!(
        r#"
name = "pack-8-brake"
[simulation]
duration_s = 0.3
engine = "multibody"
record_rate_hz = 10000.0
max_step_s = 1e-4
[[bodies]]
name = "shaft"
[bodies.speed]
kind = "sine"
omega0_rad_s = 200.0
amplitude_rad_s = 4.378
frequency_hz = 104.0
[[bodies]]
name = "housing"
fixed = true
[[couplings]]
name = "brake"
kind = "pack"
a = "shaft"
b = "housing"
pack = {pack:?}
"#
    );
    let path = dir.join("network.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A network whose only element is one resolved pack between a prescribed shaft and the
/// housing is that pack's scene (`Network::one_pack`; docs/DECISIONS.md, "A one-pack network
/// is a pack scene"): `scenes/pack-8-brake.toml` written as such a network gives the pack
/// scene's impacts CSV byte for byte, its summary JSON (wall time aside) and its printed
/// tables (the wall time's line aside), on both engines.
#[test]
fn a_one_pack_network_runs_the_pack_session_bit_for_bit() {
    let d = scratch("one-pack-network");
    let net = network_scene(&d);
    let wall = |v: &mut serde_json::Value| {
        v.as_object_mut().unwrap().remove("wall_time_s");
    };
    for engine in ["multibody", "reference"] {
        let mut outputs = Vec::new();
        for (what, scene) in [
            ("pack", "scenes/pack-8-brake.toml"),
            ("net", net.to_str().unwrap()),
        ] {
            let (json, csv) = (
                d.join(format!("{what}-{engine}.json")),
                d.join(format!("{what}-{engine}.csv")),
            );
            let o = run(&[
                "run",
                scene,
                "--engine",
                engine,
                "--no-record",
                "--summary-json",
                json.to_str().unwrap(),
                "--impacts-csv",
                csv.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
            let mut summary = super::read_json(&json);
            wall(&mut summary);
            let text: Vec<String> = super::stdout(&o)
                .lines()
                .filter(|l| !l.contains(" s wall"))
                .map(String::from)
                .collect();
            outputs.push((std::fs::read(&csv).unwrap(), summary, text));
        }
        assert!(outputs[0].0 == outputs[1].0, "{engine}: the impacts CSV");
        assert_eq!(outputs[0].1, outputs[1].1, "{engine}: the summary");
        assert_eq!(outputs[0].2, outputs[1].2, "{engine}: the printed tables");
    }
}

/// `cases::prescribed_clutch` as a scene file: the motor's speed from `w.csv` (20 rad/s at
/// t = 0 to 40 rad/s at 1 s), the load of 0.5 kg m^2, the clutch of 30 N m.
pub(super) const MOTOR: &str = include_str!("data/motor-clutch.toml");

/// `clutchpack run` of a network with a prescribed body (`[bodies.speed]` from a speed table,
/// `cases::prescribed_clutch` as a scene file) on both engines: the summary's energy names the
/// prescribed work (474 J by the closed form, `prescribed_work_j`), the balance closes, the
/// clutch locks at 0.5 s and the printed balance names the prescribed bodies. Measured
/// 2026-12-07: the work within 1.2e-11 J (reference) and 4.4e-11 J (multibody), the balances
/// 3.3e-11 and 1.7e-11 J, the lock at 0.5 s to 1e-13 s; asserted 1e-9 J, 1e-9 J and 1e-9 s.
#[test]
fn a_prescribed_network_scene_runs_and_counts_its_work() {
    let d = scratch("prescribed-motor");
    std::fs::write(d.join("w.csv"), "time_s,speed_rad_s\n0,20\n1,40\n").unwrap();
    let scene = d.join("motor.toml");
    std::fs::write(&scene, MOTOR).unwrap();
    for engine in ["reference", "multibody"] {
        let json = d.join(format!("{engine}.json"));
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
        assert!(
            super::stdout(&o).contains("prescribed bodies 474.000000 J"),
            "{}",
            super::stdout(&o)
        );
        let s = super::read_json(&json);
        let work = s["energy"]["prescribed_work_j"].as_f64().unwrap();
        let residual = s["energy"]["residual_j"].as_f64().unwrap();
        let lock = s["couplings"][0]["lock_times_s"][0].as_f64().unwrap();
        assert!((work - 474.0).abs() <= 1e-9, "{engine}: {work} J");
        assert!(residual.abs() <= 1e-9, "{engine}: residual {residual} J");
        assert!((lock - 0.5).abs() <= 1e-9, "{engine}: locks at {lock} s");
    }
}

/// A prescribed body's reaction is a co-simulation output (the FMU's and Python's
/// `Simulation`'s table), named `bodies.<body>.reaction_torque_n_m`, on a prescribed body only:
/// the motor holds the slipping clutch's 30 N m, then the locked load's `J A` = 10 N m
/// (measured: exact to the printed digit on the reference engine, the co-simulation's
/// default; asserted within 1e-9 N m). The motor's speed is not driven (its speed table
/// runs; an FMU, driving every input, would hold its speed at the start value unconnected).
#[test]
fn a_prescribed_bodys_reaction_is_a_co_simulation_output() {
    let d = scratch("prescribed-cosim");
    std::fs::write(d.join("w.csv"), "time_s,speed_rad_s\n0,20\n1,40\n").unwrap();
    let path = d.join("motor.toml");
    std::fs::write(&path, MOTOR).unwrap();
    let scene = clutchpack_scene::load(&path, &[]).unwrap();
    let mut co =
        clutchpack_sdk::CoSimulation::driving_named(scene, &["couplings.clutch.normal_force_n"])
            .unwrap();
    let names: Vec<String> = co.variables().iter().map(|v| v.name.clone()).collect();
    assert!(
        names
            .iter()
            .any(|n| n == "bodies.motor.reaction_torque_n_m"),
        "{names:?}"
    );
    assert!(!names.iter().any(|n| n == "bodies.load.reaction_torque_n_m"));
    co.start(None).unwrap();
    let reaction = |co: &clutchpack_sdk::CoSimulation| {
        let out = co.outputs().unwrap();
        out.iter()
            .find(|(n, _)| n == "bodies.motor.reaction_torque_n_m")
            .unwrap()
            .1
    };
    co.advance_to(0.25, None).unwrap();
    let slipping = reaction(&co);
    co.advance_to(0.7, None).unwrap();
    let locked = reaction(&co);
    eprintln!("reaction {slipping} N m slipping, {locked} N m locked");
    assert!((slipping - 30.0).abs() <= 1e-9, "{slipping}");
    assert!((locked - 10.0).abs() <= 1e-9, "{locked}");
    let _ = co.finish();
}
