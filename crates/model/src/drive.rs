//! Shaft drives (MODEL.md section 3): the paper's sine (eq 3), a sum of harmonics with phases,
//! and tabulated speed or torque histories.

use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// One harmonic of a speed profile: `A sin(2 pi f t + phase)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Harmonic {
    /// Amplitude `A` in rad/s.
    pub amplitude_rad_s: f64,
    /// Frequency `f` in Hz (> 0).
    pub frequency_hz: f64,
    /// Phase in rad.
    pub phase_rad: f64,
}

impl Harmonic {
    /// `cos(phase)`, the constant of the angle's integral: 1 without a call for the usual
    /// zero phase (exactly what `cos(0)` returns; the call was 4 % of a brake pack's run).
    pub fn cos_phase(&self) -> f64 {
        if self.phase_rad == 0.0 {
            1.0
        } else {
            self.phase_rad.cos()
        }
    }
}

/// A piecewise-linear table `y(t)`, held constant beyond its ends.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Table {
    /// Strictly increasing times in s.
    pub t_s: Vec<f64>,
    /// Values at those times (unit given by the owner).
    pub y: Vec<f64>,
    /// Running integral of `y` from `t_s[0]` to each knot (unit of `y` times s).
    integral: Vec<f64>,
    /// Each row's value held until the next row (a zero-order hold) instead of linear
    /// interpolation ([`Table::held`]).
    #[serde(default)]
    pub hold: bool,
}

/// Why a table is not usable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TableError {
    /// Fewer than two rows.
    #[error("a table needs at least 2 rows, found {0}")]
    TooShort(usize),
    /// Times and values differ in length.
    #[error("{0} times but {1} values")]
    LengthMismatch(usize, usize),
    /// A value is NaN or infinite.
    #[error("row {0}: value is not finite")]
    NotFinite(usize),
    /// Times do not increase.
    #[error("row {0}: time {1} s does not increase over the row before")]
    NotIncreasing(usize, f64),
}

impl Table {
    /// Builds a table from knots; times must be finite and strictly increasing.
    pub fn new(t_s: Vec<f64>, y: Vec<f64>) -> Result<Table, TableError> {
        if t_s.len() != y.len() {
            return Err(TableError::LengthMismatch(t_s.len(), y.len()));
        }
        if t_s.len() < 2 {
            return Err(TableError::TooShort(t_s.len()));
        }
        for i in 0..t_s.len() {
            if !t_s[i].is_finite() || !y[i].is_finite() {
                return Err(TableError::NotFinite(i));
            }
            if i > 0 && t_s[i] <= t_s[i - 1] {
                return Err(TableError::NotIncreasing(i, t_s[i]));
            }
        }
        let mut integral = vec![0.0; t_s.len()];
        for i in 1..t_s.len() {
            integral[i] = integral[i - 1] + 0.5 * (y[i] + y[i - 1]) * (t_s[i] - t_s[i - 1]);
        }
        Ok(Table {
            t_s,
            y,
            integral,
            hold: false,
        })
    }

    /// The same rows, each value held until the next row (a zero-order hold, as a
    /// co-simulation master gives its inputs): a step function, right-continuous at the rows.
    pub fn held(mut self) -> Table {
        self.hold = true;
        for i in 1..self.t_s.len() {
            self.integral[i] =
                self.integral[i - 1] + self.y[i - 1] * (self.t_s[i] - self.t_s[i - 1]);
        }
        self
    }

    fn segment(&self, t: f64) -> usize {
        // index i with t_s[i] <= t < t_s[i+1], clamped to the valid segments
        let i = self.t_s.partition_point(|&x| x <= t);
        i.saturating_sub(1).min(self.t_s.len() - 2)
    }

