//! The library face of a run: ensembles on the one free-play rule, a run's outcome, a stop.

use clutchpack_scene::Override;
use clutchpack_sdk::{ensemble_member, load_scene, RunRequest, Simulation};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn scene_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

/// Issue 22: `sweep --ensemble` placed discs by a rule of its own (the film's free play only);
/// a study's spread ensemble subtracted the spacing errors and the centre offset too. Now
/// both call the model's one rule: on the eccentric disc with spacing errors and its offset
/// raised to 150 um (where the old sweep rule put the outer members on a tooth), every sweep
/// member equals the study's member bit for bit, and every member passes the scene's own
/// start check (no tooth in contact at t = 0).
#[test]
fn sweep_members_are_the_study_members_and_none_starts_in_contact() {
    let file = scene_file("eccentric-disc.toml");
    let offset: Override = "discs[0].initial_offset_m=[150e-6, 0]".parse().unwrap();
    let scene = clutchpack_scene::load(&file, std::slice::from_ref(&offset)).unwrap();
    assert!(scene.pack.discs[0]
        .tooth_spacing_errors_m
        .iter()
        .any(|e| *e != 0.0));
    let count = 16u64;
    let study_text = format!(
        "[study]\nname = \"t\"\nscene = {:?}\nengine = \"multibody\"\n\n[ensemble]\nmembers = {count}\ninitial_positions = \"spread\"\n\n[set]\n\"discs[0].initial_offset_m\" = [150e-6, 0]\n",
        file.display().to_string()
    );
    let study = clutchpack_study::parse(&study_text, "t.toml", Path::new(".")).unwrap();
    assert_eq!(study.cases(), count);
    for k in 0..count {
        let from_study = study.scene(&study.case(k)).unwrap();
        let from_sweep = ensemble_member(&scene, k, count);
        let (a, b) = (
            from_sweep.pack.discs[0].initial_rel_angle_rad,
            from_study.pack.discs[0].initial_rel_angle_rad,
        );
        assert_eq!(
            a.to_bits(),
            b.to_bits(),
            "member {k}: sweep {a} rad, study {b} rad"
        );
        // the validator refuses a start with a tooth in contact
        let at: Override = format!("discs[0].initial_rel_angle_rad={a:e}")
            .parse()
            .unwrap();
        clutchpack_scene::load(&file, &[offset.clone(), at])
            .unwrap_or_else(|e| panic!("member {k} at {a} rad starts in contact: {e}"));
    }
}

/// A run through the library: the paper case's summary holds the figures `run` prints, the
/// fatigue of the one disc, and the engine's statistics.
#[test]
fn a_run_gives_its_summary() {
    let scene = load_scene(None, &[]).unwrap();
    let mut sim = Simulation::new(scene, None).unwrap();
    assert_eq!(sim.engine_name(), "reference");
    assert!(
        sim.engine_line().starts_with("engine: reference"),
        "{}",
        sim.engine_line()
    );
    let outcome = sim.run_pack(RunRequest::default()).unwrap();
    let s = outcome.summary().unwrap();
    assert_eq!(s.discs.len(), 1);
    assert_eq!(s.fatigue.len(), 1);
    assert!((s.duration_s - 0.3).abs() < 1e-12, "{}", s.duration_s);
    // the paper case's teeth rattle on both flanks: impacts, peaks of both signs
    assert!(s.discs[0].impacts > 10, "{:?}", s.discs[0]);
    assert!(s.discs[0].max_positive_n > 0.0 && s.discs[0].max_negative_n < 0.0);
    assert!(s.fatigue[0].lumped.damage_rate_per_h.is_finite());
}

/// A stop flag set before the run stops it at its first progress poll: the outcome says so
/// and still gives a (short) summary; an engine that cannot run the scene is bad input.
#[test]
fn a_stopped_run_and_a_refused_engine() {
    let stop = AtomicBool::new(true);
    let scene = load_scene(Some(&scene_file("pack-4-rattle.toml")), &[]).unwrap();
    let outcome = Simulation::new(scene, None)
        .unwrap()
        .run_pack(RunRequest {
            stop: Some(&stop),
            ..RunRequest::default()
        })
        .unwrap();
    assert!(outcome.stopped_early());
    let s = outcome.summary().unwrap();
    assert!(s.duration_s < 0.01, "stopped at {} s", s.duration_s);

    let eccentric = load_scene(Some(&scene_file("eccentric-disc.toml")), &[]).unwrap();
    let e = Simulation::new(eccentric, Some(clutchpack_sdk::EngineChoice::Reference))
        .err()
        .expect("the reference engine cannot run an eccentric disc");
    assert!(e.is_bad_input(), "{e}");
    assert!(e.to_string().contains("initial_offset_m"), "{e}");
}

