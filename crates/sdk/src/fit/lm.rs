//! The least-squares solver of a fit: Levenberg-Marquardt with bounds, a forward-difference
//! Jacobian whose columns are evaluated as one batch (the caller runs them in parallel), a
//! stop flag that returns the best point so far, and the covariance of the estimate.
//!
//! The iteration is Algorithm 3.16 of K. Madsen, H. B. Nielsen and O. Tingleff, *Methods for
//! Non-Linear Least Squares Problems*, 2nd ed. (IMM, DTU, 2004): the step `h` solves
//! `(J^T J + lambda D) h = -J^T r` with Marquardt's scaling `D = diag(J^T J)` (D. W.
//! Marquardt, *SIAM J. Appl. Math.* 11 (1963) 431-441), the gain ratio `rho` of the actual
//! to the predicted decrease of `F = r^T r / 2` (eq 3.12 there) accepts or rejects it, and
//! `lambda` follows Nielsen's update (eq 3.13 there: `lambda * max(1/3, 1 - (2 rho - 1)^3)`
//! on success, `lambda * nu, nu * 2` on failure). Bounds are kept by projecting each trial
//! point onto the box (the predicted decrease is that of the projected step). The
//! covariance is `s^2 (J^T J)^-1` with `s^2 = SSR / (m - n)` (the linearised estimate, e.g.
//! Seber and Wild, *Nonlinear Regression*, Wiley 1989, section 2.1), the inverse taken
//! through the SVD of the column-equilibrated Jacobian so that a rank-deficient pair shows
//! as a correlation of +-1 and infinite errors instead of a failed inversion.

use crate::Result;
use nalgebra::{DMatrix, DVector};

/// The solver's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    /// Most iterations (trial steps, accepted or not).
    pub max_iterations: usize,
    /// Relative forward-difference step of the Jacobian (of the internal coordinate, ln x for
    /// a log-scale parameter).
    pub fd_step: f64,
    /// Converged when a step changes no internal coordinate by more than this relative to
    /// its size.
    pub x_tol: f64,
    /// Converged when an accepted step lowers the sum of squares by less than this fraction.
    pub f_tol: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            max_iterations: 100,
            fd_step: 1e-6,
            x_tol: 1e-8,
            f_tol: 1e-12,
        }
    }
}

/// Where the solver is, for progress reports.
#[derive(Debug, Clone, PartialEq)]
pub struct LmState {
    /// Iterations so far.
    pub iteration: usize,
    /// Residual evaluations (runs) so far.
    pub evaluations: usize,
    /// Sum of squares of the weighted residuals at the best point so far.
    pub ssr: f64,
    /// The best point so far, internal coordinates.
    pub u: Vec<f64>,
}

/// What the solver found.
#[derive(Debug, Clone)]
pub(crate) struct LmOutcome {
    /// The best point, internal coordinates.
    pub u: Vec<f64>,
    /// The residuals there.
    pub r: Vec<f64>,
    /// The residuals at the start point.
    pub r_start: Vec<f64>,
    /// The Jacobian there (`m x n`), if it was computed (not when stopped before).
    pub jacobian: Option<DMatrix<f64>>,
    /// Iterations.
    pub iterations: usize,
    /// Residual evaluations.
    pub evaluations: usize,
    /// Whether a convergence test was met (else the iterations ran out, the damping grew
    /// without bound, or the stop flag was set).
    pub converged: bool,
    /// Why it ended, in words.
    pub reason: String,
    /// Whether the stop flag ended it.
    pub stopped: bool,
}

/// A batch of residual evaluations: each point (internal coordinates) to its residual
/// vector, or the error of that evaluation.
pub(crate) type Evaluate<'a> = dyn FnMut(&[Vec<f64>]) -> Vec<Result<Vec<f64>>> + 'a;

