//! The mass matrix `I = TᵀMT` (eq. 21) by composite bodies: the inertia of each subtree lumped
//! into its root body, then the wrench a unit joint rate demands projected on the joints of its
//! path to the base.

use runtime::model::JointKind;

use crate::sym::{Arg, ExprId, Graph};

use super::algebra::Sym;
use super::links::Tree;
use super::runtime_params::{ParamKind, param_index, payload_params};
use super::{M3, V3};

/// Composite inertia of a subtree about its root body's origin, in its frame.
#[derive(Clone, Copy)]
pub(super) struct Composite {
    pub(super) m: ExprId,
    pub(super) h: V3,
    pub(super) j: M3,
}

/// `I = TᵀMT` (eq. 21) by composite bodies; the full symmetric matrix, row-major.
pub fn mass_matrix(g: &mut Graph, tree: &Tree) -> Vec<Vec<ExprId>> {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let comp = composite_bodies(&mut s);
    let mut h = project(&mut s, &comp);
    // Rotor inertia: `I_a` on the diagonal (the rotor turns with `q̇` times the gear ratio).
    for (j, d) in tree.drives.iter().enumerate() {
        let a = if tree.params.is_some() {
            s.g.input(Arg::P, param_index(ParamKind::Armature, j, n))
        } else if d.armature != 0.0 {
            s.c(d.armature)
        } else {
            continue;
        };
        h[j][j] = s.g.add(h[j][j], a);
    }
    h
}

/// The composite body of every joint: each body's inertia ([`body_inertias`]), then each
/// subtree lumped into its parent, from the tips.
pub(super) fn composite_bodies(s: &mut Sym<'_>) -> Vec<Composite> {
    let mut comp = body_inertias(s);
    for i in (0..s.tree.dof()).rev() {
        if let Some(p) = s.tree.links[i].parent {
            comp[p] = add_to_parent(s, i, comp[i], comp[p]);
        }
    }
    comp
}

/// Each body's (regrouped) inertia about its origin, in its frame, plus its run-time payload or
/// body.
pub(super) fn body_inertias(s: &mut Sym<'_>) -> Vec<Composite> {
    let tree = s.tree;
    let mut comp: Vec<Composite> = tree
        .links
        .iter()
        .map(|l| Composite {
            m: s.c(l.mass),
            h: s.cv(&l.h),
            j: s.cm(&l.j),
        })
        .collect();
    let rigid = tree.params.as_ref().map_or(&[][..], |p| &p.rigid[..]);
    for &(b, at) in rigid {
        let (m, h, j) = payload_params(s, b, at);
        let c = comp[b];
        let hs = s.add3(c.h, h);
        let mut js = c.j;
        for r in 0..3 {
            for k in 0..3 {
                js[r][k] = s.g.add(c.j[r][k], j[r][k]);
            }
        }
        comp[b] = Composite {
            m: s.g.add(c.m, m),
            h: hs,
            j: js,
        };
    }
    comp
}

/// Composite `c` of body `i` moved into its parent's frame and added to the parent's `parent`.
fn add_to_parent(s: &mut Sym<'_>, i: usize, c: Composite, parent: Composite) -> Composite {
    let hp = s.parent_frame(i, c.h);
    let jp = s.congruence_to_parent(i, &c.j);
    let off = s.offset(i);
    // J_p += R J Rᵀ − m [p]×² − [p]×[h']× − [h']×[p]×  (parallel-axis theorem).
    let mut jn = parent.j;
    let pp = s.dot(off, off);
    let ph = s.dot(off, hp);
    for r in 0..3 {
        for cc in r..3 {
            // −[a]×[b]× = (a·b) 1 − b aᵀ.
            let mut v = jp[r][cc];
            // −m [p]×² = m (p·p 1 − p pᵀ)
            let ppr = s.g.mul(off[r], off[cc]);
            let t = if r == cc {
                s.g.sub(pp, ppr)
            } else {
                s.g.neg(ppr)
            };
            let t = s.g.mul(c.m, t);
            v = s.g.add(v, t);
            // −[p]×[h]× − [h]×[p]× = 2 (p·h) 1 − h pᵀ − p hᵀ
            let a = s.g.mul(hp[r], off[cc]);
            let b = s.g.mul(off[r], hp[cc]);
            let ab = s.g.add(a, b);
            let t = if r == cc {
                let d = s.g.scale(2.0, ph);
                s.g.sub(d, ab)
            } else {
                s.g.neg(ab)
            };
            v = s.g.add(v, t);
            jn[r][cc] = s.g.add(jn[r][cc], v);
        }
    }
    let jn = s.symmetrize(jn);
    let mo = s.scale3(c.m, off);
    let hn = s.add3(parent.h, mo);
    let hn = s.add3(hn, hp);
    let mn = s.g.add(parent.m, c.m);
    Composite {
        m: mn,
        h: hn,
        j: jn,
    }
}

/// `TᵀMT` from the composite bodies: column `j` is the wrench a unit rate of joint `j` demands
/// of composite `j`, moved towards the base and projected on each joint of the path.
fn project(s: &mut Sym<'_>, comp: &[Composite]) -> Vec<Vec<ExprId>> {
    let tree = s.tree;
    let n = tree.dof();
    let zero = s.g.zero();
    let mut h = vec![vec![zero; n]; n];
    for j in 0..n {
        let c = comp[j];
        // Wrench demanded of composite j by a unit rate of joint j (motion subspace e_z).
        let (mut f, mut nn) = match tree.links[j].kind {
            JointKind::Revolute => {
                let f = [s.g.neg(c.h[1]), c.h[0], zero];
                (f, [c.j[0][2], c.j[1][2], c.j[2][2]])
            }
            JointKind::Prismatic => {
                let nn = [c.h[1], s.g.neg(c.h[0]), zero];
                ([zero, zero, c.m], nn)
            }
        };
        let proj = |kind: JointKind, f: &V3, nn: &V3| match kind {
            JointKind::Revolute => nn[2],
            JointKind::Prismatic => f[2],
        };
        h[j][j] = proj(tree.links[j].kind, &f, &nn);
        let mut i = j;
        while let Some(p) = tree.links[i].parent {
            let fp = s.parent_frame(i, f);
            let np = s.parent_frame(i, nn);
            let off = s.offset(i);
            let pf = s.cross(off, fp);
            nn = s.add3(np, pf);
            f = fp;
            let v = proj(tree.links[p].kind, &f, &nn);
            h[p][j] = v;
            h[j][p] = v;
            i = p;
        }
    }
    h
}
