//! The multirate scheme on a prescribed shaft: every disc an independent ODE with its own
//! steps and events, advanced window by window (in parallel when asked) and merged into one
//! time-ordered stream of samples and impacts (crate docs, Theory).

use crate::gaps::Track;
use crate::session::{keep, shift_disc_speeds, Clock};
use crate::stepper::{Sink, Stepper};
use crate::system::System;
use crate::{no_external, ReferenceOptions};
use clutchpack_model::session::{Advance, Driven, Inputs, Session, Snapshot};
use clutchpack_model::{
    DiscSample, Engagement, EngineError, ImpactEvent, InterfaceSample, Observer, PackModel,
    RunStats, Sample,
};
use rayon::prelude::*;
use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

/// One disc's output not yet merged.
#[derive(Default)]
pub(crate) struct Buffer {
    /// `(sample number, the disc's sample, the work of its gaps below and above in J (0
    /// without gaps))` in order.
    pub(crate) samples: VecDeque<(u64, DiscSample, [f64; 2])>,
    /// Impacts in the order they closed.
    pub(crate) impacts: Vec<ImpactEvent>,
    /// `(t s, the disc's state)` of its contact samples, in order.
    pub(crate) contacts: VecDeque<(f64, DiscSample)>,
    /// Whether the observer takes contact samples (else none are kept).
    pub wants_contacts: bool,
}

clone_reusing!(Buffer {
    samples,
    impacts,
    contacts,
    wants_contacts
});

impl Sink for Buffer {
    fn sample(&mut self, k: u64, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]) {
        let work = match sys.gaps {
            Some(_) => sys.gap_work_j(y),
            None => [0.0; 2],
        };
        self.samples
            .push_back((k, sys.disc_sample(t, 0, y, &modes[0]), work));
    }
    fn impact(&mut self, e: ImpactEvent) {
        self.impacts.push(e);
    }
    fn contact(&mut self, slot: usize, t: f64, sys: &System, y: &[f64], mode: &Option<Engagement>) {
        if !self.wants_contacts {
            return;
        }
        self.contacts
            .push_back((t, sys.disc_sample(t, slot, y, mode)));
    }
}

/// Sends the contact samples of every disc up to `t` (s) inclusive, disc by disc (each in
/// time order; `Observer::contact_sample`).
fn send_contacts(runs: &mut [DiscRun], t: f64, obs: &mut dyn Observer) {
    for (i, r) in runs.iter_mut().enumerate() {
        while let Some((tc, _)) = r.out.contacts.front() {
            if *tc > t {
                break;
            }
            let (tc, d) = r.out.contacts.pop_front().expect("a front");
            obs.contact_sample(i, tc, &d);
        }
    }
}

/// One body's integration and its unmerged output.
pub(crate) struct DiscRun {
    pub stepper: Stepper,
    pub out: Buffer,
    pub error: Option<EngineError>,
    /// Its relative speed through the current window (the open-pack scheme; empty else).
    pub track: Track,
}

clone_reusing!(DiscRun {
    stepper,
    out,
    error,
    track
});

impl DiscRun {
    /// A run of `sys` from t = 0.
    pub fn new(sys: System, settings: &ReferenceOptions) -> DiscRun {
        DiscRun {
            stepper: Stepper::new(sys, settings),
            out: Buffer::default(),
            error: None,
            track: Track::default(),
        }
    }

    /// Integrates until the disc's time reaches `t_w` (s), its steps ending at `end` (s), or
    /// until the wall clock passes `deadline` (so that a stop request is seen even when the
    /// steps become very small). With `saved`, a copy of the integration goes there before a
    /// step that may pass `call_end` (s), the call's end (`crate::session::keep`).
    fn advance(
        &mut self,
        t_w: f64,
        end: f64,
        deadline: Instant,
        saved: Option<&mut Option<Box<Stepper>>>,
        call_end: f64,
    ) {
        let mut n: u32 = 0;
        let mut saved = saved;
        while self.error.is_none() && self.stepper.t < t_w {
            if let Some(slot) = saved.as_deref_mut() {
                if self.stepper.may_pass(call_end) {
                    keep(slot, &self.stepper);
                }
            }
            if let Err(e) = self.stepper.step(end, &mut self.out, &mut no_external) {
                self.error = Some(e);
            }
            n = n.wrapping_add(1);
            if n.is_multiple_of(256) && Instant::now() > deadline {
                break;
            }
        }
    }
}

