//! The reference engine on lumped driveline networks (MODEL.md section 8) against Modelica's
//! published reference results and closed forms.

// The reference values are quoted digit for digit as the reference file prints them.
#![allow(clippy::excessive_precision)]

use clutchpack_model::cases;
use clutchpack_model::network::{ClutchMode, NetworkSession};
use clutchpack_model::{ImpactEvent, NullObserver, Observer};
use clutchpack_reference::network::{run_network, ClutchEvent, NetworkOptions, NetworkSample};

#[derive(Default)]
struct Events(Vec<ClutchEvent>, Vec<NetworkSample>, Vec<ImpactEvent>);

impl Observer for Events {
    fn mesh_impact(&mut self, e: &ImpactEvent) {
        self.2.push(*e);
    }
    fn clutch_event(&mut self, e: &ClutchEvent) {
        self.0.push(*e);
    }
    fn network_sample(&mut self, s: &NetworkSample) {
        self.1.push(s.clone());
    }
}

/// Modelica's `Rotational.Examples.CoupledClutches` against its reference results: the
/// MAP-LIB reference results of the Modelica Standard Library,
/// `Modelica/Mechanics/Rotational/Examples/CoupledClutches/CoupledClutches.csv` of
/// github.com/modelica/MAP-LIB_ReferenceResults (Dymola 2020x, DASSL at tolerance 1e-6,
/// "Reg test MSL v4.0.0-rc.1"; its event rows give the instants below, its last row the speeds
/// at 1.5 s: `J1.w`, and the others through `clutchN.w_rel = w_b - w_a`). Every mode change
/// within 1 ms and every speed at 1.5 s within 1e-3 relative (issue 34's bounds). Measured:
/// the events within 4.1e-6 s and the speeds within 8.3e-6 relative, which is the reference's
/// own error (DASSL at 1e-6): this engine at tolerance 1e-9 and 1e-12 agrees with itself to
/// 1e-13 s and 2e-9 rad/s. Asserted: 2e-5 s and 5e-5 (about 5 times what was measured).
#[test]
fn coupled_clutches_match_modelica_reference_results() {
    let net = cases::coupled_clutches();
    let mut obs = Events::default();
    let run = run_network(&net, 1.5, &NetworkOptions::default(), &mut obs).unwrap();
    use ClutchMode::*;
    // (t, clutch, mode after) from the reference's mode columns
    let reference = [
        (0.4, 1, Slipping(-1)),
        (0.709_621_463_832_881_3, 1, Locked),
        (0.791_658_284_320_250_1, 0, Locked),
        (0.831_108_506_270_335_1, 0, Slipping(-1)),
        (0.9, 2, Slipping(-1)),
        (0.906_849_137_544_382_3, 0, Locked),
        (1.000_295_860_113_868_3, 0, Slipping(-1)),
        (1.143_969_630_433_705_5, 2, Locked),
        (1.25, 0, Free),
    ];
    let ours: Vec<&ClutchEvent> = obs.0.iter().filter(|e| e.t_s > 0.0).collect();
    for e in &ours {
        println!(
            "{:.9} clutch{} {:?} -> {:?}",
            e.t_s,
            e.coupling + 1,
            e.from,
            e.to
        );
    }
    assert_eq!(ours.len(), reference.len(), "{ours:?}");
    let mut worst: f64 = 0.0;
    for (e, (t, k, mode)) in ours.iter().zip(reference) {
        assert_eq!((e.coupling, e.to), (k, mode), "at {t} s");
        worst = worst.max((e.t_s - t).abs());
    }
    println!("largest difference of the event times: {worst:e} s");
    assert!(worst < 2e-5, "{worst}");
    let j1 = 3.247_034_565_240_657_1;
    let j2 = j1 - 0.783_826_964_342_972_17;
    let j3 = j2 + 6.189_601_746_610_612_5e-16;
    let j4 = j3 + 7.973_578_952_751_563_6e-12;
    let w = &run.last.speed_rad_s;
    let mut worst_w: f64 = 0.0;
    for (ours, theirs) in w.iter().zip([j1, j2, j3, j4]) {
        worst_w = worst_w.max((ours - theirs).abs() / theirs.abs());
    }
    println!("speeds at 1.5 s {w:?}, largest relative difference {worst_w:e}");
    assert!(worst_w < 5e-5, "{worst_w}");
    // our own convergence: the same run at a 1000 times tighter tolerance
    let mut fine = Events::default();
    let tight = NetworkOptions {
        tolerance: 1e-12,
        ..NetworkOptions::default()
    };
    let run_fine = run_network(&net, 1.5, &tight, &mut fine).unwrap();
    let mut self_t: f64 = 0.0;
    for (a, b) in obs.0.iter().zip(&fine.0) {
        self_t = self_t.max((a.t_s - b.t_s).abs());
    }
    let self_w = (run.last.speed_rad_s[1] - run_fine.last.speed_rad_s[1]).abs();
    println!(
        "tolerance 1e-9 against 1e-12: events within {self_t:e} s, J2 within {self_w:e} rad/s"
    );
    assert!(self_t < 1e-8 && self_w < 1e-7, "{self_t} {self_w}");
    let e = run.energy;
    println!("{e:?} residual {:e}", e.residual_j());
    assert!(e.residual_j().abs() < 1e-6 * e.drive_work_j.abs().max(e.clutch_heat_j));
}

