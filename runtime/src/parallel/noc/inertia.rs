//! The generalized inertia `I = TᵀMT` of the speeds `u`, assembled per leg from its end-point
//! inertia `Λ = J_J⁻ᵀ M_J J_J⁻¹` (eq. 68's structure) plus the platform's, a second route column
//! by column, and a payload's part of it.

use alloc::vec;
use alloc::vec::Vec;

use super::delta::delta_inertia;
use super::force::generalized_force;
use super::legs::LegKin;
use super::plan::{LegPlan, Plan};
use super::pose::Platform;
use super::shaft::shaft_inertia;
use super::ups::ups_inertia;
use crate::algebra::{M, V, add, cross, cv, dot, inertia_quad, mtv, mv, scale, sub, zero3};
use crate::drive::DriveInputs;
use crate::model::JointKind;
use crate::parallel::PlatformMotion;
use crate::payload::Payload;
use crate::scalar::Real;

/// The twist columns of a body moving with the platform, `n` speeds: `(Some(e_j), e_j × r_c)`
/// for the angular speeds (`r_c` the mass centre from the platform origin, base frame) and
/// `(None, e_j)` for the linear ones (pose).
fn platform_columns<R: Real>(
    motion: PlatformMotion,
    n: usize,
    rc: V<R>,
) -> Vec<(Option<V<R>>, V<R>)> {
    let unit = |j: usize| {
        let mut e = zero3::<R>();
        e[j] = R::c(1.0);
        e
    };
    if let PlatformMotion::PlanarPose { .. } = motion {
        // S: u = [vx, vy, ω], ω about z.
        return vec![
            (None, unit(0)),
            (None, unit(1)),
            (Some(unit(2)), cross(unit(2), rc)),
        ];
    }
    (0..n)
        .map(|j| {
            if j < 3 {
                (Some(unit(j)), cross(unit(j), rc))
            } else {
                (None, unit(j - 3))
            }
        })
        .collect()
}

/// The payload's part of the generalized inertia `I` (exactly symmetric): `T_Pᵀ M T_P` of
/// [`generalized_inertia`]'s platform term with the payload's values.
pub fn payload_inertia<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    payload: &Payload<R>,
) -> Vec<Vec<R>> {
    match &pl.parasitic {
        Some(par) => par.project_inertia(&payload_inertia_in(PlatformMotion::Pose, pl, payload)),
        None => payload_inertia_in(plan.motion, pl, payload),
    }
}

/// [`payload_inertia`] for the speeds of `motion`.
fn payload_inertia_in<R: Real>(
    motion: PlatformMotion,
    pl: &Platform<R>,
    payload: &Payload<R>,
) -> Vec<Vec<R>> {
    let n = motion.dof();
    let z = R::c(0.0);
    let mut out = vec![vec![z; n]; n];
    if motion.translates() || motion.schoenflies() {
        for (i, row) in out.iter_mut().enumerate().take(3) {
            row[i] = payload.mass;
        }
        return out;
    }
    let cols = platform_columns(motion, n, mv(&pl.rot, payload.com));
    for i in 0..n {
        for j in i..n {
            let mut v = payload.mass * dot(cols[i].1, cols[j].1);
            if let (Some(a), Some(b)) = (cols[i].0, cols[j].0) {
                let (ab, bb) = (mtv(&pl.rot, a), mtv(&pl.rot, b));
                v = v + dot(ab, mv(&payload.inertia, bb));
            }
            out[i][j] = v;
            out[j][i] = v;
        }
    }
    out
}

/// The generalized inertia `I = TᵀMT` of the speeds `u`, column by column: column `j` is the
/// generalized force of `u = 0`, `u̇ = e_j` without gravity. A second route to
/// [`generalized_inertia`] (the tests compare them).
pub fn generalized_inertia_by_columns<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
) -> Vec<Vec<R>> {
    let n = plan.dof();
    let zero = vec![R::c(0.0); n];
    let cols: Vec<Vec<R>> = (0..n)
        .map(|j| {
            let mut e = vec![R::c(0.0); n];
            e[j] = R::c(1.0);
            generalized_force(plan, pl, legs, &zero, &e, false)
        })
        .collect();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i <= j { cols[j][i] } else { cols[i][j] })
                .collect()
        })
        .collect()
}

