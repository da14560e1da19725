//! The rigid constraints of a driveline (MODEL.md section 8): every ideal gear
//! (`w_a - ratio w_b = 0`), every locked clutch (`w_a - w_b = 0`) and, with up to three terms,
//! any element that ties three bodies (a planetary set's Willis equation,
//! `z_S w_S + z_R w_R - (z_S + z_R) w_C = 0`) is one row `C_r` of a Jacobian on the bodies'
//! speeds (rad/s), its torque `lambda_r` (N m) acting on the bodies as `C_r^T lambda_r`. Both
//! engines build their rows here ([`super::Coupling::row`]) and solve them with these
//! functions, so that they make the same choice where the rows are redundant.
//!
//! Two solves, both on the matrix `A = C M^-1 C^T` (`M^-1` the bodies' inverse inertias,
//! 1/(kg m^2), 0 for a fixed body):
//! - **the constraint torques** under the torques `T` (N m) with consistent speeds:
//!   `A lambda = -C M^-1 T` (the rows' rates stay 0);
//! - **the projection at a lock**: the speeds closest to `w` in the kinetic metric that satisfy
//!   the rows, `w' = w - M^-1 C^T mu` with `A mu = C w` (angular momentum of each group kept;
//!   the kinetic energy it removes is the lock's heat).
//!
//! `A` is singular when rows are redundant (two clutches locked in parallel, a clutch locked
//! across a gear train that already ties its bodies): the symmetric elimination runs in the
//! rows' order and drops a row whose pivot falls below `1e-12` of its diagonal (it depends
//! on the rows before it), whose torque is then 0: the earlier coupling carries the load. The
//! split between parallel rigid paths is indeterminate in a rigid model; both engines make
//! this one choice, or a parallel clutch could break in one and hold in the other.

/// The most bodies one row ties (a planetary set's three members).
pub const MAX_TERMS: usize = 3;

/// One constraint row: `sum_j c_j w_{i_j} = 0` over its terms `(i_j, c_j)` (body index,
/// coefficient; the coefficients dimensionless or in the element's own units, a row's
/// torque `lambda` acting as `c_j lambda` on body `i_j`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// The coupling (element) it stands for.
    pub coupling: usize,
    terms: [(usize, f64); MAX_TERMS],
    len: usize,
}

impl Row {
    /// The two-body row `c_a w_a + c_b w_b = 0`.
    pub fn two(coupling: usize, (a, c_a): (usize, f64), (b, c_b): (usize, f64)) -> Row {
        Row {
            coupling,
            terms: [(a, c_a), (b, c_b), (0, 0.0)],
            len: 2,
        }
    }

    /// The three-body row `c_1 w_1 + c_2 w_2 + c_3 w_3 = 0`.
    pub fn three(coupling: usize, terms: [(usize, f64); 3]) -> Row {
        Row {
            coupling,
            terms,
            len: 3,
        }
    }

    /// Its terms `(body, coefficient)`.
    pub fn terms(&self) -> &[(usize, f64)] {
        &self.terms[..self.len]
    }

    /// `C_r w` (rad/s, or the coefficients' units times rad/s).
    pub fn apply(&self, w: &[f64]) -> f64 {
        let t = self.terms();
        let mut v = t[0].1 * w[t[0].0];
        for (i, c) in &t[1..] {
            v += c * w[*i];
        }
        v
    }

    /// The torque (N m) the row's torque `lambda` puts on its first body (the coupling's body
    /// `a`: `c_1 lambda`; `lambda` itself for a gear or a locked clutch, whose `c_1` is 1; the
    /// sun's torque of a planetary set): what the engines report as the coupling's torque.
    pub fn first_torque_n_m(&self, lambda: f64) -> f64 {
        self.terms[0].1 * lambda
    }

    /// `C_r M^-1 T` for the torques `torque` (N m) and inverse inertias `inv_inertia`
    /// (1/(kg m^2)): the rate the torques alone would give the row.
    pub fn rate(&self, inv_inertia: &[f64], torque: &[f64]) -> f64 {
        let t = self.terms();
        let mut v = t[0].1 * inv_inertia[t[0].0] * torque[t[0].0];
        for (i, c) in &t[1..] {
            v += c * inv_inertia[*i] * torque[*i];
        }
        v
    }
}

