//! The multirate scheme (crate docs, "Theory"): the rapier world steps at free-flight length
//! and every spline coupling integrates its own relative motion inside the world's step, with
//! its own contact-aware sub-steps; the tooth impulse of the step is handed to the disc's
//! rapier body, which carries the disc's state from one world step to the next, or, on an
//! open pack where rapier would do nothing else, the run carries it without rapier's step
//! ([`Run::carry_bodies`]) (a coupling's sub-steps go through the one landing loop,
//! `landing.rs`, as [`Alone`]).

use super::carriers::Motion;
use super::landing::SubSteps;
use super::state::{disc_sample, relative_state, Run};
use super::substep::{
    checked_sub_step, graded_step, GapDrag, Node, Path, Prescribed, Relative, ShaftAt, SubStep,
    TurnMoment, WorldStep, ALONE_KINK_FLOOR_DIVISOR, KINK_FLOOR_DIVISOR,
};
use crate::hook::{RelativeState, FLANKS};
use crate::options::{MultibodyOptions, Stepping};
use crate::stepping::{bracketed_root, contact_duration_s, coupling_step};
use clutchpack_model::{EngineError, PackModel};
use rapier3d_f64::prelude::{Rotation, Vector};

/// Why the multirate scheme cannot run this pack with these options (`None`: it can).
///
/// It needs the bodies to be independent within a world step but for weak couplings and their
/// inertial carriers: each friction disc coupled by its teeth only to the shaft (prescribed,
/// or inertial and integrated with the discs that may touch it) and each separator plate only
/// to the fixed housing or to the drum (integrated with the plates that may touch it,
/// `inertial.rs`), turning about the axis only (a per-tooth coupling too, with spacing errors
/// or held eccentric: its sub-steps land on the deepest tooth's onsets and separations,
/// [`crate::hook::Coupling::deepest_tooth_shift_m`]; not a disc that floats radially, whose
/// centre moves within the step); neighbours in an open stack
/// pull on each other only through the oil gaps' Couette drag, which a world step holds (see
/// [`GapDrag`]). A stack whose piston may push (from `Piston::open_until_s`) is open until
/// then: from that time the session integrates the clamped stack, the inertial carriers with
/// it, as one system (`clamped.rs`).
pub(super) fn unsupported(
    pack: &PackModel,
    options: &MultibodyOptions,
    per_tooth: &[bool],
) -> Option<&'static str> {
    if !matches!(options.stepping, Stepping::Adaptive(_)) {
        return Some("fixed steps (the check mode) step the whole world at dt");
    }
    if !pack.couplings.is_empty() {
        return Some(
            "a spring-damper joins the shaft and the drum (MODEL.md section 8), which the \
             multirate scheme integrates apart within a world step",
        );
    }
    let bodies = pack.discs.iter().chain(&pack.plates);
    if per_tooth
        .iter()
        .zip(bodies)
        .any(|(&p, d)| p && d.radial_float)
    {
        return Some(
            "a disc floats radially: its centre moves off the axis within a world step (two \
             more degrees of freedom the sub-steps do not integrate)",
        );
    }
    None
}

