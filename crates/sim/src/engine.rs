//! [`MultibodyEngine`]: the run loop around the rapier world, the spline hook and the step
//! controller; samples, impact events and the energy audit.

use crate::hook::{Coupling, CouplingForces, RelativeState};
use crate::integrate::{future_impulse, past_impulse, Kick, Load, LoadHistory, Motion};
use crate::options::{AdaptiveStepping, MultibodyOptions, Stepping, ToothResolution};
use crate::stack::Stack;
use crate::stepping::{
    contact_duration_s, coupling_step, profile_acceleration_bound, CouplingView,
};
use crate::world::{angle_about_z, Carrier, World};
use clutchpack_model::{
    DiscModel, DiscSample, DrumModel, Engine, EngineError, ImpactTracker, LawKind, Observer,
    PackModel, RunStats, Sample, Shaft, ShaftExcitation, SpeedProfile,
};
use clutchpack_scene::Scene;
use rapier3d_f64::prelude::{RigidBody, Rotation, Vector};

/// How often (in steps) the observer's `progress` is polled.
const PROGRESS_EVERY: u64 = 1000;

/// Energy bookkeeping of a run (J), for conservation checks: with no drag and `p = 0`,
/// `drive_work_j + drag_work_j + stack_work_j + load_work_j = (kinetic_j +
/// contact_potential_j) - (initial_kinetic_j + initial_contact_potential_j)` up to the
/// integrator's error.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyAudit {
    /// Work done by the drive since t = 0: for a prescribed shaft the work of the shaft on the
    /// teeth, the teeth's torque on the discs (those on the shaft) integrated over the shaft's
    /// turn; for an
    /// inertial shaft the work of the drive torque on the shaft (trapezoidal rule per step).
    pub drive_work_j: f64,
    /// Work of the oil drag on the discs and plates, of the shaft damping and of the drum's
    /// drag (<= 0).
    pub drag_work_j: f64,
    /// Work of the stack on the discs and plates: face friction and open-gap drag (<= 0),
    /// `sum Q (w_upper - w_lower)` per step with the step's mean speeds.
    pub stack_work_j: f64,
    /// Work of the drum's load torque (trapezoidal rule per step).
    pub load_work_j: f64,
    /// Kinetic energy at t = 0: the discs and plates, and the shaft and the drum when they are
    /// inertial.
    pub initial_kinetic_j: f64,
    /// Kinetic energy at the end of the run.
    pub kinetic_j: f64,
    /// Energy stored in the teeth at t = 0, `sum (2/5) K s^2.5` (a potential for `p = 0`).
    pub initial_contact_potential_j: f64,
    /// Energy stored in the teeth at the end of the run.
    pub contact_potential_j: f64,
}

/// The rapier3d-f64 multibody engine (see the crate docs).
#[derive(Debug, Clone)]
pub struct MultibodyEngine {
    pack: PackModel,
    record_rate_hz: f64,
    options: MultibodyOptions,
    energy: EnergyAudit,
    per_tooth: Vec<bool>,
}

/// Per-coupling event bookkeeping.
#[derive(Debug, Clone, Default)]
struct EventTrack {
    tracker: ImpactTracker,
    /// (t, depth, v_n) at the previous evaluation.
    prev: Option<(f64, f64, f64)>,
    /// The last two (t, load) of the open event, for the parabolic peak.
    last: Option<(f64, f64)>,
    before_last: Option<(f64, f64)>,
    /// The step of the open event (adaptive stepping).
    event_step_s: Option<f64>,
    /// The onset of the open event, s.
    event_t_on_s: Option<f64>,
}

impl EventTrack {
    /// Feeds the coupling's state at `t`; returns an event that closed.
    fn update(
        &mut self,
        t: f64,
        f: &CouplingForces,
        contact_step: impl FnOnce(f64) -> f64,
    ) -> Option<clutchpack_model::ImpactEvent> {
        let depth = f.depth_m;
        let v = f.kin.v_n_m_s;
        let mut closed = None;
        if depth > 0.0 {
            if !self.tracker.is_open() {
                let (t_on, v_on) = match self.prev {
                    Some((t0, d0, v0)) if d0 <= 0.0 => {
                        let w = -d0 / (depth - d0);
                        (t0 + w * (t - t0), v0 + w * (v - v0))
                    }
                    _ => (t, v),
                };
                self.tracker.begin(t_on, f.kin.flank, v_on);
                self.last = None;
                self.before_last = None;
                self.event_step_s = Some(contact_step(v_on));
                self.event_t_on_s = Some(t_on);
            }
            self.push(t, f.load_n);
        } else if self.tracker.is_open() {
            let t_off = match self.prev {
                Some((t0, d0, _)) if d0 > 0.0 => t0 + d0 / (d0 - depth) * (t - t0),
                _ => t,
            };
            self.push(t, 0.0);
            closed = self.tracker.end(t_off);
            self.event_step_s = None;
            self.event_t_on_s = None;
        }
        self.prev = Some((t, depth, v));
        closed
    }

    /// Observes a load sample and, when the previous sample was a local maximum of `|F|`, the
    /// vertex of the parabola through the three samples around it (the peak between steps).
    fn push(&mut self, t: f64, load: f64) {
        self.tracker.observe(t, load);
        if let (Some((t0, f0)), Some((t1, f1))) = (self.before_last, self.last) {
            let (a0, a1, a2) = (f0.abs(), f1.abs(), load.abs());
            if a1 > 0.0 && a1 >= a0 && a1 >= a2 && t0 < t1 && t1 < t {
                let d01 = (a1 - a0) / (t1 - t0);
                let d12 = (a2 - a1) / (t - t1);
                let curv = (d12 - d01) / (t - t0);
                if curv < 0.0 {
                    let tv = 0.5 * (t0 + t1) - d01 / (2.0 * curv);
                    if (t0..=t).contains(&tv) {
                        let av = a1 + d01 * (tv - t1) + curv * (tv - t0) * (tv - t1);
                        self.tracker.observe(tv, f1.signum() * av);
                    }
                }
            }
        }
        self.before_last = self.last;
        self.last = Some((t, load));
    }
}

impl MultibodyEngine {
    /// Builds the engine for a scene with the default options: adaptive stepping with the
    /// scene's `max_step_s`, lumped teeth where exact, per-tooth loads in the samples if the
    /// scene asks for them (`simulation.record_per_tooth`).
    pub fn from_scene(scene: &Scene) -> Result<MultibodyEngine, EngineError> {
        let mut options = MultibodyOptions {
            record_tooth_loads: scene.simulation.record_per_tooth,
            ..Default::default()
        };
        if let Stepping::Adaptive(a) = &mut options.stepping {
            a.max_step_s = scene.simulation.max_step_s;
        }
        MultibodyEngine::with_options(scene, options)
    }

    /// Builds the engine for a scene with explicit options.
    pub fn with_options(
        scene: &Scene,
        options: MultibodyOptions,
    ) -> Result<MultibodyEngine, EngineError> {
        MultibodyEngine::from_pack(scene.pack.clone(), scene.simulation.record_rate_hz, options)
    }

