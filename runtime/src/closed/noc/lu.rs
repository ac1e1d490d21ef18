//! Step 3: the LU of `Φ_d` with partial pivoting ([`Lu`]), its row swaps as selects, spare rows
//! left out by the pivoting; solves with `Φ_d` and its transpose.

use alloc::vec::Vec;

use super::CONSTRAINT_TOLERANCE;
use crate::scalar::{Real, Singular, Site};

/// An LU factorization with partial pivoting (data-dependent row swaps recorded as the
/// compared magnitudes), of a matrix with columns scaled to unit norm and at least as many
/// rows as columns: the pivoting chooses the `n` rows solved, the others (spare rows, after
/// the swaps the last ones) are left out.
#[derive(Clone, Debug)]
pub struct Lu<R> {
    m: Vec<Vec<R>>,
    swaps: Vec<(usize, usize, R, R)>,
    sc: Vec<R>,
}

/// Factorize `a` (`nr ≥ n` rows, `n` columns); a column of zero norm or a pivot
/// `|p| ≤ CONSTRAINT_TOLERANCE` is `Singular { site: Constraint(i) }` (condition estimate
/// `1/|p|`).
pub fn lu_factor<R: Real>(a: &[Vec<R>]) -> Result<Lu<R>, Singular> {
    let nr = a.len();
    let n = a.first().map_or(0, Vec::len);
    let mut sc = Vec::with_capacity(n);
    for j in 0..n {
        let mut s = R::c(0.0);
        for i in 0..nr {
            s = s + a[i][j] * a[i][j];
        }
        let s = R::check(s, R::c(0.0), R::c(1.0), Site::Constraint(j), false)?;
        sc.push(R::c(1.0) / s.sqrt());
    }
    let mut m: Vec<Vec<R>> = (0..nr)
        .map(|i| (0..n).map(|j| a[i][j] * sc[j]).collect())
        .collect();
    let mut swaps = Vec::new();
    for k in 0..n {
        // Rows swapped in the active columns only, the multipliers left where they were
        // computed (LINPACK's `dgefa`; the solves replay the swaps step by step). Swapping
        // whole rows (LAPACK's convention) is the same arithmetic, but as selects it carries
        // every earlier multiplier down each candidate row, and a banded `Φ_d` (a chain of
        // loops) becomes a dense `L` in the generated code.
        for i in k + 1..nr {
            let (p, q) = (m[i][k], m[k][k]);
            swaps.push((k, i, p, q));
            for j in k..n {
                let (x, y) = (m[i][j], m[k][j]);
                m[k][j] = R::select_abs_gt(p, q, x, y);
                m[i][j] = R::select_abs_gt(p, q, y, x);
            }
        }
        let piv = R::check(
            m[k][k],
            R::c(R::tolerance(CONSTRAINT_TOLERANCE)),
            R::c(1.0),
            Site::Constraint(k),
            true,
        )?;
        let inv = R::c(1.0) / piv;
        for i in k + 1..nr {
            let f = m[i][k] * inv;
            m[i][k] = f;
            for j in k + 1..n {
                m[i][j] = m[i][j] - f * m[k][j];
            }
        }
    }
    Ok(Lu { m, swaps, sc })
}

impl<R: Real> Lu<R> {
    /// Solve `a x = b` (`b` over every row of `a`; the rows the pivoting left out are not
    /// used).
    pub fn solve(&self, b: &[R]) -> Vec<R> {
        let n = self.sc.len();
        let nr = self.m.len();
        let mut x = b.to_vec();
        // `L⁻¹P`: each step's swaps, then its column of multipliers (`dgesl`).
        let mut swaps = self.swaps.iter().peekable();
        for k in 0..n {
            while let Some(&(_, i, p, q)) = swaps.next_if(|s| s.0 == k) {
                let (xi, xk) = (x[i], x[k]);
                x[k] = R::select_abs_gt(p, q, xi, xk);
                x[i] = R::select_abs_gt(p, q, xk, xi);
            }
            for i in k + 1..nr {
                x[i] = x[i] - self.m[i][k] * x[k];
            }
        }
        for i in (0..n).rev() {
            for j in i + 1..n {
                x[i] = x[i] - self.m[i][j] * x[j];
            }
            x[i] = x[i] / self.m[i][i];
        }
        x.truncate(n);
        for i in 0..n {
            x[i] = x[i] * self.sc[i];
        }
        x
    }

    /// Solve `aₛᵀ y = b`, `aₛ` the rows of `a` the pivoting chose (`y` over every row of `a`,
    /// zero on the others).
    pub fn solve_t(&self, b: &[R]) -> Vec<R> {
        let n = b.len();
        let mut z: Vec<R> = (0..n).map(|i| b[i] * self.sc[i]).collect();
        // Uᵀ z' = D b (forward).
        for i in 0..n {
            for j in 0..i {
                z[i] = z[i] - self.m[j][i] * z[j];
            }
            z[i] = z[i] / self.m[i][i];
        }
        // `(L⁻¹P)ᵀ`: step by step backwards, its column of multipliers, then its swaps in
        // reverse (the spare rows start at zero).
        let nr = self.m.len();
        z.resize(nr, R::c(0.0));
        let mut swaps = self.swaps.iter().rev().peekable();
        for k in (0..n).rev() {
            for i in k + 1..nr {
                z[k] = z[k] - self.m[i][k] * z[i];
            }
            while let Some(&(_, i, p, q)) = swaps.next_if(|s| s.0 == k) {
                let (zi, zk) = (z[i], z[k]);
                z[k] = R::select_abs_gt(p, q, zi, zk);
                z[i] = R::select_abs_gt(p, q, zk, zi);
            }
        }
        z
    }
}
