//! Joint drives: rotor inertia `I_a q̈` and friction `b q̇ + c q̇ / √(q̇² + v_s²)`, the lecture's
//! dissipative term `δ` beside `Tᵀ w`, with constant or run-time coefficients.

use runtime::model::Drive;

use crate::sym::{Arg, ExprId, Graph};

use super::Terms;
use super::runtime_params::{ParamKind, param_index};

/// Adds the joint drives' efforts to `tau`: `I_a q̈` (rotor inertia; when `q̈` is on) and the
/// friction `b q̇ + c q̇ / √(q̇² + v_s²)` (when friction is on) — the lecture's dissipative term
/// `δ` beside `Tᵀ w`.
pub fn add_drive_efforts(
    g: &mut Graph,
    drives: &[Drive],
    terms: Terms,
    tau: &mut [ExprId],
    rate: impl Fn(&mut Graph, Arg, usize) -> ExprId,
) {
    for (i, d) in drives.iter().enumerate() {
        if terms.acceleration && d.armature != 0.0 {
            let qdd = rate(g, Arg::Qdd, i);
            let e = g.scale(d.armature, qdd);
            tau[i] = g.add(tau[i], e);
        }
        if terms.friction && (d.viscous != 0.0 || d.coulomb != 0.0) {
            let qd = rate(g, Arg::Qd, i);
            let f = friction_effort(g, d, qd);
            tau[i] = g.add(tau[i], f);
        }
    }
}

/// `b q̇ + c q̇ / √(q̇² + v_s²)` for one joint ([`Drive::friction`]).
pub fn friction_effort(g: &mut Graph, d: &Drive, qd: ExprId) -> ExprId {
    let mut f = g.scale(d.viscous, qd);
    if d.coulomb != 0.0 {
        let sq = g.mul(qd, qd);
        let vs2 = g.constant(d.coulomb_velocity * d.coulomb_velocity);
        let den = g.add(sq, vs2);
        let den = g.sqrt(den);
        let c = g.scale(d.coulomb, qd);
        let c = g.div(c, den);
        f = g.add(f, c);
    }
    f
}

/// [`add_drive_efforts`] with the coefficients read from the run-time parameters.
pub(super) fn add_param_drive_efforts(
    g: &mut Graph,
    n: usize,
    vs: f64,
    terms: Terms,
    tau: &mut [ExprId],
) {
    for i in 0..n {
        if terms.acceleration {
            let a = g.input(Arg::P, param_index(ParamKind::Armature, i, n));
            let qdd = g.input(Arg::Qdd, i);
            let e = g.mul(a, qdd);
            tau[i] = g.add(tau[i], e);
        }
        if terms.friction {
            let b = g.input(Arg::P, param_index(ParamKind::Damping, i, n));
            let c = g.input(Arg::P, param_index(ParamKind::Friction, i, n));
            let qd = g.input(Arg::Qd, i);
            let v = g.mul(b, qd);
            let sq = g.mul(qd, qd);
            let vs2 = g.constant(vs * vs);
            let den = g.add(sq, vs2);
            let den = g.sqrt(den);
            let cq = g.mul(c, qd);
            let cf = g.div(cq, den);
            let f = g.add(v, cf);
            tau[i] = g.add(tau[i], f);
        }
    }
}
