//! The fixed template of the dynamic performance indices in a generated module
//! (`docs/indices.md`; the runtime twin is `runtime::indices`).
//!
//! [`template`] emits, for a module that already defines `const DOF: usize`, the items
//! * `InertiaIndices` (the results), `IndexError` (its own error type, independent of the
//!   module's `Singular`), the tolerances `INDEX_SYMMETRY_TOLERANCE`,
//!   `INDEX_DEFINITENESS_TOLERANCE` and `INDEX_MAX_SWEEPS`;
//! * `pub fn inertia_indices(m: &[[f64; DOF]; DOF]) -> Result<InertiaIndices, IndexError>`.
//!
//! The function treats the coordinates of `m` as the task coordinates (`J = 1`, so `Λ = E = m`;
//! see `runtime::indices`): pass the tree's `mass_matrix(&q)` (joint space) or a parallel
//! module's `actuator_mass_matrix(&x)?` (actuator space) or `mass_matrix(&x)?` (platform
//! speeds, where `E` is then `I`, not `A⁻ᵀ I`). It is `no_std`, allocation-free and has no
//! panicking operation: fixed-size arrays, loops over constant ranges, the eigenvalues by cyclic
//! Jacobi rotations (entries below 1e-17 of their diagonal pair are set to zero; at most
//! `INDEX_MAX_SWEEPS` sweeps), `sqrt` from the configured math
//! backend. Bad input gives `Err(IndexError)`, never NaN.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// Largest accepted asymmetry, relative to the largest entry (= `runtime::indices`).
pub const SYMMETRY_TOLERANCE: f64 = runtime::indices::SYMMETRY_TOLERANCE;
/// `LDLᵀ` pivots must exceed this times their diagonal entry (= `runtime::indices`).
pub const DEFINITENESS_TOLERANCE: f64 = runtime::indices::DEFINITENESS_TOLERANCE;
/// Jacobi sweeps at most (cyclic Jacobi converges quadratically: a handful suffice).
pub const MAX_SWEEPS: usize = 64;

/// The indices template (items only; needs `DOF` in scope). See the module docs.
pub fn template(cfg: &crate::Config) -> TokenStream {
    let constants = constants();
    let types = types();
    let function = inertia_indices(cfg);
    quote! {
        #constants

        #types

        #function
    }
}

/// `INDEX_SYMMETRY_TOLERANCE`, `INDEX_DEFINITENESS_TOLERANCE` and `INDEX_MAX_SWEEPS`.
fn constants() -> TokenStream {
    let real = crate::emit::real();
    let sym_tol = Literal::f64_unsuffixed(SYMMETRY_TOLERANCE);
    let def_tol = Literal::f64_unsuffixed(DEFINITENESS_TOLERANCE);
    let sweeps = Literal::usize_unsuffixed(MAX_SWEEPS);
    quote! {
        /// Largest accepted asymmetry `|m_ij − m_ji|` of [`inertia_indices`]' input, relative to
        /// its largest entry.
        pub const INDEX_SYMMETRY_TOLERANCE: #real = #sym_tol;
        /// Positive definiteness in [`inertia_indices`]: pivot `k` of `LDLᵀ` must exceed this
        /// times the diagonal entry it came from.
        pub const INDEX_DEFINITENESS_TOLERANCE: #real = #def_tol;
        /// Cyclic Jacobi sweeps at most in [`inertia_indices`].
        pub const INDEX_MAX_SWEEPS: usize = #sweeps;
    }
}

