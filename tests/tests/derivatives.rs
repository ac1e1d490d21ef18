//! The generated derivatives of the tree modules (`inverse_dynamics_derivatives`,
//! `forward_dynamics_derivatives`) against
//! * central differences of the same module's `inverse_dynamics` / `forward_dynamics`
//!   (200 random states per mechanism, step `1e-6 · max(1, ‖x‖∞)` per state), ≤ 1e-6;
//! * Richardson-extrapolated central differences (`(4 D(h/2) − D(h))/3`, error `O(h⁴)`) of the
//!   runtime's spatial RNEA (`runtime::rnea`), and forward dynamics' as `−I⁻¹ ∂RNEA/∂x` at the
//!   runtime's `q̈` with the runtime's CRBA `I` inverted by nalgebra, ≤ 1e-8. The RNEA is written in `f64` on nalgebra's `Matrix6<f64>` and the
//!   model helpers (`axis_angle`) are `f64` too, so neither a complex step nor a dual number
//!   reaches it without making the runtime generic: extrapolated differences are the
//!   independent route;
//! * `forward_dynamics_derivatives` fails exactly where `forward_dynamics` does, and its
//!   `I⁻¹` times `mass_matrix` is the identity;
//! * with friction and rotor inertia (`[scene] friction`, `rotor_inertia`), the symbolic
//!   derivatives (the generator's interpreter) against Richardson differences of the runtime
//!   NOC, whose drive law is written apart.
//!
//! Error norm: ‖a − b‖∞ / max(‖b‖∞, 1) over the whole matrix.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use runtime::model::Model;
use tests::{rel_err, rng};

const STATES: usize = 200;

fn model(file: &str, src: &str) -> Model {
    match codegen::spec::load_tree(file, src) {
        Ok((m, _)) => m,
        Err(d) => panic!("{d}"),
    }
}

/// The Jacobian (row-major, `[i][j] = ∂f_i/∂x_j`) of `f` at `x` by central differences of step
/// `h`, or Richardson-extrapolated ones when `richardson`.
fn jacobian(f: &dyn Fn(&[f64]) -> Vec<f64>, x: &[f64], h: f64, richardson: bool) -> Vec<f64> {
    let n = x.len();
    let central = |j: usize, h: f64| -> Vec<f64> {
        let mut a = x.to_vec();
        let mut b = x.to_vec();
        a[j] += h;
        b[j] -= h;
        let (fa, fb) = (f(&a), f(&b));
        fa.iter()
            .zip(&fb)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect()
    };
    let cols: Vec<Vec<f64>> = (0..n)
        .map(|j| {
            if richardson {
                let (d1, d2) = (central(j, h), central(j, h / 2.0));
                d1.iter()
                    .zip(&d2)
                    .map(|(a, b)| (4.0 * b - a) / 3.0)
                    .collect()
            } else {
                central(j, h)
            }
        })
        .collect();
    let m = cols[0].len();
    (0..m * n).map(|k| cols[k % n][k / n]).collect()
}

fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// Forward dynamics from the runtime's RNEA and CRBA, solved by nalgebra's LU.
fn rnea_forward(model: &Model, q: &[f64], qd: &[f64], tau: &[f64]) -> Vec<f64> {
    let n = q.len();
    let bias = runtime::rnea::inverse_dynamics(model, q, qd, &vec![0.0; n]);
    let m: DMatrix<f64> = runtime::rnea::mass_matrix(model, q);
    let rhs = DVector::from_iterator(n, tau.iter().zip(bias.iter()).map(|(t, b)| t - b));
    m.lu()
        .solve(&rhs)
        .expect("a regular mass matrix")
        .as_slice()
        .to_vec()
}

