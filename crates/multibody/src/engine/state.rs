//! The world state of one run: the rapier world, the table of carrier bodies (`carriers.rs`:
//! the housing, the shaft, the drum, each with its motion, external torque, angle and speed),
//! the couplings and their memories, the clock, and each scheme's own part (the shared step's
//! loads and kicks, the multirate schemes' moments and faces); and what is read from it
//! (relative states, carriers, samples).

use super::carriers::{CarrierRun, External, Motion};
use super::energy::EnergyBook;
use super::events::EventBook;
use super::scheme_state::{MultirateState, SharedStep};
use crate::hook::{Coupling, CouplingForces, RelativeState};
use crate::options::MultibodyOptions;
use crate::stack::Stack;
use crate::stepping::profile_acceleration_bound;
use crate::world::{angle_about_z, Carrier, World, SHAFT};
use clutchpack_model::{
    DiscModel, DiscSample, EngineError, PackModel, Sample, Shaft, ShaftExcitation,
};
use rapier3d_f64::prelude::{RigidBody, Vector};
use std::sync::Arc;

/// Reads the relative state of a disc in the shaft's frame. `omega_s` and `omega_d` are the
/// speeds about the axis at the time of the poses; `owed` is the disc's turn about the axis not
/// yet in its rapier pose (`world.rs`).
pub(super) fn relative_state(
    shaft: &RigidBody,
    omega_s: f64,
    disc: &RigidBody,
    omega_d: f64,
    owed: f64,
) -> RelativeState {
    let qs = *shaft.rotation();
    let qs_inv = qs.inverse();
    let q_rel = qs_inv * *disc.rotation();
    let d = qs_inv * (disc.translation() - shaft.translation());
    let dv = qs_inv * (disc.linvel() - shaft.linvel());
    let rate = dv - Vector::new(0.0, 0.0, omega_s).cross(d);
    RelativeState {
        phi: -(angle_about_z(&q_rel) + owed),
        dphi: omega_s - omega_d,
        offset: [d.x, d.y],
        offset_rate: [rate.x, rate.y],
    }
}

/// The state of one run: the world, the hook's memories, the events, the clock.
///
/// Couplings are numbered as the engine's output: the friction discs (carrier: the shaft),
/// then the separator plates (carrier: the drum, or the housing). The carriers are a table
/// (`carriers`, in the world's order, `World::carriers`), each coupling's an index into it
/// (`World::carrier_of`).
///
/// Who writes what: the models and the couplings are set here and only read after; the
/// impact events and the energy audit are books written through their own methods
/// (`events.rs`, `energy.rs`); what only one scheme keeps is that scheme's own part
/// (`scheme_state.rs`): the teeth's kicks and the loads in [`SharedStep`], written by the
/// shared step only (`forces.rs`), the bodies' moments and the clamped faces in
/// [`MultirateState`], by the multirate step only; the clock and the kinematic state (`t`,
/// the shaft's angle and speed, the bodies' speeds, the relative states and the forces, the
/// teeth's potential, the world's poses) by the two schemes that advance it, the shared step (`forces.rs`) and the
/// multirate step (`multirate.rs`, `inertial.rs`); the stack and the carriers by the shared
/// step and their own methods (`stack.rs`), and by the multirate step (the open gaps' heat,
/// the inertial carriers' angles and speeds).
///
/// A run owns everything it reads (the model behind an `Arc`, shared with the engine and the
/// clones of a session until an input changes it), so that a session can hold it and clone it.
#[derive(Clone)]
pub(super) struct Run {
    /// The pack with the inputs in force from `t` on (a session's `set_inputs` writes the
    /// driven ones, `session.rs`).
    pub(super) pack: Arc<PackModel>,
    /// The coupled bodies' models: the discs, then the plates.
    pub(super) bodies: Arc<[DiscModel]>,
    pub(super) world: World,
    /// The carrier bodies (`carriers.rs`), in the world's order (`World::carriers`): how each
    /// moves, its external torque, its angle and speed at `t`.
    pub(super) carriers: Vec<CarrierRun>,
    pub(super) stack: Option<Stack>,
    pub(super) couplings: Vec<Coupling>,
    /// Effective mass per tooth of each coupling, kg (reduced with an inertial carrier).
    pub(super) m_eff: Vec<f64>,
    /// The impact events (written through its methods only, `events.rs`).
    pub(super) events: EventBook,
    /// The hook's results at `t` (filled by [`Run::evaluate`]).
    pub(super) rel: Vec<RelativeState>,
    pub(super) forces: Vec<CouplingForces>,
    /// What only the shared step keeps from one step to the next (`scheme_state.rs`).
    pub(super) shared: SharedStep,
    /// Body speeds at `t` (synchronised with the poses), rad/s.
    pub(super) omega_d: Vec<f64>,
    /// What only the multirate schemes keep (`scheme_state.rs`).
    pub(super) multirate: MultirateState,
    /// Time of the evaluation before the last step.
    pub(super) t_prev: Option<f64>,
    /// Time, s.
    pub(super) t: f64,
    /// Elastic energy in the teeth at `t`, J.
    pub(super) potential_j: f64,
    /// The energy audit (written through its methods only, `energy.rs`).
    pub(super) energy: EnergyBook,
    /// [`Run::update_stack`]'s buffer of the teeth's normal loads, N (kept so that a step
    /// does not allocate).
    pub(super) normal_buf: Vec<f64>,
    /// Whether the open pack's multirate step carries the bodies from one world step to the
    /// next itself, without rapier's step (`Run::carry_bodies`, `multirate.rs`): every carrier
    /// fixed or prescribed, every body concentric, so that rapier would only turn each body
    /// by its mean speed over the step.
    pub(super) carries_bodies: bool,
    /// Whether rapier's poses lag the run's state (carried without rapier since);
    /// `Run::catch_up_world` brings them up to date.
    pub(super) world_behind: bool,
}

