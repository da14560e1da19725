//! The multirate scheme on an inertial carrier (crate docs, "Multirate on an inertial
//! shaft"): an inertial shaft (eq 4) with its friction discs, or the output drum with its
//! separator plates. Each world step the carrier and the bodies that may touch it are
//! integrated together with classical Runge-Kutta sub-steps, the other bodies fly free against
//! the carrier's motion (`multirate.rs`'s per-coupling integration).

use super::landing::SubSteps;
use super::state::Run;
use super::substep::{
    checked_sub_step, cut, graded_step, Carried, GapDrag, Node, Path, Rk4, ShaftAt, WorldStep,
    KINK_FLOOR_DIVISOR,
};
use crate::stepping::coupling_step;
use clutchpack_model::EngineError;
use rapier3d_f64::prelude::Vector;

/// An inertial carrier's sub-steps are at most the world step over this (dimensionless): the
/// carrier's own motion under its drive or load is integrated by the classical method, whose
/// error per step in the angle grows as the fifth power of the step (see
/// [`Run::integrate_carrier`]).
const SHAFT_SUB_STEPS: f64 = 4.0;

/// An inertial carrier's own dynamics over a sub-step: `J w' = T_ext(t) - C w - sum T_k`.
#[derive(Debug, Clone, Copy)]
struct CarrierDynamics {
    /// `1 / J`, 1/(kg m^2).
    inv_j: f64,
    /// Damping `C`, N m s/rad.
    damping: f64,
    /// The external torque (the shaft's drive, the drum's load) at the sub-step's start,
    /// middle and end, N m.
    torque: [f64; 3],
}

/// An inertial carrier's cluster at a sub-step's start ([`Run::carrier_step`]).
#[derive(Debug, Clone, Copy)]
struct Cluster<'a> {
    /// The couplings integrated with the carrier, their bodies' inverse inertias,
    /// 1/(kg m^2), and the open gaps' drag on each.
    members: &'a [usize],
    inv_j: &'a [f64],
    gaps: &'a [GapDrag],
    /// The start, s, and the carrier's speed there, rad/s.
    t: f64,
    w0: f64,
    /// Each coupling's relative angle, rad, and speed, rad/s, there.
    phi: &'a [f64],
    dphi: &'a [f64],
}

/// The buffers of [`Run::carrier_step`], reused along a world step's sub-steps (allocating
/// them per step was a tenth of an inertial-shaft pack's instructions, callgrind): the step of
/// the cluster's bodies and the carrier after them, with their powers (for `n` couplings:
/// each body's speed squared and the carrier's, the gaps' drag's on each body, the external
/// torque's), and their speeds at its start; and the couplings' states of accepted steps,
/// handed back for the next steps' results (allocating a step's two vectors was 3 % of a
/// one-disc inertial pack's instructions, in `malloc` and `free`, callgrind).
struct CarrierBuffers {
    rk: Rk4<Vec<f64>, Vec<f64>>,
    u0: Vec<f64>,
    spare: Vec<Vec<f64>>,
}

impl CarrierBuffers {
    /// The buffers for a carrier with `n` couplings.
    fn new(n: usize) -> CarrierBuffers {
        CarrierBuffers {
            rk: Rk4::new(n + 1, 2 * n + 2),
            u0: vec![0.0; n + 1],
            spare: Vec::new(),
        }
    }

    /// An empty vector for a step's result (a spare one if any).
    fn vector(&mut self) -> Vec<f64> {
        let mut v = self.spare.pop().unwrap_or_default();
        v.clear();
        v
    }
}

/// One classical Runge-Kutta step of an inertial carrier and the couplings that go with it
/// ([`Run::integrate_carrier`]).
#[derive(Debug, Clone)]
struct CarrierStep {
    /// The carrier's turn over the step, rad, and its speed at the end, rad/s.
    turn: f64,
    speed: f64,
    /// Each coupling's relative angle and speed at the end.
    phi: Vec<f64>,
    dphi: Vec<f64>,
    /// Work of the external torque on the carrier (the shaft's drive, the drum's load), J.
    external_j: f64,
    /// Work of the carrier's damping and the bodies' drag, J (<= 0).
    drag_j: f64,
    /// Work of the open gaps' drag on the bodies, J.
    gap_j: f64,
}

