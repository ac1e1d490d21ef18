//! Steps 2–3 for each leg: [`leg_kinematics`] solves its inverse kinematics in closed form
//! (or by `generic_leg`'s Newton steps), poses its bodies by the product of exponentials and
//! inverts its Jacobian `J_J` by the adjugate, checked against [`LEG_TOLERANCE`] ([`LegKin`]);
//! [`kinematics`] and [`positions`] do it for every leg at `x`; the legs' actuated positions
//! and the actuation matrix `A` (`q̇ = A u`, the actuated rows of their `J_J⁻¹ G`; the
//! lecture's eqs. 66–72).

use alloc::vec;
use alloc::vec::Vec;

use super::LEG_TOLERANCE;
use super::constraint::check_constraint;
use super::delta::{DeltaKin, delta_kin};
use super::generic_leg::generic_ik;
use super::plan::{LegPlan, Plan, cross3, dot3, sub3};
use super::pose::{Platform, platform};
use super::shaft::{shaft_ik, shaft_row};
use super::subproblems::{one_axis, rus_crank, two_axes};
use super::ups::{UpsKin, UpsPlan};
use crate::algebra::{M, V, add, cm, cross, cv, dot, ident, mm, mtv, mv, rot, scale, sub, zero3};
use crate::model::JointKind;
use crate::parallel::{LegKind, PlatformMotion};
use crate::scalar::{Real, Singular, Site};

/// A joint's position: `(sin, cos)` for a revolute, the displacement for a prismatic joint.
#[derive(Clone, Copy, Debug)]
pub enum JointPos<R> {
    /// Revolute.
    R(R, R),
    /// Prismatic.
    P(R),
}

/// The kinematic state of one leg at a configuration, resolved in its frame `L`.
#[derive(Clone, Debug)]
pub struct LegKin<R> {
    /// Joint positions.
    pub q: Vec<JointPos<R>>,
    /// Current joint axes.
    pub e: Vec<V<R>>,
    /// Current joint points.
    pub o: Vec<V<R>>,
    /// Body rotations (body → `L`).
    pub rot: Vec<M<R>>,
    /// Body mass centres.
    pub com: Vec<V<R>>,
    /// End point (spherical end) or end axis (revolute end).
    pub end: V<R>,
    /// Rows of `J_J⁻¹` (the adjugate rows divided by the determinant).
    pub jinv: [V<R>; 3],
    /// Base-frame rotation of `L` (constant).
    pub frame: M<R>,
    /// The end point relative to the platform origin, base frame (spherical end; zero else).
    pub arm: V<R>,
    /// The closed-form UPS leg's frame (when [`LegPlan::ups`] is set).
    pub ups: Option<UpsKin<R>>,
    /// The closed-form Delta leg's configuration (when [`LegPlan::delta`] is set).
    pub delta: Option<DeltaKin<R>>,
}

/// Inverse kinematics, pose and Jacobian of leg `k` for the platform pose `pl`. Each test is
/// made where its value is used: the Jacobian's (`Site::Leg`) only with `jacobian` (positions
/// alone do not need it), and a closed-form UPS leg's by its own leg vector (reach: `ρ > 0`;
/// the U's singularity: `|e₀ × s| > 0`), since nothing it returns uses its U angles or `J⁻¹`.
pub fn leg_kinematics<R: Real>(
    plan: &Plan,
    k: usize,
    pl: &Platform<R>,
    jacobian: bool,
) -> Result<LegKin<R>, Singular> {
    let lp = &plan.legs[k];
    let fr: M<R> = cm(&lp.frame.rotation);
    let ft: V<R> = cv(&lp.frame.translation);
    // The end target in L.
    let (target, arm, end_base) = end_target(lp, pl, &fr, ft);
    // Closed-form inverse kinematics.
    let (q, ups) = match (&lp.shaft, pl.tool) {
        (Some(sp), Some(tool)) => (shaft_ik(lp, sp, k, target, tool)?, None),
        _ => closed_form_ik(lp, k, &fr, target, end_base)?,
    };
    // Product of exponentials from the home configuration.
    let chain = chain_pose(lp, &q);
    let end = match lp.kind {
        LegKind::SphericalRr => target,
        _ => add(mv(&chain.g, cv(&lp.end_home)), chain.t),
    };
    let jinv = jacobian_inverse(lp, k, &chain.e, &chain.o, end, jacobian)?;
    let delta = match (&lp.delta, q[0]) {
        (Some(dp), JointPos::R(s, c)) => Some(delta_kin(dp, k, (s, c), target, jacobian)?),
        _ => None,
    };
    Ok(LegKin {
        q,
        e: chain.e,
        o: chain.o,
        rot: chain.rots,
        com: chain.coms,
        end,
        jinv,
        frame: fr,
        arm,
        ups,
        delta,
    })
}