/// Issue 35: a thermal run's recording carries every body's and the oil's temperature from
/// t = 0 to the end, window by window, ending at the run's reported final temperatures, and
/// colours the bodies in 3D; an isothermal recording has none of these topics.
#[test]
fn a_thermal_recording_carries_every_temperature() {
    let dir = std::env::temp_dir().join(format!("clutchpack-sdk-thermal-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let record = |scene: &str, out: &str| {
        let scene = load_scene(
            Some(&scene_file(scene)),
            &["simulation.duration_s=0.05".parse().unwrap()],
        )
        .unwrap();
        let mut sim = Simulation::new(scene, None).unwrap();
        let path = dir.join(out);
        let outcome = sim
            .run_pack(RunRequest {
                recording: Some(clutchpack_sdk::RecordingRequest {
                    path: path.clone(),
                    replace: clutchpack_record::Replace::Existing,
                    options: Default::default(),
                    scene_path: None,
                }),
                ..Default::default()
            })
            .unwrap();
        let stats = outcome.result.clone().unwrap();
        outcome.recording.unwrap().unwrap();
        let rec = clutchpack_record::open_complete(&path).unwrap();
        (stats, rec)
    };
    let (stats, rec) = record("pack-6-thermal.toml", "thermal.mcap");
    let report = stats.thermal.expect("a thermal report");
    let temps = rec.temperatures();
    let bodies = report.final_k.len();
    assert_eq!(temps.len(), bodies + 1, "every body and the oil");
    let windows = report.windows as usize;
    for (i, series) in temps.iter().enumerate() {
        // t = 0, then one point per window
        assert_eq!(series.len(), windows + 1, "body {i}");
        assert_eq!(series[0].t_s, 0.0);
        assert!(series.windows(2).all(|w| w[0].t_s < w[1].t_s), "body {i}");
        assert!(
            (series[windows].t_s - 0.05).abs() < 1e-9,
            "{}",
            series[windows].t_s
        );
        let last = series[windows].temperature_k;
        let want = if i < bodies {
            report.final_k[i]
        } else {
            report.oil_final_k
        };
        assert_eq!(last, want, "body {i}");
    }
    let has = |r: &clutchpack_record::RecordingReader, topic: &str| {
        r.info().topic(topic).is_some_and(|t| t.messages > 0)
    };
    assert!(has(&rec, "/scene/temperatures"));
    assert!(has(&rec, "/oil/temperature"));
    let (_, iso) = record("pack-6-engagement.toml", "iso.mcap");
    assert!(iso.temperatures().is_empty());
    assert!(!has(&iso, "/scene/temperatures"));
    std::fs::remove_dir_all(&dir).ok();
}

/// `run --windows`: the windows tile the run, their impacts add up to the run's, the largest
/// window peak is the run's largest, and their damages (rate times length) add up to the
/// run's (measured: exactly; a rainflow count per window had lost 9 %); a thermal run's
/// windows carry the oil's temperature, which rises while the gaps' drag heats it, and the
/// last is the run's final.
#[test]
fn windows_tile_the_run_and_add_up_to_it() {
    let run = |scene: Option<PathBuf>, sets: &[&str], w: f64| {
        let sets: Vec<Override> = sets.iter().map(|s| s.parse().unwrap()).collect();
        let scene = load_scene(scene.as_deref(), &sets).unwrap();
        let mut sim = Simulation::new(scene, None).unwrap();
        let outcome = sim
            .run_pack(RunRequest {
                windows_s: Some(w),
                ..Default::default()
            })
            .unwrap();
        outcome.summary().unwrap()
    };
    let s = run(None, &[], 0.1);
    assert_eq!(s.windows.len(), 3);
    let mut t = 0.0;
    for w in &s.windows {
        assert!((w.t0_s - t).abs() < 1e-12 && w.t1_s > w.t0_s, "{w:?}");
        assert!(w.oil_k.is_none());
        t = w.t1_s;
    }
    assert!((t - s.duration_s).abs() < 1e-12);
    let impacts: usize = s.windows.iter().map(|w| w.impacts).sum();
    assert_eq!(impacts, s.discs[0].impacts);
    let peak = s.windows.iter().map(|w| w.peak_abs_n).fold(0.0, f64::max);
    let d = &s.discs[0];
    assert_eq!(peak, d.max_positive_n.max(-d.max_negative_n));
    let damage: f64 = s
        .windows
        .iter()
        .map(|w| w.damage_rate_per_h * (w.t1_s - w.t0_s) / 3600.0)
        .sum();
    let whole = s.fatigue[0].lumped.damage;
    let rel = (damage - whole).abs() / whole;
    eprintln!("windows' damage {damage:e} against the run's {whole:e}: {rel:e}");
    assert!(rel < 1e-12, "{rel}");
    let th = run(
        Some(scene_file("pack-8-idle-thermal.toml")),
        &["simulation.duration_s=0.2"],
        0.1,
    );
    let oil: Vec<f64> = th.windows.iter().map(|w| w.oil_k.unwrap()).collect();
    assert_eq!(oil.len(), 2);
    assert!(oil[0] > 313.15 && oil[1] > oil[0], "{oil:?}");
    assert_eq!(oil[1], th.thermal.unwrap().oil_final_k);
    // a window length that is not a positive number of seconds, or more than 1e5 windows
    // (0.3 s / 1e-9 s), is bad input before any work
    let mut sim = Simulation::new(load_scene(None, &[]).unwrap(), None).unwrap();
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-9] {
        let Err(e) = sim.run(RunRequest {
            windows_s: Some(bad),
            ..Default::default()
        }) else {
            panic!("windows of {bad} s ran");
        };
        assert!(
            e.is_bad_input() && e.to_string().contains("--windows"),
            "{e}"
        );
    }
}

