//! Walks toward the singularities of the bundled parallel manipulators and checks the documented
//! failure behaviour of the `f64` routes (docs/method.md, "Where the method fails";
//! docs/method.md, "Where the method fails"): near a leg (type-I) or parallel (type-II)
//! singularity an evaluation either returns a result accurate to 1e-6 (relative, ∞-norm) or
//! says `Err(Singular)` with a large condition estimate — never NaN, never garbage, never a
//! panic — and once it fails it keeps failing closer to the singularity.
//!
//! The reference is the same NOC equations evaluated in double-double (`references::dd`,
//! ~32 digits): `references::dd::inverse_dynamics_dd`.
//!
//! Run `cargo test -p tests --test singularities -- --nocapture` to print the tables below.
//! In them "κ pivots" is the largest over the smallest pivot of the column-scaled LU of `A`
//! (the runtime's estimate, computed in double-double), "κ₁" the 1-norm condition number of
//! that scaled matrix; a route's cell is `Ok e` (relative error against double-double) or
//! `Err site κ̂` (the reported condition estimate). Dynamic states: three random `(u, u̇)`
//! with entries in ±1, the worst of them shown.

use std::collections::{BTreeMap, BTreeSet};

use references::dd;
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use runtime::scalar::{Singular, Site};

/// The relative accuracy an `Ok` result must reach against the double-double reference.
const ACCURACY: f64 = 1e-6;
/// An `Err` at a singularity must report a condition estimate at least the inverse of the
/// documented threshold of its site (`noc::LEG_TOLERANCE` for legs, `ACTUATION_TOLERANCE` for
/// `A`, `CONSTRAINT_TOLERANCE` for the legs' constraint couples; a reach failure or a zero
/// value may report infinity).
fn min_condition(site: Site) -> f64 {
    match site {
        Site::Leg(_) => 0.99 / noc::LEG_TOLERANCE,
        Site::Actuation(_) => 0.99 / noc::ACTUATION_TOLERANCE,
        Site::Constraint(_) => 0.99 / noc::CONSTRAINT_TOLERANCE,
        _ => 0.0,
    }
}

type Outcome = Result<Vec<f64>, Singular>;
type Route = fn(&[f64], &[f64], &[f64]) -> Outcome;
type DynRoute<'a> = Box<dyn Fn(&[f64], &[f64], &[f64]) -> Outcome + 'a>;

// ---------------------------------------------------------------------------------------------
// Models, poses, norms.

/// The model of a bundled parallel spec (looked up in `mechanisms/specs/`, then in
/// `mechanisms/specs-parallel/`).
fn model(name: &str) -> ParallelModel {
    tests::pkm::model(name)
}

/// The model of a platform spec in `tests/data/`.
fn data_model(file: &str) -> ParallelModel {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(file);
    let src = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => m,
        Ok(_) => panic!("{file} is not a parallel mechanism"),
        Err(d) => panic!("{d}"),
    }
}

fn plan(m: &ParallelModel) -> Plan {
    Plan::new(m).unwrap_or_else(|e| panic!("{}: {e}", m.name))
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

/// Rotation by `deg` degrees about base axis `axis` (0, 1, 2 = x, y, z).
fn axis_q(axis: usize, deg: f64) -> [f64; 4] {
    let h = deg.to_radians() / 2.0;
    let mut q = [h.cos(), 0.0, 0.0, 0.0];
    q[1 + axis] = h.sin();
    q
}

/// Exactly a quarter turn about `axis`, as the non-unit quaternion `(1, e)`: the evaluators
/// normalize (`2/|q|² = 1`), so the rotation matrix is exact.
fn quarter_q(axis: usize, sign: f64) -> [f64; 4] {
    let mut q = [1.0, 0.0, 0.0, 0.0];
    q[1 + axis] = sign;
    q
}

/// The home orientation of `m` as a unit quaternion.
fn home_q(m: &ParallelModel) -> [f64; 4] {
    tests::pkm::matrix_quaternion(&m.home.rotation)
}

/// `x` for the platform origin `p` (pose platforms) and orientation `q`.
fn coords(m: &ParallelModel, p: [f64; 3], q: [f64; 4]) -> Vec<f64> {
    match m.motion {
        PlatformMotion::Pose => vec![p[0], p[1], p[2], q[0], q[1], q[2], q[3]],
        PlatformMotion::Orientation { .. } => q.to_vec(),
        PlatformMotion::PlanarPoint { .. } => vec![p[0], p[1]],
        PlatformMotion::Translation { .. } => p.to_vec(),
        // φ from the home rotation: the quaternion's turn about z against home's.
        PlatformMotion::PlanarPose { .. } => {
            let h = home_q(m);
            let phi = 2.0 * (q[3] * h[0] - q[0] * h[3]).atan2(q[0] * h[0] + q[3] * h[3]);
            vec![p[0], p[1], phi]
        }
        // The tilts of R = Rz(γ)·Ry(β)·Rx(α) (home rotation the identity): α, β.
        // The tool's angle: the quaternion's turn about z.
        PlatformMotion::Schoenflies { .. } => {
            let theta = 2.0 * q[3].atan2(q[0]);
            vec![p[0], p[1], p[2], theta]
        }
        PlatformMotion::HeaveTilt { .. } => {
            let [w, a, b, c] = q;
            let n = w * w + a * a + b * b + c * c;
            let r20 = 2.0 * (a * c - w * b) / n;
            let r21 = 2.0 * (b * c + w * a) / n;
            let r22 = 1.0 - 2.0 * (a * a + b * b) / n;
            vec![p[2], r21.atan2(r22), (-r20).asin()]
        }
    }
}

fn home_x(m: &ParallelModel) -> Vec<f64> {
    tests::pkm::home_x(m)
}

/// `‖a − b‖∞ / ‖b‖∞` (infinite when anything is NaN).
fn rel(a: &[f64], b: &[f64]) -> f64 {
    tests::pkm::rel(a, b)
}

/// Three generic speed/rate states plus the static one.
fn states(dof: usize, seed: u64) -> Vec<(Vec<f64>, Vec<f64>)> {
    use rand::Rng;
    let mut rng = tests::rng(seed);
    let mut out = vec![(vec![0.0; dof], vec![0.0; dof])];
    for _ in 0..3 {
        let u = (0..dof).map(|_| rng.random_range(-1.0..1.0)).collect();
        let ud = (0..dof).map(|_| rng.random_range(-1.0..1.0)).collect();
        out.push((u, ud));
    }
    out
}

fn arr<const N: usize>(v: &[f64]) -> [f64; N] {
    let mut a = [0.0; N];
    a.copy_from_slice(v);
    a
}

/// The generated module's routes as [`Route`]s, their `Singular` mapped to the runtime's.
macro_rules! generated_routes {
    ($m:ident) => {
        mod $m {
            use mechanisms::$m as g;
            use runtime::scalar::Singular;

            pub fn err(e: g::Singular) -> Singular {
                Singular {
                    site: super::site_from_debug(&format!("{:?}", e.site)),
                    value: e.value,
                    condition_estimate: e.condition_estimate,
                }
            }
            pub fn inverse_dynamics(x: &[f64], u: &[f64], ud: &[f64]) -> super::Outcome {
                g::inverse_dynamics(&super::arr(x), &super::arr(u), &super::arr(ud))
                    .map(|t| t.to_vec())
                    .map_err(err)
            }
            pub fn forward_dynamics(x: &[f64], u: &[f64], tau: &[f64]) -> super::Outcome {
                g::forward_dynamics(&super::arr(x), &super::arr(u), &super::arr(tau))
                    .map(|t| t.to_vec())
                    .map_err(err)
            }
            pub fn actuator_rates(x: &[f64], u: &[f64], _: &[f64]) -> super::Outcome {
                g::actuator_rates(&super::arr(x), &super::arr(u))
                    .map(|t| t.to_vec())
                    .map_err(err)
            }
            pub fn inverse_kinematics(x: &[f64], _: &[f64], _: &[f64]) -> super::Outcome {
                g::inverse_kinematics(&super::arr(x))
                    .map(|t| t.to_vec())
                    .map_err(err)
            }
            pub fn mass_matrix(x: &[f64], _: &[f64], _: &[f64]) -> super::Outcome {
                g::mass_matrix(&super::arr(x))
                    .map(|m| m.iter().flatten().copied().collect())
                    .map_err(err)
            }
            pub fn actuator_mass_matrix(x: &[f64], _: &[f64], _: &[f64]) -> super::Outcome {
                g::actuator_mass_matrix(&super::arr(x))
                    .map(|m| m.iter().flatten().copied().collect())
                    .map_err(err)
            }
            pub const ROUTES: [(&str, super::Route); 6] = [
                ("inverse_dynamics", inverse_dynamics),
                ("forward_dynamics", forward_dynamics),
                ("actuator_rates", actuator_rates),
                ("inverse_kinematics", inverse_kinematics),
                ("mass_matrix", mass_matrix),
                ("actuator_mass_matrix", actuator_mass_matrix),
            ];
        }
    };
}
generated_routes!(gough_stewart);
generated_routes!(agile_eye);
generated_routes!(sliding_hexapod);
generated_routes!(rus_hexapod);
generated_routes!(planar_five_bar);
generated_routes!(delta_rl5);
generated_routes!(planar_3rrr);
generated_routes!(tsai_3upu);
generated_routes!(prs_head);
generated_routes!(delta4_rl5);

fn generated(name: &str) -> &'static [(&'static str, Route)] {
    match name {
        "gough_stewart" => &gough_stewart::ROUTES,
        "agile_eye" => &agile_eye::ROUTES,
        "sliding_hexapod" => &sliding_hexapod::ROUTES,
        "rus_hexapod" => &rus_hexapod::ROUTES,
        "planar_five_bar" => &planar_five_bar::ROUTES,
        "delta_rl5" => &delta_rl5::ROUTES,
        "planar_3rrr" => &planar_3rrr::ROUTES,
        "tsai_3upu" => &tsai_3upu::ROUTES,
        "prs_head" => &prs_head::ROUTES,
        "delta4_rl5" => &delta4_rl5::ROUTES,
        _ => panic!("no generated module {name}"),
    }
}

