//! `[thermal]` (MODEL.md section 9): the oil's viscosity law, the reference temperature of
//! the tooth film, the lumped capacities and conductances of the discs, the plates and the
//! oil, the cooler and the thermal window. Checked against `[stack]` (whose face annulus
//! gives the bodies' capacities and areas) and `[simulation]` (a thermal scene runs on one
//! step sequence) in [`super::validate`].

use super::Checker;
use crate::keys::{
    RawConvection as Cv, RawStack, RawThermal as Th, RawThermalDiscs as D,
    RawThermalFriction as Fr, RawThermalOil as O, RawThermalPlates as Pl,
};
use crate::schema::{fmt_num, Key, RawTable};
use clutchpack_model::thermal::{
    laminar_gap_h_w_m2_k, pack::FastestBody, pack::MIN_TIME_CONSTANT_S, FrictionMapError,
    FrictionTable, GapHeating, GapViscosity, ThermalBody, ThermalModel, ThermalOil,
    ThermalProperties, ViscosityError, ViscosityLaw,
};
use std::f64::consts::PI;

/// `thermal.oil.law`, in the order of the key's names.
#[derive(Clone, Copy, PartialEq)]
enum Law {
    Walther,
    Vogel,
    Table,
}

/// `thermal.convection.kind`, in the order of the key's names.
#[derive(Clone, Copy, PartialEq)]
enum Convection {
    Adiabatic,
    Given,
    LaminarGap,
}

/// `[thermal]` of a pack with `n_discs` discs and `n_plates` plates; `stack` is the scene's
/// `[stack]` (required: its faces' annulus sizes the bodies).
pub(super) fn thermal(
    ck: &mut Checker,
    r: &Th,
    stack: Option<&RawStack>,
    n_discs: usize,
    n_plates: usize,
) -> Option<ThermalModel> {
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), r.value(k), k);
    let initial = num(ck, &Th::initial_temperature_k).required(
        ck,
        &Th::initial_temperature_k.rel(),
        "required with [thermal]; set it there",
    );
    let reference = num(ck, &Th::reference_temperature_k).optional();
    let step = num(ck, &Th::step_s).or(Th::step_s.default_num());
    let gap_choices = [GapViscosity::Absolute, GapViscosity::Scaled];
    let gap_viscosity = ck
        .choice(
            &Th::gap_viscosity.rel(),
            r.gap_viscosity.as_ref(),
            &Th::gap_viscosity,
            &gap_choices,
        )
        .or(gap_choices[Th::gap_viscosity.default_choice()]);
    let empty_oil = O::default();
    let oil = r.oil.as_ref().unwrap_or(&empty_oil);
    let viscosity = viscosity(ck, oil);
    let onum = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), oil.value(k), k);
    let oil_hint = "required with [thermal]; set it in [thermal.oil]";
    let oil_capacity =
        onum(ck, &O::heat_capacity_j_k).required(ck, &O::heat_capacity_j_k.rel(), oil_hint);
    let cooler =
        onum(ck, &O::cooler_capacity_rate_w_k).or(O::cooler_capacity_rate_w_k.default_num());
    let inlet = onum(ck, &O::inlet_temperature_k).optional();
    let lambda = onum(ck, &O::conductivity_w_m_k).or(O::conductivity_w_m_k.default_num());
    let friction = friction(ck, r.friction.as_ref());

    // the faces' annulus, from [stack]
    let Some(stack) = stack else {
        ck.report(
            "thermal",
            None,
            "a [thermal] section needs a [stack]: its faces' annulus (face_inner_radius_m, \
             face_outer_radius_m) sizes the discs' and plates' heat capacities and areas",
        );
        return None;
    };
    let radius = |k: &Key| match stack.value(k) {
        Some(toml::Value::Float(x)) => Some(*x),
        Some(toml::Value::Integer(i)) => Some(*i as f64),
        _ => None,
    };
    // reported by [stack]'s own check when missing or bad
    let (ri, ro) = (
        radius(&RawStack::face_inner_radius_m),
        radius(&RawStack::face_outer_radius_m),
    );
    let gap_default = stack
        .open_gap
        .as_ref()
        .and_then(|g| g.gap_m.as_ref())
        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)));
    let conductance_per_area = convection(ck, r.convection.as_ref(), lambda?, gap_default);

    let empty_d = D::default();
    let d = r.discs.as_ref().unwrap_or(&empty_d);
    let dnum = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), d.value(k), k);
    let core = dnum(ck, &D::core_thickness_m).or(D::core_thickness_m.default_num());
    let lining = dnum(ck, &D::lining_thickness_m).or(D::lining_thickness_m.default_num());
    let disc_capacity = dnum(ck, &D::heat_capacity_j_k).optional();
    let empty_p = Pl::default();
    let p = r.plates.as_ref().unwrap_or(&empty_p);
    let pnum = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), p.value(k), k);
    let plate_t = pnum(ck, &Pl::thickness_m).or(Pl::thickness_m.default_num());
    let plate_capacity = pnum(ck, &Pl::heat_capacity_j_k).optional();

    let (ri, ro) = (ri?, ro?);
    if !(ri > 0.0 && ro > ri) {
        return None;
    }
    let (steel, paper) = (ThermalProperties::STEEL, ThermalProperties::PAPER_LINING);
    // MODEL.md section 9: a body's two faces exchange heat with the oil
    let g = conductance_per_area? * 2.0 * PI * (ro * ro - ri * ri);
    let disc = ThermalBody {
        capacity_j_k: disc_capacity?.map_or_else(
            || {
                // a steel core and two linings, their capacities added (MODEL.md section 9)
                Some(
                    steel.annulus_heat_capacity_j_k(ri, ro, core?)
                        + 2.0 * paper.annulus_heat_capacity_j_k(ri, ro, lining?),
                )
            },
            Some,
        )?,
        face_effusivity: paper.effusivity(),
        conductance_w_k: g,
    };
    let plate = ThermalBody {
        capacity_j_k: plate_capacity?.map_or_else(
            || Some(steel.annulus_heat_capacity_j_k(ri, ro, plate_t?)),
            Some,
        )?,
        face_effusivity: steel.effusivity(),
        conductance_w_k: g,
    };
    let initial = initial?;
    let model = ThermalModel {
        viscosity: viscosity?,
        reference_k: reference?.unwrap_or(initial),
        gap_viscosity: gap_viscosity?,
        step_s: step?,
        initial_k: initial,
        discs: vec![disc; n_discs],
        plates: vec![plate; n_plates],
        oil: ThermalOil {
            capacity_j_k: oil_capacity?,
            flow_capacity_w_k: cooler?,
            inlet_k: inlet?.unwrap_or(initial),
        },
        friction: friction?,
    };
    time_constant_resolvable(ck, &model).then_some(model)
}

