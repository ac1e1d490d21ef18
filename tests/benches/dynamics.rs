//! Generated dynamics vs the runtime oracles, per call.
//!
//! For the PUMA 560 (`mechanisms::puma560`) and the 7-joint iiwa transcription
//! (`mechanisms::chain7`): inverse dynamics and mass matrix, each generated / runtime NOC
//! (`runtime::noc`, nalgebra, literal `TᵀMT`) / runtime Newton–Euler (`runtime::rnea`: RNEA and
//! CRBA in spatial algebra); forward dynamics generated / runtime NOC (there is no RNEA forward
//! dynamics). Inputs are fixed pseudo-random states behind `black_box`.
//!
//! For the Gough–Stewart platform and the Agile Eye (parallel): inverse and forward dynamics,
//! generated vs the runtime evaluator `runtime::parallel::noc`.
//!
//! ```text
//! cargo bench -p tests --features figures --bench dynamics
//! ```

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use runtime::model::Model;
use tests::{random_state, rel_err, rng};

/// One bundled mechanism: its spec (for the runtime model) and its generated module.
macro_rules! bench_mechanism {
    ($fn_name:ident, $module:ident, $spec_file:literal, $seed:expr) => {
        fn $fn_name(c: &mut Criterion) {
            use mechanisms::$module as generated;
            const N: usize = generated::DOF;
            let name = stringify!($module);
            let src = include_str!(concat!("../../mechanisms/specs/", $spec_file));
            let (model, _warnings): (Model, _) = codegen::spec::load_tree($spec_file, src)
                .unwrap_or_else(|d| panic!("{}", d.render()));
            assert_eq!(model.dof(), N);

            let (q, qd, qdd) = random_state(&mut rng($seed), N);
            let q: [f64; N] = q.try_into().unwrap();
            let qd: [f64; N] = qd.try_into().unwrap();
            let qdd: [f64; N] = qdd.try_into().unwrap();
            let tau = generated::inverse_dynamics(&q, &qd, &qdd);

            // Like-for-like: all routes agree at the benchmarked state.
            let noc = runtime::noc::inverse_dynamics(&model, &q, &qd, &qdd);
            let rnea = runtime::rnea::inverse_dynamics(&model, &q, &qd, &qdd);
            assert!(rel_err(&tau, noc.as_slice()) < 1e-9, "{name}: ID vs NOC");
            assert!(rel_err(&tau, rnea.as_slice()) < 1e-9, "{name}: ID vs RNEA");
            let fd = generated::forward_dynamics(&q, &qd, &tau).expect("regular state");
            assert!(rel_err(&fd, &qdd) < 1e-6, "{name}: FD(ID(q̈)) vs q̈");

            let mut g = c.benchmark_group(format!("{name}/inverse_dynamics"));
            g.bench_function("generated", |b| {
                b.iter(|| {
                    generated::inverse_dynamics(black_box(&q), black_box(&qd), black_box(&qdd))
                })
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| {
                    runtime::noc::inverse_dynamics(
                        black_box(&model),
                        black_box(&q),
                        black_box(&qd),
                        black_box(&qdd),
                    )
                })
            });
            g.bench_function("runtime_rnea", |b| {
                b.iter(|| {
                    runtime::rnea::inverse_dynamics(
                        black_box(&model),
                        black_box(&q),
                        black_box(&qd),
                        black_box(&qdd),
                    )
                })
            });
            g.finish();

            let mut g = c.benchmark_group(format!("{name}/mass_matrix"));
            g.bench_function("generated", |b| {
                b.iter(|| generated::mass_matrix(black_box(&q)))
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| runtime::noc::mass_matrix(black_box(&model), black_box(&q)))
            });
            g.bench_function("runtime_rnea", |b| {
                b.iter(|| runtime::rnea::mass_matrix(black_box(&model), black_box(&q)))
            });
            g.finish();

            let mut g = c.benchmark_group(format!("{name}/forward_dynamics"));
            g.bench_function("generated", |b| {
                b.iter(|| {
                    generated::forward_dynamics(black_box(&q), black_box(&qd), black_box(&tau))
                })
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| {
                    runtime::noc::forward_dynamics(
                        black_box(&model),
                        black_box(&q),
                        black_box(&qd),
                        black_box(&tau),
                    )
                })
            });
            g.finish();
        }
    };
}