    /// Builds the engine for a pack model, emitting samples at `record_rate_hz`.
    pub fn from_pack(
        pack: PackModel,
        record_rate_hz: f64,
        options: MultibodyOptions,
    ) -> Result<MultibodyEngine, EngineError> {
        let bad = |m: String| Err(EngineError::Unsupported(m));
        if !(record_rate_hz > 0.0 && record_rate_hz.is_finite()) {
            return bad(format!("record rate {record_rate_hz} Hz: must be > 0"));
        }
        match options.stepping {
            Stepping::Fixed { dt_s } if !(dt_s > 0.0 && dt_s.is_finite()) => {
                return bad(format!("fixed step {dt_s} s: must be > 0"));
            }
            Stepping::Adaptive(a)
                if !(a.max_step_s > 0.0
                    && a.steps_per_contact > 1.0
                    && a.approach_fraction > 0.0
                    && a.approach_fraction < 1.0
                    && a.min_step_s > 0.0
                    && a.sustained_steps_per_period > std::f64::consts::PI
                    && a.sustained_after > 1.0) =>
            {
                return bad(format!("adaptive stepping {a:?}: needs max_step_s > 0, steps_per_contact > 1, approach_fraction in (0, 1), min_step_s > 0, sustained_steps_per_period > pi, sustained_after > 1"));
            }
            _ => {}
        }
        if let Some(st) = &pack.stack {
            if pack.discs.is_empty() || pack.plates.len() != pack.discs.len() + 1 {
                return bad(format!(
                    "a stack needs N friction discs and N + 1 separator plates ({} discs, {} \
                     plates)",
                    pack.discs.len(),
                    pack.plates.len()
                ));
            }
            let (ri, ro) = (st.face_inner_radius_m, st.face_outer_radius_m);
            let gap_ok = st
                .open_gap
                .is_none_or(|g| g.gap_m > 0.0 && g.viscosity_pa_s >= 0.0);
            let ok = ri > 0.0
                && ro > ri
                && st.piston.area_m2 > 0.0
                && st.spline_friction >= 0.0
                && gap_ok;
            if !ok {
                return bad(format!(
                    "stack: needs 0 < face_inner_radius_m < face_outer_radius_m, piston area \
                     > 0, spline friction >= 0, an open gap > 0 ({st:?})"
                ));
            }
        }
        if let Some(dr) = &pack.drum {
            if pack.plates.is_empty() || dr.inertia_kg_m2.is_nan() || dr.inertia_kg_m2 <= 0.0 {
                return bad(
                    "an output drum needs separator plates on it and an inertia > 0".into(),
                );
            }
        }
        let n_discs = pack.discs.len();
        let mut per_tooth = Vec::with_capacity(n_discs + pack.plates.len());
        for (j, d) in pack.discs.iter().chain(&pack.plates).enumerate() {
            let i = if j < n_discs {
                format!("discs[{j}]")
            } else {
                format!("plates[{}]", j - n_discs)
            };
            if d.law.kind == LawKind::Squeeze && d.law.oil.thickness_m > 0.0 {
                return bad(format!(
                    "{i}: the squeeze-film law is a damper with time constant m h^3 / (beta eta B^3 L) \
                     (nanoseconds near metal contact), too stiff for the explicit multibody step; \
                     use the reference engine"
                ));
            }
            if d.spline.teeth == 0 || d.inertia_kg_m2.is_nan() || d.inertia_kg_m2 <= 0.0 {
                return bad(format!("{i}: needs teeth > 0 and inertia > 0"));
            }
            if let Some(&e) = d.tooth_spacing_errors_m.iter().find(|e| !e.is_finite()) {
                return bad(format!("{i}: tooth spacing error {e} m: must be finite"));
            }
            if !d.tooth_spacing_errors_m.is_empty()
                && d.tooth_spacing_errors_m.len() != d.spline.teeth as usize
            {
                return bad(format!(
                    "{i}: {} tooth spacing errors for {} teeth: one per tooth or none",
                    d.tooth_spacing_errors_m.len(),
                    d.spline.teeth
                ));
            }
            per_tooth.push(match options.teeth {
                ToothResolution::PerTooth => true,
                // Concentric discs on a locked radial joint, no spacing errors: lumped is exact.
                ToothResolution::Auto => !d.is_concentric(),
                ToothResolution::Lumped if d.is_concentric() => false,
                ToothResolution::Lumped => {
                    return bad(format!(
                        "{i}: lumped teeth are exact only for a concentric disc without \
                         spacing errors (this one floats radially, is offset or has spacing \
                         errors): use per-tooth resolution"
                    ))
                }
            });
        }
        // Build once now so that a scene the world cannot hold fails here, not in `run`.
        World::build(&pack, &options.shapes, options.mount)?;
        Ok(MultibodyEngine {
            pack,
            record_rate_hz,
            options,
            energy: EnergyAudit::default(),
            per_tooth,
        })
    }

    /// The options in force.
    pub fn options(&self) -> &MultibodyOptions {
        &self.options
    }

    /// The energy audit of the last run.
    pub fn energy(&self) -> EnergyAudit {
        self.energy
    }
}

