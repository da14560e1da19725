//! A power-on upshift on a planetary set against its closed form (MODEL.md section 8's
//! dual-clutch inertia phase with the set's ratios, section 10): the issue-45 check "a power-on
//! upshift on a planetary with the output held, within 0.1 % in energy and inertia-phase time".

use super::automatics::summary;
use super::scratch;
use serde_json::Value;
use std::path::{Path, PathBuf};

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
    let clutch = r#"
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
"#;
    let scene = upshift_scene(&d, "upshift", 1e-3, clutch);
    let (t_i, e_i) = closed_form(J_IN, J_RING);
    for engine in ["reference", "multibody"] {
        let s = summary(&scene, engine, &d);
        let c = element(&s, "C");
        let locks = lock_times(&c);
        let heat = c["heat_j"].as_f64().unwrap();
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

/// The upshift's network (the input on the sun with its drive, the ring, the output on the
/// carrier held by its inertia) with the shift elements `elements` (TOML after the set's
/// `[[couplings]]`: more couplings, and bodies after the output), written into `dir` as `<name>.toml`; the reference
/// engine's longest step `max_step_s` (the multibody engine's network step is the smaller of
/// it and 1e-4 s).
fn upshift_scene(dir: &Path, name: &str, max_step_s: f64, elements: &str) -> PathBuf {
    let scene = dir.join(format!("{name}.toml"));
    let w_in0 = W_OUT * (ZS + ZR) / ZS;
    std::fs::write(
        &scene,
        format!(
            r#"name = "planetary-{name}"
[simulation]
duration_s = 0.1
record_rate_hz = 1000.0
max_step_s = {max_step_s}

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
{elements}"#
        ),
    )
    .unwrap();
    scene
}

/// The closed form of the inertia phase with the input's inertia `j_in` and the ring's
/// `j_ring` (kg m^2): its duration `t_i` (s) and the on-coming element's heat `E_i` (J), as
/// [`a_planetary_power_on_upshift_matches_the_closed_form_on_both_engines`] derives them.
fn closed_form(j_in: f64, j_ring: f64) -> (f64, f64) {
    let k = (ZS + ZR) / ZR;
    let j = j_in + j_ring * (ZS / ZR).powi(2);
    let dw = W_OUT * ZR / ZS;
    let t_i = j * dw / (k * T_C - T_E);
    (t_i, k * T_C * dw * t_i / 2.0)
}

/// The coupling named `name` of a network summary.
fn element(s: &Value, name: &str) -> Value {
    s["couplings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no coupling {name}: {s}"))
        .clone()
}

