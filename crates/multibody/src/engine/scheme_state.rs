//! What each scheme keeps in a run beside the state they share (`state.rs`): the shared
//! step's loads, kicks and teeth's motion ([`SharedStep`], `forces.rs` and `control.rs`), and
//! the multirate schemes' moments of speed, clamped faces and the clamped stack's step
//! buffers ([`MultirateState`], `multirate.rs` and `clamped.rs`). The buffers' types
//! ([`RkBuffers`], [`Stage`], [`StackStep`]) live here rather than in `clamped.rs`, which
//! fills them: `clamped.rs` steps a `Run` (`state.rs`), whose state holds this one, so
//! keeping them there made `state.rs` -> `scheme_state.rs` -> `clamped.rs` -> `state.rs` an
//! import cycle.

use super::substep::{GapDrag, Node, Rk4, TurnMoment};
use crate::integrate::{Kick, Load, LoadHistory, Motion};
use crate::stack::Face;
use clutchpack_model::{DiscSample, ImpactEvent, InterfaceSample, LocalProfile, Sample};

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
    /// The open scheme's per-step buffers (`multirate.rs`), kept so that a world step does
    /// not allocate (issue 46: a real-time host's frame loop).
    pub(super) open: OpenStepBuffers,
}

/// The buffers of one open multirate world step (`Run::multirate_step`), cleared and filled
/// at every step: their contents never outlive it.
#[derive(Debug, Clone, Default)]
pub(super) struct OpenStepBuffers {
    /// The open gaps' drag on each coupling body.
    pub(super) gaps: Vec<GapDrag>,
    /// Per coupling body: zeros, the neighbours' speeds (rad/s) and slopes (rad/s^2) the
    /// gaps' drag reads, and each body's mean speed over the step (rad/s).
    pub(super) zero: Vec<f64>,
    pub(super) w: Vec<f64>,
    pub(super) slope: Vec<f64>,
    pub(super) means: Vec<f64>,
    /// The inertial carriers of the step with their nodes at its start and end.
    pub(super) carriers: Vec<(usize, Node, Node)>,
    /// The inertial carriers of a group, in table order.
    pub(super) inertial: Vec<usize>,
    /// Each prescribed carrier's (index, angle rad, speed rad/s) at the step's end.
    pub(super) prescribed: Vec<(usize, f64, f64)>,
}

impl MultirateState {
    /// The state before the first step of a pack with `n` couplings.
    pub(super) fn new(n: usize) -> MultirateState {
        MultirateState {
            moments: vec![TurnMoment::default(); n],
            faces: Vec::new(),
            stack_buffers: None,
            open: OpenStepBuffers::default(),
        }
    }
}

/// What the system does at one stage.
#[derive(Debug, Clone)]
pub(super) struct Stage {
    /// Each coupling body's acceleration, rad/s^2, and the inertial carriers'
    /// (`System::spins` order, `clamped.rs`).
    pub(super) acc: Vec<f64>,
    pub(super) acc_carrier: Vec<f64>,
    /// The teeth's torque on each coupling body, N m.
    pub(super) teeth: Vec<f64>,
    /// Each interface's torque on its upper body, N m: friction or the gap's drag of a
    /// slipping or open face, the holding torque of a locked one.
    pub(super) face: Vec<f64>,
    /// Each interface's clamp force, N.
    pub(super) clamp: Vec<f64>,
    /// Each stack position's torque, N m (scratch).
    pub(super) torque: Vec<f64>,
    /// The inertial carriers' external torques (`System::spins` order, `clamped.rs`): the drive
    /// on an inertial shaft (eq 4), the drum's load, N m.
    pub(super) external: Vec<f64>,
}

impl Stage {
    /// A stage's buffers for `n` coupling bodies and `n_spin` inertial carriers.
    pub(super) fn new(n: usize, n_spin: usize) -> Stage {
        let n_if = n - 1;
        Stage {
            acc: vec![0.0; n],
            acc_carrier: vec![0.0; n_spin],
            teeth: vec![0.0; n],
            face: vec![0.0; n_if],
            clamp: vec![0.0; n_if],
            torque: vec![0.0; n],
            external: vec![0.0; n_spin],
        }
    }
}

