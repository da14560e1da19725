//! The clamped stack in the multirate scheme (crate docs, "The clamped stack"): from the time
//! the piston may push (`Piston::open_until_s`) every disc and plate of the stack, the drum
//! and an inertial shaft (its drive, Hu et al. eq 4, at every stage) are integrated together
//! as one system with classical Runge-Kutta sub-steps, the bodies locked to each other by
//! their faces as one body, the slipping faces' friction a torque along the sub-steps, then
//! the rapier world takes one step with each body's impulse.
//!
//! Within a world step the faces are events: a slipping face whose slip reaches zero is
//! landed on and locks if its holding torque `mu(0) F R_eff` can keep its two sides together
//! (else it slips the other way); a locked face whose torque exceeds its holding torque breaks
//! at the end of the sub-step that found it (as the shared step's velocity-level friction
//! finds it at the end of its step) and slips the way that torque pushes. The clamp forces
//! follow the teeth's loads at every stage (the splines' friction,
//! `StackModel::clamp_forces_with`).

// Index loops over the bodies (coupling order) and the interfaces (interface m joins stack
// positions m and m + 1) mirror the equations; iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

use super::carriers::{External, Motion};
use super::landing::SubSteps;
use super::scheme_state::{powers, RkBuffers, Stage};
use super::state::Run;
use super::substep::{
    checked_sub_step, cut, graded_step, Node, Prescribed, ShaftAt, WorldStep, KINK_FLOOR_DIVISOR,
};
use crate::stack::Face;
use crate::stepping::{bracketed_root, coupling_step};
use clutchpack_model::{EngineError, LocalProfile, SpeedProfile};
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
    /// The prescribed shaft's profile (`None`: the shaft is inertial), and its expansion
    /// about the world step's middle ([`Prescribed`]).
    profile: Option<Arc<SpeedProfile>>,
    local: Option<LocalProfile>,
    /// The inertial carriers integrated with the stack (an inertial shaft, the drum; any
    /// number, in this order).
    spins: Vec<Spin>,
    /// How each coupling's carrier moves.
    mounts: Vec<Mount>,
}

impl System {
    /// The prescribed shaft over the world step (`None`: the shaft is inertial).
    fn shaft(&self) -> Option<Prescribed<'_>> {
        self.profile.as_deref().map(|profile| Prescribed {
            profile,
            local: self.local.as_ref(),
        })
    }
}

/// An inertial carrier integrated with the clamped stack: `J w' = T_ext(t) - C w - sum T_k`
/// over the couplings it carries (the shaft: Hu et al. eq 4; the drum: its load and drag).
struct Spin {
    /// Its index in the run's carriers (its external torque, its state).
    carrier: usize,
    /// Whether its external torque's work is a load's in the audit (else the drive's).
    load: bool,
    /// `1 / J`, 1/(kg m^2), and the damping `C`, N m s/rad.
    inv_j: f64,
    damping: f64,
}

/// How a coupling's carrier moves within the clamped stack's sub-steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mount {
    /// The prescribed shaft: its profile, exact.
    Profile,
    /// The housing, at rest.
    Housing,
    /// Inertial carrier `k` of [`System::spins`], integrated with the stack.
    Spin(usize),
}

