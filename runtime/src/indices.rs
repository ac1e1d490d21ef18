//! Dynamic performance indices of an inertia matrix (the lecture's p. 31; `docs/indices.md`).
//!
//! Every index is computed from two matrices of the same `n × n` size:
//! * `Λ`, the inertia in the *task coordinates* (symmetric positive definite), and
//! * `E`, the *effort map* `τ = E ẍ` from task accelerations to actuator efforts when the
//!   mechanism is at rest and gravity is compensated (`E = M J⁻¹` for a joint-space inertia `M`
//!   and a square task Jacobian `ẋ = J q̇`; then `Λ = J⁻ᵀ M J⁻¹`).
//!
//! [`inertia_indices`] takes the task coordinates to be the coordinates of `M` itself (`J = 1`,
//! so `Λ = E = M`): the joint-space inertia of a tree, or the actuator-space inertia
//! `A⁻ᵀ I A⁻¹` of a parallel mechanism. [`task_indices`] takes a square Jacobian, and
//! [`platform_indices`] the platform speeds `u` of a parallel mechanism (`Λ = I`, `E = A⁻ᵀ I`,
//! with `q̇ = A u`). The indices:
//!
//! | field | definition | source |
//! |---|---|---|
//! | `eigenvalues`, `axes` | eigenvalues `λ₁ ≤ … ≤ λₙ` and unit eigenvectors of `Λ`; the generalized inertia ellipsoid `{v : vᵀ Λ v = 1}` has semi-axes `1/√λᵢ` along them | Asada 1983 |
//! | `gie_ratio` | `λ₁ / λₙ` (1 when isotropic, → 0 near a singularity) | Asada 1983 |
//! | `condition` | `λₙ / λ₁`, the 2-norm condition number of `Λ` | |
//! | `dci_trace` | `σ = tr Λ / n`, `D = Λ − σ1`, `ψ = ½ dᵀ W d` | Ma & Angeles 1990 |
//! | `dci_dimensionless` | `σ = tr(Λ²) / tr Λ`, `E = (Λ − σ1)/σ`, `ψ = ½ eᵀ W e` | Ma & Angeles 1990 |
//! | `manipulability` | `w = √det(B Bᵀ) = 1/|det E|` with `B = E⁻¹ = J M⁻¹` | Yoshikawa 1985 |
//! | `acceleration_radii` | semi-axes of `{ẍ = B τ : ‖τ‖₂ ≤ 1}`: the singular values of `B`, ascending | Yoshikawa 1985 |
//! | `isotropic_acceleration` | radius of the largest ball inside `{ẍ = B τ : |τᵢ| ≤ 1}`: `minᵢ 1/‖row i of E‖₂` | Khatib & Burdick 1987 |
//!
//! `d` (and `e`) stack the `n(n+1)/2` upper-triangle entries `i ≤ j` of `D` (of `E`) and `W` is
//! diagonal ([`Weights`]); the indices here use Frobenius weights (1 on the diagonal, 2 off it),
//! for which `ψ = ½ ‖D‖²_F` and each `σ` is the minimizer of its `ψ` (so `ψ` is the distance to
//! the nearest isotropic matrix `σ·1`). [`dci`] takes any weights. `ψ = 0` exactly when
//! `Λ = σ·1` (dynamic isotropy).
//!
//! Units: `Λ` in the units of the task coordinates' inertia (kg·m² for angles, kg for lengths,
//! mixed for mixed coordinates); `σ` of the first normalization in the same unit and `ψ` in its
//! square; the second normalization is dimensionless. Efforts are per unit effort (1 N·m or
//! 1 N per actuator), so `manipulability` and `isotropic_acceleration` are accelerations per unit
//! effort (rad/s² per N·m, m/s² per N).
//!
//! Bad input (NaN or infinite entries, a non-square or non-symmetric matrix, a matrix that is not
//! positive definite, a singular Jacobian) returns an [`IndexError`]; nothing here panics on data
//! and no result is NaN.
//!
//! References: H. Asada, "A geometrical representation of manipulator dynamics and its
//! application to arm design", ASME J. Dyn. Syst. Meas. Control 105(3), 1983; T. Yoshikawa,
//! "Dynamic manipulability of robot manipulators", IEEE ICRA 1985; O. Khatib and J. Burdick,
//! "Optimization of dynamics in manipulator design: the operational space formulation",
//! Int. J. Robotics and Automation 2(2), 1987; O. Ma and J. Angeles, "The concept of dynamic
//! isotropy and its applications to inverse kinematics and trajectory planning", IEEE ICRA 1990,
//! pp. 481–486.

