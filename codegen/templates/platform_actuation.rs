// Template: the actuator-space functions of a platform module, around its kernels
// (`id_parts`, `inertia_parts`) and its LU solves of the actuation matrix `A`
// (`lu_solve_t`, `lu_inverse`). Specialized by `codegen/src/template.rs`; compiled and tested
// as a module by `tests/tests/templates.rs`.

/// Actuator efforts `τ = A⁻ᵀ (I u̇ + C u − γ)` (N or N·m, gravity included) that produce
/// the platform motion `(x, u, ud)`; `Err` at a leg or parallel singularity.
#[inline]
pub fn inverse_dynamics(
    x: &[f64; NX],
    u: &[f64; DOF],
    ud: &[f64; DOF],
    p: &Params,
) -> Result<[f64; DOF], Singular> {
    let (a, f) = id_parts(x, u, ud, p)?;
    lu_solve_t(&a, &f)
}

/// Actuator efforts `τ = A⁻ᵀ (−γ)` (N or N·m) that hold the platform still against gravity
/// at `x`: `inverse_dynamics(x, 0, 0)`; `Err` at a leg or parallel singularity.
#[inline]
pub fn gravity(x: &[f64; NX], p: &Params) -> Result<[f64; DOF], Singular> {
    let (a, f) = gravity_parts(x, p)?;
    lu_solve_t(&a, &f)
}

/// Velocity-dependent actuator efforts `τ = A⁻ᵀ C u` (N or N·m): the Coriolis and centrifugal
/// terms of the legs and the platform, the rotors' among them; no gravity, no friction. So
/// `inverse_dynamics(x, u, ud) = M_q q̈ + coriolis(x, u) + gravity(x) (+ friction(x, u))` with
/// `M_q = actuator_mass_matrix(x)` and `q̈ = A ud` (`actuator_rates(x, ud)`).
#[inline]
pub fn coriolis(x: &[f64; NX], u: &[f64; DOF], p: &Params) -> Result<[f64; DOF], Singular> {
    let (a, f) = coriolis_parts(x, u, p)?;
    lu_solve_t(&a, &f)
}

/// Actuator efforts `τ = A⁻ᵀ Σ J⁻ᵀ δ(θ̇)` (N or N·m) of the leg joints' friction (viscous
/// and regularized Coulomb, actuated and passive joints alike) at `(x, u)`.
#[inline]
pub fn friction(x: &[f64; NX], u: &[f64; DOF], p: &Params) -> Result<[f64; DOF], Singular> {
    let (a, f) = friction_parts(x, u, p)?;
    lu_solve_t(&a, &f)
}

/// Inertia in actuator space `A⁻ᵀ I A⁻¹` (the lecture's eq. 68), symmetric.
#[allow(clippy::all)]
pub fn actuator_mass_matrix(x: &[f64; NX], p: &Params) -> Result<[[f64; DOF]; DOF], Singular> {
    let (a, i) = inertia_parts(x, p)?;
    let ai = lu_inverse(&a)?;
    // B = I A⁻¹, then A⁻ᵀ B (upper triangle, mirrored).
    let mut b = [[0.0; DOF]; DOF];
    for r in 0..DOF {
        for c in 0..DOF {
            let mut s = 0.0;
            for k in 0..DOF {
                s += i[r][k] * ai[k][c];
            }
            b[r][c] = s;
        }
    }
    let mut out = [[0.0; DOF]; DOF];
    for r in 0..DOF {
        for c in r..DOF {
            let mut s = 0.0;
            for k in 0..DOF {
                s += ai[k][r] * b[k][c];
            }
            if !s.is_finite() {
                return Err(Singular {
                    site: Site::Input,
                    value: s,
                    condition_estimate: f64::INFINITY,
                });
            }
            out[r][c] = s;
            out[c][r] = s;
        }
    }
    Ok(out)
}

