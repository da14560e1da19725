//! The multirate scheme (crate docs, "Theory"): the rapier world steps at free-flight length
//! and every spline coupling integrates its own relative motion inside the world's step, with
//! its own contact-aware sub-steps; the tooth impulse of the step is handed to the disc's
//! rapier body, which carries the disc's state from one world step to the next.

use super::state::{disc_sample, relative_state, Run, ShaftDrive};
use crate::hook::{Coupling, CouplingForces, RelativeState, FLANKS};
use crate::options::{AdaptiveStepping, MultibodyOptions, Stepping};
use crate::stepping::{bracketed_root, contact_duration_s, coupling_step, CouplingView};
use crate::world::Carrier;
use clutchpack_model::{DiscSample, EngineError, ImpactEvent, PackModel, Shaft, SpeedProfile};
use rapier3d_f64::prelude::{Rotation, Vector};

/// Why the multirate scheme cannot run this pack with these options (`None`: it can).
///
/// It needs the bodies to be independent within a world step but for weak couplings: each
/// friction disc coupled by its teeth only to a prescribed shaft and each separator plate only
/// to the fixed housing (carriers whose motion is known in advance), turning about the axis
/// only; neighbours in an open stack (the piston never clamps it) pull on each other only
/// through the oil gaps' Couette drag, which a world step holds (see [`GapDrag`]).
pub(super) fn unsupported(
    pack: &PackModel,
    options: &MultibodyOptions,
    per_tooth: &[bool],
) -> Option<&'static str> {
    if !matches!(options.stepping, Stepping::Adaptive(_)) {
        return Some("fixed steps (the check mode) step the whole world at dt");
    }
    if !matches!(pack.shaft, Shaft::Prescribed(_))
        && (pack.drum.is_some() || pack.stack.is_some() || !pack.plates.is_empty())
    {
        return Some(
            "an inertial shaft (eq 4) runs multirate with friction discs only (no plates, \
             drum or stack)",
        );
    }
    if pack.drum.is_some() {
        return Some("a drum couples its plates within a step through its inertia");
    }
    if let Some(stack) = &pack.stack {
        if piston_can_clamp(stack) {
            return Some(
                "a clamped stack (the piston's force exceeds its return spring) couples the \
                 bodies within a step through the faces' friction",
            );
        }
    } else if !pack.plates.is_empty() {
        return Some("separator plates without a stack");
    }
    if per_tooth.iter().any(|&p| p) {
        return Some(
            "per-tooth couplings (radial float, eccentric discs, spacing errors) move off the \
             axis or need every tooth's contact memory along the sub-steps",
        );
    }
    None
}

/// Whether the piston's force can ever exceed its return spring (a clamped stack), from the
/// largest pressure of its profile.
fn piston_can_clamp(stack: &clutchpack_model::StackModel) -> bool {
    use clutchpack_model::PressureProfile as P;
    let p = &stack.piston;
    let max_pa = match &p.pressure {
        P::Constant { pressure_pa } | P::Ramp { pressure_pa, .. } => *pressure_pa,
        P::Table(t) => t.y.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    };
    max_pa * p.area_m2 > p.return_spring_n
}

/// The open gaps' drag on one body over a world step, `sum_nb c (w_nb - w)` (Couette, MODEL.md
/// section 5): the neighbours' speeds held at their predicted mean over the step (see
/// `Run::multirate_step`), the body's own speed taken along its sub-steps (the damping `c`
/// per gap on its own speed is exact within the step; the neighbours' are a coupling with a
/// time constant `J / c` of seconds against a world step of 0.1 ms).
#[derive(Debug, Clone, Copy, Default)]
struct GapDrag {
    /// `c sum_nb w_nb`, N m.
    held_n_m: f64,
    /// `c` times the number of neighbours, N m s/rad.
    damping: f64,
}

/// Sub-steps near a kink of the `s^1.5` law are at most this fraction of the time from the
/// onset or to the separation (dimensionless). See [`graded_step`].
const KINK_GRADE: f64 = 0.25;

