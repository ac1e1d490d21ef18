//! A platform's base regressor for the identification tools (`identify`, `excite`): the
//! generator's regressor kernel of a parallel module (`codegen::parallel::kernels_for`, the one
//! the generated module's `regressor` wraps: `A` then `F_b`), flattened for evaluation at many
//! states, then `Aᵀ Y = F_b` solved in `f64` so that `τ = Y π_b` (docs/method.md,
//! "Identification"). A state where a guard of the kinematics fails (out of reach, a leg at a
//! singularity) or where `A` is singular has no regressor: an error naming why.

use std::collections::HashMap;

use codegen::dynamics::{BODY_PARAMETERS, body_standard_parameters};
use codegen::parallel::Layout;
use nalgebra::DMatrix;
use runtime::parallel::ParallelModel;
use runtime::parallel::noc::{self, Plan};

use super::grouping::Grouping;
use super::tape::GuardedTape;
use super::tape_lanes::LaneScratch;

/// The base regressor of a platform spec.
pub struct PlatformRegressor {
    /// The model (the spec with its `[scene]` applied).
    pub model: ParallelModel,
    /// Its plan (the runtime's evaluator, for independent efforts).
    pub plan: Plan,
    /// Its home coordinates `x`.
    pub home: Vec<f64>,
    /// `BASE_PARAMETER_NAMES`.
    pub names: Vec<String>,
    /// `BASE_PARAMETERS` of the spec.
    pub values: Vec<f64>,
    /// `G` over the named standard parameters: `π_base = G π_standard`.
    pub grouping: Grouping,
    /// The guards, then `A` (row-major), then `F_b` (row-major).
    tape: GuardedTape,
}

/// A state where a guard of the kinematics fails.
const KINEMATICS: NoRegressor =
    NoRegressor("the kinematics fail there (out of reach, or a leg at a singularity)");

/// A state with no regressor: the reason.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NoRegressor(pub &'static str);

impl PlatformRegressor {
    /// The regressor of a validated platform model; `Err` is the message (exit code 2).
    pub fn new(model: ParallelModel) -> Result<PlatformRegressor, String> {
        let plan = Plan::new(&model).map_err(|e| format!("error: {}: {e}\n", model.name))?;
        let k = codegen::parallel::kernels_for(&model, &plan, &Layout::default(), &[], true)
            .map_err(|e| {
                format!(
                    "error: {}: the mechanism is singular for every input ({e})\n",
                    model.name
                )
            })?;
        let Some(r) = k.regressor else {
            return Err(format!(
                "error: {}: this platform has no regressor (a standard parameter's model has no plan)\n",
                model.name
            ));
        };
        Ok(PlatformRegressor {
            tape: GuardedTape::new(&k.graph, &r.kernel),
            names: r.base.names,
            values: r.base.values,
            grouping: Grouping::new(&r.base.groups, r.standard_names),
            home: model.home_x(),
            model,
            plan,
        })
    }

    /// Degrees of freedom (actuators).
    pub fn dof(&self) -> usize {
        self.model.dof()
    }

    /// Coordinates `x`.
    pub fn nx(&self) -> usize {
        self.model.nx()
    }

    /// Number of base parameters.
    pub fn nbp(&self) -> usize {
        self.values.len()
    }

    /// The actuated joints' names, leg by leg.
    pub fn actuators(&self) -> Vec<String> {
        self.model
            .legs
            .iter()
            .map(|l| l.actuated_name.clone())
            .collect()
    }

    /// `Y(x, u, u̇)` into `out` (`DOF × NBP`, row-major); `buf` is scratch space.
    pub fn rows(
        &self,
        x: &[f64],
        u: &[f64],
        ud: &[f64],
        buf: &mut Vec<f64>,
        out: &mut [f64],
    ) -> Result<(), NoRegressor> {
        let all = self.tape.eval(x, u, ud, buf).ok_or(KINEMATICS)?;
        self.solve(&all, out)
    }

