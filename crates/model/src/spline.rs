//! Spline geometry of one toothed coupling (MODEL.md section 1).
//!
//! A coupling joins a carrier (the shaft) and a disc through `n` identical involute teeth.
//! The relative angle `phi = theta_shaft - theta_disc` moves freely inside the backlash
//! `+/- g0`, `g0 = d / (2 R)`; beyond it the teeth touch on one of the two flanks.

use serde::{Deserialize, Serialize};

/// Which flank of the teeth is in contact (MODEL.md section 1, sign of eq 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Flank {
    /// The shaft leads (`phi > 0`): the shaft pushes the disc forward. The per-tooth load is
    /// negative (the paper's "negative impact load").
    ShaftLeads,
    /// The disc leads (`phi < 0`): the disc overruns the shaft. The per-tooth load is positive.
    DiscLeads,
}

impl Flank {
    /// The flank on whose side a relative angle `phi` (rad) lies. `phi = 0` counts as `ShaftLeads`.
    #[inline]
    pub fn of(phi_rad: f64) -> Flank {
        if phi_rad >= 0.0 {
            Flank::ShaftLeads
        } else {
            Flank::DiscLeads
        }
    }

    /// `+1` for `ShaftLeads`, `-1` for `DiscLeads`: the sign of `phi` on this flank.
    #[inline]
    pub fn phi_sign(self) -> f64 {
        match self {
            Flank::ShaftLeads => 1.0,
            Flank::DiscLeads => -1.0,
        }
    }

    /// The sign of the per-tooth load on this flank (eq 6): `-1` when the shaft leads, `+1` when
    /// the disc leads.
    #[inline]
    pub fn load_sign(self) -> f64 {
        -self.phi_sign()
    }

    /// Short label used in tables and CSV files: `"+"` (disc leads, positive load) or `"-"`.
    pub fn label(self) -> &'static str {
        match self {
            Flank::ShaftLeads => "-",
            Flank::DiscLeads => "+",
        }
    }
}

/// Geometry of a splined coupling. All lengths in metres, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SplineGeometry {
    /// Number of teeth `n` (> 0). Every tooth carries the same load in the lumped model.
    pub teeth: u32,
    /// Pitch radius `R` in m (> 0).
    pub pitch_radius_m: f64,
    /// Pressure angle `alpha` in rad, in (0, pi/2).
    pub pressure_angle_rad: f64,
    /// Circumferential backlash `d` at the pitch circle in m (> 0): the total free play.
    pub backlash_m: f64,
}

/// Contact kinematics of one flank pair, along the line of action.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToothKinematics {
    /// The flank `phi` lies on.
    pub flank: Flank,
    /// Metal penetration along the line of action in m: `delta = (|phi| - g0) Rb`.
    /// Negative values are a metal gap.
    pub delta_m: f64,
    /// Closing speed along the line of action in m/s: `v_n = sign(phi) (omega_s - omega_d) Rb`,
    /// positive while the flanks approach.
    pub v_n_m_s: f64,
}

impl SplineGeometry {
    /// Base radius `Rb = R cos(alpha)` in m: the lever arm of the tooth load (eqs 4-6).
    pub fn base_radius_m(&self) -> f64 {
        self.pitch_radius_m * self.pressure_angle_rad.cos()
    }

    /// Half of the angular free play `g0 = d / (2 R)` in rad.
    pub fn half_play_rad(&self) -> f64 {
        self.backlash_m / (2.0 * self.pitch_radius_m)
    }

    /// The free play left on each side in rad when contact starts `engagement_offset_m` (m,
    /// along the line of action) before the metal touches (the film thickness `h_o` of the
    /// oil laws, [`crate::ToothLaw::engagement_offset_m`]): `g0 - h_o / Rb`. A disc starting
    /// at `|phi| <` this is out of contact.
    pub fn free_half_play_rad(&self, engagement_offset_m: f64) -> f64 {
        self.half_play_rad() - engagement_offset_m / self.base_radius_m()
    }

