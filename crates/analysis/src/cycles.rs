//! Cycle counting of signed per-tooth load histories (MODEL.md section 7).
//!
//! # Theory
//! - **Load history.** The teeth are free in the backlash between impacts, so an impact is one
//!   pulse `0 -> peak -> 0` of the signed per-tooth load (negative when the shaft leads). A run
//!   of impacts is the history `0, P1, 0, P2, 0, ...` ([`pulse_history`]): hits on one flank
//!   only are pulsating cycles of range `|P|` (R = 0); alternating flanks (`+P` then `-P`) pass
//!   through 0 without turning there, so they make a reversed cycle of range `2P` (R = -1). A
//!   contact that carries load for long (a locked pack) is not a pulse: where the samples
//!   resolve it, it is counted from its samples ([`impact_history`]).
//! - **Turning points** ([`turning_points`], [`TurningPoints`]): the first value, every value
//!   where the history changes direction (plateaus collapsed to one point), and the last value.
//! - **Rainflow** ([`rainflow`]): ASTM E1049-85 (2011), section 5.4.4, the three-point method:
//!   with `X` the range of the two newest points and `Y` the one before it, while `X >= Y`
//!   count `Y` as a half cycle and drop its first point if `Y` holds the starting point, else
//!   count `Y` as a full cycle and drop both its points. The residue left at the end is
//!   counted as half cycles (ASTM's rule; the PyPI `rainflow` package does the same).
//! - **Invariant.** Every full cycle removes two turning points and every half cycle one, so
//!   `sum over cycles of 2 x count = turning points - 1`: each range between two successive
//!   turning points is counted exactly once, as one half of a cycle.
//! - **Spectra.** The range histogram and range-mean matrix bin the counted cycles; the
//!   exceedance spectrum counts the contact peaks above each load level per hour of duty.

use clutchpack_model::ImpactEvent;
use serde::{Deserialize, Serialize};

/// One counted cycle between two turning points of a history (values in its unit: N).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cycle {
    /// The first turning point of the cycle's range.
    pub from: f64,
    /// The second turning point of the cycle's range.
    pub to: f64,
    /// 1 for a full cycle, 0.5 for a half cycle.
    pub count: f64,
}

impl Cycle {
    /// The range `|to - from|` (>= 0).
    pub fn range(&self) -> f64 {
        (self.to - self.from).abs()
    }
    /// The mean `(from + to) / 2`.
    pub fn mean(&self) -> f64 {
        0.5 * (self.from + self.to)
    }
    /// The amplitude `range / 2` (>= 0).
    pub fn amplitude(&self) -> f64 {
        0.5 * self.range()
    }
}

/// Turning points of a history fed one value at a time: the same points as
/// [`turning_points`] without keeping the history (a per-tooth history of a long run holds
/// millions of samples but only a few points per impact). Non-finite values are skipped.
///
/// [`Self::push`] hands back each point as soon as it is known to be a turning point (the
/// first value at once, every other one when the history turns after it); [`Self::last`] is
/// the final point of the history fed so far. Nothing is kept but the last value, so a
/// counter that takes the points as they come ([`Rainflow`]) holds memory that does not grow
/// with the history.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TurningPoints {
    /// the last value fed (plateaus collapse onto it)
    current: Option<f64>,
    /// direction of the last change: +1 rising, -1 falling, 0 none yet
    direction: i8,
    fed: usize,
}

impl TurningPoints {
    /// No points yet.
    pub fn new() -> TurningPoints {
        TurningPoints::default()
    }

    /// Feeds the next value of the history; returns the point this value confirms as a
    /// turning point, if any (the first value, or the previous value where the history
    /// turns).
    pub fn push(&mut self, x: f64) -> Option<f64> {
        if !x.is_finite() {
            return None;
        }
        self.fed += 1;
        let mut confirmed = None;
        match self.current {
            None => confirmed = Some(x),
            Some(c) => {
                if x == c {
                    return None;
                }
                let d = if x > c { 1 } else { -1 };
                if self.direction != 0 && d != self.direction {
                    confirmed = Some(c);
                }
                self.direction = d;
            }
        }
        self.current = Some(x);
        confirmed
    }

    /// The final point of the history fed so far: its last value when two or more values
    /// were fed (a history of two or more values always ends on its last value; a single
    /// value is one point, already handed back by [`Self::push`]).
    pub fn last(&self) -> Option<f64> {
        if self.fed >= 2 {
            self.current
        } else {
            None
        }
    }
}

