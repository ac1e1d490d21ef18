//! Wraps every generated function of every bundled mechanism (the list is `list.rs`) in a
//! function of the same name in a module of the same name, `tests_no_panic::<module>::<fn>`.
//!
//! - With the `prove` feature each wrapper carries `#[no_panic]`: the linker fails, naming the
//!   wrapper, unless LLVM removed every panic path from the fully inlined call (fat LTO, one
//!   codegen unit, `panic = "unwind"`). `main` calls every wrapper on opaque inputs
//!   (`black_box`), so nothing is removed as dead code and nothing is constant-folded.
//! - Without it, the same wrappers are the entry points whose reachable machine code
//!   `cargo xtask code-size` measures.
//!
//! The scalar type and the module root are the two aliases below; an `f32` build of the
//! mechanisms only has to change them.

/// The generated code's scalar.
type F = f64;
/// Where the generated modules live.
use mechanisms as root;

use std::hint::black_box;

include!("list.rs");

/// Deterministic inputs in `[-1, 1)` (xorshift), opaque to the optimizer.
fn inputs<const N: usize>(seed: &mut u64, scale: F) -> [F; N] {
    let mut out = [0.0; N];
    for v in &mut out {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        *v = ((*seed >> 11) as F / (1u64 << 53) as F * 2.0 - 1.0) * scale;
    }
    black_box(out)
}

