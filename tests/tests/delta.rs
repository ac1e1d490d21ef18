//! The Delta robot (`mechanisms/specs/delta_rl5.toml`: a translational platform, three legs of a
//! revolute crank and a parallelogram) against two independent routes:
//! - the same machine in joint coordinates (`tests/data/delta_rl5_joints.toml`, 3-RUU: each
//!   parallelogram one rod of twice the mass and transverse inertia with no spin inertia, a U at
//!   the elbow and at the platform), evaluated by the closed-loop route
//!   (`runtime::closed::noc`: its own loop equations, Newton assembly and `Φ_d` solves);
//! - Newton–Euler of every body with the joint reactions and efforts as Lagrange multipliers
//!   (`references::lagrange`), the platform's S joints replaced by the U joints of the 3-RUU, so
//!   that the reactions can hold the platform's orientation.
//!
//! Errors are relative, `‖a − b‖∞ / ‖b‖∞`.

use runtime::parallel::noc::{self, Plan};
use tests::pkm::{model, random_state, rel};
use tests::routes::Pair;

/// Random regular states per check.
const STATES: usize = 500;

fn joints_model() -> runtime::closed::ClosedModel {
    tests::routes::closed_data("delta_rl5_joints.toml")
}

/// The platform form and the joint-coordinate form agree at corresponding states: `q` by the
/// platform's inverse kinematics, the joint coordinates `x_J` by the closed route's assembly
/// from `q`, `q̇ = A v`, `q̈ = A a + Ȧ v` (`Ȧ v` the actuated rows of the literal route's
/// `L̇ u`, kinematics only). Inverse dynamics, actuator-space inertia `A⁻ᵀ I A⁻¹` against the
/// closed route's `I`, and forward dynamics (`q̈` of the closed route against `A u̇ + Ȧ v`).
#[test]
fn delta_in_joint_coordinates_matches_the_platform_form() {
    let pm = model("delta_rl5");
    let jm = joints_model();
    let pair = Pair::new(&pm, &jm);
    let pplan = &pair.task;
    let home = pm.home_x();
    let mut rng = tests::rng(0xde17a);
    let mut worst = [0.0f64; 3];
    for _ in 0..STATES {
        let (p, v, a) = random_state(pplan, &home, &mut rng, 0.0, 0.05 * pm.size());
        let (e, _) = pair.compare(&p, &v, &a, 10.0);
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
    }
    println!(
        "delta_rl5: platform form vs joint coordinates over {STATES} states, worst relative error (∞-norm): ID {:.1e}, A⁻ᵀIA⁻¹ vs I_J {:.1e}, FD {:.1e}",
        worst[0], worst[1], worst[2]
    );
    for w in worst {
        assert!(w <= 1e-12, "{worst:?}");
    }
}

/// The generated inverse dynamics against Newton–Euler with Lagrange multipliers, the platform's
/// orientation held by U joints at the rods' platform ends (axes `n = a × d` on the rod, the
/// motor axis `a` on the platform), its motion prescribed as `ω = 0`, `v`.
#[test]
fn delta_against_lagrange_multipliers() {
    use mechanisms::delta_rl5 as g;
    use references::lagrange::{self, CJointKind, Prescribed};
    let m = model("delta_rl5");
    let plan = Plan::new(&m).unwrap();
    let home = m.home_x();
    let mut rng = tests::rng(0x1a9de);
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
        "delta_rl5: generated vs Lagrange multipliers (3-RUU), worst relative error (∞-norm): {worst:.1e}"
    );
    assert!(worst <= 1e-10, "{worst:e}");
}

