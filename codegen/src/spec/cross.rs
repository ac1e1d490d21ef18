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

/// The crosses a spec's model has, as its text gives them (patterns expanded, expressions
/// evaluated): per universal joint whose expansion makes a body `<joint>_cross` (a leg's or a
/// tree's; not a joint into a platform, not a loop-closing one), `(joint name, mass, mass
/// centre, inertia about it)` in the cross's frame, zeros where `cross` is not written. For
/// `codegen identify --out`; `None` when the spec does not load.
pub fn written_crosses(
    file_name: &str,
    source: &str,
) -> Option<Vec<(String, f64, runtime::model::Vec3, runtime::model::Mat3)>> {
    let mut d = Diagnostics::new(file_name, source);
    let spec = super::read_ir(file_name, source, &mut d)?;
    if d.has_errors() {
        return None;
    }
    let (mechanism, _) = super::load_mechanism(file_name, source).ok()?;
    let names: Vec<&str> = match &mechanism {
        super::Mechanism::Tree(m) => m.bodies.iter().map(|b| b.name.as_str()).collect(),
        super::Mechanism::Parallel(p) => p
            .legs
            .iter()
            .flat_map(|l| l.bodies.iter().map(|b| b.name.as_str()))
            .collect(),
        super::Mechanism::Closed(c) => c.tree.bodies.iter().map(|b| b.name.as_str()).collect(),
    };
    Some(
        spec.joints
            .iter()
            .filter(|j| j.kind == super::ir::Kind::Universal)
            .filter(|j| names.contains(&format!("{}_cross", j.name).as_str()))
            .map(|j| match &j.cross {
                Some(c) => (j.name.clone(), c.mass, c.com, c.inertia),
                None => (j.name.clone(), 0.0, [0.0; 3], [[0.0; 3]; 3]),
            })
            .collect(),
    )
}
