//! The NOC of a closed-loop mechanism in joint coordinates, written once over [`Real`] so that
//! the runtime (`f64`) and the generator (symbolic) evaluate the same equations (see the
//! module docs of [`super`] for the method).
//!
//! # One evaluation
//! 1. Tree kinematics from `x`: body rotations and origins, joint axes and points (base frame).
//! 2. The kept loop equations `Φ` and their Jacobian rows over the joints (a cut's point rows:
//!    the columns `e_j × (P − o_j)` (R) or `e_j` (P) of the joints between the two bodies; its
//!    axis rows: `(ω_b − ω_a)·(m × n)` with `n` the axis on one side and `m ⊥ n` on the other).
//! 3. `Φ_d` (dependent columns) by LU with partial pivoting; `ẋ = S u`. An overconstrained
//!    loop's redundant equations that do not vanish identically are spare rows of the LU
//!    ([`Plan::spare`]): the pivoting chooses, per configuration, which equations to solve.
//! 4. The body motions with `ẍ = 0` give the bias `Φ̇ ẋ`; `ẍ_d = −Φ_d⁻¹ (Φ_i u̇ + Φ̇ ẋ)`.
//! 5. Each body's Newton–Euler wrench projected on its twists per unit speed (the columns of
//!    `S` pushed through the tree's velocity recursion): `f = Tᵀ w`, the lecture's eqs. 21–24
//!    (docs/method.md, "Closed loops in joint coordinates").

#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;

use super::{ClosedModel, CutKind, ancestry, perpendiculars};
use crate::algebra::{
    M, V, add, cm, cross, cv, dot, euler, ident, inertia_quad, mm, mtv, mv, rot, scale, sub, zero3,
};
use crate::drive::{DriveInputs, drive_effort};
use crate::model::{JointKind, Mat3, Transform, Vec3, mat_vec};
use crate::payload::Payload;
use crate::scalar::{Real, Singular, Site};
use crate::solve::{NoConvergence, solve_spd};

/// Pivot threshold of `Φ_d`'s LU (columns scaled to unit norm): a pivot `|p| ≤ 1e-4` is a
/// configuration where the independent coordinates (nearly) fail to determine the others. The
/// velocity terms carry `Φ_d⁻¹` twice, so rounding grows like `ε/p²`; `1e-4` keeps it near
/// `1e-8` (the same reasoning as [`crate::parallel::noc::LEG_TOLERANCE`]).
pub const CONSTRAINT_TOLERANCE: f64 = 1e-4;
/// Closure tolerance of the inputs: a kept loop equation larger than `1e-9` (times the
/// mechanism's size for the point equations, in m; as is for the axis equations) means `x`
/// does not close the loops: `Singular { site: Closure(k) }`.
pub const CLOSURE_TOLERANCE: f64 = 1e-9;
/// Newton (forward kinematics): at most this many iterations.
pub const FK_MAX_ITERATIONS: usize = 50;
/// Forward kinematics follows the path from the guess's independent coordinates to the
/// target in stages of at most this (rad; times the mechanism's size for a prismatic joint).
pub const FK_STEP: f64 = 0.25;
/// At most this many stages (longer stages beyond `FK_MAX_STAGES × FK_STEP`).
pub const FK_MAX_STAGES: usize = 64;
/// Newton converges when every kept loop equation is within `1e-12` (point equations times
/// the mechanism's size).
pub const FK_TOLERANCE: f64 = 1e-12;
/// Newton's result must also satisfy every loop equation (the redundant ones) and keep the
/// revolute axes aligned within this (scaled); else it is a spurious branch of the kept ones.
pub const FULL_TOLERANCE: f64 = 1e-9;
/// A spring shorter than this times the mechanism's size has no direction:
/// `Singular { site: Spring(k) }`.
pub const SPRING_TOLERANCE: f64 = 1e-9;
/// Rank tolerance of the home analysis, relative to `‖J‖_F` of the dimensionless loop
/// Jacobian (point rows over the size, prismatic columns times it): a residual at or below it
/// is zero. The loops close at home only to within [`super::HOME_TOLERANCE`], which leaves
/// residuals near that in redundant rows (1.9e-10 measured on the Bricard linkage opened by
/// 0.9e-9 rad), so ten times it; rounding leaves about `ε‖J‖` (1e-16), genuine rows 1e-1 on
/// the bundled loops.
pub const RANK_TOLERANCE: f64 = 1e-8;

/// One kept loop equation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Row {
    /// Component `k` (base frame) of `P_child − P_parent` of cut `cut`.
    Point {
        /// Cut index.
        cut: usize,
        /// Base-frame component.
        k: usize,
    },
    /// `n · m` of cut `cut`: `n` its axis on the parent side, `m` (in the child body's frame)
    /// one of the two unit vectors perpendicular to the axis at home.
    Axis {
        /// Cut index.
        cut: usize,
        /// `m` in the child body's frame.
        m: Vec3,
    },
}

/// One tree joint's constant data.
#[derive(Clone, Debug)]
pub struct JointPlan {
    /// Parent body (`None`: base).
    pub parent: Option<usize>,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Joint frame at `x = 0` in the parent body frame.
    pub origin: Transform,
    /// Unit axis in the joint frame.
    pub axis: Vec3,
    /// Body mass, mass centre, inertia (body frame).
    pub body: (f64, Vec3, Mat3),
    /// Friction and rotor inertia at this joint (actuated or passive).
    pub drive: crate::model::Drive,
}

/// One cut joint's constant data.
#[derive(Clone, Debug)]
pub struct CutPlan {
    /// Parent body (`None`: base).
    pub parent: Option<usize>,
    /// Child body (`None`: base).
    pub child: Option<usize>,
    /// The joint point in the parent's body frame.
    pub point_parent: Vec3,
    /// The joint point in the child's body frame.
    pub point_child: Vec3,
    /// Revolute: the axis in the parent's body frame.
    pub axis_parent: Option<Vec3>,
    /// Revolute: the axis in the child's body frame (closed loops have it equal to the
    /// parent's, not opposite).
    pub axis_child: Option<Vec3>,
}

/// What the evaluators need, prepared and checked once.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Gravity (base frame).
    pub gravity: Vec3,
    /// Tree joints.
    pub joints: Vec<JointPlan>,
    /// Cut joints.
    pub cuts: Vec<CutPlan>,
    /// The kept loop equations (`NX − DOF` of them).
    pub rows: Vec<Row>,
    /// The redundant loop equations not identically zero at home (an overconstrained loop's,
    /// such as Bricard's): spare rows of `Φ_d`'s LU, whose partial pivoting then chooses, at
    /// each configuration, which `NX − DOF` of the kept and spare equations to solve (the set
    /// chosen at home can become ill-conditioned away from it). Planar loops have none (their
    /// redundant rows vanish identically).
    pub spare: Vec<Row>,
    /// Every loop equation (the kept ones and the redundant ones), for the closure checks.
    pub all_rows: Vec<Row>,
    /// Independent joints (in order).
    pub independent: Vec<usize>,
    /// Dependent joints, in the order of the columns of `Φ_d` (banded: see `band_order`).
    pub dependent: Vec<usize>,
    /// `anc[b][j]`: joint `j` moves body `b`.
    pub anc: Vec<Vec<bool>>,
    /// The mechanism's size (m).
    pub size: f64,
    /// Spring-dampers.
    pub springs: Vec<super::Spring>,
}

