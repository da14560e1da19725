//! Issue 33, part 4: the one co-simulation layer that the FMU and Python's `Simulation` share:
//! one name per input (older names as aliases), one bound check, and the pitfall of an input
//! a host leaves unconnected made visible.

use clutchpack_sdk::cosim::{driven_from_names, Causality, Input, Quantity, UNCONNECTED};
use clutchpack_sdk::{CoSimulation, Driven, Error};
use std::path::Path;

fn scene(name: &str) -> clutchpack_scene::Scene {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name);
    clutchpack_scene::load(&file, &[]).unwrap()
}

/// The network scene `s`'s whole run on `engine` (else the scene's choice), kept as `run`
/// keeps it by default.
fn whole_run(
    s: &clutchpack_scene::Scene,
    engine: Option<clutchpack_scene::EngineChoice>,
) -> clutchpack_sdk::NetworkOutcome {
    clutchpack_sdk::Simulation::new(s.clone(), engine)
        .unwrap()
        .run(Default::default())
        .unwrap()
        .into_network()
        .unwrap()
}

/// An FMU's table (every input driven) names each input by its public name, and each input's
/// description says that an unconnected input holds its start value.
#[test]
fn every_input_has_its_public_name_and_says_what_unconnected_means() {
    let co = CoSimulation::new(scene("pack-6-engagement.toml")).unwrap();
    let inputs: Vec<_> = co
        .variables()
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .collect();
    let names: Vec<&str> = inputs.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "shaft.speed_rad_s",
            "drum.load_torque_n_m",
            "piston.pressure_pa"
        ]
    );
    for v in inputs {
        let Quantity::Input(i) = v.quantity else {
            panic!("{}: an input", v.name)
        };
        assert_eq!((i.name(), v.unit), (v.name.as_str(), Some(i.unit())));
        assert!(v.description.contains(UNCONNECTED), "{}", v.description);
    }
}

/// Python's older drive names are aliases of the public ones: both find the same input, and
/// an input the run does not have is an error listing the ones it has.
#[test]
fn older_names_are_aliases_and_unknown_inputs_list_the_inputs() {
    let driven = driven_from_names(&["piston_pressure"]).unwrap();
    assert_eq!(driven, driven_from_names(&["piston.pressure_pa"]).unwrap());
    let co = CoSimulation::driving(scene("pack-6-engagement.toml"), driven).unwrap();
    let vr = co.input_named("piston.pressure_pa").unwrap();
    assert_eq!(co.input_named("piston_pressure").unwrap(), vr);
    let e = co.input_named("shaft.speed_rad_s").unwrap_err();
    assert!(matches!(e, Error::Call(_)), "{e:?}");
    let e = e.to_string();
    assert!(e.contains("its inputs: piston.pressure_pa"), "{e}");
    let e = driven_from_names(&["pressure"]).unwrap_err();
    assert!(e.is_bad_input(), "{e:?}");
    let e = e.to_string();
    assert!(e.contains("\"piston.pressure_pa\""), "{e}");
    // an input the pack lacks is refused at the start, naming the scene
    let mut drum = Driven::NONE;
    Input::DrumLoad.drive(&mut drum);
    let e = CoSimulation::driving(scene("hu-table2.toml"), drum)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("hu-table2") && e.contains("drum"), "{e}");
}

/// One bound check for a value and for a value held with its slope: the error names the input
/// by its public name and the scene key's bound, and the run does not move.
#[test]
fn inputs_are_checked_against_their_scene_keys_bounds_in_one_place() {
    let mut co = CoSimulation::driving(
        scene("hu-table2.toml"),
        driven_from_names(&["shaft_speed"]).unwrap(),
    )
    .unwrap();
    co.start(None).unwrap();
    let e = co.set_input("shaft_speed", 1e9, [None, None]).unwrap_err();
    assert!(
        matches!(e, Error::InputOutOfBound { value, .. } if value == 1e9),
        "{e:?}"
    );
    let e = e.to_string();
    assert!(e.starts_with("shaft.speed_rad_s = 1e9 rad/s"), "{e}");
    co.set_input("shaft.speed_rad_s", 200.0, [Some(1e9), None])
        .unwrap();
    let e = co.advance_to(1e-3, None).unwrap_err();
    assert!(matches!(e, Error::InputOutOfBound { .. }), "{e:?}");
    let e = e.to_string();
    assert!(
        e.contains("shaft.speed_rad_s") && e.contains("held with its derivatives"),
        "{e}"
    );
    assert_eq!(co.time_s(), 0.0);
}

