//! Calibration: a least-squares fit of a scene's numeric keys to measured series (issue 47).
//!
//! The parameters are scene keys as `--set` takes them (dotted, array items by index; `[*]`
//! for every item that sets the key, and several keys joined by `,` take one value), each
//! within bounds, optionally on a log scale. The measured series are columns of a CSV file
//! with a time column; each is matched to a signal the scene's run produces
//! (a network's `BODY.speed_rad_s` or `BODY`, `BODY.angle_rad`, `COUPLING.torque_n_m`; a
//! pack's co-simulation outputs, `drum.speed_rad_s`, `interfaces[1].torque_n_m`, ...;
//! `signals.rs`) with a weight. Or the rows are variants of the scene (a key's value per
//! row) and the signals are statistics of a run's impact peaks, ensemble means if asked.
//! The residual of measured point `i` of signal `k` is `w_k (y_sim,k(x_i) - y_meas,k,i)`.
//! The solver
//! is Levenberg-Marquardt (`lm.rs`) with a forward-difference Jacobian whose runs go in
//! parallel on rayon's threads. [`Fit::new`] checks everything before any run; [`Fit::run`]
//! fits, reporting progress and honouring a stop flag (the best point so far is returned);
//! [`Fit::coverage`] checks the intervals on synthetic traces (`coverage.rs`).

mod coverage;
mod data;
mod lm;
mod params;
mod signals;

pub use coverage::{CoverageRequest, CoverageResult, ParamCoverage};

pub use lm::{LmOptions as FitOptions, LmState};
use params::{check_param, check_variant, Param};
pub use params::{FitParam, FitSignal};

use crate::{Error, Result};
use clutchpack_scene::{EngineChoice, Override, Scene};
use serde::Serialize;
use signals::Signal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Correlations beyond this (in magnitude) make a pair "not separately identifiable".
pub const IDENTIFIABILITY_CORRELATION: f64 = 0.99;

/// What to fit.
#[derive(Debug, Clone)]
pub struct FitRequest {
    /// The scene file.
    pub scene: PathBuf,
    /// Fixed `--set` overrides, applied before the fitted keys (none of them fitted).
    pub sets: Vec<Override>,
    /// The engine asked (else the scene's choice).
    pub engine: Option<EngineChoice>,
    /// The measured series: a CSV file with a header row, or an MCAP recording of a network
    /// scene (its series named as the signals; `None`: no measured data, only
    /// for [`Fit::coverage`], whose traces are made on the run's record-rate grid).
    pub data: Option<PathBuf>,
    /// The data's time column (s), strictly increasing.
    pub time_column: String,
    /// Rows as variants of the scene instead of times: the data's column named by this key
    /// (dotted, `[*]` and `,` as a parameter's) holds each row's value of it (strictly
    /// increasing), and the signals are per-run statistics (`BODY.max_positive_n`, ...).
    pub variant: Option<String>,
    /// Runs per variant whose statistics are averaged (ensemble members,
    /// [`crate::ensemble_member`]; 0 or 1: the scene's own run).
    pub ensemble: u64,
    /// The parameters.
    pub params: Vec<FitParam>,
    /// The signals matched to the data's columns.
    pub signals: Vec<FitSignal>,
    /// The solver's settings.
    pub options: FitOptions,
}

/// A fit checked and ready to run ([`Fit::new`]): every key, bound, column and signal
/// found good before any run.
#[derive(Debug, Clone)]
pub struct Fit {
    request: FitRequest,
    text: String,
    base_dir: PathBuf,
    params: Vec<Param>,
    signals: Vec<(FitSignal, Signal)>,
    /// The keys each variant row sets (empty: rows are times).
    variant_keys: Vec<String>,
    /// The rows: times, s, or the variant keys' values.
    rows: Vec<f64>,
    /// Measured values, `[signal][row]` (empty without data).
    measured: Vec<Vec<f64>>,
    scene_name: String,
    engine: EngineChoice,
}

/// One fitted parameter's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedParam {
    /// The key as asked.
    pub key: String,
    /// The scene keys it sets.
    pub keys: Vec<String>,
    /// Its unit.
    pub unit: &'static str,
    /// Whether it was fitted on a log scale.
    pub log: bool,
    /// The start value.
    pub start: f64,
    /// The fitted value.
    pub value: f64,
    /// Its standard error (linearised; of `ln x` times `x` on a log scale), the key's
    /// unit; infinite when the data do not determine it.
    pub std_error: f64,
    /// The 95 % interval's lower end (Student's t with the fit's degrees of freedom;
    /// `exp(ln x -+ t se)` on a log scale).
    pub ci95_low: f64,
    /// The 95 % interval's upper end.
    pub ci95_high: f64,
    /// The bounds, the key's unit.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// Whether it ended on a bound (its interval then means little).
    pub at_bound: bool,
}

