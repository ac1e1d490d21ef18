//! The generalized inertia `I = Sᵀ M_T S` of the independent coordinates from the bodies'
//! twists per unit speed, with payloads and the rotors' `Sᵀ diag(I_a) S`.

use alloc::vec;
use alloc::vec::Vec;

use super::config::Config;
use super::force::Extras;
use super::plan::Plan;
use super::twists::{UnitTwists, unit_twists};
use crate::algebra::{dot, inertia_quad, mtv, mv};
use crate::scalar::Real;

/// The generalized inertia `I = Sᵀ M_T S` of the independent coordinates, from each body's
/// twist per unit speed (exactly symmetric: the upper triangle mirrored), plus the rotors'
/// `Sᵀ diag(I_a) S`.
pub fn generalized_inertia<R: Real>(plan: &Plan, c: &Config<R>) -> Vec<Vec<R>> {
    generalized_inertia_with(plan, c, &Extras::none())
}

/// [`generalized_inertia`] with run-time [`Extras`].
pub fn generalized_inertia_with<R: Real>(
    plan: &Plan,
    c: &Config<R>,
    extras: &Extras<R>,
) -> Vec<Vec<R>> {
    let d = plan.dof();
    let n = plan.nx();
    let UnitTwists {
        rates,
        bodies: cols,
        payloads: payload_cols,
    } = unit_twists(plan, c, extras);
    let mut out = vec![vec![R::c(0.0); d]; d];
    for b in 0..n {
        let (mass, _, inertia) = plan.joints[b].body;
        if mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0) {
            continue;
        }
        for i in 0..d {
            for j in i..d {
                let (wi, vi) = cols[i][b];
                let (wj, vj) = cols[j][b];
                let v = R::c(mass) * dot(vi, vj) + inertia_quad(&c.kin.rot[b], &inertia, wi, wj);
                out[i][j] = out[i][j] + v;
            }
        }
    }
    for (k, (b, p)) in extras.payloads.iter().enumerate() {
        let rot = &c.kin.rot[*b];
        for i in 0..d {
            for j in i..d {
                let (wi, vi) = payload_cols[i][k];
                let (wj, vj) = payload_cols[j][k];
                let (wbi, wbj) = (mtv(rot, wi), mtv(rot, wj));
                let v = p.mass * dot(vi, vj) + dot(wbi, mv(&p.inertia, wbj));
                out[i][j] = out[i][j] + v;
            }
        }
    }
    for (b, jp) in plan.joints.iter().enumerate() {
        let a = match &extras.drives {
            Some(dr) => match &dr.armature {
                Some(a) => a[b],
                None => continue,
            },
            None if jp.drive.armature == 0.0 => continue,
            None => R::c(jp.drive.armature),
        };
        for i in 0..d {
            for j in i..d {
                out[i][j] = out[i][j] + a * rates[i][b] * rates[j][b];
            }
        }
    }
    for i in 0..d {
        for j in 0..i {
            out[i][j] = out[j][i];
        }
    }
    out
}
