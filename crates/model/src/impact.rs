//! Impact events: one contact event of a coupling from the start of contact to separation.

use crate::spline::Flank;
use serde::{Deserialize, Serialize};

/// One impact of a disc's teeth on the shaft's (or carrier's) teeth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImpactEvent {
    /// Index of the disc (coupling) in the scene, from 0.
    pub disc: usize,
    /// Onset in s: the instant the engagement depth crosses zero (metal contact for the dry
    /// law, film engagement for the oil laws).
    pub t_on_s: f64,
    /// Time of the peak load in s.
    pub t_peak_s: f64,
    /// Separation in s (the end of the run if the contact was still closed then).
    pub t_off_s: f64,
    /// The flank in contact.
    pub flank: Flank,
    /// Closing speed along the line of action at onset, m/s (positive while closing).
    pub v_on_m_s: f64,
    /// Peak per-tooth load in N, signed as in eq (6): negative when the shaft leads.
    pub peak_n: f64,
}

/// Builds [`ImpactEvent`]s for one coupling from explicit onset/observe/separation calls.
///
/// Engines that locate the onset exactly call [`Self::begin`] there, feed every load they
/// compute during contact to [`Self::observe`] (the largest magnitude wins), and call
/// [`Self::end`] at separation. [`Self::feed`] drives it from a plainly sampled history.
#[derive(Debug, Clone, Default)]
pub struct ImpactTracker {
    disc: usize,
    open: Option<ImpactEvent>,
    // last three samples fed through `feed`, for the parabolic peak refinement
    last: Option<(f64, f64)>,
    before_last: Option<(f64, f64)>,
    peak_is_last: bool,
}

impl ImpactTracker {
    /// A tracker for disc `disc`.
    pub fn new(disc: usize) -> ImpactTracker {
        ImpactTracker {
            disc,
            ..Default::default()
        }
    }

    /// Whether a contact event is open.
    #[inline]
    pub fn is_open(&self) -> bool {
        self.open.is_some()
    }

    /// Opens an event at `t_s` on `flank` with closing speed `v_on_m_s`.
    pub fn begin(&mut self, t_s: f64, flank: Flank, v_on_m_s: f64) {
        self.open = Some(ImpactEvent {
            disc: self.disc,
            t_on_s: t_s,
            t_peak_s: t_s,
            t_off_s: f64::NAN,
            flank,
            v_on_m_s,
            peak_n: 0.0,
        });
    }

    /// Offers a signed load `load_n` at `t_s`; kept if its magnitude is the largest so far.
    #[inline]
    pub fn observe(&mut self, t_s: f64, load_n: f64) {
        if let Some(e) = self.open.as_mut() {
            if load_n.abs() > e.peak_n.abs() {
                e.peak_n = load_n;
                e.t_peak_s = t_s;
            }
        }
    }

    /// The open event as it would close at `t_s` (its peak the largest located so far), the
    /// event left open: what a recording keeps of a contact that has not closed yet.
    pub fn peek(&self, t_s: f64) -> Option<ImpactEvent> {
        self.open.map(|e| ImpactEvent { t_off_s: t_s, ..e })
    }

    /// [`Self::peek`] with a probe not yet observed: `(t_peak s, |load| N)`, the largest
    /// magnitude probed along the steps of an engine that refines the peak only when the
    /// contact closes; taken when larger than the peak observed, signed by the flank
    /// (negative when the shaft, or the carrier, leads).
    pub fn peek_with(&self, t_s: f64, probe: Option<(f64, f64)>) -> Option<ImpactEvent> {
        self.peek(t_s).map(|mut e| {
            if let Some((t_peak, magnitude)) = probe.filter(|p| p.1 > e.peak_n.abs()) {
                e.t_peak_s = t_peak;
                e.peak_n = -e.flank.phi_sign() * magnitude;
            }
            e
        })
    }

    /// Closes the open event at `t_s` and returns it.
    pub fn end(&mut self, t_s: f64) -> Option<ImpactEvent> {
        self.last = None;
        self.before_last = None;
        self.peak_is_last = false;
        self.open.take().map(|mut e| {
            e.t_off_s = t_s;
            e
        })
    }

