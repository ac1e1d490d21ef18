//! `cargo xtask parallel-specs`: writes the parallel-mechanism specs of `mechanisms/specs/`
//! (`sliding_hexapod`, `rus_hexapod`, `agile_eye`; `gough_stewart` is written with parameters and
//! a leg pattern instead, docs/spec.md) with full-precision numbers.
//!
//! Every leg joint is at zero at home, so the joint frames of each leg are placed such that the
//! loop closes at the declared home pose of the platform; the task checks the closure itself and
//! prints, for each mechanism, the leg lengths and the condition number of the (normalized)
//! actuation matrix at home (large means near a parallel singularity).
//!
//! Conventions (docs/spec.md): SI units; `origin.rpy` and `child_origin.rpy` are fixed-axis
//! X-Y-Z angles, R = Rz(yaw)·Ry(pitch)·Rx(roll); a U joint rotates about x, then y of its joint
//! frame; a body's frame is its joint's frame after the motion.

use std::f64::consts::PI;
use std::path::Path;

use crate::pyfmt::{M3, V3, add, cross, g, repr, scale, sub, sum};

mod mechanisms;

// ---------------------------------------------------------------- small linear algebra

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

fn unit(a: V3) -> V3 {
    scale(1.0 / norm(a), a)
}

/// The rotation matrix whose columns are x, y, z.
fn columns(x: V3, y: V3, z: V3) -> M3 {
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}

fn transpose(m: M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| m[j][i]))
}

fn mat_mul(a: M3, b: M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| sum((0..3).map(|k| a[i][k] * b[k][j]))))
}

fn mat_vec(a: M3, v: V3) -> V3 {
    std::array::from_fn(|i| dot(a[i], v))
}

/// Fixed-axis X-Y-Z angles of a rotation matrix: m = Rz(y)·Ry(p)·Rx(r).
fn rpy_of(m: M3) -> V3 {
    let p = (-m[2][0]).clamp(-1.0, 1.0).asin();
    let r = m[2][1].atan2(m[2][2]);
    let y = m[1][0].atan2(m[0][0]);
    [r, p, y]
}

fn rpy_matrix(rpy: V3) -> M3 {
    let [r, p, y] = rpy;
    let (sr, cr) = (r.sin(), r.cos());
    let (sp, cp) = (p.sin(), p.cos());
    let (sy, cy) = (y.sin(), y.cos());
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// A rotation whose z axis is `z` (unit) and whose x axis is horizontal (z is not vertical).
fn frame_with_z(z: V3) -> M3 {
    let x = unit(cross([0.0, 0.0, 1.0], z));
    let y = cross(z, x);
    columns(x, y, z)
}

/// One Jacobi rotation of the symmetric `a` in the plane `(p, q)`.
fn jacobi_rotate(a: &mut [Vec<f64>], p: usize, q: usize) {
    let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
    let t = 1.0f64.copysign(theta) / (theta.abs() + (theta * theta + 1.0).sqrt());
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    for row in a.iter_mut() {
        let (akp, akq) = (row[p], row[q]);
        row[p] = c * akp - s * akq;
        row[q] = s * akp + c * akq;
    }
    // p < q: rows p and q side by side.
    let (low, high) = a.split_at_mut(q);
    for (apk, aqk) in low[p].iter_mut().zip(high[0].iter_mut()) {
        let (x, y) = (*apk, *aqk);
        *apk = c * x - s * y;
        *aqk = s * x + c * y;
    }
}

/// 2-norm condition number of a square matrix (Jacobi eigenvalues of AᵀA).
fn condition(rows: &[Vec<f64>]) -> f64 {
    let n = rows.len();
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| sum((0..n).map(|k| rows[k][i] * rows[k][j])))
                .collect()
        })
        .collect();
    for _ in 0..100 {
        let off = sum((0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|(i, j)| i != j)
            .map(|(i, j)| a[i][j].powf(2.0)));
        if off < 1e-30 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                jacobi_rotate(&mut a, p, q);
            }
        }
    }
    let mut ev: Vec<f64> = (0..n).map(|i| a[i][i]).collect();
    ev.sort_by(f64::total_cmp);
    if ev[0] > 0.0 {
        (ev[n - 1] / ev[0]).sqrt()
    } else {
        f64::INFINITY
    }
}

