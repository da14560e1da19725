//! Tabulated drive histories: a small CSV reader for `drive.file`, and the measured series a
//! fit reads ([`read_columns`]).
//!
//! The file has a header row naming its columns; the two columns used are found by name
//! (`time_s` and `speed_rad_s` or `torque_n_m`), other columns are ignored. Fields are
//! separated by commas; blank lines and lines starting with `#` are skipped; quoting is not
//! supported (the file holds numbers only). Times are in s and must increase strictly; the
//! table is held constant beyond its ends ([`clutchpack_model::Table`]).

use clutchpack_model::{Table, TableError};
use std::path::Path;

/// One row of a CSV file: its 1-based line number and its fields.
type Row<'t> = (usize, Vec<&'t str>);

/// The header row's fields and the rows after it, as (1-based line number, fields), of CSV
/// text: blank lines and lines starting with `#` skipped, fields split at commas and trimmed.
/// `shown` names the file in the message of an empty file.
fn header_and_rows<'t>(
    text: &'t str,
    shown: &str,
) -> Result<(Vec<&'t str>, impl Iterator<Item = Row<'t>>), String> {
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .map(|(n, l)| (n, l.split(',').map(str::trim).collect::<Vec<_>>()));
    let (_, header) = rows
        .next()
        .ok_or_else(|| format!("{shown}: empty file (expected a header row)"))?;
    Ok((header, rows))
}

/// The index of column `name` in `header`, else a message naming the file and the columns found.
fn column_of(header: &[&str], name: &str, shown: &str) -> Result<usize, String> {
    header.iter().position(|h| *h == name).ok_or_else(|| {
        format!(
            "{shown}: no column {name:?} in the header row (found: {})",
            header.join(", ")
        )
    })
}