/// The pitfall: an FMU drives every input, so a host that sets only the pressure holds the
/// shaft at its start speed (a constant 200 rad/s on pack-6-engagement), while Python's
/// `Simulation(drive=["piston.pressure_pa"])` keeps the scene's sine: the shaft's angles part
/// by the sine's integral (4.378 / (2 pi 104) (1 - cos(2 pi 104 t)), 6.7e-3 rad at a quarter
/// period).
#[test]
fn an_unconnected_fmu_input_holds_its_start_value_while_python_follows_the_scene() {
    let t = 0.25 / 104.0;
    let angle = |mut co: CoSimulation| {
        co.set_string_parameter(Quantity::Engine, "reference")
            .unwrap();
        co.start(None).unwrap();
        co.set_input("piston.pressure_pa", 0.0, [None, None])
            .unwrap();
        co.advance_to(t, None).unwrap();
        let out = co.outputs().unwrap();
        out.iter().find(|(n, _)| n == "shaft.angle_rad").unwrap().1
    };
    let fmu = angle(CoSimulation::new(scene("pack-6-engagement.toml")).unwrap());
    let python = angle(
        CoSimulation::driving(
            scene("pack-6-engagement.toml"),
            driven_from_names(&["piston.pressure_pa"]).unwrap(),
        )
        .unwrap(),
    );
    let w = 2.0 * std::f64::consts::PI * 104.0;
    assert!((fmu - 200.0 * t).abs() < 1e-9, "{fmu}");
    let sine = 200.0 * t + 4.378 / w * (1.0 - (w * t).cos());
    assert!((python - sine).abs() < 1e-6, "{python} against {sine}");
}

/// Issue 34: a network scene's co-simulation (the FMU's): its inputs are the engine's drive
/// and the two clutch forces by their public names (a dashed body name quoted as FMI's
/// structured names require), a negative force is refused and leaves the run usable, and a
/// state saved at 0.3 s and restored gives the same outputs at 0.6 s to the bit (the run is
/// deterministic, the state whole).
#[test]
fn a_network_co_simulation_names_its_inputs_and_rolls_back() {
    let mut co = CoSimulation::new(scene("dct-upshift-lumped.toml")).unwrap();
    let names: Vec<&str> = co
        .variables()
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .map(|v| v.name.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "bodies.crank.drive_torque_n_m",
            "couplings.K1.normal_force_n",
            "couplings.K2.normal_force_n"
        ]
    );
    assert!(co
        .variables()
        .iter()
        .any(|v| v.name == "bodies.'input-1'.speed_rad_s"));
    co.start(None).unwrap();
    co.set_input("couplings.K1.normal_force_n", 0.0, [None, None])
        .unwrap();
    let e = co
        .set_input("couplings.K2.normal_force_n", -1.0, [None, None])
        .unwrap_err()
        .to_string();
    assert!(e.contains("expected a value in [0, 100000000] N"), "{e}");
    co.set_input("couplings.K2.normal_force_n", 4500.0, [None, None])
        .unwrap();
    co.advance_to(0.3, None).unwrap();
    let saved = co.save().unwrap();
    co.advance_to(0.6, None).unwrap();
    let first = co.outputs().unwrap();
    co.restore(&saved).unwrap();
    assert_eq!(co.time_s(), 0.3);
    co.advance_to(0.6, None).unwrap();
    let again = co.outputs().unwrap();
    assert_eq!(first, again);
    // K1 released and K2 applied (4500 N) from t = 0: a shift at once, K2 locked by 0.6 s
    let get = |name: &str| first.iter().find(|(n, _)| n == name).unwrap().1;
    assert_eq!(get("couplings.K2.mode"), 0.0);
    let _ = co.finish();
    assert!(co.network_outcome().is_some());
}

