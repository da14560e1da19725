//! The rigid groups of a network in one mode: bodies joined by ideal gears and locked clutches
//! move as one degree of freedom (MODEL.md section 8). For each group: the speed factor of each
//! body (`w_i = g_i w_group`), the reduced inertia `sum g_i^2 J_i`, and a spanning tree of its
//! rigid couplings in leaves-first order, from which the torque each rigid coupling carries
//! follows body by body (the constraint torques of the tree; a rigid loop's extra coupling,
//! possible only with clutches locked in parallel, carries none).

use clutchpack_model::network::{CouplingKind, Network};

/// The rigid groups of a network for one set of locked clutches.
#[derive(Debug, Clone)]
pub(crate) struct Clusters {
    /// The group of each body.
    pub of: Vec<usize>,
    /// The speed factor of each body against its group: `w_i = g_i w_group`.
    pub g: Vec<f64>,
    /// The reduced inertia of each group, kg m^2 (`sum g_i^2 J_i`; unused for a fixed group).
    pub inertia: Vec<f64>,
    /// Whether each group holds a fixed body (it does not turn).
    pub fixed: Vec<bool>,
    /// The tree's edges leaves first: (coupling, child body, parent body).
    pub order: Vec<(usize, usize, usize)>,
}

/// `w_a = r w_b` for a rigid coupling: the ideal gear's ratio, 1 for a locked clutch.
pub(crate) fn rigid_ratio(net: &Network, k: usize) -> f64 {
    match net.couplings[k].kind {
        CouplingKind::IdealGear { ratio } => ratio,
        CouplingKind::Clutch(_)
        | CouplingKind::GearMesh(_)
        | CouplingKind::SpringDamper(_)
        | CouplingKind::Pack(_) => 1.0,
    }
}

impl Clusters {
    /// The groups when the couplings with `rigid[k]` are rigid (every ideal gear, and the
    /// locked clutches).
    pub fn build(net: &Network, rigid: &[bool]) -> Clusters {
        let n = net.bodies.len();
        let mut adj: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, c) in net.couplings.iter().enumerate() {
            if rigid[k] {
                adj[c.a].push(k);
                adj[c.b].push(k);
            }
        }
        let mut of = vec![usize::MAX; n];
        let mut g = vec![1.0; n];
        let mut inertia = Vec::new();
        let mut fixed = Vec::new();
        let mut order = Vec::new();
        // roots: fixed bodies first, so that a fixed group's unknown reaction is its root's
        let roots = (0..n)
            .filter(|&i| net.bodies[i].fixed)
            .chain((0..n).filter(|&i| !net.bodies[i].fixed));
        let mut queue = Vec::new();
        for r in roots {
            if of[r] != usize::MAX {
                continue;
            }
            let id = inertia.len();
            of[r] = id;
            g[r] = 1.0;
            queue.clear();
            queue.push(r);
            let mut head = 0;
            let mut tree = Vec::new();
            while head < queue.len() {
                let p = queue[head];
                head += 1;
                for &k in &adj[p] {
                    let c = &net.couplings[k];
                    let ch = if c.a == p { c.b } else { c.a };
                    if of[ch] != usize::MAX {
                        continue;
                    }
                    let r = rigid_ratio(net, k);
                    // w_a = r w_b
                    g[ch] = if ch == c.b { g[p] / r } else { g[p] * r };
                    of[ch] = id;
                    tree.push((k, ch, p));
                    queue.push(ch);
                }
            }
            let members = &queue[..];
            fixed.push(members.iter().any(|&i| net.bodies[i].fixed));
            inertia.push(
                members
                    .iter()
                    .filter(|&&i| !net.bodies[i].fixed)
                    .map(|&i| g[i] * g[i] * net.bodies[i].inertia_kg_m2)
                    .sum(),
            );
            order.extend(tree.into_iter().rev());
        }
        Clusters {
            of,
            g,
            inertia,
            fixed,
            order,
        }
    }

    /// The accelerations (rad/s^2) of every body from the torques on each (`torque`, N m: all
    /// but the rigid couplings'): each group's `sum g_i T_i / sum g_i^2 J_i`, times `g_i`.
    pub fn accelerations(&self, torque: &[f64], acc: &mut [f64], group: &mut Vec<f64>) {
        group.clear();
        group.resize(self.inertia.len(), 0.0);
        for (i, t) in torque.iter().enumerate() {
            group[self.of[i]] += self.g[i] * t;
        }
        for (c, a) in group.iter_mut().enumerate() {
            *a = if self.fixed[c] {
                0.0
            } else {
                *a / self.inertia[c]
            };
        }
        for (i, a) in acc.iter_mut().enumerate() {
            *a = self.g[i] * group[self.of[i]];
        }
    }

    /// The torque each rigid coupling carries (N m, on its body `a`: `lambda`, and
    /// `-r lambda` on `b`), from the bodies' accelerations and the other torques on them;
    /// `out[k]` is written for the tree's couplings only.
    pub fn rigid_torques(
        &self,
        net: &Network,
        torque: &[f64],
        acc: &[f64],
        out: &mut [f64],
        residual: &mut Vec<f64>,
    ) {
        // residual[i]: what the rigid couplings must put on body i, J a - T, less what its
        // children's couplings already put on it
        residual.clear();
        residual.extend(net.bodies.iter().enumerate().map(|(i, b)| {
            if b.fixed {
                0.0
            } else {
                b.inertia_kg_m2 * acc[i] - torque[i]
            }
        }));
        for &(k, ch, p) in &self.order {
            let c = &net.couplings[k];
            let r = rigid_ratio(net, k);
            let on_child = residual[ch];
            let (lambda, on_parent) = if ch == c.a {
                (on_child, -r * on_child)
            } else {
                let l = -on_child / r;
                (l, l)
            };
            out[k] = lambda;
            residual[p] -= on_parent;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clutchpack_model::network::{Body, Coupling};

    fn body(name: &str, j: f64) -> Body {
        Body {
            name: name.into(),
            inertia_kg_m2: j,
            drag_n_m_s_rad: 0.0,
            initial_speed_rad_s: 0.0,
            fixed: false,
            drive: None,
            firing: None,
            road_load: None,
        }
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
                    kind: CouplingKind::IdealGear { ratio: 2.0 },
                },
                Coupling {
                    name: "g2".into(),
                    a: 1,
                    b: 2,
                    kind: CouplingKind::IdealGear { ratio: 3.0 },
                },
            ],
        };
        let cl = Clusters::build(&net, &[true, true]);
        let j = 1.0 + 2.0 / 4.0 + 3.0 / 36.0;
        assert!((cl.inertia[0] - j).abs() < 1e-15);
        let torque = [10.0, 0.0, 0.0];
        let mut acc = [0.0; 3];
        let mut grp = Vec::new();
        cl.accelerations(&torque, &mut acc, &mut grp);
        assert!((acc[0] - 10.0 / j).abs() < 1e-14);
        assert!((acc[1] - acc[0] / 2.0).abs() < 1e-14);
        let mut lam = [0.0; 2];
        let mut res = Vec::new();
        cl.rigid_torques(&net, &torque, &acc, &mut lam, &mut res);
        // body c is driven by g2 alone: -3 lambda2 = J3 a3
        assert!((-3.0 * lam[1] - 3.0 * acc[2]).abs() < 1e-13);
        // body a: J1 a1 = 10 + lambda1
        assert!((acc[0] - 10.0 - lam[0]).abs() < 1e-13);
        // the root's balance closes
        assert!(res[0].abs() < 1e-13, "{res:?}");
    }
}