impl Run {
    /// The accelerations of the stack's bodies and the drum at `ts` with the teeth's torques
    /// `st.teeth` (coupling order, N m), the bodies' speeds `u` (rad/s) and the inertial
    /// carriers' `w` ([`System::spins`] order, rad/s), the faces `faces`, into `st`: each
    /// body's teeth, drag and the slipping or
    /// open faces' torques; locked runs of bodies share one acceleration (their total torque
    /// over their total inertia), and the torque each locked face passes is what keeps its two
    /// sides together.
    fn stack_stage(
        &self,
        sys: &System,
        faces: &[Face],
        ts: f64,
        u: &[f64],
        w: &[f64],
        st: &mut Stage,
    ) {
        let stack = self.stack.as_ref().expect("a stack");
        let n_if = faces.len();
        stack.clamp_at(
            ts,
            |b| {
                let i = sys.body[b];
                st.teeth[i].abs() / self.couplings[i].base_radius_m()
            },
            &mut st.clamp,
        );
        let c_gap = stack.gap_damping();
        for (b, &i) in sys.body.iter().enumerate() {
            st.torque[b] = st.teeth[i] - sys.c2[i] * u[i];
        }
        for m in 0..n_if {
            st.face[m] = 0.0;
            let Face::Slip(dir) = faces[m] else {
                continue;
            };
            let v = u[sys.body[m + 1]] - u[sys.body[m]];
            st.face[m] = if st.clamp[m] > 0.0 {
                -dir * stack.slip_torque_n_m(m, st.clamp[m], v)
            } else {
                -c_gap * v
            };
            st.torque[m + 1] += st.face[m];
            st.torque[m] -= st.face[m];
        }
        let mut lo = 0;
        while lo < sys.body.len() {
            let mut hi = lo;
            while hi < n_if && faces[hi] == Face::Locked {
                hi += 1;
            }
            // stack positions lo..=hi turn as one
            let (t_sum, j_sum) = (lo..=hi).fold((0.0, 0.0), |(t, j), b| {
                (t + st.torque[b], j + sys.j[sys.body[b]])
            });
            let alpha = t_sum / j_sum;
            let (mut t_run, mut j_run) = (0.0, 0.0);
            for b in lo..=hi {
                st.acc[sys.body[b]] = alpha;
                t_run += st.torque[b];
                j_run += sys.j[sys.body[b]];
                if b < hi {
                    // the face above b holds the part lo..=b on the group's acceleration
                    st.face[b] = t_run - j_run * alpha;
                }
            }
            lo = hi + 1;
        }
        for (k, c) in sys.spins.iter().enumerate() {
            // the drive (eq 4) or the load, the damping, the teeth's reactions
            let external = self.external_at(c.carrier, ts);
            st.external[k] = external;
            let on: f64 = (0..u.len())
                .filter(|&i| sys.mounts[i] == Mount::Spin(k))
                .map(|i| st.teeth[i])
                .sum();
            st.acc_carrier[k] = (external - c.damping * w[k] - on) * c.inv_j;
        }
    }

