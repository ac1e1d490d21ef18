//! `codegen isotropy SPEC`: search the workspace for dynamically isotropic points, where the
//! inertia is `M = σ·1` (Ma & Angeles 1990), and print them as the lecture's table does.
//!
//! The search minimizes Ma & Angeles' `ψ` (Frobenius weights) from random starts by
//! Levenberg–Marquardt on the residuals `r = √(w/2) · e` (so `ψ = ‖r‖²`, `e` the upper-triangle
//! entries of `(M − σ1)/σ` with `σ = tr(M²)/tr M`, or of `M − σ1` with `σ = tr M / n` for
//! `--normalization trace`), with forward-difference Jacobians. The search box, around home:
//! * parallel mechanisms: a rotation vector `δθ` (each component in `±angle-range` rad, applied
//!   to the home orientation by `runtime::parallel::noc::retract`) and a position offset (each
//!   component in `±range` m);
//! * trees: every joint in `±π` (revolute) or `±range` (prismatic).
//!
//! With `--design NAME=LO:HI` one number of the spec (see [`super::design`]) is a further search
//! variable in `[LO, HI]`: the search then finds designs and points together, and the table has
//! a column for the design value.
//!
//! Points where the runtime returns `Err(Singular)` reject the step. Local minima closer than
//! 1e-4 of the box are merged. A point is reported as isotropic when its dimensionless `ψ` is at
//! most `--tolerance`; when there is none, the best local minima are listed instead, marked as
//! such.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Args, ValueEnum};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use runtime::indices::{Normalization, Weights};
use runtime::workspace::Speed;

use super::design::Design;
use super::map::fmt_g;
use super::{Rng, SpaceArg, Target, progress};

/// The DCI minimized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum NormArg {
    /// `σ = tr(M²)/tr M`, `(M − σ1)/σ` (dimensionless).
    Dimensionless,
    /// `σ = tr M / n`, `M − σ1`.
    Trace,
}

/// Arguments of `isotropy`.
#[derive(Debug, Args)]
// A negative number is a value (refused by the range checks with their message), not a flag.
#[command(allow_negative_numbers = true)]
pub struct IsotropyArgs {
    /// Mechanism spec (`.toml` or `.urdf`).
    pub spec: PathBuf,
    /// Random starts (1 to 100,000).
    #[arg(long, default_value_t = 64)]
    pub samples: usize,
    /// Seed of the random starts (runs repeat exactly).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Parallel mechanisms: actuator space (`A⁻ᵀ I A⁻¹`) or platform speeds (`I`).
    #[arg(long, value_enum, default_value = "actuator")]
    pub space: SpaceArg,
    /// The DCI normalization minimized.
    #[arg(long, value_enum, default_value = "dimensionless")]
    pub normalization: NormArg,
    /// Half-width of the search box for positions (m).
    #[arg(long, default_value_t = 0.1)]
    pub range: f64,
    /// Half-width of the search box for rotations of a platform (rad).
    #[arg(long, default_value_t = 1.0)]
    pub angle_range: f64,
    /// A point is isotropic when its dimensionless ψ is at most this.
    #[arg(long, default_value_t = 1e-12)]
    pub tolerance: f64,
    /// How many local minima to list when no isotropic point is found.
    #[arg(long, default_value_t = 5)]
    pub top: usize,
    /// Also search one number of the spec, named by its TOML path, within `LO:HI`
    /// (e.g. `body.distal_a.mass=0.1:1`).
    #[arg(long, value_name = "NAME=LO:HI")]
    pub design: Option<String>,
}

/// A local minimum.
#[derive(Clone, Debug)]
pub struct Minimum {
    /// Search parameters.
    pub p: Vec<f64>,
    /// The design number's value, with `--design`.
    pub design: Option<f64>,
    /// Coordinates `x` (platform coordinates or joint positions).
    pub x: Vec<f64>,
    /// `σ = tr M / n`.
    pub sigma: f64,
    /// ψ, `σ = tr M / n`, Frobenius weights.
    pub psi_trace: f64,
    /// ψ, dimensionless, Frobenius weights.
    pub psi_dimensionless: f64,
    /// The matrix's entries (row-major), to merge points with the same inertia.
    pub matrix: Vec<f64>,
}

struct Problem<'a> {
    target: &'a Target,
    /// The design number and the middle of its range (its search variable is the offset).
    design: Option<(&'a Design, f64)>,
    half: Vec<f64>,
    norm: Normalization,
}

