//! The pack's inputs by their one public name (the FMU's variable names, which Python's
//! `Simulation` takes too), the older Python names kept as aliases, and the one check of an
//! input against the bound of the scene key it stands for (`clutchpack_scene::MAX_SPEED_RAD_S`,
//! `MAX_PRESSURE_PA`, `MAX_TORQUE_N_M`), so that a co-simulation cannot ask what a scene
//! could not (docs/DECISIONS.md, "Co-simulation hardening"); and the one quoting of a name
//! as an FMI variable name's segment ([`fmi_name_segment`]; here, below the two tables that
//! name variables, so that the network's (`network_cosim.rs`) need not import the pack's
//! (`variables.rs`), which imports it).

use crate::{Error, Result};
use clutchpack_model::session::{Driven, Inputs};

/// An input of the pack (`clutchpack_model::session::Inputs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// The prescribed shaft's speed, rad/s.
    ShaftSpeed,
    /// The drive torque on an inertial shaft, N m.
    ShaftTorque,
    /// The load torque on the drum, N m.
    DrumLoad,
    /// The pressure on the piston, Pa.
    PistonPressure,
}

impl Input {
    /// Every input, in the variable table's order.
    pub const ALL: [Input; 4] = [
        Input::ShaftSpeed,
        Input::ShaftTorque,
        Input::DrumLoad,
        Input::PistonPressure,
    ];

