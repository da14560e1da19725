//! A power-on upshift on a planetary set against its closed form (MODEL.md section 8's
//! dual-clutch inertia phase with the set's ratios, section 10): the issue-45 check "a power-on
//! upshift on a planetary with the output held, within 0.1 % in energy and inertia-phase time".

use super::{read_json, run, scratch, stderr};
use serde_json::Value;

/// Teeth of the set: sun and ring.
const ZS: f64 = 30.0;
const ZR: f64 = 70.0;
/// The input's (sun's) and the ring's inertias, kg m^2.
const J_IN: f64 = 0.2;
const J_RING: f64 = 0.05;
/// The input's drive, N m.
const T_E: f64 = 200.0;
/// The on-coming clutch's torque while it slips: mu 0.1 x c_geo 0.2 m x 20 kN, N m.
const T_C: f64 = 400.0;
/// The output's (carrier's) speed, held by an inertia of 1e6 kg m^2, rad/s.
const W_OUT: f64 = 40.0;

/// The 1 -> 2 upshift's inertia phase of a two-speed planetary (the input on the sun, the
/// output on the carrier; 1st: the ring braked, `w_in / w_out = 1 + z_R / z_S`; 2nd: a clutch
/// from the input to the ring, direct). The brake is already open; the clutch slips at a
/// constant torque `T_c` from t = 0 with the engine torque `T_e` on the input and the output
/// held. With the output held the set has one degree of freedom, the input's speed: the ring
/// turns at `w_R = ((z_S + z_R) w_out - z_S w_in) / z_R`, so the input carries
/// `J = J_in + J_R (z_S / z_R)^2`, and the clutch's slip `w_R - w_in = -k (w_in - w_out)`
/// with `k = (z_S + z_R) / z_R` brakes it by `k T_c`. The closed form (section 8's with these
/// ratios): the input falls by `dw = w_out z_R / z_S` in `t_i = J dw / (k T_c - T_e)`, and the
/// clutch takes `E_i = k T_c dw t_i / 2`.
///
/// Both engines, measured: the lock and the heat within 2.5e-7 of `t_i` and `E_i` (the
/// output's speed moves by about 1e-6 relative, which the closed form holds fixed); after the
/// lock the set turns as one body; the energy balance closes to 3.3e-8 of the drive's work on
/// the multibody engine (the rounding of the held output's 8e8 J of kinetic energy, 5e-14 of
/// it). Issue 45's bound 0.1 %; asserted 1e-4, and 1e-7 on the balance.
#[test]
fn a_planetary_power_on_upshift_matches_the_closed_form_on_both_engines() {
    let d = scratch("planetary-upshift");
    let scene = d.join("upshift.toml");
    let w_in0 = W_OUT * (ZS + ZR) / ZS;
    std::fs::write(
        &scene,
        format!(
            r#"name = "planetary-upshift"
[simulation]
duration_s = 0.1
record_rate_hz = 1000.0
max_step_s = 1e-3

[[bodies]]
name = "input"
inertia_kg_m2 = {J_IN}
initial_speed_rad_s = {w_in0}
[bodies.drive]
kind = "constant"
value_n_m = {T_E}

[[bodies]]
name = "ring"
inertia_kg_m2 = {J_RING}
initial_speed_rad_s = 0.0

[[bodies]]
name = "output"
inertia_kg_m2 = 1e6
initial_speed_rad_s = {W_OUT}

[[couplings]]
name = "set"
kind = "planetary"
a = "input"
b = "ring"
carrier = "output"
sun_teeth = {ZS}
ring_teeth = {ZR}

[[couplings]]
name = "C"
kind = "clutch"
a = "input"
b = "ring"
mu = 0.1
peak = 1.0
cgeo_m = 0.2
max_normal_force_n = 20000.0
[couplings.force]
kind = "constant"
value = 1.0
"#
        ),
    )
    .unwrap();
    let k = (ZS + ZR) / ZR;
    let j = J_IN + J_RING * (ZS / ZR).powi(2);
    let dw = W_OUT * ZR / ZS;
    let t_i = j * dw / (k * T_C - T_E);
    let e_i = k * T_C * dw * t_i / 2.0;
    for engine in ["reference", "multibody"] {
        let json = d.join(format!("{engine}.json"));
        let o = run(&[
            "run",
            scene.to_str().unwrap(),
            "--engine",
            engine,
            "--no-record",
            "--summary-json",
            json.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{engine}: {}", stderr(&o));
        let s: Value = read_json(&json);
        let c = s["couplings"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["name"] == "C")
            .unwrap()
            .clone();
        let locks: Vec<f64> = c["lock_times_s"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let heat = c["heat_j"].as_f64().unwrap();
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
        println!(
            "{engine}: lock {locks:?} s against {t_i} s ({:.2e}), heat {heat} J against {e_i} J \
             ({:.2e})",
            rel(locks[0], t_i),
            rel(heat, e_i)
        );
        assert_eq!(locks.len(), 1, "{engine}: {locks:?}");
        assert!(rel(locks[0], t_i) < 1e-4, "{engine}: {} {t_i}", locks[0]);
        assert!(rel(heat, e_i) < 1e-4, "{engine}: {heat} {e_i}");
        // after the lock the set turns as one body (2nd is direct)
        let w = |i: usize| s["bodies"][i]["final_speed_rad_s"].as_f64().unwrap();
        assert!(
            rel(w(0), w(2)) < 1e-9 && rel(w(1), w(2)) < 1e-9,
            "{engine}: {} {} {}",
            w(0),
            w(1),
            w(2)
        );
        let e = &s["energy"];
        assert!(
            e["residual_j"].as_f64().unwrap().abs() < 1e-7 * e["drive_work_j"].as_f64().unwrap(),
            "{engine}: {e}"
        );
    }
}
