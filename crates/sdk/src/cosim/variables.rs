//! The co-simulation variables of a scene (parameters, inputs, outputs with names, units and
//! descriptions): the one table that the FMU's model description and its
//! `fmi2GetReal`/`fmi2SetReal`, and Python's `Simulation`, read (through
//! [`super::CoSimulation`]), so the value references a host sees are the ones the binary
//! serves and Python's names are the FMU's.

use super::inputs::Input;
use clutchpack_model::session::Driven;
use clutchpack_scene::Scene;

/// An FMI 2.0 base type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `fmi2Real`.
    Real,
    /// `fmi2Integer`.
    Integer,
    /// `fmi2String`.
    String,
}

/// An FMI 2.0 causality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set before the run starts (variability "fixed").
    Parameter,
    /// Set by the host at each communication point (held between them).
    Input,
    /// Computed by the FMU.
    Output,
}

/// A body's output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyField {
    /// Speed, rad/s.
    Speed,
    /// Per-tooth load now, N (eq 6's sign).
    Load,
    /// Spline torque on the body now, N m (`-n F Rb`, eq 5).
    Torque,
    /// Largest `|peak|` of its impacts so far, N.
    MaxLoad,
    /// Miner damage of its teeth so far (dimensionless).
    Damage,
}

/// A friction interface's output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InterfaceField {
    /// Torque on the upper body, N m.
    Torque,
    /// Slip speed upper minus lower, rad/s.
    Slip,
    /// Clamp force, N.
    Clamp,
    /// Heat since t = 0, J.
    Heat,
}

/// What a variable stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Parameter: the engine's name.
    Engine,
    /// Parameter: the latest time the FMU may be advanced to, s.
    DurationLimit,
    /// Parameter: the MCAP recording's path (empty: none).
    RecordingPath,
    /// An input.
    Input(Input),
    /// The shaft's angle, rad.
    ShaftAngle,
    /// The inertial shaft's speed, rad/s.
    ShaftSpeed,
    /// Torque of the pack on the shaft, N m.
    PackShaftTorque,
    /// Torque of the plates on the drum or housing, N m.
    CarrierTorque,
    /// The drum's angle, rad.
    DrumAngle,
    /// The drum's speed, rad/s.
    DrumSpeed,
    /// Body `i` (the discs, then the plates).
    Body(usize, BodyField),
    /// Friction interface `m`.
    Interface(usize, InterfaceField),
    /// Impacts closed so far (Integer).
    Impacts,
    /// The impact that closed last.
    LastImpact(ImpactField),
    /// A thermal run's temperature of body `i` (the discs, then the plates), K.
    BodyTemperature(usize),
    /// A thermal run's oil temperature, K.
    OilTemperature,
    /// A network's input `j`, in [`crate::network_inputs`]' order (a drive torque, N m, or a
    /// clutch's normal force, N).
    NetworkInput(usize),
    /// A network's output `j`, in [`crate::network_outputs`]' order.
    NetworkOutput(usize),
}

/// What the last impact's outputs give.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImpactField {
    /// The body's number, 1-based in the discs-then-plates order (Integer; 0: none yet).
    Body,
    /// Onset, s.
    Onset,
    /// Time of the peak, s.
    PeakTime,
    /// End, s.
    End,
    /// Signed peak per-tooth load, N.
    Peak,
}

/// One scalar variable of the model description.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// Structured name, e.g. `discs[3].load_n` (indices from 1, as Modelica's).
    pub name: String,
    /// What it is.
    pub quantity: Quantity,
    /// Its base type.
    pub kind: Kind,
    /// Parameter, input or output.
    pub causality: Causality,
    /// Value reference (numbered per base type from 0).
    pub vr: u32,
    /// Unit (a name of the model description's unit definitions), if any.
    pub unit: Option<&'static str>,
    /// What it means, with its sign.
    pub description: String,
    /// Start value of a Real parameter or input.
    pub start_real: Option<f64>,
    /// Start value of a String parameter.
    pub start_string: Option<String>,
}

/// What every input's description says of an input its host gives no signal (an FMU drives
/// every input its pack has; docs/DECISIONS.md "Co-simulation").
pub const UNCONNECTED: &str = "Give it a signal: unconnected, it holds this start value (the \
                               scene's value at t = 0) for the whole run, not the scene's \
                               profile over time";

