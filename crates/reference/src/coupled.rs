//! The multirate scheme on an inertial shaft (eq 4): the adaptive integration carries the
//! shaft and the discs in contact; the discs in free flight advance in closed form and join
//! the integrated state at their located re-engagement (crate docs, Theory).

use crate::dopri::Dense;
use crate::session::{keep, Clock, Queue};
use crate::stepper::{Sink, Stepper, Switch};
use crate::system::{disc_sample, System};
use crate::ReferenceOptions;
use clutchpack_model::session::{Advance, Driven, Inputs, Session, Snapshot};
use clutchpack_model::{
    DiscModel, DiscSample, Engagement, EngineError, ImpactEvent, NullObserver, Observer, PackModel,
    RunStats, Sample,
};
use std::sync::Arc;

/// A disc in free flight since `t0` (s): eq (5) with `F = 0`, `J2 omega' = -C2 omega`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Free {
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
struct PackSink<'q, 'f> {
    queue: &'q mut Queue,
    free: &'f [Option<Free>],
}

/// The sample at `t` (s) of the pack whose integrated slots are in `sys` (state `y`, modes
/// `modes`) and whose other discs are free (`free`).
fn pack_sample(
    t: f64,
    sys: &System,
    y: &[f64],
    modes: &[Option<Engagement>],
    free: &[Option<Free>],
) -> Sample {
    let (theta_s, omega_s) = sys.shaft(t, y);
    let mut sample = Sample {
        t_s: t,
        shaft_angle_rad: theta_s,
        shaft_speed_rad_s: omega_s,
        discs: vec![DiscSample::default(); free.len()],
    };
    for (slot, &id) in sys.ids.iter().enumerate() {
        sample.discs[id] = sys.disc_sample(t, slot, y, &modes[slot]);
    }
    for (id, f) in free.iter().enumerate() {
        if let Some(f) = f {
            let (th, om) = f.at(t);
            sample.discs[id] = disc_sample(
                &sys.pack.discs[id],
                theta_s,
                omega_s,
                theta_s - th,
                omega_s - om,
                &None,
            );
        }
    }
    sample
}

impl Sink for PackSink<'_, '_> {
    fn sample(&mut self, _k: u64, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]) {
        self.queue.sample(pack_sample(t, sys, y, modes, self.free));
    }
    fn impact(&mut self, e: ImpactEvent) {
        self.queue.impact(e);
    }
    fn contact(&mut self, slot: usize, t: f64, sys: &System, y: &[f64], mode: &Option<Engagement>) {
        self.queue.contact(slot, t, sys, y, mode);
    }
}

/// The multirate scheme on an inertial shaft as a session.
#[derive(Clone)]
pub(crate) struct CoupledSession {
    st: Stepper,
    free: Vec<Option<Free>>,
    clock: Clock,
    queue: Queue,
    /// The integration and the free discs as they were before the last step's change of the
    /// integrated discs, when that step passed the session's time (the snapshot needs them).
    before: Option<Box<(Stepper, Vec<Option<Free>>)>>,
    /// A driven session's integration and free discs before its last step that may pass a
    /// call's end (`crate::session::keep`; [`CoupledSession::rewind`]).
    saved: Option<Box<Stepper>>,
    saved_free: Vec<Option<Free>>,
}

impl CoupledSession {
    pub fn new(pack: Arc<PackModel>, settings: &ReferenceOptions, driven: Driven) -> Self {
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
        CoupledSession {
            st,
            free,
            clock: Clock::new(driven),
            queue: Queue::default(),
            before: None,
            saved: None,
            saved_free: Vec::new(),
        }
    }

