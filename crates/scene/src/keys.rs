//! Every key of a scene file, defined once: its table, name, unit, kind and range rule,
//! default and meaning. **This is the one place to add a key.** Each [`table!`] below
//! defines one table's raw serde struct (read by [`crate::parse`]), one [`Key`] per leaf (read
//! by the validation through `RawX::key_name`, for its rule, unit and default), and the lines
//! of `clutchpack check --keys` and of docs/scene-keys.md's key table.
//!
//! To add a key to an existing table: add one line to its `table!` (doc comment, name, unit,
//! kind with its rule, default), then use the value where the typed model is built (the
//! section's module under [`crate::validate`]). To add a table: one more `table!` and one
//! `children` entry in its parent.
//!
//! Plausibility bounds (`Rule::Bounded`, `Kind::Count`'s `max`) are explained in
//! docs/DECISIONS.md, "Plausibility bounds".
//!
//! [`Key`]: crate::schema::Key

use crate::schema::{table, Dflt, Kind, Rule};
use clutchpack_model::fatigue as fat;

/// Longest simulated duration accepted, s (about 11.6 days).
pub(crate) const MAX_DURATION_S: f64 = 1e6;
/// Highest record rate accepted, Hz.
pub(crate) const MAX_RECORD_RATE_HZ: f64 = 1e6;
/// Most samples one run may emit (`duration_s * record_rate_hz`).
pub(crate) const MAX_SAMPLES: f64 = 1e8;
/// Smallest `max_step_s` accepted, s.
pub(crate) const MIN_MAX_STEP_S: f64 = 1e-9;
/// Smallest inertia of a body accepted, kg m^2 (a 10 g ring of 14 mm radius).
pub(crate) const MIN_INERTIA_KG_M2: f64 = 1e-6;
/// Largest pitch radius of a spline accepted, m (the largest wet brakes are below 1 m).
pub(crate) const MAX_PITCH_RADIUS_M: f64 = 5.0;
/// Largest equivalent modulus accepted, Pa (ten times diamond's).
pub(crate) const MAX_MODULUS_PA: f64 = 1e13;
/// Largest impact loss coefficient accepted, s/m: Hunt and Crossley's `3 (1 - e) / (2 v0)` is
/// at most 1500 s/m for a closing speed of 1 mm/s even with no rebound (e = 0); the paper's
/// case is 0.8. A run's cost grows with it (`pack-6-thermal.toml`, 0.3 s: 0.2 s of wall time
/// at 0.8, 4.3 s at 1e3, 31 s at 1e4, over 60 s at 1e5).
pub(crate) const MAX_LOSS_COEFFICIENT_S_M: f64 = 1e3;
/// Largest equivalent curvature radius accepted, m.
pub(crate) const MAX_CURVATURE_RADIUS_M: f64 = 10.0;
/// Range of the endurance limit accepted, Pa (polymers to the strongest steels, with margin).
pub(crate) const ENDURANCE_RANGE_PA: (f64, f64) = (1e6, 1e10);
/// Largest S-N slope accepted (ISO 6336-3's steepest is about 17; Haibach doubles it).
pub(crate) const MAX_SN_SLOPE: f64 = 50.0;
/// Range of the knee of the S-N curve accepted, cycles.
pub(crate) const KNEE_CYCLES_RANGE: (f64, f64) = (1e3, 1e10);
/// Range of a tooth's face width and working depth accepted, m.
pub(crate) const TOOTH_SIZE_RANGE_M: (f64, f64) = (1e-5, 1.0);
/// Largest ISO 6336-3 factor (form, stress correction, load distribution) accepted.
pub(crate) const MAX_TOOTH_FACTOR: f64 = 10.0;
/// Smallest pitch radius of a spline accepted, m.
pub(crate) const MIN_PITCH_RADIUS_M: f64 = 1e-3;
/// Largest Miner damage sum at failure accepted.
pub(crate) const MAX_CRITICAL_DAMAGE: f64 = 10.0;
/// Most teeth of one spline accepted.
pub(crate) const MAX_TEETH: u32 = 10_000;

/// Largest inertia of a body accepted, kg m^2 (a large ship's propeller line is about 1e5;
/// 1e308 passed as finite and made a clutch's heat `inf * 0`).
pub(crate) const MAX_INERTIA_KG_M2: f64 = 1e7;
/// Inertia of a body: at least [`MIN_INERTIA_KG_M2`], at most [`MAX_INERTIA_KG_M2`].
const INERTIA: Kind = Kind::Number(Rule::Bounded {
    floor: MIN_INERTIA_KG_M2,
    ceil: MAX_INERTIA_KG_M2,
});
/// Largest speed magnitude accepted, rad/s (about 950 000 rpm): of a scene's speeds and of a
/// co-simulation's speed input.
pub const MAX_SPEED_RAD_S: f64 = 1e5;
/// Largest piston pressure accepted, Pa (1000 bar: wet clutch pistons work below 3 MPa,
/// industrial hydraulics below 70 MPa): of a scene's pressures and of a co-simulation's
/// pressure input.
pub const MAX_PRESSURE_PA: f64 = 1e8;
/// Largest torque magnitude accepted, N m (the largest ship drivelines carry about 1e7 N m):
/// of a scene's load torque and of a co-simulation's torque inputs.
pub const MAX_TORQUE_N_M: f64 = 1e7;
/// A piston pressure in Pa: within `[0, MAX_PRESSURE_PA]`.
const PRESSURE: Kind = Kind::Number(Rule::Closed(0.0, MAX_PRESSURE_PA));
/// A torque in N m: within +-[`MAX_TORQUE_N_M`].
const TORQUE: Kind = Kind::Number(Rule::Closed(-MAX_TORQUE_N_M, MAX_TORQUE_N_M));
/// A speed in rad/s: within +-[`MAX_SPEED_RAD_S`].
const SPEED: Kind = Kind::Number(Rule::Closed(-MAX_SPEED_RAD_S, MAX_SPEED_RAD_S));
/// Highest drive frequency accepted, Hz (torsional excitation of a driveline is below 1e4 Hz).
pub(crate) const MAX_FREQUENCY_HZ: f64 = 1e5;
/// A drive frequency in Hz: `> 0` and at most [`MAX_FREQUENCY_HZ`].
const FREQUENCY: Kind = Kind::Number(Rule::Bounded {
    floor: 0.0,
    ceil: MAX_FREQUENCY_HZ,
});
/// Any finite number.
const FINITE: Kind = Kind::Number(Rule::Finite);
/// `> 0`.
const POSITIVE: Kind = Kind::Number(Rule::Positive);
/// `>= 0`.
const NON_NEGATIVE: Kind = Kind::Number(Rule::NonNegative);

