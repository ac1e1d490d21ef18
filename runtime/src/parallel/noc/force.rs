//! Step 5: the generalized force `f = I u̇ + C u − γ` of the speeds `u`, one Newton–Euler
//! wrench per body (eq. 12) projected to the leg joints, the end point and `u`, the platform's
//! directly; and a payload's part of it.

use alloc::vec;
use alloc::vec::Vec;

use super::delta::delta_force;
use super::legs::LegKin;
use super::motion::BodyMotion;
use super::motion::leg_motion;
use super::plan::LegPlan;
use super::plan::Plan;
use super::pose::Platform;
use super::shaft::{shaft_force, shaft_motion};
use super::ups::ups_force;
use crate::algebra::{V, add, cross, cv, dot, euler, mtv, mv, scale, sub, zero3};
use crate::drive::{DriveInputs, drive_effort};
use crate::model::{JointKind, Vec3};
use crate::parallel::PlatformMotion;
use crate::payload::Payload;
use crate::scalar::Real;

/// The generalized force `f = I u̇ + C u − γ` (`γ` only when `gravity`) of the speeds `u`.
pub fn generalized_force<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    generalized_force_with(plan, pl, legs, u, ud, gravity, None)
}

/// [`generalized_force`] with the leg joints' drives from `drives` instead of the plan (closed-form
/// UPS legs then take the generic route, where the joint efforts are formed). A Schönflies
/// shaft keeps its plan's drives (`drives` holds three joints per leg; the generator refuses
/// run-time drives on such a platform).
pub fn generalized_force_with<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    u: &[R],
    ud: &[R],
    gravity: bool,
    drives: Option<&DriveInputs<R>>,
) -> Vec<R> {
    match &pl.parasitic {
        // A 1T2R platform: the 6-DOF pose's force of t = S u, ṫ = S u̇ + Ṡ u, then Sᵀ.
        Some(par) => {
            let (t, td) = (par.twist(u), par.twist_rate(u, ud));
            let f6 = force_in(
                plan,
                PlatformMotion::Pose,
                pl,
                legs,
                &t,
                &td,
                gravity,
                drives,
            );
            par.project(&f6)
        }
        None => force_in(plan, plan.motion, pl, legs, u, ud, gravity, drives),
    }
}

