//! Damage and life of the spline teeth of a run (MODEL.md section 7).
//!
//! [`FatigueCollector`] turns what an engine emits (impact events, samples with per-tooth
//! loads when the engine resolves teeth) into the turning points of each coupling's
//! per-tooth load history and of each resolved tooth's history, and counts their cycles as
//! they come ([`crate::cycles::Rainflow`]), without keeping the samples. Each cycle's load
//! range becomes a root-stress amplitude (`clutchpack_model::fatigue`) whose Miner damage is
//! summed per tooth and per disc ([`DamageSum`]; kept cycles only when asked);
//! [`assess`] gives the figures, and [`ensemble_fatigue`] reduces the members of an ensemble
//! to mean and spread.
//!
//! # Definitions (docs/DECISIONS.md, "Fatigue")
//! - A **lumped** coupling's teeth all see the coupling's per-tooth history (from its impact
//!   events, [`crate::cycles::impact_history`]): the disc's damage is that of any one tooth.
//! - Where the engine resolves teeth, each tooth's history is its sampled load (the samples'
//!   `tooth_loads_n`): [`TeethFatigue`] gives every tooth's damage and the worst tooth. Its
//!   peaks are only as good as the sample rate (an impact lasts ~70 us: sample at >= 100 kHz
//!   for per-tooth damage; at 10 kHz the sampled peaks fall well short of the located ones).
//! - **Damage rate** per hour of the simulated duty: `D 3600 / T` with `T` the simulated
//!   time; **life** in hours `D_crit / rate` (`None`: unlimited, no damage).
//! - **Damage-equivalent load** `S_eq`: the load range in N that, applied `N_eq = N_D` times
//!   (the knee of the S-N curve), does the damage of one hour of the duty on the curve's
//!   upper line: `S_eq = (sum n_i S_i^k / N_D)^(1/k)`, `n_i` counted per hour, `S_i` the load
//!   ranges. Its stress amplitude `c S_eq / 2` against `S_D` reads directly: under Miner
//!   elementary the life is `D_crit (S_D / sigma_eq)^k` hours.

mod collector;
mod pending;
pub use collector::{DamageSum, DiscHistories, FatigueCollector, HistoryCycles};
pub use pending::PENDING_IN_MEMORY;

use crate::cycles::{
    count_ranges, exceedance_spectrum, range_histogram, range_mean_matrix, Cycle, Rainflow,
    RangeBin, RangeMeanMatrix, TurningPoints, SUSTAINED_CONTACT_SAMPLES,
};
use crate::sweep::Spread;
use clutchpack_model::fatigue::{damage_equivalent, stress_per_newton};
use clutchpack_model::{
    ImpactEvent, Material, MinerRule, Observer, Sample, SplineGeometry, ToothForm,
};
use serde::{Deserialize, Serialize};

/// Seconds per hour.
const HOUR_S: f64 = 3600.0;

/// The fatigue of one load history (one tooth) over a duty of `duration_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Assessment {
    /// Miner damage sum over the simulated time (dimensionless, >= 0).
    pub damage: f64,
    /// Damage per hour of the simulated duty, 1/h (>= 0).
    pub damage_rate_per_h: f64,
    /// Life in hours at this duty, `D_crit / rate`; `None` when the rate is 0 (unlimited).
    pub life_h: Option<f64>,
    /// Damage-equivalent load range `S_eq` in N for one hour of duty at `N_eq = N_D`
    /// (module doc).
    pub eq_load_range_n: f64,
    /// Root-stress amplitude of [`Self::eq_load_range_n`], Pa (>= 0).
    pub eq_stress_amplitude_pa: f64,
    /// Counted cycles (half cycles count 0.5).
    pub cycles: f64,
}

