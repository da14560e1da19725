//! The multirate scheme for an open whole pack (crate docs, "Whole packs"): friction discs on
//! a prescribed shaft and separator plates on the housing, the piston never clamping. Each
//! body is its own ODE with its own steps and events; the only coupling, the open gaps'
//! Couette drag between stack neighbours, is relaxed window by window (Gauss-Seidel waveform
//! relaxation over the two colours of the stack) until what it still changes in any body's
//! speed is within the allowance the crate docs state.

use crate::gaps::{Gaps, Neighbour, Track};
use crate::independent::{hold_in_runs, want_contacts, DiscRun, Merger};
use crate::session::Clock;
use crate::system::System;
use crate::{no_external, ReferenceOptions};
use clutchpack_model::session::{Advance, Driven, Inputs, Session, Snapshot};
use clutchpack_model::{
    Engagement, EngineError, InterfaceSample, Observer, PackModel, RunStats, Sample, Shaft,
    StackBody,
};
use rayon::prelude::*;
use std::sync::Arc;

/// Length of a relaxation window in simulated time, s. The gaps' drag couples a disc to its
/// plates with a rate `c / J` of about 0.5 1/s (the shipped packs), so within 1 ms a change
/// of a neighbour's speed moves a body's speed by about 5e-4 of it: one Gauss-Seidel sweep
/// shrinks the coupling's error about 2e3-fold. Longer windows would need more sweeps; shorter
/// ones cut more steps at their ends (each body's last step in a window ends on it).
const WINDOW_S: f64 = 1e-3;

/// Most sweeps a window may take before the run fails (each sweep shrinks the coupling's
/// error about 2e3-fold, so a window that needs this many is not an open pack's).
const MAX_SWEEPS: u32 = 12;

/// Whether the open-pack multirate scheme can run `pack` driven by `driven`: a whole pack on
/// a prescribed shaft, no drum, a stack whose piston never clamps (and is not driven), every
/// stack position filled.
pub(crate) fn runs_open(pack: &PackModel, driven: &Driven) -> bool {
    let nd = pack.discs.len();
    matches!(pack.shaft, Shaft::Prescribed(_))
        && pack.drum.is_none()
        && nd > 0
        && pack.plates.len() == nd + 1
        && pack.stack.as_ref().is_some_and(|s| !s.piston.can_clamp())
        && !driven.piston_pressure
}

/// `r` set to `saved` (a body's state at a window's start) and restarted with `gaps` (its
/// gaps seeing new inputs), into `r`'s own buffers.
fn restart_from(r: &mut DiscRun, saved: &DiscRun, gaps: Gaps) {
    r.clone_from(saved);
    r.stepper.sys.gaps = Some(gaps);
    r.stepper.restart();
}

/// Advances `r` until its time reaches `t` (s), its steps ending at `end` (s), recording its
/// steps' relative speed in its track.
fn advance(r: &mut DiscRun, t: f64, end: f64) {
    while r.error.is_none() && r.stepper.t < t {
        match r.stepper.step(end, &mut r.out, &mut no_external) {
            Ok(_) => {
                let (st, psi) = (&r.stepper, r.stepper.sys.off + 1);
                r.track.push(&st.cur, psi, st.t);
            }
            Err(e) => r.error = Some(e),
        }
    }
}

/// The open-pack multirate scheme as a session.
#[derive(Clone)]
pub(crate) struct OpenSession {
    /// The bodies in the engines' order: the discs, then the plates.
    runs: Vec<DiscRun>,
    /// The body at each stack position (plate 0, disc 0, plate 1, ...).
    at: Vec<usize>,
    /// The bodies relaxed first (the discs: odd positions) and second (the plates).
    first: Vec<usize>,
    second: Vec<usize>,
    pack: Arc<PackModel>,
    parallel: bool,
    clock: Clock,
    tol: f64,
    /// Time every body has reached (the end of the last window), s.
    t_w: f64,
    merger: Merger,
    /// Couette coefficient of one gap, N m s/rad, and the faces' `R_eff`, m.
    c_gap: f64,
    r_eff: f64,
    /// The last window: every body's state at its start (to find the state at a time inside
    /// it, [`Self::state_at`]).
    last: Option<Arc<LastWindow>>,
    /// What a window reuses instead of allocating (issue 46: no allocation in a host's frame
    /// loop once started).
    scratch: Scratch,
}

