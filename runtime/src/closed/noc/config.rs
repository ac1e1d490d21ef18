//! The configuration-level quantities every function shares ([`Config`]): the tree's
//! kinematics, the loop Jacobian, the LU of `Φ_d`, the closure checks and the springs'
//! directions.

use alloc::vec::Vec;

use super::loop_equations::{alignment, jacobian_row, row_value};
use super::lu::{Lu, lu_factor};
use super::plan::{Plan, row_scale};
use super::tree::{Kin, kinematics, point_of};
use super::{CLOSURE_TOLERANCE, SPRING_TOLERANCE};
use crate::algebra::{V, dot, scale, sub};
use crate::scalar::{Real, Singular, Site};

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