    /// Feeds one sample of a sampled history: `load_n` signed per-tooth load, `v_n_m_s` the
    /// closing speed. An event opens at the first non-zero load and closes at the first zero
    /// load after it; the peak is refined by a parabola through the three samples around the
    /// largest one. Returns the event that this sample closed, if any.
    pub fn feed(&mut self, t_s: f64, load_n: f64, v_n_m_s: f64) -> Option<ImpactEvent> {
        let flank_of = |f: f64| {
            if f > 0.0 {
                Flank::DiscLeads
            } else {
                Flank::ShaftLeads
            }
        };
        let mut closed = None;
        if let Some(e) = self.open {
            if load_n == 0.0 || flank_of(load_n) != e.flank {
                if self.peak_is_last {
                    // the peak was the last non-zero sample: refine with this one
                    self.refine((t_s, load_n));
                }
                closed = self.end(t_s);
            }
        }
        if load_n != 0.0 {
            if self.open.is_none() {
                self.begin(t_s, flank_of(load_n), v_n_m_s);
            }
            if self.peak_is_last {
                self.refine((t_s, load_n));
            }
            let prev_peak = self.open.map(|e| e.peak_n.abs()).unwrap_or(0.0);
            self.observe(t_s, load_n);
            self.peak_is_last = load_n.abs() > prev_peak || prev_peak == 0.0;
            self.before_last = self.last;
            self.last = Some((t_s, load_n));
        }
        closed
    }

    /// Parabolic refinement through `before_last`, `last` (the current peak) and `next`.
    fn refine(&mut self, next: (f64, f64)) {
        self.peak_is_last = false;
        let (Some((t0, f0)), Some((t1, f1))) = (self.before_last, self.last) else {
            return;
        };
        let (t2, f2) = next;
        let Some((tv, av)) = parabolic_peak((t0, f0.abs()), (t1, f1.abs()), (t2, f2.abs())) else {
            return;
        };
        let sign = f1.signum();
        if let Some(e) = self.open.as_mut() {
            if av > e.peak_n.abs() {
                e.peak_n = sign * av;
                e.t_peak_s = tv;
            }
        }
    }

    /// Closes any open event at the end of a run (`t_s`), marking the separation at `t_s`.
    pub fn finish(&mut self, t_s: f64) -> Option<ImpactEvent> {
        self.end(t_s)
    }
}

/// The smallest ratio of the two sample spacings of [`parabolic_peak`] (the shorter over the
/// longer): below it the samples are a rounding error apart (a step landing 1e-19 s from
/// a communication point or the end), the parabola's slope through them is noise, and its
/// vertex can lie 1e8 times above every sample.
pub const MIN_PEAK_SPACING_RATIO: f64 = 1e-6;

/// The peak between samples of a load's magnitude: the vertex `(t, |F|)` of the parabola
/// through three samples `(t_s, |F| in N)` in time order. `None` unless the middle sample is
/// the largest of the three, the parabola opens downward, its vertex lies within the
/// samples' span and the samples are not a rounding error apart ([`MIN_PEAK_SPACING_RATIO`]).
/// Used by [`ImpactTracker`] and by the engines that feed [`ImpactTracker::observe`]
/// themselves.
#[inline]
pub fn parabolic_peak(
    (t0, a0): (f64, f64),
    (t1, a1): (f64, f64),
    (t2, a2): (f64, f64),
) -> Option<(f64, f64)> {
    if !(a1 >= a0 && a1 >= a2) {
        return None;
    }
    let (h0, h1) = (t1 - t0, t2 - t1);
    if h0.min(h1) <= MIN_PEAK_SPACING_RATIO * h0.max(h1) {
        return None;
    }
    // Lagrange parabola through the three points; vertex
    let d01 = (a1 - a0) / (t1 - t0);
    let d12 = (a2 - a1) / (t2 - t1);
    let curv = (d12 - d01) / (t2 - t0);
    if curv >= 0.0 {
        return None;
    }
    let tv = 0.5 * (t0 + t1) - d01 / (2.0 * curv);
    if !(t0..=t2).contains(&tv) {
        return None;
    }
    Some((tv, a1 + d01 * (tv - t1) + curv * (tv - t0) * (tv - t1)))
}

