//! `codegen map SPEC --index …`: one index over a 2-D slice of the workspace, in parallel, to a
//! CSV and an SVG heat map (`docs/indices.md`).
//!
//! The slice: two coordinates vary on a regular grid, the others stay at home.
//! * Parallel mechanisms: `px`, `py`, `pz` move the platform origin (m; the range is an offset
//!   from home, the CSV and the plot show the absolute coordinate); `rx`, `ry`, `rz` are angles
//!   (rad) of rotations about the base axes applied to the home orientation,
//!   `R = R_a(first) · R_b(second) · R_home`.
//! * Trees: two joints by name (or `q0`, `q1`, …), values in rad or m; the other joints at
//!   `--at` (default 0).

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Args, ValueEnum};
use rayon::prelude::*;
use runtime::workspace::Axis;

use super::{Failure, IndexKind, SpaceArg, Target, parse_range, progress, quat_axis, quat_mul};

/// Colour scale of the heat map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Scale {
    /// Logarithmic for `cond` and `manip`, linear otherwise.
    Auto,
    /// Linear.
    Linear,
    /// log10 of the value.
    Log,
}

/// Arguments of `map`.
#[derive(Debug, Args)]
// A negative number is a value (refused by the range checks with their message), not a flag.
#[command(allow_negative_numbers = true)]
pub struct MapArgs {
    /// Mechanism spec (`.toml` or `.urdf`).
    pub spec: PathBuf,
    /// The index to map.
    #[arg(long, value_enum, default_value = "dci2")]
    pub index: IndexKind,
    /// The two coordinates of the slice: `px,py,pz,rx,ry,rz` for a parallel mechanism (those it
    /// has), joint names (or `q0`, `q1`, …) for a tree. Default: the first two.
    #[arg(long, value_name = "A,B")]
    pub axes: Option<String>,
    /// Range of each axis, `LO:HI` for both or `LO:HI,LO:HI` (m for positions, as an offset from
    /// home; rad for angles). Default: ±0.1 m, ±1 rad, ±π for revolute tree joints.
    #[arg(long, value_name = "LO:HI[,LO:HI]", allow_hyphen_values = true)]
    pub range: Option<String>,
    /// Grid points per axis, `N` or `N,M` (at least 2 each).
    #[arg(long, alias = "grid", value_name = "N[,M]", default_value = "51")]
    pub steps: String,
    /// Parallel mechanisms: actuator space (`A⁻ᵀ I A⁻¹`) or platform speeds (`I`).
    #[arg(long, value_enum, default_value = "actuator")]
    pub space: SpaceArg,
    /// Trees: the values of all joints (comma-separated, rad or m); the slice's two joints are
    /// overwritten. Default: all zero.
    #[arg(long, value_name = "Q0,Q1,…", allow_hyphen_values = true)]
    pub at: Option<String>,
    /// Output prefix: writes PREFIX.csv and PREFIX.svg. Default: `<mechanism>_<index>`.
    #[arg(short, long, value_name = "PREFIX")]
    pub output: Option<PathBuf>,
    /// Colour scale of the SVG.
    #[arg(long, value_enum, default_value = "auto")]
    pub scale: Scale,
    /// Worker threads (default: one per core; at most 1024).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// An axis's words and defaults (the axes themselves come from the runtime,
/// [`runtime::workspace::Workspace::axes`]).
pub trait AxisText {
    /// Name as in the CSV header (with its unit).
    fn label(&self) -> String;
    /// Name with its unit for the plot (`px [m]`).
    fn plot_label(&self) -> String;
    /// Default range.
    fn default_range(&self) -> (f64, f64);
    /// The value shown for the grid value `v` (absolute position for position axes).
    fn shown(&self, v: f64) -> f64;
}

impl AxisText for Axis {
    /// Name as in the CSV header (with its unit).
    fn label(&self) -> String {
        match self {
            Axis::Position { name, .. } => format!("{name}_m"),
            Axis::Rotation { name, .. } => format!("{name}_rad"),
            Axis::Joint { name, revolute, .. } => {
                format!("{name}_{}", if *revolute { "rad" } else { "m" })
            }
        }
    }
    /// Name with its unit for the plot (`px [m]`).
    fn plot_label(&self) -> String {
        match self {
            Axis::Position { name, .. } => format!("{name} [m]"),
            Axis::Rotation { name, .. } => format!("{name} [rad] (rotation about the base axis)"),
            Axis::Joint { name, revolute, .. } => {
                format!("{name} [{}]", if *revolute { "rad" } else { "m" })
            }
        }
    }
    /// Default range.
    fn default_range(&self) -> (f64, f64) {
        match self {
            Axis::Position { .. } => (-0.1, 0.1),
            Axis::Rotation { .. } => (-1.0, 1.0),
            Axis::Joint { revolute: true, .. } => (-std::f64::consts::PI, std::f64::consts::PI),
            Axis::Joint { .. } => (-0.1, 0.1),
        }
    }
    /// The value shown for the grid value `v` (absolute position for position axes).
    fn shown(&self, v: f64) -> f64 {
        match self {
            Axis::Position { home, .. } => home + v,
            _ => v,
        }
    }
}

/// The axes a mechanism offers, by name.
pub fn resolve_axes(target: &Target, spec: Option<&str>) -> Result<[Axis; 2], String> {
    let offered: Vec<Axis> = target.mechanism.axes();
    let name_of = |a: &Axis| match a {
        Axis::Position { name, .. } | Axis::Rotation { name, .. } | Axis::Joint { name, .. } => {
            name.clone()
        }
    };
    let names: Vec<String> = offered.iter().map(name_of).collect();
    let pick = |w: &str| -> Result<Axis, String> {
        let w = w.trim();
        if let Some(k) = names.iter().position(|n| n == w) {
            return Ok(offered[k].clone());
        }
        if let Some(k) = w
            .strip_prefix('q')
            .and_then(|d| d.parse::<usize>().ok())
            .filter(|_| target.mechanism.every_joint())
            .filter(|k| *k < offered.len())
        {
            return Ok(offered[k].clone());
        }
        Err(format!(
            "unknown axis `{w}`; this mechanism offers: {}",
            names.join(", ")
        ))
    };
    let (a, b) = match spec {
        Some(s) => {
            let parts: Vec<&str> = s.split(',').collect();
            if parts.len() != 2 {
                return Err(format!("--axes takes two names, e.g. {}", names.join(",")));
            }
            (pick(parts[0])?, pick(parts[1])?)
        }
        None => {
            if offered.len() < 2 {
                return Err("the mechanism has fewer than two coordinates to map".into());
            }
            (offered[0].clone(), offered[1].clone())
        }
    };
    if name_of(&a) == name_of(&b) {
        return Err("the two axes must differ".into());
    }
    Ok([a, b])
}

/// The coordinates `x` at the grid values `(u, v)` of the two axes.
pub fn point(target: &Target, axes: &[Axis; 2], base: &[f64], u: f64, v: f64) -> Vec<f64> {
    let mut x = base.to_vec();
    let qi = target.mechanism.quaternion();
    // Rotations compose from the left in the order given: R_a(u) · R_b(v) · R_home.
    let mut rot = [1.0, 0.0, 0.0, 0.0];
    for (axis, val) in axes.iter().zip([u, v]) {
        match axis {
            Axis::Position { index, .. } => x[*index] += val,
            Axis::Joint { index, .. } => x[*index] = val,
            Axis::Rotation { axis, .. } => rot = quat_mul(&rot, &quat_axis(*axis, val)),
        }
    }
    if let Some(qi) = qi {
        let home = [x[qi], x[qi + 1], x[qi + 2], x[qi + 3]];
        let q = quat_mul(&rot, &home);
        x[qi..qi + 4].copy_from_slice(&q);
    }
    x
}

/// The base coordinates of the slice (home, or `--at` for a tree).
fn base_point(target: &Target, at: Option<&str>) -> Result<Vec<f64>, String> {
    let Some(s) = at else {
        return Ok(target.mechanism.home());
    };
    if !target.mechanism.every_joint() {
        return Err("--at applies to trees only".into());
    }
    let dof = target.dof();
    let v: Result<Vec<f64>, _> = s.split(',').map(|t| t.trim().parse::<f64>()).collect();
    let v = v.map_err(|_| format!("--at `{s}`: not a list of numbers"))?;
    if v.len() != dof || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "--at needs {} finite joint values, got {}",
            dof,
            v.len()
        ));
    }
    Ok(v)
}

