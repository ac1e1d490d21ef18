//! What the workspace tools (the CLI's `map`, `isotropy` and `reduce`, `docs/indices.md`) ask of
//! a mechanism beyond its dynamics, behind one trait, [`Workspace`], so that they never match on
//! the kind: the coordinates `x` they vary and their names, home, the inertia matrix the indices
//! use and its words, inverse kinematics to the actuated joints.
//!
//! The tools' coordinates `x`: a tree's joint positions `q`; a platform's coordinates (as
//! [`crate::parallel::noc`]); closed loops' independent (actuated) joint positions, the others following
//! by assembly from home (the home branch). They differ from the state of [`Evaluator`] only for
//! closed loops, whose state holds every joint position.
//!
//! Implemented by the tree [`Model`] and by [`Platform`] and [`Loops`], which keep a parallel or
//! closed-loop model beside its runtime plan (the plans hold no names and no home pose).

use alloc::string::String;
use alloc::vec;
use alloc::vec::Vec;

use nalgebra::DMatrix;

use crate::closed::{self, ClosedModel};
use crate::evaluator::Evaluator;
use crate::indices::{self, EvalError, IndexError, InertiaIndices, Space};
use crate::model::{JointKind, Model};
use crate::scalar::Singular;

mod platform;

pub use platform::Platform;

/// One coordinate a map may vary.
#[derive(Clone, Debug, PartialEq)]
pub enum Axis {
    /// Platform position coordinate `x[index]`, home value `home`.
    Position {
        /// `px` …
        name: String,
        /// Index into `x`.
        index: usize,
        /// Its home value (m).
        home: f64,
    },
    /// Rotation about base axis `axis` (0, 1, 2), applied to the home orientation (the
    /// quaternion at [`Workspace::quaternion`]).
    Rotation {
        /// `rx` …
        name: String,
        /// 0 = x, 1 = y, 2 = z.
        axis: usize,
    },
    /// Joint position `x[index]`.
    Joint {
        /// Joint name.
        name: String,
        /// Index into `x`.
        index: usize,
        /// Revolute?
        revolute: bool,
    },
}

/// One speed coordinate of [`Workspace::displaced`]: what its offset from home moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Speed {
    /// A joint (rad when revolute, m otherwise).
    Joint {
        /// Revolute?
        revolute: bool,
    },
    /// A component of a platform's rotation vector (rad).
    Rotation,
    /// A component of a platform's translation (m).
    Translation,
}

/// Which inertia the indices use, in words: the matrix, its unit and the unit of an
/// acceleration per unit effort.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InertiaWords {
    /// The matrix (e.g. `joint-space inertia H(q) (CRBA), …`).
    pub matrix: &'static str,
    /// Its unit (`kg m^2`, `kg`, or mixed).
    pub unit: &'static str,
    /// The unit of an acceleration per unit effort.
    pub acceleration: &'static str,
}

/// Units of an inertia in joint coordinates, from which joints are revolute.
pub(crate) fn joint_units(
    revolute: impl Iterator<Item = bool> + Clone,
    mixed: &'static str,
) -> InertiaWords {
    let (unit, acceleration) = if revolute.clone().all(|r| r) {
        ("kg m^2", "rad/s^2 per N m")
    } else if revolute.clone().all(|r| !r) {
        ("kg", "m/s^2 per N")
    } else {
        (mixed, "mixed")
    };
    InertiaWords {
        matrix: "",
        unit,
        acceleration,
    }
}

/// A mechanism as the workspace tools see it (see the module docs for `x`).
pub trait Workspace: Evaluator {
    /// The mechanism's name.
    fn name(&self) -> &str;

    /// `x` at home.
    fn home(&self) -> Vec<f64>;

    /// The names of the entries of `x`.
    fn coordinate_names(&self) -> Vec<String>;

    /// The speed coordinates of [`Workspace::displaced`], one per degree of freedom.
    fn speeds(&self) -> Vec<Speed>;

