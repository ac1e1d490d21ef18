//! The NOC of a simple-platform parallel manipulator in actuator space (docs/method.md,
//! "Parallel manipulators: actuation matrix"; the lecture's eqs. 49–72), written once over
//! [`Real`] so that the runtime (`f64`) and the generator (symbolic) evaluate the same
//! equations.
//!
//! # How one evaluation goes
//! 1. The platform pose from `x` (rotation from the quaternion, normalized on the fly).
//! 2. Per leg, in the leg's own frame `L` (the home frame of its first joint, so that its axes
//!    are usually coordinate axes): closed-form inverse kinematics by the Paden–Kahan
//!    subproblems (UPS: the leg length, then the U by "two intersecting axes"; PUS and RUS: the
//!    first joint from the fixed rod length, then the U; spherical RRR: the first two joints by
//!    two intersecting axes), the joints kept as `(sin, cos)` pairs and lengths, never angles.
//! 3. The leg Jacobian `J_J` (3 × 3: the S centre's velocity for a leg ending in S, the
//!    platform's angular velocity for a spherical leg) and its inverse by the adjugate, checked
//!    against [`LEG_TOLERANCE`]: `θ̇_J = J_J⁻¹ G u` with `G` mapping `u` to the end point's
//!    velocity — the lecture's `L_J = J_J⁻¹ T`, one small solve per leg, never a system over
//!    all loops.
//! 4. Joint accelerations `θ̈_J = J_J⁻¹ (ṫ_end − J̇_J θ̇_J)`; leg body twists and twist rates from
//!    the joint rates and accelerations (columns of `T` and `Ṫ`).
//! 5. One Newton–Euler wrench per body, `w = M ṫ + W M t − w^G` (eq. 12), projected:
//!    leg bodies to the leg joints (`τ_J = T_Jᵀ w`), then to the end point by `y = J_J⁻ᵀ τ_J`,
//!    then to `u` by `Gᵀ y`; the platform's wrench directly. The sum is the generalized force
//!    `f = I u̇ + C u − γ` of the speeds `u`.
//! 6. Actuator efforts `τ = A⁻ᵀ f` where `q̇ = A u` stacks the actuated rows of the `J_J⁻¹ G`
//!    (eqs. 66–72); [`lu_solve`] factorizes `A` with partial pivoting.
//!
//! A UPS leg with a perpendicular U whose second axis is perpendicular to the leg (and a
//! massless cross) takes a closed form instead of steps 3–5 and of `J_J⁻¹` in `A`
//! ([`UpsPlan`], `ups_force`; Khalil & Guegan 2004): its frame follows from the leg direction
//! `s`, its row of `A` is `[(R p) × s; s]`, and its force on the platform comes from a few scalar
//! equations in that frame. The generic route still gives its inertia (`generalized_inertia`).
//!
//! # Files
//! One concept per file, in the order of an evaluation; this module re-exports their items.
//! * `plan.rs`: [`Plan`] and [`LegPlan`], the constant data prepared once.
//! * `ups.rs`: the closed-form UPS leg ([`UpsPlan`], [`UpsKin`], `ups_force`).
//! * `delta.rs`: the closed-form Delta leg ([`DeltaPlan`], [`DeltaKin`], `delta_force`): a RUS
//!   leg of a translational platform whose rod (a parallelogram's equivalent) has no spin
//!   inertia, with the scalar leg Jacobian `s = d·(e₀ × (E − O))`.
//! * `pose.rs`: step 1, the platform's pose ([`Platform`]).
//! * `parasitic.rs`: step 1 of a 1T2R platform (`HeaveTilt`): the parasitic components by
//!   the legs' constraints, the twist map `t = S(x) u` and its rate ([`Parasitic`]); every
//!   later step runs as for a 6-DOF pose with `t`, `ṫ`, then projects by `Sᵀ`.
//! * `shaft.rs`: a Schönflies platform's telescopic R–U–P–U shaft to the tool ([`ShaftPlan`]):
//!   its closed-form inverse kinematics, the map of its joint rates from `u`, its force and
//!   inertia (the homokinetic double Cardan: the motor turns with the tool).
//! * `subproblems.rs`: the Paden–Kahan subproblems of step 2.
//! * `legs.rs`: steps 2–3, [`leg_kinematics`] ([`LegKin`]) and [`kinematics`] of every leg;
//!   step 6's [`actuation_matrix`].
//! * `constraint.rs`: after step 3, for a platform whose coordinates hold its rotation fixed
//!   (`Translation`, a `Schoenflies` carrier), the legs' constraint couples and their test
//!   ([`check_constraint`], `Site::Constraint`: the couples no longer hold the rotation).
//! * `generic_leg.rs`: a generic leg's inverse kinematics by Newton steps.
//! * `motion.rs`: step 4, the leg bodies' motions (`leg_motion`).
//! * `force.rs`: step 5, [`generalized_force`] and [`payload_force`].
//! * `inertia.rs`: [`generalized_inertia`] and [`payload_inertia`].
//! * `lu.rs`: step 6's solves with `A`, [`lu_solve`].
//! * `dynamics.rs`: forward dynamics over [`Real`], [`forward_dynamics_generic`].
//! * `api.rs`: the `f64` functions, [`inverse_kinematics`] to [`potential_energy`], and the
//!   split of the efforts: [`gravity`], [`coriolis`], [`friction`].
//! * `assembly.rs`: forward kinematics by Newton's method, [`forward_kinematics`], and
//!   [`retract`].
//! * `frames.rs`: frames fixed to the platform (`[scene] frames`): [`frame_pose`],
//!   [`frame_jacobian`] and [`frame_jacobian_dot_u`].

