//! Issue 48, item 8: "frames never fail where a whole run succeeds". Every shipped scene
//! (shortened where it is long), on both engines where the engine accepts it, advanced in
//! frames that land on each of its schedule breakpoints, and in frames of 0.01 s and 0.05 s
//! added up as a co-simulation host adds them (ten of 0.01 s end at 0.09999999999999999;
//! seven of 0.05 s at 0.35000000000000003, a few ulps past `dct-upshift`'s breakpoint at
//! 0.35 s), against the whole run: the same impacts and the same state at the end.
//!
//! Before the fix the reference engine's network run failed on a frame ending within a few
//! ulps of where it stood ("the step collapsed to 1.39e-17 s"), and the run was lost for good.

use clutchpack_model::session::{Advance, Driven, Inputs, Snapshot};
use clutchpack_model::{Collector, Shaft, ShaftExcitation, SpeedProfile};
use clutchpack_scene::{EngineChoice, Override, Scene};
use clutchpack_sdk::{NetworkSimulation, SessionRequest, Simulation};
use std::path::{Path, PathBuf};

/// The shipped scenes, by file.
fn shipped() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    v.sort();
    v
}

/// The simulated duration a scene is tried for, s: its own, at most `cap`.
fn duration(scene: &Scene, cap: f64) -> f64 {
    scene.simulation.duration_s.min(cap)
}

/// Frame ends up to `end`: every breakpoint in `(0, end)` then `end` (`bps`), or frames of
/// `dt` added up one by one (the last cut at `end`).
fn frames(bps: Option<&[f64]>, dt: f64, end: f64) -> Vec<f64> {
    let mut out = Vec::new();
    match bps {
        Some(bps) => out.extend(bps.iter().copied().filter(|&b| b > 0.0 && b < end)),
        None => {
            let mut t = 0.0;
            loop {
                t += dt;
                if t >= end {
                    break;
                }
                out.push(t);
            }
        }
    }
    out.push(end);
    out
}

/// A pack scene's schedule breakpoints, s: its piston pressure's and its drive table's rows.
fn pack_breakpoints(scene: &Scene) -> Vec<f64> {
    let mut bps = Vec::new();
    if let Some(stack) = &scene.pack.stack {
        stack.piston.pressure.breakpoints(&mut bps);
    }
    match &scene.pack.shaft {
        Shaft::Prescribed(SpeedProfile::Table(t)) => bps.extend_from_slice(&t.t_s),
        Shaft::Inertial {
            excitation: ShaftExcitation::Torque { table, .. },
            ..
        } => bps.extend_from_slice(&table.t_s),
        _ => {}
    }
    bps.sort_by(f64::total_cmp);
    bps.dedup();
    bps
}

/// A pack scene on `engine`: the whole run against the session advanced to `ends`; the
/// sessions' steps never end at a call, so they are the same bit for bit.
fn pack_frames(name: &str, scene: &Scene, engine: EngineChoice, end: f64, ends: &[f64]) {
    let mut sim = Simulation::new(scene.clone(), Some(engine)).unwrap();
    let mut whole = Collector::default();
    sim.engine_mut().unwrap().run(end, &mut whole).unwrap();
    let mut split = Collector::default();
    let mut s = sim.engine_mut().unwrap().start(Driven::NONE).unwrap();
    s.set_stop_time(end);
    for &t in ends {
        let got = s
            .advance_to(t, &mut split)
            .unwrap_or_else(|e| panic!("{name} {engine:?}: the frame to {t} s failed: {e}"));
        assert_eq!(got, Advance::Reached, "{name} {engine:?} to {t}");
    }
    s.finish(&mut split);
    assert_eq!(
        whole.impacts.len(),
        split.impacts.len(),
        "{name} {engine:?}: impacts"
    );
    assert_eq!(
        whole.samples.last(),
        split.samples.last(),
        "{name} {engine:?}: the state at the end"
    );
}