fn generated_id(name: &str) -> Route {
    generated(name)[0].1
}

// ---------------------------------------------------------------------------------------------
// The walk.

/// One point of a walk: `δ` (degrees from the singularity) and the coordinates.
struct Point {
    delta: f64,
    x: Vec<f64>,
}

/// The runtime's `Site` for the `Debug` text of a generated module's `Site` (each generated
/// module has its own copy of the type), through `Site::from_code`, so that variants added to
/// both later map without naming them here.
fn site_from_debug(d: &str) -> Site {
    let (name, index) = match d.split_once('(') {
        Some((n, rest)) => (n, rest.trim_end_matches(')').parse::<u16>().unwrap_or(0)),
        None => (d, 0),
    };
    let base = match name {
        "MassMatrix" => 0,
        "Leg" => 256,
        "Reach" => 512,
        "Actuation" => 768,
        "Platform" => 1024,
        "Input" => 1025,
        "Constraint" => 1536,
        other => panic!("unknown generated site {other}"),
    };
    let site = Site::from_code(base + index);
    assert_eq!(format!("{site:?}"), d, "site mapping");
    site
}

/// A short name of a site (its `Debug` text, `Actuation` shortened).
fn site_word(s: Site) -> String {
    format!("{s:?}").replace("Actuation", "Act")
}

fn cell(o: &Outcome, reference: &Outcome) -> String {
    match (o, reference) {
        (Ok(t), Ok(r)) => format!("Ok {:.1e}", rel(t, r)),
        (Ok(_), Err(_)) => "Ok (ref Err)".into(),
        (Err(e), _) => format!("Err {} {:.1e}", site_word(e.site), e.condition_estimate),
    }
}

/// The worst cell over several states: an `Err` beats an `Ok`; among `Ok`s the largest error.
fn worst_cell(cells: &[(Outcome, Outcome)]) -> String {
    let mut best: Option<(f64, String)> = None;
    for (o, r) in cells {
        let score = match (o, r) {
            (Ok(t), Ok(r)) => rel(t, r),
            _ => f64::INFINITY,
        };
        if best.as_ref().is_none_or(|(s, _)| score > *s) {
            best = Some((score, cell(o, r)));
        }
    }
    best.map(|b| b.1).unwrap_or_default()
}

/// One violation of the contract: what (without varying numbers), where (δ), a detail.
struct Violation {
    kind: String,
    delta: f64,
    detail: String,
}

/// Check one route's outcomes along a walk (points ordered toward the singularity; the last is
/// the singular pose itself) against the contract; returns the violations.
fn contract(
    walk: &[Point],
    outcomes: &[(Outcome, Outcome)],
    allowed: &[fn(Site) -> bool],
) -> Vec<Violation> {
    let mut bad = Vec::new();
    let mut push = |kind: &str, delta: f64, detail: String| {
        bad.push(Violation {
            kind: kind.into(),
            delta,
            detail,
        })
    };
    let mut failed_at: Option<f64> = None;
    for (p, (o, r)) in walk.iter().zip(outcomes) {
        let d = p.delta;
        match o {
            Ok(t) => {
                if t.iter().any(|v| !v.is_finite()) {
                    push("Ok with non-finite entries", d, format!("{t:?}"));
                }
                match r {
                    Ok(r) => {
                        let e = rel(t, r);
                        if e.is_nan() || e > ACCURACY {
                            push(
                                "Ok but not within 1e-6 (relative) of double-double",
                                d,
                                format!("{e:.1e}"),
                            );
                        }
                    }
                    Err(s) => push(
                        "Ok although the double-double route fails",
                        d,
                        site_word(s.site),
                    ),
                }
                if let Some(d0) = failed_at {
                    push(
                        "Ok again after an Err farther from the singularity",
                        d,
                        format!("Err at {d0:e}"),
                    );
                }
                if d == 0.0 {
                    push("Ok at the singular pose", d, String::new());
                }
            }
            Err(s) => {
                failed_at.get_or_insert(d);
                if !allowed.iter().any(|f| f(s.site)) {
                    push(
                        &format!("Err at an unexpected site {}", site_word(s.site)),
                        d,
                        format!("value {:.1e}", s.value),
                    );
                }
                if s.condition_estimate.is_nan() || s.condition_estimate < min_condition(s.site) {
                    push(
                        "Err with a condition estimate below the inverse of its threshold",
                        d,
                        format!("{:.1e}", s.condition_estimate),
                    );
                }
            }
        }
    }
    bad
}

/// Evaluate the runtime and the generated code along `walk` for each state, print the table,
/// return the violations of the contract.
fn walk_report(
    title: &str,
    plan: &Plan,
    walk: &[Point],
    states: &[(Vec<f64>, Vec<f64>)],
    generated: Option<Route>,
    allowed: &[fn(Site) -> bool],
) -> Vec<String> {
    let mut bad = Vec::new();
    // (route, kind) → δ → (a detail, states)
    type Found = BTreeMap<(String, String), BTreeMap<usize, (String, BTreeSet<usize>)>>;
    let mut violations: Found = BTreeMap::new();
    // outcomes[route][state][point]
    let mut table: Vec<Vec<Vec<(Outcome, Outcome)>>> = Vec::new();
    let routes: Vec<(&str, DynRoute<'_>)> = {
        let mut r: Vec<(&str, DynRoute<'_>)> = vec![(
            "runtime",
            Box::new(|x: &[f64], u: &[f64], ud: &[f64]| noc::inverse_dynamics(plan, x, u, ud)),
        )];
        if let Some(g) = generated {
            r.push(("generated", Box::new(g)));
        }
        r
    };
    let reference: Vec<Vec<Outcome>> = states
        .iter()
        .map(|(u, ud)| {
            walk.iter()
                .map(|p| dd::inverse_dynamics_dd(plan, &p.x, u, ud))
                .collect()
        })
        .collect();
    for (name, f) in &routes {
        let mut per_state = Vec::new();
        for (si, (u, ud)) in states.iter().enumerate() {
            let outs: Vec<(Outcome, Outcome)> = walk
                .iter()
                .zip(&reference[si])
                .map(|(p, r)| {
                    let o =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(&p.x, u, ud)))
                            .unwrap_or_else(|_| {
                                bad.push(format!(
                                    "{title}, {name}, state {si}, δ={:e}: panic",
                                    p.delta
                                ));
                                Err(Singular {
                                    site: Site::Platform,
                                    value: f64::NAN,
                                    condition_estimate: f64::NAN,
                                })
                            });
                    (o, r.clone())
                })
                .collect();
            for v in contract(walk, &outs, allowed) {
                let e = violations
                    .entry((name.to_string(), v.kind))
                    .or_default()
                    .entry(walk.iter().position(|p| p.delta == v.delta).unwrap_or(0))
                    .or_insert_with(|| (v.detail.clone(), BTreeSet::new()));
                if v.detail > e.0 {
                    e.0 = v.detail;
                }
                e.1.insert(si);
            }
            per_state.push(outs);
        }
        table.push(per_state);
    }
    // The table.
    println!("\n### {title}\n");
    let mut head = "| δ (deg) | κ pivots (dd) | κ₁ (dd) | ‖τ‖∞ static (dd) |".to_string();
    let mut rule = "|---:|---:|---:|---:|".to_string();
    for (name, _) in &routes {
        head.push_str(&format!(" {name}, static | {name}, dynamic (worst) |"));
        rule.push_str("---|---|");
    }
    println!("{head}\n{rule}");
    for (pi, p) in walk.iter().enumerate() {
        let cond = dd::actuation_dd(plan, &p.x).map(|a| dd::conditioning(&a));
        let (kp, k1) = match cond {
            Ok(c) => (
                format!("{:.2e}", c.pivot_ratio),
                format!("{:.2e}", c.kappa1),
            ),
            Err(e) => (format!("Err {}", site_word(e.site)), "—".into()),
        };
        let tau = match &reference[0][pi] {
            Ok(t) => format!("{:.2e}", t.iter().map(|v| v.abs()).fold(0.0, f64::max)),
            Err(e) => format!("Err {}", site_word(e.site)),
        };
        let mut line = format!("| {:e} | {kp} | {k1} | {tau} |", p.delta);
        for per_state in &table {
            let stat = cell(&per_state[0][pi].0, &per_state[0][pi].1);
            let dynamic: Vec<(Outcome, Outcome)> =
                per_state[1..].iter().map(|s| s[pi].clone()).collect();
            line.push_str(&format!(" {stat} | {} |", worst_cell(&dynamic)));
        }
        println!("{line}");
    }
    for ((route, kind), at) in violations {
        let list: Vec<String> = at
            .iter()
            .map(|(pi, (detail, states))| {
                let d = walk[*pi].delta;
                let st: Vec<String> = states.iter().map(|s| s.to_string()).collect();
                if detail.is_empty() {
                    format!("δ={d:e} [states {}]", st.join(","))
                } else {
                    format!("δ={d:e} ({detail}) [states {}]", st.join(","))
                }
            })
            .collect();
        bad.push(format!("{title}, {route}: {kind} at {}", list.join(", ")));
    }
    bad
}

