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
//!   contact's onset, where the law's per-event memory is taken, and its separation).
//!
//! A crossing is bisected on the dense output to 1e-13 s relative; the run restarts there
//! with the modes settled as Modelica's `Clutch` settles them (Otter, Elmqvist and Mattsson
//! 1999): a clutch whose slip reached zero, or that engages at zero slip, is locked if the
//! torque that holds the new rigid group stays within its static limit, and slips towards the
//! torque otherwise (startForward / startBackward); the check repeats until every locked clutch
//! holds. Locking sets the group's speeds to its common speed (momentum kept; the slip there is
//! below 1e-12 rad/s).

pub(crate) mod cluster;
mod mesh;
mod modes;

use modes::settle;

use crate::dopri::{next_step, Dense, Dopri5};
use cluster::Clusters;
use clutchpack_model::network::{ClutchMode, CouplingKind, GearMesh, Network};
// the output types are the model's, shared with the multibody engine
pub use clutchpack_model::network::{
    ClutchEvent, NetworkEnergy, NetworkObserver, NetworkRun, NetworkSample,
};
use clutchpack_model::{Engagement, EngineError};

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
struct Equations<'n> {
    net: &'n Network,
    modes: Vec<Option<ClutchMode>>,
    /// Each gear mesh's contact event (its law's memory), `None` in free flight.
    contacts: Vec<Option<Engagement>>,
    clusters: Clusters,
    // scratch
    torque: Vec<f64>,
    acc: Vec<f64>,
    group: Vec<f64>,
    residual: Vec<f64>,
    coupling_torque: Vec<f64>,
    mesh_force: Vec<f64>,
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

impl<'n> Equations<'n> {
    fn new(net: &'n Network, modes: Vec<Option<ClutchMode>>) -> Self {
        let n = net.bodies.len();
        let clusters = Clusters::build(net, &rigid(net, &modes));
        Equations {
            net,
            modes,
            contacts: vec![None; net.couplings.len()],
            clusters,
            torque: vec![0.0; n],
            acc: vec![0.0; n],
            group: Vec::new(),
            residual: Vec::new(),
            coupling_torque: vec![0.0; net.couplings.len()],
            mesh_force: vec![0.0; net.couplings.len()],
        }
    }

    fn set_modes(&mut self, modes: &[Option<ClutchMode>]) {
        self.modes.copy_from_slice(modes);
        self.clusters = Clusters::build(self.net, &rigid(self.net, &self.modes));
    }

    /// Bodies' torques (all but the rigid couplings') and accelerations at `(t, y)`; the
    /// slipping clutches' and the meshes' torques into `coupling_torque` (and each mesh's
    /// force per pair, N, into `mesh_force`).
    fn forces(&mut self, t: f64, y: &[f64]) {
        let n = self.net.bodies.len();
        let w = &y[n..2 * n];
        for (i, b) in self.net.bodies.iter().enumerate() {
            self.torque[i] = if b.fixed {
                0.0
            } else {
                b.external_torque_n_m(t, y[i], w[i])
            };
        }
        for (k, c) in self.net.couplings.iter().enumerate() {
            self.coupling_torque[k] = 0.0;
            if let (Some(cl), Some(ClutchMode::Slipping(s))) =
                (self.net.couplings[k].clutch(), self.modes[k])
            {
                // MODEL.md section 8: tau = sign(w_rel) mu(|w_rel|) cgeo fn, +tau on a, -tau on b
                let tau = cl.slip_torque_n_m(s, w[c.b] - w[c.a], cl.normal_force_n(t));
                self.coupling_torque[k] = tau;
                self.torque[c.a] += tau;
                self.torque[c.b] -= tau;
            }
            if let Some(sd) = self.net.couplings[k].spring() {
                // MODEL.md section 8: T on b, -T on a; the twist is its own state
                let t = sd.torque_n_m(y[2 * n + k], w[c.a] - w[c.b]);
                self.coupling_torque[k] = -t;
                self.torque[c.a] -= t;
                self.torque[c.b] += t;
            }
            if let (Some(g), Some(e)) = (self.net.couplings[k].mesh(), self.contacts[k]) {
                // MODEL.md section 8: F signed as x; -Rb_a F on a, -+Rb_b F on b
                let f = g.force_n(&mesh_kinematics(self.net, k, g, y), &e);
                let (ta, tb) = g.torques_n_m(f);
                self.mesh_force[k] = f;
                self.coupling_torque[k] = ta;
                self.torque[c.a] += ta;
                self.torque[c.b] += tb;
            }
        }
        self.clusters
            .accelerations(&self.torque, &mut self.acc, &mut self.group);
    }

