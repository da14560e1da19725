//! Stage two: the raw file ([`crate::keys::RawScene`]) -> validated model values.
//!
//! Every value is checked where it is written against its key's definition ([`Key`]: its
//! kind, that it is finite, its range), then the rules between keys (which keys a drive kind
//! or shaft mode takes, the oil parameters a film needs, the film and the start position
//! against the free play, the backlash against the tooth pitch, the number of samples). Each
//! broken rule becomes one [`Problem`] with the key path, the value as written and the rule;
//! checking goes on after a problem, so that one run lists them all. A value that is itself
//! invalid is not used by the rules between keys (its problem is already reported).
//!
//! One module per section of the file: [`simulation`], [`drive`] (with the shaft),
//! [`bodies`] (discs and plates), [`stack`] (with the drum), [`thermal`] and [`couplings`].

mod bodies;
mod couplings;
mod drive;
mod network;
mod simulation;
mod stack;
mod thermal;
mod transmission;

use crate::error::Problem;
use crate::keys::RawScene;
use crate::schema::{show, Key, Kind, Rule};
use crate::Simulation;
use clutchpack_model::PackModel;
use std::path::Path;
use toml::Value;

/// The validated content of a scene file.
pub(crate) struct Validated {
    pub name: String,
    pub description: String,
    pub simulation: Simulation,
    pub pack: PackModel,
    pub fatigue: Vec<clutchpack_model::FatigueParams>,
    pub thermal: Option<clutchpack_model::thermal::ThermalModel>,
    pub network: Option<clutchpack_model::network::Network>,
    pub transmission: Option<clutchpack_model::network::Transmission>,
}

/// The outcome of checking one value where it is written.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Field<T> {
    /// The key is not in the file.
    Absent,
    /// The key is there but its value breaks a rule (already reported).
    Invalid,
    /// The key is there and its value is good.
    Valid(T),
}

impl<T> Field<T> {
    /// The value, or `default` if absent; `None` if invalid.
    pub fn or(self, default: T) -> Option<T> {
        match self {
            Field::Absent => Some(default),
            Field::Invalid => None,
            Field::Valid(v) => Some(v),
        }
    }

    /// [`Field::required`] with the key's path and the hint built only when reported (a
    /// pack's bodies ask for hundreds of required keys, nearly always present).
    pub fn required_with(
        self,
        ck: &mut Checker,
        key: impl FnOnce() -> String,
        hint: impl FnOnce() -> String,
    ) -> Option<T> {
        match self {
            Field::Absent => self.required(ck, &key(), &hint()),
            Field::Invalid => None,
            Field::Valid(v) => Some(v),
        }
    }

    /// The value; reports `key: missing (hint)` if absent; `None` if absent or invalid.
    pub fn required(self, ck: &mut Checker, key: &str, hint: &str) -> Option<T> {
        match self {
            Field::Absent => {
                ck.report(key, None, format!("missing ({hint})"));
                None
            }
            Field::Invalid => None,
            Field::Valid(v) => Some(v),
        }
    }

    /// `Absent` -> `Some(None)`, `Invalid` -> `None`, `Valid(v)` -> `Some(Some(v))`.
    pub fn optional(self) -> Option<Option<T>> {
        match self {
            Field::Absent => Some(None),
            Field::Invalid => None,
            Field::Valid(v) => Some(Some(v)),
        }
    }
}

/// Collects problems and checks single values against their key's definition.
#[derive(Debug, Default)]
pub(crate) struct Checker {
    /// Every problem found so far.
    pub problems: Vec<Problem>,
    /// Every file the scene's values were read from so far (its tables, its packs' files and
    /// theirs): [`crate::Scene::inputs`].
    pub files: Vec<std::path::PathBuf>,
}

impl Checker {
    /// Records one problem.
    pub fn report(
        &mut self,
        key: impl Into<String>,
        value: Option<String>,
        rule: impl Into<String>,
    ) {
        self.problems.push(Problem::new(key, value, rule));
    }

