// Template: Newton's forward kinematics of a platform module, around its `retract`
// (`platform_retract_*.rs`), its kernel `fk_parts` (`q(x)` and `A(x)`) and its LU solve
// `lu_solve`. Stand-ins replaced when specialized (`codegen/src/template.rs`):
// `FK_TOLERANCE`, `FK_MAX_ITERATIONS`, and the math calls `sin_cos` and `atan2`. Compiled and
// tested as a module by `tests/tests/templates.rs`.

/// The residual `q − q(x)` (angles wrapped to (−π, π]: `q`'s revolute entries are already
/// in [−π, π], as `q(x)`'s are), its max norm, and `A(x)`.
#[allow(clippy::all)]
fn fk_residual(q: &[f64; DOF], x: &[f64; NX]) -> Option<([f64; DOF], f64, [[f64; DOF]; DOF])> {
    let (qx, a) = fk_parts(x).ok()?;
    let mut r = [0.0; DOF];
    let mut m: f64 = 0.0;
    for i in 0..DOF {
        let mut d = q[i] - qx[i];
        if REVOLUTE[i] {
            let t = 2.0 * core::f64::consts::PI;
            if d > core::f64::consts::PI {
                d -= t;
            } else if d <= -core::f64::consts::PI {
                d += t;
            }
        }
        r[i] = d;
        let ad = if d < 0.0 { -d } else { d };
        if !(ad <= m) {
            m = ad;
        }
    }
    if m < f64::INFINITY {
        Some((r, m, a))
    } else {
        None
    }
}

/// Forward kinematics: the platform coordinates whose actuated joint positions are `q`,
/// by Newton's method from `guess` (`x ← x ⊕ A⁻¹ (q − q(x))`, the step halved while it
/// does not reduce the residual), at most {FK_MAX_ITERATIONS} iterations, converged when
/// `max |q(x) − q| ≤ {FK_TOLERANCE}` (angles modulo 2π; a bound that does not grow
/// with `q`). A non-finite `q` or `guess` is `Err` at once. The result's quaternion is
/// unit.
#[allow(clippy::all)]
pub fn forward_kinematics(q: &[f64; DOF], guess: &[f64; NX]) -> Result<[f64; NX], NoConvergence> {
    for v in q.iter().chain(guess.iter()) {
        if !v.is_finite() {
            return Err(NoConvergence {
                iterations: 0,
                residual: f64::INFINITY,
                stop: Stop::Input,
            });
        }
    }
    // Revolute targets reduced to [−π, π] once (sin and cos reduce accurately).
    let mut q = *q;
    for i in 0..DOF {
        if REVOLUTE[i] {
            let v = q[i];
            let (s, c) = sin_cos(v);
            q[i] = atan2(s, c);
        }
    }
    let q = &q;
    let tol = FK_TOLERANCE;
    let mut x = retract(guess, &[0.0; DOF]);
    let Some(mut cur) = fk_residual(q, &x) else {
        return Err(NoConvergence {
            iterations: 0,
            residual: f64::INFINITY,
            stop: Stop::Guess,
        });
    };
    for it in 0..FK_MAX_ITERATIONS {
        if cur.1 <= tol {
            return Ok(x);
        }
        let Ok(du) = lu_solve(&cur.2, &cur.0) else {
            return Err(NoConvergence {
                iterations: it,
                residual: cur.1,
                stop: Stop::Singular,
            });
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
            return Err(NoConvergence {
                iterations: it + 1,
                residual: cur.1,
                stop: Stop::Stalled,
            });
        }
    }
    if cur.1 <= tol {
        Ok(x)
    } else {
        Err(NoConvergence {
            iterations: FK_MAX_ITERATIONS,
            residual: cur.1,
            stop: Stop::Iterations,
        })
    }
}