impl Problem<'_> {
    /// The design value, the coordinates and the inertia at `p` (`None` where the spec is
    /// refused or the point fails).
    fn point(&self, p: &[f64]) -> Option<(Option<f64>, Vec<f64>, DMatrix<f64>)> {
        match self.design {
            None => {
                let x = self.target.mechanism.displaced(p);
                let m = self.target.matrix(&x).ok()?;
                Some((None, x, m))
            }
            Some((design, mid)) => {
                let (last, coords) = p.split_last()?;
                let value = mid + last;
                let target = design.target(value).ok()?;
                let x = target.mechanism.displaced(coords);
                let m = target.matrix(&x).ok()?;
                Some((Some(value), x, m))
            }
        }
    }

    /// `r = √(w/2) e` over the upper triangle, or `None` where the point fails.
    fn residuals(&self, p: &[f64]) -> Option<DVector<f64>> {
        let (_, _, m) = self.point(p)?;
        let n = m.nrows();
        let tr: f64 = m.trace();
        let (sigma, div) = match self.norm {
            Normalization::Trace => (tr / n as f64, 1.0),
            Normalization::Dimensionless => {
                let s = m.iter().map(|v| v * v).sum::<f64>() / tr;
                (s, s)
            }
        };
        let mut r = Vec::with_capacity(n * (n + 1) / 2);
        for i in 0..n {
            for j in i..n {
                let w: f64 = if i == j { 1.0 } else { 2.0 };
                let e = (m[(i, j)] - if i == j { sigma } else { 0.0 }) / div;
                r.push((0.5 * w).sqrt() * e);
            }
        }
        let r = DVector::from_vec(r);
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    fn clamp(&self, p: &mut [f64]) {
        for (v, h) in p.iter_mut().zip(&self.half) {
            *v = v.clamp(-h, *h);
        }
    }

    /// Levenberg–Marquardt from `p`.
    fn descend(&self, mut p: Vec<f64>) -> Option<Vec<f64>> {
        let d = p.len();
        let mut r = self.residuals(&p)?;
        let mut f = r.norm_squared();
        let mut mu = 1e-3;
        for _ in 0..200 {
            if f < 1e-30 {
                break;
            }
            // Forward-difference Jacobian, steps relative to the box.
            let mut jac = DMatrix::zeros(r.len(), d);
            for k in 0..d {
                let h = 1e-7 * self.half[k];
                let mut q = p.clone();
                q[k] += h;
                let col = match self.residuals(&q) {
                    Some(rk) => (rk - &r) / h,
                    None => {
                        // Backward difference next to a singular point.
                        q[k] = p[k] - h;
                        (&r - self.residuals(&q)?) / h
                    }
                };
                jac.set_column(k, &col);
            }
            let g = jac.transpose() * &r;
            let a = jac.transpose() * &jac;
            let mut accepted = false;
            for _ in 0..30 {
                let mut lhs = a.clone();
                for k in 0..d {
                    lhs[(k, k)] += mu * (a[(k, k)].max(1e-300));
                }
                let Some(step) = lhs.lu().solve(&(-&g)) else {
                    mu *= 10.0;
                    continue;
                };
                let mut q: Vec<f64> = p.iter().zip(step.iter()).map(|(a, b)| a + b).collect();
                self.clamp(&mut q);
                if let Some(rq) = self.residuals(&q) {
                    let fq = rq.norm_squared();
                    if fq < f {
                        let moved = p
                            .iter()
                            .zip(&q)
                            .zip(&self.half)
                            .map(|((a, b), h)| ((a - b) / h).abs())
                            .fold(0.0, f64::max);
                        p = q;
                        r = rq;
                        f = fq;
                        mu = (mu / 3.0).max(1e-12);
                        accepted = true;
                        if moved < 1e-14 {
                            return Some(p);
                        }
                        break;
                    }
                }
                mu *= 10.0;
            }
            if !accepted {
                break;
            }
        }
        Some(p)
    }
}

/// Run `isotropy`.
pub fn run(args: &IsotropyArgs) -> ExitCode {
    let target = match Target::load(&args.spec, args.space) {
        Ok(t) => t,
        Err(code) => return code,
    };
    if let Err(code) = check_args(args) {
        return code;
    }
    let design = match load_design(args) {
        Ok(d) => d,
        Err(code) => return code,
    };
    let (mut half, mut names) = search_box(&target, args);
    let coordinate_names = names.clone();
    if let Some(d) = &design {
        half.push(0.5 * (d.hi - d.lo));
        names.push(d.name.clone());
    }
    let norm = normalization(args.normalization);
    let problem = Problem {
        target: &target,
        design: design.as_ref().map(|d| (d, 0.5 * (d.lo + d.hi))),
        half: half.clone(),
        norm,
    };
    let mut rng = Rng::new(args.seed);
    let starts: Vec<Vec<f64>> = (0..args.samples)
        .map(|_| half.iter().map(|h| rng.uniform(-h, *h)).collect())
        .collect();
    let t0 = Instant::now();
    let found = search(&problem, starts);
    let elapsed = t0.elapsed();

    let minima = merge(found, &half, args.tolerance);
    // Every start singular or out of reach: an empty table with exit 0 said nothing.
    if minima.is_empty() {
        eprintln!(
            "error: none of the {} random starts could be evaluated (each singular or out of reach within --range {} / --angle-range {}): narrow the ranges or take more --samples",
            args.samples,
            fmt_g(args.range),
            fmt_g(args.angle_range)
        );
        return ExitCode::from(2);
    }
    let isotropic: Vec<&Minimum> = minima
        .iter()
        .filter(|m| m.psi_dimensionless <= args.tolerance)
        .collect();
    let (matrix, unit, _) = target.matrix_words();
    let report = Report {
        args,
        target: &target,
        design: design.as_ref(),
        unit: &unit,
    };
    report.print_head(&matrix, norm, elapsed.as_secs_f64());
    let rows = report.select_rows(&minima, isotropic);
    report.print_table(&coordinate_names, &rows);
    ExitCode::SUCCESS
}

