//! Speed against accuracy, measured in one run: for the PUMA 560 (a
//! tree), the Gough–Stewart platform (a parallel mechanism), the Delta (exact and Codourey's
//! simplified model, a scene level), the five-bar in joint
//! coordinates (closed loops) and a URDF with rounded angles (the iiwa 14, as written and
//! snapped), every way nocdyn offers to compute the inverse dynamics — including fidelity
//! levels and the `libm` math backend (modules from `tests/build.rs`) — timed
//! (median over repeated batches of 256 random regular states, ns per call) and compared with a
//! double-double evaluation of the same equations (`references::dd`; the worst relative error in the
//! ∞-norm over the states). Writes `PREFIX.csv`, `PREFIX.md` and `PREFIX.svg` (log–log).
//!
//! ```text
//! cargo run --profile bench -p tests --features figures --bin chart [-- PREFIX]   (default: docs/figures/chart)
//! ```

use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Instant;

use plotters::prelude::*;
use rand::Rng;

const STATES: usize = 256;
const BATCHES: usize = 31;

struct Point {
    mechanism: &'static str,
    candidate: &'static str,
    ns: f64,
    error: f64,
}

/// Median ns per call of `f` over the state indices: `BATCHES` batches of all states, or 3 when
/// one batch takes more than 0.2 s (the Lagrange-multiplier routes).
fn time(mut f: impl FnMut(usize) -> f64) -> f64 {
    let mut batch = || {
        let t = Instant::now();
        let mut acc = 0.0;
        for i in 0..STATES {
            acc += f(i);
        }
        black_box(acc);
        t.elapsed().as_nanos() as f64 / STATES as f64
    };
    let first = batch();
    let n = if first * STATES as f64 > 2e8 {
        3
    } else {
        BATCHES
    };
    let mut per: Vec<f64> = (1..n).map(|_| batch()).collect();
    per.push(first);
    per.sort_by(f64::total_cmp);
    per[n / 2]
}

fn worst(f: impl Fn(usize) -> Vec<f64>, reference: &[Vec<f64>]) -> f64 {
    (0..STATES)
        .map(|i| tests::pkm::rel(&f(i), &reference[i]))
        .fold(0.0, f64::max)
}

fn puma(points: &mut Vec<Point>) {
    use mechanisms::f32::puma560 as s;
    use mechanisms::puma560 as g;
    let path = tests::pkm::spec_path("puma560");
    let (model, _) = codegen::spec::load_tree(
        &path.to_string_lossy(),
        &std::fs::read_to_string(&path).unwrap(),
    )
    .unwrap();
    let plan = runtime::closed::noc::Plan::tree(&model);
    let mut rng = tests::rng(31);
    let states: Vec<[[f64; 6]; 3]> = (0..STATES)
        .map(|_| core::array::from_fn(|_| core::array::from_fn(|_| rng.random_range(-1.5..1.5))))
        .collect();
    // Reference at the f32-rounded states so that every candidate sees the same inputs.
    let states: Vec<[[f64; 6]; 3]> = states
        .iter()
        .map(|s| s.map(|v| v.map(|x| x as f32 as f64)))
        .collect();
    let reference: Vec<Vec<f64>> = states
        .iter()
        .map(|[q, qd, qdd]| references::dd::closed_inverse_dynamics_dd(&plan, q, qd, qdd).unwrap())
        .collect();
    let m = "PUMA 560";
    let mut add = |candidate, f: &dyn Fn(usize) -> Vec<f64>| {
        points.push(Point {
            mechanism: m,
            candidate,
            ns: time(|i| f(black_box(i))[0]),
            error: worst(f, &reference),
        });
    };
    let g64 = |i: usize| {
        let [q, qd, qdd] = &states[i];
        g::inverse_dynamics(q, qd, qdd).to_vec()
    };
    add("generated f64", &g64);
    let s32 = |i: usize| {
        let [q, qd, qdd] = states[i].map(|v| v.map(|x| x as f32));
        s::inverse_dynamics(&q, &qd, &qdd)
            .iter()
            .map(|&v| v as f64)
            .collect::<Vec<_>>()
    };
    add("generated f32", &s32);
    // The same module with `libm` trigonometry, and two fidelity levels (`[scene]`): their
    // error is against the full model's reference, so it is the model error of the level.
    let libm = |i: usize| {
        let [q, qd, qdd] = &states[i];
        tests::variants::puma_libm::inverse_dynamics(q, qd, qdd).to_vec()
    };
    add("generated f64, libm math", &libm);
    let point = |i: usize| {
        let [q, qd, qdd] = &states[i];
        tests::variants::puma_point_wrist::inverse_dynamics(q, qd, qdd).to_vec()
    };
    add("generated f64, point-mass wrist (links 4–6)", &point);
    let massless = |i: usize| {
        let [q, qd, qdd] = &states[i];
        tests::variants::puma_massless_wrist::inverse_dynamics(q, qd, qdd).to_vec()
    };
    add("generated f64, massless wrist (links 4–6)", &massless);
    let noc = |i: usize| {
        let [q, qd, qdd] = &states[i];
        runtime::noc::inverse_dynamics(&model, q, qd, qdd)
            .iter()
            .copied()
            .collect::<Vec<_>>()
    };
    add("runtime NOC (nalgebra)", &noc);
    let rnea = |i: usize| {
        let [q, qd, qdd] = &states[i];
        runtime::rnea::inverse_dynamics(&model, q, qd, qdd)
            .iter()
            .copied()
            .collect::<Vec<_>>()
    };
    add("RNEA (spatial algebra)", &rnea);
    let lag = |i: usize| {
        let [q, qd, qdd] = &states[i];
        let sys = references::lagrange::from_tree(&model, q);
        references::lagrange::inverse_dynamics(
            &sys,
            &references::lagrange::Prescribed::ActuatedJoints,
            qd,
            qdd,
        )
        .unwrap()
        .efforts
    };
    add("Newton–Euler + Lagrange multipliers", &lag);
}

