//! The reference engine on a driveline network of lumped parts (MODEL.md section 8): one
//! rotational degree of freedom per body, ideal gears and locked clutches as constraints (the
//! rigid groups of `cluster.rs`), slipping clutches as torques, every stick, slip, break and
//! release located as an event.
//!
//! # Method
//! The state is every body's angle and speed, each gear mesh's relative displacement along
//! its line of action and each spring-damper's twist (integrated themselves, with an absolute
//! tolerance on the backlash's scale and on the tolerance in rad,
//! as the pack engine integrates its relative angles: the bodies' angles grow without bound,
//! and their error with them), plus the energy counters (each clutch's heat,
//! the drives' and loads' work, the drag's loss) integrated beside them (outside the error
//! norm). Between events the modes are fixed and the right-hand side is smooth: adaptive
//! DOPRI5 steps (the pack engine's `dopri.rs`), landing on every instant where a
//! signal jumps or bends ([`Network::breakpoints`]). After each step the event functions are
//! probed at the step's quarter points on the dense output:
//! - a slipping clutch: `s w_rel` reaching 0 (`s` its direction), and its normal force
//!   reaching 0 (free);
//! - a locked clutch: `peak mu(0) cgeo fn - |tau|` reaching 0 (it breaks), `fn` reaching 0;
//! - a free clutch: `fn` rising above 0 (it engages);
//! - a gear mesh: the engagement depth of its tooth law reaching 0 from either side (a tooth
//!   contact's onset, where the law's per-event memory is taken, and its separation);
//! - a resolved pack: each disc's and plate's tooth contacts and each face's stick and slip
//!   (`packs.rs`, which also holds the pack's share of the state and of the right-hand side);
//! - a body with a road load's constant part `a > 0`: its speed reaching 0 (moving), or the
//!   other torques on its rigid group leaving the load's breakaway (held at rest).
//!
//! A crossing is bisected on the dense output to 1e-13 s relative; the run restarts there
//! with the modes settled as Modelica's `Clutch` settles them (Otter, Elmqvist and Mattsson
//! 1999): a clutch whose slip reached zero, or that engages at zero slip, is locked if the
//! torque that holds the new rigid group stays within its static limit, and slips towards the
//! torque otherwise (startForward / startBackward); the check repeats until every locked clutch
//! holds. Locking sets the group's speeds to its common speed (momentum kept; the slip there is
//! below 1e-12 rad/s).
//!
//! A road load opposes motion and jumps from `-a` to `+a` through zero speed (the model's
//! `RoadLoad`): a body it brings to rest while the other torques on its rigid group stay
//! within the load's breakaway `sum |g_i| a_i` would chatter across zero in steps of 1e-7 s
//! (issue 48, item 4: ten million steps per simulated second). It is held at rest instead, as
//! a clutch's stick is held (`modes.rs`, `hold_road_loads`): the group's speed set to 0, the
//! held bodies' loads the reaction that keeps it there (the discontinuous equation's own
//! solution, Filippov's sliding mode at zero speed: what the chatter averages to), until the
//! other torques exceed the breakaway and the group starts towards them.

pub(crate) mod cluster;
mod mesh;
mod modes;
mod packs;
mod stepper;

pub use stepper::{run_network, NetworkInput, NetworkStepper};

use cluster::{Clusters, Freedom};
use clutchpack_model::network::{ClutchMode, GearMesh, Network, Row};
// the output types are the model's, shared with the multibody engine
pub use clutchpack_model::network::{ClutchEvent, NetworkEnergy, NetworkRun, NetworkSample};
use clutchpack_model::Engagement;
use std::sync::Arc;

/// Settings of a network run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NetworkOptions {
    /// Relative (and absolute, on rad and rad/s) tolerance of the adaptive steps.
    pub tolerance: f64,
    /// Longest step, s.
    pub max_step_s: f64,
    /// Rate of the samples, Hz (0: none but the first and last).
    pub record_rate_hz: f64,
}

impl Default for NetworkOptions {
    fn default() -> Self {
        NetworkOptions {
            tolerance: 1e-9,
            max_step_s: 1e-3,
            record_rate_hz: 1000.0,
        }
    }
}

