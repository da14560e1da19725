//! A run's figures window by window (`clutchpack run --windows S`): how the impact peaks and
//! the teeth's damage rate move through a long run, e.g. as the oil warms in a thermal run.
//!
//! Each window `(t0, t1]` of the requested length (the first from `t = 0`) keeps its own
//! impact peak statistics (the impacts that closed in it). Its damage is the increase of the
//! run's own (MODEL.md section 7: the run's rainflow count with its residual as half cycles)
//! over the window, so the windows' damages add up to the run's exactly; a window holds the
//! cycles that closed in it (a rainflow count per window would lose the cycles that span
//! windows: 9 % of the damage with 0.1 s windows on the paper case). A run has at most
//! [`MAX_WINDOWS`]. A thermal run's oil and hottest body are
//! its last temperatures when the window closes (at the first sample after its end; the
//! last window at the run's end).

use clutchpack_analysis::{FatigueCollector, PeakStats};
use clutchpack_model::{FatigueParams, ImpactEvent, SplineGeometry};
use serde::{Deserialize, Serialize};

/// Most windows a run may ask for (each row holds every body's figures).
pub const MAX_WINDOWS: f64 = 1e5;

/// `Err` (bad input) unless `windows_s` (s), if given, is a positive window length giving at
/// most [`MAX_WINDOWS`] windows over a run of `duration_s` (s).
pub(crate) fn check(windows_s: Option<f64>, duration_s: f64) -> crate::Result<()> {
    match windows_s.filter(|s| !(*s > 0.0 && s.is_finite() && duration_s / *s <= MAX_WINDOWS)) {
        Some(len_s) => Err(crate::Error::BadInput(format!(
            "windows of {} s (`--windows`, `windows_s`): the window length must be a positive \
             number of seconds giving at most {} windows over the run's {} s",
            clutchpack_model::fmt_num(len_s),
            clutchpack_model::fmt_num(MAX_WINDOWS),
            clutchpack_model::fmt_num(duration_s)
        ))),
        None => Ok(()),
    }
}

/// One window of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowRow {
    /// Start of the window, s.
    pub t0_s: f64,
    /// End of the window, s (the run's end for the last, partial window).
    pub t1_s: f64,
    /// Impacts that closed in the window (every body).
    pub impacts: usize,
    /// The largest `|peak|` per tooth of any body's impact in the window, N (0 without one).
    pub peak_abs_n: f64,
    /// The body with that peak (empty without an impact).
    pub peak_body: String,
    /// The largest of the bodies' 99th percentiles of `|peak|` in the window, N.
    pub p99_abs_n: f64,
    /// The largest of the bodies' lumped tooth damage rates over the window, 1/h
    /// (MODEL.md section 7; Miner's sum of the window's cycles over its length).
    pub damage_rate_per_h: f64,
    /// The body with that damage rate.
    pub damage_body: String,
    /// A thermal run's oil temperature at the window's end, K.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oil_k: Option<f64>,
    /// A thermal run's hottest body at the window's end, K.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hottest_body_k: Option<f64>,
    /// Each body's figures in the window, engine order (the discs, then the plates).
    pub bodies: Vec<BodyWindow>,
}

/// One body's figures in one window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyWindow {
    /// The body's scene name.
    pub name: String,
    /// Its impacts that closed in the window.
    pub impacts: usize,
    /// Its largest `|peak|` per tooth in the window, N (0 without an impact).
    pub peak_abs_n: f64,
    /// Its lumped tooth damage rate over the window, 1/h.
    pub damage_rate_per_h: f64,
}

/// The open window and the rows of the closed ones.
pub(crate) struct Windows {
    /// Window length, s (> 0).
    len_s: f64,
    /// Index of the open window (it ends at `(k + 1) len_s`).
    k: u64,
    peaks: PeakStats,
    params: Vec<(SplineGeometry, FatigueParams)>,
    /// Each body's damage of the run up to the open window's start.
    damage_before: Vec<f64>,
    /// The last temperatures: (oil K, hottest body K).
    temps: Option<(f64, f64)>,
    pub rows: Vec<WindowRow>,
}

impl Windows {
    /// Windows of `len_s` (s) over couplings with the fatigue parameters `params` (engine
    /// order).
    pub fn new(len_s: f64, params: Vec<(SplineGeometry, FatigueParams)>) -> Windows {
        Windows {
            len_s,
            k: 0,
            peaks: PeakStats::new(),
            params,
            damage_before: Vec::new(),
            temps: None,
            rows: Vec::new(),
        }
    }

    /// The window length, s.
    pub fn len_s(&self) -> f64 {
        self.len_s
    }

    /// The end of the open window, s.
    pub fn end_s(&self) -> f64 {
        (self.k + 1) as f64 * self.len_s
    }

    pub fn impact(&mut self, e: &ImpactEvent) {
        self.peaks.push(e.disc, e.peak_n);
    }

    pub fn temperatures(&mut self, bodies_k: &[f64], oil_k: f64) {
        let hottest = bodies_k.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        self.temps = Some((oil_k, hottest));
    }

    /// Closes the open window at `t1_s` (s), `fatigue` being the run's collector with every
    /// sample before `t1_s`, and opens the next.
    pub fn close(&mut self, t1_s: f64, names: &[String], fatigue: &FatigueCollector) {
        let t0_s = self.k as f64 * self.len_s;
        let stats = self.peaks.stats(names).unwrap_or_default();
        let len_s = (t1_s - t0_s).max(f64::MIN_POSITIVE);
        // the run's damage so far (its duration only scales the rates, not used here)
        let so_far = crate::fatigue::assess_histories(
            &fatigue.histories(names.len()),
            &self.params,
            names,
            len_s,
        );
        let mut row = WindowRow {
            t0_s,
            t1_s,
            impacts: stats.iter().map(|d| d.impacts).sum(),
            peak_abs_n: 0.0,
            peak_body: String::new(),
            p99_abs_n: 0.0,
            damage_rate_per_h: 0.0,
            damage_body: String::new(),
            oil_k: self.temps.map(|t| t.0),
            hottest_body_k: self.temps.map(|t| t.1),
            bodies: Vec::with_capacity(names.len()),
        };
        self.damage_before.resize(so_far.len(), 0.0);
        for (i, name) in names.iter().enumerate() {
            let d = stats.get(i);
            let peak = d.map_or(0.0, |d| d.max_positive_n.max(-d.max_negative_n));
            let impacts = d.map_or(0, |d| d.impacts);
            if impacts > 0 && peak > row.peak_abs_n {
                row.peak_abs_n = peak;
                row.peak_body.clone_from(name);
            }
            row.p99_abs_n = row.p99_abs_n.max(d.map_or(0.0, |d| d.p99_abs_n));
            let rate = match (so_far.get(i), self.damage_before.get_mut(i)) {
                (Some(f), Some(before)) => {
                    let rate = (f.lumped.damage - *before) / len_s * 3600.0;
                    *before = f.lumped.damage;
                    rate
                }
                _ => 0.0,
            };
            if rate > row.damage_rate_per_h {
                row.damage_rate_per_h = rate;
                row.damage_body.clone_from(name);
            }
            row.bodies.push(BodyWindow {
                name: name.clone(),
                impacts,
                peak_abs_n: if impacts > 0 { peak } else { 0.0 },
                damage_rate_per_h: rate,
            });
        }
        self.rows.push(row);
        self.k += 1;
        self.peaks = PeakStats::new();
    }
}