    /// Its one public name: the FMU's variable and Python's `advance_to` keyword.
    pub fn name(self) -> &'static str {
        match self {
            Input::ShaftSpeed => "shaft.speed_rad_s",
            Input::ShaftTorque => "shaft.drive_torque_n_m",
            Input::DrumLoad => "drum.load_torque_n_m",
            Input::PistonPressure => "piston.pressure_pa",
        }
    }

    /// The older name Python's `Simulation(drive=[...])` took, kept as an alias so that no
    /// script breaks.
    pub fn alias(self) -> &'static str {
        match self {
            Input::ShaftSpeed => "shaft_speed",
            Input::ShaftTorque => "shaft_torque",
            Input::DrumLoad => "drum_load",
            Input::PistonPressure => "piston_pressure",
        }
    }

    /// The input named `name` (its public name or its alias).
    pub fn from_name(name: &str) -> Option<Input> {
        Input::ALL
            .into_iter()
            .find(|i| i.name() == name || i.alias() == name)
    }

    /// Its unit (a name of the model description's unit definitions).
    pub fn unit(self) -> &'static str {
        match self {
            Input::ShaftSpeed => "rad/s",
            Input::ShaftTorque | Input::DrumLoad => "N.m",
            Input::PistonPressure => "Pa",
        }
    }

    /// The highest order of derivative it takes (`fmi2SetRealInputDerivatives`): 2 for the
    /// shaft's speed, 1 for the drive torque, 0 (none) for the others.
    pub fn max_derivative_order(self) -> i32 {
        match self {
            Input::ShaftSpeed => 2,
            Input::ShaftTorque => 1,
            Input::DrumLoad | Input::PistonPressure => 0,
        }
    }

    /// Whether `driven` drives it.
    pub fn is_driven(self, driven: &Driven) -> bool {
        *self.flag(&mut driven.clone())
    }

    /// Marks it driven in `driven`.
    pub fn drive(self, driven: &mut Driven) {
        *self.flag(driven) = true;
    }

    fn flag(self, d: &mut Driven) -> &mut bool {
        match self {
            Input::ShaftSpeed => &mut d.shaft_speed,
            Input::ShaftTorque => &mut d.shaft_torque,
            Input::DrumLoad => &mut d.drum_load,
            Input::PistonPressure => &mut d.piston_pressure,
        }
    }

    /// Puts `value` with its first and second derivatives (per s, per s^2; those it does
    /// not take are ignored) into `inputs`: the one mapping from a name to the engines'
    /// inputs.
    pub fn put(self, inputs: &mut Inputs, value: f64, [slope, curvature]: [f64; 2]) {
        match self {
            Input::ShaftSpeed => {
                inputs.shaft_speed_rad_s = Some(value);
                inputs.shaft_speed_slope_rad_s2 = Some(slope);
                inputs.shaft_speed_curvature_rad_s3 = Some(curvature);
            }
            Input::ShaftTorque => {
                inputs.shaft_torque_n_m = Some(value);
                inputs.shaft_torque_slope_n_m_s = Some(slope);
            }
            Input::DrumLoad => inputs.drum_load_n_m = Some(value),
            Input::PistonPressure => inputs.piston_pressure_pa = Some(value),
        }
    }

    /// The bound of the scene key it stands for: lowest and highest value, and the key.
    pub fn bound(self) -> (f64, f64, &'static str) {
        use clutchpack_scene::{MAX_PRESSURE_PA, MAX_SPEED_RAD_S, MAX_TORQUE_N_M};
        match self {
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

    /// `Ok` if `value` lies within the bound of the scene key it stands for; else why not,
    /// naming the input (`when`: where, e.g. " at 0.1 s"), numbers as every message writes
    /// them (`clutchpack_model::fmt_num`: never hundreds of digits). The one place an input
    /// is checked against its bound.
    pub fn check(self, value: f64, when: &str) -> Result<()> {
        let (lo, hi, key) = self.bound();
        if (lo..=hi).contains(&value) {
            return Ok(());
        }
        Err(Error::InputOutOfBound {
            name: self.name().to_string(),
            value,
            unit: self.unit(),
            lo,
            hi,
            key,
            when: when.to_string(),
        })
    }
}

/// `Ok` if `value` may be given to the network input `input` (named `name` in messages):
/// within the bound of the scene key it stands for, so that a co-simulation cannot ask what
/// a scene cannot (a drive torque of 1e30 N m made the first 1 ms step run for minutes).
/// A drive torque within +-`MAX_TORQUE_N_M` (`bodies[].drive.value_n_m`), a clutch's normal
/// force within `[0, MAX_NORMAL_FORCE_N]` (`couplings[].max_normal_force_n`), a pack's
/// piston pressure within `[0, MAX_PRESSURE_PA]` (`stack.pressure.pressure_pa`), a
/// prescribed body's speed within +-`MAX_SPEED_RAD_S` (`bodies[].speed.omega0_rad_s`). The one
/// place a network input is checked against its bound (the FMU's `fmi2SetReal` and every
/// `set_input` call it).
pub fn check_network_input(
    input: clutchpack_model::network::NetworkInput,
    name: &str,
    value: f64,
) -> Result<()> {
    use clutchpack_scene::{MAX_NORMAL_FORCE_N, MAX_PRESSURE_PA, MAX_SPEED_RAD_S, MAX_TORQUE_N_M};
    let (lo, hi, unit, key) = match input {
        clutchpack_model::network::NetworkInput::Drive(_) => (
            -MAX_TORQUE_N_M,
            MAX_TORQUE_N_M,
            "N m",
            "bodies[].drive.value_n_m",
        ),
        clutchpack_model::network::NetworkInput::ClutchForce(_) => (
            0.0,
            MAX_NORMAL_FORCE_N,
            "N",
            "couplings[].max_normal_force_n",
        ),
        clutchpack_model::network::NetworkInput::PackPressure(_) => {
            (0.0, MAX_PRESSURE_PA, "Pa", "stack.pressure.pressure_pa")
        }
        clutchpack_model::network::NetworkInput::Speed(_) => (
            -MAX_SPEED_RAD_S,
            MAX_SPEED_RAD_S,
            "rad/s",
            "bodies[].speed.omega0_rad_s",
        ),
    };
    if (lo..=hi).contains(&value) {
        return Ok(());
    }
    Err(Error::InputOutOfBound {
        name: name.to_string(),
        value,
        unit,
        lo,
        hi,
        key,
        when: String::new(),
    })
}

/// The public names of the inputs `driven` drives, in the table's order.
pub fn driven_names(driven: &Driven) -> Vec<&'static str> {
    Input::ALL
        .into_iter()
        .filter(|i| i.is_driven(driven))
        .map(Input::name)
        .collect()
}

/// The inputs named in `names` (public names or aliases) as a [`Driven`]; an unknown name is
/// an error that lists the names, an input named twice (by one name or by its name and its
/// alias) an error naming it.
pub fn driven_from_names<S: AsRef<str>>(names: &[S]) -> Result<Driven> {
    let mut driven = Driven::NONE;
    for n in names {
        let n = n.as_ref();
        let i = Input::from_name(n).ok_or_else(|| {
            let all: Vec<String> = Input::ALL
                .iter()
                .map(|i| format!("{:?}", i.name()))
                .collect();
            let old: Vec<String> = Input::ALL
                .iter()
                .map(|i| format!("{:?}", i.alias()))
                .collect();
            Error::BadInput(format!(
                "drive = {n:?}: expected any of {} (or the older names {})",
                all.join(", "),
                old.join(", ")
            ))
        })?;
        if i.is_driven(&driven) {
            return Err(Error::BadInput(format!(
                "drive = {n:?}: {} is named twice; name each input once",
                i.name()
            )));
        }
        i.drive(&mut driven);
    }
    Ok(driven)
}