    /// Advances the whole clamped stack (every disc and plate, the drum, an inertial shaft)
    /// from `t` to `t1` as one system (module docs), then the rapier world one step with each
    /// body's impulse.
    pub(super) fn clamped_step(&mut self, ws: &mut WorldStep) -> Result<(), EngineError> {
        let (t1, a) = (ws.t1, ws.a);
        // the prescribed carrier's profile (the shaft's, if prescribed: `ws.drive`)
        let profile = self.carriers.iter().find_map(|k| match &k.motion {
            Motion::Prescribed(p) => Some(Arc::clone(p)),
            _ => None,
        });
        let n = self.couplings.len();
        let stack = self.stack.as_ref().expect("a stack");
        let n_if = stack.interfaces();
        if self.multirate.faces.len() != n_if {
            // the first clamped step: every face slips the way it slips now
            self.multirate.faces = (0..n_if)
                .map(|m| Face::Slip(stack.slip[m].signum()))
                .collect();
        }
        // the inertial carriers in table order (an inertial shaft, then the drum)
        let spins: Vec<Spin> = (self.inertial_carriers().into_iter())
            .map(|carrier| {
                let (inv_j, damping) = self.carriers[carrier].inertia();
                Spin {
                    carrier,
                    load: matches!(self.carriers[carrier].external, External::Load(_)),
                    inv_j,
                    damping,
                }
            })
            .collect();
        let mounts = (0..n)
            .map(|i| {
                let c = self.world.carrier_of[i];
                match self.carriers[c].motion {
                    Motion::Fixed => Mount::Housing,
                    Motion::Prescribed(_) => Mount::Profile,
                    Motion::Inertial { .. } => {
                        Mount::Spin(spins.iter().position(|s| s.carrier == c).expect("a spin"))
                    }
                }
            })
            .collect();
        let sys = System {
            body: stack.body.clone(),
            j: (0..n)
                .map(|i| 1.0 / self.inv_inertia_z(self.world.discs[i]))
                .collect(),
            c2: self.bodies.iter().map(|d| d.drag_n_m_s_rad).collect(),
            profile: profile.clone(),
            local: ws.drive.and_then(|d| d.local.cloned()),
            spins,
            mounts,
        };
        let n_spin = sys.spins.len();
        let t0 = self.t;
        let h_world = t1 - t0;
        // the inertial carriers' angles and speeds
        let (angle0, w0): (Vec<f64>, Vec<f64>) = sys
            .spins
            .iter()
            .map(|c| self.carrier_state(c.carrier))
            .unzip();
        let bufs = (self.multirate.stack_buffers.take())
            .filter(|b| b.fits(n, n_spin))
            .unwrap_or_else(|| RkBuffers::new(n, n_spin));
        let mut st = StackSteps {
            all: (0..n).collect(),
            t: t0,
            phi: self.rel.iter().map(|r| r.phi).collect(),
            u: self.omega_d.clone(),
            turn: vec![0.0; n],
            angle: angle0.clone(),
            w: w0.clone(),
            shaft: ShaftAt::of(sys.shaft(), t0),
            impulse: vec![0.0; n_if],
            evaluated_here: false,
            cap: a.max_step_s / STACK_SUB_STEPS,
            s0: Stage::new(n, n_spin),
            bufs: std::cell::RefCell::new(bufs),
            phi_h: vec![0.0; n],
            u_h: vec![0.0; n],
            faces: Vec::new(),
            sys,
        };
        self.land_sub_steps(&mut st, ws)?;
        // the bodies' and the drum's states at t1, their mean speeds over the step
        let means: Vec<f64> = st.turn.iter().map(|x| x / h_world).collect();
        self.omega_d.clone_from(&st.u);
        let mut carriers = Vec::new();
        for (k, c) in st.sys.spins.iter().enumerate() {
            let node = |t, angle, speed| Node { t, angle, speed };
            let (start, end) = (node(t0, angle0[k], w0[k]), node(t1, st.angle[k], st.w[k]));
            carriers.push((c.carrier, start, end));
            self.set_carrier_state(c.carrier, st.angle[k], st.w[k]);
        }
        self.potential_j = self.forces.iter().map(|f| f.potential_j).sum();
        let locked: Vec<bool> = self
            .multirate
            .faces
            .iter()
            .map(|f| *f == Face::Locked)
            .collect();
        // `s0` holds the stage at t1 with the faces as they end (`break_faces`)
        self.stack.as_mut().expect("a stack").record_step(
            h_world,
            &st.impulse,
            &locked,
            &st.s0.face,
        );
        self.finish_world_step(&means, t1, &carriers);
        self.multirate.stack_buffers = Some(st.bufs.into_inner());
        Ok(())
    }

