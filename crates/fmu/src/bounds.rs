//! The bounds of an FMU's (and Python's `Simulation`'s) inputs: each input is checked
//! against the bound of the scene key it stands for (`clutchpack_scene::MAX_SPEED_RAD_S`,
//! `MAX_PRESSURE_PA`, `MAX_TORQUE_N_M`), so that a co-simulation cannot ask what a scene
//! could not (docs/DECISIONS.md, "Co-simulation hardening").

use crate::variables::Input;

/// The bound of the scene key an input stands for: lowest and highest value, and the key.
fn input_bound(i: Input) -> (f64, f64, &'static str) {
    use clutchpack_scene::{MAX_PRESSURE_PA, MAX_SPEED_RAD_S, MAX_TORQUE_N_M};
    match i {
        Input::ShaftSpeed => (-MAX_SPEED_RAD_S, MAX_SPEED_RAD_S, "drive.omega0_rad_s"),
        Input::ShaftTorque => (
            -MAX_TORQUE_N_M,
            MAX_TORQUE_N_M,
            "a scene's torques, as drum.load_torque_n_m",
        ),
        Input::DrumLoad => (-MAX_TORQUE_N_M, MAX_TORQUE_N_M, "drum.load_torque_n_m"),
        Input::PistonPressure => (0.0, MAX_PRESSURE_PA, "stack.pressure.pressure_pa"),
    }
}

/// `Ok` if `value` of the input `name` (its `unit`) lies within the bound of the scene key
/// it stands for; else why not, numbers as every message writes them
/// (`clutchpack_model::fmt_num`: never hundreds of digits).
pub(crate) fn check_input(
    name: &str,
    i: Input,
    unit: &str,
    value: f64,
    when: &str,
) -> Result<(), String> {
    let (lo, hi, key) = input_bound(i);
    if (lo..=hi).contains(&value) {
        return Ok(());
    }
    let e = clutchpack_model::fmt_num;
    Err(format!(
        "{name} = {} {unit}{when}: expected a value in [{}, {}] {unit}, the bound of the \
         scene key it stands for ({key})",
        e(value),
        e(lo),
        e(hi)
    ))
}