/// [`generalized_force_with`] for the speeds of `motion`.
#[allow(clippy::too_many_arguments)]
fn force_in<R: Real>(
    plan: &Plan,
    motion: PlatformMotion,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    u: &[R],
    ud: &[R],
    gravity: bool,
    drives: Option<&DriveInputs<R>>,
) -> Vec<R> {
    let dof = motion.dof();
    let mut f: Vec<R> = vec![R::c(0.0); dof];
    let g_world: Vec3 = if gravity { plan.gravity } else { [0.0; 3] };
    let planar = motion.translates();
    // Platform angular velocity and acceleration (a planar point or a translational platform
    // does not turn).
    let (w, wd) = angular(motion, u, ud);
    for (li, (lp, lk)) in plan.legs.iter().zip(legs).enumerate() {
        let n = lp.joints.len();
        // End velocity and acceleration (base frame).
        let (v_end, a_end) = end_motion(motion, lk, u, ud, (w, wd));
        if let Some(sp) = &lp.shaft {
            // The shaft to the tool: its bodies' twists are linear in [v; ω] (shaft.rs).
            let y = shaft_force(lp, sp, lk, (v_end, u[3]), (a_end, ud[3]), cv(&g_world));
            for i in 0..4 {
                f[i] = f[i] + y[i];
            }
            continue;
        }
        if let (Some(dp), Some(dk), None) = (&lp.delta, &lk.delta, drives) {
            // A translational platform's legs end at points moving with v: G = 1₃.
            let y = delta_force(dp, dk, &lk.frame, v_end, a_end, cv(&g_world));
            for i in 0..3 {
                f[i] = f[i] + y[i];
            }
            continue;
        }
        if let (Some(up), Some(uk), None) = (&lp.ups, &lk.ups, drives) {
            let y = ups_force(up, uk, v_end, a_end, cv(&g_world));
            if let PlatformMotion::Translation { .. } | PlatformMotion::Schoenflies { .. } = motion
            {
                for i in 0..3 {
                    f[i] = f[i] + y[i];
                }
                continue;
            }
            let m = cross(lk.arm, y);
            for i in 0..3 {
                f[i] = f[i] + m[i];
                f[3 + i] = f[3 + i] + y[i];
            }
            continue;
        }
        let (qd, qdd, bodies) = leg_motion(lp, lk, v_end, a_end);
        let g_l = mtv(&lk.frame, cv::<R>(&g_world));
        let mut tau = leg_efforts(lp, lk, &bodies, g_l);
        // The joints' drives, actuated and passive (the lecture's dissipative term δ and the
        // rotors' inertia), act at the joints beside the bodies' efforts.
        for k in 0..n {
            tau[k] = tau[k]
                + match drives {
                    Some(d) => d.effort(3 * li + k, qd[k], qdd[k]),
                    None => drive_effort(&lp.drives[k], qd[k], qdd[k]),
                };
        }
        // End force (or moment) y = J⁻ᵀ τ, to the base frame, then Gᵀ y.
        let y_l = add(
            add(scale(tau[0], lk.jinv[0]), scale(tau[1], lk.jinv[1])),
            scale(tau[2], lk.jinv[2]),
        );
        let y = mv(&lk.frame, y_l);
        match motion {
            PlatformMotion::Pose | PlatformMotion::HeaveTilt { .. } => {
                let m = cross(lk.arm, y);
                for i in 0..3 {
                    f[i] = f[i] + m[i];
                    f[3 + i] = f[3 + i] + y[i];
                }
            }
            PlatformMotion::Orientation { .. }
            | PlatformMotion::Translation { .. }
            | PlatformMotion::Schoenflies { .. } => {
                for i in 0..3 {
                    f[i] = f[i] + y[i];
                }
            }
            PlatformMotion::PlanarPoint { .. } => {
                for i in 0..2 {
                    f[i] = f[i] + y[i];
                }
            }
            // Sᵀ of the end point's wrench: (y_x, y_y, (arm × y)_z).
            PlatformMotion::PlanarPose { .. } => {
                f[0] = f[0] + y[0];
                f[1] = f[1] + y[1];
                f[2] = f[2] + (lk.arm[0] * y[1] - lk.arm[1] * y[0]);
            }
        }
    }
    // The platform.
    if motion.schoenflies() {
        // The carrier only translates: m (a − g) on v (the tool is the shaft's last body).
        let (mass, _, _) = plan.platform;
        for i in 0..3 {
            f[i] = f[i] + R::c(mass) * (ud[i] - R::c(g_world[i]));
        }
        return f;
    }
    if planar {
        // A point mass at P (planar), or a body that only translates: Newton's m (a − g), the
        // same for every point, so its mass centre and inertia do not enter.
        let (mass, _, _) = plan.platform;
        for i in 0..dof {
            f[i] = f[i] + R::c(mass) * (ud[i] - R::c(g_world[i]));
        }
        return f;
    }
    let (mass, com, inertia) = plan.platform;
    let r = mv(&pl.rot, cv::<R>(&com));
    let (a0, _) = linear(motion, ud, ud);
    let a = add(add(a0, cross(wd, r)), cross(w, cross(w, r)));
    let fp = scale(R::c(mass), sub(a, cv(&g_world)));
    let np = add(euler(&pl.rot, &inertia, w, wd), cross(r, fp));
    add_platform(motion, &mut f, np, fp);
    f
}