// ---------------------------------------------------------------- inertia formulas

/// An inertia: principal moments `(ixx, iyy, izz)` or a full symmetric matrix.
enum Inertia {
    Diagonal(V3),
    Full(M3),
}

/// Solid cylinder along z about its mass centre: (ixx, iyy, izz).
fn rod_inertia(m: f64, length: f64, radius: f64) -> Inertia {
    let i = m * (3.0 * radius * radius + length * length) / 12.0;
    Inertia::Diagonal([i, i, m * radius * radius / 2.0])
}

/// Solid box with edges a, b, c along x, y, z about its mass centre.
fn box_inertia(m: f64, a: f64, b: f64, c: f64) -> Inertia {
    Inertia::Diagonal([
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    ])
}

/// A thin 90° circular arc of radius `rho` about the origin from unit direction a to b
/// (orthogonal), plus `core` kg·m² on the diagonal for the cross-section: (com, inertia about
/// the com).
fn arc_props(m: f64, rho: f64, a: V3, b: V3, core: f64) -> (V3, Inertia) {
    // Second moments S = ∫ r rᵀ dm = m ρ² (½aaᵀ + ½bbᵀ + (abᵀ + baᵀ)/π).
    let s: M3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            m * rho
                * rho
                * (0.5 * a[i] * a[j] + 0.5 * b[i] * b[j] + (a[i] * b[j] + b[i] * a[j]) / PI)
        })
    });
    let tr = s[0][0] + s[1][1] + s[2][2];
    let io: M3 =
        std::array::from_fn(|i| std::array::from_fn(|j| (if i == j { tr } else { 0.0 }) - s[i][j]));
    // Mass centre on the bisector at ρ·sin(π/4)/(π/4).
    let c = scale(
        rho * (PI / 4.0).sin() / (PI / 4.0) / 2.0f64.sqrt(),
        add(a, b),
    );
    let cc = dot(c, c);
    let ic: M3 = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            io[i][j] - m * ((if i == j { cc } else { 0.0 }) - c[i] * c[j])
                + (if i == j { core } else { 0.0 })
        })
    });
    (c, Inertia::Full(ic))
}

// ---------------------------------------------------------------- TOML output

/// Shortest repr that round-trips; exact zeros as 0.0.
fn num(x: f64) -> String {
    if x == 0.0 { "0.0".into() } else { repr(x) }
}

fn vec(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| num(*x)).collect();
    format!("[{}]", items.join(", "))
}

fn inertia_table(i: &Inertia) -> String {
    match i {
        Inertia::Diagonal(d) => format!(
            "{{ ixx = {}, iyy = {}, izz = {} }}",
            num(d[0]),
            num(d[1]),
            num(d[2])
        ),
        Inertia::Full(i) => {
            let parts = [
                ("ixx", i[0][0]),
                ("iyy", i[1][1]),
                ("izz", i[2][2]),
                ("ixy", i[0][1]),
                ("ixz", i[0][2]),
                ("iyz", i[1][2]),
            ];
            let items: Vec<String> = parts
                .iter()
                .map(|(k, v)| format!("{k} = {}", num(*v)))
                .collect();
            format!("{{ {} }}", items.join(", "))
        }
    }
}

fn origin(xyz: V3, rpy: Option<V3>) -> String {
    match rpy {
        Some(rpy) if rpy.iter().any(|a| *a != 0.0) => {
            format!("{{ xyz = {}, rpy = {} }}", vec(&xyz), vec(&rpy))
        }
        _ => format!("{{ xyz = {} }}", vec(&xyz)),
    }
}

