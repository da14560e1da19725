//! Stepping a network's equations (`super::Equations`): [`NetworkStepper`], the adaptive
//! DOPRI5 integration with its events located and the modes settled (the method is in the
//! module's docs), advanced call by call with inputs set in between, and [`run_network`], one
//! call to the end.

use super::modes::settle;
use super::{mesh, packs, sample, Equations, NetworkOptions};
use crate::dopri::{next_step, Dense, Dopri5};
use crate::thermal::Thermal;
pub use clutchpack_model::network::NetworkInput;
use clutchpack_model::network::{
    ClutchMode, EnergyTerm, Network, NetworkEnergy, NetworkRun, NetworkSample, NetworkSession,
};
use clutchpack_model::{guard_state, EngineError, Observer, RUNAWAY_SPEED_RAD_S};
use std::sync::Arc;

/// Runs `net` for `duration_s` seconds; samples and clutch events go to `obs` as they happen.
/// A network with problems ([`Network::problems`]) is refused.
pub fn run_network(
    net: &Network,
    duration_s: f64,
    options: &NetworkOptions,
    obs: &mut dyn Observer,
) -> Result<NetworkRun, EngineError> {
    let mut run = NetworkStepper::new(net, duration_s, options, obs)?;
    run.advance_to(duration_s, obs)?;
    Ok(run.finish(obs))
}

/// A network run advanced call by call ([`NetworkStepper::advance_to`]), with inputs set
/// between calls ([`NetworkStepper::set_input`]); [`run_network`] is one call to the end.
///
/// A call's end is not a step's end: the integration takes the whole run's steps whatever
/// the calls (they land on the signals' breakpoints and the run's end only), so a run split
/// into any number of calls is the whole run bit for bit, as the pack sessions are
/// (docs/DECISIONS.md, "Co-simulation"). The step that passes a call's end waits, taken and
/// its events located but not yet applied (a pending step); its dense output answers for the
/// call's time ([`NetworkStepper::sample_now`], [`NetworkStepper::heat_j`]), and the next
/// call that reaches its end applies it. An input set, or the run finished, inside it ends it
/// at the call's time from the dense output, as an event would; the integration restarts
/// there.
#[derive(Clone)]
pub struct NetworkStepper {
    eq: Equations,
    options: NetworkOptions,
    /// The run's end, s (samples stop there).
    duration_s: f64,
    y: Vec<f64>,
    atol: Vec<f64>,
    meshes: mesh::Meshes,
    breakpoints: Vec<f64>,
    next_bp: usize,
    stepper: Dopri5,
    dense: Dense,
    dy: Vec<f64>,
    ybuf: Vec<f64>,
    g0: Vec<f64>,
    g1: Vec<f64>,
    /// The time `g0` holds the guards at (the end of the last full step, whose last probe
    /// they are; NaN: none), so that the next step does not evaluate them again.
    g0_at: f64,
    /// Sample interval, s (infinite: none but the first and last).
    period: f64,
    next_sample: u64,
    /// The integration's time, s (the start of a pending step).
    t: f64,
    /// The session's time, s: `t`, or the last call's end inside the pending step.
    now: f64,
    /// The step taken past the session's time, waiting to be applied.
    pending: Option<Pending>,
    h: f64,
    steps: u64,
    events: u64,
    kinetic0: f64,
}

