//! Bodies: `[defaults]` and every `[[discs]]` entry (friction discs on the shaft), and
//! `[plate_defaults]` and every `[[plates]]` entry (separator plates on their carrier).
//!
//! Every body key is checked where it is written, generically by its definition
//! ([`Params`]); a bad value in `[defaults]` is reported once, at its `defaults.` path. Each
//! body then resolves every key in this order: its own value, then the defaults table's, then
//! the key's built-in default; a required key found nowhere is reported as missing at the
//! body's key path (`discs[1].spline.teeth`). Then the rules between keys: the oil parameters
//! a film needs, the backlash below the tooth pitch, the film and the start position inside
//! the free play.

use super::{Checker, Field};
use crate::catalog::body_keys;
use crate::keys::{
    RawBody as B, RawContact as C, RawMaterial as M, RawOil as O, RawSpline as Sp,
    RawToothForm as F,
};
use crate::schema::{fmt_num, show, Key, Kind, RawTable};
use clutchpack_model::{
    DiscModel, FatigueParams, Hertz, LawKind, Material, MinerRule, OilFilm, SplineGeometry,
    ToothForm, ToothLaw,
};

/// A body value checked where it is written, of the kind of its key.
#[derive(Debug, Clone, PartialEq)]
enum Val {
    Num(f64),
    Count(u32),
    Bool(bool),
    Text(String),
    Choice(usize),
    Numbers(Vec<f64>),
}

/// Every body key (but `name`) of one table (`[defaults]` or one `[[discs]]` entry), checked
/// where it is written.
struct Params(Vec<(&'static Key, Field<Val>)>);

impl Params {
    /// Checks every body key of `r` (`at` is `defaults` or `discs[i]`).
    fn check(ck: &mut Checker, at: &str, r: &B) -> Params {
        let mut out = Vec::new();
        for &(_, k) in body_keys() {
            if k.name == B::name.name && k.table == B::name.table {
                continue;
            }
            let path = k.at(at);
            let v = r.value(k);
            let f = match k.kind {
                Kind::Number(_) => map(ck.num(&path, v, k), Val::Num),
                Kind::Count { .. } => map(ck.count(&path, v, k), Val::Count),
                Kind::Bool => map(ck.boolean(&path, v), Val::Bool),
                Kind::Text => map(ck.text(&path, v), Val::Text),
                Kind::Choice(names) => {
                    let idx: Vec<usize> = (0..names.len()).collect();
                    map(ck.choice(&path, v, k, &idx), Val::Choice)
                }
                Kind::Numbers => {
                    let len = (k.name == B::initial_offset_m.name).then_some(2);
                    map(ck.numbers(&path, v, len), Val::Numbers)
                }
                Kind::NumberRows | Kind::Texts => {
                    unreachable!("{} is not a body key's kind", k.rel())
                }
            };
            out.push((k, f));
        }
        Params(out)
    }

    /// The checked value of `k` (the names compared first: most differ in length, and the
    /// tables of a body's keys are few and long; a scene of 33 bodies looked its keys up
    /// some 27 000 times, table first, each equal table a `memcmp`).
    fn get(&self, k: &Key) -> Field<Val> {
        self.0
            .iter()
            .find(|(p, _)| p.name == k.name && p.table == k.table)
            .map(|(_, f)| f.clone())
            .unwrap_or_else(|| unreachable!("{} is not a body key", k.rel()))
    }

    fn num(&self, k: &Key) -> Field<f64> {
        unwrap(self.get(k), |v| match v {
            Val::Num(x) => Some(x),
            _ => None,
        })
    }

    fn count(&self, k: &Key) -> Field<u32> {
        unwrap(self.get(k), |v| match v {
            Val::Count(n) => Some(n),
            _ => None,
        })
    }

    fn flag(&self, k: &Key) -> Field<bool> {
        unwrap(self.get(k), |v| match v {
            Val::Bool(b) => Some(b),
            _ => None,
        })
    }

    fn choice(&self, k: &Key) -> Field<usize> {
        unwrap(self.get(k), |v| match v {
            Val::Choice(i) => Some(i),
            _ => None,
        })
    }

    fn numbers(&self, k: &Key) -> Field<Vec<f64>> {
        unwrap(self.get(k), |v| match v {
            Val::Numbers(x) => Some(x),
            _ => None,
        })
    }
}

/// A checked field as a [`Val`].
fn map<T>(f: Field<T>, to: impl FnOnce(T) -> Val) -> Field<Val> {
    match f {
        Field::Absent => Field::Absent,
        Field::Invalid => Field::Invalid,
        Field::Valid(v) => Field::Valid(to(v)),
    }
}

/// A [`Val`] field as the type of its key.
fn unwrap<T>(f: Field<Val>, from: impl FnOnce(Val) -> Option<T>) -> Field<T> {
    match f {
        Field::Absent => Field::Absent,
        Field::Invalid => Field::Invalid,
        Field::Valid(v) => from(v).map_or(Field::Invalid, Field::Valid),
    }
}

/// Where a body's effective value came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    Own,
    Defaults,
    Builtin,
}

/// The body's field if present, else the defaults' field (with its source).
fn pick<T: Clone>(own: &Field<T>, defaults: &Field<T>) -> Field<(T, Source)> {
    match (own, defaults) {
        (Field::Valid(v), _) => Field::Valid((v.clone(), Source::Own)),
        (Field::Invalid, _) => Field::Invalid,
        (Field::Absent, Field::Valid(v)) => Field::Valid((v.clone(), Source::Defaults)),
        (Field::Absent, Field::Invalid) => Field::Invalid,
        (Field::Absent, Field::Absent) => Field::Absent,
    }
}

/// The two tables of a kind of body: the array of entries and its shared defaults
/// (`[[discs]]` and `[defaults]`, or `[[plates]]` and `[plate_defaults]`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Sec {
    /// The array of tables, `discs` or `plates`.
    items: &'static str,
    /// The defaults table, `defaults` or `plate_defaults`.
    defaults: &'static str,
    /// Default name prefix of an entry (`disc` -> `disc-1`).
    name_prefix: &'static str,
}

