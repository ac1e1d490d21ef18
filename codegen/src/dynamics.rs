//! Symbolic dynamics of a kinematic tree: the NOC products `Tᵀ(M ṫ + W M t − w^G)` and
//! `TᵀMT` built in the expression DAG with the cheap association (noc-method.md, "Evaluation
//! order matters").
//!
//! # From the NOC to the recursions
//! The lecture's twist-shaping matrix of a serial chain is block lower-triangular (eq. 34): body
//! `i`'s twist is `t_i = Σ_{j ≤ i} t_ij θ̇_j` (eq. 33) with the columns `t_ij` of eqs. 31–32 /
//! 46–48. Forming `T` and multiplying would cost `O(n²)`; instead
//! * `t = T θ̇` and `ṫ = T θ̈ + Ṫ θ̇` are evaluated by the chain recursion `ω_i = ω_{i−1} + θ̇_i e_i`
//!   (eqs. 25–26, 35–36) — the same numbers, one joint at a time;
//! * every body's Newton–Euler wrench `M_i ṫ_i + W_i M_i t_i − w_i^G` (eqs. 7–12) is formed once;
//! * `Tᵀ w` is evaluated from the tips: column `j` of `T` maps a body wrench to
//!   `e_jᵀ (n_i + (c_i − o_j) × f_i)` (R) or `e_jᵀ f_i` (P), so summing the wrenches of the
//!   subtree of joint `j`, moved to the joint axis, gives the `j`-th effort (eq. 24). Cost grows
//!   linearly with the number of joints.
//! * `I = TᵀMT` (eq. 21) is formed from composite bodies (the inertia of each subtree lumped into
//!   its root body): entry `(j, k)` is the wrench that a unit rate of joint `j` demands of the
//!   composite body of `j`, projected on joint `k`'s column; quadratic in the joints.
//!
//! # Frames
//! Quantities are resolved in body frames, where inertias are constant and joint axes are
//! coordinate axes: before building, every joint frame is rotated (a constant change of body
//! axes, folded into the constant origins) so that its axis is `+z`. A rotation about a
//! coordinate axis with exact 0/±1 constants then costs nothing, and structural zeros of `T`
//! (a body never depends on joints off its path) never appear in the graph.
//!
//! Gravity enters as an acceleration `−g` of the base (equivalent to `w_i^G = [0; m_i g]` on
//! every body, and free).

use runtime::model::{JointKind, Mat3, Model, Vec3, mat_mul, mat_vec, transpose};

use crate::sym::{Arg, ExprId, Graph};

/// A symbolic 3-vector.
pub type V3 = [ExprId; 3];
/// A symbolic 3×3 matrix (row-major).
pub type M3 = [[ExprId; 3]; 3];

/// One joint + body of the canonical tree (axis `+z` in the joint frame).
#[derive(Clone, Debug)]
struct Link {
    kind: JointKind,
    parent: Option<usize>,
    /// Constant rotation of the joint frame (q = 0) in the parent body frame.
    rot: Mat3,
    /// Constant translation of the joint frame in the parent body frame.
    trans: Vec3,
    mass: f64,
    /// First moment of mass `m c` (body frame).
    h: Vec3,
    /// Inertia about the body-frame origin (body frame).
    j: Mat3,
}

impl Link {
    /// Mass centre and inertia about it (body frame), when the (regrouped) mass is not zero.
    fn centre(&self) -> Option<(Vec3, Mat3)> {
        if self.mass == 0.0 {
            return None;
        }
        let m = self.mass;
        let c = [self.h[0] / m, self.h[1] / m, self.h[2] / m];
        let cc = dot3(&c, &c);
        let mut ic = self.j;
        for r in 0..3 {
            for s in 0..3 {
                let delta = if r == s { cc } else { 0.0 };
                ic[r][s] -= m * (delta - c[r] * c[s]);
            }
        }
        for r in 0..3 {
            for s in 0..r {
                ic[r][s] = ic[s][r];
            }
        }
        Some((c, ic))
    }
}

