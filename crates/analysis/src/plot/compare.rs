//! The comparison figure: per-disc impact loads of several recordings side by side, the
//! change against the first.

use super::*;

/// Grouped bars: runs side by side per disc.
pub(super) struct Compare<'a> {
    pub(super) runs: &'a [String],
    pub(super) discs: &'a [String],
    pub(super) values: &'a [Vec<(f64, f64)>],
}

impl Figure for Compare<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(msg)?;
        let area = root
            .titled("Largest per-tooth impact loads by disc", (FONT, 26))
            .map_err(msg)?;
        if self.runs.is_empty() || self.discs.is_empty() {
            return no_data(&area);
        }
        let (w, _) = area.dim_in_pixel();
        let (chart_area, legend_area) = area.split_horizontally(w.saturating_sub(LEGEND_W));
        let (nr, nd) = (self.runs.len(), self.discs.len());
        let (y0, y1) = padded_range(
            self.values
                .iter()
                .flatten()
                .flat_map(|&(p, n)| [p, n])
                .chain([0.0]),
            0.1,
        );
        let (x0, x1) = (-0.5, nd as f64 - 0.5);
        let mut chart = framed_chart(
            &chart_area,
            x0..x1,
            y0..y1,
            Some("disc"),
            "max peak per-tooth load [N]",
            false,
        )?;

        let group = 0.8;
        let bar = group / nr as f64;
        let label_values = nr * nd <= 24;
        let value_style = TextStyle::from((FONT, 12).into_font());
        for (r, run) in self.values.iter().enumerate() {
            let c = color(r);
            let rects = run.iter().enumerate().flat_map(|(d, &(p, n))| {
                let xa = d as f64 - 0.5 * group + r as f64 * bar + 0.06 * bar;
                let xb = xa + 0.88 * bar;
                [(p, true), (n, false)]
                    .into_iter()
                    .filter(|(v, _)| v.is_finite())
                    .map(move |(v, up)| {
                        let (lo, hi) = if up { (0.0, v) } else { (v, 0.0) };
                        Rectangle::new([(xa, lo), (xb, hi)], c.filled())
                    })
            });
            chart.draw_series(rects).map_err(msg)?;
            if label_values {
                for (d, &(p, n)) in run.iter().enumerate() {
                    let xm = d as f64 - 0.5 * group + (r as f64 + 0.5) * bar;
                    for (v, anchor, dy) in [(p, VPos::Bottom, -3), (n, VPos::Top, 3)] {
                        if v.is_finite() && v != 0.0 {
                            let (px, py) = chart.backend_coord(&(xm, v));
                            let style = value_style.pos(Pos::new(HPos::Center, anchor));
                            root.draw(&Text::new(fmt_short(round_sig(v, 4)), (px, py + dy), style))
                                .map_err(msg)?;
                        }
                    }
                }
            }
        }
        chart
            .draw_series(LineSeries::new(
                [(x0, 0.0), (x1, 0.0)],
                BLACK.stroke_width(1),
            ))
            .map_err(msg)?;
        // disc names under their groups, in image pixels
        let name_style =
            TextStyle::from((FONT, 16).into_font()).pos(Pos::new(HPos::Center, VPos::Top));
        for (d, name) in self.discs.iter().enumerate() {
            let (px, py) = chart.backend_coord(&(d as f64, y0));
            root.draw(&Text::new(name.clone(), (px, py + 8), name_style.clone()))
                .map_err(msg)?;
        }
        let mut legend: Vec<(String, Mark, RGBColor)> = self
            .runs
            .iter()
            .enumerate()
            .map(|(r, name)| (name.clone(), Mark::Bar, color(r)))
            .collect();
        legend.push((String::new(), Mark::Line, WHITE));
        legend.push(("up: max + (disc leads)".to_string(), Mark::Line, WHITE));
        legend.push(("down: max - (shaft leads)".to_string(), Mark::Line, WHITE));
        draw_legend(&legend_area, &legend)
    }
}

/// `v` rounded to `digits` significant digits (for labels).
pub(super) fn round_sig(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(digits - 1 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}
