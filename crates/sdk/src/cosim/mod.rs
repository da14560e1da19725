//! One co-simulated run as a table of variables, shared by every co-simulation front end (the
//! FMU's `fmi2*` functions, Python's `Simulation`): the variable table (`variables.rs`), the
//! inputs by their one public name with their bounds (`inputs.rs`), and [`CoSimulation`],
//! which holds the parameters and inputs as set (values and derivatives, held between
//! communication points: docs/DECISIONS.md "Co-simulation") over a [`Session`], and serves
//! the outputs by value reference or by name. FMI's own rules (its state machine, the host's
//! communication points, pointers) stay in the fmu crate.

pub(crate) mod inputs;
mod network;
mod variables;

pub use inputs::{driven_from_names, driven_names, fmi_name_segment, Input};
pub use variables::{
    uses_unit, variables, BodyField, Causality, ImpactField, InterfaceField, Kind, Quantity,
    Variable, UNCONNECTED, UNITS,
};

use crate::{
    Error, RecordingRequest, Result, RunOutcome, Session, SessionRequest, SessionState, Simulation,
};
use clutchpack_model::session::{Advance, Driven, Inputs, Snapshot};
use clutchpack_record::{RecordOptions, Replace};
use clutchpack_scene::{EngineChoice, Scene};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Numbers every run a co-simulation starts ([`CoSimulation::start`]), process-wide: a saved
/// state names the run it belongs to, and restores only into it.
static RUNS: AtomicU64 = AtomicU64::new(1);

/// A run's number, new for each run started by a co-simulation ([`CoSimulation::start`]) or
/// a network simulation ([`crate::NetworkSimulation::start`]): what its saved states carry.
pub(crate) fn next_run() -> u64 {
    RUNS.fetch_add(1, Ordering::Relaxed)
}

/// The one check that a saved state restores only into the run that saved it: a state saved
/// by run `saved` of the scene `saved_scene`, restored into run `run` of `scene` (0: none
/// started), is refused unless the two runs are one (another instance's, another scene's, or
/// a state from before a reset would make the run another scene's under its own name).
pub(crate) fn same_run(saved: u64, saved_scene: &str, run: u64, scene: &str) -> Result<()> {
    if saved != run || run == 0 {
        return Err(Error::Call(format!(
            "the state was saved by another run (scene {saved_scene:?}; this instance runs \
             {scene:?}): a state restores only into the instance and run that saved it"
        )));
    }
    Ok(())
}

/// Where a co-simulated run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Before [`CoSimulation::start`]: parameters and inputs may be set.
    Setup,
    /// Started: inputs may be set, the run advanced.
    Running,
    /// An engine failure left the run unusable: only reading, finishing, resetting (or
    /// restoring a state saved before).
    Failed,
    /// After [`CoSimulation::finish`]: the final outputs may be read.
    Ended,
}

/// A saved state of a co-simulated run ([`CoSimulation::save`]): it belongs to the run that
/// saved it (between its [`CoSimulation::start`] and its next reset) and restores only into
/// it.
pub struct SavedCoSimulation {
    /// The run that saved it ([`RUNS`]).
    run: u64,
    /// The scene of that run, for messages.
    scene: String,
    session: SavedRun,
    reals: Vec<f64>,
    slopes: Vec<[f64; 2]>,
    snapshot: Snapshot,
    /// A network's outputs and inputs as handed over when saved.
    network: (Vec<f64>, Vec<f64>),
}

/// The engine's state in a [`SavedCoSimulation`]: a pack's session or a network's run.
enum SavedRun {
    // both boxed: the two differ in size by kilobytes
    Pack(Box<SessionState>),
    Network(Box<crate::SavedNetworkSimulation>),
}

