//! The legs: the tree (the mechanism without its joints into the platform, lowered by
//! [`lower::build`]) split into one chain from the base to each joint into the platform, each
//! with one actuated joint and of a type the runtime supports, then built as a [`Leg`].

use runtime::model::{JointKind, Transform, mat_vec};
use runtime::parallel::{Leg, LegEnd};

use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom::compose;
use crate::spec::ir::{Coordinates, JointSpec, Kind, Spec};
use crate::spec::lower::{self, Axes, Built, Topo};

/// The leg types [`ParallelModel::validate`] recognises, by their expanded joint kinds.
///
/// [`ParallelModel::validate`]: runtime::parallel::ParallelModel::validate
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
const SUPPORTED_UPU: &[&[JointKind]] = &[&[
    JointKind::Revolute,
    JointKind::Revolute,
    JointKind::Prismatic,
]];
const SUPPORTED_SHAFT: &[&[JointKind]] = &[&[
    JointKind::Revolute,
    JointKind::Revolute,
    JointKind::Revolute,
    JointKind::Prismatic,
    JointKind::Revolute,
    JointKind::Revolute,
]];
/// The hint of an unsupported leg of a Schönflies platform.
pub(super) const SUPPORTED_SCHOENFLIES_HINT: &str = "supported legs for coordinates = \"schoenflies\" (a 4-axis Delta): three Delta legs (a revolute crank carrying a [[parallelogram]] to the carrier) and one telescopic shaft R-U-P-U from a motor about z on the base to the tool, whose revolute about z into the carrier closes it (the shaft along the motor axis at home, the two universal joints in phase)";
const SUPPORTED_ORIENTATION: &[&[JointKind]] = &[&[JointKind::Revolute, JointKind::Revolute]];
const SUPPORTED_PLANAR_POSE: &[&[JointKind]] = &[
    &[JointKind::Revolute, JointKind::Revolute],
    &[JointKind::Prismatic, JointKind::Revolute],
    &[JointKind::Revolute, JointKind::Prismatic],
];
const SUPPORTED_HEAVE_TILT: &[&[JointKind]] = &[
    &[JointKind::Prismatic, JointKind::Revolute],
    &[JointKind::Revolute, JointKind::Prismatic],
];
/// The hint of an unsupported leg of a 1T2R platform.
pub(super) const SUPPORTED_HEAVE_TILT_HINT: &str = "supported legs for coordinates = \"heave_tilt\": P-R-S (a slider, then a revolute whose axis is perpendicular to the rail, then the spherical joint at the platform) or R-P-S (a revolute, then a prismatic perpendicular to its axis along the line to the S centre, then the spherical joint); each keeps its S centre in the plane of its revolute joint; one of the two leg joints actuated";
/// The hint of an unsupported leg of a planar 3-DOF platform.
pub(super) const SUPPORTED_PLANAR_POSE_HINT: &str = "supported legs for coordinates = \"planar_pose\": two joints in the plane, then the revolute about z into the platform: R-R-R (revolute axes along z), P-R-R (a slider in the plane, then the rod) or R-P-R (a revolute about z, then a prismatic along the line to the platform point); one of the two leg joints actuated";
pub(super) const SUPPORTED_HINT: &str = "supported legs: for coordinates = \"pose\" any three revolute or prismatic joints (a U counts as two revolutes) ending in a spherical joint, in closed form for UPS, PUS and RUS and by Newton otherwise; R-R-R with every axis through the centre for coordinates = \"orientation\"; for coordinates = \"planar\" R-R-R with every axis along z (a five-bar's R-R leg, then the revolute at the platform point); for coordinates = \"translation\" a revolute crank with a [[parallelogram]] (a Delta leg), a U-P leg ending in a universal joint (Tsai's 3-UPU), or the legs of \"pose\"";

/// The lowered tree with what the leg steps need: its topology, the build (model and
/// bookkeeping), and the spec joints into the platform, one per leg in declared order.
pub(super) struct Tree<'a> {
    pub spec: &'a Spec,
    pub topo: &'a Topo,
    pub built: &'a Built,
    pub closing: &'a [usize],
}

