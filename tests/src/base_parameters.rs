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
