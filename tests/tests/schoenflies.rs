//! The 4-axis Delta (`mechanisms/specs/delta4_rl5.toml`: a Schönflies platform, `x = [px, py,
//! pz, θ]`, three Delta legs to the translating carrier and a telescopic R-U-P-U shaft to the
//! tool) against independent routes:
//! - the same machine in joint coordinates (`tests/data/delta4_rl5_joints.toml`: the Delta as
//!   3-RUU with equivalent rods, the shaft as its joints, the tool's revolute a loop cut),
//!   evaluated by the closed-loop route (`runtime::closed::noc`);
//! - Newton–Euler of every body with the joint reactions and efforts as Lagrange multipliers
//!   (`references::lagrange`);
//! - power balance, the forward-dynamics round trip, and the generated module against the
//!   runtime.
//!
//! Errors are relative, `‖a − b‖∞ / ‖b‖∞`.

use runtime::closed::noc as cnoc;
use runtime::parallel::noc::{self, Plan};
use tests::pkm::{model, random_state, rel};

/// Random regular states per check.
const STATES: usize = 500;

fn joints_model() -> runtime::closed::ClosedModel {
    tests::routes::closed_data("delta4_rl5_joints.toml")
}

fn mat_vec(a: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|r| r.iter().zip(v).map(|(x, y)| x * y).sum())
        .collect()
}

/// The actuated joints' accelerations `q̈ = A u̇ + Ȧ u` (the legs' joint accelerations).
fn actuator_accelerations(plan: &Plan, x: &[f64], u: &[f64], ud: &[f64]) -> Vec<f64> {
    noc::leg_joint_rates(plan, x, u, ud)
        .unwrap()
        .iter()
        .zip(&plan.legs)
        .map(|((_, qdd), lp)| qdd[lp.actuated])
        .collect()
}

/// Task coordinates against joint coordinates at corresponding states: `q` by inverse
/// kinematics, `x_J` by the closed route's assembly from `q`, `q̇ = A u`, `q̈ = A u̇ + Ȧ u`.
/// Inverse dynamics, `A⁻ᵀ I A⁻¹` against the closed route's `I`, forward dynamics.
#[test]
fn schoenflies_in_joint_coordinates_matches_the_task_form() {
    let pm = model("delta4_rl5");
    let jm = joints_model();
    let pplan = Plan::new(&pm).unwrap();
    let jplan = cnoc::Plan::new(&jm).unwrap();
    // The closed route's actuators in the task form's order.
    let names: Vec<String> = pm.legs.iter().map(|l| l.actuated_name.clone()).collect();
    let order: Vec<usize> = names
        .iter()
        .map(|n| {
            jm.independent
                .iter()
                .position(|&j| jm.tree.joints[j].name == *n)
                .unwrap_or_else(|| panic!("{n} is not independent in the joint form"))
        })
        .collect();
    let to_j = |v: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        for (i, &k) in order.iter().enumerate() {
            out[k] = v[i];
        }
        out
    };
    let from_j = |v: &[f64]| -> Vec<f64> { order.iter().map(|&k| v[k]).collect() };
    let home = pm.home_x();
    let mut rng = tests::rng(0x5c40e);
    let mut worst = [0.0f64; 3];
    let mut x_j = vec![0.0; jplan.nx()];
    for _ in 0..STATES {
        let (p, v, a) = random_state(&pplan, &home, &mut rng, 3.0, 0.2 * pm.size());
        let q = noc::inverse_kinematics(&pplan, &p).unwrap();
        x_j = cnoc::forward_kinematics(&jplan, &to_j(&q), &x_j).unwrap();
        let amat = noc::actuation(&pplan, &p).unwrap();
        let qd = mat_vec(&amat, &v);
        let qdd = actuator_accelerations(&pplan, &p, &v, &a);
        let tp = noc::inverse_dynamics(&pplan, &p, &v, &a).unwrap();
        let tj = from_j(&cnoc::inverse_dynamics(&jplan, &x_j, &to_j(&qd), &to_j(&qdd)).unwrap());
        let mp = noc::actuator_mass_matrix(&pplan, &p).unwrap();
        let mj = cnoc::mass_matrix(&jplan, &x_j).unwrap();
        let mj: Vec<Vec<f64>> = order
            .iter()
            .map(|&r| order.iter().map(|&c| mj[r][c]).collect())
            .collect();
        let tau: Vec<f64> = tp
            .iter()
            .enumerate()
            .map(|(i, t)| t + 3.0 * (i as f64 - 1.5))
            .collect();
        let ap = noc::forward_dynamics(&pplan, &p, &v, &tau).unwrap();
        let qdd_p = actuator_accelerations(&pplan, &p, &v, &ap);
        let qdd_j = from_j(&cnoc::forward_dynamics(&jplan, &x_j, &to_j(&qd), &to_j(&tau)).unwrap());
        let e = [
            rel(&tp, &tj),
            rel(&mp.concat(), &mj.concat()),
            rel(&qdd_p, &qdd_j),
        ];
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
    }
    println!(
        "delta4_rl5: task vs joint coordinates over {STATES} states, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ vs I_J {:.1e}, FD {:.1e}",
        worst[0], worst[1], worst[2]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
}

