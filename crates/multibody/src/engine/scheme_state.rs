//! What each scheme keeps in a run beside the state they share (`state.rs`): the shared
//! step's loads, kicks and teeth's motion ([`SharedStep`], `forces.rs` and `control.rs`), and
//! the multirate schemes' moments of speed, clamped faces and the clamped stack's step
//! buffers ([`MultirateState`], `multirate.rs` and `clamped.rs`).

use super::clamped::RkBuffers;
use super::substep::TurnMoment;
use crate::integrate::{Kick, Load, LoadHistory, Motion};
use crate::stack::Face;

/// The loads of one body (a disc, a plate, an inertial carrier) and their kick
/// (`integrate.rs`).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BodyLoads {
    /// Physical loads at `t` (world frame), leaving out the teeth's torque about the axis,
    /// whose kick is integrated along the step (`Run::teeth_impulse`), and the stack's torque,
    /// solved per step (`stack.rs`).
    pub(super) load: Load,
    /// Their values at the two evaluations before.
    pub(super) history: LoadHistory,
    /// The kick of `load` for the next step.
    pub(super) kick: Kick,
    /// The full loads (teeth included), for the first estimate of the synchronised speed.
    pub(super) full: Load,
    /// Their values at the two evaluations before.
    pub(super) full_history: LoadHistory,
}

/// What only the shared step keeps from one of its steps to the next (`forces.rs`,
/// `control.rs`; the multirate schemes integrate their own sub-steps and read it only at a
/// run's first evaluation, when it holds no history yet): the loads of every body with their
/// histories and kicks, the teeth's motion and the past half of their kick, a prescribed
/// carrier's next angle.
#[derive(Debug, Clone)]
pub(super) struct SharedStep {
    /// The loads of each coupled body, and of each carrier (`Run::carriers` order; written
    /// for the inertial ones).
    pub(super) loads: Vec<BodyLoads>,
    pub(super) carrier_loads: Vec<BodyLoads>,
    /// `(t, phi, dphi, ddphi)` of each coupling at the last evaluation.
    pub(super) prev_motion: Vec<Option<(f64, f64, f64, f64)>>,
    /// The teeth: the past half of their kick (N m s on the body, about the axis) and the
    /// relative motion at `t` for the future half.
    pub(super) teeth_past: Vec<f64>,
    /// The last `(x, teeth_impulse(i, x))` of each coupling since the last evaluation (the
    /// step's impulse is asked for by the stack, the landing and the forces).
    pub(super) teeth_cache: Vec<std::cell::Cell<(f64, f64)>>,
    pub(super) teeth_motion: Vec<Motion>,
    /// Each prescribed carrier's angle at the end of the step being taken, rad (`Run::carriers`
    /// order).
    pub(super) angle_next: Vec<f64>,
}

impl SharedStep {
    /// The state before the first step of a pack with `n` couplings and `n_carriers` carriers.
    pub(super) fn new(n: usize, n_carriers: usize) -> SharedStep {
        SharedStep {
            loads: vec![BodyLoads::default(); n],
            carrier_loads: vec![BodyLoads::default(); n_carriers],
            prev_motion: vec![None; n],
            teeth_past: vec![0.0; n],
            teeth_cache: vec![std::cell::Cell::new((f64::NAN, 0.0)); n],
            teeth_motion: vec![Motion::default(); n],
            angle_next: vec![0.0; n_carriers],
        }
    }
}

/// What only the multirate schemes keep in a run: each body's first moment of speed over the
/// world step being taken (its neighbours' gap drag reads its slope), and the clamped stack's
/// faces in its integration (`clamped.rs`; empty until its first step) with its step's buffers.
/// Written by `multirate.rs` and `clamped.rs`.
#[derive(Debug, Clone)]
pub(super) struct MultirateState {
    pub(super) moments: Vec<TurnMoment>,
    pub(super) faces: Vec<Face>,
    /// The clamped stack's step buffers, kept from one world step to the next.
    pub(super) stack_buffers: Option<RkBuffers>,
}

impl MultirateState {
    /// The state before the first step of a pack with `n` couplings.
    pub(super) fn new(n: usize) -> MultirateState {
        MultirateState {
            moments: vec![TurnMoment::default(); n],
            faces: Vec::new(),
            stack_buffers: None,
        }
    }
}
