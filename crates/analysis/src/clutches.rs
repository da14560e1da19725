//! Comparing the clutches of several runs of one driveline network (MODEL.md section 8): per
//! run and clutch (a lumped clutch or a resolved pack) its heat, its first lock, its largest
//! torque, with the changes against the first run, and which clutch of which run takes the
//! most heat; per run and disc or plate of a resolved pack its impacts and largest peak, and
//! which one is hit hardest. `clutchpack compare` of network recordings prints it.

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

/// One disc or plate of a resolved pack in one run, as its run's summary gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct PackBodyRun {
    /// `<pack>/<disc or plate>`.
    pub name: String,
    /// Its tooth impacts over the run.
    pub impacts: u64,
    /// Its largest |peak| per tooth, N.
    pub peak_abs_n: f64,
}

impl PackBodyRun {
    /// The pack bodies of a run from its tooth impacts (a recording cut short, whose summary
    /// was never written): each `(name, impact)` named `<pack>/discs/<disc>` or
    /// `<pack>/plates/<plate>` (the recording's names) counted under `<pack>/<disc or plate>`
    /// (the summary's), with its largest |peak|; the packs in the order of `couplings` (the
    /// run's couplings' names), each pack's discs before its plates, each in the order of its
    /// first impact. A gear mesh's impacts (no pack) are not a pack body's.
    pub fn from_impacts(
        couplings: &[String],
        impacts: &[(String, clutchpack_model::ImpactEvent)],
    ) -> Vec<PackBodyRun> {
        let mut out: Vec<((usize, bool), PackBodyRun)> = Vec::new();
        for (name, e) in impacts {
            let mut parts = name.splitn(3, '/');
            let (Some(pack), Some(role), Some(body)) = (parts.next(), parts.next(), parts.next())
            else {
                continue;
            };
            let name = format!("{pack}/{body}");
            let order = (
                couplings
                    .iter()
                    .position(|c| c == pack)
                    .unwrap_or(usize::MAX),
                role == "plates",
            );
            match out.iter_mut().find(|(_, b)| b.name == name) {
                Some((_, b)) => {
                    b.impacts += 1;
                    b.peak_abs_n = b.peak_abs_n.max(e.peak_n.abs());
                }
                None => out.push((
                    order,
                    PackBodyRun {
                        name,
                        impacts: 1,
                        peak_abs_n: e.peak_n.abs(),
                    },
                )),
            }
        }
        out.sort_by_key(|(order, _)| *order);
        out.into_iter().map(|(_, b)| b).collect()
    }
}

/// One (run, pack body) row of the comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PackBodyCompareRow {
    /// The run (its file).
    pub run: String,
    /// `<pack>/<disc or plate>`.
    pub body: String,
    /// Its tooth impacts over the run.
    pub impacts: u64,
    /// Its largest |peak| per tooth, N.
    pub peak_abs_n: f64,
    /// Change of the largest |peak| against the first run's same body, per cent.
    pub peak_change_pct: Option<f64>,
}

/// The rows of `runs` (run name, its packs' bodies), each body against the first run's body
/// of the same name.
pub fn pack_body_compare_rows(runs: &[(String, Vec<PackBodyRun>)]) -> Vec<PackBodyCompareRow> {
    let first = runs.first().map(|(_, b)| b.as_slice()).unwrap_or_default();
    runs.iter()
        .flat_map(|(run, bodies)| {
            bodies.iter().map(move |b| PackBodyCompareRow {
                run: run.clone(),
                body: b.name.clone(),
                impacts: b.impacts,
                peak_abs_n: b.peak_abs_n,
                peak_change_pct: first
                    .iter()
                    .find(|f| f.name == b.name)
                    .and_then(|f| pct(b.peak_abs_n, f.peak_abs_n)),
            })
        })
        .collect()
}

/// The row of the body hit hardest (the largest |peak| per tooth; the first of equals), if
/// any.
pub fn hardest_hit(rows: &[PackBodyCompareRow]) -> Option<&PackBodyCompareRow> {
    rows.iter()
        .fold(None, |best: Option<&PackBodyCompareRow>, r| match best {
            Some(b) if b.peak_abs_n >= r.peak_abs_n => Some(b),
            _ => Some(r),
        })
}

/// The row whose largest |peak| changed most against the first run (in magnitude, per cent;
/// the first of equals), if any changed.
pub fn largest_peak_change(rows: &[PackBodyCompareRow]) -> Option<&PackBodyCompareRow> {
    let m = |x: &PackBodyCompareRow| x.peak_change_pct.unwrap_or(0.0).abs();
    rows.iter()
        .filter(|r| m(r) > 0.0)
        .fold(None, |best: Option<&PackBodyCompareRow>, r| match best {
            Some(b) if m(b) >= m(r) => Some(b),
            _ => Some(r),
        })
}

/// The packs' bodies as a table. Columns (text and markdown): `run`, `pack body`,
/// `impacts`, `max |peak| [N]`, `change`; CSV: the [`PackBodyCompareRow`] field names.
pub fn pack_body_compare_table(rows: &[PackBodyCompareRow], format: TableFormat) -> String {
    if format == TableFormat::Csv {
        let mut out = String::from("run,body,impacts,peak_abs_n,peak_change_pct\n");
        for r in rows {
            let _ = writeln!(
                out,
                "{},{},{},{:?},{}",
                csv_field(&r.run),
                csv_field(&r.body),
                r.impacts,
                r.peak_abs_n,
                r.peak_change_pct
                    .map(|v| format!("{v:?}"))
                    .unwrap_or_default()
            );
        }
        return out;
    }
    let cols = vec![
        col("run", false),
        col("pack body", false),
        col("impacts", true),
        col("max |peak| [N]", true),
        col("change", true),
    ];
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.run.clone(),
                r.body.clone(),
                r.impacts.to_string(),
                fmt_num(r.peak_abs_n),
                r.peak_change_pct
                    .map_or_else(|| "-".to_string(), |p| format!("{p:+.1} %")),
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

    /// Each pack body against the first run's of the same name; the hardest hit is found.
    #[test]
    fn pack_bodies_compare_with_the_first_runs() {
        let body = |name: &str, impacts: u64, peak: f64| PackBodyRun {
            name: name.into(),
            impacts,
            peak_abs_n: peak,
        };
        let runs = vec![
            (
                "slow".to_string(),
                vec![body("K2/disc-1", 8, 30.0), body("K2/plate-1", 9, 10.0)],
            ),
            (
                "fast".to_string(),
                vec![body("K2/disc-1", 7, 45.0), body("K2/plate-1", 9, 5.0)],
            ),
        ];
        let rows = pack_body_compare_rows(&runs);
        assert_eq!(rows.len(), 4);
        assert!((rows[2].peak_change_pct.unwrap() - 50.0).abs() < 1e-12);
        assert!((rows[3].peak_change_pct.unwrap() + 50.0).abs() < 1e-12);
        let h = hardest_hit(&rows).unwrap();
        assert_eq!((h.run.as_str(), h.body.as_str()), ("fast", "K2/disc-1"));
        // +50 % and -50 %: the first of equals
        let c = largest_peak_change(&rows).unwrap();
        assert_eq!((c.run.as_str(), c.body.as_str()), ("fast", "K2/disc-1"));
        let text = pack_body_compare_table(&rows, TableFormat::Text);
        assert!(
            text.contains("+50.0 %") && text.contains("pack body"),
            "{text}"
        );
        assert_eq!(
            pack_body_compare_table(&rows, TableFormat::Csv)
                .lines()
                .count(),
            5
        );
    }
}
