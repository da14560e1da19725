//! The clamped stack in the multirate scheme (crate docs, "The clamped stack"): from the time
//! the piston may push (`Piston::open_until_s`) every disc and plate of the stack and the drum
//! are integrated together as one system with classical Runge-Kutta sub-steps, the bodies
//! locked to each other by their faces as one body, the slipping faces' friction a torque
//! along the sub-steps, then the rapier world takes one step with each body's impulse.
//!
//! Within a world step the faces are events: a slipping face whose slip reaches zero is landed
//! on and locks if its holding torque `mu(0) F R_eff` can keep its two sides together (else it
//! slips the other way); a locked face whose torque exceeds its holding torque breaks at the
//! end of the sub-step that found it (as the shared step's velocity-level friction finds it at
//! the end of its step) and slips the way that torque pushes. The clamp forces follow the
//! teeth's loads at every stage (the splines' friction, `StackModel::clamp_forces_n`).

// Index loops over the bodies (coupling order) and the interfaces (interface m joins stack
// positions m and m + 1) mirror the equations; iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

use super::state::{Run, ShaftDrive};
use super::substep::{checked_sub_step, graded_step, split_remainder, Counts, Node, ShaftAt};
use crate::hook::FLANKS;
use crate::options::AdaptiveStepping;
use crate::stack::Face;
use crate::stepping::{bracketed_root, coupling_step, crosses_contact};
use crate::world::Carrier;
use clutchpack_model::{DiscSample, EngineError, ImpactEvent, SpeedProfile};
use std::sync::Arc;

/// Sub-steps of the clamped stack are at most the world step over this (dimensionless), as an
/// inertial carrier's: the locked groups' and the drum's motion under the drive's and the
/// load's torques is integrated by the classical method.
const STACK_SUB_STEPS: f64 = 4.0;

/// The stack's bodies over a world step: what stays fixed along its sub-steps.
struct System {
    /// Coupling index of each stack position (plate, disc, plate, ...).
    body: Vec<usize>,
    /// Each coupling's inertia about the axis, kg m^2 (rapier's), and drag `C2`, N m s/rad.
    j: Vec<f64>,
    c2: Vec<f64>,
    /// The prescribed shaft's profile.
    profile: Arc<SpeedProfile>,
    /// The drum's inverse inertia, 1/(kg m^2), damping, N m s/rad, and load, N m (held over
    /// the world step; zeros without a drum).
    drum: Option<(f64, f64, f64)>,
    /// Each coupling's carrier.
    carriers: Vec<Carrier>,
}

/// What the system does at one stage.
struct Stage {
    /// Each coupling body's acceleration, rad/s^2, and the drum's.
    acc: Vec<f64>,
    acc_drum: f64,
    /// The teeth's torque on each coupling body, N m.
    teeth: Vec<f64>,
    /// Each interface's torque on its upper body, N m: friction or the gap's drag of a
    /// slipping or open face, the holding torque of a locked one.
    face: Vec<f64>,
    /// Each interface's clamp force, N.
    clamp: Vec<f64>,
}

