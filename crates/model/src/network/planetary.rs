//! A simple planetary set (MODEL.md section 10): sun S, carrier C and ring R, with tooth counts
//! `z_S` and `z_R` (the planets have `z_P = (z_R - z_S) / 2`). It is one kinematic constraint
//! on three bodies, Willis' equation `z_S w_S + z_R w_R - (z_S + z_R) w_C = 0` (rad/s), a row
//! of three terms ([`super::rows`]); its ideal torques are that row's `C^T lambda`: with
//! `k = z_R / z_S`, `tau_R = k tau_S` and `tau_C = -(1 + k) tau_S` (N m), and they do no work
//! (`tau_S w_S + tau_R w_R + tau_C w_C = 0` on any speeds that keep the row). A group of bodies
//! that holds a planetary set keeps two degrees of freedom, not one, until a shift element
//! holds or ties one of its members (Modelica's `Rotational.Components.IdealPlanetary`).
//!
//! A **double-pinion set** (the building block of a Ravigneaux set: each sun planet meshes with
//! a ring planet) turns its ring the other way relative to the carrier:
//! `z_S w_S - z_R w_R - (z_S - z_R) w_C = 0`; its planets' sizes are free (no parity rule).
//!
//! In a network the set's coupling has the sun as its body `a` and the ring as its body `b`;
//! the carrier is named by the set. The coupling's torque (the network's torque "on `a`") is
//! the torque on the sun, `tau_S = z_S lambda`.

use super::element::{ElementLaw, Mode, Ports, MAX_PORTS};
use super::rows::Row;
use super::{Network, NetworkProblem};
use serde::{Deserialize, Serialize};

/// The most teeth a sun or a ring may have (a bound on typing errors; an 8HP's largest ring
/// has about 100).
pub const MAX_TEETH: u32 = 1000;

/// A simple planetary set's gearing and its carrier.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanetarySet {
    /// The sun's teeth `z_S` (>= 1).
    pub sun_teeth: u32,
    /// The ring's teeth `z_R` (> `z_S`, with `z_R - z_S` even: a whole number of planet teeth).
    pub ring_teeth: u32,
    /// The carrier's index in [`super::Network::bodies`].
    pub carrier: usize,
    /// A double-pinion set (`z_S w_S - z_R w_R = (z_S - z_R) w_C`) rather than a simple one.
    #[serde(default)]
    pub double_pinion: bool,
}

impl PlanetarySet {
    /// Willis' row for the coupling `k` with the sun `sun` and the ring `ring` (body indices):
    /// `z_S w_S + z_R w_R - (z_S + z_R) w_C = 0`.
    /// (a double-pinion set: `z_S w_S - z_R w_R - (z_S - z_R) w_C = 0`).
    pub fn row(&self, k: usize, sun: usize, ring: usize) -> Row {
        let (zs, zr) = self.signed_teeth();
        Row::three(k, [(sun, zs), (ring, zr), (self.carrier, -(zs + zr))])
    }

    /// Its ports: the sun `sun`, the ring `ring` and its carrier.
    pub fn members(&self, sun: usize, ring: usize) -> Ports {
        Ports::three(sun, ring, self.carrier)
    }

    /// `(z_S, z_R)` as they enter Willis' equation: `z_R` negative for a double-pinion set.
    fn signed_teeth(&self) -> (f64, f64) {
        let (zs, zr) = (f64::from(self.sun_teeth), f64::from(self.ring_teeth));
        (zs, if self.double_pinion { -zr } else { zr })
    }

    /// The carrier's speed (rad/s) for the sun's `w_sun` and the ring's `w_ring` (rad/s):
    /// `(z_S w_S + z_R w_R) / (z_S + z_R)` (double pinion: `(z_S w_S - z_R w_R) / (z_S - z_R)`).
    pub fn carrier_speed_rad_s(&self, w_sun_rad_s: f64, w_ring_rad_s: f64) -> f64 {
        let (zs, zr) = self.signed_teeth();
        (zs * w_sun_rad_s + zr * w_ring_rad_s) / (zs + zr)
    }

    /// The problems with the gearing, as `(field, what is wrong)` (empty when good).
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let (zs, zr) = (self.sun_teeth, self.ring_teeth);
        let mut out = Vec::new();
        if zs == 0 || zs > MAX_TEETH {
            out.push(("sun_teeth", format!("{zs} must be within 1..={MAX_TEETH}")));
        }
        if zr > MAX_TEETH {
            out.push(("ring_teeth", format!("{zr} must be at most {MAX_TEETH}")));
        } else if zr <= zs {
            out.push((
                "ring_teeth",
                format!("{zr} must be larger than the sun's {zs}: the ring surrounds the sun"),
            ));
        } else if !self.double_pinion && (zr - zs) % 2 != 0 {
            out.push((
                "ring_teeth",
                format!(
                    "z_R - z_S = {} is odd: the planets would have {}.5 teeth ((z_R - z_S) / 2)",
                    zr - zs,
                    (zr - zs) / 2
                ),
            ));
        }
        out
    }
}

