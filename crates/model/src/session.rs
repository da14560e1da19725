//! Steppable engines (co-simulation): a [`Session`] advances a pack to one communication point
//! after another, with inputs that arrive one call at a time, and can be cloned to save and
//! restore its state (FMI 2.0's `fmi2GetFMUstate`). `Engine::run` is built on it.
//!
//! How an input is held between communication points and what happens to a contact open at a
//! communication point: docs/DECISIONS.md, "Co-simulation".

use crate::clutch::{InterfaceSample, PressureProfile};
use crate::drive::{Shaft, ShaftExcitation, SpeedProfile, Table};
use crate::network::output::{NetworkRun, NetworkSample};
use crate::network::{Network, NetworkInput};
use crate::pack::PackModel;
use crate::stream::{EngineError, Observer, RunStats, Sample};

/// Which of the pack's inputs a session's caller drives (the others follow the scene's
/// profiles). A session driven by nothing follows the scene exactly as `Engine::run` does,
/// and its steps never stop at a communication point (so any split of a run into calls gives
/// the run's results bit for bit). A driven session on the multibody engine ends a world step
/// at every communication point, where an input may change; on the reference engine it steps
/// past the point as an undriven one does, and an input set to a new value there ends that
/// step at the point (docs/DECISIONS.md, "Co-simulation").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Driven {
    /// The prescribed shaft's speed (a shaft with `mode = "prescribed"`).
    pub shaft_speed: bool,
    /// The drive torque on an inertial shaft (`mode = "inertial"`).
    pub shaft_torque: bool,
    /// The load torque on the drum (a pack with a drum).
    pub drum_load: bool,
    /// The pressure on the piston (a pack with a stack).
    pub piston_pressure: bool,
}

impl Driven {
    /// Nothing driven: the scene's own inputs.
    pub const NONE: Driven = Driven {
        shaft_speed: false,
        shaft_torque: false,
        drum_load: false,
        piston_pressure: false,
    };

    /// Whether any input is driven.
    pub fn any(&self) -> bool {
        self.shaft_speed || self.shaft_torque || self.drum_load || self.piston_pressure
    }

    /// Whether `pack` has every input driven: a prescribed shaft for its speed, an inertial
    /// shaft for its torque, a drum for its load, a stack for the pressure. The error says
    /// what is missing (all of it), each input by its public name (the FMU's variable,
    /// `clutchpack_sdk::cosim::Input::name`).
    pub fn check(&self, pack: &PackModel) -> Result<(), EngineError> {
        let inertial = matches!(pack.shaft, Shaft::Inertial { .. });
        let missing = [
            (self.shaft_speed && inertial, "shaft.speed_rad_s (the shaft speed) needs a prescribed shaft (shaft.mode = \"prescribed\"); an inertial shaft takes a drive torque"),
            (self.shaft_torque && !inertial, "shaft.drive_torque_n_m (the shaft torque) needs an inertial shaft (shaft.mode = \"inertial\"); a prescribed shaft takes a speed"),
            (self.drum_load && pack.drum.is_none(), "drum.load_torque_n_m (the drum load) needs a pack with a drum"),
            (self.piston_pressure && pack.stack.is_none(), "piston.pressure_pa (the piston pressure) needs a pack with a stack"),
        ];
        if !self.shaft_speed && matches!(held_table(pack), Some((_, true))) {
            return Err(EngineError::Unsupported(
                "a held speed table (drive.interpolation = \"hold\") jumps at its rows, which a \
                 run in calls does not land on: run the scene whole (`clutchpack run`, Python's \
                 `clutchpack.run`), which ends a step at every row, or drive the shaft speed \
                 (Simulation(..., drive=[\"shaft.speed_rad_s\"]), or the FMU) with the table's values"
                    .into(),
            ));
        }
        let why: Vec<&str> = missing
            .iter()
            .filter(|(m, _)| *m)
            .map(|(_, w)| *w)
            .collect();
        if why.is_empty() {
            Ok(())
        } else {
            Err(EngineError::Unsupported(why.join("; ")))
        }
    }

