//! The rapier3d-f64 world of a pack: a fixed housing, the shaft, and one dynamic body per disc
//! on a cylindrical impulse joint (ARCHITECTURE.md "The multibody engine"), or on a joint that
//! frees the radial translations too for a disc that floats radially (MODEL.md section 5).
//!
//! The shaft axis is the world `+z` axis. Bodies carry no colliders: the spline teeth are our
//! own force law, applied by the contact hook ([`crate::hook`]).

use crate::options::{BodyShapes, DiscMount};
use clutchpack_model::{EngineError, PackModel, Shaft, StackBody};
use parry3d_f64::mass_properties::MassProperties;
use rapier3d_f64::prelude::{
    GenericJointBuilder, JointAxesMask, LockedAxes, PhysicsWorld, RigidBody, RigidBodyBuilder,
    RigidBodyHandle, Rotation, Vector,
};
use std::f64::consts::PI;

/// The body a spline coupling joins a disc or plate to (the model's one definition).
pub(crate) use clutchpack_model::Carrier;

/// A body that carries spline couplings, as the rapier world holds it: the fixed housing,
/// the shaft (position-based kinematic for a prescribed speed, dynamic for eq 4), the output
/// drum of a clutch (dynamic, on a revolute joint to the housing).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CarrierBody {
    /// Its role in the pack (the model's description; for names and outputs only).
    pub role: Carrier,
    /// Its rapier body.
    pub handle: RigidBodyHandle,
    /// Whether rapier integrates it (an inertial shaft, the drum): its rotation then gets the
    /// exact exponential map after each step ([`exponential_map_deficit`]).
    pub dynamic: bool,
}

/// Index in [`World::carriers`] of the shaft (always there): after the fixed housing (0), and
/// followed by the drum when the pack has one.
pub(crate) const SHAFT: usize = 1;

/// The rapier world of one pack and the handles of its bodies.
pub(crate) struct World {
    /// All rapier state.
    pub physics: PhysicsWorld,
    /// The carrier bodies in the order the world inserts them: the housing, the shaft
    /// ([`SHAFT`]), the drum if any.
    pub carriers: Vec<CarrierBody>,
    /// One dynamic body per spline-coupled body: the friction discs in scene order, then the
    /// separator plates in scene order (the engine's coupling order).
    pub discs: Vec<RigidBodyHandle>,
    /// The carrier of each of them: an index into [`World::carriers`].
    pub carrier_of: Vec<usize>,
    /// Axial position of each one's mid-plane, m (discs and plates alternate in a stack).
    pub disc_axial_m: Vec<f64>,
    /// Turn owed to each disc by [`exponential_map_deficit`] and not yet applied to its
    /// rapier pose, as a scaled axis (rad). Readers add it ([`World::disc_turn_owed_z`]).
    owed: Vec<Vector>,
}

/// A copy of the world, exact: every part of rapier's state is cloned (the bodies with their
/// poses, speeds and applied forces, the joints with their warm-start impulses, the island
/// manager, the broad and narrow phases, the CCD solver), but the physics and collision
/// pipelines, which are not `Clone`. Those hold only workspace buffers, rebuilt at every step
/// (rapier's docs: "contains only temporary working memory"; a new pipeline also invalidates
/// the joint set's memo of its last selection, `joint_selection_primed`), so fresh ones step
/// the copy exactly as the original's step the original (checked bit for bit by
/// `tests/session.rs`, "a clone advances as the original").
impl Clone for World {
    fn clone(&self) -> World {
        World {
            physics: copy_physics(&self.physics),
            carriers: self.carriers.clone(),
            discs: self.discs.clone(),
            carrier_of: self.carrier_of.clone(),
            disc_axial_m: self.disc_axial_m.clone(),
            owed: self.owed.clone(),
        }
    }
}

/// Owed turns are applied to the rapier pose once they exceed this, rad. Setting a pose makes
/// rapier recompute the body's world mass properties (measured: a tenth of the step's cost
/// with 8 discs), while the owed turn, kept exactly, costs nothing to add when reading.
const OWED_TURN_MAX_RAD: f64 = 1e-6;

