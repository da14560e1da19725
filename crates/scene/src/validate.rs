//! Stage two: the raw file ([`crate::raw`]) -> validated model values.
//!
//! Every value is checked where it is written (its type, that it is finite, its range), then
//! the rules between keys (which keys a drive kind or shaft mode takes, the oil parameters a
//! film needs, the film and the start position against the free play). Each broken rule
//! becomes one [`Problem`] with the key path, the value as written and the rule; checking goes
//! on after a problem, so that one run lists them all. A value that is itself invalid is not
//! used by the rules between keys (its problem is already reported).
//!
//! Disc parameters resolve in this order: the disc's own value, then `[defaults]`, then the
//! built-in default; a required key found nowhere is reported as missing at the disc's key
//! path (`discs[1].spline.teeth`). A bad value in `[defaults]` is reported once, at its
//! `defaults.` path. Plates resolve the same way through `[plate_defaults]`. The `[drum]`
//! and `[stack]` tables are checked on their own, then against the bodies (a stack of N
//! discs needs N + 1 plates, a drum needs plates).

use crate::csv;
use crate::error::Problem;
use crate::raw::{
    RawDisc, RawDrive, RawDrum, RawFriction, RawPressure, RawScene, RawShaft, RawSimulation,
    RawStack,
};
use crate::schema;
use crate::{EngineChoice, Simulation};
use clutchpack_model::{
    DiscModel, DrumModel, FrictionCurve, Harmonic, Hertz, LawKind, OilFilm, OpenGap, PackModel,
    Piston, PressureProfile, Shaft, ShaftExcitation, SpeedProfile, SplineGeometry, StackModel,
    Table, TableError, ToothLaw,
};
use std::path::Path;
use toml::Value;

/// The validated content of a scene file.
pub(crate) struct Validated {
    pub name: String,
    pub description: String,
    pub simulation: Simulation,
    pub pack: PackModel,
}

/// The outcome of checking one value where it is written.
#[derive(Debug, Clone, PartialEq)]
enum Field<T> {
    /// The key is not in the file.
    Absent,
    /// The key is there but its value breaks a rule (already reported).
    Invalid,
    /// The key is there and its value is good.
    Valid(T),
}

impl<T> Field<T> {
    /// The value, or `default` if absent; `None` if invalid.
    fn or(self, default: T) -> Option<T> {
        match self {
            Field::Absent => Some(default),
            Field::Invalid => None,
            Field::Valid(v) => Some(v),
        }
    }

    /// The value; reports `key: missing (hint)` if absent; `None` if absent or invalid.
    fn required(self, ck: &mut Checker, key: &str, hint: &str) -> Option<T> {
        match self {
            Field::Absent => {
                ck.report(key, None, format!("missing ({hint})"));
                None
            }
            Field::Invalid => None,
            Field::Valid(v) => Some(v),
        }
    }
}

/// The range rule of a number (every number must also be finite).
#[derive(Debug, Clone, Copy)]
enum Rule {
    /// Any finite number.
    Finite,
    /// `> 0`.
    Positive,
    /// `>= 0`.
    NonNegative,
    /// In `[lo, hi]`, with the rule's text.
    Closed(f64, f64, &'static str),
    /// In `(lo, hi)`, with the rule's text.
    Open(f64, f64, &'static str),
}

impl Rule {
    fn holds(self, x: f64) -> bool {
        match self {
            Rule::Finite => true,
            Rule::Positive => x > 0.0,
            Rule::NonNegative => x >= 0.0,
            Rule::Closed(lo, hi, _) => (lo..=hi).contains(&x),
            Rule::Open(lo, hi, _) => x > lo && x < hi,
        }
    }

    fn text(self) -> &'static str {
        match self {
            Rule::Finite => "must be a finite number",
            Rule::Positive => "must be > 0",
            Rule::NonNegative => "must be >= 0",
            Rule::Closed(_, _, t) | Rule::Open(_, _, t) => t,
        }
    }
}

/// A value as written, in TOML syntax, for messages.
fn show(v: &Value) -> String {
    v.to_string()
}

/// Collects problems and checks single values.
#[derive(Debug, Default)]
pub(crate) struct Checker {
    /// Every problem found so far.
    pub problems: Vec<Problem>,
}

impl Checker {
    fn report(&mut self, key: impl Into<String>, value: Option<String>, rule: impl Into<String>) {
        self.problems.push(Problem::new(key, value, rule));
    }

    /// A finite number (an integer is accepted) that satisfies `rule`.
    fn number(&mut self, key: &str, v: Option<&Value>, rule: Rule) -> Field<f64> {
        let Some(v) = v else { return Field::Absent };
        let x = match v {
            Value::Float(x) => *x,
            Value::Integer(i) => *i as f64,
            _ => {
                self.report(key, Some(show(v)), "must be a number");
                return Field::Invalid;
            }
        };
        if !x.is_finite() {
            self.report(key, Some(show(v)), "must be a finite number");
            Field::Invalid
        } else if !rule.holds(x) {
            self.report(key, Some(show(v)), rule.text());
            Field::Invalid
        } else {
            Field::Valid(x)
        }
    }

    /// An integer count, >= 1 (fits a `u32`).
    fn count(&mut self, key: &str, v: Option<&Value>) -> Field<u32> {
        let Some(v) = v else { return Field::Absent };
        match v.as_integer().map(u32::try_from) {
            Some(Ok(n)) if n >= 1 => Field::Valid(n),
            _ => {
                self.report(key, Some(show(v)), "must be an integer >= 1");
                Field::Invalid
            }
        }
    }

    /// A string.
    fn text(&mut self, key: &str, v: Option<&Value>) -> Field<String> {
        let Some(v) = v else { return Field::Absent };
        match v.as_str() {
            Some(s) => Field::Valid(s.to_string()),
            None => {
                self.report(key, Some(show(v)), "must be a string");
                Field::Invalid
            }
        }
    }

    /// One of the given names.
    fn choice<T: Copy>(&mut self, key: &str, v: Option<&Value>, options: &[(&str, T)]) -> Field<T> {
        let Some(v) = v else { return Field::Absent };
        match options.iter().find(|(name, _)| v.as_str() == Some(name)) {
            Some((_, t)) => Field::Valid(*t),
            None => {
                let names: Vec<String> = options.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                self.report(
                    key,
                    Some(show(v)),
                    format!("must be one of: {}", names.join(", ")),
                );
                Field::Invalid
            }
        }
    }

