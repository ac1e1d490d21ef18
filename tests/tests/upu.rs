//! Tsai's translational 3-UPU (`mechanisms/specs/tsai_3upu.toml`: a translational platform,
//! three legs of a base U, an actuated prismatic joint and a platform U, evaluated as UPS legs to
//! the platform U centres) against two independent routes:
//! - the same machine in joint coordinates (`tests/data/tsai_3upu_joints.toml`: every U
//!   written out, leg 1 carrying the platform, legs 2 and 3 closing on it by revolute cuts),
//!   evaluated by the closed-loop route (`runtime::closed::noc`: its own loop equations,
//!   Newton assembly and `Φ_d` solves), which knows nothing of `ω = 0`: the legs' U joints hold
//!   the platform's orientation;
//! - Newton–Euler of every body with the joint reactions and efforts as Lagrange multipliers
//!   (`references::lagrange`), the platform's S joints replaced by the legs' platform U joints.
//!
//! Errors are relative, `‖a − b‖∞ / ‖b‖∞` (the ∞-norm of the difference over that of the
//! reference).

use runtime::closed::noc as cnoc;
use runtime::parallel::literal;
use runtime::parallel::noc::{self, Plan};
use tests::pkm::{model, random_state, rel};
use tests::routes::Pair;

/// Random regular states per check.
const STATES: usize = 500;

fn joints_model() -> runtime::closed::ClosedModel {
    tests::routes::closed_data("tsai_3upu_joints.toml")
}

fn mat_vec(a: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|r| r.iter().zip(v).map(|(x, y)| x * y).sum())
        .collect()
}

/// The platform form and the joint-coordinate form agree at corresponding states: `q` by the
/// platform's inverse kinematics, the joint coordinates `x_J` by the closed route's assembly
/// from `q`, `q̇ = A v`, `q̈ = A a + Ȧ v` (`Ȧ v` the actuated rows of the literal route's
/// `L̇ u`, kinematics only). Inverse dynamics, actuator-space inertia `A⁻ᵀ I A⁻¹` against the
/// closed route's `I`, and forward dynamics (`q̈` of the closed route against `A u̇ + Ȧ v`).
#[test]
fn upu_in_joint_coordinates_matches_the_platform_form() {
    let pm = model("tsai_3upu");
    let jm = joints_model();
    let pair = Pair::new(&pm, &jm);
    let pplan = &pair.task;
    let home = pm.home_x();
    let mut rng = tests::rng(0x0b03);
    let mut worst = [0.0f64; 3];
    for _ in 0..STATES {
        let (p, v, a) = random_state(pplan, &home, &mut rng, 0.0, 0.05 * pm.size());
        let (e, _) = pair.compare(&p, &v, &a, 10.0);
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
    }
    println!(
        "tsai_3upu: platform form vs joint coordinates over {STATES} states, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ vs I_J {:.1e}, FD {:.1e}",
        worst[0], worst[1], worst[2]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
}

/// The generated inverse dynamics against Newton–Euler with Lagrange multipliers, the platform's
/// orientation held by each leg's platform U (its first axis on the piston, parallel to the base
/// U's second axis now; its second on the platform, parallel to the base U's first), its motion
/// prescribed as `ω = 0`, `v`.
#[test]
fn upu_against_lagrange_multipliers() {
    use mechanisms::tsai_3upu as g;
    use references::lagrange::{self, CJointKind, Prescribed};
    let m = model("tsai_3upu");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x1a9b0);
    let mut worst: f64 = 0.0;
    for _ in 0..50 {
        let (x, u, ud) = random_state(&plan, &home, &mut rng, 0.0, 0.05 * m.size());
        let leg_q = noc::leg_joint_positions(&plan, &x).unwrap();
        let mut sys = lagrange::from_parallel(&m, &leg_q, &x);
        assert!(lagrange::closure_residual(&sys) < 1e-12 * m.size());
        let platform = sys.bodies.len() - 1;
        let (_, legs) = noc::kinematics(&plan, &x).unwrap();
        let ends: Vec<usize> = (0..sys.joints.len())
            .filter(|&j| sys.joints[j].child == platform)
            .collect();
        for (&j, lk) in ends.iter().zip(&legs) {
            let f = |v: [f64; 3]| runtime::model::mat_vec(&lk.frame, &v);
            sys.joints[j].kind = CJointKind::Universal {
                axis_parent: f(lk.e[1]),
                axis_child: f(lk.e[0]),
            };
        }
        let prescribed = Prescribed::Pose {
            body: platform,
            point: [x[0], x[1], x[2]],
        };
        let uu = [0.0, 0.0, 0.0, u[0], u[1], u[2]];
        let uud = [0.0, 0.0, 0.0, ud[0], ud[1], ud[2]];
        let sol = lagrange::inverse_dynamics(&sys, &prescribed, &uu, &uud).unwrap();
        let xa: [f64; 3] = x.clone().try_into().unwrap();
        let tau = g::inverse_dynamics(&xa, &[u[0], u[1], u[2]], &[ud[0], ud[1], ud[2]]).unwrap();
        worst = worst.max(rel(&tau, &sol.efforts));
    }
    println!(
        "tsai_3upu: generated vs Lagrange multipliers (platform U joints), worst relative error (∞-norm): {worst:.1e}"
    );
    assert!(worst <= 1e-10, "{worst:e}");
}