    /// Linearly interpolated value at `t` (held beyond the ends; with [`Table::hold`], the
    /// value of the last row at or before `t`).
    pub fn value(&self, t: f64) -> f64 {
        let n = self.t_s.len();
        if t <= self.t_s[0] {
            return self.y[0];
        }
        if t >= self.t_s[n - 1] {
            return self.y[n - 1];
        }
        let i = self.segment(t);
        if self.hold {
            return self.y[i];
        }
        let w = (t - self.t_s[i]) / (self.t_s[i + 1] - self.t_s[i]);
        self.y[i] + w * (self.y[i + 1] - self.y[i])
    }

    /// Slope `dy/dt` at `t` (0 beyond the ends; the right-hand slope at a knot).
    pub fn slope(&self, t: f64) -> f64 {
        let n = self.t_s.len();
        if self.hold || t < self.t_s[0] || t >= self.t_s[n - 1] {
            return 0.0;
        }
        let i = self.segment(t);
        (self.y[i + 1] - self.y[i]) / (self.t_s[i + 1] - self.t_s[i])
    }

    /// Exact integral of the interpolant from 0 to `t` (values before `t_s[0]` held).
    pub fn integral_from_zero(&self, t: f64) -> f64 {
        self.integral_to(t) - self.integral_to(0.0)
    }

    fn integral_to(&self, t: f64) -> f64 {
        let n = self.t_s.len();
        if t <= self.t_s[0] {
            return (t - self.t_s[0]) * self.y[0];
        }
        if t >= self.t_s[n - 1] {
            return self.integral[n - 1] + (t - self.t_s[n - 1]) * self.y[n - 1];
        }
        let i = self.segment(t);
        if self.hold {
            return self.integral[i] + self.y[i] * (t - self.t_s[i]);
        }
        let v = self.value(t);
        self.integral[i] + 0.5 * (self.y[i] + v) * (t - self.t_s[i])
    }
}

/// A shaft speed history `omega(t)` in rad/s, with `theta(0) = 0`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum SpeedProfile {
    /// `omega_0 + sum_k A_k sin(2 pi f_k t + phase_k)`; the paper's eq (3) is one harmonic
    /// with zero phase.
    Harmonics {
        /// Mean speed `omega_0` in rad/s.
        omega0_rad_s: f64,
        /// The harmonics.
        harmonics: Vec<Harmonic>,
    },
    /// Tabulated speed in rad/s, linear between rows.
    Table(Table),
    /// A speed held from `t0_s` on (a co-simulation input between two communication points,
    /// `crate::session`), with an optional slope and curvature (first- or second-order hold):
    /// `omega = speed + accel tau + jerk tau^2 / 2`, `theta = angle0 + speed tau + accel tau^2
    /// / 2 + jerk tau^3 / 6`, `tau = t - t0`. Valid for `t >= t0_s` only (engines never ask
    /// earlier).
    Held {
        /// Start of the hold, s.
        t0_s: f64,
        /// Shaft angle at `t0_s`, rad.
        angle0_rad: f64,
        /// The speed at `t0_s`, rad/s.
        speed_rad_s: f64,
        /// The speed's slope at `t0_s`, rad/s^2 (0: a zero-order hold).
        accel_rad_s2: f64,
        /// The speed's second derivative over the hold, rad/s^3 (0: at most first order).
        jerk_rad_s3: f64,
    },
}

impl SpeedProfile {
    /// The paper's drive, eq (3): `omega_0 + A sin(2 pi f t)`.
    pub fn sine(omega0_rad_s: f64, amplitude_rad_s: f64, frequency_hz: f64) -> SpeedProfile {
        SpeedProfile::Harmonics {
            omega0_rad_s,
            harmonics: vec![Harmonic {
                amplitude_rad_s,
                frequency_hz,
                phase_rad: 0.0,
            }],
        }
    }

