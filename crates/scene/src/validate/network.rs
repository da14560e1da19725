//! `[[bodies]]` and `[[couplings]]`: a driveline network (MODEL.md section 8). Every value is
//! checked at its key (`bodies[2].inertia_kg_m2`, `couplings[0].force.start_s`); then the
//! network's own rules ([`Network::problems`]: names, a coupling naming an unknown body or
//! the same body twice, a loop of ideal gears, speeds that do not mesh, a body nothing moves)
//! are reported at the key of the part they concern.

use super::{Checker, Field};
use crate::keys::{
    RawContact as Ct, RawCoupling as C, RawFiring as F, RawFiring, RawForceSignal as FS,
    RawNetBody as B, RawOil as O, RawRoadLoad as RL, RawTorqueSignal as TS,
};
use crate::keys::{MAX_FIRING_HARMONICS, MAX_FORCE_SIGNAL, MAX_TORQUE_N_M};
use crate::schema::{fmt_num, show, Key, RawTable};
use clutchpack_model::network::{
    name_problem, Body, Coupling, CouplingKind, Firing, GearMesh, LumpedClutch, Motion, Network,
    NetworkProblem, PlanetarySet, RoadLoad, Signal,
};
use clutchpack_model::{Hertz, LawKind, OilFilm, ToothLaw};
use std::path::Path;
use toml::Value;

/// The path of key `k` of item `i` of the array `array`: `bodies[2].drive.start_s`.
fn item(array: &str, k: &Key, i: usize) -> String {
    k.at(&format!("{array}[{i}]"))
}

/// The keys of one signal table (a torque in N m, or a normalized force).
struct SignalKeys {
    kind: Key,
    value: Key,
    offset: Key,
    height: Key,
    amplitude: Key,
    frequency: Key,
    phase: Key,
    start: Key,
    duration: Key,
    file: Key,
    interpolation: Key,
    /// The CSV column of the values.
    column: &'static str,
    /// The plausibility bound of the values (the value keys' own range), for a table's rows.
    range: (f64, f64),
    /// The array whose items hold the table: `bodies` or `couplings`.
    array: &'static str,
}

const TORQUE_SIGNAL: SignalKeys = SignalKeys {
    kind: TS::kind,
    value: TS::value_n_m,
    offset: TS::offset_n_m,
    height: TS::height_n_m,
    amplitude: TS::amplitude_n_m,
    frequency: TS::frequency_hz,
    phase: TS::phase_deg,
    start: TS::start_s,
    duration: TS::duration_s,
    file: TS::file,
    interpolation: TS::interpolation,
    column: "torque_n_m",
    range: (-MAX_TORQUE_N_M, MAX_TORQUE_N_M),
    array: "bodies",
};

const FORCE_SIGNAL: SignalKeys = SignalKeys {
    kind: FS::kind,
    value: FS::value,
    offset: FS::offset,
    height: FS::height,
    amplitude: FS::amplitude,
    frequency: FS::frequency_hz,
    phase: FS::phase_deg,
    start: FS::start_s,
    duration: FS::duration_s,
    file: FS::file,
    interpolation: FS::interpolation,
    column: "force",
    range: (-MAX_FORCE_SIGNAL, MAX_FORCE_SIGNAL),
    array: "couplings",
};

/// One signal table of item `i`; `get` reads a key's value as written.
fn signal<'v>(
    ck: &mut Checker,
    keys: &SignalKeys,
    i: usize,
    get: impl Fn(&Key) -> Option<&'v Value>,
    base_dir: &Path,
) -> Option<Signal> {
    #[derive(Clone, Copy, PartialEq)]
    enum K {
        Constant,
        Step,
        Ramp,
        Sine,
        Table,
    }
    use K::*;
    let p = |k: &Key| item(keys.array, k, i);
    let kind = ck
        .choice(
            &p(&keys.kind),
            get(&keys.kind),
            &keys.kind,
            &[Constant, Step, Ramp, Sine, Table],
        )
        .required(ck, &p(&keys.kind), "required")?;
    let uses: &[&Key] = match kind {
        Constant => &[&keys.value],
        Step => &[&keys.offset, &keys.height, &keys.start],
        Ramp => &[&keys.offset, &keys.height, &keys.start, &keys.duration],
        Sine => &[
            &keys.offset,
            &keys.amplitude,
            &keys.frequency,
            &keys.phase,
            &keys.start,
        ],
        Table => &[&keys.file, &keys.interpolation],
    };
    let kind_name = show(get(&keys.kind).expect("the kind was read"));
    for k in [
        &keys.value,
        &keys.offset,
        &keys.height,
        &keys.amplitude,
        &keys.frequency,
        &keys.phase,
        &keys.start,
        &keys.duration,
        &keys.file,
        &keys.interpolation,
    ] {
        if !uses.iter().any(|u| u.name == k.name) {
            ck.not_allowed(
                &p(k),
                get(k),
                &format!("not used by kind = {kind_name}; remove it"),
            );
        }
    }
    let num = |ck: &mut Checker, k: &Key| ck.num(&p(k), get(k), k);
    let required = |ck: &mut Checker, k: &Key| {
        num(ck, k).required(ck, &p(k), &format!("required for kind = {kind_name}"))
    };
    let signal = match kind {
        Constant => Signal::Constant(required(ck, &keys.value)?),
        Step | Ramp | Sine => {
            let offset = num(ck, &keys.offset).or(0.0);
            let start_s = num(ck, &keys.start).or(0.0);
            match kind {
                Step => {
                    let height = required(ck, &keys.height);
                    Signal::Step {
                        offset: offset?,
                        height: height?,
                        start_s: start_s?,
                    }
                }
                Ramp => {
                    let height = required(ck, &keys.height);
                    let duration_s = required(ck, &keys.duration);
                    Signal::Ramp {
                        offset: offset?,
                        height: height?,
                        start_s: start_s?,
                        duration_s: duration_s?,
                    }
                }
                _ => {
                    let amplitude = required(ck, &keys.amplitude);
                    let frequency_hz = required(ck, &keys.frequency);
                    let phase = num(ck, &keys.phase).or(0.0);
                    Signal::Sine {
                        offset: offset?,
                        amplitude: amplitude?,
                        frequency_hz: frequency_hz?,
                        phase_rad: phase?.to_radians(),
                        start_s: start_s?,
                    }
                }
            }
        }
        Table => {
            let file = ck.text(&p(&keys.file), get(&keys.file)).required(
                ck,
                &p(&keys.file),
                "required for kind = \"table\"",
            )?;
            let hold = ck
                .choice(
                    &p(&keys.interpolation),
                    get(&keys.interpolation),
                    &keys.interpolation,
                    &[false, true],
                )
                .or(false)?;
            ck.files.push(base_dir.join(&file));
            match crate::csv::read_table(&base_dir.join(&file), &file, keys.column, keys.range) {
                Ok(t) => Signal::Table(if hold { t.held() } else { t }),
                Err(e) => {
                    ck.report(p(&keys.file), Some(format!("\"{file}\"")), e);
                    return None;
                }
            }
        }
    };
    Some(signal)
}

