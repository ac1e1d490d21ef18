//! A tree's base regressor for the identification tools (`identify`, `excite`): the spec loaded
//! with its `[scene]`, the generator's regressor over the base parameters
//! (`codegen::dynamics::regressor`, the one the generated module's `regressor` is), flattened
//! for evaluation at many states, and the grouping matrix `G` of the base parameters
//! (`π_base = G · π_standard`, docs/identification.md).

use std::collections::HashMap;

use codegen::dynamics::{BODY_PARAMETERS, Tree, body_standard_parameters};
use codegen::sym::{Arg, Graph};
use runtime::model::Model;

use super::grouping::Grouping;
use super::tape::Tape;
use super::tape_lanes::LaneScratch;

/// The base regressor of a tree spec.
pub struct TreeRegressor {
    /// The model (the spec with its `[scene]` applied).
    pub model: Model,
    /// `BASE_PARAMETER_NAMES`.
    pub names: Vec<String>,
    /// `BASE_PARAMETERS` of the spec.
    pub values: Vec<f64>,
    /// `G` over the named standard parameters: `π_base = G π_standard`.
    pub grouping: Grouping,
    tape: Tape,
}

impl TreeRegressor {
    /// The regressor of a validated tree model.
    pub fn new(model: Model) -> TreeRegressor {
        let tree = Tree::new(&model);
        let mut g = Graph::new();
        let r = codegen::dynamics::regressor(&mut g, &tree, &model);
        TreeRegressor {
            tape: Tape::new(&g, &r.outputs),
            names: r.base.names,
            values: r.base.values,
            grouping: Grouping::new(&r.base.groups, r.standard.names),
            model,
        }
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.model.dof()
    }

    /// `Y(q, q̇, q̈)` into `out` (`DOF × NBP`, row-major); `buf` is scratch space.
    pub fn rows(&self, q: &[f64], qd: &[f64], qdd: &[f64], buf: &mut Vec<f64>, out: &mut [f64]) {
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            _ => f64::NAN,
        };
        self.tape.eval(&input, buf, out);
    }

    /// `Y` at `L` states (lane last: `q[i][k]` coordinate `i` of state `k`) into `out` (`L`
    /// blocks of `DOF × NBP`, row-major, state after state): each lane as [`Self::rows`] gives
    /// it, bit for bit.
    pub fn rows_lanes<const L: usize>(
        &self,
        q: &[[f64; L]],
        qd: &[[f64; L]],
        qdd: &[[f64; L]],
        scratch: &mut LaneScratch<L>,
        out: &mut [f64],
    ) {
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            _ => [f64::NAN; L],
        };
        let lanes = self.tape.eval_lanes_in(&input, scratch);
        let size = lanes.len();
        for (k, block) in out.chunks_exact_mut(size).take(L).enumerate() {
            for (o, v) in block.iter_mut().zip(lanes.iter()) {
                *o = v[k];
            }
        }
    }

    /// Inverse dynamics by the runtime's RNEA (independent of the regressor) plus the drives.
    pub fn inverse_dynamics(&self, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
        let tau = runtime::rnea::inverse_dynamics(&self.model, q, qd, qdd);
        (0..self.dof())
            .map(|i| tau[i] + self.model.joints[i].drive.effort(qd[i], qdd[i]))
            .collect()
    }

    /// The base parameters of a model with the same structure: `G · π_standard(model)`
    /// (standard values read by name; a name the model lacks counts 0).
    pub fn base_of(&self, model: &Model) -> Vec<f64> {
        self.grouping.apply(&standard_values(model))
    }
}

/// Every standard parameter a model could have, by name (`XX_<body>` … `M_<body>`, and
/// `FV_`, `FC_`, `IA_<joint>` from the drives as the scene made them).
pub fn standard_values(model: &Model) -> HashMap<String, f64> {
    let mut out = HashMap::new();
    for b in &model.bodies {
        let v = body_standard_parameters(b.mass, &b.com, &b.inertia);
        for (p, x) in BODY_PARAMETERS.iter().zip(v) {
            out.insert(format!("{p}_{}", b.name), x);
        }
    }
    for j in &model.joints {
        out.insert(format!("FV_{}", j.name), j.drive.viscous);
        out.insert(format!("FC_{}", j.name), j.drive.coulomb);
        out.insert(format!("IA_{}", j.name), j.drive.armature);
    }
    out
}
