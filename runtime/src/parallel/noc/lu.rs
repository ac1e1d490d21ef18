//! The solves with the actuation matrix `A` of step 6 (`τ = A⁻ᵀ f`, `A⁻¹` in forward
//! kinematics): [`lu_solve`], LU with partial pivoting of `A` with its columns scaled by unit
//! group, checked against
//! [`ACTUATION_TOLERANCE`], for fixed sizes and on row vectors.

use alloc::vec::Vec;

use super::ACTUATION_TOLERANCE;
use crate::scalar::{Singular, Site};
use crate::solve::check_finite;

/// Solve `a x = b` (`transpose`: `aᵀ x = b`) by LU with partial pivoting of `a` with each column
/// scaled by the largest 2-norm of its unit group (`groups[j]`, `PlatformMotion::unit_groups`);
/// a pivot `≤ ACTUATION_TOLERANCE` times the larger of 1 and the largest pivot (or a
/// non-finite one) is reported as `Site::Actuation(pivot)` with the ratio of that reference to
/// the pivot as the condition estimate. Both solves factorize the same matrix, so they
/// give the same verdict at every `a` (LAPACK's `dgetrf` and `dgetrs`). Fixed-size, no
/// allocation.
pub fn lu_solve<const N: usize>(
    a: &[[f64; N]; N],
    b: &[f64; N],
    transpose: bool,
    groups: &[usize],
) -> Result<[f64; N], Singular> {
    // m = a·S (column scaling S), factorized in place as P m = L U: the multipliers below the
    // diagonal, swapped with their rows.
    let mut m = *a;
    let mut norm = [0.0; N];
    for j in 0..N {
        for row in m.iter() {
            norm[j] += row[j] * row[j];
        }
    }
    // Each column scaled by the largest norm of its unit group (`groups[j]`; all one group
    // when `groups` is short).
    let group = |j: usize| groups.get(j).copied().unwrap_or(0);
    let mut sc = [1.0; N];
    for j in 0..N {
        let mut s: f64 = 0.0;
        for i in 0..N {
            if group(i) == group(j) && norm[i] > s {
                s = norm[i];
            }
        }
        let s = crate::math::sqrt(s);
        if s > 0.0 {
            sc[j] = 1.0 / s;
            for row in m.iter_mut() {
                row[j] *= sc[j];
            }
        }
    }
    let mut piv = [0usize; N];
    // The largest column of a group has unit norm: a pivot is compared with 1 as well as with
    // the largest before it.
    let mut pmax: f64 = 1.0;
    for k in 0..N {
        let mut p = k;
        let mut best = if m[k][k] < 0.0 { -m[k][k] } else { m[k][k] };
        for (i, row) in m.iter().enumerate().skip(k + 1) {
            let v = if row[k] < 0.0 { -row[k] } else { row[k] };
            if v > best {
                best = v;
                p = i;
            }
        }
        m.swap(k, p);
        piv[k] = p;
        // NaN never passes.
        if !(best > 0.0) || !best.is_finite() {
            return Err(Singular {
                site: Site::Actuation(k),
                value: m[k][k],
                condition_estimate: f64::INFINITY,
            });
        }
        pmax = if best > pmax { best } else { pmax };
        if !(best > ACTUATION_TOLERANCE * pmax) {
            return Err(Singular {
                site: Site::Actuation(k),
                value: m[k][k],
                condition_estimate: pmax / best,
            });
        }
        let inv = 1.0 / m[k][k];
        for i in k + 1..N {
            let f = m[i][k] * inv;
            m[i][k] = f;
            if f != 0.0 {
                for j in k + 1..N {
                    m[i][j] -= f * m[k][j];
                }
            }
        }
    }
    let mut x = *b;
    if transpose {
        // aᵀ x = b ⇔ (a S)ᵀ x = S b = Uᵀ Lᵀ P x: forward with Uᵀ, back with Lᵀ, then Pᵀ.
        for j in 0..N {
            x[j] *= sc[j];
        }
        for i in 0..N {
            let mut s = x[i];
            for j in 0..i {
                s -= m[j][i] * x[j];
            }
            x[i] = s / m[i][i];
        }
        for i in (0..N).rev() {
            let mut s = x[i];
            for j in i + 1..N {
                s -= m[j][i] * x[j];
            }
            x[i] = s;
        }
        for k in (0..N).rev() {
            x.swap(k, piv[k]);
        }
    } else {
        // a x = b ⇔ L U (S⁻¹ x) = P b.
        for k in 0..N {
            x.swap(k, piv[k]);
        }
        for i in 0..N {
            let mut s = x[i];
            for j in 0..i {
                s -= m[i][j] * x[j];
            }
            x[i] = s;
        }
        for i in (0..N).rev() {
            let mut s = x[i];
            for j in i + 1..N {
                s -= m[i][j] * x[j];
            }
            x[i] = s / m[i][i];
        }
        for j in 0..N {
            x[j] *= sc[j];
        }
    }
    check_finite(&[&x])?;
    Ok(x)
}

/// `lu_solve` for the sizes the bundled platforms use, on row vectors.
pub(super) fn solve_dyn(
    a: &[Vec<f64>],
    b: &[f64],
    transpose: bool,
    groups: &[usize],
) -> Result<Vec<f64>, Singular> {
    macro_rules! fixed {
        ($n:literal) => {{
            let mut m = [[0.0; $n]; $n];
            let mut v = [0.0; $n];
            for i in 0..$n {
                v[i] = b[i];
                for j in 0..$n {
                    m[i][j] = a[i][j];
                }
            }
            lu_solve(&m, &v, transpose, groups).map(|x| x.to_vec())
        }};
    }
    match b.len() {
        1 => fixed!(1),
        2 => fixed!(2),
        3 => fixed!(3),
        4 => fixed!(4),
        5 => fixed!(5),
        _ => fixed!(6),
    }
}
