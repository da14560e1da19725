//! The stack and friction hook (issue 3, build item 3; MODEL.md section 5; the laws are
//! `clutchpack_model::clutch`): the clamp force of every interface, and the friction or
//! open-gap drag torques between neighbouring discs and plates, solved at velocity level.
//!
//! # Theory
//! Interface `m` joins stack bodies `m` (lower) and `m + 1` (upper). Over a step of length
//! `h` it passes an impulse `Q_m` (N m s) to the upper body and `-Q_m` to the lower, applied
//! by rapier as the constant torque `Q_m / h`. Rapier then ends the step with the bodies'
//! mean speeds `w = w_pred + sum (+-Q) / J`, where `w_pred` holds every other load of the step
//! (the teeth's impulse integrated along the step, drag, the kick of `integrate.rs`).
//!
//! - **Clamped** (`F_m > 0`): Coulomb friction at velocity level (Moreau's time-stepping):
//!   `|Q_m| <= h mu(|v|) F_m R_eff`, with `v` the slip at the start of the step; if the
//!   impulse that makes the two mean speeds equal stays within that bound, the faces stick
//!   (exactly: no regularisation speed, no creep), else they slip with the bound, opposing the
//!   slip left at the end of the step. Stable for any step and any friction coefficient:
//!   friction never reverses the slip within a step.
//! - **Open** (`F_m = 0`): the open-gap drag `-c v` (`c = pi eta (Ro^4 - Ri^4) / (2 h_gap)`),
//!   taken implicitly on the slip at the end of the step (backward Euler: stable for any
//!   viscosity and step).
//!
//! All interfaces of the stack are coupled through the bodies they share. For a guess of
//! which interfaces stick and which slip (and which way), the conditions are linear and
//! tridiagonal along the stack and are solved directly; the guess starts from the last step
//! and is corrected until consistent (a sticking face that needs more than its bound slips, a
//! slipping face whose friction would drive the slip sticks), an active-set method that
//! settles in one or two solves. Should the guesses cycle, projected Gauss-Seidel sweeps
//! (each interface solved for its neighbours' impulses, then clamped to its bound), warm
//! started from the last step, decide instead. (Gauss-Seidel alone converges slowly on a
//! locked stack: measured about a hundred sweeps per step on six locked discs, 40 % of the
//! run time.)

// Index loops over the interfaces mirror the equations (interface m joins stack bodies m and
// m + 1); iterator chains would obscure them.
#![allow(clippy::needless_range_loop)]

use clutchpack_model::{InterfaceSample, PressureProfile, StackBody, StackModel};

/// Most Gauss-Seidel sweeps per step (the fallback of the active-set solve).
const MAX_SWEEPS: usize = 5000;

/// A friction face's state between the sub-steps of the clamped stack's multirate
/// integration (`engine/clamped.rs`): the model's one definition, for both engines (this
/// engine keeps an open face, `F = 0`, as `Slip` with its last sign, for when it clamps).
pub(crate) use clutchpack_model::Face;