    /// A boolean (`true` / `false`).
    fn boolean(&mut self, key: &str, v: Option<&Value>) -> Field<bool> {
        let Some(v) = v else { return Field::Absent };
        match v.as_bool() {
            Some(b) => Field::Valid(b),
            None => {
                self.report(key, Some(show(v)), "must be true or false");
                Field::Invalid
            }
        }
    }

    /// An array of finite numbers (integers accepted), of length `len` if given. A bad item is
    /// reported at its index (`key[3]`), a wrong length at `key`.
    fn numbers(&mut self, key: &str, v: Option<&Value>, len: Option<usize>) -> Field<Vec<f64>> {
        let Some(v) = v else { return Field::Absent };
        let Some(items) = v.as_array() else {
            self.report(key, Some(show(v)), "must be an array of numbers");
            return Field::Invalid;
        };
        if let Some(n) = len {
            if items.len() != n {
                self.report(
                    key,
                    Some(show(v)),
                    format!("must have exactly {n} numbers (it has {})", items.len()),
                );
                return Field::Invalid;
            }
        }
        let mut out = Some(Vec::with_capacity(items.len()));
        for (j, item) in items.iter().enumerate() {
            match self.number(&format!("{key}[{j}]"), Some(item), Rule::Finite) {
                Field::Valid(x) => {
                    if let Some(o) = out.as_mut() {
                        o.push(x)
                    }
                }
                _ => out = None,
            }
        }
        match out {
            Some(o) => Field::Valid(o),
            None => Field::Invalid,
        }
    }

