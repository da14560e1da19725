//! Steppable engines (issue 23): a session advanced in 1, 3 and 1,000 calls is the whole run
//! (a thermal run's temperatures too, issue 35); a saved state restored gives the same outputs
//! again.

use clutchpack_model::session::{Advance, Driven};
use clutchpack_model::{Collector, Engine};
use clutchpack_scene::{EngineChoice, Override};
use clutchpack_sdk::{SessionRequest, Simulation};
use std::path::Path;

fn simulation(file: &str, engine: EngineChoice, duration_s: f64) -> Simulation {
    let o: Vec<Override> = vec![format!("simulation.duration_s={duration_s}")
        .parse()
        .unwrap()];
    let scene =
        clutchpack_scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file), &o).unwrap();
    Simulation::new(scene, Some(engine)).unwrap()
}

/// The whole run of the multibody engine and the same run as a session advanced in `calls` equal
/// calls: everything they send, in order.
fn whole_and_split(sim: &mut Simulation, duration: f64, calls: usize) -> (Collector, Collector) {
    let mut whole = Collector::default();
    sim.engine_mut().unwrap().run(duration, &mut whole).unwrap();
    let mut split = Collector::default();
    let reference = sim.engine_name() == "reference";
    let mut s = sim.engine_mut().unwrap().start(Driven::NONE).unwrap();
    s.set_stop_time(duration);
    for k in 1..=calls {
        let t = if k == calls {
            duration
        } else {
            duration * k as f64 / calls as f64
        };
        assert_eq!(s.advance_to(t, &mut split).unwrap(), Advance::Reached);
        // the reference engine stands at t (its dense output); the multibody engine's world
        // step may end past it (module docs of crates/multibody/src/engine/session.rs)
        let now = s.time_s();
        if reference {
            assert_eq!(now, t);
        } else {
            assert!(now >= t, "{now} < {t}");
        }
        // nothing after the session's time has been sent
        assert!(split.samples.last().is_none_or(|x| x.t_s <= now));
        assert!(split.impacts.iter().all(|e| e.t_off_s <= now));
    }
    s.finish(&mut split);
    (whole, split)
}

/// Identical, not merely close: the session's steps are the run's (they never end at a call).
fn assert_identical(file: &str, engine: EngineChoice, duration: f64) {
    let mut sim = simulation(file, engine, duration);
    for calls in [1, 3, 1000] {
        let (whole, split) = whole_and_split(&mut sim, duration, calls);
        assert!(
            whole.impacts.len() > 3,
            "{file}: {} impacts",
            whole.impacts.len()
        );
        assert_eq!(
            whole.impacts, split.impacts,
            "{file} {engine:?} in {calls} calls"
        );
        assert_eq!(
            whole.samples, split.samples,
            "{file} {engine:?} in {calls} calls"
        );
        assert_eq!(whole.interfaces, split.interfaces, "{file} {engine:?}");
        // a thermal run's temperatures at t = 0, each window's end and the run's end
        assert_eq!(
            whole.temperatures, split.temperatures,
            "{file} {engine:?} in {calls} calls"
        );
        assert_eq!(
            whole.contacts, split.contacts,
            "{file} {engine:?} in {calls} calls"
        );
    }
}

#[test]
fn reference_sessions_in_any_number_of_calls_are_the_run() {
    // monolithic (a whole pack), independent discs (prescribed shafts), the open pack's
    // windows (a call inside a window: the state there from a rerun of its last pass)
    for file in [
        "scenes/hu-table2.toml",
        "scenes/pack-4-rattle.toml",
        "scenes/pack-6-engagement.toml",
        "scenes/staggered-8-disc.toml",
        "scenes/pack-8-brake.toml",
        "scenes/pack-6-thermal.toml",
    ] {
        assert_identical(file, EngineChoice::Reference, 0.1);
    }
}

