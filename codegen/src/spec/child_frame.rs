//! A tree joint placed from both bodies: `child_origin` on a joint whose child no other joint
//! reaches gives the joint frame in the child body's own frame, as SDF, MJCF and CAD exports
//! place joints (docs/spec.md, "Child-side joint frames"). The rest of the pipeline knows one
//! convention, a body's frame is its joint's frame after the motion, so this pass re-expresses
//! everything written in such a child's frame in its joint frame and drops `child_origin`:
//! the body's mass centre and inertia, the `origin` of the joints it carries, the
//! `child_origin` of loop-closing joints into it, the points of springs on it and the elbow of
//! parallelograms it carries, and a `[scene]` payload on it. The dynamics do not change: the
//! same body is described in another frame. The body's own frame is kept as its
//! `own_frame` (its pose in the joint frame), which `[scene] frames` offers.
//!
//! A `child_origin` whose child another joint also reaches keeps its meaning, a loop-closing
//! joint (`closed.rs`), and parallel mechanisms keep theirs (joints into the platform).

use runtime::model::{Mat3, Transform, Vec3, mat_vec, transpose};

use super::geom::{compose, rotate_inertia};
use super::ir::{Placement, Spec};
use crate::diag::{Diagnostic, Diagnostics};

/// `t⁻¹`.
fn inverse(t: &Transform) -> Transform {
    let r: Mat3 = transpose(&t.rotation);
    let p = mat_vec(&r, &t.translation);
    Transform {
        rotation: r,
        translation: [-p[0], -p[1], -p[2]],
    }
}

fn point(t: &Transform, p: &Vec3) -> Vec3 {
    let q = mat_vec(&t.rotation, p);
    [
        q[0] + t.translation[0],
        q[1] + t.translation[1],
        q[2] + t.translation[2],
    ]
}

/// Re-expresses each body placed by a child-side joint frame in that joint frame.
pub(crate) fn apply(mut spec: Spec, diags: &mut Diagnostics) -> Spec {
    // A parallel mechanism's legs keep `child_origin` for the joints into the platform (its
    // reader refuses it elsewhere).
    if spec.platform.is_some() {
        return spec;
    }
    for k in 0..spec.joints.len() {
        let Some(c) = spec.joints[k].child_origin else {
            continue;
        };
        let child = spec.joints[k].child.clone();
        let by = spec.joints[k].name.clone();
        let reached_twice = spec
            .joints
            .iter()
            .enumerate()
            .any(|(m, j)| m != k && j.child == child);
        if reached_twice {
            continue;
        }
        // x_joint = c⁻¹ x_child for every point written in the child's frame.
        let to_joint = inverse(&c);
        let r = to_joint.rotation;
        spec.joints[k].child_origin = None;
        spec.joints[k].child_origin_span = None;
        for b in spec.bodies.iter_mut().filter(|b| b.name == child) {
            b.com = point(&to_joint, &b.com);
            b.inertia = rotate_inertia(&r, &b.inertia);
            // The body's own frame, the one `[scene] frames` names, sits at `c⁻¹` in the
            // joint frame.
            b.own_frame = compose(&to_joint, &b.own_frame);
        }
        for m in 0..spec.joints.len() {
            if spec.joints[m].parent == child {
                let j = &mut spec.joints[m];
                match &mut j.placement {
                    Placement::Origin(t) => *t = compose(&to_joint, t),
                    Placement::Dh(_) | Placement::Mdh(_) => diags.push(
                        Diagnostic::error(format!(
                            "joint \"{}\" is placed by DH parameters on \"{child}\", whose frame joint \"{}\" gives from the child side (`child_origin`)",
                            j.name, by
                        ))
                        .with_key(j.key.clone())
                        .with_span(j.span.clone())
                        .with_hint("DH parameters need the parent's DH frame: place this joint with `origin`, or the joint into its parent without `child_origin`"),
                    ),
                }
            }
            let j = &mut spec.joints[m];
            if m != k
                && j.child == child
                && let Some(t) = &mut j.child_origin
            {
                *t = compose(&to_joint, t);
            }
        }
        for s in &mut spec.springs {
            if s.body_a.name == child {
                s.point_a = point(&to_joint, &s.point_a);
            }
            if s.body_b.name == child {
                s.point_b = point(&to_joint, &s.point_b);
            }
        }
        if let Some(p) = &mut spec.scene.payload
            && p.body.name == child
        {
            p.com = point(&to_joint, &p.com);
            p.inertia = rotate_inertia(&r, &p.inertia);
        }
    }
    spec
}
