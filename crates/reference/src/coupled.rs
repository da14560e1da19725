//! The multirate scheme on an inertial shaft (eq 4): the adaptive integration carries the
//! shaft and the discs in contact; the discs in free flight advance in closed form and join
//! the integrated state at their located re-engagement (crate docs, Theory).

use crate::dopri::Dense;
use crate::stepper::{Sink, Stepper, Switch};
use crate::system::{disc_sample, System};
use crate::ReferenceOptions;
use clutchpack_model::{
    DiscModel, DiscSample, Engagement, EngineError, ImpactEvent, Observer, PackModel, RunStats,
    Sample,
};

/// A disc in free flight since `t0` (s): eq (5) with `F = 0`, `J2 omega' = -C2 omega`.
#[derive(Debug, Clone, Copy)]
struct Free {
    t0: f64,
    /// Disc angle at `t0`, rad.
    theta0: f64,
    /// Disc speed at `t0`, rad/s.
    omega0: f64,
    /// Decay rate `k = C2 / J2`, 1/s.
    k: f64,
}

impl Free {
    fn new(t0: f64, theta0: f64, omega0: f64, d: &DiscModel) -> Free {
        Free {
            t0,
            theta0,
            omega0,
            k: d.drag_n_m_s_rad / d.inertia_kg_m2,
        }
    }

    /// Disc angle (rad) and speed (rad/s) at `t`: `omega = omega0 e^(-k tau)`,
    /// `theta = theta0 + omega0 (1 - e^(-k tau)) / k` (Hu et al. eq (5) with no spline load).
    fn at(&self, t: f64) -> (f64, f64) {
        let tau = t - self.t0;
        if self.k == 0.0 {
            (self.theta0 + self.omega0 * tau, self.omega0)
        } else {
            let e = (-self.k * tau).exp_m1(); // e^(-k tau) - 1
            (
                self.theta0 - self.omega0 * e / self.k,
                self.omega0 * (1.0 + e),
            )
        }
    }
}

/// Engagement depth (m) of free disc `d` when the shaft is at `(theta_s, omega_s)` at `t`.
fn free_depth(d: &DiscModel, f: &Free, t: f64, theta_s: f64, omega_s: f64) -> f64 {
    let (th, om) = f.at(t);
    let kin = d.spline.kinematics(theta_s - th, omega_s - om);
    d.law.engagement_depth_m(&kin)
}

/// The earliest re-engagement of a free disc inside the step `[t0, t1]` whose dense output
/// (shaft in components 0 and 1) is `dense`: `(time s, disc)`.
fn probe(
    pack: &PackModel,
    free: &[Option<Free>],
    t0: f64,
    t1: f64,
    dense: &Dense,
) -> Option<(f64, usize)> {
    let h = t1 - t0;
    let mut shaft = [[0.0; 2]; 5];
    let mut times = [0.0; 5];
    for q in 0..5 {
        times[q] = if q == 4 { t1 } else { t0 + h * q as f64 / 4.0 };
        dense.eval(times[q], &mut shaft[q]);
    }
    let mut best: Option<(f64, usize)> = None;
    for (i, f) in free.iter().enumerate() {
        let Some(f) = f else { continue };
        let d = &pack.discs[i];
        let Some(q) = (1..5).find(|&q| free_depth(d, f, times[q], shaft[q][0], shaft[q][1]) > 0.0)
        else {
            continue;
        };
        // Bisection: `a` not engaged, `b` engaged.
        let (mut a, mut b) = (times[q - 1], times[q]);
        let mut s = [0.0; 2];
        while b - a > 1e-13 {
            let m = 0.5 * (a + b);
            dense.eval(m, &mut s);
            if free_depth(d, f, m, s[0], s[1]) > 0.0 {
                b = m;
            } else {
                a = m;
            }
        }
        if best.is_none_or(|(tb, _)| b < tb) {
            best = Some((b, i));
        }
    }
    best
}