/// Reads columns `time_s` and `value_column` of the CSV file at `path` into a table whose
/// values lie within `range` (the plausibility bound of the key the column stands for: a row
/// of 1e300 N m would pass as finite and make the run take hours or diverge).
/// `shown` is the file name used in messages (as written in the scene). The error is a
/// one-line message naming the file and, where it applies, the line.
pub(crate) fn read_table(
    path: &Path,
    shown: &str,
    value_column: &str,
    range: (f64, f64),
) -> Result<Table, String> {
    let text =
        crate::read_input(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    parse_table(&text, shown, value_column, range)
}

/// Parses CSV text (see [`read_table`]).
pub(crate) fn parse_table(
    text: &str,
    shown: &str,
    value_column: &str,
    (lo, hi): (f64, f64),
) -> Result<Table, String> {
    let (header, rows) = header_and_rows(text, shown)?;
    let column = |name: &str| column_of(&header, name, shown);
    let (it, iy) = (column("time_s")?, column(value_column)?);
    let (mut t, mut y, mut lines) = (Vec::new(), Vec::new(), Vec::new());
    for (line, fields) in rows {
        let field = |i: usize, name: &str| -> Result<f64, String> {
            let f = fields
                .get(i)
                .ok_or_else(|| format!("{shown}: line {line}: no value in column {name:?}"))?;
            f.parse::<f64>()
                .map_err(|_| format!("{shown}: line {line}: {name} = {f:?} is not a number"))
        };
        t.push(field(it, "time_s")?);
        let v = field(iy, value_column)?;
        if v.is_finite() && !(lo..=hi).contains(&v) {
            return Err(format!(
                "{shown}: line {line}: {value_column} = {} is outside [{}, {}] (plausibility \
                 bound of the key it stands for)",
                crate::schema::fmt_num(v),
                crate::schema::fmt_num(lo),
                crate::schema::fmt_num(hi),
            ));
        }
        y.push(v);
        lines.push(line);
    }
    Table::new(t, y).map_err(|e| match e {
        TableError::NotFinite(i) => format!("{shown}: line {}: value is not finite", lines[i]),
        TableError::NotIncreasing(i, ts) => format!(
            "{shown}: line {}: time {ts} s does not increase over the row before",
            lines[i]
        ),
        other => format!("{shown}: {other}"),
    })
}

/// Columns of a CSV file read by name: the time column and the value columns asked for, in
/// the order asked.
#[derive(Debug, Clone, PartialEq)]
pub struct Columns {
    /// The time column, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Each asked column's values (finite), one per time.
    pub values: Vec<Vec<f64>>,
}

/// Reads the columns `time_column` and `columns` of the CSV file at `path` (the format of
/// `drive.file`: a header row, commas, `#` comments), every value finite and the times
/// strictly increasing, at least 2 rows. The error is a one-line message naming the file,
/// the column and, where it applies, the line.
pub fn read_columns(path: &Path, time_column: &str, columns: &[&str]) -> Result<Columns, String> {
    let text =
        crate::read_input(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    parse_columns(&text, &path.display().to_string(), time_column, columns)
}

/// Parses CSV text (see [`read_columns`]); `shown` names the file in messages.
pub fn parse_columns(
    text: &str,
    shown: &str,
    time_column: &str,
    columns: &[&str],
) -> Result<Columns, String> {
    let (header, rows) = header_and_rows(text, shown)?;
    let column = |name: &str| column_of(&header, name, shown);
    let it = column(time_column)?;
    let idx = columns
        .iter()
        .map(|c| column(c))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = Columns {
        time_s: Vec::new(),
        values: vec![Vec::new(); columns.len()],
    };
    for (line, fields) in rows {
        let field = |i: usize, name: &str| -> Result<f64, String> {
            let f = fields
                .get(i)
                .ok_or_else(|| format!("{shown}: line {line}: no value in column {name:?}"))?;
            let x = f
                .parse::<f64>()
                .map_err(|_| format!("{shown}: line {line}: {name} = {f:?} is not a number"))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("{shown}: line {line}: {name} = {f} is not finite"))
            }
        };
        let t = field(it, time_column)?;
        if let Some(&before) = out.time_s.last() {
            if t <= before {
                return Err(format!(
                    "{shown}: line {line}: {time_column} = {t} does not increase over the row \
                     before ({before})"
                ));
            }
        }
        out.time_s.push(t);
        for (k, (&i, name)) in idx.iter().zip(columns).enumerate() {
            out.values[k].push(field(i, name)?);
        }
    }
    if out.time_s.len() < 2 {
        return Err(format!("{shown}: at least 2 rows of data needed"));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ANY: (f64, f64) = (f64::MIN, f64::MAX);

    #[test]
    fn reads_named_columns_and_skips_comments() {
        let t = parse_table(
            "# a comment\nspeed_rad_s, time_s\n200, 0\n\n210, 0.1\n",
            "d.csv",
            "speed_rad_s",
            ANY,
        )
        .unwrap();
        assert_eq!(t.t_s, [0.0, 0.1]);
        assert_eq!(t.y, [200.0, 210.0]);
    }

    #[test]
    fn columns_are_read_by_name_and_checked() {
        let c = parse_columns("t,a,b\n0,1,2\n0.5,3,4\n", "m.csv", "t", &["b", "a"]).unwrap();
        assert_eq!(c.time_s, [0.0, 0.5]);
        assert_eq!(c.values, [vec![2.0, 4.0], vec![1.0, 3.0]]);
        let e = parse_columns("t,a\n0,1\n0,2\n", "m.csv", "t", &["a"]).unwrap_err();
        assert!(
            e.contains("line 3") && e.contains("does not increase"),
            "{e}"
        );
        let e = parse_columns("t,a\n0,1\n1,NaN\n", "m.csv", "t", &["a"]).unwrap_err();
        assert!(e.contains("line 3") && e.contains("not finite"), "{e}");
        let e = parse_columns("t,a\n0,1\n1,2\n", "m.csv", "t", &["J1"]).unwrap_err();
        assert!(e.contains("no column \"J1\""), "{e}");
    }

    #[test]
    fn errors_name_file_and_line() {
        let e =
            parse_table("time_s,torque_n_m\n0,1\n0,2\n", "d.csv", "torque_n_m", ANY).unwrap_err();
        assert_eq!(
            e,
            "d.csv: line 3: time 0 s does not increase over the row before"
        );
        let e = parse_table("time_s,torque_n_m\n0,x\n", "d.csv", "torque_n_m", ANY).unwrap_err();
        assert!(e.contains("line 2") && e.contains("\"x\""), "{e}");
        let e = parse_table("time_s,speed\n0,1\n", "d.csv", "speed_rad_s", ANY).unwrap_err();
        assert!(e.contains("no column \"speed_rad_s\""), "{e}");
        let e = parse_table("time_s,speed_rad_s\n0,1\n", "d.csv", "speed_rad_s", ANY).unwrap_err();
        assert!(e.contains("at least 2 rows"), "{e}");
        let e = parse_table(
            "time_s,speed_rad_s\n0,1\n1,nan\n",
            "d.csv",
            "speed_rad_s",
            ANY,
        )
        .unwrap_err();
        assert_eq!(e, "d.csv: line 3: value is not finite");
    }

    /// A row beyond the bound of the key its column stands for is refused at its line (issue
    /// 48's reproducer: a torque row of 1e300 N m passed as finite).
    #[test]
    fn rows_beyond_the_keys_bound_are_refused_at_their_line() {
        let text = "time_s,torque_n_m\n0,1\n1,1e300\n";
        let e = parse_table(text, "d.csv", "torque_n_m", (-1e7, 1e7)).unwrap_err();
        assert!(
            e.starts_with("d.csv: line 3: torque_n_m = 1e300 is outside"),
            "{e}"
        );
        assert!(parse_table(text, "d.csv", "torque_n_m", ANY).is_ok());
    }
}
