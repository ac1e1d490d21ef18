//! The compiled generated code of every bundled mechanism (crate `mechanisms`) against the
//! runtime NOC (`runtime::noc`, the literal `TᵀMT`, `Tᵀ(MṪ+WMT)` matrices) and the independent
//! spatial recursive Newton–Euler / composite-body route (`runtime::rnea`), on 1,000 random
//! states each; plus the properties a correct model satisfies (docs/method.md, "Properties used as checks").
//!
//! Error norm: ‖a − b‖∞ / max(‖b‖∞, 1).

use rand::Rng;
use runtime::model::Model;
use tests::{rel_err, rng};

const STATES: usize = 1000;
const TOL: f64 = 1e-12;

fn model(file: &str, src: &str) -> Model {
    match codegen::spec::load_tree(file, src) {
        Ok((m, _)) => m,
        Err(d) => panic!("{d}"),
    }
}

fn flat(m: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    let n = m.nrows();
    (0..n * n).map(|k| m[(k / n, k % n)]).collect()
}

macro_rules! mechanism_tests {
    ($($m:ident : $file:literal),* $(,)?) => {$(
        mod $m {
            use super::*;
            use mechanisms::$m as mech;

            fn spec() -> Model {
                model($file, include_str!(concat!("../../mechanisms/specs/", $file)))
            }

            fn state(r: &mut rand::rngs::StdRng) -> ([f64; mech::DOF], [f64; mech::DOF], [f64; mech::DOF]) {
                let mut q = [0.0; mech::DOF];
                let mut qd = [0.0; mech::DOF];
                let mut qdd = [0.0; mech::DOF];
                for i in 0..mech::DOF {
                    q[i] = r.random_range(-std::f64::consts::PI..std::f64::consts::PI);
                    qd[i] = r.random_range(-2.0..2.0);
                    qdd[i] = r.random_range(-5.0..5.0);
                }
                (q, qd, qdd)
            }

            #[test]
            fn agrees_with_runtime_noc_and_newton_euler() {
                let model = spec();
                assert_eq!(model.dof(), mech::DOF);
                let mut r = rng(0x6e6f63);
                let mut worst = [0.0f64; 6];
                for _ in 0..STATES {
                    let (q, qd, qdd) = state(&mut r);
                    let id = mech::inverse_dynamics(&q, &qd, &qdd);
                    let mm: Vec<f64> = mech::mass_matrix(&q).iter().flatten().copied().collect();
                    let cor = mech::coriolis(&q, &qd);
                    let gr = mech::gravity(&q);
                    let checks = [
                        rel_err(&id, runtime::noc::inverse_dynamics(&model, &q, &qd, &qdd).as_slice()),
                        rel_err(&id, runtime::rnea::inverse_dynamics(&model, &q, &qd, &qdd).as_slice()),
                        rel_err(&mm, &flat(&runtime::noc::mass_matrix(&model, &q))),
                        rel_err(&mm, &flat(&runtime::rnea::mass_matrix(&model, &q))),
                        rel_err(&cor, runtime::noc::coriolis(&model, &q, &qd).as_slice()),
                        rel_err(&gr, runtime::rnea::gravity(&model, &q).as_slice()),
                    ];
                    for (w, e) in worst.iter_mut().zip(checks) {
                        *w = w.max(e);
                    }
                }
                eprintln!(
                    "{}: worst relative error over {STATES} states: ID/NOC {:.1e}, ID/RNEA {:.1e}, \
                     M/NOC {:.1e}, M/CRBA {:.1e}, C/NOC {:.1e}, g/RNEA {:.1e}",
                    stringify!($m), worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]
                );
                for (k, w) in worst.iter().enumerate() {
                    assert!(*w <= TOL, "check {k}: relative error {w:e} > {TOL:e}");
                }
            }

            #[test]
            fn inverse_dynamics_splits_into_its_terms() {
                let mut r = rng(7);
                for _ in 0..200 {
                    let (q, qd, qdd) = state(&mut r);
                    let zero = [0.0; mech::DOF];
                    // inverse_dynamics(q, 0, 0) == gravity(q); ID = I q̈ + C q̇ + gravity.
                    assert!(rel_err(&mech::inverse_dynamics(&q, &zero, &zero), &mech::gravity(&q)) <= TOL);
                    let m = mech::mass_matrix(&q);
                    let c = mech::coriolis(&q, &qd);
                    let g = mech::gravity(&q);
                    let sum: Vec<f64> = (0..mech::DOF)
                        .map(|i| (0..mech::DOF).map(|j| m[i][j] * qdd[j]).sum::<f64>() + c[i] + g[i])
                        .collect();
                    assert!(rel_err(&sum, &mech::inverse_dynamics(&q, &qd, &qdd)) <= TOL);
                }
            }

            #[test]
            fn forward_dynamics_round_trip_and_spd() {
                let model = spec();
                let mut r = rng(11);
                for _ in 0..STATES {
                    let (q, qd, tau) = state(&mut r);
                    let m = mech::mass_matrix(&q);
                    // Symmetric, and positive definite (Cholesky succeeds).
                    let mm = nalgebra::DMatrix::from_fn(mech::DOF, mech::DOF, |i, j| m[i][j]);
                    assert!((mm.clone() - mm.transpose()).amax() == 0.0);
                    assert!(mm.clone().cholesky().is_some(), "mass matrix not SPD at {q:?}");
                    let qdd = mech::forward_dynamics(&q, &qd, &tau).expect("regular configuration");
                    let back = mech::inverse_dynamics(&q, &qd, &qdd);
                    // Relative to the effort scale; the solve loses up to cond(M) digits.
                    assert!(rel_err(&back, &tau) <= 1e-9, "round trip {:e}", rel_err(&back, &tau));
                    let fd = runtime::noc::forward_dynamics(&model, &q, &qd, &tau).expect("regular");
                    assert!(rel_err(&qdd, fd.as_slice()) <= 1e-9);
                }
            }

            /// q̇ᵀ(İ − 2C)q̇ = 0 (skew symmetry, docs/method.md, "Properties used as checks", item 2) and, with gravity off,
            /// d/dt(½ q̇ᵀ I q̇) = q̇ᵀ τ (power balance, property 3), along q(t) = q0 + v t + ½ a t².
            #[test]
            fn skew_symmetry_and_power_balance() {
                let mut r = rng(13);
                let h = 1e-5;
                for _ in 0..100 {
                    let (q0, v, a) = state(&mut r);
                    let at = |t: f64| {
                        let mut q = [0.0; mech::DOF];
                        let mut qd = [0.0; mech::DOF];
                        for i in 0..mech::DOF {
                            q[i] = q0[i] + v[i] * t + 0.5 * a[i] * t * t;
                            qd[i] = v[i] + a[i] * t;
                        }
                        (q, qd)
                    };
                    let ke = |t: f64| {
                        let (q, qd) = at(t);
                        let m = mech::mass_matrix(&q);
                        0.5 * (0..mech::DOF)
                            .map(|i| (0..mech::DOF).map(|j| qd[i] * m[i][j] * qd[j]).sum::<f64>())
                            .sum::<f64>()
                    };
                    let dke = (ke(h) - ke(-h)) / (2.0 * h);
                    let tau: Vec<f64> = mech::inverse_dynamics(&q0, &v, &a)
                        .iter()
                        .zip(mech::gravity(&q0))
                        .map(|(t, g)| t - g)
                        .collect();
                    let power: f64 = tau.iter().zip(&v).map(|(t, v)| t * v).sum();
                    let scale = power.abs().max(dke.abs()).max(1.0);
                    assert!((dke - power).abs() / scale < 1e-6, "power {power} vs dKE/dt {dke}");
                    // Skew symmetry: q̇ᵀ İ q̇ = 2 q̇ᵀ C q̇ (İ along q̇ by central differences).
                    let (qp, _) = at(h);
                    let (qm, _) = at(-h);
                    let (mp, mm) = (mech::mass_matrix(&qp), mech::mass_matrix(&qm));
                    let mut vidv = 0.0;
                    for i in 0..mech::DOF {
                        for j in 0..mech::DOF {
                            vidv += v[i] * (mp[i][j] - mm[i][j]) / (2.0 * h) * v[j];
                        }
                    }
                    // İ along q̇(0) only: use the velocity at t = 0 (a does not enter to first order).
                    let c = mech::coriolis(&q0, &v);
                    let vcv: f64 = c.iter().zip(&v).map(|(c, v)| c * v).sum();
                    let scale = vidv.abs().max(1.0);
                    assert!((vidv - 2.0 * vcv).abs() / scale < 1e-6, "q̇ᵀİq̇ {vidv} vs 2q̇ᵀCq̇ {}", 2.0 * vcv);
                }
            }
        }
    )*};
}

