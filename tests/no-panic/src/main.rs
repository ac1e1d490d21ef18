//! Wraps every generated function of every bundled mechanism (the list is `list.rs`) in a
//! function of the same name, generic over the module's `runtime::Dynamics` implementation:
//! `tests_no_panic::<fn>::<mechanisms::<module>::Module, NX, DOF>`, one instance per module.
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

use mechanisms::Dynamics;
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

// One wrapper per method of `runtime::Dynamics`, generic over the module: each module's
// instance (`mass_matrix::<planar_2r::Module, 2, 2>`, …) is a function of its own, inlined into
// nothing (`#[inline(never)]`) and, with `prove`, guarded by its own `#[no_panic]`, so the proof
// covers every generated function of every module one by one (the trait's methods forward to the
// free functions, and a tree's identities are covered with them). A method the module's kind
// does not have (`joint_rates`, `friction`, the derivatives: `None`) is proved too,
// trivially.

/// `M` with the generated code's scalar.
pub trait Module<const NX: usize, const N: usize>: Dynamics<NX, N, Scalar = F> {}
impl<M: Dynamics<NX, N, Scalar = F>, const NX: usize, const N: usize> Module<NX, N> for M {}

#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn inverse_kinematics<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
) -> Result<[F; N], M::Singular> {
    m.inverse_kinematics(x)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn forward_kinematics<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    q: &[F; N],
    guess: &[F; NX],
) -> Result<[F; NX], M::NoConvergence> {
    m.forward_kinematics(q, guess)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn actuator_rates<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
) -> Result<[F; N], M::Singular> {
    m.actuator_rates(x, u)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn inverse_dynamics<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
    ud: &[F; N],
) -> Result<[F; N], M::Singular> {
    m.inverse_dynamics(x, u, ud)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn mass_matrix<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
) -> Result<[[F; N]; N], M::Singular> {
    m.mass_matrix(x)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn actuator_mass_matrix<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
) -> Result<[[F; N]; N], M::Singular> {
    m.actuator_mass_matrix(x)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn forward_dynamics<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
    tau: &[F; N],
) -> Result<[F; N], M::Singular> {
    m.forward_dynamics(x, u, tau)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn joint_rates<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
) -> Option<Result<[F; NX], M::Singular>> {
    m.joint_rates(x, u)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn coriolis<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
) -> Option<Result<[F; N], M::Singular>> {
    m.coriolis(x, u)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn gravity<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
) -> Option<Result<[F; N], M::Singular>> {
    m.gravity(x)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
pub fn friction<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
) -> Option<Result<[F; N], M::Singular>> {
    m.friction(x, u)
}

#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
#[allow(clippy::type_complexity)]
pub fn inverse_dynamics_derivatives<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
    ud: &[F; N],
) -> Option<Result<([[F; N]; N], [[F; N]; N]), M::Singular>> {
    m.inverse_dynamics_derivatives(x, u, ud)
}
#[cfg_attr(feature = "prove", no_panic::no_panic)]
#[inline(never)]
#[allow(clippy::type_complexity)]
pub fn forward_dynamics_derivatives<M: Module<NX, N>, const NX: usize, const N: usize>(
    m: &M,
    x: &[F; NX],
    u: &[F; N],
    tau: &[F; N],
) -> Option<Result<([[F; N]; N], [[F; N]; N], [[F; N]; N]), M::Singular>> {
    m.forward_dynamics_derivatives(x, u, tau)
}