/// The inertia phase of a dual-clutch power-on upshift (MODEL.md section 8, closed form): an
/// engine `J_e` at `w_e = r1 w_out` with a constant torque `T_e`, the off-going clutch open,
/// the on-coming clutch slipping with a constant torque `T_c > T_e`, the output held by a
/// vehicle of 1e6 kg m^2. The slip at the start is `dw = w_e (1 - r2 / r1)`; the phase lasts
/// `t_i = J_e dw / (T_c - T_e)`; the on-coming clutch takes `E_i = T_c dw t_i / 2`; the output
/// torque is `r2 T_c` during it and steps by `-r2 (T_c - T_e)` at lock. Issue 34's bound is
/// 0.1 %; measured within 3e-6 (the vehicle's speed moves by 2e-6 relative, which the closed
/// form holds fixed); asserted 3e-5.
#[test]
fn dual_clutch_inertia_phase_matches_closed_form() {
    use clutchpack_model::network::*;
    let (j_e, t_e, t_c, r1, r2, w_out) = (0.25, 200.0, 400.0, 3.5, 2.1, 40.0);
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
    let clutch = |name: &str, b: usize, force: f64| Coupling {
        name: name.into(),
        a: 0,
        b,
        kind: CouplingKind::Clutch(LumpedClutch {
            mu_table: vec![(0.0, 0.1)],
            peak: 1.0,
            cgeo_m: 0.2,
            fn_max_n: 20_000.0,
            force: Signal::Constant(force),
            one_way: false,
        }),
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
            clutch("clutch-1", 1, 0.0),
            clutch("clutch-2", 2, 1.0),
            gear("gear-1", 1, r1),
            gear("gear-2", 2, r2),
        ],
    };
    let mut obs = Events::default();
    let run = run_network(&net, 0.1, &NetworkOptions::default(), &mut obs).unwrap();
    let dw = r1 * w_out * (1.0 - r2 / r1);
    let t_i = j_e * dw / (t_c - t_e);
    let e_i = t_c * dw * t_i / 2.0;
    let lock = obs
        .0
        .iter()
        .find(|e| e.coupling == 1 && e.to == ClutchMode::Locked)
        .expect("the on-coming clutch locks");
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    println!(
        "lock at {} s (closed form {t_i}), heat {} J (closed form {e_i})",
        lock.t_s, run.heat_j[1]
    );
    assert!(rel(lock.t_s, t_i) < 3e-5);
    assert!(rel(run.heat_j[1], e_i) < 3e-5);
    // the output torque: gear-2 puts -r2 lambda on the vehicle
    let output = |t: f64| {
        let s = obs
            .1
            .iter()
            .min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()))
            .unwrap();
        -r2 * s.torque_n_m[3]
    };
    let (before, after) = (output(t_i - 2e-3), output(t_i + 2e-3));
    println!("output torque {before} N m before the lock, {after} N m after");
    assert!(rel(before, r2 * t_c) < 3e-5);
    assert!(rel(after - before, -r2 * (t_c - t_e)) < 3e-5);
    assert!(run.energy.residual_j().abs() < 1e-9 * run.energy.drive_work_j);
}

