//! Recordings read back from Python (`clutchpack.read`): a pack's (its summary, impacts and
//! load series) or a network's (its attached summary, the samples as the columns `run` gives,
//! every tooth impact of its packs), through the sdk's one policy for damaged files
//! (`clutchpack_sdk::open_recording`).

use crate::{py_err, ImpactColumns};
use clutchpack_sdk::Error;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};

/// What a recording holds, for the Python half.
#[pyclass(name = "RawRecording", module = "clutchpack", frozen, get_all)]
pub(crate) struct RawRecording {
    /// The summary (JSON text): scene, engine, duration, per-body statistics and fatigue.
    summary_json: String,
    /// The scene's TOML text and overrides, as run.
    scene_text: Option<String>,
    overrides: Vec<String>,
    /// The impacts, as columns.
    impacts: ImpactColumns,
    /// Each body's load history: (name, times s, per-tooth load N).
    loads: Vec<(String, Vec<f64>, Vec<f64>)>,
    /// Why the file was salvaged, if it was damaged.
    warning: Option<String>,
    /// A network recording's sample times, s (empty for a pack's).
    sample_t_s: Vec<f64>,
    /// A network recording's columns at those times: `<body>.speed_rad_s` (rad/s) and
    /// `<coupling>.torque_n_m` (N m), as `run` gives them.
    sample_columns: Vec<(String, Vec<f64>)>,
}

/// Reads the recording at `path`; a damaged one only with `salvage` (what could be read).
#[pyfunction]
#[pyo3(signature = (path, salvage=false))]
pub(crate) fn read(py: Python<'_>, path: PathBuf, salvage: bool) -> PyResult<RawRecording> {
    py.detach(|| read_recording(&path, salvage)).map_err(py_err)
}

fn read_recording(path: &Path, salvage: bool) -> Result<RawRecording, Error> {
    let (reader, warning) = clutchpack_sdk::open_recording(path, salvage)?;
    if let Some(net) = clutchpack_sdk::record::read_network(&reader) {
        let net = net.map_err(|e| Error::BadInput(format!("{}: {e}", path.display())))?;
        if let Some(e) = reader.reread_error() {
            return Err(Error::BadInput(e.to_string()));
        }
        return Ok(raw_network_recording(&reader, net, warning));
    }
    let names = reader.disc_names();
    let impacts = reader.impacts();
    let summary = reader.summary_or_recomputed();
    let info = reader.run_info();
    let fatigue: Vec<serde_json::Value> = summary
        .fatigue
        .iter()
        .map(|f| match f {
            Some(f) => serde_json::json!({
                "damage_rate_per_h": f.damage_rate_per_h,
                "life_h": f.life_h,
                "eq_load_range_n": f.eq_load_range_n,
                "max_root_stress_pa": f.max_root_stress_pa,
            }),
            None => serde_json::Value::Null,
        })
        .collect();
    let summary_json = serde_json::json!({
        "scene": info.as_ref().map(|i| i.scene_name.clone()),
        "engine": info.as_ref().map(|i| i.engine.clone()),
        "duration_s": summary.t_end_s,
        "discs": summary.discs,
        "fatigue": fatigue,
    })
    .to_string();
    let loads = reader
        .load_histories()
        .into_iter()
        .map(|h| (h.name, h.t_s, h.load_n))
        .collect();
    if let Some(e) = reader.reread_error() {
        return Err(Error::BadInput(e.to_string()));
    }
    Ok(RawRecording {
        summary_json,
        scene_text: info.as_ref().map(|i| i.scene_text.clone()),
        overrides: info.map(|i| i.overrides).unwrap_or_default(),
        impacts: ImpactColumns::of(&impacts, &names),
        loads,
        warning,
        sample_t_s: Vec::new(),
        sample_columns: Vec::new(),
    })
}

/// A network recording read back for `clutchpack.read`: the attached summary (the run's
/// `--summary-json`; the scene and engine alone if the run did not finish), the scene, and
/// the samples as the columns `run` gives.
fn raw_network_recording(
    reader: &clutchpack_sdk::record::RecordingReader,
    net: clutchpack_sdk::record::RecordedNetwork,
    warning: Option<String>,
) -> RawRecording {
    let info = reader.run_info();
    let summary_json = net
        .summary_json
        .as_deref()
        .and_then(|j| String::from_utf8(j.to_vec()).ok())
        .unwrap_or_else(|| {
            serde_json::json!({
                "scene": info.as_ref().map(|i| i.scene_name.clone()),
                "engine": info.as_ref().map(|i| i.engine.clone()),
            })
            .to_string()
        });
    let column = |f: &dyn Fn(&clutchpack_sdk::NetworkSample) -> f64| -> Vec<f64> {
        net.samples.iter().map(f).collect()
    };
    let mut sample_columns = Vec::new();
    for (i, b) in net.bodies.iter().enumerate() {
        sample_columns.push((format!("{b}.speed_rad_s"), column(&|s| s.speed_rad_s[i])));
    }
    for (k, c) in net.couplings.iter().enumerate() {
        sample_columns.push((format!("{c}.torque_n_m"), column(&|s| s.torque_n_m[k])));
    }
    RawRecording {
        summary_json,
        scene_text: info.as_ref().map(|i| i.scene_text.clone()),
        overrides: info.map(|i| i.overrides).unwrap_or_default(),
        // the events' `disc` indices are per pack: name each by its own name
        impacts: {
            let events: Vec<_> = net
                .impacts
                .iter()
                .enumerate()
                .map(|(i, (_, e))| clutchpack_sdk::model::ImpactEvent { disc: i, ..*e })
                .collect();
            let names: Vec<String> = net.impacts.iter().map(|(n, _)| n.clone()).collect();
            ImpactColumns::of(&events, &names)
        },
        loads: Vec::new(),
        warning,
        sample_t_s: net.samples.iter().map(|s| s.t_s).collect(),
        sample_columns,
    }
}