/// Issue 44 item 4: one `Simulation` for every scene. A network scene (`coupled-clutches`)
/// is built and run by `Simulation::run` as a pack scene is; its summary, either kind's
/// `Summary`, serialises to the network summary's own JSON byte for byte (untagged: the
/// `--summary-json` of a network is what it was). What takes packs only refuses it before
/// any work with one message naming the scene and what takes a network (`run_pack`, the
/// engine, the bodies, a session), and a pack is refused where a network is expected.
#[test]
fn one_simulation_runs_a_network_and_pack_only_calls_refuse_it() {
    let short: Override = "simulation.duration_s=0.05".parse().unwrap();
    let net = load_scene(Some(&scene_file("coupled-clutches.toml")), &[short]).unwrap();
    let mut sim = Simulation::new(net, None).unwrap();
    assert!(sim.is_network());
    assert_eq!(sim.engine_name(), "reference");
    assert!(
        sim.engine_line()
            .contains("network of 4 bodies and 3 couplings), the default for a driveline network"),
        "{}",
        sim.engine_line()
    );
    let outcome = sim.run(RunRequest::default()).unwrap();
    assert_eq!(
        (outcome.scene(), outcome.engine()),
        ("coupled-clutches", "reference")
    );
    let summary = outcome.summary().unwrap();
    let network = outcome.into_network().unwrap();
    assert!((network.summary.simulated_s - 0.05).abs() < 1e-12);
    assert_eq!(
        serde_json::to_string_pretty(&summary).unwrap(),
        serde_json::to_string_pretty(&network.summary).unwrap()
    );
    sim.network_only().unwrap();
    let refusals = [
        sim.pack_only().err(),
        sim.body_names().err(),
        sim.engine_mut().err(),
        sim.run_pack(RunRequest::default()).err(),
        sim.start(Default::default()).err(),
    ];
    for e in refusals {
        let e = e.expect("a pack-only call refuses a network");
        assert!(e.is_bad_input(), "{e}");
        let text = e.to_string();
        assert!(
            text.starts_with("coupled-clutches is a network scene ([[bodies]])")
                && text.contains("sweeps and studies take pack scenes only"),
            "{text}"
        );
    }

    let mut pack = Simulation::new(load_scene(None, &[]).unwrap(), None).unwrap();
    assert!(!pack.is_network());
    let e = pack.network_only().unwrap_err();
    assert!(e.is_bad_input(), "{e}");
    assert!(
        e.to_string().contains("is a pack scene, not a network"),
        "{e}"
    );
    let stop = AtomicBool::new(true);
    let outcome = pack
        .run(RunRequest {
            stop: Some(&stop),
            ..RunRequest::default()
        })
        .unwrap();
    let summary = outcome.summary().unwrap();
    let run = outcome.into_pack().unwrap();
    assert_eq!(
        serde_json::to_string_pretty(&summary).unwrap(),
        serde_json::to_string_pretty(&run.summary().unwrap()).unwrap()
    );
}

/// One observer, one meaning of `progress` (`true` stops; a network's was `false` stops until
/// issue 44 folded its observer into the pack's): a stop flag set before a network run stops
/// it at its first poll on both engines, and an unset flag lets it run to its end. Bounds: the
/// DCT upshift runs 0.05 s here; stopped, it stands at most one record interval and a step
/// in (the reference engine's first step, the multibody engine's 0.1 ms steps), far below
/// 0.01 s; run whole it reaches 0.05 s to 1e-9 s.
#[test]
fn a_stop_flag_stops_a_network_run_and_an_unset_one_does_not() {
    let set: [Override; 1] = ["simulation.duration_s=0.05".parse().unwrap()];
    let scene = load_scene(Some(&scene_file("dct-upshift.toml")), &set).unwrap();
    for engine in [
        clutchpack_sdk::EngineChoice::Reference,
        clutchpack_sdk::EngineChoice::Multibody,
    ] {
        for stop_now in [true, false] {
            let stop = AtomicBool::new(stop_now);
            let out = Simulation::new(scene.clone(), Some(engine))
                .unwrap()
                .run(RunRequest {
                    stop: Some(&stop),
                    ..RunRequest::default()
                })
                .unwrap()
                .into_network()
                .unwrap();
            let s = &out.summary;
            assert_eq!(s.stopped, stop_now, "{engine:?}");
            if stop_now {
                assert!(s.simulated_s < 0.01, "{engine:?}: {} s", s.simulated_s);
            } else {
                assert!(
                    (s.simulated_s - 0.05).abs() < 1e-9,
                    "{engine:?}: {}",
                    s.simulated_s
                );
            }
        }
    }
}
