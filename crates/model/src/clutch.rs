//! The clutch pack beyond the paper (MODEL.md section 5): separator plates, the output drum,
//! the piston and the axial stack, wet friction between neighbouring faces, viscous drag across
//! open gaps. Pure laws and plain types; the engines apply them.
//!
//! # Theory
//! **The stack.** `N` friction discs (on the shaft's spline) and `N + 1` separator plates (on
//! the housing's spline in a brake, on an output drum's in a clutch) alternate along the axis:
//! plate 0, disc 0, plate 1, ..., disc `N-1`, plate `N`. Stack body `b` is plate `b/2` for
//! even `b` and disc `(b-1)/2` for odd `b`; interface `m` (`0 <= m < 2N`) is the pair of
//! faces between stack bodies `m` and `m + 1`. The piston pushes on plate 0; plate `N` rests
//! on the reaction ring.
//!
//! **Piston force** `F_p(t) = max(0, p(t) A - F_rs)`: pressure times piston area minus the
//! return spring's force (taken at the closed position, constant over the micrometre stroke
//! that closes a wet pack).
//!
//! **Clamp force per interface.** Every body between the piston and an interface must slide
//! axially on its spline to pass the force on; the spline's friction, `mu_spline` times the
//! normal load `Q_b = n |F|` its teeth carry, holds part of it back (MODEL.md section 5):
//! `F_m = max(0, F_p - sum over b <= m of mu_spline Q_b)`. The axial motion itself is taken as
//! quasi-static (a steel stack closes within micrometres; its axial modes are far above the
//! rattle), so the clamp forces follow the piston force and the teeth's loads instantly.
//!
//! **Face friction** (uniform pressure on an annulus `Ri..Ro`): the torque of one face is
//! `mu(v) F_clamp R_eff`, `R_eff = 2 (Ro^3 - Ri^3) / (3 (Ro^2 - Ri^2))`, opposing the slip;
//! `v = |dOmega| R_eff` is the slip speed at the effective radius.
//!
//! **Friction curve** `mu(v)`: a Stribeck-like law `mu_k + (mu_s - mu_k) exp(-v / v_s) + c v`
//! or a table. A wet clutch wants `dmu/dv >= 0` (a falling curve feeds shudder); both shapes
//! are allowed, the scenes use rising ones.
//!
//! **Stick-slip.** Engines must not regularise `sign(slip)` (a regularisation speed small
//! enough to hold a lock makes the equations stiff): the multibody engine solves the friction
//! impulses at velocity level each step (see `clutchpack_multibody`), which holds a locked interface
//! exactly while the torque it needs stays below `mu(0) F R_eff` and lets it slip with
//! `mu(v) F R_eff` otherwise.
//!
//! **Open gaps.** With no clamp force each interface is an oil gap `h` of viscosity `eta`
//! (Couette flow between parallel annuli): `T = pi eta dOmega (Ro^4 - Ri^4) / (2 h)`,
//! opposing the slip.

use crate::drive::Table;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Effective friction radius of an annulus under uniform pressure, m:
/// `R_eff = 2 (Ro^3 - Ri^3) / (3 (Ro^2 - Ri^2))` (MODEL.md section 5). `inner_m < outer_m`.
pub fn effective_radius_m(inner_m: f64, outer_m: f64) -> f64 {
    2.0 * (outer_m.powi(3) - inner_m.powi(3)) / (3.0 * (outer_m * outer_m - inner_m * inner_m))
}

/// Viscous drag torque of one open oil gap on the body whose speed exceeds the other's by
/// `slip_rad_s` (rad/s), N m: `-pi eta slip (Ro^4 - Ri^4) / (2 h)` (MODEL.md section 5; Couette
/// flow between parallel annuli `inner_m..outer_m` a gap `gap_m` apart). Negative for a
/// positive slip: it opposes the slip; the other body receives the opposite.
pub fn open_gap_drag_torque_n_m(
    viscosity_pa_s: f64,
    slip_rad_s: f64,
    inner_m: f64,
    outer_m: f64,
    gap_m: f64,
) -> f64 {
    -PI * viscosity_pa_s * slip_rad_s * (outer_m.powi(4) - inner_m.powi(4)) / (2.0 * gap_m)
}

