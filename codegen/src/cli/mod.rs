//! The tools of the CLI: the workspace tools `map` and `isotropy` (`docs/indices.md`), and
//! the identification tools `identify` and `excite` (`docs/identification.md`: `identify`,
//! `excite`, with `tree_regressor`, `tape`, `samples`, `filter`, `wls`, `spec_update`).
//!
//! Both evaluate the mechanism with the runtime, not with generated code, through one
//! `Box<dyn` [`runtime::workspace::Workspace`]`>` (no match on the kind here):
//! * trees: the joint-space inertia `H(q)` by the CRBA ([`runtime::rnea::mass_matrix`]);
//! * parallel mechanisms: [`runtime::parallel::noc::actuator_mass_matrix`] (`A⁻ᵀ I A⁻¹`,
//!   actuator space, the default) or [`runtime::parallel::noc::mass_matrix`] (`I`, platform
//!   speeds), through [`runtime::indices::parallel_indices`];
//! * closed loops: the inertia of the independent joints, assembled on the home branch. Where the runtime returns
//!   `Err(Singular)` the point is marked singular (or unreachable, for `Site::Reach`).

pub mod closed_regressor;
#[cfg(feature = "urdf")]
pub mod convert;
pub mod design;
pub mod draw;
pub mod effort_plot;
pub mod excite;
pub mod excite_bounds;
pub mod filter;
pub mod fix_home;
pub mod grouping;
pub mod identify;
pub mod isotropy;
pub mod map;
pub mod platform_path;
pub mod platform_rates;
pub mod platform_regressor;
pub mod reduce;
pub mod regressor;
pub mod samples;
pub mod spec_update;
pub mod svg;
pub mod tape;
pub mod tape_lanes;
pub mod tree_regressor;
pub mod wls;

use std::process::ExitCode;

use clap::ValueEnum;
use codegen::spec::Mechanism;
use runtime::indices::{EvalError, IndexError, InertiaIndices, Space};
use runtime::scalar::Site;
use runtime::workspace::{Loops, Platform, Workspace};

/// Which index to map.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum IndexKind {
    /// Ma & Angeles' ψ with `σ = tr(M)/n`, Frobenius weights (units of `M` squared).
    Dci,
    /// Ma & Angeles' ψ with `σ = tr(M²)/tr(M)` and `(M − σ1)/σ`, Frobenius weights
    /// (dimensionless).
    Dci2,
    /// Condition number `λ_max/λ_min`.
    Cond,
    /// Asada's ratio `λ_min/λ_max` of the generalized inertia ellipsoid.
    Gie,
    /// Yoshikawa's dynamic manipulability `√det(B Bᵀ)`, `B = E⁻¹`.
    Manip,
    /// Khatib & Burdick's isotropic acceleration for unit effort limits.
    Iso,
}

impl IndexKind {
    /// The CSV column name.
    pub fn word(self) -> &'static str {
        match self {
            IndexKind::Dci => "dci",
            IndexKind::Dci2 => "dci2",
            IndexKind::Cond => "cond",
            IndexKind::Gie => "gie",
            IndexKind::Manip => "manip",
            IndexKind::Iso => "iso",
        }
    }

    /// The index's value.
    pub fn value(self, r: &InertiaIndices) -> f64 {
        match self {
            IndexKind::Dci => r.dci_trace.psi,
            IndexKind::Dci2 => r.dci_dimensionless.psi,
            IndexKind::Cond => r.condition,
            IndexKind::Gie => r.gie_ratio,
            IndexKind::Manip => r.manipulability,
            IndexKind::Iso => r.isotropic_acceleration,
        }
    }

    /// A one-line definition, with the weights and the unit (`unit`: the unit of the inertia,
    /// `acc`: acceleration per unit effort).
    pub fn describe(self, unit: &str, acc: &str) -> String {
        match self {
            IndexKind::Dci => format!(
                "Ma & Angeles DCI psi = 1/2 e^T W e, e = upper triangle of M - sigma*1, sigma = tr(M)/n; W = Frobenius (1 on the diagonal, 2 off it); unit ({unit})^2"
            ),
            IndexKind::Dci2 => "Ma & Angeles DCI psi = 1/2 e^T W e, e = upper triangle of (M - sigma*1)/sigma, sigma = tr(M^2)/tr(M); W = Frobenius (1 on the diagonal, 2 off it); dimensionless".into(),
            IndexKind::Cond => "condition number lambda_max/lambda_min of M; dimensionless".into(),
            IndexKind::Gie => "Asada GIE ratio lambda_min/lambda_max of M; dimensionless".into(),
            IndexKind::Manip => format!(
                "Yoshikawa dynamic manipulability sqrt(det(B B^T)), B = J M^-1 (per unit effort); unit ({acc})^n"
            ),
            IndexKind::Iso => format!(
                "Khatib & Burdick isotropic acceleration, |tau_i| <= 1; unit {acc}"
            ),
        }
    }
}

