//! Tables of statistics and sweeps as aligned plain text, markdown or CSV.
//!
//! Every column header carries its unit: `max + [N]` in text and markdown, a unit suffix in
//! CSV (`max_positive_n`), as for recorded fields elsewhere in clutchpack. Text and markdown
//! round numbers to about four significant digits for reading; CSV keeps every digit
//! (Rust's shortest round-trip form) for machines.

use crate::fatigue::{format_life_h, DiscFatigue, DiscFatigueSpread};
use crate::interfaces::InterfaceStats;
use crate::stats::DiscStats;
use crate::sweep::{Spread, SweepRow};
use std::fmt::Write as _;

/// How a table is rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TableFormat {
    /// Columns aligned with spaces under a dashed rule, for a terminal.
    Text,
    /// A GitHub-flavoured markdown table (numbers right-aligned).
    Markdown,
    /// Comma-separated values with one header line (RFC 4180 quoting).
    Csv,
}

/// One column: its header and whether its cells are right-aligned (numbers).
pub(crate) struct Col {
    header: String,
    right: bool,
}

pub(crate) fn col(header: impl Into<String>, right: bool) -> Col {
    Col {
        header: header.into(),
        right,
    }
}

/// The statistics of one run, one row per disc.
///
/// Columns (text and markdown): `disc`, `max + [N]`, `max - [N]`, `p99 abs [N]`,
/// `top-10 mean abs [N]`, `impacts`, `+ impacts`, `- impacts`. CSV: `disc`,
/// `max_positive_n`, `max_negative_n`, `p99_abs_n`, `mean_top10_abs_n`, `impacts`,
/// `positive_impacts`, `negative_impacts` (the [`DiscStats`] field names).
/// An empty `stats` gives the header alone.
pub fn stats_table(stats: &[DiscStats], format: TableFormat) -> String {
    if format == TableFormat::Csv {
        let mut out = String::from(
            "disc,max_positive_n,max_negative_n,p99_abs_n,mean_top10_abs_n,impacts,positive_impacts,negative_impacts\n",
        );
        for s in stats {
            let _ = writeln!(
                out,
                "{},{:?},{:?},{:?},{:?},{},{},{}",
                csv_field(&s.name),
                s.max_positive_n,
                s.max_negative_n,
                s.p99_abs_n,
                s.mean_top10_abs_n,
                s.impacts,
                s.positive_impacts,
                s.negative_impacts
            );
        }
        return out;
    }
    let cols = vec![
        col("disc", false),
        col("max + [N]", true),
        col("max - [N]", true),
        col("p99 abs [N]", true),
        col("top-10 mean abs [N]", true),
        col("impacts", true),
        col("+ impacts", true),
        col("- impacts", true),
    ];
    let rows: Vec<Vec<String>> = stats
        .iter()
        .map(|s| {
            vec![
                s.name.clone(),
                fmt_num(s.max_positive_n),
                fmt_num(s.max_negative_n),
                fmt_num(s.p99_abs_n),
                fmt_num(s.mean_top10_abs_n),
                s.impacts.to_string(),
                s.positive_impacts.to_string(),
                s.negative_impacts.to_string(),
            ]
        })
        .collect();
    render(format, &cols, &rows)
}

