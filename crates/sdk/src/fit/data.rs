//! A fit's measured data: the columns of a CSV file (the format of `drive.file`), or the
//! series of an MCAP recording of a network scene (`clutchpack run --out`), named as the
//! fit's signals: `BODY.speed_rad_s`, `BODY.angle_rad`, `COUPLING.torque_n_m`.

use crate::{Error, Result};
use clutchpack_scene::Columns;
use std::path::Path;

/// Whether `path` names a recording (`.mcap`) rather than a CSV table.
pub(super) fn is_recording(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// The columns `columns` of the data at `path` against `row_column` (a CSV file's time or
/// variant column; a recording's sample times, s): every value finite, the rows strictly
/// increasing, at least 2. An error names the file and the column.
pub(super) fn read(path: &Path, row_column: &str, columns: &[&str]) -> Result<Columns> {
    let bad = |m: String| Error::BadInput(format!("fit data: {m}"));
    if !is_recording(path) {
        return clutchpack_scene::read_columns(path, row_column, columns).map_err(bad);
    }
    let (reader, damage) = crate::open_recording(path, false).map_err(|e| bad(e.to_string()))?;
    if let Some(d) = damage {
        return Err(bad(format!(
            "{d} (a damaged recording is not measured data: salvage it first)"
        )));
    }
    let Some(net) = clutchpack_record::read_network(&reader) else {
        return Err(bad(format!(
            "{}: a pack's recording is not read as measured data yet; export its series \
             (clutchpack export) and give the CSV file",
            path.display()
        )));
    };
    let net = net.map_err(|e| bad(format!("{}: {e}", path.display())))?;
    // the samples in strictly increasing time (an event's instant is sampled twice: the
    // first is kept, as a CSV of the history would keep it)
    let mut kept = Vec::new();
    for s in &net.samples {
        if kept
            .last()
            .is_none_or(|k: &&clutchpack_model::network::NetworkSample| s.t_s > k.t_s)
        {
            kept.push(s);
        }
    }
    let mut names = Vec::new();
    for b in &net.bodies {
        names.push(format!("{b}.speed_rad_s"));
        names.push(format!("{b}.angle_rad"));
    }
    names.extend(net.couplings.iter().map(|c| format!("{c}.torque_n_m")));
    let values = columns
        .iter()
        .map(|&c| {
            let c = if c.contains('.') {
                c.to_string()
            } else {
                format!("{c}.speed_rad_s")
            };
            let i = names.iter().position(|n| *n == c).ok_or_else(|| {
                bad(format!(
                    "{}: the recording has no series {c:?} (it has: {})",
                    path.display(),
                    names.join(", ")
                ))
            })?;
            let nb = net.bodies.len();
            Ok(kept
                .iter()
                .map(|s| {
                    if i < 2 * nb {
                        if i % 2 == 0 {
                            s.speed_rad_s[i / 2]
                        } else {
                            s.angle_rad[i / 2]
                        }
                    } else {
                        s.torque_n_m[i - 2 * nb]
                    }
                })
                .collect())
        })
        .collect::<Result<Vec<Vec<f64>>>>()?;
    if kept.len() < 2 {
        return Err(bad(format!(
            "{}: at least 2 samples needed",
            path.display()
        )));
    }
    Ok(Columns {
        time_s: kept.iter().map(|s| s.t_s).collect(),
        values,
    })
}