// Negated float comparisons make NaN fail the test (as in `parallel::noc`).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use nalgebra::DMatrix;
use nalgebra::linalg::{SVD, SymmetricEigen};

/// Largest accepted asymmetry `|m_ij − m_ji|`, relative to the largest `|m_kl|`. Inertia
/// matrices assembled as `TᵀMT` are symmetric to rounding (about 1e-16); the input is then
/// symmetrized.
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// Positive definiteness: pivot `k` of the `LDLᵀ` factorization must exceed
/// `DEFINITENESS_TOLERANCE` times the diagonal entry it came from (as for forward dynamics).
pub const DEFINITENESS_TOLERANCE: f64 = 1e-12;

/// Iterations allowed to the eigenvalue and singular-value solvers (they converge in a few
/// dozen for the sizes of mechanisms).
const MAX_ITERATIONS: usize = 10_000;

/// Why the indices could not be computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IndexError {
    /// The matrix has no rows.
    Empty,
    /// The matrix is not square (or its rows have different lengths), or two matrices that must
    /// have the same size do not.
    Shape {
        /// Rows (or the expected size).
        rows: usize,
        /// Columns of the offending row (or the size found).
        cols: usize,
    },
    /// Entry `(row, col)` is NaN or infinite.
    NotFinite {
        /// Row.
        row: usize,
        /// Column.
        col: usize,
    },
    /// `|m_ij − m_ji|` exceeds [`SYMMETRY_TOLERANCE`] times the largest entry.
    NotSymmetric {
        /// Row.
        row: usize,
        /// Column.
        col: usize,
        /// The relative asymmetry.
        asymmetry: f64,
    },
    /// Pivot `pivot` of `LDLᵀ` is not above [`DEFINITENESS_TOLERANCE`] times its diagonal
    /// entry (or an eigenvalue is not positive).
    NotPositiveDefinite {
        /// The pivot.
        pivot: usize,
        /// Its value.
        value: f64,
    },
    /// The task Jacobian (or the actuation matrix) is singular: the effort map `E` has a zero
    /// singular value.
    SingularJacobian,
    /// The weights are not `n(n+1)/2` finite, non-negative numbers.
    Weights,
    /// The eigenvalue or singular-value iteration did not converge.
    NoConvergence,
    /// An index overflowed (the matrix spans more than the `f64` range: e.g. a condition
    /// number above 1e308).
    Overflow,
}

impl fmt::Display for IndexError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            IndexError::Empty => write!(f, "the matrix is empty"),
            IndexError::Shape { rows, cols } => {
                write!(f, "the matrix is not square ({rows} rows, {cols} columns)")
            }
            IndexError::NotFinite { row, col } => {
                write!(f, "entry ({row}, {col}) is NaN or infinite")
            }
            IndexError::NotSymmetric {
                row,
                col,
                asymmetry,
            } => write!(
                f,
                "the matrix is not symmetric: entries ({row}, {col}) and ({col}, {row}) differ by {asymmetry:e} of the largest entry"
            ),
            IndexError::NotPositiveDefinite { pivot, value } => write!(
                f,
                "the matrix is not positive definite (pivot {pivot} is {value:e})"
            ),
            IndexError::SingularJacobian => write!(f, "the Jacobian is singular"),
            IndexError::Weights => write!(
                f,
                "the weights must be n(n+1)/2 finite, non-negative numbers"
            ),
            IndexError::NoConvergence => write!(f, "the eigenvalue iteration did not converge"),
            IndexError::Overflow => write!(f, "an index overflowed the f64 range"),
        }
    }
}

impl core::error::Error for IndexError {}