impl Run {
    /// The known path of coupling `i`'s carrier over the world step and the bound of its
    /// acceleration, rad/s^2: the prescribed shaft's (`drive`; the discs of an inertial shaft
    /// go with the shaft), or the housing at rest.
    fn known_path<'a>(&self, i: usize, drive: Option<Prescribed<'a>>) -> (Path<'a>, f64) {
        let k = &self.carriers[self.world.carrier_of[i]];
        match (&k.motion, drive) {
            (Motion::Prescribed(_), Some(p)) => (Path::Profile(p), k.drive_bound),
            (Motion::Fixed, _) => (Path::Housing, 0.0),
            _ => unreachable!("an inertial carrier's couplings go with it"),
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

    /// The open gaps' drag on every coupling body over the world step from `t` of length `h`
    /// ([`GapDrag`]; zero without a stack), with the neighbours' speeds affine in time: `w`
    /// at the step's middle (their mean, rad/s, coupling order) and `slope` (rad/s^2); into
    /// `g` (its contents replaced).
    fn gap_drags(&self, w: &[f64], slope: &[f64], h: f64, g: &mut Vec<GapDrag>) {
        g.clear();
        g.resize(self.couplings.len(), GapDrag::default());
        let Some(stack) = &self.stack else { return };
        let c = self.gap_coefficient();
        for m in 0..stack.interfaces() {
            let (lo, up) = (stack.body[m], stack.body[m + 1]);
            g[lo].held_n_m += c * w[up];
            g[lo].slope_n_m_s += c * slope[up];
            g[lo].damping += c;
            g[up].held_n_m += c * w[lo];
            g[up].slope_n_m_s += c * slope[lo];
            g[up].damping += c;
        }
        for x in g.iter_mut() {
            (x.t_mid_s, x.half_step_s) = (self.t + 0.5 * h, 0.5 * h);
        }
    }

    /// Advances the run from `t` to `t1` by the multirate scheme: the friction discs (each on
    /// its own against a prescribed shaft, or with an inertial shaft, [`Run::advance_carrier`]),
    /// then the plates (each on its own against the housing, or with the drum), then the rapier
    /// world takes one step of `t1 - t` with each body's impulse. Impact events that closed go
    /// to `closed` (in the order they closed within each coupling), the contact samples
    /// `(coupling, t s, state)` of the sub-steps to `contacts` (in time order within each
    /// coupling; see `EventBook::update`). Its buffers are the run's
    /// ([`OpenStepBuffers`](super::scheme_state::OpenStepBuffers)), taken for the step and put
    /// back: a step allocates nothing of its own.
    pub(super) fn multirate_step(&mut self, ws: &mut WorldStep) -> Result<(), EngineError> {
        let mut b = std::mem::take(&mut self.multirate.open);
        let out = self.multirate_step_in(ws, &mut b);
        self.multirate.open = b;
        out
    }

    /// [`Run::multirate_step`] with its buffers `b`.
    fn multirate_step_in(
        &mut self,
        ws: &mut WorldStep,
        b: &mut super::scheme_state::OpenStepBuffers,
    ) -> Result<(), EngineError> {
        let t1 = ws.t1;
        let t0 = self.t;
        let h = t1 - t0;
        // The open gaps' drag: the discs first, with their neighbours (plates, which turn
        // slowly) held at their mean speed over the step predicted from their acceleration at t
        // (teeth, gaps, drag; second order where it is smooth); then the plates, with their
        // neighbours (discs) affine in time with the mean and the first moment of the discs'
        // speeds over the step just integrated (`TurnMoment`): the plates' only drive is the
        // gaps' drag, and a disc's speed jumps within a step at its impacts. Measured on the
        // open 8-disc brake against the reference engine at 1e-12 over 25 ms: worst onset
        // 0.46 us at the default world step of 0.1 ms (0.82 us with the discs' speeds held at
        // their mean, 1.65 us with every neighbour held at its speed at t).
        let n_discs = self.pack.discs.len();
        let n = self.couplings.len();
        b.zero.clear();
        b.zero.resize(n, 0.0);
        self.gap_drags(&self.omega_d, &b.zero, h, &mut b.gaps);
        for i in 0..n {
            let theta = self.carrier_angle(i) - self.rel[i].phi;
            self.multirate.moments[i] = TurnMoment::start(t0, theta, self.omega_d[i]);
        }
        if self.stack.is_some() {
            // the plates' predicted mean speeds, for the discs, held over the step (their
            // acceleration at t as a slope too was measured no better: a plate in contact at t
            // does not keep its acceleration over the step)
            b.w.clear();
            b.w.extend((0..n).map(|j| {
                let w = self.omega_d[j];
                if j < n_discs {
                    return w;
                }
                let d = &self.bodies[j];
                let g = &b.gaps[j];
                let torque =
                    self.forces[j].moment[2] + g.held_n_m - (g.damping + d.drag_n_m_s_rad) * w;
                w + 0.5 * h * torque / d.inertia_kg_m2
            }));
            self.gap_drags(&b.w, &b.zero, h, &mut b.gaps);
        }
        b.means.clear();
        b.means.resize(n, 0.0);
        // the inertial carriers and their states at t and t1, for the world's step
        b.carriers.clear();
        // the discs, with an inertial shaft as their carrier or each alone
        let (discs, plates) = (0..n_discs, n_discs..n);
        self.advance_group(discs, b, ws)?;
        if self.stack.is_some() {
            // the discs' speeds over the step, for the plates: the affine function with their
            // mean and their first moment, from their sub-steps
            b.w.clear();
            b.w.extend((0..n).map(|j| {
                if j < n_discs {
                    b.means[j]
                } else {
                    self.omega_d[j]
                }
            }));
            b.slope.clear();
            b.slope.extend((0..n).map(|j| {
                if j < n_discs {
                    self.multirate.moments[j].slope()
                } else {
                    0.0
                }
            }));
            self.gap_drags(&b.w, &b.slope, h, &mut b.gaps);
        }
        // the plates: each alone on the housing, then the drum with its own (as an inertial
        // shaft with its discs), their gaps' drag from the discs' speeds as on the housing
        self.advance_group(plates, b, ws)?;
        self.potential_j = self.forces.iter().map(|f| f.potential_j).sum();
        let c = self.gap_coefficient();
        if let Some(s) = self.stack.as_mut() {
            // Each interface's share of the gaps' work, from the bodies' mean speeds over the
            // step (the bodies' own audit is exact along their sub-steps).
            for m in 0..s.interfaces() {
                let slip = b.means[s.body[m + 1]] - b.means[s.body[m]];
                s.impulse[m] = -c * slip * h;
                s.dissipated_j[m] += c * slip * slip * h;
            }
            s.record_open_step(h);
        }
        // The world's step: each body's impulse in two halves, `J (mean - w(t))` applied as a
        // torque over the step (rapier's semi-implicit Euler then drifts the body by
        // exactly `mean h`) and `J (w(t1) - mean)` as the speed set at its end; or, where
        // that is all rapier would do, the bodies carried without it.
        if self.carries_bodies {
            self.carry_bodies(t1, ws.drive);
        } else {
            self.finish_world_step_in(&b.means, t1, &b.carriers, &mut b.prescribed);
        }
        Ok(())
    }

    /// The world's step of the open pack from `t` to `t1` without rapier, where every carrier
    /// is fixed or prescribed and every body concentric (`Run::carries_bodies`): rapier's step
    /// would only turn each body by its mean speed over the step and set its speed at `t1`,
    /// and the next world step read the relative states back from the poses. Each coupling's
    /// state at `t1` is taken from its sub-steps instead: its relative angle `phi(t1)` moved
    /// to the carrier's exact angle as the poses' read-back moves it, by
    /// `(theta(t1) - theta~(t1)) - (theta(t) - theta~(t))` (`theta` the profile's angle in the
    /// carriers' table, `theta~` the sub-steps' expansion of it about the world step's
    /// middle); its relative speed the carrier's exact speed less the body's. That is the
    /// read-back's value without the rounding of the quaternions (1e-16 of the angle a step);
    /// the poses are brought up to date when something needs them
    /// ([`Run::catch_up_world`]). Measured: a sixth of the 16-disc brake pack's run was
    /// rapier's step and the read-back (docs/performance.md, "Against MuJoCo").
    fn carry_bodies(&mut self, t1: f64, drive: Option<Prescribed<'_>>) {
        let t0 = self.t;
        for c in 0..self.carriers.len() {
            let Motion::Prescribed(p) = &self.carriers[c].motion else {
                continue;
            };
            let (speed, angle) = p.speed_and_angle(t1);
            let shift = match drive {
                Some(d) => {
                    let path = Path::Profile(d);
                    (angle - path.at(t1).angle) - (self.carriers[c].angle - path.at(t0).angle)
                }
                None => 0.0,
            };
            self.set_carrier_state(c, angle, speed);
            for i in 0..self.couplings.len() {
                if self.world.carrier_of[i] == c {
                    self.rel[i].phi += shift;
                }
            }
        }
        for i in 0..self.couplings.len() {
            self.rel[i].dphi = self.carrier_speed(i) - self.omega_d[i];
        }
        self.t_prev = Some(t0);
        self.t = t1;
        self.world_behind = true;
    }

    /// Brings rapier's poses up to date after world steps taken without it
    /// ([`Run::carry_bodies`]): each prescribed carrier at its angle, each body at its
    /// carrier's angle less its relative angle, turning at its speed. Before anything reads
    /// the poses (the clamped stack's world steps).
    pub(super) fn catch_up_world(&mut self) {
        if !self.world_behind {
            return;
        }
        for c in 0..self.carriers.len() {
            if matches!(self.carriers[c].motion, Motion::Prescribed(_)) {
                self.world.place_carrier(c, self.carriers[c].angle);
            }
        }
        for i in 0..self.couplings.len() {
            let angle = self.carrier_angle(i) - self.rel[i].phi;
            self.world.place_disc(i, angle, self.omega_d[i]);
        }
        self.world_behind = false;
    }

    /// The world's step of the multirate schemes from `t` to `t1` after the couplings'
    /// sub-steps: each coupling body driven to its mean speed `means` over the step
    /// ([`Run::drive_to_means`]), the prescribed carriers to their angles at `t1`, the
    /// inertial carriers to theirs ([`Run::step_world_multirate`], `carriers`: index, nodes at
    /// `t` and `t1`), every body's speed then set to its speed at `t1`.
    pub(super) fn finish_world_step(
        &mut self,
        means: &[f64],
        t1: f64,
        carriers: &[(usize, Node, Node)],
    ) {
        let mut prescribed = Vec::new();
        self.finish_world_step_in(means, t1, carriers, &mut prescribed);
    }

    /// [`Run::finish_world_step`] with `prescribed` as its buffer (its contents replaced).
    fn finish_world_step_in(
        &mut self,
        means: &[f64],
        t1: f64,
        carriers: &[(usize, Node, Node)],
        prescribed: &mut Vec<(usize, f64, f64)>,
    ) {
        self.drive_to_means(means, t1 - self.t);
        // each prescribed carrier's angle and speed at t1
        prescribed.clear();
        prescribed.extend((self.carriers.iter().enumerate()).filter_map(
            |(c, k)| match &k.motion {
                Motion::Prescribed(p) => {
                    let (speed, angle) = p.speed_and_angle(t1);
                    Some((c, angle, speed))
                }
                _ => None,
            },
        ));
        for &(c, angle, _) in prescribed.iter() {
            let bodies = &mut self.world.physics.bodies;
            bodies[self.world.carriers[c].handle]
                .set_next_kinematic_rotation(Rotation::from_rotation_z(angle));
        }
        self.step_world_multirate(t1, carriers);
        for &(c, angle, speed) in prescribed.iter() {
            self.set_carrier_state(c, angle, speed);
        }
    }

    /// Advances the couplings `group` (the discs, or the plates) from `t` to `t1`, the open
    /// gaps' drag `b.gaps` on each: every one on a carrier of known motion alone against it
    /// ([`Run::advance_alone`]) first, then each inertial carrier of the group's couplings
    /// (table order) together with those it carries ([`Run::advance_carrier`], its index and
    /// nodes then pushed onto `b.carriers` for the world's step). Writes each one's speed at
    /// `t1` into `omega_d` and its mean speed over the step into `b.means`.
    fn advance_group(
        &mut self,
        group: std::ops::Range<usize>,
        b: &mut super::scheme_state::OpenStepBuffers,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        b.inertial.clear();
        for i in group {
            let c = self.world.carrier_of[i];
            if !self.carriers[c].is_inertial() {
                self.advance_alone(i, b.gaps[i], &mut b.means, ws)?;
            } else if !b.inertial.contains(&c) {
                b.inertial.push(c);
            }
        }
        b.inertial.sort_unstable();
        for k in 0..b.inertial.len() {
            let c = b.inertial[k];
            let (start, end) = self.advance_carrier(c, &b.gaps, &mut b.means, ws)?;
            b.carriers.push((c, start, end));
        }
        Ok(())
    }

    /// Advances coupling `i` alone from `t` to `t1` against its carrier's known motion (a
    /// prescribed shaft's profile, the housing at rest) with the open gaps' drag `gap`
    /// ([`Run::integrate_coupling`]); writes its speed at `t1` into `omega_d` and its mean
    /// speed over the step into `means[i]`.
    fn advance_alone(
        &mut self,
        i: usize,
        gap: GapDrag,
        means: &mut [f64],
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        let t1 = ws.t1;
        let (t0, h) = (self.t, t1 - self.t);
        let phi0 = self.rel[i].phi;
        let (path, bound) = self.known_path(i, ws.drive);
        self.integrate_coupling(i, gap, path, bound, ws)?;
        let (phi1, dphi1) = (self.rel[i].phi, self.rel[i].dphi);
        let (c0, c1) = (path.at(t0), path.at(t1));
        self.omega_d[i] = c1.speed - dphi1;
        // The body's mean speed over the step: it turns with its carrier less the change of
        // the relative angle.
        means[i] = (c1.angle - c0.angle - (phi1 - phi0)) / h;
        Ok(())
    }

    /// Sets each coupling body's torque for the world's step of length `h` (s) so that
    /// rapier's semi-implicit Euler drifts it by exactly `means[i] h`: `J (mean - w(t)) / h`.
    pub(super) fn drive_to_means(&mut self, means: &[f64], h: f64) {
        let bodies = &mut self.world.physics.bodies;
        for (i, &mean) in means.iter().enumerate() {
            let body = &mut bodies[self.world.discs[i]];
            let inv_j = body.mass_properties().local_mprops.inv_principal_inertia.z;
            let torque = (mean - body.angvel().z) / (h * inv_j);
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_torque(Vector::new(0.0, 0.0, torque), false);
        }
    }

    /// Reads every coupling's relative state at `t` from the rapier bodies (the state each
    /// coupling's sub-steps start from).
    pub(super) fn read_relative_states(&mut self) {
        if self.world_behind {
            // carried without rapier: the states are the sub-steps' ([`Run::carry_bodies`])
            return;
        }
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
            // No body floats radially here (`unsupported`): each sits at its offset in its
            // carrier's frame, exactly (its joint holds it there; rapier's pose only to the
            // joint solver's error).
            self.rel[i].offset = self.bodies[i].initial_offset_m;
            self.rel[i].offset_rate = [0.0; 2];
            self.omega_d[i] = disc.angvel().z;
        }
    }

    /// Sub-steps coupling `i` from `t` (its state in `rel[i]`, its forces in `forces[i]`) to
    /// `t1`, with the step controller of the shared scheme applied to this coupling alone and
    /// steps landed on every contact onset and separation ([`Run::land_sub_steps`]); leaves the
    /// state at `t1` in `rel[i]` and `forces[i]`, adds the work done to the energy audit and
    /// feeds the events.
    pub(super) fn integrate_coupling(
        &mut self,
        i: usize,
        gap: GapDrag,
        path: Path<'_>,
        carrier_accel_bound: f64,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        let mut alone = Alone {
            i,
            gap,
            path,
            carrier_accel_bound,
            inv_j: self.inv_inertia_z(self.world.discs[i]),
            c2: self.bodies[i].drag_n_m_s_rad,
            t: self.t,
            phi: self.rel[i].phi,
            dphi: self.rel[i].dphi,
            shaft: path.at(self.t),
            evaluated_here: false,
            start_torque_n_m: 0.0,
            missed: false,
            known: !matches!(path, Path::Nodes(_)),
        };
        self.land_sub_steps(&mut alone, ws)
    }

    /// Where within a sub-step of length `h` coupling `i`'s deepest tooth's engagement depth
    /// crosses zero (an onset when the coupling is not engaged, its separation when it is),
    /// from the relative angle `phi0` at the sub-step's start to `phi1` at its end, located on
    /// the sub-step's own path `phi_at(x)` (the relative angle after `x` s) by the Illinois
    /// root to 1e-16 m; `None` if it does not cross. The depth is the lumped one shifted by
    /// the deepest tooth's spacing error and offset (`Coupling::deepest_tooth_shift_m`).
    pub(super) fn depth_crossing(
        &self,
        i: usize,
        phi0: f64,
        phi1: f64,
        h: f64,
        phi_at: impl Fn(f64) -> f64,
    ) -> Option<f64> {
        let d = &self.bodies[i];
        let f = &self.forces[i];
        let (g0, rb) = (
            self.couplings[i].half_play_rad(),
            self.couplings[i].base_radius_m(),
        );
        let offset = d.law.engagement_offset_m();
        let engaged = f.depth_m > 0.0;
        let mut first: Option<f64> = None;
        for flank in FLANKS {
            if engaged && flank != f.kin.flank {
                continue;
            }
            let sigma = flank.phi_sign();
            let shift = self.couplings[i].deepest_tooth_shift_m(flank);
            let depth = |p: f64| (sigma * p - g0) * rb + offset + shift;
            let (d0, d1) = (depth(phi0), depth(phi1));
            if !crate::stepping::crosses_contact(engaged, d0, d1) {
                continue;
            }
            let x = bracketed_root(|x| depth(phi_at(x)), 0.0, d0, h, d1, 1e-16);
            first = Some(first.map_or(x, |b| b.min(x)));
        }
        first
    }

    /// Ends a sub-step of coupling `i` at `t` in the relative state `(phi, dphi)` with its
    /// carrier at `shaft`: checks the state, evaluates the teeth there (advancing their
    /// contact memory) into `forces[i]` and `rel[i]`, and feeds the events (a new one's step
    /// its predicted duration over `steps_per_contact`, the count of the settings the
    /// coupling steps by) and the contact samples. Returns the coupling's engagement depth
    /// there, m.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn end_sub_step(
        &mut self,
        i: usize,
        t: f64,
        phi: f64,
        dphi: f64,
        shaft: ShaftAt,
        steps_per_contact: f64,
        ws: &mut WorldStep,
    ) -> Result<f64, EngineError> {
        let d = &self.bodies[i];
        let limit = self.couplings[i].half_pitch_rad();
        if !(phi.abs() <= limit && dphi.is_finite()) {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!(
                    "disc {i}: relative angle {phi:.6e} rad, speed {dphi:.6e} rad/s (half a tooth \
                     pitch is {limit:.6e} rad)"
                ),
            });
        }
        // the disc's offset is held (it does not float radially: `unsupported`)
        let rel_state = RelativeState {
            phi,
            dphi,
            ..self.rel[i]
        };
        // evaluated in place (the forces are not copied through the call)
        self.forces[i] = self.couplings[i].evaluate(&rel_state);
        let f = &self.forces[i];
        if !(f.load_n.is_finite() && f.moment[2].is_finite()) {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!("disc {i}: tooth load {:.6e} N", f.load_n),
            });
        }
        self.rel[i] = rel_state;
        self.multirate.moments[i].add(t, shaft.angle - phi, shaft.speed - dphi);
        let m_eff = self.m_eff[i];
        let step_of = |v| contact_duration_s(&d.law, f.kin.flank, v, m_eff) / steps_per_contact;
        let tracked = self.events.update(i, t, f, steps_per_contact, step_of);
        if let Some(e) = tracked.closed {
            ws.closed.push(e);
        }
        if let Some(at) = tracked.contact_sample_at {
            // the closing state is sent at the separation
            let omega_d = shaft.speed - dphi;
            ws.contacts.push((
                i,
                at,
                disc_sample(f, &rel_state, shaft.angle, omega_d, Vec::new()),
            ));
        }
        Ok(f.depth_m)
    }
}