impl Plan {
    /// Validate `model`, choose the kept loop equations at home and check the mobility.
    pub fn new(model: &ClosedModel) -> Result<Plan, alloc::string::String> {
        model.validate()?;
        let tree = &model.tree;
        let n = tree.dof();
        let joints = joint_plans(tree);
        let cuts: Vec<CutPlan> = model
            .cuts
            .iter()
            .map(|c| CutPlan {
                parent: c.parent,
                child: c.child,
                point_parent: c.frame_parent.translation,
                point_child: c.frame_child.translation,
                axis_parent: match c.kind {
                    CutKind::Revolute { axis } => Some(mat_vec(&c.frame_parent.rotation, &axis)),
                    CutKind::Spherical => None,
                },
                axis_child: match c.kind {
                    CutKind::Revolute { axis } => Some(mat_vec(&c.frame_child.rotation, &axis)),
                    CutKind::Spherical => None,
                },
            })
            .collect();
        // Candidate rows: per cut, the three point rows, then (revolute) two axis rows.
        let mut candidates: Vec<Row> = Vec::new();
        for (ci, c) in model.cuts.iter().enumerate() {
            for k in 0..3 {
                candidates.push(Row::Point { cut: ci, k });
            }
            if let CutKind::Revolute { axis } = c.kind {
                let (p1, p2) = perpendiculars(&axis);
                for p in [p1, p2] {
                    candidates.push(Row::Axis {
                        cut: ci,
                        m: mat_vec(&c.frame_child.rotation, &p),
                    });
                }
            }
        }
        let independent = model.independent.clone();
        let dependent: Vec<usize> = (0..n).filter(|j| !independent.contains(j)).collect();
        let mut plan = Plan {
            gravity: tree.gravity,
            joints,
            cuts,
            rows: candidates.clone(),
            spare: Vec::new(),
            all_rows: candidates.clone(),
            independent,
            dependent,
            anc: ancestry(tree),
            size: model.size(),
            springs: model.springs.clone(),
        };
        // The Jacobian of every candidate at home, made dimensionless: point rows divided by
        // the size, prismatic columns multiplied by it (a slide of one size weighs as a turn of
        // one radian). Rounding leaves entries that are zero in exact arithmetic at about
        // `ε‖J‖` (a loop turned in space): the rank decisions below take a residual as zero up
        // to `tol = RANK_TOLERANCE · ‖J‖_F`, never up to exactly zero.
        let x0 = vec![0.0; n];
        let kin = kinematics(&plan, &x0);
        let jac: Vec<Vec<f64>> = candidates
            .iter()
            .map(|r| {
                let s = row_scale(&plan, r);
                let row = jacobian_row(&plan, &kin, r);
                (0..n).map(|j| row[j] * col_scale(&plan, j) / s).collect()
            })
            .collect();
        let tol = RANK_TOLERANCE * norm(&jac.concat());
        let nd = plan.dependent.len();
        // Mobility at home: NX − rank of the loop equations (all columns).
        let rank = numerical_rank(&jac, tol);
        if n - rank != plan.independent.len() {
            return Err(alloc::format!(
                "the mechanism has {} degree(s) of freedom at home ({n} joint coordinates, {rank} independent loop equations) but {} joint(s) are actuated; mark one actuated joint per degree of freedom",
                n - rank,
                plan.independent.len()
            ));
        }
        // Greedy Gram–Schmidt over the dependent columns on unit rows (the best conditioned
        // next row first); a row counts only while its residual, at the row's own size,
        // exceeds `tol`.
        let dep = |row: &[f64]| -> Vec<f64> { plan.dependent.iter().map(|&j| row[j]).collect() };
        let dep_norm: Vec<f64> = jac.iter().map(|r| norm(&dep(r))).collect();
        let mut resid: Vec<Vec<f64>> = jac
            .iter()
            .zip(&dep_norm)
            .map(|(r, &s)| {
                let d = dep(r);
                if s > tol {
                    d.iter().map(|x| x / s).collect()
                } else {
                    vec![0.0; nd]
                }
            })
            .collect();
        let mut kept: Vec<usize> = Vec::new();
        for _ in 0..nd {
            let mut best = (0usize, -1.0);
            for (i, r) in resid.iter().enumerate() {
                let s = r.iter().map(|x| x * x).sum::<f64>();
                if !kept.contains(&i) && s > best.1 + 1e-12 && libm::sqrt(s) * dep_norm[i] > tol {
                    best = (i, s);
                }
            }
            if best.1 < 0.0 {
                return Err(alloc::format!(
                    "the actuated joints do not determine the others at home: the loop equations have rank {} over the {nd} other joint coordinates (mark a different set of joints as actuated)",
                    kept.len()
                ));
            }
            let s = libm::sqrt(best.1);
            let b: Vec<f64> = resid[best.0].iter().map(|x| x / s).collect();
            kept.push(best.0);
            for r in resid.iter_mut() {
                let d: f64 = r.iter().zip(&b).map(|(x, y)| x * y).sum();
                for (x, y) in r.iter_mut().zip(&b) {
                    *x -= d * y;
                }
            }
        }
        // Mobility: every candidate row (all columns) must depend on the kept ones.
        let mut full: Vec<Vec<f64>> = Vec::new();
        for &k in &kept {
            let r = project_out(&jac[k], &full);
            let s = norm(&r);
            full.push(r.iter().map(|x| x / s).collect());
        }
        for (i, row) in jac.iter().enumerate() {
            if !kept.contains(&i) && norm(&project_out(row, &full)) > tol {
                return Err(alloc::format!(
                    "the loop equations have more independent rows than the {nd} dependent coordinates: the mechanism has fewer degrees of freedom than the {} marked actuated (loop equation {i} of cut {} is independent of the rest)",
                    plan.independent.len(),
                    model.cuts[row_cut(&candidates[i])].name
                ));
            }
        }
        kept.sort_unstable();
        plan.rows = kept.iter().map(|&i| candidates[i]).collect();
        // Spare rows: the other equations whose dependent columns do not vanish at home.
        plan.spare = (0..candidates.len())
            .filter(|i| !kept.contains(i) && dep_norm[*i] > tol)
            .map(|i| candidates[i])
            .collect();
        band_order(&mut plan);
        // The full evaluation must succeed at home.
        let d = plan.independent.len();
        inverse_dynamics(&plan, &x0, &vec![0.0; d], &vec![0.0; d]).map_err(|e| {
            alloc::format!("the mechanism is singular at its home configuration ({e})")
        })?;
        Ok(plan)
    }

    /// A tree as a mechanism without loops: every joint independent, no loop equations. The
    /// same generic evaluator then gives the tree's dynamics over any scalar (e.g. a
    /// double-double reference for the speed/accuracy chart).
    pub fn tree(tree: &crate::model::Model) -> Plan {
        Plan {
            gravity: tree.gravity,
            joints: joint_plans(tree),
            cuts: Vec::new(),
            rows: Vec::new(),
            spare: Vec::new(),
            all_rows: Vec::new(),
            independent: (0..tree.dof()).collect(),
            dependent: Vec::new(),
            anc: ancestry(tree),
            size: 1.0,
            springs: Vec::new(),
        }
    }

    /// Position coordinates (tree joints).
    pub fn nx(&self) -> usize {
        self.joints.len()
    }
    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.independent.len()
    }
    /// The rows of `Φ_d`'s LU: the kept loop equations, then the spare ones.
    pub fn system_rows(&self) -> impl Iterator<Item = &Row> {
        self.rows.iter().chain(&self.spare)
    }
}

/// The tree's joints with their bodies' inertial data.
fn joint_plans(tree: &crate::model::Model) -> Vec<JointPlan> {
    tree.joints
        .iter()
        .zip(&tree.bodies)
        .map(|(j, b)| JointPlan {
            parent: j.parent,
            kind: j.kind,
            origin: j.origin,
            axis: j.axis,
            body: (b.mass, b.com, b.inertia),
            drive: j.drive,
        })
        .collect()
}

