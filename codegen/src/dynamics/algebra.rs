//! Symbolic vector algebra over the graph ([`Sym`]): 3-vectors and 3×3 matrices of nodes, the
//! joint rotations `Rz(q_i)` from one `sin_cos` per revolute joint, changes between parent and
//! body frames, and the products shared by the recursions (`U = [ω̇]× + [ω]×[ω]×`, the gyroscopic
//! moment).

use runtime::model::{JointKind, Mat3, Vec3};

use crate::sym::{Arg, ExprId, Graph};

use super::links::Tree;
use super::{M3, V3};

/// Vector and matrix helpers over the graph.
pub(super) struct Sym<'a> {
    pub(super) g: &'a mut Graph,
    pub(super) tree: &'a Tree,
    /// `(sin q_i, cos q_i)` for revolute joints.
    pub(super) sc: Vec<Option<(ExprId, ExprId)>>,
    /// `q_i` for prismatic joints.
    pub(super) q: Vec<ExprId>,
}

impl<'a> Sym<'a> {
    pub(super) fn new(g: &'a mut Graph, tree: &'a Tree) -> Self {
        let mut sc = Vec::with_capacity(tree.dof());
        let mut q = Vec::with_capacity(tree.dof());
        for (i, l) in tree.links.iter().enumerate() {
            let qi = g.input(Arg::Q, i);
            q.push(qi);
            sc.push(match l.kind {
                JointKind::Revolute => {
                    let k = g.constant(l.phase);
                    let a = g.add(qi, k);
                    Some((g.sin(a), g.cos(a)))
                }
                JointKind::Prismatic => None,
            });
        }
        Sym { g, tree, sc, q }
    }