/// One coupling alone against its carrier's known motion (a prescribed shaft's profile, the
/// housing at rest, an inertial carrier's nodes), [`Relative::step`] for its steps.
struct Alone<'a> {
    /// The coupling, the open gaps' drag on its body, its carrier's path and the bound of
    /// the carrier's acceleration, rad/s^2.
    i: usize,
    gap: GapDrag,
    path: Path<'a>,
    carrier_accel_bound: f64,
    /// The body's inverse inertia about the axis, 1/(kg m^2) (rapier's), and drag `C2`,
    /// N m s/rad.
    inv_j: f64,
    c2: f64,
    /// The time, s, the relative state (rad, rad/s) and the carrier there.
    t: f64,
    phi: f64,
    dphi: f64,
    shaft: ShaftAt,
    /// Whether `forces[i]` holds the hook's evaluation at `(phi, dphi)`: from the first
    /// sub-step's end on (at a world step's start the state was read back from rapier).
    evaluated_here: bool,
    /// The teeth's torque at the step's start, N m.
    start_torque_n_m: f64,
    /// Whether it touched on an inertial carrier (counted once per world step).
    missed: bool,
    /// Whether its carrier's motion is known (a prescribed shaft, the housing): it steps by
    /// `WorldStep::alone`, else (an inertial carrier's nodes) by `WorldStep::a`.
    known: bool,
}

