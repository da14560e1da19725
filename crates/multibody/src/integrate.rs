//! Time integration on top of rapier's step (see "Time integration" in the crate docs).
//!
//! # Theory
//! With one substep rapier advances a body by `w_{k+1} = w_k + h_k F / m`, then
//! `x_{k+1} = x_k + h_k w_{k+1}`, for whatever force `F` is applied during the step. So
//! `w_{k+1}` is the body's mean velocity over `[t_k, t_{k+1}]`, and the exact motion satisfies
//!
//! `w_{k+1} - w_k = (1/m) integral of F(t) H_k(t) dt`,
//!
//! with `H_k` the hat function that rises linearly from 0 at `t_{k-1}` to 1 at `t_k` and falls
//! back to 0 at `t_{k+1}` (the difference of two mean velocities). The kick applied at `t_k`
//! is this integral with `F(t)` replaced by the quadratic through the forces at `t_k` (known
//! now) and at the two evaluations before. With `F'`, `F''` its derivatives at `t_k`,
//! `h_1 = t_k - t_{k-1}` and `h_0` the step about to be taken:
//!
//! `kick(h_0) = F (h_0 + h_1) / 2 + F' (h_0^2 - h_1^2) / 6 + F'' (h_0^3 + h_1^3) / 24`
//!
//! and the force handed to rapier for the step is `kick(h_0) / h_0`. With `F` alone this is the
//! leapfrog (Stormer-Verlet) with its variable-step kick weight `(h_0 + h_1) / 2`; the two
//! correction terms make the kick exact for quadratic forces, the explicit Stormer-Cowell
//! method of order three for equal steps (`h (13 F_k - 2 F_{k-1} + F_{k-2}) / 12`).
//!
//! The quadratic interpolates the past half of the hat (`[t_{k-1}, t_k]`) but extrapolates
//! its future half. Extrapolated far beyond its data it is worse than nothing: the first long
//! free-flight step after a contact would extrapolate the contact's force curve over a
//! hundred contact steps. So the future half uses the quadratic only for `h_0 <= 2 h_1`, and
//! `F` held constant otherwise (the leapfrog's rule, exact enough for the drag and the drive
//! of free flight); and the quadratic is fitted only to evenly spread data (neighbouring
//! steps within a factor 2), else the line through the last two forces. The speed
//! synchronisation below follows the same rules.
//!
//! The forces depend on the speed at `t_k` (impact damping, drag), but rapier's `w_k` is the
//! mean over the last step. The speed at `t_k` is `w_k + (1/m) integral over [t_{k-1}, t_k] of
//! ((t - t_{k-1}) / h_1) F(t) dt`, with `F` extrapolated linearly from the two evaluations
//! before `t_k`: `w_k + (h_1/2) a_{k-1} + (h_1^2/3) a'`.

