//! modelDescription.xml (FMI 2.0, co-simulation) from the variable table. Every attribute
//! value goes through quick-xml's writer, which escapes it: scene names and descriptions
//! never become markup.

use clutchpack_sdk::cosim::{uses_unit, Causality, Kind, Variable, UNITS};
use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, Event};
use quick_xml::Writer;

/// The FMU's model identifier: the binary is `binaries/linux64/<it>.so` and the C functions
/// are not prefixed.
pub const MODEL_IDENTIFIER: &str = "clutchpack_fmu";

/// The `RealTime` element of the model description's `VendorAnnotations` (tool
/// `clutchpack`): what a real-time host may count on, each a fact of the implementation
/// (docs/cosimulation.md, "Real time").
pub const REAL_TIME: &[(&str, &str)] = &[
    (
        "doStep",
        "synchronous: runs on the calling thread and returns when the step is done",
    ),
    (
        "frameCost",
        "a communication step costs what its simulated time costs: the engine's state \
         (step sizes, error history, sub-steps) carries across doStep calls, a pack's steps \
         landing on each communication point where an input may change; an input set to the \
         value it holds is not passed to the engine",
    ),
    (
        "communicationStepSize",
        "any step > 0, varying from call to call (canHandleVariableCommunicationStepSize)",
    ),
    (
        "state",
        "fmi2GetFMUstate and fmi2SetFMUstate copy the whole run, so that a master may redo a \
         step (not while recording)",
    ),
    (
        "recording",
        "written on its own thread through a bounded queue: doStep waits only when the writer \
         falls behind",
    ),
    (
        "measure",
        "clutchpack bench --frames 1ms SCENE --drive --paced (the frame time distribution on \
         this host); examples/python/fmu_realtime.py through the FMU",
    ),
];

/// What the model description says besides the variables.
#[derive(Debug, Clone)]
pub struct Header<'a> {
    /// The scene's name.
    pub model_name: &'a str,
    /// The scene's description.
    pub description: &'a str,
    /// The FMU's GUID (also in `resources/guid.txt`, checked at instantiation).
    pub guid: &'a str,
    /// The scene's duration, s (the default experiment's stop time).
    pub stop_time_s: f64,
    /// The default experiment's communication step, s.
    pub step_s: f64,
    /// Whether the inputs take derivatives (`canInterpolateInputs`): a pack's shaft speed
    /// and torque do; a network's inputs are held values.
    pub interpolates_inputs: bool,
}

fn start(name: &str, attrs: &[(&str, &str)]) -> Event<'static> {
    let mut e = BytesStart::new(name.to_string());
    for (k, v) in attrs {
        e.push_attribute((*k, *v));
    }
    Event::Start(e)
}

fn empty(name: &str, attrs: &[(&str, &str)]) -> Event<'static> {
    let mut e = BytesStart::new(name.to_string());
    for (k, v) in attrs {
        e.push_attribute((*k, *v));
    }
    Event::Empty(e)
}

fn end(name: &str) -> Event<'static> {
    Event::End(BytesEnd::new(name.to_string()))
}

