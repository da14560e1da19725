//! The ideal gear of a driveline network (MODEL.md section 8; Modelica's `IdealGear`): rigid,
//! without backlash, `w_a = ratio w_b` (`phi_a = ratio phi_b`), power conserved (the torque
//! `lambda` on `a` is `-ratio lambda` on `b`). It is one constraint row, always
//! ([`super::rows`]), and takes a degree of freedom from its bodies.

use super::element::{problem, ElementLaw, Mode, MAX_PORTS};
use super::rows::Row;
use super::{Network, NetworkProblem};
use serde::{Deserialize, Serialize};

/// An ideal gear: `w_a = ratio w_b`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IdealGear {
    /// `w_a / w_b` (nonzero; negative for an external pair turning the other way).
    pub ratio: f64,
}

impl ElementLaw for IdealGear {
    fn kind_name(&self) -> &'static str {
        "ideal_gear"
    }

    fn torque_factors(&self, _ports: &[usize]) -> Option<[f64; MAX_PORTS]> {
        Some([1.0, -self.ratio, 0.0])
    }

    /// `w_a - ratio w_b = 0`.
    fn row(&self, k: usize, ports: &[usize], _mode: Mode) -> Option<Row> {
        Some(Row::two(k, (ports[0], 1.0), (ports[1], -self.ratio)))
    }

    fn fixed_ratio(&self) -> Option<f64> {
        Some(self.ratio)
    }

    /// A ratio that is finite and nonzero, and not between a fixed and a turning body (the
    /// network checks its loops and its speeds at t = 0).
    fn problems(
        &self,
        net: &Network,
        k: usize,
        ports: &[usize],
        out: &mut Vec<NetworkProblem>,
    ) -> bool {
        let ratio = self.ratio;
        if !(ratio.is_finite() && ratio != 0.0) {
            out.push(problem(
                k,
                "ratio",
                format!("{} must be nonzero", crate::fmt_num(ratio)),
            ));
            return false;
        }
        let (ba, bb) = (&net.bodies[ports[0]], &net.bodies[ports[1]]);
        if ba.is_fixed() != bb.is_fixed() {
            let other = if ba.is_fixed() { bb } else { ba };
            let why = if other.prescribed().is_some() {
                format!(
                    "ties the prescribed body \"{}\" to the fixed one: both motions are given, \
                     so the gear over-constrains them",
                    other.name
                )
            } else {
                format!(
                    "an ideal gear from a fixed body would hold \"{}\" still: make it fixed instead",
                    other.name
                )
            };
            out.push(problem(k, "b", why));
            return false;
        }
        true
    }
}
