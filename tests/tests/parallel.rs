//! The generated code of every bundled parallel mechanism against the runtime evaluator
//! (`runtime::parallel::noc`, the same equations evaluated in `f64` without the DAG) on random
//! in-workspace states, plus properties that need no second implementation: power balance,
//! forward/inverse dynamics and kinematics round trips, symmetry and definiteness.
//! The independent route (Newton–Euler of every body with Lagrange multipliers) is in
//! `tests/lagrange.rs`.

use rand::Rng;
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use tests::pkm::{home_x, model, random_state, rel};

/// States per mechanism.
const STATES: usize = 500;

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut a = [0.0; N];
    a.copy_from_slice(v);
    a
}

fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

fn amplitudes(m: &ParallelModel) -> (f64, f64) {
    match m.motion {
        PlatformMotion::Pose => (0.15, 0.03 * m.size()),
        PlatformMotion::Orientation { .. } => (0.4, 0.0),
        PlatformMotion::PlanarPoint { .. } => (0.0, 0.05),
        PlatformMotion::Translation { .. } => (0.0, 0.05 * m.size()),
        PlatformMotion::PlanarPose { .. } => (0.15, 0.03 * m.size()),
        PlatformMotion::HeaveTilt { .. } => (0.2, 0.03 * m.size()),
        PlatformMotion::Schoenflies { .. } => (1.0, 0.05 * m.size()),
    }
}

macro_rules! generated_vs_runtime {
    ($name:ident) => {
        #[test]
        fn $name() {
            use mechanisms::$name as g;
            const NX: usize = g::NX;
            const DOF: usize = g::DOF;
            let m = model(stringify!($name));
            let plan = Plan::new(&m).unwrap();
            let home = home_x(&m);
            let (angle, reach) = amplitudes(&m);
            let mut rng = tests::rng(0x5eed ^ DOF as u64);
            let mut worst = [0.0f64; 7];
            for _ in 0..STATES {
                let (x, u, ud) = random_state(&plan, &home, &mut rng, angle, reach);
                let (xa, ua, uda): ([f64; NX], [f64; DOF], [f64; DOF]) =
                    (arr(&x), arr(&u), arr(&ud));
                let q = noc::inverse_kinematics(&plan, &x).unwrap();
                let e = [
                    rel(&g::inverse_kinematics(&xa).unwrap(), &q),
                    rel(
                        &g::actuator_rates(&xa, &ua).unwrap(),
                        &noc::actuator_rates(&plan, &x, &u).unwrap(),
                    ),
                    rel(
                        &g::inverse_dynamics(&xa, &ua, &uda).unwrap(),
                        &noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap(),
                    ),
                    rel(
                        &flat(&g::mass_matrix(&xa).unwrap()),
                        &noc::mass_matrix(&plan, &x).unwrap().concat(),
                    )
                    // The split of the efforts, against the runtime's.
                    .max(rel(
                        &g::gravity(&xa).unwrap(),
                        &noc::gravity(&plan, &x).unwrap(),
                    ))
                    .max(rel(
                        &g::coriolis(&xa, &ua).unwrap(),
                        &noc::coriolis(&plan, &x, &u).unwrap(),
                    )),
                    rel(
                        &flat(&g::actuator_mass_matrix(&xa).unwrap()),
                        &noc::actuator_mass_matrix(&plan, &x).unwrap().concat(),
                    ),
                    {
                        let tau: Vec<f64> = (0..DOF).map(|i| 10.0 * ud[i] - 3.0 * u[i]).collect();
                        rel(
                            &g::forward_dynamics(&xa, &ua, &arr(&tau)).unwrap(),
                            &noc::forward_dynamics(&plan, &x, &u, &tau).unwrap(),
                        )
                    },
                    {
                        // Round trips: forward dynamics of the inverse dynamics' efforts, and
                        // forward kinematics of the inverse kinematics from a perturbed guess.
                        let tau = g::inverse_dynamics(&xa, &ua, &uda).unwrap();
                        let back = g::forward_dynamics(&xa, &ua, &tau).unwrap();
                        let d: Vec<f64> = (0..DOF).map(|i| if i < 3 { 0.02 } else { 0.002 }).collect();
                        let guess = noc::retract(plan.motion, &x, &d);
                        let xf = g::forward_kinematics(&arr(&q), &arr(&guess)).unwrap();
                        rel(&back, &ud).max(rel(&xf, &x))
                    },
                ];
                for (w, v) in worst.iter_mut().zip(e) {
                    *w = w.max(v);
                }
            }
            eprintln!(
                "{}: worst relative errors (∞-norm) over {STATES} states: IK {:.1e}, rates {:.1e}, ID {:.1e}, I (and gravity, coriolis) {:.1e}, A⁻ᵀIA⁻¹ {:.1e}, FD {:.1e}, round trips {:.1e}",
                stringify!($name),
                worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], worst[6]
            );
            // `HOME` is the spec's home pose: reachable, and forward kinematics from it
            // returns it.
            let q = g::inverse_kinematics(&g::HOME).unwrap();
            let back = g::forward_kinematics(&q, &g::HOME).unwrap();
            assert!(rel(&back, &g::HOME) <= 1e-12, "{}: {back:?}", stringify!($name));
            for (k, w) in worst.iter().enumerate() {
                let tol = if k == 6 { 1e-9 } else { 1e-11 };
                assert!(*w <= tol, "{}: check {k}: {w:e}", stringify!($name));
            }
        }
    };
}