/// Calls every wrapper of module `m` once, at opaque, arbitrary inputs near its home (errors
/// are values too); returns a checksum.
fn run<M: Module<NX, N>, const NX: usize, const N: usize>(m: &M, seed: &mut u64) -> F {
    let m = black_box(m);
    let first = |r: Result<F, M::Singular>| match r {
        Ok(v) => v,
        Err(e) => {
            black_box(e);
            0.0
        }
    };
    let mut x = inputs::<NX>(seed, 0.1);
    for (x, h) in x.iter_mut().zip(M::HOME) {
        *x += h;
    }
    let u = inputs::<N>(seed, 1.0);
    let ud = inputs::<N>(seed, 1.0);
    let mut s = 0.0;
    let q = inverse_kinematics(m, &x);
    s += first(q.map(|v| v[0]));
    let q = q.unwrap_or(inputs::<N>(seed, 0.1));
    let x = match forward_kinematics(m, &q, &x) {
        Ok(x) => x,
        Err(e) => {
            black_box(e);
            x
        }
    };
    s += first(actuator_rates(m, &x, &u).map(|v| v[0]));
    let tau = inverse_dynamics(m, &x, &u, &ud);
    s += first(tau.map(|v| v[0]));
    s += first(mass_matrix(m, &x).map(|a| a[N - 1][0]));
    s += first(actuator_mass_matrix(m, &x).map(|a| a[0][0]));
    let tau = tau.unwrap_or(ud);
    s += first(forward_dynamics(m, &x, &u, &tau).map(|v| v[0] - ud[0]));
    if let Some(r) = joint_rates(m, &x, &u) {
        s += first(r.map(|v| v[0]));
    }
    for split in [coriolis(m, &x, &u), gravity(m, &x), friction(m, &x, &u)]
        .into_iter()
        .flatten()
    {
        s += first(split.map(|v| v[0]));
    }
    if let Some(r) = inverse_dynamics_derivatives(m, &x, &u, &ud) {
        s += first(r.map(|(a, b)| a[0][0] + b[N - 1][0]));
    }
    if let Some(r) = forward_dynamics_derivatives(m, &x, &u, &tau) {
        s += first(r.map(|(a, b, c)| a[0][0] + b[0][N - 1] + c[N - 1][N - 1]));
    }
    s
}

macro_rules! mechanisms {
    ($($m:ident),* $(,)?) => {
        /// Every mechanism's `run`, with its name.
        pub const MECHANISMS: &[(&str, fn(&mut u64) -> F)] = &[
            $((stringify!($m), |seed| run(&root::$m::Module, seed)),)*
            ("puma560_fma", |seed| run(&puma560_fma::Module, seed)),
        ];
    };
}

for_each_mechanism!(mechanisms);

/// The trees' frame functions (`[scene] frames`; not methods of `runtime::Dynamics`, their
/// names are the frames'): one wrapper per frame calling its pose, Jacobian and `J̇ q̇`, each
/// wrapper under its own `#[no_panic]`; `FRAMES` calls each once.
macro_rules! frames {
    ($($name:ident: $m:ident::{$pose:ident, $jac:ident, $jdot:ident}),* $(,)?) => {
        $(
            #[cfg_attr(feature = "prove", no_panic::no_panic)]
            #[inline(never)]
            #[allow(clippy::type_complexity)]
            pub fn $name(
                q: &[F; root::$m::DOF],
                qd: &[F; root::$m::DOF],
            ) -> (([[F; 3]; 3], [F; 3]), [[F; root::$m::DOF]; 6], [F; 6]) {
                (root::$m::$pose(q), root::$m::$jac(q), root::$m::$jdot(q, qd))
            }
        )*
        /// Every frame wrapper, with its name.
        pub const FRAMES: &[(&str, fn(&mut u64) -> F)] = &[$((stringify!($name), |seed| {
            let q = inputs(seed, 3.0);
            let qd = inputs(seed, 1.0);
            let ((r, p), j, d) = $name(&q, &qd);
            r[2][1] + p[0] + j[5][0] + d[3]
        })),*];
    };
}

