//! A universal joint's `cross` (docs/spec.md, "Joint kinds"): the inertial data of the body
//! `<joint>_cross` that the U joint's expansion adds between its two revolutes, in that body's
//! frame (the joint frame carried by the first rotation). Validated as a `[[body]]` is
//! ([`super::lower::check_values`]), lowered into the cross body ([`super::lower::build`]); a
//! joint that the tree leaves out (one into a parallel mechanism's platform, or one that closes
//! a loop) has no cross body, so a `cross` there is an error.

use super::geom::MassProps;
use super::ir::Spec;
use super::lower::Skip;
use crate::diag::{Diagnostic, Diagnostics};

/// The cross's mass properties of joint `j`, if it has a `cross`.
pub(super) fn props(j: &super::ir::JointSpec) -> Option<MassProps> {
    j.cross.as_ref().map(|c| MassProps {
        mass: c.mass,
        com: c.com,
        inertia: c.inertia,
    })
}

/// A `cross` on a joint that the tree leaves out (`skip`): an error at the key.
pub(super) fn check_skipped(spec: &Spec, skip: &Skip, diags: &mut Diagnostics) {
    for (ji, j) in spec.joints.iter().enumerate() {
        let Some(c) = &j.cross else { continue };
        if !skip.joint[ji] {
            continue;
        }
        let what = if spec.platform.is_some() {
            "meets the platform"
        } else {
            "closes a loop"
        };
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" {what}: its cross has no body in the model, so `cross` cannot be given here",
                j.name
            ))
            .with_key(c.key.clone())
            .with_span(c.span.clone())
            .with_hint("the joint is modelled by its constraint only (no cross body); put the mass on the bodies it joins, or remove `cross`"),
        );
    }
}
