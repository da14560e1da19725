//! Per-disc statistics of the impact peaks of one run.
//!
//! A run's impacts are chaotic in detail but stable in distribution (MODEL.md section 6), so
//! runs are compared by the extremes and the upper tail of the peak loads: the largest
//! positive and negative peaks, the 99th percentile of `|peak|` and the mean of the ten
//! largest `|peak|`.

use clutchpack_model::ImpactEvent;
use serde::{Deserialize, Serialize};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Number of impacts averaged by [`DiscStats::mean_top10_abs_n`].
pub const TOP_N: usize = 10;

/// Statistics of the impact peaks (`ImpactEvent::peak_n`) of one disc over one run.
///
/// Loads are per tooth in N, signed as in the model: negative when the shaft leads, positive
/// when the disc leads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscStats {
    /// Disc name (from the scene).
    pub name: String,
    /// Largest positive peak (disc leads) in N; 0 if there is none.
    pub max_positive_n: f64,
    /// Most negative peak (shaft leads) in N, a value `<= 0`; 0 if there is none.
    pub max_negative_n: f64,
    /// 99th percentile of `|peak|` over the disc's impacts in N ([`percentile`]'s linear
    /// interpolation, as numpy's default); 0 if there are no impacts.
    pub p99_abs_n: f64,
    /// Number of impacts.
    pub impacts: usize,
    /// Number of impacts with a positive peak (disc leads).
    pub positive_impacts: usize,
    /// Number of impacts with a negative peak (shaft leads).
    pub negative_impacts: usize,
    /// Mean of the [`TOP_N`] = 10 largest `|peak|` in N (of all of them if there are fewer);
    /// 0 if there are no impacts.
    pub mean_top10_abs_n: f64,
}

impl DiscStats {
    /// Statistics of a disc without impacts: all zeros.
    pub fn empty(name: impl Into<String>) -> DiscStats {
        DiscStats {
            name: name.into(),
            max_positive_n: 0.0,
            max_negative_n: 0.0,
            p99_abs_n: 0.0,
            impacts: 0,
            positive_impacts: 0,
            negative_impacts: 0,
            mean_top10_abs_n: 0.0,
        }
    }

    /// Statistics of the signed peak loads `peaks_n` (N) of one disc named `name`.
    ///
    /// NaN peaks are not counted (a finite run never produces them).
    pub fn from_peaks(name: impl Into<String>, peaks_n: &[f64]) -> DiscStats {
        let mut s = DiscStats::empty(name);
        let mut abs: Vec<f64> = Vec::with_capacity(peaks_n.len());
        for &p in peaks_n.iter().filter(|p| !p.is_nan()) {
            s.count(p);
            abs.push(p.abs());
        }
        abs.sort_by(f64::total_cmp);
        s.finish_top(&abs);
        s
    }

    /// Counts one signed peak (N, not NaN) in the counts and extremes.
    fn count(&mut self, p: f64) {
        self.impacts += 1;
        if p > 0.0 {
            self.positive_impacts += 1;
            self.max_positive_n = self.max_positive_n.max(p);
        } else if p < 0.0 {
            self.negative_impacts += 1;
            self.max_negative_n = self.max_negative_n.min(p);
        }
    }

    /// Sets the 99th percentile and the top-10 mean from `top`, the largest `|peak|` of the
    /// `self.impacts` counted, sorted ascending, at least [`top_needed`] of them.
    fn finish_top(&mut self, top: &[f64]) {
        if top.is_empty() {
            return;
        }
        self.p99_abs_n = percentile_of_top(top, self.impacts, 99.0);
        let ten = &top[top.len().saturating_sub(TOP_N)..];
        self.mean_top10_abs_n = ten.iter().sum::<f64>() / ten.len() as f64;
    }
}

/// How many of the largest of `n` values the 99th percentile and the top-10 mean need.
fn top_needed(n: usize) -> usize {
    if n == 0 {
        return 0;
    }
    let (lo, _, _) = percentile_index(n, 99.0);
    (n - lo).max(TOP_N).min(n)
}

/// `|peak|` values held in memory by [`PeakStats`] before they go to its temporary file
/// (16 bytes each in memory: 64 kB, reached within about 2 s simulated of a 4-disc rattling
/// pack, so that a run's memory is the same after 3 s as after 300 s; 16 384 held 256 kB that
/// a long run filled and a short one did not).
pub const PEAKS_IN_MEMORY: usize = 4_096;