/// The buffers a window reuses: each holds what it held at the last window, overwritten.
#[derive(Default)]
struct Scratch {
    /// Every body's state at the window's start (then kept as the last window's, whose old
    /// buffers come back here).
    saved: Vec<DiscRun>,
    /// Each body's speed through the window as its neighbours' gaps see it.
    seen: Vec<Neighbour>,
    /// The bodies of each colour to run again.
    redo: [Vec<usize>; 2],
    /// Each body's tracks published to its neighbours (a track still seen by a neighbour's
    /// gaps or by the last window's saved state is shared, the others are reused).
    tracks: Vec<Vec<Arc<Track>>>,
}

/// A copy of a session starts its own buffers (the kept tracks shared between two sessions
/// would never be free for either).
impl Clone for Scratch {
    fn clone(&self) -> Self {
        Scratch {
            tracks: vec![Vec::new(); self.tracks.len()],
            ..Scratch::default()
        }
    }
}

/// Most tracks a body keeps for reuse (each pass publishes one; the neighbours' gaps, the
/// `seen` speeds and the last window's saved states hold at most a few at once).
const KEPT_TRACKS: usize = 8;

/// Where the last window started from: every body's state (its last pass's inputs are in
/// its gaps) and the window's end, s.
struct LastWindow {
    saved: Vec<DiscRun>,
    t1: f64,
}

impl OpenSession {
    pub fn new(
        pack: Arc<PackModel>,
        settings: &ReferenceOptions,
        parallel: bool,
        driven: Driven,
    ) -> Self {
        let nd = pack.discs.len();
        let n = nd + pack.plates.len();
        let runs = (0..n)
            .map(|id| DiscRun::new(System::open_body(pack.clone(), id), settings))
            .collect();
        let at: Vec<usize> = (0..n).map(|p| StackBody::at(p).body_index(nd)).collect();
        let (first, second) = (0..n).partition(|&b| b < nd);
        let c_gap = pack
            .stack
            .as_ref()
            .map_or(0.0, |s| -s.open_gap_torque_n_m(1.0));
        let r_eff = pack.stack.as_ref().map_or(0.0, |s| s.effective_radius_m());
        OpenSession {
            runs,
            at,
            first,
            second,
            pack,
            parallel,
            clock: Clock::new(driven),
            tol: settings.tolerance,
            t_w: 0.0,
            merger: Merger::new(settings.record_rate_hz, n),
            c_gap,
            r_eff,
            last: None,
            scratch: Scratch {
                tracks: vec![Vec::new(); n],
                ..Scratch::default()
            },
        }
    }

    /// The stack position of body `b`.
    fn position(&self, b: usize) -> usize {
        self.at.iter().position(|&x| x == b).expect("a stack body")
    }

    /// The neighbours of body `b` (below, above; `None` at the stack's ends).
    fn neighbours(&self, b: usize) -> [Option<usize>; 2] {
        let p = self.position(b);
        [
            p.checked_sub(1).map(|q| self.at[q]),
            self.at.get(p + 1).copied(),
        ]
    }

    /// Whether body `b` is carried by the shaft (a disc) rather than the housing.
    fn on_shaft(&self, b: usize) -> bool {
        b < self.pack.discs.len()
    }

    /// Speed of body `b` at its stepper's time, rad/s.
    fn speed(&self, b: usize) -> f64 {
        let st = &self.runs[b].stepper;
        let w_c = if self.on_shaft(b) {
            st.sys.shaft(st.t, &[]).1
        } else {
            0.0
        };
        w_c - st.y[st.sys.off + 1]
    }

    /// Body `b` at its stepper's time: its speed (rad/s), its acceleration (rad/s^2) and
    /// whether it flies free (no tooth in contact).
    fn motion(&self, b: usize) -> (f64, f64, bool) {
        let st = &self.runs[b].stepper;
        let (t, k) = (st.t, st.sys.off + 1);
        // an open body's state: its relative angle and speed, its gaps' work, the teeth's work
        let mut dy = [0.0; 8];
        let dy = &mut dy[..st.y.len()];
        st.sys.rhs(t, &st.y, &st.modes, dy);
        let a_c = if self.on_shaft(b) {
            st.sys.carriers(t, &st.y, &st.modes)[1]
        } else {
            0.0
        };
        (self.speed(b), a_c - dy[k], st.modes[0].is_none())
    }

    /// The first pass's predictions of the bodies' speeds through the window starting at the
    /// steppers' time: a body in free flight (a plate pushed by its gaps' drag) moving on with
    /// its acceleration; a body in contact at its speed, held. (Adding the jerk its gaps give
    /// it as its neighbours accelerate changed no window's outcome on pack-8-brake: its
    /// plates' errors come from their own contacts.)
    fn predict(&self, seen: &mut Vec<Neighbour>) {
        seen.clear();
        seen.extend((0..self.runs.len()).map(|b| {
            let (omega, alpha, free) = self.motion(b);
            Neighbour::Predicted {
                t0: self.runs[b].stepper.t,
                omega,
                alpha: if free { alpha } else { 0.0 },
            }
        }));
    }