generated_vs_runtime!(gough_stewart);
generated_vs_runtime!(sliding_hexapod);
generated_vs_runtime!(rus_hexapod);
generated_vs_runtime!(agile_eye);
generated_vs_runtime!(planar_five_bar);
generated_vs_runtime!(delta_rl5);
generated_vs_runtime!(planar_3rrr);
generated_vs_runtime!(tsai_3upu);
generated_vs_runtime!(prs_head);
generated_vs_runtime!(delta4_rl5);

macro_rules! power_balance {
    ($test:ident, $name:ident) => {
        /// `q̇ᵀ (τ(x, u, u̇) − τ(x, 0, 0)) = d/dt (½ uᵀ I u)` along `x(t) = x ⊕ t u`,
        /// `u(t) = u + t u̇` (central differences, h = 1e-5), and `I` symmetric positive definite.
        #[test]
        fn $test() {
            use mechanisms::$name as g;
            const DOF: usize = g::DOF;
            let m = model(stringify!($name));
            let plan = Plan::new(&m).unwrap();
            let home = home_x(&m);
            let (angle, reach) = amplitudes(&m);
            let mut rng = tests::rng(77);
            for _ in 0..50 {
                let (x, u, ud) = random_state(&plan, &home, &mut rng, angle, reach);
                let ke = |t: f64| {
                    let xt = noc::retract(
                        plan.motion,
                        &x,
                        &u.iter().map(|v| v * t).collect::<Vec<_>>(),
                    );
                    let ut: Vec<f64> = u.iter().zip(&ud).map(|(a, b)| a + t * b).collect();
                    let i = g::mass_matrix(&arr(&xt)).unwrap();
                    let mut e = 0.0;
                    for r in 0..DOF {
                        for c in 0..DOF {
                            e += 0.5 * ut[r] * i[r][c] * ut[c];
                        }
                    }
                    e
                };
                let h = 1e-5;
                let dke = (ke(h) - ke(-h)) / (2.0 * h);
                let xa = arr(&x);
                let tau = g::inverse_dynamics(&xa, &arr(&u), &arr(&ud)).unwrap();
                let hold = g::inverse_dynamics(&xa, &[0.0; DOF], &[0.0; DOF]).unwrap();
                let qd = g::actuator_rates(&xa, &arr(&u)).unwrap();
                let p: f64 = (0..DOF).map(|i| qd[i] * (tau[i] - hold[i])).sum();
                assert!((dke - p).abs() <= 1e-6 * (1.0 + p.abs()), "{dke} vs {p}");
                // Symmetric, and Cholesky succeeds.
                let i = g::mass_matrix(&xa).unwrap();
                let mut l = [[0.0; DOF]; DOF];
                for r in 0..DOF {
                    for c in 0..DOF {
                        assert_eq!(i[r][c], i[c][r]);
                    }
                    for c in 0..=r {
                        let s: f64 = i[r][c] - (0..c).map(|k| l[r][k] * l[c][k]).sum::<f64>();
                        if r == c {
                            assert!(s > 0.0, "not positive definite");
                            l[r][r] = s.sqrt();
                        } else {
                            l[r][c] = s / l[c][c];
                        }
                    }
                }
            }
        }
    };
}