/// Forward dynamics undoes inverse dynamics (runtime and generated), and the inertial efforts'
/// power at rest matches the kinetic-energy form of the generalized inertia: with
/// `τ_I = τ(x, 0, u̇) − τ(x, 0, 0)` and `q̈ = A u̇`, `τ_I·q̈ = u̇ᵀ I u̇` (`I` by the per-leg
/// end-point inertias, `τ` by the leg-wise Newton–Euler: two routes). The power balance along
/// motions (`τ·q̇` against `d(T + V)/dt`) is `power_balance_tsai_3upu` in tests/tests/parallel.rs.
#[test]
fn upu_round_trip_and_power_balance() {
    use mechanisms::tsai_3upu as g;
    let m = model("tsai_3upu");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x0b04);
    let (mut trip, mut power) = (0.0f64, 0.0f64);
    for _ in 0..STATES {
        let (x, v, a) = random_state(&plan, &home, &mut rng, 0.0, 0.05 * m.size());
        let xa: [f64; 3] = x.clone().try_into().unwrap();
        let va: [f64; 3] = v.clone().try_into().unwrap();
        let tau = noc::inverse_dynamics(&plan, &x, &v, &a).unwrap();
        let back = noc::forward_dynamics(&plan, &x, &v, &tau).unwrap();
        trip = trip.max(rel(&back, &a));
        let tg: [f64; 3] = tau.clone().try_into().unwrap();
        let back_g = g::forward_dynamics(&xa, &va, &tg).unwrap();
        trip = trip.max(rel(&back_g, &a));
        let zero = vec![0.0; 3];
        let t_static = noc::inverse_dynamics(&plan, &x, &zero, &zero).unwrap();
        let t_acc = noc::inverse_dynamics(&plan, &x, &zero, &a).unwrap();
        let amat = noc::actuation(&plan, &x).unwrap();
        let qdd: Vec<f64> = amat
            .iter()
            .map(|r| r.iter().zip(&a).map(|(x, y)| x * y).sum())
            .collect();
        let lhs: f64 = t_acc
            .iter()
            .zip(&t_static)
            .zip(&qdd)
            .map(|((t, s), q)| (t - s) * q)
            .sum();
        let inertia = noc::mass_matrix(&plan, &x).unwrap();
        let rhs: f64 = (0..3)
            .map(|i| (0..3).map(|j| a[i] * inertia[i][j] * a[j]).sum::<f64>())
            .sum();
        power = power.max((lhs - rhs).abs() / rhs.abs().max(1e-300));
    }
    println!(
        "tsai_3upu over {STATES} states: forward-dynamics round trip (runtime and generated) {trip:.1e}, power of the inertial efforts at rest τ·(A u̇) vs u̇ᵀ I u̇ {power:.1e} (relative, ∞-norm / absolute ratio)"
    );
    assert!(trip <= 1e-10, "{trip:e}");
    assert!(power <= 1e-10, "{power:e}");
}