/// The generalized inertia `I = TᵀMT = Σ_b T_bᵀ M_b T_b` of the speeds `u` (exactly symmetric),
/// assembled per leg (eq. 68's structure): the leg's joint-space inertia `M_J` (its open chain),
/// then its end-point inertia `Λ = J⁻ᵀ M_J J⁻¹`, then `Gᵀ Λ G` with `G` the map from `u` to the
/// end point's velocity; plus the platform's `T_Pᵀ M_P T_P`.
pub fn generalized_inertia<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
) -> Vec<Vec<R>> {
    generalized_inertia_with(plan, pl, legs, None)
}

/// [`generalized_inertia`] with the leg joints' rotor inertias from `drives` instead of the
/// plan (closed-form UPS legs then take the generic route).
pub fn generalized_inertia_with<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    drives: Option<&DriveInputs<R>>,
) -> Vec<Vec<R>> {
    match &pl.parasitic {
        // A 1T2R platform: Sᵀ I₆ S with the 6-DOF pose's inertia of the twist.
        Some(par) => par.project_inertia(&inertia_in(plan, PlatformMotion::Pose, pl, legs, drives)),
        None => inertia_in(plan, plan.motion, pl, legs, drives),
    }
}

/// [`generalized_inertia_with`] for the speeds of `motion`.
fn inertia_in<R: Real>(
    plan: &Plan,
    motion: PlatformMotion,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    drives: Option<&DriveInputs<R>>,
) -> Vec<Vec<R>> {
    let n = motion.dof();
    let z = R::c(0.0);
    let mut out = vec![vec![z; n]; n];
    let pose = matches!(motion, PlatformMotion::Pose);
    for (li, (lp, lk)) in plan.legs.iter().zip(legs).enumerate() {
        let armature: [Option<R>; 3] = match drives {
            Some(d) => core::array::from_fn(|k| d.armature.as_ref().map(|a| a[3 * li + k])),
            None => core::array::from_fn(|k| {
                let a = lp.drives.get(k).map_or(0.0, |d| d.armature);
                (a != 0.0).then(|| R::c(a))
            }),
        };
        if let Some(sp) = &lp.shaft {
            // The shaft to the tool (shaft.rs): its own 4 × 4.
            let m = shaft_inertia(lp, sp, lk);
            for i in 0..4 {
                for j in 0..4 {
                    out[i][j] = out[i][j] + m[i][j];
                }
            }
            continue;
        }
        let lam = match (&lp.ups, &lk.ups, &lp.delta, &lk.delta, drives) {
            (Some(up), Some(uk), _, _, None) => ups_inertia(up, uk),
            (_, _, Some(dp), Some(dk), None) => delta_inertia(dp, dk, &lk.frame),
            _ => leg_end_inertia(lp, lk, &armature),
        };
        if pose {
            // G = [−[r]×, 1]: I_vv = Λ, I_ωv = [r]× Λ, I_ωω = [r]× Λ [r]×ᵀ.
            let r = lk.arm;
            let col = |c: usize| [lam[0][c], lam[1][c], lam[2][c]];
            let p: [V<R>; 3] = core::array::from_fn(|c| cross(r, col(c))); // columns of [r]×Λ
            for i in 0..3 {
                for j in 0..3 {
                    out[3 + i][3 + j] = out[3 + i][3 + j] + lam[i][j];
                    out[i][3 + j] = out[i][3 + j] + p[j][i];
                }
            }
            // I_ωω = ([r]×Λ)[r]×ᵀ: row i of [r]×Λ crossed with r, as columns.
            for i in 0..3 {
                let row = [p[0][i], p[1][i], p[2][i]];
                let q = cross(r, row); // column i of [r]× (row)ᵀ … = ([r]×Λ[r]×ᵀ)[:, i]
                for j in 0..3 {
                    out[j][i] = out[j][i] + q[j];
                }
            }
        } else if let PlatformMotion::PlanarPose { .. } = motion {
            // G = [e_x, e_y, e_z × r] (v_end = v + ω × r): the upper triangle of Gᵀ Λ G.
            let r = lk.arm;
            let c2 = [-r[1], r[0], R::c(0.0)];
            let lc2: V<R> =
                core::array::from_fn(|i| lam[i][0] * c2[0] + lam[i][1] * c2[1] + lam[i][2] * c2[2]);
            out[0][0] = out[0][0] + lam[0][0];
            out[0][1] = out[0][1] + lam[0][1];
            out[1][1] = out[1][1] + lam[1][1];
            out[0][2] = out[0][2] + lc2[0];
            out[1][2] = out[1][2] + lc2[1];
            out[2][2] = out[2][2] + dot(c2, lc2);
        } else {
            // Orientation (u = ω), planar point (u = in-plane velocity) or translation (u = v;
            // a Schönflies carrier's v): I += Λ's block.
            for i in 0..n.min(3) {
                for j in 0..n.min(3) {
                    out[i][j] = out[i][j] + lam[i][j];
                }
            }
        }
    }
    if motion.translates() || motion.schoenflies() {
        let (mass, _, _) = plan.platform;
        for i in 0..n.min(3) {
            out[i][i] = out[i][i] + R::c(mass);
        }
        return out;
    }
    // The platform: ω columns e_j with mass-centre velocity e_j × r_c; v columns (pose) e_j.
    let (mass, com, inertia) = plan.platform;
    let cols = platform_columns(motion, n, mv(&pl.rot, cv::<R>(&com)));
    for i in 0..n {
        for j in i..n {
            let mut v = R::c(mass) * dot(cols[i].1, cols[j].1);
            if let (Some(a), Some(b)) = (cols[i].0, cols[j].0) {
                v = v + inertia_quad(&pl.rot, &inertia, a, b);
            }
            out[i][j] = out[i][j] + v;
        }
    }
    // Exactly symmetric: the upper triangle.
    for i in 0..n {
        for j in 0..i {
            out[i][j] = out[j][i];
        }
    }
    out
}