/// ... and at least the contact step over this (dimensionless).
const KINK_FLOOR_DIVISOR: f64 = 64.0;

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
/// depth falls, never below `want / KINK_FLOOR_DIVISOR`, spreads that error over a few
/// geometrically growing steps: measured 2.6e-11 s, 67x less, for about 30 more sub-steps per
/// impact (`KINK_GRADE` 0.15 and 0.5 measured 2.4e-11 and 4.9e-11 s).
fn graded_step(want: f64, f: &CouplingForces, age_s: Option<f64>) -> f64 {
    if f.depth_m <= 0.0 {
        return want;
    }
    let floor = want / KINK_FLOOR_DIVISOR;
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

/// One sub-step's outcome: the relative state at its end and the work done along it.
#[derive(Debug, Clone, Copy)]
struct SubStep {
    /// The shaft at its end.
    shaft: ShaftAt,
    phi: f64,
    dphi: f64,
    /// Work of the shaft on the teeth, `integral T dtheta_s`, J.
    drive_j: f64,
    /// Work of the oil drag on the disc, J (<= 0).
    drag_j: f64,
    /// Work of the open gaps' drag on the body, J.
    gap_j: f64,
    /// Tooth-law evaluations it took.
    evals: u64,
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
struct Relative<'a> {
    /// The carrier's motion over the world step.
    path: Path<'a>,
    coupling: &'a Coupling,
    /// The disc's inverse inertia about the axis, from its rapier mass properties, 1/(kg m^2).
    inv_j: f64,
    /// Drag coefficient `C2`, N m s/rad.
    c2: f64,
    /// The open gaps' drag on the body.
    gap: GapDrag,
}

impl Relative<'_> {
    /// One classical Runge-Kutta step of length `h` from `(phi, dphi)` at `t`, with the work
    /// of the drive and the drag integrated by the same stages (the augmented system).
    fn rk4(&self, t: f64, shaft: ShaftAt, phi: f64, dphi: f64, h: f64) -> SubStep {
        let p = self.path;
        let (tm, te) = (t + 0.5 * h, t + h);
        let (mid, end) = (p.at(tm), p.at(te));
        let gap = self.gap;
        let (w0, wm, we) = (shaft.speed, mid.speed, end.speed);
        // The shaft's turn from t, exact.
        let (sm, se) = (mid.angle - shaft.angle, end.angle - shaft.angle);
        // The disc's speed at t; `th` below is its turn from t.
        let u0 = w0 - dphi;
        // (omega_d', teeth torque) at a stage: the shaft turned by `s` at speed `ws`, the
        // disc turned by `th` at speed `u`.
        let f = |s: f64, ws: f64, th: f64, u: f64| {
            let torque = self.coupling.probe_torque(phi + s - th, ws - u);
            // Hu et al. eq (5): J omega_d' = T - C2 omega_d, plus the open gaps' drag
            let g = gap.held_n_m - gap.damping * u;
            ((torque - self.c2 * u + g) * self.inv_j, torque)
        };
        let hh = h * h;
        let (k1, t1) = f(0.0, w0, 0.0, u0);
        let u2 = u0 + 0.5 * h * k1;
        let (k2, t2) = f(sm, wm, 0.5 * h * u0, u2);
        let u3 = u0 + 0.5 * h * k2;
        let (k3, t3) = f(sm, wm, 0.5 * h * u0 + 0.25 * hh * k1, u3);
        let u4 = u0 + h * k3;
        let (k4, t4) = f(se, we, h * u0 + 0.5 * hh * k2, u4);
        let h6 = h / 6.0;
        // The classical method on the first-order system (angle, speed), written for the
        // angle: the disc turns by h u0 + h^2/6 (k1 + k2 + k3).
        let th = h * u0 + h * h6 * (k1 + k2 + k3);
        let u1 = u0 + h6 * (k1 + 2.0 * (k2 + k3) + k4);
        SubStep {
            shaft: end,
            phi: phi + se - th,
            dphi: we - u1,
            drive_j: h6 * (t1 * w0 + 2.0 * (t2 + t3) * wm + t4 * we),
            drag_j: -self.c2 * h6 * (u0 * u0 + 2.0 * (u2 * u2 + u3 * u3) + u4 * u4),
            gap_j: h6
                * ((gap.held_n_m - gap.damping * u0) * u0
                    + 2.0
                        * ((gap.held_n_m - gap.damping * u2) * u2
                            + (gap.held_n_m - gap.damping * u3) * u3)
                    + (gap.held_n_m - gap.damping * u4) * u4),
            evals: 4,
        }
    }
}

/// The prescribed shaft at one time: its speed (rad/s) and unwrapped angle (rad), each
/// evaluated once (a sub-step's end is the next one's start; the profile's trigonometry was a
/// third of the scheme's time).
#[derive(Debug, Clone, Copy)]
struct ShaftAt {
    speed: f64,
    angle: f64,
}

impl ShaftAt {
    /// The carrier at `t`: the shaft's profile, or the housing at rest (`None`).
    fn of(p: Option<&SpeedProfile>, t: f64) -> ShaftAt {
        match p {
            Some(p) => ShaftAt {
                speed: p.speed(t),
                angle: p.angle(t),
            },
            None => ShaftAt {
                speed: 0.0,
                angle: 0.0,
            },
        }
    }
}

/// The inertial shaft at a sub-step's end: time, s, unwrapped angle, rad, speed, rad/s (the
/// nodes of [`Path::Nodes`]).
#[derive(Debug, Clone, Copy)]
struct Node {
    t: f64,
    angle: f64,
    speed: f64,
}

