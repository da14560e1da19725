//! A coverage study of a fit's intervals: synthetic traces of the scene at its own values
//! (the truth) with normal noise, each fitted from the asked start values, counting how
//! often each reported 95 % interval holds the truth (about 95 of 100 when the linearised
//! intervals are right; 90 to 99 is the binomial range of 100 such trials, 95 +- 2 sd).

use super::{Fit, FitSignal};
use crate::{Error, Result};
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// What a coverage study makes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoverageRequest {
    /// Synthetic traces, each fitted once.
    pub traces: usize,
    /// The noise's standard deviation relative to each signal's RMS over the rows at the
    /// truth (0.01: 1 %); the same for every point of a signal.
    pub noise: f64,
    /// Seed of the noise: trace `i`'s noise on signal `k` is the stream
    /// `clutchpack_study::rng::Stream::new(seed, i, k)`, so a study is reproducible and its
    /// traces do not depend on each other.
    pub seed: u64,
}

/// One parameter's coverage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParamCoverage {
    /// The key as asked.
    pub key: String,
    /// Its unit.
    pub unit: &'static str,
    /// The true value (the scene's own), the key's unit.
    pub truth: f64,
    /// Traces whose reported 95 % interval holds the truth.
    pub covered: usize,
    /// Mean of the fitted values over the traces that fitted.
    pub fitted_mean: f64,
    /// Their standard deviation (the spread the standard errors should match), the key's
    /// unit.
    pub fitted_sd: f64,
    /// Mean of the reported standard errors.
    pub std_error_mean: f64,
}

/// What a coverage study found (`fit --coverage --summary-json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoverageResult {
    /// The scene's name.
    pub scene: String,
    /// The engine that ran it.
    pub engine: &'static str,
    /// Traces asked.
    pub traces: usize,
    /// The relative noise.
    pub noise: f64,
    /// The noise's seed.
    pub seed: u64,
    /// Measured points per trace (rows times signals).
    pub points: usize,
    /// Each signal's noise standard deviation, its unit (also `1 / weight` of its
    /// residuals).
    pub noise_sd: Vec<f64>,
    /// Per parameter.
    pub params: Vec<ParamCoverage>,
    /// Traces whose every interval held its truth.
    pub all_covered: usize,
    /// Traces whose fit failed (an error, or no convergence): counted as not covering.
    pub failed: usize,
    /// Runs of the scene, all fits together (and the truth's run).
    pub runs: usize,
    /// Wall time of the study, s.
    pub wall_time_s: f64,
    /// Whether the stop flag ended it (the counts are of the traces fitted before).
    pub stopped: bool,
}

