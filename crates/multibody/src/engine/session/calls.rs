//! Where a driven [`MultibodySession`]'s calls land (issue 46): on the whole run's grid
//! points when a call's time is one of them but for rounding, so that a host's frames take
//! the whole run's steps ([`MultibodySession::land_calls_on_grid`]).

use super::MultibodySession;
use crate::options::Stepping;

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
    }

    /// The session's time, s ([`clutchpack_model::session::Session::time_s`]): the last
    /// call's time while the session stands on the grid point standing for it, else the
    /// run's.
    pub(super) fn call_time(&self) -> f64 {
        if self.run.t == self.called_s.0 {
            self.called_s.1
        } else {
            self.run.t
        }
    }
}
