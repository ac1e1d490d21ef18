//! One platform in two routes that share no dynamics code: in task coordinates (the parallel
//! route, `runtime::parallel::noc`) and in joint coordinates (the closed-loop route,
//! `runtime::closed::noc`: its own loop equations, Newton assembly and `Φ_d` solves), compared
//! at corresponding states. `tests/tests/{delta, upu, planar3, prs}.rs` use it.

use runtime::closed::ClosedModel;
use runtime::closed::noc as cnoc;
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, literal};

use crate::pkm::rel;

/// The closed-loop model of a test spec in `tests/data/`.
pub fn closed_data(file: &str) -> ClosedModel {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(file);
    let src = std::fs::read_to_string(&path).unwrap();
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Closed(m), _)) => m,
        Ok(_) => panic!("{file} is not a closed-loop mechanism"),
        Err(d) => panic!("{d}"),
    }
}

fn mat_vec(a: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|r| r.iter().zip(v).map(|(x, y)| x * y).sum())
        .collect()
}

/// The two plans of one platform.
pub struct Pair {
    /// Task coordinates.
    pub task: Plan,
    /// Joint coordinates.
    pub joints: cnoc::Plan,
}

impl Pair {
    /// The plans of `task` and `joints` (the same robot).
    pub fn new(task: &ParallelModel, joints: &ClosedModel) -> Pair {
        Pair {
            task: Plan::new(task).unwrap(),
            joints: cnoc::Plan::new(joints).unwrap(),
        }
    }

    /// At the task state `(p, v, a)` and its counterpart — `q` by the platform's inverse
    /// kinematics, the joint coordinates `x_J` by the closed route's assembly from `q`,
    /// `q̇ = A v`, `q̈ = A a + Ȧ v` (`Ȧ v` the actuated rows of the literal route's `L̇ u`,
    /// kinematics only) — the relative errors (∞-norm) of the inverse dynamics, of the
    /// actuator-space inertia `A⁻ᵀ I A⁻¹` against the closed route's `I`, and of forward
    /// dynamics under efforts moved by `push` per actuator (`q̈` of the closed route against
    /// `A u̇ + Ȧ v`); and `x_J`.
    pub fn compare(&self, p: &[f64], v: &[f64], a: &[f64], push: f64) -> ([f64; 3], Vec<f64>) {
        let (pplan, jplan) = (&self.task, &self.joints);
        let n = pplan.dof();
        let q = noc::inverse_kinematics(pplan, p).unwrap();
        let x = cnoc::forward_kinematics(jplan, &q, &vec![0.0; jplan.nx()]).unwrap();
        let t = literal::terms(pplan, p, v).unwrap();
        let amat: Vec<Vec<f64>> = (0..n)
            .map(|r| (0..n).map(|c| t.a[(r, c)]).collect())
            .collect();
        let bias: Vec<f64> = pplan
            .legs
            .iter()
            .enumerate()
            .map(|(k, lp)| t.ld_u[3 * k + lp.actuated])
            .collect();
        let plus_bias =
            |w: Vec<f64>| -> Vec<f64> { w.iter().zip(&bias).map(|(x, b)| x + b).collect() };
        let qd = mat_vec(&amat, v);
        let qdd = plus_bias(mat_vec(&amat, a));
        let tp = noc::inverse_dynamics(pplan, p, v, a).unwrap();
        let tj = cnoc::inverse_dynamics(jplan, &x, &qd, &qdd).unwrap();
        let mp = noc::actuator_mass_matrix(pplan, p).unwrap();
        let mj = cnoc::mass_matrix(jplan, &x).unwrap();
        let tau: Vec<f64> = tp
            .iter()
            .enumerate()
            .map(|(i, v)| v + push * (i as f64 - 1.0))
            .collect();
        let ap = noc::forward_dynamics(pplan, p, v, &tau).unwrap();
        let qdd_p = plus_bias(mat_vec(&amat, &ap));
        let qdd_j = cnoc::forward_dynamics(jplan, &x, &qd, &tau).unwrap();
        (
            [
                rel(&tp, &tj),
                rel(&mp.concat(), &mj.concat()),
                rel(&qdd_p, &qdd_j),
            ],
            x,
        )
    }
}