/// The stack's state during a run.
#[derive(Debug, Clone)]
pub(crate) struct Stack {
    /// The stack's model (a copy: a session changes its piston's pressure, see
    /// [`Stack::set_pressure`]).
    model: StackModel,
    /// The engine's coupling index of each stack body (`2N + 1`): plate `j` (stack body
    /// `2j`) is coupling `N + j`, disc `i` (stack body `2i + 1`) is coupling `i`.
    pub body: Vec<usize>,
    /// `R_eff` of the faces, m.
    pub r_eff: f64,
    /// Open-gap damping `c`, N m s/rad (0 without an oil gap).
    c_gap: f64,
    /// Clamp force of each interface at the current time, N.
    pub clamp: Vec<f64>,
    /// Slip `omega_upper - omega_lower` of each interface at the current time, rad/s.
    pub slip: Vec<f64>,
    /// Impulse of each interface on its upper body over the step being taken (or last taken),
    /// N m s, and the step's length, s.
    pub impulse: Vec<f64>,
    h: f64,
    /// Whether each interface sticks over that step.
    pub locked: Vec<bool>,
    /// Energy each interface has dissipated since t = 0, J (>= 0): `-sum Q_m (w_upper -
    /// w_lower)` over the steps, with the bodies' mean speeds of each step (kept by the
    /// engine, which knows them after the step).
    pub dissipated_j: Vec<f64>,
    /// The part of [`Self::dissipated_j`] each interface dissipated while clamped (clamp
    /// force `> 0`: friction, and the kinetic energy a lock takes), J (>= 0); the rest is its
    /// open gap's drag. What a thermal run books to the faces' bodies (friction) or to the
    /// oil (drag), kept where each integration knows the clamp force.
    pub friction_j: Vec<f64>,
    /// Torque of the stack on each stack body (stack order) over that step, N m.
    pub torque: Vec<f64>,
    /// Each interface's torque on its upper body at the end of the step, N m, where the
    /// clamped stack's multirate integration knows it ([`Self::record_step`]; empty on the
    /// shared step, whose torque is constant over a step): what the samples report.
    torque_now: Vec<f64>,
    /// [`Stack::update`]'s buffer of the stack bodies' normal loads (kept so that it does
    /// not allocate at every step).
    normal_buf: Vec<f64>,
}

impl Stack {
    /// The stack of `n_discs` discs and `n_discs + 1` plates (couplings `0..n_discs` are the
    /// discs, then the plates).
    pub fn new(model: &StackModel, n_discs: usize) -> Stack {
        let body = (0..2 * n_discs + 1)
            .map(|b| StackBody::at(b).body_index(n_discs))
            .collect();
        let n_if = 2 * n_discs;
        let n_bodies = 2 * n_discs + 1;
        Stack {
            model: model.clone(),
            body,
            r_eff: model.effective_radius_m(),
            c_gap: -model.open_gap_torque_n_m(1.0),
            clamp: vec![0.0; n_if],
            slip: vec![0.0; n_if],
            impulse: vec![0.0; n_if],
            dissipated_j: vec![0.0; n_if],
            friction_j: vec![0.0; n_if],
            h: 0.0,
            locked: vec![false; n_if],
            torque: vec![0.0; n_bodies],
            torque_now: Vec::new(),
            normal_buf: Vec::with_capacity(n_bodies),
        }
    }

    /// Replaces the piston's pressure history (a driven pressure, held from the session's time
    /// on); the clamp forces follow at the next [`Self::update`].
    pub fn set_pressure(&mut self, pressure: PressureProfile) {
        self.model.piston.pressure = pressure;
    }

    /// Replaces the open gaps' oil (a thermal window's new viscosity, MODEL.md section 9):
    /// their drag coefficient follows from the next step on.
    pub fn set_open_gap(&mut self, gap: Option<clutchpack_model::OpenGap>) {
        self.model.open_gap = gap;
        self.c_gap = -self.model.open_gap_torque_n_m(1.0);
    }

    /// Replaces each face's friction curve (a thermal window's `mu(v, T)` at the faces'
    /// temperatures, MODEL.md section 9; empty: the stack's own curve on every face): the
    /// friction follows from the next step on.
    pub fn set_face_friction(&mut self, curves: &[clutchpack_model::FrictionCurve]) {
        self.model.face_friction.clear();
        self.model.face_friction.extend_from_slice(curves);
    }

    /// The length of the step the impulses were last solved for, s (0 before the first).
    pub fn step_s(&self) -> f64 {
        self.h
    }

    /// Number of interfaces (`2N`).
    pub fn interfaces(&self) -> usize {
        self.clamp.len()
    }