/// The network of a scene with `[[bodies]]`.
pub(super) fn network(
    ck: &mut Checker,
    bodies: &[B],
    couplings: &[C],
    base_dir: &Path,
    scheduled: &[String],
) -> Option<(Network, Vec<clutchpack_model::FatigueParams>)> {
    let mut ok = true;
    let mut net = Network::default();
    // every resolved pack's bodies' fatigue parameters, in coupling order
    let mut fatigue = Vec::new();
    // every body's name as written (a coupling is checked against them even when another key
    // of a body is bad, so that one run lists every problem)
    let mut names: Vec<Option<String>> = Vec::new();
    for (i, r) in bodies.iter().enumerate() {
        let p = |k: &Key| item("bodies", k, i);
        let name = ck.text(&p(&B::name), r.value(&B::name)).required(
            ck,
            &p(&B::name),
            "required: couplings name their bodies by it",
        );
        if let Some(why) = name.as_deref().and_then(name_problem) {
            ck.report(p(&B::name), name.as_ref().map(|n| format!("{n:?}")), why);
            ok = false;
        }
        let fixed = ck.boolean(&p(&B::fixed), r.value(&B::fixed)).or(false);
        // a prescribed speed: the forms of [drive] at bodies[i].speed (a torque table is not
        // a speed)
        let speed_at = format!("bodies[{i}].speed");
        let prescribed = match &r.speed {
            None => Some(None),
            Some(raw) => match super::drive::drive_at(ck, Some(raw), base_dir, &speed_at).1 {
                Some(super::drive::Drive::Profile(profile)) => Some(Some(profile)),
                Some(super::drive::Drive::Torque(_)) => {
                    ck.report(
                        format!("{speed_at}.kind"),
                        Some("\"torque_table\"".into()),
                        "a prescribed body follows a speed: \"sine\", \"harmonics\" or \
                         \"speed_table\" (a torque on a body is its [bodies.drive])",
                    );
                    None
                }
                None => None,
            },
        };
        if r.speed.is_some() && fixed == Some(true) {
            ck.report(
                p(&B::fixed),
                Some("true".into()),
                "a body is fixed or follows a prescribed speed (its [bodies.speed]), not both",
            );
        }
        let given = r.speed.is_some() || fixed == Some(true);
        let inertia = ck.num(
            &p(&B::inertia_kg_m2),
            r.value(&B::inertia_kg_m2),
            &B::inertia_kg_m2,
        );
        let inertia = match (given, inertia) {
            (true, f) => {
                if !matches!(f, Field::Absent) {
                    ck.report(
                        p(&B::inertia_kg_m2),
                        r.value(&B::inertia_kg_m2).map(show),
                        "a fixed or prescribed body has no inertia (its motion is given); remove it",
                    );
                }
                Some(0.0)
            }
            (_, f) => f.required(ck, &p(&B::inertia_kg_m2), "required for a body that turns"),
        };
        let or_default =
            |ck: &mut Checker, k: &Key| ck.num(&p(k), r.value(k), k).or(k.default_num());
        let drag = or_default(ck, &B::drag_n_m_s_rad);
        let speed = or_default(ck, &B::initial_speed_rad_s);
        if r.speed.is_some() && r.value(&B::initial_speed_rad_s).is_some() {
            ck.report(
                p(&B::initial_speed_rad_s),
                r.value(&B::initial_speed_rad_s).map(show),
                "a prescribed body starts at its [bodies.speed]'s speed at t = 0; remove it",
            );
        }
        let drive = match &r.drive {
            Some(d) => signal(ck, &TORQUE_SIGNAL, i, |k| d.value(k), base_dir).map(Some),
            None => Some(None),
        };
        let firing = match &r.firing {
            Some(f) => firing(ck, f, i),
            None => Some(None),
        };
        let road_load = match &r.road_load {
            Some(l) => {
                let mut n = |k: &Key| ck.num(&p(k), l.value(k), k).or(k.default_num());
                let (a, b, c) = (
                    n(&RL::constant_n_m),
                    n(&RL::linear_n_m_s_rad),
                    n(&RL::quadratic_n_m_s2_rad2),
                );
                (|| {
                    Some(Some(RoadLoad {
                        constant_n_m: a?,
                        linear_n_m_s_rad: b?,
                        quadratic_n_m_s2_rad2: c?,
                    }))
                })()
            }
            None => Some(None),
        };
        // a road load's speed terms the engines can integrate: its linear part b is a drag
        // (J / b), its quadratic part c one of 2 c |w| at the larger of the body's initial
        // speed and 1e3 rad/s (J / (2 c w), a body at rest speeds up), both under the
        // bodies' rule on a drag's time constant
        let road_load = match (fixed.map(|_| given), inertia, speed, road_load) {
            (Some(false), Some(j), Some(w0), Some(Some(l))) => {
                let linear_ok = l.linear_n_m_s_rad == 0.0
                    || super::bodies::drag_resolvable(
                        ck,
                        (&p(&B::inertia_kg_m2), j),
                        (&p(&RL::linear_n_m_s_rad), l.linear_n_m_s_rad),
                    );
                let c = l.quadratic_n_m_s2_rad2;
                let w = w0.abs().max(1e3);
                let most = j / (super::bodies::MIN_DRAG_TIME_S * 2.0 * w);
                let quadratic_ok = c <= most;
                if !quadratic_ok {
                    ck.report(
                        p(&RL::quadratic_n_m_s2_rad2),
                        Some(fmt_num(c)),
                        format!(
                            "must be at most {} N m s^2/rad^2 with inertia {} kg m^2 \
                             (plausibility bound: at {} rad/s, the larger of the initial \
                             speed and 1000 rad/s, the load's damping 2 c w keeps a time \
                             constant J / (2 c w) of at least {} s)",
                            fmt_num(most),
                            fmt_num(j),
                            fmt_num(w),
                            fmt_num(super::bodies::MIN_DRAG_TIME_S)
                        ),
                    );
                }
                (linear_ok && quadratic_ok).then_some(Some(l))
            }
            (_, _, _, l) => l,
        };
        // a drag the engines can integrate: the bodies' rule on its time constant J / C
        let drag = match (fixed.map(|_| given), inertia, drag) {
            (Some(false), Some(j), Some(c)) if c > 0.0 => super::bodies::drag_resolvable(
                ck,
                (&p(&B::inertia_kg_m2), j),
                (&p(&B::drag_n_m_s_rad), c),
            )
            .then_some(c),
            (_, _, c) => c,
        };
        names.push(name.clone());
        match (
            name, inertia, fixed, drag, speed, drive, firing, road_load, prescribed,
        ) {
            (
                Some(name),
                Some(j),
                Some(fixed),
                Some(c),
                Some(w),
                Some(drive),
                Some(firing),
                Some(road_load),
                Some(prescribed),
            ) => net.bodies.push(Body {
                name,
                inertia_kg_m2: j,
                drag_n_m_s_rad: c,
                initial_speed_rad_s: prescribed.as_ref().map_or(w, |p| p.speed(0.0)),
                motion: match prescribed {
                    Some(p) => Motion::Prescribed(p),
                    None if fixed => Motion::Fixed,
                    None => Motion::Free,
                },
                drive,
                firing,
                road_load,
            }),
            _ => ok = false,
        }
    }
    #[derive(Clone, Copy)]
    enum Kind {
        Clutch,
        Gear,
        Mesh,
        Spring,
        Pack,
        Planetary,
        OneWay,
        Freewheel,
    }
    for (k, r) in couplings.iter().enumerate() {
        let p = |key: &Key| item("couplings", key, k);
        let default_name = format!(
            "{}-{}",
            r.value(&C::kind)
                .and_then(|v| v.as_str())
                .unwrap_or("coupling"),
            k + 1
        );
        let name = ck.text(&p(&C::name), r.value(&C::name)).or(default_name);
        if let Some(why) = name.as_deref().and_then(name_problem) {
            ck.report(p(&C::name), name.as_ref().map(|n| format!("{n:?}")), why);
            ok = false;
        }
        let kind = ck
            .choice(
                &p(&C::kind),
                r.value(&C::kind),
                &C::kind,
                &[
                    Kind::Clutch,
                    Kind::Gear,
                    Kind::Mesh,
                    Kind::Spring,
                    Kind::Pack,
                    Kind::Planetary,
                    Kind::OneWay,
                    Kind::Freewheel,
                ],
            )
            .required(ck, &p(&C::kind), "required");
        let body = |ck: &mut Checker, key: &Key| {
            let n = ck.text(&p(key), r.value(key)).required(
                ck,
                &p(key),
                "required: the name of a body in [[bodies]]",
            )?;
            let found = names.iter().position(|m| m.as_deref() == Some(n.as_str()));
            if found.is_none() {
                let names: Vec<String> =
                    names.iter().flatten().map(|b| format!("\"{b}\"")).collect();
                ck.report(
                    p(key),
                    Some(format!("\"{n}\"")),
                    format!("names no body; the bodies are {}", names.join(", ")),
                );
            }
            found
        };
        let a = body(ck, &C::a);
        let b = body(ck, &C::b);
        let Some(kind) = kind else {
            ok = false;
            continue;
        };
        let spring_keys: [&Key; 3] = [
            &C::stiffness_n_m_per_rad,
            &C::damping_n_m_s_per_rad,
            &C::free_angle_rad,
        ];
        let clutch_keys: [&Key; 6] = [
            &C::mu,
            &C::mu_speeds_rad_s,
            &C::mu_values,
            &C::peak,
            &C::cgeo_m,
            &C::max_normal_force_n,
        ];
        let mesh_keys: [&Key; 6] = [
            &C::base_radius_a_m,
            &C::base_radius_b_m,
            &C::internal,
            &C::backlash_m,
            &C::pairs,
            &C::mesh_offset_m,
        ];
        let kind_name = show(r.value(&C::kind).expect("the kind was read"));
        let refuse = |ck: &mut Checker, keys: &[&Key], tables: &[(&str, bool)], whose: &str| {
            for key in keys {
                ck.not_allowed(
                    &p(key),
                    r.value(key),
                    &format!("{whose}'s key; remove it for kind = {kind_name}"),
                );
            }
            for (table, present) in tables {
                if *present {
                    ck.report(
                        format!("couplings[{k}].{table}"),
                        None,
                        format!("{whose}'s table; remove it for kind = {kind_name}"),
                    );
                }
            }
        };
        let (force, contact, oil) = (
            ("force", r.force.is_some()),
            ("contact", r.contact.is_some()),
            ("oil", r.oil.is_some()),
        );
        if !matches!(kind, Kind::Spring) {
            refuse(ck, &spring_keys, &[], "a spring_damper");
        }
        if !matches!(kind, Kind::Pack) {
            refuse(ck, &[&C::pack], &[], "a pack");
        }
        let planetary_keys: [&Key; 4] = [
            &C::carrier,
            &C::sun_teeth,
            &C::ring_teeth,
            &C::double_pinion,
        ];
        if !matches!(kind, Kind::Planetary) {
            refuse(ck, &planetary_keys, &[], "a planetary set");
        }
        match kind {
            Kind::Freewheel => {
                refuse(ck, &[&C::ratio], &[], "an ideal gear");
                refuse(
                    ck,
                    &clutch_keys,
                    &[force],
                    "a clutch (a one_way_clutch has them)",
                );
                refuse(ck, &mesh_keys, &[contact, oil], "a gear mesh");
            }
            Kind::Planetary => {
                refuse(ck, &[&C::ratio], &[], "an ideal gear");
                refuse(ck, &clutch_keys, &[force], "a clutch");
                refuse(ck, &mesh_keys, &[contact, oil], "a gear mesh");
            }
            Kind::Pack => {
                refuse(ck, &[&C::ratio], &[], "an ideal gear");
                refuse(ck, &clutch_keys, &[force], "a clutch");
                refuse(ck, &mesh_keys, &[contact, oil], "a gear mesh");
            }
            Kind::Spring => {
                refuse(ck, &[&C::ratio], &[], "an ideal gear");
                refuse(ck, &clutch_keys, &[force], "a clutch");
                refuse(ck, &mesh_keys, &[contact, oil], "a gear mesh");
            }
            Kind::Gear => {
                refuse(ck, &clutch_keys, &[force], "a clutch");
                refuse(ck, &mesh_keys, &[contact, oil], "a gear mesh");
            }
            Kind::Clutch | Kind::OneWay => {
                refuse(ck, &[&C::ratio], &[], "an ideal gear");
                refuse(ck, &mesh_keys, &[contact, oil], "a gear mesh");
            }
            Kind::Mesh => {
                refuse(ck, &[&C::ratio], &[], "an ideal gear");
                refuse(ck, &clutch_keys, &[force], "a clutch");
            }
        }
        let built = match kind {
            Kind::Mesh => gear_mesh(ck, r, k).map(CouplingKind::GearMesh),
            Kind::Gear => ck
                .num(&p(&C::ratio), r.value(&C::ratio), &C::ratio)
                .required(ck, &p(&C::ratio), "required for an ideal_gear: w_a / w_b")
                .map(CouplingKind::ideal_gear),
            Kind::Clutch => {
                let by_schedule = name.as_ref().is_some_and(|n| scheduled.contains(n));
                clutch(ck, r, k, base_dir, by_schedule).map(CouplingKind::Clutch)
            }
            Kind::OneWay => clutch(ck, r, k, base_dir, false).map(|cl| {
                CouplingKind::Clutch(LumpedClutch {
                    one_way: true,
                    ..cl
                })
            }),
            // a one-way clutch whose clutch never closes
            Kind::Freewheel => Some(CouplingKind::Clutch(LumpedClutch {
                mu_table: vec![(0.0, 0.0)],
                peak: 1.0,
                cgeo_m: 0.0,
                fn_max_n: 0.0,
                force: Signal::Constant(0.0),
                one_way: true,
            })),
            Kind::Planetary => {
                let carrier = body(ck, &C::carrier);
                let teeth = |ck: &mut Checker, key: &Key| {
                    ck.count(&p(key), r.value(key), key).required(
                        ck,
                        &p(key),
                        "required for a planetary set",
                    )
                };
                let (zs, zr) = (teeth(ck, &C::sun_teeth), teeth(ck, &C::ring_teeth));
                let double = ck
                    .boolean(&p(&C::double_pinion), r.value(&C::double_pinion))
                    .or(false);
                (|| {
                    Some(CouplingKind::Planetary(PlanetarySet {
                        sun_teeth: zs?,
                        ring_teeth: zr?,
                        carrier: carrier?,
                        double_pinion: double?,
                    }))
                })()
            }
            Kind::Pack => pack(ck, r, k, base_dir).map(|(p, f, thermal)| {
                fatigue.extend(f);
                if let Some(th) = thermal {
                    net.pack_thermal.insert(k, th);
                }
                CouplingKind::Pack(Box::new(p))
            }),
            Kind::Spring => {
                let num = |ck: &mut Checker, key: &Key| ck.num(&p(key), r.value(key), key);
                let k_ = num(ck, &C::stiffness_n_m_per_rad).required(
                    ck,
                    &p(&C::stiffness_n_m_per_rad),
                    "the spring's stiffness, N m/rad",
                );
                let d =
                    num(ck, &C::damping_n_m_s_per_rad).or(C::damping_n_m_s_per_rad.default_num());
                let theta0 = num(ck, &C::free_angle_rad).or(C::free_angle_rad.default_num());
                (|| {
                    let spring = clutchpack_model::SpringDamper {
                        stiffness_n_m_per_rad: k_?,
                        damping_n_m_s_per_rad: d?,
                        free_angle_rad: theta0?,
                    };
                    // (only when every body was valid: their indices are then the same)
                    let all_bodies = net.bodies.len() == bodies.len();
                    let inertia = |i: Option<usize>| -> Option<f64> {
                        let b = net.bodies.get(i?).filter(|_| all_bodies)?;
                        Some(if b.is_fixed() {
                            f64::INFINITY
                        } else {
                            b.inertia_kg_m2
                        })
                    };
                    let (ja, jb) = (inertia(a), inertia(b));
                    match (ja, jb) {
                        (Some(ja), Some(jb)) => spring_resolvable(ck, k, &spring, ja, jb)
                            .then_some(CouplingKind::SpringDamper(spring)),
                        // a body already reported
                        _ => Some(CouplingKind::SpringDamper(spring)),
                    }
                })()
            }
        };
        match (name, a, b, built) {
            (Some(name), Some(a), Some(b), Some(kind)) => {
                net.couplings.push(Coupling { name, a, b, kind })
            }
            _ => ok = false,
        }
    }
    if !ok {
        return None;
    }
    let problems = net.problems();
    for pr in &problems {
        match pr {
            NetworkProblem::Body {
                index,
                field,
                message,
            } => ck.report(format!("bodies[{index}].{field}"), None, message.clone()),
            NetworkProblem::Coupling {
                index,
                field,
                message,
            } => ck.report(format!("couplings[{index}].{field}"), None, message.clone()),
        }
    }
    problems.is_empty().then_some((net, fatigue))
}