/// The end-point inertia `Λ = J_J⁻ᵀ M_J J_J⁻¹` (base frame, exactly symmetric) of a leg by the
/// generic route: the joint-space inertia `M_J` of its open chain, rotors included, then the
/// rows of `J_J⁻¹`.
fn leg_end_inertia<R: Real>(lp: &LegPlan, lk: &LegKin<R>, armature: &[Option<R>; 3]) -> M<R> {
    let z = R::c(0.0);
    let nj = lp.joints.len();
    // Joint-space inertia of the leg's open chain (bodies k ≥ max(i, j)).
    let mut mj = [[z; 3]; 3];
    for k in 0..nj {
        let (mass, _, inertia) = lp.bodies[k];
        let massless = mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0);
        if massless {
            continue;
        }
        let c = lk.com[k];
        // Twist columns of body k at its mass centre: (angular, linear).
        let cols: Vec<(Option<V<R>>, V<R>)> = (0..=k)
            .map(|j| match lp.joints[j] {
                JointKind::Revolute => (Some(lk.e[j]), cross(lk.e[j], sub(c, lk.o[j]))),
                JointKind::Prismatic => (None, lk.e[j]),
            })
            .collect();
        for i in 0..=k {
            for j in i..=k {
                let mut v = R::c(mass) * dot(cols[i].1, cols[j].1);
                if let (Some(a), Some(b)) = (cols[i].0, cols[j].0) {
                    v = v + inertia_quad(&lk.rot[k], &inertia, a, b);
                }
                mj[i][j] = mj[i][j] + v;
            }
        }
    }
    // The joints' rotors: `I_a` on the diagonal of the leg's joint-space inertia.
    for (k, a) in armature.iter().enumerate() {
        if let Some(a) = a {
            mj[k][k] = mj[k][k] + *a;
        }
    }
    for i in 0..3 {
        for j in 0..i {
            mj[i][j] = mj[j][i];
        }
    }
    // Λ = Wᵀ... with the rows of J⁻¹ in the base frame: Λ = Σ_ij M_J[i][j] w_i w_jᵀ.
    let w: [V<R>; 3] = [
        mv(&lk.frame, lk.jinv[0]),
        mv(&lk.frame, lk.jinv[1]),
        mv(&lk.frame, lk.jinv[2]),
    ];
    let b: [V<R>; 3] = core::array::from_fn(|i| {
        add(
            add(scale(mj[i][0], w[0]), scale(mj[i][1], w[1])),
            scale(mj[i][2], w[2]),
        )
    });
    let mut lam = [[z; 3]; 3];
    for r in 0..3 {
        for c in r..3 {
            lam[r][c] = w[0][r] * b[0][c] + w[1][r] * b[1][c] + w[2][r] * b[2][c];
            lam[c][r] = lam[r][c];
        }
    }
    lam
}
