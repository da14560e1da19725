//! A network scene's run (`[[bodies]]`, MODEL.md section 8; [`crate::Simulation::run`] of a
//! network scene): the reference engine or the multibody engine on the scene's driveline
//! (the engine asked, else `simulation.engine`, else the reference), its clutches' mode changes and heat, the bodies' speeds and the energy
//! balance, as one serializable summary (`run --summary-json`) and, if asked, the sampled
//! history (for the figure). Both engines give the model's output types
//! ([`clutchpack_model::network::NetworkRun`]), so the summary is built the same way.

use crate::network_keep::{pack_fatigue, Keep, Obs};
use crate::{Error, Result};
use clutchpack_model::network::{
    ClutchMode, NetworkEnergy, NetworkRun, NetworkSample, NetworkSession,
};
use clutchpack_model::EngineError;
use clutchpack_record::Recorder;
use clutchpack_reference::network::NetworkOptions;
use clutchpack_scene::{EngineChoice, Scene};
use serde::Serialize;

/// What a network run keeps and writes beside its summary: the pack run's request, the same
/// seven options (a network's recording applies the compression, chunk size and determinism
/// of its [`crate::RecordingRequest`]; its impacts CSV names each body as
/// [`NetworkOutcome::impacts`] does; its cycles feed [`NetworkOutcome::cycles`]; its windows
/// each resolved pack's [`CouplingSummary::windows`]).
pub type NetworkRequest<'a> = crate::RunRequest<'a>;

/// One mode change of a clutch.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeChange {
    /// Time, s.
    pub t_s: f64,
    /// Mode before: `free`, `slip+`, `slip-` or `locked`.
    pub from: &'static str,
    /// Mode after.
    pub to: &'static str,
    /// Each coupling's torque step at this instant, N m (after less before, on its body `a`:
    /// the output torque's step at a lock is its gear's), in the scene's order.
    pub torque_steps_n_m: Vec<f64>,
}

/// One coupling's results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CouplingSummary {
    /// Its name.
    pub name: String,
    /// `clutch`, `ideal_gear`, `gear_mesh`, `spring_damper` or `pack`.
    pub kind: &'static str,
    /// Heat of a clutch or of a pack's faces, work done on a gear mesh, or a damper's loss,
    /// over the run, J (0 for an ideal gear).
    pub heat_j: f64,
    /// Torque on its body a at the end, N m.
    pub final_torque_n_m: f64,
    /// A clutch's mode at the end (absent for a gear); a pack's faces: "locked" (all
    /// locked), "slipping" (some clamped), "free".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_mode: Option<&'static str>,
    /// The instants a clutch locked, or all of a pack's faces locked, s.
    pub lock_times_s: Vec<f64>,
    /// A gear mesh's or a pack's tooth impacts (closed contacts) over the run (0 for other
    /// kinds).
    pub impacts: u64,
    /// A gear mesh's largest impact peak per tooth pair, or a pack's largest per-tooth peak
    /// over its discs and plates, N, signed as the impacts' (negative when body a, or a
    /// pack's carrier, leads); 0 without impacts.
    pub largest_peak_n: f64,
    /// A thermal resolved pack's temperatures (K) and heat balance (J) over the run (its pack
    /// file's `[thermal]`, MODEL.md section 9; absent for other couplings).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thermal: Option<crate::ThermalSummary>,
    /// A resolved pack's figures window by window, if asked ([`NetworkRequest::windows_s`];
    /// its bodies in pack order, named as in the pack file).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub windows: Vec<crate::WindowRow>,
    /// A pack's discs, then its plates, each with its impacts (absent for other kinds).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub pack_bodies: Vec<PackBodySummary>,
    /// The smallest torque on its body a over the samples, N m.
    pub min_torque_n_m: f64,
    /// The largest torque on its body a over the samples, N m.
    pub max_torque_n_m: f64,
    /// Every mode change after t = 0, in time order.
    pub changes: Vec<ModeChange>,
}