/// With viscous friction on the actuated prismatic joints (`[scene] friction = true`), the
/// legs leave the closed form for the generic leg route (Newton–Euler of the U-P chain to the
/// platform U's centre, the drives at the joints); the platform form still agrees with the
/// joint-coordinate route, which applies the same damping at the same joints. The generic legs'
/// constraint couples are the closed form's, and they fail at the same constraint singularity.
#[test]
fn upu_with_joint_damping_matches_joint_coordinates() {
    let load = |file: &str, before: &str| {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let src = std::fs::read_to_string(&path).unwrap();
        let src = src
            .replacen(before, &format!("[scene]\nfriction = true\n\n{before}"), 1)
            .replace("actuated = true\n", "actuated = true\ndamping = 20.0\n");
        assert_eq!(src.matches("damping = 20.0").count(), 3);
        codegen::spec::load_mechanism(&path.to_string_lossy(), &src)
            .unwrap_or_else(|d| panic!("{d}"))
    };
    let (codegen::spec::Mechanism::Parallel(pm), _) =
        load("../mechanisms/specs/tsai_3upu.toml", "[platform]")
    else {
        panic!("not a parallel mechanism")
    };
    let (codegen::spec::Mechanism::Closed(jm), _) = load("data/tsai_3upu_joints.toml", "[[body]]")
    else {
        panic!("not a closed-loop mechanism")
    };
    let pplan = Plan::new(&pm).unwrap();
    assert!(
        pplan.legs.iter().all(|l| l.ups.is_none()),
        "drives take the generic route"
    );
    let jplan = cnoc::Plan::new(&jm).unwrap();
    let home = pm.home_x();
    let mut rng = tests::rng(0x0b05);
    let mut worst: f64 = 0.0;
    let mut damping: f64 = 0.0;
    for _ in 0..100 {
        let (p, v, a) = random_state(&pplan, &home, &mut rng, 0.0, 0.05 * pm.size());
        let q = noc::inverse_kinematics(&pplan, &p).unwrap();
        let x = cnoc::forward_kinematics(&jplan, &q, &vec![0.0; jplan.nx()]).unwrap();
        let t = literal::terms(&pplan, &p, &v).unwrap();
        let amat: Vec<Vec<f64>> = (0..3)
            .map(|r| (0..3).map(|c| t.a[(r, c)]).collect())
            .collect();
        let bias: Vec<f64> = pplan
            .legs
            .iter()
            .enumerate()
            .map(|(k, lp)| t.ld_u[3 * k + lp.actuated])
            .collect();
        let qd = mat_vec(&amat, &v);
        let qdd: Vec<f64> = mat_vec(&amat, &a)
            .iter()
            .zip(&bias)
            .map(|(x, b)| x + b)
            .collect();
        let tp = noc::inverse_dynamics(&pplan, &p, &v, &a).unwrap();
        let tj = cnoc::inverse_dynamics(&jplan, &x, &qd, &qdd).unwrap();
        worst = worst.max(rel(&tp, &tj));
        damping = damping.max(qd.iter().fold(0.0f64, |m, r| m.max((20.0 * r).abs())));
    }
    println!(
        "tsai_3upu with damping 20 N·s/m on the prismatic joints (up to {damping:.2} N), platform form (generic legs) vs joint coordinates, 100 states, worst relative error (∞-norm): {worst:.1e}"
    );
    assert!(damping > 1.0, "the damping must matter");
    assert!(worst <= 1e-12, "{worst:e}");
    // The generic legs' constraint couples (from the chain's U axes, `e₀ × e₁`) are the closed
    // form's (from `e₀ × e₁′`), up to sign, and fail at the same constraint singularity.
    let closed = Plan::new(&model("tsai_3upu")).unwrap();
    let mut rng = tests::rng(0x0b06);
    for _ in 0..100 {
        let (p, _, _) = random_state(&pplan, &home, &mut rng, 0.0, 0.05 * pm.size());
        let (_, generic_legs) = noc::positions(&pplan, &p).unwrap();
        let (_, closed_legs) = noc::positions(&closed, &p).unwrap();
        let g = noc::constraint_couples(&pplan, &generic_legs);
        let c = noc::constraint_couples(&closed, &closed_legs);
        assert_eq!((g.len(), c.len()), (3, 3));
        for (g, c) in g.iter().zip(&c) {
            let dot: f64 = (0..3).map(|i| g[i] * c[i]).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-13, "{g:?} vs {c:?}");
        }
    }
    let e = noc::inverse_dynamics(&pplan, &on_ray(0.3), &[0.1; 3], &[0.0; 3]).unwrap_err();
    assert!(
        matches!(e.site, runtime::scalar::Site::Constraint(_)),
        "{e:?}"
    );
}