/// Minimises `r(u)^T r(u)` over the box `[lower, upper]` from `u0` (inside it). `eval`
/// evaluates a batch of points (the Jacobian's columns are one batch); `stop` is polled
/// before each batch; `progress` is told after each.
pub(crate) fn minimize(
    u0: &[f64],
    lower: &[f64],
    upper: &[f64],
    opts: &LmOptions,
    eval: &mut Evaluate,
    stop: &dyn Fn() -> bool,
    progress: &mut dyn FnMut(&LmState),
) -> Result<LmOutcome> {
    let n = u0.len();
    let mut evaluations = 0usize;
    let one = |u: &[f64], evaluations: &mut usize, eval: &mut Evaluate| -> Result<Vec<f64>> {
        *evaluations += 1;
        eval(&[u.to_vec()]).pop().expect("one result per point")
    };
    let mut u = u0.to_vec();
    let mut r = one(&u, &mut evaluations, eval)?;
    let r_start = r.clone();
    let ssr = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
    let mut f = ssr(&r);
    let mut state = LmState {
        iteration: 0,
        evaluations,
        ssr: f,
        u: u.clone(),
    };
    progress(&state);
    let outcome = |u: Vec<f64>, r, jacobian, iterations, evaluations, converged, reason: &str| {
        Ok(LmOutcome {
            u,
            r,
            r_start: r_start.clone(),
            jacobian,
            iterations,
            evaluations,
            converged,
            reason: reason.to_string(),
            stopped: reason == STOPPED,
        })
    };
    if stop() {
        return outcome(u, r, None, 0, evaluations, false, STOPPED);
    }
    let mut jac = match jacobian(&u, &r, upper, opts.fd_step, eval, &mut evaluations) {
        Ok(Some(j)) => j,
        Ok(None) => {
            return Err(crate::Error::BadInput(
                "a fit needs at least one parameter".into(),
            ))
        }
        Err(_) if stop() => return outcome(u, r, None, 0, evaluations, false, STOPPED),
        Err(e) => return Err(e),
    };
    let (mut lambda, mut nu) = (1e-3, 2.0);
    let mut iteration = 0;
    loop {
        state.evaluations = evaluations;
        progress(&state);
        if stop() {
            return outcome(u, r, Some(jac), iteration, evaluations, false, STOPPED);
        }
        if iteration >= opts.max_iterations {
            let reason = format!("{} iterations without convergence", opts.max_iterations);
            return outcome(u, r, Some(jac), iteration, evaluations, false, &reason);
        }
        if lambda > 1e20 {
            return outcome(
                u,
                r,
                Some(jac),
                iteration,
                evaluations,
                false,
                "no step lowers the sum of squares (the damping grew without bound)",
            );
        }
        iteration += 1;
        let a = jac.transpose() * &jac;
        let g = jac.transpose() * DVector::from_column_slice(&r);
        let mut damped = a.clone();
        for j in 0..n {
            let d = a[(j, j)]
                .max(1e-12 * a.diagonal().max())
                .max(f64::MIN_POSITIVE);
            damped[(j, j)] += lambda * d;
        }
        let Some(chol) = damped.cholesky() else {
            lambda *= nu;
            nu *= 2.0;
            continue;
        };
        let h_free = chol.solve(&(-&g));
        let trial: Vec<f64> = (0..n)
            .map(|j| (u[j] + h_free[j]).clamp(lower[j], upper[j]))
            .collect();
        let h = DVector::from_iterator(n, (0..n).map(|j| trial[j] - u[j]));
        let small = (0..n).all(|j| h[j].abs() <= opts.x_tol * (u[j].abs() + opts.x_tol));
        if small {
            return outcome(
                u,
                r,
                Some(jac),
                iteration,
                evaluations,
                true,
                "the step became smaller than the tolerance",
            );
        }
        // predicted decrease of r^T r for the linearised model (twice MNT's L(0) - L(h))
        let predicted = -2.0 * h.dot(&g) - h.dot(&(&a * &h));
        let r_new = one(&trial, &mut evaluations, eval);
        let f_new = r_new.as_ref().map_or(f64::INFINITY, |r| ssr(r));
        let rho = if predicted > 0.0 {
            (f - f_new) / predicted
        } else {
            -1.0
        };
        if rho > 0.0 && f_new < f {
            let r_new = r_new.expect("finite cost: the run succeeded");
            let decrease = (f - f_new) / f.max(f64::MIN_POSITIVE);
            u = trial;
            r = r_new;
            f = f_new;
            state = LmState {
                iteration,
                evaluations,
                ssr: f,
                u: u.clone(),
            };
            if stop() {
                // the Jacobian of the new point is not computed: the best point is returned
                return outcome(u, r, None, iteration, evaluations, false, STOPPED);
            }
            jac = match jacobian(&u, &r, upper, opts.fd_step, eval, &mut evaluations) {
                Ok(j) => j.expect("n >= 1"),
                Err(_) if stop() => {
                    return outcome(u, r, None, iteration, evaluations, false, STOPPED)
                }
                Err(e) => return Err(e),
            };
            lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
            nu = 2.0;
            if decrease <= opts.f_tol {
                return outcome(
                    u,
                    r,
                    Some(jac),
                    iteration,
                    evaluations,
                    true,
                    "the sum of squares stopped decreasing",
                );
            }
        } else {
            lambda *= nu;
            nu *= 2.0;
        }
    }
}

