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

use std::collections::HashMap;

use runtime::model::{Body, JointKind, Transform, mat_vec};
use runtime::parallel::{GEOMETRY_TOLERANCE, Leg, LegEnd, ParallelModel, PlatformMotion};

use super::geom::{self, MassProps, compose};
use super::ir::{BASE, Coordinates, JointSpec, Kind, Placement, PlatformSpec, Spec};
use super::lower::{self, Skip};
use super::suggest_hint;
use crate::diag::{Diagnostic, Diagnostics};

/// The leg types [`ParallelModel::validate`] recognises, by their expanded joint kinds.
const SUPPORTED_POSE: &[&[JointKind]] = &[
    &[
        JointKind::Revolute,
        JointKind::Revolute,
        JointKind::Prismatic,
    ],
    &[
        JointKind::Prismatic,
        JointKind::Revolute,
        JointKind::Revolute,
    ],
    &[
        JointKind::Revolute,
        JointKind::Revolute,
        JointKind::Revolute,
    ],
];
const SUPPORTED_ORIENTATION: &[&[JointKind]] = &[&[JointKind::Revolute, JointKind::Revolute]];
const SUPPORTED_HINT: &str = "supported legs: for coordinates = \"pose\" any three revolute or prismatic joints (a U counts as two revolutes) ending in a spherical joint, in closed form for UPS, PUS and RUS and by Newton otherwise; R-R-R with every axis through the centre for coordinates = \"orientation\"; for coordinates = \"planar\" R-R-R with every axis along z (a five-bar's R-R leg, then the revolute at the platform point)";

