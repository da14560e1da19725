//! `--windows-plot`: the figures of `--windows S` against time (each window at its middle),
//! for a pack run (its bodies) and for a network run (each resolved pack's worst body in each
//! window; its temperatures named `<pack>/oil`, `<pack>/hottest body`).

use anyhow::{Context, Result};
use clutchpack_sdk::analysis::Panel;
use clutchpack_sdk::{BodyWindow, WindowRow};
use std::path::Path;

/// A series of a panel: its name and its points (s, value).
type Series = (String, Vec<(f64, f64)>);

/// The window's middle, s.
fn mid(w: &WindowRow) -> f64 {
    0.5 * (w.t0_s + w.t1_s)
}

/// Writes the figure of `groups` (each a pack's name, `None` for a pack run's own, and its
/// windows) to `path` (PNG or SVG by extension) under `title`: the largest peak per tooth
/// and the damage rate (log10, where any is at least 1e-12 per hour) of each body of a pack
/// run (those whose largest peak is at least a tenth of the largest of all) or of each pack
/// of a network (its worst body's in each window), and where a pack is thermal its oil's and
/// hottest body's temperature.
pub fn write(path: &Path, title: &str, groups: &[(Option<&str>, &[WindowRow])]) -> Result<()> {
    let largest = |windows: &[WindowRow], i: usize| {
        windows
            .iter()
            .filter_map(|w| w.bodies.get(i))
            .map(|b| b.peak_abs_n)
            .fold(0.0, f64::max)
    };
    let bodies = |windows: &[WindowRow]| windows.first().map_or(0, |w| w.bodies.len());
    let top = groups
        .iter()
        .flat_map(|(_, w)| (0..bodies(w)).map(|i| largest(w, i)))
        .fold(0.0, f64::max);
    let named = |pack: Option<&str>, name: &str| match pack {
        Some(p) => format!("{p}/{name}"),
        None => name.to_string(),
    };
    // the bodies that hit at all: a largest peak of at least a tenth of the run's (a plate
    // resting on its flank would only crowd the figure)
    let by_body = |f: &dyn Fn(&BodyWindow) -> f64| -> Vec<Series> {
        let mut out = Vec::new();
        for (pack, windows) in groups {
            for i in (0..bodies(windows)).filter(|&i| largest(windows, i) >= 0.1 * top) {
                let pts = windows
                    .iter()
                    .filter_map(|w| w.bodies.get(i).map(|b| (mid(w), f(b))))
                    .collect();
                out.push((named(*pack, &windows[0].bodies[i].name), pts));
            }
        }
        out
    };
    // rates below 1e-12 per hour (a million years) are left out
    let log_rate = |r: f64| if r >= 1e-12 { r.log10() } else { f64::NAN };
    // a network's packs: one series each, its worst body's in each window (the table and
    // `--summary-json` give every body's); a pack run: one series per body
    let network = groups.iter().any(|(pack, _)| pack.is_some());
    let by_pack = |f: &dyn Fn(&WindowRow) -> f64| -> Vec<Series> {
        groups
            .iter()
            .map(|(pack, windows)| {
                let pts = windows.iter().map(|w| (mid(w), f(w))).collect();
                (format!("{} (its worst body)", pack.unwrap_or("pack")), pts)
            })
            .collect()
    };
    let (peaks, rates) = if network {
        (
            by_pack(&|w| w.peak_abs_n),
            by_pack(&|w| log_rate(w.damage_rate_per_h)),
        )
    } else {
        (
            by_body(&|b| b.peak_abs_n),
            by_body(&|b| log_rate(b.damage_rate_per_h)),
        )
    };
    let some = |series: Vec<Series>| -> Vec<Series> {
        series
            .into_iter()
            .filter(|(_, pts)| pts.iter().any(|p| p.1.is_finite()))
            .collect()
    };
    let mut panels = vec![Panel {
        y_label: "largest |peak| per tooth [N]".into(),
        series: peaks,
        markers_only: false,
    }];
    let rates = some(rates);
    if !rates.is_empty() {
        panels.push(Panel {
            y_label: "log10 damage rate [log10 1/h]".into(),
            series: rates,
            markers_only: false,
        });
    }
    let mut temperatures: Vec<Series> = Vec::new();
    for (pack, windows) in groups {
        if !windows.iter().any(|w| w.oil_k.is_some()) {
            continue;
        }
        let series = |f: &dyn Fn(&WindowRow) -> Option<f64>| -> Vec<(f64, f64)> {
            windows
                .iter()
                .filter_map(|w| f(w).map(|y| (mid(w), y)))
                .collect()
        };
        temperatures.push((named(*pack, "oil"), series(&|w| w.oil_k)));
        temperatures.push((named(*pack, "hottest body"), series(&|w| w.hottest_body_k)));
    }
    if !temperatures.is_empty() {
        panels.push(Panel {
            y_label: "temperature [K]".into(),
            series: temperatures,
            markers_only: false,
        });
    }
    crate::outputs::write_with(path, |tmp| {
        clutchpack_sdk::analysis::plot_panels(tmp, title, "window's middle [s]", &panels)
            .with_context(|| format!("plotting {}", path.display()))
    })
}
