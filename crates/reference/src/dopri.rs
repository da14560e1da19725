//! Dormand-Prince 5(4) with its 4th-order dense output (Hairer, Norsett and Wanner, *Solving
//! Ordinary Differential Equations I*, section II.5 and the `dopri5` code), specialised for
//! the reference engine: no allocation per step, and a dense interpolant that the engine uses
//! to locate contact onsets, separations and load peaks inside a step.

// Butcher tableau of DOPRI5.
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error estimate coefficients (5th minus 4th order weights).
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Dense output coefficients.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// The 4th-order continuous extension of one accepted step on `[t0, t0 + h]`.
#[derive(Debug, Default)]
pub struct Dense {
    /// Start of the step, s.
    pub t0: f64,
    /// Length of the step, s.
    pub h: f64,
    r1: Vec<f64>,
    r2: Vec<f64>,
    r3: Vec<f64>,
    r4: Vec<f64>,
    r5: Vec<f64>,
}

clone_reusing!(Dense {
    t0,
    h,
    r1,
    r2,
    r3,
    r4,
    r5
});

impl Dense {
    /// Inserts two components (zero) at index `k`: a disc joins the system at the end of
    /// this step, so its interpolant is never evaluated.
    pub fn insert2(&mut self, k: usize) {
        if self.r1.len() < k {
            return;
        }
        for v in [
            &mut self.r1,
            &mut self.r2,
            &mut self.r3,
            &mut self.r4,
            &mut self.r5,
        ] {
            v.splice(k..k, [0.0, 0.0]);
        }
    }

    /// Removes the two components at index `k` (a disc leaves the system).
    pub fn remove2(&mut self, k: usize) {
        if self.r1.len() < k + 2 {
            return;
        }
        for v in [
            &mut self.r1,
            &mut self.r2,
            &mut self.r3,
            &mut self.r4,
            &mut self.r5,
        ] {
            v.drain(k..k + 2);
        }
    }

    /// Interpolated state at `t` (within the step) into `out` (its first `out.len()`
    /// components).
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        let th = fraction(self.t0, self.h, t);
        for i in 0..out.len() {
            let c = [self.r1[i], self.r2[i], self.r3[i], self.r4[i], self.r5[i]];
            out[i] = interpolate(&c, th);
        }
    }

    /// Interpolated components `range` at `t` (within the step) into `out` (the others left
    /// as they are): each the value [`Self::eval`] gives it.
    pub fn eval_range(&self, t: f64, range: std::ops::Range<usize>, out: &mut [f64]) {
        let th = fraction(self.t0, self.h, t);
        for i in range {
            let c = [self.r1[i], self.r2[i], self.r3[i], self.r4[i], self.r5[i]];
            out[i] = interpolate(&c, th);
        }
    }

    /// The interpolant of component `i` alone: `(t0, h, coefficients)` for [`eval_component`].
    pub fn component(&self, i: usize) -> (f64, f64, [f64; 5]) {
        let c = [self.r1[i], self.r2[i], self.r3[i], self.r4[i], self.r5[i]];
        (self.t0, self.h, c)
    }
}

/// The value at `t` of one component's interpolant `(t0, h, c)` from [`Dense::component`].
pub fn eval_component(t0: f64, h: f64, c: &[f64; 5], t: f64) -> f64 {
    interpolate(c, fraction(t0, h, t))
}