/// The end target in `L`, the end point relative to the platform origin (base frame) and the
/// end point in the base frame, as each leg kind needs them.
fn end_target<R: Real>(lp: &LegPlan, pl: &Platform<R>, fr: &M<R>, ft: V<R>) -> (V<R>, V<R>, V<R>) {
    match lp.kind {
        LegKind::SphericalRr => {
            let axis = mv(&pl.rot, cv(&lp.end_platform));
            (mtv(fr, axis), zero3(), zero3())
        }
        LegKind::Ups => {
            // The target is not needed: the leg vector is formed in the base frame.
            let arm = mv(&pl.rot, cv(&lp.end_platform));
            (zero3(), arm, add(pl.origin, arm))
        }
        _ => {
            let arm = mv(&pl.rot, cv(&lp.end_platform));
            let a = add(pl.origin, arm);
            (mtv(fr, sub(a, ft)), arm, a)
        }
    }
}

/// A leg's joint positions with the closed-form UPS leg's frame.
type LegIk<R> = (Vec<JointPos<R>>, Option<UpsKin<R>>);

/// The joint positions of leg `k` by its kind's closed form (or `generic_leg`'s Newton steps),
/// with the closed-form UPS leg's frame.
fn closed_form_ik<R: Real>(
    lp: &LegPlan,
    k: usize,
    fr: &M<R>,
    target: V<R>,
    end_base: V<R>,
) -> Result<LegIk<R>, Singular> {
    match lp.kind {
        LegKind::Ups => ups_ik(lp, k, fr, end_base),
        LegKind::Pus => Ok((pus_ik(lp, k, target)?, None)),
        LegKind::Rus => Ok((rus_ik(lp, k, target)?, None)),
        LegKind::PlanarRr => Ok((planar_rr_ik(lp, k, target)?, None)),
        LegKind::PlanarPr => Ok((planar_pr_ik(lp, k, target)?, None)),
        LegKind::PlanarRp => Ok((planar_rp_ik(lp, k, target)?, None)),
        LegKind::SphericalRr => Ok((spherical_rr_ik(lp, k, target)?, None)),
        // (A shaft has its own closed form, which needs the tool's angle: `shaft_ik`; without
        // it, Newton's steps would not know the motor's angle either.)
        LegKind::Generic | LegKind::Shaft => Ok((generic_ik(lp, target, k)?, None)),
    }
}

/// UPS: the U angles and the prismatic displacement from the leg vector (base frame).
fn ups_ik<R: Real>(
    lp: &LegPlan,
    k: usize,
    fr: &M<R>,
    end_base: V<R>,
) -> Result<LegIk<R>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    let mut ups = None;
    // The leg vector U centre → S centre in the base frame (the same as in L, rotated).
    let r = sub(end_base, cv(&lp.frame.apply(&lp.u_centre)));
    let rr = dot(r, r);
    let rr = R::check(rr, R::c(0.0), R::c(1.0), Site::Reach(k), false)?;
    let rho = rr.sqrt();
    let d = R::c(lp.sigma_first) * (rho - R::c(lp.length));
    let inv_rho = R::c(1.0) / rho;
    let s = scale(inv_rho, r);
    if let Some(up) = &lp.ups {
        ups = Some(ups_frame(lp, up, k, rho, inv_rho, s)?);
    }
    let dir = mtv(fr, s);
    let p = sub3(&lp.end_home, &lp.u_centre);
    let p = [p[0] / lp.length, p[1] / lp.length, p[2] / lp.length];
    let closed = lp.ups.is_some();
    let [a, b] = two_axes(
        &lp.axes[0],
        &lp.axes[1],
        cv(&p),
        dir,
        lp.sigma_u,
        k,
        !closed,
    )?;
    q.push(JointPos::R(a.0, a.1));
    q.push(JointPos::R(b.0, b.1));
    q.push(JointPos::P(d));
    Ok((q, ups))
}

