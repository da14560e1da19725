//! The multirate scheme on a prescribed shaft: every disc an independent ODE with its own
//! steps and events, advanced window by window (in parallel when asked) and merged into one
//! time-ordered stream of samples and impacts (crate docs, Theory).

use crate::stepper::{Sink, Stepper};
use crate::system::System;
use crate::{no_external, ReferenceOptions};
use clutchpack_model::{
    DiscSample, Engagement, EngineError, ImpactEvent, Observer, PackModel, RunStats, Sample,
};
use rayon::prelude::*;
use std::collections::VecDeque;
use std::time::Instant;

/// One disc's output not yet merged.
#[derive(Default)]
struct Buffer {
    /// `(sample number, the disc's sample)` in order.
    samples: VecDeque<(u64, DiscSample)>,
    /// Impacts in the order they closed.
    impacts: Vec<ImpactEvent>,
    /// `(t s, the disc's state)` of its contact samples, in order.
    contacts: VecDeque<(f64, DiscSample)>,
    /// Whether the observer takes contact samples (else none are kept).
    wants_contacts: bool,
}

impl Sink for Buffer {
    fn sample(&mut self, k: u64, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]) {
        self.samples
            .push_back((k, sys.disc_sample(t, 0, y, &modes[0])));
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

/// One disc's integration and its unmerged output.
struct DiscRun<'a> {
    stepper: Stepper<'a>,
    out: Buffer,
    error: Option<EngineError>,
}

impl DiscRun<'_> {
    /// Integrates until the disc's time reaches `t_w` (s) or the end of the run, or until
    /// the wall clock passes `deadline` (so that a stop request is seen even when the
    /// steps become very small).
    fn advance(&mut self, t_w: f64, duration_s: f64, deadline: Instant) {
        let mut n: u32 = 0;
        while self.error.is_none() && self.stepper.t < t_w && self.stepper.t < duration_s {
            if let Err(e) = self
                .stepper
                .step(duration_s, &mut self.out, &mut no_external)
            {
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

pub(crate) fn run(
    pack: &PackModel,
    settings: &ReferenceOptions,
    parallel: bool,
    duration_s: f64,
    obs: &mut dyn Observer,
) -> Result<RunStats, EngineError> {
    let nd = pack.discs.len();
    let wants_contacts = obs.wants_contact_samples();
    let mut runs: Vec<DiscRun> = (0..nd)
        .map(|i| DiscRun {
            stepper: Stepper::new(System::new(pack, vec![i]), settings),
            out: Buffer {
                wants_contacts,
                ..Buffer::default()
            },
            error: None,
        })
        .collect();
    let shaft = match &pack.shaft {
        clutchpack_model::Shaft::Prescribed(p) => p,
        clutchpack_model::Shaft::Inertial { .. } => unreachable!("a prescribed shaft"),
    };
    let rate = settings.record_rate_hz;
    let cap = (MAX_BUFFERED_SAMPLES / (rate * nd as f64)).max(2.0 / rate);
    let mut window = (1e-3f64).min(cap);
    let mut t_w = 0.0;
    let mut next_k: u64 = 0;
    let mut pending: Vec<ImpactEvent> = Vec::new();
    let mut sample = Sample {
        discs: vec![DiscSample::default(); nd],
        ..Sample::default()
    };
    let mut stopped = false;
    let mut failure: Option<EngineError> = None;
    while t_w < duration_s {
        let target = (t_w + window).min(duration_s);
        let wall = Instant::now();
        let deadline = wall + std::time::Duration::from_secs_f64(WINDOW_WALL_CUT_S);
        if parallel {
            runs.par_iter_mut()
                .for_each(|r| r.advance(target, duration_s, deadline));
        } else {
            runs.iter_mut()
                .for_each(|r| r.advance(target, duration_s, deadline));
        }
        // a window cut short by the deadline ends where the slowest disc got to
        t_w = runs
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
            window *= 0.5;
        } else if wall < WINDOW_WALL_MIN_S && 2.0 * buffered <= MAX_BUFFERED_SAMPLES {
            window = (2.0 * window).min(cap);
        }
        // Deliver everything up to `limit`: the window's end, or the last good time of the
        // earliest disc that failed.
        let mut limit = t_w;
        for r in &runs {
            if let (Some(e), true) = (&r.error, r.stepper.t <= limit) {
                limit = r.stepper.t;
                failure = Some(e.clone());
            }
        }
        for r in runs.iter_mut() {
            pending.append(&mut r.out.impacts);
        }
        pending.sort_by(|a, b| a.t_off_s.total_cmp(&b.t_off_s).then(a.disc.cmp(&b.disc)));
        let mut next_impact = 0;
        loop {
            let ts = next_k as f64 / rate;
            // a disc that failed before its first step has no sample at t = 0
            let ready = runs
                .iter()
                .all(|r| r.out.samples.front().is_some_and(|&(k, _)| k == next_k));
            if ts > limit || !ready {
                break;
            }
            while next_impact < pending.len() && pending[next_impact].t_off_s < ts {
                obs.impact(&pending[next_impact]);
                next_impact += 1;
            }
            // each disc's contact samples up to this sample first: one time order per disc
            send_contacts(&mut runs, ts, obs);
            sample.t_s = ts;
            sample.shaft_angle_rad = shaft.angle(ts);
            sample.shaft_speed_rad_s = shaft.speed(ts);
            for (r, d) in runs.iter_mut().zip(sample.discs.iter_mut()) {
                if let Some((_, s)) = r.out.samples.pop_front() {
                    *d = s;
                }
            }
            obs.sample(&sample);
            next_k += 1;
        }
        // the contact samples before the next sample (which the next window sends)
        send_contacts(&mut runs, limit.min(next_k as f64 / rate).next_down(), obs);
        while next_impact < pending.len() && pending[next_impact].t_off_s <= limit {
            obs.impact(&pending[next_impact]);
            next_impact += 1;
        }
        pending.drain(..next_impact);
        if let Some(e) = failure {
            return Err(e);
        }
        if obs.progress(t_w) {
            stopped = true;
            break;
        }
    }
    // Impacts closed beyond the last window's end (a stop), then the events still open.
    for e in &pending {
        obs.impact(e);
    }
    send_contacts(&mut runs, f64::INFINITY, obs);
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
    stats.simulated_s = if stopped { t_w } else { duration_s.min(t_w) };
    stats.stopped_early = stopped;
    Ok(stats)
}
