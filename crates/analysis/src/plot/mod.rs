//! Figures with plotters: PNG or SVG, chosen by the output file's extension.
//!
//! - [`plot_load_history`]: per-tooth load against time, one panel per disc (the paper's
//!   Fig 2).
//! - [`plot_sweep`]: the largest positive and negative peaks against a swept parameter, with
//!   ensemble min..max error bars and polynomial fit curves (the paper's Fig 3).
//! - [`plot_compare`]: a grouped bar chart of the peaks of several runs, per disc.
//! - [`plot_panels`]: stacked panels of named lines against one x axis (a run's windows).
//!
//! Text is rendered with plotters' `ab_glyph` renderer from DejaVu Sans bytes embedded in the
//! binary (the `dejavu` crate), registered on first use by [`register_fonts`]: the figures
//! need no system font. (An SVG names the font family `sans-serif`; the viewer draws it.)

mod compare;
mod history;
mod panels;
mod sweep;
use compare::*;
use history::*;
pub use panels::Panel;
use panels::Panels;
use sweep::*;

use crate::fit::PolyFit;
use crate::sweep::SweepRow;
use crate::table::fmt_short;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Why a figure could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// The file name does not end in `.png` or `.svg` (either case).
    #[error("{}: cannot tell the figure format from the extension {extension:?}: use .png or .svg", path.display())]
    UnsupportedFormat {
        /// The requested output file.
        path: PathBuf,
        /// Its extension (empty if none).
        extension: String,
    },
    /// The embedded font could not be registered with plotters (a bug).
    #[error("the embedded DejaVu Sans font could not be registered with plotters")]
    Font,
    /// The input does not describe a figure (e.g. the shapes of the arrays disagree).
    #[error("cannot plot {}: {reason}", path.display())]
    InvalidInput {
        /// The requested output file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// plotters failed while drawing or writing the file (e.g. the folder does not exist).
    #[error("drawing {} failed: {message}", path.display())]
    Draw {
        /// The requested output file.
        path: PathBuf,
        /// plotters' message.
        message: String,
    },
}

/// Registers the embedded DejaVu Sans faces with plotters under the families `sans-serif`
/// and `serif` (regular, bold, oblique) and DejaVu Sans Mono as `monospace`.
///
/// Every plot function calls it; it does the work once per process. Call it yourself before
/// drawing text with plotters outside this module.
pub fn register_fonts() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        use plotters::style::register_font;
        let mut ok = true;
        for family in ["sans-serif", "serif"] {
            ok &= register_font(family, FontStyle::Normal, dejavu::sans::regular()).is_ok();
            ok &= register_font(family, FontStyle::Bold, dejavu::sans::bold()).is_ok();
            ok &= register_font(family, FontStyle::Oblique, dejavu::sans::oblique()).is_ok();
            ok &= register_font(family, FontStyle::Italic, dejavu::sans::oblique()).is_ok();
        }
        ok &= register_font("monospace", FontStyle::Normal, dejavu::sans_mono::regular()).is_ok();
        ok
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// Per-tooth load against time, one panel per disc stacked vertically, on a shared time axis
/// in ms (the paper's Fig 2).
///
/// `series` holds `(disc name, points)` with points `(t in s, per-tooth load in N)` in time
/// order. Histories longer than a few thousand points are thinned to the minimum and maximum
/// of each of ~2000 time slices, which keeps every peak visible. Non-finite points are
/// skipped. No series at all gives a figure that says "no data".
///
/// The format follows `path`'s extension (`.png` or `.svg`).
pub fn plot_load_history(
    path: &Path,
    title: &str,
    series: &[(String, Vec<(f64, f64)>)],
) -> Result<(), PlotError> {
    let panels = series.len().max(1);
    let size = (1200, 60 + 220 * panels as u32);
    render(path, size, &LoadHistory { title, series })
}

/// Stacked [`Panel`]s of named lines (with markers) against one x axis labelled `x_label`
/// (unit included), under `title`; non-finite points are skipped.
///
/// The format follows `path`'s extension (`.png` or `.svg`).
pub fn plot_panels(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[Panel],
) -> Result<(), PlotError> {
    let size = (1200, 60 + 260 * panels.len().max(1) as u32);
    render(
        path,
        size,
        &Panels {
            title,
            x_label,
            panels,
        },
    )
}