fn finish(bad: &[String]) {
    if !bad.is_empty() {
        println!("\nVIOLATIONS ({}):", bad.len());
        for b in bad {
            println!("  {b}");
        }
        panic!(
            "{} violations of the documented failure behaviour; first: {}",
            bad.len(),
            bad[0]
        );
    }
}

/// δ = 10⁻¹ … 10⁻¹² degrees, then 0.
fn deltas() -> Vec<f64> {
    let mut d: Vec<f64> = (1..=12).map(|k| 10f64.powi(-k)).collect();
    d.push(0.0);
    d
}

// ---------------------------------------------------------------------------------------------
// Tests.

/// The double-double reference agrees with the `f64` runtime at generic states away from
/// singularities (sanity check of `references::dd::inverse_dynamics_dd`).
#[test]
fn reference_agrees_with_runtime_at_generic_states() {
    for name in [
        "gough_stewart",
        "sliding_hexapod",
        "rus_hexapod",
        "agile_eye",
        "delta_rl5",
        "planar_3rrr",
        "delta4_rl5",
    ] {
        let m = model(name);
        let plan = plan(&m);
        let home = home_x(&m);
        let mut rng = tests::rng(7);
        let mut worst: f64 = 0.0;
        for _ in 0..20 {
            use rand::Rng;
            let n = plan.dof();
            let d: Vec<f64> = (0..n)
                .map(|i| {
                    let a = if i < 3 { 0.1 } else { 0.02 * m.size() };
                    a * rng.random_range(-1.0..1.0)
                })
                .collect();
            let x = noc::retract(plan.motion, &home, &d);
            let u: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let ud: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let a = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
            let b = dd::inverse_dynamics_dd(&plan, &x, &u, &ud).unwrap();
            worst = worst.max(rel(&a, &b));
        }
        println!("{name}: f64 runtime vs double-double, worst relative error {worst:.2e}");
        assert!(worst < 1e-11, "{name}: {worst:e}");
    }
}

/// Gough–Stewart (Tsai's 6-UPS, base and platform joints on semi-regular hexagons, platform
/// centred over the base at home): the parallel (type-II) singularity at 90° yaw about the
/// vertical axis through the platform centre (Fichter 1986). Walk `ψ = 90° − δ` from home
/// (`x = [p_home, q_yaw(ψ) ⊗ q_home]`), `δ = 10⁻¹ … 10⁻¹²` degrees, then `δ = 0` with the exact
/// quarter-turn quaternion `(1, 0, 0, 1)`; the static state and three with `u, u̇` in ±1.
/// Measured (`--nocapture`):
///
/// | δ (deg) | κ pivots (dd) | κ₁ (dd) | ‖τ‖∞ static (dd) | runtime, static | runtime, dynamic (worst) | generated, static | generated, dynamic (worst) |
/// |---:|---:|---:|---:|---|---|---|---|
/// | 1e-1 | 2.22e2 | 1.72e3 | 7.94e3 | Ok 5.2e-14 | Ok 5.2e-14 | Ok 7.1e-14 | Ok 7.1e-14 |
/// | 1e-2 | 2.22e3 | 1.71e4 | 7.96e4 | Ok 1.2e-12 | Ok 1.2e-12 | Ok 1.7e-12 | Ok 1.7e-12 |
/// | 1e-3 | 2.22e4 | 1.71e5 | 7.96e5 | Ok 7.6e-12 | Ok 7.6e-12 | Ok 1.3e-11 | Ok 1.3e-11 |
/// | 1e-4 | 2.22e5 | 1.71e6 | 7.96e6 | Ok 4.8e-11 | Ok 4.8e-11 | Ok 5.1e-11 | Ok 5.1e-11 |
/// | 1e-5 | 2.22e6 | 1.71e7 | 7.96e7 | Ok 4.1e-10 | Ok 4.1e-10 | Ok 2.0e-10 | Ok 2.0e-10 |
/// | 1e-6 | 2.22e7 | 1.71e8 | 7.96e8 | Ok 4.5e-9 | Ok 4.5e-9 | Ok 8.0e-10 | Ok 8.0e-10 |
/// | 1e-7 | 2.22e8 | 1.71e9 | 7.96e9 | Err Act(5) 2.2e8 | Err Act(5) 2.2e8 | Err Act(5) 2.2e8 | Err Act(5) 2.2e8 |
/// | 1e-8 | 2.22e9 | 1.71e10 | 7.96e10 | Err Act(5) 2.2e9 | Err Act(5) 2.2e9 | Err Act(5) 2.2e9 | Err Act(5) 2.2e9 |
/// | 1e-9 | 2.22e10 | 1.71e11 | 7.96e11 | Err Act(5) 2.2e10 | Err Act(5) 2.2e10 | Err Act(5) 2.2e10 | Err Act(5) 2.2e10 |
/// | 1e-10 | 2.22e11 | 1.71e12 | 7.96e12 | Err Act(5) 2.2e11 | Err Act(5) 2.2e11 | Err Act(5) 2.2e11 | Err Act(5) 2.2e11 |
/// | 1e-11 | 2.22e12 | 1.71e13 | 7.95e13 | Err Act(5) 2.2e12 | Err Act(5) 2.2e12 | Err Act(5) 2.2e12 | Err Act(5) 2.2e12 |
/// | 1e-12 | 2.22e13 | 1.72e14 | 7.97e14 | Err Act(5) 2.2e13 | Err Act(5) 2.2e13 | Err Act(5) 2.2e13 | Err Act(5) 2.2e13 |
/// | 0 | 1.03e32 | 7.98e32 | 3.45e33 | Err Act(5) 4.2e15 | Err Act(5) 4.2e15 | Err Act(5) 1.4e16 | Err Act(5) 1.4e16 |
///
/// The conditioning grows exactly like 1/δ (pivot ratio ≈ 22.2/δ°), so the singularity is at
/// 90° to within the rounding of the spec's constants (at δ = 0 double-double sees a pivot
/// ratio of 1.0e32: `A`'s rows, `[(R p_i) × s_i; s_i]` in the closed-form UPS leg, are singular
/// to its precision). Both `f64` routes are accurate to ≤ 4.5e-9 (about `ε` times the pivot
/// ratio) while they answer and switch to `Err(Actuation(5))` between δ = 1e-6° and 1e-7°
/// (the 1e-8 pivot-ratio tolerance), with condition estimates that track the double-double
/// pivot ratio. The relative error is the same for every state: near the singularity `τ` is
/// dominated by its component along the null direction of `Aᵀ`, whose relative error is that of
/// the small pivot.
#[test]
fn gough_stewart_yaw_singularity() {
    let m = model("gough_stewart");
    let plan = plan(&m);
    let p = m.home.translation;
    let qh = home_q(&m);
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| {
            let q = if d == 0.0 {
                quarter_q(2, 1.0)
            } else {
                axis_q(2, 90.0 - d)
            };
            Point {
                delta: d,
                x: coords(&m, p, qmul(q, qh)),
            }
        })
        .collect();
    // Sanity: the singularity is really at 90°: the double-double condition grows like 1/δ.
    let k = |d: usize| dd::conditioning(&dd::actuation_dd(&plan, &walk[d].x).unwrap()).pivot_ratio;
    assert!(k(11) > 1e12 && k(11) / k(5) > 1e5, "{} {}", k(5), k(11));
    let bad = walk_report(
        "Gough–Stewart, yaw ψ = 90° − δ",
        &plan,
        &walk,
        &states(6, 0x6f),
        Some(generated_id("gough_stewart")),
        &[|s| matches!(s, Site::Actuation(_))],
    );
    finish(&bad);
}

