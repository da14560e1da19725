//! The energy audit: the work of the drive, the drag, the stack and the load, and the kinetic
//! and contact energies, for conservation checks.

/// Energy bookkeeping of a run (J), for conservation checks: with no drag and `p = 0`,
/// `drive_work_j + drag_work_j + stack_work_j + load_work_j + coupling_work_j = (kinetic_j +
/// contact_potential_j + coupling_potential_j) - (initial_kinetic_j +
/// initial_contact_potential_j + initial_coupling_potential_j)` up to the integrator's error.
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
    /// Work of the dampers of the pack's couplings between the shaft and the drum (MODEL.md
    /// section 8), `-sum d (omega_a - omega_b)^2` integrated by the trapezoidal rule per
    /// step (<= 0; 0 without couplings).
    pub coupling_work_j: f64,
    /// Energy stored in the couplings' springs at t = 0, `sum k (dtheta - theta_0)^2 / 2`.
    pub initial_coupling_potential_j: f64,
    /// Energy stored in the couplings' springs at the end of the run.
    pub coupling_potential_j: f64,
}

impl EnergyAudit {
    /// The change of the kinetic and elastic energy since t = 0, J.
    pub fn energy_change_j(&self) -> f64 {
        self.kinetic_j + self.contact_potential_j + self.coupling_potential_j
            - self.initial_kinetic_j
            - self.initial_contact_potential_j
            - self.initial_coupling_potential_j
    }

    /// The work of everything outside the bodies and the teeth since t = 0 (drive, drag,
    /// stack, load), J: equal to [`Self::energy_change_j`] up to the integration error.
    pub fn work_j(&self) -> f64 {
        self.drive_work_j
            + self.drag_work_j
            + self.stack_work_j
            + self.load_work_j
            + self.coupling_work_j
    }
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
    /// Power of the couplings' dampers, W (<= 0).
    pub(super) coupling_loss: f64,
    /// Energy stored in the couplings' springs, J.
    pub(super) coupling_potential_j: f64,
}

/// The energy audit of a run as it goes, the one place that writes it: the work of the
/// drive, the drag, the load (trapezoidal over the evaluations, [`EnergyBook::add_powers`]),
/// of the stack and of the multirate sub-steps, and the energies at the start and the end.
#[derive(Debug, Clone, Default)]
pub(super) struct EnergyBook {
    audit: EnergyAudit,
    /// Powers at the last evaluation.
    before: Option<Powers>,
}

impl EnergyBook {
    /// Adds the work since the last evaluation, from its powers and `now`'s (trapezoidal
    /// rule); for a prescribed shaft (`prescribed`) the drive's work is the teeth's torque
    /// times the shaft's turn.
    pub(super) fn add_powers(&mut self, now: Powers, prescribed: bool) {
        if let Some(b) = self.before {
            let h = now.t - b.t;
            self.audit.drive_work_j += if prescribed {
                0.5 * (b.spline_torque + now.spline_torque) * (now.theta_s - b.theta_s)
            } else {
                0.5 * (b.drive + now.drive) * h
            };
            self.audit.drag_work_j += 0.5 * (b.drag + now.drag) * h;
            self.audit.load_work_j += 0.5 * (b.load + now.load) * h;
            self.audit.coupling_work_j += 0.5 * (b.coupling_loss + now.coupling_loss) * h;
        } else {
            self.audit.initial_coupling_potential_j = now.coupling_potential_j;
        }
        self.audit.coupling_potential_j = now.coupling_potential_j;
        self.before = Some(now);
    }

    /// Adds the stack's work over a step, J.
    pub(super) fn add_stack_work(&mut self, work_j: f64) {
        self.audit.stack_work_j += work_j;
    }

    /// Adds a multirate sub-step's work of the drive and of the drag, J.
    pub(super) fn add_sub_step(&mut self, drive_j: f64, drag_j: f64) {
        self.audit.drive_work_j += drive_j;
        self.audit.drag_work_j += drag_j;
    }

    /// Adds a multirate sub-step's work of the drum's load, J.
    pub(super) fn add_load_work(&mut self, load_j: f64) {
        self.audit.load_work_j += load_j;
    }

    /// The audit so far: the works up to the last evaluation or sub-step, J (the energies at
    /// the end are set by [`Self::finish`]).
    pub(super) fn so_far(&self) -> &EnergyAudit {
        &self.audit
    }

    /// The energies at t = 0: the teeth's potential and the kinetic energy, J.
    pub(super) fn start(&mut self, contact_potential_j: f64, kinetic_j: f64) {
        self.audit.initial_contact_potential_j = contact_potential_j;
        self.audit.initial_kinetic_j = kinetic_j;
    }

    /// The audit, with the energies at the end of the run, J.
    pub(super) fn finish(&mut self, contact_potential_j: f64, kinetic_j: f64) -> EnergyAudit {
        self.audit.contact_potential_j = contact_potential_j;
        self.audit.kinetic_j = kinetic_j;
        self.audit
    }
}
