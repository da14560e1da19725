//! Damage and life of the spline teeth of a run (MODEL.md section 7).
//!
//! [`FatigueCollector`] turns what an engine emits (impact events, samples with per-tooth
//! loads when the engine resolves teeth) into the turning points of each coupling's
//! per-tooth load history and of each resolved tooth's history, without keeping the samples.
//! [`assess`] counts their cycles ([`crate::cycles::rainflow`]), converts load ranges to
//! root-stress amplitudes (`clutchpack_model::fatigue`), and sums Miner's damage per tooth and
//! per disc; [`ensemble_fatigue`] reduces the members of an ensemble to mean and spread.
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

use crate::cycles::{
    count_ranges, exceedance_spectrum, rainflow, range_histogram, range_mean_matrix, Cycle,
    RangeBin, RangeMeanMatrix, TurningPoints, SUSTAINED_CONTACT_SAMPLES,
};
use crate::sweep::Spread;
use crate::table::{col, csv_field, fmt_num, render, TableFormat};
use clutchpack_model::fatigue::{damage_equivalent, miner_damage, stress_per_newton};
use clutchpack_model::{
    ImpactEvent, Material, MinerRule, Observer, Sample, SplineGeometry, ToothForm,
};
use serde::{Deserialize, Serialize};

/// Seconds per hour.
const HOUR_S: f64 = 3600.0;

#[derive(Debug, Clone, Default)]
struct ToothTrack {
    points: TurningPoints,
    /// the open contact's signed peak
    open: Option<f64>,
    peaks: Vec<f64>,
}

impl ToothTrack {
    fn push(&mut self, x: f64) {
        self.points.push(x);
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
            self.peaks.extend(self.open.take());
            if x != 0.0 && x.is_finite() {
                self.open = Some(x);
            }
        }
    }
    fn finish(mut self) -> HistoryCycles {
        self.peaks.extend(self.open.take());
        HistoryCycles {
            cycles: rainflow(&self.points.points()),
            peaks: self.peaks,
        }
    }
}

#[derive(Debug, Clone, Default)]
struct DiscTrack {
    /// loaded samples (t s, load N) not yet claimed by a closed impact
    pending: Vec<(f64, f64)>,
    points: TurningPoints,
    peaks: Vec<f64>,
    teeth: Vec<ToothTrack>,
}

/// Collects the load histories of a run for its fatigue, as turning points (an observer of an
/// engine, or fed by hand with [`Self::sample`] and [`Self::impact`]). Impacts of one
/// coupling must arrive in time order (engines emit them as they close).
#[derive(Debug, Clone, Default)]
pub struct FatigueCollector {
    discs: Vec<DiscTrack>,
}