impl NetworkStepper {
    /// Starts `net` at t = 0 for a run of `duration_s` s: the modes settled and the first
    /// sample sent to `obs`. A network with problems ([`Network::problems`]) is refused.
    pub fn new(
        net: &Network,
        duration_s: f64,
        options: &NetworkOptions,
        obs: &mut dyn Observer,
    ) -> Result<NetworkStepper, EngineError> {
        net.check_run(duration_s)?;
        let n = net.bodies.len();
        let m = net.couplings.len();
        let initial_modes: Vec<Option<ClutchMode>> = (0..m)
            .map(|k| net.couplings[k].law().initial_mode())
            .collect();
        let mut eq = Equations::new(Arc::new(net.clone()), initial_modes);
        // the thermal packs: their parameters at the initial temperatures (MODEL.md section 9)
        for p in eq.packs.iter_mut() {
            if let Some(model) = net.pack_thermal.get(&p.k) {
                let th = Thermal::new(model.clone(), &p.sys.pack)?;
                if let Some(pack) = th.initial_pack(&p.sys.pack) {
                    p.set_pack(Arc::new(pack));
                }
                obs.pack_temperatures(p.k, 0.0, th.temperatures_k());
                p.thermal = Some(Box::new(th));
            }
        }
        let dim = eq.dim();
        let tol = options.tolerance;
        let mut atol = vec![tol; dim];
        // each element's state on its own scale (a mesh's x on its backlash, a spring's twist
        // in rad); other slots and the counters out of the norm
        for k in 0..m {
            atol[2 * n + k] = net.couplings[k]
                .law()
                .state_scale()
                .map_or(f64::INFINITY, |s| tol * s);
        }
        atol[2 * n + m..]
            .iter_mut()
            .for_each(|a| *a = f64::INFINITY);
        let mut y = vec![0.0; dim];
        for p in &eq.packs {
            // each body's relative angle on its spline's half play, its relative speed on
            // the tolerance in rad/s; the heat and the works out of the norm (as in the pack
            // engine's stepper)
            let nb = p.sys.ids.len();
            for slot in 0..nb {
                atol[p.at + 2 * slot] = tol * p.sys.disc(slot).spline.half_play_rad();
                atol[p.at + 2 * slot + 1] = tol;
            }
            y[p.at..p.at + p.sys.dim()].copy_from_slice(&p.sys.initial_state());
        }
        for (i, b) in net.bodies.iter().enumerate() {
            y[n + i] = b.initial_speed_rad_s;
        }
        for k in 0..m {
            y[2 * n + k] = net.couplings[k].law().initial_state();
        }
        let kinetic0 = eq.kinetic_j(&y);
        let mut events = 0u64;
        let ybuf = vec![0.0; dim];
        packs::switch(&mut eq.packs, n, 0.0, &mut y, None, obs);
        settle(&mut eq, 0.0, &mut y, &[], obs, &mut events);
        heal_faces(&mut eq, 0.0, &mut y, obs);
        let mut meshes = mesh::Meshes::new(m, dim);
        meshes.switch(&mut eq, 0.0, &y, None, obs);
        let mut stepper = Dopri5::new(dim);
        let mut dy = vec![0.0; dim];
        eq.rhs(0.0, &y, &mut dy);
        stepper.set_start_derivative(&dy);
        let period = if options.record_rate_hz > 0.0 {
            1.0 / options.record_rate_hz
        } else {
            f64::INFINITY
        };
        obs.network_sample(&sample(&mut eq, 0.0, &y));
        packs::emit_samples(&eq.packs, n, 0.0, &y, obs);
        Ok(NetworkStepper {
            breakpoints: net.breakpoints(duration_s),
            next_bp: 0,
            options: *options,
            duration_s,
            atol,
            meshes,
            stepper,
            dense: Dense::default(),
            dy,
            g0: vec![0.0; eq.guard_len()],
            g0_at: f64::NAN,
            g1: vec![0.0; eq.guard_len()],
            ybuf,
            period,
            next_sample: 1,
            t: 0.0,
            now: 0.0,
            pending: None,
            h: options.max_step_s.min(1e-4).min(duration_s.max(1e-12)),
            steps: 0,
            events,
            kinetic0,
            y,
            eq,
        })
    }

