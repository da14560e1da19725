//! Tests of the tables: their formats, their columns and units, and `render` against the
//! cell-by-cell formatting it replaced.

use super::*;
use crate::sweep::{sweep_rows, SweepCase};

/// The formatting `render` replaced, cell by cell and line by line: the reference its output
/// must equal.
fn render_formatted(format: TableFormat, cols: &[Col], rows: &[Vec<String>]) -> String {
    let escape = |s: &str| match format {
        TableFormat::Markdown => s.replace('|', "\\|"),
        _ => s.to_string(),
    };
    let header: Vec<String> = cols.iter().map(|c| escape(&c.header)).collect();
    let rows: Vec<Vec<String>> = rows
        .iter()
        .map(|r| r.iter().map(|s| escape(s)).collect())
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
    let pad = |s: &str, i: usize| {
        let fill = " ".repeat(widths[i] - width(s));
        if cols[i].right {
            format!("{fill}{s}")
        } else {
            format!("{s}{fill}")
        }
    };
    let line = |cells: &[String]| -> String {
        let padded: Vec<String> = cells.iter().enumerate().map(|(i, s)| pad(s, i)).collect();
        match format {
            TableFormat::Markdown => format!("| {} |\n", padded.join(" | ")),
            _ => format!("{}\n", padded.join("  ").trim_end()),
        }
    };
    let mut out = line(&header);
    match format {
        TableFormat::Markdown => {
            let rules: Vec<String> = widths
                .iter()
                .zip(cols)
                .map(|(&w, c)| {
                    if c.right {
                        format!("{}:", "-".repeat(w - 1))
                    } else {
                        "-".repeat(w)
                    }
                })
                .collect();
            let _ = writeln!(out, "| {} |", rules.join(" | "));
        }
        _ => {
            let total = widths.iter().sum::<usize>() + 2 * widths.len().saturating_sub(1);
            let _ = writeln!(out, "{}", "-".repeat(total));
        }
    }
    for r in &rows {
        out.push_str(&line(r));
    }
    out
}

/// `render` equals the cell-by-cell formatting it replaced, byte for byte, in text and
/// markdown: left and right columns, a cell wider than its header, an empty cell, a cell
/// that is all spaces (a text line's trailing spaces trimmed), a `|` (escaped in markdown),
/// multi-byte characters (widths in characters) and a column narrower than 3.
#[test]
fn render_writes_what_the_formatting_wrote() {
    let cols = [
        col("name", false),
        col("max + [N]", true),
        col("x", true),
        col("note", false),
    ];
    let rows: Vec<Vec<String>> = [
        ["disc 1", "1234.5", "1", "a | b"],
        ["plate éé", "-250", "", "   "],
        ["", "20", "123456", "°C"],
    ]
    .iter()
    .map(|r| r.iter().map(|s| s.to_string()).collect())
    .collect();
    for format in [TableFormat::Text, TableFormat::Markdown] {
        for n in 0..=rows.len() {
            let (a, b) = (
                render(format, &cols, &rows[..n]),
                render_formatted(format, &cols, &rows[..n]),
            );
            assert_eq!(a, b, "{format:?}, {n} rows");
        }
    }
}

fn two_discs() -> Vec<DiscStats> {
    vec![
        DiscStats::from_peaks("disc 1", &[1234.5, -250.0, 20.0]),
        DiscStats::from_peaks("outer, 2", &[]),
    ]
}

/// Every format has the unit-carrying headers and the values.
#[test]
fn stats_table_formats() {
    let s = two_discs();
    let text = stats_table(&s, TableFormat::Text);
    assert!(text.contains("max + [N]"), "{text}");
    assert!(text.contains("max - [N]"));
    assert!(text.contains("p99 abs [N]"));
    assert!(text.contains("1234.5"));
    assert!(text.contains("-250.0"));
    // header, rule, two rows; all rows as wide as the rule at most
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4);
    assert!(lines[1].chars().all(|c| c == '-'));
    // the numeric columns are right-aligned: the header ends where the numbers end
    let end = lines[0].find("max + [N]").unwrap() + "max + [N]".len();
    assert_eq!(&lines[2][end - 6..end], "1234.5");

    let md = stats_table(&s, TableFormat::Markdown);
    let lines: Vec<&str> = md.lines().collect();
    assert!(lines[0].starts_with("| disc"));
    assert!(lines[0].contains("| max + [N] |"));
    assert!(lines[1].starts_with("| ---") && lines[1].contains("-:"));
    assert!(lines[2].contains("| disc 1"));

    let csv = stats_table(&s, TableFormat::Csv);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "disc,max_positive_n,max_negative_n,p99_abs_n,mean_top10_abs_n,impacts,positive_impacts,negative_impacts"
    );
    assert!(lines[1].starts_with("disc 1,1234.5,-250.0,"));
    assert!(lines[1].ends_with(",3,2,1"));
    assert_eq!(lines[2], "\"outer, 2\",0.0,0.0,0.0,0.0,0,0,0");
}

/// No rows: the header alone, no panic.
#[test]
fn empty_tables() {
    for f in [TableFormat::Text, TableFormat::Markdown, TableFormat::Csv] {
        assert!(stats_table(&[], f).contains("impacts"));
        assert!(sweep_table("backlash_m", &[], f).contains("backlash_m"));
    }
}

/// Sweeps: single runs show plain values; ensembles add members, mean ± std and ranges;
/// CSV always has every column.
#[test]
fn sweep_table_formats() {
    let single = sweep_rows(&[SweepCase {
        value: 20e-6,
        members: vec![two_discs()],
    }]);
    let text = sweep_table("backlash [m]", &single, TableFormat::Text);
    assert!(text.starts_with("backlash [m]"));
    assert!(text.contains("2e-5"), "{text}");
    assert!(!text.contains('±') && !text.contains("members"));

    let ens = sweep_rows(&[SweepCase {
        value: 20e-6,
        members: vec![
            vec![DiscStats::from_peaks("d", &[100.0, -50.0])],
            vec![DiscStats::from_peaks("d", &[300.0, -70.0])],
        ],
    }]);
    let md = sweep_table("backlash_m", &ens, TableFormat::Markdown);
    assert!(md.contains("| members |"), "{md}");
    assert!(md.contains("max + range [N]"));
    assert!(md.contains("200.0 ± 141.4"));
    assert!(md.contains("100.0 .. 300.0"));
    assert!(md.contains("-60.00 ± 14.14"));

    let csv = sweep_table("backlash_m", &ens, TableFormat::Csv);
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with("backlash_m,disc,members,max_positive_mean_n,max_positive_std_n"));
    assert!(lines[0].ends_with("impacts_mean,impacts_std,impacts_min,impacts_max"));
    assert_eq!(lines[0].split(',').count(), lines[1].split(',').count());
    assert!(lines[1].starts_with("2e-5,d,2,200.0,"));
}

/// Number formatting for reading.
#[test]
fn number_formats() {
    assert_eq!(fmt_num(1234.5), "1234.5");
    assert_eq!(fmt_num(12.345), "12.35");
    assert_eq!(fmt_num(-0.12345), "-0.1235");
    assert_eq!(fmt_num(0.0), "0");
    assert_eq!(fmt_num(2e-5), "2.000e-5");
    assert_eq!(fmt_num(2.5e7), "2.500e7");
    assert_eq!(fmt_short(2e-5), "2e-5");
    assert_eq!(fmt_short(2.5e-5), "2.5e-5");
    assert_eq!(fmt_short(1000.0), "1000");
    assert_eq!(fmt_short(0.25), "0.25");
}
