//! Forward kinematics (assembly): Newton steps on the kept loop equations ([`newton_step`]),
//! followed from the guess in stages ([`forward_kinematics`]), and the closure residual.

use alloc::vec;
use alloc::vec::Vec;

use super::config::configuration;
use super::loop_equations::{alignment, row_value};
use super::plan::{Plan, row_scale};
use super::{FK_MAX_ITERATIONS, FK_MAX_STAGES, FK_STEP, FK_TOLERANCE, FULL_TOLERANCE};
use crate::model::JointKind;
use crate::scalar::{Real, Singular, Site};
use crate::solve::{NoConvergence, Stop};

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
    let fail = |it, r: f64, stop| NoConvergence {
        iterations: it,
        residual: r,
        stop,
    };
    let (mut dx, mut r, mut full) = match newton_step(plan, &x) {
        Ok(s) => s,
        Err(e) if e.site == Site::Input => return Err(fail(0, f64::INFINITY, Stop::Input)),
        Err(_) => return Err(fail(0, f64::INFINITY, Stop::Guess)),
    };
    for it in 0..FK_MAX_ITERATIONS {
        if r.abs() <= FK_TOLERANCE {
            if !(full.abs() <= FULL_TOLERANCE) {
                // The kept equations hold but not all of them: a spurious branch.
                return Err(fail(it, full.abs(), Stop::Branch));
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
            return Err(fail(it + 1, r.abs(), Stop::Stalled));
        }
    }
    Err(fail(FK_MAX_ITERATIONS, r.abs(), Stop::Iterations))
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
