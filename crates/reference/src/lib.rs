//! # clutchpack_reference
//!
//! The reduced torsional engine: one rotational degree of freedom per body (Hu et al. eqs 3-5
//! extended to any number of discs on one shaft), integrated with an adaptive Dormand-Prince
//! 5(4) method whose dense output locates every contact onset and separation exactly, so that
//! the paper law's per-event memory (the closing speed held from film engagement, MODEL.md
//! section 2) is taken at the right instant and the non-smooth start of the `s^1.5` law never
//! falls inside a step. Free flight across the backlash is cheap (large steps); contact is
//! resolved by the error control.
//!
//! It is the oracle for the multibody engine and the fast engine for sweeps. It is built from
//! the model ([`PackModel`] and [`ReferenceOptions`]), never from a scene file.
//!
//! # Theory
//! ## Equations
//! Symbols: `t` time (s); `theta_s`, `omega_s` shaft angle (rad) and speed (rad/s);
//! `theta_di`, `omega_di` the same for disc `i`; `phi_i = theta_s - theta_di` (rad) and
//! `psi_i = omega_s - omega_di` (rad/s) the relative angle and speed of coupling `i`; `J1`,
//! `C1` shaft inertia (kg m^2) and damping (N m s/rad); `J2i`, `C2i` disc inertia and oil drag;
//! `n_i` teeth, `Rb_i` base radius (m); `F_i` the signed per-tooth load (N) of the coupling's
//! law (MODEL.md sections 1-2); `T_drive(t)` the drive torque (N m); `s_i` the engagement depth
//! (m) of the law, positive inside a contact event.
//!
//! - Prescribed shaft (eq 3): `omega_s(t)`, `theta_s(t)` and `omega_s'(t)` from the profile.
//! - Inertial shaft (eq 4): `J1 omega_s' = T_drive(t) + sum_i n_i F_i Rb_i - C1 omega_s`.
//! - Disc (eq 5): `J2i omega_di' = -n_i F_i Rb_i - C2i omega_di`; so `phi_i' = psi_i`,
//!   `psi_i' = omega_s' - omega_di'`.
//!
//! Integrating the relative quantities keeps the error control on the backlash scale
//! (nanometres at the pitch circle) instead of on the growing absolute angles: the absolute
//! tolerance is `tol g0_i` for `phi_i` (`g0_i` the half play, rad), `tol` for speeds (rad/s)
//! and for the shaft angle (rad), with the relative tolerance `tol` ([`ReferenceOptions::tolerance`]).
//!
//! ## Events
//! `F_i` is only evaluated inside a contact event, which starts when `s_i` crosses zero
//! upwards and ends when it falls back to zero. After every accepted step the sign of `s_i`
//! is probed at the step's quarter points on the 4th-order dense output (catching grazing
//! contacts that enter and leave within a step); a crossing is bisected on the dense output
//! to 1e-13 s and the step is cut there; the integration restarts at the event with the new
//! mode (the paper law's memory taken at that instant). The peak of each event is located by
//! a golden-section search (to 1e-13 s) on the dense output of the last two steps around the
//! step where the load stops rising. Between events the right-hand side is smooth, so every
//! step is a regular DOPRI5 step: 5th order per step (4th-order error estimate and dense
//! output); events are located to 1e-13 s, far below the error the tolerance allows.
//!
//! ## Schemes
//! - [`Scheme::Monolithic`]: the shaft and all discs form one state vector advanced with one
//!   step sequence. Every disc's contact shrinks the step of all the others, so a pack whose
//!   discs strike out of step costs `O(N^2)` for `N` discs. Kept as the oracle of the other.
//! - [`Scheme::Multirate`] with a prescribed shaft (no stack: the engine runs none): the
//!   couplings exchange nothing (the shaft's motion is given), so each disc's `(phi_i, psi_i)`
//!   is an independent ODE. Each is integrated with its own step sequence and its own located
//!   events (the monolithic algorithm on a one-disc system, so it is exactly as accurate),
//!   in parallel on rayon's threads when there are several discs. The run advances in
//!   windows of simulated time `[T_k, T_k+1]`: every disc integrates until its own time
//!   reaches `T_k+1` (its last step may go beyond; it never shortens a step, so the result
//!   does not depend on the window), producing its samples at the output times from its dense
//!   output and its impacts; then a k-way merge emits the window's samples (all discs at the
//!   same instant) and the impacts closed up to `T_k+1` in time order. Windows adapt to
//!   about 20-100 ms of wall time each (and at most 2e5 buffered disc samples), so memory is
//!   bounded and a stop request acts within a window. Cost: linear in `N`.
//! - [`Scheme::Multirate`] with an inertial shaft (eq 4): the bodies are coupled, but only
//!   through the contacting couplings: a disc out of contact carries no load, so the shaft
//!   does not feel it, and its own motion is the closed form of eq (5) with `F = 0`:
//!   `omega_d(t) = omega_d0 e^(-k tau)`, `theta_d(t) = theta_d0 + omega_d0 (1 - e^(-k tau)) /
//!   k` with `k = C2 / J2` (1/s) and `tau = t - t0` (s) since it left contact (`theta_d0 +
//!   omega_d0 tau` for `k = 0`). So the adaptive integration carries only the shaft and the
//!   discs in contact (what is exchanged between them is the spline torque `n F Rb`, exact
//!   and continuous, inside one state vector), with the same error control and event
//!   location as the monolithic scheme; the free discs advance in closed form at no cost per
//!   step, and their re-engagement `s_i > 0` is located like any event (quarter-point probes
//!   on the shaft's dense output and the disc's closed form, bisection to 1e-13 s), after
//!   which the disc joins the integrated state; at separation it leaves it. Order and
//!   accuracy are those of the monolithic scheme; what it saves is the per-step work of the
//!   discs in free flight.
//!
//! - [`Scheme::Multirate`] on an open whole pack (plates on the housing, the piston never
//!   clamping): every disc and plate with its own steps, the gaps' drag relaxed between them
//!   window by window (below, "The open pack's multirate scheme").
//!
//! ## Whole packs (MODEL.md section 5)
//! Separator plates are couplings like discs, against their carrier: the housing (angle and
//! speed 0) or the output drum, whose angle and speed join the state:
//! `J_r omega_r' = T_load + sum_plates n F Rb - C_r omega_r`. For a plate,
//! `phi = theta_c - theta_p` and `psi = omega_c - omega_p`. The carriers feel only the spline reactions; the stack acts between
//! discs and plates, interface `m` between stack bodies `m` and `m + 1` (plate 0, disc 0,
//! plate 1, ...), with the clamp `F_m = max(0, F_p - sum_{b <= m} mu_spline n |F_b|)`. Each
//! interface is in one of three modes between events:
//! - **open** (`F_m = 0`): the Couette drag `-c slip`, `c = pi eta (Ro^4 - Ri^4) / (2 h)`;
//! - **slipping**: `mu(|v|) F_m R_eff` against the slip's direction, which is fixed between
//!   events (no regularised sign);
//! - **locked**: the bodies joined by locked interfaces form a group with one acceleration,
//!   `sum T_b / sum J_b` over its free torques (teeth, drag, the other interfaces), and each
//!   locked interface carries the torque that holds it,
//!   `X_m = sum_{b in group, b <= m} (T_b - J_b alpha)`. The slip of a locked interface stays
//!   zero exactly: its bodies'
//!   accelerations are equal in the right-hand side, and the integrator's linear stages keep
//!   equal speeds equal.
//!
//! Mode switches are events located like the contacts (quarter-point probes on the dense
//! output, bisection to 1e-13 s, restart): a clamp appears (open -> slipping, or locked if the
//! slip is zero and the lock holds) or vanishes (-> open); a slip reaches zero (-> locked if
//! `|X_m| <= mu(0) F_m R_eff`, the slip then set exactly to zero by moving the bodies above to
//! the speed below; else slipping the other way, against `X_m`); a lock needs more than
//! `mu(0) F_m R_eff` (-> slipping against `X_m`). Each interface's heat (`-torque * slip`)
//! is integrated in the state. What is exact: the stick-slip logic and its instants (to the
//! bisection), the group dynamics, the energy and momentum bookkeeping (checked to 2e-10 and
//! exactly in the right-hand side); what is integrated: everything else, at the tolerance. A
//! whole pack with a drum or a stack whose piston can clamp runs one step sequence for all its
//! bodies: the drum and the faces couple them within every step.
//!
//! ### The open pack's multirate scheme (`open.rs`, `gaps.rs`)
//! An open pack (friction discs on a prescribed shaft, plates on the housing, a stack whose
//! piston never clamps: [`clutchpack_model::Piston::can_clamp`]) couples its bodies only
//! through the open gaps' Couette drag `-c (omega_b - omega_n)`, linear and weak (`c / J`
//! about 0.4 1/s on the shipped packs). Each body is then integrated alone (its own steps and
//! events, as an independent disc), its gaps' drag computed from its neighbours' speeds over a
//! window of 1 ms on a fixed grid: Gauss-Seidel waveform relaxation over the stack's two
//! colours. The discs run first against their plates' predicted speeds (in free flight the
//! speed at the window's start moving on with its acceleration there, in contact held), then
//! the plates against the discs' dense output. A disc whose plates' passes differ from what it
//! saw by more than the tolerance allows (`c integral |d omega| dt / J`, the change of its
//! speed in free flight, against `tol (1 + |omega|)` per step it took in the window: a
//! relative tolerance on its speed, chosen by measurement) runs again from
//! the window's start against them, and its plates after it, until every pass stands (at
//! most 12 sweeps, else the run fails with the reason). What is exact: each body's equation
//! and events, as in the monolithic scheme; the coupling is converged to the tolerance, not
//! exact (measured against the monolithic scheme at 1e-12 on `pack-8-brake` over 50 ms, 292
//! impacts: peaks within 1.1e-5, onsets within 24 ns, every gap's heat within 1e-8). The gaps'
//! heat comes from the work each gap's drag does on the body below and the body above, both
//! integrated in those bodies' states. Cost: the sum of the bodies' own steps, `O(N)`, spread
//! over threads, times the reruns: on `pack-8-brake` the plates rattle against the housing
//! (pushed by the drag of the discs at 200 rad/s) and 66 % of the discs' windows run twice.
//! Allowing ten times the tolerance halves the time but moved an onset 1.5 us from the oracle's
//! by 44 ms, so the check stays at the tolerance.
//!
//! ## Thermal packs (MODEL.md section 9, `thermal.rs`)
//! A pack with a thermal model ([`ReferenceEngine::with_thermal`]) runs the monolithic scheme
//! with the temperatures of every disc, plate and the oil as slow states beside it: operator
//! splitting on a fixed window. Each accepted step's heat is booked from what the state
//! integrates (each interface's heat counter, to its two bodies by effusivity while clamped,
//! to the oil while open; the teeth's work `-n F Rb psi`, its own counter outside the error
//! norm, to the oil); at the first step end past each window the temperatures advance over it (RK4 on the
//! lumped equations) and the tooth films (eqs 7-8, scaled by `eta(T_oil) / eta(T_ref)`) and the
//! gaps' viscosity change for the next, with a restart. Steps are never cut at a window, so a
//! run whose parameters do not change is the isothermal run bit for bit. First order in the
//! window; the heat balance closes to rounding (docs/DECISIONS.md, "Thermal windows").
//!
//! ## Order and energy
//! - Order: every scheme takes the same DOPRI5 steps (5th-order solution, 4th-order error
//!   estimate and dense output) between located events, so each is 5th order in the step
//!   and its error is set by [`ReferenceOptions::tolerance`], not by the scheme. The multirate schemes
//!   add no splitting error: on a prescribed shaft the discs exchange nothing (the split is
//!   exact), and on an inertial shaft the free discs follow the exact solution of their
//!   equation while every coupling that carries a load is integrated together with the
//!   shaft in one state vector (no torque is passed between separately integrated bodies).
//!   What differs is the step sequence: each independent disc takes the steps its own
//!   contacts need, so the rounding and truncation errors differ from the monolithic run's
//!   at the tolerance's level. Measured against the monolithic scheme at 1e-12
//!   (`tests/multirate.rs`): peaks within 1.4e-6 (staggered 8-disc pack), 1.3e-5
//!   (pack-4-rattle) and 1e-5 (inertial shaft), onsets within 2.4e-8 s. The open pack's
//!   scheme converges its coupling to the tolerance (above).
//! - Energy: DOPRI5 is not symplectic; it neither conserves nor systematically dissipates
//!   energy, its energy error per step is bounded by the local error the tolerance allows,
//!   so over a run it drifts at most in proportion to the number of steps. In free flight
//!   the multirate scheme on an inertial shaft is exact (closed form), so it adds none there.
//!   The spline forces are internal to the integrated state, so the total angular momentum
//!   of an undriven, undamped inertial-shaft pack is conserved to the tolerance in every
//!   scheme (checked to 1e-9 relative in `tests/paper.rs`); a prescribed shaft is an energy
//!   source by definition, and the physical losses (the law's `p`, the film, the drag) are
//!   in the equations, not in the integrator.
//! - Cost: the monolithic scheme's steps are shared, so `N` discs striking out of step cost
//!   about `N` times the steps of one, each `N` times dearer: `O(N^2)`. The independent
//!   scheme costs the sum of the discs' own steps: `O(N)`, spread over threads. The coupled
//!   scheme costs the shaft's steps, each as dear as the discs in contact at that moment. The
//!   open pack's scheme costs the bodies' own steps, about 1.7 times for the reruns: linear in
//!   the pack (`clutchpack bench --pack-only`, 0.1 s: per disc 6.3 ms at one disc and two
//!   plates, 5.3 ms at 16 and 17, growth 0.84x; the 16-disc pack on one step sequence 232.8
//!   ms, growth 1.51x).
//!
//! # Why not an ODE crate
//! We looked at `ode_solvers` (DOPRI5/DOP853, dense output through `solout`, no event
//! location), `differential-equations` (events by Brent root finding that terminate the solve)
//! and `diffsol` (implicit, matrix based). The engine needs per-disc hybrid state (the paper
//! law's memory) switched at located events with a restart, many times per run, no allocation
//! per step, and the dense output of the last two steps for the peak search. That is a small
//! amount of code around the standard tableau (`dopri.rs`), tested against closed forms.

