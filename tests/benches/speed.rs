//! Fused multiply–add and many states per call (issue 24), in one run:
//!
//! - `fma/{mechanism}/{function}/{plain,fused}`: the bundled module (the `libm` backend)
//!   against the same spec generated with `Config::fma` (`tests::variants::fma`, the `runtime`
//!   backend with std: `f64::mul_add`, std's `sin_cos`), PUMA 560 and the 7-joint chain
//!   (inverse dynamics, mass matrix), Gough–Stewart (inverse dynamics); for the PUMA 560 also
//!   `fused_libm`, fused with the `libm` backend (`libm::fma`: `tests::variants::fma_libm_puma560`);
//! - `lanes/{mechanism}/{function}/{scalar,lanes}`: `LANES` (4) states through the scalar
//!   function one after the other against one call of its `_lanes` version (the same states,
//!   lane last), in the same module (`tests::variants::lanes`); criterion's throughput is per
//!   state; `lanes_libm/…` the same with the `libm` crate's trigonometry
//!   (`tests::variants::lanes_libm`); `lanes_vector/…` with `sin` and `cos` of all lanes at
//!   once (`Config::vector_sin_cos`, `tests::variants::lanes_vector`; its `scalar` is the
//!   same module's scalar function, std's `sin_cos`); `lanes_vector8/…` the same with 8 lanes
//!   (`tests::variants::lanes_vector8`); `lanes/{platform or closed loop}/…` the same for
//!   three platforms and two closed loops (`tests::variants::lanes_parallel`, `lanes_closed`);
//!   `lanes8/{platform}/…` three of them with 8 lanes (`tests::variants::lanes8_parallel`);
//!   `lanes_wide/…` and `lanes8_wide/…` the same three and the four-bar with the lanes'
//!   arithmetic through the `wide` crate (`Config::wide`, `tests::variants::lanes_wide`,
//!   `lanes8_wide`); `lanes_vector_wide/…` the three arms of `lanes_vector` through `wide`
//!   (`tests::variants::lanes_vector_wide`).
//!
//! `mul_add` is one instruction only with FMA enabled, and the lanes vectorize to 256-bit
//! registers only with AVX, so run it for the host CPU (a target directory of its own keeps
//! the other builds' flags apart):
//!
//! ```text
//! RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR=$PWD/target/native \
//!     cargo bench -p tests --features figures --bench speed
//! ```
//!
//! `batch_sin_cos/{mechanism}/{function}/{plain,batched}`: the 7-joint chain and the iiwa 14
//! with every function's joint angles in one call (`Config::batch_sin_cos`,
//! `tests::variants::batch_sin_cos`) against the bundled modules.
//!
//! `sin_cos/four_angles` times what one angle costs a `_lanes` function (a call per lane).
//!
//! The `#[inline(never)]` wrappers below are the functions whose instructions
//! docs/performance.md counts (`objdump -d --no-show-raw-insn -C` on the bench binary).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::Rng;

/// PUMA 560 inverse dynamics, unfused (the instruction count's "before").
#[inline(never)]
pub fn puma_id_plain(q: &[f64; 6], qd: &[f64; 6], qdd: &[f64; 6]) -> [f64; 6] {
    mechanisms::puma560::inverse_dynamics(q, qd, qdd)
}

/// PUMA 560 inverse dynamics, fused (the instruction count's "after").
#[inline(never)]
pub fn puma_id_fused(q: &[f64; 6], qd: &[f64; 6], qdd: &[f64; 6]) -> [f64; 6] {
    tests::variants::fma::puma560::inverse_dynamics(q, qd, qdd)
}

/// PUMA 560 inverse dynamics of four states in one call.
#[inline(never)]
pub fn puma_id_lanes(q: &[[f64; 4]; 6], qd: &[[f64; 4]; 6], qdd: &[[f64; 4]; 6]) -> [[f64; 4]; 6] {
    tests::variants::lanes::puma560::inverse_dynamics_lanes(q, qd, qdd)
}

