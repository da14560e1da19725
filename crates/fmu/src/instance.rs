//! One FMU instance as plain Rust: FMI 2.0's co-simulation state machine (instantiated,
//! initialisation, stepping, terminated) over `clutchpack_sdk`'s steppable run. The C
//! functions (`ffi.rs`) only translate pointers and statuses; every rule and every message
//! is here, testable without a host.

use crate::bounds::check_input;
use crate::variables::Variable;
use crate::variables::{
    variables, BodyField, Causality, ImpactField, Input, InterfaceField, Kind, Quantity,
};
use clutchpack_model::session::{Advance, Driven, Inputs, Snapshot};
use clutchpack_record::{RecordOptions, Replace};
use clutchpack_scene::{EngineChoice, Scene};
use clutchpack_sdk::{
    RecordingRequest, RunOutcome, Session, SessionRequest, SessionState, Simulation,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Numbers every run an instance starts (`fmi2ExitInitializationMode`), process-wide: a saved
/// state names the run it belongs to, and restores only into it.
static RUNS: AtomicU64 = AtomicU64::new(1);

/// Where an instance is in FMI's state machine.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// After `fmi2Instantiate` (or `fmi2Reset`): parameters and inputs may be set.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// Stepping (`fmi2DoStep`).
    Stepping,
    /// After `fmi2Terminate`: the final outputs may be read.
    Terminated,
    /// An engine failure or a bad call that leaves the run unusable: only reading,
    /// terminating, resetting and freeing.
    Failed,
}

/// A saved FMU state (`fmi2GetFMUstate`): it belongs to the run that saved it (one instance,
/// between its `fmi2ExitInitializationMode` and its next reset) and restores only into it.
pub struct SavedState {
    /// The run that saved it ([`RUNS`]).
    run: u64,
    /// The scene of that run, for messages.
    scene: String,
    session: SessionState,
    reals: Vec<f64>,
    slopes: Vec<[f64; 2]>,
    snapshot: Snapshot,
}

/// One FMU instance.
pub struct Instance {
    scene: Scene,
    /// The inputs the caller drives.
    driven: Driven,
    vars: Vec<Variable>,
    /// Value of every Real variable by value reference (parameters and inputs as set,
    /// outputs as last computed).
    reals: Vec<f64>,
    /// First and second derivatives of each Real input by value reference
    /// (`fmi2SetRealInputDerivatives`, orders 1 and 2), per s and per s^2; reset to 0
    /// whenever the input's value is set.
    slopes: Vec<[f64; 2]>,
    strings: Vec<String>,
    phase: Phase,
    stop_time_s: Option<f64>,
    session: Option<Session>,
    snapshot: Snapshot,
    /// The finished run (after `fmi2Terminate`).
    outcome: Option<RunOutcome>,
    /// Every body's damage at the time it was computed (hosts read every output at every
    /// step; the assessment covers all bodies at once).
    damage_cache: std::cell::RefCell<Option<(f64, Vec<f64>)>>,
    /// The run started by the last `fmi2ExitInitializationMode` ([`RUNS`]; 0 before).
    run: u64,
    /// The files the run reads (the FMU's resources, Python's scene file): no output may
    /// name one.
    inputs: Vec<PathBuf>,
}

/// Reads the scene an FMU carries: `resources/scene.json` (the validated scene, written by
/// `clutchpack fmu`), checking `resources/guid.txt` against the host's GUID.
pub fn load_resources(resources: &Path, guid: &str) -> Result<Scene, String> {
    let read = |name: &str| {
        let p = resources.join(name);
        std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))
    };
    let own = read("guid.txt")?;
    if own.trim() != guid {
        return Err(format!(
            "the GUID {guid:?} from the model description is not this FMU's ({:?}): the \
             model description and the resources come from different builds",
            own.trim()
        ));
    }
    let text = read("scene.json")?;
    // the scene was validated when the FMU was built, and the GUID is a hash of its text:
    // a scene edited since (a record rate of 1e300 Hz, ...) is refused, never run unchecked
    if crate::package::guid(&text) != own.trim() {
        return Err(format!(
            "{}: changed since the FMU was built (it does not hash to the FMU's GUID); \
             build the FMU again from the scene file with `clutchpack fmu`, which checks it",
            resources.join("scene.json").display()
        ));
    }
    serde_json::from_str(&text).map_err(|e| {
        format!(
            "{}: not a scene written by clutchpack fmu: {e}",
            resources.join("scene.json").display()
        )
    })
}