/// Order the dependent coordinates (the columns of `Φ_d`) and the loop equations (its rows)
/// for a narrow band: a chain of loops (the N-four-bar, a ladder) written in any order then
/// factorizes in `O(n)` instead of `O(n³)`, since the generated LU's pivot selects only mix
/// rows that share a column. Columns by reverse Cuthill–McKee over "appear in the same
/// equation" (structurally: the joints that move either body of the equation's cut), rows by
/// their first and last column; the spec's order stays where this does not make the LU
/// cheaper (counted on the structural pattern) and for fewer than eight dependent coordinates.
fn band_order(plan: &mut Plan) {
    // Below this many dependent coordinates the dense LU costs a few dozen selects at most:
    // the spec's order stays (and with it the rounding of the bundled small loops).
    const BAND_MIN: usize = 8;
    let nd = plan.dependent.len();
    let col_of = |j: usize| plan.dependent.iter().position(|&d| d == j);
    let pattern = |r: &Row| -> Vec<usize> {
        let c = &plan.cuts[row_cut(r)];
        let moves = |b: Option<usize>, j: usize| b.is_some_and(|b| plan.anc[b][j]);
        (0..plan.joints.len())
            .filter(|&j| moves(c.parent, j) || moves(c.child, j))
            .filter_map(col_of)
            .collect()
    };
    let rows: Vec<Vec<usize>> = plan.rows.iter().chain(&plan.spare).map(pattern).collect();
    let mut adj = vec![Vec::<usize>::new(); nd];
    for r in &rows {
        for &a in r {
            for &b in r {
                if a != b && !adj[a].contains(&b) {
                    adj[a].push(b);
                }
            }
        }
    }
    let mut order: Vec<usize> = Vec::with_capacity(nd);
    let mut seen = vec![false; nd];
    while order.len() < nd {
        let start = (0..nd)
            .filter(|&c| !seen[c])
            .min_by_key(|&c| (adj[c].len(), c))
            .unwrap_or(0);
        seen[start] = true;
        let mut head = order.len();
        order.push(start);
        while head < order.len() {
            let mut next: Vec<usize> = adj[order[head]]
                .iter()
                .copied()
                .filter(|&c| !seen[c])
                .collect();
            next.sort_by_key(|&c| (adj[c].len(), c));
            for c in next {
                seen[c] = true;
                order.push(c);
            }
            head += 1;
        }
    }
    order.reverse();
    // The cost of the LU (as the generator sees it) in a column order: the entries that the
    // swap selects and the eliminations touch, on the structural pattern. Rows in the order
    // they get below.
    let lu_cost = |pos: &[usize]| -> usize {
        let mut m: Vec<Vec<bool>> = rows
            .iter()
            .map(|r| {
                let mut row = vec![false; nd];
                for &c in r {
                    row[pos[c]] = true;
                }
                row
            })
            .collect();
        m.sort_by_key(|r| (r.iter().position(|&v| v), r.iter().rposition(|&v| v)));
        let mut cost = 0;
        for k in 0..nd.min(m.len()) {
            for i in k + 1..m.len() {
                if m[i][k] {
                    for j in k..nd {
                        let v = m[i][j] || m[k][j];
                        cost += usize::from(v);
                        m[i][j] = v;
                        m[k][j] = v;
                    }
                }
            }
            for i in k + 1..m.len() {
                if m[i][k] {
                    for j in k + 1..nd {
                        cost += usize::from(m[k][j]);
                        m[i][j] |= m[k][j];
                    }
                }
            }
        }
        cost
    };
    let mut pos = vec![0; nd];
    for (p, &c) in order.iter().enumerate() {
        pos[c] = p;
    }
    let identity: Vec<usize> = (0..nd).collect();
    if nd < BAND_MIN || lu_cost(&pos) >= lu_cost(&identity) {
        pos = identity;
    }
    let mut dependent = plan.dependent.clone();
    for (c, &p) in pos.iter().enumerate() {
        dependent[p] = plan.dependent[c];
    }
    let key = |r: &Row| {
        let cols = pattern(r);
        (
            cols.iter().map(|&c| pos[c]).min().unwrap_or(usize::MAX),
            cols.iter().map(|&c| pos[c]).max().unwrap_or(0),
        )
    };
    let mut kept = plan.rows.clone();
    kept.sort_by_key(|r| key(r));
    let mut spare = plan.spare.clone();
    spare.sort_by_key(|r| key(r));
    plan.rows = kept;
    plan.spare = spare;
    plan.dependent = dependent;
}

fn row_cut(r: &Row) -> usize {
    match r {
        Row::Point { cut, .. } | Row::Axis { cut, .. } => *cut,
    }
}

/// Tree kinematics at `x` (base frame).
#[derive(Clone, Debug)]
pub struct Kin<R> {
    /// Body rotations (body → base).
    pub rot: Vec<M<R>>,
    /// Body origins.
    pub pos: Vec<V<R>>,
    /// Joint axes.
    pub e: Vec<V<R>>,
    /// Joint points (the joint frame's origin before a prismatic displacement).
    pub o: Vec<V<R>>,
}

/// Body poses, joint axes and points at `x`.
pub fn kinematics<R: Real>(plan: &Plan, x: &[R]) -> Kin<R> {
    let n = plan.nx();
    let mut k = Kin {
        rot: Vec::with_capacity(n),
        pos: Vec::with_capacity(n),
        e: Vec::with_capacity(n),
        o: Vec::with_capacity(n),
    };
    for (i, j) in plan.joints.iter().enumerate() {
        let (rp, pp) = match j.parent {
            Some(p) => (k.rot[p], k.pos[p]),
            None => (ident::<R>(), zero3::<R>()),
        };
        let r0 = mm(&rp, &cm(&j.origin.rotation));
        let o = add(pp, mv(&rp, cv(&j.origin.translation)));
        let e = mv(&r0, cv(&j.axis));
        let (r, p) = match j.kind {
            JointKind::Revolute => {
                let (s, c) = x[i].sin_cos();
                (mm(&r0, &rot(&j.axis, s, c)), o)
            }
            JointKind::Prismatic => (r0, add(o, scale(x[i], e))),
        };
        k.rot.push(r);
        k.pos.push(p);
        k.e.push(e);
        k.o.push(o);
    }
    k
}

fn point_of<R: Real>(k: &Kin<R>, body: Option<usize>, local: &Vec3) -> V<R> {
    match body {
        Some(b) => add(k.pos[b], mv(&k.rot[b], cv(local))),
        None => cv(local),
    }
}

fn dir_of<R: Real>(k: &Kin<R>, body: Option<usize>, local: &Vec3) -> V<R> {
    match body {
        Some(b) => mv(&k.rot[b], cv(local)),
        None => cv(local),
    }
}

/// The value of a loop equation at `x`.
fn row_value<R: Real>(plan: &Plan, k: &Kin<R>, r: &Row) -> R {
    match *r {
        Row::Point { cut, k: i } => {
            let c = &plan.cuts[cut];
            let a = point_of(k, c.parent, &c.point_parent);
            let b = point_of(k, c.child, &c.point_child);
            b[i] - a[i]
        }
        Row::Axis { cut, m } => {
            let c = &plan.cuts[cut];
            let n = dir_of(k, c.parent, &c.axis_parent.unwrap_or([0.0; 3]));
            let mm_ = dir_of(k, c.child, &m);
            dot(n, mm_)
        }
    }
}

/// `n_parent · n_child − 1` of revolute cut `cut` (zero when the axes are aligned, `−2` when
/// opposite: the axis equations `n·m = 0` hold for both).
fn alignment<R: Real>(plan: &Plan, k: &Kin<R>, cut: usize) -> Option<R> {
    let c = &plan.cuts[cut];
    let (a, b) = (c.axis_parent?, c.axis_child?);
    Some(dot(dir_of(k, c.parent, &a), dir_of(k, c.child, &b)) - R::c(1.0))
}

/// `+1` for joints that move `child` only, `−1` for those that move `parent` only, else 0.
fn side(plan: &Plan, parent: Option<usize>, child: Option<usize>, j: usize) -> i32 {
    let on = |b: Option<usize>| b.map(|b| plan.anc[b][j]).unwrap_or(false);
    match (on(child), on(parent)) {
        (true, false) => 1,
        (false, true) => -1,
        _ => 0,
    }
}

/// The Jacobian row of a loop equation over all joints.
fn jacobian_row<R: Real>(plan: &Plan, k: &Kin<R>, r: &Row) -> Vec<R> {
    let n = plan.nx();
    let mut out = vec![R::c(0.0); n];
    match *r {
        Row::Point { cut, k: i } => {
            let c = &plan.cuts[cut];
            let p = point_of(k, c.child, &c.point_child);
            for j in 0..n {
                let s = side(plan, c.parent, c.child, j);
                if s == 0 {
                    continue;
                }
                let col = match plan.joints[j].kind {
                    JointKind::Revolute => cross(k.e[j], sub(p, k.o[j])),
                    JointKind::Prismatic => k.e[j],
                };
                out[j] = if s > 0 { col[i] } else { -col[i] };
            }
        }
        Row::Axis { cut, m } => {
            let c = &plan.cuts[cut];
            let nv = dir_of(k, c.parent, &c.axis_parent.unwrap_or([0.0; 3]));
            let w = cross(dir_of(k, c.child, &m), nv);
            for j in 0..n {
                let s = side(plan, c.parent, c.child, j);
                if s == 0 || is_prismatic_plan(plan, j) {
                    continue;
                }
                let v = dot(k.e[j], w);
                out[j] = if s > 0 { v } else { -v };
            }
        }
    }
    out
}

