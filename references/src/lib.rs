//! Independent reference routes for nocdyn's tests: each computes what the generator and the
//! runtime compute, by a route that shares none of their evaluation code.
//!
//! - [`lagrange`]: the Newton–Euler equations of every body with the joint reactions and the
//!   actuator efforts solved as Lagrange multipliers (docs/method.md, "Properties used as
//!   checks", item 5), for parallel mechanisms and closed loops.
//! - [`dd`]: double-double arithmetic (about 32 digits) and the parallel evaluator run on it,
//!   the reference of the accuracy and singularity tests.
//! - [`baumgarte`]: closed loops integrated in all tree coordinates with Baumgarte-stabilized
//!   loop constraints, the baseline of the stability comparison.
#![allow(clippy::needless_range_loop)]

pub mod baumgarte;
pub mod dd;
pub mod lagrange;
