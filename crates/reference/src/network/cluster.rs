//! The rigid groups of a network in one mode (MODEL.md section 8): the rows of the ideal
//! gears, the locked clutches and any element that ties three bodies (the model's
//! [`clutchpack_model::network::rows`], the rows the multibody engine solves too) turn the
//! bodies' accelerations into the constrained ones, `a = P T`, with
//! `P = M^-1 - M^-1 C^T A^+ C M^-1` (`A = C M^-1 C^T`, 1/(kg m^2)), and their torques into
//! `lambda = L T`, `L = -A^+ C M^-1`. Both matrices depend only on the rows and the inertias:
//! they are built once per mode (at each event that changes a mode), column by column, and
//! each right-hand side is then two matrix products.
//!
//! A group is a set of moving bodies the rows connect (a fixed body connects nothing: two
//! bodies braked to the housing are two groups). Its freedom is the rank of `P` on it: 0 (it
//! is held by a fixed body: its accelerations are exactly 0), 1 (every member turns as
//! `w_i = g_i w_r`, its root's speed, a gear train or a locked chain: its accelerations are
//! `g_i sum_j g_j T_j / J_red` with `J_red = sum g_j^2 J_j`, so that bodies locked together
//! keep equal speeds to the last bit), or more (a planetary set with none of its members held:
//! `a = P T` on the group). The road loads' hold at rest acts on groups of freedom 1 (the
//! module docs of `mod.rs`).

use clutchpack_model::network::rows::{self, Row};
use clutchpack_model::network::Body;
use clutchpack_model::network::Network;

/// A group's freedom: how many degrees of freedom its members keep under the rows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Freedom {
    /// Held by a fixed body: it does not turn.
    Fixed,
    /// One degree of freedom: `w_i = g_i w_root`.
    One,
    /// Two or more (a planetary set): accelerations from `P`.
    Many,
}

/// The rigid groups of a network for one set of rows.
#[derive(Debug, Clone)]
pub(crate) struct Clusters {
    /// The group of each body.
    pub of: Vec<usize>,
    /// The speed factor of each body against its group's root, `w_i = g_i w_root` (groups of
    /// freedom one; 0 for a fixed body, 1 elsewhere).
    pub g: Vec<f64>,
    /// The reduced inertia of each group of freedom one, kg m^2 (`sum g_i^2 J_i`; 0 for the
    /// others).
    pub inertia: Vec<f64>,
    /// Each group's freedom.
    pub freedom: Vec<Freedom>,
    /// The rows of this mode.
    rows: Vec<Row>,
    /// `P`, row-major n x n, 1/(kg m^2).
    p: Vec<f64>,
    /// `L`, row-major (rows) x n, dimensionless.
    l: Vec<f64>,
    /// Each prescribed body with its response to a unit acceleration (rad/s^2) of it: every
    /// body's acceleration and every row's torque ([`rows::prescribed_response`]).
    prescribed: Vec<(usize, Vec<f64>, Vec<f64>)>,
}

