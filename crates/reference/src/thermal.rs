//! Thermal packs on the monolithic scheme (MODEL.md section 9; docs/DECISIONS.md, "Thermal
//! windows"): the temperatures of the discs, the plates and the oil as slow states advanced
//! beside the mechanics by operator splitting on a fixed thermal window.
//!
//! # The splitting
//! The mechanics run as in an isothermal run, their viscosity-dependent parameters frozen
//! (the tooth films' `oil.viscosity_pa_s`, Hu et al. eqs 7-8, and the open gaps' Couette
//! viscosity). After every accepted step the step's heat is booked: each interface's heat
//! counter (integrated in the state, `System::rhs`) grew by the work of its friction or drag
//! torque, which goes, by the interface's mode during the step, to its two bodies split by
//! effusivity (slipping or locked) or to the oil (open: the gap's drag); the tooth forces'
//! work on the relative motion, `-n F Rb psi` (Boole's rule on the step's dense output,
//! exact to the 5th degree), goes to the oil. At the first step end at or after each
//! multiple of the window `step_s` the window closes: the temperatures advance over it
//! (`[t_w, t]`, its true length) with its heat as constant powers, by classical RK4 on the
//! linear lumped equations (MODEL.md section 9: `C dT/dt = P - G (T - T_oil)`, the oil's
//! with the cooler), in sub-steps of at most a twentieth of the fastest time constant; then
//! the film scale `eta(T_oil) / eta(T_ref)` and the gaps' viscosity are recomputed and, when
//! they changed, the pack's parameters are swapped and the integration restarts from the
//! same state (the steps are not cut at the windows: a run whose parameters never change
//! takes the isothermal run's steps bit for bit).
//!
//! The splitting error is first order in the window (the parameters lag the temperatures by
//! up to one window); the heat is booked exactly as integrated, so the energy balance closes
//! to rounding whatever the window.

use crate::stepper::Stepper;
use crate::system::Face;
use clutchpack_model::thermal::{
    body_temperature_rate_k_s, cooler_heat_w, effusivity_share, GapViscosity, ThermalModel,
    ThermalReport, Viscosity,
};
use clutchpack_model::{EngineError, PackModel, StackBody};
use std::sync::Arc;

/// A thermal run's temperatures and bookkeeping, held by the monolithic session.
#[derive(Clone)]
pub(crate) struct Thermal {
    model: ThermalModel,
    law: Viscosity,
    /// The scene's tooth film viscosities (the discs, then the plates), Pa s, and its open
    /// gaps' (0 without), at `T_ref`.
    base_film: Vec<f64>,
    base_gap: f64,
    /// Each body's capacity (J/K) and conductance (W/K), the discs then the plates.
    capacity: Vec<f64>,
    conductance: Vec<f64>,
    /// Body 1's (the lower stack body's) share of each interface's friction heat.
    share_lower: Vec<f64>,
    /// Temperatures, K: the bodies, then the oil.
    temp: Vec<f64>,
    /// The window's heat into each body and the oil (last), J.
    heat: Vec<f64>,
    /// The interface heat counters at the last step's end, J.
    counters: Vec<f64>,
    /// Start of the open window, s; index of its end (`(k + 1) step_s`).
    window_t0: f64,
    window_k: u64,
    /// The film scale in use, and the gaps' viscosity (Pa s).
    scale: f64,
    gap_eta: f64,
    report: ThermalReport,
    buf: Vec<f64>,
}