table! {
    /// The whole file.
    RawScene at "" {
        /// the scene's name in tables and recordings
        name: "", Kind::Text, Dflt::Described("default: the file name without its extension");
        /// free text
        description: "", Kind::Text, Dflt::Described("default: empty");
    }
    children {
        simulation: table RawSimulation,
        shaft: table RawShaft,
        drive: table RawDrive,
        discs: array RawBody,
        plates: array RawBody,
        drum: table RawDrum,
        stack: table RawStack,
        defaults: table RawBody,
        plate_defaults: table RawBody,
        thermal: table RawThermal,
        bodies: array RawNetBody,
        couplings: array RawCoupling,
        transmission: table RawTransmission,
    }
}

table! {
    /// `[transmission]` (network scenes): an automatic transmission's input and output bodies and its gears, each the set of shift elements (clutches and brakes among the [[couplings]]) closed in it (MODEL.md section 10). `clutchpack check` prints each gear's ratio from the constraints alone, every body's speed per unit input speed and every open element's slip.
    RawTransmission at "transmission" {
        /// the input body (a [[bodies]] name)
        input: "", Kind::Text, Dflt::Required;
        /// the output body (a [[bodies]] name)
        output: "", Kind::Text, Dflt::Required;
        /// the gear engaged at t = 0 (a gear's name); with it the shift schedule sets every element's force (their [couplings.force] is then refused): closed 1, open 0, changed by [[transmission.shifts]]
        initial_gear: "", Kind::Text, Dflt::Described("none: the elements' own [couplings.force]");
        /// with initial_gear: the input's speed at t = 0; every body turning with it (the input's group in the initial gear) starts at its speed per unit input times this (their own initial_speed_rad_s is then refused)
        initial_input_speed_rad_s: "rad/s", SPEED, Dflt::Described("none: the bodies' own initial speeds");
    }
    children {
        gears: array RawGear,
        shifts: array RawShift,
    }
}

table! {
    /// One `[[transmission.shifts]]` entry (with initial_gear): a clutch-to-clutch shift from the gear engaged before it, which opens one element (the off-going) and closes one (the on-coming). Fill: the on-coming rises from 0 to fill_level; torque phase: the off-going falls from 1 to 0 while the on-coming rises to torque_level; inertia phase: the on-coming rises to 1. Linear between these instants (MODEL.md section 10).
    RawShift at "transmission.shifts[]" {
        /// when the shift starts (after the shift before it has ended)
        at_s: "s", NON_NEGATIVE, Dflt::Required;
        /// the gear it reaches (a gear's name; not the one engaged)
        to: "", Kind::Text, Dflt::Required;
        /// the on-coming element's fill (ASSUMED default)
        fill_s: "s", Kind::Number(Rule::Bounded { floor: 1e-4, ceil: 10.0 }), Dflt::Num(0.05);
        /// the on-coming element's normalized force at the end of the fill (its kiss point; ASSUMED default)
        fill_level: "", Kind::Number(Rule::Closed(0.0, 1.0)), Dflt::Num(0.02);
        /// the torque phase (ASSUMED default)
        torque_phase_s: "s", Kind::Number(Rule::Bounded { floor: 1e-4, ceil: 10.0 }), Dflt::Num(0.1);
        /// the on-coming element's normalized force at the end of the torque phase (ASSUMED default)
        torque_level: "", Kind::Number(Rule::Closed(0.0, 1.0)), Dflt::Num(0.1);
        /// the inertia phase (ASSUMED default)
        inertia_phase_s: "s", Kind::Number(Rule::Bounded { floor: 1e-4, ceil: 10.0 }), Dflt::Num(0.2);
    }
    children {}
}

table! {
    /// One `[[transmission.gears]]` entry: a gear.
    RawGear at "transmission.gears[]" {
        /// the gear's name ("1", "R", ...), unique
        name: "", Kind::Text, Dflt::Required;
        /// the shift elements closed in it: names of [[couplings]] of kind clutch or one_way_clutch (a brake: a clutch to a fixed body), or pack (a resolved pack with a [stack]: the schedule sets its piston's pressure, the normalized level times the largest pressure of its pack file's [stack.pressure])
        closed: "", Kind::Texts, Dflt::Required;
    }
    children {}
}

table! {
    /// `[simulation]`.
    RawSimulation at "simulation" {
        /// simulated duration; duration_s x record_rate_hz (the number of samples) is bounded too
        duration_s: "s", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_DURATION_S }), Dflt::Required;
        /// the engine that runs the scene (else --engine, else the CLI chooses: reference for a torsional pack or a network, multibody otherwise)
        engine: "", Kind::Choice(&["reference", "multibody"]), Dflt::Described("optional");
        /// how the engine steps the bodies: auto (multirate where it applies, one shared step otherwise), shared (one step for every body: the multibody shared step, the reference engine's monolithic scheme; the oracle), multirate (an error for a pack the engine cannot run so)
        scheme: "", Kind::Choice(&["auto", "shared", "multirate"]), Dflt::Described("auto");
        /// rate of the output samples (impacts are located exactly whatever it is)
        record_rate_hz: "Hz", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_RECORD_RATE_HZ }), Dflt::Num(10_000.0);
        /// relative tolerance of the adaptive integrators
        tolerance: "", Kind::Number(Rule::Closed(1e-14, 1e-3)), Dflt::Num(1e-9);
        /// longest step of the adaptive integrators
        max_step_s: "s", Kind::Number(Rule::Bounded { floor: MIN_MAX_STEP_S, ceil: f64::INFINITY }), Dflt::Num(1e-4);
        /// record per-tooth loads where the engine resolves teeth
        record_per_tooth: "", Kind::Bool, Dflt::Bool(false);
        /// record each disc's load at the engine's steps inside every contact too (/discs/<disc>/load: the plotted pulses reach the impact peaks)
        record_contact_samples: "", Kind::Bool, Dflt::Bool(true);
    }
    children {}
}

table! {
    /// `[shaft]`.
    RawShaft at "shaft" {
        /// "prescribed": the shaft follows the drive's speed; "inertial": the drive acts on its inertia
        mode: "", Kind::Choice(&["prescribed", "inertial"]), Dflt::Choice("prescribed");
        /// shaft inertia J1
        inertia_kg_m2: "kg m^2", INERTIA, Dflt::When("required if inertial, an error if prescribed");
        /// shaft damping C1 (inertial only)
        damping_n_m_s_rad: "N m s/rad", NON_NEGATIVE, Dflt::Num(0.0);
        /// starting speed of the shaft
        initial_speed_rad_s: "rad/s", SPEED, Dflt::When("required with drive.kind = \"torque_table\", an error otherwise");
    }
    children {}
}