#![warn(missing_docs)]
// Index loops over state components mirror the equations; iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

/// `Clone` for a struct of the fields named, whose `clone_from` clones field by field into
/// the target's own buffers (`Vec::clone_from` keeps its allocation and clones element by
/// element), so that a scheme that saves and restores its bodies' integrations window by
/// window (`open.rs`) does not allocate once its buffers have grown. Both methods destructure
/// the struct whole: a field added and not listed here fails to compile.
macro_rules! clone_reusing {
    ($ty:ident { $($f:ident),* $(,)? }) => {
        impl Clone for $ty {
            fn clone(&self) -> Self {
                let $ty { $($f),* } = self;
                $ty { $($f: $f.clone()),* }
            }
            fn clone_from(&mut self, source: &Self) {
                let $ty { $($f),* } = self;
                $($f.clone_from(&source.$f);)*
            }
        }
    };
}

mod coupled;
mod dopri;
mod gaps;
mod independent;
pub mod network;
mod open;
mod session;
mod stepper;
mod system;
mod thermal;

use clutchpack_model::session::{Driven, Inputs, Session};
use clutchpack_model::thermal::ThermalModel;
use clutchpack_model::{Engagement, Engine, EngineError, PackModel, Shaft};
use session::MonolithicSession;
use std::sync::Arc;
use system::{Face, System};