    /// Reports a key that is present but not allowed in this configuration.
    fn not_allowed(&mut self, key: &str, v: Option<&Value>, rule: &str) -> bool {
        match v {
            Some(v) => {
                self.report(key, Some(show(v)), rule);
                true
            }
            None => false,
        }
    }
}

/// Checks everything; `None` if any value needed to build the model is missing or invalid
/// (the problems are in `ck`).
pub(crate) fn validate(
    raw: &RawScene,
    file_stem: &str,
    base_dir: &Path,
    ck: &mut Checker,
) -> Option<Validated> {
    let name = ck.text("name", raw.name.as_ref()).or(file_stem.to_string());
    let description = ck
        .text("description", raw.description.as_ref())
        .or(String::new());
    let simulation = simulation(ck, raw.simulation.as_ref());
    let (kind, drive) = drive(ck, raw.drive.as_ref(), base_dir);
    let shaft = shaft(ck, raw.shaft.as_ref(), kind, drive);
    let mut names = Vec::new();
    let discs = bodies(
        ck,
        DISCS,
        raw.defaults.as_ref(),
        raw.discs.as_deref(),
        true,
        &mut names,
    );
    let plates = bodies(
        ck,
        PLATES,
        raw.plate_defaults.as_ref(),
        raw.plates.as_deref(),
        false,
        &mut names,
    );
    let drum = raw.drum.as_ref().map(|r| drum(ck, r));
    let stack = raw.stack.as_ref().map(|r| stack(ck, r));
    // The stack alternates plates and discs: N discs need N + 1 plates; a drum carries plates.
    let n_discs = raw.discs.as_ref().map_or(0, Vec::len);
    let n_plates = raw.plates.as_ref().map_or(0, Vec::len);
    if raw.stack.is_some() && n_plates != n_discs + 1 {
        ck.report(
            "plates",
            Some(format!("[...{n_plates} entries]")),
            format!(
                "a [stack] of {n_discs} discs needs {} [[plates]] entries (plate, disc, plate, \
                 ..., plate)",
                n_discs + 1
            ),
        );
        return None;
    }
    if raw.drum.is_some() && n_plates == 0 {
        ck.report(
            "drum",
            None,
            "a [drum] carries the separator plates: add [[plates]] entries",
        );
        return None;
    }
    Some(Validated {
        name: name?,
        description: description?,
        simulation: simulation?,
        pack: PackModel {
            shaft: shaft?,
            discs: discs?,
            plates: plates?,
            drum: drum.map_or(Some(None), |d| d.map(Some))?,
            stack: stack.map_or(Some(None), |s| s.map(Some))?,
        },
    })
}

/// `[drum]`.
fn drum(ck: &mut Checker, r: &RawDrum) -> Option<DrumModel> {
    let inertia = ck
        .number(
            "drum.inertia_kg_m2",
            r.inertia_kg_m2.as_ref(),
            Rule::Positive,
        )
        .required(
            ck,
            "drum.inertia_kg_m2",
            "required with [drum]; set it there",
        );
    let load = ck
        .number(
            "drum.load_torque_n_m",
            r.load_torque_n_m.as_ref(),
            Rule::Finite,
        )
        .or(0.0);
    let drag = ck
        .number(
            "drum.drag_n_m_s_rad",
            r.drag_n_m_s_rad.as_ref(),
            Rule::NonNegative,
        )
        .or(0.0);
    let speed = ck
        .number(
            "drum.initial_speed_rad_s",
            r.initial_speed_rad_s.as_ref(),
            Rule::Finite,
        )
        .or(0.0);
    Some(DrumModel {
        inertia_kg_m2: inertia?,
        load_torque_n_m: load?,
        drag_n_m_s_rad: drag?,
        initial_speed_rad_s: speed?,
    })
}

/// Two arrays of the same length, the first strictly increasing: a table `y(x)`.
fn table(
    ck: &mut Checker,
    (x_key, x): (&str, Option<&Value>),
    (y_key, y): (&str, Option<&Value>),
    y_rule: Rule,
    hint: &str,
) -> Option<Table> {
    let xs = ck.numbers(x_key, x, None).required(ck, x_key, hint);
    let ys = ck.numbers(y_key, y, None).required(ck, y_key, hint);
    let (xs, ys) = (xs?, ys?);
    let mut ok = true;
    for (j, v) in ys.iter().enumerate() {
        if !y_rule.holds(*v) {
            ck.report(format!("{y_key}[{j}]"), Some(v.to_string()), y_rule.text());
            ok = false;
        }
    }
    if !ok {
        return None;
    }
    match Table::new(xs.clone(), ys.clone()) {
        Ok(t) => Some(t),
        Err(e) => {
            let key = match e {
                TableError::NotIncreasing(j, _) => format!("{x_key}[{j}]"),
                TableError::LengthMismatch(..) => y_key.to_string(),
                _ => x_key.to_string(),
            };
            let rule = match e {
                TableError::LengthMismatch(a, b) => {
                    format!("must have one value per entry of {x_key} ({a}), has {b}")
                }
                TableError::NotIncreasing(..) => "must increase strictly".to_string(),
                e => e.to_string(),
            };
            ck.report(key, None, rule);
            None
        }
    }
}

/// `[stack]` with its `friction`, `pressure` and `open_gap` tables.
fn stack(ck: &mut Checker, r: &RawStack) -> Option<StackModel> {
    let hint = "required with [stack]; set it there";
    let inner = ck
        .number(
            "stack.face_inner_radius_m",
            r.face_inner_radius_m.as_ref(),
            Rule::Positive,
        )
        .required(ck, "stack.face_inner_radius_m", hint);
    let outer = ck
        .number(
            "stack.face_outer_radius_m",
            r.face_outer_radius_m.as_ref(),
            Rule::Positive,
        )
        .required(ck, "stack.face_outer_radius_m", hint);
    if let (Some(ri), Some(ro)) = (inner, outer) {
        if ro <= ri {
            ck.report(
                "stack.face_outer_radius_m",
                Some(ro.to_string()),
                format!("must be > stack.face_inner_radius_m = {ri}"),
            );
        }
    }
    let spline = ck
        .number(
            "stack.spline_friction_coefficient",
            r.spline_friction_coefficient.as_ref(),
            Rule::NonNegative,
        )
        .or(0.0);
    let area = ck
        .number(
            "stack.piston_area_m2",
            r.piston_area_m2.as_ref(),
            Rule::Positive,
        )
        .required(ck, "stack.piston_area_m2", hint);
    let spring = ck
        .number(
            "stack.return_spring_n",
            r.return_spring_n.as_ref(),
            Rule::NonNegative,
        )
        .or(0.0);

    // friction
    let empty_f = RawFriction::default();
    let f = r.friction.as_ref().unwrap_or(&empty_f);
    let kind = ck
        .choice(
            "stack.friction.kind",
            f.kind.as_ref(),
            &[("stribeck", false), ("table", true)],
        )
        .or(false);
    let friction = match kind {
        None => None,
        Some(false) => {
            for (k, v) in [("slip_m_s", &f.slip_m_s), ("mu", &f.mu)] {
                ck.not_allowed(
                    &format!("stack.friction.{k}"),
                    v.as_ref(),
                    "only allowed with stack.friction.kind = \"table\"",
                );
            }
            let st = ck
                .number(
                    "stack.friction.static_mu",
                    f.static_mu.as_ref(),
                    Rule::Positive,
                )
                .required(
                    ck,
                    "stack.friction.static_mu",
                    "required; set it in [stack.friction]",
                );
            let kin = ck
                .number(
                    "stack.friction.kinetic_mu",
                    f.kinetic_mu.as_ref(),
                    Rule::Positive,
                )
                .or(st.unwrap_or(0.1));
            let vs = ck
                .number(
                    "stack.friction.stribeck_speed_m_s",
                    f.stribeck_speed_m_s.as_ref(),
                    Rule::Positive,
                )
                .or(1.0);
            let c = ck
                .number(
                    "stack.friction.viscous_slope_s_m",
                    f.viscous_slope_s_m.as_ref(),
                    Rule::NonNegative,
                )
                .or(0.0);
            (|| {
                Some(FrictionCurve::Stribeck {
                    static_mu: st?,
                    kinetic_mu: kin?,
                    stribeck_speed_m_s: vs?,
                    viscous_slope_s_m: c?,
                })
            })()
        }
        Some(true) => {
            for (k, v) in [
                ("static_mu", &f.static_mu),
                ("kinetic_mu", &f.kinetic_mu),
                ("stribeck_speed_m_s", &f.stribeck_speed_m_s),
                ("viscous_slope_s_m", &f.viscous_slope_s_m),
            ] {
                ck.not_allowed(
                    &format!("stack.friction.{k}"),
                    v.as_ref(),
                    "only allowed with stack.friction.kind = \"stribeck\"",
                );
            }
            let t = table(
                ck,
                ("stack.friction.slip_m_s", f.slip_m_s.as_ref()),
                ("stack.friction.mu", f.mu.as_ref()),
                Rule::Positive,
                "required with stack.friction.kind = \"table\"; set it in [stack.friction]",
            );
            if let Some(t) = &t {
                if t.t_s[0] != 0.0 {
                    ck.report(
                        "stack.friction.slip_m_s[0]",
                        Some(t.t_s[0].to_string()),
                        "must be 0 (the table starts at zero slip)",
                    );
                    return None;
                }
            }
            t.map(FrictionCurve::Table)
        }
    };

    // pressure
    let empty_p = RawPressure::default();
    let pr = r.pressure.as_ref().unwrap_or(&empty_p);
    #[derive(Clone, Copy, PartialEq)]
    enum PKind {
        Constant,
        Ramp,
        Table,
    }
    let pkind = ck
        .choice(
            "stack.pressure.kind",
            pr.kind.as_ref(),
            &[
                ("constant", PKind::Constant),
                ("ramp", PKind::Ramp),
                ("table", PKind::Table),
            ],
        )
        .required(
            ck,
            "stack.pressure.kind",
            "required with [stack]: \"constant\", \"ramp\" or \"table\"; set it in \
             [stack.pressure]",
        );
    let allowed: &[&str] = match pkind {
        Some(PKind::Constant) => &["pressure_pa"],
        Some(PKind::Ramp) => &["pressure_pa", "start_s", "rise_s"],
        Some(PKind::Table) => &["times_s", "values_pa"],
        None => &["pressure_pa", "start_s", "rise_s", "times_s", "values_pa"],
    };
    for (k, v) in [
        ("pressure_pa", &pr.pressure_pa),
        ("start_s", &pr.start_s),
        ("rise_s", &pr.rise_s),
        ("times_s", &pr.times_s),
        ("values_pa", &pr.values_pa),
    ] {
        if !allowed.contains(&k) {
            ck.not_allowed(
                &format!("stack.pressure.{k}"),
                v.as_ref(),
                "not used by this stack.pressure.kind",
            );
        }
    }
    let phint = "required for this stack.pressure.kind; set it in [stack.pressure]";
    let pressure = match pkind {
        None => None,
        Some(PKind::Constant) => ck
            .number(
                "stack.pressure.pressure_pa",
                pr.pressure_pa.as_ref(),
                Rule::NonNegative,
            )
            .required(ck, "stack.pressure.pressure_pa", phint)
            .map(|pressure_pa| PressureProfile::Constant { pressure_pa }),
        Some(PKind::Ramp) => {
            let p = ck
                .number(
                    "stack.pressure.pressure_pa",
                    pr.pressure_pa.as_ref(),
                    Rule::NonNegative,
                )
                .required(ck, "stack.pressure.pressure_pa", phint);
            let start = ck
                .number(
                    "stack.pressure.start_s",
                    pr.start_s.as_ref(),
                    Rule::NonNegative,
                )
                .or(0.0);
            let rise = ck
                .number("stack.pressure.rise_s", pr.rise_s.as_ref(), Rule::Positive)
                .required(ck, "stack.pressure.rise_s", phint);
            (|| {
                Some(PressureProfile::Ramp {
                    start_s: start?,
                    rise_s: rise?,
                    pressure_pa: p?,
                })
            })()
        }
        Some(PKind::Table) => table(
            ck,
            ("stack.pressure.times_s", pr.times_s.as_ref()),
            ("stack.pressure.values_pa", pr.values_pa.as_ref()),
            Rule::NonNegative,
            phint,
        )
        .map(PressureProfile::Table),
    };

    // open gaps
    let open_gap = match &r.open_gap {
        None => Some(None),
        Some(g) => {
            let ghint = "required with [stack.open_gap]; set it there";
            let eta = ck
                .number(
                    "stack.open_gap.viscosity_pa_s",
                    g.viscosity_pa_s.as_ref(),
                    Rule::Positive,
                )
                .required(ck, "stack.open_gap.viscosity_pa_s", ghint);
            let h = ck
                .number("stack.open_gap.gap_m", g.gap_m.as_ref(), Rule::Positive)
                .required(ck, "stack.open_gap.gap_m", ghint);
            match (eta, h) {
                (Some(viscosity_pa_s), Some(gap_m)) => Some(Some(OpenGap {
                    viscosity_pa_s,
                    gap_m,
                })),
                _ => None,
            }
        }
    };
    let (ri, ro) = (inner?, outer?);
    if ro <= ri {
        return None;
    }
    Some(StackModel {
        face_inner_radius_m: ri,
        face_outer_radius_m: ro,
        friction: friction?,
        piston: Piston {
            area_m2: area?,
            pressure: pressure?,
            return_spring_n: spring?,
        },
        open_gap: open_gap?,
        spline_friction: spline?,
    })
}

/// `[simulation]`.
fn simulation(ck: &mut Checker, raw: Option<&RawSimulation>) -> Option<Simulation> {
    let empty = RawSimulation::default();
    let r = raw.unwrap_or(&empty);
    let duration = ck
        .number(
            "simulation.duration_s",
            r.duration_s.as_ref(),
            Rule::Positive,
        )
        .required(
            ck,
            "simulation.duration_s",
            "required; set it in [simulation]",
        );
    let engine = match ck.choice(
        "simulation.engine",
        r.engine.as_ref(),
        &[
            ("reference", EngineChoice::Reference),
            ("multibody", EngineChoice::Multibody),
        ],
    ) {
        Field::Absent => Some(None),
        Field::Invalid => None,
        Field::Valid(e) => Some(Some(e)),
    };
    let rate = ck
        .number(
            "simulation.record_rate_hz",
            r.record_rate_hz.as_ref(),
            Rule::Positive,
        )
        .or(10_000.0);
    let tolerance = ck
        .number(
            "simulation.tolerance",
            r.tolerance.as_ref(),
            Rule::Closed(1e-14, 1e-3, "must be in [1e-14, 1e-3]"),
        )
        .or(1e-9);
    let max_step = ck
        .number(
            "simulation.max_step_s",
            r.max_step_s.as_ref(),
            Rule::Positive,
        )
        .or(1e-4);
    let per_tooth = ck
        .boolean("simulation.record_per_tooth", r.record_per_tooth.as_ref())
        .or(false);
    Some(Simulation {
        duration_s: duration?,
        engine: engine?,
        record_rate_hz: rate?,
        tolerance: tolerance?,
        max_step_s: max_step?,
        record_per_tooth: per_tooth?,
    })
}

/// `drive.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum DriveKind {
    Sine,
    Harmonics,
    SpeedTable,
    TorqueTable,
}