/// Builds whole-pack samples from the integrated state and the free discs' closed forms.
struct PackSink<'o, 'f> {
    obs: &'o mut dyn Observer,
    free: &'f [Option<Free>],
    sample: &'f mut Sample,
}

impl Sink for PackSink<'_, '_> {
    fn sample(&mut self, _k: u64, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]) {
        let (theta_s, omega_s) = sys.shaft(t, y);
        self.sample.t_s = t;
        self.sample.shaft_angle_rad = theta_s;
        self.sample.shaft_speed_rad_s = omega_s;
        for (slot, &id) in sys.ids.iter().enumerate() {
            self.sample.discs[id] = sys.disc_sample(t, slot, y, &modes[slot]);
        }
        for (id, f) in self.free.iter().enumerate() {
            if let Some(f) = f {
                let (th, om) = f.at(t);
                self.sample.discs[id] = disc_sample(
                    &sys.pack.discs[id],
                    theta_s,
                    omega_s,
                    theta_s - th,
                    omega_s - om,
                    &None,
                );
            }
        }
        self.obs.sample(self.sample);
    }
    fn impact(&mut self, e: ImpactEvent) {
        self.obs.impact(&e);
    }
    fn contact(&mut self, slot: usize, t: f64, sys: &System, y: &[f64], mode: &Option<Engagement>) {
        if !self.obs.wants_contact_samples() {
            return;
        }
        let d = sys.disc_sample(t, slot, y, mode);
        self.obs.contact_sample(sys.ids[slot], t, &d);
    }
}

pub(crate) fn run(
    pack: &PackModel,
    settings: &ReferenceOptions,
    duration_s: f64,
    obs: &mut dyn Observer,
) -> Result<RunStats, EngineError> {
    let nd = pack.discs.len();
    // Start from the whole pack and let every disc out of contact leave the integration.
    let mut st = Stepper::new(System::new(pack, (0..nd).collect()), settings);
    let mut free: Vec<Option<Free>> = vec![None; nd];
    let mut slot = 0;
    while slot < st.sys.ids.len() {
        if st.modes[slot].is_none() {
            release(&mut st, slot, &mut free);
        } else {
            slot += 1;
        }
    }
    st.restart();
    let mut sample = Sample {
        discs: vec![DiscSample::default(); nd],
        ..Sample::default()
    };
    let mut stopped = false;
    while st.t < duration_s {
        let switch = {
            let mut sink = PackSink {
                obs: &mut *obs,
                free: &free,
                sample: &mut sample,
            };
            let free = &free;
            st.step(duration_s, &mut sink, &mut |_, _, t0, t1, d| {
                probe(pack, free, t0, t1, d)
            })?
        };
        match switch {
            Switch::Separated(slot) => {
                release(&mut st, slot, &mut free);
                st.restart();
            }
            Switch::External(id) => {
                let f = free[id].take().expect("a free disc engaged");
                let (th, om) = f.at(st.t);
                let (phi, psi) = (st.y[0] - th, st.y[1] - om);
                st.insert(id, phi, psi);
                st.restart();
            }
            Switch::None | Switch::Engaged(_) => {}
        }
        if st.stats.steps.is_multiple_of(256) && obs.progress(st.t) {
            stopped = true;
            break;
        }
    }
    st.finish(&mut PackSink {
        obs,
        free: &free,
        sample: &mut sample,
    });
    let mut stats = st.stats.clone();
    stats.simulated_s = st.t;
    stats.stopped_early = stopped;
    Ok(stats)
}

/// Moves the disc in `slot` (out of contact) from the integration to free flight.
fn release(st: &mut Stepper, slot: usize, free: &mut [Option<Free>]) {
    let id = st.sys.ids[slot];
    let (phi, psi) = st.remove(slot);
    let (theta_s, omega_s) = (st.y[0], st.y[1]);
    free[id] = Some(Free::new(
        st.t,
        theta_s - phi,
        omega_s - psi,
        &st.sys.pack.discs[id],
    ));
}
