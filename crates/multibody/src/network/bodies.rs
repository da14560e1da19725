//! The rapier3d-f64 world of a driveline network (MODEL.md section 8): one dynamic rigid body
//! per body that turns, turning about the world `+z` axis (its translations and the two other
//! rotations locked by rapier's locked axes, as the pack's discs are held with
//! `DiscMount::LockedAxes`, `world.rs`), with the network's inertia about the axis; the fixed
//! body, if any, and the prescribed bodies rapier fixed bodies (a prescribed body's angle and
//! speed are kept here, set from its profile after each step: [`NetworkWorld::set_prescribed`]). No colliders and no joints: the couplings' torques
//! (`network/mod.rs`) are the only forces.
//!
//! With one solver iteration rapier is semi-implicit Euler for these torques (`lib.rs`):
//! `w += h T / J`, then the pose turns by `2 atan(w h / 2)`; the angle is kept here unwrapped
//! as `theta += h (w_k + w_{k+1}) / 2`, the exact turn of the speed's affine path under a torque
//! held over the step (rapier's own `h w_{k+1}` is first order), and written back to the pose
//! after each step (as `World::step` restores the exact turn on the pack's bodies).

use clutchpack_model::network::Network;
use parry3d_f64::mass_properties::MassProperties;
use rapier3d_f64::prelude::{
    LockedAxes, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, Rotation, Vector,
};

/// The rapier world of a network and its bodies' angles.
pub(crate) struct NetworkWorld {
    physics: PhysicsWorld,
    /// The rapier body of each network body (the fixed body's is a rapier fixed body).
    handles: Vec<RigidBodyHandle>,
    /// Whether each body is the fixed body or a prescribed one (not integrated).
    fixed: Vec<bool>,
    /// Each prescribed body's speed, rad/s (0 for the others).
    given: Vec<f64>,
    /// Each body's angle, rad, unwrapped (`theta += h w` per step).
    angle: Vec<f64>,
}

/// A copy of the world, exact: every part of rapier's state is cloned but the physics and
/// collision pipelines, which are not `Clone` and hold only workspace rebuilt at every step
/// (as the pack's `World`'s copy, `world.rs`): the copy steps as the original, to the bit
/// (`tests/network.rs`).
impl Clone for NetworkWorld {
    fn clone(&self) -> NetworkWorld {
        NetworkWorld {
            physics: crate::world::copy_physics(&self.physics),
            handles: self.handles.clone(),
            fixed: self.fixed.clone(),
            given: self.given.clone(),
            angle: self.angle.clone(),
        }
    }
}

impl NetworkWorld {
    /// Builds the world at t = 0: every body at angle 0 turning at its initial speed.
    pub fn build(net: &Network) -> NetworkWorld {
        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::ZERO;
        let p = &mut physics.integration_parameters;
        // one iteration (= one substep): rapier is semi-implicit Euler (lib.rs)
        p.num_solver_iterations = 1;
        p.max_ccd_substeps = 0;
        let mut handles = Vec::with_capacity(net.bodies.len());
        for b in &net.bodies {
            let h = if !b.is_free() {
                physics.insert_body(RigidBodyBuilder::fixed())
            } else {
                let j = b.inertia_kg_m2;
                // a nominal 1 kg (its translations are locked); the inertia about +z is J
                let mprops = MassProperties::with_principal_inertia_frame(
                    Vector::ZERO,
                    1.0,
                    Vector::new(j, j, j),
                    Rotation::IDENTITY,
                );
                let rb = RigidBodyBuilder::dynamic()
                    .can_sleep(false)
                    .gyroscopic_forces_enabled(false)
                    .allow_fast_rotation(true)
                    .additional_mass_properties(mprops)
                    .locked_axes(
                        LockedAxes::TRANSLATION_LOCKED
                            | LockedAxes::ROTATION_LOCKED_X
                            | LockedAxes::ROTATION_LOCKED_Y,
                    )
                    .angvel(Vector::new(0.0, 0.0, b.initial_speed_rad_s));
                let h = physics.insert_body(rb);
                physics.bodies[h].recompute_mass_properties_from_colliders(&physics.colliders);
                h
            };
            handles.push(h);
        }
        NetworkWorld {
            physics,
            handles,
            fixed: net.bodies.iter().map(|b| !b.is_free()).collect(),
            given: net
                .bodies
                .iter()
                .map(|b| b.prescribed().map_or(0.0, |p| p.speed(0.0)))
                .collect(),
            angle: vec![0.0; net.bodies.len()],
        }
    }

    /// Each body's speed about its axis, rad/s (0 for the fixed body).
    pub fn speeds(&self) -> Vec<f64> {
        self.handles
            .iter()
            .zip(&self.fixed)
            .zip(&self.given)
            .map(|((h, f), g)| {
                if *f {
                    *g
                } else {
                    self.physics.bodies[*h].angvel().z
                }
            })
            .collect()
    }

    /// Each body's angle, rad (unwrapped).
    pub fn angles(&self) -> &[f64] {
        &self.angle
    }

    /// Sets prescribed body `i`'s speed (rad/s) and angle (rad, unwrapped): its profile's.
    pub fn set_prescribed(&mut self, i: usize, speed_rad_s: f64, angle_rad: f64) {
        self.given[i] = speed_rad_s;
        self.angle[i] = angle_rad;
    }

    /// Sets each turning body's speed, rad/s.
    pub fn set_speeds(&mut self, w: &[f64]) {
        for (i, h) in self.handles.iter().enumerate() {
            if !self.fixed[i] {
                self.physics.bodies[*h].set_angvel(Vector::new(0.0, 0.0, w[i]), false);
            }
        }
    }

    /// Applies `torque` (N m about `+z`, per body) over a step of `h` s and steps rapier;
    /// returns the speeds at the step's end, rad/s.
    pub fn step(&mut self, torque: &[f64], h: f64) -> Vec<f64> {
        for (i, hd) in self.handles.iter().enumerate() {
            if self.fixed[i] {
                continue;
            }
            let body = &mut self.physics.bodies[*hd];
            body.reset_torques(false);
            body.add_torque(Vector::new(0.0, 0.0, torque[i]), false);
        }
        let w0 = self.speeds();
        self.physics.integration_parameters.dt = h;
        self.physics.step();
        let w = self.speeds();
        for (i, hd) in self.handles.iter().enumerate() {
            if self.fixed[i] {
                continue;
            }
            // the torque is held over the step, so the speed is affine in time and the turn
            // is exactly h (w0 + w) / 2 (rapier's semi-implicit Euler turns by h w, first
            // order); the pose gets it
            self.angle[i] += 0.5 * h * (w0[i] + w[i]);
            let q = Rotation::from_rotation_z(self.angle[i].rem_euclid(std::f64::consts::TAU));
            self.physics.bodies[*hd].set_rotation(q, false);
        }
        w
    }
}