    /// The state at the session's time: the integration's, or the pending step's dense
    /// output there.
    fn state_now(&self) -> std::borrow::Cow<'_, [f64]> {
        if self.pending.is_some() {
            let mut y = vec![0.0; self.y.len()];
            self.dense.eval(self.now, &mut y);
            std::borrow::Cow::Owned(y)
        } else {
            std::borrow::Cow::Borrowed(&self.y)
        }
    }

    /// The integration's next step from its time, its events located (`None`: no step to
    /// apply: a rejected try, or the run moved onto a breakpoint or its end). Its steps land
    /// on the signals' breakpoints and the run's end, never on a call's end.
    fn propose(&mut self, obs: &mut dyn Observer) -> Result<Option<Pending>, EngineError> {
        let tol = self.options.tolerance;
        let Self {
            eq,
            y,
            atol,
            breakpoints,
            next_bp,
            stepper,
            dense,
            dy,
            ybuf,
            g0,
            g1,
            g0_at,
            t,
            h,
            duration_s,
            ..
        } = self;
        let bp = breakpoints.get(*next_bp).copied();
        let stop = bp.map_or(*duration_s, |b| b.min(*duration_s));
        let at_bp = bp == Some(stop);
        if !at_bp && stop - *t <= 1e-13 * (1.0 + *t) {
            // the run's end within the events' precision of where the run stands: reached,
            // not a step of 1e-17 s that would count as a collapse (issue 48, item 8)
            *t = stop;
            return Ok(None);
        }
        if at_bp && stop - *t <= 1e-13 * (1.0 + *t) {
            // an event left the run at a breakpoint: the signals jump here
            *t = stop;
            *next_bp += 1;
            *g0_at = f64::NAN;
            g1.iter_mut().for_each(|g| *g = 1.0);
            settle(eq, *t, y, g1, obs, &mut self.events);
            heal_faces(eq, *t, y, obs);
            eq.rhs(*t, y, dy);
            stepper.set_start_derivative(dy);
            return Ok(None);
        }
        let land = *t + *h >= stop * (1.0 - 1e-15);
        let h_try = if land { stop - *t } else { *h };
        let err = {
            let mut f = |tt: f64, yy: &[f64], d: &mut [f64]| eq.rhs(tt, yy, d);
            stepper.try_step(&mut f, *t, y, h_try, atol, tol)
        };
        if !err.is_finite() || h_try < 1e-15 * (1.0 + *t) {
            return Err(EngineError::Diverged {
                t_s: *t,
                reason: format!("the step collapsed to {h_try:e} s (error norm {err})"),
            });
        }
        if err > 1.0 {
            *h = next_step(h_try, err).max(h_try * 0.1);
            return Ok(None);
        }
        stepper.dense_into(*t, y, h_try, dense);
        // events: the first quarter point where a guard turns <= 0
        if *g0_at != *t {
            eq.guards(*t, y, g0);
        }
        let mut event: Option<(f64, f64)> = None; // (ta, tb) bracketing the first crossing
        let mut ta = *t;
        // what the guards read (`Equations::probe_inputs`), each the value the whole state's
        // interpolation gives it
        let inputs = eq.probe_inputs();
        for q in 1..=4 {
            let tq = *t + h_try * f64::from(q) / 4.0;
            let tq = if q == 4 { *t + h_try } else { tq };
            for r in &inputs {
                dense.eval_range(tq, r.clone(), ybuf);
            }
            eq.guards(tq, ybuf, g1);
            if g0.iter().zip(g1.iter()).any(|(a, b)| *a > 0.0 && *b <= 0.0) {
                event = Some((ta, tq));
                break;
            }
            ta = tq;
        }
        let (t_new, at_event) = match event {
            Some((mut a, mut b)) => {
                // bisect the earliest crossing of the guards > 0 at t (`Equations::guards_of`)
                let armed: Vec<bool> = g0.iter().map(|g| *g > 0.0).collect();
                let crossed: Vec<bool> = g1
                    .iter()
                    .zip(&armed)
                    .map(|(g, a)| *a && *g <= 0.0)
                    .collect();
                // the components those guards read (`Equations::guard_inputs`), each the
                // value the whole state's interpolation gives it
                let inputs = eq.guard_inputs(&crossed);
                while b - a > 1e-13 * (1.0 + b) {
                    let mid = 0.5 * (a + b);
                    match &inputs {
                        Some(ranges) => {
                            for r in ranges {
                                dense.eval_range(mid, r.clone(), ybuf);
                            }
                        }
                        None => dense.eval(mid, ybuf),
                    }
                    eq.guards_of(mid, ybuf, g1, &crossed);
                    if g1.iter().zip(&crossed).any(|(g, on)| *on && *g <= 0.0) {
                        b = mid;
                    } else {
                        a = mid;
                    }
                }
                // the guards that crossed, at the instant the run restarts from
                dense.eval(b, ybuf);
                eq.guards(b, ybuf, g1);
                for (g, on) in g1.iter_mut().zip(&armed) {
                    if !on {
                        *g = 1.0;
                    }
                }
                (b, true)
            }
            None => {
                if !land {
                    // the last probe was at the step's end: the next step's start
                    g0.copy_from_slice(g1);
                    *g0_at = *t + h_try;
                }
                g1.iter_mut().for_each(|g| *g = 1.0);
                (*t + h_try, land)
            }
        };
        let landed = land && event.is_none();
        Ok(Some(Pending {
            h_try,
            err,
            t_new,
            end: if landed { stop } else { t_new },
            landed,
            at_bp,
            at_event,
        }))
    }

    /// Applies the step `p` taken by [`Self::propose`] (its contacts observed, its samples
    /// sent, its events switched, the thermal windows it reached closed), or with `cut` only
    /// its part up to `cut` (s, inside it: the state there from its dense output, as at an
    /// event, the caller restarting the integration there).
    fn apply(
        &mut self,
        p: Pending,
        cut: Option<f64>,
        obs: &mut dyn Observer,
    ) -> Result<(), EngineError> {
        let Self {
            eq,
            y,
            meshes,
            next_bp,
            stepper,
            dense,
            dy,
            ybuf,
            g1,
            g0_at,
            t,
            h,
            ..
        } = self;
        let t_new = cut.unwrap_or(p.t_new);
        meshes.observe(eq, dense, *t, t_new);
        packs::observe(&mut eq.packs, dense, *t, t_new, ybuf);
        // samples up to t_new from the dense output
        while (self.next_sample as f64) * self.period <= t_new
            && (self.next_sample as f64) * self.period < self.duration_s
        {
            let ts = self.next_sample as f64 * self.period;
            dense.eval(ts, ybuf);
            obs.network_sample(&sample(eq, ts, ybuf));
            packs::emit_samples(&eq.packs, eq.net.bodies.len(), ts, ybuf, obs);
            self.next_sample += 1;
        }
        if t_new < *t + p.h_try {
            dense.eval(t_new, ybuf);
            y.copy_from_slice(ybuf);
        } else {
            y.copy_from_slice(&stepper.y_new);
        }
        // the engines' one guard of a state (issue 48, item 2), as the multibody engine's
        let n = eq.net.bodies.len();
        guard_state(
            *t,
            "the speed of body",
            "rad/s",
            &y[n..2 * n],
            RUNAWAY_SPEED_RAD_S,
        )?;
        let landed = p.landed && cut.is_none();
        *t = if landed { p.end } else { t_new };
        self.steps += 1;
        // the thermal packs' heat of the step, by their faces' modes along it (before the
        // step's switch applies), as a pack run books it
        for pk in eq.packs.iter_mut() {
            if let Some(th) = pk.thermal.as_mut() {
                th.book(&pk.sys, &y[pk.at..pk.at + pk.sys.dim()]);
            }
        }
        if landed && p.at_bp {
            *next_bp += 1;
        }
        if cut.is_some() {
            // the caller restarts the integration here
            *g0_at = f64::NAN;
        } else if p.at_event {
            *g0_at = f64::NAN;
            meshes.switch(eq, *t, y, Some(g1), obs);
            packs::switch(&mut eq.packs, n, *t, y, Some(g1), obs);
            settle(eq, *t, y, g1, obs, &mut self.events);
            heal_faces(eq, *t, y, obs);
            eq.rhs(*t, y, dy);
            stepper.set_start_derivative(dy);
        } else {
            stepper.accept();
            *h = next_step(p.h_try, p.err);
        }
        if packs::close_thermal_windows(eq, *t, obs)? {
            // new viscosity-dependent parameters: the integration restarts from the state
            *g0_at = f64::NAN;
            heal_faces(eq, *t, y, obs);
            eq.rhs(*t, y, dy);
            stepper.set_start_derivative(dy);
        }
        *h = h.min(self.options.max_step_s);
        if obs.wants_open_contacts(*t) {
            let mut open = Vec::new();
            meshes.open(*t, &mut open);
            for pk in &eq.packs {
                pk.open(*t, &mut open);
            }
            obs.open_contacts(*t, &open);
        }
        Ok(())
    }

    /// Ends the run where it stands (a step taken past the session's time ended there, as
    /// [`Self::set_input`] ends it): the open mesh contacts closed, the last sample sent to
    /// `obs`, and the run's heat, energy balance and counts.
    pub fn finish(mut self, obs: &mut dyn Observer) -> NetworkRun {
        if let Some(p) = self.pending.take() {
            let now = self.now;
            // a state failing the runaway guard here would fail the next step: the run
            // ends with the state it has
            let _ = self.apply(p, Some(now), obs);
        }
        let (t, net) = (self.t, Arc::clone(&self.eq.net));
        let (n, m) = (net.bodies.len(), net.couplings.len());
        self.meshes.finish(&mut self.eq, t, obs);
        for p in self.eq.packs.iter_mut() {
            p.finish(t, obs);
        }
        // the thermal packs' last (partial) windows close at the run's end
        let mut pack_thermal = Vec::new();
        for p in self.eq.packs.iter_mut() {
            if let Some(th) = p.thermal.as_mut() {
                let windows = th.windows();
                let report = th.finish(t);
                if th.windows() != windows {
                    obs.pack_temperatures(p.k, t, th.temperatures_k());
                }
                pack_thermal.push((p.k, report));
            }
        }
        let last = sample(&mut self.eq, t, &self.y);
        obs.network_sample(&last);
        packs::emit_samples(&self.eq.packs, n, t, &self.y, obs);
        let y = &self.y;
        let c0 = 2 * n + m; // the counters
        let mut heat = y[c0..c0 + m].to_vec();
        let (mut mesh_work, mut damper_loss, mut spring_change) = (0.0, 0.0, 0.0);
        let mut clutch_heat = 0.0;
        for (k, h) in heat.iter_mut().enumerate() {
            let law = net.couplings[k].law();
            match law.energy_term() {
                EnergyTerm::ClutchHeat => clutch_heat += *h,
                EnergyTerm::MeshWork => mesh_work += *h,
                EnergyTerm::DamperLoss => {
                    damper_loss += *h;
                    spring_change += law.potential_change_j(y[2 * n + k]).unwrap_or(0.0);
                }
                EnergyTerm::None => *h = 0.0,
            }
        }
        for p in &self.eq.packs {
            heat[p.k] = p.face_heat_j(y);
        }
        let energy = NetworkEnergy {
            drive_work_j: y[c0 + m],
            load_work_j: y[c0 + m + 1],
            drag_loss_j: y[c0 + m + 2],
            clutch_heat_j: clutch_heat,
            mesh_work_j: mesh_work,
            damper_loss_j: damper_loss,
            spring_energy_change_j: spring_change,
            pack_loss_j: self.eq.packs.iter().map(|p| p.loss_j(y)).sum(),
            kinetic_change_j: self.eq.kinetic_j(y) - self.kinetic0,
            prescribed_work_j: if self.eq.counters == 4 {
                y[c0 + m + 3]
            } else {
                0.0
            },
        };
        NetworkRun {
            last,
            heat_j: heat,
            energy,
            steps: self.steps,
            events: self.events,
            pack_thermal,
        }
    }
}