impl Tree<'_> {
    /// The frame of joint `c` into the platform in the last leg body's (model) frame.
    pub(super) fn frame_in_tip(&self, c: usize) -> Transform {
        let pose_in_tip = self.topo.parent[c]
            .and_then(|p| self.built.attach[p])
            .map_or(Transform::IDENTITY, |a| a.pose);
        let (origin, _) = lower::placement_frames(&self.spec.joints[c].placement);
        compose(&pose_in_tip, &origin)
    }
}

/// Per leg, the model joints from the base to the last one before the joint into the platform
/// (empty for a leg without one, which is an error). A joint on two legs, or on none, is an
/// error too.
pub(super) fn split_legs(tree: &Tree<'_>, pname: &str, diags: &mut Diagnostics) -> Vec<Vec<usize>> {
    let (spec, built) = (tree.spec, tree.built);
    let model = &built.model;
    let mut leg_of: Vec<Option<usize>> = vec![None; model.dof()];
    let mut paths: Vec<Vec<usize>> = Vec::new();
    for (li, &c) in tree.closing.iter().enumerate() {
        let j = &spec.joints[c];
        let tip = tree.topo.parent[c]
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
            let first = &spec.joints[tree.closing[other]];
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
    check_on_a_leg(tree, &leg_of, pname, diags);
    paths
}

/// Every model joint lies on a leg (`leg_of`); reported once per spec joint.
fn check_on_a_leg(tree: &Tree<'_>, leg_of: &[Option<usize>], pname: &str, diags: &mut Diagnostics) {
    let spec = tree.spec;
    let mut reported = vec![false; spec.joints.len()];
    for (k, l) in leg_of.iter().enumerate() {
        let sj = tree.built.spec_joint[k];
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
}

/// The legs, one per joint into the platform along its path.
pub(super) fn build_legs(
    tree: &Tree<'_>,
    axes: &Axes,
    paths: &[Vec<usize>],
    motion: Coordinates,
    diags: &mut Diagnostics,
) -> Vec<Leg> {
    let mut legs = Vec::with_capacity(tree.closing.len());
    for (&c, path) in tree.closing.iter().zip(paths) {
        legs.push(build_leg(tree, axes, c, path, motion, diags));
    }
    legs
}

/// The leg that ends in joint `c` into the platform, along the model joints `path`; its
/// actuation, type and drives are checked first.
fn build_leg(
    tree: &Tree<'_>,
    axes: &Axes,
    c: usize,
    path: &[usize],
    motion: Coordinates,
    diags: &mut Diagnostics,
) -> Leg {
    let (spec, model) = (tree.spec, &tree.built.model);
    let j = &spec.joints[c];
    let mut spec_path: Vec<usize> = path.iter().map(|&k| tree.built.spec_joint[k]).collect();
    spec_path.dedup();
    let actuated = check_leg_actuated(spec, j, &spec_path, diags);
    check_leg_type(tree, j, path, &spec_path, motion, diags);

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
    let actuated_spec = actuated.first().copied();
    let act = actuated.first().and_then(|&a| {
        let name = &spec.joints[a].name;
        path.iter()
            .position(|&k| model.joints[k].name == *name)
            .map(|i| (i, name.clone()))
    });
    // The joint frame in the last leg body's (model) frame.
    let frame = tree.frame_in_tip(c);
    let child_origin = j.child_origin.unwrap_or(Transform::IDENTITY);
    crate::spec::no_drive(
        j,
        "meets the platform",
        "drives (damping, friction, armature) apply to the leg joints whose rates the leg Jacobian gives; remove them from the joint into the platform",
        diags,
    );
    let end = match j.kind {
        // A planar platform: the revolute joint about z at the point ties the point (the
        // platform's rotation is its own coordinate, or idle for a planar point).
        Kind::Revolute
            if matches!(
                motion,
                Coordinates::Planar | Coordinates::PlanarPose | Coordinates::Schoenflies
            ) =>
        {
            LegEnd::Spherical {
                on_leg: frame.translation,
                on_platform: child_origin.translation,
            }
        }
        Kind::Revolute => {
            let e = axes[c].first().copied().unwrap_or([0.0, 0.0, 1.0]);
            LegEnd::Revolute {
                on_leg: mat_vec(&frame.rotation, &e),
                on_platform: mat_vec(&child_origin.rotation, &e),
            }
        }
        // A universal joint into a translational platform (Tsai's 3-UPU) meets it at its centre:
        // the leg is evaluated as a UPS leg to that point (docs/spec.md).
        _ => LegEnd::Spherical {
            on_leg: frame.translation,
            on_platform: child_origin.translation,
        },
    };
    if motion == Coordinates::Schoenflies && j.kind == Kind::Revolute {
        check_tool_axis(tree, axes, c, path, diags);
    }
    let (actuated, actuated_name) = act.unwrap_or((usize::MAX, String::new()));
    let actuated_home = actuated_spec.map_or(0.0, |a| spec.joints[a].home);
    Leg {
        name: j.name.clone(),
        joints: leg_joints,
        bodies: leg_bodies,
        actuated,
        actuated_name,
        actuated_home,
        end,
    }
}

/// A Schönflies platform's tool joint `c` (a revolute into the carrier, closing the shaft's
/// leg along `path`) turns about the base `z` at home: `θ` is the tool's angle about `z`, and
/// the homokinetic shaft turns the tool about the motor's axis, which the leg's checks hold to
/// `z`.
fn check_tool_axis(
    tree: &Tree<'_>,
    axes: &Axes,
    c: usize,
    path: &[usize],
    diags: &mut Diagnostics,
) {
    let (spec, model) = (tree.spec, &tree.built.model);
    let j = &spec.joints[c];
    let mut tip = Transform::IDENTITY;
    for &k in path {
        tip = compose(&tip, &model.joints[k].origin);
    }
    let frame = compose(&tip, &tree.frame_in_tip(c));
    let e = axes[c].first().copied().unwrap_or([0.0, 0.0, 1.0]);
    let a = mat_vec(&frame.rotation, &e);
    let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    if a[0].abs() > 1e-9 * n || a[1].abs() > 1e-9 * n {
        let at = j.axes.first();
        diags.push(
            Diagnostic::error(format!(
                "the tool's joint \"{}\" into the carrier turns about [{:.4}, {:.4}, {:.4}] at home, not about the base z axis",
                j.name,
                a[0] / n,
                a[1] / n,
                a[2] / n
            ))
            .with_key(at.map_or_else(|| format!("{}.axis", j.key), |a| a.key.clone()))
            .with_span(at.map_or(j.span.clone(), |a| a.span.clone()))
            .with_hint("with coordinates = \"schoenflies\" the tool turns on the carrier about the vertical z (θ is its angle about z), parallel to its shaft's motor axis; give the joint the axis that is the base z at home"),
        );
    }
}

/// One actuated revolute or prismatic joint on the leg of joint `j` (its spec joints
/// `spec_path`). Returns the actuated ones.
fn check_leg_actuated(
    spec: &Spec,
    j: &JointSpec,
    spec_path: &[usize],
    diags: &mut Diagnostics,
) -> Vec<usize> {
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
                    .with_hint(
                        "each leg of a simple-platform mechanism has exactly one actuated joint",
                    ),
                );
            }
        }
    }
    actuated
}