/// A platform state: `x`, `u`, `u̇`.
type State = (Vec<f64>, Vec<f64>, Vec<f64>);

/// `STATES` random regular states of a platform (rounded to `f32`, so that the single-precision
/// module sees the same inputs; turns up to `angle`, moves up to `reach` from home) and the
/// double-double inverse dynamics at each.
fn platform_states(
    model: &runtime::parallel::ParallelModel,
    seed: u64,
    angle: f64,
    reach: f64,
) -> (runtime::parallel::noc::Plan, Vec<State>, Vec<Vec<f64>>) {
    let plan = runtime::parallel::noc::Plan::new(model).unwrap();
    let home = model.home_x();
    let mut rng = tests::rng(seed);
    let states: Vec<State> = (0..STATES)
        .map(|_| {
            let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, angle, reach);
            let r = |v: Vec<f64>| v.iter().map(|&a| a as f32 as f64).collect::<Vec<_>>();
            (r(x), r(u), r(ud))
        })
        .collect();
    let reference = states
        .iter()
        .map(|(x, u, ud)| references::dd::inverse_dynamics_dd(&plan, x, u, ud).unwrap())
        .collect();
    (plan, states, reference)
}

fn gough_stewart(points: &mut Vec<Point>) {
    use mechanisms::f32::gough_stewart as s;
    use mechanisms::gough_stewart as g;
    use runtime::parallel::noc;
    let model = tests::pkm::model("gough_stewart");
    let (plan, states, reference) = platform_states(&model, 32, 0.1, 0.02 * model.size());
    let m = "Gough–Stewart";
    let mut add = |candidate, f: &dyn Fn(usize) -> Vec<f64>| {
        points.push(Point {
            mechanism: m,
            candidate,
            ns: time(|i| f(black_box(i))[0]),
            error: worst(f, &reference),
        });
    };
    let arr = |i: usize| -> ([f64; 7], [f64; 6], [f64; 6]) {
        let (x, u, ud) = &states[i];
        (
            x.clone().try_into().unwrap(),
            u.clone().try_into().unwrap(),
            ud.clone().try_into().unwrap(),
        )
    };
    let g64 = |i: usize| {
        let (x, u, ud) = arr(i);
        g::inverse_dynamics(&x, &u, &ud).unwrap().to_vec()
    };
    add("generated f64", &g64);
    let s32 = |i: usize| {
        let (x, u, ud) = arr(i);
        let (x, u, ud) = (
            x.map(|v| v as f32),
            u.map(|v| v as f32),
            ud.map(|v| v as f32),
        );
        s::inverse_dynamics(&x, &u, &ud)
            .unwrap()
            .iter()
            .map(|&v| v as f64)
            .collect::<Vec<_>>()
    };
    add("generated f32", &s32);
    let point = |i: usize| {
        let (x, u, ud) = arr(i);
        tests::variants::gs_point_legs::inverse_dynamics(&x, &u, &ud)
            .unwrap()
            .to_vec()
    };
    add("generated f64, point-mass legs", &point);
    let rt = |i: usize| {
        let (x, u, ud) = &states[i];
        noc::inverse_dynamics(&plan, x, u, ud).unwrap()
    };
    add("runtime (leg-wise, f64)", &rt);
    let literal = |i: usize| {
        let (x, u, ud) = &states[i];
        runtime::parallel::literal::inverse_dynamics(&plan, x, u, ud)
            .unwrap()
            .as_slice()
            .to_vec()
    };
    add("runtime (literal NOC, nalgebra)", &literal);
    let lag = |i: usize| {
        let (x, u, ud) = &states[i];
        let legs = noc::leg_joint_positions(&plan, x).unwrap();
        let sys = references::lagrange::from_parallel(&model, &legs, x);
        let p = sys.bodies.len() - 1;
        let pre = references::lagrange::Prescribed::Pose {
            body: p,
            point: [x[0], x[1], x[2]],
        };
        references::lagrange::inverse_dynamics(&sys, &pre, u, ud)
            .unwrap()
            .efforts
    };
    add("Newton–Euler + Lagrange multipliers", &lag);
}