fn parse_steps(s: &str) -> Result<(usize, usize), String> {
    let parts: Result<Vec<usize>, _> = s.split(',').map(|t| t.trim().parse::<usize>()).collect();
    let parts = parts.map_err(|_| format!("--steps `{s}`: need N or N,M"))?;
    let (a, b) = match parts.as_slice() {
        [n] => (*n, *n),
        [n, m] => (*n, *m),
        _ => return Err(format!("--steps `{s}`: need N or N,M")),
    };
    if a < 2 || b < 2 || a.saturating_mul(b) > 25_000_000 {
        return Err(format!(
            "--steps `{s}`: each count must be at least 2 (and the grid at most 25 million points)"
        ));
    }
    Ok((a, b))
}

fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The result of a map (also used by the tests through the CSV).
pub struct MapResult {
    /// Grid values of the first axis.
    pub us: Vec<f64>,
    /// Grid values of the second axis.
    pub vs: Vec<f64>,
    /// Row-major over `(v, u)`: `values[j * us.len() + i]`.
    pub values: Vec<Result<f64, Failure>>,
}

/// Evaluate the map (parallel over the grid points, progress on stderr when it is a terminal).
pub fn evaluate(
    target: &Target,
    axes: &[Axis; 2],
    base: &[f64],
    kind: IndexKind,
    us: Vec<f64>,
    vs: Vec<f64>,
) -> MapResult {
    let n = us.len() * vs.len();
    let pb = progress(n as u64, "map");
    let values: Vec<Result<f64, Failure>> = (0..n)
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % us.len(), k / us.len());
            let x = point(target, axes, base, us[i], vs[j]);
            let r = target.indices(&x).and_then(|r| {
                let v = kind.value(&r);
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(Failure::Invalid(runtime::indices::IndexError::Overflow))
                }
            });
            pb.inc(1);
            r
        })
        .collect();
    pb.finish_and_clear();
    MapResult { us, vs, values }
}

