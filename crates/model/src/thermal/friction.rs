//! Friction coefficient against slip speed and temperature, `mu(v, T)`, as a 2-D table
//! (MODEL.md section 9, "Laws that feed back"; as Simscape's thermal clutches take it):
//! bilinear inside the grid, **clamped to the edge values** outside it (each axis held at its
//! first or last row, no extrapolation), so a run that leaves the measured range sees the
//! nearest measured coefficient and never a negative one.

/// Why a friction table cannot be built. Each message names the bad value and what was
/// expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrictionMapError {
    /// An axis has fewer than two points.
    #[error("the {axis} axis needs at least 2 points, found {len}")]
    TooShort {
        /// `speed` or `temperature`.
        axis: &'static str,
        /// Its length.
        len: usize,
    },
    /// An axis value is not finite or out of its domain.
    #[error("{axis} {index}: {value} {unit} is not finite and {expected}")]
    AxisValue {
        /// `speed` or `temperature`.
        axis: &'static str,
        /// Which point (from 0).
        index: usize,
        /// The value given.
        value: f64,
        /// `m/s` or `K`.
        unit: &'static str,
        /// What the axis needs: `>= 0` (speeds) or `> 0` (kelvin).
        expected: &'static str,
    },
    /// An axis does not strictly increase.
    #[error(
        "{axis} {index}: {value} {unit} does not exceed the one before it ({previous} {unit}): \
         the axis must strictly increase"
    )]
    AxisNotIncreasing {
        /// `speed` or `temperature`.
        axis: &'static str,
        /// Which point (from 0).
        index: usize,
        /// The value given.
        value: f64,
        /// The point before it.
        previous: f64,
        /// `m/s` or `K`.
        unit: &'static str,
    },
    /// A row of the grid does not have one value per temperature.
    #[error("row {row} of mu has {len} values, expected {expected} (one per temperature)")]
    RowLength {
        /// Which row (speed index, from 0).
        row: usize,
        /// Its length.
        len: usize,
        /// The expected length.
        expected: usize,
    },
    /// The grid does not have one row per speed.
    #[error("mu has {0} rows, expected {1} (one per speed)")]
    RowCount(usize, usize),
    /// A coefficient is not finite or negative.
    #[error("mu at speed {speed_index}, temperature {temperature_index} is {value}: expected finite and >= 0")]
    Mu {
        /// Row (speed index, from 0).
        speed_index: usize,
        /// Column (temperature index, from 0).
        temperature_index: usize,
        /// The value given.
        value: f64,
    },
}

/// `mu(v, T)` on a grid of slip speeds (m/s) and temperatures (K).
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionMap {
    /// Slip speeds at the effective radius, m/s, from >= 0, strictly increasing.
    speeds_m_s: Vec<f64>,
    /// Temperatures, K, strictly increasing.
    temperatures_k: Vec<f64>,
    /// `mu[i][j]` at `speeds_m_s[i]`, `temperatures_k[j]` (dimensionless, >= 0).
    mu: Vec<Vec<f64>>,
}

/// Checks one axis: at least 2 points, finite, above (or at) its lower bound, increasing.
fn check_axis(
    axis: &'static str,
    values: &[f64],
    unit: &'static str,
    zero_allowed: bool,
) -> Result<(), FrictionMapError> {
    if values.len() < 2 {
        return Err(FrictionMapError::TooShort {
            axis,
            len: values.len(),
        });
    }
    for (index, &value) in values.iter().enumerate() {
        let in_domain = if zero_allowed {
            value >= 0.0
        } else {
            value > 0.0
        };
        if !(value.is_finite() && in_domain) {
            return Err(FrictionMapError::AxisValue {
                axis,
                index,
                value,
                unit,
                expected: if zero_allowed { ">= 0" } else { "> 0" },
            });
        }
        if index > 0 && value <= values[index - 1] {
            return Err(FrictionMapError::AxisNotIncreasing {
                axis,
                index,
                value,
                previous: values[index - 1],
                unit,
            });
        }
    }
    Ok(())
}

/// The cell `i` (`x[i] <= x < x[i+1]`, clamped to the valid cells) and the fraction of the way
/// across it of `x`, itself clamped to the axis.
fn locate(axis: &[f64], x: f64) -> (usize, f64) {
    let n = axis.len();
    let x = x.clamp(axis[0], axis[n - 1]);
    let i = axis
        .partition_point(|&a| a <= x)
        .saturating_sub(1)
        .min(n - 2);
    (i, (x - axis[i]) / (axis[i + 1] - axis[i]))
}