/// The units the variables use, with their SI base-unit exponents `(kg, m, s, rad, K)`
/// (`K` only for a thermal scene's temperatures: [`uses_unit`]).
pub const UNITS: [(&str, [i32; 5]); 9] = [
    ("s", [0, 0, 1, 0, 0]),
    ("rad", [0, 0, 0, 1, 0]),
    ("rad/s", [0, 0, -1, 1, 0]),
    ("N", [1, 1, -2, 0, 0]),
    ("N.m", [1, 2, -2, 0, 0]),
    ("Pa", [1, -1, -2, 0, 0]),
    ("J", [1, 2, -2, 0, 0]),
    ("1", [0, 0, 0, 0, 0]),
    ("K", [0, 0, 0, 0, 1]),
];

/// Whether a model description lists the unit `name` for `vars`: every unit of [`UNITS`]
/// but `K`, which only a thermal scene's temperatures use (an isothermal scene's FMU keeps
/// the description it had).
pub fn uses_unit(name: &str, vars: &[Variable]) -> bool {
    name != "K" || vars.iter().any(|v| v.unit == Some("K"))
}

/// The co-simulation variables (the FMU's) of `scene`, whose run the engine `engine` (`reference` or
/// `multibody`) makes with the inputs `driven` (an FMU drives what [`Driven::all_for`] gives
/// the pack): parameters, then inputs, then outputs.
pub fn variables(scene: &Scene, engine: &str, driven: Driven) -> Vec<Variable> {
    table(scene, engine, driven, None)
}

/// [`variables`] of a network scene whose caller drives only the inputs `driven` (indices
/// into [`crate::network_inputs`]' list; Python's `Simulation`), the others following the
/// scene: only those are inputs.
pub(crate) fn network_variables_driving(
    scene: &Scene,
    engine: &str,
    driven: &[usize],
) -> Vec<Variable> {
    table(scene, engine, Driven::NONE, Some(driven))
}

