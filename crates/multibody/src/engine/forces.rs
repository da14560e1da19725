//! Force evaluation: the hook at `t` (relative states, tooth loads, the stack's clamp forces),
//! the physical loads on every body and their kicks, the teeth's and the drive's impulses over
//! a step, and the step itself (forces handed to rapier, the world advanced).

use super::carriers::{joined_torque, Motion};
use super::state::{relative_state, Run};
use crate::integrate::{future_impulse, past_impulse, Load};
use crate::world::{angle_about_z, SHAFT};
use clutchpack_model::EngineError;
use rapier3d_f64::prelude::{RigidBody, Rotation, Vector};

impl Run {
    /// The hook at `t`: every coupling's relative state and tooth loads, then the stack's
    /// clamp forces. Fails if the state is not finite or the teeth passed through each other
    /// (|phi| beyond half a pitch).
    pub(super) fn evaluate(&mut self, t_last_good: f64) -> Result<(), EngineError> {
        let bodies = &self.world.physics.bodies;
        // First estimates of the carriers' speeds at t: a prescribed one's profile, an
        // inertial one's rapier mean speed plus the extrapolated accelerations over the last
        // step.
        for (c, k) in self.carriers.iter_mut().enumerate() {
            let carrier = &bodies[self.world.carriers[c].handle];
            match &k.motion {
                Motion::Prescribed(p) => k.speed = p.speed(self.t),
                Motion::Inertial { j, .. } => {
                    k.speed = self.shared.carrier_loads[c].full_history.synchronised(
                        self.t,
                        carrier.angvel().z,
                        5,
                        1.0 / *j,
                    );
                }
                Motion::Fixed => {}
            }
        }
        // The teeth's torque integrated along the last step (the past half of the kick), which
        // also gives the synchronised speeds without extrapolating across a kink; summed per
        // carrier.
        let mut teeth_past_on = vec![0.0; self.carriers.len()];
        for i in 0..self.couplings.len() {
            self.shared.teeth_past[i] = 0.0;
            let Some((t0, phi0, dphi0, _)) = self.shared.prev_motion[i] else {
                continue;
            };
            let disc = &bodies[self.world.discs[i]];
            let j = self.bodies[i].inertia_kg_m2;
            let est =
                self.shared.loads[i]
                    .full_history
                    .synchronised(self.t, disc.angvel().z, 5, 1.0 / j)
                    + self.stack_past(i) / j;
            let rel = relative_state(
                &bodies[self.carrier_body(i)],
                self.carrier_speed(i),
                disc,
                est,
                self.world.disc_turn_owed_z(i),
            );
            let h1 = self.t - t0;
            if h1 > 0.0 {
                let c = &self.couplings[i];
                self.shared.teeth_past[i] =
                    past_impulse((phi0, dphi0), (rel.phi, rel.dphi), h1, |p, d| {
                        c.probe_torque(p, d)
                    });
                teeth_past_on[self.world.carrier_of[i]] += self.shared.teeth_past[i];
            }
        }
        // An inertial carrier's speed at t from its mean speed over the last step, the past
        // halves of its loads' kick, of its external torque's and of the teeth's reactions.
        for c in 0..self.carriers.len() {
            let Motion::Inertial { j, .. } = self.carriers[c].motion else {
                continue;
            };
            let loads = &self.shared.carrier_loads[c];
            if loads.history.len() > 0 {
                let past = self.external_past(c);
                self.carriers[c].speed = bodies[self.world.carriers[c].handle].angvel().z
                    + (loads.history.synchronised(self.t, 0.0, 5, 1.0) + past - teeth_past_on[c])
                        / j;
            }
        }
        self.rel.clear();
        self.forces.clear();
        self.omega_d.clear();
        self.potential_j = 0.0;
        for i in 0..self.couplings.len() {
            let disc = &bodies[self.world.discs[i]];
            let j = self.bodies[i].inertia_kg_m2;
            let mean = disc.angvel().z;
            let omega_d = if self.shared.prev_motion[i].is_some() {
                mean + (self.shared.teeth_past[i]
                    + self.shared.loads[i]
                        .history
                        .synchronised(self.t, 0.0, 5, 1.0)
                    + self.stack_past(i))
                    / j
            } else {
                self.shared.loads[i]
                    .full_history
                    .synchronised(self.t, mean, 5, 1.0 / j)
            };
            self.omega_d.push(omega_d);
        }
        // Bodies whose faces stuck over the last step turned as one body (their mean speeds
        // were made equal, `stack.rs`): their speed at t is the group's, the momentum-weighted
        // mean of the estimates (the stack's internal torques cancel in it).
        if let Some(stack) = &self.stack {
            let mut m = 0;
            while m < stack.interfaces() {
                if !stack.locked[m] {
                    m += 1;
                    continue;
                }
                let first = m;
                while m < stack.interfaces() && stack.locked[m] {
                    m += 1;
                }
                // stack bodies first..=m are locked together
                let group = &stack.body[first..=m];
                let (mut jw, mut jsum) = (0.0, 0.0);
                for &i in group {
                    let j = self.bodies[i].inertia_kg_m2;
                    jw += j * self.omega_d[i];
                    jsum += j;
                }
                for &i in group {
                    self.omega_d[i] = jw / jsum;
                }
            }
        }
        for i in 0..self.couplings.len() {
            let disc = &bodies[self.world.discs[i]];
            let omega_d = self.omega_d[i];
            let rel = relative_state(
                &bodies[self.carrier_body(i)],
                self.carrier_speed(i),
                disc,
                omega_d,
                self.world.disc_turn_owed_z(i),
            );
            let c = &mut self.couplings[i];
            let limit = std::f64::consts::PI / c.spline.teeth as f64;
            let diverged = |reason: String| EngineError::Diverged {
                t_s: t_last_good,
                reason: format!("disc {i}: {reason}"),
            };
            if !(rel.phi.abs() <= limit && rel.dphi.is_finite()) {
                return Err(diverged(format!(
                    "relative angle {:.6e} rad, speed {:.6e} rad/s (half a tooth pitch is {limit:.6e} rad)",
                    rel.phi, rel.dphi
                )));
            }
            let offset = rel.offset[0].hypot(rel.offset[1]);
            let offset_limit = limit * c.spline.pitch_radius_m;
            if !(offset <= offset_limit && rel.offset_rate.iter().all(|v| v.is_finite())) {
                return Err(diverged(format!(
                    "radial offset {offset:.6e} m (half a tooth pitch is {offset_limit:.6e} m)"
                )));
            }
            let f = c.evaluate(&rel);
            if !(f.load_n.is_finite() && f.moment[2].is_finite()) {
                return Err(diverged(format!("tooth load {:.6e} N", f.load_n)));
            }
            self.potential_j += f.potential_j;
            self.rel.push(rel);
            self.forces.push(f);
        }
        self.update_stack();
        self.audit_energy();
        self.compute_loads();
        Ok(())
    }

