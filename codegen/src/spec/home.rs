//! The home pose as geometry, for `codegen draw` ([`crate::draw`]): every joint's place and
//! axes in the base frame at zero joint coordinates, and each body as segments between its
//! joints, read off the format-neutral spec as written (before `[scene]` and before any
//! correction at home, so that a loop left open shows its gap).
//!
//! The walk starts at the base (and, for a parallel mechanism, at the platform's home pose) and
//! composes the joints' placements; a joint with `child_origin` (a loop cut, or a leg's joint
//! into the platform) is placed from both sides.

use std::collections::{HashMap, VecDeque};

use runtime::model::{Transform, Vec3, mat_vec};

use super::geom::{self, compose};
use super::ir::{BASE, Kind, Placement, Spec};
use super::lower::placement_frames;

/// A joint's kind, as drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// One rotation about its axis.
    Revolute,
    /// One translation along its axis.
    Prismatic,
    /// Two rotations (a universal or Hooke joint).
    Universal,
    /// A ball joint.
    Spherical,
    /// A rigid connection.
    Fixed,
}

impl JointKind {
    /// The spec's word for it.
    pub fn word(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
            JointKind::Universal => "universal",
            JointKind::Spherical => "spherical",
            JointKind::Fixed => "fixed",
        }
    }
}

/// One joint at home.
#[derive(Clone, Debug, PartialEq)]
pub struct HomeJoint {
    /// The joint's name (a parallelogram's ball joint at the platform takes the
    /// parallelogram's name, its universal joint at the elbow `<name>_elbow`).
    pub name: String,
    pub kind: JointKind,
    /// The joint frame's origin on its parent's side (base frame, m).
    pub at: Vec3,
    /// Its axes, unit vectors in the base frame: one for revolute and prismatic joints, two for
    /// universal joints, none for spherical and fixed joints.
    pub axes: Vec<Vec3>,
    /// An effort input: `actuated = true` in a parallel or closed-loop spec; every movable
    /// joint of a tree.
    pub actuated: bool,
    /// For a joint that closes a loop (it has `child_origin`): the joint frame's origin on the
    /// child's side. It differs from `at` when the loop is open at home as written.
    pub closes: Option<Vec3>,
}

/// What a segment belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// A moving body (or the platform).
    Body,
    /// The fixed base, from its origin to the joints on it.
    Base,
    /// One rod of a parallelogram, or its short sides.
    Rod,
}

/// A straight line of the drawing (base frame, m).
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub from: Vec3,
    pub to: Vec3,
    pub part: Part,
}

/// The mechanism at home.
#[derive(Clone, Debug, PartialEq)]
pub struct HomePose {
    /// `mechanism.name`.
    pub name: String,
    /// Tree, parallel platform or closed loops.
    pub kind: super::Kind,
    /// Every joint, in the spec's order.
    pub joints: Vec<HomeJoint>,
    /// The bodies' lines: each body from the joint that moves it (or from its frame origin) to
    /// the joints it carries.
    pub segments: Vec<Segment>,
    /// The mass centres of the bodies with mass (base frame, m), with the body's name.
    pub mass_centres: Vec<(String, Vec3)>,
}

impl HomePose {
    /// Every point drawn: joints (both sides), segment ends and mass centres.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.joints
            .iter()
            .flat_map(|j| std::iter::once(j.at).chain(j.closes))
            .chain(self.segments.iter().flat_map(|s| [s.from, s.to]))
            .chain(self.mass_centres.iter().map(|(_, c)| *c))
    }
}

fn unit(v: &Vec3) -> Vec3 {
    let n = geom::norm(v);
    if n > 0.0 && n.is_finite() {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        [0.0; 3]
    }
}

fn finite(v: &Vec3) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn distinct(a: &Vec3, b: &Vec3) -> bool {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    geom::norm(&d) > 1e-12
}