/// The session every engine's network run is to its callers (the sdk holds either engine's).
impl NetworkSession for NetworkStepper {
    /// The time the run stands at, s: the last call's end (the integration may have taken
    /// its step past it: the type's docs).
    fn time_s(&self) -> f64 {
        self.now
    }

    /// The network as run (with the inputs set so far in place of the scene's signals).
    fn network(&self) -> &Network {
        &self.eq.net
    }

    /// The temperatures of the thermal resolved pack that is coupling `k` at its last thermal
    /// window's end, K: its discs', its plates', then its oil's (`None` for another
    /// coupling). A window closes at the end of the integration's step that reaches it, as
    /// in the whole run (with a step taken past the session's time, a window ending inside
    /// it closes when the step is applied).
    fn pack_temperatures_k(&self, k: usize) -> Option<&[f64]> {
        let p = self.eq.packs.iter().find(|p| p.k == k)?;
        p.thermal.as_ref().map(|th| th.temperatures_k())
    }

    /// The state now as a sample (every body's angle and speed, every coupling's torque and
    /// a clutch's mode), at the session's time: from the pending step's dense output when
    /// the integration has taken its step past it.
    fn sample_now(&mut self) -> NetworkSample {
        if self.pending.is_some() {
            self.dense.eval(self.now, &mut self.ybuf);
            return sample(&mut self.eq, self.now, &self.ybuf);
        }
        sample(&mut self.eq, self.t, &self.y)
    }

