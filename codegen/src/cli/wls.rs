//! Weighted least squares for identification (docs/identification.md, "Weighted least
//! squares"), after Gautier: an ordinary least-squares pass, the noise of each joint estimated
//! from its residual, then the rows of joint `j` weighted by `1/σ_j` and solved again. The
//! solve is an SVD of the column-scaled stacked regressor (directions below
//! [`NULL`] of the largest singular value are left out, and the parameters they involve
//! reported); the covariance of the estimate is `σ_w² (W_wᵀ W_w)⁻¹` with `σ_w²` the weighted
//! residual's variance (close to 1 when the weights are right).

use nalgebra::{DMatrix, DVector};

/// A scaled singular value below this fraction of the largest is a null direction.
pub const NULL: f64 = 1e-10;
/// Stacked rows beyond which the SVD is taken of the triangular factor of a QR decomposition
/// (faster, a little less accurate on ill-conditioned data; below, the results are those of
/// the SVD of the whole matrix, as in docs/identification.md's tables).
const QR_ROWS: usize = 20_000;
/// A parameter whose component in a null direction exceeds this is not identifiable.
const INVOLVED: f64 = 0.1;

/// The stacked problem: `rows` of `p` entries, row `r` belongs to joint `r % n`.
pub struct Stacked {
    /// `N·n × p`, sample-major.
    pub w: DMatrix<f64>,
    /// The measured efforts, same rows.
    pub tau: DVector<f64>,
    /// Joints.
    pub n: usize,
}

/// The result of a fit.
#[derive(Clone, Debug)]
pub struct Fit {
    /// The estimate.
    pub estimate: Vec<f64>,
    /// Standard deviation of each entry.
    pub std: Vec<f64>,
    /// Condition number `σ_max/σ_min` of the (weighted) stacked regressor, unscaled.
    pub condition: f64,
    /// Per joint: the noise `σ_j` estimated from the ordinary pass (the weights' inverse).
    pub sigma: Vec<f64>,
    /// Per joint: RMS of the final residual (unweighted, in the efforts' units).
    pub residual_rms: Vec<f64>,
    /// Per parameter: whether it lies in a null direction of the data.
    pub unidentifiable: Vec<bool>,
}

/// Least squares of `w x ≈ tau` by an SVD of the column-scaled matrix; `(x, covariance factor
/// (WᵀW)⁻¹ over the kept directions, flags of parameters in null directions)`.
fn solve(w: &DMatrix<f64>, tau: &DVector<f64>) -> (DVector<f64>, DMatrix<f64>, Vec<bool>) {
    let p = w.ncols();
    let scale: Vec<f64> = (0..p)
        .map(|k| {
            let n = w.column(k).norm();
            if n > 0.0 { 1.0 / n } else { 1.0 }
        })
        .collect();
    if w.is_empty() || !finite(w) || !tau.iter().all(|v| v.is_finite()) {
        // No data, or data the SVD cannot take (it does not return on NaN).
        return (DVector::zeros(p), DMatrix::zeros(p, p), vec![true; p]);
    }
    let mut ws = w.clone();
    for (k, s) in scale.iter().enumerate() {
        ws.column_mut(k).scale_mut(*s);
    }
    // A matrix of more than [`QR_ROWS`] rows is reduced to its triangular factor `R` of
    // `ws = Q R` first: the same singular values, right singular vectors and least-squares
    // solution, at a fraction of the cost of an SVD of `ws` itself (a 50 MB file has 600,000
    // rows: 27 s → 10 s).
    let qr = (ws.nrows() > QR_ROWS.max(p)).then(|| ws.clone().qr());
    let project = |b: &DVector<f64>| -> DVector<f64> {
        match &qr {
            Some(qr) => {
                let mut b = b.clone();
                qr.q_tr_mul(&mut b);
                b.rows(0, p).into_owned()
            }
            None => b.clone(),
        }
    };
    let svd = match &qr {
        Some(qr) => qr.r(),
        None => ws.clone(),
    }
    .svd(true, true);
    let (Some(u), Some(vt)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
        return (DVector::zeros(p), DMatrix::zeros(p, p), vec![true; p]);
    };
    let sv = &svd.singular_values;
    let smax = sv.iter().copied().fold(0.0, f64::max);
    let kept: Vec<usize> = (0..sv.len()).filter(|&i| sv[i] > NULL * smax).collect();
    let apply = |b: &DVector<f64>| -> DVector<f64> {
        let utb = u.transpose() * project(b);
        let mut x = DVector::zeros(p);
        for &i in &kept {
            x += vt.row(i).transpose() * (utb[i] / sv[i]);
        }
        x
    };
    let mut x = apply(tau);
    if qr.is_some() {
        // One step of iterative refinement on the residual: noise-free data (a residual of
        // rounding) are solved about as accurately as by the SVD of the whole matrix.
        let r = tau - &ws * &x;
        x += apply(&r);
    }
    let mut cov = DMatrix::zeros(p, p);
    let mut null = vec![false; p];
    for i in 0..sv.len() {
        let v = vt.row(i).transpose();
        if kept.contains(&i) {
            cov += &v * v.transpose() / (sv[i] * sv[i]);
        } else {
            for k in 0..p {
                null[k] |= v[k].abs() > INVOLVED;
            }
        }
    }
    for k in 0..p {
        x[k] *= scale[k];
        for l in 0..p {
            cov[(k, l)] *= scale[k] * scale[l];
        }
    }
    (x, cov, null)
}