/// A network scene's run advanced call by call ([`clutchpack_sdk::NetworkSimulation`]) runs on
/// the multibody engine too, at the whole run's fixed step: `dct-upshift-lumped` in calls of 1 ms,
/// nothing driven (its samples at 1 kHz end a step at every call already), gives the whole
/// run's summary but the wall time, figure for figure (steps, events, speeds, heats).
#[test]
fn a_network_simulation_runs_on_the_multibody_engine() {
    use clutchpack_scene::EngineChoice;
    let s = scene("dct-upshift-lumped.toml");
    let engine = Some(EngineChoice::Multibody);
    let whole = whole_run(&s, engine);
    let mut sim = clutchpack_sdk::NetworkSimulation::start(&s, engine, &[], None, None).unwrap();
    assert_eq!(sim.engine(), EngineChoice::Multibody);
    let calls = (s.simulation.duration_s / 1e-3).round() as u32;
    for k in 1..=calls {
        sim.advance_to(f64::from(k) * 1e-3, None).unwrap();
    }
    let mut called = sim.finish().unwrap().summary;
    called.wall_time_s = whole.summary.wall_time_s;
    assert_eq!(called, whole.summary);
}

/// A network run advanced call by call and recorded says so in its recording's provenance, as
/// a pack's co-simulated recording does: `co_simulation = true`, the inputs the caller drove
/// by name, no scene duration (the caller decided where it ended).
#[test]
fn a_co_simulated_network_recording_says_what_was_driven() {
    let dir = std::env::temp_dir().join(format!("clutchpack-netcosim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("driven.mcap");
    let request = clutchpack_sdk::RecordingRequest {
        path: path.clone(),
        replace: clutchpack_sdk::record::Replace::Existing,
        options: Default::default(),
        scene_path: None,
    };
    let drive = ["couplings.K2.normal_force_n".to_string()];
    let mut sim = clutchpack_sdk::NetworkSimulation::start(
        &scene("dct-upshift-lumped.toml"),
        None,
        &drive,
        Some(&request),
        None,
    )
    .unwrap();
    sim.set_input(&drive[0], 1000.0).unwrap();
    sim.advance_to(0.01, None).unwrap();
    sim.finish().unwrap();
    let reader = clutchpack_sdk::record::open(&path).unwrap();
    let params = reader.info().metadata("clutchpack.params").unwrap().clone();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        params.get("co_simulation").map(String::as_str),
        Some("true")
    );
    assert_eq!(
        params.get("driven_inputs").map(String::as_str),
        Some("couplings.K2.normal_force_n")
    );
    assert!(!params.contains_key("duration_s"), "{params:?}");
}

/// A network whose pack carries temperatures (`dct-upshift.toml` with K2 from
/// `dct-k2-thermal.toml`) outputs every body's and the oil's temperature of that pack, as a
/// thermal pack scene's co-simulation does, under the coupling's name
/// (`couplings.K2.plates[1].temperature_k`, K); advanced in one call, they equal the whole
/// run's final temperatures (measured: to the bit; asserted within 1e-9 K); K1 (isothermal)
/// has none. On both engines.
#[test]
fn a_thermal_pack_on_a_network_outputs_its_temperatures() {
    use clutchpack_scene::EngineChoice;
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        thermal_pack_outputs_on(engine);
    }
}

/// [`a_thermal_pack_on_a_network_outputs_its_temperatures`] on `engine`.
fn thermal_pack_outputs_on(engine: clutchpack_scene::EngineChoice) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/dct-upshift.toml");
    let set: clutchpack_scene::Override = "couplings[2].pack=dct-k2-thermal.toml".parse().unwrap();
    let s = clutchpack_scene::load(&file, &[set]).unwrap();
    let engine = Some(engine);
    let whole = whole_run(&s, engine);
    let k2 = whole
        .summary
        .couplings
        .iter()
        .find(|c| c.name == "K2")
        .unwrap();
    let thermal = k2.thermal.as_ref().unwrap();
    let mut sim = clutchpack_sdk::NetworkSimulation::start(&s, engine, &[], None, None).unwrap();
    let names: Vec<String> = sim.variables().into_iter().map(|v| v.name).collect();
    assert!(!names
        .iter()
        .any(|n| n.starts_with("couplings.K1.") && n.ends_with("temperature_k")));
    let temperatures: Vec<&String> = names
        .iter()
        .filter(|n| n.starts_with("couplings.K2.") && n.ends_with(".temperature_k"))
        .collect();
    assert_eq!(temperatures.len(), 5 + 6 + 1, "{names:?}");
    sim.advance_to(s.simulation.duration_s, None).unwrap();
    let out = sim.outputs();
    let get = |name: &str| out.iter().find(|(n, _)| n == name).unwrap().1;
    let mut worst = (get("couplings.K2.oil.temperature_k") - thermal.oil_final_k).abs();
    for (i, b) in thermal.bodies.iter().enumerate() {
        let name = if i < 5 {
            format!("couplings.K2.discs[{i}].temperature_k")
        } else {
            format!("couplings.K2.plates[{}].temperature_k", i - 5)
        };
        worst = worst.max((get(&name) - b.final_k).abs());
    }
    assert!(worst < 1e-9, "{engine:?}: {worst}");
    // the hottest plate has heated well above the oil's 353.15 K start
    assert!(get("couplings.K2.plates[1].temperature_k") > 370.0);
}