    /// Heat of each clutch, work done on each gear mesh, or each damper's loss, since t = 0,
    /// J, by coupling (0 for an ideal gear), at the session's time.
    fn heat_j(&self) -> Vec<f64> {
        let y = self.state_now();
        let (n, m) = (self.eq.net.bodies.len(), self.eq.net.couplings.len());
        let c0 = 2 * n + m;
        (0..m)
            .map(|k| {
                let c = &self.eq.net.couplings[k];
                if c.law().energy_term() == EnergyTerm::None {
                    0.0
                } else {
                    y[c0 + k]
                }
            })
            .enumerate()
            .map(|(k, h)| {
                self.eq
                    .packs
                    .iter()
                    .find(|p| p.k == k)
                    .map_or(h, |p| p.face_heat_j(&y))
            })
            .collect()
    }

    /// Sets `input` to `value` from now on (N m, N, Pa or rad/s): the scene's signal is replaced
    /// by the held value, and the run restarts here as at a jump of a signal (a step taken past
    /// the session's time ended at it from its dense output, a speed's jump given to the state,
    /// the modes settled, events sent to `obs`). A value that is not finite, a negative force,
    /// or an input naming a body or coupling that cannot take it is refused, the run's state
    /// and inputs as they were (the step in progress is ended at the session's time all the same).
    fn set_input(
        &mut self,
        input: NetworkInput,
        value: f64,
        obs: &mut dyn Observer,
    ) -> Result<(), EngineError> {
        if let Some(p) = self.pending.take() {
            // the old input holds up to the session's time: the step ends there
            self.apply(p, Some(self.now), obs)?;
        }
        let n = self.eq.net.bodies.len();
        Arc::make_mut(&mut self.eq.net).hold_input(input, value, self.t, &self.y[..n])?;
        super::packs::jump_speed(&self.eq.packs, &mut self.y, n, input, value);
        if let NetworkInput::PackPressure(k) = input {
            // the pack's equations carry their own model: its piston's pressure held too
            let pack = self.eq.net.couplings[k].pack().expect("a pack").clone();
            if let Some(p) = self.eq.packs.iter_mut().find(|p| p.k == k) {
                p.set_pack(Arc::new(pack));
            }
        }
        // the signal's breakpoints after now are those of the network as it is now
        let t = self.t;
        self.breakpoints = self.eq.net.breakpoints(self.duration_s);
        self.next_bp = self.breakpoints.partition_point(|&b| b <= t);
        self.g1.iter_mut().for_each(|g| *g = 1.0);
        self.g0_at = f64::NAN;
        settle(
            &mut self.eq,
            t,
            &mut self.y,
            &self.g1,
            obs,
            &mut self.events,
        );
        heal_faces(&mut self.eq, t, &mut self.y, obs);
        self.eq.rhs(t, &self.y, &mut self.dy);
        self.stepper.set_start_derivative(&self.dy);
        Ok(())
    }

