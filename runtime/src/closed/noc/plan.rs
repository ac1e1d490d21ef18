//! The constant data of a closed-loop mechanism, prepared and checked once: [`Plan`] (its
//! tree [`JointPlan`]s and [`CutPlan`]s) and the choice of the loop equations at home
//! ([`Plan::new`]: the mobility from the numerical rank of the dimensionless loop Jacobian, the
//! kept [`Row`]s by greedy Gram–Schmidt over the dependent columns, the spare rows).

use alloc::vec;
use alloc::vec::Vec;

use super::RANK_TOLERANCE;
use super::api::inverse_dynamics;
use super::band::band_order;
use super::loop_equations::jacobian_row;
use super::tree::kinematics;
use crate::closed::{ClosedModel, CutKind, ancestry, perpendiculars};
use crate::model::{JointKind, Mat3, Transform, Vec3, mat_vec};

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
    /// The coordinate at home ([`super::super::ClosedModel::home`]): the joint moves by
    /// `x − home` from `origin`.
    pub home: f64,
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
        let mut joints = joint_plans(tree);
        for (j, &h) in joints.iter_mut().zip(&model.home) {
            j.home = h;
        }
        let cuts = cut_plans(model);
        let candidates = candidate_rows(model);
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
        let x0 = plan.home();
        let jac = home_jacobian(&plan, &candidates, &x0);
        let tol = RANK_TOLERANCE * norm(&jac.concat());
        check_mobility(&plan, n, &jac, tol)?;
        let (mut kept, dep_norm) = greedy_rows(&plan, &jac, tol)?;
        check_kept_span(model, &plan, &candidates, &jac, &kept, tol)?;
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
    /// This plan without its dissipation (the joints' viscous and Coulomb friction, the
    /// springs' damping; the rotor inertias kept): its generalized force at `u̇ = 0` without
    /// gravity is the velocity-dependent part `C u` alone (`coriolis`).
    pub fn without_friction(&self) -> Plan {
        let mut p = self.clone();
        for j in &mut p.joints {
            j.drive = j.drive.without_friction();
        }
        for s in &mut p.springs {
            s.damping = 0.0;
        }
        p
    }

    /// The dissipation alone: massless bodies, no rotor inertia, no gravity, springs without
    /// stiffness. Its generalized force at `(u, u̇ = 0)` with the applied forces on (springs
    /// count with gravity) is the joints' friction and the springs' damping (`friction`).
    pub fn friction_only(&self) -> Plan {
        let mut p = self.clone();
        p.gravity = [0.0; 3];
        for j in &mut p.joints {
            j.body = (0.0, j.body.1, [[0.0; 3]; 3]);
            j.drive = j.drive.friction_only();
        }
        for s in &mut p.springs {
            s.stiffness = 0.0;
        }
        p
    }

    /// Whether a joint has friction or a spring has damping.
    pub fn has_friction(&self) -> bool {
        self.joints.iter().any(|j| j.drive.has_friction())
            || self.springs.iter().any(|s| s.damping != 0.0)
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.independent.len()
    }
    /// The joint coordinates at home (absolute: [`JointPlan::home`]).
    pub fn home(&self) -> Vec<f64> {
        self.joints.iter().map(|j| j.home).collect()
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
            home: 0.0,
        })
        .collect()
}

/// The cut joints' constant data.
fn cut_plans(model: &ClosedModel) -> Vec<CutPlan> {
    model
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
        .collect()
}

/// Candidate rows: per cut, the three point rows, then (revolute) two axis rows.
fn candidate_rows(model: &ClosedModel) -> Vec<Row> {
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
    candidates
}

/// The Jacobian of every candidate at home (`x0`), made dimensionless: point rows divided by
/// the size, prismatic columns multiplied by it (a slide of one size weighs as a turn of one
/// radian). Rounding leaves entries that are zero in exact arithmetic at about `ε‖J‖` (a loop
/// turned in space): the rank decisions take a residual as zero up to
/// `tol = RANK_TOLERANCE · ‖J‖_F`, never up to exactly zero.
fn home_jacobian(plan: &Plan, candidates: &[Row], x0: &[f64]) -> Vec<Vec<f64>> {
    let n = x0.len();
    let kin = kinematics(plan, x0);
    candidates
        .iter()
        .map(|r| {
            let s = row_scale(plan, r);
            let row = jacobian_row(plan, &kin, r);
            (0..n).map(|j| row[j] * col_scale(plan, j) / s).collect()
        })
        .collect()
}

/// Mobility at home: NX − rank of the loop equations (all columns) must be the number of
/// actuated joints.
fn check_mobility(
    plan: &Plan,
    n: usize,
    jac: &[Vec<f64>],
    tol: f64,
) -> Result<(), alloc::string::String> {
    let rank = numerical_rank(jac, tol);
    if n - rank != plan.independent.len() {
        return Err(alloc::format!(
            "the mechanism has {} degree(s) of freedom at home ({n} joint coordinates, {rank} independent loop equations) but {} joint(s) are actuated; mark one actuated joint per degree of freedom",
            n - rank,
            plan.independent.len()
        ));
    }
    Ok(())
}

/// Greedy Gram–Schmidt over the dependent columns on unit rows (the best conditioned next row
/// first); a row counts only while its residual, at the row's own size, exceeds `tol`. The
/// kept rows in the order chosen, and every row's norm over the dependent columns.
fn greedy_rows(
    plan: &Plan,
    jac: &[Vec<f64>],
    tol: f64,
) -> Result<(Vec<usize>, Vec<f64>), alloc::string::String> {
    let nd = plan.dependent.len();
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
    Ok((kept, dep_norm))
}

/// Mobility: every candidate row (all columns) must depend on the kept ones.
fn check_kept_span(
    model: &ClosedModel,
    plan: &Plan,
    candidates: &[Row],
    jac: &[Vec<f64>],
    kept: &[usize],
    tol: f64,
) -> Result<(), alloc::string::String> {
    let nd = plan.dependent.len();
    let mut full: Vec<Vec<f64>> = Vec::new();
    for &k in kept {
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
    Ok(())
}

pub(super) fn row_cut(r: &Row) -> usize {
    match r {
        Row::Point { cut, .. } | Row::Axis { cut, .. } => *cut,
    }
}

pub(super) fn row_scale(plan: &Plan, r: &Row) -> f64 {
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