/// A free impact across a resolved gear mesh (MODEL.md section 8): a pinion closing its
/// backlash at `v0` on a wheel at rest, dry Hertz law without loss. The peak force per pair is
/// section 4's closed form `K^(2/5) (5/4 m_eff v0^2)^(3/5)` with
/// `m_eff = 1 / (Rb_a^2 / J_a + Rb_b^2 / J_b)`, the contact lasts `2.9433 s_max / v0`, the
/// rebound speed is `v0` and the mesh does no net work. Measured at the default tolerance
/// 1e-9: the peak within 3.5e-8 (3.9e-10 at 1e-11: it converges), the duration within 6e-9,
/// the mesh's net work 3.1e-8 of the kinetic energy, the balance 5e-10 J; asserted 2e-7,
/// 1e-7, 1e-7 and 5e-9 J.
#[test]
fn free_impact_across_a_gear_mesh_matches_closed_form() {
    use clutchpack_model::network::*;
    let (j_a, j_b, v0) = (0.02, 0.5, 0.3);
    let g = GearMesh {
        initial_offset_m: 0.5e-4 - 1e-7,
        ..cases::dry_gear_mesh(false)
    };
    let body = |name: &str, j: f64, w: f64| Body {
        name: name.into(),
        inertia_kg_m2: j,
        drag_n_m_s_rad: 0.0,
        initial_speed_rad_s: w,
        motion: Motion::Free,
        drive: None,
        firing: None,
        road_load: None,
    };
    let net = Network {
        pack_thermal: Default::default(),
        bodies: vec![body("pinion", j_a, v0 / 0.03), body("wheel", j_b, 0.0)],
        couplings: vec![Coupling {
            name: "mesh".into(),
            a: 0,
            b: 1,
            kind: CouplingKind::GearMesh(g.clone()),
        }],
    };
    let mut obs = Events::default();
    // the rebound crosses the backlash in 0.33 ms: stop before the other flank
    let run = run_network(&net, 1.2e-3, &NetworkOptions::default(), &mut obs).unwrap();
    assert_eq!(obs.2.len(), 1, "{:?}", obs.2);
    let e = obs.2[0];
    let k = g.law.hertz.coefficient();
    let m_eff = g.effective_mass_kg(j_a, j_b);
    let peak = clutchpack_model::free_impact_peak_n(k, m_eff, v0);
    let duration = clutchpack_model::free_impact_duration_s(k, m_eff, v0);
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    println!(
        "peak {} N (closed form {peak}), duration {} s (closed form {duration}), closing at {} m/s",
        e.peak_n,
        e.t_off_s - e.t_on_s,
        e.v_on_m_s
    );
    assert!(e.peak_n < 0.0, "the pinion leads: negative");
    assert!(rel(-e.peak_n, peak) < 2e-7, "{}", rel(-e.peak_n, peak));
    assert!(
        rel(e.t_off_s - e.t_on_s, duration) < 1e-7,
        "{}",
        rel(e.t_off_s - e.t_on_s, duration)
    );
    // the rebound: the line of action's speed reversed
    let w = &run.last.speed_rad_s;
    let (_, v) = g.displacement((0.0, 0.0), (w[0], w[1]));
    assert!(rel(-v, v0) < 1e-7, "rebound {v}");
    println!(
        "mesh work {} J of 1 J kinetic, residual {} J",
        run.energy.mesh_work_j,
        run.energy.residual_j()
    );
    assert!(run.energy.mesh_work_j.abs() < 1e-7 * 0.5 * j_a * (v0 / 0.03f64).powi(2));
    assert!(run.energy.residual_j().abs() < 5e-9);
}