    /// Advances to `t_end` s (at most the run's end); samples, clutch events and mesh impacts
    /// go to `obs` as the steps are applied. The steps are the whole run's: the one that
    /// passes `t_end` waits (the type's docs), unless it ends within the events' precision
    /// of `t_end` (frames added up by a host: 0.1 after ten of 0.01 is 0.09999999999999999;
    /// the run then stands at the step's end). Stops early (without error) when `obs` asks
    /// to ([`Observer::progress`]).
    fn advance_to(&mut self, t_end: f64, obs: &mut dyn Observer) -> Result<(), EngineError> {
        let t_end = t_end.min(self.duration_s);
        loop {
            if let Some(p) = self.pending {
                if p.end > t_end + 1e-13 * (1.0 + t_end) {
                    // the call ends inside the step: it waits for a later call
                    self.now = self.now.max(t_end);
                    return Ok(());
                }
                self.pending = None;
                self.apply(p, None, obs)?;
                if obs.progress(self.t) {
                    break;
                }
                continue;
            }
            if self.t >= t_end {
                break;
            }
            self.pending = self.propose(obs)?;
        }
        self.now = self.t;
        Ok(())
    }

    fn finish_boxed(self: Box<Self>, obs: &mut dyn Observer) -> NetworkRun {
        NetworkStepper::finish(*self, obs)
    }