    /// The rigid couplings' torques at the state of the last [`Self::forces`].
    fn rigid_torques(&mut self) {
        self.clusters.rigid_torques(
            self.net,
            &self.torque,
            &self.acc,
            &mut self.coupling_torque,
            &mut self.residual,
        );
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
            x_dot[k] = match (self.net.couplings[k].mesh(), self.net.couplings[k].spring()) {
                (Some(g), _) => g.displacement((0.0, 0.0), (w[c.a], w[c.b])).1,
                (_, Some(_)) => w[c.a] - w[c.b],
                _ => 0.0,
            };
        }
        // counters: [heat per coupling, drive work, load work, drag loss]
        for k in 0..m {
            let c = &self.net.couplings[k];
            counters[k] = if matches!(self.modes[k], Some(ClutchMode::Slipping(_))) {
                self.coupling_torque[k] * (w[c.b] - w[c.a])
            } else if let Some(sd) = self.net.couplings[k].spring() {
                sd.loss_rate_w(w[c.a] - w[c.b])
            } else if let (Some(g), Some(_)) = (self.net.couplings[k].mesh(), self.contacts[k]) {
                // power into the mesh: F v pairs (the torques' work on the bodies, negated)
                let (_, v) = g.displacement((0.0, 0.0), (w[c.a], w[c.b]));
                self.mesh_force[k] * v * g.pairs
            } else {
                0.0
            };
        }
        let (mut drive, mut load, mut drag) = (0.0, 0.0, 0.0);
        for (i, b) in self.net.bodies.iter().enumerate() {
            if b.fixed {
                continue;
            }
            drive += b.drive_torque_n_m(t, y[i]) * w[i];
            load += b.road_load.map_or(0.0, |l| l.torque_n_m(w[i])) * w[i];
            drag += b.drag_n_m_s_rad * w[i] * w[i];
        }
        counters[m] = drive;
        counters[m + 1] = load;
        counters[m + 2] = drag;
    }

    /// The event functions at `(t, y)`, one per clutch (> 0 while its mode holds; 0 for other
    /// couplings): slipping `min(s w_rel, fn)`, locked `min(limit - |tau|, fn)`, free `-fn`
    /// (its crossing engages).
    fn guards(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        let n = self.net.bodies.len();
        let w = &y[n..2 * n];
        let any_locked = self.modes.contains(&Some(ClutchMode::Locked));
        if any_locked {
            self.forces(t, y);
            self.rigid_torques();
        }
        for (k, c) in self.net.couplings.iter().enumerate() {
            if let Some(g) = self.net.couplings[k].mesh() {
                let depth = g
                    .law
                    .engagement_depth_m(&mesh_kinematics(self.net, k, g, y));
                out[k] = if self.contacts[k].is_some() {
                    depth
                } else {
                    -depth
                };
                continue;
            }
            let Some(cl) = self.net.couplings[k].clutch() else {
                out[k] = 1.0;
                continue;
            };
            let f = cl.normal_force_n(t);
            out[k] = match self.modes[k] {
                Some(ClutchMode::Free) => {
                    if f > 0.0 {
                        -f
                    } else {
                        1.0 + f.abs()
                    }
                }
                Some(ClutchMode::Slipping(s)) => (f64::from(s) * (w[c.b] - w[c.a])).min(f),
                Some(ClutchMode::Locked) => {
                    (cl.max_static_torque_n_m(f) - self.coupling_torque[k].abs()).min(f)
                }
                None => 1.0,
            };
        }
    }
}

fn rigid(net: &Network, modes: &[Option<ClutchMode>]) -> Vec<bool> {
    net.couplings
        .iter()
        .enumerate()
        .map(|(k, c)| match c.kind {
            CouplingKind::IdealGear { .. } => true,
            CouplingKind::Clutch(_) => modes[k] == Some(ClutchMode::Locked),
            CouplingKind::GearMesh(_) | CouplingKind::SpringDamper(_) => false,
        })
        .collect()
}