/// Mass properties of a disc about its centre, axis `+z`: a steel annulus from parry (inner
/// radius the spline pitch radius, outer radius chosen so that the annulus has the scene's
/// inertia), with the axial inertia then set to the scene's `J` exactly (parry's subtraction
/// of two cylinders leaves a few ulps of rounding).
pub(crate) fn disc_mass_properties(
    inertia_kg_m2: f64,
    inner_m: f64,
    shapes: &BodyShapes,
) -> MassProperties {
    let half = 0.5 * shapes.disc_thickness_m;
    let outer = clutchpack_model::annulus_outer_radius_m(
        inertia_kg_m2,
        inner_m,
        shapes.disc_thickness_m,
        shapes.density_kg_m3,
    );
    let annulus_y = MassProperties::from_cylinder(shapes.density_kg_m3, half, outer)
        - MassProperties::from_cylinder(shapes.density_kg_m3, half, inner_m);
    // parry's cylinders stand on +y; turn the annulus onto +z.
    let to_z = rapier3d_f64::prelude::Pose::from_parts(
        Vector::ZERO,
        Rotation::from_rotation_arc(Vector::Y, Vector::Z),
    );
    let annulus = annulus_y.transform_by(&to_z);
    let i = annulus.reconstruct_inertia_matrix();
    MassProperties::with_principal_inertia_frame(
        Vector::ZERO,
        annulus.mass(),
        Vector::new(i.x_axis.x, i.y_axis.y, inertia_kg_m2),
        Rotation::IDENTITY,
    )
}

/// Mass properties of an inertial shaft: a solid steel-like cylinder of radius `radius_m` and
/// length `length_m` whose density is scaled so that its axial inertia is `J1`.
fn shaft_mass_properties(inertia_kg_m2: f64, radius_m: f64, length_m: f64) -> MassProperties {
    let density = 2.0 * inertia_kg_m2 / (PI * radius_m.powi(4) * length_m);
    let to_z = rapier3d_f64::prelude::Pose::from_parts(
        Vector::ZERO,
        Rotation::from_rotation_arc(Vector::Y, Vector::Z),
    );
    let cyl = MassProperties::from_cylinder(density, 0.5 * length_m, radius_m).transform_by(&to_z);
    let i = cyl.reconstruct_inertia_matrix();
    MassProperties::with_principal_inertia_frame(
        Vector::ZERO,
        cyl.mass(),
        Vector::new(i.x_axis.x, i.y_axis.y, inertia_kg_m2),
        Rotation::IDENTITY,
    )
}

/// A joint that keeps rotation about `+z` and the axial slide free and locks the two radial
/// translations and the two tilts (a cylindrical joint), anchored at `anchor1` on body 1.
fn cylindrical_joint(anchor1: Vector) -> GenericJointBuilder {
    // The joint's free axis is its local X; put it on +z in both bodies.
    GenericJointBuilder::new(
        JointAxesMask::LIN_Y | JointAxesMask::LIN_Z | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z,
    )
    .local_axis1(Vector::Z)
    .local_axis2(Vector::Z)
    .local_anchor1(anchor1)
    .local_anchor2(Vector::ZERO)
    .contacts_enabled(false)
}

/// A joint that locks only the two tilts: rotation about `+z`, the axial slide and both radial
/// translations free (a disc floating radially on its spline, MODEL.md section 5; only the
/// teeth hold it radially).
fn floating_joint(anchor1: Vector) -> GenericJointBuilder {
    GenericJointBuilder::new(JointAxesMask::ANG_Y | JointAxesMask::ANG_Z)
        .local_axis1(Vector::Z)
        .local_axis2(Vector::Z)
        .local_anchor1(anchor1)
        .local_anchor2(Vector::ZERO)
        .contacts_enabled(false)
}