    /// Shaft speed in rad/s at `t` s (Hu et al. eq (3) for one harmonic).
    pub fn speed(&self, t: f64) -> f64 {
        match self {
            SpeedProfile::Harmonics {
                omega0_rad_s,
                harmonics,
            } => {
                omega0_rad_s
                    + harmonics
                        .iter()
                        .map(|h| h.amplitude_rad_s * (TAU * h.frequency_hz * t + h.phase_rad).sin())
                        .sum::<f64>()
            }
            SpeedProfile::Table(tab) => tab.value(t),
            SpeedProfile::Held {
                t0_s,
                speed_rad_s,
                accel_rad_s2,
                jerk_rad_s3,
                ..
            } => {
                let tau = t - t0_s;
                speed_rad_s + accel_rad_s2 * tau + 0.5 * jerk_rad_s3 * tau * tau
            }
        }
    }

    /// Shaft angle in rad at `t` s: the exact integral of [`Self::speed`] from 0.
    pub fn angle(&self, t: f64) -> f64 {
        match self {
            SpeedProfile::Harmonics {
                omega0_rad_s,
                harmonics,
            } => {
                omega0_rad_s * t
                    + harmonics
                        .iter()
                        .map(|h| {
                            let w = TAU * h.frequency_hz;
                            h.amplitude_rad_s / w * (h.cos_phase() - (w * t + h.phase_rad).cos())
                        })
                        .sum::<f64>()
            }
            SpeedProfile::Table(tab) => tab.integral_from_zero(t),
            SpeedProfile::Held {
                t0_s,
                angle0_rad,
                speed_rad_s,
                accel_rad_s2,
                jerk_rad_s3,
            } => {
                let tau = t - t0_s;
                angle0_rad
                    + tau * (speed_rad_s + tau * (0.5 * accel_rad_s2 + tau * jerk_rad_s3 / 6.0))
            }
        }
    }

    /// Shaft speed (rad/s) and angle (rad) at `t` s, bit for bit [`Self::speed`] and
    /// [`Self::angle`], in one pass: each harmonic's sine and cosine of the one phase
    /// `2 pi f t + phase` come from one `sincos` (the compiler fuses the pair), where the two
    /// calls paid for two range reductions. The engines ask for both at every sub-step stage.
    pub fn speed_and_angle(&self, t: f64) -> (f64, f64) {
        match self {
            SpeedProfile::Harmonics {
                omega0_rad_s,
                harmonics,
            } => {
                // the sums as `Iterator::sum` forms them (from -0.0, in order), so that both
                // values are those of `speed` and `angle` to the bit
                let (mut speed, mut angle) = (-0.0, -0.0);
                for h in harmonics {
                    let w = TAU * h.frequency_hz;
                    let (sin, cos) = (w * t + h.phase_rad).sin_cos();
                    speed += h.amplitude_rad_s * sin;
                    angle += h.amplitude_rad_s / w * (h.cos_phase() - cos);
                }
                (omega0_rad_s + speed, omega0_rad_s * t + angle)
            }
            _ => (self.speed(t), self.angle(t)),
        }
    }

    /// Shaft speed (rad/s) and angular acceleration (rad/s^2) at `t` s, bit for bit
    /// [`Self::speed`] and [`Self::acceleration`], in one pass: each harmonic's
    /// `A sin(theta)` (eq 3) and `2 pi f A cos(theta)` (eq 4) of the one phase
    /// `theta = 2 pi f t + phase` from one `sincos`, where the two calls paid for two range
    /// reductions. The reference engine asks for both at every stage of every step (its
    /// right-hand side: a disc's carrier speed and acceleration; issue 46, 27 % of the paper
    /// case's time was in `sin` and `cos`).
    pub fn speed_and_acceleration(&self, t: f64) -> (f64, f64) {
        match self {
            SpeedProfile::Harmonics {
                omega0_rad_s,
                harmonics,
            } => {
                // the sums as `Iterator::sum` forms them (from -0.0, in order), so that both
                // values are those of `speed` and `acceleration` to the bit
                let (mut speed, mut accel) = (-0.0, -0.0);
                for h in harmonics {
                    let w = TAU * h.frequency_hz;
                    let (sin, cos) = (w * t + h.phase_rad).sin_cos();
                    speed += h.amplitude_rad_s * sin;
                    accel += h.amplitude_rad_s * w * cos;
                }
                (omega0_rad_s + speed, accel)
            }
            _ => (self.speed(t), self.acceleration(t)),
        }
    }

