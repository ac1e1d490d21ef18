//! Symbolic dynamics of a kinematic tree: the NOC products `Tᵀ(M ṫ + W M t − w^G)` and
//! `TᵀMT` built in the expression DAG with the cheap association (docs/method.md,
//! "Evaluation order").
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
//!
//! # Fewer operations, same efforts
//! Every function is linear in the inertial parameters and invariant under the choice of body
//! frames, which leaves room to make the generated code cheaper without changing a single
//! output (beyond rounding). The tricks, after Khalil & Kleinfinger, "Minimum operations and
//! minimum parameters of the dynamic models of tree structure robots", IEEE J. Robotics &
//! Automation 3(6), 1987, and Khalil & Dombre, *Modeling, Identification and Control of
//! Robots*, 2002, ch. 9 and 12:
//! * **Regrouped (base) inertial parameters** (`Tree::regroup`): what a joint's motion cannot
//!   reveal is lumped into the parent body — mass, axial first moment and one transverse moment
//!   of inertia across a revolute joint, the whole rotational inertia across a prismatic one —
//!   and dropped at the fixed base. Most masses become zero, so most body forces shrink to
//!   `U h` with a two-component `h`.
//! * **Free frame choices** (`Tree::choose`): any point of a joint axis can be the body origin
//!   (Khalil's modified-DH freedom), the body axes can be turned about the joint axis, and a
//!   constant turn of the joint frame can be moved into the joint angle (`sin_cos(q + γ)`, one
//!   addition). A greedy search tries the choices that zero an offset coordinate, a rotation
//!   entry, a first moment or a product of inertia, and keeps those that lower the operation
//!   count of inverse dynamics plus mass matrix. Origins stay within the model's length scale.
//! * **Per-body moment forms** (in [`inverse_dynamics`]): about the origin or the mass centre;
//!   gyroscopic term from the products `ω_a ω_b` shared with `U`, or as `ω × (Jω)`; and the
//!   axial inertia `J_zz` optionally apart, resolved in the joint frame where it needs no
//!   rotation back to the parent. The cheapest by marginal operation count is kept.

use runtime::model::{Drive, JointKind, Mat3, Model, Vec3, mat_mul, mat_vec, transpose};

use crate::sym::{Arg, ExprId, Graph, Node};

/// A symbolic 3-vector.
pub type V3 = [ExprId; 3];
/// A symbolic 3×3 matrix (row-major).
pub type M3 = [[ExprId; 3]; 3];

/// One joint + body of the canonical tree (axis `+z` in the joint frame), with inertial
/// parameters about the body-frame origin (possibly regrouped, see `Tree::regroup`).
#[derive(Clone, Debug)]
struct Link {
    kind: JointKind,
    parent: Option<usize>,
    /// Constant rotation of the joint frame (q = 0) in the parent body frame.
    rot: Mat3,
    /// Joint angle offset: the joint turns by `Rz(q + phase)` (revolute).
    phase: f64,
    /// Constant translation of the joint frame in the parent body frame.
    trans: Vec3,
    mass: f64,
    /// First moment of mass `m c` (body frame).
    h: Vec3,
    /// Inertia about the body-frame origin (body frame).
    j: Mat3,
    /// Mass and axial first moment that `Tree::regroup` moved to the parent.
    lumped: (f64, f64),
    /// The model's body frame → this link's frame: `x_link = A x_body − d e_z` as `(A, d)`
    /// (run-time payloads are given in the body frame).
    to_link: (Mat3, f64),
}

impl Link {
    /// Mass centre and inertia about it (body frame), when the (regrouped) mass is not zero.
    fn centre(&self) -> Option<(Vec3, Mat3)> {
        if self.mass == 0.0 {
            return None;
        }
        let m = self.mass;
        let c = [self.h[0] / m, self.h[1] / m, self.h[2] / m];
        let mut ic = self.j;
        for r in 0..3 {
            for s in r..3 {
                let mut terms = vec![self.j[r][s], m * c[r] * c[s]];
                if r == s {
                    terms.extend([-m * c[0] * c[0], -m * c[1] * c[1], -m * c[2] * c[2]]);
                }
                ic[r][s] = snapped_sum(&terms);
                ic[s][r] = ic[r][s];
            }
        }
        Some((c, ic))
    }
}

/// The tree with every joint axis turned onto `+z`.
#[derive(Clone, Debug)]
pub struct Tree {
    links: Vec<Link>,
    gravity: Vec3,
    /// Per joint: friction and rotor inertia (added after the rigid-body sweeps).
    drives: Vec<Drive>,
    /// Run-time parameters (`[scene] parameters = "runtime"`): the links of the payload and of
    /// the run-time bodies, and the Coulomb speed scale; the drive coefficients are then inputs
    /// too.
    params: Option<ParamLayout>,
}

