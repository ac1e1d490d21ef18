//! Forward dynamics `q̈ = I⁻¹ (τ − C q̇ + γ)`: the mass matrix, the bias from inverse dynamics with
//! `q̈ = 0`, and an `Lᵀ D L` factorization from the tips with checked pivots.

use crate::sym::{Arg, ExprId, Graph};

use super::inverse::inverse_dynamics_sunk;
use super::{Terms, Tree, mass_matrix};

/// Relative pivot tolerance of the generated factorization: pivot `k` must exceed
/// `PIVOT_TOLERANCE · I_kk` (the diagonal entry it came from).
pub const PIVOT_TOLERANCE: f64 = 1e-12;

/// Forward dynamics `q̈ = I⁻¹ (τ − C q̇ + γ)`: composite-body `I`, the bias by the inverse
/// dynamics with `q̈ = 0`, then an `Lᵀ D L` factorization eliminated from the tips (no fill-in
/// for trees; Featherstone, RBDA §6.5) with checked pivots.
pub fn forward_dynamics(g: &mut Graph, tree: &Tree) -> Vec<ExprId> {
    let n = tree.dof();
    let m = mass_matrix(g, tree);
    let bias = inverse_dynamics_sunk(
        g,
        tree,
        Terms {
            acceleration: false,
            ..Terms::ALL
        },
        &m.concat(),
    );
    let rhs: Vec<ExprId> = (0..n)
        .map(|i| {
            let t = g.input(Arg::Tau, i);
            g.sub(t, bias[i])
        })
        .collect();
    let f = factor(g, &m);
    solve(g, &f, &f.inv_d, rhs)
}

/// The `Lᵀ D L` factorization of a mass matrix, eliminated from the tips.
pub(super) struct Factor {
    /// `1/d` of the pivots `d`, each a guard.
    pub inv_d: Vec<ExprId>,
    /// `L` (unit lower triangular, the unit diagonal implied), row-major.
    pub l: Vec<Vec<ExprId>>,
}

/// Factor `m` with checked pivots (each asked for as a guard, in the order eliminated).
pub(super) fn factor(g: &mut Graph, m: &[Vec<ExprId>]) -> Factor {
    let n = m.len();
    let mut h = m.to_vec();
    let mut inv_d = vec![g.zero(); n];
    let mut l = vec![vec![g.zero(); n]; n];
    for k in (0..n).rev() {
        let tol = g.scale(crate::scalar::tolerance(PIVOT_TOLERANCE), m[k][k]);
        let d = g.guard(h[k][k], tol, m[k][k], k);
        let one = g.constant(1.0);
        inv_d[k] = g.div(one, d);
        for i in 0..k {
            if g.is_const(h[k][i], 0.0) {
                continue;
            }
            let a = g.mul(h[k][i], inv_d[k]);
            for j in 0..=i {
                if g.is_const(h[k][j], 0.0) {
                    continue;
                }
                let p = g.mul(h[k][j], a);
                h[i][j] = g.sub(h[i][j], p);
                h[j][i] = h[i][j];
            }
            l[k][i] = a;
        }
    }
    Factor { inv_d, l }
}

/// `Lᵀ y = b` (from the last row up), `z = s ∘ y`, `L x = z` (from the first row down): with
/// `s = 1/d` the solution of `m x = b`, with `s = −1/d` its negative.
pub(super) fn solve(g: &mut Graph, f: &Factor, s: &[ExprId], b: Vec<ExprId>) -> Vec<ExprId> {
    let (n, l) = (b.len(), &f.l);
    let mut y = b;
    for k in (0..n).rev() {
        for j in (k + 1)..n {
            if !g.is_const(l[j][k], 0.0) {
                let p = g.mul(l[j][k], y[j]);
                y[k] = g.sub(y[k], p);
            }
        }
    }
    let mut x: Vec<ExprId> = (0..n).map(|k| g.mul(y[k], s[k])).collect();
    for k in 0..n {
        for i in 0..k {
            if !g.is_const(l[k][i], 0.0) {
                let p = g.mul(l[k][i], x[i]);
                x[k] = g.sub(x[k], p);
            }
        }
    }
    x
}
