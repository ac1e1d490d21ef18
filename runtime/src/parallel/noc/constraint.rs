//! The constraint test of a platform held in rotation by its legs (`Translation`, and the
//! carrier of `Schoenflies`): [`constraint_couples`] and [`check_constraint`].
//!
//! Such a platform's coordinates hold its rotation fixed, and the evaluators give it `ω = 0`.
//! What actually holds it are the legs' constraint wrenches, the wrenches reciprocal to every
//! joint screw of a leg. Each leg of these platforms allows every translation, so its
//! constraint wrenches are pure couples, and a couple `c` is reciprocal to a twist `[ω; v]`
//! when `c·ω = 0`. The legs hold the rotation only while their couples together span the
//! three directions of `ω`. Where they stop spanning (a constraint singularity, Zlatanov,
//! Bonev & Gosselin, "Constraint singularities of parallel mechanisms", ICRA 2002), the
//! platform gains a rotation that no leg resists and that the actuators do not see: `A` stays
//! regular and the efforts stay finite, but they describe a mechanism that is no longer the
//! one modelled.
//!
//! The couples, per leg, from its current joint axes (one couple each):
//! * a UPU leg (Tsai's 3-UPU, run as a UPS leg to the platform U's centre): the platform U's
//!   axes are parallel to the base U's, swapped (checked at load), so the couple is normal to
//!   both of the base U's axes, `e₀ × e₁`;
//! * a Delta leg (a crank carrying a parallelogram of two ball–ball rods, run as its
//!   equivalent RUS leg): the two rod forces `±f d` through the two rods, `w a` apart, make the
//!   couple `a × d`, normal to the parallelogram's plane (`a` the short sides' direction, the
//!   crank axis; `d` the rod direction). The leg's other constraint, the force along the rods,
//!   is not reciprocal to the crank's rotation. One couple per parallelogram leg, not two: a
//!   parallelogram of ball–ball rods also lets its distal side turn about the rod direction
//!   (`a_parallelogram_allows_four_motions` in `codegen::spec::parallel::screws`).
//!
//! A Delta leg's couple is `a × d` of two unit vectors, not normalized: where the rods turn
//! parallel to the crank axis the parallelogram folds flat and its couple vanishes with
//! `|a × d|` (its own leg test fails there too, since `s = d·j ≤ |j| |a × d|`).
//!
//! The test: the couples as rows of length at most 1, factorized by LU with partial pivoting
//! (the pivoting chooses the three best of them when there are more); a pivot
//! `|p| ≤ CONSTRAINT_TOLERANCE` is `Site::Constraint(i)`, the condition estimate `1/|p|`, as
//! the closed loops' `Φ_d`.

use alloc::vec::Vec;

use super::CONSTRAINT_TOLERANCE;
use super::legs::LegKin;
use super::plan::Plan;
use crate::algebra::{V, cross, cv, dot, mv, scale, sub};
use crate::model::JointKind;
use crate::parallel::{LegKind, PlatformMotion};
use crate::scalar::{Real, Singular, Site};

/// Whether `plan`'s platform is held in rotation by its legs' couples (the motions whose
/// coordinates fix the rotation of the body the legs hold: `Translation`, `Schoenflies`).
pub fn held_by_couples(plan: &Plan) -> bool {
    matches!(
        plan.motion,
        PlatformMotion::Translation { .. } | PlatformMotion::Schoenflies { .. }
    )
}