impl Thermal {
    /// The thermal state of `model` for the session's `pack` at t = 0 (the interface
    /// counters at 0).
    pub fn new(model: ThermalModel, pack: &PackModel) -> Result<Thermal, EngineError> {
        let law = model.viscosity.fit().map_err(|e| {
            EngineError::Unsupported(format!("thermal.oil: the viscosity law: {e}"))
        })?;
        let nd = pack.discs.len();
        let bodies: Vec<_> = model.discs.iter().chain(&model.plates).copied().collect();
        if bodies.len() != nd + pack.plates.len() {
            return Err(EngineError::Unsupported(format!(
                "the thermal model has {} bodies, the pack {}",
                bodies.len(),
                nd + pack.plates.len()
            )));
        }
        let n_if = pack.stack.as_ref().map_or(0, |_| 2 * nd);
        let share_lower = (0..n_if)
            .map(|m| {
                let lo = &bodies[StackBody::at(m).body_index(nd)];
                let up = &bodies[StackBody::at(m + 1).body_index(nd)];
                // MODEL.md section 9: body 1 takes e_1 / (e_1 + e_2)
                effusivity_share(lo.face_effusivity, up.face_effusivity)
            })
            .collect();
        let n = bodies.len();
        let t0 = model.initial_k;
        let base_gap = pack
            .stack
            .as_ref()
            .and_then(|s| s.open_gap.as_ref())
            .map_or(0.0, |g| g.viscosity_pa_s);
        let mut th = Thermal {
            law,
            base_film: pack
                .discs
                .iter()
                .chain(&pack.plates)
                .map(|d| d.law.oil.viscosity_pa_s)
                .collect(),
            base_gap,
            capacity: bodies.iter().map(|b| b.capacity_j_k).collect(),
            conductance: bodies.iter().map(|b| b.conductance_w_k).collect(),
            share_lower,
            temp: vec![t0; n + 1],
            heat: vec![0.0; n + 1],
            counters: vec![0.0; n_if],
            window_t0: 0.0,
            window_k: 0,
            scale: 1.0,
            gap_eta: base_gap,
            report: ThermalReport {
                final_k: vec![t0; n],
                max_k: vec![t0; n],
                oil_final_k: t0,
                oil_max_k: t0,
                ..ThermalReport::default()
            },
            buf: Vec::new(),
            model,
        };
        // the parameters of the first window: the temperatures at t = 0
        let (scale, gap) = th.parameters();
        th.scale = scale;
        th.gap_eta = gap;
        Ok(th)
    }

    /// The film scale and the gaps' viscosity (Pa s) at the current oil temperature.
    fn parameters(&self) -> (f64, f64) {
        let t_oil = self.temp[self.temp.len() - 1];
        // MODEL.md section 9: the tooth film (eqs 7-8) scaled by eta(T) / eta(T_ref); exactly
        // 1 at T_ref
        let scale = self.law.film_scale(t_oil, self.model.reference_k);
        let gap = match self.model.gap_viscosity {
            GapViscosity::Absolute => self.law.viscosity_pa_s(t_oil),
            GapViscosity::Scaled => self.base_gap * scale,
        };
        (scale, gap)
    }

    /// `pack` with the parameters in use: the film viscosities scaled, the gaps' set.
    fn apply(&self, pack: &PackModel) -> PackModel {
        let mut out = pack.clone();
        let nd = out.discs.len();
        for (b, d) in out
            .discs
            .iter_mut()
            .chain(out.plates.iter_mut())
            .enumerate()
        {
            d.law.oil.viscosity_pa_s = self.base_film[b] * self.scale;
        }
        debug_assert_eq!(self.base_film.len(), nd + pack.plates.len());
        if let Some(g) = out.stack.as_mut().and_then(|s| s.open_gap.as_mut()) {
            g.viscosity_pa_s = self.gap_eta;
        }
        out
    }

    /// The pack the session starts with, when its parameters at t = 0 differ from the
    /// scene's (`None`: unchanged).
    pub fn initial_pack(&self, pack: &PackModel) -> Option<PackModel> {
        let changed = self.scale != 1.0
            || (self.gap_eta != self.base_gap
                && pack.stack.as_ref().is_some_and(|s| s.open_gap.is_some()));
        changed.then(|| self.apply(pack))
    }

