//! A network scene's run advanced call by call (MODEL.md section 8, "Inputs"): every drive
//! torque and clutch normal force has one public name, the caller sets the inputs it drives
//! between calls (each held from the instant it is set, as the pack's co-simulation holds its
//! inputs: docs/DECISIONS.md "Co-simulation"), and the outputs (every body's speed and angle,
//! every coupling's torque, a clutch's slip, mode and heat) are read by name. The one
//! co-simulation layer ([`crate::CoSimulation`]: the FMU, Python's `Simulation`) runs a
//! network scene through it. Either engine runs it: the reference engine's
//! [`clutchpack_reference::network::NetworkStepper`] or the multibody engine's
//! [`clutchpack_multibody::network::NetworkStepper`] (at the fixed step
//! [`crate::network::multibody_step_s`], as a whole run of the scene).

use crate::network::{
    conclude, engine_failed, multibody_step_s, reference_options, start_recording, NetworkOutcome,
};
use crate::network_keep::{Keep, Obs};
use crate::{Error, RecordingRequest, Result};
use clutchpack_model::network::{
    ClutchMode, Network, NetworkInput, NetworkSample, NetworkSession, OutputQuantity, Transmission,
};
use clutchpack_model::{EngineError, Observer};
use clutchpack_multibody::network::{NetworkStepOptions, NetworkStepper as MultibodyStepper};
use clutchpack_reference::network::NetworkStepper as ReferenceStepper;
use clutchpack_scene::{EngineChoice, Scene};
use std::sync::atomic::AtomicBool;

/// A network run on either engine, advanced call by call: the engine it runs on and its
/// session ([`NetworkSession`], which both engines' steppers implement with the same
/// semantics: MODEL.md section 8, "Inputs"), boxed (1 kB and, with its rapier world, 7.5 kB).
struct Stepper {
    engine: EngineChoice,
    run: Box<dyn NetworkSession>,
}

impl Clone for Stepper {
    fn clone(&self) -> Self {
        Stepper {
            engine: self.engine,
            run: self.run.boxed_clone(),
        }
    }
}

impl Stepper {
    /// Starts `net` at t = 0 on `engine` for a run of `duration_s` s, at the scene's settings
    /// (as [`crate::Simulation::run`] runs it whole).
    fn new(
        scene: &Scene,
        net: &Network,
        engine: EngineChoice,
        duration_s: f64,
        obs: &mut dyn Observer,
    ) -> std::result::Result<Stepper, EngineError> {
        let run: Box<dyn NetworkSession> = match engine {
            EngineChoice::Reference => {
                let options = reference_options(scene);
                Box::new(ReferenceStepper::new(net, duration_s, &options, obs)?)
            }
            EngineChoice::Multibody => {
                let options = NetworkStepOptions {
                    step_s: multibody_step_s(scene),
                    record_rate_hz: scene.simulation.record_rate_hz,
                };
                Box::new(MultibodyStepper::new(net, duration_s, &options, obs)?)
            }
        };
        Ok(Stepper { engine, run })
    }

    /// The engine running it.
    fn engine(&self) -> EngineChoice {
        self.engine
    }
}

impl std::ops::Deref for Stepper {
    type Target = dyn NetworkSession;
    fn deref(&self) -> &Self::Target {
        &*self.run
    }
}

impl std::ops::DerefMut for Stepper {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut *self.run
    }
}

/// One variable of a network co-simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct NetworkVariable {
    /// Its public name (`bodies.<body>.speed_rad_s`, `couplings.<clutch>.normal_force_n`).
    pub name: String,
    /// `input` or `output`.
    pub causality: &'static str,
    /// Its SI unit, as the FMU's unit definitions name it (`rad/s`, `N.m`, `N`, `J`, `1`).
    pub unit: &'static str,
    /// What it is, with its sign.
    pub description: String,
}