/// Each coupling's effective mass along its line of action, kg: the body's, in series with
/// its carrier's when the carrier is a body of its own (the step control's impact duration).
fn effective_masses(
    bodies: &[DiscModel],
    carrier_of: &[usize],
    carriers: &[CarrierRun],
) -> Vec<f64> {
    bodies
        .iter()
        .zip(carrier_of)
        .map(|(d, &c)| {
            let md = d.spline.effective_mass_kg(d.inertia_kg_m2);
            match carriers[c].motion {
                Motion::Inertial { j, .. } => {
                    let mc = d.spline.effective_mass_kg(j);
                    md * mc / (md + mc)
                }
                _ => md,
            }
        })
        .collect()
}

/// Bound of the shaft's acceleration from its drive alone, rad/s^2: the profile's for a
/// prescribed shaft or an inertial one driven by a profile (eq 4), the largest drive torque
/// over `J1` for a torque drive.
pub(super) fn shaft_accel_bound(shaft: &Shaft) -> f64 {
    match shaft {
        Shaft::Prescribed(p) => profile_acceleration_bound(p),
        Shaft::Inertial {
            inertia_kg_m2,
            excitation,
            ..
        } => match excitation {
            ShaftExcitation::Profile(p) => profile_acceleration_bound(p),
            ShaftExcitation::Torque { table, .. } => {
                table.y.iter().fold(0.0, |m: f64, y| m.max(y.abs())) / inertia_kg_m2
            }
            ShaftExcitation::Held { torque_n_m, .. } => torque_n_m.abs() / inertia_kg_m2,
        },
    }
}

impl Run {
    pub(super) fn new(
        pack: Arc<PackModel>,
        opts: &MultibodyOptions,
        per_tooth: &[bool],
        multirate: bool,
    ) -> Result<Run, EngineError> {
        let world = World::build(&pack, &opts.shapes, opts.mount.for_scheme(multirate))?;
        let bodies: Arc<[DiscModel]> = pack.discs.iter().chain(&pack.plates).cloned().collect();
        let couplings: Vec<Coupling> = bodies
            .iter()
            .zip(per_tooth)
            .map(|(d, &pt)| {
                let errors: Vec<f64> = (0..d.tooth_spacing_errors_m.len())
                    .map(|k| d.tooth_phase_error_rad(k))
                    .collect();
                Coupling::new(d.spline, d.law, pt, &errors)
            })
            .collect();
        let nd = couplings.len();
        // the carriers in the world's order: the housing at rest, the shaft (eq 3 or 4), the
        // drum (its inertia, drag and load)
        let carriers: Vec<CarrierRun> = world
            .carriers
            .iter()
            .map(|c| {
                let still = |motion, external, speed| CarrierRun {
                    motion,
                    external,
                    drive_bound: 0.0,
                    exact: false,
                    switch: None,
                    name: "housing",
                    angle: 0.0,
                    speed,
                };
                match (c.role, &pack.shaft, &pack.drum) {
                    (Carrier::Housing, _, _) => still(Motion::Fixed, External::None, 0.0),
                    (Carrier::Shaft, Shaft::Prescribed(p), _) => CarrierRun {
                        drive_bound: shaft_accel_bound(&pack.shaft),
                        exact: true,
                        name: "shaft",
                        ..still(
                            Motion::Prescribed(Arc::new(p.clone())),
                            External::Drive,
                            pack.shaft.initial_speed_rad_s(),
                        )
                    },
                    (
                        Carrier::Shaft,
                        Shaft::Inertial {
                            inertia_kg_m2,
                            damping_n_m_s_rad,
                            ..
                        },
                        _,
                    ) => CarrierRun {
                        drive_bound: shaft_accel_bound(&pack.shaft),
                        exact: true,
                        name: "inertial shaft",
                        ..still(
                            Motion::Inertial {
                                j: *inertia_kg_m2,
                                damping: *damping_n_m_s_rad,
                            },
                            External::Drive,
                            pack.shaft.initial_speed_rad_s(),
                        )
                    },
                    (Carrier::Drum, _, Some(dr)) => CarrierRun {
                        name: "drum",
                        ..still(
                            Motion::Inertial {
                                j: dr.inertia_kg_m2,
                                damping: dr.drag_n_m_s_rad,
                            },
                            External::Load(dr.load_torque_n_m),
                            dr.initial_speed_rad_s,
                        )
                    },
                    (Carrier::Drum, _, None) => unreachable!("a drum body without a drum"),
                }
            })
            .collect();
        let n_carriers = carriers.len();
        let m_eff = effective_masses(&bodies, &world.carrier_of, &carriers);
        let stack = pack
            .stack
            .as_ref()
            .map(|st| Stack::new(st, pack.discs.len()));
        let carries_bodies = multirate
            && carriers.iter().all(|k| !k.is_inertial())
            && bodies
                .iter()
                .all(|d| !d.radial_float && d.initial_offset_m == [0.0; 2]);
        Ok(Run {
            bodies,
            world,
            carriers,
            stack,
            couplings,
            m_eff,
            events: EventBook::new(nd),
            rel: Vec::with_capacity(nd),
            forces: Vec::with_capacity(nd),
            shared: SharedStep::new(nd, n_carriers),
            omega_d: Vec::with_capacity(nd),
            multirate: MultirateState::new(nd),
            t_prev: None,
            t: 0.0,
            potential_j: 0.0,
            energy: EnergyBook::default(),
            normal_buf: Vec::with_capacity(nd),
            carries_bodies,
            world_behind: false,
            pack,
        })
    }