/// The model description of an FMU with `header` and `vars`.
pub fn model_description(header: &Header, vars: &[Variable]) -> String {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    let mut events = vec![Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None))];
    let tool = format!("clutchpack {}", env!("CARGO_PKG_VERSION"));
    events.push(start(
        "fmiModelDescription",
        &[
            ("fmiVersion", "2.0"),
            ("modelName", header.model_name),
            ("guid", header.guid),
            ("description", header.description),
            ("generationTool", &tool),
            ("variableNamingConvention", "structured"),
            ("numberOfEventIndicators", "0"),
        ],
    ));
    events.push(empty(
        "CoSimulation",
        &[
            ("modelIdentifier", MODEL_IDENTIFIER),
            ("needsExecutionTool", "false"),
            ("canHandleVariableCommunicationStepSize", "true"),
            (
                "canInterpolateInputs",
                if header.interpolates_inputs {
                    "true"
                } else {
                    "false"
                },
            ),
            ("maxOutputDerivativeOrder", "0"),
            ("canRunAsynchronuously", "false"),
            ("canBeInstantiatedOnlyOncePerProcess", "false"),
            ("canNotUseMemoryManagementFunctions", "true"),
            ("canGetAndSetFMUstate", "true"),
            ("canSerializeFMUstate", "false"),
            ("providesDirectionalDerivative", "false"),
        ],
    ));
    events.push(start("UnitDefinitions", &[]));
    for (name, exps) in UNITS {
        if !uses_unit(name, vars) {
            continue;
        }
        events.push(start("Unit", &[("name", name)]));
        let values: Vec<(String, &str)> = exps
            .iter()
            .zip(["kg", "m", "s", "rad", "K"])
            .filter(|(e, _)| **e != 0)
            .map(|(e, b)| (e.to_string(), b))
            .collect();
        let attrs: Vec<(&str, &str)> = values.iter().map(|(e, b)| (*b, e.as_str())).collect();
        events.push(empty("BaseUnit", &attrs));
        events.push(end("Unit"));
    }
    events.push(end("UnitDefinitions"));
    events.push(empty(
        "DefaultExperiment",
        &[
            ("startTime", "0"),
            ("stopTime", &header.stop_time_s.to_string()),
            ("stepSize", &header.step_s.to_string()),
        ],
    ));
    // What the FMU honours in a real-time loop (issue 46), in the tool's own annotation
    // (FMI 2.0 section 2.2.6): facts of the implementation, true of every FMU it builds; the
    // frame's cost on a host is measured there (`measure`).
    events.push(start("VendorAnnotations", &[]));
    events.push(start("Tool", &[("name", "clutchpack")]));
    events.push(empty("RealTime", REAL_TIME));
    events.push(end("Tool"));
    events.push(end("VendorAnnotations"));
    events.push(start("ModelVariables", &[]));
    for v in vars {
        let vr = v.vr.to_string();
        let (causality, variability, initial) = match (v.causality, v.kind) {
            (Causality::Parameter, _) => ("parameter", "fixed", Some("exact")),
            (Causality::Input, _) => ("input", "continuous", None),
            (Causality::Output, Kind::Real) => ("output", "continuous", Some("calculated")),
            (Causality::Output, _) => ("output", "discrete", Some("calculated")),
        };
        let mut attrs = vec![
            ("name", v.name.as_str()),
            ("valueReference", vr.as_str()),
            ("description", v.description.as_str()),
            ("causality", causality),
            ("variability", variability),
        ];
        if let Some(i) = initial {
            attrs.push(("initial", i));
        }
        events.push(start("ScalarVariable", &attrs));
        let start_real = v.start_real.map(|x| x.to_string());
        let mut type_attrs = Vec::new();
        if let Some(u) = v.unit {
            type_attrs.push(("unit", u));
        }
        if let Some(s) = &start_real {
            type_attrs.push(("start", s.as_str()));
        }
        if let Some(s) = &v.start_string {
            type_attrs.push(("start", s.as_str()));
        }
        let type_name = match v.kind {
            Kind::Real => "Real",
            Kind::Integer => "Integer",
            Kind::String => "String",
        };
        events.push(empty(type_name, &type_attrs));
        events.push(end("ScalarVariable"));
    }
    events.push(end("ModelVariables"));
    events.push(start("ModelStructure", &[]));
    let outputs: Vec<String> = vars
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| (i + 1).to_string())
        .collect();
    for section in ["Outputs", "InitialUnknowns"] {
        events.push(start(section, &[]));
        for index in &outputs {
            events.push(empty("Unknown", &[("index", index)]));
        }
        events.push(end(section));
    }
    events.push(end("ModelStructure"));
    events.push(end("fmiModelDescription"));
    for e in events {
        w.write_event(e).expect("writing to memory");
    }
    String::from_utf8(w.into_inner()).expect("the writer writes UTF-8")
}
