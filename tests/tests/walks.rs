//! Walks toward the singularities of every bundled closed loop and parallel mechanism: at every
//! step each generated function and the runtime's `f64` function agree on `Ok` versus `Err`,
//! and on the `Site` of an `Err`.
//!
//! Closed loops (joint coordinates), two kinds:
//! - **Constraint** (`Φ_d` singular: the independent coordinates stop determining the others).
//!   Each independent coordinate is walked from home both ways, the loops closed at each step
//!   by the runtime's `forward_kinematics` from the last state, until assembly fails (a fold
//!   of the loop equations) or a full turn; the fold is then bracketed by bisection and
//!   approached in geometrically shrinking steps (1e-1 … 1e-13 of the step), where the
//!   condition of `Φ_d` grows without bound.
//! - **Closure** (`x` does not close the loops): a dependent coordinate moved off an assembled
//!   state by 1e-13 … 1e-1.
//!
//! Parallel mechanisms: the walks of `singularities.rs` (a yaw to 90° and a descent to the base
//! plane for the hexapods, the Agile Eye's leg and parallel singularities, the planar five-bar's
//! workspace boundary), with every public function compared.

use runtime::closed::noc::{self as cnoc, Plan as ClosedPlan};
use runtime::scalar::Singular;

/// `Ok` or the `Debug` text of the `Err`'s site.
type Verdict = Result<(), String>;

fn verdict<T>(r: &Result<T, Singular>) -> Verdict {
    r.as_ref().map(|_| ()).map_err(|e| format!("{:?}", e.site))
}

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut a = [0.0; N];
    a.copy_from_slice(v);
    a
}