/// The pack scene of a `kind = "pack"` coupling `k` (key `pack`, relative to the network
/// scene's folder), read by the pack scene's own loader: its problems are reported at
/// `couplings[k].pack` with the pack file's key paths. A network scene there and a pack the
/// reference engine cannot run (radial float, offsets, spacing errors) are refused. With the
/// pack, its bodies' fatigue parameters (its discs', then its plates') and its `[thermal]`
/// model, if it has one (the pack then carries its temperatures on the network).
fn pack(
    ck: &mut Checker,
    r: &C,
    k: usize,
    base_dir: &Path,
) -> Option<(
    clutchpack_model::PackModel,
    Vec<clutchpack_model::FatigueParams>,
    Option<clutchpack_model::thermal::ThermalModel>,
)> {
    let key = item("couplings", &C::pack, k);
    let file = ck.text(&key, r.value(&C::pack)).required(
        ck,
        &key,
        "required for kind = \"pack\": a pack scene file",
    )?;
    let shown = Some(format!("\"{file}\""));
    let path = base_dir.join(&file);
    let refuse = |ck: &mut Checker, why: String| {
        ck.report(key.clone(), shown.clone(), why);
        None
    };
    let text = match crate::read_input(&path) {
        Ok(t) => t,
        Err(error) => return refuse(ck, format!("cannot read {}: {error}", path.display())),
    };
    // A network scene is refused before it is validated: validating it would load its own
    // packs, and a pack file that names a network back (itself, or a -> b -> a) would recurse
    // until the stack overflows.
    if text
        .parse::<toml::Table>()
        .is_ok_and(|t| t.contains_key("bodies"))
    {
        return refuse(
            ck,
            format!(
                "{} is a network scene, not a pack (it has [[bodies]]): a pack file holds one \
                 pack ([shaft], [[discs]], ...), and a network never names a network",
                path.display()
            ),
        );
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let scene = match crate::parse(&text, &path.display().to_string(), folder, &[]) {
        Ok(s) => s,
        Err(e) => {
            let lines: Vec<String> = e.problems().iter().map(|p| p.to_string()).collect();
            return refuse(
                ck,
                format!(
                    "the pack scene {} has problems: {}",
                    path.display(),
                    lines.join("; ")
                ),
            );
        }
    };
    ck.files.push(path.clone());
    ck.files.extend(scene.inputs.iter().cloned());
    if let Some(part) = scene.pack.non_torsional_parts().first() {
        use clutchpack_model::NonTorsional as N;
        let what = match *part {
            N::RadialFloat(i) => format!("discs[{i}] floats radially"),
            N::InitialOffset(i) => format!("discs[{i}] starts off the axis"),
            N::SpacingErrors(i) => format!("discs[{i}] has tooth spacing errors"),
            N::PlatePerTooth(j) => {
                format!("plates[{j}] floats, starts off the axis or has spacing errors")
            }
        };
        return refuse(
            ck,
            format!(
                "{}: {what}, which needs the multibody engine; a pack on a network runs on the reference engine (one rotational degree of freedom per disc)",
                path.display()
            ),
        );
    }
    Some((scene.pack, scene.fatigue, scene.thermal))
}

/// Shortest time scale of a spring-damper accepted, s: its damping time constant
/// `J_r / d` and `sqrt(J_r / k)` (the natural period over 2 pi) on the two bodies' reduced
/// inertia `J_r = J_a J_b / (J_a + J_b)` (`J_a` alone when b is fixed). The bodies' bound on
/// a drag's time constant ([`super::bodies::MIN_DRAG_TIME_S`]): the engines integrate the
/// spring explicitly or by its own multirate step, both needing steps below these scales.
const MIN_SPRING_TIME_S: f64 = super::bodies::MIN_DRAG_TIME_S;

/// Whether the engines can integrate spring-damper `k` between bodies of inertias `ja` and
/// `jb` (kg m^2; infinite for a fixed body) in useful time, and its preload torque
/// `k |theta_0|` is a plausible torque. Reports each failure at its key, with the largest
/// accepted value.
fn spring_resolvable(
    ck: &mut Checker,
    k: usize,
    s: &clutchpack_model::SpringDamper,
    ja: f64,
    jb: f64,
) -> bool {
    let p = |key: &Key| item("couplings", key, k);
    let jr = if ja.is_infinite() {
        jb
    } else if jb.is_infinite() {
        ja
    } else {
        ja * jb / (ja + jb)
    };
    let mut good = true;
    let (d, stiff, theta0) = (
        s.damping_n_m_s_per_rad,
        s.stiffness_n_m_per_rad,
        s.free_angle_rad,
    );
    if d > 0.0 && jr / d < MIN_SPRING_TIME_S {
        ck.report(
            p(&C::damping_n_m_s_per_rad),
            Some(fmt_num(d)),
            format!(
                "must be at most {} N m s/rad between bodies of reduced inertia {} kg m^2 \
                 (plausibility bound: a damping time constant J / d of at least {} s); this \
                 one is {:.3e} s",
                fmt_num(jr / MIN_SPRING_TIME_S),
                fmt_num(jr),
                fmt_num(MIN_SPRING_TIME_S),
                jr / d
            ),
        );
        good = false;
    }
    if stiff > 0.0 && (jr / stiff).sqrt() < MIN_SPRING_TIME_S {
        ck.report(
            p(&C::stiffness_n_m_per_rad),
            Some(fmt_num(stiff)),
            format!(
                "must be at most {} N m/rad between bodies of reduced inertia {} kg m^2 \
                 (plausibility bound: sqrt(J / k) of at least {} s, its natural period over 2 pi)",
                fmt_num(jr / (MIN_SPRING_TIME_S * MIN_SPRING_TIME_S)),
                fmt_num(jr),
                fmt_num(MIN_SPRING_TIME_S),
            ),
        );
        good = false;
    }
    if stiff * theta0.abs() > MAX_TORQUE_N_M {
        ck.report(
            p(&C::free_angle_rad),
            Some(fmt_num(theta0)),
            format!(
                "its preload torque k |theta_0| = {} N m must be at most {} N m (plausibility \
                 bound of a torque)",
                fmt_num(stiff * theta0.abs()),
                fmt_num(MAX_TORQUE_N_M)
            ),
        );
        good = false;
    }
    good
}

/// `[bodies.firing]` of body `i`: `Some(Some(..))` when valid, `None` after reporting.
fn firing(ck: &mut Checker, r: &RawFiring, i: usize) -> Option<Option<Firing>> {
    let p = |k: &Key| format!("bodies[{i}].firing.{}", k.name);
    let cylinders = ck
        .count(&p(&F::cylinders), r.value(&F::cylinders), &F::cylinders)
        .required(ck, &p(&F::cylinders), "required for [bodies.firing]");
    let strokes = match ck.count(&p(&F::strokes), r.value(&F::strokes), &F::strokes) {
        Field::Valid(s) if s == 2 || s == 4 => Some(s),
        Field::Valid(s) => {
            ck.report(p(&F::strokes), Some(s.to_string()), "must be 4 or 2");
            None
        }
        Field::Absent => Some(4),
        Field::Invalid => None,
    };
    let amplitudes = ck
        .numbers(&p(&F::amplitudes_n_m), r.value(&F::amplitudes_n_m), None)
        .required(
            ck,
            &p(&F::amplitudes_n_m),
            "required: the amplitude of each multiple of the firing order, N m",
        );
    let amplitudes = match amplitudes {
        Some(a) if a.is_empty() => {
            ck.report(
                p(&F::amplitudes_n_m),
                Some("[]".into()),
                "needs at least one amplitude",
            );
            None
        }
        Some(a) if a.len() > MAX_FIRING_HARMONICS => {
            ck.report(
                p(&F::amplitudes_n_m),
                Some(format!("[...{} entries]", a.len())),
                format!(
                    "at most {MAX_FIRING_HARMONICS} harmonics (plausibility bound: an engine's \
                     spectrum above the 12th multiple of its firing order is below noise)"
                ),
            );
            None
        }
        Some(a) => {
            let mut good = true;
            for (j, x) in a.iter().enumerate() {
                if x.abs() > MAX_TORQUE_N_M {
                    ck.report(
                        format!("{}[{j}]", p(&F::amplitudes_n_m)),
                        Some(fmt_num(*x)),
                        format!(
                            "must be within [-{0}, {0}] N m (plausibility bound of a torque)",
                            fmt_num(MAX_TORQUE_N_M)
                        ),
                    );
                    good = false;
                }
            }
            good.then_some(a)
        }
        None => None,
    };
    let n = amplitudes.as_ref().map(Vec::len);
    let phases = match ck.numbers(&p(&F::phases_deg), r.value(&F::phases_deg), n) {
        Field::Valid(v) => Some(v.iter().map(|d| d.to_radians()).collect()),
        Field::Absent => n.map(|n| vec![0.0; n]),
        Field::Invalid => None,
    };
    Some(Some(Firing {
        cylinders: cylinders?,
        strokes: strokes?,
        amplitudes_n_m: amplitudes?,
        phases_rad: phases?,
    }))
}

/// A clutch's keys and its `force` table.
/// A lumped clutch's keys; `by_schedule`: a shift element whose force the transmission's
/// schedule sets (its `[couplings.force]` is then refused, and a placeholder stands in).
fn clutch(
    ck: &mut Checker,
    r: &C,
    k: usize,
    base_dir: &Path,
    by_schedule: bool,
) -> Option<LumpedClutch> {
    let p = |key: &Key| item("couplings", key, k);
    let mu = ck.num(&p(&C::mu), r.value(&C::mu), &C::mu);
    let speeds = ck.numbers(&p(&C::mu_speeds_rad_s), r.value(&C::mu_speeds_rad_s), None);
    let values = ck.numbers(&p(&C::mu_values), r.value(&C::mu_values), None);
    let table = match (mu, speeds, values) {
        (Field::Valid(mu), Field::Absent, Field::Absent) => Some(vec![(0.0, mu)]),
        (Field::Absent, Field::Valid(w), Field::Valid(m)) => {
            if w.len() != m.len() || w.is_empty() {
                ck.report(
                    p(&C::mu_values),
                    None,
                    format!(
                        "must have one value per entry of mu_speeds_rad_s ({}), has {}",
                        w.len(),
                        m.len()
                    ),
                );
                None
            } else {
                Some(w.into_iter().zip(m).collect())
            }
        }
        (Field::Invalid, ..) | (_, Field::Invalid, _) | (.., Field::Invalid) => None,
        _ => {
            ck.report(
                p(&C::mu),
                None,
                "a clutch needs mu, or mu_speeds_rad_s with mu_values (not both)",
            );
            None
        }
    };
    let peak = ck
        .num(&p(&C::peak), r.value(&C::peak), &C::peak)
        .or(C::peak.default_num());
    let cgeo = ck
        .num(&p(&C::cgeo_m), r.value(&C::cgeo_m), &C::cgeo_m)
        .or(C::cgeo_m.default_num());
    let fn_max = ck
        .num(
            &p(&C::max_normal_force_n),
            r.value(&C::max_normal_force_n),
            &C::max_normal_force_n,
        )
        .required(ck, &p(&C::max_normal_force_n), "required for a clutch");
    let force = match &r.force {
        Some(_) if by_schedule => {
            ck.report(
                format!("couplings[{k}].force"),
                None,
                "set by [transmission]'s shift schedule (initial_gear and [[transmission.shifts]]): remove it",
            );
            None
        }
        None if by_schedule => Some(Signal::Constant(0.0)),
        Some(f) => signal(ck, &FORCE_SIGNAL, k, |key| f.value(key), base_dir),
        None => {
            ck.report(
                format!("couplings[{k}].force"),
                None,
                "missing (a clutch's normalized normal force: a [couplings.force] table)",
            );
            None
        }
    };
    let clutch = LumpedClutch {
        mu_table: table?,
        peak: peak?,
        cgeo_m: cgeo?,
        fn_max_n: fn_max?,
        force: force?,
        one_way: false,
    };
    let mut good = true;
    for (field, message) in clutch.problems() {
        let key = match field {
            "mu" if r.value(&C::mu).is_none() => p(&C::mu_speeds_rad_s),
            "fn_max_n" => p(&C::max_normal_force_n),
            "force" => format!("couplings[{k}].force"),
            other => format!("couplings[{k}].{other}"),
        };
        ck.report(key, None, message);
        good = false;
    }
    good.then_some(clutch)
}

/// A gear mesh's keys and its tooth law (`[couplings.contact]`, `[couplings.oil]`: the keys of
/// a disc's law, MODEL.md section 2).
fn gear_mesh(ck: &mut Checker, r: &C, k: usize) -> Option<GearMesh> {
    let p = |key: &Key| item("couplings", key, k);
    let num = |ck: &mut Checker, key: &Key| ck.num(&p(key), r.value(key), key);
    let required = |ck: &mut Checker, key: &Key| {
        num(ck, key).required(ck, &p(key), "required for a gear_mesh")
    };
    let ra = required(ck, &C::base_radius_a_m);
    let rb = required(ck, &C::base_radius_b_m);
    let backlash = required(ck, &C::backlash_m);
    let pairs = num(ck, &C::pairs).or(C::pairs.default_num());
    let offset = num(ck, &C::mesh_offset_m).or(0.0);
    let internal = ck
        .boolean(&p(&C::internal), r.value(&C::internal))
        .or(false);
    // the law: [couplings.contact] and [couplings.oil] (couplings[k].contact.modulus_pa)
    let at = format!("couplings[{k}]");
    let cv = |key: &Key| r.contact.as_ref().and_then(|c| c.value(key));
    let ov = |key: &Key| r.oil.as_ref().and_then(|o| o.value(key));
    let law = ck
        .choice(
            &Ct::law.at(&at),
            cv(&Ct::law),
            &Ct::law,
            &[LawKind::Paper, LawKind::Dry, LawKind::Squeeze],
        )
        .or(LawKind::Paper);
    let hint = "required for a gear_mesh (in its [couplings.contact])";
    let modulus = ck
        .num(
            &Ct::modulus_pa.at(&at),
            cv(&Ct::modulus_pa),
            &Ct::modulus_pa,
        )
        .required(ck, &Ct::modulus_pa.at(&at), hint);
    let curvature = ck
        .num(
            &Ct::curvature_radius_m.at(&at),
            cv(&Ct::curvature_radius_m),
            &Ct::curvature_radius_m,
        )
        .required(ck, &Ct::curvature_radius_m.at(&at), hint);
    let loss = ck
        .num(
            &Ct::loss_coefficient_s_m.at(&at),
            cv(&Ct::loss_coefficient_s_m),
            &Ct::loss_coefficient_s_m,
        )
        .or(0.0);
    let film = ck
        .num(
            &O::film_thickness_m.at(&at),
            ov(&O::film_thickness_m),
            &O::film_thickness_m,
        )
        .or(0.0);
    let needs_oil = matches!((law, film), (Some(l), Some(h)) if l != LawKind::Dry && h > 0.0);
    let oil_num = |ck: &mut Checker, key: &Key| {
        let f = ck.num(&key.at(&at), ov(key), key);
        if needs_oil {
            f.required(
                ck,
                &key.at(&at),
                "required with a film (film_thickness_m > 0) and a law that is not dry",
            )
        } else {
            f.or(0.0)
        }
    };
    let viscosity = oil_num(ck, &O::viscosity_pa_s);
    let leakage = oil_num(ck, &O::leakage_coefficient);
    let width = oil_num(ck, &O::width_m);
    let length = oil_num(ck, &O::length_m);
    let v_floor = ck
        .num(
            &O::v_floor_m_s.at(&at),
            ov(&O::v_floor_m_s),
            &O::v_floor_m_s,
        )
        .or(O::v_floor_m_s.default_num());
    let h_min = ck
        .num(&O::h_min_m.at(&at), ov(&O::h_min_m), &O::h_min_m)
        .or(O::h_min_m.default_num());
    let mesh = GearMesh {
        base_radius_a_m: ra?,
        base_radius_b_m: rb?,
        internal: internal?,
        backlash_m: backlash?,
        pairs: pairs?,
        initial_offset_m: offset?,
        law: ToothLaw {
            kind: law?,
            hertz: Hertz {
                modulus_pa: modulus?,
                curvature_radius_m: curvature?,
                loss_coefficient_s_m: loss?,
            },
            oil: OilFilm {
                thickness_m: film?,
                viscosity_pa_s: viscosity?,
                leakage_coefficient: leakage?,
                width_m: width?,
                length_m: length?,
                v_floor_m_s: v_floor?,
                h_min_m: h_min?,
            },
        },
    };
    // the film and the start inside the free play, along the line of action
    let half = 0.5 * mesh.backlash_m;
    let reach = half - mesh.law.engagement_offset_m();
    if reach <= 0.0 {
        ck.report(
            O::film_thickness_m.at(&at),
            Some(crate::schema::fmt_num(mesh.law.oil.thickness_m)),
            format!("must be < backlash_m / 2 = {half:e} m (else both flanks engage at once)"),
        );
        return None;
    }
    if mesh.initial_offset_m.abs() >= reach {
        ck.report(
            p(&C::mesh_offset_m),
            Some(crate::schema::fmt_num(mesh.initial_offset_m)),
            format!(
                "the mesh must start inside its free play: |x| must be < backlash_m / 2 - the film = {reach:e} m"
            ),
        );
        return None;
    }
    Some(mesh)
}
