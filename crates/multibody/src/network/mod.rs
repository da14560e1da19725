//! The multibody engine on a driveline network of lumped parts (MODEL.md section 8): every
//! body that turns is a rapier3d-f64 rigid body turning about its axis (`bodies.rs`), the
//! drives (with an engine's firing harmonics in its angle), drag, road loads, slipping
//! clutches', spring-dampers' and gear meshes' torques are applied to it each step (the
//! meshes' contacts in `mesh.rs`), and
//! the ideal gears and locked clutches are velocity-level constraints solved each step
//! (`constraint.rs`). The output types are the model's ([`clutchpack_model::network`]), the
//! reference engine's, so that the two engines' runs compare field by field. A run is a
//! [`NetworkStepper`] (`stepper.rs`), advanced call by call with inputs
//! ([`NetworkInput`]) set in between as the reference engine's is; [`run_network`] is one
//! call to the end.
//!
//! # Method
//! Fixed steps of `step_s` (shortened to land on the signals' breakpoints, the sample times
//! and the events below, and while a gear mesh is in contact). At the start of a step at `t`,
//! with the speeds `w`:
//! 0. **Mesh contacts** (`mesh.rs`): a gear mesh whose engagement depth (its tooth law's, on
//!    the penetration `|x| - b/2`) is above 0 opens a contact event there (the law's memory
//!    taken, its Hertz duration predicted at the closing speed), one whose depth is at or
//!    below 0 closes it (an [`clutchpack_model::ImpactEvent`] to
//!    [`Observer::mesh_impact`]). While in contact the step is at most the predicted
//!    duration over 256 and the local period of the linearised law over 256 (over 64 once
//!    the contact outlasts four predicted durations: a loaded mesh).
//! 1. **Modes** (Modelica's `Clutch`, as the reference engine settles them; MODEL.md section
//!    8): a clutch is free while `fn(t) <= 0`; a free clutch that engages slips if its slip
//!    is not zero and is tried locked otherwise; a slipping clutch whose slip `s w_rel` has
//!    reached zero (within `1e-10 (1 + |w_a| + |w_b|)` rad/s) is tried locked. The speeds of
//!    the new rigid groups are merged, angular momentum kept (`rows::project`, the model's; the
//!    kinetic energy this removes, rounding after a landed step, is the lock's heat).
//! 2. **Torques at `t`**: each body's drive, road load and drag
//!    ([`clutchpack_model::network::Body::external_torque_n_m`]), each slipping clutch's
//!    `tau = sign(w_rel) mu(|w_rel|) cgeo fn` (+tau on `a`, -tau on `b`,
//!    the clutch's law, [`ElementLaw::port_torque_n_m`](clutchpack_model::network::ElementLaw::port_torque_n_m)), each spring-damper's `T = k (theta_a - theta_b -
//!    theta_0) + d (w_a - w_b)` (-T on `a`, +T on `b`), each gear mesh's force per pair `F`,
//!    signed as its `x`, from the model's law at `x` and its rate (MODEL.md section 8:
//!    `-Rb_a F` on `a`, `-Rb_b F` on `b`, internal `+Rb_b F`, times the pairs,
//!    [`GearMesh::torques_n_m`](clutchpack_model::network::GearMesh::torques_n_m)); then the constraint torques `lambda` of the gears
//!    and locked clutches that keep every constraint (the model's `rows::constraint_torques`). A locked clutch
//!    whose `|lambda|` exceeds its static limit `peak mu(0) cgeo fn`
//!    ([`ElementLaw::locked_margin_n_m`](clutchpack_model::network::ElementLaw::locked_margin_n_m)) slips towards it; the one furthest over goes
//!    first and the solve repeats (as the reference's `settle`). These are the samples'
//!    torques.
//! 3. **The step's torques** (the explicit midpoint rule): the same torques at
//!    `t + h / 2` and the speeds predicted there, `w + (h / 2) T(t) / J` (the angles there
//!    on the same path, `theta + (h / 4) (w + w_mid)`), held over the step.
//!    The method is second order (measured: every difference to the reference engine falls
//!    by 4.0 when the step is halved, `tests/network.rs`) and exact where the torques are
//!    constant between events.
//! 4. **Landing**: the torques are held over the step, so each body's speed is affine in the
//!    step's length and the state anywhere in the step is known before it is taken: a
//!    slipping clutch whose slip would change sign shortens the step to land on its zero
//!    (exactly, to rounding); a clutch force `fn` that would cross zero (a sine; a ramp's bend
//!    is a breakpoint already), and a locked clutch's holding torque that would reach its
//!    static limit (a break), and a gear mesh's engagement depth that would cross 0 (its `x`
//!    is quadratic over the step: an onset or a separation), are bisected on that trajectory
//!    to 1e-13 s and landed on. The step's torques are then taken again at the shorter step's
//!    midpoint (a mesh's crossing landed on a hair short of its instant by that change is
//!    reached by the next, tiny step: further landing passes on the new torques changed no
//!    impact of `tests/network.rs` in its 15th digit).
//! 5. **Step**: the torques go to the rapier bodies, and rapier (one solver iteration:
//!    semi-implicit Euler) steps `w += h T / J`; the engine keeps each body's angle
//!    unwrapped as `theta += h (w_k + w_{k+1}) / 2` (the exact turn of the affine speed) and
//!    writes it back to the pose (rapier turns by `2 atan(w h / 2)`, `world.rs`), and projects
//!    the speeds on the constraints against rapier's rounding.
//!
//! # Energy
//! Every torque's work is counted over a step with the step's mean speed `(w_k + w_{k+1}) / 2`
//! (the drives', the road loads', the drag's, each slipping clutch's `tau (w_b - w_a)` and
//! each mesh's `F pairs (x_{k+1} - x_k)`, the work done on the mesh: its impact losses, plus
//! the elastic energy of a contact still closed at the end).
//! Since `J (w_{k+1} - w_k) = h T`, those works sum to the change of kinetic energy exactly
//! (the discrete energy identity of the scheme), the constraint torques doing no work when
//! the constraints hold at both ends of the step: the balance closes to rounding, while the
//! works themselves are second-order accurate in the step.