/// A network scene on `engine`: the whole run against the run advanced to `ends` (each call
/// ends a step: the two differ by the steps' placement only). Measured over the shipped
/// networks: the speeds at the end within 2e-9 of the fastest body's, but for
/// `dct-upshift-lumped` on the reference engine in frames of 0.01 s, 1.3e-4 (its clutch K1
/// sticks and slips under the firing's torque from 0.2 s: each event moves with the steps);
/// the multibody engine's within 5e-10. Asserted 3e-4, and the gear meshes' impact counts
/// (`NetworkOutcome::impacts`: none in the shipped networks' first 0.4 s) within 5 %.
fn network_frames(name: &str, scene: &Scene, engine: EngineChoice, end: f64, ends: &[f64]) {
    if let Err(e) = NetworkSimulation::start(scene, Some(engine), &[], None, Some(end)) {
        // an engine that cannot run the network (the multibody engine on a pack whose
        // carriers are one rigid group) says so before any frame
        println!("{name} {engine:?}: not run: {e}");
        return;
    }
    let run = |ends: &[f64]| {
        let mut sim = NetworkSimulation::start(scene, Some(engine), &[], None, Some(end))
            .unwrap_or_else(|e| panic!("{name} {engine:?}: {e}"));
        for &t in ends {
            sim.advance_to(t, None)
                .unwrap_or_else(|e| panic!("{name} {engine:?}: the frame to {t} s failed: {e}"));
        }
        assert!(
            (sim.time_s() - end).abs() <= 1e-12 * (1.0 + end),
            "{name} {engine:?}: stands at {}",
            sim.time_s()
        );
        let speeds: Vec<f64> = sim
            .outputs()
            .into_iter()
            .filter(|(n, _)| n.ends_with(".speed_rad_s"))
            .map(|(_, v)| v)
            .collect();
        let running = sim.impact_count();
        let outcome = sim.finish().unwrap();
        // the running count (what `bench --frames` tallies per frame) is the summary's,
        // but for the contacts still open at the end, which `finish` closes: at most one
        // per gear mesh and per pack body
        let couplings = &outcome.summary.couplings;
        let total: u64 = couplings.iter().map(|c| c.impacts).sum();
        let open_at_most: usize = couplings.iter().map(|c| c.pack_bodies.len().max(1)).sum();
        assert!(
            running <= total && total - running <= open_at_most as u64,
            "{name} {engine:?}: {running} impacts counted as the run went, {total} in the \
             summary (at most {open_at_most} open at the end)"
        );
        println!("{name} {engine:?}: {running} impacts counted in frames, {total} in the summary");
        (speeds, outcome.impacts.len())
    };
    let (w_whole, n_whole) = run(&[end]);
    let (w_split, n_split) = run(ends);
    let top = w_whole.iter().fold(1.0f64, |m, w| m.max(w.abs()));
    let apart = w_whole
        .iter()
        .zip(&w_split)
        .map(|(a, b)| (a - b).abs() / top)
        .fold(0.0, f64::max);
    println!(
        "{name} {engine:?} in {} frames: speeds within {apart:.2e}, impacts {n_whole} / {n_split}",
        ends.len()
    );
    assert!(apart < 3e-4, "{name} {engine:?}: speeds apart by {apart:e}");
    let dn = (n_whole as f64 - n_split as f64).abs();
    assert!(
        dn <= 0.05 * n_whole as f64,
        "{name} {engine:?}: {n_whole} impacts whole, {n_split} in frames"
    );
}

#[test]
fn frames_landing_on_breakpoints_match_whole_run() {
    let mut tried = 0;
    for file in shipped() {
        let name = file.file_stem().unwrap().to_string_lossy().to_string();
        let scene = clutchpack_scene::load(&file, &Vec::<Override>::new()).unwrap();
        for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
            if scene.engine(Some(engine), &name).is_err() {
                continue;
            }
            match &scene.network {
                Some(net) => {
                    // dct-upshift's pressure ramps end at 0.35 s
                    let end = duration(&scene, 0.4);
                    let bps = net.breakpoints(end);
                    for ends in [
                        frames(Some(&bps), 0.0, end),
                        frames(None, 0.01, end),
                        frames(None, 0.05, end),
                    ] {
                        network_frames(&name, &scene, engine, end, &ends);
                    }
                }
                None => {
                    let end = duration(&scene, 0.1);
                    let bps = pack_breakpoints(&scene);
                    for ends in [
                        frames(Some(&bps), 0.0, end),
                        frames(None, 0.01, end),
                        frames(None, 0.05, end),
                    ] {
                        pack_frames(&name, &scene, engine, end, &ends);
                    }
                }
            }
            tried += 1;
        }
    }
    assert!(tried >= 30, "{tried} scene and engine pairs");
}

/// A scene's path under `scenes/`.
fn scene_file(name: &str) -> Scene {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{name}.toml"));
    clutchpack_scene::load(&file, &Vec::<Override>::new()).unwrap()
}

