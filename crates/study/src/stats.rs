//! Ensemble statistics: mean, standard deviation, extremes, the 95 % confidence interval of
//! the mean (Student's t), and Welch's interval for the difference of two means.

use serde::Serialize;

/// Two-sided 95 % quantiles `t_{0.975, nu}` of Student's t for nu = 1..=30 (standard tables,
/// e.g. NIST/SEMATECH e-Handbook 1.3.6.7.2, six digits).
const T975: [f64; 30] = [
    12.706205, 4.302653, 3.182446, 2.776445, 2.570582, 2.446912, 2.364624, 2.306004, 2.262157,
    2.228139, 2.200985, 2.178813, 2.160369, 2.144787, 2.131450, 2.119905, 2.109816, 2.100922,
    2.093024, 2.085963, 2.079614, 2.073873, 2.068658, 2.063899, 2.059539, 2.055529, 2.051831,
    2.048407, 2.045230, 2.042272,
];

/// `t_{0.975, nu}` for `nu >= 1` degrees of freedom (fractional for Welch): the table for
/// nu <= 30, interpolated linearly in `1 / nu` between integers; above 30 the Cornish-Fisher
/// expansion of t about the normal quantile z = 1.959964 to the 1/nu^4 term (Abramowitz &
/// Stegun 26.7.5), which is within 2e-6 of the tables there. NaN for nu < 1.
pub fn t975(nu: f64) -> f64 {
    if nu.is_nan() || nu < 1.0 {
        return f64::NAN;
    }
    if nu <= 30.0 {
        let lo = nu.floor();
        let hi = nu.ceil();
        let (tl, th) = (T975[lo as usize - 1], T975[hi as usize - 1]);
        if lo == hi {
            return tl;
        }
        let s = (1.0 / lo - 1.0 / nu) / (1.0 / lo - 1.0 / hi);
        return tl + s * (th - tl);
    }
    let z: f64 = 1.959_963_984_540_054;
    let (z2, z3, z5, z7, z9) = (z * z, z.powi(3), z.powi(5), z.powi(7), z.powi(9));
    let _ = z2;
    z + (z3 + z) / (4.0 * nu)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * nu * nu)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * nu.powi(3))
        + (79.0 * z9 + 776.0 * z7 + 1482.0 * z5 - 1920.0 * z3 - 945.0 * z) / (92160.0 * nu.powi(4))
}

/// Summary of an ensemble of values (one unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    /// Number of values.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation (n - 1); 0 for n = 1.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Half-width of the 95 % confidence interval of the mean, `t_{0.975, n-1} std / sqrt(n)`;
    /// NaN for n = 1 (one sample says nothing about the spread).
    pub ci95_half: f64,
}

impl Summary {
    /// Summary of `values` (NaN values are skipped). `None` when there is none.
    pub fn of(values: &[f64]) -> Option<Summary> {
        let v: Vec<f64> = values.iter().copied().filter(|x| !x.is_nan()).collect();
        let n = v.len();
        if n == 0 {
            return None;
        }
        let mean = v.iter().sum::<f64>() / n as f64;
        let var = if n > 1 {
            v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        let std = var.sqrt();
        Some(Summary {
            n,
            mean,
            std,
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            ci95_half: if n > 1 {
                t975((n - 1) as f64) * std / (n as f64).sqrt()
            } else {
                f64::NAN
            },
        })
    }
}

/// The difference `b - a` of two ensemble means with Welch's 95 % confidence interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Difference {
    /// `mean(b) - mean(a)`.
    pub delta: f64,
    /// Half-width of the 95 % interval, `t_{0.975, nu} se`.
    pub ci95_half: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub dof: f64,
    /// True when the interval excludes 0 (a two-sided test at the 5 % level).
    pub significant: bool,
}