/// Three arrays (angles, rates, accelerations) of `L` random states, state-major.
fn states<const N: usize, const L: usize>(seed: u64) -> [[[f64; N]; L]; 3] {
    let mut r = tests::rng(seed);
    let pi = std::f64::consts::PI;
    [pi, 2.0, 5.0]
        .map(|a| core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-a..a))))
}

macro_rules! fma_tree {
    ($fn_name:ident, $m:ident) => {
        fn $fn_name(c: &mut Criterion) {
            use mechanisms::$m as plain;
            use tests::variants::fma::$m as fused;
            const N: usize = plain::DOF;
            let [q, qd, qdd] = states::<N, 1>(11).map(|s| s[0]);
            let mut g = c.benchmark_group(concat!("fma/", stringify!($m), "/inverse_dynamics"));
            g.bench_function("plain", |b| {
                b.iter(|| plain::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qdd)))
            });
            g.bench_function("fused", |b| {
                b.iter(|| fused::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qdd)))
            });
            g.finish();
            let mut g = c.benchmark_group(concat!("fma/", stringify!($m), "/mass_matrix"));
            g.bench_function("plain", |b| b.iter(|| plain::mass_matrix(black_box(&q))));
            g.bench_function("fused", |b| b.iter(|| fused::mass_matrix(black_box(&q))));
            g.finish();
        }
    };
}
fma_tree!(fma_puma560_runtime, puma560);
fma_tree!(fma_chain7, chain7);

/// The PUMA 560's `fma` groups with `fused_libm` beside `plain` and `fused`.
fn fma_puma560(c: &mut Criterion) {
    fma_puma560_runtime(c);
    use tests::variants::fma_libm_puma560 as fused_libm;
    let [q, qd, qdd] = states::<6, 1>(11).map(|s| s[0]);
    let mut g = c.benchmark_group("fma/puma560/inverse_dynamics");
    g.bench_function("fused_libm", |b| {
        b.iter(|| fused_libm::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qdd)))
    });
    g.finish();
    let mut g = c.benchmark_group("fma/puma560/mass_matrix");
    g.bench_function("fused_libm", |b| {
        b.iter(|| fused_libm::mass_matrix(black_box(&q)))
    });
    g.finish();
}

fn fma_gough_stewart(c: &mut Criterion) {
    use mechanisms::gough_stewart as plain;
    use tests::variants::fma::gough_stewart as fused;
    let x = plain::HOME;
    let u: [f64; 6] = core::array::from_fn(|i| 0.1 - 0.03 * i as f64);
    let ud: [f64; 6] = core::array::from_fn(|i| 0.5 - 0.2 * i as f64);
    assert!(plain::inverse_dynamics(&x, &u, &ud).is_ok());
    let mut g = c.benchmark_group("fma/gough_stewart/inverse_dynamics");
    g.bench_function("plain", |b| {
        b.iter(|| plain::inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
    });
    g.bench_function("fused", |b| {
        b.iter(|| fused::inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
    });
    g.finish();
}

/// `batch_sin_cos/{mechanism}/{function}/{plain,batched}`: the bundled module against the same
/// spec with every function's joint angles in one `sin_cos_batch` call (`Config::batch_sin_cos`,
/// `tests::variants::batch_sin_cos`), both through `runtime::math` with std (std's `sin_cos`:
/// two libm calls per angle), inverse dynamics and mass matrix.
macro_rules! batch_tree {
    ($fn_name:ident, $m:ident) => {
        fn $fn_name(c: &mut Criterion) {
            use mechanisms::$m as plain;
            use tests::variants::batch_sin_cos::$m as batched;
            const N: usize = plain::DOF;
            let [q, qd, qdd] = states::<N, 1>(11).map(|s| s[0]);
            let mut g = c.benchmark_group(concat!(
                "batch_sin_cos/",
                stringify!($m),
                "/inverse_dynamics"
            ));
            g.bench_function("plain", |b| {
                b.iter(|| plain::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qdd)))
            });
            g.bench_function("batched", |b| {
                b.iter(|| batched::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qdd)))
            });
            g.finish();
            let mut g =
                c.benchmark_group(concat!("batch_sin_cos/", stringify!($m), "/mass_matrix"));
            g.bench_function("plain", |b| b.iter(|| plain::mass_matrix(black_box(&q))));
            g.bench_function("batched", |b| {
                b.iter(|| batched::mass_matrix(black_box(&q)))
            });
            g.finish();
        }
    };
}
batch_tree!(batch_chain7, chain7);
batch_tree!(batch_iiwa14, iiwa14);