table! {
    /// `[drive]`.
    RawDrive at "drive" {
        /// what drives the shaft (in [bodies.speed], a network body's prescribed speed: sine, harmonics or speed_table)
        kind: "", Kind::Choice(&["sine", "harmonics", "speed_table", "torque_table"]), Dflt::Required;
        /// mean shaft speed
        omega0_rad_s: "rad/s", SPEED, Dflt::When("required for sine and harmonics");
        /// speed amplitude (Hu et al. eq (3))
        amplitude_rad_s: "rad/s", SPEED, Dflt::When("sine: required");
        /// excitation frequency
        frequency_hz: "Hz", FREQUENCY, Dflt::When("sine: required");
        /// phase of the sine (sine only)
        phase_deg: "deg", FINITE, Dflt::Num(0.0);
        /// CSV with a header row, relative to the scene file's folder; speed_table: columns time_s, speed_rad_s; torque_table: columns time_s, torque_n_m (needs shaft.mode = "inertial")
        file: "", Kind::Text, Dflt::When("required for speed_table and torque_table");
        /// speed_table and torque_table: "linear" between rows, or "hold": each row's value held until the next row (a zero-order hold, as a co-simulation master gives its inputs; a held speed table runs with a step ending at every row)
        interpolation: "", Kind::Choice(&["linear", "hold"]), Dflt::Choice("linear");
    }
    children {
        harmonics: array RawHarmonic,
    }
}

table! {
    /// One `[[drive.harmonics]]` entry (drive.kind = "harmonics": at least one).
    RawHarmonic at "drive.harmonics[]" {
        /// amplitude of this term
        amplitude_rad_s: "rad/s", SPEED, Dflt::Required;
        /// frequency of this term
        frequency_hz: "Hz", FREQUENCY, Dflt::Required;
        /// phase of this term
        phase_deg: "deg", FINITE, Dflt::Num(0.0);
    }
    children {}
}

table! {
    /// `[drum]`: the output drum of a clutch (the plates sit on it, else on the housing).
    RawDrum at "drum" {
        /// drum inertia
        inertia_kg_m2: "kg m^2", INERTIA, Dflt::When("required with [drum]");
        /// load on the drum about the axis (negative brakes it)
        load_torque_n_m: "N m", TORQUE, Dflt::Num(0.0);
        /// drum drag
        drag_n_m_s_rad: "N m s/rad", NON_NEGATIVE, Dflt::Num(0.0);
        /// starting speed of the drum
        initial_speed_rad_s: "rad/s", SPEED, Dflt::Num(0.0);
    }
    children {}
}

/// Largest torsional stiffness of a coupling accepted, N m/rad (a solid steel shaft of 100 mm
/// diameter and 10 mm length is about 8e7 N m/rad).
pub(crate) const MAX_COUPLING_STIFFNESS_N_M_PER_RAD: f64 = 1e9;

table! {
    /// `[stack]`: the piston, the clamped stack and its friction faces.
    RawStack at "stack" {
        /// inner radius of the friction faces
        face_inner_radius_m: "m", POSITIVE, Dflt::When("required with [stack]");
        /// outer radius of the friction faces, > face_inner_radius_m
        face_outer_radius_m: "m", POSITIVE, Dflt::When("required with [stack]");
        /// axial spline friction holds back mu n |F| per body
        spline_friction_coefficient: "", NON_NEGATIVE, Dflt::Num(0.0);
        /// piston area
        piston_area_m2: "m^2", POSITIVE, Dflt::When("required with [stack]");
        /// piston force = p A - return spring, never < 0
        return_spring_n: "N", NON_NEGATIVE, Dflt::Num(0.0);
    }
    children {
        friction: table RawFriction,
        pressure: table RawPressure,
        open_gap: table RawOpenGap,
    }
}

table! {
    /// `[stack.friction]`.
    RawFriction at "stack.friction" {
        /// the friction law of the faces
        kind: "", Kind::Choice(&["stribeck", "table"]), Dflt::Choice("stribeck");
        /// mu at zero slip
        static_mu: "", POSITIVE, Dflt::When("stribeck: required");
        /// mu beyond the Stribeck speed
        kinetic_mu: "", POSITIVE, Dflt::Described("stribeck: default static_mu");
        /// the Stribeck speed (stribeck only)
        stribeck_speed_m_s: "m/s", POSITIVE, Dflt::Num(1.0);
        /// mu rises by this per m/s of slip (stribeck only)
        viscous_slope_s_m: "s/m", NON_NEGATIVE, Dflt::Num(0.0);
        /// slip speeds, increasing from 0
        slip_m_s: "m/s", Kind::Numbers, Dflt::When("table: required");
        /// mu > 0, one per slip_m_s
        mu: "", Kind::Numbers, Dflt::When("table: required");
    }
    children {}
}

table! {
    /// `[stack.pressure]`.
    RawPressure at "stack.pressure" {
        /// the piston pressure history
        kind: "", Kind::Choice(&["constant", "ramp", "table"]), Dflt::When("required with [stack]");
        /// the (final) pressure
        pressure_pa: "Pa", PRESSURE, Dflt::When("constant and ramp: required");
        /// when the rise starts (ramp only)
        start_s: "s", NON_NEGATIVE, Dflt::Num(0.0);
        /// rise time
        rise_s: "s", POSITIVE, Dflt::When("ramp: required");
        /// times, increasing
        times_s: "s", Kind::Numbers, Dflt::When("table: required");
        /// pressures in [0, 1e8], one per times_s
        values_pa: "Pa", Kind::Numbers, Dflt::When("table: required");
    }
    children {}
}

table! {
    /// `[stack.open_gap]`: viscous drag across the gaps of an open pack.
    RawOpenGap at "stack.open_gap" {
        /// oil in the open gaps
        viscosity_pa_s: "Pa s", POSITIVE, Dflt::When("required with [stack.open_gap]");
        /// axial gap per open interface
        gap_m: "m", POSITIVE, Dflt::When("required with [stack.open_gap]");
    }
    children {}
}

