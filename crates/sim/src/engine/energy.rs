//! The energy audit: the work of the drive, the drag, the stack and the load, and the kinetic
//! and contact energies, for conservation checks.

use super::state::{Run, ShaftDrive};
use crate::world::Carrier;

/// Energy bookkeeping of a run (J), for conservation checks: with no drag and `p = 0`,
/// `drive_work_j + drag_work_j + stack_work_j + load_work_j = (kinetic_j +
/// contact_potential_j) - (initial_kinetic_j + initial_contact_potential_j)` up to the
/// integrator's error.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyAudit {
    /// Work done by the drive since t = 0: for a prescribed shaft the work of the shaft on the
    /// teeth, the teeth's torque on the discs (those on the shaft) integrated over the shaft's
    /// turn; for an
    /// inertial shaft the work of the drive torque on the shaft (trapezoidal rule per step).
    pub drive_work_j: f64,
    /// Work of the oil drag on the discs and plates, of the shaft damping and of the drum's
    /// drag (<= 0).
    pub drag_work_j: f64,
    /// Work of the stack on the discs and plates: face friction and open-gap drag (<= 0),
    /// `sum Q (w_upper - w_lower)` per step with the step's mean speeds.
    pub stack_work_j: f64,
    /// Work of the drum's load torque (trapezoidal rule per step).
    pub load_work_j: f64,
    /// Kinetic energy at t = 0: the discs and plates, and the shaft and the drum when they are
    /// inertial.
    pub initial_kinetic_j: f64,
    /// Kinetic energy at the end of the run.
    pub kinetic_j: f64,
    /// Energy stored in the teeth at t = 0, `sum (2/5) K s^2.5` (a potential for `p = 0`).
    pub initial_contact_potential_j: f64,
    /// Energy stored in the teeth at the end of the run.
    pub contact_potential_j: f64,
}

/// Powers at one evaluation, for the trapezoidal energy audit.
#[derive(Debug, Clone, Copy)]
pub(super) struct Powers {
    pub(super) t: f64,
    pub(super) theta_s: f64,
    /// Sum of the teeth's torques on the discs, N m (prescribed shaft: work = torque x turn).
    pub(super) spline_torque: f64,
    /// Power of the drive torque on an inertial shaft, W.
    pub(super) drive: f64,
    /// Power of the drag, the shaft damping and the drum's drag, W.
    pub(super) drag: f64,
    /// Power of the drum's load torque, W.
    pub(super) load: f64,
}

impl Run<'_> {
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
                self.pack.shaft.drive_torque_n_m(self.t) * self.omega_s,
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
        let now = Powers {
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
        };
        if let Some(b) = self.powers_before {
            let h = now.t - b.t;
            self.energy.drive_work_j += match self.shaft {
                ShaftDrive::Prescribed(_) => {
                    0.5 * (b.spline_torque + now.spline_torque) * (now.theta_s - b.theta_s)
                }
                ShaftDrive::Inertial { .. } => 0.5 * (b.drive + now.drive) * h,
            };
            self.energy.drag_work_j += 0.5 * (b.drag + now.drag) * h;
            self.energy.load_work_j += 0.5 * (b.load + now.load) * h;
        }
        self.powers_before = Some(now);
    }
}
