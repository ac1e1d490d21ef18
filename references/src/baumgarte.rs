//! Closed loops integrated in redundant coordinates: every joint coordinate of the spanning tree
//! is a state, the loop-closing joints are constraints `Φ(x) = 0` held by Lagrange multipliers,
//! and Baumgarte's stabilization (J. Baumgarte, "Stabilization of constraints and integrals of
//! motion in dynamical systems", Comput. Methods Appl. Mech. Eng. 1, 1972) replaces `Φ̈ = 0` by
//! `Φ̈ + 2α Φ̇ + β² Φ = 0`:
//!
//! ```text
//! [ M(x)  Φ_xᵀ ] [ ẍ ]   [ −h(x, ẋ)                      ]
//! [ Φ_x    0   ] [ μ ] = [ −Φ̇_x ẋ − 2α Φ_x ẋ − β² Φ(x) ]
//! ```
//!
//! with the tree's mass matrix `M` and bias `h` (gravity included) from `runtime::noc` and the
//! loop equations from `runtime::closed::noc::constraints`. This is the classical alternative to
//! the NOC route of `runtime::simulate`, which integrates only the independent coordinates and
//! assembles the others by Newton at every stage, so that its loops cannot drift open. The
//! stability table (docs/accuracy.md) sets the two side by side.

use nalgebra::{DMatrix, DVector};
use runtime::closed::noc::{Plan, constraints};
use runtime::model::Model;

/// What a run gives.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// Simulated time reached (s).
    pub time: f64,
    /// Largest kinetic energy seen (J).
    pub max_kinetic: f64,
    /// Largest `|E(t) − E(0)|` (J).
    pub max_drift: f64,
    /// Largest loop-closure residual `max |Φ|` over the kept loop equations (m for point
    /// equations, dimensionless for axis equations).
    pub max_closure: f64,
    /// Why the run stopped early (a singular KKT matrix).
    pub stopped: Option<String>,
}

impl Run {
    /// `max |E − E0| / max T`.
    pub fn relative_drift(&self) -> f64 {
        if self.max_kinetic > 0.0 {
            self.max_drift / self.max_kinetic
        } else {
            self.max_drift
        }
    }
}

/// `ẍ` from the stabilized KKT system; `None` when it is singular.
fn accel(
    plan: &Plan,
    tree: &Model,
    x: &[f64],
    xd: &[f64],
    alpha: f64,
    beta: f64,
) -> Option<Vec<f64>> {
    let n = x.len();
    let zero = vec![0.0; n];
    let m = runtime::noc::mass_matrix(tree, x);
    let h = runtime::noc::inverse_dynamics(tree, x, xd, &zero);
    let (phi, jac, bias) = constraints(plan, x, xd);
    let k = phi.len();
    let mut a = DMatrix::zeros(n + k, n + k);
    let mut b = DVector::zeros(n + k);
    for i in 0..n {
        for j in 0..n {
            a[(i, j)] = m[(i, j)];
        }
        b[i] = -h[i];
    }
    for (r, row) in jac.iter().enumerate() {
        let mut phid = 0.0;
        for j in 0..n {
            a[(n + r, j)] = row[j];
            a[(j, n + r)] = row[j];
            phid += row[j] * xd[j];
        }
        b[n + r] = -bias[r] - 2.0 * alpha * phid - beta * beta * phi[r];
    }
    let sol = a.lu().solve(&b)?;
    let out: Vec<f64> = (0..n).map(|i| sol[i]).collect();
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// `max |Φ(x)|` over the kept loop equations.
pub fn residual(plan: &Plan, x: &[f64]) -> f64 {
    let zero = vec![0.0; x.len()];
    constraints(plan, x, &zero)
        .0
        .iter()
        .fold(0.0, |m, v| m.max(v.abs()))
}

fn energy(tree: &Model, x: &[f64], xd: &[f64]) -> (f64, f64) {
    let t = runtime::noc::kinetic_energy(tree, x, xd);
    (t, t + runtime::noc::potential_energy(tree, x))
}

/// Classical RK4 of `(x, ẋ)` with step `dt` for `steps` steps from `(x0, 0)`, no actuation, with
/// Baumgarte parameters `alpha`, `beta` (1/s; `0, 0` is the unstabilized index-1 form).
pub fn simulate(
    plan: &Plan,
    tree: &Model,
    x0: &[f64],
    dt: f64,
    steps: usize,
    alpha: f64,
    beta: f64,
) -> Run {
    let n = x0.len();
    let mut x = x0.to_vec();
    let mut xd = vec![0.0; n];
    let (_, e0) = energy(tree, &x, &xd);
    let mut run = Run {
        time: 0.0,
        max_kinetic: 0.0,
        max_drift: 0.0,
        max_closure: residual(plan, &x),
        stopped: None,
    };
    let axpy = |a: &[f64], s: f64, b: &[f64]| -> Vec<f64> {
        a.iter().zip(b).map(|(p, q)| p + s * q).collect()
    };
    for step in 0..steps {
        let f = |x: &[f64], xd: &[f64]| accel(plan, tree, x, xd, alpha, beta);
        // One classical RK4 step; `None` when a stage meets a singular KKT matrix.
        let stages = (|| {
            let a1 = f(&x, &xd)?;
            let (x2, v2) = (axpy(&x, 0.5 * dt, &xd), axpy(&xd, 0.5 * dt, &a1));
            let a2 = f(&x2, &v2)?;
            let (x3, v3) = (axpy(&x, 0.5 * dt, &v2), axpy(&xd, 0.5 * dt, &a2));
            let a3 = f(&x3, &v3)?;
            let (x4, v4) = (axpy(&x, dt, &v3), axpy(&xd, dt, &a3));
            let a4 = f(&x4, &v4)?;
            Some((a1, a2, a3, a4, v2, v3, v4))
        })();
        let Some((a1, a2, a3, a4, v2, v3, v4)) = stages else {
            run.stopped = Some(format!(
                "singular KKT matrix at t = {:.3} s",
                step as f64 * dt
            ));
            return run;
        };
        for i in 0..n {
            x[i] += dt / 6.0 * (xd[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
            xd[i] += dt / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
        }
        run.time = (step + 1) as f64 * dt;
        let (t, e) = energy(tree, &x, &xd);
        run.max_kinetic = run.max_kinetic.max(t);
        run.max_drift = run.max_drift.max((e - e0).abs());
        run.max_closure = run.max_closure.max(residual(plan, &x));
    }
    run
}