    /// `Y` at `L` states (lane last: `x[i][k]` coordinate `i` of state `k`) into `out` (`L`
    /// blocks of `DOF × NBP`, row-major, state after state): each lane as [`Self::rows`] gives
    /// it, bit for bit (the kernel over the lanes, then each lane's own solve).
    pub fn rows_lanes<const L: usize>(
        &self,
        x: &[[f64; L]],
        u: &[[f64; L]],
        ud: &[[f64; L]],
        scratch: &mut LaneScratch<L>,
        out: &mut [f64],
    ) -> [Result<(), NoRegressor>; L] {
        let (all, ok) = self.tape.eval_lanes(x, u, ud, scratch);
        let size = self.dof() * self.nbp();
        let mut lane = Vec::with_capacity(all.len());
        std::array::from_fn(|k| {
            if !ok[k] {
                return Err(KINEMATICS);
            }
            lane.clear();
            lane.extend(all.iter().map(|v| v[k]));
            self.solve(&lane, &mut out[k * size..(k + 1) * size])
        })
    }

    /// `Y` from the kernel's outputs `all` (`A` then `F_b`, row-major): `Aᵀ Y = F_b` solved.
    fn solve(&self, all: &[f64], out: &mut [f64]) -> Result<(), NoRegressor> {
        let (n, nbp) = (self.dof(), self.nbp());
        // `A` row-major; solve `Aᵀ Y = F_b`.
        let at_t = DMatrix::from_fn(n, n, |r, c| all[c * n + r]);
        let fb = DMatrix::from_row_slice(n, nbp, &all[n * n..]);
        if !(at_t.iter().chain(fb.iter()).all(|v| v.is_finite())) {
            return Err(NoRegressor("the regressor is not finite there"));
        }
        let lu = at_t.lu();
        let d: Vec<f64> = lu.u().diagonal().iter().map(|v| v.abs()).collect();
        let top = d.iter().fold(0.0f64, |m, v| m.max(*v));
        if top.is_nan() || top <= 0.0 || d.iter().any(|v| *v <= 1e-12 * top) {
            return Err(NoRegressor(
                "the actuation matrix A is singular there (an actuator singularity)",
            ));
        }
        let y = lu
            .solve(&fb)
            .ok_or(NoRegressor("the actuation matrix A is singular there"))?;
        for i in 0..n {
            for k in 0..nbp {
                out[i * nbp + k] = y[(i, k)];
            }
        }
        Ok(())
    }

    /// Actuator efforts by the runtime's `f64` evaluator (independent of the regressor).
    pub fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Option<Vec<f64>> {
        noc::inverse_dynamics(&self.plan, x, u, ud).ok()
    }

    /// The base parameters of a model with the same structure: `G · π_standard(model)`
    /// (standard values read by name; a name the model lacks counts 0).
    pub fn base_of(&self, model: &ParallelModel) -> Vec<f64> {
        self.grouping.apply(&standard_values(model))
    }
}

/// Every standard parameter a platform model could have, by name: `XX_<body>` … `M_<body>` of
/// the platform and the legs' bodies, `FV_`, `FC_`, `IA_<joint>` of the legs' joints.
pub fn standard_values(model: &ParallelModel) -> HashMap<String, f64> {
    let mut out = HashMap::new();
    let bodies = std::iter::once(&model.platform).chain(model.legs.iter().flat_map(|l| &l.bodies));
    for b in bodies {
        let v = body_standard_parameters(b.mass, &b.com, &b.inertia);
        for (p, x) in BODY_PARAMETERS.iter().zip(v) {
            out.insert(format!("{p}_{}", b.name), x);
        }
    }
    for j in model.legs.iter().flat_map(|l| &l.joints) {
        out.insert(format!("FV_{}", j.name), j.drive.viscous);
        out.insert(format!("FC_{}", j.name), j.drive.coulomb);
        out.insert(format!("IA_{}", j.name), j.drive.armature);
    }
    out
}
