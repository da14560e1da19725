//! What a run reports from its state as it goes: the impact events and contact samples of
//! each coupling (with its `EventBook`) and the energy audit (with its `EnergyBook`). The run's
//! state (`state.rs`) holds the trackers and the audit; the bookkeeping types know nothing of
//! the run.

use super::energy::Powers;

use super::carriers::{External, Motion};
use super::state::Run;
use crate::stepping::contact_duration_s;
use crate::world::SHAFT;
use clutchpack_model::Observer;

impl Run {
    /// Feeds the impact trackers with the state at `t` and sends the impacts that closed and
    /// the contact samples due: a new event's step its predicted duration over
    /// `steps_per_contact`, or over `alone_steps_per_contact` for a coupling on a carrier of
    /// known motion (the multirate scheme's couplings alone, `AdaptiveStepping::alone`; the
    /// same count for the shared step).
    pub(super) fn track_events(
        &mut self,
        steps_per_contact: f64,
        alone_steps_per_contact: f64,
        observer: &mut dyn Observer,
    ) {
        for i in 0..self.couplings.len() {
            let steps_per_contact = if self.carriers[self.world.carrier_of[i]].is_inertial() {
                steps_per_contact
            } else {
                alone_steps_per_contact
            };
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
        for k in &self.carriers {
            if let Motion::Inertial { j, .. } = k.motion {
                e += 0.5 * j * k.speed * k.speed;
            }
        }
        e
    }

    /// Adds the work done since the last evaluation (trapezoidal rule) to the energy audit.
    pub(super) fn audit_energy(&mut self) {
        let mut drag: f64 = self
            .bodies
            .iter()
            .zip(&self.omega_d)
            .map(|(d, w)| -d.drag_n_m_s_rad * w * w)
            .sum();
        // each carrier's damping power and its external torque's (the drive's, a load's):
        // none for a carrier that is not a body of its own
        let (mut drive, mut load) = (None, None);
        for (c, k) in self.carriers.iter().enumerate() {
            let (external, damping) = match k.motion {
                Motion::Inertial { damping, .. } => (
                    self.external_at(c, self.t) * k.speed,
                    -damping * k.speed * k.speed,
                ),
                _ => (0.0, 0.0),
            };
            drag += damping;
            let book = match k.external {
                External::Drive => &mut drive,
                External::Load(_) => &mut load,
                External::None => continue,
            };
            *book = Some(book.map_or(external, |p: f64| p + external));
        }
        let mut now = Powers {
            t: self.t,
            theta_s: self.carriers[SHAFT].angle,
            spline_torque: self
                .forces
                .iter()
                .zip(&self.world.carrier_of)
                .filter(|(_, &c)| c == SHAFT)
                .map(|(f, _)| f.moment[2])
                .sum(),
            drive: drive.unwrap_or(0.0),
            drag,
            load: load.unwrap_or(0.0),
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
        let prescribed = matches!(self.carriers[SHAFT].motion, Motion::Prescribed(_));
        self.energy.add_powers(now, prescribed);
    }
}