/// The friction interfaces of one run, one row each, in stack order.
///
/// Columns (text and markdown): `interface`, `max clamp [N]`, `max |torque| [N m]`,
/// `locked since [s]` (`slipping` when the faces slip at the end), `heat [J]`. CSV:
/// `interface`, `max_clamp_n`, `max_abs_torque_n_m`, `locked_since_s` (empty when
/// slipping), `dissipated_j`.
pub fn interface_table(stats: &[InterfaceStats], format: TableFormat) -> String {
    if format == TableFormat::Csv {
        let mut out =
            String::from("interface,max_clamp_n,max_abs_torque_n_m,locked_since_s,dissipated_j\n");
        for s in stats {
            let _ = writeln!(
                out,
                "{},{:?},{:?},{},{:?}",
                csv_field(&s.name),
                s.max_clamp_n,
                s.max_abs_torque_n_m,
                s.locked_since_s
                    .map(|t| format!("{t:?}"))
                    .unwrap_or_default(),
                s.dissipated_j
            );
        }
        return out;
    }
    let cols = vec![
        col("interface", false),
        col("max clamp [N]", true),
        col("max |torque| [N m]", true),
        col("locked since [s]", true),
        col("heat [J]", true),
    ];
    let rows: Vec<Vec<String>> = stats
        .iter()
        .map(|s| {
            vec![
                s.name.clone(),
                fmt_num(s.max_clamp_n),
                fmt_num(s.max_abs_torque_n_m),
                s.locked_since_s
                    .map_or_else(|| "slipping".to_string(), |t| format!("{t:.4}")),
                fmt_num(s.dissipated_j),
            ]
        })
        .collect();
    render(format, &cols, &rows)
}

/// The rows of a sweep, one line per (parameter value, disc).
///
/// `param` heads the value column as given: name it with its unit (`backlash_m`,
/// `backlash [m]`). Text and markdown show `mean ± std` when any row has more than one
/// ensemble member, adding `members` and `min .. max` range columns; with single runs only
/// the values. Columns (those marked * with ensembles only): `param`, `disc`, `members`*,
/// `max + [N]`, `max + range [N]`*, `max - [N]`, `max - range [N]`*, `p99 abs [N]`,
/// `impacts`. CSV always has every number:
/// `param`, `disc`, `members`, then `mean`, `std`, `min`, `max` of each of `max_positive_*_n`,
/// `max_negative_*_n`, `p99_abs_*_n` and `impacts_*`.
pub fn sweep_table(param: &str, rows: &[SweepRow], format: TableFormat) -> String {
    if format == TableFormat::Csv {
        let mut out = format!("{},disc,members", csv_field(param));
        for q in ["max_positive", "max_negative", "p99_abs"] {
            for s in ["mean", "std", "min", "max"] {
                let _ = write!(out, ",{q}_{s}_n");
            }
        }
        out.push_str(",impacts_mean,impacts_std,impacts_min,impacts_max\n");
        for r in rows {
            let _ = write!(
                out,
                "{:?},{},{}",
                r.value,
                csv_field(&r.disc),
                r.max_positive.n
            );
            for s in [&r.max_positive, &r.max_negative, &r.p99_abs, &r.impacts] {
                let _ = write!(out, ",{:?},{:?},{:?},{:?}", s.mean, s.std, s.min, s.max);
            }
            out.push('\n');
        }
        return out;
    }
    let ensembles = rows.iter().any(|r| r.max_positive.n > 1);
    let mut cols = vec![col(param, true), col("disc", false)];
    if ensembles {
        cols.push(col("members", true));
    }
    cols.push(col("max + [N]", true));
    if ensembles {
        cols.push(col("max + range [N]", true));
    }
    cols.push(col("max - [N]", true));
    if ensembles {
        cols.push(col("max - range [N]", true));
    }
    cols.push(col("p99 abs [N]", true));
    cols.push(col("impacts", true));
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut c = vec![fmt_short(r.value), r.disc.clone()];
            if ensembles {
                c.push(r.max_positive.n.to_string());
            }
            c.push(mean_std(&r.max_positive));
            if ensembles {
                c.push(range(&r.max_positive));
            }
            c.push(mean_std(&r.max_negative));
            if ensembles {
                c.push(range(&r.max_negative));
            }
            c.push(mean_std(&r.p99_abs));
            c.push(mean_std(&r.impacts));
            c
        })
        .collect();
    render(format, &cols, &cells)
}

/// `mean ± std`, or the mean alone for a single member.
fn mean_std(s: &Spread) -> String {
    if s.n > 1 {
        format!("{} ± {}", fmt_num(s.mean), fmt_num(s.std))
    } else {
        fmt_num(s.mean)
    }
}

