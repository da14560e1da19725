//! `export --csv DIR`: one CSV file per topic of ours (see [`export_csv`]).

use crate::read::{ReadError, RecordingReader};
use clutchpack_analysis::csv_field;
use clutchpack_model::Flank;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Writes one CSV file per topic of ours into `dir` (created if missing) and returns their
/// paths.
///
/// | file | topic | columns |
/// | --- | --- | --- |
/// | `shaft.csv` | `/shaft` | `t_s,angle_rad,speed_rad_s` |
/// | `spline_<segment>.csv` | `/discs/<segment>/spline` | `t_s,rel_angle_rad,closing_speed_m_s,penetration_m,load_n,torque_n_m,engaged,stiffness_n_m1_5,speed_rad_s,angle_rad` |
/// | `load_<segment>.csv` | `/discs/<segment>/load` | `t_s,load_n,rel_angle_rad,contact_step` |
/// | `teeth_<segment>.csv` | `/discs/<segment>/teeth` | `t_s,tooth_0_n,tooth_1_n,...` |
/// | `interface_<segment>.csv` | `/interfaces/<segment>` | `t_s,slip_rad_s,slip_m_s,mu,clamp_n,torque_n_m,locked,dissipated_j` |
/// | `impacts.csv` | `/impacts` | `disc,disc_index,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n` |
/// | `summary.csv` | `/summary` | `disc,max_positive_n,max_negative_n,p99_abs_n,impacts,positive_impacts,negative_impacts,mean_top10_abs_n` |
///
/// Numbers are written in Rust's shortest round-trip form (read back exactly); `engaged` is
/// 0 or 1, as are `locked` and `contact_step`; `flank` is `shaft_leads` or `disc_leads`. `summary.csv` holds the stored summary,
/// or for a run that did not finish the one recomputed from the recovered impacts.
/// Files of topics without messages are not written (but for the shaft, impacts and summary).
pub fn export_csv(
    reader: &RecordingReader,
    dir: impl AsRef<Path>,
) -> Result<Vec<PathBuf>, ReadError> {
    export_csv_until(reader, dir, &AtomicBool::new(false))
}