macro_rules! derivative_tests {
    ($($m:ident : $file:literal),* $(,)?) => {$(
        mod $m {
            use super::*;
            use mechanisms::$m as mech;
            const N: usize = mech::DOF;

            fn spec() -> Model {
                model($file, include_str!(concat!("../../mechanisms/specs/", $file)))
            }

            fn state(r: &mut rand::rngs::StdRng) -> ([f64; N], [f64; N], [f64; N], [f64; N]) {
                let mut s = [[0.0; N]; 4];
                for i in 0..N {
                    s[0][i] = r.random_range(-std::f64::consts::PI..std::f64::consts::PI);
                    s[1][i] = r.random_range(-2.0..2.0);
                    s[2][i] = r.random_range(-5.0..5.0);
                    s[3][i] = r.random_range(-20.0..20.0);
                }
                (s[0], s[1], s[2], s[3])
            }

            fn arr(x: &[f64]) -> [f64; N] {
                let mut a = [0.0; N];
                a.copy_from_slice(x);
                a
            }

            /// `(∂τ/∂q, ∂τ/∂q̇, ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ)` of `id` and `fd` by differences, the
            /// steps `step[0] · max(1, ‖q‖∞)` in `q` and `step[1] · max(1, ‖x‖∞)` in `x = q̇, τ`
            /// (without drives the dynamics are quadratic in `q̇` and affine in `τ`: central
            /// differences have no truncation error there, and a long step the least rounding).
            fn differences(
                id: &dyn Fn(&[f64; N], &[f64; N], &[f64; N]) -> Vec<f64>,
                fd: &dyn Fn(&[f64; N], &[f64; N], &[f64; N]) -> Vec<f64>,
                (q, qd, qdd, tau): ([f64; N], [f64; N], [f64; N], [f64; N]),
                step: [f64; 2],
                richardson: bool,
            ) -> [Vec<f64>; 5] {
                let norm = |x: &[f64; N]| x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                let hq = step[0] * norm(&q);
                let hv = step[1] * norm(&qd);
                let ht = step[1] * norm(&tau);
                [
                    jacobian(&|x| id(&arr(x), &qd, &qdd), &q, hq, richardson),
                    jacobian(&|x| id(&q, &arr(x), &qdd), &qd, hv, richardson),
                    jacobian(&|x| fd(&arr(x), &qd, &tau), &q, hq, richardson),
                    jacobian(&|x| fd(&q, &arr(x), &tau), &qd, hv, richardson),
                    jacobian(&|x| fd(&q, &qd, &arr(x)), &tau, ht, richardson),
                ]
            }

            /// The runtime's route: Richardson differences of the RNEA for `∂τ/∂q`, `∂τ/∂q̇`;
            /// then, at `q̈ = I⁻¹(τ − RNEA(q, q̇, 0))` (CRBA, nalgebra's LU),
            /// `∂q̈/∂x = −I⁻¹ ∂RNEA/∂x` and `I⁻¹`. (Differencing that `q̈` directly would
            /// amplify its rounding, `cond(I) ε ‖q̈‖`, by `1/h`: the gripper's fingers make
            /// `I` ill-conditioned enough that no one step stays under 1e-8 for every state.)
            fn rnea_derivatives(
                model: &Model,
                id: &dyn Fn(&[f64; N], &[f64; N], &[f64; N]) -> Vec<f64>,
                (q, qd, qdd, tau): ([f64; N], [f64; N], [f64; N], [f64; N]),
            ) -> [Vec<f64>; 5] {
                let fd = |_: &[f64; N], _: &[f64; N], _: &[f64; N]| vec![0.0; N];
                let [a, b, ..] = differences(id, &fd, (q, qd, qdd, tau), [3e-4, 1e-1], true);
                let acc = arr(&rnea_forward(model, &q, &qd, &tau));
                let [c, d, ..] = differences(id, &fd, (q, qd, acc, tau), [3e-4, 1e-1], true);
                let minv = runtime::rnea::mass_matrix(model, &q).try_inverse().expect("regular");
                let solve = |m: &[f64]| -> Vec<f64> {
                    let m = DMatrix::from_row_slice(N, N, m);
                    let x = -&minv * m;
                    (0..N * N).map(|k| x[(k / N, k % N)]).collect()
                };
                let e = (0..N * N).map(|k| minv[(k / N, k % N)]).collect();
                [a, b, solve(&c), solve(&d), e]
            }

            /// The generated derivatives at a state, in the order of [`differences`].
            fn generated(q: &[f64; N], qd: &[f64; N], qdd: &[f64; N], tau: &[f64; N]) -> [Vec<f64>; 5] {
                let (a, b) = mech::inverse_dynamics_derivatives(q, qd, qdd);
                let (c, d, e) = mech::forward_dynamics_derivatives(q, qd, tau).expect("regular");
                [flat(&a), flat(&b), flat(&c), flat(&d), flat(&e)]
            }

            #[test]
            fn agree_with_differences_of_the_generated_functions() {
                let mut r = rng(0xd1ff);
                let mut worst = [0.0f64; 5];
                let id = |q: &[f64; N], qd: &[f64; N], qdd: &[f64; N]| mech::inverse_dynamics(q, qd, qdd).to_vec();
                let fd = |q: &[f64; N], qd: &[f64; N], tau: &[f64; N]| mech::forward_dynamics(q, qd, tau).expect("regular").to_vec();
                for _ in 0..STATES {
                    let s = state(&mut r);
                    let got = generated(&s.0, &s.1, &s.2, &s.3);
                    let want = differences(&id, &fd, s, [1e-6, 1e-3], false);
                    for k in 0..5 {
                        worst[k] = worst[k].max(rel_err(&got[k], &want[k]));
                    }
                }
                eprintln!(
                    "{}: central differences of the module, worst over {STATES} states: \
                     dID/dq {:.1e}, dID/dqd {:.1e}, dFD/dq {:.1e}, dFD/dqd {:.1e}, dFD/dtau {:.1e}",
                    stringify!($m), worst[0], worst[1], worst[2], worst[3], worst[4]
                );
                assert!(worst.iter().all(|w| *w <= 1e-6), "{worst:?}");
            }

            #[test]
            fn agree_with_extrapolated_differences_of_the_runtime_rnea() {
                let model = spec();
                let mut r = rng(0xd2ff);
                let mut worst = [0.0f64; 5];
                let id = |q: &[f64; N], qd: &[f64; N], qdd: &[f64; N]| {
                    runtime::rnea::inverse_dynamics(&model, q, qd, qdd).as_slice().to_vec()
                };
                for _ in 0..STATES {
                    let s = state(&mut r);
                    let got = generated(&s.0, &s.1, &s.2, &s.3);
                    let want = rnea_derivatives(&model, &id, s);
                    for k in 0..5 {
                        worst[k] = worst[k].max(rel_err(&got[k], &want[k]));
                    }
                }
                eprintln!(
                    "{}: Richardson differences of the RNEA (FD: −I⁻¹ ∂RNEA/∂x), worst over {STATES} states: \
                     dID/dq {:.1e}, dID/dqd {:.1e}, dFD/dq {:.1e}, dFD/dqd {:.1e}, dFD/dtau {:.1e}",
                    stringify!($m), worst[0], worst[1], worst[2], worst[3], worst[4]
                );
                assert!(worst.iter().all(|w| *w <= 1e-8), "{worst:?}");
            }

            #[test]
            fn inverse_mass_matrix_and_errors_match_forward_dynamics() {
                let mut r = rng(0xd3ff);
                let mut worst: f64 = 0.0;
                for _ in 0..STATES {
                    let (q, qd, _, tau) = state(&mut r);
                    let (_, _, minv) = mech::forward_dynamics_derivatives(&q, &qd, &tau).unwrap();
                    let m = mech::mass_matrix(&q);
                    for i in 0..N {
                        for j in 0..N {
                            let p: f64 = (0..N).map(|k| minv[i][k] * m[k][j]).sum();
                            worst = worst.max((p - if i == j { 1.0 } else { 0.0 }).abs());
                        }
                    }
                }
                eprintln!("{}: worst |I⁻¹·I − 1| {worst:.1e}", stringify!($m));
                assert!(worst <= 1e-12, "{worst:e}");
                // Non-finite and huge inputs, at every position of every argument.
                let (q, qd, _, tau) = state(&mut r);
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e200] {
                    for arg in 0..3 {
                        for i in 0..N {
                            let mut x = [q, qd, tau];
                            x[arg][i] = bad;
                            let a = mech::forward_dynamics(&x[0], &x[1], &x[2]);
                            let b = mech::forward_dynamics_derivatives(&x[0], &x[1], &x[2]);
                            match (a, b) {
                                (Ok(_), Ok(_)) => {}
                                (Err(a), Err(b)) => {
                                    assert_eq!(a.pivot, b.pivot, "{bad} at {arg}/{i}");
                                    assert_eq!(a.value.to_bits(), b.value.to_bits(), "{bad} at {arg}/{i}");
                                    assert_eq!(
                                        a.condition_estimate.to_bits(),
                                        b.condition_estimate.to_bits()
                                    );
                                }
                                (a, b) => panic!("{bad} at {arg}/{i}: {a:?} vs {:?}", b.map(|_| ())),
                            }
                        }
                    }
                }
            }
        }
    )*};
}

