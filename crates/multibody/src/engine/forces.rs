//! Force evaluation: the hook at `t` (relative states, tooth loads, the stack's clamp forces),
//! the physical loads on every body and their kicks, the teeth's and the drive's impulses over
//! a step, and the step itself (forces handed to rapier, the world advanced).

use super::state::{relative_state, Run, ShaftDrive};
use crate::integrate::{future_impulse, past_impulse, Load, Motion};
use crate::world::{angle_about_z, Carrier};
use clutchpack_model::EngineError;
use rapier3d_f64::prelude::{RigidBody, Rotation, Vector};

impl Run {
    /// The hook at `t`: every coupling's relative state and tooth loads, then the stack's
    /// clamp forces. Fails if the state is not finite or the teeth passed through each other
    /// (|phi| beyond half a pitch).
    pub(super) fn evaluate(&mut self, t_last_good: f64) -> Result<(), EngineError> {
        let bodies = &self.world.physics.bodies;
        let shaft = &bodies[self.world.shaft];
        // First estimates of the speeds at t: rapier's mean speeds plus the extrapolated
        // accelerations over the last step.
        self.omega_s = match &self.shaft {
            ShaftDrive::Prescribed(p) => p.speed(self.t),
            ShaftDrive::Inertial { j1, .. } => self.shared.shaft_loads.full_history.synchronised(
                self.t,
                shaft.angvel().z,
                5,
                1.0 / *j1,
            ),
        };
        if let (Some(d), Some(h)) = (self.drum.as_mut(), self.world.drum) {
            d.omega = self.shared.drum_loads.full_history.synchronised(
                self.t,
                bodies[h].angvel().z,
                5,
                1.0 / d.model.inertia_kg_m2,
            );
        }
        // The teeth's torque integrated along the last step (the past half of the kick), which
        // also gives the synchronised speeds without extrapolating across a kink.
        let mut teeth_past_shaft = 0.0;
        let mut teeth_past_drum = 0.0;
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
                match self.world.carriers[i] {
                    Carrier::Shaft => teeth_past_shaft += self.shared.teeth_past[i],
                    Carrier::Drum => teeth_past_drum += self.shared.teeth_past[i],
                    Carrier::Housing => {}
                }
            }
        }
        let load_past = self.drum_load_past();
        if let ShaftDrive::Inertial { j1, .. } = self.shaft {
            if self.shared.shaft_loads.history.len() > 0 {
                self.omega_s = shaft.angvel().z
                    + (self
                        .shared
                        .shaft_loads
                        .history
                        .synchronised(self.t, 0.0, 5, 1.0)
                        + self.drive_past()
                        - teeth_past_shaft)
                        / j1;
            }
        }
        if let (Some(d), Some(h)) = (self.drum.as_mut(), self.world.drum) {
            if self.shared.drum_loads.history.len() > 0 {
                d.omega = bodies[h].angvel().z
                    + (self
                        .shared
                        .drum_loads
                        .history
                        .synchronised(self.t, 0.0, 5, 1.0)
                        + load_past
                        - teeth_past_drum)
                        / d.model.inertia_kg_m2;
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
    /// (`session.rs`): the relative motion of every coupling on the shaft by the shaft's speed
    /// jump `shaft_jump` (rad/s; the bodies' speeds are continuous, so `dphi` and the offset's
    /// rate in the shaft's turning frame jump), the tooth loads at it (the contact memories
    /// keep their events), the clamp forces; on the shared step (not `multirate`, whose
    /// sub-steps do their own audit and read no kicks) also the energy audit's powers (a
    /// zero-length interval, no work) and the loads and kicks of the next step. The past half
    /// of the teeth's kick keeps the motion before the jump, as the step that ended at `t` had.
    pub(super) fn input_changed(&mut self, shaft_jump: f64, multirate: bool) {
        self.potential_j = 0.0;
        for i in 0..self.couplings.len() {
            if self.world.carriers[i] == Carrier::Shaft && shaft_jump != 0.0 {
                let rel = &mut self.rel[i];
                rel.dphi += shaft_jump;
                // rate = dv - omega_s z x d in the shaft's frame
                rel.offset_rate[0] += shaft_jump * rel.offset[1];
                rel.offset_rate[1] -= shaft_jump * rel.offset[0];
            }
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

    /// The stack's clamp forces and slips at `t` from the teeth's normal loads
    /// `n |F| = |torque| / Rb` and the bodies' speeds (no-op without a stack).
    pub(super) fn update_stack(&mut self) {
        if let Some(stack) = self.stack.as_mut() {
            let normal: Vec<f64> = self
                .forces
                .iter()
                .zip(self.bodies.iter())
                .map(|(f, d)| f.moment[2].abs() / d.spline.base_radius_m())
                .collect();
            stack.update(self.t, &normal, &self.omega_d);
        }
    }

    /// The physical loads at `t` on every body (the drag, the teeth and their reactions, the
    /// drive, the drum's load) and the kicks for the next step.
    pub(super) fn compute_loads(&mut self) {
        let bodies = &self.world.physics.bodies;
        let mut shaft_force = Vector::ZERO;
        let mut shaft_torque = Vector::ZERO;
        let mut shaft_torque_full = Vector::ZERO;
        let mut drum_force = Vector::ZERO;
        let mut drum_torque = Vector::ZERO;
        let mut drum_torque_full = Vector::ZERO;
        let mut disc_accel = vec![0.0; self.forces.len()];
        for (i, f) in self.forces.iter().enumerate() {
            let d = &self.bodies[i];
            let carrier = self.world.carriers[i];
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
            match carrier {
                Carrier::Shaft => {
                    shaft_torque_full -= reaction;
                    shaft_force -= force;
                    shaft_torque -= reaction - Vector::new(0.0, 0.0, f.moment[2]);
                }
                Carrier::Drum => {
                    drum_torque_full -= reaction;
                    drum_force -= force;
                    drum_torque -= reaction - Vector::new(0.0, 0.0, f.moment[2]);
                }
                Carrier::Housing => {}
            }
            self.shared.loads[i].kick = self.shared.loads[i]
                .history
                .kick(self.t, &self.shared.loads[i].load);
        }
        let drive_now = self.drive_torque(self.t);
        // MODEL.md section 8: the couplings between the shaft and the drum (a spring-damper),
        // smooth in time: through the polynomial kick, as the drag
        let joined = (!self.pack.couplings.is_empty()).then(|| self.coupling_loads());
        let shaft_accel = match &self.shaft {
            ShaftDrive::Prescribed(p) => p.acceleration(self.t),
            &ShaftDrive::Inertial { j1, c1 } => {
                // Hu et al. eq (4): the drive torque, the spline reactions, damping -C1 omega.
                // The drive is a known function of time: its kick is integrated exactly
                // (`drive_impulse`), not extrapolated.
                let damping = -c1 * self.omega_s;
                shaft_torque.z += damping;
                shaft_torque_full.z += damping + drive_now;
                if let Some(c) = joined {
                    shaft_torque.z += c.shaft_n_m;
                    shaft_torque_full.z += c.shaft_n_m;
                }
                let l = |t: Vector| [shaft_force.x, shaft_force.y, shaft_force.z, t.x, t.y, t.z];
                self.shared.shaft_loads.load = l(shaft_torque);
                self.shared.shaft_loads.full = l(shaft_torque_full);
                self.shared.shaft_loads.kick = self
                    .shared
                    .shaft_loads
                    .history
                    .kick(self.t, &self.shared.shaft_loads.load);
                shaft_torque_full.z / j1
            }
        };
        let drum_accel = match self.drum.as_mut() {
            Some(dr) => {
                // The drum: its load torque, its drag, the plates' spline reactions.
                let own = dr.model.load_torque_n_m - dr.model.drag_n_m_s_rad * dr.omega;
                // A driven load is integrated exactly (`drum_load_impulse`), not extrapolated.
                drum_torque.z += if self.shared.exact_drum_load {
                    -dr.model.drag_n_m_s_rad * dr.omega
                } else {
                    own
                };
                drum_torque_full.z += own;
                if let Some(c) = joined {
                    drum_torque.z += c.drum_n_m;
                    drum_torque_full.z += c.drum_n_m;
                }
                let l = |t: Vector| [drum_force.x, drum_force.y, drum_force.z, t.x, t.y, t.z];
                self.shared.drum_loads.load = l(drum_torque);
                self.shared.drum_loads.full = l(drum_torque_full);
                self.shared.drum_loads.kick = self
                    .shared
                    .drum_loads
                    .history
                    .kick(self.t, &self.shared.drum_loads.load);
                drum_torque_full.z / dr.model.inertia_kg_m2
            }
            None => 0.0,
        };
        for c in &self.shared.teeth_cache {
            c.set((f64::NAN, 0.0));
        }
        for (i, m) in self.shared.teeth_motion.iter_mut().enumerate() {
            let carrier_accel = match self.world.carriers[i] {
                Carrier::Shaft => shaft_accel,
                Carrier::Drum => drum_accel,
                Carrier::Housing => 0.0,
            };
            let ddphi = carrier_accel - disc_accel[i];
            let (jerk, jerk_step) = match self.shared.prev_motion[i] {
                Some((t0, _, _, dd0)) if self.t > t0 => {
                    ((ddphi - dd0) / (self.t - t0), self.t - t0)
                }
                _ => (0.0, 0.0),
            };
            *m = Motion {
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
            .drum
            .as_ref()
            .map_or((0.0, 0.0), |d| (d.theta, d.omega));
        self.pack.coupling_loads((self.theta_s, self.omega_s), drum)
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

    /// The drive torque on an inertial shaft integrated against the rising ramp of the last
    /// step (N m s; 0 before the first step or for a prescribed shaft).
    pub(super) fn drive_past(&self) -> f64 {
        let Some(t0) = self.t_prev else {
            return 0.0;
        };
        let h = self.t - t0;
        if h <= 0.0 || matches!(self.shaft, ShaftDrive::Prescribed(_)) {
            return 0.0;
        }
        crate::integrate::ramp_integral(t0, h, true, |t| self.drive_torque(t))
    }

    /// The drive torque on an inertial shaft at `t`, N m: the pack's excitation, or before a
    /// driven torque's last change (`drive_switch`) the value held until then.
    pub(super) fn drive_torque(&self, t: f64) -> f64 {
        match self.drive_switch {
            Some((t_switch, before)) if t < t_switch => before,
            _ => self.pack.shaft.drive_torque_n_m(t),
        }
    }

    /// A driven drum load at `t`, N m: the drum's, or before its last change (`load_switch`)
    /// the value held until then.
    fn drum_load(&self, t: f64) -> f64 {
        match (self.shared.load_switch, &self.drum) {
            (Some((t_switch, before)), _) if t < t_switch => before,
            (_, Some(d)) => d.model.load_torque_n_m,
            (_, None) => 0.0,
        }
    }

    /// A driven drum load integrated against the rising ramp of the last step, N m s (0 when
    /// the load is not driven: it is then in the drum's polynomial kick).
    pub(super) fn drum_load_past(&self) -> f64 {
        match self.t_prev {
            Some(t0) if self.shared.exact_drum_load && self.t > t0 => {
                crate::integrate::ramp_integral(t0, self.t - t0, true, |t| self.drum_load(t))
            }
            _ => 0.0,
        }
    }

    /// The kick of a driven drum load for a step of length `x` from `t` (both halves, N m s; 0
    /// when the load is not driven).
    pub(super) fn drum_load_impulse(&self, x: f64) -> f64 {
        if !self.shared.exact_drum_load {
            return 0.0;
        }
        self.drum_load_past()
            + crate::integrate::ramp_integral(self.t, x, false, |t| self.drum_load(t))
    }

    /// The kick of the drive torque on an inertial shaft for a step of length `x` from `t`
    /// (both halves, N m s).
    pub(super) fn drive_impulse(&self, x: f64) -> f64 {
        if matches!(self.shaft, ShaftDrive::Prescribed(_)) {
            return 0.0;
        }
        self.drive_past()
            + crate::integrate::ramp_integral(self.t, x, false, |t| self.drive_torque(t))
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
        let drive = self.drive_impulse(h);
        let drum_load = self.drum_load_impulse(h);
        let bodies = &mut self.world.physics.bodies;
        let apply = |body: &mut RigidBody, l: Load| {
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_force(Vector::new(l[0], l[1], l[2]), false);
            body.add_torque(Vector::new(l[3], l[4], l[5]), false);
        };
        let mut teeth_on_shaft = 0.0;
        let mut teeth_on_drum = 0.0;
        for (i, body) in self.shared.loads.iter_mut().enumerate() {
            let mut load = body.kick.applied(h);
            load[5] += teeth[i] + stack[i];
            match self.world.carriers[i] {
                Carrier::Shaft => teeth_on_shaft -= teeth[i],
                Carrier::Drum => teeth_on_drum -= teeth[i],
                Carrier::Housing => {}
            }
            apply(&mut bodies[self.world.discs[i]], load);
            body.history.push(self.t, body.load);
            body.full_history.push(self.t, body.full);
            let m = &self.shared.teeth_motion[i];
            self.shared.prev_motion[i] = Some((self.t, m.phi, m.dphi, m.ddphi));
        }
        let shaft = &mut bodies[self.world.shaft];
        match &self.shaft {
            ShaftDrive::Prescribed(p) => {
                self.shared.theta_next = p.angle(t_next);
                shaft
                    .set_next_kinematic_rotation(Rotation::from_rotation_z(self.shared.theta_next));
            }
            ShaftDrive::Inertial { .. } => {
                let mut load = self.shared.shaft_loads.kick.applied(h);
                load[5] += teeth_on_shaft + drive / h;
                apply(shaft, load);
                self.shared
                    .shaft_loads
                    .history
                    .push(self.t, self.shared.shaft_loads.load);
                self.shared
                    .shaft_loads
                    .full_history
                    .push(self.t, self.shared.shaft_loads.full);
            }
        }
        if let (Some(_), Some(hd)) = (&self.drum, self.world.drum) {
            let mut load = self.shared.drum_loads.kick.applied(h);
            load[5] += teeth_on_drum + drum_load / h;
            apply(&mut bodies[hd], load);
            self.shared
                .drum_loads
                .history
                .push(self.t, self.shared.drum_loads.load);
            self.shared
                .drum_loads
                .full_history
                .push(self.t, self.shared.drum_loads.full);
        }
    }

    /// Steps the world to `t_next` (after [`Run::apply_forces`]) and updates the shaft and
    /// drum angles and the stack's work.
    pub(super) fn advance(&mut self, t_next: f64) {
        let h = t_next - self.t;
        let q_before = *self.world.physics.bodies[self.world.shaft].rotation();
        let drum_before = self
            .world
            .drum
            .map(|hd| *self.world.physics.bodies[hd].rotation());
        self.world.step(h);
        self.t_prev = Some(self.t);
        self.t = t_next;
        self.theta_s = match self.shaft {
            ShaftDrive::Prescribed(_) => self.shared.theta_next,
            ShaftDrive::Inertial { .. } => {
                let q_after = *self.world.physics.bodies[self.world.shaft].rotation();
                self.theta_s + angle_about_z(&(q_before.inverse() * q_after))
            }
        };
        if let (Some(d), Some(hd), Some(q0)) = (self.drum.as_mut(), self.world.drum, drum_before) {
            let q1 = *self.world.physics.bodies[hd].rotation();
            d.theta += angle_about_z(&(q0.inverse() * q1));
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