/// Whether the fastest time constant of `model` is at least
/// [`clutchpack_model::thermal::MIN_TIME_CONSTANT_S`] (docs/DECISIONS.md, "Plausibility
/// bounds"; issue 48): else reported at the capacity that sets it, with what it would need.
fn time_constant_resolvable(ck: &mut Checker, model: &ThermalModel) -> bool {
    let (tau, which) = model.fastest_time_constant_s();
    if tau >= MIN_TIME_CONSTANT_S {
        return true;
    }
    let (key, capacity, conductance) = match which {
        FastestBody::Disc => (
            &D::heat_capacity_j_k,
            model.discs[0].capacity_j_k,
            model.discs[0].conductance_w_k,
        ),
        FastestBody::Plate => (
            &Pl::heat_capacity_j_k,
            model.plates[0].capacity_j_k,
            model.plates[0].conductance_w_k,
        ),
        FastestBody::Oil => (
            &O::heat_capacity_j_k,
            model.oil.capacity_j_k,
            capacity_rate_sum(model),
        ),
    };
    ck.report(
        key.rel(),
        Some(fmt_num(capacity)),
        format!(
            "with {} W/K to the oil{} its time constant is {} s, under the {} s that the \
             thermal window's sub-steps need (plausibility bound): a capacity of at least {} \
             J/K, or less convection{}",
            fmt_num(conductance),
            if which == FastestBody::Oil {
                " and the cooler"
            } else {
                ""
            },
            fmt_num(tau),
            fmt_num(MIN_TIME_CONSTANT_S),
            fmt_num(MIN_TIME_CONSTANT_S * conductance),
            if which == FastestBody::Oil {
                " or a smaller cooler"
            } else {
                ""
            },
        ),
    );
    false
}