/// `name` as one segment of an FMI 2.0 structured variable name (the model description's
/// `variableNamingConvention = "structured"`, FMI 2.0 section 2.2.9): as it is when it is an
/// identifier (`[A-Za-z_][A-Za-z0-9_]*`: `K2`, `crank`), else a quoted name (`'input-1'`),
/// with `'`, `"`, `?`, `\` and the control characters the grammar names escaped. The one
/// quoting of FMI names: every network variable's name goes through it. A character the
/// grammar cannot write at all (one outside ASCII, another control character) is an error
/// naming it.
pub fn fmi_name_segment(name: &str) -> Result<String, Error> {
    let mut chars = name.chars();
    let identifier = chars
        .next()
        .is_some_and(|c| c == '_' || c.is_ascii_alphabetic())
        && chars.all(|c| c == '_' || c.is_ascii_alphanumeric());
    if identifier {
        return Ok(name.to_string());
    }
    let mut out = String::with_capacity(name.len() + 2);
    out.push('\'');
    for c in name.chars() {
        match c {
            '\'' => out.push_str("\\'"),
            '"' => out.push_str("\\\""),
            '?' => out.push_str("\\?"),
            '\\' => out.push_str("\\\\"),
            '\u{7}' => out.push_str("\\a"),
            '\u{8}' => out.push_str("\\b"),
            '\u{c}' => out.push_str("\\f"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '\u{b}' => out.push_str("\\v"),
            ' '..='~' => out.push(c),
            _ => {
                return Err(Error::BadInput(format!(
                    "{name:?}: the character {c:?} cannot be written in an FMI variable name \
                     (ASCII only): rename it in the scene"
                )))
            }
        }
    }
    out.push('\'');
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_input_has_one_name_and_one_alias() {
        for i in Input::ALL {
            assert_eq!(Input::from_name(i.name()), Some(i));
            assert_eq!(Input::from_name(i.alias()), Some(i));
            let mut d = Driven::NONE;
            i.drive(&mut d);
            assert!(i.is_driven(&d));
            assert_eq!(driven_names(&d), vec![i.name()]);
        }
        let d = driven_from_names(&["piston_pressure", "shaft.speed_rad_s"]).unwrap();
        assert!(d.piston_pressure && d.shaft_speed && !d.drum_load && !d.shaft_torque);
        let e = driven_from_names(&["pressure"]).unwrap_err().to_string();
        assert!(
            e.contains("piston.pressure_pa") && e.contains("piston_pressure"),
            "{e}"
        );
    }

    #[test]
    fn inputs_are_checked_against_their_keys_bounds() {
        let e = Input::ShaftSpeed.check(1e9, "").unwrap_err().to_string();
        assert!(
            e.contains("shaft.speed_rad_s = 1e9 rad/s") && e.contains("100000"),
            "{e}"
        );
        assert!(Input::PistonPressure.check(-1.0, "").is_err());
        assert!(Input::PistonPressure.check(1e6, "").is_ok());
    }
}

#[cfg(test)]
mod name_tests {
    use super::fmi_name_segment;

    /// Identifiers pass as they are; other names are quoted with the grammar's escapes; a
    /// character outside ASCII is refused with the name.
    #[test]
    fn fmi_names_are_identifiers_or_quoted() {
        assert_eq!(fmi_name_segment("K2").unwrap(), "K2");
        assert_eq!(fmi_name_segment("_a1").unwrap(), "_a1");
        assert_eq!(fmi_name_segment("input-1").unwrap(), "'input-1'");
        assert_eq!(fmi_name_segment("1st").unwrap(), "'1st'");
        assert_eq!(fmi_name_segment("a b").unwrap(), "'a b'");
        assert_eq!(fmi_name_segment("it's").unwrap(), "'it\\'s'");
        assert_eq!(fmi_name_segment("a\\b?").unwrap(), "'a\\\\b\\?'");
        assert_eq!(fmi_name_segment("").unwrap(), "''");
        let e = fmi_name_segment("vélo").unwrap_err().to_string();
        assert!(e.contains("vélo") && e.contains("'é'"), "{e}");
    }
}