    /// Locks face `m` whose slip just reached zero (landed): its two sides' speeds made equal
    /// to their momentum-weighted mean (the rounding of the landing; the kinetic energy that
    /// takes is the face's heat), then the break check decides whether it holds.
    fn lock_face(&mut self, sys: &System, m: usize, u: &mut [f64]) {
        self.multirate.faces[m] = Face::Locked;
        let nb = sys.body.len();
        let (mut lo, mut hi) = (m, m + 1);
        while lo > 0 && self.multirate.faces[lo - 1] == Face::Locked {
            lo -= 1;
        }
        while hi + 1 < nb && self.multirate.faces[hi] == Face::Locked {
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
        let stack = self.stack.as_mut().expect("a stack");
        stack.dissipated_j[m] += lost;
        stack.friction_j[m] += lost;
    }

    /// Breaks every locked face whose torque exceeds its holding torque at `t` (the state
    /// just evaluated: the teeth's torques in `forces`), the worst first, each then slipping
    /// the way that torque pushes its upper side (module docs); `s` is a stage's buffers.
    fn break_faces(&mut self, sys: &System, t: f64, u: &[f64], w: &[f64], s: &mut Stage) {
        loop {
            for (x, f) in s.teeth.iter_mut().zip(&self.forces) {
                *x = f.moment[2];
            }
            self.stack_stage(sys, &self.multirate.faces, t, u, w, s);
            let stack = self.stack.as_ref().expect("a stack");
            let mut worst: Option<(f64, usize)> = None;
            for m in 0..self.multirate.faces.len() {
                if self.multirate.faces[m] != Face::Locked {
                    continue;
                }
                let hold = stack.holding_torque_n_m(m, s.clamp[m]);
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
            self.multirate.faces[m] = Face::Slip(-s.face[m].signum());
        }
    }
}

/// Where a sub-step of the clamped stack starts ([`Run::stack_step`]).
struct StackStart<'a> {
    /// The faces, held over the sub-step.
    faces: &'a [Face],
    /// The first stage, evaluated at the start.
    k1: &'a Stage,
    /// The start, s, and a prescribed shaft there.
    t: f64,
    shaft: ShaftAt,
    /// Each coupling's relative angle, rad, and its body's speed, rad/s.
    phi: &'a [f64],
    u0: &'a [f64],
    /// The inertial carriers' speeds, rad/s ([`System::spins`] order).
    w0: &'a [f64],
}

impl Run {
    /// One classical Runge-Kutta step ([`Rk4::rk4`]) of length `h` of the clamped stack and
    /// the inertial carriers from `start` (the faces held, the first stage already
    /// evaluated), into `b.out`; the works integrated by the same stages.
    fn stack_step(&self, sys: &System, start: &StackStart, h: f64, b: &mut RkBuffers) {
        let StackStart {
            faces,
            k1,
            t,
            shaft,
            phi,
            u0,
            w0,
        } = *start;
        let (n, n_spin, n_if) = (u0.len(), w0.len(), faces.len());
        let (tm, te) = (t + 0.5 * h, t + h);
        let (mid, end) = (ShaftAt::of(sys.shaft(), tm), ShaftAt::of(sys.shaft(), te));
        let RkBuffers { k, rk, x0, out } = b;
        x0[..n].copy_from_slice(u0);
        x0[n..].copy_from_slice(w0);
        let lens = powers(n, n_spin, n_if);
        // a stage: the first given, the others with the teeth probed with the carriers turned
        // from t (a prescribed shaft's exact, the inertial ones, after the bodies, by
        // `th[n..]` at `x[n..]`) and the bodies by `th[..n]` at `x[..n]`; its powers
        // ([`powers`])
        rk.rk4(t, h, x0, |s, ts, th, x, acc, power| {
            let at = [shaft, mid, mid, end][s];
            let ((th, c_turn), (u, w)) = (th.split_at(n), x.split_at(n));
            let st: &Stage = if s == 0 {
                k1
            } else {
                let st = &mut k[s - 1];
                for i in 0..n {
                    let (turn, speed) = match sys.mounts[i] {
                        Mount::Profile => (at.angle - shaft.angle, at.speed),
                        Mount::Housing => (0.0, 0.0),
                        Mount::Spin(k) => (c_turn[k], w[k]),
                    };
                    st.teeth[i] =
                        self.couplings[i].probe_torque(phi[i] + turn - th[i], speed - u[i]);
                }
                self.stack_stage(sys, faces, ts, u, w, st);
                st
            };
            acc[..n].copy_from_slice(&st.acc);
            acc[n..].copy_from_slice(&st.acc_carrier);
            let [drive, sq, sq_carrier, external, impulse, face_work, friction] = cut(power, lens);
            for ((d, &mount), &torque) in drive.iter_mut().zip(&sys.mounts).zip(&st.teeth) {
                if mount == Mount::Profile {
                    *d = torque * at.speed;
                }
            }
            for (q, &u) in sq.iter_mut().zip(u) {
                *q = u * u;
            }
            for k in 0..n_spin {
                sq_carrier[k] = w[k] * w[k];
                external[k] = st.external[k] * w[k];
            }
            let out = impulse.iter_mut().zip(face_work).zip(friction);
            let of = faces
                .iter()
                .zip(&st.face)
                .zip(&st.clamp)
                .zip(sys.body.windows(2));
            for (((impulse, work), friction), (((mode, &face), &clamp), b)) in out.zip(of) {
                *impulse = face;
                if *mode != Face::Locked {
                    let v = u[b[1]] - u[b[0]];
                    *work = face * v;
                    // the friction's part: the stages where the face is clamped
                    *friction = if clamp > 0.0 { face * v } else { 0.0 };
                }
            }
        });
        let [drive, sq, sq_carrier, external, impulse, face_work, friction] =
            cut(&mut rk.work, lens);
        out.carrier_turn.copy_from_slice(&rk.turn[n..]);
        out.w_carrier.copy_from_slice(&rk.u1[n..]);
        out.turn.copy_from_slice(&rk.turn[..n]);
        out.u.copy_from_slice(&rk.u1[..n]);
        (out.drive_j, out.drag_j, out.load_j) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let turn = out.turn[i];
            let carrier_turn = match sys.mounts[i] {
                Mount::Profile => end.angle - shaft.angle,
                Mount::Housing => 0.0,
                Mount::Spin(k) => out.carrier_turn[k],
            };
            out.phi[i] = phi[i] + carrier_turn - turn;
            if sys.mounts[i] == Mount::Profile {
                out.drive_j += drive[i];
            }
            out.drag_j -= sys.c2[i] * sq[i];
        }
        for (k, spin) in sys.spins.iter().enumerate() {
            out.drag_j -= spin.damping * sq_carrier[k];
            // the external torque's work: the drive's on an inertial shaft (eq 4), the
            // drum's load
            let work = external[k];
            if spin.load {
                out.load_j += work;
            } else {
                out.drive_j += work;
            }
        }
        for m in 0..n_if {
            out.impulse[m] = impulse[m];
            let slipping = faces[m] != Face::Locked;
            out.face_j[m] = if slipping { face_work[m] } else { 0.0 };
            out.friction_j[m] = if slipping { friction[m] } else { 0.0 };
        }
    }
}