    /// The profile expanded about `t_m` (s) for evaluations within `reach_s` of it
    /// ([`LocalProfile`]), or `None` for a table, a held speed (no trigonometry to save) or
    /// harmonics too fast for the series within the reach (`2 pi f reach` beyond about 0.7
    /// rad: 0.1 ms reaches 1.1 kHz).
    pub fn local(&self, t_m: f64, reach_s: f64) -> Option<LocalProfile> {
        self.local_reusing(t_m, reach_s, None)
    }

    /// [`SpeedProfile::local`] reusing `old`'s buffer (a previous expansion's, `None`: a new
    /// one), so that a loop expanding the profile at every step does not allocate.
    pub fn local_reusing(
        &self,
        t_m: f64,
        reach_s: f64,
        old: Option<LocalProfile>,
    ) -> Option<LocalProfile> {
        let SpeedProfile::Harmonics {
            omega0_rad_s,
            harmonics,
        } = self
        else {
            return None;
        };
        let x_max = harmonics
            .iter()
            .map(|h| (TAU * h.frequency_hz * reach_s).abs())
            .fold(0.0, f64::max);
        // the fewest terms whose first left out is below the truncation
        let (mut k, mut next) = (1, x_max * x_max / 6.0);
        while next > SERIES_TRUNCATION {
            if k == SERIES_TERMS_MAX || !next.is_finite() {
                return None;
            }
            k += 1;
            next *= x_max * x_max / ((2 * k) as f64 * (2 * k + 1) as f64);
        }
        let (speed_m, angle_m) = self.speed_and_angle(t_m);
        let mut terms = old.map(|o| o.terms).unwrap_or_default();
        terms.clear();
        terms.extend(harmonics.iter().map(|h| {
            let w = TAU * h.frequency_hz;
            let (sin_m, cos_m) = (w * t_m + h.phase_rad).sin_cos();
            [w, h.amplitude_rad_s, h.amplitude_rad_s / w, sin_m, cos_m]
        }));
        Some(LocalProfile {
            t_m,
            speed_m,
            angle_m,
            omega0: *omega0_rad_s,
            terms,
            series_terms: k,
        })
    }

    /// Shaft angular acceleration in rad/s^2 at `t` s (the `2 pi f A cos(2 pi f t)` of eq (4)).
    pub fn acceleration(&self, t: f64) -> f64 {
        match self {
            SpeedProfile::Harmonics { harmonics, .. } => harmonics
                .iter()
                .map(|h| {
                    let w = TAU * h.frequency_hz;
                    h.amplitude_rad_s * w * (w * t + h.phase_rad).cos()
                })
                .sum(),
            SpeedProfile::Table(tab) => tab.slope(t),
            SpeedProfile::Held {
                t0_s,
                accel_rad_s2,
                jerk_rad_s3,
                ..
            } => accel_rad_s2 + jerk_rad_s3 * (t - t0_s),
        }
    }
}

