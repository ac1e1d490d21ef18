//! The NOC of a closed-loop mechanism in joint coordinates, written once over [`Real`] so that
//! the runtime (`f64`) and the generator (symbolic) evaluate the same equations (see the
//! module docs of [`super`] for the method).
//!
//! # One evaluation
//! 1. Tree kinematics from `x`: body rotations and origins, joint axes and points (base frame).
//! 2. The kept loop equations `Φ` and their Jacobian rows over the joints (a cut's point rows:
//!    the columns `e_j × (P − o_j)` (R) or `e_j` (P) of the joints between the two bodies; its
//!    axis rows: `(ω_b − ω_a)·(m × n)` with `n` the axis on one side and `m ⊥ n` on the other).
//! 3. `Φ_d` (dependent columns) by LU with partial pivoting; `ẋ = S u`. An overconstrained
//!    loop's redundant equations that do not vanish identically are spare rows of the LU
//!    ([`Plan::spare`]): the pivoting chooses, per configuration, which equations to solve.
//! 4. The body motions with `ẍ = 0` give the bias `Φ̇ ẋ`; `ẍ_d = −Φ_d⁻¹ (Φ_i u̇ + Φ̇ ẋ)`.
//! 5. Each body's Newton–Euler wrench projected on its twists per unit speed (the columns of
//!    `S` pushed through the tree's velocity recursion): `f = Tᵀ w`, the lecture's eqs. 21–24
//!    (docs/method.md, "Closed loops in joint coordinates").
//!
//! # Files
//! One concept per file, in the order of an evaluation; this module re-exports their items and
//! holds the tolerances.
//! * `plan.rs`: [`Plan`] and the choice of the kept loop equations at home.
//! * `band.rs`: the banded order of `Φ_d`'s columns and rows.
//! * `tree.rs`: step 1, the spanning tree's [`kinematics`]; `frames.rs`: the pose of a frame
//!   fixed to a tree body ([`frame_pose`], `[scene] frames`).
//! * `loop_equations.rs`: step 2, the loop equations, their Jacobian rows and bias `Φ̇ ẋ`.
//! * `lu.rs`: step 3, [`lu_factor`] of `Φ_d`.
//! * `config.rs`: steps 1–3 with the closure checks, [`configuration`].
//! * `motion.rs`: step 4, the body motions by the tree recursion, [`motions`].
//! * `twists.rs`: `ẋ = S u` ([`joint_rates_generic`]) and the twists per unit speed.
//! * `force.rs`: step 5, [`generalized_force`] with run-time [`Extras`].
//! * `inertia.rs`: [`generalized_inertia`].
//! * `dynamics.rs`: forward dynamics over [`Real`], [`forward_dynamics_generic`].
//! * `assembly.rs`: forward kinematics by Newton's method, [`forward_kinematics`].
//! * `api.rs`: the `f64` functions, [`joint_rates`] to [`potential_energy`].

#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

mod api;
mod assembly;
mod band;
mod config;
mod dynamics;
mod force;
mod frames;
mod inertia;
mod loop_equations;
mod lu;
mod motion;
mod plan;
mod tree;
mod twists;

pub use api::{
    constraint_condition, constraints, coriolis, forward_dynamics, friction, generalized_effort,
    gravity, inverse_dynamics, joint_rates, mass_matrix, potential_energy,
};
pub use assembly::{closure_residual, forward_kinematics, newton_assembly, newton_step};
pub use config::{Config, configuration};
pub use dynamics::{forward_dynamics_generic, forward_dynamics_with};
pub use force::{Extras, generalized_force, generalized_force_with};
pub use frames::frame_pose;
pub use inertia::{generalized_inertia, generalized_inertia_with};
pub use lu::{Lu, lu_factor};
pub use motion::{BodyMotion, motions};
pub use plan::{CutPlan, JointPlan, Plan, Row};
pub use tree::{Kin, kinematics};
pub use twists::joint_rates_generic;

// `plan.rs` names the spring-dampers `super::Spring`.
use super::Spring;

#[cfg(doc)]
use crate::scalar::Real;

/// Pivot threshold of `Φ_d`'s LU (columns scaled to unit norm): a pivot `|p| ≤ 1e-4` is a
/// configuration where the independent coordinates (nearly) fail to determine the others. The
/// velocity terms carry `Φ_d⁻¹` twice, so rounding grows like `ε/p²`; `1e-4` keeps it near
/// `1e-8` (the same reasoning as [`crate::parallel::noc::LEG_TOLERANCE`]).
pub const CONSTRAINT_TOLERANCE: f64 = 1e-4;
/// Closure tolerance of the inputs: a kept loop equation larger than `1e-9` (times the
/// mechanism's size for the point equations, in m; as is for the axis equations) means `x`
/// does not close the loops: `Singular { site: Closure(k) }`.
pub const CLOSURE_TOLERANCE: f64 = 1e-9;
/// Newton (forward kinematics): at most this many iterations.
pub const FK_MAX_ITERATIONS: usize = 50;
/// Forward kinematics follows the path from the guess's independent coordinates to the
/// target in stages of at most this (rad; times the mechanism's size for a prismatic joint).
pub const FK_STEP: f64 = 0.25;
/// At most this many stages (longer stages beyond `FK_MAX_STAGES × FK_STEP`).
pub const FK_MAX_STAGES: usize = 64;
/// Newton converges when every kept loop equation is within `1e-12` (point equations times
/// the mechanism's size).
pub const FK_TOLERANCE: f64 = 1e-12;
/// Newton's result must also satisfy every loop equation (the redundant ones) and keep the
/// revolute axes aligned within this (scaled); else it is a spurious branch of the kept ones.
pub const FULL_TOLERANCE: f64 = 1e-9;
/// A spring shorter than this times the mechanism's size has no direction:
/// `Singular { site: Spring(k) }`.
pub const SPRING_TOLERANCE: f64 = 1e-9;
/// Rank tolerance of the home analysis, relative to `‖J‖_F` of the dimensionless loop
/// Jacobian (point rows over the size, prismatic columns times it): a residual at or below it
/// is zero. The loops close at home only to within [`super::HOME_TOLERANCE`], which leaves
/// residuals near that in redundant rows (1.9e-10 measured on the Bricard linkage opened by
/// 0.9e-9 rad), so ten times it; rounding leaves about `ε‖J‖` (1e-16), genuine rows 1e-1 on
/// the bundled loops.
pub const RANK_TOLERANCE: f64 = 1e-8;
