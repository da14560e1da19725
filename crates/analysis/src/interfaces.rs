//! Per friction interface figures of a run: the largest clamp force and friction torque, when
//! the faces locked for good, and the heat they took ([`InterfaceStats`]), accumulated from
//! the engine's interface samples as they come (a run) or as they are read back (a
//! recording).

use clutchpack_model::InterfaceSample;
use serde::{Deserialize, Serialize};

/// What one friction interface did over a run.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct InterfaceStats {
    /// The interface's name, `<lower>__<upper>` (the piston side first).
    pub name: String,
    /// Largest clamp force, N.
    pub max_clamp_n: f64,
    /// Largest `|torque|` of the interface, N m.
    pub max_abs_torque_n_m: f64,
    /// Start of the final locked stretch, s: the faces stayed locked from then to the end.
    /// `None` when they were slipping at the end.
    pub locked_since_s: Option<f64>,
    /// Heat the interface took from t = 0 to the end, J (its last `dissipated_j`).
    pub dissipated_j: f64,
    /// Samples seen.
    pub samples: u64,
}

impl InterfaceStats {
    /// An empty record for the interface `name`.
    pub fn new(name: impl Into<String>) -> InterfaceStats {
        InterfaceStats {
            name: name.into(),
            ..Default::default()
        }
    }

    /// Takes in the interface's state at `t_s` (s); samples must come in time order.
    pub fn update(&mut self, t_s: f64, f: &InterfaceSample) {
        if f.clamp_n.is_finite() {
            self.max_clamp_n = self.max_clamp_n.max(f.clamp_n);
        }
        if f.torque_n_m.is_finite() {
            self.max_abs_torque_n_m = self.max_abs_torque_n_m.max(f.torque_n_m.abs());
        }
        self.locked_since_s = match (f.locked, self.locked_since_s) {
            (true, Some(t0)) => Some(t0),
            (true, None) => Some(t_s),
            (false, _) => None,
        };
        self.dissipated_j = f.dissipated_j;
        self.samples += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(locked: bool, clamp_n: f64, torque_n_m: f64, dissipated_j: f64) -> InterfaceSample {
        InterfaceSample {
            clamp_n,
            torque_n_m,
            locked,
            dissipated_j,
            ..Default::default()
        }
    }

    /// Maxima, the last heat figure, and the start of the last locked stretch (a lock that
    /// broke loose does not count).
    #[test]
    fn accumulates_maxima_heat_and_the_final_lock() {
        let mut s = InterfaceStats::new("p1__d1");
        s.update(0.0, &sample(false, 10.0, -3.0, 0.0));
        s.update(0.1, &sample(true, 50.0, 7.0, 1.0));
        s.update(0.2, &sample(false, 40.0, -9.0, 2.0));
        assert_eq!(s.locked_since_s, None);
        s.update(0.3, &sample(true, 30.0, 1.0, 2.5));
        s.update(0.4, &sample(true, f64::NAN, 1.0, 2.5));
        assert_eq!(s.locked_since_s, Some(0.3));
        assert_eq!((s.max_clamp_n, s.max_abs_torque_n_m), (50.0, 9.0));
        assert_eq!((s.dissipated_j, s.samples), (2.5, 5));
    }
}
