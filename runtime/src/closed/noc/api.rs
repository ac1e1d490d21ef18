//! The `f64` functions: inputs checked finite, the generic evaluators, outputs checked finite
//! (joint rates, inverse dynamics, the loop equations for integrators in redundant
//! coordinates, the generalized inertia, forward dynamics, the condition of `Φ_d`, potential
//! energy).

use alloc::vec;
use alloc::vec::Vec;

use super::config::configuration;
use super::dynamics::forward_dynamics_generic;
use super::force::generalized_force;
use super::inertia::generalized_inertia;
use super::loop_equations::{jacobian_row, row_bias, row_value};
use super::motion::motions;
use super::plan::Plan;
use super::tree::{kinematics, point_of};
use super::twists::joint_rates_generic;
use crate::algebra::{add, cv, dot, mv, sub};
use crate::scalar::{Singular, Site};

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

/// Efforts of the independent coordinates that hold the mechanism still against gravity and
/// the springs at `x` (`−γ`): `inverse_dynamics(x, 0, 0)`.
pub fn gravity(plan: &Plan, x: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x])?;
    let c = configuration(plan, x, true)?;
    let z = vec![0.0; plan.dof()];
    finite(generalized_force(plan, &c, &z, &z, true))
}

/// Velocity-dependent efforts `C u` (Coriolis and centrifugal terms, the rotor inertias'
/// among them; no gravity, springs or friction).
pub fn coriolis(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u])?;
    let c = configuration(plan, x, true)?;
    let z = vec![0.0; plan.dof()];
    finite(generalized_force(
        &plan.without_friction(),
        &c,
        u,
        &z,
        false,
    ))
}

/// Efforts of the dissipation at `(x, u)`: every joint's friction (viscous and regularized
/// Coulomb) and the springs' damping, mapped to the independent coordinates by `Sᵀ`.
pub fn friction(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u])?;
    let c = configuration(plan, x, true)?;
    let z = vec![0.0; plan.dof()];
    finite(generalized_force(&plan.friction_only(), &c, u, &z, true))
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
