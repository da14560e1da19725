//! The sub-step kernel of the multirate schemes (`multirate.rs`, `inertial.rs`, `clamped.rs`):
//! the one classical Runge-Kutta step of a set of bodies, with the one quadrature of the works
//! along it ([`Rk4::rk4`]), to which each scheme gives its right-hand side; a coupling's step
//! against its carrier's path ([`Relative`]), graded towards the tooth law's kinks, with the
//! open gaps' drag held over the step; the world-step context the schemes pass down
//! ([`WorldStep`]); and what the multirate schemes count.

use crate::hook::{Coupling, CouplingForces};
use crate::options::AdaptiveStepping;
use clutchpack_model::{DiscSample, EngineError, ImpactEvent, LocalProfile, SpeedProfile};

/// One world step of the multirate schemes as their sub-steps see it (the context the
/// schemes pass down instead of long argument lists): where it ends, the step controller's
/// settings, and where the sub-steps report what they count, the impacts that closed and the
/// contact samples.
pub(super) struct WorldStep<'a> {
    /// The world step's end, s.
    pub(super) t1: f64,
    /// The step controller's settings.
    pub(super) a: &'a AdaptiveStepping,
    /// ... and those of a coupling alone against a carrier of known motion
    /// ([`AdaptiveStepping::alone`]).
    pub(super) alone: &'a AdaptiveStepping,
    /// The prescribed shaft over the world step (`None`: the shaft is inertial).
    pub(super) drive: Option<Prescribed<'a>>,
    /// What the multirate loop counts in the run.
    pub(super) counts: &'a mut Counts,
    /// Impact events that closed (in the order they closed within each coupling).
    pub(super) closed: &'a mut Vec<ImpactEvent>,
    /// Contact samples `(coupling, t s, state)` of the sub-steps (in time order within each
    /// coupling; see `EventBook::update`).
    pub(super) contacts: &'a mut Vec<(usize, f64, DiscSample)>,
}

/// The open gaps' drag on one body over a world step, `sum_nb c (w_nb - w)` (Couette, MODEL.md
/// section 5): the neighbours' speeds taken as an affine function of time over the step with
/// their mean and their first moment about its middle (predicted, or integrated before; see
/// `Run::multirate_step`), the body's own speed along its sub-steps (the damping `c` per gap
/// on its own speed is exact within the step; the neighbours' are a coupling with a time
/// constant `J / c` of seconds against a world step of 0.1 ms).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct GapDrag {
    /// `c sum_nb w_nb` at the step's middle (the mean over the step), N m.
    pub(super) held_n_m: f64,
    /// Its rate over the step, N m/s: `c sum_nb` of the neighbours' speeds' slopes (the
    /// affine function with their first moment).
    pub(super) slope_n_m_s: f64,
    /// The world step's middle, s, and half its length, s.
    pub(super) t_mid_s: f64,
    pub(super) half_step_s: f64,
    /// `c` times the number of neighbours, N m s/rad.
    pub(super) damping: f64,
}

impl GapDrag {
    /// The drag on the body at `t` (s) turning at `u` (rad/s), N m.
    pub(super) fn torque(&self, t: f64, u: f64) -> f64 {
        self.held_n_m + self.slope_n_m_s * (t - self.t_mid_s) - self.damping * u
    }

    /// The largest magnitude of the neighbours' part over the step, N m (for the step
    /// controller's bound of the body's acceleration).
    pub(super) fn bound_n_m(&self) -> f64 {
        self.held_n_m.abs() + self.slope_n_m_s.abs() * self.half_step_s
    }
}

/// A body's first moment of speed about a world step's middle, accumulated along its sub-steps
/// (`Run::end_sub_step`): `integral (s - t_mid) w ds` from the body's turns at the sub-steps'
/// ends by cubic Hermite quadrature (exact for a cubic angle between them), for the slope of
/// its speed that its neighbours' gap drag takes ([`GapDrag`]).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct TurnMoment {
    /// The world step's start, s.
    t0: f64,
    /// The body's angle at the start, rad.
    theta0: f64,
    /// The last sub-step's end: time, s, angle from `theta0`, rad, speed, rad/s.
    t: f64,
    turn: f64,
    speed: f64,
    /// `integral (theta - theta0) ds` so far, rad s.
    integral: f64,
}