bench_mechanism!(puma560, puma560, "puma560.toml", 560);
bench_mechanism!(chain7, chain7, "chain7.toml", 7);

/// A bundled parallel mechanism: generated vs the runtime evaluators, for inverse and forward
/// dynamics: `runtime_noc` is `runtime::parallel::noc` (the association the generator expands,
/// leg by leg, in `f64` with `Vec`s), `runtime_literal` is `runtime::parallel::literal` (the
/// lecture's dense `TᵀMT`, `Tᵀ(MṪ + WMT)` and `A⁻ᵀ`, the parallel counterpart of the trees'
/// literal NOC).
macro_rules! bench_parallel {
    ($fn_name:ident, $module:ident) => {
        fn $fn_name(c: &mut Criterion) {
            use mechanisms::$module as generated;
            use runtime::parallel::literal;
            use runtime::parallel::noc::{self, Plan};
            const NX: usize = generated::NX;
            const N: usize = generated::DOF;
            let name = stringify!($module);
            let model = tests::pkm::model(name);
            let plan = Plan::new(&model).expect("valid model");
            let home = tests::pkm::home_x(&model);
            let (angle, reach) = match model.motion {
                runtime::parallel::PlatformMotion::Pose => (0.1, 0.02 * model.size()),
                runtime::parallel::PlatformMotion::Orientation { .. } => (0.3, 0.0),
                runtime::parallel::PlatformMotion::PlanarPoint { .. } => (0.0, 0.05),
                runtime::parallel::PlatformMotion::Translation { .. } => (0.0, 0.02 * model.size()),
                runtime::parallel::PlatformMotion::PlanarPose { .. }
                | runtime::parallel::PlatformMotion::HeaveTilt { .. }
                | runtime::parallel::PlatformMotion::Schoenflies { .. } => {
                    (0.1, 0.02 * model.size())
                }
            };
            let (x, u, ud) =
                tests::pkm::random_state(&plan, &home, &mut rng(N as u64), angle, reach);
            let x: [f64; NX] = x.try_into().unwrap();
            let u: [f64; N] = u.try_into().unwrap();
            let ud: [f64; N] = ud.try_into().unwrap();
            let tau = generated::inverse_dynamics(&x, &u, &ud).expect("regular state");
            let reference = noc::inverse_dynamics(&plan, &x, &u, &ud).expect("regular state");
            assert!(rel_err(&tau, &reference) < 1e-9, "{name}: ID vs runtime");

            let mut g = c.benchmark_group(format!("{name}/inverse_dynamics"));
            g.bench_function("generated", |b| {
                b.iter(|| generated::inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| {
                    noc::inverse_dynamics(
                        black_box(&plan),
                        black_box(&x),
                        black_box(&u),
                        black_box(&ud),
                    )
                })
            });
            // (The literal route does not take a Schönflies platform: its `Err` is not timed.)
            let literal_ok = literal::inverse_dynamics(&plan, &x, &u, &ud).is_ok();
            if literal_ok {
                g.bench_function("runtime_literal", |b| {
                    b.iter(|| {
                        literal::inverse_dynamics(
                            black_box(&plan),
                            black_box(&x),
                            black_box(&u),
                            black_box(&ud),
                        )
                    })
                });
            }
            g.finish();

            let mut g = c.benchmark_group(format!("{name}/forward_dynamics"));
            g.bench_function("generated", |b| {
                b.iter(|| {
                    generated::forward_dynamics(black_box(&x), black_box(&u), black_box(&tau))
                })
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| {
                    noc::forward_dynamics(
                        black_box(&plan),
                        black_box(&x),
                        black_box(&u),
                        black_box(&tau),
                    )
                })
            });
            if literal_ok {
                g.bench_function("runtime_literal", |b| {
                    b.iter(|| {
                        literal::forward_dynamics(
                            black_box(&plan),
                            black_box(&x),
                            black_box(&u),
                            black_box(&tau),
                        )
                    })
                });
            }
            g.finish();
        }
    };
}