/// A harmonic speed profile expanded about one time `t_m`, for the many evaluations an
/// integrator's sub-steps make within `reach` of it (a world step of the multibody engine:
/// every stage of every sub-step of every disc asks for the shaft's speed and angle there).
///
/// Each harmonic's phase at `t_m`, `theta_m = 2 pi f t_m + phase`, is evaluated once
/// (`sincos`); at `t = t_m + tau` the addition theorems give
/// `sin(theta_m + x) = sin(theta_m) + cos(theta_m) sin x - sin(theta_m) (1 - cos x)` and
/// `cos(theta_m) - cos(theta_m + x) = cos(theta_m) (1 - cos x) + sin(theta_m) sin x` with
/// `x = 2 pi f tau`, and `sin x`, `1 - cos x` from their Taylor series, short since `|x|`
/// is small (Abramowitz and Stegun 4.3.65, 4.3.66): [`SpeedProfile::speed`] and
/// [`SpeedProfile::angle`] to rounding (a few ulps, no cancellation in `1 - cos x`), without
/// the libm calls that were 15 % of a 16-disc brake pack's run. As the exact forms, the
/// speed is `omega_0 + sum_k A_k sin(theta_k)` (Hu et al. eq (3) for one harmonic) and the
/// angle its exact integral from 0.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalProfile {
    /// The expansion's time `t_m`, s, and the profile's speed (rad/s) and angle (rad) there.
    t_m: f64,
    speed_m: f64,
    angle_m: f64,
    /// The mean speed `omega_0`, rad/s.
    omega0: f64,
    /// Each harmonic: `2 pi f` (rad/s), `A` (rad/s), `A / (2 pi f)` (rad), and the sine and
    /// cosine of its phase at `t_m`.
    terms: Vec<[f64; 5]>,
    /// Terms of the two series kept ([`SERIES_TERMS_MAX`] at most).
    series_terms: usize,
}

/// At most this many terms of each series (`sin x` to `x^15`, `1 - cos x` to `x^16`).
const SERIES_TERMS_MAX: usize = 8;

/// `(-1)^k / (2k + 1)!`, the series of `sin x / x` in `x^2`.
const SIN_SERIES: [f64; SERIES_TERMS_MAX] = [
    1.0,
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
];

/// `(-1)^k / (2k + 2)!`, the series of `(1 - cos x) / x^2` in `x^2`.
const VERSINE_SERIES: [f64; SERIES_TERMS_MAX] = [
    1.0 / 2.0,
    -1.0 / 24.0,
    1.0 / 720.0,
    -1.0 / 40_320.0,
    1.0 / 3_628_800.0,
    -1.0 / 479_001_600.0,
    1.0 / 87_178_291_200.0,
    -1.0 / 20_922_789_888_000.0,
];

/// The series stop where the first term left out is below this fraction of the first kept
/// (1e-17, a tenth of the rounding of a double): `x_max^(2k) / (2k + 1)! <= 1e-17` with `k`
/// terms of `sin x` (and less for `1 - cos x`).
const SERIES_TRUNCATION: f64 = 1e-17;

impl LocalProfile {
    /// The profile's speed (rad/s) and angle (rad) at `t` (s), within the reach the expansion
    /// was made for.
    #[inline]
    pub fn speed_and_angle(&self, t: f64) -> (f64, f64) {
        // the series' length a constant of each arm: the loops unrolled (the count was a
        // tenth of an evaluation's instructions), the sums the same
        match self.series_terms {
            1 => self.speed_and_angle_in::<1>(t),
            2 => self.speed_and_angle_in::<2>(t),
            3 => self.speed_and_angle_in::<3>(t),
            4 => self.speed_and_angle_in::<4>(t),
            5 => self.speed_and_angle_in::<5>(t),
            6 => self.speed_and_angle_in::<6>(t),
            7 => self.speed_and_angle_in::<7>(t),
            _ => self.speed_and_angle_in::<SERIES_TERMS_MAX>(t),
        }
    }

    /// [`Self::speed_and_angle`] with `N` terms of each series (`series_terms`).
    #[inline(always)]
    fn speed_and_angle_in<const N: usize>(&self, t: f64) -> (f64, f64) {
        let tau = t - self.t_m;
        let (mut speed, mut angle) = (0.0, 0.0);
        for &[w, a, a_w, sin_m, cos_m] in &self.terms {
            let x = w * tau;
            let y = x * x;
            let (mut s, mut v) = (0.0, 0.0);
            for k in (0..N).rev() {
                s = SIN_SERIES[k] + y * s;
                v = VERSINE_SERIES[k] + y * v;
            }
            // sin x and 1 - cos x
            let (sin_x, versine) = (x * s, y * v);
            speed += a * (cos_m * sin_x - sin_m * versine);
            angle += a_w * (cos_m * versine + sin_m * sin_x);
        }
        (
            self.speed_m + speed,
            self.angle_m + (self.omega0 * tau + angle),
        )
    }
}