/// The network's equations in one mode.
#[derive(Clone)]
struct Equations {
    /// The network (shared with the modes' settling; an input set in a session replaces a
    /// signal in it: [`NetworkStepper::set_input`]).
    net: Arc<Network>,
    modes: Vec<Option<ClutchMode>>,
    /// Each gear mesh's contact event (its law's memory), `None` in free flight.
    contacts: Vec<Option<Engagement>>,
    clusters: Clusters,
    /// The resolved packs, in coupling order (their state after the network's counters).
    packs: Vec<packs::NetPack>,
    /// Each pack's bodies' loads at the state of the last [`Equations::forces`], N (by slot;
    /// [`crate::system::System::loads_into`]): its reactions' and then its stack's.
    loads: Vec<Vec<f64>>,
    // scratch
    torque: Vec<f64>,
    acc: Vec<f64>,
    group: Vec<f64>,
    coupling_torque: Vec<f64>,
    mesh_force: Vec<f64>,
    /// Whether each body is held at rest by its road load (the module's docs).
    held: Vec<bool>,
    /// The direction each body with a road load's constant part moved in at the last
    /// settling (+1, -1; 0: at rest, or no such load): its guard is its speed along it.
    moving: Vec<f64>,
    /// Each rigid group's torque `sum g_i T_i` without the holding reactions (N m, on its
    /// speed) and the breakaway its held bodies give, `sum |g_i| a_i` (N m), as the last
    /// [`Equations::forces`] found them (while any body is held).
    hold_torque: Vec<f64>,
    hold_capacity: Vec<f64>,
    /// Each prescribed body's acceleration at the last [`Equations::forces`], rad/s^2 (0 for
    /// the other bodies).
    alpha: Vec<f64>,
    /// The counters after the couplings': drive work, load work, drag loss, and with a
    /// prescribed body its reactions' work (3 or 4; docs/DECISIONS.md "A prescribed body").
    counters: usize,
}

/// A mesh's tooth kinematics at the state `y = [angles, speeds, ...]`.
fn mesh_kinematics(
    net: &Network,
    k: usize,
    g: &GearMesh,
    y: &[f64],
) -> clutchpack_model::ToothKinematics {
    let n = net.bodies.len();
    let c = &net.couplings[k];
    // x is its own state component; its rate from the speeds
    let (_, v) = g.displacement((0.0, 0.0), (y[n + c.a], y[n + c.b]));
    g.kinematics(y[2 * n + k], v)
}

impl Equations {
    fn new(net: Arc<Network>, modes: Vec<Option<ClutchMode>>) -> Self {
        let (n, m) = (net.bodies.len(), net.couplings.len());
        let clusters = Clusters::build(&net, rigid_rows(&net, &modes));
        // a fourth counter only with a prescribed body: the state of every other network
        // keeps its layout (and its error norm its terms)
        let counters = if net.bodies.iter().any(|b| b.prescribed().is_some()) {
            4
        } else {
            3
        };
        let packs = packs::build(&net, 2 * n + 2 * m + counters, m);
        Equations {
            loads: vec![Vec::new(); packs.len()],
            alpha: vec![0.0; n],
            counters,
            packs,
            net,
            modes,
            contacts: vec![None; m],
            clusters,
            torque: vec![0.0; n],
            acc: vec![0.0; n],
            group: Vec::new(),
            coupling_torque: vec![0.0; m],
            mesh_force: vec![0.0; m],
            held: vec![false; n],
            moving: vec![0.0; n],
            hold_torque: Vec::new(),
            hold_capacity: Vec::new(),
        }
    }

    /// The first guard of the bodies' road loads (after the couplings' and the packs').
    fn body_guard_at(&self) -> usize {
        self.net.couplings.len() + self.packs.iter().map(packs::NetPack::guards).sum::<usize>()
    }

    /// The breakaway of body `i`'s road load, N m: its constant part (0: none, or fixed).
    fn breakaway(&self, i: usize) -> f64 {
        let b = &self.net.bodies[i];
        if !b.is_free() {
            0.0
        } else {
            b.road_load.map_or(0.0, |l| l.constant_n_m)
        }
    }

