//! Forward dynamics over [`Real`]: `u̇` from `I u̇ = Aᵀ τ − (C u − γ)`, with payloads on the
//! platform and run-time drives.

use alloc::vec;
use alloc::vec::Vec;

use super::force::{generalized_force_with, payload_force};
use super::inertia::{generalized_inertia_with, payload_inertia};
use super::legs::{actuation_matrix, kinematics};
use super::plan::Plan;
use crate::drive::DriveInputs;
use crate::payload::Payload;
use crate::scalar::{Real, Singular};
use crate::solve::solve_spd;

/// Forward dynamics: `u̇` with `I u̇ = Aᵀ τ − (C u − γ)`.
pub fn forward_dynamics_generic<R: Real>(
    plan: &Plan,
    x: &[R],
    u: &[R],
    tau: &[R],
) -> Result<Vec<R>, Singular> {
    forward_dynamics_with(plan, x, u, tau, &[], None)
}

/// [`forward_dynamics_generic`] with [`Payload`]s on the platform (a payload, and the
/// platform's own inertia when it is given at run time) and the leg joints' drives from
/// `drives` (see [`generalized_force_with`]).
pub fn forward_dynamics_with<R: Real>(
    plan: &Plan,
    x: &[R],
    u: &[R],
    tau: &[R],
    payloads: &[Payload<R>],
    drives: Option<&DriveInputs<R>>,
) -> Result<Vec<R>, Singular> {
    let (pl, legs) = kinematics(plan, x)?;
    let n = plan.dof();
    let zero = vec![R::c(0.0); n];
    let mut h = generalized_force_with(plan, &pl, &legs, u, &zero, true, drives);
    for p in payloads {
        let hp = payload_force(plan, &pl, p, u, &zero, true);
        for i in 0..n {
            h[i] = h[i] + hp[i];
        }
    }
    let a = actuation_matrix(plan, &pl, &legs);
    let rhs: Vec<R> = (0..n)
        .map(|i| {
            let mut s = -h[i];
            for (k, row) in a.iter().enumerate() {
                s = s + row[i] * tau[k];
            }
            s
        })
        .collect();
    let mut m = generalized_inertia_with(plan, &pl, &legs, drives);
    for p in payloads {
        let mp = payload_inertia(plan, &pl, p);
        for i in 0..n {
            for j in 0..n {
                m[i][j] = m[i][j] + mp[i][j];
            }
        }
    }
    solve_spd(&m, &rhs)
}