/// One matched signal's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SignalFit {
    /// The signal.
    pub signal: String,
    /// Its data column.
    pub column: String,
    /// Its weight.
    pub weight: f64,
    /// Measured points.
    pub points: usize,
    /// RMS of fitted minus measured (unweighted), the signal's unit.
    pub rms: f64,
    /// RMS at the start values, the signal's unit.
    pub rms_start: f64,
}

/// The measured and fitted series of one signal (for the figure).
#[derive(Debug, Clone, PartialEq)]
pub struct SignalSeries {
    /// The signal.
    pub signal: String,
    /// The rows: measured times, s, or the variant key's values (its unit).
    pub x: Vec<f64>,
    /// Measured values.
    pub measured: Vec<f64>,
    /// Simulated at the fitted values, at the measured rows.
    pub fitted: Vec<f64>,
}

/// What a fit found (`fit --summary-json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FitResult {
    /// The scene's name.
    pub scene: String,
    /// The engine that ran it.
    pub engine: &'static str,
    /// What the rows are: `time_s`, or the variant key.
    pub rows: String,
    /// Runs averaged per variant (1 for a time series).
    pub ensemble: u64,
    /// The parameters, as asked.
    pub params: Vec<FittedParam>,
    /// The correlation matrix of the parameters, in their order.
    pub correlation: Vec<Vec<f64>>,
    /// The signals.
    pub signals: Vec<SignalFit>,
    /// Sum of squares of the weighted residuals at the fitted values.
    pub ssr: f64,
    /// Residual points minus parameters.
    pub dof: usize,
    /// Evaluations of the residuals: each one run of the scene for a time series, `rows x
    /// ensemble` runs with `--variant`.
    pub runs: usize,
    /// Runs of the scene in all.
    pub scene_runs: usize,
    /// Solver iterations.
    pub iterations: usize,
    /// Wall time of the fit, s.
    pub wall_time_s: f64,
    /// Whether a convergence test was met.
    pub converged: bool,
    /// Why the solver ended.
    pub reason: String,
    /// Whether the stop flag ended it (the values are the best so far).
    pub stopped: bool,
    /// What the numbers do not say by themselves: parameters the data do not separate
    /// (correlation beyond [`IDENTIFIABILITY_CORRELATION`]), undetermined ones, ones on a
    /// bound, no convergence.
    pub warnings: Vec<String>,
    /// The measured and fitted series.
    #[serde(skip)]
    pub series: Vec<SignalSeries>,
}

