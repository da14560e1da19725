//! What a run keeps for its outputs: peak statistics, interfaces, fatigue sums, the impacts
//! CSV, and (when asked) the load histories.

use crate::{Error, Result};
use clutchpack_analysis::{DiscFatigue, DiscStats, FatigueCollector, InterfaceStats, PeakStats};
use clutchpack_model::{
    FatigueParams, ImpactEvent, InterfaceSample, Observer, Sample, SplineGeometry,
};
use clutchpack_scene::Scene;
use std::path::Path;

/// Keeps what a run's outputs need, in memory that does not grow with the run unless an
/// output asks for every value: the impact peaks' statistics ([`PeakStats`]), the teeth's
/// fatigue as running sums ([`FatigueCollector::summing`]), what each friction interface did
/// (when named with [`RunCollector::with_interfaces`]), the impacts CSV written as the
/// impacts come ([`RunCollector::with_impacts_csv`]). Kept whole only when asked: the load
/// histories and impacts for `--plot` (`keep_history`) and every counted cycle for
/// `--fatigue-json` ([`RunCollector::with_fatigue`]).
pub struct RunCollector {
    /// Every impact, only when `keep_history` (the plot merges their peaks in).
    pub impacts: Vec<ImpactEvent>,
    /// The statistics of every impact's peak.
    pub peaks: PeakStats,
    pub interfaces: Vec<InterfaceStats>,
    /// Per disc: (t s, load N) samples, only when `keep_history`.
    pub history: Vec<Vec<(f64, f64)>>,
    pub keep_history: bool,
    /// The load histories' cycles for the teeth's fatigue (MODEL.md section 7).
    pub fatigue: FatigueCollector,
    /// Spline and fatigue parameters of each coupling (engine order), set by
    /// [`RunCollector::with_fatigue`]; empty: no fatigue in the recording's summary.
    pub fatigue_params: Vec<(SplineGeometry, FatigueParams)>,
    /// The impacts CSV being written, if asked.
    csv: Option<ImpactsCsv>,
    /// The impact that closed last (in the order the engine sent them).
    pub last_impact: Option<ImpactEvent>,
    /// The figures window by window, when asked ([`RunCollector::with_windows`]).
    windows: Option<crate::windows::Windows>,
    /// The bodies' names, engine order (for the windows' rows).
    names: Vec<String>,
    /// A thermal run's latest temperatures, K: the bodies (engine order), then the oil;
    /// empty before the first (and in an isothermal run).
    pub temperatures_k: Vec<f64>,
}

impl RunCollector {
    pub fn new(discs: usize, keep_history: bool) -> RunCollector {
        RunCollector {
            impacts: Vec::new(),
            peaks: PeakStats::new(),
            interfaces: Vec::new(),
            history: vec![Vec::new(); discs],
            keep_history,
            fatigue: FatigueCollector::new(),
            fatigue_params: Vec::new(),
            csv: None,
            last_impact: None,
            windows: None,
            names: Vec::new(),
            temperatures_k: Vec::new(),
        }
    }

    /// An independent copy of everything kept (a steppable run's saved state); an error with
    /// an impacts CSV (a file being written cannot be rewound) or when the peaks spilled to a
    /// temporary file cannot be copied.
    pub fn try_clone(&self) -> Result<RunCollector> {
        if self.csv.is_some() {
            return Err(Error::BadInput(
                "a run that writes an impacts CSV cannot save its state".into(),
            ));
        }
        Ok(RunCollector {
            impacts: self.impacts.clone(),
            peaks: self.peaks.try_clone().map_err(Error::io(
                "the impact peaks kept in a temporary file (copying them)",
            ))?,
            interfaces: self.interfaces.clone(),
            history: self.history.clone(),
            keep_history: self.keep_history,
            fatigue: self.fatigue.clone(),
            fatigue_params: self.fatigue_params.clone(),
            csv: None,
            last_impact: self.last_impact,
            windows: None,
            names: self.names.clone(),
            temperatures_k: self.temperatures_k.clone(),
        })
    }