/// What a host's run gives: every impact, the state at the end, the steps taken.
type HostRun = (Vec<clutchpack_model::ImpactEvent>, Snapshot, u64);

/// `scene` on `engine` through the sdk's session as a host runs it, to `end` s in calls to
/// `ends`, the inputs `driven` held at the scene's values at t = 0 and set again before every
/// call when `set_each_call` (as `CoSimulation` does), else once before the first.
fn host_run(
    scene: &Scene,
    engine: EngineChoice,
    end: f64,
    ends: &[f64],
    driven: Driven,
    set_each_call: bool,
) -> HostRun {
    let sim = Simulation::new(scene.clone(), Some(engine)).unwrap();
    let mut s = sim
        .start(SessionRequest {
            driven,
            stop_time_s: Some(end),
            keep_history: true,
            ..SessionRequest::default()
        })
        .unwrap();
    let held = Inputs::of_scene(&scene.pack, &driven, 0.0);
    for (i, &t) in ends.iter().enumerate() {
        if driven.any() && (set_each_call || i == 0) {
            s.set_inputs(&held).unwrap();
        }
        assert_eq!(s.advance_to(t, None).unwrap(), Advance::Reached);
    }
    let snap = s.snapshot();
    let done = s.finish();
    let steps = done.stats().unwrap().steps;
    (done.collector.impacts, snap, steps)
}

/// Issue 46: a host's 1 ms frames (`advance_to` every 1e-3 s, the FMU's, Python's and the
/// sdk's sessions) cost what the whole run costs only if each call carries the engine's
/// state on (its step sizes, its multirate windows and sub-steps, its drive's expansion)
/// instead of restarting it. `pack-8-brake` for 0.05 s (about 300 impacts) on both engines,
/// in 1 ms frames against one call: the same impacts, the same state at the end and the same
/// number of steps, bit for bit.
#[test]
fn frames_of_1ms_cost_and_give_what_the_whole_run_does() {
    let scene = scene_file("pack-8-brake");
    let end = 0.05;
    let ends = frames(None, 1e-3, end);
    assert_eq!(ends.len(), 50);
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        let whole = host_run(&scene, engine, end, &[end], Driven::NONE, false);
        let framed = host_run(&scene, engine, end, &ends, Driven::NONE, false);
        assert!(whole.0.len() > 100, "{engine:?}: {} impacts", whole.0.len());
        assert_eq!(whole.0, framed.0, "{engine:?}: the impacts");
        assert_eq!(whole.1, framed.1, "{engine:?}: the state at the end");
        assert_eq!(whole.2, framed.2, "{engine:?}: the steps");
    }
}

/// Issue 46: a host sets every input at every communication point (`CoSimulation`, the FMU),
/// mostly to the value it already holds. Passed on, each such call restarted the engine's
/// integration (the reference engine's first derivative, the multibody engine's drive) and
/// cloned the pack. A driven `pack-8-brake` (every input held at its value at t = 0) in 1 ms
/// frames, the unchanged inputs set at every call, gives what the same frames give with
/// the inputs set once, bit for bit, on both engines.
#[test]
fn unchanged_inputs_set_at_every_frame_do_not_restart_the_engine() {
    let scene = scene_file("pack-8-brake");
    let end = 0.02;
    let ends = frames(None, 1e-3, end);
    let driven = Driven::all_for(&scene.pack);
    assert!(driven.any());
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        let once = host_run(&scene, engine, end, &ends, driven, false);
        let each = host_run(&scene, engine, end, &ends, driven, true);
        assert!(!once.0.is_empty(), "{engine:?}: no impacts");
        assert_eq!(once.0, each.0, "{engine:?}: the impacts");
        assert_eq!(once.1, each.1, "{engine:?}: the state at the end");
        assert_eq!(once.2, each.2, "{engine:?}: the steps");
    }
}

/// `scene` (a network) on `engine` to `end` s in calls to `ends` (nothing driven), the outputs
/// read after every call as a host reads them: the bodies' final speeds (rad/s) and the run's
/// summary (its wall time zeroed): the steps and events, every body's final speed and angle,
/// every coupling's impacts and heat, the energy balance.
fn network_host_run(
    scene: &Scene,
    engine: EngineChoice,
    end: f64,
    ends: &[f64],
) -> (Vec<f64>, clutchpack_sdk::NetworkSummary) {
    network_driven_run(scene, engine, end, ends, &[])
}

