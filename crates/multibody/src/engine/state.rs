//! The world state of one run: the rapier world, the drives of the shaft and the drum, the
//! couplings and their memories, the clock, and each scheme's own part (the shared step's
//! loads and kicks, the multirate schemes' moments and faces); and what is read from it
//! (relative states, carriers, samples).

use super::energy::EnergyBook;
use super::events::EventBook;
use super::scheme_state::{MultirateState, SharedStep};
use crate::hook::{Coupling, CouplingForces, RelativeState};
use crate::options::MultibodyOptions;
use crate::stack::Stack;
use crate::stepping::profile_acceleration_bound;
use crate::world::{angle_about_z, Carrier, World};
use clutchpack_model::{
    DiscModel, DiscSample, DrumModel, EngineError, PackModel, Sample, Shaft, ShaftExcitation,
    SpeedProfile,
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

/// The shaft as the run loop drives it.
#[derive(Debug, Clone)]
pub(super) enum ShaftDrive {
    /// Follows a speed profile exactly (eq 3); shared (`Arc`) so that a loop can hold it while
    /// it writes the run's state.
    Prescribed(Arc<SpeedProfile>),
    /// A body (eq 4): inertia `J1`, damping `C1`.
    Inertial { j1: f64, c1: f64 },
}

/// The output drum as the run loop drives it: a body with inertia, a load torque and drag,
/// carrying the separator plates.
#[derive(Debug, Clone)]
pub(super) struct DrumRun {
    pub(super) model: DrumModel,
    /// Speed at `t` (synchronised) and unwrapped angle, rad/s and rad.
    pub(super) omega: f64,
    pub(super) theta: f64,
}

/// The state of one run: the world, the hook's memories, the events, the clock.
///
/// Couplings are numbered as the engine's output: the friction discs (carrier: the shaft),
/// then the separator plates (carrier: the drum, or the housing).
///
/// Who writes what: the models and the couplings are set here and only read after; the
/// impact events and the energy audit are books written through their own methods
/// (`events.rs`, `energy.rs`); what only one scheme keeps is that scheme's own part
/// (`scheme_state.rs`): the teeth's kicks and the loads in [`SharedStep`], written by the
/// shared step only (`forces.rs`), the bodies' moments and the clamped faces in
/// [`MultirateState`], by the multirate step only; the clock and the kinematic state (`t`,
/// the shaft's angle and speed, the bodies' speeds, the relative states and the forces, the
/// teeth's potential, the world's poses) by the two schemes that advance it, the shared step (`forces.rs`) and the
/// multirate step (`multirate.rs`, `inertial.rs`); the stack and the drum by the shared step
/// and their own methods (`stack.rs`), and by the multirate step (the open gaps' heat, the
/// drum's angle and speed).
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
    pub(super) shaft: ShaftDrive,
    /// Bound of the drive's shaft acceleration, rad/s^2.
    pub(super) shaft_accel_bound: f64,
    pub(super) drum: Option<DrumRun>,
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
    /// Time, unwrapped shaft angle and shaft speed.
    pub(super) t: f64,
    pub(super) theta_s: f64,
    pub(super) omega_s: f64,
    /// Elastic energy in the teeth at `t`, J.
    pub(super) potential_j: f64,
    /// The energy audit (written through its methods only, `energy.rs`).
    pub(super) energy: EnergyBook,
    /// A driven drive torque on an inertial shaft changed at this time, s, from this value,
    /// N m: the torque before it, for the past half of the kick of the step that ends there
    /// (`forces.rs`). `None`: the pack's excitation holds for all `t`.
    pub(super) drive_switch: Option<(f64, f64)>,
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
        let shaft = match &pack.shaft {
            Shaft::Prescribed(p) => ShaftDrive::Prescribed(Arc::new(p.clone())),
            Shaft::Inertial {
                inertia_kg_m2,
                damping_n_m_s_rad,
                ..
            } => ShaftDrive::Inertial {
                j1: *inertia_kg_m2,
                c1: *damping_n_m_s_rad,
            },
        };
        let shaft_accel_bound = shaft_accel_bound(&pack.shaft);
        let m_eff = bodies
            .iter()
            .zip(&world.carriers)
            .map(|(d, carrier)| {
                let md = d.spline.effective_mass_kg(d.inertia_kg_m2);
                let carrier_inertia = match (carrier, &shaft) {
                    (Carrier::Shaft, ShaftDrive::Inertial { j1, .. }) => Some(*j1),
                    (Carrier::Drum, _) => pack.drum.map(|dr| dr.inertia_kg_m2),
                    _ => None,
                };
                match carrier_inertia {
                    Some(j) => {
                        let mc = d.spline.effective_mass_kg(j);
                        md * mc / (md + mc)
                    }
                    None => md,
                }
            })
            .collect();
        let drum = pack.drum.map(|model| DrumRun {
            model,
            omega: model.initial_speed_rad_s,
            theta: 0.0,
        });
        let stack = pack
            .stack
            .as_ref()
            .map(|st| Stack::new(st, pack.discs.len()));
        Ok(Run {
            bodies,
            world,
            shaft,
            shaft_accel_bound,
            drum,
            stack,
            couplings,
            m_eff,
            events: EventBook::new(nd),
            rel: Vec::with_capacity(nd),
            forces: Vec::with_capacity(nd),
            shared: SharedStep::new(nd),
            omega_d: Vec::with_capacity(nd),
            multirate: MultirateState::new(nd),
            t_prev: None,
            t: 0.0,
            theta_s: 0.0,
            omega_s: pack.shaft.initial_speed_rad_s(),
            potential_j: 0.0,
            energy: EnergyBook::default(),
            drive_switch: None,
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
        match self.world.carriers[i] {
            Carrier::Shaft => self.omega_s,
            Carrier::Housing => 0.0,
            Carrier::Drum => self.drum.as_ref().map_or(0.0, |d| d.omega),
        }
    }

    /// The unwrapped angle of coupling `i`'s carrier at `t`, rad.
    pub(super) fn carrier_angle(&self, i: usize) -> f64 {
        match self.world.carriers[i] {
            Carrier::Shaft => self.theta_s,
            Carrier::Housing => 0.0,
            Carrier::Drum => self.drum.as_ref().map_or(0.0, |d| d.theta),
        }
    }

    /// The rapier body of coupling `i`'s carrier.
    pub(super) fn carrier_body(&self, i: usize) -> rapier3d_f64::prelude::RigidBodyHandle {
        match self.world.carriers[i] {
            Carrier::Shaft => self.world.shaft,
            Carrier::Housing => self.world.housing,
            Carrier::Drum => self.world.drum.expect("a drum"),
        }
    }

    /// The sample at `t`.
    pub(super) fn sample(&self, tooth_loads: bool) -> Sample {
        Sample {
            t_s: self.t,
            shaft_angle_rad: self.theta_s,
            shaft_speed_rad_s: self.omega_s,
            discs: (0..self.forces.len())
                .map(|i| self.disc_sample(i, tooth_loads))
                .collect(),
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
