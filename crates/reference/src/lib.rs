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
//! It is the oracle for the multibody engine and the fast engine for sweeps.
//!
//! # Theory
//! State: for an inertial shaft `(theta_s, omega_s)`, then per disc `i` the relative angle
//! `phi_i = theta_s - theta_di` and relative speed `psi_i = omega_s - omega_di`. Integrating
//! the relative quantities keeps the error control on the backlash scale (nanometres at the
//! pitch circle) instead of on the growing absolute angles.
//!
//! - Prescribed shaft (eq 3): `omega_s(t)`, `theta_s(t)` and `omega_s'(t)` from the profile.
//! - Inertial shaft (eq 4): `J1 omega_s' = T_drive(t) + sum_i n_i F_i Rb_i - C1 omega_s`.
//! - Disc (eq 5): `J2 omega_d' = -n F Rb - C2 omega_d`; so `phi' = psi`,
//!   `psi' = omega_s' - omega_d'`.
//! - `F` is the signed per-tooth load of the coupling's law (MODEL.md sections 1-2); it is
//!   only evaluated inside a contact event, which starts when the engagement depth `s`
//!   crosses zero upwards and ends when it falls back to zero. Both crossings are located on
//!   the dense output by bisection to 1e-13 s; the integration restarts there.
//! - The peak of each event is located by a golden-section search on the dense output around
//!   the step where the load stops rising.
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

pub mod dopri;

use clutchpack_model::{
    DiscModel, Engagement, Engine, EngineError, Flank, ImpactTracker, Observer, PackModel,
    RunStats, Sample, Shaft, ToothKinematics,
};
use clutchpack_scene::Scene;
use dopri::{next_step, Dense, Dopri5};

/// Integration and output settings of the reference engine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Relative error tolerance (dimensionless). Absolute tolerances derive from it: `tol *
    /// g0` rad for relative angles, `tol * 1 rad/s` for speeds, `tol * 1 rad` for the shaft angle.
    pub tolerance: f64,
    /// Largest step in s.
    pub max_step_s: f64,
    /// Sample rate of the output in Hz (samples at `k / rate`, k = 0, 1, ...).
    pub record_rate_hz: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            tolerance: 1e-9,
            max_step_s: 1e-4,
            record_rate_hz: 10_000.0,
        }
    }
}

/// The reduced torsional engine for a [`PackModel`].
#[derive(Debug, Clone)]
pub struct ReferenceEngine {
    pack: PackModel,
    settings: Settings,
}

impl ReferenceEngine {
    /// An engine for `pack` with `settings`.
    pub fn new(pack: PackModel, settings: Settings) -> ReferenceEngine {
        ReferenceEngine { pack, settings }
    }

    /// An engine for a validated scene, with the scene's solver settings.
    pub fn from_scene(scene: &Scene) -> ReferenceEngine {
        let s = &scene.simulation;
        ReferenceEngine::new(
            scene.pack.clone(),
            Settings {
                tolerance: s.tolerance,
                max_step_s: s.max_step_s,
                record_rate_hz: s.record_rate_hz,
            },
        )
    }

    /// The model this engine runs.
    pub fn pack(&self) -> &PackModel {
        &self.pack
    }
}

/// Per-disc constants and the equations of motion.
struct System<'a> {
    pack: &'a PackModel,
    /// Index of the first disc state: 0 for a prescribed shaft, 2 for an inertial one.
    off: usize,
}

