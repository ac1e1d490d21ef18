// Template: the actuator-space functions of a closed-loop module in joint coordinates, whose
// actuated joints are its independent coordinates (`A = 1`). Specialized by
// `codegen/src/template.rs`; compiled and tested as a module by `tests/tests/templates.rs`.

/// The independent coordinates of `x` (rad or m, `ACTUATOR_NAMES` order).
#[allow(clippy::all)]
pub fn inverse_kinematics(x: &[f64; NX]) -> Result<[f64; DOF], Singular> {
    let mut q = [0.0; DOF];
    for k in 0..DOF {
        let v = x[INDEPENDENT[k]];
        if !v.is_finite() {
            return Err(Singular {
                site: Site::Input,
                value: v,
                condition_estimate: f64::INFINITY,
            });
        }
        q[k] = v;
    }
    Ok(q)
}

/// The actuated joints' rates `q̇ = A u`: the actuated joints are the independent
/// coordinates (`A = 1`), so `u` itself. `Err(Site::Input)` for a non-finite independent
/// coordinate or speed;
/// whether `x` closes the loops is not needed here (`joint_rates` checks it).
#[allow(clippy::all)]
pub fn actuator_rates(x: &[f64; NX], u: &[f64; DOF]) -> Result<[f64; DOF], Singular> {
    inverse_kinematics(x)?;
    for k in 0..DOF {
        if !u[k].is_finite() {
            return Err(Singular {
                site: Site::Input,
                value: u[k],
                condition_estimate: f64::INFINITY,
            });
        }
    }
    Ok(*u)
}

/// The mass matrix in actuator space, `A⁻ᵀ I A⁻¹` (the lecture's eq. 68): the
/// actuated joints are the independent coordinates (`A = 1`), so it is `mass_matrix`.
#[allow(clippy::all)]
#[inline(always)]
pub fn actuator_mass_matrix(x: &[f64; NX], p: &Params) -> Result<[[f64; DOF]; DOF], Singular> {
    mass_matrix(x, p)
}
