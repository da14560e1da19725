//! The lumped friction clutch of a driveline network (MODEL.md section 8), with the semantics
//! of Modelica's `Rotational.Components.Clutch` (MSL 4.0): a normal force
//! `fn = fn_max f_normalized(t)`, free while `fn <= 0`; slipping with the torque
//! `mu(w_rel) cgeo fn` against the relative speed; locked while the torque that holds it stays
//! within `peak mu(0) cgeo fn`. Stick and slip are events the engines locate.
//!
//! Sign convention (the network's, as Modelica's flanges): `w_rel = w_b - w_a` (rad/s); the
//! clutch's torque `tau` (N m) acts as `+tau` on body `a` and `-tau` on body `b`, so a
//! slipping clutch has `tau = sign(w_rel) mu(|w_rel|) cgeo fn`, which brings the two speeds
//! together.

pub use super::element::ClutchMode;
use super::element::{
    problem, ElementLaw, EnergyTerm, InputSpec, Mode, OutputQuantity, OutputSpec, SlipEnd,
    MAX_PORTS,
};
use super::rows::Row;
use super::signal::Signal;
use super::{friction, CouplingKind, Network, NetworkInput, NetworkProblem};
use serde::{Deserialize, Serialize};

/// A lumped friction clutch (or brake, when one side is a fixed body).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LumpedClutch {
    /// The sliding friction coefficient against the relative speed for `w_rel >= 0`:
    /// rows `(w_rel rad/s, mu)` with increasing speeds (Modelica's `mu_pos`); linear between
    /// rows, extrapolated from the last two rows beyond the last (Modelica's `LastTwoPoints`),
    /// one row means a constant `mu`.
    pub mu_table: Vec<(f64, f64)>,
    /// Ratio of the largest static friction to the sliding friction at zero speed (>= 1,
    /// Modelica's `peak`).
    pub peak: f64,
    /// Geometry constant, m: the torque per unit friction force (Modelica's `cgeo`; for `N`
    /// faces of radii `ri`..`ro` under uniform wear, `N (ro + ri) / 2`).
    pub cgeo_m: f64,
    /// Largest normal force, N (Modelica's `fn_max`).
    pub fn_max_n: f64,
    /// The normalized normal force `f_normalized(t)` (0..1; engaged while > 0).
    pub force: Signal,
    /// A one-way clutch (Modelica's `OneWayClutch`: a freewheel in parallel with this
    /// clutch, MODEL.md section 10): `w_rel = w_b - w_a` never turns negative; at zero it
    /// locks, holding any torque `tau <= 0` on `a` (the freewheel) and a positive one up to
    /// the static limit (the clutch: 0 while it is free); forward it slips as the clutch.
    /// With no normal force ever, a plain freewheel.
    #[serde(default)]
    pub one_way: bool,
}

impl LumpedClutch {
    /// The sliding friction coefficient at `|w_rel|` (rad/s).
    pub fn mu(&self, slip_speed_rad_s: f64) -> f64 {
        let w = slip_speed_rad_s.abs();
        let rows = &self.mu_table;
        match rows.len() {
            0 => 0.0,
            1 => rows[0].1,
            n => {
                // the segment holding w; the first below the table, the last two beyond it
                let i = rows[1..n - 1].partition_point(|r| r.0 <= w);
                let (w0, m0) = rows[i];
                let (w1, m1) = rows[i + 1];
                m0 + (m1 - m0) * (w - w0) / (w1 - w0)
            }
        }
    }

    /// The normal force at `t`, N (`fn_max f_normalized(t)`; may be <= 0: free).
    pub fn normal_force_n(&self, t: f64) -> f64 {
        self.fn_max_n * self.force.value(t)
    }

    /// The torque of a slipping clutch, N m: `sign(w_rel) mu(|w_rel|) cgeo fn` for the
    /// direction `direction` (+1 forward, -1 backward; taken from the mode, so that a clutch
    /// that starts to slip from rest has its torque at once).
    pub fn slip_torque_n_m(&self, direction: i8, w_rel_rad_s: f64, normal_n: f64) -> f64 {
        f64::from(direction) * self.mu(w_rel_rad_s) * self.cgeo_m * normal_n.max(0.0)
    }