/// The home pose of a read spec; `None` when some joint cannot be placed (a body that does not
/// exist, a joint whose parent is never reached: the spec's diagnostics say why).
pub(crate) fn home_pose(spec: &Spec) -> Option<HomePose> {
    let nb = spec.bodies.len();
    // Body index by name (the first of duplicates, which the spec's checks report).
    let mut by_name: HashMap<&str, usize> = HashMap::new();
    for (i, b) in spec.bodies.iter().enumerate() {
        by_name.entry(b.name.as_str()).or_insert(i);
    }
    let index = |name: &str| by_name.get(name).copied();
    // Pose of each body's frame at home; the base is `None` in `index`, kept apart.
    let mut pose: Vec<Option<Transform>> = vec![None; nb];
    // The point a body's lines start from (the joint that moves it, then the DH `d` point).
    let mut start: Vec<Vec<Vec3>> = vec![Vec::new(); nb];
    let platform = spec.platform.as_ref();
    let mut queue: VecDeque<&str> = VecDeque::from([BASE]);
    if let Some(ps) = platform
        && let Some(name) = ps.body.as_deref()
        && let Some(i) = index(name)
    {
        pose[i] = Some(ps.home);
        queue.push_back(name);
    }
    let pose_of = |pose: &[Option<Transform>], name: &str| -> Option<Transform> {
        if name == BASE {
            Some(Transform::IDENTITY)
        } else {
            index(name).and_then(|i| pose[i])
        }
    };
    // Tree joints by parent, in the spec's order; placed outward from the base (and the
    // platform), each body once.
    let mut carried: HashMap<&str, Vec<usize>> = HashMap::new();
    for (ji, j) in spec.joints.iter().enumerate() {
        if j.child_origin.is_none() {
            carried.entry(j.parent.as_str()).or_default().push(ji);
        }
    }
    let mut frame: Vec<Option<Transform>> = vec![None; spec.joints.len()];
    while let Some(body) = queue.pop_front() {
        let Some(p) = pose_of(&pose, body) else {
            continue;
        };
        for &ji in carried.get(body).map_or(&[][..], |v| v.as_slice()) {
            let j = &spec.joints[ji];
            let Some(c) = index(&j.child) else { continue };
            if pose[c].is_some() {
                continue;
            }
            let (origin, offset) = placement_frames(&j.placement);
            let f = compose(&p, &origin);
            frame[ji] = Some(f);
            pose[c] = Some(compose(&f, &offset));
            start[c].push(f.translation);
            if let Placement::Dh(dh) = &j.placement
                && dh.d != 0.0
            {
                start[c].push(f.apply(&[0.0, 0.0, dh.d]));
            }
            queue.push_back(j.child.as_str());
        }
    }
    // Loop-closing joints: placed from their parent; their child side from the child's pose.
    for (ji, j) in spec.joints.iter().enumerate() {
        if j.child_origin.is_some()
            && let Some(p) = pose_of(&pose, &j.parent)
        {
            frame[ji] = Some(compose(&p, &placement_frames(&j.placement).0));
        }
    }
    let actuated_by_default = platform.is_none() && !super::closed::is_closed(spec);
    let mut joints = Vec::with_capacity(spec.joints.len());
    for (ji, j) in spec.joints.iter().enumerate() {
        let f = frame[ji]?;
        let kind = match j.kind {
            Kind::Revolute => JointKind::Revolute,
            Kind::Prismatic => JointKind::Prismatic,
            Kind::Universal => JointKind::Universal,
            Kind::Spherical => JointKind::Spherical,
            Kind::Fixed => JointKind::Fixed,
        };
        let written: Vec<Vec3> = j.axes.iter().map(|a| a.v).collect();
        let local = match (kind, written.is_empty()) {
            (JointKind::Revolute | JointKind::Prismatic, true) => vec![[0.0, 0.0, 1.0]],
            (JointKind::Universal, true) => vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            (JointKind::Revolute | JointKind::Prismatic, false) => written[..1].to_vec(),
            (JointKind::Universal, false) => written.into_iter().take(2).collect(),
            _ => Vec::new(),
        };
        let axes = local
            .iter()
            .map(|a| unit(&mat_vec(&f.rotation, a)))
            .collect();
        let closes = match &j.child_origin {
            Some(co) => Some(pose_of(&pose, &j.child)?.compose(co).translation),
            None => None,
        };
        joints.push(HomeJoint {
            name: j.name.clone(),
            kind,
            at: f.translation,
            axes,
            actuated: j.actuated || (actuated_by_default && kind != JointKind::Fixed),
            closes,
        });
    }

    let mut segments = Vec::new();
    // The base: from its origin to each joint on it.
    for (j, hj) in spec.joints.iter().zip(&joints) {
        if j.parent == BASE && distinct(&[0.0; 3], &hj.at) {
            segments.push(Segment {
                from: [0.0; 3],
                to: hj.at,
                part: Part::Base,
            });
        }
    }
    let widths = |name: &str| {
        spec.parallelograms
            .iter()
            .position(|n| n == name)
            .and_then(|i| spec.parallelogram_widths.get(i).copied())
    };
    for (bi, body) in spec.bodies.iter().enumerate() {
        let Some(bp) = pose[bi] else { continue };
        // Ends on this body: the parent side of the joints it carries, the child side of the
        // loop-closing joints into it.
        let mut ends: Vec<Vec3> = Vec::new();
        for (j, hj) in spec.joints.iter().zip(&joints) {
            if j.parent == body.name {
                ends.push(hj.at);
            }
            if j.child == body.name
                && let Some(c) = hj.closes
            {
                ends.push(c);
            }
        }
        // A parallelogram's equivalent rod: its two rods and short sides instead.
        let rod_of = spec
            .joints
            .iter()
            .zip(&joints)
            .find(|(j, _)| j.parent == body.name && widths(&j.name).is_some());
        let elbow = spec
            .joints
            .iter()
            .zip(&joints)
            .find(|(j, hj)| j.child == body.name && hj.kind == JointKind::Universal);
        if let (Some((j, s)), Some((_, u))) = (rod_of, elbow)
            && let (Some(w), Some(a)) = (widths(&j.name), u.axes.first())
            && w > 0.0
        {
            let h = 0.5 * w;
            let p = s.closes.unwrap_or(s.at);
            let shift = |q: &Vec3, k: f64| [q[0] + k * a[0], q[1] + k * a[1], q[2] + k * a[2]];
            for k in [-h, h] {
                segments.push(Segment {
                    from: shift(&u.at, k),
                    to: shift(&p, k),
                    part: Part::Rod,
                });
            }
            for q in [u.at, p] {
                segments.push(Segment {
                    from: shift(&q, -h),
                    to: shift(&q, h),
                    part: Part::Rod,
                });
            }
        } else {
            let path = &start[bi];
            let from = path.last().copied().unwrap_or(bp.translation);
            for w in path.windows(2) {
                segments.push(Segment {
                    from: w[0],
                    to: w[1],
                    part: Part::Body,
                });
            }
            if ends.is_empty() && distinct(&from, &bp.translation) {
                ends.push(bp.translation);
            }
            for (k, e) in ends.iter().enumerate() {
                // Once per place (a fixed pin and a joint at one point).
                if distinct(&from, e) && ends[..k].iter().all(|o| distinct(o, e)) {
                    segments.push(Segment {
                        from,
                        to: *e,
                        part: Part::Body,
                    });
                }
            }
        }
    }
    let mass_centres = spec
        .bodies
        .iter()
        .zip(&pose)
        .filter(|(b, _)| b.mass > 0.0)
        .filter_map(|(b, p)| Some((b.name.clone(), p.as_ref()?.apply(&b.com))))
        .collect();
    let kind = if platform.is_some() {
        super::Kind::Parallel
    } else if super::closed::is_closed(spec) {
        super::Kind::Closed
    } else {
        super::Kind::Tree
    };
    let home = HomePose {
        name: spec.name.clone(),
        kind,
        joints,
        segments,
        mass_centres,
    };
    let ok = home.points().all(|p| finite(&p));
    ok.then_some(home)
}
