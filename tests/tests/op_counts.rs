//! Growth of the generated code with the number of joints.
//!
//! The NOC inverse dynamics is `O(n)` (one outward twist pass, one inward wrench pass, the
//! `Tᵀ` projection folded into it), the mass matrix `O(n²)` (composite bodies, one entry per
//! joint pair). Both claims are checked on the generator's own operation counts
//! ([`codegen::Generated::stats`]) for serial chains of n = 2..=12 revolute joints, in two
//! flavours: fully generic geometry (random axes, origins, inertias, gravity: no zero or unit
//! entry to fold) and DH-like geometry (z axes, twists of 0 / ±π/2 that fold to exact 0 / ±1,
//! as in most real arms).
//!
//! The assertions are written to fail on a wrong complexity: an `O(n²)` inverse dynamics has
//! increments `flops(n+1) − flops(n)` that grow linearly in `n` (≈ 2.5× from n = 4 to n = 11,
//! far over the 1.25× allowed) and a positive quadratic coefficient in the fit; an `O(n³)` mass
//! matrix has `flops / n²` doubling from n = 6 to n = 12.

use std::f64::consts::FRAC_PI_2;

use codegen::{Config, schedule::OpCount, tree::generate};
use runtime::model::{Body, Joint, JointKind, Model, Transform, exact_sin_cos};
use tests::{Shape, random_model, rng};

use rand::Rng;

const N_MIN: usize = 2;
const N_MAX: usize = 12;
/// Below this many joints base effects (gravity, the fixed base) dominate; ratios start here.
const N_ASYMPTOTIC: usize = 4;

/// A DH-like revolute chain (modified DH: `Rx(α) Tx(a) Rz(θ) Tz(d)`): every axis is the joint
/// frame's z, twists cycle through 0, π/2, −π/2 (exact, so they fold), link lengths and offsets
/// are generic, inertias are diagonal (principal axes along the link frame), mass centres are
/// generic, gravity is −z.
fn dh_chain(seed: u64, n: usize) -> Model {
    let mut r = rng(seed);
    let twists = [FRAC_PI_2, 0.0, -FRAC_PI_2];
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    for i in 0..n {
        let alpha = twists[i % twists.len()];
        let a: f64 = r.random_range(-0.5..0.5);
        let d: f64 = r.random_range(-0.5..0.5);
        let (sa, ca) = exact_sin_cos(alpha);
        // Tx(a) Rx(α) Tz(d) = Trans([a, −d sin α, d cos α]) · Rx(α).
        joints.push(Joint {
            name: format!("j{i}"),
            kind: JointKind::Revolute,
            parent: i.checked_sub(1),
            origin: Transform::from_xyz_rpy([a, -d * sa, d * ca], [alpha, 0.0, 0.0]),
            axis: [0.0, 0.0, 1.0],
            drive: Default::default(),
        });
        let ix: f64 = r.random_range(0.01..1.0);
        let iy: f64 = r.random_range(0.01..1.0);
        let iz: f64 = r.random_range((ix - iy).abs() + 0.001..ix + iy);
        bodies.push(Body {
            name: format!("b{i}"),
            mass: r.random_range(0.1..5.0),
            com: [
                r.random_range(-0.3..0.3),
                r.random_range(-0.3..0.3),
                r.random_range(-0.3..0.3),
            ],
            inertia: [[ix, 0.0, 0.0], [0.0, iy, 0.0], [0.0, 0.0, iz]],
        });
    }
    Model {
        name: format!("dh_{n}"),
        gravity: [0.0, 0.0, -9.81],
        bodies,
        joints,
    }
}

fn generic_chain(seed: u64, n: usize) -> Model {
    random_model(
        seed,
        Shape {
            joints: n,
            prismatic: 0.0,
            chain: true,
            coordinate_axes: false,
        },
    )
}

/// Operation counts of one generated module by function name.
fn counts(model: &Model) -> (OpCount, OpCount) {
    let out = generate(model, &Default::default(), &Config::default());
    assert_eq!(out.dof, model.dof());
    let get = |name: &str| {
        out.stats
            .iter()
            .find(|(f, _)| f == name)
            .unwrap_or_else(|| panic!("no stats for {name}"))
            .1
    };
    (get("inverse_dynamics"), get("mass_matrix"))
}

