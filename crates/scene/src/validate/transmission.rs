//! `[transmission]` of a network scene (MODEL.md section 10): the input and output bodies and
//! the gears, each the set of shift elements closed in it; every gear's kinematics checked
//! (one degree of freedom left to the input, the output turning with it), every element
//! closed in some gear. A shift element is a lumped clutch or a resolved pack with a stack:
//! with a schedule a pack's piston pressure is the schedule's level times its rated pressure,
//! the largest of its pack file's own profile (`clutchpack_model::network::gears`).

use super::Checker;
use crate::keys::{RawGear as G, RawNetBody, RawShift as S, RawTransmission as T};
use crate::schema::{Key, RawTable};
use clutchpack_model::network::{CouplingKind, Gear, Network, Shift, Transmission};

/// Whether a gear may close a coupling of kind `kind`: one its schedule can actuate, an element
/// with an actuation input of its own (`ElementLaw::input`: a lumped clutch's or a one-way
/// clutch's normal force, a resolved pack's piston pressure when it has a stack).
fn shift_element(kind: &CouplingKind) -> bool {
    kind.law().input().is_some()
}

/// The names every gear closes, when `[transmission]` has an initial gear or shifts (its
/// schedule then sets those elements' forces): read from the raw table, before the network is
/// validated.
pub(super) fn scheduled_elements(raw: &T) -> Vec<String> {
    // (shifts without an initial gear are reported by the transmission, not as missing forces)
    if raw.initial_gear.is_none() && raw.shifts.is_none() {
        return Vec::new();
    }
    let mut out: Vec<String> = raw
        .gears
        .iter()
        .flatten()
        .filter_map(|g| g.closed.as_ref()?.as_array().cloned())
        .flatten()
        .filter_map(|v| v.as_str().map(str::to_string))
        .collect();
    out.sort();
    out.dedup();
    out
}

