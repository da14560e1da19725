//! The fatigue collector: what an engine emits (impact events, samples with per-tooth loads)
//! turned into the turning points of each coupling's and each resolved tooth's load history,
//! their cycles counted as they come and their Miner sums kept ([`DamageSum`]); the
//! assessment of what it collected is the parent module's.

use super::pending::PendingSamples;
use super::*;

/// Running Miner sums of one load history's cycles on one S-N curve: what an assessment
/// needs of the cycles ([`Assessment`]), taken one cycle at a time so that a long run keeps
/// no cycles. [`assess_cycles`] folds kept cycles through the same sums, so a history
/// assessed as it is counted and one assessed from its kept cycles give the same figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DamageSum {
    /// Root stress per newton of per-tooth load, Pa/N.
    stress_pa_per_n: f64,
    material: Material,
    /// Miner's sum `sum n_i / N(S_i)` so far (dimensionless).
    damage: f64,
    /// `sum n_i dF_i^k` in N^k, `k` the S-N slope: the damage-equivalent load's numerator.
    moment: f64,
    /// Counted cycles (half cycles count 0.5).
    cycles: f64,
}

impl DamageSum {
    /// No cycles yet, for root stress `stress_pa_per_n` (Pa/N) on `material`'s S-N curve.
    pub fn new(stress_pa_per_n: f64, material: Material) -> DamageSum {
        DamageSum {
            stress_pa_per_n,
            material,
            damage: 0.0,
            moment: 0.0,
            cycles: 0.0,
        }
    }

    /// Whether these sums are on the curve and stress factor asked for.
    pub fn is_for(&self, stress_pa_per_n: f64, material: &Material) -> bool {
        self.stress_pa_per_n == stress_pa_per_n && self.material == *material
    }

    /// Adds `count` cycles (0.5 for a half cycle) of load range `range_n` (N, >= 0).
    pub fn add(&mut self, range_n: f64, count: f64) {
        // Miner (MODEL.md section 7): D = sum n_i / N(S_i), S the stress amplitude c dF / 2
        let amplitude_pa = 0.5 * self.stress_pa_per_n * range_n;
        self.damage += count * self.material.damage_per_cycle(amplitude_pa);
        self.moment += count * range_n.abs().powf(self.material.slope);
        self.cycles += count;
    }

    /// The figures of the cycles added, over `duration_s` of simulated duty.
    pub fn assessment(&self, duration_s: f64) -> Assessment {
        let per_hour = if duration_s > 0.0 {
            HOUR_S / duration_s
        } else {
            0.0
        };
        let rate = self.damage * per_hour;
        // S_eq = (sum n_i dF_i^k per hour / N_D)^(1/k) (module doc): the summed moment as a
        // unit range counted that many times
        let eq = if self.cycles > 0.0 {
            damage_equivalent(
                [(1.0, self.moment * per_hour)],
                self.material.slope,
                self.material.knee_cycles,
            )
        } else {
            0.0
        };
        Assessment {
            damage: self.damage,
            damage_rate_per_h: rate,
            life_h: (rate > 0.0).then(|| self.material.critical_damage / rate),
            eq_load_range_n: eq,
            eq_stress_amplitude_pa: 0.5 * self.stress_pa_per_n * eq,
            cycles: self.cycles,
        }
    }
}

/// One load history counted as it is fed: its turning points go straight into the rainflow
/// counter, whose cycles are kept (when asked) and summed (when the S-N curve is known).
#[derive(Debug, Clone)]
struct HistoryTrack {
    points: TurningPoints,
    rainflow: Rainflow,
    out: HistoryCycles,
    keep: bool,
}

impl HistoryTrack {
    /// A history starting at 0 N (teeth free).
    fn new(keep: bool, sums: Option<DamageSum>) -> HistoryTrack {
        let mut t = HistoryTrack {
            points: TurningPoints::new(),
            rainflow: Rainflow::new(),
            out: HistoryCycles {
                sums,
                ..Default::default()
            },
            keep,
        };
        t.push(0.0);
        t
    }

    fn push(&mut self, x: f64) {
        if let Some(p) = self.points.push(x) {
            let (out, keep) = (&mut self.out, self.keep);
            self.rainflow.push(p, |c| out.count(c, keep));
        }
    }

