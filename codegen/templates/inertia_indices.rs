// Template: the dynamic performance indices of an inertia matrix, for any generated module
// that defines `const DOF: usize` (nocdyn's `docs/indices.md`; the runtime twin is
// `runtime::indices`). Stand-ins replaced when specialized (`codegen/src/template.rs`):
// `SYMMETRY_TOLERANCE`, `DEFINITENESS_TOLERANCE`, `MAX_SWEEPS`, and the math call `sqrt`.
// Compiled and tested as a module by `tests/tests/indices.rs`.

/// Largest accepted asymmetry `|m_ij − m_ji|` of [`inertia_indices`]' input, relative to
/// its largest entry.
pub const INDEX_SYMMETRY_TOLERANCE: f64 = SYMMETRY_TOLERANCE;
/// Positive definiteness in [`inertia_indices`]: pivot `k` of `LDLᵀ` must exceed this
/// times the diagonal entry it came from.
pub const INDEX_DEFINITENESS_TOLERANCE: f64 = DEFINITENESS_TOLERANCE;
/// Cyclic Jacobi sweeps at most in [`inertia_indices`].
pub const INDEX_MAX_SWEEPS: usize = MAX_SWEEPS;

/// Dynamic performance indices of an inertia matrix `M` whose coordinates are the task
/// coordinates (`Λ = M`, efforts `τ = M ẍ` at rest with gravity compensated; units are
/// those of `M`: kg·m² for angles, kg for lengths). See nocdyn's `docs/indices.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InertiaIndices {
    /// Eigenvalues `λ` of `M`, ascending.
    pub eigenvalues: [f64; DOF],
    /// `axes[k]`: the unit eigenvector of `eigenvalues[k]` (largest-magnitude entry
    /// positive), a principal axis of Asada's generalized inertia ellipsoid
    /// `{v : vᵀ M v = 1}` with semi-axis `1/√λ_k`.
    pub axes: [[f64; DOF]; DOF],
    /// Asada: `λ_min / λ_max`.
    pub gie_ratio: f64,
    /// Condition number `λ_max / λ_min`.
    pub condition: f64,
    /// Ma & Angeles, first normalization: `σ = tr M / n`.
    pub dci_trace_sigma: f64,
    /// `ψ = ½ ‖M − σ1‖²_F` (Frobenius weights: 1 on the diagonal, 2 off it, over the
    /// upper triangle), units of `M` squared.
    pub dci_trace_psi: f64,
    /// Ma & Angeles, second normalization: `σ = tr(M²) / tr M`.
    pub dci_dimensionless_sigma: f64,
    /// `ψ = ½ ‖(M − σ1)/σ‖²_F` (Frobenius weights), dimensionless.
    pub dci_dimensionless_psi: f64,
    /// Yoshikawa's dynamic manipulability measure `√det(M⁻¹M⁻ᵀ) = 1/det M`.
    pub manipulability: f64,
    /// Semi-axes of Yoshikawa's ellipsoid `{M⁻¹τ : ‖τ‖ ≤ 1}`: `1/λ`, ascending.
    pub acceleration_radii: [f64; DOF],
    /// Khatib & Burdick's isotropic acceleration for `|τ_i| ≤ 1`:
    /// `min_i 1/‖row i of M‖₂`.
    pub isotropic_acceleration: f64,
}

/// Why [`inertia_indices`] could not compute the indices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IndexError {
    /// Entry `(row, col)` is NaN or infinite.
    NotFinite {
        /// Row.
        row: usize,
        /// Column.
        col: usize,
    },
    /// `|m_ij − m_ji|` exceeds [`INDEX_SYMMETRY_TOLERANCE`] times the largest entry.
    NotSymmetric {
        /// Row.
        row: usize,
        /// Column.
        col: usize,
    },
    /// Pivot `pivot` of `LDLᵀ` (or an eigenvalue) is not clearly positive.
    NotPositiveDefinite {
        /// The pivot.
        pivot: usize,
        /// Its value.
        value: f64,
    },
    /// The Jacobi iteration did not converge in [`INDEX_MAX_SWEEPS`] sweeps.
    NoConvergence,
    /// An index overflowed the `f64` range.
    Overflow,
}

