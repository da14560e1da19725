//! A network scene's run (`[[bodies]]`, MODEL.md section 8): the reference engine or the
//! multibody engine on the scene's driveline (the engine asked, else `simulation.engine`, else
//! the reference), its clutches' mode changes and heat, the bodies' speeds and the energy
//! balance, as one serializable summary (`run --summary-json`) and, if asked, the sampled
//! history (for the figure). Both engines give the model's output types
//! ([`clutchpack_model::network::NetworkRun`]), so the summary is built the same way.

use crate::{Error, Result};
use clutchpack_model::network::{ClutchEvent, ClutchMode, NetworkObserver, NetworkSample};
use clutchpack_record::NetworkRecorder;
use clutchpack_reference::network::NetworkOptions;
use clutchpack_scene::{EngineChoice, Scene};
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a network run keeps beside its summary.
#[derive(Default)]
pub struct NetworkRequest<'a> {
    /// Keep every sample (the figure's data; memory grows with the run).
    pub keep_history: bool,
    /// Record the run (MCAP: every body, coupling and clutch event, the 3D view;
    /// [`clutchpack_record::NetworkRecorder`]). Of the options the compression, chunk size and
    /// determinism apply.
    pub recording: Option<crate::RecordingRequest>,
    /// Set to stop the run (a signal); the outcome then holds what ran.
    pub stop: Option<&'a AtomicBool>,
    /// Called with the simulated time reached, s.
    pub progress: Option<&'a mut dyn FnMut(f64)>,
    /// Write every tooth impact (a gear mesh's, a pack's disc's or plate's) to this CSV file
    /// as it comes: `name,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n`, named as
    /// [`NetworkOutcome::impacts`] names them; complete up to a stop or a failure.
    pub impacts_csv: Option<std::path::PathBuf>,
    /// Keep every resolved pack body's counted load cycles for [`NetworkOutcome::cycles`]
    /// (memory grows with the run; without, the fatigue is summed as it is counted).
    pub keep_cycles: bool,
    /// Give every resolved pack's figures window by window, windows of this length in s
    /// (`run --windows S`; [`CouplingSummary::windows`]).
    pub windows_s: Option<f64>,
}

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
    /// `drive + load - drag - heat - mesh work - damper loss - spring energy change - pack
    /// loss - kinetic change`, J (zero to the integrator's tolerance).
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

/// What a network run keeps as it goes (its own state, across the calls of a
/// [`NetworkSimulation`]).
#[derive(Default)]
pub(crate) struct Keep {
    keep_history: bool,
    /// Keep every pack body's counted cycles ([`NetworkRequest::keep_cycles`]).
    keep_cycles: bool,
    events: Vec<ClutchEvent>,
    /// (t, each coupling's torque step) at each switching instant.
    steps: Vec<(f64, Vec<f64>)>,
    /// Per coupling: the smallest and largest torque sampled.
    range: Vec<(f64, f64)>,
    /// Per coupling: (impacts, largest peak) of a gear mesh or of a pack's bodies together.
    impacts: std::collections::HashMap<usize, (u64, f64)>,
    /// Per (pack coupling, body in the pack): (impacts, largest peak).
    pack_bodies: std::collections::HashMap<(usize, usize), (u64, f64)>,
    /// Per pack coupling: its bodies' load histories for the fatigue (samples and impacts),
    /// summed on each body's S-N curve as they are counted ([`Keep::with_packs`]).
    pack_fatigue: std::collections::BTreeMap<usize, clutchpack_analysis::FatigueCollector>,
    /// The impacts CSV being written, if asked, and each coupling's first row name's index
    /// in it (a mesh's name, a pack's first body's).
    csv: Option<(crate::collector::ImpactsCsv, Vec<usize>)>,
    /// Per pack coupling, if asked: its windows and its bodies' names.
    windows: std::collections::BTreeMap<usize, (crate::windows::Windows, Vec<String>)>,
    /// Per pack coupling: its faces' mode as a clutch's label ("free", "slipping",
    /// "locked"), and the instants all its faces locked.
    pack_modes: std::collections::HashMap<usize, (&'static str, Vec<f64>)>,
    history: Vec<NetworkSample>,
    /// With the history: every impact as (coupling, body in a pack, t_peak s, peak N).
    impact_log: Vec<(usize, Option<usize>, f64, f64)>,
    stopped: bool,
    /// The recording, until its first error.
    pub recorder: Option<NetworkRecorder>,
    /// The recording's first error (it then stops the run).
    pub record_error: Option<clutchpack_record::RecordError>,
}

impl Keep {
    /// A fresh keep that records with `recorder` (if any) and keeps every sample if
    /// `keep_history`.
    pub fn new(recorder: Option<NetworkRecorder>, keep_history: bool) -> Keep {
        Keep {
            keep_history,
            recorder,
            ..Keep::default()
        }
    }