/// The clamped stack's sub-steps as the one landing loop drives them
/// ([`Run::land_sub_steps`]): every coupling body and the inertial carriers as one system,
/// the faces' slips reaching zero its own events (landed on, the face then locked).
struct StackSteps {
    /// The system, and every coupling (all are integrated together).
    sys: System,
    all: Vec<usize>,
    /// The time, s; each coupling's relative angle, rad, its body's speed, rad/s, and turn
    /// since the world step's start, rad; the inertial carriers' angles, rad, and speeds,
    /// rad/s; a prescribed shaft.
    t: f64,
    phi: Vec<f64>,
    u: Vec<f64>,
    turn: Vec<f64>,
    angle: Vec<f64>,
    w: Vec<f64>,
    shaft: ShaftAt,
    /// Each interface's impulse on its upper body since the world step's start, N m s.
    impulse: Vec<f64>,
    /// Whether `forces` holds the hook's evaluation at the state (from the first sub-step's
    /// end on).
    evaluated_here: bool,
    /// The longest sub-step, s.
    cap: f64,
    /// The stage at `t` (the first of the next step).
    s0: Stage,
    bufs: std::cell::RefCell<RkBuffers>,
    /// The relative angles and the body speeds at the end of the full sub-step (kept while the
    /// searches' trial steps overwrite the buffers).
    phi_h: Vec<f64>,
    u_h: Vec<f64>,
    /// The faces, held over the sub-step.
    faces: Vec<Face>,
}

