//! [`Workspace`] of a parallel platform. The matches here are on the platform's motion type
//! (which coordinates it has), not on the mechanism's kind.

use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use nalgebra::DMatrix;

use super::{Axis, InertiaWords, Speed, Workspace, joint_units};
use crate::evaluator::Evaluator;
use crate::indices::{self, EvalError, InertiaIndices, Space};
use crate::model::JointKind;
use crate::parallel::{ParallelModel, Plan, PlatformMotion, noc};
use crate::scalar::Singular;

/// A parallel model and its runtime plan.
#[derive(Clone, Debug)]
pub struct Platform {
    /// The model.
    pub model: ParallelModel,
    /// The runtime's plan.
    pub plan: Plan,
}

impl Platform {
    /// The plan of `model` (its refusal as the runtime words it).
    pub fn new(model: ParallelModel) -> Result<Platform, String> {
        let plan = Plan::new(&model)?;
        Ok(Platform { model, plan })
    }
}

impl Evaluator for Platform {
    fn dof(&self) -> usize {
        self.model.dof()
    }
    fn forward_dynamics(&self, x: &[f64], u: &[f64], tau: &[f64]) -> Result<Vec<f64>, String> {
        Evaluator::forward_dynamics(&self.plan, x, u, tau)
    }
    fn inverse_dynamics(&self, x: &[f64], u: &[f64], ud: &[f64]) -> Result<Vec<f64>, String> {
        Evaluator::inverse_dynamics(&self.plan, x, u, ud)
    }
    fn advance(&self, x: &[f64], d: &[f64]) -> Result<Vec<f64>, String> {
        Evaluator::advance(&self.plan, x, d)
    }
    fn energy(&self, x: &[f64], u: &[f64]) -> Result<(f64, f64), String> {
        Evaluator::energy(&self.plan, x, u)
    }
}