/// Agile Eye (spherical 3-RRR, exact Agile-Eye geometry): the platform turned by
/// `R_x(30°)·R_y(90° − δ)`, which carries the platform axis `v₁ = z` of leg 1 onto its base axis
/// `u₁ = x` at `δ = 0` while `v₂`, `v₃` stay generic. There `u₁, w₁, v₁` become coplanar (a leg
/// singularity of leg 1) and, as docs/method.md, "Where the method fails", says for this geometry, the actuation matrix
/// becomes singular with it (its scaled pivot ratio grows like 1/δ). `δ = 0` uses the exact
/// quarter-turn quaternion for `R_y(90°)`.
///
/// Measured (`--nocapture`; states: static, then three with `u, u̇` in ±1):
///
/// | δ (deg) | κ pivots (dd) | κ₁ (dd) | ‖τ‖∞ static (dd) | runtime, static | runtime, dynamic (worst) | generated, static | generated, dynamic (worst) |
/// |---:|---:|---:|---:|---|---|---|---|
/// | 1e-1 | 4.96e2 | 9.98e2 | 8.46e1 | Ok 2.2e-14 | Ok 2.1e-13 | Ok 2.2e-14 | Ok 2.0e-13 |
/// | 1e-2 | 4.96e3 | 9.93e3 | 8.47e2 | Ok 3.5e-13 | Ok 2.0e-12 | Ok 3.5e-13 | Ok 1.8e-12 |
/// | 1e-3 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e4 | Err Leg(0) 5.7e4 | Err Leg(0) 5.7e4 | Err Leg(0) 5.7e4 |
/// | 1e-4 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e5 | Err Leg(0) 5.7e5 | Err Leg(0) 5.7e5 | Err Leg(0) 5.7e5 |
/// | 1e-5 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e6 | Err Leg(0) 5.7e6 | Err Leg(0) 5.7e6 | Err Leg(0) 5.7e6 |
/// | 1e-6 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e7 | Err Leg(0) 5.7e7 | Err Leg(0) 5.7e7 | Err Leg(0) 5.7e7 |
/// | 1e-7 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e8 | Err Leg(0) 5.7e8 | Err Leg(0) 5.7e8 | Err Leg(0) 5.7e8 |
/// | 1e-8 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e9 | Err Leg(0) 5.7e9 | Err Leg(0) 5.7e9 | Err Leg(0) 5.7e9 |
/// | 1e-9 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e10 | Err Leg(0) 5.7e10 | Err Leg(0) 5.7e10 | Err Leg(0) 5.7e10 |
/// | 1e-10 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e11 | Err Leg(0) 5.7e11 | Err Leg(0) 5.7e11 | Err Leg(0) 5.7e11 |
/// | 1e-11 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.7e12 | Err Leg(0) 5.7e12 | Err Leg(0) 5.7e12 | Err Leg(0) 5.7e12 |
/// | 1e-12 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) 5.8e13 | Err Leg(0) 5.8e13 | Err Leg(0) 5.8e13 | Err Leg(0) 5.8e13 |
/// | 0 | Err Leg(0) | — | Err Leg(0) | Err Leg(0) inf | Err Leg(0) inf | Err Leg(0) inf | Err Leg(0) inf |
///
/// Both `f64` routes answer to ≤ 2.1e-13 at δ ≥ 1e-2° and return `Err(Leg(0))` from
/// δ = 1e-3° on, where the leg's scaled determinant (≈ δ in radians) falls below
/// `LEG_TOLERANCE` (1e-4), with condition estimates growing like 1/δ. The double-double route
/// applies the same leg test, hence its `Err Leg(0)`. The tolerance is what keeps this leg's
/// closed-form inverse kinematics (Paden–Kahan subproblem 2, whose `γ² ~ δ²` is formed with an
/// absolute error ~ε, so the first angle is off by ~ε/δ²) out of `Ok` answers: the
/// velocity-dependent terms grow like 1/δ² and would carry that error.
#[test]
fn agile_eye_leg_and_parallel_singularity() {
    let m = model("agile_eye");
    let plan = plan(&m);
    let qh = home_q(&m);
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| {
            let qy = if d == 0.0 {
                quarter_q(1, 1.0)
            } else {
                axis_q(1, 90.0 - d)
            };
            Point {
                delta: d,
                x: coords(&m, [0.0; 3], qmul(qmul(axis_q(0, 30.0), qy), qh)),
            }
        })
        .collect();
    let k = |d: usize| dd::conditioning(&dd::actuation_dd(&plan, &walk[d].x).unwrap()).pivot_ratio;
    // The pivot ratio of `A` grows as the walk closes in (the legs' threshold stops the
    // double-double route too below δ ≈ 6e-3°).
    assert!(k(1) / k(0) > 5.0, "{} {}", k(0), k(1));
    let bad = walk_report(
        "Agile Eye, R_x(30°)·R_y(90° − δ): v₁ → u₁",
        &plan,
        &walk,
        &states(3, 0xae),
        Some(generated_id("agile_eye")),
        &[
            |s| matches!(s, Site::Leg(_)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
}

/// The planar five-bar walked to its outer boundary: the point `P` moves along a ray from the
/// left base joint `A1` until the left leg is stretched straight (`|P − A1| = l1 + l2 =
/// 0.45 m`), a leg (type-I) singularity where the two elbow branches meet. `δ` is here the
/// distance from the boundary in metres (1e-1 … 1e-12 m, then 0).
#[test]
fn planar_five_bar_boundary_singularity() {
    let m = model("planar_five_bar");
    let plan = plan(&m);
    let (c, s) = (70f64.to_radians().cos(), 70f64.to_radians().sin());
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| {
            let r = 0.45 - d;
            Point {
                delta: d,
                x: vec![-0.1 + r * c, r * s],
            }
        })
        .collect();
    let bad = walk_report(
        "Planar five-bar, |P − A1| = 0.45 m − δ (left leg stretched)",
        &plan,
        &walk,
        &states(2, 0xfb),
        Some(generated_id("planar_five_bar")),
        &[
            |s| matches!(s, Site::Leg(_)),
            |s| matches!(s, Site::Reach(_)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
}

/// Delta (`delta_rl5`): leg 0's boundary, where its elbow circle touches the sphere of the rod
/// length about its platform point `P₀` (the arm and the rod in one line, stretched): the two
/// elbow branches meet and the leg Jacobian's scalar `d·(a × (E − O))` vanishes, a leg
/// (type-I) singularity. The platform moves in leg 0's plane (y = 0) along the line from the
/// motor axis `O₀` through `P₀` at home, `|P₀ − O₀| = l_arm + l_rod − δ` m (1e-1 … 1e-12 m,
/// then 0).
#[test]
fn delta_stretched_leg_singularity() {
    let m = model("delta_rl5");
    let plan = plan(&m);
    let (o, p0): ([f64; 3], [f64; 3]) = ([0.33, 0.0, 0.0], [0.125, 0.0, -1.0]);
    let dir = [p0[0] - o[0], 0.0, p0[2] - o[2]];
    let n = (dir[0] * dir[0] + dir[2] * dir[2]).sqrt();
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| {
            let r = 0.42 + 1.055 - d;
            Point {
                delta: d,
                x: vec![o[0] + r * dir[0] / n - 0.125, 0.0, o[2] + r * dir[2] / n],
            }
        })
        .collect();
    let bad = walk_report(
        "Delta, |P₀ − O₀| = 1.475 m − δ (leg 0 stretched)",
        &plan,
        &walk,
        &states(3, 0xde),
        Some(generated_id("delta_rl5")),
        &[
            |s| matches!(s, Site::Leg(0)),
            |s| matches!(s, Site::Reach(0)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
}

/// Delta (`delta_rl5`): a parallel (type-II) singularity inside the workspace, where the three
/// rod directions become coplanar (the rows `dᵀ/s` of `A` dependent) while every leg stays
/// regular (`|d·(a × (E − O))| ≈ 0.24`, far from the leg test). Found on the line `y = 0.1 m`,
/// `z = −0.6 m`: `x*` is where the runtime's `det A` changes sign between 1.0 and 1.04 m
/// (bisection to rounding); the walk is `x = x* − δ` (1e-1 … 1e-12 m, then `x*`). (Off the
/// symmetry plane `y = 0` on purpose: there the singular direction is `e_y` itself, `A`'s
/// second column vanishes, and the unit-column scaling of the pivot test normalizes it back to
/// a regular-looking matrix, so the test misses it; see the report of issue 20.)
#[test]
fn delta_parallel_singularity() {
    delta_type_two(0.1);
}

/// The Delta's type-II singularity on its symmetry plane `y = 0`: there the uncontrollable
/// direction is the `x` axis, so a column of `A` vanishes while the others stay. Scaling each
/// column by its own norm made that `A` look regular (`Ok` with errors up to 6e-2 at 1e-11 m);
/// the columns of one unit group are scaled together now (`PlatformMotion::unit_groups`).
#[test]
fn delta_parallel_singularity_on_its_symmetry_plane() {
    delta_type_two(0.0);
}

/// A walk in `x` toward the Delta's type-II singularity at height `z = −0.6 m` and `y`.
fn delta_type_two(y: f64) {
    let m = model("delta_rl5");
    let plan = plan(&m);
    let det = |x: f64| {
        let a = noc::actuation(&plan, &[x, y, -0.6]).unwrap();
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let (mut lo, mut hi) = (1.0, 1.04);
    assert!(det(lo) * det(hi) < 0.0, "no sign change of det A");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if det(mid) * det(lo) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let xs = lo;
    println!("Delta: det A changes sign at x* = {xs} m (y = {y} m, z = -0.6 m)");
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: vec![xs - d, y, -0.6],
        })
        .collect();
    let bad = walk_report(
        "Delta, x = x* − δ (rods coplanar)",
        &plan,
        &walk,
        &states(3, 0xd2),
        Some(generated_id("delta_rl5")),
        &[|s| matches!(s, Site::Actuation(_))],
    );
    finish(&bad);
}

/// 4-axis Delta (`delta4_rl5`): the Delta's leg 1 (its first Delta leg; leg 0 is the shaft)
/// stretched as in `delta_stretched_leg_singularity`, the tool turned by 40°: `Leg(1)`, then
/// `Reach(1)`.
#[test]
fn delta4_stretched_leg_singularity() {
    let m = model("delta4_rl5");
    let plan = plan(&m);
    let (o, p0): ([f64; 3], [f64; 3]) = ([0.33, 0.0, 0.0], [0.125, 0.0, -1.0]);
    let dir = [p0[0] - o[0], 0.0, p0[2] - o[2]];
    let n = (dir[0] * dir[0] + dir[2] * dir[2]).sqrt();
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| {
            let r = 0.42 + 1.055 - d;
            Point {
                delta: d,
                x: vec![
                    o[0] + r * dir[0] / n - 0.125,
                    0.0,
                    o[2] + r * dir[2] / n,
                    40f64.to_radians(),
                ],
            }
        })
        .collect();
    let bad = walk_report(
        "4-axis Delta, |P₁ − O₁| = 1.475 m − δ (leg 1 stretched)",
        &plan,
        &walk,
        &states(4, 0xd4),
        Some(generated_id("delta4_rl5")),
        &[
            |s| matches!(s, Site::Leg(1)),
            |s| matches!(s, Site::Reach(1)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
}

/// 4-axis Delta (`delta4_rl5`): the Delta's type-II singularity (the rods coplanar) at
/// `y = 0.1 m`, `z = −0.6 m`, `x* − δ`, the tool turned by −70°: the shaft's row `(0, 0, 0, 1)`
/// of `A` does not help, `Actuation(_)`.
#[test]
fn delta4_parallel_singularity() {
    let m = model("delta4_rl5");
    let plan = plan(&m);
    let (y, th) = (0.1, (-70f64).to_radians());
    // The Delta legs' 3 × 3 block of A (rows 1..4, columns 0..3).
    let det = |x: f64| {
        let a = noc::actuation(&plan, &[x, y, -0.6, th]).unwrap();
        let b = |r: usize, c: usize| a[r + 1][c];
        b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1))
            - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0))
            + b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0))
    };
    let (mut lo, mut hi) = (1.0, 1.04);
    assert!(det(lo) * det(hi) < 0.0, "no sign change of det A");
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if det(mid) * det(lo) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let xs = lo;
    println!("4-axis Delta: det A changes sign at x* = {xs} m (y = {y} m, z = -0.6 m)");
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: vec![xs - d, y, -0.6, th],
        })
        .collect();
    let bad = walk_report(
        "4-axis Delta, x = x* − δ (rods coplanar)",
        &plan,
        &walk,
        &states(4, 0xd5),
        Some(generated_id("delta4_rl5")),
        &[|s| matches!(s, Site::Actuation(_))],
    );
    finish(&bad);
}