impl SubSteps for StackSteps {
    type Step = ();

    fn t(&self) -> f64 {
        self.t
    }

    fn members(&self) -> &[usize] {
        &self.all
    }

    fn phi(&self, k: usize) -> f64 {
        self.phi[k]
    }

    fn want(&mut self, run: &mut Run, ws: &mut WorldStep) -> Result<f64, EngineError> {
        let (a, t, n) = (ws.a, self.t, self.phi.len());
        let sys = &self.sys;
        // the teeth's torques at t: the last sub-step's evaluation, else probes
        for i in 0..n {
            self.s0.teeth[i] = if self.evaluated_here {
                run.forces[i].moment[2]
            } else {
                run.couplings[i].probe_torque(self.phi[i], run.rel[i].dphi)
            };
        }
        if !self.evaluated_here {
            ws.counts.evals += n as u64;
        }
        run.stack_stage(sys, &run.multirate.faces, t, &self.u, &self.w, &mut self.s0);
        // An open face takes the sign of its slip (for when it clamps). A clamped one found
        // slipping against its sign crossed zero unlanded (closer to a sub-step's start
        // than the landing looks): it locks now if it holds (its friction must never push
        // the slip along).
        let mut turned = false;
        for m in 0..run.multirate.faces.len() {
            let Face::Slip(dir) = run.multirate.faces[m] else {
                continue;
            };
            let v = self.u[sys.body[m + 1]] - self.u[sys.body[m]];
            if v == 0.0 || v.signum() == dir {
                continue;
            }
            if self.s0.clamp[m] > 0.0 {
                run.lock_face(sys, m, &mut self.u);
                turned = true;
            } else {
                run.multirate.faces[m] = Face::Slip(v.signum());
            }
        }
        if turned {
            run.break_faces(sys, t, &self.u, &self.w, &mut self.s0);
        }
        // the step each coupling wants, with its relative acceleration bounded by its
        // carrier's bound and twice its body's acceleration at t (plus 1 rad/s^2): the
        // bound only sizes the free-flight sub-steps (how soon a gap may close); every
        // onset within a sub-step is landed on all the same
        let mut want = self.cap;
        let s0 = &self.s0;
        let reaction = |k: usize| -> f64 {
            (0..n)
                .filter(|&i| sys.mounts[i] == Mount::Spin(k))
                .map(|i| s0.teeth[i].abs())
                .sum()
        };
        let spin_bound: Vec<f64> = (sys.spins.iter().enumerate())
            .map(|(k, c)| run.inertial_accel_bound(c.carrier, self.w[k], reaction(k)))
            .collect();
        for i in 0..n {
            let carrier = match sys.mounts[i] {
                Mount::Profile => run.carriers[run.world.carrier_of[i]].drive_bound,
                Mount::Housing => 0.0,
                Mount::Spin(k) => spin_bound[k],
            };
            let bound = carrier + 2.0 * s0.acc[i].abs() + 1.0;
            let f = run.forces[i];
            let view = run.coupling_view(i, &f, (self.phi[i], run.rel[i].dphi), bound, t);
            let (w, _) = coupling_step(&view, a);
            want = want.min(graded_step(
                w,
                &f,
                run.events.event_age_s(i, t),
                KINK_FLOOR_DIVISOR,
            ));
        }
        let want = checked_sub_step(want, a, t, || "the clamped stack".into())?;
        self.faces.clone_from(&run.multirate.faces);
        Ok(want)
    }