/// The platform at `|p_xy| = r` in the direction 40° from `x`, `z = 0.35 m`: on the circle
/// `r = 2 (a − b) = 0.3 m` the legs' constraint couples are coplanar (the derivation is at
/// `upu_constraint_singularity` in tests/tests/singularities.rs).
fn on_ray(r: f64) -> Vec<f64> {
    let t = 40f64.to_radians();
    vec![r * t.cos(), r * t.sin(), 0.35]
}

/// The constraint singularity is the whole mechanism's, not an artefact of `ω = 0`: the
/// joint-coordinate twin (every U written out, the platform's orientation free and held only
/// by the legs' joints, `ω = 0` nowhere assumed) degrades at the same place. Walking to
/// `|p_xy| = 0.3 m` (40°, `z = 0.35 m`, δ = 1e-1 … 1e-12 m), the two routes agree to 9.0e-15
/// at δ = 0.1 m, then drift apart as the couples turn dependent: 2.2e-13, 1.8e-10, 1.2e-8,
/// 1.6e-5 (the worst of ID, `A⁻ᵀIA⁻¹`, FD) at 1e-2 … 1e-5 m, where the joint route still
/// answers `Ok`; at 1e-6 m its assembly from `q` stalls (`NoConvergence`, `Stalled`), the
/// same δ at which the task route's couple test answers `Err(Constraint(2))`.
///
/// The drift is the joint route's, and it goes as the cube of `Φ_d`'s condition estimate `κ`
/// (`constraint_condition`, which grows as 1/δ: 4.0 at 0.1 m, 8.4e3 at 1e-5 m): the worst
/// error over `κ³ ε` stays within 0.09 … 2.0 over those four decades of `κ`, while over `κ² ε`
/// it grows from 2.6 to 1.0e3. The assembly from `q` is exact only to `κ ε` (the platform
/// turned by 1.6e-12 rad at 1e-5 m, against 8.8e-17 at 0.1 m); off the translational manifold
/// by that much, the nearly mobile platform turns at a rate `κ` times larger, whose velocity
/// products (`Ṫ`, a second factor `κ`) reach the efforts: `κ³ ε`. The task route is not
/// affected (its couples only gate it; its efforts stay within 5.8e-16 of a double-double
/// evaluation to 1e-5 m: `upu_constraint_singularity` in tests/tests/singularities.rs). So in
/// joint coordinates, near a constraint singularity, an `Ok` is only as accurate as `κ³ ε`
/// (2e-4 at the `Err` threshold `κ = 1e4`): docs/closed-loops.md, "Accuracy near a constraint
/// singularity". The test asserts the law, `error ≤ 4 κ³ ε`, at every step.
#[test]
fn upu_constraint_singularity_in_joint_coordinates() {
    let pm = model("tsai_3upu");
    let jm = joints_model();
    let pair = Pair::new(&pm, &jm);
    let (pplan, jplan) = (&pair.task, &pair.joints);
    let (v, a) = ([0.1, -0.2, 0.05], [0.3, 0.1, -0.2]);
    let mut first = (None, None);
    let mut guess = vec![0.0; jplan.nx()];
    for k in 1..=12 {
        let d = 10f64.powi(-k);
        let p = on_ray(0.3 - d);
        let task = noc::inverse_dynamics(pplan, &p, &v, &a);
        let q = noc::inverse_kinematics(pplan, &p).unwrap();
        // The joint-coordinate route: its assembly from `q`, then its inverse dynamics.
        let joint = match cnoc::forward_kinematics(jplan, &q, &guess) {
            Ok(x) => {
                guess.clone_from(&x);
                let qd = mat_vec(&noc::actuation(pplan, &p).unwrap_or_default(), &v);
                match cnoc::inverse_dynamics(jplan, &x, &qd, &qd) {
                    Ok(_) => Ok(()),
                    Err(e) => Err(format!("{:?}", e.site)),
                }
            }
            Err(e) => Err(format!("assembly {:?}", e.stop)),
        };
        println!(
            "δ = {d:e} m: task {:?}, joints {joint:?}",
            task.as_ref().map(|_| ()).map_err(|e| e.site),
        );
        if task.is_err() && first.0.is_none() {
            first.0 = Some(d);
        }
        if joint.is_err() && first.1.is_none() {
            first.1 = Some(d);
        }
        if let Err(e) = &task {
            assert!(
                matches!(e.site, runtime::scalar::Site::Constraint(_)),
                "{e:?}"
            );
        }
        if task.is_ok() && joint.is_ok() {
            // The routes drift apart as the couples turn dependent: the joint-coordinate
            // route solves with `Φ_d`, whose conditioning goes with the couples'.
            let (e, x) = pair.compare(&p, &v, &a, 10.0);
            let kappa = cnoc::constraint_condition(jplan, &x);
            let worst = e.iter().copied().fold(0.0, f64::max);
            println!(
                "  task vs joints (ID, A⁻ᵀIA⁻¹, FD): {:.1e} {:.1e} {:.1e}; κ = {kappa:.2e}, worst / (κ³ ε) = {:.2e}",
                e[0],
                e[1],
                e[2],
                worst / (kappa.powi(3) * f64::EPSILON)
            );
            if k == 1 {
                assert!(e.iter().all(|e| *e <= 1e-12), "δ = {d:e}: {e:?}");
            }
            assert!(
                worst <= 4.0 * kappa.powi(3) * f64::EPSILON,
                "δ = {d:e}: {e:?} beyond 4 κ³ ε (κ = {kappa:e})"
            );
        }
    }
    println!(
        "3-UPU toward |p_xy| = 0.3 m: first Err at δ = {:?} m (task coordinates), {:?} m (joint coordinates)",
        first.0, first.1
    );
    assert_eq!(first.0, Some(1e-6));
    assert!(
        first.1.is_some_and(|d| d >= 1e-6),
        "the joint-coordinate route still answers closer than the task route: {first:?}"
    );
}

