//! The `f64` functions: inputs checked finite, the generic evaluators, outputs checked finite
//! (inverse kinematics, the actuation matrix and actuator rates, inverse dynamics, the
//! generalized inertia and the inertia in actuator space (eq. 68), forward dynamics, potential
//! energy).

use alloc::vec;
use alloc::vec::Vec;

use super::dynamics::forward_dynamics_generic;
use super::force::{generalized_force, leg_rates};
use super::inertia::generalized_inertia;
use super::legs::{JointPos, actuated_positions, actuation_matrix, kinematics, positions};
use super::lu::solve_dyn;
use super::parasitic::parasitic_pose;
use super::plan::Plan;
use super::pose::platform;
use crate::algebra::{V, add, dot, mv};
use crate::scalar::Singular;
use crate::solve::check_finite;

/// `Ok(v)` when every entry is finite, else `Err(Site::Input)` (an overflow).
fn finite(v: Vec<f64>) -> Result<Vec<f64>, Singular> {
    check_finite(&[&v])?;
    Ok(v)
}

/// Actuated joint positions (rad or m) for the platform coordinates `x`.
pub fn inverse_kinematics(plan: &Plan, x: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x])?;
    let (_, legs) = positions(plan, x)?;
    finite(actuated_positions(plan, &legs))
}

/// The platform's full pose at `x`, `[px, py, pz, qw, qx, qy, qz]` (the platform frame's
/// origin, m, and its unit quaternion, platform → base): for a 1T2R platform (`HeaveTilt`)
/// the parasitic components `px`, `py` and the turn `γ` about `z` come from the legs'
/// constraints, the quaternion is `qz(γ) ⊗ qy(β) ⊗ qx(α) ⊗ q_home` ([`parasitic_pose`], as the
/// generated `platform_pose`); for the others it is the rotation's with `qw ≥ 0`.
pub fn platform_pose(plan: &Plan, x: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x])?;
    if plan.motion.parasitic() {
        return finite(parasitic_pose(plan, x)?.to_vec());
    }
    let pl = platform(plan, x)?;
    let q = crate::model::matrix_quaternion(&pl.rot);
    let s = if q[0] < 0.0 { -1.0 } else { 1.0 };
    let o = pl.origin;
    finite(vec![
        o[0],
        o[1],
        o[2],
        s * q[0],
        s * q[1],
        s * q[2],
        s * q[3],
    ])
}

/// Every leg's joint positions (rad or m, the spec's joint order after U expansion) at `x`.
pub fn leg_joint_positions(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (_, legs) = kinematics(plan, x)?;
    Ok(legs
        .iter()
        .map(|lk| {
            lk.q.iter()
                .map(|q| match *q {
                    JointPos::R(s, c) => libm::atan2(s, c),
                    JointPos::P(d) => d,
                })
                .collect()
        })
        .collect())
}

/// One leg's joint rates and accelerations `(θ̇, θ̈)`.
pub type JointRates = (Vec<f64>, Vec<f64>);

/// Every leg's joint rates and accelerations `(θ̇, θ̈)` (rad/s or m/s, and per s²; the spec's
/// joint order after U expansion) at `(x, u, u̇)`: the actuated ones are `q̇ = A u` and
/// `q̈ = A u̇ + Ȧ u`.
pub fn leg_joint_rates(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<JointRates>, Singular> {
    check_finite(&[x, u, ud])?;
    let (pl, legs) = kinematics(plan, x)?;
    let out = leg_rates(plan, &pl, &legs, u, ud);
    for (a, b) in &out {
        check_finite(&[a, b])?;
    }
    Ok(out)
}

/// The actuation matrix `A` at `x` (`q̇ = A u`).
pub fn actuation(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (pl, legs) = kinematics(plan, x)?;
    Ok(actuation_matrix(plan, &pl, &legs))
}

/// Actuator rates `q̇ = A u`.
pub fn actuator_rates(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[u])?;
    let a = actuation(plan, x)?;
    finite(
        a.iter()
            .map(|row| row.iter().zip(u).map(|(a, b)| a * b).sum())
            .collect(),
    )
}

/// Actuator efforts `τ = A⁻ᵀ (I u̇ + C u − γ)` (N or N·m; gravity included).
pub fn inverse_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, ud])?;
    let (pl, legs) = kinematics(plan, x)?;
    let f = generalized_force(plan, &pl, &legs, u, ud, true);
    let a = actuation_matrix(plan, &pl, &legs);
    solve_dyn(&a, &f, true, plan.column_units())
}