/// The fraction `(t - t0) / h` of a step `[t0, t0 + h]` at `t`, clamped to [0, 1].
fn fraction(t0: f64, h: f64, t: f64) -> f64 {
    if h > 0.0 {
        ((t - t0) / h).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The dense output's polynomial (Hairer's form for DOPRI5) at the step's fraction `th`.
fn interpolate(c: &[f64; 5], th: f64) -> f64 {
    let th1 = 1.0 - th;
    c[0] + th * (c[1] + th1 * (c[2] + th * (c[3] + th1 * c[4])))
}

/// Workspace and stages of the integrator for a system of dimension `n`.
#[derive(Debug)]
pub struct Dopri5 {
    /// Stage derivatives k1..k7 (k1 is f(t, y) at the start of the step; k7 at its end).
    k: [Vec<f64>; 7],
    ytmp: Vec<f64>,
    /// Candidate state at the end of the step.
    pub y_new: Vec<f64>,
    err: Vec<f64>,
    /// How many leading components the error norm takes (`None`: all): counters after them
    /// (a thermal run's teeth work) are integrated without steering the step, and the norm
    /// of the others is exactly what it is without them.
    pub norm_len: Option<usize>,
}

clone_reusing!(Dopri5 {
    k,
    ytmp,
    y_new,
    err,
    norm_len
});

impl Dopri5 {
    /// Allocates the workspace for dimension `n`.
    pub fn new(n: usize) -> Dopri5 {
        let v = || vec![0.0; n];
        Dopri5 {
            k: [v(), v(), v(), v(), v(), v(), v()],
            ytmp: v(),
            y_new: v(),
            err: v(),
            norm_len: None,
        }
    }

    /// Resizes the workspace to dimension `n` (the derivative at the start of the next step
    /// must be set again).
    pub fn resize(&mut self, n: usize) {
        for v in self.k.iter_mut() {
            v.resize(n, 0.0);
        }
        for v in [&mut self.ytmp, &mut self.y_new, &mut self.err] {
            v.resize(n, 0.0);
        }
    }

    /// `f(t, y)` at the start of the next step (call after a restart or at t = 0).
    pub fn set_start_derivative(&mut self, dy: &[f64]) {
        self.k[0].copy_from_slice(dy);
    }

    /// Tries a step of size `h` from `(t, y)`. Fills `y_new` and returns the scaled RMS error
    /// norm (accept when <= 1), with scale `atol[i] + rtol * max(|y_i|, |y_new_i|)`.
    pub fn try_step<F: FnMut(f64, &[f64], &mut [f64])>(
        &mut self,
        f: &mut F,
        t: f64,
        y: &[f64],
        h: f64,
        atol: &[f64],
        rtol: f64,
    ) -> f64 {
        let n = y.len();
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let yt = &mut self.ytmp;
        for i in 0..n {
            yt[i] = y[i] + h * A21 * k1[i];
        }
        f(t + C2 * h, yt, k2);
        for i in 0..n {
            yt[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        f(t + C3 * h, yt, k3);
        for i in 0..n {
            yt[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        f(t + C4 * h, yt, k4);
        for i in 0..n {
            yt[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        f(t + C5 * h, yt, k5);
        for i in 0..n {
            yt[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        f(t + h, yt, k6);
        let yn = &mut self.y_new;
        for i in 0..n {
            yn[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        f(t + h, yn, k7);
        let mut sum = 0.0;
        // the components in the norm: the first `norm_len` (counters after them are integrated
        // but do not steer the step)
        let m = self.norm_len.map_or(n, |m| m.min(n));
        for i in 0..m {
            self.err[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let sc = atol[i] + rtol * y[i].abs().max(yn[i].abs());
            let r = self.err[i] / sc;
            sum += r * r;
        }
        (sum / m as f64).sqrt()
    }

    /// Builds the dense output of the step just tried from `(t, y)` with size `h`.
    pub fn dense_into(&self, t: f64, y: &[f64], h: f64, d: &mut Dense) {
        let n = y.len();
        for v in [&mut d.r1, &mut d.r2, &mut d.r3, &mut d.r4, &mut d.r5] {
            v.resize(n, 0.0);
        }
        let [k1, _k2, k3, k4, k5, k6, k7] = &self.k;
        for i in 0..n {
            let ydiff = self.y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            d.r1[i] = y[i];
            d.r2[i] = ydiff;
            d.r3[i] = bspl;
            d.r4[i] = ydiff - h * k7[i] - bspl;
            d.r5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
        d.t0 = t;
        d.h = h;
    }

    /// After an accepted step: the end derivative becomes the next start derivative (FSAL).
    pub fn accept(&mut self) {
        self.k.swap(0, 6);
    }
}

/// New step size from an error norm `err` (> 0) of a method of order 5 (4 embedded), with a
/// safety factor 0.9 and growth limited to [0.2, 5].
pub fn next_step(h: f64, err: f64) -> f64 {
    let fac = if err == 0.0 {
        5.0
    } else {
        (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
    };
    h * fac
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harmonic oscillator y'' = -y over 10 periods: the adaptive step reaches the exact
    /// solution within a small multiple of the tolerance, and the dense output between steps
    /// is as accurate as the steps (4th order interpolant).
    #[test]
    fn harmonic_oscillator_and_dense_output() {
        let mut f = |_t: f64, y: &[f64], dy: &mut [f64]| {
            dy[0] = y[1];
            dy[1] = -y[0];
        };
        let mut s = Dopri5::new(2);
        let mut y = vec![1.0, 0.0];
        let mut dy = vec![0.0; 2];
        f(0.0, &y, &mut dy);
        s.set_start_derivative(&dy);
        let (mut t, mut h): (f64, f64) = (0.0, 1e-3);
        let tend = 20.0 * std::f64::consts::PI;
        let atol = [1e-12, 1e-12];
        let mut d = Dense::default();
        let mut worst_dense: f64 = 0.0;
        let mut buf = [0.0; 2];
        while t < tend {
            h = h.min(tend - t);
            let err = s.try_step(&mut f, t, &y, h, &atol, 1e-10);
            if err <= 1.0 {
                s.dense_into(t, &y, h, &mut d);
                let tm = t + 0.37 * h;
                d.eval(tm, &mut buf);
                worst_dense = worst_dense.max((buf[0] - tm.cos()).abs());
                s.accept();
                t += h;
                y.copy_from_slice(&s.y_new);
            }
            h = next_step(h, err);
        }
        assert!((y[0] - 1.0).abs() < 1e-8, "{}", y[0]);
        assert!(y[1].abs() < 1e-8, "{}", y[1]);
        assert!(worst_dense < 1e-8, "dense error {worst_dense}");
    }
}