    /// The held bodies' reactions added to `torque` (each group's torque, clamped to its
    /// breakaway, shared by the held bodies in proportion to `|g_i| a_i`), after their own
    /// road loads and drags were taken at zero speed; each group's torque and breakaway kept
    /// for the guards.
    fn hold(&mut self) {
        let groups = self.clusters.inertia.len();
        self.hold_torque.clear();
        self.hold_torque.resize(groups, 0.0);
        self.hold_capacity.clear();
        self.hold_capacity.resize(groups, 0.0);
        for i in 0..self.torque.len() {
            let (c, g) = (self.clusters.of[i], self.clusters.g[i]);
            self.hold_torque[c] += g * self.torque[i];
            if self.held[i] {
                let a = self.breakaway(i);
                self.hold_capacity[c] += g.abs() * a;
            }
        }
        for i in 0..self.torque.len() {
            if self.held[i] {
                let (c, g) = (self.clusters.of[i], self.clusters.g[i]);
                let (cap, gt) = (self.hold_capacity[c], self.hold_torque[c]);
                let share = g.abs() * self.breakaway(i) / cap;
                self.torque[i] += (-gt).clamp(-cap, cap) * share / g;
            }
        }
    }

    /// The bodies' kinetic energy at the state `y`, J, with every pack's discs and plates.
    fn kinetic_j(&self, y: &[f64]) -> f64 {
        let net = &self.net;
        let n = net.bodies.len();
        let w = &y[n..2 * n];
        net.bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| b.is_free())
            .map(|(i, b)| 0.5 * b.inertia_kg_m2 * y[n + i] * y[n + i])
            .sum::<f64>()
            + self.packs.iter().map(|p| p.kinetic_j(y, w)).sum::<f64>()
    }

    /// The state's length: the bodies' angles and speeds, a slot and a counter per coupling,
    /// the drives', loads' and drag's counters, then every pack's state.
    fn dim(&self) -> usize {
        let (n, m) = (self.net.bodies.len(), self.net.couplings.len());
        2 * n + 2 * m + self.counters + self.packs.iter().map(packs::NetPack::len).sum::<usize>()
    }

    /// The guards' count: one per coupling, then every pack's.
    fn guard_len(&self) -> usize {
        self.body_guard_at() + self.net.bodies.len()
    }

    /// Sets the couplings' modes and builds their rigid groups, kept when the modes are
    /// those they were built for (the groups follow from the modes alone: an input set in a
    /// session changes a signal, never a row; most events, a pack's tooth contacts among
    /// them, leave the modes as they were).
    fn set_modes(&mut self, modes: &[Option<ClutchMode>]) {
        if self.modes == modes {
            return;
        }
        self.modes.copy_from_slice(modes);
        self.clusters = Clusters::build(&self.net, rigid_rows(&self.net, &self.modes));
    }

    /// Bodies' torques (all but the rigid couplings') and accelerations at `(t, y)`; the
    /// slipping clutches' and the meshes' torques into `coupling_torque` (and each mesh's
    /// force per pair, N, into `mesh_force`).
    fn forces(&mut self, t: f64, y: &[f64]) {
        self.torques(t, y);
        self.accelerations();
    }

    /// [`Self::forces`] without the accelerations (`acc` left as it was): what the guards,
    /// the samples and the modes' settling read (the rigid couplings' torques, the holds'
    /// margins), the same values. Only the right-hand side reads `acc`, after its own
    /// [`Self::forces`]; the guards' probes and bisections took the accelerations for nothing
    /// (issue 45: the resolved shift's cost).
    fn torques(&mut self, t: f64, y: &[f64]) {
        let n = self.net.bodies.len();
        let w = &y[n..2 * n];
        for (i, b) in self.net.bodies.iter().enumerate() {
            if let Some(p) = b.prescribed() {
                self.alpha[i] = p.acceleration(t);
            }
            self.torque[i] = if !b.is_free() {
                0.0
            } else if self.held[i] {
                // at rest: its load is the holding reaction (`hold`), its drag nothing
                b.external_torque_n_m(t, y[i], 0.0)
            } else {
                b.external_torque_n_m(t, y[i], w[i])
            };
        }
        for (k, c) in self.net.couplings.iter().enumerate() {
            self.coupling_torque[k] = 0.0;
            // MODEL.md section 8: a force element's torque on a, the opposite on b (a
            // slipping clutch's, a spring-damper's at its twist, its own state)
            let law = c.law();
            if let Some(ta) = law.port_torque_n_m(t, y[2 * n + k], w[c.a], w[c.b], self.modes[k]) {
                self.coupling_torque[k] = ta;
                self.torque[c.a] += ta;
                self.torque[c.b] -= ta;
            }
            if let (Some(g), Some(e)) = (c.mesh(), self.contacts[k]) {
                // MODEL.md section 8: F signed as x; -Rb_a F on a, -+Rb_b F on b
                let f = g.force_n(&mesh_kinematics(&self.net, k, g, y), &e);
                let (ta, tb) = g.torques_n_m(f);
                self.mesh_force[k] = f;
                self.coupling_torque[k] = ta;
                self.torque[c.a] += ta;
                self.torque[c.b] += tb;
            }
        }
        for (p, loads) in self.packs.iter().zip(self.loads.iter_mut()) {
            // packs.rs, pass (1): the spline reactions (Hu et al. eq 4) on both carriers,
            // from the bodies' loads (kept for the stack's balance at the same state)
            p.sys.loads_into(p.part(y), &p.modes, loads);
            let [ta, tb] = p.sys.reactions_from_n_m(loads, &p.modes);
            self.coupling_torque[p.k] = ta;
            self.torque[p.a] += ta;
            self.torque[p.b] += tb;
        }
        if self.held.contains(&true) {
            self.hold();
        }
    }

    /// The bodies' accelerations from the torques of the last [`Self::torques`], rad/s^2.
    fn accelerations(&mut self) {
        let any_held = self.held.contains(&true);
        self.clusters
            .accelerations(&self.torque, &mut self.acc, &mut self.group);
        if self.clusters.any_prescribed() {
            self.clusters.add_prescribed(&self.alpha, &mut self.acc);
        }
        if any_held {
            // a group held within its breakaway does not move: exactly (the reactions'
            // sum cancels the other torques only to rounding)
            for i in 0..self.acc.len() {
                let c = self.clusters.of[i];
                if self.hold_capacity[c] > 0.0 && self.hold_torque[c].abs() <= self.hold_capacity[c]
                {
                    self.acc[i] = 0.0;
                }
            }
        }
    }

    /// The rigid couplings' torques at the state of the last [`Self::forces`].
    fn rigid_torques(&mut self) {
        self.clusters
            .rigid_torques(&self.torque, &self.alpha, &mut self.coupling_torque);
    }

    /// `dy/dt` of the state `[angles, speeds, meshes' x, counters]`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.net.bodies.len();
        let (theta_dot, rest) = dy.split_at_mut(n);
        let (w_dot, rest) = rest.split_at_mut(n);
        let m = self.net.couplings.len();
        let (x_dot, counters) = rest.split_at_mut(m);
        let w = &y[n..2 * n];
        theta_dot.copy_from_slice(w);
        self.forces(t, y);
        w_dot.copy_from_slice(&self.acc);
        for (k, c) in self.net.couplings.iter().enumerate() {
            x_dot[k] = c.law().state_rate(w[c.a], w[c.b]);
        }
        // counters: [power into each element, drive work, load work, drag loss]
        for k in 0..m {
            let c = &self.net.couplings[k];
            let p = c
                .law()
                .power_w(self.modes[k], self.coupling_torque[k], w[c.a], w[c.b]);
            counters[k] = if let Some(p) = p {
                p
            } else if let (Some(g), Some(_)) = (c.mesh(), self.contacts[k]) {
                // power into the mesh: F v pairs (the torques' work on the bodies, negated)
                let (_, v) = g.displacement((0.0, 0.0), (w[c.a], w[c.b]));
                self.mesh_force[k] * v * g.pairs
            } else {
                0.0
            };
        }
        let (mut drive, mut load, mut drag) = (0.0, 0.0, 0.0);
        for (i, b) in self.net.bodies.iter().enumerate() {
            if !b.is_free() {
                continue;
            }
            drive += b.drive_torque_n_m(t, y[i]) * w[i];
            load += b.road_load.map_or(0.0, |l| l.torque_n_m(w[i])) * w[i];
            drag += b.drag_n_m_s_rad * w[i] * w[i];
        }
        counters[m] = drive;
        counters[m + 1] = load;
        counters[m + 2] = drag;
        if self.counters == 4 {
            // the prescribed bodies' reactions' power, R w (the torques of `forces` above)
            counters[m + 3] = (0..n)
                .filter(|&i| self.net.bodies[i].prescribed().is_some())
                .map(|i| self.clusters.reaction_n_m(i, &self.torque, &self.alpha) * w[i])
                .sum();
        }
        for (p, loads) in self.packs.iter().zip(&self.loads) {
            // packs.rs, pass (3): each pack's bodies against their carriers' motion (the
            // loads of pass (1), at this state)
            let c = p.carriers(w, &self.acc);
            let (at, d) = (p.at, p.sys.dim());
            let (part, rate) = (&y[at..at + d], &mut dy[at..at + d]);
            p.sys
                .rhs_with_loads(t, part, &p.modes, &c, Some(loads), rate);
            dy[at + d] = p.drag_power_w(y, w);
        }
    }

    /// The event functions at `(t, y)`, one per coupling (> 0 while its mode holds): a
    /// mesh's engagement depth, every other element's own guard
    /// ([`clutchpack_model::network::ElementLaw::guard`]: a clutch's slip, static margin or
    /// normal force), then the packs' and the road loads'.
    fn guards(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        self.guards_where(t, y, out, None);
    }

    /// [`Self::guards`] of the guards `want` marks only (the others in `out` left as they
    /// were, but a pack's faces written together), each the same value: the forces computed only for a marked coupling's or
    /// road load's guard, a pack's stack only for a marked face, a disc's or plate's depth
    /// only where marked. An event's bisection evaluates those that crossed by its bracket's
    /// end (`stepper.rs`): another guard could only have moved it by dipping to <= 0 and back
    /// between two probes with a trial landing in the dip (docs/DECISIONS.md, "The resolved
    /// shift's event guards").
    fn guards_of(&mut self, t: f64, y: &[f64], out: &mut [f64], want: &[bool]) {
        self.guards_where(t, y, out, Some(want));
    }

    /// The state's components every guard reads: the bodies' angles and speeds, the
    /// elements' own states and the packs' discs' and plates' relative angles and speeds (not
    /// the counters, the faces' heat, the teeth's work or the drag's): a step's probes
    /// interpolate those alone (issue 45, the resolved shift's cost).
    fn probe_inputs(&self) -> Vec<std::ops::Range<usize>> {
        let (n, m) = (self.net.bodies.len(), self.net.couplings.len());
        std::iter::once(0..2 * n + m)
            .chain((self.packs.iter()).map(|p| p.at..p.at + 2 * p.sys.ids.len()))
            .collect()
    }

    /// The state's components the guards `want` marks read, when they are only packs'
    /// (their discs' and plates' relative angles and speeds, and the bodies' speeds for
    /// their faces): an event's bisection between two probes then interpolates those alone
    /// (issue 45, the resolved shift's cost: most events are a disc's or a plate's tooth
    /// contact). `None` (the whole state) when a coupling's or a road load's guard is marked:
    /// they take the network's forces, which read every body and element.
    fn guard_inputs(&self, want: &[bool]) -> Option<Vec<std::ops::Range<usize>>> {
        let (n, m) = (self.net.bodies.len(), self.net.couplings.len());
        let at = self.body_guard_at();
        if want[..m].contains(&true) || want[at..].contains(&true) {
            return None;
        }
        let mut ranges = Vec::with_capacity(1 + self.packs.len());
        ranges.push(n..2 * n);
        for p in &self.packs {
            if want[p.guard_at..p.guard_at + p.guards()].contains(&true) {
                ranges.push(p.at..p.at + 2 * p.sys.ids.len());
            }
        }
        Some(ranges)
    }

    /// [`Self::guards`] (`want` `None`) or [`Self::guards_of`].
    fn guards_where(&mut self, t: f64, y: &[f64], out: &mut [f64], want: Option<&[bool]>) {
        let n = self.net.bodies.len();
        let m = self.net.couplings.len();
        let w = &y[n..2 * n];
        let at = self.body_guard_at();
        let wanted = |i: usize| want.is_none_or(|x| x[i]);
        // the couplings' and the road loads' guards need the forces when a clutch is locked
        // or a body held; the packs' never do
        let any_own = want.is_none_or(|x| x[..m].contains(&true) || x[at..at + n].contains(&true));
        let any_locked = self.modes.contains(&Some(ClutchMode::Locked));
        let any_held = self.held.contains(&true);
        // the forces at this state give the packs' loads too
        let forced = any_own && (any_locked || any_held);
        if forced {
            self.torques(t, y);
            self.rigid_torques();
        }
        for (k, c) in self.net.couplings.iter().enumerate() {
            if !wanted(k) {
                continue;
            }
            if let Some(g) = c.mesh() {
                let depth = g
                    .law
                    .engagement_depth_m(&mesh_kinematics(&self.net, k, g, y));
                out[k] = if self.contacts[k].is_some() {
                    depth
                } else {
                    -depth
                };
                continue;
            }
            let (w_rel, held) = (w[c.b] - w[c.a], self.coupling_torque[k]);
            out[k] = c.law().guard(t, w_rel, self.modes[k], held);
        }
        for (p, loads) in self.packs.iter().zip(&self.loads) {
            let r = p.guard_at..p.guard_at + p.guards();
            let known = forced.then_some(&loads[..]);
            p.guard_values(t, y, w, &mut out[r.clone()], want.map(|x| &x[r]), known);
        }
        // the road loads: a held group's breakaway less its torque, a moving body's speed
        // along its direction
        for i in 0..n {
            if !wanted(at + i) {
                continue;
            }
            out[at + i] = if self.held[i] {
                let c = self.clusters.of[i];
                self.hold_capacity[c] - self.hold_torque[c].abs()
            } else if self.moving[i] != 0.0 {
                self.moving[i] * w[i]
            } else {
                1.0
            };
        }
    }
}