/// The inputs of `net` by their public names: each prescribed body's speed
/// (`bodies.<body>.speed_rad_s`, rad/s: a body with `[bodies.speed]`, as a one-pack scene's
/// `shaft.speed_rad_s`), the drive torque of each turning body the scene
/// drives (`bodies.<body>.drive_torque_n_m`, N m: a body with `[bodies.drive]` or
/// `[bodies.firing]`; give a body `drive = 0` to make it an input), each clutch's normal
/// force (`couplings.<clutch>.normal_force_n`, N) and each resolved pack's piston pressure
/// (`couplings.<pack>.pressure_pa`, Pa; a pack with a `[stack]`).
pub fn network_inputs(net: &Network) -> Vec<(String, NetworkInput)> {
    let bodies = net.bodies.iter().enumerate().flat_map(|(i, b)| {
        let speed = b.prescribed().map(|_| {
            (
                format!("bodies.{}.speed_rad_s", segment(&b.name)),
                NetworkInput::Speed(i),
            )
        });
        let drive = (!b.is_fixed() && (b.drive.is_some() || b.firing.is_some())).then(|| {
            (
                format!("bodies.{}.drive_torque_n_m", segment(&b.name)),
                NetworkInput::Drive(i),
            )
        });
        speed.into_iter().chain(drive)
    });
    // each element's own input (its law's), those of one kind together in the order the
    // inputs are listed (clutches' forces, then packs' pressures), each kind by coupling
    let mut elements: Vec<(String, NetworkInput)> = net
        .couplings
        .iter()
        .enumerate()
        .filter_map(|(k, c)| {
            let spec = c.law().input()?;
            Some((
                format!("couplings.{}.{}", segment(&c.name), spec.suffix),
                (spec.input)(k),
            ))
        })
        .collect();
    elements.sort_by_key(|(_, input)| input.rank());
    bodies.chain(elements).collect()
}

/// A body's or coupling's name as a segment of a variable's name: the FMI structured name's
/// (`K2`, `'input-1'`: [`crate::cosim::fmi_name_segment`]); a name FMI cannot write (outside
/// ASCII) is kept as it is (an FMU of it is refused: [`network_name_problems`]).
fn segment(name: &str) -> String {
    crate::cosim::fmi_name_segment(name).unwrap_or_else(|_| name.to_string())
}

/// Why `net`'s names cannot be an FMU's variable names (empty: they can).
pub fn network_name_problems(net: &Network) -> Vec<String> {
    let names = net.bodies.iter().map(|b| &b.name);
    names
        .chain(net.couplings.iter().map(|c| &c.name))
        .filter_map(|n| {
            crate::cosim::fmi_name_segment(n)
                .err()
                .map(|e| e.to_string())
        })
        .collect()
}

/// The value of `input` in `net` at `t` (s): a prescribed body's speed (rad/s), a drive
/// signal's torque (N m, without the firing harmonics, which stay locked to the angle), a
/// clutch's normal force (N) or a pack's piston pressure (Pa).
fn input_value(net: &Network, input: NetworkInput, t: f64) -> f64 {
    match input {
        NetworkInput::Drive(i) => net.bodies[i].drive.as_ref().map_or(0.0, |s| s.value(t)),
        NetworkInput::Speed(i) => net.bodies[i].prescribed().map_or(0.0, |p| p.speed(t)),
        NetworkInput::ClutchForce(k) | NetworkInput::PackPressure(k) => {
            net.couplings[k].law().input_value(t)
        }
    }
}

/// The variable of the input `input` of `net`, named `name`.
fn input_variable(net: &Network, name: &str, input: NetworkInput) -> NetworkVariable {
    let (unit, description) = match input {
        NetworkInput::Drive(i) => (
            "N.m",
            format!(
                "drive torque on {}, N m (positive in its sense of rotation; its firing \
                 harmonics add to it)",
                net.bodies[i].name
            ),
        ),
        NetworkInput::Speed(i) => (
            "rad/s",
            format!(
                "speed of the prescribed {} (positive in its sense of rotation); its angle \
                 integrates it",
                net.bodies[i].name
            ),
        ),
        NetworkInput::ClutchForce(k) | NetworkInput::PackPressure(k) => {
            let c = &net.couplings[k];
            c.law().input().map_or(("", String::new()), |spec| {
                (spec.unit, spec.description.replacen("{}", &c.name, 1))
            })
        }
    };
    NetworkVariable {
        name: name.to_string(),
        causality: "input",
        unit,
        description,
    }
}

