//! The load-history figure: each disc's per-tooth load against time, thinned per pixel
//! column, the impacts' located peaks merged in.

use super::*;

/// Fig 2: load histories.
pub(super) struct LoadHistory<'a> {
    pub(super) title: &'a str,
    pub(super) series: &'a [(String, Vec<(f64, f64)>)],
}

impl Figure for LoadHistory<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(msg)?;
        let area = root.titled(self.title, (FONT, 26)).map_err(msg)?;
        if self.series.is_empty() {
            return no_data(&area);
        }
        // time in ms from here on
        let data: Vec<Vec<(f64, f64)>> = self
            .series
            .iter()
            .map(|(_, p)| {
                thin(p, 2000)
                    .into_iter()
                    .map(|(t, f)| (t * 1e3, f))
                    .collect()
            })
            .collect();
        let (t0, t1) = padded_range(data.iter().flatten().map(|p| p.0), 0.0);
        let panels = area.split_evenly((data.len(), 1));
        for (i, ((name, pts), panel)) in self
            .series
            .iter()
            .map(|s| &s.0)
            .zip(&data)
            .zip(&panels)
            .enumerate()
        {
            let last = i + 1 == data.len();
            let (y0, y1) = padded_range(pts.iter().map(|p| p.1).chain([0.0]), 0.08);
            let mut chart = ChartBuilder::on(panel)
                .caption(name, (FONT, 18))
                .margin(8)
                .margin_right(24)
                .x_label_area_size(if last { 48 } else { 26 })
                .y_label_area_size(84)
                .build_cartesian_2d(t0..t1, y0..y1)
                .map_err(msg)?;
            style_mesh(
                &mut chart,
                last.then_some("time [ms]"),
                "per-tooth load [N]",
                true,
            )?;
            chart
                .draw_series(LineSeries::new([(t0, 0.0), (t1, 0.0)], BLACK.mix(0.5)))
                .map_err(msg)?;
            chart
                .draw_series(LineSeries::new(
                    pts.iter().copied(),
                    color(i).stroke_width(1),
                ))
                .map_err(msg)?;
            if pts.is_empty() {
                no_data(&chart.plotting_area().strip_coord_spec())?;
            }
        }
        Ok(())
    }
}