/// The most random starts `--samples` takes: each is a Levenberg–Marquardt search (about
/// 25 ms on the Gough–Stewart platform), and the starts are drawn before the search, so
/// billions of them ran out of memory (or overflowed the allocation: a panic).
const MAX_SAMPLES: usize = 100_000;

/// The numeric arguments' bounds.
fn check_args(args: &IsotropyArgs) -> Result<(), ExitCode> {
    if args.samples > MAX_SAMPLES {
        eprintln!("error: --samples {}: at most {MAX_SAMPLES}", args.samples);
        return Err(ExitCode::from(2));
    }
    let valid = args.range > 0.0
        && args.range.is_finite()
        && args.angle_range > 0.0
        && args.angle_range.is_finite()
        && args.samples > 0
        && args.tolerance >= 0.0;
    if !valid {
        eprintln!(
            "error: --range and --angle-range must be positive, --samples at least 1, --tolerance non-negative"
        );
        return Err(ExitCode::from(2));
    }
    Ok(())
}

/// `--design`, parsed against the spec's text.
fn load_design(args: &IsotropyArgs) -> Result<Option<Design>, ExitCode> {
    match &args.design {
        None => Ok(None),
        Some(arg) => {
            let file = args.spec.to_string_lossy().into_owned();
            let parsed = std::fs::read_to_string(&args.spec)
                .map_err(|e| e.to_string())
                .and_then(|source| Design::parse(arg, &file, &source, args.space));
            match parsed {
                Ok(d) => Ok(Some(d)),
                Err(e) => {
                    eprintln!("error: {e}");
                    Err(ExitCode::from(2))
                }
            }
        }
    }
}

/// The search box's half-widths and the coordinates' names (without the design variable).
fn search_box(target: &Target, args: &IsotropyArgs) -> (Vec<f64>, Vec<String>) {
    let half = target
        .mechanism
        .speeds()
        .iter()
        .map(|s| match s {
            Speed::Joint { revolute: true } => std::f64::consts::PI,
            Speed::Joint { revolute: false } | Speed::Translation => args.range,
            Speed::Rotation => args.angle_range,
        })
        .collect();
    (half, target.mechanism.coordinate_names())
}

fn normalization(arg: NormArg) -> Normalization {
    match arg {
        NormArg::Dimensionless => Normalization::Dimensionless,
        NormArg::Trace => Normalization::Trace,
    }
}

/// The local minima from each start (in parallel, progress on stderr when it is a terminal).
fn search(problem: &Problem<'_>, starts: Vec<Vec<f64>>) -> Vec<Minimum> {
    let pb = progress(starts.len() as u64, "isotropy");
    let found: Vec<Minimum> = starts
        .into_par_iter()
        .filter_map(|s| {
            let out = problem.descend(s).and_then(|p| {
                let (design, x, m) = problem.point(&p)?;
                let w = Weights::frobenius(m.nrows());
                let d1 = runtime::indices::dci(&m, Normalization::Trace, &w).ok()?;
                let d2 = runtime::indices::dci(&m, Normalization::Dimensionless, &w).ok()?;
                Some(Minimum {
                    p,
                    design,
                    x,
                    sigma: d1.sigma,
                    psi_trace: d1.psi,
                    psi_dimensionless: d2.psi,
                    matrix: m.iter().copied().collect(),
                })
            });
            pb.inc(1);
            out
        })
        .collect();
    pb.finish_and_clear();
    found
}

