//! # clutchpack_analysis
//!
//! Post-processing of clutchpack runs: what the per-tooth impact loads of a run, an ensemble
//! or a parameter sweep amount to, as numbers, tables and pictures.
//!
//! The rattle of a clutch pack is chaotic (MODEL.md section 6): two correct solvers agree
//! impact by impact for only ~0.1 s, so longer runs are compared *statistically* (largest
//! peaks, 99th percentile, mean of the top impacts), and a sweep reports the mean and spread
//! of an ensemble of runs rather than one chaotic sample.
//!
//! ## What this crate does
//! - [`stats`]: per-disc statistics of the impact peaks of one run ([`stats::disc_stats`]),
//!   and [`stats::percentile`] (numpy's default `linear` definition).
//! - [`sweep`]: ensemble spreads ([`sweep::Spread`]) and one row per (parameter value, disc)
//!   of a sweep ([`sweep::sweep_rows`]); [`sweep::sweep_fits`] fits the ensemble means.
//! - [`cycles`]: turning points and rainflow counting (ASTM E1049-85) of signed per-tooth
//!   load histories, range histograms, range-mean matrices and exceedance spectra.
//! - [`fatigue`]: damage, damage rate, life and damage-equivalent load per disc and per tooth
//!   of a run ([`fatigue::FatigueCollector`], [`fatigue::assess`]) and of an ensemble;
//!   [`fatigue_plot`] draws the exceedance spectra and the per-tooth damage around a disc.
//! - [`fit`]: least-squares polynomial fits with nalgebra ([`fit::polyfit`]), with `x`
//!   centred and scaled so that parameters such as a backlash of `0..100e-6` m fit well.
//! - [`table`]: aligned plain text, markdown and CSV tables, units in the headers.
//! - [`plot`]: PNG or SVG figures with plotters (load history, sweep with fits, comparison
//!   of runs), rendered with an embedded DejaVu Sans font so they work without system fonts.
//!
//! ## What it does not do
//! - Run engines or read scene files, or read and write recordings: it takes the
//!   [`ImpactEvent`](clutchpack_model::ImpactEvent)s and load histories the caller collected.
//! - Decide the ensemble: the caller chooses members (initial disc positions within the
//!   backlash, drive phases) and hands one statistics list per member to [`sweep`].
//!
//! # Conventions
//! - Loads are per tooth, in N, signed as in clutchpack_model (Hu et al. eq (6)):
//!   **negative when the shaft leads, positive when the disc leads**. "Max negative" is the
//!   most negative peak, a number `<= 0`.
//! - Times are in s in the data; the load-history plot shows ms.
//! - Empty input gives zeros (or an empty table, or a figure saying "no data"), never a panic.
//! - Errors: one `thiserror` enum per module that can fail ([`fit::FitError`],
//!   [`plot::PlotError`]); the other modules cannot fail.

#![warn(missing_docs)]

pub mod clutches;
pub mod cycles;
pub mod fatigue;
pub mod fatigue_plot;
pub mod fit;
pub mod interfaces;
pub mod plot;
pub mod stats;
pub mod sweep;
pub mod table;

/// A fixed pseudo-random generator (PCG-style LCG) for the property tests of this crate, so
/// that they are repeatable.
#[cfg(test)]
pub(crate) struct Lcg(pub(crate) u64);

#[cfg(test)]
impl Lcg {
    /// The next value, uniform in [0, 1).
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

pub use clutches::{
    clutch_compare_rows, clutch_compare_table, hardest_hit, hottest_clutch, largest_peak_change,
    pack_body_compare_rows, pack_body_compare_table, ClutchCompareRow, ClutchRun,
    PackBodyCompareRow, PackBodyRun,
};
pub use fatigue::{
    assess, disc_cycles, ensemble_fatigue, DiscCycles, DiscFatigue, DiscFatigueSpread,
    FatigueCollector,
};
pub use fit::{polyfit, FitError, PolyFit};
pub use interfaces::InterfaceStats;
pub use plot::{
    figure_format, plot_compare, plot_load_history, plot_panels, plot_sweep, register_fonts,
    FigureFormat, Panel, PlotError,
};
pub use stats::{disc_stats, percentile, DiscStats, PeakStats};
pub use sweep::{sweep_fits, sweep_rows, Spread, SweepCase, SweepRow};
pub use table::{
    csv_field, fatigue_spread_table, fatigue_table, interface_table, stats_table, sweep_table,
    TableFormat,
};