/// One co-simulated run of a scene: its variable table with the values set, over a
/// [`Session`] (a pack) or a [`crate::NetworkSimulation`] (a network scene).
pub struct CoSimulation {
    scene: Scene,
    /// The inputs the caller drives.
    driven: Driven,
    vars: Vec<Variable>,
    /// Value of every Real variable by value reference (parameters and inputs as set,
    /// outputs as last computed).
    reals: Vec<f64>,
    /// First and second derivatives of each Real input by value reference (orders 1 and 2),
    /// per s and per s^2; reset to 0 whenever the input's value is set.
    slopes: Vec<[f64; 2]>,
    strings: Vec<String>,
    session: Option<Session>,
    snapshot: Snapshot,
    /// Set when an engine failure left the run unusable.
    failed: bool,
    /// Set by [`CoSimulation::finish`].
    ended: bool,
    /// The finished run (after [`CoSimulation::finish`] of a started run).
    outcome: Option<RunOutcome>,
    /// Every body's damage at the time it was computed (hosts read every output at every
    /// step; the assessment covers all bodies at once).
    damage_cache: std::cell::RefCell<Option<(f64, Vec<f64>)>>,
    /// The run started by the last [`CoSimulation::start`] ([`RUNS`]; 0 before).
    run: u64,
    /// The files the run reads (the FMU's resources, Python's scene file): no output may
    /// name one.
    inputs: Vec<PathBuf>,
    /// A network scene's run, while it goes.
    network: Option<crate::NetworkSimulation>,
    /// A network scene's finished run.
    network_outcome: Option<crate::NetworkOutcome>,
    /// A network's outputs as last computed, in [`crate::network_outputs`]' order.
    network_outputs: Vec<f64>,
    /// A network's inputs as last handed to its run, in [`crate::network_inputs`]' order
    /// (NaN: never, or not driven).
    network_pushed: Vec<f64>,
    /// The scene file, named in a recording ([`CoSimulation::loaded_from`]).
    scene_path: Option<PathBuf>,
}

impl CoSimulation {
    /// A co-simulation of `scene` (engine: the scene's choice, as `clutchpack run` makes
    /// it) driving every input the pack has, as an FMU does.
    pub fn new(scene: Scene) -> Result<CoSimulation> {
        let driven = Driven::all_for(&scene.pack);
        CoSimulation::driving(scene, driven)
    }

    /// A co-simulation of `scene` whose caller drives only `driven` (the other inputs follow
    /// the scene's profiles; Python's `Simulation`). Driving nothing, the run is the scene's
    /// run split into calls. Inputs the pack does not have are an error naming them.
    pub fn driving(scene: Scene, driven: Driven) -> Result<CoSimulation> {
        // a network drives every input it has (`network_inputs`); a pack, what `driven` names
        let driven = if scene.network.is_some() {
            Driven::NONE
        } else {
            driven
                .check(&scene.pack)
                .map_err(|e| Error::BadInput(format!("{}: {e}", scene.name)))?;
            driven
        };
        let engine = scene.engine(None, &scene.name)?;
        let vars = variables(&scene, engine.name(), driven);
        Ok(CoSimulation::with_table(scene, driven, vars))
    }

    /// A co-simulation of `scene` whose caller drives the inputs named in `drive`, the others
    /// following the scene (Python's `Simulation`): a pack's by the FMU's names or their older
    /// aliases ([`driven_from_names`]), a network's by their public names
    /// ([`crate::network_inputs`]: `bodies.<body>.drive_torque_n_m`,
    /// `couplings.<clutch>.normal_force_n`, `couplings.<pack>.pressure_pa`). A name the scene
    /// has no input for, or one named twice, is bad input naming it.
    pub fn driving_named<S: AsRef<str>>(scene: Scene, drive: &[S]) -> Result<CoSimulation> {
        let Some(net) = &scene.network else {
            return CoSimulation::driving(scene, driven_from_names(drive)?);
        };
        let names: Vec<String> = drive.iter().map(|n| n.as_ref().to_string()).collect();
        let driven = crate::network_cosim::driven_inputs(&scene.name, net, &names)?;
        let engine = scene.engine(None, &scene.name)?;
        let vars = variables::network_variables_driving(&scene, engine.name(), &driven);
        Ok(CoSimulation::with_table(scene, Driven::NONE, vars))
    }

