//! What a network run keeps as it goes (`Keep`, fed by the engines through `Obs`, the
//! [`Observer`] of one call): the clutches' events and torque ranges, the tooth impacts'
//! tallies, the resolved packs' fatigue collectors, windows and impacts CSV, the samples when
//! asked; the recording (the one [`Recorder`], which observes the run beside it); and the
//! packs' fatigue at the run's end. `crate::network` builds
//! the summary from it.

use crate::Result;
use clutchpack_model::network::{ClutchEvent, ClutchMode, NetworkSample};
use clutchpack_model::Observer;
use clutchpack_record::Recorder;
use clutchpack_scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};

/// What a network run keeps as it goes (its own state, across the calls of a
/// [`crate::NetworkSimulation`]).
#[derive(Default)]
pub(crate) struct Keep {
    pub(crate) keep_history: bool,
    /// Keep every pack body's counted cycles ([`crate::NetworkRequest::keep_cycles`]).
    pub(crate) keep_cycles: bool,
    pub(crate) events: Vec<ClutchEvent>,
    /// (t, each coupling's torque step) at each switching instant.
    pub(crate) steps: Vec<(f64, Vec<f64>)>,
    /// Per coupling: the smallest and largest torque sampled.
    pub(crate) range: Vec<(f64, f64)>,
    /// Per coupling: (impacts, largest peak) of a gear mesh or of a pack's bodies together.
    pub(crate) impacts: std::collections::HashMap<usize, (u64, f64)>,
    /// Per (pack coupling, body in the pack): (impacts, largest peak).
    pub(crate) pack_bodies: std::collections::HashMap<(usize, usize), (u64, f64)>,
    /// Per pack coupling: its bodies' load histories for the fatigue (samples and impacts),
    /// summed on each body's S-N curve as they are counted ([`Keep::with_packs`]).
    pub(crate) pack_fatigue:
        std::collections::BTreeMap<usize, clutchpack_analysis::FatigueCollector>,
    /// The impacts CSV being written, if asked, and each coupling's first row name's index
    /// in it (a mesh's name, a pack's first body's).
    pub(crate) csv: Option<(crate::collector::ImpactsCsv, Vec<usize>)>,
    /// Per pack coupling, if asked: its windows and its bodies' names.
    pub(crate) windows: std::collections::BTreeMap<usize, (crate::windows::Windows, Vec<String>)>,
    /// Per pack coupling: its faces' mode as a clutch's label ("free", "slipping",
    /// "locked"), and the instants all its faces locked.
    pub(crate) pack_modes: std::collections::HashMap<usize, (&'static str, Vec<f64>)>,
    pub(crate) history: Vec<NetworkSample>,
    /// With the history: every impact as (coupling, body in a pack, t_peak s, peak N).
    pub(crate) impact_log: Vec<(usize, Option<usize>, f64, f64)>,
    pub(crate) stopped: bool,
    /// The recording (its first error stops the run: [`Keep::record_failed`]).
    pub recorder: Option<Recorder>,
    /// What an automatic's shifts need of the samples (a transmission with a schedule).
    pub(crate) shifts: Option<crate::shifts::ShiftProbe>,
}

impl Keep {
    /// A resolved pack's faces' mode now, as a clutch's (all locked: locked; some clamped:
    /// slipping; none: free); `None` for another coupling.
    pub(crate) fn pack_mode(&self, coupling: usize) -> Option<ClutchMode> {
        self.pack_modes.get(&coupling).map(|m| match m.0 {
            "locked" => ClutchMode::Locked,
            "slipping" => ClutchMode::Slipping(1),
            _ => ClutchMode::Free,
        })
    }