/// Solves `A x = rhs` for `A = C M^-1 C^T` of `rows` (`inv_inertia` per body, 1/(kg m^2));
/// `x` has one entry per row, 0 for the rows dropped as redundant (those that depend on the
/// rows before them).
pub fn solve(rows: &[Row], inv_inertia: &[f64], rhs: &[f64], x: &mut Vec<f64>) {
    let m = rows.len();
    x.clear();
    x.resize(m, 0.0);
    if m == 0 {
        return;
    }
    eliminate(rows, inv_inertia, rhs, x);
}

/// The indices of the rows the elimination drops as redundant: those that depend on the rows
/// before them, with the inverse inertias `inv_inertia` (1/(kg m^2); 0 for a fixed body).
pub fn redundant(rows: &[Row], inv_inertia: &[f64]) -> Vec<usize> {
    let mut x = vec![0.0; rows.len()];
    let active = eliminate(rows, inv_inertia, &vec![0.0; rows.len()], &mut x);
    (0..rows.len()).filter(|&r| !active[r]).collect()
}

/// [`solve`]'s elimination into `x` (sized to the rows); returns which rows it kept.
fn eliminate(rows: &[Row], inv_inertia: &[f64], rhs: &[f64], x: &mut [f64]) -> Vec<bool> {
    let e = Elimination::new(rows, inv_inertia);
    x.copy_from_slice(rhs);
    e.solve_in_place(x);
    e.active
}

/// The symmetric elimination of `A = C M^-1 C^T` for some rows and inverse inertias, kept to
/// solve for one right-hand side after another ([`Elimination::constraint_torques`]): the same
/// operations in the same order as [`solve`], so the same results to the bit, without
/// building and eliminating `A` again while the rows stand (a network's rows change only
/// where a clutch locks or releases).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Elimination {
    /// The rows it eliminated.
    rows: Vec<Row>,
    /// Their count.
    m: usize,
    /// `A` eliminated (row-major `m x m`; its upper triangle is the back substitution's).
    a: Vec<f64>,
    /// The multiplier of row `k` subtracted from row `r > k` (`f[r * m + k]`; 0: none).
    f: Vec<f64>,
    /// Which rows it kept (the others depend on the rows before them).
    active: Vec<bool>,
}

impl Elimination {
    /// The elimination of `rows` with the inverse inertias `inv_inertia` (1/(kg m^2) per body,
    /// 0 for a fixed body).
    pub fn new(rows: &[Row], inv_inertia: &[f64]) -> Elimination {
        let m = rows.len();
        // A_rs = sum_i C_ri C_si / J_i: only the bodies the two rows share
        let mut a = vec![0.0; m * m];
        for (r, p) in rows.iter().enumerate() {
            for (s, q) in rows.iter().enumerate() {
                let mut v = 0.0;
                for (i, ci) in p.terms() {
                    for (j, cj) in q.terms() {
                        if i == j {
                            v += ci * cj * inv_inertia[*i];
                        }
                    }
                }
                a[r * m + s] = v;
            }
        }
        // symmetric elimination in the rows' order (A is symmetric positive semi-definite): a
        // row whose pivot falls below 1e-12 of its own diagonal depends on the rows before it
        // and is dropped (its torque 0: the earlier coupling carries the load)
        let mut f = vec![0.0; m * m];
        let mut active = vec![false; m];
        for k in 0..m {
            let piv = a[k * m + k];
            let diag: f64 = rows[k]
                .terms()
                .iter()
                .map(|(i, c)| c * c * inv_inertia[*i])
                .sum();
            if piv.is_nan() || piv <= 1e-12 * diag {
                continue;
            }
            active[k] = true;
            for r in k + 1..m {
                let fr = a[r * m + k] / piv;
                f[r * m + k] = fr;
                if fr == 0.0 {
                    continue;
                }
                for c in k..m {
                    a[r * m + c] -= fr * a[k * m + c];
                }
            }
        }
        Elimination {
            rows: rows.to_vec(),
            m,
            a,
            f,
            active,
        }
    }

    /// The rows it eliminated (a caller keeps it while its rows are these).
    pub fn rows(&self) -> &[Row] {
        &self.rows
    }