/// What drives an inertial shaft (eq 4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ShaftExcitation {
    /// Hu et al. eq (4): drive torque `J1 * d(omega_profile)/dt`, the shaft starting at the
    /// profile's speed.
    Profile(SpeedProfile),
    /// A tabulated drive torque in N m (positive along the positive rotation).
    Torque {
        /// The torque history, N m.
        table: Table,
        /// Shaft speed at t = 0, rad/s.
        initial_speed_rad_s: f64,
    },
    /// A drive torque held from `t0_s` on (a co-simulation input between two communication
    /// points, `crate::session`), with an optional slope (first-order hold): `T = torque +
    /// rate (t - t0)`.
    Held {
        /// Start of the hold, s.
        t0_s: f64,
        /// The torque at `t0_s`, N m (positive along the positive rotation).
        torque_n_m: f64,
        /// Its slope over the hold, N m/s (0: a zero-order hold).
        rate_n_m_s: f64,
        /// Shaft speed at t = 0, rad/s.
        initial_speed_rad_s: f64,
    },
}

impl ShaftExcitation {
    /// The shaft's speed at t = 0 this drive starts it at, rad/s.
    pub fn initial_speed_rad_s(&self) -> f64 {
        match self {
            ShaftExcitation::Profile(p) => p.speed(0.0),
            ShaftExcitation::Torque {
                initial_speed_rad_s,
                ..
            }
            | ShaftExcitation::Held {
                initial_speed_rad_s,
                ..
            } => *initial_speed_rad_s,
        }
    }
}

/// The shaft model (MODEL.md section 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shaft {
    /// The shaft follows a speed history whatever the load (eq 3).
    Prescribed(SpeedProfile),
    /// The shaft is a body: `J1 omega' = T_drive + n F Rb - C1 omega` summed over couplings (eq 4).
    Inertial {
        /// `J1` in kg m^2 (> 0).
        inertia_kg_m2: f64,
        /// `C1` in N m s/rad (>= 0).
        damping_n_m_s_rad: f64,
        /// The drive.
        excitation: ShaftExcitation,
    },
}

impl Shaft {
    /// Shaft speed at t = 0 in rad/s.
    pub fn initial_speed_rad_s(&self) -> f64 {
        match self {
            Shaft::Prescribed(p) => p.speed(0.0),
            Shaft::Inertial { excitation, .. } => excitation.initial_speed_rad_s(),
        }
    }