/// The generated inverse dynamics against Newton–Euler with Lagrange multipliers: the Delta
/// legs' platform ends as U joints (axes `n = a × d` on the rod, the motor axis `a` on the
/// carrier: they hold its orientation), the tool's joint a revolute about `z`, the actuated
/// joints' rates and accelerations prescribed (`q̇ = A u`, `q̈ = A u̇ + Ȧ u`).
#[test]
fn schoenflies_against_lagrange_multipliers() {
    use mechanisms::delta4_rl5 as g;
    use references::lagrange::{self, CJointKind, Prescribed};
    let m = model("delta4_rl5");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x1a94);
    let mut worst: f64 = 0.0;
    let mut worst_rt: f64 = 0.0;
    for _ in 0..100 {
        let (x, u, ud) = random_state(&plan, &home, &mut rng, 3.0, 0.2 * m.size());
        let leg_q = noc::leg_joint_positions(&plan, &x).unwrap();
        let mut sys = lagrange::from_parallel(&m, &leg_q, &x);
        assert!(lagrange::closure_residual(&sys) < 1e-12 * m.size());
        let platform = sys.bodies.len() - 1;
        let (_, legs) = noc::kinematics(&plan, &x).unwrap();
        let ends: Vec<usize> = (0..sys.joints.len())
            .filter(|&j| sys.joints[j].child == platform)
            .collect();
        for ((&j, lk), lp) in ends.iter().zip(&legs).zip(&plan.legs) {
            if lp.shaft.is_some() {
                sys.joints[j].kind = CJointKind::Revolute {
                    axis: [0.0, 0.0, 1.0],
                };
                continue;
            }
            let f = |v: [f64; 3]| runtime::model::mat_vec(&lk.frame, &v);
            let a = f(lk.e[0]);
            let d = f([
                lk.end[0] - lk.o[1][0],
                lk.end[1] - lk.o[1][1],
                lk.end[2] - lk.o[1][2],
            ]);
            let n = [
                a[1] * d[2] - a[2] * d[1],
                a[2] * d[0] - a[0] * d[2],
                a[0] * d[1] - a[1] * d[0],
            ];
            let nn = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            sys.joints[j].kind = CJointKind::Universal {
                axis_parent: [n[0] / nn, n[1] / nn, n[2] / nn],
                axis_child: a,
            };
        }
        let amat = noc::actuation(&plan, &x).unwrap();
        let qd = mat_vec(&amat, &u);
        let qdd = actuator_accelerations(&plan, &x, &u, &ud);
        let sol = lagrange::inverse_dynamics(&sys, &Prescribed::ActuatedJoints, &qd, &qdd).unwrap();
        let xa: [f64; 4] = x.clone().try_into().unwrap();
        let ua: [f64; 4] = u.clone().try_into().unwrap();
        let uda: [f64; 4] = ud.clone().try_into().unwrap();
        let tau = g::inverse_dynamics(&xa, &ua, &uda).unwrap();
        worst = worst.max(rel(&tau, &sol.efforts));
        let rt = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        worst_rt = worst_rt.max(rel(&rt, &sol.efforts));
    }
    println!(
        "delta4_rl5: generated vs Lagrange multipliers, worst relative error (∞-norm): {worst:.1e}; runtime {worst_rt:.1e}"
    );
    assert!(worst <= 1e-10, "{worst:e}");
    assert!(worst_rt <= 1e-10, "{worst_rt:e}");
}