/// A spring-damper between two free inertias released from a twist (MODEL.md section 8): the
/// twist follows the damped oscillator's closed form
/// `q(t) = q0 e^(-zeta wn t) (cos wd t + zeta wn / wd sin wd t)` with
/// `wn^2 = k (1/J_a + 1/J_b)` and `2 zeta wn = d (1/J_a + 1/J_b)`, and the energy closes:
/// the kinetic and spring energies' change equals the damper's loss. Measured at the default
/// tolerance: the twist (from the bodies' angles) within 3.3e-8 of q0 after 0.4 s (about 8
/// periods), the balance to 3.1e-8 J of the 0.4 J stored; asserted 1e-7 and 1e-7 J.
#[test]
fn spring_damper_rings_down_as_the_closed_form() {
    let net = cases::spring_ring_down();
    let q0 = cases::RING_DOWN_TWIST_RAD;
    let t_end = 0.4;
    let run = run_network(&net, t_end, &NetworkOptions::default(), &mut NullObserver).unwrap();
    let q = cases::spring_ring_down_twist_rad(t_end);
    let a = &run.last.angle_rad;
    let twist = a[0] - a[1] + q0;
    let err = (twist - q).abs() / q0;
    println!(
        "twist {twist} rad against {q} rad: {err:e} of q0; balance {:e} J",
        run.energy.residual_j()
    );
    assert!(err < 1e-7, "{err}");
    assert!(run.energy.residual_j().abs() < 1e-7);
    assert!(run.energy.damper_loss_j > 0.0);
}

/// An engine alone on its firing harmonics (`cases::firing_engine`): the firing torque is a
/// potential's slope in the crank angle, so `w(theta)^2 = w0^2 + 2 (V(0) - V(theta)) / J`
/// at every sample. Its speed swings by about +-5 rad/s twice a revolution; the angle-locked
/// torque keeps its period in angle, not in time. Measured over 0.5 s (8 revolutions, 16
/// firings): 2.6e-9 relative at the default tolerance 1e-9 and 2.7e-10 at 1e-11 (it
/// converges); asserted 1e-8 and 1e-9.
#[test]
fn firing_harmonics_follow_the_crank_angle_as_the_closed_form() {
    let net = cases::firing_engine();
    let b = &net.bodies[0];
    let f = b.firing.as_ref().unwrap();
    let w0 = b.initial_speed_rad_s;
    for (tolerance, bound) in [(1e-9, 1e-8), (1e-11, 1e-9)] {
        let mut obs = Events::default();
        let options = NetworkOptions {
            tolerance,
            ..Default::default()
        };
        let run = run_network(&net, 0.5, &options, &mut obs).unwrap();
        let (mut worst, mut lo, mut hi) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
        for s in &obs.1 {
            let theta = s.angle_rad[0];
            let w = (w0 * w0 + 2.0 * (f.potential_j(0.0) - f.potential_j(theta)) / b.inertia_kg_m2)
                .sqrt();
            worst = worst.max((s.speed_rad_s[0] / w - 1.0).abs());
            lo = lo.min(s.speed_rad_s[0]);
            hi = hi.max(s.speed_rad_s[0]);
        }
        println!(
        "{} samples, speed {lo:.3} .. {hi:.3} rad/s, worst {worst:.2e} against the closed form; \
         energy residual {:.2e} J",
        obs.1.len(),
        run.energy.residual_j()
    );
        assert!(obs.1.len() > 400);
        assert!(
            hi - lo > 4.0,
            "the firing torque moves the engine: {lo} .. {hi}"
        );
        assert!(worst < bound, "tolerance {tolerance:e}: {worst:e}");
    }
}