/// The transmission of `net` as `[transmission]` describes it, or `None` (each problem
/// reported at its key). With an initial gear its schedule sets every element's force in
/// `net`, and with `initial_input_speed_rad_s` the speeds of the bodies that turn with the
/// input (`bodies`: the raw bodies, whose own speeds are then refused).
pub(super) fn transmission(
    ck: &mut Checker,
    raw: &T,
    net: &mut Network,
    bodies: &[RawNetBody],
) -> Option<Transmission> {
    let body = |ck: &mut Checker, key: &Key| {
        let path = key.at("transmission");
        let name = ck.text(&path, raw.value(key)).required(
            ck,
            &path,
            "required: the name of a body in [[bodies]]",
        )?;
        let found = net.body_index(&name);
        if found.is_none() {
            ck.report(
                path,
                Some(format!("\"{name}\"")),
                "names no body in [[bodies]]",
            );
        }
        found
    };
    let (input, output) = (body(ck, &T::input), body(ck, &T::output));
    let raw_gears = raw.gears.as_deref().unwrap_or_default();
    if raw_gears.is_empty() {
        ck.report(
            "transmission.gears",
            None,
            "needs at least one [[transmission.gears]] entry",
        );
        return None;
    }
    let mut gears = Vec::new();
    let mut ok = true;
    for (i, g) in raw_gears.iter().enumerate() {
        let at = |key: &Key| format!("transmission.gears[{i}].{}", key.name);
        let name = ck.text(&at(&G::name), g.value(&G::name)).required(
            ck,
            &at(&G::name),
            "required: the gear's name",
        );
        if let Some(n) = &name {
            if gears.iter().any(|o: &Gear| &o.name == n) {
                ck.report(at(&G::name), Some(format!("\"{n}\"")), "names two gears");
                ok = false;
            }
        }
        let closed = ck.texts(&at(&G::closed), g.value(&G::closed)).required(
            ck,
            &at(&G::closed),
            "required: the elements closed in this gear",
        );
        let mut indices = Vec::new();
        for (j, e) in closed.iter().flatten().enumerate() {
            let path = format!("{}[{j}]", at(&G::closed));
            match net.couplings.iter().position(|c| &c.name == e) {
                Some(k) if shift_element(&net.couplings[k].kind) => {
                    if indices.contains(&k) {
                        ck.report(
                            path,
                            Some(format!("\"{e}\"")),
                            "is named twice in this gear",
                        );
                        ok = false;
                    }
                    indices.push(k);
                }
                Some(_) => {
                    ck.report(
                        path,
                        Some(format!("\"{e}\"")),
                        "is not a shift element: a gear closes couplings of kind clutch, one_way_clutch or pack (a pack with a [stack] and its piston)",
                    );
                    ok = false;
                }
                None => {
                    ck.report(
                        path,
                        Some(format!("\"{e}\"")),
                        "names no coupling in [[couplings]]",
                    );
                    ok = false;
                }
            }
        }
        match (name, closed) {
            (Some(name), Some(_)) => gears.push(Gear {
                name,
                closed: indices,
            }),
            _ => ok = false,
        }
    }
    let gear_named =
        |ck: &mut Checker, path: &str, v: Option<&toml::Value>| -> Option<Option<usize>> {
            let name = ck.text(path, v).or(String::new())?;
            if v.is_none() {
                return Some(None);
            }
            match gears.iter().position(|g: &Gear| g.name == name) {
                Some(i) => Some(Some(i)),
                None => {
                    let names: Vec<String> =
                        gears.iter().map(|g| format!("\"{}\"", g.name)).collect();
                    ck.report(
                        path,
                        Some(format!("\"{name}\"")),
                        format!("names no gear; the gears are {}", names.join(", ")),
                    );
                    None
                }
            }
        };
    let initial_gear = gear_named(
        ck,
        &T::initial_gear.at("transmission"),
        raw.value(&T::initial_gear),
    );
    let w_in = ck
        .num(
            &T::initial_input_speed_rad_s.at("transmission"),
            raw.value(&T::initial_input_speed_rad_s),
            &T::initial_input_speed_rad_s,
        )
        .or(f64::NAN);
    let mut shifts = Vec::new();
    for (i, r) in raw.shifts.iter().flatten().enumerate() {
        let at = |key: &Key| format!("transmission.shifts[{i}].{}", key.name);
        let num =
            |ck: &mut Checker, key: &Key| ck.num(&at(key), r.value(key), key).or(key.default_num());
        let at_s = ck.num(&at(&S::at_s), r.value(&S::at_s), &S::at_s).required(
            ck,
            &at(&S::at_s),
            "when the shift starts",
        );
        let to = gear_named(ck, &at(&S::to), r.value(&S::to));
        if r.value(&S::to).is_none() {
            ck.report(at(&S::to), None, "required: the gear the shift reaches");
        }
        let (fill_s, fill_level) = (num(ck, &S::fill_s), num(ck, &S::fill_level));
        let (torque_phase_s, torque_level) =
            (num(ck, &S::torque_phase_s), num(ck, &S::torque_level));
        let inertia_phase_s = num(ck, &S::inertia_phase_s);
        match (
            at_s,
            to.flatten(),
            fill_s,
            fill_level,
            torque_phase_s,
            torque_level,
            inertia_phase_s,
        ) {
            (
                Some(at_s),
                Some(to),
                Some(fill_s),
                Some(fill_level),
                Some(torque_phase_s),
                Some(torque_level),
                Some(inertia_phase_s),
            ) => {
                shifts.push(Shift {
                    at_s,
                    to,
                    fill_s,
                    fill_level,
                    torque_phase_s,
                    torque_level,
                    inertia_phase_s,
                });
            }
            _ => ok = false,
        }
    }
    let initial_gear = initial_gear?;
    if initial_gear.is_none() {
        if raw.shifts.is_some() {
            ck.report(
                "transmission.shifts",
                None,
                "needs transmission.initial_gear: the gear the schedule starts from",
            );
            ok = false;
        }
        if w_in.is_some_and(|w| !w.is_nan()) {
            ck.report(
                T::initial_input_speed_rad_s.at("transmission"),
                None,
                "needs transmission.initial_gear: the gear that sets the other speeds",
            );
            ok = false;
        }
    }
    let tr = Transmission {
        input: input?,
        output: output?,
        gears,
        initial_gear,
        shifts,
    };
    if !ok {
        return None;
    }
    if tr.input == tr.output {
        ck.report(
            T::output.at("transmission"),
            None,
            "must be another body than the input",
        );
        return None;
    }
    for (i, g) in tr.gears.iter().enumerate() {
        if let Err(why) = tr.kinematics(net, i) {
            ck.report(
                format!("transmission.gears[{i}].{}", G::closed.name),
                None,
                format!("gear \"{}\" {why}", g.name),
            );
            ok = false;
        }
    }
    if !ok {
        return None;
    }
    match tr.schedule() {
        Some(Ok(forces)) => {
            for (k, force) in forces {
                // each element takes the schedule's level as its law says (a clutch's normal
                // force, a pack's pressure as the level times its rated pressure: the module's
                // docs)
                match net.couplings[k].law().scheduled(&force) {
                    Ok(Some(kind)) => net.couplings[k].kind = kind,
                    Ok(None) => {}
                    Err((field, why)) => {
                        ck.report(
                            format!("couplings[{k}].{field}"),
                            None,
                            format!("\"{}\" {why}", net.couplings[k].name),
                        );
                        ok = false;
                    }
                }
            }
        }
        Some(Err((i, why))) => {
            ck.report(format!("transmission.shifts[{i}].to"), None, why);
            ok = false;
        }
        None => {}
    }
    let w_in = w_in.filter(|w| !w.is_nan());
    if let Some(w_in) = w_in {
        let own: Vec<f64> = net.bodies.iter().map(|b| b.initial_speed_rad_s).collect();
        // the gear was checked: it has speeds
        if let Some(speeds) = tr.initial_speeds_rad_s(net, w_in, &own) {
            for (i, (b, w)) in net.bodies.iter_mut().zip(speeds).enumerate() {
                if w != b.initial_speed_rad_s
                    && bodies
                        .get(i)
                        .is_some_and(|r| r.initial_speed_rad_s.is_some())
                {
                    ck.report(
                        format!("bodies[{i}].initial_speed_rad_s"),
                        None,
                        "set by transmission.initial_input_speed_rad_s (the body turns with the input in the initial gear): remove it",
                    );
                    ok = false;
                }
                b.initial_speed_rad_s = w;
            }
        }
    }
    ok.then_some(tr)
}