impl TurnMoment {
    /// Starts a world step at `t0` with the body at angle `theta0` (rad) and speed `w0`.
    pub(super) fn start(t0: f64, theta0: f64, w0: f64) -> TurnMoment {
        TurnMoment {
            t0,
            theta0,
            t: t0,
            turn: 0.0,
            speed: w0,
            integral: 0.0,
        }
    }

    /// A sub-step's end at `t` with the body at angle `theta` (rad) and speed `w` (rad/s).
    pub(super) fn add(&mut self, t: f64, theta: f64, w: f64) {
        let (d, turn) = (t - self.t, theta - self.theta0);
        self.integral += 0.5 * d * (self.turn + turn) + d * d / 12.0 * (self.speed - w);
        (self.t, self.turn, self.speed) = (t, turn, w);
    }

    /// The slope of the affine speed with the body's mean speed `(turn at t) / h` and its first
    /// moment over the step so far (to `t`, length `h`), rad/s^2: `12 m1 / h^3` with
    /// `m1 = integral (s - t_mid) w ds = h turn / 2 - integral turn ds`.
    pub(super) fn slope(&self) -> f64 {
        let h = self.t - self.t0;
        if h <= 0.0 {
            return 0.0;
        }
        12.0 * (0.5 * h * self.turn - self.integral) / (h * h * h)
    }
}

/// What the multirate loop counts in a run.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Counts {
    /// Sub-steps taken by all couplings together.
    pub(super) substeps: u64,
    /// Tooth-law evaluations (stages, landings, the evaluation at each sub-step's end).
    pub(super) evals: u64,
    /// Inertial carriers (shaft, drum): couplings that touched within a world step they were
    /// predicted to fly through (integrated against the carrier's motion without their own
    /// reaction on it).
    pub(super) missed: u64,
}

/// Sub-steps near a kink of the `s^1.5` law are at most this fraction of the time from the
/// onset or to the separation (dimensionless). See [`graded_step`].
const KINK_GRADE: f64 = 0.25;

/// ... and at least the contact step over this (dimensionless), in the couplings integrated
/// with an inertial carrier and in the clamped stack.
pub(super) const KINK_FLOOR_DIVISOR: f64 = 64.0;

/// ... and over this for a coupling alone against a carrier of known motion (a prescribed
/// shaft, the housing; dimensionless; issue 46). The step touching an onset errs as
/// `floor^2.5` (the impulse of `t^1.5` by the step's quadrature: `0.0024 floor^2.5` for
/// Simpson's weights), the graded steps after it as `KINK_GRADE^2.5 want^2.5` together, so a
/// floor of an eighth of the contact step adds an error no larger than the grading's own
/// while it saves about ten sub-steps per impact. Measured against the reference engine at
/// 1e-12 on the open 8-disc brake at world steps of 1e-5 s (worst onset over the first 10,
/// 20 and 30 ms; floors 1/64, 1/16, 1/8, 1/4, 1/2): 7.2e-11 / 7.3e-11 / 6.6e-11 / 6.7e-11 /
/// 6.3e-10 s, 5.9e-10 / 5.3e-10 / 4.1e-10 / 2.8e-10 / 4.5e-9 s, 4.8e-9 / 4.5e-9 / 3.6e-9 /
/// 4.7e-9 / 4.7e-8 s: the floor's own error shows only at a half, and an eighth keeps a factor
/// of two from it (docs/DECISIONS.md, "Multirate scheme of the multibody engine").
pub(super) const ALONE_KINK_FLOOR_DIVISOR: f64 = 8.0;