/// A group `name` of `scalar` (`l` states through the scalar function, one after the other)
/// against `lanes` (one `_lanes` call of the same states); criterion's throughput is per state.
fn scalar_vs_lanes<A, B>(
    c: &mut Criterion,
    name: String,
    l: usize,
    mut scalar: impl FnMut() -> A,
    mut lanes: impl FnMut() -> B,
) {
    let mut grp = c.benchmark_group(name);
    grp.throughput(Throughput::Elements(l as u64));
    grp.bench_function("scalar", |b| b.iter(&mut scalar));
    grp.bench_function("lanes", |b| b.iter(&mut lanes));
    grp.finish();
}

macro_rules! lanes_tree {
    ($fn_name:ident, $m:ident) => {
        lanes_tree!($fn_name, lanes, $m);
    };
    ($fn_name:ident, $variant:ident, $m:ident) => {
        fn $fn_name(c: &mut Criterion) {
            use tests::variants::$variant::$m as g;
            const N: usize = g::DOF;
            const L: usize = g::LANES;
            // One state per row for the scalar calls, lane-last (transposed) for the lanes.
            let [q, qd, qdd] = states::<N, L>(12);
            let [ql, qdl, qddl] = [q, qd, qdd].map(transpose);
            let taul = g::inverse_dynamics_lanes(&ql, &qdl, &qddl);
            let tau: [[f64; N]; L] = transpose(taul);
            let name = concat!(stringify!($variant), "/", stringify!($m));
            scalar_vs_lanes(
                c,
                format!("{name}/inverse_dynamics"),
                L,
                || {
                    let (q, qd, qdd) = (black_box(&q), black_box(&qd), black_box(&qdd));
                    core::array::from_fn::<_, L, _>(|k| g::inverse_dynamics(&q[k], &qd[k], &qdd[k]))
                },
                || g::inverse_dynamics_lanes(black_box(&ql), black_box(&qdl), black_box(&qddl)),
            );
            scalar_vs_lanes(
                c,
                format!("{name}/mass_matrix"),
                L,
                || {
                    let q = black_box(&q);
                    core::array::from_fn::<_, L, _>(|k| g::mass_matrix(&q[k]))
                },
                || g::mass_matrix_lanes(black_box(&ql)),
            );
            scalar_vs_lanes(
                c,
                format!("{name}/forward_dynamics"),
                L,
                || {
                    let (q, qd, tau) = (black_box(&q), black_box(&qd), black_box(&tau));
                    core::array::from_fn::<_, L, _>(|k| g::forward_dynamics(&q[k], &qd[k], &tau[k]))
                },
                || g::forward_dynamics_lanes(black_box(&ql), black_box(&qdl), black_box(&taul)),
            );
        }
    };
}
lanes_tree!(lanes_puma560, puma560);
lanes_tree!(lanes_chain7, chain7);
lanes_tree!(lanes_iiwa14, iiwa14);
lanes_tree!(lanes_libm_puma560, lanes_libm, puma560);
lanes_tree!(lanes_libm_chain7, lanes_libm, chain7);
lanes_tree!(lanes_vector_puma560, lanes_vector, puma560);
lanes_tree!(lanes_vector_chain7, lanes_vector, chain7);
lanes_tree!(lanes_vector_iiwa14, lanes_vector, iiwa14);
lanes_tree!(lanes_vector_wide_puma560, lanes_vector_wide, puma560);
lanes_tree!(lanes_vector_wide_chain7, lanes_vector_wide, chain7);
lanes_tree!(lanes_vector_wide_iiwa14, lanes_vector_wide, iiwa14);
lanes_tree!(lanes_vector8_puma560, lanes_vector8, puma560);
lanes_tree!(lanes_vector8_chain7, lanes_vector8, chain7);
lanes_tree!(lanes_vector8_iiwa14, lanes_vector8, iiwa14);