/// Turning points of `history`: its first value, each value where it changes direction
/// (plateaus collapsed), and its last value. Non-finite values are skipped.
pub fn turning_points(history: &[f64]) -> Vec<f64> {
    let mut t = TurningPoints::new();
    let mut out: Vec<f64> = history.iter().filter_map(|&x| t.push(x)).collect();
    out.extend(t.last());
    out
}

/// Rainflow counting fed one turning point at a time (ASTM E1049-85 section 5.4.4, the
/// three-point method; see [`rainflow`]): each cycle is handed out as soon as it is counted,
/// and only the points not yet counted (the residue, a handful for a load history that keeps
/// returning to zero) are kept.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Rainflow {
    stack: Vec<f64>,
}

impl Rainflow {
    /// No points yet.
    pub fn new() -> Rainflow {
        Rainflow::default()
    }

    /// Takes the next turning point; calls `out` with each cycle it completes.
    pub fn push(&mut self, p: f64, mut out: impl FnMut(Cycle)) {
        let stack = &mut self.stack;
        stack.push(p);
        while stack.len() >= 3 {
            let n = stack.len();
            // ASTM E1049 5.4.4 (b)-(d): X = newest range, Y = the previous one
            let x = (stack[n - 1] - stack[n - 2]).abs();
            let y = (stack[n - 2] - stack[n - 3]).abs();
            if x < y {
                break;
            }
            if n == 3 {
                // (e): Y contains the starting point S: half a cycle, discard S
                out(Cycle {
                    from: stack[0],
                    to: stack[1],
                    count: 0.5,
                });
                stack.remove(0);
            } else {
                // (f): a full cycle; discard its peak and valley
                out(Cycle {
                    from: stack[n - 3],
                    to: stack[n - 2],
                    count: 1.0,
                });
                stack.drain(n - 3..n - 1);
            }
        }
    }

    /// Ends the history: the residue's ranges as half cycles (ASTM E1049 5.4.4 (g)), handed
    /// to `out` in order.
    pub fn finish(self, mut out: impl FnMut(Cycle)) {
        for w in self.stack.windows(2) {
            out(Cycle {
                from: w[0],
                to: w[1],
                count: 0.5,
            });
        }
    }

    /// Points held (the residue so far).
    pub fn held(&self) -> usize {
        self.stack.len()
    }
}

/// Rainflow counting of a sequence of turning points by ASTM E1049-85 section 5.4.4 (the
/// three-point method), the residue counted as half cycles. Cycles come in the order they
/// are counted. Feeding a raw history gives the same cycles as its turning points only when
/// it has no interior points that are not turning points: pass it through
/// [`turning_points`] first.
pub fn rainflow(points: &[f64]) -> Vec<Cycle> {
    let mut out = Vec::new();
    let mut r = Rainflow::new();
    for &p in points {
        r.push(p, |c| out.push(c));
    }
    r.finish(|c| out.push(c));
    out
}

/// The counted cycles summed per distinct range, as (range, count) sorted by range: the form
/// of the PyPI `rainflow` package's `count_cycles` without binning.
pub fn count_ranges(cycles: &[Cycle]) -> Vec<(f64, f64)> {
    let mut r: Vec<(f64, f64)> = cycles.iter().map(|c| (c.range(), c.count)).collect();
    r.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(r.len());
    for (range, n) in r {
        match out.last_mut() {
            Some(last) if last.0 == range => last.1 += n,
            _ => out.push((range, n)),
        }
    }
    out
}

/// The load history of a train of pulses `0, P1, 0, P2, ..., 0` from the signed peaks.
pub fn pulse_history(peaks: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut h = vec![0.0];
    for p in peaks {
        h.push(p);
        h.push(0.0);
    }
    h
}

/// Samples strictly inside a contact, at or above which the contact is counted from its
/// samples rather than as one pulse (see [`impact_history`]). Four samples show the rise,
/// the top and the fall of a load; an impact of the paper's case (~70 us) sampled at
/// 10 kHz holds none or one.
pub const SUSTAINED_CONTACT_SAMPLES: usize = 4;

