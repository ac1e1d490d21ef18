//! `inverse_dynamics_derivatives` and `forward_dynamics_derivatives` of every bundled module,
//! platforms and closed loops above all (the trees' have their own checks in
//! `derivatives.rs`), against two routes that share nothing with the generator's symbolic
//! differentiation:
//! - **differences of the generated functions themselves.** Column `j` of `∂/∂x` is the rate
//!   along the speed `u_j`: the module's own `forward_kinematics` from the actuated
//!   coordinates moved by `±h · actuator_rates(x, e_j)` gives the two points (on the
//!   quaternion's sphere, on the loops' constraint manifold), central differences of
//!   `inverse_dynamics` and `forward_dynamics` between them; `∂/∂u`, `∂/∂τ` likewise in `u`
//!   and `τ`. ≤ 1e-6 relative on 200 states per module, the step chosen per state;
//! - **dual numbers through the runtime's evaluators**, which are written over `Real`
//!   ([`tests::dual`]): `x + ε E e_j` with `E` the tangent of the platform's `retract`
//!   (the closed loops: `S e_j`, the runtime's joint rates), `A⁻ᵀ f` and `I⁻¹ (Aᵀ τ − h)` by
//!   the runtime's own generic LU and `LDLᵀ`. The trees go through the closed-loop evaluator
//!   as a mechanism without loops (`Plan::tree`; the runtime's RNEA is `f64` only), which
//!   shares nothing with the generator's tree recursions. ≤ 1e-11 relative on 100 states per
//!   module.
//!
//! Errors are relative in the ∞-norm over the whole matrix.

use mechanisms::Dynamics;
use rand::Rng;
use rand::rngs::StdRng;
use tests::dual::{Dual, seeded, split};

include!("../no-panic/src/list.rs");

/// States per module for the differences.
const STATES: usize = 200;

/// `‖a − b‖∞ / ‖b‖∞` over all entries (the denominator at least `floor`).
fn rel(a: &[f64], b: &[f64], floor: f64) -> f64 {
    let num = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let den = b.iter().map(|y| y.abs()).fold(floor, f64::max);
    if num.is_nan() {
        f64::INFINITY
    } else {
        num / den
    }
}

fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

fn unit<const N: usize>(j: usize) -> [f64; N] {
    core::array::from_fn(|i| f64::from(u8::from(i == j)))
}

/// The worst errors of one module: ID and FD derivatives against differences.
#[derive(Default, Debug)]
struct Worst {
    id: f64,
    fd: f64,
}

/// A regular assembled state near home (the actuated coordinates moved by up to `reach`),
/// speeds and rates in ±1.
#[allow(clippy::type_complexity)]
fn state<M: Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
    rng: &mut StdRng,
    reach: f64,
) -> ([f64; N], [f64; NX], [f64; N], [f64; N]) {
    let q0 = m.inverse_kinematics(&M::HOME).expect("home is regular");
    loop {
        let q: [f64; N] = core::array::from_fn(|i| q0[i] + reach * rng.random_range(-1.0..1.0));
        let Ok(x) = m.forward_kinematics(&q, &M::HOME) else {
            continue;
        };
        let u = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let ud = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
        if m.inverse_dynamics_derivatives(&x, &u, &ud)
            .is_none_or(|r| r.is_err())
            || m.forward_dynamics(&x, &u, &ud).is_err()
        {
            continue;
        }
        return (q, x, u, ud);
    }
}

