//! Constant frame arithmetic in `f64`, done before any node is built: the rotation that turns a
//! joint axis onto `+z`, rotations about `z`, sums and products that snap analytic cancellations
//! to exact zeros, and the parallel-axis theorem that moves inertial parameters between frames.

use runtime::model::{Mat3, Vec3, transpose};

/// `Rz(a)`, exact for multiples of π/2.
pub(super) fn rot_z(a: f64) -> Mat3 {
    let (s, c) = runtime::model::exact_sin_cos(a);
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// `a · b` with [`snapped_sum`] entries, and entries within rounding of ±1 made exact.
pub(super) fn snapped_mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let v = snapped_sum(&[a[r][0] * b[0][c], a[r][1] * b[1][c], a[r][2] * b[2][c]]);
            m[r][c] = if (v.abs() - 1.0).abs() <= 4.0 * f64::EPSILON {
                v.signum()
            } else {
                v
            };
        }
    }
    m
}

/// `a · v` with [`snapped_sum`] entries.
pub(super) fn snapped_mat_vec(a: &Mat3, v: &Vec3) -> Vec3 {
    let mut r = [0.0; 3];
    for (k, rk) in r.iter_mut().enumerate() {
        *rk = snapped_sum(&[a[k][0] * v[0], a[k][1] * v[1], a[k][2] * v[2]]);
    }
    r
}

/// `Σ terms`, or exactly 0 when the sum is below the rounding level of its terms (a parameter
/// that cancels analytically — an origin moved onto a mass centre, a product of inertia moved
/// to zero — must become a structural zero, not a 1e-18 that costs a multiplication).
pub(super) fn snapped_sum(terms: &[f64]) -> f64 {
    let sum: f64 = terms.iter().sum();
    let mag: f64 = terms.iter().map(|t| t.abs()).sum();
    if sum.abs() <= 32.0 * f64::EPSILON * mag {
        0.0
    } else {
        sum
    }
}

/// Inertial parameters `(m, h, J)` of a body (first moment `h` and inertia `J` about its frame
/// origin) moved to a frame in which that body's frame has rotation `rot` and origin `p` (the
/// parallel-axis theorem): `h' = m p + R h`, `J' = R J Rᵀ + m (p·p 1 − p pᵀ) + 2 (p·Rh) 1 − Rh pᵀ
/// − p (Rh)ᵀ`; added to `(hp, jp)` with [`snapped_sum`].
pub(super) fn transfer_into(
    rot: &Mat3,
    p: &Vec3,
    m: f64,
    h: &Vec3,
    j: &Mat3,
    hp: &mut Vec3,
    jp: &mut Mat3,
) {
    let rh = snapped_mat_vec(rot, h);
    let rj = snapped_mat_mul(rot, &snapped_mat_mul(j, &transpose(rot)));
    for r in 0..3 {
        for s in r..3 {
            let mut terms = vec![
                jp[r][s],
                rj[r][s],
                -m * p[r] * p[s],
                -rh[r] * p[s],
                -p[r] * rh[s],
            ];
            if r == s {
                for k in 0..3 {
                    terms.push(m * p[k] * p[k]);
                    terms.push(2.0 * p[k] * rh[k]);
                }
            }
            jp[r][s] = snapped_sum(&terms);
            jp[s][r] = jp[r][s];
        }
        hp[r] = snapped_sum(&[hp[r], m * p[r], rh[r]]);
    }
}

/// A rotation `Q` with `Q e_z = a` (exact for ±coordinate axes).
pub(super) fn frame_with_z_along(a: &Vec3) -> Mat3 {
    let [x, y, z] = *a;
    // Columns are the new x, y, z axes.
    let cols: [Vec3; 3] = if *a == [0.0, 0.0, 1.0] {
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    } else if *a == [0.0, 0.0, -1.0] {
        [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
    } else if *a == [1.0, 0.0, 0.0] {
        [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    } else if *a == [-1.0, 0.0, 0.0] {
        [[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]]
    } else if *a == [0.0, 1.0, 0.0] {
        [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    } else if *a == [0.0, -1.0, 0.0] {
        [[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]
    } else {
        // A unit vector orthogonal to a, then the third by the cross product.
        let u = if x.abs() <= y.abs() && x.abs() <= z.abs() {
            let n = (y * y + z * z).sqrt();
            [0.0, z / n, -y / n]
        } else if y.abs() <= z.abs() {
            let n = (x * x + z * z).sqrt();
            [-z / n, 0.0, x / n]
        } else {
            let n = (x * x + y * y).sqrt();
            [y / n, -x / n, 0.0]
        };
        let v = [
            y * u[2] - z * u[1],
            z * u[0] - x * u[2],
            x * u[1] - y * u[0],
        ];
        [u, v, *a]
    };
    // Matrix with those columns.
    [
        [cols[0][0], cols[1][0], cols[2][0]],
        [cols[0][1], cols[1][1], cols[2][1]],
        [cols[0][2], cols[1][2], cols[2][2]],
    ]
}
