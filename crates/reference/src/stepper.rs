//! One adaptive DOPRI5 integration of a [`System`] with located contact events: the kernel
//! that every scheme runs (the monolithic scheme on the whole pack, the multirate schemes on
//! one disc or on the shaft with the discs in contact).

use crate::dopri::{next_step, Dense, Dopri5};
use crate::system::System;
use crate::ReferenceOptions;
use clutchpack_model::{DiscModel, Engagement, EngineError, ImpactEvent, ImpactTracker, RunStats};
use clutchpack_model::{STALL_SPAN_S, STALL_STEPS as STALL_BLOCK};

/// Receives what a [`Stepper`] produces.
pub(crate) trait Sink {
    /// Output sample number `k` at `t` (s) with the system's state `y` and modes.
    fn sample(&mut self, k: u64, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]);
    /// A completed impact event.
    fn impact(&mut self, e: ImpactEvent);
    /// The disc in `slot` at `t` (s), at a step inside its contact event, its onset or the
    /// step that closes it, with the system's state `y` and the mode the disc had along the
    /// step (`Observer::contact_sample`).
    fn contact(&mut self, slot: usize, t: f64, sys: &System, y: &[f64], mode: &Option<Engagement>);
}

/// What ended an accepted step besides its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Switch {
    /// The step ran its full length.
    None,
    /// The disc in this slot started a contact event.
    Engaged(usize),
    /// The disc in this slot ended its contact event (its impact has been emitted).
    Separated(usize),
    /// An event outside the system (reported by the `external` probe) cut the step; the caller
    /// changes the system and calls [`Stepper::restart`].
    External(usize),
}

/// Per-slot bookkeeping of contact events.
#[derive(Clone)]
pub(crate) struct DiscTrack {
    pub tracker: ImpactTracker,
    /// |load| at the end of the last accepted step, N.
    last_abs: f64,
    /// Whether the load was still rising at the end of the last accepted step.
    rising: bool,
    /// Onset of the current event, s.
    t_on: f64,
    /// Whether the onset's contact sample is still to be sent (at the start of the next step).
    onset_pending: bool,
    /// Steps taken inside the current event.
    contact_steps: u32,
    /// Time of the last contact sample sent, s.
    last_contact_t: f64,
    /// Whether the end of the current step goes out as a contact sample whatever the thinning
    /// (the load's maximum lies in this step or the last).
    contact_due: bool,
}

/// Every this many steps inside a contact is sent as a contact sample, and the step that ends
/// on the separation, and both ends of the steps around the load's maximum (the step where
/// `|F|` stops rising and the one before). The steps inside a contact are about 60 (the
/// paper case, tolerance 1e-9) and already denser where the load bends (the error control):
/// every second one gives about 30 points per contact at half the recording's cost of every
/// step, and the steps around the peak keep its largest point as close to the located peak
/// as every step would (measured 0.13 % on the paper case, `tests/contact_samples.rs`;
/// grazing film contacts of `pack-4-rattle` with 8 steps in all were 2.8 % low without them).
const CONTACT_SAMPLE_EVERY: u32 = 2;

impl DiscTrack {
    fn new(id: usize) -> DiscTrack {
        DiscTrack {
            tracker: ImpactTracker::new(id),
            last_abs: 0.0,
            rising: false,
            t_on: 0.0,
            onset_pending: false,
            contact_steps: 0,
            last_contact_t: f64::NEG_INFINITY,
            contact_due: false,
        }
    }
}

