//! What an engine's run of a driveline network gives (MODEL.md section 8), the same types for
//! the reference engine and the multibody engine so that their runs compare field by field:
//! samples of every body's angle and speed and every coupling's torque, the clutches' mode
//! changes, the energy balance, and the observer that receives them in time order.

use super::ClutchMode;
use crate::ImpactEvent;

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

/// What receives a network run's output, in time order.
pub trait NetworkObserver {
    /// A sample at the record rate (and at t = 0 and the end).
    fn sample(&mut self, _sample: &NetworkSample) {}
    /// A clutch changed mode.
    fn clutch_event(&mut self, _event: &ClutchEvent) {}
    /// The state just before and just after an instant where clutches changed mode (sent
    /// before their [`Self::clutch_event`]s): the couplings' torques jump there (the output
    /// torque's step at a lock).
    fn switched(&mut self, _before: &NetworkSample, _after: &NetworkSample) {}
    /// A gear mesh's tooth contact closed (its `disc` is the coupling's index; the peak is
    /// the force per tooth pair, negative when body `a` leads: `x > 0`).
    fn mesh_impact(&mut self, _impact: &ImpactEvent) {}
    /// A tooth contact of a resolved pack's disc or plate closed: `coupling` is the pack's
    /// coupling index, the impact's `disc` the body's index in the pack (its discs, then its
    /// plates), its peak the per-tooth load as the pack engines sign it.
    fn pack_impact(&mut self, _coupling: usize, _impact: &ImpactEvent) {}
    /// A resolved pack's discs and plates at a sample's instant `t_s` (s), sent after the
    /// [`Self::sample`] of that instant: each body's absolute angle (rad), speed (rad/s) and
    /// per-tooth load (N, signed as in Hu et al. eq (6): negative when its carrier leads),
    /// its discs then its plates.
    fn pack_sample(
        &mut self,
        _coupling: usize,
        _t_s: f64,
        _angle_rad: &[f64],
        _speed_rad_s: &[f64],
        _load_n: &[f64],
    ) {
    }
    /// A thermal resolved pack's temperatures at `t_s` (s), K: its discs', then its plates',
    /// then its oil's; at t = 0 and at the end of each thermal window (MODEL.md section 9).
    fn pack_temperatures(&mut self, _coupling: usize, _t_s: f64, _temperatures_k: &[f64]) {}
    /// A resolved pack's faces changed mode at `t_s` (s): `locked` of its `faces` friction
    /// faces are locked now (all of them: the pack has locked, its carriers turn as one but
    /// for the splines' play), `clamped` are clamped (locked or slipping).
    fn pack_faces(
        &mut self,
        _coupling: usize,
        _t_s: f64,
        _locked: usize,
        _clamped: usize,
        _faces: usize,
    ) {
    }
    /// Whether it wants the tooth contacts open at `t_s` (s, the end of an accepted step)
    /// through [`Self::open_contacts`]: asked after every step, so it answers cheaply; no by
    /// default.
    fn wants_open_contacts(&mut self, _t_s: f64) -> bool {
        false
    }
    /// The tooth contacts open at `t_s` (s), when [`Self::wants_open_contacts`] asked: each as
    /// `(coupling, body in a pack, event)`, the event as it would close at `t_s` (its onset,
    /// its peak located so far, `t_off_s = t_s`), as [`Self::mesh_impact`] (`body` `None`)
    /// and [`Self::pack_impact`] give closed ones. A contact stays open for seconds where a
    /// locked pack's teeth carry its torque: what a run cut short would otherwise lose.
    fn open_contacts(&mut self, _t_s: f64, _open: &[(usize, Option<usize>, ImpactEvent)]) {}
    /// Polled after every step with the time reached, s; `false` stops the run there.
    fn progress(&mut self, _t_s: f64) -> bool {
        true
    }
}

/// Ignores everything.
impl NetworkObserver for () {}

/// A network run advanced call by call, on either engine (both engines' `NetworkStepper`s
/// implement it with the same semantics, MODEL.md section 8, "Inputs"): what a caller that
/// does not care which engine runs the network holds, boxed.
pub trait NetworkSession: Send {
    /// The time the run stands at, s.
    fn time_s(&self) -> f64;

    /// The network as run (the inputs set so far in place of the scene's signals).
    fn network(&self) -> &super::Network;

    /// The state now (angles rad, speeds rad/s, torques N m, modes), at the session's time.
    fn sample_now(&mut self) -> NetworkSample;

    /// The temperatures of the thermal resolved pack that is coupling `k`, K (its discs',
    /// plates', then oil's; `None` for another coupling).
    fn pack_temperatures_k(&self, k: usize) -> Option<&[f64]>;

    /// Each coupling's heat (a mesh's work, a damper's loss) since t = 0, J.
    fn heat_j(&self) -> Vec<f64>;

    /// Sets `input` to `value` (N m, N or Pa), held from now on; a refused value leaves the
    /// run's inputs as they were.
    fn set_input(
        &mut self,
        input: super::NetworkInput,
        value: f64,
        obs: &mut dyn NetworkObserver,
    ) -> Result<(), crate::EngineError>;

    /// Advances to `t_end` s (at most the run's end).
    fn advance_to(
        &mut self,
        t_end: f64,
        obs: &mut dyn NetworkObserver,
    ) -> Result<(), crate::EngineError>;

    /// Ends the run where it stands: its last sample, heat, energy balance and counts.
    fn finish_boxed(self: Box<Self>, obs: &mut dyn NetworkObserver) -> NetworkRun;

    /// A copy of the whole run (a saved state).
    fn boxed_clone(&self) -> Box<dyn NetworkSession>;
}
