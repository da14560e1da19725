//! A driveline network on the multibody engine advanced call by call: [`NetworkStepper`],
//! the method of the module's docs (`mod.rs`: fixed steps landed on the breakpoints, the
//! samples and the events; the modes settled at the start of each step) with inputs set
//! between calls, and [`run_network`], one call to the end.

use super::bodies::NetworkWorld;
use super::mesh::{self, Mesh};
use super::packs::NetPack;
use super::{NetworkStepOptions, Run};
use clutchpack_model::network::{
    Body, ClutchMode, Network, NetworkEnergy, NetworkInput, NetworkRun, NetworkSample,
    NetworkSession,
};
use clutchpack_model::{guard_state, EngineError, Observer, RUNAWAY_SPEED_RAD_S};
use std::sync::Arc;

/// Runs `net` on the multibody engine for `duration_s` seconds; samples and clutch events go
/// to `obs` as they happen. A network with problems ([`Network::problems`]), a duration or a
/// step that is not finite and positive are refused.
pub fn run_network(
    net: &Network,
    duration_s: f64,
    options: &NetworkStepOptions,
    obs: &mut dyn Observer,
) -> Result<NetworkRun, EngineError> {
    let mut run = NetworkStepper::new(net, duration_s, options, obs)?;
    run.advance_to(duration_s, obs)?;
    Ok(run.finish(obs))
}

/// Whether `a` is `b` within the events' precision, `1e-12 (1 + |b|)` s.
fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + b.abs())
}

/// A network run on the multibody engine advanced call by call
/// ([`NetworkStepper::advance_to`]), with inputs set between calls
/// ([`NetworkStepper::set_input`]); [`run_network`] is one call to the end. Every call ends
/// a step at its time, as a breakpoint of the signals does, so a run split into calls
/// differs from the whole run by the steps' placement only (second order in the step).
/// A clone advances as the original, to the bit (the rapier world is copied whole but its
/// workspace, `bodies.rs`): a saved state.
#[derive(Clone)]
pub struct NetworkStepper {
    run: Run,
    /// The longest step, s.
    h_max: f64,
    /// The run's end, s (samples stop there).
    duration_s: f64,
    /// Each body's speed at t = 0, rad/s (the kinetic energy's change at the end).
    w_start: Vec<f64>,
    /// The signals' breakpoints up to the end, s, and the first not yet reached.
    breakpoints: Vec<f64>,
    next_bp: usize,
    /// Sample interval, s (infinite: none but the last), and the next sample's number.
    period: f64,
    next_sample: u64,
    /// The sample time the step from `t` stops at, s (taken before the sample at `t`).
    t_sample: f64,
    /// The longest step the open mesh contacts allow from `t`, s.
    h_contact: f64,
    /// The time the run stands at, s.
    t: f64,
    /// Steps taken.
    steps: u64,
    /// Whether the start of a step at `t` (breakpoints passed, contacts switched, modes
    /// settled, a sample due) is done.
    started: bool,
}

