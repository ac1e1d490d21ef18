//! The parallel-manipulator evaluator on a Gough–Stewart platform built by hand (Tsai 2000's
//! geometry, see docs/method.md, "Test cases from the literature"): kinematic closure, rates against
//! finite differences, symmetry and definiteness of the inertia, power balance, forward
//! kinematics and forward dynamics round trips.

#![allow(clippy::needless_range_loop)]

use runtime::model::{Body, Joint, JointKind, Transform};
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{Leg, LegEnd, ParallelModel, PlatformMotion};

fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn diag(a: f64) -> [[f64; 3]; 3] {
    [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a]]
}
fn massless(name: &str) -> Body {
    Body {
        name: name.into(),
        mass: 0.0,
        com: [0.0; 3],
        inertia: [[0.0; 3]; 3],
    }
}

pub fn gough_stewart() -> ParallelModel {
    gough_stewart_at_yaw(0.0)
}

/// The same platform assembled at home with the platform turned by `yaw` about the vertical.
pub fn gough_stewart_at_yaw(yaw: f64) -> ParallelModel {
    let (sy, cy) = yaw.sin_cos();
    let turn = [[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]];
    let b = [
        [-2.12, 1.374, 0.0],
        [-2.38, 1.224, 0.0],
        [-2.38, -1.224, 0.0],
        [-2.12, -1.374, 0.0],
        [0.0, -0.15, 0.0],
        [0.0, 0.15, 0.0],
    ];
    let p = [
        [0.17, 0.595, -0.4],
        [-0.6, 0.15, -0.4],
        [-0.6, -0.15, -0.4],
        [0.17, -0.595, -0.4],
        [0.43, -0.445, -0.4],
        [0.43, 0.445, -0.4],
    ];
    let home = [-1.5, 0.0, 1.0];
    let mut legs = Vec::new();
    for i in 0..6 {
        let pr = runtime::model::mat_vec(&turn, &p[i]);
        let a = [home[0] + pr[0], home[1] + pr[1], home[2] + pr[2]];
        let d: [f64; 3] = [a[0] - b[i][0], a[1] - b[i][1], a[2] - b[i][2]];
        let len: f64 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let len = len.sqrt();
        let z = unit(d);
        let x = unit(cross([0.0, 0.0, 1.0], z));
        let y = cross(z, x);
        let rot = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]];
        let j = |name: String, kind, parent, origin, axis| Joint {
            name,
            kind,
            parent,
            origin,
            axis,
            drive: Default::default(),
        };
        legs.push(Leg {
            name: format!("s{i}"),
            joints: vec![
                j(
                    format!("u{i}_1"),
                    JointKind::Revolute,
                    None,
                    Transform {
                        rotation: rot,
                        translation: b[i],
                    },
                    [1.0, 0.0, 0.0],
                ),
                j(
                    format!("u{i}_2"),
                    JointKind::Revolute,
                    Some(0),
                    Transform::IDENTITY,
                    [0.0, 1.0, 0.0],
                ),
                j(
                    format!("p{i}"),
                    JointKind::Prismatic,
                    Some(1),
                    Transform::IDENTITY,
                    [0.0, 0.0, 1.0],
                ),
            ],
            bodies: vec![
                massless("cross"),
                Body {
                    name: format!("cylinder{i}"),
                    mass: 0.1,
                    com: [0.0, 0.0, 0.5],
                    inertia: diag(1.0 / 160.0),
                },
                Body {
                    name: format!("piston{i}"),
                    mass: 0.1,
                    com: [0.0, 0.0, len - 0.5],
                    inertia: [
                        [1.0 / 160.0, 0.0, 0.0],
                        [0.0, 1.0 / 150.0, 0.0],
                        [0.0, 0.0, 1.0 / 400.0],
                    ],
                },
            ],
            actuated: 2,
            actuated_name: format!("p{i}"),
            actuated_home: 0.0,
            end: LegEnd::Spherical {
                on_leg: [0.0, 0.0, len],
                on_platform: p[i],
            },
        });
    }
    ParallelModel {
        name: "gs".into(),
        gravity: [0.0, 0.0, -9.81],
        motion: PlatformMotion::Pose,
        platform: Body {
            name: "platform".into(),
            mass: 1.5,
            com: [0.01, -0.02, 0.03],
            inertia: [[0.08, 0.001, 0.0], [0.001, 0.09, 0.002], [0.0, 0.002, 0.1]],
        },
        home: Transform {
            rotation: turn,
            translation: home,
        },
        legs,
    }
}