impl Instance {
    /// An instance of `scene` (engine: the scene's choice, as `clutchpack run` makes it)
    /// driving every input the pack has, as an FMU does.
    pub fn new(scene: Scene) -> Result<Instance, String> {
        let driven = Driven::all_for(&scene.pack);
        Instance::driving(scene, driven)
    }

    /// An instance of `scene` whose caller drives only `driven` (the other inputs follow the
    /// scene's profiles; Python's `Simulation`). Driving nothing, the run is the scene's run
    /// split into calls.
    pub fn driving(scene: Scene, driven: Driven) -> Result<Instance, String> {
        let engine = scene.engine(None, &scene.name).map_err(|e| e.to_string())?;
        let vars = variables(&scene, engine.name(), driven);
        let mut inst = Instance {
            driven,
            reals: Vec::new(),
            slopes: Vec::new(),
            strings: Vec::new(),
            vars,
            scene,
            phase: Phase::Instantiated,
            stop_time_s: None,
            session: None,
            snapshot: Snapshot::default(),
            outcome: None,
            damage_cache: Default::default(),
            run: 0,
            inputs: Vec::new(),
        };
        inst.reset();
        Ok(inst)
    }

    /// The files the run reads (the FMU's resources, a scene file), which no output may name.
    pub fn reading(mut self, inputs: Vec<PathBuf>) -> Instance {
        self.inputs = inputs;
        self
    }