mod bodies;
mod mesh;
mod packs;
mod stepper;

pub use clutchpack_model::network::NetworkInput;
pub use stepper::{run_network, NetworkStepper};

use bodies::NetworkWorld;
pub(crate) use clutchpack_model::network::rows::{self as constraint, Row};
use clutchpack_model::network::{
    friction, ClutchEvent, ClutchMode, Network, NetworkEnergy, NetworkSample, SlipEnd,
};
use clutchpack_model::Observer;
use mesh::Mesh;
use std::sync::Arc;

/// Settings of a network run on the multibody engine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NetworkStepOptions {
    /// The fixed step, s (> 0; shortened to land on breakpoints, samples and events).
    pub step_s: f64,
    /// Rate of the samples, Hz (0: none but the first and last).
    pub record_rate_hz: f64,
}

impl Default for NetworkStepOptions {
    fn default() -> Self {
        NetworkStepOptions {
            step_s: 1e-4,
            record_rate_hz: 1000.0,
        }
    }
}

/// Torques at one state: each body's but the constraints' (N m), each row's, each
/// coupling's on its body `a`, and each gear mesh's force per pair (N, signed as its `x`).
#[derive(Default)]
struct Torques {
    body: Vec<f64>,
    lambda: Vec<f64>,
    coupling: Vec<f64>,
    mesh_force: Vec<f64>,
    /// Each prescribed body's acceleration, rad/s^2 (empty without one).
    alpha: Vec<f64>,
}

/// Columns of `P` (1/(kg m^2)) by body, with the rows they were computed for.
type Columns = (Vec<Row>, Vec<Option<Arc<[f64]>>>);