/// Runs `net` for `duration_s` seconds; samples and clutch events go to `obs` as they happen.
/// A network with problems ([`Network::problems`]) is refused.
pub fn run_network(
    net: &Network,
    duration_s: f64,
    options: &NetworkOptions,
    obs: &mut dyn NetworkObserver,
) -> Result<NetworkRun, EngineError> {
    net.check_run(duration_s)?;
    let n = net.bodies.len();
    let m = net.couplings.len();
    let dim = 2 * n + 2 * m + 3;
    let tol = options.tolerance;
    let mut atol = vec![tol; dim];
    // the meshes' x on their backlash's scale; other slots and the counters out of the norm
    for k in 0..m {
        atol[2 * n + k] = match (net.couplings[k].mesh(), net.couplings[k].spring()) {
            (Some(g), _) => tol * g.backlash_m,
            (_, Some(_)) => tol,
            _ => f64::INFINITY,
        };
    }
    atol[2 * n + m..]
        .iter_mut()
        .for_each(|a| *a = f64::INFINITY);
    let mut y = vec![0.0; dim];
    for (i, b) in net.bodies.iter().enumerate() {
        y[n + i] = b.initial_speed_rad_s;
    }
    for k in 0..m {
        if let Some(g) = net.couplings[k].mesh() {
            y[2 * n + k] = g.initial_offset_m;
        }
    }
    let initial_modes: Vec<Option<ClutchMode>> = (0..m)
        .map(|k| net.couplings[k].clutch().map(|_| ClutchMode::Free))
        .collect();
    let mut eq = Equations::new(net, initial_modes);
    let kinetic = |y: &[f64]| -> f64 {
        net.bodies
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.fixed)
            .map(|(i, b)| 0.5 * b.inertia_kg_m2 * y[n + i] * y[n + i])
            .sum()
    };
    let kinetic0 = kinetic(&y);
    let mut events = 0u64;
    settle(&mut eq, 0.0, &mut y, &[], obs, &mut events);
    let mut meshes = mesh::Meshes::new(m, dim);
    meshes.switch(&mut eq, 0.0, &y, None, obs);
    let breakpoints = net.breakpoints(duration_s);
    let mut next_bp = 0;
    let mut stepper = Dopri5::new(dim);
    let mut dense = Dense::default();
    let mut dy = vec![0.0; dim];
    let mut ybuf = vec![0.0; dim];
    let (mut g0, mut g1) = (vec![0.0; m], vec![0.0; m]);
    eq.rhs(0.0, &y, &mut dy);
    stepper.set_start_derivative(&dy);
    let period = if options.record_rate_hz > 0.0 {
        1.0 / options.record_rate_hz
    } else {
        f64::INFINITY
    };
    let mut next_sample = 0u64;
    let mut t = 0.0;
    obs.sample(&sample(&mut eq, 0.0, &y));
    next_sample += 1;
    let mut h = options.max_step_s.min(1e-4).min(duration_s.max(1e-12));
    let mut steps = 0u64;
    while t < duration_s {
        let stop = breakpoints.get(next_bp).copied().unwrap_or(duration_s);
        if stop - t <= 1e-13 * (1.0 + t) && next_bp < breakpoints.len() {
            // an event left the run at a breakpoint: the signals jump here
            t = stop;
            next_bp += 1;
            g1.iter_mut().for_each(|g| *g = 1.0);
            settle(&mut eq, t, &mut y, &g1, obs, &mut events);
            eq.rhs(t, &y, &mut dy);
            stepper.set_start_derivative(&dy);
            continue;
        }
        let land = t + h >= stop * (1.0 - 1e-15);
        let h_try = if land { stop - t } else { h };
        let err = {
            let eqr = &mut eq;
            let mut f = |tt: f64, yy: &[f64], d: &mut [f64]| eqr.rhs(tt, yy, d);
            stepper.try_step(&mut f, t, &y, h_try, &atol, tol)
        };
        if !err.is_finite() || h_try < 1e-15 * (1.0 + t) {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!("the step collapsed to {h_try:e} s (error norm {err})"),
            });
        }
        if err > 1.0 {
            h = next_step(h_try, err).max(h_try * 0.1);
            continue;
        }
        stepper.dense_into(t, &y, h_try, &mut dense);
        // events: the first quarter point where a guard turns <= 0
        eq.guards(t, &y, &mut g0);
        let mut event: Option<(f64, f64)> = None; // (ta, tb) bracketing the first crossing
        let mut ta = t;
        for q in 1..=4 {
            let tq = t + h_try * f64::from(q) / 4.0;
            let tq = if q == 4 { t + h_try } else { tq };
            dense.eval(tq, &mut ybuf);
            eq.guards(tq, &ybuf, &mut g1);
            if g0.iter().zip(&g1).any(|(a, b)| *a > 0.0 && *b <= 0.0) {
                event = Some((ta, tq));
                break;
            }
            ta = tq;
        }
        let (t_new, at_event) = match event {
            Some((mut a, mut b)) => {
                // bisect the earliest crossing: the guards that were > 0 at t
                let armed: Vec<bool> = g0.iter().map(|g| *g > 0.0).collect();
                while b - a > 1e-13 * (1.0 + b) {
                    let mid = 0.5 * (a + b);
                    dense.eval(mid, &mut ybuf);
                    eq.guards(mid, &ybuf, &mut g1);
                    if g1.iter().zip(&armed).any(|(g, on)| *on && *g <= 0.0) {
                        b = mid;
                    } else {
                        a = mid;
                    }
                }
                // the guards that crossed, at the instant the run restarts from
                dense.eval(b, &mut ybuf);
                eq.guards(b, &ybuf, &mut g1);
                for (g, on) in g1.iter_mut().zip(&armed) {
                    if !on {
                        *g = 1.0;
                    }
                }
                (b, true)
            }
            None => {
                g1.iter_mut().for_each(|g| *g = 1.0);
                (t + h_try, land)
            }
        };
        meshes.observe(&mut eq, &dense, t, t_new);
        // samples up to t_new from the dense output
        while (next_sample as f64) * period <= t_new && (next_sample as f64) * period < duration_s {
            let ts = next_sample as f64 * period;
            dense.eval(ts, &mut ybuf);
            obs.sample(&sample(&mut eq, ts, &ybuf));
            next_sample += 1;
        }
        if t_new < t + h_try {
            dense.eval(t_new, &mut ybuf);
            y.copy_from_slice(&ybuf);
        } else {
            y.copy_from_slice(&stepper.y_new);
        }
        t = if land && event.is_none() { stop } else { t_new };
        steps += 1;
        if land && event.is_none() && next_bp < breakpoints.len() {
            next_bp += 1;
        }
        if at_event {
            meshes.switch(&mut eq, t, &y, Some(&g1), obs);
            settle(&mut eq, t, &mut y, &g1, obs, &mut events);
            eq.rhs(t, &y, &mut dy);
            stepper.set_start_derivative(&dy);
        } else {
            stepper.accept();
            h = next_step(h_try, err);
        }
        h = h.min(options.max_step_s);
        if !obs.progress(t) {
            break;
        }
    }
    meshes.finish(&mut eq, t, obs);
    let last = sample(&mut eq, t, &y);
    obs.sample(&last);
    let c0 = 2 * n + m; // the counters
    let mut heat = y[c0..c0 + m].to_vec();
    let (mut mesh_work, mut damper_loss, mut spring_change) = (0.0, 0.0, 0.0);
    for (k, h) in heat.iter_mut().enumerate() {
        if net.couplings[k].mesh().is_some() {
            mesh_work += *h;
        } else if let Some(sd) = net.couplings[k].spring() {
            damper_loss += *h;
            spring_change += sd.potential_j(y[2 * n + k]) - sd.potential_j(0.0);
        } else if net.couplings[k].clutch().is_none() {
            *h = 0.0;
        }
    }
    let energy = NetworkEnergy {
        drive_work_j: y[c0 + m],
        load_work_j: y[c0 + m + 1],
        drag_loss_j: y[c0 + m + 2],
        clutch_heat_j: heat.iter().sum::<f64>() - mesh_work - damper_loss,
        mesh_work_j: mesh_work,
        damper_loss_j: damper_loss,
        spring_energy_change_j: spring_change,
        kinetic_change_j: kinetic(&y) - kinetic0,
    };
    Ok(NetworkRun {
        last,
        heat_j: heat,
        energy,
        steps,
        events,
    })
}

/// The state at `t` as a sample (the couplings' torques computed there).
fn sample(eq: &mut Equations, t: f64, y: &[f64]) -> NetworkSample {
    let n = eq.net.bodies.len();
    eq.forces(t, y);
    eq.rigid_torques();
    NetworkSample {
        t_s: t,
        angle_rad: y[..n].to_vec(),
        speed_rad_s: y[n..2 * n].to_vec(),
        torque_n_m: eq.coupling_torque.clone(),
        mode: eq.modes.clone(),
    }
}