    /// A co-simulation of `scene` with the variable table `vars`, before its start.
    fn with_table(scene: Scene, driven: Driven, vars: Vec<Variable>) -> CoSimulation {
        let mut co = CoSimulation {
            driven,
            reals: Vec::new(),
            slopes: Vec::new(),
            strings: Vec::new(),
            vars,
            scene,
            session: None,
            snapshot: Snapshot::default(),
            failed: false,
            ended: false,
            outcome: None,
            damage_cache: Default::default(),
            run: 0,
            inputs: Vec::new(),
            network: None,
            network_outcome: None,
            network_outputs: Vec::new(),
            network_pushed: Vec::new(),
            scene_path: None,
        };
        co.reset();
        co
    }

    /// The files the run reads (the FMU's resources, a scene file), which no output may name.
    pub fn reading(mut self, inputs: Vec<PathBuf>) -> CoSimulation {
        self.inputs = inputs;
        self
    }

    /// The scene file the scene was loaded from, named in a recording of the run (as
    /// `clutchpack run` names it).
    pub fn loaded_from(mut self, path: Option<PathBuf>) -> CoSimulation {
        self.scene_path = path;
        self
    }

    /// Back to the state before [`CoSimulation::start`], every variable at its start value
    /// (a recording in progress is finished with what it holds).
    pub fn reset(&mut self) {
        let count = |k| self.vars.iter().filter(|v| v.kind == k).count();
        let (nr, ns) = (count(Kind::Real), count(Kind::String));
        self.reals = vec![0.0; nr];
        self.slopes = vec![[0.0; 2]; nr];
        self.strings = vec![String::new(); ns];
        for v in &self.vars {
            match v.kind {
                Kind::Real => self.reals[v.vr as usize] = v.start_real.unwrap_or(0.0),
                Kind::String => {
                    self.strings[v.vr as usize] = v.start_string.clone().unwrap_or_default()
                }
                Kind::Integer => {}
            }
        }
        if let Some(s) = self.session.take() {
            let _ = s.finish();
        }
        self.snapshot = Snapshot::default();
        self.failed = false;
        self.ended = false;
        self.outcome = None;
        self.damage_cache.take();
        self.run = 0;
        if let Some(n) = self.network.take() {
            let _ = n.finish();
        }
        self.network_outcome = None;
        self.network_outputs.clear();
        self.network_pushed.clear();
    }