    /// Back to the state after instantiation, every variable at its start value.
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
            // a recording in progress is finished with what it holds
            let _ = s.finish();
        }
        self.phase = Phase::Instantiated;
        self.stop_time_s = None;
        self.snapshot = Snapshot::default();
        self.outcome = None;
        self.damage_cache.take();
        self.run = 0;
    }

    /// Where the instance is.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The variables.
    pub fn variables(&self) -> &[Variable] {
        &self.vars
    }

    fn var(&self, kind: Kind, vr: u32) -> Result<&Variable, String> {
        self.vars
            .iter()
            .find(|v| v.kind == kind && v.vr == vr)
            .ok_or_else(|| format!("no {kind:?} variable has the value reference {vr}"))
    }

    /// `fmi2SetupExperiment`: the run starts at t = 0; a stop time, if given, is where the
    /// steps land rather than pass.
    pub fn setup_experiment(&mut self, start_s: f64, stop_s: Option<f64>) -> Result<(), String> {
        if self.phase != Phase::Instantiated {
            return Err("fmi2SetupExperiment is allowed only after instantiation".into());
        }
        if start_s != 0.0 {
            return Err(format!(
                "startTime = {start_s} s: a pack's run starts at t = 0 (its initial state is \
                 the scene's)"
            ));
        }
        if let Some(stop) = stop_s {
            if !(stop.is_finite() && stop > 0.0) {
                return Err(format!("stopTime = {stop} s: expected a positive time"));
            }
        }
        self.stop_time_s = stop_s;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> Result<(), String> {
        if self.phase != Phase::Instantiated {
            return Err("fmi2EnterInitializationMode is allowed only after instantiation".into());
        }
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: starts the run with the parameters and inputs set.
    pub fn exit_initialization(&mut self) -> Result<(), String> {
        if self.phase != Phase::Initialization {
            return Err("fmi2ExitInitializationMode is allowed only in initialization".into());
        }
        let engine_name = self.string_of(Quantity::Engine);
        let engine = EngineChoice::from_name(&engine_name).ok_or_else(|| {
            format!(
                "engine = {engine_name:?}: expected one of {}",
                EngineChoice::names().join(", ")
            )
        })?;
        let limit = self.real_of(Quantity::DurationLimit);
        if !(limit.is_finite() && limit > 0.0) {
            return Err(format!(
                "duration_limit_s = {limit}: expected a positive time in s"
            ));
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
            .map_err(|e| format!("{e} (leave recording_path empty to run without a recording)"))?;
        }
        let recording = (!path.is_empty()).then(|| RecordingRequest {
            path: PathBuf::from(&path),
            replace: Replace::Existing,
            options: RecordOptions::default(),
            scene_path: None,
        });
        let sim = Simulation::new(self.scene.clone(), Some(engine)).map_err(|e| e.to_string())?;
        let mut session = sim
            .start(SessionRequest {
                driven: self.driven,
                stop_time_s: self.stop_time_s,
                recording,
                keep_history: false,
            })
            .map_err(|e| e.to_string())?;
        if self.driven.any() {
            session
                .set_inputs(&self.inputs())
                .map_err(|e| e.to_string())?;
        }
        self.snapshot = session.snapshot();
        self.session = Some(session);
        self.phase = Phase::Stepping;
        self.run = RUNS.fetch_add(1, Ordering::Relaxed);
        Ok(())
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

    /// The inputs as set now.
    fn inputs(&self) -> Inputs {
        let mut out = Inputs::default();
        for v in &self.vars {
            if let Quantity::Input(i) = v.quantity {
                let x = Some(self.reals[v.vr as usize]);
                let [slope, curvature] = self.slopes[v.vr as usize];
                match i {
                    Input::ShaftSpeed => {
                        out.shaft_speed_rad_s = x;
                        out.shaft_speed_slope_rad_s2 = Some(slope);
                        out.shaft_speed_curvature_rad_s3 = Some(curvature);
                    }
                    Input::ShaftTorque => {
                        out.shaft_torque_n_m = x;
                        out.shaft_torque_slope_n_m_s = Some(slope);
                    }
                    Input::DrumLoad => out.drum_load_n_m = x,
                    Input::PistonPressure => out.piston_pressure_pa = x,
                }
            }
        }
        out
    }

    /// `fmi2SetReal` of one variable.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), String> {
        let v = self.var(Kind::Real, vr)?;
        match v.causality {
            Causality::Output => Err(format!("{} is an output: it cannot be set", v.name)),
            Causality::Parameter
                if !matches!(self.phase, Phase::Instantiated | Phase::Initialization) =>
            {
                Err(format!(
                    "{} is a fixed parameter: set it before fmi2ExitInitializationMode",
                    v.name
                ))
            }
            _ if !value.is_finite() => {
                Err(format!("{} = {value}: expected a finite value", v.name))
            }
            Causality::Input if matches!(self.phase, Phase::Terminated | Phase::Failed) => {
                Err(format!("{}: the run has ended", v.name))
            }
            Causality::Input => {
                let Quantity::Input(i) = v.quantity else {
                    unreachable!("an input variable stands for an input")
                };
                check_input(&v.name, i, v.unit.unwrap_or(""), value, "")?;
                self.reals[vr as usize] = value;
                self.slopes[vr as usize] = [0.0; 2];
                Ok(())
            }
            _ => {
                self.reals[vr as usize] = value;
                self.slopes[vr as usize] = [0.0; 2];
                Ok(())
            }
        }
    }

    /// `fmi2SetRealInputDerivatives` of one input: its slope (`order` 1) or, for the shaft's
    /// speed, also its second derivative (`order` 2) over the coming communication steps,
    /// until its value is set again (a first- or second-order hold). Only the shaft's speed
    /// and drive torque take derivatives.
    pub fn set_real_derivative(&mut self, vr: u32, order: i32, value: f64) -> Result<(), String> {
        let v = self.var(Kind::Real, vr)?;
        if !matches!(
            v.quantity,
            Quantity::Input(Input::ShaftSpeed | Input::ShaftTorque)
        ) {
            return Err(format!(
                "{}: only the shaft's speed or drive torque take an input derivative",
                v.name
            ));
        }
        let most = if v.quantity == Quantity::Input(Input::ShaftSpeed) {
            2
        } else {
            1
        };
        if !(1..=most).contains(&order) {
            return Err(format!(
                "{}: derivative of order {order}: it takes orders 1 to {most}",
                v.name
            ));
        }
        if !value.is_finite() {
            return Err(format!(
                "{}: slope {value}: expected a finite value",
                v.name
            ));
        }
        if matches!(self.phase, Phase::Terminated | Phase::Failed) {
            return Err(format!("{}: the run has ended", v.name));
        }
        self.slopes[vr as usize][order as usize - 1] = value;
        Ok(())
    }

    /// `fmi2SetString` of one variable.
    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<(), String> {
        let v = self.var(Kind::String, vr)?;
        if !matches!(self.phase, Phase::Instantiated | Phase::Initialization) {
            return Err(format!(
                "{} is a fixed parameter: set it before fmi2ExitInitializationMode",
                v.name
            ));
        }
        self.strings[vr as usize] = value.to_string();
        Ok(())
    }

    /// `fmi2GetString` of one variable.
    pub fn get_string(&self, vr: u32) -> Result<&str, String> {
        self.var(Kind::String, vr)?;
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

    /// `fmi2GetInteger` of one variable (the impacts so far, the last impact's body).
    pub fn get_integer(&self, vr: u32) -> Result<i32, String> {
        let v = self.var(Kind::Integer, vr)?;
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

    /// `fmi2GetReal` of one variable.
    pub fn get_real(&self, vr: u32) -> Result<f64, String> {
        let v = self.var(Kind::Real, vr)?;
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
            _ => self.reals[vr as usize],
        })
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

    /// `fmi2DoStep`: holds the inputs from `t_s` and advances to `t_s + h_s`.
    pub fn do_step(&mut self, t_s: f64, h_s: f64) -> Result<(), String> {
        if self.phase != Phase::Stepping {
            return Err(format!(
                "fmi2DoStep in {:?}: allowed only after fmi2ExitInitializationMode",
                self.phase
            ));
        }
        let limit = self.real_of(Quantity::DurationLimit);
        let session = self.session.as_mut().expect("a session while stepping");
        let now = session.time_s();
        if !t_s.is_finite() {
            return Err(format!(
                "currentCommunicationPoint = {t_s} s: expected a finite time (the FMU stands \
                 at {now} s)"
            ));
        }
        if (t_s - now).abs() > 1e-9 * now.max(1e-3) {
            return Err(format!(
                "currentCommunicationPoint = {t_s} s, but the FMU stands at {now} s"
            ));
        }
        let end = t_s + h_s;
        if !(h_s > 0.0 && end.is_finite()) {
            return Err(format!("communicationStepSize = {h_s} s: expected > 0"));
        }
        if end > limit * (1.0 + 1e-12) {
            return Err(format!(
                "a step to {end} s passes duration_limit_s = {limit} s (set the parameter to \
                 run longer)"
            ));
        }
        self.advance_to(end.max(now), None).map(|_| ())
    }

    /// Holds the inputs set from the run's time and advances to `t_end` (s); `stop` (checked
    /// at the engine's progress polls) ends it early: `Ok(false)`, the run standing at an
    /// earlier time. The steps of [`Instance::do_step`] without its checks of the host's
    /// communication point and the duration limit (Python's `Simulation`).
    pub fn advance_to(&mut self, t_end: f64, stop: Option<&AtomicBool>) -> Result<bool, String> {
        if self.phase != Phase::Stepping {
            return Err(format!(
                "advancing in {:?}: allowed only after initialization",
                self.phase
            ));
        }
        self.check_held_inputs(t_end)?;
        let inputs = self.inputs();
        let session = self.session.as_mut().expect("a session while stepping");
        if self.driven.any() {
            session.set_inputs(&inputs).map_err(|e| e.to_string())?;
        }
        match session.advance_to(t_end, stop) {
            Ok(a) => {
                self.snapshot = session.snapshot();
                Ok(a == Advance::Reached)
            }
            Err(e) if e.is_bad_input() => Err(e.to_string()),
            Err(e) => {
                self.phase = Phase::Failed;
                Err(e.to_string())
            }
        }
    }

    /// Each input held with its slopes (a first- or second-order hold) from the run's time to
    /// `t_end` (s) stays within its scene key's bound (`bounds.rs`) at `t_end`: a slope
    /// cannot carry an input where its value could not be set.
    fn check_held_inputs(&self, t_end: f64) -> Result<(), String> {
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
            check_input(
                &v.name,
                i,
                v.unit.unwrap_or(""),
                x,
                &format!(
                    " at {} s (held with its derivatives)",
                    clutchpack_model::fmt_num(t_end)
                ),
            )?;
        }
        Ok(())
    }

    /// The time the run stands at, s (after `fmi2Terminate`: where it ended).
    pub fn time_s(&self) -> f64 {
        match (&self.session, &self.outcome) {
            (Some(s), _) => s.time_s(),
            (None, Some(o)) => o.result.as_ref().map_or(0.0, |r| r.simulated_s),
            _ => 0.0,
        }
    }

    /// `fmi2Terminate`: finishes the run (its recording too); the final outputs stay
    /// readable. Warnings of the finish (a recording's summary) come back as text.
    pub fn terminate(&mut self) -> Result<Vec<String>, String> {
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
        self.phase = Phase::Terminated;
        Ok(warnings)
    }

    /// The finished run, after [`Instance::terminate`].
    pub fn outcome(&self) -> Option<&RunOutcome> {
        self.outcome.as_ref()
    }

    /// `fmi2GetFMUstate`.
    pub fn save(&self) -> Result<SavedState, String> {
        let s = self
            .session
            .as_ref()
            .filter(|_| self.phase == Phase::Stepping)
            .ok_or("fmi2GetFMUstate is supported while stepping (after initialization)")?;
        Ok(SavedState {
            run: self.run,
            scene: self.scene.name.clone(),
            session: s.save().map_err(|e| e.to_string())?,
            reals: self.reals.clone(),
            slopes: self.slopes.clone(),
            snapshot: self.snapshot.clone(),
        })
    }

    /// `fmi2SetFMUstate`: only a state this run saved (never another instance's, another
    /// scene's, or one from before a reset; a recorded run saves none, so it is never
    /// rewound).
    pub fn restore(&mut self, state: &SavedState) -> Result<(), String> {
        if state.run != self.run || self.run == 0 {
            return Err(format!(
                "the state was saved by another run (scene {:?}; this instance runs {:?}): a \
                 state restores only into the instance and run that saved it",
                state.scene, self.scene.name
            ));
        }
        let s = self
            .session
            .as_mut()
            .filter(|_| matches!(self.phase, Phase::Stepping | Phase::Failed))
            .ok_or("fmi2SetFMUstate is supported while stepping (after initialization)")?;
        s.restore(&state.session).map_err(|e| e.to_string())?;
        self.reals.clone_from(&state.reals);
        self.slopes.clone_from(&state.slopes);
        self.snapshot = state.snapshot.clone();
        self.damage_cache.take();
        self.phase = Phase::Stepping;
        Ok(())
    }
}
