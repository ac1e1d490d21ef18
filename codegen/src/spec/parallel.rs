//! Lowering of a parallel mechanism (a spec with a `[platform]` table) to a
//! [`ParallelModel`]: the joints into the platform close the loops; everything else is lowered
//! with the tree machinery of [`super::lower`] into a tree hanging from the base, which is then
//! split into legs (one chain from the base to each joint into the platform).
//!
//! Checks, all reported together: the platform table, the joints into the platform (kind,
//! `child_origin`, not actuated), `actuated` (one revolute or prismatic joint per leg), the
//! leg structure (simple chains, no shared or dangling bodies), the leg types the runtime
//! supports, the mobility (Grübler–Kutzbach) and the number of actuators against the platform's
//! DOF, and finally [`ParallelModel::validate`] (leg geometry and loop closure at home).
//!
//! By concept: [`platform`] (the `[platform]` table and the rigid body the platform forms with
//! what is fixed to it), [`joints`] (the joint-level checks before the tree is built),
//! [`mobility`] (the whole-mechanism counts), [`legs`] (splitting the tree into legs and
//! building them) and [`validate`] (the checks on the assembled model). [`lower_checked`] runs
//! them in order.

use std::collections::HashMap;

use runtime::model::Transform;
use runtime::parallel::ParallelModel;

use super::geom::compose;
use super::ir::{Kind, PlatformSpec, Spec};
use super::lower;
use crate::diag::Diagnostics;

mod joints;
mod legs;
mod mobility;
mod platform;
mod screws;
mod validate;

use joints::{check_actuated_kind, check_has_closing, check_joints, check_planar_point};
use legs::{Tree, build_legs, split_legs};
use mobility::check_mobility;
use platform::{assemble, check_platform, on_platform};
use screws::check_declared_motion;
use validate::{
    check_orientation_axes, check_upu_axes, check_upu_legs, close_at_home, rank_check,
    runtime_checks,
};

/// Validates a spec with a `[platform]` table and builds the parallel model. Errors and
/// warnings go to `diags`; `None` when there was any error.
pub(crate) fn lower_parallel(spec: &Spec, diags: &mut Diagnostics) -> Option<ParallelModel> {
    let ps = spec.platform.as_ref()?;
    // The whole-mechanism counts are reported beside everything else, but they must not stop
    // the leg-by-leg checks (which stop at the first stage with errors); with a wrong count the
    // runtime's own validation would only repeat it.
    let mut global = Diagnostics::new(diags.file_name(), diags.source());
    // Joints or a pattern's copies that could not be read (already reported) would only make
    // the counts wrong.
    if !spec.joints_incomplete {
        check_mobility(spec, ps, &mut global);
    }
    let model = lower_checked(spec, ps, diags, !global.has_errors());
    diags.extend(global);
    model.filter(|_| !diags.has_errors())
}

/// The leg-by-leg checks and the lowering, in stages: the platform and the joints, the tree
/// (topology and build), the legs, the assembled model, and (when `run_validate`) the
/// runtime's own checks. Each stage runs only when the ones before it found no error.
fn lower_checked(
    spec: &Spec,
    ps: &PlatformSpec,
    diags: &mut Diagnostics,
    run_validate: bool,
) -> Option<ParallelModel> {
    let axes = lower::check_values(spec, diags);

    // Body names → first index (duplicates are reported by the topology check).
    let mut body_index: HashMap<&str, usize> = HashMap::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        body_index.entry(b.name.as_str()).or_insert(i);
    }

    let platform = check_platform(spec, ps, &body_index, diags);
    let motion = ps.coordinates;

    let Some(pb) = platform else {
        // Without a platform nothing else can be told apart from a tree; report the joint-level
        // mistakes that do not depend on it.
        for j in &spec.joints {
            check_actuated_kind(j, diags);
        }
        return None;
    };
    let pname = spec.bodies[pb].name.as_str();

    // The joints into the platform close the loops; the platform and what is fixed to it
    // (a tool, a payload) form one rigid body.
    let closing: Vec<bool> = spec.joints.iter().map(|j| j.child == pname).collect();
    let mut on = on_platform(spec, pb, &body_index, &closing, diags);
    check_joints(spec, ps, pname, &closing, &body_index, &mut on, diags);
    check_planar_point(spec, ps, pname, diags);
    if !spec.joints_incomplete {
        check_has_closing(ps, pname, &closing, diags);
    }

    let topo = lower::check_topology(spec, diags, &on.skip);
    if diags.has_errors() {
        return None;
    }
    let topo = topo?;
    let motion = motion?;
    let built = lower::build(spec, &topo, &axes, diags);
    if diags.has_errors() {
        return None;
    }

    // Split the tree into legs: the path from each closing joint's parent back to the base.
    let closing_joints: Vec<usize> = (0..spec.joints.len()).filter(|&j| closing[j]).collect();
    let tree = Tree {
        spec,
        topo: &topo,
        built: &built,
        closing: &closing_joints,
    };
    let paths = split_legs(&tree, pname, diags);
    if diags.has_errors() {
        return None;
    }

    let legs = build_legs(&tree, &axes, &paths, motion, diags);
    let mut pm = assemble(spec, ps, motion, pname, &on.parts, legs);
    close_at_home(&tree, &mut pm, diags);
    check_orientation_axes(&tree, &pm, diags);
    check_upu_legs(&tree, &axes, &mut pm, diags);
    // Each leg's type and geometry (the runtime's checks, which name the leg and the joint)
    // before the declared motion against the legs' (which names only the motions), then the
    // rank at home.
    if !diags.has_errors() && run_validate {
        runtime_checks(spec, ps, &closing_joints, &pm, diags);
    }
    if !diags.has_errors() {
        check_declared_motion(&tree, &axes, ps, &pm, diags);
    }
    if !diags.has_errors() {
        check_upu_axes(&tree, &axes, &pm, diags);
    }
    if diags.has_errors() || !run_validate {
        return None;
    }
    rank_check(spec, ps, &closing_joints, &pm, diags);
    if diags.has_errors() { None } else { Some(pm) }
}

/// The pose in the platform frame of `body` when it is the platform or hangs from it by fixed
/// joints (`None` otherwise): where a run-time payload on it enters the platform's inertia.
pub(crate) fn pose_on_platform(spec: &Spec, body: &str) -> Option<Transform> {
    let platform = spec.platform.as_ref()?.body.as_deref()?;
    let mut at = body;
    let mut pose = Transform::IDENTITY;
    // At most one step per joint: a loop of fixed joints cannot trap the walk.
    for _ in 0..=spec.joints.len() {
        if at == platform {
            return Some(pose);
        }
        let j = spec.joints.iter().find(|j| j.child == at)?;
        if j.kind != Kind::Fixed {
            return None;
        }
        let (origin, offset) = lower::placement_frames(&j.placement);
        pose = compose(&compose(&origin, &offset), &pose);
        at = j.parent.as_str();
    }
    None
}
