//! Fatigue figures: the exceedance spectra of all discs in one log-log chart, and the damage
//! of each resolved tooth around its disc as a polar plot (MODEL.md section 7).

use crate::plot::{color, msg, no_data, render, Figure, PlotError, FONT};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The exceedance spectra `(disc name, [(load level N, exceedances per hour)])` (from
/// [`crate::cycles::exceedance_spectrum`]) as steps in one log-log chart, and beside it one
/// polar panel per `(disc name, damage per tooth)` in `teeth` (tooth `k` at `2 pi k / n` from
/// the shaft's `+x`, counter-clockwise; radius = damage over the disc's largest tooth
/// damage, the worst tooth marked). Levels or rates that are not positive are left out
/// (a log axis has no zero). The format follows `path`'s extension (`.png` or `.svg`).
pub fn plot_spectrum(
    path: &Path,
    title: &str,
    spectra: &[(String, Vec<(f64, f64)>)],
    teeth: &[(String, Vec<f64>)],
) -> Result<(), PlotError> {
    let polar = teeth.len().min(4) as u32;
    render(
        path,
        (1000 + 520 * polar, 700),
        &Spectrum {
            title,
            spectra,
            teeth: &teeth[..polar as usize],
        },
    )
}

struct Spectrum<'a> {
    title: &'a str,
    spectra: &'a [(String, Vec<(f64, f64)>)],
    teeth: &'a [(String, Vec<f64>)],
}

fn decade_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo > hi {
        return (1.0, 10.0);
    }
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil());
    (lo, if hi > lo { hi } else { lo * 10.0 })
}

impl Figure for Spectrum<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(msg)?;
        let area = root.titled(self.title, (FONT, 24)).map_err(msg)?;
        let (w, _) = area.dim_in_pixel();
        let (left, right) = area.split_horizontally(w - 520 * self.teeth.len() as u32);
        let pts: Vec<Vec<(f64, f64)>> = self
            .spectra
            .iter()
            .map(|(_, s)| {
                s.iter()
                    .copied()
                    .filter(|p| p.0 > 0.0 && p.1 > 0.0)
                    .collect()
            })
            .collect();
        if pts.iter().all(|p| p.is_empty()) {
            no_data(&left)?;
        } else {
            let (x0, x1) = decade_range(pts.iter().flatten().map(|p| p.0));
            let (y0, y1) = decade_range(pts.iter().flatten().map(|p| p.1));
            let mut chart = ChartBuilder::on(&left)
                .caption("exceedance spectra of the contact peaks", (FONT, 18))
                .margin(12)
                .margin_right(24)
                .x_label_area_size(48)
                .y_label_area_size(84)
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(msg)?;
            chart
                .configure_mesh()
                .x_desc("per-tooth peak load |F| [N]")
                .y_desc("impacts per hour with |F| >= load")
                .label_style((FONT, 14))
                .axis_desc_style((FONT, 16))
                .light_line_style(WHITE.mix(0.0))
                .x_label_formatter(&|v| crate::table::fmt_short(*v))
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()
                .map_err(msg)?;
            for (i, ((name, _), p)) in self.spectra.iter().zip(&pts).enumerate() {
                // a cumulative count is a staircase: hold each rate down to the next level
                let mut steps = Vec::with_capacity(2 * p.len());
                for (k, &(l, n)) in p.iter().enumerate() {
                    if k > 0 {
                        steps.push((l, p[k - 1].1));
                    }
                    steps.push((l, n));
                }
                let c = color(i);
                chart
                    .draw_series(LineSeries::new(steps, c.stroke_width(2)))
                    .map_err(msg)?
                    .label(name.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 18, y)], c.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .label_font((FONT, 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.4))
                .draw()
                .map_err(msg)?;
        }
        let panels = right.split_evenly((1, self.teeth.len().max(1)));
        for ((name, damage), panel) in self.teeth.iter().zip(&panels) {
            draw_polar(panel, name, damage)?;
        }
        Ok(())
    }
}