/// The friction coefficient as a function of the slip speed at the effective radius.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum FrictionCurve {
    /// `mu(v) = mu_k + (mu_s - mu_k) exp(-v / v_s) + c v` (dimensionless; `v >= 0` in m/s).
    /// `mu_s < mu_k` or `c > 0` gives the rising curve wet clutches need against shudder.
    Stribeck {
        /// `mu_s = mu(0)`, the coefficient at zero slip (holds a locked interface).
        static_mu: f64,
        /// `mu_k`, the coefficient approached beyond the Stribeck speed (without `c`).
        kinetic_mu: f64,
        /// `v_s` in m/s (> 0): the slip speed over which `mu` moves from `mu_s` to `mu_k`.
        stribeck_speed_m_s: f64,
        /// `c` in s/m (>= 0 usually): the viscous rise of `mu` with slip speed.
        viscous_slope_s_m: f64,
    },
    /// `mu` interpolated linearly in a table of slip speeds (m/s, from 0) and coefficients,
    /// held beyond its last row.
    Table(Table),
}

impl FrictionCurve {
    /// A constant coefficient `mu` (dimensionless).
    pub fn constant(mu: f64) -> FrictionCurve {
        FrictionCurve::Stribeck {
            static_mu: mu,
            kinetic_mu: mu,
            stribeck_speed_m_s: 1.0,
            viscous_slope_s_m: 0.0,
        }
    }

    /// `mu` at the slip speed `v_m_s` (its magnitude is used), dimensionless.
    pub fn mu(&self, v_m_s: f64) -> f64 {
        let v = v_m_s.abs();
        match self {
            FrictionCurve::Stribeck {
                static_mu,
                kinetic_mu,
                stribeck_speed_m_s,
                viscous_slope_s_m,
            } => {
                kinetic_mu
                    + (static_mu - kinetic_mu) * (-v / stribeck_speed_m_s).exp()
                    + viscous_slope_s_m * v
            }
            FrictionCurve::Table(t) => t.value(v),
        }
    }

    /// `mu(0)`: the coefficient that holds a locked interface.
    pub fn static_mu(&self) -> f64 {
        self.mu(0.0)
    }
}

/// The pressure history on the piston.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum PressureProfile {
    /// A constant pressure, Pa (0: an open pack).
    Constant {
        /// Pa.
        pressure_pa: f64,
    },
    /// 0 until `start_s`, then rising linearly to `pressure_pa` over `rise_s`, then held.
    Ramp {
        /// Start of the rise, s.
        start_s: f64,
        /// Duration of the rise, s (> 0).
        rise_s: f64,
        /// Final pressure, Pa.
        pressure_pa: f64,
    },
    /// A table of pressure (Pa) over time (s), linear between rows, held beyond its ends.
    Table(Table),
}

impl PressureProfile {
    /// Appends every instant (s) where the pressure jumps or bends: a ramp's start and end,
    /// a table's rows.
    pub fn breakpoints(&self, out: &mut Vec<f64>) {
        match self {
            PressureProfile::Constant { .. } => {}
            PressureProfile::Ramp {
                start_s, rise_s, ..
            } => out.extend([*start_s, start_s + rise_s]),
            PressureProfile::Table(t) => out.extend_from_slice(&t.t_s),
        }
    }

    /// Pressure at `t_s`, Pa.
    pub fn pressure_pa(&self, t_s: f64) -> f64 {
        match self {
            PressureProfile::Constant { pressure_pa } => *pressure_pa,
            PressureProfile::Ramp {
                start_s,
                rise_s,
                pressure_pa,
            } => pressure_pa * ((t_s - start_s) / rise_s).clamp(0.0, 1.0),
            PressureProfile::Table(t) => t.value(t_s),
        }
    }
}

/// The piston that clamps the stack.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Piston {
    /// Piston area in m^2 (> 0).
    pub area_m2: f64,
    /// The pressure history on it.
    pub pressure: PressureProfile,
    /// Force of the return spring at the closed position, N (>= 0); it holds the piston off
    /// the stack until `p A` exceeds it.
    pub return_spring_n: f64,
}

impl Piston {
    /// Piston force on the stack at `t_s`, N (>= 0): `max(0, p(t) A - F_rs)`.
    pub fn force_n(&self, t_s: f64) -> f64 {
        (self.pressure.pressure_pa(t_s) * self.area_m2 - self.return_spring_n).max(0.0)
    }