/// No false alarms: the couple test answers `Ok` at every state of a region that keeps at least
/// 5 cm from the constraint-singular cylinder `|p_xy| = 0.3 m` and from the base plane (where
/// the couples of the other kinds meet): 1,000 platform positions with `|p_xy| ≤ 0.25 m`,
/// `z ∈ [0.15, 0.6] m`, each with a random `(u, u̇)`. There the runtime's and the generated
/// efforts are `Ok`, agree to 1e-12 (relative, ∞-norm), and the smallest couple pivot is
/// printed.
#[test]
fn upu_no_constraint_false_alarms() {
    use mechanisms::tsai_3upu as g;
    use rand::Rng;
    let m = model("tsai_3upu");
    let plan = Plan::new(&m).unwrap();
    let mut rng = tests::rng(0x0b05);
    let (mut worst, mut n) = (0.0f64, 0);
    let mut smallest = f64::INFINITY;
    while n < 1000 {
        let (px, py) = (rng.random_range(-0.25..0.25), rng.random_range(-0.25..0.25));
        if f64::hypot(px, py) > 0.25 {
            continue;
        }
        let x = [px, py, rng.random_range(0.15..0.6)];
        let u: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let ud: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let t = noc::inverse_dynamics(&plan, &x, &u, &ud)
            .unwrap_or_else(|e| panic!("runtime at {x:?}: {e:?}"));
        let tg = g::inverse_dynamics(&x, &u, &ud)
            .unwrap_or_else(|e| panic!("generated at {x:?}: {e:?}"));
        worst = worst.max(rel(&tg, &t));
        // How far from dependent the couples are: their LU's pivots (untested).
        let (_, legs) = noc::positions(&plan, &x).unwrap();
        smallest = smallest.min(min_pivot(&noc::couple_pivots(&plan, &legs)));
        n += 1;
    }
    println!(
        "tsai_3upu: {n} states with |p_xy| ≤ 0.25 m, z in [0.15, 0.6] m: no Err; generated vs runtime {worst:.1e}; smallest couple pivot {smallest:.3}"
    );
    assert!(worst <= 1e-12, "{worst:e}");
    assert!(smallest > 10.0 * noc::CONSTRAINT_TOLERANCE);
}

/// The smallest pivot of the couples' LU, in magnitude.
fn min_pivot(pivots: &[f64]) -> f64 {
    pivots.iter().fold(f64::INFINITY, |m, p| m.min(p.abs()))
}