impl Workspace for Platform {
    fn name(&self) -> &str {
        &self.model.name
    }
    fn home(&self) -> Vec<f64> {
        self.model.home_x()
    }
    fn coordinate_names(&self) -> Vec<String> {
        let names: &[&str] = match self.model.motion {
            PlatformMotion::Pose => &["px", "py", "pz", "qw", "qx", "qy", "qz"],
            PlatformMotion::Orientation { .. } => &["qw", "qx", "qy", "qz"],
            PlatformMotion::PlanarPoint { .. } => &["px", "py"],
            PlatformMotion::Translation { .. } => &["px", "py", "pz"],
            PlatformMotion::PlanarPose { .. } => &["px", "py", "phi"],
            PlatformMotion::HeaveTilt { .. } => &["pz", "alpha", "beta"],
            PlatformMotion::Schoenflies { .. } => &["px", "py", "pz", "theta"],
        };
        names.iter().map(|n| String::from(*n)).collect()
    }
    fn speeds(&self) -> Vec<Speed> {
        match self.model.motion {
            PlatformMotion::Pose => [[Speed::Rotation; 3], [Speed::Translation; 3]].concat(),
            PlatformMotion::Orientation { .. } => vec![Speed::Rotation; 3],
            PlatformMotion::PlanarPoint { .. } => vec![Speed::Translation; 2],
            PlatformMotion::Translation { .. } => vec![Speed::Translation; 3],
            PlatformMotion::PlanarPose { .. } => {
                vec![Speed::Translation, Speed::Translation, Speed::Rotation]
            }
            PlatformMotion::HeaveTilt { .. } => {
                vec![Speed::Translation, Speed::Rotation, Speed::Rotation]
            }
            PlatformMotion::Schoenflies { .. } => {
                [[Speed::Translation; 3].as_slice(), &[Speed::Rotation]].concat()
            }
        }
    }
    fn displaced(&self, p: &[f64]) -> Vec<f64> {
        noc::retract(self.model.motion, &self.model.home_x(), p)
    }
    fn axes(&self) -> Vec<Axis> {
        let home = self.model.home_x();
        let pos = |i: usize| Axis::Position {
            name: ["px", "py", "pz"][i].into(),
            index: i,
            home: home[i],
        };
        let rot = |i: usize| Axis::Rotation {
            name: ["rx", "ry", "rz"][i].into(),
            axis: i,
        };
        match self.model.motion {
            PlatformMotion::Pose => vec![pos(0), pos(1), pos(2), rot(0), rot(1), rot(2)],
            PlatformMotion::Orientation { .. } => vec![rot(0), rot(1), rot(2)],
            PlatformMotion::PlanarPoint { .. } => vec![pos(0), pos(1)],
            PlatformMotion::Translation { .. } => vec![pos(0), pos(1), pos(2)],
            // φ is a coordinate of x (no quaternion): stepped as a joint angle.
            PlatformMotion::PlanarPose { .. } => vec![
                pos(0),
                pos(1),
                Axis::Joint {
                    name: "phi".into(),
                    index: 2,
                    revolute: true,
                },
            ],
            // The tilts are coordinates of x (no quaternion): stepped as joint angles.
            PlatformMotion::HeaveTilt { .. } => vec![
                Axis::Position {
                    name: "pz".into(),
                    index: 0,
                    home: home[0],
                },
                Axis::Joint {
                    name: "alpha".into(),
                    index: 1,
                    revolute: true,
                },
                Axis::Joint {
                    name: "beta".into(),
                    index: 2,
                    revolute: true,
                },
            ],
            // θ is a coordinate of x: stepped as a joint angle.
            PlatformMotion::Schoenflies { .. } => vec![
                pos(0),
                pos(1),
                pos(2),
                Axis::Joint {
                    name: "theta".into(),
                    index: 3,
                    revolute: true,
                },
            ],
        }
    }
    fn quaternion(&self) -> Option<usize> {
        match self.model.motion {
            PlatformMotion::Pose => Some(3),
            PlatformMotion::Orientation { .. } => Some(0),
            PlatformMotion::PlanarPoint { .. }
            | PlatformMotion::Translation { .. }
            | PlatformMotion::PlanarPose { .. }
            | PlatformMotion::HeaveTilt { .. }
            | PlatformMotion::Schoenflies { .. } => None,
        }
    }
    fn inertia(&self, x: &[f64], space: Space) -> Result<DMatrix<f64>, EvalError> {
        let rows = match space {
            Space::Actuator => noc::actuator_mass_matrix(&self.plan, x),
            Space::Platform => noc::mass_matrix(&self.plan, x),
        }?;
        Ok(indices::validate_spd(&indices::from_rows(&rows)?)?)
    }
    fn indices(&self, x: &[f64], space: Space) -> Result<InertiaIndices, EvalError> {
        indices::parallel_indices(&self.plan, x, space)
    }
    fn inertia_words(&self, space: Space) -> InertiaWords {
        match space {
            Space::Actuator => InertiaWords {
                matrix: "actuator-space inertia A^-T I A^-1 (actuator_mass_matrix), task = actuated joint coordinates",
                ..joint_units(
                    self.model
                        .legs
                        .iter()
                        .map(|l| l.joints[l.actuated].kind == JointKind::Revolute),
                    "mixed",
                )
            },
            Space::Platform => {
                let (unit, acceleration) = match self.model.motion {
                    PlatformMotion::Orientation { .. } => ("kg m^2", "rad/s^2 per unit effort"),
                    PlatformMotion::PlanarPoint { .. } | PlatformMotion::Translation { .. } => {
                        ("kg", "m/s^2 per unit effort")
                    }
                    PlatformMotion::Pose => ("kg m^2 | kg m | kg (mixed)", "mixed"),
                    PlatformMotion::PlanarPose { .. }
                    | PlatformMotion::HeaveTilt { .. }
                    | PlatformMotion::Schoenflies { .. } => ("kg | kg m | kg m^2 (mixed)", "mixed"),
                };
                InertiaWords {
                    matrix: "generalized inertia I in platform speeds u (mass_matrix), efforts tau = A^-T I u'",
                    unit,
                    acceleration,
                }
            }
        }
    }
    fn actuated(&self, x: &[f64]) -> Result<Vec<f64>, Singular> {
        noc::inverse_kinematics(&self.plan, x)
    }
    fn sample_widths(&self) -> Vec<f64> {
        let (angle, reach) = match self.model.motion {
            PlatformMotion::Pose => (0.1, 0.02 * self.model.size()),
            PlatformMotion::Orientation { .. } => (0.3, 0.0),
            PlatformMotion::PlanarPoint { .. } => (0.0, 0.05),
            PlatformMotion::Translation { .. } => (0.0, 0.02 * self.model.size()),
            PlatformMotion::PlanarPose { .. }
            | PlatformMotion::HeaveTilt { .. }
            | PlatformMotion::Schoenflies { .. } => (0.1, 0.02 * self.model.size()),
        };
        self.speeds()
            .iter()
            .map(|s| match s {
                Speed::Translation => reach,
                _ => angle,
            })
            .collect()
    }
    /// The k-th body of every leg (the legs are alike); the platform stays.
    fn body_groups(&self, bodies: &[String]) -> Vec<Vec<String>> {
        let legs = &self.model.legs;
        let longest = legs.iter().map(|l| l.bodies.len()).max().unwrap_or(0);
        (0..longest)
            .map(|k| {
                legs.iter()
                    .filter_map(|l| l.bodies.get(k))
                    .map(|b| b.name.clone())
                    .filter(|n| bodies.contains(n))
                    .collect::<Vec<_>>()
            })
            .filter(|g| !g.is_empty())
            .collect()
    }
}