bench_parallel!(gough_stewart, gough_stewart);
bench_parallel!(agile_eye, agile_eye);
bench_parallel!(delta_rl5, delta_rl5);
bench_parallel!(planar_3rrr, planar_3rrr);
bench_parallel!(tsai_3upu, tsai_3upu);
bench_parallel!(delta4_rl5, delta4_rl5);

/// A bundled closed-loop mechanism in joint coordinates: generated vs the runtime evaluator
/// (`runtime::closed::noc`) vs the independent Newton–Euler + Lagrange-multiplier route (dense
/// SVD over every body's twist), inverse dynamics; and generated vs runtime forward dynamics.
macro_rules! bench_closed {
    ($fn_name:ident, $module:ident) => {
        fn $fn_name(c: &mut Criterion) {
            use mechanisms::$module as generated;
            use runtime::closed::noc::{self, Plan};
            const NX: usize = generated::NX;
            const N: usize = generated::DOF;
            let name = stringify!($module);
            let model = tests::closed::model(name);
            let plan = Plan::new(&model).expect("valid model");
            let (x, u, ud) =
                tests::closed::random_state(&plan, &mut rng(N as u64), tests::closed::reach(name));
            let x: [f64; NX] = x.try_into().unwrap();
            let u: [f64; N] = u.try_into().unwrap();
            let ud: [f64; N] = ud.try_into().unwrap();
            let tau = generated::inverse_dynamics(&x, &u, &ud).expect("regular state");
            let reference = noc::inverse_dynamics(&plan, &x, &u, &ud).expect("regular state");
            assert!(rel_err(&tau, &reference) < 1e-9, "{name}: ID vs runtime");
            let sys = references::lagrange::from_closed(&model, &x);

            let mut g = c.benchmark_group(format!("{name}/inverse_dynamics"));
            g.bench_function("generated", |b| {
                b.iter(|| generated::inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| {
                    noc::inverse_dynamics(
                        black_box(&plan),
                        black_box(&x),
                        black_box(&u),
                        black_box(&ud),
                    )
                })
            });
            g.bench_function("lagrange_multipliers", |b| {
                b.iter(|| {
                    references::lagrange::inverse_dynamics(
                        black_box(&sys),
                        &references::lagrange::Prescribed::ActuatedJoints,
                        black_box(&u),
                        black_box(&ud),
                    )
                })
            });
            g.finish();

            let mut g = c.benchmark_group(format!("{name}/forward_dynamics"));
            g.bench_function("generated", |b| {
                b.iter(|| {
                    generated::forward_dynamics(black_box(&x), black_box(&u), black_box(&tau))
                })
            });
            g.bench_function("runtime_noc", |b| {
                b.iter(|| {
                    noc::forward_dynamics(
                        black_box(&plan),
                        black_box(&x),
                        black_box(&u),
                        black_box(&tau),
                    )
                })
            });
            g.finish();
        }
    };
}

bench_closed!(five_bar_joints, five_bar_joints);
bench_closed!(spherical_five_bar, spherical_five_bar);

fn config() -> Criterion {
    Criterion::default()
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(500))
        .sample_size(30)
}

