//! The generated dynamics of nocdyn's bundled mechanisms: one module per spec in `specs/`, each
//! with `DOF`, `JOINT_NAMES`, `mass_matrix`, `coriolis`, `gravity`, `inverse_dynamics` and
//! `forward_dynamics` (see the generated headers for op counts).
//!
//! `#![no_std]`, no `alloc`: trigonometry comes from `runtime::math` (std with the `std`
//! feature, `libm` otherwise).
#![no_std]

include!(concat!(env!("OUT_DIR"), "/mechanisms.rs"));
