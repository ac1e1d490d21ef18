//! Helpers of the regressor tests (trees, platforms, closed loops): Khalil's standard
//! parameters written from the parallel-axis theorem, and a numerical rank by an SVD.

use nalgebra::DMatrix;
use runtime::model::{Mat3, Vec3};

/// Khalil's ten standard parameters `XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M` of a body (inertia
/// about the body-frame origin) of mass `mass`, mass centre `c` and central inertia `ic`.
pub fn standard(mass: f64, c: &Vec3, ic: &Mat3) -> [f64; 10] {
    let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let j = |r: usize, k: usize| ic[r][k] + mass * (if r == k { cc } else { 0.0 } - c[r] * c[k]);
    [
        j(0, 0),
        j(0, 1),
        j(0, 2),
        j(1, 1),
        j(1, 2),
        j(2, 2),
        mass * c[0],
        mass * c[1],
        mass * c[2],
        mass,
    ]
}

/// Numerical rank of the columns (each scaled to unit norm; columns below `1e-10` of the
/// largest norm are zero) by an SVD, relative tolerance `1e-8`.
pub fn rank(cols: &[Vec<f64>]) -> usize {
    let largest = cols
        .iter()
        .map(|c| c.iter().map(|x| x * x).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    let kept: Vec<Vec<f64>> = cols
        .iter()
        .filter_map(|c| {
            let nrm = c.iter().map(|x| x * x).sum::<f64>().sqrt();
            (nrm > 1e-10 * largest).then(|| c.iter().map(|x| x / nrm).collect())
        })
        .collect();
    if kept.is_empty() {
        return 0;
    }
    let rows = kept[0].len();
    let a = DMatrix::from_fn(rows, kept.len(), |i, j| kept[j][i]);
    let sv = a.svd(false, false).singular_values;
    let max = sv.iter().copied().fold(0.0, f64::max);
    sv.iter().filter(|&&s| s > 1e-8 * max).count()
}

/// [`rank`] of a matrix's columns.
pub fn rank_of(a: &DMatrix<f64>) -> usize {
    let cols: Vec<Vec<f64>> = a
        .column_iter()
        .map(|c| c.iter().copied().collect())
        .collect();
    rank(&cols)
}

/// The worst `‖Y π − τ‖∞ / ‖τ‖∞` over `states` states, `draw` giving each state's efforts `τ`
/// and regressor `Y` (rows of `K` entries).
pub fn worst_linear_form_error<const K: usize>(
    pi: &[f64; K],
    states: usize,
    mut draw: impl FnMut() -> (Vec<f64>, Vec<[f64; K]>),
) -> f64 {
    let mut worst = 0.0f64;
    for _ in 0..states {
        let (tau, y) = draw();
        let yp: Vec<f64> = y
            .iter()
            .map(|row| row.iter().zip(pi).map(|(a, b)| a * b).sum())
            .collect();
        worst = worst.max(crate::pkm::rel(&yp, &tau));
    }
    worst
}

/// The ranks of the standard regressor stacked over `states` states, of the generated one, and
/// of both side by side: `draw` gives each state's `n × ncols` standard block and `n × nbp`
/// generated block.
pub fn stacked_ranks(
    states: usize,
    (n, ncols, nbp): (usize, usize, usize),
    mut draw: impl FnMut() -> (DMatrix<f64>, DMatrix<f64>),
) -> (usize, usize, usize) {
    let mut std_rows = DMatrix::zeros(states * n, ncols);
    let mut gen_rows = DMatrix::zeros(states * n, nbp);
    for s in 0..states {
        let (a, b) = draw();
        std_rows.view_mut((s * n, 0), (n, ncols)).copy_from(&a);
        gen_rows.view_mut((s * n, 0), (n, nbp)).copy_from(&b);
    }
    let both = DMatrix::from_fn(states * n, ncols + nbp, |i, k| {
        if k < ncols {
            std_rows[(i, k)]
        } else {
            gen_rows[(i, k - ncols)]
        }
    });
    (rank_of(&std_rows), rank_of(&gen_rows), rank_of(&both))
}