/// The Delta (`delta_rl5`, translational platform coordinates): the exact model and Codourey's
/// simplified one (`[scene] delta_model = "codourey"`, rod masses lumped 2/3 at the elbows and
/// 1/3 on the platform), both against the double-double evaluation of the exact model, so the
/// simplified level's error is the model error it makes (docs/scene.md). States within ±0.3 m of
/// home per coordinate.
fn delta(points: &mut Vec<Point>) {
    use mechanisms::delta_rl5 as g;
    use mechanisms::f32::delta_rl5 as s;
    use runtime::parallel::noc;
    use tests::variants::delta_codourey as c;
    let model = tests::pkm::model("delta_rl5");
    let (plan, states, reference) = platform_states(&model, 33, 0.0, 0.3);
    let m = "Delta (RL5)";
    let mut add = |candidate, f: &dyn Fn(usize) -> Vec<f64>| {
        points.push(Point {
            mechanism: m,
            candidate,
            ns: time(|i| f(black_box(i))[0]),
            error: worst(f, &reference),
        });
    };
    let arr = |i: usize| -> ([f64; 3], [f64; 3], [f64; 3]) {
        let (x, u, ud) = &states[i];
        (
            x.clone().try_into().unwrap(),
            u.clone().try_into().unwrap(),
            ud.clone().try_into().unwrap(),
        )
    };
    let g64 = |i: usize| {
        let (x, u, ud) = arr(i);
        g::inverse_dynamics(&x, &u, &ud).unwrap().to_vec()
    };
    add("generated f64", &g64);
    let s32 = |i: usize| {
        let (x, u, ud) = arr(i);
        let (x, u, ud) = (
            x.map(|v| v as f32),
            u.map(|v| v as f32),
            ud.map(|v| v as f32),
        );
        s::inverse_dynamics(&x, &u, &ud)
            .unwrap()
            .iter()
            .map(|&v| v as f64)
            .collect::<Vec<_>>()
    };
    add("generated f32", &s32);
    let cod = |i: usize| {
        let (x, u, ud) = arr(i);
        c::inverse_dynamics(&x, &u, &ud).unwrap().to_vec()
    };
    add("generated f64, Codourey's simplified Delta", &cod);
    let rt = |i: usize| {
        let (x, u, ud) = &states[i];
        noc::inverse_dynamics(&plan, x, u, ud).unwrap()
    };
    add("runtime (leg-wise, f64)", &rt);
}