power_balance!(power_balance_gough_stewart, gough_stewart);
power_balance!(power_balance_sliding_hexapod, sliding_hexapod);
power_balance!(power_balance_rus_hexapod, rus_hexapod);
power_balance!(power_balance_agile_eye, agile_eye);
power_balance!(power_balance_planar_five_bar, planar_five_bar);
power_balance!(power_balance_delta_rl5, delta_rl5);
power_balance!(power_balance_planar_3rrr, planar_3rrr);
power_balance!(power_balance_tsai_3upu, tsai_3upu);
power_balance!(power_balance_prs_head, prs_head);
power_balance!(power_balance_delta4_rl5, delta4_rl5);

/// Home is where every leg joint is zero (the spec's placements), and the loops close there.
#[test]
fn home_joint_positions_are_zero() {
    for name in tests::pkm::PARALLEL {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let q = noc::leg_joint_positions(&plan, &home_x(&m)).unwrap();
        for leg in &q {
            for v in leg {
                assert!(v.abs() < 1e-12, "{name}: {q:?}");
            }
        }
    }
}

macro_rules! against_lagrange {
    ($test:ident, $name:ident) => {
        /// The generated inverse dynamics against the independent route: Newton–Euler of every
        /// body with the joint reactions and actuator efforts solved as Lagrange multipliers
        /// (`references::lagrange`, dense least squares in Cartesian body coordinates). The body
        /// poses come from the runtime's leg inverse kinematics, so the loop closure is
        /// checked first.
        #[test]
        fn $test() {
            use mechanisms::$name as g;
            use references::lagrange::{self, Prescribed};
            const DOF: usize = g::DOF;
            let m = model(stringify!($name));
            let plan = Plan::new(&m).unwrap();
            let home = home_x(&m);
            let (angle, reach) = amplitudes(&m);
            let mut rng = tests::rng(0x1a9 ^ DOF as u64);
            let mut worst: f64 = 0.0;
            for _ in 0..20 {
                let (x, u, ud) = random_state(&plan, &home, &mut rng, angle, reach);
                let leg_q = noc::leg_joint_positions(&plan, &x).unwrap();
                let sys = lagrange::from_parallel(&m, &leg_q, &x);
                let closure = lagrange::closure_residual(&sys);
                assert!(closure < 1e-12 * m.size(), "loop open by {closure:e}");
                let platform = sys.bodies.len() - 1;
                let (prescribed, uu, uud) = match m.motion {
                    PlatformMotion::Pose => (
                        Prescribed::Pose {
                            body: platform,
                            point: [x[0], x[1], x[2]],
                        },
                        u.clone(),
                        ud.clone(),
                    ),
                    PlatformMotion::Orientation { .. } => (
                        Prescribed::Orientation { body: platform },
                        u.clone(),
                        ud.clone(),
                    ),
                    // The point's in-plane velocity; the point body's idle spin is prescribed
                    // zero (its rotational inertia is not part of the model).
                    PlatformMotion::PlanarPoint { height } => (
                        Prescribed::Pose {
                            body: platform,
                            point: [x[0], x[1], height],
                        },
                        vec![0.0, 0.0, 0.0, u[0], u[1], 0.0],
                        vec![0.0, 0.0, 0.0, ud[0], ud[1], 0.0],
                    ),
                    // The Delta's parallelograms hold the platform's orientation; its own test
                    // (tests/tests/delta.rs) gives the reference U joints to hold it.
                    PlatformMotion::Translation { .. } => unreachable!("see tests/tests/delta.rs"),
                    // A 1T2R platform's reference is in tests/tests/prs.rs (as a pose).
                    PlatformMotion::HeaveTilt { .. } => unreachable!("see tests/tests/prs.rs"),
                    // A 4-axis Delta's reference is in tests/tests/schoenflies.rs.
                    PlatformMotion::Schoenflies { .. } => {
                        unreachable!("see tests/tests/schoenflies.rs")
                    }
                    // t = S u: ω = (0, 0, u₂), the platform origin's velocity (u₀, u₁, 0).
                    PlatformMotion::PlanarPose { height, .. } => (
                        Prescribed::Pose {
                            body: platform,
                            point: [x[0], x[1], height],
                        },
                        vec![0.0, 0.0, u[2], u[0], u[1], 0.0],
                        vec![0.0, 0.0, ud[2], ud[0], ud[1], 0.0],
                    ),
                };
                let sol = lagrange::inverse_dynamics(&sys, &prescribed, &uu, &uud).unwrap();
                let tau = g::inverse_dynamics(&arr(&x), &arr(&u), &arr(&ud)).unwrap();
                worst = worst.max(rel(&tau, &sol.efforts));
            }
            eprintln!(
                "{}: generated vs Lagrange multipliers, worst relative error (∞-norm): {worst:.1e}",
                stringify!($name)
            );
            assert!(worst <= 1e-10, "{worst:e}");
        }
    };
}