/// The most worker threads `--threads` takes: more only spawn idle threads (100,000 of them
/// never finished starting).
const MAX_THREADS: usize = 1024;

/// Run `map`.
pub fn run(args: &MapArgs) -> ExitCode {
    if let Some(t) = args.threads
        && t > MAX_THREADS
    {
        return usage(format!("--threads {t}: at most {MAX_THREADS}"));
    }
    let target = match Target::load(&args.spec, args.space) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let slice = match Slice::parse(args, &target) {
        Ok(s) => s,
        Err(e) => return usage(e),
    };
    let prefix = args
        .output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}_{}", target.name(), args.index.word())));
    let csv_path = prefix.with_extension("csv");
    let svg_path = prefix.with_extension("svg");
    // Neither file may replace the spec, and both go where they can (before any work).
    if let Err(code) = super::distinct_outputs(
        &[("the spec", args.spec.as_path())],
        &[
            ("the CSV", Some(csv_path.as_path())),
            ("the SVG", Some(svg_path.as_path())),
        ],
    ) {
        return code;
    }
    let (us, vs) = slice.grids();

    let t0 = Instant::now();
    let result = match slice.evaluate(args, &target, us, vs) {
        Ok(r) => r,
        Err(e) => return usage(e),
    };
    let elapsed = t0.elapsed();

    // CSV: one row per grid point.
    let csv = csv_text(args.index, &slice.axes, &result);
    if let Err(e) = super::write_output(&csv_path, &csv) {
        eprintln!("error: cannot write {}: {e}", csv_path.display());
        return ExitCode::from(1);
    }

    let (matrix, unit, acc) = target.matrix_words();
    let log = match args.scale {
        Scale::Log => true,
        Scale::Linear => false,
        Scale::Auto => matches!(args.index, IndexKind::Cond | IndexKind::Manip),
    };
    let counts = Counts::new(&result);
    let title = format!("{}: {}", target.name(), args.index.word());
    let subtitle = format!("{}; {}", matrix, args.index.describe(&unit, &acc));
    let axes = &slice.axes;
    let plot = svg::HeatMap {
        title: &title,
        subtitle: &subtitle,
        x_label: &axes[0].plot_label(),
        y_label: &axes[1].plot_label(),
        xs: result.us.iter().map(|u| axes[0].shown(*u)).collect(),
        ys: result.vs.iter().map(|v| axes[1].shown(*v)).collect(),
        values: &result.values,
        log,
    };
    if let Err(e) = plot
        .render()
        .and_then(|svg| super::write_output(&svg_path, &svg))
    {
        eprintln!("error: cannot write {}: {e}", svg_path.display());
        return ExitCode::from(1);
    }
    outln!("mechanism: {} ({} DOF)", target.name(), target.dof());
    outln!("matrix: {matrix}; unit {unit}");
    outln!("index: {}", args.index.describe(&unit, &acc));
    slice.print_grid();
    counts.print();
    let (nu, nv) = (slice.nu, slice.nv);
    outln!(
        "time: {:.3} s ({:.2} us per point, {} threads)",
        elapsed.as_secs_f64(),
        elapsed.as_secs_f64() * 1e6 / (nu * nv) as f64,
        args.threads.unwrap_or_else(rayon::current_num_threads)
    );
    outln!("wrote {} and {}", csv_path.display(), svg_path.display());
    ExitCode::SUCCESS
}