impl System<'_> {
    fn dim(&self) -> usize {
        self.off + 2 * self.pack.discs.len()
    }

    /// Shaft angle (rad) and speed (rad/s) at `t` for state `y`.
    fn shaft(&self, t: f64, y: &[f64]) -> (f64, f64) {
        match &self.pack.shaft {
            Shaft::Prescribed(p) => (p.angle(t), p.speed(t)),
            Shaft::Inertial { .. } => (y[0], y[1]),
        }
    }

    fn kin(&self, i: usize, y: &[f64]) -> ToothKinematics {
        let d = &self.pack.discs[i];
        d.spline
            .kinematics(y[self.off + 2 * i], y[self.off + 2 * i + 1])
    }

    /// Signed per-tooth load of disc `i` in N for its mode.
    fn load(&self, i: usize, y: &[f64], mode: &Option<Engagement>) -> f64 {
        match mode {
            Some(e) => self.pack.discs[i].law.load_n(&self.kin(i, y), e),
            None => 0.0,
        }
    }

    /// Engagement depth of disc `i` in m (positive inside a contact event).
    fn depth(&self, i: usize, y: &[f64]) -> f64 {
        let d = &self.pack.discs[i];
        d.law.engagement_depth_m(&self.kin(i, y))
    }

    fn rhs(&self, t: f64, y: &[f64], modes: &[Option<Engagement>], dy: &mut [f64]) {
        let mut shaft_torque = 0.0;
        let (omega_s, alpha_prescribed) = match &self.pack.shaft {
            Shaft::Prescribed(p) => (p.speed(t), p.acceleration(t)),
            Shaft::Inertial { .. } => (y[1], 0.0),
        };
        // Per-disc loads first: an inertial shaft needs their sum.
        let mut alpha_s = alpha_prescribed;
        if let Shaft::Inertial {
            inertia_kg_m2,
            damping_n_m_s_rad,
            ..
        } = &self.pack.shaft
        {
            for (i, d) in self.pack.discs.iter().enumerate() {
                let f = self.load(i, y, &modes[i]);
                // Hu et al. eq (4): the spline reaction n F Rb acts back on the shaft
                shaft_torque += d.spline.teeth as f64 * f * d.spline.base_radius_m();
            }
            alpha_s = (self.pack.shaft.drive_torque_n_m(t) + shaft_torque
                - damping_n_m_s_rad * omega_s)
                / inertia_kg_m2;
            dy[0] = omega_s;
            dy[1] = alpha_s;
        }
        for (i, d) in self.pack.discs.iter().enumerate() {
            let k = self.off + 2 * i;
            let f = self.load(i, y, &modes[i]);
            let omega_d = omega_s - y[k + 1];
            // Hu et al. eq (5)
            let alpha_d =
                (d.spline.disc_torque_n_m(f) - d.drag_n_m_s_rad * omega_d) / d.inertia_kg_m2;
            dy[k] = y[k + 1];
            dy[k + 1] = alpha_s - alpha_d;
        }
    }

    fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        if self.off == 2 {
            y[0] = 0.0;
            y[1] = self.pack.shaft.initial_speed_rad_s();
        }
        for (i, d) in self.pack.discs.iter().enumerate() {
            y[self.off + 2 * i] = d.initial_rel_angle_rad;
            y[self.off + 2 * i + 1] = d.initial_rel_speed_rad_s;
        }
        y
    }

    fn sample(&self, t: f64, y: &[f64], modes: &[Option<Engagement>]) -> Sample {
        let (theta_s, omega_s) = self.shaft(t, y);
        let discs = self
            .pack
            .discs
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let k = self.off + 2 * i;
                let kin = self.kin(i, y);
                let f = self.load(i, y, &modes[i]);
                clutchpack_model::DiscSample {
                    angle_rad: theta_s - y[k],
                    speed_rad_s: omega_s - y[k + 1],
                    rel_angle_rad: y[k],
                    penetration_m: kin.delta_m,
                    closing_speed_m_s: kin.v_n_m_s,
                    load_n: f,
                    torque_n_m: d.spline.disc_torque_n_m(f),
                    engaged: modes[i].is_some(),
                    stiffness: modes[i].map(|e| e.stiffness).unwrap_or(0.0),
                    tooth_loads_n: Vec::new(),
                }
            })
            .collect();
        Sample {
            t_s: t,
            shaft_angle_rad: theta_s,
            shaft_speed_rad_s: omega_s,
            discs,
        }
    }
}

/// Evaluates the dense output of the last two steps at `t`.
fn eval2(prev: &Dense, cur: &Dense, t: f64, out: &mut [f64]) {
    if t < cur.t0 && prev.h > 0.0 {
        prev.eval(t, out)
    } else {
        cur.eval(t, out)
    }
}

/// Per-disc bookkeeping of contact events.
struct DiscTrack {
    tracker: ImpactTracker,
    /// |load| at the end of the last accepted step, N.
    last_abs: f64,
    /// Whether the load was still rising at the end of the last accepted step.
    rising: bool,
    /// Onset of the current event, s.
    t_on: f64,
}

fn check_disc(d: &DiscModel) -> Result<(), EngineError> {
    let ok = d.inertia_kg_m2 > 0.0 && d.spline.teeth > 0 && d.spline.backlash_m > 0.0;
    if !ok {
        return Err(EngineError::Unsupported(format!(
            "disc {}: inertia, teeth and backlash must be positive",
            d.name
        )));
    }
    // One rotational DOF with the lumped law is exact only for a concentric disc with
    // identical teeth (MODEL.md section 5).
    if !d.is_concentric() {
        return Err(EngineError::Unsupported(format!(
            "disc {}: radial float, an initial offset or tooth spacing errors need the per-tooth \
             multibody engine (the reference engine has one rotational degree of freedom per \
             body and identical teeth)",
            d.name
        )));
    }
    Ok(())
}

