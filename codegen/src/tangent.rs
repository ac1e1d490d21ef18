//! Derivatives of the closed-chain kinds' functions along their coordinates' tangent spaces
//! ([method.md, "Derivatives"](../../docs/method.md#derivatives)).
//!
//! A platform's or a closed loop's coordinates `x` are not free: a quaternion stays unit, the
//! joint positions of a closed loop stay on the constraint manifold. Its speeds `u` are free,
//! and `ẋ = E(x) u`: `E` is the tangent of the platform's `retract`
//! ([`runtime::parallel::noc::tangent`]), or a closed loop's `S` (the joint rates per unit
//! independent speed). The derivative of a function `f(x, …)` along the speed `u_j` is
//! `Σ_k ∂f/∂x_k E_kj`: one forward-mode pass over the DAG with the inputs `x_k` seeded by the
//! nodes `E_kj` ([`Derivative::along`]), folded and shared like every other node.

use crate::scalar::{Sx, with};
use crate::sym::derivative::Derivative;
use crate::sym::{Arg, ExprId};

/// One direction of the inputs: each seeded input with its rate.
pub(crate) type Direction = Vec<(Arg, usize, ExprId)>;

/// The directions `ẋ = E e_j` of the columns of `e` (`nx × n`), structural zeros left out.
pub(crate) fn along_coordinates(e: &[Vec<Sx>]) -> Vec<Direction> {
    let n = e.first().map_or(0, Vec::len);
    (0..n)
        .map(|j| {
            e.iter()
                .enumerate()
                .filter(|(_, row)| !with(|g| g.is_const(row[j].0, 0.0)))
                .map(|(k, row)| (Arg::X, k, row[j].0))
                .collect()
        })
        .collect()
}

/// The unit directions of the `n` inputs `arg`.
pub(crate) fn along_inputs(arg: Arg, n: usize) -> Vec<Direction> {
    let one = with(|g| g.constant(1.0));
    (0..n).map(|j| vec![(arg, j, one)]).collect()
}

/// `∂f_i/∂d_j` for the outputs `f` and the directions `d`, row-major (`[i][j]`).
pub(crate) fn jacobian(f: &[ExprId], directions: &[Direction]) -> Vec<ExprId> {
    let n = directions.len();
    let mut out = vec![with(|g| g.zero()); f.len() * n];
    for (j, d) in directions.iter().enumerate() {
        let mut pass = Derivative::along(d);
        for (i, &fi) in f.iter().enumerate() {
            out[i * n + j] = with(|g| pass.of(g, fi));
        }
    }
    out
}

/// The guards of `a`, then those of `b` not among them.
pub(crate) fn union(mut a: Vec<ExprId>, b: Vec<ExprId>) -> Vec<ExprId> {
    for g in b {
        if !a.contains(&g) {
            a.push(g);
        }
    }
    a
}

/// The derivatives of forward dynamics by the implicit function theorem, instead of
/// differentiating its factorization: with `f(x, u, u̇) = I u̇ + h` the generalized force (its
/// `u̇` the inputs `Arg::Ud`) and forward dynamics solving `f(x, u, u̇) = B τ`,
/// `∂u̇/∂d = I⁻¹ (∂(B τ)/∂d − ∂f/∂d |_{u̇ = FD})` along each direction `d` of `x` and `u`, and
/// `∂u̇/∂τ_j = I⁻¹ B e_j`. Every solve is [`runtime::solve::solve_spd`] on the very nodes of
/// forward dynamics' own inertia, so its `LDLᵀ` and guards are forward dynamics' (shared in
/// the DAG). `b_rate[j]` is `∂(B τ)/∂x_j` (zero where `B` is constant), `b` is `B` (`n × n`).
/// The result: `u̇`, then `∂u̇/∂x`, `∂u̇/∂u`, `∂u̇/∂τ`, row-major.
pub(crate) struct ImplicitForward<'a> {
    /// `u̇ = FD(x, u, τ)`.
    pub fd: &'a [Sx],
    /// `f(x, u, u̇)` at the inputs `Arg::Ud`.
    pub f: &'a [Sx],
    /// `I`, the nodes forward dynamics factorizes.
    pub inertia: &'a [Vec<Sx>],
    /// `∂(B τ)/∂x_j` per direction of `x` (empty: `B` constant).
    pub b_rate: &'a [Vec<Sx>],
    /// `B`.
    pub b: &'a [Vec<Sx>],
}

impl ImplicitForward<'_> {
    pub(crate) fn derivatives(
        &self,
        along_x: &[Direction],
        along_u: &[Direction],
    ) -> Result<Vec<ExprId>, runtime::scalar::Singular> {
        let n = self.fd.len();
        let f: Vec<ExprId> = self.f.iter().map(|s| s.0).collect();
        // `∂f/∂x` and `∂f/∂u` with `u̇` held, then `u̇ = FD` put in.
        let (dfx, dfu) = (jacobian(&f, along_x), jacobian(&f, along_u));
        let fd: Vec<ExprId> = self.fd.iter().map(|s| s.0).collect();
        let put = |a: Arg, i: usize| (a == Arg::Ud).then(|| fd[i]);
        let mut memo = std::collections::HashMap::new();
        let (dfx, dfu) = with(|g| {
            let x = crate::sym::derivative::substitute(g, &dfx, &put, &mut memo);
            let u = crate::sym::derivative::substitute(g, &dfu, &put, &mut memo);
            (x, u)
        });
        let column =
            |m: &[ExprId], j: usize| -> Vec<Sx> { (0..n).map(|i| Sx(m[i * n + j])).collect() };
        let mut out = vec![with(|g| g.zero()); n + 3 * n * n];
        for (i, &v) in fd.iter().enumerate() {
            out[i] = v;
        }
        let mut put_column = |block: usize, j: usize, v: Vec<Sx>| {
            for (i, s) in v.into_iter().enumerate() {
                out[n + block * n * n + i * n + j] = s.0;
            }
        };
        for j in 0..n {
            let rhs_x: Vec<Sx> = column(&dfx, j)
                .into_iter()
                .enumerate()
                .map(|(i, d)| match self.b_rate.get(j) {
                    Some(r) => r[i] - d,
                    None => -d,
                })
                .collect();
            let rhs_u: Vec<Sx> = column(&dfu, j).into_iter().map(|d| -d).collect();
            let rhs_t: Vec<Sx> = (0..n).map(|i| self.b[i][j]).collect();
            put_column(0, j, runtime::solve::solve_spd(self.inertia, &rhs_x)?);
            put_column(1, j, runtime::solve::solve_spd(self.inertia, &rhs_u)?);
            put_column(2, j, runtime::solve::solve_spd(self.inertia, &rhs_t)?);
        }
        Ok(out)
    }
}
