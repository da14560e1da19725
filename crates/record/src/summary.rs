//! The per-disc summary stored on `/summary` at the end of a run.
//!
//! A disc's entry is `clutchpack_analysis::DiscStats` itself (one definition of max, p99 and
//! top-10 mean for the whole project); this module only converts it to and from the
//! `/summary` message.

use crate::proto;
pub use clutchpack_analysis::DiscStats;
use clutchpack_model::ImpactEvent;

/// How many of the largest `|peak|` the "top" mean takes (10).
pub use clutchpack_analysis::stats::TOP_N;

/// Disc indices past the named discs that [`RunSummary::from_impacts`] still gives entries.
pub const MAX_EXTRA_DISCS: usize = 1024;

/// A run's summary: one [`DiscStats`] per disc in scene order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunSummary {
    /// Simulated time at the end of the run in s.
    pub t_end_s: f64,
    /// One entry per disc, in scene order.
    pub discs: Vec<DiscStats>,
}

impl RunSummary {
    /// The summary of `impacts` for discs named `names` (`ImpactEvent::disc` indexes
    /// `names`; impacts of an index beyond it get entries named `disc <index>`, up to
    /// [`MAX_EXTRA_DISCS`] past the names, and impacts beyond that are not counted: a
    /// foreign file's index cannot make this allocate without bound), at the end time
    /// `t_end_s` (s).
    pub fn from_impacts(names: &[String], impacts: &[ImpactEvent], t_end_s: f64) -> RunSummary {
        let limit = names.len() + MAX_EXTRA_DISCS;
        let n = impacts
            .iter()
            .map(|e| e.disc + 1)
            .filter(|&n| n <= limit)
            .max()
            .unwrap_or(0)
            .max(names.len());
        let mut peaks = vec![Vec::new(); n];
        for e in impacts.iter().filter(|e| e.disc < n) {
            peaks[e.disc].push(e.peak_n);
        }
        RunSummary {
            t_end_s,
            discs: peaks
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let name = names.get(i).cloned().unwrap_or_else(|| format!("disc {i}"));
                    DiscStats::from_peaks(name, p)
                })
                .collect(),
        }
    }

    pub(crate) fn to_proto(&self) -> proto::RunSummary {
        proto::RunSummary {
            t_end_s: self.t_end_s,
            discs: self
                .discs
                .iter()
                .enumerate()
                .map(|(i, d)| proto::DiscSummary {
                    name: d.name.clone(),
                    index: i as u32,
                    max_positive_n: d.max_positive_n,
                    max_negative_n: d.max_negative_n,
                    p99_abs_n: d.p99_abs_n,
                    impacts: d.impacts as u64,
                    positive_impacts: d.positive_impacts as u64,
                    negative_impacts: d.negative_impacts as u64,
                    mean_top10_abs_n: d.mean_top10_abs_n,
                })
                .collect(),
        }
    }

    pub(crate) fn from_proto(p: proto::RunSummary) -> RunSummary {
        RunSummary {
            t_end_s: p.t_end_s,
            discs: p
                .discs
                .into_iter()
                .map(|d| DiscStats {
                    name: d.name,
                    max_positive_n: d.max_positive_n,
                    max_negative_n: d.max_negative_n,
                    p99_abs_n: d.p99_abs_n,
                    // A count in a foreign file beyond usize saturates rather than wraps.
                    impacts: usize::try_from(d.impacts).unwrap_or(usize::MAX),
                    positive_impacts: usize::try_from(d.positive_impacts).unwrap_or(usize::MAX),
                    negative_impacts: usize::try_from(d.negative_impacts).unwrap_or(usize::MAX),
                    mean_top10_abs_n: d.mean_top10_abs_n,
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::Flank;

    fn ev(disc: usize, peak_n: f64) -> ImpactEvent {
        ImpactEvent {
            disc,
            t_on_s: 0.0,
            t_peak_s: 0.0,
            t_off_s: 0.0,
            flank: Flank::of(-peak_n),
            v_on_m_s: 0.0,
            peak_n,
        }
    }

    /// Extremes, counts, numpy-linear p99 and the top-10 mean of a known set of peaks:
    /// |peaks| = 1..=20, so p99 = 19 + 0.81 * 1 = 19.81 and the top ten average 15.5.
    #[test]
    fn statistics_of_known_peaks() {
        let peaks: Vec<f64> = (1..=20)
            .map(|i| if i % 2 == 0 { i as f64 } else { -(i as f64) })
            .collect();
        let s = DiscStats::from_peaks("a", &peaks);
        assert_eq!(s.impacts, 20);
        assert_eq!(s.positive_impacts, 10);
        assert_eq!(s.negative_impacts, 10);
        assert_eq!(s.max_positive_n, 20.0);
        assert_eq!(s.max_negative_n, -19.0);
        assert!((s.p99_abs_n - 19.81).abs() < 1e-12);
        assert!((s.mean_top10_abs_n - 15.5).abs() < 1e-12);
    }

    /// A disc without impacts gets zeros; an impact beyond the names gets its own entry.
    #[test]
    fn empty_discs_and_unknown_indices() {
        let s =
            RunSummary::from_impacts(&["a".into()], &[ev(2, 5.0), ev(usize::MAX / 2, 1.0)], 1.0);
        assert_eq!(s.discs.len(), 3, "an absurd index is not counted");
        assert_eq!(s.discs[0], DiscStats::from_peaks("a", &[]));
        assert_eq!(s.discs[0].p99_abs_n, 0.0);
        assert_eq!(s.discs[2].name, "disc 2");
        assert_eq!(s.discs[2].max_positive_n, 5.0);
        assert_eq!(RunSummary::from_proto(s.to_proto()), s);
    }
}