    /// A contact's signed peak (N).
    fn peak(&mut self, p: f64) {
        self.out.contacts += 1;
        self.out.max_abs_peak_n = self.out.max_abs_peak_n.max(p.abs());
        if self.keep {
            self.out.peaks.push(p);
        }
    }

    fn finish(mut self) -> HistoryCycles {
        let keep = self.keep;
        if let Some(p) = self.points.last() {
            let out = &mut self.out;
            self.rainflow.push(p, |c| out.count(c, keep));
        }
        let mut out = self.out;
        self.rainflow.finish(|c| out.count(c, keep));
        out
    }
}

#[derive(Debug, Clone)]
struct ToothTrack {
    history: HistoryTrack,
    /// the open contact's signed peak
    open: Option<f64>,
}

impl ToothTrack {
    fn push(&mut self, x: f64) {
        self.history.push(x);
        // contact peaks as crate::cycles::contact_peaks, streamed
        let same = self
            .open
            .is_some_and(|p| x != 0.0 && (x > 0.0) == (p > 0.0));
        if same {
            if let Some(p) = self.open.as_mut() {
                if x.abs() > p.abs() {
                    *p = x;
                }
            }
        } else {
            if let Some(p) = self.open.take() {
                self.history.peak(p);
            }
            if x != 0.0 && x.is_finite() {
                self.open = Some(x);
            }
        }
    }
    fn finish(mut self) -> HistoryCycles {
        if let Some(p) = self.open.take() {
            self.history.peak(p);
        }
        self.history.finish()
    }
}

#[derive(Debug, Clone)]
struct DiscTrack {
    /// loaded samples (t s, load N) not yet claimed by a closed impact (bounded in memory,
    /// the older ones in a temporary file)
    pending: PendingSamples,
    lumped: HistoryTrack,
    teeth: Vec<ToothTrack>,
}

/// Collects the load histories of a run for its fatigue, counted as they come (an observer
/// of an engine, or fed by hand with [`Self::sample`] and [`Self::impact`]). Impacts of one
/// coupling must arrive in time order (engines emit them as they close).
///
/// Memory: the turning points go straight into each history's rainflow counter
/// ([`crate::cycles::Rainflow`]), so only the uncounted residue and the loaded samples of the
/// open contact are held. [`Self::new`] also keeps every counted cycle and contact peak (for
/// spectra: [`disc_cycles`]), which grows with the run; [`Self::summing`] keeps only the
/// running Miner sums of each coupling's S-N curve ([`DamageSum`]), which do not.
#[derive(Debug, Clone)]
pub struct FatigueCollector {
    discs: Vec<DiscTrack>,
    /// keep every cycle and peak
    keep: bool,
    /// per coupling: root stress per newton (Pa/N) and S-N curve, for the running sums
    curves: Vec<(f64, Material)>,
}

impl Default for FatigueCollector {
    fn default() -> Self {
        FatigueCollector::new()
    }
}

/// The counted cycles and contact peaks of one load history.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct HistoryCycles {
    /// Rainflow cycles of the signed per-tooth load, N ([`crate::cycles::rainflow`]), in the
    /// order they were counted; empty when the collector kept none
    /// ([`FatigueCollector::summing`]).
    pub cycles: Vec<Cycle>,
    /// Signed peak of each contact (impact), N; empty when the collector kept none.
    pub peaks: Vec<f64>,
    /// Contacts (impacts) counted.
    pub contacts: usize,
    /// Largest `|peak|` of the contacts, N (0 without contacts).
    pub max_abs_peak_n: f64,
    /// The running Miner sums, when the history was collected with its S-N curve.
    #[serde(skip)]
    pub sums: Option<DamageSum>,
}

impl HistoryCycles {
    fn count(&mut self, c: Cycle, keep: bool) {
        if let Some(s) = self.sums.as_mut() {
            s.add(c.range(), c.count);
        }
        if keep {
            self.cycles.push(c);
        }
    }

    /// The history's figures with root stress `stress_pa_per_n` (Pa/N) on `material`'s S-N
    /// curve over `duration_s`: from the running sums when they were collected on that curve,
    /// else from the kept cycles (a history collected by [`FatigueCollector::summing`] on
    /// another curve has none: assess it on its own curve).
    pub fn assessment(
        &self,
        stress_pa_per_n: f64,
        material: &Material,
        duration_s: f64,
    ) -> Assessment {
        match &self.sums {
            Some(s) if s.is_for(stress_pa_per_n, material) => s.assessment(duration_s),
            _ => assess_cycles(&self.cycles, stress_pa_per_n, material, duration_s),
        }
    }
}

