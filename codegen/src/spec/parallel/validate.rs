//! The checks on the assembled model: the axes of an orientation platform's revolute ends
//! through the centre, then the runtime's own checks ([`ParallelModel::validate`], leg by leg and
//! whole, and [`Plan::new`]'s rank check at home), each message placed at its leg.
//!
//! [`Plan::new`]: runtime::parallel::Plan::new

use runtime::model::{Transform, mat_vec};
use runtime::parallel::{GEOMETRY_TOLERANCE, LegEnd, ParallelModel, PlatformMotion};

use super::legs::{SUPPORTED_HEAVE_TILT_HINT, SUPPORTED_HINT, SUPPORTED_PLANAR_POSE_HINT, Tree};
use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom;
use crate::spec::ir::{Coordinates, PlatformSpec, Spec};

/// Revolute ends: the axis must pass through the centre on both sides (the runtime compares
/// only the directions). Same tolerance as the runtime's geometric checks.
pub(super) fn check_orientation_axes(tree: &Tree<'_>, pm: &ParallelModel, diags: &mut Diagnostics) {
    let tol = GEOMETRY_TOLERANCE * pm.size();
    if let PlatformMotion::Orientation { centre } = pm.motion {
        for (leg, &c) in pm.legs.iter().zip(tree.closing) {
            let j = &tree.spec.joints[c];
            let LegEnd::Revolute {
                on_leg,
                on_platform,
            } = leg.end
            else {
                continue;
            };
            let co = j.child_origin.unwrap_or(Transform::IDENTITY).translation;
            if geom::norm(&geom::cross(&co, &on_platform)) > tol {
                diags.push(
                    Diagnostic::error(format!(
                        "the axis of joint \"{}\" does not pass through the platform frame's origin (the centre of rotation)",
                        j.name
                    ))
                    .with_key(format!("{}.child_origin", j.key))
                    .with_span(j.child_origin_span.clone().or(j.span.clone()))
                    .with_hint("in an orientation mechanism every joint axis passes through the centre: put child_origin.xyz on the axis (e.g. at [0, 0, 0])"),
                );
            }
            let tip = runtime::parallel::leg_home_poses(leg)
                .last()
                .copied()
                .unwrap_or(Transform::IDENTITY);
            let p = tip.apply(&tree.frame_in_tip(c).translation);
            let e = mat_vec(&tip.rotation, &on_leg);
            let d = [centre[0] - p[0], centre[1] - p[1], centre[2] - p[2]];
            if geom::norm(&geom::cross(&d, &e)) > tol {
                diags.push(
                    Diagnostic::error(format!(
                        "the axis of joint \"{}\" does not pass through the centre of rotation at home",
                        j.name
                    ))
                    .with_key(j.key.clone())
                    .with_span(j.span.clone())
                    .with_hint("in an orientation mechanism every joint axis passes through the centre: place the joint's origin on a line through platform.centre along its axis"),
                );
            }
        }
    }
}

/// The runtime's own checks (leg geometry, loop closure at home), leg by leg so that every
/// leg's problem is reported, then once for the whole model; then the full rank of the
/// constraint Jacobian at home.
pub(super) fn runtime_checks(
    spec: &Spec,
    ps: &PlatformSpec,
    closing: &[usize],
    pm: &ParallelModel,
    diags: &mut Diagnostics,
) {
    let mut messages: Vec<String> = Vec::new();
    for leg in &pm.legs {
        let one = ParallelModel {
            legs: vec![leg.clone(); pm.dof()],
            ..pm.clone()
        };
        if let Err(e) = one.validate() {
            messages.push(e);
        }
    }
    if messages.is_empty()
        && let Err(e) = pm.validate()
    {
        messages.push(e);
    }
    // Full rank of the constraint Jacobian at home: `Plan::new` evaluates the legs and the
    // actuation matrix there.
    if messages.is_empty()
        && let Err(e) = runtime::parallel::Plan::new(pm)
    {
        messages.push(e);
    }
    for msg in messages {
        diags.push(validate_diagnostic(spec, ps, closing, msg));
    }
}

/// A [`ParallelModel::validate`] message as a diagnostic: at the leg's joint into the platform
/// when it names a leg (`"leg <name>…"`), else at the `[platform]` table.
fn validate_diagnostic(
    spec: &Spec,
    ps: &PlatformSpec,
    closing: &[usize],
    msg: String,
) -> Diagnostic {
    let leg = closing.iter().map(|&c| &spec.joints[c]).find(|j| {
        msg.strip_prefix("leg ")
            .and_then(|r| r.strip_prefix(j.name.as_str()))
            .is_some_and(|r| r.starts_with(':') || r.starts_with(' '))
    });
    let hint = if msg.contains("does not close") {
        "at home every leg joint is at zero: place the leg's joint frames (`origin`) so that the joint on the leg meets `child_origin` on the platform at platform.home"
    } else if ps.coordinates == Some(Coordinates::PlanarPose) {
        SUPPORTED_PLANAR_POSE_HINT
    } else if ps.coordinates == Some(Coordinates::HeaveTilt) {
        SUPPORTED_HEAVE_TILT_HINT
    } else {
        SUPPORTED_HINT
    };
    let d = Diagnostic::error(msg).with_hint(hint);
    match leg {
        Some(j) => d.with_key(j.key.clone()).with_span(j.span.clone()),
        None => d.with_key("platform").with_span(ps.span.clone()),
    }
}
