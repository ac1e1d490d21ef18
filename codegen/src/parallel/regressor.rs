//! A platform's regressor ([method.md, "Identification"](../../../docs/method.md#identification-the-regressor-and-base-parameters)):
//! the generalized force `f = I u̇ + C u − γ` is linear in every body's ten standard
//! parameters and in the leg joints' drive coefficients, so the actuator efforts are
//! `τ = A⁻ᵀ F(x, u, u̇) π` (eq. 66).
//!
//! Column `k` of `F` is the generalized force of the mechanism whose only parameter is
//! `π_k = 1`, built by the same evaluator on a model with that body's mass, mass centre and
//! central inertia set accordingly and every other body and drive zero. A unit `XX … ZZ` is a
//! massless body with that inertia tensor; a unit `M` a point mass at the origin; a unit
//! `MX` is the difference of a unit mass at `(1, 0, 0)` with central inertia
//! `−(|c|² 1 − c cᵀ)` (so that its inertia about the origin is zero) and the unit `M`. The
//! columns are scanned for base parameters as a tree's are, at random regular states near
//! home; legs and the platform regroup across one another where the scan finds them
//! dependent (identical legs, the platform's mass with the legs' end bodies).

use runtime::model::{Body, Drive, Mat3};
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use runtime::scalar::Singular;

use crate::dynamics::{self, BODY_PARAMETERS, Base, Standard, body_standard_parameters};
use crate::scalar::{Sx, flat, guarded, ids, with};
use crate::sym::{Arg, ExprId};

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

/// What a standard parameter's column is made of: the generalized force of `plus`, less that
/// of `minus`.
struct Column {
    name: String,
    value: f64,
    plus: ParallelModel,
    minus: Option<ParallelModel>,
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

/// `model` with body `b` (0 the platform, then the legs' bodies in order) set to `(m, c, I)`.
fn with_body(
    bare: &ParallelModel,
    b: usize,
    mass: f64,
    com: [f64; 3],
    inertia: Mat3,
) -> ParallelModel {
    let mut m = bare.clone();
    let body = if b == 0 {
        &mut m.platform
    } else {
        m.legs
            .iter_mut()
            .flat_map(|l| l.bodies.iter_mut())
            .nth(b - 1)
            .expect("body index within the model")
    };
    body.mass = mass;
    body.com = com;
    body.inertia = inertia;
    m
}

/// The standard parameters of `model`, each with the models whose forces make its column.
fn columns(model: &ParallelModel) -> Vec<Column> {
    let zero = bare(model);
    let bodies: Vec<&Body> = std::iter::once(&model.platform)
        .chain(model.legs.iter().flat_map(|l| l.bodies.iter()))
        .collect();
    let mut out = Vec::new();
    for (b, body) in bodies.iter().enumerate() {
        let values = body_standard_parameters(body.mass, &body.com, &body.inertia);
        let unit_mass = with_body(&zero, b, 1.0, [0.0; 3], [[0.0; 3]; 3]);
        for (k, what) in BODY_PARAMETERS.iter().enumerate() {
            let (plus, minus) = match k {
                0..=5 => {
                    let (r, c) = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)][k];
                    let mut i = [[0.0; 3]; 3];
                    i[r][c] = 1.0;
                    i[c][r] = 1.0;
                    (with_body(&zero, b, 0.0, [0.0; 3], i), None)
                }
                6..=8 => {
                    let a = k - 6;
                    let mut c = [0.0; 3];
                    c[a] = 1.0;
                    // Central inertia −(|c|² 1 − c cᵀ): none about the origin.
                    let i: Mat3 = std::array::from_fn(|r| {
                        std::array::from_fn(|s| c[r] * c[s] - if r == s { 1.0 } else { 0.0 })
                    });
                    (with_body(&zero, b, 1.0, c, i), Some(unit_mass.clone()))
                }
                _ => (unit_mass.clone(), None),
            };
            out.push(Column {
                name: format!("{what}_{}", body.name),
                value: values[k],
                plus,
                minus,
            });
        }
    }
    // The drives' coefficients, per leg joint, when the model has any.
    let joints = || {
        model.legs.iter().enumerate().flat_map(|(l, leg)| {
            leg.joints
                .iter()
                .enumerate()
                .map(move |(j, joint)| (l, j, joint))
        })
    };
    let friction = joints().any(|(_, _, j)| j.drive.viscous != 0.0 || j.drive.coulomb != 0.0);
    let armature = joints().any(|(_, _, j)| j.drive.armature != 0.0);
    for (l, j, joint) in joints() {
        let d = joint.drive;
        let kinds = [
            ("FV", friction, d.viscous),
            ("FC", friction && d.coulomb_velocity > 0.0, d.coulomb),
            ("IA", armature, d.armature),
        ];
        for (k, (what, on, value)) in kinds.into_iter().enumerate() {
            if !on {
                continue;
            }
            let mut plus = zero.clone();
            let drive = &mut plus.legs[l].joints[j].drive;
            drive.coulomb_velocity = d.coulomb_velocity;
            match k {
                0 => drive.viscous = 1.0,
                1 => drive.coulomb = 1.0,
                _ => drive.armature = 1.0,
            }
            out.push(Column {
                name: format!("{what}_{}", joint.name),
                value,
                plus,
                minus: None,
            });
        }
    }
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
    let cols = columns(model);
    let (built, guards) = guarded(|| -> Result<Option<Vec<Vec<ExprId>>>, Singular> {
        let mut out = Vec::with_capacity(cols.len());
        for c in &cols {
            let Some(plus) = force(&c.plus) else {
                return Ok(None);
            };
            let mut f = plus?;
            if let Some(m) = &c.minus {
                let Some(minus) = force(m) else {
                    return Ok(None);
                };
                let minus = minus?;
                f.iter_mut().zip(&minus).for_each(|(p, m)| *p = *p - *m);
            }
            out.push(ids(&f));
        }
        Ok(Some(out))
    });
    let Some(columns) = built? else {
        return Ok(None);
    };
    let standard = Standard {
        names: cols.iter().map(|c| c.name.clone()).collect(),
        values: cols.iter().map(|c| c.value).collect(),
        columns,
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