impl World {
    /// Builds the world at t = 0: shaft angle 0 at its initial speed, each disc at
    /// `theta_d = -phi(0)` turning at `omega_s(0) - dphi(0)`; each plate likewise relative to
    /// its carrier (the housing at rest, or the drum at angle 0 and its initial speed). The
    /// discs are held by `mount` as resolved for the run's scheme
    /// ([`DiscMount::for_scheme`]; an unresolved [`DiscMount::Auto`] holds them by the joint).
    pub fn build(
        pack: &PackModel,
        shapes: &BodyShapes,
        mount: DiscMount,
    ) -> Result<World, EngineError> {
        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::ZERO;
        let p = &mut physics.integration_parameters;
        // ARCHITECTURE.md: with one iteration (= one substep) rapier is semi-implicit Euler.
        p.num_solver_iterations = 1;
        // No colliders: no CCD.
        p.max_ccd_substeps = 0;

        let omega0 = pack.shaft.initial_speed_rad_s();
        let housing = physics.insert_body(RigidBodyBuilder::fixed());
        let n = pack.discs.len();
        let np = pack.plates.len();
        let disc_axial_m: Vec<f64> = if np == 0 {
            (0..n)
                .map(|i| (i as f64 - 0.5 * (n as f64 - 1.0)) * shapes.disc_pitch_m)
                .collect()
        } else {
            // A stack: plate 0, disc 0, plate 1, ... (clutchpack_model::clutch), a pitch
            // apart, centred on the origin.
            let centre = 0.5 * ((n + np) as f64 - 1.0);
            let at = |b: usize| (b as f64 - centre) * shapes.disc_pitch_m;
            (0..n)
                .map(|i| at(StackBody::Disc(i).position()))
                .chain((0..np).map(|j| at(StackBody::Plate(j).position())))
                .collect()
        };

        let (shaft, shaft_dynamic) = match &pack.shaft {
            Shaft::Prescribed(_) => {
                let rb = RigidBodyBuilder::kinematic_position_based()
                    .can_sleep(false)
                    .angvel(Vector::new(0.0, 0.0, omega0));
                (physics.insert_body(rb), false)
            }
            Shaft::Inertial { inertia_kg_m2, .. } => {
                let radius = pack
                    .discs
                    .iter()
                    .map(|d| d.spline.pitch_radius_m)
                    .fold(f64::INFINITY, f64::min);
                let radius = if radius.is_finite() { radius } else { 0.05 };
                let length = (n.max(1) as f64) * shapes.disc_pitch_m;
                let rb = RigidBodyBuilder::dynamic()
                    .can_sleep(false)
                    .gyroscopic_forces_enabled(false)
                    .allow_fast_rotation(true)
                    .additional_mass_properties(shaft_mass_properties(
                        *inertia_kg_m2,
                        radius,
                        length,
                    ))
                    .angvel(Vector::new(0.0, 0.0, omega0));
                let h = physics.insert_body(rb);
                // The housing holds the shaft on its axis: a revolute joint about +z.
                let joint = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                    .local_axis1(Vector::Z)
                    .local_axis2(Vector::Z)
                    .contacts_enabled(false);
                physics.insert_impulse_joint(housing, h, joint);
                (h, true)
            }
        };

        let drum = match &pack.drum {
            None => None,
            Some(dr) => {
                let radius = pack
                    .plates
                    .iter()
                    .map(|p| p.spline.pitch_radius_m)
                    .fold(0.0, f64::max)
                    .max(0.05);
                let length = ((n + np).max(1) as f64) * shapes.disc_pitch_m;
                let rb = RigidBodyBuilder::dynamic()
                    .can_sleep(false)
                    .gyroscopic_forces_enabled(false)
                    .allow_fast_rotation(true)
                    .additional_mass_properties(shaft_mass_properties(
                        dr.inertia_kg_m2,
                        radius,
                        length,
                    ))
                    .angvel(Vector::new(0.0, 0.0, dr.initial_speed_rad_s));
                let h = physics.insert_body(rb);
                let joint = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                    .local_axis1(Vector::Z)
                    .local_axis2(Vector::Z)
                    .contacts_enabled(false);
                physics.insert_impulse_joint(housing, h, joint);
                Some(h)
            }
        };
        let body = |role, handle, dynamic| CarrierBody {
            role,
            handle,
            dynamic,
        };
        let mut carriers = vec![
            body(Carrier::Housing, housing, false),
            body(Carrier::Shaft, shaft, shaft_dynamic),
        ];
        // the initial speed of each carrier, rad/s
        let mut speeds = vec![0.0, omega0];
        if let (Some(h), Some(dr)) = (drum, &pack.drum) {
            carriers.push(body(Carrier::Drum, h, true));
            speeds.push(dr.initial_speed_rad_s);
        }
        let carrier_of: Vec<usize> = (0..n + np)
            .map(|i| {
                let role = pack.carrier(i);
                carriers
                    .iter()
                    .position(|c| c.role == role)
                    .expect("a carrier")
            })
            .collect();

        let mut discs = Vec::with_capacity(n + np);
        for (i, d) in pack.discs.iter().chain(&pack.plates).enumerate() {
            let (carrier, omega_c) = (carriers[carrier_of[i]].handle, speeds[carrier_of[i]]);
            let mprops = disc_mass_properties(d.inertia_kg_m2, d.spline.pitch_radius_m, shapes);
            let [ex, ey] = d.initial_offset_m;
            // The centre starts at its offset in the shaft's frame (the world frame at t = 0),
            // moving with the shaft: v = omega_0 z x e.
            let mut rb = RigidBodyBuilder::dynamic()
                .can_sleep(false)
                .gyroscopic_forces_enabled(false)
                .allow_fast_rotation(true)
                .additional_mass_properties(mprops)
                .translation(Vector::new(ex, ey, disc_axial_m[i]))
                .rotation(Vector::new(0.0, 0.0, -d.initial_rel_angle_rad))
                .linvel(Vector::new(-omega_c * ey, omega_c * ex, 0.0))
                .angvel(Vector::new(0.0, 0.0, omega_c - d.initial_rel_speed_rad_s));
            // An eccentric disc that does not float is held at its offset in the shaft's
            // frame, which turns: only a joint to the shaft can do that.
            let eccentric = !d.radial_float && (ex != 0.0 || ey != 0.0);
            let locked_axes = mount == DiscMount::LockedAxes && !eccentric;
            if locked_axes {
                // The shaft's axis is the world z axis (a kinematic shaft, or a dynamic one on
                // a revolute joint to the housing), so world-locked axes hold the disc on it.
                rb = rb.locked_axes(if d.radial_float {
                    LockedAxes::ROTATION_LOCKED_X | LockedAxes::ROTATION_LOCKED_Y
                } else {
                    LockedAxes::TRANSLATION_LOCKED_X
                        | LockedAxes::TRANSLATION_LOCKED_Y
                        | LockedAxes::ROTATION_LOCKED_X
                        | LockedAxes::ROTATION_LOCKED_Y
                });
            }
            let h = physics.insert_body(rb);
            // Now rather than at the first step: the multirate scheme reads the disc's
            // inertia from its mass properties before the world has stepped.
            let body = &mut physics.bodies[h];
            body.recompute_mass_properties_from_colliders(&physics.colliders);
            if !locked_axes {
                let joint = if d.radial_float {
                    floating_joint(Vector::new(0.0, 0.0, disc_axial_m[i]))
                } else {
                    cylindrical_joint(Vector::new(ex, ey, disc_axial_m[i]))
                };
                physics.insert_impulse_joint(carrier, h, joint);
            }
            discs.push(h);
        }
        Ok(World {
            physics,
            carriers,
            owed: vec![Vector::ZERO; discs.len()],
            discs,
            carrier_of,
            disc_axial_m,
        })
    }