    fn boxed_clone(&self) -> Box<dyn NetworkSession> {
        Box::new(self.clone())
    }
}

/// A step taken and its events located, not yet applied ([`NetworkStepper::propose`],
/// [`NetworkStepper::apply`]).
#[derive(Clone, Copy)]
struct Pending {
    /// Its length, s, and its error norm (at most 1: accepted).
    h_try: f64,
    err: f64,
    /// Where it ends, s: its first event's instant, else its start plus `h_try`.
    t_new: f64,
    /// The time the run stands at once it is applied, s (a step landing on a breakpoint or
    /// the run's end: exactly there).
    end: f64,
    /// Whether it lands on its stop (a breakpoint or the run's end) without an event.
    landed: bool,
    /// Whether its stop is a breakpoint.
    at_bp: bool,
    /// Whether the run restarts at its end (an event, or a landing).
    at_event: bool,
}

/// Settles the packs' faces that an event or a settling left switching (their guards not
/// positive: `packs::heal`), until none is (at most a few rounds: each settles faces whose
/// neighbours' changes moved them).
fn heal_faces(eq: &mut Equations, t: f64, y: &mut [f64], obs: &mut dyn Observer) {
    if eq.packs.iter().all(|p| p.sys.faces.is_empty()) {
        return;
    }
    let mut g = vec![0.0; eq.guard_len()];
    let n = eq.net.bodies.len();
    for _ in 0..4 {
        eq.guards(t, y, &mut g);
        if !packs::heal(&mut eq.packs, n, t, y, &g, obs) {
            break;
        }
    }
}