/// A usage error: the message on stderr, exit code 2.
fn usage(msg: String) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(2)
}

/// The slice from the arguments: axes, ranges, grid sizes and the base point.
struct Slice {
    axes: [Axis; 2],
    ranges: [(f64, f64); 2],
    nu: usize,
    nv: usize,
    base: Vec<f64>,
}

impl Slice {
    /// `--axes`, `--range`, `--steps` and `--at`, checked in that order.
    fn parse(args: &MapArgs, target: &Target) -> Result<Slice, String> {
        let axes = resolve_axes(target, args.axes.as_deref())?;
        let ranges = match &args.range {
            None => [axes[0].default_range(), axes[1].default_range()],
            Some(s) => parse_ranges(s)?,
        };
        let (nu, nv) = parse_steps(&args.steps)?;
        let base = base_point(target, args.at.as_deref())?;
        Ok(Slice {
            axes,
            ranges,
            nu,
            nv,
            base,
        })
    }

    /// The grid values of the two axes.
    fn grids(&self) -> (Vec<f64>, Vec<f64>) {
        let us = grid(self.ranges[0].0, self.ranges[0].1, self.nu);
        let vs = grid(self.ranges[1].0, self.ranges[1].1, self.nv);
        (us, vs)
    }

    /// The map over the grid values `us`, `vs`, on `--threads` worker threads.
    fn evaluate(
        &self,
        args: &MapArgs,
        target: &Target,
        us: Vec<f64>,
        vs: Vec<f64>,
    ) -> Result<MapResult, String> {
        let (axes, base) = (&self.axes, &self.base);
        Ok(match args.threads {
            Some(t) => match rayon::ThreadPoolBuilder::new().num_threads(t).build() {
                Ok(pool) => pool.install(|| evaluate(target, axes, base, args.index, us, vs)),
                Err(e) => return Err(format!("--threads: {e}")),
            },
            None => evaluate(target, axes, base, args.index, us, vs),
        })
    }

    /// The `grid:` line.
    fn print_grid(&self) {
        let (axes, ranges) = (&self.axes, &self.ranges);
        outln!(
            "grid: {} x {} = {} points ({} in [{}, {}], {} in [{}, {}])",
            self.nu,
            self.nv,
            self.nu * self.nv,
            axes[0].label(),
            fmt_g(axes[0].shown(ranges[0].0)),
            fmt_g(axes[0].shown(ranges[0].1)),
            axes[1].label(),
            fmt_g(axes[1].shown(ranges[1].0)),
            fmt_g(axes[1].shown(ranges[1].1))
        );
    }
}