/// Nodes (on `[0, 1]`) and weights of 3-point Gauss-Legendre quadrature (exact to degree 5).
const GAUSS3: [(f64, f64); 3] = [
    (0.112_701_665_379_258_3, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

/// The relative motion of a coupling at `t_k` for the future half of its teeth's kick: angle,
/// speed, acceleration and jerk (rad, rad/s, rad/s^2, rad/s^3).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Motion {
    pub phi: f64,
    pub dphi: f64,
    pub ddphi: f64,
    /// Backward difference of the last two accelerations, and the step it spans (s).
    pub jerk: f64,
    pub jerk_step: f64,
}

/// `integral over [0, x] of torque(phi(u), dphi(u)) (x - u) / x du` along the Taylor path
/// `phi(u) = phi + dphi u + ddphi u^2 / 2 + jerk u^3 / 6`: the future half of the teeth's kick
/// for a step of length `x` (N m s). The jerk term keeps the speed, and so the impact
/// damping `1 + p v`, accurate to `O(u^3)` (without it the method falls to second order
/// whenever `p > 0`); like the kick's quadratic it is extrapolated only over up to twice the
/// step it was measured on.
pub(crate) fn future_impulse(m: &Motion, x: f64, torque: impl Fn(f64, f64) -> f64) -> f64 {
    let jerk = if x <= 2.0 * m.jerk_step { m.jerk } else { 0.0 };
    GAUSS3
        .iter()
        .map(|&(n, w)| {
            let u = n * x;
            let phi = m.phi + u * (m.dphi + u * (0.5 * m.ddphi + u * jerk / 6.0));
            let dphi = m.dphi + u * (m.ddphi + 0.5 * u * jerk);
            w * x * torque(phi, dphi) * (1.0 - n)
        })
        .sum()
}

/// `integral over [0, h] of torque(phi(u), dphi(u)) u / h du` along the cubic Hermite path from
/// `(phi0, dphi0)` to `(phi1, dphi1)` over the last step `h`: the past half of the teeth's kick
/// and of the speed synchronisation (N m s).
pub(crate) fn past_impulse(
    (phi0, dphi0): (f64, f64),
    (phi1, dphi1): (f64, f64),
    h: f64,
    torque: impl Fn(f64, f64) -> f64,
) -> f64 {
    GAUSS3
        .iter()
        .map(|&(u, w)| {
            let (u2, u3) = (u * u, u * u * u);
            let phi = (2.0 * u3 - 3.0 * u2 + 1.0) * phi0
                + (u3 - 2.0 * u2 + u) * h * dphi0
                + (-2.0 * u3 + 3.0 * u2) * phi1
                + (u3 - u2) * h * dphi1;
            let dphi = (6.0 * u2 - 6.0 * u) / h * phi0
                + (3.0 * u2 - 4.0 * u + 1.0) * dphi0
                + (-6.0 * u2 + 6.0 * u) / h * phi1
                + (3.0 * u2 - 2.0 * u) * dphi1;
            w * h * torque(phi, dphi) * u
        })
        .sum()
}

/// `integral over [t0, t0 + h] of f(t) w(t) dt` with the rising ramp `w = (t - t0) / h`
/// (`rising`) or the falling ramp `w = (t0 + h - t) / h`, by 3-point Gauss-Legendre: a half of
/// the kick of a load known as a function of time (the drive torque of an inertial shaft).
pub(crate) fn ramp_integral(t0: f64, h: f64, rising: bool, f: impl Fn(f64) -> f64) -> f64 {
    GAUSS3
        .iter()
        .map(|&(n, w)| {
            let ramp = if rising { n } else { 1.0 - n };
            w * h * f(t0 + n * h) * ramp
        })
        .sum()
}

/// A physical load (force and torque, world frame) on one body at one instant, as six numbers:
/// force x, y, z, torque x, y, z.
pub(crate) type Load = [f64; 6];

/// The loads of one body at the last two evaluations.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct LoadHistory {
    /// `(t, load)`, most recent first.
    entries: [(f64, Load); 2],
    len: usize,
}

/// The kick polynomial of one body for the step from `t_k`: `impulse(h0)` is the impulse to
/// deliver during a step of length `h0` (N s and N m s).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Kick {
    f: Load,
    d1: Load,
    d2: Load,
    h1: f64,
}

impl Kick {
    /// The impulse over the dual cell for a step of length `h0`, component `c`.
    pub fn impulse_component(&self, c: usize, h0: f64) -> f64 {
        let h1 = self.h1;
        // past half: the interpolating quadratic against the rising ramp
        let past =
            self.f[c] * 0.5 * h1 - self.d1[c] * h1 * h1 / 6.0 + self.d2[c] * h1 * h1 * h1 / 24.0;
        // future half: extrapolated only over up to twice the last step
        let future = if h0 <= 2.0 * h1 {
            self.f[c] * 0.5 * h0 + self.d1[c] * h0 * h0 / 6.0 + self.d2[c] * h0 * h0 * h0 / 24.0
        } else {
            self.f[c] * 0.5 * h0
        };
        past + future
    }

    /// The force and torque to apply during a step of length `h0`: `impulse(h0) / h0`.
    pub fn applied(&self, h0: f64) -> Load {
        let mut out = [0.0; 6];
        for (c, o) in out.iter_mut().enumerate() {
            *o = self.impulse_component(c, h0) / h0;
        }
        out
    }
}

