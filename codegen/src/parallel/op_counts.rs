//! Operation counts of a platform module's fixed parts beyond its kernels: the LU solves of
//! the actuation matrix and the products around them (error paths not counted).

use crate::schedule::OpCount;

/// Operation count of the emitted `lu_solve_many::<K>` for an `n × n` matrix: squared column
/// norms, partial pivoting, `k` right-hand sides (`lu_solve` is `k = 1`, `lu_inverse` is
/// `k = n`). The error paths (a square root and a division each) are not counted.
pub fn lu_many_ops(n: usize, k: usize, groups: &[usize]) -> OpCount {
    let mut c = OpCount::default();
    // Squared column norms (for the scale-free pivot test), and each unit group's largest.
    c.mul += n * n;
    c.add += n * (n - 1);
    let distinct = (0..n)
        .filter(|&j| (0..j).all(|i| groups.get(i) != groups.get(j)))
        .count();
    c.cmp += n - distinct;
    // With several groups, each group's reference against every other group's, converted.
    c.mul += distinct * (distinct - 1);
    c.cmp += distinct * (distinct - 1);
    for p in 0..n {
        let rows = n - p - 1;
        // The pivot's conditional swaps (one comparison per lower row); its square and the
        // two cross-multiplied products of the tolerance test, the tolerance's product, the
        // test and the running maximum's comparison.
        c.cmp += rows + 2;
        c.mul += 4;
        // Its reciprocal, and the updates of the columns right of it and of the right-hand
        // sides.
        c.div += 1;
        c.mul += rows * (1 + (n - p - 1) + k);
        c.add += rows * ((n - p - 1) + k);
    }
    // Back substitution for k right-hand sides (by the reciprocal pivots).
    c.mul += k * (n * (n - 1) / 2) + n * k;
    c.add += k * (n * (n - 1) / 2);
    c
}

/// Operation count of `lu_solve` (one right-hand side).
pub fn lu_ops(n: usize, groups: &[usize]) -> OpCount {
    lu_many_ops(n, 1, groups)
}

/// Operation count of `lu_inverse` followed by `A⁻ᵀ I A⁻¹` (`I A⁻¹` in full, then the upper
/// triangle of `A⁻ᵀ (I A⁻¹)`).
pub fn lu_inverse_ops(n: usize, groups: &[usize]) -> OpCount {
    let mut c = lu_many_ops(n, n, groups);
    let tri = n * (n + 1) / 2;
    c.mul += n * n * n + tri * n;
    c.add += (n * n + tri) * (n - 1);
    c
}

/// Operation count of `inverse_dynamics_derivatives` beyond its kernel: `lu_inverse`, then
/// `τ = A⁻ᵀ f` and, for each of the `2n` columns, its right-hand side (`∂f/∂x_j − (∂A/∂x_j)ᵀ τ`
/// or `∂f/∂u_j`) and its product with `A⁻ᵀ`.
pub fn idd_solve_ops(n: usize, groups: &[usize]) -> OpCount {
    let mut c = lu_many_ops(n, n, groups);
    // `A⁻ᵀ` times `2n + 1` vectors, and `n` products `(∂A/∂x_j)ᵀ τ` subtracted.
    c.mul += (2 * n + 1) * n * n + n * n * n;
    c.add += (2 * n + 1) * n * (n - 1) + n * n * n;
    c
}

/// `a + times · b`.
pub(super) fn plus(a: OpCount, b: OpCount, times: usize) -> OpCount {
    OpCount {
        add: a.add + b.add * times,
        mul: a.mul + b.mul * times,
        neg: a.neg + b.neg * times,
        div: a.div + b.div * times,
        sqrt: a.sqrt + b.sqrt * times,
        sin_cos: a.sin_cos + b.sin_cos * times,
        cmp: a.cmp + b.cmp * times,
        atan2: a.atan2 + b.atan2 * times,
        fma: a.fma + b.fma * times,
    }
}

/// Operation count of `regressor` beyond its kernel: `lu_inverse` (`lu`), then `A⁻ᵀ F_b`.
pub(super) fn regressor_solve_ops(lu: OpCount, n: usize, nbp: usize) -> OpCount {
    let mut c = lu;
    c.mul += n * n * nbp;
    c.add += n * (n - 1) * nbp;
    c
}