impl Clusters {
    /// The groups of `net` when `rows` are the rigid constraints (every ideal gear, and the
    /// locked clutches: [`clutchpack_model::network::Coupling::row`]).
    pub fn build(net: &Network, rows: Vec<Row>) -> Clusters {
        let n = net.bodies.len();
        let inv: Vec<f64> = net.bodies.iter().map(Body::inverse_inertia).collect();
        // P and L column by column: the response to a unit torque on each body
        let (p, l) = rows::projected(&rows, &inv);
        // the groups: moving bodies connected by a row's terms
        let moving: Vec<bool> = net.bodies.iter().map(Body::is_free).collect();
        let of = rows::groups(&rows, &moving);
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); of.iter().max().map_or(0, |m| m + 1)];
        for (i, &c) in of.iter().enumerate() {
            members[c].push(i);
        }
        let mut g = vec![1.0; n];
        let mut inertia = vec![0.0; members.len()];
        let mut freedom = vec![Freedom::Fixed; members.len()];
        for (c, mem) in members.iter().enumerate() {
            let scale = mem.iter().map(|&i| inv[i]).fold(0.0, f64::max);
            // the root: the member that moves most freely under its own torque
            let Some(&r) = mem
                .iter()
                .filter(|&&i| p[i * n + i] > 1e-12 * scale)
                .max_by(|&&a, &&b| p[a * n + a].total_cmp(&p[b * n + b]))
            else {
                mem.iter().for_each(|&i| g[i] = 0.0);
                continue;
            };
            let prr = p[r * n + r];
            let factors: Vec<f64> = mem.iter().map(|&i| p[i * n + r] / prr).collect();
            // rank one: P_ij = g_i g_j P_rr on the group
            let one = mem.iter().zip(&factors).all(|(&i, gi)| {
                mem.iter()
                    .zip(&factors)
                    .all(|(&j, gj)| (p[i * n + j] - gi * gj * prr).abs() <= 1e-9 * prr)
            });
            if !one {
                freedom[c] = Freedom::Many;
                continue;
            }
            freedom[c] = Freedom::One;
            let along = speed_factors(net, &rows, mem, r);
            for (&i, gi) in mem.iter().zip(&factors) {
                g[i] = along.iter().find(|(k, _)| *k == i).map_or(*gi, |x| x.1);
            }
            inertia[c] = mem
                .iter()
                .map(|&i| {
                    if !net.bodies[i].is_free() {
                        0.0
                    } else {
                        g[i] * g[i] * net.bodies[i].inertia_kg_m2
                    }
                })
                .sum();
        }
        for (i, b) in net.bodies.iter().enumerate() {
            if !b.is_free() {
                g[i] = 0.0;
            }
        }
        let prescribed = (0..n)
            .filter(|&i| net.bodies[i].prescribed().is_some())
            .map(|i| {
                let (acc, lambda) = rows::prescribed_response(&rows, &inv, i);
                (i, acc, lambda)
            })
            .collect();
        Clusters {
            prescribed,
            of,
            g,
            inertia,
            freedom,
            rows,
            p,
            l,
        }
    }

    /// The accelerations (rad/s^2) of every body from the torques on each (`torque`, N m: all
    /// but the rows'): 0 in a group a fixed body holds; `g_i sum g_j T_j / J_red` in a group of freedom
    /// one; `(P T)_i` otherwise.
    pub fn accelerations(&self, torque: &[f64], acc: &mut [f64], group: &mut Vec<f64>) {
        let n = torque.len();
        group.clear();
        group.resize(self.inertia.len(), 0.0);
        for (i, t) in torque.iter().enumerate() {
            group[self.of[i]] += self.g[i] * t;
        }
        for (c, a) in group.iter_mut().enumerate() {
            *a = match self.freedom[c] {
                Freedom::One => *a / self.inertia[c],
                Freedom::Fixed | Freedom::Many => 0.0,
            };
        }
        for (i, a) in acc.iter_mut().enumerate() {
            let c = self.of[i];
            *a = match self.freedom[c] {
                Freedom::Fixed => 0.0,
                Freedom::One => self.g[i] * group[c],
                // row i of P against T: the same products summed in the same order as
                // indexing them, without a bounds check per term
                Freedom::Many => (self.p[i * n..(i + 1) * n].iter())
                    .zip(torque)
                    .map(|(p, t)| p * t)
                    .sum(),
            };
        }
    }

    /// The torque each rigid coupling puts on its body `a` (N m, written to `out` at its
    /// coupling: [`Row::first_torque_n_m`] of `lambda = L T`, plus the prescribed bodies'
    /// share) under the other torques `torque` on the bodies (N m) and the prescribed bodies'
    /// accelerations `alpha` (rad/s^2, by body; read at the prescribed bodies only).
    pub fn rigid_torques(&self, torque: &[f64], alpha: &[f64], out: &mut [f64]) {
        for (r, row) in self.rows.iter().enumerate() {
            out[row.coupling] = row.first_torque_n_m(self.lambda(r, torque, alpha));
        }
    }

    /// Row `r`'s torque (N m): `(L T)_r` and the prescribed bodies' share.
    fn lambda(&self, r: usize, torque: &[f64], alpha: &[f64]) -> f64 {
        let n = torque.len();
        // the same products summed in the same order as indexing them
        let mut lambda: f64 = (self.l[r * n..(r + 1) * n].iter())
            .zip(torque)
            .map(|(l, t)| l * t)
            .sum();
        for (p, _, l) in &self.prescribed {
            lambda += l[r] * alpha[*p];
        }
        lambda
    }

    /// Whether a body's motion is prescribed.
    pub fn any_prescribed(&self) -> bool {
        !self.prescribed.is_empty()
    }

    /// Adds the prescribed bodies' accelerations `alpha` (rad/s^2, by body) and what they
    /// impose on the bodies tied to them to `acc` (rad/s^2; [`Self::accelerations`] gave the
    /// torques' share, 0 at a prescribed body).
    pub fn add_prescribed(&self, alpha: &[f64], acc: &mut [f64]) {
        for (p, k, _) in &self.prescribed {
            for (a, ki) in acc.iter_mut().zip(k) {
                *a += ki * alpha[*p];
            }
        }
    }

    /// The reaction of prescribed body `p` (N m, positive along its rotation): what keeps its
    /// profile against the torques `torque` on it (N m, all but the rows') and the rows' at the
    /// accelerations `alpha` (rad/s^2), its inertia infinite: `-(T_p + (C^T lambda)_p)`.
    pub fn reaction_n_m(&self, p: usize, torque: &[f64], alpha: &[f64]) -> f64 {
        let mut on = torque[p];
        for (r, row) in self.rows.iter().enumerate() {
            for (i, c) in row.terms() {
                if *i == p {
                    on += c * self.lambda(r, torque, alpha);
                }
            }
        }
        -on
    }

    /// Projects the speeds `w` (rad/s) onto the rows, each group's angular momentum kept (a
    /// lock's merge: [`rows::project`]), the speeds of a group a fixed body holds exactly 0
    /// (those the prescribed bodies hold: their speeds times the groups' response to them).
    pub fn project(&self, net: &Network, w: &mut [f64]) {
        let inv: Vec<f64> = net.bodies.iter().map(Body::inverse_inertia).collect();
        rows::project(&self.rows, &inv, w);
        let given: Vec<(usize, f64)> = self
            .prescribed
            .iter()
            .map(|(p, _, _)| (*p, w[*p]))
            .collect();
        for i in 0..w.len() {
            if self.freedom[self.of[i]] == Freedom::Fixed && net.bodies[i].is_free() {
                w[i] = 0.0;
                for ((_, k, _), (_, wp)) in self.prescribed.iter().zip(&given) {
                    w[i] += k[i] * wp;
                }
            } else if net.bodies[i].is_fixed() {
                w[i] = 0.0;
            }
        }
    }
}