/// Welch's interval for `mean(b) - mean(a)` (unequal variances): `se^2 = s_a^2/n_a +
/// s_b^2/n_b`, `nu = se^4 / ((s_a^2/n_a)^2/(n_a-1) + (s_b^2/n_b)^2/(n_b-1))`. `None` unless
/// both ensembles have at least two values. Two spreads of zero give a zero-width interval
/// (significant if the means differ at all).
pub fn welch(a: &Summary, b: &Summary) -> Option<Difference> {
    if a.n < 2 || b.n < 2 {
        return None;
    }
    let va = a.std * a.std / a.n as f64;
    let vb = b.std * b.std / b.n as f64;
    let se2 = va + vb;
    let delta = b.mean - a.mean;
    if se2 == 0.0 {
        return Some(Difference {
            delta,
            ci95_half: 0.0,
            dof: f64::INFINITY,
            significant: delta != 0.0,
        });
    }
    let dof = se2 * se2 / (va * va / (a.n - 1) as f64 + vb * vb / (b.n - 1) as f64);
    let half = t975(dof.max(1.0)) * se2.sqrt();
    Some(Difference {
        delta,
        ci95_half: half,
        dof,
        significant: delta.abs() > half,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_the_tables_and_join_smoothly() {
        assert_eq!(t975(1.0), 12.706205);
        assert_eq!(t975(10.0), 2.228139);
        // the expansion meets the table at 30 (table 2.042272) and gives the textbook values
        // t(40) = 2.021075, t(60) = 2.000298, t(120) = 1.979930 (NIST tables, 6 digits)
        assert!(
            (t975(30.000001) - 2.042272).abs() < 5e-6,
            "{}",
            t975(30.000001)
        );
        assert!((t975(40.0) - 2.021075).abs() < 2e-6);
        assert!((t975(60.0) - 2.000298).abs() < 2e-6);
        assert!((t975(120.0) - 1.979930).abs() < 2e-6);
        assert!(t975(1e9) - 1.959964 < 1e-6);
        // between integers it lies between the neighbours
        let t = t975(4.5);
        assert!(t < 2.776445 && t > 2.570582);
        assert!(t975(0.5).is_nan());
    }

    /// The summary of 1..=5: mean 3, std sqrt(2.5), CI half-width t(4) sqrt(2.5) / sqrt(5).
    #[test]
    fn summary_by_hand() {
        let s = Summary::of(&[3.0, 1.0, 5.0, 2.0, 4.0]).unwrap();
        assert_eq!((s.n, s.mean, s.min, s.max), (5, 3.0, 1.0, 5.0));
        assert!((s.std - 2.5f64.sqrt()).abs() < 1e-15);
        assert!((s.ci95_half - 2.776445 * (0.5f64).sqrt()).abs() < 1e-12);
        assert!(Summary::of(&[]).is_none());
        assert!(Summary::of(&[7.0]).unwrap().ci95_half.is_nan());
    }

    /// Welch by hand: a = {1, 2, 3} (mean 2, var 1), b = {2, 4, 6, 8} (mean 5, var 20/3):
    /// se^2 = 1/3 + 5/3 = 2, nu = 4 / ((1/3)^2/2 + (5/3)^2/3) = 4.3373...
    #[test]
    fn welch_by_hand() {
        let a = Summary::of(&[1.0, 2.0, 3.0]).unwrap();
        let b = Summary::of(&[2.0, 4.0, 6.0, 8.0]).unwrap();
        let d = welch(&a, &b).unwrap();
        assert_eq!(d.delta, 3.0);
        let nu = 4.0 / ((1.0f64 / 3.0).powi(2) / 2.0 + (5.0f64 / 3.0).powi(2) / 3.0);
        assert!((d.dof - nu).abs() < 1e-12);
        assert!((d.ci95_half - t975(nu) * 2f64.sqrt()).abs() < 1e-12);
        // 3 +- 2.7 * 1.41 = 3 +- 3.8: not significant
        assert!(!d.significant);
        let c = Summary::of(&[102.0, 104.0, 106.0, 108.0]).unwrap();
        assert!(welch(&a, &c).unwrap().significant);
    }
}