/// The sub-step a coupling in contact takes, s, given the step controller's `want` (s): graded
/// towards the law's two kinks.
///
/// At an onset the load grows as `t^1.5` from the landed onset (and falls as `(t_off - t)^1.5`
/// to the separation), whose derivatives beyond the first are unbounded there: the classical
/// method's error in the impulse of the step touching the kink is of order `h^2.5`, not `h^5`,
/// and it dominates the whole impact's (measured on the 8-disc staggered pack at 128 steps
/// per contact: the early onsets 1.7e-9 s off the reference at tolerance 1e-12, falling only
/// as `h^2.5 .. h^3` with more steps). A graded mesh, `h <= KINK_GRADE * (t - t_on)` after
/// the onset and `h <= KINK_GRADE * s / |v_n|` (the predicted time to separation) while the
/// depth falls, never below `want / floor_divisor` ([`KINK_FLOOR_DIVISOR`],
/// [`ALONE_KINK_FLOOR_DIVISOR`]), spreads that error over a few geometrically growing steps:
/// measured 2.6e-11 s, 67x less, for about 30 more sub-steps per impact (`KINK_GRADE` 0.15
/// and 0.5 measured 2.4e-11 and 4.9e-11 s).
#[inline]
pub(super) fn graded_step(
    want: f64,
    f: &CouplingForces,
    age_s: Option<f64>,
    floor_divisor: f64,
) -> f64 {
    if f.depth_m <= 0.0 {
        return want;
    }
    let floor = want / floor_divisor;
    let mut h = want;
    if let Some(age) = age_s {
        h = h.min((KINK_GRADE * age).max(floor));
    }
    let v = f.kin.v_n_m_s;
    if v < 0.0 {
        h = h.min((KINK_GRADE * f.depth_m / -v).max(floor));
    }
    h
}

/// The sub-step `want` (s) a controller asked for at `t` (s), or the run's failure when it
/// collapsed below the smallest step (or is not a number); `who()` names what asked.
#[inline]
pub(super) fn checked_sub_step(
    want: f64,
    a: &AdaptiveStepping,
    t: f64,
    who: impl FnOnce() -> String,
) -> Result<f64, EngineError> {
    if want.is_nan() || want < a.min_step_s {
        return Err(EngineError::Diverged {
            t_s: t,
            reason: format!("{}: the sub-step collapsed to {want:.3e} s", who()),
        });
    }
    Ok(want)
}

/// The next (sub-)step, s, towards an end `rem` s away when the controller wants `want` s:
/// the rest if `want` covers it, half of it if `want` covers more than half (two even steps
/// rather than a long one and a sliver), else `want`.
pub(super) fn split_remainder(want: f64, rem: f64) -> f64 {
    if want >= rem {
        rem
    } else if want > 0.5 * rem {
        0.5 * rem
    } else {
        want
    }
}

/// The buffers of the one classical Runge-Kutta step of the multirate schemes
/// ([`Rk4::rk4`]): each body's accelerations at the four stages, the stages' turns and speeds
/// (scratch), the powers' partial sums over the stages, and the step's result. `V` holds one
/// value per body, `P` one per power the scheme integrates: `[f64; 1]` and `[f64; 3]` for a
/// coupling alone (no allocation on its hot path), `Vec<f64>`s for a system (allocated once
/// per world step, [`Rk4::new`]).
#[derive(Debug, Clone, Default)]
pub(super) struct Rk4<V, P> {
    /// Each body's acceleration at the four stages, rad/s^2.
    k: [V; 4],
    /// Each body's turn from the start, rad, and speed, rad/s, at the stage being evaluated
    /// (scratch).
    th: V,
    x: V,
    /// Each power's sum at the two middle stages, and a stage's powers (W, or N m for an
    /// impulse; scratch).
    mid: P,
    p: P,
    /// Each body's turn over the step, rad, and its speed at the end, rad/s.
    pub(super) turn: V,
    pub(super) u1: V,
    /// Each power's integral over the step, J (N m s for an impulse; its value at the first
    /// stage along the step).
    pub(super) work: P,
}