    /// Solves `A x = rhs` in place: `x` holds `rhs` (one entry per row) and is left with the
    /// solution, 0 for the rows dropped, as [`solve`] gives it.
    fn solve_in_place(&self, x: &mut [f64]) {
        let (m, a) = (self.m, &self.a);
        // the right-hand side through the elimination's steps, in their order
        for k in (0..m).filter(|&k| self.active[k]) {
            for r in k + 1..m {
                let f = self.f[r * m + k];
                if f == 0.0 {
                    continue;
                }
                x[r] -= f * x[k];
            }
        }
        // back substitution on the independent rows (each reads the solution of the
        // independent rows after it); the others are 0
        for k in (0..m).rev() {
            if !self.active[k] {
                continue;
            }
            let mut v = x[k];
            for c in k + 1..m {
                if self.active[c] {
                    v -= a[k * m + c] * x[c];
                }
            }
            x[k] = v / a[k * m + k];
        }
        for k in (0..m).filter(|&k| !self.active[k]) {
            x[k] = 0.0;
        }
    }

    /// [`project`] onto its rows with the inverse inertias `inv_inertia` it was made with
    /// (1/(kg m^2)): the speeds `w` (rad/s) closest to them in the kinetic metric that keep
    /// the rows, momentum kept.
    pub fn project(&self, inv_inertia: &[f64], w: &mut [f64]) {
        if self.m == 0 {
            return;
        }
        let mut mu: Vec<f64> = self.rows.iter().map(|r| r.apply(w)).collect();
        self.solve_in_place(&mut mu);
        let mut dw = vec![0.0; w.len()];
        add_torques(&self.rows, &mu, &mut dw);
        for (i, v) in w.iter_mut().enumerate() {
            *v -= inv_inertia[i] * dw[i];
        }
    }

    /// [`constraint_torques`] of its rows with the inverse inertias `inv_inertia` it was made
    /// with (1/(kg m^2)) under the torques `torque` (N m), into `lambda` (N m, one per row).
    pub fn constraint_torques(&self, inv_inertia: &[f64], torque: &[f64], lambda: &mut Vec<f64>) {
        lambda.clear();
        lambda.extend(self.rows.iter().map(|r| -r.rate(inv_inertia, torque)));
        self.solve_in_place(lambda);
    }
}

/// The constraint torques `lambda` (N m, one per row) that keep the rows' rates at 0 under
/// the torques `torque` (N m) on bodies of inverse inertias `inv_inertia`:
/// `A lambda = -C M^-1 T`.
pub fn constraint_torques(
    rows: &[Row],
    inv_inertia: &[f64],
    torque: &[f64],
    lambda: &mut Vec<f64>,
) {
    let rhs: Vec<f64> = rows.iter().map(|r| -r.rate(inv_inertia, torque)).collect();
    solve(rows, inv_inertia, &rhs, lambda);
}

/// `P = M^-1 - M^-1 C^T A^+ C M^-1` (row-major n x n, 1/(kg m^2): every body's
/// acceleration under a unit torque on each, the rows holding) and `L = -A^+ C M^-1`
/// (row-major rows x n: each row's torque under those unit torques), column by column from
/// [`constraint_torques`], for the inverse inertias `inv_inertia` (1/(kg m^2), 0 for a fixed
/// body). With unit inertias `P` is the projector on the speeds the rows allow.
pub fn projected(rows: &[Row], inv_inertia: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (n, m) = (inv_inertia.len(), rows.len());
    let (mut p, mut l) = (vec![0.0; n * n], vec![0.0; m * n]);
    let mut lambda = Vec::new();
    for i in 0..n {
        let mut unit = vec![0.0; n];
        unit[i] = 1.0;
        constraint_torques(rows, inv_inertia, &unit, &mut lambda);
        add_torques(rows, &lambda, &mut unit);
        for j in 0..n {
            p[j * n + i] = inv_inertia[j] * unit[j];
        }
        for r in 0..m {
            l[r * n + i] = lambda[r];
        }
    }
    (p, l)
}