/// Where a parallel mechanism's indices are taken (ignored for trees).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SpaceArg {
    /// Actuated joint coordinates: `M = A⁻ᵀ I A⁻¹`.
    Actuator,
    /// Platform speeds `u`: `Λ = I`, efforts through `A⁻ᵀ`.
    Platform,
}

/// Why a point has no value.
#[derive(Clone, Debug, PartialEq)]
pub enum Failure {
    /// The runtime returned `Err(Singular)` with `Site::Reach`: the pose is outside the workspace.
    Unreachable,
    /// The runtime returned `Err(Singular)` at another site (leg or parallel singularity).
    Singular(Site),
    /// The inertia matrix failed the index checks (not positive definite, …).
    Invalid(IndexError),
}

impl Failure {
    /// The CSV status word.
    pub fn word(&self) -> String {
        match self {
            Failure::Unreachable => "unreachable".into(),
            Failure::Singular(site) => match site {
                Site::Leg(k) => format!("singular_leg_{k}"),
                Site::Actuation(i) => format!("singular_actuation_{i}"),
                Site::Constraint(i) => format!("singular_constraint_{i}"),
                _ => "singular".into(),
            },
            Failure::Invalid(_) => "invalid".into(),
        }
    }
}

/// A mechanism ready to evaluate, whatever its kind, and where its indices are taken.
pub struct Target {
    /// The mechanism: `x` a tree's joint positions, a platform's coordinates, or closed loops'
    /// independent (actuated) joint positions, the others following by assembly from home (the
    /// home branch); see [`runtime::workspace`].
    pub mechanism: Box<dyn Workspace + Send + Sync>,
    /// Actuator or platform space (platforms only).
    pub space: Space,
}

/// The runtime's evaluator of a loaded mechanism: the one place the CLI meets the kind, to
/// construct it. The error is the runtime's refusal of the model, rendered for `name`.
pub fn workspace(
    name: &str,
    mechanism: Mechanism,
) -> Result<Box<dyn Workspace + Send + Sync>, String> {
    let refused = |e: String| format!("error: {name}: {e}\n");
    Ok(match mechanism {
        Mechanism::Tree(model) => Box::new(model),
        Mechanism::Parallel(model) => Box::new(Platform::new(model).map_err(refused)?),
        Mechanism::Closed(model) => Box::new(Loops::new(model).map_err(refused)?),
    })
}

/// The failure of a point, from the runtime's error.
fn failure(e: EvalError) -> Failure {
    match e {
        EvalError::Singular(s) if matches!(s.site, Site::Reach(_)) => Failure::Unreachable,
        EvalError::Singular(s) => Failure::Singular(s.site),
        EvalError::Index(i) => Failure::Invalid(i),
        EvalError::Unassembled => Failure::Unreachable,
    }
}

/// A spec file's name (as given) and text. On failure the error is printed and the exit code
/// returned: 1 when the file cannot be read, 2 when it is not UTF-8 (an invalid spec).
pub fn read_spec(spec: &std::path::Path) -> Result<(String, String), ExitCode> {
    let bytes = codegen::build_script::read_spec(spec).map_err(|e| {
        eprintln!("error: cannot read {}: {e}", spec.display());
        ExitCode::from(1)
    })?;
    let name = spec.to_string_lossy().into_owned();
    let source = codegen::spec::source_text(&name, bytes).map_err(|d| {
        eprint!("{}", d.render());
        ExitCode::from(2)
    })?;
    Ok((name, source))
}

/// The `[scene]` sidecar of `spec`: the file `--scene` names, else `ROBOT.scene.toml` beside a
/// `ROBOT.urdf` when it exists (with a note on standard error), else none.
pub fn sidecar(
    spec: &std::path::Path,
    given: Option<&std::path::Path>,
) -> Result<Option<codegen::spec::SceneFile>, ExitCode> {
    let path = match given {
        Some(p) => p.to_path_buf(),
        None => {
            let Some(beside) = codegen::build_script::scene_beside(spec) else {
                return Ok(None);
            };
            eprintln!("note: with the scene file {}", beside.display());
            beside
        }
    };
    let (name, text) = read_spec(&path)?;
    Ok(Some(codegen::spec::SceneFile { name, text }))
}