/// What [`Tree::with_runtime_params`] makes an input.
#[derive(Clone, Debug)]
struct ParamLayout {
    /// Rigid bodies with run-time inertial parameters: `(link, first index)` of the payload
    /// (index 0) and of each run-time body ([`body_param_index`]). Each enters as a payload on
    /// its link.
    rigid: Vec<(usize, usize)>,
    coulomb_velocity: f64,
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

/// A body in the canonical frames, before the origin choice: mass centre and inertia about it.
#[derive(Clone, Debug)]
struct Canonical {
    kind: JointKind,
    parent: Option<usize>,
    rot: Mat3,
    trans: Vec3,
    mass: f64,
    c: Vec3,
    ic: Mat3,
    /// `Q_i`: the canonical body axes in the model's body frame (`e_z` along the axis).
    q: Mat3,
}

/// The free choices of [`Tree::build`], per body: where its origin sits on its joint axis
/// (a shift along `z` from the canonical origin) and, for a revolute joint, which of `J_xx`,
/// `J_yy` the regrouping zeroes.
#[derive(Clone, Debug, PartialEq)]
struct Choice {
    shift: Vec<f64>,
    lump_xx: Vec<bool>,
    /// Body axes turned about `z` by this angle.
    turn: Vec<f64>,
    /// Joint angle offset `γ` (revolute): the code evaluates `sin_cos(q + γ)` and the joint
    /// frame's constant rotation absorbs `Rz(−γ)`.
    phase: Vec<f64>,
}

/// `Rz(a)`, exact for multiples of π/2.
fn rot_z(a: f64) -> Mat3 {
    let (s, c) = runtime::model::exact_sin_cos(a);
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

/// `a · b` with [`snapped_sum`] entries, and entries within rounding of ±1 made exact.
fn snapped_mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for r in 0..3 {
        for c in 0..3 {
            let v = snapped_sum(&[a[r][0] * b[0][c], a[r][1] * b[1][c], a[r][2] * b[2][c]]);
            m[r][c] = if (v.abs() - 1.0).abs() <= 4.0 * f64::EPSILON {
                v.signum()
            } else {
                v
            };
        }
    }
    m
}

/// `a · v` with [`snapped_sum`] entries.
fn snapped_mat_vec(a: &Mat3, v: &Vec3) -> Vec3 {
    let mut r = [0.0; 3];
    for (k, rk) in r.iter_mut().enumerate() {
        *rk = snapped_sum(&[a[k][0] * v[0], a[k][1] * v[1], a[k][2] * v[2]]);
    }
    r
}

/// `Σ terms`, or exactly 0 when the sum is below the rounding level of its terms (a parameter
/// that cancels analytically — an origin moved onto a mass centre, a product of inertia moved
/// to zero — must become a structural zero, not a 1e-18 that costs a multiplication).
fn snapped_sum(terms: &[f64]) -> f64 {
    let sum: f64 = terms.iter().sum();
    let mag: f64 = terms.iter().map(|t| t.abs()).sum();
    if sum.abs() <= 32.0 * f64::EPSILON * mag {
        0.0
    } else {
        sum
    }
}

/// Inertial parameters `(m, h, J)` of a body (first moment `h` and inertia `J` about its frame
/// origin) moved to a frame in which that body's frame has rotation `rot` and origin `p` (the
/// parallel-axis theorem): `h' = m p + R h`, `J' = R J Rᵀ + m (p·p 1 − p pᵀ) + 2 (p·Rh) 1 − Rh pᵀ
/// − p (Rh)ᵀ`; added to `(hp, jp)` with [`snapped_sum`].
fn transfer_into(rot: &Mat3, p: &Vec3, m: f64, h: &Vec3, j: &Mat3, hp: &mut Vec3, jp: &mut Mat3) {
    let rh = snapped_mat_vec(rot, h);
    let rj = snapped_mat_mul(rot, &snapped_mat_mul(j, &transpose(rot)));
    for r in 0..3 {
        for s in r..3 {
            let mut terms = vec![
                jp[r][s],
                rj[r][s],
                -m * p[r] * p[s],
                -rh[r] * p[s],
                -p[r] * rh[s],
            ];
            if r == s {
                for k in 0..3 {
                    terms.push(m * p[k] * p[k]);
                    terms.push(2.0 * p[k] * rh[k]);
                }
            }
            jp[r][s] = snapped_sum(&terms);
            jp[s][r] = jp[r][s];
        }
        hp[r] = snapped_sum(&[hp[r], m * p[r], rh[r]]);
    }
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
    /// Canonicalize a validated model (each body frame `B_i` becomes `B_i Q_i` with
    /// `Q_i e_z = axis_i`, so the motion is about (along) `+z`), then choose the body origins
    /// on the joint axes and regroup the inertial parameters so that the generated code is
    /// cheapest (see `Tree::choose`).
    pub fn new(model: &Model) -> Tree {
        let canon = Self::canonical(model);
        let mut tree = Self::choose(&canon, model.gravity);
        tree.drives = model.joints.iter().map(|j| j.drive).collect();
        tree
    }

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

    fn canonical(model: &Model) -> Vec<Canonical> {
        let qs: Vec<Mat3> = model
            .joints
            .iter()
            .map(|j| frame_with_z_along(&j.axis))
            .collect();
        let mut links = Vec::with_capacity(model.dof());
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
            links.push(Canonical {
                kind: joint.kind,
                parent: joint.parent,
                rot,
                trans,
                mass: body.mass,
                c: mat_vec(&qt, &body.com),
                ic: mat_mul(&qt, &mat_mul(&body.inertia, &qs[i])),
                q: qs[i],
            });
        }
        links
    }

