//! Step 5: the generalized force `f = Tᵀ w` of the independent coordinates (the lecture's
//! eqs. 21–24, each body's wrench by eq. 12), with the springs and the joints' drives; and the
//! run-time [`Extras`].

use alloc::vec;
use alloc::vec::Vec;

use super::config::Config;
use super::loop_equations::row_bias;
use super::motion::motions;
use super::plan::Plan;
use super::twists::{offset, unit_twists};
use crate::algebra::{V, add, cross, cv, dot, euler, mtv, mv, scale, sub, zero3};
use crate::drive::{DriveInputs, drive_effort};
use crate::model::Vec3;
use crate::payload::Payload;
use crate::scalar::Real;

/// Values of a closed-loop mechanism given at run time in place of the plan's constants (a
/// generated module's `Params`, where they are symbolic inputs).
#[derive(Clone, Debug)]
pub struct Extras<R> {
    /// Rigid bodies given at run time, each attached to tree body `.0` (its mass centre and
    /// inertia in that body's frame): a payload, and the bodies whose inertial parameters are
    /// run-time parameters (their constants zero in the plan).
    pub payloads: Vec<(usize, Payload<R>)>,
    /// The drives of every tree joint (entry `j`: tree joint `j`), replacing the plan's.
    pub drives: Option<DriveInputs<R>>,
}

impl<R> Extras<R> {
    /// No run-time values: the plan's constants.
    pub fn none() -> Extras<R> {
        Extras {
            payloads: Vec::new(),
            drives: None,
        }
    }
}

/// The generalized force `f = I u̇ + C u − γ` (`γ` only with `gravity`) of the independent
/// coordinates: `f = Tᵀ w`, each body's wrench projected by its twist per unit speed (equal to
/// `Sᵀ τ_T` with the open tree's joint efforts `τ_T`, with less cancellation).
pub fn generalized_force<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    generalized_force_with(plan, c, u, ud, gravity, &Extras::none())
}

/// [`generalized_force`] with run-time [`Extras`].
pub fn generalized_force_with<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
    extras: &Extras<R>,
) -> Vec<R> {
    // The columns of `S` and the bodies' twists per unit speed (for the projection below);
    // `ẋ = S u` from the columns, the independent rates exactly `u`.
    let t = unit_twists(plan, c, extras);
    let mut xd = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.independent.iter().enumerate() {
        xd[j] = u[k];
    }
    for &j in &plan.dependent {
        xd[j] = (1..u.len()).fold(t.rates[0][j] * u[0], |s, k| s + t.rates[k][j] * u[k]);
    }
    let bias_m = motions(plan, &c.kin, &xd, None);
    let rhs: Vec<R> = plan
        .system_rows()
        .zip(&c.jac)
        .map(|(r, row)| {
            let b = row_bias(plan, &c.kin, &bias_m, r);
            plan.independent
                .iter()
                .zip(ud)
                .fold(-b, |s, (&j, &a)| s - row[j] * a)
        })
        .collect();
    let xdd_d = c.lu.solve(&rhs);
    let mut xdd = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.independent.iter().enumerate() {
        xdd[j] = ud[k];
    }
    for (k, &j) in plan.dependent.iter().enumerate() {
        xdd[j] = xdd_d[k];
    }
    let m = motions(plan, &c.kin, &xd, Some(&xdd));
    // Virtual power body by body (the lecture's eqs. 21–24, `f = Tᵀ w` with `T`'s block rows the
    // bodies' twists per unit speed): f_k = Σ_b ω_b⁽ᵏ⁾·n_b + v_b⁽ᵏ⁾·f_b, each body's wrench
    // `w_b = M ṫ + W M t − w^G` (eq. 12) at its mass centre. Not `Sᵀ τ_T`: the open tree's
    // joint efforts hold whole subtrees on long lever arms and cancel in the projection (by up
    // to 1,600 times the result on the bundled loops), and their rounding survives; the
    // bodies' powers cancel far less (≤ 8 times, Bricard's 170).
    let d = plan.dof();
    let g: V<R> = if gravity { cv(&plan.gravity) } else { zero3() };
    let mut f = vec![R::c(0.0); d];
    for b in 0..plan.nx() {
        let (mass, com, inertia) = plan.joints[b].body;
        if mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0) {
            continue;
        }
        let r = offset(&c.kin, b, cv(&com));
        let fb = scale(R::c(mass), sub(m[b].accel_rel(r), g));
        let nb = euler(&c.kin.rot[b], &inertia, m[b].w, m[b].alpha);
        for (k, fk) in f.iter_mut().enumerate() {
            let (w, v) = t.bodies[k][b];
            *fk = *fk + (dot(w, nb) + dot(v, fb));
        }
    }
    for (i, (b, p)) in extras.payloads.iter().enumerate() {
        let rot = &c.kin.rot[*b];
        let r = offset(&c.kin, *b, p.com);
        let fb = scale(p.mass, sub(m[*b].accel_rel(r), g));
        let (wb, ab) = (mtv(rot, m[*b].w), mtv(rot, m[*b].alpha));
        let nb = mv(rot, add(mv(&p.inertia, ab), cross(wb, mv(&p.inertia, wb))));
        for (k, fk) in f.iter_mut().enumerate() {
            let (w, v) = t.payloads[k][i];
            *fk = *fk + (dot(w, nb) + dot(v, fb));
        }
    }
    // Springs (applied forces, counted with gravity): the tension `T = k (L − L₀) + c L̇`
    // does the virtual power `−T L̇`, so each effort gains `T ∂L/∂u_k`, with
    // `∂L/∂u_k = n · (v_b⁽ᵏ⁾ − v_a⁽ᵏ⁾)` at the two points.
    if gravity {
        for (s, &(l, n)) in plan.springs.iter().zip(&c.springs) {
            let dl: Vec<R> = (0..d)
                .map(|k| {
                    let at = |body: Option<usize>, p: &Vec3| -> V<R> {
                        let Some(b) = body else { return zero3() };
                        let (w, v) = t.bodies[k][b];
                        let com = plan.joints[b].body.1;
                        let r = mv(
                            &c.kin.rot[b],
                            cv(&[p[0] - com[0], p[1] - com[1], p[2] - com[2]]),
                        );
                        add(v, cross(w, r))
                    };
                    dot(n, sub(at(s.body_b, &s.point_b), at(s.body_a, &s.point_a)))
                })
                .collect();
            let ldot = (1..d).fold(dl[0] * u[0], |acc, k| acc + dl[k] * u[k]);
            let tension = R::c(s.stiffness) * (l - R::c(s.rest_length)) + R::c(s.damping) * ldot;
            for (fk, g) in f.iter_mut().zip(&dl) {
                *fk = *fk + tension * *g;
            }
        }
    }
    // The drives of every tree joint, actuated or passive: `I_a ẍ + δ(ẋ)`, mapped by `Sᵀ`
    // (the lecture's dissipative term δ).
    for (j, jp) in plan.joints.iter().enumerate() {
        let e = match &extras.drives {
            Some(dr) => dr.effort(j, xd[j], xdd[j]),
            None if jp.drive.is_none() => continue,
            None => drive_effort(&jp.drive, xd[j], xdd[j]),
        };
        for (k, fk) in f.iter_mut().enumerate() {
            *fk = *fk + t.rates[k][j] * e;
        }
    }
    f
}
