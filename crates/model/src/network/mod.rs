//! Drivelines as networks (MODEL.md section 8): named rotational bodies (shafts, drums, an
//! engine's crank, a vehicle reduced to a shaft) joined by couplings (lumped clutches, ideal
//! gears, gear meshes, spring-dampers and resolved packs), each coupling a term in both
//! bodies' equations, equal and opposite in its own coordinate.
//!
//! Conventions: every body turns about its own axis; angles in rad, speeds in rad/s, torques
//! in N m, positive in the body's sense of rotation. A coupling between bodies `a` and `b`
//! has the relative speed `w_rel = w_b - w_a` for a clutch (Modelica's flanges), and an ideal
//! gear ties `w_a = ratio w_b` (Modelica's `IdealGear`: `phi_a = ratio phi_b`, power
//! conserved: the torque `lambda` on `a` is `-ratio lambda` on `b`).

pub mod clutch;
pub mod element;
pub mod firing;
pub mod friction;
pub mod gear;
pub mod gears;
pub mod ideal_gear;
pub mod output;
pub mod planetary;
pub mod resolved_pack;
pub mod rows;
pub mod signal;
pub mod spring_damper;

pub use crate::session::NetworkSession;
pub use clutch::{ClutchMode, LumpedClutch};
pub use element::{
    ElementLaw, EnergyTerm, InputSpec, Mode, OutputQuantity, OutputSpec, OwnBodies, Ports, SlipEnd,
};
pub use firing::Firing;
pub use gear::GearMesh;
pub use gears::{Gear, GearKinematics, Shift, Transmission};
pub use ideal_gear::IdealGear;
pub use output::{ClutchEvent, NetworkEnergy, NetworkRun, NetworkSample};
pub use planetary::PlanetarySet;
pub use rows::Row;
pub use signal::{NetworkInput, Signal};

use serde::{Deserialize, Serialize};

/// A load that opposes motion: `-sign(w) (a + b |w| + c w^2)` (N m), zero at rest (a
/// vehicle's rolling resistance, losses and air drag reduced to a shaft; at `w = 0` the
/// constant part does not hold the body: it is not static friction). A body it brings to rest
/// while the other torques on it stay within `a` stays there (the equation's own solution
/// across the jump at zero speed; the reference engine holds it so, docs/DECISIONS.md, "A
/// road load at rest").
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RoadLoad {
    /// `a`, N m (>= 0).
    pub constant_n_m: f64,
    /// `b`, N m s/rad (>= 0).
    pub linear_n_m_s_rad: f64,
    /// `c`, N m s^2/rad^2 (>= 0).
    pub quadratic_n_m_s2_rad2: f64,
}

impl RoadLoad {
    /// The load's torque on the body at speed `w` (rad/s), N m, signed against `w`.
    pub fn torque_n_m(&self, w_rad_s: f64) -> f64 {
        if w_rad_s == 0.0 {
            return 0.0;
        }
        let m = w_rad_s.abs();
        -w_rad_s.signum()
            * (self.constant_n_m + self.linear_n_m_s_rad * m + self.quadratic_n_m_s2_rad2 * m * m)
    }
}

/// How a body of a network moves.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub enum Motion {
    /// Under its torques, with its inertia.
    #[default]
    Free,
    /// Fixed (the housing, the ground): it never turns; a clutch to it is a brake.
    Fixed,
    /// At a prescribed speed (a test rig's motor, a one-pack scene's prescribed shaft): its
    /// angle, speed and acceleration are the profile's whatever the torques on it (an infinite
    /// inertia in the constraints, as a fixed body's, but turning); what ties other bodies to
    /// it (a locked clutch, a gear) makes them follow it, and the torque it takes to keep the
    /// profile is its reaction ([`NetworkSample::reaction_n_m`]), whose work the energy audit
    /// counts ([`NetworkEnergy::prescribed_work_j`]).
    Prescribed(crate::SpeedProfile),
}

