//! One interface to every kind of mechanism the runtime evaluates in `f64`: a tree
//! ([`Model`], `runtime::noc`), a parallel platform ([`parallel::Plan`]) and closed loops
//! ([`closed::Plan`]). Tools that only need the dynamics (the simulator) take a
//! `&dyn Evaluator` and never match on the kind.
//!
//! The state is `(x, u)`: a tree's joint positions and rates; a platform's coordinates (the
//! quaternion kept on the unit sphere by the retraction) and speeds; a closed loop's joint
//! positions (all of them) and its independent rates.

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use crate::closed;
use crate::model::Model;
use crate::parallel;

/// A mechanism's dynamics in `f64`, whatever its kind. Errors are the evaluators' own
/// messages (a singular configuration, a failed assembly).
pub trait Evaluator {
    /// Degrees of freedom: the number of speeds `u`.
    fn dof(&self) -> usize;

    /// Speed rates `u̇` under the actuator efforts `tau` (N or N·m, one per speed).
    fn forward_dynamics(&self, x: &[f64], u: &[f64], tau: &[f64]) -> Result<Vec<f64>, String>;

    /// Actuator efforts (N or N·m, one per speed) for the speed rates `ud`.
    fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Result<Vec<f64>, String>;

    /// `x ⊕ d`: the positions moved by `d`, given in speed coordinates (a tree adds, a platform
    /// retracts onto its manifold, closed loops move their independent coordinates and
    /// reassemble).
    fn advance(&self, x: &[f64], d: &[f64]) -> Result<Vec<f64>, String>;

    /// Kinetic and potential energy (J; the potential is zero at the base origin).
    fn energy(&self, x: &[f64], u: &[f64]) -> Result<(f64, f64), String>;

    /// How far `x` is from closing the loops (closed loops: scaled as in
    /// `closed::noc::closure_residual`); zero for a mechanism without loops.
    fn closure(&self, _x: &[f64]) -> f64 {
        0.0
    }
}

/// `½ uᵀ M u`.
fn kinetic(m: &[Vec<f64>], u: &[f64]) -> f64 {
    0.5 * (0..u.len())
        .map(|i| (0..u.len()).map(|j| u[i] * m[i][j] * u[j]).sum::<f64>())
        .sum::<f64>()
}

impl Evaluator for Model {
    fn dof(&self) -> usize {
        Model::dof(self)
    }
    fn forward_dynamics(&self, x: &[f64], u: &[f64], tau: &[f64]) -> Result<Vec<f64>, String> {
        crate::noc::forward_dynamics(self, x, u, tau)
            .map(|v| v.iter().copied().collect())
            .map_err(|e| format!("{e:?}"))
    }
    fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Result<Vec<f64>, String> {
        Ok(crate::noc::inverse_dynamics(self, x, u, ud)
            .iter()
            .copied()
            .collect())
    }
    fn advance(&self, x: &[f64], d: &[f64]) -> Result<Vec<f64>, String> {
        Ok(x.iter().zip(d).map(|(a, b)| a + b).collect())
    }
    fn energy(&self, x: &[f64], u: &[f64]) -> Result<(f64, f64), String> {
        Ok((
            crate::noc::kinetic_energy(self, x, u),
            crate::noc::potential_energy(self, x),
        ))
    }
}

impl Evaluator for parallel::Plan {
    fn dof(&self) -> usize {
        parallel::Plan::dof(self)
    }
    fn forward_dynamics(&self, x: &[f64], u: &[f64], tau: &[f64]) -> Result<Vec<f64>, String> {
        parallel::noc::forward_dynamics(self, x, u, tau).map_err(|e| format!("{e}"))
    }
    fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Result<Vec<f64>, String> {
        parallel::noc::inverse_dynamics(self, x, u, ud).map_err(|e| format!("{e}"))
    }
    fn advance(&self, x: &[f64], d: &[f64]) -> Result<Vec<f64>, String> {
        Ok(parallel::noc::retract(self.motion, x, d))
    }
    fn energy(&self, x: &[f64], u: &[f64]) -> Result<(f64, f64), String> {
        let m = parallel::noc::mass_matrix(self, x).map_err(|e| format!("{e}"))?;
        let v = parallel::noc::potential_energy(self, x).map_err(|e| format!("{e}"))?;
        Ok((kinetic(&m, u), v))
    }
}

impl Evaluator for closed::Plan {
    fn dof(&self) -> usize {
        closed::Plan::dof(self)
    }
    fn forward_dynamics(&self, x: &[f64], u: &[f64], tau: &[f64]) -> Result<Vec<f64>, String> {
        closed::noc::forward_dynamics(self, x, u, tau).map_err(|e| format!("{e}"))
    }
    fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Result<Vec<f64>, String> {
        closed::noc::inverse_dynamics(self, x, u, ud).map_err(|e| format!("{e}"))
    }
    fn advance(&self, x: &[f64], d: &[f64]) -> Result<Vec<f64>, String> {
        let xi: Vec<f64> = self
            .independent
            .iter()
            .zip(d)
            .map(|(&j, dj)| x[j] + dj)
            .collect();
        closed::noc::forward_kinematics(self, &xi, x).map_err(|e| format!("assembly failed: {e:?}"))
    }
    fn energy(&self, x: &[f64], u: &[f64]) -> Result<(f64, f64), String> {
        let m = closed::noc::mass_matrix(self, x).map_err(|e| format!("{e}"))?;
        Ok((kinetic(&m, u), closed::noc::potential_energy(self, x)))
    }
    fn closure(&self, x: &[f64]) -> f64 {
        closed::noc::closure_residual(self, x)
    }
}