/// Merge duplicates, best first: points closer than 1e-4 of the box; and, among points that
/// are not isotropic, points with the same matrix to 1e-5 of its largest entry (a coordinate
/// the inertia does not depend on, such as a tree's first joint about gravity, gives a
/// continuum of equal minima). Distinct isotropic points may share σ·1 (mirror images), so
/// they are merged by distance only.
fn merge(found: Vec<Minimum>, half: &[f64], tolerance: f64) -> Vec<Minimum> {
    let mut found = found;
    found.sort_by(|a, b| a.psi_dimensionless.total_cmp(&b.psi_dimensionless));
    let mut minima: Vec<Minimum> = Vec::new();
    for m in found {
        let dup = minima.iter().any(|o| {
            let near =
                o.p.iter()
                    .zip(&m.p)
                    .zip(half)
                    .all(|((a, b), h)| ((a - b) / h).abs() < 1e-4);
            let big = o.matrix.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let same = o
                .matrix
                .iter()
                .zip(&m.matrix)
                .all(|(a, b)| (a - b).abs() <= 1e-5 * big);
            near || (same && m.psi_dimensionless > tolerance)
        });
        if !dup {
            minima.push(m);
        }
    }
    minima
}

/// What the printed report needs.
struct Report<'a> {
    args: &'a IsotropyArgs,
    target: &'a Target,
    design: Option<&'a Design>,
    /// Unit of σ.
    unit: &'a str,
}

impl Report<'_> {
    /// The mechanism, the matrix, the search and the design.
    fn print_head(&self, matrix: &str, norm: Normalization, seconds: f64) {
        let (args, unit) = (self.args, self.unit);
        outln!(
            "mechanism: {} ({} DOF)",
            self.target.name(),
            self.target.dof()
        );
        outln!("matrix: {matrix}; sigma in {unit}");
        outln!(
            "search: {} random starts (seed {}), Levenberg-Marquardt on psi ({}), W = Frobenius (1 on the diagonal, 2 off it); {:.2} s",
            args.samples,
            args.seed,
            match norm {
                Normalization::Trace => "sigma = tr(M)/n",
                Normalization::Dimensionless => "sigma = tr(M^2)/tr(M), dimensionless",
            },
            seconds
        );
        if let Some(d) = self.design {
            outln!(
                "design: {} in [{}, {}] (the spec has {}), searched with the coordinates",
                d.name,
                fmt_g(d.lo),
                fmt_g(d.hi),
                fmt_g(d.written)
            );
        }
    }

    /// The isotropic points or, when there is none, the best local minima; with the line
    /// that says which.
    fn select_rows<'m>(
        &self,
        minima: &'m [Minimum],
        isotropic: Vec<&'m Minimum>,
    ) -> Vec<&'m Minimum> {
        let args = self.args;
        if isotropic.is_empty() {
            outln!(
                "no isotropic point found (psi2 <= {:e}); the {} best local minima of psi:",
                args.tolerance,
                args.top.min(minima.len())
            );
            minima.iter().take(args.top).collect()
        } else {
            outln!(
                "{} dynamically isotropic point(s) (psi2 <= {:e}):",
                isotropic.len(),
                args.tolerance
            );
            isotropic
        }
    }

    /// The table of `rows`.
    fn print_table(&self, coordinate_names: &[String], rows: &[&Minimum]) {
        let unit = self.unit;
        let design_head = self
            .design
            .map(|d| (format!(" {} |", d.name), "---:|"))
            .unwrap_or_default();
        outln!(
            "| point |{} coordinates ({}) | actuated joints q | sigma [{unit}] | psi (tr/n) [({unit})^2] | psi2 |",
            design_head.0,
            coordinate_names.join(", ")
        );
        outln!("|---|{}---|---|---:|---:|---:|", design_head.1);
        for (k, m) in rows.iter().enumerate() {
            self.print_row(k, m);
        }
    }

    /// Row `k` of the table.
    fn print_row(&self, k: usize, m: &Minimum) {
        let coords =
            m.x.iter()
                .map(|v| fixed6(*v))
                .collect::<Vec<_>>()
                .join(", ");
        // The actuated joints of a parallel mechanism, with the row's design.
        let redesigned = match (self.design, m.design) {
            (Some(d), Some(v)) => d.target(v).ok(),
            _ => None,
        };
        let q = redesigned
            .as_ref()
            .unwrap_or(self.target)
            .mechanism
            .actuated(&m.x)
            .map(|q| q.iter().map(|v| fixed6(*v)).collect::<Vec<_>>().join(", "))
            .unwrap_or_else(|_| "-".into());
        let design_cell = m
            .design
            .map(|v| format!(" {} |", fixed6(v)))
            .unwrap_or_default();
        outln!(
            "| {} |{design_cell} ({coords}) | ({q}) | {} | {} | {} |",
            k + 1,
            fmt_g(m.sigma),
            fmt_g(m.psi_trace),
            fmt_g(m.psi_dimensionless)
        );
    }
}

/// Six decimals, without a "-0.000000".
fn fixed6(v: f64) -> String {
    let v = if v.abs() < 5e-7 { 0.0 } else { v };
    format!("{v:.6}")
}