/// The response to a unit acceleration (1 rad/s^2) of the prescribed body `p` (whose inverse
/// inertia in `inv_inertia` is 0, as a fixed body's: its motion is given), every other torque
/// 0: each body's acceleration (rad/s^2; 1 at `p`, the rows' kinematics on the bodies they tie
/// to it) and each row's torque (N m). The rows' rates vanish with `a = u + M^-1 C^T lambda`,
/// `u` the unit at `p`: `A lambda = -C u`. Accelerations and torques are linear in `p`'s
/// acceleration, so the engines add `alpha_p(t)` times this response to `P T` and `L T`; and
/// the speeds a group held by prescribed bodies alone takes are the same combination of
/// their speeds.
pub fn prescribed_response(rows: &[Row], inv_inertia: &[f64], p: usize) -> (Vec<f64>, Vec<f64>) {
    let n = inv_inertia.len();
    let rhs: Vec<f64> = rows
        .iter()
        .map(|r| {
            -r.terms()
                .iter()
                .filter(|(i, _)| *i == p)
                .map(|(_, c)| c)
                .sum::<f64>()
        })
        .collect();
    let mut lambda = Vec::new();
    solve(rows, inv_inertia, &rhs, &mut lambda);
    let mut t = vec![0.0; n];
    add_torques(rows, &lambda, &mut t);
    let mut acc: Vec<f64> = (0..n).map(|i| inv_inertia[i] * t[i]).collect();
    acc[p] = 1.0;
    (acc, lambda)
}

/// The group of each of `n` bodies: the bodies that move (`moving[i]`) connected by a row's
/// terms share one; a body that does not move (a fixed body) connects nothing and is a group
/// of its own. Groups are numbered in the order of their first body.
pub fn groups(rows: &[Row], moving: &[bool]) -> Vec<usize> {
    let n = moving.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for r in rows {
        let mut first: Option<usize> = None;
        for (i, _) in r.terms().iter().filter(|(i, _)| moving[*i]) {
            match first {
                None => first = Some(*i),
                Some(f) => {
                    let (x, y) = (root(&mut parent, f), root(&mut parent, *i));
                    parent[x.max(y)] = x.min(y);
                }
            }
        }
    }
    let mut of = vec![usize::MAX; n];
    let mut next = 0;
    for i in 0..n {
        let r = root(&mut parent, i);
        if of[r] == usize::MAX {
            of[r] = next;
            next += 1;
        }
        of[i] = of[r];
    }
    of
}

/// Adds `C^T lambda` to the bodies' torques `out` (N m).
pub fn add_torques(rows: &[Row], lambda: &[f64], out: &mut [f64]) {
    for (r, l) in rows.iter().zip(lambda) {
        for (i, c) in r.terms() {
            out[*i] += c * l;
        }
    }
}

