//! Steppable runs (`clutchpack_model::session`): what every scheme's session shares (the
//! queue that holds output past the session's time, the checks and the holding of inputs) and
//! the monolithic scheme's session. The multirate schemes' sessions are in `independent.rs`
//! and `coupled.rs`.
//!
//! A session steps exactly as a whole run does, driven or not (its steps end at the stop
//! time, never at a communication point), so that a run split into calls is the run, bit for
//! bit; a step may then pass the session's time, and what it produced beyond waits in the
//! [`Queue`] for the next call. A driven session keeps a copy of its integration before a
//! step that may pass the call's end; an input set to a new value there ends that step at the
//! session's time (the copy stepped again to it, what it gives again not sent twice) and the
//! integration restarts with the input (docs/DECISIONS.md, "Co-simulation").

use crate::stepper::{Sink, Stepper, Switch};
use crate::system::System;
use crate::thermal::{swap_pack, Thermal};
use crate::{face_event, no_external, ReferenceOptions};
use clutchpack_model::session::{hold_inputs, Advance, Driven, Inputs, Session, Snapshot};
use clutchpack_model::{
    DiscSample, Engagement, EngineError, ImpactEvent, InterfaceSample, NullObserver, Observer,
    PackModel, RunStats, Sample,
};
use std::collections::VecDeque;
use std::sync::Arc;

/// One piece of output, in the order the steps produced it.
#[derive(Debug, Clone)]
enum Item {
    Sample(Sample),
    Interfaces(f64, Vec<InterfaceSample>),
    Impact(ImpactEvent),
    Contact(usize, f64, DiscSample),
    /// A thermal window's end: the bodies' temperatures, then the oil's, K.
    Temperatures(f64, Vec<f64>),
}

impl Item {
    /// The time the item describes, s (an impact's: its end).
    fn t_s(&self) -> f64 {
        match self {
            Item::Sample(s) => s.t_s,
            Item::Interfaces(t, _) | Item::Contact(_, t, _) | Item::Temperatures(t, _) => *t,
            Item::Impact(e) => e.t_off_s,
        }
    }
}

/// Output produced by steps that passed the session's time, kept for the next call.
#[derive(Debug, Clone, Default)]
pub(crate) struct Queue {
    items: VecDeque<Item>,
    /// Whether the observer takes contact samples (asked at every call).
    pub wants_contacts: bool,
    /// The samples' and the interface samples' buffers of items sent, for the next items
    /// (issue 46: no allocation in a host's frame loop once started; they were two a sample).
    spare_samples: Vec<Sample>,
    spare_interfaces: Vec<Vec<InterfaceSample>>,
}

/// Most spare buffers a queue keeps of each kind (a call's steps queue at most a few
/// samples past the session's time; the rest are sent within the call).
const SPARE_BUFFERS: usize = 64;

impl Queue {
    /// Drops every item held (a rewound session's: what its last step produced past the
    /// session's time, or what the same steps taken again produced up to it, sent before).
    pub fn clear(&mut self) {
        self.items.clear();
    }
    /// Queues the sample of `sys` at `t` (state `y`, modes `modes`), then its interface
    /// samples if it has interfaces, in buffers of items sent before.
    pub fn sample_of(&mut self, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]) {
        let mut s = self.spare_samples.pop().unwrap_or_default();
        sys.sample_into(t, y, modes, &mut s);
        self.items.push_back(Item::Sample(s));
        if sys.interfaces() > 0 {
            let mut i = self.spare_interfaces.pop().unwrap_or_default();
            sys.interface_samples_into(t, y, modes, &mut i);
            self.items.push_back(Item::Interfaces(t, i));
        }
    }
    pub fn sample(&mut self, s: Sample) {
        self.items.push_back(Item::Sample(s));
    }
    pub fn impact(&mut self, e: ImpactEvent) {
        self.items.push_back(Item::Impact(e));
    }
    /// A thermal run's temperatures at `t` (s): the bodies', then the oil's, K.
    pub fn temperatures(&mut self, t: f64, k: &[f64]) {
        self.items.push_back(Item::Temperatures(t, k.to_vec()));
    }
    /// The contact sample of the coupling in `slot` of `sys` at `t` (state `y`), if the
    /// observer takes them.
    pub fn contact(
        &mut self,
        slot: usize,
        t: f64,
        sys: &System,
        y: &[f64],
        mode: &Option<Engagement>,
    ) {
        if self.wants_contacts {
            let d = sys.disc_sample(t, slot, y, mode);
            self.items.push_back(Item::Contact(sys.ids[slot], t, d));
        }
    }

    /// A poll during a call to `t` (s), the steps at `t_steps` (s): sends what the steps
    /// completed (so that the queue stays short on a long call), then asks the observer
    /// whether to stop (`Observer::progress`).
    pub fn poll(&mut self, t_steps: f64, t: f64, obs: &mut dyn Observer) -> bool {
        self.flush(t_steps.min(t), obs);
        obs.progress(t_steps)
    }

    /// Sends the items up to `t` (s) inclusive to `obs`, in the order they were produced;
    /// the first item later than `t` and everything after it wait.
    pub fn flush(&mut self, t: f64, obs: &mut dyn Observer) {
        while self.items.front().is_some_and(|i| i.t_s() <= t) {
            match self.items.pop_front().expect("a front") {
                Item::Sample(s) => {
                    obs.sample(&s);
                    if self.spare_samples.len() < SPARE_BUFFERS {
                        self.spare_samples.push(s);
                    }
                }
                Item::Interfaces(t, i) => {
                    obs.interfaces(t, &i);
                    if self.spare_interfaces.len() < SPARE_BUFFERS {
                        self.spare_interfaces.push(i);
                    }
                }
                Item::Impact(e) => obs.impact(&e),
                Item::Contact(d, t, s) => obs.contact_sample(d, t, &s),
                Item::Temperatures(t, k) => {
                    if let Some((oil, bodies)) = k.split_last() {
                        obs.temperatures(t, bodies, *oil);
                    }
                }
            }
        }
    }
}

