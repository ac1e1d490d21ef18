//! A closed-loop module's regressor ([method.md, "Identification"](../../../docs/method.md#identification-the-regressor-and-base-parameters)):
//! the generalized force of the independent coordinates, `f = Sᵀ τ_tree` (eq. 24), is linear in
//! every tree body's ten standard parameters, in the joints' drive coefficients and in the
//! springs' stiffness and damping. The columns come from unit-parameter models on the same
//! evaluator (`crate::unit_parameters`; a unit stiffness keeps the spring's rest length) and
//! are scanned for base parameters as a tree's are, at random assembled states near home.

use runtime::closed::ClosedModel;
use runtime::closed::noc::{self, Plan};
use runtime::model::{Drive, JointKind};
use runtime::scalar::Singular;

use crate::dynamics::{self, Base};
use crate::scalar::{Sx, with};
use crate::sym::{Arg, ExprId};
use crate::unit_parameters::{self, Column};

/// The regressor kernel over the base parameters (`DOF × NBP`, row-major) and the guards of
/// its evaluation.
pub(super) struct ClosedRegressor {
    pub outputs: Vec<ExprId>,
    pub guards: Vec<ExprId>,
    pub base: Base,
    /// The standard parameters' names, in the order the groups index.
    pub standard_names: Vec<String>,
    /// The model's standard parameters, same order.
    pub standard_values: Vec<f64>,
}

/// `model` with every body, drive and spring zero.
fn bare(model: &ClosedModel) -> ClosedModel {
    let mut m = model.clone();
    for b in &mut m.tree.bodies {
        (b.mass, b.com, b.inertia) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
    }
    for j in &mut m.tree.joints {
        j.drive = Drive::NONE;
    }
    for s in &mut m.springs {
        (s.stiffness, s.damping) = (0.0, 0.0);
    }
    m
}

/// The standard parameters of `model`: each tree body's, the joints' drives, then each
/// spring's stiffness `K` and damping `D` (when it has them).
fn columns(model: &ClosedModel) -> Vec<Column<ClosedModel>> {
    let zero = bare(model);
    let mut out = Vec::new();
    for (b, body) in model.tree.bodies.iter().enumerate() {
        let with = |mass, com, inertia| {
            let mut m = zero.clone();
            let set = &mut m.tree.bodies[b];
            (set.mass, set.com, set.inertia) = (mass, com, inertia);
            m
        };
        out.extend(unit_parameters::body_columns(
            &body.name,
            (body.mass, &body.com, &body.inertia),
            &with,
        ));
    }
    let named: Vec<(&str, Drive)> = model
        .tree
        .joints
        .iter()
        .map(|j| (j.name.as_str(), j.drive))
        .collect();
    out.extend(unit_parameters::drive_columns(&named, &|j, drive| {
        let mut m = zero.clone();
        m.tree.joints[j].drive = drive;
        m
    }));
    for (k, s) in model.springs.iter().enumerate() {
        for (what, value, stiff) in [("K", s.stiffness, true), ("D", s.damping, false)] {
            if value == 0.0 {
                continue;
            }
            let mut m = zero.clone();
            if stiff {
                m.springs[k].stiffness = 1.0;
            } else {
                m.springs[k].damping = 1.0;
            }
            out.push(Column {
                name: format!("{what}_{}", s.name),
                value,
                plus: m,
                minus: None,
            });
        }
    }
    out
}

/// The regressor of `model` at the inputs `x`, `u`, `u̇` over its base parameters. `Ok(None)`
/// when a standard parameter's model has no plan.
pub(super) fn regressor(
    model: &ClosedModel,
    plan: &Plan,
    x: &[Sx],
    u: &[Sx],
    ud: &[Sx],
) -> Result<Option<ClosedRegressor>, Singular> {
    let n = plan.dof();
    let force = |m: &ClosedModel| -> Option<Result<Vec<Sx>, Singular>> {
        let plan = Plan::new(m).ok()?;
        Some(
            noc::configuration(&plan, x, true)
                .map(|c| noc::generalized_force(&plan, &c, u, ud, true)),
        )
    };
    let Some((standard, guards)) = unit_parameters::standard(&columns(model), &force)? else {
        return Ok(None);
    };
    // Random assembled states: the independent coordinates within ±π rad (as a tree's) or ±5 %
    // of the mechanism's size from home, the others by Newton from home (a state where that
    // fails is drawn again; one on another assembly branch is a state all the same); speeds
    // and accelerations within ±1 rad/s or ±0.5 sizes/s.
    let home = plan.home();
    let size = model.size();
    let (step, rate): (Vec<f64>, Vec<f64>) = plan
        .independent
        .iter()
        .map(|&j| match model.tree.joints[j].kind {
            JointKind::Revolute => (std::f64::consts::PI, 1.0),
            JointKind::Prismatic => (0.05 * size, 0.5 * size),
        })
        .unzip();
    let base = with(|g| {
        dynamics::base_parameters_with(g, &standard, n, &mut |r| {
            let xi: Vec<f64> = plan
                .independent
                .iter()
                .zip(&step)
                .map(|(&j, s)| home[j] + s * r.draw())
                .collect();
            let x = noc::newton_assembly(plan, &xi, &home)
                .unwrap_or_else(|_| vec![f64::NAN; home.len()]);
            let u: Vec<f64> = rate.iter().map(|s| s * r.draw()).collect();
            let ud: Vec<f64> = rate.iter().map(|s| s * r.draw()).collect();
            vec![(Arg::X, x), (Arg::U, u), (Arg::Ud, ud)]
        })
    });
    let mut outputs = Vec::with_capacity(n * base.kept.len());
    for i in 0..n {
        outputs.extend(base.kept.iter().map(|&k| standard.columns[k][i]));
    }
    Ok(Some(ClosedRegressor {
        outputs,
        guards,
        base,
        standard_names: standard.names,
        standard_values: standard.values,
    }))
}
