//! The open stack's oil gaps as an input of one body (the open-pack multirate scheme,
//! `open.rs`, crate docs "Whole packs"): the Couette drag of the gaps below and above a body,
//! from its neighbours' speeds over the current window, predicted from the window's start
//! (speed and acceleration there) or taken from the dense output of the neighbour's last pass
//! through the window.

use crate::dopri::{eval_component, Dense};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// One accepted step of a body's relative speed `psi` (rad/s): the step `[t0, t0 + h]` of the
/// dense output (s), the time the step ended at (s; before `t0 + h` when an event cut it) and
/// the interpolant's coefficients.
#[derive(Debug, Clone, Copy)]
struct Segment {
    t0: f64,
    h: f64,
    t_end: f64,
    c: [f64; 5],
}

/// A body's relative speed `psi = omega_carrier - omega_body` (rad/s) through one window: the
/// dense output of its accepted steps, in order.
#[derive(Debug, Default)]
pub(crate) struct Track {
    segments: Vec<Segment>,
}

clone_reusing!(Track { segments });

impl Track {
    /// Forgets the last window.
    pub fn clear(&mut self) {
        self.segments.clear();
    }

    /// Number of steps in the window.
    pub fn len(&self) -> usize {
        self.segments.len()
    }

    /// Appends the step just accepted: the dense output `d` of state component `i` (the
    /// body's `psi`), the step having ended at `t_end` (s).
    pub fn push(&mut self, d: &Dense, i: usize, t_end: f64) {
        let (t0, h, c) = d.component(i);
        self.segments.push(Segment { t0, h, t_end, c });
    }

    /// `psi` at `t` (s), rad/s: the step that ends at or after `t` (the last one past the
    /// end). `hint` is where the last lookup found its step (the integrator asks for times
    /// close together): checked first, then its successor, then a binary search.
    fn psi(&self, t: f64, hint: &AtomicUsize) -> f64 {
        let n = self.segments.len();
        let covers = |j: usize| {
            j < n && self.segments[j].t_end >= t && (j == 0 || self.segments[j - 1].t_end < t)
        };
        let h = hint.load(Ordering::Relaxed);
        let j = if covers(h) {
            h
        } else if covers(h + 1) {
            h + 1
        } else {
            self.segments.partition_point(|s| s.t_end < t).min(n - 1)
        };
        hint.store(j, Ordering::Relaxed);
        let s = &self.segments[j];
        eval_component(s.t0, s.h, &s.c, t)
    }

    /// `integral |f(t)| dt` over the window (f in rad/s; rad) by Simpson's rule on every step.
    fn integral_abs(&self, f: impl Fn(f64) -> f64) -> f64 {
        let Some(first) = self.segments.first() else {
            return 0.0;
        };
        let (mut a, mut fa) = (first.t0, f(first.t0).abs());
        let mut sum = 0.0;
        for s in &self.segments {
            let fm = f(0.5 * (a + s.t_end)).abs();
            let fb = f(s.t_end).abs();
            sum += (s.t_end - a) / 6.0 * (fa + 4.0 * fm + fb);
            (a, fa) = (s.t_end, fb);
        }
        sum
    }
}

/// A neighbour's speed over a window, as a body's gap sees it.
#[derive(Debug)]
pub(crate) enum Neighbour {
    /// The first pass's prediction: its speed `omega` (rad/s) at the window's start `t0` (s)
    /// moving on with the acceleration `alpha` (rad/s^2) it had there.
    Predicted { t0: f64, omega: f64, alpha: f64 },
    /// Its last pass through the window; `on_shaft` when its carrier is the shaft (a friction
    /// disc), else the housing (a plate, carrier at rest).
    /// `hint`: where the last lookup in `psi` found its step.
    Track {
        psi: Arc<Track>,
        on_shaft: bool,
        hint: AtomicUsize,
    },
}

impl Clone for Neighbour {
    fn clone(&self) -> Self {
        match self {
            Neighbour::Predicted { t0, omega, alpha } => Neighbour::Predicted {
                t0: *t0,
                omega: *omega,
                alpha: *alpha,
            },
            Neighbour::Track { psi, on_shaft, .. } => Neighbour::track(psi.clone(), *on_shaft),
        }
    }
}

impl Neighbour {
    /// The neighbour of the track `psi` (its relative speed), carried by the shaft when
    /// `on_shaft`, else by the housing.
    pub fn track(psi: Arc<Track>, on_shaft: bool) -> Neighbour {
        Neighbour::Track {
            psi,
            on_shaft,
            hint: AtomicUsize::new(0),
        }
    }

