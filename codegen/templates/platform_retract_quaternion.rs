// Template: `retract` of a platform module whose coordinates hold a unit quaternion (6-DOF
// pose or 3-DOF orientation): `x ⊕ du`, the rotation vector applied on the left. Stand-ins
// replaced when specialized (`codegen/src/template.rs`): `QUATERNION` (the quaternion's index
// in `x`), `HAS_POSITION` (whether `x` starts with a position), and the math calls `sqrt` and
// `sin_cos`. Compiled and tested as a module by `tests/tests/templates.rs`.

/// `x` moved by the small motion `du` (rotation vector, then translation; base frame).
#[allow(clippy::all)]
fn retract(x: &[f64; NX], du: &[f64; DOF]) -> [f64; NX] {
    let a2 = du[0] * du[0] + du[1] * du[1] + du[2] * du[2];
    let a = sqrt(a2);
    let (s, c) = sin_cos(0.5 * a);
    let k = if a > 0.0 { s / a } else { 0.5 };
    let d = [c, k * du[0], k * du[1], k * du[2]];
    let i = QUATERNION;
    let q = [x[i], x[i + 1], x[i + 2], x[i + 3]];
    let r = [
        d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
        d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
        d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
        d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0],
    ];
    let n = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3];
    let n = sqrt(n);
    let mut out = *x;
    for j in 0..4 {
        out[i + j] = r[j] / n;
    }
    if HAS_POSITION {
        for i in 0..3 {
            out[i] += du[3 + i];
        }
    }
    out
}
