//! `clutchpack._clutchpack`: the native half of the `clutchpack` Python package, a thin layer
//! over `clutchpack_sdk` (the same library the command line calls, so a run from Python is a
//! run of the CLI). It hands Python plain values (JSON text for the summaries, lists for
//! columns); the Python half (`python/clutchpack/__init__.py`) makes them DataFrames and numpy
//! arrays.
//!
//! Errors: bad input (a scene, a key, an engine that cannot run the pack, a damaged recording
//! not salvaged) raises `ValueError` with the message the CLI prints; a failed run or a file
//! that cannot be written raises `RuntimeError`. An engine runs with the GIL released; Ctrl-C
//! (SIGINT) stops it within about 50 ms of wall time, its outputs complete (the recording
//! finished), and then raises `KeyboardInterrupt`.

mod fit;
mod recording;
mod stepper;

use clutchpack_sdk::scene::{EngineChoice, Override};
use clutchpack_sdk::{Error, Outcome, RecordingRequest, RunRequest, Simulation};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How often a running engine looks for Ctrl-C (Python's signal handlers), wall time.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// An sdk error as the Python exception a user expects: `ValueError` for bad input.
fn py_err(e: Error) -> PyErr {
    if e.is_bad_input() {
        PyValueError::new_err(e.to_string())
    } else {
        PyRuntimeError::new_err(e.to_string())
    }
}

/// A validated scene: a file, a TOML text or a dict, with its overrides.
#[pyclass(name = "Scene", module = "clutchpack", frozen)]
struct Scene {
    inner: clutchpack_sdk::scene::Scene,
    /// The scene file, if it came from one.
    path: Option<PathBuf>,
    /// The folder relative paths in the scene resolve against.
    base_dir: PathBuf,
    /// The overrides applied (`KEY=VALUE`), in order.
    sets: Vec<Override>,
}

#[pymethods]
impl Scene {
    /// The scene's name (its file as named when loaded).
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    /// The scene's TOML text (before the overrides).
    #[getter]
    fn text(&self) -> String {
        self.inner.source_text.clone()
    }
    /// The overrides applied, as `KEY=VALUE`.
    #[getter]
    fn overrides(&self) -> Vec<String> {
        self.inner.overrides.clone()
    }
    /// Simulated duration, s.
    #[getter]
    fn duration_s(&self) -> f64 {
        self.inner.simulation.duration_s
    }
    /// The bodies whose teeth are loaded: the friction discs, then the separator plates.
    #[getter]
    fn bodies(&self) -> Vec<String> {
        let p = &self.inner.pack;
        p.discs
            .iter()
            .chain(&p.plates)
            .map(|d| d.name.clone())
            .collect()
    }
    /// Whether the scene is a driveline network (`[[bodies]]`; run it with `run` as any
    /// scene: it gives speeds and coupling torques, not tooth loads).
    #[getter]
    fn is_network(&self) -> bool {
        self.inner.network.is_some()
    }
    /// The scene file, if the scene came from one.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }
    /// The engine `run` would choose and why (`engine: ...`, as `clutchpack run` prints).
    fn engine_line(&self, engine: Option<&str>) -> PyResult<String> {
        let sim = Simulation::new(self.inner.clone(), engine_choice(engine)?).map_err(py_err)?;
        Ok(sim.engine_line().to_string())
    }
    /// This scene reloaded with more overrides `sets` (`(key, value)` pairs, after its own).
    fn with_sets(&self, sets: Vec<(String, String)>) -> PyResult<Scene> {
        let mut all = self.sets.clone();
        all.extend(overrides(sets));
        let inner = clutchpack_sdk::scene::parse(
            &self.inner.source_text,
            &self.inner.name,
            &self.base_dir,
            &all,
        )
        .map_err(|e| py_err(e.into()))?;
        Ok(Scene {
            inner,
            path: self.path.clone(),
            base_dir: self.base_dir.clone(),
            sets: all,
        })
    }
    fn __repr__(&self) -> String {
        format!(
            "Scene({:?}, {} bodies, {} s)",
            self.inner.name,
            self.bodies().len(),
            self.inner.simulation.duration_s
        )
    }
}

/// The one output policy of every front end (`clutchpack_sdk::record::check_outputs`), before any
/// work: each `(argument, path)` given names a new or regular file in an existing folder, not
/// a folder, a device or a FIFO, not another output and not the scene file; else
/// `ValueError` naming the argument.
fn check_outputs(outputs: &[(&str, Option<&Path>)], scene: &Scene) -> PyResult<()> {
    let outs: Vec<clutchpack_sdk::record::OutputPath> = outputs
        .iter()
        .filter_map(|(label, p)| p.map(|p| clutchpack_sdk::record::OutputPath::file(label, p)))
        .collect();
    // the scene file and every file it read (its tables, a network's pack files)
    let inputs: Vec<&Path> = scene
        .path
        .as_deref()
        .into_iter()
        .chain(scene.inner.inputs.iter().map(|p| p.as_path()))
        .collect();
    clutchpack_sdk::record::check_outputs(&outs, &inputs)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// `jobs` threads, else one per core; at least 1, at most 256 (as `clutchpack sweep`).
fn threads(jobs: Option<usize>) -> usize {
    jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
        .clamp(1, 256)
}

/// `engine` as the sdk's choice (`None`: the scene's); an unknown name is a `ValueError`.
fn engine_choice(engine: Option<&str>) -> PyResult<Option<EngineChoice>> {
    engine
        .map(|e| e.parse::<EngineChoice>().map_err(PyValueError::new_err))
        .transpose()
}

/// `(key, value)` pairs as overrides.
fn overrides(sets: Vec<(String, String)>) -> Vec<Override> {
    sets.into_iter()
        .map(|(key, value)| Override { key, value })
        .collect()
}

/// Loads and validates a scene from a file (`path`), a TOML text (`text`, named `name` in
/// messages) or neither (the paper's case, built in), with the overrides `sets`.
#[pyfunction]
#[pyo3(signature = (path=None, text=None, name=None, sets=Vec::new()))]
fn load_scene(
    path: Option<PathBuf>,
    text: Option<String>,
    name: Option<String>,
    sets: Vec<(String, String)>,
) -> PyResult<Scene> {
    let sets = overrides(sets);
    let here = std::env::current_dir().unwrap_or_else(|_| PathBuf::from("."));
    let (inner, base_dir) = match (&path, text) {
        (Some(_), Some(_)) => {
            return Err(PyValueError::new_err(
                "give a scene as a path or as a text, not both",
            ))
        }
        (None, Some(t)) => {
            let name = name.unwrap_or_else(|| "<scene text>".into());
            let s = clutchpack_sdk::scene::parse(&t, &name, &here, &sets)
                .map_err(|e| py_err(e.into()))?;
            (s, here)
        }
        (p, None) => {
            let s = clutchpack_sdk::load_scene(p.as_deref(), &sets).map_err(py_err)?;
            let dir = p
                .as_deref()
                .and_then(Path::parent)
                .map_or(here, Path::to_path_buf);
            (s, dir)
        }
    };
    Ok(Scene {
        inner,
        path,
        base_dir,
        sets,
    })
}

/// A scene from the JSON text of a Python dict (the TOML file's tables as nested dicts),
/// named `name` in messages.
#[pyfunction]
#[pyo3(signature = (json, name, sets=Vec::new()))]
fn scene_from_json(json: &str, name: &str, sets: Vec<(String, String)>) -> PyResult<Scene> {
    let value: toml::Value = serde_json::from_str(json)
        .map_err(|e| PyValueError::new_err(format!("{name}: not a scene: {e}")))?;
    let text = toml::to_string(&value)
        .map_err(|e| PyValueError::new_err(format!("{name}: not a scene: {e}")))?;
    load_scene(None, Some(text), Some(name.to_string()), sets)
}

/// Impacts as columns: body name, onset, peak and separation times (s), flank, closing speed
/// at onset (m/s), signed peak per-tooth load (N), one entry per impact.
#[pyclass(name = "ImpactColumns", module = "clutchpack", frozen, get_all)]
#[derive(Clone)]
pub struct ImpactColumns {
    disc: Vec<String>,
    t_on_s: Vec<f64>,
    t_peak_s: Vec<f64>,
    t_off_s: Vec<f64>,
    flank: Vec<String>,
    v_on_m_s: Vec<f64>,
    peak_n: Vec<f64>,
}

impl ImpactColumns {
    /// `impacts`, their bodies named by `names` (engine order).
    pub(crate) fn of(
        impacts: &[clutchpack_sdk::model::ImpactEvent],
        names: &[String],
    ) -> ImpactColumns {
        let name_of = |i: usize| names.get(i).cloned().unwrap_or_else(|| format!("disc {i}"));
        ImpactColumns {
            disc: impacts.iter().map(|e| name_of(e.disc)).collect(),
            t_on_s: impacts.iter().map(|e| e.t_on_s).collect(),
            t_peak_s: impacts.iter().map(|e| e.t_peak_s).collect(),
            t_off_s: impacts.iter().map(|e| e.t_off_s).collect(),
            flank: impacts
                .iter()
                .map(|e| e.flank.label().to_string())
                .collect(),
            v_on_m_s: impacts.iter().map(|e| e.v_on_m_s).collect(),
            peak_n: impacts.iter().map(|e| e.peak_n).collect(),
        }
    }
}

/// What one run of a scene, a pack or a network, gave, for the Python half.
#[pyclass(name = "RawRun", module = "clutchpack", frozen, get_all)]
struct RawRun {
    /// `--summary-json`'s content (JSON text), a pack's or a network's.
    summary_json: String,
    /// The engine line (`engine: ... , why`).
    engine_line: String,
    /// A pack's impacts, as columns (a network's: none; its packs' go to `impacts_csv`).
    impacts: ImpactColumns,
    /// Sample times, s (empty unless kept).
    sample_t_s: Vec<f64>,
    /// The columns at those times, by name: a pack's per-tooth load of each body, N (named
    /// by the body); a network's `<body>.speed_rad_s` (rad/s) and `<coupling>.torque_n_m`
    /// (N m, on its body a).
    sample_columns: Vec<(String, Vec<f64>)>,
    /// The recording's path, if recorded.
    recording: Option<PathBuf>,
    /// Whether the run stopped before its duration.
    stopped_early: bool,
    /// Warnings to show (a recording's summary without statistics, ...).
    warnings: Vec<String>,
}

/// A progress callback for a run with the GIL released: every [`SIGNAL_POLL`] it takes the GIL
/// to check Python's signals; a pending one (Ctrl-C) is kept in `interrupt` and sets `stop`,
/// which ends the run with its outputs complete.
fn signal_poll<'a>(stop: &'a AtomicBool, interrupt: &'a mut Option<PyErr>) -> impl FnMut(f64) + 'a {
    let mut last = Instant::now();
    move |_t: f64| {
        if last.elapsed() >= SIGNAL_POLL {
            last = Instant::now();
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                *interrupt = Some(e);
                stop.store(true, Ordering::SeqCst);
            }
        }
    }
}

/// Runs `scene`, a pack or a network (engine: `engine`, else the scene's choice), as
/// `clutchpack run` does, through the sdk's one `Simulation::run`: optionally recording to
/// `record` and writing every impact to `impacts_csv` (each replaced if it exists); keeps the
/// sampled history when `keep_samples`. The GIL is released while the engine runs; Ctrl-C
/// stops it with its outputs complete and raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (scene, engine=None, record=None, impacts_csv=None, keep_samples=true, deterministic=false))]
fn run(
    py: Python<'_>,
    scene: &Scene,
    engine: Option<&str>,
    record: Option<PathBuf>,
    impacts_csv: Option<PathBuf>,
    keep_samples: bool,
    deterministic: bool,
) -> PyResult<RawRun> {
    check_outputs(
        &[
            ("record =", record.as_deref()),
            ("impacts_csv =", impacts_csv.as_deref()),
        ],
        scene,
    )?;
    let mut sim = Simulation::new(scene.inner.clone(), engine_choice(engine)?).map_err(py_err)?;
    // as `clutchpack run --out` asks (a network's recording applies the determinism alone)
    let recording = record.map(|path| RecordingRequest {
        path,
        replace: clutchpack_sdk::record::Replace::Existing,
        options: clutchpack_sdk::record::RecordOptions {
            deterministic,
            per_tooth: scene.inner.simulation.record_per_tooth,
            contact_samples: scene.inner.simulation.record_contact_samples,
            ..clutchpack_sdk::record::RecordOptions::default()
        },
        scene_path: scene.path.clone(),
    });
    let stop = AtomicBool::new(false);
    let mut interrupt: Option<PyErr> = None;
    let outcome = py.detach(|| {
        let mut progress = signal_poll(&stop, &mut interrupt);
        sim.run(RunRequest {
            keep_history: true,
            keep_cycles: false,
            impacts_csv,
            recording,
            stop: Some(&stop),
            progress: Some(&mut progress),
            windows_s: None,
        })
    });
    let outcome = outcome.map_err(py_err)?;
    if let Some(e) = outcome.impacts_csv_error() {
        return Err(PyRuntimeError::new_err(e.to_string()));
    }
    let recording = match outcome.recording() {
        Some(Ok(p)) => Some(p.to_path_buf()),
        Some(Err(e)) => return Err(PyRuntimeError::new_err(format!("the recording: {e}"))),
        None => None,
    };
    if let Some(e) = interrupt {
        // the outputs are complete up to the stop; the user asked to stop
        return Err(e);
    }
    let summary = outcome.summary().map_err(py_err)?;
    let (impacts, (sample_t_s, sample_columns)) = match &outcome {
        Outcome::Pack(o) => (
            ImpactColumns::of(&o.collector.impacts, &o.body_names),
            pack_columns(o),
        ),
        Outcome::Network(o) => (ImpactColumns::of(&[], &[]), network_columns(o)),
    };
    let (sample_t_s, sample_columns) = if keep_samples {
        (sample_t_s, sample_columns)
    } else {
        (Vec::new(), Vec::new())
    };
    Ok(RawRun {
        summary_json: serde_json::to_string(&summary)
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?,
        engine_line: sim.engine_line().to_string(),
        impacts,
        sample_t_s,
        sample_columns,
        recording,
        stopped_early: outcome.stopped_early(),
        warnings: outcome.warnings().to_vec(),
    })
}

/// A pack run's sample times, s, and each body's per-tooth load at them, N, by body.
fn pack_columns(o: &clutchpack_sdk::RunOutcome) -> (Vec<f64>, Vec<(String, Vec<f64>)>) {
    let h = &o.collector.history;
    let t = h
        .first()
        .map(|v| v.iter().map(|p| p.0).collect())
        .unwrap_or_default();
    let loads = o
        .body_names
        .iter()
        .zip(h)
        .map(|(n, v)| (n.clone(), v.iter().map(|p| p.1).collect()))
        .collect();
    (t, loads)
}

/// A network run's sample times, s, and its columns at them: each body's speed
/// (`<body>.speed_rad_s`, rad/s), then each coupling's torque on its body a
/// (`<coupling>.torque_n_m`, N m).
fn network_columns(o: &clutchpack_sdk::NetworkOutcome) -> (Vec<f64>, Vec<(String, Vec<f64>)>) {
    let h = &o.history;
    let column = |f: &dyn Fn(&clutchpack_sdk::NetworkSample) -> f64| h.iter().map(f).collect();
    let s = &o.summary;
    let speeds = s.bodies.iter().enumerate().map(|(i, b)| {
        let name = format!("{}.speed_rad_s", b.name);
        (name, column(&|x| x.speed_rad_s[i]))
    });
    let torques = s.couplings.iter().enumerate().map(|(k, c)| {
        let name = format!("{}.torque_n_m", c.name);
        (name, column(&|x| x.torque_n_m[k]))
    });
    (
        h.iter().map(|x| x.t_s).collect(),
        speeds.chain(torques).collect(),
    )
}

/// Runs `f` on a worker thread with the GIL released, polling Ctrl-C on this (the main)
/// thread; on Ctrl-C sets `stop` (which `f` must honour), waits for `f` to return, and
/// raises `KeyboardInterrupt`.
///
/// This thread sleeps until the worker says it is done (a channel), waking every
/// [`SIGNAL_POLL`] to poll Ctrl-C (as a whole run's [`signal_poll`]): a call returns as soon
/// as its work is done. It used to
/// sleep 20 us, 40 us, 80 us, ... between looks at the worker, so that a call of 0.3 ms
/// returned after about 0.6 ms and one of 17 us after 80 us or more: a host's 1 ms frames
/// (`Simulation.advance_to`) cost 1.5-3 times their work (issue 46).
fn interruptible<T: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    f: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    let mut interrupt = None;
    let out = py.detach(|| {
        std::thread::scope(|s| {
            let (done, finished) = std::sync::mpsc::sync_channel::<()>(1);
            let worker = s.spawn(move || {
                let out = f();
                // the receiver waits until this is sent (or the sender dropped by a panic)
                let _ = done.send(());
                out
            });
            loop {
                match finished.recv_timeout(SIGNAL_POLL) {
                    Ok(()) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                        if interrupt.is_none() {
                            if let Err(e) = Python::attach(|py| py.check_signals()) {
                                interrupt = Some(e);
                                stop.store(true, Ordering::SeqCst);
                            }
                        }
                    }
                }
            }
            worker.join()
        })
    });
    let out = out.map_err(|_| PyRuntimeError::new_err("a worker thread panicked"))?;
    match interrupt {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// A sweep of `param` over `values` on `scene` (reloaded with `param=value` and `sets` for
/// each value), each value as an ensemble of `ensemble` members, on `jobs` threads: the
/// sweep table's rows and the members' fatigue, as `clutchpack sweep --summary-json` gives
/// them (JSON text).
#[pyfunction]
#[pyo3(signature = (scene, param, values, ensemble=1, jobs=None, engine=None))]
fn sweep(
    py: Python<'_>,
    scene: &Scene,
    param: &str,
    values: Vec<f64>,
    ensemble: usize,
    jobs: Option<usize>,
    engine: Option<&str>,
) -> PyResult<String> {
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "values {values:?}: expected one or more finite numbers"
        )));
    }
    let engine = engine_choice(engine)?;
    let scenes = values
        .iter()
        .map(|v| {
            let case = scene.with_sets(vec![(param.to_string(), format!("{v:e}"))])?;
            Ok(case.inner)
        })
        .collect::<PyResult<Vec<_>>>()?;
    let jobs = threads(jobs);
    // sweeps take pack scenes only: a network is refused before any case runs
    let sim = Simulation::new(scenes[0].clone(), engine).map_err(py_err)?;
    sim.pack_only().map_err(py_err)?;
    let engine_name = sim.engine_name();
    let stop = AtomicBool::new(false);
    let runs = interruptible(py, &stop, || {
        clutchpack_sdk::run_cases(
            &scenes,
            &values,
            param,
            ensemble,
            jobs,
            engine,
            &stop,
            &|_, _| {},
        )
    })?
    .map_err(py_err)?;
    let rows = clutchpack_sdk::analysis::sweep_rows(&runs.cases);
    let fatigue: Vec<serde_json::Value> = runs
        .cases
        .iter()
        .zip(&scenes)
        .zip(&runs.fatigue)
        .map(|((c, s), members)| {
            let d_crit: Vec<f64> = s
                .fatigue
                .iter()
                .map(|f| f.material.critical_damage)
                .collect();
            serde_json::json!({
                "value": c.value,
                "discs": clutchpack_sdk::analysis::ensemble_fatigue(members, &d_crit),
            })
        })
        .collect();
    let out = serde_json::json!({
        "scene": scenes[0].name,
        "engine": engine_name,
        "param": param,
        "values": values,
        "ensemble": ensemble,
        "jobs": jobs,
        "wall_time_s": runs.wall_s,
        "rows": rows,
        "fatigue": fatigue,
    });
    Ok(out.to_string())
}

