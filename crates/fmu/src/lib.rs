//! # clutchpack_fmu: a clutch pack as an FMI 2.0 co-simulation FMU
//!
//! `clutchpack fmu SCENE --out FILE.fmu` packs a scene into an FMU that a driveline model
//! (Simulink, Dymola, GT-SUITE, Amesim, SimulationX, FMPy, ...) imports as a co-simulation
//! slave: the pack between the host's inertias, its tooth and face torques acting back on the
//! host's driveline.
//!
//! - `variables.rs`: the FMU's variables for a scene (parameters, inputs, outputs with SI
//!   units and descriptions), the one table both the description and the binary read.
//! - `description.rs`: modelDescription.xml.
//! - `package.rs`: the `.fmu` archive (description, binary, the scene as resources).
//! - `bounds.rs`: the inputs' bounds, those of the scene keys they stand for.
//! - `instance.rs`: FMI's state machine over `clutchpack_sdk::Session` (the inputs held
//!   between communication points, docs/DECISIONS.md "Co-simulation").
//! - `ffi.rs`: the `fmi2*` C functions this crate exports when built as a cdylib (the FMU's
//!   `binaries/linux64/clutchpack_fmu.so`).
//!
//! The binary carries the scene it was built from (`resources/scene.json`, the validated
//! scene; `resources/scene.toml`, its text for reading), so the FMU runs wherever the host
//! runs, without clutchpack installed.

#![warn(missing_docs)]

mod bounds;
pub mod description;
#[cfg(feature = "ffi")]
pub mod ffi;
pub mod instance;
pub mod package;
pub mod variables;

pub use description::MODEL_IDENTIFIER;
pub use instance::{Instance, Phase};
pub use package::{check_representable, write_fmu, PackageError, DEFAULT_STEP_S};
pub use variables::{variables, Variable};