/// The speed factors `g_i` against the root `r` of a group of freedom one that the rows give
/// from the root (each row with one member left unknown gives it), so that bodies a locked
/// clutch ties get exactly equal factors; a member the rows do not reach that way (a
/// three-body row with two unknowns) is left out: the caller takes `P`'s ratio.
fn speed_factors(net: &Network, rows: &[Row], members: &[usize], r: usize) -> Vec<(usize, f64)> {
    // the root, and the fixed bodies at rest
    let mut known: Vec<(usize, f64)> = std::iter::once((r, 1.0))
        .chain(
            (0..net.bodies.len())
                .filter(|&i| !net.bodies[i].is_free())
                .map(|i| (i, 0.0)),
        )
        .collect();
    let get = |known: &[(usize, f64)], b: usize| known.iter().find(|(k, _)| *k == b).map(|x| x.1);
    loop {
        let mut progress = false;
        for row in rows {
            let t = row.terms();
            if !t.iter().any(|(b, _)| members.contains(b)) {
                continue;
            }
            let mut unknown = t.iter().filter(|(b, _)| get(&known, *b).is_none());
            let (Some(&(u, cu)), None) = (unknown.next(), unknown.next()) else {
                continue;
            };
            // sum_j c_j g_j = 0: g_u = -(sum of the others) / c_u
            let rest: f64 = t
                .iter()
                .filter(|(b, _)| *b != u)
                .map(|(b, c)| c * get(&known, *b).unwrap_or(0.0))
                .sum();
            known.push((u, -rest / cu));
            progress = true;
        }
        if !progress {
            return known;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::network::{Body, Coupling, CouplingKind, Motion};

    fn body(name: &str, j: f64) -> Body {
        Body {
            name: name.into(),
            inertia_kg_m2: j,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 0.0,
            motion: Motion::Free,
            drive: None,
            firing: None,
            road_load: None,
        }
    }

    fn rows_of(net: &Network) -> Vec<Row> {
        net.couplings
            .iter()
            .enumerate()
            .filter_map(|(k, c)| c.row(k, None))
            .collect()
    }

    /// A torque on the first of three bodies geared 2:1 and then 3:1: the group's inertia is
    /// `J1 + J2/4 + J3/36`, each gear carries what the bodies beyond it need, and power is
    /// conserved through each gear.
    #[test]
    fn geared_chain_reduces_and_carries_torque() {
        let net = Network {
            pack_thermal: Default::default(),
            bodies: vec![body("a", 1.0), body("b", 2.0), body("c", 3.0)],
            couplings: vec![
                Coupling {
                    name: "g1".into(),
                    a: 0,
                    b: 1,
                    kind: CouplingKind::ideal_gear(2.0),
                },
                Coupling {
                    name: "g2".into(),
                    a: 1,
                    b: 2,
                    kind: CouplingKind::ideal_gear(3.0),
                },
            ],
        };
        let cl = Clusters::build(&net, rows_of(&net));
        assert_eq!(cl.freedom, vec![Freedom::One]);
        let j = 1.0 + 2.0 / 4.0 + 3.0 / 36.0;
        // the root is the body that moves most freely: a's factor 1 on it, the gears' below
        let jr = cl.inertia[0];
        let (ga, gb, gc) = (cl.g[0], cl.g[1], cl.g[2]);
        assert!((gb - ga / 2.0).abs() < 1e-15 * ga.abs() && (gc - gb / 3.0).abs() < 1e-15);
        assert!((jr / (ga * ga) - j).abs() < 1e-14, "{jr} {ga}");
        let torque = [10.0, 0.0, 0.0];
        let mut acc = [0.0; 3];
        let mut grp = Vec::new();
        cl.accelerations(&torque, &mut acc, &mut grp);
        assert!((acc[0] - 10.0 / j).abs() < 1e-14);
        assert!((acc[1] - acc[0] / 2.0).abs() < 1e-14);
        let mut lam = [0.0; 2];
        cl.rigid_torques(&torque, &[0.0; 3], &mut lam);
        // body c is driven by g2 alone: -3 lambda2 = J3 a3
        assert!((-3.0 * lam[1] - 3.0 * acc[2]).abs() < 1e-13);
        // body a: J1 a1 = 10 + lambda1
        assert!((acc[0] - 10.0 - lam[0]).abs() < 1e-13);
    }

    /// A three-body row with none of its bodies fixed leaves the group two degrees of
    /// freedom: its accelerations keep the row, and with the torques in the Willis ratio
    /// `z_S : z_R : -(z_S + z_R)` (the set's own ideal torques) the bodies do not accelerate.
    #[test]
    fn three_body_row_is_a_group_of_two_freedoms() {
        let net = Network {
            pack_thermal: Default::default(),
            bodies: vec![body("sun", 0.01), body("ring", 0.2), body("carrier", 0.1)],
            couplings: vec![],
        };
        let (zs, zr) = (30.0, 90.0);
        let rows = vec![Row::three(0, [(0, zs), (1, zr), (2, -(zs + zr))])];
        let cl = Clusters::build(&net, rows.clone());
        assert_eq!(cl.freedom, vec![Freedom::Many]);
        let mut acc = [0.0; 3];
        cl.accelerations(&[5.0, -1.0, 2.0], &mut acc, &mut Vec::new());
        assert!(rows[0].apply(&acc).abs() < 1e-11, "{acc:?}");
        cl.accelerations(&[zs, zr, -(zs + zr)], &mut acc, &mut Vec::new());
        assert!(acc.iter().all(|a| a.abs() < 1e-10), "{acc:?}");
    }
}