/// Actuator efforts that hold the mechanism still against gravity at `x`: `A⁻ᵀ (−γ)`, equal
/// to `inverse_dynamics(x, 0, 0)` (N or N·m).
pub fn gravity(plan: &Plan, x: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x])?;
    let (pl, legs) = kinematics(plan, x)?;
    let z = vec![0.0; plan.dof()];
    let f = generalized_force(plan, &pl, &legs, &z, &z, true);
    let a = actuation_matrix(plan, &pl, &legs);
    solve_dyn(&a, &f, true, plan.column_units())
}

/// Velocity-dependent actuator efforts `A⁻ᵀ C u` (Coriolis and centrifugal terms, the rotor
/// inertias' among them; no gravity, no friction).
pub fn coriolis(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u])?;
    let (pl, legs) = kinematics(plan, x)?;
    let z = vec![0.0; plan.dof()];
    let f = generalized_force(&plan.without_friction(), &pl, &legs, u, &z, false);
    let a = actuation_matrix(plan, &pl, &legs);
    solve_dyn(&a, &f, true, plan.column_units())
}

/// Actuator efforts of the leg joints' friction (viscous and regularized Coulomb, actuated
/// and passive joints) at `(x, u)`, mapped to the actuators: `A⁻ᵀ Σ J⁻ᵀ δ(θ̇)`.
pub fn friction(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u])?;
    let (pl, legs) = kinematics(plan, x)?;
    let z = vec![0.0; plan.dof()];
    let f = generalized_force(&plan.friction_only(), &pl, &legs, u, &z, false);
    let a = actuation_matrix(plan, &pl, &legs);
    solve_dyn(&a, &f, true, plan.column_units())
}

/// The generalized force `I u̇ + C u − γ` of the speeds `u` (before the actuation map).
pub fn generalized_effort(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, ud])?;
    let (pl, legs) = kinematics(plan, x)?;
    finite(generalized_force(plan, &pl, &legs, u, ud, true))
}

/// The generalized inertia `I = TᵀMT` of the speeds `u`.
pub fn mass_matrix(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (pl, legs) = kinematics(plan, x)?;
    let i = generalized_inertia(plan, &pl, &legs);
    check_finite(&[&i.concat()])?;
    Ok(i)
}

/// The inertia in actuator space `A⁻ᵀ I A⁻¹` (the lecture's eq. 68).
pub fn actuator_mass_matrix(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (pl, legs) = kinematics(plan, x)?;
    let i = generalized_inertia(plan, &pl, &legs);
    let a = actuation_matrix(plan, &pl, &legs);
    let n = plan.dof();
    // B = I A⁻¹ column by column (A⁻¹ e_j), then A⁻ᵀ B.
    let mut b = vec![vec![0.0; n]; n];
    for j in 0..n {
        let mut e = vec![0.0; n];
        e[j] = 1.0;
        let c = solve_dyn(&a, &e, false, plan.column_units())?;
        for r in 0..n {
            b[r][j] = (0..n).map(|k| i[r][k] * c[k]).sum();
        }
    }
    let mut out = vec![vec![0.0; n]; n];
    for j in 0..n {
        let col: Vec<f64> = (0..n).map(|r| b[r][j]).collect();
        let c = solve_dyn(&a, &col, true, plan.column_units())?;
        for r in 0..n {
            out[r][j] = c[r];
        }
    }
    // Symmetrize (the exact matrix is symmetric).
    for r in 0..n {
        for c in r + 1..n {
            let m = 0.5 * (out[r][c] + out[c][r]);
            out[r][c] = m;
            out[c][r] = m;
        }
    }
    check_finite(&[&out.concat()])?;
    Ok(out)
}

/// Forward dynamics: `u̇` for the actuator efforts `tau`.
pub fn forward_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    tau: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, tau])?;
    finite(forward_dynamics_generic(plan, x, u, tau)?)
}

/// Potential energy of gravity at `x`, `−Σ m_b gᵀ c_b` over the platform and every leg body
/// (J, zero at the base origin). `Err` where the legs cannot be solved.
pub fn potential_energy(plan: &Plan, x: &[f64]) -> Result<f64, Singular> {
    let (pl, legs) = kinematics(plan, x)?;
    let g: V<f64> = plan.gravity;
    let (mass, com, _) = plan.platform;
    let mut v = -mass * dot(g, add(pl.origin, mv(&pl.rot, com)));
    for (lp, lk) in plan.legs.iter().zip(&legs) {
        for (k, (m, _, _)) in lp.bodies.iter().enumerate() {
            let c = lp.frame.apply(&lk.com[k]);
            v -= m * dot(g, c);
        }
    }
    Ok(v)
}