    /// Runs the bodies `group` from the window's start to `t1` (s) against the neighbours'
    /// speeds `seen` (by body), each from its saved state at the window's start.
    fn pass(&mut self, group: &[usize], seen: &[Neighbour], saved: &[DiscRun], t1: f64) {
        for &b in group {
            let gaps = self.gaps_seeing(b, seen);
            restart_from(&mut self.runs[b], &saved[b], gaps);
        }
        let run = |(b, r): (usize, &mut DiscRun)| {
            if group.contains(&b) {
                r.track.clear();
                advance(r, t1, t1);
            }
        };
        if self.parallel && group.len() > 1 {
            self.runs.par_iter_mut().enumerate().for_each(run);
        } else {
            self.runs.iter_mut().enumerate().for_each(run);
        }
    }

    /// The gaps of body `b` seeing its neighbours' speeds `seen` (by body).
    fn gaps_seeing(&self, b: usize, seen: &[Neighbour]) -> Gaps {
        let [lo, hi] = self.neighbours(b);
        Gaps {
            c: self.c_gap,
            below: lo.map(|q| seen[q].clone()),
            above: hi.map(|q| seen[q].clone()),
        }
    }

    /// The state of body `b` at `t` (s) into `y` and its contact modes there, `t` at or before
    /// its time and inside the last window: from its last steps, or (further back) from a
    /// rerun of the window's last pass, which takes the same steps.
    fn state_at(&self, b: usize, t: f64, y: &mut Vec<f64>) -> Vec<Option<Engagement>> {
        let st = &self.runs[b].stepper;
        match (&self.last, st.remembers(t)) {
            (Some(last), false) => {
                let gaps = st.sys.gaps.clone().expect("an open body");
                let mut r = last.saved[b].clone();
                restart_from(&mut r, &last.saved[b], gaps);
                r.out.wants_contacts = false;
                advance(&mut r, t, last.t1);
                r.stepper.state_at(t, y).to_vec()
            }
            _ => st.state_at(t, y).to_vec(),
        }
    }

    /// The bodies' tracks of their last pass as neighbours' inputs, each copied into one of
    /// the body's kept tracks that nothing sees any more (a new one if none is free).
    fn tracks(&mut self, group: &[usize], seen: &mut [Neighbour]) {
        for &b in group {
            let kept = &mut self.scratch.tracks[b];
            let track = &self.runs[b].track;
            let free = kept.iter_mut().position(|k| Arc::get_mut(k).is_some());
            let psi = match free {
                Some(i) => {
                    Arc::get_mut(&mut kept[i])
                        .expect("unshared")
                        .clone_from(track);
                    kept[i].clone()
                }
                None => {
                    let k = Arc::new(track.clone());
                    if kept.len() < KEPT_TRACKS {
                        kept.push(k.clone());
                    }
                    k
                }
            };
            seen[b] = Neighbour::track(psi, self.on_shaft(b));
        }
    }

    /// How much the neighbours' latest passes `seen` differ from what body `b`'s last pass
    /// saw, against what it is allowed: `c sum integral |d omega| dt / J` (rad/s; the change
    /// of its speed in free flight) over `tol (1 + |omega|)` (a relative tolerance on its
    /// speed) per step it took in the window. At most 1: its pass stands.
    fn unsettled(&self, b: usize, seen: &[Neighbour]) -> f64 {
        let r = &self.runs[b];
        let gaps = r.stepper.sys.gaps.as_ref().expect("an open body");
        let mut moved = 0.0;
        for (q, used) in self
            .neighbours(b)
            .into_iter()
            .zip([&gaps.below, &gaps.above])
        {
            if let (Some(q), Some(used)) = (q, used) {
                if let Neighbour::Track { psi, .. } = &seen[q] {
                    if !matches!(used, Neighbour::Track { psi: p, .. } if Arc::ptr_eq(p, psi)) {
                        moved += used.change(psi);
                    }
                }
            }
        }
        let j = r.stepper.sys.disc(0).inertia_kg_m2;
        let allowed = self.tol * (1.0 + self.speed(b).abs());
        self.c_gap * moved / j / (allowed * r.track.len().max(1) as f64)
    }