    /// Drive torque on an inertial shaft in N m at `t` (0 for a prescribed shaft).
    pub fn drive_torque_n_m(&self, t: f64) -> f64 {
        match self {
            Shaft::Prescribed(_) => 0.0,
            Shaft::Inertial {
                inertia_kg_m2,
                excitation,
                ..
            } => match excitation {
                // Hu et al. eq (4): J1 * 2 pi f A cos(2 pi f t)
                ShaftExcitation::Profile(p) => inertia_kg_m2 * p.acceleration(t),
                ShaftExcitation::Torque { table, .. } => table.value(t),
                ShaftExcitation::Held {
                    t0_s,
                    torque_n_m,
                    rate_n_m_s,
                    ..
                } => torque_n_m + rate_n_m_s * (t - t0_s),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Table;

    #[test]
    fn a_held_table_is_a_step_function_with_its_exact_integral() {
        let t = Table::new(vec![0.0, 1.0, 3.0], vec![2.0, 5.0, -1.0])
            .unwrap()
            .held();
        assert_eq!(
            (t.value(0.5), t.value(1.0), t.value(2.9), t.value(9.0)),
            (2.0, 5.0, 5.0, -1.0)
        );
        assert_eq!(t.slope(0.5), 0.0);
        // 2 * 1 + 5 * 2 + (-1) * 1
        assert!((t.integral_from_zero(4.0) - 11.0).abs() < 1e-12);
        assert!((t.integral_from_zero(2.0) - 7.0).abs() < 1e-12);
    }

    use super::*;
    use approx::assert_relative_eq;

    /// The angle is the integral of the speed and the acceleration its derivative
    /// (central differences, h = 1e-6 s: truncation error h^2 A w^3 / 6 ~ 1e-3 of A w).
    #[test]
    fn harmonics_are_consistent() {
        let p = SpeedProfile::Harmonics {
            omega0_rad_s: 100.0,
            harmonics: vec![
                Harmonic {
                    amplitude_rad_s: 4.0,
                    frequency_hz: 104.0,
                    phase_rad: 0.3,
                },
                Harmonic {
                    amplitude_rad_s: 1.0,
                    frequency_hz: 208.0,
                    phase_rad: -1.0,
                },
            ],
        };
        assert_eq!(p.angle(0.0), 0.0);
        let h = 1e-6;
        for i in 1..50 {
            let t = i as f64 * 1.3e-3;
            let dtheta = (p.angle(t + h) - p.angle(t - h)) / (2.0 * h);
            assert_relative_eq!(dtheta, p.speed(t), max_relative = 1e-8);
            let domega = (p.speed(t + h) - p.speed(t - h)) / (2.0 * h);
            assert_relative_eq!(domega, p.acceleration(t), epsilon = 1e-3 * 4.0 * 1307.0);
        }
    }

    /// `speed_and_angle` is `speed` and `angle` to the bit (the engines' outputs rest on it):
    /// one and two harmonics with phases, 20 000 times over a second, and the other profiles;
    /// and so are `speed_and_acceleration`'s of `speed` and `acceleration`.
    #[test]
    fn speed_and_angle_is_speed_and_angle_to_the_bit() {
        let two = SpeedProfile::Harmonics {
            omega0_rad_s: -37.5,
            harmonics: vec![
                Harmonic {
                    amplitude_rad_s: 4.0,
                    frequency_hz: 104.0,
                    phase_rad: 0.3,
                },
                Harmonic {
                    amplitude_rad_s: 1.0,
                    frequency_hz: 208.7,
                    phase_rad: -1.0,
                },
            ],
        };
        let held = SpeedProfile::Held {
            t0_s: 0.1,
            angle0_rad: 2.0,
            speed_rad_s: 50.0,
            accel_rad_s2: 3.0,
            jerk_rad_s3: -7.0,
        };
        let table =
            SpeedProfile::Table(Table::new(vec![0.0, 0.4, 1.0], vec![1.0, 9.0, 2.0]).unwrap());
        for p in [SpeedProfile::sine(100.0, 4.378, 104.0), two, held, table] {
            for i in 0..20_000 {
                let t = 0.1 + i as f64 * 4.5e-5 + 1e-9 * (i % 7) as f64;
                let (w, a) = p.speed_and_angle(t);
                assert_eq!(
                    (w.to_bits(), a.to_bits()),
                    (p.speed(t).to_bits(), p.angle(t).to_bits())
                );
                let (w, alpha) = p.speed_and_acceleration(t);
                assert_eq!(
                    (w.to_bits(), alpha.to_bits()),
                    (p.speed(t).to_bits(), p.acceleration(t).to_bits())
                );
            }
        }
    }

    /// The expansion about a world step's middle agrees with the exact forms to rounding
    /// over the step (0.1 ms at 104 and 208.7 Hz with phases, at 0.1 s and at 60 s, where
    /// the phase `2 pi f t` of the exact forms itself carries 8e-15 and 4e-12 rad of
    /// rounding), is exact at its middle, and is refused where the series would be long.
    #[test]
    fn the_local_expansion_is_the_profile_to_rounding() {
        let p = SpeedProfile::Harmonics {
            omega0_rad_s: 100.0,
            harmonics: vec![
                Harmonic {
                    amplitude_rad_s: 4.378,
                    frequency_hz: 104.0,
                    phase_rad: 0.0,
                },
                Harmonic {
                    amplitude_rad_s: 1.0,
                    frequency_hz: 208.7,
                    phase_rad: -1.0,
                },
            ],
        };
        let h = 1e-4;
        for t0 in [0.0, 0.1, 60.0] {
            let local = p.local(t0 + 0.5 * h, 0.5 * h).expect("short");
            // x up to 2 pi 208.7 Hz 0.05 ms = 0.066 rad: sin x to x^9
            assert_eq!(local.series_terms, 5);
            assert_eq!(
                local.speed_and_angle(t0 + 0.5 * h),
                p.speed_and_angle(t0 + 0.5 * h)
            );
            // the exact forms' own rounding: that of the phase, 2 pi f t
            let phase_ulp = f64::EPSILON * (TAU * 208.7 * (t0 + h)).max(1.0);
            for i in 0..=100 {
                let t = t0 + i as f64 * 0.01 * h;
                let (w, a) = local.speed_and_angle(t);
                let (w_exact, a_exact) = p.speed_and_angle(t);
                assert!(
                    (w - w_exact).abs() <= 4e-16 * 100.0 + 6.0 * phase_ulp,
                    "{t}: {w} {w_exact}"
                );
                let angle_ulp = f64::EPSILON * a_exact.abs();
                assert!(
                    (a - a_exact).abs() <= 4.0 * angle_ulp + phase_ulp,
                    "{t}: {a} {a_exact}"
                );
            }
        }
        // 0.7 rad within the reach: the longest series; beyond it, none
        assert_eq!(p.local(0.1, 0.69 / (TAU * 208.7)).unwrap().series_terms, 8);
        assert_eq!(p.local(0.1, 0.72 / (TAU * 208.7)), None);
        let held = SpeedProfile::Held {
            t0_s: 0.0,
            angle0_rad: 0.0,
            speed_rad_s: 1.0,
            accel_rad_s2: 0.0,
            jerk_rad_s3: 0.0,
        };
        assert_eq!(held.local(0.1, 1e-4), None);
    }

    #[test]
    fn sine_is_eq3() {
        let p = SpeedProfile::sine(200.0, 4.378, 104.0);
        let t = 1.234e-3;
        assert_relative_eq!(
            p.speed(t),
            200.0 + 4.378 * (TAU * 104.0 * t).sin(),
            max_relative = 1e-15
        );
    }

    /// The exact integral of a piecewise-linear table (trapezoids), including beyond the ends.
    #[test]
    fn table_integral_is_exact() {
        let tab = Table::new(vec![0.0, 1.0, 3.0], vec![2.0, 4.0, 0.0]).unwrap();
        assert_relative_eq!(tab.integral_from_zero(1.0), 3.0, max_relative = 1e-15);
        assert_relative_eq!(tab.integral_from_zero(2.0), 3.0 + 3.0, max_relative = 1e-15);
        assert_relative_eq!(tab.integral_from_zero(4.0), 3.0 + 4.0, max_relative = 1e-15);
        assert_eq!(tab.slope(0.5), 2.0);
        assert_eq!(tab.value(10.0), 0.0);
    }

    #[test]
    fn bad_tables_are_rejected() {
        assert!(matches!(
            Table::new(vec![0.0], vec![1.0]),
            Err(TableError::TooShort(1))
        ));
        assert!(matches!(
            Table::new(vec![0.0, 0.0], vec![1.0, 2.0]),
            Err(TableError::NotIncreasing(1, _))
        ));
        assert!(matches!(
            Table::new(vec![0.0, 1.0], vec![1.0, f64::NAN]),
            Err(TableError::NotFinite(1))
        ));
    }
}