mechanism_tests! {
    planar_2r: "planar_2r.toml",
    puma560: "puma560.toml",
    puma560_urdf: "puma560.urdf",
    stanford_arm: "stanford_arm.toml",
    gripper_tree: "gripper_tree.toml",
    chain7: "chain7.toml",
    iiwa14: "iiwa14.urdf",
}

/// The PUMA 560 written as DH rows in TOML and as a URDF (mechanisms/specs/puma560.*) is the
/// same robot: every generated function agrees.
#[test]
fn puma560_toml_and_urdf_agree() {
    use mechanisms::{puma560 as a, puma560_urdf as b};
    let mut r = rng(17);
    for _ in 0..STATES {
        let mut q = [0.0; 6];
        let mut qd = [0.0; 6];
        let mut qdd = [0.0; 6];
        for i in 0..6 {
            q[i] = r.random_range(-3.0..3.0);
            qd[i] = r.random_range(-2.0..2.0);
            qdd[i] = r.random_range(-5.0..5.0);
        }
        assert!(
            rel_err(
                &a::inverse_dynamics(&q, &qd, &qdd),
                &b::inverse_dynamics(&q, &qd, &qdd)
            ) <= TOL
        );
        let ma: Vec<f64> = a::mass_matrix(&q).iter().flatten().copied().collect();
        let mb: Vec<f64> = b::mass_matrix(&q).iter().flatten().copied().collect();
        assert!(rel_err(&ma, &mb) <= TOL);
        assert!(rel_err(&a::gravity(&q), &b::gravity(&q)) <= TOL);
        assert!(rel_err(&a::coriolis(&q, &qd), &b::coriolis(&q, &qd)) <= TOL);
    }
}

