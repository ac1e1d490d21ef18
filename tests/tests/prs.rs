//! 1T2R platforms with parasitic motion in task coordinates `x = [pz, α, β]`
//! (`coordinates = "heave_tilt"`: a 3-PRS) against independent routes:
//! - the 3-PRS tripod in task coordinates (`tests/data/tripod_3prs_task.toml`) against the same
//!   machine in joint coordinates (`mechanisms/specs/tripod_3prs.toml`: leg 1 carries the
//!   platform in the tree, two spherical cuts), evaluated by the closed-loop route
//!   (`runtime::closed::noc`: its own loop equations, Newton assembly and `Φ_d` solves): the
//!   efforts, the actuator-space inertia, forward dynamics, and the parasitic components
//!   against the platform pose of the assembled joint-coordinate configuration;
//! - Newton–Euler with Lagrange multipliers (`references::lagrange`), the actuated joints'
//!   motion prescribed, for the bundled head (generated), the tripod and a 3-RPS
//!   (`tests/data/rps_task.toml`, runtime);
//! - the twist map `S` against central differences of the pose; singular walks.
//!
//! Errors are relative, `‖a − b‖∞ / ‖b‖∞` (∞-norm of the difference over the ∞-norm of the
//! reference; matrices flattened).

#![allow(clippy::needless_range_loop)]

use runtime::closed::noc as cnoc;
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, literal};
use tests::pkm::{random_state, rel};
use tests::routes::Pair;

/// Random regular states per check.
const STATES: usize = 500;

fn data(name: &str) -> (std::path::PathBuf, String) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("data/{name}.toml"));
    let src = std::fs::read_to_string(&path).unwrap();
    (path, src)
}

fn joints_model() -> runtime::closed::ClosedModel {
    tests::closed::model("tripod_3prs")
}

fn task_model() -> ParallelModel {
    data_model("tripod_3prs_task")
}

fn data_model(name: &str) -> ParallelModel {
    let (path, src) = data(name);
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => m,
        Ok(_) => panic!("not a parallel mechanism"),
        Err(d) => panic!("{d}"),
    }
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
    runtime::model::quaternion_matrix(&[q[0], q[1], q[2], q[3]])
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
    let jm = joints_model();
    let pair = Pair::new(&pm, &jm);
    let pplan = &pair.task;
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
        let (p, v, a) = state(pplan, &home, &mut rng);
        let (e, x) = pair.compare(&p, &v, &a, 3.0);
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
        // The parasitic components: the closed route's platform body (frame at leg 1's S
        // centre, base orientation at home) against the task form's pose, its origin moved to
        // that S centre.
        let pose = noc::platform_pose(pplan, &p).unwrap();
        let r = quat_matrix(&pose[3..]);
        let s1 = [0.0, 0.15, 0.0];
        let at_s1: Vec<f64> = (0..3)
            .map(|i| pose[i] + r[i][0] * s1[0] + r[i][1] * s1[1] + r[i][2] * s1[2])
            .collect();
        let kin = cnoc::kinematics(&pair.joints, &x);
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

/// The model with its platform as a 6-DOF pose at the full pose `pose` of a 1T2R state (for
/// the Lagrange reference, which places the platform from `x`).
fn as_pose(m: &ParallelModel) -> ParallelModel {
    let mut out = m.clone();
    out.motion = runtime::parallel::PlatformMotion::Pose;
    out
}