/// The friction discs.
pub(super) const DISCS: Sec = Sec {
    items: "discs",
    defaults: "defaults",
    name_prefix: "disc",
};

/// The separator plates.
pub(super) const PLATES: Sec = Sec {
    items: "plates",
    defaults: "plate_defaults",
    name_prefix: "plate",
};

/// Where to set a body key `k` (`spline.teeth` -> `[discs.spline] or [defaults.spline]`).
fn where_to_set(sec: Sec, k: &Key) -> String {
    let (items, defaults) = (sec.items, sec.defaults);
    if k.table.is_empty() {
        format!("[[{items}]] or [{defaults}]")
    } else {
        let t = k.table;
        format!("[{items}.{t}] or [{defaults}.{t}]")
    }
}

/// ` (inherited from defaults.k)` when the value came from `[defaults]`.
fn inherited(sec: Sec, source: Source, k: &Key) -> String {
    if source == Source::Defaults {
        format!(" (inherited from {})", k.at(sec.defaults))
    } else {
        String::new()
    }
}

/// `[defaults]` and every `[[discs]]` (or `[plate_defaults]` and every `[[plates]]`).
/// `names` holds the names taken so far, with the key of their entry (names are unique
/// across discs and plates); `at_least_one` makes an empty array a problem. Each body comes
/// with the fatigue parameters of its teeth.
pub(super) fn bodies(
    ck: &mut Checker,
    sec: Sec,
    defaults: Option<&B>,
    raw: Option<&[B]>,
    at_least_one: bool,
    names: &mut Vec<(String, String)>,
) -> Option<Vec<(DiscModel, FatigueParams)>> {
    let empty = B::default();
    let raw_defaults = defaults.unwrap_or(&empty);
    if raw_defaults.name.is_some() {
        ck.report(
            format!("{}.name", sec.defaults),
            None,
            format!(
                "unknown key ({}; a name belongs to each [[{}]] entry)",
                crate::catalog::expected_text(sec.defaults),
                sec.items
            ),
        );
    }
    let d = Params::check(ck, sec.defaults, raw_defaults);
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
        let item = format!("{}[{i}]", sec.items);
        let name_key = B::name.at(&item);
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
            names.push((n.clone(), item.clone()));
        }
        let own = Params::check(ck, &item, r);
        let body = Body {
            sec,
            item,
            own: &own,
            defaults: &d,
        };
        match (body.resolve(ck, name), out.as_mut()) {
            (Some(disc), Some(v)) => v.push(disc),
            _ => out = None,
        }
    }
    out
}

