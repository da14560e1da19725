//! What an engine's run of a driveline network gives (MODEL.md section 8), the same types for
//! the reference engine and the multibody engine so that their runs compare field by field:
//! samples of every body's angle and speed and every coupling's torque, the clutches' mode
//! changes, the energy balance, and the observer that receives them in time order.

use super::ClutchMode;

/// The network's state at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkSample {
    /// Time, s.
    pub t_s: f64,
    /// Each body's angle, rad.
    pub angle_rad: Vec<f64>,
    /// Each body's speed, rad/s.
    pub speed_rad_s: Vec<f64>,
    /// Each coupling's torque on its body `a`, N m (a clutch's `tau`; an ideal gear's
    /// `lambda`, `-ratio lambda` on `b`).
    pub torque_n_m: Vec<f64>,
    /// Each clutch's mode (`None` for another kind of coupling).
    pub mode: Vec<Option<ClutchMode>>,
}

/// A clutch changing mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClutchEvent {
    /// Time, s.
    pub t_s: f64,
    /// Index of the coupling.
    pub coupling: usize,
    /// Mode before.
    pub from: ClutchMode,
    /// Mode after.
    pub to: ClutchMode,
}

/// Where the energy went over a run, J (MODEL.md section 8, "Energy").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NetworkEnergy {
    /// Work of the drives, J.
    pub drive_work_j: f64,
    /// Work of the road loads (<= 0), J.
    pub load_work_j: f64,
    /// Loss to the bodies' drag (>= 0), J.
    pub drag_loss_j: f64,
    /// Heat of the clutches (>= 0), J.
    pub clutch_heat_j: f64,
    /// Kinetic energy at the end less at the start, J.
    pub kinetic_change_j: f64,
}

impl NetworkEnergy {
    /// `drive + load - drag - heat - kinetic change`, J: zero to the integrator's tolerance.
    pub fn residual_j(&self) -> f64 {
        self.drive_work_j + self.load_work_j
            - self.drag_loss_j
            - self.clutch_heat_j
            - self.kinetic_change_j
    }
}

/// What a network run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkRun {
    /// The state at the end.
    pub last: NetworkSample,
    /// Each clutch's heat, J (0 for other couplings).
    pub heat_j: Vec<f64>,
    /// The energy balance.
    pub energy: NetworkEnergy,
    /// Accepted steps.
    pub steps: u64,
    /// Events located (mode changes and breakpoints).
    pub events: u64,
}

/// What receives a network run's output, in time order.
pub trait NetworkObserver {
    /// A sample at the record rate (and at t = 0 and the end).
    fn sample(&mut self, _sample: &NetworkSample) {}
    /// A clutch changed mode.
    fn clutch_event(&mut self, _event: &ClutchEvent) {}
    /// Polled after every step with the time reached, s; `false` stops the run there.
    fn progress(&mut self, _t_s: f64) -> bool {
        true
    }
}

/// Ignores everything.
impl NetworkObserver for () {}