table! {
    /// A body's parameters: one `[[discs]]` or `[[plates]]` entry, or `[defaults]` /
    /// `[plate_defaults]` (every key but `name`). Keys resolve as: the entry's, else the
    /// defaults table's, else the built-in default.
    RawBody at "" {
        /// unique among discs and plates (only in [[discs]] and [[plates]] entries)
        name: "", Kind::Text, Dflt::Described("default \"disc-<i+1>\" or \"plate-<j+1>\"");
        /// body inertia J2
        inertia_kg_m2: "kg m^2", INERTIA, Dflt::Required;
        /// oil drag C2
        drag_n_m_s_rad: "N m s/rad", NON_NEGATIVE, Dflt::Num(0.0);
        /// phi(0) = theta_shaft - theta_disc; must lie inside the free play
        initial_rel_angle_rad: "rad", FINITE, Dflt::Num(0.0);
        /// omega_shaft(0) - omega_disc(0)
        initial_rel_speed_rad_s: "rad/s", SPEED, Dflt::Num(0.0);
        /// the disc may move radially on its spline (multibody engine only)
        radial_float: "", Kind::Bool, Dflt::Bool(false);
        /// one per tooth (tooth k at 2 pi k / n from the shaft's +x axis) or none; circumferential spacing error at the pitch circle, positive closes the shaft-leads gap (multibody engine only)
        tooth_spacing_errors_m: "m", Kind::Numbers, Dflt::Described("default empty");
        /// [x, y] in the shaft's frame: the centre's offset from the axis at t = 0 (held there unless radial_float; multibody engine only)
        initial_offset_m: "m", Kind::Numbers, Dflt::Described("default [0, 0]");
    }
    children {
        spline: table RawSpline,
        contact: table RawContact,
        oil: table RawOil,
        fatigue: table RawToothForm,
        material: table RawMaterial,
    }
}

table! {
    /// `spline` of a body.
    RawSpline at "spline" {
        /// number of teeth n
        teeth: "", Kind::Count { max: MAX_TEETH }, Dflt::Required;
        /// pitch radius R
        pitch_radius_m: "m", Kind::Number(Rule::Bounded { floor: MIN_PITCH_RADIUS_M, ceil: MAX_PITCH_RADIUS_M }), Dflt::Required;
        /// pressure angle alpha
        pressure_angle_deg: "deg", Kind::Number(Rule::Open(0.0, 90.0)), Dflt::Required;
        /// total circumferential free play d at the pitch circle; below the tooth pitch 2 pi R / n
        backlash_m: "m", POSITIVE, Dflt::Required;
    }
    children {}
}

table! {
    /// `contact` of a body.
    RawContact at "contact" {
        /// the tooth law (MODEL.md section 2)
        law: "", Kind::Choice(&["paper", "dry", "squeeze"]), Dflt::Choice("paper");
        /// equivalent modulus E
        modulus_pa: "Pa", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_MODULUS_PA }), Dflt::Required;
        /// equivalent curvature radius r
        curvature_radius_m: "m", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_CURVATURE_RADIUS_M }), Dflt::Required;
        /// impact loss p
        loss_coefficient_s_m: "s/m", Kind::Number(Rule::Closed(0.0, MAX_LOSS_COEFFICIENT_S_M)), Dflt::Num(0.0);
    }
    children {}
}

table! {
    /// `oil` of a body.
    RawOil at "oil" {
        /// film thickness h_o; below half the free play along the line of action
        film_thickness_m: "m", NON_NEGATIVE, Dflt::Num(0.0);
        /// oil viscosity
        viscosity_pa_s: "Pa s", POSITIVE, Dflt::When("required if film_thickness_m > 0 and law is not dry");
        /// leakage coefficient beta
        leakage_coefficient: "", POSITIVE, Dflt::When("required like viscosity_pa_s");
        /// film width B
        width_m: "m", POSITIVE, Dflt::When("required like viscosity_pa_s");
        /// film length L
        length_m: "m", POSITIVE, Dflt::When("required like viscosity_pa_s");
        /// floor of the held closing speed
        v_floor_m_s: "m/s", POSITIVE, Dflt::Num(0.01);
        /// smallest film of the squeeze law
        h_min_m: "m", POSITIVE, Dflt::Num(1e-6);
    }
    children {}
}

table! {
    /// `fatigue` of a body: the tooth form for the root stress and flank pressure (MODEL.md
    /// section 7; ISO 6336-3's factors applied to the spline tooth). Defaults ASSUMED for the
    /// paper's disc (docs/DECISIONS.md, "Fatigue").
    RawToothForm at "fatigue" {
        /// tooth form factor Y_F of sigma_F = F_t / (b m) Y_F Y_S K_l; ASSUMED default: ISO 6336-3 for a rack-like 20 deg tooth
        form_factor: "", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_TOOTH_FACTOR }), Dflt::Num(fat::DEFAULT_FORM_FACTOR);
        /// stress correction factor Y_S (root fillet notch); ASSUMED default: ISO 6336-3, basic rack fillet
        stress_correction_factor: "", Kind::Number(Rule::Closed(1.0, MAX_TOOTH_FACTOR)), Dflt::Num(fat::DEFAULT_STRESS_CORRECTION);
        /// axial load distribution factor K_l: peak over mean line load along the face
        load_distribution_factor: "", Kind::Number(Rule::Closed(1.0, MAX_TOOTH_FACTOR)), Dflt::Num(fat::DEFAULT_LOAD_DISTRIBUTION);
        /// engaged face width b (the disc's thickness)
        face_width_m: "m", Kind::Number(Rule::Bounded { floor: TOOTH_SIZE_RANGE_M.0, ceil: TOOTH_SIZE_RANGE_M.1 }), Dflt::Num(fat::DEFAULT_FACE_WIDTH_M);
        /// working depth h_w of the flank pressure p = F_t / (b h_w); ASSUMED default 0.9 m of the paper's 3 mm module
        working_depth_m: "m", Kind::Number(Rule::Bounded { floor: TOOTH_SIZE_RANGE_M.0, ceil: TOOTH_SIZE_RANGE_M.1 }), Dflt::Num(fat::DEFAULT_WORKING_DEPTH_M);
    }
    children {}
}