/// The state of a run between steps.
#[derive(Clone)]
struct Run {
    /// The network as run (the stepper's own: an input set replaces its signal).
    net: Arc<Network>,
    world: NetworkWorld,
    modes: Vec<Option<ClutchMode>>,
    /// Each body's speed, rad/s (the rapier bodies', 0 for the fixed body).
    w: Vec<f64>,
    /// Each body's inverse inertia, 1/(kg m^2) (0 for the fixed body).
    inv_inertia: Vec<f64>,
    /// The active constraint rows (gears and locked clutches).
    rows: Vec<Row>,
    /// Their elimination with `inv_inertia`, made again only where they change
    /// ([`Run::build_rows`]): every evaluation's constraint torques solved without eliminating
    /// `A` again.
    elimination: constraint::Elimination,
    /// Each body's torque but the constraints', N m.
    torque: Vec<f64>,
    /// Each row's torque, N m.
    lambda: Vec<f64>,
    /// Each prescribed body's acceleration at the held torques' time, rad/s^2 (0 for the
    /// others; empty without a prescribed body).
    alpha: Vec<f64>,
    /// Each coupling's torque on its body `a`, N m.
    coupling_torque: Vec<f64>,
    /// The gear meshes (their `x` and contacts), in the couplings' order.
    meshes: Vec<Mesh>,
    /// Each mesh's force per pair, N, signed as its `x` (with the torques).
    mesh_force: Vec<f64>,
    /// The resolved packs (`packs.rs`), in the couplings' order.
    packs: Vec<packs::NetPack>,
    /// The columns of `P` computed for these rows, by body (`packs.rs`, `Run::column`).
    columns: Columns,
    heat: Vec<f64>,
    energy: NetworkEnergy,
    events: u64,
}

impl Run {
    /// The rows of the gears and the locked clutches ([`clutchpack_model::network::Coupling::row`]).
    fn build_rows(&mut self) {
        self.rows.clear();
        for (k, c) in self.net.couplings.iter().enumerate() {
            self.rows.extend(c.row(k, self.modes[k]));
        }
        if self.elimination.rows() != self.rows.as_slice() {
            self.elimination = constraint::Elimination::new(&self.rows, &self.inv_inertia);
        }
    }

    /// The torques at `(t, w)`: the bodies' own and the slipping clutches' into `torque`, the
    /// rows' into `lambda` (MODEL.md section 8), every coupling's into `coupling_torque`.
    fn torques(&mut self, t: f64) {
        let mut out = Torques::default();
        let x: Vec<f64> = self.meshes.iter().map(|m| m.x).collect();
        self.evaluate(t, self.world.angles(), &self.w, &x, &mut out);
        self.keep(out);
    }

    /// Keeps `out` as the torques held.
    fn keep(&mut self, out: Torques) {
        self.torque = out.body;
        self.lambda = out.lambda;
        self.coupling_torque = out.coupling;
        self.mesh_force = out.mesh_force;
        self.alpha = out.alpha;
    }

    /// Sets the prescribed bodies' speeds (rad/s) and angles (rad) in `w` and `theta` to
    /// their profiles' at `t` (s).
    fn prescribe(&self, t: f64, w: &mut [f64], theta: &mut [f64]) {
        for (i, b) in self.net.bodies.iter().enumerate() {
            if let Some(p) = b.prescribed() {
                (w[i], theta[i]) = p.speed_and_angle(t);
            }
        }
    }

    /// Each body's acceleration under the torques `total` (N m), rad/s^2.
    fn accelerations(&self, total: &[f64]) -> Vec<f64> {
        let mut acc: Vec<f64> = total
            .iter()
            .zip(&self.inv_inertia)
            .map(|(t, j)| j * t)
            .collect();
        // a prescribed body's is its profile's (its inverse inertia is 0)
        for (i, a) in self.alpha.iter().enumerate() {
            if self.net.bodies[i].prescribed().is_some() {
                acc[i] = *a;
            }
        }
        acc
    }

    /// Column `i` of the inverse inertia projected on the rows, `P = M^-1 - M^-1 C^T
    /// (C M^-1 C^T)^-1 C M^-1` (1/(kg m^2)): every body's acceleration under a unit torque
    /// on body `i` (`packs.rs`).
    fn response(&self, i: usize) -> Vec<f64> {
        let mut unit = vec![0.0; self.w.len()];
        unit[i] = 1.0;
        let mut lambda = Vec::new();
        constraint::constraint_torques(&self.rows, &self.inv_inertia, &unit, &mut lambda);
        constraint::add_torques(&self.rows, &lambda, &mut unit);
        self.accelerations(&unit)
    }

