//! nocdyn generator.
//!
//! Data flow (one module per stage, each a pure function):
//! `spec` (TOML / URDF text → validated [`runtime::model::Model`], or [`diag::Diagnostics`]) →
//! `dynamics` (symbolic NOC quantities in an expression DAG, [`sym`]) →
//! `opt` (passes on the DAG) → `emit` (Rust tokens → prettyplease → `String`).
//!
//! [`compile`] is the pure entry point; the CLI, build scripts and the proc macro are thin
//! adapters around it.

pub mod diag;
pub mod spec;