    /// Collects every resolved pack's bodies' fatigue on their S-N curves (the pack files'
    /// parameters), keeping every counted cycle too if `keep_cycles`, and their figures in
    /// windows of `windows_s` (s) if given.
    pub fn with_packs(mut self, scene: &Scene, keep_cycles: bool, windows_s: Option<f64>) -> Keep {
        self.keep_cycles = keep_cycles;
        if let Some(net) = &scene.network {
            for (k, (names, params)) in pack_params(scene, net) {
                let curves = crate::fatigue::curves(&params);
                if let Some(len_s) = windows_s {
                    let w = crate::windows::Windows::new(len_s, params.clone());
                    self.windows.insert(k, (w, names));
                }
                self.pack_fatigue.insert(
                    k,
                    clutchpack_analysis::FatigueCollector::summing(curves, keep_cycles),
                );
            }
        }
        self
    }

    /// Also writes every tooth impact to the CSV file `path` as it comes
    /// ([`NetworkRequest::impacts_csv`]).
    pub fn with_impacts_csv(mut self, path: &std::path::Path, scene: &Scene) -> Result<Keep> {
        let Some(net) = &scene.network else {
            return Ok(self);
        };
        let (mut names, mut first) = (Vec::new(), Vec::new());
        for (k, c) in net.couplings.iter().enumerate() {
            first.push(names.len());
            match c.pack() {
                Some(p) => names.extend(
                    (0..p.discs.len() + p.plates.len())
                        .map(|i| clutchpack_record::impact_name(net, k, Some(i))),
                ),
                None => names.push(clutchpack_record::impact_name(net, k, None)),
            }
        }
        let csv = crate::collector::ImpactsCsv::create(path, &names, "name")?;
        self.csv = Some((csv, first));
        Ok(self)
    }

    /// Writes `e`, an impact of coupling `coupling` (of its body `body` in a pack), to the
    /// impacts CSV if one is written.
    fn csv_row(&mut self, coupling: usize, body: Option<usize>, e: &clutchpack_model::ImpactEvent) {
        if let Some((csv, first)) = self.csv.as_mut() {
            let disc = first
                .get(coupling)
                .map_or(usize::MAX, |f| f + body.unwrap_or(0));
            csv.row(&clutchpack_model::ImpactEvent { disc, ..*e });
        }
    }

    /// Completes the impacts CSV (if one is written) and renames it into place.
    pub(crate) fn finish_csv(&mut self) -> Result<()> {
        match self.csv.take() {
            Some((csv, _)) => csv.finish(),
            None => Ok(()),
        }
    }

    /// Runs `write` on the recorder, keeping its first error (after which nothing more is
    /// recorded and the run stops).
    fn record(
        &mut self,
        write: impl FnOnce(
            &mut NetworkRecorder,
        ) -> std::result::Result<(), clutchpack_record::RecordError>,
    ) {
        if let Some(r) = self.recorder.as_mut() {
            if let Err(e) = write(r) {
                self.record_error = Some(e);
            }
        }
    }

