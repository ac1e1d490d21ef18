//! Compile-fail tests of `nocdyn_macros::mechanism!` (in `tests/ui.rs`). trybuild builds its
//! cases in a project that depends on what this crate depends on: the macro alone, so the macro's
//! own dependencies (codegen, syn, …) are built once there, for the macro, and not a second time
//! for the cases.