/// Projects the speeds `w` (rad/s) onto the rows, momentum kept: `w' = w - M^-1 C^T mu`,
/// `A mu = C w`.
pub fn project(rows: &[Row], inv_inertia: &[f64], w: &mut [f64]) {
    if rows.is_empty() {
        return;
    }
    Elimination::new(rows, inv_inertia).project(inv_inertia, w);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(coupling: usize, a: usize, b: usize, coef_b: f64) -> Row {
        Row::two(coupling, (a, 1.0), (b, coef_b))
    }

    /// Three bodies geared 2:1 then 3:1 under a torque on the first: the constraint torques
    /// give every body the acceleration of the reduced group, `10 / (J1 + J2/4 + J3/36)`
    /// times its speed factor.
    #[test]
    fn geared_chain_accelerates_as_one_body() {
        let rows = [row(0, 0, 1, -2.0), row(1, 1, 2, -3.0)];
        let inv = [1.0, 0.5, 1.0 / 3.0];
        let t = [10.0, 0.0, 0.0];
        let mut lambda = Vec::new();
        constraint_torques(&rows, &inv, &t, &mut lambda);
        let mut tot = t;
        add_torques(&rows, &lambda, &mut tot);
        let acc: Vec<f64> = (0..3).map(|i| inv[i] * tot[i]).collect();
        let j = 1.0 + 2.0 / 4.0 + 3.0 / 36.0;
        assert!((acc[0] - 10.0 / j).abs() < 1e-13, "{acc:?}");
        assert!((acc[1] - acc[0] / 2.0).abs() < 1e-13);
        assert!((acc[2] - acc[1] / 3.0).abs() < 1e-13);
    }

    /// An elimination kept over several torques (a network step's evaluations) gives each
    /// time what a fresh solve gives, to the bit, on rows with a redundant one and a
    /// three-term one; its rows are the ones it was made for.
    #[test]
    fn a_kept_elimination_solves_as_a_fresh_one() {
        let rows = [
            Row::three(0, [(0, 30.0), (1, 90.0), (2, -120.0)]),
            row(1, 0, 1, -1.0),
            row(2, 1, 0, -1.0),
            row(3, 2, 3, -2.5),
        ];
        let inv = [100.0, 20.0, 2.0, 0.7];
        let kept = Elimination::new(&rows, &inv);
        assert_eq!(kept.rows(), &rows[..]);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for t in [[20.0, 0.0, 0.0, -3.0], [-1.5, 7.25, 0.1, 0.0], [0.0; 4]] {
            kept.constraint_torques(&inv, &t, &mut a);
            constraint_torques(&rows, &inv, &t, &mut b);
            assert_eq!(a.len(), 4);
            assert_eq!(a, b, "{t:?}");
            assert_eq!(a[2], 0.0, "the redundant row carries nothing");
        }
    }

    /// Two clutches locked in parallel between the same bodies are one redundant row: the
    /// projection still merges the speeds with the momentum kept, the second row carries 0.
    #[test]
    fn redundant_rows_are_dropped() {
        let rows = [row(0, 0, 1, -1.0), row(1, 0, 1, -1.0)];
        let inv = [1.0, 0.5];
        let mut w = [4.0, 1.0];
        project(&rows, &inv, &mut w);
        // momentum 4 + 2 = 6 over 3 kg m^2
        assert!(
            (w[0] - 2.0).abs() < 1e-14 && (w[1] - 2.0).abs() < 1e-14,
            "{w:?}"
        );
        let mut x = Vec::new();
        solve(&rows, &inv, &[3.0, 3.0], &mut x);
        // the first carries the load, the second nothing
        assert!(x[1] == 0.0 && (x[0] - 2.0).abs() < 1e-14, "{x:?}");
    }

    /// A three-term row (a planetary set's Willis equation with z_S = 30, z_R = 90: sun 0,
    /// ring 1, carrier 2) leaves two degrees of freedom: with the ring fixed (inverse
    /// inertia 0) a torque on the sun turns the carrier at a quarter of the sun's speed,
    /// the ideal torques stand in the ratio `z_S : z_R : -(z_S + z_R)`, and the power the
    /// row's torques put in is zero at any speeds that satisfy it.
    #[test]
    fn three_body_row_gives_the_willis_ratios() {
        let (zs, zr) = (30.0, 90.0);
        let rows = [Row::three(0, [(0, zs), (1, zr), (2, -(zs + zr))])];
        let inv = [1.0 / 0.01, 0.0, 1.0 / 0.5];
        let t = [20.0, 0.0, 0.0];
        let mut lambda = Vec::new();
        constraint_torques(&rows, &inv, &t, &mut lambda);
        let mut tot = t;
        add_torques(&rows, &lambda, &mut tot);
        let acc: Vec<f64> = (0..3).map(|i| inv[i] * tot[i]).collect();
        // the row's terms are about 1.5e4 rad/s^2: rounding leaves about 1e-12 of them
        assert!(rows[0].apply(&acc).abs() < 1e-10, "{acc:?}");
        assert!(
            (acc[2] - acc[0] * zs / (zs + zr)).abs() < 1e-12 * acc[0],
            "{acc:?}"
        );
        // the reduced inertia on the sun: J_S + J_C (z_S / (z_S + z_R))^2
        let j = 0.01 + 0.5 * (zs / (zs + zr)).powi(2);
        assert!((acc[0] - 20.0 / j).abs() < 1e-10 * acc[0], "{acc:?}");
        // ideal power: sum_j c_j lambda w_j = lambda C w = 0 for any w on the row
        let w = [400.0, 0.0, 100.0];
        assert!(rows[0].apply(&w).abs() < 1e-12);
        // projection from inconsistent speeds lands on the row
        let mut w = [400.0, 0.0, 50.0];
        project(&rows, &inv, &mut w);
        assert!(rows[0].apply(&w).abs() < 1e-9, "{w:?}");
    }
}