/// The rigid rows in the modes `modes`: every ideal gear and the locked clutches
/// ([`clutchpack_model::network::Coupling::row`]).
fn rigid_rows(net: &Network, modes: &[Option<ClutchMode>]) -> Vec<Row> {
    net.couplings
        .iter()
        .enumerate()
        .filter_map(|(k, c)| c.row(k, modes[k]))
        .collect()
}

/// The state at `t` as a sample (the couplings' torques computed there).
fn sample(eq: &mut Equations, t: f64, y: &[f64]) -> NetworkSample {
    let n = eq.net.bodies.len();
    eq.torques(t, y);
    eq.rigid_torques();
    NetworkSample {
        t_s: t,
        angle_rad: y[..n].to_vec(),
        speed_rad_s: y[n..2 * n].to_vec(),
        torque_n_m: eq.coupling_torque.clone(),
        mode: eq.modes.clone(),
        reaction_n_m: reactions(eq),
    }
}

/// Each prescribed body's reaction at the state of the last [`Equations::forces`], N m (0 for
/// the other bodies); empty without a prescribed body.
fn reactions(eq: &Equations) -> Vec<f64> {
    if !eq.clusters.any_prescribed() {
        return Vec::new();
    }
    (0..eq.net.bodies.len())
        .map(|i| {
            if eq.net.bodies[i].prescribed().is_some() {
                eq.clusters.reaction_n_m(i, &eq.torque, &eq.alpha)
            } else {
                0.0
            }
        })
        .collect()
}

#[cfg(test)]
mod tests;
