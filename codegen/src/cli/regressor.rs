//! The base regressor of either kind of spec the identification tools take: a tree's
//! ([`TreeRegressor`]: joints, `q, q̇, q̈`) or a platform's ([`PlatformRegressor`]: actuators,
//! `x, u, u̇`), so that `identify` and `excite` are written once. Closed loops are refused.

use codegen::spec::Mechanism;

use super::platform_regressor::{NoRegressor, PlatformRegressor};
use super::samples::Columns;
use super::tree_regressor::TreeRegressor;

/// A spec's base regressor.
pub enum Regressor {
    /// A tree (serial or branched chain).
    Tree(Box<TreeRegressor>),
    /// A parallel mechanism (`[platform]`).
    Platform(Box<PlatformRegressor>),
}

impl Regressor {
    /// Load a spec's text (with its `[scene]`): its regressor and the loader's rendered
    /// warnings. The error is rendered text (exit code 2).
    pub fn compile(name: &str, source: &str) -> Result<(Regressor, String), String> {
        let loaded = codegen::spec::load(name, source, &codegen::spec::SceneOverrides::default())
            .map_err(|d| d.render())?;
        let warnings = if loaded.warnings.is_empty() {
            String::new()
        } else {
            loaded.warnings.render()
        };
        let r = match loaded.mechanism {
            Mechanism::Tree(m) => Regressor::Tree(Box::new(TreeRegressor::new(m))),
            Mechanism::Parallel(m) => Regressor::Platform(Box::new(PlatformRegressor::new(m)?)),
            Mechanism::Closed(_) => {
                return Err(format!(
                    "error: {name}: a mechanism with closed loops; identification works on trees and platforms (closed loops not yet, issue 23)\n"
                ));
            }
        };
        Ok((r, warnings))
    }

    /// The mechanism's name.
    pub fn mechanism(&self) -> &str {
        match self {
            Regressor::Tree(r) => &r.model.name,
            Regressor::Platform(r) => &r.model.name,
        }
    }

    /// Efforts per sample (joints or actuators).
    pub fn dof(&self) -> usize {
        match self {
            Regressor::Tree(r) => r.dof(),
            Regressor::Platform(r) => r.dof(),
        }
    }

    /// Number of base parameters.
    pub fn nbp(&self) -> usize {
        self.values().len()
    }

    /// `BASE_PARAMETER_NAMES`.
    pub fn names(&self) -> &[String] {
        match self {
            Regressor::Tree(r) => &r.names,
            Regressor::Platform(r) => &r.names,
        }
    }

    /// `BASE_PARAMETERS` of the spec.
    pub fn values(&self) -> &[f64] {
        match self {
            Regressor::Tree(r) => &r.values,
            Regressor::Platform(r) => &r.values,
        }
    }

    /// What the efforts act at: `"joint"` or `"actuator"`.
    pub fn effort_kind(&self) -> &'static str {
        match self {
            Regressor::Tree(_) => "joint",
            Regressor::Platform(_) => "actuator",
        }
    }

    /// The names of the efforts' joints (the actuated joints of a platform).
    pub fn effort_names(&self) -> Vec<String> {
        match self {
            Regressor::Tree(r) => r.model.joints.iter().map(|j| j.name.clone()).collect(),
            Regressor::Platform(r) => r.actuators(),
        }
    }

    /// The columns of a measurement file.
    pub fn columns(&self) -> Columns {
        match self {
            Regressor::Tree(_) => Columns::joints(&self.effort_names()),
            Regressor::Platform(r) => {
                let (n, nx) = (r.dof(), r.nx());
                Columns {
                    kinds: ["x", "u", "ud", "tau"],
                    counts: [nx, n, n, n],
                    names: [Vec::new(), Vec::new(), Vec::new(), r.actuators()],
                    differentiable: false,
                }
            }
        }
    }

    /// `Y` at positions `p`, speeds `v`, accelerations `a` into `out` (`DOF × NBP`,
    /// row-major); `buf` is scratch space. A tree always has one.
    pub fn rows(
        &self,
        p: &[f64],
        v: &[f64],
        a: &[f64],
        buf: &mut Vec<f64>,
        out: &mut [f64],
    ) -> Result<(), NoRegressor> {
        match self {
            Regressor::Tree(r) => {
                r.rows(p, v, a, buf, out);
                Ok(())
            }
            Regressor::Platform(r) => r.rows(p, v, a, buf, out),
        }
    }

    /// Whether coordinate `j` of a trajectory is a turn (a platform's angle, bounded by
    /// `--turn`) rather than a move (`--reach`); `None` for a tree's joints (`--q-max`).
    pub fn turns(&self, j: usize) -> Option<bool> {
        match self {
            Regressor::Tree(_) => None,
            Regressor::Platform(r) => Some(super::platform_path::angular(r.model.motion, j)),
        }
    }

    /// The state at trajectory coordinates `d` (rates `dd`, `ddd`): a tree's `(q, q̇, q̈)`
    /// are the coordinates, a platform's `(x, u, u̇)` are around home
    /// ([`super::platform_path`]).
    pub fn state(&self, d: &[f64], dd: &[f64], ddd: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        match self {
            Regressor::Tree(_) => (d.to_vec(), dd.to_vec(), ddd.to_vec()),
            Regressor::Platform(r) => {
                super::platform_path::state(r.model.motion, &r.home, d, dd, ddd)
            }
        }
    }

    /// The efforts by the runtime's own inverse dynamics (independent of the regressor);
    /// `None` where a platform's evaluator finds the state singular.
    pub fn inverse_dynamics(&self, p: &[f64], v: &[f64], a: &[f64]) -> Option<Vec<f64>> {
        match self {
            Regressor::Tree(r) => Some(r.inverse_dynamics(p, v, a)),
            Regressor::Platform(r) => r.inverse_dynamics(p, v, a),
        }
    }

    /// The base parameters of another spec text of the same structure (its `[scene]`
    /// applied), on this regressor's grouping.
    pub fn base_of_spec(&self, file: &str, text: &str) -> Result<Vec<f64>, String> {
        let loaded = codegen::spec::load(file, text, &codegen::spec::SceneOverrides::default())
            .map_err(|d| d.render())?;
        match (self, loaded.mechanism) {
            (Regressor::Tree(r), Mechanism::Tree(m)) => Ok(r.base_of(&m)),
            (Regressor::Platform(r), Mechanism::Parallel(m)) => Ok(r.base_of(&m)),
            _ => Err(format!("error: {file}: not the same kind of mechanism")),
        }
    }
}