/// [`variables`], a network's inputs all (`network_driven` `None`) or those listed.
fn table(
    scene: &Scene,
    engine: &str,
    driven: Driven,
    network_driven: Option<&[usize]>,
) -> Vec<Variable> {
    let mut v = Table::default();
    let pack = &scene.pack;
    parameters(&mut v, scene, engine);
    if let Some(net) = &scene.network {
        let driven = |j: usize| network_driven.is_none_or(|d| d.contains(&j));
        network_variables(&mut v, net, scene.transmission.as_ref(), &driven);
        return v.0;
    }
    // every input a host is given, with what it holds when the host connects nothing to it
    // (docs/DECISIONS.md "Co-simulation": an FMU drives every input it has)
    let starts = [
        (
            Input::ShaftSpeed,
            driven.shaft_speed.then(|| pack.shaft.initial_speed_rad_s()),
            "speed of the prescribed shaft (positive: its positive rotation); the shaft's \
             angle integrates it",
        ),
        (
            Input::ShaftTorque,
            driven
                .shaft_torque
                .then(|| pack.shaft.drive_torque_n_m(0.0)),
            "drive torque on the inertial shaft (eq 4's T_drive, positive along the positive \
             rotation)",
        ),
        (
            Input::DrumLoad,
            pack.drum
                .as_ref()
                .filter(|_| driven.drum_load)
                .map(|d| d.load_torque_n_m),
            "load torque on the drum (negative: it brakes a drum turning the positive way)",
        ),
        (
            Input::PistonPressure,
            pack.stack
                .as_ref()
                .filter(|_| driven.piston_pressure)
                .map(|s| s.piston.pressure.pressure_pa(0.0)),
            "pressure on the piston (>= 0)",
        ),
    ];
    for (input, start, what) in starts {
        if let Some(start) = start {
            v.input(
                input,
                &format!("{what}; held until the next communication point. {UNCONNECTED}"),
                start,
            );
        }
    }
    v.output(
        "shaft.angle_rad",
        Quantity::ShaftAngle,
        "rad",
        "the shaft's angle",
    );
    if matches!(pack.shaft, clutchpack_model::Shaft::Inertial { .. }) {
        v.output(
            "shaft.speed_rad_s",
            Quantity::ShaftSpeed,
            "rad/s",
            "the inertial shaft's speed",
        );
    }
    v.output(
        "pack.shaft_torque_n_m",
        Quantity::PackShaftTorque,
        "N.m",
        "torque of the pack on the shaft now (the discs' spline reactions sum n F Rb, eq 4; \
         positive along the positive rotation): what a host's shaft inertia feels",
    );
    if !pack.plates.is_empty() {
        let on = if pack.drum.is_some() {
            "drum"
        } else {
            "housing"
        };
        v.output(
            "pack.carrier_torque_n_m",
            Quantity::CarrierTorque,
            "N.m",
            &format!(
                "torque of the plates on the {on} now (their spline reactions; positive along \
                 the positive rotation)"
            ),
        );
    }
    if pack.drum.is_some() {
        v.output(
            "drum.angle_rad",
            Quantity::DrumAngle,
            "rad",
            "the drum's angle",
        );
        v.output(
            "drum.speed_rad_s",
            Quantity::DrumSpeed,
            "rad/s",
            "the drum's speed",
        );
    }
    let nd = pack.discs.len();
    for (i, body) in pack.discs.iter().chain(&pack.plates).enumerate() {
        let (list, k) = if i < nd {
            ("discs", i + 1)
        } else {
            ("plates", i - nd + 1)
        };
        let name = &body.name;
        let fields = [
            (BodyField::Speed, "speed_rad_s", Some("rad/s"), "speed now"),
            (
                BodyField::Load,
                "load_n",
                Some("N"),
                "per-tooth load now (eq 6; negative when its carrier leads)",
            ),
            (
                BodyField::Torque,
                "torque_n_m",
                Some("N.m"),
                "spline torque on it now (-n F Rb, eq 5)",
            ),
            (
                BodyField::MaxLoad,
                "max_load_n",
                Some("N"),
                "largest per-tooth |load| of its impacts so far",
            ),
            (
                BodyField::Damage,
                "damage",
                Some("1"),
                "Miner damage sum of its teeth so far (1: the predicted life used up; MODEL.md \
                 section 7)",
            ),
        ];
        for (field, suffix, unit, what) in fields {
            v.push(Variable {
                name: format!("{list}[{k}].{suffix}"),
                quantity: Quantity::Body(i, field),
                kind: Kind::Real,
                causality: Causality::Output,
                vr: 0,
                unit,
                description: format!("{name}: {what}"),
                start_real: None,
                start_string: None,
            });
        }
    }
    for (m, f) in crate::friction_interfaces(scene).iter().enumerate() {
        let what = format!("interface {} ({} | {})", m + 1, f.lower, f.upper);
        let fields = [
            (
                InterfaceField::Torque,
                "torque_n_m",
                "N.m",
                "friction (or open-gap drag) torque on the upper body now",
            ),
            (
                InterfaceField::Slip,
                "slip_rad_s",
                "rad/s",
                "slip speed, upper minus lower body, now",
            ),
            (InterfaceField::Clamp, "clamp_n", "N", "clamp force now"),
            (InterfaceField::Heat, "heat_j", "J", "heat since t = 0"),
        ];
        for (field, suffix, unit, text) in fields {
            v.output(
                &format!("interfaces[{}].{suffix}", m + 1),
                Quantity::Interface(m, field),
                unit,
                &format!("{what}: {text}"),
            );
        }
    }
    v.push(Variable {
        name: "last_impact.body".into(),
        quantity: Quantity::LastImpact(ImpactField::Body),
        kind: Kind::Integer,
        causality: Causality::Output,
        vr: 0,
        unit: None,
        description: "the body of the impact that closed last: its number in the discs then \
                      the plates, from 1 (0: none yet; when several close within one step, the \
                      last; the recording has them all)"
            .into(),
        start_real: None,
        start_string: None,
    });
    for (field, suffix, unit, what) in [
        (ImpactField::Onset, "t_on_s", "s", "onset"),
        (ImpactField::PeakTime, "t_peak_s", "s", "time of the peak"),
        (ImpactField::End, "t_off_s", "s", "end"),
        (
            ImpactField::Peak,
            "peak_n",
            "N",
            "signed peak per-tooth load (eq 6's sign)",
        ),
    ] {
        v.output(
            &format!("last_impact.{suffix}"),
            Quantity::LastImpact(field),
            unit,
            &format!("the impact that closed last: its {what} (0: none yet)"),
        );
    }
    v.push(Variable {
        name: "impacts".into(),
        quantity: Quantity::Impacts,
        kind: Kind::Integer,
        causality: Causality::Output,
        vr: 0,
        unit: None,
        description: "impacts (contact events of any body) closed so far".into(),
        start_real: None,
        start_string: None,
    });
    // a thermal scene's temperatures (MODEL.md section 9), after every other output so that
    // the value references of those stay what an isothermal scene's are
    if scene.thermal.is_some() {
        for (i, body) in pack.discs.iter().chain(&pack.plates).enumerate() {
            let (list, k) = if i < nd {
                ("discs", i + 1)
            } else {
                ("plates", i - nd + 1)
            };
            v.output(
                &format!("{list}[{k}].temperature_k"),
                Quantity::BodyTemperature(i),
                "K",
                &format!(
                    "{}: its lumped temperature at the last thermal window's end",
                    body.name
                ),
            );
        }
        v.output(
            "oil.temperature_k",
            Quantity::OilTemperature,
            "K",
            "the oil's temperature at the last thermal window's end",
        );
    }
    v.0
}