/// A carrier's motion over a world step as a coupling's sub-steps see it: a prescribed
/// shaft's profile, the housing at rest, or an inertial shaft's motion already integrated
/// over the step ([`Run::integrate_shaft`]) given by its nodes: exact at them, the cubic
/// Hermite interpolant of angle and speed between them (used by couplings in free flight,
/// whose motion does not depend on the shaft's: only their depth, for the landing, does).
#[derive(Debug, Clone, Copy)]
enum Path<'a> {
    Profile(&'a SpeedProfile),
    Housing,
    Nodes(&'a [Node]),
}

impl Path<'_> {
    /// The carrier at `t`.
    fn at(self, t: f64) -> ShaftAt {
        match self {
            Path::Profile(p) => ShaftAt::of(Some(p), t),
            Path::Housing => ShaftAt::of(None, t),
            Path::Nodes(n) => {
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
    }
}

/// What the multirate loop counts in a run.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Counts {
    /// Sub-steps taken by all couplings together.
    pub(super) substeps: u64,
    /// Tooth-law evaluations (stages, landings, the evaluation at each sub-step's end).
    pub(super) evals: u64,
    /// Inertial shaft: couplings that touched within a world step they were predicted to
    /// fly through (integrated against the shaft's motion without their own reaction on it).
    pub(super) missed: u64,
}

impl Run {
    /// The speed profile of coupling `i`'s carrier: the prescribed shaft's (the multirate
    /// scheme runs only on one), `None` for the housing (at rest).
    fn profile(&self, i: usize) -> Option<std::sync::Arc<SpeedProfile>> {
        match (self.world.carriers[i], &self.shaft) {
            (Carrier::Shaft, ShaftDrive::Prescribed(p)) => Some(std::sync::Arc::clone(p)),
            (Carrier::Shaft, ShaftDrive::Inertial { .. }) => {
                unreachable!("the multirate scheme needs a prescribed shaft")
            }
            (Carrier::Housing, _) => None,
            (Carrier::Drum, _) => unreachable!("the multirate scheme runs no drum"),
        }
    }

    /// The open gaps' Couette coefficient `c` (torque per slip), N m s/rad; 0 without a stack
    /// or without oil in the gaps.
    fn gap_coefficient(&self) -> f64 {
        -self
            .pack
            .stack
            .as_ref()
            .map_or(0.0, |m| m.open_gap_torque_n_m(1.0))
    }

    /// The open gaps' drag on every coupling body over a world step from `t` ([`GapDrag`];
    /// zero without a stack), with the neighbours' speeds `w` (rad/s, coupling order).
    fn gap_drags(&self, w: &[f64]) -> Vec<GapDrag> {
        let mut g = vec![GapDrag::default(); self.couplings.len()];
        let Some(stack) = &self.stack else { return g };
        let c = self.gap_coefficient();
        for m in 0..stack.interfaces() {
            let (lo, up) = (stack.body[m], stack.body[m + 1]);
            g[lo].held_n_m += c * w[up];
            g[lo].damping += c;
            g[up].held_n_m += c * w[lo];
            g[up].damping += c;
        }
        g
    }

    /// Advances the run from `t` to `t1` by the multirate scheme: every coupling sub-steps its
    /// relative motion over `[t, t1]`, then the rapier world takes one step of `t1 - t` with
    /// each disc's tooth impulse. Impact events that closed go to `closed` (in the order they
    /// closed within each coupling), the contact samples `(coupling, t s, state)` of the
    /// sub-steps to `contacts` (in time order within each coupling; see
    /// `EventBook::update`).
    pub(super) fn multirate_step(
        &mut self,
        t1: f64,
        a: &AdaptiveStepping,
        counts: &mut Counts,
        closed: &mut Vec<ImpactEvent>,
        contacts: &mut Vec<(usize, f64, DiscSample)>,
    ) -> Result<(), EngineError> {
        if let ShaftDrive::Inertial { c1, .. } = self.shaft {
            return self.multirate_step_inertial(t1, a, c1, counts, closed, contacts);
        }
        let t0 = self.t;
        let h = t1 - t0;
        let ShaftDrive::Prescribed(shaft_profile) = &self.shaft else {
            unreachable!("the multirate scheme needs a prescribed shaft")
        };
        let theta_s1 = shaft_profile.angle(t1);
        let omega_s1 = shaft_profile.speed(t1);
        // The open gaps' drag: the discs first, with their neighbours (plates, which turn
        // slowly) at their mean speed over the step predicted from their acceleration at t
        // (teeth, gaps, drag; second order where it is smooth); then the plates, with their
        // neighbours (discs) at the discs' mean speeds over the step just integrated: the
        // plates' only drive is the gaps' drag, and a disc's speed jumps within a step at its
        // impacts. Measured on the open 8-disc brake against the reference engine at 1e-12
        // over 25 ms: worst onset 0.43 us at the default world step of 0.1 ms, 0.13 us at
        // 0.05 ms (1.65 us and 1.06 us with every neighbour held at its speed at t).
        let n_discs = self.pack.discs.len();
        let mut gaps = self.gap_drags(&self.omega_d);
        if self.stack.is_some() {
            // the plates' predicted mean speeds, for the discs
            let w: Vec<f64> = (0..self.couplings.len())
                .map(|j| {
                    let w = self.omega_d[j];
                    if j < n_discs {
                        return w;
                    }
                    let d = &self.bodies[j];
                    let torque = self.forces[j].moment[2] + gaps[j].held_n_m
                        - (gaps[j].damping + d.drag_n_m_s_rad) * w;
                    w + 0.5 * h * torque / d.inertia_kg_m2
                })
                .collect();
            gaps = self.gap_drags(&w);
        }
        let mut means = Vec::with_capacity(self.couplings.len());
        self.potential_j = 0.0;
        for i in 0..self.couplings.len() {
            if i == n_discs && self.stack.is_some() {
                let w: Vec<f64> = (0..self.couplings.len())
                    .map(|j| {
                        if j < n_discs {
                            means[j]
                        } else {
                            self.omega_d[j]
                        }
                    })
                    .collect();
                gaps = self.gap_drags(&w);
            }
            let phi0 = self.rel[i].phi;
            let p = self.profile(i);
            let (path, bound) = match p.as_deref() {
                Some(p) => (Path::Profile(p), self.shaft_accel_bound),
                None => (Path::Housing, 0.0),
            };
            self.integrate_coupling(i, t1, a, gaps[i], path, bound, counts, closed, contacts)?;
            let (phi1, dphi1) = (self.rel[i].phi, self.rel[i].dphi);
            let (c0, c1) = (path.at(t0), path.at(t1));
            self.omega_d[i] = c1.speed - dphi1;
            self.potential_j += self.forces[i].potential_j;
            // The body's mean speed over the step: it turns with its carrier less the change
            // of the relative angle.
            means.push((c1.angle - c0.angle - (phi1 - phi0)) / h);
        }
        let c = self.gap_coefficient();
        if let Some(s) = self.stack.as_mut() {
            // Each interface's share of the gaps' work, from the bodies' mean speeds over the
            // step (the bodies' own audit is exact along their sub-steps).
            for m in 0..s.interfaces() {
                let slip = means[s.body[m + 1]] - means[s.body[m]];
                s.impulse[m] = -c * slip * h;
                s.dissipated_j[m] += c * slip * slip * h;
            }
            s.record_open_step(h);
        }
        // The world's step: each disc's impulse in two halves, `J (mean - w(t))` applied as a
        // torque over the step (rapier's semi-implicit Euler then drifts the disc by
        // exactly `mean h`) and `J (w(t1) - mean)` as the speed set at its end.
        let bodies = &mut self.world.physics.bodies;
        for (i, &mean) in means.iter().enumerate() {
            let body = &mut bodies[self.world.discs[i]];
            let inv_j = body.mass_properties().local_mprops.inv_principal_inertia.z;
            let torque = (mean - body.angvel().z) / (h * inv_j);
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_torque(Vector::new(0.0, 0.0, torque), false);
        }
        bodies[self.world.shaft].set_next_kinematic_rotation(Rotation::from_rotation_z(theta_s1));
        self.world.step(h);
        let bodies = &mut self.world.physics.bodies;
        for i in 0..self.couplings.len() {
            let body = &mut bodies[self.world.discs[i]];
            body.set_angvel(Vector::new(0.0, 0.0, self.omega_d[i]), false);
        }
        self.t_prev = Some(t0);
        self.t = t1;
        self.theta_s = theta_s1;
        self.omega_s = omega_s1;
        Ok(())
    }

    /// Reads every coupling's relative state at `t` from the rapier bodies (the state each
    /// coupling's sub-steps start from).
    pub(super) fn read_relative_states(&mut self) {
        let bodies = &self.world.physics.bodies;
        for i in 0..self.couplings.len() {
            let disc = &bodies[self.world.discs[i]];
            self.rel[i] = relative_state(
                &bodies[self.carrier_body(i)],
                self.carrier_speed(i),
                disc,
                disc.angvel().z,
                self.world.disc_turn_owed_z(i),
            );
            self.omega_d[i] = disc.angvel().z;
        }
    }

    /// Sub-steps coupling `i` from `t` (its state in `rel[i]`, its forces in `forces[i]`) to
    /// `t1`, with the step controller of the shared scheme applied to this coupling alone and
    /// steps landed on every contact onset and separation; leaves the state at `t1` in
    /// `rel[i]` and `forces[i]`, adds the work done to the energy audit and feeds the events.
    #[allow(clippy::too_many_arguments)]
    fn integrate_coupling(
        &mut self,
        i: usize,
        t1: f64,
        a: &AdaptiveStepping,
        gap: GapDrag,
        path: Path<'_>,
        carrier_accel_bound: f64,
        counts: &mut Counts,
        closed: &mut Vec<ImpactEvent>,
        contacts: &mut Vec<(usize, f64, DiscSample)>,
    ) -> Result<(), EngineError> {
        let bodies = std::sync::Arc::clone(&self.bodies);
        let d = &bodies[i];
        let inv_j = self.world.physics.bodies[self.world.discs[i]]
            .mass_properties()
            .local_mprops
            .inv_principal_inertia
            .z;
        let (g0, rb) = (d.spline.half_play_rad(), d.spline.base_radius_m());
        let offset = d.law.engagement_offset_m();
        let m_eff = self.m_eff[i];
        // On an inertial shaft the teeth's work is internal (the drive's is the shaft's,
        // integrated with it) and a coupling integrated here is in free flight (the others
        // go with the shaft, `integrate_shaft`): one that touches all the same is counted.
        let inertial = matches!(path, Path::Nodes(_));
        let mut missed = false;
        let mut t = self.t;
        let (mut phi, mut dphi) = (self.rel[i].phi, self.rel[i].dphi);
        let mut shaft = path.at(t);
        while t < t1 {
            let f = self.forces[i];
            let wd = shaft.speed - dphi;
            let view = CouplingView {
                forces: &f,
                law: &d.law,
                phi,
                dphi,
                g0,
                rb,
                m_eff_kg: m_eff,
                // 1 % over the bound: rounding must not make it optimistic.
                rel_accel_bound: 1.01
                    * (carrier_accel_bound
                        + ((d.drag_n_m_s_rad + gap.damping) * wd.abs() + gap.held_n_m.abs())
                            * inv_j),
                event_step_s: self.events.event_step_s(i),
                event_age_s: self.events.event_age_s(i, t),
            };
            let (want, _) = coupling_step(&view, a);
            let want = graded_step(want, &f, self.events.event_age_s(i, t));
            if want.is_nan() || want < a.min_step_s {
                return Err(EngineError::Diverged {
                    t_s: t,
                    reason: format!("disc {i}: the sub-step collapsed to {want:.3e} s"),
                });
            }
            let rem = t1 - t;
            let mut h = if want >= rem {
                rem
            } else if want > 0.5 * rem {
                0.5 * rem
            } else {
                want
            };
            let rel = Relative {
                path,
                coupling: &self.couplings[i],
                inv_j,
                c2: d.drag_n_m_s_rad,
                gap,
            };
            let mut step = rel.rk4(t, shaft, phi, dphi, h);
            // Never step over an onset or a separation: land on it (the `s^1.5` law's kink
            // then falls on a sub-step boundary and the step keeps its order).
            let engaged = f.depth_m > 0.0;
            let tiny = 1e-3 * h.min(want);
            for flank in FLANKS {
                if engaged && flank != f.kin.flank {
                    continue;
                }
                let sigma = flank.phi_sign();
                let depth = |p: f64| (sigma * p - g0) * rb + offset;
                let (d0, d1) = (depth(phi), depth(step.phi));
                let crosses = if engaged {
                    d0 > 0.0 && d1 <= 0.0
                } else {
                    d0 <= 0.0 && d1 > 0.0
                };
                if !crosses {
                    continue;
                }
                let evals = std::cell::Cell::new(0);
                let x = bracketed_root(
                    |x| {
                        evals.set(evals.get() + 4);
                        depth(rel.rk4(t, shaft, phi, dphi, x).phi)
                    },
                    0.0,
                    d0,
                    h,
                    d1,
                    1e-16,
                );
                counts.evals += evals.get();
                if x > tiny && x < h {
                    h = x;
                    step = rel.rk4(t, shaft, phi, dphi, x);
                    counts.evals += 4;
                }
            }
            t = if h == rem { t1 } else { t + h };
            phi = step.phi;
            dphi = step.dphi;
            shaft = step.shaft;
            counts.substeps += 1;
            counts.evals += step.evals + 1;
            self.energy
                .add_sub_step(if inertial { 0.0 } else { step.drive_j }, step.drag_j);
            self.energy.add_stack_work(step.gap_j);
            let f = self.end_sub_step(i, t, phi, dphi, shaft, a, closed, contacts)?;
            if inertial && f.depth_m > 0.0 && !missed {
                missed = true;
                counts.missed += 1;
            }
        }
        Ok(())
    }

    /// Ends a sub-step of coupling `i` at `t` in the relative state `(phi, dphi)` with its
    /// carrier at `shaft`: checks the state, evaluates the teeth there (advancing their
    /// contact memory) into `forces[i]` and `rel[i]`, and feeds the events and the contact
    /// samples.
    #[allow(clippy::too_many_arguments)]
    fn end_sub_step(
        &mut self,
        i: usize,
        t: f64,
        phi: f64,
        dphi: f64,
        shaft: ShaftAt,
        a: &AdaptiveStepping,
        closed: &mut Vec<ImpactEvent>,
        contacts: &mut Vec<(usize, f64, DiscSample)>,
    ) -> Result<CouplingForces, EngineError> {
        let d = &self.bodies[i];
        let limit = std::f64::consts::PI / d.spline.teeth as f64;
        if !(phi.abs() <= limit && dphi.is_finite()) {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!(
                    "disc {i}: relative angle {phi:.6e} rad, speed {dphi:.6e} rad/s (half a tooth \
                     pitch is {limit:.6e} rad)"
                ),
            });
        }
        let rel_state = RelativeState {
            phi,
            dphi,
            ..Default::default()
        };
        let f = self.couplings[i].evaluate(&rel_state);
        if !(f.load_n.is_finite() && f.moment[2].is_finite()) {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!("disc {i}: tooth load {:.6e} N", f.load_n),
            });
        }
        self.forces[i] = f;
        self.rel[i] = rel_state;
        let steps_per_contact = a.steps_per_contact;
        let m_eff = self.m_eff[i];
        let step_of = |v| contact_duration_s(&d.law, f.kin.flank, v, m_eff) / steps_per_contact;
        let tracked = self.events.update(i, t, &f, steps_per_contact, step_of);
        if let Some(e) = tracked.closed {
            closed.push(e);
        }
        if let Some(at) = tracked.contact_sample_at {
            // the closing state is sent at the separation
            let omega_d = shaft.speed - dphi;
            contacts.push((
                i,
                at,
                disc_sample(&f, &rel_state, shaft.angle, omega_d, Vec::new()),
            ));
        }
        Ok(f)
    }
}