/// The inputs named in `drive` (public names, [`network_inputs`]) of the network `net` of the
/// scene `scene`, as indices into [`network_inputs`]' list, in the order named: a name that
/// is not one of its inputs, or one named twice, is bad input naming it (and the inputs).
pub(crate) fn driven_inputs(scene: &str, net: &Network, drive: &[String]) -> Result<Vec<usize>> {
    let all_inputs = network_inputs(net);
    let mut driven = Vec::with_capacity(drive.len());
    for name in drive {
        let Some(j) = all_inputs.iter().position(|(n, _)| n == name) else {
            let names: Vec<&str> = all_inputs.iter().map(|(n, _)| n.as_str()).collect();
            return Err(Error::BadInput(format!(
                "drive: {name:?} is not an input of {scene}; its inputs are {}",
                names.join(", ")
            )));
        };
        if driven.contains(&j) {
            return Err(Error::BadInput(format!(
                "drive: {name:?} is named twice; name each input once"
            )));
        }
        driven.push(j);
    }
    Ok(driven)
}

/// Every input of `net` as a variable, with its value at t = 0 in the scene (what an FMU's
/// input holds until its host sets it).
pub fn network_input_variables(net: &Network) -> Vec<(NetworkVariable, f64)> {
    network_inputs(net)
        .into_iter()
        .map(|(name, input)| {
            (
                input_variable(net, &name, input),
                input_value(net, input, 0.0),
            )
        })
        .collect()
}

/// The outputs of `net`, in the order [`NetworkSimulation::outputs`] gives their values: per
/// body its speed and angle (and a prescribed body's reaction torque,
/// `bodies.<body>.reaction_torque_n_m`, N m); per coupling its torque on body a, for a clutch its slip
/// `w_b - w_a`, its mode (Modelica's numbers) and its heat, for a resolved pack its faces'
/// heat and, if it carries temperatures (`[thermal]`), each disc's, plate's and its oil's
/// (`couplings.<pack>.discs[i].temperature_k`, `.plates[j].temperature_k`,
/// `.oil.temperature_k`, K).
pub fn network_outputs(net: &Network, tr: Option<&Transmission>) -> Vec<NetworkVariable> {
    let var = |name: String, unit: &'static str, description: String| NetworkVariable {
        name,
        causality: "output",
        unit,
        description,
    };
    let mut out = Vec::new();
    for b in &net.bodies {
        out.push(var(
            format!("bodies.{}.speed_rad_s", segment(&b.name)),
            "rad/s",
            format!("speed of {}, rad/s", b.name),
        ));
        out.push(var(
            format!("bodies.{}.angle_rad", segment(&b.name)),
            "rad",
            format!("angle of {} from t = 0, rad", b.name),
        ));
        if b.prescribed().is_some() {
            out.push(var(
                format!("bodies.{}.reaction_torque_n_m", segment(&b.name)),
                "N.m",
                format!(
                    "torque keeping {} at its prescribed speed, N m, positive in its sense \
                     of rotation (the couplings' on it, reversed)",
                    b.name
                ),
            ));
        }
    }
    for (k, c) in net.couplings.iter().enumerate() {
        out.push(var(
            format!("couplings.{}.torque_n_m", segment(&c.name)),
            "N.m",
            format!("torque of {} on its body a, N m", c.name),
        ));
        for spec in c.law().outputs() {
            out.push(var(
                format!("couplings.{}.{}", segment(&c.name), spec.suffix),
                spec.unit,
                spec.description.replacen("{}", &c.name, 1),
            ));
        }
        if let (Some(own), true) = (c.law().own_bodies(), net.pack_thermal.contains_key(&k)) {
            // as a thermal pack scene's own outputs name them, under the coupling
            let lists = [("discs", own.discs.len()), ("plates", own.plates.len())];
            for (list, n) in lists {
                for i in 0..n {
                    out.push(var(
                        format!("couplings.{}.{list}[{i}].temperature_k", segment(&c.name)),
                        "K",
                        format!(
                            "{list}[{i}] of pack {}: its lumped temperature at the last \
                             thermal window's end, K",
                            c.name
                        ),
                    ));
                }
            }
            out.push(var(
                format!("couplings.{}.oil.temperature_k", segment(&c.name)),
                "K",
                format!(
                    "the oil of pack {}: its temperature at the last thermal window's end, K",
                    c.name
                ),
            ));
        }
    }
    if tr.is_some() {
        out.push(var(
            "transmission.gear".into(),
            "1",
            "the gear engaged: its index in [[transmission.gears]] (0 the first; the 8-speed's \
             R is 0, its 1st 1), -1 while none is (a shift's inertia phase)"
                .into(),
        ));
    }
    out
}