    /// One window `[t_w, t1]` (Gauss-Seidel waveform relaxation over the stack's two colours):
    /// the discs against their plates' predicted speeds, the plates against the discs' passes;
    /// then each disc whose plates moved more than the tolerance allows
    /// ([`Self::unsettled`]) again against the plates' last passes, and its plates again,
    /// until every pass stands.
    fn window(&mut self, t1: f64) -> Result<(), EngineError> {
        let mut saved = std::mem::take(&mut self.scratch.saved);
        saved.clone_from(&self.runs);
        let mut seen = std::mem::take(&mut self.scratch.seen);
        let mut redo = std::mem::take(&mut self.scratch.redo);
        let relaxed = self.relax(&saved, &mut seen, &mut redo, t1);
        self.scratch.seen = seen;
        self.scratch.redo = redo;
        if let Err(e) = relaxed {
            self.scratch.saved = saved;
            return Err(e);
        }
        self.t_w = t1;
        // the saved states become the last window's, whose buffers are reused next window
        // (unless a copy of the session shares them)
        match self.last.as_mut().and_then(Arc::get_mut) {
            Some(last) => {
                std::mem::swap(&mut last.saved, &mut saved);
                last.t1 = t1;
                self.scratch.saved = saved;
            }
            None => self.last = Some(Arc::new(LastWindow { saved, t1 })),
        }
        Ok(())
    }

    /// The sweeps of [`Self::window`] from the bodies' states `saved` at its start to `t1`
    /// (s), with the neighbours' speeds in `seen` and the bodies to run again in `redo`.
    fn relax(
        &mut self,
        saved: &[DiscRun],
        seen: &mut Vec<Neighbour>,
        redo: &mut [Vec<usize>; 2],
        t1: f64,
    ) -> Result<(), EngineError> {
        self.predict(seen);
        let [redo_first, redo_second] = redo;
        redo_first.clone_from(&self.first);
        redo_second.clone_from(&self.second);
        let mut sweeps = 0;
        loop {
            self.pass(redo_first, seen, saved, t1);
            self.tracks(redo_first, seen);
            self.pass(redo_second, seen, saved, t1);
            self.tracks(redo_second, seen);
            if let Some(e) = self.runs.iter().find_map(|r| r.error.clone()) {
                return Err(e);
            }
            sweeps += 1;
            // the discs to run again, and the one furthest from settled
            redo_first.clear();
            let mut worst = (0, 0.0);
            for &b in &self.first {
                let u = self.unsettled(b, seen);
                if u > worst.1 {
                    worst = (b, u);
                }
                if u > 1.0 {
                    redo_first.push(b);
                }
            }
            if redo_first.is_empty() {
                break;
            }
            if sweeps >= MAX_SWEEPS {
                return Err(EngineError::Diverged {
                    t_s: self.t_w,
                    reason: format!(
                        "the open gaps' drag did not converge in {MAX_SWEEPS} sweeps of the \
                         window [{}, {t1}] s (body {} still {:.2e} times the tolerance)",
                        self.t_w, worst.0, worst.1
                    ),
                });
            }
            redo_second.clear();
            for &q in &self.second {
                if self
                    .neighbours(q)
                    .iter()
                    .flatten()
                    .any(|b| redo_first.contains(b))
                {
                    redo_second.push(q);
                }
            }
        }
        Ok(())
    }

    /// Ends the last window at the session's time, before an input changes (a driven session
    /// whose window passed its time): every body back at the window's start (its saved
    /// state), the window run again to the session's time, what it gives again (sent before)
    /// dropped with everything the bodies and the merge held past the session's time.
    fn rewind(&mut self) -> Result<(), EngineError> {
        let t = self.clock.t;
        if self.t_w <= t {
            return Ok(());
        }
        let Some(last) = self.last.clone() else {
            return Ok(());
        };
        self.merger.drop_after(t);
        // the contact samples up to `t` still to be sent (they wait for the next sample)
        let waiting: Vec<_> = self
            .runs
            .iter_mut()
            .map(|r| {
                let mut c = std::mem::take(&mut r.out.contacts);
                c.retain(|&(tc, _)| tc <= t);
                c
            })
            .collect();
        let wants = self.runs.first().is_some_and(|r| r.out.wants_contacts);
        for (r, s) in self.runs.iter_mut().zip(&last.saved) {
            r.clone_from(s);
            r.out.wants_contacts = false;
        }
        self.t_w = self.runs.first().map_or(t, |r| r.stepper.t);
        drop(last);
        let done = if self.t_w < t { self.window(t) } else { Ok(()) };
        for (r, c) in self.runs.iter_mut().zip(waiting) {
            r.out.samples.clear();
            r.out.impacts.clear();
            r.out.contacts = c;
            r.out.wants_contacts = wants;
        }
        done
    }