/// Reads the relative state of a disc in the shaft's frame. `omega_s` and `omega_d` are the
/// speeds about the axis at the time of the poses; `owed` is the disc's turn about the axis not
/// yet in its rapier pose (`world.rs`).
fn relative_state(
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

/// Powers at one evaluation, for the trapezoidal energy audit.
#[derive(Debug, Clone, Copy)]
struct Powers {
    t: f64,
    theta_s: f64,
    /// Sum of the teeth's torques on the discs, N m (prescribed shaft: work = torque x turn).
    spline_torque: f64,
    /// Power of the drive torque on an inertial shaft, W.
    drive: f64,
    /// Power of the drag, the shaft damping and the drum's drag, W.
    drag: f64,
    /// Power of the drum's load torque, W.
    load: f64,
}

/// The shaft as the run loop drives it.
#[derive(Debug, Clone, Copy)]
enum ShaftDrive<'a> {
    /// Follows a speed profile exactly (eq 3).
    Prescribed(&'a SpeedProfile),
    /// A body (eq 4): inertia `J1`, damping `C1`.
    Inertial { j1: f64, c1: f64 },
}

/// The output drum as the run loop drives it: a body with inertia, a load torque and drag,
/// carrying the separator plates.
#[derive(Debug, Clone)]
struct DrumRun {
    model: DrumModel,
    /// Speed at `t` (synchronised) and unwrapped angle, rad/s and rad.
    omega: f64,
    theta: f64,
    /// The loads on it other than the teeth's torque about the axis, and their kick.
    load: Load,
    history: LoadHistory,
    kick: Kick,
    /// The full loads (teeth included), for the first estimate of its speed.
    full_load: Load,
    full_history: LoadHistory,
    /// Acceleration at `t`, rad/s^2.
    accel: f64,
}

/// The state of one run: the world, the hook's memories, the events, the clock.
///
/// Couplings are numbered as the engine's output: the friction discs (carrier: the shaft),
/// then the separator plates (carrier: the drum, or the housing).
struct Run<'a> {
    pack: &'a PackModel,
    /// The coupled bodies' models: the discs, then the plates.
    bodies: Vec<&'a DiscModel>,
    world: World,
    shaft: ShaftDrive<'a>,
    /// Bound of the drive's shaft acceleration, rad/s^2.
    shaft_accel_bound: f64,
    drum: Option<DrumRun>,
    stack: Option<Stack<'a>>,
    couplings: Vec<Coupling>,
    /// Effective mass per tooth of each coupling, kg (reduced with an inertial carrier).
    m_eff: Vec<f64>,
    tracks: Vec<EventTrack>,
    /// The hook's results at `t` (filled by [`Run::evaluate`]).
    rel: Vec<RelativeState>,
    forces: Vec<CouplingForces>,
    /// Powers at the last evaluation.
    powers_before: Option<Powers>,
    /// Physical loads at `t` (world frame) on each coupled body and on an inertial shaft.
    disc_loads: Vec<Load>,
    shaft_load: Load,
    /// Their values at the two evaluations before, and the kicks for the next step. These
    /// leave out the teeth's torque about the axis, whose kick is integrated along the step
    /// (`teeth_past`, `teeth_motion`), and the stack's torques, solved per step (`stack.rs`).
    disc_history: Vec<LoadHistory>,
    shaft_history: LoadHistory,
    disc_kicks: Vec<Kick>,
    shaft_kick: Kick,
    /// The full loads (teeth included) and their history, for the first estimate of the
    /// synchronised speeds.
    disc_full_loads: Vec<Load>,
    shaft_full_load: Load,
    disc_full_history: Vec<LoadHistory>,
    shaft_full_history: LoadHistory,
    /// `(t, phi, dphi, ddphi)` of each coupling at the last evaluation.
    prev_motion: Vec<Option<(f64, f64, f64, f64)>>,
    /// The teeth: the past half of their kick (N m s on the body, about the axis) and the
    /// relative motion at `t` for the future half.
    teeth_past: Vec<f64>,
    /// The last `(x, teeth_impulse(i, x))` of each coupling since the last evaluation (the
    /// step's impulse is asked for by the stack, the landing and the forces).
    teeth_cache: Vec<std::cell::Cell<(f64, f64)>>,
    teeth_motion: Vec<Motion>,
    /// Body speeds at `t` (synchronised with the poses), rad/s.
    omega_d: Vec<f64>,
    /// Time of the evaluation before the last step.
    t_prev: Option<f64>,
    /// Prescribed shaft: its angle at the end of the step being taken.
    theta_next: f64,
    /// Time, unwrapped shaft angle and shaft speed.
    t: f64,
    theta_s: f64,
    omega_s: f64,
    /// Elastic energy in the teeth at `t`, J.
    potential_j: f64,
    energy: EnergyAudit,
}

impl<'a> Run<'a> {
    fn new(
        pack: &'a PackModel,
        opts: &MultibodyOptions,
        per_tooth: &[bool],
    ) -> Result<Run<'a>, EngineError> {
        let world = World::build(pack, &opts.shapes, opts.mount)?;
        let bodies: Vec<&DiscModel> = pack.discs.iter().chain(&pack.plates).collect();
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
        let tracks = (0..nd)
            .map(|i| EventTrack {
                tracker: ImpactTracker::new(i),
                ..Default::default()
            })
            .collect();
        let (shaft, shaft_accel_bound) = match &pack.shaft {
            Shaft::Prescribed(p) => (ShaftDrive::Prescribed(p), profile_acceleration_bound(p)),
            Shaft::Inertial {
                inertia_kg_m2,
                damping_n_m_s_rad,
                excitation,
            } => (
                ShaftDrive::Inertial {
                    j1: *inertia_kg_m2,
                    c1: *damping_n_m_s_rad,
                },
                match excitation {
                    ShaftExcitation::Profile(p) => profile_acceleration_bound(p),
                    ShaftExcitation::Torque { table, .. } => {
                        table.y.iter().fold(0.0, |m: f64, y| m.max(y.abs())) / inertia_kg_m2
                    }
                },
            ),
        };
        let m_eff = bodies
            .iter()
            .zip(&world.carriers)
            .map(|(d, carrier)| {
                let md = d.spline.effective_mass_kg(d.inertia_kg_m2);
                let carrier_inertia = match (carrier, shaft) {
                    (Carrier::Shaft, ShaftDrive::Inertial { j1, .. }) => Some(j1),
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
            load: [0.0; 6],
            history: LoadHistory::default(),
            kick: Kick::default(),
            full_load: [0.0; 6],
            full_history: LoadHistory::default(),
            accel: 0.0,
        });
        let stack = pack
            .stack
            .as_ref()
            .map(|st| Stack::new(st, pack.discs.len()));
        Ok(Run {
            pack,
            bodies,
            world,
            shaft,
            shaft_accel_bound,
            drum,
            stack,
            couplings,
            m_eff,
            tracks,
            rel: Vec::with_capacity(nd),
            forces: Vec::with_capacity(nd),
            powers_before: None,
            disc_loads: vec![[0.0; 6]; nd],
            shaft_load: [0.0; 6],
            disc_history: vec![LoadHistory::default(); nd],
            shaft_history: LoadHistory::default(),
            disc_kicks: vec![Kick::default(); nd],
            shaft_kick: Kick::default(),
            disc_full_loads: vec![[0.0; 6]; nd],
            shaft_full_load: [0.0; 6],
            disc_full_history: vec![LoadHistory::default(); nd],
            shaft_full_history: LoadHistory::default(),
            prev_motion: vec![None; nd],
            teeth_past: vec![0.0; nd],
            teeth_cache: vec![std::cell::Cell::new((f64::NAN, 0.0)); nd],
            teeth_motion: vec![Motion::default(); nd],
            omega_d: Vec::with_capacity(nd),
            t_prev: None,
            theta_next: 0.0,
            t: 0.0,
            theta_s: 0.0,
            omega_s: pack.shaft.initial_speed_rad_s(),
            potential_j: 0.0,
            energy: EnergyAudit::default(),
        })
    }

    /// The stack's torque on coupling body `i` over the step being taken, N m (0 without a
    /// stack).
    fn stack_torque(&self, i: usize) -> f64 {
        self.stack.as_ref().map_or(0.0, |s| s.torque_on(i))
    }

    /// The ramp integral of the stack's torque on body `i` over the last step (the step's
    /// constant torque times half its length), N m s: its share of the speed synchronised
    /// to `t`.
    fn stack_past(&self, i: usize) -> f64 {
        match (&self.stack, self.t_prev) {
            (Some(s), Some(t0)) => {
                let b = s.body.iter().position(|&b| b == i);
                b.map_or(0.0, |b| s.torque[b] * 0.5 * (self.t - t0))
            }
            _ => 0.0,
        }
    }

    /// The speed of coupling `i`'s carrier at `t`, rad/s.
    fn carrier_speed(&self, i: usize) -> f64 {
        match self.world.carriers[i] {
            Carrier::Shaft => self.omega_s,
            Carrier::Housing => 0.0,
            Carrier::Drum => self.drum.as_ref().map_or(0.0, |d| d.omega),
        }
    }

