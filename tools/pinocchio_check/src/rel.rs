//! The harnesses' error measure, shared by the three programs of `tools/pinocchio_check`
//! (this crate, `sweep/` and `gough_stewart/`, each its own workspace, include this file).

/// Worst relative error of `a` against `b`: the largest absolute difference over the largest
/// `|b|` (∞-norms).
pub fn rel(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}