/// The two normalizations of Ma & Angeles' dynamic conditioning index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Normalization {
    /// `σ = tr M / n`, `D = M − σ1` (σ and ψ carry the units of `M` and its square).
    Trace,
    /// `σ = tr(M²) / tr M`, `E = (M − σ1)/σ` (dimensionless ψ).
    Dimensionless,
}

/// The diagonal weight matrix `W` of `ψ = ½ eᵀ W e`: one weight per upper-triangle entry
/// `(i, j)`, `i ≤ j`, row by row (`(0,0), (0,1), …, (0,n−1), (1,1), …`).
#[derive(Clone, Debug, PartialEq)]
pub struct Weights {
    n: usize,
    w: Vec<f64>,
}

impl Weights {
    /// Frobenius weights: 1 on the diagonal, 2 off it, so that `ψ = ½ ‖D‖²_F` counts both
    /// `D_ij` and `D_ji`. With them each normalization's `σ` minimizes its `ψ`.
    pub fn frobenius(n: usize) -> Weights {
        let mut w = Vec::with_capacity(n * (n + 1) / 2);
        for i in 0..n {
            for j in i..n {
                w.push(if i == j { 1.0 } else { 2.0 });
            }
        }
        Weights { n, w }
    }

    /// Unit weights: 1 on every upper-triangle entry.
    pub fn unit(n: usize) -> Weights {
        Weights {
            n,
            w: vec![1.0; n * (n + 1) / 2],
        }
    }

    /// Weights given per upper-triangle entry, row by row. `Err(IndexError::Weights)` unless
    /// there are `n(n+1)/2` finite, non-negative numbers.
    pub fn new(n: usize, w: Vec<f64>) -> Result<Weights, IndexError> {
        if w.len() != n * (n + 1) / 2 || w.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(IndexError::Weights);
        }
        Ok(Weights { n, w })
    }

    /// The matrix size.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The weight of entry `(i, j)` (either order); 0 out of range.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        if j >= self.n {
            return 0.0;
        }
        // Entries before row i: n + (n−1) + … + (n−i+1) = i n − i(i−1)/2.
        let k = i * self.n - i * i.saturating_sub(1) / 2 + (j - i);
        self.w.get(k).copied().unwrap_or(0.0)
    }
}

/// One dynamic conditioning index: the scale `σ` of the isotropic matrix `σ·1` and the
/// weighted distance `ψ` to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dci {
    /// `σ` (units of `M` for both normalizations).
    pub sigma: f64,
    /// `ψ = ½ eᵀ W e` (units of `M` squared for [`Normalization::Trace`], dimensionless for
    /// [`Normalization::Dimensionless`]).
    pub psi: f64,
}

/// The indices of one inertia matrix (see the module docs for the definitions and units).
#[derive(Clone, Debug, PartialEq)]
pub struct InertiaIndices {
    /// Eigenvalues of `Λ`, ascending.
    pub eigenvalues: Vec<f64>,
    /// Unit eigenvectors of `Λ` as columns, in the order of `eigenvalues` (the principal axes of
    /// Asada's ellipsoid; each column's largest-magnitude entry is positive).
    pub axes: DMatrix<f64>,
    /// Asada's ratio `λ_min / λ_max`.
    pub gie_ratio: f64,
    /// `λ_max / λ_min`.
    pub condition: f64,
    /// Ma & Angeles, `σ = tr Λ / n`, Frobenius weights.
    pub dci_trace: Dci,
    /// Ma & Angeles, `σ = tr(Λ²)/tr Λ`, `(Λ − σ1)/σ`, Frobenius weights.
    pub dci_dimensionless: Dci,
    /// Yoshikawa's dynamic manipulability measure `√det(B Bᵀ) = 1/|det E|`.
    pub manipulability: f64,
    /// Semi-axes of Yoshikawa's dynamic manipulability ellipsoid (singular values of `B = E⁻¹`),
    /// ascending.
    pub acceleration_radii: Vec<f64>,
    /// Khatib & Burdick's isotropic acceleration for unit effort limits `|τᵢ| ≤ 1`.
    pub isotropic_acceleration: f64,
}

impl InertiaIndices {
    /// Semi-axes `1/√λᵢ` of the generalized inertia ellipsoid `{v : vᵀ Λ v = 1}`, in the order of
    /// `eigenvalues` (largest first).
    pub fn gie_semi_axes(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|l| 1.0 / libm::sqrt(*l))
            .collect()
    }
}