    /// The unwrapped angle of coupling `i`'s carrier at `t`, rad.
    fn carrier_angle(&self, i: usize) -> f64 {
        match self.world.carriers[i] {
            Carrier::Shaft => self.theta_s,
            Carrier::Housing => 0.0,
            Carrier::Drum => self.drum.as_ref().map_or(0.0, |d| d.theta),
        }
    }

    /// The rapier body of coupling `i`'s carrier.
    fn carrier_body(&self, i: usize) -> rapier3d_f64::prelude::RigidBodyHandle {
        match self.world.carriers[i] {
            Carrier::Shaft => self.world.shaft,
            Carrier::Housing => self.world.housing,
            Carrier::Drum => self.world.drum.expect("a drum"),
        }
    }

    /// Kinetic energy of the discs, the plates (and of an inertial shaft and the drum) at
    /// `t`, J: `sum J w^2 / 2` with the synchronised speeds, plus `m v^2 / 2` of the bodies'
    /// centres (rapier's speed over the last step: zero for a concentric body, whose joint
    /// locks every other motion).
    fn kinetic_energy(&self) -> f64 {
        let bodies = &self.world.physics.bodies;
        let mut e: f64 = self
            .bodies
            .iter()
            .zip(&self.omega_d)
            .zip(&self.world.discs)
            .map(|((d, w), &h)| {
                let b = &bodies[h];
                0.5 * d.inertia_kg_m2 * w * w + 0.5 * b.mass() * b.linvel().length_squared()
            })
            .sum();
        if let ShaftDrive::Inertial { j1, .. } = self.shaft {
            e += 0.5 * j1 * self.omega_s * self.omega_s;
        }
        if let Some(d) = &self.drum {
            e += 0.5 * d.model.inertia_kg_m2 * d.omega * d.omega;
        }
        e
    }

    /// The hook at `t`: every coupling's relative state and tooth loads, then the stack's
    /// clamp forces. Fails if the state is not finite or the teeth passed through each other
    /// (|phi| beyond half a pitch).
    fn evaluate(&mut self, t_last_good: f64) -> Result<(), EngineError> {
        let bodies = &self.world.physics.bodies;
        let shaft = &bodies[self.world.shaft];
        // First estimates of the speeds at t: rapier's mean speeds plus the extrapolated
        // accelerations over the last step.
        self.omega_s = match self.shaft {
            ShaftDrive::Prescribed(p) => p.speed(self.t),
            ShaftDrive::Inertial { j1, .. } => {
                self.shaft_full_history
                    .synchronised(self.t, shaft.angvel().z, 5, 1.0 / j1)
            }
        };
        if let (Some(d), Some(h)) = (self.drum.as_mut(), self.world.drum) {
            d.omega = d.full_history.synchronised(
                self.t,
                bodies[h].angvel().z,
                5,
                1.0 / d.model.inertia_kg_m2,
            );
        }
        // The teeth's torque integrated along the last step (the past half of the kick), which
        // also gives the synchronised speeds without extrapolating across a kink.
        let mut teeth_past_shaft = 0.0;
        let mut teeth_past_drum = 0.0;
        for i in 0..self.couplings.len() {
            self.teeth_past[i] = 0.0;
            let Some((t0, phi0, dphi0, _)) = self.prev_motion[i] else {
                continue;
            };
            let disc = &bodies[self.world.discs[i]];
            let j = self.bodies[i].inertia_kg_m2;
            let est = self.disc_full_history[i].synchronised(self.t, disc.angvel().z, 5, 1.0 / j)
                + self.stack_past(i) / j;
            let rel = relative_state(
                &bodies[self.carrier_body(i)],
                self.carrier_speed(i),
                disc,
                est,
                self.world.disc_turn_owed_z(i),
            );
            let h1 = self.t - t0;
            if h1 > 0.0 {
                let c = &self.couplings[i];
                self.teeth_past[i] =
                    past_impulse((phi0, dphi0), (rel.phi, rel.dphi), h1, |p, d| {
                        c.probe_torque(p, d)
                    });
                match self.world.carriers[i] {
                    Carrier::Shaft => teeth_past_shaft += self.teeth_past[i],
                    Carrier::Drum => teeth_past_drum += self.teeth_past[i],
                    Carrier::Housing => {}
                }
            }
        }
        if let ShaftDrive::Inertial { j1, .. } = self.shaft {
            if self.shaft_history.len() > 0 {
                self.omega_s = shaft.angvel().z
                    + (self.shaft_history.synchronised(self.t, 0.0, 5, 1.0) + self.drive_past()
                        - teeth_past_shaft)
                        / j1;
            }
        }
        if let (Some(d), Some(h)) = (self.drum.as_mut(), self.world.drum) {
            if d.history.len() > 0 {
                d.omega = bodies[h].angvel().z
                    + (d.history.synchronised(self.t, 0.0, 5, 1.0) - teeth_past_drum)
                        / d.model.inertia_kg_m2;
            }
        }
        self.rel.clear();
        self.forces.clear();
        self.omega_d.clear();
        self.potential_j = 0.0;
        for i in 0..self.couplings.len() {
            let disc = &bodies[self.world.discs[i]];
            let j = self.bodies[i].inertia_kg_m2;
            let mean = disc.angvel().z;
            let omega_d = if self.prev_motion[i].is_some() {
                mean + (self.teeth_past[i]
                    + self.disc_history[i].synchronised(self.t, 0.0, 5, 1.0)
                    + self.stack_past(i))
                    / j
            } else {
                self.disc_full_history[i].synchronised(self.t, mean, 5, 1.0 / j)
            };
            self.omega_d.push(omega_d);
        }
        // Bodies whose faces stuck over the last step turned as one body (their mean speeds
        // were made equal, `stack.rs`): their speed at t is the group's, the momentum-weighted
        // mean of the estimates (the stack's internal torques cancel in it).
        if let Some(stack) = &self.stack {
            let mut m = 0;
            while m < stack.interfaces() {
                if !stack.locked[m] {
                    m += 1;
                    continue;
                }
                let first = m;
                while m < stack.interfaces() && stack.locked[m] {
                    m += 1;
                }
                // stack bodies first..=m are locked together
                let group = &stack.body[first..=m];
                let (mut jw, mut jsum) = (0.0, 0.0);
                for &i in group {
                    let j = self.bodies[i].inertia_kg_m2;
                    jw += j * self.omega_d[i];
                    jsum += j;
                }
                for &i in group {
                    self.omega_d[i] = jw / jsum;
                }
            }
        }
        for i in 0..self.couplings.len() {
            let disc = &bodies[self.world.discs[i]];
            let omega_d = self.omega_d[i];
            let rel = relative_state(
                &bodies[self.carrier_body(i)],
                self.carrier_speed(i),
                disc,
                omega_d,
                self.world.disc_turn_owed_z(i),
            );
            let c = &mut self.couplings[i];
            let limit = std::f64::consts::PI / c.spline.teeth as f64;
            let diverged = |reason: String| EngineError::Diverged {
                t_s: t_last_good,
                reason: format!("disc {i}: {reason}"),
            };
            if !(rel.phi.abs() <= limit && rel.dphi.is_finite()) {
                return Err(diverged(format!(
                    "relative angle {} rad, speed {} rad/s (half a tooth pitch is {limit} rad)",
                    rel.phi, rel.dphi
                )));
            }
            let offset = rel.offset[0].hypot(rel.offset[1]);
            let offset_limit = limit * c.spline.pitch_radius_m;
            if !(offset <= offset_limit && rel.offset_rate.iter().all(|v| v.is_finite())) {
                return Err(diverged(format!(
                    "radial offset {offset} m (half a tooth pitch is {offset_limit} m)"
                )));
            }
            let f = c.evaluate(&rel);
            if !(f.load_n.is_finite() && f.moment[2].is_finite()) {
                return Err(diverged(format!("tooth load {} N", f.load_n)));
            }
            self.potential_j += f.potential_j;
            self.rel.push(rel);
            self.forces.push(f);
        }
        if let Some(stack) = self.stack.as_mut() {
            // The teeth's normal load n |F| = |torque| / Rb of each coupling.
            let normal: Vec<f64> = self
                .forces
                .iter()
                .zip(&self.bodies)
                .map(|(f, d)| f.moment[2].abs() / d.spline.base_radius_m())
                .collect();
            stack.update(self.t, &normal, &self.omega_d);
        }
        self.audit_energy();
        self.compute_loads();
        Ok(())
    }

