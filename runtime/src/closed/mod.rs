//! Closed loops in joint coordinates: a spanning tree of one-DOF joints plus loop-closing (cut)
//! joints, with a chosen set of tree coordinates as the independent coordinates (a four-bar by
//! its crank angle, a five-bar by its two actuated angles, a spherical five-bar, a Bricard
//! linkage).
//!
//! # The model
//! * The tree is a [`Model`] (its conventions: body `i` moved by joint `i`, parents first). Its
//!   joint positions `x` (`NX` of them, rad or m) are the mechanism's position coordinates; at
//!   `x = 0` (home) the spec's geometry closes every loop.
//! * Each cut joint ([`Cut`]) joins a frame on one body (or the base) to a frame on another;
//!   a revolute cut keeps the two frames' origins together and their axes aligned (5 scalar
//!   equations), a spherical cut keeps the origins together (3). Together they are the loop
//!   equations `Φ(x) = 0`.
//! * The independent coordinates `x_i` (`DOF` of them, the joints marked `actuated`) determine
//!   the others `x_d` through `Φ`; their rates `u = ẋ_i` are the speeds and their efforts are
//!   the generalized forces (the actuator efforts when those joints are the actuated ones).
//!
//! # The method (docs/method.md, "Closed loops in joint coordinates"; the lecture's eqs. 21–24
//! with the tree's joint rates, shaped by the loop equations, as the twist-shaping coordinates)
//! * Redundant loop equations are common (a planar loop written in 3-D has 5 equations per cut
//!   joint of which 2 are independent; the Bricard linkage has one redundant equation). At home,
//!   [`Plan::new`] keeps `NX − DOF` rows of `Φ_x` that are independent over the dependent
//!   columns (greedy Gram–Schmidt on unit-scaled rows) and checks that the others depend on
//!   them: the mobility `NX − rank Φ_x` must equal `DOF`. Every rank decision is relative:
//!   `Φ_x` made dimensionless (point rows over the size, prismatic columns times it), a
//!   residual at or below [`noc::RANK_TOLERANCE`] `· ‖Φ_x‖_F` is zero (a loop turned in space
//!   has rounding noise where an axis-aligned one has exact zeros). The other rows whose dependent
//!   columns do not vanish at home (an overconstrained loop's: Bricard's fifth equation) are
//!   spare rows of `Φ_d`'s LU ([`noc::Plan::spare`]): its partial pivoting then chooses, at each
//!   configuration, which `NX − DOF` equations to solve.
//! * Velocities: `ẋ_d = −Φ_d⁻¹ Φ_i u`, i.e. `ẋ = S u`, `S = [1; −Φ_d⁻¹ Φ_i]` — the natural
//!   orthogonal complement of the loop Jacobian (`Φ_x S = 0`).
//! * Accelerations: `ẍ_d = −Φ_d⁻¹ (Φ_i u̇ + Φ̇ ẋ)`, the bias `Φ̇ ẋ` from the tree's body
//!   accelerations with `ẍ = 0`.
//! * Dynamics: each body's Newton–Euler wrench for `(x, ẋ, ẍ)` at its mass centre, projected by
//!   its twist per unit speed (column `k` of `S` through the velocity recursion): `f_k =
//!   Σ_b ω_b⁽ᵏ⁾·n_b + v_b⁽ᵏ⁾·f_b`, the lecture's `f = Tᵀ w` (eqs. 21–24). This equals `Sᵀ τ_T` with
//!   `τ_T` the open tree's joint efforts, but those hold whole subtrees on long lever arms and
//!   cancel in the projection (by up to 1,600 times the result on the bundled loops), so
//!   their rounding survived it; the bodies' powers cancel far less. The inertia `Sᵀ M_T S`
//!   from the same twists.
//! * `Φ_d` is factorized by LU with partial pivoting after scaling its columns to unit norm
//!   (pivot choices are data-dependent selections, so the generated code pivots too); a pivot
//!   `≤ CONSTRAINT_TOLERANCE` is `Singular { site: Constraint(i) }`.
//!
//! [`Model`]: crate::model::Model

// NaN must fail the closure tests: negated comparisons on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use crate::model::{Mat3, Model, Transform, Vec3, mat_vec};

pub mod noc;

pub use noc::Plan;

/// How a cut joint closes its loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CutKind {
    /// A revolute joint about `axis` (unit, in the cut joint's frame): origins coincide and the
    /// axis is common (5 equations).
    Revolute {
        /// The axis in the joint frame.
        axis: Vec3,
    },
    /// A spherical joint: origins coincide (3 equations).
    Spherical,
}

/// A loop-closing joint between a frame on `parent` and a frame on `child` (`None`: the base).
/// At home the two frames coincide.
#[derive(Clone, Debug, PartialEq)]
pub struct Cut {
    /// Name (from the spec).
    pub name: String,
    /// Tree body carrying the first frame (`None`: the base).
    pub parent: Option<usize>,
    /// The joint frame in `parent`'s body frame.
    pub frame_parent: Transform,
    /// Tree body carrying the second frame.
    pub child: Option<usize>,
    /// The joint frame in `child`'s body frame.
    pub frame_child: Transform,
    /// Revolute or spherical.
    pub kind: CutKind,
}

