//! The fixed items of every parallel module, around the DAG kernels: the error types, the
//! partially pivoted LU of the actuation matrix `A` and the public functions built on it
//! (`inverse_dynamics`, `actuator_mass_matrix`), and Newton's forward kinematics
//! (`retract`, `fk_residual`, `forward_kinematics`). The error types and the straight-line LU
//! solves are built here; the rest are the real Rust files `codegen/templates/platform_*.rs`,
//! specialized by [`crate::template`].

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::parallel::PlatformMotion;
use runtime::parallel::noc::{self, Plan};

use crate::template::Specialize;
use crate::{Config, emit, lu};

/// `inverse_dynamics`, `actuator_mass_matrix` and `inverse_dynamics_derivatives` around the
/// kernels and the LU solves.
const ACTUATION: &str = include_str!("../../templates/platform_actuation.rs");
/// `retract` of coordinates that hold a quaternion.
const RETRACT_QUATERNION: &str = include_str!("../../templates/platform_retract_quaternion.rs");
/// `retract` of a planar point.
const RETRACT_SUM: &str = include_str!("../../templates/platform_retract_sum.rs");
/// `fk_residual` and `forward_kinematics`.
const NEWTON: &str = include_str!("../../templates/platform_newton.rs");

/// The fixed items of every parallel module: error types, the LU of `A`, and the public
/// functions that wrap the DAG kernels `want` says are emitted (by the name before `_parts`:
/// `id`, `inertia`, `gravity`, `coriolis`, `friction`).
pub(super) fn templates(
    cfg: &Config,
    plan: &Plan,
    revolute: &[bool],
    want: &dyn Fn(&str) -> bool,
    params: bool,
) -> TokenStream {
    let types = error_types(
        plan.motion.parasitic(),
        plan.motion.schoenflies(),
        noc::held_by_couples(plan),
    );
    let lu_solve = lu_fn(
        cfg,
        plan,
        "lu_solve",
        " Solve `a x = b`: LU with partial pivoting by conditional row swaps, straight-line code.\n\n A pivot of `a` with each column scaled by its unit group's reference (the group's largest\n 2-norm, or another group's times the platform's radius between the speeds in rad/s and\n those in m/s, whichever is larger) must exceed the tolerance times the larger of 1 and the largest\n pivot so far (compared squared and cross-multiplied: no square root or division outside\n the error path); otherwise `Err(Site::Actuation(k))` with the ratio of that reference to\n this pivot as the condition estimate.",
        false,
        lu::Rhs::Vector,
        false,
    );
    // Wrappers of the kernels `[scene] functions` may leave out.
    let actuation = Specialize::new(cfg).params(params);
    let split: Vec<&str> = ["gravity", "coriolis", "friction"]
        .into_iter()
        .filter(|f| want(f))
        .collect();
    let id_wrapper = if want("id") || !split.is_empty() {
        let lu_solve_t = lu_fn(
            cfg,
            plan,
            "lu_solve_t",
            " Solve `aᵀ x = b` (as `lu_solve`, on the transpose).",
            true,
            lu::Rhs::Vector,
            false,
        );
        let id = if want("id") {
            actuation.items(ACTUATION, &["inverse_dynamics"])
        } else {
            quote!()
        };
        let split = actuation.items(ACTUATION, &split);
        quote!(#id #split #lu_solve_t)
    } else {
        quote!()
    };
    let inverse: Vec<&str> = [
        ("inertia", "actuator_mass_matrix"),
        ("idd", "inverse_dynamics_derivatives"),
        ("regressor", "regressor"),
    ]
    .into_iter()
    .filter(|(kernel, _)| want(kernel))
    .map(|(_, f)| f)
    .collect();
    let amm_wrapper = if inverse.is_empty() {
        quote!()
    } else {
        let lu_inverse = lu_fn(
            cfg,
            plan,
            "lu_inverse",
            " `a⁻¹`: one factorization (as `lu_solve`) for the `DOF` columns of the identity.",
            false,
            lu::Rhs::Identity,
            false,
        );
        let f = actuation.items(ACTUATION, &inverse);
        quote!(#lu_inverse #f)
    };
    // Over the lanes (`crate::lanes`): the solves of the kernels that have `_lanes` versions.
    let solve_lanes = cfg.lanes.is_some() && (want("id") || want("gravity") || want("coriolis"));
    let inverse_lanes = cfg.lanes.is_some() && want("inertia");
    let lanes = if solve_lanes || inverse_lanes {
        let solve =
            solve_lanes.then(|| lu_fn(cfg, plan, "lu_solve_t", "", true, lu::Rhs::Vector, true));
        let inverse = inverse_lanes
            .then(|| lu_fn(cfg, plan, "lu_inverse", "", false, lu::Rhs::Identity, true));
        let helpers = lu::lanes_helpers();
        quote!(#solve #inverse #helpers)
    } else {
        quote!()
    };
    let kinematics = kinematics(cfg, plan);
    quote! {
        #types

        /// Which actuators are revolute (angles are compared modulo 2π).
        const REVOLUTE: [bool; DOF] = [#(#revolute),*];

        #lu_solve

        #id_wrapper

        #amm_wrapper

        #lanes

        #kinematics
    }
}

/// `Site` (its leg and actuation variants documented with the tolerances; `Constraint` for a
/// platform held in rotation by its legs' couples, `couples`), `Singular` and `NoConvergence`.
fn error_types(parasitic: bool, schoenflies: bool, couples: bool) -> TokenStream {
    let tol = crate::scalar::tolerance;
    let leg_tol = tol(noc::LEG_TOLERANCE);
    let act_tol = tol(noc::ACTUATION_TOLERANCE);
    let mut leg_doc = format!(
        " Leg `k`'s Jacobian is singular: `|det J| ≤ {leg_tol:e} · ∏‖columns‖` (a leg, type-I, singularity)."
    );
    if schoenflies {
        // The shaft's Jacobian columns are orthogonal: its test is the U's bend.
        let shaft_tol = tol(noc::SHAFT_TOLERANCE);
        leg_doc.push_str(&format!(
            " For the tool's R-U-P-U shaft: its universal joint at gimbal lock, `cos² θ ≤ {shaft_tol:e}` (the tube at right angles to the motor axis)."
        ));
    }
    let act_doc = format!(
        " Pivot `i` of the actuation matrix `A` (each column scaled by the largest norm of its unit group, partial pivoting) is `≤ {act_tol:e}` times the larger of 1 and the largest pivot: a parallel (type-II) singularity."
    );
    // A 1T2R platform's pose comes from its legs' constraints, not from a quaternion.
    let platform_doc = if parasitic {
        " The legs' constraints do not fix the platform's parasitic motion: their Jacobian in `(px, py, γ)` is singular."
    } else {
        " The platform quaternion is zero (or not finite)."
    };
    let reach_doc = if parasitic {
        " Leg `k` cannot reach the platform: the pose is outside the workspace (or the parasitic motion's Newton steps leave leg `k`'s constraint unmet)."
    } else {
        " Leg `k` cannot reach the platform: the pose is outside the workspace."
    };
    // A platform whose coordinates hold its rotation: the legs' constraint couples must hold it.
    let constraint_variant = if couples {
        let doc = format!(
            " Pivot `i` of the LU of the legs' constraint couples (unit rows, partial pivoting) is `|p| ≤ {:e}`: the couples no longer hold the rotation the coordinates fix (a constraint singularity; the platform gains a rotation no leg resists).",
            tol(noc::CONSTRAINT_TOLERANCE)
        );
        quote! {
            #[doc = #doc]
            Constraint(usize),
        }
    } else {
        quote!()
    };
    let errors = crate::module::error_types(
        "Which matrix, leg or pivot.",
        "The determinant, pivot or discriminant that failed its test.",
        "The last residual `max |q(x) − q|` (m or rad).",
    );
    quote! {
        /// Where an evaluation failed.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Site {
            /// Pivot `i` of the generalized inertia's `LDLᵀ` (forward dynamics).
            MassMatrix(usize),
            #[doc = #leg_doc]
            Leg(usize),
            #[doc = #reach_doc]
            Reach(usize),
            #[doc = #act_doc]
            Actuation(usize),
            #[doc = #platform_doc]
            Platform,
            #constraint_variant
            /// An input (`x`, `u`, `ud`, `tau`) is NaN or infinite, or so large that a result
            /// overflows.
            Input,
        }

        #errors
    }
}

/// One of the module's LU solves of `A` (`lu_solve`, `lu_solve_t`, `lu_inverse`): the pivot
/// test at the actuation tolerance, squared.
fn lu_fn(
    cfg: &Config,
    plan: &Plan,
    name: &str,
    doc: &str,
    transpose: bool,
    rhs: lu::Rhs,
    lanes: bool,
) -> TokenStream {
    let act_tol = crate::scalar::tolerance(noc::ACTUATION_TOLERANCE);
    // The squared tolerance, rounded to 13 significant digits so that `1e-8²` reads `1e-16`.
    let act_tol2 = act_tol * act_tol;
    let act_tol2 = format!("{act_tol2:.12e}").parse().unwrap_or(act_tol2);
    let sqrt_call = |t: TokenStream| emit::math_call(cfg, "sqrt", t);
    lu::lu_solve_fn(&lu::LuSolve {
        name,
        doc,
        n: plan.dof(),
        transpose,
        rhs,
        tol2: act_tol2,
        units: plan.column_units(),
        sqrt: &sqrt_call,
        lanes,
    })
}

/// `retract`, `fk_residual` and `forward_kinematics` for the platform's motion: where its
/// quaternion sits in `x`, whether `x` has a position, Newton's tolerance (scaled to the
/// mechanism) and iteration limit.
fn kinematics(cfg: &Config, plan: &Plan) -> TokenStream {
    let fk_tol = crate::scalar::tolerance(noc::FK_TOLERANCE);
    let fk_max = noc::FK_MAX_ITERATIONS;
    // Rounded to 13 significant digits, as the squared tolerance of the LU.
    let fk_tol = fk_tol * plan.fk_scale();
    let fk_tol = format!("{fk_tol:.12e}").parse().unwrap_or(fk_tol);
    let (quaternion, has_position) = match plan.motion {
        PlatformMotion::Pose => (3usize, true),
        PlatformMotion::Orientation { .. } => (0usize, false),
        PlatformMotion::PlanarPoint { .. }
        | PlatformMotion::Translation { .. }
        | PlatformMotion::PlanarPose { .. }
        | PlatformMotion::HeaveTilt { .. }
        | PlatformMotion::Schoenflies { .. } => (0usize, false),
    };
    let sp = Specialize::new(cfg)
        .constant("QUATERNION", Literal::usize_unsuffixed(quaternion))
        .flag("HAS_POSITION", has_position)
        .constant("FK_TOLERANCE", Literal::f64_unsuffixed(fk_tol))
        .constant("FK_MAX_ITERATIONS", Literal::usize_unsuffixed(fk_max))
        .doc("FK_TOLERANCE", format!("{fk_tol:e}"))
        .doc("FK_MAX_ITERATIONS", fk_max.to_string());
    // A planar pose's [px, py, φ] ⊕ [δx, δy, δφ] is a sum too.
    let retract = if plan.motion.translates()
        || plan.motion.planar_pose()
        || plan.motion.parasitic()
        || plan.motion.schoenflies()
    {
        sp.items(RETRACT_SUM, &["retract"])
    } else {
        sp.items(RETRACT_QUATERNION, &["retract"])
    };
    let rest = sp.items(NEWTON, &["fk_residual", "forward_kinematics"]);
    quote!(#retract #rest)
}