derivative_tests! {
    planar_2r: "planar_2r.toml",
    puma560: "puma560.toml",
    puma560_urdf: "puma560.urdf",
    stanford_arm: "stanford_arm.toml",
    gripper_tree: "gripper_tree.toml",
    chain7: "chain7.toml",
    iiwa14: "iiwa14.urdf",
}

/// Friction and rotor inertia in the scene: the symbolic derivatives (evaluated by the
/// generator's interpreter) against Richardson differences of the runtime NOC with its drives.
#[test]
fn drives_are_differentiated() {
    use codegen::sym::Arg;
    let src = include_str!("../../mechanisms/specs/puma560.toml");
    let m = model(
        "puma560.toml",
        &format!("{src}\n[scene]\nfriction = true\nrotor_inertia = true\n"),
    );
    let s = codegen::symbolic(&m);
    let n = 6;
    let mut r = rng(0xd4ff);
    let mut worst = [0.0f64; 5];
    for _ in 0..50 {
        let v = |r: &mut rand::rngs::StdRng, a: f64| -> Vec<f64> {
            (0..n).map(|_| r.random_range(-a..a)).collect()
        };
        let (q, qdd, tau) = (v(&mut r, 3.0), v(&mut r, 5.0), v(&mut r, 20.0));
        // Speeds away from the regularized Coulomb law's knee (`v_s`), where the differences'
        // step would have to shrink with it.
        let qd: Vec<f64> = v(&mut r, 1.5)
            .iter()
            .map(|x| x + 0.5 * x.signum())
            .collect();
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            Arg::Tau => tau[i],
            _ => f64::NAN,
        };
        let idd = s.graph.eval(&s.inverse_dynamics_derivatives, &input);
        let fdd = s.graph.eval(&s.forward_dynamics_derivatives, &input);
        let got = [
            &idd[..n * n],
            &idd[n * n..],
            &fdd[n..n + n * n],
            &fdd[n + n * n..n + 2 * n * n],
            &fdd[n + 2 * n * n..],
        ];
        let id = |q: &[f64], qd: &[f64]| {
            runtime::noc::inverse_dynamics(&m, q, qd, &qdd)
                .as_slice()
                .to_vec()
        };
        let fd = |q: &[f64], qd: &[f64], tau: &[f64]| {
            runtime::noc::forward_dynamics(&m, q, qd, tau)
                .unwrap()
                .as_slice()
                .to_vec()
        };
        let want = [
            jacobian(&|x| id(x, &qd), &q, 1e-3, true),
            jacobian(&|x| id(&q, x), &qd, 1e-3, true),
            jacobian(&|x| fd(x, &qd, &tau), &q, 1e-3, true),
            jacobian(&|x| fd(&q, x, &tau), &qd, 1e-3, true),
            jacobian(&|x| fd(&q, &qd, x), &tau, 1e-3, true),
        ];
        for k in 0..5 {
            worst[k] = worst[k].max(rel_err(got[k], &want[k]));
        }
    }
    eprintln!("puma560 with drives: Richardson differences of the runtime NOC: {worst:?}");
    assert!(worst.iter().all(|w| *w <= 1e-8), "{worst:?}");
}
