//! Symbolic dynamics of a kinematic tree: the NOC products `Tᵀ(M ṫ + W M t − w^G)` and
//! `TᵀMT` built in the expression DAG with the cheap association (docs/method.md,
//! "Evaluation order").
//!
//! # From the NOC to the recursions
//! The lecture's twist-shaping matrix of a serial chain is block lower-triangular (eq. 34): body
//! `i`'s twist is `t_i = Σ_{j ≤ i} t_ij θ̇_j` (eq. 33) with the columns `t_ij` of eqs. 31–32 /
//! 46–48. Forming `T` and multiplying would cost `O(n²)`; instead
//! * `t = T θ̇` and `ṫ = T θ̈ + Ṫ θ̇` are evaluated by the chain recursion `ω_i = ω_{i−1} + θ̇_i e_i`
//!   (eqs. 25–26, 35–36) — the same numbers, one joint at a time;
//! * every body's Newton–Euler wrench `M_i ṫ_i + W_i M_i t_i − w_i^G` (eqs. 7–12) is formed once;
//! * `Tᵀ w` is evaluated from the tips: column `j` of `T` maps a body wrench to
//!   `e_jᵀ (n_i + (c_i − o_j) × f_i)` (R) or `e_jᵀ f_i` (P), so summing the wrenches of the
//!   subtree of joint `j`, moved to the joint axis, gives the `j`-th effort (eq. 24). Cost grows
//!   linearly with the number of joints.
//! * `I = TᵀMT` (eq. 21) is formed from composite bodies (the inertia of each subtree lumped into
//!   its root body): entry `(j, k)` is the wrench that a unit rate of joint `j` demands of the
//!   composite body of `j`, projected on joint `k`'s column; quadratic in the joints.
//!
//! # Frames
//! Quantities are resolved in body frames, where inertias are constant and joint axes are
//! coordinate axes: before building, every joint frame is rotated (a constant change of body
//! axes, folded into the constant origins) so that its axis is `+z`. A rotation about a
//! coordinate axis with exact 0/±1 constants then costs nothing, and structural zeros of `T`
//! (a body never depends on joints off its path) never appear in the graph.
//!
//! Gravity enters as an acceleration `−g` of the base (equivalent to `w_i^G = [0; m_i g]` on
//! every body, and free).
//!
//! # Fewer operations, same efforts
//! Every function is linear in the inertial parameters and invariant under the choice of body
//! frames, which leaves room to make the generated code cheaper without changing a single
//! output (beyond rounding). The tricks, after Khalil & Kleinfinger, "Minimum operations and
//! minimum parameters of the dynamic models of tree structure robots", IEEE J. Robotics &
//! Automation 3(6), 1987, and Khalil & Dombre, *Modeling, Identification and Control of
//! Robots*, 2002, ch. 9 and 12:
//! * **Regrouped (base) inertial parameters** (`Tree::regroup`): what a joint's motion cannot
//!   reveal is lumped into the parent body — mass, axial first moment and one transverse moment
//!   of inertia across a revolute joint, the whole rotational inertia across a prismatic one —
//!   and dropped at the fixed base. Most masses become zero, so most body forces shrink to
//!   `U h` with a two-component `h`.
//! * **Free frame choices** (`Tree::choose`): any point of a joint axis can be the body origin
//!   (Khalil's modified-DH freedom), the body axes can be turned about the joint axis, and a
//!   constant turn of the joint frame can be moved into the joint angle (`sin_cos(q + γ)`, one
//!   addition). A greedy search tries the choices that zero an offset coordinate, a rotation
//!   entry, a first moment or a product of inertia, and keeps those that lower the operation
//!   count of inverse dynamics plus mass matrix. Origins stay within the model's length scale.
//! * **Per-body moment forms** (in [`inverse_dynamics`]): about the origin or the mass centre;
//!   gyroscopic term from the products `ω_a ω_b` shared with `U`, or as `ω × (Jω)`; and the
//!   axial inertia `J_zz` optionally apart, resolved in the joint frame where it needs no
//!   rotation back to the parent. The cheapest by marginal operation count is kept.
//!
//! # Layout
//! * `links`: the [`Tree`] of links in the canonical frames (every joint axis turned onto `+z`),
//!   built for one choice of frames; `frames`: the constant frame arithmetic it uses;
//! * `regroup`: the regrouped (base) inertial parameters;
//! * `choice`: the greedy search over the free frame choices, priced by `flops`;
//! * `algebra`: symbolic vectors, matrices and joint rotations over the graph;
//! * `inverse`: [`inverse_dynamics`], the recursion that evaluates `Tᵀ(M ṫ + W M t − w^G)`;
//! * `composite`: [`mass_matrix`], `TᵀMT` by composite bodies;
//! * `forward`: [`forward_dynamics`] by an `Lᵀ D L` factorization;
//! * `derivatives`: [`inverse_dynamics_derivatives`] and [`forward_dynamics_derivatives`],
//!   by differentiating the inverse-dynamics DAG (or by `recursive_derivatives` where that is
//!   cheaper, [`prefer_recursive_derivatives`]) and solving with forward dynamics' factors;
//! * `recursive_derivatives`: [`recursive_inverse_dynamics_derivatives`], `∂τ/∂q` and `∂τ/∂q̇`
//!   from composite quantities per body and dot products per pair of joints;
//! * `drives`: joint friction and rotor inertia;
//! * `kinematics`: [`frame_kinematics`], the pose, Jacobian and `J̇ q̇` of the frames
//!   `[scene] frames` names;
//! * `runtime_params`: the run-time parameter layout ([`param_index`]) and the run-time bodies'
//!   inertial parameters;
//! * `regressor`: the standard regressor, one column per standard inertial or drive parameter;
//! * `base_parameters`: the base (identifiable) parameters found from it, and [`regressor`], the
//!   regressor over them.

mod algebra;
mod base_parameters;
mod choice;
mod composite;
mod derivatives;
mod drives;
mod flops;
mod forward;
mod frames;
mod inverse;
mod kinematics;
mod links;
mod recursive_derivatives;
mod regressor;
mod regroup;
mod runtime_params;

use crate::sym::ExprId;

pub use base_parameters::{Base, Regressor, State, Stream, base_parameters_with, regressor};
pub use composite::mass_matrix;
pub use derivatives::{
    forward_dynamics_derivatives, inverse_dynamics_derivatives, prefer_recursive_derivatives,
};
pub use drives::{add_drive_efforts, friction_effort};
pub use forward::{PIVOT_TOLERANCE, forward_dynamics};
pub use inverse::{Terms, inverse_dynamics};
pub use kinematics::{FramePart, frame_kinematics};
pub use links::Tree;
pub use recursive_derivatives::recursive_inverse_dynamics_derivatives;
pub use regressor::{BODY_PARAMETERS, Standard, body_standard_parameters};
pub use runtime_params::{ParamKind, body_param_index, param_count, param_count_with, param_index};

/// A symbolic 3-vector.
pub type V3 = [ExprId; 3];
/// A symbolic 3×3 matrix (row-major).
pub type M3 = [[ExprId; 3]; 3];
