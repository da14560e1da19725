//! What every engine emits (samples, impact events, a run report) to an [`Observer`], the one
//! observer of every run (a pack's and a driveline network's); the `Engine` trait and the
//! network's `NetworkSession` are in `crate::session`.

use crate::clutch::InterfaceSample;
use crate::impact::ImpactEvent;
use crate::network::output::{ClutchEvent, NetworkSample};
use serde::{Deserialize, Serialize};

/// State of one disc's coupling at one instant.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DiscSample {
    /// Disc angle in rad (positive in the shaft's positive rotation).
    pub angle_rad: f64,
    /// Disc speed in rad/s.
    pub speed_rad_s: f64,
    /// Relative angle `phi = theta_s - theta_d` in rad (positive: the shaft leads).
    pub rel_angle_rad: f64,
    /// Metal penetration along the line of action in m (negative: a gap).
    pub penetration_m: f64,
    /// Closing speed along the line of action of the flank `phi` lies on, m/s (positive closing).
    pub closing_speed_m_s: f64,
    /// Per-tooth load in N, signed as eq (6) (negative when the shaft leads).
    pub load_n: f64,
    /// Spline torque on the disc in N m (`-n F Rb`, eq 5).
    pub torque_n_m: f64,
    /// Whether a contact event (film or metal) is in progress.
    pub engaged: bool,
    /// Stiffness `K` of the current contact event in N/m^1.5 (0 when not engaged).
    pub stiffness: f64,
    /// Per-tooth loads in N when the engine resolves teeth (empty for lumped engines).
    pub tooth_loads_n: Vec<f64>,
    /// Offset of the disc's centre from the shaft axis in m, `[x, y]` in the shaft's frame
    /// (radial float, an eccentric start); `[0, 0]` for engines with one rotational degree of
    /// freedom per body.
    #[serde(default)]
    pub center_offset_m: [f64; 2],
}

/// The state of the whole pack at one instant.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Sample {
    /// Time in s.
    pub t_s: f64,
    /// Shaft angle in rad.
    pub shaft_angle_rad: f64,
    /// Shaft speed in rad/s.
    pub shaft_speed_rad_s: f64,
    /// One entry per disc, in scene order.
    pub discs: Vec<DiscSample>,
}