/// The largest positive and negative peak loads against a swept parameter (the paper's
/// Fig 3).
///
/// For each disc in `rows` (from [`crate::sweep::sweep_rows`]): the ensemble mean of the max
/// positive peak (circles) and of the max negative peak (triangles), in N, at each parameter
/// value, with error bars from the ensemble's min to its max when a row has more than one
/// member. `fits` holds `(disc, fit of max +, fit of max -)` (e.g. from
/// [`crate::sweep::sweep_fits`]), drawn as curves over the swept range; a disc without a fit
/// has its means joined by thin lines instead. `param` labels the x axis as given: include
/// its unit (`backlash [m]`).
///
/// The format follows `path`'s extension (`.png` or `.svg`).
pub fn plot_sweep(
    path: &Path,
    param: &str,
    rows: &[SweepRow],
    fits: &[(String, PolyFit, PolyFit)],
) -> Result<(), PlotError> {
    render(path, (1200, 760), &Sweep { param, rows, fits })
}

/// A grouped bar chart comparing runs: for each disc, one bar per run, the max positive peak
/// upwards and the max negative peak downwards, in N.
///
/// `values[run][disc] = (max_positive_n, max_negative_n)` with `runs.len()` rows of
/// `discs.len()` pairs (else [`PlotError::InvalidInput`]). Runs are told apart by colour
/// and the legend.
///
/// The format follows `path`'s extension (`.png` or `.svg`).
pub fn plot_compare(
    path: &Path,
    runs: &[String],
    discs: &[String],
    values: &[Vec<(f64, f64)>],
) -> Result<(), PlotError> {
    if values.len() != runs.len() {
        return Err(PlotError::InvalidInput {
            path: path.to_path_buf(),
            reason: format!("{} runs but values for {} runs", runs.len(), values.len()),
        });
    }
    if let Some((r, v)) = values
        .iter()
        .enumerate()
        .find(|(_, v)| v.len() != discs.len())
    {
        return Err(PlotError::InvalidInput {
            path: path.to_path_buf(),
            reason: format!(
                "{} discs but values[{r}] (run {:?}) has {} pairs",
                discs.len(),
                runs[r],
                v.len()
            ),
        });
    }
    let width = (320 + 170 * discs.len() as u32).max(900);
    render(
        path,
        (width, 700),
        &Compare {
            runs,
            discs,
            values,
        },
    )
}

// ---------------------------------------------------------------------------------------------
// backends

/// A figure that can be drawn on any plotters backend.
pub(crate) trait Figure {
    /// Draws on `root` (already the full image); a plotters error becomes its message.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// A figure file's format, from its extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FigureFormat {
    /// `.png` (either case): a bitmap.
    Png,
    /// `.svg` (either case): a vector drawing.
    Svg,
}

/// The format a figure written to `path` would have, from its extension (`.png` or `.svg`,
/// either case); any other extension is [`PlotError::UnsupportedFormat`]. Commands call it
/// before any work, so that a figure they cannot write never costs a simulation.
pub fn figure_format(path: &Path) -> Result<FigureFormat, PlotError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "png" => Ok(FigureFormat::Png),
        "svg" => Ok(FigureFormat::Svg),
        _ => Err(PlotError::UnsupportedFormat {
            path: path.to_path_buf(),
            extension,
        }),
    }
}

/// Opens a PNG or SVG backend by `path`'s extension, draws `figure` and writes the file.
pub(crate) fn render(path: &Path, size: (u32, u32), figure: &impl Figure) -> Result<(), PlotError> {
    let format = figure_format(path)?;
    register_fonts()?;
    let failed = |message: String| PlotError::Draw {
        path: path.to_path_buf(),
        message,
    };
    if format == FigureFormat::Png {
        let root = BitMapBackend::new(path, size).into_drawing_area();
        figure.draw(&root).map_err(failed)?;
        root.present().map_err(|e| failed(e.to_string()))
    } else {
        let root = SVGBackend::new(path, size).into_drawing_area();
        figure.draw(&root).map_err(failed)?;
        root.present().map_err(|e| failed(e.to_string()))
    }
}

// ---------------------------------------------------------------------------------------------
// the figures

/// The registered font family used for all text.
pub(crate) const FONT: &str = "sans-serif";

/// Width of the legend panel to the right of the sweep and comparison charts, px.
const LEGEND_W: u32 = 330;

/// Matplotlib's "tab10" colours: distinct, and readable on white.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

pub(crate) fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// A plotters error as its message.
pub(crate) fn msg(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// `(lo, hi)` of the finite values, widened by `frac` of the span on each side; a single
/// value gets +-10 % of itself (+-1 at zero); no values give `(0, 1)`.
fn padded_range(values: impl IntoIterator<Item = f64>, frac: f64) -> (f64, f64) {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        (0.0, 1.0)
    } else if lo == hi {
        let d = if lo != 0.0 { 0.1 * lo.abs() } else { 1.0 };
        (lo - d, hi + d)
    } else {
        let d = frac * (hi - lo);
        (lo - d, hi + d)
    }
}

