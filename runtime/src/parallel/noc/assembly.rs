//! Forward kinematics (assembly): the platform coordinates from the actuated joint positions
//! by Newton's method on `q(x)` with the actuation matrix, and [`retract`], the motion
//! `x ⊕ δu` that keeps the quaternion unit.

use alloc::vec;
use alloc::vec::Vec;

use super::legs::{actuated_positions, actuation_matrix, kinematics};
use super::lu::solve_dyn;
use super::plan::Plan;
use crate::model::JointKind;
use crate::parallel::PlatformMotion;
use crate::scalar::Real;
use crate::solve::{NoConvergence, Stop, check_finite};

/// Newton iterations of [`forward_kinematics`] at most.
pub const FK_MAX_ITERATIONS: usize = 50;
/// Convergence of [`forward_kinematics`]: `max |q(x) − q| ≤ FK_TOLERANCE · Plan::fk_scale()`
/// (angle residuals wrapped to `(−π, π]`). The bound does not grow with `q`: a huge target is
/// met as closely as a small one, or not at all.
pub const FK_TOLERANCE: f64 = 1e-12;

/// Wrap an angle difference to `(−π, π]`.
fn wrap(a: f64) -> f64 {
    let t = core::f64::consts::TAU;
    let r = a - t * libm::round(a / t);
    if r <= -core::f64::consts::PI {
        r + t
    } else {
        r
    }
}

/// `x` moved by the small motion `du` (`[δθ; δp]` or `δθ`, base frame): the rotation vector
/// multiplies the quaternion from the left, the origin is translated (a translating platform's
/// `x ⊕ δp`, and a planar pose's `[px, py, φ] ⊕ [δx, δy, δφ]`, is the sum).
pub fn retract(motion: PlatformMotion, x: &[f64], du: &[f64]) -> Vec<f64> {
    let (qi, pi) = match motion {
        PlatformMotion::Pose => (3, Some(0)),
        PlatformMotion::Orientation { .. } => (0, None),
        PlatformMotion::PlanarPoint { .. }
        | PlatformMotion::Translation { .. }
        | PlatformMotion::PlanarPose { .. }
        | PlatformMotion::HeaveTilt { .. }
        | PlatformMotion::Schoenflies { .. } => {
            return x.iter().zip(du).map(|(a, b)| a + b).collect();
        }
    };
    let th = [du[0], du[1], du[2]];
    let a = libm::sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
    let (s, c) = crate::math::sin_cos(0.5 * a);
    let k = if a > 1e-300 { s / a } else { 0.5 };
    let d = [c, k * th[0], k * th[1], k * th[2]];
    let q = [x[qi], x[qi + 1], x[qi + 2], x[qi + 3]];
    let mut r = [
        d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
        d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
        d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
        d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0],
    ];
    let n = libm::sqrt(r.iter().map(|v| v * v).sum());
    for v in r.iter_mut() {
        *v /= n;
    }
    let mut out = x.to_vec();
    out[qi..qi + 4].copy_from_slice(&r);
    if let Some(p) = pi {
        for i in 0..3 {
            out[p + i] += du[3 + i];
        }
    }
    out
}

/// The tangent of [`retract`] at `du = 0`: the `nx × n` matrix `E(x)` with `ẋ = E(x) u`, so
/// that a function's derivative along the speed `u_j` is `Σ_k ∂f/∂x_k E_kj`. A quaternion `q`
/// moves as `q̇ = ½ (0, ω) ⊗ q` (`ω` in the base frame, on the left as in [`retract`]), a
/// position as `ṗ = v`; every other motion's `x ⊕ δu` is a sum, `E = 1`.
pub fn tangent<R: Real>(motion: PlatformMotion, x: &[R]) -> Vec<Vec<R>> {
    let (qi, pi) = match motion {
        PlatformMotion::Pose => (3, Some(0)),
        PlatformMotion::Orientation { .. } => (0, None),
        _ => {
            return (0..x.len())
                .map(|k| {
                    (0..x.len())
                        .map(|j| R::c(f64::from(u8::from(k == j))))
                        .collect()
                })
                .collect();
        }
    };
    let n = if pi.is_some() { 6 } else { 3 };
    let mut e = vec![vec![R::c(0.0); n]; x.len()];
    let half = R::c(0.5);
    let [w, a, b, c] = [x[qi], x[qi + 1], x[qi + 2], x[qi + 3]];
    // ½ (0, e_j) ⊗ (w, a, b, c) for the unit rotation rates e_0, e_1, e_2.
    let columns = [[-a, w, -c, b], [-b, c, w, -a], [-c, -b, a, w]];
    for (j, col) in columns.iter().enumerate() {
        for (k, &v) in col.iter().enumerate() {
            e[qi + k][j] = half * v;
        }
    }
    if let Some(p) = pi {
        for i in 0..3 {
            e[p + i][3 + i] = R::c(1.0);
        }
    }
    e
}