/// An inertial shaft's sub-steps are at most the world step over this (dimensionless): the
/// shaft's own motion under its drive (eq 4) is integrated by the classical method, whose
/// error per step in the angle grows as the fifth power of the step (see
/// [`Run::integrate_shaft`]).
const SHAFT_SUB_STEPS: f64 = 4.0;

/// One classical Runge-Kutta step of an inertial shaft and the couplings that go with it
/// ([`Run::integrate_shaft`]).
#[derive(Debug, Clone)]
struct ShaftStep {
    /// The shaft's turn over the step, rad, and its speed at the end, rad/s.
    turn: f64,
    speed: f64,
    /// Each coupling's relative angle and speed at the end.
    phi: Vec<f64>,
    dphi: Vec<f64>,
    /// Work of the drive torque on the shaft, J.
    drive_j: f64,
    /// Work of the shaft's damping and the discs' drag, J (<= 0).
    drag_j: f64,
}

impl Run {
    /// The bound of an inertial shaft's acceleration at speed `w` with the teeth's torques
    /// `reaction` (sum of magnitudes, N m) on it, rad/s^2: the drive's bound, the damping,
    /// the reactions (as the shared step's controller, `control.rs`).
    fn inertial_accel_bound(&self, c1: f64, inv_j1: f64, w: f64, reaction: f64) -> f64 {
        self.shaft_accel_bound + (c1 * w.abs() + reaction) * inv_j1
    }