/// A leg's joint efforts `τ = T_Jᵀ w` from its bodies' Newton–Euler wrenches (about each mass
/// centre, eq. 12), accumulated from the last body inwards; `g_l` gravity in `L`.
pub(super) fn leg_efforts<R: Real>(
    lp: &LegPlan,
    lk: &LegKin<R>,
    bodies: &[BodyMotion<R>],
    g_l: V<R>,
) -> Vec<R> {
    let n = lp.joints.len();
    let mut force = zero3::<R>();
    let mut moment0 = zero3::<R>(); // about the origin of L
    let mut tau: Vec<R> = vec![R::c(0.0); n.max(3)];
    for k in (0..n).rev() {
        let (mass, _, inertia) = lp.bodies[k];
        let massless = mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0);
        if !massless {
            let c = lk.com[k];
            let m = &bodies[k];
            let a = m.accel_at(lk.o[k], c);
            let nk = euler(&lk.rot[k], &inertia, m.w, m.alpha);
            let fk = scale(R::c(mass), sub(a, g_l));
            force = add(force, fk);
            moment0 = add(moment0, add(nk, cross(c, fk)));
        }
        let mo = sub(moment0, cross(lk.o[k], force));
        tau[k] = match lp.joints[k] {
            JointKind::Revolute => dot(lk.e[k], mo),
            JointKind::Prismatic => dot(lk.e[k], force),
        };
    }
    tau
}

/// A leg's end-point velocity and acceleration (base frame) from `u`, `u̇` (the platform's
/// angular velocity for a spherical leg), with the platform's angular velocity and
/// acceleration `(w, wd)`.
pub(super) fn end_motion<R: Real>(
    motion: PlatformMotion,
    lk: &LegKin<R>,
    u: &[R],
    ud: &[R],
    (w, wd): (V<R>, V<R>),
) -> (V<R>, V<R>) {
    match motion {
        // (A 1T2R platform arrives here as a 6-DOF pose with its twist.)
        PlatformMotion::Pose
        | PlatformMotion::PlanarPose { .. }
        | PlatformMotion::HeaveTilt { .. } => {
            let (v, a) = linear(motion, u, ud);
            let v_end = add(v, cross(w, lk.arm));
            let a_end = add(add(a, cross(wd, lk.arm)), cross(w, cross(w, lk.arm)));
            (v_end, a_end)
        }
        PlatformMotion::Orientation { .. } => (w, wd),
        PlatformMotion::PlanarPoint { .. } => {
            let z = R::c(0.0);
            ([u[0], u[1], z], [ud[0], ud[1], z])
        }
        // t = S u, S = [0; 1₃]: every platform point moves with u (a Schönflies
        // carrier's points with u's first three).
        PlatformMotion::Translation { .. } | PlatformMotion::Schoenflies { .. } => {
            ([u[0], u[1], u[2]], [ud[0], ud[1], ud[2]])
        }
    }
}

/// Every leg's joint rates and accelerations `(θ̇, θ̈)` at `(u, u̇)` (a 1T2R platform's `u` as
/// its twist): the leg Jacobians' solves (`leg_motion`), a Schönflies shaft's closed form.
pub fn leg_rates<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    u: &[R],
    ud: &[R],
) -> Vec<(Vec<R>, Vec<R>)> {
    let (motion, u, ud) = match &pl.parasitic {
        Some(par) => (
            PlatformMotion::Pose,
            par.twist(u).to_vec(),
            par.twist_rate(u, ud).to_vec(),
        ),
        None => (plan.motion, u.to_vec(), ud.to_vec()),
    };
    let wwd = angular(motion, &u, &ud);
    plan.legs
        .iter()
        .zip(legs)
        .map(|(lp, lk)| {
            let (v_end, a_end) = end_motion(motion, lk, &u, &ud, wwd);
            let (qd, qdd, _) = match &lp.shaft {
                Some(sp) => shaft_motion(lp, sp, lk, (v_end, u[3]), (a_end, ud[3])),
                None => leg_motion(lp, lk, v_end, a_end),
            };
            (qd, qdd)
        })
        .collect()
}

/// The platform's angular velocity and acceleration from `u`, `u̇` (`ω = 0` for a platform that
/// only translates; `(0, 0, u₂)` for a planar pose).
pub(crate) fn angular<R: Real>(motion: PlatformMotion, u: &[R], ud: &[R]) -> (V<R>, V<R>) {
    let z = R::c(0.0);
    match motion {
        PlatformMotion::Pose
        | PlatformMotion::Orientation { .. }
        | PlatformMotion::HeaveTilt { .. } => ([u[0], u[1], u[2]], [ud[0], ud[1], ud[2]]),
        PlatformMotion::PlanarPose { .. } => ([z, z, u[2]], [z, z, ud[2]]),
        PlatformMotion::PlanarPoint { .. }
        | PlatformMotion::Translation { .. }
        | PlatformMotion::Schoenflies { .. } => (zero3(), zero3()),
    }
}

