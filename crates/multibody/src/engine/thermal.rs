//! Thermal packs in the multibody engine (MODEL.md section 9; docs/DECISIONS.md, "Thermal
//! windows"): what this engine books, world step by world step, into the engine-independent
//! windows ([`ThermalWindows`], which hold the temperatures, advance them at each window's
//! end and give the pack its new viscosity-dependent parameters), and the swap of those
//! parameters into the run.
//!
//! # What this engine books
//! After every world step (of either scheme): each interface's dissipated work
//! (`Stack::dissipated_j`, kept by the stack's own integration) grew by its friction's and its
//! gap's drag's work; the part done while clamped (`Stack::friction_j`: the clamped stack's
//! sub-step stages with a clamp force `> 0`, the shared step's steps that started clamped,
//! the locks) goes to its two bodies by effusivity, the rest (open) to the oil;
//! the teeth's work on the relative motion `-n F Rb psi` (the reference engine's) to the oil,
//! taken from the energy audit as what the step's external work (drive, drag, the stack's
//! faces, the load, a coupling's damper) put in beyond the change of the kinetic energy and
//! of a coupling's spring: the teeth are the only other torques on the bodies, so that
//! difference is their work, exact up to the integration error of the audit (with lossless
//! teeth, `p = 0`, on the duty cycle: 2.8e-6 J off the elastic energy left in them,
//! `tests/thermal.rs`). A pack carried by a network (`carried.rs`) has its carriers' torques
//! held between calls, which world steps land on: their work is then `T (theta_1 - theta_0)`
//! exactly, and a carrier's speed set by the network is not the teeth's work. A step whose
//! window closes with new parameters swaps them into the spline couplings' tooth laws (a
//! paper-law contact keeps the stiffness it took at its onset, eqs 8-9; the new film reaches it
//! at its next contact) and the stack's open gaps.

use super::state::Run;
use clutchpack_model::thermal::{FaceMode, ThermalModel, ThermalReport, ThermalWindows};
use clutchpack_model::{DiscModel, EngineError, Observer, PackModel};
use std::sync::Arc;

/// A thermal run's windows and this engine's counters, held by the session.
#[derive(Debug, Clone)]
pub(super) struct Thermal {
    windows: ThermalWindows,
    /// Each interface's dissipated work and its clamped part at the last booking, J.
    counters: Vec<f64>,
    friction: Vec<f64>,
    /// The audit's external work without the stack's (drive, drag, load, the couplings'
    /// dampers) and the stack's, the kinetic energy and the couplings' springs' energy, at
    /// the last booking, J.
    external_j: f64,
    stack_j: f64,
    kinetic_j: f64,
    spring_j: f64,
    /// Whether the carriers' external torques are held between the run's calls (a pack carried
    /// by a network, `carried.rs`): their work is then booked exactly, `T (theta_1 - theta_0)`.
    held: bool,
    /// The audit's drag and couplings' dampers' work, J, the time, s, and each carrier's
    /// angle, rad, at the last booking (for `held`).
    drag_j: f64,
    t_j: f64,
    angles: Vec<f64>,
}

impl Thermal {
    /// The windows of `model` for `pack` at t = 0 and the pack the run starts with (`pack`
    /// with the parameters at t = 0 when they differ from the scene's).
    pub(super) fn new(
        model: ThermalModel,
        pack: Arc<PackModel>,
    ) -> Result<(Thermal, Arc<PackModel>), EngineError> {
        let windows = ThermalWindows::new(model, &pack)?;
        let pack = match windows.initial_pack(&pack) {
            Some(p) => Arc::new(p),
            None => pack,
        };
        let n_if = windows.interfaces();
        Ok((
            Thermal {
                windows,
                counters: vec![0.0; n_if],
                friction: vec![0.0; n_if],
                external_j: 0.0,
                stack_j: 0.0,
                kinetic_j: 0.0,
                spring_j: 0.0,
                held: false,
                drag_j: 0.0,
                t_j: 0.0,
                angles: Vec::new(),
            },
            pack,
        ))
    }

    /// Takes the run's state at its start (t = 0, evaluated) as the first booking's, and
    /// sends the temperatures there (the first point of their series).
    pub(super) fn start(&mut self, run: &Run, observer: &mut dyn Observer) {
        self.mark(run);
        self.send(run.t, observer);
    }

    /// The counters at the run's current state.
    fn mark(&mut self, run: &Run) {
        let a = run.energy.so_far();
        self.external_j = external_work_j(a);
        self.stack_j = a.stack_work_j;
        self.spring_j = a.coupling_potential_j;
        self.kinetic_j = run.kinetic_energy();
        self.drag_j = a.drag_work_j + a.coupling_work_j;
        self.t_j = run.t;
        self.angles.clear();
        self.angles.extend(run.carriers.iter().map(|k| k.angle));
        if let Some(s) = &run.stack {
            let n_if = self.counters.len();
            self.counters.copy_from_slice(&s.dissipated_j[..n_if]);
            self.friction.copy_from_slice(&s.friction_j[..n_if]);
        }
    }