/// Sends a whole-pack (or all-disc) stepper's output to a queue.
struct QueueSink<'q> {
    queue: &'q mut Queue,
}

impl Sink for QueueSink<'_> {
    fn sample(&mut self, _k: u64, t: f64, sys: &System, y: &[f64], modes: &[Option<Engagement>]) {
        self.queue.sample_of(t, sys, y, modes);
    }
    fn impact(&mut self, e: ImpactEvent) {
        self.queue.impact(e);
    }
    fn contact(&mut self, slot: usize, t: f64, sys: &System, y: &[f64], mode: &Option<Engagement>) {
        self.queue.contact(slot, t, sys, y, mode);
    }
}

/// What every scheme's session keeps besides its integration.
#[derive(Debug, Clone)]
pub(crate) struct Clock {
    /// The session's time (the last communication point reached), s.
    pub t: f64,
    /// The stop time (steps land on it), s; infinite when none was set.
    pub stop: f64,
    /// The inputs the caller drives.
    pub driven: Driven,
    /// Whether the session failed (it must not be advanced again).
    pub failed: bool,
}

impl Clock {
    pub fn new(driven: Driven) -> Clock {
        Clock {
            t: 0.0,
            stop: f64::INFINITY,
            driven,
            failed: false,
        }
    }

    /// Ends a call to `t` (s) that ended with `advance`, the stepper at `stepper_t` (s): the
    /// session's time, `t` or (stopped) where the stepper got to.
    pub fn end_call(&mut self, advance: Advance, stepper_t: f64, t: f64) -> f64 {
        self.t = if advance == Advance::Stopped {
            stepper_t.min(t)
        } else {
            t
        };
        self.t
    }

    /// Where the steps of a call to `t` (s) end: at the stop time (at `t` when the stop time
    /// lies before it), driven or not: the steps of a run split into calls are the whole
    /// run's (issue 46: a driven session ended a step at every call, `hu-table2` 3692 steps
    /// in 1 ms frames against 3497 in one call).
    pub fn step_end(&self, t: f64) -> f64 {
        self.stop.max(t)
    }

    /// Whether the session keeps a copy of its integration before a step that may pass a
    /// call's end: a driven one, whose inputs may change there ([`keep`]).
    pub fn keeps(&self) -> bool {
        self.driven.any()
    }

    /// Checks a call to `t` (s).
    pub fn check_advance(&self, t: f64) -> Result<(), EngineError> {
        if self.failed {
            return Err(EngineError::Unsupported(
                "the session failed before; start a new one".into(),
            ));
        }
        if !(t.is_finite() && t >= self.t) {
            return Err(EngineError::Unsupported(format!(
                "advance to t = {} s: expected a finite time at or after the session's time \
                 {} s",
                clutchpack_model::fmt_num(t),
                clutchpack_model::fmt_num(self.t)
            )));
        }
        Ok(())
    }

    /// Checks inputs against what the session drives; returns the pack with them held from
    /// the session's time on and the jump of the prescribed shaft's speed (rad/s).
    pub fn hold(&self, pack: &PackModel, inputs: &Inputs) -> Result<(PackModel, f64), EngineError> {
        let undriven = inputs.undriven(&self.driven);
        if !undriven.is_empty() {
            return Err(EngineError::Unsupported(format!(
                "the session does not drive the {} (the scene's profile runs it); start the \
                 session with it driven",
                undriven.join(", ")
            )));
        }
        if let Some((name, v)) = inputs.invalid() {
            return Err(EngineError::Unsupported(format!(
                "{name} = {}: expected a finite value (a pressure >= 0)",
                clutchpack_model::fmt_num(v)
            )));
        }
        Ok(hold_inputs(pack, self.t, inputs))
    }
}