impl DriveKind {
    const ALL: [(&'static str, DriveKind); 4] = [
        ("sine", DriveKind::Sine),
        ("harmonics", DriveKind::Harmonics),
        ("speed_table", DriveKind::SpeedTable),
        ("torque_table", DriveKind::TorqueTable),
    ];

    fn name(self) -> &'static str {
        DriveKind::ALL
            .iter()
            .find(|(_, k)| *k == self)
            .map(|(n, _)| *n)
            .unwrap_or("?")
    }

    /// The `[drive]` keys this kind takes besides `kind`.
    fn keys(self) -> &'static [&'static str] {
        match self {
            DriveKind::Sine => &[
                "omega0_rad_s",
                "amplitude_rad_s",
                "frequency_hz",
                "phase_deg",
            ],
            DriveKind::Harmonics => &["omega0_rad_s", "harmonics"],
            DriveKind::SpeedTable | DriveKind::TorqueTable => &["file"],
        }
    }
}

/// What the `[drive]` table describes.
enum Drive {
    /// A speed history (sine, harmonics, speed table).
    Profile(SpeedProfile),
    /// A torque history in N m (torque table).
    Torque(Table),
}

/// `[drive]`: its kind (for the shaft's rules) and the drive itself.
fn drive(
    ck: &mut Checker,
    raw: Option<&RawDrive>,
    base_dir: &Path,
) -> (Field<DriveKind>, Option<Drive>) {
    let empty = RawDrive::default();
    let r = raw.unwrap_or(&empty);
    let kind_field = ck.choice("drive.kind", r.kind.as_ref(), &DriveKind::ALL);
    let kind = match kind_field.clone() {
        Field::Absent => {
            ck.report(
                "drive.kind",
                None,
                "missing (required: \"sine\", \"harmonics\", \"speed_table\" or \"torque_table\"; \
                 set it in [drive])",
            );
            return (Field::Absent, None);
        }
        Field::Invalid => return (Field::Invalid, None),
        Field::Valid(k) => k,
    };

    // Keys of other kinds are errors: they would be silently ignored otherwise.
    let given: [(&str, Option<&Value>, bool); 6] = [
        (
            "omega0_rad_s",
            r.omega0_rad_s.as_ref(),
            r.omega0_rad_s.is_some(),
        ),
        (
            "amplitude_rad_s",
            r.amplitude_rad_s.as_ref(),
            r.amplitude_rad_s.is_some(),
        ),
        (
            "frequency_hz",
            r.frequency_hz.as_ref(),
            r.frequency_hz.is_some(),
        ),
        ("phase_deg", r.phase_deg.as_ref(), r.phase_deg.is_some()),
        ("harmonics", None, r.harmonics.is_some()),
        ("file", r.file.as_ref(), r.file.is_some()),
    ];
    for (key, value, present) in given {
        if present && !kind.keys().contains(&key) {
            ck.report(
                format!("drive.{key}"),
                value.map(show),
                format!(
                    "not used by drive.kind = \"{}\" (it takes: {})",
                    kind.name(),
                    kind.keys().join(", ")
                ),
            );
        }
    }

    let required = |what: &str| {
        format!(
            "required with drive.kind = \"{}\"; set it in [drive]{what}",
            kind.name()
        )
    };
    let drive = match kind {
        DriveKind::Sine => {
            let omega0 = ck
                .number("drive.omega0_rad_s", r.omega0_rad_s.as_ref(), Rule::Finite)
                .required(ck, "drive.omega0_rad_s", &required(""));
            let amplitude = ck
                .number(
                    "drive.amplitude_rad_s",
                    r.amplitude_rad_s.as_ref(),
                    Rule::Finite,
                )
                .required(ck, "drive.amplitude_rad_s", &required(""));
            let frequency = ck
                .number(
                    "drive.frequency_hz",
                    r.frequency_hz.as_ref(),
                    Rule::Positive,
                )
                .required(ck, "drive.frequency_hz", &required(""));
            let phase = ck
                .number("drive.phase_deg", r.phase_deg.as_ref(), Rule::Finite)
                .or(0.0);
            (|| {
                Some(Drive::Profile(SpeedProfile::Harmonics {
                    omega0_rad_s: omega0?,
                    harmonics: vec![Harmonic {
                        amplitude_rad_s: amplitude?,
                        frequency_hz: frequency?,
                        phase_rad: phase?.to_radians(),
                    }],
                }))
            })()
        }
        DriveKind::Harmonics => {
            let omega0 = ck
                .number("drive.omega0_rad_s", r.omega0_rad_s.as_ref(), Rule::Finite)
                .required(ck, "drive.omega0_rad_s", &required(""));
            let raw_harmonics = r.harmonics.as_deref().unwrap_or_default();
            if raw_harmonics.is_empty() {
                ck.report(
                    "drive.harmonics",
                    None,
                    "missing (drive.kind = \"harmonics\" needs at least one [[drive.harmonics]] \
                     entry with amplitude_rad_s and frequency_hz)",
                );
            }
            let mut harmonics = Some(Vec::new());
            for (i, h) in raw_harmonics.iter().enumerate() {
                let key = |k: &str| format!("drive.harmonics[{i}].{k}");
                let hint = "required; set it in [[drive.harmonics]]";
                let amplitude = ck
                    .number(
                        &key("amplitude_rad_s"),
                        h.amplitude_rad_s.as_ref(),
                        Rule::Finite,
                    )
                    .required(ck, &key("amplitude_rad_s"), hint);
                let frequency = ck
                    .number(
                        &key("frequency_hz"),
                        h.frequency_hz.as_ref(),
                        Rule::Positive,
                    )
                    .required(ck, &key("frequency_hz"), hint);
                let phase = ck
                    .number(&key("phase_deg"), h.phase_deg.as_ref(), Rule::Finite)
                    .or(0.0);
                match (amplitude, frequency, phase, harmonics.as_mut()) {
                    (Some(a), Some(f), Some(p), Some(v)) => v.push(Harmonic {
                        amplitude_rad_s: a,
                        frequency_hz: f,
                        phase_rad: p.to_radians(),
                    }),
                    _ => harmonics = None,
                }
            }
            match (omega0, harmonics) {
                (Some(omega0_rad_s), Some(harmonics)) if !harmonics.is_empty() => {
                    Some(Drive::Profile(SpeedProfile::Harmonics {
                        omega0_rad_s,
                        harmonics,
                    }))
                }
                _ => None,
            }
        }
        DriveKind::SpeedTable | DriveKind::TorqueTable => {
            let column = if kind == DriveKind::SpeedTable {
                "speed_rad_s"
            } else {
                "torque_n_m"
            };
            let file = ck.text("drive.file", r.file.as_ref()).required(
                ck,
                "drive.file",
                &required(&format!(
                    " (a CSV file with columns time_s and {column}, relative to the scene \
                     file's folder)"
                )),
            );
            file.and_then(
                |file| match csv::read_table(&base_dir.join(&file), &file, column) {
                    Ok(table) if kind == DriveKind::SpeedTable => {
                        Some(Drive::Profile(SpeedProfile::Table(table)))
                    }
                    Ok(table) => Some(Drive::Torque(table)),
                    Err(message) => {
                        ck.report("drive.file", r.file.as_ref().map(show), message);
                        None
                    }
                },
            )
        }
    };
    (Field::Valid(kind), drive)
}

