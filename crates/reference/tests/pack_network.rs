//! A resolved pack as a coupling of a network (MODEL.md section 8; issue 34) against the pack
//! engine's own run of the same pack: a network of one pack between two inertias is the pack
//! scene with an inertial shaft and a drum, impact for impact.

use clutchpack_model::cases::{engaging_clutch, pack_as_network};
use clutchpack_model::{Collector, Engine, ImpactEvent, Observer, PackModel};
use clutchpack_reference::network::{run_network, NetworkOptions, NetworkSample};
use clutchpack_reference::{ReferenceEngine, ReferenceOptions};

#[derive(Default)]
struct Packs {
    impacts: Vec<(usize, ImpactEvent)>,
    samples: Vec<NetworkSample>,
}

impl Observer for Packs {
    fn pack_impact(&mut self, coupling: usize, e: &ImpactEvent) {
        self.impacts.push((coupling, *e));
    }
    fn network_sample(&mut self, s: &NetworkSample) {
        self.samples.push(s.clone());
    }
}

/// The pack engine's run of `pack` at tolerance `tol` for `duration` s: its impacts in the
/// order they opened, the shaft's speed at the end (rad/s) and the faces' heat (J).
fn pack_run(pack: &PackModel, duration: f64, tol: f64) -> (Vec<ImpactEvent>, f64, f64) {
    let mut c = Collector::default();
    let settings = ReferenceOptions {
        tolerance: tol,
        record_rate_hz: 1000.0,
        ..ReferenceOptions::default()
    };
    ReferenceEngine::new(pack.clone(), settings)
        .run(duration, &mut c)
        .expect("the pack runs");
    let heat = c
        .interfaces
        .last()
        .map_or(0.0, |(_, f)| f.iter().map(|f| f.dissipated_j).sum());
    let shaft = c.samples.last().expect("samples").shaft_speed_rad_s;
    (sorted(&c.impacts), shaft, heat)
}

/// The network's settings beside [`pack_run`]'s: tolerance `tol`, steps of at most 0.1 ms,
/// samples at 1 kHz.
fn network_options(tol: f64) -> NetworkOptions {
    NetworkOptions {
        tolerance: tol,
        max_step_s: 1e-4,
        record_rate_hz: 1000.0,
    }
}

/// `v` in the order the impacts opened (engines send them as they close).
fn sorted(v: &[ImpactEvent]) -> Vec<ImpactEvent> {
    let mut v = v.to_vec();
    v.sort_by(|a, b| a.t_on_s.total_cmp(&b.t_on_s));
    v
}

/// The worst onset difference (s) and relative peak difference of two runs' impacts that
/// opened before `until` s, asserting that they are the same impacts (body and flank).
fn worst(a: &[ImpactEvent], b: &[ImpactEvent], until: f64) -> (usize, f64, f64) {
    let early = |v: &[ImpactEvent]| {
        v.iter()
            .copied()
            .filter(|e| e.t_on_s < until)
            .collect::<Vec<_>>()
    };
    let (a, b) = (early(a), early(b));
    assert_eq!(a.len(), b.len());
    let (mut on, mut peak) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.disc, x.flank), (y.disc, y.flank), "{x:?} {y:?}");
        on = on.max((x.t_on_s - y.t_on_s).abs());
        peak = peak.max((x.peak_n - y.peak_n).abs() / x.peak_n.abs());
    }
    (a.len(), on, peak)
}