fn is_prismatic_plan(plan: &Plan, j: usize) -> bool {
    plan.joints[j].kind == JointKind::Prismatic
}

/// A body's motion: angular velocity `w` and acceleration `alpha`, the velocity `v` and
/// acceleration `a` of its material point at its joint point `o`.
#[derive(Clone, Copy, Debug)]
pub struct BodyMotion<R> {
    /// Angular velocity.
    pub w: V<R>,
    /// Angular acceleration.
    pub alpha: V<R>,
    /// Velocity of the material point at `o`.
    pub v: V<R>,
    /// Acceleration of the material point at `o`.
    pub a: V<R>,
}

impl<R: Real> BodyMotion<R> {
    fn at_rest() -> Self {
        BodyMotion {
            w: zero3(),
            alpha: zero3(),
            v: zero3(),
            a: zero3(),
        }
    }
    /// Velocity of the material point at `x`, knowing the motion at `o`.
    fn vel_at(&self, o: V<R>, x: V<R>) -> V<R> {
        add(self.v, cross(self.w, sub(x, o)))
    }
    /// Acceleration of the material point at `x`.
    fn accel_at(&self, o: V<R>, x: V<R>) -> V<R> {
        self.accel_rel(sub(x, o))
    }
    /// Velocity of the material point at `o + r`.
    fn vel_rel(&self, r: V<R>) -> V<R> {
        add(self.v, cross(self.w, r))
    }
    /// Acceleration of the material point at `o + r`.
    fn accel_rel(&self, r: V<R>) -> V<R> {
        add(
            add(self.a, cross(self.alpha, r)),
            cross(self.w, cross(self.w, r)),
        )
    }
}

/// Body motions by the tree recursion (the lecture's eqs. 25–26, 33): `ω = ω_p + ẋ e`,
/// `ω̇ = ω̇_p + ẍ e + ẋ ω_p × e` (R); `a(o) = a_p(o) + ẍ e + 2 ẋ ω_p × e` (P). `xdd = None`: `ẍ = 0`.
pub fn motions<R: Real>(
    plan: &Plan,
    k: &Kin<R>,
    xd: &[R],
    xdd: Option<&[R]>,
) -> Vec<BodyMotion<R>> {
    let n = plan.nx();
    let mut out: Vec<BodyMotion<R>> = Vec::with_capacity(n);
    for i in 0..n {
        let o = k.o[i];
        let (w0, al0, v0, a0) = match plan.joints[i].parent {
            None => (zero3(), zero3(), zero3(), zero3()),
            Some(p) => {
                let m = &out[p];
                (m.w, m.alpha, m.vel_at(k.o[p], o), m.accel_at(k.o[p], o))
            }
        };
        let e = k.e[i];
        let we = cross(w0, e);
        let qdd_e = match xdd {
            Some(a) => scale(a[i], e),
            None => zero3(),
        };
        out.push(match plan.joints[i].kind {
            JointKind::Revolute => BodyMotion {
                w: add(w0, scale(xd[i], e)),
                alpha: add(add(al0, qdd_e), scale(xd[i], we)),
                v: v0,
                a: a0,
            },
            JointKind::Prismatic => BodyMotion {
                w: w0,
                alpha: al0,
                v: add(v0, scale(xd[i], e)),
                a: add(add(a0, qdd_e), scale(R::c(2.0) * xd[i], we)),
            },
        });
    }
    out
}

fn motion_of<R: Real>(m: &[BodyMotion<R>], body: Option<usize>) -> BodyMotion<R> {
    body.map(|b| m[b]).unwrap_or_else(BodyMotion::at_rest)
}

fn origin_of<R: Real>(k: &Kin<R>, body: Option<usize>) -> V<R> {
    body.map(|b| k.o[b]).unwrap_or_else(zero3)
}

/// `Φ̇ ẋ` of a kept loop equation from the body motions with `ẍ = 0`.
fn row_bias<R: Real>(plan: &Plan, k: &Kin<R>, m: &[BodyMotion<R>], r: &Row) -> R {
    match *r {
        Row::Point { cut, k: i } => {
            let c = &plan.cuts[cut];
            let p = point_of(k, c.child, &c.point_child);
            let ab = motion_of(m, c.child).accel_at(origin_of(k, c.child), p);
            let aa = motion_of(m, c.parent).accel_at(origin_of(k, c.parent), p);
            ab[i] - aa[i]
        }
        Row::Axis { cut, m: ml } => {
            let c = &plan.cuts[cut];
            let n = dir_of(k, c.parent, &c.axis_parent.unwrap_or([0.0; 3]));
            let mv_ = dir_of(k, c.child, &ml);
            let (ma, mb) = (motion_of(m, c.parent), motion_of(m, c.child));
            let dw = sub(mb.w, ma.w);
            let da = sub(mb.alpha, ma.alpha);
            // d/dt[(ω_b − ω_a)·(m × n)] with ṁ = ω_b × m, ṅ = ω_a × n.
            let mdot_n = cross(cross(mb.w, mv_), n);
            let m_ndot = cross(mv_, cross(ma.w, n));
            dot(da, cross(mv_, n)) + dot(dw, add(mdot_n, m_ndot))
        }
    }
}

/// An LU factorization with partial pivoting (data-dependent row swaps recorded as the
/// compared magnitudes), of a matrix with columns scaled to unit norm and at least as many
/// rows as columns: the pivoting chooses the `n` rows solved, the others (spare rows, after
/// the swaps the last ones) are left out.
#[derive(Clone, Debug)]
pub struct Lu<R> {
    m: Vec<Vec<R>>,
    swaps: Vec<(usize, usize, R, R)>,
    sc: Vec<R>,
}

/// Factorize `a` (`nr ≥ n` rows, `n` columns); a column of zero norm or a pivot
/// `|p| ≤ CONSTRAINT_TOLERANCE` is `Singular { site: Constraint(i) }` (condition estimate
/// `1/|p|`).
pub fn lu_factor<R: Real>(a: &[Vec<R>]) -> Result<Lu<R>, Singular> {
    let nr = a.len();
    let n = a.first().map_or(0, Vec::len);
    let mut sc = Vec::with_capacity(n);
    for j in 0..n {
        let mut s = R::c(0.0);
        for i in 0..nr {
            s = s + a[i][j] * a[i][j];
        }
        let s = R::check(s, R::c(0.0), R::c(1.0), Site::Constraint(j), false)?;
        sc.push(R::c(1.0) / s.sqrt());
    }
    let mut m: Vec<Vec<R>> = (0..nr)
        .map(|i| (0..n).map(|j| a[i][j] * sc[j]).collect())
        .collect();
    let mut swaps = Vec::new();
    for k in 0..n {
        // Rows swapped in the active columns only, the multipliers left where they were
        // computed (LINPACK's `dgefa`; the solves replay the swaps step by step). Swapping
        // whole rows (LAPACK's convention) is the same arithmetic, but as selects it carries
        // every earlier multiplier down each candidate row, and a banded `Φ_d` (a chain of
        // loops) becomes a dense `L` in the generated code.
        for i in k + 1..nr {
            let (p, q) = (m[i][k], m[k][k]);
            swaps.push((k, i, p, q));
            for j in k..n {
                let (x, y) = (m[i][j], m[k][j]);
                m[k][j] = R::select_abs_gt(p, q, x, y);
                m[i][j] = R::select_abs_gt(p, q, y, x);
            }
        }
        let piv = R::check(
            m[k][k],
            R::c(R::tolerance(CONSTRAINT_TOLERANCE)),
            R::c(1.0),
            Site::Constraint(k),
            true,
        )?;
        let inv = R::c(1.0) / piv;
        for i in k + 1..nr {
            let f = m[i][k] * inv;
            m[i][k] = f;
            for j in k + 1..n {
                m[i][j] = m[i][j] - f * m[k][j];
            }
        }
    }
    Ok(Lu { m, swaps, sc })
}

