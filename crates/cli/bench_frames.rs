//! `clutchpack bench --frames DT SCENE`: a scene advanced frame by frame as a real-time host
//! advances it (the sdk's session, `advance_to` every `DT` of simulated time) against the
//! same scene advanced in one call, in the same process: the wall times and their ratio, the
//! frames' wall-time distribution and overruns against a budget, the real-time factor, and
//! whether the outputs (the impacts' count, each body's largest peak, the last impact, the
//! final state) are the whole run's. Printed, never
//! asserted (docs/performance.md, "Frames").

use crate::common::BadInput;
use anyhow::Result;
use clutchpack_sdk::model::session::{Driven, Inputs};
use clutchpack_sdk::model::ImpactEvent;
use clutchpack_sdk::scene::{EngineChoice, Override, Scene};
use clutchpack_sdk::{load_scene, NetworkSimulation, SessionRequest, Simulation};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// What `bench --frames` was asked (checked by [`bench_frames`] before any work).
pub struct FramesRequest<'a> {
    /// The frame length, s.
    pub frame_s: f64,
    pub scene_path: &'a Path,
    pub engine: Option<EngineChoice>,
    /// The simulated time, s.
    pub duration_s: Option<f64>,
    /// The budget of a frame as a fraction of the frame (> 0).
    pub budget_fraction: f64,
    pub summary_json: Option<&'a Path>,
    /// Each frame of the last round's framed run as CSV.
    pub frames_csv: Option<&'a Path>,
    /// Rounds, each a whole run then a framed run (the median ratio is reported).
    pub rounds: usize,
    /// Pace the framed run as a real-time host does: frame `k` starts no earlier than `k`
    /// frame lengths of wall time after the first (the thread sleeps in between), so that
    /// the frames meet the caches, the scheduler and a real-time policy's throttling as a
    /// host's frames do. The framed wall time is then the frames' own (sleeps left out).
    pub paced: bool,
    /// With `paced`: wait for each frame spinning on the clock instead of sleeping, as a rig's
    /// loop on a core of its own does (the core never idles, so its caches and clock stay
    /// warm between the frames).
    pub spin: bool,
    /// Drive every input the scene has, as an FMU does, each held at its value at t = 0 and
    /// set again at every call (both sides: the whole run is the driven run in one call).
    pub drive: bool,
}

