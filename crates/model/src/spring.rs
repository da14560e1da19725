//! The torsional spring-damper law (MODEL.md section 8): a damper spring or a dual-mass
//! flywheel's spring between two rotating bodies a and b, as a pure function of their relative
//! motion, with its potential, its loss and the closed forms of two inertias joined by it.
//!
//! Nothing here knows a pack: the pack's couplings (`crate::pack::PackCoupling`) name the two
//! bodies; a driveline network takes the same law between any two of its bodies.
//!
//! Signs (the crate's two-sided convention, see `# Conventions`): the law's coordinate is
//! MODEL.md's `dtheta = theta_a - theta_b` (as the spline's `phi`, the opposite of the
//! convention's `rel`), and the torque it reports is the torque **on b**; a receives the
//! opposite.

use serde::{Deserialize, Serialize};

/// A linear torsional spring with a viscous damper in parallel (MODEL.md section 8).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpringDamper {
    /// Torsional stiffness `k`, N m/rad (>= 0).
    pub stiffness_n_m_per_rad: f64,
    /// Viscous damping `d`, N m s/rad (>= 0).
    pub damping_n_m_s_per_rad: f64,
    /// Free angle `theta_0`, rad: the twist `theta_a - theta_b` at which the spring carries no
    /// torque (0: relaxed when the two bodies are at the same angle).
    pub free_angle_rad: f64,
}

impl SpringDamper {
    /// The torque on body b, N m, at the twist `dtheta_rad = theta_a - theta_b` (rad) and the
    /// twist rate `domega_rad_s = omega_a - omega_b` (rad/s); body a receives the opposite.
    /// MODEL.md section 8: `T = k (theta_a - theta_b - theta_0) + d (omega_a - omega_b)`,
    /// positive when a leads (it pulls b forward and holds a back).
    pub fn torque_n_m(&self, dtheta_rad: f64, domega_rad_s: f64) -> f64 {
        self.stiffness_n_m_per_rad * (dtheta_rad - self.free_angle_rad)
            + self.damping_n_m_s_per_rad * domega_rad_s
    }

    /// The energy stored in the spring at the twist `dtheta_rad` (rad), J (>= 0):
    /// `V = k (dtheta - theta_0)^2 / 2`.
    pub fn potential_j(&self, dtheta_rad: f64) -> f64 {
        let x = dtheta_rad - self.free_angle_rad;
        0.5 * self.stiffness_n_m_per_rad * x * x
    }

    /// The power the damper turns into heat at the twist rate `domega_rad_s` (rad/s), W
    /// (>= 0): `d (omega_a - omega_b)^2`. The torques' power on the two bodies is
    /// `-(dV/dt) - d domega^2`.
    pub fn loss_rate_w(&self, domega_rad_s: f64) -> f64 {
        self.damping_n_m_s_per_rad * domega_rad_s * domega_rad_s
    }

    /// `1/J_a + 1/J_b`, 1/(kg m^2), the inverse of the reduced inertia; a body that does not
    /// yield (a prescribed shaft) has `J = f64::INFINITY` and adds nothing.
    fn inverse_reduced_inertia(j_a_kg_m2: f64, j_b_kg_m2: f64) -> f64 {
        1.0 / j_a_kg_m2 + 1.0 / j_b_kg_m2
    }

    /// The undamped natural frequency of two free inertias `J_a`, `J_b` (kg m^2; either may be
    /// `f64::INFINITY` for a body that does not yield) joined by this spring, rad/s:
    /// `omega_n = sqrt(k (J_a + J_b) / (J_a J_b))` (MODEL.md section 8), written
    /// `sqrt(k (1/J_a + 1/J_b))` so that one infinite inertia gives `sqrt(k / J)`.
    pub fn natural_frequency_rad_s(&self, j_a_kg_m2: f64, j_b_kg_m2: f64) -> f64 {
        (self.stiffness_n_m_per_rad * Self::inverse_reduced_inertia(j_a_kg_m2, j_b_kg_m2)).sqrt()
    }

