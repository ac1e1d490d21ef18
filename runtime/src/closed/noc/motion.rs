//! The bodies' motions ([`BodyMotion`]) by the tree recursion (the lecture's eqs. 25–26, 33).

use alloc::vec::Vec;

use super::plan::Plan;
use super::tree::Kin;
use crate::algebra::{V, add, cross, scale, sub, zero3};
use crate::model::JointKind;
use crate::scalar::Real;

/// A body's motion: angular velocity `w` and acceleration `alpha`, the velocity `v` and
/// acceleration `a` of its material point at its joint point `o`.
#[derive(Clone, Copy, Debug)]
pub struct BodyMotion<R> {
    /// Angular velocity.
    pub w: V<R>,
    /// Angular acceleration.
    pub alpha: V<R>,
    /// Velocity of the material point at `o`.
    pub v: V<R>,
    /// Acceleration of the material point at `o`.
    pub a: V<R>,
}

impl<R: Real> BodyMotion<R> {
    fn at_rest() -> Self {
        BodyMotion {
            w: zero3(),
            alpha: zero3(),
            v: zero3(),
            a: zero3(),
        }
    }
    /// Velocity of the material point at `x`, knowing the motion at `o`.
    fn vel_at(&self, o: V<R>, x: V<R>) -> V<R> {
        add(self.v, cross(self.w, sub(x, o)))
    }
    /// Acceleration of the material point at `x`.
    pub(super) fn accel_at(&self, o: V<R>, x: V<R>) -> V<R> {
        self.accel_rel(sub(x, o))
    }
    /// Velocity of the material point at `o + r`.
    pub(super) fn vel_rel(&self, r: V<R>) -> V<R> {
        add(self.v, cross(self.w, r))
    }
    /// Acceleration of the material point at `o + r`.
    pub(super) fn accel_rel(&self, r: V<R>) -> V<R> {
        add(
            add(self.a, cross(self.alpha, r)),
            cross(self.w, cross(self.w, r)),
        )
    }
}

/// Body motions by the tree recursion (the lecture's eqs. 25–26, 33): `ω = ω_p + ẋ e`,
/// `ω̇ = ω̇_p + ẍ e + ẋ ω_p × e` (R); `a(o) = a_p(o) + ẍ e + 2 ẋ ω_p × e` (P). `xdd = None`: `ẍ = 0`.
pub fn motions<R: Real>(
    plan: &Plan,
    k: &Kin<R>,
    xd: &[R],
    xdd: Option<&[R]>,
) -> Vec<BodyMotion<R>> {
    let n = plan.nx();
    let mut out: Vec<BodyMotion<R>> = Vec::with_capacity(n);
    for i in 0..n {
        let o = k.o[i];
        let (w0, al0, v0, a0) = match plan.joints[i].parent {
            None => (zero3(), zero3(), zero3(), zero3()),
            Some(p) => {
                let m = &out[p];
                (m.w, m.alpha, m.vel_at(k.o[p], o), m.accel_at(k.o[p], o))
            }
        };
        let e = k.e[i];
        let we = cross(w0, e);
        let qdd_e = match xdd {
            Some(a) => scale(a[i], e),
            None => zero3(),
        };
        out.push(match plan.joints[i].kind {
            JointKind::Revolute => BodyMotion {
                w: add(w0, scale(xd[i], e)),
                alpha: add(add(al0, qdd_e), scale(xd[i], we)),
                v: v0,
                a: a0,
            },
            JointKind::Prismatic => BodyMotion {
                w: w0,
                alpha: al0,
                v: add(v0, scale(xd[i], e)),
                a: add(add(a0, qdd_e), scale(R::c(2.0) * xd[i], we)),
            },
        });
    }
    out
}

pub(super) fn motion_of<R: Real>(m: &[BodyMotion<R>], body: Option<usize>) -> BodyMotion<R> {
    body.map(|b| m[b]).unwrap_or_else(BodyMotion::at_rest)
}

pub(super) fn origin_of<R: Real>(k: &Kin<R>, body: Option<usize>) -> V<R> {
    body.map(|b| k.o[b]).unwrap_or_else(zero3)
}