impl<R: Real> Lu<R> {
    /// Solve `a x = b` (`b` over every row of `a`; the rows the pivoting left out are not
    /// used).
    pub fn solve(&self, b: &[R]) -> Vec<R> {
        let n = self.sc.len();
        let nr = self.m.len();
        let mut x = b.to_vec();
        // `L⁻¹P`: each step's swaps, then its column of multipliers (`dgesl`).
        let mut swaps = self.swaps.iter().peekable();
        for k in 0..n {
            while let Some(&(_, i, p, q)) = swaps.next_if(|s| s.0 == k) {
                let (xi, xk) = (x[i], x[k]);
                x[k] = R::select_abs_gt(p, q, xi, xk);
                x[i] = R::select_abs_gt(p, q, xk, xi);
            }
            for i in k + 1..nr {
                x[i] = x[i] - self.m[i][k] * x[k];
            }
        }
        for i in (0..n).rev() {
            for j in i + 1..n {
                x[i] = x[i] - self.m[i][j] * x[j];
            }
            x[i] = x[i] / self.m[i][i];
        }
        x.truncate(n);
        for i in 0..n {
            x[i] = x[i] * self.sc[i];
        }
        x
    }

    /// Solve `aₛᵀ y = b`, `aₛ` the rows of `a` the pivoting chose (`y` over every row of `a`,
    /// zero on the others).
    pub fn solve_t(&self, b: &[R]) -> Vec<R> {
        let n = b.len();
        let mut z: Vec<R> = (0..n).map(|i| b[i] * self.sc[i]).collect();
        // Uᵀ z' = D b (forward).
        for i in 0..n {
            for j in 0..i {
                z[i] = z[i] - self.m[j][i] * z[j];
            }
            z[i] = z[i] / self.m[i][i];
        }
        // `(L⁻¹P)ᵀ`: step by step backwards, its column of multipliers, then its swaps in
        // reverse (the spare rows start at zero).
        let nr = self.m.len();
        z.resize(nr, R::c(0.0));
        let mut swaps = self.swaps.iter().rev().peekable();
        for k in (0..n).rev() {
            for i in k + 1..nr {
                z[k] = z[k] - self.m[i][k] * z[i];
            }
            while let Some(&(_, i, p, q)) = swaps.next_if(|s| s.0 == k) {
                let (zi, zk) = (z[i], z[k]);
                z[k] = R::select_abs_gt(p, q, zi, zk);
                z[i] = R::select_abs_gt(p, q, zk, zi);
            }
        }
        z
    }
}

/// The configuration-level quantities shared by every function.
pub struct Config<R> {
    /// Tree kinematics.
    pub kin: Kin<R>,
    /// Jacobian rows of the kept equations, then the spare ones (all joints).
    pub jac: Vec<Vec<R>>,
    /// LU of `Φ_d`.
    pub lu: Lu<R>,
    /// The checked values of the closure tests (with `check`). Nothing else uses them: a
    /// generator keeps every test it was asked for as a root of the function's DAG.
    pub checks: Vec<R>,
    /// Each spring's length `L` and unit direction `n` (from its first point to its second).
    pub springs: Vec<(R, V<R>)>,
}

/// Kinematics, the loop Jacobian and the LU of `Φ_d` at `x`; with `check`, the kept loop
/// equations must hold within [`CLOSURE_TOLERANCE`].
pub fn configuration<R: Real>(plan: &Plan, x: &[R], check: bool) -> Result<Config<R>, Singular> {
    let kin = kinematics(plan, x);
    let mut checks = Vec::new();
    if check {
        for (i, r) in plan.rows.iter().enumerate() {
            let tol = R::tolerance(CLOSURE_TOLERANCE) * row_scale(plan, r);
            let v = row_value(plan, &kin, r);
            // |Φ| < tol  ⇔  tol² − Φ² > 0.
            checks.push(R::check(
                R::c(tol * tol) - v * v,
                R::c(0.0),
                R::c(tol * tol),
                Site::Closure(i),
                false,
            )?);
        }
    }
    if check {
        for cut in 0..plan.cuts.len() {
            if let Some(a) = alignment(plan, &kin, cut) {
                // Aligned, not opposite: n_a·n_b > 0.
                checks.push(R::check(
                    a + R::c(1.0),
                    R::c(0.0),
                    R::c(1.0),
                    Site::Closure(plan.rows.len() + cut),
                    false,
                )?);
            }
        }
    }
    let jac: Vec<Vec<R>> = plan
        .system_rows()
        .map(|r| jacobian_row(plan, &kin, r))
        .collect();
    let phid: Vec<Vec<R>> = jac
        .iter()
        .map(|row| plan.dependent.iter().map(|&j| row[j]).collect())
        .collect();
    let lu = lu_factor(&phid)?;
    // Springs: a length above `SPRING_TOLERANCE` times the size, else no direction.
    let mut springs = Vec::with_capacity(plan.springs.len());
    for (i, s) in plan.springs.iter().enumerate() {
        let d = sub(
            point_of(&kin, s.body_b, &s.point_b),
            point_of(&kin, s.body_a, &s.point_a),
        );
        let tol = R::tolerance(SPRING_TOLERANCE) * plan.size;
        let l2 = R::check(
            dot(d, d),
            R::c(tol * tol),
            R::c(plan.size * plan.size),
            Site::Spring(i),
            false,
        )?;
        let l = l2.sqrt();
        let inv = R::c(1.0) / l;
        springs.push((l, scale(inv, d)));
    }
    Ok(Config {
        kin,
        jac,
        lu,
        checks,
        springs,
    })
}

fn row_scale(plan: &Plan, r: &Row) -> f64 {
    match r {
        Row::Point { .. } => plan.size,
        Row::Axis { .. } => 1.0,
    }
}

/// The weight of joint `j`'s column in the home analysis: 1 for a revolute (rad), the size for
/// a prismatic joint (m), so that every column is per unit of dimensionless motion.
fn col_scale(plan: &Plan, j: usize) -> f64 {
    match plan.joints[j].kind {
        JointKind::Revolute => 1.0,
        JointKind::Prismatic => plan.size,
    }
}

fn norm(v: &[f64]) -> f64 {
    libm::sqrt(v.iter().map(|x| x * x).sum::<f64>())
}

/// `v` minus its components along the orthonormal `basis`.
fn project_out(v: &[f64], basis: &[Vec<f64>]) -> Vec<f64> {
    let mut r = v.to_vec();
    for b in basis {
        let d: f64 = r.iter().zip(b).map(|(x, y)| x * y).sum();
        for (x, y) in r.iter_mut().zip(b) {
            *x -= d * y;
        }
    }
    r
}

/// The numerical rank of `rows` at threshold `tol`: Gram–Schmidt with pivoting on the largest
/// residual (QR with column pivoting of the transpose, Businger & Golub 1965), counting the
/// steps whose pivot residual exceeds `tol` (Golub & Van Loan, "numerical rank"), at most one
/// per column.
fn numerical_rank(rows: &[Vec<f64>], tol: f64) -> usize {
    let mut resid: Vec<Vec<f64>> = rows.to_vec();
    let mut done = vec![false; rows.len()];
    let width = rows.first().map_or(0, Vec::len);
    let mut rank = 0;
    while rank < width {
        let best = (0..resid.len())
            .filter(|&i| !done[i])
            .map(|i| (i, norm(&resid[i])))
            .fold(None, |b: Option<(usize, f64)>, c| match b {
                Some(b) if b.1 >= c.1 => Some(b),
                _ => Some(c),
            });
        let Some((i, s)) = best.filter(|b| b.1 > tol) else {
            return rank;
        };
        done[i] = true;
        rank += 1;
        let b = [resid[i].iter().map(|x| x / s).collect::<Vec<f64>>()];
        for (k, r) in resid.iter_mut().enumerate() {
            if !done[k] {
                *r = project_out(r, &b);
            }
        }
    }
    rank
}

/// All joint rates `ẋ = S u` (`ẋ_d = −Φ_d⁻¹ Φ_i u`).
pub fn joint_rates_generic<R: Real>(plan: &Plan, c: &Config<R>, u: &[R]) -> Vec<R> {
    let rhs: Vec<R> = c
        .jac
        .iter()
        .map(|row| {
            plan.independent
                .iter()
                .zip(u)
                .fold(R::c(0.0), |s, (&j, &uj)| s - row[j] * uj)
        })
        .collect();
    let xd_d = c.lu.solve(&rhs);
    let mut xd = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.independent.iter().enumerate() {
        xd[j] = u[k];
    }
    for (k, &j) in plan.dependent.iter().enumerate() {
        xd[j] = xd_d[k];
    }
    xd
}