impl NetworkStepper {
    /// Starts `net` at t = 0 for a run of `duration_s` s: the modes settled, the mesh
    /// contacts opened and the first sample sent to `obs`. A network with problems
    /// ([`Network::problems`]), a duration or a step that is not finite and positive, or a
    /// record rate that is not finite and >= 0 are refused.
    pub fn new(
        net: &Network,
        duration_s: f64,
        options: &NetworkStepOptions,
        obs: &mut dyn Observer,
    ) -> Result<NetworkStepper, EngineError> {
        net.check_run(duration_s)?;
        let h_max = options.step_s;
        if !(h_max.is_finite() && h_max > 0.0) {
            return Err(EngineError::Unsupported(format!(
                "step {h_max} s must be finite and > 0"
            )));
        }
        if !(options.record_rate_hz.is_finite() && options.record_rate_hz >= 0.0) {
            return Err(EngineError::Unsupported(format!(
                "record rate {} Hz must be finite and >= 0",
                options.record_rate_hz
            )));
        }
        let n = net.bodies.len();
        let m = net.couplings.len();
        let world = NetworkWorld::build(net);
        let mut run = Run {
            w: world.speeds(),
            inv_inertia: net.bodies.iter().map(Body::inverse_inertia).collect(),
            world,
            modes: (0..m)
                .map(|k| net.couplings[k].law().initial_mode())
                .collect(),
            rows: Vec::new(),
            elimination: Default::default(),
            torque: vec![0.0; n],
            lambda: Vec::new(),
            alpha: Vec::new(),
            coupling_torque: vec![0.0; m],
            meshes: Mesh::of(net),
            mesh_force: Vec::new(),
            packs: Vec::new(),
            columns: (Vec::new(), Vec::new()),
            heat: vec![0.0; m],
            energy: NetworkEnergy::default(),
            events: 0,
            net: Arc::new(net.clone()),
        };
        // the packs' carriers are their bodies' rigid groups at t = 0 (the gears' rows)
        run.build_rows();
        run.packs = NetPack::of(net, &run.w, |i| run.response(i), options)?;
        let mut stepper = NetworkStepper {
            w_start: run.w.clone(),
            run,
            h_max,
            duration_s,
            breakpoints: net.breakpoints(duration_s),
            next_bp: 0,
            period: if options.record_rate_hz > 0.0 {
                1.0 / options.record_rate_hz
            } else {
                f64::INFINITY
            },
            next_sample: 0,
            t_sample: 0.0,
            h_contact: f64::INFINITY,
            t: 0.0,
            steps: 0,
            started: false,
        };
        for p in stepper.run.packs.iter_mut() {
            p.faces_to(0.0, obs);
        }
        stepper.start_step(obs);
        Ok(stepper)
    }

    /// The start of a step at `t` (the module's method, steps 0 and 1): the breakpoints
    /// reached passed (each an event), the mesh contacts opened or closed and the step they
    /// allow taken, the modes settled, and the sample due at `t` sent to `obs`.
    fn start_step(&mut self, obs: &mut dyn Observer) {
        let t = self.t;
        let bps = &self.breakpoints;
        while self.next_bp < bps.len() && bps[self.next_bp] <= t + 1e-12 * (1.0 + t) {
            self.next_bp += 1;
            self.run.events += 1;
        }
        // the first sample at t = 0 whatever the rate (0 x an infinite period is NaN)
        self.t_sample = if self.next_sample == 0 {
            0.0
        } else {
            self.next_sample as f64 * self.period
        };
        // a contact's onset or separation at t (landed on), before the torques at t
        self.h_contact = mesh::start_step(&mut self.run.meshes, t, &self.run.w, obs);
        self.run.settle(t, obs);
        let t_sample = self.t_sample;
        if (near(t, t_sample) || t_sample <= t) && t_sample < self.duration_s && t < self.duration_s
        {
            obs.network_sample(&self.run.sample(t));
            let theta = self.run.world.angles();
            for p in &self.run.packs {
                p.sample_to(t, theta, obs);
            }
            self.next_sample += 1;
        }
        self.started = true;
    }

