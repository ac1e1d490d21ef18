//! The joint-level checks before the tree is built: the joints into the platform (which close
//! the legs), `actuated` on the other joints, `child_origin` only into the platform, one meeting
//! point for a planar platform, and at least one joint into the platform.

use std::collections::HashMap;

use runtime::model::Transform;

use super::mobility::apart;
use super::platform::OnPlatform;
use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom;
use crate::spec::ir::{BASE, Coordinates, JointSpec, Kind, Placement, PlatformSpec, Spec};

/// Every joint: a joint into the platform (`closing`) is checked as one and left out of the
/// tree checks; any other may be actuated only if revolute or prismatic, and has no
/// `child_origin`.
pub(super) fn check_joints(
    spec: &Spec,
    ps: &PlatformSpec,
    pname: &str,
    closing: &[bool],
    body_index: &HashMap<&str, usize>,
    on: &mut OnPlatform,
    diags: &mut Diagnostics,
) {
    let motion = ps.coordinates;
    for (ji, j) in spec.joints.iter().enumerate() {
        if closing[ji] {
            on.skip.joint[ji] = true;
            check_closing_joint(j, ps, motion, body_index, &on.pose, diags);
        } else {
            check_actuated_kind(j, diags);
            if j.child_origin.is_some() {
                diags.push(
                    Diagnostic::error(format!(
                        "`child_origin` is only for joints into the platform, but the child of joint \"{}\" is \"{}\"",
                        j.name, j.child
                    ))
                    .with_key(format!("{}.child_origin", j.key))
                    .with_span(j.child_origin_span.clone().or(j.span.clone()))
                    .with_hint(format!(
                        "child_origin gives the joint frame in the platform frame for joints with child = \"{pname}\"; elsewhere the child's frame is the joint frame: remove it"
                    )),
                );
            }
        }
    }
}

/// A planar platform is a point: every joint into it meets it there.
pub(super) fn check_planar_point(
    spec: &Spec,
    ps: &PlatformSpec,
    pname: &str,
    diags: &mut Diagnostics,
) {
    if ps.coordinates == Some(Coordinates::Planar)
        && let Some([(first, p), (j, q)]) = apart(spec, ps)
    {
        let v = |p: [f64; 3]| {
            format!(
                "[{}, {}, {}]",
                geom::num(p[0]),
                geom::num(p[1]),
                geom::num(p[2])
            )
        };
        diags.push(
            Diagnostic::error(format!(
                "joints \"{}\" and \"{}\" meet the planar platform \"{pname}\" at different points ({} and {} in its frame)",
                first.name,
                j.name,
                v(p),
                v(q)
            ))
            .with_key(format!("{}.child_origin", j.key))
            .with_span(j.child_origin_span.clone().or(j.span.clone()))
            .with_hint("with coordinates = \"planar\" the platform is the point where the legs meet (a five-bar's tool point; its rotation is not modelled): give every joint into it the same child_origin. A linkage closed at different points of a link is a closed loop in joint coordinates: leave out [platform] and keep child_origin on the loop-closing joints"),
        );
    }
}

/// At least one joint ends at the platform.
pub(super) fn check_has_closing(
    ps: &PlatformSpec,
    pname: &str,
    closing: &[bool],
    diags: &mut Diagnostics,
) {
    if !closing.iter().any(|c| *c) {
        diags.push(
            Diagnostic::error(format!("no joint ends at the platform \"{pname}\""))
                .with_key("platform.body")
                .with_span(ps.body_span.clone())
                .with_hint(format!(
                    "each leg ends in a joint with child = \"{pname}\" and a `child_origin` (its frame in the platform frame)"
                )),
        );
    }
}

/// `actuated` only on revolute and prismatic joints.
pub(super) fn check_actuated_kind(j: &JointSpec, diags: &mut Diagnostics) {
    if j.actuated && !matches!(j.kind, Kind::Revolute | Kind::Prismatic) {
        let hint = match j.kind {
            Kind::Universal => {
                "only revolute and prismatic joints can be actuated; to drive one axis of a universal joint, write it as two revolute joints with a massless body between them"
            }
            _ => "only revolute and prismatic joints can be actuated",
        };
        diags.push(
            Diagnostic::error(format!("a {} joint cannot be actuated", j.kind.word()))
                .with_key(format!("{}.actuated", j.key))
                .with_span(j.actuated_span.clone().or(j.span.clone()))
                .with_hint(hint),
        );
    }
}

