//! Step 2 and the bias of step 4: a loop equation's value `Φ`, its Jacobian row over the
//! joints (a cut's point rows `e_j × (P − o_j)` (R) or `e_j` (P); its axis rows
//! `(ω_b − ω_a)·(m × n)`), its bias `Φ̇ ẋ`, and the revolute cuts' axis alignment.

use alloc::vec;
use alloc::vec::Vec;

use super::motion::{BodyMotion, motion_of, origin_of};
use super::plan::{Plan, Row};
use super::tree::{Kin, dir_of, point_of};
use crate::algebra::{add, cross, dot, sub};
use crate::model::JointKind;
use crate::scalar::Real;

/// The value of a loop equation at `x`.
pub(super) fn row_value<R: Real>(plan: &Plan, k: &Kin<R>, r: &Row) -> R {
    match *r {
        Row::Point { cut, k: i } => {
            let c = &plan.cuts[cut];
            let a = point_of(k, c.parent, &c.point_parent);
            let b = point_of(k, c.child, &c.point_child);
            b[i] - a[i]
        }
        Row::Axis { cut, m } => {
            let c = &plan.cuts[cut];
            let n = dir_of(k, c.parent, &c.axis_parent.unwrap_or([0.0; 3]));
            let mm_ = dir_of(k, c.child, &m);
            dot(n, mm_)
        }
    }
}

/// `n_parent · n_child − 1` of revolute cut `cut` (zero when the axes are aligned, `−2` when
/// opposite: the axis equations `n·m = 0` hold for both).
pub(super) fn alignment<R: Real>(plan: &Plan, k: &Kin<R>, cut: usize) -> Option<R> {
    let c = &plan.cuts[cut];
    let (a, b) = (c.axis_parent?, c.axis_child?);
    Some(dot(dir_of(k, c.parent, &a), dir_of(k, c.child, &b)) - R::c(1.0))
}

/// `+1` for joints that move `child` only, `−1` for those that move `parent` only, else 0.
fn side(plan: &Plan, parent: Option<usize>, child: Option<usize>, j: usize) -> i32 {
    let on = |b: Option<usize>| b.map(|b| plan.anc[b][j]).unwrap_or(false);
    match (on(child), on(parent)) {
        (true, false) => 1,
        (false, true) => -1,
        _ => 0,
    }
}

/// The Jacobian row of a loop equation over all joints.
pub(super) fn jacobian_row<R: Real>(plan: &Plan, k: &Kin<R>, r: &Row) -> Vec<R> {
    let n = plan.nx();
    let mut out = vec![R::c(0.0); n];
    match *r {
        Row::Point { cut, k: i } => {
            let c = &plan.cuts[cut];
            let p = point_of(k, c.child, &c.point_child);
            for j in 0..n {
                let s = side(plan, c.parent, c.child, j);
                if s == 0 {
                    continue;
                }
                let col = match plan.joints[j].kind {
                    JointKind::Revolute => cross(k.e[j], sub(p, k.o[j])),
                    JointKind::Prismatic => k.e[j],
                };
                out[j] = if s > 0 { col[i] } else { -col[i] };
            }
        }
        Row::Axis { cut, m } => {
            let c = &plan.cuts[cut];
            let nv = dir_of(k, c.parent, &c.axis_parent.unwrap_or([0.0; 3]));
            let w = cross(dir_of(k, c.child, &m), nv);
            for j in 0..n {
                let s = side(plan, c.parent, c.child, j);
                if s == 0 || is_prismatic_plan(plan, j) {
                    continue;
                }
                let v = dot(k.e[j], w);
                out[j] = if s > 0 { v } else { -v };
            }
        }
    }
    out
}

fn is_prismatic_plan(plan: &Plan, j: usize) -> bool {
    plan.joints[j].kind == JointKind::Prismatic
}

/// `Φ̇ ẋ` of a kept loop equation from the body motions with `ẍ = 0`.
pub(super) fn row_bias<R: Real>(plan: &Plan, k: &Kin<R>, m: &[BodyMotion<R>], r: &Row) -> R {
    match *r {
        Row::Point { cut, k: i } => {
            let c = &plan.cuts[cut];
            let p = point_of(k, c.child, &c.point_child);
            let ab = motion_of(m, c.child).accel_at(origin_of(k, c.child), p);
            let aa = motion_of(m, c.parent).accel_at(origin_of(k, c.parent), p);
            ab[i] - aa[i]
        }
        Row::Axis { cut, m: ml } => {
            let c = &plan.cuts[cut];
            let n = dir_of(k, c.parent, &c.axis_parent.unwrap_or([0.0; 3]));
            let mv_ = dir_of(k, c.child, &ml);
            let (ma, mb) = (motion_of(m, c.parent), motion_of(m, c.child));
            let dw = sub(mb.w, ma.w);
            let da = sub(mb.alpha, ma.alpha);
            // d/dt[(ω_b − ω_a)·(m × n)] with ṁ = ω_b × m, ṅ = ω_a × n.
            let mdot_n = cross(cross(mb.w, mv_), n);
            let m_ndot = cross(mv_, cross(ma.w, n));
            dot(da, cross(mv_, n)) + dot(dw, add(mdot_n, m_ndot))
        }
    }
}
