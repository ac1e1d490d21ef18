//! The fixed items of every closed-loop module: the error types, the actuator-space functions
//! that need no kernel (`inverse_kinematics`, `actuator_rates`), and the assembly
//! (`forward_kinematics`, staged, around `newton_assembly`, Newton's method on the
//! `newton_step` kernel). The error types are built here; the rest are the real Rust files
//! `codegen/templates/closed_*.rs`, specialized by [`crate::template`].

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::closed::noc;

use crate::Config;
use crate::params::Layout;
use crate::template::Specialize;

/// `inverse_kinematics`, `actuator_rates` and `actuator_mass_matrix`.
const ACTUATION: &str = include_str!("../../templates/closed_actuation.rs");
/// `forward_kinematics` and `newton_assembly`.
const KINEMATICS: &str = include_str!("../../templates/closed_kinematics.rs");

/// The fixed items (with `Site::Spring` when the mechanism has spring-dampers).
pub(super) fn templates(cfg: &Config, springs: bool) -> TokenStream {
    let types = error_types(springs);
    let actuators =
        Specialize::new(cfg).items(ACTUATION, &["inverse_kinematics", "actuator_rates"]);
    let kinematics = kinematics(cfg);
    quote! {
        #types

        #actuators

        #kinematics
    }
}

/// `Site` (its closure and constraint variants documented with the tolerances; `Spring` with
/// `springs`), `Singular` and `NoConvergence`.
fn error_types(springs: bool) -> TokenStream {
    let tol = crate::scalar::tolerance;
    let con_tol = tol(noc::CONSTRAINT_TOLERANCE);
    let clo_tol = tol(noc::CLOSURE_TOLERANCE);
    let closure_doc = format!(
        " Kept loop equation `k` exceeds `{clo_tol:e}` (times the mechanism's size for a point equation): `x` does not close the loops. `value` is `tol² − Φ_k²`."
    );
    let constraint_doc = format!(
        " Pivot `i` of the LU of `Φ_d` (columns scaled to unit norm, partial pivoting) is `|p| ≤ {con_tol:e}`: the independent coordinates (nearly) fail to determine the others."
    );
    let spring_variant = if springs {
        let doc = format!(
            " Spring `k` (`SPRING_NAMES` order) is shorter than `{:e}` times the mechanism's size: its force has no direction.",
            noc::SPRING_TOLERANCE
        );
        quote! {
            #[doc = #doc]
            Spring(usize),
        }
    } else {
        quote!()
    };
    let errors = crate::module::error_types(
        "Which matrix, equation or pivot.",
        "The value that failed its test.",
        "The last largest scaled loop-equation residual.",
    );
    quote! {
        /// Where an evaluation failed.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Site {
            /// Pivot `i` of the generalized inertia's `LDLᵀ` (forward dynamics).
            MassMatrix(usize),
            #[doc = #closure_doc]
            Closure(usize),
            #[doc = #constraint_doc]
            Constraint(usize),
            #spring_variant
            /// An input is NaN or infinite, or so large that a result overflows.
            Input,
        }

        #errors
    }
}

/// `actuator_mass_matrix`, the name every actuator-space module has: `mass_matrix` itself.
pub(super) fn actuator_mass_matrix(cfg: &Config, layout: &Layout) -> TokenStream {
    Specialize::new(cfg)
        .params(layout.any())
        .items(ACTUATION, &["actuator_mass_matrix"])
}

/// `forward_kinematics` (the independent coordinates moved to `q` in stages, each assembled
/// by `newton_assembly`, else one solve from the guess) and `newton_assembly` (one Newton
/// solve on `newton_step`), with their tolerances (the kept equations', every equation's,
/// and the stall acceptance of single precision) and limits.
fn kinematics(cfg: &Config) -> TokenStream {
    let tol = crate::scalar::tolerance;
    // In single precision the loop equations' rounding floor can sit above the rescaled 1e-12
    // (near 1e-5 of the size for poorly conditioned loops, measured on the four-bar and
    // Bricard): when no step reduces the residual any more, a residual within the rescaled
    // 1e-10 (3.7e-5) is accepted. In f64 the two are the same.
    let stall_tol = if tol(1.0e-12) == 1.0e-12 {
        noc::FK_TOLERANCE
    } else {
        tol(1e-10)
    };
    Specialize::new(cfg)
        .constant(
            "FK_MAX_STAGES",
            Literal::usize_unsuffixed(noc::FK_MAX_STAGES),
        )
        .constant(
            "FK_MAX_STAGES_REAL",
            Literal::f64_unsuffixed(noc::FK_MAX_STAGES as f64),
        )
        .constant(
            "FK_MAX_ITERATIONS",
            Literal::usize_unsuffixed(noc::FK_MAX_ITERATIONS),
        )
        .constant(
            "FK_TOLERANCE",
            Literal::f64_unsuffixed(tol(noc::FK_TOLERANCE)),
        )
        .constant(
            "FULL_TOLERANCE",
            Literal::f64_unsuffixed(tol(noc::FULL_TOLERANCE)),
        )
        .constant("STALL_TOLERANCE", Literal::f64_unsuffixed(stall_tol))
        .items(KINEMATICS, &["forward_kinematics", "newton_assembly"])
}