/// One disc's or plate's results in a pack on a network.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackBodySummary {
    /// Its name in the pack scene.
    pub name: String,
    /// Its tooth impacts (closed contacts) over the run.
    pub impacts: u64,
    /// Its largest per-tooth peak, N, signed as in Hu et al. eq (6) (negative when its
    /// carrier leads); 0 without impacts.
    pub largest_peak_n: f64,
    /// Fatigue damage of its spline teeth per hour of this duty, 1/h (>= 0): the rainflow
    /// cycles of its per-tooth load (its samples and impacts, as a pack run counts them)
    /// against the S-N curve of the pack file's `fatigue.*` and `material.*` (MODEL.md
    /// section 7).
    pub damage_rate_per_h: f64,
    /// Its teeth's life at this duty, h (`None`: no damage, unlimited).
    pub life_h: Option<f64>,
}

/// One body's results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodySummary {
    /// Its name.
    pub name: String,
    /// Speed at the end, rad/s.
    pub final_speed_rad_s: f64,
    /// Angle at the end, rad.
    pub final_angle_rad: f64,
}

/// Where the energy went, J (MODEL.md section 8, "Energy"): the engine's own balance
/// ([`clutchpack_model::network::NetworkEnergy`], its fields flattened into the JSON) and its
/// residual.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergySummary {
    /// The balance's terms, J.
    #[serde(flatten)]
    pub terms: clutchpack_model::network::NetworkEnergy,
    /// `drive + prescribed + load - drag - heat - mesh work - damper loss - spring energy
    /// change - pack loss - kinetic change`, J (zero to the integrator's tolerance).
    pub residual_j: f64,
}

/// A network run's summary (`run --summary-json` of a network scene).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NetworkSummary {
    /// The scene's name.
    pub scene: String,
    /// The engine (`reference` or `multibody`).
    pub engine: &'static str,
    /// Simulated time, s.
    pub simulated_s: f64,
    /// Wall time of the run, s.
    pub wall_time_s: f64,
    /// Accepted steps.
    pub steps: u64,
    /// Events located (mode changes and the signals' breakpoints).
    pub events: u64,
    /// Whether the run was stopped before its end (a signal).
    pub stopped: bool,
    /// Per body, in the scene's order.
    pub bodies: Vec<BodySummary>,
    /// Per coupling, in the scene's order.
    pub couplings: Vec<CouplingSummary>,
    /// The energy balance.
    pub energy: EnergySummary,
    /// An automatic's shifts as the run made them (a `[transmission]` with a schedule;
    /// otherwise empty and not written).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shifts: Vec<crate::shifts::ShiftSummary>,
}

/// A network run's outcome.
#[derive(Debug, Clone)]
pub struct NetworkOutcome {
    /// The summary.
    pub summary: NetworkSummary,
    /// Every sample, if asked ([`NetworkRequest::keep_history`]).
    pub history: Vec<NetworkSample>,
    /// Every tooth impact as `(name, t_peak s, peak N)`, if the history is kept: a gear
    /// mesh's by its coupling's name, a pack's disc's or plate's as `<pack>/discs/<disc>` or
    /// `<pack>/plates/<plate>` (the recording's names on `/network/impacts`).
    pub impacts: Vec<(String, f64, f64)>,
    /// The recording's path, if one was asked ([`NetworkRequest::recording`]).
    pub recording: Option<std::path::PathBuf>,
    /// Every resolved pack body's counted load cycles and load spectra, named
    /// `<pack>/discs/<disc>` or `<pack>/plates/<plate>`, if asked
    /// ([`NetworkRequest::keep_cycles`]; `run --fatigue-json`).
    pub cycles: Vec<clutchpack_analysis::DiscCycles>,
}

/// The multibody engine's longest step on a network scene, s: `simulation.max_step_s`, at most
/// 1e-4 s (the engine is second order, its events landed on: at 1e-4 s CoupledClutches' mode
/// changes are within 5.9e-8 s and its speeds within 8.1e-8 of the reference engine's,
/// `crates/multibody/tests/network.rs`; a gear mesh in contact steps shorter).
pub fn multibody_step_s(scene: &Scene) -> f64 {
    scene.simulation.max_step_s.min(MULTIBODY_NETWORK_STEP_S)
}