/// The closed-form UPS leg's frame (`UpsPlan`): c = e₀·s, d² = |e₀ × s|² (= 1 − c², formed
/// so that it keeps its relative accuracy near the U's singularity d → 0, where e₀ ∥ s; the
/// same test as `two_axes`' γ² ≤ 0).
fn ups_frame<R: Real>(
    lp: &LegPlan,
    up: &UpsPlan,
    k: usize,
    rho: R,
    inv_rho: R,
    s: V<R>,
) -> Result<UpsKin<R>, Singular> {
    let e0 = cv::<R>(&up.e0);
    let c = dot(e0, s);
    let m = cross(e0, s);
    let d2 = R::check(dot(m, m), R::c(0.0), R::c(1.0), Site::Leg(k), false)?;
    let dd = R::c(lp.sigma_u) * d2.sqrt();
    let inv_d = R::c(1.0) / dd;
    Ok(UpsKin {
        rho,
        inv_rho,
        cot: c * inv_d,
        inv_d,
        t: scale(inv_d, sub(e0, scale(c, s))),
        e1: scale(-inv_d, m),
        s,
    })
}

/// A first prismatic joint (PUS, planar PR): the slider's displacement `s` that puts the
/// elbow `u` (the U centre or the elbow revolute) at the fixed length from `target` (its line
/// meets the sphere about `target`; the branch of home), and `u`. Out of reach: `Site::Reach`.
fn slider_to_sphere<R: Real>(lp: &LegPlan, k: usize, target: V<R>) -> Result<(R, V<R>), Singular> {
    let e0 = lp.axes[0];
    let dd = sub(target, cv(&lp.u_centre));
    let t = dot(cv(&e0), dd);
    let disc = t * t - dot(dd, dd) + R::c(lp.length * lp.length);
    let disc = R::check(
        disc,
        R::c(0.0),
        R::c(lp.length * lp.length),
        Site::Reach(k),
        false,
    )?;
    let s = t - R::c(lp.sigma_first) * disc.sqrt();
    Ok((s, add(cv(&lp.u_centre), scale(s, cv(&e0)))))
}

/// A first revolute joint (RUS, planar RR): the crank's `(sin, cos)` that puts the elbow at the
/// fixed length from `target`, and the direction elbow → `target` in the crank's home frame.
fn crank_to_sphere<R: Real>(
    lp: &LegPlan,
    k: usize,
    target: V<R>,
) -> Result<((R, R), V<R>), Singular> {
    let (s0, c0) = rus_crank(lp, target, k)?;
    let r0 = rot(&lp.axes[0], s0, c0);
    let o0 = cv(&lp.points[0]);
    let u = add(o0, mv(&r0, sub(cv(&lp.u_centre), o0)));
    Ok(((s0, c0), mtv(&r0, sub(target, u))))
}

/// PUS: the slider's displacement on the rod-length sphere about `target`, then the U angles.
fn pus_ik<R: Real>(lp: &LegPlan, k: usize, target: V<R>) -> Result<Vec<JointPos<R>>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    let (s, u) = slider_to_sphere(lp, k, target)?;
    let qv = sub(target, u);
    let p = sub3(&lp.end_home, &lp.u_centre);
    let [a, b] = two_axes(&lp.axes[1], &lp.axes[2], cv(&p), qv, lp.sigma_u, k, true)?;
    q.push(JointPos::P(s));
    q.push(JointPos::R(a.0, a.1));
    q.push(JointPos::R(b.0, b.1));
    Ok(q)
}

/// RUS: the crank angle, then the U angles of the rod in the crank's home frame.
fn rus_ik<R: Real>(lp: &LegPlan, k: usize, target: V<R>) -> Result<Vec<JointPos<R>>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    // The rod direction in the crank's home frame.
    let ((s0, c0), qv) = crank_to_sphere(lp, k, target)?;
    let p = sub3(&lp.end_home, &lp.u_centre);
    // A Delta leg's U angles serve only the positions (its closed form does not use them, and
    // its own test covers the leg): unchecked.
    let check = lp.delta.is_none();
    let [a, b] = two_axes(&lp.axes[1], &lp.axes[2], cv(&p), qv, lp.sigma_u, k, check)?;
    q.push(JointPos::R(s0, c0));
    q.push(JointPos::R(a.0, a.1));
    q.push(JointPos::R(b.0, b.1));
    Ok(q)
}

/// Planar RR: the proximal angle, then the distal one in the proximal link's home frame.
fn planar_rr_ik<R: Real>(
    lp: &LegPlan,
    k: usize,
    target: V<R>,
) -> Result<Vec<JointPos<R>>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    // The distal link's direction in the proximal link's home frame.
    let ((s0, c0), qv) = crank_to_sphere(lp, k, target)?;
    let p = sub3(&lp.end_home, &lp.u_centre);
    let (s1, c1) = one_axis(&lp.axes[1], cv(&p), qv);
    q.push(JointPos::R(s0, c0));
    q.push(JointPos::R(s1, c1));
    Ok(q)
}