/// `min .. max`, or `-` for a single member.
fn range(s: &Spread) -> String {
    if s.n > 1 {
        format!("{} .. {}", fmt_num(s.min), fmt_num(s.max))
    } else {
        "-".to_string()
    }
}

/// Renders text or markdown with columns padded to their widest cell (in characters), written
/// into one string: numbers right-aligned, a markdown cell's `|` escaped, a text line's
/// trailing spaces trimmed (a table of a 33-body pack's figures was a tenth of a short run's
/// instructions when every cell and line was formatted on its own).
pub(crate) fn render(format: TableFormat, cols: &[Col], rows: &[Vec<String>]) -> String {
    use std::borrow::Cow;
    let md = matches!(format, TableFormat::Markdown);
    fn escape(md: bool, s: &str) -> Cow<'_, str> {
        if md && s.contains('|') {
            Cow::Owned(s.replace('|', "\\|"))
        } else {
            Cow::Borrowed(s)
        }
    }
    let header: Vec<Cow<'_, str>> = cols.iter().map(|c| escape(md, &c.header)).collect();
    let rows: Vec<Vec<Cow<'_, str>>> = rows
        .iter()
        .map(|r| r.iter().map(|s| escape(md, s)).collect())
        .collect();
    let width = |s: &str| s.chars().count();
    let widths: Vec<usize> = (0..cols.len())
        .map(|i| {
            rows.iter()
                .map(|r| width(&r[i]))
                .chain([width(&header[i]), 3])
                .max()
                .unwrap_or(3)
        })
        .collect();
    let spaces = |out: &mut String, n: usize| out.extend(std::iter::repeat_n(' ', n));
    let line = |out: &mut String, cells: &[Cow<'_, str>]| {
        let start = out.len();
        if md {
            out.push_str("| ");
        }
        for (i, s) in cells.iter().enumerate() {
            if i > 0 {
                out.push_str(if md { " | " } else { "  " });
            }
            let fill = widths[i] - width(s);
            if cols[i].right {
                spaces(out, fill);
                out.push_str(s);
            } else {
                out.push_str(s);
                spaces(out, fill);
            }
        }
        if md {
            out.push_str(" |");
        } else {
            let kept = out[start..].trim_end().len();
            out.truncate(start + kept);
        }
        out.push('\n');
    };
    let line_len = widths.iter().sum::<usize>() + 3 * widths.len() + 4;
    let mut out = String::with_capacity(line_len * (rows.len() + 2));
    line(&mut out, &header);
    if md {
        out.push('|');
        for (&w, c) in widths.iter().zip(cols) {
            out.push(' ');
            out.extend(std::iter::repeat_n('-', if c.right { w - 1 } else { w }));
            if c.right {
                out.push(':');
            }
            out.push_str(" |");
        }
        out.push('\n');
    } else {
        let total = widths.iter().sum::<usize>() + 2 * widths.len().saturating_sub(1);
        out.extend(std::iter::repeat_n('-', total));
        out.push('\n');
    }
    for r in &rows {
        line(&mut out, r);
    }
    out
}

/// A CSV field (RFC 4180): quoted, with doubled quotes, when it holds a comma, a quote or a
/// line break; as is otherwise. The one CSV quoting of the project (tables, exports, impacts).
pub fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// About four significant digits for reading (at least one decimal between 1e-3 and 1e6,
/// scientific notation outside): `1234.5`, `12.35`, `0.1235`, `2.000e-5`.
pub(crate) fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        format!("{v}")
    } else if v == 0.0 {
        "0".to_string()
    } else if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(1, 6) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.3e}")
    }
}

/// Like [`fmt_num`] without trailing zeros (`2e-5`, `0.25`, `1000`): parameter values and
/// axis ticks.
pub(crate) fn fmt_short(v: f64) -> String {
    let s = fmt_num(v);
    let (mantissa, exp) = match s.find('e') {
        Some(i) => s.split_at(i),
        None => (s.as_str(), ""),
    };
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    format!("{mantissa}{exp}")
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
mod tests;