/// Receives what an engine produces, in time order: the one observer of every run. A pack run
/// sends the pack's methods ([`Observer::sample`] to [`Observer::wants_contact_samples`]), a
/// driveline network's run the network's ([`Observer::network_sample`] to
/// [`Observer::open_contacts`]); both poll [`Observer::progress`]. Every method has a default
/// that keeps nothing.
pub trait Observer {
    /// A pack run's sample at the recording rate.
    fn sample(&mut self, _sample: &Sample) {}
    /// A completed impact event.
    fn impact(&mut self, _event: &ImpactEvent) {}
    /// The state of the stack's friction interfaces, at the same instants as the samples
    /// (engines with a stack only; interface `m` lies between stack bodies `m` and `m + 1`,
    /// see `crate::clutch`).
    fn interfaces(&mut self, _t_s: f64, _interfaces: &[InterfaceSample]) {}
    /// The state of disc `disc` (index in [`Sample::discs`], scene order) at time `t_s` (s)
    /// at an integration step inside one of its contact events: the dense history of the
    /// contacts that the record-rate [`Observer::sample`]s are too sparse to resolve (a contact
    /// lasts about as long as a sample interval). Units and signs are those of
    /// [`DiscSample`] (`load_n` per tooth in N, negative when the shaft leads, eq (6));
    /// `tooth_loads_n` may be empty.
    ///
    /// An engine sends, for each contact event (film or metal), the state at its located
    /// onset, at accepted steps (or sub-steps, thinned to a few dozen per contact, see the
    /// engine's docs) while it is in progress, and at the step that closes it, so that every
    /// point lies in `[t_on_s, t_off_s]` of one of the disc's [`ImpactEvent`]s. For each disc
    /// these calls and the disc's entries of the [`Observer::sample`]s come in non-decreasing
    /// time order together (the calls of different discs may interleave out of time order).
    /// They do not replace the samples: statistics and fatigue use the regular samples only.
    fn contact_sample(&mut self, _disc: usize, _t_s: f64, _state: &DiscSample) {}
    /// A thermal run's temperatures at time `t_s` (s), at the end of each thermal window
    /// (MODEL.md section 9): `bodies_k` one per body in the order of
    /// [`crate::thermal::ThermalReport::final_k`] (the discs in scene order, then the plates),
    /// K; `oil_k` the oil's, K. In time order with the samples; never called in an
    /// isothermal run.
    fn temperatures(&mut self, _t_s: f64, _bodies_k: &[f64], _oil_k: f64) {}
    /// Whether this observer takes [`Observer::contact_sample`]s; engines build and buffer
    /// them only then (asked once, at the start of a run). Default `false`: statistics,
    /// sweeps and benches run without their cost.
    fn wants_contact_samples(&self) -> bool {
        false
    }
    /// A driveline network's sample at the record rate (and at t = 0 and the end; MODEL.md
    /// section 8).
    fn network_sample(&mut self, _sample: &NetworkSample) {}
    /// A network's clutch changed mode.
    fn clutch_event(&mut self, _event: &ClutchEvent) {}
    /// A network's state just before and just after an instant where clutches changed mode
    /// (sent before their [`Observer::clutch_event`]s): the couplings' torques jump there (the
    /// output torque's step at a lock).
    fn switched(&mut self, _before: &NetworkSample, _after: &NetworkSample) {}
    /// A network's gear mesh's tooth contact closed (its `disc` is the coupling's index; the
    /// peak is the force per tooth pair in N, negative when body `a` leads: `x > 0`).
    fn mesh_impact(&mut self, _impact: &ImpactEvent) {}
    /// A tooth contact of a network's resolved pack's disc or plate closed: `coupling` is the
    /// pack's coupling index, the impact's `disc` the body's index in the pack (its discs,
    /// then its plates), its peak the per-tooth load in N as the pack engines sign it.
    fn pack_impact(&mut self, _coupling: usize, _impact: &ImpactEvent) {}
    /// A network's resolved pack's discs and plates at a sample's instant `t_s` (s), sent
    /// after the [`Observer::network_sample`] of that instant: each body's absolute angle
    /// (rad), speed (rad/s) and per-tooth load (N, signed as in Hu et al. eq (6): negative when
    /// its carrier leads), its discs then its plates.
    fn pack_sample(
        &mut self,
        _coupling: usize,
        _t_s: f64,
        _angle_rad: &[f64],
        _speed_rad_s: &[f64],
        _load_n: &[f64],
    ) {
    }
    /// A network's thermal resolved pack's temperatures at `t_s` (s), K: its discs', then its
    /// plates', then its oil's; at t = 0 and at the end of each thermal window (MODEL.md
    /// section 9).
    fn pack_temperatures(&mut self, _coupling: usize, _t_s: f64, _temperatures_k: &[f64]) {}
    /// A network's resolved pack's faces changed mode at `t_s` (s): `locked` of its `faces`
    /// friction faces are locked now (all of them: the pack has locked, its carriers turn as
    /// one but for the splines' play), `clamped` are clamped (locked or slipping).
    fn pack_faces(
        &mut self,
        _coupling: usize,
        _t_s: f64,
        _locked: usize,
        _clamped: usize,
        _faces: usize,
    ) {
    }
    /// Whether it wants a network's tooth contacts open at `t_s` (s, the end of an accepted
    /// step) through [`Observer::open_contacts`]: asked after every step, so it answers
    /// cheaply; no by default.
    fn wants_open_contacts(&mut self, _t_s: f64) -> bool {
        false
    }
    /// A network's tooth contacts open at `t_s` (s), when [`Observer::wants_open_contacts`]
    /// asked: each as `(coupling, body in a pack, event)`, the event as it would close at
    /// `t_s` (its onset, its peak located so far, `t_off_s = t_s`), as
    /// [`Observer::mesh_impact`] (`body` `None`) and [`Observer::pack_impact`] give closed
    /// ones. A contact stays open for seconds where a locked pack's teeth carry its torque:
    /// what a run cut short would otherwise lose.
    fn open_contacts(&mut self, _t_s: f64, _open: &[(usize, Option<usize>, ImpactEvent)]) {}
    /// Called now and then with the simulated time in s (a network run: after every step);
    /// returning `true` stops the run early and cleanly, where it stands (used for Ctrl-C and
    /// a recording's first error). Every run, pack or network, reads it the same way.
    fn progress(&mut self, _t_s: f64) -> bool {
        false
    }
}

/// An observer that keeps nothing.
pub struct NullObserver;
impl Observer for NullObserver {}