/// Planar PR: the slider's displacement that puts the elbow at the rod length from `target`
/// (the slider's line meets the circle about `target`; the branch of home), then the rod's
/// angle about the elbow.
fn planar_pr_ik<R: Real>(
    lp: &LegPlan,
    k: usize,
    target: V<R>,
) -> Result<Vec<JointPos<R>>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    let (s, u) = slider_to_sphere(lp, k, target)?;
    let p = sub3(&lp.end_home, &lp.u_centre);
    let (s1, c1) = one_axis(&lp.axes[1], cv(&p), sub(target, u));
    q.push(JointPos::P(s));
    q.push(JointPos::R(s1, c1));
    Ok(q)
}

/// Planar RP: the angle and the length of the line from the revolute axis to `target` (in the
/// plane); `Site::Leg` when `target` is on the axis (the angle is undefined there).
fn planar_rp_ik<R: Real>(
    lp: &LegPlan,
    k: usize,
    target: V<R>,
) -> Result<Vec<JointPos<R>>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    let e0 = lp.axes[0];
    let d = sub(target, cv(&lp.points[0]));
    let d = sub(d, scale(dot(cv(&e0), d), cv(&e0)));
    let l2 = lp.length * lp.length;
    let rr = R::check(dot(d, d), R::c(0.0), R::c(l2), Site::Leg(k), false)?;
    let rho = rr.sqrt();
    // The home line h (length `lp.length`) turned about e0 onto d.
    let h = sub3(&lp.end_home, &lp.points[0]);
    let hz = dot3(&e0, &h);
    let h = [h[0] - hz * e0[0], h[1] - hz * e0[1], h[2] - hz * e0[2]];
    let inv = R::c(1.0) / (R::c(lp.length) * rho);
    let s0 = dot(cv(&cross3(&e0, &h)), d) * inv;
    let c0 = dot(cv(&h), d) * inv;
    q.push(JointPos::R(s0, c0));
    q.push(JointPos::P(R::c(lp.sigma_first) * (rho - R::c(lp.length))));
    Ok(q)
}

/// Spherical RR: the two angles that turn the end axis at home onto `target`.
fn spherical_rr_ik<R: Real>(
    lp: &LegPlan,
    k: usize,
    target: V<R>,
) -> Result<Vec<JointPos<R>>, Singular> {
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(lp.joints.len());
    let [a, b] = two_axes(
        &lp.axes[0],
        &lp.axes[1],
        cv(&lp.end_home),
        target,
        lp.sigma_u,
        k,
        true,
    )?;
    q.push(JointPos::R(a.0, a.1));
    q.push(JointPos::R(b.0, b.1));
    Ok(q)
}

/// A leg's bodies posed by the product of exponentials.
struct Chain<R> {
    /// The rotation `G` of the last joint's displacement.
    g: M<R>,
    /// The translation `t` of the last joint's displacement.
    t: V<R>,
    /// Current joint axes.
    e: Vec<V<R>>,
    /// Current joint points.
    o: Vec<V<R>>,
    /// Body rotations (body → `L`).
    rots: Vec<M<R>>,
    /// Body mass centres.
    coms: Vec<V<R>>,
}

/// Product of exponentials from the home configuration: D = Π exp(ξ_j θ_j), x ↦ G x + t.
fn chain_pose<R: Real>(lp: &LegPlan, q: &[JointPos<R>]) -> Chain<R> {
    let n = lp.joints.len();
    let mut g: M<R> = ident();
    let mut t: V<R> = zero3();
    let mut e = Vec::with_capacity(n);
    let mut o = Vec::with_capacity(n);
    let mut rots = Vec::with_capacity(n);
    let mut coms = Vec::with_capacity(n);
    for j in 0..n {
        let ej = mv(&g, cv(&lp.axes[j]));
        let oj = add(mv(&g, cv(&lp.points[j])), t);
        match q[j] {
            JointPos::R(s, c) => {
                g = mm(&g, &rot(&lp.axes[j], s, c));
                t = sub(oj, mv(&g, cv(&lp.points[j])));
            }
            JointPos::P(d) => {
                t = add(t, scale(d, ej));
            }
        }
        let h = &lp.homes[j];
        rots.push(mm(&g, &cm(&h.rotation)));
        let (_, com, _) = lp.bodies[j];
        let ch = h.apply(&com);
        coms.push(add(mv(&g, cv(&ch)), t));
        e.push(ej);
        o.push(oj);
    }
    Chain {
        g,
        t,
        e,
        o,
        rots,
        coms,
    }
}

