//! The main-effects figure: for each design factor, the mean peak of the hardest-hit disc at
//! each of the factor's levels (over every case at that level: the other factors and the
//! ensemble averaged out), with its 95 % confidence interval (Student's t).

use crate::merge::Merged;
use crate::stats::Summary;
use plotters::prelude::*;
use std::path::Path;

/// Why the figure could not be made.
#[derive(Debug, thiserror::Error)]
#[error("{}: plotting: {reason}", path.display())]
pub struct PlotError {
    /// The file.
    pub path: std::path::PathBuf,
    /// Why.
    pub reason: String,
}

/// One panel: a factor's levels with (mean, CI half-width, n) of the hardest disc's
/// `peak_abs_n` (N).
#[derive(Debug, Clone, PartialEq)]
pub struct Effect {
    /// The factor's key.
    pub factor: String,
    /// (level, summary) in level order.
    pub points: Vec<(f64, Summary)>,
}

/// The main effects of every design factor on `disc`'s `peak_abs_n`; without design factors,
/// one panel `all cases` at level 0.
pub fn main_effects(m: &Merged, disc: usize) -> Vec<Effect> {
    let nf = m.header.design_factors;
    if nf == 0 {
        return Summary::of(&m.values(disc, "peak_abs_n", |_| true))
            .map(|s| Effect {
                factor: "all cases".into(),
                points: vec![(0.0, s)],
            })
            .into_iter()
            .collect();
    }
    (0..nf)
        .map(|f| {
            let mut levels: Vec<f64> = m.records.iter().map(|r| r.values[f]).collect();
            levels.sort_by(f64::total_cmp);
            levels.dedup();
            Effect {
                factor: m.header.columns[f].clone(),
                points: levels
                    .into_iter()
                    .filter_map(|l| {
                        Summary::of(&m.values(disc, "peak_abs_n", |r| r.values[f] == l))
                            .map(|s| (l, s))
                    })
                    .collect(),
            }
        })
        .collect()
}

/// Draws the main effects of `m` on its hardest-hit disc to `path` (PNG or SVG by extension).
pub fn plot_main_effects(path: &Path, m: &Merged) -> Result<(), PlotError> {
    let err = |reason: String| PlotError {
        path: path.into(),
        reason,
    };
    clutchpack_analysis::register_fonts().map_err(|e| err(e.to_string()))?;
    let disc = m
        .hardest_disc()
        .ok_or_else(|| err("no successful case to plot".into()))?;
    let effects = main_effects(m, disc);
    let title = format!(
        "{}: peak of {} (hardest hit), mean and 95 % CI",
        m.header.name, m.discs[disc]
    );
    let n = effects.len().max(1);
    let size = ((420 * n).max(720) as u32, 460u32);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "png" => {
            let root = BitMapBackend::new(path, size).into_drawing_area();
            draw(&root, &title, &effects).map_err(err)?;
            root.present().map_err(|e| err(e.to_string()))
        }
        "svg" => {
            let root = SVGBackend::new(path, size).into_drawing_area();
            draw(&root, &title, &effects).map_err(err)?;
            root.present().map_err(|e| err(e.to_string()))
        }
        other => Err(err(format!(
            "cannot tell the figure format from the extension {other:?}: use .png or .svg"
        ))),
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    effects: &[Effect],
) -> Result<(), String> {
    let e = |x: &dyn std::fmt::Display| x.to_string();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let root = root.titled(title, ("sans-serif", 18)).map_err(|x| e(&x))?;
    let panels = root.split_evenly((1, effects.len().max(1)));
    // one shared y range, so that the panels compare
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for ef in effects {
        for (_, s) in &ef.points {
            let h = if s.ci95_half.is_finite() {
                s.ci95_half
            } else {
                0.0
            };
            lo = lo.min(s.mean - h).min(s.min);
            hi = hi.max(s.mean + h).max(s.max);
        }
    }
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(1e-9);
    let (lo, hi) = ((lo - pad).max(0.0), hi + pad);
    for (panel, ef) in panels.iter().zip(effects) {
        let xs: Vec<f64> = ef.points.iter().map(|p| p.0).collect();
        let (x0, x1) = (
            xs.iter().copied().fold(f64::INFINITY, f64::min),
            xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let xpad = if x1 > x0 { (x1 - x0) * 0.1 } else { 1.0 };
        let mut chart = ChartBuilder::on(panel)
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(70)
            .build_cartesian_2d((x0 - xpad)..(x1 + xpad), lo..hi)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc(ef.factor.as_str())
            .y_desc("peak |load| per tooth (N)")
            .x_labels(6)
            .y_labels(8)
            .draw()
            .map_err(|x| e(&x))?;
        // the ensemble's range (min..max), light
        chart
            .draw_series(ef.points.iter().map(|(x, s)| {
                ErrorBar::new_vertical(
                    *x,
                    s.min,
                    s.mean,
                    s.max,
                    RGBColor(180, 180, 200).stroke_width(1),
                    6,
                )
            }))
            .map_err(|x| e(&x))?;
        // the 95 % confidence interval of the mean, bold
        chart
            .draw_series(ef.points.iter().map(|(x, s)| {
                let h = if s.ci95_half.is_finite() {
                    s.ci95_half
                } else {
                    0.0
                };
                ErrorBar::new_vertical(*x, s.mean - h, s.mean, s.mean + h, BLUE.stroke_width(2), 12)
            }))
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(
                ef.points.iter().map(|(x, s)| (*x, s.mean)),
                BLUE,
            ))
            .map_err(|x| e(&x))?;
        chart
            .draw_series(
                ef.points
                    .iter()
                    .map(|(x, s)| Circle::new((*x, s.mean), 4, BLUE.filled())),
            )
            .map_err(|x| e(&x))?;
    }
    Ok(())
}