    /// The stack's torque on coupling body `i` over the step being taken, N m (0 without a
    /// stack).
    pub(super) fn stack_torque(&self, i: usize) -> f64 {
        self.stack.as_ref().map_or(0.0, |s| s.torque_on(i))
    }

    /// The ramp integral of the stack's torque on body `i` over the last step (the step's
    /// constant torque times half its length), N m s: its share of the speed synchronised
    /// to `t`.
    pub(super) fn stack_past(&self, i: usize) -> f64 {
        match (&self.stack, self.t_prev) {
            (Some(s), Some(t0)) => {
                let b = s.body.iter().position(|&b| b == i);
                b.map_or(0.0, |b| s.torque[b] * 0.5 * (self.t - t0))
            }
            _ => 0.0,
        }
    }

    /// The speed of coupling `i`'s carrier at `t`, rad/s.
    pub(super) fn carrier_speed(&self, i: usize) -> f64 {
        self.carriers[self.world.carrier_of[i]].speed
    }

    /// The unwrapped angle of coupling `i`'s carrier at `t`, rad.
    pub(super) fn carrier_angle(&self, i: usize) -> f64 {
        self.carriers[self.world.carrier_of[i]].angle
    }

    /// The rapier body of coupling `i`'s carrier.
    pub(super) fn carrier_body(&self, i: usize) -> rapier3d_f64::prelude::RigidBodyHandle {
        self.world.carriers[self.world.carrier_of[i]].handle
    }

    /// The sample at `t`.
    pub(super) fn sample(&self, tooth_loads: bool) -> Sample {
        Sample {
            t_s: self.t,
            shaft_angle_rad: self.carriers[SHAFT].angle,
            shaft_speed_rad_s: self.carriers[SHAFT].speed,
            discs: (0..self.forces.len())
                .map(|i| self.disc_sample(i, tooth_loads))
                .collect(),
        }
    }

    /// [`Run::sample`] into `out`, reusing its buffers: without per-tooth loads (lumped
    /// couplings, or `tooth_loads` false) it allocates nothing once `out` has held a sample.
    pub(super) fn sample_into(&self, tooth_loads: bool, out: &mut Sample) {
        out.t_s = self.t;
        out.shaft_angle_rad = self.carriers[SHAFT].angle;
        out.shaft_speed_rad_s = self.carriers[SHAFT].speed;
        let n = self.forces.len();
        out.discs.truncate(n);
        for i in 0..n {
            let mut loads = match out.discs.get_mut(i) {
                Some(d) => std::mem::take(&mut d.tooth_loads_n),
                None => Vec::new(),
            };
            loads.clear();
            if tooth_loads {
                loads.extend(self.couplings[i].tooth_loads_n());
            }
            let d = disc_sample(
                &self.forces[i],
                &self.rel[i],
                self.carrier_angle(i),
                self.omega_d[i],
                loads,
            );
            match out.discs.get_mut(i) {
                Some(slot) => *slot = d,
                None => out.discs.push(d),
            }
        }
    }