    /// The damping ratio of the same two inertias (dimensionless, >= 0; < 1 underdamped):
    /// `zeta = d / (2 sqrt(k J_r))`, `J_r = J_a J_b / (J_a + J_b)` the reduced inertia; infinite
    /// for `k = 0` and `d > 0`.
    pub fn damping_ratio(&self, j_a_kg_m2: f64, j_b_kg_m2: f64) -> f64 {
        let inv = Self::inverse_reduced_inertia(j_a_kg_m2, j_b_kg_m2);
        self.damping_n_m_s_per_rad * inv / (2.0 * (self.stiffness_n_m_per_rad * inv).sqrt())
    }

    /// The damped frequency of the twist's free oscillation, rad/s:
    /// `omega_d = omega_n sqrt(1 - zeta^2)` (NaN when overdamped, `zeta >= 1`).
    pub fn damped_frequency_rad_s(&self, j_a_kg_m2: f64, j_b_kg_m2: f64) -> f64 {
        let zeta = self.damping_ratio(j_a_kg_m2, j_b_kg_m2);
        self.natural_frequency_rad_s(j_a_kg_m2, j_b_kg_m2) * (1.0 - zeta * zeta).sqrt()
    }

    /// The logarithmic decrement of the twist's free oscillation (dimensionless): the natural
    /// log of the ratio of two successive peaks of `dtheta - theta_0`,
    /// `delta = 2 pi zeta / sqrt(1 - zeta^2)` (NaN when overdamped).
    pub fn log_decrement(&self, j_a_kg_m2: f64, j_b_kg_m2: f64) -> f64 {
        let zeta = self.damping_ratio(j_a_kg_m2, j_b_kg_m2);
        2.0 * std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: SpringDamper = SpringDamper {
        stiffness_n_m_per_rad: 2000.0,
        damping_n_m_s_per_rad: 1.5,
        free_angle_rad: 0.01,
    };

    /// The law's signs: a leading (positive twist beyond `theta_0`, or opening speed) pulls b
    /// forward; the potential is zero at the free angle; the loss is never negative.
    #[test]
    fn law_signs_and_energy() {
        assert_eq!(S.torque_n_m(0.01, 0.0), 0.0);
        assert!((S.torque_n_m(0.02, 0.0) - 20.0).abs() < 1e-12);
        assert!((S.torque_n_m(0.01, 2.0) - 3.0).abs() < 1e-12);
        assert!(S.torque_n_m(0.0, -1.0) < 0.0);
        assert_eq!(S.potential_j(0.01), 0.0);
        assert!((S.potential_j(0.03) - 0.5 * 2000.0 * 0.02 * 0.02).abs() < 1e-15);
        // dV/dx is the spring part of the torque
        let h = 1e-6;
        let dv = (S.potential_j(0.03 + h) - S.potential_j(0.03 - h)) / (2.0 * h);
        assert!((dv - S.torque_n_m(0.03, 0.0)).abs() < 1e-6);
        assert!(S.loss_rate_w(-3.0) > 0.0 && S.loss_rate_w(0.0) == 0.0);
    }

    /// The closed forms: MODEL.md section 8's `sqrt(k (J_a + J_b) / (J_a J_b))`, the one-body
    /// limit `sqrt(k / J)` for an infinite inertia, `zeta = d / (2 sqrt(k J_r))` and the
    /// logarithmic decrement of a lightly damped pair.
    #[test]
    fn closed_forms() {
        let (ja, jb) = (0.5, 0.3);
        let wn = (2000.0f64 * (ja + jb) / (ja * jb)).sqrt();
        assert!((S.natural_frequency_rad_s(ja, jb) - wn).abs() < 1e-12 * wn);
        assert!(
            (S.natural_frequency_rad_s(f64::INFINITY, jb) - (2000.0f64 / jb).sqrt()).abs() < 1e-12
        );
        let jr = ja * jb / (ja + jb);
        let zeta = 1.5 / (2.0 * (2000.0 * jr).sqrt());
        assert!((S.damping_ratio(ja, jb) - zeta).abs() < 1e-15);
        let delta = 2.0 * std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt();
        assert!((S.log_decrement(ja, jb) - delta).abs() < 1e-15);
        assert!((S.damped_frequency_rad_s(ja, jb) - wn * (1.0 - zeta * zeta).sqrt()).abs() < 1e-12);
    }
}
