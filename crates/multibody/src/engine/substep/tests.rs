//! The sub-step kernel's tests: the kinks' grading, the turn's moment, the step's order and
//! its audit.

use super::*;

/// The graded sub-step: the floor at an onset, a quarter of the contact's age after it,
/// the controller's step once that is longer, a quarter of the predicted time to
/// separation (depth over the opening speed) while the depth falls, nothing in free flight
/// or while the depth grows.
#[test]
fn sub_steps_are_graded_at_the_kinks() {
    let forces = |depth_m: f64, v_n_m_s: f64| CouplingForces {
        kin: clutchpack_model::ToothKinematics {
            flank: clutchpack_model::Flank::ShaftLeads,
            delta_m: depth_m,
            v_n_m_s,
        },
        depth_m,
        load_n: 0.0,
        force: [0.0; 2],
        moment: [0.0; 3],
        stiffness: 0.0,
        potential_j: 0.0,
        gap_margin_m: 0.0,
        speed_margin_m_s: 0.0,
    };
    let want = 64e-8;
    let growing = forces(1e-7, 0.5);
    assert_eq!(
        graded_step(want, &growing, Some(0.0), KINK_FLOOR_DIVISOR),
        1e-8
    );
    assert_eq!(
        graded_step(want, &growing, Some(8e-7), KINK_FLOOR_DIVISOR),
        2e-7
    );
    assert_eq!(
        graded_step(want, &growing, Some(1e-5), KINK_FLOOR_DIVISOR),
        want
    );
    assert_eq!(graded_step(want, &growing, None, KINK_FLOOR_DIVISOR), want);
    // 1e-7 m at 0.5 m/s: 2e-7 s to the separation
    let falling = forces(1e-7, -0.5);
    assert_eq!(
        graded_step(want, &falling, Some(1e-5), KINK_FLOOR_DIVISOR),
        0.25 * 2e-7
    );
    assert_eq!(
        graded_step(want, &forces(1e-12, -0.5), Some(1e-5), KINK_FLOOR_DIVISOR),
        1e-8
    );
    assert_eq!(
        graded_step(want, &forces(-1e-7, -0.5), Some(0.0), KINK_FLOOR_DIVISOR),
        want
    );
    // a coupling alone on a carrier of known motion: the same grading from an eighth
    let alone = ALONE_KINK_FLOOR_DIVISOR;
    assert_eq!(graded_step(want, &growing, Some(0.0), alone), 8e-8);
    assert_eq!(graded_step(want, &growing, Some(8e-7), alone), 2e-7);
    assert_eq!(
        graded_step(want, &forces(1e-12, -0.5), Some(1e-5), alone),
        8e-8
    );
}

/// The first moment of speed over a world step from the body's angle and speed at uneven
/// sub-step ends is exact for a cubic angle (Hermite quadrature): `theta = a s + b s^2 +
/// c s^3` from `t0` = 0.3 s over 1e-4 s in five uneven sub-steps gives the slope
/// `12 m1 / h^3` of the exact moment to rounding; a body turning at constant speed has
/// slope 0, and the affine speed so found has the body's mean and moment.
#[test]
fn turn_moment_is_exact_for_a_cubic_angle() {
    let (a, b, c) = (200.0, 3.0e3, -4.0e7);
    let (t0, h) = (0.3, 1e-4);
    let theta = |s: f64| 50.0 + a * s + b * s * s + c * s * s * s;
    let speed = |s: f64| a + 2.0 * b * s + 3.0 * c * s * s;
    let mut m = TurnMoment::start(t0, theta(0.0), speed(0.0));
    let mut flat = TurnMoment::start(t0, 1.0, a);
    for f in [0.1, 0.15, 0.5, 0.9, 1.0] {
        m.add(t0 + f * h, theta(f * h), speed(f * h));
        flat.add(t0 + f * h, 1.0 + a * f * h, a);
    }
    // m1 = integral_0^h (s - h/2) w(s) ds for w = a + 2 b s + 3 c s^2
    let m1 = 2.0 * b * h.powi(3) / 12.0 + 3.0 * c * h.powi(4) / 12.0;
    let exact = 12.0 * m1 / h.powi(3);
    assert!(
        (m.slope() - exact).abs() < 1e-6 * exact.abs(),
        "{} vs {exact}",
        m.slope()
    );
    assert!(flat.slope().abs() < 1e-3, "{}", flat.slope());
    let g = GapDrag {
        held_n_m: 2.0,
        slope_n_m_s: 10.0,
        t_mid_s: t0 + 0.5 * h,
        half_step_s: 0.5 * h,
        damping: 0.5,
    };
    assert_eq!(g.torque(t0 + 0.5 * h, 4.0), 0.0);
    assert!((g.torque(t0 + h, 0.0) - (2.0 + 10.0 * 0.5 * h)).abs() < 1e-15);
    assert!((g.bound_n_m() - (2.0 + 10.0 * 0.5 * h)).abs() < 1e-15);
}

/// A disc in free flight inside the backlash of a shaft at rest, slowed by its drag:
/// `omega_d = w0 e^(-r t)`, `r = C2 / J`, so `phi = -w0 (1 - e^(-r t)) / r` and the drag's
/// work equals the change of kinetic energy, `J (omega_d^2 - w0^2) / 2`. The classical
/// Runge-Kutta step is fourth order: halving the step divides the error by about 16
/// (within 1: the next term of the error is smaller by a further factor `r h`), and the
/// drag's work from the same stages matches the kinetic energy lost to 1e-5 (measured
/// 2.2e-6 at `r h = 0.1`).
#[test]
fn sub_step_is_fourth_order_and_audits_the_drag() {
    // the bench disc's spline and dry law (`scenes/bench-8-disc.toml`)
    let disc = clutchpack_model::cases::bench_disc("d");
    let (spline, law) = (disc.spline, disc.law);
    let coupling = Coupling::new(spline, law, false, &[]);
    let profile = SpeedProfile::sine(0.0, 0.0, 1.0);
    let prescribed = Prescribed {
        profile: &profile,
        local: None,
    };
    let (j, c2, w0) = (0.2, 20.0, 1e-3);
    let rel = Relative {
        path: Path::Profile(prescribed),
        coupling: &coupling,
        inv_j: 1.0 / j,
        c2,
        gap: GapDrag::default(),
        // free flight within the backlash all along: no tooth touches
        start_torque_n_m: 0.0,
    };
    assert_eq!(coupling.probe_torque(0.0, -w0), 0.0);
    let r = c2 / j;
    let duration = 0.05;
    let run = |n: usize| {
        let h = duration / n as f64;
        let (mut phi, mut dphi, mut drag) = (0.0, -w0, 0.0);
        for k in 0..n {
            let t = k as f64 * h;
            let s = rel.step(t, prescribed.at(t), phi, dphi, h);
            (phi, dphi, drag) = (s.phi, s.dphi, drag + s.drag_j);
        }
        let wd = w0 * (-r * duration).exp();
        let phi_exact = -w0 * (1.0 - (-r * duration).exp()) / r;
        assert!((-dphi - wd).abs() < 1e-6 * w0, "{dphi} vs {wd}");
        let work = 0.5 * j * (wd * wd - w0 * w0);
        // fourth order too: 2.2e-6 relative at r h = 0.1 (50 steps)
        assert!((drag - work).abs() < 1e-5 * work.abs(), "{drag} vs {work}");
        (phi - phi_exact).abs()
    };
    let ratio = run(50) / run(100);
    assert!((ratio - 16.0).abs() < 1.0, "{ratio}");
}
