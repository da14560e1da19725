//! Least-squares polynomial fits (the paper's Fig 3 fits quadratics of the peak loads
//! against a parameter).
//!
//! # Theory
//! Given points `(x_i, y_i)`, `i = 1..m`, and a degree `d`, find `c_0..c_d` minimising
//! `sum_i (y_i - p(x_i))^2` with `p(x) = c_0 + c_1 x + ... + c_d x^d`.
//!
//! Sweep parameters are often tiny or far from zero (a backlash of `0..100e-6` m, a speed of
//! `1000..1100` rad/s), which makes the Vandermonde matrix `[x_i^k]` badly conditioned:
//! its columns differ by factors of `1e-4` per power, or are nearly parallel. So the fit is
//! made in the centred, scaled variable
//!
//! `u = (x - x_c) / x_s`, `x_c = (x_min + x_max) / 2`, `x_s = (x_max - x_min) / 2`,
//!
//! which lies in `[-1, 1]`: the matrix `V_ik = u_i^k` is well conditioned for low degrees.
//! `V a = y` is solved in the least-squares sense by the SVD of `V` (nalgebra), then the
//! coefficients are expanded back to powers of `x` with the binomial theorem:
//!
//! `c_j = sum_{k >= j} a_k x_s^(-k) C(k, j) (-x_c)^(k - j)`.
//!
//! The coefficient of determination is `R^2 = 1 - SS_res / SS_tot` with
//! `SS_res = sum (y_i - p(x_i))^2` and `SS_tot = sum (y_i - mean(y))^2` (`R^2 = 1` when all
//! `y_i` are equal: a constant is fitted exactly).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Why [`polyfit`] could not fit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// `x` and `y` differ in length.
    #[error("x has {x_len} values but y has {y_len}")]
    LengthMismatch {
        /// Length of `x`.
        x_len: usize,
        /// Length of `y`.
        y_len: usize,
    },
    /// Fewer points than coefficients.
    #[error("a degree-{degree} fit needs at least {needed} points, got {points}")]
    TooFewPoints {
        /// Points given.
        points: usize,
        /// The requested degree.
        degree: usize,
        /// `degree + 1`.
        needed: usize,
    },
    /// Fewer distinct `x` values than coefficients: the polynomial is not determined.
    #[error("a degree-{degree} fit needs at least {needed} distinct x values, got {distinct}")]
    TooFewDistinctX {
        /// Distinct `x` values given.
        distinct: usize,
        /// The requested degree.
        degree: usize,
        /// `degree + 1`.
        needed: usize,
    },
    /// A NaN or infinite value in the data.
    #[error("point {index} is not finite: x = {x}, y = {y}")]
    NonFinite {
        /// Index of the first bad point.
        index: usize,
        /// Its `x`.
        x: f64,
        /// Its `y`.
        y: f64,
    },
    /// The scaled Vandermonde matrix is numerically singular (a very high degree).
    #[error("the degree-{degree} fit is numerically singular (condition number {condition:e})")]
    IllConditioned {
        /// The requested degree.
        degree: usize,
        /// Ratio of the largest to the smallest singular value of the scaled matrix.
        condition: f64,
    },
}

/// A polynomial `p(x) = c0 + c1 x + c2 x^2 + ...` from [`polyfit`].
///
/// Units: `c_k` is in (unit of y) / (unit of x)^k.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PolyFit {
    /// `c0, c1, c2, ...`: the coefficient of `x^k` at index `k`.
    pub coefficients: Vec<f64>,
    /// Coefficient of determination of the fit on its data, `1 - SS_res / SS_tot`
    /// (1 for a perfect fit, and for constant data).
    pub r_squared: f64,
}

impl PolyFit {
    /// The polynomial at `x` (Horner's scheme), in the unit of the fitted `y`.
    pub fn eval(&self, x: f64) -> f64 {
        self.coefficients
            .iter()
            .rev()
            .fold(0.0, |acc, &c| acc * x + c)
    }

    /// The degree: the number of coefficients less one (0 for an empty polynomial).
    pub fn degree(&self) -> usize {
        self.coefficients.len().saturating_sub(1)
    }
}

/// Largest ratio of singular values accepted before a fit is called singular.
const MAX_CONDITION: f64 = 1e12;

