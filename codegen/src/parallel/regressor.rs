//! A platform's regressor ([method.md, "Identification"](../../../docs/method.md#identification-the-regressor-and-base-parameters)):
//! the generalized force `f = I u̇ + C u − γ` is linear in every body's ten standard
//! parameters and in the leg joints' drive coefficients, so the actuator efforts are
//! `τ = A⁻ᵀ F(x, u, u̇) π` (eq. 66). The columns of `F` come from unit-parameter models on the
//! same evaluator (`crate::unit_parameters`) and are scanned for base parameters as a tree's
//! are, at random regular states near home; legs and the platform regroup across one another
//! where the scan finds them dependent.

use runtime::model::{Body, Drive};
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use runtime::scalar::Singular;

use crate::dynamics::{self, Base};
use crate::scalar::{Sx, flat, with};
use crate::sym::{Arg, ExprId};
use crate::unit_parameters::{self, Column};

/// The regressor kernel over the base parameters: `A` (row-major), then `F_b` (`DOF × NBP`,
/// row-major), so that `τ = A⁻ᵀ F_b · BASE_PARAMETERS`.
pub(super) struct PlatformRegressor {
    /// `A` then `F_b`.
    pub outputs: Vec<ExprId>,
    /// The guards of its evaluation (the kinematics').
    pub guards: Vec<ExprId>,
    /// The base parameters.
    pub base: Base,
    /// The standard parameters' names, in the order the groups index.
    pub standard_names: Vec<String>,
    /// The model's standard parameters, same order.
    pub standard_values: Vec<f64>,
}

/// `model` with every body and drive zero.
fn bare(model: &ParallelModel) -> ParallelModel {
    let mut m = model.clone();
    let zero = |b: &mut Body| {
        b.mass = 0.0;
        b.com = [0.0; 3];
        b.inertia = [[0.0; 3]; 3];
    };
    zero(&mut m.platform);
    for leg in &mut m.legs {
        leg.bodies.iter_mut().for_each(zero);
        for j in &mut leg.joints {
            j.drive = Drive::NONE;
        }
    }
    m
}

/// The standard parameters of `model`: the platform's, each leg's bodies' in order, then the
/// leg joints' drives.
fn columns(model: &ParallelModel) -> Vec<Column<ParallelModel>> {
    let zero = bare(model);
    let bodies: Vec<&Body> = std::iter::once(&model.platform)
        .chain(model.legs.iter().flat_map(|l| l.bodies.iter()))
        .collect();
    let mut out = Vec::new();
    for (b, body) in bodies.iter().enumerate() {
        let with = |mass, com, inertia| {
            let mut m = zero.clone();
            let set = if b == 0 {
                &mut m.platform
            } else {
                m.legs
                    .iter_mut()
                    .flat_map(|l| l.bodies.iter_mut())
                    .nth(b - 1)
                    .expect("body index within the model")
            };
            (set.mass, set.com, set.inertia) = (mass, com, inertia);
            m
        };
        out.extend(unit_parameters::body_columns(
            &body.name,
            (body.mass, &body.com, &body.inertia),
            &with,
        ));
    }
    let joints: Vec<(usize, usize)> = model
        .legs
        .iter()
        .enumerate()
        .flat_map(|(l, leg)| (0..leg.joints.len()).map(move |j| (l, j)))
        .collect();
    let named: Vec<(&str, Drive)> = joints
        .iter()
        .map(|&(l, j)| {
            let joint = &model.legs[l].joints[j];
            (joint.name.as_str(), joint.drive)
        })
        .collect();
    out.extend(unit_parameters::drive_columns(&named, &|k, drive| {
        let mut m = zero.clone();
        let (l, j) = joints[k];
        m.legs[l].joints[j].drive = drive;
        m
    }));
    out
}

/// Whether speed `j` of `motion` is a rate of turn (rad/s).
fn angular(motion: PlatformMotion, j: usize) -> bool {
    match motion {
        PlatformMotion::Pose | PlatformMotion::Orientation { .. } => j < 3,
        PlatformMotion::PlanarPoint { .. } | PlatformMotion::Translation { .. } => false,
        PlatformMotion::PlanarPose { .. } => j == 2,
        PlatformMotion::HeaveTilt { .. } => j > 0,
        PlatformMotion::Schoenflies { .. } => j == 3,
    }
}

/// The regressor of `model` (whose plan is built at `x`, `u`, `u̇` with actuation matrix `a`)
/// over its base parameters. `Ok(None)` when a standard parameter's model has no plan.
pub(super) fn regressor(
    model: &ParallelModel,
    x: &[Sx],
    u: &[Sx],
    ud: &[Sx],
    a: &[Vec<Sx>],
) -> Result<Option<PlatformRegressor>, Singular> {
    let n = model.dof();
    let force = |m: &ParallelModel| -> Option<Result<Vec<Sx>, Singular>> {
        let plan = Plan::new(m).ok()?;
        Some(
            noc::kinematics(&plan, x)
                .map(|(pl, legs)| noc::generalized_force(&plan, &pl, &legs, u, ud, true)),
        )
    };
    let Some((standard, guards)) = unit_parameters::standard(&columns(model), &force)? else {
        return Ok(None);
    };
    // Random regular states near home: turns within ±0.25 rad and moves within ±5 % of the
    // mechanism's size; speeds and accelerations within ±1 rad/s, ±0.5 sizes/s.
    let home = model.home_x();
    let size = model.size();
    let (step, rate): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|j| {
            if angular(model.motion, j) {
                (0.25, 1.0)
            } else {
                (0.05 * size, 0.5 * size)
            }
        })
        .unzip();
    let base = with(|g| {
        dynamics::base_parameters_with(g, &standard, n, &mut |r| {
            let du: Vec<f64> = step.iter().map(|s| s * r.draw()).collect();
            let x = noc::retract(model.motion, &home, &du);
            let u: Vec<f64> = rate.iter().map(|s| s * r.draw()).collect();
            let ud: Vec<f64> = rate.iter().map(|s| s * r.draw()).collect();
            vec![(Arg::X, x), (Arg::U, u), (Arg::Ud, ud)]
        })
    });
    let mut outputs = flat(a);
    for i in 0..n {
        outputs.extend(base.kept.iter().map(|&k| standard.columns[k][i]));
    }
    Ok(Some(PlatformRegressor {
        outputs,
        guards,
        base,
        standard_names: standard.names,
        standard_values: standard.values,
    }))
}
