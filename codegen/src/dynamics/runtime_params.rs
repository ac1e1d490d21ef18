//! Run-time parameters (`[scene] parameters = "runtime"`, `[scene] runtime_inertia`): the layout
//! of the parameter array, the tree's [`ParamLayout`], and the inertial parameters of a run-time
//! payload or body as nodes in its link's frame.

use crate::sym::{Arg, ExprId};

use super::algebra::Sym;
use super::links::Tree;
use super::{M3, V3};

/// What [`Tree::with_runtime_params`] makes an input.
#[derive(Clone, Debug)]
pub(super) struct ParamLayout {
    /// Rigid bodies with run-time inertial parameters: `(link, first index)` of the payload
    /// (index 0) and of each run-time body ([`body_param_index`]). Each enters as a payload on
    /// its link.
    pub(super) rigid: Vec<(usize, usize)>,
    pub(super) coulomb_velocity: f64,
}

/// Index into the run-time parameter array (`Params::to_array`) of a `dof`-joint tree:
/// `0` payload mass, `1..4` its mass centre, `4..10` its inertia `xx, xy, xz, yy, yz, zz` (body
/// frame of the payload's body, about the mass centre), then per joint `damping`, `friction`,
/// `armature` (`10 + kind·dof + joint`), then ten entries per run-time body
/// ([`body_param_index`], in the same order as the payload's).
pub fn param_index(kind: ParamKind, joint: usize, dof: usize) -> usize {
    match kind {
        ParamKind::Damping => 10 + joint,
        ParamKind::Friction => 10 + dof + joint,
        ParamKind::Armature => 10 + 2 * dof + joint,
    }
}

/// The per-joint run-time parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamKind {
    /// Viscous friction coefficient.
    Damping,
    /// Coulomb friction level.
    Friction,
    /// Reflected rotor inertia.
    Armature,
}

/// Number of run-time parameters of a `dof`-joint tree without run-time bodies.
pub fn param_count(dof: usize) -> usize {
    10 + 3 * dof
}

/// Number of run-time parameters of a `dof`-joint tree with `bodies` run-time bodies
/// (`[scene] runtime_inertia`).
pub fn param_count_with(dof: usize, bodies: usize) -> usize {
    param_count(dof) + 10 * bodies
}

/// First index of run-time body `k`'s ten parameters in a `dof`-joint tree: after the drives,
/// mass, mass centre (3), inertia about it `xx, xy, xz, yy, yz, zz`, as the payload's.
pub fn body_param_index(k: usize, dof: usize) -> usize {
    param_count(dof) + 10 * k
}

impl Tree {
    /// The same tree with run-time parameters: the payload (on model body `payload`, if any)
    /// and every joint's drive coefficients become inputs (`Arg::P`, see [`param_index`]).
    pub fn with_runtime_params(mut self, payload: Option<usize>, coulomb_velocity: f64) -> Tree {
        self.params = Some(ParamLayout {
            rigid: payload.map(|b| (b, 0)).into_iter().collect(),
            coulomb_velocity,
        });
        self
    }

    /// Run-time inertial parameters of rigid bodies (`[scene] runtime_inertia`; call after
    /// [`Tree::with_runtime_params`]): entry `k` rides on model body `bodies[k]` and reads its
    /// ten parameters from [`body_param_index`]`(k, dof)`, exactly as a run-time payload there.
    /// The bodies' constants must already be zero in the model.
    pub fn with_runtime_bodies(mut self, bodies: &[usize]) -> Tree {
        let n = self.dof();
        if let Some(p) = &mut self.params {
            p.rigid.extend(
                bodies
                    .iter()
                    .enumerate()
                    .map(|(k, &b)| (b, body_param_index(k, n))),
            );
        }
        self
    }

    /// Whether the tree takes run-time parameters.
    pub fn has_runtime_params(&self) -> bool {
        self.params.is_some()
    }
}

/// The inertial parameters of a run-time payload or body (`Arg::P` entries `at..at + 10`) in
/// link `b`'s frame: mass, first moment `m c` and inertia about the link origin
/// (`x_link = A x_body − d e_z`; parallel-axis theorem).
pub(super) fn payload_params(s: &mut Sym<'_>, b: usize, at: usize) -> (ExprId, V3, M3) {
    let (m, c, ic) = centre_params(s, b, at);
    let h = s.scale3(m, c);
    // J = I_c + m (c·c 1 − c cᵀ) = I_c + (h·c) 1 − h cᵀ.
    let hc = s.dot(h, c);
    let mut j = ic;
    for r in 0..3 {
        for k in r..3 {
            let hck = s.g.mul(h[r], c[k]);
            let mut v = s.g.sub(ic[r][k], hck);
            if r == k {
                v = s.g.add(v, hc);
            }
            j[r][k] = v;
            j[k][r] = v;
        }
    }
    (m, h, j)
}

/// The inertial parameters of a run-time payload or body (`Arg::P` entries `at..at + 10`) in
/// link `b`'s frame: mass, mass centre and inertia about it (`x_link = A x_body − d e_z`).
pub(super) fn centre_params(s: &mut Sym<'_>, b: usize, at: usize) -> (ExprId, V3, M3) {
    let (a, d) = s.tree.links[b].to_link;
    let p = |s: &mut Sym<'_>, k: usize| s.g.input(Arg::P, at + k);
    let m = p(s, 0);
    let cb = [p(s, 1), p(s, 2), p(s, 3)];
    let ic_b = {
        let (xx, xy, xz, yy, yz, zz) = (p(s, 4), p(s, 5), p(s, 6), p(s, 7), p(s, 8), p(s, 9));
        [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
    };
    let am = s.cm(&a);
    let c = s.mat_vec(&am, cb);
    let dz = s.c(d);
    let c = [c[0], c[1], s.g.sub(c[2], dz)];
    // A I Aᵀ, entry by entry (A is constant; mostly a signed permutation, so this folds).
    let zero = s.g.zero();
    let mut ic = [[zero; 3]; 3];
    for r in 0..3 {
        for k in r..3 {
            let mut acc = zero;
            for u in 0..3 {
                for v in 0..3 {
                    let coef = a[r][u] * a[k][v];
                    if coef != 0.0 {
                        let t = s.g.scale(coef, ic_b[u][v]);
                        acc = s.g.add(acc, t);
                    }
                }
            }
            ic[r][k] = acc;
            ic[k][r] = acc;
        }
    }
    (m, c, ic)
}
