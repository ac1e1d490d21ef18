//! Planar 3-DOF platforms in task coordinates `x = [px, py, φ]` (`coordinates = "planar_pose"`)
//! against independent routes:
//! - the 3-RRR of `mechanisms/specs/planar_3rrr.toml` against the same machine in joint
//!   coordinates (`tests/data/planar_3rrr_joints.toml`: leg 1 carries the platform in the tree,
//!   two revolute cuts), evaluated by the closed-loop route (`runtime::closed::noc`: its own loop
//!   equations, Newton assembly and `Φ_d` solves);
//! - Newton–Euler of every body with the joint reactions and efforts as Lagrange multipliers
//!   (`references::lagrange`), for the 3-RRR (generated module), the 3-RPR and the 3-PRR
//!   (`tests/data/planar_3rpr.toml`, `planar_3prr.toml`, runtime evaluator);
//! - power balance and the forward-dynamics round trip of the generated 3-RRR.
//!
//! Errors are relative, `‖a − b‖∞ / ‖b‖∞` (∞-norm of the difference over the ∞-norm of the
//! reference; matrices flattened).

use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, literal};
use tests::pkm::{model, random_state, rel};
use tests::routes::Pair;

/// Random regular states per check.
const STATES: usize = 500;

fn data(name: &str) -> (std::path::PathBuf, String) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("data/{name}.toml"));
    let src = std::fs::read_to_string(&path).unwrap();
    (path, src)
}

fn joints_model() -> runtime::closed::ClosedModel {
    tests::routes::closed_data("planar_3rrr_joints.toml")
}

fn data_model(name: &str) -> ParallelModel {
    let (path, src) = data(name);
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => m,
        Ok(_) => panic!("{name} is not a parallel mechanism"),
        Err(d) => panic!("{d}"),
    }
}

fn arr(v: &[f64]) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// Random states: φ within ±0.3 rad, the origin within ±2 cm of home.
fn state(
    plan: &Plan,
    home: &[f64],
    rng: &mut rand::rngs::StdRng,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    random_state(plan, home, rng, 0.3, 0.02)
}