impl Fit {
    /// The coverage study `req` of this fit: the truth is each parameter's value in the
    /// scene (with the `--set` overrides; the key's default when the file does not set
    /// it), the traces are the run at the truth on the fit's rows (the data's times, or
    /// the record-rate grid without data) plus normal noise of `req.noise` times each
    /// signal's RMS, weighted by `1 / sd` (the asked weights are not used), and each is
    /// fitted from the asked start values with the asked bounds. `progress(done)` is called
    /// as traces finish; `stop` ends the study (the counts are of the traces done).
    pub fn coverage(
        &self,
        req: &CoverageRequest,
        stop: Option<&AtomicBool>,
        progress: &mut (dyn FnMut(usize) + Send),
    ) -> Result<CoverageResult> {
        use rayon::prelude::*;
        let bad = |m: String| Error::BadInput(m);
        if req.traces == 0 {
            return Err(bad("--coverage: at least 1 trace".into()));
        }
        if !(req.noise.is_finite() && req.noise > 0.0 && req.noise < 1.0) {
            return Err(bad(format!(
                "--noise {}: a relative standard deviation in (0, 1) expected",
                req.noise
            )));
        }
        let started = Instant::now();
        let truth = self
            .params
            .iter()
            .map(|p| {
                let x = p.scene_value.ok_or_else(|| {
                    bad(format!(
                        "--coverage: {} has no value in the scene and no default (the truth)",
                        p.asked.key
                    ))
                })?;
                let u = p.to_internal(x);
                if !(p.lower..=p.upper).contains(&u) {
                    return Err(bad(format!(
                        "--coverage: the truth {} = {x} (the scene's value) lies outside \
                         the bounds asked",
                        p.asked.key
                    )));
                }
                Ok(x)
            })
            .collect::<Result<Vec<f64>>>()?;
        let exact = self.simulate(&truth, stop)?;
        let noise_sd: Vec<f64> = exact
            .iter()
            .zip(&self.signals)
            .map(|(y, (s, _))| {
                let rms = (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).sqrt();
                if rms > 0.0 && rms.is_finite() {
                    Ok(req.noise * rms)
                } else {
                    Err(bad(format!(
                        "--coverage: signal {} is {rms} (RMS) at the truth: a noise relative \
                         to it is not defined",
                        s.signal
                    )))
                }
            })
            .collect::<Result<_>>()?;
        let mut base = self.clone();
        for ((s, _), sd) in base.signals.iter_mut().zip(&noise_sd) {
            *s = FitSignal {
                weight: 1.0 / sd,
                ..s.clone()
            };
        }
        let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
        let done = Mutex::new((0usize, progress));
        let fits: Vec<Option<Result<super::FitResult>>> = (0..req.traces)
            .into_par_iter()
            .map(|i| {
                if stopped() {
                    return None;
                }
                let mut fit = base.clone();
                fit.measured = exact
                    .iter()
                    .zip(&noise_sd)
                    .enumerate()
                    .map(|(k, (y, sd))| {
                        let mut rng =
                            clutchpack_study::rng::Stream::new(req.seed, i as u64, k as u64);
                        y.iter().map(|v| v + sd * rng.standard_normal()).collect()
                    })
                    .collect();
                let r = fit.run(stop, &mut |_, _| {});
                if stopped() || r.as_ref().is_ok_and(|r| r.stopped) {
                    return None;
                }
                let mut d = done.lock().expect("no panic holds it");
                d.0 += 1;
                let n = d.0;
                (d.1)(n);
                Some(r)
            })
            .collect();
        let finished: Vec<&Result<super::FitResult>> = fits.iter().flatten().collect();
        let good: Vec<&super::FitResult> = finished
            .iter()
            .filter_map(|r| r.as_ref().ok())
            .filter(|r| r.converged)
            .collect();
        let failed = finished.len() - good.len();
        let runs = 1 + finished
            .iter()
            .filter_map(|r| r.as_ref().ok())
            .map(|r| r.runs)
            .sum::<usize>();
        let holds = |r: &super::FitResult, j: usize| {
            let p = &r.params[j];
            p.ci95_low <= truth[j] && truth[j] <= p.ci95_high
        };
        let params = self
            .params
            .iter()
            .enumerate()
            .map(|(j, p)| {
                let v: Vec<f64> = good.iter().map(|r| r.params[j].value).collect();
                let n = v.len().max(1) as f64;
                let mean = v.iter().sum::<f64>() / n;
                let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>()
                    / (v.len().max(2) - 1) as f64)
                    .sqrt();
                ParamCoverage {
                    key: p.asked.key.clone(),
                    unit: p.unit,
                    truth: truth[j],
                    covered: good.iter().filter(|r| holds(r, j)).count(),
                    fitted_mean: mean,
                    fitted_sd: sd,
                    std_error_mean: good.iter().map(|r| r.params[j].std_error).sum::<f64>() / n,
                }
            })
            .collect();
        let all_covered = good
            .iter()
            .filter(|r| (0..truth.len()).all(|j| holds(r, j)))
            .count();
        Ok(CoverageResult {
            scene: self.scene_name.clone(),
            engine: self.engine.name(),
            traces: req.traces,
            noise: req.noise,
            seed: req.seed,
            points: self.rows.len() * self.signals.len(),
            noise_sd,
            params,
            all_covered,
            failed,
            runs,
            wall_time_s: started.elapsed().as_secs_f64(),
            stopped: finished.len() < req.traces,
        })
    }
}
