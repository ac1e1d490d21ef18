// Template: the assembly of a closed-loop module in joint coordinates (`forward_kinematics`,
// staged, around `newton_assembly`, Newton's method on the module's `newton_step` kernel).
// Stand-ins replaced when specialized (`codegen/src/template.rs`): `FK_MAX_STAGES` (and the
// same number as a float, `FK_MAX_STAGES_REAL`), `FK_MAX_ITERATIONS`, the tolerances
// `FK_TOLERANCE` (kept equations), `FULL_TOLERANCE` (every equation) and `STALL_TOLERANCE`
// (a stalled residual accepted). Compiled and tested as a module by
// `tests/tests/templates.rs`.

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
pub fn forward_kinematics(q: &[f64; DOF], guess: &[f64; NX]) -> Result<[f64; NX], NoConvergence> {
    let mut need: f64 = 1.0;
    for k in 0..DOF {
        let d = q[k] - guess[INDEPENDENT[k]];
        let a = (if d < 0.0 { -d } else { d }) / STEP[k];
        if !(a <= need) {
            need = a;
        }
    }
    if need > 1.0 {
        let stages = if need < FK_MAX_STAGES_REAL {
            let n = need as usize;
            if (n as f64) < need { n + 1 } else { n }
        } else {
            FK_MAX_STAGES
        };
        let mut x = *guess;
        let mut followed = true;
        for s in 1..=stages {
            let t = s as f64 / stages as f64;
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

/// One Newton solve of `forward_kinematics` from `guess`.
#[allow(clippy::all)]
fn newton_assembly(q: &[f64; DOF], guess: &[f64; NX]) -> Result<[f64; NX], NoConvergence> {
    // A dependent angle moved to within ±π of its guess (the same configuration): a
    // long Newton step can land turns away, where f32 (and f64) keep fewer digits.
    let wrap = |x: &mut [f64; NX]| {
        let t = 2.0 * core::f64::consts::PI;
        for i in 0..NX {
            let d = x[i] - guess[i];
            let ad = if d < 0.0 { -d } else { d };
            if WRAP[i] && ad > core::f64::consts::PI && ad < 1e9 {
                let k = d / t + 0.5;
                let mut n = k as i64 as f64;
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
    let abs = |v: f64| if v < 0.0 { -v } else { v };
    let (mut dx, mut r, mut full) = match newton_step(&x) {
        Ok(s) => s,
        Err(e) => {
            return Err(NoConvergence {
                iterations: 0,
                residual: f64::INFINITY,
                stop: if e.site == Site::Input {
                    Stop::Input
                } else {
                    Stop::Guess
                },
            });
        }
    };
    for it in 0..FK_MAX_ITERATIONS {
        if abs(r) <= FK_TOLERANCE {
            if !(abs(full) <= FULL_TOLERANCE) {
                // The kept equations hold but not all of them: a spurious branch.
                return Err(NoConvergence {
                    iterations: it,
                    residual: abs(full),
                    stop: Stop::Branch,
                });
            }
            // One more full step: the coordinates to rounding.
            let mut xn = x;
            for i in 0..NX {
                xn[i] += dx[i];
            }
            if let Ok((_, rn, fulln)) = newton_step(&xn) {
                if abs(rn) <= abs(r) && abs(fulln) <= FULL_TOLERANCE {
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
            if abs(r) <= STALL_TOLERANCE && abs(full) <= FULL_TOLERANCE {
                return Ok(x);
            }
            return Err(NoConvergence {
                iterations: it + 1,
                residual: abs(r),
                stop: Stop::Stalled,
            });
        }
    }
    Err(NoConvergence {
        iterations: FK_MAX_ITERATIONS,
        residual: abs(r),
        stop: Stop::Iterations,
    })
}
