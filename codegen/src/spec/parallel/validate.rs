//! The checks on the assembled model: the axes of an orientation platform's revolute ends
//! through the centre, then the runtime's own checks ([`ParallelModel::validate`], leg by leg and
//! whole, and [`Plan::new`]'s rank check at home), each message placed at its leg.
//!
//! [`Plan::new`]: runtime::parallel::Plan::new

use runtime::model::{Transform, Vec3, mat_mul, mat_vec};
use runtime::parallel::{GEOMETRY_TOLERANCE, LegEnd, ParallelModel, PlatformMotion};

use super::legs::{
    SUPPORTED_HEAVE_TILT_HINT, SUPPORTED_HINT, SUPPORTED_PLANAR_POSE_HINT,
    SUPPORTED_SCHOENFLIES_HINT, Tree,
};
use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom;
use crate::spec::ir::{Coordinates, Kind, PlatformSpec, Spec};
use crate::spec::lower::Axes;

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

/// The legs that end in a universal joint into a translational platform and are U-P below it
/// (Tsai's 3-UPU: two revolutes, then a prismatic joint), their closing joint and the U's two
/// axes at home (base frame, unit; the cross's first axis first). Other legs into a U (an
/// R-U-U) are the leg-type check's to report, not these checks'.
fn upu_legs<'a>(
    tree: &'a Tree<'_>,
    axes: &'a Axes,
    pm: &'a ParallelModel,
) -> impl Iterator<Item = (&'a runtime::parallel::Leg, usize, Vec<Vec3>)> + 'a {
    pm.legs
        .iter()
        .zip(tree.closing)
        .filter(move |(_, c)| {
            matches!(pm.motion, PlatformMotion::Translation { .. })
                && tree.spec.joints[**c].kind == Kind::Universal
        })
        .filter(|(leg, _)| {
            use runtime::model::JointKind::{Prismatic, Revolute};
            leg.joints
                .iter()
                .map(|j| j.kind)
                .eq([Revolute, Revolute, Prismatic])
        })
        .map(move |(leg, &c)| {
            let tip = runtime::parallel::leg_home_poses(leg)
                .last()
                .copied()
                .unwrap_or(Transform::IDENTITY);
            let rot = mat_mul(&tip.rotation, &tree.frame_in_tip(c).rotation);
            let e: Vec<Vec3> = axes
                .get(c)
                .into_iter()
                .flatten()
                .map(|a| unit(&mat_vec(&rot, a)))
                .collect();
            (leg, c, e)
        })
}

fn unit(v: &Vec3) -> Vec3 {
    let n = geom::norm(v);
    if n > 0.0 {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        *v
    }
}

fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// A U-P leg into a translational platform's universal joint (Tsai's 3-UPU): the base U's two
/// axes meet, and the prismatic joint runs along the line from the base U's centre to the
/// platform U's. (The leg is evaluated as a UPS leg to the platform U's centre, which needs
/// both.) At the joint into the platform.
pub(super) fn check_upu_legs(
    tree: &Tree<'_>,
    axes: &Axes,
    pm: &mut ParallelModel,
    diags: &mut Diagnostics,
) {
    let tol = GEOMETRY_TOLERANCE * pm.size();
    let before = pm.clone();
    for (leg, c, _) in upu_legs(tree, axes, &before) {
        let j = &tree.spec.joints[c];
        let poses = runtime::parallel::leg_home_poses(leg);
        let ax: Vec<(Vec3, Vec3)> = poses
            .iter()
            .zip(&leg.joints)
            .map(|(p, jt)| (unit(&mat_vec(&p.rotation, &jt.axis)), p.translation))
            .collect();
        let (e0, p0) = ax[0];
        let (e1, p1) = ax[1];
        let n = geom::cross(&e0, &e1);
        let nn = geom::norm(&n);
        let gap = if nn < 1e-9 {
            f64::INFINITY
        } else {
            let d = sub(&p1, &p0);
            (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]).abs() / nn
        };
        let base_word = |k: usize| {
            tree.spec.joints[tree.built.spec_joint[tree_index(tree, leg, k)]]
                .name
                .clone()
        };
        if gap > tol {
            diags.push(
                Diagnostic::error(format!(
                    "leg \"{}\": the two axes of its base U (joints \"{}\" and \"{}\") do not meet",
                    j.name,
                    base_word(0),
                    base_word(1)
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone())
                .with_hint("a 3-UPU leg is a universal joint at the base, a prismatic joint and a universal joint at the platform: write the base joint as kind = \"universal\" (its two axes meet at its origin)"),
            );
            continue;
        }
        // The U centre: the meeting point (on the first axis, nearest the second).
        let w = sub(&p0, &p1);
        let (b, d, e) = (
            e0[0] * e1[0] + e0[1] * e1[1] + e0[2] * e1[2],
            e0[0] * w[0] + e0[1] * w[1] + e0[2] * w[2],
            e1[0] * w[0] + e1[1] * w[1] + e1[2] * w[2],
        );
        let s = (b * e - d) / (1.0 - b * b).max(f64::MIN_POSITIVE);
        let centre = [p0[0] + s * e0[0], p0[1] + s * e0[1], p0[2] + s * e0[2]];
        let tip = poses[2];
        let top = tip.apply(&tree.frame_in_tip(c).translation);
        let off = geom::norm(&geom::cross(&sub(&top, &centre), &ax[2].0));
        if off > tol && off <= runtime::closed::HOME_CORRECTION * pm.size() {
            // Rounded numbers: the prismatic axis is turned onto the line of the U centres
            // (a turn of about `off` / the leg's length), so that the leg is the UPS leg it
            // was meant to be.
            let along = unit(&sub(&top, &centre));
            let k = before.legs.iter().position(|l| std::ptr::eq(l, leg));
            if let Some(k) = k {
                let r = &poses[2].rotation;
                pm.legs[k].joints[2].axis = std::array::from_fn(|i| {
                    r[0][i] * along[0] + r[1][i] * along[1] + r[2][i] * along[2]
                });
            }
            diags.push(
                Diagnostic::warning(format!(
                    "leg \"{}\": its prismatic joint \"{}\" runs {} m off the line from the base U's centre to the platform U's centre at home; its axis is taken along that line",
                    j.name,
                    base_word(2),
                    geom::num(off)
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone())
                .with_hint(format!(
                    "offsets up to {:.0e} × the mechanism's size are corrected so, as rounded numbers leave them; point the prismatic joint's axis at the platform U's centre to silence this",
                    runtime::closed::HOME_CORRECTION
                )),
            );
        } else if off > tol {
            diags.push(
                Diagnostic::error(format!(
                    "leg \"{}\": its prismatic joint \"{}\" does not run along the line from the base U's centre to the platform U's centre (off by {} m at home)",
                    j.name,
                    base_word(2),
                    geom::num(off)
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone())
                .with_hint("in a 3-UPU leg the prismatic joint's axis is the line through the two U centres: point the prismatic joint's axis from the base U's centre at the platform U's centre"),
            );
        }
    }
}

/// The spec joint behind model joint `k` of `leg` (found by name in the built model).
fn tree_index(tree: &Tree<'_>, leg: &runtime::parallel::Leg, k: usize) -> usize {
    let name = &leg.joints[k].name;
    tree.built
        .model
        .joints
        .iter()
        .position(|j| j.name == *name)
        .unwrap_or(0)
}

/// Tsai's condition that keeps a 3-UPU translating beyond home: in each leg the base U's first
/// axis is parallel to the platform U's second, and the base U's second to the platform U's
/// first (Tsai 1996; Di Gregorio & Parenti-Castelli 1998). At home the declared-motion check
/// has already passed; this one is about every other pose.
pub(super) fn check_upu_axes(
    tree: &Tree<'_>,
    axes: &Axes,
    pm: &ParallelModel,
    diags: &mut Diagnostics,
) {
    for (leg, c, e) in upu_legs(tree, axes, pm) {
        let j = &tree.spec.joints[c];
        let poses = runtime::parallel::leg_home_poses(leg);
        if e.len() != 2 {
            continue;
        }
        let base: Vec<Vec3> = poses
            .iter()
            .zip(&leg.joints)
            .take(2)
            .map(|(p, jt)| unit(&mat_vec(&p.rotation, &jt.axis)))
            .collect();
        let parallel = |a: &Vec3, b: &Vec3| geom::norm(&geom::cross(a, b)) <= 1e-9;
        if !(parallel(&base[0], &e[1]) && parallel(&base[1], &e[0])) {
            diags.push(
                Diagnostic::error(format!(
                    "leg \"{}\": the platform U's axes are not parallel to the base U's in reverse order, so the platform would turn away from home",
                    j.name
                ))
                .with_key(format!("{}.axes", j.key))
                .with_span(j.axes.first().and_then(|a| a.span.clone()).or(j.span.clone()))
                .with_hint("Tsai's translational 3-UPU: the platform U's first axis parallel to the base U's second, its second axis parallel to the base U's first"),
            );
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
    for msg in messages {
        diags.push(validate_diagnostic(spec, ps, closing, msg));
    }
}

/// Full rank of the constraint Jacobian at home: `Plan::new` evaluates the legs and the
/// actuation matrix there (after [`runtime_checks`], which the leg evaluators rely on).
pub(super) fn rank_check(
    spec: &Spec,
    ps: &PlatformSpec,
    closing: &[usize],
    pm: &ParallelModel,
    diags: &mut Diagnostics,
) {
    if let Err(e) = runtime::parallel::Plan::new(pm) {
        diags.push(validate_diagnostic(spec, ps, closing, e));
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
    } else if msg.contains("of the actuation matrix") {
        "the platform can move at home with every actuator held (a parallel singularity): the legs' lines of action are dependent there, as when they all meet in one point or are all parallel; move the legs' points on the platform or on the base, or the home pose, so that they are not"
    } else if ps.coordinates == Some(Coordinates::PlanarPose) {
        SUPPORTED_PLANAR_POSE_HINT
    } else if ps.coordinates == Some(Coordinates::HeaveTilt) {
        SUPPORTED_HEAVE_TILT_HINT
    } else if ps.coordinates == Some(Coordinates::Schoenflies) {
        SUPPORTED_SCHOENFLIES_HINT
    } else {
        SUPPORTED_HINT
    };
    // A Schönflies shaft's message names the joint at fault (a U joint's expanded revolutes
    // as `<name>_1`, `<name>_2`): the diagnostic points at it.
    let named = (ps.coordinates == Some(Coordinates::Schoenflies))
        .then(|| {
            spec.joints
                .iter()
                .filter(|j| !closing.iter().any(|&c| spec.joints[c].name == j.name))
                .filter_map(|j| {
                    [
                        format!(" {} ", j.name),
                        format!(" {}_1", j.name),
                        format!(" {}_2", j.name),
                    ]
                    .iter()
                    .filter_map(|p| msg.find(p.as_str()))
                    .min()
                    .map(|at| (at, j))
                })
                .min_by_key(|(at, _)| *at)
                .map(|(_, j)| j)
        })
        .flatten();
    let d = Diagnostic::error(msg.clone()).with_hint(hint);
    if let Some(j) = named {
        return d.with_key(j.key.clone()).with_span(j.span.clone());
    }
    match leg {
        Some(j) => d.with_key(j.key.clone()).with_span(j.span.clone()),
        None => d.with_key("platform").with_span(ps.span.clone()),
    }
}

/// Legs that miss closing at home by little (rounded numbers: at most
/// [`HOME_CORRECTION`](runtime::closed::HOME_CORRECTION) × the size, and 1° for a revolute
/// end's axis) are closed by moving the joint's point (or axis) on the platform to where the
/// leg ends, each with a warning that gives the `child_origin` used (`codegen fix-home`
/// writes it into the spec). Larger gaps are left to [`runtime_checks`]' error.
pub(super) fn close_at_home(tree: &Tree<'_>, pm: &mut ParallelModel, diags: &mut Diagnostics) {
    let bound = runtime::closed::HOME_CORRECTION * pm.size();
    for _ in 0..pm.legs.len() {
        let Some((k, end)) = pm.open_leg() else {
            return;
        };
        let Some(j) = tree.closing.get(k).map(|&c| &tree.spec.joints[c]) else {
            return;
        };
        let now = j.child_origin.unwrap_or(Transform::IDENTITY);
        let (gap, to, what) = match (pm.legs[k].end, end) {
            (
                LegEnd::Spherical { on_platform: a, .. },
                LegEnd::Spherical { on_platform: b, .. },
            ) => {
                let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                let gap = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let t = &now.translation;
                let to = Transform {
                    rotation: now.rotation,
                    translation: [t[0] + d[0], t[1] + d[1], t[2] + d[2]],
                };
                (gap, to, format!("{gap:.2e} m"))
            }
            (LegEnd::Revolute { on_platform: a, .. }, LegEnd::Revolute { on_platform: b, .. }) => {
                let c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).clamp(-1.0, 1.0);
                let turn = c.acos();
                let gap = 0.0;
                let to = Transform {
                    rotation: mat_mul(&runtime::model::align(&a, &b), &now.rotation),
                    translation: now.translation,
                };
                if turn > runtime::closed::HOME_CORRECTION_ANGLE || turn.is_nan() {
                    return;
                }
                (gap, to, format!("{:.2e}°", turn.to_degrees()))
            }
            _ => return,
        };
        if gap > bound || gap.is_nan() {
            return;
        }
        let value = crate::spec::geom::xyz_rpy(&to);
        diags.push(
            Diagnostic::warning(format!(
                "leg {}'s loop is {what} open at home; it is closed by moving the joint's frame on the platform to `child_origin = {value}`",
                pm.legs[k].name,
            ))
            .with_fix("child_origin", value.clone())
            .with_key(format!("{}.child_origin", j.key))
            .with_span(j.child_origin_span.clone().or(j.span.clone()))
            .with_hint(crate::spec::closed::home_correction_hint(bound)),
        );
        pm.legs[k].end = end;
    }
}