impl Engine for ReferenceEngine {
    fn name(&self) -> &'static str {
        "reference"
    }

    fn disc_names(&self) -> Vec<String> {
        self.pack.discs.iter().map(|d| d.name.clone()).collect()
    }

    fn run(&mut self, duration_s: f64, obs: &mut dyn Observer) -> Result<RunStats, EngineError> {
        for d in &self.pack.discs {
            check_disc(d)?;
        }
        if !self.pack.plates.is_empty() || self.pack.drum.is_some() || self.pack.stack.is_some() {
            return Err(EngineError::Unsupported(
                "separator plates, an output drum and the clamped stack need the multibody \
                 engine (the reference engine models friction discs on one shaft)"
                    .into(),
            ));
        }
        let sys = System {
            pack: &self.pack,
            off: if matches!(self.pack.shaft, Shaft::Inertial { .. }) {
                2
            } else {
                0
            },
        };
        let nd = self.pack.discs.len();
        let n = sys.dim();
        let tol = self.settings.tolerance;
        let mut atol = vec![tol; n];
        for (i, d) in self.pack.discs.iter().enumerate() {
            atol[sys.off + 2 * i] = tol * d.spline.half_play_rad();
        }
        let mut stats = RunStats::default();
        let mut modes: Vec<Option<Engagement>> = vec![None; nd];
        let mut tracks: Vec<DiscTrack> = (0..nd)
            .map(|i| DiscTrack {
                tracker: ImpactTracker::new(i),
                last_abs: 0.0,
                rising: false,
                t_on: 0.0,
            })
            .collect();

        let mut y = sys.initial_state();
        // A disc may start inside a contact event (engaged at t = 0).
        for i in 0..nd {
            if sys.depth(i, &y) > 0.0 {
                let kin = sys.kin(i, &y);
                modes[i] = Some(self.pack.discs[i].law.engage(&kin));
                tracks[i].tracker.begin(0.0, kin.flank, kin.v_n_m_s);
                tracks[i].rising = true;
            }
        }
        let mut solver = Dopri5::new(n);
        let mut dy = vec![0.0; n];
        let mut t = 0.0;
        sys.rhs(t, &y, &modes, &mut dy);
        stats.rhs_evals += 1;
        solver.set_start_derivative(&dy);
        let mut h: f64 = self.settings.max_step_s.min(1e-6);
        let mut prev = Dense::default();
        let mut cur = Dense::default();
        let mut buf = vec![0.0; n];
        let mut y_new = vec![0.0; n];
        let rate = self.settings.record_rate_hz;
        let mut next_sample: u64 = 0;
        let sample_time = |k: u64| k as f64 / rate;

        while t < duration_s {
            h = h.min(self.settings.max_step_s).min(duration_s - t);
            if h < 1e-15 * t.max(1.0) && duration_s - t > 1e-15 * t.max(1.0) {
                return Err(EngineError::Diverged {
                    t_s: t,
                    reason: format!("the step size collapsed to {h:e} s"),
                });
            }
            let modes_ref = &modes;
            let mut f = |tt: f64, yy: &[f64], out: &mut [f64]| sys.rhs(tt, yy, modes_ref, out);
            let err = solver.try_step(&mut f, t, &y, h, &atol, tol);
            stats.rhs_evals += 6;
            if !err.is_finite() || solver.y_new.iter().any(|v| !v.is_finite()) {
                if h > 1e-14 {
                    h *= 0.1;
                    stats.rejected_steps += 1;
                    continue;
                }
                return Err(EngineError::Diverged {
                    t_s: t,
                    reason: "the state became non-finite".into(),
                });
            }
            if err > 1.0 {
                stats.rejected_steps += 1;
                h = next_step(h, err);
                continue;
            }
            // Accepted: build the dense output of [t, t + h].
            std::mem::swap(&mut prev, &mut cur);
            solver.dense_into(t, &y, h, &mut cur);
            let t_end = t + h;

            // Earliest mode switch inside the step (probes at quarter points catch grazing
            // contacts that enter and leave within a step).
            let mut event: Option<(f64, usize)> = None;
            for i in 0..nd {
                let triggered = |yy: &[f64]| {
                    let g = sys.depth(i, yy);
                    if modes[i].is_some() {
                        g <= 0.0
                    } else {
                        g > 0.0
                    }
                };
                let mut ta = t;
                let mut found = None;
                for q in 1..=4 {
                    let tq = if q == 4 {
                        t_end
                    } else {
                        t + h * q as f64 / 4.0
                    };
                    if q == 4 {
                        buf.copy_from_slice(&solver.y_new);
                    } else {
                        cur.eval(tq, &mut buf);
                    }
                    if triggered(&buf) {
                        found = Some((ta, tq));
                        break;
                    }
                    ta = tq;
                }
                if let Some((mut a, mut b)) = found {
                    // Bisection: `a` not triggered, `b` triggered.
                    while b - a > 1e-13 {
                        let m = 0.5 * (a + b);
                        cur.eval(m, &mut buf);
                        if triggered(&buf) {
                            b = m;
                        } else {
                            a = m;
                        }
                    }
                    if event.is_none_or(|(te, _)| b < te) {
                        event = Some((b, i));
                    }
                }
            }
            let t_new = event.map(|(te, _)| te).unwrap_or(t_end);
            if event.is_some() {
                cur.eval(t_new, &mut y_new);
            } else {
                y_new.copy_from_slice(&solver.y_new);
            }

            // Peaks of the open contact events.
            for i in 0..nd {
                if modes[i].is_none() {
                    continue;
                }
                let f_new = sys.load(i, &y_new, &modes[i]);
                let tr = &mut tracks[i];
                if f_new.abs() < tr.last_abs && tr.rising {
                    // The peak lies in the last two steps: golden-section search.
                    let lo = if prev.h > 0.0 {
                        prev.t0.max(tr.t_on)
                    } else {
                        cur.t0
                    };
                    let (tp, fp) = golden_peak(lo, t_new, |tt| {
                        eval2(&prev, &cur, tt, &mut buf);
                        sys.load(i, &buf, &modes[i])
                    });
                    tr.tracker.observe(tp, fp);
                    tr.rising = false;
                } else if f_new.abs() >= tr.last_abs {
                    tr.rising = true;
                }
                tr.tracker.observe(t_new, f_new);
                tr.last_abs = f_new.abs();
            }

            // Samples on the output grid inside (t, t_new].
            while sample_time(next_sample) <= t_new {
                let ts = sample_time(next_sample);
                if ts < t {
                    // only the very first sample (t = 0) can fall here
                    obs.sample(&sys.sample(ts, &y, &modes));
                } else {
                    cur.eval(ts, &mut buf);
                    obs.sample(&sys.sample(ts, &buf, &modes));
                }
                next_sample += 1;
            }

            stats.steps += 1;
            t = t_new;
            y.copy_from_slice(&y_new);
            if let Some((te, i)) = event {
                let kin = sys.kin(i, &y);
                if modes[i].is_some() {
                    modes[i] = None;
                    if let Some(e) = tracks[i].tracker.end(te) {
                        obs.impact(&e);
                    }
                } else {
                    let e = self.pack.discs[i].law.engage(&kin);
                    modes[i] = Some(e);
                    let tr = &mut tracks[i];
                    tr.tracker.begin(te, flank_of(&kin), kin.v_n_m_s);
                    tr.t_on = te;
                    tr.last_abs = 0.0;
                    tr.rising = true;
                }
                sys.rhs(t, &y, &modes, &mut dy);
                stats.rhs_evals += 1;
                solver.set_start_derivative(&dy);
            } else {
                solver.accept();
            }
            h = next_step(h, err);
            if stats.steps % 1024 == 0 && obs.progress(t) {
                stats.stopped_early = true;
                break;
            }
        }
        for tr in tracks.iter_mut() {
            if let Some(e) = tr.tracker.finish(t) {
                obs.impact(&e);
            }
        }
        stats.simulated_s = t;
        Ok(stats)
    }
}

fn flank_of(kin: &ToothKinematics) -> Flank {
    kin.flank
}

/// Maximises `|f|` on `[a, b]` by golden-section search (f unimodal in |f|); returns the
/// argument and the signed value. 60 iterations shrink the bracket by 0.618^60 ~ 3e-13.
fn golden_peak(mut a: f64, mut b: f64, mut f: impl FnMut(f64) -> f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_9;
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let mut fc = f(c);
    let mut fd = f(d);
    for _ in 0..60 {
        if fc.abs() > fd.abs() {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = f(d);
        }
        if b - a < 1e-13 {
            break;
        }
    }
    if fc.abs() > fd.abs() {
        (c, fc)
    } else {
        (d, fd)
    }
}