    /// The scene's inputs that a session can drive for `pack`: the shaft's speed or torque,
    /// the drum's load, the piston's pressure (what an FMU of the pack takes).
    pub fn all_for(pack: &PackModel) -> Driven {
        let inertial = matches!(pack.shaft, Shaft::Inertial { .. });
        Driven {
            shaft_speed: !inertial,
            shaft_torque: inertial,
            drum_load: pack.drum.is_some(),
            piston_pressure: pack.stack.is_some(),
        }
    }
}

/// Input values set at a communication point and held (zero-order hold) until the next one.
/// `None` keeps the value held before (at the start of a session: the scene's profile's value
/// at t = 0). Only the inputs the session was started to drive ([`Driven`]) may be set.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Inputs {
    /// Prescribed shaft speed, rad/s (positive: the shaft's positive rotation). The shaft's
    /// angle stays continuous: it integrates the held speed.
    pub shaft_speed_rad_s: Option<f64>,
    /// Drive torque on an inertial shaft, N m (positive along the positive rotation; eq 4's
    /// `T_drive`).
    pub shaft_torque_n_m: Option<f64>,
    /// Load torque on the drum, N m (negative: it brakes a drum turning the positive way).
    pub drum_load_n_m: Option<f64>,
    /// Pressure on the piston, Pa (>= 0).
    pub piston_pressure_pa: Option<f64>,
    /// Slope of the prescribed shaft's speed over the coming interval, rad/s^2 (a first-order
    /// hold, FMI's input derivative); `None` or with no speed set: 0 from this point on.
    pub shaft_speed_slope_rad_s2: Option<f64>,
    /// Second derivative of the prescribed shaft's speed over the coming interval, rad/s^3
    /// (a second-order hold); as [`Inputs::shaft_speed_slope_rad_s2`].
    pub shaft_speed_curvature_rad_s3: Option<f64>,
    /// Slope of the inertial shaft's drive torque over the coming interval, N m/s; as
    /// [`Inputs::shaft_speed_slope_rad_s2`].
    pub shaft_torque_slope_n_m_s: Option<f64>,
}

impl Inputs {
    /// The scene's values at `t_s` of the inputs `driven` (the others `None`): what a driven
    /// session holds from its start until its caller sets them.
    pub fn of_scene(pack: &PackModel, driven: &Driven, t_s: f64) -> Inputs {
        let speed = match &pack.shaft {
            Shaft::Prescribed(p) => Some(p.speed(t_s)),
            Shaft::Inertial { .. } => None,
        };
        Inputs {
            shaft_speed_rad_s: speed.filter(|_| driven.shaft_speed),
            shaft_torque_n_m: Some(pack.shaft.drive_torque_n_m(t_s))
                .filter(|_| driven.shaft_torque),
            drum_load_n_m: pack
                .drum
                .map(|d| d.load_torque_n_m)
                .filter(|_| driven.drum_load),
            piston_pressure_pa: pack
                .stack
                .as_ref()
                .map(|s| s.piston.pressure.pressure_pa(t_s))
                .filter(|_| driven.piston_pressure),
            ..Inputs::default()
        }
    }

    /// The driven inputs that `self` sets and `driven` does not allow, by name.
    pub fn undriven(&self, driven: &Driven) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self.shaft_speed_rad_s.is_some() && !driven.shaft_speed {
            out.push("shaft speed");
        }
        if self.shaft_torque_n_m.is_some() && !driven.shaft_torque {
            out.push("shaft torque");
        }
        if self.drum_load_n_m.is_some() && !driven.drum_load {
            out.push("drum load");
        }
        if self.piston_pressure_pa.is_some() && !driven.piston_pressure {
            out.push("piston pressure");
        }
        if (self.shaft_speed_slope_rad_s2.is_some() || self.shaft_speed_curvature_rad_s3.is_some())
            && !driven.shaft_speed
        {
            out.push("shaft speed's derivatives");
        }
        if self.shaft_torque_slope_n_m_s.is_some() && !driven.shaft_torque {
            out.push("shaft torque's slope");
        }
        out
    }

    /// The first value that is not finite (or a negative pressure), as `(name, value)`.
    pub fn invalid(&self) -> Option<(&'static str, f64)> {
        let all = [
            ("shaft speed", self.shaft_speed_rad_s),
            ("shaft torque", self.shaft_torque_n_m),
            ("drum load", self.drum_load_n_m),
            ("piston pressure", self.piston_pressure_pa),
            ("shaft speed's slope", self.shaft_speed_slope_rad_s2),
            ("shaft speed's curvature", self.shaft_speed_curvature_rad_s3),
            ("shaft torque's slope", self.shaft_torque_slope_n_m_s),
        ];
        for (name, v) in all {
            if let Some(v) = v {
                if !v.is_finite() || (name == "piston pressure" && v < 0.0) {
                    return Some((name, v));
                }
            }
        }
        None
    }
}