    pub(super) fn c(&mut self, v: f64) -> ExprId {
        self.g.constant(v)
    }
    pub(super) fn cv(&mut self, v: &Vec3) -> V3 {
        [self.c(v[0]), self.c(v[1]), self.c(v[2])]
    }
    pub(super) fn cm(&mut self, m: &Mat3) -> M3 {
        [self.cv(&m[0]), self.cv(&m[1]), self.cv(&m[2])]
    }
    pub(super) fn zero3(&mut self) -> V3 {
        let z = self.g.zero();
        [z, z, z]
    }
    pub(super) fn add3(&mut self, a: V3, b: V3) -> V3 {
        [
            self.g.add(a[0], b[0]),
            self.g.add(a[1], b[1]),
            self.g.add(a[2], b[2]),
        ]
    }
    pub(super) fn scale3(&mut self, s: ExprId, a: V3) -> V3 {
        [
            self.g.mul(s, a[0]),
            self.g.mul(s, a[1]),
            self.g.mul(s, a[2]),
        ]
    }
    pub(super) fn dot(&mut self, a: V3, b: V3) -> ExprId {
        let x = self.g.mul(a[0], b[0]);
        let y = self.g.mul(a[1], b[1]);
        let z = self.g.mul(a[2], b[2]);
        let s = self.g.add(x, y);
        self.g.add(s, z)
    }
    pub(super) fn cross(&mut self, a: V3, b: V3) -> V3 {
        let mut r = [a[0]; 3];
        for (k, rk) in r.iter_mut().enumerate() {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let p = self.g.mul(a[i], b[j]);
            let m = self.g.mul(a[j], b[i]);
            *rk = self.g.sub(p, m);
        }
        r
    }
    pub(super) fn mat_vec(&mut self, m: &M3, v: V3) -> V3 {
        let mut r = v;
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = self.dot(m[i], v);
        }
        r
    }
    pub(super) fn mat_t_vec(&mut self, m: &M3, v: V3) -> V3 {
        let cols = [
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ];
        let mut r = v;
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = self.dot(cols[i], v);
        }
        r
    }

    /// `U = [ω̇]× + [ω]×[ω]×`, so that `ω̇ × p + ω × (ω × p) = U p`: computed once per body
    /// and shared by its mass centre and its children's origins (Khalil & Kleinfinger, 1987).
    pub(super) fn u_matrix(&mut self, w: V3, wd: V3) -> M3 {
        let g = &mut *self.g;
        let w00 = g.mul(w[0], w[0]);
        let w11 = g.mul(w[1], w[1]);
        let w22 = g.mul(w[2], w[2]);
        let w01 = g.mul(w[0], w[1]);
        let w02 = g.mul(w[0], w[2]);
        let w12 = g.mul(w[1], w[2]);
        let d0 = g.add(w11, w22);
        let d1 = g.add(w00, w22);
        let d2 = g.add(w00, w11);
        [
            [g.neg(d0), g.sub(w01, wd[2]), g.add(w02, wd[1])],
            [g.add(w01, wd[2]), g.neg(d1), g.sub(w12, wd[0])],
            [g.sub(w02, wd[1]), g.add(w12, wd[0]), g.neg(d2)],
        ]
    }

    /// Gyroscopic moment `ω × (I ω)` for a constant inertia `I`, written as a linear combination
    /// of the products `ω_a ω_b` (shared with [`Sym::u_matrix`]); for a diagonal `I` each
    /// component is one product times `I_jj − I_ii`.
    pub(super) fn gyro(&mut self, inertia: &Mat3, w: V3) -> V3 {
        let mut out = [self.g.zero(); 3];
        for (k, o) in out.iter_mut().enumerate() {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            // ω_i (Iω)_j − ω_j (Iω)_i = Σ_l I_jl ω_i ω_l − I_il ω_j ω_l
            let mut coef = [[0.0f64; 3]; 3];
            for l in 0..3 {
                let (a, b) = (i.min(l), i.max(l));
                coef[a][b] += inertia[j][l];
                let (a, b) = (j.min(l), j.max(l));
                coef[a][b] -= inertia[i][l];
            }
            let mut acc = self.g.zero();
            for a in 0..3 {
                for b in a..3 {
                    if coef[a][b] != 0.0 {
                        let p = self.g.mul(w[a], w[b]);
                        let t = self.g.scale(coef[a][b], p);
                        acc = self.g.add(acc, t);
                    }
                }
            }
            *o = acc;
        }
        out
    }

    /// Gyroscopic moment `ω × (I ω)` formed as written: `Iω`, then the cross product.
    pub(super) fn gyro_cross(&mut self, inertia: &Mat3, w: V3) -> V3 {
        let im = self.cm(inertia);
        let iw = self.mat_vec(&im, w);
        self.cross(w, iw)
    }

    /// `Rz(q_i)ᵀ v` (revolute), `v` (prismatic).
    pub(super) fn rz_t(&mut self, i: usize, v: V3) -> V3 {
        self.rotate_z(i, v, true)
    }
    /// `Rz(q_i) v` (revolute), `v` (prismatic).
    pub(super) fn rz(&mut self, i: usize, v: V3) -> V3 {
        self.rotate_z(i, v, false)
    }
    /// `Rz(q_i) v`, or `Rz(q_i)ᵀ v` when `transpose`; the identity for prismatic joints.
    pub(super) fn rotate_z(&mut self, i: usize, v: V3, transpose: bool) -> V3 {
        let Some((s, c)) = self.sc[i] else { return v };
        // Nodes are created in a fixed order (ids decide operand order in the output).
        let cv0 = self.g.mul(c, v[0]);
        let sv1 = self.g.mul(s, v[1]);
        if transpose {
            let x = self.g.add(cv0, sv1);
            let cv1 = self.g.mul(c, v[1]);
            let sv0 = self.g.mul(s, v[0]);
            [x, self.g.sub(cv1, sv0), v[2]]
        } else {
            let x = self.g.sub(cv0, sv1);
            let sv0 = self.g.mul(s, v[0]);
            let cv1 = self.g.mul(c, v[1]);
            [x, self.g.add(sv0, cv1), v[2]]
        }
    }
    /// Parent-frame components → body-`i` components.
    pub(super) fn child_frame(&mut self, i: usize, v: V3) -> V3 {
        let r0 = self.cm(&self.tree.links[i].rot);
        let u = self.mat_t_vec(&r0, v);
        self.rz_t(i, u)
    }
    /// Body-`i` components → parent-frame components.
    pub(super) fn parent_frame(&mut self, i: usize, v: V3) -> V3 {
        let u = self.rz(i, v);
        let r0 = self.cm(&self.tree.links[i].rot);
        self.mat_vec(&r0, u)
    }
    /// Position of body `i`'s origin in its parent's frame.
    pub(super) fn offset(&mut self, i: usize) -> V3 {
        let l = &self.tree.links[i];
        let p0 = l.trans;
        let ez = [l.rot[0][2], l.rot[1][2], l.rot[2][2]];
        let kind = l.kind;
        let p = self.cv(&p0);
        match kind {
            JointKind::Revolute => p,
            JointKind::Prismatic => {
                let e = self.cv(&ez);
                let d = self.scale3(self.q[i], e);
                self.add3(p, d)
            }
        }
    }
    /// Symmetric `R S Rᵀ` for body `i`'s rotation `R = R0 Rz(q_i)` (upper triangle computed,
    /// mirrored).
    pub(super) fn congruence_to_parent(&mut self, i: usize, s: &M3) -> M3 {
        let a = self.congruence_rz(i, s);
        self.congruence_r0(i, &a)
    }
    /// Symmetric `R0 A R0ᵀ` for body `i`'s fixed rotation `R0` (the second step of
    /// [`Sym::congruence_to_parent`]).
    pub(super) fn congruence_r0(&mut self, i: usize, a: &M3) -> M3 {
        let r0 = self.cm(&self.tree.links[i].rot);
        // T = R0 A (rows), B_rc = T_r · R0_c for r ≤ c.
        let t: Vec<V3> = (0..3)
            .map(|r| {
                let col = |c: usize| [a[0][c], a[1][c], a[2][c]];
                let (c0, c1, c2) = (col(0), col(1), col(2));
                [
                    self.dot(r0[r], c0),
                    self.dot(r0[r], c1),
                    self.dot(r0[r], c2),
                ]
            })
            .collect();
        let mut b = *a;
        for r in 0..3 {
            for c in r..3 {
                b[r][c] = self.dot(t[r], r0[c]);
            }
        }
        self.symmetrize(b)
    }
    /// Symmetric `Rz(q_i) S Rz(q_i)ᵀ` (the first step of [`Sym::congruence_to_parent`]; `S`
    /// itself for prismatic joints).
    pub(super) fn congruence_rz(&mut self, i: usize, s: &M3) -> M3 {
        let cols = [
            [s[0][0], s[1][0], s[2][0]],
            [s[0][1], s[1][1], s[2][1]],
            [s[0][2], s[1][2], s[2][2]],
        ];
        // Rz S: rotate each column.
        let rs: Vec<V3> = cols.iter().map(|&c| self.rz(i, c)).collect();
        // (Rz S) Rzᵀ = (Rz (Rz S)ᵀ)ᵀ: rotate each row of Rz S.
        let rows: Vec<V3> = (0..3).map(|r| [rs[0][r], rs[1][r], rs[2][r]]).collect();
        let a_rows: Vec<V3> = rows.iter().map(|&r| self.rz(i, r)).collect();
        // a_rows[r] is column r of A (= row r, A symmetric up to rounding); use it as A's rows.
        let a: M3 = [
            [a_rows[0][0], a_rows[1][0], a_rows[2][0]],
            [a_rows[0][1], a_rows[1][1], a_rows[2][1]],
            [a_rows[0][2], a_rows[1][2], a_rows[2][2]],
        ];
        self.symmetrize(a)
    }
    pub(super) fn symmetrize(&mut self, mut m: M3) -> M3 {
        for r in 0..3 {
            for c in 0..r {
                m[r][c] = m[c][r];
            }
        }
        m
    }
}
