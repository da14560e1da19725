//! An engine's firing-order torque, locked to its crank angle (MODEL.md section 8, "Inputs";
//! docs/DECISIONS.md, "An engine's firing harmonics"): the gas and mass torques of a piston
//! engine repeat with every firing, `n_f = 2 z / s` times a revolution (`z` cylinders, `s`
//! strokes), so their fluctuation about the mean is a Fourier series in the crank angle
//! `theta`, not in time: it speeds up and slows down with the engine,
//!
//! `T_f(theta) = sum_k a_k sin(k n_f theta + phi_k)`, N m, `k = 1, 2, ...`.
//!
//! It is the derivative of the potential `V(theta) = sum_k a_k / (k n_f) cos(k n_f theta +
//! phi_k)` (`T_f = -dV/dtheta`), so its work from `theta_0` to `theta_1` is `V(theta_0) -
//! V(theta_1)` whatever the speed (a closed form the tests use).

use serde::{Deserialize, Serialize};

/// The firing-order harmonics of an engine body (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Firing {
    /// Number of cylinders `z` (>= 1).
    pub cylinders: u32,
    /// Strokes per working cycle `s`: 4 (a four-stroke engine fires each cylinder every
    /// second revolution) or 2.
    pub strokes: u32,
    /// `a_k`: the amplitude of the `k`-th multiple of the firing order (`k = 1, 2, ...` in
    /// order), N m (finite).
    pub amplitudes_n_m: Vec<f64>,
    /// `phi_k`: the phase of each term at `theta = 0` (the body's angle at t = 0), rad; as
    /// many as `amplitudes_n_m`.
    pub phases_rad: Vec<f64>,
}

impl Firing {
    /// Firing events per revolution, `n_f = 2 z / s` (2 for a four-stroke four-cylinder).
    pub fn order(&self) -> f64 {
        2.0 * f64::from(self.cylinders) / f64::from(self.strokes)
    }

    /// The firing torque at crank angle `theta_rad` (rad), N m, positive along the rotation.
    pub fn torque_n_m(&self, theta_rad: f64) -> f64 {
        let nf = self.order();
        self.terms()
            .map(|(k, a, phi)| a * (k * nf * theta_rad + phi).sin())
            .sum()
    }

    /// The potential `V(theta)` whose negative slope is the torque, J (module docs).
    pub fn potential_j(&self, theta_rad: f64) -> f64 {
        let nf = self.order();
        self.terms()
            .map(|(k, a, phi)| a / (k * nf) * (k * nf * theta_rad + phi).cos())
            .sum()
    }

    /// What is wrong with it, or `None`: a count of cylinders of 0, strokes other than 2 or
    /// 4, no amplitude, an amplitude or phase not finite, phases not one per amplitude.
    pub fn problem(&self) -> Option<String> {
        if self.cylinders == 0 {
            return Some("cylinders must be >= 1".into());
        }
        if self.strokes != 2 && self.strokes != 4 {
            return Some(format!("strokes = {}: must be 2 or 4", self.strokes));
        }
        if self.amplitudes_n_m.is_empty() {
            return Some("amplitudes_n_m needs at least one amplitude".into());
        }
        if self.phases_rad.len() != self.amplitudes_n_m.len() {
            return Some(format!(
                "{} phases for {} amplitudes: give one phase per amplitude",
                self.phases_rad.len(),
                self.amplitudes_n_m.len()
            ));
        }
        if self
            .amplitudes_n_m
            .iter()
            .chain(&self.phases_rad)
            .any(|v| !v.is_finite())
        {
            return Some("an amplitude or phase is not finite".into());
        }
        None
    }

    /// `(k, a_k, phi_k)` for `k = 1, 2, ...`.
    fn terms(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        self.amplitudes_n_m
            .iter()
            .zip(&self.phases_rad)
            .enumerate()
            .map(|(i, (&a, &phi))| ((i + 1) as f64, a, phi))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn four_cylinder() -> Firing {
        Firing {
            cylinders: 4,
            strokes: 4,
            amplitudes_n_m: vec![120.0, 30.0],
            phases_rad: vec![0.3, -1.0],
        }
    }

    #[test]
    fn a_four_stroke_four_cylinder_fires_twice_a_revolution() {
        let f = four_cylinder();
        assert_eq!(f.order(), 2.0);
        // periodic in half a revolution
        for theta in [0.0, 0.7, 2.0] {
            let d = f.torque_n_m(theta) - f.torque_n_m(theta + std::f64::consts::PI);
            assert!(d.abs() < 1e-12, "{d}");
        }
        let two = Firing {
            strokes: 2,
            ..four_cylinder()
        };
        assert_eq!(two.order(), 4.0);
    }

    #[test]
    fn the_torque_is_the_potentials_negative_slope() {
        let f = four_cylinder();
        let h = 1e-6;
        for theta in [0.0, 0.4, 1.9, 5.0] {
            let slope = (f.potential_j(theta + h) - f.potential_j(theta - h)) / (2.0 * h);
            // central difference: error ~ h^2 V''' ~ 1e-12 a (k nf)^2
            assert!((f.torque_n_m(theta) + slope).abs() < 1e-7, "{theta}");
        }
    }

    #[test]
    fn bad_firing_is_named() {
        let mut f = four_cylinder();
        f.strokes = 3;
        assert!(f.problem().unwrap().contains("strokes = 3"));
        let mut f = four_cylinder();
        f.phases_rad.pop();
        assert!(f.problem().unwrap().contains("1 phases for 2 amplitudes"));
        let mut f = four_cylinder();
        f.amplitudes_n_m[0] = f64::NAN;
        assert!(f.problem().unwrap().contains("not finite"));
        assert_eq!(four_cylinder().problem(), None);
    }
}