macro_rules! tree {
    ($($m:ident),* $(,)?) => {
        $(
            pub mod $m {
                use super::F;
                use super::root::$m as g;
                const N: usize = g::DOF;

                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn mass_matrix(q: &[F; N]) -> [[F; N]; N] {
                    g::mass_matrix(q)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn coriolis(q: &[F; N], qd: &[F; N]) -> [F; N] {
                    g::coriolis(q, qd)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn gravity(q: &[F; N]) -> [F; N] {
                    g::gravity(q)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn inverse_dynamics(q: &[F; N], qd: &[F; N], qdd: &[F; N]) -> [F; N] {
                    g::inverse_dynamics(q, qd, qdd)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn forward_dynamics(
                    q: &[F; N],
                    qd: &[F; N],
                    tau: &[F; N],
                ) -> Result<[F; N], g::Singular> {
                    g::forward_dynamics(q, qd, tau)
                }

                /// Calls every wrapper once; returns a checksum.
                pub fn run(seed: &mut u64) -> F {
                    let q = super::inputs::<N>(seed, 3.0);
                    let qd = super::inputs::<N>(seed, 1.0);
                    let qdd = super::inputs::<N>(seed, 1.0);
                    let mut s = mass_matrix(&q)[N - 1][0];
                    s += coriolis(&q, &qd)[0];
                    s += gravity(&q)[0];
                    let tau = inverse_dynamics(&q, &qd, &qdd);
                    s += match forward_dynamics(&q, &qd, &tau) {
                        Ok(a) => a[0] - qdd[0],
                        Err(e) => e.value,
                    };
                    s
                }
            }
        )*
        /// Every tree mechanism's `run`, with its name.
        pub const TREES: &[(&str, fn(&mut u64) -> F)] = &[$((stringify!($m), $m::run)),*];
    };
}

macro_rules! parallel {
    ($($m:ident),* $(,)?) => {
        $(
            pub mod $m {
                use super::F;
                use super::root::$m as g;
                const N: usize = g::DOF;
                const NX: usize = g::NX;

                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn inverse_kinematics(x: &[F; NX]) -> Result<[F; N], g::Singular> {
                    g::inverse_kinematics(x)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn actuator_rates(x: &[F; NX], u: &[F; N]) -> Result<[F; N], g::Singular> {
                    g::actuator_rates(x, u)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn inverse_dynamics(
                    x: &[F; NX],
                    u: &[F; N],
                    ud: &[F; N],
                ) -> Result<[F; N], g::Singular> {
                    g::inverse_dynamics(x, u, ud)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn mass_matrix(x: &[F; NX]) -> Result<[[F; N]; N], g::Singular> {
                    g::mass_matrix(x)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn actuator_mass_matrix(x: &[F; NX]) -> Result<[[F; N]; N], g::Singular> {
                    g::actuator_mass_matrix(x)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn forward_dynamics(
                    x: &[F; NX],
                    u: &[F; N],
                    tau: &[F; N],
                ) -> Result<[F; N], g::Singular> {
                    g::forward_dynamics(x, u, tau)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn forward_kinematics(
                    q: &[F; N],
                    guess: &[F; NX],
                ) -> Result<[F; NX], g::NoConvergence> {
                    g::forward_kinematics(q, guess)
                }

                /// Calls every wrapper once (at opaque, arbitrary inputs: errors are values
                /// too); returns a checksum.
                pub fn run(seed: &mut u64) -> F {
                    let pick = |r: Result<F, g::Singular>| match r {
                        Ok(v) => v,
                        Err(e) => e.value,
                    };
                    let x = super::inputs::<NX>(seed, 0.1);
                    let u = super::inputs::<N>(seed, 1.0);
                    let ud = super::inputs::<N>(seed, 1.0);
                    let q = super::inputs::<N>(seed, 0.1);
                    let mut s = pick(inverse_kinematics(&x).map(|v| v[0]));
                    s += pick(actuator_rates(&x, &u).map(|v| v[0]));
                    s += pick(inverse_dynamics(&x, &u, &ud).map(|v| v[0]));
                    s += pick(mass_matrix(&x).map(|m| m[0][0]));
                    s += pick(actuator_mass_matrix(&x).map(|m| m[0][0]));
                    s += pick(forward_dynamics(&x, &u, &ud).map(|v| v[0]));
                    s += match forward_kinematics(&q, &x) {
                        Ok(xf) => xf[0],
                        Err(e) => e.residual,
                    };
                    s
                }
            }
        )*
        /// Every parallel mechanism's `run`, with its name.
        pub const PARALLEL: &[(&str, fn(&mut u64) -> F)] = &[$((stringify!($m), $m::run)),*];
    };
}

macro_rules! closed {
    ($($m:ident),* $(,)?) => {
        $(
            pub mod $m {
                use super::F;
                use super::root::$m as g;
                const N: usize = g::DOF;
                const NX: usize = g::NX;

                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn inverse_kinematics(x: &[F; NX]) -> Result<[F; N], g::Singular> {
                    g::inverse_kinematics(x)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn forward_kinematics(
                    q: &[F; N],
                    guess: &[F; NX],
                ) -> Result<[F; NX], g::NoConvergence> {
                    g::forward_kinematics(q, guess)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn joint_rates(x: &[F; NX], u: &[F; N]) -> Result<[F; NX], g::Singular> {
                    g::joint_rates(x, u)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn actuator_rates(x: &[F; NX], u: &[F; N]) -> Result<[F; N], g::Singular> {
                    g::actuator_rates(x, u)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn actuator_mass_matrix(x: &[F; NX]) -> Result<[[F; N]; N], g::Singular> {
                    g::actuator_mass_matrix(x)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn inverse_dynamics(
                    x: &[F; NX],
                    u: &[F; N],
                    ud: &[F; N],
                ) -> Result<[F; N], g::Singular> {
                    g::inverse_dynamics(x, u, ud)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn mass_matrix(x: &[F; NX]) -> Result<[[F; N]; N], g::Singular> {
                    g::mass_matrix(x)
                }
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn forward_dynamics(
                    x: &[F; NX],
                    u: &[F; N],
                    tau: &[F; N],
                ) -> Result<[F; N], g::Singular> {
                    g::forward_dynamics(x, u, tau)
                }

                /// Calls every wrapper once; returns a checksum.
                pub fn run(seed: &mut u64) -> F {
                    let pick = |r: Result<F, g::Singular>| match r {
                        Ok(v) => v,
                        Err(e) => e.value,
                    };
                    let x = super::inputs::<NX>(seed, 0.1);
                    let u = super::inputs::<N>(seed, 1.0);
                    let ud = super::inputs::<N>(seed, 1.0);
                    let mut s = pick(inverse_kinematics(&x).map(|v| v[0]));
                    let x = match forward_kinematics(&[0.0; N], &x) {
                        Ok(x) => x,
                        Err(e) => {
                            s += e.residual;
                            x
                        }
                    };
                    s += pick(joint_rates(&x, &u).map(|v| v[0]));
                    s += pick(actuator_rates(&x, &u).map(|v| v[0]));
                    s += pick(actuator_mass_matrix(&x).map(|m| m[0][0]));
                    s += pick(inverse_dynamics(&x, &u, &ud).map(|v| v[0]));
                    s += pick(mass_matrix(&x).map(|m| m[0][0]));
                    s += pick(forward_dynamics(&x, &u, &ud).map(|v| v[0]));
                    s
                }
            }
        )*
        /// Every closed-loop mechanism's `run`, with its name.
        pub const CLOSED: &[(&str, fn(&mut u64) -> F)] = &[$((stringify!($m), $m::run)),*];
    };
}

for_each_mechanism!(tree, parallel, closed);

/// A function that can panic (index out of bounds): `--features canary` must fail to link.
#[cfg(feature = "canary")]
#[no_panic::no_panic]
#[inline(never)]
fn canary(v: &[F; 4], i: usize) -> F {
    v[i]
}

fn main() {
    let mut seed = black_box(0x9e37_79b9_7f4a_7c15_u64);
    #[cfg(feature = "canary")]
    println!("canary: {}", canary(&black_box([1.0; 4]), black_box(7)));
    for (name, run) in TREES.iter().chain(PARALLEL).chain(CLOSED) {
        let s = run(&mut seed);
        println!("{name}: checksum {s:e}");
    }
}