    /// Updates the clamp forces and slips at `t_s`: `tooth_normal_n[i]` is the normal load
    /// `n |F|` of coupling `i`'s teeth (N), `omega[i]` its body's speed (rad/s).
    pub fn update(&mut self, t_s: f64, tooth_normal_n: &[f64], omega: &[f64]) {
        let mut q = std::mem::take(&mut self.normal_buf);
        q.clear();
        q.extend(self.body.iter().map(|&i| tooth_normal_n[i]));
        self.model
            .clamp_forces_n(self.model.piston.force_n(t_s), &q, &mut self.clamp);
        self.normal_buf = q;
        for m in 0..self.interfaces() {
            self.slip[m] = omega[self.body[m + 1]] - omega[self.body[m]];
        }
    }

    /// The clamp forces at `t_s` into `out` (one per interface, N) for the teeth's normal
    /// loads `n |F|` of the stack's bodies, `normal(b)` of stack position `b` (N):
    /// `StackModel::clamp_forces_with`.
    pub fn clamp_at(&self, t_s: f64, normal: impl Fn(usize) -> f64, out: &mut [f64]) {
        self.model
            .clamp_forces_with(self.model.piston.force_n(t_s), normal, out);
    }

    /// The friction torque interface `m` clamped with `clamp_n` (N) passes at the slip
    /// `slip_rad_s` (rad/s), N m: `mu(|v|) F R_eff` (its magnitude; it opposes the slip).
    pub fn slip_torque_n_m(&self, m: usize, clamp_n: f64, slip_rad_s: f64) -> f64 {
        self.model.friction_of(m).mu(slip_rad_s * self.r_eff) * clamp_n * self.r_eff
    }

    /// The largest torque interface `m` holds locked, clamped with `clamp_n` (N), N m:
    /// `mu(0) F R_eff`.
    pub fn holding_torque_n_m(&self, m: usize, clamp_n: f64) -> f64 {
        self.model.friction_of(m).static_mu() * clamp_n * self.r_eff
    }

    /// The open gaps' damping `c`, N m s/rad (0 without oil in the gaps).
    pub fn gap_damping(&self) -> f64 {
        self.c_gap
    }

    /// Records a step of length `h` (s) taken outside [`Self::solve`] by the clamped stack's
    /// multirate integration: each interface's impulse on its upper body over it (N m s),
    /// whether it ended locked and its torque on its upper body at the end (N m; friction, the
    /// gap's drag, or the holding torque of a locked face); [`Self::dissipated_j`] is kept by
    /// the integration.
    pub fn record_step(&mut self, h: f64, impulse: &[f64], locked: &[bool], torque_now: &[f64]) {
        self.h = h;
        self.torque_now.clear();
        self.torque_now.extend_from_slice(torque_now);
        self.impulse.copy_from_slice(impulse);
        self.locked.copy_from_slice(locked);
        self.torque.iter_mut().for_each(|t| *t = 0.0);
        for m in 0..self.interfaces() {
            let t = impulse[m] / h;
            self.torque[m + 1] += t;
            self.torque[m] -= t;
        }
    }

    /// The largest torque the stack can put on coupling body `i` at the current clamp
    /// forces and slips, N m (a bound for the step controller).
    pub fn torque_bound(&self, i: usize) -> f64 {
        let mut bound = 0.0;
        for m in 0..self.interfaces() {
            if self.body[m] == i || self.body[m + 1] == i {
                bound += if self.clamp[m] > 0.0 {
                    let f = self.model.friction_of(m);
                    f.static_mu().max(f.mu(self.slip[m] * self.r_eff)) * self.clamp[m] * self.r_eff
                } else {
                    self.c_gap * self.slip[m].abs()
                };
            }
        }
        bound
    }

