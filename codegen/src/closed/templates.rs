//! The fixed items of every closed-loop module: the error types, the actuator-space functions
//! that need no kernel (`inverse_kinematics`, `actuator_rates`), and the assembly
//! (`forward_kinematics`, staged, around `newton_assembly`, Newton's method on the
//! `newton_step` kernel).

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use runtime::closed::noc;

/// The fixed items (with `Site::Spring` when the mechanism has spring-dampers).
pub(super) fn templates(springs: bool) -> TokenStream {
    let types = error_types(springs);
    let actuators = actuator_functions();
    let forward_kinematics = forward_kinematics();
    let newton_assembly = newton_assembly();
    quote! {
        #types

        #actuators

        #forward_kinematics

        #newton_assembly
    }
}

/// `Site` (its closure and constraint variants documented with the tolerances; `Spring` with
/// `springs`), `Singular` and `NoConvergence`.
fn error_types(springs: bool) -> TokenStream {
    let tol = crate::scalar::tolerance;
    let con_tol = tol(noc::CONSTRAINT_TOLERANCE);
    let clo_tol = tol(noc::CLOSURE_TOLERANCE);
    let closure_doc = format!(
        " Kept loop equation `k` exceeds `{clo_tol:e}` (times the mechanism's size for a point equation): `x` does not close the loops. `value` is `tol² − Φ_k²`."
    );
    let constraint_doc = format!(
        " Pivot `i` of the LU of `Φ_d` (columns scaled to unit norm, partial pivoting) is `|p| ≤ {con_tol:e}`: the independent coordinates (nearly) fail to determine the others."
    );
    let spring_variant = if springs {
        let doc = format!(
            " Spring `k` (`SPRING_NAMES` order) is shorter than `{:e}` times the mechanism's size: its force has no direction.",
            noc::SPRING_TOLERANCE
        );
        quote! {
            #[doc = #doc]
            Spring(usize),
        }
    } else {
        quote!()
    };
    let errors = crate::module::error_types(
        "Which matrix, equation or pivot.",
        "The value that failed its test.",
        "The last largest scaled loop-equation residual.",
    );
    quote! {
        /// Where an evaluation failed.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Site {
            /// Pivot `i` of the generalized inertia's `LDLᵀ` (forward dynamics).
            MassMatrix(usize),
            #[doc = #closure_doc]
            Closure(usize),
            #[doc = #constraint_doc]
            Constraint(usize),
            #spring_variant
            /// An input is NaN or infinite, or so large that a result overflows.
            Input,
        }

        #errors
    }
}