/// `shaft.mode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ShaftMode {
    Prescribed,
    Inertial,
}

/// `[shaft]`, combined with the drive.
fn shaft(
    ck: &mut Checker,
    raw: Option<&RawShaft>,
    kind: Field<DriveKind>,
    drive: Option<Drive>,
) -> Option<Shaft> {
    let empty = RawShaft::default();
    let r = raw.unwrap_or(&empty);
    let mode = ck
        .choice(
            "shaft.mode",
            r.mode.as_ref(),
            &[
                ("prescribed", ShaftMode::Prescribed),
                ("inertial", ShaftMode::Inertial),
            ],
        )
        .or(ShaftMode::Prescribed);

    let inertial_only = "only allowed with shaft.mode = \"inertial\" (a prescribed shaft follows \
                         its speed whatever the load)";
    let (inertia, damping) = if mode == Some(ShaftMode::Prescribed) {
        ck.not_allowed(
            "shaft.inertia_kg_m2",
            r.inertia_kg_m2.as_ref(),
            inertial_only,
        );
        ck.not_allowed(
            "shaft.damping_n_m_s_rad",
            r.damping_n_m_s_rad.as_ref(),
            inertial_only,
        );
        (None, None)
    } else {
        let inertia = ck
            .number(
                "shaft.inertia_kg_m2",
                r.inertia_kg_m2.as_ref(),
                Rule::Positive,
            )
            .required(
                ck,
                "shaft.inertia_kg_m2",
                "required with shaft.mode = \"inertial\"; set it in [shaft]",
            );
        let damping = ck
            .number(
                "shaft.damping_n_m_s_rad",
                r.damping_n_m_s_rad.as_ref(),
                Rule::NonNegative,
            )
            .or(0.0);
        (inertia, damping)
    };

    let torque_drive = kind == Field::Valid(DriveKind::TorqueTable);
    let initial_speed = if torque_drive {
        ck.number(
            "shaft.initial_speed_rad_s",
            r.initial_speed_rad_s.as_ref(),
            Rule::Finite,
        )
        .required(
            ck,
            "shaft.initial_speed_rad_s",
            "required with drive.kind = \"torque_table\" (a torque does not set the \
                 starting speed); set it in [shaft]",
        )
    } else {
        if let Field::Valid(k) = kind {
            ck.not_allowed(
                "shaft.initial_speed_rad_s",
                r.initial_speed_rad_s.as_ref(),
                &format!(
                    "only allowed with drive.kind = \"torque_table\" (drive.kind = \"{}\" sets \
                     the starting speed)",
                    k.name()
                ),
            );
        }
        None
    };
    if torque_drive && mode == Some(ShaftMode::Prescribed) {
        ck.report(
            "drive.kind",
            Some("\"torque_table\"".into()),
            "needs shaft.mode = \"inertial\" (a prescribed shaft follows a speed, not a torque)",
        );
        return None;
    }

    match (mode?, drive?) {
        (ShaftMode::Prescribed, Drive::Profile(p)) => Some(Shaft::Prescribed(p)),
        (ShaftMode::Prescribed, Drive::Torque(_)) => None,
        (ShaftMode::Inertial, drive) => Some(Shaft::Inertial {
            inertia_kg_m2: inertia?,
            damping_n_m_s_rad: damping?,
            excitation: match drive {
                Drive::Profile(p) => ShaftExcitation::Profile(p),
                Drive::Torque(table) => ShaftExcitation::Torque {
                    table,
                    initial_speed_rad_s: initial_speed?,
                },
            },
        }),
    }
}