    /// One step from `t` (the module's method, steps 2 to 5), ending at `t_end` s at the
    /// latest, and its works counted (the module's "Energy").
    fn step(&mut self, t_end: f64, obs: &mut dyn Observer) -> Result<(), EngineError> {
        let t = self.t;
        let t_sample = self.t_sample;
        let stop = self
            .breakpoints
            .get(self.next_bp)
            .copied()
            .unwrap_or(self.duration_s)
            .min(self.duration_s)
            .min(if t_sample > t {
                t_sample
            } else {
                f64::INFINITY
            })
            .min(t_end);
        let h = (stop - t).min(self.h_max).min(self.h_contact).max(0.0);
        let run = &mut self.run;
        // the step's torques: at its midpoint (explicit midpoint rule), landed with them
        let mut h = run.landing(t, h);
        let start = run.total();
        let (mut w_force, mut theta_force) = run.step_torques(t, h, &start);
        let h_mid = run.landing(t, h);
        if h_mid < h {
            h = h_mid;
            (w_force, theta_force) = run.step_torques(t, h, &start);
        }
        // at least 1e-13 (1 + t) s, so that time moves (a landing nearer than that is on
        // the step's end to within the events' own precision)
        h = h.max(1e-13 * (1.0 + t)).min(stop - t);
        let t_force = t + 0.5 * h;
        let t_new = if h == stop - t { stop } else { t + h };
        let h = t_new - t;
        let w0 = run.w.clone();
        let mut total = run.total();
        let mut acc = run.accelerations(&total);
        run.advance_packs(t_new, &mut total, &mut acc, obs)?;
        // the torques the world takes must be numbers (rapier would make a NaN torque's
        // speeds zero, not NaN, and the run would end as if it had integrated)
        guard_state(t, "the torque on body", "N m", &total, f64::INFINITY)?;
        let paths: Vec<mesh::Path> = run
            .meshes
            .iter()
            .map(|mesh| mesh.path(t, h, &w0, &acc))
            .collect();
        run.w = run.world.step(&total, h);
        // a prescribed body moves as its profile says (its angle too, exactly)
        for (i, b) in run.net.bodies.iter().enumerate() {
            if let Some(p) = b.prescribed() {
                let (w, theta) = p.speed_and_angle(t_new);
                run.world.set_prescribed(i, w, theta);
                run.w[i] = w;
            }
        }
        // rapier's speeds keep the rows to rounding; remove it (momentum kept)
        run.elimination.project(&run.inv_inertia, &mut run.w);
        run.world.set_speeds(&run.w);
        // the engines' one guard (issue 48, item 2): a fixed step past its stability limit
        // grows the speeds geometrically; stop with the reference engine's divergence error
        // rather than finish with 1e200-sized and NaN outputs
        guard_state(t, "the speed of body", "rad/s", &run.w, RUNAWAY_SPEED_RAD_S)?;
        let net = Arc::clone(&run.net);
        // the works over the step, with the step's mean speeds (the discrete energy identity)
        for (i, b) in net.bodies.iter().enumerate() {
            if b.prescribed().is_some() {
                // its reaction's work, -T_p (every torque on it, the rows' and the packs'
                // with them) on its mean speed: the discrete energy identity's share of it
                run.energy.prescribed_work_j -= h * total[i] * 0.5 * (w0[i] + run.w[i]);
            }
            if !b.is_free() {
                continue;
            }
            let wbar = 0.5 * (w0[i] + run.w[i]);
            let drive = b.drive_torque_n_m(t_force, theta_force[i]);
            run.energy.drive_work_j += h * drive * wbar;
            let wf = w_force[i];
            run.energy.load_work_j += h * b.road_load.map_or(0.0, |l| l.torque_n_m(wf)) * wbar;
            run.energy.drag_loss_j += h * b.drag_n_m_s_rad * wf * wbar;
        }
        for (k, c) in net.couplings.iter().enumerate() {
            if matches!(run.modes[k], Some(ClutchMode::Slipping(_))) {
                let wrel = 0.5 * (w0[c.b] + run.w[c.b] - w0[c.a] - run.w[c.a]);
                run.heat[k] += h * run.coupling_torque[k] * wrel;
            }
            // a damper's share of the torque held over the step, on the step's mean twist rate
            // (a spring's share is its potential's change, at the end)
            let rate = 0.5 * (w0[c.a] + run.w[c.a] - w0[c.b] - run.w[c.b]);
            let held = w_force[c.a] - w_force[c.b];
            if let Some(loss) = c.law().damping_loss_j(h, held, rate) {
                run.heat[k] += loss;
                run.energy.damper_loss_j += loss;
            }
        }
        for (j, mesh) in run.meshes.iter_mut().enumerate() {
            let work = mesh.advance(&paths[j], &run.w, run.mesh_force[j]);
            run.heat[mesh.coupling] += work;
            run.energy.mesh_work_j += work;
        }
        for p in run.packs.iter_mut() {
            let [ra, rb] = p.reaction;
            let (wa, wb) = (0.5 * (w0[p.a] + run.w[p.a]), 0.5 * (w0[p.b] + run.w[p.b]));
            p.work_in_j -= h * (ra * wa + rb * wb);
            p.faces_to(t_new, obs);
        }
        self.t = t_new;
        self.steps += 1;
        self.started = false;
        Ok(())
    }

