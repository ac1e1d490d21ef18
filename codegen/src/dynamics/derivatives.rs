//! Derivatives of the dynamics: `∂τ/∂q`, `∂τ/∂q̇` of inverse dynamics by forward-mode
//! differentiation of its DAG ([`crate::sym::derivative`]) or by the recursive analytic route
//! ([`recursive_inverse_dynamics_derivatives`]), whichever needs fewer operations for the tree
//! ([`prefer_recursive_derivatives`]), and those of forward dynamics from them: `q̈ = FD(q, q̇, τ)` solves `ID(q, q̇, q̈) = τ`, so
//! `∂q̈/∂x = −I⁻¹ ∂ID/∂x` at `q̈ = FD(q, q̇, τ)` (`x` = `q` or `q̇`) and `∂q̈/∂τ = I⁻¹`, every
//! solve through forward dynamics' own `Lᵀ D L` factorization and its guards.

use std::collections::{BTreeSet, HashMap, HashSet};

use crate::sym::derivative::{Derivative, substitute};
use crate::sym::{Arg, ExprId, Graph, Node};

use super::flops::{Paid, marginal_flops};
use super::forward::{factor, solve};
use super::recursive_derivatives::recursive_inverse_dynamics_derivatives;
use super::{Tree, mass_matrix};

/// `(∂τ/∂q, ∂τ/∂q̇)` of the inverse-dynamics outputs `id` by forward mode, one direction per
/// `q_j` and `q̇_j`: `2n²` nodes, each matrix row-major (`[i][j] = ∂τ_i/∂x_j`).
pub fn inverse_dynamics_derivatives(g: &mut Graph, id: &[ExprId]) -> Vec<ExprId> {
    let n = id.len();
    let mut out = vec![g.zero(); 2 * n * n];
    for (m, arg) in [Arg::Q, Arg::Qd].into_iter().enumerate() {
        for j in 0..n {
            let mut d = Derivative::new(arg, j);
            for i in 0..n {
                out[m * n * n + i * n + j] = d.of(g, id[i]);
            }
        }
    }
    out
}

/// `(q̈, ∂q̈/∂q, ∂q̈/∂q̇, I⁻¹)`: `n + 3n²` nodes, matrices row-major. `did` is
/// [`inverse_dynamics_derivatives`] of the tree's inverse dynamics, `fd` its forward dynamics
/// (whose factorization this one shares, node for node: the same guards).
pub fn forward_dynamics_derivatives(
    g: &mut Graph,
    tree: &Tree,
    did: &[ExprId],
    fd: &[ExprId],
) -> Vec<ExprId> {
    let n = fd.len();
    let m = mass_matrix(g, tree);
    let f = factor(g, &m);
    let neg_inv_d: Vec<ExprId> = f.inv_d.iter().map(|&s| g.neg(s)).collect();
    let mut out = fd.to_vec();
    out.resize(n + 3 * n * n, g.zero());
    // `∂ID/∂x` at `q̈ = FD`: a column at a time, solved with `−1/d`.
    let with = |a: Arg, i: usize| (a == Arg::Qdd).then(|| fd[i]);
    let mut memo = HashMap::new();
    for part in 0..2 {
        for j in 0..n {
            let col: Vec<ExprId> = (0..n).map(|i| did[part * n * n + i * n + j]).collect();
            let b = substitute(g, &col, &with, &mut memo);
            let x = solve(g, &f, &neg_inv_d, b);
            for i in 0..n {
                out[n + part * n * n + i * n + j] = x[i];
            }
        }
    }
    // `I⁻¹` by columns of the identity, its lower triangle mirrored.
    let (zero, one) = (g.zero(), g.constant(1.0));
    let cols: Vec<Vec<ExprId>> = (0..n)
        .map(|j| {
            let e = (0..n).map(|i| if i == j { one } else { zero }).collect();
            solve(g, &f, &f.inv_d, e)
        })
        .collect();
    for i in 0..n {
        for j in 0..n {
            out[n + 2 * n * n + i * n + j] = cols[i.min(j)][i.max(j)];
        }
    }
    out
}

/// Replaces `did` (forward mode, [`inverse_dynamics_derivatives`]) and `fdd`
/// ([`forward_dynamics_derivatives`] from it) by the recursive route's when its `∂τ/∂q`, `∂τ/∂q̇`
/// need fewer operations (forward mode stays on a tie). Called after every other function of the
/// module is built, so that their nodes (and emitted text) are those they have without it; the
/// recursive route is built on a copy of the graph, kept only when chosen. `fd` are forward
/// dynamics' outputs. The choice depends on the tree alone: deterministic.
///
/// The recursive route is also left out when it reads an input that forward mode does not: the
/// derivatives would then fail on a non-finite value that `forward_dynamics` ignores.
pub fn prefer_recursive_derivatives(
    g: &mut Graph,
    tree: &Tree,
    did: &mut Vec<ExprId>,
    fdd: &mut Vec<ExprId>,
    fd: &[ExprId],
) {
    let mut rg = g.clone();
    let recursive = recursive_inverse_dynamics_derivatives(&mut rg, tree);
    let none = Paid::default();
    if marginal_flops(&rg, &recursive, &none) >= marginal_flops(g, did, &none)
        || !inputs(&rg, &recursive).is_subset(&inputs(g, did))
    {
        return;
    }
    *fdd = forward_dynamics_derivatives(&mut rg, tree, &recursive, fd);
    *did = recursive;
    *g = rg;
}

/// The inputs that `roots` read.
fn inputs(g: &Graph, roots: &[ExprId]) -> BTreeSet<(Arg, u16)> {
    let mut seen: HashSet<ExprId> = HashSet::new();
    let mut stack = roots.to_vec();
    let mut out = BTreeSet::new();
    while let Some(id) = stack.pop() {
        if !seen.insert(id) {
            continue;
        }
        if let Node::Input(a, i) = g.node(id) {
            out.insert((a, i));
        }
        stack.extend(g.operands(id));
    }
    out
}
