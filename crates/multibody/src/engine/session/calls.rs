//! Where a driven [`MultibodySession`]'s calls land (issue 46): on the whole run's grid
//! points when a call's time is one of them but for rounding, so that a host's frames take
//! the whole run's steps ([`MultibodySession::land_calls_on_grid`]).
//!
//! A call's time may still fall inside a step: a contact step of the adaptive shared step
//! (which keeps its length), a world step of the multirate scheme off the grid (a host's
//! 25 us frames against 1e-4 s world steps). A driven session started through `Engine::start`
//! then takes the step that passes the call as a session driven by nothing does (the whole
//! run's step), keeping a copy of itself before it ([`Passed`]) and holding what the step
//! produced ([`Held`]) for the next call. The call stands at its time
//! ([`MultibodySession::call_time`]; the snapshot is the state at the step's end, past it by
//! less than a step). An input set to a new value at the call's time, and `finish`, rewind
//! ([`MultibodySession::rewind`]): the copy steps again to the call's time, as every driven
//! call's step ended there before, what the passing step produced is dropped and what the
//! shortened one produces goes out with the next call.

use super::{Loop, MultibodySession};
use crate::options::Stepping;
use clutchpack_model::{DiscSample, EngineError, ImpactEvent, InterfaceSample, Observer, Sample};

/// A driven shared step that passed a call: the session before it and the call, s (the grid
/// point it landed on, [`MultibodySession::landing`], and its time).
#[derive(Clone)]
pub(super) struct Passed {
    before: MultibodySession,
    call: Option<(f64, f64)>,
}

/// What a step passing a call produced, in the order it produced it, until the next call.
#[derive(Clone, Default)]
pub(super) struct Held {
    items: Vec<Item>,
}

#[derive(Clone)]
enum Item {
    Sample(Sample),
    Interfaces(f64, Vec<InterfaceSample>),
    Impact(ImpactEvent),
    Contact(usize, f64, DiscSample),
    Temperatures(f64, Vec<f64>, f64),
}

impl Observer for Held {
    fn sample(&mut self, sample: &Sample) {
        self.items.push(Item::Sample(sample.clone()));
    }
    fn impact(&mut self, event: &ImpactEvent) {
        self.items.push(Item::Impact(*event));
    }
    fn interfaces(&mut self, t_s: f64, interfaces: &[InterfaceSample]) {
        self.items.push(Item::Interfaces(t_s, interfaces.to_vec()));
    }
    fn contact_sample(&mut self, disc: usize, t_s: f64, state: &DiscSample) {
        self.items.push(Item::Contact(disc, t_s, state.clone()));
    }
    fn temperatures(&mut self, t_s: f64, bodies_k: &[f64], oil_k: f64) {
        self.items
            .push(Item::Temperatures(t_s, bodies_k.to_vec(), oil_k));
    }
}

impl Held {
    /// Sends what is held to `observer`, in its order, and forgets it.
    pub(super) fn send(&mut self, observer: &mut dyn Observer) {
        for item in self.items.drain(..) {
            match item {
                Item::Sample(s) => observer.sample(&s),
                Item::Interfaces(t, i) => observer.interfaces(t, &i),
                Item::Impact(e) => observer.impact(&e),
                Item::Contact(d, t, s) => observer.contact_sample(d, t, &s),
                Item::Temperatures(t, k, oil) => observer.temperatures(t, &k, oil),
            }
        }
    }
}

impl MultibodySession {
    /// Lands a driven session's calls on the whole run's grid points (issue 46): a call's time
    /// within rounding (a billionth of the grid's interval) of a point of the record grid
    /// (adaptive steps) or of the fixed steps' grid is that point, so that the steps end where
    /// one call's steps end
    /// (a host's frame end `k T`, 9e-3, and the grid's `j / rate`, 9.000000000000001e-3, are
    /// the same instant; a step landing on the former instead of the latter changed the run's
    /// outputs in their last bits, `hu-table2` and `pack-8-brake` in 1 ms frames). A call's
    /// time inside a step (off the grid) still ends that step there. What `Engine::start`
    /// does; the network's pack sessions, whose calls are its own steps, land on them.
    pub fn land_calls_on_grid(&mut self) {
        self.calls_on_grid = true;
    }