/// A square matrix from rows (as the parallel runtime returns them). `Err` when empty, ragged or
/// not square.
pub fn from_rows(rows: &[Vec<f64>]) -> Result<DMatrix<f64>, IndexError> {
    let n = rows.len();
    if n == 0 {
        return Err(IndexError::Empty);
    }
    for r in rows {
        if r.len() != n {
            return Err(IndexError::Shape {
                rows: n,
                cols: r.len(),
            });
        }
    }
    Ok(DMatrix::from_fn(n, n, |i, j| rows[i][j]))
}

/// `Ok` when `m` is square, non-empty and finite.
fn check_finite_square(m: &DMatrix<f64>) -> Result<usize, IndexError> {
    let n = m.nrows();
    if n == 0 || m.ncols() == 0 {
        return Err(IndexError::Empty);
    }
    if m.ncols() != n {
        return Err(IndexError::Shape {
            rows: n,
            cols: m.ncols(),
        });
    }
    for i in 0..n {
        for j in 0..n {
            if !m[(i, j)].is_finite() {
                return Err(IndexError::NotFinite { row: i, col: j });
            }
        }
    }
    Ok(n)
}

/// Check that `m` is a finite, symmetric, positive definite square matrix and return it
/// symmetrized (`(m + mᵀ)/2`).
pub fn validate_spd(m: &DMatrix<f64>) -> Result<DMatrix<f64>, IndexError> {
    let n = check_finite_square(m)?;
    let scale = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if !(scale > 0.0) || !scale.is_finite() {
        return Err(IndexError::NotPositiveDefinite {
            pivot: 0,
            value: 0.0,
        });
    }
    for i in 0..n {
        for j in i + 1..n {
            let d = (m[(i, j)] - m[(j, i)]).abs() / scale;
            if !(d <= SYMMETRY_TOLERANCE) {
                return Err(IndexError::NotSymmetric {
                    row: i,
                    col: j,
                    asymmetry: d,
                });
            }
        }
    }
    let s = DMatrix::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    // LDLᵀ without pivoting: every pivot must be a clear positive fraction of its diagonal.
    let mut a = s.clone();
    for k in 0..n {
        let d = a[(k, k)];
        if !(d > DEFINITENESS_TOLERANCE * s[(k, k)]) || !(s[(k, k)] > 0.0) {
            return Err(IndexError::NotPositiveDefinite { pivot: k, value: d });
        }
        for i in k + 1..n {
            let l = a[(i, k)] / d;
            for j in k + 1..=i {
                let v = a[(i, j)] - l * a[(j, k)];
                a[(i, j)] = v;
            }
        }
    }
    Ok(s)
}

/// Ma & Angeles' dynamic conditioning index of the symmetric positive definite `m` in one
/// normalization with the weights `w` (with non-Frobenius weights `σ` is still the formula's,
/// no longer the minimizer of `ψ`).
pub fn dci(m: &DMatrix<f64>, normalization: Normalization, w: &Weights) -> Result<Dci, IndexError> {
    let m = validate_spd(m)?;
    let n = m.nrows();
    if w.n() != n {
        return Err(IndexError::Weights);
    }
    Ok(dci_of(&m, normalization, w))
}

fn dci_of(m: &DMatrix<f64>, normalization: Normalization, w: &Weights) -> Dci {
    let n = m.nrows();
    let tr: f64 = (0..n).map(|i| m[(i, i)]).sum();
    let (sigma, div) = match normalization {
        Normalization::Trace => (tr / n as f64, 1.0),
        Normalization::Dimensionless => {
            // tr(M²) = Σ_ij m_ij m_ji = ‖M‖²_F for symmetric M; scaled by the largest entry
            // so that the squares cannot overflow.
            let big = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let tr2: f64 = m.iter().map(|v| (v / big) * (v / big)).sum();
            let s = big * (tr2 / (tr / big));
            (s, s)
        }
    };
    let mut psi = 0.0;
    for i in 0..n {
        for j in i..n {
            let e = (m[(i, j)] - if i == j { sigma } else { 0.0 }) / div;
            psi += w.get(i, j) * e * e;
        }
    }
    Dci {
        sigma,
        psi: 0.5 * psi,
    }
}