impl Run {
    /// Inertial carrier `c`'s dynamics over a sub-step of length `h` from `t`: its inertia and
    /// damping ([`CarrierRun::inertia`](super::carriers::CarrierRun::inertia)) and its
    /// external torque (the shaft's drive, eq 4, at the step's start, middle and end; the
    /// drum's load, held over a world step; [`Run::external_at`]).
    fn carrier_dynamics(&self, c: usize, t: f64, h: f64) -> CarrierDynamics {
        let (inv_j, damping) = self.carriers[c].inertia();
        let torque = [t, t + 0.5 * h, t + h].map(|ts| self.external_at(c, ts));
        CarrierDynamics {
            inv_j,
            damping,
            torque,
        }
    }

    /// The inverse of a rapier body's inertia about the axis, 1/(kg m^2).
    pub(super) fn inv_inertia_z(&self, h: rapier3d_f64::prelude::RigidBodyHandle) -> f64 {
        self.world.physics.bodies[h]
            .mass_properties()
            .local_mprops
            .inv_principal_inertia
            .z
    }

    /// One classical Runge-Kutta step ([`Rk4::rk4`]) of length `h` of an inertial carrier
    /// (dynamics `dy`) and the couplings of its cluster `cl` from their states at `cl.t`,
    /// integrated as one system: the carrier
    /// `J w' = T_ext(t) - C w - sum T_k` (the shaft: Hu et al. eq 4; the drum: its load and
    /// drag), each body `J w_d' = T_k - C2 w_d + g_k(w_d)` (eq 5 and the gaps' drag), `T_k`
    /// the teeth's torque on body `k` at `phi_k = theta_c - theta_d`. As in
    /// [`Relative::step`](super::substep::Relative::step) the bodies' own motions are
    /// integrated, not the relative ones. The teeth's torques cancel in the total angular
    /// momentum at every stage, so the step conserves it exactly (a linear invariant) but for
    /// the external torque, the damping and the gaps.
    fn carrier_step(
        &self,
        cl: &Cluster,
        dy: &CarrierDynamics,
        h: f64,
        b: &mut CarrierBuffers,
    ) -> CarrierStep {
        let Cluster {
            members: cluster,
            inv_j,
            gaps,
            w0,
            phi,
            dphi,
            ..
        } = *cl;
        let n = cluster.len();
        let (inv_j1, c1) = (dy.inv_j, dy.damping);
        let (mut phi1, mut dphi1) = (b.vector(), b.vector());
        let CarrierBuffers { rk, u0, .. } = b;
        // the bodies' speeds, then the carrier's
        for k in 0..n {
            u0[k] = w0 - dphi[k];
        }
        u0[n] = w0;
        let [e1, em, e4] = dy.torque;
        // The accelerations at stage `s` (0 to 3) at `ts`: body k turned by `th[k]` from t
        // at `u[k]`, the carrier (last) by `th[n]` at `u[n]`; the powers: each body's speed
        // squared (the drag's over -C2) and the carrier's, the gaps' drag's on each body, the
        // external torque's.
        rk.rk4(cl.t, h, u0, |s, ts, th, u, acc, power| {
            let (th, u, acc) = (&th[..=n], &u[..=n], &mut acc[..=n]);
            let [sq, gap_power, external] = cut(power, [n + 1, n, 1]);
            let (sc, w) = (th[n], u[n]);
            let mut teeth = 0.0;
            for k in 0..n {
                let i = cluster[k];
                let body = Carried {
                    coupling: &self.couplings[i],
                    phi: phi[k],
                    inv_j: inv_j[k],
                    c2: self.bodies[i].drag_n_m_s_rad,
                    gap: &gaps[k],
                };
                let (torque, a, g) = body.stage(ts, sc, w, th[k], u[k]);
                acc[k] = a;
                teeth += torque;
                sq[k] = u[k] * u[k];
                gap_power[k] = g * u[k];
            }
            let ext = [e1, em, em, e4][s];
            acc[n] = (ext - c1 * w - teeth) * inv_j1;
            sq[n] = w * w;
            external[0] = ext * w;
        });
        let [sq, gap_work, external] = cut(&mut rk.work, [n + 1, n, 1]);
        let (turn, speed) = (rk.turn[n], rk.u1[n]);
        let mut drag_j = -c1 * sq[n];
        let mut gap_j = 0.0;
        for k in 0..n {
            phi1.push(phi[k] + turn - rk.turn[k]);
            dphi1.push(speed - rk.u1[k]);
            drag_j -= self.bodies[cluster[k]].drag_n_m_s_rad * sq[k];
            gap_j += gap_work[k];
        }
        CarrierStep {
            turn,
            speed,
            phi: phi1,
            dphi: dphi1,
            external_j: external[0],
            drag_j,
            gap_j,
        }
    }