/// `pack` with `inputs` held from `t_s` on (a zero-order hold, or first-order with a slope;
/// `crate::session`), and the jump
/// of the prescribed shaft's speed at `t_s` (rad/s, new minus old; 0 when it is not set): the
/// speed becomes `SpeedProfile::Held` from the shaft's angle at `t_s` (so the angle stays
/// continuous), the drive torque `ShaftExcitation::Held`, the pressure a constant, the drum's
/// load its new value. Inputs the pack does not have are ignored (checked by
/// [`Driven::check`] when the session starts).
pub fn hold_inputs(pack: &PackModel, t_s: f64, inputs: &Inputs) -> (PackModel, f64) {
    let mut out = pack.clone();
    let mut jump = 0.0;
    match &mut out.shaft {
        Shaft::Prescribed(p) => {
            if inputs.shaft_speed_rad_s.is_some()
                || inputs.shaft_speed_slope_rad_s2.is_some()
                || inputs.shaft_speed_curvature_rad_s3.is_some()
            {
                let v = inputs.shaft_speed_rad_s.unwrap_or_else(|| p.speed(t_s));
                jump = v - p.speed(t_s);
                *p = SpeedProfile::Held {
                    t0_s: t_s,
                    angle0_rad: p.angle(t_s),
                    speed_rad_s: v,
                    accel_rad_s2: inputs.shaft_speed_slope_rad_s2.unwrap_or(0.0),
                    jerk_rad_s3: inputs.shaft_speed_curvature_rad_s3.unwrap_or(0.0),
                };
            }
        }
        Shaft::Inertial { excitation, .. } => {
            if inputs.shaft_torque_n_m.is_some() || inputs.shaft_torque_slope_n_m_s.is_some() {
                let torque = inputs
                    .shaft_torque_n_m
                    .unwrap_or_else(|| pack.shaft.drive_torque_n_m(t_s));
                let initial_speed_rad_s = pack.shaft.initial_speed_rad_s();
                *excitation = ShaftExcitation::Held {
                    t0_s: t_s,
                    torque_n_m: torque,
                    rate_n_m_s: inputs.shaft_torque_slope_n_m_s.unwrap_or(0.0),
                    initial_speed_rad_s,
                };
            }
        }
    }
    if let (Some(d), Some(load)) = (out.drum.as_mut(), inputs.drum_load_n_m) {
        d.load_torque_n_m = load;
    }
    if let (Some(s), Some(p)) = (out.stack.as_mut(), inputs.piston_pressure_pa) {
        s.piston.pressure = PressureProfile::Constant { pressure_pa: p };
    }
    (out, jump)
}

/// The pack's state at a session's current time: what an FMU outputs at a communication point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Snapshot {
    /// The shaft and every body (the discs, then the plates), as the engines' samples: per
    /// body the speed (rad/s), the per-tooth load (N, signed as eq 6) and the spline torque
    /// on the body (N m, `-n F Rb`, eq 5).
    pub sample: Sample,
    /// The stack's friction interfaces (empty without a stack).
    pub interfaces: Vec<InterfaceSample>,
    /// Drum angle (rad) and speed (rad/s); `None` for plates on the housing or no plates.
    pub drum: Option<(f64, f64)>,
}