    /// Whether the piston can ever push on the stack: its largest pressure times its area
    /// exceeds the return spring. When not, every interface stays an open oil gap for the
    /// whole run (the engines' multirate schemes for open packs rely on it).
    pub fn can_clamp(&self) -> bool {
        self.open_until_s() < f64::INFINITY
    }

    /// The time before which the piston cannot push on the stack, s: its force
    /// `max(0, p(t) A - F_rs)` is zero for every `t` before it (the multibody engine's multirate
    /// scheme runs an open pack until then). `f64::INFINITY` when the pressure never exceeds
    /// the return spring (see [`Piston::can_clamp`]), `f64::NEG_INFINITY` when it may push
    /// from the start (a constant pressure over the spring, a table whose first row is).
    /// Conservative where the exact instant would round: a ramp's start, the row of a table
    /// after which the pressure first rises over the spring.
    pub fn open_until_s(&self) -> f64 {
        let pushes = |p: f64| p * self.area_m2 > self.return_spring_n;
        match &self.pressure {
            PressureProfile::Constant { pressure_pa } if pushes(*pressure_pa) => f64::NEG_INFINITY,
            PressureProfile::Ramp {
                start_s,
                pressure_pa,
                ..
            } if pushes(*pressure_pa) => *start_s,
            PressureProfile::Constant { .. } | PressureProfile::Ramp { .. } => f64::INFINITY,
            PressureProfile::Table(t) => match t.y.iter().position(|&p| pushes(p)) {
                None => f64::INFINITY,
                Some(0) => f64::NEG_INFINITY,
                // below the spring at row k - 1 and linear up to row k
                Some(k) => t.t_s[k - 1],
            },
        }
    }
}

/// The oil gaps of an open pack (no clamp force).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OpenGap {
    /// Oil viscosity `eta` in the gaps, Pa s (> 0).
    pub viscosity_pa_s: f64,
    /// Axial gap `h` between neighbouring faces when open, m (> 0).
    pub gap_m: f64,
}

/// What a friction face of the stack does between two stick-slip events (MODEL.md section
/// 5), as both engines track it. The reference engine opens a face whose clamp force is zero
/// ([`Face::Open`]); the multibody engine keeps such a face as [`Face::Slip`] with its last
/// sign, for when it clamps again (its clamp force, zero, gives no torque).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Face {
    /// No clamp force: an oil gap (Couette drag).
    Open,
    /// Clamped and slipping; the sign (+1 or -1) of its slip `omega_upper - omega_lower`
    /// (rad/s, upper: the body further from the piston).
    Slip(f64),
    /// Clamped and stuck: the two faces turn as one while the torque that holds them stays
    /// within `mu(0) F R_eff`.
    Locked,
}

/// The axial stack and its friction interfaces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StackModel {
    /// Inner radius `Ri` of the friction faces (the annulus that touches), m (> 0).
    pub face_inner_radius_m: f64,
    /// Outer radius `Ro` of the friction faces, m (> `Ri`).
    pub face_outer_radius_m: f64,
    /// `mu(v)` of every face (of each face without its own in [`Self::face_friction`]).
    pub friction: FrictionCurve,
    /// Each interface's own `mu(v)` (interface `m` joins stack bodies `m` and `m + 1`), set
    /// by a thermal run from `mu(v, T)` at the face's temperature (MODEL.md section 9);
    /// empty: every face takes [`Self::friction`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub face_friction: Vec<FrictionCurve>,
    /// The piston.
    pub piston: Piston,
    /// Viscous drag across open gaps; `None`: no drag.
    pub open_gap: Option<OpenGap>,
    /// Friction coefficient `mu_spline` of the axial slide on the splines (dimensionless,
    /// >= 0): each body holds back `mu_spline n |F|` of the clamp force.
    pub spline_friction: f64,
}

impl StackModel {
    /// The `mu(v)` of interface `m`: its own curve when [`Self::face_friction`] has one,
    /// else [`Self::friction`].
    pub fn friction_of(&self, m: usize) -> &FrictionCurve {
        self.face_friction.get(m).unwrap_or(&self.friction)
    }

    /// `R_eff` of the faces, m.
    pub fn effective_radius_m(&self) -> f64 {
        effective_radius_m(self.face_inner_radius_m, self.face_outer_radius_m)
    }