/// The longest fixed step of the multibody engine on a network, s.
pub const MULTIBODY_NETWORK_STEP_S: f64 = 1e-4;

/// Runs a network scene on `engine` ([`crate::Simulation::run`] of a network, which chose
/// it): the reference engine at the scene's tolerance and longest step, the multibody engine
/// at the fixed step [`multibody_step_s`]. A pack scene is bad input.
pub(crate) fn run(
    scene: &Scene,
    engine: EngineChoice,
    req: NetworkRequest,
) -> Result<NetworkOutcome> {
    let Some(net) = &scene.network else {
        return Err(crate::simulation::not_a_network(&scene.name));
    };
    let sim = &scene.simulation;
    if req.windows_s.is_some() && !net.couplings.iter().any(|c| c.law().own_bodies().is_some()) {
        return Err(Error::BadInput(format!(
            "windows (`--windows`, `windows_s`): {} has no resolved pack (kind = \"pack\") \
             whose bodies' figures they would give",
            scene.name
        )));
    }
    let mut keep =
        Keep::new(None, req.keep_history).with_packs(scene, req.keep_cycles, req.windows_s);
    if let Some(path) = &req.impacts_csv {
        keep = keep.with_impacts_csv(path, scene)?;
    }
    keep.recorder = start_recording(scene, engine, req.recording.as_ref(), None)?;
    let mut obs = Obs {
        keep: &mut keep,
        stop: req.stop,
        progress: req.progress,
    };
    let start = std::time::Instant::now();
    // the shifts' starts, where each shift's energy balance is taken
    let stops = obs
        .keep
        .shifts
        .as_ref()
        .map_or_else(Vec::new, |p| p.starts_s());
    let run = match engine {
        EngineChoice::Reference => clutchpack_reference::network::NetworkStepper::new(
            net,
            sim.duration_s,
            &reference_options(scene),
            &mut obs,
        )
        .map(|s| Box::new(s) as Box<dyn NetworkSession>),
        EngineChoice::Multibody => {
            let options = clutchpack_multibody::network::NetworkStepOptions {
                step_s: multibody_step_s(scene),
                record_rate_hz: sim.record_rate_hz,
            };
            clutchpack_multibody::network::NetworkStepper::new(
                net,
                sim.duration_s,
                &options,
                &mut obs,
            )
            .map(|s| Box::new(s) as Box<dyn NetworkSession>)
        }
    }
    .and_then(|run| run_stopping(run, sim.duration_s, &stops, &mut obs));
    let (run, energies) = run.map_err(|source| engine_failed(scene, engine, &mut keep, source))?;
    if let Some(p) = keep.shifts.as_mut() {
        p.set_energies(energies);
    }
    conclude(scene, engine, keep, run, start.elapsed().as_secs_f64())
}

/// Runs `run` to `duration_s` (s), stopping at each of `stops_s` (s, increasing) to take the
/// energy balance there: from a copy of the run finished at that instant, its output to no
/// observer. The reference engine's run is the same bit for bit whatever its calls; the
/// multibody engine's lands a step on each call's end, which the shifts' starts already are
/// (breakpoints of the schedule's signals), so that both give the run without stops. A run
/// stopped (`obs`'s stop or recording error) takes no more balances.
fn run_stopping(
    mut run: Box<dyn NetworkSession>,
    duration_s: f64,
    stops_s: &[f64],
    obs: &mut Obs,
) -> std::result::Result<(NetworkRun, Vec<(f64, NetworkEnergy)>), EngineError> {
    let mut energies = Vec::new();
    for &t in stops_s.iter().filter(|t| **t < duration_s) {
        run.advance_to(t, obs)?;
        if obs.keep.stopped || obs.keep.record_failed() {
            // stopped there: no step more
            return Ok((run.finish_boxed(obs), energies));
        }
        energies.push((
            t,
            run.boxed_clone()
                .finish_boxed(&mut clutchpack_model::NullObserver)
                .energy,
        ));
    }
    run.advance_to(duration_s, obs)?;
    Ok((run.finish_boxed(obs), energies))
}