impl Run {
    /// The accelerations of the stack's bodies and the drum at `ts` with the teeth's torques
    /// `teeth` (coupling order, N m), the bodies' speeds `u` (rad/s) and the drum's `w_drum`,
    /// the faces `faces`: each body's teeth, drag and the slipping or open faces' torques;
    /// locked runs of bodies share one acceleration (their total torque over their total
    /// inertia), and the torque each locked face passes is what keeps its two sides together.
    fn stack_stage(
        &self,
        sys: &System,
        faces: &[Face],
        ts: f64,
        teeth: Vec<f64>,
        u: &[f64],
        w_drum: f64,
    ) -> Stage {
        let stack = self.stack.as_ref().expect("a stack");
        let n_if = faces.len();
        let normal: Vec<f64> = teeth
            .iter()
            .enumerate()
            .map(|(i, t)| t.abs() / self.couplings[i].base_radius_m())
            .collect();
        let mut clamp = vec![0.0; n_if];
        stack.clamp_at(ts, &normal, &mut clamp);
        let c_gap = stack.gap_damping();
        let mut face = vec![0.0; n_if];
        let mut torque: Vec<f64> = sys
            .body
            .iter()
            .map(|&i| teeth[i] - sys.c2[i] * u[i])
            .collect();
        for m in 0..n_if {
            let Face::Slipping(dir) = faces[m] else {
                continue;
            };
            let v = u[sys.body[m + 1]] - u[sys.body[m]];
            face[m] = if clamp[m] > 0.0 {
                -dir * stack.slip_torque_n_m(clamp[m], v)
            } else {
                -c_gap * v
            };
            torque[m + 1] += face[m];
            torque[m] -= face[m];
        }
        let mut acc = vec![0.0; u.len()];
        let mut lo = 0;
        while lo < sys.body.len() {
            let mut hi = lo;
            while hi < n_if && faces[hi] == Face::Locked {
                hi += 1;
            }
            // stack positions lo..=hi turn as one
            let (t_sum, j_sum) = (lo..=hi).fold((0.0, 0.0), |(t, j), b| {
                (t + torque[b], j + sys.j[sys.body[b]])
            });
            let alpha = t_sum / j_sum;
            let (mut t_run, mut j_run) = (0.0, 0.0);
            for b in lo..=hi {
                acc[sys.body[b]] = alpha;
                t_run += torque[b];
                j_run += sys.j[sys.body[b]];
                if b < hi {
                    // the face above b holds the part lo..=b on the group's acceleration
                    face[b] = t_run - j_run * alpha;
                }
            }
            lo = hi + 1;
        }
        let acc_drum = match sys.drum {
            Some((inv_j, damping, load)) => {
                let on_drum: f64 = (0..u.len())
                    .filter(|&i| sys.carriers[i] == Carrier::Drum)
                    .map(|i| teeth[i])
                    .sum();
                (load - damping * w_drum - on_drum) * inv_j
            }
            None => 0.0,
        };
        Stage {
            acc,
            acc_drum,
            teeth,
            face,
            clamp,
        }
    }

    /// Whether the clamped stack's integration can run this pack: a stack on a prescribed
    /// shaft (an inertial shaft with a stack that clamps hands over to the shared step).
    pub(super) fn can_integrate_clamped_stack(&self) -> bool {
        self.stack.is_some() && matches!(self.shaft, ShaftDrive::Prescribed(_))
    }