/// Fatigue of a history's cycles with `stress_pa_per_n` (Pa/N, from
/// `clutchpack_model::fatigue::stress_per_newton`), over `duration_s` of simulated duty.
pub fn assess_cycles(
    cycles: &[Cycle],
    stress_pa_per_n: f64,
    material: &Material,
    duration_s: f64,
) -> Assessment {
    // the running sums in counting order: the same arithmetic as a live collector's
    let mut sums = DamageSum::new(stress_pa_per_n, *material);
    for c in cycles {
        sums.add(c.range(), c.count);
    }
    sums.assessment(duration_s)
}

/// Damage of every resolved tooth of a disc, and its worst tooth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TeethFatigue {
    /// Damage sum of tooth `k` over the simulated time (index = tooth, at `2 pi k / n` from
    /// the shaft's `+x`).
    pub damage: Vec<f64>,
    /// Index of the most damaged tooth (the lowest index among equals).
    pub worst_tooth: usize,
    /// The worst tooth's figures.
    pub worst: Assessment,
    /// Mean damage over the teeth.
    pub mean_damage: f64,
}

/// Fatigue of one disc's spline teeth over a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscFatigue {
    /// Disc (coupling) name.
    pub name: String,
    /// Simulated duty in s.
    pub duration_s: f64,
    /// Impacts (contacts) of the coupling.
    pub impacts: usize,
    /// Root stress per newton of per-tooth load, Pa/N.
    pub stress_pa_per_n: f64,
    /// Largest tooth-root bending stress of the run, Pa (from the largest |peak|).
    pub max_root_stress_pa: f64,
    /// Largest flank pressure of the run, Pa.
    pub max_flank_pressure_pa: f64,
    /// The rule below the knee used.
    pub rule: MinerRule,
    /// The figures of the coupling's per-tooth history (every tooth when lumped).
    #[serde(flatten)]
    pub lumped: Assessment,
    /// Per-tooth figures where the engine resolved teeth.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub teeth: Option<TeethFatigue>,
}

impl Assessment {
    /// The first of its figures that is not finite (`inf` or `NaN`), by name.
    pub fn non_finite(&self) -> Option<&'static str> {
        [
            ("damage", self.damage),
            ("damage rate", self.damage_rate_per_h),
            ("life", self.life_h.unwrap_or(0.0)),
            ("S_eq", self.eq_load_range_n),
            ("sigma_eq", self.eq_stress_amplitude_pa),
            ("cycles", self.cycles),
        ]
        .into_iter()
        .find(|(_, v)| !v.is_finite())
        .map(|(n, _)| n)
    }
}

impl DiscFatigue {
    /// The first of its figures that is not finite, by name: a load or an S-N curve outside
    /// what f64 holds (a result is finite or refused, never printed as `inf` with exit 0).
    pub fn non_finite(&self) -> Option<&'static str> {
        if !self.max_root_stress_pa.is_finite() {
            return Some("max sigma_F");
        }
        if !self.max_flank_pressure_pa.is_finite() {
            return Some("max p");
        }
        self.lumped.non_finite().or_else(|| {
            self.teeth.as_ref().and_then(|t| {
                t.worst
                    .non_finite()
                    .or((!t.mean_damage.is_finite()).then_some("tooth damage"))
            })
        })
    }
}