    /// Its speed at `t` (s), rad/s, the shaft turning at `omega_shaft()` (rad/s; asked only
    /// for a neighbour on the shaft).
    pub fn omega(&self, t: f64, omega_shaft: impl Fn() -> f64) -> f64 {
        match self {
            Neighbour::Predicted { t0, omega, alpha } => omega + alpha * (t - t0),
            Neighbour::Track {
                psi,
                on_shaft,
                hint,
            } => (if *on_shaft { omega_shaft() } else { 0.0 }) - psi.psi(t, hint),
        }
    }

    /// `integral |omega - omega_new| dt` (rad) over the window between this speed and the
    /// neighbour's new pass `new` (its `psi`), by Simpson's rule on the new pass's steps. Both
    /// have the same carrier, so the shaft's speed cancels.
    pub fn change(&self, new: &Track) -> f64 {
        let hint = AtomicUsize::new(0);
        match self {
            Neighbour::Predicted { .. } => {
                // a prediction is only made of a plate (on the housing: omega = -psi)
                new.integral_abs(|t| self.omega(t, || 0.0) + new.psi(t, &hint))
            }
            Neighbour::Track { psi, hint: h, .. } => {
                new.integral_abs(|t| psi.psi(t, h) - new.psi(t, &hint))
            }
        }
    }
}

/// The gaps on both sides of one body: the Couette coefficient and its neighbours below
/// (towards the piston) and above, `None` at an end of the stack.
#[derive(Debug, Clone)]
pub(crate) struct Gaps {
    /// `c = pi eta (Ro^4 - Ri^4) / (2 h)` of one gap, N m s/rad (MODEL.md section 5).
    pub c: f64,
    pub below: Option<Neighbour>,
    pub above: Option<Neighbour>,
}

impl Gaps {
    /// The drag of the gap below and of the gap above on the body turning at `omega_b`
    /// (rad/s) at `t` (s), N m each: `-c (omega_b - omega_neighbour)` (MODEL.md section 5).
    pub fn torques_n_m(&self, t: f64, omega_b: f64, omega_shaft: impl Fn() -> f64) -> [f64; 2] {
        let drag = |n: &Option<Neighbour>| {
            n.as_ref()
                .map_or(0.0, |n| -self.c * (omega_b - n.omega(t, &omega_shaft)))
        };
        [drag(&self.below), drag(&self.above)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dopri::Dopri5;

    /// A track built from DOPRI5 steps of `psi' = cos t` returns `sin t` between and at its
    /// steps' ends, and a held neighbour's change against it is the largest difference.
    #[test]
    fn track_interpolates_its_steps() {
        let mut solver = Dopri5::new(1);
        let f = |t: f64, _y: &[f64], dy: &mut [f64]| dy[0] = t.cos();
        let (mut t, mut y) = (0.0, vec![0.0]);
        let mut dy = vec![1.0];
        f(0.0, &y, &mut dy);
        solver.set_start_derivative(&dy);
        let mut track = Track::default();
        let mut d = Dense::default();
        for _ in 0..10 {
            let h = 0.1;
            let mut ff = f;
            let err = solver.try_step(&mut ff, t, &y, h, &[1e-12], 1e-12);
            assert!(err.is_finite());
            solver.dense_into(t, &y, h, &mut d);
            y.copy_from_slice(&solver.y_new);
            t += h;
            solver.accept();
            track.push(&d, 0, t);
        }
        let hint = AtomicUsize::new(0);
        for k in (0..=100).chain((0..=100).rev()) {
            let tk = k as f64 * 0.01;
            assert!((track.psi(tk, &hint) - tk.sin()).abs() < 1e-7, "{tk}");
        }
        // on the housing: omega = -psi; held at 0, the change is the integral of |sin t| on
        // [0, 1], 1 - cos 1
        let held = Neighbour::Predicted {
            t0: 0.0,
            omega: 0.0,
            alpha: 0.0,
        };
        let change = held.change(&track);
        assert!((change - (1.0 - 1f64.cos())).abs() < 1e-7, "{change}");
        let same = Neighbour::track(Arc::new(track.clone()), true);
        assert_eq!(same.change(&track), 0.0);
        assert_eq!(same.omega(0.5, || 3.0), 3.0 - track.psi(0.5, &hint));
    }
}