    /// Re-evaluates the state at `t` after a session's driven input changed there
    /// (`session.rs`): the relative motion of every coupling on carrier `carrier` by that
    /// carrier's speed jump `jump` (rad/s; the bodies' speeds are continuous, so `dphi` and the
    /// offset's rate in the carrier's turning frame jump), the tooth loads at it (the contact
    /// memories keep their events), the clamp forces; on the shared step (not `multirate`,
    /// whose sub-steps do their own audit and read no kicks) also the energy audit's powers (a
    /// zero-length interval, no work) and the loads and kicks of the next step. The past half
    /// of the teeth's kick keeps the motion before the jump, as the step that ended at `t` had.
    pub(super) fn input_changed(&mut self, carrier: usize, jump: f64, multirate: bool) {
        self.carrier_jumped(carrier, jump);
        self.potential_j = 0.0;
        for i in 0..self.couplings.len() {
            let f = self.couplings[i].evaluate(&self.rel[i]);
            self.potential_j += f.potential_j;
            self.forces[i] = f;
        }
        self.update_stack();
        if !multirate {
            self.audit_energy();
            self.compute_loads();
        }
    }

    /// The relative motion of every coupling on carrier `carrier` after that carrier's speed
    /// jumped by `jump` (rad/s) at `t`: `dphi` and the offset's rate in its turning frame jump
    /// (nothing re-evaluated: [`Run::input_changed`] does that).
    pub(super) fn carrier_jumped(&mut self, carrier: usize, jump: f64) {
        if jump == 0.0 {
            return;
        }
        for i in 0..self.couplings.len() {
            if self.world.carrier_of[i] == carrier {
                let rel = &mut self.rel[i];
                rel.dphi += jump;
                // rate = dv - omega_s z x d in the carrier's frame
                rel.offset_rate[0] += jump * rel.offset[1];
                rel.offset_rate[1] -= jump * rel.offset[0];
            }
        }
    }

