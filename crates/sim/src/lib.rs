//! # clutchpack_sim
//!
//! The multibody engine: a clutch pack as rigid bodies in a rapier3d-f64 world, the spline
//! teeth as our own force law applied tooth by tooth, and a contact-aware step.
//!
//! ## What this crate does
//! - Builds a rapier world from a [`clutchpack_model::PackModel`] and [`MultibodyOptions`]
//!   (the record rate, the stepping; the CLI turns a scene into those): a fixed housing, the shaft (a
//!   position-based kinematic body following the prescribed speed, eq 3, or a dynamic body on
//!   a revolute joint to the housing for an inertial shaft, eq 4), and one dynamic body per
//!   friction disc joined to the shaft by a cylindrical impulse joint (rotation about `+z` and
//!   axial slide free; radial translations and tilts locked), or optionally held by rapier's
//!   locked axes ([`DiscMount`], the same motion at about half the cost per step). A disc
//!   with `radial_float` has its radial translations free too (only the teeth hold it); an
//!   eccentric disc (`initial_offset_m` without float) is held at its offset in the shaft's
//!   frame by a cylindrical joint anchored there. Each
//!   disc's mass and transverse inertia come from a steel annulus (parry's cylinders; inner
//!   radius the spline pitch radius, outer radius chosen so that the annulus has the scene's
//!   inertia); its inertia about the axis is the scene's `J` exactly.
//! - Each step, the spline contact hook (`hook.rs`) reads every coupling's relative pose and
//!   velocity, evaluates the model's tooth law per tooth (each tooth with its own contact
//!   memory) and applies the forces along the teeth's lines of action, with each tooth's
//!   spacing error and the disc's radial offset (MODEL.md section 5). A concentric coupling
//!   without spacing errors is lumped (one tooth times `n`, exact there); any other is
//!   resolved tooth by tooth ([`ToothResolution::Auto`]). The teeth's torque is integrated
//!   along each step rather than sampled at its start (`integrate.rs`).
//! - Implements [`clutchpack_model::Engine`]: samples at the scene's recording rate, impact
//!   events with the model's definitions ([`clutchpack_model::ImpactTracker`]: onset where the
//!   engagement depth becomes positive, the peak of `|F|`, separation where the depth falls
//!   back), an energy audit ([`EnergyAudit`]).
//! - Fixed steps (the check mode) or contact-aware adaptive steps ([`AdaptiveStepping`]).
//! - The whole pack (MODEL.md section 5): separator plates, each a dynamic body on a
//!   cylindrical joint to its carrier (the fixed housing of a brake, or the output drum of a
//!   clutch: a dynamic body on a revolute joint to the housing, with inertia, load torque and
//!   drag), with its own spline coupling and tooth law; and the stack hook (`stack.rs`): the
//!   piston force, clamp forces reduced by axial spline friction, face friction
//!   `mu(v) F R_eff` with exact stick-slip at velocity level, open-gap viscous drag. Plates
//!   follow the discs in samples and impact events; the interfaces' slip, `mu`, clamp force
//!   and torque go to [`clutchpack_model::Observer::interfaces`] at the sample times.
//!
//! ## What it does not do (yet)
//! - The axial motion of the stack: the clamp forces follow the piston and the teeth's loads
//!   quasi-statically (`clutchpack_model::clutch`); no axial compliance, no gap closing.
//! - Friction at the stack is first order in time (velocity-level, the torque constant over a
//!   step): fine for slip and lock-up, not for the `s^1.5` impact (the teeth keep their
//!   third-order treatment).
//! - The radial motion of a floating disc is integrated by the polynomial kick of its forces
//!   (second to third order), not along the step like the teeth's torque about the axis; its
//!   radial speed in the law's damping is rapier's mean speed over the last step. Onsets of
//!   per-tooth couplings are not landed on (the controller's worst-case gap covers them with
//!   contact steps instead).
//! - The squeeze-film law: its damper has a nanosecond time constant near metal contact, too
//!   stiff for an explicit step; [`MultibodyEngine::new`] refuses it (use the
//!   reference engine).
//!
//! ## Rapier facts this crate relies on (measured on rapier3d-f64 0.36.1)
//! - `num_solver_iterations = 1` is one substep: rapier is then semi-implicit Euler
//!   (`v += dt F / m`, then `x += dt v`) for our user forces.
//! - User forces persist until reset: every step resets and re-adds them.
//! - Rapier turns a body by `2 atan(|w| dt / 2)` per step, not `|w| dt` (see below).
//! - A position-based kinematic body lands exactly on the pose it is given: the prescribed
//!   shaft angle has no integration error.
//!
//! ## Time integration
//! Rapier with one substep is semi-implicit Euler: `w_{k+1} = w_k + h_k F / m`, then
//! `x_{k+1} = x_k + h_k w_{k+1}`, for whatever force `F` we apply during the step. Read that
//! way, `w_{k+1}` is the mean velocity over the step, and the engine chooses `F` so that the
//! scheme is accurate (`integrate.rs` has the derivation):
//! - **Kick.** The impulse of a step is the force integrated against the hat function of the
//!   two neighbouring steps, with the force interpolated by the quadratic through its values at
//!   the last three evaluations: the leapfrog for constant forces, the explicit Stormer-Cowell
//!   method of order three for equal steps, and correct for varying steps (without the
//!   variable-step weight every change of step length costs `(h_k - h_{k-1}) a / 2` of speed).
//! - **Synchronised speeds.** The law's impact damping `1 + p v_n` and the paper law's held
//!   `dv` need the closing speed at `t_k`, not the mean over the last step; the engine adds the
//!   integral of the extrapolated acceleration over the last step. Measured on the paper case
//!   at 1 us steps: the first peak moves from 0.66 % to 0.01 % of the independent solver.
//!   Samples, events and the energy audit use these speeds too.
//! - **Landing.** The `s^1.5` law has a kink at `s = 0`. Adaptive steps land exactly on every
//!   onset and separation (a step's outcome is known before it is taken), so that within a
//!   step the force is smooth.
//! - **Exponential map.** Rapier turns a body by `2 atan(|w| h / 2)` per step (a linearised
//!   quaternion update), not `|w| h`: 6.7e-7 rad per 100 us step at 200 rad/s, far more than
//!   the backlash tolerates. The engine restores the exact turn after every step (`world.rs`;
//!   on the discs it is owed, and added when reading, until it reaches 1e-6 rad, since setting
//!   a pose makes rapier recompute the body's world mass properties).
//!
//! The prescribed shaft is a position-based kinematic body set to the profile's exact angle at
//! every step; its speed in the law is the profile's exact speed.
//!
//! # Conventions
//! Those of [`clutchpack_model`]: SI units, the shaft axis is `+z`, `phi = theta_s - theta_d`,
//! per-tooth loads negative when the shaft leads.

#![warn(missing_docs)]

pub mod engine;
mod hook;
mod integrate;
pub mod options;
mod stack;
mod stepping;
mod world;

pub use engine::{EnergyAudit, MultibodyEngine};
pub use options::{
    AdaptiveStepping, BodyShapes, DiscMount, MultibodyOptions, Scheme, Stepping, ToothResolution,
};