/// Wall time a window aims at, s: long enough that the per-window overhead (a rayon
/// dispatch, the merge) is small, short enough that a stop request acts within 0.5 s.
const WINDOW_WALL_MIN_S: f64 = 0.02;
const WINDOW_WALL_MAX_S: f64 = 0.1;
/// Wall time after which a window is cut short, s.
const WINDOW_WALL_CUT_S: f64 = 0.25;
/// Most disc samples, record-rate and contact samples together, buffered per window (about
/// 60 bytes each: 240 kB, which a core's caches hold, so the merge reads them from cache;
/// and memory that does not grow with a run's density of contacts). A window is checked
/// after it ran, so one disc's buffer may briefly hold up to about this many. With 2e4 the
/// buffers of a 4-disc recorded run held about 0.5 MB per disc once a dense window had come,
/// which a 300 s run met and a 3 s run did not.
const MAX_BUFFERED_SAMPLES: f64 = 4e3;

/// The multirate scheme on a prescribed shaft as a session: the discs' integrations and the
/// merge's state between calls.
#[derive(Clone)]
pub(crate) struct IndependentSession {
    runs: Vec<DiscRun>,
    pack: Arc<PackModel>,
    parallel: bool,
    clock: Clock,
    /// Window length in simulated time, s, and its upper bound.
    window: f64,
    cap: f64,
    /// Time every disc has reached and whose output has been merged, s.
    t_w: f64,
    merger: Merger,
    /// A driven session's integration of each disc before its last step that may pass a
    /// call's end (`crate::session::keep`; `IndependentSession::rewind`).
    saved: Vec<Option<Box<Stepper>>>,
}

impl IndependentSession {
    pub fn new(
        pack: Arc<PackModel>,
        settings: &ReferenceOptions,
        parallel: bool,
        driven: Driven,
    ) -> Self {
        let nd = pack.discs.len();
        let runs = (0..nd)
            .map(|i| DiscRun::new(System::new(pack.clone(), vec![i]), settings))
            .collect();
        let rate = settings.record_rate_hz;
        let cap = (MAX_BUFFERED_SAMPLES / (rate * nd as f64)).max(2.0 / rate);
        IndependentSession {
            runs,
            pack,
            parallel,
            clock: Clock::new(driven),
            window: (1e-3f64).min(cap),
            cap,
            t_w: 0.0,
            merger: Merger::new(rate, nd),
            saved: vec![None; nd],
        }
    }