    /// The stack's clamp forces and slips at `t` from the teeth's normal loads
    /// `n |F| = |torque| / Rb` and the bodies' speeds (no-op without a stack).
    pub(super) fn update_stack(&mut self) {
        if let Some(stack) = self.stack.as_mut() {
            let mut normal = std::mem::take(&mut self.normal_buf);
            normal.clear();
            normal.extend(
                self.forces
                    .iter()
                    .zip(self.bodies.iter())
                    .map(|(f, d)| f.moment[2].abs() / d.spline.base_radius_m()),
            );
            stack.update(self.t, &normal, &self.omega_d);
            self.normal_buf = normal;
        }
    }

    /// The physical loads at `t` on every body (the drag, the teeth and their reactions, the
    /// drive, the drum's load) and the kicks for the next step.
    pub(super) fn compute_loads(&mut self) {
        let bodies = &self.world.physics.bodies;
        // per carrier: the couplings' force on it, their torque on it less the teeth's about
        // the axis, and their full torque (world frame)
        let nc = self.carriers.len();
        let mut carrier_force = vec![Vector::ZERO; nc];
        let mut carrier_torque = vec![Vector::ZERO; nc];
        let mut carrier_torque_full = vec![Vector::ZERO; nc];
        let mut disc_accel = vec![0.0; self.forces.len()];
        for (i, f) in self.forces.iter().enumerate() {
            let d = &self.bodies[i];
            let c = self.world.carrier_of[i];
            let qs = *bodies[self.carrier_body(i)].rotation();
            // Hu et al. eq (5): drag -C2 omega_d.
            let drag = -d.drag_n_m_s_rad * self.omega_d[i];
            let f_local = Vector::new(f.force[0], f.force[1], 0.0);
            let m_local = Vector::new(f.moment[0], f.moment[1], f.moment[2]);
            // The hook's moment is about the axis point of the disc's mid-plane; the disc's
            // centre sits at the offset e from it.
            let e_local = Vector::new(self.rel[i].offset[0], self.rel[i].offset[1], 0.0);
            let force = qs * f_local;
            let torque = qs * (m_local - e_local.cross(f_local)) + Vector::new(0.0, 0.0, drag);
            self.shared.loads[i].full = [force.x, force.y, force.z, torque.x, torque.y, torque.z];
            // The stack's torque over the step just taken stands for its torque at t.
            let stack = match &self.stack {
                Some(s) => s
                    .body
                    .iter()
                    .position(|&b| b == i)
                    .map_or(0.0, |b| s.torque[b]),
                None => 0.0,
            };
            disc_accel[i] = (torque.z + stack) / d.inertia_kg_m2;
            // The reaction on the carrier, about its centre: -(m + a x F), a the mid-plane.
            let a = Vector::new(0.0, 0.0, self.world.disc_axial_m[i]);
            let reaction = qs * (m_local + a.cross(f_local));
            // The teeth's torque about the axis is integrated along the step instead
            // (`teeth_impulse`); the rest (radial forces, tilting moments, the moment of the
            // radial force about an offset centre) goes through the polynomial kick.
            let mut partial = self.shared.loads[i].full;
            partial[5] -= f.moment[2];
            self.shared.loads[i].load = partial;
            carrier_torque_full[c] -= reaction;
            carrier_force[c] -= force;
            carrier_torque[c] -= reaction - Vector::new(0.0, 0.0, f.moment[2]);
            self.shared.loads[i].kick = self.shared.loads[i]
                .history
                .kick(self.t, &self.shared.loads[i].load);
        }
        // MODEL.md section 8: the couplings between the shaft and the drum (a spring-damper),
        // smooth in time: through the polynomial kick, as the drag
        let joined = (!self.pack.couplings.is_empty()).then(|| self.coupling_loads());
        let mut carrier_accel = vec![0.0; nc];
        for c in 0..nc {
            let k = &self.carriers[c];
            carrier_accel[c] = match &k.motion {
                Motion::Fixed => 0.0,
                Motion::Prescribed(p) => p.acceleration(self.t),
                &Motion::Inertial { j, damping } => {
                    // Hu et al. eq (4) for an inertial shaft: the drive torque, the spline
                    // reactions, damping -C1 w; the drum: its load torque, its drag, the
                    // plates' spline reactions. An external torque known as a function of
                    // time (the drive, a driven load) is integrated exactly
                    // (`external_impulse`), not extrapolated.
                    let own = self.external_at(c, self.t);
                    let damping = -damping * k.speed;
                    carrier_torque[c].z += if k.exact { damping } else { own + damping };
                    carrier_torque_full[c].z += own + damping;
                    if let Some(l) = joined {
                        let on = joined_torque(&l, self.world.carriers[c].role);
                        carrier_torque[c].z += on;
                        carrier_torque_full[c].z += on;
                    }
                    let f = carrier_force[c];
                    let l = |t: Vector| [f.x, f.y, f.z, t.x, t.y, t.z];
                    let loads = &mut self.shared.carrier_loads[c];
                    loads.load = l(carrier_torque[c]);
                    loads.full = l(carrier_torque_full[c]);
                    loads.kick = loads.history.kick(self.t, &loads.load);
                    carrier_torque_full[c].z / j
                }
            };
        }
        for c in &self.shared.teeth_cache {
            c.set((f64::NAN, 0.0));
        }
        for (i, m) in self.shared.teeth_motion.iter_mut().enumerate() {
            let ddphi = carrier_accel[self.world.carrier_of[i]] - disc_accel[i];
            let (jerk, jerk_step) = match self.shared.prev_motion[i] {
                Some((t0, _, _, dd0)) if self.t > t0 => {
                    ((ddphi - dd0) / (self.t - t0), self.t - t0)
                }
                _ => (0.0, 0.0),
            };
            *m = crate::integrate::Motion {
                phi: self.rel[i].phi,
                dphi: self.rel[i].dphi,
                ddphi,
                jerk,
                jerk_step,
            };
        }
    }