    /// Books the heat of the step `st` just took, with each interface's mode during it
    /// (`faces`, read before the step's switch is applied).
    pub fn book_step(&mut self, st: &Stepper) {
        let nd = st.sys.pack.discs.len();
        let oil = self.heat.len() - 1;
        // the faces: friction to the two bodies by effusivity, an open gap's drag to the oil
        let counters = st.sys.interface_heat_j(&st.y);
        for (m, &q_now) in counters.iter().enumerate() {
            let dq = q_now - self.counters[m];
            self.counters[m] = q_now;
            match st.sys.faces[m] {
                Face::Open => {
                    self.heat[oil] += dq;
                    self.report.gap_heat_j += dq;
                }
                Face::Slip(_) | Face::Locked => {
                    let share = self.share_lower[m];
                    self.heat[StackBody::at(m).body_index(nd)] += share * dq;
                    self.heat[StackBody::at(m + 1).body_index(nd)] += (1.0 - share) * dq;
                    self.report.friction_heat_j += dq;
                }
            }
        }
        // the teeth: -n F Rb psi over the step (Boole's rule, 5 points of the dense output)
        let modes = st.step_modes();
        if modes.iter().all(Option::is_none) || st.cur.h <= 0.0 {
            return;
        }
        // the step ran from the start of its dense output to the stepper's time (an event
        // ends it before the interpolant's end)
        let (t0, h) = (st.cur.t0, st.t - st.cur.t0);
        if h <= 0.0 {
            return;
        }
        const W: [f64; 5] = [7.0, 32.0, 12.0, 32.0, 7.0];
        let mut q = 0.0;
        self.buf.resize(st.y.len(), 0.0);
        for (i, w) in W.iter().enumerate() {
            let t = if i == 4 {
                st.t
            } else {
                t0 + h * i as f64 / 4.0
            };
            st.cur.eval(t, &mut self.buf);
            for (slot, mode) in modes.iter().enumerate() {
                if mode.is_none() {
                    continue;
                }
                let d = st.sys.disc(slot);
                let f = st.sys.load(slot, &self.buf, mode);
                let psi = self.buf[st.sys.off + 2 * slot + 1];
                let rb = d.spline.base_radius_m();
                q -= w * d.spline.teeth as f64 * f * rb * psi;
            }
        }
        let q = q * h / 90.0;
        self.heat[oil] += q;
        self.report.impact_heat_j += q;
    }

    /// Thermal windows closed so far.
    pub fn windows(&self) -> u64 {
        self.report.windows
    }

    /// The temperatures now, K: the bodies (discs, then plates), then the oil.
    pub fn temperatures_k(&self) -> &[f64] {
        &self.temp
    }

    /// Closes the windows that ended by the stepper's time `t` (s): advances the temperatures
    /// over `[t_w, t]` and returns the pack with the new parameters when they changed.
    /// An error when the oil's temperature has left the viscosity law (Vogel's `eta` is
    /// infinite at and below its `c`).
    pub fn close_windows(
        &mut self,
        t: f64,
        pack: &PackModel,
    ) -> Result<Option<PackModel>, EngineError> {
        let step = self.model.step_s;
        if t < (self.window_k + 1) as f64 * step {
            return Ok(None);
        }
        while (self.window_k + 1) as f64 * step <= t {
            self.window_k += 1;
        }
        self.advance(t);
        let (scale, gap) = self.parameters();
        if !(scale.is_finite() && scale > 0.0 && gap.is_finite()) {
            return Err(EngineError::Diverged {
                t_s: t,
                reason: format!(
                    "the oil at {} K is outside its viscosity law (film scale {scale}, gap \
                     viscosity {gap} Pa s): check [thermal.oil]",
                    self.temp[self.temp.len() - 1]
                ),
            });
        }
        if scale == self.scale && gap == self.gap_eta {
            return Ok(None);
        }
        self.scale = scale;
        self.gap_eta = gap;
        self.report.updates += 1;
        Ok(Some(self.apply(pack)))
    }