/// The oil's conductance to everything it exchanges heat with, W/K: every body's and the
/// cooler's capacity rate.
fn capacity_rate_sum(model: &ThermalModel) -> f64 {
    model
        .discs
        .iter()
        .chain(&model.plates)
        .map(|b| b.conductance_w_k)
        .sum::<f64>()
        + model.oil.flow_capacity_w_k
}

/// `[thermal.friction]`: the faces' `mu(v, T)` (MODEL.md section 9), fitted once here so that
/// a scene that validates runs; `Some(None)` without the table, `None` when it is bad (the
/// problem reported at the key and value the map refuses, with its rule).
fn friction(ck: &mut Checker, f: Option<&Fr>) -> Option<Option<FrictionTable>> {
    let Some(f) = f else { return Some(None) };
    let hint = "required with [thermal.friction]; set it there";
    let speeds = ck
        .numbers(&Fr::speeds_m_s.rel(), f.value(&Fr::speeds_m_s), None)
        .required(ck, &Fr::speeds_m_s.rel(), hint);
    let temps = ck
        .numbers(
            &Fr::temperatures_k.rel(),
            f.value(&Fr::temperatures_k),
            None,
        )
        .required(ck, &Fr::temperatures_k.rel(), hint);
    let mu = ck
        .number_rows(&Fr::mu.rel(), f.value(&Fr::mu))
        .required(ck, &Fr::mu.rel(), hint);
    let table = FrictionTable {
        speeds_m_s: speeds?,
        temperatures_k: temps?,
        mu: mu?,
    };
    let err = match table.fit() {
        Ok(_) => return Some(Some(table)),
        Err(e) => e,
    };
    let axis_key = |axis: &str| {
        if axis == "speed" {
            Fr::speeds_m_s.rel()
        } else {
            Fr::temperatures_k.rel()
        }
    };
    let mu_key = Fr::mu.rel();
    let (key, value, rule) = match &err {
        FrictionMapError::TooShort { axis, len } => (
            axis_key(axis),
            Some(format!("[...{len} values]")),
            "must have at least 2 values".to_string(),
        ),
        FrictionMapError::AxisValue {
            axis,
            index,
            value,
            expected,
            ..
        } => (
            format!("{}[{index}]", axis_key(axis)),
            Some(fmt_num(*value)),
            format!("must be finite and {expected}"),
        ),
        FrictionMapError::AxisNotIncreasing {
            axis,
            index,
            value,
            previous,
            ..
        } => (
            format!("{}[{index}]", axis_key(axis)),
            Some(fmt_num(*value)),
            format!(
                "must exceed the value before it ({}): the values must strictly increase",
                fmt_num(*previous)
            ),
        ),
        FrictionMapError::RowCount(rows, speeds) => (
            mu_key.clone(),
            Some(format!("[...{rows} rows]")),
            format!(
                "must have one row per entry of {} ({speeds})",
                Fr::speeds_m_s.rel()
            ),
        ),
        FrictionMapError::RowLength { row, len, expected } => (
            format!("{mu_key}[{row}]"),
            Some(format!("[...{len} values]")),
            format!(
                "must have one value per entry of {} ({expected})",
                Fr::temperatures_k.rel()
            ),
        ),
        FrictionMapError::Mu {
            speed_index,
            temperature_index,
            value,
        } => (
            format!("{mu_key}[{speed_index}][{temperature_index}]"),
            Some(fmt_num(*value)),
            "must be finite and >= 0 (a friction coefficient)".to_string(),
        ),
    };
    ck.report(key, value, rule);
    None
}