/// Forward kinematics: the platform coordinates `x` whose actuated joint positions are `q`, by
/// Newton's method from `guess` (`x ← x ⊕ A⁻¹ (q − q(x))`, the step halved while it does not
/// reduce the residual), at most [`FK_MAX_ITERATIONS`] iterations, converged when the residual
/// is within [`FK_TOLERANCE`] times [`Plan::fk_scale`]. Revolute targets count modulo 2π. A
/// non-finite `q` or `guess` is `Err` at once. The quaternion of the result is unit.
pub fn forward_kinematics(
    plan: &Plan,
    q: &[f64],
    guess: &[f64],
) -> Result<Vec<f64>, NoConvergence> {
    let n = plan.dof();
    let revolute: Vec<bool> = plan
        .legs
        .iter()
        .map(|l| l.joints[l.actuated] == JointKind::Revolute)
        .collect();
    if check_finite(&[q, guess]).is_err() {
        return Err(NoConvergence {
            iterations: 0,
            residual: f64::INFINITY,
            stop: Stop::Input,
        });
    }
    let tol = FK_TOLERANCE * plan.fk_scale();
    // Revolute targets reduced to [−π, π] once, with the accurate range reduction of sin and
    // cos, so that every residual below is a difference of two such angles (O(1) to wrap,
    // whatever the size of `q`).
    let q: Vec<f64> = q
        .iter()
        .zip(&revolute)
        .map(|(&v, &r)| {
            if r {
                let (s, c) = crate::math::sin_cos(v);
                crate::math::atan2(s, c)
            } else {
                v
            }
        })
        .collect();
    let residual = |x: &[f64]| -> Option<(Vec<f64>, f64, Vec<Vec<f64>>)> {
        let (pl, legs) = kinematics(plan, x).ok()?;
        let qx = actuated_positions(plan, &legs);
        let r: Vec<f64> = (0..n)
            .map(|i| {
                let d = q[i] - qx[i];
                if revolute[i] { wrap(d) } else { d }
            })
            .collect();
        let m = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !m.is_finite() {
            return None;
        }
        Some((r, m, actuation_matrix(plan, &pl, &legs)))
    };
    let mut x = retract(plan.motion, guess, &vec![0.0; n]);
    let Some(mut cur) = residual(&x) else {
        return Err(NoConvergence {
            iterations: 0,
            residual: f64::INFINITY,
            stop: Stop::Guess,
        });
    };
    for it in 0..FK_MAX_ITERATIONS {
        if cur.1 <= tol {
            return Ok(x);
        }
        let Ok(du) = solve_dyn(&cur.2, &cur.0, false, plan.column_units()) else {
            return Err(NoConvergence {
                iterations: it,
                residual: cur.1,
                stop: Stop::Singular,
            });
        };
        let mut step = 1.0;
        let mut next = None;
        for _ in 0..20 {
            let d: Vec<f64> = du.iter().map(|v| v * step).collect();
            let xn = retract(plan.motion, &x, &d);
            if let Some(r) = residual(&xn) {
                if r.1 < cur.1 {
                    next = Some((xn, r));
                    break;
                }
            }
            step *= 0.5;
        }
        match next {
            Some((xn, r)) => {
                x = xn;
                cur = r;
            }
            None => {
                return Err(NoConvergence {
                    iterations: it + 1,
                    residual: cur.1,
                    stop: Stop::Stalled,
                });
            }
        }
    }
    if cur.1 <= tol {
        Ok(x)
    } else {
        Err(NoConvergence {
            iterations: FK_MAX_ITERATIONS,
            residual: cur.1,
            stop: Stop::Iterations,
        })
    }
}