/// 4-axis Delta (`delta4_rl5`): the shaft's upper U at its gimbal lock, the tube levelled out
/// along the U's first axis (the tube at right angles to the motor axis: `cos θ₂ → 0`). The
/// carrier at `(0.3, 0, −0.15 − δ)`, `θ = 0`, puts the lower U's centre at the height of the
/// upper one. This lies far outside the Delta's reach (its legs would answer `Reach`), but the
/// shaft is leg 0 and its test comes first: `Reach(1)` while the shaft is regular, `Leg(0)` at
/// the lock (`cos² θ₂ ≤ SHAFT_TOLERANCE`, δ ≲ 3e-5 m).
#[test]
fn delta4_shaft_gimbal_lock() {
    let m = model("delta4_rl5");
    let plan = plan(&m);
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: vec![0.3, 0.0, -0.15 - d, 0.0],
        })
        .collect();
    let bad = walk_report(
        "4-axis Delta, carrier at (0.3, 0, −0.15 − δ) (the shaft's U at its gimbal lock)",
        &plan,
        &walk,
        &states(4, 0xd6),
        Some(generated_id("delta4_rl5")),
        &[
            |s| matches!(s, Site::Leg(0)),
            |s| matches!(s, Site::Reach(1)),
        ],
    );
    finish(&bad);
    for (u, ud) in states(4, 0xd6) {
        let e = noc::inverse_dynamics(&plan, &[0.3, 0.0, -0.15, 0.0], &u, &ud).unwrap_err();
        assert_eq!(e.site, Site::Leg(0));
        let g = generated_id("delta4_rl5")(&[0.3, 0.0, -0.15, 0.0], &u, &ud).unwrap_err();
        assert_eq!(g.site, Site::Leg(0));
    }
    // The tube's length to zero (the carrier's tool point at the upper U): `Reach(0)`.
    let e = noc::inverse_kinematics(&plan, &[0.0, 0.0, -0.15, 0.0]).unwrap_err();
    assert_eq!(e.site, Site::Reach(0));
}

/// Planar 3-RRR (`planar_3rrr`, task coordinates `[px, py, φ]`): leg 0's boundary, its
/// proximal and distal links in one line (stretched, `|B₀ − A₀| = l₁ + l₂`): the leg Jacobian's
/// determinant vanishes, a leg (type-I) singularity. The platform keeps its home rotation
/// (`φ = 0`) and moves so that `B₀` runs along the line from `A₀` through `B₀`'s home position,
/// `|B₀ − A₀| = l₁ + l₂ − δ = 0.8 m − δ` (1e-1 … 1e-12 m, then 0; the links of
/// `mechanisms/specs/planar_3rrr.toml`, 0.4 m each). Measured (`--nocapture`): both `f64`
/// routes `Ok` to ≤ 2.3e-9 against double-double down to δ = 1e-8 m, then `Err(Leg(0))` from
/// 1e-9 m (double-double too) to δ = 0 (where double-double reports `Reach(0)`); 1 mm beyond,
/// `Err(Reach(0))` from both.
#[test]
fn planar_3rrr_stretched_leg_singularity() {
    let m = model("planar_3rrr");
    let plan = plan(&m);
    let home = home_x(&m);
    let (a0, b0) = planar_3rrr_leg0(&m);
    let dir = [b0[0] - a0[0], b0[1] - a0[1]];
    let n = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| {
            let r = 0.8 - d;
            // The platform origin that puts B₀ at A₀ + r·dir (B₀ − origin is fixed at φ = 0).
            let p = [
                a0[0] + r * dir[0] / n - (b0[0] - home[0]),
                a0[1] + r * dir[1] / n - (b0[1] - home[1]),
            ];
            Point {
                delta: d,
                x: vec![p[0], p[1], 0.0],
            }
        })
        .collect();
    let bad = walk_report(
        "Planar 3-RRR, |B₀ − A₀| = 0.8 m − δ (leg 0 stretched)",
        &plan,
        &walk,
        &states(3, 0x3e),
        Some(generated_id("planar_3rrr")),
        &[
            |s| matches!(s, Site::Leg(0)),
            |s| matches!(s, Site::Reach(0)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
    // Beyond the boundary (1 mm further): out of reach, generated and runtime alike.
    let x = {
        let r = 0.801;
        [
            a0[0] + r * dir[0] / n - (b0[0] - home[0]),
            a0[1] + r * dir[1] / n - (b0[1] - home[1]),
            0.0,
        ]
    };
    let e = noc::inverse_kinematics(&plan, &x).unwrap_err();
    assert_eq!(e.site, Site::Reach(0), "{e:?}");
    let g = mechanisms::planar_3rrr::inverse_dynamics(&x, &[0.0; 3], &[0.0; 3]).unwrap_err();
    assert_eq!(site_from_debug(&format!("{:?}", g.site)), Site::Reach(0));
}

/// Leg 0's base joint `A₀` and platform joint `B₀` at home (base frame, in the plane).
fn planar_3rrr_leg0(m: &ParallelModel) -> ([f64; 2], [f64; 2]) {
    let a = m.legs[0].joints[0].origin.translation;
    let runtime::parallel::LegEnd::Spherical { on_platform, .. } = m.legs[0].end else {
        panic!("a planar leg ends in a point")
    };
    let b = m.home.apply(&on_platform);
    ([a[0], a[1]], [b[0], b[1]])
}

/// Planar 3-RRR: a parallel (type-II) singularity, where the three distal links' lines meet in
/// one point (the rows of `A` dependent) while every leg stays regular. Found by turning the
/// platform about its origin at home position: `φ*` is where the runtime's `det A` changes sign
/// (bisection to rounding, legs regular); the walk is `φ = φ* − δ` (1e-1 … 1e-12 rad, then `φ*`).
/// Measured: `φ* = 0.7406672962…` rad; both `f64` routes `Ok` to ≤ 1.3e-8 against
/// double-double (pivot ratio 1.6e7 at 1e-9 rad) down to δ = 1e-9 rad, then `Err(Actuation(2))`
/// from 1e-10 rad.
#[test]
fn planar_3rrr_parallel_singularity() {
    let m = model("planar_3rrr");
    let plan = plan(&m);
    let home = home_x(&m);
    let det = |phi: f64| {
        let a = noc::actuation(&plan, &[home[0], home[1], phi]).ok()?;
        Some(
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]),
        )
    };
    // The first sign change of det A from home, turning counter-clockwise in 0.01 rad steps.
    let mut lo = 0.0;
    let mut d_lo = det(lo).unwrap();
    let mut hi = lo;
    loop {
        hi += 0.01;
        assert!(hi < 3.2, "no sign change of det A");
        let d_hi = det(hi).expect("legs regular on the way");
        if d_lo * d_hi < 0.0 {
            break;
        }
        lo = hi;
        d_lo = d_hi;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if det(mid).unwrap() * d_lo > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let ps = lo;
    println!("Planar 3-RRR: det A changes sign at φ* = {ps} rad (origin at home)");
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: vec![home[0], home[1], ps - d],
        })
        .collect();
    let bad = walk_report(
        "Planar 3-RRR, φ = φ* − δ (distal links concurrent)",
        &plan,
        &walk,
        &states(3, 0x3f),
        Some(generated_id("planar_3rrr")),
        &[|s| matches!(s, Site::Actuation(_))],
    );
    finish(&bad);
}

