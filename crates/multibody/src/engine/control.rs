//! Step control: the step each coupling allows, the stack's impulses for a step, and the
//! landing of steps on contact onsets and separations.

use super::state::{Run, ShaftDrive};
use crate::options::AdaptiveStepping;
use crate::stepping::{coupling_step, CouplingView};
use crate::world::Carrier;

impl Run {
    /// What the step controller ([`coupling_step`]) reads of coupling `i` at `t` (s): its
    /// evaluated `forces`, its relative angle and speed `rel` (rad, rad/s), and the bound
    /// of `|d dphi / dt|` in free flight `accel_bound` (rad/s^2), taken 1 % over (rounding
    /// must not make it optimistic).
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
        let a_shaft = match self.shaft {
            ShaftDrive::Prescribed(_) => self.shaft_accel_bound,
            ShaftDrive::Inertial { j1, c1 } => {
                // The drive, the damping, and the teeth's reactions at t (contacts elsewhere
                // in the pack jolt the shaft).
                let reaction: f64 = self
                    .forces
                    .iter()
                    .zip(&self.world.carriers)
                    .filter(|(_, c)| **c == Carrier::Shaft)
                    .map(|(f, _)| f.moment[2].abs())
                    .sum();
                self.shaft_accel_bound + (c1 * self.omega_s.abs() + reaction) / j1
            }
        };
        let a_drum = match &self.drum {
            Some(d) => {
                let reaction: f64 = self
                    .forces
                    .iter()
                    .zip(&self.world.carriers)
                    .filter(|(_, c)| **c == Carrier::Drum)
                    .map(|(f, _)| f.moment[2].abs())
                    .sum();
                (d.model.load_torque_n_m.abs() + d.model.drag_n_m_s_rad * d.omega.abs() + reaction)
                    / d.model.inertia_kg_m2
            }
            None => 0.0,
        };
        let mut want = a.max_step_s;
        let (mut a_shaft, mut a_drum) = (a_shaft, a_drum);
        if !self.pack.couplings.is_empty() {
            // the couplings' torques jolt the shaft and the drum too; and their free
            // oscillation is resolved like a contact (MODEL.md section 8)
            let c = self.coupling_loads();
            if let ShaftDrive::Inertial { j1, .. } = self.shaft {
                a_shaft += c.shaft_n_m.abs() / j1;
            }
            if let Some(d) = &self.drum {
                a_drum += c.drum_n_m.abs() / d.model.inertia_kg_m2;
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
            let a_carrier = match self.world.carriers[i] {
                Carrier::Shaft => a_shaft,
                Carrier::Drum => a_drum,
                Carrier::Housing => 0.0,
            };
            let rel = self.rel[i];
            let view = self.coupling_view(
                i,
                &self.forces[i],
                (rel.phi, rel.dphi),
                a_carrier + a_disc,
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
        let j_shaft = match self.shaft {
            ShaftDrive::Inertial { j1, .. } => j1,
            ShaftDrive::Prescribed(_) => f64::INFINITY,
        };
        let j_drum = self
            .drum
            .as_ref()
            .map_or(f64::INFINITY, |d| d.model.inertia_kg_m2);
        let inertia = |b| match b {
            clutchpack_model::PackBody::Shaft => j_shaft,
            clutchpack_model::PackBody::Drum => j_drum,
        };
        self.pack
            .couplings
            .iter()
            .map(|c| match &c.kind {
                clutchpack_model::PackCouplingKind::SpringDamper(s) => {
                    2.0 * std::f64::consts::PI
                        / s.natural_frequency_rad_s(inertia(c.a), inertia(c.b))
                }
            })
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
        let theta_s0 = match self.shaft {
            ShaftDrive::Prescribed(_) => self.theta_s,
            ShaftDrive::Inertial { .. } => 0.0,
        };
        let w_s = bodies[self.world.shaft].angvel().z;
        let shaft_turn = |x: f64| match &self.shaft {
            ShaftDrive::Prescribed(p) => p.angle(self.t + x) - theta_s0,
            &ShaftDrive::Inertial { j1, .. } => {
                let teeth: f64 = (0..self.couplings.len())
                    .filter(|&i| self.world.carriers[i] == Carrier::Shaft)
                    .map(|i| self.teeth_impulse(i, x))
                    .sum();
                x * (w_s
                    + (self.shared.shaft_loads.kick.impulse_component(5, x)
                        + self.drive_impulse(x)
                        - teeth)
                        / j1)
            }
        };
        let drum_turn = |x: f64| match (&self.drum, self.world.drum) {
            (Some(d), Some(hd)) => {
                let teeth: f64 = (0..self.couplings.len())
                    .filter(|&i| self.world.carriers[i] == Carrier::Drum)
                    .map(|i| self.teeth_impulse(i, x))
                    .sum();
                x * (bodies[hd].angvel().z
                    + (self.shared.drum_loads.kick.impulse_component(5, x)
                        + self.drum_load_impulse(x)
                        - teeth)
                        / d.model.inertia_kg_m2)
            }
            _ => 0.0,
        };
        // The carriers' turns over the whole step, computed once (a drum's sums every plate's
        // teeth).
        let (shaft_turn_h, drum_turn_h) = (shaft_turn(h), drum_turn(h));
        let carrier_turn = |i: usize, x: f64| match self.world.carriers[i] {
            Carrier::Shaft if x == h => shaft_turn_h,
            Carrier::Drum if x == h => drum_turn_h,
            Carrier::Shaft => shaft_turn(x),
            Carrier::Drum => drum_turn(x),
            Carrier::Housing => 0.0,
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