/// The reference engine's options (as `MultibodyOptions` are the multibody engine's): the
/// integration tolerance, the largest step and the sample rate of its output.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceOptions {
    /// Relative error tolerance (dimensionless). Absolute tolerances derive from it: `tol *
    /// g0` rad for relative angles, `tol * 1 rad/s` for speeds, `tol * 1 rad` for the shaft angle.
    pub tolerance: f64,
    /// Largest step in s.
    pub max_step_s: f64,
    /// Sample rate of the output in Hz (samples at `k / rate`, k = 0, 1, ...).
    pub record_rate_hz: f64,
}

impl Default for ReferenceOptions {
    fn default() -> Self {
        ReferenceOptions {
            tolerance: 1e-9,
            max_step_s: 1e-4,
            record_rate_hz: 10_000.0,
        }
    }
}

/// How the engine advances the bodies (see the crate's Theory section).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scheme {
    /// Each body with its own steps where the bodies exchange nothing: independent discs
    /// on a prescribed shaft; on an inertial shaft, the discs in free flight in closed form
    /// and only the shaft with the contacting discs integrated (the default).
    #[default]
    Multirate,
    /// One state vector and one step sequence for the shaft and every disc (the oracle).
    Monolithic,
}

/// The reduced torsional engine for a [`PackModel`].
#[derive(Debug, Clone)]
pub struct ReferenceEngine {
    pack: PackModel,
    settings: ReferenceOptions,
    scheme: Scheme,
    parallel: bool,
    thermal: Option<ThermalModel>,
}

