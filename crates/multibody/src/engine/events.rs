//! Impact events of each coupling: onset, peak (with the parabola through the samples around
//! it) and separation, with the model's definitions ([`clutchpack_model::ImpactTracker`]).

use crate::hook::CouplingForces;

use clutchpack_model::{parabolic_peak, ImpactEvent, ImpactTracker};

/// Per-coupling event bookkeeping.
#[derive(Debug, Clone, Default)]
struct EventTrack {
    tracker: ImpactTracker,
    /// (t, depth, v_n) at the previous evaluation.
    prev: Option<(f64, f64, f64)>,
    /// The last two (t, load) of the open event, for the parabolic peak.
    last: Option<(f64, f64)>,
    before_last: Option<(f64, f64)>,
    /// The step of the open event (adaptive stepping).
    event_step_s: Option<f64>,
    /// The onset of the open event, s.
    event_t_on_s: Option<f64>,
    /// Time of the last contact sample sent, s.
    last_contact_sample_s: f64,
}

/// Contact samples per contact aimed at ([`EventTrack::contact_sample_due`]): with 32 points
/// the largest sample of a half-sine-like pulse lies at most 1/64 of the contact from its
/// peak, `1 - cos(pi / 64) = 0.12 %` below it; every sub-step (128 per contact and more near
/// the kinks) would quadruple the recording's contact data for no visible gain.
pub(crate) const CONTACT_SAMPLES_PER_CONTACT: f64 = 32.0;

impl EventTrack {
    /// Feeds the coupling's state at `t`; returns an event that closed.
    fn update(
        &mut self,
        t: f64,
        f: &CouplingForces,
        contact_step: impl FnOnce(f64) -> f64,
    ) -> Option<clutchpack_model::ImpactEvent> {
        let depth = f.depth_m;
        let v = f.kin.v_n_m_s;
        let mut closed = None;
        if depth > 0.0 {
            if !self.tracker.is_open() {
                let (t_on, v_on) = match self.prev {
                    Some((t0, d0, v0)) if d0 <= 0.0 => {
                        let w = -d0 / (depth - d0);
                        (t0 + w * (t - t0), v0 + w * (v - v0))
                    }
                    _ => (t, v),
                };
                self.tracker.begin(t_on, f.kin.flank, v_on);
                self.last = None;
                self.before_last = None;
                self.event_step_s = Some(contact_step(v_on));
                self.event_t_on_s = Some(t_on);
            }
            self.push(t, f.load_n);
        } else if self.tracker.is_open() {
            let t_off = match self.prev {
                Some((t0, d0, _)) if d0 > 0.0 => t0 + d0 / (d0 - depth) * (t - t0),
                _ => t,
            };
            self.push(t, 0.0);
            closed = self.tracker.end(t_off);
            self.event_step_s = None;
            self.event_t_on_s = None;
        }
        self.prev = Some((t, depth, v));
        closed
    }

    /// Whether the coupling's state at `t`, just fed to [`Self::update`], goes out as a
    /// contact sample (`Observer::contact_sample`); `was_open` says whether an event was open
    /// before that update. Sent: the first state inside an event, the state that closes it
    /// (at the event's separation `t_off_s`, interpolated to the zero of the engagement depth
    /// between this state and the one before: the two are the same instant, to rounding, when
    /// the step landed on the separation, as steps do), and in between states at least `max(T, age) / CONTACT_SAMPLES_PER_CONTACT` apart, `T`
    /// the event's predicted duration (`steps_per_contact` times its contact step) and `age`
    /// the time since its onset: about 32 points over an impact, and a sustained contact's
    /// points thin out geometrically (32 more per e-fold of its age; the regular samples
    /// carry it at the record rate).
    fn contact_sample_due(&mut self, t: f64, was_open: bool, steps_per_contact: f64) -> bool {
        let due = match (was_open, self.tracker.is_open()) {
            (false, false) => false,
            (false, true) | (true, false) => true,
            (true, true) => {
                let duration = self.event_step_s.unwrap_or(0.0) * steps_per_contact;
                let age = self.event_t_on_s.map_or(0.0, |t_on| t - t_on);
                t - self.last_contact_sample_s >= duration.max(age) / CONTACT_SAMPLES_PER_CONTACT
            }
        };
        if due {
            self.last_contact_sample_s = t;
        }
        due
    }

