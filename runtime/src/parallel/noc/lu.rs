//! The solves with the actuation matrix `A` of step 6 (`τ = A⁻ᵀ f`, `A⁻¹` in forward
//! kinematics): [`lu_solve`], LU with partial pivoting of `A` with its columns scaled by unit
//! group ([`ColumnUnits`]), checked against
//! [`ACTUATION_TOLERANCE`], for fixed sizes and on row vectors.

use alloc::vec::Vec;

use super::ACTUATION_TOLERANCE;
use crate::scalar::{Singular, Site};
use crate::solve::check_finite;

/// How the pivot test of `A` ([`lu_solve`]) scales its columns (docs/method.md, "Parallel
/// manipulators: actuation matrix", the actuator efforts): each column by the reference of its
/// unit group (`PlatformMotion::unit_groups`), the larger of the group's largest column 2-norm
/// and every other group's largest, converted by the platform's radius `L`: a column of a rotation speed
/// (rad/s) is compared with `L` times one of a translation speed (m/s), as the legs' moment
/// arms make it. So a whole group that vanishes is a small pivot, as a single column that
/// shrinks within its group is: a planar 3-RPR whose three leg lines pass through the
/// platform's origin has an `ω` column of zeros (rounding noise at a computed pose), which
/// its own norm would scale back to unit length.
#[derive(Clone, Copy, Debug)]
pub struct ColumnUnits<'a> {
    /// The unit group of each column (`PlatformMotion::unit_groups`).
    pub groups: &'a [usize],
    /// Per group, whether its speeds are rotations (`PlatformMotion::rotational_groups`).
    pub rotational: &'a [bool],
    /// The platform's radius `L` (m, `ParallelModel::platform_radius`).
    pub length: f64,
}

impl ColumnUnits<'_> {
    /// The group of column `j` (all one group when `groups` is short).
    pub fn group(&self, j: usize) -> usize {
        self.groups.get(j).copied().unwrap_or(0)
    }

    /// Whether groups `h` and `g` are of one kind (`None`), or `h` holds translations and `g`
    /// rotations (`Some(true)`), or the other way round (`Some(false)`).
    fn conversion(&self, h: usize, g: usize) -> Option<bool> {
        let rot = |k: usize| self.rotational.get(k).copied().unwrap_or(false);
        (rot(h) != rot(g)).then(|| rot(g))
    }

    /// The factor that turns a column norm of group `h` into one comparable with group `g`'s:
    /// `L` from translations to rotations, `1/L` back, 1 between groups of one kind.
    pub fn factor(&self, h: usize, g: usize) -> f64 {
        match self.conversion(h, g) {
            Some(true) => self.length,
            Some(false) => 1.0 / self.length,
            None => 1.0,
        }
    }

    /// [`Self::factor`] for squared norms: `L²`, `1/L²` or 1.
    pub fn factor2(&self, h: usize, g: usize) -> f64 {
        match self.conversion(h, g) {
            Some(true) => self.length * self.length,
            Some(false) => 1.0 / (self.length * self.length),
            None => 1.0,
        }
    }

    /// Column `j`'s squared reference from the squared column norms `norm2`: the largest
    /// `norm2[i] · factor2(group(i), group(j))` (NaN left out).
    pub fn reference2(&self, norm2: &[f64], j: usize) -> f64 {
        self.largest(norm2, j, |h, g| self.factor2(h, g))
    }

    /// Column `j`'s reference from column norms `norm` of any one kind (2-norms, largest
    /// magnitudes): the largest `norm[i] · factor(group(i), group(j))` (NaN left out).
    pub fn reference(&self, norm: &[f64], j: usize) -> f64 {
        self.largest(norm, j, |h, g| self.factor(h, g))
    }

    fn largest(&self, norm: &[f64], j: usize, factor: impl Fn(usize, usize) -> f64) -> f64 {
        let gj = self.group(j);
        let mut s: f64 = 0.0;
        for (i, &n) in norm.iter().enumerate() {
            let gi = self.group(i);
            let v = if gi == gj { n } else { n * factor(gi, gj) };
            if v > s {
                s = v;
            }
        }
        s
    }
}

/// Solve `a x = b` (`transpose`: `aᵀ x = b`) by LU with partial pivoting of `a` with each column
/// scaled by its unit group's reference ([`ColumnUnits`]); a pivot `≤ ACTUATION_TOLERANCE`
/// times the larger of 1 and the largest pivot (or a non-finite one) is reported as
/// `Site::Actuation(pivot)` with the ratio of that reference to the pivot as the condition
/// estimate. Both solves factorize the same matrix, so they give the same verdict at every `a`
/// (LAPACK's `dgetrf` and `dgetrs`). Fixed-size, no allocation.
pub fn lu_solve<const N: usize>(
    a: &[[f64; N]; N],
    b: &[f64; N],
    transpose: bool,
    units: ColumnUnits<'_>,
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
    // Each column scaled by its unit group's reference.
    let mut sc = [1.0; N];
    for j in 0..N {
        let s = crate::math::sqrt(units.reference2(&norm, j));
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
    units: ColumnUnits<'_>,
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
            lu_solve(&m, &v, transpose, units).map(|x| x.to_vec())
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