/// Fewest discs for which the multirate scheme spreads the discs over rayon's threads.
const PARALLEL_MIN_DISCS: usize = 2;

impl ReferenceEngine {
    /// An engine for `pack` with `settings`, the [`Scheme::Multirate`] scheme, parallel.
    pub fn new(pack: PackModel, settings: ReferenceOptions) -> ReferenceEngine {
        ReferenceEngine {
            pack,
            settings,
            scheme: Scheme::default(),
            parallel: true,
            thermal: None,
        }
    }

    /// The same engine carrying the temperatures of `thermal` (MODEL.md section 9; `None`:
    /// isothermal). A thermal run takes the monolithic scheme whatever the scheme asked
    /// (the module `thermal`'s docs: the temperatures advance beside one step sequence).
    pub fn with_thermal(mut self, thermal: Option<ThermalModel>) -> ReferenceEngine {
        self.thermal = thermal;
        self
    }

    /// The same engine with the scheme `scheme`.
    pub fn with_scheme(mut self, scheme: Scheme) -> ReferenceEngine {
        self.scheme = scheme;
        self
    }

    /// The same engine, allowed (`true`, the default) or not to spread independent discs over
    /// rayon's threads (the results are identical either way).
    pub fn with_parallel(mut self, parallel: bool) -> ReferenceEngine {
        self.parallel = parallel;
        self
    }