    /// Integrates inertial carrier `c` from `t` to `t1` together with the couplings `cluster`
    /// (those that may touch it within the world step; the others fly free and load nothing),
    /// the open gaps' drag `gaps` on each coupling, with sub-steps of the shortest any of them
    /// wants (the prescribed shaft's controller and grading, applied to each), at most the
    /// world step over [`SHAFT_SUB_STEPS`], landed on every onset and separation
    /// ([`Run::land_sub_steps`]). Leaves the couplings' states at `t1` in `rel` and `forces`,
    /// adds the external torque's, the damping's, the drag's and the gaps' work to the audit,
    /// feeds the events, and returns the carrier's nodes (the motion the free couplings
    /// follow).
    fn integrate_carrier(
        &mut self,
        c: usize,
        cluster: &[usize],
        gaps: &[GapDrag],
        ws: &mut WorldStep,
    ) -> Result<Vec<Node>, EngineError> {
        let n = cluster.len();
        let (angle, w) = self.carrier_state(c);
        let mut steps = CarrierSteps {
            c,
            cluster,
            inv_j: cluster
                .iter()
                .map(|&i| self.inv_inertia_z(self.world.discs[i]))
                .collect(),
            gaps: cluster.iter().map(|&i| gaps[i]).collect(),
            t: self.t,
            angle,
            w,
            phi: cluster.iter().map(|&i| self.rel[i].phi).collect(),
            dphi: cluster.iter().map(|&i| self.rel[i].dphi).collect(),
            nodes: vec![Node {
                t: self.t,
                angle,
                speed: w,
            }],
            cap: ws.a.max_step_s / SHAFT_SUB_STEPS,
            bufs: std::cell::RefCell::new(CarrierBuffers::new(n)),
        };
        self.land_sub_steps(&mut steps, ws)?;
        Ok(steps.nodes)
    }

