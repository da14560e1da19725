//! Step control: the step each coupling allows, the stack's impulses for a step, and the
//! landing of steps on contact onsets and separations.

use super::carriers::{joined_torque, External, Motion};
use super::state::Run;
use crate::options::AdaptiveStepping;
use crate::stepping::{coupling_step, CouplingView};
use crate::world::SHAFT;

impl Run {
    /// What the step controller ([`coupling_step`]) reads of coupling `i` at `t` (s): its
    /// evaluated `forces`, its relative angle and speed `rel` (rad, rad/s), and the bound
    /// of `|d dphi / dt|` in free flight `accel_bound` (rad/s^2), taken 1 % over (rounding
    /// must not make it optimistic).
    #[inline]
    pub(super) fn coupling_view<'a>(
        &'a self,
        i: usize,
        forces: &'a crate::hook::CouplingForces,
        rel: (f64, f64),
        accel_bound: f64,
        t: f64,
    ) -> CouplingView<'a> {
        let d = &self.bodies[i];
        CouplingView {
            forces,
            law: &d.law,
            phi: rel.0,
            dphi: rel.1,
            g0: self.couplings[i].half_play_rad(),
            rb: self.couplings[i].base_radius_m(),
            m_eff_kg: self.m_eff[i],
            rel_accel_bound: 1.01 * accel_bound,
            event_step_s: self.events.event_step_s(i),
            event_age_s: self.events.event_age_s(i, t),
        }
    }

    /// The step the adaptive controller wants at `t`, s, and whether it is a contact step.
    pub(super) fn desired_step(&self, a: &AdaptiveStepping) -> (f64, bool) {
        // Each carrier's acceleration bound: a prescribed one's profile's, an inertial one's
        // external torque (the drive's bound, or the load), its damping and the teeth's
        // reactions at t (contacts elsewhere in the pack jolt it).
        let mut a_carrier: Vec<f64> = (self.carriers.iter().enumerate())
            .map(|(c, k)| match k.motion {
                Motion::Fixed => 0.0,
                Motion::Prescribed(_) => k.drive_bound,
                Motion::Inertial { j, damping } => {
                    let reaction: f64 = self
                        .forces
                        .iter()
                        .zip(&self.world.carrier_of)
                        .filter(|(_, &of)| of == c)
                        .map(|(f, _)| f.moment[2].abs())
                        .sum();
                    match k.external {
                        External::Load(l) => (l.abs() + damping * k.speed.abs() + reaction) / j,
                        External::Drive => k.drive_bound + (damping * k.speed.abs() + reaction) / j,
                        External::None => (damping * k.speed.abs() + reaction) / j,
                    }
                }
            })
            .collect();
        let mut want = a.max_step_s;
        if !self.pack.couplings.is_empty() {
            // the couplings' torques jolt the inertial carriers too; and their free
            // oscillation is resolved like a contact (MODEL.md section 8)
            let loads = self.coupling_loads();
            for (c, k) in self.carriers.iter().enumerate() {
                if let Motion::Inertial { j, .. } = k.motion {
                    a_carrier[c] += joined_torque(&loads, self.world.carriers[c].role).abs() / j;
                }
            }
            want = want.min(self.coupling_period_s() / a.steps_per_contact);
        }
        let mut contact = false;
        for (i, d) in self.bodies.iter().enumerate() {
            let stack = self.stack.as_ref().map_or(0.0, |s| {
                s.body
                    .iter()
                    .position(|&b| b == i)
                    .map_or(0.0, |_| s.torque_bound(i))
            });
            let a_disc = (d.drag_n_m_s_rad * self.omega_d[i].abs() + stack) / d.inertia_kg_m2;
            let rel = self.rel[i];
            let view = self.coupling_view(
                i,
                &self.forces[i],
                (rel.phi, rel.dphi),
                a_carrier[self.world.carrier_of[i]] + a_disc,
                self.t,
            );
            let (dt, c) = coupling_step(&view, a);
            if dt < want {
                want = dt;
                contact = c;
            }
        }
        (want, contact)
    }

    /// The shortest undamped period of the pack's couplings between the shaft and the drum,
    /// s: `2 pi / omega_n`, `omega_n = sqrt(k (1/J_a + 1/J_b))` with a prescribed shaft as an
    /// infinite inertia (MODEL.md section 8); infinite without couplings.
    pub(super) fn coupling_period_s(&self) -> f64 {
        let j_of = |c: usize| match self.carriers[c].motion {
            Motion::Inertial { j, .. } => j,
            _ => f64::INFINITY,
        };
        let j_shaft = j_of(SHAFT);
        let j_drum = self.world.drum().map_or(f64::INFINITY, j_of);
        let inertia = |b| match b {
            clutchpack_model::PackBody::Shaft => j_shaft,
            clutchpack_model::PackBody::Drum => j_drum,
        };
        self.pack
            .couplings
            .iter()
            .map(|c| c.period_s(inertia(c.a), inertia(c.b)))
            .fold(f64::INFINITY, f64::min)
    }

    /// Solves the stack's impulses for a step of length `h` from `t` (no-op without a stack):
    /// every other load of the step is known, so each body's mean speed over the step
    /// without the stack is too (`stack.rs`).
    pub(super) fn solve_stack(&mut self, h: f64) {
        if self.stack.is_none() {
            return;
        }
        let bodies = &self.world.physics.bodies;
        let n = self.couplings.len();
        let mut w_pred = vec![0.0; n];
        let mut inv_j = vec![0.0; n];
        for i in 0..n {
            let j = self.bodies[i].inertia_kg_m2;
            inv_j[i] = 1.0 / j;
            w_pred[i] = bodies[self.world.discs[i]].angvel().z
                + (self.shared.loads[i].kick.impulse_component(5, h) + self.teeth_impulse(i, h))
                    / j;
        }
        if let Some(s) = self.stack.as_mut() {
            s.solve(h, &w_pred, &inv_j);
        }
    }

    /// The step length, at most `h`, that lands exactly on the first contact onset or
    /// separation within `h` of any coupling, if one falls in `(tiny, h)`.
    ///
    /// A step's outcome is known before it is taken: the forces are constant over it, so the
    /// relative angle after a step of length `x` is
    /// `phi + dtheta_c(x) - x (w_d + kick(x) a_d)`, `kick(x) = (h_{k-1} + x) / 2`, with `w_d`
    /// rapier's (staggered) disc speed and `a_d` the disc's acceleration from the forces at `t`
    /// (and likewise for an inertial carrier; a prescribed shaft turns by its profile, the
    /// housing not at all). The stack's torque is the one solved for the step `h`. The
    /// engagement depth along it is solved for zero by bracketed secant steps, to 1e-16 m.
    /// Landing a step on each onset and separation keeps the `s^1.5` law's kink at `s = 0`
    /// on step boundaries: within a step the force is smooth and the leapfrog keeps its second
    /// order.
    pub(super) fn landing(&self, h: f64, tiny: f64) -> Option<f64> {
        let bodies = &self.world.physics.bodies;
        // Carrier c's turn after x s: a prescribed one's by its profile, the housing's none,
        // an inertial one's by its speed and kicks (its loads', its external torque's, the
        // teeth's reactions).
        let turn_of = |c: usize, x: f64| {
            let k = &self.carriers[c];
            match &k.motion {
                Motion::Fixed => 0.0,
                Motion::Prescribed(p) => p.angle(self.t + x) - k.angle,
                &Motion::Inertial { j, .. } => {
                    let teeth: f64 = (0..self.couplings.len())
                        .filter(|&i| self.world.carrier_of[i] == c)
                        .map(|i| self.teeth_impulse(i, x))
                        .sum();
                    x * (bodies[self.world.carriers[c].handle].angvel().z
                        + (self.shared.carrier_loads[c].kick.impulse_component(5, x)
                            + self.external_impulse(c, x)
                            - teeth)
                            / j)
                }
            }
        };
        // The carriers' turns over the whole step, computed once (a drum's sums every plate's
        // teeth).
        let turn_h: Vec<f64> = (0..self.carriers.len()).map(|c| turn_of(c, h)).collect();
        let carrier_turn = |i: usize, x: f64| {
            let c = self.world.carrier_of[i];
            if x == h {
                turn_h[c]
            } else {
                turn_of(c, x)
            }
        };
        let mut best: Option<f64> = None;
        for (i, d) in self.bodies.iter().enumerate() {
            let f = &self.forces[i];
            // Landing follows the concentric tooth: with radial play or spacing errors the
            // first tooth to touch is another one.
            if f.gap_margin_m > 0.0 {
                continue;
            }
            let w_d = bodies[self.world.discs[i]].angvel().z;
            let kick = &self.shared.loads[i].kick;
            let j = d.inertia_kg_m2;
            let stack = self.stack_torque(i);
            let g0 = d.spline.half_play_rad();
            let rb = self.couplings[i].base_radius_m();
            let offset = d.law.engagement_offset_m();
            let phi0 = self.rel[i].phi;
            let turn_d = |x: f64| {
                x * (w_d
                    + (kick.impulse_component(5, x) + self.teeth_impulse(i, x) + stack * x) / j)
            };
            let phi = |x: f64| phi0 + carrier_turn(i, x) - turn_d(x);
            let phi_h = phi(h);
            let engaged = f.depth_m > 0.0;
            for flank in crate::hook::FLANKS {
                if engaged && flank != f.kin.flank {
                    continue;
                }
                let sigma = flank.phi_sign();
                let depth = |x: f64| (sigma * phi(x) - g0) * rb + offset;
                let d0 = (sigma * phi0 - g0) * rb + offset;
                let d1 = (sigma * phi_h - g0) * rb + offset;
                let crosses = crate::stepping::crosses_contact(engaged, d0, d1);
                if !crosses {
                    continue;
                }
                let x = crate::stepping::bracketed_root(depth, 0.0, d0, h, d1, 1e-16);
                if x > tiny && best.is_none_or(|b| x < b) {
                    best = Some(x);
                }
            }
        }
        best
    }
}