/// A network run advanced call by call (`NetworkStepper`), its clutch forces driven as inputs
/// (MODEL.md section 8, "Inputs"): CoupledClutches with clutch2's and clutch3's normal forces
/// set by the caller (0 N held from t = 0, 20 N set at 0.4 s and at 0.9 s, the scene's steps)
/// in calls of 10 ms gives the scene's own run: the same mode changes, each at the same instant
/// (measured 0 s; asserted 1e-12 s), the same speeds at 1.5 s (measured 3.6e-16 relative: the
/// step that passes 0.4 s is ended there from its dense output where the scene's run lands a
/// step on its breakpoint; asserted 1e-12, far inside the tolerance 1e-9; 1.7e-9 when every
/// call ended a step). The calls alone (nothing driven, the state read at every call as a
/// host reads it) are the whole run bit for bit (issue 46): its events, its steps, its speeds.
/// A negative or non-finite force, or a drive on a body the network does not have, is refused.
#[test]
fn a_network_advanced_in_calls_with_driven_clutch_forces_is_the_scenes_run() {
    use clutchpack_reference::network::{NetworkInput, NetworkStepper};
    let net = cases::coupled_clutches();
    let options = NetworkOptions {
        tolerance: 1e-9,
        max_step_s: 1e-3,
        record_rate_hz: 1000.0,
    };
    let mut whole = Events::default();
    let reference = run_network(&net, 1.5, &options, &mut whole).unwrap();
    let k = |name: &str| net.couplings.iter().position(|c| c.name == name).unwrap();
    let (c2, c3) = (k("clutch2"), k("clutch3"));
    for driven in [false, true] {
        let mut obs = Events::default();
        let mut run = NetworkStepper::new(&net, 1.5, &options, &mut obs).unwrap();
        if driven {
            for c in [c2, c3] {
                run.set_input(NetworkInput::ClutchForce(c), 0.0, &mut obs)
                    .unwrap();
            }
        }
        for call in 1..=150 {
            let t = f64::from(call) * 0.01;
            run.advance_to(t, &mut obs).unwrap();
            assert!(
                (run.time_s() - t).abs() < 1e-12,
                "{} against {t}",
                run.time_s()
            );
            if !driven {
                // a host reads the state at every call: it must not move the steps
                let now = run.sample_now();
                assert_eq!(now.t_s, run.time_s());
            }
            if driven && (call == 40 || call == 90) {
                let c = if call == 40 { c2 } else { c3 };
                run.set_input(NetworkInput::ClutchForce(c), 20.0, &mut obs)
                    .unwrap();
            }
        }
        let got = run.finish(&mut obs);
        assert_eq!(obs.0.len(), whole.0.len(), "driven {driven}: {:?}", obs.0);
        let worst_t = obs
            .0
            .iter()
            .zip(&whole.0)
            .map(|(a, b)| {
                assert_eq!((a.coupling, a.from, a.to), (b.coupling, b.from, b.to));
                (a.t_s - b.t_s).abs()
            })
            .fold(0.0, f64::max);
        let worst_w = got
            .last
            .speed_rad_s
            .iter()
            .zip(&reference.last.speed_rad_s)
            .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
            .fold(0.0, f64::max);
        println!("driven {driven}: events within {worst_t:.2e} s, speeds {worst_w:.2e}");
        assert!(worst_t < 1e-12 && worst_w < 1e-12);
        if !driven {
            assert_eq!(got.last, reference.last, "the state at the end");
            assert_eq!(got.steps, reference.steps, "the steps");
            assert_eq!(obs.0, whole.0, "the events");
            assert_eq!(obs.1, whole.1, "the samples");
        }
    }
    let mut obs = Events::default();
    let mut run = NetworkStepper::new(&net, 1.5, &options, &mut obs).unwrap();
    assert!(run
        .set_input(NetworkInput::ClutchForce(c2), -1.0, &mut obs)
        .is_err());
    assert!(run
        .set_input(NetworkInput::ClutchForce(c2), f64::NAN, &mut obs)
        .is_err());
    assert!(run
        .set_input(NetworkInput::Drive(99), 1.0, &mut obs)
        .is_err());
}