/// Central differences of one module's functions against its derivative functions.
fn by_differences<M: Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
    reach: f64,
) -> Worst {
    let mut rng = tests::rng(0xd1ff ^ N as u64);
    let mut worst = Worst::default();
    // A module whose scene leaves the derivatives out (the 6-RUS and 6-PUS hexapods).
    let q0 = m.inverse_kinematics(&M::HOME).unwrap();
    let x0 = m.forward_kinematics(&q0, &M::HOME).unwrap();
    let zero = [0.0; N];
    if m.inverse_dynamics_derivatives(&x0, &zero, &zero).is_none() {
        assert!(m.forward_dynamics_derivatives(&x0, &zero, &zero).is_none());
        eprintln!(
            "{}: no derivative functions (its [scene] leaves them out)",
            M::NAME
        );
        return worst;
    }
    for _ in 0..STATES {
        let (q, x, u, ud) = state(m, &mut rng, reach);
        let tau = m.inverse_dynamics(&x, &u, &ud).unwrap();
        let (dx, du) = m
            .inverse_dynamics_derivatives(&x, &u, &ud)
            .unwrap()
            .unwrap();
        let (fx, fu, ft) = m
            .forward_dynamics_derivatives(&x, &u, &tau)
            .unwrap()
            .unwrap();
        // The step: 1e-4 of the coordinates' scale, so that the truncation (h⁴, extrapolated
        // below) and the rounding (ε/h) errors meet near 1e-11 of the derivatives.
        let scale = q.iter().fold(0.1f64, |s, v| s.max(v.abs()));
        let h = 1e-4 * scale;
        let (mut ndx, mut ndu, mut nfx, mut nfu, mut nft) = (
            [[0.0; N]; N],
            [[0.0; N]; N],
            [[0.0; N]; N],
            [[0.0; N]; N],
            [[0.0; N]; N],
        );
        for j in 0..N {
            let rate = m.actuator_rates(&x, &unit(j)).unwrap();
            let at = |s: f64| {
                let qs: [f64; N] = core::array::from_fn(|i| q[i] + s * rate[i]);
                m.forward_kinematics(&qs, &x).expect("assembles near x")
            };
            let (xp, xm, xp2, xm2) = (at(h), at(-h), at(0.5 * h), at(-0.5 * h));
            let shift = |v: &[f64; N], s: f64| -> [f64; N] {
                core::array::from_fn(|i| v[i] + if i == j { s } else { 0.0 })
            };
            let id = |x: &[f64; NX], u: &[f64; N]| m.inverse_dynamics(x, u, &ud).unwrap();
            let fd =
                |x: &[f64; NX], u: &[f64; N], t: &[f64; N]| m.forward_dynamics(x, u, t).unwrap();
            // Along x with h; u and τ enter at most quadratically (u) or linearly (τ): unit
            // steps leave only rounding.
            // Richardson's extrapolation of the central differences with steps h and h/2
            // along x (fourth order); u enters quadratically and τ linearly, so one central
            // difference with a unit step leaves only rounding.
            let richardson = |p: [f64; N], m: [f64; N], p2: [f64; N], m2: [f64; N]| -> [f64; N] {
                core::array::from_fn(|i| {
                    (4.0 * (p2[i] - m2[i]) / h - (p[i] - m[i]) / (2.0 * h)) / 3.0
                })
            };
            let central = |p: [f64; N], m: [f64; N], s: f64| -> [f64; N] {
                core::array::from_fn(|i| (p[i] - m[i]) / (2.0 * s))
            };
            let cols = [
                richardson(id(&xp, &u), id(&xm, &u), id(&xp2, &u), id(&xm2, &u)),
                central(id(&x, &shift(&u, 0.5)), id(&x, &shift(&u, -0.5)), 0.5),
                richardson(
                    fd(&xp, &u, &tau),
                    fd(&xm, &u, &tau),
                    fd(&xp2, &u, &tau),
                    fd(&xm2, &u, &tau),
                ),
                central(
                    fd(&x, &shift(&u, 0.5), &tau),
                    fd(&x, &shift(&u, -0.5), &tau),
                    0.5,
                ),
                central(
                    fd(&x, &u, &shift(&tau, 1.0)),
                    fd(&x, &u, &shift(&tau, -1.0)),
                    1.0,
                ),
            ];
            for (k, c) in cols.iter().enumerate() {
                let target = [&mut ndx, &mut ndu, &mut nfx, &mut nfu, &mut nft][k].as_mut_slice();
                for i in 0..N {
                    target[i][j] = c[i];
                }
            }
        }
        // The floor: a derivative's natural size, the efforts (or rates) over the step's scale.
        let tau_floor = tau.iter().fold(1e-9, |s: f64, v| s.max(v.abs()));
        let ud_floor = ud.iter().fold(1e-9, |s: f64, v| s.max(v.abs()));
        worst.id = worst
            .id
            .max(rel(&flat(&dx), &flat(&ndx), tau_floor * 1e-3))
            .max(rel(&flat(&du), &flat(&ndu), tau_floor * 1e-3));
        worst.fd = worst
            .fd
            .max(rel(&flat(&fx), &flat(&nfx), ud_floor * 1e-3))
            .max(rel(&flat(&fu), &flat(&nfu), ud_floor * 1e-3))
            .max(rel(&flat(&ft), &flat(&nft), 1e-300));
    }
    worst
}