/// A coupling summary's lock instants, s.
fn lock_times(c: &Value) -> Vec<f64> {
    c["lock_times_s"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// A friction disc's and a separator plate's inertias in the packs below, kg m^2 (those of
/// `scenes/eight-speed-e.toml`).
const J_DISC: f64 = 0.004;
const J_PLATE: f64 = 0.003;
/// The packs' faces: inner and outer radii (m), their constant friction coefficient, the
/// piston's area (m^2) and its return spring (N).
const FACES_M: (f64, f64) = (0.075, 0.095);
const MU: f64 = 0.1;
const PISTON_M2: f64 = 0.01;
const SPRING_N: f64 = 500.0;

/// A resolved pack `<name>.toml` in `dir` (the discs and plates of `scenes/eight-speed-e.toml`
/// on their splines with its oil film and tooth law): `discs` friction discs and one plate
/// more, every face between them, a constant friction coefficient [`MU`] (`static_mu =
/// kinetic_mu`, no viscous slope), no axial spline friction (every face clamped alike), no
/// open-gap drag, a constant piston pressure `pressure_pa` (its rated pressure: a schedule's
/// level 1), the discs and plates starting at `disc_rad` and `plate_rad` in their play.
fn pack_file(
    dir: &Path,
    name: &str,
    discs: usize,
    pressure_pa: f64,
    disc_rad: f64,
    plate_rad: f64,
) {
    let mut bodies = String::new();
    for i in 1..=discs {
        bodies += &format!("[[discs]]\nname = \"disc-{i}\"\n");
    }
    for i in 1..=discs + 1 {
        bodies += &format!("[[plates]]\nname = \"plate-{i}\"\n");
    }
    let (ri, ro) = FACES_M;
    let text = format!(
        r#"name = "{name}"
[simulation]
duration_s = 0.1
[shaft]
mode = "prescribed"
[drive]
kind = "sine"
omega0_rad_s = 100.0
amplitude_rad_s = 0.0
frequency_hz = 50.0
[defaults]
inertia_kg_m2 = {J_DISC}
drag_n_m_s_rad = 0.0
initial_rel_angle_rad = {disc_rad}
[defaults.spline]
teeth = 40
pitch_radius_m = 0.07
pressure_angle_deg = 20.0
backlash_m = 0.3e-3
[defaults.contact]
law = "paper"
modulus_pa = 210e9
curvature_radius_m = 1.75e-3
loss_coefficient_s_m = 0.5
[defaults.oil]
film_thickness_m = 10e-6
viscosity_pa_s = 0.01
leakage_coefficient = 0.421
width_m = 2.0e-3
length_m = 2.0e-3
v_floor_m_s = 0.01
[plate_defaults]
inertia_kg_m2 = {J_PLATE}
drag_n_m_s_rad = 0.0
initial_rel_angle_rad = {plate_rad}
[plate_defaults.spline]
teeth = 48
pitch_radius_m = 0.1
pressure_angle_deg = 30.0
backlash_m = 0.3e-3
[plate_defaults.contact]
law = "paper"
modulus_pa = 210e9
curvature_radius_m = 1.75e-3
loss_coefficient_s_m = 0.5
[plate_defaults.oil]
film_thickness_m = 10e-6
viscosity_pa_s = 0.01
leakage_coefficient = 0.421
width_m = 1.5e-3
length_m = 1.5e-3
v_floor_m_s = 0.01
{bodies}
[drum]
inertia_kg_m2 = 0.05
[stack]
face_inner_radius_m = {ri}
face_outer_radius_m = {ro}
piston_area_m2 = {PISTON_M2}
return_spring_n = {SPRING_N}
spline_friction_coefficient = 0.0
[stack.friction]
static_mu = {MU}
kinetic_mu = {MU}
viscous_slope_s_m = 0.0
[stack.pressure]
kind = "constant"
pressure_pa = {pressure_pa}
"#
    );
    std::fs::write(dir.join(format!("{name}.toml")), text).unwrap();
}

/// The same upshift with its shift elements resolved packs (issue 45: "within 1 % (resolved
/// packs) in energy and inertia-phase time"): the on-coming clutch C (4 friction discs on the
/// input, 5 plates on the ring) and the off-going brake B (4 discs on the ring, 5 plates on the
/// housing), each disc and plate a body on its spline with its tooth contacts and oil film,
/// starting centred in its play. The packs' friction is made for the closed form: a constant
/// coefficient, no axial spline friction and no open-gap drag, C's constant pressure the one
/// whose clamp gives the lumped clutch's capacity (`T_c = 2 N mu F R_eff`, MODEL.md section 5,
/// `F = p A - F_spring`), B's zero (released). The discs and plates ride on their carriers, so
/// the closed form counts their inertias there (C's discs on the input; its plates and B's
/// discs on the ring): they lengthen the phase by 10 % (0.05802 s against 0.05256 s).
///
/// Measured (2026-12-07) on both engines: C's faces all lock 3.0e-4 (reference) and 2.7e-4
/// (multibody, a lock timed to its 1e-4 s network step) before `t_i`, and their heat is
/// 1.9e-3 below `E_i` (1544.15 J against 1547.08 J). What remains is the splines': at the
/// start each disc and plate crosses its play before its teeth take the faces' torque (16
/// impacts on C, up to 99 N per tooth), and while it does its faces slip less than its
/// carriers, the difference going into its teeth; the packs' whole loss (faces, teeth, B's
/// rattling discs: 64 impacts) is 4.6e-4 above `E_i` (1547.8 J). At the lock the teeth's
/// swing breaks the faces loose once more (they lock again at 0.069 s). The two engines'
/// heat agree within 5e-6; the balance closes to 1e-8 of the drive's work. Asserted: the lock
/// 1e-3 and the heat 4e-3 from the closed form (3x and 2x what is measured, within the
/// issue's 1e-2), the packs' whole loss 1.5e-3, the balance 1e-7.
#[test]
fn a_planetary_power_on_upshift_with_resolved_packs_matches_the_closed_form_on_both_engines() {
    let d = scratch("planetary-upshift-packs");
    let (n_c, n_b) = (4, 4);
    let r_eff = 2.0 * (FACES_M.1.powi(3) - FACES_M.0.powi(3))
        / (3.0 * (FACES_M.1.powi(2) - FACES_M.0.powi(2)));
    let clamp = T_C / (2.0 * n_c as f64 * MU * r_eff);
    pack_file(&d, "c", n_c, (clamp + SPRING_N) / PISTON_M2, 0.0, 0.0);
    pack_file(&d, "b", n_b, 0.0, 0.0, 0.0);
    let elements = r#"
[[bodies]]
name = "housing"
fixed = true

[[couplings]]
name = "C"
kind = "pack"
a = "input"
b = "ring"
pack = "c.toml"

[[couplings]]
name = "B"
kind = "pack"
a = "ring"
b = "housing"
pack = "b.toml"
"#;
    let scene = upshift_scene(&d, "packs", 1e-4, elements);
    let j_in = J_IN + n_c as f64 * J_DISC;
    let j_ring = J_RING + (n_c + 1) as f64 * J_PLATE + n_b as f64 * J_DISC;
    let (t_i, e_i) = closed_form(j_in, j_ring);
    let (t_bare, e_bare) = closed_form(J_IN, J_RING);
    println!("closed form: {t_i} s, {e_i} J (without the packs' inertias {t_bare} s, {e_bare} J)");
    for engine in ["reference", "multibody"] {
        let s = summary(&scene, engine, &d);
        let c = element(&s, "C");
        let locks = lock_times(&c);
        let heat = c["heat_j"].as_f64().unwrap();
        let e = &s["energy"];
        let pack_loss = e["pack_loss_j"].as_f64().unwrap();
        println!(
            "{engine}: lock {locks:?} s against {t_i} s ({:.2e}), heat {heat} J against {e_i} J \
             ({:.2e}), the packs' loss {pack_loss} J ({:.2e}); C {} impacts (largest {} N), B {} \
             impacts; {} steps; energy {e}",
            rel(locks[0], t_i),
            rel(heat, e_i),
            rel(pack_loss, e_i),
            c["impacts"],
            c["largest_peak_n"],
            element(&s, "B")["impacts"],
            s["steps"],
        );
        assert!(
            rel(locks[0], t_i) < 1e-3,
            "{engine}: {locks:?} against {t_i}"
        );
        assert!(rel(heat, e_i) < 4e-3, "{engine}: {heat} against {e_i}");
        assert!(
            rel(pack_loss, e_i) < 1.5e-3,
            "{engine}: {pack_loss} against {e_i}"
        );
        assert!(
            e["residual_j"].as_f64().unwrap().abs() < 1e-7 * e["drive_work_j"].as_f64().unwrap(),
            "{engine}: {e}"
        );
    }
}