/// The multibody engine takes a resolved pack's piston pressure as a network input
/// (`couplings.<pack>.pressure_pa`): `dct-upshift.toml` driven from the pack files' own
/// schedules, held at each 1 ms interval's midpoint, gives the scene's shift on that engine:
/// K2 locked at the end and its heat within 1e-4 of the whole run's (measured 2026-11-27:
/// 1.1e-5), its lock within 1 ms (measured 3.0e-4 s: a lock is timed to the network step);
/// the output `couplings.K2.heat_j` at the end is the summary's.
#[test]
fn the_multibody_engine_drives_a_packs_pressure_by_name() {
    use clutchpack_scene::EngineChoice;
    let s = scene("dct-upshift.toml");
    let engine = Some(EngineChoice::Multibody);
    let whole = whole_run(&s, engine);
    let names = [
        "couplings.K1.pressure_pa".to_string(),
        "couplings.K2.pressure_pa".to_string(),
    ];
    let mut sim = clutchpack_sdk::NetworkSimulation::start(&s, engine, &names, None, None).unwrap();
    // the pack files' schedules (dct-k1.toml, dct-k2.toml)
    let ramp = |t: f64, pts: &[(f64, f64)]| {
        let i = pts.iter().rposition(|p| p.0 <= t).unwrap();
        match pts.get(i + 1) {
            Some(q) => pts[i].1 + (q.1 - pts[i].1) * (t - pts[i].0) / (q.0 - pts[i].0),
            None => pts[i].1,
        }
    };
    let k1 = [(0.0, 1.05e6), (0.2, 1.05e6), (0.35, 0.0)];
    let k2 = [
        (0.0, 0.0),
        (0.2, 0.0),
        (0.35, 0.45e6),
        (0.7, 0.45e6),
        (0.8, 1.05e6),
    ];
    for k in 1..=1000 {
        let mid = (f64::from(k) - 0.5) * 1e-3;
        sim.set_input(&names[0], ramp(mid, &k1)).unwrap();
        sim.set_input(&names[1], ramp(mid, &k2)).unwrap();
        sim.advance_to(f64::from(k) * 1e-3, None).unwrap();
    }
    // the heat output is the pack's faces' heat so far, as the summary's at the end
    let out = sim.outputs();
    let heat_out = out
        .iter()
        .find(|(n, _)| n == "couplings.K2.heat_j")
        .unwrap()
        .1;
    let driven = sim.finish().unwrap().summary;
    let k2_of = |s: &clutchpack_sdk::NetworkSummary| {
        s.couplings.iter().find(|c| c.name == "K2").unwrap().clone()
    };
    let (a, b) = (k2_of(&whole.summary), k2_of(&driven));
    assert!(
        (heat_out - b.heat_j).abs() <= 1e-9 * b.heat_j,
        "{heat_out} J against {b:?}"
    );
    let rel = (b.heat_j - a.heat_j).abs() / a.heat_j;
    assert!(
        rel <= 1e-4,
        "K2's heat {} J against {} J ({rel:.2e})",
        b.heat_j,
        a.heat_j
    );
    assert_eq!(b.lock_times_s.len(), a.lock_times_s.len(), "{b:?}");
    let dt = (b.lock_times_s[0] - a.lock_times_s[0]).abs();
    assert!(
        dt <= 1e-3,
        "K2 locks at {:?} against {:?}",
        b.lock_times_s,
        a.lock_times_s
    );
    eprintln!("K2 heat {rel:.2e} apart, lock {dt:.2e} s apart");
}