impl Target {
    /// Load a spec for the tools. Errors and warnings are printed; the exit code is returned.
    pub fn load(spec: &std::path::Path, space: SpaceArg) -> Result<Target, ExitCode> {
        let (name, source) = read_spec(spec)?;
        let (target, warnings) = Target::compile(&name, &source, space).map_err(|e| {
            eprint!("{e}");
            ExitCode::from(2)
        })?;
        if !warnings.is_empty() {
            eprint!("{warnings}");
        }
        Ok(target)
    }

    /// A spec's text for the tools (no I/O), with the rendered warnings. The error is the
    /// rendered diagnostics, or the runtime's refusal of the model.
    pub fn compile(name: &str, source: &str, space: SpaceArg) -> Result<(Target, String), String> {
        let (mechanism, warnings) =
            codegen::spec::load_mechanism(name, source).map_err(|d| d.render())?;
        let warnings = if warnings.is_empty() {
            String::new()
        } else {
            warnings.render()
        };
        let target = Target {
            mechanism: workspace(name, mechanism)?,
            space: match space {
                SpaceArg::Actuator => Space::Actuator,
                SpaceArg::Platform => Space::Platform,
            },
        };
        Ok((target, warnings))
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.mechanism.dof()
    }

    /// The mechanism's name.
    pub fn name(&self) -> &str {
        self.mechanism.name()
    }

    /// The indices at the coordinates `x`.
    pub fn indices(&self, x: &[f64]) -> Result<InertiaIndices, Failure> {
        self.mechanism.indices(x, self.space).map_err(failure)
    }

    /// The matrix `Λ` the indices use at `x` (the joint-space, actuator-space or platform
    /// inertia), symmetrized and checked (`runtime::indices::validate_spd`).
    pub fn matrix(&self, x: &[f64]) -> Result<nalgebra::DMatrix<f64>, Failure> {
        self.mechanism.inertia(x, self.space).map_err(failure)
    }

    /// Which matrix the indices use, and its unit (for the messages).
    pub fn matrix_words(&self) -> (String, String, String) {
        let w = self.mechanism.inertia_words(self.space);
        (w.matrix.into(), w.unit.into(), w.acceleration.into())
    }
}

/// A deterministic pseudo-random generator (SplitMix64), so that runs repeat exactly.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// Seeded generator.
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    /// Next `u64`.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

/// A progress bar on stderr, hidden when stderr is not a terminal (pipes, CI, tests).
pub fn progress(len: u64, what: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::new(len);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} (eta {eta})",
    ) {
        pb.set_style(style);
    }
    pb.set_message(what.to_string());
    pb
}

/// Quaternion product `a ⊗ b` (`[w, x, y, z]`).
pub fn quat_mul(a: &[f64; 4], b: &[f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The unit quaternion of a rotation by `angle` (rad) about base axis `axis` (0 = x, 1 = y,
/// 2 = z).
pub fn quat_axis(axis: usize, angle: f64) -> [f64; 4] {
    let (s, c) = (0.5 * angle).sin_cos();
    let mut q = [c, 0.0, 0.0, 0.0];
    q[1 + axis.min(2)] = s;
    q
}

/// Parse a `lo:hi` range.
pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("`{s}`: a range is written LO:HI, e.g. -0.1:0.1"))?;
    let lo: f64 = a
        .trim()
        .parse()
        .map_err(|_| format!("`{a}` is not a number"))?;
    let hi: f64 = b
        .trim()
        .parse()
        .map_err(|_| format!("`{b}` is not a number"))?;
    // The width too: `-1e308:1e308` spans infinity, and the grid and the heat map's axis
    // became NaN (a panic in the plotting library). And the heat map's cells reach half a
    // cell, at most half the width, beyond each end: `8e307:1.6e308` put its edge at infinity
    // and the plotting library's axis ticks looped forever.
    let w = hi - lo;
    if !(lo.is_finite()
        && hi.is_finite()
        && lo < hi
        && w.is_finite()
        && (lo - w).is_finite()
        && (hi + w).is_finite())
    {
        return Err(format!(
            "`{s}`: need finite LO < HI, with HI - LO, LO - (HI - LO) and HI + (HI - LO) finite"
        ));
    }
    Ok((lo, hi))
}

/// Write `text` to the output file `path` (`codegen::build_script::write_if_changed`: a
/// temporary file renamed into place, untouched when equal; a device, FIFO or socket such as
/// `/dev/stdout`, `/dev/full` or a named pipe only written into, never read first), the error
/// as its message.
pub fn write_output(path: &std::path::Path, text: &str) -> Result<(), String> {
    codegen::build_script::write_if_changed(path, text).map_err(|e| e.to_string())
}

/// The file a path names, for comparing paths: the canonical path when it exists, else its
/// directory's canonical path joined with its name (a file about to be written), else the path.
fn file_identity(p: &std::path::Path) -> std::path::PathBuf {
    if let Ok(c) = std::fs::canonicalize(p) {
        return c;
    }
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    match (std::fs::canonicalize(dir), p.file_name()) {
        (Ok(d), Some(n)) => d.join(n),
        _ => p.to_path_buf(),
    }
}

/// The inputs of a tool that reads `spec` and its scene file `scene` (the one `--scene` names,
/// or `ROBOT.scene.toml` beside a URDF), for [`distinct_outputs`]: an output onto either
/// replaced what had just been read.
pub fn spec_inputs<'a>(
    spec: &'a std::path::Path,
    scene: Option<&'a std::path::Path>,
) -> Vec<(&'static str, &'a std::path::Path)> {
    let mut inputs = vec![("the spec", spec)];
    inputs.extend(scene.map(|s| ("the scene file", s)));
    inputs
}