against_lagrange!(lagrange_gough_stewart, gough_stewart);
against_lagrange!(lagrange_sliding_hexapod, sliding_hexapod);
against_lagrange!(lagrange_rus_hexapod, rus_hexapod);
against_lagrange!(lagrange_agile_eye, agile_eye);
against_lagrange!(lagrange_planar_five_bar, planar_five_bar);
against_lagrange!(lagrange_planar_3rrr, planar_3rrr);

/// A generic leg (`LegKind::Generic`, inverse kinematics by a fixed number of Newton steps),
/// compiled (`tests/build.rs`, `codegen/tests/data/good_parallel/generic_leg.toml`): the
/// generated functions against the runtime on random states, the forward/inverse kinematics
/// round trip from a perturbed guess, and an error far outside the workspace. (The runtime's
/// generic leg is checked against Newton–Euler with Lagrange multipliers in
/// `tests/tests/lagrange.rs`.)
#[test]
fn generic_leg_module_matches_runtime() {
    use runtime::parallel::noc;
    use tests::variants::generic_leg as g;
    let path = "../codegen/tests/data/good_parallel/generic_leg.toml";
    let src = std::fs::read_to_string(path).unwrap();
    let Ok((codegen::spec::Mechanism::Parallel(model), _)) =
        codegen::spec::load_mechanism(path, &src)
    else {
        panic!("{path} is a parallel mechanism")
    };
    let kinds = model.validate().unwrap();
    assert!(
        kinds.contains(&runtime::parallel::LegKind::Generic),
        "{kinds:?}"
    );
    let plan = noc::Plan::new(&model).unwrap();
    let home = model.home_x();
    let mut r = tests::rng(91);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut r, 0.2, 0.05);
        let xa: [f64; 7] = arr(&x);
        let q = g::inverse_kinematics(&xa).unwrap();
        worst = worst.max(tests::pkm::rel(
            &q,
            &noc::inverse_kinematics(&plan, &x).unwrap(),
        ));
        let tau = g::inverse_dynamics(&xa, &arr(&u), &arr(&ud)).unwrap();
        let want = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        worst = worst.max(tests::pkm::rel(&tau, &want));
        let back = g::forward_dynamics(&xa, &arr(&u), &tau).unwrap();
        worst = worst.max(tests::pkm::rel(&back, &ud));
        // Forward kinematics from a perturbed guess returns the pose.
        let mut guess = xa;
        for v in guess.iter_mut().take(3) {
            *v += 0.01;
        }
        let xf = g::forward_kinematics(&q, &guess).unwrap();
        let sign = if xf[3] * xa[3] < 0.0 { -1.0 } else { 1.0 };
        for i in 0..7 {
            let s = if i < 3 { 1.0 } else { sign };
            assert!((s * xf[i] - xa[i]).abs() < 1e-9, "{xf:?} vs {xa:?}");
        }
    }
    println!("generic leg: generated vs runtime {worst:.1e}");
    assert!(worst < 1e-11, "{worst:e}");
    // Far from home (rotations to 2 rad, translations to 1 m), where the Newton steps from
    // home may not converge: a finite result or an error, never NaN.
    let (mut ok, mut err) = (0, 0);
    for _ in 0..500 {
        let d: Vec<f64> = (0..6)
            .map(|i| if i < 3 { 2.0 } else { 1.0 } * r.random_range(-1.0..1.0))
            .collect();
        let x: [f64; 7] = arr(&noc::retract(plan.motion, &home, &d));
        match g::inverse_dynamics(&x, &[0.1; 6], &[0.2; 6]) {
            Ok(t) => {
                assert!(t.iter().all(|v| v.is_finite()), "{x:?}: {t:?}");
                ok += 1;
            }
            Err(_) => err += 1,
        }
    }
    println!("far poses: {ok} finite, {err} errors");
    assert_eq!(ok + err, 500);
}
