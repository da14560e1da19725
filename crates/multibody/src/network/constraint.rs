//! The velocity-level constraints of a driveline network on the multibody engine (MODEL.md
//! section 8): every ideal gear (`w_a - ratio w_b = 0`) and every locked clutch
//! (`w_a - w_b = 0`) is one row `C_r` of a Jacobian on the bodies' speeds, and its torque
//! `lambda_r` acts as `C_r^T lambda_r` (`lambda` on body `a`, `-ratio lambda` or `-lambda` on
//! `b`: the network's sign convention for a coupling's torque on `a`).
//!
//! Two solves, both on the matrix `A = C M^-1 C^T` (`M^-1` the bodies' inverse inertias, 0 for
//! the fixed body):
//! - **the step's constraint torques**: `lambda` such that the speeds at the end of a step of
//!   length `h` under the torques `T` satisfy every row, `C (w + h M^-1 (T + C^T lambda)) = 0`,
//!   i.e. `A lambda = -C w / h - C M^-1 T` (rapier's velocity constraint, solved exactly here
//!   rather than by rapier's one Gauss-Seidel sweep, so that a chain of gears and clutches
//!   holds to rounding and the torque a locked clutch carries is exact for its break test);
//! - **the projection at a lock**: the speeds closest to `w` in the kinetic metric that satisfy
//!   the rows, `w' = w - M^-1 C^T mu` with `A mu = C w` (angular momentum of each group kept;
//!   the kinetic energy it removes is the lock's heat).
//!
//! `A` is singular when rows are redundant (two clutches locked in parallel, a clutch locked
//! across a gear train that already ties its bodies): the symmetric elimination runs in the
//! couplings' order and drops a row whose pivot falls below `1e-12` of its diagonal (it
//! depends on the rows before it), whose torque is then 0: the earlier coupling carries the
//! load. The split between parallel rigid paths is indeterminate in a rigid model; the
//! reference engine's spanning tree gives the later coupling none either, and the two engines
//! must make the same choice, or a parallel clutch could break in one and hold in the other.

/// One constraint row: `coef_a w_a + coef_b w_b = 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Row {
    /// The coupling it stands for.
    pub coupling: usize,
    /// Body `a`.
    pub a: usize,
    /// Body `b`.
    pub b: usize,
    /// Coefficient of `w_a` (1).
    pub coef_a: f64,
    /// Coefficient of `w_b` (`-ratio` for a gear, -1 for a locked clutch).
    pub coef_b: f64,
}

impl Row {
    /// `C_r w`, rad/s.
    pub fn apply(&self, w: &[f64]) -> f64 {
        self.coef_a * w[self.a] + self.coef_b * w[self.b]
    }
}

/// Solves `A x = rhs` for `A = C M^-1 C^T` of `rows` (`inv_inertia` per body, 1/(kg m^2));
/// `x` has one entry per row, 0 for the rows dropped as redundant (those that depend on the
/// rows before them).
pub(crate) fn solve(rows: &[Row], inv_inertia: &[f64], rhs: &[f64], x: &mut Vec<f64>) {
    let m = rows.len();
    x.clear();
    x.resize(m, 0.0);
    if m == 0 {
        return;
    }
    // A_rs = sum_i C_ri C_si / J_i: only the bodies the two rows share
    let mut a = vec![0.0; m * m];
    for (r, p) in rows.iter().enumerate() {
        for (s, q) in rows.iter().enumerate() {
            let mut v = 0.0;
            for (i, ci) in [(p.a, p.coef_a), (p.b, p.coef_b)] {
                for (j, cj) in [(q.a, q.coef_a), (q.b, q.coef_b)] {
                    if i == j {
                        v += ci * cj * inv_inertia[i];
                    }
                }
            }
            a[r * m + s] = v;
        }
    }
    // symmetric elimination in the rows' order (A is symmetric positive semi-definite): a
    // row whose pivot falls below 1e-12 of its own diagonal depends on the rows before it
    // and is dropped (its torque 0: the earlier coupling carries the load)
    let mut b = rhs.to_vec();
    let mut active = vec![false; m];
    for k in 0..m {
        let piv = a[k * m + k];
        let diag: f64 = [(rows[k].a, rows[k].coef_a), (rows[k].b, rows[k].coef_b)]
            .iter()
            .map(|(i, c)| c * c * inv_inertia[*i])
            .sum();
        if piv.is_nan() || piv <= 1e-12 * diag {
            continue;
        }
        active[k] = true;
        for r in k + 1..m {
            let f = a[r * m + k] / piv;
            if f == 0.0 {
                continue;
            }
            for c in k..m {
                a[r * m + c] -= f * a[k * m + c];
            }
            b[r] -= f * b[k];
        }
    }
    // back substitution on the independent rows; the others are 0
    for k in (0..m).rev() {
        if !active[k] {
            continue;
        }
        let mut v = b[k];
        for c in k + 1..m {
            if active[c] {
                v -= a[k * m + c] * x[c];
            }
        }
        x[k] = v / a[k * m + k];
    }
}

/// Adds `C^T lambda` to the bodies' torques `out` (N m).
pub(crate) fn add_torques(rows: &[Row], lambda: &[f64], out: &mut [f64]) {
    for (r, l) in rows.iter().zip(lambda) {
        out[r.a] += r.coef_a * l;
        out[r.b] += r.coef_b * l;
    }
}

/// Projects the speeds `w` (rad/s) onto the rows, momentum kept: `w' = w - M^-1 C^T mu`,
/// `A mu = C w`.
pub(crate) fn project(rows: &[Row], inv_inertia: &[f64], w: &mut [f64]) {
    if rows.is_empty() {
        return;
    }
    let rhs: Vec<f64> = rows.iter().map(|r| r.apply(w)).collect();
    let mut mu = Vec::new();
    solve(rows, inv_inertia, &rhs, &mut mu);
    let mut dw = vec![0.0; w.len()];
    add_torques(rows, &mu, &mut dw);
    for (i, v) in w.iter_mut().enumerate() {
        *v -= inv_inertia[i] * dw[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(coupling: usize, a: usize, b: usize, coef_b: f64) -> Row {
        Row {
            coupling,
            a,
            b,
            coef_a: 1.0,
            coef_b,
        }
    }

    /// Three bodies geared 2:1 then 3:1 under a torque on the first: the constraint torques
    /// give every body the acceleration of the reduced group, `10 / (J1 + J2/4 + J3/36)`
    /// times its speed factor.
    #[test]
    fn geared_chain_accelerates_as_one_body() {
        let rows = [row(0, 0, 1, -2.0), row(1, 1, 2, -3.0)];
        let inv = [1.0, 0.5, 1.0 / 3.0];
        let t = [10.0, 0.0, 0.0];
        // A lambda = -C M^-1 T (speeds already consistent)
        let rhs: Vec<f64> = rows
            .iter()
            .map(|r| -(r.coef_a * inv[r.a] * t[r.a] + r.coef_b * inv[r.b] * t[r.b]))
            .collect();
        let mut lambda = Vec::new();
        solve(&rows, &inv, &rhs, &mut lambda);
        let mut tot = t;
        add_torques(&rows, &lambda, &mut tot);
        let acc: Vec<f64> = (0..3).map(|i| inv[i] * tot[i]).collect();
        let j = 1.0 + 2.0 / 4.0 + 3.0 / 36.0;
        assert!((acc[0] - 10.0 / j).abs() < 1e-13, "{acc:?}");
        assert!((acc[1] - acc[0] / 2.0).abs() < 1e-13);
        assert!((acc[2] - acc[1] / 3.0).abs() < 1e-13);
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
}