/// Values of a closed-loop mechanism given at run time in place of the plan's constants (a
/// generated module's `Params`, where they are symbolic inputs).
#[derive(Clone, Debug)]
pub struct Extras<R> {
    /// Rigid bodies given at run time, each attached to tree body `.0` (its mass centre and
    /// inertia in that body's frame): a payload, and the bodies whose inertial parameters are
    /// run-time parameters (their constants zero in the plan).
    pub payloads: Vec<(usize, Payload<R>)>,
    /// The drives of every tree joint (entry `j`: tree joint `j`), replacing the plan's.
    pub drives: Option<DriveInputs<R>>,
}

impl<R> Extras<R> {
    /// No run-time values: the plan's constants.
    pub fn none() -> Extras<R> {
        Extras {
            payloads: Vec::new(),
            drives: None,
        }
    }
}

/// The generalized force `f = I u̇ + C u − γ` (`γ` only with `gravity`) of the independent
/// coordinates: `f = Tᵀ w`, each body's wrench projected by its twist per unit speed (equal to
/// `Sᵀ τ_T` with the open tree's joint efforts `τ_T`, with less cancellation).
pub fn generalized_force<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    generalized_force_with(plan, c, u, ud, gravity, &Extras::none())
}

/// [`generalized_force`] with run-time [`Extras`].
pub fn generalized_force_with<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
    extras: &Extras<R>,
) -> Vec<R> {
    // The columns of `S` and the bodies' twists per unit speed (for the projection below);
    // `ẋ = S u` from the columns, the independent rates exactly `u`.
    let t = unit_twists(plan, c, extras);
    let mut xd = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.independent.iter().enumerate() {
        xd[j] = u[k];
    }
    for &j in &plan.dependent {
        xd[j] = (1..u.len()).fold(t.rates[0][j] * u[0], |s, k| s + t.rates[k][j] * u[k]);
    }
    let bias_m = motions(plan, &c.kin, &xd, None);
    let rhs: Vec<R> = plan
        .system_rows()
        .zip(&c.jac)
        .map(|(r, row)| {
            let b = row_bias(plan, &c.kin, &bias_m, r);
            plan.independent
                .iter()
                .zip(ud)
                .fold(-b, |s, (&j, &a)| s - row[j] * a)
        })
        .collect();
    let xdd_d = c.lu.solve(&rhs);
    let mut xdd = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.independent.iter().enumerate() {
        xdd[j] = ud[k];
    }
    for (k, &j) in plan.dependent.iter().enumerate() {
        xdd[j] = xdd_d[k];
    }
    let m = motions(plan, &c.kin, &xd, Some(&xdd));
    // Virtual power body by body (the lecture's eqs. 21–24, `f = Tᵀ w` with `T`'s block rows the
    // bodies' twists per unit speed): f_k = Σ_b ω_b⁽ᵏ⁾·n_b + v_b⁽ᵏ⁾·f_b, each body's wrench
    // `w_b = M ṫ + W M t − w^G` (eq. 12) at its mass centre. Not `Sᵀ τ_T`: the open tree's
    // joint efforts hold whole subtrees on long lever arms and cancel in the projection (by up
    // to 1,600 times the result on the bundled loops), and their rounding survives; the
    // bodies' powers cancel far less (≤ 8 times, Bricard's 170).
    let d = plan.dof();
    let g: V<R> = if gravity { cv(&plan.gravity) } else { zero3() };
    let mut f = vec![R::c(0.0); d];
    for b in 0..plan.nx() {
        let (mass, com, inertia) = plan.joints[b].body;
        if mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0) {
            continue;
        }
        let r = offset(&c.kin, b, cv(&com));
        let fb = scale(R::c(mass), sub(m[b].accel_rel(r), g));
        let nb = euler(&c.kin.rot[b], &inertia, m[b].w, m[b].alpha);
        for (k, fk) in f.iter_mut().enumerate() {
            let (w, v) = t.bodies[k][b];
            *fk = *fk + (dot(w, nb) + dot(v, fb));
        }
    }
    for (i, (b, p)) in extras.payloads.iter().enumerate() {
        let rot = &c.kin.rot[*b];
        let r = offset(&c.kin, *b, p.com);
        let fb = scale(p.mass, sub(m[*b].accel_rel(r), g));
        let (wb, ab) = (mtv(rot, m[*b].w), mtv(rot, m[*b].alpha));
        let nb = mv(rot, add(mv(&p.inertia, ab), cross(wb, mv(&p.inertia, wb))));
        for (k, fk) in f.iter_mut().enumerate() {
            let (w, v) = t.payloads[k][i];
            *fk = *fk + (dot(w, nb) + dot(v, fb));
        }
    }
    // Springs (applied forces, counted with gravity): the tension `T = k (L − L₀) + c L̇`
    // does the virtual power `−T L̇`, so each effort gains `T ∂L/∂u_k`, with
    // `∂L/∂u_k = n · (v_b⁽ᵏ⁾ − v_a⁽ᵏ⁾)` at the two points.
    if gravity {
        for (s, &(l, n)) in plan.springs.iter().zip(&c.springs) {
            let dl: Vec<R> = (0..d)
                .map(|k| {
                    let at = |body: Option<usize>, p: &Vec3| -> V<R> {
                        let Some(b) = body else { return zero3() };
                        let (w, v) = t.bodies[k][b];
                        let com = plan.joints[b].body.1;
                        let r = mv(
                            &c.kin.rot[b],
                            cv(&[p[0] - com[0], p[1] - com[1], p[2] - com[2]]),
                        );
                        add(v, cross(w, r))
                    };
                    dot(n, sub(at(s.body_b, &s.point_b), at(s.body_a, &s.point_a)))
                })
                .collect();
            let ldot = (1..d).fold(dl[0] * u[0], |acc, k| acc + dl[k] * u[k]);
            let tension = R::c(s.stiffness) * (l - R::c(s.rest_length)) + R::c(s.damping) * ldot;
            for (fk, g) in f.iter_mut().zip(&dl) {
                *fk = *fk + tension * *g;
            }
        }
    }
    // The drives of every tree joint, actuated or passive: `I_a ẍ + δ(ẋ)`, mapped by `Sᵀ`
    // (the lecture's dissipative term δ).
    for (j, jp) in plan.joints.iter().enumerate() {
        let e = match &extras.drives {
            Some(dr) => dr.effort(j, xd[j], xdd[j]),
            None if jp.drive.is_none() => continue,
            None => drive_effort(&jp.drive, xd[j], xdd[j]),
        };
        for (k, fk) in f.iter_mut().enumerate() {
            *fk = *fk + t.rates[k][j] * e;
        }
    }
    f
}

/// The point `p` of body `b` (body-frame coordinates) relative to the body's joint point,
/// `(pos − o) + R p` (base frame): formed from the difference of the two absolute points, not
/// from the absolute position of `p`, so far from the base origin nothing large cancels (and
/// `pos − o` folds to zero where they coincide).
fn offset<R: Real>(k: &Kin<R>, b: usize, p: V<R>) -> V<R> {
    add(sub(k.pos[b], k.o[b]), mv(&k.rot[b], p))
}

/// Per unit independent speed `u = e_k`: the joint rates (column `k` of `S`), each body's
/// angular velocity and mass-centre velocity, each payload's likewise.
struct UnitTwists<R> {
    rates: Vec<Vec<R>>,
    bodies: Vec<Vec<(V<R>, V<R>)>>,
    payloads: Vec<Vec<(V<R>, V<R>)>>,
}