    /// Tooth pitch at the pitch circle `2 pi R / n` in m: the backlash must be below it (a
    /// gap wider than the pitch leaves no tooth).
    pub fn tooth_pitch_m(&self) -> f64 {
        std::f64::consts::TAU * self.pitch_radius_m / self.teeth as f64
    }

    /// Metal clearance along the line of action with the disc centred, `g0 Rb`, in m.
    pub fn half_play_line_m(&self) -> f64 {
        self.half_play_rad() * self.base_radius_m()
    }

    /// Penetration and closing speed for a relative angle `phi_rad = theta_s - theta_d` and
    /// relative speed `dphi_rad_s = omega_s - omega_d` (MODEL.md section 1).
    pub fn kinematics(&self, phi_rad: f64, dphi_rad_s: f64) -> ToothKinematics {
        self.kinematics_at(phi_rad, dphi_rad_s, self.base_radius_m())
    }

    /// [`Self::kinematics`] with the base radius `rb_m` (m) already known: an engine that
    /// evaluates it millions of times keeps [`Self::base_radius_m`] instead of a cosine per
    /// call.
    pub fn kinematics_at(&self, phi_rad: f64, dphi_rad_s: f64, rb: f64) -> ToothKinematics {
        let flank = Flank::of(phi_rad);
        ToothKinematics {
            flank,
            delta_m: (phi_rad.abs() - self.half_play_rad()) * rb,
            v_n_m_s: flank.phi_sign() * dphi_rad_s * rb,
        }
    }

    /// Torque on the disc in N m from a signed per-tooth load `load_n` (eq 5): `-n F Rb`.
    /// The shaft receives the opposite, `+n F Rb` (eq 4).
    pub fn disc_torque_n_m(&self, load_n: f64) -> f64 {
        -(self.teeth as f64) * load_n * self.base_radius_m()
    }

    /// Effective mass of the disc at the line of action for all `n` teeth together, in kg:
    /// `m_eff = J / (n Rb^2)`; used by the closed-form impact (MODEL.md section 4).
    pub fn effective_mass_kg(&self, inertia_kg_m2: f64) -> f64 {
        let rb = self.base_radius_m();
        inertia_kg_m2 / (self.teeth as f64 * rb * rb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn paper() -> SplineGeometry {
        SplineGeometry {
            teeth: 154,
            pitch_radius_m: 0.231,
            pressure_angle_rad: 20f64.to_radians(),
            backlash_m: 0.75e-3,
        }
    }

    /// At phi = +/- g0 the flanks just touch: zero penetration on either side.
    #[test]
    fn penetration_is_zero_at_the_edge_of_the_backlash() {
        let g = paper();
        let g0 = g.half_play_rad();
        assert_relative_eq!(g0, 0.75e-3 / 0.462, max_relative = 1e-15);
        assert!(g.kinematics(g0, 0.0).delta_m.abs() < 1e-18);
        assert!(g.kinematics(-g0, 0.0).delta_m.abs() < 1e-18);
        assert_eq!(g.kinematics(-g0, 0.0).flank, Flank::DiscLeads);
    }

    /// Closing speed is positive when the flanks approach on both sides.
    #[test]
    fn closing_speed_sign() {
        let g = paper();
        let g0 = g.half_play_rad();
        // Shaft side: phi > 0 growing -> closing.
        assert!(g.kinematics(g0, 1.0).v_n_m_s > 0.0);
        // Disc side: phi < 0 becoming more negative -> closing.
        assert!(g.kinematics(-g0, -1.0).v_n_m_s > 0.0);
        assert!(g.kinematics(-g0, 1.0).v_n_m_s < 0.0);
    }

    /// A negative (shaft-leads) load accelerates the disc (eq 5).
    #[test]
    fn shaft_leading_load_drives_the_disc_forward() {
        let g = paper();
        assert!(g.disc_torque_n_m(-100.0) > 0.0);
        assert_relative_eq!(
            g.disc_torque_n_m(-1.0),
            154.0 * 0.231 * 20f64.to_radians().cos(),
            max_relative = 1e-15
        );
    }
}