/// One robot's inverse dynamics in task coordinates (inverse kinematics included) against the
/// same robot in joint coordinates (the closed-loop route), both generated, at the same
/// configuration (`$x`; the joint form assembled at its actuated coordinates) and rates (the
/// platform speeds `$u`; the actuator rates they imply); the accelerations are arbitrary, the
/// same numbers for both (the cost does not depend on them). `$label` names the task side
/// (the platform's coordinates, or task coordinates) as the figures in docs/parallel.md do.
macro_rules! task_vs_joints {
    ($name:ident, $task:path, $joints:path, $group:literal, $label:literal, $x:expr, $u:expr, $ud:expr) => {
        fn $name(c: &mut Criterion) {
            use $joints as joints;
            use $task as task;
            let x = $x;
            let (u, ud) = ($u, $ud);
            let q = task::inverse_kinematics(&x).expect("in reach");
            let qd = task::actuator_rates(&x, &u).expect("regular");
            let xj = joints::forward_kinematics(&q, &joints::HOME).expect("assembles");
            let tau = task::inverse_dynamics(&x, &u, &ud).expect("regular");
            let tau_j = joints::inverse_dynamics(&xj, &qd, &ud).expect("regular");
            assert!(tau.iter().chain(&tau_j).all(|v| v.is_finite()));
            let mut g = c.benchmark_group($group);
            g.bench_function($label, |b| {
                b.iter(|| task::inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
            });
            g.bench_function("joint_coordinates", |b| {
                b.iter(|| joints::inverse_dynamics(black_box(&xj), black_box(&qd), black_box(&ud)))
            });
            g.finish();
        }
    };
}

// The Delta at home, in its platform coordinates.
task_vs_joints!(
    delta_task_vs_joints,
    mechanisms::delta_rl5,
    tests::variants::delta_joints,
    "delta_rl5/inverse_dynamics_task_vs_joints",
    "platform_coordinates",
    mechanisms::delta_rl5::HOME,
    [0.3, -0.2, 0.1],
    [1.0, 0.5, -2.0]
);
// The planar 3-RRR at home, `[px, py, φ]`.
task_vs_joints!(
    planar3_task_vs_joints,
    mechanisms::planar_3rrr,
    tests::variants::planar3_joints,
    "planar_3rrr/inverse_dynamics_task_vs_joints",
    "task_coordinates",
    mechanisms::planar_3rrr::HOME,
    [0.3, -0.2, 0.5],
    [1.0, 0.5, -2.0]
);
// Tsai's 3-UPU at home, in its platform coordinates.
task_vs_joints!(
    upu_task_vs_joints,
    mechanisms::tsai_3upu,
    tests::variants::upu_joints,
    "tsai_3upu/inverse_dynamics_task_vs_joints",
    "platform_coordinates",
    mechanisms::tsai_3upu::HOME,
    [0.3, -0.2, 0.1],
    [1.0, 0.5, -2.0]
);
// The 3-PRS tripod at a tilted pose, `[pz, α, β]` (the parasitic motion included), against the
// bundled `tripod_3prs` in joint coordinates.
task_vs_joints!(
    prs_task_vs_joints,
    tests::variants::tripod_task,
    mechanisms::tripod_3prs,
    "tripod_3prs/inverse_dynamics_task_vs_joints",
    "task_coordinates",
    {
        let h = tests::variants::tripod_task::HOME;
        [h[0] + 0.01, 0.1, -0.05]
    },
    [0.03, -0.2, 0.5],
    [1.0, 0.5, -2.0]
);

// The 4-axis Delta at home, the tool turned by 0.3 rad, `[px, py, pz, θ]`.
task_vs_joints!(
    delta4_task_vs_joints,
    mechanisms::delta4_rl5,
    tests::variants::delta4_joints,
    "delta4_rl5/inverse_dynamics_task_vs_joints",
    "task_coordinates",
    {
        let h = mechanisms::delta4_rl5::HOME;
        [h[0], h[1], h[2], 0.3]
    },
    [0.3, -0.2, 0.1, 2.0],
    [1.0, 0.5, -2.0, 5.0]
);

/// A state near home: the actuated coordinates moved by 0.01, speeds and rates fixed numbers.
fn near_home<M: runtime::Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
) -> ([f64; NX], [f64; N], [f64; N]) {
    let q0 = m.inverse_kinematics(&M::HOME).expect("home is regular");
    let q: [f64; N] = core::array::from_fn(|i| q0[i] + 0.01 * (i as f64 + 1.0));
    let x = m.forward_kinematics(&q, &M::HOME).expect("assembles");
    let u: [f64; N] = core::array::from_fn(|i| 0.3 - 0.1 * i as f64);
    let ud: [f64; N] = core::array::from_fn(|i| 1.0 - 0.4 * i as f64);
    (x, u, ud)
}