    /// The physical loads at `t` on every body (the drag, the teeth and their reactions, the
    /// drive, the drum's load) and the kicks for the next step.
    fn compute_loads(&mut self) {
        let bodies = &self.world.physics.bodies;
        let mut shaft_force = Vector::ZERO;
        let mut shaft_torque = Vector::ZERO;
        let mut shaft_torque_full = Vector::ZERO;
        let mut drum_force = Vector::ZERO;
        let mut drum_torque = Vector::ZERO;
        let mut drum_torque_full = Vector::ZERO;
        let mut disc_accel = vec![0.0; self.forces.len()];
        for (i, f) in self.forces.iter().enumerate() {
            let d = self.bodies[i];
            let carrier = self.world.carriers[i];
            let qs = *bodies[self.carrier_body(i)].rotation();
            // Hu et al. eq (5): drag -C2 omega_d.
            let drag = -d.drag_n_m_s_rad * self.omega_d[i];
            let f_local = Vector::new(f.force[0], f.force[1], 0.0);
            let m_local = Vector::new(f.moment[0], f.moment[1], f.moment[2]);
            // The hook's moment is about the axis point of the disc's mid-plane; the disc's
            // centre sits at the offset e from it.
            let e_local = Vector::new(self.rel[i].offset[0], self.rel[i].offset[1], 0.0);
            let force = qs * f_local;
            let torque = qs * (m_local - e_local.cross(f_local)) + Vector::new(0.0, 0.0, drag);
            self.disc_full_loads[i] = [force.x, force.y, force.z, torque.x, torque.y, torque.z];
            // The stack's torque over the step just taken stands for its torque at t.
            let stack = match &self.stack {
                Some(s) => s
                    .body
                    .iter()
                    .position(|&b| b == i)
                    .map_or(0.0, |b| s.torque[b]),
                None => 0.0,
            };
            disc_accel[i] = (torque.z + stack) / d.inertia_kg_m2;
            // The reaction on the carrier, about its centre: -(m + a x F), a the mid-plane.
            let a = Vector::new(0.0, 0.0, self.world.disc_axial_m[i]);
            let reaction = qs * (m_local + a.cross(f_local));
            // The teeth's torque about the axis is integrated along the step instead
            // (`teeth_impulse`); the rest (radial forces, tilting moments, the moment of the
            // radial force about an offset centre) goes through the polynomial kick.
            let mut partial = self.disc_full_loads[i];
            partial[5] -= f.moment[2];
            self.disc_loads[i] = partial;
            match carrier {
                Carrier::Shaft => {
                    shaft_torque_full -= reaction;
                    shaft_force -= force;
                    shaft_torque -= reaction - Vector::new(0.0, 0.0, f.moment[2]);
                }
                Carrier::Drum => {
                    drum_torque_full -= reaction;
                    drum_force -= force;
                    drum_torque -= reaction - Vector::new(0.0, 0.0, f.moment[2]);
                }
                Carrier::Housing => {}
            }
            self.disc_kicks[i] = self.disc_history[i].kick(self.t, &self.disc_loads[i]);
        }
        let shaft_accel = match self.shaft {
            ShaftDrive::Prescribed(p) => p.acceleration(self.t),
            ShaftDrive::Inertial { j1, c1 } => {
                // Hu et al. eq (4): the drive torque, the spline reactions, damping -C1 omega.
                // The drive is a known function of time: its kick is integrated exactly
                // (`drive_impulse`), not extrapolated.
                let damping = -c1 * self.omega_s;
                shaft_torque.z += damping;
                shaft_torque_full.z += damping + self.pack.shaft.drive_torque_n_m(self.t);
                let l = |t: Vector| [shaft_force.x, shaft_force.y, shaft_force.z, t.x, t.y, t.z];
                self.shaft_load = l(shaft_torque);
                self.shaft_full_load = l(shaft_torque_full);
                self.shaft_kick = self.shaft_history.kick(self.t, &self.shaft_load);
                shaft_torque_full.z / j1
            }
        };
        let drum_accel = match self.drum.as_mut() {
            Some(dr) => {
                // The drum: its load torque, its drag, the plates' spline reactions.
                let own = dr.model.load_torque_n_m - dr.model.drag_n_m_s_rad * dr.omega;
                drum_torque.z += own;
                drum_torque_full.z += own;
                let l = |t: Vector| [drum_force.x, drum_force.y, drum_force.z, t.x, t.y, t.z];
                dr.load = l(drum_torque);
                dr.full_load = l(drum_torque_full);
                dr.kick = dr.history.kick(self.t, &dr.load);
                dr.accel = drum_torque_full.z / dr.model.inertia_kg_m2;
                dr.accel
            }
            None => 0.0,
        };
        for c in &self.teeth_cache {
            c.set((f64::NAN, 0.0));
        }
        for (i, m) in self.teeth_motion.iter_mut().enumerate() {
            let carrier_accel = match self.world.carriers[i] {
                Carrier::Shaft => shaft_accel,
                Carrier::Drum => drum_accel,
                Carrier::Housing => 0.0,
            };
            let ddphi = carrier_accel - disc_accel[i];
            let (jerk, jerk_step) = match self.prev_motion[i] {
                Some((t0, _, _, dd0)) if self.t > t0 => {
                    ((ddphi - dd0) / (self.t - t0), self.t - t0)
                }
                _ => (0.0, 0.0),
            };
            *m = Motion {
                phi: self.rel[i].phi,
                dphi: self.rel[i].dphi,
                ddphi,
                jerk,
                jerk_step,
            };
        }
    }

    /// The impulse of the teeth of coupling `i` on its body about the axis over a step of
    /// length `x` from `t` (both halves of the kick), N m s.
    fn teeth_impulse(&self, i: usize, x: f64) -> f64 {
        let (cx, cv) = self.teeth_cache[i].get();
        if cx == x {
            return cv;
        }
        let c = &self.couplings[i];
        let v = self.teeth_past[i]
            + future_impulse(&self.teeth_motion[i], x, |p, d| c.probe_torque(p, d));
        self.teeth_cache[i].set((x, v));
        v
    }

