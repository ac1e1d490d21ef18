//! Rigidly turned copies of the bundled loops: the rank and mobility decisions at home must not
//! depend on how the mechanism sits in the base frame (a loop turned in space has rounding
//! noise where the axis-aligned one has exact zeros), and the efforts must not either.

use references::lagrange;
use runtime::closed::ClosedModel;
use runtime::closed::noc as cnoc;
use runtime::model::{Mat3, Transform, Vec3, mat_vec, matrix_quaternion};
use runtime::parallel::noc as pnoc;
use runtime::parallel::{ParallelModel, PlatformMotion};
use tests::pkm::{PARALLEL, rel};

/// A generic turn (no axis along a coordinate axis, no special angle).
fn generic_turn() -> Transform {
    Transform::from_xyz_rpy([0.0; 3], [0.7, -0.4, 1.1])
}

/// A generic turn about z (the planar point platform's plane stays `z = height`).
fn turn_about_z() -> Transform {
    Transform::from_xyz_rpy([0.0; 3], [0.0, 0.0, 1.1])
}

/// `m` turned rigidly by `t` about the base origin: every frame placed on the base, and the
/// gravity, turned with it.
fn turn_closed(m: &ClosedModel, t: &Transform) -> ClosedModel {
    let mut out = m.clone();
    out.tree.gravity = mat_vec(&t.rotation, &m.tree.gravity);
    for j in &mut out.tree.joints {
        if j.parent.is_none() {
            j.origin = t.compose(&j.origin);
        }
    }
    for c in &mut out.cuts {
        if c.parent.is_none() {
            c.frame_parent = t.compose(&c.frame_parent);
        }
        if c.child.is_none() {
            c.frame_child = t.compose(&c.frame_child);
        }
    }
    for s in &mut out.springs {
        if s.body_a.is_none() {
            s.point_a = t.apply(&s.point_a);
        }
        if s.body_b.is_none() {
            s.point_b = t.apply(&s.point_b);
        }
    }
    out
}

fn turn_parallel(m: &ParallelModel, t: &Transform) -> ParallelModel {
    let mut out = m.clone();
    out.gravity = mat_vec(&t.rotation, &m.gravity);
    out.home = t.compose(&m.home);
    for leg in &mut out.legs {
        leg.joints[0].origin = t.compose(&leg.joints[0].origin);
    }
    out.motion = match m.motion {
        PlatformMotion::Orientation { centre } => PlatformMotion::Orientation {
            centre: t.apply(&centre),
        },
        PlatformMotion::Translation { rotation } => PlatformMotion::Translation {
            rotation: runtime::model::mat_mul(&t.rotation, &rotation),
        },
        // Turned about z (the plane stays): the home rotation turns, φ stays relative to it.
        PlatformMotion::PlanarPose { height, rotation } => PlatformMotion::PlanarPose {
            height,
            rotation: runtime::model::mat_mul(&t.rotation, &rotation),
        },
        // Turned about z: the carrier's rotation turns, θ stays relative to it.
        PlatformMotion::Schoenflies { rotation } => PlatformMotion::Schoenflies {
            rotation: runtime::model::mat_mul(&t.rotation, &rotation),
        },
        other => other,
    };
    out
}