/// Thins a time history to the first, minimum, maximum and last point of each of `slices`
/// equal time slices (in time order) when it has more than `4 * slices` points: a line
/// through them looks like the full history at the figure's resolution and keeps every peak.
/// Non-finite points are dropped.
fn thin(points: &[(f64, f64)], slices: usize) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(t, f)| t.is_finite() && f.is_finite())
        .collect();
    let (t0, t1) = padded_range(pts.iter().map(|p| p.0), 0.0);
    if pts.len() <= 4 * slices || t1 <= t0 {
        return pts;
    }
    let slice_of = |t: f64| (((t - t0) / (t1 - t0) * slices as f64) as usize).min(slices - 1);
    let mut out = Vec::with_capacity(4 * slices);
    let mut i = 0;
    while i < pts.len() {
        let s = slice_of(pts[i].0);
        let mut j = i;
        let (mut lo, mut hi) = (i, i);
        while j < pts.len() && slice_of(pts[j].0) == s {
            if pts[j].1 < pts[lo].1 {
                lo = j;
            }
            if pts[j].1 > pts[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let mut keep = [i, lo, hi, j - 1];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for k in keep {
            if k != last {
                out.push(pts[k]);
                last = k;
            }
        }
        i = j;
    }
    out
}

/// Writes "no data" in the middle of `area`.
pub(crate) fn no_data<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>) -> Result<(), String> {
    let (w, h) = area.dim_in_pixel();
    let style = TextStyle::from((FONT, 22).into_font())
        .color(&RGBColor(110, 110, 110))
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw(&Text::new("no data", (w as i32 / 2, h as i32 / 2), style))
        .map_err(msg)
}

/// What a legend entry shows before its label.
#[derive(Clone, Copy)]
enum Mark {
    Circle,
    Triangle,
    Line,
    Bar,
    Whisker,
}

/// Draws `entries` as a legend column in `area` (a panel beside the chart: never over data).
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Mark, RGBColor)],
) -> Result<(), String> {
    let (x, mut y) = (8, 60);
    let text = TextStyle::from((FONT, 15).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    for (label, mark, c) in entries {
        match mark {
            Mark::Circle => area.draw(&Circle::new((x + 12, y), 5, c.filled())),
            Mark::Triangle => area.draw(&TriangleMarker::new((x + 12, y), 7, c.filled())),
            Mark::Line => area.draw(&PathElement::new(
                vec![(x, y), (x + 24, y)],
                c.stroke_width(2),
            )),
            Mark::Bar => area.draw(&Rectangle::new(
                [(x + 5, y - 8), (x + 19, y + 8)],
                c.filled(),
            )),
            Mark::Whisker => area.draw(&PathElement::new(
                vec![
                    (x + 7, y - 8),
                    (x + 17, y - 8),
                    (x + 12, y - 8),
                    (x + 12, y + 8),
                    (x + 7, y + 8),
                    (x + 17, y + 8),
                ],
                c.stroke_width(1),
            )),
        }
        .map_err(msg)?;
        area.draw(&Text::new(label.clone(), (x + 32, y), text.clone()))
            .map_err(msg)?;
        y += 26;
    }
    Ok(())
}

/// The common axis styling: tick labels without trailing zeros, light grid.
/// The chart of a one-panel figure on `area`, in the frame every such figure shares (margin,
/// label areas, mesh styled by [`style_mesh`]): x over `x` and y over `y`, axis captions
/// `x_desc` and `y_desc`, x labels only when `x_labels`.
fn framed_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    x_desc: Option<&str>,
    y_desc: &str,
    x_labels: bool,
) -> Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String> {
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(56)
        .y_label_area_size(90)
        .build_cartesian_2d(x, y)
        .map_err(msg)?;
    style_mesh(&mut chart, x_desc, y_desc, x_labels)?;
    Ok(chart)
}