    /// Advances rapier by `dt` s, then restores the exponential map on the dynamic bodies'
    /// rotations (see [`exponential_map_deficit`]).
    pub fn step(&mut self, dt: f64) {
        self.physics.integration_parameters.dt = dt;
        self.physics.step();
        for (owed, &h) in self.owed.iter_mut().zip(&self.discs) {
            let body = &mut self.physics.bodies[h];
            *owed += exponential_map_deficit(body, dt);
            if owed.length() > OWED_TURN_MAX_RAD {
                turn(body, *owed);
                *owed = Vector::ZERO;
            }
        }
        for c in self.carriers.iter().filter(|c| c.dynamic) {
            let body = &mut self.physics.bodies[c.handle];
            let d = exponential_map_deficit(body, dt);
            turn(body, d);
        }
    }

    /// The index in [`World::carriers`] of the output drum, if the pack has one.
    pub fn drum(&self) -> Option<usize> {
        self.carriers.iter().position(|c| c.role == Carrier::Drum)
    }

    /// The turn about `+z` owed to disc `i` and not yet in its rapier pose, rad.
    pub fn disc_turn_owed_z(&self, i: usize) -> f64 {
        self.owed[i].z
    }

    /// Places disc (or plate) `i` at `angle` about `+z` (rad, unwrapped) turning at `speed`
    /// (rad/s), with no turn owed: its pose brought up to date by the run that carried it
    /// (`Run::catch_up_world`).
    pub(crate) fn place_disc(&mut self, i: usize, angle: f64, speed: f64) {
        let body = &mut self.physics.bodies[self.discs[i]];
        body.set_rotation(Rotation::from_rotation_z(angle), false);
        body.set_angvel(Vector::new(0.0, 0.0, speed), false);
        self.owed[i] = Vector::ZERO;
    }

    /// Places carrier `c` (a kinematic shaft) at `angle` about `+z` (rad, unwrapped): its
    /// pose and its next pose.
    pub(crate) fn place_carrier(&mut self, c: usize, angle: f64) {
        let body = &mut self.physics.bodies[self.carriers[c].handle];
        body.set_rotation(Rotation::from_rotation_z(angle), false);
    }
}