/// Validates a spec with a `[platform]` table and builds the parallel model. Errors and
/// warnings go to `diags`; `None` when there was any error.
pub(crate) fn lower_parallel(spec: &Spec, diags: &mut Diagnostics) -> Option<ParallelModel> {
    let ps = spec.platform.as_ref()?;
    // The whole-mechanism counts are reported beside everything else, but they must not stop
    // the leg-by-leg checks (which stop at the first stage with errors); with a wrong count the
    // runtime's own validation would only repeat it.
    let mut global = Diagnostics::new(diags.file_name(), diags.source());
    check_mobility(spec, ps, &mut global);
    let model = lower_checked(spec, ps, diags, !global.has_errors());
    diags.extend(global);
    model.filter(|_| !diags.has_errors())
}

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
    let mut skip = Skip::none(spec);
    skip.body[pb] = true;
    let mut platform_parts = vec![(pb, Transform::IDENTITY)];
    let mut on_platform: Vec<Option<Transform>> = vec![None; spec.bodies.len()];
    on_platform[pb] = Some(Transform::IDENTITY);
    loop {
        let mut grew = false;
        for (ji, j) in spec.joints.iter().enumerate() {
            if closing[ji] || skip.joint[ji] {
                continue;
            }
            let Some(&p) = body_index.get(j.parent.as_str()) else {
                continue;
            };
            let Some(pose) = on_platform[p] else {
                continue;
            };
            skip.joint[ji] = true;
            grew = true;
            let child = body_index.get(j.child.as_str()).copied();
            if j.kind != Kind::Fixed {
                // Leave what it carries out of the tree checks too (no "not attached" echo).
                if let Some(c) = child
                    && on_platform[c].is_none()
                {
                    on_platform[c] = Some(Transform::IDENTITY);
                    skip.body[c] = true;
                }
                diags.push(
                    Diagnostic::error(format!(
                        "joint \"{}\" moves a body on the platform, but a {} joint cannot hang from the platform",
                        j.name,
                        j.kind.word()
                    ))
                    .with_key(format!("{}.kind", j.key))
                    .with_span(j.kind_span.clone())
                    .with_hint("a simple-platform mechanism carries only rigid attachments on its platform: use kind = \"fixed\" (its mass is added to the platform's)"),
                );
                continue;
            }
            let Some(c) = child else {
                continue; // reported by the topology check
            };
            if on_platform[c].is_some() {
                diags.push(
                    Diagnostic::error(format!(
                        "joint \"{}\" closes a loop on the platform: body \"{}\" is already part of it",
                        j.name, j.child
                    ))
                    .with_key(format!("{}.child", j.key))
                    .with_span(j.child_span.clone())
                    .with_hint("bodies fixed to the platform form a tree hanging from it"),
                );
                continue;
            }
            let (origin, offset) = lower::placement_frames(&j.placement);
            let at = compose(&pose, &compose(&origin, &offset));
            on_platform[c] = Some(at);
            skip.body[c] = true;
            platform_parts.push((c, at));
        }
        if !grew {
            break;
        }
    }
    for (ji, j) in spec.joints.iter().enumerate() {
        if closing[ji] {
            skip.joint[ji] = true;
            check_closing_joint(j, ps, motion, &body_index, &on_platform, diags);
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
    if motion == Some(Coordinates::Planar)
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

    let topo = lower::check_topology(spec, diags, &skip);
    if diags.has_errors() {
        return None;
    }
    let topo = topo?;
    let motion = motion?;
    let built = lower::build(spec, &topo, &axes, diags);
    if diags.has_errors() {
        return None;
    }
    let model = &built.model;

    // Split the tree into legs: the path from each closing joint's parent back to the base.
    let closing_joints: Vec<usize> = (0..spec.joints.len()).filter(|&j| closing[j]).collect();
    let mut leg_of: Vec<Option<usize>> = vec![None; model.dof()];
    let mut paths: Vec<Vec<usize>> = Vec::new();
    for (li, &c) in closing_joints.iter().enumerate() {
        let j = &spec.joints[c];
        let tip = topo.parent[c]
            .and_then(|p| built.attach[p])
            .and_then(|a| a.target);
        let Some(tip) = tip else {
            diags.push(
                Diagnostic::error(format!(
                    "leg \"{}\" has no moving joint: its parent \"{}\" is fixed to the base",
                    j.name, j.parent
                ))
                .with_key(format!("{}.parent", j.key))
                .with_span(j.parent_span.clone())
                .with_hint("a leg is a chain of revolute, prismatic and universal joints from the base to its joint into the platform"),
            );
            paths.push(Vec::new());
            continue;
        };
        let mut path = vec![tip];
        while let Some(p) = model.joints[*path.last().unwrap_or(&tip)].parent {
            path.push(p);
        }
        path.reverse();
        let mut shared = None;
        for &k in &path {
            match leg_of[k] {
                Some(other) if shared.is_none() => shared = Some((other, k)),
                Some(_) => {}
                None => leg_of[k] = Some(li),
            }
        }
        if let Some((other, k)) = shared {
            let sj = &spec.joints[built.spec_joint[k]];
            let first = &spec.joints[closing_joints[other]];
            diags.push(
                Diagnostic::error(format!(
                    "legs \"{}\" and \"{}\" share joint \"{}\"",
                    first.name, j.name, sj.name
                ))
                .with_key(format!("{}.parent", j.key))
                .with_span(j.parent_span.clone())
                .with_hint("in a simple-platform mechanism each leg is its own chain from the base to the platform: give every leg its own bodies and joints"),
            );
        }
        paths.push(path);
    }
    let mut reported = vec![false; spec.joints.len()];
    for (k, l) in leg_of.iter().enumerate() {
        let sj = built.spec_joint[k];
        if l.is_none() && !std::mem::replace(&mut reported[sj], true) {
            let j = &spec.joints[sj];
            diags.push(
                Diagnostic::error(format!(
                    "joint \"{}\" is on no leg: its body \"{}\" does not lead to the platform",
                    j.name, j.child
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone())
                .with_hint(format!(
                    "in a parallel mechanism every moving body lies on exactly one leg, a chain from the base to a joint with child = \"{pname}\""
                )),
            );
        }
    }
    if diags.has_errors() {
        return None;
    }

    // Build the legs.
    let mut legs = Vec::with_capacity(closing_joints.len());
    for (&c, path) in closing_joints.iter().zip(&paths) {
        let j = &spec.joints[c];
        let mut spec_path: Vec<usize> = path.iter().map(|&k| built.spec_joint[k]).collect();
        spec_path.dedup();
        // One actuated revolute or prismatic joint.
        let actuated: Vec<usize> = spec_path
            .iter()
            .copied()
            .filter(|&s| spec.joints[s].actuated)
            .collect();
        match actuated.as_slice() {
            [] => diags.push(
                Diagnostic::error(format!("leg \"{}\" has no actuated joint", j.name))
                    .with_key(j.key.clone())
                    .with_span(j.span.clone())
                    .with_hint(format!(
                        "mark one revolute or prismatic joint of the leg ({}) with actuated = true",
                        spec_path
                            .iter()
                            .map(|&s| format!("\"{}\"", spec.joints[s].name))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
            ),
            [_] => {}
            [first, rest @ ..] => {
                for &r in rest {
                    let rj = &spec.joints[r];
                    diags.push(
                        Diagnostic::error(format!(
                            "leg \"{}\" has more than one actuated joint: \"{}\" and \"{}\"",
                            j.name, spec.joints[*first].name, rj.name
                        ))
                        .with_key(format!("{}.actuated", rj.key))
                        .with_span(rj.actuated_span.clone().or(rj.span.clone()))
                        .with_hint("each leg of a simple-platform mechanism has exactly one actuated joint"),
                    );
                }
            }
        }
        // A leg type the runtime supports.
        let kinds: Vec<JointKind> = path.iter().map(|&k| model.joints[k].kind).collect();
        let supported = match motion {
            Coordinates::Pose => SUPPORTED_POSE,
            Coordinates::Orientation | Coordinates::Planar => SUPPORTED_ORIENTATION,
        };
        if !supported.contains(&kinds.as_slice()) {
            let word: Vec<&str> = spec_path
                .iter()
                .map(|&s| letter(spec.joints[s].kind))
                .chain([letter(j.kind)])
                .collect();
            diags.push(
                Diagnostic::error(format!(
                    "leg \"{}\" is {}, which is not a supported leg type",
                    j.name,
                    word.join("-")
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone())
                .with_hint(SUPPORTED_HINT),
            );
        }

        let leg_joints = path
            .iter()
            .enumerate()
            .map(|(n, &k)| {
                let mut lj = model.joints[k].clone();
                lj.parent = n.checked_sub(1);
                lj
            })
            .collect();
        let leg_bodies = path.iter().map(|&k| model.bodies[k].clone()).collect();
        let act = actuated.first().and_then(|&a| {
            let name = &spec.joints[a].name;
            path.iter()
                .position(|&k| model.joints[k].name == *name)
                .map(|i| (i, name.clone()))
        });
        // The joint frame in the last leg body's (model) frame.
        let pose_in_tip = topo.parent[c]
            .and_then(|p| built.attach[p])
            .map_or(Transform::IDENTITY, |a| a.pose);
        let (origin, _) = lower::placement_frames(&j.placement);
        let frame = compose(&pose_in_tip, &origin);
        let child_origin = j.child_origin.unwrap_or(Transform::IDENTITY);
        super::no_drive(
            j,
            "meets the platform",
            "drives (damping, friction, armature) apply to the leg joints whose rates the leg Jacobian gives; remove them from the joint into the platform",
            diags,
        );
        let end = match j.kind {
            // A planar point platform: the revolute joint at the point only ties the point.
            Kind::Revolute if motion == Coordinates::Planar => LegEnd::Spherical {
                on_leg: frame.translation,
                on_platform: child_origin.translation,
            },
            Kind::Revolute => {
                let e = axes[c].first().copied().unwrap_or([0.0, 0.0, 1.0]);
                LegEnd::Revolute {
                    on_leg: mat_vec(&frame.rotation, &e),
                    on_platform: mat_vec(&child_origin.rotation, &e),
                }
            }
            _ => LegEnd::Spherical {
                on_leg: frame.translation,
                on_platform: child_origin.translation,
            },
        };
        let (actuated, actuated_name) = act.unwrap_or((usize::MAX, String::new()));
        legs.push(Leg {
            name: j.name.clone(),
            joints: leg_joints,
            bodies: leg_bodies,
            actuated,
            actuated_name,
            end,
        });
    }

    let centre = ps.centre.unwrap_or(ps.home.translation);
    let motion = match motion {
        Coordinates::Pose => PlatformMotion::Pose,
        Coordinates::Orientation => PlatformMotion::Orientation { centre },
        Coordinates::Planar => PlatformMotion::PlanarPoint {
            height: ps.home.translation[2],
        },
    };
    let parts: Vec<MassProps> = platform_parts
        .iter()
        .map(|&(b, at)| {
            let b = &spec.bodies[b];
            MassProps {
                mass: b.mass,
                com: b.com,
                inertia: b.inertia,
            }
            .transformed(&at)
        })
        .collect();
    let mp = MassProps::combine(&parts);
    let pm = ParallelModel {
        name: spec.name.clone(),
        gravity: spec.gravity,
        motion,
        platform: Body {
            name: pname.to_owned(),
            mass: mp.mass,
            com: mp.com,
            inertia: mp.inertia,
        },
        home: ps.home,
        legs,
    };

    // Revolute ends: the axis must pass through the centre on both sides (the runtime compares
    // only the directions). Same tolerance as the runtime's geometric checks.
    let tol = GEOMETRY_TOLERANCE * pm.size();
    if let PlatformMotion::Orientation { centre } = pm.motion {
        for (leg, &c) in pm.legs.iter().zip(&closing_joints) {
            let j = &spec.joints[c];
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
            let pose_in_tip = topo.parent[c]
                .and_then(|p| built.attach[p])
                .map_or(Transform::IDENTITY, |a| a.pose);
            let (origin, _) = lower::placement_frames(&j.placement);
            let p = tip.apply(&compose(&pose_in_tip, &origin).translation);
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
    if diags.has_errors() || !run_validate {
        return None;
    }

    // The runtime's own checks (leg geometry, loop closure at home), leg by leg so that every
    // leg's problem is reported, then once for the whole model.
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
        && let Err(e) = runtime::parallel::Plan::new(&pm)
    {
        messages.push(e);
    }
    for msg in messages {
        diags.push(validate_diagnostic(spec, ps, &closing_joints, msg));
    }
    if diags.has_errors() { None } else { Some(pm) }
}

/// The typical length for tolerances: the home position, at least 1 mm (as
/// [`ParallelModel::size`]; the leg joints are not known yet).
fn scale(ps: &PlatformSpec) -> f64 {
    let mut s = geom::norm(&ps.home.translation).max(1e-3);
    if let Some(c) = ps.centre {
        s = s.max(geom::norm(&c));
    }
    s
}

fn letter(k: Kind) -> &'static str {
    match k {
        Kind::Revolute => "R",
        Kind::Prismatic => "P",
        Kind::Universal => "U",
        Kind::Spherical => "S",
        Kind::Fixed => "fixed",
    }
}

/// The `[platform]` table: the body exists, `centre` fits the coordinates. Returns the platform
/// body's index.
fn check_platform(
    spec: &Spec,
    ps: &PlatformSpec,
    body_index: &HashMap<&str, usize>,
    diags: &mut Diagnostics,
) -> Option<usize> {
    match ps.coordinates {
        Some(Coordinates::Pose) if ps.centre.is_some() => {
            diags.push(
                Diagnostic::error("`centre` is only for coordinates = \"orientation\"")
                    .with_key("platform.centre")
                    .with_span(ps.centre_span.clone())
                    .with_hint("a 6-DOF platform has no fixed centre; remove `centre` (or use coordinates = \"orientation\")"),
            );
        }
        Some(Coordinates::Orientation) => {
            if let Some(c) = ps.centre {
                let h = ps.home.translation;
                let d = geom::norm(&[c[0] - h[0], c[1] - h[1], c[2] - h[2]]);
                if d > GEOMETRY_TOLERANCE * scale(ps) {
                    diags.push(
                        Diagnostic::error("the centre of rotation must be the platform frame's origin at home")
                            .with_key("platform.centre")
                            .with_span(ps.centre_span.clone())
                            .with_hint(format!(
                                "centre = [{}, {}, {}] but home.xyz = [{}, {}, {}]; place the platform frame at the centre (or leave `centre` out: it defaults to home.xyz)",
                                geom::num(c[0]), geom::num(c[1]), geom::num(c[2]),
                                geom::num(h[0]), geom::num(h[1]), geom::num(h[2])
                            )),
                    );
                }
            }
        }
        _ => {}
    }
    let name = ps.body.as_deref()?;
    if name == BASE {
        diags.push(
            Diagnostic::error("the platform cannot be the base")
                .with_key("platform.body")
                .with_span(ps.body_span.clone())
                .with_hint("the platform is the moving body that the legs carry: one of the [[body]] entries"),
        );
        return None;
    }
    match body_index.get(name) {
        Some(&b) => Some(b),
        None => {
            let names: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
            diags.push(
                Diagnostic::error(format!("the platform body \"{name}\" does not exist"))
                    .with_key("platform.body")
                    .with_span(ps.body_span.clone())
                    .with_hint(suggest_hint(name, &names).unwrap_or_else(|| {
                        "the platform is one of the [[body]] entries: add it, with its mass and inertia in the platform frame".into()
                    })),
            );
            None
        }
    }
}

/// Mobility by Grübler–Kutzbach, `M = λ(n − j − 1) + Σf` over the spec's bodies (plus the base)
/// and joints (minus the idle spin of a planar point platform), against the platform's DOF; and
/// the number of actuators against the DOF.
fn check_mobility(spec: &Spec, ps: &PlatformSpec, diags: &mut Diagnostics) {
    let Some(coords) = ps.coordinates else {
        return;
    };
    let (lambda, dof, what) = match coords {
        Coordinates::Pose => (6i64, 6i64, "spatial, λ = 6"),
        Coordinates::Orientation => (3, 3, "spherical, λ = 3"),
        Coordinates::Planar => (3, 2, "planar, λ = 3"),
    };
    let n = spec.bodies.len() as i64 + 1;
    let j = spec.joints.len() as i64;
    let f: i64 = spec
        .joints
        .iter()
        .map(|j| match j.kind {
            Kind::Revolute | Kind::Prismatic => 1,
            Kind::Universal => 2,
            Kind::Spherical => 3,
            Kind::Fixed => 0,
        })
        .sum();
    // A planar point platform's spin about the plane normal is idle (the point has no
    // orientation), so it does not count; a "platform" that the legs meet at different points
    // is a link whose spin they determine.
    let idle = i64::from(coords == Coordinates::Planar && apart(spec, ps).is_none());
    let m = lambda * (n - j - 1) + f - idle;
    let coords_word = match coords {
        Coordinates::Pose => "pose",
        Coordinates::Orientation => "orientation",
        Coordinates::Planar => "planar",
    };
    if m != dof {
        diags.push(
            Diagnostic::error(format!(
                "the mechanism's mobility is {m} (Grübler–Kutzbach, {what}), but a platform with coordinates = \"{coords_word}\" has {dof} degrees of freedom"
            ))
            .with_key("platform.coordinates")
            .with_span(ps.coordinates_span.clone())
            .with_hint(format!(
                "M = λ(n − j − 1) + Σf with n = {n} bodies (with the base), j = {j} joints and Σf = {f} joint freedoms (U counts 2, S 3, fixed 0); check the legs' joints{}",
                match coords {
                    Coordinates::Pose => ": each leg of a 6-DOF platform has six joint freedoms (UPS, PUS, RUS)",
                    Coordinates::Orientation => ": each leg of a spherical mechanism is R-R-R",
                    Coordinates::Planar => ": each leg of a planar five-bar is R-R, joined at the point by a revolute",
                }
            )),
        );
    }
    let actuated = spec.joints.iter().filter(|j| j.actuated).count() as i64;
    if actuated != dof {
        diags.push(
            Diagnostic::error(format!(
                "{actuated} joint{} actuated, but the platform has {dof} degrees of freedom",
                if actuated == 1 { " is" } else { "s are" }
            ))
            .with_key("platform")
            .with_span(ps.span.clone())
            .with_hint(format!(
                "a parallel mechanism has one actuator per degree of freedom: mark exactly one revolute or prismatic joint in each of the {dof} legs with actuated = true"
            )),
        );
    }
}

/// Two joints into the platform that meet it at different points (their `child_origin`, the
/// platform frame's origin when missing; beyond the geometric tolerance), with the points.
type Apart<'a> = [(&'a JointSpec, [f64; 3]); 2];

/// `None` when every joint into the platform meets it at the same point.
fn apart<'a>(spec: &'a Spec, ps: &PlatformSpec) -> Option<Apart<'a>> {
    let at = |j: &'a JointSpec| (j, j.child_origin.unwrap_or(Transform::IDENTITY).translation);
    let mut into = spec
        .joints
        .iter()
        .filter(|j| Some(j.child.as_str()) == ps.body.as_deref())
        .map(at);
    let (first, p) = into.next()?;
    into.find(|(_, q)| {
        geom::norm(&[q[0] - p[0], q[1] - p[1], q[2] - p[2]]) > GEOMETRY_TOLERANCE * scale(ps)
    })
    .map(|other| [(first, p), other])
}

/// `actuated` only on revolute and prismatic joints.
fn check_actuated_kind(j: &JointSpec, diags: &mut Diagnostics) {
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
        };
        if j.kind != want {
            diags.push(
                Diagnostic::error(format!(
                    "the platform \"{pname}\" is the child of {} joint \"{}\", but with coordinates = \"{word}\" a joint into the platform must be {}",
                    j.kind.word(),
                    j.name,
                    want.word()
                ))
                .with_key(format!("{}.kind", j.key))
                .with_span(j.kind_span.clone())
                .with_hint("the joints into the platform close the legs' loops: spherical joints for a 6-DOF (pose) platform, revolute joints with axes through the centre for an orientation platform; attach bodies rigidly to the platform with fixed joints from the platform instead"),
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
    } else {
        SUPPORTED_HINT
    };
    let d = Diagnostic::error(msg).with_hint(hint);
    match leg {
        Some(j) => d.with_key(j.key.clone()).with_span(j.span.clone()),
        None => d.with_key("platform").with_span(ps.span.clone()),
    }
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