/// Hamilton product `a ⊗ b` of quaternions `[w, x, y, z]`.
fn qmul(a: &[f64], b: &[f64]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

fn rv(r: &Mat3, v: &[f64]) -> Vec3 {
    mat_vec(r, &[v[0], v[1], v[2]])
}

/// The platform coordinates and speeds `(x, u)` of `motion` seen in the turned base frame.
fn turn_state(motion: PlatformMotion, r: &Mat3, x: &[f64], u: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let q = matrix_quaternion(r);
    match motion {
        PlatformMotion::Pose => {
            let p = rv(r, &x[..3]);
            let qx = qmul(&q, &x[3..]);
            let (w, v) = (rv(r, &u[..3]), rv(r, &u[3..]));
            (
                [p.as_slice(), &qx].concat(),
                [w.as_slice(), v.as_slice()].concat(),
            )
        }
        PlatformMotion::Orientation { .. } => (qmul(&q, x).to_vec(), rv(r, u).to_vec()),
        PlatformMotion::PlanarPoint { .. } => {
            let p = rv(r, &[x[0], x[1], 0.0]);
            let v = rv(r, &[u[0], u[1], 0.0]);
            (vec![p[0], p[1]], vec![v[0], v[1]])
        }
        PlatformMotion::Translation { .. } => (rv(r, x).to_vec(), rv(r, u).to_vec()),
        PlatformMotion::PlanarPose { .. } => {
            let p = rv(r, &[x[0], x[1], 0.0]);
            let v = rv(r, &[u[0], u[1], 0.0]);
            (vec![p[0], p[1], x[2]], vec![v[0], v[1], u[2]])
        }
        PlatformMotion::HeaveTilt { .. } => unreachable!("not turned"),
        PlatformMotion::Schoenflies { .. } => {
            let p = rv(r, &[x[0], x[1], x[2]]);
            let v = rv(r, &[u[0], u[1], u[2]]);
            (vec![p[0], p[1], p[2], x[3]], vec![v[0], v[1], v[2], u[3]])
        }
    }
}

#[test]
fn turned_closed_loops_are_accepted_with_the_same_efforts() {
    let t = generic_turn();
    let mut worst_all: f64 = 0.0;
    for name in tests::closed::CLOSED {
        let m = tests::closed::model(name);
        let plan = cnoc::Plan::new(&m).unwrap();
        let turned = turn_closed(&m, &t);
        let tplan =
            cnoc::Plan::new(&turned).unwrap_or_else(|e| panic!("{name} turned is refused: {e}"));
        assert_eq!(tplan.dof(), plan.dof(), "{name}");
        codegen::closed::generate(&turned, &Default::default(), &codegen::Config::default())
            .unwrap_or_else(|e| panic!("{name} turned: no code: {e}"));
        let mut rng = tests::rng(41);
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            let (x, u, ud) =
                tests::closed::random_state(&plan, &mut rng, tests::closed::reach(name));
            let a = cnoc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
            let b = cnoc::inverse_dynamics(&tplan, &x, &u, &ud).unwrap();
            worst = worst.max(rel(&b, &a));
        }
        println!("{name}: turned vs original efforts, max relative error (∞-norm) {worst:.1e}");
        worst_all = worst_all.max(worst);
    }
    assert!(worst_all < 1e-12, "{worst_all:e}");
}

#[test]
fn turned_platforms_are_accepted_with_the_same_efforts() {
    let mut worst_all: f64 = 0.0;
    for name in PARALLEL {
        let m = tests::pkm::model(name);
        if m.motion.parasitic() {
            // A 1T2R platform's tilts are about the base axes: turning the base changes what
            // the coordinates mean (no state of the turned model matches `x` as simply).
            continue;
        }
        let t = match m.motion {
            // (A Schönflies tool turns about z: its motor axis must stay along z.)
            PlatformMotion::PlanarPoint { .. }
            | PlatformMotion::PlanarPose { .. }
            | PlatformMotion::Schoenflies { .. } => turn_about_z(),
            _ => generic_turn(),
        };
        let plan = pnoc::Plan::new(&m).unwrap();
        let turned = turn_parallel(&m, &t);
        let tplan =
            pnoc::Plan::new(&turned).unwrap_or_else(|e| panic!("{name} turned is refused: {e}"));
        codegen::parallel::generate(&turned, &Default::default(), &codegen::Config::default())
            .unwrap_or_else(|e| panic!("{name} turned: no code: {e}"));
        let home = m.home_x();
        let mut rng = tests::rng(42);
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, 0.2, 0.02);
            let a = pnoc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
            let (tx, tu) = turn_state(m.motion, &t.rotation, &x, &u);
            let (_, tud) = turn_state(m.motion, &t.rotation, &x, &ud);
            let b = pnoc::inverse_dynamics(&tplan, &tx, &tu, &tud).unwrap();
            worst = worst.max(rel(&b, &a));
        }
        println!("{name}: turned vs original efforts, max relative error (∞-norm) {worst:.1e}");
        worst_all = worst_all.max(worst);
    }
    assert!(worst_all < 1e-12, "{worst_all:e}");
}