/// Tsai's 3-UPU (`tsai_3upu`): leg 0 turns toward its base U's first axis (the tangent
/// `e₀ = e_y` at `B₀ = (0.3, 0, 0)`): the platform at `(0.15, 0.3, δ)` puts leg 0's platform
/// U centre at `(0.3, 0.3, δ)`, so the leg direction tends to `e₀` and the U's second axis
/// `e₀ × s` is lost (a leg singularity, `|e₀ × s| → 0`). With every base U's first axis in the
/// base plane (Tsai's arrangement) a leg can lie along it only at `z = 0`, where all three legs
/// lie in the base plane and `A` is singular too: both kinds meet there. Measured: `A`'s pivot
/// test reports `Actuation(2)` from δ = 1e-9 m, and the UPS leg's own test (`|e₀ × s| > 0`)
/// `Leg(0)` at δ = 0, runtime and generated alike; the dynamic error grows to 1.9e-9 at 1e-7 m
/// before that.
#[test]
fn upu_leg_singularity() {
    let m = model("tsai_3upu");
    let plan = plan(&m);
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: vec![0.15, 0.3, d],
        })
        .collect();
    let bad = walk_report(
        "3-UPU, platform at (0.15, 0.3, δ) (leg 0 along its base U's first axis)",
        &plan,
        &walk,
        &states(3, 0x0b0),
        Some(generated_id("tsai_3upu")),
        &[
            |s| matches!(s, Site::Leg(0)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
}

/// Tsai's 3-UPU (`tsai_3upu`): the platform lowered into the base plane, `(0, 0, δ)`: the three
/// leg directions `s_k` (the rows of `A`) become coplanar while every leg stays regular (each
/// leg radial, `|e₀ × s| = 1`), a parallel (type-II) singularity. It is a constraint
/// singularity as well: each leg's couple (normal to its base U's two axes, `s` less its
/// component along the tangent `e₀`) is `∝ −(a − b) r_k + δ e_z` here, so the three turn
/// horizontal and the platform gains the turn about `z` (every U's second axis is vertical in
/// the base plane). The couples' test is the looser one: `Constraint(2)` from δ = 1e-6 m (its
/// pivot is 20 δ), runtime, generated and double-double alike; `A`'s own pivot test would
/// answer only below 1e-10 m (`Actuation(2)` before the couples were tested).
#[test]
fn upu_parallel_singularity() {
    let m = model("tsai_3upu");
    let plan = plan(&m);
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: vec![0.0, 0.0, d],
        })
        .collect();
    let bad = walk_report(
        "3-UPU, platform at (0, 0, δ) (legs coplanar)",
        &plan,
        &walk,
        &states(3, 0x0b1),
        Some(generated_id("tsai_3upu")),
        &[
            |s| matches!(s, Site::Constraint(_)),
            |s| matches!(s, Site::Actuation(_)),
        ],
    );
    finish(&bad);
}

/// The determinant of the unit constraint couples of the legs at `x` (positions only, no
/// test), with the couples.
fn couple_det(plan: &Plan, x: &[f64]) -> f64 {
    let (_, legs) = noc::positions(plan, x).unwrap();
    let c: Vec<[f64; 3]> = noc::constraint_couples(plan, &legs)
        .into_iter()
        .map(|v| {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / n, v[1] / n, v[2] / n]
        })
        .collect();
    assert_eq!(c.len(), 3);
    c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
        - c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0])
        + c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0])
}

/// Tsai's 3-UPU (`tsai_3upu`): a constraint singularity away from every other kind. Each leg is
/// held by one couple, normal to both of its base U's axes (the platform U's are parallel to
/// them). With the base U's first axis `e₀ₖ` tangent to the base circle (radius `a = 0.3 m`,
/// legs at 0°, 120°, 240°, radial directions `rₖ`), its second axis at right angles to the leg
/// and the platform U's centres on a circle of radius `b = 0.15 m`, the couple is the leg
/// direction less its component along `e₀ₖ`: `nₖ ∝ cₖ rₖ + z e_z` with `cₖ = p·rₖ − (a − b)`
/// for the platform at `p = (px, py, z)`. Then `det[n₀ n₁ n₂] ∝ z (c₀c₁ + c₁c₂ + c₂c₀)`, and
/// from `Σ cₖ = −3 (a − b)`, `Σ cₖ² = (3/2) |p_xy|² + 3 (a − b)²`:
/// `c₀c₁ + c₁c₂ + c₂c₀ = 3 (a − b)² − (3/4) |p_xy|²`. So above the base plane the couples
/// are coplanar exactly where the platform's centre is `2 (a − b) = 0.3 m` from the axis, at
/// every height: there the platform gains a rotation no leg resists (about `(z, 0, −(a − b))`
/// turned to the walk's direction), while every leg and `A` stay regular. The walk: at 40° and
/// `z = 0.35 m`, `|p_xy| = 0.3 m − δ` (1e-1 … 1e-12 m, then 0); the runtime's couple
/// determinant is checked to change sign across `0.3 m` first. Measured (`--nocapture`): `Ok`
/// (errors ≤ 5.8e-16 against double-double, `A` well conditioned throughout) down to
/// δ = 1e-5 m, `Err(Constraint(2))` from 1e-6 m to δ = 0 (the pivot is about 10 δ, so the test
/// answers within about 1e-5 m), runtime, generated and double-double alike.
#[test]
fn upu_constraint_singularity() {
    let m = model("tsai_3upu");
    let plan = plan(&m);
    let (c, s) = (40f64.to_radians().cos(), 40f64.to_radians().sin());
    let at = |r: f64| vec![r * c, r * s, 0.35];
    let (inside, outside) = (couple_det(&plan, &at(0.299)), couple_det(&plan, &at(0.301)));
    assert!(
        inside * outside < 0.0,
        "the couples' determinant keeps its sign across |p_xy| = 0.3 m: {inside:e}, {outside:e}"
    );
    assert!(couple_det(&plan, &at(0.3)).abs() < 1e-14);
    let walk: Vec<Point> = deltas()
        .into_iter()
        .map(|d| Point {
            delta: d,
            x: at(0.3 - d),
        })
        .collect();
    let bad = walk_report(
        "3-UPU, |p_xy| = 0.3 m − δ at 40°, z = 0.35 m (the legs' couples coplanar)",
        &plan,
        &walk,
        &states(3, 0x0b2),
        Some(generated_id("tsai_3upu")),
        &[|s| matches!(s, Site::Constraint(_))],
    );
    finish(&bad);
    // The other functions that test the legs' Jacobians fail there too, generated and runtime;
    // the positions alone do not.
    let x = at(0.3);
    for (name, f) in generated("tsai_3upu") {
        let o = f(&x, &[0.1, 0.2, 0.3], &[0.3, 0.2, 0.1]);
        if *name == "inverse_kinematics" {
            assert!(o.is_ok(), "{name}: {o:?}");
        } else {
            assert!(
                matches!(
                    o,
                    Err(Singular {
                        site: Site::Constraint(_),
                        ..
                    })
                ),
                "{name}: {o:?}"
            );
        }
    }
    assert!(noc::inverse_kinematics(&plan, &x).is_ok());
    for e in [
        noc::mass_matrix(&plan, &x).map(|_| ()),
        noc::actuator_rates(&plan, &x, &[0.1, 0.2, 0.3]).map(|_| ()),
        noc::forward_dynamics(&plan, &x, &[0.0; 3], &[1.0; 3]).map(|_| ()),
    ] {
        assert!(
            matches!(
                e,
                Err(Singular {
                    site: Site::Constraint(_),
                    ..
                })
            ),
            "{e:?}"
        );
    }
}

/// A platform axis approaching the base axis of a *different* leg (`v₂ → u₃` by
/// `R_z(30°)·R_y(−90° + δ)`, `v₁`, `v₃` generic) is *not* singular for the exact Agile-Eye
/// geometry: the actuation matrix stays well conditioned (scaled pivot ratio → √3) and the
/// runtime is accurate to ~1e-16 all the way to δ = 0. Recorded so the claim is checked.
#[test]
fn agile_eye_other_leg_axis_is_not_singular() {
    let m = model("agile_eye");
    let plan = plan(&m);
    let qh = home_q(&m);
    for d in deltas() {
        let qy = if d == 0.0 {
            quarter_q(1, -1.0)
        } else {
            axis_q(1, -90.0 + d)
        };
        let x = coords(&m, [0.0; 3], qmul(qmul(axis_q(2, 30.0), qy), qh));
        let c = dd::conditioning(&dd::actuation_dd(&plan, &x).unwrap());
        assert!(c.pivot_ratio < 10.0, "δ={d:e}: {c:?}");
        for (u, ud) in states(3, 1) {
            let a = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
            let b = dd::inverse_dynamics_dd(&plan, &x, &u, &ud).unwrap();
            assert!(rel(&a, &b) < 1e-13, "δ={d:e}: {:e}", rel(&a, &b));
        }
    }
}

/// The runtime evaluators (`noc::*`) and the generated code under NaN and ±∞ in any one input
/// (`x`, `u`, `u̇` or `τ`) of every bundled parallel mechanism at home: `Err`, or `Ok` with
/// finite entries; never a panic, never NaN or ∞ returned as `Ok`.
///
/// Measured against the current runtime: every such input gives `Err(Site::Input)` from every
/// route, runtime and generated (no panics). (Before `noc::check_finite` was added during this
/// work, a non-finite `u`, `u̇` or `τ` went straight through: `inverse_dynamics`,
/// `forward_dynamics` and `actuator_rates` returned `Ok` with NaN or ±∞ entries for all four
/// mechanisms, and the generated `gough_stewart::inverse_kinematics` returned `Ok([±inf; …])`
/// for an infinite position.)
#[test]
fn non_finite_inputs() {
    let bad = probe_inputs(&[
        (f64::NAN, "NaN"),
        (f64::INFINITY, "±inf"),
        (f64::NEG_INFINITY, "±inf"),
    ]);
    finish(&bad);
}