/// The signed per-tooth load history of one coupling from its impact events (any order;
/// they are taken by onset) and its sampled loads `(t s, load N)` in time order.
///
/// Each event is a pulse `0, peak, 0`. An event holding at least
/// [`SUSTAINED_CONTACT_SAMPLES`] samples with a non-zero load strictly inside
/// `(t_on_s, t_off_s)` is a sustained contact: its history is `0`, those samples with the
/// located peak merged in at `t_peak_s` (time order), `0`. Samples outside every event and
/// zero loads are not part of the history (the teeth are free there).
pub fn impact_history(events: &[ImpactEvent], samples: &[(f64, f64)]) -> Vec<f64> {
    let mut ev: Vec<&ImpactEvent> = events.iter().collect();
    ev.sort_by(|a, b| a.t_on_s.total_cmp(&b.t_on_s));
    let mut h = vec![0.0];
    for e in ev {
        let lo = samples.partition_point(|s| s.0 <= e.t_on_s);
        let inside: Vec<(f64, f64)> = samples[lo..]
            .iter()
            .take_while(|s| s.0 < e.t_off_s)
            .filter(|s| s.1 != 0.0)
            .copied()
            .collect();
        if inside.len() >= SUSTAINED_CONTACT_SAMPLES {
            let mut merged = inside;
            let at = merged.partition_point(|s| s.0 <= e.t_peak_s);
            merged.insert(at, (e.t_peak_s, e.peak_n));
            h.extend(merged.iter().map(|s| s.1));
        } else {
            h.push(e.peak_n);
        }
        h.push(0.0);
    }
    h
}

/// The signed peak of each contact of a sampled history: a contact is a maximal run of
/// non-zero values of one sign, its peak the value of largest magnitude.
pub fn contact_peaks(history: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    let mut cur: Option<f64> = None;
    for &x in history {
        let same = cur.is_some_and(|p| x != 0.0 && (x > 0.0) == (p > 0.0));
        if same {
            let p = cur.unwrap_or(0.0);
            if x.abs() > p.abs() {
                cur = Some(x);
            }
        } else {
            out.extend(cur.take());
            if x != 0.0 && x.is_finite() {
                cur = Some(x);
            }
        }
    }
    out.extend(cur);
    out
}

/// One bin of a histogram of cycle ranges.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeBin {
    /// Lower edge (inclusive), in the unit of the ranges.
    pub lo: f64,
    /// Upper edge (exclusive; the last bin includes it).
    pub hi: f64,
    /// Cycles counted in the bin (half cycles count 0.5).
    pub count: f64,
}

fn bin_of(x: f64, lo: f64, width: f64, bins: usize) -> usize {
    if width <= 0.0 {
        return 0;
    }
    (((x - lo) / width).floor().max(0.0) as usize).min(bins - 1)
}

/// Histogram of the cycles' ranges in `bins` equal bins from 0 to the largest range (empty
/// without cycles or bins).
pub fn range_histogram(cycles: &[Cycle], bins: usize) -> Vec<RangeBin> {
    if cycles.is_empty() || bins == 0 {
        return Vec::new();
    }
    let top = cycles.iter().map(Cycle::range).fold(0.0, f64::max);
    let width = top / bins as f64;
    let mut out: Vec<RangeBin> = (0..bins)
        .map(|i| RangeBin {
            lo: i as f64 * width,
            hi: (i + 1) as f64 * width,
            count: 0.0,
        })
        .collect();
    for c in cycles {
        out[bin_of(c.range(), 0.0, width, bins)].count += c.count;
    }
    out
}

/// The range-mean (Markov) matrix of counted cycles: `counts[i][j]` cycles with range in bin
/// `i` and mean in bin `j`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RangeMeanMatrix {
    /// Edges of the range bins (`bins + 1` values, from 0), in the unit of the loads.
    pub range_edges: Vec<f64>,
    /// Edges of the mean bins (`bins + 1` values), in the unit of the loads.
    pub mean_edges: Vec<f64>,
    /// Cycle counts, `[range bin][mean bin]` (half cycles count 0.5).
    pub counts: Vec<Vec<f64>>,
}

/// The range-mean matrix of `cycles` with `range_bins` range bins from 0 to the largest
/// range and `mean_bins` mean bins over the span of the means.
pub fn range_mean_matrix(cycles: &[Cycle], range_bins: usize, mean_bins: usize) -> RangeMeanMatrix {
    let (rb, mb) = (range_bins.max(1), mean_bins.max(1));
    let top = cycles.iter().map(Cycle::range).fold(0.0, f64::max);
    let lo = cycles.iter().map(Cycle::mean).fold(f64::INFINITY, f64::min);
    let hi = cycles
        .iter()
        .map(Cycle::mean)
        .fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if cycles.is_empty() {
        (0.0, 0.0)
    } else {
        (lo, hi)
    };
    let (rw, mw) = (top / rb as f64, (hi - lo) / mb as f64);
    let mut counts = vec![vec![0.0; mb]; rb];
    for c in cycles {
        counts[bin_of(c.range(), 0.0, rw, rb)][bin_of(c.mean(), lo, mw, mb)] += c.count;
    }
    RangeMeanMatrix {
        range_edges: (0..=rb).map(|i| i as f64 * rw).collect(),
        mean_edges: (0..=mb).map(|i| lo + i as f64 * mw).collect(),
        counts,
    }
}