/// Newton–Euler of every body with the joint reactions and actuator efforts as Lagrange
/// multipliers (`references::lagrange`), the actuated joints' rates and accelerations
/// prescribed (`q̇ = A u`, `q̈ = A u̇ + Ȧ u`, kinematics of the literal route): the platform's
/// motion, parasitic components included, follows from the joints in the reference. The
/// runtime's and the generated efforts of the bundled head, and the runtime's of the tripod.
#[test]
fn prs_against_lagrange_multipliers() {
    use references::lagrange::{self, Prescribed};
    for (name, m, generated) in [
        ("prs_head", tests::pkm::model("prs_head"), true),
        ("tripod_3prs_task", task_model(), false),
        ("rps_task", data_model("rps_task"), false),
    ] {
        let plan = Plan::new(&m).unwrap();
        let pm = as_pose(&m);
        let home = m.home_x();
        let mut rng = tests::rng(0x7a9);
        let mut worst: f64 = 0.0;
        for _ in 0..100 {
            let (x, u, ud) = state(&plan, &home, &mut rng);
            let leg_q = noc::leg_joint_positions(&plan, &x).unwrap();
            let pose = noc::platform_pose(&plan, &x).unwrap();
            let sys = lagrange::from_parallel(&pm, &leg_q, &pose);
            let closure = lagrange::closure_residual(&sys);
            assert!(
                closure < 1e-12 * m.size(),
                "{name}: loop open by {closure:e}"
            );
            let t = literal::terms(&plan, &x, &u).unwrap();
            let qd: Vec<f64> = (0..3)
                .map(|r| (0..3).map(|c| t.a[(r, c)] * u[c]).sum())
                .collect();
            let qdd: Vec<f64> = (0..3)
                .map(|r| {
                    (0..3).map(|c| t.a[(r, c)] * ud[c]).sum::<f64>()
                        + t.ld_u[3 * r + plan.legs[r].actuated]
                })
                .collect();
            let sol =
                lagrange::inverse_dynamics(&sys, &Prescribed::ActuatedJoints, &qd, &qdd).unwrap();
            let tau = if generated {
                let (xa, ua, uda) = (arr(&x), arr(&u), arr(&ud));
                mechanisms::prs_head::inverse_dynamics(&xa, &ua, &uda)
                    .unwrap()
                    .to_vec()
            } else {
                noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap()
            };
            worst = worst.max(rel(&tau, &sol.efforts));
        }
        println!(
            "{name}: {} vs Lagrange multipliers over 100 states, worst relative error (∞-norm) of the efforts: {worst:.1e}",
            if generated { "generated" } else { "runtime" }
        );
        assert!(worst <= 1e-10, "{name}: {worst:e}");
    }
}

fn arr(v: &[f64]) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

/// The twist map `S` against central differences of the full pose: `v = ṗ` and `ω` from
/// `Ṙ Rᵀ` along each coordinate, and the constraints `nᵢ·(cᵢ − bᵢ) = 0` met by the pose
/// (the S centres in their legs' planes, by the legs' own inverse kinematics: the S centre
/// of the leg chain equals the platform's point).
#[test]
fn twist_map_matches_central_differences_of_the_pose() {
    let m = tests::pkm::model("prs_head");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x5d1f);
    let mut worst: f64 = 0.0;
    let h = 1e-6;
    for _ in 0..200 {
        let (x, _, _) = state(&plan, &home, &mut rng);
        let (_, _, par) = noc::parasitic(&plan, &x).unwrap();
        for j in 0..3 {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[j] += h;
            xm[j] -= h;
            let (rp, op, _) = noc::parasitic(&plan, &xp).unwrap();
            let (rm, om, _) = noc::parasitic(&plan, &xm).unwrap();
            let (r0, _, _) = noc::parasitic(&plan, &x).unwrap();
            // Ṙ Rᵀ = [ω]×.
            let mut rd = [[0.0; 3]; 3];
            for a in 0..3 {
                for b in 0..3 {
                    rd[a][b] = (rp[a][b] - rm[a][b]) / (2.0 * h);
                }
            }
            let mut w = [[0.0; 3]; 3];
            for a in 0..3 {
                for b in 0..3 {
                    w[a][b] = (0..3).map(|k| rd[a][k] * r0[b][k]).sum();
                }
            }
            let fd = [
                w[2][1],
                w[0][2],
                w[1][0],
                (op[0] - om[0]) / (2.0 * h),
                (op[1] - om[1]) / (2.0 * h),
                (op[2] - om[2]) / (2.0 * h),
            ];
            let col: Vec<f64> = (0..6).map(|i| par.s[i][j]).collect();
            worst = worst.max(rel(&col, &fd));
        }
    }
    println!(
        "prs_head: S against central differences (h = 1e-6), worst relative error: {worst:.1e}"
    );
    assert!(worst <= 1e-8, "{worst:e}");
}