fn dot3(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Inertial parameters `(m, h, J)` of a body (first moment `h` and inertia `J` about its frame
/// origin), moved to a frame in which that body's frame has rotation `rot` and origin `p`:
/// `h' = m p + R h`, `J' = R J Rᵀ + m (p·p 1 − p pᵀ) + 2 (p·Rh) 1 − Rh pᵀ − p (Rh)ᵀ`.
fn transfer(rot: &Mat3, p: &Vec3, m: f64, h: &Vec3, j: &Mat3) -> (Vec3, Mat3) {
    let rh = mat_vec(rot, h);
    let rj = mat_mul(rot, &mat_mul(j, &transpose(rot)));
    let pp = dot3(p, p);
    let ph = dot3(p, &rh);
    let mut jn = [[0.0; 3]; 3];
    for r in 0..3 {
        for s in r..3 {
            let d = if r == s { 1.0 } else { 0.0 };
            jn[r][s] =
                rj[r][s] + m * (d * pp - p[r] * p[s]) + 2.0 * d * ph - rh[r] * p[s] - p[r] * rh[s];
            jn[s][r] = jn[r][s];
        }
    }
    let hn = [m * p[0] + rh[0], m * p[1] + rh[1], m * p[2] + rh[2]];
    (hn, jn)
}

/// The tree with every joint axis turned onto `+z`.
#[derive(Clone, Debug)]
pub struct Tree {
    links: Vec<Link>,
    gravity: Vec3,
}

/// A rotation `Q` with `Q e_z = a` (exact for ±coordinate axes).
fn frame_with_z_along(a: &Vec3) -> Mat3 {
    let [x, y, z] = *a;
    // Columns are the new x, y, z axes.
    let cols: [Vec3; 3] = if *a == [0.0, 0.0, 1.0] {
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    } else if *a == [0.0, 0.0, -1.0] {
        [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
    } else if *a == [1.0, 0.0, 0.0] {
        [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    } else if *a == [-1.0, 0.0, 0.0] {
        [[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]]
    } else if *a == [0.0, 1.0, 0.0] {
        [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    } else if *a == [0.0, -1.0, 0.0] {
        [[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]
    } else {
        // A unit vector orthogonal to a, then the third by the cross product.
        let u = if x.abs() <= y.abs() && x.abs() <= z.abs() {
            let n = (y * y + z * z).sqrt();
            [0.0, z / n, -y / n]
        } else if y.abs() <= z.abs() {
            let n = (x * x + z * z).sqrt();
            [-z / n, 0.0, x / n]
        } else {
            let n = (x * x + y * y).sqrt();
            [y / n, -x / n, 0.0]
        };
        let v = [
            y * u[2] - z * u[1],
            z * u[0] - x * u[2],
            x * u[1] - y * u[0],
        ];
        [u, v, *a]
    };
    // Matrix with those columns.
    [
        [cols[0][0], cols[1][0], cols[2][0]],
        [cols[0][1], cols[1][1], cols[2][1]],
        [cols[0][2], cols[1][2], cols[2][2]],
    ]
}

impl Tree {
    /// Canonicalize a validated model: each body frame `B_i` becomes `B_i Q_i` with
    /// `Q_i e_z = axis_i`, so the motion is about (along) `+z`; origins and inertial data follow.
    pub fn new(model: &Model) -> Tree {
        let n = model.dof();
        let qs: Vec<Mat3> = model
            .joints
            .iter()
            .map(|j| frame_with_z_along(&j.axis))
            .collect();
        let mut links = Vec::with_capacity(n);
        for (i, (joint, body)) in model.joints.iter().zip(&model.bodies).enumerate() {
            let qp = joint.parent.map(|p| transpose(&qs[p]));
            let (rot, trans) = match qp {
                Some(qpt) => (
                    mat_mul(&qpt, &mat_mul(&joint.origin.rotation, &qs[i])),
                    mat_vec(&qpt, &joint.origin.translation),
                ),
                None => (
                    mat_mul(&joint.origin.rotation, &qs[i]),
                    joint.origin.translation,
                ),
            };
            let qt = transpose(&qs[i]);
            let c = mat_vec(&qt, &body.com);
            let ic = mat_mul(&qt, &mat_mul(&body.inertia, &qs[i]));
            let m = body.mass;
            let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
            let mut j = [[0.0; 3]; 3];
            for r in 0..3 {
                for s in 0..3 {
                    let delta = if r == s { cc } else { 0.0 };
                    j[r][s] = ic[r][s] + m * (delta - c[r] * c[s]);
                }
            }
            // Keep the stored inertia exactly symmetric.
            for r in 0..3 {
                for s in 0..r {
                    j[r][s] = j[s][r];
                }
            }
            links.push(Link {
                kind: joint.kind,
                parent: joint.parent,
                rot,
                trans,
                mass: m,
                h: [m * c[0], m * c[1], m * c[2]],
                j,
            });
        }
        let mut tree = Tree {
            links,
            gravity: model.gravity,
        };
        tree.regroup();
        tree
    }

    /// Lump into each parent the inertial parameters of its child that the child's joint motion
    /// cannot reveal (Khalil & Kleinfinger 1987; Khalil & Dombre 2002, §9.4 / §12.5), from the
    /// tips to the root; parameters lumped into the fixed base are dropped. The efforts of every
    /// function are unchanged (they are linear in the inertial parameters, and the lumped part
    /// has the same kinetic and potential energy on either side of the joint), but zeros appear
    /// in the parameters and cost nothing.
    /// * Revolute joint (axis `z` through the body origin): a body `(m, [0, 0, h_z],
    ///   diag(A, A, 0))` is symmetric about the axis, so turning about it changes nothing: the
    ///   mass, `h_z` and `A` (`J_yy` here, as Khalil's `YY_j`) move to the parent.
    /// * Prismatic joint: the body does not turn relative to its parent, so its whole rotational
    ///   inertia (a pure moment of inertia, `m = 0`, `h = 0`) moves to the parent.
    fn regroup(&mut self) {
        for i in (0..self.links.len()).rev() {
            let l = &mut self.links[i];
            let (m, h, j) = match l.kind {
                JointKind::Revolute => {
                    let a = l.j[1][1];
                    let moved = (
                        l.mass,
                        [0.0, 0.0, l.h[2]],
                        [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0; 3]],
                    );
                    l.mass = 0.0;
                    l.h[2] = 0.0;
                    l.j[0][0] -= a;
                    l.j[1][1] = 0.0;
                    moved
                }
                JointKind::Prismatic => {
                    let moved = (0.0, [0.0; 3], l.j);
                    l.j = [[0.0; 3]; 3];
                    moved
                }
            };
            let (rot, trans, parent) = (l.rot, l.trans, l.parent);
            if let Some(p) = parent {
                let (hn, jn) = transfer(&rot, &trans, m, &h, &j);
                let lp = &mut self.links[p];
                lp.mass += m;
                for r in 0..3 {
                    lp.h[r] += hn[r];
                    for s in 0..3 {
                        lp.j[r][s] += jn[r][s];
                    }
                }
            }
        }
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.links.len()
    }
}

/// Vector and matrix helpers over the graph.
struct Sym<'a> {
    g: &'a mut Graph,
    tree: &'a Tree,
    /// `(sin q_i, cos q_i)` for revolute joints.
    sc: Vec<Option<(ExprId, ExprId)>>,
    /// `q_i` for prismatic joints.
    q: Vec<ExprId>,
}

impl<'a> Sym<'a> {
    fn new(g: &'a mut Graph, tree: &'a Tree) -> Self {
        let mut sc = Vec::with_capacity(tree.dof());
        let mut q = Vec::with_capacity(tree.dof());
        for (i, l) in tree.links.iter().enumerate() {
            let qi = g.input(Arg::Q, i);
            q.push(qi);
            sc.push(match l.kind {
                JointKind::Revolute => Some((g.sin(qi), g.cos(qi))),
                JointKind::Prismatic => None,
            });
        }
        Sym { g, tree, sc, q }
    }

    fn c(&mut self, v: f64) -> ExprId {
        self.g.constant(v)
    }
    fn cv(&mut self, v: &Vec3) -> V3 {
        [self.c(v[0]), self.c(v[1]), self.c(v[2])]
    }
    fn cm(&mut self, m: &Mat3) -> M3 {
        [self.cv(&m[0]), self.cv(&m[1]), self.cv(&m[2])]
    }
    fn zero3(&mut self) -> V3 {
        let z = self.g.zero();
        [z, z, z]
    }
    fn add3(&mut self, a: V3, b: V3) -> V3 {
        [
            self.g.add(a[0], b[0]),
            self.g.add(a[1], b[1]),
            self.g.add(a[2], b[2]),
        ]
    }
    fn scale3(&mut self, s: ExprId, a: V3) -> V3 {
        [
            self.g.mul(s, a[0]),
            self.g.mul(s, a[1]),
            self.g.mul(s, a[2]),
        ]
    }
    fn dot(&mut self, a: V3, b: V3) -> ExprId {
        let x = self.g.mul(a[0], b[0]);
        let y = self.g.mul(a[1], b[1]);
        let z = self.g.mul(a[2], b[2]);
        let s = self.g.add(x, y);
        self.g.add(s, z)
    }
    fn cross(&mut self, a: V3, b: V3) -> V3 {
        let mut r = [a[0]; 3];
        for (k, rk) in r.iter_mut().enumerate() {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let p = self.g.mul(a[i], b[j]);
            let m = self.g.mul(a[j], b[i]);
            *rk = self.g.sub(p, m);
        }
        r
    }
    fn mat_vec(&mut self, m: &M3, v: V3) -> V3 {
        let mut r = v;
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = self.dot(m[i], v);
        }
        r
    }
    fn mat_t_vec(&mut self, m: &M3, v: V3) -> V3 {
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
    fn u_matrix(&mut self, w: V3, wd: V3) -> M3 {
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
    fn gyro(&mut self, inertia: &Mat3, w: V3) -> V3 {
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

    /// `Rz(q_i)ᵀ v` (revolute), `v` (prismatic).
    fn rz_t(&mut self, i: usize, v: V3) -> V3 {
        match self.sc[i] {
            Some((s, c)) => {
                let a = self.g.mul(c, v[0]);
                let b = self.g.mul(s, v[1]);
                let x = self.g.add(a, b);
                let a = self.g.mul(c, v[1]);
                let b = self.g.mul(s, v[0]);
                let y = self.g.sub(a, b);
                [x, y, v[2]]
            }
            None => v,
        }
    }
    /// `Rz(q_i) v` (revolute), `v` (prismatic).
    fn rz(&mut self, i: usize, v: V3) -> V3 {
        match self.sc[i] {
            Some((s, c)) => {
                let a = self.g.mul(c, v[0]);
                let b = self.g.mul(s, v[1]);
                let x = self.g.sub(a, b);
                let a = self.g.mul(s, v[0]);
                let b = self.g.mul(c, v[1]);
                let y = self.g.add(a, b);
                [x, y, v[2]]
            }
            None => v,
        }
    }
    /// Parent-frame components → body-`i` components.
    fn child_frame(&mut self, i: usize, v: V3) -> V3 {
        let r0 = self.cm(&self.tree.links[i].rot);
        let u = self.mat_t_vec(&r0, v);
        self.rz_t(i, u)
    }
    /// Body-`i` components → parent-frame components.
    fn parent_frame(&mut self, i: usize, v: V3) -> V3 {
        let u = self.rz(i, v);
        let r0 = self.cm(&self.tree.links[i].rot);
        self.mat_vec(&r0, u)
    }
    /// Position of body `i`'s origin in its parent's frame.
    fn offset(&mut self, i: usize) -> V3 {
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
    fn congruence_to_parent(&mut self, i: usize, s: &M3) -> M3 {
        // A = Rz S Rzᵀ, then B = R0 A R0ᵀ.
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
        let a = self.symmetrize(a);
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
        let mut b = a;
        for r in 0..3 {
            for c in r..3 {
                b[r][c] = self.dot(t[r], r0[c]);
            }
        }
        self.symmetrize(b)
    }
    fn symmetrize(&mut self, mut m: M3) -> M3 {
        for r in 0..3 {
            for c in 0..r {
                m[r][c] = m[c][r];
            }
        }
        m
    }
}

/// Which generalized-force terms an inverse-dynamics sweep includes.
#[derive(Clone, Copy, Debug)]
pub struct Terms {
    /// Velocity terms (`q̇` is an input); else `q̇ = 0`.
    pub velocity: bool,
    /// Acceleration terms (`q̈` is an input); else `q̈ = 0`.
    pub acceleration: bool,
    /// Gravity.
    pub gravity: bool,
}

/// `Tᵀ (M ṫ + W M t − w^G)`: inverse dynamics (or its parts), one effort per joint.
pub fn inverse_dynamics(g: &mut Graph, tree: &Tree, terms: Terms) -> Vec<ExprId> {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let zero = s.g.zero();
    let qd: Vec<ExprId> = (0..n)
        .map(|i| {
            if terms.velocity {
                s.g.input(Arg::Qd, i)
            } else {
                zero
            }
        })
        .collect();
    let qdd: Vec<ExprId> = (0..n)
        .map(|i| {
            if terms.acceleration {
                s.g.input(Arg::Qdd, i)
            } else {
                zero
            }
        })
        .collect();
    let a0 = if terms.gravity {
        let gv = tree.gravity;
        s.cv(&[-gv[0], -gv[1], -gv[2]])
    } else {
        s.zero3()
    };
    // Forward sweep: twists t_i = T_i q̇ and their rates ṫ_i = T_i q̈ + Ṫ_i q̇ (eqs. 25–26, 33),
    // resolved in body frames; `acc` is the acceleration of the body-frame origin.
    let mut omega: Vec<V3> = Vec::with_capacity(n);
    let mut omegad: Vec<V3> = Vec::with_capacity(n);
    let mut acc: Vec<V3> = Vec::with_capacity(n);
    for i in 0..n {
        let l = &tree.links[i];
        let (wp, wdp, ap) = match l.parent {
            Some(p) => (omega[p], omegad[p], acc[p]),
            None => (s.zero3(), s.zero3(), a0),
        };
        let (w, wd, a) = match l.kind {
            JointKind::Revolute => {
                let p = s.offset(i);
                // Origin acceleration in the parent frame: a_p + ω̇_p × p + ω_p × (ω_p × p).
                let u = s.u_matrix(wp, wdp);
                let up = s.mat_vec(&u, p);
                let ao = s.add3(ap, up);
                let a = s.child_frame(i, ao);
                let w_in = s.child_frame(i, wp);
                let wd_in = s.child_frame(i, wdp);
                // ω_i = ω_p + e q̇; ω̇_i = ω̇_p + e q̈ + ω_p × e q̇ (e = +z).
                let w = [w_in[0], w_in[1], s.g.add(w_in[2], qd[i])];
                let x = s.g.mul(w_in[1], qd[i]);
                let y = s.g.mul(w_in[0], qd[i]);
                let wd = [
                    s.g.add(wd_in[0], x),
                    s.g.sub(wd_in[1], y),
                    s.g.add(wd_in[2], qdd[i]),
                ];
                (w, wd, a)
            }
            JointKind::Prismatic => {
                let w = s.child_frame(i, wp);
                let wd = s.child_frame(i, wdp);
                // r: the joint's offset in body axes (R0ᵀ p0 + e q).
                let r0t = transpose(&tree.links[i].rot);
                let rc = mat_vec(&r0t, &tree.links[i].trans);
                let rc = s.cv(&rc);
                let r = [rc[0], rc[1], s.g.add(rc[2], s.q[i])];
                let ap_in = s.child_frame(i, ap);
                let u = s.u_matrix(w, wd);
                let ur = s.mat_vec(&u, r);
                // 2 ω × e ḋ + e d̈.
                let x = s.g.mul(w[1], qd[i]);
                let y = s.g.mul(w[0], qd[i]);
                let cor = [s.g.scale(2.0, x), s.g.scale(-2.0, y), qdd[i]];
                let a = s.add3(ap_in, ur);
                let a = s.add3(a, cor);
                (w, wd, a)
            }
        };
        omega.push(w);
        omegad.push(wd);
        acc.push(a);
    }
    // Body wrenches M_i ṫ_i + W_i M_i t_i − w_i^G (eq. 12), about the body-frame origin.
    let mut force: Vec<V3> = Vec::with_capacity(n);
    let mut moment: Vec<V3> = Vec::with_capacity(n);
    for i in 0..n {
        let l = &tree.links[i];
        let m = s.c(l.mass);
        let h = s.cv(&l.h);
        let jm = s.cm(&l.j);
        let (w, wd, a) = (omega[i], omegad[i], acc[i]);
        let ma = s.scale3(m, a);
        let u = s.u_matrix(w, wd);
        let uh = s.mat_vec(&u, h);
        let f = s.add3(ma, uh);
        // Moment about the origin, two equivalent forms; keep the cheaper one for this body:
        // J ω̇ + ω × Jω + h × a (inertia about the origin), or
        // I_c ω̇ + ω × I_c ω + c × f (about the mass centre, then moved).
        let jwd = s.mat_vec(&jm, wd);
        let gyro = s.gyro(&l.j, w);
        let ha = s.cross(h, a);
        let n_o = s.add3(jwd, gyro);
        let n_o = s.add3(n_o, ha);
        let nn = match l.centre() {
            Some((lc, lic)) => {
                let icm = s.cm(&lic);
                let c = s.cv(&lc);
                let iwd = s.mat_vec(&icm, wd);
                let gyro_c = s.gyro(&lic, w);
                let cf = s.cross(c, f);
                let n_c = s.add3(iwd, gyro_c);
                let n_c = s.add3(n_c, cf);
                let cost = |g: &Graph, n: &V3| {
                    let roots = [f[0], f[1], f[2], n[0], n[1], n[2]];
                    crate::schedule::schedule(g, &roots).ops.flops()
                };
                if cost(s.g, &n_c) < cost(s.g, &n_o) {
                    n_c
                } else {
                    n_o
                }
            }
            None => n_o,
        };
        force.push(f);
        moment.push(nn);
    }
    // Backward sweep: Tᵀ w, accumulated from the tips (eq. 24).
    let mut tau = vec![zero; n];
    for i in (0..n).rev() {
        tau[i] = match tree.links[i].kind {
            JointKind::Revolute => moment[i][2],
            JointKind::Prismatic => force[i][2],
        };
        if let Some(p) = tree.links[i].parent {
            let f = s.parent_frame(i, force[i]);
            let nn = s.parent_frame(i, moment[i]);
            let off = s.offset(i);
            let pf = s.cross(off, f);
            let nn = s.add3(nn, pf);
            force[p] = s.add3(force[p], f);
            moment[p] = s.add3(moment[p], nn);
        }
    }
    tau
}

/// Composite inertia of a subtree about its root body's origin, in its frame.
#[derive(Clone, Copy)]
struct Composite {
    m: ExprId,
    h: V3,
    j: M3,
}

/// `I = TᵀMT` (eq. 21) by composite bodies; the full symmetric matrix, row-major.
pub fn mass_matrix(g: &mut Graph, tree: &Tree) -> Vec<Vec<ExprId>> {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let mut comp: Vec<Composite> = tree
        .links
        .iter()
        .map(|l| Composite {
            m: s.c(l.mass),
            h: s.cv(&l.h),
            j: s.cm(&l.j),
        })
        .collect();
    for i in (0..n).rev() {
        if let Some(p) = tree.links[i].parent {
            let c = comp[i];
            let hp = s.parent_frame(i, c.h);
            let jp = s.congruence_to_parent(i, &c.j);
            let off = s.offset(i);
            // J_p += R J Rᵀ − m [p]×² − [p]×[h']× − [h']×[p]×  (parallel-axis theorem).
            let mut jn = comp[p].j;
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
            let hn = s.add3(comp[p].h, mo);
            let hn = s.add3(hn, hp);
            let mn = s.g.add(comp[p].m, c.m);
            comp[p] = Composite {
                m: mn,
                h: hn,
                j: jn,
            };
        }
    }
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

/// Relative pivot tolerance of the generated factorization: pivot `k` must exceed
/// `PIVOT_TOLERANCE · I_kk` (the diagonal entry it came from).
pub const PIVOT_TOLERANCE: f64 = 1e-12;

/// Forward dynamics `q̈ = I⁻¹ (τ − C q̇ + γ)`: composite-body `I`, the bias by the inverse
/// dynamics with `q̈ = 0`, then an `Lᵀ D L` factorization eliminated from the tips (no fill-in
/// for trees; Featherstone, RBDA §6.5) with checked pivots.
pub fn forward_dynamics(g: &mut Graph, tree: &Tree) -> Vec<ExprId> {
    let n = tree.dof();
    let m = mass_matrix(g, tree);
    let bias = inverse_dynamics(
        g,
        tree,
        Terms {
            velocity: true,
            acceleration: false,
            gravity: true,
        },
    );
    let rhs: Vec<ExprId> = (0..n)
        .map(|i| {
            let t = g.input(Arg::Tau, i);
            g.sub(t, bias[i])
        })
        .collect();
    let mut h = m.clone();
    let mut inv_d = vec![g.zero(); n];
    let mut l = vec![vec![g.zero(); n]; n];
    for k in (0..n).rev() {
        let tol = g.scale(PIVOT_TOLERANCE, m[k][k]);
        let d = g.guard(h[k][k], tol, m[k][k], k);
        let one = g.constant(1.0);
        inv_d[k] = g.div(one, d);
        for i in 0..k {
            if g.is_const(h[k][i], 0.0) {
                continue;
            }
            let a = g.mul(h[k][i], inv_d[k]);
            for j in 0..=i {
                if g.is_const(h[k][j], 0.0) {
                    continue;
                }
                let p = g.mul(h[k][j], a);
                h[i][j] = g.sub(h[i][j], p);
                h[j][i] = h[i][j];
            }
            l[k][i] = a;
        }
    }
    // Lᵀ y = b (from the last row up), z = D⁻¹ y, L x = z (from the first row down).
    let mut y = rhs;
    for k in (0..n).rev() {
        for j in (k + 1)..n {
            if !g.is_const(l[j][k], 0.0) {
                let p = g.mul(l[j][k], y[j]);
                y[k] = g.sub(y[k], p);
            }
        }
    }
    let mut x: Vec<ExprId> = (0..n).map(|k| g.mul(y[k], inv_d[k])).collect();
    for k in 0..n {
        for i in 0..k {
            if !g.is_const(l[k][i], 0.0) {
                let p = g.mul(l[k][i], x[i]);
                x[k] = g.sub(x[k], p);
            }
        }
    }
    x
}