/// `(n, ID flops, MM flops)` for n = N_MIN..=N_MAX, printed as a table (in one piece, so that
/// parallel tests do not interleave).
fn table(label: &str, model: impl Fn(usize) -> Model) -> Vec<(usize, f64, f64)> {
    let mut t = format!(
        "\n{label}\n| {:>2} | {:>8} | {:>10} | {:>8} | {:>11} | {:>10} |\n|---:|---:|---:|---:|---:|---:|\n",
        "n", "ID flops", "ID flops/n", "MM flops", "MM flops/n²", "MM /entry"
    );
    let mut rows = Vec::new();
    for n in N_MIN..=N_MAX {
        let (id, mm) = counts(&model(n));
        let (id, mm) = (id.flops() as f64, mm.flops() as f64);
        let nf = n as f64;
        let entries = nf * (nf + 1.0) / 2.0;
        t += &format!(
            "| {n:>2} | {id:>8} | {:>10.1} | {mm:>8} | {:>11.2} | {:>10.2} |\n",
            id / nf,
            mm / (nf * nf),
            mm / entries
        );
        rows.push((n, id, mm));
    }
    eprint!("{t}");
    rows
}

/// Least-squares fit `y ≈ c0 + c1 n + c2 n²`; returns `[c0, c1, c2]`.
fn quadratic_fit(points: &[(f64, f64)]) -> [f64; 3] {
    // Normal equations, 3×3, solved by Cramer's rule (well conditioned for n ≤ 12).
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for &(x, y) in points {
        let p = [1.0, x, x * x];
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += p[i] * p[j];
            }
            b[i] += p[i] * y;
        }
    }
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&a);
    let mut c = [0.0; 3];
    for k in 0..3 {
        let mut m = a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        c[k] = det(&m) / d;
    }
    c
}

fn max(it: impl Iterator<Item = f64>) -> f64 {
    it.fold(f64::NEG_INFINITY, f64::max)
}

fn min(it: impl Iterator<Item = f64>) -> f64 {
    it.fold(f64::INFINITY, f64::min)
}

type Row = (usize, f64, f64);

/// Inverse dynamics is linear in n: the criteria it violates (empty: none).
fn linear_id_violations(label: &str, rows: &[Row]) -> Vec<String> {
    let mut bad = Vec::new();
    let asym: Vec<_> = rows.iter().filter(|r| r.0 >= N_ASYMPTOTIC).collect();
    let mid = (N_ASYMPTOTIC + N_MAX) / 2;
    // 1. Flops per joint level off: over the upper half of the range they vary by ≤ 15 %
    //    (O(n²): +50 % from n = 8 to n = 12). The lower half is not flat: the joints next to the
    //    fixed base are cheaper (zero base twist, constant base-frame quantities fold), so
    //    flops/n rises towards the per-joint increment from below.
    let per_joint = || asym.iter().filter(|r| r.0 >= mid).map(|r| r.1 / r.0 as f64);
    let (hi, lo) = (max(per_joint()), min(per_joint()));
    if hi > 1.15 * lo {
        bad.push(format!(
            "{label}: ID flops/joint not flat for n ≥ {mid}: {lo:.1} … {hi:.1}"
        ));
    }
    // 2. The cost of one more joint does not grow with n: the increments of the upper half of
    //    the range are at most 1.25× the largest increment of the lower half (O(n²): ≈ 1.5×).
    let inc: Vec<(usize, f64)> = asym.windows(2).map(|w| (w[0].0, w[1].1 - w[0].1)).collect();
    let early = max(inc.iter().filter(|d| d.0 < mid).map(|d| d.1));
    let late = max(inc.iter().filter(|d| d.0 >= mid).map(|d| d.1));
    eprintln!("{label}: ID increments flops(n+1) − flops(n): {inc:?}");
    if !(early > 0.0 && late <= 1.25 * early) {
        bad.push(format!(
            "{label}: ID increment grows with n: ≤ {early} below n = {mid}, up to {late} above"
        ));
    }
    // 3. A quadratic fit has a negligible n² term: at n = N_MAX it adds < 5 % of the linear
    //    term's per-joint cost.
    let pts: Vec<(f64, f64)> = asym.iter().map(|r| (r.0 as f64, r.1)).collect();
    let [c0, c1, c2] = quadratic_fit(&pts);
    eprintln!("{label}: ID fit ≈ {c0:.1} + {c1:.2} n + {c2:.3} n²");
    if !(c1 > 0.0 && c2.abs() * N_MAX as f64 <= 0.05 * c1) {
        bad.push(format!(
            "{label}: ID flops not linear: fit {c0:.1} + {c1:.2} n + {c2:.3} n²"
        ));
    }
    bad
}