/// Turns a body by the scaled axis `turn` (world frame).
fn turn(body: &mut RigidBody, turn: Vector) {
    let angle = turn.length();
    if angle > 0.0 {
        let fix = Rotation::from_axis_angle(turn / angle, angle);
        let q = (fix * *body.rotation()).normalize();
        body.set_rotation(q, false);
    }
}

/// Corrects rapier's linearised rotation update to the exact one for the step's angular
/// velocity.
///
/// Measured on rapier3d-f64 0.36.1 (`RigidBodyVelocity::integrate_linearized`): the new
/// rotation is `normalize((1, w dt / 2) q)`, a turn of `2 atan(|w| dt / 2)` about `w` instead of
/// `|w| dt`. The lag, `(|w| dt)^3 / 12` per step, is 6.7e-13 rad per 1 us step at 200 rad/s
/// (150 nm per second at the pitch circle) and 6.7e-7 rad per 100 us step: far more than the
/// backlash tolerates. The missing `|w| dt - 2 atan(|w| dt / 2)` is turned about the same axis,
/// so the disc turns by exactly `w dt` (semi-implicit Euler on the angle).
///
/// Returns the missing turn as a scaled axis (rad); [`World::step`] applies it to the pose, or
/// owes it to the disc until it is large enough to be worth a pose update.
pub(crate) fn exponential_map_deficit(body: &RigidBody, dt: f64) -> Vector {
    let w = body.angvel();
    let speed = w.length();
    if speed == 0.0 || !speed.is_finite() {
        return Vector::ZERO;
    }
    let theta = speed * dt;
    let deficit = theta - 2.0 * (0.5 * theta).atan();
    w * (deficit / speed)
}

/// Rotation angle of `q` about `+z` in (-pi, pi], for rotations about `+z` (tilts are locked).
pub(crate) fn angle_about_z(q: &Rotation) -> f64 {
    2.0 * q.z.atan2(q.w)
}

/// A copy of rapier's world `p`, exact but for the physics and collision pipelines, which
/// are not `Clone` and hold only workspace rebuilt at every step (see [`World`]'s `Clone`):
/// the copy steps as the original, to the bit. The pack's [`World`] and the network's world
/// are copied through it.
pub(crate) fn copy_physics(p: &PhysicsWorld) -> PhysicsWorld {
    PhysicsWorld {
        gravity: p.gravity,
        integration_parameters: p.integration_parameters,
        physics_pipeline: rapier3d_f64::pipeline::PhysicsPipeline::new(),
        collision_pipeline: rapier3d_f64::pipeline::CollisionPipeline::new(),
        islands: p.islands.clone(),
        broad_phase: p.broad_phase.clone(),
        narrow_phase: p.narrow_phase.clone(),
        bodies: p.bodies.clone(),
        colliders: p.colliders.clone(),
        impulse_joints: p.impulse_joints.clone(),
        multibody_joints: p.multibody_joints.clone(),
        soft_bodies: p.soft_bodies.clone(),
        ccd_solver: p.ccd_solver.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The annulus of MODEL.md section 4: J2 = 0.156 kg m^2 with inner radius 0.231 m and 3 mm
    /// of steel needs an outer radius of about 0.290 m; parry's mass and transverse inertia
    /// match the closed forms of an annulus (m = rho pi t (Ro^2 - Ri^2),
    /// I_t = m (3 (Ro^2 + Ri^2) + t^2) / 12) to rounding, and the axial inertia is exact.
    #[test]
    fn disc_annulus_has_the_scene_inertia() {
        let shapes = BodyShapes::default();
        let ro = clutchpack_model::annulus_outer_radius_m(0.156, 0.231, 3e-3, 7850.0);
        assert!((ro - 0.290).abs() < 1e-3, "Ro = {ro}");
        let mp = disc_mass_properties(0.156, 0.231, &shapes);
        let m = 7850.0 * PI * 3e-3 * (ro * ro - 0.231 * 0.231);
        assert_relative_eq!(mp.mass(), m, max_relative = 1e-10);
        let it = m * (3.0 * (ro * ro + 0.231 * 0.231) + 9e-6) / 12.0;
        let i = mp.reconstruct_inertia_matrix();
        assert_relative_eq!(i.x_axis.x, it, max_relative = 1e-9);
        assert_relative_eq!(i.y_axis.y, it, max_relative = 1e-9);
        assert_relative_eq!(i.z_axis.z, 0.156, max_relative = 1e-15);
    }
}