/// Finite inputs so large that the evaluation overflows (one entry of `x`, `u`, `u̇` or `τ`
/// set to ±1e300): the same contract, `Err` or finite `Ok`, never NaN or ∞ as `Ok`.
///
/// Measured: **violated**. `inverse_dynamics` and `forward_dynamics` (runtime and generated)
/// return `Ok` with NaN for a speed `u` of ±1e300 (the quadratic velocity terms overflow to ∞,
/// then ∞ − ∞; all four mechanisms, 20 of 21 entries). The generated `inverse_kinematics`
/// returns `Ok([±inf; …])` for a Gough–Stewart position entry of ±1e300 (the runtime says
/// `Err(Leg(0))`: its U-joint checks run, the generated function dropped them because the leg
/// lengths do not need the U angles) and `Ok` with NaN for an Agile-Eye quaternion entry
/// `x[1..4]` of ±1e300 (the runtime says `Err(Reach(0))`). Nothing checks that the results are
/// finite; this test fails until something does (e.g. a final finiteness check of the
/// outputs, reported as `Site::Input`).
#[test]
fn overflowing_finite_inputs() {
    let bad = probe_inputs(&[(1e300, "±1e300"), (-1e300, "±1e300")]);
    finish(&bad);
}

/// Evaluate every runtime and generated route of every bundled parallel mechanism at home with
/// one entry of `x`, `u` or `u̇`/`τ` replaced by each of `values`; print a table of outcomes and
/// return the violations (panic, or `Ok` with a non-finite entry).
fn probe_inputs(values: &[(f64, &str)]) -> Vec<String> {
    type Runtime = fn(&Plan, &[f64], &[f64], &[f64]) -> Outcome;
    let runtime: [(&str, Runtime); 6] = [
        ("inverse_dynamics", |p, x, u, ud| {
            noc::inverse_dynamics(p, x, u, ud)
        }),
        ("forward_dynamics", |p, x, u, tau| {
            noc::forward_dynamics(p, x, u, tau)
        }),
        ("actuator_rates", |p, x, u, _| noc::actuator_rates(p, x, u)),
        ("inverse_kinematics", |p, x, _, _| {
            noc::inverse_kinematics(p, x)
        }),
        ("mass_matrix", |p, x, _, _| {
            noc::mass_matrix(p, x).map(|m| m.concat())
        }),
        ("actuator_mass_matrix", |p, x, _, _| {
            noc::actuator_mass_matrix(p, x).map(|m| m.concat())
        }),
    ];
    // (route, input) → outcome → mechanisms (with the offending index).
    type Table = BTreeMap<(String, String), BTreeMap<String, BTreeSet<String>>>;
    let mut table: Table = BTreeMap::new();
    let mut bad_keys: BTreeSet<(String, String, String)> = BTreeSet::new();
    for name in [
        "gough_stewart",
        "sliding_hexapod",
        "rus_hexapod",
        "agile_eye",
        "delta_rl5",
        "planar_3rrr",
        "delta4_rl5",
    ] {
        let m = model(name);
        let plan = plan(&m);
        let x0 = home_x(&m);
        let n = plan.dof();
        let u0: Vec<f64> = (0..n).map(|i| 0.1 * (i as f64 + 1.0)).collect();
        let w0: Vec<f64> = (0..n).map(|i| 0.2 - 0.05 * i as f64).collect();
        let gen_routes = generated(name);
        for slot in 0..3 {
            let len = [x0.len(), n, n][slot];
            for i in 0..len {
                for &(bad_value, value) in values {
                    let (mut x, mut u, mut w) = (x0.clone(), u0.clone(), w0.clone());
                    [&mut x, &mut u, &mut w][slot][i] = bad_value;
                    let input = format!("{} {value}", ["x", "u", "u̇/τ"][slot]);
                    let mut judge = |route: String, o: std::thread::Result<Outcome>| {
                        let (outcome, violation) = match o {
                            Err(_) => ("PANIC".to_string(), true),
                            Ok(Ok(t)) if t.iter().any(|v| v.is_nan()) => {
                                ("Ok with NaN".to_string(), true)
                            }
                            Ok(Ok(t)) if t.iter().any(|v| !v.is_finite()) => {
                                ("Ok with ±inf".to_string(), true)
                            }
                            Ok(Ok(_)) => ("Ok, finite".to_string(), false),
                            Ok(Err(e)) => (format!("Err {}", site_word(e.site)), false),
                        };
                        if violation {
                            bad_keys.insert((route.clone(), input.clone(), outcome.clone()));
                        }
                        table
                            .entry((route, input.clone()))
                            .or_default()
                            .entry(outcome)
                            .or_default()
                            .insert(format!("{name}[{i}]"));
                    };
                    let uses = |r: &str| match slot {
                        0 => true,
                        1 => matches!(
                            r,
                            "inverse_dynamics" | "forward_dynamics" | "actuator_rates"
                        ),
                        _ => matches!(r, "inverse_dynamics" | "forward_dynamics"),
                    };
                    for (rname, f) in runtime.iter().filter(|r| uses(r.0)) {
                        let o = std::panic::catch_unwind(|| f(&plan, &x, &u, &w));
                        judge(format!("runtime {rname}"), o);
                    }
                    for (rname, f) in gen_routes.iter().filter(|r| uses(r.0)) {
                        let o = std::panic::catch_unwind(|| f(&x, &u, &w));
                        judge(format!("generated {rname}"), o);
                    }
                }
            }
        }
    }
    let names: BTreeSet<&str> = values.iter().map(|v| v.1).collect();
    let names: Vec<&str> = names.into_iter().collect();
    println!(
        "\n### Inputs (one entry of x, u or u̇/τ set to {})\n",
        names.join(", ")
    );
    println!("| route | input | outcomes (mechanism[index] of the first few) |");
    println!("|---|---|---|");
    let short = |set: &BTreeSet<String>| -> String {
        let v: Vec<&str> = set.iter().map(|s| s.as_str()).collect();
        if v.len() > 4 {
            format!("{}, … ({} cases)", v[..4].join(", "), v.len())
        } else {
            v.join(", ")
        }
    };
    for ((route, input), outcomes) in &table {
        let cells: Vec<String> = outcomes
            .iter()
            .map(|(o, set)| {
                let mark = if bad_keys.contains(&(route.clone(), input.clone(), o.clone())) {
                    " ✗"
                } else {
                    ""
                };
                format!("**{o}{mark}**: {}", short(set))
            })
            .collect();
        println!("| {route} | {input} | {} |", cells.join("; "));
    }
    let bad: Vec<String> = bad_keys
        .iter()
        .map(|(route, input, outcome)| {
            format!(
                "{route} with {input}: {outcome} ({})",
                short(&table[&(route.clone(), input.clone())][outcome])
            )
        })
        .collect();
    bad
}

/// A pose out of reach: the platform far from where the fixed-length legs can meet it. For the
/// 6-RUS hexapod lifting the platform by 10 × its size is enough; the sliding (6-PUS) hexapod
/// has vertical rails without stroke limits, so lifting is always reachable and the platform is
/// moved sideways instead. Every route must say `Err(Site::Reach(_))` (no NaN, no panic).
/// Measured: all do (runtime, double-double, generated; leg 0 first). The reported condition
/// estimate differs: `scale/|value|` (≈ 4e-3) from the runtime, `inf` from the generated code,
/// which tests `value > 0` instead of `|value| > 0` before dividing.
#[test]
fn out_of_reach() {
    let cases: [(&str, [f64; 3]); 6] = [
        ("rus_hexapod", [0.0, 0.0, 10.0]),
        ("delta_rl5", [3.0, 0.0, 0.0]),
        ("delta4_rl5", [3.0, 0.0, 0.0]),
        ("planar_3rrr", [3.0, 0.0, 0.0]),
        ("sliding_hexapod", [10.0, 0.0, 0.0]),
        ("sliding_hexapod", [0.0, -10.0, 2.0]),
    ];
    for (name, dir) in cases {
        let m = model(name);
        let plan = plan(&m);
        let s = m.size();
        let mut x = home_x(&m);
        for (xi, di) in x.iter_mut().zip(dir) {
            *xi += di * s;
        }
        let n = plan.dof();
        let z = vec![0.0; n];
        let u: Vec<f64> = (0..n).map(|i| 0.1 * i as f64).collect();
        let outcomes: Vec<(&str, Outcome)> = vec![
            ("runtime", noc::inverse_dynamics(&plan, &x, &u, &z)),
            ("double-double", dd::inverse_dynamics_dd(&plan, &x, &u, &z)),
            ("generated", generated_id(name)(&x, &u, &z)),
            (
                "runtime inverse_kinematics",
                noc::inverse_kinematics(&plan, &x),
            ),
        ];
        for (route, o) in outcomes {
            match o {
                Err(e) => {
                    println!("{name} {dir:?}×{s:.3} m, {route}: {e}");
                    assert!(
                        matches!(e.site, Site::Reach(_)),
                        "{name} {route}: expected Reach, got {e}"
                    );
                    assert!(!e.condition_estimate.is_nan());
                }
                Ok(t) => panic!("{name} {route}: out of reach but Ok({t:?})"),
            }
        }
    }
    // Lifting the sliding hexapod stays reachable (vertical rails) and accurate.
    let m = model("sliding_hexapod");
    let plan = plan(&m);
    let mut x = home_x(&m);
    x[2] += 10.0 * m.size();
    let z = vec![0.0; 6];
    let a = noc::inverse_dynamics(&plan, &x, &z, &z).unwrap();
    let b = dd::inverse_dynamics_dd(&plan, &x, &z, &z).unwrap();
    assert!(rel(&a, &b) < 1e-12);
}