    /// The largest torque the locked clutch holds, N m: `peak mu(0) cgeo fn` (0 when free).
    pub fn max_static_torque_n_m(&self, normal_n: f64) -> f64 {
        self.peak * self.mu(0.0) * self.cgeo_m * normal_n.max(0.0)
    }

    /// How far the locked clutch is from breaking at the normal force `normal_n` (N) under
    /// the torque `tau` (N m, on its body `a`) that holds it, N m: its static limit less
    /// `|tau|`; a one-way clutch's less `tau` (its freewheel holds any `tau <= 0`). It breaks
    /// where this reaches 0.
    pub fn margin_n_m(&self, tau_n_m: f64, normal_n: f64) -> f64 {
        let limit = self.max_static_torque_n_m(normal_n);
        if self.one_way {
            limit - tau_n_m
        } else {
            limit - tau_n_m.abs()
        }
    }

    /// The problems with the parameters, as `(field, what is wrong)` (empty when good).
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let mut out = Vec::new();
        if self.mu_table.is_empty() {
            out.push(("mu", "needs at least one row".to_string()));
        }
        for (i, (w, mu)) in self.mu_table.iter().enumerate() {
            if !w.is_finite() || !mu.is_finite() || *w < 0.0 || *mu < 0.0 {
                out.push((
                    "mu",
                    format!("row {i}: ({w}, {mu}) must be finite and >= 0"),
                ));
            }
            if i > 0 && *w <= self.mu_table[i - 1].0 {
                out.push(("mu", format!("row {i}: speed {w} does not increase")));
            }
        }
        if !(self.peak.is_finite() && self.peak >= 1.0) {
            out.push(("peak", format!("{} must be >= 1", self.peak)));
        }
        if !(self.cgeo_m.is_finite() && self.cgeo_m >= 0.0) {
            out.push(("cgeo_m", format!("{} must be >= 0", self.cgeo_m)));
        }
        if !(self.fn_max_n.is_finite() && self.fn_max_n >= 0.0) {
            out.push(("fn_max_n", format!("{} must be >= 0", self.fn_max_n)));
        }
        if !self.force.is_valid() {
            out.push(("force", "has a value that is not finite".to_string()));
        }
        out
    }
}