/// Keeps in `slot` a copy of `now` (into the buffers of the last copy: no allocation once the
/// copies are as large): a driven session's integration before a step that may pass the
/// call's end, to end that step at the session's time should an input change there.
pub(crate) fn keep<T: Clone>(slot: &mut Option<Box<T>>, now: &T) {
    match slot {
        Some(b) => b.as_mut().clone_from(now),
        None => *slot = Some(Box::new(now.clone())),
    }
}

/// Adds `jump` (rad/s) to the relative speed of every disc slot of `st` against the shaft
/// (a jump of the prescribed shaft's speed; the plates' carriers do not move with it).
pub(crate) fn shift_disc_speeds(st: &mut Stepper, jump: f64) {
    if jump == 0.0 {
        return;
    }
    let nd = st.sys.pack.discs.len();
    for slot in 0..st.sys.ids.len() {
        if st.sys.ids[slot] < nd {
            st.y[st.sys.off + 2 * slot + 1] += jump;
        }
    }
}

/// The monolithic scheme's session: one stepper for the shaft and every coupling (and, on a
/// whole pack, the drum and the stack's faces with their stick-slip events).
#[derive(Clone)]
pub(crate) struct MonolithicSession {
    st: Stepper,
    clock: Clock,
    queue: Queue,
    /// Observer polls every this many steps.
    poll: u64,
    buf: Vec<f64>,
    /// The temperatures of a thermal run (`crate::thermal`); `None`: isothermal.
    thermal: Option<Box<Thermal>>,
    /// A driven session's integration and temperatures before its last step that may pass a
    /// call's end ([`keep`]; `MonolithicSession::rewind`).
    saved: Option<Box<Stepper>>,
    saved_thermal: Option<Box<Thermal>>,
}

impl MonolithicSession {
    pub fn new(pack: Arc<PackModel>, settings: &ReferenceOptions, driven: Driven) -> Self {
        let nd = pack.discs.len() + pack.plates.len();
        let mut st = Stepper::new(System::new(pack, (0..nd).collect()), settings);
        settle_faces(&mut st);
        MonolithicSession {
            st,
            clock: Clock::new(driven),
            queue: Queue::default(),
            // A step costs O(N): poll the observer about every 1024 disc-steps (a stop acts
            // within a few ms of wall time whatever the pack).
            poll: (1024 / nd.max(1)).max(1) as u64,
            buf: Vec::new(),
            thermal: None,
            saved: None,
            saved_thermal: None,
        }
    }

    /// The same session carrying the temperatures of `model` (MODEL.md section 9): the pack's
    /// viscosity-dependent parameters set for t = 0, then updated window by window.
    pub fn with_thermal(
        mut self,
        model: clutchpack_model::thermal::ThermalModel,
    ) -> Result<Self, EngineError> {
        let th = Thermal::new(model, &self.st.sys.pack)?;
        // the teeth's work integrated in the state, beside the faces' heat counters
        self.st.carry_teeth_work();
        if let Some(pack) = th.initial_pack(&self.st.sys.pack) {
            swap_pack(&mut self.st, pack);
        }
        // the temperatures at t = 0, the first point of their series
        self.queue.temperatures(self.st.t, th.temperatures_k());
        self.thermal = Some(Box::new(th));
        Ok(self)
    }

    /// Steps until the stepper's time reaches `t` (s), the steps ending at `end` (s), their
    /// output queued and sent up to the stepper's time at every poll of `obs`.
    fn steps(&mut self, t: f64, end: f64, obs: &mut dyn Observer) -> Result<Advance, EngineError> {
        let stack = self.st.sys.pack.stack.is_some();
        let mut advance = Advance::Reached;
        // a copy before a step that may pass `t`, where an input may change (not when the
        // steps end at `t`)
        let keeps = self.clock.keeps() && end > t;
        while self.st.t < t {
            if keeps && self.st.may_pass(t) {
                keep(&mut self.saved, &self.st);
                if let Some(th) = &self.thermal {
                    keep(&mut self.saved_thermal, th.as_ref());
                }
            }
            let mut sink = QueueSink {
                queue: &mut self.queue,
            };
            let buf = &mut self.buf;
            let switch = if stack {
                self.st.step(end, &mut sink, &mut |sys, modes, t0, t1, d| {
                    face_event(sys, modes, t0, t1, d, buf)
                })
            } else {
                self.st.step(end, &mut sink, &mut no_external)
            };
            let switch = match switch {
                Ok(s) => s,
                Err(e) => {
                    self.clock.failed = true;
                    self.queue.flush(self.st.t, obs);
                    return Err(e);
                }
            };
            // the step's heat, by the faces' modes along it (before its switch applies)
            if let Some(th) = self.thermal.as_mut() {
                th.book_step(&self.st);
            }
            if let Switch::External(m) = switch {
                let st = &mut self.st;
                st.sys.settle_face(m, st.t, &mut st.y, &st.modes);
                self.st.restart();
            }
            if let Some(th) = self.thermal.as_mut() {
                let windows = th.windows();
                let closed = th.close_windows(self.st.t, &self.st.sys.pack);
                if th.windows() != windows {
                    self.queue.temperatures(self.st.t, th.temperatures_k());
                }
                match closed {
                    Ok(Some(pack)) => swap_pack(&mut self.st, pack),
                    Ok(None) => {}
                    Err(e) => {
                        self.clock.failed = true;
                        self.queue.flush(self.st.t, obs);
                        return Err(e);
                    }
                }
            }
            if self.st.stats.steps.is_multiple_of(self.poll) && self.queue.poll(self.st.t, t, obs) {
                advance = Advance::Stopped;
                break;
            }
        }
        Ok(advance)
    }

