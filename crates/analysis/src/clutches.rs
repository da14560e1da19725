//! Comparing the clutches of several runs of one driveline network (MODEL.md section 8): per
//! run and clutch its heat, its first lock, its largest torque, with the changes against the
//! first run, and which clutch of which run takes the most heat. `clutchpack compare` of
//! network recordings prints it.

use crate::table::{col, csv_field, fmt_num, render, TableFormat};
use serde::Serialize;
use std::fmt::Write as _;

/// One clutch of one run, as its run's summary gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct ClutchRun {
    /// The clutch's name.
    pub name: String,
    /// Heat over the run, J.
    pub heat_j: f64,
    /// Its first lock, s (`None`: it never locked).
    pub first_lock_s: Option<f64>,
    /// Its largest torque on its body a over the samples, `max |tau|`, N m.
    pub max_abs_torque_n_m: f64,
}

/// One (run, clutch) row of the comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClutchCompareRow {
    /// The run (its file).
    pub run: String,
    /// The clutch.
    pub clutch: String,
    /// Heat over the run, J.
    pub heat_j: f64,
    /// Change of the heat against the first run's same clutch, per cent.
    pub heat_change_pct: Option<f64>,
    /// Its first lock, s.
    pub first_lock_s: Option<f64>,
    /// Its first lock less the first run's, s.
    pub lock_shift_s: Option<f64>,
    /// Its largest |torque|, N m.
    pub max_abs_torque_n_m: f64,
    /// Change of the largest |torque| against the first run's, per cent.
    pub torque_change_pct: Option<f64>,
}

fn pct(new: f64, old: f64) -> Option<f64> {
    (old != 0.0).then(|| 100.0 * (new - old) / old)
}

/// The rows of `runs` (run name, its clutches), each clutch against the first run's clutch of
/// the same name.
pub fn clutch_compare_rows(runs: &[(String, Vec<ClutchRun>)]) -> Vec<ClutchCompareRow> {
    let first = runs.first().map(|(_, c)| c.as_slice()).unwrap_or_default();
    runs.iter()
        .flat_map(|(run, clutches)| {
            clutches.iter().map(move |c| {
                let base = first.iter().find(|b| b.name == c.name);
                ClutchCompareRow {
                    run: run.clone(),
                    clutch: c.name.clone(),
                    heat_j: c.heat_j,
                    heat_change_pct: base.and_then(|b| pct(c.heat_j, b.heat_j)),
                    first_lock_s: c.first_lock_s,
                    lock_shift_s: base
                        .and_then(|b| b.first_lock_s)
                        .zip(c.first_lock_s)
                        .map(|(b, n)| n - b),
                    max_abs_torque_n_m: c.max_abs_torque_n_m,
                    torque_change_pct: base
                        .and_then(|b| pct(c.max_abs_torque_n_m, b.max_abs_torque_n_m)),
                }
            })
        })
        .collect()
}

/// The row whose clutch takes the most heat (the one that suffers most), if any.
pub fn hottest_clutch(rows: &[ClutchCompareRow]) -> Option<&ClutchCompareRow> {
    rows.iter().max_by(|a, b| a.heat_j.total_cmp(&b.heat_j))
}

/// The comparison as a table. Columns (text and markdown): `run`, `clutch`, `heat [J]`,
/// `change`, `first lock [s]`, `shift [s]`, `max |torque| [N m]`, `change`; CSV: the
/// [`ClutchCompareRow`] field names.
pub fn clutch_compare_table(rows: &[ClutchCompareRow], format: TableFormat) -> String {
    let o = |x: Option<f64>| x.map(|v| format!("{v:?}")).unwrap_or_default();
    if format == TableFormat::Csv {
        let mut out = String::from(
            "run,clutch,heat_j,heat_change_pct,first_lock_s,lock_shift_s,max_abs_torque_n_m,torque_change_pct\n",
        );
        for r in rows {
            let _ = writeln!(
                out,
                "{},{},{:?},{},{},{},{:?},{}",
                csv_field(&r.run),
                csv_field(&r.clutch),
                r.heat_j,
                o(r.heat_change_pct),
                o(r.first_lock_s),
                o(r.lock_shift_s),
                r.max_abs_torque_n_m,
                o(r.torque_change_pct)
            );
        }
        return out;
    }
    let change = |p: Option<f64>| p.map_or_else(|| "-".to_string(), |p| format!("{p:+.1} %"));
    let cols = vec![
        col("run", false),
        col("clutch", false),
        col("heat [J]", true),
        col("change", true),
        col("first lock [s]", true),
        col("shift [s]", true),
        col("max |torque| [N m]", true),
        col("change", true),
    ];
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.run.clone(),
                r.clutch.clone(),
                fmt_num(r.heat_j),
                change(r.heat_change_pct),
                r.first_lock_s
                    .map_or_else(|| "never".to_string(), |t| format!("{t:.6}")),
                r.lock_shift_s
                    .map_or_else(|| "-".to_string(), |d| format!("{d:+.6}")),
                fmt_num(r.max_abs_torque_n_m),
                change(r.torque_change_pct),
            ]
        })
        .collect();
    render(format, &cols, &cells)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clutch(name: &str, heat: f64, lock: Option<f64>, torque: f64) -> ClutchRun {
        ClutchRun {
            name: name.into(),
            heat_j: heat,
            first_lock_s: lock,
            max_abs_torque_n_m: torque,
        }
    }

    /// Each clutch against the first run's of the same name: the heat's and torque's changes
    /// in per cent, the lock's shift in s; the hottest clutch is found; a clutch the first run
    /// lacks has no change.
    #[test]
    fn rows_compare_each_clutch_with_the_first_runs() {
        let runs = vec![
            (
                "slow".to_string(),
                vec![
                    clutch("K1", 2.0, None, 300.0),
                    clutch("K2", 10000.0, Some(0.575), 400.0),
                ],
            ),
            (
                "fast".to_string(),
                vec![
                    clutch("K1", 1.0, None, 300.0),
                    clutch("K2", 12000.0, Some(0.5), 500.0),
                    clutch("K3", 5.0, None, 1.0),
                ],
            ),
        ];
        let rows = clutch_compare_rows(&runs);
        assert_eq!(rows.len(), 5);
        let k2 = &rows[3];
        assert_eq!((k2.run.as_str(), k2.clutch.as_str()), ("fast", "K2"));
        assert!((k2.heat_change_pct.unwrap() - 20.0).abs() < 1e-12);
        assert!((k2.lock_shift_s.unwrap() + 0.075).abs() < 1e-12);
        assert!((k2.torque_change_pct.unwrap() - 25.0).abs() < 1e-12);
        assert_eq!(rows[4].heat_change_pct, None);
        assert_eq!(rows[0].lock_shift_s, None);
        assert_eq!(hottest_clutch(&rows).map(|r| r.run.as_str()), Some("fast"));
        let text = clutch_compare_table(&rows, TableFormat::Text);
        assert!(text.contains("+20.0 %") && text.contains("never"), "{text}");
        let csv = clutch_compare_table(&rows, TableFormat::Csv);
        assert_eq!(csv.lines().count(), 6);
    }
}