    /// Advances the whole clamped stack (every disc and plate, and the drum) from `t` to `t1`
    /// as one system (module docs), then the rapier world one step with each body's impulse.
    pub(super) fn clamped_step(
        &mut self,
        t1: f64,
        a: &AdaptiveStepping,
        counts: &mut Counts,
        closed: &mut Vec<ImpactEvent>,
        contacts: &mut Vec<(usize, f64, DiscSample)>,
    ) -> Result<(), EngineError> {
        let ShaftDrive::Prescribed(profile) = &self.shaft else {
            unreachable!("the clamped stack's integration runs on a prescribed shaft");
        };
        let profile = Arc::clone(profile);
        let n = self.couplings.len();
        let stack = self.stack.as_ref().expect("a stack");
        let n_if = stack.interfaces();
        if self.faces.len() != n_if {
            // the first clamped step: every face slips the way it slips now
            self.faces = (0..n_if)
                .map(|m| Face::Slipping(stack.slip[m].signum()))
                .collect();
        }
        let sys = System {
            body: stack.body.clone(),
            j: (0..n)
                .map(|i| 1.0 / self.inv_inertia_z(self.world.discs[i]))
                .collect(),
            c2: self.bodies.iter().map(|d| d.drag_n_m_s_rad).collect(),
            profile: Arc::clone(&profile),
            drum: self.drum.as_ref().map(|d| {
                (
                    1.0 / d.model.inertia_kg_m2,
                    d.model.drag_n_m_s_rad,
                    d.model.load_torque_n_m,
                )
            }),
            carriers: self.world.carriers.clone(),
        };
        let t0 = self.t;
        let h_world = t1 - t0;
        let mut t = t0;
        let phi0: Vec<f64> = self.rel.iter().map(|r| r.phi).collect();
        let mut phi = phi0.clone();
        let mut u: Vec<f64> = self.omega_d.clone();
        let mut turn = vec![0.0; n];
        let (drum_angle0, drum_w0) = self
            .drum
            .as_ref()
            .map_or((0.0, 0.0), |d| (d.theta, d.omega));
        let (mut drum_angle, mut w_drum) = (drum_angle0, drum_w0);
        let mut shaft = ShaftAt::of(Some(&profile), t);
        let mut impulse = vec![0.0; n_if];
        let mut evaluated_here = false;
        let cap = a.max_step_s / STACK_SUB_STEPS;
        while t < t1 {
            // the teeth's torques at t: the last sub-step's evaluation, else probes
            let teeth0: Vec<f64> = if evaluated_here {
                self.forces.iter().map(|f| f.moment[2]).collect()
            } else {
                counts.evals += n as u64;
                (0..n)
                    .map(|i| self.couplings[i].probe_torque(phi[i], self.rel[i].dphi))
                    .collect()
            };
            let s0 = self.stack_stage(&sys, &self.faces, t, teeth0, &u, w_drum);
            // the step each coupling wants, its body's acceleration bounded by its locked
            // group's torques and its carrier's
            let mut want = cap;
            let drum_bound = sys.drum.map_or(0.0, |(inv_j, damping, load)| {
                let on: f64 = (0..n)
                    .filter(|&i| sys.carriers[i] == Carrier::Drum)
                    .map(|i| s0.teeth[i].abs())
                    .sum();
                (load.abs() + damping * w_drum.abs() + on) * inv_j
            });
            for i in 0..n {
                let carrier = match sys.carriers[i] {
                    Carrier::Shaft => self.shaft_accel_bound,
                    Carrier::Drum => drum_bound,
                    Carrier::Housing => 0.0,
                };
                let bound = carrier + 2.0 * s0.acc[i].abs() + 1.0;
                let f = self.forces[i];
                let view = self.coupling_view(i, &f, (phi[i], self.rel[i].dphi), bound, t);
                let (w, _) = coupling_step(&view, a);
                want = want.min(graded_step(w, &f, self.events.event_age_s(i, t)));
            }
            let want = checked_sub_step(want, a, t, || "the clamped stack".into())?;
            let rem = t1 - t;
            let mut h = split_remainder(want, rem);
            let faces = self.faces.clone();
            let rk4 = |x: f64| self.stack_rk4(&sys, &faces, &s0, t, shaft, &phi, &u, w_drum, x);
            let mut step = rk4(h);
            counts.evals += 3 * n as u64;
            // land on the first onset or separation of any coupling, or the first slip
            // reaching zero
            let tiny = 1e-3 * h.min(want);
            let evals = std::cell::Cell::new(0);
            let mut first: Option<(f64, Option<usize>)> = None;
            let mut consider = |x: f64, face: Option<usize>| {
                if x > tiny && x < h && first.is_none_or(|(b, _)| x < b) {
                    first = Some((x, face));
                }
            };
            for i in 0..n {
                let d = &self.bodies[i];
                let f = &self.forces[i];
                let (g0, rb) = (d.spline.half_play_rad(), self.couplings[i].base_radius_m());
                let offset = d.law.engagement_offset_m();
                let engaged = f.depth_m > 0.0;
                for flank in FLANKS {
                    if engaged && flank != f.kin.flank {
                        continue;
                    }
                    let sigma = flank.phi_sign();
                    let shift = self.couplings[i].deepest_tooth_shift_m(flank);
                    let depth = |p: f64| (sigma * p - g0) * rb + offset + shift;
                    let (d0, d1) = (depth(phi[i]), depth(step.phi[i]));
                    if !crosses_contact(engaged, d0, d1) {
                        continue;
                    }
                    let x = bracketed_root(
                        |x| {
                            evals.set(evals.get() + 3 * n as u64);
                            depth(rk4(x).phi[i])
                        },
                        0.0,
                        d0,
                        h,
                        d1,
                        1e-16,
                    );
                    consider(x, None);
                }
            }
            for m in 0..n_if {
                let Face::Slipping(dir) = faces[m] else {
                    continue;
                };
                if s0.clamp[m] <= 0.0 {
                    continue;
                }
                let (lo, up) = (sys.body[m], sys.body[m + 1]);
                let g = |s: &StackStep| dir * (s.u[up] - s.u[lo]);
                let (g0, g1) = (dir * (u[up] - u[lo]), g(&step));
                if g0 > 0.0 && g1 <= 0.0 {
                    let x = bracketed_root(
                        |x| {
                            evals.set(evals.get() + 3 * n as u64);
                            g(&rk4(x))
                        },
                        0.0,
                        g0,
                        h,
                        g1,
                        0.0,
                    );
                    consider(x, Some(m));
                }
            }
            counts.evals += evals.get();
            let mut locks = None;
            if let Some((x, face)) = first {
                h = x;
                step = rk4(x);
                counts.evals += 3 * n as u64;
                locks = face;
            }
            t = if h == rem { t1 } else { t + h };
            for (x, dx) in turn.iter_mut().zip(&step.turn) {
                *x += dx;
            }
            phi.clone_from(&step.phi);
            u.clone_from(&step.u);
            drum_angle += step.drum_turn;
            w_drum = step.w_drum;
            shaft = ShaftAt::of(Some(&profile), t);
            for m in 0..n_if {
                impulse[m] += step.impulse[m];
            }
            counts.substeps += 1;
            self.energy.add_sub_step(step.drive_j, step.drag_j);
            self.energy.add_load_work(step.load_j);
            self.energy.add_stack_work(step.face_j.iter().sum());
            let stack = self.stack.as_mut().expect("a stack");
            for m in 0..n_if {
                stack.dissipated_j[m] -= step.face_j[m];
            }
            if let Some(m) = locks {
                self.lock_face(&sys, m, &mut u);
            }
            for i in 0..n {
                let at = match sys.carriers[i] {
                    Carrier::Shaft => shaft,
                    Carrier::Drum => ShaftAt {
                        speed: w_drum,
                        angle: drum_angle,
                    },
                    Carrier::Housing => ShaftAt {
                        speed: 0.0,
                        angle: 0.0,
                    },
                };
                let dphi = at.speed - u[i];
                self.end_sub_step(i, t, phi[i], dphi, at, a, closed, contacts)?;
            }
            evaluated_here = true;
            self.break_faces(&sys, t, &u, w_drum);
        }
        // the bodies' and the drum's states at t1, their mean speeds over the step
        let means: Vec<f64> = turn.iter().map(|x| x / h_world).collect();
        self.omega_d.clone_from(&u);
        let mut carriers = Vec::new();
        if let (Some(d), Some(handle)) = (self.drum.as_mut(), self.world.drum) {
            (d.theta, d.omega) = (drum_angle, w_drum);
            let start = Node {
                t: t0,
                angle: drum_angle0,
                speed: drum_w0,
            };
            let end = Node {
                t: t1,
                angle: drum_angle,
                speed: w_drum,
            };
            carriers.push((handle, start, end));
        }
        self.potential_j = self.forces.iter().map(|f| f.potential_j).sum();
        let locked: Vec<bool> = self.faces.iter().map(|f| *f == Face::Locked).collect();
        self.stack
            .as_mut()
            .expect("a stack")
            .record_step(h_world, &impulse, &locked);
        self.finish_world_step(&means, t1, Some(&profile), &carriers);
        Ok(())
    }