/// One classical Runge-Kutta step of the clamped stack (`Run::stack_step`, `clamped.rs`).
#[derive(Debug, Clone)]
pub(super) struct StackStep {
    /// Each coupling body's turn, rad, speed at the end, rad/s, and relative angle at the end.
    pub(super) turn: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) phi: Vec<f64>,
    /// The inertial carriers' turns, rad, and speeds at the end, rad/s (`System::spins` order,
    /// `clamped.rs`).
    pub(super) carrier_turn: Vec<f64>,
    pub(super) w_carrier: Vec<f64>,
    /// Each interface's impulse on its upper body, N m s, and the work of its torque on the
    /// slip (friction, the gap's drag; 0 locked), J (<= 0).
    pub(super) impulse: Vec<f64>,
    pub(super) face_j: Vec<f64>,
    /// The part of `face_j` done while clamped (the stages with a clamp force `> 0`), J.
    pub(super) friction_j: Vec<f64>,
    /// Work of the drive (a prescribed shaft's on the discs' teeth, an inertial shaft's drive
    /// torque, eq 4), of the drag (bodies, the carriers' damping) and of the drum's load, J.
    pub(super) drive_j: f64,
    pub(super) drag_j: f64,
    pub(super) load_j: f64,
}

/// The buffers of `Run::stack_step` (`clamped.rs`), reused along the sub-steps (a step
/// allocating its stages was a fifth of the clamped stack's time, perf) and from one world
/// step to the next (`MultirateState::stack_buffers`: the memory stays where the caches have
/// it).
#[derive(Debug, Clone)]
pub(super) struct RkBuffers {
    /// The stages 2, 3 and 4.
    pub(super) k: [Stage; 3],
    /// The step of the bodies (coupling order) and the inertial carriers after them, with
    /// their powers ([`powers`]), and their speeds at its start.
    pub(super) rk: Rk4<Vec<f64>, Vec<f64>>,
    pub(super) x0: Vec<f64>,
    pub(super) out: StackStep,
}

impl RkBuffers {
    /// Whether these are the buffers for `n` coupling bodies and `n_spin` inertial carriers.
    pub(super) fn fits(&self, n: usize, n_spin: usize) -> bool {
        self.out.u.len() == n && self.out.w_carrier.len() == n_spin
    }

    /// The buffers for `n` coupling bodies and `n_spin` inertial carriers.
    pub(super) fn new(n: usize, n_spin: usize) -> RkBuffers {
        let v = || vec![0.0; n];
        let c = || vec![0.0; n_spin];
        RkBuffers {
            k: [
                Stage::new(n, n_spin),
                Stage::new(n, n_spin),
                Stage::new(n, n_spin),
            ],
            rk: Rk4::new(n + n_spin, powers(n, n_spin, n - 1).iter().sum()),
            x0: vec![0.0; n + n_spin],
            out: StackStep {
                turn: v(),
                u: v(),
                phi: v(),
                carrier_turn: c(),
                w_carrier: c(),
                impulse: vec![0.0; n - 1],
                face_j: vec![0.0; n - 1],
                friction_j: vec![0.0; n - 1],
                drive_j: 0.0,
                drag_j: 0.0,
                load_j: 0.0,
            },
        }
    }
}

/// The lengths of the clamped stack's powers by kind (`substep::cut`), for `n` coupling bodies,
/// `n_spin` inertial carriers and `n_if` interfaces: the drive's on each body's teeth (a
/// prescribed shaft's; not written on another carrier), each body's speed squared (the drag's
/// over -C2), each inertial carrier's speed squared and its external torque's (the drive's on
/// an inertial shaft, eq 4; the drum's load), each interface's torque (its impulse), its work
/// on the slip and the part of it done while clamped (the friction's; not written for a
/// locked face).
pub(super) fn powers(n: usize, n_spin: usize, n_if: usize) -> [usize; 7] {
    [n, n, n_spin, n_spin, n_if, n_if, n_if]
}

/// The buffers of a session's loops (`session.rs`): what one step or one sample fills and the
/// observer reads, cleared before each use (their contents never outlive it).
#[derive(Debug, Clone, Default)]
pub(super) struct SessionBuffers {
    /// The sample being sent and the stack's interfaces at it.
    pub(super) sample: Sample,
    pub(super) interfaces: Vec<InterfaceSample>,
    /// The impacts a world step closed, and its contact samples `(coupling, t s, state)`.
    pub(super) closed: Vec<ImpactEvent>,
    pub(super) contacts: Vec<(usize, f64, DiscSample)>,
    /// The prescribed shaft's expansion over the world step (the last one's buffer).
    pub(super) local: Option<LocalProfile>,
}