impl Fit {
    /// Checks the request, before any run: each key exists in the scene and holds a
    /// number, its bounds are ordered and within the key's own rule, its start within them,
    /// no key fitted twice or also `--set`; the data file has the columns, increasing times
    /// within the run, no NaN; each signal is one the scene produces; the scene loads at
    /// the start values. Every refusal is bad input naming the problem.
    pub fn new(request: FitRequest) -> Result<Fit> {
        let bad = |m: String| Error::BadInput(m);
        if request.params.is_empty() {
            return Err(bad("fit: no parameter to fit (--param)".into()));
        }
        if request.signals.is_empty() {
            return Err(bad("fit: no signal matched to the data (--match)".into()));
        }
        let text = clutchpack_scene::read_input(&request.scene).map_err(|error| {
            Error::Scene(clutchpack_scene::SceneError::Read {
                path: request.scene.clone(),
                error,
            })
        })?;
        let shown = request.scene.display().to_string();
        let mut params = Vec::new();
        let mut seen: Vec<String> = request.sets.iter().map(|o| o.key.clone()).collect();
        for p in &request.params {
            params.push(check_param(p, &text, &shown, &mut seen)?);
        }
        let variant_keys = match &request.variant {
            Some(key) => check_variant(key, &text, &seen)?,
            None => Vec::new(),
        };
        let base_dir = request
            .scene
            .parent()
            .unwrap_or(Path::new(""))
            .to_path_buf();
        let mut fit = Fit {
            text,
            base_dir,
            params,
            signals: Vec::new(),
            variant_keys,
            rows: Vec::new(),
            measured: Vec::new(),
            scene_name: String::new(),
            engine: EngineChoice::Reference,
            request,
        };
        let start: Vec<f64> = fit.params.iter().map(|p| p.start).collect();
        let scene = fit.scene_at(&start, None)?;
        fit.engine = scene.engine(fit.request.engine, &scene.name)?;
        fit.scene_name = scene.name.clone();
        for s in &fit.request.signals {
            let signal = Signal::resolve(&scene, fit.engine, &s.signal)?;
            match (signal.per_run(), &fit.request.variant) {
                (true, None) => {
                    return Err(bad(format!(
                        "signal {:?} is one value per run: its rows are variants of the \
                         scene (--variant KEY), not times",
                        s.signal
                    )))
                }
                (false, Some(v)) => {
                    return Err(bad(format!(
                        "signal {:?} is a series in time: with --variant {v} the rows are \
                         variants, and the signals one value per run (BODY.max_positive_n, \
                         BODY.max_negative_n, BODY.p99_abs_n, BODY.mean_top10_abs_n)",
                        s.signal
                    )))
                }
                _ => {}
            }
            fit.signals.push((s.clone(), signal));
        }
        let Some(data_path) = fit.request.data.clone() else {
            if fit.request.variant.is_some() {
                return Err(bad(
                    "fit: variants (--variant) need a data file giving their values (--data)"
                        .into(),
                ));
            }
            // no data (a coverage study): the run's record-rate grid
            let sim = &scene.simulation;
            let n = (sim.duration_s * sim.record_rate_hz).floor() as usize;
            fit.rows = (0..=n).map(|i| i as f64 / sim.record_rate_hz).collect();
            return Ok(fit);
        };
        let columns: Vec<&str> = fit
            .request
            .signals
            .iter()
            .map(|s| s.column.as_str())
            .collect();
        let row_column = fit
            .request
            .variant
            .as_deref()
            .unwrap_or(&fit.request.time_column);
        if fit.request.variant.is_some() && data::is_recording(&data_path) {
            return Err(bad(format!(
                "fit data {}: variants (--variant) are read from a CSV table, not a recording",
                data_path.display()
            )));
        }
        let data = data::read(&data_path, row_column, &columns)?;
        if fit.request.variant.is_some() {
            // every variant loads (its value within its key's rule) before any run
            for &x in &data.time_s {
                fit.scene_at(&start, Some(x)).map_err(|e| {
                    bad(format!(
                        "fit data {}: the variant {row_column} = {x:?} does not load: {e}",
                        data_path.display()
                    ))
                })?;
            }
        } else {
            let (t0, t1) = (data.time_s[0], *data.time_s.last().expect("2 rows"));
            let end = scene.simulation.duration_s;
            if t0 < 0.0 || t1 > end {
                return Err(bad(format!(
                    "fit data {}: times {t0} to {t1} s lie outside the run (0 to {end} s, \
                     simulation.duration_s)",
                    data_path.display()
                )));
            }
        }
        let m = data.time_s.len() * columns.len();
        if m <= fit.params.len() {
            return Err(bad(format!(
                "fit: {m} measured points for {} parameters (more points than parameters needed)",
                fit.params.len()
            )));
        }
        fit.rows = data.time_s;
        fit.measured = data.values;
        Ok(fit)
    }

    /// The scene with the fixed overrides, the parameters at `values` (the keys' units)
    /// and, for a variant row, the variant keys at `row`.
    fn scene_at(&self, values: &[f64], row: Option<f64>) -> Result<Scene> {
        let mut overrides = self.overrides(values);
        if let Some(x) = row {
            overrides.extend(self.variant_keys.iter().map(|k| Override {
                key: k.clone(),
                value: format!("{x:?}"),
            }));
        }
        Ok(clutchpack_scene::parse(
            &self.text,
            &self.request.scene.display().to_string(),
            &self.base_dir,
            &overrides,
        )?)
    }

    /// The fixed overrides followed by every parameter's keys at `values`.
    fn overrides(&self, values: &[f64]) -> Vec<Override> {
        let mut o = self.request.sets.clone();
        for (p, &x) in self.params.iter().zip(values) {
            o.extend(p.keys.iter().map(|k| Override {
                key: k.clone(),
                value: format!("{x:?}"),
            }));
        }
        o
    }