    /// Ends the run where it stands: the open mesh contacts closed, the last sample sent to
    /// `obs`, and the run's heat (J), energy balance (the module's "Energy") and counts.
    pub fn finish(mut self, obs: &mut dyn Observer) -> NetworkRun {
        let t = self.t;
        let run = &mut self.run;
        for mesh in &mut run.meshes {
            mesh.finish(t, obs);
        }
        let mut pack_thermal = Vec::new();
        for p in run.packs.iter_mut() {
            if let Some(report) = p.finish(obs) {
                pack_thermal.push((p.k, report));
            }
        }
        let last = run.sample(t);
        obs.network_sample(&last);
        for p in &run.packs {
            p.sample_to(t, run.world.angles(), obs);
        }
        run.energy.clutch_heat_j =
            run.heat.iter().sum::<f64>() - run.energy.damper_loss_j - run.energy.mesh_work_j;
        let net = &run.net;
        let angles = run.world.angles();
        run.energy.spring_energy_change_j = (0..net.couplings.len())
            .filter_map(|k| {
                let c = &net.couplings[k];
                c.law().potential_change_j(angles[c.a] - angles[c.b])
            })
            .sum();
        // per body as J (w - w0) (w + w0) / 2: no cancellation between large energies
        run.energy.kinetic_change_j = net
            .bodies
            .iter()
            .zip(self.w_start.iter().zip(&run.w))
            .filter(|(b, _)| b.is_free())
            .map(|(b, (w0, w))| 0.5 * b.inertia_kg_m2 * (w - w0) * (w + w0))
            .sum();
        // the packs' discs and plates with the bodies; each pack's loss is the carriers' work
        // on it less its bodies' kinetic change (`packs.rs`, "Energy")
        for p in &run.packs {
            let dk = p.kinetic_change_j();
            run.energy.kinetic_change_j += dk;
            run.energy.pack_loss_j += p.work_in_j - dk;
            run.heat[p.k] = p.face_heat_j();
        }
        NetworkRun {
            last,
            heat_j: std::mem::take(&mut run.heat),
            energy: run.energy,
            steps: self.steps,
            events: run.events,
            pack_thermal,
        }
    }
}

/// The session every engine's network run is to its callers (the sdk holds either engine's).
impl NetworkSession for NetworkStepper {
    /// The time the run stands at, s.
    fn time_s(&self) -> f64 {
        self.t
    }

    /// The network as run (with the inputs set so far in place of the scene's signals).
    fn network(&self) -> &Network {
        &self.run.net
    }

    /// The temperatures of the thermal pack that is coupling `k`, K (its discs', plates',
    /// then oil's, as at its last thermal window's end); `None` for another coupling.
    fn pack_temperatures_k(&self, k: usize) -> Option<&[f64]> {
        self.run.packs.iter().find(|p| p.k == k)?.temperatures_k()
    }

    /// The state now as a sample (every body's angle, rad, and speed, rad/s, every
    /// coupling's torque on its body `a`, N m, and a clutch's mode).
    fn sample_now(&mut self) -> NetworkSample {
        self.run.sample(self.t)
    }

    /// Heat of each clutch or resolved pack's faces, work done on each gear mesh, or each
    /// damper's loss, since t = 0, J, by coupling (0 for an ideal gear or a spring-damper's
    /// spring).
    fn heat_j(&self) -> Vec<f64> {
        let mut heat = self.run.heat.clone();
        // a resolved pack's: its faces' (and open gaps') heat so far
        for p in &self.run.packs {
            heat[p.k] = p.face_heat_j();
        }
        heat
    }