    /// Solves the impulses of a step of length `h` (s) for the mean speeds `w_pred` (rad/s)
    /// the coupling bodies would reach without the stack, with inverse inertias `inv_j`
    /// (1/(kg m^2)); fills [`Self::impulse`], [`Self::locked`] and [`Self::torque`].
    pub fn solve(&mut self, h: f64, w_pred: &[f64], inv_j: &[f64]) {
        let n_if = self.interfaces();
        // warm start: the last impulses, scaled to the step
        if self.h > 0.0 {
            let scale = h / self.h;
            for q in &mut self.impulse {
                *q *= scale;
            }
        }
        self.h = h;
        self.torque_now.clear();
        let mut w: Vec<f64> = self.body.iter().map(|&i| w_pred[i]).collect();
        let inv: Vec<f64> = self.body.iter().map(|&i| inv_j[i]).collect();
        let bound: Vec<f64> = (0..n_if)
            .map(|m| {
                if self.clamp[m] > 0.0 {
                    let mu = self.model.friction_of(m).mu(self.slip[m] * self.r_eff);
                    h * mu * self.clamp[m] * self.r_eff
                } else {
                    0.0
                }
            })
            .collect();
        let k_gap = self.c_gap * h;
        if let Some(q) = self.active_set(&w, &inv, &bound, k_gap) {
            self.impulse = q;
            self.finish(h, &bound);
            return;
        }
        for m in 0..n_if {
            let q = if self.clamp[m] > 0.0 {
                self.impulse[m].clamp(-bound[m], bound[m])
            } else if k_gap > 0.0 {
                self.impulse[m]
            } else {
                0.0
            };
            self.impulse[m] = q;
            w[m + 1] += q * inv[m + 1];
            w[m] -= q * inv[m];
        }
        let scale = w.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        let tol = (1e-12f64).max(1e-15 * scale);
        for _ in 0..MAX_SWEEPS {
            let mut worst = 0.0f64;
            for m in 0..n_if {
                let s = inv[m] + inv[m + 1];
                let v = w[m + 1] - w[m];
                let q = self.impulse[m];
                let new = if self.clamp[m] > 0.0 {
                    // the impulse that stops the slip, within the friction bound
                    (q - v / s).clamp(-bound[m], bound[m])
                } else if k_gap > 0.0 {
                    // Q' = -k (v + (Q' - Q) s)
                    -k_gap * (v - q * s) / (1.0 + k_gap * s)
                } else {
                    0.0
                };
                let d = new - q;
                if d != 0.0 {
                    w[m + 1] += d * inv[m + 1];
                    w[m] -= d * inv[m];
                    self.impulse[m] = new;
                    worst = worst.max((d * s).abs());
                }
            }
            if worst < tol {
                break;
            }
        }
        self.finish(h, &bound);
    }

    /// The torques and lock flags of the solved impulses.
    fn finish(&mut self, h: f64, bound: &[f64]) {
        let n_if = self.interfaces();
        self.torque.iter_mut().for_each(|t| *t = 0.0);
        for m in 0..n_if {
            self.locked[m] = self.clamp[m] > 0.0 && self.impulse[m].abs() < bound[m];
            let t = self.impulse[m] / h;
            self.torque[m + 1] += t;
            self.torque[m] -= t;
        }
    }