/// The derivative functions beside `inverse_dynamics`, generated, through `runtime::Dynamics`
/// (the module's own functions, forwarded): `{name}/derivatives/{function}` at a state near
/// home (the actuated coordinates moved by 0.01, speeds and rates fixed numbers).
fn derivatives_of<M: runtime::Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    c: &mut Criterion,
    m: &M,
) {
    let (x, u, ud) = near_home(m);
    let tau = m.inverse_dynamics(&x, &u, &ud).expect("regular");
    assert!(
        m.inverse_dynamics_derivatives(&x, &u, &ud)
            .is_some_and(|r| r.is_ok())
    );
    assert!(
        m.forward_dynamics_derivatives(&x, &u, &tau)
            .is_some_and(|r| r.is_ok())
    );
    let mut g = c.benchmark_group(format!("{}/derivatives", M::NAME));
    g.bench_function("inverse_dynamics", |b| {
        b.iter(|| m.inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
    });
    g.bench_function("inverse_dynamics_derivatives", |b| {
        b.iter(|| m.inverse_dynamics_derivatives(black_box(&x), black_box(&u), black_box(&ud)))
    });
    g.bench_function("forward_dynamics_derivatives", |b| {
        b.iter(|| m.forward_dynamics_derivatives(black_box(&x), black_box(&u), black_box(&tau)))
    });
    g.finish();
}

/// The derivatives of the issue's five: two arms, a 6-DOF platform, a spherical platform and
/// Andrews' squeezer (a closed loop).
fn derivatives(c: &mut Criterion) {
    derivatives_of(c, &mechanisms::puma560::Module);
    derivatives_of(c, &mechanisms::chain7::Module);
    derivatives_of(c, &mechanisms::gough_stewart::Module);
    derivatives_of(c, &mechanisms::agile_eye::Module);
    derivatives_of(c, &mechanisms::andrews_squeezer::Module);
}

/// `regressor` beside `inverse_dynamics` (`{name}/regressor/{function}`), at the derivative
/// benches' state near home; a tree's `regressor` returns the array, the others a `Result`.
macro_rules! regressor_benches {
    ($($m:ident),* $(,)?) => {
        fn regressor(c: &mut Criterion) {
            use runtime::Dynamics;
            $({
                use mechanisms::$m as g;
                let m = g::Module;
                let (x, u, ud) = near_home(&m);
                let mut grp = c.benchmark_group(format!("{}/regressor", stringify!($m)));
                grp.bench_function("inverse_dynamics", |b| {
                    b.iter(|| m.inverse_dynamics(black_box(&x), black_box(&u), black_box(&ud)))
                });
                grp.bench_function("regressor", |b| {
                    b.iter(|| g::regressor(black_box(&x), black_box(&u), black_box(&ud)))
                });
                grp.finish();
            })*
        }
    };
}

regressor_benches!(
    puma560,
    chain7,
    gough_stewart,
    delta_rl5,
    agile_eye,
    andrews_squeezer
);

criterion_group! {
    name = benches;
    config = config();
    targets = puma560, chain7, gough_stewart, agile_eye, delta_rl5, delta_task_vs_joints, planar_3rrr, planar3_task_vs_joints, tsai_3upu, upu_task_vs_joints, prs_task_vs_joints, delta4_rl5, delta4_task_vs_joints, five_bar_joints, spherical_five_bar, derivatives, regressor
}
criterion_main!(benches);