/// How far the random states move the actuated coordinates (rad or m).
fn reach(name: &str) -> f64 {
    match name {
        "planar_five_bar" | "delta_rl5" | "delta4_rl5" | "planar_3rrr" => 0.1,
        "gough_stewart" | "sliding_hexapod" | "rus_hexapod" | "tsai_3upu" | "prs_head" => 0.02,
        "tripod_3prs" => 0.02,
        n if tests::closed::CLOSED.contains(&n) => tests::closed::reach(n).min(0.5),
        _ => 0.5,
    }
}

macro_rules! differences {
    ($($name:ident),* $(,)?) => {
        #[test]
        fn derivatives_match_differences_of_the_generated_functions() {
            let mut failed = Vec::new();
            $(
                let w = by_differences(&mechanisms::$name::Module, reach(stringify!($name)));
                eprintln!(
                    "{}: worst relative errors (∞-norm) against central differences over {STATES} states: ∂ID {:.1e}, ∂FD {:.1e}",
                    stringify!($name), w.id, w.fd
                );
                if !(w.id <= 1e-6 && w.fd <= 1e-6) {
                    failed.push((stringify!($name), w));
                }
            )*
            assert!(failed.is_empty(), "{failed:?}");
        }
    };
}

for_each_mechanism!(differences);

/// `A⁻ᵀ f` and the forward dynamics of a platform over any `Real`, from the runtime's generic
/// pieces: the leg kinematics, `A`, the generalized force and inertia, the closed loops' LU
/// (for `Aᵀ τ = f`) and the `LDLᵀ` of `solve_spd`.
mod platform {
    use runtime::parallel::noc::{self, Plan};
    use runtime::scalar::Real;

    pub fn inverse_dynamics<R: Real>(plan: &Plan, x: &[R], u: &[R], ud: &[R]) -> Vec<R> {
        let (pl, legs) = noc::kinematics(plan, x).unwrap();
        let f = noc::generalized_force(plan, &pl, &legs, u, ud, true);
        let a = noc::actuation_matrix(plan, &pl, &legs);
        runtime::closed::noc::lu_factor(&a).unwrap().solve_t(&f)
    }

    pub fn forward_dynamics<R: Real>(plan: &Plan, x: &[R], u: &[R], tau: &[R]) -> Vec<R> {
        noc::forward_dynamics_generic(plan, x, u, tau).unwrap()
    }
}

/// A function of `(x, u, w)` over dual numbers.
type DualFn<'a> = dyn Fn(&[Dual], &[Dual], &[Dual]) -> Vec<Dual> + 'a;

/// Column `j` of `∂y/∂(x, u, ·)` by one dual evaluation: `x + ε dx`, `u + ε du`, `w + ε dw`.
fn dual_column(
    f: &DualFn<'_>,
    (x, dx): (&[f64], &[f64]),
    (u, du): (&[f64], &[f64]),
    (w, dw): (&[f64], &[f64]),
) -> Vec<f64> {
    split(&f(&seeded(x, dx), &seeded(u, du), &seeded(w, dw))).1
}

/// The three derivative matrices of `f(x, u, w)` by dual numbers, `[i][j]`, with the
/// directions of `x` the columns of `e` (`nx × n`).
fn dual_jacobians(
    f: &DualFn<'_>,
    x: &[f64],
    u: &[f64],
    w: &[f64],
    e: &[Vec<f64>],
) -> [Vec<f64>; 3] {
    let n = u.len();
    let zx = vec![0.0; x.len()];
    let zn = vec![0.0; n];
    let mut out = [vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]];
    for j in 0..n {
        let ej: Vec<f64> = (0..n).map(|i| f64::from(u8::from(i == j))).collect();
        let ex: Vec<f64> = e.iter().map(|row| row[j]).collect();
        let cols = [
            dual_column(f, (x, &ex), (u, &zn), (w, &zn)),
            dual_column(f, (x, &zx), (u, &ej), (w, &zn)),
            dual_column(f, (x, &zx), (u, &zn), (w, &ej)),
        ];
        for (k, c) in cols.iter().enumerate() {
            for i in 0..n {
                out[k][i * n + j] = c[i];
            }
        }
    }
    out
}