/// Issue 48, item 9: a network simulation's saved state restores only into the run that
/// saved it. A `dct-upshift.toml` run handed a state of a `dct-upshift-lumped.toml` run (or of
/// another run of its own scene) refuses it, naming both scenes, and goes on as it was: its
/// time, and a summary that still names its scene and its two resolved packs; its own state
/// restores. The co-simulation layer (the FMU's network path) refuses it too.
#[test]
fn network_restore_refuses_a_state_of_another_simulation() {
    use clutchpack_sdk::NetworkSimulation;
    let (packs, lumped) = (scene("dct-upshift.toml"), scene("dct-upshift-lumped.toml"));
    let mut other = NetworkSimulation::start(&lumped, None, &[], None, None).unwrap();
    other.advance_to(0.02, None).unwrap();
    let foreign = other.save().unwrap();
    let mut twin = NetworkSimulation::start(&packs, None, &[], None, None).unwrap();
    twin.advance_to(0.01, None).unwrap();
    let sibling = twin.save().unwrap();

    let mut sim = NetworkSimulation::start(&packs, None, &[], None, None).unwrap();
    sim.advance_to(0.01, None).unwrap();
    let own = sim.save().unwrap();
    sim.advance_to(0.015, None).unwrap();
    for (state, from) in [(&foreign, "dct-upshift-lumped"), (&sibling, "dct-upshift")] {
        let e = sim.restore(state).unwrap_err();
        assert!(e.is_bad_input(), "{e}");
        let text = e.to_string();
        let names = format!("scene {from:?}; this instance runs \"dct-upshift\"");
        assert!(
            text.contains("another run") && text.contains(&names),
            "{text}"
        );
        assert_eq!(sim.time_s(), 0.015);
    }
    sim.restore(&own).unwrap();
    assert_eq!(sim.time_s(), 0.01);
    sim.advance_to(0.02, None).unwrap();
    let summary = sim.finish().unwrap().summary;
    assert_eq!(summary.scene, "dct-upshift");
    let names: Vec<&str> = summary.couplings.iter().map(|c| c.name.as_str()).collect();
    assert!(names.contains(&"K1") && names.contains(&"K2"), "{names:?}");

    // the FMU's network path: a co-simulation of one scene refuses another's state
    let mut a = CoSimulation::new(lumped).unwrap();
    a.start(None).unwrap();
    a.advance_to(0.01, None).unwrap();
    let state = a.save().unwrap();
    let mut b = CoSimulation::new(packs).unwrap();
    b.start(None).unwrap();
    let e = b.restore(&state).unwrap_err();
    assert!(matches!(e, Error::Call(_)), "{e:?}");
    assert!(e.to_string().contains("another run"), "{e}");
}

/// Issue 48, item 11: an input named twice in `drive` (by one name, or by its name and its
/// older alias; a network's by its one name) is refused naming it, as an unknown one is.
#[test]
fn drive_naming_an_input_twice_is_refused() {
    for names in [
        ["piston.pressure_pa", "piston.pressure_pa"],
        ["piston_pressure", "piston.pressure_pa"],
    ] {
        let e = driven_from_names(&names).unwrap_err().to_string();
        assert!(
            e.contains("piston.pressure_pa is named twice"),
            "{names:?}: {e}"
        );
    }
    let k2 = "couplings.K2.normal_force_n".to_string();
    let e = clutchpack_sdk::NetworkSimulation::start(
        &scene("dct-upshift-lumped.toml"),
        None,
        &[k2.clone(), k2],
        None,
        None,
    )
    .err()
    .expect("refused");
    assert!(e.is_bad_input(), "{e}");
    assert!(
        e.to_string()
            .contains("\"couplings.K2.normal_force_n\" is named twice"),
        "{e}"
    );
}