/// The velocity and acceleration of the platform frame's origin from `u`, `u̇` of a platform
/// that turns (`Pose`: `u[3..6]`; `PlanarPose`: `(u₀, u₁, 0)`; zero for an orientation
/// platform, whose origin is the fixed centre).
pub(crate) fn linear<R: Real>(motion: PlatformMotion, u: &[R], ud: &[R]) -> (V<R>, V<R>) {
    let z = R::c(0.0);
    match motion {
        PlatformMotion::Pose => ([u[3], u[4], u[5]], [ud[3], ud[4], ud[5]]),
        PlatformMotion::PlanarPose { .. } => ([u[0], u[1], z], [ud[0], ud[1], z]),
        _ => (zero3(), zero3()),
    }
}

/// Adds a turning platform body's Newton–Euler wrench (eq. 12; moment `np` about the platform
/// frame's origin, force `fp`) to `f` through its twist-shaping block: `Sᵀ [n; f]`.
fn add_platform<R: Real>(motion: PlatformMotion, f: &mut [R], np: V<R>, fp: V<R>) {
    match motion {
        PlatformMotion::PlanarPose { .. } => {
            f[0] = f[0] + fp[0];
            f[1] = f[1] + fp[1];
            f[2] = f[2] + np[2];
        }
        PlatformMotion::Pose => {
            for i in 0..3 {
                f[i] = f[i] + np[i];
                f[3 + i] = f[3 + i] + fp[i];
            }
        }
        _ => {
            for i in 0..3 {
                f[i] = f[i] + np[i];
            }
        }
    }
}

/// The payload's part of the generalized force `f = I u̇ + C u − γ` (`γ` only when `gravity`):
/// the platform's own term of [`generalized_force`] (Newton–Euler of one rigid body moving with
/// the platform, eq. 12, mapped by its twist-shaping block `T_Pᵀ`) with the payload's values.
pub fn payload_force<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    payload: &Payload<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    match &pl.parasitic {
        Some(par) => {
            let (t, td) = (par.twist(u), par.twist_rate(u, ud));
            par.project(&payload_in(
                plan,
                PlatformMotion::Pose,
                pl,
                payload,
                &t,
                &td,
                gravity,
            ))
        }
        None => payload_in(plan, plan.motion, pl, payload, u, ud, gravity),
    }
}

/// [`payload_force`] for the speeds of `motion`.
fn payload_in<R: Real>(
    plan: &Plan,
    motion: PlatformMotion,
    pl: &Platform<R>,
    payload: &Payload<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    let n = motion.dof();
    let mut f = vec![R::c(0.0); n];
    let g: V<R> = cv(&if gravity { plan.gravity } else { [0.0; 3] });
    if motion.translates() || motion.schoenflies() {
        // On a translating platform (a Schönflies carrier: the payload rides on the carrier).
        for i in 0..n.min(3) {
            f[i] = payload.mass * (ud[i] - g[i]);
        }
        return f;
    }
    let (w, wd) = angular(motion, u, ud);
    let (a0, _) = linear(motion, ud, ud);
    let r = mv(&pl.rot, payload.com);
    let a = add(add(a0, cross(wd, r)), cross(w, cross(w, r)));
    let fp = scale(payload.mass, sub(a, g));
    // Euler's equation in the platform frame, then to the base frame.
    let (wb, ab) = (mtv(&pl.rot, w), mtv(&pl.rot, wd));
    let nb = add(
        mv(&payload.inertia, ab),
        cross(wb, mv(&payload.inertia, wb)),
    );
    let np = add(mv(&pl.rot, nb), cross(r, fp));
    add_platform(motion, &mut f, np, fp);
    f
}
