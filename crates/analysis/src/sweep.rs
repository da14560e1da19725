//! Ensembles and parameter sweeps.
//!
//! A chaotic run is one sample (MODEL.md section 6). A sweep case is one parameter value run
//! as an ensemble: the same scene from several initial disc positions within the backlash,
//! or drive phases. Each member gives one list of [`DiscStats`]; [`sweep_rows`] reduces them
//! to a mean and spread per (value, disc), and [`sweep_fits`] fits the means against the
//! parameter (the paper's Fig 3 fits quadratics through single samples instead).

use crate::fit::{polyfit, FitError, PolyFit};
use crate::stats::DiscStats;
use serde::{Deserialize, Serialize};

/// Mean and spread of one quantity over the members of an ensemble, in its unit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Arithmetic mean.
    pub mean: f64,
    /// Sample standard deviation, `sqrt(sum (v - mean)^2 / (n - 1))`; 0 when `n <= 1`.
    pub std: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Number of values (ensemble members).
    pub n: usize,
}

impl Spread {
    /// The spread of `values` (all zeros with `n = 0` for an empty slice).
    pub fn of(values: &[f64]) -> Spread {
        let n = values.len();
        if n == 0 {
            return Spread {
                mean: 0.0,
                std: 0.0,
                min: 0.0,
                max: 0.0,
                n: 0,
            };
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let std = if n > 1 {
            (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        Spread {
            mean,
            std,
            min: values.iter().copied().fold(f64::INFINITY, f64::min),
            max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            n,
        }
    }
}

/// One value of a swept parameter, run as an ensemble.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepCase {
    /// The parameter value, in the parameter's unit (name it with the unit, e.g.
    /// `backlash_m`, where the sweep is tabulated or plotted).
    pub value: f64,
    /// One `Vec<DiscStats>` per ensemble member (from [`crate::stats::disc_stats`]).
    pub members: Vec<Vec<DiscStats>>,
}

/// The ensemble statistics of one disc at one parameter value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRow {
    /// The parameter value, in the parameter's unit.
    pub value: f64,
    /// Disc name.
    pub disc: String,
    /// Spread of [`DiscStats::max_positive_n`] over the members, N.
    pub max_positive: Spread,
    /// Spread of [`DiscStats::max_negative_n`] over the members, N (values `<= 0`).
    pub max_negative: Spread,
    /// Spread of [`DiscStats::p99_abs_n`] over the members, N.
    pub p99_abs: Spread,
    /// Spread of the impact count [`DiscStats::impacts`] over the members (a count).
    pub impacts: Spread,
}

/// One row per (case, disc): cases in the given order, and within a case the discs in the
/// order they first appear among its members (matched by name).
///
/// A member without a given disc does not count for it (`n` tells how many did). A case
/// without members gives no rows.
pub fn sweep_rows(cases: &[SweepCase]) -> Vec<SweepRow> {
    let mut rows = Vec::new();
    for case in cases {
        let mut discs: Vec<&str> = Vec::new();
        for s in case.members.iter().flatten() {
            if !discs.contains(&s.name.as_str()) {
                discs.push(&s.name);
            }
        }
        for disc in discs {
            let of_disc: Vec<&DiscStats> = case
                .members
                .iter()
                .filter_map(|m| m.iter().find(|s| s.name == disc))
                .collect();
            let spread = |f: fn(&DiscStats) -> f64| {
                Spread::of(&of_disc.iter().map(|s| f(s)).collect::<Vec<_>>())
            };
            rows.push(SweepRow {
                value: case.value,
                disc: disc.to_string(),
                max_positive: spread(|s| s.max_positive_n),
                max_negative: spread(|s| s.max_negative_n),
                p99_abs: spread(|s| s.p99_abs_n),
                impacts: spread(|s| s.impacts as f64),
            });
        }
    }
    rows
}

/// Per disc (in order of first appearance in `rows`), polynomial fits of degree `degree`
/// (2 for the paper's quadratics) of the ensemble **means** of the max positive and the max
/// negative peak (N) against the parameter value: `(disc, fit of max +, fit of max -)`,
/// ready for [`crate::plot::plot_sweep`].
///
/// Fitting the means is the least-squares fit of all members' values when every case has the
/// same number of members. Fails with the first disc's [`FitError`] (e.g. too few values).
pub fn sweep_fits(
    rows: &[SweepRow],
    degree: usize,
) -> Result<Vec<(String, PolyFit, PolyFit)>, FitError> {
    let mut discs: Vec<&str> = Vec::new();
    for r in rows {
        if !discs.contains(&r.disc.as_str()) {
            discs.push(&r.disc);
        }
    }
    discs
        .into_iter()
        .map(|disc| {
            let of: Vec<&SweepRow> = rows.iter().filter(|r| r.disc == disc).collect();
            let x: Vec<f64> = of.iter().map(|r| r.value).collect();
            let pos: Vec<f64> = of.iter().map(|r| r.max_positive.mean).collect();
            let neg: Vec<f64> = of.iter().map(|r| r.max_negative.mean).collect();
            Ok((
                disc.to_string(),
                polyfit(&x, &pos, degree)?,
                polyfit(&x, &neg, degree)?,
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn stats(name: &str, pos: f64, neg: f64, impacts: usize) -> DiscStats {
        DiscStats {
            max_positive_n: pos,
            max_negative_n: neg,
            p99_abs_n: pos.max(-neg),
            impacts,
            ..DiscStats::empty(name)
        }
    }

    /// Hand values: {2, 4, 4, 4, 5, 5, 7, 9} has mean 5, sum of squares 32, sample std
    /// sqrt(32 / 7); one value has std 0; none gives zeros.
    #[test]
    fn spread_of_hand_values() {
        let s = Spread::of(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_relative_eq!(s.mean, 5.0);
        assert_relative_eq!(s.std, (32.0f64 / 7.0).sqrt(), max_relative = 1e-15);
        assert_eq!((s.min, s.max, s.n), (2.0, 9.0, 8));
        let s = Spread::of(&[-3.5]);
        assert_eq!(
            (s.mean, s.std, s.min, s.max, s.n),
            (-3.5, 0.0, -3.5, -3.5, 1)
        );
        let s = Spread::of(&[]);
        assert_eq!((s.mean, s.std, s.min, s.max, s.n), (0.0, 0.0, 0.0, 0.0, 0));
    }

    /// Two cases of two-member ensembles become one row per (case, disc) with the members'
    /// spread; a member missing a disc does not count for it.
    #[test]
    fn rows_of_a_two_case_sweep() {
        let cases = vec![
            SweepCase {
                value: 10e-6,
                members: vec![
                    vec![stats("a", 100.0, -200.0, 10), stats("b", 50.0, -60.0, 4)],
                    vec![stats("a", 140.0, -100.0, 14)],
                ],
            },
            SweepCase {
                value: 20e-6,
                members: vec![vec![stats("a", 300.0, -400.0, 7)]],
            },
            SweepCase {
                value: 30e-6,
                members: vec![],
            },
        ];
        let rows = sweep_rows(&cases);
        assert_eq!(rows.len(), 3);
        assert_eq!((rows[0].value, rows[0].disc.as_str()), (10e-6, "a"));
        assert_eq!(rows[0].max_positive.mean, 120.0);
        assert_relative_eq!(rows[0].max_positive.std, 800.0f64.sqrt());
        assert_eq!(rows[0].max_negative.min, -200.0);
        assert_eq!(rows[0].max_negative.max, -100.0);
        assert_eq!(rows[0].p99_abs.mean, 170.0);
        assert_eq!(rows[0].impacts.mean, 12.0);
        assert_eq!(rows[1].disc, "b");
        assert_eq!(rows[1].max_positive.n, 1);
        assert_eq!(rows[2].value, 20e-6);
        assert_eq!(rows[2].max_negative.mean, -400.0);
        assert!(sweep_rows(&[]).is_empty());
    }

    /// Means lying on a quadratic are fitted exactly, per disc and per sign.
    #[test]
    fn fits_of_the_means() {
        let cases: Vec<SweepCase> = (0..5)
            .map(|i| {
                let b = i as f64 * 25e-6;
                let pos = 100.0 + 1e10 * b * b;
                SweepCase {
                    value: b,
                    members: vec![
                        vec![stats("a", pos - 5.0, -2.0 * pos, 1)],
                        vec![stats("a", pos + 5.0, -2.0 * pos, 1)],
                    ],
                }
            })
            .collect();
        let fits = sweep_fits(&sweep_rows(&cases), 2).unwrap();
        assert_eq!(fits.len(), 1);
        let (disc, p, n) = &fits[0];
        assert_eq!(disc, "a");
        assert_relative_eq!(p.coefficients[2], 1e10, max_relative = 1e-9);
        assert_relative_eq!(n.coefficients[0], -200.0, max_relative = 1e-9);
        assert!(sweep_fits(&sweep_rows(&cases[..2]), 2).is_err());
        assert!(sweep_fits(&[], 2).unwrap().is_empty());
    }
}