/// The histories of one coupling.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DiscHistories {
    /// The coupling's per-tooth history from its impact events (every tooth of a lumped
    /// coupling; the mean tooth of a resolved one).
    pub lumped: HistoryCycles,
    /// Each tooth's own sampled history, where the engine resolved teeth (else empty).
    pub teeth: Vec<HistoryCycles>,
}

impl FatigueCollector {
    /// An empty collector that keeps every counted cycle and contact peak (couplings are
    /// added as they appear).
    pub fn new() -> FatigueCollector {
        FatigueCollector {
            discs: Vec::new(),
            keep: true,
            curves: Vec::new(),
        }
    }

    /// An empty collector that sums each coupling's damage on its S-N curve as the cycles are
    /// counted: `curves[i]` = (root stress per newton in Pa/N, material) of coupling `i`
    /// (`clutchpack_model::fatigue::stress_per_newton`). With `keep_cycles` it also keeps
    /// every cycle and peak ([`Self::new`]'s memory); without, its memory does not grow with
    /// the run. Couplings past the end of `curves` are counted without sums.
    pub fn summing(curves: Vec<(f64, Material)>, keep_cycles: bool) -> FatigueCollector {
        FatigueCollector {
            discs: Vec::new(),
            keep: keep_cycles,
            curves,
        }
    }

    fn disc(&mut self, i: usize) -> &mut DiscTrack {
        if self.discs.len() <= i {
            let (keep, curves) = (self.keep, &self.curves);
            let first = self.discs.len();
            self.discs.extend((first..=i).map(|k| {
                let sums = curves.get(k).map(|&(c, m)| DamageSum::new(c, m));
                DiscTrack {
                    pending: PendingSamples::default(),
                    lumped: HistoryTrack::new(keep, sums),
                    teeth: Vec::new(),
                }
            }));
        }
        &mut self.discs[i]
    }

    /// Takes a sample: loaded samples wait for their impact; resolved teeth feed their own
    /// histories.
    pub fn sample(&mut self, s: &Sample) {
        let keep = self.keep;
        for (i, d) in s.discs.iter().enumerate() {
            let t = self.disc(i);
            if d.load_n != 0.0 && d.load_n.is_finite() {
                t.pending.push(s.t_s, d.load_n);
            }
            if !d.tooth_loads_n.is_empty() {
                if t.teeth.len() < d.tooth_loads_n.len() {
                    let sums = t
                        .lumped
                        .out
                        .sums
                        .map(|s| DamageSum::new(s.stress_pa_per_n, s.material));
                    t.teeth.resize_with(d.tooth_loads_n.len(), || ToothTrack {
                        history: HistoryTrack::new(keep, sums),
                        open: None,
                    });
                }
                for (k, &x) in t.teeth.iter_mut().zip(&d.tooth_loads_n) {
                    k.push(x);
                }
            }
        }
    }

    /// Takes a closed impact: a pulse, or its samples when they resolve it (the rule of
    /// [`crate::cycles::impact_history`]).
    pub fn impact(&mut self, e: &ImpactEvent) {
        let DiscTrack {
            pending, lumped, ..
        } = self.disc(e.disc);
        let h = lumped;
        h.push(0.0);
        // the samples strictly inside the contact, streamed in time order (a sustained
        // contact's may be millions, partly on disk): the first few wait until there are
        // enough to count it from its samples, the peak goes in before the first sample
        // after it
        // (on the stack: an impact allocates nothing, issue 46's frame loop)
        let mut first = [(0.0, 0.0); SUSTAINED_CONTACT_SAMPLES];
        let mut n_first = 0;
        let mut sustained = false;
        let mut peak_in = false;
        let mut feed = |h: &mut HistoryTrack, s: (f64, f64)| {
            if !peak_in && s.0 > e.t_peak_s {
                h.push(e.peak_n);
                peak_in = true;
            }
            h.push(s.1);
        };
        pending.claim(e.t_on_s, e.t_off_s, |s| {
            if sustained {
                feed(h, s);
            } else {
                first[n_first] = s;
                n_first += 1;
                if n_first >= SUSTAINED_CONTACT_SAMPLES {
                    sustained = true;
                    for &s in &first {
                        feed(h, s);
                    }
                }
            }
        });
        if !(sustained && peak_in) {
            h.push(e.peak_n);
        }
        h.push(0.0);
        h.peak(e.peak_n);
    }