    /// The clamp force of every interface, N, for the piston force `piston_n` (N) and the
    /// teeth's normal loads `Q_b = n |F|` of the stack bodies in stack order (N; `2N + 1`
    /// values for `2N` interfaces): `F_m = max(0, F_p - sum_{b <= m} mu_spline Q_b)`.
    pub fn clamp_forces_n(&self, piston_n: f64, tooth_normal_loads_n: &[f64], out: &mut [f64]) {
        self.clamp_forces_with(
            piston_n,
            |b| tooth_normal_loads_n.get(b).copied().unwrap_or(0.0),
            out,
        );
    }

    /// [`Self::clamp_forces_n`] with the normal load `Q_b` (N) of stack body `b` given by
    /// `tooth_normal_load_n(b)`, for an engine that keeps the loads in another order.
    pub fn clamp_forces_with(
        &self,
        piston_n: f64,
        tooth_normal_load_n: impl Fn(usize) -> f64,
        out: &mut [f64],
    ) {
        let mut f = piston_n;
        for (m, o) in out.iter_mut().enumerate() {
            f -= self.spline_friction * tooth_normal_load_n(m);
            *o = f.max(0.0);
        }
    }

    /// Viscous drag of one open gap on the faster body for a slip of `slip_rad_s`, N m (0
    /// without `open_gap`).
    pub fn open_gap_torque_n_m(&self, slip_rad_s: f64) -> f64 {
        match self.open_gap {
            Some(g) => open_gap_drag_torque_n_m(
                g.viscosity_pa_s,
                slip_rad_s,
                self.face_inner_radius_m,
                self.face_outer_radius_m,
                g.gap_m,
            ),
            None => 0.0,
        }
    }
}

/// The output drum of a clutch: the separator plates' carrier, a body with inertia and a load.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DrumModel {
    /// Rotational inertia about the axis, kg m^2 (> 0).
    pub inertia_kg_m2: f64,
    /// Constant load torque on the drum about the axis, N m (negative: it brakes a drum
    /// turning the positive way).
    pub load_torque_n_m: f64,
    /// Viscous drag `C` on the drum, N m s/rad (>= 0): torque `-C omega`.
    pub drag_n_m_s_rad: f64,
    /// Drum speed at t = 0, rad/s.
    pub initial_speed_rad_s: f64,
}

/// What one friction interface does at one instant (per-interface output of an engine).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct InterfaceSample {
    /// Slip speed `omega_upper - omega_lower` of the two faces (stack bodies `m + 1` and `m`),
    /// rad/s.
    pub slip_rad_s: f64,
    /// Slip speed at the effective radius, m/s (same sign).
    pub slip_m_s: f64,
    /// The friction coefficient in use, `mu(|v|)` (dimensionless; 0 for an open interface).
    pub mu: f64,
    /// Clamp force, N (0: open).
    pub clamp_n: f64,
    /// Torque of the interface on stack body `m + 1` about the axis, N m (the lower body
    /// receives the opposite); friction while clamped, viscous drag while open.
    pub torque_n_m: f64,
    /// Whether the faces are locked together (no slip) during the last step.
    pub locked: bool,
    /// Energy the interface has turned into heat since t = 0, J (>= 0): the work of its
    /// friction (or open-gap drag) torque against the slip, summed step by step.
    pub dissipated_j: f64,
}

/// A body of the stack by its kind and index: the one definition of stack order (plate 0,
/// disc 0, plate 1, ..., disc `N-1`, plate `N`; module docs), used by the engines, the
/// recording's drawing and the naming of the friction interfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StackBody {
    /// Separator plate `j` (`0..=N`).
    Plate(usize),
    /// Friction disc `i` (`0..N`).
    Disc(usize),
}

impl StackBody {
    /// The body at stack position `b` (from the piston, 0-based): plate `b/2` for even `b`,
    /// disc `(b-1)/2` for odd `b`.
    pub fn at(b: usize) -> StackBody {
        if b.is_multiple_of(2) {
            StackBody::Plate(b / 2)
        } else {
            StackBody::Disc(b / 2)
        }
    }

    /// The stack position of this body (inverse of [`StackBody::at`]).
    pub fn position(self) -> usize {
        match self {
            StackBody::Plate(j) => 2 * j,
            StackBody::Disc(i) => 2 * i + 1,
        }
    }

