//! Lowering of a closed-loop mechanism in joint coordinates (a spec without `[platform]` whose
//! loop-closing joints carry `child_origin`) to a [`ClosedModel`]: the joints without
//! `child_origin` form a spanning tree (lowered by [`super::lower`]); each joint with
//! `child_origin` closes a loop between its parent and child bodies; the `actuated` joints are
//! the independent coordinates.
//!
//! Checks, all reported together: the cut joints' kinds (revolute or spherical), `actuated`
//! only on revolute or prismatic tree joints, at least one actuated joint, the tree rules for
//! the rest, and then [`Plan::new`] (loops closed at home, the mobility against the number of
//! actuated joints, the chosen coordinates determining the others).

use runtime::closed::{ClosedModel, Cut, CutKind, Plan};
use runtime::model::Transform;

use super::geom::compose;
use super::ir::{JointSpec, Kind, Spec};
use super::lower::{self, Skip};
use crate::diag::{Diagnostic, Diagnostics};

/// `true` when `spec` is a closed-loop mechanism in joint coordinates.
pub(crate) fn is_closed(spec: &Spec) -> bool {
    spec.platform.is_none() && spec.joints.iter().any(|j| j.child_origin.is_some())
}

/// Validate a closed-loop spec and build its model (`None` when there was any error), also
/// returning where each spec body went in the tree (`lower::Attach`:
/// the model body and the pose in its frame; a run-time payload's place).
pub(crate) fn lower_closed_attached(
    spec: &Spec,
    diags: &mut Diagnostics,
) -> Option<(ClosedModel, Vec<Option<lower::Attach>>)> {
    let axes = lower::check_values(spec, diags);
    let mut skip = Skip::none(spec);
    check_misplaced_child_origin(spec, diags, &mut skip);
    check_cut_joints(spec, diags, &mut skip);
    check_some_actuated(spec, diags);
    let topo = lower::check_topology(spec, diags, &skip);
    if diags.has_errors() {
        return None;
    }
    let topo = topo?;
    let built = lower::build(spec, &topo, &axes, diags);
    lower::check_runtime_bodies(spec, &built.attach, diags);
    if diags.has_errors() {
        return None;
    }
    let model = built.model;
    let attach = built.attach;
    let independent = independent_coordinates(spec, &skip, &built.spec_joint);
    let cuts = cuts(spec, &skip, &axes, &attach);
    let springs = springs(spec, &attach, diags);
    if diags.has_errors() {
        return None;
    }
    // Each tree joint's coordinate at home (`home`, docs/spec.md "Coordinates at home").
    let home: Vec<f64> = built
        .spec_joint
        .iter()
        .map(|&s| spec.joints[s].home)
        .collect();
    let mut closed = ClosedModel {
        name: spec.name.clone(),
        tree: model,
        cuts,
        independent,
        springs,
        home: if home.iter().all(|&h| h == 0.0) {
            Vec::new()
        } else {
            home
        },
    };
    if check_locked_at_home(spec, &closed, diags) {
        return None;
    }
    close_at_home(spec, &mut closed, diags);
    check_spring_lengths(spec, &closed, diags);
    if diags.has_errors() {
        return None;
    }
    check_plan(spec, &closed, diags)?;
    Some((closed, attach))
}

/// A joint with `child_origin` closes a loop only when its child is also reached by a tree
/// joint (or is the base).
fn in_tree(spec: &Spec, name: &str) -> bool {
    name == super::ir::BASE
        || spec
            .joints
            .iter()
            .any(|k| k.child_origin.is_none() && k.child == name)
}