/// Parses a frame length: a number of seconds, or with a unit `s`, `ms` or `us` (`1ms`,
/// `250us`, `0.001`). Zero, negative and non-finite lengths are refused.
pub fn parse_frame(text: &str) -> std::result::Result<f64, String> {
    let t = text.trim();
    let (num, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix("us") {
        (n, 1e-6)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else {
        (t, 1.0)
    };
    let v: f64 = num.trim().parse().map_err(|_| {
        format!("--frames {text:?}: expected a frame length such as 1ms, 250us or 0.001 (s)")
    })?;
    let s = v * scale;
    if !(s.is_finite() && s > 0.0) {
        return Err(format!(
            "--frames {text:?}: expected a frame length > 0 (s), got {s}"
        ));
    }
    Ok(s)
}

/// One side of a round: the whole run or the framed run.
struct Side {
    wall_s: f64,
    /// Each frame's wall time, s (one entry for the whole run).
    frames_s: Vec<f64>,
    /// Each frame's CPU time on the calling thread, s: its own cost. A frame whose wall time
    /// is far over its CPU time waited for the core (another process ran, the scheduler's
    /// noise), not for the engine.
    frames_cpu_s: Vec<f64>,
    /// Each frame's tooth impacts closed (a network's: its gear meshes' and resolved packs').
    frames_impacts: Vec<u32>,
    outputs: Outputs,
    steps: u64,
}

/// What the two sides are compared on.
#[derive(Default, Clone)]
struct Outputs {
    /// Pack: the impact that closed last; network: none.
    last_impact: Option<ImpactEvent>,
    /// Pack: `(every impact, 0)` then per body `(0, largest |peak| N)`; network: per coupling
    /// and pack body `(impacts, largest peak N)`.
    coupling: Vec<(u64, f64)>,
    /// The final state: each body's speed (rad/s), then angle (rad).
    state: Vec<f64>,
    /// The time the run stands at, s.
    t_end_s: f64,
}

/// How far the framed run's outputs are from the whole run's.
#[derive(Serialize, Default, Clone, Copy)]
pub struct Difference {
    pub impacts_whole: usize,
    pub impacts_framed: usize,
    /// The difference of the last impacts' peak times, s (pack scenes).
    pub last_peak_time_diff_s: f64,
    /// Largest difference of the bodies' (and a network's couplings') largest peaks and of
    /// the last impacts' peaks, N.
    pub max_peak_diff_n: f64,
    /// Largest difference of the final speeds (rad/s) and angles (rad).
    pub max_state_diff: f64,
    /// Whether every compared value is the same bit for bit.
    pub identical: bool,
}

/// One round's figures.
#[derive(Serialize, Clone)]
pub struct Round {
    pub whole_wall_s: f64,
    pub framed_wall_s: f64,
    /// Framed over whole wall time.
    pub ratio: f64,
    pub whole_steps: u64,
    pub framed_steps: u64,
    pub frame_median_s: f64,
    pub frame_p99_s: f64,
    pub frame_p999_s: f64,
    pub frame_max_s: f64,
    /// The frames' CPU time on the calling thread (their own cost, without the time the
    /// core ran something else), s.
    pub frame_cpu_median_s: f64,
    pub frame_cpu_p99_s: f64,
    pub frame_cpu_p999_s: f64,
    pub frame_cpu_max_s: f64,
    /// Frames whose wall time passed the budget.
    pub overruns: usize,
    /// Frames whose CPU time passed the budget (the overruns that are the engine's own).
    pub cpu_overruns: usize,
    /// Framed wall time over simulated time (< 1: faster than real time).
    pub real_time_factor: f64,
    pub difference: Difference,
}

/// `--summary-json`'s content.
#[derive(Serialize)]
struct Summary<'a> {
    scene: &'a str,
    engine: &'a str,
    frame_s: f64,
    duration_s: f64,
    driven: bool,
    paced: bool,
    /// Whether the paced frames were waited for by spinning (else by sleeping).
    spin: bool,
    frames: usize,
    budget_s: f64,
    median_ratio: f64,
    /// Each frame's least CPU time over the rounds (one round: its CPU time).
    frame_cost: FrameCost,
    rounds: &'a [Round],
}

/// The distribution of the frames' own cost: each frame's least CPU time over the rounds, s.
#[derive(Serialize, Clone, Copy)]
struct FrameCost {
    median_s: f64,
    p99_s: f64,
    p999_s: f64,
    max_s: f64,
    /// Frames whose least CPU time passed the budget.
    overruns: usize,
}

/// A frame's start: the wall clock and the calling thread's CPU clock.
struct FrameClock {
    wall: Instant,
    cpu: Option<cpu_time::ThreadTime>,
}

impl FrameClock {
    fn now() -> FrameClock {
        FrameClock {
            wall: Instant::now(),
            cpu: cpu_time::ThreadTime::try_now().ok(),
        }
    }

    /// Pushes the wall time (s) and the thread's CPU time (s; 0 where the clock is missing)
    /// since [`FrameClock::now`].
    fn push(&self, wall_s: &mut Vec<f64>, cpu_s: &mut Vec<f64>) {
        let cpu = self.cpu.as_ref().and_then(|c| c.try_elapsed().ok());
        wall_s.push(self.wall.elapsed().as_secs_f64());
        cpu_s.push(cpu.map_or(0.0, |d| d.as_secs_f64()));
    }
}

/// How a paced run waits for its frames: each frame `frame_s` (s) after the last, by
/// sleeping or by spinning on the clock.
#[derive(Clone, Copy)]
struct Pace {
    frame_s: f64,
    spin: bool,
}

/// Waits until frame `k` (from 0) is due, `k` frame lengths after `t0`; at once without
/// `pace` or when the frame is late.
fn wait_for_frame(t0: Instant, k: usize, pace: Option<Pace>) {
    if let Some(p) = pace {
        let due = t0 + std::time::Duration::from_secs_f64(k as f64 * p.frame_s);
        if p.spin {
            while Instant::now() < due {
                std::hint::spin_loop();
            }
            return;
        }
        let now = Instant::now();
        if due > now {
            std::thread::sleep(due - now);
        }
    }
}

/// A side's wall time, s: since `t0`, or when paced the frames' own (`frames_s`, s) without
/// the sleeps between them.
fn busy_wall_s(t0: Instant, frames_s: &[f64], pace: Option<Pace>) -> f64 {
    if pace.is_some() {
        frames_s.iter().sum()
    } else {
        t0.elapsed().as_secs_f64()
    }
}

/// The `q` quantile (0..=1) of sorted `v` (nearest rank).
fn quantile(v: &[f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let i = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[i]
}

/// `bench --frames`: checks everything before any work (the scene loads, the engine runs it,
/// the frame fits the duration, the budget is a positive fraction, the summary's path takes a
/// file), then runs the rounds and prints each one's figures.
pub fn bench_frames(r: FramesRequest, stop: &AtomicBool) -> Result<ExitCode> {
    if !(r.budget_fraction.is_finite() && r.budget_fraction > 0.0) {
        return Err(BadInput(format!(
            "--budget-fraction {}: expected a fraction of the frame > 0",
            r.budget_fraction
        ))
        .into());
    }
    let sets: Vec<Override> = Vec::new();
    let scene = load_scene(Some(r.scene_path), &sets)?;
    let duration = r.duration_s.unwrap_or(scene.simulation.duration_s);
    if !(duration.is_finite() && duration > 0.0) {
        return Err(BadInput(format!("--duration {duration}: expected a time > 0 (s)")).into());
    }
    if r.frame_s > duration {
        return Err(BadInput(format!(
            "--frames {} s is longer than the run ({} s): expected a frame at most the duration",
            r.frame_s, duration
        ))
        .into());
    }
    let engine = scene.engine(r.engine, &scene.name)?;
    let outputs: Vec<crate::outputs::Output> = [
        ("--summary-json", r.summary_json),
        ("--frames-csv", r.frames_csv),
    ]
    .into_iter()
    .filter_map(|(flag, p)| p.map(|p| crate::outputs::Output::file(flag, p)))
    .collect();
    if !outputs.is_empty() {
        let inputs: Vec<&Path> = std::iter::once(r.scene_path)
            .chain(scene.inputs.iter().map(|p| p.as_path()))
            .collect();
        crate::outputs::check_outputs(&outputs, &inputs)?;
    }
    // a network's engine refuses the scene (the multibody engine on one rigid group) here
    if scene.network.is_some() {
        NetworkSimulation::start(&scene, Some(engine), &[], None, Some(duration))?;
    } else {
        Simulation::new(scene.clone(), Some(engine))?;
    }
    // frame ends k dt (not added up: a host's sum drifts by ulps), the last one the duration
    let n = (duration / r.frame_s - 1e-9).ceil().max(1.0) as usize;
    let ends: Vec<f64> = (1..=n)
        .map(|k| {
            if k == n {
                duration
            } else {
                k as f64 * r.frame_s
            }
        })
        .collect();
    let budget = r.budget_fraction * r.frame_s;
    if cfg!(debug_assertions) {
        out!("warning: a debug build; build with --release for meaningful figures");
    }
    out!(
        "{} on the {} engine{}{}, {} s in {} frames of {} s (budget {:.3e} s per frame), {} round(s)",
        scene.name,
        engine.name(),
        if r.drive {
            ", every input driven (held at t = 0)"
        } else {
            ""
        },
        match (r.paced, r.spin) {
            (true, false) => ", the frames paced at their wall-clock times (sleeping between)",
            (true, true) => ", the frames paced at their wall-clock times (spinning between)",
            _ => "",
        },
        duration,
        n,
        r.frame_s,
        budget,
        r.rounds.max(1)
    );
    let mut rounds = Vec::new();
    let mut last_framed: Option<Side> = None;
    // each frame's least CPU time over the rounds, s
    let mut least_cpu_s = vec![f64::INFINITY; n];
    for _ in 0..r.rounds.max(1) {
        let whole = side(&scene, engine, duration, &[duration], r.drive, None, stop)?;
        if stop.load(Ordering::SeqCst) {
            return Ok(crate::signals::exit_code());
        }
        let pace = r.paced.then_some(Pace {
            frame_s: r.frame_s,
            spin: r.spin,
        });
        let framed = side(&scene, engine, duration, &ends, r.drive, pace, stop)?;
        if stop.load(Ordering::SeqCst) {
            return Ok(crate::signals::exit_code());
        }
        let round = figures(&whole, &framed, budget, duration);
        print_round(&round);
        rounds.push(round);
        for (m, c) in least_cpu_s.iter_mut().zip(&framed.frames_cpu_s) {
            *m = m.min(*c);
        }
        last_framed = Some(framed);
    }
    if let (Some(p), Some(f)) = (r.frames_csv, &last_framed) {
        let mut text = String::from("frame,t_end_s,wall_s,cpu_s,impacts\n");
        for (k, t) in ends.iter().enumerate() {
            text += &format!(
                "{},{t},{:e},{:e},{}\n",
                k + 1,
                f.frames_s[k],
                f.frames_cpu_s[k],
                f.frames_impacts[k]
            );
        }
        crate::outputs::write_text(p, &text)?;
    }
    let mut ratios: Vec<f64> = rounds.iter().map(|x| x.ratio).collect();
    ratios.sort_by(f64::total_cmp);
    let median_ratio = ratios[ratios.len() / 2];
    out!(
        "median framed/whole ratio over {} round(s): {median_ratio:.3}",
        rounds.len()
    );
    // The frames are the same work in every round (the run is deterministic): a frame's least
    // CPU time over the rounds is its own cost, with another process's or the hypervisor's
    // share of the core (which lands on different frames each round) mostly left out.
    least_cpu_s.sort_by(f64::total_cmp);
    let cost = FrameCost {
        median_s: quantile(&least_cpu_s, 0.5),
        p99_s: quantile(&least_cpu_s, 0.99),
        p999_s: quantile(&least_cpu_s, 0.999),
        max_s: least_cpu_s.last().copied().unwrap_or(0.0),
        overruns: least_cpu_s.iter().filter(|&&x| x > budget).count(),
    };
    if rounds.len() > 1 {
        out!(
            "frame cost (each frame's least CPU time over the {} rounds): median {:.1} us, p99 {:.1} us, p99.9 {:.1} us, max {:.1} us; {} over the budget",
            rounds.len(),
            cost.median_s * 1e6,
            cost.p99_s * 1e6,
            cost.p999_s * 1e6,
            cost.max_s * 1e6,
            cost.overruns
        );
    }
    if let Some(p) = r.summary_json {
        crate::outputs::write_json(
            p,
            &Summary {
                scene: &scene.name,
                engine: engine.name(),
                frame_s: r.frame_s,
                duration_s: duration,
                driven: r.drive,
                paced: r.paced,
                spin: r.paced && r.spin,
                frames: n,
                budget_s: budget,
                median_ratio,
                frame_cost: cost,
                rounds: &rounds,
            },
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

fn print_round(r: &Round) {
    let d = &r.difference;
    out!(
        "  whole {:.4} s ({} steps), framed {:.4} s ({} steps): ratio {:.3}; real-time factor {:.3}",
        r.whole_wall_s,
        r.whole_steps,
        r.framed_wall_s,
        r.framed_steps,
        r.ratio,
        r.real_time_factor
    );
    out!(
        "  frame wall time: median {:.1} us, p99 {:.1} us, p99.9 {:.1} us, max {:.1} us; {} overrun(s)",
        r.frame_median_s * 1e6,
        r.frame_p99_s * 1e6,
        r.frame_p999_s * 1e6,
        r.frame_max_s * 1e6,
        r.overruns
    );
    out!(
        "  frame CPU time (the calling thread's): median {:.1} us, p99 {:.1} us, p99.9 {:.1} us, max {:.1} us; {} overrun(s)",
        r.frame_cpu_median_s * 1e6,
        r.frame_cpu_p99_s * 1e6,
        r.frame_cpu_p999_s * 1e6,
        r.frame_cpu_max_s * 1e6,
        r.cpu_overruns
    );
    out!(
        "  outputs: {} ({} / {} impacts, last peak times within {:.2e} s, largest peaks within {:.2e} N, final state within {:.2e})",
        if d.identical { "identical" } else { "differ" },
        d.impacts_whole,
        d.impacts_framed,
        d.last_peak_time_diff_s,
        d.max_peak_diff_n,
        d.max_state_diff
    );
}

/// A round's figures from its two sides.
fn figures(whole: &Side, framed: &Side, budget: f64, duration: f64) -> Round {
    let mut f = framed.frames_s.clone();
    f.sort_by(f64::total_cmp);
    let mut c = framed.frames_cpu_s.clone();
    c.sort_by(f64::total_cmp);
    let (w, s) = (&whole.outputs, &framed.outputs);
    let mut d = Difference {
        impacts_whole: w.coupling.iter().map(|c| c.0 as usize).sum::<usize>(),
        impacts_framed: s.coupling.iter().map(|c| c.0 as usize).sum::<usize>(),
        ..Difference::default()
    };
    let mut same = w.last_impact == s.last_impact
        && w.coupling.len() == s.coupling.len()
        && w.state.len() == s.state.len()
        && w.t_end_s == s.t_end_s;
    if let (Some(a), Some(b)) = (w.last_impact, s.last_impact) {
        d.last_peak_time_diff_s = (a.t_peak_s - b.t_peak_s).abs();
        d.max_peak_diff_n = (a.peak_n - b.peak_n).abs();
    }
    for (a, b) in w.coupling.iter().zip(&s.coupling) {
        d.max_peak_diff_n = d.max_peak_diff_n.max((a.1 - b.1).abs());
        same &= a.0 == b.0 && a.1.to_bits() == b.1.to_bits();
    }
    for (a, b) in w.state.iter().zip(&s.state) {
        d.max_state_diff = d.max_state_diff.max((a - b).abs());
        same &= a.to_bits() == b.to_bits();
    }
    d.identical = same;
    Round {
        whole_wall_s: whole.wall_s,
        framed_wall_s: framed.wall_s,
        ratio: framed.wall_s / whole.wall_s,
        whole_steps: whole.steps,
        framed_steps: framed.steps,
        frame_median_s: quantile(&f, 0.5),
        frame_p99_s: quantile(&f, 0.99),
        frame_p999_s: quantile(&f, 0.999),
        frame_max_s: f.last().copied().unwrap_or(0.0),
        frame_cpu_median_s: quantile(&c, 0.5),
        frame_cpu_p99_s: quantile(&c, 0.99),
        frame_cpu_p999_s: quantile(&c, 0.999),
        frame_cpu_max_s: c.last().copied().unwrap_or(0.0),
        overruns: f.iter().filter(|&&x| x > budget).count(),
        cpu_overruns: c.iter().filter(|&&x| x > budget).count(),
        real_time_factor: framed.wall_s / duration,
        difference: d,
    }
}

/// Runs `scene` on `engine` to `duration` (s) through the calls `ends` (s, the last one the
/// duration) as a host does, timing each call.
fn side(
    scene: &Scene,
    engine: EngineChoice,
    duration: f64,
    ends: &[f64],
    drive: bool,
    pace: Option<Pace>,
    stop: &AtomicBool,
) -> Result<Side> {
    let mut frames_s = Vec::with_capacity(ends.len());
    let mut frames_cpu_s = Vec::with_capacity(ends.len());
    let mut frames_impacts = Vec::with_capacity(ends.len());
    if let Some(net) = &scene.network {
        let names: Vec<String> = if drive {
            clutchpack_sdk::network_inputs(net)
                .into_iter()
                .map(|(n, _)| n)
                .collect()
        } else {
            Vec::new()
        };
        let mut sim = NetworkSimulation::start(scene, Some(engine), &names, None, Some(duration))?;
        let held = sim.input_values();
        let t0 = Instant::now();
        let mut impacts = sim.impact_count();
        for (k, &t) in ends.iter().enumerate() {
            wait_for_frame(t0, k, pace);
            let f0 = FrameClock::now();
            for (name, v) in &held {
                sim.set_input(name, *v)?;
            }
            sim.advance_to(t, Some(stop))?;
            // a host reads the outputs' values at every communication point, as the
            // co-simulation (the FMU) does: their names were formatted once, at the start
            std::hint::black_box(sim.output_values());
            f0.push(&mut frames_s, &mut frames_cpu_s);
            let now = sim.impact_count();
            frames_impacts.push((now - impacts) as u32);
            impacts = now;
        }
        let wall_s = busy_wall_s(t0, &frames_s, pace);
        let t_end_s = sim.time_s();
        let state = sim
            .outputs()
            .into_iter()
            .filter(|(n, _)| n.ends_with(".speed_rad_s") || n.ends_with(".angle_rad"))
            .map(|(_, v)| v)
            .collect();
        let done = sim.finish()?;
        let s = &done.summary;
        let mut coupling: Vec<(u64, f64)> = s
            .couplings
            .iter()
            .map(|c| (c.impacts, c.largest_peak_n))
            .collect();
        for c in &s.couplings {
            coupling.extend(c.pack_bodies.iter().map(|b| (b.impacts, b.largest_peak_n)));
        }
        return Ok(Side {
            wall_s,
            frames_s,
            frames_cpu_s,
            frames_impacts,
            steps: s.steps,
            outputs: Outputs {
                last_impact: None,
                coupling,
                state,
                t_end_s,
            },
        });
    }
    let sim = Simulation::new(scene.clone(), Some(engine))?;
    let driven = if drive {
        Driven::all_for(&scene.pack)
    } else {
        Driven::NONE
    };
    let held = Inputs::of_scene(&scene.pack, &driven, 0.0);
    let mut session = sim.start(SessionRequest {
        driven,
        stop_time_s: Some(duration),
        // as a host runs it (`CoSimulation`, the FMU): nothing kept but the statistics (the
        // kept history's doubling vectors were the slowest frames' own cost, 3.6 and 7.2 ms
        // at frames 3277 and 6554 of `pack-8-brake`'s 10 s)
        keep_history: false,
        ..SessionRequest::default()
    })?;
    let t0 = Instant::now();
    let mut impacts = session.impact_count();
    for (k, &t) in ends.iter().enumerate() {
        wait_for_frame(t0, k, pace);
        let f0 = FrameClock::now();
        if drive {
            // what `CoSimulation` does at every call of a driven run
            session.set_inputs(&held)?;
        }
        session.advance_to(t, Some(stop))?;
        // a host reads the outputs at every communication point (`CoSimulation`'s snapshot)
        std::hint::black_box(session.snapshot());
        f0.push(&mut frames_s, &mut frames_cpu_s);
        let now = session.impact_count();
        frames_impacts.push((now - impacts) as u32);
        impacts = now;
    }
    let wall_s = busy_wall_s(t0, &frames_s, pace);
    let snap = session.snapshot();
    let mut state: Vec<f64> = vec![snap.sample.shaft_speed_rad_s, snap.sample.shaft_angle_rad];
    for d in &snap.sample.discs {
        state.push(d.speed_rad_s);
        state.push(d.angle_rad);
    }
    let t_end_s = session.time_s();
    let done = session.finish();
    let steps = done.stats()?.steps;
    // after `finish`, which closes the contacts still open
    let c = &done.collector;
    let mut coupling = vec![(c.impact_count() as u64, 0.0)];
    coupling.extend((0..done.body_names.len()).map(|i| (0, c.peaks.max_abs_n(i))));
    let last_impact = c.last_impact;
    Ok(Side {
        wall_s,
        frames_s,
        frames_cpu_s,
        frames_impacts,
        steps,
        outputs: Outputs {
            last_impact,
            coupling,
            state,
            t_end_s,
        },
    })
}

/// The frame of `bench --frames` as given, with its scene: the scene is required with it and
/// refused without it.
pub fn request<'a>(
    frames: Option<&str>,
    scene: Option<&'a PathBuf>,
) -> Result<Option<(f64, &'a Path)>> {
    match (frames, scene) {
        (None, None) => Ok(None),
        (None, Some(p)) => Err(BadInput(format!(
            "bench {}: a scene is benched frame by frame; add --frames 1ms (the frame length)",
            p.display()
        ))
        .into()),
        (Some(_), None) => Err(BadInput(
            "bench --frames: name the scene to run frame by frame (bench --frames 1ms \
             scenes/pack-8-brake.toml)"
                .into(),
        )
        .into()),
        (Some(f), Some(p)) => Ok(Some((parse_frame(f).map_err(BadInput)?, p.as_path()))),
    }
}

#[cfg(test)]
mod tests {
    use super::parse_frame;

    #[test]
    fn frame_lengths_parse_with_units_and_refuse_nonsense() {
        assert_eq!(parse_frame("1ms").unwrap(), 1e-3);
        assert_eq!(parse_frame("250us").unwrap(), 250.0 * 1e-6);
        assert_eq!(parse_frame("0.002").unwrap(), 0.002);
        assert_eq!(parse_frame("0.5s").unwrap(), 0.5);
        for bad in ["", "ms", "0ms", "-1ms", "abc", "nan", "inf"] {
            assert!(parse_frame(bad).is_err(), "{bad:?}");
        }
    }
}
