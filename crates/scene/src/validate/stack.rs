//! `[drum]` and `[stack]` (with its `friction`, `pressure` and `open_gap` tables): the parts
//! of a whole pack (MODEL.md section 5). Checked on their own here; against the bodies (N + 1
//! plates for N discs, plates on a drum) in [`super::validate`].

use super::Checker;
use crate::keys::{RawDrum, RawFriction as F, RawOpenGap as G, RawPressure as P, RawStack as St};
use crate::schema::{fmt_num, Key, RawTable, Rule};
use clutchpack_model::{
    DrumModel, FrictionCurve, OpenGap, Piston, PressureProfile, StackModel, Table, TableError,
};
use toml::Value;

/// `[drum]`.
pub(super) fn drum(ck: &mut Checker, r: &RawDrum) -> Option<DrumModel> {
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), r.value(k), k);
    let inertia = num(ck, &RawDrum::inertia_kg_m2).required(
        ck,
        &RawDrum::inertia_kg_m2.rel(),
        "required with [drum]; set it there",
    );
    let mut or_default = |k: &Key| num(ck, k).or(k.default_num());
    let load = or_default(&RawDrum::load_torque_n_m);
    let drag = or_default(&RawDrum::drag_n_m_s_rad);
    let speed = or_default(&RawDrum::initial_speed_rad_s);
    // the drum's drag: the bodies' bound on the drag time constant J / C
    if let (Some(j), Some(c)) = (inertia, drag) {
        if !super::bodies::drag_resolvable(
            ck,
            (&RawDrum::inertia_kg_m2.rel(), j),
            (&RawDrum::drag_n_m_s_rad.rel(), c),
        ) {
            return None;
        }
    }
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
        if let Err(rule) = y_rule.check(*v, "") {
            ck.report(format!("{y_key}[{j}]"), Some(fmt_num(*v)), rule);
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
pub(super) fn stack(ck: &mut Checker, r: &St) -> Option<StackModel> {
    let hint = "required with [stack]; set it there";
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), r.value(k), k);
    let inner =
        num(ck, &St::face_inner_radius_m).required(ck, &St::face_inner_radius_m.rel(), hint);
    let outer =
        num(ck, &St::face_outer_radius_m).required(ck, &St::face_outer_radius_m.rel(), hint);
    if let (Some(ri), Some(ro)) = (inner, outer) {
        if ro <= ri {
            ck.report(
                St::face_outer_radius_m.rel(),
                Some(fmt_num(ro)),
                format!(
                    "must be > {} = {}",
                    St::face_inner_radius_m.rel(),
                    fmt_num(ri)
                ),
            );
        }
    }
    let spline =
        num(ck, &St::spline_friction_coefficient).or(St::spline_friction_coefficient.default_num());
    let area = num(ck, &St::piston_area_m2).required(ck, &St::piston_area_m2.rel(), hint);
    let spring = num(ck, &St::return_spring_n).or(St::return_spring_n.default_num());
    let friction = friction(ck, r);
    let pressure = pressure(ck, r);

    // open gaps
    let open_gap = match &r.open_gap {
        None => Some(None),
        Some(g) => {
            let ghint = "required with [stack.open_gap]; set it there";
            let eta = ck
                .num(
                    &G::viscosity_pa_s.rel(),
                    g.value(&G::viscosity_pa_s),
                    &G::viscosity_pa_s,
                )
                .required(ck, &G::viscosity_pa_s.rel(), ghint);
            let h = ck
                .num(&G::gap_m.rel(), g.value(&G::gap_m), &G::gap_m)
                .required(ck, &G::gap_m.rel(), ghint);
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
        face_friction: Vec::new(),
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

/// `[stack.friction]`.
fn friction(ck: &mut Checker, r: &St) -> Option<FrictionCurve> {
    let empty = F::default();
    let f = r.friction.as_ref().unwrap_or(&empty);
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), f.value(k), k);
    let kinds = [false, true];
    let table_kind = ck
        .choice(&F::kind.rel(), f.kind.as_ref(), &F::kind, &kinds)
        .or(kinds[F::kind.default_choice()])?;
    if !table_kind {
        for k in [&F::slip_m_s, &F::mu] {
            ck.not_allowed(
                &k.rel(),
                f.value(k),
                "only allowed with stack.friction.kind = \"table\"",
            );
        }
        let st = num(ck, &F::static_mu).required(
            ck,
            &F::static_mu.rel(),
            "required; set it in [stack.friction]",
        );
        let kin = num(ck, &F::kinetic_mu).or(st.unwrap_or(0.1));
        let vs = num(ck, &F::stribeck_speed_m_s).or(F::stribeck_speed_m_s.default_num());
        let c = num(ck, &F::viscous_slope_s_m).or(F::viscous_slope_s_m.default_num());
        return Some(FrictionCurve::Stribeck {
            static_mu: st?,
            kinetic_mu: kin?,
            stribeck_speed_m_s: vs?,
            viscous_slope_s_m: c?,
        });
    }
    for k in [
        &F::static_mu,
        &F::kinetic_mu,
        &F::stribeck_speed_m_s,
        &F::viscous_slope_s_m,
    ] {
        ck.not_allowed(
            &k.rel(),
            f.value(k),
            "only allowed with stack.friction.kind = \"stribeck\"",
        );
    }
    let t = table(
        ck,
        (&F::slip_m_s.rel(), f.slip_m_s.as_ref()),
        (&F::mu.rel(), f.mu.as_ref()),
        Rule::Positive,
        "required with stack.friction.kind = \"table\"; set it in [stack.friction]",
    )?;
    if t.t_s[0] != 0.0 {
        ck.report(
            format!("{}[0]", F::slip_m_s.rel()),
            Some(fmt_num(t.t_s[0])),
            "must be 0 (the table starts at zero slip)",
        );
        return None;
    }
    Some(FrictionCurve::Table(t))
}