/// One rotational body of a network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Its name (unique in the network).
    pub name: String,
    /// Inertia about its axis, kg m^2 (> 0; ignored for a fixed body).
    pub inertia_kg_m2: f64,
    /// Viscous drag, N m s/rad (>= 0): the torque `-C w`.
    pub drag_n_m_s_rad: f64,
    /// Speed at t = 0, rad/s (a prescribed body's is its profile's at t = 0).
    pub initial_speed_rad_s: f64,
    /// How it moves: free, fixed or at a prescribed speed ([`Motion`]).
    pub motion: Motion,
    /// The driving torque on it, N m, positive in its sense of rotation (`None`: none).
    pub drive: Option<Signal>,
    /// An engine's firing-order harmonics in its own angle, added to `drive` (`None`: none;
    /// [`Firing`]).
    #[serde(default)]
    pub firing: Option<Firing>,
    /// A load opposing its motion (`None`: none).
    pub road_load: Option<RoadLoad>,
}

impl Body {
    /// Whether it is the fixed body.
    pub fn is_fixed(&self) -> bool {
        self.motion == Motion::Fixed
    }

    /// Whether it moves under its torques (neither fixed nor prescribed).
    #[inline]
    pub fn is_free(&self) -> bool {
        self.motion == Motion::Free
    }

    /// Its speed profile, if it is prescribed.
    pub fn prescribed(&self) -> Option<&crate::SpeedProfile> {
        match &self.motion {
            Motion::Prescribed(p) => Some(p),
            _ => None,
        }
    }

    /// Its inverse inertia in the constraints, 1/(kg m^2): `1 / J` for a free body, 0 for a
    /// fixed or prescribed one (an infinite inertia: its motion is given).
    pub fn inverse_inertia(&self) -> f64 {
        if self.is_free() {
            1.0 / self.inertia_kg_m2
        } else {
            0.0
        }
    }

    /// The driving torque at `t` (s) and the body's angle `theta` (rad), N m: its drive
    /// signal and its firing harmonics.
    #[inline]
    pub fn drive_torque_n_m(&self, t: f64, theta_rad: f64) -> f64 {
        self.drive.as_ref().map_or(0.0, |s| s.value(t))
            + self
                .firing
                .as_ref()
                .map_or(0.0, |f| f.torque_n_m(theta_rad))
    }

    /// The external torque on the body at `t` (s), angle `theta` (rad) and speed `w`
    /// (rad/s), N m: its drive ([`Self::drive_torque_n_m`]), its road load and its drag.
    #[inline]
    pub fn external_torque_n_m(&self, t: f64, theta_rad: f64, w_rad_s: f64) -> f64 {
        let load = self.road_load.map_or(0.0, |l| l.torque_n_m(w_rad_s));
        self.drive_torque_n_m(t, theta_rad) + load - self.drag_n_m_s_rad * w_rad_s
    }
}

/// What a coupling is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CouplingKind {
    /// A lumped friction clutch (a brake when one body is fixed).
    Clutch(LumpedClutch),
    /// An ideal gear: `w_a = ratio w_b` (rigid, no backlash; one degree of freedom fewer).
    IdealGear(IdealGear),
    /// A gear mesh with backlash and a tooth law (gear rattle; MODEL.md section 8).
    GearMesh(GearMesh),
    /// A torsional spring-damper (a damper spring, a dual-mass flywheel; MODEL.md section 8):
    /// `T = k (theta_a - theta_b - theta_0) + d (w_a - w_b)` on `b`, `-T` on `a`.
    SpringDamper(crate::spring::SpringDamper),
    /// A resolved pack (MODEL.md sections 2-5 and 8): its friction discs splined to body `a`,
    /// its separator plates to body `b` (a drum; the housing when `b` is fixed), each disc and
    /// plate a body of its own with its tooth contacts, and its stack and piston. The pack's
    /// own `shaft` and `drum` are not used: the network's bodies `a` and `b` carry it.
    Pack(Box<crate::PackModel>),
    /// A simple planetary set (MODEL.md section 10): body `a` its sun, body `b` its ring,
    /// the carrier named by the set; Willis' equation `z_S w_S + z_R w_R = (z_S + z_R) w_C`
    /// a constraint on the three (rigid, ideal, no backlash). Its torque on `a` is the sun's.
    Planetary(PlanetarySet),
}

/// A coupling between two bodies of a network.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coupling {
    /// Its name (unique in the network).
    pub name: String,
    /// Index of body `a` in [`Network::bodies`].
    pub a: usize,
    /// Index of body `b`.
    pub b: usize,
    /// What it is.
    pub kind: CouplingKind,
}