/// The generated module against the runtime: `platform_pose` (the parasitic components), and
/// forward kinematics from the actuated positions back to `x`; forward dynamics of the
/// efforts of inverse dynamics gives `u̇` back.
#[test]
fn prs_head_generated_pose_fk_and_round_trip() {
    use mechanisms::prs_head as g;
    let m = tests::pkm::model("prs_head");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x11e4);
    let mut worst = [0.0f64; 3];
    let mut parasitic = [0.0f64; 3];
    for _ in 0..STATES {
        let (x, u, ud) = state(&plan, &home, &mut rng);
        let (xa, ua, uda) = (arr(&x), arr(&u), arr(&ud));
        let pg = g::platform_pose(&xa).unwrap();
        let pr = noc::platform_pose(&plan, &x).unwrap();
        worst[0] = worst[0].max(rel(&pg, &pr));
        let (_, _, par) = noc::parasitic(&plan, &x).unwrap();
        // The head's home origin is on the z axis: `y` is the parasitic motion itself.
        for (p, y) in parasitic.iter_mut().zip(par.y) {
            *p = p.max(y.abs());
        }
        let q = g::inverse_kinematics(&xa).unwrap();
        let xf = g::forward_kinematics(&q, &g::HOME).unwrap();
        worst[1] = worst[1].max(rel(&xf, &xa));
        let tau = g::inverse_dynamics(&xa, &ua, &uda).unwrap();
        let back = g::forward_dynamics(&xa, &ua, &tau).unwrap();
        worst[2] = worst[2].max(rel(&back, &uda));
    }
    println!(
        "prs_head: generated vs runtime platform_pose {:.1e}, FK(IK(x)) vs x {:.1e}, FD(ID) vs u̇ {:.1e} (relative, ∞-norm, {STATES} states); largest parasitic |px| {:.2e} m, |py| {:.2e} m, |γ| {:.2e} rad",
        worst[0], worst[1], worst[2], parasitic[0], parasitic[1], parasitic[2]
    );
    assert!(worst[0] <= 1e-14, "{worst:?}");
    assert!(worst[1] <= 1e-10, "{worst:?}");
    assert!(worst[2] <= 1e-12, "{worst:?}");
    assert!(parasitic[2] > 1e-4, "{parasitic:?}");
}