impl Rk4<Vec<f64>, Vec<f64>> {
    /// The buffers for `n` bodies and `powers` powers.
    pub(super) fn new(n: usize, powers: usize) -> Rk4<Vec<f64>, Vec<f64>> {
        let v = || vec![0.0; n];
        let p = || vec![0.0; powers];
        Rk4 {
            k: [v(), v(), v(), v()],
            th: v(),
            x: v(),
            mid: p(),
            p: p(),
            turn: v(),
            u1: v(),
            work: p(),
        }
    }
}

impl<V: AsMut<[f64]>, P: AsMut<[f64]>> Rk4<V, P> {
    /// The one classical Runge-Kutta step of the multirate schemes (Kutta 1901: nodes 0, 1/2,
    /// 1/2, 1, weights 1/6, 1/3, 1/3, 1/6), of length `h` from `t`, of the bodies' motion
    /// `theta' = u`, `u' = a(t, theta - theta(t), u)` from their speeds `u0`, with the works
    /// of the scheme's powers integrated by the same stages (the augmented system, so that
    /// the audit closes to the method's order). A coupling alone against its carrier's path
    /// ([`Relative::step`]), an inertial carrier with its cluster (`inertial.rs`) and the
    /// clamped stack with its inertial carriers (`clamped.rs`) each give their right-hand side
    /// as `stage(s, ts, th, u, acc, power)`, which writes into `acc` the bodies' accelerations
    /// and into `power` the powers at stage `s` (0 to 3) at `ts`, the bodies turned by `th`
    /// (rad) from `t` and turning at `u` (rad/s).
    ///
    /// Written for the angle, as the method on the first-order system (angle, speed) gives
    /// it: each body turns by `h u0 + h^2/6 (k1 + k2 + k3)` and ends at
    /// `u0 + h/6 (k1 + 2 k2 + 2 k3 + k4)`; each power `p` does the work
    /// `h/6 (p1 + 2 (p2 + p3) + p4)` (the one energy quadrature of the multirate schemes).
    pub(super) fn rk4(
        &mut self,
        t: f64,
        h: f64,
        u0: &[f64],
        mut stage: impl FnMut(usize, f64, &[f64], &[f64], &mut [f64], &mut [f64]),
    ) {
        let hh = h * h;
        let (tm, te) = (t + 0.5 * h, t + h);
        let Rk4 {
            k,
            th,
            x,
            mid,
            p,
            turn,
            u1,
            work,
        } = self;
        let [k1, k2, k3, k4] = k.each_mut().map(|x| x.as_mut());
        let (th, x, turn, u1) = (th.as_mut(), x.as_mut(), turn.as_mut(), u1.as_mut());
        let (mid, p, work) = (mid.as_mut(), p.as_mut(), work.as_mut());
        let n = u0.len();
        let ([k1, k2, k3, k4], th, x, turn, u1) = (
            [&mut k1[..n], &mut k2[..n], &mut k3[..n], &mut k4[..n]],
            &mut th[..n],
            &mut x[..n],
            &mut turn[..n],
            &mut u1[..n],
        );
        th.fill(0.0);
        // the powers folded as they come (p1 in `work`, p2 + p3 in `mid`): the quadrature's
        // own sums in its own order, in three buffers rather than five
        stage(0, t, th, u0, k1, work);
        for i in 0..n {
            th[i] = 0.5 * h * u0[i];
            x[i] = u0[i] + 0.5 * h * k1[i];
        }
        stage(1, tm, th, x, k2, mid);
        for i in 0..n {
            th[i] = 0.5 * h * u0[i] + 0.25 * hh * k1[i];
            x[i] = u0[i] + 0.5 * h * k2[i];
        }
        stage(2, tm, th, x, k3, p);
        for (m, &p3) in mid.iter_mut().zip(&*p) {
            *m += p3;
        }
        for i in 0..n {
            th[i] = h * u0[i] + 0.5 * hh * k2[i];
            x[i] = u0[i] + h * k3[i];
        }
        stage(3, te, th, x, k4, p);
        let h6 = h / 6.0;
        for i in 0..n {
            turn[i] = h * u0[i] + h * h6 * (k1[i] + k2[i] + k3[i]);
            u1[i] = u0[i] + h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        for ((w, &m), &p4) in work.iter_mut().zip(&*mid).zip(&*p) {
            *w = h6 * (*w + 2.0 * m + p4);
        }
    }
}

/// `v` cut into consecutive slices of the lengths `lens` (a scheme's powers by kind).
#[inline]
pub(super) fn cut<const K: usize>(mut v: &mut [f64], lens: [usize; K]) -> [&mut [f64]; K] {
    lens.map(|n| {
        let (a, rest) = std::mem::take(&mut v).split_at_mut(n);
        v = rest;
        a
    })
}

/// One sub-step's outcome: the relative state at its end and the work done along it.
#[derive(Debug, Clone, Copy)]
pub(super) struct SubStep {
    /// The shaft at its end.
    pub(super) shaft: ShaftAt,
    pub(super) phi: f64,
    pub(super) dphi: f64,
    /// Work of the shaft on the teeth, `integral T dtheta_s`, J.
    pub(super) drive_j: f64,
    /// Work of the oil drag on the disc, J (<= 0).
    pub(super) drag_j: f64,
    /// Work of the open gaps' drag on the body, J.
    pub(super) gap_j: f64,
    /// Tooth-law evaluations it took.
    pub(super) evals: u64,
}

/// A coupling's body on its carrier at the stages of a sub-step: the one body law of the
/// steps of a coupling alone ([`Relative::step`]) and of an inertial carrier's cluster
/// (`Run::carrier_step`), Hu et al. eq (5) with the open gaps' drag,
/// `J omega_d' = T(phi, phi') - C2 omega_d + g(omega_d)`. (The clamped stack's bodies sum
/// their torques over the groups their locked faces make, `clamped.rs`.)
#[derive(Clone, Copy)]
pub(super) struct Carried<'a> {
    /// The coupling (its teeth).
    pub(super) coupling: &'a Coupling,
    /// The relative angle at the sub-step's start, rad.
    pub(super) phi: f64,
    /// The body's inverse inertia about the axis, 1/(kg m^2), and its drag `C2`, N m s/rad.
    pub(super) inv_j: f64,
    pub(super) c2: f64,
    /// The open gaps' drag on the body.
    pub(super) gap: &'a GapDrag,
}