/// Runs shard `shard` of `shards` of the study file `study` (all of it by default) into the
/// folder `out` on `jobs` threads: the cases its part lacks, as `clutchpack study run`.
/// Returns (part file, cases, skipped, ran, failed, complete). Ctrl-C stops it between
/// cases, the part complete up to there, and raises `KeyboardInterrupt`.
#[pyfunction]
#[pyo3(signature = (study, out, jobs=None, shard=0, shards=1))]
fn study_run(
    py: Python<'_>,
    study: PathBuf,
    out: PathBuf,
    jobs: Option<usize>,
    shard: u64,
    shards: u64,
) -> PyResult<(PathBuf, usize, usize, usize, usize, bool)> {
    let s =
        clutchpack_sdk::study::load(&study).map_err(|e| PyValueError::new_err(e.to_string()))?;
    if shards == 0 || shard >= shards {
        return Err(PyValueError::new_err(format!(
            "shard {shard} of {shards}: the index must be in 0..{shards} (shards >= 1)"
        )));
    }
    let jobs = threads(jobs);
    let shard = clutchpack_sdk::study::Shard {
        index: shard,
        count: shards,
    };
    let stop = AtomicBool::new(false);
    let o = interruptible(py, &stop, || {
        clutchpack_sdk::run_study_shard(&s, &out, shard, jobs, &stop, &|_, _| {})
    })?
    .map_err(py_err)?;
    Ok((o.path, o.cases, o.skipped, o.ran, o.failed, o.complete))
}

