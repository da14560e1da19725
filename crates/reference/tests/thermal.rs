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

/// `[thermal.friction]` constant in slip speed and linear in temperature, `mu = 0.12 - 4e-4
/// (T - 353.15 K)` (0.12 at 80 deg C, 0.08 at 180 deg C), on pack-6-engagement with its gaps:
/// every clamped face reports the `mu` the table gives at its face's temperature (the hotter
/// of its two bodies) at the window before or after the sample (a sample at a window's end
/// may be taken either side of the swap), and every slipping face passes the torque `mu F
/// R_eff` with it. The check is not vacuous: the faces' `mu` spans what the plates' rise
/// gives. Measured (29 856 clamped face samples, 4 591 slipping): every `mu` within 1.4e-17
/// of the table's, every slipping torque exactly `mu F R_eff`; the faces' `mu` from 0.12 down
/// to 0.11543 (the hottest face +11.4 K at its peak; plate-1 ends +5.83 K); bounds 1e-14
/// and 1e-12, a few roundings.
#[test]
fn faces_take_the_tables_mu_at_their_temperature() {
    let scene = pack6(
        true,
        &format!(
            "[thermal]\ninitial_temperature_k = 353.15\n{OIL}[thermal.friction]\n\
             speeds_m_s = [0.0, 10.0]\ntemperatures_k = [353.15, 453.15]\n\
             mu = [[0.12, 0.08], [0.12, 0.08]]\n"
        ),
    );
    let nd = scene.pack.discs.len();
    let r_eff = scene.pack.stack.as_ref().unwrap().effective_radius_m();
    let (c, report) = run(&scene, 0.3);
    let report = report.unwrap();
    assert!(report.updates > 0);
    let table = |t: f64| 0.12 - 4e-4 * (t.clamp(353.15, 453.15) - 353.15);
    let face_mu = |temps: &[f64], m: usize| {
        let lo = temps[StackBody::at(m).body_index(nd)];
        let up = temps[StackBody::at(m + 1).body_index(nd)];
        table(lo.max(up))
    };
    let (mut worst_mu, mut worst_torque) = (0.0f64, 0.0f64);
    let (mut low, mut checked, mut slipping) = (f64::INFINITY, 0, 0);
    for (t, faces) in &c.interfaces {
        // the temperature records around t: the last before it and the first at or after
        let k = c.temperatures.partition_point(|(tr, _, _)| tr < t);
        let before = &c.temperatures[k.saturating_sub(1)].1;
        let after = &c.temperatures[k.min(c.temperatures.len() - 1)].1;
        for (m, f) in faces.iter().enumerate() {
            if f.clamp_n <= 0.0 {
                continue;
            }
            checked += 1;
            let off = (f.mu - face_mu(before, m))
                .abs()
                .min((f.mu - face_mu(after, m)).abs());
            worst_mu = worst_mu.max(off);
            low = low.min(f.mu);
            if !f.locked && f.slip_rad_s != 0.0 {
                slipping += 1;
                let want = f.mu * f.clamp_n * r_eff;
                worst_torque = worst_torque.max(rel(f.torque_n_m.abs(), want));
            }
        }
    }
    eprintln!(
        "mu(T): {checked} clamped samples ({slipping} slipping), worst mu {worst_mu:e}, worst \
         torque {worst_torque:e}, lowest mu {low}, plate-1 +{} K",
        report.final_k[nd] - 353.15
    );
    assert!(checked > 1000 && slipping > 100, "{checked} {slipping}");
    assert!(worst_mu < 1e-14, "worst mu {worst_mu:e}");
    assert!(worst_torque < 1e-12, "worst torque {worst_torque:e}");
    // the plates rise by several kelvin: mu falls by 4e-4 per kelvin
    assert!(low < 0.12 - 1e-3, "lowest mu {low}");
}

/// A `[thermal.friction]` table that is the scene's own `mu(v)` at every temperature (the
/// stack's friction as a table on the same speeds, every column alike) leaves the run as it
/// is without the table, bit for bit: the per-face curves are the stack's, no swap is made for
/// them, and the film and gaps follow the oil as before.
#[test]
fn a_table_equal_at_every_temperature_is_the_run_without_it() {
    let thermal = format!("[thermal]\ninitial_temperature_k = 353.15\n{OIL}");
    let as_table = |scene_extra: &str| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let text = std::fs::read_to_string(root.join("pack-6-engagement.toml")).unwrap();
        let from = text.find("[stack.friction]").unwrap();
        let to = text[from..].find("[stack.pressure]").unwrap() + from;
        let text = format!(
            "{}[stack.friction]\nkind = \"table\"\nslip_m_s = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0]\n\
             mu = [0.1, 0.1118, 0.119, 0.1259, 0.1295, 0.13]\n\n{}\n{thermal}{scene_extra}",
            &text[..from],
            &text[to..]
        );
        clutchpack_scene::parse(&text, "pack-6-engagement.toml", &root, &[]).unwrap()
    };
    let plain = as_table("");
    let mapped = as_table(
        "[thermal.friction]\nspeeds_m_s = [0.0, 0.25, 0.5, 1.0, 2.0, 4.0]\n\
         temperatures_k = [313.15, 453.15]\nmu = [[0.1, 0.1], [0.1118, 0.1118], \
         [0.119, 0.119], [0.1259, 0.1259], [0.1295, 0.1295], [0.13, 0.13]]\n",
    );
    assert!(mapped.thermal.as_ref().unwrap().friction.is_some());
    let (a, ra) = run(&plain, 0.3);
    let (b, rb) = run(&mapped, 0.3);
    let (ra, rb) = (ra.unwrap(), rb.unwrap());
    assert!(ra.friction_heat_j > 1e3, "{ra:?}");
    assert_eq!(ra, rb);
    assert_eq!(a.samples, b.samples);
    assert_eq!(a.impacts, b.impacts);
    assert_eq!(a.interfaces, b.interfaces);
    assert_eq!(a.temperatures, b.temperatures);
}
