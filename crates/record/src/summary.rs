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

/// Disc indices past the named discs that [`RecordedSummary::from_impacts`] still gives entries.
pub const MAX_EXTRA_DISCS: usize = 1024;

/// The fatigue figures of one disc kept in the recording's `/summary`
/// (`clutchpack_analysis::DiscFatigue` in short).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FatigueSummary {
    /// Damage per hour of the simulated duty, 1/h (>= 0).
    pub damage_rate_per_h: f64,
    /// Life in hours at this duty; `None`: unlimited (no damage).
    pub life_h: Option<f64>,
    /// Damage-equivalent load range for one hour at the knee's cycles, N.
    pub eq_load_range_n: f64,
    /// Largest tooth-root bending stress of the run, Pa.
    pub max_root_stress_pa: f64,
    /// The most damaged resolved tooth: (index, life in h or `None` if unlimited), with
    /// the number of resolved teeth; `None` when the engine did not resolve teeth.
    pub worst_tooth: Option<(u32, Option<f64>, u32)>,
}

impl From<&clutchpack_analysis::DiscFatigue> for FatigueSummary {
    fn from(d: &clutchpack_analysis::DiscFatigue) -> FatigueSummary {
        FatigueSummary {
            damage_rate_per_h: d.lumped.damage_rate_per_h,
            life_h: d.lumped.life_h,
            eq_load_range_n: d.lumped.eq_load_range_n,
            max_root_stress_pa: d.max_root_stress_pa,
            worst_tooth: d
                .teeth
                .as_ref()
                .map(|t| (t.worst_tooth as u32, t.worst.life_h, t.damage.len() as u32)),
        }
    }
}

/// What a recording stores of its run (its `/summary` topic, [`proto::SummaryMessage`] on
/// disk): one [`DiscStats`] per disc in scene order, and the discs' fatigue when
/// the run assessed it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RecordedSummary {
    /// Simulated time at the end of the run in s.
    pub t_end_s: f64,
    /// One entry per disc, in scene order.
    pub discs: Vec<DiscStats>,
    /// The fatigue of each disc's spline teeth (MODEL.md section 7), in the order of
    /// `discs`; empty when the run did not assess fatigue (older files, failed runs).
    pub fatigue: Vec<Option<FatigueSummary>>,
}

impl RecordedSummary {
    /// The summary of `impacts` for discs named `names` (`ImpactEvent::disc` indexes
    /// `names`; impacts of an index beyond it get entries named `disc <index>`, up to
    /// [`MAX_EXTRA_DISCS`] past the names, and impacts beyond that are not counted: a
    /// foreign file's index cannot make this allocate without bound), at the end time
    /// `t_end_s` (s).
    pub fn from_impacts(
        names: &[String],
        impacts: &[ImpactEvent],
        t_end_s: f64,
    ) -> RecordedSummary {
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
        RecordedSummary {
            t_end_s,
            discs: peaks
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let name = names.get(i).cloned().unwrap_or_else(|| format!("disc {i}"));
                    DiscStats::from_peaks(name, p)
                })
                .collect(),
            fatigue: Vec::new(),
        }
    }

    /// The fatigue of disc `i`, if the run assessed it.
    pub fn fatigue_of(&self, i: usize) -> Option<&FatigueSummary> {
        self.fatigue.get(i).and_then(Option::as_ref)
    }

    pub(crate) fn to_proto(&self) -> proto::SummaryMessage {
        proto::SummaryMessage {
            t_end_s: self.t_end_s,
            discs: self
                .discs
                .iter()
                .enumerate()
                .map(|(i, d)| {
                    let fatigue = self.fatigue_of(i);
                    let f = fatigue.copied().unwrap_or_default();
                    let (worst_tooth, worst_life, teeth) = f.worst_tooth.unwrap_or((0, None, 0));
                    proto::DiscSummary {
                        fatigue: fatigue.is_some(),
                        damage_rate_per_h: f.damage_rate_per_h,
                        life_h: f.life_h.unwrap_or(0.0),
                        eq_load_range_n: f.eq_load_range_n,
                        max_root_stress_pa: f.max_root_stress_pa,
                        teeth,
                        worst_tooth,
                        worst_tooth_life_h: worst_life.unwrap_or(0.0),
                        name: d.name.clone(),
                        index: i as u32,
                        max_positive_n: d.max_positive_n,
                        max_negative_n: d.max_negative_n,
                        p99_abs_n: d.p99_abs_n,
                        impacts: d.impacts as u64,
                        positive_impacts: d.positive_impacts as u64,
                        negative_impacts: d.negative_impacts as u64,
                        mean_top10_abs_n: d.mean_top10_abs_n,
                    }
                })
                .collect(),
        }
    }

    pub(crate) fn from_proto(p: proto::SummaryMessage) -> RecordedSummary {
        let life = |h: f64| (h > 0.0).then_some(h);
        let fatigue: Vec<Option<FatigueSummary>> = p
            .discs
            .iter()
            .map(|d| {
                d.fatigue.then(|| FatigueSummary {
                    damage_rate_per_h: d.damage_rate_per_h,
                    life_h: life(d.life_h),
                    eq_load_range_n: d.eq_load_range_n,
                    max_root_stress_pa: d.max_root_stress_pa,
                    worst_tooth: (d.teeth > 0)
                        .then(|| (d.worst_tooth, life(d.worst_tooth_life_h), d.teeth)),
                })
            })
            .collect();
        RecordedSummary {
            t_end_s: p.t_end_s,
            // a file without fatigue keeps the list empty, as the run that wrote it had it
            fatigue: if fatigue.iter().any(Option::is_some) {
                fatigue
            } else {
                Vec::new()
            },
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
        let s = RecordedSummary::from_impacts(
            &["a".into()],
            &[ev(2, 5.0), ev(usize::MAX / 2, 1.0)],
            1.0,
        );
        assert_eq!(s.discs.len(), 3, "an absurd index is not counted");
        assert_eq!(s.discs[0], DiscStats::from_peaks("a", &[]));
        assert_eq!(s.discs[0].p99_abs_n, 0.0);
        assert_eq!(s.discs[2].name, "disc 2");
        assert_eq!(s.discs[2].max_positive_n, 5.0);
        assert_eq!(RecordedSummary::from_proto(s.to_proto()), s);
        // fatigue figures round-trip; unlimited lives stay unlimited
        let mut f = s.clone();
        f.fatigue = vec![None; 3];
        f.fatigue[0] = Some(FatigueSummary {
            damage_rate_per_h: 0.0,
            life_h: None,
            eq_load_range_n: 0.0,
            max_root_stress_pa: 0.0,
            worst_tooth: None,
        });
        f.fatigue[2] = Some(FatigueSummary {
            damage_rate_per_h: 2e-3,
            life_h: Some(500.0),
            eq_load_range_n: 321.0,
            max_root_stress_pa: 4e8,
            worst_tooth: Some((17, Some(250.0), 154)),
        });
        assert_eq!(RecordedSummary::from_proto(f.to_proto()), f);
    }
}