/// The planar 2R arm against its textbook closed form (two rods, joints about z, gravity −y;
/// e.g. Spong, Hutchinson & Vidyasagar, "Robot Modeling and Control", 2006, §7.4.1) with the
/// parameters of mechanisms/specs/planar_2r.toml: l1 = 1, lc1 = 0.5, m1 = 2, l2 = 0.8, lc2 = 0.4,
/// m2 = 1, I_zz = m l²/12.
#[test]
fn planar_2r_matches_the_textbook_closed_form() {
    use mechanisms::planar_2r as mech;
    let (m1, m2, l1, lc1, lc2, g) = (2.0, 1.0, 1.0, 0.5, 0.4, 9.81);
    let (i1, i2) = (m1 * l1 * l1 / 12.0, m2 * 0.8 * 0.8 / 12.0);
    let mut r = rng(19);
    for _ in 0..STATES {
        let q: [f64; 2] = [r.random_range(-3.0..3.0), r.random_range(-3.0..3.0)];
        let qd: [f64; 2] = [r.random_range(-2.0..2.0), r.random_range(-2.0..2.0)];
        let qdd = [r.random_range(-5.0f64..5.0), r.random_range(-5.0f64..5.0)];
        let (c2, s2) = (q[1].cos(), q[1].sin());
        let d11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2) + i1 + i2;
        let d12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + i2;
        let d22 = m2 * lc2 * lc2 + i2;
        let hh = -m2 * l1 * lc2 * s2;
        let g1 = (m1 * lc1 + m2 * l1) * g * q[0].cos() + m2 * lc2 * g * (q[0] + q[1]).cos();
        let g2 = m2 * lc2 * g * (q[0] + q[1]).cos();
        let tau = [
            d11 * qdd[0] + d12 * qdd[1] + hh * qd[1] * qd[1] + 2.0 * hh * qd[0] * qd[1] + g1,
            d12 * qdd[0] + d22 * qdd[1] - hh * qd[0] * qd[0] + g2,
        ];
        let e = rel_err(&mech::inverse_dynamics(&q, &qd, &qdd), &tau);
        assert!(e <= TOL, "planar 2R vs closed form: {e:e}");
    }
}

/// Bad input to the generated tree functions (docs/spec.md, "Bad input"): NaN and ∞ propagate
/// through `inverse_dynamics` and its parts by IEEE arithmetic (no panic, no check);
/// `forward_dynamics` returns `Err(Singular)` when a NaN reaches a pivot of the mass matrix
/// (here `q[1]`, which sets the 2R arm's mass matrix), and `Err` with `pivot == DOF` when the
/// pivots pass but the result is not finite: never an `Ok` holding NaN.
#[test]
fn nan_and_infinity_propagate_as_documented() {
    use mechanisms::planar_2r as mech;
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let tau = mech::inverse_dynamics(&[0.1, nan], &[0.0; 2], &[0.0; 2]);
    assert!(tau.iter().all(|t| t.is_nan()), "{tau:?}");
    let tau = mech::inverse_dynamics(&[0.1, 0.2], &[inf, 0.0], &[0.0; 2]);
    assert!(tau.iter().any(|t| !t.is_finite()), "{tau:?}");
    assert!(
        mech::mass_matrix(&[0.0, nan])
            .iter()
            .flatten()
            .any(|m| m.is_nan())
    );
    assert!(mech::gravity(&[nan, 0.0]).iter().any(|g| g.is_nan()));
    assert!(mech::forward_dynamics(&[0.1, nan], &[0.0; 2], &[1.0; 2]).is_err());
    for (q, qd, tau) in [
        ([0.1, 0.2], [0.0; 2], [nan, 1.0]),
        ([0.1, 0.2], [inf, 0.0], [0.0; 2]),
        ([nan, 0.2], [0.0; 2], [0.0; 2]),
    ] {
        let e = mech::forward_dynamics(&q, &qd, &tau).unwrap_err();
        assert_eq!(e.pivot, mech::DOF, "{q:?} {qd:?} {tau:?}: {e:?}");
        assert!(!e.value.is_finite() && e.condition_estimate == f64::INFINITY);
    }
}

