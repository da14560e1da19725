//! The energy audit: the work of the drive, the drag, the stack and the load, and the kinetic
//! and contact energies, for conservation checks.

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