    /// The simulated signals at the measured rows, `[signal][row]`, for the parameters at
    /// `values`.
    fn simulate(&self, values: &[f64], stop: Option<&AtomicBool>) -> Result<Vec<Vec<f64>>> {
        use rayon::prelude::*;
        let signals: Vec<&Signal> = self.signals.iter().map(|(_, s)| s).collect();
        if self.variant_keys.is_empty() {
            let scene = self.scene_at(values, None)?;
            return signals::series(
                &scene,
                self.request.engine,
                self.engine,
                &signals,
                &self.rows,
                stop,
            );
        }
        let per_row = self
            .rows
            .par_iter()
            .map(|&x| {
                let scene = self.scene_at(values, Some(x))?;
                signals::statistics(
                    &scene,
                    self.request.engine,
                    &signals,
                    self.request.ensemble,
                    stop,
                )
            })
            .collect::<Result<Vec<Vec<f64>>>>()?;
        Ok((0..signals.len())
            .map(|k| per_row.iter().map(|r| r[k]).collect())
            .collect())
    }

    /// The weighted residual vector for the simulated series.
    fn residuals(&self, sim: &[Vec<f64>]) -> Vec<f64> {
        let mut r = Vec::with_capacity(self.rows.len() * sim.len());
        for (k, (s, _)) in self.signals.iter().enumerate() {
            r.extend(
                sim[k]
                    .iter()
                    .zip(&self.measured[k])
                    .map(|(y, m)| s.weight * (y - m)),
            );
        }
        r
    }

    /// The parameters' values (the keys' units) at internal coordinates `u`.
    fn values(&self, u: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(u)
            .map(|(p, &u)| p.to_value(u))
            .collect()
    }

    /// The scene's name.
    pub fn scene_name(&self) -> &str {
        &self.scene_name
    }

    /// The parameters' keys as asked, in order.
    pub fn param_keys(&self) -> Vec<&str> {
        self.params.iter().map(|p| p.asked.key.as_str()).collect()
    }