    /// The model this engine runs.
    pub fn pack(&self) -> &PackModel {
        &self.pack
    }

    /// The scheme this engine runs.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// Whether the pack is a whole pack (plates, a drum or a stack): monolithic unless it is
    /// an open pack on a prescribed shaft (crate docs, "Whole packs").
    pub fn is_whole(&self) -> bool {
        self.pack.is_whole()
    }

    /// Whether the discs run in parallel: the multirate scheme on a prescribed shaft with
    /// parallelism allowed, at least two discs and more than one rayon thread.
    fn runs_parallel(&self) -> bool {
        self.scheme == Scheme::Multirate
            && !self.is_whole()
            && matches!(self.pack.shaft, Shaft::Prescribed(_))
            && self.spreads_bodies()
    }

    /// Whether independent bodies may be spread over threads: allowed, at least two discs
    /// and more than one rayon thread.
    fn spreads_bodies(&self) -> bool {
        self.parallel
            && self.pack.discs.len() >= PARALLEL_MIN_DISCS
            && rayon::current_num_threads() > 1
    }

    /// Whether a run takes the open-pack multirate scheme (crate docs, "Whole packs").
    fn runs_open(&self) -> bool {
        self.scheme == Scheme::Multirate
            && self.thermal.is_none()
            && open::runs_open(&self.pack, &Driven::NONE)
    }