/// Fatigue of a disc from its histories, spline, tooth form and material, over `duration_s`.
pub fn assess(
    name: &str,
    h: &DiscHistories,
    spline: &SplineGeometry,
    form: &ToothForm,
    material: &Material,
    duration_s: f64,
) -> DiscFatigue {
    let c = stress_per_newton(spline, form);
    let top = h.lumped.max_abs_peak_n;
    let top_teeth = h.teeth.iter().fold(0.0f64, |m, t| m.max(t.max_abs_peak_n));
    let top = top.max(top_teeth);
    let teeth = (!h.teeth.is_empty()).then(|| {
        let each: Vec<Assessment> = h
            .teeth
            .iter()
            .map(|t| t.assessment(c, material, duration_s))
            .collect();
        let mut worst = 0;
        for (k, a) in each.iter().enumerate() {
            if a.damage > each[worst].damage {
                worst = k;
            }
        }
        TeethFatigue {
            damage: each.iter().map(|a| a.damage).collect(),
            worst_tooth: worst,
            worst: each[worst],
            mean_damage: each.iter().map(|a| a.damage).sum::<f64>() / each.len() as f64,
        }
    });
    DiscFatigue {
        name: name.to_string(),
        duration_s,
        impacts: h.lumped.contacts,
        stress_pa_per_n: c,
        max_root_stress_pa: clutchpack_model::fatigue::root_stress_pa(top, spline, form),
        max_flank_pressure_pa: clutchpack_model::fatigue::flank_pressure_pa(top, spline, form),
        rule: material.rule,
        lumped: h.lumped.assessment(c, material, duration_s),
        teeth,
    }
}

/// Ensemble figures of one disc: the spread of the members' damage rates, and the life at
/// their mean rate (a mean of lives would be dominated by the luckiest member, and is
/// infinite as soon as one member does no damage).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscFatigueSpread {
    /// Disc name.
    pub name: String,
    /// Spread of the damage rate over the members, 1/h.
    pub damage_rate_per_h: Spread,
    /// `D_crit / mean rate` in hours; `None` when no member did damage.
    pub life_at_mean_rate_h: Option<f64>,
    /// Shortest member life (at the largest rate), h; `None` when no member did damage.
    pub life_min_h: Option<f64>,
    /// Longest member life (at the smallest rate), h; `None`: unlimited for some member.
    pub life_max_h: Option<f64>,
    /// Spread of the damage-equivalent load range, N.
    pub eq_load_range_n: Spread,
}

/// Mean and spread per disc of an ensemble's members (each one `Vec<DiscFatigue>` in the same
/// disc order), with the discs' critical damage `critical_damage` (one per disc, or one for
/// all when shorter).
pub fn ensemble_fatigue(
    members: &[Vec<DiscFatigue>],
    critical_damage: &[f64],
) -> Vec<DiscFatigueSpread> {
    let Some(first) = members.first() else {
        return Vec::new();
    };
    first
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let rates: Vec<f64> = members
                .iter()
                .filter_map(|m| m.get(i))
                .map(|x| x.lumped.damage_rate_per_h)
                .collect();
            let eq: Vec<f64> = members
                .iter()
                .filter_map(|m| m.get(i))
                .map(|x| x.lumped.eq_load_range_n)
                .collect();
            let dc = critical_damage
                .get(i)
                .or(critical_damage.last())
                .copied()
                .unwrap_or(1.0);
            let s = Spread::of(&rates);
            let life = |r: f64| (r > 0.0).then(|| dc / r);
            DiscFatigueSpread {
                name: d.name.clone(),
                damage_rate_per_h: s,
                life_at_mean_rate_h: life(s.mean),
                life_min_h: life(s.max),
                life_max_h: life(s.min),
                eq_load_range_n: Spread::of(&eq),
            }
        })
        .collect()
}

/// A life in hours for tables: `unlimited` for `None`, else 3 significant digits.
pub fn format_life_h(life_h: Option<f64>) -> String {
    match life_h {
        None => "unlimited".to_string(),
        Some(h) if !(1e-2..1e5).contains(&h) => format!("{h:.2e}"),
        Some(h) => sig3(h),
    }
}

fn sig3(x: f64) -> String {
    let digits = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.digits$}")
}

/// Bins of the range histogram and of each axis of the range-mean matrix in [`DiscCycles`].
pub const SPECTRUM_BINS: usize = 20;