    /// A fresh keep that records with `recorder` (if any) and keeps every sample if
    /// `keep_history`.
    pub fn new(recorder: Option<Recorder>, keep_history: bool) -> Keep {
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
        if let (Some(net), Some(tr)) = (&scene.network, &scene.transmission) {
            self.shifts = crate::shifts::ShiftProbe::new(net, tr);
        }
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
    /// ([`crate::NetworkRequest::impacts_csv`]).
    pub fn with_impacts_csv(mut self, path: &std::path::Path, scene: &Scene) -> Result<Keep> {
        let Some(net) = &scene.network else {
            return Ok(self);
        };
        let (mut names, mut first) = (Vec::new(), Vec::new());
        for (k, c) in net.couplings.iter().enumerate() {
            first.push(names.len());
            match c.law().own_bodies() {
                Some(own) => names.extend(
                    (0..own.len()).map(|i| clutchpack_record::impact_name(net, k, Some(i))),
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

    /// Whether the recording met an error (the run then stops).
    pub(crate) fn record_failed(&self) -> bool {
        self.recorder.as_ref().is_some_and(|r| r.error().is_some())
    }

    /// The recording's first error, taken (nothing more is recorded).
    pub(crate) fn take_record_error(&mut self) -> Option<clutchpack_record::RecordError> {
        self.recorder.as_mut().and_then(Recorder::take_error)
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
            shifts: self.shifts.clone(),
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

/// The observer of one call of an engine: what it gives goes into `keep` and its recorder;
/// `stop` and `progress` are the call's.
pub(crate) struct Obs<'k, 'a> {
    pub keep: &'k mut Keep,
    pub stop: Option<&'a AtomicBool>,
    pub progress: Option<&'a mut dyn FnMut(f64)>,
}

impl Observer for Obs<'_, '_> {
    fn network_sample(&mut self, s: &NetworkSample) {
        let k = &mut *self.keep;
        if let Some(r) = &mut k.recorder {
            r.network_sample(s);
        }
        k.range
            .resize(s.torque_n_m.len(), (f64::INFINITY, f64::NEG_INFINITY));
        for (r, t) in k.range.iter_mut().zip(&s.torque_n_m) {
            *r = (r.0.min(*t), r.1.max(*t));
        }
        if k.keep_history {
            k.history.push(s.clone());
        }
        if let Some(p) = &mut k.shifts {
            p.sample(s);
        }
    }
    fn clutch_event(&mut self, e: &ClutchEvent) {
        if let Some(r) = &mut self.keep.recorder {
            r.clutch_event(e);
        }
        self.keep.events.push(*e);
    }
    fn mesh_impact(&mut self, e: &clutchpack_model::ImpactEvent) {
        if let Some(r) = &mut self.keep.recorder {
            r.mesh_impact(e);
        }
        self.keep.csv_row(e.disc, None, e);
        if self.keep.keep_history {
            self.keep
                .impact_log
                .push((e.disc, None, e.t_peak_s, e.peak_n));
        }
        tally(self.keep.impacts.entry(e.disc).or_default(), e.peak_n);
    }
    fn pack_impact(&mut self, coupling: usize, e: &clutchpack_model::ImpactEvent) {
        if let Some(r) = &mut self.keep.recorder {
            r.pack_impact(coupling, e);
        }
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
        if let Some(r) = &mut self.keep.recorder {
            r.pack_sample(coupling, t, angle_rad, speed_rad_s, load_n);
        }
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
        if let Some(r) = &mut self.keep.recorder {
            r.pack_temperatures(coupling, t, temperatures_k);
        }
        if let Some((w, _)) = self.keep.windows.get_mut(&coupling) {
            if let Some((oil, bodies)) = temperatures_k.split_last() {
                w.temperatures(bodies, *oil);
            }
        }
    }
    fn pack_faces(&mut self, coupling: usize, t: f64, locked: usize, clamped: usize, faces: usize) {
        if let Some(p) = &mut self.keep.shifts {
            p.pack_faces(coupling, t, locked, clamped, faces);
        }
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
        if let Some(r) = &mut self.keep.recorder {
            r.pack_faces(coupling, t, locked, clamped, faces);
        }
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
    fn wants_open_contacts(&mut self, t: f64) -> bool {
        self.keep
            .recorder
            .as_mut()
            .is_some_and(|r| r.wants_open_contacts(t))
    }
    fn open_contacts(
        &mut self,
        t: f64,
        open: &[(usize, Option<usize>, clutchpack_model::ImpactEvent)],
    ) {
        if let Some(r) = &mut self.keep.recorder {
            r.open_contacts(t, open);
        }
    }
    fn progress(&mut self, t: f64) -> bool {
        if let Some(p) = self.progress.as_mut() {
            p(t);
        }
        let stop = self.stop.is_some_and(|s| s.load(Ordering::Relaxed));
        self.keep.stopped |= stop;
        let failed = self.keep.recorder.as_mut().is_some_and(|r| r.progress(t));
        stop || failed
    }
}

/// Every resolved pack's bodies' names and their spline and fatigue parameters (the pack
/// files' `fatigue.*` and `material.*`: the scene's `fatigue` holds every pack's bodies in
/// coupling order), by coupling.
pub(crate) fn pack_params(
    scene: &Scene,
    net: &clutchpack_model::network::Network,
) -> std::collections::BTreeMap<usize, (Vec<String>, Vec<FatigueInput>)> {
    let mut out = std::collections::BTreeMap::new();
    let mut offset = 0;
    for (k, c) in net.couplings.iter().enumerate() {
        let Some(own) = c.law().own_bodies() else {
            continue;
        };
        let bodies: Vec<&clutchpack_model::DiscModel> = own.iter().collect();
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
/// ([`crate::NetworkOutcome::cycles`]).
pub(crate) fn pack_fatigue(
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