    /// The counted histories of every coupling seen, in index order; `couplings` pads the
    /// list for couplings that never hit.
    pub fn finish(self, couplings: usize) -> Vec<DiscHistories> {
        let (keep, curves) = (self.keep, self.curves);
        let tracks = self.discs.into_iter().map(|d| (d.lumped, d.teeth));
        finish_tracks(tracks, keep, &curves, couplings)
    }

    /// What [`Self::finish`] gives, leaving the collector as it is (to be fed on): copies
    /// only the histories' counters, not the loaded samples waiting for their impact (which
    /// `finish` does not count).
    pub fn histories(&self, couplings: usize) -> Vec<DiscHistories> {
        let tracks = self
            .discs
            .iter()
            .map(|d| (d.lumped.clone(), d.teeth.clone()));
        finish_tracks(tracks, self.keep, &self.curves, couplings)
    }

    /// Loaded samples held in memory, waiting for the impact that claims them: at most
    /// [`super::PENDING_IN_MEMORY`] per coupling, however long its contact stays closed (the
    /// older ones wait in a temporary file).
    pub fn held_samples(&self) -> usize {
        self.discs.iter().map(|d| d.pending.held()).sum()
    }

    /// Why some loaded samples kept in the temporary file could not be read back, if they
    /// could not: the figures of the contacts that held them then miss them.
    pub fn spill_error(&self) -> Option<&str> {
        self.discs.iter().find_map(|d| d.pending.error())
    }
}

/// The counted histories of `tracks` (each coupling's lumped history and its teeth's), in
/// index order, padded with empty histories to `couplings`.
fn finish_tracks(
    tracks: impl Iterator<Item = (HistoryTrack, Vec<ToothTrack>)>,
    keep: bool,
    curves: &[(f64, Material)],
    couplings: usize,
) -> Vec<DiscHistories> {
    let mut out: Vec<DiscHistories> = tracks
        .map(|(mut lumped, teeth)| {
            lumped.push(0.0);
            DiscHistories {
                lumped: lumped.finish(),
                teeth: teeth.into_iter().map(ToothTrack::finish).collect(),
            }
        })
        .collect();
    let first = out.len();
    out.extend((first..couplings).map(|k| DiscHistories {
        lumped: HistoryTrack::new(keep, curves.get(k).map(|&(c, m)| DamageSum::new(c, m))).finish(),
        teeth: Vec::new(),
    }));
    out
}

impl FatigueCollector {
    /// A collector fed with recorded `samples` and `impacts` (of any order) as an engine
    /// would feed it live: each impact after the samples up to its separation. On the same
    /// samples and events it holds the same histories as the live collector.
    pub fn replay(samples: &[Sample], impacts: &[ImpactEvent]) -> FatigueCollector {
        let mut ev: Vec<&ImpactEvent> = impacts.iter().collect();
        ev.sort_by(|a, b| a.t_off_s.total_cmp(&b.t_off_s));
        let mut c = FatigueCollector::new();
        let mut next = 0;
        for e in ev {
            while samples.get(next).is_some_and(|s| s.t_s <= e.t_off_s) {
                c.sample(&samples[next]);
                next += 1;
            }
            c.impact(e);
        }
        for s in &samples[next.min(samples.len())..] {
            c.sample(s);
        }
        c
    }
}

impl Observer for FatigueCollector {
    fn sample(&mut self, s: &Sample) {
        FatigueCollector::sample(self, s);
    }
    fn impact(&mut self, e: &ImpactEvent) {
        FatigueCollector::impact(self, e);
    }
}

#[cfg(test)]
impl FatigueCollector {
    /// Turning points coupling `disc`'s rainflow counters hold (its lumped history and its
    /// teeth's), for the memory bound's test.
    pub(super) fn held_points(&self, disc: usize) -> usize {
        let d = &self.discs[disc];
        d.lumped.rainflow.held()
            + d.teeth
                .iter()
                .map(|k| k.history.rainflow.held())
                .sum::<usize>()
    }
}