table! {
    /// `material` of a body: the S-N curve of the tooth root (Basquin with a knee) and the
    /// failure criterion (MODEL.md section 7). Defaults ASSUMED for a through-hardened steel
    /// disc core (ISO 6336-5 MQ; docs/DECISIONS.md, "Fatigue").
    RawMaterial at "material" {
        /// endurance limit S_D as a root stress amplitude at knee_cycles; ASSUMED default: sigma_Flim of through-hardened steel (ISO 6336-5 MQ)
        endurance_amplitude_pa: "Pa", Kind::Number(Rule::Bounded { floor: ENDURANCE_RANGE_PA.0, ceil: ENDURANCE_RANGE_PA.1 }), Dflt::Num(fat::DEFAULT_ENDURANCE_AMPLITUDE_PA);
        /// cycles N_D at the knee of the S-N curve
        knee_cycles: "", Kind::Number(Rule::Bounded { floor: KNEE_CYCLES_RANGE.0, ceil: KNEE_CYCLES_RANGE.1 }), Dflt::Num(fat::DEFAULT_KNEE_CYCLES);
        /// Basquin exponent k above the knee, N = N_D (S_D / S)^k; ASSUMED default from ISO 6336-3's life factor
        slope: "", Kind::Number(Rule::Open(1.0, MAX_SN_SLOPE)), Dflt::Num(fat::DEFAULT_SLOPE);
        /// below the knee: no damage (original), slope k (elementary) or slope 2k - 1 (haibach)
        miner_rule: "", Kind::Choice(&["original", "elementary", "haibach"]), Dflt::Choice(fat::DEFAULT_MINER_RULE.name());
        /// Miner damage sum at failure D_crit
        critical_damage: "", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_CRITICAL_DAMAGE }), Dflt::Num(fat::DEFAULT_CRITICAL_DAMAGE);
    }
    children {}
}

/// Lowest temperature accepted, K (a cold start at -120 deg C is far below any oil's pour
/// point).
pub(crate) const MIN_TEMPERATURE_K: f64 = 150.0;
/// Highest temperature accepted, K (a paper lining chars near 600 K; steel glows at 1000 K).
pub(crate) const MAX_TEMPERATURE_K: f64 = 1000.0;
/// A temperature in K, within the plausibility bounds [`MIN_TEMPERATURE_K`], [`MAX_TEMPERATURE_K`].
const TEMPERATURE: Kind = Kind::Number(Rule::Bounded {
    floor: MIN_TEMPERATURE_K,
    ceil: MAX_TEMPERATURE_K,
});
/// A thickness of a disc's core or lining or of a plate, m.
const THICKNESS: Kind = Kind::Number(Rule::Bounded {
    floor: 1e-5,
    ceil: 0.1,
});

/// Smallest heat capacity of a thermal body or of the oil accepted, J/K (2 g of steel is
/// about 1 J/K; the thinnest real plate, 85 J/K). Issue 48: `1e-9` J/K passed `check` and
/// made the thermal window's sub-steps explode.
pub(crate) const MIN_HEAT_CAPACITY_J_K: f64 = 1e-2;
/// A heat capacity in J/K: at least [`MIN_HEAT_CAPACITY_J_K`].
const HEAT_CAPACITY: Kind = Kind::Number(Rule::Bounded {
    floor: MIN_HEAT_CAPACITY_J_K,
    ceil: f64::INFINITY,
});
/// Largest cooler capacity rate accepted, W/K (500 kg/s of oil through the cooler; a
/// transmission's is 10 to 1000 W/K).
pub(crate) const MAX_COOLER_RATE_W_K: f64 = 1e6;
/// Largest heat transfer coefficient of a face accepted, W/(m^2 K) (boiling water is below
/// 1e5; an oil film on a clutch face, 1e2 to 1e4).
pub(crate) const MAX_HEAT_TRANSFER_W_M2_K: f64 = 1e6;
/// Smallest laminar oil gap accepted, m (1 um; a clutch's open gaps are 0.05 to 1 mm).
pub(crate) const MIN_OIL_GAP_M: f64 = 1e-6;
/// Largest thermal conductivity of the oil accepted, W/(m K) (copper's is 400; an oil's, 0.13).
pub(crate) const MAX_CONDUCTIVITY_W_M_K: f64 = 1e3;

table! {
    /// `[thermal]`: temperatures of every disc, plate and the oil, fed back into the tooth film and the open gaps' drag (MODEL.md section 9; both engines: the reference engine's monolithic scheme, either scheme of the multibody engine). Temperatures in K.
    RawThermal at "thermal" {
        /// temperature of every body and the oil at t = 0
        initial_temperature_k: "K", TEMPERATURE, Dflt::Required;
        /// where the tooth films' oil.viscosity_pa_s hold: the film scale is eta(T_oil) / eta(T_ref), exactly 1 there
        reference_temperature_k: "K", TEMPERATURE, Dflt::Described("default initial_temperature_k (the scene's film viscosities are taken as calibrated where the run starts)");
        /// thermal window: the temperatures, the film scale and the gaps' viscosity advance once per window (operator splitting, first order in it); the update lands on the first step ending at or after each multiple
        step_s: "s", Kind::Number(Rule::Bounded { floor: 1e-6, ceil: 10.0 }), Dflt::Num(1e-3);
        /// the open gaps' viscosity: "absolute" eta(T_oil) of the law, or "scaled": stack.open_gap.viscosity_pa_s times the film scale (for an effective, calibrated gap viscosity)
        gap_viscosity: "", Kind::Choice(&["absolute", "scaled"]), Dflt::Choice("absolute");
    }
    children {
        oil: table RawThermalOil,
        convection: table RawConvection,
        discs: table RawThermalDiscs,
        plates: table RawThermalPlates,
        friction: table RawThermalFriction,
    }
}

table! {
    /// `[thermal.friction]`: the faces' friction coefficient against slip speed and temperature, mu(v, T) (MODEL.md section 9): bilinear between the points, held at the table's edges (no extrapolation). At every thermal window's end each face takes mu(v, T_face) at the hotter of its two bodies' temperatures, in place of [stack.friction]. Without it the faces keep [stack.friction] all the run.
    RawThermalFriction at "thermal.friction" {
        /// slip speeds at the effective radius, from >= 0, strictly increasing, at least 2
        speeds_m_s: "m/s", Kind::Numbers, Dflt::When("required with [thermal.friction]");
        /// face temperatures, strictly increasing, at least 2
        temperatures_k: "K", Kind::Numbers, Dflt::When("required with [thermal.friction]");
        /// one row per speeds_m_s, each with one mu >= 0 per temperatures_k: mu = [[mu(v0, T0), mu(v0, T1), ...], [mu(v1, T0), ...], ...]
        mu: "", Kind::NumberRows, Dflt::When("required with [thermal.friction]");
    }
    children {}
}