    /// Each body's total torque (N m): its own, the slipping clutches' and the rows'.
    fn total(&self) -> Vec<f64> {
        let mut total = self.torque.clone();
        constraint::add_torques(&self.rows, &self.lambda, &mut total);
        total
    }

    /// The torques held over the step `[t, t + h]`: those at its midpoint, the speeds there
    /// predicted from the torques `start` at its start (the explicit midpoint rule, second
    /// order: `w_mid = w + (h / 2) T_start / J`; a row's bodies stay consistent since the
    /// start's torques keep the rows). Returns the speeds (rad/s) and angles (rad) they were
    /// evaluated at.
    fn step_torques(&mut self, t: f64, h: f64, start: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let w_mid: Vec<f64> = (0..self.w.len())
            .map(|i| self.w[i] + 0.5 * h * self.inv_inertia[i] * start[i])
            .collect();
        // the angles there on the same path (the speed affine from w to w_mid: an engine's
        // firing torque is a function of its angle)
        let mut theta_mid: Vec<f64> = (0..self.w.len())
            .map(|i| self.world.angles()[i] + 0.25 * h * (self.w[i] + w_mid[i]))
            .collect();
        let mut w_mid = w_mid;
        self.prescribe(t + 0.5 * h, &mut w_mid, &mut theta_mid);
        // each mesh's x there on the same path
        let x_mid = mesh::positions(&self.meshes, 0.5 * h, &self.w, &self.accelerations(start));
        let mut out = Torques::default();
        self.evaluate(t + 0.5 * h, &theta_mid, &w_mid, &x_mid, &mut out);
        self.keep(out);
        (w_mid, theta_mid)
    }

    /// The torques at `(t, theta, w)`, the meshes at `x` (m, one per mesh), in the present
    /// modes and contacts into `out` (MODEL.md section 8).
    fn evaluate(&self, t: f64, theta: &[f64], w: &[f64], x: &[f64], out: &mut Torques) {
        let net = &*self.net;
        out.body.clear();
        out.body.extend(net.bodies.iter().enumerate().map(|(i, b)| {
            if !b.is_free() {
                0.0
            } else {
                b.external_torque_n_m(t, theta[i], w[i])
            }
        }));
        out.coupling.clear();
        out.coupling.resize(net.couplings.len(), 0.0);
        for (k, c) in net.couplings.iter().enumerate() {
            // MODEL.md section 8: a force element's torque on a, the opposite on b (a
            // slipping clutch's; a spring-damper's at the twist theta_a - theta_b, both bodies
            // starting at angle 0 as the reference engine's twist state does)
            let twist = theta[c.a] - theta[c.b];
            if let Some(ta) = c
                .law()
                .port_torque_n_m(t, twist, w[c.a], w[c.b], self.modes[k])
            {
                out.coupling[k] = ta;
                out.body[c.a] += ta;
                out.body[c.b] -= ta;
            }
        }
        // the packs' reactions of the last step: the estimate of this one's (`packs.rs`)
        for p in &self.packs {
            out.body[p.a] += p.reaction[0];
            out.body[p.b] += p.reaction[1];
            out.coupling[p.k] = p.reaction[0];
        }
        let (body, coupling) = (&mut out.body, &mut out.coupling);
        mesh::add_torques(&self.meshes, x, w, body, coupling, &mut out.mesh_force);
        // A lambda = -C M^-1 T: the rows' rates vanish, so rows that hold at the step's
        // start hold at its end (the speeds are projected after each step against rounding)
        // (with the rows' elimination kept: the same operations, the same torques to the bit)
        debug_assert_eq!(self.elimination.rows(), self.rows.as_slice());
        self.elimination
            .constraint_torques(&self.inv_inertia, &out.body, &mut out.lambda);
        // the prescribed bodies' accelerations, and the rows' torques that make the bodies
        // tied to them follow (`rows::prescribed_response`: linear in each acceleration)
        out.alpha.clear();
        if net.bodies.iter().any(|b| b.prescribed().is_some()) {
            out.alpha.resize(net.bodies.len(), 0.0);
            for (i, b) in net.bodies.iter().enumerate() {
                let Some(p) = b.prescribed() else { continue };
                out.alpha[i] = p.acceleration(t);
                let (_, lambda) = constraint::prescribed_response(&self.rows, &self.inv_inertia, i);
                for (l, li) in out.lambda.iter_mut().zip(&lambda) {
                    *l += li * out.alpha[i];
                }
            }
        }
        for (r, l) in self.rows.iter().zip(&out.lambda) {
            out.coupling[r.coupling] = r.first_torque_n_m(*l);
        }
    }