/// Collects everything in memory (tests and small runs).
#[derive(Debug, Default, Clone)]
pub struct Collector {
    /// All samples.
    pub samples: Vec<Sample>,
    /// All impact events in the order they closed.
    pub impacts: Vec<ImpactEvent>,
    /// The friction interfaces' states with their times in s (engines with a stack).
    pub interfaces: Vec<(f64, Vec<InterfaceSample>)>,
    /// The contact samples `(disc, t s, state)` in the order they came
    /// ([`Observer::contact_sample`]).
    pub contacts: Vec<(usize, f64, DiscSample)>,
    /// A thermal run's temperatures `(t s, bodies K, oil K)` ([`Observer::temperatures`]).
    pub temperatures: Vec<(f64, Vec<f64>, f64)>,
}

impl Observer for Collector {
    fn sample(&mut self, sample: &Sample) {
        self.samples.push(sample.clone());
    }
    fn impact(&mut self, event: &ImpactEvent) {
        self.impacts.push(*event);
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.interfaces.push((t_s, interfaces.to_vec()));
    }
    fn contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        self.contacts.push((disc, t_s, state.clone()));
    }
    fn temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        self.temperatures.push((t_s, bodies_k.to_vec(), oil_k));
    }
    fn wants_contact_samples(&self) -> bool {
        true
    }
}

/// What a finished (or stopped) run reports.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RunStats {
    /// Simulated time reached, s.
    pub simulated_s: f64,
    /// Accepted integration steps.
    pub steps: u64,
    /// Rejected steps (adaptive engines).
    pub rejected_steps: u64,
    /// Evaluations of the equations of motion.
    pub rhs_evals: u64,
    /// Whether the observer stopped the run early.
    pub stopped_early: bool,
    /// A thermal run's temperatures and heat balance (`None` for an isothermal run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal: Option<crate::thermal::ThermalReport>,
}

/// Steps per block of the engines' stall check (see [`STALL_SPAN_S`]).
pub const STALL_STEPS: u64 = 1 << 16;
/// Least simulated time, s, a block of [`STALL_STEPS`] adaptive steps must advance; an engine
/// whose steps fall below that (a mean step under 6e-11 s) stops with
/// [`EngineError::Diverged`]. Real packs stay far above it (the paper case's steps inside a
/// contact are about 1e-7 s); a law made stiff by a value far outside practice (a loss
/// coefficient of 1e19 s/m, a drive at 1e19 Hz) falls below it and would run for days.
pub const STALL_SPAN_S: f64 = 4e-6;

/// Largest speed magnitude of a body in an engine's state, rad/s: ten times the largest a
/// scene or a co-simulation input may give (the scene crate's `MAX_SPEED_RAD_S`, 1e5 rad/s,
/// about 950 000 rpm). A state beyond it is no driveline: an explicit step past its stability
/// limit (a coupling stiffer or a damping larger than the step can take) grows the state
/// geometrically, and [`guard_state`] stops the run there rather than let it end with
/// 1e200-sized or NaN outputs (issue 48, item 2).
pub const RUNAWAY_SPEED_RAD_S: f64 = 1e6;

/// The engines' one divergence guard of a state (packs, networks, thermal states; issue 48:
/// "a run either integrates or says it diverged"): `Ok` when every value of `values` is
/// finite and at most `bound` in magnitude (`f64::INFINITY`: finite only), else
/// [`EngineError::Diverged`] at `t_s` (s, the time of the last good state) naming the first
/// offending value: `what` (its kind, e.g. "a body's speed") with its index, the value and
/// `unit`.
pub fn guard_state(
    t_s: f64,
    what: &str,
    unit: &str,
    values: &[f64],
    bound: f64,
) -> Result<(), EngineError> {
    // two comparisons per value: the check stays off the profile of a step
    match values.iter().position(|v| v.is_nan() || v.abs() > bound) {
        None => Ok(()),
        Some(i) => Err(EngineError::Diverged {
            t_s,
            reason: if values[i].is_finite() {
                format!(
                    "{what} {i} reached {:.3e} {unit}, beyond {bound:e} {unit}: the integration \
                     ran away (a coupling stiffer, or a damping or force larger, than the step \
                     can take)",
                    values[i]
                )
            } else {
                format!("{what} {i} is not finite ({})", values[i])
            },
        }),
    }
}

/// Why an engine could not finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EngineError {
    /// The state became non-finite or the step size collapsed.
    #[error("the simulation diverged at t = {t_s:.9} s: {reason}")]
    Diverged {
        /// Time of the last good state, s.
        t_s: f64,
        /// What went wrong.
        reason: String,
    },
    /// The engine cannot run this model.
    #[error("this engine cannot run the scene: {0}")]
    Unsupported(String),
}