table! {
    /// `[thermal.oil]`: the oil's viscosity law, its volume and the cooler.
    RawThermalOil at "thermal.oil" {
        /// viscosity law: "walther" (ASTM D341, two kinematic viscosities), "vogel" (three dynamic viscosities) or "table" (ln eta linear between rows, held beyond them)
        law: "", Kind::Choice(&["walther", "vogel", "table"]), Dflt::Required;
        /// increasing temperatures of the law's points: 2 for walther, 3 for vogel, at least 2 for a table
        temperatures_k: "K", Kind::Numbers, Dflt::Required;
        /// walther: the kinematic viscosities at temperatures_k, decreasing, > 0.3e-6
        kinematic_viscosities_m2_s: "m^2/s", Kind::Numbers, Dflt::When("walther: required, an error otherwise");
        /// vogel and table: the dynamic viscosities at temperatures_k, decreasing
        viscosities_pa_s: "Pa s", Kind::Numbers, Dflt::When("vogel and table: required, an error for walther");
        /// walther: density for eta = nu rho; ASSUMED default: an ATF near 80 deg C
        density_kg_m3: "kg/m^3", Kind::Number(Rule::Bounded { floor: 100.0, ceil: 3000.0 }), Dflt::Num(850.0);
        /// heat capacity m c_p of the oil volume (sump or cooling flow)
        heat_capacity_j_k: "J/K", HEAT_CAPACITY, Dflt::Required;
        /// the cooler's capacity rate m_dot c_p; 0: no cooler
        cooler_capacity_rate_w_k: "W/K", Kind::Number(Rule::Closed(0.0, MAX_COOLER_RATE_W_K)), Dflt::Num(0.0);
        /// temperature of the oil the cooler returns
        inlet_temperature_k: "K", TEMPERATURE, Dflt::Described("default thermal.initial_temperature_k");
        /// thermal conductivity lambda of the oil (laminar_gap convection); ASSUMED default: an ATF
        conductivity_w_m_k: "W/(m K)", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_CONDUCTIVITY_W_M_K }), Dflt::Num(0.13);
    }
    children {}
}

table! {
    /// `[thermal.convection]`: heat from each body's two faces to the oil, h A (T - T_oil).
    RawConvection at "thermal.convection" {
        /// "adiabatic" (none), "given" (h_w_m2_k) or "laminar_gap": h = 7.541 lambda / (2 s), fully developed, both walls heated (VDI Heat Atlas Gb 7)
        kind: "", Kind::Choice(&["adiabatic", "given", "laminar_gap"]), Dflt::Choice("laminar_gap");
        /// given: the heat transfer coefficient of every face
        h_w_m2_k: "W/(m^2 K)", Kind::Number(Rule::Bounded { floor: 0.0, ceil: MAX_HEAT_TRANSFER_W_M2_K }), Dflt::When("given: required, an error otherwise");
        /// laminar_gap: the oil gap s at each face
        gap_m: "m", Kind::Number(Rule::Bounded { floor: MIN_OIL_GAP_M, ceil: f64::INFINITY }), Dflt::Described("laminar_gap: default stack.open_gap.gap_m, else required; an error otherwise");
    }
    children {}
}

table! {
    /// `[thermal.discs]`: every friction disc: a steel core between two paper linings on the faces' annulus (stack.face_inner_radius_m to face_outer_radius_m); its faces are the linings'.
    RawThermalDiscs at "thermal.discs" {
        /// thickness of the steel core; ASSUMED default
        core_thickness_m: "m", THICKNESS, Dflt::Num(1.0e-3);
        /// thickness of each of the two linings; ASSUMED default
        lining_thickness_m: "m", THICKNESS, Dflt::Num(0.5e-3);
        /// heat capacity m c of one disc, instead of the geometry's
        heat_capacity_j_k: "J/K", HEAT_CAPACITY, Dflt::Described("default: steel core and paper linings (clutchpack_model::thermal::ThermalProperties)");
    }
    children {}
}

table! {
    /// `[thermal.plates]`: every separator plate: a steel annulus on the faces' annulus.
    RawThermalPlates at "thermal.plates" {
        /// thickness of a plate; ASSUMED default: MODEL.md section 9's plate
        thickness_m: "m", THICKNESS, Dflt::Num(1.8e-3);
        /// heat capacity m c of one plate, instead of the geometry's
        heat_capacity_j_k: "J/K", HEAT_CAPACITY, Dflt::Described("default: steel (clutchpack_model::thermal::ThermalProperties::STEEL)");
    }
    children {}
}

/// The signal kinds of a network's drives and clutch forces (`clutchpack_model::network::Signal`).
const SIGNAL_KINDS: Kind = Kind::Choice(&["constant", "step", "ramp", "sine", "table"]);

table! {
    /// One `[[bodies]]` entry: a rotational body of a driveline network (MODEL.md section 8): free (its inertia), fixed (`fixed = true`) or at a prescribed speed (a `[bodies.speed]` table, the forms of `[drive]`: sine, harmonics, speed_table; its motion given whatever the torques on it, its reaction reported, no inertia, drive, firing, road load or drag). A scene with `[[bodies]]` is a network scene: its bodies and `[[couplings]]` replace `[shaft]`, `[drive]`, `[[discs]]`, `[[plates]]`, `[drum]` and `[stack]`; a resolved pack is a coupling of kind "pack" naming its pack scene file.
    RawNetBody at "" {
        /// the body's name, unique; couplings name their bodies by it
        name: "", Kind::Text, Dflt::Required;
        /// inertia about its axis
        inertia_kg_m2: "kg m^2", INERTIA, Dflt::When("required, an error for a fixed or prescribed body");
        /// viscous drag: the torque -C w
        drag_n_m_s_rad: "N m s/rad", NON_NEGATIVE, Dflt::Num(0.0);
        /// speed at t = 0 (the speeds of bodies joined by ideal gears must mesh; an error for a prescribed body, which starts at its profile's)
        initial_speed_rad_s: "rad/s", SPEED, Dflt::Num(0.0);
        /// a fixed body (the housing): it never turns; a clutch to it is a brake
        fixed: "", Kind::Bool, Dflt::Bool(false);
    }
    children {
        speed: table RawDrive,
        drive: table RawTorqueSignal,
        firing: table RawFiring,
        road_load: table RawRoadLoad,
    }
}