/// The verdicts of a closed-loop module's functions at `(x, u, ud)`: (name, generated).
type ClosedRoutes = fn(&[f64], &[f64], &[f64]) -> Vec<(&'static str, Verdict)>;

macro_rules! closed_routes {
    ($($m:ident),*) => {
        fn closed_generated(name: &str) -> ClosedRoutes {
            match name {
                $(stringify!($m) => |x, u, ud| {
                    use mechanisms::$m as g;
                    let v = |r: Result<(), g::Singular>| r.map_err(|e| format!("{:?}", e.site));
                    let (x, u, ud) = (arr(x), arr(u), arr(ud));
                    vec![
                        ("joint_rates", v(g::joint_rates(&x, &u).map(|_| ()))),
                        ("inverse_dynamics", v(g::inverse_dynamics(&x, &u, &ud).map(|_| ()))),
                        ("mass_matrix", v(g::mass_matrix(&x).map(|_| ()))),
                        ("forward_dynamics", v(g::forward_dynamics(&x, &u, &ud).map(|_| ()))),
                    ]
                },)*
                _ => panic!("no generated module {name}"),
            }
        }
    };
}
closed_routes!(
    four_bar,
    five_bar_joints,
    spherical_five_bar,
    bricard,
    n_four_bar,
    tripod_3prs,
    andrews_squeezer
);

fn closed_runtime(plan: &ClosedPlan, x: &[f64], u: &[f64], ud: &[f64]) -> Vec<Verdict> {
    vec![
        verdict(&cnoc::joint_rates(plan, x, u)),
        verdict(&cnoc::inverse_dynamics(plan, x, u, ud)),
        verdict(&cnoc::mass_matrix(plan, x)),
        verdict(&cnoc::forward_dynamics(plan, x, u, ud)),
    ]
}

/// Compares every function at `x`; returns the runtime's verdicts. Disagreements go to `bad`.
fn compare_closed(
    name: &str,
    plan: &ClosedPlan,
    x: &[f64],
    what: &str,
    bad: &mut Vec<String>,
) -> Vec<Verdict> {
    let d = plan.dof();
    let u: Vec<f64> = (0..d).map(|k| 0.3 + 0.2 * k as f64).collect();
    let ud: Vec<f64> = (0..d).map(|k| -0.5 + 0.1 * k as f64).collect();
    let rt = closed_runtime(plan, x, &u, &ud);
    let generated = closed_generated(name)(x, &u, &ud);
    for ((f, g), r) in generated.iter().zip(&rt) {
        if g != r {
            bad.push(format!(
                "{name} {f} at {what}: generated {g:?}, runtime {r:?}"
            ));
        }
    }
    rt
}

/// Walks of one closed loop; returns the sites the runtime reported.
fn walk_closed(name: &str, bad: &mut Vec<String>) -> Vec<String> {
    let model = tests::closed::model(name);
    let plan = ClosedPlan::new(&model).unwrap();
    let home = vec![0.0; plan.nx()];
    let mut sites = Vec::new();
    let mut note = |v: &[Verdict]| {
        for e in v.iter().filter_map(|r| r.as_ref().err()) {
            if !sites.contains(e) {
                sites.push(e.clone());
            }
        }
    };
    // Toward a fold of the loop equations.
    for k in 0..plan.dof() {
        let j = plan.independent[k];
        let prismatic = model.tree.joints[j].kind == runtime::model::JointKind::Prismatic;
        let h = if prismatic { 0.02 * plan.size } else { 0.05 };
        let steps = if prismatic { 50 } else { 126 };
        for sign in [1.0, -1.0] {
            let xi_at = |t: f64| -> Vec<f64> {
                let mut xi: Vec<f64> = plan.independent.iter().map(|&j| home[j]).collect();
                xi[k] += sign * t;
                xi
            };
            let mut x = home.clone();
            let mut t = 0.0;
            let mut failed = None;
            // (t, x, condition of Φ_d) along the walk.
            let mut path: Vec<(f64, Vec<f64>, f64)> =
                vec![(0.0, x.clone(), cnoc::constraint_condition(&plan, &x))];
            for s in 1..=steps {
                let ts = s as f64 * h;
                match cnoc::forward_kinematics(&plan, &xi_at(ts), &x) {
                    Ok(xn) => {
                        x = xn;
                        t = ts;
                        let v = compare_closed(name, &plan, &x, &format!("t = {t}"), bad);
                        note(&v);
                        path.push((t, x.clone(), cnoc::constraint_condition(&plan, &x)));
                    }
                    Err(_) => {
                        failed = Some(ts);
                        break;
                    }
                }
            }
            if std::env::var("WALKS_DEBUG").is_ok() {
                let m = path.iter().map(|p| p.2).fold(0.0, f64::max);
                println!(
                    "{name} k {k} sign {sign}: {} steps, failed {failed:?}, max cond {m:e}",
                    path.len()
                );
            }
            // Approach `t*` from the state `x0` at `t0`: 1e-1 … 1e-13 of the way left.
            let mut approach = |t0: f64, x0: &[f64], ts: f64, bad: &mut Vec<String>| {
                let mut xa = x0.to_vec();
                for e in 1..=13 {
                    let ta = ts + (t0 - ts) * 10f64.powi(-e);
                    if let Ok(xn) = cnoc::forward_kinematics(&plan, &xi_at(ta), &xa) {
                        xa = xn;
                        let v = compare_closed(name, &plan, &xa, &format!("t* + {}", ta - ts), bad);
                        note(&v);
                    }
                }
            };
            // Peaks of the condition of Φ_d (a bifurcation, or a fold the assembly stepped
            // over): refined by golden section, then approached from both sides.
            for i in 1..path.len().saturating_sub(1) {
                let (c0, c1, c2) = (path[i - 1].2, path[i].2, path[i + 1].2);
                if !(c1 > 10.0 && c1 >= c0 && c1 >= c2) {
                    continue;
                }
                let xi = path[i].1.clone();
                let cond = |t: f64| {
                    cnoc::forward_kinematics(&plan, &xi_at(t), &xi)
                        .map_or(-1.0, |x| cnoc::constraint_condition(&plan, &x))
                };
                let (mut a, mut b) = (path[i - 1].0, path[i + 1].0);
                let r = 0.5 * (5f64.sqrt() - 1.0);
                for _ in 0..80 {
                    let (m1, m2) = (b - r * (b - a), a + r * (b - a));
                    if cond(m1) >= cond(m2) {
                        b = m2;
                    } else {
                        a = m1;
                    }
                }
                let ts = 0.5 * (a + b);
                approach(path[i - 1].0, &path[i - 1].1, ts, bad);
                approach(path[i + 1].0, &path[i + 1].1, ts, bad);
            }
            let Some(mut hi) = failed else { continue };
            // A fold where assembly fails: bracket it, then approach it.
            let mut lo = t;
            let mut x_lo = x.clone();
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                match cnoc::forward_kinematics(&plan, &xi_at(mid), &x_lo) {
                    Ok(xn) => {
                        lo = mid;
                        x_lo = xn;
                    }
                    Err(_) => hi = mid,
                }
            }
            approach(t, &x, lo, bad);
            let v = compare_closed(name, &plan, &x_lo, "the fold", bad);
            note(&v);
            // Assembly stops where `Φ_d`'s condition reaches its own limit; past it, move the
            // dependent coordinates along `Φ_d`'s near-null direction, which keeps the loops
            // closed to second order, in steps of 1e-2 … 1e-12 each way.
            let n = null_direction(&plan, &x_lo);
            for e in 2..=12 {
                for side in [1.0, -1.0] {
                    let mut xs = x_lo.clone();
                    for (k, &j) in plan.dependent.iter().enumerate() {
                        xs[j] += side * 10f64.powi(-e) * n[k];
                    }
                    let v = compare_closed(name, &plan, &xs, &format!("fold + {side}e-{e} n"), bad);
                    note(&v);
                }
            }
        }
    }
    // Off the loops: a dependent coordinate displaced.
    let j = plan.dependent[0];
    for e in (1..=13).rev() {
        let mut x = home.clone();
        x[j] += 10f64.powi(-e);
        let v = compare_closed(name, &plan, &x, &format!("x[{j}] + 1e-{e}"), bad);
        note(&v);
    }
    sites
}

