//! The torsional spring-damper between the shaft and the drum (MODEL.md section 8) on the
//! multibody engine against its closed forms (as `crates/reference/tests/spring.rs`): two
//! inertias released from a twist oscillate at `omega_d = omega_n sqrt(1 - zeta^2)` and decay
//! by the logarithmic decrement `2 pi zeta / sqrt(1 - zeta^2)`; the engine's energy audit
//! (kinetic + spring = start - damper loss) balances.

use clutchpack_model::cases::{spring_pair, SPRING_PAIR_DRUM_KG_M2, SPRING_PAIR_SHAFT_KG_M2};
use clutchpack_model::checks::free_oscillation;
use clutchpack_model::{Collector, Engine, Sample, SpringDamper};
use clutchpack_multibody::{MultibodyEngine, MultibodyOptions};

const SPRING: SpringDamper = SpringDamper {
    stiffness_n_m_per_rad: 2000.0,
    damping_n_m_s_per_rad: 0.8,
    free_angle_rad: 0.02,
};

/// The drum's angle from a sample: the plate on it (the last body) at `angle_rad`, its
/// carrier `rel_angle_rad` ahead.
fn drum_angle(s: &Sample) -> f64 {
    let p = s.discs.last().unwrap();
    p.angle_rad + p.rel_angle_rad
}

/// The twist less its free angle over `duration` s, and the engine (for its audit).
fn run(prescribed: bool, duration: f64) -> (Vec<(f64, f64)>, MultibodyEngine) {
    let options = MultibodyOptions::with_settings(20_000.0, 1e-4, false);
    let mut e = MultibodyEngine::new(spring_pair(SPRING, prescribed), options).unwrap();
    assert!(!e.is_multirate(), "{}", e.scheme_explanation());
    let mut c = Collector::default();
    e.run(duration, &mut c).unwrap();
    assert!(c.impacts.is_empty(), "the splines never touch");
    let x = c
        .samples
        .iter()
        .map(|s| {
            (
                s.t_s,
                s.shaft_angle_rad - drum_angle(s) - SPRING.free_angle_rad,
            )
        })
        .collect();
    (x, e)
}

/// Two free inertias over 0.4 s (6.6 periods; the shared step, as the multirate scheme
/// refuses a spring-damper): period within 1e-8 and decrement within 1e-6 relative of the
/// closed forms (measured: 1.1e-9 and 2.7e-7), and the energy audit balanced within 1e-6 of
/// the spring's initial energy (measured 7.8e-8 J of 0.4 J, 2.0e-7).
#[test]
fn two_inertias_oscillate_and_decay_as_the_closed_forms() {
    let (js, jd) = (SPRING_PAIR_SHAFT_KG_M2, SPRING_PAIR_DRUM_KG_M2);
    let (x, e) = run(false, 0.4);
    let (period, decrement) = free_oscillation(&x).unwrap();
    let want_period = 2.0 * std::f64::consts::PI / SPRING.damped_frequency_rad_s(js, jd);
    let want_decrement = SPRING.log_decrement(js, jd);
    let (ep, ed) = (
        (period / want_period - 1.0).abs(),
        (decrement / want_decrement - 1.0).abs(),
    );
    let a = e.energy();
    let imbalance = a.energy_change_j() - a.work_j();
    println!(
        "period {period} s ({ep:.1e}), decrement {decrement} ({ed:.1e}); energy: damper {} J, \
         spring {} -> {} J, imbalance {imbalance:.2e} J; {}",
        a.coupling_work_j,
        a.initial_coupling_potential_j,
        a.coupling_potential_j,
        e.scheme_explanation()
    );
    assert!(
        ep < 1e-8 && ed < 1e-6,
        "{period} vs {want_period}, {decrement} vs {want_decrement}"
    );
    assert!((a.initial_coupling_potential_j - SPRING.potential_j(0.0)).abs() < 1e-12);
    assert!(a.coupling_work_j < -0.5 * SPRING.potential_j(0.0));
    assert!(imbalance.abs() < 1e-6 * SPRING.potential_j(0.0), "{a:?}");
}

/// A prescribed shaft drives the drum through the spring: one inertia, `omega_n = sqrt(k /
/// J)`; the same bounds (measured: 1.0e-10 and 1.7e-7), the audit within 2e-4 of the spring's
/// energy (measured 4.1e-5 J: the drive's work, the spring's torque times the shaft's turn by
/// the trapezoidal rule per step, 27 J, to 1.5e-6).
#[test]
fn a_prescribed_shaft_drives_the_drum_through_the_spring() {
    let jd = SPRING_PAIR_DRUM_KG_M2;
    let (x, e) = run(true, 0.4);
    let (period, decrement) = free_oscillation(&x).unwrap();
    let want_period = 2.0 * std::f64::consts::PI / SPRING.damped_frequency_rad_s(f64::INFINITY, jd);
    let want_decrement = SPRING.log_decrement(f64::INFINITY, jd);
    let a = e.energy();
    let imbalance = a.energy_change_j() - a.work_j();
    println!(
        "period {period} vs {want_period} s, decrement {decrement} vs {want_decrement}; \
         imbalance {imbalance:.2e} J, drive {} J",
        a.drive_work_j
    );
    assert!((period / want_period - 1.0).abs() < 1e-8);
    assert!((decrement / want_decrement - 1.0).abs() < 1e-6);
    assert!(imbalance.abs() < 2e-4 * SPRING.potential_j(0.0), "{a:?}");
}
