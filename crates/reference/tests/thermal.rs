//! Thermal packs on the reference engine (issue 35, MODEL.md section 9): the closed forms a
//! run must meet. pack-6-engagement (its 6 discs rattle, then the piston clamps the 13
//! bodies and the faces slip until they lock) with a `[thermal]` section.

use clutchpack_model::checks::heat_j;
use clutchpack_model::thermal::{ThermalProperties, ThermalReport};
use clutchpack_model::{Collector, Engine, StackBody};
use clutchpack_reference::{ReferenceEngine, ReferenceOptions};
use clutchpack_scene::Scene;
use std::path::Path;

/// pack-6-engagement's text: with `[stack.open_gap]` removed when `gaps` is false, then
/// `thermal` appended (TOML tables, may be empty).
fn pack6(gaps: bool, thermal: &str) -> Scene {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let text = std::fs::read_to_string(root.join("pack-6-engagement.toml")).unwrap();
    let text = if gaps {
        text
    } else {
        let cut = text.find("[stack.open_gap]").expect("an open gap");
        text[..cut].to_string()
    };
    let text = format!("{text}\n{thermal}");
    clutchpack_scene::parse(&text, "pack-6-engagement.toml", &root, &[]).unwrap()
}

/// Runs `scene` for `duration_s` on the reference engine with its own settings.
fn run(scene: &Scene, duration_s: f64) -> (Collector, Option<ThermalReport>) {
    let sim = &scene.simulation;
    let mut engine = ReferenceEngine::new(
        scene.pack.clone(),
        ReferenceOptions {
            tolerance: sim.tolerance,
            max_step_s: sim.max_step_s,
            record_rate_hz: sim.record_rate_hz,
        },
    )
    .with_thermal(scene.thermal.clone());
    let mut c = Collector::default();
    let stats = engine.run(duration_s, &mut c).unwrap();
    (c, stats.thermal)
}

/// An ATF (issue 35's MB 236.14 fluid: 29 / 6.5 cSt at 40 / 100 deg C) by Walther.
const OIL: &str = "[thermal.oil]\nlaw = \"walther\"\ntemperatures_k = [313.15, 373.15]\n\
                   kinematic_viscosities_m2_s = [29e-6, 6.5e-6]\nheat_capacity_j_k = 2000.0\n";

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// The adiabatic engagement (no convection, no cooler, no open gaps: the faces' heat goes
/// to the bodies only, the teeth's to the oil): each body rises by its share of its faces'
/// heat (effusivity split per face, steel 0.953 against the paper lining) over its m c, the
/// heat per face read from the run's interface table; the heat generated is the heat stored
/// (no cooler). Measured: worst body 4.6e-13 relative, balance 1.2e-14 (38.8 kJ of face heat,
/// 38 J of teeth; plate-1 +5.95 K, disc-1 +0.70 K); bounds 1e-9, issue 35's, 4000 times the
/// rounding of 300 windows measured.
#[test]
fn adiabatic_engagement_raises_each_body_by_its_share() {
    let scene = pack6(
        false,
        &format!(
            "[thermal]\ninitial_temperature_k = 353.15\n[thermal.convection]\n\
             kind = \"adiabatic\"\n{OIL}"
        ),
    );
    let th = scene.thermal.clone().unwrap();
    let (c, report) = run(&scene, 0.3);
    let r = report.expect("a thermal report");
    let nd = scene.pack.discs.len();
    let n_if = 2 * nd;
    let q: Vec<f64> = (0..n_if).map(|m| heat_j(&c, m)).collect();
    let total: f64 = q.iter().sum();
    assert!(total > 1e3, "the engagement's heat: {total} J");
    let bodies: Vec<_> = th.discs.iter().chain(&th.plates).copied().collect();
    let mut expected = vec![0.0; bodies.len()];
    for (m, q_m) in q.iter().enumerate() {
        let (lo, up) = (
            StackBody::at(m).body_index(nd),
            StackBody::at(m + 1).body_index(nd),
        );
        let share =
            bodies[lo].face_effusivity / (bodies[lo].face_effusivity + bodies[up].face_effusivity);
        expected[lo] += share * q_m;
        expected[up] += (1.0 - share) * q_m;
    }
    let steel = ThermalProperties::STEEL.effusivity();
    let paper = ThermalProperties::PAPER_LINING.effusivity();
    assert!((steel / (steel + paper) - 0.95296).abs() < 1e-5);
    let mut worst: f64 = 0.0;
    for (b, body) in bodies.iter().enumerate() {
        let rise = r.final_k[b] - th.initial_k;
        let want = expected[b] / body.capacity_j_k;
        assert!(want > 0.0, "body {b} takes heat");
        worst = worst.max(rel(rise, want));
    }
    eprintln!(
        "adiabatic: {total} J of face heat, {} J of teeth; worst body {worst:e}; plate-1 +{} K, \
         disc-1 +{} K",
        r.impact_heat_j,
        r.final_k[nd] - th.initial_k,
        r.final_k[0] - th.initial_k
    );
    assert!(worst < 1e-9, "worst body {worst:e}");
    assert!(
        rel(r.friction_heat_j, total) < 1e-12,
        "{} vs {total}",
        r.friction_heat_j
    );
    assert_eq!(r.gap_heat_j, 0.0);
    assert!(
        r.impact_heat_j > 0.0,
        "the teeth dissipate: {} J",
        r.impact_heat_j
    );
    assert_eq!(r.cooler_j, 0.0);
    let balance = rel(r.accounted_j(), r.generated_j());
    eprintln!("balance {balance:e}");
    assert!(balance < 1e-9, "balance {balance:e}");
}

/// With the temperatures held at T_ref (capacities of 1e30 J/K: a window's rise of about
/// 1e-27 K is below half an ulp of 353 K, so T stays T_ref bit for bit) the film scale is
/// exactly 1 and the gaps keep the scene's viscosity ("scaled"): the thermal run is the
/// isothermal run bit for bit (samples, impacts and interfaces), and no parameter changed.
#[test]
fn film_scale_of_one_is_the_isothermal_run_bit_for_bit() {
    let iso = pack6(true, "");
    assert!(iso.thermal.is_none());
    let held = pack6(
        true,
        &format!(
            "[thermal]\ninitial_temperature_k = 353.15\ngap_viscosity = \"scaled\"\n\
             [thermal.discs]\nheat_capacity_j_k = 1e30\n[thermal.plates]\n\
             heat_capacity_j_k = 1e30\n{}",
            OIL.replace("heat_capacity_j_k = 2000.0", "heat_capacity_j_k = 1e30")
        ),
    );
    assert_eq!(held.pack, iso.pack);
    let (a, _) = run(&iso, 0.3);
    let (b, r) = run(&held, 0.3);
    let r = r.unwrap();
    assert_eq!(r.updates, 0);
    assert!(r.windows >= 299 && r.generated_j() > 1e3, "{r:?}");
    assert!(r.final_k.iter().all(|&t| t == 353.15) && r.oil_final_k == 353.15);
    assert_eq!(a.samples, b.samples);
    assert_eq!(a.impacts, b.impacts);
    assert_eq!(a.interfaces, b.interfaces);
    assert_eq!(a.contacts, b.contacts);
}