/// Each leg's constraint couple (base frame), for the legs that impose one: a UPU leg's unit
/// `e₀ × e₁`, a Delta leg's `a × d` of unit vectors, whose length is the sine between the rods
/// and the crank axis (see the module's text). Empty unless [`held_by_couples`].
pub fn constraint_couples<R: Real>(plan: &Plan, legs: &[LegKin<R>]) -> Vec<V<R>> {
    let mut out = Vec::new();
    if !held_by_couples(plan) {
        return out;
    }
    let unit = |c: V<R>| scale(R::c(1.0) / dot(c, c).sqrt(), c);
    for (lp, lk) in plan.legs.iter().zip(legs) {
        let couple = match (lp.kind, &lk.ups, &lk.delta) {
            // The closed-form UPS leg keeps the U's second axis e₁′ (base frame, unit, at right
            // angles to e₀): the couple is unit already.
            (LegKind::Ups, Some(uk), _) => Some(cross(mv(&lk.frame, cv(&lp.axes[0])), uk.e1)),
            // The closed-form Delta leg keeps the rod direction d (unit) in L. `|a × d|` is the
            // sine between the rods and the crank axis, and it vanishes with the couple where
            // the parallelogram folds flat onto that axis: not normalized, so the test sees it
            // (a singularity test never scales a quantity by itself alone).
            (LegKind::Rus, _, Some(dk)) => Some(mv(&lk.frame, cross(cv(&lp.axes[0]), dk.d))),
            // A U's two axes stay at their fixed angle: `|e₀ × e₁|` is a constant of the leg.
            (LegKind::Ups, None, _) => Some(unit(mv(&lk.frame, cross(lk.e[0], lk.e[1])))),
            // The generic Delta leg: the rod `P − E` over its (fixed) length, as above.
            (LegKind::Rus, _, None) => Some(scale(
                R::c(1.0 / lp.length),
                mv(&lk.frame, cross(lk.e[0], sub(lk.end, lk.o[1]))),
            )),
            // A UPU leg the closed form does not take (its U's axes do not meet, or its
            // prismatic axis is off the U centres' line).
            (LegKind::Generic, _, _)
                if lp.joints.as_slice()
                    == [
                        JointKind::Revolute,
                        JointKind::Revolute,
                        JointKind::Prismatic,
                    ] =>
            {
                Some(unit(mv(&lk.frame, cross(lk.e[0], lk.e[1]))))
            }
            _ => None,
        };
        out.extend(couple);
    }
    out
}

/// The test of [`constraint_couples`]: with at least three couples, the LU with partial
/// pivoting of their rows; a pivot `|p| ≤ CONSTRAINT_TOLERANCE` (or a couple of zero
/// length) is `Site::Constraint(i)` with the condition estimate `1/|p|`.
pub fn check_constraint<R: Real>(plan: &Plan, legs: &[LegKin<R>]) -> Result<(), Singular> {
    couple_lu(plan, legs, true).map(|_| ())
}

/// The three pivots of [`check_constraint`]'s LU, untested (empty with fewer than three
/// couples): how far the couples are from dependent (each at most 1 in magnitude).
pub fn couple_pivots(plan: &Plan, legs: &[LegKin<f64>]) -> Vec<f64> {
    couple_lu(plan, legs, false).unwrap_or_default()
}

/// The LU of the couples as rows (partial pivoting as selects, rows swapped in the active
/// columns only), each pivot tested when `test`; the pivots.
fn couple_lu<R: Real>(plan: &Plan, legs: &[LegKin<R>], test: bool) -> Result<Vec<R>, Singular> {
    let couples = constraint_couples(plan, legs);
    let mut pivots = Vec::new();
    if couples.len() < 3 {
        return Ok(pivots);
    }
    let mut m = couples;
    let nr = m.len();
    for k in 0..3 {
        for i in k + 1..nr {
            let (p, q) = (m[i][k], m[k][k]);
            for j in k..3 {
                let (x, y) = (m[i][j], m[k][j]);
                m[k][j] = R::select_abs_gt(p, q, x, y);
                m[i][j] = R::select_abs_gt(p, q, y, x);
            }
        }
        let piv = if test {
            R::check(
                m[k][k],
                R::c(R::tolerance(CONSTRAINT_TOLERANCE)),
                R::c(1.0),
                Site::Constraint(k),
                true,
            )?
        } else {
            m[k][k]
        };
        pivots.push(piv);
        let inv = R::c(1.0) / piv;
        for i in k + 1..nr {
            let f = m[i][k] * inv;
            for j in k + 1..3 {
                m[i][j] = m[i][j] - f * m[k][j];
            }
        }
    }
    Ok(pivots)
}