    /// `x` at the offsets `p` from home in speed coordinates (a platform's orientation by its
    /// rotation vector, retracted as in `parallel::noc::retract`).
    fn displaced(&self, p: &[f64]) -> Vec<f64>;

    /// The axes a map may vary, in the order offered.
    fn axes(&self) -> Vec<Axis>;

    /// Where `x` holds a unit quaternion (`[w, x, y, z]`) that [`Axis::Rotation`] turns.
    fn quaternion(&self) -> Option<usize> {
        None
    }

    /// Whether `x` is the position of every joint (a tree's `q`), so that a tool may take all
    /// of them (`--at`) or name them by index (`q0`, `q1`, …).
    fn every_joint(&self) -> bool {
        false
    }

    /// The inertia the indices use at `x` (`space` matters to platforms only), symmetrized and
    /// checked ([`indices::validate_spd`]). `Err(EvalError::Unassembled)` where closed loops do
    /// not assemble on the home branch.
    fn inertia(&self, x: &[f64], space: Space) -> Result<DMatrix<f64>, EvalError>;

    /// The indices at `x` (see [`Workspace::inertia`]).
    fn indices(&self, x: &[f64], space: Space) -> Result<InertiaIndices, EvalError> {
        Ok(indices::inertia_indices(&self.inertia(x, space)?)?)
    }

    /// Which matrix [`Workspace::inertia`] is, in words.
    fn inertia_words(&self, space: Space) -> InertiaWords;

    /// The actuated joints' positions at `x` (the identity but for platforms).
    fn actuated(&self, x: &[f64]) -> Result<Vec<f64>, Singular> {
        Ok(x.to_vec())
    }

    /// The home state of [`Evaluator`] (every joint position for closed loops).
    fn home_state(&self) -> Vec<f64> {
        self.home()
    }

    /// Half-widths, one per speed coordinate, of the random offsets from the home state at
    /// which `reduce` compares efforts.
    fn sample_widths(&self) -> Vec<f64>;

    /// Groups of bodies that a model reduction treats together, among the spec's `bodies`:
    /// each body alone but for platforms.
    fn body_groups(&self, bodies: &[String]) -> Vec<Vec<String>> {
        bodies.iter().map(|b| vec![b.clone()]).collect()
    }
}

/// `Err(NotFinite)` unless `x` has `n` finite entries.
fn check_input(x: &[f64], n: usize) -> Result<(), EvalError> {
    if x.len() != n || x.iter().any(|v| !v.is_finite()) {
        return Err(EvalError::Index(IndexError::NotFinite { row: 0, col: 0 }));
    }
    Ok(())
}

impl Workspace for Model {
    fn name(&self) -> &str {
        &self.name
    }
    fn home(&self) -> Vec<f64> {
        vec![0.0; self.dof()]
    }
    fn coordinate_names(&self) -> Vec<String> {
        self.joints.iter().map(|j| j.name.clone()).collect()
    }
    fn speeds(&self) -> Vec<Speed> {
        self.joints
            .iter()
            .map(|j| Speed::Joint {
                revolute: j.kind == JointKind::Revolute,
            })
            .collect()
    }
    fn displaced(&self, p: &[f64]) -> Vec<f64> {
        p.to_vec()
    }
    fn axes(&self) -> Vec<Axis> {
        self.joints
            .iter()
            .enumerate()
            .map(|(i, j)| Axis::Joint {
                name: j.name.clone(),
                index: i,
                revolute: j.kind == JointKind::Revolute,
            })
            .collect()
    }
    fn every_joint(&self) -> bool {
        true
    }
    fn inertia(&self, x: &[f64], _space: Space) -> Result<DMatrix<f64>, EvalError> {
        check_input(x, self.dof())?;
        Ok(indices::validate_spd(&crate::rnea::mass_matrix(self, x))?)
    }
    fn indices(&self, x: &[f64], _space: Space) -> Result<InertiaIndices, EvalError> {
        Ok(indices::tree_indices(self, x)?)
    }
    fn inertia_words(&self, _space: Space) -> InertiaWords {
        let all_r = self.joints.iter().all(|j| j.kind == JointKind::Revolute);
        let all_p = self.joints.iter().all(|j| j.kind == JointKind::Prismatic);
        let (unit, acceleration) = if all_r {
            ("kg m^2", "rad/s^2 per N m")
        } else if all_p {
            ("kg", "m/s^2 per N")
        } else {
            ("kg m^2 | kg m | kg (mixed joints)", "mixed")
        };
        InertiaWords {
            matrix: "joint-space inertia H(q) (CRBA), task = joint coordinates (J = 1)",
            unit,
            acceleration,
        }
    }
    fn sample_widths(&self) -> Vec<f64> {
        vec![3.0; self.dof()]
    }
}