/// The unit right singular vector of `Φ_d` (kept equations, dependent columns) of the
/// smallest singular value at `x`.
fn null_direction(plan: &ClosedPlan, x: &[f64]) -> Vec<f64> {
    let (_, jac, _) = cnoc::constraints(plan, x, &vec![0.0; plan.nx()]);
    let nd = plan.dependent.len();
    let a = nalgebra::DMatrix::from_fn(jac.len(), nd, |i, k| jac[i][plan.dependent[k]]);
    let svd = a.svd(false, true);
    let v = svd.v_t.expect("V requested");
    let (k, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .fold(
            (0, f64::INFINITY),
            |b, (i, &s)| if s < b.1 { (i, s) } else { b },
        );
    (0..nd).map(|c| v[(k, c)]).collect()
}

#[test]
fn closed_loops_generated_and_runtime_agree_toward_singularities() {
    let mut bad = Vec::new();
    let mut constraint = Vec::new();
    for name in tests::closed::CLOSED {
        let sites = walk_closed(name, &mut bad);
        println!("{name}: runtime sites met {sites:?}");
        assert!(
            sites.iter().any(|s| s.starts_with("Closure")),
            "{name}: the closure walk met no Closure error"
        );
        if sites.iter().any(|s| s.starts_with("Constraint")) {
            constraint.push(name);
        }
    }
    println!("Constraint singularities reached: {constraint:?}");
    // The five-bars' distal links align, Bricard's linkage and the tripod meet folds, the
    // N-four-bar changes mobility with its bars horizontal. The crank-rocker four-bar and
    // Andrews' squeezer turn their crank fully without one.
    for name in [
        "five_bar_joints",
        "spherical_five_bar",
        "bricard",
        "n_four_bar",
        "tripod_3prs",
    ] {
        assert!(
            constraint.contains(&name),
            "{name}: no Constraint singularity reached"
        );
    }
    assert!(
        bad.is_empty(),
        "{} disagreements:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// Parallel mechanisms.

use runtime::parallel::noc::{self as pnoc, Plan as ParallelPlan};
use runtime::parallel::{ParallelModel, PlatformMotion};

/// The verdicts of a parallel module's public functions at `(x, u, ud)`.
type ParallelRoutes = fn(&[f64], &[f64], &[f64]) -> Vec<(&'static str, Verdict)>;

macro_rules! parallel_routes {
    ($($m:ident),*) => {
        fn parallel_generated(name: &str) -> ParallelRoutes {
            match name {
                $(stringify!($m) => |x, u, ud| {
                    use mechanisms::$m as g;
                    let v = |r: Result<(), g::Singular>| r.map_err(|e| format!("{:?}", e.site));
                    let (x, u, ud) = (arr(x), arr(u), arr(ud));
                    vec![
                        ("inverse_kinematics", v(g::inverse_kinematics(&x).map(|_| ()))),
                        ("actuator_rates", v(g::actuator_rates(&x, &u).map(|_| ()))),
                        ("inverse_dynamics", v(g::inverse_dynamics(&x, &u, &ud).map(|_| ()))),
                        ("mass_matrix", v(g::mass_matrix(&x).map(|_| ()))),
                        ("actuator_mass_matrix", v(g::actuator_mass_matrix(&x).map(|_| ()))),
                        ("forward_dynamics", v(g::forward_dynamics(&x, &u, &ud).map(|_| ()))),
                    ]
                },)*
                _ => panic!("no generated module {name}"),
            }
        }
    };
}
parallel_routes!(
    gough_stewart,
    agile_eye,
    sliding_hexapod,
    rus_hexapod,
    planar_five_bar,
    delta_rl5,
    planar_3rrr,
    tsai_3upu,
    prs_head,
    delta4_rl5
);

fn parallel_runtime(plan: &ParallelPlan, x: &[f64], u: &[f64], ud: &[f64]) -> Vec<Verdict> {
    vec![
        verdict(&pnoc::inverse_kinematics(plan, x)),
        verdict(&pnoc::actuator_rates(plan, x, u)),
        verdict(&pnoc::inverse_dynamics(plan, x, u, ud)),
        verdict(&pnoc::mass_matrix(plan, x)),
        verdict(&pnoc::actuator_mass_matrix(plan, x)),
        verdict(&pnoc::forward_dynamics(plan, x, u, ud)),
    ]
}

fn compare_parallel(
    name: &str,
    plan: &ParallelPlan,
    x: &[f64],
    what: &str,
    bad: &mut Vec<String>,
    sites: &mut Vec<String>,
) {
    let d = plan.dof();
    let u: Vec<f64> = (0..d).map(|k| 0.3 - 0.1 * k as f64).collect();
    let ud: Vec<f64> = (0..d).map(|k| -0.4 + 0.15 * k as f64).collect();
    let rt = parallel_runtime(plan, x, &u, &ud);
    let generated = parallel_generated(name)(x, &u, &ud);
    // The two functions that invert `A` test the same pivots of the same matrix.
    let verdict_of = |f: &str| generated.iter().find(|(n, _)| *n == f).map(|(_, v)| v);
    if verdict_of("inverse_dynamics") != verdict_of("actuator_mass_matrix") {
        bad.push(format!(
            "{name} at {what} (x = {x:?}): inverse_dynamics {:?}, actuator_mass_matrix {:?}",
            verdict_of("inverse_dynamics"),
            verdict_of("actuator_mass_matrix")
        ));
    }
    for ((f, g), r) in generated.iter().zip(&rt) {
        if g != r {
            bad.push(format!(
                "{name} {f} at {what} (x = {x:?}): generated {g:?}, runtime {r:?}"
            ));
        }
        if let Err(s) = r
            && !sites.contains(s)
        {
            sites.push(s.clone());
        }
    }
}

/// Quaternion `[w, x, y, z]` product `a ⊗ b`.
fn qmul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// Home turned by `deg` about base axis `axis` (and, for pose platforms, moved by `dp`).
fn turned(m: &ParallelModel, axis: usize, deg: f64, dp: [f64; 3]) -> Vec<f64> {
    let home = tests::pkm::home_x(m);
    let h = deg.to_radians() / 2.0;
    let mut r = [h.cos(), 0.0, 0.0, 0.0];
    r[1 + axis] = h.sin();
    match m.motion {
        PlatformMotion::Pose => {
            let q = qmul(r, [home[3], home[4], home[5], home[6]]);
            vec![
                home[0] + dp[0],
                home[1] + dp[1],
                home[2] + dp[2],
                q[0],
                q[1],
                q[2],
                q[3],
            ]
        }
        PlatformMotion::Orientation { .. } => {
            qmul(r, [home[0], home[1], home[2], home[3]]).to_vec()
        }
        PlatformMotion::PlanarPoint { .. } => vec![home[0] + dp[0], home[1] + dp[1]],
        PlatformMotion::Translation { .. } => {
            vec![home[0] + dp[0], home[1] + dp[1], home[2] + dp[2]]
        }
        // Turned about z only (the plane's normal): φ.
        PlatformMotion::PlanarPose { .. } => vec![
            home[0] + dp[0],
            home[1] + dp[1],
            home[2] + if axis == 2 { deg.to_radians() } else { 0.0 },
        ],
        // Moved by dp, the tool turned about z.
        PlatformMotion::Schoenflies { .. } => vec![
            home[0] + dp[0],
            home[1] + dp[1],
            home[2] + dp[2],
            home[3] + if axis == 2 { deg.to_radians() } else { 0.0 },
        ],
        // Heave dz, tilted about x (α) or y (β).
        PlatformMotion::HeaveTilt { .. } => vec![
            home[0] + dp[2],
            home[1] + if axis == 0 { deg.to_radians() } else { 0.0 },
            home[2] + if axis == 1 { deg.to_radians() } else { 0.0 },
        ],
    }
}

#[test]
fn parallel_generated_and_runtime_agree_toward_singularities() {
    let mut bad = Vec::new();
    for name in tests::pkm::PARALLEL {
        let m = tests::pkm::model(name);
        let plan = ParallelPlan::new(&m).unwrap();
        let home = tests::pkm::home_x(&m);
        let mut sites = Vec::new();
        let mut at = |x: Vec<f64>, what: String, bad: &mut Vec<String>| {
            compare_parallel(name, &plan, &x, &what, bad, &mut sites)
        };
        match m.motion {
            PlatformMotion::Pose => {
                // Yaw to 90° (parallel singularities), tilts, and a descent to the base
                // plane (legs in the base plane: leg and parallel singularities).
                for axis in 0..3 {
                    for s in 0..=400 {
                        let deg = 90.0 * s as f64 / 400.0;
                        at(
                            turned(&m, axis, deg, [0.0; 3]),
                            format!("{deg}° about {axis}"),
                            &mut bad,
                        );
                    }
                }
                for s in 0..=400 {
                    let dz = -home[2] * s as f64 / 400.0;
                    at(
                        turned(&m, 0, 0.0, [0.0, 0.0, dz]),
                        format!("dz {dz}"),
                        &mut bad,
                    );
                }
                at(
                    vec![1e5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0],
                    "far away".into(),
                    &mut bad,
                );
            }
            PlatformMotion::Orientation { .. } => {
                for axis in 0..3 {
                    for s in 0..=720 {
                        let deg = 180.0 * s as f64 / 720.0;
                        at(
                            turned(&m, axis, deg, [0.0; 3]),
                            format!("{deg}° about {axis}"),
                            &mut bad,
                        );
                    }
                }
            }
            PlatformMotion::PlanarPoint { .. } => {
                for (dx, dy) in [(1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (0.7, 0.7)] {
                    for s in 0..=800 {
                        let t = 0.5 * s as f64 / 800.0;
                        at(
                            turned(&m, 0, 0.0, [dx * t, dy * t, 0.0]),
                            format!("{t} along ({dx}, {dy})"),
                            &mut bad,
                        );
                    }
                }
            }
            PlatformMotion::PlanarPose { .. } => {
                // Out of the workspace in the plane (legs stretched: leg singularities, then
                // out of reach), and turned about z both ways (type-II singularities).
                for (dx, dy) in [(1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (-0.7, 0.7)] {
                    for s in 0..=800 {
                        let t = 0.6 * s as f64 / 800.0;
                        at(
                            turned(&m, 2, 0.0, [dx * t, dy * t, 0.0]),
                            format!("{t} along ({dx}, {dy})"),
                            &mut bad,
                        );
                    }
                }
                for s in 0..=720 {
                    let deg = -180.0 + 360.0 * s as f64 / 720.0;
                    at(
                        turned(&m, 2, deg, [0.0; 3]),
                        format!("{deg}° about z"),
                        &mut bad,
                    );
                }
            }
            PlatformMotion::HeaveTilt { .. } => {
                // Tilted both ways about x and y (legs folding and stretching: leg
                // singularities, out of reach, the parasitic solve's limits), and heaved up
                // and down.
                for axis in 0..2 {
                    for s in 0..=720 {
                        let deg = -90.0 + 180.0 * s as f64 / 720.0;
                        at(
                            turned(&m, axis, deg, [0.0; 3]),
                            format!("{deg}° about {axis}"),
                            &mut bad,
                        );
                    }
                }
                // From one step above the base plane: in it, a 3-PRS with horizontal rails
                // (prs_head) has every link horizontal and `A`'s heave column exactly zero, and
                // the generated and the runtime LU may name different legs for the tie
                // (tests/tests/prs.rs checks that both answer `Actuation` there).
                for s in 1..=800 {
                    let dz = home[0] * (-1.0 + 2.0 * s as f64 / 800.0);
                    at(
                        turned(&m, 0, 0.0, [0.0, 0.0, dz]),
                        format!("dz {dz}"),
                        &mut bad,
                    );
                }
            }
            PlatformMotion::Schoenflies { .. } => {
                // The Delta's walks (out of the workspace sideways and down, up toward the
                // base), the tool turned all the way round, and the carrier raised toward the
                // shaft's upper U off the axis (the tube levels out: its U's gimbal lock) and on
                // it (the tube's length to zero).
                let dirs = [
                    [1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, -1.0],
                    [0.0, 0.0, 1.0],
                    [0.6, 0.0, 0.8],
                ];
                for d in dirs {
                    for s in 0..=800 {
                        let t = 1.2 * s as f64 / 800.0;
                        at(
                            turned(&m, 2, 30.0, [d[0] * t, d[1] * t, d[2] * t]),
                            format!("{t} m along {d:?}"),
                            &mut bad,
                        );
                    }
                }
                for s in 0..=720 {
                    let deg = -360.0 + 720.0 * s as f64 / 720.0;
                    at(
                        turned(&m, 2, deg, [0.1, 0.0, 0.0]),
                        format!("{deg}° about z"),
                        &mut bad,
                    );
                }
                for (dx, label) in [(0.3, "off the axis"), (0.0, "on the axis")] {
                    for s in 0..=800 {
                        let dz = 1.0 * s as f64 / 800.0;
                        at(
                            turned(&m, 2, 10.0, [dx, 0.0, dz]),
                            format!("raised {dz} m {label}"),
                            &mut bad,
                        );
                    }
                }
            }
            PlatformMotion::Translation { .. } => {
                // Out of the workspace sideways and down (the legs stretched: leg
                // singularities, then out of reach), and up toward the base (the rods level
                // out: leg and parallel singularities).
                let dirs = [
                    [1.0, 0.0, 0.0],
                    [-1.0, 0.0, 0.0],
                    [0.0, 1.0, 0.0],
                    [0.0, 0.0, -1.0],
                    [0.0, 0.0, 1.0],
                    [0.6, 0.0, 0.8],
                    [-0.6, 0.0, 0.8],
                ];
                for d in dirs {
                    for s in 0..=800 {
                        let t = 1.2 * s as f64 / 800.0;
                        at(
                            turned(&m, 0, 0.0, [d[0] * t, d[1] * t, d[2] * t]),
                            format!("{t} m along {d:?}"),
                            &mut bad,
                        );
                    }
                }
                // Exactly into the base plane (a 3-UPU's legs all in it: parallel and, at
                // points, leg singularities, which the steps above pass between).
                at(
                    turned(&m, 0, 0.0, [0.0, 0.0, -home[2]]),
                    "into the base plane".into(),
                    &mut bad,
                );
                at(
                    turned(&m, 0, 0.0, [0.15, 0.3, -home[2]]),
                    "into the base plane, leg 0 along its first axis".into(),
                    &mut bad,
                );
            }
        }
        println!("{name}: runtime sites met {sites:?}");
        assert!(!sites.is_empty(), "{name}: the walks met no singularity");
    }
    assert!(
        bad.is_empty(),
        "{} disagreements:\n{}",
        bad.len(),
        bad.join("\n")
    );
}