/// Refuse output files that would overwrite an input or another output (`(flag, path)` each,
/// the inputs' flag being what names them in the message, e.g. `"the spec"`): exit code 2
/// before any work, so that a slip of the shell never replaces the measurements with a plot;
/// and outputs onto a directory or into a missing one: exit code 1, nothing written.
pub fn distinct_outputs(
    inputs: &[(&str, &std::path::Path)],
    outputs: &[(&str, Option<&std::path::Path>)],
) -> Result<(), ExitCode> {
    let outputs: Vec<(&str, &std::path::Path)> = outputs
        .iter()
        .filter_map(|(f, p)| p.map(|p| (*f, p)))
        .collect();
    for (k, (flag, path)) in outputs.iter().enumerate() {
        let id = file_identity(path);
        let clash = inputs
            .iter()
            .find(|(_, q)| file_identity(q) == id)
            .map(|(what, _)| what.to_string())
            .or_else(|| {
                outputs[..k]
                    .iter()
                    .find(|(_, q)| file_identity(q) == id)
                    .map(|(f, _)| format!("the file of {f}"))
            });
        if let Some(what) = clash {
            eprintln!(
                "error: {flag} {}: that is {what}, which it would overwrite: write to another file",
                path.display()
            );
            return Err(ExitCode::from(2));
        }
    }
    // Where a file cannot go, no other is written either (I/O error, exit code 1, before
    // any work).
    for (flag, path) in &outputs {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => std::path::Path::new("."),
        };
        let why = if path.is_dir() {
            Some("is a directory")
        } else if !dir.is_dir() {
            Some("its directory does not exist")
        } else {
            None
        };
        if let Some(why) = why {
            eprintln!("error: {flag} {}: {why}", path.display());
            return Err(ExitCode::from(1));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse() {
        assert_eq!(parse_range("-0.1:0.1"), Ok((-0.1, 0.1)));
        assert!(parse_range("0.1:-0.1").is_err());
        assert!(parse_range("0.1").is_err());
        assert!(parse_range("a:1").is_err());
        assert!(parse_range("nan:1").is_err());
        assert!(parse_range("-1e308:1e308").is_err());
        // A heat map's cell edge at infinity: `map` hung in the plotting library (QA).
        assert!(parse_range("8e307:1.6e308").is_err());
        assert!(parse_range("-1.6e308:-8e307").is_err());
        assert!(parse_range("1e308:1.1e308").is_ok());
    }

    #[test]
    fn quaternions_compose_like_rotations() {
        // Two quarter turns about z make a half turn about z.
        let q = quat_mul(
            &quat_axis(2, std::f64::consts::FRAC_PI_2),
            &quat_axis(2, std::f64::consts::FRAC_PI_2),
        );
        assert!(q[0].abs() < 1e-15 && (q[3].abs() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn rng_is_uniform_enough_and_repeatable() {
        let mut a = Rng::new(7);
        let mut b = Rng::new(7);
        let xs: Vec<f64> = (0..1000).map(|_| a.uniform(-1.0, 1.0)).collect();
        let ys: Vec<f64> = (0..1000).map(|_| b.uniform(-1.0, 1.0)).collect();
        assert_eq!(xs, ys);
        assert!(xs.iter().all(|x| (-1.0..1.0).contains(x)));
        let mean = xs.iter().sum::<f64>() / 1000.0;
        assert!(mean.abs() < 0.1, "{mean}");
    }
}