    /// Where the run is.
    pub fn stage(&self) -> Stage {
        if self.ended {
            Stage::Ended
        } else if self.failed {
            Stage::Failed
        } else if self.session.is_some() || self.network.is_some() {
            Stage::Running
        } else {
            Stage::Setup
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The variables.
    pub fn variables(&self) -> &[Variable] {
        &self.vars
    }

    /// The variable of base type `kind` with the value reference `vr`.
    pub fn variable(&self, kind: Kind, vr: u32) -> Result<&Variable> {
        self.vars
            .iter()
            .find(|v| v.kind == kind && v.vr == vr)
            .ok_or_else(|| {
                Error::Call(format!("no {kind:?} variable has the value reference {vr}"))
            })
    }

    /// The value reference of the input `name` (its public name or its older alias); else an
    /// error that lists the inputs this run has.
    pub fn input_named(&self, name: &str) -> Result<u32> {
        let wanted = Input::from_name(name);
        self.vars
            .iter()
            .find(|v| match v.quantity {
                Quantity::Input(i) => wanted == Some(i),
                Quantity::NetworkInput(_) => v.name == name,
                _ => false,
            })
            .map(|v| v.vr)
            .ok_or_else(|| {
                let inputs: Vec<&str> = self
                    .vars
                    .iter()
                    .filter(|v| v.causality == Causality::Input)
                    .map(|v| v.name.as_str())
                    .collect();
                // a network's input its caller chose not to drive (`driving_named`)
                let undriven =
                    self.scene.network.as_ref().is_some_and(|net| {
                        crate::network_inputs(net).iter().any(|(n, _)| n == name)
                    });
                let why = if undriven {
                    "is not driven: name it in `drive` when the simulation starts"
                } else {
                    "is not an input of this simulation"
                };
                Error::Call(format!(
                    "{name:?} {why} (its inputs: {})",
                    if inputs.is_empty() {
                        "none: it follows the scene's profiles".to_string()
                    } else {
                        inputs.join(", ")
                    }
                ))
            })
    }

    fn real_of(&self, q: Quantity) -> f64 {
        self.vars
            .iter()
            .find(|v| v.quantity == q)
            .map_or(0.0, |v| self.reals[v.vr as usize])
    }

    fn string_of(&self, q: Quantity) -> String {
        self.vars
            .iter()
            .find(|v| v.quantity == q)
            .map_or(String::new(), |v| self.strings[v.vr as usize].clone())
    }

    /// The parameter `duration_limit_s`: the latest time the host may advance to, s.
    pub fn duration_limit_s(&self) -> f64 {
        self.real_of(Quantity::DurationLimit)
    }

    /// Sets the String parameter standing for `q` (the engine, the recording's path).
    pub fn set_string_parameter(&mut self, q: Quantity, value: &str) -> Result<()> {
        let vr = self
            .vars
            .iter()
            .find(|v| v.quantity == q && v.kind == Kind::String)
            .map(|v| v.vr)
            .ok_or_else(|| Error::Call(format!("no String parameter stands for {q:?}")))?;
        self.set_string(vr, value)
    }

    /// Starts the run with the parameters and inputs set; steps land on `stop_time_s` if
    /// given. Bad parameters (the engine, the duration limit, a recording path the output
    /// policy refuses) are an error before any work.
    pub fn start(&mut self, stop_time_s: Option<f64>) -> Result<()> {
        if self.stage() != Stage::Setup {
            return Err(Error::Call("the run has already started".into()));
        }
        let engine_name = self.string_of(Quantity::Engine);
        let engine = EngineChoice::from_name(&engine_name).ok_or_else(|| {
            Error::BadInput(format!(
                "engine = {engine_name:?}: expected one of {}",
                EngineChoice::names().join(", ")
            ))
        })?;
        let limit = self.duration_limit_s();
        if !(limit.is_finite() && limit > 0.0) {
            return Err(Error::BadInput(format!(
                "duration_limit_s = {limit}: expected a positive time in s"
            )));
        }
        let path = self.string_of(Quantity::RecordingPath);
        if !path.is_empty() {
            // the one output policy of every front end, before any work
            let inputs: Vec<&Path> = self.inputs.iter().map(PathBuf::as_path).collect();
            clutchpack_record::check_outputs(
                &[clutchpack_record::OutputPath::file(
                    "recording_path",
                    Path::new(&path),
                )],
                &inputs,
            )
            .map_err(|e| {
                Error::BadInput(format!(
                    "{e} (leave recording_path empty to run without a recording)"
                ))
            })?;
        }
        let recording = (!path.is_empty()).then(|| RecordingRequest {
            path: PathBuf::from(&path),
            replace: Replace::Existing,
            options: RecordOptions::default(),
            scene_path: self.scene_path.clone(),
        });
        if self.scene.network.is_some() {
            return self.start_network(engine, recording, stop_time_s);
        }
        let sim = Simulation::new(self.scene.clone(), Some(engine))?;
        let mut session = sim.start(SessionRequest {
            driven: self.driven,
            stop_time_s,
            recording,
            keep_history: false,
        })?;
        if self.driven.any() {
            session.set_inputs(&self.inputs())?;
        }
        self.snapshot = session.snapshot();
        self.session = Some(session);
        self.run = next_run();
        Ok(())
    }

    /// The inputs as set now: the input hold's one translation to the engines' inputs.
    fn inputs(&self) -> Inputs {
        let mut out = Inputs::default();
        for v in &self.vars {
            if let Quantity::Input(i) = v.quantity {
                i.put(
                    &mut out,
                    self.reals[v.vr as usize],
                    self.slopes[v.vr as usize],
                );
            }
        }
        out
    }

    /// Sets a Real variable (`fmi2SetReal`): a parameter before the run starts, an input
    /// (within its scene key's bound) until the run ends, never an output.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<()> {
        let stage = self.stage();
        let v = self.variable(Kind::Real, vr)?;
        match v.causality {
            Causality::Output => Err(Error::Call(format!(
                "{} is an output: it cannot be set",
                v.name
            ))),
            Causality::Parameter if stage != Stage::Setup => Err(Error::Call(format!(
                "{} is a fixed parameter: set it before the run starts \
                 (fmi2ExitInitializationMode)",
                v.name
            ))),
            _ if !value.is_finite() => Err(Error::BadInput(format!(
                "{} = {value}: expected a finite value",
                v.name
            ))),
            Causality::Input if matches!(stage, Stage::Ended | Stage::Failed) => {
                Err(Error::Call(format!("{}: the run has ended", v.name)))
            }
            Causality::Input => {
                match v.quantity {
                    Quantity::Input(i) => i.check(value, "")?,
                    // the bound of the scene key it stands for, checked when set (before the
                    // run starts too: fmi2SetReal answers at once, not at the next step)
                    Quantity::NetworkInput(j) => {
                        let input = self.scene.network.as_ref().and_then(|net| {
                            crate::network_cosim::network_inputs(net)
                                .get(j)
                                .map(|(_, input)| *input)
                        });
                        if let Some(input) = input {
                            crate::cosim::inputs::check_network_input(input, &v.name, value)?;
                        }
                    }
                    _ => {}
                }
                self.reals[vr as usize] = value;
                self.slopes[vr as usize] = [0.0; 2];
                Ok(())
            }
            Causality::Parameter => {
                self.reals[vr as usize] = value;
                self.slopes[vr as usize] = [0.0; 2];
                Ok(())
            }
        }
    }

    /// Sets a derivative of an input (`fmi2SetRealInputDerivatives`): its slope (`order` 1)
    /// or, for the shaft's speed, also its second derivative (`order` 2) over the coming
    /// communication steps, until its value is set again (a first- or second-order hold).
    /// Only the shaft's speed and drive torque take derivatives.
    pub fn set_real_derivative(&mut self, vr: u32, order: i32, value: f64) -> Result<()> {
        let stage = self.stage();
        let v = self.variable(Kind::Real, vr)?;
        let most = match v.quantity {
            Quantity::Input(i) => i.max_derivative_order(),
            Quantity::NetworkInput(_) => {
                return Err(Error::Call(format!(
                    "{}: a network's input is held (zero-order); it takes no slope",
                    v.name
                )))
            }
            _ => 0,
        };
        if most == 0 {
            return Err(Error::Call(format!(
                "{}: only the shaft's speed or drive torque take an input derivative",
                v.name
            )));
        }
        if !(1..=most).contains(&order) {
            return Err(Error::BadInput(format!(
                "{}: derivative of order {order}: it takes orders 1 to {most}",
                v.name
            )));
        }
        if !value.is_finite() {
            return Err(Error::BadInput(format!(
                "{}: slope {value}: expected a finite value",
                v.name
            )));
        }
        if matches!(stage, Stage::Ended | Stage::Failed) {
            return Err(Error::Call(format!("{}: the run has ended", v.name)));
        }
        self.slopes[vr as usize][order as usize - 1] = value;
        Ok(())
    }

    /// Sets the input `name` (public name or alias) to `value`, held from the run's time on,
    /// with its first and second derivatives if given (Python's `Simulation`).
    pub fn set_input(
        &mut self,
        name: &str,
        value: f64,
        derivatives: [Option<f64>; 2],
    ) -> Result<()> {
        let vr = self.input_named(name)?;
        self.set_real(vr, value)?;
        for (order, d) in (1..).zip(derivatives) {
            if let Some(d) = d {
                self.set_real_derivative(vr, order, d)?;
            }
        }
        Ok(())
    }

    /// Sets a String parameter (`fmi2SetString`), before the run starts.
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<()> {
        let stage = self.stage();
        let v = self.variable(Kind::String, vr)?;
        if stage != Stage::Setup {
            return Err(Error::Call(format!(
                "{} is a fixed parameter: set it before the run starts \
                 (fmi2ExitInitializationMode)",
                v.name
            )));
        }
        self.strings[vr as usize] = value.to_string();
        Ok(())
    }

    /// A String variable (`fmi2GetString`).
    pub fn get_string(&self, vr: u32) -> Result<&str> {
        self.variable(Kind::String, vr)?;
        Ok(&self.strings[vr as usize])
    }

    /// The impact that closed last.
    fn last_impact(&self) -> Option<clutchpack_model::ImpactEvent> {
        match (&self.session, &self.outcome) {
            (Some(s), _) => s.last_impact(),
            (None, Some(o)) => o.collector.last_impact,
            _ => None,
        }
    }

    /// An Integer variable (`fmi2GetInteger`: the impacts so far, the last impact's body).
    pub fn get_integer(&self, vr: u32) -> Result<i32> {
        let v = self.variable(Kind::Integer, vr)?;
        if v.quantity == Quantity::LastImpact(ImpactField::Body) {
            return Ok(self.last_impact().map_or(0, |e| e.disc as i32 + 1));
        }
        let n = match (&self.session, &self.outcome) {
            (Some(s), _) => s.impact_count(),
            (None, Some(o)) => o.collector.impact_count(),
            _ => 0,
        };
        Ok(n.min(i32::MAX as usize) as i32)
    }

    /// A Real variable (`fmi2GetReal`): a parameter or input as set, an output as computed
    /// at the run's time (SI units: the variable's).
    pub fn get_real(&self, vr: u32) -> Result<f64> {
        let v = self.variable(Kind::Real, vr)?;
        if v.causality != Causality::Output {
            return Ok(self.reals[vr as usize]);
        }
        let s = &self.snapshot;
        let nd = self.scene.pack.discs.len();
        Ok(match v.quantity {
            Quantity::ShaftAngle => s.sample.shaft_angle_rad,
            Quantity::ShaftSpeed => s.sample.shaft_speed_rad_s,
            Quantity::PackShaftTorque => s.shaft_torque_n_m(nd),
            Quantity::CarrierTorque => s.carrier_torque_n_m(nd),
            Quantity::DrumAngle => s.drum.map_or(0.0, |d| d.0),
            Quantity::DrumSpeed => s.drum.map_or(0.0, |d| d.1),
            Quantity::Body(i, f) => {
                let body = s.sample.discs.get(i);
                match f {
                    BodyField::Speed => body.map_or(0.0, |b| b.speed_rad_s),
                    BodyField::Load => body.map_or(0.0, |b| b.load_n),
                    BodyField::Torque => body.map_or(0.0, |b| b.torque_n_m),
                    BodyField::MaxLoad => self.max_load(i),
                    BodyField::Damage => self.damage(i),
                }
            }
            Quantity::Interface(m, f) => {
                let x = s.interfaces.get(m).copied().unwrap_or_default();
                match f {
                    InterfaceField::Torque => x.torque_n_m,
                    InterfaceField::Slip => x.slip_rad_s,
                    InterfaceField::Clamp => x.clamp_n,
                    InterfaceField::Heat => x.dissipated_j,
                }
            }
            Quantity::LastImpact(f) => self.last_impact().map_or(0.0, |e| match f {
                ImpactField::Onset => e.t_on_s,
                ImpactField::PeakTime => e.t_peak_s,
                ImpactField::End => e.t_off_s,
                ImpactField::Peak => e.peak_n,
                ImpactField::Body => 0.0,
            }),
            Quantity::BodyTemperature(i) => self.temperature_k(i),
            Quantity::OilTemperature => {
                self.temperature_k(self.scene.pack.discs.len() + self.scene.pack.plates.len())
            }
            Quantity::NetworkOutput(j) => self.network_outputs.get(j).copied().unwrap_or(0.0),
            _ => self.reals[vr as usize],
        })
    }

    /// Every output's `(name, value)` now (the Integer ones as floats), in table order.
    pub fn outputs(&self) -> Result<Vec<(String, f64)>> {
        self.vars
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| {
                let x = match v.kind {
                    Kind::Real => self.get_real(v.vr),
                    _ => self.get_integer(v.vr).map(f64::from),
                };
                x.map(|x| (v.name.clone(), x))
            })
            .collect()
    }

