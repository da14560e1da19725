//! # clutchpack_multibody
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
//!   axial slide free; radial translations and tilts locked), or held by rapier's
//!   locked axes ([`DiscMount`], the same motion at about half the cost per step; the
//!   default for the multirate scheme, whose world only carries the bodies between world
//!   steps, the joint for the shared step). A disc
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
//! - Is steppable (`Engine::start`, [`MultibodySession`]): a run advances one communication
//!   point at a time on either scheme, with the shaft's speed or torque, the drum's load and
//!   the piston's pressure driven by the caller (held between calls), and can be cloned to save
//!   and restore its state; `Engine::run` is one session advanced once, and a session driven
//!   by nothing gives `run`'s outputs bit for bit however its run is split into calls
//!   (`engine/session.rs`).
//! - Fixed steps (the check mode) or contact-aware adaptive steps ([`AdaptiveStepping`]), on
//!   one of two schemes ([`Scheme`], chosen automatically, see "Theory"): the multirate
//!   scheme, where the world steps at free-flight length and each disc's coupling sub-steps
//!   only its own contacts (cost linear in the number of discs; on an inertial shaft the
//!   shaft sub-steps with the discs that may touch it), or the shared step, where every body
//!   advances with the shortest step any coupling needs.
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
//! - On the shared step, friction at the stack is first order in time (velocity-level, the
//!   torque constant over a step): fine for slip and lock-up, not for the `s^1.5` impact (the
//!   teeth keep their third-order treatment). The multirate scheme's clamped stack is fourth
//!   order between events (above).
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
//! every step; its speed in the law is the profile's exact speed. (Within a world step of the
//! multirate schemes the sub-steps read a harmonic profile from its expansion about the step's
//! middle, [`clutchpack_model::LocalProfile`]: the same angle and speed to rounding.)
//!
//! ## Theory: the two schemes
//! [`MultibodyEngine::scheme_explanation`] says which one runs and why.
//!
//! **Shared step** (`Scheme::Shared`; the scheme of every pack the multirate one cannot run:
//! fixed steps, a disc floating radially). All bodies
//! advance with one contact-aware step, the shortest any coupling needs; the kick above makes
//! it third order (explicit Stormer-Cowell for equal steps) and, for constant steps within a
//! contact, symplectic: the energy error oscillates without drift (measured: drive work equals
//! the change of energy to 7.7e-7 over a 50 ms rattle). Its cost grows as the square of the
//! pack: each disc's contact shrinks every body's step (16 staggered discs: 71 000 steps, 3.1x
//! the per-disc cost of one disc).
//!
//! **Multirate** (`Scheme::Auto` on a prescribed shaft with couplings turning about the axis
//! only (concentric, or per-tooth with spacing errors or held eccentric, below; plates without
//! a stack too, each alone against its carrier): friction
//! discs, and separator plates on the housing or on a drum with an open stack, see "Multirate
//! with a drum" below; and the same on an inertial shaft, see "Multirate on an inertial shaft"
//! below). Within a world step the bodies are then independent: each one's teeth couple it only
//! to a carrier whose motion is known in advance (the shaft's profile, the housing at rest),
//! and neighbours pull on each other only through the open gaps' Couette drag, a coupling of
//! time constant `J / c` of seconds (2.2 s on `cases::staggered_brake`) against a world step
//! of 0.1 ms. Each body's sub-steps take that drag with its own speed exact and its
//! neighbours' as a known function of time: the discs' neighbours (plates) held at their mean
//! speed predicted from their acceleration at the step's start; the plates' neighbours (discs,
//! integrated first) affine in time with the discs' mean speed and first moment of speed over
//! the step, accumulated along the discs' sub-steps by cubic Hermite quadrature
//! (`TurnMoment`): a disc's speed jumps at its impacts within the step, and its speed held at
//! its mean gives the plate the right impulse but the wrong turn, first order in the step
//! (measured on `pack-6-engagement`'s open 50 ms: the plates' light impacts on the drum parted
//! from the reference from 15 ms, 24 us off; with the moment they agree over 30 ms within
//! 0.28 us). The drag's work is integrated by the sub-steps' stages (the energy audit's stack
//! work) and each gap's share, from the mean slips, is its heat. Measured on the open 8-disc
//! brake against the reference engine at 1e-12 over 25 ms: worst onset 0.46 us and peak
//! 3.3e-4 at the default world step. A clamped stack and a disc floating radially still run
//! the shared step. *Per-tooth couplings* whose body turns about the axis only (tooth spacing
//! errors, a disc held eccentric) run multirate since issue 20: their teeth's torque is the
//! hook's probe along the stages, their sub-steps land on the deepest tooth's onsets and
//! separations (`Coupling::deepest_tooth_shift_m`, exact while the offset does not move),
//! the other teeth's onsets fall inside sub-steps as in the shared step. Measured on
//! `eccentric-disc.toml` held at its offset (`radial_float = false`) over 50 ms against the
//! shared step at world steps of at most 6.25e-7 s: 25 impacts, peaks within 4.4e-4, onsets
//! within 0.16 us (spacing errors alone: 7.3e-4, 0.45 us; `tests/per_tooth.rs`). Over 0.3 s
//! 0.19 s against the shared step's 0.41 s: the 154 teeth's law is 85 % of either scheme's
//! time (perf), so a scheme can save only the rest. Every sub-step's first stage is the
//! hook's evaluation at the last sub-step's end (the same torque to the bit as a probe, which
//! the per-tooth moment is written to match): three probes per sub-step, not four.
//! So the rapier world steps at free-flight length
//! (`max_step_s`, landing on the sample times) and each coupling integrates its own relative
//! motion over the world step with its own sub-steps (`engine/multirate.rs`):
//! - *The sub-step* is the classical Runge-Kutta method (order 4) on the disc's motion,
//!   `J omega_d' = T(phi, phi') - C2 omega_d` (Hu et al. eq (5)), with
//!   `phi = theta_s(t) - theta_d` and the shaft's angle and speed exact from the profile (a
//!   harmonic one from its expansion about the world step's middle, equal to rounding,
//!   `Prescribed` in `engine/substep.rs`): in free flight without drag the disc turns at
//!   constant speed and the sub-step is exact whatever its length. Its length is the shared step's controller applied to this coupling
//!   alone (128 sub-steps per predicted contact), landing on every onset and separation.
//! - *The kinks.* The `s^1.5` law's load grows as `t^1.5` from an onset (and falls as
//!   `(t_off - t)^1.5` to a separation), so the step touching a kink is only of order `h^2.5`
//!   in the impulse; sub-steps are graded there (at most a quarter of the time from the onset
//!   or to the predicted separation, at least 1/64 of the contact step, 1/8 for a coupling
//!   alone on a carrier of known motion), which restores the
//!   convergence: measured on the 8-disc staggered pack against the reference engine at
//!   tolerance 1e-12, early onsets 2.6e-11 s off at 128 sub-steps per contact (1.7e-9 s
//!   ungraded), 1.9e-12 s at 256.
//! - *The world step* hands each disc's result to its rapier body, which carries the state:
//!   the disc's mean speed over the step enters as a torque (rapier's semi-implicit Euler then
//!   turns the disc by exactly the sub-steps' turn) and the end speed is set after it. The
//!   round trip through rapier is exact to rounding (measured 4e-16 rad, 6e-15 rad/s), so the
//!   scheme's error is the sub-steps' alone: fourth order away from the kinks. Where that is
//!   all rapier does (an open pack: every carrier fixed or prescribed, every body concentric)
//!   the run carries the bodies itself (issue 46): each coupling keeps its sub-steps' state at
//!   the world step's end, its relative angle moved to the carrier's exact angle as the
//!   poses' read-back moved it, without the quaternions' rounding; rapier's poses are brought
//!   up to date only before the clamped stack, which reads them (`Run::carry_bodies`).
//! - *Energy.* The classical Runge-Kutta method is not symplectic: it dissipates slightly,
//!   `|R(i w h)| = 1 - (w h)^6 / 144` per step of an oscillation of frequency `w`, about
//!   2.5e-5 of a sustained contact's vibration energy per period at its 32 steps per period,
//!   nothing in free flight. The drive's and the drag's work are integrated by the same stages (the
//!   augmented system), so the energy audit closes to the integration error: measured 5.8e-11
//!   of the drive's work over a 50 ms rattle (7.7e-7 on the shared step).
//! - *Cost.* One rapier step per world step for the whole pack, plus each disc's sub-steps,
//!   which only a disc in contact takes (about 215 per impact): linear in the number of discs.
//!   Measured on the staggered pack (0.1 s, `cargo bench -p clutchpack_multibody --bench staggered`):
//!   per-disc wall time 0.65-0.7x one disc's at 4, 8 and 16 discs. `perf` on 16 discs
//!   (`examples/staggered.rs`): 36 % in the shaft profile's sin/cos (two evaluations per
//!   sub-step), 22 % in the sub-steps' arithmetic and the step controller, 18 % in rapier
//!   (1 000 world steps), 13 % in the tooth law, 7 % in allocation and the kernel, 2 % in the
//!   impact trackers. Issue 33 (`perf` of the 16-disc brake pack, `clutchpack run` of the
//!   `brake-16.toml` of `bench/mujoco/brake.py`, 225 000 sub-steps per 0.1 s, 175 per impact): the
//!   profile's `sin` and `cos` at every stage were still 15 %, the controller's local period
//!   of a contact (two roots, three divisions per sub-step) 10 %. One `sincos` per harmonic
//!   ([`clutchpack_model::SpeedProfile::speed_and_angle`]), then the expansion about each world
//!   step's middle (no libm call per stage), the period decided without its roots when it
//!   cannot bind (`stepping.rs`) and the half play kept as `Rb` is (`hook.rs`): 0.81x the
//!   engine's time on that pack (`clutchpack bench`, same minute: 55.4-55.9 against
//!   68.6-68.9 ms) and over 0.3 s whole processes; now about 20 % rapier's world step (joint
//!   constraints), 8 % each the sub-step's arithmetic and the landing loop, 10 % the tooth
//!   law, 5 % each the controller and the expansion.
//!
//! **Multirate on an inertial shaft** (issue 20; eq 4, `J1 omega_s' = T_drive - C1 omega_s -
//! sum T_k`; with plates and a drum see "Multirate with a drum" below). The discs no longer meet a carrier whose motion is known
//! in advance: the shaft's motion depends on the teeth's reactions. But a disc in free flight
//! loads nothing, so within a world step only the discs that touch the shaft couple to it.
//! Each world step (`Run::multirate_step_inertial`):
//! - *The cluster.* The couplings in contact at `t`, and those whose controller step (the
//!   prescribed scheme's, with the shaft's acceleration bounded by the drive, the damping and
//!   the reactions at `t`, as the shared step's controller) is shorter than the world step,
//!   go with the shaft.
//! - *The shaft and its cluster* are integrated as one system, the classical Runge-Kutta
//!   method on every body's own motion (`Run::carrier_step`: the shaft `J1 w' = T_drive(t) -
//!   C1 w - sum T_k`, each disc `J w_d' = T_k - C2 w_d`), with sub-steps of the shortest any
//!   member wants (the prescribed scheme's controller and grading, each coupling with its own
//!   reduced mass `m_eff = md mc / (md + mc)`), at most a quarter of the world step (the
//!   drive), landed on every member's onsets and separations. No coupling's load is held:
//!   overlapping contacts couple through the shaft exactly, to the method's order (fourth
//!   away from the kinks, graded at them as above). The cost of a sub-step grows with the
//!   cluster's size, which is the number of discs near contact at once, not the pack's.
//! - *The others* fly free against the shaft's motion so found: its nodes (the sub-steps'
//!   ends), exact there, the cubic Hermite interpolant between (only their depth, for the
//!   landing, reads it between nodes; their own motion does not depend on the shaft's). The
//!   controller's bound makes a touch within the step impossible unless a contact in the
//!   cluster jolts the shaft beyond it; such a coupling would be integrated against the
//!   shaft's motion without its reaction on it for the rest of the step (counted,
//!   `Counts::missed`: none in the measurements below).
//! - *Momentum and energy.* The teeth's torques enter the shaft and the discs at the same
//!   stages with opposite signs, and any Runge-Kutta method keeps a linear invariant: the
//!   total angular momentum `J1 omega_s + sum J omega_d` changes only by the drive's and the
//!   damping's (and the drag's) impulses; each body's result is handed to its rapier body
//!   as on a prescribed shaft (the shaft by its mean speed set for the step, then its end
//!   speed). Measured on the 8 staggered discs on an undriven, undamped shaft (J1 = 2 kg m^2,
//!   108 impacts in 50 ms): conserved to 1.6e-15 relative (`tests/inertial_multirate.rs`).
//!   The energy behaves as on a prescribed shaft: the method dissipates `(w h)^6 / 144` per
//!   step of an oscillation, nothing in free flight; the drive's work on the shaft, the
//!   damping's and the drag's are integrated by the same stages.
//! - *Accuracy* (the 8 staggered discs on J1 = 2 kg m^2 driven by `J1 d(profile)/dt`, against
//!   the shared step at 1024 steps per contact and 25 us; `tests/inertial_multirate.rs`): over
//!   15 ms (43 impacts) every impact's peak within 4.3e-5 and onset within 4.6 ns at the
//!   default settings (the shared step at its defaults: 1.1e-3 and 0.12 us). Order: against
//!   the shared step at 2048 steps per contact and 10 us, 4.6e-5 and 4.9 ns at 128 sub-steps
//!   per contact, 7.9e-6 and 0.87 ns at 256: halving the sub-steps divides the error by 5.7
//!   (`2^2.5`, the order of a sub-step touching a kink of the `s^1.5` law; but the reference
//!   is itself only 2.6e-6 and 0.29 ns from the shared step at 1024, so which limits the
//!   ratio is not resolved; the scheme is the prescribed one's, fourth order away from the
//!   kinks, applied to the shaft with its cluster). This rattle is chaotic: the shared
//!   step at 1024 and 2048 steps per contact are 4.4e-4 apart by 20 ms and differ in their
//!   impacts by 50 ms, so no comparison holds over 50 ms.
//! - *Cost* (`examples/inertial.rs`: the staggered pack on J1 = 2 kg m^2, 0.1 s simulated,
//!   release, best of 5 runs): per-disc wall time 8.9, 6.1, 7.0 and 8.3 ms at N = 1, 4, 8
//!   and 16 discs (1.00, 0.68, 0.79, 0.93x one disc's), against the shared step's 31, 39, 54
//!   and 72 ms (1.00, 1.25, 1.72, 2.30x): 3.5x faster at one disc, 8.7x at 16. A disc pushed
//!   along by the shaft's drive rides its flank for long stretches, so the cluster holds
//!   about 60 % of the discs at a time (9.8 of 16 per world step on average) and the
//!   sub-steps of each follow the tightest contact in it (tooth-law evaluations per disc:
//!   61 000 at one disc, 281 000 at 16). Before the step controller skipped the contact
//!   duration of a flank it cannot reach within the step (two powers each) and the cluster
//!   used the couplings' kept base radius instead of a cosine, 16 discs cost 12.4 ms per disc
//!   (1.08x; perf: 20 % `pow`, 12 % `cos`).
//!
//! **Multirate with a drum, and the piston's start** (issue 20). The drum is an inertial
//! carrier as the inertial shaft is: each world step it is integrated with the plates that may
//! touch it by the same kernel (`engine/inertial.rs`, on the drum's entry of the run's table
//! of carriers, `engine/carriers.rs`: the drum
//! `J w' = T_load - C w - sum T_k` with its load held over the world step, each plate
//! `J w_p' = T_k - C2 w_p` plus its gaps' drag, held as for plates on the housing), the
//! others flying free against its nodes; the same order, momentum and energy behaviour as
//! above (the load's work integrated by the same stages: the audit closes to 2.8e-11 of the
//! drive's work over 50 ms of `pack-6-engagement` held open, `tests/stack.rs`). A stack whose
//! piston may push later is open until then (`Piston::open_until_s`): the session runs the
//! open multirate scheme to that time and the clamped stack's from there (below).
//! Measured on `pack-6-engagement`'s open 50 ms: 0.04 s against 0.63 s; against the reference
//! engine at 1e-12 at world steps of 5e-5 s the discs'
//! 137 impacts over the first 50 ms agree within 1.0e-3 of the peak and 0.52 us, the plates'
//! 47 over the first 30 ms within 2.3e-3 and 0.28 us, where the shared step's first-order gap
//! drag limited the discs' agreement to 25 ms. On an inertial shaft both
//! carriers run so, each with its bodies, the discs first (the shaft's cluster), then the
//! plates (the drum's), coupled only through the gaps' drag as on a prescribed shaft: the
//! energy audit closes to 3.6e-11 of the drive's work over 50 ms, and the discs' 36 impacts
//! over the first 15 ms agree with the reference engine at 1e-12 within 3.7e-4 and 0.17 us
//! (`tests/cross_engine.rs`, which says why not longer: the pack is chaotic beyond what the
//! reference itself resolves).
//!
//! **The clamped stack** (issue 20, `engine/clamped.rs`). Once the piston may push nothing in
//! the stack is weak: every face couples its two bodies, and the splines' friction makes each
//! clamp force depend on every tooth load below it. So the stack's discs and plates, the drum
//! and an inertial shaft are integrated together as one system by the classical
//! Runge-Kutta method (order 4 between events), sub-steps of the shortest any coupling wants
//! (at most a quarter of the world step), landed on every onset and separation; the rapier
//! world still steps once per world step with each body's impulse. A locked run of bodies is
//! one body (total torque over total inertia: its members' speeds stay equal to the bit, a
//! locked face does not creep); a slipping face passes `mu(|v|) F R_eff` against its slip and
//! an open one the gaps' drag, both evaluated at every stage. A slip reaching zero is landed on
//! (order kept) and the face locks if its holding torque `mu(0) F R_eff` keeps its sides
//! together, its sides' speeds set to their momentum-weighted mean (the landing's rounding,
//! counted as the face's heat); a locked face beyond its holding torque breaks at the end of
//! the sub-step that finds it (first order in that event's time, as the shared step's
//! velocity-level friction is in every one). Energy: the drive's, the load's, the drag's and
//! the faces' work are integrated by the same stages, so the audit closes to the method's
//! truncation (1.4e-10 of the drive's work over 0.12 s of the engaging clutch with its drum's
//! load, `tests/stack.rs`). Measured on `pack-6-engagement`: every interface's first lock
//! within 3.5e-4 and the heat within 4.0e-4 of the shared step at 2.5e-6 s; the micro-slips
//! of its faces at capacity as the reference engine's exact stick-slip events show them and
//! the shared step missed (DECISIONS); 0.20 s against the shared step's 1.20 s over 0.3 s,
//! whole processes in turn (5.8x; 27 900 sub-steps of the 13 bodies in the locked 214 ms at
//! 4 us each, against 25 100 shared steps at 17.8 us). On an inertial shaft the shaft joins
//! the system (Hu et al. eq 4: its drive, its damping, the discs' reactions): with
//! J1 = 2 kg m^2, locks within 1.3e-4 and heat within 6.0e-4 of the shared step at 2.5e-6 s,
//! 0.38 s against 2.41 s.
//!
//! **Where a whole pack's time goes today** (issue 20; the 16-disc brake pack, 16 staggered
//! discs and 17 plates on the housing with the open gaps' drag, which runs the shared step;
//! `perf record --call-graph dwarf` of `clutchpack run` on the `brake-16.toml` of
//! `bench/mujoco/brake.py`, 20 ms, release build): 52 % in rapier's world step (the 34
//! bodies' joint constraints rebuilt and solved at every shared step: 84 590 steps per 0.1 s,
//! 84 per impact), 14 % in the hook's evaluation, 13 % in the step controller, 12.5 % in the
//! stack's solve, 5 % in `powf` (`s^1.5`, contact durations), 7 % in copies. Every one of these is
//! paid per shared step, so the cure is fewer world steps (the multirate scheme), not a
//! faster step. Before the kinematics kept `Rb` (`hook.rs`), a cosine per tooth-law call was
//! 16 % of the run on its own: keeping it made the 16-disc brake 12 % faster (1.80 -> 1.56 s
//! for 50 ms, whole process, median of 5 in turn), with byte-identical results. Per 0.1 s
//! simulated, same minute, whole processes (median of 5, in turn): MuJoCo 4 0.248 s (N = 8)
//! and 0.436 s (N = 16) against this engine's 1.28 s and 3.46 s (before the `Rb` change); the
//! reference engine runs the same packs in 0.100 s and 0.231 s. `clutchpack bench` prints the
//! per-disc growth (N = 1, 4, 8, 16: 1.00, 2.05, 2.87, 4.18x).
//!
//! ## Thermal packs (MODEL.md section 9, `engine/thermal.rs`)
//! A pack with a thermal model ([`MultibodyEngine::with_thermal`]) carries the temperatures of
//! every disc, plate and the oil on the model's windows
//! ([`clutchpack_model::thermal::ThermalWindows`], the reference engine's too), in either
//! scheme. After each world step its heat is booked: each face's dissipated work (kept by the
//! stack's integration) by its mode at the step's start, to its two bodies by effusivity
//! while clamped, to the oil while open; the teeth's work on the relative motion, to the oil,
//! from the energy audit (the step's external work beyond the kinetic energy's change). At
//! the first world step end past each window the temperatures advance and new tooth films
//! and gap viscosities go into the couplings' laws and the stack. World steps are never cut
//! at a window. First order in the window; the heat balance closes to rounding
//! (docs/DECISIONS.md, "Thermal windows").
//!
//! # Conventions
//! Those of [`clutchpack_model`]: SI units, the shaft axis is `+z`, `phi = theta_s - theta_d`,
//! per-tooth loads negative when the shaft leads.

#![warn(missing_docs)]

pub mod engine;
mod hook;
mod integrate;
pub mod network;
pub mod options;
mod stack;
mod stepping;
mod world;

pub use engine::{Carried, EnergyAudit, MultibodyEngine, MultibodySession};
pub use options::{
    AdaptiveStepping, BodyShapes, DiscMount, MultibodyOptions, Scheme, Stepping, ToothResolution,
};