    /// Sends the temperatures at `t` (s).
    fn send(&self, t: f64, observer: &mut dyn Observer) {
        if let Some((oil, bodies)) = self.windows.temperatures_k().split_last() {
            observer.temperatures(t, bodies, *oil);
        }
    }

    /// Books the world step that just ended at `run.t` (module docs), closes the windows that
    /// ended by then (their temperatures sent) and swaps new parameters into `run`.
    pub(super) fn after_step(
        &mut self,
        run: &mut Run,
        observer: &mut dyn Observer,
    ) -> Result<(), EngineError> {
        if let Some(s) = &run.stack {
            for m in 0..self.counters.len() {
                let friction = s.friction_j[m] - self.friction[m];
                let all = s.dissipated_j[m] - self.counters[m];
                self.windows.book_face(m, friction, FaceMode::Clamped);
                self.windows.book_face(m, all - friction, FaceMode::Open);
            }
        }
        let a = run.energy.so_far();
        let kinetic = run.kinetic_energy();
        let external = if self.held {
            // the carriers' torques are held over the step (world steps land on the calls
            // where they change): their work is T times the turn, exactly, where the audit's
            // trapezoid would leave its error on the large flows through the carriers
            let t_mid = 0.5 * (self.t_j + run.t);
            let carriers: f64 = (0..run.carriers.len())
                .filter(|&c| run.carriers[c].is_inertial())
                .map(|c| run.external_at(c, t_mid) * (run.carriers[c].angle - self.angles[c]))
                .sum();
            carriers + (a.drag_work_j + a.coupling_work_j - self.drag_j)
        } else {
            external_work_j(a) - self.external_j
        };
        // the teeth's work on the relative motion: what the external work put in beyond the
        // kinetic energy's and the springs' energy's change (the teeth's torques are the only
        // others on the bodies)
        let teeth = external + (a.stack_work_j - self.stack_j)
            - (kinetic - self.kinetic_j)
            - (a.coupling_potential_j - self.spring_j);
        self.windows.book_teeth(teeth);
        self.mark(run);
        let windows = self.windows.windows();
        let closed = self.windows.close_windows(run.t, &run.pack);
        if self.windows.windows() != windows {
            self.send(run.t, observer);
        }
        if let Some(pack) = closed? {
            run.set_parameters(pack);
        }
        Ok(())
    }

    /// The kinetic energy changed by `dk_j` (J) outside the run's steps (a network setting a
    /// carrier's speed, `carried.rs`): not the teeth's work, so not booked as theirs; and the
    /// carriers' torques are held between calls from now on (their work booked exactly).
    pub(super) fn carried(&mut self, dk_j: f64) {
        self.kinetic_j += dk_j;
        self.held = true;
    }

    /// Every body's temperature, then the oil's, K, as at the last window's end.
    pub(super) fn temperatures_k(&self) -> &[f64] {
        self.windows.temperatures_k()
    }

    /// Closes the last window at `t` (s), sends its temperatures, and returns the report.
    pub(super) fn finish(&mut self, t: f64, observer: &mut dyn Observer) -> ThermalReport {
        let windows = self.windows.windows();
        let report = self.windows.finish(t);
        if self.windows.windows() != windows {
            self.send(t, observer);
        }
        report
    }
}

/// The audit's work of everything on the bodies but the stack and the teeth, J: the drive,
/// the drag, the load, and the dampers of the pack's couplings (MODEL.md section 8; a damper
/// between the shaft and the drum is not part of the pack's thermal model).
fn external_work_j(a: &super::EnergyAudit) -> f64 {
    a.drive_work_j + a.drag_work_j + a.load_work_j + a.coupling_work_j
}

impl Run {
    /// Swaps the viscosity-dependent parameters of `pack` (the same bodies and stack, a
    /// thermal window's new tooth films, open gaps and faces' friction curves) into the run:
    /// the couplings' tooth laws, the bodies' models and the stack's open gaps and faces.
    pub(super) fn set_parameters(&mut self, pack: PackModel) {
        let bodies: Arc<[DiscModel]> = pack.discs.iter().chain(&pack.plates).cloned().collect();
        for (c, b) in self.couplings.iter_mut().zip(bodies.iter()) {
            c.law = b.law;
        }
        if let (Some(s), Some(m)) = (self.stack.as_mut(), pack.stack.as_ref()) {
            s.set_open_gap(m.open_gap);
            s.set_face_friction(&m.face_friction);
        }
        self.bodies = bodies;
        self.pack = Arc::new(pack);
    }
}