/// A platform's or closed loop's functions, `LANES` (4, or 8 in the `lanes8/` group) regular states through the scalar
/// function one after the other against one `_lanes` call (`tests::variants::lanes_parallel`,
/// `lanes_closed`): inverse dynamics, the actuator-space mass matrix, forward dynamics.
macro_rules! lanes_sites {
    ($fn_name:ident, $variant:ident, $m:ident, $states:path) => {
        lanes_sites!($fn_name, $variant, $m, $states, "lanes/");
    };
    ($fn_name:ident, $variant:ident, $m:ident, $states:path, $group:literal) => {
        fn $fn_name(c: &mut Criterion) {
            use tests::variants::$variant::$m as g;
            const N: usize = g::DOF;
            const NX: usize = g::NX;
            const L: usize = g::LANES;
            let mut r = tests::rng(14);
            let mut state = $states(stringify!($m));
            let states: Vec<_> = (0..L).map(|_| state(&mut r)).collect();
            let x: [[f64; NX]; L] =
                core::array::from_fn(|k| states[k].0.clone().try_into().expect("NX coordinates"));
            let u: [[f64; N]; L] =
                core::array::from_fn(|k| states[k].1.clone().try_into().expect("DOF speeds"));
            let ud: [[f64; N]; L] =
                core::array::from_fn(|k| states[k].2.clone().try_into().expect("DOF rates"));
            let (xl, ul, udl) = (transpose(x), transpose(u), transpose(ud));
            let (taul, status) = g::inverse_dynamics_lanes(&xl, &ul, &udl);
            assert!(status.iter().all(Result::is_ok));
            let tau: [[f64; N]; L] = transpose(taul);
            let name = concat!($group, stringify!($m));
            scalar_vs_lanes(
                c,
                format!("{name}/inverse_dynamics"),
                L,
                || {
                    let (x, u, ud) = (black_box(&x), black_box(&u), black_box(&ud));
                    core::array::from_fn::<_, L, _>(|k| g::inverse_dynamics(&x[k], &u[k], &ud[k]))
                },
                || g::inverse_dynamics_lanes(black_box(&xl), black_box(&ul), black_box(&udl)),
            );
            scalar_vs_lanes(
                c,
                format!("{name}/actuator_mass_matrix"),
                L,
                || {
                    let x = black_box(&x);
                    core::array::from_fn::<_, L, _>(|k| g::actuator_mass_matrix(&x[k]))
                },
                || g::actuator_mass_matrix_lanes(black_box(&xl)),
            );
            scalar_vs_lanes(
                c,
                format!("{name}/forward_dynamics"),
                L,
                || {
                    let (x, u, tau) = (black_box(&x), black_box(&u), black_box(&tau));
                    core::array::from_fn::<_, L, _>(|k| g::forward_dynamics(&x[k], &u[k], &tau[k]))
                },
                || g::forward_dynamics_lanes(black_box(&xl), black_box(&ul), black_box(&taul)),
            );
        }
    };
}
lanes_sites!(
    lanes_gough_stewart,
    lanes_parallel,
    gough_stewart,
    tests::pkm::near_home
);
lanes_sites!(
    lanes_delta_rl5,
    lanes_parallel,
    delta_rl5,
    tests::pkm::near_home
);
lanes_sites!(
    lanes_agile_eye,
    lanes_parallel,
    agile_eye,
    tests::pkm::near_home
);
lanes_sites!(
    lanes8_gough_stewart,
    lanes8_parallel,
    gough_stewart,
    tests::pkm::near_home,
    "lanes8/"
);
lanes_sites!(
    lanes8_delta_rl5,
    lanes8_parallel,
    delta_rl5,
    tests::pkm::near_home,
    "lanes8/"
);
lanes_sites!(
    lanes8_agile_eye,
    lanes8_parallel,
    agile_eye,
    tests::pkm::near_home,
    "lanes8/"
);
lanes_sites!(
    lanes_four_bar,
    lanes_closed,
    four_bar,
    tests::closed::assembled
);
lanes_sites!(
    lanes_andrews_squeezer,
    lanes_closed,
    andrews_squeezer,
    tests::closed::assembled
);
lanes_sites!(
    lanes_wide_gough_stewart,
    lanes_wide,
    gough_stewart,
    tests::pkm::near_home,
    "lanes_wide/"
);
lanes_sites!(
    lanes8_wide_gough_stewart,
    lanes8_wide,
    gough_stewart,
    tests::pkm::near_home,
    "lanes8_wide/"
);
lanes_sites!(
    lanes_wide_delta_rl5,
    lanes_wide,
    delta_rl5,
    tests::pkm::near_home,
    "lanes_wide/"
);
lanes_sites!(
    lanes8_wide_delta_rl5,
    lanes8_wide,
    delta_rl5,
    tests::pkm::near_home,
    "lanes8_wide/"
);
lanes_sites!(
    lanes_wide_agile_eye,
    lanes_wide,
    agile_eye,
    tests::pkm::near_home,
    "lanes_wide/"
);
lanes_sites!(
    lanes8_wide_agile_eye,
    lanes8_wide,
    agile_eye,
    tests::pkm::near_home,
    "lanes8_wide/"
);
lanes_sites!(
    lanes_wide_four_bar,
    lanes_wide,
    four_bar,
    tests::closed::assembled,
    "lanes_wide/"
);