/// The leg Jacobian's columns (`J_J`, 3 × 3) from the joints' axes `e` and points `o` and
/// the end point `end`, all in one frame, and which of them are moment arms (a revolute axis
/// crossed with the way to the end point; the others are unit axes, of constant norm).
fn jacobian_columns<R: Real>(
    lp: &LegPlan,
    e: &[V<R>],
    o: &[V<R>],
    end: V<R>,
) -> (Vec<V<R>>, [bool; 3]) {
    let n = lp.joints.len();
    let arm = |j: usize, p: V<R>| cross(e[j], sub(p, o[j]));
    match lp.kind {
        LegKind::SphericalRr => (vec![e[0], e[1], end], [false; 3]),
        // A virtual third column along the plane normal keeps J_J 3 × 3; its rate is zero
        // because the end point moves in the plane.
        LegKind::PlanarRr => (vec![arm(0, end), arm(1, end), e[0]], [true, true, false]),
        // The same virtual column (the revolute's axis is the plane normal).
        LegKind::PlanarPr => (vec![e[0], arm(1, end), e[1]], [false, true, false]),
        LegKind::PlanarRp => (vec![arm(0, end), e[1], e[0]], [true, false, false]),
        // A shaft: the tube's U and prismatic joint at the second U's centre T = o₄ (the
        // motor's column is known from ω; shaft.rs).
        LegKind::Shaft => (vec![arm(1, o[4]), arm(2, o[4]), e[3]], [true, true, false]),
        _ => {
            let revolute = |j: usize| lp.joints.get(j) == Some(&JointKind::Revolute);
            let cols = (0..n)
                .map(|j| if revolute(j) { arm(j, end) } else { e[j] })
                .collect();
            (cols, [revolute(0), revolute(1), revolute(2)])
        }
    }
}

/// [`LegPlan::column_home`]: the squared norms at home of the leg Jacobian's moment-arm
/// columns (0 for its unit-axis columns, which need no floor).
pub(super) fn home_column_norms(lp: &LegPlan) -> [f64; 3] {
    let (cols, arms) = jacobian_columns(lp, &lp.axes, &lp.points, lp.end_home);
    core::array::from_fn(|k| if arms[k] { dot(cols[k], cols[k]) } else { 0.0 })
}

/// The rows of `J_J⁻¹` from the Jacobian columns' adjugate, the determinant tested (with
/// `jacobian`, and not for a closed-form UPS leg).
fn jacobian_inverse<R: Real>(
    lp: &LegPlan,
    k: usize,
    e: &[V<R>],
    o: &[V<R>],
    end: V<R>,
    jacobian: bool,
) -> Result<[V<R>; 3], Singular> {
    // Jacobian columns and their adjugate.
    let (cols, _) = jacobian_columns(lp, e, o, end);
    let r0 = cross(cols[1], cols[2]);
    let r1 = cross(cols[2], cols[0]);
    let r2 = cross(cols[0], cols[1]);
    let det = dot(cols[0], r0);
    // Each column's squared norm, a moment arm's at least its norm at home
    // (`LegPlan::column_home`).
    let norm2 = |k: usize| {
        let n = dot(cols[k], cols[k]);
        match lp.column_home[k] {
            0.0 => n,
            f => R::select_abs_gt(n, R::c(f), n, R::c(f)),
        }
    };
    let hn = (norm2(0) * norm2(1) * norm2(2)).sqrt();
    // (A shaft's columns are orthogonal: its own test is the U's gimbal lock, in `shaft_ik`.)
    let det = if jacobian && lp.ups.is_none() && lp.delta.is_none() && lp.shaft.is_none() {
        R::check(
            det,
            R::c(R::tolerance(LEG_TOLERANCE)) * hn,
            hn,
            Site::Leg(k),
            true,
        )?
    } else {
        det
    };
    let id = R::c(1.0) / det;
    Ok([scale(id, r0), scale(id, r1), scale(id, r2)])
}

/// The legs' kinematics at `x`, their Jacobians tested and, for a platform held in rotation by
/// its legs, their constraint couples (`Site::Constraint`).
pub fn kinematics<R: Real>(
    plan: &Plan,
    x: &[R],
) -> Result<(Platform<R>, Vec<LegKin<R>>), Singular> {
    kinematics_of(plan, x, true)
}