    /// The index of this body in the engines' body list of a pack of `n_discs` discs: the
    /// discs first, then the plates.
    pub fn body_index(self, n_discs: usize) -> usize {
        match self {
            StackBody::Plate(j) => n_discs + j,
            StackBody::Disc(i) => i,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// R_eff of a thin ring is its radius; of a full disc 2/3 of its radius (closed forms of
    /// the uniform-pressure formula).
    #[test]
    fn effective_radius_closed_forms() {
        assert_relative_eq!(
            effective_radius_m(0.2, 0.2 + 1e-9),
            0.2,
            max_relative = 1e-8
        );
        assert_relative_eq!(effective_radius_m(1e-12, 0.3), 0.2, max_relative = 1e-9);
        // 0.231..0.290: 2 (0.024389 - 0.012326391) / (3 (0.0841 - 0.053361))
        let by_hand = 2.0 * (0.29f64.powi(3) - 0.231f64.powi(3))
            / (3.0 * (0.29f64.powi(2) - 0.231f64.powi(2)));
        assert_relative_eq!(
            effective_radius_m(0.231, 0.29),
            by_hand,
            max_relative = 1e-15
        );
        assert!((effective_radius_m(0.231, 0.29) - 0.2612).abs() < 1e-3);
    }

    /// The open-gap drag integrates the Couette shear stress `eta w r / h` over the annulus:
    /// `T = integral of (eta w r / h) r 2 pi r dr` from Ri to Ro; checked against a midpoint
    /// sum, and it opposes the slip (a property over signs).
    #[test]
    fn open_gap_drag_is_the_couette_integral() {
        let (eta, w, ri, ro, h) = (0.03, 12.0, 0.2, 0.28, 0.1e-3);
        let n = 100_000;
        let dr = (ro - ri) / n as f64;
        let sum: f64 = (0..n)
            .map(|i| {
                let r = ri + (i as f64 + 0.5) * dr;
                eta * w * r / h * r * 2.0 * PI * r * dr
            })
            .sum();
        assert_relative_eq!(
            open_gap_drag_torque_n_m(eta, w, ri, ro, h),
            -sum,
            max_relative = 1e-8
        );
        for w in [-3.0, -1e-3, 1e-3, 7.0] {
            assert!(open_gap_drag_torque_n_m(eta, w, ri, ro, h) * w < 0.0);
        }
    }

    /// The Stribeck-like curve: mu(0) = mu_s, mu -> mu_k (+ c v) far beyond v_s, rising when
    /// mu_s < mu_k; a table interpolates and holds its last row.
    #[test]
    fn friction_curves() {
        let c = FrictionCurve::Stribeck {
            static_mu: 0.10,
            kinetic_mu: 0.13,
            stribeck_speed_m_s: 0.5,
            viscous_slope_s_m: 0.001,
        };
        assert_relative_eq!(c.static_mu(), 0.10, max_relative = 1e-15);
        assert_relative_eq!(c.mu(0.5), 0.13 - 0.03 / std::f64::consts::E + 0.0005);
        assert_relative_eq!(c.mu(-0.5), c.mu(0.5));
        assert!((c.mu(20.0) - (0.13 + 0.02)).abs() < 1e-12);
        let mut last = 0.0;
        for i in 0..100 {
            let mu = c.mu(i as f64 * 0.05);
            assert!(mu >= last, "rising");
            last = mu;
        }
        let t =
            FrictionCurve::Table(Table::new(vec![0.0, 1.0, 2.0], vec![0.1, 0.12, 0.13]).unwrap());
        assert_relative_eq!(t.mu(0.5), 0.11, max_relative = 1e-15);
        assert_relative_eq!(t.mu(-1.5), 0.125, max_relative = 1e-15);
        assert_eq!(t.mu(9.0), 0.13);
        assert_eq!(FrictionCurve::constant(0.12).mu(3.0), 0.12);
    }

    /// The piston force is pressure times area minus the return spring, never pulling; the
    /// ramp rises linearly between its start and its end.
    #[test]
    fn piston_force() {
        let p = Piston {
            area_m2: 0.01,
            pressure: PressureProfile::Ramp {
                start_s: 0.01,
                rise_s: 0.02,
                pressure_pa: 1e6,
            },
            return_spring_n: 2000.0,
        };
        assert_eq!(p.force_n(0.0), 0.0);
        assert_eq!(p.force_n(0.012), 0.0); // 1e5 Pa * 0.01 m^2 = 1000 N < 2000 N
        assert_relative_eq!(p.force_n(0.02), 5e5 * 0.01 - 2000.0, max_relative = 1e-12);
        assert_relative_eq!(p.force_n(1.0), 1e4 - 2000.0, max_relative = 1e-12);
        // it can clamp: 1e6 Pa * 0.01 m^2 = 1e4 N > 2000 N; not against a spring of 1e4 N
        assert!(p.can_clamp());
        let held_off = Piston {
            return_spring_n: 1e4,
            ..p.clone()
        };
        assert!(!held_off.can_clamp());
        assert_eq!(held_off.force_n(1.0), 0.0);
    }

    /// Spline friction holds back mu_spline Q_b at each body from the piston on: the clamp
    /// force falls along the stack and never pulls.
    #[test]
    fn clamp_force_falls_along_the_stack() {
        let s = StackModel {
            face_friction: Vec::new(),
            face_inner_radius_m: 0.2,
            face_outer_radius_m: 0.25,
            friction: FrictionCurve::constant(0.1),
            piston: Piston {
                area_m2: 0.01,
                pressure: PressureProfile::Constant { pressure_pa: 0.0 },
                return_spring_n: 0.0,
            },
            open_gap: None,
            spline_friction: 0.1,
        };
        let q = [1000.0, 2000.0, 500.0, 3000.0, 10_000.0];
        let mut f = [0.0; 4];
        s.clamp_forces_n(1000.0, &q, &mut f);
        assert_eq!(f, [900.0, 700.0, 650.0, 350.0]);
        s.clamp_forces_n(500.0, &q, &mut f);
        assert_eq!(f, [400.0, 200.0, 150.0, 0.0]);
    }

    /// Stack order round-trips and interleaves plates and discs, plates at both ends.
    #[test]
    fn stack_order() {
        let n = 3;
        let order: Vec<StackBody> = (0..2 * n + 1).map(StackBody::at).collect();
        assert_eq!(order[0], StackBody::Plate(0));
        assert_eq!(order[1], StackBody::Disc(0));
        assert_eq!(order[2 * n], StackBody::Plate(n));
        for (b, body) in order.iter().enumerate() {
            assert_eq!(body.position(), b);
        }
        let mut idx: Vec<usize> = order.iter().map(|b| b.body_index(n)).collect();
        idx.sort();
        assert_eq!(
            idx,
            (0..2 * n + 1).collect::<Vec<_>>(),
            "every body exactly once"
        );
    }

    /// The piston pushes on the stack only once `p A` exceeds the return spring: its force is
    /// zero before `open_until_s` (checked on a fine grid), which is a ramp's start, the row
    /// of a table before the first one over the spring, never for a pressure below it, and
    /// from the start for a constant pressure or a first row above it; `can_clamp` agrees.
    #[test]
    fn the_piston_is_open_until_it_can_push() {
        let piston = |pressure| Piston {
            area_m2: 0.05,
            pressure,
            return_spring_n: 2000.0,
        };
        let ramp = |p| PressureProfile::Ramp {
            start_s: 0.05,
            rise_s: 0.03,
            pressure_pa: p,
        };
        let table = |y: Vec<f64>| {
            PressureProfile::Table(Table::new(vec![0.0, 0.01, 0.02, 0.03], y).unwrap())
        };
        let cases = [
            (ramp(1.2e6), 0.05),
            (ramp(4.0e4), f64::INFINITY), // 2000 N exactly: never more
            (
                PressureProfile::Constant { pressure_pa: 1e5 },
                f64::NEG_INFINITY,
            ),
            (
                PressureProfile::Constant { pressure_pa: 1e4 },
                f64::INFINITY,
            ),
            (table(vec![0.0, 3e4, 1e5, 0.0]), 0.01),
            (table(vec![5e4, 0.0, 0.0, 0.0]), f64::NEG_INFINITY),
            (table(vec![0.0, 3e4, 3e4, 0.0]), f64::INFINITY),
        ];
        for (pressure, expected) in cases {
            let p = piston(pressure);
            let open = p.open_until_s();
            assert_eq!(open, expected, "{p:?}");
            assert_eq!(p.can_clamp(), open < f64::INFINITY, "{p:?}");
            let mut pushed = false;
            for k in 0..=1000 {
                let t = 1e-4 * k as f64;
                if t < open {
                    assert_eq!(p.force_n(t), 0.0, "{p:?} at {t}");
                }
                pushed |= p.force_n(t) > 0.0;
            }
            assert_eq!(pushed, p.can_clamp(), "{p:?}");
        }
    }
}
