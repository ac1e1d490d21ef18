//! 3-vectors and 3 × 3 matrices over [`Real`] (rows of arrays, no allocation), the rotation
//! of an axis and angle, and one rigid body's Euler moment and inertia quadratic form: the
//! small algebra the parallel and closed-loop evaluators share.

use crate::model::{Mat3, Vec3};
use crate::scalar::Real;

pub(crate) type V<R> = [R; 3];
pub(crate) type M<R> = [[R; 3]; 3];

pub(crate) fn cv<R: Real>(v: &Vec3) -> V<R> {
    [R::c(v[0]), R::c(v[1]), R::c(v[2])]
}
pub(crate) fn cm<R: Real>(m: &Mat3) -> M<R> {
    [cv(&m[0]), cv(&m[1]), cv(&m[2])]
}
pub(crate) fn add<R: Real>(a: V<R>, b: V<R>) -> V<R> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub(crate) fn sub<R: Real>(a: V<R>, b: V<R>) -> V<R> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(crate) fn scale<R: Real>(s: R, a: V<R>) -> V<R> {
    [s * a[0], s * a[1], s * a[2]]
}
pub(crate) fn dot<R: Real>(a: V<R>, b: V<R>) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross<R: Real>(a: V<R>, b: V<R>) -> V<R> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn mv<R: Real>(m: &M<R>, v: V<R>) -> V<R> {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}
pub(crate) fn mtv<R: Real>(m: &M<R>, v: V<R>) -> V<R> {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}
pub(crate) fn mm<R: Real>(a: &M<R>, b: &M<R>) -> M<R> {
    let col = |j: usize| [b[0][j], b[1][j], b[2][j]];
    let (c0, c1, c2) = (col(0), col(1), col(2));
    [
        [dot(a[0], c0), dot(a[0], c1), dot(a[0], c2)],
        [dot(a[1], c0), dot(a[1], c1), dot(a[1], c2)],
        [dot(a[2], c0), dot(a[2], c1), dot(a[2], c2)],
    ]
}
pub(crate) fn zero3<R: Real>() -> V<R> {
    [R::c(0.0); 3]
}
pub(crate) fn ident<R: Real>() -> M<R> {
    let (o, z) = (R::c(1.0), R::c(0.0));
    [[o, z, z], [z, o, z], [z, z, o]]
}

/// Rotation by the angle whose `(sin, cos)` is `(s, c)` about the unit `axis` (Rodrigues:
/// `c·1 + s·[e]× + (1 − c)·e eᵀ`).
pub(crate) fn rot<R: Real>(e: &Vec3, s: R, c: R) -> M<R> {
    let v = R::c(1.0) - c;
    let e_ = cv::<R>(e);
    let mut m = [[R::c(0.0); 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = if i == j {
                // c + (1 − c) e_i² written as e_i² + c (1 − e_i²): exactly 1 on a coordinate
                // axis (and c across it), so constants fold in the generator.
                R::c(e[i] * e[i]) + c * R::c(1.0 - e[i] * e[i])
            } else {
                v * R::c(e[i] * e[j])
            };
        }
    }
    // s·[e]×
    m[0][1] = m[0][1] - s * e_[2];
    m[0][2] = m[0][2] + s * e_[1];
    m[1][0] = m[1][0] + s * e_[2];
    m[1][2] = m[1][2] - s * e_[0];
    m[2][0] = m[2][0] - s * e_[1];
    m[2][1] = m[2][1] + s * e_[0];
    m
}

/// Euler's equation `I ω̇ + ω × I ω` (eq. 12's rotational row) for a body with rotation `rot`
/// and inertia `inertia` (body frame), in the frame `rot` maps to. An isotropic inertia `c·1`
/// needs no rotation: the moment is `c ω̇`.
pub(crate) fn euler<R: Real>(rot: &M<R>, inertia: &Mat3, w: V<R>, wd: V<R>) -> V<R> {
    let c = inertia[0][0];
    let isotropic = inertia[1][1] == c
        && inertia[2][2] == c
        && inertia[0][1] == 0.0
        && inertia[0][2] == 0.0
        && inertia[1][2] == 0.0
        && inertia[1][0] == 0.0
        && inertia[2][0] == 0.0
        && inertia[2][1] == 0.0;
    if isotropic {
        return scale(R::c(c), wd);
    }
    let wb = mtv(rot, w);
    let ab = mtv(rot, wd);
    let ib = cm::<R>(inertia);
    let nb = add(mv(&ib, ab), cross(wb, mv(&ib, wb)));
    mv(rot, nb)
}

/// `aᵀ I b` for a body with rotation `rot` and inertia `inertia` (body frame); `c (a·b)` for an
/// isotropic inertia `c·1`.
pub(crate) fn inertia_quad<R: Real>(rot: &M<R>, inertia: &Mat3, a: V<R>, b: V<R>) -> R {
    let c = inertia[0][0];
    let isotropic = inertia[1][1] == c
        && inertia[2][2] == c
        && [inertia[0][1], inertia[0][2], inertia[1][2]] == [0.0; 3]
        && [inertia[1][0], inertia[2][0], inertia[2][1]] == [0.0; 3];
    if isotropic {
        return R::c(c) * dot(a, b);
    }
    let (ab, bb) = (mtv(rot, a), mtv(rot, b));
    dot(ab, mv(&cm::<R>(inertia), bb))
}