    /// Sets `input` to `value` from now on (N m, N, Pa or rad/s; [`Network::hold_input`]): the
    /// scene's signal is replaced by the held value in the stepper's own network, its
    /// breakpoints after now taken again, and the run restarts here as at a jump of a signal
    /// (a speed's jump given to the state, `run_speed_jump`; counted as an event; the
    /// clutches' modes settled at once, MODEL.md section 8, events sent to `obs`). A value that is not finite, a negative force, or an input naming a body or
    /// coupling that cannot take it is refused, the run unchanged.
    fn set_input(
        &mut self,
        input: NetworkInput,
        value: f64,
        obs: &mut dyn Observer,
    ) -> Result<(), EngineError> {
        let t = self.t;
        let run = &mut self.run;
        Arc::make_mut(&mut run.net).hold_input(input, value, t, run.world.angles())?;
        if let NetworkInput::PackPressure(k) = input {
            // the pack's session holds it too (the network's copy keeps the breakpoints)
            if let Some(p) = self.run.packs.iter_mut().find(|p| p.k == k) {
                p.hold_pressure(value)?;
            }
        }
        if let NetworkInput::Speed(i) = input {
            // the body's speed jumps to the value, its angle kept; what a row ties to it
            // follows (momentum kept, as after a step); a pack it carries holds it too
            run_speed_jump(&mut self.run, i, value)?;
        }
        self.breakpoints = self.run.net.breakpoints(self.duration_s);
        self.next_bp = self
            .breakpoints
            .partition_point(|&b| b <= t + 1e-12 * (1.0 + t));
        self.run.events += 1;
        self.run.settle(t, obs);
        Ok(())
    }

    /// Advances to `t_end` s (at most the run's end), a step ending there (within the
    /// events' precision, `1e-12 (1 + t)` s, as the run's end); samples, clutch events and
    /// mesh impacts go to `obs` as they happen. Stops early (without error) when `obs` asks
    /// to ([`Observer::progress`]).
    fn advance_to(&mut self, t_end: f64, obs: &mut dyn Observer) -> Result<(), EngineError> {
        let t_end = t_end.min(self.duration_s);
        loop {
            if !self.started {
                self.start_step(obs);
            }
            if self.t >= t_end || near(self.t, t_end) {
                return Ok(());
            }
            self.step(t_end, obs)?;
            if obs.wants_open_contacts(self.t) {
                let mut open = Vec::new();
                for m in &self.run.meshes {
                    open.extend(m.open(self.t).map(|e| (m.coupling, None, e)));
                }
                for p in &self.run.packs {
                    p.open(&mut open);
                }
                obs.open_contacts(self.t, &open);
            }
            if obs.progress(self.t) {
                self.run.settle(self.t, obs);
                return Ok(());
            }
        }
    }

    fn finish_boxed(self: Box<Self>, obs: &mut dyn Observer) -> NetworkRun {
        NetworkStepper::finish(*self, obs)
    }

    fn boxed_clone(&self) -> Box<dyn NetworkSession> {
        Box::new(self.clone())
    }
}

/// Sets the prescribed body `i`'s speed in `run` to `value` (rad/s; its profile already held,
/// [`Network::hold_input`]), its angle kept: what a row ties to it follows (the speeds
/// projected, momentum kept, as after a step), and a pack carried by it holds the speed too
/// (its session's shaft, from its own angle).
fn run_speed_jump(run: &mut Run, i: usize, value: f64) -> Result<(), EngineError> {
    let angle = run.world.angles()[i];
    run.world.set_prescribed(i, value, angle);
    run.w[i] = value;
    run.elimination.project(&run.inv_inertia, &mut run.w);
    run.world.set_speeds(&run.w);
    let profile = run.net.bodies[i].prescribed().cloned();
    for p in run.packs.iter_mut().filter(|p| p.a == i) {
        if let Some(profile) = &profile {
            p.hold_speed(profile, value)?;
        }
    }
    Ok(())
}