/// The reference engine's settings for a network scene: its tolerance, longest step and
/// sample rate.
pub(crate) fn reference_options(scene: &Scene) -> NetworkOptions {
    let sim = &scene.simulation;
    NetworkOptions {
        tolerance: sim.tolerance,
        max_step_s: sim.max_step_s,
        record_rate_hz: sim.record_rate_hz,
    }
}

/// The recording of a network run, if asked.
/// `co_simulation`: the inputs the caller drives and where the run ends, for a run advanced
/// call by call (its recording says so, as a pack's co-simulated recording does).
pub(crate) fn start_recording(
    scene: &Scene,
    engine: EngineChoice,
    request: Option<&crate::RecordingRequest>,
    co_simulation: Option<(&[String], Option<f64>)>,
) -> Result<Option<Recorder>> {
    let (Some(r), Some(net)) = (request, &scene.network) else {
        return Ok(None);
    };
    let mut info = crate::summary::run_info(scene, engine.name(), r.scene_path.as_deref());
    if let Some((driven, stop_time_s)) = co_simulation {
        crate::session::co_simulation_params(&mut info.params, driven, stop_time_s);
    }
    let mut recorder = Recorder::create_network_output(&r.path, r.replace, &info, net, &r.options)?;
    if let Some(tr) = &scene.transmission {
        recorder.set_transmission(tr)?;
    }
    Ok(Some(recorder))
}

/// An engine failure as the error to report, the recording finished first (it holds the run
/// up to the failure, and the message says where it is).
pub(crate) fn engine_failed(
    scene: &Scene,
    engine: EngineChoice,
    keep: &mut Keep,
    source: clutchpack_model::EngineError,
) -> Error {
    let recorded = keep.recorder.take().map(|r| r.finish(None));
    // the impacts CSV holds the run up to the failure too (a write error of its own is lost
    // behind the engine's, which is the one to report)
    let _ = keep.finish_csv();
    let kept = match recorded {
        Some(Ok(p)) => format!(" (the recording {} holds the run up to there)", p.display()),
        _ => String::new(),
    };
    Error::Engine {
        context: format!("{} ({} engine, network){kept}", scene.name, engine.name()),
        source,
    }
}