/// The reason given when the stop flag ended the fit.
pub(crate) const STOPPED: &str = "stopped (the best point so far)";

/// The forward-difference Jacobian at `u` (residuals `r`): one batch of `n` evaluations,
/// each coordinate stepped by `fd_step` times its size (at least `fd_step`), backwards
/// where the forward step would leave the box or its run failed. `None` for `n = 0`.
fn jacobian(
    u: &[f64],
    r: &[f64],
    upper: &[f64],
    fd_step: f64,
    eval: &mut Evaluate,
    evaluations: &mut usize,
) -> Result<Option<DMatrix<f64>>> {
    let n = u.len();
    if n == 0 {
        return Ok(None);
    }
    let mut steps: Vec<f64> = (0..n)
        .map(|j| {
            let h = fd_step * u[j].abs().max(1.0);
            if u[j] + h > upper[j] {
                -h
            } else {
                h
            }
        })
        .collect();
    let point = |j: usize, h: f64| {
        let mut p = u.to_vec();
        p[j] += h;
        p
    };
    let points: Vec<Vec<f64>> = (0..n).map(|j| point(j, steps[j])).collect();
    let mut results = eval(&points);
    *evaluations += n;
    // a column whose run failed (a run can fail at one parameter value and not beside it:
    // the engine's step collapsing on an event at the run's end) is taken backwards
    let failed: Vec<usize> = (0..n).filter(|&j| results[j].is_err()).collect();
    if !failed.is_empty() {
        for &j in &failed {
            steps[j] = -steps[j];
        }
        *evaluations += failed.len();
        let again = eval(
            &failed
                .iter()
                .map(|&j| point(j, steps[j]))
                .collect::<Vec<_>>(),
        );
        for (&j, res) in failed.iter().zip(again) {
            results[j] = res;
        }
    }
    let mut jac = DMatrix::zeros(r.len(), n);
    for (j, res) in results.into_iter().enumerate() {
        let rj = res?;
        for i in 0..r.len() {
            jac[(i, j)] = (rj[i] - r[i]) / steps[j];
        }
    }
    Ok(Some(jac))
}

/// The linearised covariance of the estimate, internal coordinates: `s^2 (J^T J)^-1` with
/// `s^2 = ssr / dof`. A column of zeros (a parameter the residuals do not depend on) and the
/// directions the SVD finds singular give infinite variances; the result's correlations are
/// those of the pseudo-inverse of the column-equilibrated matrix.
pub(crate) struct Covariance {
    /// Standard error of each internal coordinate (infinite when not determined).
    pub std_error: Vec<f64>,
    /// Correlation matrix (`n x n`, 1 on the diagonal).
    pub correlation: Vec<Vec<f64>>,
}

/// Singular values below this fraction of the largest count as zero.
const RCOND_ZERO: f64 = 1e-12;