/// [`export_csv`] that stops before the next file once `stop` is set (a signal): the files
/// written until then are complete (each is written whole) and returned.
pub fn export_csv_until(
    reader: &RecordingReader,
    dir: impl AsRef<Path>,
    stop: &AtomicBool,
) -> Result<Vec<PathBuf>, ReadError> {
    let dir = dir.as_ref();
    std::fs::create_dir_all(dir).map_err(|source| ReadError::Export {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut written = Vec::new();
    let mut put = |name: &str, text: String| -> Result<(), ReadError> {
        if stop.load(Ordering::SeqCst) {
            return Ok(());
        }
        let path = dir.join(name);
        // whole or not at all: a temporary sibling renamed into place
        crate::output::write_whole(&path, text.as_bytes()).map_err(|source| ReadError::Export {
            path: path.clone(),
            source,
        })?;
        written.push(path);
        Ok(())
    };

    let mut s = String::from("t_s,angle_rad,speed_rad_s\n");
    for m in reader.shaft_states() {
        let _ = writeln!(s, "{:?},{:?},{:?}", m.t_s, m.angle_rad, m.speed_rad_s);
    }
    put("shaft.csv", s)?;

    for d in reader.disc_series() {
        if !d.states.is_empty() {
            let mut s = String::from(
                "t_s,rel_angle_rad,closing_speed_m_s,penetration_m,load_n,torque_n_m,engaged,stiffness_n_m1_5,speed_rad_s,angle_rad\n",
            );
            for m in &d.states {
                let _ = writeln!(
                    s,
                    "{:?},{:?},{:?},{:?},{:?},{:?},{},{:?},{:?},{:?}",
                    m.t_s,
                    m.rel_angle_rad,
                    m.closing_speed_m_s,
                    m.penetration_m,
                    m.load_n,
                    m.torque_n_m,
                    u8::from(m.engaged),
                    m.stiffness_n_m1_5,
                    m.speed_rad_s,
                    m.angle_rad
                );
            }
            put(&format!("spline_{}.csv", d.segment), s)?;
        }
        if !d.teeth.is_empty() {
            let n = d.teeth.iter().map(|t| t.loads_n.len()).max().unwrap_or(0);
            let mut s = String::from("t_s");
            for i in 0..n {
                let _ = write!(s, ",tooth_{i}_n");
            }
            s.push('\n');
            for t in &d.teeth {
                let _ = write!(s, "{:?}", t.t_s);
                for i in 0..n {
                    match t.loads_n.get(i) {
                        Some(x) => {
                            let _ = write!(s, ",{x:?}");
                        }
                        None => s.push(','),
                    }
                }
                s.push('\n');
            }
            put(&format!("teeth_{}.csv", d.segment), s)?;
        }
    }

    let segments: std::collections::BTreeMap<usize, String> = reader
        .disc_series()
        .into_iter()
        .map(|d| (d.index, d.segment))
        .collect();
    for (i, series) in reader.dense_loads().iter().enumerate() {
        let Some(segment) = segments.get(&i).filter(|_| !series.is_empty()) else {
            continue;
        };
        let mut s = String::from("t_s,load_n,rel_angle_rad,contact_step\n");
        for m in series {
            let _ = writeln!(
                s,
                "{:?},{:?},{:?},{}",
                m.t_s,
                m.load_n,
                m.rel_angle_rad,
                u8::from(m.contact_step)
            );
        }
        put(&format!("load_{segment}.csv"), s)?;
    }

    for f in reader.interface_series() {
        if f.states.is_empty() {
            continue;
        }
        let mut s =
            String::from("t_s,slip_rad_s,slip_m_s,mu,clamp_n,torque_n_m,locked,dissipated_j\n");
        for m in &f.states {
            let _ = writeln!(
                s,
                "{:?},{:?},{:?},{:?},{:?},{:?},{},{:?}",
                m.t_s,
                m.slip_rad_s,
                m.slip_m_s,
                m.mu,
                m.clamp_n,
                m.torque_n_m,
                u8::from(m.locked),
                m.dissipated_j
            );
        }
        put(&format!("interface_{}.csv", f.segment), s)?;
    }

    let names = reader.disc_names();
    let mut s = String::from("disc,disc_index,t_on_s,t_peak_s,t_off_s,flank,v_on_m_s,peak_n\n");
    for e in reader.impacts() {
        let name = names
            .get(e.disc)
            .cloned()
            .unwrap_or_else(|| format!("disc {}", e.disc));
        let flank = match e.flank {
            Flank::ShaftLeads => "shaft_leads",
            Flank::DiscLeads => "disc_leads",
        };
        let _ = writeln!(
            s,
            "{},{},{:?},{:?},{:?},{flank},{:?},{:?}",
            csv_field(&name),
            e.disc,
            e.t_on_s,
            e.t_peak_s,
            e.t_off_s,
            e.v_on_m_s,
            e.peak_n
        );
    }
    put("impacts.csv", s)?;

    let mut s = String::from(
        "disc,max_positive_n,max_negative_n,p99_abs_n,impacts,positive_impacts,negative_impacts,mean_top10_abs_n\n",
    );
    for d in reader.summary_or_recomputed().discs {
        let _ = writeln!(
            s,
            "{},{:?},{:?},{:?},{},{},{},{:?}",
            csv_field(&d.name),
            d.max_positive_n,
            d.max_negative_n,
            d.p99_abs_n,
            d.impacts,
            d.positive_impacts,
            d.negative_impacts,
            d.mean_top10_abs_n
        );
    }
    put("summary.csv", s)?;
    Ok(written)
}