/// A leg type the runtime supports, by the expanded joint kinds along `path`.
fn check_leg_type(
    tree: &Tree<'_>,
    j: &JointSpec,
    path: &[usize],
    spec_path: &[usize],
    motion: Coordinates,
    diags: &mut Diagnostics,
) {
    let (spec, model) = (tree.spec, &tree.built.model);
    let kinds: Vec<JointKind> = path.iter().map(|&k| model.joints[k].kind).collect();
    let supported = match motion {
        // A universal joint into a translational platform ends a U-P leg (Tsai's 3-UPU).
        Coordinates::Translation if j.kind == Kind::Universal => SUPPORTED_UPU,
        Coordinates::Schoenflies if j.kind == Kind::Revolute => SUPPORTED_SHAFT,
        Coordinates::Pose | Coordinates::Translation | Coordinates::Schoenflies => SUPPORTED_POSE,
        Coordinates::Orientation | Coordinates::Planar => SUPPORTED_ORIENTATION,
        Coordinates::PlanarPose => SUPPORTED_PLANAR_POSE,
        Coordinates::HeaveTilt => SUPPORTED_HEAVE_TILT,
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
            .with_hint(match motion {
                Coordinates::PlanarPose => SUPPORTED_PLANAR_POSE_HINT,
                Coordinates::HeaveTilt => SUPPORTED_HEAVE_TILT_HINT,
                Coordinates::Schoenflies => SUPPORTED_SCHOENFLIES_HINT,
                _ => SUPPORTED_HINT,
            }),
        );
    }
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