impl ElementLaw for PlanetarySet {
    fn kind_name(&self) -> &'static str {
        "planetary"
    }

    /// The sun, the ring and the carrier.
    fn ports(&self, a: usize, b: usize) -> Ports {
        self.members(a, b)
    }

    /// Willis' row on the sun, the ring and the carrier, always.
    fn row(&self, k: usize, ports: &[usize], _mode: Mode) -> Option<Row> {
        let (zs, zr) = self.signed_teeth();
        Some(Row::three(
            k,
            [(ports[0], zs), (ports[1], zr), (ports[2], -(zs + zr))],
        ))
    }

    /// Willis' coefficients over the sun's: `1`, `z_R / z_S`, `-(z_S + z_R) / z_S`.
    fn torque_factors(&self, ports: &[usize]) -> Option<[f64; MAX_PORTS]> {
        let row = ElementLaw::row(self, 0, ports, None)?;
        let first = row.terms()[0].1;
        let mut out = [0.0; MAX_PORTS];
        for (o, (_, c)) in out.iter_mut().zip(row.terms()) {
            *o = c / first;
        }
        Some(out)
    }

    fn problems(
        &self,
        net: &Network,
        k: usize,
        ports: &[usize],
        out: &mut Vec<NetworkProblem>,
    ) -> bool {
        network_problems(net, k, ports[0], ports[1], self, out);
        true
    }
}

/// The problems of the planetary set `ps` of coupling `k` on the sun `a` and the ring `b`,
/// pushed to `out`: its gearing, a carrier that is a body of the network other than its sun
/// and ring, at most one fixed member (two would hold the third: make it fixed instead), and
/// speeds at t = 0 that keep Willis' equation.
fn network_problems(
    net: &Network,
    k: usize,
    a: usize,
    b: usize,
    ps: &PlanetarySet,
    out: &mut Vec<NetworkProblem>,
) {
    let problem = |field, message: String| NetworkProblem::Coupling {
        index: k,
        field,
        message,
    };
    for (field, message) in ps.problems() {
        out.push(problem(field, message));
    }
    let n = net.bodies.len();
    if ps.carrier >= n {
        out.push(problem(
            "carrier",
            "names a body that is not in the network".into(),
        ));
        return;
    }
    if ps.carrier == a || ps.carrier == b {
        out.push(problem(
            "carrier",
            "must be a third body, not the sun (a) or the ring (b)".into(),
        ));
        return;
    }
    let members = [a, b, ps.carrier];
    let fixed: Vec<&str> = members
        .iter()
        .filter(|&&i| net.bodies[i].is_fixed())
        .map(|&i| net.bodies[i].name.as_str())
        .collect();
    if fixed.len() > 1 {
        out.push(problem(
            "carrier",
            format!(
                "two of its members are fixed ({}): the third would be held still; make it fixed instead",
                fixed.join(", ")
            ),
        ));
        return;
    }
    if !ps.problems().is_empty() {
        return;
    }
    let w = |i: usize| net.bodies[i].initial_speed_rad_s;
    let want = ps.carrier_speed_rad_s(w(a), w(b));
    let wc = w(ps.carrier);
    if (wc - want).abs() > 1e-9 * (1.0 + wc.abs().max(want.abs())) {
        out.push(problem(
            "carrier",
            format!(
                "the speeds at t = 0 do not keep Willis' equation: the carrier \"{}\" turns at {} rad/s but (z_S w_S + z_R w_R) / (z_S + z_R) is {} rad/s",
                net.bodies[ps.carrier].name,
                crate::fmt_num(wc),
                crate::fmt_num(want)
            ),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With the ring held, the carrier turns at `z_S / (z_S + z_R)` of the sun (a 30/90 set:
    /// a quarter), and the row holds there.
    #[test]
    fn ring_held_gives_the_first_gear_ratio() {
        let p = PlanetarySet {
            sun_teeth: 30,
            ring_teeth: 90,
            carrier: 2,
            double_pinion: false,
        };
        let wc = p.carrier_speed_rad_s(400.0, 0.0);
        assert_eq!(wc, 100.0);
        assert!(p.row(0, 0, 1).apply(&[400.0, 0.0, wc]).abs() < 1e-12);
        assert!(p.problems().is_empty());
    }

    /// Gearing that cannot be built is refused with the reason.
    #[test]
    fn impossible_gearing_is_refused() {
        let bad = |zs, zr| {
            PlanetarySet {
                sun_teeth: zs,
                ring_teeth: zr,
                carrier: 2,
                double_pinion: false,
            }
            .problems()
        };
        assert!(bad(30, 91)[0].1.contains("odd"));
        assert!(bad(90, 30)[0].1.contains("larger than the sun"));
        assert_eq!(bad(0, 30)[0].0, "sun_teeth");
    }

    /// A double-pinion set with its carrier held turns its ring the same way as its sun at
    /// `z_S / z_R` (a 30/90 set: a third), and with its ring held its carrier at
    /// `z_S / (z_S - z_R)` of the sun, backwards.
    #[test]
    fn double_pinion_turns_the_ring_with_the_sun() {
        let p = PlanetarySet {
            sun_teeth: 30,
            ring_teeth: 90,
            carrier: 2,
            double_pinion: true,
        };
        let row = p.row(0, 0, 1);
        assert!(row.apply(&[300.0, 100.0, 0.0]).abs() < 1e-12);
        assert_eq!(p.carrier_speed_rad_s(300.0, 0.0), -150.0);
        assert!(p.problems().is_empty());
    }
}