/// A URDF with its quarter and half turns rounded to 5 digits (`1.5708`, `3.1416`), as many
/// published files write them: generated as written, and snapped (`snap = 1e-4`). The reference
/// is the file as written, so the snapped module's error is the model change the snap made.
fn iiwa(points: &mut Vec<Point>) {
    use tests::variants::{iiwa_rounded as w, iiwa_snapped as s};
    let src = std::fs::read_to_string(tests::pkm::spec_path("iiwa14").with_extension("urdf"))
        .unwrap()
        .replace("1.5707963267948966", "1.5708")
        .replace("3.141592653589793", "3.1416");
    let (model, _) = codegen::spec::load_tree("iiwa14.urdf", &src).unwrap();
    let plan = runtime::closed::noc::Plan::tree(&model);
    let mut rng = tests::rng(34);
    let states: Vec<[[f64; 7]; 3]> = (0..STATES)
        .map(|_| core::array::from_fn(|_| core::array::from_fn(|_| rng.random_range(-1.5..1.5))))
        .collect();
    let reference: Vec<Vec<f64>> = states
        .iter()
        .map(|[q, qd, qdd]| references::dd::closed_inverse_dynamics_dd(&plan, q, qd, qdd).unwrap())
        .collect();
    let m = "iiwa 14 (URDF angles to 5 digits)";
    let mut add = |candidate, f: &dyn Fn(usize) -> Vec<f64>| {
        points.push(Point {
            mechanism: m,
            candidate,
            ns: time(|i| f(black_box(i))[0]),
            error: worst(f, &reference),
        });
    };
    let g64 = |i: usize| {
        let [q, qd, qdd] = &states[i];
        w::inverse_dynamics(q, qd, qdd).to_vec()
    };
    add("generated f64", &g64);
    let snapped = |i: usize| {
        let [q, qd, qdd] = &states[i];
        s::inverse_dynamics(q, qd, qdd).to_vec()
    };
    add("generated f64, snapped 1e-4", &snapped);
    let noc = |i: usize| {
        let [q, qd, qdd] = &states[i];
        runtime::noc::inverse_dynamics(&model, q, qd, qdd)
            .iter()
            .copied()
            .collect::<Vec<_>>()
    };
    add("runtime NOC (nalgebra)", &noc);
}

fn five_bar(points: &mut Vec<Point>) {
    use mechanisms::f32::five_bar_joints as s;
    use mechanisms::five_bar_joints as g;
    use runtime::closed::noc;
    let model = tests::closed::model("five_bar_joints");
    let plan = noc::Plan::new(&model).unwrap();
    let mut rng = tests::rng(33);
    let mut states: Vec<([f64; 4], [f64; 2], [f64; 2])> = Vec::new();
    while states.len() < STATES {
        let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, 1.0);
        // Regular as `tests/tests/f32.rs` defines it: the loop equations' condition at most
        // 100 and no joint faster than 10 times the independent speeds (near the five-bar's
        // boundary singularities the distal links turn 20 times faster than the actuators,
        // and every route's error grows with that).
        let fastest = (0..2)
            .map(|k| {
                let mut e = [0.0; 2];
                e[k] = 1.0;
                noc::joint_rates(&plan, &x, &e).map_or(f64::INFINITY, |r| {
                    r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
                })
            })
            .fold(0.0f64, f64::max);
        if noc::constraint_condition(&plan, &x) > 100.0 || fastest > 10.0 {
            continue;
        }
        let x: [f64; 4] = x.try_into().unwrap();
        // Assemble the f32-rounded independent coordinates in f64: the common state.
        let xi = [
            x[plan.independent[0]] as f32 as f64,
            x[plan.independent[1]] as f32 as f64,
        ];
        let Ok(x) = g::forward_kinematics(&xi, &x) else {
            continue;
        };
        states.push((
            x,
            [u[0] as f32 as f64, u[1] as f32 as f64],
            [ud[0] as f32 as f64, ud[1] as f32 as f64],
        ));
    }
    let reference: Vec<Vec<f64>> = states
        .iter()
        .map(|(x, u, ud)| references::dd::closed_inverse_dynamics_dd(&plan, x, u, ud).unwrap())
        .collect();
    let m = "five-bar (joint coordinates)";
    let mut add = |candidate, f: &dyn Fn(usize) -> Vec<f64>| {
        points.push(Point {
            mechanism: m,
            candidate,
            ns: time(|i| f(black_box(i))[0]),
            error: worst(f, &reference),
        });
    };
    let g64 = |i: usize| {
        let (x, u, ud) = &states[i];
        g::inverse_dynamics(x, u, ud).unwrap().to_vec()
    };
    add("generated f64", &g64);
    let s32 = |i: usize| {
        let (x, u, ud) = &states[i];
        let xi = [x[plan.independent[0]] as f32, x[plan.independent[1]] as f32];
        let x32 = s::forward_kinematics(&xi, &x.map(|v| v as f32)).unwrap();
        s::inverse_dynamics(&x32, &u.map(|v| v as f32), &ud.map(|v| v as f32))
            .unwrap()
            .iter()
            .map(|&v| v as f64)
            .collect::<Vec<_>>()
    };
    // The f32 time includes its own assembly (f32 states cannot hold the f64 closure).
    add("generated f32 (+ f32 assembly)", &s32);
    let rt = |i: usize| {
        let (x, u, ud) = &states[i];
        noc::inverse_dynamics(&plan, x, u, ud).unwrap()
    };
    add("runtime (generic, f64)", &rt);
    let lag = |i: usize| {
        let (x, u, ud) = &states[i];
        let sys = references::lagrange::from_closed(&model, x);
        references::lagrange::inverse_dynamics(
            &sys,
            &references::lagrange::Prescribed::ActuatedJoints,
            u,
            ud,
        )
        .unwrap()
        .efforts
    };
    add("Newton–Euler + Lagrange multipliers", &lag);
}