    /// A copy without the recording (a saved state of a session that does not record).
    pub fn clone_unrecorded(&self) -> Keep {
        Keep {
            keep_history: self.keep_history,
            keep_cycles: self.keep_cycles,
            events: self.events.clone(),
            steps: self.steps.clone(),
            range: self.range.clone(),
            impacts: self.impacts.clone(),
            pack_bodies: self.pack_bodies.clone(),
            pack_modes: self.pack_modes.clone(),
            pack_fatigue: self.pack_fatigue.clone(),
            csv: None,
            windows: std::collections::BTreeMap::new(),
            history: self.history.clone(),
            impact_log: self.impact_log.clone(),
            stopped: self.stopped,
            recorder: None,
            record_error: None,
        }
    }
}

/// Counts one more impact of peak `peak_n` (N) in `(impacts, largest peak)`, keeping the
/// peak of largest magnitude with its sign.
fn tally(m: &mut (u64, f64), peak_n: f64) {
    m.0 += 1;
    if peak_n.abs() > m.1.abs() {
        m.1 = peak_n;
    }
}

/// The observer of one call of an engine: what it gives goes into `keep`; `stop` and
/// `progress` are the call's.
pub(crate) struct Obs<'k, 'a> {
    pub keep: &'k mut Keep,
    pub stop: Option<&'a AtomicBool>,
    pub progress: Option<&'a mut dyn FnMut(f64)>,
}

impl NetworkObserver for Obs<'_, '_> {
    fn sample(&mut self, s: &NetworkSample) {
        let k = &mut *self.keep;
        k.record(|r| r.write_sample(s));
        k.range
            .resize(s.torque_n_m.len(), (f64::INFINITY, f64::NEG_INFINITY));
        for (r, t) in k.range.iter_mut().zip(&s.torque_n_m) {
            *r = (r.0.min(*t), r.1.max(*t));
        }
        if k.keep_history {
            k.history.push(s.clone());
        }
    }
    fn clutch_event(&mut self, e: &ClutchEvent) {
        self.keep.record(|r| r.write_clutch_event(e));
        self.keep.events.push(*e);
    }
    fn mesh_impact(&mut self, e: &clutchpack_model::ImpactEvent) {
        self.keep.record(|r| r.write_mesh_impact(e));
        self.keep.csv_row(e.disc, None, e);
        if self.keep.keep_history {
            self.keep
                .impact_log
                .push((e.disc, None, e.t_peak_s, e.peak_n));
        }
        tally(self.keep.impacts.entry(e.disc).or_default(), e.peak_n);
    }
    fn pack_impact(&mut self, coupling: usize, e: &clutchpack_model::ImpactEvent) {
        self.keep.record(|r| r.write_pack_impact(coupling, e));
        self.keep.csv_row(coupling, Some(e.disc), e);
        if let Some((w, _)) = self.keep.windows.get_mut(&coupling) {
            w.impact(e);
        }
        self.keep
            .pack_fatigue
            .entry(coupling)
            .or_default()
            .impact(e);
        if self.keep.keep_history {
            self.keep
                .impact_log
                .push((coupling, Some(e.disc), e.t_peak_s, e.peak_n));
        }
        tally(self.keep.impacts.entry(coupling).or_default(), e.peak_n);
        let body = self.keep.pack_bodies.entry((coupling, e.disc));
        tally(body.or_default(), e.peak_n);
    }
    fn pack_sample(
        &mut self,
        coupling: usize,
        t: f64,
        angle_rad: &[f64],
        speed_rad_s: &[f64],
        load_n: &[f64],
    ) {
        self.keep
            .record(|r| r.write_pack_sample(coupling, t, angle_rad, speed_rad_s, load_n));
        let sample = clutchpack_model::Sample {
            t_s: t,
            discs: load_n
                .iter()
                .map(|&l| clutchpack_model::DiscSample {
                    load_n: l,
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        };
        let collector = self.keep.pack_fatigue.entry(coupling).or_default();
        if let Some((w, names)) = self.keep.windows.get_mut(&coupling) {
            // the windows that ended before this sample close on the samples up to their end
            while t > w.end_s() {
                let t1 = w.end_s();
                w.close(t1, names, collector);
            }
        }
        collector.sample(&sample);
    }
    fn pack_temperatures(&mut self, coupling: usize, t: f64, temperatures_k: &[f64]) {
        self.keep
            .record(|r| r.write_pack_temperatures(coupling, t, temperatures_k));
        if let Some((w, _)) = self.keep.windows.get_mut(&coupling) {
            if let Some((oil, bodies)) = temperatures_k.split_last() {
                w.temperatures(bodies, *oil);
            }
        }
    }
    fn pack_faces(&mut self, coupling: usize, t: f64, locked: usize, clamped: usize, faces: usize) {
        let mode = if locked == faces {
            "locked"
        } else if clamped > 0 {
            "slipping"
        } else {
            "free"
        };
        let m = self
            .keep
            .pack_modes
            .entry(coupling)
            .or_insert(("free", Vec::new()));
        if mode == "locked" && m.0 != "locked" {
            m.1.push(t);
        }
        m.0 = mode;
    }
    fn switched(&mut self, before: &NetworkSample, after: &NetworkSample) {
        let steps = after
            .torque_n_m
            .iter()
            .zip(&before.torque_n_m)
            .map(|(a, b)| a - b)
            .collect();
        self.keep.steps.push((after.t_s, steps));
    }
    fn progress(&mut self, t: f64) -> bool {
        if let Some(p) = self.progress.as_mut() {
            p(t);
        }
        let stop = self.stop.is_some_and(|s| s.load(Ordering::Relaxed));
        self.keep.stopped |= stop;
        !stop && self.keep.record_error.is_none()
    }
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

/// Runs a network scene on the engine `asked` (e.g. `--engine`), else the scene's
/// `simulation.engine`, else the reference engine: the reference engine at the scene's
/// tolerance and longest step, the multibody engine at the fixed step
/// [`multibody_step_s`]. A pack scene is bad input.
pub fn run_network_scene(
    scene: &Scene,
    asked: Option<EngineChoice>,
    req: NetworkRequest,
) -> Result<NetworkOutcome> {
    let Some(net) = &scene.network else {
        return Err(Error::BadInput(format!(
            "{} is a pack scene, not a network ([[bodies]])",
            scene.name
        )));
    };
    let engine = scene.engine(asked, &scene.name)?;
    let sim = &scene.simulation;
    crate::windows::check(req.windows_s, sim.duration_s)?;
    if req.windows_s.is_some() && !net.couplings.iter().any(|c| c.pack().is_some()) {
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
    let run = match engine {
        EngineChoice::Reference => clutchpack_reference::network::run_network(
            net,
            sim.duration_s,
            &reference_options(scene),
            &mut obs,
        ),
        EngineChoice::Multibody => {
            let options = clutchpack_multibody::network::NetworkStepOptions {
                step_s: multibody_step_s(scene),
                record_rate_hz: sim.record_rate_hz,
            };
            clutchpack_multibody::network::run_network(net, sim.duration_s, &options, &mut obs)
        }
    };
    let run = run.map_err(|source| engine_failed(scene, engine, &mut keep, source))?;
    conclude(scene, engine, keep, run, start.elapsed().as_secs_f64())
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
) -> Result<Option<NetworkRecorder>> {
    let (Some(r), Some(net)) = (request, &scene.network) else {
        return Ok(None);
    };
    let mut info = crate::summary::run_info(scene, engine.name(), r.scene_path.as_deref());
    if let Some((driven, stop_time_s)) = co_simulation {
        crate::session::co_simulation_params(&mut info.params, driven, stop_time_s);
    }
    Ok(Some(NetworkRecorder::create_output(
        &r.path, r.replace, &info, net, &r.options,
    )?))
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

/// Every resolved pack's bodies' names and their spline and fatigue parameters (the pack
/// files' `fatigue.*` and `material.*`: the scene's `fatigue` holds every pack's bodies in
/// coupling order), by coupling.
fn pack_params(
    scene: &Scene,
    net: &clutchpack_model::network::Network,
) -> std::collections::BTreeMap<usize, (Vec<String>, Vec<FatigueInput>)> {
    let mut out = std::collections::BTreeMap::new();
    let mut offset = 0;
    for (k, c) in net.couplings.iter().enumerate() {
        let Some(p) = c.pack() else { continue };
        let bodies: Vec<&clutchpack_model::DiscModel> = p.discs.iter().chain(&p.plates).collect();
        let params: Vec<_> = bodies
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let f = scene.fatigue.get(offset + i).copied().unwrap_or_default();
                (d.spline, f)
            })
            .collect();
        offset += bodies.len();
        let names = bodies.iter().map(|d| d.name.clone()).collect();
        out.insert(k, (names, params));
    }
    out
}

/// A body's spline geometry and fatigue parameters.
type FatigueInput = (
    clutchpack_model::SplineGeometry,
    clutchpack_model::FatigueParams,
);

/// Every resolved pack's bodies' fatigue from what `keep` collected over `duration_s` of
/// duty, by coupling; and with `cycles`, every body's counted cycles
/// ([`NetworkOutcome::cycles`]).
fn pack_fatigue(
    scene: &Scene,
    net: &clutchpack_model::network::Network,
    keep: &mut Keep,
    duration_s: f64,
    cycles: &mut Vec<clutchpack_analysis::DiscCycles>,
) -> std::collections::BTreeMap<usize, Vec<clutchpack_analysis::DiscFatigue>> {
    let mut out = std::collections::BTreeMap::new();
    for (k, (names, params)) in pack_params(scene, net) {
        let collector = keep.pack_fatigue.remove(&k).unwrap_or_default();
        if duration_s <= 0.0 {
            continue;
        }
        let histories = collector.finish(names.len());
        if keep.keep_cycles {
            cycles.extend(names.iter().zip(&histories).enumerate().map(|(i, (_, h))| {
                let name = clutchpack_record::impact_name(net, k, Some(i));
                clutchpack_analysis::disc_cycles(&name, h, duration_s)
            }));
        }
        out.insert(
            k,
            crate::fatigue::assess_histories(&histories, &params, &names, duration_s),
        );
    }
    out
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
        return Err(Error::BadInput(format!("{} is not a network", scene.name)));
    };
    if let Some(e) = keep.record_error.take() {
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
                        let names: Vec<String> = c.pack().map_or_else(Vec::new, |p| {
                            p.discs
                                .iter()
                                .chain(&p.plates)
                                .map(|d| d.name.clone())
                                .collect()
                        });
                        crate::ThermalSummary::new(r, &names)
                    }),
                pack_bodies: c.pack().map_or_else(Vec::new, |p| {
                    p.discs
                        .iter()
                        .chain(&p.plates)
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
    };
    let recording = match keep.recorder.take() {
        Some(r) => {
            let json = serde_json::to_vec_pretty(&summary).map_err(|e| {
                Error::BadInput(format!("the summary of {} as JSON: {e}", scene.name))
            })?;
            Some(r.finish(Some(&json))?)
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
