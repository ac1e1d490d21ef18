//! A platform's derivative kernels ([method.md, "Derivatives"](../../../docs/method.md#derivatives)):
//! along the tangent of `x` ([`crate::tangent`]), the speeds and the efforts.

use runtime::parallel::noc::{self, Plan};
use runtime::scalar::{Real, Singular};

use crate::scalar::{Sx, flat, guarded, ids};
use crate::sym::{Arg, ExprId};
use crate::tangent;

/// The outputs of a platform's two derivative functions.
pub(super) struct Derivatives {
    /// `A`, `f`, then `∂A/∂x_j` (one matrix per speed `j`), `∂f/∂x` and `∂f/∂u` (`[i][j]`):
    /// the kernel of `inverse_dynamics_derivatives`, whose template solves
    /// `∂τ = A⁻ᵀ (∂f − (∂A)ᵀ τ)` (eq. 66 differentiated).
    pub idd_parts: Vec<ExprId>,
    /// `u̇`, then `∂u̇/∂x`, `∂u̇/∂u` and `∂u̇/∂τ`.
    pub forward_dynamics: Vec<ExprId>,
    /// The guards the forward-dynamics derivatives asked for (forward dynamics' own).
    pub forward_guards: Vec<ExprId>,
}

impl Derivatives {
    /// From the actuation matrix `a`, the generalized force `f(x, u, u̇)` (at the inputs
    /// `u̇`), forward dynamics' `fd`, its inertia `i` and the efforts `tau` (inputs).
    pub(super) fn of(
        plan: &Plan,
        x: &[Sx],
        a: &[Vec<Sx>],
        f: &[Sx],
        fd: &[Sx],
        i: &[Vec<Sx>],
        tau: &[Sx],
    ) -> Result<Derivatives, Singular> {
        let n = plan.dof();
        let along_x = tangent::along_coordinates(&noc::tangent(plan.motion, x));
        let along_u = tangent::along_inputs(Arg::U, n);
        let da = tangent::jacobian(&flat(a), &along_x);
        // `[r][c][j]` → `[j][r][c]`: one matrix per direction.
        let da: Vec<ExprId> = (0..n * n * n)
            .map(|k| da[(k % (n * n)) * n + k / (n * n)])
            .collect();
        let idd_parts = [
            flat(a),
            ids(f),
            da.clone(),
            tangent::jacobian(&ids(f), &along_x),
            tangent::jacobian(&ids(f), &along_u),
        ]
        .concat();
        // Forward dynamics solves `f(x, u, u̇) = Aᵀ τ`: `B = Aᵀ`, `∂(B τ)/∂x_j = (∂A/∂x_j)ᵀ τ`.
        let b: Vec<Vec<Sx>> = (0..n).map(|r| (0..n).map(|c| a[c][r]).collect()).collect();
        let b_rate: Vec<Vec<Sx>> = (0..n)
            .map(|j| {
                (0..n)
                    .map(|c| {
                        (0..n).fold(Sx::c(0.0), |s, r| {
                            s + Sx(da[j * n * n + r * n + c]) * tau[r]
                        })
                    })
                    .collect()
            })
            .collect();
        let (fdd, forward_guards) = guarded(|| {
            tangent::ImplicitForward {
                fd,
                f,
                inertia: i,
                b_rate: &b_rate,
                b: &b,
            }
            .derivatives(&along_x, &along_u)
        });
        Ok(Derivatives {
            idd_parts,
            forward_dynamics: fdd?,
            forward_guards,
        })
    }
}