/// Detects the impacts in a sampled per-tooth load history (`t_s`, `load_n`, `v_n_m_s` of
/// equal length) of disc `disc` with [`ImpactTracker::feed`]; an event still open at the last
/// sample is closed there.
pub fn detect_impacts(
    disc: usize,
    t_s: &[f64],
    load_n: &[f64],
    v_n_m_s: &[f64],
) -> Vec<ImpactEvent> {
    let mut tr = ImpactTracker::new(disc);
    let mut out = Vec::new();
    for i in 0..t_s.len().min(load_n.len()).min(v_n_m_s.len()) {
        if let Some(e) = tr.feed(t_s[i], load_n[i], v_n_m_s[i]) {
            out.push(e);
        }
    }
    if let Some(e) = tr.finish(*t_s.last().unwrap_or(&0.0)) {
        out.push(e);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Two half-sine pulses of opposite sign, sampled at 1 us: two events with the right
    /// flanks, onsets, and peaks refined to within 1e-5 relative of the true maximum.
    #[test]
    fn detects_two_pulses_and_refines_the_peak() {
        let dt = 1e-6;
        let mut t = Vec::new();
        let mut f = Vec::new();
        for i in 0..400 {
            let ti = i as f64 * dt + 0.3e-6;
            let load = if (50e-6..120e-6).contains(&ti) {
                -600.0 * (std::f64::consts::PI * (ti - 50e-6) / 70e-6).sin()
            } else if (200e-6..260e-6).contains(&ti) {
                450.0 * (std::f64::consts::PI * (ti - 200e-6) / 60e-6).sin()
            } else {
                0.0
            };
            t.push(ti);
            f.push(load);
        }
        let v = vec![0.1; t.len()];
        let ev = detect_impacts(3, &t, &f, &v);
        assert_eq!(ev.len(), 2);
        assert_eq!(ev[0].flank, Flank::ShaftLeads);
        assert_eq!(ev[1].flank, Flank::DiscLeads);
        assert_eq!(ev[0].disc, 3);
        assert_relative_eq!(ev[0].peak_n, -600.0, max_relative = 1e-5);
        assert_relative_eq!(ev[0].t_peak_s, 85e-6, epsilon = 0.05e-6);
        assert_relative_eq!(ev[1].peak_n, 450.0, max_relative = 1e-5);
        assert!(ev[0].t_on_s >= 50e-6 && ev[0].t_on_s <= 51e-6);
        assert!(ev[1].t_off_s >= 260e-6 && ev[1].t_off_s <= 261e-6);
    }

    /// Samples a rounding error apart (a step that landed 1e-19 s from a communication point)
    /// give no parabola: its vertex would lie 1e10 N above loads of 100 N (issue 36's absurd
    /// FMU peaks). Evenly spaced samples still refine.
    #[test]
    fn samples_a_rounding_error_apart_give_no_parabolic_peak() {
        let t1 = 0.12;
        let near = t1 - 1e-19_f64.max(t1 * f64::EPSILON);
        assert_eq!(
            parabolic_peak((near, 100.0), (t1, 160.0), (t1 + 1e-4, 150.0)),
            None
        );
        assert_eq!(
            parabolic_peak((t1 - 1e-4, 150.0), (t1, 160.0), (t1 + 1e-14, 100.0)),
            None
        );
        // the vertex by hand: t = 5/14, |F| = 160 + 60 t - 35 (t + 1) t = 164.4642857...
        let (tv, av) = parabolic_peak((-1.0, 100.0), (0.0, 160.0), (1.0, 150.0)).unwrap();
        assert!((tv - 5.0 / 14.0).abs() < 1e-12, "{tv}");
        assert!((av - 164.464_285_714_285_7).abs() < 1e-9, "{av}");
    }

    /// An event still open at the end of the history is closed at the last sample.
    #[test]
    fn open_event_is_closed_at_the_end() {
        let ev = detect_impacts(0, &[0.0, 1.0, 2.0], &[0.0, 5.0, 6.0], &[0.0; 3]);
        assert_eq!(ev.len(), 1);
        assert_eq!(ev[0].t_off_s, 2.0);
        assert_eq!(ev[0].peak_n, 6.0);
    }
}
