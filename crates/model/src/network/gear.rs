//! A gear mesh with backlash between two bodies of a network (MODEL.md section 8): the
//! relative displacement along the line of action `x = Rb_a theta_a + Rb_b theta_b` (external
//! mesh; internal: `Rb_a theta_a - Rb_b theta_b`) plus its value at t = 0, the backlash `b`
//! along the line of action, and the tooth law of section 2 on the penetration
//! `|x| - b/2` (gear rattle is the same impact physics as spline rattle). The mesh force `F`,
//! signed as `x`, acts as `-Rb_a F` on `a` and `-Rb_b F` on `b` (internal: `+Rb_b F` on `b`),
//! times the tooth pairs in contact.

use crate::law::{Engagement, ToothLaw};
use crate::spline::{Flank, ToothKinematics};
use serde::{Deserialize, Serialize};

/// A gear mesh with backlash and a tooth law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GearMesh {
    /// Base radius of the gear on body `a`, m (> 0).
    pub base_radius_a_m: f64,
    /// Base radius of the gear on body `b`, m (> 0).
    pub base_radius_b_m: f64,
    /// An internal mesh (a ring gear): `b` turns the same way as `a`.
    pub internal: bool,
    /// Backlash along the line of action, m (> 0): the free travel from one flank to the other.
    pub backlash_m: f64,
    /// Tooth pairs carrying the load together (the contact ratio's whole part; >= 1).
    pub pairs: f64,
    /// Relative displacement `x` at t = 0, m (0: centred in the backlash).
    pub initial_offset_m: f64,
    /// The tooth law of each pair (MODEL.md section 2).
    pub law: ToothLaw,
}

impl GearMesh {
    /// `+1` for an external mesh, `-1` for an internal one: the sign of `Rb_b theta_b` in `x`.
    pub fn b_sign(&self) -> f64 {
        if self.internal {
            -1.0
        } else {
            1.0
        }
    }

    /// The relative displacement `x` (m) and its rate `v` (m/s) along the line of action from
    /// the two bodies' angles (rad, from t = 0) and speeds (rad/s).
    pub fn displacement(&self, theta: (f64, f64), omega: (f64, f64)) -> (f64, f64) {
        let s = self.b_sign();
        (
            self.initial_offset_m
                + self.base_radius_a_m * theta.0
                + s * self.base_radius_b_m * theta.1,
            self.base_radius_a_m * omega.0 + s * self.base_radius_b_m * omega.1,
        )
    }

    /// The tooth kinematics of `x`, `v`: the flank on `x`'s side (positive `x`:
    /// [`Flank::ShaftLeads`], body `a` leads), the penetration `|x| - b/2` and the closing
    /// speed `sign(x) v`.
    pub fn kinematics(&self, x_m: f64, v_m_s: f64) -> ToothKinematics {
        let flank = Flank::of(x_m);
        ToothKinematics {
            flank,
            delta_m: x_m.abs() - 0.5 * self.backlash_m,
            v_n_m_s: flank.phi_sign() * v_m_s,
        }
    }

    /// The mesh force `F` per pair, N, signed as `x`, during a contact event.
    pub fn force_n(&self, kin: &ToothKinematics, engagement: &Engagement) -> f64 {
        kin.flank.phi_sign() * self.law.load_magnitude(kin, engagement)
    }

    /// The torques on `a` and `b` (N m) of the force `F` per pair:
    /// `(-Rb_a F, -+Rb_b F) pairs`.
    pub fn torques_n_m(&self, force_n: f64) -> (f64, f64) {
        (
            -self.base_radius_a_m * force_n * self.pairs,
            -self.b_sign() * self.base_radius_b_m * force_n * self.pairs,
        )
    }

    /// The effective mass of one tooth pair at the line of action, kg:
    /// `1 / (pairs (Rb_a^2 / J_a + Rb_b^2 / J_b))` for the inertias `J_a`, `J_b` (kg m^2);
    /// MODEL.md section 8's closed-form impact uses it.
    pub fn effective_mass_kg(&self, inertia_a_kg_m2: f64, inertia_b_kg_m2: f64) -> f64 {
        let (ra, rb) = (self.base_radius_a_m, self.base_radius_b_m);
        1.0 / (self.pairs * (ra * ra / inertia_a_kg_m2 + rb * rb / inertia_b_kg_m2))
    }

    /// The problems with the parameters, as `(field, what is wrong)`.
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        for (field, v) in [
            ("base_radius_a_m", self.base_radius_a_m),
            ("base_radius_b_m", self.base_radius_b_m),
            ("backlash_m", self.backlash_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                out.push((field, format!("{v} must be > 0")));
            }
        }
        if !(self.pairs.is_finite() && self.pairs >= 1.0) {
            out.push(("pairs", format!("{} must be >= 1", self.pairs)));
        }
        if !self.initial_offset_m.is_finite() {
            out.push(("initial_offset_m", "must be finite".to_string()));
        }
        out
    }
}

impl super::ElementLaw for GearMesh {
    fn kind_name(&self) -> &'static str {
        "gear_mesh"
    }

    /// Its displacement `x` along the line of action, on its backlash's scale.
    fn state_scale(&self) -> Option<f64> {
        Some(self.backlash_m)
    }

    /// `x` at t = 0.
    fn initial_state(&self) -> f64 {
        self.initial_offset_m
    }

    /// `x`'s rate `Rb_a w_a +- Rb_b w_b` (m/s).
    fn state_rate(&self, w_a: f64, w_b: f64) -> f64 {
        self.displacement((0.0, 0.0), (w_a, w_b)).1
    }

    fn energy_term(&self) -> super::EnergyTerm {
        super::EnergyTerm::MeshWork
    }

    fn problems(
        &self,
        _net: &super::Network,
        k: usize,
        _ports: &[usize],
        out: &mut Vec<super::NetworkProblem>,
    ) -> bool {
        for (field, message) in GearMesh::problems(self) {
            out.push(super::element::problem(k, field, message));
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(internal: bool) -> GearMesh {
        crate::cases::dry_gear_mesh(internal)
    }

    /// A mesh's force does no work on a rigid rotation of the pair that keeps `x` (power
    /// `T_a w_a + T_b w_b = -F v`), for both mesh kinds.
    #[test]
    fn torques_do_the_work_of_the_force_along_the_line() {
        for internal in [false, true] {
            let m = mesh(internal);
            let (wa, wb) = (30.0, -7.0);
            let (_, v) = m.displacement((0.0, 0.0), (wa, wb));
            let f = 123.0;
            let (ta, tb) = m.torques_n_m(f);
            assert!(
                (ta * wa + tb * wb + f * v).abs() < 1e-12,
                "internal {internal}"
            );
        }
        let m = mesh(false);
        let kin = m.kinematics(-6e-5, -1.0);
        assert_eq!(kin.flank, Flank::DiscLeads);
        assert!((kin.delta_m - 1e-5).abs() < 1e-18);
        assert_eq!(kin.v_n_m_s, 1.0);
        let e = m.law.engage(&kin);
        assert!(m.force_n(&kin, &e) < 0.0);
        assert!((m.effective_mass_kg(0.01, 0.5) - 1.0 / (0.09 + 0.0162)).abs() < 1e-12);
        assert!(m.problems().is_empty());
    }
}