/// A joint's optional keys.
#[derive(Default)]
struct JointKeys {
    origin: Option<String>,
    axis: Option<V3>,
    actuated: bool,
    child_origin: Option<String>,
}

/// A spec's lines.
struct Spec {
    lines: Vec<String>,
}

impl Spec {
    fn new(header: &str) -> Spec {
        let mut lines: Vec<String> = header
            .trim_matches('\n')
            .split('\n')
            .map(|l| {
                if l.is_empty() {
                    "#".to_string()
                } else {
                    format!("# {l}")
                }
            })
            .collect();
        lines.push(
            "# Generated by `cargo xtask parallel-specs`; edit the task, not this file.".into(),
        );
        Spec { lines }
    }

    fn blank(&mut self) {
        self.lines.push(String::new());
    }

    fn comment(&mut self, text: &str) {
        self.lines.push(format!("# {text}"));
    }

    fn table(&mut self, header: &str, items: &[(&str, String)]) {
        self.lines.push(header.into());
        for (k, v) in items {
            self.lines.push(format!("{k} = {v}"));
        }
        self.blank();
    }

    fn body(&mut self, name: &str, mass: f64, com: V3, inertia: &Inertia) {
        self.table(
            "[[body]]",
            &[
                ("name", format!("\"{name}\"")),
                ("mass", num(mass)),
                ("com", vec(&com)),
                ("inertia", inertia_table(inertia)),
            ],
        );
    }

    fn joint(&mut self, name: &str, kind: &str, parent: &str, child: &str, keys: JointKeys) {
        let mut items = vec![
            ("name", format!("\"{name}\"")),
            ("kind", format!("\"{kind}\"")),
            ("parent", format!("\"{parent}\"")),
            ("child", format!("\"{child}\"")),
        ];
        if let Some(o) = keys.origin {
            items.push(("origin", o));
        }
        if let Some(a) = keys.axis {
            items.push(("axis", vec(&a)));
        }
        if keys.actuated {
            items.push(("actuated", "true".into()));
        }
        if let Some(c) = keys.child_origin {
            items.push(("child_origin", c));
        }
        self.table("[[joint]]", &items);
    }

    fn write(&self, dir: &Path, file: &str) -> std::io::Result<()> {
        let text = format!("{}\n", self.lines.join("\n").trim_end_matches('\n'));
        std::fs::write(dir.join(file), text)?;
        println!("wrote {file}");
        Ok(())
    }
}

/// Six points in three pairs, 3-fold symmetric: angles phase + 120k ∓ half_angle, in the order
/// (pair 0 −, pair 0 +, pair 1 −, …).
fn semi_regular(radius: f64, half_angle_deg: f64, phase_deg: f64, z: f64) -> Vec<V3> {
    let mut pts = Vec::new();
    for k in 0..3 {
        for s in [-1.0, 1.0] {
            let a = (phase_deg + 120.0 * k as f64 + s * half_angle_deg).to_radians();
            pts.push([radius * a.cos(), radius * a.sin(), z]);
        }
    }
    pts
}

fn check_closure(name: &str, tip: V3, target: V3) {
    let d = norm(sub(tip, target));
    assert!(d < 1e-12, "{name}: the loop does not close ({} m)", g(d, 6));
}

fn plucker_condition(points: &[V3], dirs: &[V3]) -> f64 {
    let rows: Vec<Vec<f64>> = points
        .iter()
        .zip(dirs)
        .map(|(p, s)| [cross(*p, *s), *s].concat())
        .collect();
    condition(&rows)
}

/// Writes the three specs into `dir`.
pub fn run(dir: &Path) -> std::io::Result<()> {
    mechanisms::sliding_hexapod(dir)?;
    mechanisms::rus_hexapod(dir)?;
    mechanisms::agile_eye(dir)
}