    /// Where a call to `t_s` (s) lands: the grid point `t_s` stands for
    /// ([`Self::land_calls_on_grid`]) or `t_s` itself (a session driven by nothing, a call at
    /// or past the declared end, a time off the grid).
    pub(super) fn landing(&self, t_s: f64) -> f64 {
        if !self.calls_on_grid || !self.driven.any() || t_s >= self.end_s || t_s < 0.0 {
            return t_s;
        }
        let (g, interval) = match self.options.stepping {
            // the fixed steps' grid as `advance_shared` computes it
            Stepping::Fixed { dt_s } => ((t_s / dt_s).round() * dt_s, dt_s),
            Stepping::Adaptive(_) => {
                let j = (t_s * self.options.record_rate_hz).round() as u64;
                (self.rec_time(j), 1.0 / self.options.record_rate_hz)
            }
        };
        if (g - t_s).abs() <= self.slack(interval) {
            g
        } else {
            t_s
        }
    }

    /// Keeps, after a call to `t_s` (s) that landed on `to` (s, [`Self::landing`]), the call's
    /// time for [`Self::call_time`] while the session stands on `to`.
    pub(super) fn landed(&mut self, to: f64, t_s: f64) {
        if to != t_s && self.run.t == to {
            self.called_s = (to, t_s);
        }
        match self.passed.as_deref_mut() {
            Some(p) if self.run.t > to => p.call = Some((to, t_s)),
            _ => self.passed = None,
        }
    }

    /// Whether the session carries its steps past a call: a driven session started through
    /// `Engine::start` on adaptive steps (the multirate scheme's world steps, the shared
    /// step's).
    pub(super) fn carries(&self) -> bool {
        self.calls_on_grid
            && self.driven.any()
            && matches!(self.options.stepping, Stepping::Adaptive(_))
    }

    /// Keeps a copy of the session before a step that passes a call.
    pub(super) fn keep_before(&mut self) {
        let before = MultibodySession {
            passed: None,
            held: Held::default(),
            ..self.clone()
        };
        self.passed = Some(Box::new(Passed { before, call: None }));
    }

    /// Starts a call to `t_s` (s, landing on `to`): a step that passed the last call and
    /// passes this one too leaves it standing at its time (`true`: nothing to do); else what
    /// the last call's step held goes out to `observer`.
    pub(super) fn resume(&mut self, to: f64, t_s: f64, observer: &mut dyn Observer) -> bool {
        if let Some(p) = self.passed.as_deref_mut() {
            if self.run.t > to {
                p.call = Some((to, t_s));
                return true;
            }
        }
        self.passed = None;
        self.held.send(observer);
        false
    }

    /// Ends a step that passed the session's time there, before an input changes or the run
    /// finishes: the copy
    /// kept before it steps again to the call's time (the step shortened to it), what the
    /// passing step produced dropped, what the shortened one produces held for the next call.
    pub(super) fn rewind(&mut self) -> Result<(), EngineError> {
        let Some(Passed {
            before,
            call: Some((to, t_s)),
        }) = self.passed.take().map(|p| *p)
        else {
            return Ok(());
        };
        *self = before;
        let mut held = Held::default();
        let out = match self.scheme {
            Loop::Shared => self.advance_shared(to, false, &mut held),
            Loop::Multirate(a) => self.advance_multirate(to, a, false, &mut held),
        };
        self.held = held;
        self.failed = out.is_err();
        self.landed(to, t_s);
        out.map(|_| ())
    }

    /// The session's time, s ([`clutchpack_model::session::Session::time_s`]): the last
    /// call's time while the session stands on the grid point standing for it or past it by
    /// a step that passed it, else the run's.
    pub(super) fn call_time(&self) -> f64 {
        if let Some((_, t_s)) = self.passed.as_ref().and_then(|p| p.call) {
            t_s
        } else if self.run.t == self.called_s.0 {
            self.called_s.1
        } else {
            self.run.t
        }
    }
}