/// A closed-loop model and its runtime plan.
#[derive(Clone, Debug)]
pub struct Loops {
    /// The model.
    pub model: ClosedModel,
    /// The runtime's plan.
    pub plan: closed::Plan,
}

impl Loops {
    /// The plan of `model` (its refusal as the runtime words it).
    pub fn new(model: ClosedModel) -> Result<Loops, String> {
        let plan = closed::Plan::new(&model)?;
        Ok(Loops { model, plan })
    }

    /// The independent joints, as joints of the spanning tree.
    fn independent(&self) -> impl Iterator<Item = &crate::model::Joint> + Clone {
        self.plan
            .independent
            .iter()
            .map(|&j| &self.model.tree.joints[j])
    }
}

impl Evaluator for Loops {
    fn dof(&self) -> usize {
        self.plan.dof()
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
    fn closure(&self, x: &[f64]) -> f64 {
        Evaluator::closure(&self.plan, x)
    }
}

impl Workspace for Loops {
    fn name(&self) -> &str {
        &self.model.name
    }
    fn home(&self) -> Vec<f64> {
        let home = self.plan.home();
        self.plan.independent.iter().map(|&i| home[i]).collect()
    }
    fn coordinate_names(&self) -> Vec<String> {
        self.independent().map(|j| j.name.clone()).collect()
    }
    fn speeds(&self) -> Vec<Speed> {
        self.independent()
            .map(|j| Speed::Joint {
                revolute: j.kind == JointKind::Revolute,
            })
            .collect()
    }
    fn displaced(&self, p: &[f64]) -> Vec<f64> {
        // The independent joints are zero at home.
        p.to_vec()
    }
    fn axes(&self) -> Vec<Axis> {
        self.independent()
            .enumerate()
            .map(|(k, j)| Axis::Joint {
                name: j.name.clone(),
                index: k,
                revolute: j.kind == JointKind::Revolute,
            })
            .collect()
    }
    fn inertia(&self, x: &[f64], _space: Space) -> Result<DMatrix<f64>, EvalError> {
        use crate::closed::noc;
        check_input(x, self.plan.dof())?;
        // Assemble on the home branch; no convergence = not reachable on it.
        let full = noc::forward_kinematics(&self.plan, x, &vec![0.0; self.plan.nx()])
            .map_err(|_| EvalError::Unassembled)?;
        let rows = noc::mass_matrix(&self.plan, &full)?;
        Ok(indices::validate_spd(&indices::from_rows(&rows)?)?)
    }
    fn inertia_words(&self, _space: Space) -> InertiaWords {
        InertiaWords {
            matrix: "inertia S^T M S of the actuated (independent) joints, closed loops assembled on the home branch",
            ..joint_units(
                self.independent().map(|j| j.kind == JointKind::Revolute),
                "mixed",
            )
        }
    }
    fn home_state(&self) -> Vec<f64> {
        self.plan.home()
    }
    fn sample_widths(&self) -> Vec<f64> {
        vec![0.5; self.plan.dof()]
    }
}
