//! Step 4: a leg's joint rates and accelerations through `J_J⁻¹`, and its bodies' motions by
//! the chain recursion (the lecture's eqs. 25–26, 33).

use alloc::vec::Vec;

use super::legs::LegKin;
use super::plan::LegPlan;
use crate::algebra::{V, add, cross, dot, mtv, scale, sub, zero3};
use crate::model::JointKind;
use crate::parallel::LegKind;
use crate::scalar::Real;

/// The motion of one leg body: angular velocity and acceleration, and the acceleration of its
/// material point at the joint point `o_k` (velocities of points are not needed: the
/// accelerations carry them in their `ω × (ω × r)` and Coriolis terms).
#[derive(Clone, Copy, Debug)]
pub struct BodyMotion<R> {
    /// Angular velocity.
    pub w: V<R>,
    /// Angular acceleration.
    pub alpha: V<R>,
    /// Acceleration of the material point at the joint point `o_k`.
    pub a: V<R>,
}

impl<R: Real> BodyMotion<R> {
    /// Acceleration of the body's material point at `x`, knowing it at `o`.
    pub fn accel_at(&self, o: V<R>, x: V<R>) -> V<R> {
        let r = sub(x, o);
        add(
            add(self.a, cross(self.alpha, r)),
            cross(self.w, cross(self.w, r)),
        )
    }
}

/// The leg's body motions by the chain recursion (the lecture's eqs. 25–26, 33): for joint `j`
/// with axis `e` through `o_j`, `ω_j = ω_{j−1} + θ̇ e`, `ω̇_j = ω̇_{j−1} + θ̈ e + θ̇ ω_{j−1} × e`
/// (R), and `a_j(o_j) = a_{j−1}(o_j) + θ̈ e + 2 θ̇ ω_{j−1} × e` (P). `qdd = None`: θ̈ = 0 (the
/// bias `J̇ θ̇`).
pub(super) fn chain<R: Real>(
    lp: &LegPlan,
    lk: &LegKin<R>,
    qd: &[R],
    qdd: Option<&[R]>,
) -> Vec<BodyMotion<R>> {
    let n = lp.joints.len();
    let mut out: Vec<BodyMotion<R>> = Vec::with_capacity(n);
    for j in 0..n {
        let (w0, alpha0, a0) = match out.last() {
            None => (zero3::<R>(), zero3::<R>(), zero3::<R>()),
            Some(p) => (p.w, p.alpha, p.accel_at(lk.o[j - 1], lk.o[j])),
        };
        let e = lk.e[j];
        let we = cross(w0, e);
        let qdd_e = match qdd {
            Some(a) => scale(a[j], e),
            None => zero3(),
        };
        out.push(match lp.joints[j] {
            JointKind::Revolute => BodyMotion {
                w: add(w0, scale(qd[j], e)),
                alpha: add(add(alpha0, qdd_e), scale(qd[j], we)),
                a: a0,
            },
            JointKind::Prismatic => BodyMotion {
                w: w0,
                alpha: alpha0,
                a: add(add(a0, qdd_e), scale(R::c(2.0) * qd[j], we)),
            },
        });
    }
    out
}

/// Steps 3–4 for one leg: joint rates `θ̇ = J⁻¹ v_end`, joint accelerations
/// `θ̈ = J⁻¹ (a_end − J̇ θ̇)` (the end's acceleration with `θ̈ = 0` first) and the leg bodies'
/// motions by the chain recursion, all in the leg frame `L`. `v_end`, `a_end`: the end point's
/// velocity and acceleration (or the platform's angular velocity and acceleration for a
/// spherical leg), base frame.
pub(crate) fn leg_motion<R: Real>(
    lp: &LegPlan,
    lk: &LegKin<R>,
    v_end: V<R>,
    a_end: V<R>,
) -> (Vec<R>, Vec<R>, Vec<BodyMotion<R>>) {
    let n = lp.joints.len();
    let v_l = mtv(&lk.frame, v_end);
    let a_l = mtv(&lk.frame, a_end);
    let qd: Vec<R> = (0..3).map(|i| dot(lk.jinv[i], v_l)).collect();
    let bias = chain(lp, lk, &qd, None);
    let last = n - 1;
    let bias_end = match lp.kind {
        LegKind::SphericalRr => {
            // ω_P = θ̇0 e0 + θ̇1 e1 + θ̇2 e_end; e_end turns with body 1.
            add(bias[last].alpha, scale(qd[2], cross(bias[last].w, lk.end)))
        }
        _ => bias[last].accel_at(lk.o[last], lk.end),
    };
    let rhs = sub(a_l, bias_end);
    let qdd: Vec<R> = (0..3).map(|i| dot(lk.jinv[i], rhs)).collect();
    let motion = chain(lp, lk, &qd, Some(&qdd));
    (qd, qdd, motion)
}