    /// Observes a load sample and, when the previous sample was a local maximum of `|F|`, the
    /// vertex of the parabola through the three samples around it (the peak between steps).
    #[inline]
    fn push(&mut self, t: f64, load: f64) {
        self.tracker.observe(t, load);
        if let (Some((t0, f0)), Some((t1, f1))) = (self.before_last, self.last) {
            if f1 != 0.0 && t0 < t1 && t1 < t {
                let peak = parabolic_peak((t0, f0.abs()), (t1, f1.abs()), (t, load.abs()));
                if let Some((tv, av)) = peak {
                    self.tracker.observe(tv, f1.signum() * av);
                }
            }
        }
        self.before_last = self.last;
        self.last = Some((t, load));
    }
}

/// What one update of a coupling's tracker gave.
pub(super) struct Tracked {
    /// The impact that closed, if one did.
    pub(super) closed: Option<ImpactEvent>,
    /// When a contact sample is due, the time to send it at (the separation for the state
    /// that closed an impact); `None` also when the observer takes no contact samples.
    pub(super) contact_sample_at: Option<f64>,
}

/// The impact events of every coupling of a run, the one place that writes them: each
/// coupling's tracker and its contact-sample schedule.
#[derive(Debug, Clone)]
pub(super) struct EventBook {
    tracks: Vec<EventTrack>,
    /// Whether the observer takes contact samples (`Observer::wants_contact_samples`).
    contact_samples: bool,
}

impl EventBook {
    /// The trackers of `couplings` couplings, numbered as the engine's output.
    pub(super) fn new(couplings: usize) -> EventBook {
        EventBook {
            tracks: (0..couplings)
                .map(|i| EventTrack {
                    tracker: ImpactTracker::new(i),
                    ..Default::default()
                })
                .collect(),
            contact_samples: false,
        }
    }

    /// Whether contact samples are scheduled (the observer's wish).
    pub(super) fn take_contact_samples(&mut self, yes: bool) {
        self.contact_samples = yes;
    }

    /// The step of coupling `i`'s open event, s.
    pub(super) fn event_step_s(&self, i: usize) -> Option<f64> {
        self.tracks[i].event_step_s
    }

    /// The age at `t` of coupling `i`'s open event, s.
    pub(super) fn event_age_s(&self, i: usize, t: f64) -> Option<f64> {
        self.tracks[i].event_t_on_s.map(|t_on| t - t_on)
    }

    /// Feeds coupling `i`'s state at `t` (`contact_step` gives the step of a new event from
    /// its closing speed, [`EventTrack::update`]); says whether an impact closed and whether a
    /// contact sample is due ([`EventTrack::contact_sample_due`]).
    #[inline]
    pub(super) fn update(
        &mut self,
        i: usize,
        t: f64,
        f: &CouplingForces,
        steps_per_contact: f64,
        contact_step: impl FnOnce(f64) -> f64,
    ) -> Tracked {
        let track = &mut self.tracks[i];
        let was_open = track.tracker.is_open();
        let closed = track.update(t, f, contact_step);
        let due = self.contact_samples && track.contact_sample_due(t, was_open, steps_per_contact);
        Tracked {
            closed,
            contact_sample_at: due.then(|| closed.map_or(t, |e| e.t_off_s)),
        }
    }

    /// Every open event as it would close at `t` (its peak the largest so far), left open.
    pub(super) fn open(&self, t: f64) -> impl Iterator<Item = ImpactEvent> + '_ {
        self.tracks.iter().filter_map(move |k| k.tracker.peek(t))
    }

    /// Closes the events still open at the end of the run, `t`.
    pub(super) fn finish(&mut self, t: f64) -> Vec<ImpactEvent> {
        self.tracks
            .iter_mut()
            .filter_map(|k| k.tracker.finish(t))
            .collect()
    }
}