/// Loops closed at home only to within the closure tolerance (every tree joint's home angle
/// moved by 0.9e-9 rad, where the closure check still passes) leave residuals near that
/// tolerance in the loop equations' redundant rows (1.9e-10 of `‖J‖_F` on the Bricard linkage):
/// the mobility is unchanged. Guards the rank tolerance from being tightened below the
/// closure tolerance (to `n·ε`).
#[test]
fn loops_closed_to_the_tolerance_keep_their_mobility() {
    let mut tried = 0;
    for name in tests::closed::CLOSED {
        let m = tests::closed::model(name);
        for j in 0..m.tree.dof() {
            let mut p = m.clone();
            let jt = &mut p.tree.joints[j];
            let turn = runtime::model::axis_angle(&jt.axis, 0.9e-9);
            jt.origin.rotation = runtime::model::mat_mul(&jt.origin.rotation, &turn);
            if p.validate().is_err() {
                continue;
            }
            tried += 1;
            let plan = cnoc::Plan::new(&p).unwrap_or_else(|e| panic!("{name}, joint {j}: {e}"));
            assert_eq!(plan.dof(), m.dof(), "{name}, joint {j}");
        }
    }
    assert!(tried > 30, "{tried}");
}

fn data(file: &str) -> ClosedModel {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(file);
    let src = std::fs::read_to_string(&path).expect("spec readable");
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Closed(m), _)) => m,
        Ok(_) => panic!("{file} is not a closed-loop mechanism"),
        Err(d) => panic!("{d}"),
    }
}

/// The efforts of the independent joints by the Cartesian Newton–Euler + Lagrange-multiplier
/// route (`independent` order), at a closed state.
fn lagrange_efforts(m: &ClosedModel, x: &[f64], u: &[f64], ud: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..m.independent.len()).collect();
    order.sort_by_key(|&k| m.independent[k]);
    let us: Vec<f64> = order.iter().map(|&k| u[k]).collect();
    let uds: Vec<f64> = order.iter().map(|&k| ud[k]).collect();
    let sys = lagrange::from_closed(m, x);
    assert!(lagrange::closure_residual(&sys) < 1e-9);
    let sol = lagrange::inverse_dynamics(&sys, &lagrange::Prescribed::ActuatedJoints, &us, &uds)
        .unwrap_or_else(|e| panic!("Lagrange route failed: {e}"));
    let mut out = vec![0.0; u.len()];
    for (i, &k) in order.iter().enumerate() {
        out[k] = sol.efforts[i];
    }
    out
}

/// Accepted with `dof` degrees of freedom, and the efforts at random closed states against the
/// Lagrange route; returns the worst relative error (∞-norm).
fn check_against_lagrange(m: &ClosedModel, dof: usize, reach: f64) -> f64 {
    let plan = cnoc::Plan::new(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
    codegen::closed::generate(m, &Default::default(), &codegen::Config::default())
        .unwrap_or_else(|e| panic!("{}: no code: {e}", m.name));
    assert_eq!(plan.dof(), dof);
    assert_eq!(plan.rows.len(), plan.nx() - dof);
    let mut rng = tests::rng(43);
    let mut worst: f64 = 0.0;
    for _ in 0..30 {
        let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, reach);
        let ours = cnoc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        worst = worst.max(rel(&ours, &lagrange_efforts(m, &x, &u, &ud)));
    }
    worst
}

/// A planar 3-RRR on a plane inclined by rpy (0.3, 0.2): the loops' out-of-plane equations are
/// rounding noise (exact zeros when the plane is x-y), and were counted as equations ("1 DOF").
#[test]
fn planar_3rrr_on_an_inclined_plane_has_three_dof() {
    let m = data("planar_3rrr_inclined.toml");
    assert_eq!(m.nx(), 7);
    let worst = check_against_lagrange(&m, 3, 0.3);
    println!("planar 3-RRR, inclined: NOC vs Lagrange, max relative error (∞-norm) {worst:.1e}");
    assert!(worst < 1e-10, "{worst:e}");
}

/// A Delta robot with 4R parallelogram forearms, legs at 120°: 25 loop equations of rank 13
/// over 16 joints (counted as 15 before, "1 DOF").
#[test]
fn delta_with_4r_parallelograms_has_three_dof() {
    let m = data("delta_4r.toml");
    assert_eq!((m.nx(), m.cuts.len()), (16, 5));
    let worst = check_against_lagrange(&m, 3, 0.3);
    println!("Delta, 4R parallelograms: NOC vs Lagrange, max relative error (∞-norm) {worst:.1e}");
    assert!(worst < 1e-10, "{worst:e}");
}