    /// Also assesses the teeth's fatigue with the scene's parameters ([`crate::fatigue_params`]),
    /// summing the damage as the cycles are counted; `keep_cycles` also keeps every cycle
    /// (for `--fatigue-json`'s spectra; memory grows with the run).
    pub fn with_fatigue(mut self, scene: &Scene, keep_cycles: bool) -> RunCollector {
        self.fatigue_params = crate::fatigue::fatigue_params(scene);
        self.fatigue = FatigueCollector::summing(self.curves(), keep_cycles);
        self
    }

    /// Each coupling's S-N curve for the collectors: (root stress per newton of tooth load,
    /// Pa/N; material), from [`Self::with_fatigue`]'s parameters.
    fn curves(&self) -> Vec<(f64, clutchpack_model::Material)> {
        crate::fatigue::curves(&self.fatigue_params)
    }

    /// Also keeps the figures of every window of `len_s` (s) of the bodies `names` (engine
    /// order; `crate::windows`); call after [`Self::with_fatigue`], whose curves it uses.
    pub fn with_windows(mut self, len_s: f64, names: &[String]) -> RunCollector {
        self.names = names.to_vec();
        self.windows = Some(crate::windows::Windows::new(
            len_s,
            self.fatigue_params.clone(),
        ));
        self
    }

    /// Closes the last window at the run's end `t_s` (s) and gives the windows' rows (empty
    /// when none were asked).
    pub fn finish_windows(&mut self, t_s: f64) -> Vec<crate::WindowRow> {
        match self.windows.as_mut() {
            Some(w) => {
                if t_s > w.end_s() - w.len_s() {
                    w.close(t_s, &self.names, &self.fatigue);
                }
                std::mem::take(&mut w.rows)
            }
            None => Vec::new(),
        }
    }

    /// Also writes every impact to the CSV file `path` as it comes (a temporary sibling,
    /// renamed into place by [`Self::finish_impacts_csv`]); `names` are the disc names in
    /// engine order.
    pub fn with_impacts_csv(mut self, path: &Path, names: &[String]) -> Result<RunCollector> {
        self.csv = Some(ImpactsCsv::create(path, names, "disc")?);
        Ok(self)
    }

    /// Completes the impacts CSV (if one is written) with the impacts so far and renames it
    /// into place.
    pub fn finish_impacts_csv(&mut self) -> Result<()> {
        match self.csv.take() {
            Some(c) => c.finish(),
            None => Ok(()),
        }
    }

    /// Impacts so far.
    pub fn impact_count(&self) -> usize {
        self.peaks.impacts()
    }

    /// The per-disc statistics of the impacts so far, named `names`.
    pub fn disc_stats(&self, names: &[String]) -> Result<Vec<DiscStats>> {
        self.peaks.stats(names).map_err(Error::io(
            "the impact peaks kept in a temporary file (reading them back)",
        ))
    }

    /// The fatigue of every coupling (named `names`) over `duration_s` of simulated duty,
    /// from the histories collected so far.
    pub fn assess_fatigue(&self, names: &[String], duration_s: f64) -> Vec<DiscFatigue> {
        crate::fatigue::assess_histories(
            &self.fatigue.histories(names.len()),
            &self.fatigue_params,
            names,
            duration_s,
        )
    }

    /// Also keeps the figures of the stack's friction interfaces, named in stack order.
    pub fn with_interfaces(mut self, names: impl IntoIterator<Item = String>) -> RunCollector {
        self.interfaces = names.into_iter().map(InterfaceStats::new).collect();
        self
    }

    /// Load histories with each impact's onset, peak and separation merged in (see
    /// [`merge_peaks`]); only with `keep_history`.
    pub fn histories_with_peaks(&self) -> Vec<Vec<(f64, f64)>> {
        let mut h = self.history.clone();
        merge_peaks(&mut h, &self.impacts);
        h
    }
}

/// The impacts CSV of a run, written row by row to a temporary sibling of its path: a
/// header, then `name,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n` per impact, where the
/// first column (`disc` for a pack run, `name` for a network run) names the impact's body.
pub(crate) struct ImpactsCsv {
    pending: clutchpack_record::PendingFile,
    out: std::io::BufWriter<std::fs::File>,
    names: Vec<String>,
    /// the first write error (reported by `finish`)
    error: Option<std::io::Error>,
}