/// The exceedance spectrum of contact peaks: for each distinct peak magnitude `L` (N, from
/// the largest down), the number of peaks with `|P| >= L` per hour of a duty of `duration_s`
/// seconds. Empty without peaks or with a non-positive duration.
pub fn exceedance_spectrum(peaks: &[f64], duration_s: f64) -> Vec<(f64, f64)> {
    if duration_s.is_nan() || duration_s <= 0.0 {
        return Vec::new();
    }
    let mut m: Vec<f64> = peaks
        .iter()
        .map(|p| p.abs())
        .filter(|p| p.is_finite())
        .collect();
    m.sort_by(|a, b| b.total_cmp(a));
    let per_hour = 3600.0 / duration_s;
    let mut out: Vec<(f64, f64)> = Vec::new();
    for (i, &l) in m.iter().enumerate() {
        let n = (i + 1) as f64 * per_hour;
        match out.last_mut() {
            Some(last) if last.0 == l => last.1 = n,
            _ => out.push((l, n)),
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use clutchpack_model::Flank;

    use crate::Lcg;

    /// ASTM E1049-85 (2011) Fig. 6's worked example: the history
    /// [-2, 1, -3, 5, -1, 3, -4, 4, -2] gives exactly (3, 0.5), (4, 1.5), (6, 0.5), (8, 1.0),
    /// (9, 0.5). Exact: the values are small integers.
    #[test]
    fn astm_e1049_worked_example() {
        let h = [-2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0];
        let tp = turning_points(&h);
        assert_eq!(tp, h.to_vec());
        let c = count_ranges(&rainflow(&tp));
        assert_eq!(
            c,
            vec![(3.0, 0.5), (4.0, 1.5), (6.0, 0.5), (8.0, 1.0), (9.0, 0.5)]
        );
    }

    /// Turning points: plateaus collapse, points on a monotone stretch go, the ends stay;
    /// the streaming form gives the same points as the batch form.
    #[test]
    fn turning_points_of_small_histories() {
        assert_eq!(
            turning_points(&[0.0, 1.0, 2.0, 1.0, 1.0, 0.0, 3.0]),
            vec![0.0, 2.0, 0.0, 3.0]
        );
        assert_eq!(
            turning_points(&[0.0, 0.0, 1.0, 1.0, 0.0]),
            vec![0.0, 1.0, 0.0]
        );
        assert_eq!(turning_points(&[5.0]), vec![5.0]);
        assert_eq!(turning_points(&[]), Vec::<f64>::new());
        assert_eq!(
            turning_points(&[1.0, f64::NAN, 2.0, 0.0]),
            vec![1.0, 2.0, 0.0]
        );
        // alternating flanks pass through 0 without turning there: range 2P
        let h = pulse_history([500.0, -500.0, 500.0]);
        assert_eq!(turning_points(&h), vec![0.0, 500.0, -500.0, 500.0, 0.0]);
        let c = count_ranges(&rainflow(&turning_points(&h)));
        assert_eq!(c, vec![(500.0, 1.0), (1000.0, 1.0)]);
    }

    /// One flank only: n pulses of peak P are n cycles of range P (n - 1 full ones and the
    /// residue's two half cycles), R = 0.
    #[test]
    fn pulses_on_one_flank_are_pulsating_cycles() {
        let h = pulse_history(vec![-700.0; 9]);
        let c = rainflow(&turning_points(&h));
        assert_eq!(count_ranges(&c), vec![(700.0, 9.0)]);
        assert!(c.iter().all(|c| c.mean() == -350.0));
    }

    /// Properties over 500 random histories: the largest counted range equals the history's
    /// peak-to-valley span (the global extremes always close one range), and the counts
    /// conserve the ranges between turning points: sum of 2 x count = turning points - 1.
    /// Both are exact (no arithmetic beyond subtraction of the same two values).
    #[test]
    fn largest_range_is_the_span_and_counts_conserve() {
        let mut g = Lcg(2024);
        for case in 0..500 {
            let n = 2 + (g.next() * 200.0) as usize;
            let h: Vec<f64> = (0..n)
                .map(|_| (g.next() * 2000.0 - 1000.0).round())
                .collect();
            let tp = turning_points(&h);
            let c = rainflow(&tp);
            let span = h.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
                - h.iter().fold(f64::INFINITY, |a, &b| a.min(b));
            let top = c.iter().map(Cycle::range).fold(0.0, f64::max);
            assert_eq!(top, span, "case {case}");
            let twice: f64 = c.iter().map(|c| 2.0 * c.count).sum();
            assert_eq!(twice, (tp.len() - 1) as f64, "case {case}");
            // the streamed points equal the definition applied to the whole history:
            // plateaus collapsed, then the ends and every strict local extremum
            let mut flat: Vec<f64> = h.clone();
            flat.dedup();
            let mut naive = vec![flat[0]];
            for w in flat.windows(3) {
                if (w[1] - w[0]) * (w[2] - w[1]) < 0.0 {
                    naive.push(w[1]);
                }
            }
            // two or more values always end on the last one (n >= 2 here)
            naive.push(*flat.last().unwrap());
            assert_eq!(tp, naive, "case {case}");
        }
    }

    /// An impact of disc 0 (closing at 0.1 m/s, the flank from the peak's sign), for the
    /// cycle and fatigue tests.
    pub(crate) fn event(t_on: f64, t_peak: f64, t_off: f64, peak: f64) -> ImpactEvent {
        ImpactEvent {
            disc: 0,
            t_on_s: t_on,
            t_peak_s: t_peak,
            t_off_s: t_off,
            flank: if peak > 0.0 {
                Flank::DiscLeads
            } else {
                Flank::ShaftLeads
            },
            v_on_m_s: 0.1,
            peak_n: peak,
        }
    }

    /// Short impacts are pulses whatever samples fall inside them; a contact holding four or
    /// more loaded samples is counted from them with its located peak merged in by time.
    #[test]
    fn impact_history_pulses_and_sustained_contacts() {
        let ev = [event(1.0, 1.05, 1.1, -800.0), event(0.1, 0.15, 0.2, 600.0)];
        let samples = [(0.12, 300.0), (1.02, -500.0), (1.5, 0.0)];
        assert_eq!(
            impact_history(&ev, &samples),
            vec![0.0, 600.0, 0.0, -800.0, 0.0]
        );
        // a locked contact from 2 s to 3 s with a load varying in it
        let locked = [event(2.0, 2.45, 3.0, -900.0)];
        let s: Vec<(f64, f64)> = [
            (1.9, 0.0),
            (2.1, -300.0),
            (2.3, -600.0),
            (2.5, -400.0),
            (2.7, -700.0),
            (2.9, -100.0),
            (3.1, 0.0),
        ]
        .to_vec();
        assert_eq!(
            impact_history(&locked, &s),
            vec![0.0, -300.0, -600.0, -900.0, -400.0, -700.0, -100.0, 0.0]
        );
    }

    /// Contact peaks of a sampled history: runs of one sign split at zeros and sign changes.
    #[test]
    fn contact_peaks_of_samples() {
        let h = [0.0, 1.0, 3.0, 2.0, 0.0, -1.0, -4.0, 2.0, 0.0, 0.0, 5.0];
        assert_eq!(contact_peaks(&h), vec![3.0, -4.0, 2.0, 5.0]);
    }

    /// Exceedance: counts of |peak| >= level, per hour; histogram and matrix keep the counts.
    #[test]
    fn spectra_keep_the_counts() {
        let ex = exceedance_spectrum(&[-100.0, 300.0, 200.0, -300.0], 1.8);
        assert_eq!(ex, vec![(300.0, 4000.0), (200.0, 6000.0), (100.0, 8000.0)]);
        assert!(exceedance_spectrum(&[1.0], 0.0).is_empty());
        let c = rainflow(&turning_points(&[
            -2.0, 1.0, -3.0, 5.0, -1.0, 3.0, -4.0, 4.0, -2.0,
        ]));
        let total: f64 = c.iter().map(|c| c.count).sum();
        let h = range_histogram(&c, 3);
        assert_eq!(h.len(), 3);
        assert_eq!(h.iter().map(|b| b.count).sum::<f64>(), total);
        assert_eq!(h[2].hi, 9.0);
        let m = range_mean_matrix(&c, 4, 5);
        assert_eq!(m.counts.iter().flatten().sum::<f64>(), total);
        assert_eq!(m.range_edges.len(), 5);
        assert_eq!(m.mean_edges.len(), 6);
        assert!(range_histogram(&[], 3).is_empty());
    }
}