impl core::fmt::Display for IndexError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            IndexError::NotFinite { row, col } => write!(f, "entry ({row}, {col}) is not finite"),
            IndexError::NotSymmetric { row, col } => {
                write!(f, "entries ({row}, {col}) and ({col}, {row}) differ")
            }
            IndexError::NotPositiveDefinite { pivot, value } => {
                write!(f, "not positive definite: pivot {pivot} is {value:e}")
            }
            IndexError::NoConvergence => write!(f, "the eigenvalue iteration did not converge"),
            IndexError::Overflow => write!(f, "an index overflows"),
        }
    }
}

impl core::error::Error for IndexError {}

/// Asada's generalized inertia ellipsoid (eigenvalues, axes, `λ_min/λ_max`), the
/// condition number, Ma & Angeles' dynamic conditioning index in both normalizations
/// (Frobenius weights), Yoshikawa's dynamic manipulability and Khatib & Burdick's
/// isotropic acceleration of the symmetric positive definite `m` (e.g. `mass_matrix`,
/// or `actuator_mass_matrix` of a parallel mechanism). No allocation, no panic.
#[allow(clippy::all)]
pub fn inertia_indices(m: &[[f64; DOF]; DOF]) -> Result<InertiaIndices, IndexError> {
    let mut scale: f64 = 0.0;
    for i in 0..DOF {
        for j in 0..DOF {
            let v = m[i][j];
            if !(v - v == 0.0) {
                return Err(IndexError::NotFinite { row: i, col: j });
            }
            let a = if v < 0.0 { -v } else { v };
            if a > scale {
                scale = a;
            }
        }
    }
    if !(scale > 0.0) {
        return Err(IndexError::NotPositiveDefinite {
            pivot: 0,
            value: 0.0,
        });
    }
    let mut a = [[0.0; DOF]; DOF];
    for i in 0..DOF {
        for j in 0..DOF {
            let d = m[i][j] - m[j][i];
            let d = if d < 0.0 { -d } else { d };
            if !(d <= INDEX_SYMMETRY_TOLERANCE * scale) {
                return Err(IndexError::NotSymmetric { row: i, col: j });
            }
            a[i][j] = 0.5 * (m[i][j] + m[j][i]);
        }
    }
    let s = a;
    // LDLᵀ without pivoting (lower triangle): positive definiteness and det M.
    let mut l = a;
    let mut det = 1.0;
    for k in 0..DOF {
        let d = l[k][k];
        if !(s[k][k] > 0.0) || !(d > INDEX_DEFINITENESS_TOLERANCE * s[k][k]) {
            return Err(IndexError::NotPositiveDefinite { pivot: k, value: d });
        }
        det *= d;
        for i in k + 1..DOF {
            let f = l[i][k] / d;
            for j in k + 1..i + 1 {
                l[i][j] -= f * l[j][k];
            }
        }
    }
    // Cyclic Jacobi: a ← Pᵀ a P, v ← v P, until the off-diagonal part is negligible.
    let mut v = [[0.0; DOF]; DOF];
    for i in 0..DOF {
        v[i][i] = 1.0;
    }
    let mut converged = false;
    for _ in 0..INDEX_MAX_SWEEPS {
        // A sweep that finds every off-diagonal entry negligible ends the iteration.
        let mut rotated = false;
        for p in 0..DOF {
            for q in p + 1..DOF {
                let apq = a[p][q];
                let app = if a[p][p] < 0.0 { -a[p][p] } else { a[p][p] };
                let aqq = if a[q][q] < 0.0 { -a[q][q] } else { a[q][q] };
                let mag = if apq < 0.0 { -apq } else { apq };
                if mag <= 1e-17 * (app + aqq) {
                    a[p][q] = 0.0;
                    a[q][p] = 0.0;
                    continue;
                }
                rotated = true;
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let at = if theta < 0.0 { -theta } else { theta };
                let t = if at > 1e18 {
                    0.5 / theta
                } else {
                    let r = 1.0 / (at + sqrt(theta * theta + 1.0));
                    if theta < 0.0 { -r } else { r }
                };
                let c = 1.0 / sqrt(t * t + 1.0);
                let sn = t * c;
                for k in 0..DOF {
                    let (x, y) = (a[k][p], a[k][q]);
                    a[k][p] = c * x - sn * y;
                    a[k][q] = sn * x + c * y;
                }
                for k in 0..DOF {
                    let (x, y) = (a[p][k], a[q][k]);
                    a[p][k] = c * x - sn * y;
                    a[q][k] = sn * x + c * y;
                }
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                for k in 0..DOF {
                    let (x, y) = (v[k][p], v[k][q]);
                    v[k][p] = c * x - sn * y;
                    v[k][q] = sn * x + c * y;
                }
            }
        }
        if !rotated {
            converged = true;
            break;
        }
    }
    if !converged {
        return Err(IndexError::NoConvergence);
    }
    let mut eigenvalues = [0.0; DOF];
    let mut axes = [[0.0; DOF]; DOF];
    for k in 0..DOF {
        eigenvalues[k] = a[k][k];
        for i in 0..DOF {
            axes[k][i] = v[i][k];
        }
    }
    // Selection sort, ascending.
    for i in 0..DOF {
        for j in i + 1..DOF {
            if eigenvalues[j] < eigenvalues[i] {
                let e = eigenvalues[i];
                eigenvalues[i] = eigenvalues[j];
                eigenvalues[j] = e;
                let x = axes[i];
                axes[i] = axes[j];
                axes[j] = x;
            }
        }
    }
    for k in 0..DOF {
        let mut big = 0.0;
        for i in 0..DOF {
            let x = axes[k][i];
            if (if x < 0.0 { -x } else { x }) > (if big < 0.0 { -big } else { big }) {
                big = x;
            }
        }
        if big < 0.0 {
            for i in 0..DOF {
                axes[k][i] = -axes[k][i];
            }
        }
    }
    let lmin = eigenvalues[0];
    let lmax = eigenvalues[DOF - 1];
    if !(lmin > 0.0) {
        return Err(IndexError::NotPositiveDefinite {
            pivot: 0,
            value: lmin,
        });
    }
    // Ma & Angeles, both normalizations, Frobenius weights.
    let mut tr = 0.0;
    let mut tr2 = 0.0;
    for i in 0..DOF {
        tr += s[i][i];
        for j in 0..DOF {
            let x = s[i][j] / scale;
            tr2 += x * x;
        }
    }
    let sigma1 = tr / (DOF as f64);
    let sigma2 = scale * (tr2 / (tr / scale));
    let mut psi1 = 0.0;
    let mut psi2 = 0.0;
    for i in 0..DOF {
        for j in 0..DOF {
            let shift1 = if i == j { sigma1 } else { 0.0 };
            let shift2 = if i == j { sigma2 } else { 0.0 };
            let d = s[i][j] - shift1;
            let e = (s[i][j] - shift2) / sigma2;
            psi1 += d * d;
            psi2 += e * e;
        }
    }
    // Yoshikawa (J = 1): radii 1/λ; Khatib & Burdick: min 1/‖row‖.
    let mut acceleration_radii = [0.0; DOF];
    for k in 0..DOF {
        acceleration_radii[k] = 1.0 / eigenvalues[DOF - 1 - k];
    }
    let mut isotropic_acceleration = f64::INFINITY;
    for i in 0..DOF {
        let mut r2 = 0.0;
        for j in 0..DOF {
            r2 += s[i][j] * s[i][j];
        }
        let r = 1.0 / sqrt(r2);
        if r < isotropic_acceleration {
            isotropic_acceleration = r;
        }
    }
    let out = InertiaIndices {
        eigenvalues,
        axes,
        gie_ratio: lmin / lmax,
        condition: lmax / lmin,
        dci_trace_sigma: sigma1,
        dci_trace_psi: 0.5 * psi1,
        dci_dimensionless_sigma: sigma2,
        dci_dimensionless_psi: 0.5 * psi2,
        manipulability: 1.0 / det,
        acceleration_radii,
        isotropic_acceleration,
    };
    let check = [
        out.condition,
        out.dci_trace_psi,
        out.dci_dimensionless_sigma,
        out.dci_dimensionless_psi,
        out.manipulability,
        out.isotropic_acceleration,
        acceleration_radii[DOF - 1],
    ];
    for x in check {
        if !(x - x == 0.0) {
            return Err(IndexError::Overflow);
        }
    }
    Ok(out)
}