impl Carried<'_> {
    /// The body's acceleration, rad/s^2, at `ts` (s) turning at `u` (rad/s) with the teeth's
    /// torque `torque` (N m) on it, and the open gaps' drag on it there, N m.
    pub(super) fn accel(&self, ts: f64, torque: f64, u: f64) -> (f64, f64) {
        let gap = self.gap.torque(ts, u);
        ((torque - self.c2 * u + gap) * self.inv_j, gap)
    }

    /// The teeth's torque on the body, N m, its acceleration, rad/s^2, and the open gaps'
    /// drag on it, N m, at a stage at `ts`: the carrier turned by `turn` (rad) from the
    /// sub-step's start and turning at `speed` (rad/s), the body turned by `th` and turning
    /// at `u`.
    pub(super) fn stage(&self, ts: f64, turn: f64, speed: f64, th: f64, u: f64) -> (f64, f64, f64) {
        let torque = self.coupling.probe_torque(self.phi + turn - th, speed - u);
        let (acc, gap) = self.accel(ts, torque, u);
        (torque, acc, gap)
    }
}

/// The relative motion of one coupling on a prescribed shaft, integrated as the disc's own
/// motion `J omega_d' = T(phi, phi') - C2 omega_d` (Hu et al. eq (5)) with
/// `phi = theta_s(t) - theta_d`, `phi' = omega_s(t) - omega_d` (eq (3): the shaft's angle and
/// speed are the profile's, exact). Integrating the disc rather than the relative angle
/// leaves the shaft's motion out of the truncation error: in free flight without drag the
/// disc turns at a constant speed and the sub-step is exact whatever its length (integrating
/// the relative angle with the classical method costs `a_s''' h^5 / 720` per step: at 104 Hz
/// and 0.1 ms, 1e-11 rad, enough to move the onsets of a chaotic rattle by microseconds
/// within 40 ms).
pub(super) struct Relative<'a> {
    /// The carrier's motion over the world step.
    pub(super) path: Path<'a>,
    pub(super) coupling: &'a Coupling,
    /// The disc's inverse inertia about the axis, from its rapier mass properties, 1/(kg m^2).
    pub(super) inv_j: f64,
    /// Drag coefficient `C2`, N m s/rad.
    pub(super) c2: f64,
    /// The open gaps' drag on the body.
    pub(super) gap: GapDrag,
    /// The teeth's torque on the disc at the step's start, N m (the first stage's; the hook's
    /// evaluation of the last sub-step's end, or a probe at a world step's start).
    pub(super) start_torque_n_m: f64,
}