    /// The drive torque on an inertial shaft integrated against the rising ramp of the last
    /// step (N m s; 0 before the first step or for a prescribed shaft).
    fn drive_past(&self) -> f64 {
        let Some(t0) = self.t_prev else {
            return 0.0;
        };
        let h = self.t - t0;
        if h <= 0.0 || matches!(self.shaft, ShaftDrive::Prescribed(_)) {
            return 0.0;
        }
        crate::integrate::ramp_integral(t0, h, true, |t| self.pack.shaft.drive_torque_n_m(t))
    }

    /// The kick of the drive torque on an inertial shaft for a step of length `x` from `t`
    /// (both halves, N m s).
    fn drive_impulse(&self, x: f64) -> f64 {
        if matches!(self.shaft, ShaftDrive::Prescribed(_)) {
            return 0.0;
        }
        self.drive_past()
            + crate::integrate::ramp_integral(self.t, x, false, |t| {
                self.pack.shaft.drive_torque_n_m(t)
            })
    }

    /// Adds the work done since the last evaluation (trapezoidal rule) to the energy audit.
    fn audit_energy(&mut self) {
        let (drive, shaft_damping) = match self.shaft {
            ShaftDrive::Prescribed(_) => (0.0, 0.0),
            ShaftDrive::Inertial { c1, .. } => (
                self.pack.shaft.drive_torque_n_m(self.t) * self.omega_s,
                -c1 * self.omega_s * self.omega_s,
            ),
        };
        let drag: f64 = self
            .bodies
            .iter()
            .zip(&self.omega_d)
            .map(|(d, w)| -d.drag_n_m_s_rad * w * w)
            .sum();
        let (drum_drag, load) = match &self.drum {
            Some(d) => (
                -d.model.drag_n_m_s_rad * d.omega * d.omega,
                d.model.load_torque_n_m * d.omega,
            ),
            None => (0.0, 0.0),
        };
        let now = Powers {
            t: self.t,
            theta_s: self.theta_s,
            spline_torque: self
                .forces
                .iter()
                .zip(&self.world.carriers)
                .filter(|(_, c)| **c == Carrier::Shaft)
                .map(|(f, _)| f.moment[2])
                .sum(),
            drive,
            drag: drag + shaft_damping + drum_drag,
            load,
        };
        if let Some(b) = self.powers_before {
            let h = now.t - b.t;
            self.energy.drive_work_j += match self.shaft {
                ShaftDrive::Prescribed(_) => {
                    0.5 * (b.spline_torque + now.spline_torque) * (now.theta_s - b.theta_s)
                }
                ShaftDrive::Inertial { .. } => 0.5 * (b.drive + now.drive) * h,
            };
            self.energy.drag_work_j += 0.5 * (b.drag + now.drag) * h;
            self.energy.load_work_j += 0.5 * (b.load + now.load) * h;
        }
        self.powers_before = Some(now);
    }

    /// Feeds the impact trackers with the state at `t`.
    fn track_events(&mut self, steps_per_contact: f64, observer: &mut dyn Observer) {
        for (i, track) in self.tracks.iter_mut().enumerate() {
            let law = &self.bodies[i].law;
            let f = &self.forces[i];
            let m = self.m_eff[i];
            let step = |v| contact_duration_s(law, f.kin.flank, v, m) / steps_per_contact;
            if let Some(e) = track.update(self.t, f, step) {
                observer.impact(&e);
            }
        }
    }

    /// The sample at `t`.
    fn sample(&self, tooth_loads: bool) -> Sample {
        Sample {
            t_s: self.t,
            shaft_angle_rad: self.theta_s,
            shaft_speed_rad_s: self.omega_s,
            discs: (0..self.forces.len())
                .map(|i| {
                    let f = &self.forces[i];
                    let phi = self.rel[i].phi;
                    DiscSample {
                        angle_rad: self.carrier_angle(i) - phi,
                        speed_rad_s: self.omega_d[i],
                        rel_angle_rad: phi,
                        penetration_m: f.kin.delta_m,
                        closing_speed_m_s: f.kin.v_n_m_s,
                        load_n: f.load_n,
                        torque_n_m: f.moment[2],
                        engaged: f.depth_m > 0.0,
                        stiffness: f.stiffness,
                        tooth_loads_n: if tooth_loads {
                            self.couplings[i].tooth_loads_n()
                        } else {
                            Vec::new()
                        },
                    }
                })
                .collect(),
        }
    }

    /// The step the adaptive controller wants at `t`, s, and whether it is a contact step.
    fn desired_step(&self, a: &AdaptiveStepping) -> (f64, bool) {
        let a_shaft = match self.shaft {
            ShaftDrive::Prescribed(_) => self.shaft_accel_bound,
            ShaftDrive::Inertial { j1, c1 } => {
                // The drive, the damping, and the teeth's reactions at t (contacts elsewhere
                // in the pack jolt the shaft).
                let reaction: f64 = self
                    .forces
                    .iter()
                    .zip(&self.world.carriers)
                    .filter(|(_, c)| **c == Carrier::Shaft)
                    .map(|(f, _)| f.moment[2].abs())
                    .sum();
                self.shaft_accel_bound + (c1 * self.omega_s.abs() + reaction) / j1
            }
        };
        let a_drum = match &self.drum {
            Some(d) => {
                let reaction: f64 = self
                    .forces
                    .iter()
                    .zip(&self.world.carriers)
                    .filter(|(_, c)| **c == Carrier::Drum)
                    .map(|(f, _)| f.moment[2].abs())
                    .sum();
                (d.model.load_torque_n_m.abs() + d.model.drag_n_m_s_rad * d.omega.abs() + reaction)
                    / d.model.inertia_kg_m2
            }
            None => 0.0,
        };
        let mut want = a.max_step_s;
        let mut contact = false;
        for (i, d) in self.bodies.iter().enumerate() {
            let stack = self.stack.as_ref().map_or(0.0, |s| {
                s.body
                    .iter()
                    .position(|&b| b == i)
                    .map_or(0.0, |_| s.torque_bound(i))
            });
            let a_disc = (d.drag_n_m_s_rad * self.omega_d[i].abs() + stack) / d.inertia_kg_m2;
            let a_carrier = match self.world.carriers[i] {
                Carrier::Shaft => a_shaft,
                Carrier::Drum => a_drum,
                Carrier::Housing => 0.0,
            };
            let view = CouplingView {
                forces: &self.forces[i],
                law: &d.law,
                phi: self.rel[i].phi,
                dphi: self.rel[i].dphi,
                g0: d.spline.half_play_rad(),
                rb: d.spline.base_radius_m(),
                m_eff_kg: self.m_eff[i],
                // 1 % over the bound: rounding must not make it optimistic.
                rel_accel_bound: 1.01 * (a_carrier + a_disc),
                event_step_s: self.tracks[i].event_step_s,
                event_age_s: self.tracks[i].event_t_on_s.map(|t_on| self.t - t_on),
            };
            let (dt, c) = coupling_step(&view, a);
            if dt < want {
                want = dt;
                contact = c;
            }
        }
        (want, contact)
    }