/// [`engaging_clutch`]: four discs on an inertial shaft and five plates on a drum rattle,
/// then from 20 ms the piston clamps the stack, the faces slip, stick and slip again under
/// the shaft's fluctuation, and the drum is pulled up towards the shaft's speed. The pack
/// engine's run (its monolithic scheme) and the network's (the same pack between the bodies
/// `shaft` and `drum`), both at tolerance 1e-10:
/// - before the piston pushes, the same impacts one by one (body, flank, onset, peak);
/// - through the engagement, where stick-slip under rattle makes the run as sensitive to the
///   step sequence as to the tolerance, the faces' heat and the shaft's final speed within
///   the scatter of the pack's own runs over tolerances 1e-9 to 1e-12;
/// - the network's energy balance closed with the pack's losses and bodies in it.
#[test]
fn one_pack_between_two_inertias_is_the_pack_scenes_run() {
    let pack = engaging_clutch();
    let (duration, tol) = (0.06, 1e-10);
    let (alone, shaft, heat) = pack_run(&pack, duration, tol);
    let (tighter, shaft_t, heat_t) = pack_run(&pack, duration, tol / 10.0);
    let net = pack_as_network(&pack).expect("an inertial shaft");
    let mut obs = Packs::default();
    let options = network_options(tol);
    let run = run_network(&net, duration, &options, &mut obs).expect("the network runs");
    let on_net = sorted(&obs.impacts.iter().map(|(_, e)| *e).collect::<Vec<_>>());
    let net_heat = run.heat_j[0];
    let net_shaft = run.last.speed_rad_s[0];
    println!(
        "impacts: pack {} (at tol / 10: {}), network {}",
        alone.len(),
        tighter.len(),
        on_net.len()
    );
    let (n, on, peak) = worst(&alone, &on_net, 0.02);
    let (_, on_t, peak_t) = worst(&alone, &tighter, 0.02);
    println!("before 20 ms, {n} impacts: network onset {on:e} s, peak {peak:e}; pack at tol / 10 {on_t:e} s, {peak_t:e}");
    println!("heat: pack {heat} J, at tol / 10 {heat_t} J, network {net_heat} J");
    println!("shaft at the end: pack {shaft}, at tol / 10 {shaft_t}, network {net_shaft} rad/s");
    let count = |v: &[ImpactEvent]| v.iter().filter(|e| e.t_on_s < 0.03).count();
    println!(
        "before 30 ms: pack {}, at tol / 10 {}, network {}",
        count(&alone),
        count(&tighter),
        count(&on_net)
    );
    let e = run.energy;
    println!("energy {e:?}, residual {} J", e.residual_j());
    assert!(n >= 40, "the pack rattles: {n} impacts before 20 ms");
    assert!(on <= 2e-7, "{on}");
    assert!(peak <= 3e-4, "{peak}");
    assert_eq!(count(&alone), count(&on_net));
    // measured: heat 0.89 % apart, the shaft 0.37 rad/s; the pack engine's own run scatters
    // as much with its tolerance (1e-9 ... 1e-12: heat 112.7 ... 114.6 J, 1.7 %; the shaft
    // 98.03 ... 98.45 rad/s), and the network's runs lie inside that scatter
    assert!(heat > 10.0);
    assert!((net_heat - heat).abs() <= 0.02 * heat, "{net_heat} {heat}");
    assert!((net_shaft - shaft).abs() <= 0.65, "{net_shaft} {shaft}");
    assert!(
        e.residual_j().abs() <= 1e-8 * e.drive_work_j.abs(),
        "{}",
        e.residual_j()
    );
}

/// The inertia phase of a dual-clutch power-on upshift (MODEL.md section 8) with both
/// clutches resolved packs ([`clutchpack_model::cases::wet_clutch`]: discs on the input
/// shafts, plates on the engine), against the closed form of the lumped test
/// (`tests/network.rs`, `dual_clutch_inertia_phase_matches_closed_form`): the off-going pack
/// open, the on-coming one clamped with a constant force, so that it slips with
/// `T_c = 2 N mu F R_eff`; the engine side's inertia is the engine's and every plate's (they
/// ride on its spline). The phase lasts `t_i = J dw / (T_c - T_e)`, the on-coming pack takes
/// `E_i = T_c dw t_i / 2`. Issue 34's bound is 1 %. Measured: the last face locks 8.3e-4
/// late (at 78.78 ms: the faces lock, break and lock again over 1.1 ms while the discs and
/// plates rattle at the synchronisation, 514 tooth impacts in all), the heat 1.7e-3 low;
/// asserted 2e-3 and 4e-3. The lumped shift agrees to 3e-6: the rest is the packs' rattle.
#[test]
fn dual_clutch_shift_with_resolved_packs_matches_closed_form() {
    use clutchpack_model::cases::wet_clutch;
    use clutchpack_model::network::*;
    let (j_e, t_e, r1, r2, w_out) = (0.25, 200.0, 3.5, 2.1, 40.0);
    let (n1, n2, clamp) = (4, 5, 4700.0);
    let body = |name: &str, j: f64, w: f64, drive: Option<Signal>| Body {
        name: name.into(),
        inertia_kg_m2: j,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: w,
        motion: Motion::Free,
        drive,
        firing: None,
        road_load: None,
    };
    let (k1, k2) = (wet_clutch(n1, 0.0), wet_clutch(n2, clamp));
    let stack = k2.stack.as_ref().unwrap();
    let t_c = 2.0 * n2 as f64 * 0.1 * clamp * stack.effective_radius_m();
    let plates: f64 = k1
        .plates
        .iter()
        .chain(&k2.plates)
        .map(|p| p.inertia_kg_m2)
        .sum();
    let pack = |name: &str, a: usize, p: PackModel| Coupling {
        name: name.into(),
        a,
        b: 0,
        kind: CouplingKind::Pack(Box::new(p)),
    };
    let gear = |name: &str, a: usize, ratio: f64| Coupling {
        name: name.into(),
        a,
        b: 3,
        kind: CouplingKind::ideal_gear(ratio),
    };
    let net = Network {
        pack_thermal: Default::default(),
        bodies: vec![
            body("engine", j_e, r1 * w_out, Some(Signal::Constant(t_e))),
            body("shaft-1", 0.02, r1 * w_out, None),
            body("shaft-2", 0.02, r2 * w_out, None),
            body("vehicle", 1e6, w_out, None),
        ],
        couplings: vec![
            pack("K1", 1, k1),
            pack("K2", 2, k2),
            gear("gear-1", 1, r1),
            gear("gear-2", 2, r2),
        ],
    };
    #[derive(Default)]
    struct Faces(Vec<(usize, f64, usize, usize)>, usize);
    impl Observer for Faces {
        fn pack_faces(&mut self, k: usize, t: f64, locked: usize, _c: usize, faces: usize) {
            self.0.push((k, t, locked, faces));
        }
        fn pack_impact(&mut self, _k: usize, _e: &ImpactEvent) {
            self.1 += 1;
        }
    }
    let mut obs = Faces::default();
    let run = run_network(&net, 0.12, &NetworkOptions::default(), &mut obs).unwrap();
    let dw = r1 * w_out * (1.0 - r2 / r1);
    let t_i = (j_e + plates) * dw / (t_c - t_e);
    let e_i = t_c * dw * t_i / 2.0;
    let lock = obs
        .0
        .iter()
        .find(|(k, t, locked, faces)| *k == 1 && *t > 0.0 && locked == faces)
        .expect("the on-coming pack locks")
        .1;
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    println!(
        "T_c {t_c} N m; lock at {lock} s (closed form {t_i}, {:e}), heat {} J (closed form {e_i}, {:e}); {} impacts, {} steps",
        rel(lock, t_i),
        run.heat_j[1],
        rel(run.heat_j[1], e_i),
        obs.1,
        run.steps
    );
    assert!(rel(lock, t_i) < 2e-3);
    assert!(rel(run.heat_j[1], e_i) < 4e-3);
    assert!(run.energy.residual_j().abs() < 1e-8 * run.energy.drive_work_j);
}