    /// A thermal run's temperature `i` now, K (the bodies, then the oil), from the last
    /// thermal window the engine closed; the scene's initial temperature before the run starts.
    fn temperature_k(&self, i: usize) -> f64 {
        let now = match (&self.session, &self.outcome) {
            (Some(s), _) => s.temperatures_k().get(i).copied(),
            (None, Some(o)) => o.collector.temperatures_k.get(i).copied(),
            _ => None,
        };
        now.or(self.scene.thermal.as_ref().map(|t| t.initial_k))
            .unwrap_or(0.0)
    }

    fn max_load(&self, i: usize) -> f64 {
        match (&self.session, &self.outcome) {
            (Some(s), _) => s.max_loads_n().get(i).copied().unwrap_or(0.0),
            (None, Some(o)) => o.collector.peaks.max_abs_n(i),
            _ => 0.0,
        }
    }

    fn damage(&self, i: usize) -> f64 {
        let t = self.time_s();
        let mut cache = self.damage_cache.borrow_mut();
        if cache.as_ref().is_none_or(|(tc, _)| *tc != t) {
            let all = match (&self.session, &self.outcome) {
                (Some(s), _) => s.damage(),
                (None, Some(o)) => o.fatigue().iter().map(|f| f.lumped.damage).collect(),
                _ => Vec::new(),
            };
            *cache = Some((t, all));
        }
        cache
            .as_ref()
            .and_then(|(_, d)| d.get(i).copied())
            .unwrap_or(0.0)
    }

