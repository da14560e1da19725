//! Impact events of each coupling: onset, peak (with the parabola through the samples around
//! it) and separation, with the model's definitions ([`clutchpack_model::ImpactTracker`]).

use super::state::Run;
use crate::hook::CouplingForces;
use crate::stepping::contact_duration_s;
use clutchpack_model::{parabolic_peak, ImpactTracker, Observer};

/// Per-coupling event bookkeeping.
#[derive(Debug, Clone, Default)]
pub(super) struct EventTrack {
    pub(super) tracker: ImpactTracker,
    /// (t, depth, v_n) at the previous evaluation.
    pub(super) prev: Option<(f64, f64, f64)>,
    /// The last two (t, load) of the open event, for the parabolic peak.
    pub(super) last: Option<(f64, f64)>,
    pub(super) before_last: Option<(f64, f64)>,
    /// The step of the open event (adaptive stepping).
    pub(super) event_step_s: Option<f64>,
    /// The onset of the open event, s.
    pub(super) event_t_on_s: Option<f64>,
}

impl EventTrack {
    /// Feeds the coupling's state at `t`; returns an event that closed.
    pub(super) fn update(
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

    /// Observes a load sample and, when the previous sample was a local maximum of `|F|`, the
    /// vertex of the parabola through the three samples around it (the peak between steps).
    pub(super) fn push(&mut self, t: f64, load: f64) {
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

impl Run<'_> {
    /// Feeds the impact trackers with the state at `t`.
    pub(super) fn track_events(&mut self, steps_per_contact: f64, observer: &mut dyn Observer) {
        for (i, track) in self.tracks.iter_mut().enumerate() {
            let law = &self.bodies[i].law;
            let f = &self.forces[i];
            let m = self.m_eff[i];
            let step = |v| contact_duration_s(law, f.kin.flank, v, m) / steps_per_contact;
            if let Some(e) = track.update(self.t, f, step) {
                observer.impact(&e);
            }
        }
    }
}