impl CouplingKind {
    /// An ideal gear of the ratio `w_a / w_b`.
    pub fn ideal_gear(ratio: f64) -> CouplingKind {
        CouplingKind::IdealGear(IdealGear { ratio })
    }

    /// Its law ([`element`]): the one `match` on the kinds, every other part of the tree asks
    /// the law.
    #[inline]
    pub fn law(&self) -> &dyn ElementLaw {
        match self {
            CouplingKind::Clutch(c) => c,
            CouplingKind::IdealGear(g) => g,
            CouplingKind::GearMesh(g) => g,
            CouplingKind::SpringDamper(s) => s,
            CouplingKind::Pack(p) => &**p,
            CouplingKind::Planetary(p) => p,
        }
    }
}

impl Coupling {
    /// Its law ([`CouplingKind::law`]).
    #[inline]
    pub fn law(&self) -> &dyn ElementLaw {
        self.kind.law()
    }

    /// Its lumped clutch, if it is one.
    pub fn clutch(&self) -> Option<&LumpedClutch> {
        match &self.kind {
            CouplingKind::Clutch(c) => Some(c),
            _ => None,
        }
    }

    /// Its gear mesh, if it is one.
    pub fn mesh(&self) -> Option<&GearMesh> {
        match &self.kind {
            CouplingKind::GearMesh(g) => Some(g),
            _ => None,
        }
    }

    /// Its resolved pack, if it is one.
    pub fn pack(&self) -> Option<&crate::PackModel> {
        match &self.kind {
            CouplingKind::Pack(p) => Some(p),
            _ => None,
        }
    }
}

/// A driveline: bodies and the couplings between them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Network {
    /// The bodies.
    pub bodies: Vec<Body>,
    /// The couplings.
    pub couplings: Vec<Coupling>,
    /// The thermal model of each resolved pack that carries temperatures (its pack file's
    /// `[thermal]`, MODEL.md section 9), by coupling index; the others run isothermal.
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub pack_thermal: std::collections::BTreeMap<usize, crate::thermal::ThermalModel>,
}