/// The parameters every co-simulation has: the engine, the duration limit, the recording's
/// path.
fn parameters(v: &mut Table, scene: &Scene, engine: &str) {
    v.string(
        "engine",
        Quantity::Engine,
        "the engine: \"reference\" (one rotational degree of freedom per body) or \
         \"multibody\" (rapier3d bodies, per-tooth contacts)",
        engine,
    );
    v.param(
        "duration_limit_s",
        Quantity::DurationLimit,
        "s",
        "the latest time the FMU may be advanced to; a step past it fails (a guard against \
         a runaway host; the scene's simulation.duration_s by default)",
        scene.simulation.duration_s,
    );
    v.string(
        "recording_path",
        Quantity::RecordingPath,
        "an MCAP file to record the co-simulated run to (empty: no recording); replaced \
         if it exists",
        "",
    );
}

/// A network scene's inputs (every turning body's drive torque, every clutch's normal force;
/// each starting at the scene's value at t = 0), those `driven`, and outputs
/// ([`crate::network_outputs`]).
fn network_variables(
    v: &mut Table,
    net: &clutchpack_model::network::Network,
    tr: Option<&clutchpack_model::network::Transmission>,
    driven: &dyn Fn(usize) -> bool,
) {
    let mut inputs = Vec::new();
    for (j, (var, start)) in crate::network_cosim::network_input_variables(net)
        .into_iter()
        .enumerate()
        .filter(|(j, _)| driven(*j))
    {
        inputs.push(var.name.clone());
        v.push(Variable {
            name: var.name,
            quantity: Quantity::NetworkInput(j),
            kind: Kind::Real,
            causality: Causality::Input,
            vr: 0,
            unit: Some(var.unit),
            description: format!(
                "{}; held until the next communication point. {UNCONNECTED}",
                var.description
            ),
            start_real: Some(start),
            start_string: None,
        });
    }
    for (j, var) in crate::network_outputs(net, tr).into_iter().enumerate() {
        if inputs.contains(&var.name) {
            // a driven prescribed body's speed is its input (a one-pack scene's shaft's is)
            continue;
        }
        v.push(Variable {
            name: var.name,
            quantity: Quantity::NetworkOutput(j),
            kind: Kind::Real,
            causality: Causality::Output,
            vr: 0,
            unit: Some(var.unit),
            description: var.description,
            start_real: None,
            start_string: None,
        });
    }
}

/// Builds the list, numbering value references per base type.
#[derive(Default)]
struct Table(Vec<Variable>);

impl Table {
    fn push(&mut self, mut var: Variable) {
        var.vr = self.0.iter().filter(|x| x.kind == var.kind).count() as u32;
        self.0.push(var);
    }
    fn string(&mut self, name: &str, quantity: Quantity, description: &str, start: &str) {
        self.push(Variable {
            name: name.into(),
            quantity,
            kind: Kind::String,
            causality: Causality::Parameter,
            vr: 0,
            unit: None,
            description: description.into(),
            start_real: None,
            start_string: Some(start.into()),
        });
    }
    fn param(&mut self, name: &str, q: Quantity, unit: &'static str, what: &str, start: f64) {
        self.push(Variable {
            name: name.into(),
            quantity: q,
            kind: Kind::Real,
            causality: Causality::Parameter,
            vr: 0,
            unit: Some(unit),
            description: what.into(),
            start_real: Some(start),
            start_string: None,
        });
    }
    fn input(&mut self, input: Input, what: &str, start: f64) {
        self.push(Variable {
            name: input.name().into(),
            quantity: Quantity::Input(input),
            kind: Kind::Real,
            causality: Causality::Input,
            vr: 0,
            unit: Some(input.unit()),
            description: what.into(),
            start_real: Some(start),
            start_string: None,
        });
    }
    fn output(&mut self, name: &str, q: Quantity, unit: &'static str, what: &str) {
        self.push(Variable {
            name: name.into(),
            quantity: q,
            kind: Kind::Real,
            causality: Causality::Output,
            vr: 0,
            unit: Some(unit),
            description: what.into(),
            start_real: None,
            start_string: None,
        });
    }
}
