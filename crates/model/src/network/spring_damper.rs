//! The torsional spring-damper as an element of a driveline network (MODEL.md section 8): the
//! law of `crate::spring` (shared with a pack's couplings) between two bodies,
//! `T = k (theta_a - theta_b - theta_0) + d (w_a - w_b)` on `b` and `-T` on `a`, its twist the
//! engines' own state, its damper's loss and its spring's stored energy its share of the
//! energy audit.

use super::element::{problem, ElementLaw, EnergyTerm, Mode, MAX_PORTS};
use super::{Network, NetworkProblem};
use crate::spring::SpringDamper;

impl ElementLaw for SpringDamper {
    fn kind_name(&self) -> &'static str {
        "spring_damper"
    }

    fn torque_factors(&self, _ports: &[usize]) -> Option<[f64; MAX_PORTS]> {
        Some([1.0, -1.0, 0.0])
    }

    /// `-T` on `a` (MODEL.md section 8), at the twist `theta_a - theta_b`.
    fn port_torque_n_m(
        &self,
        _t_s: f64,
        twist_rad: f64,
        w_a: f64,
        w_b: f64,
        _mode: Mode,
    ) -> Option<f64> {
        Some(-SpringDamper::torque_n_m(self, twist_rad, w_a - w_b))
    }

    /// The twist, on the tolerance in rad.
    fn state_scale(&self) -> Option<f64> {
        Some(1.0)
    }

    /// `w_a - w_b`.
    fn state_rate(&self, w_a: f64, w_b: f64) -> f64 {
        w_a - w_b
    }

    fn energy_term(&self) -> EnergyTerm {
        EnergyTerm::DamperLoss
    }

    /// The damper's loss `d (w_a - w_b)^2`.
    fn power_w(&self, _mode: Mode, _torque_n_m: f64, w_a: f64, w_b: f64) -> Option<f64> {
        Some(self.loss_rate_w(w_a - w_b))
    }

    fn damping_loss_j(&self, h_s: f64, w_rel_held: f64, w_rel_mean: f64) -> Option<f64> {
        Some(h_s * self.damping_n_m_s_per_rad * w_rel_held * w_rel_mean)
    }

    fn potential_change_j(&self, twist_rad: f64) -> Option<f64> {
        Some(self.potential_j(twist_rad) - self.potential_j(0.0))
    }

    /// Stiffness and damping finite and `>= 0`, the free angle finite.
    fn problems(
        &self,
        _net: &Network,
        k: usize,
        _ports: &[usize],
        out: &mut Vec<NetworkProblem>,
    ) -> bool {
        let (kk, d) = (self.stiffness_n_m_per_rad, self.damping_n_m_s_per_rad);
        let good = kk.is_finite()
            && kk >= 0.0
            && d.is_finite()
            && d >= 0.0
            && self.free_angle_rad.is_finite();
        if !good {
            out.push(problem(
                k,
                "stiffness_n_m_per_rad",
                "stiffness and damping must be finite and >= 0".into(),
            ));
        }
        true
    }
}
