//! What an engine's run of a driveline network gives (MODEL.md section 8), the same types for
//! the reference engine and the multibody engine so that their runs compare field by field:
//! samples of every body's angle and speed and every coupling's torque, the clutches' mode
//! changes and the energy balance (the one observer that receives them in time order is
//! [`crate::Observer`], the network's session trait `crate::session::NetworkSession`).

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
    /// `lambda`, `-ratio lambda` on `b`; a gear mesh's `-Rb_a F pairs`; a spring-damper's
    /// `-T`).
    pub torque_n_m: Vec<f64>,
    /// Each clutch's mode (`None` for another kind of coupling).
    pub mode: Vec<Option<ClutchMode>>,
    /// Each prescribed body's reaction, N m, positive in its sense of rotation: the torque
    /// its drive puts on it to keep its profile against every coupling on it (its inertia
    /// infinite: [`super::Motion::Prescribed`]); 0 for the other bodies. Empty when the
    /// network has no prescribed body.
    pub reaction_n_m: Vec<f64>,
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
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct NetworkEnergy {
    /// Work of the drives, J.
    pub drive_work_j: f64,
    /// Work of the road loads (<= 0), J.
    pub load_work_j: f64,
    /// Loss to the bodies' drag (>= 0), J.
    pub drag_loss_j: f64,
    /// Heat of the clutches (>= 0), J.
    pub clutch_heat_j: f64,
    /// Work done on the gear meshes, J: their teeth's impact losses, plus the elastic energy
    /// of a contact still closed at the end.
    pub mesh_work_j: f64,
    /// Loss to the spring-dampers' dampers (>= 0), J.
    pub damper_loss_j: f64,
    /// The spring-dampers' stored energy at the end less at the start, J.
    pub spring_energy_change_j: f64,
    /// What the resolved packs took (>= 0 but for a contact's elastic energy), J: their
    /// faces' heat, their teeth's work (impact losses, plus the elastic energy of a contact
    /// still closed at the end) and their discs' and plates' oil drag.
    pub pack_loss_j: f64,
    /// Kinetic energy at the end less at the start (the packs' discs and plates with the
    /// bodies), J.
    pub kinetic_change_j: f64,
    /// Work of the prescribed bodies' reactions, J: what keeping their profiles put in
    /// (`integral R w dt`, [`NetworkSample::reaction_n_m`]; absent from the JSON without a
    /// prescribed body).
    #[serde(skip_serializing_if = "is_zero")]
    pub prescribed_work_j: f64,
}

/// Whether `x` is 0 (a field left out of the JSON).
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl NetworkEnergy {
    /// `drive + prescribed + load - drag - heat - mesh work - damper loss - spring energy
    /// change - pack loss - kinetic change`, J: zero to the integrator's tolerance.
    pub fn residual_j(&self) -> f64 {
        self.drive_work_j + self.prescribed_work_j + self.load_work_j
            - self.drag_loss_j
            - self.clutch_heat_j
            - self.mesh_work_j
            - self.damper_loss_j
            - self.spring_energy_change_j
            - self.pack_loss_j
            - self.kinetic_change_j
    }
}

/// What a network run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkRun {
    /// The state at the end.
    pub last: NetworkSample,
    /// Each clutch's heat, each gear mesh's work and each damper's loss, J (0 for an ideal
    /// gear).
    pub heat_j: Vec<f64>,
    /// The energy balance.
    pub energy: NetworkEnergy,
    /// Accepted steps.
    pub steps: u64,
    /// Events located (mode changes and breakpoints).
    pub events: u64,
    /// Each thermal resolved pack's temperatures and heat over the run (MODEL.md section 9),
    /// by coupling index, in coupling order.
    pub pack_thermal: Vec<(usize, crate::thermal::ThermalReport)>,
}