    /// What the pack's couplings between the shaft and the drum (MODEL.md section 8) do at
    /// `t`: their torques on both, the energy they store and the power they lose (the
    /// shaft's and the drum's angles and speeds at `t`).
    pub(super) fn coupling_loads(&self) -> clutchpack_model::CouplingLoads {
        let drum = self
            .world
            .drum()
            .map_or((0.0, 0.0), |d| self.carrier_state(d));
        self.pack.coupling_loads(self.carrier_state(SHAFT), drum)
    }

    /// The impulse of the teeth of coupling `i` on its body about the axis over a step of
    /// length `x` from `t` (both halves of the kick), N m s.
    pub(super) fn teeth_impulse(&self, i: usize, x: f64) -> f64 {
        let (cx, cv) = self.shared.teeth_cache[i].get();
        if cx == x {
            return cv;
        }
        let c = &self.couplings[i];
        let v = self.shared.teeth_past[i]
            + future_impulse(&self.shared.teeth_motion[i], x, |p, d| c.probe_torque(p, d));
        self.shared.teeth_cache[i].set((x, v));
        v
    }

    /// The external torque on inertial carrier `c` (the drive on an inertial shaft, a driven
    /// drum load) integrated against the rising ramp of the last step, N m s: its share of the
    /// speed synchronised to `t`. 0 before the first step, for a carrier that is not inertial,
    /// or whose external torque goes through the polynomial kick (not `exact`).
    pub(super) fn external_past(&self, c: usize) -> f64 {
        let k = &self.carriers[c];
        let Some(t0) = self.t_prev else {
            return 0.0;
        };
        let h = self.t - t0;
        if h <= 0.0 || !k.exact || !k.is_inertial() {
            return 0.0;
        }
        crate::integrate::ramp_integral(t0, h, true, |t| self.external_at(c, t))
    }

    /// The kick of inertial carrier `c`'s external torque for a step of length `x` from `t`
    /// (both halves, N m s; 0 as for [`Run::external_past`]).
    pub(super) fn external_impulse(&self, c: usize, x: f64) -> f64 {
        let k = &self.carriers[c];
        if !k.exact || !k.is_inertial() {
            return 0.0;
        }
        self.external_past(c)
            + crate::integrate::ramp_integral(self.t, x, false, |t| self.external_at(c, t))
    }