/// The legs' constraint couples over the Delta's reach (`Site::Constraint`, docs/method.md):
/// each parallelogram of ball–ball rods holds the platform by one couple, `a × d` (`a` the
/// motor axis, `d` the rod direction), normal to the parallelogram's plane; the three must
/// span. On a grid of platform positions (5 cm steps, `|x|, |y| ≤ 0.6 m`,
/// `z ∈ [−1.4, −0.6] m`), at every position the legs reach: the verdicts of
/// `inverse_dynamics`, runtime and generated alike, and the smallest couple pivot among the
/// positions that answer `Ok`. Measured (`--nocapture`): 8,769 positions, all `Ok`, smallest
/// pivot 0.292 (the test's threshold is 1e-4): no false alarm, and the Delta's other walks
/// (tests/tests/singularities.rs) keep their sites. (The couples would turn coplanar where, for
/// instance, all three rods hang vertical in their legs' radial planes: every `a × d` is then
/// horizontal.)
#[test]
fn delta_constraint_couples_over_the_reach() {
    use mechanisms::delta_rl5 as g;
    use std::collections::BTreeMap;
    let m = model("delta_rl5");
    let plan = Plan::new(&m).unwrap();
    let mut sites: BTreeMap<String, usize> = BTreeMap::new();
    let (mut reached, mut smallest) = (0usize, f64::INFINITY);
    let (u, ud) = ([0.3, -0.2, 0.1], [1.0, 0.5, -0.5]);
    for i in -12..=12 {
        for j in -12..=12 {
            for k in 0..=16 {
                let x = [0.05 * i as f64, 0.05 * j as f64, -0.6 - 0.05 * k as f64];
                let Ok((_, legs)) = noc::positions(&plan, &x) else {
                    continue;
                };
                reached += 1;
                let r = noc::inverse_dynamics(&plan, &x, &u, &ud);
                let gen_site =
                    g::inverse_dynamics(&x, &u, &ud).map_err(|e| format!("{:?}", e.site));
                let site = r.as_ref().map(|_| ()).map_err(|e| format!("{:?}", e.site));
                assert_eq!(site, gen_site.map(|_| ()), "{x:?}");
                *sites
                    .entry(site.err().unwrap_or_else(|| "Ok".into()))
                    .or_default() += 1;
                if r.is_ok() {
                    smallest = smallest.min(min_pivot(&noc::couple_pivots(&plan, &legs)));
                }
            }
        }
    }
    println!(
        "delta_rl5: {reached} reachable grid positions, inverse_dynamics verdicts {sites:?}; smallest couple pivot where Ok {smallest:.3}"
    );
    assert!(
        !sites.keys().any(|s| s.starts_with("Constraint")),
        "{sites:?}"
    );
    assert!(smallest > 100.0 * noc::CONSTRAINT_TOLERANCE, "{smallest:e}");
}

/// The Delta legs' generic route (taken when a leg joint has a drive: here damping on the
/// motors) forms each couple from the chain (`e₀ × (P − E)`, the crank axis and the rod from
/// the elbow's U centre, over the rod's length), the closed form from its rod direction
/// (`a × d`): the same couples, up to sign, at 100 random states.
#[test]
fn delta_generic_legs_have_the_closed_form_couples() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/delta_rl5.toml");
    let src = std::fs::read_to_string(&path).unwrap();
    let src = src
        .replacen("[platform]", "[scene]\nfriction = true\n\n[platform]", 1)
        .replace("actuated = true\n", "actuated = true\ndamping = 0.5\n");
    let (codegen::spec::Mechanism::Parallel(damped), _) =
        codegen::spec::load_mechanism(&path.to_string_lossy(), &src)
            .unwrap_or_else(|d| panic!("{d}"))
    else {
        panic!("not a parallel mechanism")
    };
    let generic = Plan::new(&damped).unwrap();
    assert!(
        generic.legs.iter().all(|l| l.delta.is_none()),
        "drives take the generic route"
    );
    let m = model("delta_rl5");
    let closed = Plan::new(&m).unwrap();
    assert!(closed.legs.iter().all(|l| l.delta.is_some()));
    let home = m.home_x();
    let mut rng = tests::rng(0xde1c);
    for _ in 0..100 {
        let (p, _, _) = random_state(&closed, &home, &mut rng, 0.0, 0.1 * m.size());
        let (_, gl) = noc::positions(&generic, &p).unwrap();
        let (_, cl) = noc::positions(&closed, &p).unwrap();
        let (g, c) = (
            noc::constraint_couples(&generic, &gl),
            noc::constraint_couples(&closed, &cl),
        );
        assert_eq!((g.len(), c.len()), (3, 3));
        for (g, c) in g.iter().zip(&c) {
            let dot: f64 = (0..3).map(|i| g[i] * c[i]).sum();
            let s = dot.signum();
            let off = (0..3).fold(0.0f64, |m, i| m.max((g[i] - s * c[i]).abs()));
            assert!(off < 1e-13, "{p:?}: {g:?} vs {c:?}");
        }
    }
}

/// The smallest pivot of the couples' LU, in magnitude.
fn min_pivot(pivots: &[f64]) -> f64 {
    pivots.iter().fold(f64::INFINITY, |m, p| m.min(p.abs()))
}
