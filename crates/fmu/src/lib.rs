//! # clutchpack_fmu: a clutch pack as an FMI 2.0 co-simulation FMU
//!
//! `clutchpack fmu SCENE --out FILE.fmu` packs a scene into an FMU that a driveline model
//! (Simulink, Dymola, GT-SUITE, Amesim, SimulationX, FMPy, ...) imports as a co-simulation
//! slave: the pack between the host's inertias, its tooth and face torques acting back on the
//! host's driveline.
//!
//! The FMU's variables for a scene (parameters, inputs, outputs with SI units and
//! descriptions, the inputs' bounds) and the inputs held between communication points are the
//! sdk's co-simulation layer (`clutchpack_sdk::cosim`, which Python's `Simulation` uses too;
//! docs/DECISIONS.md "Co-simulation"); this crate keeps what is FMI's:
//!
//! - `description.rs`: modelDescription.xml from the sdk's variable table.
//! - `package.rs`: the `.fmu` archive (description, binary, the scene as resources).
//! - `instance.rs`: FMI's state machine and the host's communication points over
//!   `clutchpack_sdk::CoSimulation`.
//! - `ffi.rs`: the `fmi2*` C functions this crate exports when built as a cdylib (the FMU's
//!   `binaries/linux64/clutchpack_fmu.so`).
//!
//! The binary carries the scene it was built from (`resources/scene.json`, the validated
//! scene; `resources/scene.toml`, its text for reading), so the FMU runs wherever the host
//! runs, without clutchpack installed.

#![warn(missing_docs)]

pub mod description;
#[cfg(feature = "ffi")]
pub mod ffi;
pub mod instance;
pub mod package;

/// The variable table the model description and the binary read (the sdk's).
pub use clutchpack_sdk::cosim::{variables, Variable};
pub use description::MODEL_IDENTIFIER;
pub use instance::{FmiError, FmiResult, Instance, Phase};
pub use package::{check_representable, write_fmu, PackageError, DEFAULT_STEP_S};