/// Singular walks of the head, generated and runtime alike, every site of the generated module
/// equal to the runtime's and the efforts equal where both are regular. Tilted about x and about
/// y to ±170° from home: a tilt raises the S centres on one side until a link stands vertical,
/// perpendicular to its horizontal rail (the leg Jacobian's `Site::Leg`, then out of reach,
/// `Site::Reach`); tilted about −x the two S centres that rise sit 0.1 m off the x axis and climb
/// at most 0.1 m, short of the 0.143 m to the links' reach, and that walk stays regular. Lowered
/// to the base plane: the links turn horizontal, so no actuator force has a vertical component
/// (type II): the efforts grow as 1/pz, and in the plane both answer `Site::Actuation`.
#[test]
fn prs_head_tilt_walks_meet_the_same_sites() {
    use mechanisms::prs_head as g;
    let m = tests::pkm::model("prs_head");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut seen: Vec<String> = Vec::new();
    // Regular efforts agree to 1e-9, relative, times the growth of `A`'s condition number:
    // on the way down it grows as 1/pz.
    let tol = |x: &[f64; 3]| 1e-9 * (home[0] / x[0]).max(1.0);
    let walk_through = |what: String, xs: &mut dyn Iterator<Item = [f64; 3]>| {
        let mut walk: Vec<String> = Vec::new();
        for x in xs {
            let u = [0.1, -0.2, 0.3];
            let r = noc::inverse_dynamics(&plan, &x, &u, &u);
            let gr = g::inverse_dynamics(&x, &u, &u);
            match (&r, &gr) {
                (Ok(a), Ok(b)) => assert!(rel(b, a) <= tol(&x), "{x:?}: {a:?} vs {b:?}"),
                (Err(a), Err(b)) => {
                    let site = format!("{:?}", a.site);
                    assert_eq!(site, format!("{:?}", b.site), "{x:?}: {a:?} vs {b:?}");
                    if walk.last() != Some(&site) {
                        walk.push(site);
                    }
                }
                _ => panic!("{x:?}: runtime {r:?}, generated {gr:?}"),
            }
        }
        println!("prs_head {what}: sites in order {walk:?}");
        walk
    };
    for axis in 0..2 {
        for sign in [1.0, -1.0] {
            let walk = walk_through(
                format!("tilted about {} ({sign:+}) to 170°", ["x", "y"][axis]),
                &mut (0..=3400).map(|s| {
                    let t = sign * (170.0 * s as f64 / 3400.0).to_radians();
                    let mut x = [home[0], 0.0, 0.0];
                    x[1 + axis] = t;
                    x
                }),
            );
            if axis == 0 && sign < 0.0 {
                assert!(walk.is_empty(), "{walk:?}");
            } else {
                assert!(walk.iter().any(|s| s.starts_with("Reach(")), "{walk:?}");
            }
            seen.extend(walk);
        }
    }
    // Geometrically, to 1e-12 of the home height: the links' vertical components, and with
    // them `A`'s heave column, shrink as pz, and the efforts that hold the platform up grow as
    // 1/pz (type II). The tilt columns shrink with it, so `A` is a regular matrix times pz:
    // the pivot test, which compares the heave column with the tilt columns times the
    // platform's radius, sees no singularity short of the plane, and the efforts are large but
    // accurate; the walk compares what both answer.
    let down: Vec<[f64; 3]> = (0..=240)
        .map(|k| [home[0] * 10f64.powf(-(k as f64) / 20.0), 0.0, 0.0])
        .collect();
    seen.extend(walk_through(
        "lowered to the base plane".into(),
        &mut down.iter().copied(),
    ));
    let effort = |x: &[f64; 3]| {
        let t = g::inverse_dynamics(x, &[0.0; 3], &[0.0; 3]).unwrap();
        t.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let growth = effort(&down[240]) / effort(&down[0]);
    println!(
        "prs_head lowered to 1e-12 of its home height: largest effort {growth:.1e} times home's"
    );
    assert!(growth > 1e9, "{growth:e}");
    // In the plane every link is horizontal and `A`'s heave column is zero: both evaluators
    // answer `Actuation` (which leg they name is a tie between zero pivots).
    let plane = [0.0; 3];
    let a = noc::inverse_dynamics(&plan, &plane, &[0.0; 3], &[0.0; 3]).unwrap_err();
    let b = g::inverse_dynamics(&plane, &[0.0; 3], &[0.0; 3]).unwrap_err();
    for e in [format!("{:?}", a.site), format!("{:?}", b.site)] {
        assert!(e.starts_with("Actuation("), "{e}");
    }
    assert!(seen.iter().any(|s| s.starts_with("Reach(")), "{seen:?}");
}

/// Tilted about x to the edge of leg 0's reach, bisected: the last regular tilts meet its leg
/// Jacobian's test (`Site::Leg(0)`: the rod perpendicular to the rail) before the slider's
/// circle misses the rail (`Site::Reach(0)`), generated and runtime alike.
#[test]
fn prs_head_leg_singularity_before_reach() {
    use mechanisms::prs_head as g;
    let m = tests::pkm::model("prs_head");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let at = |t: f64| [home[0], t, 0.0];
    let site = |t: f64| {
        let a = noc::inverse_dynamics(&plan, &at(t), &[0.0; 3], &[0.0; 3]).err();
        let b = g::inverse_dynamics(&at(t), &[0.0; 3], &[0.0; 3]).err();
        assert_eq!(
            a.map(|e| format!("{:?}", e.site)),
            b.map(|e| format!("{:?}", e.site)),
            "tilt {t}"
        );
        a.map(|e| e.site)
    };
    // The first failing tilt of a coarse walk, then bisection between it and the last Ok.
    let (mut lo, mut hi) = (0.0, 0.0);
    for s in 0..=3400 {
        let t = (170.0 * s as f64 / 3400.0).to_radians();
        if site(t).is_some() {
            hi = t;
            break;
        }
        lo = t;
    }
    assert!(hi > 0.0, "no failure on the walk");
    let mut sites = Vec::new();
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        match site(mid) {
            None => lo = mid,
            Some(s) => {
                sites.push(format!("{s:?}"));
                hi = mid;
            }
        }
    }
    // Just past the last regular tilt the leg's test fails first.
    let first = site(hi);
    println!(
        "prs_head tilted about x: last regular tilt {lo:.15} rad, first failure {hi:.15} rad at {first:?}; sites met while bisecting {sites:?}"
    );
    assert_eq!(first, Some(runtime::parallel::Site::Leg(0)), "{sites:?}");
    assert_eq!(site(hi + 1e-3), Some(runtime::parallel::Site::Reach(0)));
}