/// The indices with the task coordinates equal to the coordinates of `m` (`J = 1`, so
/// `Λ = E = m`): `m` is the joint-space inertia of a tree or the actuator-space inertia
/// `A⁻ᵀ I A⁻¹` of a parallel mechanism.
pub fn inertia_indices(m: &DMatrix<f64>) -> Result<InertiaIndices, IndexError> {
    let lambda = validate_spd(m)?;
    let e = lambda.clone();
    indices_of(lambda, &e)
}

/// The indices in task coordinates `ẋ = J q̇` (`J` square and invertible) of the joint- or
/// actuator-space inertia `m`: `Λ = J⁻ᵀ m J⁻¹` (Asada's task-space inertia) and `E = m J⁻¹`.
pub fn task_indices(m: &DMatrix<f64>, j: &DMatrix<f64>) -> Result<InertiaIndices, IndexError> {
    let m = validate_spd(m)?;
    let n = m.nrows();
    if check_finite_square(j)? != n {
        return Err(IndexError::Shape {
            rows: n,
            cols: j.nrows(),
        });
    }
    let jinv = j
        .clone()
        .lu()
        .try_inverse()
        .ok_or(IndexError::SingularJacobian)?;
    let e = &m * &jinv;
    let lambda = jinv.transpose() * &e;
    let lambda = finite_or_singular(lambda)?;
    let lambda = validate_spd(&lambda)?;
    indices_of(lambda, &finite_or_singular(e)?)
}

/// The indices of a parallel mechanism in its platform speeds `u`: `Λ = I` (the generalized
/// inertia, `runtime::parallel::noc::mass_matrix`) and `E = A⁻ᵀ I` (actuator efforts per platform
/// acceleration, `q̇ = A u`, `runtime::parallel::noc::actuation`). The same as
/// [`task_indices`]`(A⁻ᵀ I A⁻¹, A⁻¹)`.
pub fn platform_indices(i: &DMatrix<f64>, a: &DMatrix<f64>) -> Result<InertiaIndices, IndexError> {
    let lambda = validate_spd(i)?;
    let n = lambda.nrows();
    if check_finite_square(a)? != n {
        return Err(IndexError::Shape {
            rows: n,
            cols: a.nrows(),
        });
    }
    // E = A⁻ᵀ I: solve Aᵀ E = I.
    let e = a
        .transpose()
        .lu()
        .solve(&lambda)
        .ok_or(IndexError::SingularJacobian)?;
    indices_of(lambda, &finite_or_singular(e)?)
}

fn finite_or_singular(m: DMatrix<f64>) -> Result<DMatrix<f64>, IndexError> {
    if m.iter().all(|v| v.is_finite()) {
        Ok(m)
    } else {
        Err(IndexError::SingularJacobian)
    }
}

/// Khatib & Burdick's isotropic acceleration for effort limits `|τᵢ| ≤ limits[i]` (N·m or N):
/// the radius of the largest ball about 0 inside `{ẍ : |(E ẍ)ᵢ| ≤ limitsᵢ}`, i.e.
/// `minᵢ limitsᵢ / ‖row i of E‖₂`. `Err` for a shape mismatch, non-finite or negative limits, or
/// a zero row (the acceleration is then unbounded: `E` is singular).
pub fn isotropic_acceleration(e: &DMatrix<f64>, limits: &[f64]) -> Result<f64, IndexError> {
    let n = check_finite_square(e)?;
    if limits.len() != n {
        return Err(IndexError::Shape {
            rows: n,
            cols: limits.len(),
        });
    }
    let mut best = f64::INFINITY;
    for i in 0..n {
        let l = limits[i];
        if !(l.is_finite() && l >= 0.0) {
            return Err(IndexError::Weights);
        }
        // ‖row‖₂ scaled by its largest entry, so that the squares cannot overflow.
        let big = (0..n).fold(0.0f64, |a, j| a.max(e[(i, j)].abs()));
        let r = big
            * libm::sqrt(
                (0..n)
                    .map(|j| (e[(i, j)] / big) * (e[(i, j)] / big))
                    .sum::<f64>(),
            );
        if !(r > 0.0) || !r.is_finite() {
            return Err(IndexError::SingularJacobian);
        }
        best = best.min(l / r);
    }
    Ok(best)
}