    /// The inverse of the inertial shaft's inertia `1 / J1`, 1/(kg m^2): the model's, not
    /// rapier's, which is 0 until its first step computes the body's mass properties.
    fn inv_j1(&self) -> f64 {
        match self.shaft {
            ShaftDrive::Inertial { j1, .. } => 1.0 / j1,
            ShaftDrive::Prescribed(_) => 0.0,
        }
    }

    /// The inverse of a rapier body's inertia about the axis, 1/(kg m^2).
    fn inv_inertia_z(&self, h: rapier3d_f64::prelude::RigidBodyHandle) -> f64 {
        self.world.physics.bodies[h]
            .mass_properties()
            .local_mprops
            .inv_principal_inertia
            .z
    }

    /// One classical Runge-Kutta step of length `h` from `t` of the inertial shaft (speed
    /// `w0`) and the couplings `cluster` (relative states `phi`, `dphi`), integrated as one
    /// system: the shaft `J1 w' = T_drive(t) - C1 w - sum T_k` (Hu et al. eq 4), each disc
    /// `J w_d' = T_k - C2 w_d` (eq 5), `T_k` the teeth's torque on disc `k` at
    /// `phi_k = theta_s - theta_d`. As in [`Relative::rk4`] the bodies' own motions are
    /// integrated, not the relative ones. The teeth's torques cancel in the total angular
    /// momentum at every stage, so the step conserves it exactly (a linear invariant) but
    /// for the drive and the damping.
    #[allow(clippy::too_many_arguments)]
    fn shaft_rk4(
        &self,
        cluster: &[usize],
        inv_j: &[f64],
        inv_j1: f64,
        c1: f64,
        t: f64,
        w0: f64,
        phi: &[f64],
        dphi: &[f64],
        h: f64,
    ) -> ShaftStep {
        let n = cluster.len();
        let hh = h * h;
        let u0: Vec<f64> = (0..n).map(|k| w0 - dphi[k]).collect();
        // The accelerations at a stage at `ts`: the shaft turned by `s` at speed `w`, disc k
        // by `th[k]` at `u[k]`; the discs' into `acc`, returns the shaft's and the drive.
        let stage = |ts: f64, s: f64, w: f64, th: &[f64], u: &[f64], acc: &mut [f64]| {
            let mut teeth = 0.0;
            for k in 0..n {
                let i = cluster[k];
                let torque = self.couplings[i].probe_torque(phi[k] + s - th[k], w - u[k]);
                teeth += torque;
                acc[k] = (torque - self.bodies[i].drag_n_m_s_rad * u[k]) * inv_j[k];
            }
            let drive = self.drive_torque(ts);
            ((drive - c1 * w - teeth) * inv_j1, drive)
        };
        let (mut k1, mut k2, mut k3, mut k4) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let zero = vec![0.0; n];
        let (a1, d1) = stage(t, 0.0, w0, &zero, &u0, &mut k1);
        let w2 = w0 + 0.5 * h * a1;
        let th2: Vec<f64> = u0.iter().map(|u| 0.5 * h * u).collect();
        let u2: Vec<f64> = (0..n).map(|k| u0[k] + 0.5 * h * k1[k]).collect();
        let (a2, d2) = stage(t + 0.5 * h, 0.5 * h * w0, w2, &th2, &u2, &mut k2);
        let w3 = w0 + 0.5 * h * a2;
        let th3: Vec<f64> = (0..n)
            .map(|k| 0.5 * h * u0[k] + 0.25 * hh * k1[k])
            .collect();
        let u3: Vec<f64> = (0..n).map(|k| u0[k] + 0.5 * h * k2[k]).collect();
        let (a3, d3) = stage(
            t + 0.5 * h,
            0.5 * h * w0 + 0.25 * hh * a1,
            w3,
            &th3,
            &u3,
            &mut k3,
        );
        let w4 = w0 + h * a3;
        let th4: Vec<f64> = (0..n).map(|k| h * u0[k] + 0.5 * hh * k2[k]).collect();
        let u4: Vec<f64> = (0..n).map(|k| u0[k] + h * k3[k]).collect();
        let (a4, d4) = stage(t + h, h * w0 + 0.5 * hh * a2, w4, &th4, &u4, &mut k4);
        let h6 = h / 6.0;
        let turn = h * w0 + h * h6 * (a1 + a2 + a3);
        let speed = w0 + h6 * (a1 + 2.0 * (a2 + a3) + a4);
        let sq = |a: f64, b: f64, c: f64, d: f64| a * a + 2.0 * (b * b + c * c) + d * d;
        let mut drag_j = -c1 * h6 * sq(w0, w2, w3, w4);
        let mut phi1 = Vec::with_capacity(n);
        let mut dphi1 = Vec::with_capacity(n);
        for k in 0..n {
            let th = h * u0[k] + h * h6 * (k1[k] + k2[k] + k3[k]);
            let u1 = u0[k] + h6 * (k1[k] + 2.0 * (k2[k] + k3[k]) + k4[k]);
            phi1.push(phi[k] + turn - th);
            dphi1.push(speed - u1);
            drag_j -= self.bodies[cluster[k]].drag_n_m_s_rad * h6 * sq(u0[k], u2[k], u3[k], u4[k]);
        }
        ShaftStep {
            turn,
            speed,
            phi: phi1,
            dphi: dphi1,
            drive_j: h6 * (d1 * w0 + 2.0 * (d2 * w2 + d3 * w3) + d4 * w4),
            drag_j,
        }
    }

