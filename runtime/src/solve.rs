//! The solves every evaluator shares: a symmetric positive definite `LDLᵀ` over [`Real`] with
//! checked pivots, the finiteness check of `f64` inputs and results, and the failure of a Newton
//! solve (forward kinematics, assembly).

// Index loops read like the equations; negated float comparisons make NaN fail the test.
#![allow(clippy::needless_range_loop)]

use alloc::vec;
use alloc::vec::Vec;

use crate::scalar::{Real, Singular, Site};

/// Generalized-inertia threshold of forward dynamics: pivot `i` of `LDLᵀ` must exceed
/// `PIVOT_TOLERANCE` times the diagonal entry it came from (as for trees).
pub const PIVOT_TOLERANCE: f64 = 1e-12;

/// Solve `m x = b` for a symmetric positive definite `m` by `LDLᵀ` (no pivoting), each pivot
/// checked against [`PIVOT_TOLERANCE`] times its diagonal entry.
pub fn solve_spd<R: Real>(m: &[Vec<R>], b: &[R]) -> Result<Vec<R>, Singular> {
    let n = b.len();
    let mut l: Vec<Vec<R>> = vec![vec![R::c(0.0); n]; n];
    let mut d: Vec<R> = vec![R::c(0.0); n];
    for j in 0..n {
        let mut dj = m[j][j];
        for k in 0..j {
            dj = dj - l[j][k] * l[j][k] * d[k];
        }
        let dj = R::check(
            dj,
            R::c(R::tolerance(PIVOT_TOLERANCE)) * m[j][j],
            m[j][j],
            Site::MassMatrix(j),
            false,
        )?;
        d[j] = dj;
        let inv = R::c(1.0) / dj;
        for i in j + 1..n {
            let mut s = m[i][j];
            for k in 0..j {
                s = s - l[i][k] * l[j][k] * d[k];
            }
            l[i][j] = s * inv;
        }
    }
    let mut y = b.to_vec();
    for i in 0..n {
        for k in 0..i {
            y[i] = y[i] - l[i][k] * y[k];
        }
    }
    for i in 0..n {
        y[i] = y[i] / d[i];
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            y[i] = y[i] - l[k][i] * y[k];
        }
    }
    Ok(y)
}

/// `Err(Site::Input)` unless every value is finite.
pub fn check_finite(inputs: &[&[f64]]) -> Result<(), Singular> {
    for v in inputs.iter().flat_map(|s| s.iter()) {
        if !v.is_finite() {
            return Err(Singular {
                site: Site::Input,
                value: *v,
                condition_estimate: f64::INFINITY,
            });
        }
    }
    Ok(())
}

/// A Newton solve (forward kinematics, assembly) did not converge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoConvergence {
    /// Newton iterations made.
    pub iterations: usize,
    /// The last residual `max |q(x) − q|` (m or rad; infinite when no pose was reachable).
    pub residual: f64,
}