    /// The exact impulses for a guess of which interfaces stick and which slip (which way),
    /// improved until the guess is consistent: each guess makes the conditions linear
    /// (stick: no slip at the end of the step; slip: the bound, opposing the slip; open: the
    /// implicit damper), a tridiagonal system along the stack solved directly; a sticking
    /// interface that needs more than its bound slips, a slipping one whose friction would
    /// drive the slip sticks. The guess starts from the last step, so in steady slip or lock
    /// one solve does. `None` if the guesses cycle (then Gauss-Seidel sweeps decide).
    fn active_set(&self, wp: &[f64], inv: &[f64], bound: &[f64], k_gap: f64) -> Option<Vec<f64>> {
        #[derive(Clone, Copy, PartialEq)]
        enum State {
            Stick,
            Slip(f64),
            Open,
        }
        let n = bound.len();
        let vp: Vec<f64> = (0..n).map(|m| wp[m + 1] - wp[m]).collect();
        let mut state: Vec<State> = (0..n)
            .map(|m| {
                if self.clamp[m] <= 0.0 {
                    State::Open
                } else if self.locked[m] {
                    State::Stick
                } else if self.impulse[m] != 0.0 {
                    State::Slip(self.impulse[m].signum())
                } else {
                    State::Slip(-vp[m].signum())
                }
            })
            .collect();
        let (mut a, mut b, mut c, mut d) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut q = vec![0.0; n];
        let scale = wp.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let tol = (1e-12f64).max(1e-15 * scale);
        for _ in 0..2 * n + 4 {
            for m in 0..n {
                let s = inv[m] + inv[m + 1];
                (a[m], b[m], c[m], d[m]) = match state[m] {
                    State::Stick => (-inv[m], s, -inv[m + 1], -vp[m]),
                    State::Slip(sigma) => (0.0, 1.0, 0.0, sigma * bound[m]),
                    State::Open if k_gap > 0.0 => (
                        -k_gap * inv[m],
                        1.0 + k_gap * s,
                        -k_gap * inv[m + 1],
                        -k_gap * vp[m],
                    ),
                    State::Open => (0.0, 1.0, 0.0, 0.0),
                };
            }
            // Thomas algorithm (the matrix is diagonally dominant)
            for m in 1..n {
                let w = a[m] / b[m - 1];
                b[m] -= w * c[m - 1];
                d[m] -= w * d[m - 1];
            }
            q[n - 1] = d[n - 1] / b[n - 1];
            for m in (0..n - 1).rev() {
                q[m] = (d[m] - c[m] * q[m + 1]) / b[m];
            }
            if !q.iter().all(|x| x.is_finite()) {
                return None;
            }
            let mut changed = false;
            for m in 0..n {
                match state[m] {
                    State::Stick if q[m].abs() > bound[m] => {
                        state[m] = State::Slip(q[m].signum());
                        changed = true;
                    }
                    State::Slip(sigma) => {
                        let below = if m > 0 { q[m - 1] } else { 0.0 };
                        let above = if m + 1 < n { q[m + 1] } else { 0.0 };
                        let v = vp[m] + (inv[m] + inv[m + 1]) * q[m]
                            - inv[m + 1] * above
                            - inv[m] * below;
                        if sigma * v > tol {
                            state[m] = State::Stick;
                            changed = true;
                        }
                    }
                    _ => {}
                }
            }
            if !changed {
                return Some(q);
            }
        }
        None
    }

    /// Records a step of length `h` (s) of an open stack taken outside [`Self::solve`] (the
    /// multirate scheme integrates the gaps' drag with each body's sub-steps and fills
    /// [`Self::impulse`] and [`Self::dissipated_j`]): nothing is locked.
    pub fn record_open_step(&mut self, h: f64) {
        self.h = h;
        self.torque_now.clear();
        self.locked.iter_mut().for_each(|l| *l = false);
    }

    /// The torque of the stack on coupling body `i` over the step being taken, N m.
    pub fn torque_on(&self, i: usize) -> f64 {
        self.body
            .iter()
            .position(|&b| b == i)
            .map_or(0.0, |b| self.torque[b])
    }

    /// What each interface does now (its torque is the one of the last step taken, or the
    /// one at its end where the clamped stack's integration recorded it).
    pub fn samples(&self) -> Vec<InterfaceSample> {
        let mut out = Vec::new();
        self.samples_into(&mut out);
        out
    }