/// `[thermal.convection]`: the conductance per area of a face, W/(m^2 K).
fn convection(
    ck: &mut Checker,
    c: Option<&Cv>,
    lambda: f64,
    gap_default: Option<f64>,
) -> Option<f64> {
    let empty = Cv::default();
    let c = c.unwrap_or(&empty);
    let kinds = [
        Convection::Adiabatic,
        Convection::Given,
        Convection::LaminarGap,
    ];
    let kind = ck
        .choice(&Cv::kind.rel(), c.kind.as_ref(), &Cv::kind, &kinds)
        .or(kinds[Cv::kind.default_choice()])?;
    let num = |ck: &mut Checker, k: &Key| ck.num(&k.rel(), c.value(k), k);
    let only = |ck: &mut Checker, k: &Key, rule: &str| ck.not_allowed(&k.rel(), c.value(k), rule);
    match kind {
        Convection::Adiabatic => {
            only(
                ck,
                &Cv::h_w_m2_k,
                "only allowed with thermal.convection.kind = \"given\"",
            );
            only(
                ck,
                &Cv::gap_m,
                "only allowed with thermal.convection.kind = \"laminar_gap\"",
            );
            Some(0.0)
        }
        Convection::Given => {
            only(
                ck,
                &Cv::gap_m,
                "only allowed with thermal.convection.kind = \"laminar_gap\"",
            );
            num(ck, &Cv::h_w_m2_k).required(
                ck,
                &Cv::h_w_m2_k.rel(),
                "required with thermal.convection.kind = \"given\"; set it in [thermal.convection]",
            )
        }
        Convection::LaminarGap => {
            only(
                ck,
                &Cv::h_w_m2_k,
                "only allowed with thermal.convection.kind = \"given\"",
            );
            let gap = match num(ck, &Cv::gap_m).optional()? {
                Some(s) => s,
                None => match gap_default {
                    Some(s) if s > 0.0 => s,
                    _ => {
                        ck.report(
                            Cv::gap_m.rel(),
                            None,
                            "missing (required with thermal.convection.kind = \"laminar_gap\" \
                             when the scene has no stack.open_gap.gap_m; set it in \
                             [thermal.convection])",
                        );
                        return None;
                    }
                },
            };
            // VDI Heat Atlas Gb 7 eq 37, fully developed, both walls (MODEL.md section 9)
            Some(laminar_gap_h_w_m2_k(
                lambda,
                gap,
                GapHeating::BothWalls,
                None,
            ))
        }
    }
}