/// Disc parameters checked where they are written (in `[defaults]` or one `[[discs]]`).
struct Params {
    inertia: Field<f64>,
    drag: Field<f64>,
    angle: Field<f64>,
    speed: Field<f64>,
    radial_float: Field<bool>,
    spacing_errors: Field<Vec<f64>>,
    offset: Field<Vec<f64>>,
    teeth: Field<u32>,
    pitch_radius: Field<f64>,
    pressure_angle_deg: Field<f64>,
    backlash: Field<f64>,
    law: Field<LawKind>,
    modulus: Field<f64>,
    curvature: Field<f64>,
    loss: Field<f64>,
    film: Field<f64>,
    viscosity: Field<f64>,
    leakage: Field<f64>,
    width: Field<f64>,
    length: Field<f64>,
    v_floor: Field<f64>,
    h_min: Field<f64>,
}

/// Checks the parameters of one table (`prefix` is `defaults` or `discs[i]`).
fn params(ck: &mut Checker, prefix: &str, r: &RawDisc) -> Params {
    let key = |k: &str| format!("{prefix}.{k}");
    let sp = r.spline.as_ref();
    let co = r.contact.as_ref();
    let oil = r.oil.as_ref();
    Params {
        inertia: ck.number(
            &key("inertia_kg_m2"),
            r.inertia_kg_m2.as_ref(),
            Rule::Positive,
        ),
        drag: ck.number(
            &key("drag_n_m_s_rad"),
            r.drag_n_m_s_rad.as_ref(),
            Rule::NonNegative,
        ),
        angle: ck.number(
            &key("initial_rel_angle_rad"),
            r.initial_rel_angle_rad.as_ref(),
            Rule::Finite,
        ),
        speed: ck.number(
            &key("initial_rel_speed_rad_s"),
            r.initial_rel_speed_rad_s.as_ref(),
            Rule::Finite,
        ),
        radial_float: ck.boolean(&key("radial_float"), r.radial_float.as_ref()),
        spacing_errors: ck.numbers(
            &key("tooth_spacing_errors_m"),
            r.tooth_spacing_errors_m.as_ref(),
            None,
        ),
        offset: ck.numbers(
            &key("initial_offset_m"),
            r.initial_offset_m.as_ref(),
            Some(2),
        ),
        teeth: ck.count(&key("spline.teeth"), sp.and_then(|s| s.teeth.as_ref())),
        pitch_radius: ck.number(
            &key("spline.pitch_radius_m"),
            sp.and_then(|s| s.pitch_radius_m.as_ref()),
            Rule::Positive,
        ),
        pressure_angle_deg: ck.number(
            &key("spline.pressure_angle_deg"),
            sp.and_then(|s| s.pressure_angle_deg.as_ref()),
            Rule::Open(0.0, 90.0, "must be in (0, 90) (exclusive)"),
        ),
        backlash: ck.number(
            &key("spline.backlash_m"),
            sp.and_then(|s| s.backlash_m.as_ref()),
            Rule::Positive,
        ),
        law: ck.choice(
            &key("contact.law"),
            co.and_then(|c| c.law.as_ref()),
            &[
                ("paper", LawKind::Paper),
                ("dry", LawKind::Dry),
                ("squeeze", LawKind::Squeeze),
            ],
        ),
        modulus: ck.number(
            &key("contact.modulus_pa"),
            co.and_then(|c| c.modulus_pa.as_ref()),
            Rule::Positive,
        ),
        curvature: ck.number(
            &key("contact.curvature_radius_m"),
            co.and_then(|c| c.curvature_radius_m.as_ref()),
            Rule::Positive,
        ),
        loss: ck.number(
            &key("contact.loss_coefficient_s_m"),
            co.and_then(|c| c.loss_coefficient_s_m.as_ref()),
            Rule::NonNegative,
        ),
        film: ck.number(
            &key("oil.film_thickness_m"),
            oil.and_then(|o| o.film_thickness_m.as_ref()),
            Rule::NonNegative,
        ),
        viscosity: ck.number(
            &key("oil.viscosity_pa_s"),
            oil.and_then(|o| o.viscosity_pa_s.as_ref()),
            Rule::Positive,
        ),
        leakage: ck.number(
            &key("oil.leakage_coefficient"),
            oil.and_then(|o| o.leakage_coefficient.as_ref()),
            Rule::Positive,
        ),
        width: ck.number(
            &key("oil.width_m"),
            oil.and_then(|o| o.width_m.as_ref()),
            Rule::Positive,
        ),
        length: ck.number(
            &key("oil.length_m"),
            oil.and_then(|o| o.length_m.as_ref()),
            Rule::Positive,
        ),
        v_floor: ck.number(
            &key("oil.v_floor_m_s"),
            oil.and_then(|o| o.v_floor_m_s.as_ref()),
            Rule::Positive,
        ),
        h_min: ck.number(
            &key("oil.h_min_m"),
            oil.and_then(|o| o.h_min_m.as_ref()),
            Rule::Positive,
        ),
    }
}