impl ImpactsCsv {
    /// Starts the CSV at `path` (a temporary sibling until [`Self::finish`]); `names[i]`
    /// names the impacts whose `disc` is `i`, and `first` heads their column.
    pub(crate) fn create(path: &Path, names: &[String], first: &str) -> Result<ImpactsCsv> {
        let (pending, file) =
            clutchpack_record::PendingFile::create(path, clutchpack_record::Replace::Existing)
                .map_err(Error::io(path))?;
        let mut c = ImpactsCsv {
            pending,
            out: std::io::BufWriter::new(file),
            names: names.to_vec(),
            error: None,
        };
        c.write(|w| writeln!(w, "{first},t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n"));
        Ok(c)
    }

    fn write(&mut self, f: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>) {
        if self.error.is_none() {
            if let Err(e) = f(&mut self.out) {
                self.error = Some(e);
            }
        }
    }

    /// Writes the row of `e` (named by its `disc` index).
    pub(crate) fn row(&mut self, e: &ImpactEvent) {
        let name = self
            .names
            .get(e.disc)
            .cloned()
            .unwrap_or_else(|| format!("disc {}", e.disc));
        self.write(|w| {
            writeln!(
                w,
                "{},{:.9},{:.9},{:.9},{},{:.6},{:.4}",
                clutchpack_analysis::csv_field(&name),
                e.t_on_s,
                e.t_peak_s,
                e.t_off_s,
                e.flank.label(),
                e.v_on_m_s,
                e.peak_n
            )
        });
    }

    /// Flushes the rows and renames the file into place (a write error discards it).
    pub(crate) fn finish(mut self) -> Result<()> {
        use std::io::Write as _;
        let path = self.pending.target().to_path_buf();
        let flushed = match self.error.take() {
            Some(e) => Err(e),
            None => self
                .out
                .flush()
                .and_then(|()| self.out.get_ref().sync_all()),
        };
        match flushed {
            Ok(()) => {
                drop(self.out);
                self.pending.commit().map_err(Error::io(path))?;
                Ok(())
            }
            Err(e) => {
                self.pending.discard();
                Err(Error::Io { path, source: e })
            }
        }
    }
}

/// Merges each impact's onset (0 N), located peak and separation (0 N) into the sampled load
/// histories `(t s, load N)` of its disc, in time order, so that plotted spikes reach the
/// located peaks whatever the sample rate.
pub fn merge_peaks(histories: &mut [Vec<(f64, f64)>], impacts: &[ImpactEvent]) {
    for e in impacts {
        if let Some(v) = histories.get_mut(e.disc) {
            v.extend([(e.t_on_s, 0.0), (e.t_peak_s, e.peak_n), (e.t_off_s, 0.0)]);
        }
    }
    for v in histories.iter_mut() {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
}

impl Observer for RunCollector {
    fn sample(&mut self, s: &Sample) {
        if let Some(w) = &mut self.windows {
            // the windows that ended before this sample close on the samples up to their end
            while s.t_s > w.end_s() {
                let t1 = w.end_s();
                w.close(t1, &self.names, &self.fatigue);
            }
        }
        self.fatigue.sample(s);
        if self.keep_history {
            for (i, d) in s.discs.iter().enumerate() {
                self.history[i].push((s.t_s, d.load_n));
            }
        }
    }
    fn impact(&mut self, e: &ImpactEvent) {
        self.last_impact = Some(*e);
        if self.keep_history {
            self.impacts.push(*e);
        }
        self.peaks.push(e.disc, e.peak_n);
        if let Some(c) = &mut self.csv {
            c.row(e);
        }
        self.fatigue.impact(e);
        if let Some(w) = &mut self.windows {
            w.impact(e);
        }
    }
    fn temperatures(&mut self, _t_s: f64, bodies_k: &[f64], oil_k: f64) {
        self.temperatures_k.clear();
        self.temperatures_k.extend_from_slice(bodies_k);
        self.temperatures_k.push(oil_k);
        if let Some(w) = &mut self.windows {
            w.temperatures(bodies_k, oil_k);
        }
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        for (st, f) in self.interfaces.iter_mut().zip(interfaces) {
            st.update(t_s, f);
        }
    }
}
