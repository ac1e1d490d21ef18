// Template: `retract` of a platform module whose coordinates are a position that only
// translates, a planar point or a translational platform (`x ⊕ du` is a sum). Compiled and
// tested as a module by `tests/tests/templates.rs`.

/// `x` moved by `du` (the point's displacement, m).
#[allow(clippy::all)]
fn retract(x: &[f64; NX], du: &[f64; DOF]) -> [f64; NX] {
    let mut out = *x;
    for i in 0..NX {
        out[i] += du[i];
    }
    out
}