    /// A finite number (an integer is accepted) that satisfies `rule`; `unit` is named after
    /// plausibility bounds.
    pub fn number(&mut self, path: &str, v: Option<&Value>, rule: Rule, unit: &str) -> Field<f64> {
        let Some(v) = v else { return Field::Absent };
        let x = match v {
            Value::Float(x) => *x,
            Value::Integer(i) => *i as f64,
            _ => {
                self.report(path, Some(show(v)), "must be a number");
                return Field::Invalid;
            }
        };
        if !x.is_finite() {
            self.report(path, Some(show(v)), "must be a finite number");
            return Field::Invalid;
        }
        match rule.check(x, unit) {
            Ok(()) => Field::Valid(x),
            Err(text) => {
                self.report(path, Some(show(v)), text);
                Field::Invalid
            }
        }
    }

    /// A value of key `k` (a number key) at `path`.
    pub fn num(&mut self, path: &str, v: Option<&Value>, k: &Key) -> Field<f64> {
        match k.kind {
            Kind::Number(rule) => self.number(path, v, rule, k.unit),
            _ => unreachable!("{} is not a number key", k.rel()),
        }
    }

    /// An integer count of key `k`, in `[1, max]` (fits a `u32`).
    pub fn count(&mut self, path: &str, v: Option<&Value>, k: &Key) -> Field<u32> {
        let Kind::Count { max } = k.kind else {
            unreachable!("{} is not a count key", k.rel())
        };
        let Some(v) = v else { return Field::Absent };
        match v.as_integer() {
            Some(n) if n >= 1 && n <= i64::from(max) => Field::Valid(n as u32),
            Some(n) if n > i64::from(max) => {
                self.report(
                    path,
                    Some(show(v)),
                    format!("must be an integer <= {max} (plausibility bound)"),
                );
                Field::Invalid
            }
            _ => {
                self.report(path, Some(show(v)), "must be an integer >= 1");
                Field::Invalid
            }
        }
    }

    /// A string.
    pub fn text(&mut self, path: &str, v: Option<&Value>) -> Field<String> {
        let Some(v) = v else { return Field::Absent };
        match v.as_str() {
            Some(s) => Field::Valid(s.to_string()),
            None => {
                self.report(path, Some(show(v)), "must be a string");
                Field::Invalid
            }
        }
    }

    /// One of the names of key `k` (`Kind::Choice`), as the value of the same index in
    /// `values`.
    pub fn choice<T: Copy>(
        &mut self,
        path: &str,
        v: Option<&Value>,
        k: &Key,
        values: &[T],
    ) -> Field<T> {
        let Kind::Choice(names) = k.kind else {
            unreachable!("{} is not a choice key", k.rel())
        };
        debug_assert_eq!(names.len(), values.len(), "{}", k.rel());
        let Some(v) = v else { return Field::Absent };
        match names.iter().position(|n| v.as_str() == Some(n)) {
            Some(i) => Field::Valid(values[i]),
            None => {
                let names: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
                self.report(
                    path,
                    Some(show(v)),
                    format!("must be one of: {}", names.join(", ")),
                );
                Field::Invalid
            }
        }
    }

    /// A boolean (`true` / `false`).
    pub fn boolean(&mut self, path: &str, v: Option<&Value>) -> Field<bool> {
        let Some(v) = v else { return Field::Absent };
        match v.as_bool() {
            Some(b) => Field::Valid(b),
            None => {
                self.report(path, Some(show(v)), "must be true or false");
                Field::Invalid
            }
        }
    }

    /// An array of strings (at least one). A bad item is reported at its index (`key[3]`).
    pub fn texts(&mut self, path: &str, v: Option<&Value>) -> Field<Vec<String>> {
        let Some(v) = v else { return Field::Absent };
        let Some(items) = v.as_array().filter(|a| !a.is_empty()) else {
            self.report(path, Some(show(v)), "must be a non-empty array of strings");
            return Field::Invalid;
        };
        let mut out = Some(Vec::with_capacity(items.len()));
        for (j, item) in items.iter().enumerate() {
            match item.as_str() {
                Some(t) => {
                    if let Some(o) = out.as_mut() {
                        o.push(t.to_string());
                    }
                }
                None => {
                    self.report(format!("{path}[{j}]"), Some(show(item)), "must be a string");
                    out = None;
                }
            }
        }
        out.map_or(Field::Invalid, Field::Valid)
    }