    /// Each locked clutch's margin at `(t, w)`, N m: its static limit less the torque that
    /// holds it (`peak mu(0) cgeo fn - |lambda|`; it breaks where this reaches 0); `+inf`
    /// for the other couplings.
    fn margins(
        &self,
        t: f64,
        theta: &[f64],
        w: &[f64],
        x: &[f64],
        scratch: &mut Torques,
    ) -> Vec<f64> {
        self.evaluate(t, theta, w, x, scratch);
        (0..self.net.couplings.len())
            .map(|k| match self.modes[k] {
                Some(ClutchMode::Locked) => self.net.couplings[k]
                    .law()
                    .locked_margin_n_m(t, scratch.coupling[k])
                    .unwrap_or(f64::INFINITY),
                _ => f64::INFINITY,
            })
            .collect()
    }

    fn kinetic(&self) -> f64 {
        self.net
            .bodies
            .iter()
            .zip(&self.w)
            .filter(|(b, _)| b.is_free())
            .map(|(b, w)| 0.5 * b.inertia_kg_m2 * w * w)
            .sum()
    }

    /// Settles the clutches' modes at the start of a step at `t` (MODEL.md section 8; the
    /// rules of the reference engine's `settle`), merges the new rigid groups' speeds and
    /// leaves the step's torques computed.
    fn settle(&mut self, t: f64, obs: &mut dyn Observer) {
        let net = Arc::clone(&self.net);
        let before = self.modes.clone();
        let w_before = self.w.clone();
        for (k, c) in net.couplings.iter().enumerate() {
            // the step landed on the slip's zero: within the scale of it (the stick/slip
            // rule's `SlipEnd::Landed`)
            let (wa, wb) = (self.w[c.a], self.w[c.b]);
            self.modes[k] = c.law().settle(t, before[k], wa, wb, SlipEnd::Landed);
        }
        let newly_locked = (0..net.couplings.len()).find(|&k| {
            self.modes[k] == Some(ClutchMode::Locked) && before[k] != Some(ClutchMode::Locked)
        });
        // lock what locks; release the locked clutch furthest over its limit, and again
        for round in 0..=net.couplings.len() {
            self.build_rows();
            if round == 0 {
                if let Some(k) = newly_locked {
                    let k0 = self.kinetic();
                    self.elimination.project(&self.inv_inertia, &mut self.w);
                    self.world.set_speeds(&self.w);
                    // the merge's loss (rounding after a landed step) is the lock's heat
                    self.heat[k] += k0 - self.kinetic();
                }
            }
            self.torques(t);
            match friction::furthest_over(&net, &self.modes, &self.coupling_torque, t) {
                Some((k, to)) => self.modes[k] = Some(to),
                None => break,
            }
        }
        if before != self.modes {
            self.events += 1;
            // the state just before (the old modes at t) and after: the torques' steps
            let (modes, w) = (self.modes.clone(), self.w.clone());
            (self.modes, self.w) = (before.clone(), w_before);
            self.build_rows();
            self.torques(t);
            let state_before = self.sample(t);
            (self.modes, self.w) = (modes, w);
            self.build_rows();
            self.torques(t);
            obs.switched(&state_before, &self.sample(t));
        }
        for (k, (b, a)) in before.iter().zip(&self.modes).enumerate() {
            if let (Some(from), Some(to)) = (b, a) {
                if from != to {
                    obs.clutch_event(&ClutchEvent {
                        t_s: t,
                        coupling: k,
                        from: *from,
                        to: *to,
                    });
                }
            }
        }
    }

