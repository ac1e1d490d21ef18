//! Standard regressor columns from unit-parameter models ([method.md, "Identification"](../../docs/method.md#identification-the-regressor-and-base-parameters)),
//! for the mechanisms whose evaluator takes bodies as mass, mass centre and central inertia
//! (platforms, closed loops): the generalized force is linear in every body's ten standard
//! parameters, in the joints' drive coefficients and in the springs' stiffness and damping,
//! so column `k` is the force of the mechanism whose only parameter is `π_k = 1`.
//!
//! A unit `XX … ZZ` is a massless body with that inertia tensor; a unit `M` a point mass at the
//! body origin; a unit `MX` the difference of a unit mass at `(1, 0, 0)` with central inertia
//! `−(|c|² 1 − c cᵀ)` (so that its inertia about the origin is zero) and the unit `M`.

use runtime::model::{Drive, Mat3, Vec3};
use runtime::scalar::Singular;

use crate::dynamics::{BODY_PARAMETERS, Standard, body_standard_parameters};
use crate::scalar::{Sx, guarded, ids};
use crate::sym::ExprId;

/// One standard parameter: its name, the spec's value, and the model whose force is its
/// column, less that of `minus` when given.
pub(crate) struct Column<M> {
    pub name: String,
    pub value: f64,
    pub plus: M,
    pub minus: Option<M>,
}

/// The ten columns of a body named `name` with parameters `(mass, com, inertia)`: `with(m, c,
/// I)` is the model with every body and drive zero but this one set to `(m, c, I)`.
pub(crate) fn body_columns<M>(
    name: &str,
    (mass, com, inertia): (f64, &Vec3, &Mat3),
    with: &dyn Fn(f64, Vec3, Mat3) -> M,
) -> Vec<Column<M>> {
    let values = body_standard_parameters(mass, com, inertia);
    let zero = [[0.0; 3]; 3];
    BODY_PARAMETERS
        .iter()
        .enumerate()
        .map(|(k, what)| {
            let (plus, minus) = match k {
                0..=5 => {
                    let (r, c) = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)][k];
                    let mut i = zero;
                    i[r][c] = 1.0;
                    i[c][r] = 1.0;
                    (with(0.0, [0.0; 3], i), None)
                }
                6..=8 => {
                    let mut c = [0.0; 3];
                    c[k - 6] = 1.0;
                    // Central inertia −(|c|² 1 − c cᵀ): none about the origin.
                    let i: Mat3 = std::array::from_fn(|r| {
                        std::array::from_fn(|s| c[r] * c[s] - if r == s { 1.0 } else { 0.0 })
                    });
                    (with(1.0, c, i), Some(with(1.0, [0.0; 3], zero)))
                }
                _ => (with(1.0, [0.0; 3], zero), None),
            };
            Column {
                name: format!("{what}_{name}"),
                value: values[k],
                plus,
                minus,
            }
        })
        .collect()
}

/// The drive columns of the joints `(name, drive)`: `FV` and `FC` (the Coulomb level, for the
/// joints with a speed scale) when any joint has friction, `IA` when any has rotor inertia;
/// `with(j, d)` is the model with every body and drive zero but joint `j`'s drive `d`.
pub(crate) fn drive_columns<M>(
    joints: &[(&str, Drive)],
    with: &dyn Fn(usize, Drive) -> M,
) -> Vec<Column<M>> {
    let friction = joints
        .iter()
        .any(|(_, d)| d.viscous != 0.0 || d.coulomb != 0.0);
    let armature = joints.iter().any(|(_, d)| d.armature != 0.0);
    let mut out = Vec::new();
    for (j, (name, d)) in joints.iter().enumerate() {
        let unit = Drive {
            coulomb_velocity: d.coulomb_velocity,
            ..Drive::NONE
        };
        let kinds = [
            (
                "FV",
                friction,
                d.viscous,
                Drive {
                    viscous: 1.0,
                    ..unit
                },
            ),
            (
                "FC",
                friction && d.coulomb_velocity > 0.0,
                d.coulomb,
                Drive {
                    coulomb: 1.0,
                    ..unit
                },
            ),
            (
                "IA",
                armature,
                d.armature,
                Drive {
                    armature: 1.0,
                    ..unit
                },
            ),
        ];
        for (what, on, value, drive) in kinds {
            if on {
                out.push(Column {
                    name: format!("{what}_{name}"),
                    value,
                    plus: with(j, drive),
                    minus: None,
                });
            }
        }
    }
    out
}

/// The generalized force of a model in the current graph: `None` when it has no plan.
pub(crate) type Force<'a, M> = dyn Fn(&M) -> Option<Result<Vec<Sx>, Singular>> + 'a;

/// The standard regressor of `cols`, each column the generalized force `force` builds for its
/// models in the current graph, with the guards that asked for. `Ok(None)` when a model has no
/// plan (`force` gives `None`).
pub(crate) fn standard<M>(
    cols: &[Column<M>],
    force: &Force<'_, M>,
) -> Result<Option<(Standard, Vec<ExprId>)>, Singular> {
    let (built, guards) = guarded(|| -> Result<Option<Vec<Vec<ExprId>>>, Singular> {
        let mut out = Vec::with_capacity(cols.len());
        for c in cols {
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
    Ok(built?.map(|columns| {
        (
            Standard {
                names: cols.iter().map(|c| c.name.clone()).collect(),
                values: cols.iter().map(|c| c.value).collect(),
                columns,
            },
            guards,
        )
    }))
}