/// Per-disc statistics ([`DiscStats`]) of impact peaks taken one at a time, in memory that
/// does not grow with the run.
///
/// Counts and extremes are kept as they come. The exact 99th percentile needs every
/// `|peak|`: up to [`PEAKS_IN_MEMORY`] of them are held in memory, the rest go to an unnamed
/// temporary file (in `TMPDIR`, removed by the system when the run ends, however it ends),
/// read back once by [`Self::stats`] keeping only each disc's top 1 % (at least ten). The
/// figures equal [`disc_stats`] of the same peaks exactly. If the temporary file cannot be
/// created or written (no space), the values stay in memory: nothing is lost.
#[derive(Debug, Default)]
pub struct PeakStats {
    discs: Vec<DiscStats>,
    /// (disc, |peak| N) not yet written to the file
    held: Vec<(u32, f64)>,
    file: Option<std::fs::File>,
    /// the file failed: hold everything
    in_memory_only: bool,
}

/// Bytes of one (disc u32, |peak| f64) record of the temporary file.
const RECORD_BYTES: usize = 12;

impl PeakStats {
    /// No peaks yet.
    pub fn new() -> PeakStats {
        PeakStats::default()
    }

    /// The largest `|peak|` of disc `disc` so far, N (0 before its first impact).
    pub fn max_abs_n(&self, disc: usize) -> f64 {
        self.discs
            .get(disc)
            .map_or(0.0, |d| d.max_positive_n.max(-d.max_negative_n))
    }

    /// Impacts counted so far.
    pub fn impacts(&self) -> usize {
        self.discs.iter().map(|d| d.impacts).sum()
    }

    /// Takes one impact's signed peak `peak_n` (N) of disc `disc`; NaN is not counted.
    pub fn push(&mut self, disc: usize, peak_n: f64) {
        if peak_n.is_nan() {
            return;
        }
        if self.discs.len() <= disc {
            self.discs.resize_with(disc + 1, || DiscStats::empty(""));
        }
        self.discs[disc].count(peak_n);
        self.held.push((disc as u32, peak_n.abs()));
        if self.held.len() >= PEAKS_IN_MEMORY && !self.in_memory_only {
            if let Err(_e) = self.spill() {
                // no temporary space: keep the values in memory rather than lose them
                self.in_memory_only = true;
            }
        }
    }

    /// An independent copy (a steppable run's saved state): the values spilled to the
    /// temporary file are copied to a new one. Errors only when the file cannot be copied.
    pub fn try_clone(&self) -> std::io::Result<PeakStats> {
        use std::io::{Seek, SeekFrom};
        let file = match self.file.as_ref() {
            Some(mut f) => {
                f.seek(SeekFrom::Start(0))?;
                let mut copy = tempfile::tempfile()?;
                std::io::copy(&mut f, &mut copy)?;
                Some(copy)
            }
            None => None,
        };
        Ok(PeakStats {
            discs: self.discs.clone(),
            held: self.held.clone(),
            file,
            in_memory_only: self.in_memory_only,
        })
    }

    /// Whether some values went to the temporary file.
    pub fn spilled(&self) -> bool {
        self.file.is_some()
    }

