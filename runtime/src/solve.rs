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
    /// Why it stopped, which tells a `q` outside the workspace from a guess too far away.
    pub stop: Stop,
}

/// Why forward kinematics stopped without converging.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// A non-finite `q` or guess.
    Input,
    /// The guess itself, with these actuated coordinates, cannot be evaluated (a leg cannot
    /// reach it, or it is singular): give a guess inside the workspace.
    Guess,
    /// The Jacobian of `q(x)` became singular on the way: `q` is at or near the workspace's
    /// boundary or a singularity lies between the guess and `q`.
    Singular,
    /// No step along Newton's direction reduces the residual any more, though it is not zero:
    /// most likely `q` is outside the workspace (no configuration has it), or beyond a
    /// singularity seen from the guess.
    Stalled,
    /// The residual still fell at the iteration limit: Newton was on its way; a closer guess
    /// (the last configuration of a trajectory) converges.
    Iterations,
    /// Closed loops: the kept loop equations hold but not all of them (a spurious branch of
    /// the kept equations): give a guess on the intended assembly.
    Branch,
}