/// The files in `dir`, by name, sorted.
fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Issue 48, item 12: a recorded run dropped without `finish` (a Python `Simulation`
/// collected, a script that ends) leaves its recording complete under its own name, as
/// `finish` would (the strict reader opens it, its summary attached), not as a `.partial-`
/// file: a network's run and a pack's session alike.
#[test]
fn a_recorded_run_dropped_without_finish_leaves_a_complete_recording() {
    let dir = tempfile::tempdir().unwrap();
    let request = |name: &str| clutchpack_sdk::RecordingRequest {
        path: dir.path().join(name),
        replace: clutchpack_sdk::record::Replace::Existing,
        options: Default::default(),
        scene_path: None,
    };
    let net = request("network.mcap");
    let mut sim = clutchpack_sdk::NetworkSimulation::start(
        &scene("dct-upshift-lumped.toml"),
        None,
        &[],
        Some(&net),
        None,
    )
    .unwrap();
    sim.advance_to(0.05, None).unwrap();
    drop(sim);
    let pack = request("pack.mcap");
    let s = clutchpack_sdk::Simulation::new(scene("hu-table2.toml"), None).unwrap();
    let mut session = s
        .start(clutchpack_sdk::SessionRequest {
            driven: Driven::NONE,
            stop_time_s: None,
            recording: Some(pack.clone()),
            keep_history: false,
        })
        .unwrap();
    session.advance_to(0.02, None).unwrap();
    drop(session);
    assert_eq!(files_in(dir.path()), ["network.mcap", "pack.mcap"]);
    let reader = clutchpack_sdk::record::open(&net.path).unwrap();
    let recorded = clutchpack_sdk::record::read_network(&reader)
        .unwrap()
        .unwrap();
    assert!(recorded.summary_json.is_some());
    let last = recorded.samples.last().unwrap().t_s;
    assert!((last - 0.05).abs() < 1e-9, "{last}");
    let reader = clutchpack_sdk::record::open(&pack.path).unwrap();
    assert!(reader.summary().is_some());
}

/// Issue 44, item 4: one co-simulation for Python's `Simulation` of either kind. A network's
/// caller drives the inputs it names ([`CoSimulation::driving_named`]), the others follow the
/// scene: driving K2's force alone, it is the one input; K1's force is refused as not driven,
/// a slope as a network input takes none, an unknown or twice-named input when the run is
/// made. Driving nothing, `dct-upshift-lumped` in calls of 10 ms (reference engine) gives the
/// whole run's summary but the wall time, figure for figure (before, the co-simulation drove
/// every input of a network, each held at its value at t = 0, and Python went around it).
#[test]
fn a_co_simulation_drives_the_network_inputs_it_names() {
    let s = scene("dct-upshift-lumped.toml");
    let k2 = "couplings.K2.normal_force_n";
    let mut co = CoSimulation::driving_named(s.clone(), &[k2]).unwrap();
    let inputs: Vec<&str> = co
        .variables()
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .map(|v| v.name.as_str())
        .collect();
    assert_eq!(inputs, [k2]);
    co.start(None).unwrap();
    let e = co
        .set_input("couplings.K1.normal_force_n", 0.0, [None, None])
        .unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("is not driven"),
        "{e}"
    );
    let e = co.set_input(k2, 10.0, [Some(1.0), None]).unwrap_err();
    assert!(e.to_string().contains("takes no slope"), "{e}");
    co.set_input(k2, 1000.0, [None, None]).unwrap();
    assert!(co.advance_to(0.01, None).unwrap());
    for (names, words) in [
        (vec!["couplings.K3.normal_force_n"], "is not an input of"),
        (vec![k2, k2], "is named twice"),
    ] {
        let e = CoSimulation::driving_named(s.clone(), &names)
            .err()
            .expect("refused");
        assert!(e.is_bad_input() && e.to_string().contains(words), "{e}");
    }

    let whole = whole_run(&s, None);
    let mut co = CoSimulation::driving_named(s.clone(), &[] as &[&str]).unwrap();
    co.start(None).unwrap();
    let calls = (s.simulation.duration_s / 1e-2).round() as u32;
    for k in 1..=calls {
        co.advance_to(f64::from(k) * 1e-2, None).unwrap();
    }
    let _ = co.finish();
    let mut called = co.network_outcome().unwrap().summary.clone();
    called.wall_time_s = whole.summary.wall_time_s;
    assert_eq!(called, whole.summary);
}