/// A linear spring-damper between two points (an applied force element): tension
/// `T = stiffness · (L − rest_length) + damping · L̇` along the line of the points, `L` their
/// distance; it pulls the points together when `T > 0`.
#[derive(Clone, Debug, PartialEq)]
pub struct Spring {
    /// Name (from the spec).
    pub name: String,
    /// Tree body of the first point (`None`: the base).
    pub body_a: Option<usize>,
    /// The first point in `body_a`'s frame (m).
    pub point_a: Vec3,
    /// Tree body of the second point (`None`: the base).
    pub body_b: Option<usize>,
    /// The second point in `body_b`'s frame (m).
    pub point_b: Vec3,
    /// Stiffness (N/m), `>= 0`.
    pub stiffness: f64,
    /// Rest length (m), `>= 0`.
    pub rest_length: f64,
    /// Damping (N·s/m), `>= 0`.
    pub damping: f64,
}

/// A validated closed-loop mechanism in joint coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedModel {
    /// Mechanism name.
    pub name: String,
    /// The spanning tree (its `gravity` is the mechanism's).
    pub tree: Model,
    /// The loop-closing joints.
    pub cuts: Vec<Cut>,
    /// Indices of the independent (actuated) tree joints, in order.
    pub independent: Vec<usize>,
    /// Spring-dampers (applied forces, with gravity in the generalized force).
    pub springs: Vec<Spring>,
    /// Each tree joint's coordinate at home (rad or m; the spec's `home`), empty for all zero:
    /// every function takes absolute coordinates, tree joint `i` being turned (or moved) by
    /// `x_i − home_i` from its frame at home (docs/spec.md, "Coordinates at home").
    pub home: Vec<f64>,
}

/// Length tolerance of the closure check at home, relative to the mechanism's size.
pub const HOME_TOLERANCE: f64 = 1e-9;
/// The largest gap at home that the spec reader closes by itself (moving the loop-closing
/// joint's frame on its child side, with a warning): this fraction of the mechanism's size
/// (m), and [`HOME_CORRECTION_ANGLE`] for a revolute cut's axis. Values typed to four or five
/// digits leave gaps far below it; a gap above it is an error (a wrong spec, not rounding).
pub const HOME_CORRECTION: f64 = 1e-3;
/// The largest turn (rad, 1°) of a revolute cut's axis that the spec reader closes by itself.
pub const HOME_CORRECTION_ANGLE: f64 = 0.017453292519943295;

impl ClosedModel {
    /// Position coordinates (tree joints).
    pub fn nx(&self) -> usize {
        self.tree.dof()
    }
    /// Degrees of freedom (independent coordinates).
    pub fn dof(&self) -> usize {
        self.independent.len()
    }

    /// The typical length (m): the largest distance of a body origin or cut point from the base
    /// origin at home, at least 1 mm.
    pub fn size(&self) -> f64 {
        let poses = home_poses(&self.tree);
        let n = |v: &Vec3| libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        let mut s: f64 = 1e-3;
        for p in &poses {
            s = s.max(n(&p.translation));
        }
        for c in &self.cuts {
            s = s.max(n(
                &frame_at_home(&poses, c.parent, &c.frame_parent).translation
            ));
        }
        s
    }

    /// The length (m) of spring `k` at home (every tree joint at zero).
    pub fn spring_length_at_home(&self, k: usize) -> f64 {
        let poses = home_poses(&self.tree);
        let s = &self.springs[k];
        let at = |b: Option<usize>, p: &Vec3| b.map_or(Transform::IDENTITY, |b| poses[b]).apply(p);
        let (a, b) = (at(s.body_a, &s.point_a), at(s.body_b, &s.point_b));
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    }

    /// Structural checks: independent joints valid and distinct, at least one cut, and every
    /// loop closed at home (origins together, revolute axes aligned).
    pub fn validate(&self) -> Result<(), String> {
        let n = self.nx();
        if self.cuts.is_empty() {
            return Err("no loop-closing joint: this is a tree".into());
        }
        if self.independent.is_empty() {
            return Err("no independent coordinate: mark the actuated joints".into());
        }
        for (k, &j) in self.independent.iter().enumerate() {
            if j >= n || self.independent[..k].contains(&j) {
                return Err(format!(
                    "independent coordinate {k} is not a distinct tree joint"
                ));
            }
        }
        for c in &self.cuts {
            for b in [c.parent, c.child].into_iter().flatten() {
                if b >= n {
                    return Err(format!("cut joint {}: unknown body {b}", c.name));
                }
            }
            if c.parent == c.child {
                return Err(format!("cut joint {} joins a body to itself", c.name));
            }
        }
        let poses = home_poses(&self.tree);
        let tol = HOME_TOLERANCE * self.size();
        for c in &self.cuts {
            let a = frame_at_home(&poses, c.parent, &c.frame_parent);
            let b = frame_at_home(&poses, c.child, &c.frame_child);
            let d = [
                a.translation[0] - b.translation[0],
                a.translation[1] - b.translation[1],
                a.translation[2] - b.translation[2],
            ];
            let dist = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if !(dist <= tol) {
                return Err(format!(
                    "the loop through joint {} does not close at home: its frame's origin is {:?} m on one side and {:?} m on the other ({dist:.3e} m apart)",
                    c.name, a.translation, b.translation
                ));
            }
            if let CutKind::Revolute { axis } = c.kind {
                let ea = mat_vec(&a.rotation, &axis);
                let eb = mat_vec(&b.rotation, &axis);
                let d = [ea[0] - eb[0], ea[1] - eb[1], ea[2] - eb[2]];
                let dist = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                if !(dist <= 1e-9) {
                    return Err(format!(
                        "the loop through joint {} does not close at home: its axis is {ea:?} on one side and {eb:?} on the other",
                        c.name
                    ));
                }
            }
        }
        Ok(())
    }
}

