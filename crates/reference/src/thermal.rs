//! Thermal packs on the monolithic scheme (MODEL.md section 9; docs/DECISIONS.md, "Thermal
//! windows"): what the reference engine books into the engine-independent windows
//! ([`clutchpack_model::thermal::ThermalWindows`], which hold the temperatures, advance them
//! at each window's end and give the pack its new viscosity-dependent parameters).
//!
//! # What this engine books
//! After every accepted step: each interface's heat counter (integrated in the state,
//! `System::rhs`) grew by the work of its friction or drag torque, which goes by the
//! interface's mode during the step (read before the step's switch applies) to its two bodies
//! (slipping or locked) or to the oil (open); the tooth forces' work on the relative motion,
//! `-n F Rb psi` (integrated in the state beside the faces' counters, outside the step's
//! error norm: `System::teeth_work`), to the oil. When a window's end brings new parameters, the pack is swapped and the integration
//! restarts from the same state (the steps are not cut at the windows: a run whose parameters
//! never change takes the isothermal run's steps bit for bit).

use crate::stepper::Stepper;
use crate::system::{Face, System};
use clutchpack_model::thermal::{FaceMode, ThermalModel, ThermalReport, ThermalWindows};
use clutchpack_model::{EngineError, PackModel};
use std::sync::Arc;

/// A thermal run's windows and this engine's counters, held by the monolithic session.
#[derive(Clone)]
pub(crate) struct Thermal {
    windows: ThermalWindows,
    /// The interface heat counters and the teeth's work at the last step's end, J.
    counters: Vec<f64>,
    teeth: f64,
}

impl Thermal {
    /// The thermal state of `model` for the session's `pack` at t = 0 (the interface
    /// counters at 0).
    pub fn new(model: ThermalModel, pack: &PackModel) -> Result<Thermal, EngineError> {
        let windows = ThermalWindows::new(model, pack)?;
        Ok(Thermal {
            counters: vec![0.0; windows.interfaces()],
            teeth: 0.0,
            windows,
        })
    }

    /// The pack the session starts with, when its parameters at t = 0 differ from the
    /// scene's (`None`: unchanged).
    pub fn initial_pack(&self, pack: &PackModel) -> Option<PackModel> {
        self.windows.initial_pack(pack)
    }

    /// Books the heat of the step `st` just took, with each interface's mode during it
    /// (`faces`, read before the step's switch is applied).
    pub fn book_step(&mut self, st: &Stepper) {
        self.book(&st.sys, &st.y);
    }

    /// Books the heat of the step that just ended at the state `y` of `sys` (the system's
    /// own part of a network's state: `network::packs`), each interface by its mode during
    /// the step (`sys.faces`, read before the step's switch is applied).
    pub fn book(&mut self, sys: &System, y: &[f64]) {
        // the faces: friction to the two bodies by effusivity, an open gap's drag to the oil
        let counters = sys.interface_heat_j(y);
        for (m, &q_now) in counters.iter().enumerate() {
            let dq = q_now - self.counters[m];
            self.counters[m] = q_now;
            let mode = match sys.faces[m] {
                Face::Open => FaceMode::Open,
                Face::Slip(_) | Face::Locked => FaceMode::Clamped,
            };
            self.windows.book_face(m, dq, mode);
        }
        // the teeth: -n F Rb psi over the step, integrated in the state
        let q = sys.teeth_work_j(y);
        self.windows.book_teeth(q - self.teeth);
        self.teeth = q;
    }

    /// Thermal windows closed so far.
    pub fn windows(&self) -> u64 {
        self.windows.windows()
    }

    /// The temperatures now, K: the bodies (discs, then plates), then the oil.
    pub fn temperatures_k(&self) -> &[f64] {
        self.windows.temperatures_k()
    }

    /// Closes the windows that ended by the stepper's time `t` (s)
    /// ([`ThermalWindows::close_windows`]).
    pub fn close_windows(
        &mut self,
        t: f64,
        pack: &PackModel,
    ) -> Result<Option<PackModel>, EngineError> {
        self.windows.close_windows(t, pack)
    }

    /// Closes the last window at `t` (s) and returns the run's report.
    pub fn finish(&mut self, t: f64) -> ThermalReport {
        self.windows.finish(t)
    }
}

/// Swaps `st`'s pack for `pack` and restarts its integration from the same state.
pub(crate) fn swap_pack(st: &mut Stepper, pack: PackModel) {
    st.sys.set_pack(Arc::new(pack));
    st.restart();
}