    /// Sends the output up to `limit` (s): the bodies' samples, each followed by the gaps'.
    fn merge(&mut self, limit: f64, obs: &mut dyn Observer) {
        let (at, c, r_eff) = (&self.at, self.c_gap, self.r_eff);
        let whole = limit >= self.t_w;
        self.merger
            .merge(&mut self.runs, limit, whole, obs, &|s, w, out| {
                gap_samples(at, c, r_eff, s, w, out);
                true
            });
    }
}

/// The open gaps of a merged sample `s` (bodies at stack positions `at`; each gap's Couette
/// coefficient `c`, N m s/rad, faces' `R_eff` m): each one's slip, torque on the body above and
/// the heat it has made, `-(work on the body below + work on the body above)` from the bodies'
/// gap work `works` (J, below and above; MODEL.md section 5); into `out` (cleared first).
fn gap_samples(
    at: &[usize],
    c: f64,
    r_eff: f64,
    s: &Sample,
    works: &[[f64; 2]],
    out: &mut Vec<InterfaceSample>,
) {
    out.clear();
    out.extend(at.windows(2).map(|w| {
        let (lo, hi) = (w[0], w[1]);
        let slip = s.discs[hi].speed_rad_s - s.discs[lo].speed_rad_s;
        InterfaceSample {
            slip_rad_s: slip,
            slip_m_s: slip * r_eff,
            mu: 0.0,
            clamp_n: 0.0,
            torque_n_m: -c * slip,
            locked: false,
            dissipated_j: -(works[lo][1] + works[hi][0]),
        }
    }));
}

impl Session for OpenSession {
    fn time_s(&self) -> f64 {
        self.clock.t
    }

    fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), EngineError> {
        if let Err(e) = self.rewind() {
            self.clock.failed = true;
            return Err(e);
        }
        self.pack = hold_in_runs(&self.clock, &self.pack, &mut self.runs, inputs)?;
        Ok(())
    }

    fn set_stop_time(&mut self, t_s: f64) {
        self.clock.stop = t_s;
    }

    fn advance_to(&mut self, t: f64, obs: &mut dyn Observer) -> Result<Advance, EngineError> {
        self.clock.check_advance(t)?;
        want_contacts(&mut self.runs, obs);
        let end = self.clock.step_end(t);
        while self.t_w < t {
            // windows on a fixed grid (a run split into calls takes the same steps, driven or
            // not; a window past the call's end is run again to it should an input change)
            let k = (self.t_w / WINDOW_S + 1e-9).floor() + 1.0;
            let t1 = (k * WINDOW_S).min(end);
            if let Err(e) = self.window(t1) {
                self.clock.failed = true;
                // deliver what came before the window that failed
                let before = self.t_w;
                self.runs.iter_mut().for_each(|r| r.error = None);
                self.merge(before, obs);
                return Err(e);
            }
            self.merge(self.t_w.min(t), obs);
            if obs.progress(self.t_w.min(t)) {
                self.clock.t = self.t_w.min(t);
                return Ok(Advance::Stopped);
            }
        }
        self.merge(t, obs);
        self.clock.t = t;
        Ok(Advance::Reached)
    }

    fn snapshot(&self) -> Snapshot {
        let t = self.clock.t;
        let mut y = Vec::new();
        let mut sample = Sample {
            t_s: t,
            discs: Vec::with_capacity(self.runs.len()),
            ..Sample::default()
        };
        let mut works = Vec::with_capacity(self.runs.len());
        for (b, r) in self.runs.iter().enumerate() {
            let modes = self.state_at(b, t, &mut y);
            sample
                .discs
                .push(r.stepper.sys.disc_sample(t, 0, &y, &modes[0]));
            works.push(r.stepper.sys.gap_work_j(&y));
        }
        (sample.shaft_angle_rad, sample.shaft_speed_rad_s) = self.runs[0].stepper.sys.shaft(t, &[]);
        let mut interfaces = Vec::new();
        gap_samples(
            &self.at,
            self.c_gap,
            self.r_eff,
            &sample,
            &works,
            &mut interfaces,
        );
        Snapshot {
            interfaces,
            sample,
            drum: None,
        }
    }

    fn finish(&mut self, obs: &mut dyn Observer) -> RunStats {
        let mut stats = self.merger.finish(&mut self.runs, obs);
        stats.simulated_s = self.clock.t;
        stats
    }

    fn boxed_clone(&self) -> Box<dyn Session> {
        Box::new(self.clone())
    }
}