    /// Coupling `i`'s state at `t` (per-tooth loads only when `tooth_loads`).
    pub(super) fn disc_sample(&self, i: usize, tooth_loads: bool) -> DiscSample {
        let tooth_loads_n = if tooth_loads {
            self.couplings[i].tooth_loads_n()
        } else {
            Vec::new()
        };
        disc_sample(
            &self.forces[i],
            &self.rel[i],
            self.carrier_angle(i),
            self.omega_d[i],
            tooth_loads_n,
        )
    }
}

/// A coupling's state: its forces `f`, relative state `rel`, the carrier's angle (rad), the
/// disc's speed (rad/s) and the per-tooth loads (N, empty when not resolved or not asked).
pub(super) fn disc_sample(
    f: &CouplingForces,
    rel: &RelativeState,
    carrier_angle_rad: f64,
    omega_d_rad_s: f64,
    tooth_loads_n: Vec<f64>,
) -> DiscSample {
    DiscSample {
        angle_rad: carrier_angle_rad - rel.phi,
        speed_rad_s: omega_d_rad_s,
        rel_angle_rad: rel.phi,
        penetration_m: f.kin.delta_m,
        closing_speed_m_s: f.kin.v_n_m_s,
        load_n: f.load_n,
        torque_n_m: f.moment[2],
        engaged: f.depth_m > 0.0,
        stiffness: f.stiffness,
        tooth_loads_n,
        center_offset_m: rel.offset,
    }
}

/// The carriers' table (`carriers.rs`) as the schemes read and write it.
impl Run {
    /// The couplings carried by carrier `c`.
    pub(super) fn carried_by(&self, c: usize) -> Vec<usize> {
        (0..self.couplings.len())
            .filter(|&i| self.world.carrier_of[i] == c)
            .collect()
    }

    /// The inertial carriers, in table order.
    pub(super) fn inertial_carriers(&self) -> Vec<usize> {
        (0..self.carriers.len())
            .filter(|&c| self.carriers[c].is_inertial())
            .collect()
    }

    /// Carrier `c`'s unwrapped angle, rad, and speed, rad/s, at `t`.
    pub(super) fn carrier_state(&self, c: usize) -> (f64, f64) {
        let k = &self.carriers[c];
        (k.angle, k.speed)
    }

    /// Recomputes each coupling's effective mass (`m_eff`) after a carrier's inertia changed.
    pub(super) fn refresh_effective_masses(&mut self) {
        self.m_eff = effective_masses(&self.bodies, &self.world.carrier_of, &self.carriers);
    }

    /// Sets carrier `c`'s unwrapped angle, rad, and speed, rad/s (at a world step's end).
    pub(super) fn set_carrier_state(&mut self, c: usize, angle: f64, speed: f64) {
        let k = &mut self.carriers[c];
        (k.angle, k.speed) = (angle, speed);
    }

    /// The external torque on carrier `c` at `t` (s), N m, positive along the positive
    /// rotation: the drive (Hu et al. eq 4) as a function of time, a load held between inputs,
    /// or before a driven torque's last change (`switch`) the value held until then (only the
    /// shared step's past half-kick reaches back before it; the multirate schemes' sub-steps
    /// start at or after it).
    pub(super) fn external_at(&self, c: usize, t: f64) -> f64 {
        let k = &self.carriers[c];
        match (k.switch, k.external) {
            (Some((t_switch, before)), _) if t < t_switch => before,
            (_, External::Drive) => self.pack.shaft.drive_torque_n_m(t),
            (_, External::Load(l)) => l,
            (_, External::None) => 0.0,
        }
    }

    /// The bound of inertial carrier `c`'s acceleration at speed `w` with the teeth's torques
    /// `reaction` (sum of magnitudes, N m) on it, rad/s^2: its external torque's bound (the
    /// drive's, or a load's), the damping, the reactions (as the shared step's controller,
    /// `control.rs`).
    pub(super) fn inertial_accel_bound(&self, c: usize, w: f64, reaction: f64) -> f64 {
        let (inv_j, damping) = self.carriers[c].inertia();
        let own = match self.carriers[c].external {
            External::Drive => self.carriers[c].drive_bound,
            External::Load(l) => l.abs() * inv_j,
            External::None => 0.0,
        };
        own + (damping * w.abs() + reaction) * inv_j
    }

    /// Books the work of inertial carrier `c`'s external torque (J) in the energy audit: the
    /// drive's or the load's.
    pub(super) fn book_external(&mut self, c: usize, work_j: f64, drag_j: f64) {
        match self.carriers[c].external {
            External::Load(_) => {
                self.energy.add_sub_step(0.0, drag_j);
                self.energy.add_load_work(work_j);
            }
            _ => self.energy.add_sub_step(work_j, drag_j),
        }
    }
}
