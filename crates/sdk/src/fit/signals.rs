//! What a fit compares: the signals a scene's run produces, by name, read from the run's
//! samples and interpolated at the measured times.
//!
//! A network scene (`[[bodies]]`) produces, per body `B`, `B.speed_rad_s` (also written `B`
//! alone) and `B.angle_rad`, and per coupling `C`, `C.torque_n_m` (the torque on its body
//! `a`, sign as in [`clutchpack_model::network::NetworkSample`]).

use crate::{Error, Result};
use clutchpack_model::network::NetworkSample;
use clutchpack_scene::Scene;

/// One signal of a network run: which series of the samples, and which item.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Signal {
    /// A body's speed, rad/s.
    Speed(usize),
    /// A body's angle, rad.
    Angle(usize),
    /// A coupling's torque on its body `a`, N m.
    Torque(usize),
}

impl Signal {
    /// The signal called `name` in `scene`, or an error listing the signals the scene has.
    pub(crate) fn resolve(scene: &Scene, name: &str) -> Result<Signal> {
        let Some(net) = &scene.network else {
            return Err(Error::BadInput(format!(
                "signal {name:?}: {} is a pack scene; a fit compares the signals of network \
                 scenes ([[bodies]]) so far",
                scene.name
            )));
        };
        let body = |b: &str| net.bodies.iter().position(|x| x.name == b);
        let coupling = |c: &str| net.couplings.iter().position(|x| x.name == c);
        let (item, quantity) = name.rsplit_once('.').unwrap_or((name, "speed_rad_s"));
        let found = match quantity {
            "speed_rad_s" => body(item).map(Signal::Speed),
            "angle_rad" => body(item).map(Signal::Angle),
            "torque_n_m" => coupling(item).map(Signal::Torque),
            _ => None,
        };
        found.ok_or_else(|| {
            let mut names: Vec<String> = net
                .bodies
                .iter()
                .flat_map(|b| {
                    [
                        format!("{}.speed_rad_s", b.name),
                        format!("{}.angle_rad", b.name),
                    ]
                })
                .collect();
            names.extend(
                net.couplings
                    .iter()
                    .map(|c| format!("{}.torque_n_m", c.name)),
            );
            Error::BadInput(format!(
                "signal {name:?}: {} does not produce it (it produces: {}; a body's name alone \
                 is its speed)",
                scene.name,
                names.join(", ")
            ))
        })
    }

    /// Its value in one sample.
    fn value(self, s: &NetworkSample) -> f64 {
        match self {
            Signal::Speed(i) => s.speed_rad_s[i],
            Signal::Angle(i) => s.angle_rad[i],
            Signal::Torque(k) => s.torque_n_m[k],
        }
    }

    /// Its values at the times `t` (ascending, within the run), linear between the samples.
    pub(crate) fn at(self, history: &[NetworkSample], t: &[f64]) -> Vec<f64> {
        t.iter()
            .map(|&t| {
                let k = history.partition_point(|s| s.t_s <= t);
                match (k.checked_sub(1).map(|i| &history[i]), history.get(k)) {
                    (Some(a), Some(b)) if b.t_s > a.t_s => {
                        let w = (t - a.t_s) / (b.t_s - a.t_s);
                        self.value(a) + w * (self.value(b) - self.value(a))
                    }
                    (Some(a), _) => self.value(a),
                    (None, Some(b)) => self.value(b),
                    (None, None) => f64::NAN,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, w: f64) -> NetworkSample {
        NetworkSample {
            t_s: t,
            angle_rad: vec![0.0],
            speed_rad_s: vec![w],
            torque_n_m: vec![],
            mode: vec![],
        }
    }

    /// Linear between samples, the sample itself at its time, held at the ends.
    #[test]
    fn interpolates_between_samples() {
        let h = [sample(0.0, 1.0), sample(1.0, 3.0), sample(2.0, 3.0)];
        let v = Signal::Speed(0).at(&h, &[0.0, 0.25, 1.0, 1.5, 2.0]);
        assert_eq!(v, [1.0, 1.5, 3.0, 3.0, 3.0]);
    }
}