/// The lumped clutch and the one-way clutch as an element (the module's docs; the stick/slip
/// rule is [`friction`]'s).
impl ElementLaw for LumpedClutch {
    fn kind_name(&self) -> &'static str {
        if self.one_way {
            "one_way_clutch"
        } else {
            "clutch"
        }
    }

    fn torque_factors(&self, _ports: &[usize]) -> Option<[f64; MAX_PORTS]> {
        Some([1.0, -1.0, 0.0])
    }

    fn initial_mode(&self) -> Mode {
        Some(ClutchMode::Free)
    }

    /// Locked: `w_a - w_b = 0`.
    fn row(&self, k: usize, ports: &[usize], mode: Mode) -> Option<Row> {
        (mode == Some(ClutchMode::Locked)).then(|| Row::two(k, (ports[0], 1.0), (ports[1], -1.0)))
    }

    /// Slipping: `tau = sign(w_rel) mu(|w_rel|) cgeo fn` on `a` (MODEL.md section 8).
    fn port_torque_n_m(
        &self,
        t_s: f64,
        _twist_rad: f64,
        w_a: f64,
        w_b: f64,
        mode: Mode,
    ) -> Option<f64> {
        match mode {
            Some(ClutchMode::Slipping(s)) => {
                Some(self.slip_torque_n_m(s, w_b - w_a, self.normal_force_n(t_s)))
            }
            _ => None,
        }
    }

    fn energy_term(&self) -> EnergyTerm {
        EnergyTerm::ClutchHeat
    }

    /// Slipping: its heat rate `tau (w_b - w_a)`.
    fn power_w(&self, mode: Mode, torque_n_m: f64, w_a: f64, w_b: f64) -> Option<f64> {
        matches!(mode, Some(ClutchMode::Slipping(_))).then(|| torque_n_m * (w_b - w_a))
    }

    /// Its normal force's.
    fn breakpoints(&self, out: &mut Vec<f64>) {
        self.force.breakpoints(out);
    }

    /// `fn > 0`.
    fn engaged(&self, t_s: f64) -> Option<bool> {
        Some(self.normal_force_n(t_s) > 0.0)
    }

    /// Slipping: its direction; free, a one-way clutch's freewheel: forward.
    fn slip_sense(&self, mode: Mode) -> Option<i8> {
        match mode {
            Some(ClutchMode::Slipping(s)) => Some(s),
            Some(ClutchMode::Free) if self.one_way => Some(1),
            _ => None,
        }
    }

    /// Slipping `min(s w_rel, fn)`, locked `min(limit - |tau|, fn)` (a one-way clutch:
    /// `limit - tau`, held without a normal force by its freewheel), free `-fn` (a one-way
    /// clutch: `min(-fn, w_rel)`, its freewheel locking where the slip reaches zero).
    fn guard(&self, t_s: f64, w_rel: f64, mode: Mode, held_n_m: f64) -> f64 {
        let f = self.normal_force_n(t_s);
        match mode {
            Some(ClutchMode::Free) => {
                let engage = if f > 0.0 { -f } else { 1.0 + f.abs() };
                if self.one_way {
                    engage.min(w_rel)
                } else {
                    engage
                }
            }
            Some(ClutchMode::Slipping(s)) => (f64::from(s) * w_rel).min(f),
            Some(ClutchMode::Locked) if self.one_way => LumpedClutch::margin_n_m(self, held_n_m, f),
            Some(ClutchMode::Locked) => LumpedClutch::margin_n_m(self, held_n_m, f).min(f),
            None => 1.0,
        }
    }

    fn settle(&self, t_s: f64, before: Mode, w_a: f64, w_b: f64, end: SlipEnd) -> Mode {
        let f = self.normal_force_n(t_s);
        Some(friction::settled_mode(
            self.one_way,
            f,
            before,
            w_a,
            w_b,
            end,
        ))
    }

    fn locked_margin_n_m(&self, t_s: f64, held_n_m: f64) -> Option<f64> {
        Some(LumpedClutch::margin_n_m(
            self,
            held_n_m,
            self.normal_force_n(t_s),
        ))
    }

    /// Towards its torque (`+1` when the torque on `a` is positive); a one-way clutch forward,
    /// or free without a normal force.
    fn released_mode(&self, t_s: f64, held_n_m: f64) -> Mode {
        Some(if self.one_way && self.normal_force_n(t_s) <= 0.0 {
            ClutchMode::Free
        } else if self.one_way || held_n_m > 0.0 {
            ClutchMode::Slipping(1)
        } else {
            ClutchMode::Slipping(-1)
        })
    }

    /// Its parameters'; a one-way clutch's speeds at t = 0 keep `w_b >= w_a`.
    fn problems(
        &self,
        net: &Network,
        k: usize,
        ports: &[usize],
        out: &mut Vec<NetworkProblem>,
    ) -> bool {
        for (field, message) in LumpedClutch::problems(self) {
            out.push(problem(k, field, message));
        }
        let (a, b) = (&net.bodies[ports[0]], &net.bodies[ports[1]]);
        let (wa, wb) = (a.initial_speed_rad_s, b.initial_speed_rad_s);
        if self.one_way && wb < wa {
            out.push(problem(
                k,
                "b",
                format!(
                    "a one-way clutch keeps w_b >= w_a, but at t = 0 \"{}\" turns at {} rad/s, below \"{}\"'s {} rad/s",
                    b.name,
                    crate::fmt_num(wb),
                    a.name,
                    crate::fmt_num(wa)
                ),
            ));
        }
        true
    }

    /// Its normal force (`normal_force_n`, N).
    fn input(&self) -> Option<InputSpec> {
        Some(InputSpec {
            input: NetworkInput::ClutchForce,
            suffix: "normal_force_n",
            unit: "N",
            description: "normal force of clutch {}, N (>= 0; 0: free)",
        })
    }

    /// `fn(t)`, N (>= 0).
    fn input_value(&self, t_s: f64) -> f64 {
        self.normal_force_n(t_s).max(0.0)
    }

    /// Its normal force signal is the level (`fn = level fn_max`).
    fn scheduled(&self, level: &Signal) -> Result<Option<CouplingKind>, (&'static str, String)> {
        Ok(Some(CouplingKind::Clutch(LumpedClutch {
            force: level.clone(),
            ..self.clone()
        })))
    }

    /// `fn(t)`, N, as its signal gives it.
    fn clamp_force_n(&self, t_s: f64) -> Option<f64> {
        Some(self.normal_force_n(t_s))
    }

    /// Its slip, its mode and its heat.
    fn outputs(&self) -> &'static [OutputSpec] {
        &[
            OutputSpec {
                suffix: "slip_rad_s",
                unit: "rad/s",
                description: "slip w_b - w_a of {}, rad/s",
                quantity: OutputQuantity::Slip,
            },
            OutputSpec {
                suffix: "mode",
                unit: "1",
                description: "mode of {} as Modelica's Clutch numbers it: 2 free, 1 slipping \
                              forward, 0 locked, -1 slipping backward",
                quantity: OutputQuantity::Mode,
            },
            OutputSpec {
                suffix: "heat_j",
                unit: "J",
                description: "heat {} has made since t = 0, J",
                quantity: OutputQuantity::Heat,
            },
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn msl(force: Signal) -> LumpedClutch {
        // Modelica's Clutch defaults with CoupledClutches' peak and fn_max
        LumpedClutch {
            mu_table: vec![(0.0, 0.5)],
            peak: 1.1,
            cgeo_m: 1.0,
            fn_max_n: 20.0,
            force,
            one_way: false,
        }
    }

    /// The torques of Modelica's clutch: sliding `mu cgeo fn` against the slip, static up to
    /// `peak` times that; free without force.
    #[test]
    fn torques_follow_modelica() {
        let c = msl(Signal::Constant(0.5));
        let fn_n = c.normal_force_n(0.0);
        assert_eq!(fn_n, 10.0);
        assert_eq!(c.slip_torque_n_m(-1, -3.0, fn_n), -5.0);
        assert_eq!(c.slip_torque_n_m(1, 3.0, fn_n), 5.0);
        assert!((c.max_static_torque_n_m(fn_n) - 5.5).abs() < 1e-15);
        assert_eq!(c.max_static_torque_n_m(-1.0), 0.0);
        assert!(c.problems().is_empty());
    }

    /// A table is linear between rows and extrapolated from its last two rows.
    #[test]
    fn mu_table_interpolates_and_extrapolates() {
        let mut c = msl(Signal::Constant(1.0));
        c.mu_table = vec![(0.0, 0.1), (10.0, 0.2), (20.0, 0.25)];
        assert!((c.mu(5.0) - 0.15).abs() < 1e-15);
        assert!((c.mu(-5.0) - 0.15).abs() < 1e-15);
        assert!((c.mu(15.0) - 0.225).abs() < 1e-15);
        assert!((c.mu(30.0) - 0.3).abs() < 1e-15);
        c.mu_table = vec![(0.0, 0.1), (0.0, 0.2)];
        assert_eq!(c.problems().len(), 1);
    }

    #[test]
    fn modes_have_modelica_codes() {
        assert_eq!(ClutchMode::Free.modelica_code(), 2);
        assert_eq!(ClutchMode::Slipping(-1).modelica_code(), -1);
        assert_eq!(ClutchMode::Locked.modelica_code(), 0);
        assert_eq!(ClutchMode::Slipping(1).label(), "slip+");
    }
}