/// A pose near home: small rotation vector `r`, offset `dp`.
fn pose(r: [f64; 3], dp: [f64; 3]) -> Vec<f64> {
    let x0 = vec![-1.5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let mut x = runtime::parallel::noc::retract(
        PlatformMotion::Pose,
        &x0,
        &[r[0], r[1], r[2], dp[0], dp[1], dp[2]],
    );
    x.truncate(7);
    x
}

fn lcg(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

#[test]
fn home_is_zero_and_loops_close() {
    let m = gough_stewart();
    let plan = Plan::new(&m).expect("valid");
    let x = pose([0.0; 3], [0.0; 3]);
    let q = noc::leg_joint_positions(&plan, &x).unwrap();
    for leg in &q {
        for v in leg {
            assert!(v.abs() < 1e-14, "{q:?}");
        }
    }
}

#[test]
fn rates_match_finite_differences() {
    let m = gough_stewart();
    let plan = Plan::new(&m).unwrap();
    let mut s = 7u64;
    for _ in 0..20 {
        let x = pose(
            [0.2 * lcg(&mut s), 0.2 * lcg(&mut s), 0.3 * lcg(&mut s)],
            [0.2 * lcg(&mut s), 0.2 * lcg(&mut s), 0.2 * lcg(&mut s)],
        );
        let u: Vec<f64> = (0..6).map(|_| lcg(&mut s)).collect();
        let qd = noc::actuator_rates(&plan, &x, &u).unwrap();
        let h = 1e-6;
        let xp = runtime::parallel::noc::retract(
            PlatformMotion::Pose,
            &x,
            &u.iter().map(|v| v * h).collect::<Vec<_>>(),
        );
        let xm = runtime::parallel::noc::retract(
            PlatformMotion::Pose,
            &x,
            &u.iter().map(|v| -v * h).collect::<Vec<_>>(),
        );
        let qp = noc::inverse_kinematics(&plan, &xp).unwrap();
        let qm = noc::inverse_kinematics(&plan, &xm).unwrap();
        for i in 0..6 {
            let fd = (qp[i] - qm[i]) / (2.0 * h);
            assert!((fd - qd[i]).abs() < 1e-6, "{i}: {fd} vs {}", qd[i]);
        }
    }
}

#[test]
fn inertia_spd_and_power_balance() {
    let mut m = gough_stewart();
    m.gravity = [0.0; 3];
    let plan = Plan::new(&m).unwrap();
    let mut s = 11u64;
    for _ in 0..20 {
        let x = pose(
            [0.2 * lcg(&mut s), 0.2 * lcg(&mut s), 0.3 * lcg(&mut s)],
            [0.2 * lcg(&mut s), 0.2 * lcg(&mut s), 0.2 * lcg(&mut s)],
        );
        let u: Vec<f64> = (0..6).map(|_| lcg(&mut s)).collect();
        let ud: Vec<f64> = (0..6).map(|_| lcg(&mut s)).collect();
        let i = noc::mass_matrix(&plan, &x).unwrap();
        // Two routes to I: per-leg end-point inertias J⁻ᵀ M_J J⁻¹ vs inverse-dynamics columns.
        let (pl, legs) = noc::kinematics(&plan, &x).unwrap();
        let by_columns = noc::generalized_inertia_by_columns(&plan, &pl, &legs);
        for r in 0..6 {
            for c in 0..6 {
                assert_eq!(i[r][c], i[c][r]);
                assert!(
                    (i[r][c] - by_columns[r][c]).abs() < 1e-12 * (1.0 + i[r][r].abs()),
                    "I[{r}][{c}] {} vs {}",
                    i[r][c],
                    by_columns[r][c]
                );
            }
        }
        // d/dt (½ uᵀ I u) along x(t) = x ⊕ t u, u(t) = u + t ud equals uᵀ f.
        let ke = |t: f64| {
            let xt = runtime::parallel::noc::retract(
                PlatformMotion::Pose,
                &x,
                &u.iter().map(|v| v * t).collect::<Vec<_>>(),
            );
            let ut: Vec<f64> = u.iter().zip(&ud).map(|(a, b)| a + t * b).collect();
            let i = noc::mass_matrix(&plan, &xt).unwrap();
            let mut e = 0.0;
            for r in 0..6 {
                for c in 0..6 {
                    e += 0.5 * ut[r] * i[r][c] * ut[c];
                }
            }
            e
        };
        let h = 1e-5;
        let dke = (ke(h) - ke(-h)) / (2.0 * h);
        let f = noc::generalized_effort(&plan, &x, &u, &ud).unwrap();
        let p: f64 = f.iter().zip(&u).map(|(a, b)| a * b).sum();
        assert!((dke - p).abs() < 1e-6 * (1.0 + p.abs()), "{dke} vs {p}");
        // Power of the actuators equals the same.
        let tau = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        let qd = noc::actuator_rates(&plan, &x, &u).unwrap();
        let pa: f64 = tau.iter().zip(&qd).map(|(a, b)| a * b).sum();
        assert!((pa - p).abs() < 1e-9 * (1.0 + p.abs()), "{pa} vs {p}");
        // Forward dynamics inverts inverse dynamics.
        let udd = noc::forward_dynamics(&plan, &x, &u, &tau).unwrap();
        for k in 0..6 {
            assert!((udd[k] - ud[k]).abs() < 1e-9, "{udd:?} vs {ud:?}");
        }
        // Forward kinematics from a perturbed guess.
        let q = noc::inverse_kinematics(&plan, &x).unwrap();
        let guess = runtime::parallel::noc::retract(
            PlatformMotion::Pose,
            &x,
            &[0.05, -0.03, 0.04, 0.02, 0.03, -0.01],
        );
        let xf = noc::forward_kinematics(&plan, &q, &guess).unwrap();
        for k in 0..7 {
            assert!((xf[k] - x[k]).abs() < 1e-9, "{xf:?} vs {x:?}");
        }
    }
}

/// A platform assembled at its parallel singularity (90° yaw, Fichter 1986) is rejected when it
/// is prepared: the constraint Jacobian must have full rank at home.
#[test]
fn singular_home_is_rejected() {
    let e = Plan::new(&gough_stewart_at_yaw(core::f64::consts::FRAC_PI_2)).unwrap_err();
    assert!(e.contains("singular at its home pose"), "{e}");
    assert!(Plan::new(&gough_stewart_at_yaw(0.3)).is_ok());
}

/// The closed-form UPS leg (`noc::UpsPlan`) against the generic route (chain recursion, adjugate
/// inverse of `J_J`): the same generalized force, mass matrix and actuation matrix, for the platform above,
/// for one with off-axis mass centres and full inertia matrices, and for U joints whose axes
/// are swapped (the other branch of the leg frame, `d < 0`).
#[test]
fn closed_form_ups_leg_matches_generic_route() {
    let plain = gough_stewart();
    let mut skew = gough_stewart();
    for leg in skew.legs.iter_mut() {
        leg.bodies[1].com = [0.013, -0.021, 0.47];
        leg.bodies[1].inertia = [
            [0.006, 0.0004, -0.0003],
            [0.0004, 0.007, 0.0002],
            [-0.0003, 0.0002, 0.002],
        ];
        leg.bodies[2].com[0] = -0.017;
        leg.bodies[2].com[1] = 0.008;
        leg.bodies[2].inertia[0][2] = 0.0005;
        leg.bodies[2].inertia[2][0] = 0.0005;
    }
    let mut swapped = skew.clone();
    for leg in swapped.legs.iter_mut() {
        leg.joints[0].axis = [0.0, 1.0, 0.0];
        leg.joints[1].axis = [1.0, 0.0, 0.0];
    }
    for m in [plain, skew, swapped] {
        let plan = Plan::new(&m).unwrap();
        assert!(plan.legs.iter().all(|l| l.ups.is_some()));
        let mut generic = plan.clone();
        for l in generic.legs.iter_mut() {
            l.ups = None;
        }
        let mut s = 5u64;
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            let x = pose(
                [0.2 * lcg(&mut s), 0.2 * lcg(&mut s), 0.3 * lcg(&mut s)],
                [0.2 * lcg(&mut s), 0.2 * lcg(&mut s), 0.2 * lcg(&mut s)],
            );
            let u: Vec<f64> = (0..6).map(|_| lcg(&mut s)).collect();
            let ud: Vec<f64> = (0..6).map(|_| lcg(&mut s)).collect();
            let a = noc::generalized_effort(&plan, &x, &u, &ud).unwrap();
            let b = noc::generalized_effort(&generic, &x, &u, &ud).unwrap();
            let big = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for k in 0..6 {
                worst = worst.max((a[k] - b[k]).abs() / big);
            }
            // The mass matrix: the closed-form end-point inertia of each leg.
            let ma = noc::mass_matrix(&plan, &x).unwrap();
            let mb = noc::mass_matrix(&generic, &x).unwrap();
            let big = mb.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for r in 0..6 {
                for c in 0..6 {
                    worst = worst.max((ma[r][c] - mb[r][c]).abs() / big);
                }
            }
            let aa = noc::actuation(&plan, &x).unwrap();
            let ab = noc::actuation(&generic, &x).unwrap();
            for r in 0..6 {
                for c in 0..6 {
                    worst = worst.max((aa[r][c] - ab[r][c]).abs());
                }
            }
        }
        println!("closed form vs generic: worst {worst:.1e}");
        assert!(worst < 1e-13, "{}: {worst:e}", m.name);
    }
}