impl Snapshot {
    /// Torque of the pack on the shaft, N m (positive along the shaft's positive rotation):
    /// the discs' spline reactions `sum n F Rb` (eq 4), the first `n_discs` bodies.
    pub fn shaft_torque_n_m(&self, n_discs: usize) -> f64 {
        -self.sample.discs[..n_discs.min(self.sample.discs.len())]
            .iter()
            .map(|d| d.torque_n_m)
            .sum::<f64>()
    }

    /// Torque of the plates on their carrier (the drum or the housing), N m (positive along
    /// the positive rotation): the plates' spline reactions, the bodies after the discs.
    pub fn carrier_torque_n_m(&self, n_discs: usize) -> f64 {
        -self
            .sample
            .discs
            .iter()
            .skip(n_discs)
            .map(|d| d.torque_n_m)
            .sum::<f64>()
    }
}

/// How a call to [`Session::advance_to`] ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Advance {
    /// The session reached the asked time.
    Reached,
    /// The observer asked to stop ([`Observer::progress`]); the session stands at an earlier
    /// time, everything up to it delivered.
    Stopped,
}

/// A run in progress that owns everything it needs (no borrow of the engine or the model).
pub trait Session: Send {
    /// The time the session's state stands at, s: the last communication point reached; a
    /// session driven by nothing on the multibody engine may stand up to one world step past
    /// it (its steps never end at a call), the reference engine exactly at it (its dense
    /// output).
    fn time_s(&self) -> f64;
    /// Sets inputs from [`Session::time_s`] on, held until changed. Fails (nothing changed)
    /// on an input the session does not drive or a value that is not finite.
    fn set_inputs(&mut self, inputs: &Inputs) -> Result<(), EngineError>;
    /// Advances to `t_s` (>= [`Session::time_s`]), sending the samples, contact samples and
    /// impacts closed up to `t_s` to `observer`. On error, everything before the failure has
    /// been delivered and the session must not be advanced again.
    fn advance_to(&mut self, t_s: f64, observer: &mut dyn Observer)
        -> Result<Advance, EngineError>;
    /// Declares the time the session will not be advanced beyond (FMI's stop time, `run`'s
    /// duration), s: steps land on it rather than pass it, as a run's last step does. Without
    /// it a session driven by nothing steps past its communication points as far as its
    /// steps go.
    fn set_stop_time(&mut self, t_s: f64);
    /// The pack's state at [`Session::time_s`] (`sample.t_s`).
    fn snapshot(&self) -> Snapshot;
    /// Ends the run: the contact events still open are closed (at the engine's last step,
    /// which a session driven by nothing and without a stop time may have taken past
    /// [`Session::time_s`]) and sent; returns the run's statistics. The session is spent
    /// afterwards.
    fn finish(&mut self, observer: &mut dyn Observer) -> RunStats;
    /// A copy of the whole state (FMI state save/restore): advancing the copy gives exactly
    /// what advancing the original would.
    fn boxed_clone(&self) -> Box<dyn Session>;
}

/// A held (zero-order hold) table driving the shaft: its speed (prescribed shaft, `true`) or
/// its drive torque (inertial shaft, `false`).
pub fn held_table(pack: &PackModel) -> Option<(&Table, bool)> {
    match &pack.shaft {
        Shaft::Prescribed(SpeedProfile::Table(t)) if t.hold => Some((t, true)),
        Shaft::Inertial {
            excitation: ShaftExcitation::Torque { table, .. },
            ..
        } if table.hold => Some((table, false)),
        _ => None,
    }
}