/// Residual `tau − w x`.
fn residual(s: &Stacked, x: &DVector<f64>) -> DVector<f64> {
    &s.tau - &s.w * x
}

/// Whether every entry of `w` is finite.
fn finite(w: &DMatrix<f64>) -> bool {
    w.iter().all(|v| v.is_finite())
}

/// Condition number of `w` (no scaling); infinite for a rank-deficient, empty or non-finite
/// `w`.
pub fn condition(w: &DMatrix<f64>) -> f64 {
    if w.is_empty() || !finite(w) {
        return f64::INFINITY;
    }
    // The triangular factor of a tall `w` has its singular values, at a fraction of the cost.
    let sv = if w.nrows() > QR_ROWS.max(w.ncols()) {
        w.clone().qr().r().singular_values()
    } else {
        w.clone().singular_values()
    };
    let max = sv.iter().copied().fold(0.0, f64::max);
    let min = sv.iter().copied().fold(f64::INFINITY, f64::min);
    if min > 0.0 { max / min } else { f64::INFINITY }
}

/// Fit, weighted by the joints' noise (`weighted`) or not.
pub fn fit(s: &Stacked, weighted: bool) -> Fit {
    let (m, p, n) = (s.w.nrows(), s.w.ncols(), s.n.max(1));
    let samples = m / n;
    let (x0, _, _) = solve(&s.w, &s.tau);
    let r0 = residual(s, &x0);
    // σ_j² = ‖ρ_j‖² / (N − c_j), c_j the columns that joint j's rows touch.
    let mut sigma: Vec<f64> = (0..n)
        .map(|j| {
            let ss: f64 = (j..m).step_by(n).map(|r| r0[r] * r0[r]).sum();
            let cj = (0..p)
                .filter(|&k| (j..m).step_by(n).any(|r| s.w[(r, k)] != 0.0))
                .count();
            (ss / (samples.saturating_sub(cj).max(1)) as f64).sqrt()
        })
        .collect();
    let largest = sigma.iter().copied().fold(0.0, f64::max);
    let weighted = weighted && largest > 0.0;
    if weighted {
        for (j, sj) in sigma.iter_mut().enumerate() {
            let rms_tau = ((j..m).step_by(n).map(|r| s.tau[r] * s.tau[r]).sum::<f64>()
                / samples.max(1) as f64)
                .sqrt();
            *sj = sj.max(1e-9 * largest).max(1e-15 * rms_tau);
        }
    }
    let row_weight = |r: usize| if weighted { 1.0 / sigma[r % n] } else { 1.0 };
    let mut ww = s.w.clone();
    let mut tw = s.tau.clone();
    for r in 0..m {
        let f = row_weight(r);
        ww.row_mut(r).scale_mut(f);
        tw[r] *= f;
    }
    let (x, cov, unidentifiable) = solve(&ww, &tw);
    let rw = &tw - &ww * &x;
    let dof = m.saturating_sub(p).max(1) as f64;
    let var = rw.norm_squared() / dof;
    let r = residual(s, &x);
    let residual_rms = (0..n)
        .map(|j| {
            ((j..m).step_by(n).map(|k| r[k] * r[k]).sum::<f64>() / samples.max(1) as f64).sqrt()
        })
        .collect();
    Fit {
        estimate: x.iter().copied().collect(),
        std: (0..p)
            .map(|k| (var * cov[(k, k)]).max(0.0).sqrt())
            .collect(),
        condition: condition(&ww),
        sigma: if weighted { sigma } else { vec![1.0; n] },
        residual_rms,
        unidentifiable,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_data_are_recovered_and_a_missing_direction_is_flagged() {
        // Two joints, three parameters; row = [1, t, t²] on joint 0 and [t, 0, 1] on joint 1.
        let truth = [1.5, -0.25, 3.0];
        let mut rows = Vec::new();
        for k in 0..20 {
            let t = k as f64 * 0.1;
            rows.push(vec![1.0, t, t * t]);
            rows.push(vec![t, 0.0, 1.0]);
        }
        let w = DMatrix::from_fn(rows.len(), 3, |r, c| rows[r][c]);
        let tau = &w * DVector::from_column_slice(&truth);
        let f = fit(&Stacked { w, tau, n: 2 }, true);
        for (a, b) in f.estimate.iter().zip(truth) {
            assert!((a - b).abs() < 1e-12, "{a} {b}");
        }
        assert!(f.unidentifiable.iter().all(|u| !u));
        // A duplicated column: both parameters are flagged.
        let w = DMatrix::from_fn(40, 2, |r, _| (r as f64).sin());
        let tau = DVector::from_fn(40, |r, _| (r as f64).sin());
        let f = fit(&Stacked { w, tau, n: 2 }, false);
        assert_eq!(f.unidentifiable, vec![true, true]);
    }
}