frames!(
    planar_2r_link2: planar_2r::{link2_pose, link2_jacobian, link2_jacobian_dot_qd},
    puma560_link6: puma560::{link6_pose, link6_jacobian, link6_jacobian_dot_qd},
    puma560_urdf_link6: puma560_urdf::{link6_pose, link6_jacobian, link6_jacobian_dot_qd},
    stanford_arm_link6: stanford_arm::{link6_pose, link6_jacobian, link6_jacobian_dot_qd},
    gripper_tree_fa_distal: gripper_tree::{fa_distal_pose, fa_distal_jacobian, fa_distal_jacobian_dot_qd},
    gripper_tree_fb_distal: gripper_tree::{fb_distal_pose, fb_distal_jacobian, fb_distal_jacobian_dot_qd},
    chain7_iiwa_link_7: chain7::{iiwa_link_7_pose, iiwa_link_7_jacobian, iiwa_link_7_jacobian_dot_qd},
    iiwa14_iiwa_link_ee: iiwa14::{iiwa_link_ee_pose, iiwa_link_ee_jacobian, iiwa_link_ee_jacobian_dot_qd},
    iiwa14_tool: iiwa14::{tool_pose, tool_jacobian, tool_jacobian_dot_qd},
);

/// The PUMA 560 generated with `fma`, `batch_sin_cos` and the `Dynamics` impl (`build.rs`):
/// every function through the generic wrappers above, as a mechanism of its own (`MECHANISMS`).
#[allow(dead_code)]
mod puma560_fma {
    include!(concat!(env!("OUT_DIR"), "/fma/puma560.rs"));
}

// Without the target's FMA, the runtime's `mul_add` on x86 is the `libm` crate's, whose call
// through a pointer the proof cannot see through.
#[cfg(all(
    feature = "prove",
    any(target_arch = "x86", target_arch = "x86_64"),
    not(target_feature = "fma")
))]
compile_error!(
    "on x86 the proof needs the target's FMA for its `fma` module: build it as .ci/run does, with `-C target-feature=+fma` for the target (`--target <host>` and `CARGO_TARGET_<HOST>_RUSTFLAGS`)"
);

/// The PUMA 560 generated with `lanes = 4` and `vector_sin_cos` (`build.rs`).
#[allow(dead_code)]
mod puma560_lanes {
    include!(concat!(env!("OUT_DIR"), "/puma560.rs"));
}

/// Its `_lanes` functions, each under its own `#[no_panic]`; `LANES` calls each once.
macro_rules! lanes {
    ($($name:ident($($arg:ident),*) -> $out:ty;)*) => {
        $(
            #[cfg_attr(feature = "prove", no_panic::no_panic)]
            #[inline(never)]
            pub fn $name($($arg: &[[F; puma560_lanes::LANES]; puma560_lanes::DOF]),*) -> $out {
                puma560_lanes::$name($($arg),*)
            }
        )*
    };
}

type Lanes6 = [[F; puma560_lanes::LANES]; puma560_lanes::DOF];
lanes! {
    inverse_dynamics_lanes(q, qd, qdd) -> Lanes6;
    mass_matrix_lanes(q) -> [Lanes6; puma560_lanes::DOF];
    coriolis_lanes(q, qd) -> Lanes6;
    gravity_lanes(q) -> Lanes6;
    forward_dynamics_lanes(q, qd, tau)
        -> (Lanes6, [Result<(), puma560_lanes::Singular>; puma560_lanes::LANES]);
}

/// Every `_lanes` wrapper, called once on opaque inputs (angles up to ±4 rad; a seed-dependent
/// state may also put a lane beyond the vector `sin_cos`'s range: scale 1e6).
pub const LANES: &[(&str, fn(&mut u64) -> F)] = &[("puma560_lanes", |seed| {
    let mut state = |scale: F| -> Lanes6 {
        core::array::from_fn(|_| inputs::<{ puma560_lanes::LANES }>(seed, scale))
    };
    let (q, far, qd, qdd) = (state(4.0), state(1e6), state(1.0), state(1.0));
    let tau = inverse_dynamics_lanes(&q, &qd, &qdd);
    let (a, status) = forward_dynamics_lanes(&q, &qd, &tau);
    tau[0][0]
        + mass_matrix_lanes(&far)[0][0][0]
        + coriolis_lanes(&q, &qd)[1][0]
        + gravity_lanes(&q)[2][0]
        + if status[0].is_ok() { a[0][0] } else { 0.0 }
})];

/// The planar 3-RRR and the four-bar generated with `lanes = 4` (`build.rs`).
#[allow(dead_code)]
mod planar_3rrr_lanes {
    include!(concat!(env!("OUT_DIR"), "/planar_3rrr.rs"));
}
#[allow(dead_code)]
mod four_bar_lanes {
    include!(concat!(env!("OUT_DIR"), "/four_bar.rs"));
}