    /// The length of the step from `t`, at most `h`, that lands on the first slip reaching
    /// zero, the first clutch force crossing zero and the first mesh contact's onset or
    /// separation within it.
    fn landing(&self, t: f64, h: f64) -> f64 {
        let net = &*self.net;
        let mut best = h;
        let mut any_locked = false;
        let total = self.total();
        let acc = self.accelerations(&total);
        if !self.meshes.is_empty() {
            best = mesh::landing(&self.meshes, t, best, &self.w, &acc);
        }
        for (k, c) in net.couplings.iter().enumerate() {
            let law = c.law();
            // a slip reaching zero; a free one-way clutch's too (its freewheel locks there)
            if let Some(s) = law.slip_sense(self.modes[k]) {
                let (wa, wb) = (self.w[c.a], self.w[c.b]);
                let s = f64::from(s);
                let s0 = s * (wb - wa);
                let scale = 1e-10 * (1.0 + wa.abs() + wb.abs());
                // the slip's rate, constant over the step (the torques are held)
                let rate = s * (acc[c.b] - acc[c.a]);
                let s1 = s0 + h * rate;
                if s0 > scale && s1 <= 0.0 {
                    best = best.min(h * s0 / (s0 - s1));
                }
            }
            if self.modes[k] == Some(ClutchMode::Locked) {
                any_locked = true;
            }
            // its actuation switching on or off (a clutch's normal force crossing zero)
            let Some(on0) = law.engaged(t) else {
                continue;
            };
            let on = |tt: f64| law.engaged(tt) == Some(true);
            if on(t + h) != on0 {
                let (mut a, mut b) = (t, t + h);
                while b - a > 1e-13 * (1.0 + b) {
                    let mid = 0.5 * (a + b);
                    if on(mid) == on0 {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                best = best.min(b - t);
            }
        }
        if any_locked {
            // a break: the holding torque reaching the static limit on the step's own
            // trajectory (the speeds affine in the step's length), bisected to 1e-13 s
            let at = |hh: f64, scratch: &mut Torques| {
                let mut w: Vec<f64> = (0..self.w.len())
                    .map(|i| self.w[i] + hh * self.inv_inertia[i] * total[i])
                    .collect();
                let mut theta: Vec<f64> = (0..self.w.len())
                    .map(|i| self.world.angles()[i] + 0.5 * hh * (self.w[i] + w[i]))
                    .collect();
                self.prescribe(t + hh, &mut w, &mut theta);
                let x = mesh::positions(&self.meshes, hh, &self.w, &acc);
                self.margins(t + hh, &theta, &w, &x, scratch)
            };
            let mut scratch = Torques::default();
            let g0 = at(0.0, &mut scratch);
            let g1 = at(best, &mut scratch);
            for k in 0..g0.len() {
                if !(g0[k] > 0.0 && g1[k] <= 0.0) {
                    continue;
                }
                let (mut a, mut b) = (0.0, best);
                while b - a > 1e-13 * (1.0 + t) {
                    let mid = 0.5 * (a + b);
                    if at(mid, &mut scratch)[k] <= 0.0 {
                        b = mid;
                    } else {
                        a = mid;
                    }
                }
                best = best.min(b);
            }
        }
        best
    }

    fn sample(&self, t: f64) -> NetworkSample {
        NetworkSample {
            t_s: t,
            angle_rad: self.world.angles().to_vec(),
            speed_rad_s: self.w.clone(),
            torque_n_m: self.coupling_torque.clone(),
            mode: self.modes.clone(),
            reaction_n_m: self.reactions(),
        }
    }

    /// Each prescribed body's reaction under the torques held (N m, 0 for the other bodies;
    /// empty without a prescribed body): `-(T_p + (C^T lambda)_p)`, its inertia infinite.
    fn reactions(&self) -> Vec<f64> {
        if self.alpha.is_empty() {
            return Vec::new();
        }
        let total = self.total();
        (0..total.len())
            .map(|i| {
                if self.net.bodies[i].prescribed().is_some() {
                    -total[i]
                } else {
                    0.0
                }
            })
            .collect()
    }
}