/// The counted cycles of one coupling in detail: what `clutchpack run --fatigue-json` writes
/// per disc (MODEL.md section 7's range-mean matrix, range histogram and exceedance
/// spectrum), and the exact ranges an independent counter is checked against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiscCycles {
    /// Disc name.
    pub name: String,
    /// The coupling's per-tooth history counted: (load range N, count) per distinct range,
    /// sorted by range ([`crate::cycles::count_ranges`]; half cycles count 0.5).
    pub ranges: Vec<(f64, f64)>,
    /// Histogram of the ranges, [`SPECTRUM_BINS`] bins from 0 to the largest, N.
    pub range_histogram: Vec<RangeBin>,
    /// Range-mean matrix, [`SPECTRUM_BINS`] x [`SPECTRUM_BINS`] bins, N.
    pub range_mean: RangeMeanMatrix,
    /// Exceedance spectrum of the contact peaks: (|peak| level N, peaks at or above it per
    /// hour of the duty), from the largest level down.
    pub exceedance_per_h: Vec<(f64, f64)>,
    /// Each resolved tooth's counted history as (range N, count) (empty when the engine did
    /// not resolve teeth).
    pub teeth_ranges: Vec<Vec<(f64, f64)>>,
}

/// The counted cycles of one coupling's histories over `duration_s` in detail.
pub fn disc_cycles(name: &str, h: &DiscHistories, duration_s: f64) -> DiscCycles {
    let c = &h.lumped.cycles;
    DiscCycles {
        name: name.to_string(),
        ranges: count_ranges(c),
        range_histogram: range_histogram(c, SPECTRUM_BINS),
        range_mean: range_mean_matrix(c, SPECTRUM_BINS, SPECTRUM_BINS),
        exceedance_per_h: exceedance_spectrum(&h.lumped.peaks, duration_s),
        teeth_ranges: h.teeth.iter().map(|t| count_ranges(&t.cycles)).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycles::tests::event;
    use crate::cycles::{impact_history, rainflow, turning_points};
    use approx::assert_relative_eq;
    use clutchpack_model::DiscSample;

    fn paper() -> SplineGeometry {
        clutchpack_model::cases::paper_spline()
    }

    fn sample(t: f64, load: f64, teeth: Vec<f64>) -> Sample {
        Sample {
            t_s: t,
            discs: vec![DiscSample {
                load_n: load,
                tooth_loads_n: teeth,
                ..Default::default()
            }],
            ..Default::default()
        }
    }

    /// The streaming collector counts the same cycles as the batch history of
    /// crate::cycles::impact_history on the same events and samples (pulses and a sustained
    /// contact), and counts resolved teeth from their samples.
    #[test]
    fn collector_equals_batch_history() {
        let mut events = Vec::new();
        let mut samples = Vec::new();
        let mut c = FatigueCollector::new();
        let mut t = 0.0;
        for k in 0..40 {
            let peak = if k % 3 == 0 {
                500.0 + k as f64
            } else {
                -(300.0 + 7.0 * k as f64)
            };
            let long = k % 7 == 0;
            let e = event(
                t + 0.01,
                t + 0.015,
                t + if long { 0.05 } else { 0.0101 },
                peak,
            );
            // samples every 5 ms, loaded inside contacts; the impact closes after the first
            // sample past its separation, as engines emit it
            let mut emitted = false;
            for j in 0..20 {
                let ts = t + j as f64 * 0.005 + 0.0001;
                let inside = ts > e.t_on_s && ts < e.t_off_s;
                let load = if inside {
                    peak * (0.3 + 0.03 * j as f64)
                } else {
                    0.0
                };
                samples.push((ts, load));
                c.sample(&sample(ts, load, vec![load, 0.5 * load]));
                if ts > e.t_off_s && !emitted {
                    emitted = true;
                    events.push(e);
                    c.impact(&e);
                }
            }
            t += 0.1;
        }
        let h = c.finish(1);
        let batch = rainflow(&turning_points(&impact_history(&events, &samples)));
        assert_eq!(count_ranges(&h[0].lumped.cycles), count_ranges(&batch));
        assert_eq!(h[0].lumped.peaks.len(), 40);
        let tooth0: Vec<f64> = std::iter::once(0.0)
            .chain(samples.iter().map(|s| s.1))
            .collect();
        assert_eq!(
            count_ranges(&h[0].teeth[0].cycles),
            count_ranges(&rainflow(&turning_points(&tooth0)))
        );
        assert_eq!(h[0].teeth[0].peaks, crate::cycles::contact_peaks(&tooth0));
    }

    /// Issue 36, item 4 ("A flat footprint"): a contact that stays closed for long (a plate
    /// resting on its flank, as pack-8-brake's do from 0.16 s to the end) keeps its loaded
    /// samples until it separates, since its located peak goes in among them at its time. Past
    /// [`PENDING_IN_MEMORY`] per coupling they wait in the temporary file: the memory held
    /// stays bounded, and the contact's cycles are the batch history's
    /// ([`impact_history`]) bit for bit wherever the peak falls (before the first sample, among
    /// those on disk, among those in memory, after the last), with samples of the next contact
    /// already waiting when one closes.
    #[test]
    fn long_contacts_count_from_disk_as_from_memory() {
        let n = 3 * PENDING_IN_MEMORY + 123;
        let dt = 1e-4;
        for peak_at in [
            -0.5,
            10.0,
            5_000.0,
            12_000.5,
            n as f64 - 1.0,
            n as f64 - 0.2,
        ] {
            let mut c = FatigueCollector::new();
            let (mut events, mut samples) = (Vec::new(), Vec::new());
            let mut most_held = 0;
            let mut t0 = 0.0;
            let mut open: Option<ImpactEvent> = None;
            for (k, sign) in [(0, 1.0), (1, -1.0), (2, 1.0)] {
                // a contact from t0 with n samples inside, the peak at sample index peak_at
                let e = event(
                    t0,
                    t0 + (peak_at + 0.5) * dt,
                    t0 + (n as f64 + 0.25) * dt,
                    sign * (900.0 + k as f64),
                );
                for j in 0..n {
                    let ts = t0 + (j as f64 + 0.5) * dt;
                    let x = j as f64;
                    let load = sign * (400.0 + 150.0 * (0.37 * x).sin() + 80.0 * (0.011 * x).sin());
                    samples.push((ts, load));
                    c.sample(&sample(ts, load, Vec::new()));
                    most_held = most_held.max(c.held_samples());
                    // the contact before closes after this one's first samples
                    if j == 5 {
                        if let Some(before) = open.take() {
                            c.impact(&before);
                        }
                    }
                }
                t0 = e.t_off_s + 0.1 * dt;
                events.push(e);
                open = Some(e);
            }
            if let Some(last) = open.take() {
                c.impact(&last);
            }
            assert!(
                most_held <= PENDING_IN_MEMORY,
                "samples held in memory: {most_held}"
            );
            assert!(c.spill_error().is_none());
            let h = c.finish(1);
            let batch = rainflow(&turning_points(&impact_history(&events, &samples)));
            assert_eq!(h[0].lumped.cycles, batch, "peak at sample {peak_at}");
            assert!(h[0].lumped.cycles.len() > n / 10);
        }
    }

    /// A collector that only sums (bounded memory) gives bit for bit the figures of one that
    /// keeps every cycle, for the lumped history and each resolved tooth, over 20 000 random
    /// impacts on both flanks (pulses and sustained contacts), and it keeps no cycle, no peak
    /// and only a few uncounted points: its memory does not grow with the run.
    #[test]
    fn summing_collector_equals_keeping_one_and_keeps_nothing() {
        let g = paper();
        let form = ToothForm::default();
        let c = stress_per_newton(&g, &form);
        let mat = Material::default();
        const IMPACTS: usize = 20_000;
        let mut keeping = FatigueCollector::new();
        let mut summing = FatigueCollector::summing(vec![(c, mat)], false);
        let mut rng = crate::Lcg(0x9e3779b97f4a7c15);
        let mut uniform = move || rng.next();
        let mut t = 0.0;
        let mut most_held = 0;
        for _ in 0..IMPACTS {
            let peak = (uniform() - 0.5) * 2000.0;
            let long = uniform() < 0.1;
            let e = event(
                t + 1e-4,
                t + 2e-4,
                t + if long { 6e-4 } else { 1.5e-4 },
                peak,
            );
            for j in 0..8 {
                let ts = t + j as f64 * 1e-4 + 5e-5;
                let load = if ts > e.t_on_s && ts < e.t_off_s {
                    peak * (0.2 + 0.1 * j as f64)
                } else {
                    0.0
                };
                let s = sample(ts, load, vec![load, -0.5 * load]);
                keeping.sample(&s);
                summing.sample(&s);
            }
            keeping.impact(&e);
            summing.impact(&e);
            let held = summing.held_points(0);
            most_held = most_held.max(held);
            t += 1e-3;
        }
        // the residue holds the records of a random history: it grows like log n (measured
        // 36 points over the 3 histories after 2 000 impacts, 53 after 20 000, 61 after
        // 200 000), not like n
        let bound = 3 * 4 * (IMPACTS as f64).log2() as usize;
        assert!(
            most_held <= bound,
            "uncounted points held: {most_held} > {bound}"
        );
        let (hk, hs) = (keeping.finish(1), summing.finish(1));
        assert!(hs[0].lumped.cycles.is_empty() && hs[0].lumped.peaks.is_empty());
        assert!(hs[0]
            .teeth
            .iter()
            .all(|t| t.cycles.is_empty() && t.peaks.is_empty()));
        assert!(hk[0].lumped.cycles.len() > IMPACTS / 2);
        let (fk, fs) = (
            assess("d", &hk[0], &g, &form, &mat, 20.0),
            assess("d", &hs[0], &g, &form, &mat, 20.0),
        );
        assert_eq!(fk, fs);
        assert!(fs.lumped.damage > 0.0 && fs.impacts == IMPACTS);
        assert!(fs.teeth.as_ref().is_some_and(|t| t.damage.len() == 2));
        // a summing collector assessed on another curve falls back to its (absent) cycles:
        // the sums are only used for the curve they were taken on
        assert!(!hs[0].lumped.sums.unwrap().is_for(2.0 * c, &mat));
    }

    /// n pulses of peak P on one flank in T seconds: n cycles of range P, damage
    /// n / N(c P / 2), rate D 3600 / T, life D_crit / rate, and S_eq = P (n 3600 / T / N_D)^(1/k)
    /// (MODEL.md section 7's check, per hour). Under Miner elementary the life is
    /// D_crit (S_D / sigma_eq)^k hours. Tolerances: a few roundings of powf.
    #[test]
    fn pulses_closed_form() {
        let g = paper();
        let f = ToothForm::default();
        let m = Material::default();
        let (n, p, t) = (50usize, -950.0, 0.3);
        let mut col = FatigueCollector::new();
        for k in 0..n {
            let t0 = k as f64 * 0.005;
            col.impact(&event(t0, t0 + 3e-5, t0 + 7e-5, p));
        }
        let h = col.finish(1);
        let d = assess("disc", &h[0], &g, &f, &m, t);
        let c = stress_per_newton(&g, &f);
        let amp = c * 950.0 / 2.0;
        assert_relative_eq!(d.lumped.cycles, n as f64);
        assert_relative_eq!(
            d.lumped.damage,
            n as f64 / m.cycles_to_failure(amp),
            max_relative = 1e-12
        );
        assert_relative_eq!(
            d.lumped.damage_rate_per_h,
            d.lumped.damage * 3600.0 / t,
            max_relative = 1e-12
        );
        assert_relative_eq!(
            d.lumped.life_h.unwrap(),
            1.0 / d.lumped.damage_rate_per_h,
            max_relative = 1e-12
        );
        let per_h = n as f64 * 3600.0 / t;
        assert_relative_eq!(
            d.lumped.eq_load_range_n,
            950.0 * (per_h / 3e6).powf(1.0 / 6.2),
            max_relative = 1e-12
        );
        let el = m.with_rule(MinerRule::Elementary);
        let de = assess("disc", &h[0], &g, &f, &el, t);
        assert_relative_eq!(
            de.lumped.life_h.unwrap(),
            (m.endurance_amplitude_pa / de.lumped.eq_stress_amplitude_pa).powf(6.2),
            max_relative = 1e-10
        );
        assert_relative_eq!(d.max_root_stress_pa, c * 950.0, max_relative = 1e-14);
        assert_eq!(d.impacts, n);
    }

    /// No impacts: no damage, unlimited life; a quiet ensemble has no life either.
    #[test]
    fn no_impacts_unlimited_life() {
        let h = FatigueCollector::new().finish(2);
        assert_eq!(h.len(), 2);
        let d = assess(
            "d",
            &h[1],
            &paper(),
            &ToothForm::default(),
            &Material::default(),
            0.3,
        );
        assert_eq!(d.lumped.damage, 0.0);
        assert_eq!(d.lumped.life_h, None);
        assert!(d.teeth.is_none());
        let e = ensemble_fatigue(&[vec![d.clone()], vec![d]], &[1.0]);
        assert_eq!(e[0].life_at_mean_rate_h, None);
        assert_eq!(format_life_h(None), "unlimited");
        assert_eq!(format_life_h(Some(12.345)), "12.3");
        assert_eq!(format_life_h(Some(2.5e7)), "2.50e7");
    }

    /// Per-tooth: the worst tooth is the one with the largest damage, and its index is kept.
    #[test]
    fn worst_tooth_and_its_index() {
        let mut col = FatigueCollector::new();
        for k in 0..400 {
            let on = k % 4 == 1;
            let base = if on { -900.0 } else { 0.0 };
            col.sample(&sample(
                k as f64 * 1e-4,
                base,
                vec![base, 1.5 * base, 0.5 * base],
            ));
        }
        let h = col.finish(1);
        let d = assess(
            "d",
            &h[0],
            &paper(),
            &ToothForm::default(),
            &Material::default(),
            0.04,
        );
        let t = d.teeth.unwrap();
        assert_eq!(t.worst_tooth, 1);
        assert!(t.damage[1] > t.damage[0] && t.damage[0] > t.damage[2]);
        assert_relative_eq!(
            t.mean_damage,
            t.damage.iter().sum::<f64>() / 3.0,
            max_relative = 1e-14
        );
    }

    /// Ensemble: mean and spread of the rates; life at the mean rate, extreme lives at the
    /// extreme rates.
    #[test]
    fn ensemble_mean_and_spread() {
        let mk = |rate: f64| DiscFatigue {
            name: "d".into(),
            duration_s: 1.0,
            impacts: 1,
            stress_pa_per_n: 1.0,
            max_root_stress_pa: 0.0,
            max_flank_pressure_pa: 0.0,
            rule: MinerRule::Haibach,
            lumped: Assessment {
                damage: rate / 3600.0,
                damage_rate_per_h: rate,
                life_h: Some(1.0 / rate),
                eq_load_range_n: 1.0,
                eq_stress_amplitude_pa: 1.0,
                cycles: 1.0,
            },
            teeth: None,
        };
        let e = ensemble_fatigue(&[vec![mk(1e-3)], vec![mk(3e-3)]], &[1.0]);
        assert_relative_eq!(e[0].damage_rate_per_h.mean, 2e-3);
        assert_relative_eq!(e[0].life_at_mean_rate_h.unwrap(), 500.0);
        assert_relative_eq!(e[0].life_min_h.unwrap(), 1000.0 / 3.0);
        assert_relative_eq!(e[0].life_max_h.unwrap(), 1000.0);
    }
}