/// Least-squares polynomial of degree `degree` through the points `(x[i], y[i])`.
///
/// Fits in the centred, scaled variable `u = (x - x_c) / x_s` with nalgebra's SVD and
/// expands back to powers of `x` (see the module's Theory): coefficients of an exact
/// quadratic in `x = 0..100e-6` come back to ~1e-12 relative.
///
/// Errors: [`FitError::LengthMismatch`], [`FitError::NonFinite`],
/// [`FitError::TooFewPoints`] (fewer than `degree + 1` points),
/// [`FitError::TooFewDistinctX`] and [`FitError::IllConditioned`].
pub fn polyfit(x: &[f64], y: &[f64], degree: usize) -> Result<PolyFit, FitError> {
    if x.len() != y.len() {
        return Err(FitError::LengthMismatch {
            x_len: x.len(),
            y_len: y.len(),
        });
    }
    if let Some(index) = (0..x.len()).find(|&i| !x[i].is_finite() || !y[i].is_finite()) {
        return Err(FitError::NonFinite {
            index,
            x: x[index],
            y: y[index],
        });
    }
    let needed = degree + 1;
    if x.len() < needed {
        return Err(FitError::TooFewPoints {
            points: x.len(),
            degree,
            needed,
        });
    }
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    if sorted.len() < needed {
        return Err(FitError::TooFewDistinctX {
            distinct: sorted.len(),
            degree,
            needed,
        });
    }

    // centre and scale: u in [-1, 1]
    let (x_min, x_max) = (sorted[0], sorted[sorted.len() - 1]);
    let x_c = 0.5 * (x_min + x_max);
    let x_s = if x_max > x_min {
        0.5 * (x_max - x_min)
    } else {
        1.0
    };
    let u: Vec<f64> = x.iter().map(|&xi| (xi - x_c) / x_s).collect();

    let m = x.len();
    let v = DMatrix::from_fn(m, needed, |i, k| u[i].powi(k as i32));
    let b = DVector::from_column_slice(y);
    let svd = v.svd(true, true);
    let s_max = svd.singular_values.max();
    let s_min = svd.singular_values.min();
    let condition = if s_min > 0.0 {
        s_max / s_min
    } else {
        f64::INFINITY
    };
    if condition > MAX_CONDITION {
        return Err(FitError::IllConditioned { degree, condition });
    }
    let a = svd
        .solve(&b, 0.0)
        .map_err(|_| FitError::IllConditioned { degree, condition })?;

    // residuals in the scaled basis (the accurate one)
    let y_mean = y.iter().sum::<f64>() / m as f64;
    let ss_tot: f64 = y.iter().map(|yi| (yi - y_mean).powi(2)).sum();
    let ss_res: f64 = u
        .iter()
        .zip(y)
        .map(|(&ui, &yi)| {
            let p = a.iter().rev().fold(0.0, |acc, &ak| acc * ui + ak);
            (yi - p).powi(2)
        })
        .sum();
    let r_squared = if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else {
        1.0
    };

    // back to powers of x: c_j = sum_{k>=j} a_k x_s^-k C(k, j) (-x_c)^(k-j)
    let mut coefficients = vec![0.0; needed];
    for (k, &ak) in a.iter().enumerate() {
        let scaled = ak / x_s.powi(k as i32);
        let mut binom = 1.0; // C(k, j), from j = 0
        for (j, c) in coefficients.iter_mut().enumerate().take(k + 1) {
            *c += scaled * binom * (-x_c).powi((k - j) as i32);
            binom = binom * (k - j) as f64 / (j + 1) as f64;
        }
    }
    Ok(PolyFit {
        coefficients,
        r_squared,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// An exact quadratic over a backlash-like range `0..100e-6` comes back with every
    /// coefficient to 1e-9 relative and R^2 = 1: the scaling removes the `1e-4`-per-power
    /// spread of the Vandermonde columns (unscaled, the condition number would be ~1e9).
    #[test]
    fn recovers_an_exact_quadratic_on_a_tiny_range() {
        let c = [350.0, -4.2e6, 9.1e10];
        let x: Vec<f64> = (0..11).map(|i| i as f64 * 10e-6).collect();
        let y: Vec<f64> = x.iter().map(|&x| c[0] + c[1] * x + c[2] * x * x).collect();
        let f = polyfit(&x, &y, 2).unwrap();
        assert_eq!(f.degree(), 2);
        for (got, want) in f.coefficients.iter().zip(c) {
            assert_relative_eq!(*got, want, max_relative = 1e-9);
        }
        assert!((f.r_squared - 1.0).abs() < 1e-12, "R^2 = {}", f.r_squared);
        let truth = c[0] + c[1] * 55e-6 + c[2] * 55e-6 * 55e-6;
        assert_relative_eq!(f.eval(55e-6), truth, max_relative = 1e-12);
    }

    /// The same far from zero (a speed of 1000..1100 rad/s), where the unscaled columns
    /// `1, x, x^2` are nearly parallel; the centring is what saves this one.
    #[test]
    fn recovers_an_exact_quadratic_far_from_zero() {
        let c = [-2.0e4, 35.0, -0.0175];
        let x: Vec<f64> = (0..6).map(|i| 1000.0 + 20.0 * i as f64).collect();
        let y: Vec<f64> = x.iter().map(|&x| c[0] + c[1] * x + c[2] * x * x).collect();
        let f = polyfit(&x, &y, 2).unwrap();
        for (got, want) in f.coefficients.iter().zip(c) {
            assert_relative_eq!(*got, want, max_relative = 1e-9);
        }
        assert!((f.r_squared - 1.0).abs() < 1e-12);
    }

    /// A noisy quadratic: with +-2 % deterministic pseudo-noise on 41 points the fit stays
    /// within a few per cent of the curve's coefficients and R^2 is high but below 1.
    #[test]
    fn fits_a_noisy_quadratic_reasonably() {
        let c = [100.0, 2.0e6, 3.0e10];
        let mut state = 12345u64;
        let mut noise = || {
            // xorshift64*: uniform in [-1, 1)
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            let r = state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
            r as f64 / (1u64 << 52) as f64 - 1.0
        };
        let x: Vec<f64> = (0..41).map(|i| i as f64 * 2.5e-6).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|&x| (c[0] + c[1] * x + c[2] * x * x) * (1.0 + 0.02 * noise()))
            .collect();
        let f = polyfit(&x, &y, 2).unwrap();
        for &xi in &x {
            let truth = c[0] + c[1] * xi + c[2] * xi * xi;
            assert_relative_eq!(f.eval(xi), truth, max_relative = 0.02);
        }
        assert_relative_eq!(f.coefficients[2], c[2], max_relative = 0.1);
        assert!(
            f.r_squared > 0.99 && f.r_squared < 1.0,
            "R^2 = {}",
            f.r_squared
        );
    }

    /// A straight line through noisy-free points and a constant: degrees 1 and 0.
    #[test]
    fn low_degrees() {
        let f = polyfit(&[1.0, 2.0, 3.0], &[3.0, 5.0, 7.0], 1).unwrap();
        assert_relative_eq!(f.coefficients[0], 1.0, epsilon = 1e-12);
        assert_relative_eq!(f.coefficients[1], 2.0, epsilon = 1e-12);
        // degree 0 is the mean; constant data has R^2 = 1 by definition
        let f = polyfit(&[1.0, 2.0], &[4.0, 6.0], 0).unwrap();
        assert_relative_eq!(f.coefficients[0], 5.0, epsilon = 1e-12);
        assert_eq!(f.r_squared, 0.0);
        let f = polyfit(&[3.0, 3.0], &[2.0, 2.0], 0).unwrap();
        assert_eq!(f.r_squared, 1.0);
        assert_relative_eq!(f.eval(100.0), 2.0, epsilon = 1e-12);
    }

    /// Bad input is an error naming the problem, never a panic.
    #[test]
    fn errors() {
        assert_eq!(
            polyfit(&[], &[], 2),
            Err(FitError::TooFewPoints {
                points: 0,
                degree: 2,
                needed: 3
            })
        );
        assert!(matches!(
            polyfit(&[1.0, 2.0], &[1.0], 1),
            Err(FitError::LengthMismatch { x_len: 2, y_len: 1 })
        ));
        assert!(matches!(
            polyfit(&[1.0, 2.0, 3.0], &[1.0, f64::NAN, 3.0], 1),
            Err(FitError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            polyfit(&[1.0, f64::INFINITY, 3.0], &[1.0, 2.0, 3.0], 1),
            Err(FitError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            polyfit(&[1.0, 1.0, 2.0, 2.0], &[1.0, 2.0, 3.0, 4.0], 2),
            Err(FitError::TooFewDistinctX { distinct: 2, .. })
        ));
        let x: Vec<f64> = (0..40).map(f64::from).collect();
        assert!(matches!(
            polyfit(&x, &x, 35),
            Err(FitError::IllConditioned { .. })
        ));
    }
}