/// The legs' joint positions at `x`: [`kinematics`] without the Jacobians' tests (their
/// `J⁻¹` is not to be used).
pub fn positions<R: Real>(plan: &Plan, x: &[R]) -> Result<(Platform<R>, Vec<LegKin<R>>), Singular> {
    kinematics_of(plan, x, false)
}

fn kinematics_of<R: Real>(
    plan: &Plan,
    x: &[R],
    jacobian: bool,
) -> Result<(Platform<R>, Vec<LegKin<R>>), Singular> {
    let pl = platform(plan, x)?;
    let mut legs = Vec::with_capacity(plan.legs.len());
    for k in 0..plan.legs.len() {
        legs.push(leg_kinematics(plan, k, &pl, jacobian)?);
    }
    // With the Jacobians (every velocity-level function), the legs' constraint couples must
    // still hold the rotation the coordinates fix.
    if jacobian {
        check_constraint(plan, &legs)?;
    }
    Ok((pl, legs))
}

/// Actuated joint positions (rad or m) of the legs, in leg order: each leg's coordinate at
/// home ([`LegPlan::actuated_home`], 0 unless the spec says) plus the joint's displacement from
/// its home frame.
pub fn actuated_positions<R: Real>(plan: &Plan, legs: &[LegKin<R>]) -> Vec<R> {
    plan.legs
        .iter()
        .zip(legs)
        .map(|(lp, lk)| {
            let q = match lk.q[lp.actuated] {
                JointPos::R(s, c) => s.atan2(c),
                JointPos::P(d) => d,
            };
            if lp.actuated_home == 0.0 {
                q
            } else {
                q + R::c(lp.actuated_home)
            }
        })
        .collect()
}

/// The actuation matrix `A` (`q̇ = A u`), row-major `DOF × DOF` (a 1T2R platform's is the
/// 6-DOF pose's rows times its twist map: `A = A₆ S`).
pub fn actuation_matrix<R: Real>(plan: &Plan, pl: &Platform<R>, legs: &[LegKin<R>]) -> Vec<Vec<R>> {
    let motion = match pl.parasitic {
        Some(_) => PlatformMotion::Pose,
        None => plan.motion,
    };
    let rows: Vec<Vec<R>> = plan
        .legs
        .iter()
        .zip(legs)
        .map(|(lp, lk)| {
            // q̇_a = (row_a of J⁻¹) · Lᵀ v_end = g · v_end with g = L · row_a; for a
            // closed-form UPS leg the prismatic rate is ±ρ̇ = ±s·v_end.
            // a Delta leg's crank rate is q̇ = (d/s)·v_end.
            if let Some(sp) = &lp.shaft {
                return shaft_row(lp, sp, lk);
            }
            let g = match (&lk.ups, &lk.delta) {
                (Some(uk), _) => scale(R::c(lp.sigma_first), uk.s),
                (None, Some(dk)) => mv(&lk.frame, scale(dk.inv_s, dk.d)),
                (None, None) => mv(&lk.frame, lk.jinv[lp.actuated]),
            };
            match motion {
                PlatformMotion::Pose | PlatformMotion::HeaveTilt { .. } => {
                    let m = cross(lk.arm, g);
                    vec![m[0], m[1], m[2], g[0], g[1], g[2]]
                }
                PlatformMotion::Orientation { .. } => vec![g[0], g[1], g[2]],
                PlatformMotion::PlanarPoint { .. } => vec![g[0], g[1]],
                PlatformMotion::Translation { .. } => vec![g[0], g[1], g[2]],
                // A Delta leg of a Schönflies carrier: the tool's ω does not move it.
                PlatformMotion::Schoenflies { .. } => vec![g[0], g[1], g[2], R::c(0.0)],
                // v_end = v + ω × arm with ω = (0, 0, u₂): q̇ = g·v + (arm × g)_z ω.
                PlatformMotion::PlanarPose { .. } => {
                    vec![g[0], g[1], lk.arm[0] * g[1] - lk.arm[1] * g[0]]
                }
            }
        })
        .collect();
    match &pl.parasitic {
        Some(par) => rows
            .iter()
            .map(|row| {
                (0..3)
                    .map(|j| {
                        let mut a = R::c(0.0);
                        for k in 0..6 {
                            a = a + row[k] * par.s[k][j];
                        }
                        a
                    })
                    .collect()
            })
            .collect(),
        None => rows,
    }
}