fn unit_twists<R: Real>(plan: &Plan, c: &Config<R>, extras: &Extras<R>) -> UnitTwists<R> {
    let d = plan.dof();
    let n = plan.nx();
    let mut t = UnitTwists {
        rates: Vec::with_capacity(d),
        bodies: Vec::with_capacity(d),
        payloads: Vec::with_capacity(d),
    };
    for k in 0..d {
        let mut e = vec![R::c(0.0); d];
        e[k] = R::c(1.0);
        let xd = joint_rates_generic(plan, c, &e);
        let m = motions(plan, &c.kin, &xd, None);
        t.payloads.push(
            extras
                .payloads
                .iter()
                .map(|(b, p)| (m[*b].w, m[*b].vel_rel(offset(&c.kin, *b, p.com))))
                .collect(),
        );
        t.rates.push(xd);
        t.bodies.push(
            (0..n)
                .map(|b| {
                    let (_, com, _) = plan.joints[b].body;
                    (m[b].w, m[b].vel_rel(offset(&c.kin, b, cv(&com))))
                })
                .collect(),
        );
    }
    t
}

/// The generalized inertia `I = Sᵀ M_T S` of the independent coordinates, from each body's
/// twist per unit speed (exactly symmetric: the upper triangle mirrored), plus the rotors'
/// `Sᵀ diag(I_a) S`.
pub fn generalized_inertia<R: Real>(plan: &Plan, c: &Config<R>) -> Vec<Vec<R>> {
    generalized_inertia_with(plan, c, &Extras::none())
}

/// [`generalized_inertia`] with run-time [`Extras`].
pub fn generalized_inertia_with<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    extras: &Extras<R>,
) -> Vec<Vec<R>> {
    let d = plan.dof();
    let n = plan.nx();
    let UnitTwists {
        rates,
        bodies: cols,
        payloads: payload_cols,
    } = unit_twists(plan, c, extras);
    let mut out = vec![vec![R::c(0.0); d]; d];
    for b in 0..n {
        let (mass, _, inertia) = plan.joints[b].body;
        if mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0) {
            continue;
        }
        for i in 0..d {
            for j in i..d {
                let (wi, vi) = cols[i][b];
                let (wj, vj) = cols[j][b];
                let v = R::c(mass) * dot(vi, vj) + inertia_quad(&c.kin.rot[b], &inertia, wi, wj);
                out[i][j] = out[i][j] + v;
            }
        }
    }
    for (k, (b, p)) in extras.payloads.iter().enumerate() {
        let rot = &c.kin.rot[*b];
        for i in 0..d {
            for j in i..d {
                let (wi, vi) = payload_cols[i][k];
                let (wj, vj) = payload_cols[j][k];
                let (wbi, wbj) = (mtv(rot, wi), mtv(rot, wj));
                let v = p.mass * dot(vi, vj) + dot(wbi, mv(&p.inertia, wbj));
                out[i][j] = out[i][j] + v;
            }
        }
    }
    for (b, jp) in plan.joints.iter().enumerate() {
        let a = match &extras.drives {
            Some(dr) => match &dr.armature {
                Some(a) => a[b],
                None => continue,
            },
            None if jp.drive.armature == 0.0 => continue,
            None => R::c(jp.drive.armature),
        };
        for i in 0..d {
            for j in i..d {
                out[i][j] = out[i][j] + a * rates[i][b] * rates[j][b];
            }
        }
    }
    for i in 0..d {
        for j in 0..i {
            out[i][j] = out[j][i];
        }
    }
    out
}

/// Forward dynamics: `u̇` with `I u̇ = τ − (C u − γ)`.
pub fn forward_dynamics_generic<R: Real>(
    plan: &Plan,
    x: &[R],
    u: &[R],
    tau: &[R],
) -> Result<Vec<R>, Singular> {
    forward_dynamics_with(plan, x, u, tau, &Extras::none())
}

/// [`forward_dynamics_generic`] with run-time [`Extras`].
pub fn forward_dynamics_with<R: Real>(
    plan: &Plan,
    x: &[R],
    u: &[R],
    tau: &[R],
    extras: &Extras<R>,
) -> Result<Vec<R>, Singular> {
    let c = configuration(plan, x, true)?;
    let d = plan.dof();
    let zero = vec![R::c(0.0); d];
    let h = generalized_force_with(plan, &c, u, &zero, true, extras);
    let rhs: Vec<R> = (0..d).map(|i| tau[i] - h[i]).collect();
    let m = generalized_inertia_with(plan, &c, extras);
    solve_spd(&m, &rhs)
}

/// One Newton step of the kept loop equations at `x` (the independent coordinates held; with
/// spare rows, of those the LU's pivoting chose): the full step `Δx` (zero on the independent
/// coordinates), the largest scaled residual of the kept and spare equations,
/// `max_k |Φ_k| / scale_k`, and that of every loop equation and of the revolute
/// axes' alignment `n_a·n_b − 1` (both signed: the entry of largest magnitude).
pub fn newton_step<R: Real>(plan: &Plan, x: &[R]) -> Result<(Vec<R>, R, R), Singular> {
    let c = configuration(plan, x, false)?;
    let phi: Vec<R> = plan
        .system_rows()
        .map(|r| row_value(plan, &c.kin, r))
        .collect();
    let rhs: Vec<R> = phi.iter().map(|&v| -v).collect();
    let dd = c.lu.solve(&rhs);
    let mut dx = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.dependent.iter().enumerate() {
        dx[j] = dd[k];
    }
    let mut kept = R::c(0.0);
    for (r, &v) in plan.system_rows().zip(&phi) {
        let s = v * R::c(1.0 / row_scale(plan, r));
        kept = R::select_abs_gt(s, kept, s, kept);
    }
    // Converged means every loop equation, the redundant ones too, and the revolute axes
    // aligned (not opposite): the kept equations alone also vanish on spurious branches.
    let mut worst = R::c(0.0);
    for r in &plan.all_rows {
        let s = row_value(plan, &c.kin, r) * R::c(1.0 / row_scale(plan, r));
        worst = R::select_abs_gt(s, worst, s, worst);
    }
    for cut in 0..plan.cuts.len() {
        if let Some(s) = alignment(plan, &c.kin, cut) {
            worst = R::select_abs_gt(s, worst, s, worst);
        }
    }
    Ok((dx, kept, worst))
}

// ---------------------------------------------------------------------------------------------
// f64 API

fn check_finite(inputs: &[&[f64]]) -> Result<(), Singular> {
    crate::solve::check_finite(inputs)
}

fn finite(v: Vec<f64>) -> Result<Vec<f64>, Singular> {
    for &x in &v {
        if !x.is_finite() {
            return Err(Singular {
                site: Site::Input,
                value: x,
                condition_estimate: f64::INFINITY,
            });
        }
    }
    Ok(v)
}

/// All joint rates `ẋ = S u` at the closed configuration `x`.
pub fn joint_rates(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u])?;
    let c = configuration(plan, x, true)?;
    finite(joint_rates_generic(plan, &c, u))
}

/// Generalized forces of the independent coordinates (the actuator efforts, N or N·m) for the
/// motion `(x, u, u̇)`, gravity included.
pub fn inverse_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, ud])?;
    let c = configuration(plan, x, true)?;
    finite(generalized_force(plan, &c, u, ud, true))
}

/// `C u − γ` and friends: the generalized force with a chosen gravity switch.
pub fn generalized_effort(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
    gravity: bool,
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, ud])?;
    let c = configuration(plan, x, true)?;
    finite(generalized_force(plan, &c, u, ud, gravity))
}

/// The kept loop equations at `(x, ẋ)` for integrators in redundant coordinates (all the tree's
/// joint coordinates): their values `Φ(x)`, the Jacobian `Φ_x` (one row per kept equation, `NX`
/// columns) and the acceleration bias `Φ̇_x ẋ`, so that `Φ̈ = Φ_x ẍ + Φ̇_x ẋ`. No factorization:
/// valid at singular configurations too.
pub fn constraints(plan: &Plan, x: &[f64], xd: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>, Vec<f64>) {
    let kin = kinematics(plan, x);
    let m = motions(plan, &kin, xd, None);
    let phi = plan.rows.iter().map(|r| row_value(plan, &kin, r)).collect();
    let jac = plan
        .rows
        .iter()
        .map(|r| jacobian_row(plan, &kin, r))
        .collect();
    let bias = plan
        .rows
        .iter()
        .map(|r| row_bias(plan, &kin, &m, r))
        .collect();
    (phi, jac, bias)
}

/// The generalized inertia of the independent coordinates.
pub fn mass_matrix(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let c = configuration(plan, x, true)?;
    let m = generalized_inertia(plan, &c);
    for row in &m {
        finite(row.clone())?;
    }
    Ok(m)
}