    /// Runs the discs through one window ending at most at `target` (s), their steps ending
    /// at `end`, and sends what the window completed; returns the error of the earliest disc
    /// that failed.
    /// A driven session keeps each disc's integration before a step that may pass
    /// `call_end` (s), the call's end.
    fn window(
        &mut self,
        target: f64,
        end: f64,
        call_end: f64,
        obs: &mut dyn Observer,
    ) -> Result<(), EngineError> {
        let runs = &mut self.runs;
        let wall = Instant::now();
        let deadline = wall + std::time::Duration::from_secs_f64(WINDOW_WALL_CUT_S);
        let keeps = self.clock.keeps() && end > call_end;
        let saved = &mut self.saved;
        let run = |(r, s): (&mut DiscRun, &mut Option<Box<Stepper>>)| {
            r.advance(target, end, deadline, keeps.then_some(s), call_end)
        };
        if self.parallel {
            runs.par_iter_mut().zip(saved.par_iter_mut()).for_each(run);
        } else {
            runs.iter_mut().zip(saved.iter_mut()).for_each(run);
        }
        // a window cut short by the deadline ends where the slowest disc got to
        self.t_w = runs
            .iter()
            .filter(|r| r.error.is_none())
            .map(|r| r.stepper.t.min(target))
            .fold(target, f64::min);
        let wall = wall.elapsed().as_secs_f64();
        // what the window left to merge: its samples and, when asked for, its contact
        // samples (about 30 per contact, not bounded by `cap`)
        let buffered = runs
            .iter()
            .map(|r| r.out.samples.len() + r.out.contacts.len())
            .sum::<usize>() as f64;
        if wall > WINDOW_WALL_MAX_S || buffered > MAX_BUFFERED_SAMPLES {
            self.window *= 0.5;
        } else if wall < WINDOW_WALL_MIN_S && 2.0 * buffered <= MAX_BUFFERED_SAMPLES {
            self.window = (2.0 * self.window).min(self.cap);
        }
        // Deliver everything up to `limit`: the window's end, or the last good time of the
        // earliest disc that failed.
        let mut limit = self.t_w;
        let mut failure = None;
        for r in runs.iter() {
            if let (Some(e), true) = (&r.error, r.stepper.t <= limit) {
                limit = r.stepper.t;
                failure = Some(e.clone());
            }
        }
        self.merger.merge(runs, limit, true, obs, &|_, _, _| false);
        match failure {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

impl Session for IndependentSession {
    fn time_s(&self) -> f64 {
        self.clock.t
    }

    fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), EngineError> {
        if let Err(e) = rewind_runs(
            &mut self.runs,
            &mut self.saved,
            &mut self.merger,
            self.clock.t,
        ) {
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
            let target = (self.t_w + self.window).min(t);
            if let Err(e) = self.window(target, end, t, obs) {
                self.clock.failed = true;
                return Err(e);
            }
            if obs.progress(self.t_w) {
                self.clock.t = self.t_w;
                return Ok(Advance::Stopped);
            }
        }
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
        for r in &self.runs {
            let modes = r.stepper.state_at(t, &mut y);
            sample
                .discs
                .push(r.stepper.sys.disc_sample(t, 0, &y, &modes[0]));
        }
        if let Some(r) = self.runs.first() {
            (sample.shaft_angle_rad, sample.shaft_speed_rad_s) = r.stepper.sys.shaft(t, &[]);
        }
        Snapshot {
            sample,
            interfaces: Vec::new(),
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

/// The interface samples of a merged sample from its bodies' samples and their gaps' work (J,
/// below and above, in the bodies' order), written into the buffer given (cleared first);
/// false when the scheme has none.
pub(crate) type InterfacesOf<'a> =
    &'a dyn Fn(&Sample, &[[f64; 2]], &mut Vec<InterfaceSample>) -> bool;

/// The merge of the bodies' separately integrated output into one time-ordered stream.
#[derive(Clone)]
pub(crate) struct Merger {
    rate: f64,
    /// Number of the next merged sample.
    next_k: u64,
    /// Impacts closed but not yet sent, in the order of their end.
    pending: Vec<ImpactEvent>,
    sample: Sample,
    /// Each body's gap work at the sample being merged, J.
    works: Vec<[f64; 2]>,
    /// The interface samples of the sample being merged (kept: no allocation per sample).
    interfaces: Vec<InterfaceSample>,
}

impl Merger {
    /// A merge of `n` bodies sampled at `rate` Hz.
    pub fn new(rate: f64, n: usize) -> Merger {
        Merger {
            rate,
            next_k: 0,
            pending: Vec::new(),
            sample: Sample {
                discs: vec![DiscSample::default(); n],
                ..Sample::default()
            },
            works: vec![[0.0; 2]; n],
            interfaces: Vec::new(),
        }
    }

    /// Sends the samples (each followed by the interfaces `interfaces` makes of it), contact
    /// samples and impacts of `runs` up to `limit` (s) in time order; the contact samples
    /// after the last sample only when `limit_is_window_end` (so that the contact samples of
    /// the bodies interleave alike whatever calls a session took: by sample and by window).
    pub fn merge(
        &mut self,
        runs: &mut [DiscRun],
        limit: f64,
        limit_is_window_end: bool,
        obs: &mut dyn Observer,
        interfaces: InterfacesOf,
    ) {
        for r in runs.iter_mut() {
            self.pending.append(&mut r.out.impacts);
        }
        let pending = &mut self.pending;
        pending.sort_by(|a, b| a.t_off_s.total_cmp(&b.t_off_s).then(a.disc.cmp(&b.disc)));
        let mut next_impact = 0;
        loop {
            let ts = self.next_k as f64 / self.rate;
            // a disc that failed before its first step has no sample at t = 0
            let ready = runs.iter().all(|r| {
                r.out
                    .samples
                    .front()
                    .is_some_and(|&(k, _, _)| k == self.next_k)
            });
            if ts > limit || !ready {
                break;
            }
            while next_impact < pending.len() && pending[next_impact].t_off_s < ts {
                obs.impact(&pending[next_impact]);
                next_impact += 1;
            }
            // each disc's contact samples up to this sample first: one time order per disc
            send_contacts(runs, ts, obs);
            let sample = &mut self.sample;
            sample.t_s = ts;
            // the shaft of the first disc's system: the pack with the inputs held so far
            let shaft = &runs[0].stepper.sys;
            (sample.shaft_angle_rad, sample.shaft_speed_rad_s) = shaft.shaft(ts, &[]);
            for ((r, d), w) in runs
                .iter_mut()
                .zip(sample.discs.iter_mut())
                .zip(self.works.iter_mut())
            {
                if let Some((_, s, work)) = r.out.samples.pop_front() {
                    *d = s;
                    *w = work;
                }
            }
            obs.sample(sample);
            if interfaces(sample, &self.works, &mut self.interfaces) {
                obs.interfaces(ts, &self.interfaces);
            }
            self.next_k += 1;
        }
        // the contact samples before the next sample (which the next window sends), when the
        // bodies' output is complete up to `limit`
        if limit_is_window_end {
            send_contacts(
                runs,
                limit.min(self.next_k as f64 / self.rate).next_down(),
                obs,
            );
        }
        while next_impact < pending.len() && pending[next_impact].t_off_s <= limit {
            obs.impact(&pending[next_impact]);
            next_impact += 1;
        }
        pending.drain(..next_impact);
    }

    /// Drops the impacts held that closed after `t` (s) (a rewound session's: its last steps'
    /// past its time).
    pub fn drop_after(&mut self, t: f64) {
        self.pending.retain(|e| e.t_off_s <= t);
    }

    /// Sends what is left at the end of a run: the impacts closed beyond the last merge (a
    /// stop), the contact samples, then the events still open; returns the bodies' summed
    /// step counts.
    pub fn finish(&mut self, runs: &mut [DiscRun], obs: &mut dyn Observer) -> RunStats {
        for e in self.pending.drain(..) {
            obs.impact(&e);
        }
        send_contacts(runs, f64::INFINITY, obs);
        let mut stats = RunStats::default();
        for r in runs.iter_mut() {
            let mut rest = Buffer::default();
            r.stepper.finish(&mut rest);
            for e in &rest.impacts {
                obs.impact(e);
            }
            let s = &r.stepper.stats;
            stats.steps += s.steps;
            stats.rejected_steps += s.rejected_steps;
            stats.rhs_evals += s.rhs_evals;
        }
        stats
    }
}

/// Ends at the session's time `t` (s) every step of `runs` that passed it, before an input
/// changes (a driven session whose output is merged up to `t`): each such disc's integration
/// kept in `saved` stepped again to `t`, what those steps give again (sent before) dropped
/// with everything the discs and `merger` held past `t` (the last steps' output).
fn rewind_runs(
    runs: &mut [DiscRun],
    saved: &mut [Option<Box<Stepper>>],
    merger: &mut Merger,
    t: f64,
) -> Result<(), EngineError> {
    merger.drop_after(t);
    for (r, s) in runs.iter_mut().zip(saved.iter()) {
        // all merged up to `t`: the samples left are past it, the contact samples at `t`
        // wait for the next sample
        r.out.samples.clear();
        r.out.impacts.clear();
        r.out.contacts.retain(|&(tc, _)| tc <= t);
        let Some(s) = s.as_deref().filter(|_| r.stepper.t > t) else {
            continue;
        };
        r.stepper.clone_from(s);
        let mut again = Buffer::default();
        while r.stepper.t < t {
            r.stepper.step(t, &mut again, &mut no_external)?;
        }
    }
    Ok(())
}

/// Holds `inputs` from the session's time (`clock`) in every run of `runs` on `pack`: the
/// pack with them, the discs' relative speeds shifted by a jump of the shaft's speed, the
/// integrations restarted; returns the new pack.
pub(crate) fn hold_in_runs(
    clock: &Clock,
    pack: &PackModel,
    runs: &mut [DiscRun],
    inputs: &Inputs,
) -> Result<Arc<PackModel>, EngineError> {
    let (pack, jump) = clock.hold(pack, inputs)?;
    let pack = Arc::new(pack);
    for r in runs.iter_mut() {
        r.stepper.sys.pack = pack.clone();
        shift_disc_speeds(&mut r.stepper, jump);
        r.stepper.restart();
    }
    Ok(pack)
}

/// Tells every run whether `obs` takes contact samples (asked at every call).
pub(crate) fn want_contacts(runs: &mut [DiscRun], obs: &dyn Observer) {
    let wants = obs.wants_contact_samples();
    for r in runs.iter_mut() {
        r.out.wants_contacts = wants;
    }
}
