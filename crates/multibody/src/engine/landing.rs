//! The one landing loop of the multirate schemes (issue 33): a scheme's sub-steps over a
//! world step ([`SubSteps`]: a coupling alone against its carrier's path, `multirate.rs`; an
//! inertial carrier with its cluster, `inertial.rs`; the clamped stack, `clamped.rs`), each
//! of the length its controller wants, landed on the first contact onset or separation of any
//! of its couplings or on the scheme's own events (a face's slip reaching zero).

use super::state::Run;
use super::substep::{split_remainder, WorldStep};
use clutchpack_model::EngineError;

impl Run {
    /// The one landing loop of the multirate schemes: sub-steps `s` from `t` to the world
    /// step's end, each of the length its controller wants (`SubSteps::want`, split so that
    /// the last two are even), shortened to land on the first onset or separation of any of
    /// its couplings within it (located on the sub-step's own path by
    /// [`Run::depth_crossing`]; the `s^1.5` law's kink then falls on a sub-step boundary and
    /// the step keeps its order), then accepted (`SubSteps::accept`: its state, the counts,
    /// the works, the sub-step's end for every coupling).
    pub(super) fn land_sub_steps<S: SubSteps>(
        &mut self,
        s: &mut S,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError> {
        let t1 = ws.t1;
        while s.t() < t1 {
            let t = s.t();
            let want = s.want(self, ws)?;
            let rem = t1 - t;
            let mut h = split_remainder(want, rem);
            let mut step = s.step(self, h);
            s.keep(&step);
            // Never step over an onset or a separation of any coupling, nor over the scheme's
            // own events: land on the first.
            let tiny = 1e-3 * h.min(want);
            // the trial steps of the searches
            let trials = std::cell::Cell::new(0);
            let mut first: Option<(f64, Option<usize>)> = None;
            let mut consider = |x: f64, event: Option<usize>| {
                if x > tiny && x < h && first.is_none_or(|(b, _)| x < b) {
                    first = Some((x, event));
                }
            };
            for k in 0..s.members().len() {
                let (i, phi0) = (s.members()[k], s.phi(k));
                let crossing = self.depth_crossing(i, phi0, s.phi_kept(&step, k), h, |x| {
                    trials.set(trials.get() + 1);
                    s.phi_end(&s.step(self, x), k)
                });
                if let Some(x) = crossing {
                    consider(x, None);
                }
            }
            s.events(self, h, &mut consider, &trials);
            ws.counts.evals += trials.get() * s.evals_per_step();
            let mut event = None;
            if let Some((x, e)) = first {
                h = x;
                step = s.step(self, x);
                ws.counts.evals += s.evals_per_step();
                event = e;
            } else if trials.get() > 0 && s.trials_overwrite() {
                // the searches left another step in the scheme's buffers
                step = s.step(self, h);
                ws.counts.evals += s.evals_per_step();
            }
            let t = if h == rem { t1 } else { t + h };
            s.accept(self, step, t, event, ws)?;
        }
        Ok(())
    }
}

/// A multirate scheme's sub-steps as the one landing loop drives them
/// ([`Run::land_sub_steps`]): a set of couplings integrated together (with their carrier's
/// known path, or with their inertial carrier) from their state at `t`.
pub(super) trait SubSteps {
    /// One sub-step's outcome.
    type Step;
    /// The time the sub-steps have reached, s.
    fn t(&self) -> f64;
    /// The couplings integrated together.
    fn members(&self) -> &[usize];
    /// Member `k`'s relative angle at `t`, rad.
    fn phi(&self, k: usize) -> f64;
    /// The sub-step the controller wants from `t`, s (checked: the run's failure when it
    /// collapsed); readies the step's start (what the schemes count goes to `ws`).
    fn want(&mut self, run: &mut Run, ws: &mut WorldStep) -> Result<f64, EngineError>;
    /// One step of length `h` from `t` (the one classical Runge-Kutta step, `Rk4::rk4`, on
    /// the scheme's right-hand side).
    fn step(&self, run: &Run, h: f64) -> Self::Step;
    /// Member `k`'s relative angle at the end of `step`, rad.
    fn phi_end(&self, step: &Self::Step, k: usize) -> f64;
    /// Keeps what the searches need of the full step `step` (a scheme whose trial steps
    /// overwrite its buffers, [`SubSteps::trials_overwrite`]).
    fn keep(&mut self, _step: &Self::Step) {}
    /// Member `k`'s relative angle at the end of the full step `step` (kept), rad.
    fn phi_kept(&self, step: &Self::Step, k: usize) -> f64 {
        self.phi_end(step, k)
    }
    /// Whether a trial step overwrites the step it was given (the full step is then taken
    /// again after searches that did not land).
    fn trials_overwrite(&self) -> bool {
        false
    }
    /// The scheme's own events within the step of length `h` (as `consider(x, Some(e))`,
    /// located on trial steps counted in `trials`): none but the couplings' depth crossings.
    fn events(
        &self,
        _run: &Run,
        _h: f64,
        _consider: &mut dyn FnMut(f64, Option<usize>),
        _trials: &std::cell::Cell<u64>,
    ) {
    }
    /// Tooth-law evaluations of one step.
    fn evals_per_step(&self) -> u64;
    /// Takes `step`, ending at `t`, landed on the scheme's own event `event` if any: the
    /// state, the counts, the works, each member's sub-step end ([`Run::end_sub_step`]).
    fn accept(
        &mut self,
        run: &mut Run,
        step: Self::Step,
        t: f64,
        event: Option<usize>,
        ws: &mut WorldStep,
    ) -> Result<(), EngineError>;
}