/// The counted cycles and contact peaks of one load history.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct HistoryCycles {
    /// Rainflow cycles of the signed per-tooth load, N ([`crate::cycles::rainflow`]).
    pub cycles: Vec<Cycle>,
    /// Signed peak of each contact (impact), N.
    pub peaks: Vec<f64>,
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
    /// An empty collector (couplings are added as they appear).
    pub fn new() -> FatigueCollector {
        FatigueCollector::default()
    }

    fn disc(&mut self, i: usize) -> &mut DiscTrack {
        if self.discs.len() <= i {
            self.discs.resize_with(i + 1, || DiscTrack {
                points: {
                    let mut p = TurningPoints::new();
                    p.push(0.0);
                    p
                },
                ..Default::default()
            });
        }
        &mut self.discs[i]
    }

    /// Takes a sample: loaded samples wait for their impact; resolved teeth feed their own
    /// histories.
    pub fn sample(&mut self, s: &Sample) {
        for (i, d) in s.discs.iter().enumerate() {
            let t = self.disc(i);
            if d.load_n != 0.0 && d.load_n.is_finite() {
                t.pending.push((s.t_s, d.load_n));
            }
            if !d.tooth_loads_n.is_empty() {
                if t.teeth.len() < d.tooth_loads_n.len() {
                    t.teeth.resize_with(d.tooth_loads_n.len(), || {
                        let mut k = ToothTrack::default();
                        k.points.push(0.0);
                        k
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
        let t = self.disc(e.disc);
        let inside: Vec<(f64, f64)> = t
            .pending
            .iter()
            .filter(|s| s.0 > e.t_on_s && s.0 < e.t_off_s)
            .copied()
            .collect();
        t.points.push(0.0);
        if inside.len() >= SUSTAINED_CONTACT_SAMPLES {
            let at = inside.partition_point(|s| s.0 <= e.t_peak_s);
            for s in &inside[..at] {
                t.points.push(s.1);
            }
            t.points.push(e.peak_n);
            for s in &inside[at..] {
                t.points.push(s.1);
            }
        } else {
            t.points.push(e.peak_n);
        }
        t.points.push(0.0);
        t.peaks.push(e.peak_n);
        t.pending.retain(|s| s.0 > e.t_off_s);
    }

    /// The counted histories of every coupling seen, in index order; `couplings` pads the
    /// list for couplings that never hit.
    pub fn finish(self, couplings: usize) -> Vec<DiscHistories> {
        let mut out: Vec<DiscHistories> = self
            .discs
            .into_iter()
            .map(|d| {
                let mut p = d.points;
                p.push(0.0);
                DiscHistories {
                    lumped: HistoryCycles {
                        cycles: rainflow(&p.points()),
                        peaks: d.peaks,
                    },
                    teeth: d.teeth.into_iter().map(ToothTrack::finish).collect(),
                }
            })
            .collect();
        out.resize_with(couplings.max(out.len()), DiscHistories::default);
        out
    }
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
    let ranges = count_ranges(cycles);
    // Miner (MODEL.md section 7): D = sum n_i / N(S_i), S the stress amplitude c dF / 2
    let damage = miner_damage(
        ranges.iter().map(|&(r, n)| (0.5 * stress_pa_per_n * r, n)),
        material,
    );
    let per_hour = if duration_s > 0.0 {
        HOUR_S / duration_s
    } else {
        0.0
    };
    let rate = damage * per_hour;
    let eq = damage_equivalent(
        ranges.iter().map(|&(r, n)| (r, n * per_hour)),
        material.slope,
        material.knee_cycles,
    );
    Assessment {
        damage,
        damage_rate_per_h: rate,
        life_h: (rate > 0.0).then(|| material.critical_damage / rate),
        eq_load_range_n: eq,
        eq_stress_amplitude_pa: 0.5 * stress_pa_per_n * eq,
        cycles: ranges.iter().map(|r| r.1).sum(),
    }
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
    let top = h.lumped.peaks.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    let top_teeth = h
        .teeth
        .iter()
        .flat_map(|t| &t.peaks)
        .fold(0.0f64, |m, p| m.max(p.abs()));
    let top = top.max(top_teeth);
    let teeth = (!h.teeth.is_empty()).then(|| {
        let each: Vec<Assessment> = h
            .teeth
            .iter()
            .map(|t| assess_cycles(&t.cycles, c, material, duration_s))
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
        impacts: h.lumped.peaks.len(),
        stress_pa_per_n: c,
        max_root_stress_pa: clutchpack_model::fatigue::root_stress_pa(top, spline, form),
        max_flank_pressure_pa: clutchpack_model::fatigue::flank_pressure_pa(top, spline, form),
        rule: material.rule,
        lumped: assess_cycles(&h.lumped.cycles, c, material, duration_s),
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

fn fmt_mpa(pa: f64) -> String {
    format!("{:.1}", pa * 1e-6)
}

fn fmt_opt(x: Option<f64>) -> String {
    x.map_or_else(String::new, |v| format!("{v:?}"))
}

/// The fatigue of one run, one row per disc.
///
/// Columns (text and markdown): `disc`, `impacts`, `cycles`, `max sigma_F [MPa]` (root
/// stress of the largest peak), `max p [MPa]` (flank pressure), `damage [1/h]`, `life [h]`
/// (at this duty; `unlimited` without damage), `S_eq [N]` (damage-equivalent load range for
/// one hour at `N_D`), `sigma_eq [MPa]` (its stress amplitude), and where the engine resolved
/// teeth `worst tooth` (index) and `worst life [h]`. CSV: the same with unit suffixes and
/// every digit (`life_h` empty when unlimited).
pub fn fatigue_table(discs: &[DiscFatigue], format: TableFormat) -> String {
    let teeth = discs.iter().any(|d| d.teeth.is_some());
    if format == TableFormat::Csv {
        let mut out = String::from(
            "disc,impacts,cycles,max_root_stress_pa,max_flank_pressure_pa,damage_rate_per_h,life_h,eq_load_range_n,eq_stress_amplitude_pa,worst_tooth,worst_tooth_life_h\n",
        );
        for d in discs {
            let a = &d.lumped;
            let (wt, wl) = d
                .teeth
                .as_ref()
                .map_or((String::new(), String::new()), |t| {
                    (t.worst_tooth.to_string(), fmt_opt(t.worst.life_h))
                });
            out.push_str(&format!(
                "{},{},{:?},{:?},{:?},{:?},{},{:?},{:?},{wt},{wl}\n",
                csv_field(&d.name),
                d.impacts,
                a.cycles,
                d.max_root_stress_pa,
                d.max_flank_pressure_pa,
                a.damage_rate_per_h,
                fmt_opt(a.life_h),
                a.eq_load_range_n,
                a.eq_stress_amplitude_pa
            ));
        }
        return out;
    }
    let mut cols = vec![
        col("disc", false),
        col("impacts", true),
        col("cycles", true),
        col("max sigma_F [MPa]", true),
        col("max p [MPa]", true),
        col("damage [1/h]", true),
        col("life [h]", true),
        col("S_eq [N]", true),
        col("sigma_eq [MPa]", true),
    ];
    if teeth {
        cols.push(col("worst tooth", true));
        cols.push(col("worst life [h]", true));
    }
    let rows: Vec<Vec<String>> = discs
        .iter()
        .map(|d| {
            let a = &d.lumped;
            let mut r = vec![
                d.name.clone(),
                d.impacts.to_string(),
                fmt_num(a.cycles),
                fmt_mpa(d.max_root_stress_pa),
                fmt_mpa(d.max_flank_pressure_pa),
                fmt_num(a.damage_rate_per_h),
                format_life_h(a.life_h),
                fmt_num(a.eq_load_range_n),
                fmt_mpa(a.eq_stress_amplitude_pa),
            ];
            if teeth {
                match &d.teeth {
                    Some(t) => {
                        r.push(t.worst_tooth.to_string());
                        r.push(format_life_h(t.worst.life_h));
                    }
                    None => r.extend(["-".to_string(), "-".to_string()]),
                }
            }
            r
        })
        .collect();
    render(format, &cols, &rows)
}

/// `mean ± std` (the mean alone for one member).
fn mean_std(s: &Spread) -> String {
    if s.n > 1 {
        format!("{} ± {}", fmt_num(s.mean), fmt_num(s.std))
    } else {
        fmt_num(s.mean)
    }
}

/// The fatigue of ensembles: one row per (parameter value, disc); `param` names the first
/// column (`None`: no parameter column, one ensemble).
///
/// Columns (text and markdown): `param` (when given), `disc`, `members`, `damage [1/h]` (mean ± std of
/// the members' damage rates), `damage range [1/h]` (min .. max), `life [h]` (at the mean
/// rate), `life range [h]` (at the largest .. the smallest rate), `S_eq [N]` (mean ± std).
/// CSV: `damage_rate_{mean,std,min,max}_per_h`, `life_at_mean_rate_h`, `life_min_h`,
/// `life_max_h`, `eq_load_range_{mean,std}_n` (lives empty when unlimited).
pub fn fatigue_spread_table(
    param: Option<&str>,
    rows: &[(f64, Vec<DiscFatigueSpread>)],
    format: TableFormat,
) -> String {
    if format == TableFormat::Csv {
        let mut out = String::new();
        if let Some(p) = param {
            out.push_str(&csv_field(p));
            out.push(',');
        }
        out.push_str("disc,members,damage_rate_mean_per_h,damage_rate_std_per_h,damage_rate_min_per_h,damage_rate_max_per_h,life_at_mean_rate_h,life_min_h,life_max_h,eq_load_range_mean_n,eq_load_range_std_n\n");
        for (v, discs) in rows {
            for d in discs {
                let r = &d.damage_rate_per_h;
                if param.is_some() {
                    out.push_str(&format!("{v:?},"));
                }
                out.push_str(&format!(
                    "{},{},{:?},{:?},{:?},{:?},{},{},{},{:?},{:?}\n",
                    csv_field(&d.name),
                    r.n,
                    r.mean,
                    r.std,
                    r.min,
                    r.max,
                    fmt_opt(d.life_at_mean_rate_h),
                    fmt_opt(d.life_min_h),
                    fmt_opt(d.life_max_h),
                    d.eq_load_range_n.mean,
                    d.eq_load_range_n.std
                ));
            }
        }
        return out;
    }
    let mut cols = Vec::new();
    if let Some(p) = param {
        cols.push(col(p, true));
    }
    cols.extend([
        col("disc", false),
        col("members", true),
        col("damage [1/h]", true),
        col("damage range [1/h]", true),
        col("life [h]", true),
        col("life range [h]", true),
        col("S_eq [N]", true),
    ]);
    let mut cells = Vec::new();
    for (v, discs) in rows {
        for d in discs {
            let r = &d.damage_rate_per_h;
            let mut row = Vec::new();
            if param.is_some() {
                row.push(fmt_num(*v));
            }
            row.extend([
                d.name.clone(),
                r.n.to_string(),
                mean_std(r),
                format!("{} .. {}", fmt_num(r.min), fmt_num(r.max)),
                format_life_h(d.life_at_mean_rate_h),
                format!(
                    "{} .. {}",
                    format_life_h(d.life_min_h),
                    format_life_h(d.life_max_h)
                ),
                mean_std(&d.eq_load_range_n),
            ]);
            cells.push(row);
        }
    }
    render(format, &cols, &cells)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cycles::{impact_history, turning_points};
    use approx::assert_relative_eq;
    use clutchpack_model::{DiscSample, Flank};

    fn paper() -> SplineGeometry {
        clutchpack_model::cases::paper_spline()
    }

    fn event(t_on: f64, t_peak: f64, t_off: f64, peak: f64) -> ImpactEvent {
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
