//! `clutchpack.fit`: a least-squares fit of scene keys to measured series, the same
//! arguments and the same messages as `clutchpack fit` (both call `clutchpack_sdk::Fit`);
//! the Python half turns the result into DataFrames.

use crate::{engine_choice, interruptible, py_err};
use clutchpack_sdk::fit::FitOptions;
use clutchpack_sdk::scene::Override;
use clutchpack_sdk::{Fit, FitParam, FitRequest, FitSignal};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// One signal's series: (name, rows: times s or the variant's values, measured, fitted).
type Series = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// What a fit gives the Python half.
#[pyclass(name = "RawFit", module = "clutchpack", frozen, get_all)]
pub struct RawFit {
    /// `clutchpack fit --summary-json`'s content (JSON text).
    summary_json: String,
    /// Per signal: (name, rows: times s or the variant's values, measured, fitted).
    series: Vec<Series>,
    /// The fitted scene's TOML text (what `--fitted-scene` writes).
    fitted_scene: String,
}

/// Fits `params` (`KEY[=START][:LO:HI][:log]`, as `--param`) of the scene file `scene` to
/// the columns of `data` matched by `matches` (`SIGNAL[=COLUMN][:WEIGHT]`, as `--match`),
/// with `sets` fixed (as `--set`); the other arguments as the command line's options. Bad
/// input raises `ValueError` with the command line's message, before any run; Ctrl-C
/// returns the best point so far (the summary's `stopped`).
#[pyfunction]
#[pyo3(signature = (scene, data, params, matches, sets=vec![], engine=None,
    time_column="time_s".to_string(), variant=None, ensemble=1, max_iterations=100,
    fd_step=1e-6, fitted_scene=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit(
    py: Python<'_>,
    scene: PathBuf,
    data: PathBuf,
    params: Vec<String>,
    matches: Vec<String>,
    sets: Vec<(String, String)>,
    engine: Option<&str>,
    time_column: String,
    variant: Option<String>,
    ensemble: u64,
    max_iterations: usize,
    fd_step: f64,
    fitted_scene: Option<PathBuf>,
) -> PyResult<RawFit> {
    let bad = PyValueError::new_err;
    if !(fd_step > 0.0 && fd_step < 0.1) {
        return Err(bad(format!("--fd-step {fd_step}: must be in (0, 0.1)")));
    }
    if ensemble == 0 {
        return Err(bad("--ensemble 0: at least 1 run per variant".to_string()));
    }
    let params = params
        .iter()
        .map(|p| p.parse::<FitParam>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| bad(e.to_string()))?;
    let signals = matches
        .iter()
        .map(|s| s.parse::<FitSignal>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| bad(e.to_string()))?;
    let wanted = fitted_scene.as_deref();
    if let Some(p) = wanted {
        clutchpack_sdk::record::check_outputs(
            &[clutchpack_sdk::record::OutputPath::file("fitted_scene", p)],
            &[scene.as_path(), data.as_path()],
        )
        .map_err(|e| bad(e.to_string()))?;
    }
    let prepared = Fit::new(FitRequest {
        scene,
        sets: sets
            .into_iter()
            .map(|(key, value)| Override { key, value })
            .collect(),
        engine: engine_choice(engine)?,
        data: Some(data),
        time_column,
        variant,
        ensemble,
        params,
        signals,
        options: FitOptions {
            max_iterations,
            fd_step,
            ..FitOptions::default()
        },
    })
    .map_err(py_err)?;
    let stop = AtomicBool::new(false);
    let result =
        interruptible(py, &stop, || prepared.run(Some(&stop), &mut |_, _| {}))?.map_err(py_err)?;
    let text = prepared.fitted_scene_text(&result).map_err(py_err)?;
    if let Some(p) = wanted {
        write(p, &text)?;
    }
    Ok(RawFit {
        summary_json: serde_json::to_string(&result)
            .map_err(|e| bad(format!("the fit's summary: {e}")))?,
        series: result
            .series
            .iter()
            .map(|s| {
                (
                    s.signal.clone(),
                    s.x.clone(),
                    s.measured.clone(),
                    s.fitted.clone(),
                )
            })
            .collect(),
        fitted_scene: text,
    })
}

/// Writes the fitted scene (whole, through a temporary sibling).
fn write(path: &Path, text: &str) -> PyResult<()> {
    clutchpack_sdk::record::write_whole(path, text.as_bytes())
        .map(|_| ())
        .map_err(|e| {
            pyo3::exceptions::PyOSError::new_err(format!("writing {}: {e}", path.display()))
        })
}