/// A joint with `child_origin` whose child no tree joint reaches: `child_origin` is misplaced
/// and the joint stays in the tree (one precise error instead of an echo about an unattached
/// body).
///
/// When several joints reach a body and every one carries `child_origin`, they contradict each
/// other (each would close a loop, none places the body): one error names them all, and the
/// others than the first are left out of the topology so that nothing echoes it.
fn check_misplaced_child_origin(spec: &Spec, diags: &mut Diagnostics, skip: &mut Skip) {
    let mut grouped: Vec<&str> = Vec::new();
    for j in &spec.joints {
        if j.child_origin.is_none()
            || in_tree(spec, &j.child)
            || grouped.contains(&j.child.as_str())
        {
            continue;
        }
        let all: Vec<usize> = (0..spec.joints.len())
            .filter(|&k| spec.joints[k].child == j.child)
            .collect();
        if all.len() < 2 {
            continue;
        }
        grouped.push(&j.child);
        let names: Vec<String> = all
            .iter()
            .map(|&k| format!("\"{}\"", spec.joints[k].name))
            .collect();
        for &k in &all[1..] {
            skip.joint[k] = true;
        }
        diags.push(
            Diagnostic::error(format!(
                "body \"{}\" is reached only by joints with `child_origin` ({}): one of these joints must stay in the tree",
                j.child,
                names.join(", ")
            ))
            .with_key(format!("{}.child_origin", j.key))
            .with_span(j.child_origin_span.clone().or(j.span.clone()))
            .with_hint(format!(
                "`child_origin` marks a joint that closes a loop between two bodies the other joints already place; remove it from one of these {} joints (its child's frame is then its joint frame), and the others close the loops",
                all.len()
            )),
        );
    }
    for j in &spec.joints {
        if grouped.contains(&j.child.as_str()) {
            continue;
        }
        if j.child_origin.is_some() && !in_tree(spec, &j.child) {
            diags.push(
                Diagnostic::error(format!(
                    "joint \"{}\" has `child_origin`, which marks a loop-closing joint, but its child \"{}\" is reached by no other joint",
                    j.name, j.child
                ))
                .with_key(format!("{}.child_origin", j.key))
                .with_span(j.child_origin_span.clone().or(j.span.clone()))
                .with_hint("in a tree the child's frame is the joint frame: remove child_origin; a loop-closing joint joins two bodies that the other joints already place (a parallel mechanism's joints into the platform need a [platform] table)"),
            );
        }
    }
}

/// Marks the loop-closing joints in `skip` and checks them (kind, no drive, not actuated) and
/// the actuated tree joints (revolute or prismatic).
fn check_cut_joints(spec: &Spec, diags: &mut Diagnostics, skip: &mut Skip) {
    for (ji, j) in spec.joints.iter().enumerate() {
        if j.child_origin.is_some() && in_tree(spec, &j.child) {
            skip.joint[ji] = true;
            check_cut_joint(j, diags);
        } else if j.actuated && !matches!(j.kind, Kind::Revolute | Kind::Prismatic) {
            diags.push(
                Diagnostic::error(format!("a {} joint cannot be actuated", j.kind.word()))
                    .with_key(format!("{}.actuated", j.key))
                    .with_span(j.actuated_span.clone().or(j.span.clone()))
                    .with_hint("only revolute and prismatic joints can be actuated (be independent coordinates)"),
            );
        }
    }
}

/// A loop-closing joint: revolute or spherical, no drive, not actuated.
fn check_cut_joint(j: &JointSpec, diags: &mut Diagnostics) {
    if !matches!(j.kind, Kind::Revolute | Kind::Spherical) {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" closes a loop (it has `child_origin`), but a {} joint cannot close a loop",
                j.name,
                j.kind.word()
            ))
            .with_key(format!("{}.kind", j.key))
            .with_span(j.kind_span.clone())
            .with_hint("loop-closing joints are revolute or spherical; put the other joint of the loop in the tree (without child_origin) and close the loop at a revolute or spherical joint"),
        );
    }
    super::no_drive(
        j,
        "closes a loop",
        "drives (damping, friction, armature) apply to tree joints, whose rates are coordinates; close the loop at a joint without them",
        diags,
    );
    if j.actuated {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" closes a loop and cannot be actuated",
                j.name
            ))
            .with_key(format!("{}.actuated", j.key))
            .with_span(j.actuated_span.clone().or(j.span.clone()))
            .with_hint(
                "the independent coordinates are tree joints: close the loop at a passive joint",
            ),
        );
    }
}

/// At least one joint is actuated.
fn check_some_actuated(spec: &Spec, diags: &mut Diagnostics) {
    if !spec.joints.iter().any(|j| j.actuated) {
        diags.push(
            Diagnostic::error("no joint is actuated")
                .with_span(spec.anchor.clone())
                .with_hint("a closed-loop mechanism in joint coordinates takes its independent coordinates from the joints marked `actuated = true` (their efforts are the generalized forces); mark as many as it has degrees of freedom"),
        );
    }
}

/// Independent coordinates: the model joint of each actuated spec joint.
fn independent_coordinates(spec: &Spec, skip: &Skip, spec_joint: &[usize]) -> Vec<usize> {
    let mut independent = Vec::new();
    for (ji, j) in spec.joints.iter().enumerate() {
        if j.actuated
            && !skip.joint[ji]
            && let Some(k) = spec_joint.iter().position(|&s| s == ji)
        {
            independent.push(k);
        }
    }
    independent
}

/// A spec body's model body and its pose in that body's frame (`None` for the base).
fn body_of(
    spec: &Spec,
    attach: &[Option<lower::Attach>],
    name: &str,
) -> Option<(Option<usize>, Transform)> {
    if name == super::ir::BASE {
        return Some((None, Transform::IDENTITY));
    }
    let b = spec.bodies.iter().position(|b| b.name == name)?;
    let a = attach[b]?;
    Some((a.target, a.pose))
}

