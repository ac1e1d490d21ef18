//! The fixed items of every parallel module, around the DAG kernels: the error types, the
//! partially pivoted LU of the actuation matrix `A` and the public functions built on it
//! (`inverse_dynamics`, `actuator_mass_matrix`), and Newton's forward kinematics
//! (`retract`, `fk_residual`, `forward_kinematics`).

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::parallel::PlatformMotion;
use runtime::parallel::noc::{self, Plan};

use crate::{Config, emit, lu};

/// The fixed items of every parallel module: error types, the LU of `A`, and the public
/// functions that wrap the DAG kernels.
pub(super) fn templates(
    cfg: &Config,
    plan: &Plan,
    revolute: &[bool],
    want: &dyn Fn(&str) -> bool,
    params: bool,
) -> TokenStream {
    // With run-time parameters the wrappers take and pass on `p: &Params`.
    let (p_arg, p_pass) = if params {
        (quote!(, p: &Params), quote!(, p))
    } else {
        (quote!(), quote!())
    };
    let types = error_types();
    let lu_solve = lu_fn(
        cfg,
        plan,
        "lu_solve",
        " Solve `a x = b`: LU with partial pivoting by conditional row swaps, straight-line code.\n\n A pivot of `a` with its columns scaled to unit 2-norm must exceed the tolerance times the\n largest so far (compared squared and cross-multiplied: no square root or division outside\n the error path); otherwise `Err(Site::Actuation(k))` with the ratio of the largest scaled\n pivot to this one as the condition estimate.",
        false,
        lu::Rhs::Vector,
    );
    // Wrappers of the kernels `[scene] functions` may leave out.
    let id_wrapper = if want("inverse_dynamics") {
        inverse_dynamics(cfg, plan, &p_arg, &p_pass)
    } else {
        quote!()
    };
    let amm_wrapper = if want("actuator_mass_matrix") {
        actuator_mass_matrix(cfg, plan, &p_arg, &p_pass)
    } else {
        quote!()
    };
    let retract = retract(cfg, plan);
    let fk_residual = fk_residual();
    let forward_kinematics = forward_kinematics(cfg, plan);
    quote! {
        #types

        /// Which actuators are revolute (angles are compared modulo 2π).
        const REVOLUTE: [bool; DOF] = [#(#revolute),*];

        #lu_solve

        #id_wrapper

        #amm_wrapper

        #retract

        #fk_residual

        #forward_kinematics
    }
}

/// `Site` (its leg and actuation variants documented with the tolerances), `Singular` and
/// `NoConvergence`.
fn error_types() -> TokenStream {
    let tol = crate::scalar::tolerance;
    let leg_tol = tol(noc::LEG_TOLERANCE);
    let act_tol = tol(noc::ACTUATION_TOLERANCE);
    let leg_doc = format!(
        " Leg `k`'s Jacobian is singular: `|det J| ≤ {leg_tol:e} · ∏‖columns‖` (a leg, type-I, singularity)."
    );
    let act_doc = format!(
        " Pivot `i` of the actuation matrix `A` (columns scaled to unit norm, partial pivoting) is `≤ {act_tol:e}` times the largest pivot: a parallel (type-II) singularity."
    );
    let errors = crate::module::error_types(
        "Which matrix, leg or pivot.",
        "The determinant, pivot or discriminant that failed its test.",
        "The last residual `max |q(x) − q|` (m or rad).",
    );
    quote! {
        /// Where an evaluation failed.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Site {
            /// Pivot `i` of the generalized inertia's `LDLᵀ` (forward dynamics).
            MassMatrix(usize),
            #[doc = #leg_doc]
            Leg(usize),
            /// Leg `k` cannot reach the platform: the pose is outside the workspace.
            Reach(usize),
            #[doc = #act_doc]
            Actuation(usize),
            /// The platform quaternion is zero (or not finite).
            Platform,
            /// An input (`x`, `u`, `ud`, `tau`) is NaN or infinite, or so large that a result
            /// overflows.
            Input,
        }

        #errors
    }
}

/// One of the module's LU solves of `A` (`lu_solve`, `lu_solve_t`, `lu_inverse`): the pivot
/// test at the actuation tolerance, squared.
fn lu_fn(
    cfg: &Config,
    plan: &Plan,
    name: &str,
    doc: &str,
    transpose: bool,
    rhs: lu::Rhs,
) -> TokenStream {
    let act_tol = crate::scalar::tolerance(noc::ACTUATION_TOLERANCE);
    // The squared tolerance, rounded to 13 significant digits so that `1e-8²` reads `1e-16`.
    let act_tol2 = act_tol * act_tol;
    let act_tol2 = format!("{act_tol2:.12e}").parse().unwrap_or(act_tol2);
    let sqrt_call = |t: TokenStream| emit::math_call(cfg, "sqrt", t);
    lu::lu_solve_fn(&lu::LuSolve {
        name,
        doc,
        n: plan.dof(),
        transpose,
        rhs,
        tol2: act_tol2,
        sqrt: &sqrt_call,
    })
}