/// A network run advanced call by call, with the inputs the caller drives set between calls.
pub struct NetworkSimulation {
    scene: Scene,
    stepper: Stepper,
    keep: Keep,
    /// The driven inputs, by name.
    driven: Vec<(String, NetworkInput)>,
    /// Every input the network has, by name (to name them in errors).
    all_inputs: Vec<(String, NetworkInput)>,
    started: std::time::Instant,
    /// Set when an engine failure left the run unusable.
    failed: bool,
    /// This run's number (`crate::cosim::next_run`): its saved states carry it, and only
    /// they restore into it.
    run: u64,
}

/// A saved state of a [`NetworkSimulation`] (without a recording): it belongs to the run
/// that saved it and restores only into it.
pub struct SavedNetworkSimulation {
    stepper: Stepper,
    keep: Keep,
    /// The run that saved it.
    run: u64,
    /// That run's scene, for messages.
    scene: String,
}

impl NetworkSimulation {
    /// Starts the network scene `scene` at t = 0 on `engine` (else the scene's choice, else
    /// the reference engine), the caller driving the inputs named in `drive` (their public
    /// names, [`network_inputs`]; each holds the scene's value at t = 0 until it is set),
    /// recording to `recording` if asked, the run ending at `stop_time_s` if given (else the
    /// scene's duration). Unknown names or a pack scene are bad input.
    pub fn start(
        scene: &Scene,
        engine: Option<EngineChoice>,
        drive: &[String],
        recording: Option<&RecordingRequest>,
        stop_time_s: Option<f64>,
    ) -> Result<NetworkSimulation> {
        let Some(net) = &scene.network else {
            return Err(Error::BadInput(format!(
                "{} is a pack scene, not a network ([[bodies]])",
                scene.name
            )));
        };
        let engine = scene.engine(engine, &scene.name)?;
        let all_inputs = network_inputs(net);
        let driven: Vec<(String, NetworkInput)> = driven_inputs(&scene.name, net, drive)?
            .into_iter()
            .map(|j| all_inputs[j].clone())
            .collect();
        let duration = match stop_time_s {
            Some(t) if t.is_finite() && t > 0.0 => t,
            Some(t) => {
                return Err(Error::BadInput(format!(
                    "stop_time = {t}: expected a finite number of seconds > 0"
                )))
            }
            None => scene.simulation.duration_s,
        };
        let driven_names: Vec<String> = driven.iter().map(|(n, _)| n.clone()).collect();
        let mut keep = Keep::new(
            start_recording(scene, engine, recording, Some((&driven_names, stop_time_s)))?,
            false,
        )
        .with_packs(scene, false, None);
        let started = std::time::Instant::now();
        let mut obs = Obs {
            keep: &mut keep,
            stop: None,
            progress: None,
        };
        let mut stepper = Stepper::new(scene, net, engine, duration, &mut obs)
            .map_err(|source| engine_failed(scene, engine, &mut keep, source))?;
        // a driven input holds the scene's value at t = 0 until it is set
        let mut obs = Obs {
            keep: &mut keep,
            stop: None,
            progress: None,
        };
        for (_, input) in &driven {
            let v = input_value(net, *input, 0.0);
            stepper
                .set_input(*input, v, &mut obs)
                .map_err(|e| Error::BadInput(e.to_string()))?;
        }
        Ok(NetworkSimulation {
            scene: scene.clone(),
            stepper,
            keep,
            driven,
            all_inputs,
            started,
            failed: false,
            run: crate::cosim::next_run(),
        })
    }

    /// Every variable: the driven inputs, then the outputs ([`Self::outputs`]'s names, but a
    /// driven prescribed body's speed, which is its input's).
    pub fn variables(&self) -> Vec<NetworkVariable> {
        let net = self.stepper.network();
        let mut out: Vec<NetworkVariable> = self
            .driven
            .iter()
            .map(|(name, input)| input_variable(net, name, *input))
            .collect();
        // a driven prescribed body's speed is its input (as a one-pack scene's shaft's)
        let outputs = network_outputs(net, self.scene.transmission.as_ref());
        out.extend(
            outputs
                .into_iter()
                .filter(|o| !self.driven.iter().any(|(n, _)| *n == o.name)),
        );
        out
    }

    /// The time the run stands at, s.
    pub fn time_s(&self) -> f64 {
        self.stepper.time_s()
    }

    /// Tooth impacts closed so far: the gear meshes' and the resolved packs' bodies'
    /// together (a pack session's [`crate::Session::impact_count`], for a network).
    pub fn impact_count(&self) -> u64 {
        self.keep.impacts.values().map(|m| m.0).sum()
    }