/// An open brake on an inertial shaft ([`clutchpack_model::cases::staggered_brake`]`(4)` with
/// the shaft of `staggered_inertial`: four discs out of step, five plates on the fixed
/// housing, the open stack's oil gaps between them) as a network of the shaft and the fixed
/// housing. Measured: the 36 impacts of the first 15 ms within 5.6e-9 s and 2.7e-5 of their
/// peaks (asserted 2e-8 s and 1e-4); after that the discs' rattle against the inertial shaft
/// grows as sensitive to the steps as to the tolerance (the pack's own run at 1e-10 and 1e-11
/// ends 0.30 rad/s apart), and the network ends 0.31 rad/s from the pack's run at 1e-10 and
/// 0.017 from the one at 1e-11 (asserted 0.5), its gaps' heat 9.3e-5 from it (the pack's own
/// runs 1.1e-4 apart; asserted 1e-3); the energy balance closes with the gaps' heat in the
/// pack's losses.
#[test]
fn an_open_brake_on_a_network_is_the_pack_run_impact_for_impact() {
    use clutchpack_model::cases::{staggered_brake, staggered_inertial};
    let mut pack = staggered_brake(4);
    pack.shaft = staggered_inertial(4).shaft;
    let (duration, tol) = (0.06, 1e-10);
    let (alone, shaft, heat) = pack_run(&pack, duration, tol);
    let net = pack_as_network(&pack).expect("an inertial shaft");
    assert!(net.bodies[1].is_fixed(), "the plates on the housing");
    let mut obs = Packs::default();
    let options = network_options(tol);
    let run = run_network(&net, duration, &options, &mut obs).expect("the network runs");
    let on_net = sorted(&obs.impacts.iter().map(|(_, e)| *e).collect::<Vec<_>>());
    let (n, on, peak) = worst(&alone, &on_net, 0.015);
    let (tighter, tighter_shaft, tighter_heat) = pack_run(&pack, duration, tol / 10.0);
    let e = run.energy;
    println!(
        "pack at tol / 10: {} impacts, shaft {tighter_shaft} rad/s, heat {tighter_heat} J",
        tighter.len()
    );
    println!(
        "open brake: {n} impacts, worst onset {on:e} s, peak {peak:e}; shaft {shaft} / {} rad/s; gaps' heat {heat} / {} J; balance {:e} J",
        run.last.speed_rad_s[0],
        run.heat_j[0],
        e.residual_j()
    );
    assert!(n >= 30, "{n}");
    assert!(on <= 2e-8, "{on}");
    assert!(peak <= 1e-4, "{peak}");
    assert!((run.last.speed_rad_s[0] - shaft).abs() <= 0.5, "{shaft}");
    assert!(
        (run.heat_j[0] - heat).abs() <= 1e-3 * heat,
        "{} {heat}",
        run.heat_j[0]
    );
    assert!(e.residual_j().abs() <= 1e-8 * e.drive_work_j.abs().max(e.pack_loss_j));
}
