//! 1T2R platforms with parasitic motion in task coordinates `x = [pz, α, β]`
//! (`coordinates = "heave_tilt"`: a 3-PRS) against independent routes:
//! - the 3-PRS tripod in task coordinates (`tests/data/tripod_3prs_task.toml`) against the same
//!   machine in joint coordinates (`mechanisms/specs/tripod_3prs.toml`: leg 1 carries the
//!   platform in the tree, two spherical cuts), evaluated by the closed-loop route
//!   (`runtime::closed::noc`: its own loop equations, Newton assembly and `Φ_d` solves): the
//!   efforts, the actuator-space inertia, forward dynamics, and the parasitic components
//!   against the platform pose of the assembled joint-coordinate configuration;
//! - the parasitic motion's constraints and its twist map `S` against central differences of
//!   the pose.
//!
//! Errors are relative, `‖a − b‖∞ / ‖b‖∞` (∞-norm of the difference over the ∞-norm of the
//! reference; matrices flattened).

use runtime::closed::noc as cnoc;
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, literal};
use tests::pkm::{random_state, rel};

/// Random regular states per check.
const STATES: usize = 500;

fn data(name: &str) -> (std::path::PathBuf, String) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("data/{name}.toml"));
    let src = std::fs::read_to_string(&path).unwrap();
    (path, src)
}

fn spec(name: &str) -> (std::path::PathBuf, String) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../mechanisms/specs/{name}.toml"));
    let src = std::fs::read_to_string(&path).unwrap();
    (path, src)
}

fn joints_model() -> runtime::closed::ClosedModel {
    let (path, src) = spec("tripod_3prs");
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Closed(m), _)) => m,
        Ok(_) => panic!("not a closed-loop mechanism"),
        Err(d) => panic!("{d}"),
    }
}

fn task_model() -> ParallelModel {
    let (path, src) = data("tripod_3prs_task");
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => m,
        Ok(_) => panic!("not a parallel mechanism"),
        Err(d) => panic!("{d}"),
    }
}

fn mat_vec(a: &[Vec<f64>], v: &[f64]) -> Vec<f64> {
    a.iter()
        .map(|r| r.iter().zip(v).map(|(x, y)| x * y).sum())
        .collect()
}

/// Random states: tilts within ±0.2 rad, heave within ±2 cm of home.
fn state(
    plan: &Plan,
    home: &[f64],
    rng: &mut rand::rngs::StdRng,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    random_state(plan, home, rng, 0.2, 0.02)
}

/// The rotation matrix of a unit quaternion `[w, x, y, z]`.
fn quat_matrix(q: &[f64]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = [q[0], q[1], q[2], q[3]];
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// The task-coordinate form and the joint-coordinate form agree at corresponding states: `q` by
/// the platform's inverse kinematics, the joint coordinates `x_J` by the closed route's assembly
/// from `q`, `q̇ = A u`, `q̈ = A u̇ + Ȧ u` (`Ȧ u` the actuated rows of the literal route's
/// `L̇ u`, kinematics only). Inverse dynamics, actuator-space inertia `A⁻ᵀ I A⁻¹` against the
/// closed route's `I`, forward dynamics (`q̈` of the closed route against `A u̇ + Ȧ u`), and the
/// platform's full pose (`platform_pose`: the parasitic components) against the closed route's
/// platform body pose.
#[test]
fn tripod_3prs_in_joint_coordinates_matches_the_task_form() {
    let pm = task_model();
    let pplan = Plan::new(&pm).unwrap();
    let jm = joints_model();
    let jplan = cnoc::Plan::new(&jm).unwrap();
    let platform_body = jm
        .tree
        .bodies
        .iter()
        .position(|b| b.name == "platform")
        .expect("platform body");
    let home = pm.home_x();
    let mut rng = tests::rng(0x9525);
    let mut worst = [0.0f64; 4];
    let mut gamma_max: f64 = 0.0;
    for _ in 0..STATES {
        let (p, v, a) = state(&pplan, &home, &mut rng);
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
        // Inverse dynamics.
        let tp = noc::inverse_dynamics(&pplan, &p, &v, &a).unwrap();
        let tj = cnoc::inverse_dynamics(&jplan, &x, &qd, &qdd).unwrap();
        worst[0] = worst[0].max(rel(&tp, &tj));
        // Actuator-space inertia.
        let mp = noc::actuator_mass_matrix(&pplan, &p).unwrap();
        let mj = cnoc::mass_matrix(&jplan, &x).unwrap();
        worst[1] = worst[1].max(rel(&mp.concat(), &mj.concat()));
        // Forward dynamics under the same efforts.
        let tau: Vec<f64> = tp
            .iter()
            .enumerate()
            .map(|(i, v)| v + 3.0 * (i as f64 - 1.0))
            .collect();
        let ap = noc::forward_dynamics(&pplan, &p, &v, &tau).unwrap();
        let qdd_p: Vec<f64> = mat_vec(&amat, &ap)
            .iter()
            .zip(&bias)
            .map(|(x, b)| x + b)
            .collect();
        let qdd_j = cnoc::forward_dynamics(&jplan, &x, &qd, &tau).unwrap();
        worst[2] = worst[2].max(rel(&qdd_p, &qdd_j));
        // The parasitic components: the closed route's platform body (frame at leg 1's S
        // centre, base orientation at home) against the task form's pose, its origin moved to
        // that S centre.
        let pose = noc::platform_pose(&pplan, &p).unwrap();
        let r = quat_matrix(&pose[3..]);
        let s1 = [0.0, 0.15, 0.0];
        let at_s1: Vec<f64> = (0..3)
            .map(|i| pose[i] + r[i][0] * s1[0] + r[i][1] * s1[1] + r[i][2] * s1[2])
            .collect();
        let kin = cnoc::kinematics(&jplan, &x);
        let mut mine = at_s1.clone();
        let mut theirs = kin.pos[platform_body].to_vec();
        for i in 0..3 {
            for j in 0..3 {
                mine.push(r[i][j]);
                theirs.push(kin.rot[platform_body][i][j]);
            }
        }
        worst[3] = worst[3].max(rel(&mine, &theirs));
        gamma_max = gamma_max.max(libm::atan2(r[1][0], r[0][0]).abs());
    }
    println!(
        "tripod_3prs: task form vs joint coordinates over {STATES} states, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ vs I_J {:.1e}, FD {:.1e}, platform pose {:.1e} (largest parasitic turn |γ| {gamma_max:.2e} rad)",
        worst[0], worst[1], worst[2], worst[3]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
    assert!(
        gamma_max > 1e-4,
        "the parasitic turn should not vanish: {gamma_max:e}"
    );
}
