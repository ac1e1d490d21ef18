//! The fixed template of the dynamic performance indices in a generated module
//! (`docs/indices.md`; the runtime twin is `runtime::indices`).
//!
//! [`template`] emits, for a module that already defines `const DOF: usize`, the items
//! * `InertiaIndices` (the results), `IndexError` (its own error type, independent of the
//!   module's `Singular`), the tolerances `INDEX_SYMMETRY_TOLERANCE`,
//!   `INDEX_DEFINITENESS_TOLERANCE` and `INDEX_MAX_SWEEPS`;
//! * `pub fn inertia_indices(m: &[[f64; DOF]; DOF]) -> Result<InertiaIndices, IndexError>`.
//!
//! The function treats the coordinates of `m` as the task coordinates (`J = 1`, so `Λ = E = m`;
//! see `runtime::indices`): pass the tree's `mass_matrix(&q)` (joint space) or a parallel
//! module's `actuator_mass_matrix(&x)?` (actuator space) or `mass_matrix(&x)?` (platform
//! speeds, where `E` is then `I`, not `A⁻ᵀ I`). It is `no_std`, allocation-free and has no
//! panicking operation: fixed-size arrays, loops over constant ranges, the eigenvalues by cyclic
//! Jacobi rotations (entries below 1e-17 of their diagonal pair are set to zero; at most
//! `INDEX_MAX_SWEEPS` sweeps), `sqrt` from the configured math
//! backend. Bad input gives `Err(IndexError)`, never NaN. The items are the real Rust file
//! `codegen/templates/inertia_indices.rs`, specialized by `template::Specialize`.

use proc_macro2::{Literal, TokenStream};

use crate::template::Specialize;

/// The items, as a real Rust file.
const TEMPLATE: &str = include_str!("../templates/inertia_indices.rs");

/// Largest accepted asymmetry, relative to the largest entry (= `runtime::indices`).
pub const SYMMETRY_TOLERANCE: f64 = runtime::indices::SYMMETRY_TOLERANCE;
/// `LDLᵀ` pivots must exceed this times their diagonal entry (= `runtime::indices`).
pub const DEFINITENESS_TOLERANCE: f64 = runtime::indices::DEFINITENESS_TOLERANCE;
/// Jacobi sweeps at most (cyclic Jacobi converges quadratically: a handful suffice).
pub const MAX_SWEEPS: usize = 64;

/// The indices template (items only; needs `DOF` in scope). See the module docs.
pub fn template(cfg: &crate::Config) -> TokenStream {
    Specialize::new(cfg)
        .constant(
            "SYMMETRY_TOLERANCE",
            Literal::f64_unsuffixed(SYMMETRY_TOLERANCE),
        )
        .constant(
            "DEFINITENESS_TOLERANCE",
            Literal::f64_unsuffixed(DEFINITENESS_TOLERANCE),
        )
        .constant("MAX_SWEEPS", Literal::usize_unsuffixed(MAX_SWEEPS))
        .items(
            TEMPLATE,
            &[
                "INDEX_SYMMETRY_TOLERANCE",
                "INDEX_DEFINITENESS_TOLERANCE",
                "INDEX_MAX_SWEEPS",
                "InertiaIndices",
                "IndexError",
                "inertia_indices",
            ],
        )
}