    /// Solves the stack's impulses for a step of length `h` from `t` (no-op without a stack):
    /// every other load of the step is known, so each body's mean speed over the step
    /// without the stack is too (`stack.rs`).
    fn solve_stack(&mut self, h: f64) {
        if self.stack.is_none() {
            return;
        }
        let bodies = &self.world.physics.bodies;
        let n = self.couplings.len();
        let mut w_pred = vec![0.0; n];
        let mut inv_j = vec![0.0; n];
        for i in 0..n {
            let j = self.bodies[i].inertia_kg_m2;
            inv_j[i] = 1.0 / j;
            w_pred[i] = bodies[self.world.discs[i]].angvel().z
                + (self.disc_kicks[i].impulse_component(5, h) + self.teeth_impulse(i, h)) / j;
        }
        if let Some(s) = self.stack.as_mut() {
            s.solve(h, &w_pred, &inv_j);
        }
    }

    /// The step length, at most `h`, that lands exactly on the first contact onset or
    /// separation within `h` of any coupling, if one falls in `(tiny, h)`.
    ///
    /// A step's outcome is known before it is taken: the forces are constant over it, so the
    /// relative angle after a step of length `x` is
    /// `phi + dtheta_c(x) - x (w_d + kick(x) a_d)`, `kick(x) = (h_{k-1} + x) / 2`, with `w_d`
    /// rapier's (staggered) disc speed and `a_d` the disc's acceleration from the forces at `t`
    /// (and likewise for an inertial carrier; a prescribed shaft turns by its profile, the
    /// housing not at all). The stack's torque is the one solved for the step `h`. The
    /// engagement depth along it is solved for zero by bracketed secant steps, to 1e-16 m.
    /// Landing a step on each onset and separation keeps the `s^1.5` law's kink at `s = 0`
    /// on step boundaries: within a step the force is smooth and the leapfrog keeps its second
    /// order.
    fn landing(&self, h: f64, tiny: f64) -> Option<f64> {
        let bodies = &self.world.physics.bodies;
        let theta_s0 = match self.shaft {
            ShaftDrive::Prescribed(_) => self.theta_s,
            ShaftDrive::Inertial { .. } => 0.0,
        };
        let w_s = bodies[self.world.shaft].angvel().z;
        let shaft_turn = |x: f64| match self.shaft {
            ShaftDrive::Prescribed(p) => p.angle(self.t + x) - theta_s0,
            ShaftDrive::Inertial { j1, .. } => {
                let teeth: f64 = (0..self.couplings.len())
                    .filter(|&i| self.world.carriers[i] == Carrier::Shaft)
                    .map(|i| self.teeth_impulse(i, x))
                    .sum();
                x * (w_s
                    + (self.shaft_kick.impulse_component(5, x) + self.drive_impulse(x) - teeth)
                        / j1)
            }
        };
        let drum_turn = |x: f64| match (&self.drum, self.world.drum) {
            (Some(d), Some(hd)) => {
                let teeth: f64 = (0..self.couplings.len())
                    .filter(|&i| self.world.carriers[i] == Carrier::Drum)
                    .map(|i| self.teeth_impulse(i, x))
                    .sum();
                x * (bodies[hd].angvel().z
                    + (d.kick.impulse_component(5, x) - teeth) / d.model.inertia_kg_m2)
            }
            _ => 0.0,
        };
        // The carriers' turns over the whole step, computed once (a drum's sums every plate's
        // teeth).
        let (shaft_turn_h, drum_turn_h) = (shaft_turn(h), drum_turn(h));
        let carrier_turn = |i: usize, x: f64| match self.world.carriers[i] {
            Carrier::Shaft if x == h => shaft_turn_h,
            Carrier::Drum if x == h => drum_turn_h,
            Carrier::Shaft => shaft_turn(x),
            Carrier::Drum => drum_turn(x),
            Carrier::Housing => 0.0,
        };
        let mut best: Option<f64> = None;
        for (i, d) in self.bodies.iter().enumerate() {
            let f = &self.forces[i];
            // Landing follows the concentric tooth: with radial play or spacing errors the
            // first tooth to touch is another one.
            if f.gap_margin_m > 0.0 {
                continue;
            }
            let w_d = bodies[self.world.discs[i]].angvel().z;
            let kick = &self.disc_kicks[i];
            let j = d.inertia_kg_m2;
            let stack = self.stack_torque(i);
            let g0 = d.spline.half_play_rad();
            let rb = d.spline.base_radius_m();
            let offset = d.law.engagement_offset_m();
            let phi0 = self.rel[i].phi;
            let turn_d = |x: f64| {
                x * (w_d
                    + (kick.impulse_component(5, x) + self.teeth_impulse(i, x) + stack * x) / j)
            };
            let phi = |x: f64| phi0 + carrier_turn(i, x) - turn_d(x);
            let phi_h = phi(h);
            let engaged = f.depth_m > 0.0;
            for flank in crate::hook::FLANKS {
                if engaged && flank != f.kin.flank {
                    continue;
                }
                let sigma = flank.phi_sign();
                let depth = |x: f64| (sigma * phi(x) - g0) * rb + offset;
                let d0 = (sigma * phi0 - g0) * rb + offset;
                let d1 = (sigma * phi_h - g0) * rb + offset;
                let crosses = if engaged {
                    d0 > 0.0 && d1 <= 0.0
                } else {
                    d0 <= 0.0 && d1 > 0.0
                };
                if !crosses {
                    continue;
                }
                let x = crate::stepping::bracketed_root(depth, 0.0, d0, h, d1, 1e-16);
                if x > tiny && best.is_none_or(|b| x < b) {
                    best = Some(x);
                }
            }
        }
        best
    }

    /// Resets and applies every body's forces for the step from `t` to `t_next`: each body's
    /// kick over the step divided by its length (see `integrate.rs`), and the stack's torques
    /// solved for this step ([`Run::solve_stack`]).
    fn apply_forces(&mut self, t_next: f64) {
        let h = t_next - self.t;
        let teeth: Vec<f64> = (0..self.couplings.len())
            .map(|i| self.teeth_impulse(i, h) / h)
            .collect();
        let stack: Vec<f64> = (0..self.couplings.len())
            .map(|i| self.stack_torque(i))
            .collect();
        let drive = self.drive_impulse(h);
        let bodies = &mut self.world.physics.bodies;
        let apply = |body: &mut RigidBody, l: Load| {
            body.reset_forces(false);
            body.reset_torques(false);
            body.add_force(Vector::new(l[0], l[1], l[2]), false);
            body.add_torque(Vector::new(l[3], l[4], l[5]), false);
        };
        let mut teeth_on_shaft = 0.0;
        let mut teeth_on_drum = 0.0;
        for (i, kick) in self.disc_kicks.iter().enumerate() {
            let mut load = kick.applied(h);
            load[5] += teeth[i] + stack[i];
            match self.world.carriers[i] {
                Carrier::Shaft => teeth_on_shaft -= teeth[i],
                Carrier::Drum => teeth_on_drum -= teeth[i],
                Carrier::Housing => {}
            }
            apply(&mut bodies[self.world.discs[i]], load);
            self.disc_history[i].push(self.t, self.disc_loads[i]);
            self.disc_full_history[i].push(self.t, self.disc_full_loads[i]);
            let m = &self.teeth_motion[i];
            self.prev_motion[i] = Some((self.t, m.phi, m.dphi, m.ddphi));
        }
        let shaft = &mut bodies[self.world.shaft];
        match self.shaft {
            ShaftDrive::Prescribed(p) => {
                self.theta_next = p.angle(t_next);
                shaft.set_next_kinematic_rotation(Rotation::from_rotation_z(self.theta_next));
            }
            ShaftDrive::Inertial { .. } => {
                let mut load = self.shaft_kick.applied(h);
                load[5] += teeth_on_shaft + drive / h;
                apply(shaft, load);
                self.shaft_history.push(self.t, self.shaft_load);
                self.shaft_full_history.push(self.t, self.shaft_full_load);
            }
        }
        if let (Some(d), Some(hd)) = (self.drum.as_mut(), self.world.drum) {
            let mut load = d.kick.applied(h);
            load[5] += teeth_on_drum;
            apply(&mut bodies[hd], load);
            d.history.push(self.t, d.load);
            d.full_history.push(self.t, d.full_load);
        }
    }

