//! The workspace tools of the CLI (`docs/indices.md`): `map` and `isotropy`.
//!
//! Both evaluate the mechanism with the runtime, not with generated code:
//! * trees: the joint-space inertia `H(q)` by the CRBA ([`runtime::rnea::mass_matrix`]);
//! * parallel mechanisms: [`runtime::parallel::noc::actuator_mass_matrix`] (`A⁻ᵀ I A⁻¹`,
//!   actuator space, the default) or [`runtime::parallel::noc::mass_matrix`] (`I`, platform
//!   speeds), through [`runtime::indices::parallel_indices`]. Where the runtime returns
//!   `Err(Singular)` the point is marked singular (or unreachable, for `Site::Reach`).

pub mod design;
pub mod isotropy;
pub mod map;
pub mod reduce;
pub mod svg;

use std::process::ExitCode;

use clap::ValueEnum;
use codegen::spec::Mechanism;
use runtime::indices::{self, EvalError, IndexError, InertiaIndices, Space};
use runtime::model::{JointKind, Model};
use runtime::parallel::{ParallelModel, Plan, PlatformMotion};
use runtime::scalar::Site;

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

/// A mechanism ready to evaluate.
pub enum Target {
    /// A tree: `x = q`.
    Tree(Model),
    /// A parallel mechanism: `x` its platform coordinates.
    Parallel {
        /// The model.
        model: Box<ParallelModel>,
        /// The runtime's plan.
        plan: Box<Plan>,
        /// Actuator or platform space.
        space: Space,
    },
    /// Closed loops in joint coordinates: `x` the independent (actuated) joint positions; the
    /// others follow by assembly from home (the home branch).
    Closed {
        /// The model.
        model: Box<runtime::closed::ClosedModel>,
        /// The runtime's plan.
        plan: Box<runtime::closed::Plan>,
    },
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
        let target = match mechanism {
            Mechanism::Tree(model) => Target::Tree(model),
            Mechanism::Parallel(model) => {
                let plan = Plan::new(&model).map_err(|e| format!("error: {name}: {e}\n"))?;
                Target::Parallel {
                    model: Box::new(model),
                    plan: Box::new(plan),
                    space: match space {
                        SpaceArg::Actuator => Space::Actuator,
                        SpaceArg::Platform => Space::Platform,
                    },
                }
            }
            Mechanism::Closed(model) => {
                let plan = runtime::closed::Plan::new(&model)
                    .map_err(|e| format!("error: {name}: {e}\n"))?;
                Target::Closed {
                    model: Box::new(model),
                    plan: Box::new(plan),
                }
            }
        };
        Ok((target, warnings))
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        match self {
            Target::Tree(m) => m.dof(),
            Target::Parallel { model, .. } => model.dof(),
            Target::Closed { model, .. } => model.dof(),
        }
    }

    /// The mechanism's name.
    pub fn name(&self) -> &str {
        match self {
            Target::Tree(m) => &m.name,
            Target::Parallel { model, .. } => &model.name,
            Target::Closed { model, .. } => &model.name,
        }
    }

    /// The indices at the coordinates `x` (joint positions of a tree, platform coordinates of a
    /// parallel mechanism).
    pub fn indices(&self, x: &[f64]) -> Result<InertiaIndices, Failure> {
        match self {
            Target::Tree(model) => indices::tree_indices(model, x).map_err(Failure::Invalid),
            Target::Parallel { plan, space, .. } => indices::parallel_indices(plan, x, *space)
                .map_err(|e| match e {
                    EvalError::Singular(s) if matches!(s.site, Site::Reach(_)) => {
                        Failure::Unreachable
                    }
                    EvalError::Singular(s) => Failure::Singular(s.site),
                    EvalError::Index(i) => Failure::Invalid(i),
                }),
            Target::Closed { .. } => {
                let m = self.matrix(x)?;
                indices::inertia_indices(&m).map_err(Failure::Invalid)
            }
        }
    }

    /// The matrix `Λ` the indices use at `x` (the joint-space, actuator-space or platform
    /// inertia), symmetrized and checked (`runtime::indices::validate_spd`).
    pub fn matrix(&self, x: &[f64]) -> Result<nalgebra::DMatrix<f64>, Failure> {
        use runtime::parallel::noc;
        let singular = |s: runtime::scalar::Singular| match s.site {
            Site::Reach(_) => Failure::Unreachable,
            site => Failure::Singular(site),
        };
        let m = match self {
            Target::Tree(model) => {
                if x.len() != model.dof() || x.iter().any(|v| !v.is_finite()) {
                    return Err(Failure::Invalid(IndexError::NotFinite { row: 0, col: 0 }));
                }
                runtime::rnea::mass_matrix(model, x)
            }
            Target::Parallel { plan, space, .. } => {
                let rows = match space {
                    Space::Actuator => noc::actuator_mass_matrix(plan, x),
                    Space::Platform => noc::mass_matrix(plan, x),
                }
                .map_err(singular)?;
                indices::from_rows(&rows).map_err(Failure::Invalid)?
            }
            Target::Closed { plan, .. } => {
                use runtime::closed::noc as cnoc;
                if x.len() != plan.dof() || x.iter().any(|v| !v.is_finite()) {
                    return Err(Failure::Invalid(IndexError::NotFinite { row: 0, col: 0 }));
                }
                // Assemble on the home branch; no convergence = not reachable on it.
                let full = cnoc::forward_kinematics(plan, x, &vec![0.0; plan.nx()])
                    .map_err(|_| Failure::Unreachable)?;
                let rows = cnoc::mass_matrix(plan, &full).map_err(singular)?;
                indices::from_rows(&rows).map_err(Failure::Invalid)?
            }
        };
        indices::validate_spd(&m).map_err(Failure::Invalid)
    }

    /// Which matrix the indices use, and its unit (for the messages).
    pub fn matrix_words(&self) -> (String, String, String) {
        match self {
            Target::Closed { model, plan } => {
                let rev: Vec<bool> = plan
                    .independent
                    .iter()
                    .map(|&j| model.tree.joints[j].kind == JointKind::Revolute)
                    .collect();
                let (unit, acc) = if rev.iter().all(|r| *r) {
                    ("kg m^2", "rad/s^2 per N m")
                } else if rev.iter().all(|r| !*r) {
                    ("kg", "m/s^2 per N")
                } else {
                    ("mixed", "mixed")
                };
                (
                    "inertia S^T M S of the actuated (independent) joints, closed loops assembled on the home branch".into(),
                    unit.into(),
                    acc.into(),
                )
            }
            Target::Tree(model) => {
                let all_r = model.joints.iter().all(|j| j.kind == JointKind::Revolute);
                let all_p = model.joints.iter().all(|j| j.kind == JointKind::Prismatic);
                let (unit, acc) = if all_r {
                    ("kg m^2", "rad/s^2 per N m")
                } else if all_p {
                    ("kg", "m/s^2 per N")
                } else {
                    ("kg m^2 | kg m | kg (mixed joints)", "mixed")
                };
                (
                    "joint-space inertia H(q) (CRBA), task = joint coordinates (J = 1)".into(),
                    unit.into(),
                    acc.into(),
                )
            }
            Target::Parallel { model, space, .. } => {
                let revolute = model
                    .legs
                    .iter()
                    .map(|l| l.joints[l.actuated].kind == JointKind::Revolute)
                    .collect::<Vec<_>>();
                match space {
                    Space::Actuator => {
                        let (unit, acc) = if revolute.iter().all(|r| *r) {
                            ("kg m^2", "rad/s^2 per N m")
                        } else if revolute.iter().all(|r| !*r) {
                            ("kg", "m/s^2 per N")
                        } else {
                            ("mixed", "mixed")
                        };
                        (
                            "actuator-space inertia A^-T I A^-1 (actuator_mass_matrix), task = actuated joint coordinates".into(),
                            unit.into(),
                            acc.into(),
                        )
                    }
                    Space::Platform => {
                        let (unit, acc) = match model.motion {
                            PlatformMotion::Orientation { .. } => {
                                ("kg m^2", "rad/s^2 per unit effort")
                            }
                            PlatformMotion::PlanarPoint { .. } => ("kg", "m/s^2 per unit effort"),
                            PlatformMotion::Pose => ("kg m^2 | kg m | kg (mixed)", "mixed"),
                        };
                        (
                            "generalized inertia I in platform speeds u (mass_matrix), efforts tau = A^-T I u'".into(),
                            unit.into(),
                            acc.into(),
                        )
                    }
                }
            }
        }
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
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(format!("`{s}`: need finite LO < HI"));
    }
    Ok((lo, hi))
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