/// Where a disc's effective value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    Disc,
    Defaults,
    Builtin,
}

/// The disc's field if present, else the defaults' field (with its source).
fn pick<T: Clone>(disc: &Field<T>, defaults: &Field<T>) -> Field<(T, Source)> {
    match (disc, defaults) {
        (Field::Valid(v), _) => Field::Valid((v.clone(), Source::Disc)),
        (Field::Invalid, _) => Field::Invalid,
        (Field::Absent, Field::Valid(v)) => Field::Valid((v.clone(), Source::Defaults)),
        (Field::Absent, Field::Invalid) => Field::Invalid,
        (Field::Absent, Field::Absent) => Field::Absent,
    }
}

/// The two tables of a kind of body: the array of entries and its shared defaults
/// (`[[discs]]` and `[defaults]`, or `[[plates]]` and `[plate_defaults]`).
#[derive(Debug, Clone, Copy)]
struct Sec {
    /// The array of tables, `discs` or `plates`.
    items: &'static str,
    /// The defaults table, `defaults` or `plate_defaults`.
    defaults: &'static str,
    /// Default name prefix of an entry (`disc` -> `disc-1`).
    name_prefix: &'static str,
}

const DISCS: Sec = Sec {
    items: "discs",
    defaults: "defaults",
    name_prefix: "disc",
};

const PLATES: Sec = Sec {
    items: "plates",
    defaults: "plate_defaults",
    name_prefix: "plate",
};

/// Where to set a disc key `k` (`spline.teeth` -> `[discs.spline] or [defaults.spline]`).
fn where_to_set(sec: Sec, k: &str) -> String {
    let (items, defaults) = (sec.items, sec.defaults);
    match k.split_once('.') {
        Some((section, _)) => format!("[{items}.{section}] or [{defaults}.{section}]"),
        None => format!("[[{items}]] or [{defaults}]"),
    }
}

/// A required disc parameter: the disc's, else the defaults'; missing is reported at
/// `item.k` (`discs[1].spline.teeth`).
fn required<T: Clone>(
    ck: &mut Checker,
    sec: Sec,
    item: &str,
    k: &str,
    disc: &Field<T>,
    defaults: &Field<T>,
) -> Option<T> {
    pick(disc, defaults)
        .required(
            ck,
            &format!("{item}.{k}"),
            &format!("required; set it in {}", where_to_set(sec, k)),
        )
        .map(|(v, _)| v)
}

/// An optional disc parameter with a built-in default.
fn optional<T: Clone>(disc: &Field<T>, defaults: &Field<T>, builtin: T) -> Option<(T, Source)> {
    pick(disc, defaults).or((builtin, Source::Builtin))
}

/// ` (inherited from defaults.k)` when the value came from `[defaults]`.
fn inherited(sec: Sec, source: Source, k: &str) -> String {
    if source == Source::Defaults {
        format!(" (inherited from {}.{k})", sec.defaults)
    } else {
        String::new()
    }
}

/// `[defaults]` and every `[[discs]]` (or `[plate_defaults]` and every `[[plates]]`).
/// `names` holds the names taken so far, with the key of their entry (names are unique
/// across discs and plates); `at_least_one` makes an empty array a problem.
fn bodies(
    ck: &mut Checker,
    sec: Sec,
    defaults: Option<&RawDisc>,
    raw: Option<&[RawDisc]>,
    at_least_one: bool,
    names: &mut Vec<(String, String)>,
) -> Option<Vec<DiscModel>> {
    let empty = RawDisc::default();
    let raw_defaults = defaults.unwrap_or(&empty);
    if raw_defaults.name.is_some() {
        ck.report(
            format!("{}.name", sec.defaults),
            None,
            format!(
                "unknown key ({}; a name belongs to each [[{}]] entry)",
                schema::expected_text(sec.defaults),
                sec.items
            ),
        );
    }
    let d = params(ck, sec.defaults, raw_defaults);
    let raw = raw.unwrap_or_default();
    if raw.is_empty() {
        if at_least_one {
            ck.report(
                sec.items,
                None,
                format!("missing (at least one [[{}]] entry is required)", sec.items),
            );
            return None;
        }
        return Some(Vec::new());
    }

    let mut out = Some(Vec::with_capacity(raw.len()));
    for (i, r) in raw.iter().enumerate() {
        let name_key = format!("{}[{i}].name", sec.items);
        let name = match ck.text(&name_key, r.name.as_ref()) {
            Field::Valid(s) if s.trim().is_empty() => {
                ck.report(&name_key, r.name.as_ref().map(show), "must not be empty");
                None
            }
            f => f.or(format!("{}-{}", sec.name_prefix, i + 1)),
        };
        if let Some(n) = &name {
            if let Some((_, other)) = names.iter().find(|(m, _)| m == n) {
                ck.report(
                    &name_key,
                    Some(format!("{n:?}")),
                    format!("names must be unique ({other} has the same name)"),
                );
            }
            names.push((n.clone(), format!("{}[{i}]", sec.items)));
        }
        let own = params(ck, &format!("{}[{i}]", sec.items), r);
        let disc = disc(ck, sec, i, name, &own, &d);
        match (disc, out.as_mut()) {
            (Some(disc), Some(v)) => v.push(disc),
            _ => out = None,
        }
    }
    out
}