    /// Advances inertial carrier `c` and the couplings it carries from `t` to `t1`, the open
    /// gaps' drag `gaps` on each coupling (indexed by coupling): the couplings that may touch
    /// it within the world step (in contact at `t`, or closer to it than the prescribed
    /// scheme's controller lets a coupling fly within the step, with the carrier's
    /// acceleration bounded by its drive or load, its damping and the reactions at `t`) are
    /// integrated with the carrier as one system ([`Run::integrate_carrier`]); every other
    /// one then flies free against the carrier's motion so found ([`Path::Nodes`]), as against
    /// a prescribed shaft. Writes each carried coupling's speed at `t1` into `omega_d` and its
    /// mean speed over the step into `means`; returns the carrier's nodes at `t` and `t1`.
    pub(super) fn advance_carrier(
        &mut self,
        c: usize,
        gaps: &[GapDrag],
        means: &mut [f64],
        ws: &mut WorldStep,
    ) -> Result<(Node, Node), EngineError> {
        let (t1, a) = (ws.t1, ws.a);
        let t0 = self.t;
        let h = t1 - t0;
        let carried = self.carried_by(c);
        let reaction: f64 = carried
            .iter()
            .map(|&i| self.forces[i].moment[2].abs())
            .sum();
        let a_carrier = self.inertial_accel_bound(c, self.carrier_state(c).1, reaction);
        let mut cluster = Vec::new();
        let mut free = Vec::new();
        for &i in &carried {
            let f = self.forces[i];
            if f.depth_m > 0.0 {
                cluster.push(i);
                continue;
            }
            let d = &self.bodies[i];
            let g = gaps[i];
            let inv_j = self.inv_inertia_z(self.world.discs[i]);
            let wd = self.carrier_state(c).1 - self.rel[i].dphi;
            let bound =
                a_carrier + ((d.drag_n_m_s_rad + g.damping) * wd.abs() + g.bound_n_m()) * inv_j;
            let rel = self.rel[i];
            let view = self.coupling_view(i, &f, (rel.phi, rel.dphi), bound, t0);
            if coupling_step(&view, a).0 < h {
                cluster.push(i);
            } else {
                free.push(i);
            }
        }
        let phi0: Vec<f64> = self.rel.iter().map(|r| r.phi).collect();
        let nodes = self.integrate_carrier(c, &cluster, gaps, ws)?;
        let path = Path::Nodes(&nodes);
        for &i in &free {
            self.integrate_coupling(i, gaps[i], path, a_carrier, ws)?;
        }
        let (start, end) = (nodes[0], nodes[nodes.len() - 1]);
        for &i in &carried {
            self.omega_d[i] = end.speed - self.rel[i].dphi;
            means[i] = (end.angle - start.angle - (self.rel[i].phi - phi0[i])) / h;
        }
        self.set_carrier_state(c, end.angle, end.speed);
        Ok((start, end))
    }

    /// The world's step of the multirate schemes from `t` to `t1`, after each coupling body's
    /// torque was set to drift it by its mean speed ([`Run::drive_to_means`]): each inertial
    /// carrier's body (`carriers`: its index in the table and its nodes at `t` and `t1`) gets its mean
    /// speed set for the step instead of a torque (rapier's inverse inertia of such a body
    /// reads 0 until its first step computes the body's mass properties, and the torque from
    /// it, infinite, left every body at rest from then on: measured); then every body's speed
    /// is set to its speed at `t1`, and the clock advances.
    pub(super) fn step_world_multirate(&mut self, t1: f64, carriers: &[(usize, Node, Node)]) {
        let t0 = self.t;
        let h = t1 - t0;
        let bodies = &mut self.world.physics.bodies;
        for &(c, start, end) in carriers {
            let body = &mut bodies[self.world.carriers[c].handle];
            body.reset_forces(false);
            body.reset_torques(false);
            let mean = (end.angle - start.angle) / h;
            body.set_angvel(Vector::new(0.0, 0.0, mean), false);
        }
        self.world.step(h);
        let bodies = &mut self.world.physics.bodies;
        for i in 0..self.couplings.len() {
            let body = &mut bodies[self.world.discs[i]];
            body.set_angvel(Vector::new(0.0, 0.0, self.omega_d[i]), false);
        }
        for &(c, _, end) in carriers {
            bodies[self.world.carriers[c].handle]
                .set_angvel(Vector::new(0.0, 0.0, end.speed), false);
        }
        self.t_prev = Some(t0);
        self.t = t1;
    }
}