/// What a `_lanes` function pays per angle: four `sin_cos` calls of the math backend, std
/// (the modules here: `runtime::math`) and the `libm` crate.
fn sin_cos(c: &mut Criterion) {
    let x: [f64; 4] = [0.3, -1.2, 2.5, -2.9];
    let mut g = c.benchmark_group("sin_cos/four_angles");
    g.throughput(Throughput::Elements(4));
    g.bench_function("runtime_math_std", |b| {
        b.iter(|| black_box(&x).map(runtime::math::sin_cos))
    });
    g.bench_function("libm", |b| b.iter(|| black_box(&x).map(libm::sincos)));
    g.finish();
}

/// `a` with rows and columns swapped.
fn transpose<const R: usize, const C: usize>(a: [[f64; C]; R]) -> [[f64; R]; C] {
    core::array::from_fn(|j| core::array::from_fn(|i| a[i][j]))
}

/// The wrappers once, so that they are in the binary for the instruction count.
fn wrappers(c: &mut Criterion) {
    let [q, qd, qdd] = states::<6, 4>(13);
    let [ql, qdl, qddl] = [q, qd, qdd].map(transpose);
    let mut g = c.benchmark_group("wrappers/puma560/inverse_dynamics");
    g.bench_function("plain", |b| {
        b.iter(|| puma_id_plain(black_box(&q[0]), &qd[0], &qdd[0]))
    });
    g.bench_function("fused", |b| {
        b.iter(|| puma_id_fused(black_box(&q[0]), &qd[0], &qdd[0]))
    });
    g.bench_function("lanes", |b| {
        b.iter(|| puma_id_lanes(black_box(&ql), &qdl, &qddl))
    });
    g.finish();
}

fn config() -> Criterion {
    Criterion::default()
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500))
        .sample_size(30)
}

criterion_group! {
    name = benches;
    config = config();
    targets = fma_puma560, fma_chain7, fma_gough_stewart, batch_chain7, batch_iiwa14, lanes_puma560, lanes_chain7, lanes_iiwa14, lanes_libm_puma560, lanes_libm_chain7, lanes_vector_puma560, lanes_vector_chain7, lanes_vector_iiwa14, lanes_vector_wide_puma560, lanes_vector_wide_chain7, lanes_vector_wide_iiwa14, lanes_vector8_puma560, lanes_vector8_chain7, lanes_vector8_iiwa14, lanes_gough_stewart, lanes_delta_rl5, lanes_agile_eye, lanes8_gough_stewart, lanes8_delta_rl5, lanes8_agile_eye, lanes_wide_gough_stewart, lanes8_wide_gough_stewart, lanes_wide_delta_rl5, lanes8_wide_delta_rl5, lanes_wide_agile_eye, lanes8_wide_agile_eye, lanes_wide_four_bar, lanes_four_bar, lanes_andrews_squeezer, sin_cos, wrappers
}
criterion_main!(benches);