fn style_mesh<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    x_desc: Option<&str>,
    y_desc: &str,
    x_labels: bool,
) -> Result<(), String> {
    let fmt = |v: &f64| fmt_short(*v);
    let mut mesh = chart.configure_mesh();
    mesh.x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .y_desc(y_desc)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .bold_line_style(RGBColor(220, 220, 220))
        .light_line_style(RGBColor(242, 242, 242));
    if let Some(d) = x_desc {
        mesh.x_desc(d);
    }
    if !x_labels {
        mesh.disable_x_mesh().x_labels(0);
    }
    mesh.draw().map_err(msg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::DiscStats;
    use crate::sweep::{sweep_fits, sweep_rows, SweepCase};
    use std::path::PathBuf;

    /// A folder for the figures: `$CLUTCHPACK_PLOT_DIR` if set (kept, to look at them),
    /// else a fresh folder under the system temp dir (removed by [`Out::drop`]).
    struct Out {
        dir: PathBuf,
        keep: bool,
    }

    impl Out {
        fn new(test: &str) -> Out {
            match std::env::var_os("CLUTCHPACK_PLOT_DIR") {
                Some(d) => {
                    let dir = PathBuf::from(d);
                    std::fs::create_dir_all(&dir).unwrap();
                    Out { dir, keep: true }
                }
                None => {
                    let dir = std::env::temp_dir()
                        .join(format!("clutchpack_analysis_{}_{test}", std::process::id()));
                    std::fs::create_dir_all(&dir).unwrap();
                    Out { dir, keep: false }
                }
            }
        }
        fn path(&self, name: &str) -> PathBuf {
            self.dir.join(name)
        }
    }

    impl Drop for Out {
        fn drop(&mut self) {
            if !self.keep {
                let _ = std::fs::remove_dir_all(&self.dir);
            }
        }
    }

    /// The file exists, is not trivially small and starts like its format.
    fn assert_figure(path: &Path) {
        let bytes = std::fs::read(path).unwrap();
        assert!(
            bytes.len() > 1000,
            "{}: {} bytes",
            path.display(),
            bytes.len()
        );
        let ext = path
            .extension()
            .unwrap()
            .to_str()
            .unwrap()
            .to_ascii_lowercase();
        match ext.as_str() {
            "png" => assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n"),
            _ => {
                let text = std::str::from_utf8(&bytes).expect("an SVG is UTF-8");
                assert!(text.contains("<svg") && text.contains("<text"));
            }
        }
    }

    /// Three discs rattling for 0.3 s at 1 us: half-sine pulses of alternating sign.
    fn histories() -> Vec<(String, Vec<(f64, f64)>)> {
        (0..3)
            .map(|d| {
                let pts = (0..300_000)
                    .map(|i| {
                        let t = i as f64 * 1e-6;
                        let k = (t / 4e-3) as usize; // one pulse per 4 ms
                        let tau = t - k as f64 * 4e-3;
                        let width = 60e-6 * (1.0 + 0.2 * d as f64);
                        let amp = (400.0 + 150.0 * ((k * 7 + d * 3) % 5) as f64)
                            * if (k + d).is_multiple_of(3) { 1.0 } else { -1.0 };
                        let f = if tau < width {
                            amp * (std::f64::consts::PI * tau / width).sin()
                        } else {
                            0.0
                        };
                        (t, f)
                    })
                    .collect();
                (format!("disc {}", d + 1), pts)
            })
            .collect()
    }

    /// A sweep of the backlash over 20..100 um, four-member ensembles, two discs whose peaks
    /// grow quadratically with some scatter.
    fn sweep() -> Vec<SweepRow> {
        let cases: Vec<SweepCase> = (1..=5)
            .map(|i| {
                let b = i as f64 * 20e-6;
                let members = (0..4)
                    .map(|m| {
                        let jitter = 1.0 + 0.04 * (m as f64 - 1.5);
                        vec![
                            DiscStats {
                                max_positive_n: (300.0 + 6e10 * b * b) * jitter,
                                max_negative_n: -(500.0 + 9e10 * b * b) * jitter,
                                ..DiscStats::empty("disc 1")
                            },
                            DiscStats {
                                max_positive_n: (200.0 + 2e7 * b) * jitter,
                                max_negative_n: -(250.0 + 3e10 * b * b) / jitter,
                                ..DiscStats::empty("disc 2")
                            },
                        ]
                    })
                    .collect();
                SweepCase { value: b, members }
            })
            .collect();
        sweep_rows(&cases)
    }

    /// Every figure is written as PNG and as SVG (upper-case extensions too), with no system
    /// font needed.
    #[test]
    fn figures_are_written_as_png_and_svg() {
        let out = Out::new("figures");
        let rows = sweep();
        let fits = sweep_fits(&rows, 2).unwrap();
        let runs = vec![
            "reference".to_string(),
            "multibody".to_string(),
            "dry".to_string(),
        ];
        let discs: Vec<String> = (1..=4).map(|d| format!("disc {d}")).collect();
        let values: Vec<Vec<(f64, f64)>> = (0..3)
            .map(|r| {
                (0..4)
                    .map(|d| {
                        (
                            800.0 + 90.0 * (r * 4 + d) as f64,
                            -1200.0 + 70.0 * (r + 2 * d) as f64,
                        )
                    })
                    .collect()
            })
            .collect();
        let hist = histories();
        for ext in ["png", "svg", "PNG"] {
            let p = out.path(&format!("history.{ext}"));
            plot_load_history(&p, "Per-tooth impact loads, 3 discs", &hist).unwrap();
            assert_figure(&p);
            let p = out.path(&format!("sweep.{ext}"));
            plot_sweep(&p, "backlash [m]", &rows, &fits).unwrap();
            assert_figure(&p);
            let p = out.path(&format!("compare.{ext}"));
            plot_compare(&p, &runs, &discs, &values).unwrap();
            assert_figure(&p);
        }
        // single runs without fits: means joined by lines, no error bars
        let single: Vec<SweepRow> = rows
            .iter()
            .map(|r| {
                let mut r = r.clone();
                r.max_positive.n = 1;
                r
            })
            .collect();
        let p = out.path("sweep_single.png");
        plot_sweep(&p, "backlash [m]", &single, &[]).unwrap();
        assert_figure(&p);
    }

    /// Empty input draws a "no data" figure instead of failing or panicking.
    #[test]
    fn empty_input_draws_no_data() {
        let out = Out::new("empty");
        for ext in ["png", "svg"] {
            let p = out.path(&format!("empty_history.{ext}"));
            plot_load_history(&p, "nothing", &[]).unwrap();
            assert!(p.exists());
            let p = out.path(&format!("empty_panel.{ext}"));
            plot_load_history(&p, "one empty disc", &[("d".to_string(), vec![])]).unwrap();
            assert!(p.exists());
            let p = out.path(&format!("empty_sweep.{ext}"));
            plot_sweep(&p, "x", &[], &[]).unwrap();
            assert!(p.exists());
            let p = out.path(&format!("empty_compare.{ext}"));
            plot_compare(&p, &[], &[], &[]).unwrap();
            assert!(p.exists());
        }
    }

    /// The format comes from the extension: anything but png/svg is an error naming it, and
    /// no file is written.
    #[test]
    fn unknown_extension_is_an_error() {
        let out = Out::new("ext");
        for name in ["figure.jpg", "figure", "figure.svg.txt"] {
            let p = out.path(name);
            let e = plot_load_history(&p, "t", &histories()[..1]).unwrap_err();
            assert!(matches!(e, PlotError::UnsupportedFormat { .. }), "{e}");
            assert!(e.to_string().contains(".png or .svg"));
            assert!(!p.exists());
        }
        let e = plot_sweep(&out.path("s.pdf"), "x", &[], &[]).unwrap_err();
        assert!(
            matches!(e, PlotError::UnsupportedFormat { ref extension, .. } if extension == "pdf")
        );
    }

    /// Bad shapes and unwritable paths are errors, not panics.
    #[test]
    fn bad_input_and_paths_are_errors() {
        let out = Out::new("bad");
        let runs = vec!["a".to_string()];
        let discs = vec!["d1".to_string(), "d2".to_string()];
        let e = plot_compare(&out.path("c.png"), &runs, &discs, &[vec![(1.0, -1.0)]]).unwrap_err();
        assert!(matches!(e, PlotError::InvalidInput { .. }), "{e}");
        let e = plot_compare(&out.path("c.png"), &runs, &discs, &[]).unwrap_err();
        assert!(matches!(e, PlotError::InvalidInput { .. }), "{e}");
        let missing = out.path("no/such/folder/h.png");
        let e = plot_load_history(&missing, "t", &histories()[..1]).unwrap_err();
        assert!(matches!(e, PlotError::Draw { .. }), "{e}");
    }

    /// Thinning keeps every extreme and the ends, and leaves short histories alone.
    #[test]
    fn thinning_keeps_the_peaks() {
        let h = &histories()[0].1;
        let t = thin(h, 2000);
        assert!(t.len() <= 4 * 2000 && t.len() > 2000, "{}", t.len());
        let max = |p: &[(f64, f64)]| p.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let min = |p: &[(f64, f64)]| p.iter().map(|p| p.1).fold(f64::MAX, f64::min);
        assert_eq!(max(&t), max(h));
        assert_eq!(min(&t), min(h));
        assert_eq!(t[0], h[0]);
        assert_eq!(t.last(), h.last());
        assert!(t.windows(2).all(|w| w[0].0 < w[1].0));
        let short = vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)];
        assert_eq!(thin(&short, 2000), vec![(0.0, 1.0), (2.0, 3.0)]);
    }
}