/// One state's worst relative errors `(∂ID, ∂FD)` of module `m` against dual numbers through
/// `id` and `fd` (the runtime's routes over `Real`), `x` moved along the columns of `e`.
#[allow(clippy::too_many_arguments)]
fn against_duals<M: Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
    id: &DualFn<'_>,
    fd: &DualFn<'_>,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
    tau: &[f64],
    e: &[Vec<f64>],
) -> (f64, f64) {
    let [ix, iu, _] = dual_jacobians(id, x, u, ud, e);
    let [fx, fu, ft] = dual_jacobians(fd, x, u, tau, e);
    let arr = |v: &[f64]| -> [f64; NX] { core::array::from_fn(|i| v[i]) };
    let vec = |v: &[f64]| -> [f64; N] { core::array::from_fn(|i| v[i]) };
    let (gx, gu) = m
        .inverse_dynamics_derivatives(&arr(x), &vec(u), &vec(ud))
        .unwrap()
        .unwrap();
    let (hx, hu, ht) = m
        .forward_dynamics_derivatives(&arr(x), &vec(u), &vec(tau))
        .unwrap()
        .unwrap();
    let id_err = rel(&flat(&gx), &ix, 1e-300).max(rel(&flat(&gu), &iu, 1e-300));
    let fd_err = rel(&flat(&hx), &fx, 1e-300)
        .max(rel(&flat(&hu), &fu, 1e-300))
        .max(rel(&flat(&ht), &ft, 1e-300));
    (id_err, fd_err)
}

/// [`against_duals`] through the closed-loop evaluator of `plan` (a closed loop's, or a tree's
/// as a mechanism without loops).
#[allow(clippy::too_many_arguments)]
fn through_closed_route<M: Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
    plan: &runtime::closed::noc::Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
    tau: &[f64],
    e: &[Vec<f64>],
) -> (f64, f64) {
    use runtime::closed::noc::{self, Extras};
    let id = |x: &[Dual], u: &[Dual], w: &[Dual]| {
        let c = noc::configuration(plan, x, true).unwrap();
        noc::generalized_force_with(plan, &c, u, w, true, &Extras::none())
    };
    let fd =
        |x: &[Dual], u: &[Dual], w: &[Dual]| noc::forward_dynamics_generic(plan, x, u, w).unwrap();
    against_duals(m, &id, &fd, x, u, ud, tau, e)
}

/// Report one module's worst errors against dual numbers; `false` above 1e-11.
fn duals_within(name: &str, (id, fd): (f64, f64)) -> bool {
    eprintln!(
        "{name}: generated against dual numbers through the runtime, worst relative errors (∞-norm) over 100 states: ∂ID {id:.1e}, ∂FD {fd:.1e}"
    );
    id <= 1e-11 && fd <= 1e-11
}

macro_rules! platform_duals {
    ($($name:ident),* $(,)?) => {
        #[test]
        fn platform_derivatives_match_dual_numbers_through_the_runtime() {
            use runtime::parallel::noc::{self, Plan};
            let mut failed = Vec::new();
            $({
                use mechanisms::$name as g;
                let m = tests::pkm::model(stringify!($name));
                let plan = Plan::new(&m).unwrap();
                let home = tests::pkm::home_x(&m);
                let mut rng = tests::rng(0xd0a1 ^ g::DOF as u64);
                let (mut id, mut fd) = (0.0f64, 0.0f64);
                for _ in 0..100 {
                    let r = reach(stringify!($name));
                    let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, 4.0 * r, r);
                    let e = noc::tangent::<f64>(plan.motion, &x);
                    let tau = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
                    let fid = |x: &[Dual], u: &[Dual], w: &[Dual]| platform::inverse_dynamics(&plan, x, u, w);
                    let ffd = |x: &[Dual], u: &[Dual], w: &[Dual]| platform::forward_dynamics(&plan, x, u, w);
                    let (i, f) = against_duals(&g::Module, &fid, &ffd, &x, &u, &ud, &tau, &e);
                    (id, fd) = (id.max(i), fd.max(f));
                }
                if !duals_within(stringify!($name), (id, fd)) {
                    failed.push((stringify!($name), id, fd));
                }
            })*
            assert!(failed.is_empty(), "{failed:?}");
        }
    };
}