/// See [`Covariance`].
pub(crate) fn covariance(jac: &DMatrix<f64>, ssr: f64, dof: usize) -> Covariance {
    let n = jac.ncols();
    let s2 = ssr / dof.max(1) as f64;
    let norms: Vec<f64> = (0..n).map(|j| jac.column(j).norm()).collect();
    let mut scaled = jac.clone();
    for (j, &c) in norms.iter().enumerate() {
        if c > 0.0 {
            scaled.column_mut(j).scale_mut(1.0 / c);
        }
    }
    let svd = scaled.svd(false, true);
    let v_t = svd.v_t.expect("asked for V^T");
    let smax = svd.singular_values.max();
    // (D^-1 J^T J D^-1)^-1 = V S^-2 V^T over the nonzero singular values
    let mut inv = DMatrix::zeros(n, n);
    let mut singular_dirs = Vec::new();
    for (k, &s) in svd.singular_values.iter().enumerate() {
        let row = v_t.row(k);
        if s > RCOND_ZERO * smax && s > 0.0 {
            inv += row.transpose() * row / (s * s);
        } else {
            singular_dirs.push(row.transpose());
        }
    }
    let mut std_error = vec![0.0; n];
    for j in 0..n {
        let undetermined = norms[j] == 0.0
            || singular_dirs
                .iter()
                .any(|v: &DVector<f64>| v[j].abs() > 1e-6);
        std_error[j] = if undetermined {
            f64::INFINITY
        } else {
            (s2 * inv[(j, j)]).sqrt() / norms[j]
        };
    }
    let mut correlation = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..n {
            correlation[i][j] = if i == j {
                1.0
            } else if let Some(v) = singular_dirs
                .iter()
                .find(|v| v[i].abs() > 1e-6 && v[j].abs() > 1e-6)
            {
                // an exactly singular direction moves both together: fully correlated
                (v[i] * v[j]).signum()
            } else {
                let d = (inv[(i, i)] * inv[(j, j)]).sqrt();
                if d > 0.0 {
                    inv[(i, j)] / d
                } else {
                    0.0
                }
            };
        }
    }
    Covariance {
        std_error,
        correlation,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exponential decay `y = a exp(-b t)` of MNT's example 1.1, from exact data: the
    /// solver finds `(a, b) = (2, 0.5)` from `(1, 1)` to 1e-10 (the data are exact, the
    /// Jacobian's forward differences only slow the last steps), and the clamp holds a bound.
    #[test]
    fn fits_an_exponential_decay_and_keeps_bounds() {
        let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-0.5 * t).exp()).collect();
        let mut eval = |pts: &[Vec<f64>]| -> Vec<Result<Vec<f64>>> {
            pts.iter()
                .map(|p| {
                    Ok(t.iter()
                        .zip(&y)
                        .map(|(t, y)| p[0] * (-p[1] * t).exp() - y)
                        .collect())
                })
                .collect()
        };
        let o = minimize(
            &[1.0, 1.0],
            &[0.0, 0.0],
            &[10.0, 10.0],
            &LmOptions::default(),
            &mut eval,
            &|| false,
            &mut |_| {},
        )
        .unwrap();
        assert!(o.converged, "{}", o.reason);
        assert!(
            (o.u[0] - 2.0).abs() < 1e-10 && (o.u[1] - 0.5).abs() < 1e-10,
            "{:?}",
            o.u
        );
        // b held below its true value by its bound: the fit ends on the bound
        let o = minimize(
            &[1.0, 0.2],
            &[0.0, 0.0],
            &[10.0, 0.3],
            &LmOptions::default(),
            &mut eval,
            &|| false,
            &mut |_| {},
        )
        .unwrap();
        assert_eq!(o.u[1], 0.3);
    }

    /// A stop flag set before the first step returns the start point, marked stopped.
    #[test]
    fn a_stop_returns_the_best_point_so_far() {
        let mut eval = |pts: &[Vec<f64>]| -> Vec<Result<Vec<f64>>> {
            pts.iter().map(|p| Ok(vec![p[0] - 1.0])).collect()
        };
        let o = minimize(
            &[3.0],
            &[-10.0],
            &[10.0],
            &LmOptions::default(),
            &mut eval,
            &|| true,
            &mut |_| {},
        )
        .unwrap();
        assert!(o.stopped && o.u == [3.0] && o.evaluations == 1);
    }

    /// Two columns that only enter as a product (`y = a b t`): the covariance says so
    /// (correlation -1 in log coordinates, infinite errors), and an independent pair gets
    /// the closed form of a straight line's slope error `s / sqrt(sum t^2)`.
    #[test]
    fn covariance_flags_a_product_and_matches_a_line() {
        let t: Vec<f64> = (1..=10).map(f64::from).collect();
        // d(a b t)/d ln a = a b t = d(a b t)/d ln b: identical columns
        let jac = DMatrix::from_fn(10, 2, |i, _| 2.0 * t[i]);
        let c = covariance(&jac, 1.0, 8);
        assert!(c.std_error.iter().all(|s| s.is_infinite()));
        assert_eq!(c.correlation[0][1], -1.0);
        let line = DMatrix::from_fn(10, 1, |i, _| t[i]);
        let c = covariance(&line, 8.0, 8);
        let expected = 1.0 / t.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((c.std_error[0] - expected).abs() < 1e-12 * expected);
    }
}