/// `inverse_dynamics`, the wrapper of `id_parts`, and the `lu_solve_t` it calls.
fn inverse_dynamics(
    cfg: &Config,
    plan: &Plan,
    p_arg: &TokenStream,
    p_pass: &TokenStream,
) -> TokenStream {
    let real = crate::emit::real();
    let lu_solve_t = lu_fn(
        cfg,
        plan,
        "lu_solve_t",
        " Solve `aᵀ x = b` (as `lu_solve`, on the transpose).",
        true,
        lu::Rhs::Vector,
    );
    quote! {
    /// Actuator efforts `τ = A⁻ᵀ (I u̇ + C u − γ)` (N or N·m, gravity included) that produce
    /// the platform motion `(x, u, ud)`; `Err` at a leg or parallel singularity.
    #[inline]
    pub fn inverse_dynamics(x: &[#real; NX], u: &[#real; DOF], ud: &[#real; DOF] #p_arg) -> Result<[#real; DOF], Singular> {
        let (a, f) = id_parts(x, u, ud #p_pass)?;
        lu_solve_t(&a, &f)
    }

    #lu_solve_t

    }
}

/// The `lu_inverse` it calls and `actuator_mass_matrix`, the wrapper of `inertia_parts`.
fn actuator_mass_matrix(
    cfg: &Config,
    plan: &Plan,
    p_arg: &TokenStream,
    p_pass: &TokenStream,
) -> TokenStream {
    let real = crate::emit::real();
    let lu_inverse = lu_fn(
        cfg,
        plan,
        "lu_inverse",
        " `a⁻¹`: one factorization (as `lu_solve`) for the `DOF` columns of the identity.",
        false,
        lu::Rhs::Identity,
    );
    quote! {
    #lu_inverse

    /// Inertia in actuator space `A⁻ᵀ I A⁻¹` (the lecture's eq. 68), symmetric.
    #[allow(clippy::all)]
    pub fn actuator_mass_matrix(x: &[#real; NX] #p_arg) -> Result<[[#real; DOF]; DOF], Singular> {
        let (a, i) = inertia_parts(x #p_pass)?;
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
                    return Err(Singular { site: Site::Input, value: s, condition_estimate: #real::INFINITY });
                }
                out[r][c] = s;
                out[c][r] = s;
            }
        }
        Ok(out)
    }

    }
}

/// `retract` for the platform's motion: its quaternion's index in `x`, whether `x` has a
/// position, and the math calls.
fn retract(cfg: &Config, plan: &Plan) -> TokenStream {
    let sqrt_n = emit::math_call(cfg, "sqrt", quote!(n));
    let sqrt_a = emit::math_call(cfg, "sqrt", quote!(a2));
    let sin_cos = emit::math_call(cfg, "sin_cos", quote!(0.5 * a));
    let (qi, has_p) = match plan.motion {
        PlatformMotion::Pose => (3usize, true),
        PlatformMotion::Orientation { .. } => (0usize, false),
        PlatformMotion::PlanarPoint { .. } => (0usize, false),
    };
    let planar = matches!(plan.motion, PlatformMotion::PlanarPoint { .. });
    let qi = Literal::usize_unsuffixed(qi);
    let translate = if has_p {
        quote! {
            for i in 0..3 {
                out[i] += du[3 + i];
            }
        }
    } else {
        quote!()
    };
    retract_template(planar, qi, translate, sqrt_a, sin_cos, sqrt_n)
}

/// The `retract` template: `x ⊕ du`.
fn retract_template(
    planar: bool,
    qi: Literal,
    translate: TokenStream,
    sqrt_a: TokenStream,
    sin_cos: TokenStream,
    sqrt_n: TokenStream,
) -> TokenStream {
    let real = crate::emit::real();
    if planar {
        return quote! {
            /// `x` moved by `du` (the point's displacement, m).
            #[allow(clippy::all)]
            fn retract(x: &[#real; NX], du: &[#real; DOF]) -> [#real; NX] {
                let mut out = *x;
                for i in 0..NX {
                    out[i] += du[i];
                }
                out
            }
        };
    }
    quote! {
        /// `x` moved by the small motion `du` (rotation vector, then translation; base frame).
        #[allow(clippy::all)]
        fn retract(x: &[#real; NX], du: &[#real; DOF]) -> [#real; NX] {
            let a2 = du[0] * du[0] + du[1] * du[1] + du[2] * du[2];
            let a = #sqrt_a;
            let (s, c) = #sin_cos;
            let k = if a > 0.0 { s / a } else { 0.5 };
            let d = [c, k * du[0], k * du[1], k * du[2]];
            let i = #qi;
            let q = [x[i], x[i + 1], x[i + 2], x[i + 3]];
            let r = [
                d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
                d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
                d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
                d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0],
            ];
            let n = r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3];
            let n = #sqrt_n;
            let mut out = *x;
            for j in 0..4 {
                out[i + j] = r[j] / n;
            }
            #translate
            out
        }

    }
}

/// `fk_residual`: Newton's residual of `forward_kinematics`, with `A(x)`.
fn fk_residual() -> TokenStream {
    let real = crate::emit::real();
    quote! {
        /// The residual `q − q(x)` (angles wrapped to (−π, π]: `q`'s revolute entries are already
        /// in [−π, π], as `q(x)`'s are), its max norm, and `A(x)`.
        #[allow(clippy::all)]
        fn fk_residual(q: &[#real; DOF], x: &[#real; NX]) -> Option<([#real; DOF], #real, [[#real; DOF]; DOF])> {
            let (qx, a) = fk_parts(x).ok()?;
            let mut r = [0.0; DOF];
            let mut m: #real = 0.0;
            for i in 0..DOF {
                let mut d = q[i] - qx[i];
                if REVOLUTE[i] {
                    let t = 2.0 * core::#real::consts::PI;
                    if d > core::#real::consts::PI {
                        d -= t;
                    } else if d <= -core::#real::consts::PI {
                        d += t;
                    }
                }
                r[i] = d;
                let ad = if d < 0.0 { -d } else { d };
                if !(ad <= m) {
                    m = ad;
                }
            }
            if m < #real::INFINITY { Some((r, m, a)) } else { None }
        }
    }
}

/// `forward_kinematics`: Newton's method on `fk_residual`, its tolerance (scaled to the
/// mechanism) and iteration limit in its docs.
fn forward_kinematics(cfg: &Config, plan: &Plan) -> TokenStream {
    let real = crate::emit::real();
    let fk_tol = crate::scalar::tolerance(noc::FK_TOLERANCE);
    let fk_max = noc::FK_MAX_ITERATIONS;
    // Rounded to 13 significant digits, as the squared tolerance of the LU.
    let fk_tol = fk_tol * plan.fk_scale();
    let fk_tol = format!("{fk_tol:.12e}").parse().unwrap_or(fk_tol);
    let fk_tol_lit = Literal::f64_unsuffixed(fk_tol);
    let fk_doc = [
        " Forward kinematics: the platform coordinates whose actuated joint positions are `q`,"
            .to_string(),
        " by Newton's method from `guess` (`x ← x ⊕ A⁻¹ (q − q(x))`, the step halved while it"
            .to_string(),
        format!(" does not reduce the residual), at most {fk_max} iterations, converged when"),
        format!(" `max |q(x) − q| ≤ {fk_tol:e}` (angles modulo 2π; a bound that does not grow"),
        " with `q`). A non-finite `q` or `guess` is `Err` at once. The result's quaternion is"
            .to_string(),
        " unit.".to_string(),
    ];
    let sin_cos_q = emit::math_call(cfg, "sin_cos", quote!(v));
    let atan2_sc = emit::math_call(cfg, "atan2", quote!(s, c));
    let fk_max_lit = Literal::usize_unsuffixed(fk_max);
    quote! {
        #(#[doc = #fk_doc])*
        #[allow(clippy::all)]
        pub fn forward_kinematics(q: &[#real; DOF], guess: &[#real; NX]) -> Result<[#real; NX], NoConvergence> {
            for v in q.iter().chain(guess.iter()) {
                if !v.is_finite() {
                    return Err(NoConvergence { iterations: 0, residual: #real::INFINITY });
                }
            }
            // Revolute targets reduced to [−π, π] once (sin and cos reduce accurately).
            let mut q = *q;
            for i in 0..DOF {
                if REVOLUTE[i] {
                    let v = q[i];
                    let (s, c) = #sin_cos_q;
                    q[i] = #atan2_sc;
                }
            }
            let q = &q;
            let tol = #fk_tol_lit;
            let mut x = retract(guess, &[0.0; DOF]);
            let Some(mut cur) = fk_residual(q, &x) else {
                return Err(NoConvergence { iterations: 0, residual: #real::INFINITY });
            };
            for it in 0..#fk_max_lit {
                if cur.1 <= tol {
                    return Ok(x);
                }
                let Ok(du) = lu_solve(&cur.2, &cur.0) else {
                    return Err(NoConvergence { iterations: it, residual: cur.1 });
                };
                let mut step = 1.0;
                let mut moved = false;
                for _ in 0..20 {
                    let mut d = [0.0; DOF];
                    for i in 0..DOF {
                        d[i] = du[i] * step;
                    }
                    let xn = retract(&x, &d);
                    if let Some(r) = fk_residual(q, &xn) {
                        if r.1 < cur.1 {
                            x = xn;
                            cur = r;
                            moved = true;
                            break;
                        }
                    }
                    step *= 0.5;
                }
                if !moved {
                    return Err(NoConvergence { iterations: it + 1, residual: cur.1 });
                }
            }
            if cur.1 <= tol {
                Ok(x)
            } else {
                Err(NoConvergence { iterations: #fk_max_lit, residual: cur.1 })
            }
        }
    }
}
