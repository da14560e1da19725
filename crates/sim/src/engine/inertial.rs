//! The multirate scheme on an inertial shaft (eq 4; crate docs, "Multirate on an inertial
//! shaft"): each world step the shaft and the discs that may touch it are integrated together
//! with classical Runge-Kutta sub-steps, the other discs fly free against the shaft's motion
//! (`multirate.rs`'s per-coupling integration).

use super::multirate::Counts;
use super::state::{Run, ShaftDrive};
use super::substep::{
    checked_sub_step, graded_step, split_remainder, GapDrag, Node, Path, ShaftAt,
};
use crate::hook::FLANKS;
use crate::options::AdaptiveStepping;
use crate::stepping::{bracketed_root, coupling_step};
use clutchpack_model::{DiscSample, EngineError, ImpactEvent};
use rapier3d_f64::prelude::Vector;

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
        // the drive at the step's start, middle (stages 2 and 3) and end
        let drives = [
            self.drive_torque(t),
            self.drive_torque(t + 0.5 * h),
            self.drive_torque(t + h),
        ];
        let stage = |drive: f64, s: f64, w: f64, th: &[f64], u: &[f64], acc: &mut [f64]| {
            let mut teeth = 0.0;
            for k in 0..n {
                let i = cluster[k];
                let torque = self.couplings[i].probe_torque(phi[k] + s - th[k], w - u[k]);
                teeth += torque;
                acc[k] = (torque - self.bodies[i].drag_n_m_s_rad * u[k]) * inv_j[k];
            }
            ((drive - c1 * w - teeth) * inv_j1, drive)
        };
        let (mut k1, mut k2, mut k3, mut k4) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let zero = vec![0.0; n];
        let (a1, d1) = stage(drives[0], 0.0, w0, &zero, &u0, &mut k1);
        let w2 = w0 + 0.5 * h * a1;
        let th2: Vec<f64> = u0.iter().map(|u| 0.5 * h * u).collect();
        let u2: Vec<f64> = (0..n).map(|k| u0[k] + 0.5 * h * k1[k]).collect();
        let (a2, d2) = stage(drives[1], 0.5 * h * w0, w2, &th2, &u2, &mut k2);
        let w3 = w0 + 0.5 * h * a2;
        let th3: Vec<f64> = (0..n)
            .map(|k| 0.5 * h * u0[k] + 0.25 * hh * k1[k])
            .collect();
        let u3: Vec<f64> = (0..n).map(|k| u0[k] + 0.5 * h * k2[k]).collect();
        let (a3, d3) = stage(
            drives[1],
            0.5 * h * w0 + 0.25 * hh * a1,
            w3,
            &th3,
            &u3,
            &mut k3,
        );
        let w4 = w0 + h * a3;
        let th4: Vec<f64> = (0..n).map(|k| h * u0[k] + 0.5 * hh * k2[k]).collect();
        let u4: Vec<f64> = (0..n).map(|k| u0[k] + h * k3[k]).collect();
        let (a4, d4) = stage(drives[2], h * w0 + 0.5 * hh * a2, w4, &th4, &u4, &mut k4);
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
                let bound = a_shaft + d.drag_n_m_s_rad * wd.abs() * inv_j[k];
                let view = self.coupling_view(i, &f, (phi[k], dphi[k]), bound, t);
                let (wk, _) = coupling_step(&view, a);
                want = want.min(graded_step(wk, &f, self.events.event_age_s(i, t)));
            }
            let want = checked_sub_step(want, a, t, || "inertial shaft".into())?;
            let rem = t1 - t;
            let mut h = split_remainder(want, rem);
            let rk4 = |x: f64| self.shaft_rk4(cluster, &inv_j, inv_j1, c1, t, w, &phi, &dphi, x);
            let mut step = rk4(h);
            // Never step over an onset or a separation of any coupling: land on the first.
            let tiny = 1e-3 * h.min(want);
            let mut first: Option<f64> = None;
            for (k, &i) in cluster.iter().enumerate() {
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
                    let depth = |p: f64| (sigma * p - g0) * rb + offset;
                    let (d0, d1) = (depth(phi[k]), depth(step.phi[k]));
                    let crosses = crate::stepping::crosses_contact(engaged, d0, d1);
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
    pub(super) fn multirate_step_inertial(
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
            let bound = a_shaft + d.drag_n_m_s_rad * wd.abs() * inv_j;
            let rel = self.rel[i];
            let view = self.coupling_view(i, &f, (rel.phi, rel.dphi), bound, t0);
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
        self.drive_to_means(&means, h);
        let bodies = &mut self.world.physics.bodies;
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