/// Forward dynamics `u̇` for the efforts `tau` of the independent coordinates.
pub fn forward_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    tau: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, tau])?;
    finite(forward_dynamics_generic(plan, x, u, tau)?)
}

/// Condition estimate of the loop equations' dependent block at `x`: the reciprocal of the
/// smallest pivot of the unit-column-scaled, partially pivoted LU of `Φ_d` (1 for orthonormal
/// columns; `∞` where the independent coordinates stop determining the others). The functions
/// return `Err(Constraint)` above `1 / CONSTRAINT_TOLERANCE` = 1e4.
pub fn constraint_condition(plan: &Plan, x: &[f64]) -> f64 {
    let k = kinematics(plan, x);
    let phid: Vec<Vec<f64>> = plan
        .system_rows()
        .map(|r| {
            let row = jacobian_row(plan, &k, r);
            plan.dependent.iter().map(|&j| row[j]).collect()
        })
        .collect();
    // The same factorization without the threshold.
    let n = plan.dependent.len();
    let nr = phid.len();
    let mut m = phid;
    for j in 0..n {
        let s = libm::sqrt((0..nr).map(|i| m[i][j] * m[i][j]).sum::<f64>());
        if !(s > 0.0) {
            return f64::INFINITY;
        }
        for row in m.iter_mut() {
            row[j] /= s;
        }
    }
    let mut smallest = f64::INFINITY;
    for c in 0..n {
        let p = (c..nr)
            .max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()))
            .unwrap_or(c);
        m.swap(c, p);
        let piv = m[c][c];
        smallest = smallest.min(piv.abs());
        if piv == 0.0 {
            return f64::INFINITY;
        }
        for i in c + 1..nr {
            let f = m[i][c] / piv;
            for j in c..n {
                m[i][j] -= f * m[c][j];
            }
        }
    }
    1.0 / smallest
}

/// The largest scaled loop-equation residual at `x` (every equation, m relative to the size
/// or dimensionless, and the revolute axes' alignment), as [`forward_kinematics`] tests it.
pub fn closure_residual(plan: &Plan, x: &[f64]) -> f64 {
    newton_step(plan, x).map_or(f64::INFINITY, |(_, _, r)| r.abs())
}

/// The number of continuation stages from `guess` to the independent coordinates `xi`: no
/// independent coordinate moves more than [`FK_STEP`] (rad, or times the size for a
/// prismatic joint) per stage, at most [`FK_MAX_STAGES`]; 1 for non-finite input.
fn continuation_stages(plan: &Plan, xi: &[f64], guess: &[f64]) -> usize {
    let mut need: f64 = 1.0;
    for (k, &j) in plan.independent.iter().enumerate() {
        let step = match plan.joints[j].kind {
            JointKind::Revolute => FK_STEP,
            JointKind::Prismatic => FK_STEP * plan.size,
        };
        need = need.max(libm::ceil(libm::fabs(xi[k] - guess[j]) / step));
    }
    if need.is_finite() {
        (need as usize).min(FK_MAX_STAGES)
    } else {
        1
    }
}

/// Forward kinematics (assembly): the closed configuration whose independent coordinates are
/// `xi`, on the branch of `guess`. The independent coordinates move from `guess`'s to `xi` in
/// equal stages (`continuation_stages`), each assembled by [`newton_assembly`] from the last
/// (path following: a far target stays on the guess's assembly mode instead of wherever one
/// Newton solve from far away lands). If a stage fails (the straight path crosses a
/// singularity), one Newton solve from `guess` decides, as with a single stage.
pub fn forward_kinematics(
    plan: &Plan,
    xi: &[f64],
    guess: &[f64],
) -> Result<Vec<f64>, NoConvergence> {
    let stages = continuation_stages(plan, xi, guess);
    if stages > 1 {
        let mut x = guess.to_vec();
        let mut followed = true;
        for s in 1..=stages {
            let t = s as f64 / stages as f64;
            let q: Vec<f64> = if s == stages {
                xi.to_vec()
            } else {
                plan.independent
                    .iter()
                    .zip(xi)
                    .map(|(&j, &v)| guess[j] + t * (v - guess[j]))
                    .collect()
            };
            match newton_assembly(plan, &q, &x) {
                Ok(xn) => x = xn,
                Err(_) => {
                    followed = false;
                    break;
                }
            }
        }
        if followed {
            return Ok(x);
        }
    }
    newton_assembly(plan, xi, guess)
}

/// One Newton solve (the stage of [`forward_kinematics`]): the closed configuration with
/// independent coordinates `xi` nearest `guess` in Newton's sense (the step halved while it
/// does not reduce the residual), at most [`FK_MAX_ITERATIONS`] iterations, converged when
/// every kept loop equation is within [`FK_TOLERANCE`] (point equations times the size); then
/// one more full step (kept unless it raises the residual) takes the coordinates to rounding.
/// Each dependent angle stays within ±π of its guess (the same configuration with the fewest
/// turns: a long Newton step can land turns away, where fewer digits are left).
pub fn newton_assembly(plan: &Plan, xi: &[f64], guess: &[f64]) -> Result<Vec<f64>, NoConvergence> {
    let mut x = guess.to_vec();
    for (k, &j) in plan.independent.iter().enumerate() {
        x[j] = xi[k];
    }
    let fail = |it, r: f64| NoConvergence {
        iterations: it,
        residual: r,
    };
    let Ok((mut dx, mut r, mut full)) = newton_step(plan, &x) else {
        return Err(fail(0, f64::INFINITY));
    };
    for it in 0..FK_MAX_ITERATIONS {
        if r.abs() <= FK_TOLERANCE {
            if !(full.abs() <= FULL_TOLERANCE) {
                // The kept equations hold but not all of them: a spurious branch.
                return Err(fail(it, full.abs()));
            }
            // One more full step (Newton converges quadratically): the coordinates to rounding.
            let xn: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + b).collect();
            if let Ok((_, rn, fulln)) = newton_step(plan, &xn)
                && rn.abs() <= r.abs()
                && fulln.abs() <= FULL_TOLERANCE
            {
                return Ok(xn);
            }
            return Ok(x);
        }
        let mut step = 1.0;
        let mut moved = false;
        for _ in 0..20 {
            let mut xn: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + step * b).collect();
            wrap_near(plan, &mut xn, guess);
            if let Ok((dn, rn, fulln)) = newton_step(plan, &xn)
                && rn.abs() < r.abs()
            {
                x = xn;
                dx = dn;
                r = rn;
                full = fulln;
                moved = true;
                break;
            }
            step *= 0.5;
        }
        if !moved {
            return Err(fail(it + 1, r.abs()));
        }
    }
    Err(fail(FK_MAX_ITERATIONS, r.abs()))
}

/// The dependent revolute coordinates of `x` moved by whole turns to within ±π of `guess`'s.
fn wrap_near(plan: &Plan, x: &mut [f64], guess: &[f64]) {
    let t = 2.0 * core::f64::consts::PI;
    for &j in &plan.dependent {
        let d = x[j] - guess[j];
        if plan.joints[j].kind == JointKind::Revolute
            && d.abs() > core::f64::consts::PI
            && d.abs() < 1e9
        {
            x[j] = guess[j] + (d - libm::floor(d / t + 0.5) * t);
        }
    }
}

/// Potential energy at `x`: gravity's `−Σ m_b gᵀ c_b` (J, zero at the base origin) plus the springs'
/// `½ k (L − L₀)²`.
pub fn potential_energy(plan: &Plan, x: &[f64]) -> f64 {
    let k = kinematics(plan, x);
    let mut v = 0.0;
    for (b, j) in plan.joints.iter().enumerate() {
        let (mass, com, _) = j.body;
        let c = add(k.pos[b], mv(&k.rot[b], cv(&com)));
        v -= mass * dot(cv(&plan.gravity), c);
    }
    // The springs' elastic energy, `½ k (L − L₀)²`.
    for s in &plan.springs {
        let d = sub(
            point_of(&k, s.body_b, &s.point_b),
            point_of(&k, s.body_a, &s.point_a),
        );
        let stretch = libm::sqrt(dot(d, d)) - s.rest_length;
        v += 0.5 * s.stiffness * stretch * stretch;
    }
    v
}