/// The result `InertiaIndices` and the error `IndexError`.
fn types() -> TokenStream {
    let real = crate::emit::real();
    let real_doc = crate::emit::real_text(" An index overflowed the `f64` range.");
    quote! {
        /// Dynamic performance indices of an inertia matrix `M` whose coordinates are the task
        /// coordinates (`Λ = M`, efforts `τ = M ẍ` at rest with gravity compensated; units are
        /// those of `M`: kg·m² for angles, kg for lengths). See nocdyn's `docs/indices.md`.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct InertiaIndices {
            /// Eigenvalues `λ` of `M`, ascending.
            pub eigenvalues: [#real; DOF],
            /// `axes[k]`: the unit eigenvector of `eigenvalues[k]` (largest-magnitude entry
            /// positive), a principal axis of Asada's generalized inertia ellipsoid
            /// `{v : vᵀ M v = 1}` with semi-axis `1/√λ_k`.
            pub axes: [[#real; DOF]; DOF],
            /// Asada: `λ_min / λ_max`.
            pub gie_ratio: #real,
            /// Condition number `λ_max / λ_min`.
            pub condition: #real,
            /// Ma & Angeles, first normalization: `σ = tr M / n`.
            pub dci_trace_sigma: #real,
            /// `ψ = ½ ‖M − σ1‖²_F` (Frobenius weights: 1 on the diagonal, 2 off it, over the
            /// upper triangle), units of `M` squared.
            pub dci_trace_psi: #real,
            /// Ma & Angeles, second normalization: `σ = tr(M²) / tr M`.
            pub dci_dimensionless_sigma: #real,
            /// `ψ = ½ ‖(M − σ1)/σ‖²_F` (Frobenius weights), dimensionless.
            pub dci_dimensionless_psi: #real,
            /// Yoshikawa's dynamic manipulability measure `√det(M⁻¹M⁻ᵀ) = 1/det M`.
            pub manipulability: #real,
            /// Semi-axes of Yoshikawa's ellipsoid `{M⁻¹τ : ‖τ‖ ≤ 1}`: `1/λ`, ascending.
            pub acceleration_radii: [#real; DOF],
            /// Khatib & Burdick's isotropic acceleration for `|τ_i| ≤ 1`:
            /// `min_i 1/‖row i of M‖₂`.
            pub isotropic_acceleration: #real,
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
                value: #real,
            },
            /// The Jacobi iteration did not converge in [`INDEX_MAX_SWEEPS`] sweeps.
            NoConvergence,
            #[doc = #real_doc]
            Overflow,
        }
    }
}

/// `inertia_indices`: one straight function whose body is the steps below, in order.
fn inertia_indices(cfg: &crate::Config) -> TokenStream {
    let real = crate::emit::real();
    let input = input_checks();
    let ldlt = ldlt();
    let jacobi = jacobi_sweeps(cfg);
    let eigen = sorted_eigenpairs();
    let dci = conditioning_indices();
    let acceleration = acceleration_indices(cfg);
    let output = output();
    quote! {
        /// Asada's generalized inertia ellipsoid (eigenvalues, axes, `λ_min/λ_max`), the
        /// condition number, Ma & Angeles' dynamic conditioning index in both normalizations
        /// (Frobenius weights), Yoshikawa's dynamic manipulability and Khatib & Burdick's
        /// isotropic acceleration of the symmetric positive definite `m` (e.g. `mass_matrix`,
        /// or `actuator_mass_matrix` of a parallel mechanism). No allocation, no panic.
        #[allow(clippy::all)]
        pub fn inertia_indices(m: &[[#real; DOF]; DOF]) -> Result<InertiaIndices, IndexError> {
            #input
            #ldlt
            #jacobi
            #eigen
            #dci
            #acceleration
            #output
        }
    }
}

/// Statements: the largest entry `scale` (every entry finite, not all zero), the symmetry test
/// and the symmetrized `a`, kept as `s`.
fn input_checks() -> TokenStream {
    let real = crate::emit::real();
    quote! {
        let mut scale: #real = 0.0;
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
            return Err(IndexError::NotPositiveDefinite { pivot: 0, value: 0.0 });
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
    }
}

/// Statements: `LDLᵀ` of `a` (positive definiteness, `det`).
fn ldlt() -> TokenStream {
    quote! {
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
    }
}

/// Statements: cyclic Jacobi sweeps on `a`, the rotations accumulated in `v`.
fn jacobi_sweeps(cfg: &crate::Config) -> TokenStream {
    let sqrt_theta = crate::emit::math_call(cfg, "sqrt", quote!(theta * theta + 1.0));
    let sqrt_t = crate::emit::math_call(cfg, "sqrt", quote!(t * t + 1.0));
    quote! {
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
                        let r = 1.0 / (at + #sqrt_theta);
                        if theta < 0.0 { -r } else { r }
                    };
                    let c = 1.0 / #sqrt_t;
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
    }
}

/// Statements: the eigenvalues ascending with their axes (largest-magnitude entry positive),
/// `lmin` and `lmax` (`lmin` positive).
fn sorted_eigenpairs() -> TokenStream {
    quote! {
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
            return Err(IndexError::NotPositiveDefinite { pivot: 0, value: lmin });
        }
    }
}

/// Statements: Ma & Angeles' `σ` and `ψ` in both normalizations.
fn conditioning_indices() -> TokenStream {
    let real = crate::emit::real();
    quote! {
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
        let sigma1 = tr / (DOF as #real);
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
    }
}

/// Statements: Yoshikawa's acceleration radii and Khatib & Burdick's isotropic acceleration.
fn acceleration_indices(cfg: &crate::Config) -> TokenStream {
    let real = crate::emit::real();
    let sqrt_row = crate::emit::math_call(cfg, "sqrt", quote!(r2));
    quote! {
        // Yoshikawa (J = 1): radii 1/λ; Khatib & Burdick: min 1/‖row‖.
        let mut acceleration_radii = [0.0; DOF];
        for k in 0..DOF {
            acceleration_radii[k] = 1.0 / eigenvalues[DOF - 1 - k];
        }
        let mut isotropic_acceleration = #real::INFINITY;
        for i in 0..DOF {
            let mut r2 = 0.0;
            for j in 0..DOF {
                r2 += s[i][j] * s[i][j];
            }
            let r = 1.0 / #sqrt_row;
            if r < isotropic_acceleration {
                isotropic_acceleration = r;
            }
        }
    }
}

/// Statements: the result, `Err(IndexError::Overflow)` if an index is not finite.
fn output() -> TokenStream {
    quote! {
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
}
