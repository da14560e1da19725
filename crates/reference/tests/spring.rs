//! The torsional spring-damper between the shaft and the drum (MODEL.md section 8) against its
//! closed forms: two inertias released from a twist oscillate at `omega_d = omega_n sqrt(1 -
//! zeta^2)` and decay by the logarithmic decrement `2 pi zeta / sqrt(1 - zeta^2)`, with the
//! kinetic energy, the spring's and the damper's loss summing to the start's.

use clutchpack_model::cases::{spring_pair, SPRING_PAIR_DRUM_KG_M2, SPRING_PAIR_SHAFT_KG_M2};
use clutchpack_model::checks::free_oscillation;
use clutchpack_model::{Collector, Engine, Sample, SpringDamper};
use clutchpack_reference::{ReferenceEngine, ReferenceOptions};

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

fn run(prescribed: bool, duration: f64) -> Vec<Sample> {
    let options = ReferenceOptions {
        tolerance: 1e-10,
        max_step_s: 1e-3,
        record_rate_hz: 20_000.0,
    };
    let mut e = ReferenceEngine::new(spring_pair(SPRING, prescribed), options);
    let mut c = Collector::default();
    e.run(duration, &mut c).unwrap();
    assert!(c.impacts.is_empty(), "the splines never touch");
    c.samples
}

/// Two free inertias over 0.4 s (6.6 periods): period within 1e-8 and decrement within 1e-7
/// relative of the closed forms (measured: 3.4e-10 and 1.2e-8, the decrement's the peaks'
/// parabolas'), and the energy (kinetic + spring + damper loss, the drum's speed from the
/// conserved momentum, the loss by the trapezoidal rule on the samples) kept within 1e-6 of
/// the spring's initial energy (measured 7.0e-8 J of 0.4 J, 1.7e-7).
#[test]
fn two_inertias_oscillate_and_decay_as_the_closed_forms() {
    let (js, jd) = (SPRING_PAIR_SHAFT_KG_M2, SPRING_PAIR_DRUM_KG_M2);
    let samples = run(false, 0.4);
    let x: Vec<(f64, f64)> = samples
        .iter()
        .map(|s| {
            (
                s.t_s,
                s.shaft_angle_rad - drum_angle(s) - SPRING.free_angle_rad,
            )
        })
        .collect();
    let (period, decrement) = free_oscillation(&x).unwrap();
    let want_period = 2.0 * std::f64::consts::PI / SPRING.damped_frequency_rad_s(js, jd);
    let want_decrement = SPRING.log_decrement(js, jd);
    let (ep, ed) = (
        (period / want_period - 1.0).abs(),
        (decrement / want_decrement - 1.0).abs(),
    );
    println!("period {period} s ({ep:.1e}), decrement {decrement} ({ed:.1e})");
    assert!(
        ep < 1e-8 && ed < 1e-7,
        "{period} vs {want_period}, {decrement} vs {want_decrement}"
    );
    // energy: both start at 100 rad/s; the spring holds k theta_0^2 / 2
    let momentum = (js + jd) * 100.0;
    let e0 = 0.5 * (js + jd) * 100.0 * 100.0 + SPRING.potential_j(0.0);
    let mut loss = 0.0;
    let mut worst = 0.0f64;
    let mut prev: Option<(f64, f64)> = None;
    for s in &samples {
        let ws = s.shaft_speed_rad_s;
        let wd = (momentum - js * ws) / jd;
        let rate = SPRING.loss_rate_w(ws - wd);
        if let Some((t0, r0)) = prev {
            loss += 0.5 * (r0 + rate) * (s.t_s - t0);
        }
        prev = Some((s.t_s, rate));
        let e = 0.5 * js * ws * ws
            + 0.5 * jd * wd * wd
            + SPRING.potential_j(s.shaft_angle_rad - drum_angle(s))
            + loss;
        worst = worst.max((e - e0).abs());
    }
    let scale = SPRING.potential_j(0.0);
    println!("energy: worst {worst:.2e} J of {scale} J, damper {loss} J");
    assert!(loss > 0.5 * scale);
    assert!(worst < 1e-6 * scale, "{worst}");
}

/// A prescribed shaft drives the drum through the spring: one inertia, `omega_n = sqrt(k /
/// J)`, the same bounds (measured: 4.4e-10 and 1.2e-8).
#[test]
fn a_prescribed_shaft_drives_the_drum_through_the_spring() {
    let jd = SPRING_PAIR_DRUM_KG_M2;
    let x: Vec<(f64, f64)> = run(true, 0.4)
        .iter()
        .map(|s| {
            (
                s.t_s,
                s.shaft_angle_rad - drum_angle(s) - SPRING.free_angle_rad,
            )
        })
        .collect();
    let (period, decrement) = free_oscillation(&x).unwrap();
    let want_period = 2.0 * std::f64::consts::PI / SPRING.damped_frequency_rad_s(f64::INFINITY, jd);
    let want_decrement = SPRING.log_decrement(f64::INFINITY, jd);
    println!("period {period} vs {want_period} s, decrement {decrement} vs {want_decrement}");
    assert!((period / want_period - 1.0).abs() < 1e-8);
    assert!((decrement / want_decrement - 1.0).abs() < 1e-7);
}
