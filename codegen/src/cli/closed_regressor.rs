//! A closed loop's base regressor for the identification tools (`identify`, `excite`): the
//! generator's regressor kernel of a closed-loop module (`codegen::closed::kernels_for`, the one
//! the generated module's `regressor` wraps), flattened for evaluation at many states. Its
//! outputs are `F_b` (`DOF × NBP`, row-major) directly: `τ = F_b π_b`, the efforts of the
//! independent coordinates, over all `NX` tree joint coordinates `x` (assembled), the
//! independent speeds `u` and rates `u̇` (docs/closed-loops.md, "Regressor and base
//! parameters"). A measurement file gives the independent coordinates `q`, assembled here by
//! the module's own Newton solve from the previous row (the first from home), or all of `x`.

use std::collections::HashMap;

use runtime::closed::ClosedModel;
use runtime::closed::noc::{self, Plan};

use super::grouping::Grouping;
use super::platform_regressor::NoRegressor;
use super::tape::GuardedTape;
use super::tape_lanes::LaneScratch;

/// The base regressor of a closed-loop spec.
pub struct ClosedRegressor {
    /// The model (the spec with its `[scene]` applied).
    pub model: ClosedModel,
    /// Its plan (the runtime's evaluator: assembly and independent efforts).
    pub plan: Plan,
    /// All tree joint coordinates at home.
    pub home: Vec<f64>,
    /// `BASE_PARAMETER_NAMES`.
    pub names: Vec<String>,
    /// `BASE_PARAMETERS` of the spec.
    pub values: Vec<f64>,
    /// `G` over the named standard parameters (`XX_<body>`, `FV_<joint>`, `K_<spring>`, …):
    /// `π_base = G π_standard`.
    pub grouping: Grouping,
    /// The guards, then `F_b` (row-major).
    tape: GuardedTape,
}

impl ClosedRegressor {
    /// The regressor of a validated closed-loop model; `Err` is the message (exit code 2).
    pub fn new(model: ClosedModel) -> Result<ClosedRegressor, String> {
        let plan = Plan::new(&model).map_err(|e| format!("error: {}: {e}\n", model.name))?;
        let k = codegen::closed::kernels_for(&model, &plan, &[], true).map_err(|e| {
            format!(
                "error: {}: the mechanism is singular for every input ({e})\n",
                model.name
            )
        })?;
        let Some(r) = k.regressor else {
            return Err(format!(
                "error: {}: this mechanism has no regressor (a standard parameter's model has no plan)\n",
                model.name
            ));
        };
        Ok(ClosedRegressor {
            tape: GuardedTape::new(&k.graph, &r.kernel),
            names: r.base.names,
            values: r.base.values,
            grouping: Grouping::new(&r.base.groups, r.standard_names),
            home: plan.home(),
            model,
            plan,
        })
    }

    /// Degrees of freedom (independent coordinates).
    pub fn dof(&self) -> usize {
        self.plan.dof()
    }

    /// Tree joint coordinates `x`.
    pub fn nx(&self) -> usize {
        self.plan.nx()
    }

    /// The independent (actuated) joints' names.
    pub fn independent(&self) -> Vec<String> {
        self.plan
            .independent
            .iter()
            .map(|&j| self.model.tree.joints[j].name.clone())
            .collect()
    }

    /// The closed configuration `x` with independent coordinates `q`, by the module's Newton
    /// solve from `from` (home when `None`); `None` where it does not converge.
    pub fn assemble(&self, q: &[f64], from: Option<&[f64]>) -> Option<Vec<f64>> {
        noc::newton_assembly(&self.plan, q, from.unwrap_or(&self.home)).ok()
    }

    /// The independent coordinates of a configuration `x`.
    pub fn coordinates(&self, x: &[f64]) -> Vec<f64> {
        self.plan.independent.iter().map(|&j| x[j]).collect()
    }

    /// The independent coordinates at home.
    pub fn home_coordinates(&self) -> Vec<f64> {
        self.coordinates(&self.home)
    }

    /// `F_b(x, u, u̇)` into `out` (`DOF × NBP`, row-major); `buf` is scratch space.
    pub fn rows(
        &self,
        x: &[f64],
        u: &[f64],
        ud: &[f64],
        buf: &mut Vec<f64>,
        out: &mut [f64],
    ) -> Result<(), NoRegressor> {
        let all = self.tape.eval(x, u, ud, buf).ok_or(NOT_CLOSED)?;
        finite(&all)?;
        out[..all.len()].copy_from_slice(&all);
        Ok(())
    }

    /// `F_b` at `L` states (lane last: `x[i][k]` coordinate `i` of state `k`) into `out` (`L`
    /// blocks of `DOF × NBP`, row-major, state after state): each lane as [`Self::rows`] gives
    /// it, bit for bit.
    pub fn rows_lanes<const L: usize>(
        &self,
        x: &[[f64; L]],
        u: &[[f64; L]],
        ud: &[[f64; L]],
        scratch: &mut LaneScratch<L>,
        out: &mut [f64],
    ) -> [Result<(), NoRegressor>; L] {
        let (all, ok) = self.tape.eval_lanes(x, u, ud, scratch);
        let size = all.len();
        std::array::from_fn(|k| {
            if !ok[k] {
                return Err(NOT_CLOSED);
            }
            let lane = &mut out[k * size..(k + 1) * size];
            for (o, v) in lane.iter_mut().zip(all) {
                *o = v[k];
            }
            finite(lane)
        })
    }

    /// Efforts of the independent coordinates by the runtime's `f64` evaluator (independent
    /// of the regressor); `None` where it fails.
    pub fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Option<Vec<f64>> {
        noc::inverse_dynamics(&self.plan, x, u, ud).ok()
    }

    /// The base parameters of a model with the same structure: `G · π_standard(model)`
    /// (standard values read by name; a name the model lacks counts 0).
    pub fn base_of(&self, model: &ClosedModel) -> Vec<f64> {
        self.grouping.apply(&standard_values(model))
    }
}

/// A state where a guard fails.
const NOT_CLOSED: NoRegressor = NoRegressor(
    "the configuration does not close the loops, or the constraints are singular there",
);

/// `Err` where a value of the regressor is not finite.
fn finite(all: &[f64]) -> Result<(), NoRegressor> {
    if all.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(NoRegressor("the regressor is not finite there"))
    }
}

/// Every standard parameter a closed-loop model could have, by name: `XX_<body>` … `M_<body>`
/// of the tree bodies, `FV_`, `FC_`, `IA_<joint>` of the tree joints, `K_`, `D_<spring>`.
pub fn standard_values(model: &ClosedModel) -> HashMap<String, f64> {
    let mut out = super::tree_regressor::standard_values(&model.tree);
    for s in &model.springs {
        out.insert(format!("K_{}", s.name), s.stiffness);
        out.insert(format!("D_{}", s.name), s.damping);
    }
    out
}