    /// One line saying which scheme runs and why, e.g. `"multirate: prescribed shaft, no
    /// stack; 8 independent discs on 2 threads"`.
    pub fn describe(&self) -> String {
        let nd = self.pack.discs.len();
        let discs = if nd == 1 { "disc" } else { "discs" };
        if let Some(th) = &self.thermal {
            return format!(
                "monolithic: one step sequence for the shaft, {nd} {discs} and {} plates, with \
                 the temperatures of every body and the oil advanced every {} s beside it \
                 (a thermal pack runs monolithic)",
                self.pack.plates.len(),
                th.step_s
            );
        }
        if self.runs_open() {
            let threads = if self.spreads_bodies() {
                format!(" on {} threads", rayon::current_num_threads())
            } else {
                String::new()
            };
            return format!(
                "multirate: an open pack (the piston never clamps), so {nd} {discs} on the \
                 prescribed shaft and {} plates on the housing each take their own steps{threads}, \
                 the open gaps' drag between them relaxed window by window to the tolerance",
                self.pack.plates.len()
            );
        }
        if self.is_whole() {
            let np = self.pack.plates.len();
            let carrier = if self.pack.drum.is_some() {
                "the drum"
            } else {
                "the housing"
            };
            let stack = if self.pack.stack.is_some() {
                ", the stack's faces (oil gaps, exact stick and slip) coupling neighbours"
            } else {
                ""
            };
            let couplings = match self.pack.couplings.len() {
                0 => String::new(),
                1 => ", a spring-damper joining the shaft and the drum".to_string(),
                n => format!(", {n} spring-dampers joining the shaft and the drum"),
            };
            return format!(
                "monolithic: one step sequence for the shaft, {nd} {discs} and {np} plates on \
                 {carrier}{stack}{couplings} (a whole pack runs monolithic)"
            );
        }
        match (self.scheme, &self.pack.shaft) {
            (Scheme::Monolithic, _) => {
                format!(
                    "monolithic: one step sequence for the shaft and all {nd} {discs} (as asked)"
                )
            }
            (Scheme::Multirate, Shaft::Prescribed(_)) => {
                let threads = if self.runs_parallel() {
                    format!(" on {} threads", rayon::current_num_threads())
                } else {
                    String::new()
                };
                format!("multirate: prescribed shaft, no stack; {nd} independent {discs}{threads}")
            }
            (Scheme::Multirate, Shaft::Inertial { .. }) => format!(
                "multirate: inertial shaft (eq 4) integrated with the discs in contact; {nd} \
                 {discs} in free flight in closed form"
            ),
        }
    }
}

/// No events outside the system.
pub(crate) fn no_external(
    _sys: &System,
    _modes: &[Option<Engagement>],
    _t0: f64,
    _t1: f64,
    _d: &dopri::Dense,
) -> Option<(f64, usize)> {
    None
}