#[test]
fn multibody_sessions_in_any_number_of_calls_are_the_run() {
    // the multirate scheme (prescribed shafts, the open brake) and the shared step (the
    // engaging clutch's clamped stack)
    for file in [
        "scenes/hu-table2.toml",
        "scenes/pack-4-rattle.toml",
        "scenes/pack-6-engagement.toml",
        "scenes/staggered-8-disc.toml",
        "scenes/pack-8-brake.toml",
        "scenes/pack-6-thermal.toml",
    ] {
        assert_identical(file, EngineChoice::Multibody, 0.05);
    }
}

#[test]
fn reference_session_on_an_inertial_shaft_is_the_run() {
    // the coupled scheme (the shaft integrated with the discs in contact)
    let o: Vec<Override> = [
        "simulation.duration_s=0.1",
        "shaft.mode=\"inertial\"",
        "shaft.inertia_kg_m2=0.5",
    ]
    .iter()
    .map(|s| s.parse().unwrap())
    .collect();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/pack-4-rattle.toml");
    let scene = clutchpack_scene::load(&file, &o).unwrap();
    let mut sim = Simulation::new(scene, Some(EngineChoice::Reference)).unwrap();
    for calls in [1, 3, 1000] {
        let (whole, split) = whole_and_split(&mut sim, 0.1, calls);
        assert!(whole.impacts.len() > 3);
        assert_eq!(whole.impacts, split.impacts, "in {calls} calls");
        assert_eq!(whole.samples, split.samples, "in {calls} calls");
    }
}

/// Save at 40 ms, run to 100 ms, restore, run to 100 ms again: the same impacts and snapshot.
#[test]
fn a_restored_state_gives_the_same_outputs() {
    for (file, engine) in [
        ("scenes/pack-4-rattle.toml", EngineChoice::Reference),
        ("scenes/pack-6-engagement.toml", EngineChoice::Reference),
        ("scenes/pack-4-rattle.toml", EngineChoice::Multibody),
        ("scenes/pack-6-engagement.toml", EngineChoice::Multibody),
    ] {
        let sim = simulation(file, engine, 0.1);
        let driven = Driven::all_for(&sim.scene().pack);
        let mut s = sim
            .start(SessionRequest {
                driven,
                keep_history: true,
                ..SessionRequest::default()
            })
            .unwrap();
        let mut t = 0.0;
        while t < 0.04 - 1e-12 {
            t += 1e-4;
            s.advance_to(t, None).unwrap();
        }
        let saved = s.save().unwrap();
        let impacts_at_save = s_impacts(&s);
        let run_on = |s: &mut clutchpack_sdk::Session| {
            let mut t = s.time_s();
            while t < 0.1 - 1e-12 {
                t += 1e-4;
                s.advance_to(t, None).unwrap();
            }
            (s.snapshot(), s.max_loads_n(), s_impacts(s))
        };
        let first = run_on(&mut s);
        s.restore(&saved).unwrap();
        assert_eq!(s_impacts(&s), impacts_at_save);
        let second = run_on(&mut s);
        assert!(first.2 > impacts_at_save, "{file}: impacts after the save");
        assert_eq!(first, second, "{file}");
    }
}

fn s_impacts(s: &clutchpack_sdk::Session) -> usize {
    s.impact_count()
}