    /// Advances the temperatures from the window's start to `t` (s) with its heat as
    /// constant powers (MODEL.md section 9's lumped equations, classical RK4).
    fn advance(&mut self, t: f64) {
        let dt = t - self.window_t0;
        self.window_t0 = t;
        if dt <= 0.0 {
            return;
        }
        self.report.windows += 1;
        let n = self.capacity.len();
        let power: Vec<f64> = self.heat.iter().map(|q| q / dt).collect();
        self.heat.iter_mut().for_each(|q| *q = 0.0);
        let oil = &self.model.oil;
        // the fastest time constant, s: a twentieth of it per RK4 sub-step
        let mut tau = f64::INFINITY;
        let mut g_sum = 0.0;
        for b in 0..n {
            if self.conductance[b] > 0.0 {
                tau = tau.min(self.capacity[b] / self.conductance[b]);
            }
            g_sum += self.conductance[b];
        }
        if g_sum + oil.flow_capacity_w_k > 0.0 {
            tau = tau.min(oil.capacity_j_k / (g_sum + oil.flow_capacity_w_k));
        }
        let subs = if tau.is_finite() {
            ((dt / (0.05 * tau)).ceil() as usize).max(1)
        } else {
            1
        };
        let h = dt / subs as f64;
        // state: the bodies, the oil, the cooler's heat (J)
        let rate = |y: &[f64], out: &mut [f64]| {
            let t_oil = y[n];
            let mut to_oil = power[n];
            for b in 0..n {
                out[b] = body_temperature_rate_k_s(
                    power[b],
                    self.conductance[b],
                    y[b],
                    t_oil,
                    self.capacity[b],
                );
                to_oil += self.conductance[b] * (y[b] - t_oil);
            }
            let cooler = cooler_heat_w(oil.flow_capacity_w_k, t_oil, oil.inlet_k);
            out[n] = (to_oil - cooler) / oil.capacity_j_k;
            out[n + 1] = cooler;
        };
        let mut y: Vec<f64> = self.temp.clone();
        y.push(0.0);
        let m = y.len();
        let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
            vec![0.0; m],
            vec![0.0; m],
            vec![0.0; m],
            vec![0.0; m],
            vec![0.0; m],
        );
        for _ in 0..subs {
            rate(&y, &mut k1);
            for i in 0..m {
                tmp[i] = y[i] + 0.5 * h * k1[i];
            }
            rate(&tmp, &mut k2);
            for i in 0..m {
                tmp[i] = y[i] + 0.5 * h * k2[i];
            }
            rate(&tmp, &mut k3);
            for i in 0..m {
                tmp[i] = y[i] + h * k3[i];
            }
            rate(&tmp, &mut k4);
            for i in 0..m {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        self.report.cooler_j += y[n + 1];
        self.temp.copy_from_slice(&y[..=n]);
        for b in 0..n {
            self.report.max_k[b] = self.report.max_k[b].max(self.temp[b]);
        }
        self.report.oil_max_k = self.report.oil_max_k.max(self.temp[n]);
    }

    /// Closes the last window at `t` (s) and returns the run's report.
    pub fn finish(&mut self, t: f64) -> ThermalReport {
        self.advance(t);
        let n = self.capacity.len();
        let t0 = self.model.initial_k;
        let mut r = self.report.clone();
        r.final_k = self.temp[..n].to_vec();
        r.oil_final_k = self.temp[n];
        r.stored_bodies_j = (0..n).map(|b| self.capacity[b] * (self.temp[b] - t0)).sum();
        r.stored_oil_j = self.model.oil.capacity_j_k * (self.temp[n] - t0);
        r
    }
}

/// Swaps `st`'s pack for `pack` and restarts its integration from the same state.
pub(crate) fn swap_pack(st: &mut Stepper, pack: PackModel) {
    st.sys.set_pack(Arc::new(pack));
    st.restart();
}