/// [`network_host_run`] with the inputs `drive` driven (each holding the scene's value at
/// t = 0) and set again before every call to the value they hold, as an FMU's host sets
/// every input at every communication point.
fn network_driven_run(
    scene: &Scene,
    engine: EngineChoice,
    end: f64,
    ends: &[f64],
    drive: &[String],
) -> (Vec<f64>, clutchpack_sdk::NetworkSummary) {
    let mut sim = NetworkSimulation::start(scene, Some(engine), drive, None, Some(end)).unwrap();
    let mut speeds = Vec::new();
    for &t in ends {
        for (name, v) in sim.input_values() {
            sim.set_input(&name, v).unwrap();
        }
        sim.advance_to(t, None).unwrap();
        assert!(
            (sim.time_s() - t).abs() <= 1e-12,
            "{} for {t}",
            sim.time_s()
        );
        speeds = sim
            .outputs()
            .into_iter()
            .filter(|(n, _)| n.ends_with(".speed_rad_s"))
            .map(|(_, v)| v)
            .collect();
    }
    let mut summary = sim.finish().unwrap().summary;
    summary.wall_time_s = 0.0;
    (speeds, summary)
}

/// Issue 46 on a network: `dct-upshift` (its two resolved packs in the driveline) in 1 ms
/// frames for 0.5 s (the packs' first impacts come after 0.3 s), the outputs read after every
/// frame, against one call: the same speeds and the same summary (steps, events, every
/// body's final state, every pack body's impacts, the heat and the energy balance) bit for
/// bit, on both engines. The multibody engine's world steps are on the frames' grid. The
/// reference engine's network integration ended a step at every call before (its dense
/// output not carried past a call): 12353 steps against 12085 over 1 s, the packs' impacts
/// 984 against 1022, the speeds within 2.1e-7 of the fastest body's; now the step that passes
/// a call waits for the next one and its dense output answers for the call's time.
#[test]
fn network_frames_of_1ms_match_whole_run() {
    let scene = scene_file("dct-upshift");
    let end = 0.5;
    let ends = frames(None, 1e-3, end);
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        let (w_whole, whole) = network_host_run(&scene, engine, end, &[end]);
        let (w_split, split) = network_host_run(&scene, engine, end, &ends);
        let impacts: u64 = whole
            .couplings
            .iter()
            .flat_map(|c| c.pack_bodies.iter().map(|b| b.impacts))
            .sum();
        println!(
            "dct-upshift {engine:?}: {} steps, {impacts} impacts",
            whole.steps
        );
        assert!(impacts > 20, "{engine:?}: {impacts} impacts");
        assert_eq!(w_whole, w_split, "{engine:?}: the speeds");
        assert_eq!(whole, split, "{engine:?}: the summary");
    }
}

/// Issue 46: a host sets every input at every communication point (the FMU's `fmi2SetReal`),
/// mostly to the value it already holds. `dct-upshift` with every input driven (each holding
/// the scene's value at t = 0: its drive torque, its clutches' forces, its packs' pressures)
/// in 1 ms frames for 0.3 s, every input set again before every frame, gives the driven run
/// in one call bit for bit on both engines: an unchanged input neither ends nor restarts the
/// reference engine's step.
#[test]
fn unchanged_network_inputs_set_at_every_frame_keep_the_whole_runs_steps() {
    let scene = scene_file("dct-upshift");
    let end = 0.3;
    let ends = frames(None, 1e-3, end);
    let net = scene.network.as_ref().expect("a network scene");
    let drive: Vec<String> = clutchpack_sdk::network_inputs(net)
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    assert!(drive.len() >= 3, "{drive:?}");
    for engine in [EngineChoice::Reference, EngineChoice::Multibody] {
        let (w_whole, whole) = network_driven_run(&scene, engine, end, &[end], &drive);
        let (w_split, split) = network_driven_run(&scene, engine, end, &ends, &drive);
        assert!(whole.steps > 1000, "{engine:?}: {} steps", whole.steps);
        assert_eq!(w_whole, w_split, "{engine:?}: the speeds");
        assert_eq!(whole, split, "{engine:?}: the summary");
    }
}