/// A problem with a network, naming the body or coupling (by index) and what is wrong; the
/// scene turns it into a key path.
#[derive(Debug, Clone, PartialEq)]
pub enum NetworkProblem {
    /// A body's field.
    Body {
        /// Index in `bodies`.
        index: usize,
        /// The field (`inertia_kg_m2`, `name`, ...).
        field: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A coupling's field.
    Coupling {
        /// Index in `couplings`.
        index: usize,
        /// The field (`a`, `b`, `ratio`, `mu`, ...).
        field: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// Why `name` cannot name a body or a coupling of a network, if it cannot: a name is part of
/// every output and co-simulation variable that concerns its part (`bodies.<name>.speed_rad_s`,
/// `couplings.<name>.heat_j`, a figure's legend), so it is not empty, has no character that
/// separates the parts of such a name (`.`, `[`, `]`), no quote, and no control character or
/// space at either end.
pub fn name_problem(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        Some("must not be empty (outputs and co-simulation variables are named by it)")
    } else if name.chars().any(|c| c.is_control()) {
        Some("must not contain control characters")
    } else if name.trim() != name {
        Some("must not begin or end with a space")
    } else if name.contains(['.', '[', ']', '"', '\'', '\\']) {
        Some("must not contain '.', '[', ']', quotes or '\\' (they separate or quote the parts of a variable name such as bodies.<name>.speed_rad_s)")
    } else {
        None
    }
}

impl Network {
    /// The index of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The network's problems (empty when an engine can run it): unique names; positive
    /// inertias; at most one fixed body; couplings naming two different bodies; ideal gears that form no loop (a loop
    /// over-constrains, consistent or not) and do not tie a moving body to a fixed one;
    /// speeds that satisfy the ideal gears at t = 0; every group of connected bodies with
    /// something that moves it (a drive, or a speed at t = 0).
    pub fn problems(&self) -> Vec<NetworkProblem> {
        let mut out = Vec::new();
        let body = |index, field, message: String| NetworkProblem::Body {
            index,
            field,
            message,
        };
        let coupling = |index, field, message: String| NetworkProblem::Coupling {
            index,
            field,
            message,
        };
        if self.bodies.is_empty() {
            out.push(body(0, "name", "a network needs at least one body".into()));
        }
        for (i, b) in self.bodies.iter().enumerate() {
            if let Some(why) = name_problem(&b.name) {
                out.push(body(i, "name", why.into()));
            }
            if self.bodies[..i].iter().any(|o| o.name == b.name) {
                out.push(body(i, "name", format!("\"{}\" names two bodies", b.name)));
            }
            let good_inertia = b.inertia_kg_m2.is_finite() && b.inertia_kg_m2 > 0.0;
            if b.is_free() && !good_inertia {
                out.push(body(
                    i,
                    "inertia_kg_m2",
                    format!("{} must be > 0", crate::fmt_num(b.inertia_kg_m2)),
                ));
            }
            if b.is_fixed() && b.initial_speed_rad_s != 0.0 {
                out.push(body(
                    i,
                    "initial_speed_rad_s",
                    "a fixed body does not turn: its speed is 0".into(),
                ));
            }
            if let Some(p) = b.prescribed() {
                let w0 = p.speed(0.0);
                if (b.initial_speed_rad_s - w0).abs() > 1e-12 * (1.0 + w0.abs()) {
                    out.push(body(
                        i,
                        "initial_speed_rad_s",
                        format!(
                            "a prescribed body starts at its profile's speed, {} rad/s",
                            crate::fmt_num(w0)
                        ),
                    ));
                }
                let torque = if b.drive.is_some() {
                    Some("drive")
                } else if b.firing.is_some() {
                    Some("firing")
                } else if b.road_load.is_some() {
                    Some("road_load")
                } else if b.drag_n_m_s_rad != 0.0 {
                    Some("drag_n_m_s_rad")
                } else {
                    None
                };
                if let Some(field) = torque {
                    out.push(body(
                        i,
                        field,
                        "a prescribed body follows its speed whatever the torques on it: a torque on it changes only its reaction; remove it".into(),
                    ));
                }
            }
            if b.is_fixed() && (b.drive.is_some() || b.firing.is_some() || b.road_load.is_some()) {
                out.push(body(
                    i,
                    if b.drive.is_some() {
                        "drive"
                    } else if b.firing.is_some() {
                        "firing"
                    } else {
                        "road_load"
                    },
                    "a fixed body does not turn: a torque on it does nothing; remove it".into(),
                ));
            }
            if b.is_fixed() && self.bodies[..i].iter().any(|o| o.is_fixed()) {
                out.push(body(
                    i,
                    "fixed",
                    "a second fixed body: the ground is one body (brakes to it share it)".into(),
                ));
            }
            if b.drive.as_ref().is_some_and(|d| !d.is_valid()) {
                out.push(body(i, "drive", "has a value that is not finite".into()));
            }
            if let Some(why) = b.firing.as_ref().and_then(Firing::problem) {
                out.push(body(i, "firing", why));
            }
        }
        let n = self.bodies.len();
        // union-find with the speed factor of each body against its root: w_i = g_i w_root
        let mut root: Vec<usize> = (0..n).collect();
        let mut factor = vec![1.0; n];
        fn find(root: &mut [usize], factor: &mut [f64], i: usize) -> (usize, f64) {
            let (mut r, mut g) = (i, 1.0);
            while root[r] != r {
                g *= factor[r];
                r = root[r];
            }
            (r, g)
        }
        let mut linked: Vec<usize> = (0..n).collect(); // components over every coupling
        fn top(linked: &mut [usize], mut i: usize) -> usize {
            while linked[i] != i {
                i = linked[i];
            }
            i
        }
        for (k, c) in self.couplings.iter().enumerate() {
            if let Some(why) = name_problem(&c.name) {
                out.push(coupling(k, "name", why.into()));
            }
            if self.couplings[..k].iter().any(|o| o.name == c.name) {
                out.push(coupling(
                    k,
                    "name",
                    format!("\"{}\" names two couplings", c.name),
                ));
            }
            if c.a >= n || c.b >= n {
                out.push(coupling(
                    k,
                    "a",
                    "names a body that is not in the network".into(),
                ));
                continue;
            }
            if c.a == c.b {
                out.push(coupling(
                    k,
                    "b",
                    format!("couples \"{}\" to itself", self.bodies[c.a].name),
                ));
                continue;
            }
            let (ta, tb) = (top(&mut linked, c.a), top(&mut linked, c.b));
            linked[ta] = tb;
            let (law, ports) = (c.law(), c.ports());
            let sound = law.problems(self, k, &ports, &mut out);
            // a further port (a planetary set's carrier) joins the group
            for &p in &ports[2..] {
                if p < n {
                    let (tp, tb) = (top(&mut linked, p), top(&mut linked, c.b));
                    linked[tp] = tb;
                }
            }
            let Some(ratio) = law.fixed_ratio().filter(|_| sound) else {
                continue;
            };
            // a rigid two-port tie `w_a = ratio w_b` (an ideal gear): no loop of them, and
            // speeds at t = 0 that keep it
            let (ba, bb) = (&self.bodies[c.a], &self.bodies[c.b]);
            let (ra, ga) = find(&mut root, &mut factor, c.a);
            let (rb, gb) = find(&mut root, &mut factor, c.b);
            if ra == rb {
                out.push(coupling(
                    k,
                    "b",
                    "closes a loop of ideal gears, which over-constrains the bodies (one gear of the loop is redundant, or the ratios contradict)".into(),
                ));
                continue;
            }
            // w_a = ratio w_b: w_rb = (ga / (ratio gb)) w_ra... join rb under ra
            root[rb] = ra;
            factor[rb] = ga / (ratio * gb);
            let (wa, wb) = (ba.initial_speed_rad_s, bb.initial_speed_rad_s);
            let want = ratio * wb;
            if (wa - want).abs() > 1e-9 * (1.0 + wa.abs().max(want.abs())) {
                out.push(coupling(
                    k,
                    "ratio",
                    format!(
                        "the speeds at t = 0 do not mesh: \"{}\" turns at {} rad/s but ratio x \"{}\"'s {} rad/s is {}",
                        ba.name,
                        crate::fmt_num(wa),
                        bb.name,
                        crate::fmt_num(wb),
                        crate::fmt_num(want)
                    ),
                ));
            }
        }
        // the rigid rows that hold always (gears, planetary sets) independent: a redundant one
        // over-constrains the bodies (the gears' loops are found above with their ratios)
        // (a prescribed body's motion is given as a fixed body's is: a gear between two
        // bodies whose motions are given, directly or through other gears, over-constrains)
        let prescribed = self.bodies.iter().any(|b| b.prescribed().is_some());
        if out.is_empty() && (prescribed || self.couplings.iter().any(|c| c.ports().len() > 2)) {
            let mut rows: Vec<Row> = self
                .couplings
                .iter()
                .enumerate()
                .filter_map(|(k, c)| c.row(k, None))
                .collect();
            let inv: Vec<f64> = self
                .bodies
                .iter()
                .map(|b| if b.is_free() { 1.0 } else { 0.0 })
                .collect();
            for r in rows::redundant(&rows, &inv) {
                out.push(coupling(
                    rows[r].coupling,
                    "b",
                    "over-constrains its bodies: with the ideal gears and planetary sets before it, its constraint is redundant or contradicts them (every member it ties is already tied, or held by a fixed or prescribed body)".into(),
                ));
            }
            // a clutch that could lock a prescribed body to the fixed one or to another
            // prescribed one (directly or through the gears): its lock would over-constrain
            let always = rows.len();
            for (k, c) in self.couplings.iter().enumerate() {
                if !prescribed || c.row(k, None).is_some() {
                    continue;
                }
                let Some(lock) = c.row(k, Some(ClutchMode::Locked)) else {
                    continue;
                };
                rows.push(lock);
                if rows::redundant(&rows, &inv).contains(&always) {
                    out.push(coupling(
                        k,
                        "b",
                        "could lock two bodies whose motions are given (a prescribed body and the fixed one, or two prescribed ones, directly or through gears): the lock would over-constrain them; give one of them an inertia".into(),
                    ));
                }
                rows.pop();
            }
        }
        // every group of connected bodies has something that moves it
        for i in 0..n {
            let t = top(&mut linked, i);
            if (0..i).any(|j| top(&mut linked, j) == t) {
                continue; // reported with the group's first body
            }
            let group: Vec<usize> = (0..n).filter(|&j| top(&mut linked, j) == t).collect();
            let moved = group.iter().any(|&j| {
                let b = &self.bodies[j];
                b.drive.is_some()
                    || b.firing.is_some()
                    || b.initial_speed_rad_s != 0.0
                    || b.prescribed().is_some()
            });
            if !moved && group.iter().any(|&j| !self.bodies[j].is_fixed()) {
                out.push(body(
                    i,
                    "drive",
                    format!(
                        "nothing moves \"{}\"{}: no body on its path has a drive or a speed at t = 0",
                        self.bodies[i].name,
                        if group.len() > 1 {
                            format!(" and the {} bodies coupled to it", group.len() - 1)
                        } else {
                            String::new()
                        }
                    ),
                ));
            }
        }
        out
    }

    /// What every engine checks before it runs the network for `duration_s` seconds: no
    /// [`Self::problems`], and a finite, non-negative duration.
    pub fn check_run(&self, duration_s: f64) -> Result<(), crate::EngineError> {
        if let Some(p) = self.problems().first() {
            return Err(crate::EngineError::Unsupported(format!("{p:?}")));
        }
        if !(duration_s.is_finite() && duration_s >= 0.0) {
            return Err(crate::EngineError::Unsupported(format!(
                "duration {} s must be finite and >= 0",
                crate::fmt_num(duration_s)
            )));
        }
        Ok(())
    }

    /// Every instant (s, sorted, unique, within `[0, end]`) where a signal of the network jumps
    /// or bends: the engines land a step on each.
    pub fn breakpoints(&self, end_s: f64) -> Vec<f64> {
        let mut out = Vec::new();
        for b in &self.bodies {
            if let Some(d) = &b.drive {
                d.breakpoints(&mut out);
            }
            if let Some(crate::SpeedProfile::Table(table)) = b.prescribed() {
                // a prescribed speed table's rows: its slope (or its value, held) jumps
                out.extend_from_slice(&table.t_s);
            }
        }
        for c in &self.couplings {
            c.law().breakpoints(&mut out);
        }
        out.retain(|t| *t > 0.0 && *t < end_s);
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(name: &str, w: f64) -> Body {
        Body {
            name: name.into(),
            inertia_kg_m2: 1.0,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: w,
            motion: Motion::Free,
            drive: None,
            firing: None,
            road_load: None,
        }
    }

    fn gear(name: &str, a: usize, b: usize, ratio: f64) -> Coupling {
        Coupling {
            name: name.into(),
            a,
            b,
            kind: CouplingKind::ideal_gear(ratio),
        }
    }

    /// A road load opposes motion and vanishes at rest.
    #[test]
    fn road_load_opposes_motion() {
        let l = RoadLoad {
            constant_n_m: 1.0,
            linear_n_m_s_rad: 0.1,
            quadratic_n_m_s2_rad2: 0.01,
        };
        assert!((l.torque_n_m(10.0) + 3.0).abs() < 1e-15);
        assert!((l.torque_n_m(-10.0) - 3.0).abs() < 1e-15);
        assert_eq!(l.torque_n_m(0.0), 0.0);
    }

    /// A loop of ideal gears, a coupling to itself, an unmeshed start and a body nothing moves
    /// are each reported at their coupling or body.
    #[test]
    fn problems_name_the_part() {
        let mut net = Network {
            pack_thermal: Default::default(),
            bodies: vec![
                body("a", 3.0),
                body("b", 1.0),
                body("c", 1.0),
                body("d", 0.0),
            ],
            couplings: vec![gear("g1", 0, 1, 3.0), gear("g2", 1, 2, 1.0)],
        };
        let p = net.problems();
        assert_eq!(p.len(), 1, "{p:?}");
        assert!(matches!(
            &p[0],
            NetworkProblem::Body {
                index: 3,
                field: "drive",
                ..
            }
        ));
        net.bodies[3].initial_speed_rad_s = 1.0;
        assert!(net.problems().is_empty());
        net.couplings.push(gear("g3", 2, 0, 1.0 / 3.0));
        let p = net.problems();
        assert!(
            matches!(&p[0], NetworkProblem::Coupling { index: 2, field: "b", message } if message.contains("loop")),
            "{p:?}"
        );
        net.couplings.pop();
        net.couplings[0].kind = CouplingKind::ideal_gear(2.0);
        let p = net.problems();
        assert!(
            matches!(&p[0], NetworkProblem::Coupling { index: 0, field: "ratio", message } if message.contains("do not mesh")),
            "{p:?}"
        );
    }
}