/// Most cylinders of an engine accepted (a plausibility bound: W16 and V24 engines exist).
pub(crate) const MAX_CYLINDERS: u32 = 24;
/// Most firing-order harmonics of one engine accepted (a plausibility bound: an engine's
/// torque spectrum above the 12th multiple of its firing order is below measurement noise;
/// each term costs every step a sine).
pub(crate) const MAX_FIRING_HARMONICS: usize = 64;
/// Largest magnitude of a clutch's normalized normal force accepted (`[couplings.force]`'s
/// values and table rows; the normal force is `max_normal_force_n` times it, 1 when fully
/// applied in Modelica's convention).
pub const MAX_FORCE_SIGNAL: f64 = 1e3;
/// A normalized clutch force: within +-[`MAX_FORCE_SIGNAL`].
const FORCE: Kind = Kind::Number(Rule::Closed(-MAX_FORCE_SIGNAL, MAX_FORCE_SIGNAL));
/// Largest free angle of a spring-damper accepted, rad (160 turns: a wound spring's preload
/// is a few turns at most); its preload torque `k theta_0` is held to [`MAX_TORQUE_N_M`] too.
pub(crate) const MAX_FREE_ANGLE_RAD: f64 = 1e3;
/// Largest normal force of a lumped clutch accepted, N (a wet clutch's piston carries about
/// 1e4 to 1e5 N; the largest industrial brakes below 1e7 N).
pub const MAX_NORMAL_FORCE_N: f64 = 1e8;

table! {
    /// `[bodies.firing]`: an engine's firing-order harmonics, added to its drive and locked to the body's own angle theta (0 at t = 0): sum_k a_k sin(k n_f theta + phi_k) with n_f = 2 cylinders / strokes firings a revolution (docs/DECISIONS.md, "An engine's firing harmonics").
    RawFiring at "firing" {
        /// number of cylinders z
        cylinders: "", Kind::Count { max: MAX_CYLINDERS }, Dflt::Required;
        /// strokes of the working cycle: 4 (each cylinder fires every second revolution) or 2
        strokes: "", Kind::Count { max: 4 }, Dflt::Described("default 4");
        /// a_k: amplitude of the k-th multiple of the firing order (k = 1, 2, ... in order)
        amplitudes_n_m: "N m", Kind::Numbers, Dflt::Required;
        /// phi_k: phase of each term at theta = 0, one per amplitude
        phases_deg: "deg", Kind::Numbers, Dflt::Described("default all 0");
    }
    children {}
}

table! {
    /// `[bodies.drive]`: a driving torque on the body, positive in its sense of rotation.
    RawTorqueSignal at "drive" {
        /// "constant" (value_n_m), "step" (offset_n_m, then + height_n_m from start_s), "ramp" (offset_n_m rising by height_n_m over duration_s from start_s), "sine" (offset_n_m + amplitude_n_m sin(2 pi f (t - start_s) + phase) from start_s), "table" (file)
        kind: "", SIGNAL_KINDS, Dflt::Required;
        /// constant: the torque
        value_n_m: "N m", TORQUE, Dflt::When("constant: required");
        /// step, ramp, sine: the torque before start_s (sine: the mean)
        offset_n_m: "N m", TORQUE, Dflt::Num(0.0);
        /// step, ramp: the change
        height_n_m: "N m", TORQUE, Dflt::When("step and ramp: required");
        /// sine: the amplitude
        amplitude_n_m: "N m", TORQUE, Dflt::When("sine: required");
        /// sine: the frequency
        frequency_hz: "Hz", FREQUENCY, Dflt::When("sine: required");
        /// sine: the phase at start_s
        phase_deg: "deg", FINITE, Dflt::Num(0.0);
        /// step, ramp, sine: when it starts
        start_s: "s", NON_NEGATIVE, Dflt::Num(0.0);
        /// ramp: its length
        duration_s: "s", POSITIVE, Dflt::When("ramp: required");
        /// table: CSV with a header row and columns time_s, torque_n_m, relative to the scene file's folder
        file: "", Kind::Text, Dflt::When("table: required");
        /// table: "linear" between rows, or "hold" (each row's value until the next)
        interpolation: "", Kind::Choice(&["linear", "hold"]), Dflt::Choice("linear");
    }
    children {}
}

table! {
    /// `[bodies.road_load]`: a load opposing motion, -sign(w) (a + b |w| + c w^2), zero at rest (a vehicle reduced to a shaft).
    RawRoadLoad at "road_load" {
        /// a: the constant part (rolling resistance)
        constant_n_m: "N m", Kind::Number(Rule::Closed(0.0, MAX_TORQUE_N_M)), Dflt::Num(0.0);
        /// b: the part proportional to speed
        linear_n_m_s_rad: "N m s/rad", NON_NEGATIVE, Dflt::Num(0.0);
        /// c: the part proportional to speed squared (air drag)
        quadratic_n_m_s2_rad2: "N m s^2/rad^2", Kind::Number(Rule::Closed(0.0, MAX_TORQUE_N_M)), Dflt::Num(0.0);
    }
    children {}
}