/// The generated error types are `core::error::Error`s with a message, so the README's
/// `forward_dynamics(&q, &qd, &tau)?` compiles in a function returning `Box<dyn Error>` (QA:
/// it did not, the types had neither `Display` nor `Error`).
#[test]
fn generated_errors_are_errors_with_a_message() {
    use std::error::Error;
    fn tree(q: [f64; 2]) -> Result<[f64; 2], Box<dyn Error>> {
        Ok(mechanisms::planar_2r::forward_dynamics(
            &q, &[0.0; 2], &[1.0; 2],
        )?)
    }
    assert!(tree([0.1, 0.2]).is_ok());
    let e = tree([f64::NAN, 0.2]).unwrap_err().to_string();
    assert!(e.starts_with("non-finite input or result"), "{e}");
    let e = mechanisms::planar_2r::inertia_indices(&[[f64::NAN; 2]; 2]).unwrap_err();
    assert_eq!(e.to_string(), "entry (0, 0) is not finite");
    use mechanisms::gough_stewart as gs;
    fn platform(x: &[f64; gs::NX]) -> Result<[f64; gs::DOF], Box<dyn Error>> {
        Ok(gs::inverse_dynamics(x, &[0.0; gs::DOF], &[0.0; gs::DOF])?)
    }
    assert!(platform(&gs::HOME).is_ok());
    let e = platform(&[f64::NAN; gs::NX]).unwrap_err().to_string();
    assert!(e.starts_with("singular at Input"), "{e}");
    let e = gs::forward_kinematics(&[f64::NAN; gs::DOF], &gs::HOME).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("did not converge (Input)"), "{text}");
    let _: &dyn Error = &e;
}

/// Issue 18, 4c: finite inputs whose result overflows. The PUMA 560 with a base rate of 1e155
/// rad/s (its square overflows) gave `Ok` holding NaN; the `f32` module did so from 1e20.
/// Both, and the runtime, now return `Err` with `pivot == DOF`; at an ordinary rate they still
/// answer.
#[test]
fn tree_forward_dynamics_never_returns_a_nan() {
    use mechanisms::f32::puma560 as m32;
    use mechanisms::puma560 as m64;
    let model = model(
        "puma560.toml",
        include_str!("../../mechanisms/specs/puma560.toml"),
    );
    let tau = [1.0; 6];
    for (q, w) in [
        ([0.0; 6], 1e155),
        ([0.1, -0.4, 0.3, 0.2, 0.5, -0.1], 1e155),
        ([0.1, -0.4, 0.3, 0.2, 0.5, -0.1], f64::MAX),
    ] {
        let mut qd = [0.0; 6];
        qd[0] = w;
        let e = m64::forward_dynamics(&q, &qd, &tau).unwrap_err();
        assert_eq!(e.pivot, m64::DOF, "f64 at {w:e}: {e:?}");
        let e = runtime::noc::forward_dynamics(&model, &q, &qd, &tau).unwrap_err();
        assert_eq!(e.pivot, 6, "runtime at {w:e}: {e:?}");
    }
    let q = [0.1, -0.4, 0.3, 0.2, 0.5, -0.1];
    let mut qd = [0.0; 6];
    qd[0] = 1e3;
    let ok = m64::forward_dynamics(&q, &qd, &tau).unwrap();
    assert!(ok.iter().all(|v| v.is_finite()));
    let (q32, tau32) = (q.map(|v| v as f32), tau.map(|v| v as f32));
    for w in [1e20f32, 1e30, f32::MAX] {
        let mut qd = [0.0f32; 6];
        qd[0] = w;
        let e = m32::forward_dynamics(&q32, &qd, &tau32).unwrap_err();
        assert_eq!(e.pivot, m32::DOF, "f32 at {w:e}: {e:?}");
    }
}