impl ClosedModel {
    /// The first cut joint whose two frames do not meet at home (beyond the tolerance of
    /// [`ClosedModel::validate`]), with the correction `D` that closes it: its frame on the
    /// child side, `frame_child · D`, meets the parent side's (the origins for a spherical cut,
    /// the whole frame for a revolute one). `None` when every loop closes.
    pub fn open_cut(&self) -> Option<(usize, Transform)> {
        let poses = home_poses(&self.tree);
        let tol = HOME_TOLERANCE * self.size();
        self.cuts.iter().enumerate().find_map(|(k, c)| {
            let a = frame_at_home(&poses, c.parent, &c.frame_parent);
            let b = frame_at_home(&poses, c.child, &c.frame_child);
            let d = [
                a.translation[0] - b.translation[0],
                a.translation[1] - b.translation[1],
                a.translation[2] - b.translation[2],
            ];
            let dist = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            let bt = transpose(&b.rotation);
            // A revolute cut's axes must coincide: the rotation (in the child-side frame) that
            // turns the child side's axis onto the parent side's, about their common normal.
            let turn = match c.kind {
                CutKind::Revolute { axis } => {
                    let (ea, eb) = (mat_vec(&a.rotation, &axis), mat_vec(&b.rotation, &axis));
                    let e = [ea[0] - eb[0], ea[1] - eb[1], ea[2] - eb[2]];
                    (!(libm::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) <= 1e-9))
                        .then(|| crate::model::align(&axis, &mat_vec(&bt, &ea)))
                }
                CutKind::Spherical => None,
            };
            if dist <= tol && turn.is_none() {
                // The tests of `validate`.
                return None;
            }
            let rotation = turn.unwrap_or(Transform::IDENTITY.rotation);
            Some((
                k,
                Transform {
                    rotation,
                    translation: mat_vec(&bt, &d),
                },
            ))
        })
    }
}

fn transpose(m: &Mat3) -> Mat3 {
    core::array::from_fn(|i| core::array::from_fn(|j| m[j][i]))
}

/// Body poses of the tree at `x = 0` (base frame).
pub fn home_poses(tree: &Model) -> Vec<Transform> {
    let mut out: Vec<Transform> = Vec::with_capacity(tree.dof());
    for j in &tree.joints {
        let p = j.parent.map(|p| out[p]).unwrap_or(Transform::IDENTITY);
        out.push(p.compose(&j.origin));
    }
    out
}

fn frame_at_home(poses: &[Transform], body: Option<usize>, frame: &Transform) -> Transform {
    body.map(|b| poses[b])
        .unwrap_or(Transform::IDENTITY)
        .compose(frame)
}

/// Unit vectors `p1, p2` completing the unit `e` to a right-handed orthonormal basis
/// (deterministic: `p1` is the coordinate axis least aligned with `e`, made orthogonal).
pub fn perpendiculars(e: &Vec3) -> (Vec3, Vec3) {
    let a = [e[0].abs(), e[1].abs(), e[2].abs()];
    let k = if a[0] <= a[1] && a[0] <= a[2] {
        0
    } else if a[1] <= a[2] {
        1
    } else {
        2
    };
    let mut t = [0.0; 3];
    t[k] = 1.0;
    let d = t[0] * e[0] + t[1] * e[1] + t[2] * e[2];
    let mut p1 = [t[0] - d * e[0], t[1] - d * e[1], t[2] - d * e[2]];
    let n = libm::sqrt(p1[0] * p1[0] + p1[1] * p1[1] + p1[2] * p1[2]);
    for v in &mut p1 {
        *v /= n;
    }
    // Exact zeros stay exact for coordinate axes.
    for v in &mut p1 {
        if v.abs() < 1e-17 {
            *v = 0.0;
        }
    }
    let p2 = [
        e[1] * p1[2] - e[2] * p1[1],
        e[2] * p1[0] - e[0] * p1[2],
        e[0] * p1[1] - e[1] * p1[0],
    ];
    (p1, p2)
}

/// Ancestor flags: `anc[b][j]` is true when joint `j` moves body `b`.
pub(crate) fn ancestry(tree: &Model) -> Vec<Vec<bool>> {
    let n = tree.dof();
    (0..n)
        .map(|b| (0..n).map(|j| tree.supports(j, b)).collect())
        .collect()
}