/// The outcome of a finished (or stopped) network run: its summary from what `keep` kept and
/// the engine's `run`, and the recording finished with the summary attached.
pub(crate) fn conclude(
    scene: &Scene,
    engine: EngineChoice,
    mut keep: Keep,
    run: clutchpack_model::network::NetworkRun,
    wall_time_s: f64,
) -> Result<NetworkOutcome> {
    let Some(net) = &scene.network else {
        return Err(crate::simulation::not_a_network(&scene.name));
    };
    if let Some(e) = keep.take_record_error() {
        return Err(e.into());
    }
    keep.finish_csv()?;
    let last = &run.last;
    let mut cycles = Vec::new();
    let mut windows = std::collections::BTreeMap::new();
    for (k, (mut w, names)) in std::mem::take(&mut keep.windows) {
        if let Some(collector) = keep.pack_fatigue.get(&k) {
            if last.t_s > w.end_s() - w.len_s() {
                w.close(last.t_s, &names, collector);
            }
        }
        windows.insert(k, w.rows);
    }
    let fatigue = pack_fatigue(scene, net, &mut keep, last.t_s, &mut cycles);
    let couplings = net
        .couplings
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let changes: Vec<ModeChange> = keep
                .events
                .iter()
                .filter(|e| e.coupling == k && e.t_s > 0.0)
                .map(|e| ModeChange {
                    t_s: e.t_s,
                    from: e.from.label(),
                    to: e.to.label(),
                    torque_steps_n_m: keep
                        .steps
                        .iter()
                        .find(|(t, _)| *t == e.t_s)
                        .map_or_else(Vec::new, |(_, s)| s.clone()),
                })
                .collect();
            CouplingSummary {
                name: c.name.clone(),
                kind: clutchpack_record::coupling_kind_name(&c.kind),
                heat_j: run.heat_j[k],
                final_torque_n_m: last.torque_n_m[k],
                final_mode: last.mode[k]
                    .map(ClutchMode::label)
                    .or(keep.pack_modes.get(&k).map(|m| m.0)),
                lock_times_s: keep
                    .events
                    .iter()
                    .filter(|e| e.coupling == k && e.to == ClutchMode::Locked)
                    .map(|e| e.t_s)
                    .chain(
                        keep.pack_modes
                            .get(&k)
                            .into_iter()
                            .flat_map(|m| m.1.clone()),
                    )
                    .collect(),
                impacts: keep.impacts.get(&k).map_or(0, |m| m.0),
                largest_peak_n: keep.impacts.get(&k).map_or(0.0, |m| m.1),
                windows: windows.remove(&k).unwrap_or_default(),
                thermal: run
                    .pack_thermal
                    .iter()
                    .find(|(j, _)| *j == k)
                    .map(|(_, r)| {
                        let names = c.law().own_bodies().map_or_else(Vec::new, |o| o.names());
                        crate::ThermalSummary::new(r, &names)
                    }),
                pack_bodies: c.law().own_bodies().map_or_else(Vec::new, |own| {
                    own.iter()
                        .enumerate()
                        .map(|(i, d)| {
                            let m = keep.pack_bodies.get(&(k, i)).copied().unwrap_or((0, 0.0));
                            let f = fatigue.get(&k).and_then(|f| f.get(i));
                            PackBodySummary {
                                name: d.name.clone(),
                                impacts: m.0,
                                largest_peak_n: m.1,
                                damage_rate_per_h: f.map_or(0.0, |f| f.lumped.damage_rate_per_h),
                                life_h: f.and_then(|f| f.lumped.life_h),
                            }
                        })
                        .collect()
                }),
                min_torque_n_m: keep.range.get(k).map_or(0.0, |r| r.0),
                max_torque_n_m: keep.range.get(k).map_or(0.0, |r| r.1),
                changes,
            }
        })
        .collect();
    let e = run.energy;
    let summary = NetworkSummary {
        scene: scene.name.clone(),
        engine: engine.name(),
        simulated_s: last.t_s,
        wall_time_s,
        steps: run.steps,
        events: run.events,
        stopped: keep.stopped,
        bodies: net
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| BodySummary {
                name: b.name.clone(),
                final_speed_rad_s: last.speed_rad_s[i],
                final_angle_rad: last.angle_rad[i],
            })
            .collect(),
        couplings,
        energy: EnergySummary {
            terms: e,
            residual_j: e.residual_j(),
        },
        shifts: match (&keep.shifts, &scene.transmission) {
            (Some(p), Some(tr)) => p.report(net, tr, &keep.events, &run.energy),
            _ => Vec::new(),
        },
    };
    let recording = match keep.recorder.take() {
        Some(mut r) => {
            // a deterministic recording holds no wall time (two runs give the same bytes)
            let wall_time_s = if r.deterministic() {
                0.0
            } else {
                summary.wall_time_s
            };
            let recorded = NetworkSummary {
                wall_time_s,
                ..summary.clone()
            };
            let json = serde_json::to_vec_pretty(&recorded).map_err(|e| {
                Error::BadInput(format!("the summary of {} as JSON: {e}", scene.name))
            })?;
            r.set_summary_json(json);
            Some(r.finish(None)?)
        }
        None => None,
    };
    let impacts = keep
        .impact_log
        .iter()
        .map(|&(k, body, t, peak)| {
            let name = clutchpack_record::impact_name(net, k, body);
            (name, t, peak)
        })
        .collect();
    Ok(NetworkOutcome {
        summary,
        impacts,
        history: keep.history,
        recording,
        cycles,
    })
}
