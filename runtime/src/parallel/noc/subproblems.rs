//! The Paden–Kahan subproblems of the legs' closed-form inverse kinematics (step 2): one
//! rotation axis, two intersecting axes, and the RUS crank from the rod length; the joints as
//! `(sin, cos)` pairs.

use super::plan::{LegPlan, cross3, dot3, sub3};
use crate::algebra::{V, add, cross, cv, dot, scale, sub};
use crate::model::Vec3;
use crate::scalar::{Real, Singular, Site};

/// Paden–Kahan subproblem 2: `(sin, cos)` of `θ1, θ2` with `R(e1, θ1)·R(e2, θ2)·p = q`
/// (`e1`, `e2` unit, intersecting; `|p| = |q|`), on the branch `sigma`.
pub(super) fn two_axes<R: Real>(
    e1: &Vec3,
    e2: &Vec3,
    p: V<R>,
    q: V<R>,
    sigma: f64,
    leg: usize,
    check: bool,
) -> Result<[(R, R); 2], Singular> {
    let w = dot3(e1, e2);
    let k = cross3(e1, e2);
    let kk = dot3(&k, &k);
    let den = 1.0 / (w * w - 1.0);
    let e2p = dot(cv(e2), p);
    let e1q = dot(cv(e1), q);
    let alpha = (R::c(w) * e2p - e1q) * R::c(den);
    let beta = (R::c(w) * e1q - e2p) * R::c(den);
    let pp = dot(p, p);
    // γ² |e1 × e2|² = |p|² − α² − β² − 2wαβ. Near a leg singularity (q → ±e1) the difference
    // cancels; for perpendicular axes (w = 0, α = e1·q) it is |e1 × q|² − (e2·p)² since |q| = |p|,
    // which keeps the small value's relative accuracy (error ~ε/δ instead of ~ε/δ²).
    let g2 = if w == 0.0 {
        let eq = cross(cv(e1), q);
        (dot(eq, eq) - e2p * e2p) * R::c(1.0 / kk)
    } else {
        (pp - alpha * alpha - beta * beta - R::c(2.0 * w) * alpha * beta) * R::c(1.0 / kk)
    };
    // γ² < 0: the target is out of reach; γ² ≈ 0 (within 1e-12 of |p|²): the boundary of the
    // leg's workspace, where its Jacobian is singular.
    // Unchecked (`!check`) where the caller's own tests cover these cases and nothing it
    // returns uses the angles.
    let g2 = if check {
        let g2 = R::check(
            g2,
            R::c(-R::tolerance(1e-12)) * pp,
            pp,
            Site::Reach(leg),
            false,
        )?;
        R::check(g2, R::c(0.0), pp, Site::Leg(leg), false)?
    } else {
        g2
    };
    let gamma = R::c(sigma) * g2.sqrt();
    let c = add(
        add(scale(alpha, cv(e1)), scale(beta, cv(e2))),
        scale(gamma, cv(&k)),
    );
    // θ2 turns p about e2 onto c.
    let pperp = sub(p, scale(e2p, cv(e2)));
    let cperp = sub(c, scale(e2p, cv(e2)));
    let n2 = dot(pperp, pperp);
    let s2 = dot(cross(cv(e2), pperp), cperp) / n2;
    let c2 = dot(pperp, cperp) / n2;
    // θ1 turns c about e1 onto q.
    let cq = sub(c, scale(e1q, cv(e1)));
    let qq = sub(q, scale(e1q, cv(e1)));
    let n1 = dot(cq, cq);
    let n1 = if check {
        R::check(n1, R::c(0.0), pp, Site::Leg(leg), false)?
    } else {
        n1
    };
    let s1 = dot(cross(cv(e1), cq), qq) / n1;
    let c1 = dot(cq, qq) / n1;
    Ok([(s1, c1), (s2, c2)])
}

/// Paden–Kahan subproblem 1: `(sin, cos)` of the rotation about the unit `e` that turns `p`
/// onto `q` (equal components across `e`).
pub(super) fn one_axis<R: Real>(e: &Vec3, p: V<R>, q: V<R>) -> (R, R) {
    let pp = sub(p, scale(dot(cv(e), p), cv(e)));
    let qq = sub(q, scale(dot(cv(e), q), cv(e)));
    let n = dot(pp, pp);
    (dot(cross(cv(e), pp), qq) / n, dot(pp, qq) / n)
}

/// RUS: `(sin, cos)` of the crank angle that puts the U centre at the rod length from `a` (`L`).
pub(super) fn rus_crank<R: Real>(plan: &LegPlan, a: V<R>, leg: usize) -> Result<(R, R), Singular> {
    let e0 = plan.axes[0];
    let o0 = plan.points[0];
    let r = sub3(&plan.u_centre, &o0);
    let rpar = dot3(&e0, &r);
    let rperp = [
        r[0] - rpar * e0[0],
        r[1] - rpar * e0[1],
        r[2] - rpar * e0[2],
    ];
    let er = cross3(&e0, &rperp);
    let d = sub(a, cv(&o0));
    let kk = (dot(d, d) + R::c(dot3(&r, &r) - plan.length * plan.length)) * R::c(0.5)
        - R::c(rpar) * dot(d, cv(&e0));
    let aa = dot(d, cv(&rperp));
    let bb = dot(d, cv(&er));
    let rho2 = aa * aa + bb * bb;
    let disc = rho2 - kk * kk;
    let disc = R::check(disc, R::c(0.0), rho2, Site::Reach(leg), false)?;
    let sq = R::c(plan.sigma_first) * disc.sqrt();
    let c = (aa * kk - bb * sq) / rho2;
    let s = (bb * kk + aa * sq) / rho2;
    Ok((s, c))
}