// (The 6-PUS and 6-RUS hexapods' scenes leave the derivatives out.)
platform_duals!(
    gough_stewart,
    agile_eye,
    planar_five_bar,
    delta_rl5,
    planar_3rrr,
    tsai_3upu,
    prs_head,
    delta4_rl5,
);

macro_rules! closed_duals {
    ($($name:ident),* $(,)?) => {
        #[test]
        fn closed_loop_derivatives_match_dual_numbers_through_the_runtime() {
            use runtime::closed::noc::{self, Plan};
            let mut failed = Vec::new();
            $({
                use mechanisms::$name as g;
                let m = tests::closed::model(stringify!($name));
                let plan = Plan::new(&m).unwrap();
                let mut rng = tests::rng(0xc105 ^ g::DOF as u64);
                let (mut id, mut fd) = (0.0f64, 0.0f64);
                let n = plan.dof();
                for _ in 0..100 {
                    let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, tests::closed::reach(stringify!($name)));
                    // The manifold's tangent: S e_j, the runtime's joint rates.
                    let cols: Vec<Vec<f64>> = (0..n)
                        .map(|j| {
                            let ej: Vec<f64> = (0..n).map(|i| f64::from(u8::from(i == j))).collect();
                            noc::joint_rates(&plan, &x, &ej).unwrap()
                        })
                        .collect();
                    let e: Vec<Vec<f64>> = (0..plan.nx()).map(|k| cols.iter().map(|c| c[k]).collect()).collect();
                    let tau = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
                    let (i, f) = through_closed_route(&g::Module, &plan, &x, &u, &ud, &tau, &e);
                    (id, fd) = (id.max(i), fd.max(f));
                }
                if !duals_within(stringify!($name), (id, fd)) {
                    failed.push((stringify!($name), id, fd));
                }
            })*
            assert!(failed.is_empty(), "{failed:?}");
        }
    };
}

closed_duals!(
    four_bar,
    five_bar_joints,
    spherical_five_bar,
    bricard,
    n_four_bar,
    tripod_3prs,
    andrews_squeezer,
);

macro_rules! tree_duals {
    ($(($name:ident, $file:literal)),* $(,)?) => {
        #[test]
        fn tree_derivatives_match_dual_numbers_through_the_runtime() {
            use runtime::closed::noc::Plan;
            let mut failed = Vec::new();
            $({
                use mechanisms::$name as g;
                let path = tests::pkm::spec_path("x").with_file_name($file);
                let src = std::fs::read_to_string(&path).unwrap();
                let (model, _) = codegen::spec::load_tree($file, &src).unwrap_or_else(|d| panic!("{d}"));
                let plan = Plan::tree(&model);
                let n = g::DOF;
                let e: Vec<Vec<f64>> = (0..n)
                    .map(|k| (0..n).map(|j| f64::from(u8::from(k == j))).collect())
                    .collect();
                let mut rng = tests::rng(0x7ee ^ n as u64);
                let (mut id, mut fd) = (0.0f64, 0.0f64);
                for _ in 0..100 {
                    let (q, qd, qdd) = tests::random_state(&mut rng, n);
                    let qa: [f64; g::DOF] = core::array::from_fn(|i| q[i]);
                    let (qda, qdda) = (
                        core::array::from_fn(|i| qd[i]),
                        core::array::from_fn(|i| qdd[i]),
                    );
                    let tau = g::inverse_dynamics(&qa, &qda, &qdda);
                    let (i, f) = through_closed_route(&g::Module, &plan, &q, &qd, &qdd, &tau, &e);
                    (id, fd) = (id.max(i), fd.max(f));
                }
                if !duals_within(stringify!($name), (id, fd)) {
                    failed.push((stringify!($name), id, fd));
                }
            })*
            assert!(failed.is_empty(), "{failed:?}");
        }
    };
}

tree_duals!(
    (planar_2r, "planar_2r.toml"),
    (puma560, "puma560.toml"),
    (puma560_urdf, "puma560.urdf"),
    (stanford_arm, "stanford_arm.toml"),
    (gripper_tree, "gripper_tree.toml"),
    (chain7, "chain7.toml"),
    (iiwa14, "iiwa14.urdf"),
);