    /// [`Stack::samples`] into `out` (its contents replaced).
    pub fn samples_into(&self, out: &mut Vec<InterfaceSample>) {
        out.clear();
        out.extend((0..self.interfaces()).map(|m| {
            let clamped = self.clamp[m] > 0.0;
            InterfaceSample {
                slip_rad_s: self.slip[m],
                slip_m_s: self.slip[m] * self.r_eff,
                mu: if clamped {
                    self.model.friction_of(m).mu(self.slip[m] * self.r_eff)
                } else {
                    0.0
                },
                clamp_n: self.clamp[m],
                torque_n_m: if !self.torque_now.is_empty() {
                    self.torque_now[m]
                } else if self.h > 0.0 {
                    self.impulse[m] / self.h
                } else {
                    0.0
                },
                locked: self.locked[m],
                dissipated_j: self.dissipated_j[m],
            }
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::{FrictionCurve, OpenGap, Piston, PressureProfile};

    fn model(pressure_pa: f64, gap: Option<OpenGap>) -> StackModel {
        StackModel {
            face_friction: Vec::new(),
            face_inner_radius_m: 0.2,
            face_outer_radius_m: 0.25,
            friction: FrictionCurve::constant(0.1),
            piston: Piston {
                area_m2: 0.01,
                pressure: PressureProfile::Constant { pressure_pa },
                return_spring_n: 0.0,
            },
            open_gap: gap,
            spline_friction: 0.0,
        }
    }

    /// One disc between two plates, the disc 10 rad/s faster: a weak clamp lets it slip with
    /// `mu F R_eff` on each face (opposing the slip), a strong one locks all three to the
    /// momentum-weighted mean speed in one step (Moreau: exactly, no creep).
    #[test]
    fn slip_with_the_bound_or_lock_exactly() {
        let m = model(1e4, None); // 100 N
        let mut s = Stack::new(&m, 1);
        s.update(0.0, &[0.0; 3], &[10.0, 0.0, 0.0]);
        let (h, inv) = (1e-4, [1.0 / 0.2, 1.0 / 0.1, 1.0 / 0.1]);
        s.solve(h, &[10.0, 0.0, 0.0], &inv);
        let t = 0.1 * 100.0 * m.effective_radius_m();
        // coupling 0 (the disc, stack body 1) is braked by both faces
        assert!((s.torque_on(0) + 2.0 * t).abs() < 1e-12 * t);
        assert!((s.torque_on(1) - t).abs() < 1e-12 * t && (s.torque_on(2) - t).abs() < 1e-12 * t);
        assert!(!s.locked[0] && !s.locked[1]);

        let strong = model(1e9, None);
        let mut s = Stack::new(&strong, 1);
        s.update(0.0, &[0.0; 3], &[10.0, 0.0, 0.0]);
        s.solve(h, &[10.0, 0.0, 0.0], &inv);
        let w: Vec<f64> = (0..3)
            .map(|i| [10.0, 0.0, 0.0][i] + s.torque_on(i) * h * inv[i])
            .collect();
        let mean = 10.0 * 0.2 / 0.4;
        for x in w {
            assert!((x - mean).abs() < 1e-12, "{x} vs {mean}");
        }
        assert!(s.locked[0] && s.locked[1]);
    }

    /// An open gap is a damper taken implicitly: even with an absurd viscosity the slip decays
    /// without reversing (the backward-Euler factor `1 / (1 + c h S)`), and for a small one the
    /// torque is the Couette law `-c v`.
    #[test]
    fn open_gap_is_an_implicit_damper() {
        let gap = OpenGap {
            viscosity_pa_s: 289.1,
            gap_m: 1e-5,
        };
        let m = model(0.0, Some(gap));
        let mut s = Stack::new(&m, 1);
        s.update(0.0, &[0.0; 3], &[10.0, 0.0, 0.0]);
        let inv = [1.0 / 0.2, 1.0 / 0.1, 1.0 / 0.1];
        s.solve(1e-4, &[10.0, 0.0, 0.0], &inv);
        let w0 = 10.0 + s.torque_on(0) * 1e-4 * inv[0];
        let w1 = s.torque_on(1) * 1e-4 * inv[1];
        assert!(w0 > w1 && w0 < 10.0, "{w0} {w1}");

        let thin = model(
            0.0,
            Some(OpenGap {
                viscosity_pa_s: 0.01,
                gap_m: 1e-4,
            }),
        );
        let mut s = Stack::new(&thin, 1);
        s.update(0.0, &[0.0; 3], &[10.0, 0.0, 0.0]);
        s.solve(1e-6, &[10.0, 0.0, 0.0], &inv);
        // on the lower plate (body 0, coupling 1): +c v from the faster disc
        let expected = -thin.open_gap_torque_n_m(10.0);
        assert!(
            ((s.torque_on(1) - expected) / expected).abs() < 1e-4,
            "{} vs {expected}",
            s.torque_on(1)
        );
    }
}