    /// Ends the step that passed the session's time there, before an input changes (a driven
    /// session): the integration (and temperatures) kept before it stepped again to the
    /// session's time, what those steps give again (sent before) dropped with what the step
    /// had produced past it.
    fn rewind(&mut self) -> Result<(), EngineError> {
        let t = self.clock.t;
        let Some(saved) = self.saved.as_deref().filter(|_| self.st.t > t) else {
            return Ok(());
        };
        self.st.clone_from(saved);
        if let (Some(th), Some(kept)) = (self.thermal.as_mut(), self.saved_thermal.as_deref()) {
            th.as_mut().clone_from(kept);
        }
        self.queue.clear();
        let done = self.steps(t, t, &mut NullObserver);
        self.queue.clear();
        if done.is_err() {
            self.clock.failed = true;
        }
        done.map(|_| ())
    }
}

/// Sets every face of a stack's pack to its mode at the stepper's time (from the piston on)
/// and restarts the integration; nothing without a stack.
fn settle_faces(st: &mut Stepper) {
    if st.sys.pack.stack.is_some() {
        for m in 0..st.sys.faces.len() {
            let (t, modes) = (st.t, st.modes.clone());
            st.sys.settle_face(m, t, &mut st.y, &modes);
        }
        st.restart();
    }
}

impl Session for MonolithicSession {
    fn time_s(&self) -> f64 {
        self.clock.t
    }

    fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), EngineError> {
        self.rewind()?;
        let (pack, jump) = self.clock.hold(&self.st.sys.pack, inputs)?;
        self.st.sys.pack = Arc::new(pack);
        shift_disc_speeds(&mut self.st, jump);
        self.st.restart();
        if inputs.piston_pressure_pa.is_some() {
            settle_faces(&mut self.st);
        }
        Ok(())
    }

    fn set_stop_time(&mut self, t_s: f64) {
        self.clock.stop = t_s;
    }

    fn advance_to(&mut self, t: f64, obs: &mut dyn Observer) -> Result<Advance, EngineError> {
        self.clock.check_advance(t)?;
        self.queue.wants_contacts = obs.wants_contact_samples();
        let advance = self.steps(t, self.clock.step_end(t), obs)?;
        let now = self.clock.end_call(advance, self.st.t, t);
        self.queue.flush(now, obs);
        Ok(advance)
    }

    fn snapshot(&self) -> Snapshot {
        let t = self.clock.t;
        let mut y = Vec::new();
        let modes = self.st.state_at(t, &mut y);
        let sys = &self.st.sys;
        Snapshot {
            sample: sys.sample(t, &y, modes),
            interfaces: if sys.interfaces() > 0 {
                sys.interface_samples(t, &y, modes)
            } else {
                Vec::new()
            },
            drum: sys.drum_state(&y),
        }
    }

    fn finish(&mut self, obs: &mut dyn Observer) -> RunStats {
        self.st.finish(&mut QueueSink {
            queue: &mut self.queue,
        });
        let t = self.st.t;
        let thermal = self.thermal.as_mut().map(|th| {
            // the last (partial) window closes at the run's end
            let windows = th.windows();
            let report = th.finish(t);
            if th.windows() != windows {
                self.queue.temperatures(t, th.temperatures_k());
            }
            report
        });
        self.queue.flush(f64::INFINITY, obs);
        let mut stats = self.st.stats.clone();
        stats.simulated_s = self.clock.t;
        stats.thermal = thermal;
        stats
    }

    fn boxed_clone(&self) -> Box<dyn Session> {
        Box::new(self.clone())
    }
}