pub(crate) fn check_disc(d: &DiscModel) -> Result<(), EngineError> {
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

/// The adaptive integration of one system.
pub(crate) struct Stepper {
    pub sys: System,
    /// Time reached, s.
    pub t: f64,
    /// State at `t`.
    pub y: Vec<f64>,
    /// Contact mode of each slot.
    pub modes: Vec<Option<Engagement>>,
    /// The modes along the last accepted step (they differ from `modes` after a step that
    /// ended on a switch), for [`Stepper::state_at`].
    step_modes: Vec<Option<Engagement>>,
    tracks: Vec<DiscTrack>,
    solver: Dopri5,
    /// Dense output of the step before the last accepted one, and of the last.
    prev: Dense,
    pub cur: Dense,
    h: f64,
    atol: Vec<f64>,
    tol: f64,
    max_step: f64,
    rate: f64,
    /// Number of the next output sample (at `k / rate`).
    pub next_sample: u64,
    buf: Vec<f64>,
    /// The state at a step's three inner quarter points (for the event probes).
    quarters: Vec<f64>,
    y_new: Vec<f64>,
    dy: Vec<f64>,
    pub stats: RunStats,
    /// Time at the start of the current block of [`STALL_BLOCK`] steps, s.
    block_t0: f64,
}

clone_reusing!(Stepper {
    sys,
    t,
    y,
    modes,
    step_modes,
    tracks,
    solver,
    prev,
    cur,
    h,
    atol,
    tol,
    max_step,
    rate,
    next_sample,
    buf,
    quarters,
    y_new,
    dy,
    stats,
    block_t0,
});

impl Stepper {
    /// Starts `sys` at t = 0 from its initial state; a disc may start inside a contact event.
    pub fn new(sys: System, settings: &ReferenceOptions) -> Stepper {
        let n = sys.dim();
        let tol = settings.tolerance;
        let y = sys.initial_state();
        let mut s = Stepper {
            t: 0.0,
            modes: vec![None; sys.ids.len()],
            step_modes: Vec::new(),
            tracks: sys.ids.iter().map(|&id| DiscTrack::new(id)).collect(),
            atol: vec![tol; n],
            solver: Dopri5::new(n),
            prev: Dense::default(),
            cur: Dense::default(),
            h: settings.max_step_s.min(1e-6),
            tol,
            max_step: settings.max_step_s,
            rate: settings.record_rate_hz,
            next_sample: 0,
            buf: vec![0.0; n],
            quarters: Vec::new(),
            y_new: vec![0.0; n],
            dy: vec![0.0; n],
            stats: RunStats::default(),
            block_t0: 0.0,
            y,
            sys,
        };
        for slot in 0..s.sys.ids.len() {
            s.atol[s.sys.off + 2 * slot] = tol * s.sys.disc(slot).spline.half_play_rad();
            if s.sys.depth(slot, &s.y) > 0.0 {
                s.engage(slot, 0.0);
            }
        }
        s.restart();
        s
    }

    /// Opens a contact event of `slot` at `t` (its state is `self.y`).
    fn engage(&mut self, slot: usize, t: f64) {
        let kin = self.sys.kin(slot, &self.y);
        self.modes[slot] = Some(self.sys.disc(slot).law.engage(&kin));
        let tr = &mut self.tracks[slot];
        tr.tracker.begin(t, kin.flank, kin.v_n_m_s);
        tr.t_on = t;
        tr.last_abs = 0.0;
        tr.rising = true;
        tr.onset_pending = true;
        tr.contact_steps = 0;
        tr.contact_due = false;
    }

    /// Extends the state by the teeth's work on the relative motion (J, from 0 now;
    /// [`System::teeth_work`]), outside the step's error norm, and restarts the integration.
    pub fn carry_teeth_work(&mut self) {
        if self.sys.teeth_work {
            return;
        }
        let n = self.sys.dim();
        self.sys.teeth_work = true;
        self.y.push(0.0);
        for v in [&mut self.atol, &mut self.buf, &mut self.y_new, &mut self.dy] {
            v.resize(n + 1, 0.0);
        }
        self.atol[n] = self.tol;
        self.solver.resize(n + 1);
        self.solver.norm_len = Some(n);
        self.restart();
    }

    /// Restarts the integration at `(t, y)` after a change of mode or of the system.
    pub fn restart(&mut self) {
        self.sys.rhs(self.t, &self.y, &self.modes, &mut self.dy);
        self.stats.rhs_evals += 1;
        self.solver.set_start_derivative(&self.dy);
    }

    /// Adds the disc `id` to the system in the slot that keeps `ids` sorted, with relative
    /// angle `phi` (rad) and speed `psi` (rad/s) at `self.t`, opening a contact event there
    /// when its engagement depth is positive. Call [`Self::restart`] afterwards.
    pub fn insert(&mut self, id: usize, phi: f64, psi: f64) -> usize {
        let slot = self.sys.ids.partition_point(|&x| x < id);
        let k = self.sys.off + 2 * slot;
        self.sys.ids.insert(slot, id);
        self.y.splice(k..k, [phi, psi]);
        let g0 = self.sys.disc(slot).spline.half_play_rad();
        self.atol.splice(k..k, [self.tol * g0, self.tol]);
        self.modes.insert(slot, None);
        self.tracks.insert(slot, DiscTrack::new(id));
        self.prev.insert2(k);
        self.cur.insert2(k);
        self.resize();
        if self.sys.depth(slot, &self.y) > 0.0 {
            self.engage(slot, self.t);
        }
        slot
    }

    /// Removes the disc in `slot` (out of contact) from the system; returns its `(phi, psi)`.
    /// Call [`Self::restart`] afterwards.
    pub fn remove(&mut self, slot: usize) -> (f64, f64) {
        debug_assert!(self.modes[slot].is_none());
        let k = self.sys.off + 2 * slot;
        let out = (self.y[k], self.y[k + 1]);
        self.sys.ids.remove(slot);
        self.y.drain(k..k + 2);
        self.atol.drain(k..k + 2);
        self.modes.remove(slot);
        self.tracks.remove(slot);
        self.prev.remove2(k);
        self.cur.remove2(k);
        self.resize();
        out
    }

    fn resize(&mut self) {
        let n = self.sys.dim();
        self.solver.resize(n);
        self.buf.resize(n, 0.0);
        self.y_new.resize(n, 0.0);
        self.dy.resize(n, 0.0);
    }

    /// The state at `t` (s) into `out` and the contact modes it has there: the current state
    /// for `t >= self.t`, else the dense output of the last two steps (`t` must not lie
    /// before them; a session's time lies in the last step).
    pub fn state_at(&self, t: f64, out: &mut Vec<f64>) -> &[Option<Engagement>] {
        out.resize(self.y.len(), 0.0);
        if t >= self.t || self.cur.h <= 0.0 {
            out.copy_from_slice(&self.y);
            &self.modes
        } else {
            eval2(&self.prev, &self.cur, t, out);
            &self.step_modes
        }
    }

    /// Whether the next step may end past `t` (s): the step the controller wants (a rejection
    /// only shortens it) reaches beyond `t`. A driven session keeps a copy of the stepper
    /// before such a step, to end it at its communication point should an input change there
    /// (`crate::session::Rewind`).
    pub fn may_pass(&self, t: f64) -> bool {
        self.t + self.h.min(self.max_step) > t
    }

    /// Whether [`Self::state_at`] knows the state at `t` (s): `t` at or after the stepper's
    /// time or inside its last two steps.
    pub fn remembers(&self, t: f64) -> bool {
        let start = if self.prev.h > 0.0 {
            self.prev.t0
        } else {
            self.cur.t0
        };
        t >= self.t || self.cur.h <= 0.0 || t >= start
    }

    /// Closes the open contact events at the end of a run (or a stop) at `self.t`.
    pub fn finish(&mut self, sink: &mut impl Sink) {
        for tr in self.tracks.iter_mut() {
            if let Some(e) = tr.tracker.finish(self.t) {
                sink.impact(e);
            }
        }
    }

    /// Takes one accepted step towards `end` (s): locates the earliest mode switch inside it
    /// (and the earliest event `external(system, modes, t0, t1, dense)` reports, as `(time,
    /// id)`), refines
    /// the peaks of the open events, emits the samples and the impacts of the step to `sink`
    /// and applies the switch.
    pub fn step(
        &mut self,
        end: f64,
        sink: &mut impl Sink,
        external: &mut impl FnMut(
            &System,
            &[Option<Engagement>],
            f64,
            f64,
            &Dense,
        ) -> Option<(f64, usize)>,
    ) -> Result<Switch, EngineError> {
        let t = self.t;
        self.step_modes.clone_from(&self.modes);
        // The located onsets of the events opened since the last step: their first contact
        // samples (after the grid samples up to `t`, sent by the last step).
        for (i, tr) in self.tracks.iter_mut().enumerate() {
            if std::mem::take(&mut tr.onset_pending) {
                sink.contact(i, t, &self.sys, &self.y, &self.modes[i]);
                tr.last_contact_t = t;
            }
        }
        let (err, h, free) = loop {
            // the step the controller wants, and the one taken (cut short by `end`)
            let free = self.h.min(self.max_step);
            let h = free.min(end - t);
            if h < 1e-15 * t.max(1.0) && end - t > 1e-15 * t.max(1.0) {
                return Err(EngineError::Diverged {
                    t_s: t,
                    reason: format!("the step size collapsed to {h:e} s"),
                });
            }
            let (sys, modes) = (&self.sys, &self.modes);
            let mut f = |tt: f64, yy: &[f64], out: &mut [f64]| sys.rhs(tt, yy, modes, out);
            let err = self
                .solver
                .try_step(&mut f, t, &self.y, h, &self.atol, self.tol);
            self.stats.rhs_evals += 6;
            if !err.is_finite() || self.solver.y_new.iter().any(|v| !v.is_finite()) {
                if h > 1e-14 {
                    self.h = h * 0.1;
                    self.stats.rejected_steps += 1;
                    continue;
                }
                return Err(EngineError::Diverged {
                    t_s: t,
                    reason: "the state became non-finite".into(),
                });
            }
            if err > 1.0 {
                self.stats.rejected_steps += 1;
                self.h = next_step(h, err);
                continue;
            }
            break (err, h, free);
        };
        // Accepted: build the dense output of [t, t + h].
        std::mem::swap(&mut self.prev, &mut self.cur);
        self.solver.dense_into(t, &self.y, h, &mut self.cur);
        // A step cut short by `end` lands on it exactly (`t + (end - t)` may round an ulp
        // short, which would leave a step of 1e-18 s), and does not shrink the steps after it
        // (a driven session's step ends at a communication point where an input changed).
        let cut = h < free;
        let t_end = if cut { end } else { t + h };
        let sys = &self.sys;
        let cur = &self.cur;
        let buf = &mut self.buf;

        // Earliest mode switch inside the step (probes at quarter points catch grazing
        // contacts that enter and leave within a step).
        let mut event: Option<(f64, usize)> = None;
        // the state at the quarter points, evaluated once for every slot
        let n = buf.len();
        let quarters = &mut self.quarters;
        quarters.resize(3 * n, 0.0);
        for q in 1..=3 {
            cur.eval(t + h * q as f64 / 4.0, &mut quarters[(q - 1) * n..q * n]);
        }
        for i in 0..sys.ids.len() {
            let engaged = self.modes[i].is_some();
            let triggered = |yy: &[f64]| {
                let g = sys.depth(i, yy);
                if engaged {
                    g <= 0.0
                } else {
                    g > 0.0
                }
            };
            let mut ta = t;
            let mut found = None;
            for q in 1..=4 {
                let (tq, yq) = if q == 4 {
                    (t_end, &self.solver.y_new[..])
                } else {
                    (t + h * q as f64 / 4.0, &quarters[(q - 1) * n..q * n])
                };
                if triggered(yq) {
                    found = Some((ta, tq));
                    break;
                }
                ta = tq;
            }
            if let Some((mut a, mut b)) = found {
                // Bisection: `a` not triggered, `b` triggered.
                while b - a > 1e-13 {
                    let m = 0.5 * (a + b);
                    cur.eval(m, buf);
                    if triggered(buf) {
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
        let mut ext = None;
        if let Some((te, id)) = external(sys, &self.modes, t, t_end, cur) {
            if event.is_none_or(|(ti, _)| te < ti) {
                event = None;
                ext = Some((te, id));
            }
        }
        let t_new = event
            .map(|(te, _)| te)
            .or(ext.map(|(te, _)| te))
            .unwrap_or(t_end);
        if event.is_some() || ext.is_some() {
            cur.eval(t_new, &mut self.y_new);
        } else {
            self.y_new.copy_from_slice(&self.solver.y_new);
        }

        // Peaks of the open contact events.
        for i in 0..sys.ids.len() {
            if self.modes[i].is_none() {
                continue;
            }
            let f_new = sys.load(i, &self.y_new, &self.modes[i]);
            let tr = &mut self.tracks[i];
            if f_new.abs() < tr.last_abs && tr.rising {
                // The peak lies in the last two steps: golden-section search.
                let prev = &self.prev;
                let lo = if prev.h > 0.0 {
                    prev.t0.max(tr.t_on)
                } else {
                    cur.t0
                };
                let mode = &self.modes[i];
                let (tp, fp) = golden_peak(lo, t_new, |tt| {
                    eval2(prev, cur, tt, buf);
                    sys.load(i, buf, mode)
                });
                tr.tracker.observe(tp, fp);
                tr.rising = false;
                // The steps around the peak: the last step's end if the thinning skipped it
                // (before this step's grid samples, so in time order) and this step's end.
                if t > tr.last_contact_t {
                    sink.contact(i, t, sys, &self.y, mode);
                    tr.last_contact_t = t;
                }
                tr.contact_due = true;
            } else if f_new.abs() >= tr.last_abs {
                tr.rising = true;
            }
            tr.tracker.observe(t_new, f_new);
            tr.last_abs = f_new.abs();
        }

        // Samples on the output grid inside (t, t_new].
        let rate = self.rate;
        while self.next_sample as f64 / rate <= t_new {
            let ts = self.next_sample as f64 / rate;
            if ts < t {
                // only the very first sample (t = 0) can fall here
                sink.sample(self.next_sample, ts, sys, &self.y, &self.modes);
            } else {
                cur.eval(ts, buf);
                sink.sample(self.next_sample, ts, sys, buf, &self.modes);
            }
            self.next_sample += 1;
        }
        // Contact samples at the step's end for the discs in contact along it, every
        // CONTACT_SAMPLE_EVERY-th step and the step that ends on a separation (its end is the
        // located `t_off`).
        for i in 0..sys.ids.len() {
            if self.modes[i].is_some() {
                let tr = &mut self.tracks[i];
                tr.contact_steps += 1;
                let closes = event.is_some_and(|(_, j)| j == i);
                let due = std::mem::take(&mut tr.contact_due);
                if closes || due || tr.contact_steps.is_multiple_of(CONTACT_SAMPLE_EVERY) {
                    sink.contact(i, t_new, sys, &self.y_new, &self.modes[i]);
                    tr.last_contact_t = t_new;
                }
            }
        }

        self.stats.steps += 1;
        self.t = t_new;
        self.y.copy_from_slice(&self.y_new);
        let switch = if let Some((te, i)) = event {
            if self.modes[i].is_some() {
                self.modes[i] = None;
                if let Some(e) = self.tracks[i].tracker.end(te) {
                    sink.impact(e);
                }
                Switch::Separated(i)
            } else {
                self.engage(i, te);
                Switch::Engaged(i)
            }
        } else if let Some((_, id)) = ext {
            Switch::External(id)
        } else {
            Switch::None
        };
        match switch {
            Switch::None => self.solver.accept(),
            // the caller restarts after changing the system
            Switch::External(_) => {}
            _ => self.restart(),
        }
        self.h = if cut {
            next_step(h, err).max(free)
        } else {
            next_step(h, err)
        };
        self.stats.simulated_s = self.t;
        if self.stats.steps.is_multiple_of(STALL_BLOCK) {
            if self.t - self.block_t0 < STALL_SPAN_S {
                return Err(EngineError::Diverged {
                    t_s: self.t,
                    reason: format!(
                        "{STALL_BLOCK} steps advanced only {:.3e} s: the contact is stiffer than \
                         the engine can integrate (check the contact and oil values)",
                        self.t - self.block_t0
                    ),
                });
            }
            self.block_t0 = self.t;
        }
        Ok(switch)
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

/// Maximises `|f|` on `[a, b]` by golden-section search (f unimodal in |f|); returns the
/// argument and the signed value. 60 iterations shrink the bracket by 0.618^60 ~ 3e-13.
pub(crate) fn golden_peak(mut a: f64, mut b: f64, mut f: impl FnMut(f64) -> f64) -> (f64, f64) {
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