/// A planar 3-RPR whose leg lines all pass through the platform's origin when it is turned by
/// `-beta` (`tests/data/rpr_turning.toml`): the platform turns about its origin with the
/// actuators held, so `A`'s rotation column vanishes there (each leg's moment arm about the
/// origin is zero: plane geometry, independent of the code). That column is alone in its unit
/// group (rad/s), and scaled by its own norm it looked regular: the generated inverse dynamics
/// returned `Ok` with 1.9e11 N 1e-12 rad from it. Its reference is now
/// at least the translation group's times the platform's radius (`noc::ColumnUnits`).
/// Checked: every route says `Err(Actuation)` there and `1e-12` rad from it, with a condition
/// estimate of at least `1/ACTUATION_TOLERANCE`; the generated module (inverse dynamics and
/// actuator mass matrix), the runtime and the literal route agree on `Ok` or `Err` and its site
/// along a walk toward it; where `Ok`, the results agree with the literal route to the
/// accuracy the condition allows; forward dynamics, which needs no `A⁻¹`, answers throughout.
#[test]
fn rpr_legs_through_the_platform_origin() {
    use tests::variants::rpr_turning as g;
    let m = data_model("rpr_turning.toml");
    let plan = plan(&m);
    let beta = 40f64.to_radians();
    // The moment arm of each leg line about the platform's origin at turn `phi` (plane
    // geometry): base points at radius 0.6, platform points at 0.15 turned by `beta + phi`.
    let arm = |phi: f64| {
        (0..3)
            .map(|i| {
                let a = i as f64 * 2.0 * std::f64::consts::PI / 3.0;
                let (bx, by) = (0.6 * a.cos(), 0.6 * a.sin());
                let (px, py) = (0.15 * (a + beta + phi).cos(), 0.15 * (a + beta + phi).sin());
                let (dx, dy) = (px - bx, py - by);
                (px * dy - py * dx).abs() / dx.hypot(dy)
            })
            .fold(0.0, f64::max)
    };
    assert!(
        arm(-beta) < 1e-15 && arm(0.0) > 0.05,
        "the geometry is not the one described"
    );
    let (u, ud) = ([0.1, -0.2, 0.3], [0.5, 0.4, -0.3]);
    // Each module has its own `Singular`: compared by site (as printed) and estimate.
    type Verdict = Result<Vec<f64>, (String, f64)>;
    fn verdict<T: AsRef<[f64]>, E: std::fmt::Debug>(
        r: Result<T, E>,
        err: impl Fn(&E) -> (String, f64),
    ) -> Verdict {
        r.map(|v| v.as_ref().to_vec()).map_err(|e| err(&e))
    }
    let site = |r: &Verdict| r.as_ref().err().map(|e| e.0.clone());
    let mut seen_err = false;
    for k in 0..=14 {
        let delta = if k == 14 { 0.0 } else { 10f64.powi(-k) };
        let x = [0.0, 0.0, -beta + delta];
        let of_module = |e: &g::Singular| (format!("{:?}", e.site), e.condition_estimate);
        let of_runtime = |e: &Singular| (format!("{:?}", e.site), e.condition_estimate);
        let gen_id = verdict(g::inverse_dynamics(&x, &u, &ud), of_module);
        let gen_m = verdict(g::actuator_mass_matrix(&x).map(|m| m.concat()), of_module);
        let gen_fd = verdict(g::forward_dynamics(&x, &u, &ud), of_module);
        let rt = verdict(noc::inverse_dynamics(&plan, &x, &u, &ud), of_runtime);
        let lit = verdict(
            runtime::parallel::literal::inverse_dynamics(&plan, &x, &u, &ud)
                .map(|t| t.as_slice().to_vec()),
            of_runtime,
        );
        assert_eq!(
            site(&gen_id),
            site(&rt),
            "δ = {delta:e}: generated vs runtime"
        );
        assert_eq!(
            site(&gen_id),
            site(&gen_m),
            "δ = {delta:e}: ID vs actuator mass matrix"
        );
        // Forward dynamics needs no `A⁻¹` (docs/method.md): it answers here too.
        assert!(gen_fd.is_ok(), "δ = {delta:e}: forward dynamics {gen_fd:?}");
        assert_eq!(
            site(&gen_id),
            site(&lit),
            "δ = {delta:e}: generated vs literal"
        );
        match (&gen_id, &lit) {
            (Ok(a), Ok(b)) => {
                assert!(!seen_err, "δ = {delta:e}: Ok again after an Err closer out");
                // The error grows like the condition, about 1/δ here.
                let e = tests::pkm::rel(a, b);
                assert!(
                    e < 1e-13 / delta.min(1.0),
                    "δ = {delta:e}: {e:e} against the literal route"
                );
            }
            (Err((site, cond)), _) => {
                seen_err = true;
                assert!(
                    site.starts_with("Actuation("),
                    "δ = {delta:e}: {site} {cond:e}"
                );
                assert!(
                    *cond >= min_condition(Site::Actuation(0)),
                    "δ = {delta:e}: {site} {cond:e}"
                );
            }
            _ => unreachable!(),
        }
        if delta <= 1e-12 {
            assert!(
                gen_id.is_err(),
                "δ = {delta:e}: Ok at the singularity: {gen_id:?}"
            );
        }
        if delta >= 1e-4 {
            assert!(
                gen_id.is_ok(),
                "δ = {delta:e}: Err away from it: {gen_id:?}"
            );
        }
    }
}

/// A planar 3-RRR with equal links whose first leg folds onto its base joint
/// (`tests/data/planar_3rrr_fold.toml`, the platform at `(ε, 0.2)` m: the platform point
/// `ε` from the base joint). There the leg Jacobian's first column, `e_z × (P − A)`, vanishes
/// (a leg singularity; the crank's rate grows as 1/ε). The determinant test divided by each
/// column's own norm, so a column of length ε was scaled back to unit length: `actuator_rates`
/// answered `Ok` down to ε = 1e-16, 1.8e-5 off at 1e-12 and 1.4e-2 at 1e-16 (relative, against
/// double-double). Each column's norm is now floored by its norm at home
/// (`LegPlan::column_home`), so the leg is `Err(Leg(0))` once `|P − A|` is below
/// `LEG_TOLERANCE` times its home value (0.2 m). Checked on the generated module against the
/// double-double route: every answer is `Ok` within `ACCURACY` or `Err` with a condition
/// estimate past its site's threshold, `Err(Leg(0))` from 1e-6 m, `Ok` at 1e-4 m.
#[test]
fn rrr_leg_folded_onto_its_base_joint() {
    use tests::variants::rrr_fold as g;
    let m = data_model("planar_3rrr_fold.toml");
    // The double-double reference without the floors (its own 32 digits hold to ε = 1e-16).
    let mut reference = plan(&m);
    for leg in &mut reference.legs {
        leg.column_home = [0.0; 3];
    }
    let (u, ud) = ([0.01, 0.02, 0.03], [0.1, 0.2, 0.3]);
    let rel = |a: &[f64], b: &[f64]| {
        let n = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / n
    };
    let site_ok = |site: String, cond: f64, eps: f64| {
        let min = if site.starts_with("Leg(") {
            min_condition(Site::Leg(0))
        } else if site.starts_with("Actuation(") {
            min_condition(Site::Actuation(0))
        } else {
            0.0
        };
        assert!(
            cond >= min,
            "ε = {eps:e}: {site} with condition estimate {cond:e}"
        );
    };
    for k in 1..=16 {
        let eps = 10f64.powi(-k);
        let x = [eps, 0.2, 0.0];
        let a = references::dd::actuation_dd(&reference, &x).expect("double-double A");
        let rates_dd: Vec<f64> = a
            .iter()
            .map(|row| {
                row.iter()
                    .zip(&u)
                    .fold(dd::DD::from(0.0), |s, (aij, uj)| s + aij.mul_f64(*uj))
                    .to_f64()
            })
            .collect();
        let rates = g::actuator_rates(&x, &u);
        match &rates {
            Ok(r) => {
                let e = rel(r, &rates_dd);
                assert!(e <= ACCURACY, "ε = {eps:e}: actuator_rates Ok, {e:e} off");
            }
            Err(e) => site_ok(format!("{:?}", e.site), e.condition_estimate, eps),
        }
        match (
            g::inverse_dynamics(&x, &u, &ud),
            dd::inverse_dynamics_dd(&reference, &x, &u, &ud),
        ) {
            (Ok(t), Ok(t_dd)) => {
                let e = rel(&t, &t_dd);
                assert!(e <= ACCURACY, "ε = {eps:e}: inverse_dynamics Ok, {e:e} off");
            }
            (Ok(t), Err(d)) => panic!("ε = {eps:e}: Ok({t:?}) where double-double fails: {d:?}"),
            (Err(e), _) => site_ok(format!("{:?}", e.site), e.condition_estimate, eps),
        }
        let leg = rates.err().map(|e| format!("{:?}", e.site));
        if eps <= 1e-6 {
            assert_eq!(leg.as_deref(), Some("Leg(0)"), "ε = {eps:e}");
        }
        if eps >= 1e-4 {
            assert_eq!(leg, None, "ε = {eps:e}");
        }
    }
}