/// The shipped scene `name` on `engine`, every input driven (held at its value at t = 0 and
/// set again before every call, as a host sets them) for `end` s: the driven run in calls to
/// `ends` gives the driven run in one call bit for bit: the steps, every impact (at least one),
/// the state at the end.
fn driven_frames_match_whole_run(name: &str, engine: EngineChoice, end: f64, ends: &[f64]) {
    let scene = scene_file(name);
    let driven = Driven::all_for(&scene.pack);
    assert!(driven.any(), "{name}");
    let whole = host_run(&scene, engine, end, &[end], driven, true);
    let framed = host_run(&scene, engine, end, ends, driven, true);
    assert!(!whole.0.is_empty(), "{name} {engine:?}: no impacts");
    assert_eq!(whole.2, framed.2, "{name} {engine:?}: the steps");
    assert_eq!(whole.0, framed.0, "{name} {engine:?}: the impacts");
    assert_eq!(whole.1, framed.1, "{name} {engine:?}: the state at the end");
}

/// Issue 46: a driven pack session on the reference engine ended a step at every call, where
/// an input may change, so a host's 1 ms frames took other steps than the driven whole run
/// (`hu-table2` 3692 against 3497 over 0.3 s, its peaks within 3.4e-6 N). Through the sdk's
/// session as a host runs it (every input driven, held at its value at t = 0 and set again
/// before every call): `hu-table2` (independent discs) and `pack-4-damper` (the monolithic
/// scheme: an inertial shaft driven by a torque, a drum) for 0.05 s in 1 ms frames give the
/// driven run in one call bit for bit: the steps counted, every impact, the state at the end.
#[test]
fn driven_pack_session_ended_a_step_at_every_frame() {
    let end = 0.05;
    let ends = frames(None, 1e-3, end);
    for name in ["hu-table2", "pack-4-damper"] {
        driven_frames_match_whole_run(name, EngineChoice::Reference, end, &ends);
    }
}

/// Issue 46: a driven pack session on the multibody engine landed its steps on a host's frame
/// ends `k T` rather than on the record grid's `j / rate` the whole run lands on, the same
/// instants but for rounding (9e-3 against 9.000000000000001e-3), so its outputs differed in
/// their last bits (`hu-table2` in 1 ms frames over 0.3 s: the final state within 4.3e-8,
/// the peaks within 3.2e-6 N; `pack-8-brake` within 5.8e-7 and 5.2e-9 N). Through the sdk's
/// session as a host runs it (every input driven, held at its value at t = 0 and set again
/// before every call): `hu-table2` and `pack-8-brake` (the multirate scheme, a prescribed
/// shaft) for 0.05 s in 1 ms frames give the driven run in one call bit for bit: the steps,
/// every impact, the state at the end.
#[test]
fn driven_multibody_session_landed_on_the_frames_off_the_grid() {
    let end = 0.05;
    let ends = frames(None, 1e-3, end);
    for name in ["hu-table2", "pack-8-brake"] {
        driven_frames_match_whole_run(name, EngineChoice::Multibody, end, &ends);
    }
}

/// Issue 46: a driven pack session on the multibody engine's adaptive shared step ended a
/// contact step at every call, where an input may change (`pack-4-damper` in 1 ms frames over
/// 0.3 s: 54559 steps against 54426 in one call, its peaks within 3.8e-5 N). Now the step
/// that passes a call is the whole run's, a copy kept before it for an input changed there.
/// `pack-4-damper` (an inertial shaft driven by a torque, a drum) for 0.05 s in 1 ms frames,
/// every input set again before every call, gives the driven run in one call bit for bit: the
/// steps, every impact, the state at the end.
#[test]
fn driven_multibody_shared_step_ended_a_step_at_every_frame() {
    let end = 0.05;
    let ends = frames(None, 1e-3, end);
    driven_frames_match_whole_run("pack-4-damper", EngineChoice::Multibody, end, &ends);
}

/// Issue 46: a host's frame end inside a world step of a driven multibody session ended that
/// step there (the multirate scheme's world steps are 1e-4 s; a hardware-in-the-loop host runs
/// 25 us frames), so the framed run took other steps than the whole run. Now the step that
/// passes a frame's end is the whole run's (a copy kept before it, its outputs held for the
/// next call). `hu-table2`, `pack-8-brake` (multirate) and `pack-4-damper` (shared step),
/// every input driven and set again before every call, for 0.05 s in 25 us frames (accumulated,
/// off the record grid) give the driven run in one call bit for bit.
#[test]
fn driven_multibody_session_ended_a_world_step_at_a_frame_inside_it() {
    let end = 0.05;
    let ends = frames(None, 2.5e-5, end);
    for name in ["hu-table2", "pack-8-brake", "pack-4-damper"] {
        driven_frames_match_whole_run(name, EngineChoice::Multibody, end, &ends);
    }
}
