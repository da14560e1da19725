//! The gears of an automatic transmission from its topology alone (MODEL.md section 10): a
//! gear is the set of shift elements (clutches and brakes among the couplings) that are closed;
//! with their rows and the rows that always hold (ideal gears, planetary sets), the speeds the
//! rows allow are the null space of `C` (the fixed bodies held). In a gear the input's group
//! must keep exactly one degree of freedom, the output turning in it: every member's speed per
//! unit input speed follows, the ratio `w_in / w_out`, and the slip `w_b - w_a` of every open
//! element (its drag depends on it).
//!
//! The null space is taken from the projector `P = I - C^T (C C^T)^+ C` on the moving bodies
//! ([`super::rows::projected`] with unit inertias): rank one on the input's group means one
//! degree of freedom, and its column at the input is the speeds per unit input.

use super::rows::{self, Row};
use super::{ClutchMode, Network};
use serde::{Deserialize, Serialize};

/// One gear: the elements closed in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gear {
    /// Its name (`"1"`, `"R"`, ...).
    pub name: String,
    /// The couplings (indices in [`Network::couplings`], each a clutch or a brake) closed in it.
    pub closed: Vec<usize>,
}

/// An automatic transmission on a network: its input and output bodies and its gears.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Transmission {
    /// The input body (index in [`Network::bodies`]).
    pub input: usize,
    /// The output body.
    pub output: usize,
    /// The gears, in the order given.
    pub gears: Vec<Gear>,
}

/// A gear's kinematics.
#[derive(Debug, Clone, PartialEq)]
pub struct GearKinematics {
    /// `w_in / w_out` (dimensionless; negative: the output turns backwards, a reverse gear).
    pub ratio: f64,
    /// Every body's speed per unit input speed (0 for a body that does not turn with the
    /// input, and for the fixed bodies).
    pub speeds_per_input: Vec<f64>,
    /// Each shift element open in this gear with its slip `w_b - w_a` per unit input speed:
    /// `(coupling index, slip)`.
    pub open_slips: Vec<(usize, f64)>,
}

impl Transmission {
    /// The shift elements: every coupling closed in some gear, in the couplings' order.
    pub fn elements(&self) -> Vec<usize> {
        let mut out: Vec<usize> = self.gears.iter().flat_map(|g| g.closed.clone()).collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The kinematics of gear `gear` (index in [`Self::gears`]) on `net`, or why it has none
    /// (the message names the element or the bodies at fault).
    pub fn kinematics(&self, net: &Network, gear: usize) -> Result<GearKinematics, String> {
        let g = &self.gears[gear];
        let n = net.bodies.len();
        let rows: Vec<Row> = net
            .couplings
            .iter()
            .enumerate()
            .filter_map(|(k, c)| {
                let mode = g.closed.contains(&k).then_some(ClutchMode::Locked);
                c.row(k, mode)
            })
            .collect();
        let inv: Vec<f64> = net
            .bodies
            .iter()
            .map(|b| if b.fixed { 0.0 } else { 1.0 })
            .collect();
        if let Some(r) = rows::redundant(&rows, &inv).first() {
            return Err(format!(
                "over-constrains the transmission: \"{}\" ties members the elements and gear sets before it already tie",
                net.couplings[rows[*r].coupling].name
            ));
        }
        let (p, _) = rows::projected(&rows, &inv);
        let (i, o) = (self.input, self.output);
        let pin = p[i * n + i];
        if pin <= 1e-12 {
            return Err(format!(
                "holds the input \"{}\" still: its elements lock the transmission",
                net.bodies[i].name
            ));
        }
        let moving: Vec<bool> = net.bodies.iter().map(|b| !b.fixed).collect();
        let of = rows::groups(&rows, &moving);
        let members: Vec<usize> = (0..n).filter(|&j| of[j] == of[i]).collect();
        let v: Vec<f64> = (0..n).map(|j| p[j * n + i] / pin).collect();
        // one degree of freedom: P = v v^T P_in,in on the input's group
        let one = members.iter().all(|&a| {
            members
                .iter()
                .all(|&b| (p[a * n + b] - v[a] * v[b] * pin).abs() <= 1e-9 * (1.0 + pin))
        });
        if !one {
            return Err(format!(
                "leaves the input \"{}\" more than one degree of freedom: close more elements (or fewer gear sets turn freely)",
                net.bodies[i].name
            ));
        }
        if of[o] != of[i] || v[o].abs() <= 1e-12 {
            return Err(format!(
                "the output \"{}\" does not turn with the input \"{}\"",
                net.bodies[o].name, net.bodies[i].name
            ));
        }
        let open_slips = self
            .elements()
            .into_iter()
            .filter(|k| !g.closed.contains(k))
            .map(|k| {
                let c = &net.couplings[k];
                (k, v[c.b] - v[c.a])
            })
            .collect();
        Ok(GearKinematics {
            ratio: 1.0 / v[o],
            speeds_per_input: v,
            open_slips,
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::cases::eight_speed;

    /// The 8HP's nine gears from its topology alone: each ratio is the published exact
    /// fraction (MODEL.md section 10) to 1e-12 relative (measured: 4e-15 and below, the
    /// elimination's rounding); in 6th every member turns with the input; in 1st the open
    /// elements D and E slip.
    #[test]
    fn eight_speed_ratios_are_the_exact_fractions() {
        let (net, tr) = eight_speed();
        let want = [
            -1744.0 / 529.0,
            108.0 / 23.0,
            72.0 / 23.0,
            162.0 / 77.0,
            5.0 / 3.0,
            8826.0 / 6871.0,
            1.0,
            120.0 / 143.0,
            2.0 / 3.0,
        ];
        for (g, w) in want.iter().enumerate() {
            let k = tr.kinematics(&net, g).unwrap();
            assert!(
                (k.ratio - w).abs() < 1e-12 * w.abs(),
                "gear {}: {} against {w}",
                tr.gears[g].name,
                k.ratio
            );
        }
        let sixth = tr.kinematics(&net, 6).unwrap();
        assert!(
            sixth.speeds_per_input[..8]
                .iter()
                .all(|v| (v - 1.0).abs() < 1e-12),
            "{sixth:?}"
        );
        let first = tr.kinematics(&net, 1).unwrap();
        assert_eq!(first.open_slips.len(), 2);
        assert!(
            first.open_slips.iter().all(|(_, s)| s.abs() > 0.01),
            "{first:?}"
        );
    }

    /// A gear of two elements leaves a degree of freedom too many, one of four holds the input
    /// still (eight rows on eight moving bodies), each refused with the reason.
    #[test]
    fn gears_that_are_no_gear_are_refused_with_the_reason() {
        let (net, mut tr) = eight_speed();
        tr.gears[1].closed = vec![4, 5];
        assert!(tr
            .kinematics(&net, 1)
            .unwrap_err()
            .contains("more than one degree of freedom"));
        tr.gears[1].closed = vec![4, 5, 6, 7];
        assert!(tr
            .kinematics(&net, 1)
            .unwrap_err()
            .contains("holds the input"));
    }
}