/// `thermal.oil`'s viscosity law, fitted once here so that a scene that validates runs.
fn viscosity(ck: &mut Checker, o: &O) -> Option<ViscosityLaw> {
    let names = [Law::Walther, Law::Vogel, Law::Table];
    let law = ck
        .choice(&O::law.rel(), o.law.as_ref(), &O::law, &names)
        .required(
            ck,
            &O::law.rel(),
            "required with [thermal]: \"walther\", \"vogel\" or \"table\"; set it in [thermal.oil]",
        );
    let temps = ck
        .numbers(&O::temperatures_k.rel(), o.temperatures_k.as_ref(), None)
        .required(
            ck,
            &O::temperatures_k.rel(),
            "required with [thermal]; set it in [thermal.oil]",
        );
    let law = law?;
    let (values_key, other) = match law {
        Law::Walther => (&O::kinematic_viscosities_m2_s, &O::viscosities_pa_s),
        Law::Vogel | Law::Table => (&O::viscosities_pa_s, &O::kinematic_viscosities_m2_s),
    };
    ck.not_allowed(
        &other.rel(),
        o.value(other),
        "not used by this thermal.oil.law",
    );
    if law != Law::Walther {
        ck.not_allowed(
            &O::density_kg_m3.rel(),
            o.value(&O::density_kg_m3),
            "only allowed with thermal.oil.law = \"walther\"",
        );
    }
    let density = ck
        .num(
            &O::density_kg_m3.rel(),
            o.value(&O::density_kg_m3),
            &O::density_kg_m3,
        )
        .or(O::density_kg_m3.default_num());
    let values = ck
        .numbers(&values_key.rel(), o.value(values_key), None)
        .required(
            ck,
            &values_key.rel(),
            "required for this thermal.oil.law; set it in [thermal.oil]",
        );
    let (temps, values, density) = (temps?, values?, density?);
    let count = match law {
        Law::Walther => Some(2),
        Law::Vogel => Some(3),
        Law::Table => None,
    };
    if let Some(n) = count {
        for (k, len) in [
            (&O::temperatures_k, temps.len()),
            (values_key, values.len()),
        ] {
            if len != n {
                ck.report(
                    k.rel(),
                    Some(format!("[...{len} values]")),
                    format!("must have exactly {n} values for this thermal.oil.law"),
                );
                return None;
            }
        }
    }
    let spec = match law {
        Law::Walther => ViscosityLaw::Walther {
            temperatures_k: [temps[0], temps[1]],
            kinematic_m2_s: [values[0], values[1]],
            density_kg_m3: density,
        },
        Law::Vogel => ViscosityLaw::Vogel {
            temperatures_k: [temps[0], temps[1], temps[2]],
            viscosities_pa_s: [values[0], values[1], values[2]],
        },
        Law::Table => ViscosityLaw::Table {
            temperatures_k: temps.clone(),
            viscosities_pa_s: values.clone(),
        },
    };
    match spec.fit() {
        Ok(_) => Some(spec),
        Err(e) => {
            // the key and value the law refuses, with its rule
            let (key, value) = match &e {
                ViscosityError::Temperature { index, value_k }
                | ViscosityError::TemperaturesNotIncreasing { index, value_k, .. } => (
                    format!("{}[{index}]", O::temperatures_k.rel()),
                    Some(fmt_num(*value_k)),
                ),
                ViscosityError::Viscosity { index, value, .. }
                | ViscosityError::ViscositiesNotDecreasing { index, value, .. } => (
                    format!("{}[{index}]", values_key.rel()),
                    Some(fmt_num(*value)),
                ),
                ViscosityError::Density(x) => (O::density_kg_m3.rel(), Some(fmt_num(*x))),
                ViscosityError::TooShort(_) => (O::temperatures_k.rel(), None),
                ViscosityError::LengthMismatch(..) => (values_key.rel(), None),
                ViscosityError::VogelNotConvex { .. } => (values_key.rel(), None),
            };
            let rule = match &e {
                ViscosityError::LengthMismatch(a, b) => format!(
                    "must have one value per entry of {} ({a}), has {b}",
                    O::temperatures_k.rel()
                ),
                e => e.to_string(),
            };
            ck.report(key, value, rule);
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{parse, Problem, SceneError};
    use clutchpack_model::thermal::{GapViscosity, ThermalProperties, ViscosityLaw};
    use std::f64::consts::PI;
    use std::path::Path;

    /// pack-6-engagement with `extra` appended.
    fn pack6(extra: &str) -> Result<crate::Scene, SceneError> {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let text = std::fs::read_to_string(root.join("pack-6-engagement.toml")).unwrap();
        parse(
            &format!("{text}\n{extra}"),
            "pack-6-engagement.toml",
            &root,
            &[],
        )
    }

    fn problems(extra: &str) -> Vec<Problem> {
        match pack6(extra) {
            Err(SceneError::Invalid { problems, .. }) => problems,
            other => panic!("expected problems, got {other:?}"),
        }
    }

    const OIL: &str = "[thermal.oil]\nlaw = \"walther\"\ntemperatures_k = [313.15, 373.15]\n\
                       kinematic_viscosities_m2_s = [29e-6, 6.5e-6]\nheat_capacity_j_k = 2000.0\n";

    /// Without `[thermal]` the scene is what it was (no thermal model); with it, the
    /// capacities and conductances by hand (1e-12 relative): a plate 7850 pi (Ro^2 - Ri^2)
    /// 1.8e-3 x 460, a disc a 1 mm core and two 0.5 mm linings, both faces at the laminar
    /// gap's h = 7.541 x 0.13 / (2 x 1 mm) over 2 pi (Ro^2 - Ri^2); T_ref defaults to the
    /// initial temperature, the inlet too.
    #[test]
    fn thermal_section_by_hand() {
        assert!(pack6("").unwrap().thermal.is_none());
        let s = pack6(&format!("[thermal]\ninitial_temperature_k = 353.15\n{OIL}")).unwrap();
        let th = s.thermal.unwrap();
        let (ri, ro) = (0.235f64, 0.290f64);
        let area = PI * (ro * ro - ri * ri);
        let plate = 7850.0 * area * 1.8e-3 * 460.0;
        let disc = 7850.0 * area * 1.0e-3 * 460.0 + 2.0 * 1100.0 * area * 0.5e-3 * 1600.0;
        let g = 7.541 * 0.13 / 2e-3 * 2.0 * area;
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        assert_eq!((th.discs.len(), th.plates.len()), (6, 7));
        assert!(
            rel(th.plates[0].capacity_j_k, plate) < 1e-12,
            "{:?}",
            th.plates[0]
        );
        assert!(
            rel(th.discs[0].capacity_j_k, disc) < 1e-12,
            "{:?}",
            th.discs[0]
        );
        assert!(rel(th.discs[0].conductance_w_k, g) < 1e-12);
        assert!(rel(th.plates[6].conductance_w_k, g) < 1e-12);
        assert_eq!(
            th.plates[0].face_effusivity,
            ThermalProperties::STEEL.effusivity()
        );
        assert_eq!(
            th.discs[0].face_effusivity,
            ThermalProperties::PAPER_LINING.effusivity()
        );
        assert_eq!(th.reference_k, 353.15);
        assert_eq!(th.oil.inlet_k, 353.15);
        assert_eq!(th.oil.flow_capacity_w_k, 0.0);
        assert_eq!(th.step_s, 1e-3);
        assert_eq!(th.gap_viscosity, GapViscosity::Absolute);
        assert!(matches!(th.viscosity, ViscosityLaw::Walther { .. }));
        assert!(th.viscosity.fit().is_ok());
    }

    /// Bad input names the key, the value and the rule, never panics.
    #[test]
    fn bad_thermal_input_is_named() {
        let has = |ps: &[Problem], key: &str, rule: &str| {
            assert!(
                ps.iter().any(|p| p.key == key && p.rule.contains(rule)),
                "no {key}: ...{rule}... in {ps:?}"
            )
        };
        let ps = problems(&format!("[thermal]\n{OIL}"));
        has(&ps, "thermal.initial_temperature_k", "missing");
        let ps = problems(&format!("[thermal]\ninitial_temperature_k = 20.0\n{OIL}"));
        has(&ps, "thermal.initial_temperature_k", "plausibility");
        // Walther takes two points
        let ps = problems(&format!(
            "[thermal]\ninitial_temperature_k = 353.15\n{}",
            OIL.replace("[313.15, 373.15]", "[313.15, 373.15, 393.15]")
        ));
        has(&ps, "thermal.oil.temperatures_k", "exactly 2");
        // viscosities rising with temperature
        let ps = problems(&format!(
            "[thermal]\ninitial_temperature_k = 353.15\n{}",
            OIL.replace("[29e-6, 6.5e-6]", "[6.5e-6, 29e-6]")
        ));
        has(&ps, "thermal.oil.kinematic_viscosities_m2_s[1]", "decrease");
        // Vogel through points whose ln(eta) is not convex
        let vogel = "[thermal.oil]\nlaw = \"vogel\"\ntemperatures_k = [300.0, 350.0, 400.0]\n\
                     viscosities_pa_s = [0.1, 0.09, 0.01]\nheat_capacity_j_k = 2000.0\n";
        let ps = problems(&format!(
            "[thermal]\ninitial_temperature_k = 353.15\n{vogel}"
        ));
        has(&ps, "thermal.oil.viscosities_pa_s", "Vogel");
        // a key of another law
        let ps = problems(&format!(
            "[thermal]\ninitial_temperature_k = 353.15\n{OIL}viscosities_pa_s = [1.0, 0.5]\n"
        ));
        has(&ps, "thermal.oil.viscosities_pa_s", "not used");
        // given convection without its h, and a laminar gap key with it
        let ps = problems(&format!(
            "[thermal]\ninitial_temperature_k = 353.15\n{OIL}[thermal.convection]\nkind = \"given\"\ngap_m = 1e-3\n"
        ));
        has(&ps, "thermal.convection.h_w_m2_k", "missing");
        has(&ps, "thermal.convection.gap_m", "only allowed");
        // the multirate scheme, which the multibody engine runs
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let text = std::fs::read_to_string(root.join("pack-6-engagement.toml")).unwrap();
        let set: crate::Override = "simulation.scheme=multirate".parse().unwrap();
        let r = parse(
            &format!("{text}\n[thermal]\ninitial_temperature_k = 353.15\n{OIL}"),
            "x.toml",
            &root,
            &[set],
        );
        // valid: the multibody engine runs it (the reference engine's refusal of the scheme
        // for a whole pack is the sdk's, as for every pack with a stack)
        assert!(r.is_ok(), "{r:?}");
    }

    /// A thermal scene runs on either engine: the one it or the command line asks for
    /// (pack-6-engagement asks for the multibody engine), else the reference engine for its
    /// torsional pack.
    #[test]
    fn thermal_scenes_run_on_both_engines() {
        use crate::EngineChoice;
        let s = pack6(&format!("[thermal]\ninitial_temperature_k = 353.15\n{OIL}")).unwrap();
        assert_eq!(s.engine(None, "x").unwrap(), EngineChoice::Multibody);
        assert_eq!(
            s.engine(Some(EngineChoice::Reference), "x").unwrap(),
            EngineChoice::Reference
        );
        let mut s = s;
        s.simulation.engine = None;
        assert_eq!(s.engine(None, "x").unwrap(), EngineChoice::Reference);
        assert_eq!(
            s.engine(Some(EngineChoice::Multibody), "x").unwrap(),
            EngineChoice::Multibody
        );
    }

    /// `[thermal.friction]`: a good table is the model's (its rows as given); every bad one
    /// is named at its key with the value and the rule, never a panic.
    #[test]
    fn friction_table_is_read_and_bad_ones_named() {
        let head = format!("[thermal]\ninitial_temperature_k = 353.15\n{OIL}");
        let table = |speeds: &str, temps: &str, mu: &str| {
            format!(
                "{head}[thermal.friction]\nspeeds_m_s = {speeds}\ntemperatures_k = {temps}\n\
                 mu = {mu}\n"
            )
        };
        let s = pack6(&table(
            "[0.0, 2.0]",
            "[313.15, 393.15]",
            "[[0.13, 0.11], [0.14, 0.12]]",
        ))
        .unwrap();
        let f = s.thermal.unwrap().friction.expect("the table");
        assert_eq!(f.speeds_m_s, vec![0.0, 2.0]);
        assert_eq!(f.temperatures_k, vec![313.15, 393.15]);
        assert_eq!(f.mu, vec![vec![0.13, 0.11], vec![0.14, 0.12]]);
        assert!(f.fit().is_ok());
        let has = |extra: String, key: &str, value: Option<&str>, rule: &str| {
            let ps = problems(&extra);
            assert!(
                ps.iter().any(|p| p.key == key
                    && p.rule.contains(rule)
                    && (value.is_none() || p.value.as_deref() == value)),
                "no {key} = {value:?}: ...{rule}... in {ps:?}"
            )
        };
        let mu2 = "[[0.13, 0.11], [0.14, 0.12]]";
        has(
            table("[0.0]", "[313.15, 393.15]", "[[0.13, 0.11]]"),
            "thermal.friction.speeds_m_s",
            None,
            "at least 2",
        );
        has(
            table("[-0.5, 2.0]", "[313.15, 393.15]", mu2),
            "thermal.friction.speeds_m_s[0]",
            Some("-0.5"),
            ">= 0",
        );
        has(
            table("[0.0, 2.0]", "[393.15, 313.15]", mu2),
            "thermal.friction.temperatures_k[1]",
            Some("313.15"),
            "strictly increase",
        );
        has(
            table("[0.0, 2.0]", "[313.15, 393.15]", "[[0.13, 0.11]]"),
            "thermal.friction.mu",
            None,
            "one row per entry of thermal.friction.speeds_m_s (2)",
        );
        has(
            table("[0.0, 2.0]", "[313.15, 393.15]", "[[0.13, 0.11], [0.14]]"),
            "thermal.friction.mu[1]",
            None,
            "one value per entry of thermal.friction.temperatures_k (2)",
        );
        has(
            table(
                "[0.0, 2.0]",
                "[313.15, 393.15]",
                "[[0.13, 0.11], [0.14, -0.02]]",
            ),
            "thermal.friction.mu[1][1]",
            Some("-0.02"),
            ">= 0",
        );
        has(
            table(
                "[0.0, 2.0]",
                "[313.15, 393.15]",
                "[[0.13, 0.11], [0.14, \"x\"]]",
            ),
            "thermal.friction.mu[1][1]",
            None,
            "must be a number",
        );
        has(
            table("[0.0, 2.0]", "[313.15, 393.15]", "0.1"),
            "thermal.friction.mu",
            Some("0.1"),
            "array of rows",
        );
        has(
            format!("{head}[thermal.friction]\nspeeds_m_s = [0.0, 1.0]\n"),
            "thermal.friction.temperatures_k",
            None,
            "missing",
        );
    }

    /// No stack: the bodies' annulus is unknown.
    #[test]
    fn thermal_needs_a_stack() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let text = std::fs::read_to_string(root.join("hu-table2.toml")).unwrap();
        let r = parse(
            &format!("{text}\n[thermal]\ninitial_temperature_k = 353.15\n{OIL}"),
            "hu-table2.toml",
            &root,
            &[],
        );
        match r {
            Err(SceneError::Invalid { problems, .. }) => assert!(
                problems
                    .iter()
                    .any(|p| p.key == "thermal" && p.rule.contains("[stack]")),
                "{problems:?}"
            ),
            other => panic!("{other:?}"),
        }
    }
}