/// What `Engine::run` does: a session of `engine` from t = 0 to `duration_s`, finished.
/// A held table on the shaft (`Table::hold`) runs as a driven session whose communication
/// points are the table's rows, each row's value set there: the held speed's jumps are where
/// steps end (an engine integrating relative speeds cannot step across a jump of the
/// prescribed speed), exactly as a co-simulation master holding the same values drives it.
/// Anything else runs as one session driven by nothing.
pub fn run_engine<E: Engine + ?Sized>(
    engine: &E,
    duration_s: f64,
    observer: &mut dyn Observer,
) -> Result<RunStats, EngineError> {
    let Some((table, speed)) = held_table(engine.model()) else {
        let mut session = engine.start(Driven::NONE)?;
        session.set_stop_time(duration_s);
        let advance = session.advance_to(duration_s, observer)?;
        let mut stats = session.finish(observer);
        stats.stopped_early = advance == Advance::Stopped;
        return Ok(stats);
    };
    let table = table.clone();
    let mut session = engine.start(Driven {
        shaft_speed: speed,
        shaft_torque: !speed,
        ..Driven::NONE
    })?;
    session.set_stop_time(duration_s);
    let mut advance = Advance::Reached;
    while session.time_s() < duration_s {
        let t = session.time_s();
        let v = Some(table.value(t));
        session.set_inputs(&if speed {
            Inputs {
                shaft_speed_rad_s: v,
                ..Inputs::default()
            }
        } else {
            Inputs {
                shaft_torque_n_m: v,
                ..Inputs::default()
            }
        })?;
        let next = table
            .t_s
            .iter()
            .copied()
            .find(|&x| x > t)
            .map_or(duration_s, |x| x.min(duration_s));
        advance = session.advance_to(next, observer)?;
        if advance == Advance::Stopped {
            break;
        }
    }
    let mut stats = session.finish(observer);
    stats.stopped_early = advance == Advance::Stopped;
    Ok(stats)
}

/// A simulation engine built from a scene.
pub trait Engine {
    /// Short name (`"reference"`, `"multibody"`).
    fn name(&self) -> &'static str;
    /// Names of the discs in output order.
    fn disc_names(&self) -> Vec<String>;
    /// The model this engine runs.
    fn model(&self) -> &PackModel;
    /// Starts a steppable run at t = 0 ([`Session`]) whose caller drives the inputs `driven`
    /// (the others follow the scene's profiles). The session owns a copy of the model: the
    /// engine stays usable.
    fn start(&self, driven: Driven) -> Result<Box<dyn Session>, EngineError>;
    /// Runs from t = 0 to `duration_s`, sending samples and impacts to `observer`. On error,
    /// everything before the failure has already been delivered. Built on [`Engine::start`]
    /// ([`run_engine`]).
    fn run(
        &mut self,
        duration_s: f64,
        observer: &mut dyn Observer,
    ) -> Result<RunStats, EngineError> {
        run_engine(self, duration_s, observer)
    }
}

/// A network run advanced call by call, on either engine (both engines' `NetworkStepper`s
/// implement it with the same semantics, MODEL.md section 8, "Inputs"): what a caller that
/// does not care which engine runs the network holds, boxed.
pub trait NetworkSession: Send {
    /// The time the run stands at, s.
    fn time_s(&self) -> f64;

    /// The network as run (the inputs set so far in place of the scene's signals).
    fn network(&self) -> &Network;

    /// The state now (angles rad, speeds rad/s, torques N m, modes), at the session's time.
    fn sample_now(&mut self) -> NetworkSample;

    /// The temperatures of the thermal resolved pack that is coupling `k`, K (its discs',
    /// plates', then oil's; `None` for another coupling).
    fn pack_temperatures_k(&self, k: usize) -> Option<&[f64]>;

    /// Each coupling's heat (a mesh's work, a damper's loss) since t = 0, J.
    fn heat_j(&self) -> Vec<f64>;

    /// Sets `input` to `value` (N m, N or Pa), held from now on; a refused value leaves the
    /// run's inputs as they were.
    fn set_input(
        &mut self,
        input: NetworkInput,
        value: f64,
        obs: &mut dyn Observer,
    ) -> Result<(), EngineError>;

    /// Advances to `t_end` s (at most the run's end).
    fn advance_to(&mut self, t_end: f64, obs: &mut dyn Observer) -> Result<(), EngineError>;

    /// Ends the run where it stands: its last sample, heat, energy balance and counts.
    fn finish_boxed(self: Box<Self>, obs: &mut dyn Observer) -> NetworkRun;

    /// A copy of the whole run (a saved state).
    fn boxed_clone(&self) -> Box<dyn NetworkSession>;
}