/// The loop-closing joints, each between the model bodies its parent and child became part of.
fn cuts(
    spec: &Spec,
    skip: &Skip,
    axes: &lower::Axes,
    attach: &[Option<lower::Attach>],
) -> Vec<Cut> {
    let mut cuts = Vec::new();
    for (ji, j) in spec.joints.iter().enumerate() {
        if !skip.joint[ji] {
            continue;
        }
        let (Some((pa, pose_a)), Some((cb, pose_b))) = (
            body_of(spec, attach, &j.parent),
            body_of(spec, attach, &j.child),
        ) else {
            continue; // reported by the topology check
        };
        let (origin, _) = lower::placement_frames(&j.placement);
        let frame_parent = compose(&pose_a, &origin);
        let frame_child = compose(&pose_b, &j.child_origin.unwrap_or(Transform::IDENTITY));
        let kind = match j.kind {
            Kind::Revolute => CutKind::Revolute {
                axis: axes[ji].first().copied().unwrap_or([0.0, 0.0, 1.0]),
            },
            _ => CutKind::Spherical,
        };
        cuts.push(Cut {
            name: j.name.clone(),
            parent: pa,
            frame_parent,
            child: cb,
            frame_child,
            kind,
        });
    }
    cuts
}

/// Springs: each point in the frame of the model body its spec body became part of.
fn springs(
    spec: &Spec,
    attach: &[Option<lower::Attach>],
    diags: &mut Diagnostics,
) -> Vec<runtime::closed::Spring> {
    let mut springs = Vec::new();
    for sp in &spec.springs {
        let mut end = |body: &super::ir::Named, point: &runtime::model::Vec3| {
            let place = body_of(spec, attach, &body.name);
            if place.is_none() {
                let names: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
                diags.push(
                    Diagnostic::error(format!(
                        "spring \"{}\" names body {:?}, which the mechanism does not have",
                        sp.name, body.name
                    ))
                    .with_key(body.key.clone())
                    .with_span(body.span.clone())
                    .with_hint(
                        super::suggest_hint(&body.name, &names)
                            .unwrap_or_else(|| "name a [[body]] of this spec, or \"base\"".into()),
                    ),
                );
            }
            place.map(|(target, pose)| (target, pose.apply(point)))
        };
        let (a, b) = (end(&sp.body_a, &sp.point_a), end(&sp.body_b, &sp.point_b));
        if let (Some((body_a, point_a)), Some((body_b, point_b))) = (a, b) {
            springs.push(runtime::closed::Spring {
                name: sp.name.clone(),
                body_a,
                point_a,
                body_b,
                point_b,
                stiffness: sp.stiffness,
                rest_length: sp.rest_length,
                damping: sp.damping,
            });
        }
    }
    springs
}

/// A spring of zero length at home has no direction there (the functions' `Spring` guard).
fn check_spring_lengths(spec: &Spec, closed: &ClosedModel, diags: &mut Diagnostics) {
    let size = closed.size();
    for (k, sp) in spec.springs.iter().enumerate() {
        let l = closed.spring_length_at_home(k);
        if l <= runtime::closed::noc::SPRING_TOLERANCE * size {
            diags.push(
                Diagnostic::error(format!("spring \"{}\" has zero length at home ({l:e} m)", sp.name))
                    .with_key(sp.key.clone())
                    .with_span(sp.span.clone())
                    .with_hint("its two points coincide with every joint at zero, so its force has no direction there: check point_a and point_b"),
            );
        }
    }
}

/// The hint of a loop closed at home (closed loops and platforms alike): the bound `bound`
/// (m) and `codegen fix-home`.
pub(super) fn home_correction_hint(bound: f64) -> String {
    format!(
        "gaps up to {:.0e} × the mechanism's size ({bound:.2e} m here) and 1° are closed so, as rounded numbers leave them; `codegen fix-home FILE` writes the corrected child_origin into the spec",
        runtime::closed::HOME_CORRECTION
    )
}