/// A platform's or closed loop's `_lanes` functions (the six every such module has with
/// lanes), each under its own `#[no_panic]`, in a module named after it (`x` has `NX` rows,
/// the rest `DOF`).
macro_rules! site_lanes {
    ($proof:ident, $m:ident) => {
        site_lanes! {
            $proof, $m,
            inverse_dynamics_lanes(x: NX, u: DOF, ud: DOF) -> Vector;
            gravity_lanes(x: NX) -> Vector;
            coriolis_lanes(x: NX, u: DOF) -> Vector;
            mass_matrix_lanes(x: NX) -> Matrix;
            actuator_mass_matrix_lanes(x: NX) -> Matrix;
            forward_dynamics_lanes(x: NX, u: DOF, tau: DOF) -> Vector;
        }
    };
    ($proof:ident, $m:ident, $($name:ident($($arg:ident: $len:ident),*) -> $out:ident;)*) => {
        mod $proof {
            use super::$m as m;
            use super::F;
            pub type Status = [Result<(), m::Singular>; m::LANES];
            pub type Vector = ([[F; m::LANES]; m::DOF], Status);
            pub type Matrix = ([[[F; m::LANES]; m::DOF]; m::DOF], Status);
            $(
                #[cfg_attr(feature = "prove", no_panic::no_panic)]
                #[inline(never)]
                pub fn $name($($arg: &[[F; m::LANES]; m::$len]),*) -> $out {
                    m::$name($($arg),*)
                }
            )*
        }
    };
}

site_lanes!(planar_3rrr_proof, planar_3rrr_lanes);
site_lanes!(four_bar_proof, four_bar_lanes);

/// The `_lanes` wrappers of a platform's or closed loop's proof module, called once on opaque
/// inputs (coordinates in ±1: regular and singular lanes alike).
macro_rules! site_lanes_run {
    ($proof:ident, $m:ident) => {
        (stringify!($m), |seed: &mut u64| -> F {
            use $m as m;
            use $proof as p;
            let mut rows = |scale: F| -> [[F; m::LANES]; m::NX] {
                core::array::from_fn(|_| inputs::<{ m::LANES }>(seed, scale))
            };
            let x = rows(1.0);
            let mut rows = |scale: F| -> [[F; m::LANES]; m::DOF] {
                core::array::from_fn(|_| inputs::<{ m::LANES }>(seed, scale))
            };
            let (u, ud) = (rows(1.0), rows(1.0));
            // The checksum adds lane 0 of each result where its status is `Ok`.
            let ok = |v: F, s: &p::Status| if s[0].is_ok() { v } else { 0.0 };
            let (tau, ts) = p::inverse_dynamics_lanes(&x, &u, &ud);
            let (a, fs) = p::forward_dynamics_lanes(&x, &u, &tau);
            let (g, gs) = p::gravity_lanes(&x);
            let (c, cs) = p::coriolis_lanes(&x, &u);
            let (m, ms) = p::mass_matrix_lanes(&x);
            let (am, ams) = p::actuator_mass_matrix_lanes(&x);
            ok(tau[0][0], &ts)
                + ok(g[0][0], &gs)
                + ok(c[0][0], &cs)
                + ok(m[0][0][0], &ms)
                + ok(am[0][0][0], &ams)
                + ok(a[0][0], &fs)
        })
    };
}

/// Every platform and closed-loop `_lanes` wrapper, called once.
pub const SITE_LANES: &[(&str, fn(&mut u64) -> F)] = &[
    site_lanes_run!(planar_3rrr_proof, planar_3rrr_lanes),
    site_lanes_run!(four_bar_proof, four_bar_lanes),
];

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
    for (name, run) in MECHANISMS
        .iter()
        .chain(FRAMES)
        .chain(LANES)
        .chain(SITE_LANES)
    {
        let s = run(&mut seed);
        println!("{name}: checksum {s:e}");
    }
}