/// A prescribed shaft driven by the paper's sine sampled and held at 1e-5 s steps gives the
/// impacts of the run of the same held speed as a table (`drive.interpolation = "hold"`):
/// identical, since both end a step at every row and set the row's value there.
#[test]
fn a_driven_shaft_is_the_run_of_the_same_held_table() {
    use clutchpack_model::session::Inputs;
    use clutchpack_model::{Shaft, SpeedProfile, Table};
    let duration = 0.05;
    let mut sim = simulation("scenes/hu-table2.toml", EngineChoice::Reference, duration);
    let Shaft::Prescribed(sine) = sim.scene().pack.shaft.clone() else {
        panic!("a prescribed shaft")
    };
    let (h, n) = (1e-5, 5000);
    let times: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    let mut s = sim
        .engine_mut()
        .unwrap()
        .start(Driven {
            shaft_speed: true,
            ..Driven::NONE
        })
        .unwrap();
    s.set_stop_time(duration);
    let mut driven = Collector::default();
    for (k, &t) in times.iter().enumerate() {
        let v = sine.speed(t);
        s.set_inputs(&Inputs {
            shaft_speed_rad_s: Some(v),
            ..Inputs::default()
        })
        .unwrap();
        let next = times.get(k + 1).copied().unwrap_or(duration);
        s.advance_to(next, &mut driven).unwrap();
    }
    s.finish(&mut driven);
    let speeds = times.iter().map(|&t| sine.speed(t)).collect();
    let mut pack = sim.scene().pack.clone();
    pack.shaft = Shaft::Prescribed(SpeedProfile::Table(
        Table::new(times, speeds).unwrap().held(),
    ));
    let engine = clutchpack_reference::ReferenceEngine::new(
        pack.clone(),
        clutchpack_reference::ReferenceOptions::default(),
    );
    // an engine asked to step across the held table's jumps refuses
    let refused = engine.start(Driven::NONE).err().expect("refused");
    assert!(
        refused.to_string().contains("held speed table"),
        "{refused}"
    );
    let mut table = Collector::default();
    let mut engine = engine;
    engine.run(duration, &mut table).unwrap();
    assert!(table.impacts.len() > 10);
    assert_eq!(driven.impacts, table.impacts);
    // against the continuous sine: the hold delays the speed by h/2 on average
    let mut whole = Collector::default();
    sim.engine_mut().unwrap().run(duration, &mut whole).unwrap();
    let worst = whole
        .impacts
        .iter()
        .zip(&table.impacts)
        .map(|(a, b)| (a.peak_n - b.peak_n).abs() / a.peak_n.abs())
        .fold(0.0, f64::max);
    eprintln!(
        "held at 1e-5 s vs the continuous sine: {} vs {} impacts, worst peak {worst:.2e}",
        table.impacts.len(),
        whole.impacts.len()
    );
}

/// The open pack's relaxation windows (1 ms) hold many calls: a snapshot at a call inside a
/// window is the state the run passes through there (found by rerunning the window's last
/// pass), identical to the whole run's sample at that instant.
#[test]
fn reference_snapshots_inside_an_open_packs_window_are_the_run() {
    let mut sim = simulation("scenes/pack-8-brake.toml", EngineChoice::Reference, 0.02);
    let mut whole = Collector::default();
    sim.engine_mut().unwrap().run(0.02, &mut whole).unwrap();
    let mut s = sim.engine_mut().unwrap().start(Driven::NONE).unwrap();
    s.set_stop_time(0.02);
    let mut split = Collector::default();
    for k in 1..=200u32 {
        let t = k as f64 / 1e4;
        s.advance_to(t, &mut split).unwrap();
        let snap = s.snapshot();
        let w = &whole.samples[k as usize];
        assert_eq!(w.t_s, t);
        // the same dense output at the same instant (a sample on a step's end is the dense
        // output's value there, the snapshot the step's end state: an ulp apart)
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(1e-3);
        for (a, b) in w.discs.iter().zip(&snap.sample.discs) {
            assert!(
                close(a.rel_angle_rad, b.rel_angle_rad)
                    && close(a.speed_rad_s, b.speed_rad_s)
                    && (a.load_n - b.load_n).abs() <= 1e-9 * a.load_n.abs().max(1.0),
                "at {t} s: {a:?} vs {b:?}"
            );
        }
        let gaps = &whole.interfaces[k as usize];
        assert_eq!(gaps.0, t);
        assert_eq!(gaps.1.len(), snap.interfaces.len());
        for (a, b) in gaps.1.iter().zip(&snap.interfaces) {
            assert!(close(a.dissipated_j, b.dissipated_j), "at {t} s");
        }
    }
}