impl Relative<'_> {
    /// One classical Runge-Kutta step ([`Rk4::rk4`]) of length `h` from `(phi, dphi)` at `t`,
    /// with the work of the drive, the drag and the gaps integrated by the same stages.
    pub(super) fn step(&self, t: f64, shaft: ShaftAt, phi: f64, dphi: f64, h: f64) -> SubStep {
        let p = self.path;
        let (tm, te) = (t + 0.5 * h, t + h);
        let (mid, end) = (p.at(tm), p.at(te));
        let (w0, wm, we) = (shaft.speed, mid.speed, end.speed);
        // The shaft's turn from t, exact.
        let (sm, se) = (mid.angle - shaft.angle, end.angle - shaft.angle);
        // The disc's speed at t.
        let u0 = w0 - dphi;
        // Hu et al. eq (5): J omega_d' = T - C2 omega_d, plus the open gaps' drag
        let body = Carried {
            coupling: self.coupling,
            phi,
            inv_j: self.inv_j,
            c2: self.c2,
            gap: &self.gap,
        };
        // the powers: the shaft's on the teeth, the disc's speed squared (the drag's, over
        // -C2), the gaps' drag's
        let mut rk = Rk4::<[f64; 1], [f64; 3]>::default();
        // a stage: the teeth's torque at the start given, else probed with the shaft turned
        // from t at its speed there (exact) and the disc turned by `th` at `u`
        rk.rk4(t, h, &[u0], |s, ts, th, u, acc, power| {
            let (u, speed) = (u[0], [w0, wm, wm, we][s]);
            let (torque, a, g) = if s == 0 {
                let torque = self.start_torque_n_m;
                let (a, g) = body.accel(ts, torque, u);
                (torque, a, g)
            } else {
                let turn = if s < 3 { sm } else { se };
                body.stage(ts, turn, speed, th[0], u)
            };
            acc[0] = a;
            power.copy_from_slice(&[torque * speed, u * u, g * u]);
        });
        let [drive, sq, gap_j] = rk.work;
        SubStep {
            shaft: end,
            phi: phi + se - rk.turn[0],
            dphi: we - rk.u1[0],
            drive_j: drive,
            drag_j: -self.c2 * sq,
            gap_j,
            evals: 3,
        }
    }
}

/// The prescribed shaft at one time: its speed (rad/s) and unwrapped angle (rad), each
/// evaluated once (a sub-step's end is the next one's start; the profile's trigonometry was a
/// third of the scheme's time).
#[derive(Debug, Clone, Copy)]
pub(super) struct ShaftAt {
    /// The carrier's speed, rad/s, and angle, rad.
    pub(super) speed: f64,
    pub(super) angle: f64,
}