/// A joint into the platform: the right kind for the coordinates, with `child_origin`, passive,
/// placed with `origin` or `mdh`, and with a parent that is a leg body.
fn check_closing_joint(
    j: &JointSpec,
    ps: &PlatformSpec,
    coords: Option<Coordinates>,
    body_index: &HashMap<&str, usize>,
    on_platform: &[Option<Transform>],
    diags: &mut Diagnostics,
) {
    let pname = ps.body.as_deref().unwrap_or_default();
    if let Some(coords) = coords {
        let (want, word) = match coords {
            Coordinates::Pose => (Kind::Spherical, "pose"),
            Coordinates::Orientation => (Kind::Revolute, "orientation"),
            Coordinates::Planar => (Kind::Revolute, "planar"),
            Coordinates::Translation => (Kind::Spherical, "translation"),
            Coordinates::PlanarPose => (Kind::Revolute, "planar_pose"),
            Coordinates::HeaveTilt => (Kind::Spherical, "heave_tilt"),
            Coordinates::Schoenflies => (Kind::Spherical, "schoenflies"),
        };
        // Tsai's 3-UPU: a universal joint into a translational platform (its cross is massless
        // and, with ω = 0, its angles follow from the leg's; docs/spec.md).
        let upu = coords == Coordinates::Translation && j.kind == Kind::Universal;
        // A Schönflies carrier: the tool's revolute about z ends the shaft's leg.
        let tool = coords == Coordinates::Schoenflies && j.kind == Kind::Revolute;
        if j.kind != want && !upu && !tool {
            diags.push(
                Diagnostic::error(format!(
                    "the platform \"{pname}\" is the child of {} joint \"{}\", but with coordinates = \"{word}\" a joint into the platform must be {}",
                    j.kind.word(),
                    j.name,
                    want.word()
                ))
                .with_key(format!("{}.kind", j.key))
                .with_span(j.kind_span.clone())
                .with_hint("the joints into the platform close the legs' loops: spherical joints for a 6-DOF (pose) or translational platform (a Delta's [[parallelogram]] brings its own; a translational platform also takes universal joints, Tsai's 3-UPU), revolute joints with axes through the centre for an orientation platform; attach bodies rigidly to the platform with fixed joints from the platform instead"),
            );
        }
    }
    if j.child_origin.is_none() {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" into the platform has no `child_origin`",
                j.name
            ))
            .with_key(format!("{}.child_origin", j.key))
            .with_span(j.span.clone())
            .with_hint("add child_origin = { xyz = [..], rpy = [..] }: the joint frame in the platform frame (it closes the loop)"),
        );
    }
    if j.actuated {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" into the platform cannot be actuated",
                j.name
            ))
            .with_key(format!("{}.actuated", j.key))
            .with_span(j.actuated_span.clone().or(j.span.clone()))
            .with_hint("the joint that closes a leg at the platform is passive; actuate a revolute or prismatic joint of the leg"),
        );
    }
    if j.parent == BASE {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" connects the base directly to the platform",
                j.name
            ))
            .with_key(format!("{}.parent", j.key))
            .with_span(j.parent_span.clone())
            .with_hint("a leg is a chain of at least one moving joint from the base to its joint into the platform"),
        );
    } else if body_index
        .get(j.parent.as_str())
        .is_some_and(|&p| on_platform[p].is_some())
    {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" connects the platform to itself",
                j.name
            ))
            .with_key(format!("{}.parent", j.key))
            .with_span(j.parent_span.clone())
            .with_hint("the parent of a joint into the platform is the last body of a leg"),
        );
    }
    if let Placement::Dh(_) = j.placement {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" into the platform is placed with standard `dh`",
                j.name
            ))
            .with_key(format!("{}.dh", j.key))
            .with_span(j.span.clone())
            .with_hint("standard DH would move the platform's frame to the distal DH frame; place the joint with `origin` (or `mdh`) and `child_origin`"),
        );
    }
}