    /// Steps until the integration's time reaches `t` (s), the steps ending at `end` (s), the
    /// discs leaving and joining it; the output queued and sent up to the integration's time
    /// at every poll of `obs`.
    fn steps(&mut self, t: f64, end: f64, obs: &mut dyn Observer) -> Result<Advance, EngineError> {
        let mut advance = Advance::Reached;
        // a copy before a step that may pass `t`, where an input may change (not when the
        // steps end at `t`)
        let keeps = self.clock.keeps() && end > t;
        while self.st.t < t {
            if keeps && self.st.may_pass(t) {
                keep(&mut self.saved, &self.st);
                self.saved_free.clone_from(&self.free);
            }
            let step = {
                let mut sink = PackSink {
                    queue: &mut self.queue,
                    free: &self.free,
                };
                let (free, pack) = (&self.free, self.st.sys.pack.clone());
                self.st.step(end, &mut sink, &mut |_, _, t0, t1, d| {
                    probe(&pack, free, t0, t1, d)
                })
            };
            let switch = match step {
                Ok(s) => s,
                Err(e) => {
                    self.clock.failed = true;
                    self.queue.flush(self.st.t, obs);
                    return Err(e);
                }
            };
            let regroups = matches!(switch, Switch::Separated(_) | Switch::External(_));
            self.before =
                (regroups && self.st.t > t).then(|| Box::new((self.st.clone(), self.free.clone())));
            match switch {
                Switch::Separated(slot) => {
                    release(&mut self.st, slot, &mut self.free);
                    self.st.restart();
                }
                Switch::External(id) => {
                    let f = self.free[id].take().expect("a free disc engaged");
                    let (th, om) = f.at(self.st.t);
                    let (phi, psi) = (self.st.y[0] - th, self.st.y[1] - om);
                    self.st.insert(id, phi, psi);
                    self.st.restart();
                }
                Switch::None | Switch::Engaged(_) => {}
            }
            if self.st.stats.steps.is_multiple_of(256) && self.queue.poll(self.st.t, t, obs) {
                advance = Advance::Stopped;
                break;
            }
        }
        Ok(advance)
    }

    /// Ends the step that passed the session's time there, before an input changes (a driven
    /// session): the integration and the free discs kept before it stepped again to the
    /// session's time, what those steps give again (sent before) dropped with what the step
    /// had produced past it.
    fn rewind(&mut self) -> Result<(), EngineError> {
        let t = self.clock.t;
        let Some(saved) = self.saved.as_deref().filter(|_| self.st.t > t) else {
            return Ok(());
        };
        self.st.clone_from(saved);
        self.free.clone_from(&self.saved_free);
        self.before = None;
        self.queue.clear();
        let done = self.steps(t, t, &mut NullObserver);
        self.queue.clear();
        if done.is_err() {
            self.clock.failed = true;
        }
        done.map(|_| ())
    }
}

impl Session for CoupledSession {
    fn time_s(&self) -> f64 {
        self.clock.t
    }

    fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), EngineError> {
        self.rewind()?;
        // an inertial shaft: its drive torque, no jump of a speed
        let (pack, _) = self.clock.hold(&self.st.sys.pack, inputs)?;
        self.st.sys.pack = Arc::new(pack);
        self.st.restart();
        Ok(())
    }

    fn set_stop_time(&mut self, t_s: f64) {
        self.clock.stop = t_s;
    }

    fn advance_to(&mut self, t: f64, obs: &mut dyn Observer) -> Result<Advance, EngineError> {
        self.clock.check_advance(t)?;
        self.queue.wants_contacts = obs.wants_contact_samples();
        let end = self.clock.step_end(t);
        let advance = self.steps(t, end, obs)?;
        let now = self.clock.end_call(advance, self.st.t, t);
        self.queue.flush(now, obs);
        Ok(advance)
    }

    fn snapshot(&self) -> Snapshot {
        let t = self.clock.t;
        let (st, free) = match &self.before {
            Some(b) if t < self.st.t => (&b.0, &b.1),
            _ => (&self.st, &self.free),
        };
        let mut y = Vec::new();
        let modes = st.state_at(t, &mut y);
        Snapshot {
            sample: pack_sample(t, &st.sys, &y, modes, free),
            interfaces: Vec::new(),
            drum: None,
        }
    }

    fn finish(&mut self, obs: &mut dyn Observer) -> RunStats {
        self.st.finish(&mut PackSink {
            queue: &mut self.queue,
            free: &self.free,
        });
        self.queue.flush(f64::INFINITY, obs);
        let mut stats = self.st.stats.clone();
        stats.simulated_s = self.clock.t;
        stats
    }

    fn boxed_clone(&self) -> Box<dyn Session> {
        Box::new(self.clone())
    }
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