    /// The engine running it.
    pub fn engine(&self) -> EngineChoice {
        self.stepper.engine()
    }

    /// The scene being run.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Sets the driven input `name` to `value` (N m, N, Pa or rad/s), held from now on (a
    /// prescribed body's speed from its angle now: [`Network::hold_input`]). An input that is
    /// not driven (or not one of the network's), a value that is not finite, or a negative
    /// force is bad input; the run is unchanged then. A value equal to the input's now (a
    /// held speed set again) changes nothing: the run goes on as if it had not been set.
    pub fn set_input(&mut self, name: &str, value: f64) -> Result<()> {
        self.usable()?;
        let Some((_, input)) = self.driven.iter().find(|(n, _)| n == name) else {
            let why = if self.all_inputs.iter().any(|(n, _)| n == name) {
                "is not driven (name it in `drive` when the simulation starts)"
            } else {
                "is not an input of this network"
            };
            let names: Vec<&str> = self.driven.iter().map(|(n, _)| n.as_str()).collect();
            return Err(Error::BadInput(format!(
                "{name:?} {why}; the driven inputs are [{}]",
                names.join(", ")
            )));
        };
        crate::cosim::inputs::check_network_input(*input, name, value)?;
        // held from the start: its value set again is not passed on (docs/DECISIONS.md)
        if input_value(self.stepper.network(), *input, self.time_s()) == value {
            return Ok(());
        }
        let mut obs = Obs {
            keep: &mut self.keep,
            stop: None,
            progress: None,
        };
        self.stepper
            .set_input(*input, value, &mut obs)
            .map_err(|e| {
                Error::BadInput(format!(
                    "{name} = {}: {e}",
                    clutchpack_model::fmt_num(value)
                ))
            })
    }

    /// Advances to `t` s (at most the run's end); `stop` stops it early (a signal; the run
    /// then stands at an earlier time with everything before kept). An engine failure leaves
    /// the run unusable but for [`Self::finish`].
    pub fn advance_to(&mut self, t: f64, stop: Option<&AtomicBool>) -> Result<()> {
        self.advance_polled(t, stop, None)
    }