    /// An array of finite numbers (integers accepted), of length `len` if given. A bad item is
    /// reported at its index (`key[3]`), a wrong length at `key`.
    pub fn numbers(
        &mut self,
        path: &str,
        v: Option<&Value>,
        len: Option<usize>,
    ) -> Field<Vec<f64>> {
        let Some(v) = v else { return Field::Absent };
        let Some(items) = v.as_array() else {
            self.report(path, Some(show(v)), "must be an array of numbers");
            return Field::Invalid;
        };
        if let Some(n) = len {
            if items.len() != n {
                self.report(
                    path,
                    Some(show(v)),
                    format!("must have exactly {n} numbers (it has {})", items.len()),
                );
                return Field::Invalid;
            }
        }
        let mut out = Some(Vec::with_capacity(items.len()));
        for (j, item) in items.iter().enumerate() {
            match self.number(&format!("{path}[{j}]"), Some(item), Rule::Finite, "") {
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

    /// An array of rows, each an array of finite numbers ([`Self::numbers`]: a bad item is
    /// reported at `key[i][j]`, a row that is not an array at `key[i]`).
    pub fn number_rows(&mut self, path: &str, v: Option<&Value>) -> Field<Vec<Vec<f64>>> {
        let Some(v) = v else { return Field::Absent };
        let Some(rows) = v.as_array() else {
            self.report(
                path,
                Some(show(v)),
                "must be an array of rows (arrays of numbers)",
            );
            return Field::Invalid;
        };
        let mut out = Some(Vec::with_capacity(rows.len()));
        for (i, row) in rows.iter().enumerate() {
            match self.numbers(&format!("{path}[{i}]"), Some(row), None) {
                Field::Valid(r) => {
                    if let Some(o) = out.as_mut() {
                        o.push(r)
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
    pub fn not_allowed(&mut self, key: &str, v: Option<&Value>, rule: &str) -> bool {
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
    let simulation = simulation::simulation(ck, raw.simulation.as_ref());
    if let Some(bodies) = raw.bodies.as_deref() {
        return network_scene(ck, raw, bodies, base_dir, name, description, simulation);
    }
    let (kind, drive) = drive::drive(ck, raw.drive.as_ref(), base_dir);
    let shaft = drive::shaft(ck, raw.shaft.as_ref(), kind, drive);
    let mut names = Vec::new();
    let discs = bodies::bodies(
        ck,
        bodies::DISCS,
        raw.defaults.as_ref(),
        raw.discs.as_deref(),
        true,
        &mut names,
    );
    let plates = bodies::bodies(
        ck,
        bodies::PLATES,
        raw.plate_defaults.as_ref(),
        raw.plates.as_deref(),
        false,
        &mut names,
    );
    let drum = raw.drum.as_ref().map(|r| stack::drum(ck, r));
    if raw.transmission.is_some() {
        ck.report(
            "transmission",
            None,
            "only in a network scene: an automatic's gears close couplings between [[bodies]]",
        );
    }
    let stack = raw.stack.as_ref().map(|r| stack::stack(ck, r));
    let couplings = couplings::couplings(ck, raw.couplings.as_deref(), raw.drum.is_some());
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
    let thermal = match &raw.thermal {
        None => Some(None),
        // either engine carries the temperatures; the reference engine runs a thermal pack
        // (which has a stack) on its monolithic scheme, as every whole pack (the sdk refuses
        // "multirate" for it), the multibody engine on either of its schemes
        Some(t) => thermal::thermal(ck, t, raw.stack.as_ref(), n_discs, n_plates).map(Some),
    };
    let (discs, disc_fatigue): (Vec<_>, Vec<_>) = discs?.into_iter().unzip();
    let (plates, plate_fatigue): (Vec<_>, Vec<_>) = plates?.into_iter().unzip();
    Some(Validated {
        fatigue: disc_fatigue.into_iter().chain(plate_fatigue).collect(),
        name: name?,
        description: description?,
        simulation: simulation?,
        pack: PackModel {
            shaft: shaft?,
            discs,
            plates,
            drum: drum.map_or(Some(None), |d| d.map(Some))?,
            stack: stack.map_or(Some(None), |s| s.map(Some))?,
            couplings: couplings?,
        },
        thermal: thermal?,
        network: None,
        transmission: None,
    })
}

/// A network scene (`[[bodies]]`, MODEL.md section 8): the pack's sections are refused (a
/// resolved pack on a network is a coupling naming its own pack scene file), the simulation
/// settings that only a pack uses too; the `pack` is an empty placeholder that nothing runs.
fn network_scene(
    ck: &mut Checker,
    raw: &RawScene,
    bodies: &[crate::keys::RawNetBody],
    base_dir: &Path,
    name: Option<String>,
    description: Option<String>,
    simulation: Option<Simulation>,
) -> Option<Validated> {
    let pack_sections = [
        ("shaft", raw.shaft.is_some()),
        ("drive", raw.drive.is_some()),
        ("discs", raw.discs.is_some()),
        ("plates", raw.plates.is_some()),
        ("drum", raw.drum.is_some()),
        ("stack", raw.stack.is_some()),
        ("defaults", raw.defaults.is_some()),
        ("plate_defaults", raw.plate_defaults.is_some()),
        ("thermal", raw.thermal.is_some()),
    ];
    for (section, present) in pack_sections {
        if present {
            ck.report(
                section,
                None,
                "not in a network scene: a network ([[bodies]]) holds a resolved pack in its own pack scene file, [[couplings]] kind = \"pack\" with pack = \"<file>.toml\"",
            );
        }
    }
    // the shift elements whose force a schedule sets (every name a gear closes, when the
    // transmission has an initial gear)
    let scheduled = raw
        .transmission
        .as_ref()
        .map_or_else(Vec::new, transmission::scheduled_elements);
    let network = network::network(
        ck,
        bodies,
        raw.couplings.as_deref().unwrap_or(&[]),
        base_dir,
        &scheduled,
    );
    let (mut network, fatigue) = match network {
        Some((n, f)) => (Some(n), f),
        None => (None, Vec::new()),
    };
    // the gears of an automatic, on a network that is good (its schedule sets the elements'
    // forces and its initial gear the members' speeds)
    let transmission = match (&raw.transmission, &mut network) {
        (None, _) => Some(None),
        (Some(t), Some(net)) => transmission::transmission(ck, t, net, bodies).map(Some),
        (Some(_), None) => None,
    };
    // a network that is one pack between a prescribed shaft and the housing or a drum is that
    // pack's scene: it runs the pack's own session, to the bit (docs/DECISIONS.md, "A
    // one-pack network is a pack scene")
    if let (Some(net), Some(None)) = (&network, &transmission) {
        if let Some(pack) = net.one_pack() {
            return Some(Validated {
                name: name?,
                description: description?,
                simulation: simulation?,
                pack,
                fatigue,
                thermal: net.pack_thermal.get(&0).cloned(),
                network: None,
                transmission: None,
            });
        }
    }
    Some(Validated {
        name: name?,
        description: description?,
        simulation: simulation?,
        pack: PackModel {
            shaft: clutchpack_model::Shaft::Prescribed(clutchpack_model::SpeedProfile::sine(
                0.0, 0.0, 1.0,
            )),
            discs: Vec::new(),
            plates: Vec::new(),
            drum: None,
            stack: None,
            couplings: Vec::new(),
        },
        fatigue,
        thermal: None,
        network: Some(network?),
        transmission: transmission?,
    })
}
