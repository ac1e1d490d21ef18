// Template: `retract` of a platform module whose `x ⊕ du` is a sum: a position that only
// translates (a planar point, a translational platform) or a planar pose `[px, py, φ]`.
// Compiled and tested as a module by `tests/tests/templates.rs`.

/// `x` moved by `du`, a sum (displacements in m; a planar pose's `δφ` in rad).
#[allow(clippy::all)]
fn retract(x: &[f64; NX], du: &[f64; DOF]) -> [f64; NX] {
    let mut out = *x;
    for i in 0..NX {
        out[i] += du[i];
    }
    out
}
