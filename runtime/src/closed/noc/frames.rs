//! The pose of a frame fixed to a body of the spanning tree (`[scene] frames` of a closed-loop
//! module): the tree's kinematics at `x` ([`super::kinematics`]) and the frame's placement.

use super::plan::Plan;
use super::tree::kinematics;
use crate::algebra::{M, V, add, cm, cv, ident, mm, mv, zero3};
use crate::model::Transform;
use crate::scalar::Real;

/// Rotation base ← frame and origin (base frame) of a frame with pose `placement` in tree body
/// `body` (`None`: the base), at the tree joint positions `x`.
pub fn frame_pose<R: Real>(
    plan: &Plan,
    x: &[R],
    body: Option<usize>,
    placement: &Transform,
) -> (M<R>, V<R>) {
    let (rot, pos) = match body {
        Some(b) => {
            let k = kinematics(plan, x);
            (k.rot[b], k.pos[b])
        }
        None => (ident::<R>(), zero3::<R>()),
    };
    (
        mm(&rot, &cm(&placement.rotation)),
        add(pos, mv(&rot, cv(&placement.translation))),
    )
}
