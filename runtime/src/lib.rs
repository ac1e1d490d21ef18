//! nocdyn runtime.
//!
//! * [`math`]: the only float entry point of generated code (`sin_cos`, `sqrt`), std or `libm`.
//! * [`model`] (feature `alloc`): the validated mechanism — bodies, joints, frames — that the
//!   generator compiles and the generic runtime evaluates.
//! * [`noc`] (feature `alloc`): the Natural Orthogonal Complement evaluated literally with nalgebra
//!   (`T`, `Ṫ`, `M`, `W`, `I = TᵀMT`, `C = Tᵀ(MṪ+WMT)`): the first oracle.
//! * [`parallel`] (feature `alloc`): simple-platform parallel manipulators — the model, leg
//!   kinematics and the NOC in actuator space, generic over the scalar so the generator reuses it.
//! * [`closed`] (feature `alloc`): closed loops in joint coordinates — a spanning tree, cut
//!   joints, independent coordinates — with the NOC `S = [1; −Φ_d⁻¹Φ_i]`, generic over the scalar.
//! * [`indices`] (feature `alloc`): dynamic performance indices of an inertia matrix — Asada's
//!   ellipsoid, condition number, Ma & Angeles' DCI (both normalizations), Yoshikawa's
//!   manipulability, Khatib & Burdick's isotropic acceleration.
//! * [`simulate`] (feature `alloc`): fixed-step RK4 and symplectic Euler of any of the above
//!   with no actuation, and its energy drift.
//! * [`workspace`] (feature `alloc`): what the workspace tools ask of any kind of mechanism
//!   (coordinates, home, the inertia the indices use), behind one trait.
//! * [`rnea`] (feature `alloc`): recursive Newton–Euler and composite-rigid-body algorithms in
//!   spatial (6-D) algebra, written from their own equations: the independent second route.
#![no_std]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

pub mod math;
pub mod module;

pub use module::Dynamics;

// The shared floor every mechanism kind stands on.
#[cfg(feature = "alloc")]
pub(crate) mod algebra;
#[cfg(feature = "alloc")]
pub mod drive;
#[cfg(feature = "alloc")]
pub mod payload;
#[cfg(feature = "alloc")]
pub mod scalar;
#[cfg(feature = "alloc")]
pub mod solve;

#[cfg(feature = "alloc")]
pub mod closed;
#[cfg(feature = "alloc")]
pub mod evaluator;
#[cfg(feature = "alloc")]
pub mod indices;
#[cfg(feature = "alloc")]
pub mod model;
#[cfg(feature = "alloc")]
pub mod noc;
#[cfg(feature = "alloc")]
pub mod parallel;
#[cfg(feature = "alloc")]
pub mod rnea;
#[cfg(feature = "alloc")]
pub mod simulate;
#[cfg(feature = "alloc")]
pub mod workspace;
