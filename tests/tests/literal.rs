//! The two runtime routes of a parallel mechanism against each other: the literal NOC
//! (`runtime::parallel::literal`: dense `T`, `Ṫu`, `M`, `W`, then `TᵀMT` and
//! `Tᵀ(M ṫ + W M t − w^G)`, every leg by its generic chain) and the leg-wise evaluator the
//! generator compiles (`runtime::parallel::noc`: one Newton–Euler wrench per body projected leg
//! by leg, closed-form UPS legs). They share the kinematics only, so agreement checks the
//! dynamics of each, including the Gough–Stewart's closed-form legs (Khalil & Guegan 2004)
//! against the literal `TᵀMT`.

use rand::Rng;
use runtime::model::Drive;
use runtime::parallel::PlatformMotion;
use runtime::parallel::literal;
use runtime::parallel::noc::{self, Plan};
use runtime::scalar::Site;
use tests::pkm::{PARALLEL, home_x, model, random_state, rel};

/// States per mechanism and case.
const STATES: usize = 200;

/// Worst ∞-norm relative error allowed between the routes.
const TOL: f64 = 1e-11;

fn amplitudes(m: &runtime::parallel::ParallelModel) -> (f64, f64) {
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

fn rows(m: &[Vec<f64>]) -> Vec<f64> {
    m.concat()
}

fn dense(m: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    m.transpose().as_slice().to_vec()
}

/// The worst errors of inverse dynamics, mass matrix, actuator-space inertia and forward
/// dynamics of the literal route against the leg-wise one over `STATES` random states.
fn compare(name: &str, plan: &Plan, home: &[f64], angle: f64, reach: f64, seed: u64) -> [f64; 4] {
    let mut rng = tests::rng(seed);
    let mut worst = [0.0f64; 4];
    for _ in 0..STATES {
        let (x, u, ud) = random_state(plan, home, &mut rng, angle, reach);
        let tau = noc::inverse_dynamics(plan, &x, &u, &ud).unwrap();
        let e = [
            rel(
                literal::inverse_dynamics(plan, &x, &u, &ud)
                    .unwrap()
                    .as_slice(),
                &tau,
            ),
            rel(
                &dense(&literal::mass_matrix(plan, &x).unwrap()),
                &rows(&noc::mass_matrix(plan, &x).unwrap()),
            ),
            rel(
                &dense(&literal::actuator_mass_matrix(plan, &x).unwrap()),
                &rows(&noc::actuator_mass_matrix(plan, &x).unwrap()),
            ),
            rel(
                literal::forward_dynamics(plan, &x, &u, &tau)
                    .unwrap()
                    .as_slice(),
                &noc::forward_dynamics(plan, &x, &u, &tau).unwrap(),
            ),
        ];
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
    }
    let shown: Vec<String> = worst.iter().map(|w| format!("{w:.1e}")).collect();
    println!("{name}: literal vs leg-wise, worst [ID, I, A⁻ᵀIA⁻¹, FD] = {shown:?}");
    worst
}

#[test]
fn literal_noc_agrees_with_the_leg_wise_evaluator() {
    for (i, name) in PARALLEL.iter().enumerate() {
        let m = model(name);
        if m.motion.schoenflies() {
            // The literal route does not take a Schönflies platform's six-joint shaft (its
            // `terms` answer `Err`); tests/tests/schoenflies.rs checks it by other routes.
            assert!(
                runtime::parallel::literal::terms(&Plan::new(&m).unwrap(), &home_x(&m), &[0.0; 4])
                    .is_err()
            );
            continue;
        }
        let plan = Plan::new(&m).unwrap();
        let (angle, reach) = amplitudes(&m);
        let worst = compare(name, &plan, &home_x(&m), angle, reach, 0x11 + i as u64);
        assert!(worst.iter().all(|e| *e <= TOL), "{name}: {worst:?}");
    }
}

/// Every leg joint (actuated and passive) with random friction and rotor inertia: the literal
/// route maps them by `Lᵀ` and `Lᵀ I_a L`, the leg-wise one inside each leg's `J⁻ᵀ`.
#[test]
fn literal_noc_agrees_with_drives_on_every_leg_joint() {
    let mut rng = tests::rng(0xd71e);
    for (i, name) in PARALLEL.iter().enumerate() {
        let m = model(name);
        if m.motion.schoenflies() {
            // The literal route does not take a Schönflies platform's six-joint shaft (its
            // `terms` answer `Err`); tests/tests/schoenflies.rs checks it by other routes.
            assert!(
                runtime::parallel::literal::terms(&Plan::new(&m).unwrap(), &home_x(&m), &[0.0; 4])
                    .is_err()
            );
            continue;
        }
        let mut plan = Plan::new(&m).unwrap();
        for lp in &mut plan.legs {
            // A leg with drives takes the generic route (as `Plan::new` would choose).
            lp.ups = None;
            lp.delta = None;
            for d in &mut lp.drives {
                *d = Drive {
                    viscous: rng.random_range(0.0..20.0),
                    coulomb: rng.random_range(0.0..5.0),
                    coulomb_velocity: 1e-2,
                    armature: rng.random_range(0.0..2.0),
                };
            }
        }
        let (angle, reach) = amplitudes(&m);
        let worst = compare(name, &plan, &home_x(&m), angle, reach, 0x22 + i as u64);
        assert!(worst.iter().all(|e| *e <= TOL), "{name}: {worst:?}");
        // The drives change the efforts, so the comparison above can fail.
        let plain = Plan::new(&m).unwrap();
        let (x, u, ud) = random_state(&plan, &home_x(&m), &mut rng, angle, reach);
        let a = literal::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        let b = literal::inverse_dynamics(&plain, &x, &u, &ud).unwrap();
        assert!(rel(a.as_slice(), b.as_slice()) > 1e-3, "{name}");
    }
}

/// `T` is a natural orthogonal complement: every leg's last body carries its end point with the
/// platform's velocity (the loop-closure constraint `K T = 0`, checked through the twists), and
/// `TᵀMT` is symmetric positive definite.
#[test]
fn literal_twists_close_the_loops() {
    let m = model("gough_stewart");
    let plan = Plan::new(&m).unwrap();
    let mut rng = tests::rng(7);
    let (angle, reach) = amplitudes(&m);
    for _ in 0..50 {
        let (x, u, _) = random_state(&plan, &home_x(&m), &mut rng, angle, reach);
        let terms = literal::terms(&plan, &x, &u).unwrap();
        let (pl, legs) = noc::kinematics(&plan, &x).unwrap();
        let twist = &terms.t * nalgebra::DVector::from_column_slice(&u);
        let rot = nalgebra::Matrix3::from_fn(|i, j| pl.rot[i][j]);
        let w = nalgebra::Vector3::new(u[0], u[1], u[2]);
        let v = nalgebra::Vector3::new(u[3], u[4], u[5]);
        let mut b = 0;
        for (lp, lk) in plan.legs.iter().zip(&legs) {
            b += lp.joints.len();
            let last = b - 1;
            // Velocity of the S centre as a point of the leg's last body and of the platform.
            let frame = nalgebra::Matrix3::from_fn(|i, j| lk.frame[i][j]);
            let com = nalgebra::Vector3::from(lk.com[lp.joints.len() - 1]);
            let end = nalgebra::Vector3::from(lk.end);
            let wl = twist.fixed_rows::<3>(6 * last).into_owned();
            let vc = twist.fixed_rows::<3>(6 * last + 3).into_owned();
            let v_leg = vc + wl.cross(&(frame * (end - com)));
            let arm = rot * nalgebra::Vector3::from(lp.end_platform);
            let v_platform = v + w.cross(&arm);
            assert!(
                (v_leg - v_platform).amax() <= 1e-12 * (1.0 + v_platform.amax()),
                "{v_leg} vs {v_platform}"
            );
        }
        let i = terms.t.transpose() * &terms.m * &terms.t;
        assert!((&i - i.transpose()).amax() <= 1e-12 * i.amax());
        assert!(i.cholesky().is_some());
    }
}

/// Bad input and the parallel singularity give errors, never NaN.
#[test]
fn literal_route_refuses_bad_input_and_singular_poses() {
    let m = model("gough_stewart");
    let plan = Plan::new(&m).unwrap();
    let x = home_x(&m);
    let z = [0.0; 6];
    let mut bad = x.clone();
    bad[0] = f64::NAN;
    let e = literal::inverse_dynamics(&plan, &bad, &z, &z).unwrap_err();
    assert_eq!(e.site, Site::Input);
    assert!(literal::forward_dynamics(&plan, &x, &z, &[f64::INFINITY; 6]).is_err());
    // The semi-regular Gough–Stewart platform at 90° yaw is singular (Site::Actuation).
    let yaw = std::f64::consts::FRAC_PI_2;
    let q0 = [x[3], x[4], x[5], x[6]];
    let qz = [(yaw / 2.0).cos(), 0.0, 0.0, (yaw / 2.0).sin()];
    let q = [
        qz[0] * q0[0] - qz[3] * q0[3],
        qz[0] * q0[1] - qz[3] * q0[2],
        qz[0] * q0[2] + qz[3] * q0[1],
        qz[0] * q0[3] + qz[3] * q0[0],
    ];
    let xs = [x[0], x[1], x[2], q[0], q[1], q[2], q[3]];
    let leg_wise = noc::inverse_dynamics(&plan, &xs, &z, &z).unwrap_err();
    let lit = literal::inverse_dynamics(&plan, &xs, &z, &z).unwrap_err();
    assert!(matches!(leg_wise.site, Site::Actuation(_)), "{leg_wise:?}");
    assert!(matches!(lit.site, Site::Actuation(_)), "{lit:?}");
    assert!(lit.condition_estimate > 1e8, "{lit:?}");
}
