//! Step 1: the spanning tree's kinematics at `x` ([`Kin`]: body rotations and origins, joint
//! axes and points, base frame), and the points and directions fixed in its bodies.

use alloc::vec::Vec;

use super::plan::Plan;
use crate::algebra::{M, V, add, cm, cv, ident, mm, mv, rot, scale, zero3};
use crate::model::{JointKind, Vec3};
use crate::scalar::Real;

/// Tree kinematics at `x` (base frame).
#[derive(Clone, Debug)]
pub struct Kin<R> {
    /// Body rotations (body → base).
    pub rot: Vec<M<R>>,
    /// Body origins.
    pub pos: Vec<V<R>>,
    /// Joint axes.
    pub e: Vec<V<R>>,
    /// Joint points (the joint frame's origin before a prismatic displacement).
    pub o: Vec<V<R>>,
}

/// Body poses, joint axes and points at `x`.
pub fn kinematics<R: Real>(plan: &Plan, x: &[R]) -> Kin<R> {
    let n = plan.nx();
    let mut k = Kin {
        rot: Vec::with_capacity(n),
        pos: Vec::with_capacity(n),
        e: Vec::with_capacity(n),
        o: Vec::with_capacity(n),
    };
    for (i, j) in plan.joints.iter().enumerate() {
        let (rp, pp) = match j.parent {
            Some(p) => (k.rot[p], k.pos[p]),
            None => (ident::<R>(), zero3::<R>()),
        };
        let r0 = mm(&rp, &cm(&j.origin.rotation));
        let o = add(pp, mv(&rp, cv(&j.origin.translation)));
        let e = mv(&r0, cv(&j.axis));
        // The displacement from the joint's frame at home.
        let xi = if j.home == 0.0 {
            x[i]
        } else {
            x[i] - R::c(j.home)
        };
        let (r, p) = match j.kind {
            JointKind::Revolute => {
                let (s, c) = xi.sin_cos();
                (mm(&r0, &rot(&j.axis, s, c)), o)
            }
            JointKind::Prismatic => (r0, add(o, scale(xi, e))),
        };
        k.rot.push(r);
        k.pos.push(p);
        k.e.push(e);
        k.o.push(o);
    }
    k
}

pub(super) fn point_of<R: Real>(k: &Kin<R>, body: Option<usize>, local: &Vec3) -> V<R> {
    match body {
        Some(b) => add(k.pos[b], mv(&k.rot[b], cv(local))),
        None => cv(local),
    }
}

pub(super) fn dir_of<R: Real>(k: &Kin<R>, body: Option<usize>, local: &Vec3) -> V<R> {
    match body {
        Some(b) => mv(&k.rot[b], cv(local)),
        None => cv(local),
    }
}