/// `--range`: `LO:HI` for both axes or `LO:HI,LO:HI`.
fn parse_ranges(s: &str) -> Result<[(f64, f64); 2], String> {
    let parts: Vec<&str> = s.split(',').collect();
    let parsed: Result<Vec<(f64, f64)>, String> = parts.iter().map(|p| parse_range(p)).collect();
    match parsed.as_deref() {
        Ok([r]) => Ok([*r, *r]),
        Ok([r, t]) => Ok([*r, *t]),
        Ok(_) => Err(format!("--range `{s}`: need LO:HI or LO:HI,LO:HI")),
        Err(e) => Err(e.clone()),
    }
}

/// The CSV: one row per grid point.
fn csv_text(index: IndexKind, axes: &[Axis; 2], result: &MapResult) -> String {
    let mut csv = String::new();
    csv.push_str(&format!(
        "ix,iy,{},{},{},status\n",
        axes[0].label(),
        axes[1].label(),
        index.word()
    ));
    for (k, r) in result.values.iter().enumerate() {
        let (i, j) = (k % result.us.len(), k / result.us.len());
        let (u, v) = (axes[0].shown(result.us[i]), axes[1].shown(result.vs[j]));
        match r {
            Ok(val) => csv.push_str(&format!("{i},{j},{u:.9},{v:.9},{val:.12e},ok\n")),
            Err(f) => csv.push_str(&format!("{i},{j},{u:.9},{v:.9},,{}\n", f.word())),
        }
    }
    csv
}

/// The values' range and the failures by kind.
struct Counts {
    /// The regular points' values.
    finite: Vec<f64>,
    vmin: f64,
    vmax: f64,
    singular: usize,
    unreachable: usize,
    invalid: usize,
}

impl Counts {
    fn new(result: &MapResult) -> Counts {
        let finite: Vec<f64> = result
            .values
            .iter()
            .filter_map(|r| r.clone().ok())
            .collect();
        let (vmin, vmax) = finite
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        let singular = result
            .values
            .iter()
            .filter(|r| matches!(r, Err(Failure::Singular(_))))
            .count();
        let unreachable = result
            .values
            .iter()
            .filter(|r| matches!(r, Err(Failure::Unreachable)))
            .count();
        let invalid = result
            .values
            .iter()
            .filter(|r| matches!(r, Err(Failure::Invalid(_))))
            .count();
        Counts {
            finite,
            vmin,
            vmax,
            singular,
            unreachable,
            invalid,
        }
    }

    /// The `range:` and `singular:` lines.
    fn print(&self) {
        if self.finite.is_empty() {
            outln!("range: no regular point");
        } else {
            outln!(
                "range: {} .. {} over {} regular points",
                fmt_g(self.vmin),
                fmt_g(self.vmax),
                self.finite.len()
            );
        }
        outln!(
            "singular: {}, unreachable: {}, invalid: {}",
            self.singular,
            self.unreachable,
            self.invalid
        );
    }
}

/// A compact number for messages.
pub fn fmt_g(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e4) {
        format!("{v:.4e}")
    } else {
        format!("{v:.6}")
    }
}

use super::svg;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_parse() {
        assert_eq!(parse_steps("11"), Ok((11, 11)));
        assert_eq!(parse_steps("11,3"), Ok((11, 3)));
        assert!(parse_steps("1").is_err());
        assert!(parse_steps("a").is_err());
        assert!(parse_steps("2,2,2").is_err());
    }

    #[test]
    fn grid_ends_at_the_range() {
        let g = grid(-0.1, 0.1, 5);
        assert_eq!(g.len(), 5);
        assert_eq!(g[0], -0.1);
        assert_eq!(g[4], 0.1);
        assert!(g[2].abs() < 1e-17);
    }
}