/// An inertial carrier with its cluster as the one landing loop drives it
/// ([`Run::integrate_carrier`]).
struct CarrierSteps<'a> {
    /// The carrier and the couplings integrated with it, their bodies' inverse inertias,
    /// 1/(kg m^2), and the open gaps' drag on each.
    c: usize,
    cluster: &'a [usize],
    inv_j: Vec<f64>,
    gaps: Vec<GapDrag>,
    /// The time, s, the carrier's angle, rad, and speed, rad/s, and each coupling's relative
    /// angle, rad, and speed, rad/s, there.
    t: f64,
    angle: f64,
    w: f64,
    phi: Vec<f64>,
    dphi: Vec<f64>,
    /// The carrier at the sub-steps' ends so far.
    nodes: Vec<Node>,
    /// The longest sub-step, s.
    cap: f64,
    bufs: std::cell::RefCell<CarrierBuffers>,
}

impl SubSteps for CarrierSteps<'_> {
    type Step = CarrierStep;

    fn t(&self) -> f64 {
        self.t
    }

    fn members(&self) -> &[usize] {
        self.cluster
    }

    fn phi(&self, k: usize) -> f64 {
        self.phi[k]
    }

    fn want(&mut self, run: &mut Run, ws: &mut WorldStep) -> Result<f64, EngineError> {
        let (a, t, w) = (ws.a, self.t, self.w);
        let reaction: f64 = self
            .cluster
            .iter()
            .map(|&i| run.forces[i].moment[2].abs())
            .sum();
        let a_carrier = run.inertial_accel_bound(self.c, w, reaction);
        let mut want = self.cap;
        for (k, &i) in self.cluster.iter().enumerate() {
            let d = &run.bodies[i];
            let f = run.forces[i];
            let wd = w - self.dphi[k];
            let g = self.gaps[k];
            let bound = a_carrier
                + ((d.drag_n_m_s_rad + g.damping) * wd.abs() + g.bound_n_m()) * self.inv_j[k];
            let view = run.coupling_view(i, &f, (self.phi[k], self.dphi[k]), bound, t);
            let (wk, _) = coupling_step(&view, a);
            want = want.min(graded_step(
                wk,
                &f,
                run.events.event_age_s(i, t),
                KINK_FLOOR_DIVISOR,
            ));
        }
        let who = run.carriers[self.c].name;
        checked_sub_step(want, a, t, || who.into())
    }

    fn step(&self, run: &Run, h: f64) -> CarrierStep {
        let b = &mut self.bufs.borrow_mut();
        let dy = run.carrier_dynamics(self.c, self.t, h);
        let start = Cluster {
            members: self.cluster,
            inv_j: &self.inv_j,
            gaps: &self.gaps,
            t: self.t,
            w0: self.w,
            phi: &self.phi,
            dphi: &self.dphi,
        };
        run.carrier_step(&start, &dy, h, b)
    }

    fn phi_end(&self, step: &CarrierStep, k: usize) -> f64 {
        step.phi[k]
    }

    fn evals_per_step(&self) -> u64 {
        4 * self.cluster.len() as u64
    }

    fn accept(
        &mut self,
        run: &mut Run,
        step: CarrierStep,
        t: f64,
        _: Option<usize>,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        self.t = t;
        self.angle += step.turn;
        self.w = step.speed;
        // the step's vectors become the state, the state's go back to the buffers
        let (phi, dphi) = (
            std::mem::replace(&mut self.phi, step.phi),
            std::mem::replace(&mut self.dphi, step.dphi),
        );
        self.bufs.get_mut().spare.extend([phi, dphi]);
        ws.counts.substeps += 1;
        ws.counts.evals += 5 * self.cluster.len() as u64;
        run.book_external(self.c, step.external_j, step.drag_j);
        run.energy.add_stack_work(step.gap_j);
        let (angle, w) = (self.angle, self.w);
        self.nodes.push(Node { t, angle, speed: w });
        let at = ShaftAt { speed: w, angle };
        for (k, &i) in self.cluster.iter().enumerate() {
            run.end_sub_step(
                i,
                t,
                self.phi[k],
                self.dphi[k],
                at,
                ws.a.steps_per_contact,
                ws,
            )?;
        }
        Ok(())
    }
}