    /// The tree for one [`Choice`]: body origins moved along their axes, then regrouped.
    fn build(canon: &[Canonical], gravity: Vec3, choice: &Choice) -> Tree {
        let mut links = Vec::with_capacity(canon.len());
        for (i, b) in canon.iter().enumerate() {
            let d = choice.shift[i];
            // New origin o + d e_z: the joint frame moves by d along its axis (R e_z d in the
            // parent), the parent's own shift moves the other way.
            let dp = b.parent.map_or(0.0, |p| choice.shift[p]);
            let trans = [
                snapped_sum(&[b.trans[0], b.rot[0][2] * d]),
                snapped_sum(&[b.trans[1], b.rot[1][2] * d]),
                snapped_sum(&[b.trans[2], b.rot[2][2] * d, -dp]),
            ];
            let c = [b.c[0], b.c[1], snapped_sum(&[b.c[2], -d])];
            // Turned axes: parent axes by Rz(β_p), own by Rz(β_i), joint phase γ_i:
            // rot' = Rz(β_p)ᵀ rot Rz(β_i − γ_i); trans' = Rz(β_p)ᵀ trans; c' = Rz(β_i)ᵀ c.
            let tp = transpose(&rot_z(b.parent.map_or(0.0, |p| choice.turn[p])));
            let phase = match b.kind {
                JointKind::Revolute => choice.phase[i],
                JointKind::Prismatic => 0.0,
            };
            let rot = snapped_mat_mul(
                &tp,
                &snapped_mat_mul(&b.rot, &rot_z(choice.turn[i] - phase)),
            );
            let trans = snapped_mat_vec(&tp, &trans);
            let ti = rot_z(choice.turn[i]);
            let c = snapped_mat_vec(&transpose(&ti), &c);
            let ic = snapped_mat_mul(&transpose(&ti), &snapped_mat_mul(&b.ic, &ti));
            let m = b.mass;
            // Inertia about the origin: I_c + m (c·c 1 − c cᵀ).
            let mut j = ic;
            for r in 0..3 {
                for s in r..3 {
                    let mut terms = vec![ic[r][s], -m * c[r] * c[s]];
                    if r == s {
                        terms.extend([m * c[0] * c[0], m * c[1] * c[1], m * c[2] * c[2]]);
                    }
                    j[r][s] = snapped_sum(&terms);
                    j[s][r] = j[r][s];
                }
            }
            links.push(Link {
                kind: b.kind,
                parent: b.parent,
                rot,
                phase,
                trans,
                mass: m,
                h: [m * c[0], m * c[1], m * c[2]],
                j,
                lumped: (0.0, 0.0),
                to_link: (mat_mul(&transpose(&ti), &transpose(&b.q)), d),
            });
        }
        let drives = vec![Drive::NONE; links.len()];
        let mut tree = Tree {
            links,
            gravity,
            drives,
            params: None,
        };
        tree.regroup(&choice.lump_xx);
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
    ///   mass, `h_z` and `A` (`J_yy`, Khalil's `YY_j`, or `J_xx`) move to the parent.
    /// * Prismatic joint: the body does not turn relative to its parent, so its whole rotational
    ///   inertia (a pure moment of inertia, `m = 0`, `h = 0`) moves to the parent.
    fn regroup(&mut self, lump_xx: &[bool]) {
        for i in (0..self.links.len()).rev() {
            let l = &mut self.links[i];
            let (m, h, j) = match l.kind {
                JointKind::Revolute => {
                    let (keep, zero) = if lump_xx[i] { (1, 0) } else { (0, 1) };
                    let a = l.j[zero][zero];
                    let moved = (
                        l.mass,
                        [0.0, 0.0, l.h[2]],
                        [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0; 3]],
                    );
                    l.lumped = (l.mass, l.h[2]);
                    l.mass = 0.0;
                    l.h[2] = 0.0;
                    l.j[keep][keep] = snapped_sum(&[l.j[keep][keep], -a]);
                    l.j[zero][zero] = 0.0;
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
                let lp = &mut self.links[p];
                lp.mass += m;
                transfer_into(&rot, &trans, m, &h, &j, &mut lp.h, &mut lp.j);
            }
        }
    }

    /// Operation count that `Tree::choose` minimizes: inverse dynamics plus mass matrix (the
    /// other functions are parts or consumers of these).
    fn cost(&self) -> usize {
        let mut g = Graph::new();
        let id = inverse_dynamics(&mut g, self, Terms::ALL);
        let mm: Vec<ExprId> = mass_matrix(&mut g, self).concat();
        // Each function is scheduled on its own, so count each cone separately.
        let count = |roots: &[ExprId]| {
            let mut p = Paid::default();
            p.pay(&g, roots);
            p.0.iter()
                .enumerate()
                .filter(|&(k, &b)| b && is_flop(g.node(ExprId(k as u32))))
                .count()
        };
        count(&id) + count(&mm)
    }

    /// Greedy search over the [`Choice`]s (the frame freedom of Khalil's modified DH
    /// convention: any point of a joint axis can be a body origin and the body axes can turn
    /// about it, and the kinetic energy does not care): body by body from the tips, try
    /// origins that zero a coordinate of a joint offset or a product of inertia, turns that
    /// zero a coordinate of a first moment, child offset or child axis (or diagonalize `J`'s xy
    /// block), joint phases that make a joint rotation sparser, and the other `J_xx`/`J_yy`
    /// lump; keep whatever lowers [`Tree::cost`].
    fn choose(canon: &[Canonical], gravity: Vec3) -> Tree {
        let n = canon.len();
        let mut choice = Choice {
            shift: vec![0.0; n],
            lump_xx: vec![false; n],
            turn: vec![0.0; n],
            phase: vec![0.0; n],
        };
        // Origins stay within the model's own length scale (a far origin would make the
        // parameters cancel against each other and cost accuracy).
        let norm = |v: &Vec3| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let reach = canon
            .iter()
            .map(|b| norm(&b.trans).max(norm(&b.c)))
            .fold(0.0, f64::max);
        let mut best = Self::build(canon, gravity, &choice);
        let mut best_cost = best.cost();
        // Choices already tried (exact keys: the same choice always costs the same).
        let key = |c: &Choice| -> Vec<u64> {
            let bits = |v: &Vec<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let mut k = bits(&c.shift);
            k.extend(bits(&c.turn));
            k.extend(bits(&c.phase));
            k.extend(c.lump_xx.iter().map(|&b| b as u64));
            k
        };
        let mut tried: rustc_hash::FxHashSet<Vec<u64>> = Default::default();
        tried.insert(key(&choice));
        // One sweep from the tips: each body decided once, in the same context whatever follows
        // it, so that a chain of n + 1 joints costs a chain of n plus one joint (repeated sweeps
        // find a little more but make the count of a growing chain erratic).
        for i in (0..n).rev() {
            for cand in best.candidates(&choice, i) {
                if cand.shift[i].abs() > reach || !tried.insert(key(&cand)) {
                    continue;
                }
                let t = Self::build(canon, gravity, &cand);
                let c = t.cost();
                if c < best_cost {
                    best = t;
                    best_cost = c;
                    choice = cand;
                }
            }
        }
        best
    }

    /// Move the origins of the children of `i` whose axes are parallel to `i`'s by `d` along
    /// that common direction (recursively), so that their offsets do not change when `i`'s
    /// origin moves by `d`. `false` when there is no such child.
    fn shift_parallel_children(&self, choice: &mut Choice, i: usize, d: f64) -> bool {
        let mut any = false;
        for (k, c) in self.links.iter().enumerate() {
            let z = c.rot[2][2];
            if c.parent == Some(i) && (z == 1.0 || z == -1.0) {
                choice.shift[k] += z * d;
                self.shift_parallel_children(choice, k, z * d);
                any = true;
            }
        }
        any
    }

    /// Alternative choices for body `i`, from the current tree.
    fn candidates(&self, choice: &Choice, i: usize) -> Vec<Choice> {
        let l = &self.links[i];
        let mut deltas = Vec::new();
        // Zero a coordinate of the body's own offset in its parent.
        for k in 0..3 {
            if l.rot[k][2] != 0.0 && l.trans[k] != 0.0 {
                deltas.push(-l.trans[k] / l.rot[k][2]);
            }
        }
        // Zero the axial coordinate of a child's offset.
        for c in &self.links {
            if c.parent == Some(i) && c.trans[2] != 0.0 {
                deltas.push(c.trans[2]);
            }
        }
        // Put the origin level with the mass centre of what is lumped into the parent.
        if l.lumped.0 != 0.0 && l.lumped.1 != 0.0 {
            deltas.push(l.lumped.1 / l.lumped.0);
        }
        // Zero a product of inertia J_xz or J_yz (it changes by d h_x, d h_y).
        for k in 0..2 {
            if l.h[k] != 0.0 && l.j[k][2] != 0.0 {
                deltas.push(-l.j[k][2] / l.h[k]);
            }
        }
        let mut out = Vec::new();
        for d in deltas {
            if d.is_finite() {
                let mut c = choice.clone();
                c.shift[i] += d;
                out.push(c.clone());
                // The same, with the subtree of parallel axes moved along (their offsets kept).
                if self.shift_parallel_children(&mut c, i, d) {
                    out.push(c);
                }
            }
        }
        if l.kind == JointKind::Revolute {
            let mut c = choice.clone();
            c.lump_xx[i] = !c.lump_xx[i];
            out.push(c);
            // Joint phase: make the joint frame's rotation sparser (zero an entry of its x or
            // y column), or drop the phase.
            let r = &l.rot;
            let mut turns = Vec::new();
            for k in 0..3 {
                if r[k][0] != 0.0 && r[k][1] != 0.0 {
                    // (Zeroing r[k][1] instead only swaps the roles of x and y.)
                    turns.push((-r[k][0]).atan2(r[k][1]));
                }
            }
            for a in turns {
                let mut c = choice.clone();
                c.phase[i] -= a;
                out.push(c);
            }
            if choice.phase[i] != 0.0 {
                let mut c = choice.clone();
                c.phase[i] = 0.0;
                out.push(c);
            }
        }
        // Body axes turned about z to zero a coordinate of a 2-vector in the xy plane: the first
        // moment, a child's offset or a child's axis; or to diagonalize J's xy block.
        let mut vs: Vec<[f64; 2]> = vec![[l.h[0], l.h[1]]];
        for c in &self.links {
            if c.parent == Some(i) {
                vs.push([c.trans[0], c.trans[1]]);
                for k in 0..3 {
                    vs.push([c.rot[0][k], c.rot[1][k]]);
                }
            }
        }
        let mut turns = Vec::new();
        for v in vs {
            if v[0] != 0.0 && v[1] != 0.0 {
                turns.push(v[1].atan2(v[0]));
            }
        }
        if l.j[0][1] != 0.0 {
            turns.push(0.5 * (2.0 * l.j[0][1]).atan2(l.j[0][0] - l.j[1][1]));
        }
        for a in turns {
            let mut c = choice.clone();
            c.turn[i] += a;
            out.push(c.clone());
            if l.kind == JointKind::Revolute {
                // The same with the joint frame's rotation kept (the phase follows).
                c.phase[i] += a;
                out.push(c);
            }
        }
        // A child's axis turned into the xz plane of this body and the child's joint phase
        // chosen with it: the child's joint rotation becomes `Ry(α)` (the two moves of the DH
        // convention; either alone may not pay).
        for (k, ch) in self.links.iter().enumerate() {
            let z = [ch.rot[0][2], ch.rot[1][2]];
            if ch.parent != Some(i)
                || ch.kind != JointKind::Revolute
                || (z[0] == 0.0 && z[1] == 0.0)
            {
                continue;
            }
            let a = z[1].atan2(z[0]);
            let r = snapped_mat_mul(&transpose(&rot_z(a)), &ch.rot);
            // Child's x axis along this body's y (its x and z components zero).
            let b = (-r[0][0]).atan2(r[0][1]);
            let mut c = choice.clone();
            c.turn[i] += a;
            if l.kind == JointKind::Revolute {
                c.phase[i] += a;
            }
            c.phase[k] -= b;
            out.push(c);
        }
        out
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

    /// Gyroscopic moment `ω × (I ω)` formed as written: `Iω`, then the cross product.
    fn gyro_cross(&mut self, inertia: &Mat3, w: V3) -> V3 {
        let im = self.cm(inertia);
        let iw = self.mat_vec(&im, w);
        self.cross(w, iw)
    }

    /// `Rz(q_i)ᵀ v` (revolute), `v` (prismatic).
    fn rz_t(&mut self, i: usize, v: V3) -> V3 {
        self.rotate_z(i, v, true)
    }
    /// `Rz(q_i) v` (revolute), `v` (prismatic).
    fn rz(&mut self, i: usize, v: V3) -> V3 {
        self.rotate_z(i, v, false)
    }
    /// `Rz(q_i) v`, or `Rz(q_i)ᵀ v` when `transpose`; the identity for prismatic joints.
    fn rotate_z(&mut self, i: usize, v: V3, transpose: bool) -> V3 {
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

/// Nodes already needed (their cost is sunk), indexed by node id.
#[derive(Clone, Default)]
struct Paid(Vec<bool>);

impl Paid {
    fn contains(&self, id: ExprId) -> bool {
        self.0.get(id.0 as usize).copied().unwrap_or(false)
    }
    /// Add the cone of `roots`.
    fn pay(&mut self, g: &Graph, roots: &[ExprId]) {
        if self.0.len() < g.len() {
            self.0.resize(g.len(), false);
        }
        let mut stack: Vec<ExprId> = roots.to_vec();
        while let Some(id) = stack.pop() {
            if !self.0[id.0 as usize] {
                self.0[id.0 as usize] = true;
                stack.extend(g.operands(id));
            }
        }
    }
}

/// `true` for the nodes that [`crate::schedule::OpCount::flops`] counts.
fn is_flop(n: Node) -> bool {
    matches!(
        n,
        Node::Add(..)
            | Node::Sub(..)
            | Node::Mul(..)
            | Node::Div(..)
            | Node::Neg(..)
            | Node::Sqrt(..)
    )
}

/// Arithmetic operations (as counted by [`crate::schedule::OpCount::flops`]) that `roots` need
/// beyond the nodes in `paid`: the marginal cost of a choice.
fn marginal_flops(g: &Graph, roots: &[ExprId], paid: &Paid) -> usize {
    let mut seen: rustc_hash::FxHashSet<ExprId> = Default::default();
    let mut stack: Vec<ExprId> = roots.to_vec();
    let mut flops = 0;
    while let Some(id) = stack.pop() {
        if paid.contains(id) || !seen.insert(id) {
            continue;
        }
        if is_flop(g.node(id)) {
            flops += 1;
        }
        stack.extend(g.operands(id));
    }
    flops
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
    /// Joint friction (the drives' dissipative efforts `δ(q̇)`; `q̇` is an input).
    pub friction: bool,
}

impl Terms {
    /// Everything: inverse dynamics.
    pub const ALL: Terms = Terms {
        velocity: true,
        acceleration: true,
        gravity: true,
        friction: true,
    };
    /// Nothing (switch terms on with struct update syntax).
    pub const NONE: Terms = Terms {
        velocity: false,
        acceleration: false,
        gravity: false,
        friction: false,
    };
}

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

/// `Tᵀ (M ṫ + W M t − w^G)`: inverse dynamics (or its parts), one effort per joint.
pub fn inverse_dynamics(g: &mut Graph, tree: &Tree, terms: Terms) -> Vec<ExprId> {
    inverse_dynamics_sunk(g, tree, terms, &[])
}

/// [`inverse_dynamics`] in a function that also needs the nodes of `sunk` (forward dynamics:
/// the mass matrix), which the run-time bodies' choice of wrench form counts as paid.
fn inverse_dynamics_sunk(g: &mut Graph, tree: &Tree, terms: Terms, sunk: &[ExprId]) -> Vec<ExprId> {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let zero = s.g.zero();
    // `arg[i]` for every joint when the term is on, else structural zeros.
    let inputs = |g: &mut Graph, arg: Arg, on: bool| -> Vec<ExprId> {
        (0..n)
            .map(|i| if on { g.input(arg, i) } else { zero })
            .collect()
    };
    let qd = inputs(s.g, Arg::Qd, terms.velocity);
    let qdd = inputs(s.g, Arg::Qdd, terms.acceleration);
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
    // ω and ω̇ resolved in the joint frame (the body frame before the joint's own rotation).
    let mut omega_j: Vec<V3> = Vec::with_capacity(n);
    let mut omegad_j: Vec<V3> = Vec::with_capacity(n);
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
                // ω_i = ω_p + e q̇; ω̇_i = ω̇_p + e q̈ + ω_p × e q̇ (e = +z), in either frame.
                let r0 = s.cm(&l.rot);
                let mut frames = [(wp, wdp); 2];
                for (k, fr) in frames.iter_mut().enumerate() {
                    let (mut w_in, mut wd_in) = (s.mat_t_vec(&r0, wp), s.mat_t_vec(&r0, wdp));
                    if k == 0 {
                        w_in = s.rz_t(i, w_in);
                        wd_in = s.rz_t(i, wd_in);
                    }
                    let w = [w_in[0], w_in[1], s.g.add(w_in[2], qd[i])];
                    let x = s.g.mul(w_in[1], qd[i]);
                    let y = s.g.mul(w_in[0], qd[i]);
                    let wd = [
                        s.g.add(wd_in[0], x),
                        s.g.sub(wd_in[1], y),
                        s.g.add(wd_in[2], qdd[i]),
                    ];
                    *fr = (w, wd);
                }
                omega_j.push(frames[1].0);
                omegad_j.push(frames[1].1);
                (frames[0].0, frames[0].1, a)
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
                omega_j.push(w);
                omegad_j.push(wd);
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
    let mut extra_moment: Vec<V3> = Vec::with_capacity(n);
    // Nodes already needed by the wrenches chosen so far (their cost is sunk).
    let mut paid = Paid::default();
    for i in 0..n {
        let l = &tree.links[i];
        let m = s.c(l.mass);
        let h = s.cv(&l.h);
        let (w, wd, a) = (omega[i], omegad[i], acc[i]);
        let ma = s.scale3(m, a);
        let u = s.u_matrix(w, wd);
        let uh = s.mat_vec(&u, h);
        let f = s.add3(ma, uh);
        // Moment about the origin, equivalent forms; keep the cheapest for this body:
        // J ω̇ + ω × Jω + h × a (inertia about the origin), or
        // I_c ω̇ + ω × I_c ω + c × f (about the mass centre, then moved);
        // the gyroscopic term either from the shared products ω_a ω_b ([`Sym::gyro`]) or as
        // ω × (Jω) (cheaper for a full inertia tensor); and the axial moment of inertia
        // `diag(0, 0, J_zz)` either with the rest or apart, in the joint frame: it is
        // unchanged by the joint's rotation, so its moment needs no rotation back to the
        // parent (`extra`, added after the rotation).
        let (wj, wdj) = (omega_j[i], omegad_j[i]);
        let mut tensors: Vec<(Mat3, Option<V3>)> = vec![(l.j, None)];
        if let Some((lc, lic)) = l.centre() {
            let c = s.cv(&lc);
            let cf = s.cross(c, f);
            tensors.push((lic, Some(cf)));
        }
        let ha = s.cross(h, a);
        let mut forms: Vec<(V3, V3)> = Vec::new();
        for (tensor, moved) in tensors {
            let mut splits = vec![(tensor, 0.0)];
            if l.kind == JointKind::Revolute && tensor[2][2] != 0.0 {
                let mut rest = tensor;
                rest[2][2] = 0.0;
                splits.push((rest, tensor[2][2]));
            }
            for (rest, axial) in splits {
                let extra = if axial != 0.0 {
                    let ax = [[0.0; 3], [0.0; 3], [0.0, 0.0, axial]];
                    let g = s.gyro_cross(&ax, wj);
                    [g[0], g[1], s.g.scale(axial, wdj[2])]
                } else {
                    s.zero3()
                };
                let rm = s.cm(&rest);
                let iwd = s.mat_vec(&rm, wd);
                let last = match moved {
                    Some(cf) => cf,
                    None => ha,
                };
                for cross_form in [false, true] {
                    let gyro = if cross_form {
                        s.gyro_cross(&rest, w)
                    } else {
                        s.gyro(&rest, w)
                    };
                    let nb = s.add3(iwd, gyro);
                    forms.push((s.add3(nb, last), extra));
                }
            }
        }
        let mut best = usize::MAX;
        let mut choice = forms[0];
        for &(nb, extra) in &forms {
            let rotated = s.rz(i, nb);
            let rotated = s.add3(rotated, extra);
            let roots = [f[0], f[1], f[2], rotated[0], rotated[1], rotated[2]];
            let c = marginal_flops(s.g, &roots, &paid);
            if c < best {
                best = c;
                choice = (nb, extra);
            }
        }
        let (nb, extra) = choice;
        paid.pay(
            s.g,
            &[
                f[0], f[1], f[2], nb[0], nb[1], nb[2], extra[0], extra[1], extra[2],
            ],
        );
        force.push(f);
        moment.push(choice.0);
        extra_moment.push(choice.1);
    }
    // A run-time payload or body on link b: its Newton–Euler wrench about the link origin
    // (eq. 12), `f = m a + ω̇ × h + ω × (ω × h)`, `n = J ω̇ + ω × J ω + h × a`.
    let rigid = tree.params.as_ref().map_or(&[][..], |p| &p.rigid[..]);
    for &(b, at) in rigid {
        let (m, h, j) = payload_params(&mut s, b, at);
        let (w, wd, a) = (omega[b], omegad[b], acc[b]);
        let ma = s.scale3(m, a);
        let u = s.u_matrix(w, wd);
        let uh = s.mat_vec(&u, h);
        let f = s.add3(ma, uh);
        let jwd = s.mat_vec(&j, wd);
        let jw = s.mat_vec(&j, w);
        let gyro = s.cross(w, jw);
        let ha = s.cross(h, a);
        let nb = s.add3(jwd, gyro);
        let nb = s.add3(nb, ha);
        let (f, nb) = if at == 0 {
            (f, nb)
        } else {
            // A run-time body: the same wrench formed about its mass centre,
            // `f = m (a + U c)`, `n = I_c ω̇ + ω × I_c ω + c × f`, needs no inertia about the
            // origin; keep the cheaper form (the payload keeps the first).
            let (m, c, ic) = centre_params(&mut s, b, at);
            let uc = s.mat_vec(&u, c);
            let ac = s.add3(a, uc);
            let fc = s.scale3(m, ac);
            let iwd = s.mat_vec(&ic, wd);
            let iw = s.mat_vec(&ic, w);
            let gyro = s.cross(w, iw);
            let cf = s.cross(c, fc);
            let nc = s.add3(iwd, gyro);
            let nc = s.add3(nc, cf);
            let mut known = paid.clone();
            known.pay(s.g, sunk);
            let cost = |s: &Sym<'_>, f: &V3, n: &V3| {
                marginal_flops(s.g, &[f[0], f[1], f[2], n[0], n[1], n[2]], &known)
            };
            let chosen = if cost(&s, &fc, &nc) < cost(&s, &f, &nb) {
                (fc, nc)
            } else {
                (f, nb)
            };
            let (f, n) = chosen;
            paid.pay(s.g, &[f[0], f[1], f[2], n[0], n[1], n[2]]);
            chosen
        };
        force[b] = s.add3(force[b], f);
        moment[b] = s.add3(moment[b], nb);
    }
    // Backward sweep: Tᵀ w, accumulated from the tips (eq. 24).
    let mut tau = vec![zero; n];
    for i in (0..n).rev() {
        tau[i] = match tree.links[i].kind {
            JointKind::Revolute => s.g.add(moment[i][2], extra_moment[i][2]),
            JointKind::Prismatic => force[i][2],
        };
        if let Some(p) = tree.links[i].parent {
            let f = s.parent_frame(i, force[i]);
            let nn = s.rz(i, moment[i]);
            let nn = s.add3(nn, extra_moment[i]);
            let r0 = s.cm(&tree.links[i].rot);
            let nn = s.mat_vec(&r0, nn);
            let off = s.offset(i);
            let pf = s.cross(off, f);
            let nn = s.add3(nn, pf);
            force[p] = s.add3(force[p], f);
            moment[p] = s.add3(moment[p], nn);
        }
    }
    match &tree.params {
        None => add_drive_efforts(s.g, &tree.drives, terms, &mut tau, |g, arg, i| {
            g.input(arg, i)
        }),
        Some(pl) => add_param_drive_efforts(s.g, n, pl.coulomb_velocity, terms, &mut tau),
    }
    tau
}

/// [`add_drive_efforts`] with the coefficients read from the run-time parameters.
fn add_param_drive_efforts(g: &mut Graph, n: usize, vs: f64, terms: Terms, tau: &mut [ExprId]) {
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

/// The inertial parameters of a run-time payload or body (`Arg::P` entries `at..at + 10`) in
/// link `b`'s frame: mass, first moment `m c` and inertia about the link origin
/// (`x_link = A x_body − d e_z`; parallel-axis theorem).
fn payload_params(s: &mut Sym<'_>, b: usize, at: usize) -> (ExprId, V3, M3) {
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
fn centre_params(s: &mut Sym<'_>, b: usize, at: usize) -> (ExprId, V3, M3) {
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
    let rigid = tree.params.as_ref().map_or(&[][..], |p| &p.rigid[..]);
    for &(b, at) in rigid {
        let (m, h, j) = payload_params(&mut s, b, at);
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

/// Relative pivot tolerance of the generated factorization: pivot `k` must exceed
/// `PIVOT_TOLERANCE · I_kk` (the diagonal entry it came from).
pub const PIVOT_TOLERANCE: f64 = 1e-12;

/// Forward dynamics `q̈ = I⁻¹ (τ − C q̇ + γ)`: composite-body `I`, the bias by the inverse
/// dynamics with `q̈ = 0`, then an `Lᵀ D L` factorization eliminated from the tips (no fill-in
/// for trees; Featherstone, RBDA §6.5) with checked pivots.
pub fn forward_dynamics(g: &mut Graph, tree: &Tree) -> Vec<ExprId> {
    let n = tree.dof();
    let m = mass_matrix(g, tree);
    let bias = inverse_dynamics_sunk(
        g,
        tree,
        Terms {
            acceleration: false,
            ..Terms::ALL
        },
        &m.concat(),
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
        let tol = g.scale(crate::scalar::tolerance(PIVOT_TOLERANCE), m[k][k]);
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