    /// Locks face `m` whose slip just reached zero (landed): its two sides' speeds made equal
    /// to their momentum-weighted mean (the rounding of the landing; the kinetic energy that
    /// takes is the face's heat), then the break check decides whether it holds.
    fn lock_face(&mut self, sys: &System, m: usize, u: &mut [f64]) {
        self.faces[m] = Face::Locked;
        let nb = sys.body.len();
        let (mut lo, mut hi) = (m, m + 1);
        while lo > 0 && self.faces[lo - 1] == Face::Locked {
            lo -= 1;
        }
        while hi + 1 < nb && self.faces[hi] == Face::Locked {
            hi += 1;
        }
        let (mut p, mut j, mut e0) = (0.0, 0.0, 0.0);
        for b in lo..=hi {
            let i = sys.body[b];
            p += sys.j[i] * u[i];
            j += sys.j[i];
            e0 += 0.5 * sys.j[i] * u[i] * u[i];
        }
        let w = p / j;
        for b in lo..=hi {
            u[sys.body[b]] = w;
        }
        let lost = e0 - 0.5 * j * w * w;
        self.energy.add_stack_work(-lost);
        self.stack.as_mut().expect("a stack").dissipated_j[m] += lost;
    }

    /// Breaks every locked face whose torque exceeds its holding torque at `t` (the state
    /// just evaluated: the teeth's torques in `forces`), the worst first, each then slipping
    /// the way that torque pushes its upper side (module docs).
    fn break_faces(&mut self, sys: &System, t: f64, u: &[f64], w_drum: f64) {
        loop {
            let teeth: Vec<f64> = self.forces.iter().map(|f| f.moment[2]).collect();
            let s = self.stack_stage(sys, &self.faces, t, teeth, u, w_drum);
            let stack = self.stack.as_ref().expect("a stack");
            let mut worst: Option<(f64, usize)> = None;
            for m in 0..self.faces.len() {
                if self.faces[m] != Face::Locked {
                    continue;
                }
                let hold = stack.holding_torque_n_m(s.clamp[m]);
                let excess = s.face[m].abs() - hold;
                if excess > 0.0 && worst.is_none_or(|(e, _)| excess > e) {
                    worst = Some((excess, m));
                }
            }
            let Some((_, m)) = worst else {
                return;
            };
            // the upper side gets less than it needs: it falls behind (slip < 0) if it needed
            // a positive torque
            self.faces[m] = Face::Slipping(-s.face[m].signum());
        }
    }
}

