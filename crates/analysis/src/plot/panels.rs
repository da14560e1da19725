//! Stacked panels of lines against one x axis: a run's figures window by window (`run
//! --windows S --windows-plot FILE`), or any few series that share their abscissa.

use super::*;

/// One panel: its y-axis label (with its unit) and its named series of `(x, y)` points.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The y axis' label, unit included (`peak per tooth [N]`).
    pub y_label: String,
    /// `(name, points)`, each drawn as a line with markers, named in the panel's legend.
    pub series: Vec<(String, Vec<(f64, f64)>)>,
    /// Markers only, no lines (a scatter of events: impacts' peaks).
    pub markers_only: bool,
}

pub(super) struct Panels<'a> {
    pub(super) title: &'a str,
    pub(super) x_label: &'a str,
    pub(super) panels: &'a [Panel],
}

impl Figure for Panels<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(msg)?;
        let area = root.titled(self.title, (FONT, 26)).map_err(msg)?;
        if self.panels.is_empty() {
            return no_data(&area);
        }
        let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
        let xs = self
            .panels
            .iter()
            .flat_map(|p| &p.series)
            .flat_map(|s| s.1.iter().filter(finite).map(|p| p.0));
        let (x0, x1) = padded_range(xs, 0.02);
        let areas = area.split_evenly((self.panels.len(), 1));
        for (i, (panel, region)) in self.panels.iter().zip(&areas).enumerate() {
            let last = i + 1 == self.panels.len();
            let ys = panel
                .series
                .iter()
                .flat_map(|s| s.1.iter().filter(finite).map(|p| p.1));
            let (y0, y1) = padded_range(ys, 0.08);
            let mut chart = ChartBuilder::on(region)
                .margin(8)
                .margin_right(24)
                .x_label_area_size(if last { 48 } else { 26 })
                .y_label_area_size(96)
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(msg)?;
            style_mesh(
                &mut chart,
                last.then_some(self.x_label),
                &panel.y_label,
                true,
            )?;
            for (k, (name, pts)) in panel.series.iter().enumerate() {
                let c = color(k);
                let pts: Vec<(f64, f64)> = pts.iter().filter(finite).copied().collect();
                if panel.markers_only {
                    chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                        .map_err(msg)?
                        .label(name.as_str())
                        .legend(move |(x, y)| Circle::new((x + 9, y), 4, c.filled()));
                    continue;
                }
                chart
                    .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                    .map_err(msg)?
                    .label(name.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                    });
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                    .map_err(msg)?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.4))
                .label_font((FONT, 14))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(msg)?;
        }
        Ok(())
    }
}