    /// The drive torque on an inertial shaft at `t`, N m: the pack's excitation, or before a
    /// driven torque's last change the value held until then ([`Run::external_at`]).
    pub(super) fn drive_torque(&self, t: f64) -> f64 {
        self.external_at(SHAFT, t)
    }

    /// Resets and applies every body's forces for the step from `t` to `t_next`: each body's
    /// kick over the step divided by its length (see `integrate.rs`), and the stack's torques
    /// solved for this step ([`Run::solve_stack`]).
    pub(super) fn apply_forces(&mut self, t_next: f64) {
        let h = t_next - self.t;
        let teeth: Vec<f64> = (0..self.couplings.len())
            .map(|i| self.teeth_impulse(i, h) / h)
            .collect();
        let stack: Vec<f64> = (0..self.couplings.len())
            .map(|i| self.stack_torque(i))
            .collect();
        let nc = self.carriers.len();
        let external: Vec<f64> = (0..nc).map(|c| self.external_impulse(c, h)).collect();
        let bodies = &mut self.world.physics.bodies;
        let apply = |body: &mut RigidBody, l: Load| {
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_force(Vector::new(l[0], l[1], l[2]), false);
            body.add_torque(Vector::new(l[3], l[4], l[5]), false);
        };
        let mut teeth_on = vec![0.0; nc];
        for (i, body) in self.shared.loads.iter_mut().enumerate() {
            let mut load = body.kick.applied(h);
            load[5] += teeth[i] + stack[i];
            teeth_on[self.world.carrier_of[i]] -= teeth[i];
            apply(&mut bodies[self.world.discs[i]], load);
            body.history.push(self.t, body.load);
            body.full_history.push(self.t, body.full);
            let m = &self.shared.teeth_motion[i];
            self.shared.prev_motion[i] = Some((self.t, m.phi, m.dphi, m.ddphi));
        }
        for c in 0..nc {
            let body = &mut bodies[self.world.carriers[c].handle];
            match &self.carriers[c].motion {
                Motion::Fixed => {}
                Motion::Prescribed(p) => {
                    self.shared.angle_next[c] = p.angle(t_next);
                    body.set_next_kinematic_rotation(Rotation::from_rotation_z(
                        self.shared.angle_next[c],
                    ));
                }
                Motion::Inertial { .. } => {
                    let loads = &mut self.shared.carrier_loads[c];
                    let mut load = loads.kick.applied(h);
                    load[5] += teeth_on[c] + external[c] / h;
                    apply(body, load);
                    loads.history.push(self.t, loads.load);
                    loads.full_history.push(self.t, loads.full);
                }
            }
        }
    }

    /// Steps the world to `t_next` (after [`Run::apply_forces`]) and updates the carriers'
    /// angles and the stack's work.
    pub(super) fn advance(&mut self, t_next: f64) {
        let h = t_next - self.t;
        let rotation = |world: &crate::world::World, c: usize| {
            *world.physics.bodies[world.carriers[c].handle].rotation()
        };
        let before: Vec<Rotation> = (0..self.carriers.len())
            .map(|c| rotation(&self.world, c))
            .collect();
        self.world.step(h);
        self.t_prev = Some(self.t);
        self.t = t_next;
        for (c, q0) in before.into_iter().enumerate() {
            let k = &mut self.carriers[c];
            match k.motion {
                Motion::Fixed => {}
                Motion::Prescribed(_) => k.angle = self.shared.angle_next[c],
                Motion::Inertial { .. } => {
                    let q1 = rotation(&self.world, c);
                    k.angle += angle_about_z(&(q0.inverse() * q1));
                }
            }
        }
        if let Some(s) = self.stack.as_mut() {
            let bodies = &self.world.physics.bodies;
            let discs = &self.world.discs;
            let w = |i: usize| bodies[discs[i]].angvel().z;
            for m in 0..s.interfaces() {
                let slip = w(s.body[m + 1]) - w(s.body[m]);
                let work = s.impulse[m] * slip;
                self.energy.add_stack_work(work);
                s.dissipated_j[m] -= work;
                // the step's impulse was solved with the clamp at its start
                if s.clamp[m] > 0.0 {
                    s.friction_j[m] -= work;
                }
            }
        }
    }
}