/// The second chart: error against condition while walking the Gough–Stewart platform to its
/// parallel singularity at 90° yaw (`ψ = 90° − δ`, δ = 10⁻¹ … 10⁻¹² degrees; a dynamic state
/// with `u`, `u̇` in ±1), for the generated `f64` and `f32` code, the runtime and the
/// Lagrange-multiplier route. The condition is the double-double pivot ratio of `A` (columns
/// scaled). A route that answers `Err` at a step has no point there (the table says so).
fn walk(prefix: &str) -> Result<(), Box<dyn std::error::Error>> {
    use mechanisms::f32::gough_stewart as s;
    use mechanisms::gough_stewart as g;
    use runtime::parallel::noc;
    let model = tests::pkm::model("gough_stewart");
    let plan = noc::Plan::new(&model).unwrap();
    let home = model.home_x();
    let qh = [home[3], home[4], home[5], home[6]];
    let qmul = |a: [f64; 4], b: [f64; 4]| {
        [
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
        ]
    };
    let u = [0.3, -0.2, 0.1, 0.05, -0.1, 0.2];
    let ud = [-0.4, 0.3, 0.2, -0.1, 0.15, -0.25];
    let routes = [
        "generated f64",
        "generated f32",
        "runtime f64",
        "Lagrange multipliers",
    ];
    let mut rows: Vec<(f64, f64, Vec<Option<f64>>)> = Vec::new();
    for k in 1..=12 {
        let delta = 10f64.powi(-k);
        let psi = (90.0 - delta).to_radians();
        let q = qmul([(psi / 2.0).cos(), 0.0, 0.0, (psi / 2.0).sin()], qh);
        let x: Vec<f64> = vec![home[0], home[1], home[2], q[0], q[1], q[2], q[3]];
        // The f32 code gets the state rounded to f32; its reference is taken there.
        let x32: Vec<f64> = x.iter().map(|&v| v as f32 as f64).collect();
        let cond = references::dd::conditioning(
            &references::dd::actuation_dd(&plan, &x).map_err(|e| e.to_string())?,
        )
        .pivot_ratio;
        let Ok(reference) = references::dd::inverse_dynamics_dd(&plan, &x, &u, &ud) else {
            continue;
        };
        let reference32 = references::dd::inverse_dynamics_dd(&plan, &x32, &u, &ud).ok();
        let err = |t: Vec<f64>| tests::pkm::rel(&t, &reference);
        let xa: [f64; 7] = x.clone().try_into().unwrap();
        let e64 = g::inverse_dynamics(&xa, &u, &ud)
            .ok()
            .map(|t| err(t.to_vec()));
        let e32 = s::inverse_dynamics(
            &xa.map(|v| v as f32),
            &u.map(|v| v as f32),
            &ud.map(|v| v as f32),
        )
        .ok()
        .zip(reference32)
        .map(|(t, r)| tests::pkm::rel(&t.iter().map(|&v| v as f64).collect::<Vec<_>>(), &r));
        let ert = noc::inverse_dynamics(&plan, &x, &u, &ud).ok().map(err);
        let elg = noc::leg_joint_positions(&plan, &x).ok().and_then(|legs| {
            let sys = references::lagrange::from_parallel(&model, &legs, &x);
            let p = sys.bodies.len() - 1;
            let pre = references::lagrange::Prescribed::Pose {
                body: p,
                point: [x[0], x[1], x[2]],
            };
            references::lagrange::inverse_dynamics(&sys, &pre, &u, &ud)
                .ok()
                .map(|s| err(s.efforts))
        });
        rows.push((delta, cond, vec![e64, e32, ert, elg]));
    }
    let mut md = String::from("| δ (deg) | condition (dd pivot ratio) |");
    for r in routes {
        md.push_str(&format!(" {r} |"));
    }
    md.push_str("\n|---:|---:|---:|---:|---:|---:|\n");
    let mut csv = String::from("delta_deg,condition,route,relative_error\n");
    for (d, c, es) in &rows {
        md.push_str(&format!("| {d:.0e} | {c:.2e} |"));
        for (r, e) in routes.iter().zip(es) {
            match e {
                Some(e) => {
                    md.push_str(&format!(" {e:.1e} |"));
                    writeln!(csv, "{d:e},{c:e},{r},{e:e}")?;
                }
                None => md.push_str(" Err |"),
            }
        }
        md.push('\n');
    }
    std::fs::write(format!("{prefix}_walk.md"), &md)?;
    std::fs::write(format!("{prefix}_walk.csv"), &csv)?;
    print!("{md}");
    let svg = format!("{prefix}_walk.svg");
    let root = SVGBackend::new(&svg, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Gough–Stewart walked to its 90° yaw singularity: error against condition",
            ("sans-serif", 18),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (1e1f64..1e16f64).log_scale(),
            (1e-17f64..1e1f64).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("condition (double-double pivot ratio of A)")
        .y_desc("relative error vs double-double (missing: Err)")
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let colours = [RED, BLUE, GREEN, MAGENTA];
    for (k, r) in routes.iter().enumerate() {
        let c = colours[k];
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter_map(|(_, cond, es)| es[k].map(|e| (*cond, e.max(2e-17))))
            .collect();
        chart
            .draw_series(std::iter::once(PathElement::new(
                pts.clone(),
                c.stroke_width(2),
            )))?
            .label(*r)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 4, c.filled())))?;
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()?;
    root.present()?;
    eprintln!("wrote {prefix}_walk.csv, {prefix}_walk.md and {svg}");
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let prefix = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "docs/figures/chart".into());
    let mut points = Vec::new();
    puma(&mut points);
    gough_stewart(&mut points);
    delta(&mut points);
    five_bar(&mut points);
    iiwa(&mut points);
    let mut csv = String::from("mechanism,candidate,ns_per_call,max_relative_error\n");
    let mut md = String::from(
        "| mechanism | candidate | ns per call | × generated f64 | worst relative error vs double-double |\n|---|---|---:|---:|---:|\n",
    );
    for p in &points {
        let base = points
            .iter()
            .find(|q| q.mechanism == p.mechanism && q.candidate == "generated f64")
            .map_or(1.0, |q| q.ns);
        writeln!(
            csv,
            "{},{},{:.1},{:.3e}",
            p.mechanism, p.candidate, p.ns, p.error
        )?;
        writeln!(
            md,
            "| {} | {} | {:.0} | {:.1} | {:.1e} |",
            p.mechanism,
            p.candidate,
            p.ns,
            p.ns / base,
            p.error
        )?;
    }
    std::fs::write(format!("{prefix}.csv"), &csv)?;
    std::fs::write(format!("{prefix}.md"), &md)?;
    print!("{md}");
    let svg = format!("{prefix}.svg");
    let root = SVGBackend::new(&svg, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let (x0, x1) = (1.0f64, 1e8f64);
    let (y0, y1) = (1e-17f64, 1e0f64);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Inverse dynamics: time per call against error (one run)",
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("ns per call (median)")
        .y_desc("worst relative error vs double-double")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    let colours = [RED, BLUE, GREEN, MAGENTA, CYAN];
    let mechs = [
        "PUMA 560",
        "Gough–Stewart",
        "Delta (RL5)",
        "five-bar (joint coordinates)",
        "iiwa 14 (URDF angles to 5 digits)",
    ];
    for (k, m) in mechs.iter().enumerate() {
        let c = colours[k];
        let pts: Vec<&Point> = points.iter().filter(|p| p.mechanism == *m).collect();
        chart
            .draw_series(
                pts.iter()
                    .map(|p| Circle::new((p.ns, p.error.max(y0 * 2.0)), 5, c.filled())),
            )?
            .label(*m)
            .legend(move |(x, y)| Circle::new((x, y), 5, c.filled()));
        chart.draw_series(pts.iter().map(|p| {
            Text::new(
                p.candidate.to_string(),
                (p.ns * 1.15, p.error.max(y0 * 2.0)),
                ("sans-serif", 11).into_font().color(&c),
            )
        }))?;
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()?;
    root.present()?;
    eprintln!("wrote {prefix}.csv, {prefix}.md and {svg}");
    walk(&prefix)
}