/// One disc's per-tooth damage as a closed polar curve, normalised by its largest value.
fn draw_polar<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    name: &str,
    damage: &[f64],
) -> Result<(), String> {
    let top = damage
        .iter()
        .copied()
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max);
    let worst = damage.iter().position(|&d| d == top);
    let caption = match worst {
        Some(k) if top > 0.0 => format!("{name}: tooth damage / {top:.3e} (worst: tooth {k})"),
        _ => format!("{name}: no tooth damage"),
    };
    let mut chart = ChartBuilder::on(panel)
        .caption(caption, (FONT, 15))
        .margin(16)
        .build_cartesian_2d(-1.15f64..1.15, -1.15f64..1.15)
        .map_err(msg)?;
    let circle = |r: f64| -> Vec<(f64, f64)> {
        (0..=180)
            .map(|i| {
                let a = i as f64 / 180.0 * std::f64::consts::TAU;
                (r * a.cos(), r * a.sin())
            })
            .collect()
    };
    for r in [0.25, 0.5, 0.75, 1.0] {
        chart
            .draw_series(LineSeries::new(
                circle(r),
                BLACK.mix(if r == 1.0 { 0.5 } else { 0.15 }),
            ))
            .map_err(msg)?;
    }
    chart
        .draw_series(LineSeries::new([(-1.1, 0.0), (1.1, 0.0)], BLACK.mix(0.15)))
        .map_err(msg)?;
    chart
        .draw_series(LineSeries::new([(0.0, -1.1), (0.0, 1.1)], BLACK.mix(0.15)))
        .map_err(msg)?;
    if damage.is_empty() || top <= 0.0 {
        return Ok(());
    }
    let n = damage.len() as f64;
    let at = |k: usize, r: f64| {
        let a = std::f64::consts::TAU * k as f64 / n;
        (r * a.cos(), r * a.sin())
    };
    let mut curve: Vec<(f64, f64)> = damage
        .iter()
        .enumerate()
        .map(|(k, &d)| at(k, d / top))
        .collect();
    curve.push(curve[0]);
    chart
        .draw_series(LineSeries::new(curve, color(3).stroke_width(2)))
        .map_err(msg)?;
    if let Some(k) = worst {
        chart
            .draw_series([Circle::new(at(k, 1.0), 6, color(3).filled())])
            .map_err(msg)?;
    }
    chart
        .draw_series([Text::new(
            "+x, tooth 0",
            (1.0, -0.08),
            (FONT, 13).into_font(),
        )])
        .map_err(msg)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both formats are written, with and without per-tooth panels, and with no data.
    #[test]
    fn writes_png_and_svg() {
        let dir =
            std::env::temp_dir().join(format!("clutchpack-fatigue-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let spectra = vec![
            (
                "disc 1".to_string(),
                vec![(950.0, 12000.0), (600.0, 60000.0), (200.0, 2.4e5)],
            ),
            ("disc 2".to_string(), vec![(500.0, 1e4)]),
        ];
        let teeth = [(
            "disc 1".to_string(),
            (0..154)
                .map(|k| 1e-6 * (1.0 + (k as f64 * 0.1).sin().abs()))
                .collect(),
        )];
        for (f, t) in [("a.png", &teeth[..]), ("b.svg", &[][..])] {
            let p = dir.join(f);
            plot_spectrum(&p, "test", &spectra, t).unwrap();
            assert!(std::fs::metadata(&p).unwrap().len() > 1000);
        }
        plot_spectrum(&dir.join("c.png"), "empty", &[], &[]).unwrap();
        assert!(matches!(
            plot_spectrum(&dir.join("d.pdf"), "x", &spectra, &[]),
            Err(PlotError::UnsupportedFormat { .. })
        ));
        std::fs::remove_dir_all(&dir).ok();
    }
}