/// With drives (`[scene] friction = true`, `rotor_inertia = true`) on the fourth motor, the
/// telescope and motor 1 (viscous, Coulomb and rotor inertia), the task form (the shaft's
/// closed form with its joints' drives, leg 1 on the generic route) agrees with the joint
/// coordinates, which apply the same drives at the same joints: inverse dynamics, `A⁻ᵀ I A⁻¹`
/// and forward dynamics; and the split `gravity + coriolis + friction + inertial` sums to the
/// inverse dynamics.
#[test]
fn schoenflies_with_drives_matches_joint_coordinates() {
    let load = |file: &str, before: &str| {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
        let src = std::fs::read_to_string(&path).unwrap();
        let drive = "damping = 3.0\nfriction = 0.7\narmature = 0.02\n";
        let src = src
            .replacen(
                before,
                &format!("[scene]\nfriction = true\nrotor_inertia = true\n\n{before}"),
                1,
            )
            .replace(
                "name = \"motor4\"\n",
                &format!("name = \"motor4\"\n{drive}"),
            )
            .replace(
                "name = \"telescope\"\n",
                "name = \"telescope\"\ndamping = 5.0\nfriction = 1.5\narmature = 0.3\n",
            )
            .replace(
                "name = \"motor1\"\n",
                &format!("name = \"motor1\"\n{drive}"),
            );
        assert_eq!(src.matches("damping = ").count(), 3);
        codegen::spec::load_mechanism(&path.to_string_lossy(), &src)
            .unwrap_or_else(|d| panic!("{d}"))
    };
    let (codegen::spec::Mechanism::Parallel(pm), _) =
        // The written-out form (its Delta legs one by one, not a pattern): a drive on motor1
        // alone.
        load("../codegen/tests/data/expanded/delta4_rl5.toml", "[platform]")
    else {
        panic!("not a parallel mechanism")
    };
    let (codegen::spec::Mechanism::Closed(jm), _) = load("data/delta4_rl5_joints.toml", "[[body]]")
    else {
        panic!("not a closed-loop mechanism")
    };
    let pplan = Plan::new(&pm).unwrap();
    assert!(pplan.has_friction());
    let jplan = cnoc::Plan::new(&jm).unwrap();
    let home = pm.home_x();
    let mut rng = tests::rng(0xd41e);
    let mut worst = [0.0f64; 4];
    let mut x_j = vec![0.0; jplan.nx()];
    for _ in 0..100 {
        let (p, v, a) = random_state(&pplan, &home, &mut rng, 3.0, 0.2 * pm.size());
        let q = noc::inverse_kinematics(&pplan, &p).unwrap();
        x_j = cnoc::forward_kinematics(&jplan, &q, &x_j).unwrap();
        let amat = noc::actuation(&pplan, &p).unwrap();
        let qd = mat_vec(&amat, &v);
        let qdd = actuator_accelerations(&pplan, &p, &v, &a);
        let tp = noc::inverse_dynamics(&pplan, &p, &v, &a).unwrap();
        let tj = cnoc::inverse_dynamics(&jplan, &x_j, &qd, &qdd).unwrap();
        let mp = noc::actuator_mass_matrix(&pplan, &p).unwrap();
        let mj = cnoc::mass_matrix(&jplan, &x_j).unwrap();
        let tau: Vec<f64> = tp.iter().map(|t| t + 2.0).collect();
        let ap = noc::forward_dynamics(&pplan, &p, &v, &tau).unwrap();
        let qdd_p = actuator_accelerations(&pplan, &p, &v, &ap);
        let qdd_j = cnoc::forward_dynamics(&jplan, &x_j, &qd, &tau).unwrap();
        // The split: τ = gravity + coriolis + friction + M q̈ (q̈ = A u̇ + Ȧ u, in actuator
        // space the inertial part is τ(x, u, u̇) − τ(x, u, 0)).
        let g = noc::gravity(&pplan, &p).unwrap();
        let c = noc::coriolis(&pplan, &p, &v).unwrap();
        let f = noc::friction(&pplan, &p, &v).unwrap();
        let zero = vec![0.0; 4];
        let still = noc::inverse_dynamics(&pplan, &p, &v, &zero).unwrap();
        let sum: Vec<f64> = (0..4).map(|i| g[i] + c[i] + f[i]).collect();
        let e = [
            rel(&tp, &tj),
            rel(&mp.concat(), &mj.concat()),
            rel(&qdd_p, &qdd_j),
            rel(&sum, &still),
        ];
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
    }
    println!(
        "delta4_rl5 with drives on motor4, telescope and motor1: task vs joint coordinates, 100 states, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ {:.1e}, FD {:.1e}; gravity + coriolis + friction vs τ(x, u, 0) {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
}

/// The tool turned by whole turns is the same machine: at `θ + 2πk` (`k = ±1, ±2, ±3`, tool
/// angles out to about 22 rad) the generated inverse dynamics, `A⁻ᵀ I A⁻¹` and forward dynamics
/// equal those at `θ`, and `inverse_kinematics` the same motor angles modulo 2π (each revolute
/// actuator's angle is returned in `(−π, π]`). With the checks above against independent routes,
/// which draw `θ` within ±3 rad, this covers every tool angle.
#[test]
fn schoenflies_is_periodic_in_the_tool_angle() {
    use mechanisms::delta4_rl5 as g;
    use std::f64::consts::PI;
    let m = model("delta4_rl5");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x2f1);
    let wrapped = |d: f64| d - 2.0 * PI * (d / (2.0 * PI)).round();
    let mut worst = [0.0f64; 4];
    for _ in 0..200 {
        let (x, u, ud) = random_state(&plan, &home, &mut rng, 3.0, 0.2 * m.size());
        let x: [f64; 4] = x.try_into().unwrap();
        let u: [f64; 4] = u.try_into().unwrap();
        let ud: [f64; 4] = ud.try_into().unwrap();
        let tau = g::inverse_dynamics(&x, &u, &ud).unwrap();
        let mass = g::actuator_mass_matrix(&x).unwrap();
        let acc = g::forward_dynamics(&x, &u, &tau).unwrap();
        let q = g::inverse_kinematics(&x).unwrap();
        for k in [-3.0, -2.0, -1.0, 1.0, 2.0, 3.0] {
            let mut xk = x;
            xk[3] += 2.0 * PI * k;
            let qk = g::inverse_kinematics(&xk).unwrap();
            let e = [
                rel(&g::inverse_dynamics(&xk, &u, &ud).unwrap(), &tau),
                rel(
                    &g::actuator_mass_matrix(&xk).unwrap().concat(),
                    &mass.concat(),
                ),
                rel(&g::forward_dynamics(&xk, &u, &tau).unwrap(), &acc),
                (0..4)
                    .map(|i| wrapped(qk[i] - q[i]).abs())
                    .fold(0.0, f64::max),
            ];
            for (w, e) in worst.iter_mut().zip(e) {
                *w = w.max(e);
            }
        }
    }
    println!(
        "delta4_rl5: θ + 2πk against θ, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ {:.1e}, FD {:.1e}; motor angles {:.1e} rad",
        worst[0], worst[1], worst[2], worst[3]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
}