    /// [`Self::advance_to`] with `progress` called at the engine's progress polls with the
    /// simulated time reached, s: a front end's own stop check on the calling thread
    /// (Python's signals), so that a call needs no second thread to stay interruptible.
    pub fn advance_polled<'a>(
        &mut self,
        t: f64,
        stop: Option<&'a AtomicBool>,
        progress: Option<&'a mut dyn FnMut(f64)>,
    ) -> Result<()> {
        self.usable()?;
        if !t.is_finite() || t < self.time_s() {
            return Err(Error::BadInput(format!(
                "advance_to({t}): expected a time >= the current {} s",
                self.time_s()
            )));
        }
        let mut obs = Obs {
            keep: &mut self.keep,
            stop,
            progress,
        };
        if let Err(source) = self.stepper.advance_to(t, &mut obs) {
            self.failed = true;
            let engine = self.stepper.engine();
            return Err(engine_failed(&self.scene, engine, &mut self.keep, source));
        }
        if let Some(e) = self.keep.take_record_error() {
            self.failed = true;
            return Err(e.into());
        }
        Ok(())
    }

    fn usable(&self) -> Result<()> {
        if self.failed {
            return Err(Error::BadInput(format!(
                "{}: the run failed at t = {} s; only finish() remains",
                self.scene.name,
                self.time_s()
            )));
        }
        Ok(())
    }

    /// Every output now, by name, in [`network_outputs`]' order (SI units; [`Self::variables`]
    /// gives each unit).
    pub fn outputs(&mut self) -> Vec<(String, f64)> {
        let values = self.output_values();
        network_outputs(self.stepper.network(), self.scene.transmission.as_ref())
            .into_iter()
            .map(|v| v.name)
            .zip(values)
            .collect()
    }

    /// [`Self::outputs`]' values alone, in their order (a co-simulation reads them at every
    /// communication point; their names, formatted, cost more than the values on a small
    /// network).
    pub fn output_values(&mut self) -> Vec<f64> {
        let s: NetworkSample = self.stepper.sample_now();
        let heat = self.stepper.heat_j();
        let net = self.stepper.network();
        // the elements' modes: a clutch's from the sample, a resolved pack's faces' as kept
        let modes: Vec<Option<ClutchMode>> = (0..net.couplings.len())
            .map(|k| s.mode[k].or_else(|| self.keep.pack_mode(k)))
            .collect();
        let mut values = Vec::new();
        for i in 0..net.bodies.len() {
            values.push(s.speed_rad_s[i]);
            values.push(s.angle_rad[i]);
            if net.bodies[i].prescribed().is_some() {
                values.push(s.reaction_n_m.get(i).copied().unwrap_or(0.0));
            }
        }
        for (k, c) in net.couplings.iter().enumerate() {
            values.push(s.torque_n_m[k]);
            for spec in c.law().outputs() {
                values.push(match spec.quantity {
                    OutputQuantity::Slip => s.speed_rad_s[c.b] - s.speed_rad_s[c.a],
                    OutputQuantity::Mode => {
                        f64::from(modes[k].unwrap_or(ClutchMode::Free).modelica_code())
                    }
                    OutputQuantity::Heat => heat[k],
                });
            }
            // a thermal pack's discs', plates' and oil's temperatures
            if let (Some(own), true) = (c.law().own_bodies(), net.pack_thermal.contains_key(&k)) {
                let bodies = own.len();
                match self.stepper.pack_temperatures_k(k) {
                    Some(t) => values.extend_from_slice(t),
                    None => values.extend(std::iter::repeat_n(f64::NAN, bodies + 1)),
                }
            }
        }
        if let Some(tr) = &self.scene.transmission {
            let engaged = tr.engaged(&modes);
            values.push(engaged.map_or(-1.0, |g| g as f64));
        }
        values
    }

    /// The value now of each driven input, by name (N m or N).
    pub fn input_values(&self) -> Vec<(String, f64)> {
        let net = self.stepper.network();
        let t = self.stepper.time_s();
        self.driven
            .iter()
            .map(|(name, input)| (name.clone(), input_value(net, *input, t)))
            .collect()
    }

    /// Saves the whole state, to [`Self::restore`] later (not while recording: a file cannot
    /// go back in time).
    pub fn save(&self) -> Result<SavedNetworkSimulation> {
        if self.keep.recorder.is_some() {
            return Err(Error::BadInput(
                "save(): not while recording (a recording cannot go back in time)".into(),
            ));
        }
        self.usable()?;
        Ok(SavedNetworkSimulation {
            stepper: self.stepper.clone(),
            keep: self.keep.clone_unrecorded(),
            run: self.run,
            scene: self.scene.name.clone(),
        })
    }

    /// Goes back to a state saved by [`Self::save`] of this run; a state of another run (of
    /// this scene or another) is bad input and leaves the run as it was.
    pub fn restore(&mut self, saved: &SavedNetworkSimulation) -> Result<()> {
        crate::cosim::same_run(saved.run, &saved.scene, self.run, &self.scene.name)?;
        if self.keep.recorder.is_some() {
            return Err(Error::BadInput(
                "restore(): not while recording (a recording cannot go back in time)".into(),
            ));
        }
        self.stepper = saved.stepper.clone();
        self.keep = saved.keep.clone_unrecorded();
        self.failed = false;
        Ok(())
    }

    /// Ends the run where it stands: the summary (`run --summary-json`'s for a network), the
    /// recording finished with it.
    pub fn finish(mut self) -> Result<NetworkOutcome> {
        self.conclude_here()
    }

    /// [`Self::finish`] in place: what the run kept is taken (a recording's file closed and
    /// moved into place), so that dropping it afterwards does nothing more.
    fn conclude_here(&mut self) -> Result<NetworkOutcome> {
        let mut keep = std::mem::take(&mut self.keep);
        let mut obs = Obs {
            keep: &mut keep,
            stop: None,
            progress: None,
        };
        let engine = self.stepper.engine();
        // the engine's finish takes its stepper whole; this one is not used after it
        let run = self.stepper.clone().run.finish_boxed(&mut obs);
        let wall_s = self.started.elapsed().as_secs_f64();
        conclude(&self.scene, engine, keep, run, wall_s)
    }
}

/// A recorded run dropped without [`NetworkSimulation::finish`] (a Python `Simulation`
/// collected, a script that ends) is finished as `finish` would: its recording complete,
/// with its summary, under its own name (as a run stopped by a signal leaves it), not left
/// as a `.partial-` file that only a salvage reads.
impl Drop for NetworkSimulation {
    fn drop(&mut self) {
        if self.keep.recorder.is_some() {
            let _ = self.conclude_here();
        }
    }
}
