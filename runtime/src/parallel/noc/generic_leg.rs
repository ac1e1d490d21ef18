//! The inverse kinematics of a generic leg ([`LegKind::Generic`]): a fixed number of Newton
//! steps from the home configuration ([`GENERIC_IK_ITERATIONS`]), checked against
//! [`GENERIC_IK_TOLERANCE`].

use alloc::vec::Vec;

use super::LEG_TOLERANCE;
use super::legs::JointPos;
use super::plan::LegPlan;
use crate::algebra::{M, V, add, cross, cv, dot, ident, mm, mv, rot, scale, sub, zero3};
use crate::model::JointKind;
use crate::scalar::{Real, Singular, Site};

#[cfg(doc)]
use super::legs::leg_kinematics;
#[cfg(doc)]
use crate::parallel::LegKind;

/// Newton steps of a generic leg's inverse kinematics ([`LegKind::Generic`]): a fixed count,
/// because a generated module unrolls them. From the home configuration the error falls
/// quadratically once it is small; twelve steps reach the `f64` floor from the poses the
/// bundled tests use (rotations to 0.3 rad and translations to 0.1 m from home).
pub const GENERIC_IK_ITERATIONS: usize = 12;

/// Newton's method picks no branch: far from home (rotations beyond about a radian) the steps
/// may converge to another assembly of the leg than the one at home, which is then a valid but
/// different solution. Closed-form leg types keep their declared branch.
///
/// A generic leg's inverse kinematics has converged when its S centre is within this fraction
/// of the leg's reach (first joint to S centre at home) of the target; otherwise the pose is
/// `Site::Reach` (unreachable on the home branch within [`GENERIC_IK_ITERATIONS`] steps).
pub const GENERIC_IK_TOLERANCE: f64 = 1e-9;

/// The joint positions of `th` (angles as sine and cosine).
fn joint_positions<R: Real>(lp: &LegPlan, th: &[R; 3]) -> Vec<JointPos<R>> {
    lp.joints
        .iter()
        .zip(th)
        .map(|(kind, &t)| match kind {
            JointKind::Revolute => {
                let (s, c) = t.sin_cos();
                JointPos::R(s, c)
            }
            JointKind::Prismatic => JointPos::P(t),
        })
        .collect()
}

/// The S centre and the Jacobian columns (leg frame `L`) of a three-joint leg at `q`: the
/// product of exponentials of [`leg_kinematics`], without the bodies.
fn end_and_columns<R: Real>(lp: &LegPlan, q: &[JointPos<R>]) -> (V<R>, [V<R>; 3]) {
    let mut g: M<R> = ident();
    let mut t: V<R> = zero3();
    let mut e = [zero3::<R>(); 3];
    let mut o = [zero3::<R>(); 3];
    for j in 0..3 {
        e[j] = mv(&g, cv(&lp.axes[j]));
        o[j] = add(mv(&g, cv(&lp.points[j])), t);
        match q[j] {
            JointPos::R(s, c) => {
                g = mm(&g, &rot(&lp.axes[j], s, c));
                t = sub(o[j], mv(&g, cv(&lp.points[j])));
            }
            JointPos::P(d) => t = add(t, scale(d, e[j])),
        }
    }
    let end = add(mv(&g, cv(&lp.end_home)), t);
    let cols = core::array::from_fn(|j| match lp.joints[j] {
        JointKind::Revolute => cross(e[j], sub(end, o[j])),
        JointKind::Prismatic => e[j],
    });
    (end, cols)
}

/// Inverse kinematics of a generic leg of plan `k` (target: the S centre in `L`) by
/// [`GENERIC_IK_ITERATIONS`] Newton steps from `θ = 0`, each `θ ← θ − J⁻¹ (p(θ) − target)` with
/// `J⁻¹` by its adjugate (a singular `J` is `Site::Leg(k)`); then the residual is checked
/// against [`GENERIC_IK_TOLERANCE`] (`Site::Reach(k)`).
pub(super) fn generic_ik<R: Real>(
    lp: &LegPlan,
    target: V<R>,
    k: usize,
) -> Result<Vec<JointPos<R>>, Singular> {
    let mut th = [R::c(0.0); 3];
    for _ in 0..GENERIC_IK_ITERATIONS {
        let (end, cols) = end_and_columns(lp, &joint_positions(lp, &th));
        let r = sub(end, target);
        let adj = [
            cross(cols[1], cols[2]),
            cross(cols[2], cols[0]),
            cross(cols[0], cols[1]),
        ];
        let det = dot(cols[0], adj[0]);
        let hn = (dot(cols[0], cols[0]) * dot(cols[1], cols[1]) * dot(cols[2], cols[2])).sqrt();
        let det = R::check(
            det,
            R::c(R::tolerance(LEG_TOLERANCE)) * hn,
            hn,
            Site::Leg(k),
            true,
        )?;
        let inv = R::c(1.0) / det;
        for i in 0..3 {
            th[i] = th[i] - dot(adj[i], r) * inv;
        }
    }
    let q = joint_positions(lp, &th);
    let (end, _) = end_and_columns(lp, &q);
    let r = sub(end, target);
    let tol = R::tolerance(GENERIC_IK_TOLERANCE) * lp.length;
    R::check(
        R::c(tol * tol) - dot(r, r),
        R::c(0.0),
        R::c(tol * tol),
        Site::Reach(k),
        false,
    )?;
    Ok(q)
}