/// `inverse_kinematics` and `actuator_rates`: the actuated joints are the independent
/// coordinates.
fn actuator_functions() -> TokenStream {
    let real = crate::emit::real();
    quote! {
        /// The independent coordinates of `x` (rad or m, `ACTUATOR_NAMES` order).
        #[allow(clippy::all)]
        pub fn inverse_kinematics(x: &[#real; NX]) -> Result<[#real; DOF], Singular> {
            let mut q = [0.0; DOF];
            for k in 0..DOF {
                let v = x[INDEPENDENT[k]];
                if !v.is_finite() {
                    return Err(Singular { site: Site::Input, value: v, condition_estimate: #real::INFINITY });
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
        pub fn actuator_rates(x: &[#real; NX], u: &[#real; DOF]) -> Result<[#real; DOF], Singular> {
            inverse_kinematics(x)?;
            for k in 0..DOF {
                if !u[k].is_finite() {
                    return Err(Singular { site: Site::Input, value: u[k], condition_estimate: #real::INFINITY });
                }
            }
            Ok(*u)
        }
    }
}

/// `forward_kinematics`: the independent coordinates moved to `q` in stages, each assembled by
/// `newton_assembly`, else one solve from the guess.
fn forward_kinematics() -> TokenStream {
    let real = crate::emit::real();
    let max_stages = Literal::usize_unsuffixed(noc::FK_MAX_STAGES);
    let max_stages_f = Literal::f64_unsuffixed(noc::FK_MAX_STAGES as f64);
    quote! {
        /// Forward kinematics (assembly): the joint positions that close the loops with the
        /// independent coordinates `q` (angles compared as given), on the branch of `guess`
        /// (pass the last configuration to follow a motion, or `HOME`). The independent
        /// coordinates move from `guess`'s to `q` in equal stages of at most `STEP` each (at
        /// most 64 stages), each assembled by Newton's method from the last: a far target
        /// stays on the guess's assembly mode. If a stage fails (the straight path crosses a
        /// singularity), one Newton solve from `guess` decides. Each solve: the step halved
        /// while it does not reduce the residual; at most 50 iterations, converged when every
        /// kept loop equation is within `1e-12` (times the mechanism's size for a point
        /// equation) and every loop equation (the redundant ones too) and revolute-axis
        /// alignment within `1e-9` (else a spurious branch: `Err`), then one more full step
        /// (kept unless it raises the residual); each dependent angle stays within ±π of its
        /// guess.
        #[allow(clippy::all)]
        pub fn forward_kinematics(q: &[#real; DOF], guess: &[#real; NX]) -> Result<[#real; NX], NoConvergence> {
            let mut need: #real = 1.0;
            for k in 0..DOF {
                let d = q[k] - guess[INDEPENDENT[k]];
                let a = (if d < 0.0 { -d } else { d }) / STEP[k];
                if !(a <= need) {
                    need = a;
                }
            }
            if need > 1.0 {
                let stages = if need < #max_stages_f {
                    let n = need as usize;
                    if (n as #real) < need { n + 1 } else { n }
                } else {
                    #max_stages
                };
                let mut x = *guess;
                let mut followed = true;
                for s in 1..=stages {
                    let t = s as #real / stages as #real;
                    let mut qs = *q;
                    if s < stages {
                        for k in 0..DOF {
                            let g = guess[INDEPENDENT[k]];
                            qs[k] = g + t * (q[k] - g);
                        }
                    }
                    match newton_assembly(&qs, &x) {
                        Ok(xn) => x = xn,
                        Err(_) => {
                            followed = false;
                            break;
                        }
                    }
                }
                if followed {
                    return Ok(x);
                }
            }
            newton_assembly(q, guess)
        }
    }
}

/// `newton_assembly`: one Newton solve on `newton_step`, with its tolerances (the kept
/// equations', every equation's, and the stall acceptance of single precision) and iteration
/// limit.
fn newton_assembly() -> TokenStream {
    let real = crate::emit::real();
    let tol = crate::scalar::tolerance;
    let fk_tol = Literal::f64_unsuffixed(tol(noc::FK_TOLERANCE));
    // In single precision the loop equations' rounding floor can sit above the rescaled 1e-12
    // (near 1e-5 of the size for poorly conditioned loops, measured on the four-bar and
    // Bricard): when no step reduces the residual any more, a residual within the rescaled
    // 1e-10 (3.7e-5) is accepted. In f64 the two are the same.
    let stall_tol = Literal::f64_unsuffixed(if tol(1.0e-12) == 1.0e-12 {
        noc::FK_TOLERANCE
    } else {
        tol(1e-10)
    });
    let fk_max = Literal::usize_unsuffixed(noc::FK_MAX_ITERATIONS);
    let full_tol = Literal::f64_unsuffixed(tol(noc::FULL_TOLERANCE));
    quote! {
        /// One Newton solve of `forward_kinematics` from `guess`.
        #[allow(clippy::all)]
        fn newton_assembly(q: &[#real; DOF], guess: &[#real; NX]) -> Result<[#real; NX], NoConvergence> {
            // A dependent angle moved to within ±π of its guess (the same configuration): a
            // long Newton step can land turns away, where f32 (and f64) keep fewer digits.
            let wrap = |x: &mut [#real; NX]| {
                let t = 2.0 * core::#real::consts::PI;
                for i in 0..NX {
                    let d = x[i] - guess[i];
                    let ad = if d < 0.0 { -d } else { d };
                    if WRAP[i] && ad > core::#real::consts::PI && ad < 1e9 {
                        let k = d / t + 0.5;
                        let mut n = k as i64 as #real;
                        if n > k {
                            n -= 1.0;
                        }
                        x[i] = guess[i] + (d - n * t);
                    }
                }
            };
            let mut x = *guess;
            for k in 0..DOF {
                x[INDEPENDENT[k]] = q[k];
            }
            let abs = |v: #real| if v < 0.0 { -v } else { v };
            let Ok((mut dx, mut r, mut full)) = newton_step(&x) else {
                return Err(NoConvergence { iterations: 0, residual: #real::INFINITY });
            };
            for it in 0..#fk_max {
                if abs(r) <= #fk_tol {
                    if !(abs(full) <= #full_tol) {
                        // The kept equations hold but not all of them: a spurious branch.
                        return Err(NoConvergence { iterations: it, residual: abs(full) });
                    }
                    // One more full step: the coordinates to rounding.
                    let mut xn = x;
                    for i in 0..NX {
                        xn[i] += dx[i];
                    }
                    if let Ok((_, rn, fulln)) = newton_step(&xn) {
                        if abs(rn) <= abs(r) && abs(fulln) <= #full_tol {
                            return Ok(xn);
                        }
                    }
                    return Ok(x);
                }
                let mut step = 1.0;
                let mut moved = false;
                for _ in 0..20 {
                    let mut xn = x;
                    for i in 0..NX {
                        xn[i] += step * dx[i];
                    }
                    wrap(&mut xn);
                    if let Ok((dn, rn, fulln)) = newton_step(&xn) {
                        if abs(rn) < abs(r) {
                            x = xn;
                            dx = dn;
                            r = rn;
                            full = fulln;
                            moved = true;
                            break;
                        }
                    }
                    step *= 0.5;
                }
                if !moved {
                    if abs(r) <= #stall_tol && abs(full) <= #full_tol {
                        return Ok(x);
                    }
                    return Err(NoConvergence { iterations: it + 1, residual: abs(r) });
                }
            }
            Err(NoConvergence { iterations: #fk_max, residual: abs(r) })
        }
    }
}