/// A row's coefficient at the fraction `ft` across temperature cell `j`.
fn column(row: &[f64], j: usize, ft: f64) -> f64 {
    row[j] + ft * (row[j + 1] - row[j])
}

impl FrictionMap {
    /// Builds the map: `speeds_m_s` (m/s, >= 0, strictly increasing, at least 2),
    /// `temperatures_k` (K, > 0, strictly increasing, at least 2) and `mu[i][j]` at speed `i`
    /// and temperature `j`, each finite and >= 0.
    pub fn new(
        speeds_m_s: Vec<f64>,
        temperatures_k: Vec<f64>,
        mu: Vec<Vec<f64>>,
    ) -> Result<FrictionMap, FrictionMapError> {
        check_axis("speed", &speeds_m_s, "m/s", true)?;
        check_axis("temperature", &temperatures_k, "K", false)?;
        if mu.len() != speeds_m_s.len() {
            return Err(FrictionMapError::RowCount(mu.len(), speeds_m_s.len()));
        }
        for (speed_index, row) in mu.iter().enumerate() {
            if row.len() != temperatures_k.len() {
                return Err(FrictionMapError::RowLength {
                    row: speed_index,
                    len: row.len(),
                    expected: temperatures_k.len(),
                });
            }
            for (temperature_index, &value) in row.iter().enumerate() {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(FrictionMapError::Mu {
                        speed_index,
                        temperature_index,
                        value,
                    });
                }
            }
        }
        Ok(FrictionMap {
            speeds_m_s,
            temperatures_k,
            mu,
        })
    }

    /// `mu` at slip speed `v_m_s` (m/s; its magnitude is used, as [`crate::FrictionCurve`]
    /// does) and temperature `t_k` (K), dimensionless: bilinear in the cell that holds the
    /// point, each coordinate clamped to its axis first. Interpolated in temperature first,
    /// then in speed as [`crate::Table::value`] interpolates (the end rows returned as they
    /// are), so that [`Self::curve_at`] gives the same bits.
    pub fn mu(&self, v_m_s: f64, t_k: f64) -> f64 {
        let (j, ft) = locate(&self.temperatures_k, t_k);
        let at = |i: usize| column(&self.mu[i], j, ft);
        let (s, v) = (&self.speeds_m_s, v_m_s.abs());
        let n = s.len();
        if v <= s[0] {
            return at(0);
        }
        if v >= s[n - 1] {
            return at(n - 1);
        }
        let (i, fv) = locate(s, v);
        let (low, high) = (at(i), at(i + 1));
        low + fv * (high - low)
    }

    /// `mu(0, T)`: the coefficient that holds a locked interface at `t_k` (K).
    pub fn static_mu(&self, t_k: f64) -> f64 {
        self.mu(0.0, t_k)
    }

    /// The slip-speed curve `v -> mu(v, T)` at the temperature `t_k` (K), as the stack's
    /// faces take it ([`crate::FrictionCurve::Table`] on the map's speeds): each row's
    /// coefficient interpolated in temperature exactly as [`Self::mu`] does, so the curve
    /// gives [`Self::mu`]`(v, t_k)` bit for bit at every slip speed (linear between the rows,
    /// held beyond them).
    pub fn curve_at(&self, t_k: f64) -> crate::FrictionCurve {
        let (j, ft) = locate(&self.temperatures_k, t_k);
        let column = self.mu.iter().map(|row| column(row, j, ft)).collect();
        let table = crate::Table::new(self.speeds_m_s.clone(), column)
            .expect("a validated map's speeds increase and its coefficients are finite");
        crate::FrictionCurve::Table(table)
    }

    /// The slip speeds of the map, m/s (increasing, from >= 0).
    pub fn speeds_m_s(&self) -> &[f64] {
        &self.speeds_m_s
    }

    /// The temperatures of the map, K (increasing).
    pub fn temperatures_k(&self) -> &[f64] {
        &self.temperatures_k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rising curve that falls as the oil warms: 2 speeds x 3 temperatures.
    fn map() -> FrictionMap {
        FrictionMap::new(
            vec![0.0, 2.0],
            vec![313.15, 353.15, 393.15],
            vec![vec![0.12, 0.11, 0.10], vec![0.14, 0.12, 0.11]],
        )
        .unwrap()
    }

    /// At a grid point, the grid's value; mid-cell, the hand-computed bilinear value; outside,
    /// the edge's (1e-15 absolute: a few roundings).
    #[test]
    fn bilinear_inside_clamped_outside() {
        let m = map();
        assert!((m.mu(2.0, 353.15) - 0.12).abs() < 1e-15);
        assert!((m.mu(-2.0, 353.15) - 0.12).abs() < 1e-15, "|v| is used");
        // the centre of cell (0..2 m/s, 313.15..353.15 K): mean of its 4 corners
        let centre = (0.12 + 0.11 + 0.14 + 0.12) / 4.0;
        assert!((m.mu(1.0, 333.15) - centre).abs() < 1e-15);
        // a quarter across in v, three quarters in T, the second cell: by hand
        // low = 0.11 + 0.75 (0.10 - 0.11) = 0.1025, high = 0.12 + 0.75 (0.11 - 0.12) = 0.1125
        // mu = 0.1025 + 0.25 (0.1125 - 0.1025) = 0.105
        assert!((m.mu(0.5, 383.15) - 0.105).abs() < 1e-15);
        // clamped: beyond the fastest speed and the hottest temperature, below the coldest
        assert!((m.mu(50.0, 500.0) - 0.11).abs() < 1e-15);
        assert!((m.mu(50.0, 200.0) - 0.14).abs() < 1e-15);
        assert!((m.static_mu(250.0) - 0.12).abs() < 1e-15);
        assert!((m.mu(1.0, 1000.0) - 0.105).abs() < 1e-15);
    }

    /// The curve at a temperature is the map at that temperature, bit for bit, at every slip
    /// speed (on the rows, between them, beyond both ends, either sign).
    #[test]
    fn curve_at_a_temperature_is_the_map() {
        let m = map();
        for t in [250.0, 313.15, 330.0, 353.15, 371.3, 393.15, 450.0] {
            let c = m.curve_at(t);
            for v in [0.0, 0.3, 1.0, 1.7, 2.0, 3.5, -0.8] {
                assert_eq!(c.mu(v).to_bits(), m.mu(v, t).to_bits(), "v {v}, T {t}");
            }
            assert_eq!(c.static_mu(), m.static_mu(t));
        }
    }

    /// Bad grids are refused, each error naming the value and what was expected.
    #[test]
    fn bad_grids_are_refused_with_the_value() {
        let e = |s: Vec<f64>, t: Vec<f64>, m: Vec<Vec<f64>>| {
            FrictionMap::new(s, t, m).unwrap_err().to_string()
        };
        let good_t = vec![300.0, 400.0];
        let good_m = vec![vec![0.1, 0.1], vec![0.1, 0.1]];
        let msg = e(vec![0.0], good_t.clone(), good_m.clone());
        assert!(
            msg.contains("speed axis needs at least 2 points, found 1"),
            "{msg}"
        );
        let msg = e(vec![0.0, 0.0], good_t.clone(), good_m.clone());
        assert!(msg.contains("speed 1: 0 m/s does not exceed"), "{msg}");
        let msg = e(vec![-1.0, 1.0], good_t.clone(), good_m.clone());
        assert!(
            msg.contains("speed 0: -1 m/s") && msg.contains(">= 0"),
            "{msg}"
        );
        let msg = e(vec![0.0, 1.0], vec![0.0, 400.0], good_m.clone());
        assert!(
            msg.contains("temperature 0: 0 K") && msg.contains("> 0"),
            "{msg}"
        );
        let msg = e(vec![0.0, 1.0], good_t.clone(), vec![vec![0.1, 0.1]]);
        assert!(msg.contains("mu has 1 rows, expected 2"), "{msg}");
        let msg = e(
            vec![0.0, 1.0],
            good_t.clone(),
            vec![vec![0.1], vec![0.1, 0.1]],
        );
        assert!(
            msg.contains("row 0 of mu has 1 values, expected 2"),
            "{msg}"
        );
        let msg = e(
            vec![0.0, 1.0],
            good_t,
            vec![vec![0.1, 0.1], vec![0.1, -0.05]],
        );
        assert!(
            msg.contains("speed 1, temperature 1 is -0.05") && msg.contains(">= 0"),
            "{msg}"
        );
    }
}