    /// Steps the world to `t_next` (after [`Run::apply_forces`]) and updates the shaft and
    /// drum angles and the stack's work.
    fn advance(&mut self, t_next: f64) {
        let h = t_next - self.t;
        let q_before = *self.world.physics.bodies[self.world.shaft].rotation();
        let drum_before = self
            .world
            .drum
            .map(|hd| *self.world.physics.bodies[hd].rotation());
        self.world.step(h);
        self.t_prev = Some(self.t);
        self.t = t_next;
        self.theta_s = match self.shaft {
            ShaftDrive::Prescribed(_) => self.theta_next,
            ShaftDrive::Inertial { .. } => {
                let q_after = *self.world.physics.bodies[self.world.shaft].rotation();
                self.theta_s + angle_about_z(&(q_before.inverse() * q_after))
            }
        };
        if let (Some(d), Some(hd), Some(q0)) = (self.drum.as_mut(), self.world.drum, drum_before) {
            let q1 = *self.world.physics.bodies[hd].rotation();
            d.theta += angle_about_z(&(q0.inverse() * q1));
        }
        if let Some(s) = self.stack.as_mut() {
            let bodies = &self.world.physics.bodies;
            let discs = &self.world.discs;
            let w = |i: usize| bodies[discs[i]].angvel().z;
            for m in 0..s.interfaces() {
                let slip = w(s.body[m + 1]) - w(s.body[m]);
                let work = s.impulse[m] * slip;
                self.energy.stack_work_j += work;
                s.dissipated_j[m] -= work;
            }
        }
    }
}

impl Engine for MultibodyEngine {
    fn name(&self) -> &'static str {
        "multibody"
    }

    fn disc_names(&self) -> Vec<String> {
        self.pack
            .discs
            .iter()
            .chain(&self.pack.plates)
            .map(|d| d.name.clone())
            .collect()
    }

    // `u64::is_multiple_of` needs Rust 1.87; the workspace's rust-version is 1.86.
    #[allow(clippy::manual_is_multiple_of)]
    fn run(
        &mut self,
        duration_s: f64,
        observer: &mut dyn Observer,
    ) -> Result<RunStats, EngineError> {
        let opts = &self.options;
        let mut run = Run::new(&self.pack, opts, &self.per_tooth)?;
        let period = 1.0 / self.record_rate_hz;
        let rec_time = |j: u64| j as f64 * period;
        let mut rec_index: u64 = 0;
        // Half of the current step: samples are taken at the step nearest to the grid when
        // the step does not land on it (fixed steps, adaptive contact steps).
        let mut half_step = match opts.stepping {
            Stepping::Fixed { dt_s } => 0.5 * dt_s,
            Stepping::Adaptive(_) => 0.0,
        };
        let steps_per_contact = match opts.stepping {
            Stepping::Adaptive(a) => a.steps_per_contact,
            Stepping::Fixed { .. } => AdaptiveStepping::default().steps_per_contact,
        };
        let mut steps: u64 = 0;
        let mut stopped = false;
        let mut t_last_good = 0.0;
        loop {
            run.evaluate(t_last_good)?;
            t_last_good = run.t;
            if steps == 0 {
                run.energy.initial_contact_potential_j = run.potential_j;
                run.energy.initial_kinetic_j = run.kinetic_energy();
            }
            run.track_events(steps_per_contact, observer);
            if rec_time(rec_index) <= run.t + half_step {
                observer.sample(&run.sample(opts.record_tooth_loads));
                if let Some(s) = &run.stack {
                    observer.interfaces(run.t, &s.samples());
                }
                while rec_time(rec_index) <= run.t + half_step {
                    rec_index += 1;
                }
            }
            if steps > 0 && steps % PROGRESS_EVERY == 0 && observer.progress(run.t) {
                stopped = true;
            }
            if stopped || run.t >= duration_s {
                break;
            }
            let t = run.t;
            let t_next = match opts.stepping {
                Stepping::Fixed { dt_s } => ((steps + 1) as f64 * dt_s).min(duration_s),
                Stepping::Adaptive(a) => {
                    let (want, contact) = run.desired_step(&a);
                    if want.is_nan() || want < a.min_step_s {
                        return Err(EngineError::Diverged {
                            t_s: t,
                            reason: format!("the step size collapsed to {want} s"),
                        });
                    }
                    // Free-flight steps land on the sampling grid; contact steps keep their
                    // length (a varying step spoils the symplectic step's energy).
                    half_step = if contact { 0.5 * want } else { 0.0 };
                    let target = if contact {
                        duration_s
                    } else {
                        rec_time(rec_index).min(duration_s)
                    };
                    let rem = target - t;
                    let h = if want >= rem {
                        rem
                    } else if want > 0.5 * rem {
                        0.5 * rem
                    } else {
                        want
                    };
                    // The stack's torques for this step enter the landing's prediction.
                    run.solve_stack(h);
                    // Never step over an onset or a separation: land on it.
                    match run.landing(h, 1e-3 * h.min(want)) {
                        Some(x) => {
                            half_step = 0.5 * x;
                            t + x
                        }
                        None if h == rem => target,
                        None => t + h,
                    }
                }
            };
            // (Re)solve the stack for the step actually taken.
            let h = t_next - t;
            if run.stack.as_ref().is_some_and(|s| s.step_s() != h) {
                run.solve_stack(h);
            }
            run.apply_forces(t_next);
            run.advance(t_next);
            steps += 1;
        }
        for track in run.tracks.iter_mut() {
            if let Some(e) = track.tracker.finish(run.t) {
                observer.impact(&e);
            }
        }
        run.energy.contact_potential_j = run.potential_j;
        run.energy.kinetic_j = run.kinetic_energy();
        self.energy = run.energy;
        Ok(RunStats {
            simulated_s: run.t,
            steps,
            rejected_steps: 0,
            rhs_evals: steps + 1,
            stopped_early: stopped,
        })
    }
}