impl ShaftAt {
    /// The carrier at `t`: the prescribed shaft, or the housing at rest (`None`).
    pub(super) fn of(p: Option<Prescribed<'_>>, t: f64) -> ShaftAt {
        match p {
            Some(p) => p.at(t),
            None => ShaftAt {
                speed: 0.0,
                angle: 0.0,
            },
        }
    }
}

/// The prescribed shaft over one world step as its sub-steps see it: its profile, and the
/// profile expanded about the step's middle when it has harmonics
/// ([`clutchpack_model::LocalProfile`]: the same speed and angle to rounding, without the
/// `sincos` per harmonic and per stage that was 15 % of a brake pack's run).
#[derive(Debug, Clone, Copy)]
pub(super) struct Prescribed<'a> {
    pub(super) profile: &'a SpeedProfile,
    pub(super) local: Option<&'a LocalProfile>,
}

impl Prescribed<'_> {
    /// The shaft at `t` (within the world step of the expansion).
    #[inline]
    pub(super) fn at(self, t: f64) -> ShaftAt {
        let (speed, angle) = match self.local {
            Some(l) => l.speed_and_angle(t),
            None => self.profile.speed_and_angle(t),
        };
        ShaftAt { speed, angle }
    }
}

/// An inertial carrier (shaft, drum) at a sub-step's end: time, s, unwrapped angle, rad,
/// speed, rad/s (the nodes of [`Path::Nodes`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Node {
    /// Time, s; the carrier's angle, rad, and speed, rad/s, there.
    pub(super) t: f64,
    pub(super) angle: f64,
    pub(super) speed: f64,
}

/// A carrier's motion over a world step as a coupling's sub-steps see it: a prescribed
/// shaft's profile, the housing at rest, or an inertial carrier's (shaft, drum) motion
/// integrated over the step ([`Run::integrate_carrier`]) given by its nodes: exact at them,
/// the cubic Hermite interpolant of angle and speed between them (used by couplings in free
/// flight, whose motion does not depend on the carrier's: only their depth, for the landing,
/// does).
#[derive(Debug, Clone, Copy)]
pub(super) enum Path<'a> {
    Profile(Prescribed<'a>),
    Housing,
    Nodes(&'a [Node]),
}

impl Path<'_> {
    /// The carrier at `t` (inlined: the call spilled the step's registers; nodes out of line).
    #[inline(always)]
    pub(super) fn at(self, t: f64) -> ShaftAt {
        match self {
            Path::Profile(p) => p.at(t),
            Path::Housing => ShaftAt::of(None, t),
            Path::Nodes(n) => Path::nodes_at(n, t),
        }
    }

    /// An inertial carrier at `t` from its nodes: exact at one, cubic Hermite between two.
    #[inline(never)]
    fn nodes_at(n: &[Node], t: f64) -> ShaftAt {
        let k = n.partition_point(|x| x.t < t);
        if k < n.len() && n[k].t == t {
            return ShaftAt {
                speed: n[k].speed,
                angle: n[k].angle,
            };
        }
        let k = k.clamp(1, n.len() - 1);
        let (a, b) = (n[k - 1], n[k]);
        let h = b.t - a.t;
        let s = (t - a.t) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (
            2.0 * s3 - 3.0 * s2 + 1.0,
            s3 - 2.0 * s2 + s,
            -2.0 * s3 + 3.0 * s2,
            s3 - s2,
        );
        // the derivative of the cubic, per unit time
        let (d00, d10, d01, d11) = (
            6.0 * (s2 - s),
            3.0 * s2 - 4.0 * s + 1.0,
            6.0 * (s - s2),
            3.0 * s2 - 2.0 * s,
        );
        ShaftAt {
            angle: h00 * a.angle + h10 * h * a.speed + h01 * b.angle + h11 * h * b.speed,
            speed: (d00 * a.angle + d01 * b.angle) / h + d10 * a.speed + d11 * b.speed,
        }
    }
}

#[cfg(test)]
mod tests;