/// Loops that miss closing at home by little (rounded numbers: at most
/// [`HOME_CORRECTION`](runtime::closed::HOME_CORRECTION) × the size, and
/// [`HOME_CORRECTION_ANGLE`](runtime::closed::HOME_CORRECTION_ANGLE) for a revolute cut's
/// axis) are closed by moving the cut's frame on its child side, each with a warning that
/// gives the `child_origin` used (`codegen fix-home` writes it into the spec). Larger gaps are
/// left to [`check_plan`]'s error.
fn close_at_home(spec: &Spec, closed: &mut ClosedModel, diags: &mut Diagnostics) {
    let bound = runtime::closed::HOME_CORRECTION * closed.size();
    for _ in 0..closed.cuts.len() {
        let Some((k, fix)) = closed.open_cut() else {
            return;
        };
        let t = &fix.translation;
        let gap = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        let r = &fix.rotation;
        let turn = ((r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0)
            .clamp(-1.0, 1.0)
            .acos();
        let cut = &closed.cuts[k];
        let Some(j) = spec.joints.iter().find(|j| j.name == cut.name) else {
            return;
        };
        if gap > bound || turn > runtime::closed::HOME_CORRECTION_ANGLE || gap.is_nan() {
            return;
        }
        let now = j
            .child_origin
            .unwrap_or(runtime::model::Transform::IDENTITY);
        let to = now.compose(&fix);
        let what = if turn > 0.0 {
            format!("{gap:.2e} m and {:.2e}°", turn.to_degrees())
        } else {
            format!("{gap:.2e} m")
        };
        let value = super::geom::xyz_rpy(&to);
        diags.push(
            Diagnostic::warning(format!(
                "the loop through joint \"{}\" is {what} open at home; it is closed by moving the joint's frame on its child side to `child_origin = {value}`",
                j.name,
            ))
            .with_fix("child_origin", value.clone())
            .with_key(format!("{}.child_origin", j.key))
            .with_span(j.child_origin_span.clone().or(j.span.clone()))
            .with_hint(home_correction_hint(bound)),
        );
        let c = &mut closed.cuts[k];
        c.frame_child = c.frame_child.compose(&fix);
    }
}

/// `[scene] locked` joints held away from their home value move the loops off the home pose
/// the spec closes: the gap is theirs, not a cut's (whose `child_origin` the closure check
/// would otherwise blame, or silently move when the gap is small). When a loop is open at
/// home and some locked joint's value is not its home, each such lock is an error at its key;
/// true when one was reported.
fn check_locked_at_home(spec: &Spec, closed: &ClosedModel, diags: &mut Diagnostics) -> bool {
    if closed.open_cut().is_none() {
        return false;
    }
    let mut reported = false;
    for (n, value) in &spec.scene.locked {
        let Some(j) = spec.joints.iter().find(|j| j.name == n.name) else {
            continue;
        };
        if *value == j.home {
            continue;
        }
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" is locked at {value}, but the spec closes its loops with it at {} (its home): held there, it opens them",
                j.name, j.home
            ))
            .with_key(n.key.clone())
            .with_span(n.span.clone())
            .with_hint("in a closed loop a joint can be locked only at its home value; to hold it elsewhere, write the home pose with the joint there (the loops' other joints placed so that every loop closes), or leave it free"),
        );
        reported = true;
    }
    reported
}

/// The loop analysis ([`Plan::new`]); `None` when it fails (reported).
fn check_plan(spec: &Spec, closed: &ClosedModel, diags: &mut Diagnostics) -> Option<()> {
    if let Err(e) = Plan::new(closed) {
        // A loop that does not close: point at its joint and say which `child_origin` closes
        // it; otherwise at the first loop-closing joint (the loops are where the analysis
        // failed).
        let open = closed.open_cut().and_then(|(k, fix)| {
            let name = &closed.cuts[k].name;
            let j = spec.joints.iter().find(|j| &j.name == name)?;
            Some((j, fix))
        });
        let hint = match open {
            Some((j, fix)) => {
                let now = j.child_origin.unwrap_or(runtime::model::Transform::IDENTITY);
                let to = now.compose(&fix);
                format!(
                    "with every tree joint at zero, `child_origin = {}` closes this loop (if that is not the intended geometry, check the joint origins along the loop)",
                    super::geom::xyz_rpy(&to)
                )
            }
            None => "the mechanism is assembled at home with every tree joint at zero: check the joint origins, `child_origin` and which joints are actuated (one per degree of freedom)".to_string(),
        };
        // The loops close but the actuated set does not fit them (more or fewer actuated
        // joints than degrees of freedom, or ones that do not determine the others: every
        // such message of `Plan::new` names the actuated joints): point at the last
        // `actuated`, the key to change, not at a loop that is fine.
        let actuated = match open {
            None if e.contains("actuated") => spec.joints.iter().rev().find(|j| j.actuated),
            _ => None,
        };
        let at = open
            .map(|(j, _)| j)
            .or_else(|| spec.joints.iter().find(|j| j.child_origin.is_some()));
        let mut d = Diagnostic::error(e).with_hint(hint);
        if let Some(j) = actuated {
            d = d
                .with_key(format!("{}.actuated", j.key))
                .with_span(j.actuated_span.clone().or(j.span.clone()));
        } else if let Some(j) = at {
            d = d
                .with_key(format!("{}.child_origin", j.key))
                .with_span(j.child_origin_span.clone().or(j.span.clone()));
        } else {
            d = d.with_span(spec.anchor.clone());
        }
        diags.push(d);
        return None;
    }
    Some(())
}
