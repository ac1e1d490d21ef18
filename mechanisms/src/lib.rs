//! The generated dynamics of nocdyn's bundled mechanisms: one module per spec in `specs/`, each
//! with its constants and free functions (trees: `DOF`, `JOINT_NAMES`, `FRAME_NAMES` and each tip frame's `_pose`, `_jacobian`, `_jacobian_dot_qd`, `mass_matrix`,
//! `coriolis`, `gravity`, `inverse_dynamics`, `forward_dynamics`, their derivatives, and
//! `regressor` with `NBP`, `BASE_PARAMETERS`, `BASE_PARAMETER_NAMES`; parallel platforms and closed
//! loops: `NX`, `DOF`, `HOME`, kinematics and dynamics, `gravity` and `coriolis` among them; see the generated headers for op
//! counts), and a unit struct `Module` that implements [`Dynamics`] by calling them, so that
//! code over every kind of module is written once.
//!
//! `#![no_std]`, no `alloc`: trigonometry comes from `runtime::math` (std with the `std`
//! feature, `libm` otherwise).
#![no_std]

pub use runtime::Dynamics;

include!(concat!(env!("OUT_DIR"), "/mechanisms.rs"));