    fn step(&self, run: &Run, h: f64) {
        let start = StackStart {
            faces: &self.faces,
            k1: &self.s0,
            t: self.t,
            shaft: self.shaft,
            phi: &self.phi,
            u0: &self.u,
            w0: &self.w,
        };
        run.stack_step(&self.sys, &start, h, &mut self.bufs.borrow_mut());
    }

    fn phi_end(&self, _: &(), k: usize) -> f64 {
        self.bufs.borrow().out.phi[k]
    }

    fn keep(&mut self, _: &()) {
        let b = self.bufs.borrow();
        self.phi_h.copy_from_slice(&b.out.phi);
        self.u_h.copy_from_slice(&b.out.u);
    }

    fn phi_kept(&self, _: &(), k: usize) -> f64 {
        self.phi_h[k]
    }

    fn trials_overwrite(&self) -> bool {
        true
    }

    /// The first slip of a clamped slipping face reaching zero.
    fn events(
        &self,
        run: &Run,
        h: f64,
        consider: &mut dyn FnMut(f64, Option<usize>),
        trials: &std::cell::Cell<u64>,
    ) {
        for m in 0..self.faces.len() {
            let Face::Slip(dir) = self.faces[m] else {
                continue;
            };
            if self.s0.clamp[m] <= 0.0 {
                continue;
            }
            let (lo, up) = (self.sys.body[m], self.sys.body[m + 1]);
            let g = |u: &[f64]| dir * (u[up] - u[lo]);
            let (g0, g1) = (g(&self.u), g(&self.u_h));
            if g0 > 0.0 && g1 <= 0.0 {
                let x = bracketed_root(
                    |x| {
                        trials.set(trials.get() + 1);
                        self.step(run, x);
                        g(&self.bufs.borrow().out.u)
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
    }

    fn evals_per_step(&self) -> u64 {
        3 * self.phi.len() as u64
    }

    fn accept(
        &mut self,
        run: &mut Run,
        _: (),
        t: f64,
        event: Option<usize>,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        let n = self.phi.len();
        // the sub-step's first full step (before the searches)
        ws.counts.evals += 3 * n as u64;
        let b = self.bufs.borrow();
        let step = &b.out;
        self.t = t;
        for (x, dx) in self.turn.iter_mut().zip(&step.turn) {
            *x += dx;
        }
        self.phi.clone_from(&step.phi);
        self.u.clone_from(&step.u);
        for (x, dx) in self.angle.iter_mut().zip(&step.carrier_turn) {
            *x += dx;
        }
        self.w.clone_from(&step.w_carrier);
        self.shaft = ShaftAt::of(self.sys.shaft(), t);
        for (x, dx) in self.impulse.iter_mut().zip(&step.impulse) {
            *x += dx;
        }
        ws.counts.substeps += 1;
        run.energy.add_sub_step(step.drive_j, step.drag_j);
        run.energy.add_load_work(step.load_j);
        run.energy.add_stack_work(step.face_j.iter().sum());
        let stack = run.stack.as_mut().expect("a stack");
        for (x, dx) in stack.dissipated_j.iter_mut().zip(&step.face_j) {
            *x -= dx;
        }
        for (x, dx) in stack.friction_j.iter_mut().zip(&step.friction_j) {
            *x -= dx;
        }
        drop(b);
        if let Some(m) = event {
            run.lock_face(&self.sys, m, &mut self.u);
        }
        for i in 0..n {
            let at = match self.sys.mounts[i] {
                Mount::Profile => self.shaft,
                Mount::Housing => ShaftAt {
                    speed: 0.0,
                    angle: 0.0,
                },
                Mount::Spin(k) => ShaftAt {
                    speed: self.w[k],
                    angle: self.angle[k],
                },
            };
            let dphi = at.speed - self.u[i];
            run.end_sub_step(i, t, self.phi[i], dphi, at, ws.a.steps_per_contact, ws)?;
        }
        self.evaluated_here = true;
        run.break_faces(&self.sys, t, &self.u, &self.w, &mut self.s0);
        Ok(())
    }
}