fn indices_of(lambda: DMatrix<f64>, e: &DMatrix<f64>) -> Result<InertiaIndices, IndexError> {
    let n = lambda.nrows();
    let eig = SymmetricEigen::try_new(lambda.clone(), f64::EPSILON, MAX_ITERATIONS)
        .ok_or(IndexError::NoConvergence)?;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let eigenvalues: Vec<f64> = order.iter().map(|&k| eig.eigenvalues[k]).collect();
    let mut axes = DMatrix::zeros(n, n);
    for (c, &k) in order.iter().enumerate() {
        let col = eig.eigenvectors.column(k);
        let big = col
            .iter()
            .fold(0.0f64, |a, v| if v.abs() > a.abs() { *v } else { a });
        let s = if big < 0.0 { -1.0 } else { 1.0 };
        for r in 0..n {
            axes[(r, c)] = s * col[r];
        }
    }
    let (lmin, lmax) = (eigenvalues[0], eigenvalues[n - 1]);
    if !(lmin > 0.0) || !lmax.is_finite() {
        return Err(IndexError::NotPositiveDefinite {
            pivot: order[0],
            value: lmin,
        });
    }
    let w = Weights::frobenius(n);
    let dci_trace = dci_of(&lambda, Normalization::Trace, &w);
    let dci_dimensionless = dci_of(&lambda, Normalization::Dimensionless, &w);
    // Yoshikawa: B = E⁻¹, radii = singular values of B = 1/σ(E).
    let svd = SVD::try_new(e.clone(), false, false, f64::EPSILON, MAX_ITERATIONS)
        .ok_or(IndexError::NoConvergence)?;
    let mut radii = Vec::with_capacity(n);
    let mut manipulability = 1.0;
    for s in svd.singular_values.iter() {
        if !(*s > 0.0) || !s.is_finite() {
            return Err(IndexError::SingularJacobian);
        }
        radii.push(1.0 / s);
        manipulability /= s;
    }
    radii.sort_unstable_by(|a, b| a.total_cmp(b));
    if !manipulability.is_finite() {
        return Err(IndexError::SingularJacobian);
    }
    let isotropic_acceleration = isotropic_acceleration(e, &vec![1.0; n])?;
    let finite = [
        lmax / lmin,
        lmin / lmax,
        dci_trace.sigma,
        dci_trace.psi,
        dci_dimensionless.sigma,
        dci_dimensionless.psi,
        isotropic_acceleration,
    ]
    .iter()
    .chain(radii.iter())
    .all(|v| v.is_finite());
    if !finite {
        return Err(IndexError::Overflow);
    }
    Ok(InertiaIndices {
        eigenvalues,
        axes,
        gie_ratio: lmin / lmax,
        condition: lmax / lmin,
        dci_trace,
        dci_dimensionless,
        manipulability,
        acceleration_radii: radii,
        isotropic_acceleration,
    })
}

/// Where a parallel mechanism's indices are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    /// Actuated joint coordinates `q`: `Λ = E = A⁻ᵀ I A⁻¹`
    /// (`runtime::parallel::noc::actuator_mass_matrix`).
    Actuator,
    /// Platform speeds `u`: `Λ = I` (`runtime::parallel::noc::mass_matrix`), `E = A⁻ᵀ I`.
    Platform,
}

/// A mechanism's indices could not be computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EvalError {
    /// The runtime failed: a singular or unreachable pose, or a bad input.
    Singular(crate::scalar::Singular),
    /// The inertia matrix failed its checks.
    Index(IndexError),
    /// Closed loops do not assemble on the home branch at the given coordinates.
    Unassembled,
}

impl fmt::Display for EvalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EvalError::Singular(s) => write!(f, "{s}"),
            EvalError::Index(e) => write!(f, "{e}"),
            EvalError::Unassembled => write!(f, "the loops do not assemble on the home branch"),
        }
    }
}

impl core::error::Error for EvalError {}

impl From<IndexError> for EvalError {
    fn from(e: IndexError) -> Self {
        EvalError::Index(e)
    }
}

