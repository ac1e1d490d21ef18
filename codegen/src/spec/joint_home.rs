//! `home` on a joint: its coordinate at home, so that the generated functions take and return
//! absolute coordinates (a leg length of 0.866 m, a motor angle from the horizontal) rather than
//! displacements from home (docs/spec.md, "Coordinates at home").
//!
//! - In a tree the joint's motion at coordinate `q` is its motion at `q − home` before: the
//!   joint frame is turned by `−home` about its axis (revolute) or moved by `−home` along it
//!   (prismatic), or DH's `theta` / `d` take `−home`. Nothing else in a tree refers to home.
//! - In a parallel mechanism the actuated joints' `home` is added to what
//!   `inverse_kinematics` returns and expected by `forward_kinematics`
//!   (`runtime::parallel::Leg::actuated_home`, set by the lowering); the legs' other joints are
//!   internal to the module, and their `home` changes nothing.
//! - In closed loops in joint coordinates the frames stay as written (the spec's home closes
//!   the loops); the tree joints' homes are `runtime::closed::ClosedModel::home`, which the
//!   evaluator subtracts before it turns a joint (generated and runtime alike) and `HOME`
//!   holds. A loop-closing joint has no coordinate: `home` is an error there.

use super::closed;
use super::geom::{compose, rotation, trans};
use super::ir::{Kind, Placement, Spec};
use crate::diag::{Diagnostic, Diagnostics};

/// Applies the trees' `home` values to the joint frames (closed loops keep theirs for the
/// lowering; a loop-closing joint's is an error).
pub(crate) fn apply(mut spec: Spec, diags: &mut Diagnostics) -> Spec {
    if spec.platform.is_some() {
        return spec;
    }
    let loops = closed::is_closed(&spec);
    for j in &mut spec.joints {
        let h = j.home;
        if h == 0.0 {
            continue;
        }
        if loops {
            // The loop-closing joints have no coordinate; the tree joints' homes go to
            // `ClosedModel::home` (spec/closed.rs), the frames staying where the spec closes
            // the loops.
            if j.child_origin.is_some() {
                diags.push(
                    Diagnostic::error(format!(
                        "joint \"{}\" closes a loop, and has no coordinate to give at home",
                        j.name
                    ))
                    .with_key(format!("{}.home", j.key))
                    .with_span(j.home_span.clone().or(j.span.clone()))
                    .with_hint("the loop-closing joint's angle follows from the tree joints: remove `home` here"),
                );
            }
            continue;
        }
        let axis = j.axes.first().map_or([0.0, 0.0, 1.0], |a| {
            let n = (a.v[0] * a.v[0] + a.v[1] * a.v[1] + a.v[2] * a.v[2]).sqrt();
            if n > 0.0 {
                [a.v[0] / n, a.v[1] / n, a.v[2] / n]
            } else {
                [0.0, 0.0, 1.0]
            }
        });
        match (&mut j.placement, j.kind) {
            (Placement::Origin(t), Kind::Revolute) => {
                let turn = runtime::model::Transform {
                    rotation: rotation(&axis, -h),
                    translation: [0.0; 3],
                };
                *t = compose(t, &turn);
            }
            (Placement::Origin(t), Kind::Prismatic) => {
                *t = compose(t, &trans([-h * axis[0], -h * axis[1], -h * axis[2]]));
            }
            (Placement::Dh(d) | Placement::Mdh(d), Kind::Revolute) => d.theta -= h,
            (Placement::Dh(d) | Placement::Mdh(d), Kind::Prismatic) => d.d -= h,
            _ => {}
        }
    }
    spec
}