/// `stack.pressure.kind`, in the order of the key's names.
#[derive(Clone, Copy, PartialEq)]
enum PKind {
    Constant,
    Ramp,
    Table,
}

/// `[stack.pressure]`.
fn pressure(ck: &mut Checker, r: &St) -> Option<PressureProfile> {
    let empty = P::default();
    let pr = r.pressure.as_ref().unwrap_or(&empty);
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), pr.value(k), k);
    let pkind = ck
        .choice(
            &P::kind.rel(),
            pr.kind.as_ref(),
            &P::kind,
            &[PKind::Constant, PKind::Ramp, PKind::Table],
        )
        .required(
            ck,
            &P::kind.rel(),
            "required with [stack]: \"constant\", \"ramp\" or \"table\"; set it in \
             [stack.pressure]",
        );
    // An invalid kind was reported: which keys it takes is unknown.
    let pkind = pkind?;
    let allowed: &[&Key] = match pkind {
        PKind::Constant => &[&P::pressure_pa],
        PKind::Ramp => &[&P::pressure_pa, &P::start_s, &P::rise_s],
        PKind::Table => &[&P::times_s, &P::values_pa],
    };
    for k in &P::KEYS[1..] {
        if !allowed.iter().any(|a| a.name == k.name) {
            ck.not_allowed(
                &k.rel(),
                pr.value(k),
                "not used by this stack.pressure.kind",
            );
        }
    }
    let phint = "required for this stack.pressure.kind; set it in [stack.pressure]";
    match pkind {
        PKind::Constant => num(ck, &P::pressure_pa)
            .required(ck, &P::pressure_pa.rel(), phint)
            .map(|pressure_pa| PressureProfile::Constant { pressure_pa }),
        PKind::Ramp => {
            let p = num(ck, &P::pressure_pa).required(ck, &P::pressure_pa.rel(), phint);
            let start = num(ck, &P::start_s).or(P::start_s.default_num());
            let rise = num(ck, &P::rise_s).required(ck, &P::rise_s.rel(), phint);
            Some(PressureProfile::Ramp {
                start_s: start?,
                rise_s: rise?,
                pressure_pa: p?,
            })
        }
        PKind::Table => table(
            ck,
            (&P::times_s.rel(), pr.times_s.as_ref()),
            (&P::values_pa.rel(), pr.values_pa.as_ref()),
            Rule::Closed(0.0, crate::keys::MAX_PRESSURE_PA),
            phint,
        )
        .map(PressureProfile::Table),
    }
}