impl From<crate::scalar::Singular> for EvalError {
    fn from(e: crate::scalar::Singular) -> Self {
        EvalError::Singular(e)
    }
}

/// The indices of a parallel mechanism at the platform coordinates `x`, in actuator or platform
/// space. `Err(EvalError::Singular)` where the runtime returns `Err(Singular)` (leg or parallel
/// singularity, unreachable pose, bad input).
pub fn parallel_indices(
    plan: &crate::parallel::Plan,
    x: &[f64],
    space: Space,
) -> Result<InertiaIndices, EvalError> {
    use crate::parallel::noc;
    match space {
        Space::Actuator => Ok(inertia_indices(&from_rows(&noc::actuator_mass_matrix(
            plan, x,
        )?)?)?),
        Space::Platform => {
            let i = from_rows(&noc::mass_matrix(plan, x)?)?;
            let a = from_rows(&noc::actuation(plan, x)?)?;
            Ok(platform_indices(&i, &a)?)
        }
    }
}

/// The indices of a tree in joint space at `q` (`Λ = E = H(q)`, the joint-space inertia by the
/// composite-rigid-body algorithm, [`crate::rnea::mass_matrix`]). `Err(Shape)` when `q` has the
/// wrong length.
pub fn tree_indices(model: &crate::model::Model, q: &[f64]) -> Result<InertiaIndices, IndexError> {
    if q.len() != model.dof() {
        return Err(IndexError::Shape {
            rows: model.dof(),
            cols: q.len(),
        });
    }
    if let Some(k) = q.iter().position(|v| !v.is_finite()) {
        return Err(IndexError::NotFinite { row: k, col: 0 });
    }
    inertia_indices(&crate::rnea::mass_matrix(model, q))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m2(a: f64, b: f64, c: f64) -> DMatrix<f64> {
        DMatrix::from_row_slice(2, 2, &[a, b, b, c])
    }

    /// Ma & Angeles (ICRA 1990) normalizations, checked on the example in
    /// docs/method.md, "Dynamic performance indices": M = [[2, .5], [.5, 1]] gives
    /// σ₁ = 1.5, ψ₁ = 0.5 and σ₂ = 1.833333, ψ₂ = 0.181818 with Frobenius weights.
    #[test]
    fn published_two_by_two_check() {
        let m = m2(2.0, 0.5, 1.0);
        let w = Weights::frobenius(2);
        let d1 = dci(&m, Normalization::Trace, &w).unwrap();
        let d2 = dci(&m, Normalization::Dimensionless, &w).unwrap();
        assert!((d1.sigma - 1.5).abs() < 1e-12, "{d1:?}");
        assert!((d1.psi - 0.5).abs() < 1e-12, "{d1:?}");
        assert!((d2.sigma - 1.833333).abs() < 1e-6, "{d2:?}");
        assert!((d2.psi - 0.181818).abs() < 1e-6, "{d2:?}");
        let all = inertia_indices(&m).unwrap();
        assert_eq!(all.dci_trace, d1);
        assert_eq!(all.dci_dimensionless, d2);
    }

    /// Hand-computed: eigenvalues of [[2, .5], [.5, 1]] are (3 ± √2)/2.
    #[test]
    fn two_by_two_eigenvalues_and_derived_indices() {
        let m = m2(2.0, 0.5, 1.0);
        let r = inertia_indices(&m).unwrap();
        let s2 = 2.0f64.sqrt();
        let (l1, l2) = ((3.0 - s2) / 2.0, (3.0 + s2) / 2.0);
        assert!((r.eigenvalues[0] - l1).abs() < 1e-14);
        assert!((r.eigenvalues[1] - l2).abs() < 1e-14);
        assert!((r.gie_ratio - l1 / l2).abs() < 1e-14);
        assert!((r.condition - l2 / l1).abs() < 1e-13);
        // det M = 1.75, so w = 1/1.75; the ellipsoid radii are 1/λ.
        assert!((r.manipulability - 1.0 / 1.75).abs() < 1e-14);
        assert!((r.acceleration_radii[0] - 1.0 / l2).abs() < 1e-14);
        assert!((r.acceleration_radii[1] - 1.0 / l1).abs() < 1e-13);
        // Rows of M: ‖(2, .5)‖ = √4.25 is the larger.
        assert!((r.isotropic_acceleration - 1.0 / 4.25f64.sqrt()).abs() < 1e-14);
        // Axes are unit eigenvectors.
        for c in 0..2 {
            let v = r.axes.column(c).into_owned();
            assert!((v.norm() - 1.0).abs() < 1e-14);
            let mv = &m * &v;
            assert!((mv - r.eigenvalues[c] * v).norm() < 1e-14);
        }
    }

    #[test]
    fn isotropic_matrix_has_zero_dci() {
        let m = DMatrix::<f64>::identity(3, 3) * 0.042;
        let r = inertia_indices(&m).unwrap();
        assert_eq!(r.dci_trace.psi, 0.0);
        assert_eq!(r.dci_dimensionless.psi, 0.0);
        assert!((r.dci_trace.sigma - 0.042).abs() < 1e-16);
        assert!((r.dci_dimensionless.sigma - 0.042).abs() < 1e-16);
        assert!((r.condition - 1.0).abs() < 1e-15);
    }

    #[test]
    fn weights_index_the_upper_triangle_row_by_row() {
        let w = Weights::new(3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        assert_eq!(w.get(0, 0), 1.0);
        assert_eq!(w.get(0, 2), 3.0);
        assert_eq!(w.get(2, 0), 3.0);
        assert_eq!(w.get(1, 1), 4.0);
        assert_eq!(w.get(1, 2), 5.0);
        assert_eq!(w.get(2, 2), 6.0);
        assert!(Weights::new(3, vec![1.0; 5]).is_err());
        assert!(Weights::new(2, vec![1.0, f64::NAN, 1.0]).is_err());
        assert!(Weights::new(2, vec![1.0, -1.0, 1.0]).is_err());
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            inertia_indices(&m2(1.0, f64::NAN, 1.0)),
            Err(IndexError::NotFinite { .. })
        ));
        assert!(matches!(
            inertia_indices(&DMatrix::from_row_slice(2, 2, &[1.0, 0.1, 0.2, 1.0])),
            Err(IndexError::NotSymmetric { .. })
        ));
        assert!(matches!(
            inertia_indices(&m2(1.0, 2.0, 1.0)),
            Err(IndexError::NotPositiveDefinite { .. })
        ));
        assert!(matches!(
            inertia_indices(&m2(1.0, 1.0, 1.0)),
            Err(IndexError::NotPositiveDefinite { .. })
        ));
        assert!(matches!(
            inertia_indices(&m2(0.0, 0.0, 0.0)),
            Err(IndexError::NotPositiveDefinite { .. })
        ));
        assert!(matches!(
            inertia_indices(&DMatrix::zeros(0, 0)),
            Err(IndexError::Empty)
        ));
        assert!(matches!(
            inertia_indices(&DMatrix::zeros(2, 3)),
            Err(IndexError::Shape { .. })
        ));
        assert!(matches!(
            from_rows(&[vec![1.0, 0.0], vec![0.0]]),
            Err(IndexError::Shape { .. })
        ));
        assert!(matches!(
            task_indices(&m2(2.0, 0.5, 1.0), &m2(1.0, 1.0, 1.0)),
            Err(IndexError::SingularJacobian)
        ));
        assert!(matches!(
            inertia_indices(&m2(f64::INFINITY, 0.0, 1.0)),
            Err(IndexError::NotFinite { .. })
        ));
        let r = inertia_indices(&m2(1e300, 0.0, 1e-300));
        // A condition number beyond the f64 range: an error (the eigenvalue solver scales by
        // the largest entry, so the small eigenvalue may also underflow to zero).
        assert!(
            matches!(
                r,
                Err(IndexError::Overflow | IndexError::NotPositiveDefinite { .. })
            ),
            "{r:?}"
        );
        // Large but representable: no overflow in tr(M²).
        let big = inertia_indices(&m2(1e200, 0.0, 1e200)).unwrap();
        assert_eq!(big.dci_dimensionless.psi, 0.0);
        assert_eq!(big.dci_dimensionless.sigma, 1e200);
    }
}