/// One body being resolved: its own values over its defaults table's.
struct Body<'a> {
    sec: Sec,
    /// `discs[i]`.
    item: String,
    own: &'a Params,
    defaults: &'a Params,
}

impl Body<'_> {
    /// A required key: the body's, else the defaults'; missing is reported at
    /// `item.k` (`discs[1].spline.teeth`).
    fn required<T: Clone>(
        &self,
        ck: &mut Checker,
        k: &Key,
        get: impl Fn(&Params, &Key) -> Field<T>,
    ) -> Option<T> {
        pick(&get(self.own, k), &get(self.defaults, k))
            .required_with(
                ck,
                || k.at(&self.item),
                || format!("required; set it in {}", where_to_set(self.sec, k)),
            )
            .map(|(v, _)| v)
    }

    /// An optional number with its key's default, with where it came from.
    fn num(&self, k: &Key) -> Option<(f64, Source)> {
        pick(&self.own.num(k), &self.defaults.num(k)).or((k.default_num(), Source::Builtin))
    }

    /// The fatigue parameters of the body's teeth (`fatigue.*`, `material.*`): every value
    /// is checked by its key's rule where it is written; no rules between them.
    fn fatigue(&self) -> Option<FatigueParams> {
        let rules = [
            MinerRule::Original,
            MinerRule::Elementary,
            MinerRule::Haibach,
        ];
        let rule = pick(
            &self.own.choice(&M::miner_rule),
            &self.defaults.choice(&M::miner_rule),
        )
        .or((M::miner_rule.default_choice(), Source::Builtin))
        .map(|(i, _)| rules[i]);
        let n = |k: &Key| self.num(k).map(|(v, _)| v);
        Some(FatigueParams {
            form: ToothForm {
                form_factor: n(&F::form_factor)?,
                stress_correction: n(&F::stress_correction_factor)?,
                load_distribution: n(&F::load_distribution_factor)?,
                face_width_m: n(&F::face_width_m)?,
                working_depth_m: n(&F::working_depth_m)?,
            },
            material: Material {
                endurance_amplitude_pa: n(&M::endurance_amplitude_pa)?,
                knee_cycles: n(&M::knee_cycles)?,
                slope: n(&M::slope)?,
                rule: rule?,
                critical_damage: n(&M::critical_damage)?,
            },
        })
    }

    /// Resolves and cross-checks the body.
    fn resolve(
        &self,
        ck: &mut Checker,
        name: Option<String>,
    ) -> Option<(DiscModel, FatigueParams)> {
        let (sec, item) = (self.sec, self.item.as_str());
        let (own, d) = (self.own, self.defaults);
        let inertia = self.required(ck, &B::inertia_kg_m2, Params::num);
        let drag = self.num(&B::drag_n_m_s_rad);
        let angle = self.num(&B::initial_rel_angle_rad);
        let speed = self.num(&B::initial_rel_speed_rad_s);
        let radial_float = pick(&own.flag(&B::radial_float), &d.flag(&B::radial_float))
            .or((B::radial_float.default_bool(), Source::Builtin));
        let spacing_errors = pick(
            &own.numbers(&B::tooth_spacing_errors_m),
            &d.numbers(&B::tooth_spacing_errors_m),
        )
        .or((Vec::new(), Source::Builtin));
        let offset = pick(
            &own.numbers(&B::initial_offset_m),
            &d.numbers(&B::initial_offset_m),
        )
        .or((vec![0.0, 0.0], Source::Builtin));
        let teeth = self.required(ck, &Sp::teeth, Params::count);
        let pitch = self.required(ck, &Sp::pitch_radius_m, Params::num);
        let alpha_deg = self.required(ck, &Sp::pressure_angle_deg, Params::num);
        let backlash = pick(&own.num(&Sp::backlash_m), &d.num(&Sp::backlash_m)).required_with(
            ck,
            || Sp::backlash_m.at(item),
            || format!("required; set it in {}", where_to_set(sec, &Sp::backlash_m)),
        );
        let laws = [LawKind::Paper, LawKind::Dry, LawKind::Squeeze];
        let law = pick(&own.choice(&C::law), &d.choice(&C::law))
            .or((C::law.default_choice(), Source::Builtin))
            .map(|(i, _)| laws[i]);
        let modulus = self.required(ck, &C::modulus_pa, Params::num);
        let curvature = self.required(ck, &C::curvature_radius_m, Params::num);
        let loss = self.num(&C::loss_coefficient_s_m);
        let film = self.num(&O::film_thickness_m);

        // The film parameters are needed when a film carries load: thickness > 0, law not dry.
        let needs_oil =
            matches!((law, film), (Some(l), Some((h, _))) if l != LawKind::Dry && h > 0.0);
        let oil_param = |ck: &mut Checker, k: &Key| {
            if needs_oil {
                pick(&own.num(k), &d.num(k))
                    .required_with(
                        ck,
                        || k.at(item),
                        || {
                            format!(
                                "required when oil.film_thickness_m > 0 and contact.law is not \
                                 \"dry\"; set it in {}",
                                where_to_set(sec, k)
                            )
                        },
                    )
                    .map(|(v, _)| v)
            } else {
                pick(&own.num(k), &d.num(k))
                    .or((0.0, Source::Builtin))
                    .map(|(v, _)| v)
            }
        };
        let viscosity = oil_param(ck, &O::viscosity_pa_s);
        let leakage = oil_param(ck, &O::leakage_coefficient);
        let width = oil_param(ck, &O::width_m);
        let length = oil_param(ck, &O::length_m);
        let v_floor = self.num(&O::v_floor_m_s);
        let h_min = self.num(&O::h_min_m);

        let spline = (|| {
            Some(SplineGeometry {
                teeth: teeth?,
                pitch_radius_m: pitch?,
                pressure_angle_rad: alpha_deg?.to_radians(),
                backlash_m: backlash?.0,
            })
        })();
        // The backlash must be below the tooth pitch: a gap wider than the pitch leaves no
        // tooth.
        let mut backlash_ok = true;
        if let (Some(g), Some((_, b_source))) = (spline, backlash) {
            if g.backlash_m >= g.tooth_pitch_m() {
                ck.report(
                    Sp::backlash_m.at(item),
                    Some(fmt_num(g.backlash_m)),
                    format!(
                        "must be < the tooth pitch 2 pi R / n = {} m (spline.teeth = {}, \
                         spline.pitch_radius_m = {}){}",
                        fmt_num(g.tooth_pitch_m()),
                        g.teeth,
                        fmt_num(g.pitch_radius_m),
                        inherited(sec, b_source, &Sp::backlash_m)
                    ),
                );
                backlash_ok = false;
            }
        }
        let spline = spline.filter(|_| backlash_ok);

        // One spacing error per tooth, or none.
        let mut spacing_ok = true;
        if let (Some(n), Some((errors, source))) = (teeth, spacing_errors.as_ref()) {
            if !errors.is_empty() && errors.len() != n as usize {
                ck.report(
                    B::tooth_spacing_errors_m.at(item),
                    Some(format!("[...{} numbers]", errors.len())),
                    format!(
                        "must have one number per tooth (spline.teeth = {n}) or be empty{}",
                        inherited(sec, *source, &B::tooth_spacing_errors_m)
                    ),
                );
                spacing_ok = false;
            }
        }

        // The film and the start position against the free play, along the line of action.
        let mut inside = spacing_ok && backlash_ok;
        if let (Some(spline), Some(kind), Some((h_o, film_source)), Some((phi0, angle_source))) =
            (spline, law, film, angle)
        {
            let half_play_m = spline.half_play_line_m();
            let offset_m = if kind == LawKind::Dry { 0.0 } else { h_o };
            if kind != LawKind::Dry && h_o >= half_play_m {
                ck.report(
                    O::film_thickness_m.at(item),
                    Some(fmt_num(h_o)),
                    format!(
                        "must be < g0 Rb = {half_play_m:.6e} m, half the free play along the \
                         line of action (else both flanks engage at once){}",
                        inherited(sec, film_source, &O::film_thickness_m)
                    ),
                );
                inside = false;
            } else if phi0.abs() * spline.base_radius_m() >= half_play_m - offset_m {
                let reach_m = half_play_m - offset_m;
                ck.report(
                    B::initial_rel_angle_rad.at(item),
                    Some(fmt_num(phi0)),
                    format!(
                        "the disc must start inside the free play: |phi0| Rb must be < g0 Rb - \
                         h_o = {reach_m:.6e} m, i.e. |phi0| < {:.6e} rad{}",
                        spline.free_half_play_rad(offset_m),
                        inherited(sec, angle_source, &B::initial_rel_angle_rad)
                    ),
                );
                inside = false;
            }
        }
        // Every tooth must start inside the free play too (checked below, on the built disc,
        // by the model's one rule: `DiscModel::start_free_play_rad`).
        let tooth_check = (
            spacing_errors.as_ref().map(|(_, s)| *s),
            offset.as_ref().map(|(_, s)| *s),
            angle.map(|(_, s)| s),
        );
        let fatigue = self.fatigue();
        if !inside {
            return None;
        }

        let disc = DiscModel {
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
        };
        if let (Some(errors_source), Some(offset_source), Some(_)) = tooth_check {
            let free = disc.start_free_play_rad();
            let phi0 = disc.initial_rel_angle_rad;
            if phi0.abs() >= free {
                let e = disc.initial_offset_m;
                let offset_len = e[0].hypot(e[1]);
                let worst = disc
                    .tooth_spacing_errors_m
                    .iter()
                    .fold(0.0f64, |m, x| m.max(x.abs()));
                let (k, value, source) = if offset_len > 0.0 {
                    (
                        &B::initial_offset_m,
                        format!("[{}, {}]", fmt_num(e[0]), fmt_num(e[1])),
                        offset_source,
                    )
                } else {
                    (
                        &B::tooth_spacing_errors_m,
                        format!("[...max |e| = {}]", fmt_num(worst)),
                        errors_source,
                    )
                };
                ck.report(
                    k.at(item),
                    Some(value),
                    format!(
                        "every tooth must start inside the free play: |phi0| = {} rad must be \
                         < {free:.6e} rad, the half play less (h_o + max|e_k| cos(alpha) + \
                         |offset|) / Rb{}",
                        fmt_num(phi0),
                        inherited(sec, source, k)
                    ),
                );
                return None;
            }
        }
        if !resolvable(ck, item, &disc) {
            return None;
        }
        Some((disc, fatigue?))
    }
}

