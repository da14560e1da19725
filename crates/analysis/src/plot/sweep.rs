//! The sweep figure (the paper's Fig 3): each disc's peak loads against the swept parameter,
//! ensemble spread as error bars, with the fitted polynomials.

use super::*;

/// The sampled fit curves of one disc: (disc's colour index, max + curve, max - curve).
pub(super) type Curves = (usize, Vec<(f64, f64)>, Vec<(f64, f64)>);

/// Fig 3: peaks against a swept parameter.
pub(super) struct Sweep<'a> {
    pub(super) param: &'a str,
    pub(super) rows: &'a [SweepRow],
    pub(super) fits: &'a [(String, PolyFit, PolyFit)],
}

impl Figure for Sweep<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(msg)?;
        let title = format!("Peak per-tooth impact loads vs {}", self.param);
        let area = root.titled(&title, (FONT, 26)).map_err(msg)?;
        let rows: Vec<&SweepRow> = self.rows.iter().filter(|r| r.max_positive.n > 0).collect();
        if rows.is_empty() && self.fits.is_empty() {
            return no_data(&area);
        }
        let (w, _) = area.dim_in_pixel();
        let (chart_area, legend_area) = area.split_horizontally(w.saturating_sub(LEGEND_W));

        // discs in order of first appearance, rows first, then discs with only a fit
        let mut discs: Vec<&str> = Vec::new();
        for name in rows
            .iter()
            .map(|r| r.disc.as_str())
            .chain(self.fits.iter().map(|f| f.0.as_str()))
        {
            if !discs.contains(&name) {
                discs.push(name);
            }
        }
        let (x_lo, x_hi) = padded_range(rows.iter().map(|r| r.value), 0.0);
        // fit curves over the swept range of their disc (all rows' range if it has none)
        let curves: Vec<Curves> = self
            .fits
            .iter()
            .map(|(disc, pos, neg)| {
                let i = discs.iter().position(|d| d == disc).unwrap_or(0);
                let own: Vec<f64> = rows
                    .iter()
                    .filter(|r| &r.disc == disc)
                    .map(|r| r.value)
                    .collect();
                let (a, b) = if own.len() > 1 {
                    padded_range(own, 0.0)
                } else {
                    (x_lo, x_hi)
                };
                let xs: Vec<f64> = (0..=200).map(|k| a + (b - a) * k as f64 / 200.0).collect();
                let p = xs.iter().map(|&x| (x, pos.eval(x))).collect();
                let n = xs.iter().map(|&x| (x, neg.eval(x))).collect();
                (i, p, n)
            })
            .collect();
        let (x0, x1) = padded_range(rows.iter().map(|r| r.value), 0.05);
        let ys = rows
            .iter()
            .flat_map(|r| {
                [
                    r.max_positive.min,
                    r.max_positive.max,
                    r.max_positive.mean,
                    r.max_negative.min,
                    r.max_negative.max,
                    r.max_negative.mean,
                ]
            })
            .chain(
                curves
                    .iter()
                    .flat_map(|c| c.1.iter().chain(&c.2).map(|p| p.1)),
            )
            .chain([0.0]);
        let (y0, y1) = padded_range(ys, 0.06);

        let mut chart = framed_chart(
            &chart_area,
            x0..x1,
            y0..y1,
            Some(self.param),
            "peak per-tooth load [N]",
            true,
        )?;
        chart
            .draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], BLACK.mix(0.5)))
            .map_err(msg)?;

        let mut legend: Vec<(String, Mark, RGBColor)> = Vec::new();
        for (i, disc) in discs.iter().enumerate() {
            let c = color(i);
            let mut of: Vec<&SweepRow> = rows.iter().copied().filter(|r| r.disc == *disc).collect();
            of.sort_by(|a, b| a.value.total_cmp(&b.value));
            if of.is_empty() {
                continue;
            }
            let has_fit = curves.iter().any(|cv| cv.0 == i);
            let pos: Vec<(f64, f64)> = of.iter().map(|r| (r.value, r.max_positive.mean)).collect();
            let neg: Vec<(f64, f64)> = of.iter().map(|r| (r.value, r.max_negative.mean)).collect();
            if !has_fit {
                for line in [&pos, &neg] {
                    chart
                        .draw_series(LineSeries::new(
                            line.iter().copied(),
                            c.mix(0.6).stroke_width(1),
                        ))
                        .map_err(msg)?;
                }
            }
            chart
                .draw_series(of.iter().filter(|r| r.max_positive.n > 1).flat_map(|r| {
                    [
                        ErrorBar::new_vertical(
                            r.value,
                            r.max_positive.min,
                            r.max_positive.mean,
                            r.max_positive.max,
                            c.stroke_width(1),
                            10,
                        ),
                        ErrorBar::new_vertical(
                            r.value,
                            r.max_negative.min,
                            r.max_negative.mean,
                            r.max_negative.max,
                            c.stroke_width(1),
                            10,
                        ),
                    ]
                }))
                .map_err(msg)?;
            chart
                .draw_series(pos.iter().map(|&p| Circle::new(p, 5, c.filled())))
                .map_err(msg)?;
            chart
                .draw_series(neg.iter().map(|&p| TriangleMarker::new(p, 7, c.filled())))
                .map_err(msg)?;
            legend.push((format!("{disc}: max + (disc leads)"), Mark::Circle, c));
            legend.push((format!("{disc}: max - (shaft leads)"), Mark::Triangle, c));
        }
        for ((i, pos, neg), (disc, fp, fn_)) in curves.iter().zip(self.fits) {
            let c = color(*i);
            for line in [pos, neg] {
                chart
                    .draw_series(LineSeries::new(line.iter().copied(), c.stroke_width(2)))
                    .map_err(msg)?;
            }
            legend.push((
                format!(
                    "{disc}: fit deg {} (R² {:.3} / {:.3})",
                    fp.degree().max(fn_.degree()),
                    fp.r_squared,
                    fn_.r_squared
                ),
                Mark::Line,
                c,
            ));
        }
        let members: Vec<usize> = rows.iter().map(|r| r.max_positive.n).collect();
        if members.iter().any(|&n| n > 1) {
            let (lo, hi) = (
                members.iter().min().copied().unwrap_or(0),
                members.iter().max().copied().unwrap_or(0),
            );
            let n = if lo == hi {
                format!("{lo}")
            } else {
                format!("{lo}-{hi}")
            };
            legend.push((
                format!("markers: mean of {n} runs"),
                Mark::Circle,
                RGBColor(90, 90, 90),
            ));
            legend.push((
                "bars: ensemble min .. max".to_string(),
                Mark::Whisker,
                RGBColor(90, 90, 90),
            ));
        }
        draw_legend(&legend_area, &legend)
    }
}