/// Merges the study parts in `dir` into `results.csv`, `summary.csv`, `results.parquet` and
/// the main-effects figure (`plot_format`: `png` or `svg`), as `clutchpack study merge`;
/// returns the path of `results.csv`. Missing shards raise `RuntimeError` naming them.
#[pyfunction]
#[pyo3(signature = (dir, plot_format="png"))]
fn study_merge(py: Python<'_>, dir: PathBuf, plot_format: &str) -> PyResult<PathBuf> {
    if !["png", "svg"].contains(&plot_format) {
        return Err(PyValueError::new_err(format!(
            "plot_format {plot_format:?}: expected png or svg"
        )));
    }
    py.detach(|| clutchpack_sdk::merge_study(&dir, plot_format))
        .map_err(py_err)?;
    Ok(dir.join("results.csv"))
}

/// The native module.
#[pymodule]
fn _clutchpack(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<ImpactColumns>()?;
    m.add_class::<RawRun>()?;
    m.add_class::<recording::RawRecording>()?;
    m.add_class::<fit::RawFit>()?;
    m.add_class::<stepper::Stepper>()?;
    m.add_class::<stepper::StepperState>()?;
    m.add_function(wrap_pyfunction!(load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(recording::read, m)?)?;
    m.add_function(wrap_pyfunction!(study_run, m)?)?;
    m.add_function(wrap_pyfunction!(study_merge, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // the most cases a sweep runs (values x members), for the Python half's check of
    // `ensemble`, which names the argument
    m.add("MAX_BATCH_CASES", clutchpack_sdk::MAX_BATCH_CASES)?;
    Ok(())
}