    /// Integrates an inertial shaft from `t` to `t1` together with the couplings `cluster`
    /// (those that may touch within the world step; the others fly free and load nothing),
    /// with sub-steps of the shortest any of them wants (the prescribed shaft's controller
    /// and grading, applied to each), at most the world step over [`SHAFT_SUB_STEPS`], landed
    /// on every onset and separation. Leaves the couplings' states at `t1` in `rel` and
    /// `forces`, adds the drive's, the damping's and the drag's work to the audit, feeds the
    /// events, and returns the shaft's nodes (the motion the free couplings follow).
    #[allow(clippy::too_many_arguments)]
    fn integrate_shaft(
        &mut self,
        t1: f64,
        a: &AdaptiveStepping,
        c1: f64,
        cluster: &[usize],
        counts: &mut Counts,
        closed: &mut Vec<ImpactEvent>,
        contacts: &mut Vec<(usize, f64, DiscSample)>,
    ) -> Result<Vec<Node>, EngineError> {
        let n = cluster.len();
        let inv_j1 = self.inv_j1();
        let inv_j: Vec<f64> = cluster
            .iter()
            .map(|&i| self.inv_inertia_z(self.world.discs[i]))
            .collect();
        let mut t = self.t;
        let (mut angle, mut w) = (self.theta_s, self.omega_s);
        let mut phi: Vec<f64> = cluster.iter().map(|&i| self.rel[i].phi).collect();
        let mut dphi: Vec<f64> = cluster.iter().map(|&i| self.rel[i].dphi).collect();
        let mut nodes = vec![Node { t, angle, speed: w }];
        let cap = a.max_step_s / SHAFT_SUB_STEPS;
        while t < t1 {
            let reaction: f64 = cluster
                .iter()
                .map(|&i| self.forces[i].moment[2].abs())
                .sum();
            let a_shaft = self.inertial_accel_bound(c1, inv_j1, w, reaction);
            let mut want = cap;
            for (k, &i) in cluster.iter().enumerate() {
                let d = &self.bodies[i];
                let f = self.forces[i];
                let wd = w - dphi[k];
                let view = CouplingView {
                    forces: &f,
                    law: &d.law,
                    phi: phi[k],
                    dphi: dphi[k],
                    g0: d.spline.half_play_rad(),
                    rb: d.spline.base_radius_m(),
                    m_eff_kg: self.m_eff[i],
                    rel_accel_bound: 1.01 * (a_shaft + d.drag_n_m_s_rad * wd.abs() * inv_j[k]),
                    event_step_s: self.events.event_step_s(i),
                    event_age_s: self.events.event_age_s(i, t),
                };
                let (wk, _) = coupling_step(&view, a);
                want = want.min(graded_step(wk, &f, self.events.event_age_s(i, t)));
            }
            if want.is_nan() || want < a.min_step_s {
                return Err(EngineError::Diverged {
                    t_s: t,
                    reason: format!("inertial shaft: the sub-step collapsed to {want:.3e} s"),
                });
            }
            let rem = t1 - t;
            let mut h = if want >= rem {
                rem
            } else if want > 0.5 * rem {
                0.5 * rem
            } else {
                want
            };
            let rk4 = |x: f64| self.shaft_rk4(cluster, &inv_j, inv_j1, c1, t, w, &phi, &dphi, x);
            let mut step = rk4(h);
            // Never step over an onset or a separation of any coupling: land on the first.
            let tiny = 1e-3 * h.min(want);
            let mut first: Option<f64> = None;
            for (k, &i) in cluster.iter().enumerate() {
                let d = &self.bodies[i];
                let f = &self.forces[i];
                let (g0, rb) = (d.spline.half_play_rad(), d.spline.base_radius_m());
                let offset = d.law.engagement_offset_m();
                let engaged = f.depth_m > 0.0;
                for flank in FLANKS {
                    if engaged && flank != f.kin.flank {
                        continue;
                    }
                    let sigma = flank.phi_sign();
                    let depth = |p: f64| (sigma * p - g0) * rb + offset;
                    let (d0, d1) = (depth(phi[k]), depth(step.phi[k]));
                    let crosses = if engaged {
                        d0 > 0.0 && d1 <= 0.0
                    } else {
                        d0 <= 0.0 && d1 > 0.0
                    };
                    if !crosses {
                        continue;
                    }
                    let evals = std::cell::Cell::new(0);
                    let x = bracketed_root(
                        |x| {
                            evals.set(evals.get() + 4 * n as u64);
                            depth(rk4(x).phi[k])
                        },
                        0.0,
                        d0,
                        h,
                        d1,
                        1e-16,
                    );
                    counts.evals += evals.get();
                    if x > tiny && x < h && first.is_none_or(|b| x < b) {
                        first = Some(x);
                    }
                }
            }
            if let Some(x) = first {
                h = x;
                step = rk4(x);
                counts.evals += 4 * n as u64;
            }
            t = if h == rem { t1 } else { t + h };
            angle += step.turn;
            w = step.speed;
            phi.clone_from(&step.phi);
            dphi.clone_from(&step.dphi);
            counts.substeps += 1;
            counts.evals += 5 * n as u64;
            self.energy.add_sub_step(step.drive_j, step.drag_j);
            nodes.push(Node { t, angle, speed: w });
            let at = ShaftAt { speed: w, angle };
            for (k, &i) in cluster.iter().enumerate() {
                self.end_sub_step(i, t, phi[k], dphi[k], at, a, closed, contacts)?;
            }
        }
        Ok(nodes)
    }

