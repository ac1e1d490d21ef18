//! The natural orthogonal complement's columns: the joint rates `ẋ = S u`
//! ([`joint_rates_generic`]) and, per unit independent speed, the joint rates and the bodies'
//! twists that project the wrenches (`T`, the lecture's eqs. 21–24).

use alloc::vec;
use alloc::vec::Vec;

use super::config::Config;
use super::force::Extras;
use super::motion::motions;
use super::plan::Plan;
use super::tree::Kin;
use crate::algebra::{V, add, cv, mv, sub};
use crate::scalar::Real;

/// All joint rates `ẋ = S u` (`ẋ_d = −Φ_d⁻¹ Φ_i u`).
pub fn joint_rates_generic<R: Real>(plan: &Plan, c: &Config<R>, u: &[R]) -> Vec<R> {
    let rhs: Vec<R> = c
        .jac
        .iter()
        .map(|row| {
            plan.independent
                .iter()
                .zip(u)
                .fold(R::c(0.0), |s, (&j, &uj)| s - row[j] * uj)
        })
        .collect();
    let xd_d = c.lu.solve(&rhs);
    let mut xd = vec![R::c(0.0); plan.nx()];
    for (k, &j) in plan.independent.iter().enumerate() {
        xd[j] = u[k];
    }
    for (k, &j) in plan.dependent.iter().enumerate() {
        xd[j] = xd_d[k];
    }
    xd
}

/// The point `p` of body `b` (body-frame coordinates) relative to the body's joint point,
/// `(pos − o) + R p` (base frame): formed from the difference of the two absolute points, not
/// from the absolute position of `p`, so far from the base origin nothing large cancels (and
/// `pos − o` folds to zero where they coincide).
pub(super) fn offset<R: Real>(k: &Kin<R>, b: usize, p: V<R>) -> V<R> {
    add(sub(k.pos[b], k.o[b]), mv(&k.rot[b], p))
}

/// Per unit independent speed `u = e_k`: the joint rates (column `k` of `S`), each body's
/// angular velocity and mass-centre velocity, each payload's likewise.
pub(super) struct UnitTwists<R> {
    pub(super) rates: Vec<Vec<R>>,
    pub(super) bodies: Vec<Vec<(V<R>, V<R>)>>,
    pub(super) payloads: Vec<Vec<(V<R>, V<R>)>>,
}

pub(super) fn unit_twists<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    extras: &Extras<R>,
) -> UnitTwists<R> {
    let d = plan.dof();
    let n = plan.nx();
    let mut t = UnitTwists {
        rates: Vec::with_capacity(d),
        bodies: Vec::with_capacity(d),
        payloads: Vec::with_capacity(d),
    };
    for k in 0..d {
        let mut e = vec![R::c(0.0); d];
        e[k] = R::c(1.0);
        let xd = joint_rates_generic(plan, c, &e);
        let m = motions(plan, &c.kin, &xd, None);
        t.payloads.push(
            extras
                .payloads
                .iter()
                .map(|(b, p)| (m[*b].w, m[*b].vel_rel(offset(&c.kin, *b, p.com))))
                .collect(),
        );
        t.rates.push(xd);
        t.bodies.push(
            (0..n)
                .map(|b| {
                    let (_, com, _) = plan.joints[b].body;
                    (m[b].w, m[b].vel_rel(offset(&c.kin, b, cv(&com))))
                })
                .collect(),
        );
    }
    t
}