    /// Holds the inputs set from the run's time and advances to `t_end` (s); `stop` (checked
    /// at the engine's progress polls) ends it early: `Ok(false)`, the run standing at an
    /// earlier time. A bad input leaves the run usable; an engine failure does not
    /// ([`Stage::Failed`]).
    pub fn advance_to(&mut self, t_end: f64, stop: Option<&AtomicBool>) -> Result<bool> {
        self.advance_polled(t_end, stop, None)
    }

    /// [`CoSimulation::advance_to`] with `progress` called at the engine's progress polls
    /// ([`Session::advance_polled`], [`crate::NetworkSimulation::advance_polled`]).
    pub fn advance_polled<'a>(
        &mut self,
        t_end: f64,
        stop: Option<&'a AtomicBool>,
        progress: Option<&'a mut dyn FnMut(f64)>,
    ) -> Result<bool> {
        if self.stage() != Stage::Running {
            return Err(Error::Call(format!(
                "advancing in {:?}: allowed only after the run has started",
                self.stage()
            )));
        }
        if self.network.is_some() {
            return self.advance_network(t_end, stop, progress);
        }
        self.check_held_inputs(t_end)?;
        let inputs = self.inputs();
        let session = self.session.as_mut().expect("a session while running");
        if self.driven.any() {
            session.set_inputs(&inputs)?;
        }
        match session.advance_polled(t_end, stop, progress) {
            Ok(a) => {
                self.snapshot = session.snapshot();
                Ok(a == Advance::Reached)
            }
            Err(e) => {
                // a bad input leaves the run usable; an engine failure does not
                self.failed |= !e.is_bad_input();
                Err(e)
            }
        }
    }

    /// Each input held with its derivatives (a first- or second-order hold) from the run's
    /// time to `t_end` (s) stays within its scene key's bound at `t_end`: a slope cannot
    /// carry an input where its value could not be set.
    fn check_held_inputs(&self, t_end: f64) -> Result<()> {
        let dt = t_end - self.time_s();
        for v in &self.vars {
            let Quantity::Input(i) = v.quantity else {
                continue;
            };
            let [slope, curvature] = self.slopes[v.vr as usize];
            if slope == 0.0 && curvature == 0.0 {
                continue;
            }
            let x = self.reals[v.vr as usize] + slope * dt + 0.5 * curvature * dt * dt;
            i.check(
                x,
                &format!(
                    " at {} s (held with its derivatives)",
                    clutchpack_model::fmt_num(t_end)
                ),
            )?;
        }
        Ok(())
    }

    /// The time the run stands at, s (after [`CoSimulation::finish`]: where it ended).
    pub fn time_s(&self) -> f64 {
        if let Some(n) = &self.network {
            return n.time_s();
        }
        if let Some(o) = &self.network_outcome {
            return o.summary.simulated_s;
        }
        match (&self.session, &self.outcome) {
            (Some(s), _) => s.time_s(),
            (None, Some(o)) => o.result.as_ref().map_or(0.0, |r| r.simulated_s),
            _ => 0.0,
        }
    }

    /// Ends the run (its recording finished, open contacts closed); the final outputs stay
    /// readable. The warnings of the finish (a recording's summary) come back as text.
    pub fn finish(&mut self) -> Vec<String> {
        let mut warnings = Vec::new();
        if let Some(s) = self.session.take() {
            let outcome = s.finish();
            warnings.extend(outcome.warnings.iter().cloned());
            if let Some(Err(e)) = &outcome.recording {
                warnings.push(format!("the recording could not be finished: {e}"));
            }
            if let Err(e) = &outcome.result {
                warnings.push(format!("the run had failed: {e}"));
            }
            self.outcome = Some(outcome);
        }
        if let Some(n) = self.network.take() {
            match n.finish() {
                Ok(o) => self.network_outcome = Some(o),
                Err(e) => warnings.push(format!("the network run could not be finished: {e}")),
            }
        }
        self.ended = true;
        warnings
    }

    /// The finished run, after [`CoSimulation::finish`].
    pub fn outcome(&self) -> Option<&RunOutcome> {
        self.outcome.as_ref()
    }

    /// A network scene's finished run, after [`CoSimulation::finish`].
    pub fn network_outcome(&self) -> Option<&crate::NetworkOutcome> {
        self.network_outcome.as_ref()
    }

    /// Saves the whole state (not while recording: a recording cannot be rewound).
    pub fn save(&self) -> Result<SavedCoSimulation> {
        if let Some(n) = self
            .network
            .as_ref()
            .filter(|_| self.stage() == Stage::Running)
        {
            return Ok(SavedCoSimulation {
                run: self.run,
                scene: self.scene.name.clone(),
                session: SavedRun::Network(Box::new(n.save()?)),
                reals: self.reals.clone(),
                slopes: self.slopes.clone(),
                snapshot: self.snapshot.clone(),
                network: (self.network_outputs.clone(), self.network_pushed.clone()),
            });
        }
        let s = self
            .session
            .as_ref()
            .filter(|_| self.stage() == Stage::Running)
            .ok_or_else(|| {
                Error::Call(
                    "a state can be saved while the run goes (after fmi2ExitInitializationMode)"
                        .into(),
                )
            })?;
        Ok(SavedCoSimulation {
            run: self.run,
            scene: self.scene.name.clone(),
            session: SavedRun::Pack(Box::new(s.save()?)),
            reals: self.reals.clone(),
            slopes: self.slopes.clone(),
            snapshot: self.snapshot.clone(),
            network: Default::default(),
        })
    }

    /// Restores a state this run saved (never another instance's, another scene's, or one
    /// from before a reset; a recorded run saves none, so it is never rewound); a failed run
    /// goes on from the state.
    pub fn restore(&mut self, state: &SavedCoSimulation) -> Result<()> {
        same_run(state.run, &state.scene, self.run, &self.scene.name)?;
        let going = || {
            Error::Call(
                "a state can be restored while the run goes (after fmi2ExitInitializationMode)"
                    .into(),
            )
        };
        match &state.session {
            SavedRun::Pack(saved) => {
                let s = self
                    .session
                    .as_mut()
                    .filter(|_| !self.ended)
                    .ok_or_else(going)?;
                s.restore(saved)?;
            }
            SavedRun::Network(saved) => {
                let n = self
                    .network
                    .as_mut()
                    .filter(|_| !self.ended)
                    .ok_or_else(going)?;
                n.restore(saved)?;
                (self.network_outputs, self.network_pushed) = state.network.clone();
            }
        }
        self.reals.clone_from(&state.reals);
        self.slopes.clone_from(&state.slopes);
        self.snapshot = state.snapshot.clone();
        self.damage_cache.take();
        self.failed = false;
        Ok(())
    }
}