    /// [`Run::multirate_step`] on an inertial shaft (friction discs only): the couplings that
    /// may touch within the world step (in contact at `t`, or closer to it than the prescribed
    /// scheme's controller lets a coupling fly within the step, with the shaft's acceleration
    /// bounded by the drive, the damping and the reactions at `t`) are integrated with the
    /// shaft as one system ([`Run::integrate_shaft`]); every other coupling then flies free
    /// against the shaft's motion so found ([`Path::Nodes`]), as against a prescribed shaft.
    fn multirate_step_inertial(
        &mut self,
        t1: f64,
        a: &AdaptiveStepping,
        c1: f64,
        counts: &mut Counts,
        closed: &mut Vec<ImpactEvent>,
        contacts: &mut Vec<(usize, f64, DiscSample)>,
    ) -> Result<(), EngineError> {
        let t0 = self.t;
        let h = t1 - t0;
        let n = self.couplings.len();
        let inv_j1 = self.inv_j1();
        let reaction: f64 = self.forces.iter().map(|f| f.moment[2].abs()).sum();
        let a_shaft = self.inertial_accel_bound(c1, inv_j1, self.omega_s, reaction);
        let mut cluster = Vec::new();
        for i in 0..n {
            let f = self.forces[i];
            if f.depth_m > 0.0 {
                cluster.push(i);
                continue;
            }
            let d = &self.bodies[i];
            let inv_j = self.inv_inertia_z(self.world.discs[i]);
            let wd = self.omega_s - self.rel[i].dphi;
            let view = CouplingView {
                forces: &f,
                law: &d.law,
                phi: self.rel[i].phi,
                dphi: self.rel[i].dphi,
                g0: d.spline.half_play_rad(),
                rb: d.spline.base_radius_m(),
                m_eff_kg: self.m_eff[i],
                rel_accel_bound: 1.01 * (a_shaft + d.drag_n_m_s_rad * wd.abs() * inv_j),
                event_step_s: self.events.event_step_s(i),
                event_age_s: self.events.event_age_s(i, t0),
            };
            if coupling_step(&view, a).0 < h {
                cluster.push(i);
            }
        }
        let phi0: Vec<f64> = self.rel.iter().map(|r| r.phi).collect();
        let nodes = self.integrate_shaft(t1, a, c1, &cluster, counts, closed, contacts)?;
        let path = Path::Nodes(&nodes);
        let mut in_cluster = cluster.iter().peekable();
        for i in 0..n {
            if in_cluster.peek() == Some(&&i) {
                in_cluster.next();
                continue;
            }
            self.integrate_coupling(
                i,
                t1,
                a,
                GapDrag::default(),
                path,
                a_shaft,
                counts,
                closed,
                contacts,
            )?;
        }
        let (start, end) = (nodes[0], nodes[nodes.len() - 1]);
        let mut means = Vec::with_capacity(n);
        self.potential_j = 0.0;
        for (i, &phi0) in phi0.iter().enumerate() {
            self.omega_d[i] = end.speed - self.rel[i].dphi;
            self.potential_j += self.forces[i].potential_j;
            means.push((end.angle - start.angle - (self.rel[i].phi - phi0)) / h);
        }
        // The world's step, as on a prescribed shaft (`multirate_step`); the shaft's body
        // gets its mean speed set for the step instead of a torque: rapier's inverse inertia
        // of the shaft reads 0 until its first step computes the body's mass properties, and
        // the torque from it, infinite, left every body at rest from then on (measured).
        let shaft_mean = (end.angle - start.angle) / h;
        let bodies = &mut self.world.physics.bodies;
        for (i, &mean) in means.iter().enumerate() {
            let body = &mut bodies[self.world.discs[i]];
            let inv_j = body.mass_properties().local_mprops.inv_principal_inertia.z;
            let torque = (mean - body.angvel().z) / (h * inv_j);
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_torque(Vector::new(0.0, 0.0, torque), false);
        }
        let shaft = &mut bodies[self.world.shaft];
        shaft.reset_forces(false);
        shaft.reset_torques(false);
        shaft.set_angvel(Vector::new(0.0, 0.0, shaft_mean), false);
        self.world.step(h);
        let bodies = &mut self.world.physics.bodies;
        for i in 0..n {
            let body = &mut bodies[self.world.discs[i]];
            body.set_angvel(Vector::new(0.0, 0.0, self.omega_d[i]), false);
        }
        bodies[self.world.shaft].set_angvel(Vector::new(0.0, 0.0, end.speed), false);
        self.t_prev = Some(t0);
        self.t = t1;
        self.theta_s = end.angle;
        self.omega_s = end.speed;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The graded sub-step: the floor at an onset, a quarter of the contact's age after it,
    /// the controller's step once that is longer, a quarter of the predicted time to
    /// separation (depth over the opening speed) while the depth falls, nothing in free flight
    /// or while the depth grows.
    #[test]
    fn sub_steps_are_graded_at_the_kinks() {
        let forces = |depth_m: f64, v_n_m_s: f64| CouplingForces {
            kin: clutchpack_model::ToothKinematics {
                flank: clutchpack_model::Flank::ShaftLeads,
                delta_m: depth_m,
                v_n_m_s,
            },
            depth_m,
            load_n: 0.0,
            force: [0.0; 2],
            moment: [0.0; 3],
            stiffness: 0.0,
            potential_j: 0.0,
            gap_margin_m: 0.0,
            speed_margin_m_s: 0.0,
        };
        let want = 64e-8;
        let growing = forces(1e-7, 0.5);
        assert_eq!(graded_step(want, &growing, Some(0.0)), 1e-8);
        assert_eq!(graded_step(want, &growing, Some(8e-7)), 2e-7);
        assert_eq!(graded_step(want, &growing, Some(1e-5)), want);
        assert_eq!(graded_step(want, &growing, None), want);
        // 1e-7 m at 0.5 m/s: 2e-7 s to the separation
        let falling = forces(1e-7, -0.5);
        assert_eq!(graded_step(want, &falling, Some(1e-5)), 0.25 * 2e-7);
        assert_eq!(graded_step(want, &forces(1e-12, -0.5), Some(1e-5)), 1e-8);
        assert_eq!(graded_step(want, &forces(-1e-7, -0.5), Some(0.0)), want);
    }

    /// A disc in free flight inside the backlash of a shaft at rest, slowed by its drag:
    /// `omega_d = w0 e^(-r t)`, `r = C2 / J`, so `phi = -w0 (1 - e^(-r t)) / r` and the drag's
    /// work equals the change of kinetic energy, `J (omega_d^2 - w0^2) / 2`. The classical
    /// Runge-Kutta step is fourth order: halving the step divides the error by about 16
    /// (within 1: the next term of the error is smaller by a further factor `r h`), and the
    /// drag's work from the same stages matches the kinetic energy lost to 1e-5 (measured
    /// 2.2e-6 at `r h = 0.1`).
    #[test]
    fn sub_step_is_fourth_order_and_audits_the_drag() {
        // the bench disc's spline and dry law (`scenes/bench-8-disc.toml`)
        let disc = clutchpack_model::cases::bench_disc("d");
        let (spline, law) = (disc.spline, disc.law);
        let coupling = Coupling::new(spline, law, false, &[]);
        let profile = SpeedProfile::sine(0.0, 0.0, 1.0);
        let (j, c2, w0) = (0.2, 20.0, 1e-3);
        let rel = Relative {
            path: Path::Profile(&profile),
            coupling: &coupling,
            inv_j: 1.0 / j,
            c2,
            gap: GapDrag::default(),
        };
        let r = c2 / j;
        let duration = 0.05;
        let run = |n: usize| {
            let h = duration / n as f64;
            let (mut phi, mut dphi, mut drag) = (0.0, -w0, 0.0);
            for k in 0..n {
                let t = k as f64 * h;
                let s = rel.rk4(t, ShaftAt::of(Some(&profile), t), phi, dphi, h);
                (phi, dphi, drag) = (s.phi, s.dphi, drag + s.drag_j);
            }
            let wd = w0 * (-r * duration).exp();
            let phi_exact = -w0 * (1.0 - (-r * duration).exp()) / r;
            assert!((-dphi - wd).abs() < 1e-6 * w0, "{dphi} vs {wd}");
            let work = 0.5 * j * (wd * wd - w0 * w0);
            // fourth order too: 2.2e-6 relative at r h = 0.1 (50 steps)
            assert!((drag - work).abs() < 1e-5 * work.abs(), "{drag} vs {work}");
            (phi - phi_exact).abs()
        };
        let ratio = run(50) / run(100);
        assert!((ratio - 16.0).abs() < 1.0, "{ratio}");
    }
}