/// Closing speed at which [`resolvable`] judges the shortest tooth impact, m/s (spline rattle
/// closes at well below 1 m/s; the paper's impacts at about 0.3 m/s).
pub(crate) const PLAUSIBLE_CLOSING_SPEED_M_S: f64 = 10.0;
/// Shortest tooth impact an engine must resolve, s: about 30 steps of 3e-9 s (the paper's last
/// 75 us). A shorter one asks for steps near the engines' stall guard (6e-11 s mean).
pub(crate) const MIN_IMPACT_DURATION_S: f64 = 1e-7;
/// Shortest drag time constant `J / C`, s, of every body with a drag or damping to ground (a
/// disc or plate's drag, an inertial shaft's damping, the drum's drag): the engines apply it
/// explicitly, stable for steps below `2 J / C`; a clutch body's drag time constant is seconds.
pub(crate) const MIN_DRAG_TIME_S: f64 = 1e-6;

/// Whether the engines can integrate a body of inertia `J` (its key path and value) with the
/// drag or damping `C` to ground (its key path and value): its time constant `J / C` is at
/// least [`MIN_DRAG_TIME_S`]. Else reports at the drag's key the largest accepted value and
/// the step the value would need. One rule for the discs, the plates, the shaft and the drum.
pub(super) fn drag_resolvable(
    ck: &mut Checker,
    (inertia_key, inertia): (&str, f64),
    (drag_key, drag): (&str, f64),
) -> bool {
    let tau = inertia / drag;
    if tau.is_nan() || tau < MIN_DRAG_TIME_S {
        ck.report(
            drag_key,
            Some(fmt_num(drag)),
            format!(
                "must be at most {} N m s/rad with {inertia_key} = {} (plausibility bound: a \
                 drag time constant J / C of at least {} s); this one is {tau:.3e} s and would \
                 need steps below {:.1e} s",
                fmt_num(inertia / MIN_DRAG_TIME_S),
                fmt_num(inertia),
                fmt_num(MIN_DRAG_TIME_S),
                2.0 * tau,
            ),
        );
        return false;
    }
    true
}