/// The task-coordinate form and the joint-coordinate form agree at corresponding states: `q` by
/// the platform's inverse kinematics, the joint coordinates `x_J` by the closed route's assembly
/// from `q`, `q̇ = A u`, `q̈ = A u̇ + Ȧ u` (`Ȧ u` the actuated rows of the literal route's
/// `L̇ u`, kinematics only). Inverse dynamics, actuator-space inertia `A⁻ᵀ I A⁻¹` against the
/// closed route's `I`, and forward dynamics (`q̈` of the closed route against `A u̇ + Ȧ u`).
#[test]
fn planar_3rrr_in_joint_coordinates_matches_the_task_form() {
    let pm = model("planar_3rrr");
    let jm = joints_model();
    let pair = Pair::new(&pm, &jm);
    let pplan = &pair.task;
    let home = pm.home_x();
    let mut rng = tests::rng(0x3a44);
    let mut worst = [0.0f64; 3];
    for _ in 0..STATES {
        let (p, v, a) = state(pplan, &home, &mut rng);
        let (e, _) = pair.compare(&p, &v, &a, 3.0);
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
    }
    println!(
        "planar_3rrr: task form vs joint coordinates over {STATES} states, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ vs I_J {:.1e}, FD {:.1e}",
        worst[0], worst[1], worst[2]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
}

/// The generated module against the runtime's task-coordinate route and the closed route's
/// generated module in joint coordinates (the bench's pair), at the same states.
#[test]
fn planar_3rrr_generated_task_and_joint_modules_agree() {
    use mechanisms::planar_3rrr as g;
    use tests::variants::planar3_joints as gj;
    let pm = model("planar_3rrr");
    let pplan = Plan::new(&pm).unwrap();
    let home = pm.home_x();
    let mut rng = tests::rng(0x3a45);
    let mut worst: f64 = 0.0;
    for _ in 0..STATES {
        let (p, v, a) = state(&pplan, &home, &mut rng);
        let (x, u, ud) = (arr(&p), arr(&v), arr(&a));
        let q = g::inverse_kinematics(&x).unwrap();
        let qd = g::actuator_rates(&x, &u).unwrap();
        let xj = gj::forward_kinematics(&q, &gj::HOME).unwrap();
        // q̈ = A u̇ + Ȧ u from the runtime's literal route (kinematics only).
        let t = literal::terms(&pplan, &p, &v).unwrap();
        let qdd: Vec<f64> = (0..3)
            .map(|r| {
                (0..3).map(|c| t.a[(r, c)] * a[c]).sum::<f64>()
                    + t.ld_u[3 * r + pplan.legs[r].actuated]
            })
            .collect();
        let tau = g::inverse_dynamics(&x, &u, &ud).unwrap();
        let tau_j = gj::inverse_dynamics(&xj, &qd, &arr(&qdd)).unwrap();
        worst = worst.max(rel(&tau, &tau_j));
    }
    println!(
        "planar_3rrr: generated task module vs generated joint module over {STATES} states, worst relative error (∞-norm) of the efforts: {worst:.1e}"
    );
    assert!(worst <= 1e-12, "{worst:e}");
}

/// The actuator efforts of a route at `(x, u, u̇)`.
type Efforts = dyn Fn(&Plan, &[f64], &[f64], &[f64]) -> Vec<f64>;

/// Newton–Euler with Lagrange multipliers: the legs' revolutes about z, a spherical joint at each
/// platform point (the three together hold the platform in its plane), the platform's motion
/// prescribed as `t = S u` (`ω = (0, 0, u₂)`, the origin's velocity `(u₀, u₁, 0)`).
fn against_lagrange(m: &ParallelModel, seed: u64, states: usize, efforts: &Efforts) -> f64 {
    use references::lagrange::{self, Prescribed};
    let plan = Plan::new(m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(seed);
    let mut worst: f64 = 0.0;
    let runtime::parallel::PlatformMotion::PlanarPose { height, .. } = m.motion else {
        panic!("{}: not a planar pose", m.name)
    };
    for _ in 0..states {
        let (x, u, ud) = state(&plan, &home, &mut rng);
        let leg_q = noc::leg_joint_positions(&plan, &x).unwrap();
        let sys = lagrange::from_parallel(m, &leg_q, &x);
        let closure = lagrange::closure_residual(&sys);
        assert!(closure < 1e-12 * m.size(), "loop open by {closure:e}");
        let platform = sys.bodies.len() - 1;
        let prescribed = Prescribed::Pose {
            body: platform,
            point: [x[0], x[1], height],
        };
        let uu = [0.0, 0.0, u[2], u[0], u[1], 0.0];
        let uud = [0.0, 0.0, ud[2], ud[0], ud[1], 0.0];
        let sol = lagrange::inverse_dynamics(&sys, &prescribed, &uu, &uud).unwrap();
        worst = worst.max(rel(&efforts(&plan, &x, &u, &ud), &sol.efforts));
    }
    worst
}

#[test]
fn planar_3rrr_generated_against_lagrange_multipliers() {
    use mechanisms::planar_3rrr as g;
    let m = model("planar_3rrr");
    let worst = against_lagrange(&m, 0x1a93, 100, &|_, x, u, ud| {
        g::inverse_dynamics(&arr(x), &arr(u), &arr(ud))
            .unwrap()
            .to_vec()
    });
    println!(
        "planar_3rrr: generated vs Lagrange multipliers over 100 states, worst relative error (∞-norm): {worst:.1e}"
    );
    assert!(worst <= 1e-10, "{worst:e}");
}

#[test]
fn planar_3rpr_and_3prr_against_lagrange_multipliers() {
    for (name, seed) in [("planar_3rpr", 0x3e9), ("planar_3prr", 0x3f2)] {
        let m = data_model(name);
        let worst = against_lagrange(&m, seed, 100, &|plan, x, u, ud| {
            noc::inverse_dynamics(plan, x, u, ud).unwrap()
        });
        println!(
            "{name}: runtime vs Lagrange multipliers over 100 states, worst relative error (∞-norm): {worst:.1e}"
        );
        assert!(worst <= 1e-10, "{name}: {worst:e}");
    }
}

/// Either leg joint may be actuated: the 3-RRR at its elbows, the 3-RPR at its base revolutes
/// and the 3-PRR at its rod revolutes (the models of the specs with the other joint of each leg
/// actuated), the runtime against Lagrange multipliers.
#[test]
fn other_actuated_joints_against_lagrange_multipliers() {
    for (mut m, seed) in [
        (model("planar_3rrr"), 0x51),
        (data_model("planar_3rpr"), 0x52),
        (data_model("planar_3prr"), 0x53),
    ] {
        for leg in &mut m.legs {
            leg.actuated = 1 - leg.actuated;
            leg.actuated_name = leg.joints[leg.actuated].name.clone();
        }
        let worst = against_lagrange(&m, seed, 100, &|plan, x, u, ud| {
            noc::inverse_dynamics(plan, x, u, ud).unwrap()
        });
        println!(
            "{} actuated at its other leg joints: runtime vs Lagrange multipliers over 100 states, worst relative error (∞-norm): {worst:.1e}",
            m.name
        );
        assert!(worst <= 1e-10, "{}: {worst:e}", m.name);
    }
}

/// `det A` at `x`.
fn det_a(plan: &Plan, x: &[f64]) -> f64 {
    let a = noc::actuation(plan, x).unwrap();
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

/// Forward kinematics (Newton on `q(x)` with `A`, `x ⊕ δu` a sum) recovers the platform pose
/// from the actuated positions of its inverse kinematics, for the three leg kinds, from a guess
/// 2 mm and 0.02 rad off, at states of home's aspect (`det A` of home's sign and at least a
/// tenth of home's: a type-II locus crosses the 3-RPR's sampling range near `φ ≈ −0.16` rad,
/// and beyond it a pose has a mirrored twin nearby with the same `q`). From home it always
/// returns a pose with the same `q` (checked at every state), not always the same pose.
/// Errors: `‖x_FK − x‖∞` (m and rad), `‖q(x_FK) − q‖∞ / ‖q‖∞`.
#[test]
fn forward_kinematics_round_trip() {
    for m in [
        model("planar_3rrr"),
        data_model("planar_3prr"),
        data_model("planar_3rpr"),
    ] {
        let plan = Plan::new(&m).unwrap();
        let home = m.home_x();
        let d_home = det_a(&plan, &home);
        let mut rng = tests::rng(0xf0);
        let (mut worst, mut worst_q): (f64, f64) = (0.0, 0.0);
        let mut n = 0;
        while n < 100 {
            let (x, _, _) = state(&plan, &home, &mut rng);
            let q = noc::inverse_kinematics(&plan, &x).unwrap();
            let other = noc::forward_kinematics(&plan, &q, &home).unwrap();
            let q_other = noc::inverse_kinematics(&plan, &other).unwrap();
            worst_q = worst_q.max(rel(&q_other, &q));
            if det_a(&plan, &x) / d_home < 0.1 {
                continue;
            }
            n += 1;
            let guess = [x[0] + 0.002, x[1] - 0.002, x[2] + 0.02];
            let back = noc::forward_kinematics(&plan, &q, &guess).unwrap();
            worst = worst.max((0..3).fold(0.0, |w: f64, i| w.max((back[i] - x[i]).abs())));
        }
        println!(
            "{}: forward kinematics of q(x) over 100 states of home's aspect, worst ‖x_FK − x‖∞ {worst:.1e} (guess 2 mm, 0.02 rad off); from home, worst ‖q(x_FK) − q‖∞/‖q‖∞ {worst_q:.1e}",
            m.name
        );
        assert!(worst <= 1e-9, "{}: {worst:e}", m.name);
        assert!(worst_q <= 1e-9, "{}: {worst_q:e}", m.name);
    }
}

/// The leg kinds are recognised, and their legs close at home.
#[test]
fn planar_leg_kinds_are_recognised() {
    use runtime::parallel::LegKind;
    for (m, kind) in [
        (model("planar_3rrr"), LegKind::PlanarRr),
        (data_model("planar_3prr"), LegKind::PlanarPr),
        (data_model("planar_3rpr"), LegKind::PlanarRp),
    ] {
        let kinds = m.validate().unwrap();
        assert_eq!(kinds, vec![kind; 3], "{}", m.name);
        // Home is every leg joint at zero.
        let plan = Plan::new(&m).unwrap();
        let legs = noc::leg_joint_positions(&plan, &m.home_x()).unwrap();
        for l in legs {
            for q in l {
                assert!(q.abs() < 1e-12, "{}: {q:e} at home", m.name);
            }
        }
    }
}

/// Power balance of the generated 3-RRR: `τ·q̇ = d/dt (T + V)` along a trajectory, checked by
/// `τ·q̇ = uᵀ I u̇ + ½ uᵀ İ u − m g·v_c`-free form: the efforts of `u̇ = 0` without gravity do no
/// work on a rigid system moving at constant `u` only through `C u`, so `uᵀ (C u) = ½ uᵀ İ u`,
/// with `İ` by central differences of the generated mass matrix along `u`.
#[test]
fn planar_3rrr_power_balance_and_round_trip() {
    use mechanisms::planar_3rrr as g;
    let m = model("planar_3rrr");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x90e7);
    let (mut worst_p, mut worst_fd) = (0.0f64, 0.0f64);
    for _ in 0..STATES {
        let (x, u, ud) = state(&plan, &home, &mut rng);
        let (xa, ua, uda) = (arr(&x), arr(&u), arr(&ud));
        // Forward-dynamics round trip: u̇ = FD(x, u, ID(x, u, u̇)).
        let tau = g::inverse_dynamics(&xa, &ua, &uda).unwrap();
        let back = g::forward_dynamics(&xa, &ua, &tau).unwrap();
        worst_fd = worst_fd.max(rel(&back, &ud));
        // Power: τ_C·q̇ with τ_C the efforts of u̇ = 0 minus the static ones is ½ uᵀ İ u.
        let tc = g::inverse_dynamics(&xa, &ua, &[0.0; 3]).unwrap();
        let ts = g::inverse_dynamics(&xa, &[0.0; 3], &[0.0; 3]).unwrap();
        let qd = g::actuator_rates(&xa, &ua).unwrap();
        let p_c: f64 = (0..3).map(|i| (tc[i] - ts[i]) * qd[i]).sum();
        let h = 1e-6;
        let step = |s: f64| -> [f64; 3] { [x[0] + s * u[0], x[1] + s * u[1], x[2] + s * u[2]] };
        let ip = g::mass_matrix(&step(h)).unwrap();
        let im = g::mass_matrix(&step(-h)).unwrap();
        let mut half: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                half += 0.5 * u[i] * (ip[i][j] - im[i][j]) / (2.0 * h) * u[j];
            }
        }
        let scale = (0..3)
            .map(|i| (tc[i] - ts[i]).abs() * qd[i].abs())
            .sum::<f64>()
            .max(1e-3);
        worst_p = worst_p.max((p_c - half).abs() / scale);
    }
    println!(
        "planar_3rrr: power balance τ_C·q̇ = ½uᵀİu (İ by central differences, h = 1e-6) worst relative error {worst_p:.1e}; FD(ID) round trip worst relative error (∞-norm) {worst_fd:.1e}"
    );
    assert!(worst_p <= 1e-6, "{worst_p:e}");
    assert!(worst_fd <= 1e-12, "{worst_fd:e}");
}