    fn spill(&mut self) -> std::io::Result<()> {
        let mut bytes = Vec::with_capacity(self.held.len() * RECORD_BYTES);
        for &(d, v) in &self.held {
            bytes.extend_from_slice(&d.to_le_bytes());
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        append_to_temp(&mut self.file, &bytes)?;
        self.held.clear();
        Ok(())
    }

    /// The statistics so far, one entry per disc in `names` order (as [`disc_stats`]: discs
    /// without impacts get zeros, impacts of discs past `names` get entries `disc {index}`).
    ///
    /// Errors only when the temporary file cannot be read back.
    pub fn stats(&self, names: &[String]) -> std::io::Result<Vec<DiscStats>> {
        let n = self.discs.len().max(names.len());
        let need: Vec<usize> = (0..n)
            .map(|i| top_needed(self.discs.get(i).map_or(0, |d| d.impacts)))
            .collect();
        // each disc's largest |peak| in a min-heap of bounded size
        let mut tops: Vec<BinaryHeap<Reverse<Ordered>>> = need
            .iter()
            .map(|&k| BinaryHeap::with_capacity(k + 1))
            .collect();
        let mut take = |d: usize, v: f64| {
            let (heap, k) = (&mut tops[d], need[d]);
            heap.push(Reverse(Ordered(v)));
            if heap.len() > k {
                heap.pop();
            }
        };
        if let Some(mut f) = self.file.as_ref() {
            use std::io::{Read, Seek, SeekFrom};
            f.seek(SeekFrom::Start(0))?;
            let mut r = std::io::BufReader::with_capacity(1 << 16, f);
            let mut rec = [0u8; RECORD_BYTES];
            loop {
                match r.read_exact(&mut rec) {
                    Ok(()) => {}
                    Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
                    Err(e) => return Err(e),
                }
                let d = u32::from_le_bytes([rec[0], rec[1], rec[2], rec[3]]) as usize;
                let mut v = [0u8; 8];
                v.copy_from_slice(&rec[4..]);
                if d < n {
                    take(d, f64::from_le_bytes(v));
                }
            }
        }
        for &(d, v) in &self.held {
            take(d as usize, v);
        }
        Ok(tops
            .into_iter()
            .enumerate()
            .map(|(i, heap)| {
                let mut s = self
                    .discs
                    .get(i)
                    .cloned()
                    .unwrap_or_else(|| DiscStats::empty(""));
                s.name = names.get(i).cloned().unwrap_or_else(|| format!("disc {i}"));
                let mut top: Vec<f64> = heap.into_iter().map(|Reverse(Ordered(v))| v).collect();
                top.sort_by(f64::total_cmp);
                s.finish_top(&top);
                s
            })
            .collect())
    }
}

/// An `f64` ordered by [`f64::total_cmp`] (for the heaps of [`PeakStats::stats`]).
#[derive(Debug, Clone, Copy)]
struct Ordered(f64);
impl PartialEq for Ordered {
    fn eq(&self, o: &Self) -> bool {
        self.0.total_cmp(&o.0).is_eq()
    }
}
impl Eq for Ordered {}
impl PartialOrd for Ordered {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Ordered {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

/// Per-disc statistics of a run's impacts, one entry per disc in `names` order.
///
/// `ImpactEvent::disc` indexes `names`. A disc without impacts gets zeros. Impacts whose
/// disc index is beyond `names` are not dropped: entries named `disc {index}` are appended
/// for them, so the output has `max(names.len(), largest index + 1)` entries.
pub fn disc_stats(names: &[String], impacts: &[ImpactEvent]) -> Vec<DiscStats> {
    let n_discs = impacts
        .iter()
        .map(|e| e.disc + 1)
        .max()
        .unwrap_or(0)
        .max(names.len());
    let mut peaks: Vec<Vec<f64>> = vec![Vec::new(); n_discs];
    for e in impacts {
        peaks[e.disc].push(e.peak_n);
    }
    peaks
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let name = names.get(i).cloned().unwrap_or_else(|| format!("disc {i}"));
            DiscStats::from_peaks(name, p)
        })
        .collect()
}

/// The `q`-th percentile (`q` in `[0, 100]`, clamped) of `values`, in their unit.
///
/// Definition: numpy's default `method = 'linear'` (Hyndman & Fan type 7). With the `n`
/// values sorted ascending as `v[0] <= ... <= v[n-1]`, the position is `h = (n - 1) q / 100`
/// and the result `v[floor(h)] + (h - floor(h)) (v[floor(h) + 1] - v[floor(h)])`: linear
/// interpolation between the order statistics around `h`. So `q = 0` gives the minimum,
/// `q = 100` the maximum and `q = 50` the median.
///
/// NaN values are ignored; an empty slice (or one of NaNs only) gives 0. A NaN `q` gives NaN.
pub fn percentile(values: &[f64], q: f64) -> f64 {
    if q.is_nan() {
        return f64::NAN;
    }
    let mut v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
    v.sort_by(f64::total_cmp);
    percentile_sorted(&v, q)
}

/// [`percentile`] of values already sorted ascending and free of NaN.
fn percentile_sorted(sorted: &[f64], q: f64) -> f64 {
    percentile_of_top(sorted, sorted.len(), q)
}

/// The order statistics around the `q`-th percentile of `n` values: (lower index, upper
/// index, interpolation fraction), [`percentile`]'s definition.
fn percentile_index(n: usize, q: f64) -> (usize, usize, f64) {
    let h = (n - 1) as f64 * q.clamp(0.0, 100.0) / 100.0;
    let lo = (h.floor() as usize).min(n - 1);
    let hi = (lo + 1).min(n - 1);
    (lo, hi, h - lo as f64)
}

/// [`percentile`] of `n` values of which `top` holds the largest, sorted ascending (all of
/// them, or at least the ones from the percentile's lower index on).
fn percentile_of_top(top: &[f64], n: usize, q: f64) -> f64 {
    if n == 0 || top.is_empty() {
        return 0.0;
    }
    let (lo, hi, frac) = percentile_index(n, q);
    // sorted[i] of all n values is top[i - skipped]
    let skipped = n - top.len();
    let at = |i: usize| top[i.saturating_sub(skipped).min(top.len() - 1)];
    if frac == 0.0 || lo == hi {
        at(lo)
    } else {
        at(lo) + frac * (at(hi) - at(lo))
    }
}

/// Appends `bytes` to the unnamed temporary file in `file` (made at the first call; removed
/// by the system when it is closed): the one spill of what a long run would otherwise hold
/// in memory ([`PeakStats`], the fatigue collector's pending contact samples). Always at the
/// end: reading back may have moved the offset.
pub(crate) fn append_to_temp(
    file: &mut Option<std::fs::File>,
    bytes: &[u8],
) -> std::io::Result<()> {
    use std::io::{Seek, SeekFrom, Write};
    let mut f = match file {
        Some(f) => &*f,
        None => &*file.insert(tempfile::tempfile()?),
    };
    f.seek(SeekFrom::End(0))?;
    f.write_all(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use clutchpack_model::Flank;

    fn ev(disc: usize, peak_n: f64) -> ImpactEvent {
        ImpactEvent {
            disc,
            t_on_s: 0.0,
            t_peak_s: 0.0,
            t_off_s: 0.0,
            flank: if peak_n > 0.0 {
                Flank::DiscLeads
            } else {
                Flank::ShaftLeads
            },
            v_on_m_s: 0.1,
            peak_n,
        }
    }

    /// Values printed by numpy 1.26, `np.percentile(v, q)` with the default method.
    #[test]
    fn percentile_matches_numpy_linear() {
        // np.percentile([15, 20, 35, 40, 50], 40) = 29.0 (h = 1.6: 20 + 0.6 * 15)
        assert_relative_eq!(percentile(&[15.0, 20.0, 35.0, 40.0, 50.0], 40.0), 29.0);
        // np.percentile([1, 2, 3, 4], 99) = 3.97 (h = 2.97)
        assert_relative_eq!(
            percentile(&[1.0, 2.0, 3.0, 4.0], 99.0),
            3.97,
            max_relative = 1e-15
        );
        // np.percentile([10, 7, 4, 3, 2, 1], 50) = 3.5: unsorted input, median of an even count
        assert_relative_eq!(percentile(&[10.0, 7.0, 4.0, 3.0, 2.0, 1.0], 50.0), 3.5);
        // np.percentile([1, 2, 3, 4], 25) = 1.75
        assert_relative_eq!(percentile(&[1.0, 2.0, 3.0, 4.0], 25.0), 1.75);
        // np.percentile(range(101), 99) = 99.0: exactly on an order statistic
        let r: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(percentile(&r, 99.0), 99.0);
        // np.percentile(range(10), 99) = 8.91 (h = 8.91)
        let r: Vec<f64> = (0..10).map(f64::from).collect();
        assert_relative_eq!(percentile(&r, 99.0), 8.91, max_relative = 1e-15);
    }

    /// The ends and the degenerate cases: q = 0 / 100 are min / max, q is clamped, one value
    /// is every percentile, an empty slice gives 0, NaN values are ignored.
    #[test]
    fn percentile_edges() {
        let v = [-3.0, 5.0, 1.0];
        assert_eq!(percentile(&v, 0.0), -3.0);
        assert_eq!(percentile(&v, 100.0), 5.0);
        assert_eq!(percentile(&v, -10.0), -3.0);
        assert_eq!(percentile(&v, 250.0), 5.0);
        assert_eq!(percentile(&[7.5], 37.0), 7.5);
        assert_eq!(percentile(&[], 99.0), 0.0);
        assert_eq!(percentile(&[f64::NAN, 2.0, 4.0], 50.0), 3.0);
        assert!(percentile(&v, f64::NAN).is_nan());
    }

    /// A hand-made run of two discs: the signs pick the flank counts and extremes, |peak|
    /// feeds the percentile and the top-10 mean (all hand-computed).
    #[test]
    fn disc_stats_of_a_hand_made_run() {
        let names = vec!["d0".to_string(), "d1".to_string(), "idle".to_string()];
        let mut impacts = vec![ev(0, -100.0), ev(1, 50.0), ev(0, 300.0), ev(0, -250.0)];
        impacts.push(ev(0, 20.0));
        // disc 1: twelve impacts 10, -20, 30, ..., -120 (alternating sign)
        for k in 1..=11 {
            let m = 10.0 * (k + 1) as f64;
            impacts.push(ev(1, if k % 2 == 1 { -m } else { m }));
        }
        let s = disc_stats(&names, &impacts);
        assert_eq!(s.len(), 3);

        let d0 = &s[0];
        assert_eq!(d0.name, "d0");
        assert_eq!(
            (d0.impacts, d0.positive_impacts, d0.negative_impacts),
            (4, 2, 2)
        );
        assert_eq!(d0.max_positive_n, 300.0);
        assert_eq!(d0.max_negative_n, -250.0);
        // |peak| sorted: 20 100 250 300; h = 3 * 0.99 = 2.97 -> 250 + 0.97 * 50
        assert_relative_eq!(d0.p99_abs_n, 298.5, max_relative = 1e-14);
        assert_relative_eq!(d0.mean_top10_abs_n, 670.0 / 4.0);

        // disc 1: the 50 above plus 20, 30, ..., 120: 12 impacts
        let d1 = &s[1];
        assert_eq!(d1.impacts, 12);
        // positives: 50, 30, 50, 70, 90, 110 -> 6; negatives: 20, 40, ..., 120 -> 6
        assert_eq!((d1.positive_impacts, d1.negative_impacts), (6, 6));
        assert_eq!(d1.max_positive_n, 110.0);
        assert_eq!(d1.max_negative_n, -120.0);
        // top 10 of {20,30,40,50,50,60,...,120}: all but 20 and 30
        let top: f64 = [
            40.0, 50.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0, 110.0, 120.0,
        ]
        .iter()
        .sum();
        assert_relative_eq!(d1.mean_top10_abs_n, top / 10.0);
        // sorted 12 values, h = 11 * 0.99 = 10.89: 110 + 0.89 * 10
        assert_relative_eq!(d1.p99_abs_n, 118.9, max_relative = 1e-14);

        assert_eq!(s[2], DiscStats::empty("idle"));
    }

    /// Empty input gives zeros, and impacts of unnamed discs get entries of their own.
    #[test]
    fn disc_stats_empty_and_unnamed() {
        assert!(disc_stats(&[], &[]).is_empty());
        let s = disc_stats(&["a".to_string()], &[]);
        assert_eq!(s, vec![DiscStats::empty("a")]);
        let s = disc_stats(&["a".to_string()], &[ev(2, -5.0)]);
        assert_eq!(s.len(), 3);
        assert_eq!(s[1], DiscStats::empty("disc 1"));
        assert_eq!(s[2].name, "disc 2");
        assert_eq!(s[2].max_negative_n, -5.0);
        assert_eq!(s[2].max_positive_n, 0.0);
    }

    /// Only negative peaks: the positive maximum stays 0 (not the "largest" negative value).
    #[test]
    fn one_sided_runs_report_zero_on_the_other_side() {
        let s = DiscStats::from_peaks("x", &[-3.0, -1.0]);
        assert_eq!(s.max_positive_n, 0.0);
        assert_eq!(s.max_negative_n, -3.0);
        let s = DiscStats::from_peaks("x", &[3.0, 1.0]);
        assert_eq!(s.max_negative_n, 0.0);
        assert_eq!(s.max_positive_n, 3.0);
    }

    /// The statistics survive a JSON round trip unchanged, under their unit-suffixed names.
    #[test]
    fn serde_round_trip() {
        let s = DiscStats::from_peaks("x", &[1.0, -2.0]);
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.contains("\"max_negative_n\":-2.0"));
        assert_eq!(serde_json::from_str::<DiscStats>(&json).unwrap(), s);
    }

    /// The bounded accumulator gives exactly the statistics of the whole list
    /// ([`disc_stats`]), below and far above its in-memory limit (values in the temporary
    /// file), with ties, discs without impacts and impacts past the names; asked mid-run and
    /// fed on, it still appends (the read-back moves the file offset).
    #[test]
    fn peak_stats_equal_the_whole_list_in_and_beyond_memory() {
        let mut rng = crate::Lcg(12345);
        let mut next = move || rng.next();
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        for total in [0, 7, 1000, 3 * PEAKS_IN_MEMORY + 17] {
            let mut acc = PeakStats::new();
            let mut events = Vec::new();
            for k in 0..total {
                // disc 1 never hits; disc 3 is past the names; rounded loads tie often
                let disc = [0, 2, 2, 3][k % 4];
                let peak = ((next() - 0.5) * 2000.0).round();
                acc.push(disc, peak);
                events.push(ev(disc, peak));
                if k == total / 2 {
                    assert_eq!(acc.stats(&names).unwrap(), disc_stats(&names, &events));
                }
            }
            acc.push(0, f64::NAN);
            assert_eq!(acc.spilled(), total > PEAKS_IN_MEMORY, "{total}");
            assert_eq!(acc.impacts(), total);
            let want = disc_stats(&names, &events);
            assert_eq!(acc.stats(&names).unwrap(), want, "{total} impacts");
            assert_eq!(want.len(), if total > 3 { 4 } else { 3 });
        }
    }
}