/// `bench --frames` (issue 46) refuses a frame that does not parse, is not > 0 or is longer
/// than the run, and a frame without its scene, with exit 2 and a message naming the value,
/// before any work (nothing printed on stdout).
#[test]
fn bench_frames_refuses_bad_frames_before_any_work() {
    let scene = super::hardening::repo("scenes/hu-table2.toml");
    for (args, says) in [
        (
            vec!["--frames", "abc", &scene],
            "\"abc\": expected a frame length",
        ),
        (
            vec!["--frames", "0ms", &scene],
            "expected a frame length > 0",
        ),
        (vec!["--frames=-1ms", &scene], "expected a frame length > 0"),
        (
            vec!["--frames", "1s", &scene],
            "longer than the run (0.3 s)",
        ),
        (
            vec!["--frames", "1ms", &scene, "--duration", "0.0005"],
            "longer than the run (0.0005 s)",
        ),
        (vec!["--frames", "1ms"], "name the scene"),
        (
            vec!["--frames", "1ms", &scene, "--budget-fraction", "0"],
            "--budget-fraction 0",
        ),
    ] {
        let o = super::bin()
            .arg("bench")
            .args(&args)
            .output()
            .expect("the binary runs");
        let err = super::hardening::exit_2(&o, &format!("{args:?}"));
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(super::stdout(&o).is_empty(), "{args:?}: work was done");
    }
}

/// `bench --frames 1ms` on `hu-table2` for 0.02 s: 20 frames, and the outputs of the frames
/// are the whole run's bit for bit (a session driven by nothing takes the whole run's steps
/// whatever its calls), as its `--summary-json` says.
#[test]
fn bench_frames_runs_and_finds_the_frames_outputs_identical() {
    let dir = super::scratch("bench-frames");
    let json = dir.join("frames.json");
    // `bench --frames 1ms` on hu-table2 for 0.02 s with `extra`, its summary into `json`
    let bench = |extra: &[&str]| {
        let scene = super::hardening::repo("scenes/hu-table2.toml");
        let mut args = vec!["bench", "--frames", "1ms", &scene, "--duration", "0.02"];
        args.extend_from_slice(extra);
        args.extend(["--summary-json", json.to_str().unwrap()]);
        super::run(&args)
    };
    let o = bench(&[]);
    assert!(o.status.success(), "{}", super::stderr(&o));
    assert!(
        super::stdout(&o).contains("outputs: identical"),
        "{}",
        super::stdout(&o)
    );
    let v = super::read_json(&json);
    assert_eq!(v["frames"], 20);
    let round = &v["rounds"][0];
    assert_eq!(round["difference"]["identical"], true, "{v}");
    assert_eq!(round["whole_steps"], round["framed_steps"], "{v}");
    assert!(
        round["difference"]["impacts_whole"].as_u64().unwrap() > 0,
        "{v}"
    );
    assert_eq!((&v["paced"], &v["spin"]), (&false.into(), &false.into()));
    // paced, spinning between the frames: 20 frames take at least their 20 ms of wall time
    // and give the same outputs; `--spin` without `--paced` is refused
    let t0 = std::time::Instant::now();
    let o = bench(&["--paced", "--spin"]);
    assert!(o.status.success(), "{}", super::stderr(&o));
    assert!(t0.elapsed().as_secs_f64() >= 0.019);
    let v = super::read_json(&json);
    assert_eq!((&v["paced"], &v["spin"]), (&true.into(), &true.into()));
    assert_eq!(v["rounds"][0]["difference"]["identical"], true, "{v}");
    let o = super::run(&["bench", "--frames", "1ms", "--spin"]);
    assert_eq!(o.status.code(), Some(2), "{}", super::stderr(&o));
    assert!(
        super::stderr(&o).contains("--paced"),
        "{}",
        super::stderr(&o)
    );
}