/// A payload on a 1T2R platform (`payload_force`, `payload_inertia`, which take the 6-DOF
/// pose's route with the twist `S u` and project by `Sᵀ`): the head's own platform body moved
/// into a payload on a massless platform gives the same generalized force and inertia.
#[test]
fn prs_head_payload_equals_the_platform_body() {
    use runtime::payload::Payload;
    let m = tests::pkm::model("prs_head");
    let plan = Plan::new(&m).unwrap();
    let mut bare = plan.clone();
    let (mass, com, inertia) = plan.platform;
    bare.platform = (0.0, [0.0; 3], [[0.0; 3]; 3]);
    let payload = Payload::<f64>::from_f64(mass, com, inertia);
    let home = m.home_x();
    let mut rng = tests::rng(0x9a71);
    let mut worst = [0.0f64; 2];
    for _ in 0..200 {
        let (x, u, ud) = state(&plan, &home, &mut rng);
        let (pl, legs) = noc::kinematics(&plan, &x).unwrap();
        let f = noc::generalized_force(&plan, &pl, &legs, &u, &ud, true);
        let mut fb = noc::generalized_force(&bare, &pl, &legs, &u, &ud, true);
        let fp = noc::payload_force(&bare, &pl, &payload, &u, &ud, true);
        for (a, b) in fb.iter_mut().zip(&fp) {
            *a += b;
        }
        worst[0] = worst[0].max(rel(&fb, &f));
        let i = noc::generalized_inertia(&plan, &pl, &legs);
        let mut ib = noc::generalized_inertia(&bare, &pl, &legs);
        let ip = noc::payload_inertia(&bare, &pl, &payload);
        for (ra, rb) in ib.iter_mut().zip(&ip) {
            for (a, b) in ra.iter_mut().zip(rb) {
                *a += b;
            }
        }
        worst[1] = worst[1].max(rel(&ib.concat(), &i.concat()));
    }
    println!(
        "prs_head: platform as a payload vs as the platform body, worst relative error: force {:.1e}, inertia {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst[0] <= 1e-13 && worst[1] <= 1e-13, "{worst:?}");
}