impl LoadHistory {
    /// The kick polynomial for the load `now` at time `t`.
    pub fn kick(&self, t: f64, now: &Load) -> Kick {
        let mut k = Kick {
            f: *now,
            ..Default::default()
        };
        if self.len == 0 {
            return k;
        }
        let (t1, l1) = self.entries[0];
        let h1 = t - t1;
        k.h1 = h1;
        if h1 <= 0.0 {
            return k;
        }
        // The quadratic only from evenly spread data (a short step next to a long one, as
        // around a landing, makes its curvature the derivative of a kink).
        let h2 = if self.len >= 2 {
            t1 - self.entries[1].0
        } else {
            0.0
        };
        let quadratic = h2 > 0.0 && h1 <= 2.0 * h2 && h2 <= 2.0 * h1;
        for c in 0..6 {
            let dd1 = (now[c] - l1[c]) / h1;
            if quadratic {
                let dd2 = (l1[c] - self.entries[1].1[c]) / h2;
                let ddd = (dd1 - dd2) / (h1 + h2);
                // Derivatives at t of the quadratic through the three points.
                k.d1[c] = dd1 + ddd * h1;
                k.d2[c] = 2.0 * ddd;
            } else {
                k.d1[c] = dd1;
            }
        }
        k
    }

    /// How many evaluations are recorded (at most 2).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Records the load at `t`.
    pub fn push(&mut self, t: f64, load: Load) {
        self.entries[1] = self.entries[0];
        self.entries[0] = (t, load);
        self.len = (self.len + 1).min(2);
    }

    /// The speed along component `c` (3..6: angular about x, y, z) at `t`, from rapier's mean
    /// speed `mean` over the last step, for a body of inverse inertia `inv_m` along it.
    pub fn synchronised(&self, t: f64, mean: f64, c: usize, inv_m: f64) -> f64 {
        if self.len == 0 {
            return mean;
        }
        let (t1, l1) = self.entries[0];
        let h1 = t - t1;
        let a1 = l1[c] * inv_m;
        let slope = if self.len >= 2 {
            let (t2, l2) = self.entries[1];
            let h2 = t1 - t2;
            if h2 > 0.0 && h1 <= 2.0 * h2 && h2 <= 2.0 * h1 {
                (a1 - l2[c] * inv_m) / h2
            } else {
                0.0
            }
        } else {
            0.0
        };
        mean + 0.5 * h1 * a1 + h1 * h1 * slope / 3.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kick integrates any quadratic force exactly against the hat function (the
    /// definition of the method), for unequal steps: check against a closed-form integral.
    #[test]
    fn kick_is_exact_for_quadratic_forces() {
        let f = |t: f64| 3.0 - 2.0 * t + 5.0 * t * t;
        let (t2, t1, t0, tn) = (0.1, 0.35, 0.5, 0.75);
        let mut h = LoadHistory::default();
        h.push(t2, [f(t2), 0.0, 0.0, 0.0, 0.0, 0.0]);
        h.push(t1, [f(t1), 0.0, 0.0, 0.0, 0.0, 0.0]);
        let k = h.kick(t0, &[f(t0), 0.0, 0.0, 0.0, 0.0, 0.0]);
        // integral of f * hat over [t1, tn], by Simpson on each half (exact for cubics)
        let simpson = |a: f64, b: f64, g: &dyn Fn(f64) -> f64| {
            (b - a) / 6.0 * (g(a) + 4.0 * g(0.5 * (a + b)) + g(b))
        };
        let rise = |t: f64| f(t) * (t - t1) / (t0 - t1);
        let fall = |t: f64| f(t) * (tn - t) / (tn - t0);
        let exact = simpson(t1, t0, &rise) + simpson(t0, tn, &fall);
        let got = k.impulse_component(0, tn - t0);
        assert!((got - exact).abs() < 1e-14, "{got} vs {exact}");
    }

    /// The synchronised speed is exact for a linear force: the mean speed over the last step
    /// plus the integral of the acceleration against the rising ramp.
    #[test]
    fn synchronised_speed_is_exact_for_linear_forces() {
        // x'' = a(t) = 2 + 3 t, v(t) = 1 + 2 t + 1.5 t^2, x(t) = t + t^2 + t^3 / 2
        let x = |t: f64| t + t * t + 0.5 * t * t * t;
        let v = |t: f64| 1.0 + 2.0 * t + 1.5 * t * t;
        let (t2, t1, t0) = (0.2, 0.5, 0.7);
        let mut h = LoadHistory::default();
        h.push(t2, [0.0, 0.0, 0.0, 0.0, 0.0, 2.0 + 3.0 * t2]);
        h.push(t1, [0.0, 0.0, 0.0, 0.0, 0.0, 2.0 + 3.0 * t1]);
        let mean = (x(t0) - x(t1)) / (t0 - t1);
        let got = h.synchronised(t0, mean, 5, 1.0);
        assert!((got - v(t0)).abs() < 1e-13, "{got} vs {}", v(t0));
    }
}
