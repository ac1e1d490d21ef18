//! Forward dynamics over [`Real`]: `u̇` from `I u̇ = τ − (C u − γ)`.

use alloc::vec;
use alloc::vec::Vec;

use super::config::configuration;
use super::force::{Extras, generalized_force_with};
use super::inertia::generalized_inertia_with;
use super::plan::Plan;
use crate::scalar::{Real, Singular};
use crate::solve::solve_spd;

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