/// `(∂τ/∂x, ∂τ/∂u)` of `inverse_dynamics` at `(x, u, ud)`; element `[i][j] = ∂τ_i/∂x_j`.
/// The derivative in `x` is taken along the tangent `x ⊕ δu` of the speeds: column `j` is the
/// rate of `τ` while `x` moves as the speed `u_j` moves it (a quaternion `q̇ = ½ (0, ω) ⊗ q`
/// with `ω` in the base frame, a position `ṗ = v`; for every other motion `x ⊕ δu` is the
/// sum and this is `∂τ/∂x`). `∂τ/∂u̇` is `actuator_mass_matrix(x)·A(x)`. From `Aᵀ τ = f`:
/// `∂τ = A⁻ᵀ (∂f − (∂A)ᵀ τ)`, with the one LU of `A` that `inverse_dynamics` uses, so it fails
/// where `inverse_dynamics` does.
#[allow(clippy::all)]
pub fn inverse_dynamics_derivatives(
    x: &[f64; NX],
    u: &[f64; DOF],
    ud: &[f64; DOF],
    p: &Params,
) -> Result<([[f64; DOF]; DOF], [[f64; DOF]; DOF]), Singular> {
    let (a, f, da, dfx, dfu) = idd_parts(x, u, ud, p)?;
    let ai = lu_inverse(&a)?;
    // `A⁻ᵀ b`: row `r` of the result is column `r` of `A⁻¹` against `b`.
    let solve_t = |b: &[f64; DOF]| -> [f64; DOF] {
        let mut out = [0.0; DOF];
        for r in 0..DOF {
            let mut s = 0.0;
            for k in 0..DOF {
                s += ai[k][r] * b[k];
            }
            out[r] = s;
        }
        out
    };
    let tau = solve_t(&f);
    let mut dx = [[0.0; DOF]; DOF];
    let mut du = [[0.0; DOF]; DOF];
    for j in 0..DOF {
        let mut bx = [0.0; DOF];
        let mut bu = [0.0; DOF];
        for i in 0..DOF {
            let mut s = dfx[i][j];
            for k in 0..DOF {
                s -= da[j][k][i] * tau[k];
            }
            bx[i] = s;
            bu[i] = dfu[i][j];
        }
        let (cx, cu) = (solve_t(&bx), solve_t(&bu));
        for i in 0..DOF {
            if !(cx[i].is_finite() && cu[i].is_finite()) {
                return Err(Singular {
                    site: Site::Input,
                    value: if cx[i].is_finite() { cu[i] } else { cx[i] },
                    condition_estimate: f64::INFINITY,
                });
            }
            dx[i][j] = cx[i];
            du[i][j] = cu[i];
        }
    }
    Ok((dx, du))
}

/// The regressor over the base parameters: `inverse_dynamics(x, u, ud) = regressor(x, u, ud) ·
/// BASE_PARAMETERS`, element `[i][k]` the effort of actuator `i` per unit of base parameter
/// `k` (`BASE_PARAMETER_NAMES[k]`: the standard parameters it groups). `Y = A⁻ᵀ F_b` with the
/// generalized forces `F_b` of the base parameters (eq. 66 column by column); `Err` at a leg
/// or parallel singularity, as `inverse_dynamics`.
#[allow(clippy::all)]
pub fn regressor(
    x: &[f64; NX],
    u: &[f64; DOF],
    ud: &[f64; DOF],
) -> Result<[[f64; NBP]; DOF], Singular> {
    let (a, f) = regressor_parts(x, u, ud)?;
    let ai = lu_inverse(&a)?;
    // Row `r` of `A⁻ᵀ F_b`: column `r` of `A⁻¹` against each column of `F_b`.
    let mut y = [[0.0; NBP]; DOF];
    for r in 0..DOF {
        for c in 0..NBP {
            let mut s = 0.0;
            for k in 0..DOF {
                s += ai[k][r] * f[k][c];
            }
            if !s.is_finite() {
                return Err(Singular {
                    site: Site::Input,
                    value: s,
                    condition_estimate: f64::INFINITY,
                });
            }
            y[r][c] = s;
        }
    }
    Ok(y)
}