/// Resolves and cross-checks one disc.
fn disc(
    ck: &mut Checker,
    sec: Sec,
    i: usize,
    name: Option<String>,
    p: &Params,
    d: &Params,
) -> Option<DiscModel> {
    let item = format!("{}[{i}]", sec.items);
    let inertia = required(ck, sec, &item, "inertia_kg_m2", &p.inertia, &d.inertia);
    let drag = optional(&p.drag, &d.drag, 0.0);
    let angle = optional(&p.angle, &d.angle, 0.0);
    let speed = optional(&p.speed, &d.speed, 0.0);
    let radial_float = optional(&p.radial_float, &d.radial_float, false);
    let spacing_errors = optional(&p.spacing_errors, &d.spacing_errors, Vec::new());
    let offset = optional(&p.offset, &d.offset, vec![0.0, 0.0]);
    let teeth = required(ck, sec, &item, "spline.teeth", &p.teeth, &d.teeth);
    let pitch = required(
        ck,
        sec,
        &item,
        "spline.pitch_radius_m",
        &p.pitch_radius,
        &d.pitch_radius,
    );
    let alpha_deg = required(
        ck,
        sec,
        &item,
        "spline.pressure_angle_deg",
        &p.pressure_angle_deg,
        &d.pressure_angle_deg,
    );
    let backlash = required(
        ck,
        sec,
        &item,
        "spline.backlash_m",
        &p.backlash,
        &d.backlash,
    );
    let law = optional(&p.law, &d.law, LawKind::Paper).map(|(l, _)| l);
    let modulus = required(ck, sec, &item, "contact.modulus_pa", &p.modulus, &d.modulus);
    let curvature = required(
        ck,
        sec,
        &item,
        "contact.curvature_radius_m",
        &p.curvature,
        &d.curvature,
    );
    let loss = optional(&p.loss, &d.loss, 0.0);
    let film = optional(&p.film, &d.film, 0.0);

    // The film parameters are needed when a film carries load: thickness > 0, law not dry.
    let needs_oil = matches!((law, film), (Some(l), Some((h, _))) if l != LawKind::Dry && h > 0.0);
    let mut oil_param = |k: &str, disc: &Field<f64>, defaults: &Field<f64>| {
        if needs_oil {
            pick(disc, defaults)
                .required(
                    ck,
                    &format!("{item}.{k}"),
                    &format!(
                        "required when oil.film_thickness_m > 0 and contact.law is not \"dry\"; \
                         set it in {}",
                        where_to_set(sec, k)
                    ),
                )
                .map(|(v, _)| v)
        } else {
            optional(disc, defaults, 0.0).map(|(v, _)| v)
        }
    };
    let viscosity = oil_param("oil.viscosity_pa_s", &p.viscosity, &d.viscosity);
    let leakage = oil_param("oil.leakage_coefficient", &p.leakage, &d.leakage);
    let width = oil_param("oil.width_m", &p.width, &d.width);
    let length = oil_param("oil.length_m", &p.length, &d.length);
    let v_floor = optional(&p.v_floor, &d.v_floor, 0.01);
    let h_min = optional(&p.h_min, &d.h_min, 1e-6);

    let spline = (|| {
        Some(SplineGeometry {
            teeth: teeth?,
            pitch_radius_m: pitch?,
            pressure_angle_rad: alpha_deg?.to_radians(),
            backlash_m: backlash?,
        })
    })();

    // One spacing error per tooth, or none.
    let mut spacing_ok = true;
    if let (Some(n), Some((errors, source))) = (teeth, spacing_errors.as_ref()) {
        if !errors.is_empty() && errors.len() != n as usize {
            ck.report(
                format!("{item}.tooth_spacing_errors_m"),
                Some(format!("[...{} numbers]", errors.len())),
                format!(
                    "must have one number per tooth (spline.teeth = {n}) or be empty{}",
                    inherited(sec, *source, "tooth_spacing_errors_m")
                ),
            );
            spacing_ok = false;
        }
    }

    // The film and the start position against the free play, along the line of action.
    let mut inside = spacing_ok;
    if let (Some(spline), Some(kind), Some((h_o, film_source)), Some((phi0, angle_source))) =
        (spline, law, film, angle)
    {
        let half_play_m = spline.half_play_line_m();
        let offset_m = if kind == LawKind::Dry { 0.0 } else { h_o };
        if kind != LawKind::Dry && h_o >= half_play_m {
            ck.report(
                format!("{item}.oil.film_thickness_m"),
                Some(h_o.to_string()),
                format!(
                    "must be < g0 Rb = {half_play_m:.6e} m, half the free play along the line \
                     of action (else both flanks engage at once){}",
                    inherited(sec, film_source, "oil.film_thickness_m")
                ),
            );
            inside = false;
        } else if phi0.abs() * spline.base_radius_m() >= half_play_m - offset_m {
            let reach_m = half_play_m - offset_m;
            ck.report(
                format!("{item}.initial_rel_angle_rad"),
                Some(phi0.to_string()),
                format!(
                    "the disc must start inside the free play: |phi0| Rb must be < g0 Rb - h_o \
                     = {reach_m:.6e} m, i.e. |phi0| < {:.6e} rad{}",
                    reach_m / spline.base_radius_m(),
                    inherited(sec, angle_source, "initial_rel_angle_rad")
                ),
            );
            inside = false;
        } else if let (Some((errors, errors_source)), Some((e, offset_source))) =
            (spacing_errors.as_ref(), offset.as_ref())
        {
            // Every tooth must start inside the free play too: a spacing error e_k moves its
            // gap by e_k cos(alpha) along the line of action, the offset by up to |e|.
            let worst_error = errors.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let along = worst_error * spline.pressure_angle_rad.cos();
            let offset_len = e[0].hypot(e[1]);
            let reach_m = half_play_m - offset_m;
            if inside && phi0.abs() * spline.base_radius_m() + along + offset_len >= reach_m {
                let (key, value, source, k) = if offset_len > 0.0 {
                    (
                        "initial_offset_m",
                        format!("[{}, {}]", e[0], e[1]),
                        *offset_source,
                        "initial_offset_m",
                    )
                } else {
                    (
                        "tooth_spacing_errors_m",
                        format!("[...max |e| = {worst_error}]"),
                        *errors_source,
                        "tooth_spacing_errors_m",
                    )
                };
                ck.report(
                    format!("{item}.{key}"),
                    Some(value),
                    format!(
                        "every tooth must start inside the free play: |phi0| Rb + max|e_k| \
                         cos(alpha) + |offset| = {:.6e} m must be < g0 Rb - h_o = {reach_m:.6e} m{}",
                        phi0.abs() * spline.base_radius_m() + along + offset_len,
                        inherited(sec, source, k)
                    ),
                );
                inside = false;
            }
        }
    }
    if !inside {
        return None;
    }

    Some(DiscModel {
        name: name?,
        spline: spline?,
        law: ToothLaw {
            kind: law?,
            hertz: Hertz {
                modulus_pa: modulus?,
                curvature_radius_m: curvature?,
                loss_coefficient_s_m: loss?.0,
            },
            oil: OilFilm {
                thickness_m: film?.0,
                viscosity_pa_s: viscosity?,
                leakage_coefficient: leakage?,
                width_m: width?,
                length_m: length?,
                v_floor_m_s: v_floor?.0,
                h_min_m: h_min?.0,
            },
        },
        inertia_kg_m2: inertia?,
        drag_n_m_s_rad: drag?.0,
        initial_rel_angle_rad: angle?.0,
        initial_rel_speed_rad_s: speed?.0,
        radial_float: radial_float?.0,
        tooth_spacing_errors_m: spacing_errors?.0,
        initial_offset_m: {
            let (e, _) = offset?;
            [e[0], e[1]]
        },
    })
}