    /// Runs the fit. `stop` is polled before every batch of runs and by the runs themselves:
    /// once set, the best point so far is the result ([`FitResult::stopped`]).
    /// `progress(state, values)` is called after every batch with the solver's state and the
    /// best values so far (the keys' units).
    pub fn run(
        &self,
        stop: Option<&AtomicBool>,
        progress: &mut dyn FnMut(&LmState, &[f64]),
    ) -> Result<FitResult> {
        use rayon::prelude::*;
        if self.measured.is_empty() {
            return Err(Error::BadInput(
                "fit: no measured data to fit (--data)".into(),
            ));
        }
        let started = Instant::now();
        let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let mut eval = |points: &[Vec<f64>]| -> Vec<Result<Vec<f64>>> {
            points
                .par_iter()
                .map(|u| {
                    let sim = self.simulate(&self.values(u), stop)?;
                    if stopped() {
                        return Err(Error::BadInput("stopped".into()));
                    }
                    Ok(self.residuals(&sim))
                })
                .collect()
        };
        let lower: Vec<f64> = self.params.iter().map(|p| p.lower).collect();
        let upper: Vec<f64> = self.params.iter().map(|p| p.upper).collect();
        let u0: Vec<f64> = self.params.iter().map(|p| p.to_internal(p.start)).collect();
        let outcome = lm::minimize(
            &u0,
            &lower,
            &upper,
            &self.request.options,
            &mut eval,
            &stopped,
            &mut |s| progress(s, &self.values(&s.u)),
        );
        let outcome = match outcome {
            Err(_) if stopped() => {
                return Err(Error::BadInput(
                    "fit stopped before its first run finished".into(),
                ))
            }
            o => o?,
        };
        // the simulated series back from the weighted residuals: y = r / w + measured
        let series_of = |r: &[f64]| -> Vec<Vec<f64>> {
            let len = self.rows.len();
            self.signals
                .iter()
                .enumerate()
                .map(|(k, (s, _))| {
                    r[k * len..(k + 1) * len]
                        .iter()
                        .zip(&self.measured[k])
                        .map(|(r, m)| r / s.weight + m)
                        .collect()
                })
                .collect()
        };
        let fitted = series_of(&outcome.r);
        let start = series_of(&outcome.r_start);
        let runs = outcome.evaluations;
        let n = self.params.len();
        let m = outcome.r.len();
        let dof = m - n;
        let ssr: f64 = outcome.r.iter().map(|x| x * x).sum();
        let cov = outcome
            .jacobian
            .as_ref()
            .map(|j| lm::covariance(j, ssr, dof));
        let t = clutchpack_study::stats::t975(dof as f64);
        let mut warnings = Vec::new();
        let params: Vec<FittedParam> = self
            .params
            .iter()
            .enumerate()
            .map(|(j, p)| {
                let u = outcome.u[j];
                let se_u = cov.as_ref().map_or(f64::NAN, |c| c.std_error[j]);
                let (lo, hi) = (u - t * se_u, u + t * se_u);
                let at_bound = u <= p.lower || u >= p.upper;
                if at_bound {
                    warnings.push(format!(
                        "{} ended on its bound ({}): its interval is not a confidence interval",
                        p.asked.key,
                        p.to_value(u)
                    ));
                }
                FittedParam {
                    key: p.asked.key.clone(),
                    keys: p.keys.clone(),
                    unit: p.unit,
                    log: p.asked.log,
                    start: p.start,
                    value: p.to_value(u),
                    std_error: if p.asked.log {
                        p.to_value(u) * se_u
                    } else {
                        se_u
                    },
                    ci95_low: p.to_value(lo),
                    ci95_high: p.to_value(hi),
                    lower: p.to_value(p.lower),
                    upper: p.to_value(p.upper),
                    at_bound,
                }
            })
            .collect();
        let correlation = cov
            .as_ref()
            .map_or_else(|| vec![vec![f64::NAN; n]; n], |c| c.correlation.clone());
        for i in 0..n {
            for j in i + 1..n {
                let c = correlation[i][j];
                if c.abs() > IDENTIFIABILITY_CORRELATION {
                    warnings.push(format!(
                        "{} and {} are not separately identifiable from these signals \
                         (correlation {c:+.4}): the data fix a combination of them, not each; \
                         fix one of them (--set) or add a signal that separates them",
                        params[i].key, params[j].key
                    ));
                }
            }
        }
        for p in &params {
            if !p.std_error.is_finite() {
                warnings.push(format!(
                    "{}: the data do not determine it (infinite standard error)",
                    p.key
                ));
            } else if p.std_error > p.value.abs() {
                warnings.push(format!(
                    "{}: its standard error {:.3e} exceeds its value {:.6e} (poorly determined)",
                    p.key, p.std_error, p.value
                ));
            }
        }
        if !outcome.converged && !outcome.stopped {
            warnings.push(format!("the fit did not converge: {}", outcome.reason));
        }
        let rms = |a: &[f64], b: &[f64]| {
            (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
        };
        let signals = self
            .signals
            .iter()
            .enumerate()
            .map(|(k, (s, _))| SignalFit {
                signal: s.signal.clone(),
                column: s.column.clone(),
                weight: s.weight,
                points: self.rows.len(),
                rms: rms(&fitted[k], &self.measured[k]),
                rms_start: rms(&start[k], &self.measured[k]),
            })
            .collect();
        let series = self
            .signals
            .iter()
            .enumerate()
            .map(|(k, (s, _))| SignalSeries {
                signal: s.signal.clone(),
                x: self.rows.clone(),
                measured: self.measured[k].clone(),
                fitted: fitted[k].clone(),
            })
            .collect();
        Ok(FitResult {
            scene: self.scene_name.clone(),
            engine: self.engine.name(),
            rows: self
                .request
                .variant
                .clone()
                .unwrap_or_else(|| "time_s".into()),
            ensemble: if self.request.variant.is_some() {
                self.request.ensemble.max(1)
            } else {
                1
            },
            params,
            correlation,
            signals,
            ssr,
            dof,
            runs,
            scene_runs: if self.variant_keys.is_empty() {
                runs
            } else {
                runs * self.rows.len() * self.request.ensemble.max(1) as usize
            },
            iterations: outcome.iterations,
            wall_time_s: started.elapsed().as_secs_f64(),
            converged: outcome.converged,
            reason: outcome.reason,
            stopped: outcome.stopped,
            warnings,
            series,
        })
    }

    /// The scene with the fitted values, as TOML text (the file's comments are not kept): a
    /// header naming the fit, then the scene with the fixed overrides and every fitted key.
    pub fn fitted_scene_text(&self, result: &FitResult) -> Result<String> {
        let values: Vec<f64> = result.params.iter().map(|p| p.value).collect();
        let body = clutchpack_scene::apply_to_text(
            &self.text,
            &self.request.scene.display().to_string(),
            &self.overrides(&values),
        )?;
        let mut head = format!(
            "# {} fitted by `clutchpack fit` to {} ({} runs)\n",
            self.request.scene.display(),
            self.request
                .data
                .as_deref()
                .map_or_else(|| "no data".into(), |d| d.display().to_string()),
            result.runs
        );
        for p in &result.params {
            head.push_str(&format!(
                "#   {} = {} {} (95 % interval {} to {})\n",
                p.key, p.value, p.unit, p.ci95_low, p.ci95_high
            ));
        }
        for w in &result.warnings {
            head.push_str(&format!("# warning: {w}\n"));
        }
        Ok(format!("{head}\n{body}"))
    }
}