/// One classical Runge-Kutta step of the clamped stack ([`Run::stack_rk4`]).
struct StackStep {
    /// Each coupling body's turn, rad, speed at the end, rad/s, and relative angle at the end.
    turn: Vec<f64>,
    u: Vec<f64>,
    phi: Vec<f64>,
    /// The drum's turn, rad, and speed at the end, rad/s.
    drum_turn: f64,
    w_drum: f64,
    /// Each interface's impulse on its upper body, N m s, and the work of its torque on the
    /// slip (friction, the gap's drag; 0 locked), J (<= 0).
    impulse: Vec<f64>,
    face_j: Vec<f64>,
    /// Work of the shaft on the discs' teeth, of the drag (bodies and drum) and of the drum's
    /// load, J.
    drive_j: f64,
    drag_j: f64,
    load_j: f64,
}

impl Run {
    /// One classical Runge-Kutta step of length `h` from `t` of the clamped stack and the drum
    /// (the faces `faces` held), from the bodies' speeds `u0`, relative angles `phi`, the
    /// drum's speed `w0_drum`, the first stage `s0` already evaluated; the works integrated
    /// by the same stages.
    #[allow(clippy::too_many_arguments)]
    fn stack_rk4(
        &self,
        sys: &System,
        faces: &[Face],
        s0: &Stage,
        t: f64,
        shaft: ShaftAt,
        phi: &[f64],
        u0: &[f64],
        w0_drum: f64,
        h: f64,
    ) -> StackStep {
        let n = u0.len();
        let hh = h * h;
        let (tm, te) = (t + 0.5 * h, t + h);
        let (mid, end) = (
            ShaftAt::of(Some(&sys.profile), tm),
            ShaftAt::of(Some(&sys.profile), te),
        );
        // the carriers' turns from t and speeds at a stage: the shaft's exact
        let stage = |ts: f64, at: ShaftAt, d_turn: f64, wd: f64, th: &[f64], u: &[f64]| {
            let teeth = (0..n)
                .map(|i| {
                    let (turn, speed) = match sys.carriers[i] {
                        Carrier::Shaft => (at.angle - shaft.angle, at.speed),
                        Carrier::Drum => (d_turn, wd),
                        Carrier::Housing => (0.0, 0.0),
                    };
                    self.couplings[i].probe_torque(phi[i] + turn - th[i], speed - u[i])
                })
                .collect();
            self.stack_stage(sys, faces, ts, teeth, u, wd)
        };
        let k1 = s0;
        let th2: Vec<f64> = u0.iter().map(|u| 0.5 * h * u).collect();
        let u2: Vec<f64> = (0..n).map(|i| u0[i] + 0.5 * h * k1.acc[i]).collect();
        let (dt2, wd2) = (0.5 * h * w0_drum, w0_drum + 0.5 * h * k1.acc_drum);
        let k2 = stage(tm, mid, dt2, wd2, &th2, &u2);
        let th3: Vec<f64> = (0..n)
            .map(|i| 0.5 * h * u0[i] + 0.25 * hh * k1.acc[i])
            .collect();
        let u3: Vec<f64> = (0..n).map(|i| u0[i] + 0.5 * h * k2.acc[i]).collect();
        let (dt3, wd3) = (
            0.5 * h * w0_drum + 0.25 * hh * k1.acc_drum,
            w0_drum + 0.5 * h * k2.acc_drum,
        );
        let k3 = stage(tm, mid, dt3, wd3, &th3, &u3);
        let th4: Vec<f64> = (0..n).map(|i| h * u0[i] + 0.5 * hh * k2.acc[i]).collect();
        let u4: Vec<f64> = (0..n).map(|i| u0[i] + h * k3.acc[i]).collect();
        let (dt4, wd4) = (
            h * w0_drum + 0.5 * hh * k2.acc_drum,
            w0_drum + h * k3.acc_drum,
        );
        let k4 = stage(te, end, dt4, wd4, &th4, &u4);
        let h6 = h / 6.0;
        let quad = |a: f64, b: f64, c: f64, d: f64| h6 * (a + 2.0 * (b + c) + d);
        let mut turn = Vec::with_capacity(n);
        let mut u1 = Vec::with_capacity(n);
        let mut phi1 = Vec::with_capacity(n);
        let drum_turn = h * w0_drum + h * h6 * (k1.acc_drum + k2.acc_drum + k3.acc_drum);
        let w_drum = quad(k1.acc_drum, k2.acc_drum, k3.acc_drum, k4.acc_drum) + w0_drum;
        let (mut drive_j, mut drag_j) = (0.0, 0.0);
        for i in 0..n {
            let th = h * u0[i] + h * h6 * (k1.acc[i] + k2.acc[i] + k3.acc[i]);
            turn.push(th);
            u1.push(u0[i] + quad(k1.acc[i], k2.acc[i], k3.acc[i], k4.acc[i]));
            let carrier_turn = match sys.carriers[i] {
                Carrier::Shaft => end.angle - shaft.angle,
                Carrier::Drum => drum_turn,
                Carrier::Housing => 0.0,
            };
            phi1.push(phi[i] + carrier_turn - th);
            if sys.carriers[i] == Carrier::Shaft {
                drive_j += quad(
                    k1.teeth[i] * shaft.speed,
                    k2.teeth[i] * mid.speed,
                    k3.teeth[i] * mid.speed,
                    k4.teeth[i] * end.speed,
                );
            }
            let c2 = sys.c2[i];
            drag_j -= c2 * quad(u0[i] * u0[i], u2[i] * u2[i], u3[i] * u3[i], u4[i] * u4[i]);
        }
        let mut load_j = 0.0;
        if let Some((_, damping, load)) = sys.drum {
            drag_j -= damping * quad(w0_drum * w0_drum, wd2 * wd2, wd3 * wd3, wd4 * wd4);
            load_j = load * quad(w0_drum, wd2, wd3, wd4);
        }
        let n_if = faces.len();
        let mut impulse = vec![0.0; n_if];
        let mut face_j = vec![0.0; n_if];
        for m in 0..n_if {
            impulse[m] = quad(k1.face[m], k2.face[m], k3.face[m], k4.face[m]);
            if faces[m] != Face::Locked {
                let (lo, up) = (sys.body[m], sys.body[m + 1]);
                let v = |u: &[f64]| u[up] - u[lo];
                face_j[m] = quad(
                    k1.face[m] * v(u0),
                    k2.face[m] * v(&u2),
                    k3.face[m] * v(&u3),
                    k4.face[m] * v(&u4),
                );
            }
        }
        StackStep {
            turn,
            u: u1,
            phi: phi1,
            drum_turn,
            w_drum,
            impulse,
            face_j,
            drive_j,
            drag_j,
            load_j,
        }
    }
}