/// Issue 46: a call that ends inside a step leaves the step waiting, and what is read, set or
/// finished there is at the call's time. CoupledClutches advanced to 0.4005 s (inside a step:
/// its steps are up to 1 ms): the run stands at 0.4005 s, its state there read (the step's
/// dense output) without moving the steps (advanced on to 1.5 s it is the whole run, bit for
/// bit); a refused input (a negative force) ends the step there and leaves the state as it
/// was, bit for bit; finishing there ends the run at 0.4005 s with that state and heat, bit
/// for bit, its energy balance closing (measured 1.1e-13 J; asserted 1e-9 J, a whole run's
/// residual at this tolerance).
#[test]
fn a_run_read_set_or_finished_inside_a_step_stands_at_the_call() {
    use clutchpack_reference::network::{NetworkInput, NetworkStepper};
    let net = cases::coupled_clutches();
    let options = NetworkOptions::default();
    let c2 = net
        .couplings
        .iter()
        .position(|c| c.name == "clutch2")
        .unwrap();
    let t = 0.4005;
    let mut obs = Events::default();
    let mut run = NetworkStepper::new(&net, 1.5, &options, &mut obs).unwrap();
    run.advance_to(t, &mut obs).unwrap();
    assert_eq!(run.time_s(), t);
    let before = run.sample_now();
    assert_eq!(before.t_s, t);
    let mut on = run.clone();
    let mut on_obs = Events::default();
    on.advance_to(1.5, &mut on_obs).unwrap();
    let mut whole = Events::default();
    let reference = run_network(&net, 1.5, &options, &mut whole).unwrap();
    let on = on.finish(&mut on_obs);
    assert_eq!((on.last, on.steps), (reference.last, reference.steps));
    assert!(run
        .set_input(NetworkInput::ClutchForce(c2), -1.0, &mut obs)
        .is_err());
    assert_eq!(run.time_s(), t);
    let after = run.sample_now();
    assert_eq!(
        before, after,
        "the state at the call, kept by a refused input"
    );
    let heat = run.heat_j();
    let done = run.finish(&mut obs);
    assert_eq!(done.last.t_s, t);
    assert_eq!(done.last.speed_rad_s, before.speed_rad_s);
    assert_eq!(done.heat_j, heat);
    let residual = done.energy.residual_j();
    println!("energy residual {residual:.2e} J");
    assert!(residual.abs() < 1e-9, "{residual:e} J");
}

/// A prescribed body engaging a free one through a lumped clutch
/// ([`cases::prescribed_clutch`]: the motor at `20 + 20 t` rad/s, the load of 0.5 kg m^2 from
/// rest, 30 N m of slip torque) against its closed form: the clutch locks at 0.5 s, the load
/// then follows the motor (36 rad/s at 0.8 s), the heat is 150 J, the motor's reaction 30 N m
/// while slipping and 10 N m locked, its work 474 J, and the balance closes. Measured
/// 2026-12-07: the lock within 2.4e-14 s, the speeds within 3.6e-13 rad/s, the heat within
/// 8.2e-13 J, the reactions exact, the work within 1.2e-11 J, the residual 6.3e-12 J
/// (DOPRI5 integrates the slip phase's polynomials exactly: rounding); asserted 1e-12 s and
/// 1e-9 in the others' units (the tolerance's scale, 40x and more above the measured).
#[test]
fn a_prescribed_body_engages_a_free_one_as_the_closed_form() {
    let net = cases::prescribed_clutch();
    let mut obs = cases::PrescribedClutchObserver::default();
    let opts = NetworkOptions::default();
    let run = run_network(&net, cases::PRESCRIBED_CLUTCH_DURATION_S, &opts, &mut obs).unwrap();
    let rows = cases::prescribed_clutch_against_closed_form(&run, &obs);
    for (what, got, want) in rows {
        println!("{what}: {got} (closed form {want}, off {:.1e})", got - want);
        let bound = if what == "lock time s" { 1e-12 } else { 1e-9 };
        assert!((got - want).abs() < bound, "{what}: {got} against {want}");
    }
}