table! {
    /// One `[[couplings]]` entry: a coupling between bodies a and b (MODEL.md section 8): in a network scene between two of its [[bodies]]; in a one-pack scene (no [[bodies]]) a spring_damper between its shaft and its drum. Signs: a clutch's slip is w_b - w_a and its torque acts +tau on a, -tau on b (Modelica's flanges); an ideal gear ties w_a = ratio w_b; a gear mesh's force F, signed as x, acts -Rb_a F on a and -Rb_b F on b (internal: +Rb_b F); a spring_damper's torque T = k (theta_a - theta_b - theta_0) + d (w_a - w_b) acts +T on b, -T on a; a planetary set's torque is the one on its sun (a).
    RawCoupling at "" {
        /// the coupling's name, unique (tables, summaries and figures name it)
        name: "", Kind::Text, Dflt::Described("default \"<kind>-<i+1>\" (\"clutch-2\")");
        /// "clutch": a lumped friction clutch (Modelica's Rotational.Components.Clutch; a brake when one body is fixed); "ideal_gear": a rigid gear without backlash; "gear_mesh": a gear pair with backlash and the tooth law of [couplings.contact] and [couplings.oil] along its line of action (gear rattle); "spring_damper": a torsional spring with a viscous damper in parallel (a clutch damper, a dual-mass flywheel; one-pack scenes, between "shaft" and "drum"); "pack": a resolved pack of the pack scene in `pack` (network scenes), its friction discs on body a, its plates on body b; "planetary": a simple planetary set, its sun body a, its ring body b, its carrier `carrier` (Willis: z_S w_S + z_R w_R = (z_S + z_R) w_C; MODEL.md section 10); "one_way_clutch": a freewheel in parallel with a lumped clutch (Modelica's OneWayClutch: w_b - w_a never turns negative; the clutch's keys); "freewheel": a one-way clutch without a clutch (no keys of its own)
        kind: "", Kind::Choice(&["clutch", "ideal_gear", "gear_mesh", "spring_damper", "pack", "planetary", "one_way_clutch", "freewheel"]), Dflt::Required;
        /// the name of body a (a one-pack scene: "shaft" or "drum", the drum with [drum]; a prescribed shaft drives b through a spring_damper)
        a: "", Kind::Text, Dflt::Required;
        /// the name of body b, not a
        b: "", Kind::Text, Dflt::Required;
        /// ideal_gear: w_a / w_b (negative: b turns the other way)
        ratio: "", FINITE, Dflt::When("ideal_gear: required, an error otherwise");
        /// clutch: the sliding friction coefficient, constant (or mu_speeds_rad_s with mu_values)
        mu: "", NON_NEGATIVE, Dflt::When("clutch: mu, or mu_speeds_rad_s with mu_values");
        /// clutch: increasing slip speeds (>= 0) of a friction table, linear between rows and extrapolated from the last two (Modelica's mu_pos)
        mu_speeds_rad_s: "rad/s", Kind::Numbers, Dflt::When("clutch: with mu_values, instead of mu");
        /// clutch: the friction coefficients at mu_speeds_rad_s
        mu_values: "", Kind::Numbers, Dflt::When("clutch: with mu_speeds_rad_s");
        /// clutch: static over sliding friction at zero slip, >= 1
        peak: "", Kind::Number(Rule::Closed(1.0, 100.0)), Dflt::Num(1.0);
        /// clutch: torque per friction force, N (ro + ri) / 2 for N faces under uniform wear (Modelica's cgeo)
        cgeo_m: "m", NON_NEGATIVE, Dflt::Num(1.0);
        /// clutch: the normal force at force = 1 (Modelica's fn_max)
        max_normal_force_n: "N", Kind::Number(Rule::Closed(0.0, MAX_NORMAL_FORCE_N)), Dflt::When("clutch: required");
        /// gear_mesh: base radius of the gear on body a
        base_radius_a_m: "m", Kind::Number(Rule::Bounded { floor: MIN_PITCH_RADIUS_M, ceil: MAX_PITCH_RADIUS_M }), Dflt::When("gear_mesh: required");
        /// gear_mesh: base radius of the gear on body b
        base_radius_b_m: "m", Kind::Number(Rule::Bounded { floor: MIN_PITCH_RADIUS_M, ceil: MAX_PITCH_RADIUS_M }), Dflt::When("gear_mesh: required");
        /// gear_mesh: an internal mesh (a ring gear: b turns the same way as a); else external
        internal: "", Kind::Bool, Dflt::Bool(false);
        /// gear_mesh: backlash along the line of action (the free travel from flank to flank)
        backlash_m: "m", POSITIVE, Dflt::When("gear_mesh: required");
        /// gear_mesh: tooth pairs sharing the load (the contact ratio's whole part)
        pairs: "", Kind::Number(Rule::Closed(1.0, 10.0)), Dflt::Num(1.0);
        /// gear_mesh: relative displacement x = Rb_a theta_a +- Rb_b theta_b at t = 0 (0: centred in the backlash); |x| + the film must be < backlash_m / 2
        mesh_offset_m: "m", FINITE, Dflt::Num(0.0);
        /// spring_damper: torsional stiffness k
        stiffness_n_m_per_rad: "N m/rad", Kind::Number(Rule::Closed(0.0, MAX_COUPLING_STIFFNESS_N_M_PER_RAD)), Dflt::When("spring_damper: required");
        /// spring_damper: viscous damping d
        damping_n_m_s_per_rad: "N m s/rad", NON_NEGATIVE, Dflt::Num(0.0);
        /// pack: a pack scene file (its [[discs]], [[plates]], [stack], ... as a pack scene has them; relative to this scene's folder); its [shaft], [drive], [drum] and [simulation] are not used here: bodies a and b carry it
        pack: "", Kind::Text, Dflt::When("pack: required");
        /// planetary: the name of the carrier body (a third body, not a or b)
        carrier: "", Kind::Text, Dflt::When("planetary: required");
        /// planetary: the sun's teeth z_S
        sun_teeth: "", Kind::Count { max: clutchpack_model::network::planetary::MAX_TEETH }, Dflt::When("planetary: required");
        /// planetary: the ring's teeth z_R (> z_S; a simple set's z_R - z_S even: the planets have (z_R - z_S) / 2)
        ring_teeth: "", Kind::Count { max: clutchpack_model::network::planetary::MAX_TEETH }, Dflt::When("planetary: required");
        /// planetary: a double-pinion set (a Ravigneaux set's building block: z_S w_S - z_R w_R = (z_S - z_R) w_C, the ring turning the other way relative to the carrier)
        double_pinion: "", Kind::Bool, Dflt::Bool(false);
        /// spring_damper: free angle theta_0, the twist theta_a - theta_b at which the spring carries no torque (both bodies start at angle 0, so a non-zero theta_0 starts the spring twisted)
        free_angle_rad: "rad", Kind::Number(Rule::Closed(-MAX_FREE_ANGLE_RAD, MAX_FREE_ANGLE_RAD)), Dflt::Num(0.0);
    }
    children {
        force: table RawForceSignal,
        contact: table RawContact,
        oil: table RawOil,
    }
}

table! {
    /// `[couplings.force]`: a clutch's normalized normal force f(t) (the normal force is max_normal_force_n f; engaged while > 0).
    RawForceSignal at "force" {
        /// "constant" (value), "step" (offset, then + height from start_s), "ramp" (offset rising by height over duration_s from start_s), "sine" (offset + amplitude sin(2 pi f (t - start_s) + phase) from start_s), "table" (file)
        kind: "", SIGNAL_KINDS, Dflt::Required;
        /// constant: the force
        value: "", FORCE, Dflt::When("constant: required");
        /// step, ramp, sine: the force before start_s (sine: the mean)
        offset: "", FORCE, Dflt::Num(0.0);
        /// step, ramp: the change
        height: "", FORCE, Dflt::When("step and ramp: required");
        /// sine: the amplitude
        amplitude: "", FORCE, Dflt::When("sine: required");
        /// sine: the frequency
        frequency_hz: "Hz", FREQUENCY, Dflt::When("sine: required");
        /// sine: the phase at start_s
        phase_deg: "deg", FINITE, Dflt::Num(0.0);
        /// step, ramp, sine: when it starts
        start_s: "s", NON_NEGATIVE, Dflt::Num(0.0);
        /// ramp: its length
        duration_s: "s", POSITIVE, Dflt::When("ramp: required");
        /// table: CSV with a header row and columns time_s, force, relative to the scene file's folder
        file: "", Kind::Text, Dflt::When("table: required");
        /// table: "linear" between rows, or "hold" (each row's value until the next)
        interpolation: "", Kind::Choice(&["linear", "hold"]), Dflt::Choice("linear");
    }
    children {}
}