/// The mass matrix is at most quadratic in n: the criteria it violates (empty: none).
fn quadratic_mm_violations(label: &str, rows: &[Row]) -> Vec<String> {
    let mut bad = Vec::new();
    let per_n2 = |r: &&Row| r.2 / (r.0 * r.0) as f64;
    let per_entry_per_n = |r: &&Row| r.2 / (r.0 * (r.0 + 1) / 2) as f64 / r.0 as f64;
    let asym: Vec<_> = rows.iter().filter(|r| r.0 >= N_ASYMPTOTIC).collect();
    let mid = (N_ASYMPTOTIC + N_MAX) / 2;
    let lower = || asym.iter().filter(|r| r.0 <= mid);
    let upper = || asym.iter().filter(|r| r.0 > mid);
    // 1. flops / n² bounded: the largest value in the upper half of the range is at most 1.2×
    //    the largest in the lower half (O(n³): 1.5×).
    let (early, late) = (max(lower().map(per_n2)), max(upper().map(per_n2)));
    if late > 1.2 * early {
        bad.push(format!(
            "{label}: MM flops/n² grows: ≤ {early:.2} up to n = {mid}, up to {late:.2} above"
        ));
    }
    // 2. Flops per entry grow at most linearly: (flops/entry)/n does not increase from the lower
    //    to the upper half of the range by more than 10 % (O(n⁴) overall: 1.5×).
    let (early, late) = (
        max(lower().map(per_entry_per_n)),
        max(upper().map(per_entry_per_n)),
    );
    if late > 1.1 * early {
        bad.push(format!(
            "{label}: MM flops/entry grows faster than n: {early:.3}·n up to n = {mid}, \
             {late:.3}·n above"
        ));
    }
    // 3. The second differences (twice the n² coefficient) do not grow: a cubic makes them rise
    //    linearly in n.
    let d2: Vec<(usize, f64)> = asym
        .windows(3)
        .map(|w| (w[1].0, w[2].2 - 2.0 * w[1].2 + w[0].2))
        .collect();
    eprintln!("{label}: MM second differences: {d2:?}");
    let early = max(d2.iter().filter(|d| d.0 <= mid).map(|d| d.1));
    let late = max(d2.iter().filter(|d| d.0 > mid).map(|d| d.1));
    if late > 1.25 * early.max(1.0) {
        bad.push(format!(
            "{label}: MM second differences grow (cubic?): ≤ {early} up to n = {mid}, \
             {late} above"
        ));
    }
    bad
}

fn check(label: &str, model: impl Fn(usize) -> Model) {
    let rows = table(label, model);
    let mut bad = linear_id_violations(label, &rows);
    bad.extend(quadratic_mm_violations(label, &rows));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

// One seed for every n: the (n+1)-joint chain is the n-joint chain plus one link (the models
// draw their links in order), so the increments measure one more joint and nothing else.

#[test]
fn generic_chain_inverse_dynamics_is_linear_and_mass_matrix_quadratic() {
    check("generic n-R chain (random axes, origins, inertias)", |n| {
        generic_chain(0xC0DE, n)
    });
}

#[test]
fn dh_chain_inverse_dynamics_is_linear_and_mass_matrix_quadratic() {
    check("DH-like n-R chain (z axes, twists 0/±π/2)", |n| {
        dh_chain(0xD4, n)
    });
}

/// The criteria reject wrong growth: each can fail.
#[test]
fn criteria_reject_superlinear_id_and_supercubic_mm() {
    let rows = |id: fn(f64) -> f64, mm: fn(f64) -> f64| -> Vec<Row> {
        (N_MIN..=N_MAX)
            .map(|n| (n, id(n as f64), mm(n as f64)))
            .collect()
    };
    // Linear ID with a cheap base, quadratic MM: accepted.
    let good = rows(|n| 222.0 * n - 278.0, |n| 30.0 * n * n + 60.0 * n - 100.0);
    assert_eq!(linear_id_violations("linear", &good), Vec::<String>::new());
    assert_eq!(
        quadratic_mm_violations("quadratic", &good),
        Vec::<String>::new()
    );
    // O(n²) inverse dynamics (a modest n² term beside a large linear one): all three criteria.
    let quadratic_id = rows(|n| 150.0 * n + 12.0 * n * n, |_| 0.0);
    assert_eq!(linear_id_violations("O(n²) ID", &quadratic_id).len(), 3);
    // O(n³) mass matrix: flops/n² and the second differences.
    let cubic_mm = rows(|_| 0.0, |n| 30.0 * n * n + 4.0 * n * n * n);
    let v = quadratic_mm_violations("O(n³) MM", &cubic_mm);
    assert_eq!(v.len(), 2, "{v:?}");
    // O(n⁴) mass matrix: all three.
    let quartic_mm = rows(|_| 0.0, |n| 30.0 * n * n + n * n * n * n);
    assert_eq!(quadratic_mm_violations("O(n⁴) MM", &quartic_mm).len(), 3);
}
