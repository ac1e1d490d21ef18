//! Frames fixed to the platform (`[scene] frames` of a parallel mechanism): a frame's pose
//! from the platform's, the map `J(x)` of the speeds `u` to its twist `[ω; v]` (angular first,
//! base-frame components, `v` the velocity of the frame's origin) and `J̇ u`, so that the
//! frame's classical acceleration `[ω̇; p̈]` is `J u̇ + J̇ u`.
//!
//! The platform's own twist from `u` is `[ω; v_O]` of its frame's origin `O`: `u` itself, or
//! its parts, for every motion but the 1T2R platform's, whose `t = S(x) u` gains `Ṡ u`
//! ([`super::Parasitic`]). A frame at `ρ = R p` from `O` (`p` its origin in the platform frame)
//! moves with `v = v_O + ω × ρ` and accelerates with `a_O + ω̇ × ρ + ω × (ω × ρ)`.

use alloc::vec::Vec;

use super::pose::Platform;
use crate::algebra::{M, V, cm, cross, cv, mv};
use crate::model::Transform;
use crate::parallel::PlatformMotion;
use crate::scalar::Real;

/// The frame's pose: rotation base ← frame and its origin (base frame).
pub fn frame_pose<R: Real>(pl: &Platform<R>, placement: &Transform) -> (M<R>, V<R>) {
    let c = cm::<R>(&placement.rotation);
    let rot = core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            pl.rot[i][0] * c[0][j] + pl.rot[i][1] * c[1][j] + pl.rot[i][2] * c[2][j]
        })
    });
    let rho = arm(pl, placement);
    (rot, core::array::from_fn(|i| pl.origin[i] + rho[i]))
}

/// The platform's twist `[ω; v_O]` from `u`, and, with `rate`, its acceleration at `u̇ = 0`
/// (`Ṡ u` of a 1T2R platform; zero for the others, whose `u̇` is the acceleration).
fn platform_twist<R: Real>(
    motion: PlatformMotion,
    pl: &Platform<R>,
    u: &[R],
    rate: bool,
) -> [R; 6] {
    let z = R::c(0.0);
    if let Some(par) = &pl.parasitic {
        return if rate {
            par.twist_rate(u, &[z, z, z])
        } else {
            par.twist(u)
        };
    }
    if rate {
        return [z; 6];
    }
    match motion {
        PlatformMotion::Pose => core::array::from_fn(|i| u[i]),
        PlatformMotion::Orientation { .. } => [u[0], u[1], u[2], z, z, z],
        PlatformMotion::PlanarPoint { .. } => [z, z, z, u[0], u[1], z],
        PlatformMotion::PlanarPose { .. } => [z, z, u[2], u[0], u[1], z],
        // A Schönflies platform's frames ride on the carrier, which translates (`u[3]` turns
        // the tool).
        PlatformMotion::Translation { .. }
        | PlatformMotion::Schoenflies { .. }
        | PlatformMotion::HeaveTilt { .. } => [z, z, z, u[0], u[1], u[2]],
    }
}

/// `ρ = R p`, the frame's origin from the platform frame's (base components).
fn arm<R: Real>(pl: &Platform<R>, placement: &Transform) -> V<R> {
    mv(&pl.rot, cv::<R>(&placement.translation))
}

/// The frame's twist `[ω; v]` for the speeds `u`.
pub fn frame_twist<R: Real>(
    motion: PlatformMotion,
    pl: &Platform<R>,
    placement: &Transform,
    u: &[R],
) -> [R; 6] {
    let t = platform_twist(motion, pl, u, false);
    let w = [t[0], t[1], t[2]];
    let wr = cross(w, arm(pl, placement));
    [t[0], t[1], t[2], t[3] + wr[0], t[4] + wr[1], t[5] + wr[2]]
}

/// `J`, 6 × n row-major (rows `ω` then `v`): the frame's twist per unit speed.
pub fn frame_jacobian<R: Real>(
    motion: PlatformMotion,
    pl: &Platform<R>,
    placement: &Transform,
) -> Vec<R> {
    let n = motion.dof();
    let cols: Vec<[R; 6]> = (0..n)
        .map(|j| {
            let u: Vec<R> = (0..n)
                .map(|k| R::c(if k == j { 1.0 } else { 0.0 }))
                .collect();
            frame_twist(motion, pl, placement, &u)
        })
        .collect();
    (0..6 * n).map(|k| cols[k % n][k / n]).collect()
}

/// `J̇ u`: the frame's classical acceleration `[ω̇; p̈]` at `u̇ = 0`.
pub fn frame_jacobian_dot_u<R: Real>(
    motion: PlatformMotion,
    pl: &Platform<R>,
    placement: &Transform,
    u: &[R],
) -> [R; 6] {
    let t = platform_twist(motion, pl, u, false);
    let b = platform_twist(motion, pl, u, true);
    let (w, wd) = ([t[0], t[1], t[2]], [b[0], b[1], b[2]]);
    let rho = arm(pl, placement);
    let a = cross(wd, rho);
    let c = cross(w, cross(w, rho));
    [
        b[0],
        b[1],
        b[2],
        b[3] + a[0] + c[0],
        b[4] + a[1] + c[1],
        b[5] + a[2] + c[2],
    ]
}