/// The earliest stick-slip event of the stack's faces inside the step `[t0, t1]` (dense output
/// `d`), as `(time, interface)`: each face's switching condition
/// ([`System::face_switches`]) probed at the step's quarter points, the first crossing
/// bisected to 1e-13 s (as the contact events are).
pub(crate) fn face_event(
    sys: &System,
    modes: &[Option<Engagement>],
    t0: f64,
    t1: f64,
    d: &dopri::Dense,
    buf: &mut Vec<f64>,
) -> Option<(f64, usize)> {
    // An open pack stays open while the piston does not push: skip the probe then (the
    // clamp of an interface is at most the piston force)
    let piston = &sys.pack.stack.as_ref().expect("a stack").piston;
    if sys.faces.iter().all(|f| *f == Face::Open)
        && (0..=4).all(|q| piston.force_n(t0 + (t1 - t0) * q as f64 / 4.0) <= 0.0)
    {
        return None;
    }
    buf.resize(sys.dim(), 0.0);
    // whether face `m` switches at `t` (the stack evaluated in the thread's buffers)
    let switches = |m: usize, t: f64, buf: &mut Vec<f64>| {
        d.eval(t, buf);
        sys.with_carriers_and_stack(t, buf, modes, |_, ev| sys.face_switches(m, ev))
    };
    let mut ta = t0;
    for q in 1..=4 {
        let tq = if q == 4 {
            t1
        } else {
            t0 + (t1 - t0) * q as f64 / 4.0
        };
        d.eval(tq, buf);
        let any = sys.with_carriers_and_stack(tq, buf, modes, |_, ev| {
            (0..sys.faces.len()).any(|m| sys.face_switches(m, ev))
        });
        if any {
            // the earliest of the faces that fired in (ta, tq]
            let fired = |m: usize, buf: &mut Vec<f64>| switches(m, tq, buf);
            let mut best: Option<(f64, usize)> = None;
            for m in 0..sys.faces.len() {
                if !fired(m, buf) {
                    continue;
                }
                let (mut a, mut b) = (ta, tq);
                while b - a > 1e-13 {
                    let mid = 0.5 * (a + b);
                    if switches(m, mid, buf) {
                        b = mid;
                    } else {
                        a = mid;
                    }
                }
                if best.is_none_or(|(tb, _)| b < tb) {
                    best = Some((b, m));
                }
            }
            return best;
        }
        ta = tq;
    }
    None
}

impl Engine for ReferenceEngine {
    fn name(&self) -> &'static str {
        "reference"
    }

    fn disc_names(&self) -> Vec<String> {
        // the engines' body order: the discs, then the plates
        self.pack
            .discs
            .iter()
            .chain(&self.pack.plates)
            .map(|d| d.name.clone())
            .collect()
    }

    fn model(&self) -> &PackModel {
        &self.pack
    }

    fn start(&self, driven: Driven) -> Result<Box<dyn Session>, EngineError> {
        for d in self.pack.discs.iter().chain(&self.pack.plates) {
            stepper::check_disc(d)?;
        }
        driven.check(&self.pack)?;
        let (pack, settings) = (Arc::new(self.pack.clone()), &self.settings);
        if let Some(th) = &self.thermal {
            let session =
                MonolithicSession::new(pack, settings, driven).with_thermal(th.clone())?;
            let mut session: Box<dyn Session> = Box::new(session);
            if driven.any() {
                session.set_inputs(&Inputs::of_scene(&self.pack, &driven, 0.0))?;
            }
            return Ok(session);
        }
        let mut session: Box<dyn Session> = match (self.scheme, &self.pack.shaft) {
            (Scheme::Multirate, _) if open::runs_open(&pack, &driven) => Box::new(
                open::OpenSession::new(pack, settings, self.spreads_bodies(), driven),
            ),
            (Scheme::Multirate, _) if pack.discs.is_empty() || self.is_whole() => {
                Box::new(MonolithicSession::new(pack, settings, driven))
            }
            (Scheme::Monolithic, _) => Box::new(MonolithicSession::new(pack, settings, driven)),
            (Scheme::Multirate, Shaft::Prescribed(_)) => Box::new(
                independent::IndependentSession::new(pack, settings, self.runs_parallel(), driven),
            ),
            (Scheme::Multirate, Shaft::Inertial { .. }) => {
                Box::new(coupled::CoupledSession::new(pack, settings, driven))
            }
        };
        if driven.any() {
            // the driven inputs held at the scene's values until the caller sets them
            session.set_inputs(&Inputs::of_scene(&self.pack, &driven, 0.0))?;
        }
        Ok(session)
    }
}