impl SubSteps for Alone<'_> {
    type Step = SubStep;

    fn t(&self) -> f64 {
        self.t
    }

    fn members(&self) -> &[usize] {
        std::slice::from_ref(&self.i)
    }

    fn phi(&self, _: usize) -> f64 {
        self.phi
    }

    fn want(&mut self, run: &mut Run, ws: &mut WorldStep) -> Result<f64, EngineError> {
        let a = if self.known { ws.alone } else { ws.a };
        let (i, t, gap) = (self.i, self.t, self.gap);
        let f = &run.forces[i];
        let wd = self.shaft.speed - self.dphi;
        let bound = self.carrier_accel_bound
            + ((self.c2 + gap.damping) * wd.abs() + gap.bound_n_m()) * self.inv_j;
        let view = run.coupling_view(i, f, (self.phi, self.dphi), bound, t);
        let (want, _) = coupling_step(&view, a);
        let floor_divisor = if self.known {
            ALONE_KINK_FLOOR_DIVISOR
        } else {
            KINK_FLOOR_DIVISOR
        };
        let want = graded_step(want, f, run.events.event_age_s(i, t), floor_divisor);
        let want = checked_sub_step(want, a, t, || format!("disc {i}"))?;
        self.start_torque_n_m = if self.evaluated_here {
            f.moment[2]
        } else {
            ws.counts.evals += 1;
            run.couplings[i].probe_torque(self.phi, self.dphi)
        };
        Ok(want)
    }

    fn step(&self, run: &Run, h: f64) -> SubStep {
        let rel = Relative {
            path: self.path,
            coupling: &run.couplings[self.i],
            inv_j: self.inv_j,
            c2: self.c2,
            gap: self.gap,
            start_torque_n_m: self.start_torque_n_m,
        };
        rel.step(self.t, self.shaft, self.phi, self.dphi, h)
    }

    fn phi_end(&self, step: &SubStep, _: usize) -> f64 {
        step.phi
    }

    fn evals_per_step(&self) -> u64 {
        3
    }

    fn accept(
        &mut self,
        run: &mut Run,
        step: SubStep,
        t: f64,
        _: Option<usize>,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        // On an inertial carrier (shaft, drum) the teeth's work is internal (the drive's or
        // the load's is the carrier's, integrated with it) and a coupling integrated here is
        // in free flight (the others go with the carrier, `integrate_carrier`): one that
        // touches all the same is counted.
        let inertial = matches!(self.path, Path::Nodes(_));
        (self.t, self.phi, self.dphi, self.shaft) = (t, step.phi, step.dphi, step.shaft);
        ws.counts.substeps += 1;
        ws.counts.evals += step.evals + 1;
        run.energy
            .add_sub_step(if inertial { 0.0 } else { step.drive_j }, step.drag_j);
        run.energy.add_stack_work(step.gap_j);
        let steps_per_contact = if self.known {
            ws.alone.steps_per_contact
        } else {
            ws.a.steps_per_contact
        };
        let depth = run.end_sub_step(
            self.i,
            t,
            self.phi,
            self.dphi,
            self.shaft,
            steps_per_contact,
            ws,
        )?;
        self.evaluated_here = true;
        if inertial && depth > 0.0 && !self.missed {
            self.missed = true;
            ws.counts.missed += 1;
        }
        Ok(())
    }
}