// Index loops read like the equations; negated float comparisons make NaN fail the test.
#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::collapsible_if
)]

mod api;
mod assembly;
mod constraint;
mod delta;
mod dynamics;
mod force;
mod frames;
mod generic_leg;
mod inertia;
mod legs;
mod lu;
mod motion;
mod parasitic;
mod plan;
mod pose;
mod shaft;
mod subproblems;
mod ups;

pub use crate::payload::Payload;
pub use crate::solve::{NoConvergence, PIVOT_TOLERANCE, Stop, check_finite, solve_spd};

pub use api::{
    JointRates, actuation, actuator_mass_matrix, actuator_rates, coriolis, forward_dynamics,
    friction, generalized_effort, gravity, inverse_dynamics, inverse_kinematics,
    leg_joint_positions, leg_joint_rates, mass_matrix, platform_pose, potential_energy,
};
pub use assembly::{FK_MAX_ITERATIONS, FK_TOLERANCE, forward_kinematics, retract, tangent};
pub use constraint::{check_constraint, constraint_couples, couple_pivots, held_by_couples};
pub use delta::{DeltaKin, DeltaPlan};
pub use dynamics::{forward_dynamics_generic, forward_dynamics_with};
pub use force::{generalized_force, generalized_force_with, leg_rates, payload_force};
pub use frames::{frame_jacobian, frame_jacobian_dot_u, frame_pose, frame_twist};
pub use generic_leg::{GENERIC_IK_ITERATIONS, GENERIC_IK_TOLERANCE};
pub use inertia::{
    generalized_inertia, generalized_inertia_by_columns, generalized_inertia_with, payload_inertia,
};
pub use legs::{
    JointPos, LegKin, actuated_positions, actuation_matrix, kinematics, leg_kinematics, positions,
};
pub use lu::{ColumnUnits, lu_solve};
pub(crate) use motion::leg_motion;
pub use parasitic::{
    FullPose, PARASITIC_ITERATIONS, PARASITIC_TOLERANCE, Parasitic, parasitic, parasitic_pose,
};
pub use plan::{LegPlan, Plan};
pub use pose::{Platform, platform};
pub use shaft::{SHAFT_TOLERANCE, ShaftPlan};
pub use ups::{UpsKin, UpsPlan};

#[cfg(doc)]
use crate::scalar::Real;

/// Leg-Jacobian threshold: a leg is singular when `|det J_J| ≤ LEG_TOLERANCE · ∏‖columns‖`
/// (the Hadamard ratio `h`; its inverse, reported as the condition estimate, grows like the
/// condition number of `J_J`), a moment-arm column's norm taken at least its norm at home
/// (`LegPlan::column_home`: a column that vanishes, the end point reaching a revolute axis, is
/// then a small ratio). The velocity terms carry `J⁻¹` twice, so rounding near a leg
/// singularity grows like `ε/h²` (measured on the five-bar's stretched leg): `1e-4` keeps it
/// below about `1e-8`.
pub const LEG_TOLERANCE: f64 = 1e-4;
/// Actuation-matrix threshold: `A` (each column scaled by its unit group's reference,
/// [`ColumnUnits`]) is singular when a pivot of its partially pivoted LU is
/// `≤ ACTUATION_TOLERANCE` times the larger of 1 and the largest pivot; the condition estimate
/// is the ratio of that reference to the pivot.
pub const ACTUATION_TOLERANCE: f64 = 1e-8;
/// Constraint-couple threshold of a platform held in rotation by its legs (`Translation`, a
/// `Schoenflies` carrier): the legs' constraint couples, as unit rows, are dependent when a
/// pivot of their partially pivoted LU is `≤ CONSTRAINT_TOLERANCE` in magnitude
/// ([`check_constraint`], `Site::Constraint(i)`, condition estimate `1/|pivot|`); the same
/// value as the closed loops' test of `Φ_d`.
pub const CONSTRAINT_TOLERANCE: f64 = 1e-4;