/// Whether the engines can resolve `disc` in useful time: its hardest tooth impact (Hertz
/// stiffness `H`, the film only softens it; effective mass `J / (n Rb^2)`, closing at
/// [`PLAUSIBLE_CLOSING_SPEED_M_S`]) lasts at least [`MIN_IMPACT_DURATION_S`], and its drag time
/// constant is at least [`MIN_DRAG_TIME_S`]. Reports each failure with the step it would need.
fn resolvable(ck: &mut Checker, item: &str, disc: &DiscModel) -> bool {
    let mut ok = true;
    let h = clutchpack_model::law::hertz_coefficient(
        disc.law.hertz.modulus_pa,
        disc.law.hertz.curvature_radius_m,
    );
    let m_eff = disc.spline.effective_mass_kg(disc.inertia_kg_m2);
    let t_c = clutchpack_model::free_impact_duration_s(h, m_eff, PLAUSIBLE_CLOSING_SPEED_M_S);
    if t_c.is_nan() || t_c < MIN_IMPACT_DURATION_S {
        ck.report(
            B::inertia_kg_m2.at(item),
            Some(fmt_num(disc.inertia_kg_m2)),
            format!(
                "with contact.modulus_pa = {} and spline.teeth = {}, a tooth impact at {} m/s \
                 would last {t_c:.3e} s (Hertz, effective mass J / (n Rb^2) = {m_eff:.3e} kg) \
                 and need steps of about {:.1e} s; the engines resolve impacts of at least {} s \
                 (plausibility bound): raise the inertia or lower the modulus",
                fmt_num(disc.law.hertz.modulus_pa),
                disc.spline.teeth,
                fmt_num(PLAUSIBLE_CLOSING_SPEED_M_S),
                t_c / 30.0,
                fmt_num(MIN_IMPACT_DURATION_S),
            ),
        );
        ok = false;
    }
    ok &= drag_resolvable(
        ck,
        (&B::inertia_kg_m2.at(item), disc.inertia_kg_m2),
        (&B::drag_n_m_s_rad.at(item), disc.drag_n_m_s_rad),
    );
    ok
}
