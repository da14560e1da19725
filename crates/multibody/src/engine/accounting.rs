//! What a run reports from its state as it goes: the impact events and contact samples of
//! each coupling (with its `EventBook`) and the energy audit (with its `EnergyBook`). The run's
//! state (`state.rs`) holds the trackers and the audit; the bookkeeping types know nothing of
//! the run.

use super::energy::Powers;

use super::state::{Run, ShaftDrive};
use crate::stepping::contact_duration_s;
use crate::world::Carrier;
use clutchpack_model::Observer;

impl Run {
    /// Feeds the impact trackers with the state at `t` and sends the impacts that closed and
    /// the contact samples due.
    pub(super) fn track_events(&mut self, steps_per_contact: f64, observer: &mut dyn Observer) {
        for i in 0..self.couplings.len() {
            let law = &self.bodies[i].law;
            let f = &self.forces[i];
            let m = self.m_eff[i];
            let step = |v| contact_duration_s(law, f.kin.flank, v, m) / steps_per_contact;
            let tracked = self.events.update(i, self.t, f, steps_per_contact, step);
            if let Some(e) = &tracked.closed {
                observer.impact(e);
            }
            if let Some(t) = tracked.contact_sample_at {
                observer.contact_sample(i, t, &self.disc_sample(i, false));
            }
        }
    }
}

impl Run {
    /// Kinetic energy of the discs, the plates (and of an inertial shaft and the drum) at
    /// `t`, J: `sum J w^2 / 2` with the synchronised speeds, plus `m v^2 / 2` of the bodies'
    /// centres (rapier's speed over the last step: zero for a concentric body, whose joint
    /// locks every other motion).
    pub(super) fn kinetic_energy(&self) -> f64 {
        let bodies = &self.world.physics.bodies;
        let mut e: f64 = self
            .bodies
            .iter()
            .zip(&self.omega_d)
            .zip(&self.world.discs)
            .map(|((d, w), &h)| {
                let b = &bodies[h];
                0.5 * d.inertia_kg_m2 * w * w + 0.5 * b.mass() * b.linvel().length_squared()
            })
            .sum();
        if let ShaftDrive::Inertial { j1, .. } = self.shaft {
            e += 0.5 * j1 * self.omega_s * self.omega_s;
        }
        if let Some(d) = &self.drum {
            e += 0.5 * d.model.inertia_kg_m2 * d.omega * d.omega;
        }
        e
    }

    /// Adds the work done since the last evaluation (trapezoidal rule) to the energy audit.
    pub(super) fn audit_energy(&mut self) {
        let (drive, shaft_damping) = match self.shaft {
            ShaftDrive::Prescribed(_) => (0.0, 0.0),
            ShaftDrive::Inertial { c1, .. } => (
                self.drive_torque(self.t) * self.omega_s,
                -c1 * self.omega_s * self.omega_s,
            ),
        };
        let drag: f64 = self
            .bodies
            .iter()
            .zip(&self.omega_d)
            .map(|(d, w)| -d.drag_n_m_s_rad * w * w)
            .sum();
        let (drum_drag, load) = match &self.drum {
            Some(d) => (
                -d.model.drag_n_m_s_rad * d.omega * d.omega,
                d.model.load_torque_n_m * d.omega,
            ),
            None => (0.0, 0.0),
        };
        let mut now = Powers {
            t: self.t,
            theta_s: self.theta_s,
            spline_torque: self
                .forces
                .iter()
                .zip(&self.world.carriers)
                .filter(|(_, c)| **c == Carrier::Shaft)
                .map(|(f, _)| f.moment[2])
                .sum(),
            drive,
            drag: drag + shaft_damping + drum_drag,
            load,
            coupling_loss: 0.0,
            coupling_potential_j: 0.0,
        };
        if !self.pack.couplings.is_empty() {
            // MODEL.md section 8: a prescribed shaft also works on the couplings (it exerts
            // the opposite of their torque on it); they store and lose energy
            let c = self.coupling_loads();
            now.spline_torque -= c.shaft_n_m;
            now.coupling_loss = -c.loss_rate_w;
            now.coupling_potential_j = c.potential_j;
        }
        let prescribed = matches!(self.shaft, ShaftDrive::Prescribed(_));
        self.energy.add_powers(now, prescribed);
    }
}
