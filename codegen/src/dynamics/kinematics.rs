//! Frame kinematics of a tree (`[scene] frames`): the pose of a frame fixed to a body, its
//! 6 × n Jacobian and `J̇ q̇`, built in the DAG like the dynamics (so constants fold, structural
//! zeros vanish and the shared products are formed once per function).
//!
//! Convention (docs/method.md, "Frame kinematics"): a frame's twist is `[ω; v]`, angular first
//! as everywhere in nocdyn, both in base-frame components, `v` the velocity of the frame's
//! origin (Pinocchio's `LOCAL_WORLD_ALIGNED`, angular first). `J q̇` is that twist and
//! `J q̈ + J̇ q̇ = [ω̇; p̈]`, the frame's classical acceleration.
//!
//! The links' frames are the canonical ones ([`Tree`]: every joint axis `+z`, origins on the
//! axes), so a link's joint axis in the base is the third column of its rotation and its origin
//! is a point of that axis: a revolute joint's column is `[z_j; z_j × (p − o_j)]`, a prismatic
//! one's `[0; z_j]`. `J̇ q̇` is the acceleration at `q̈ = 0`, by the chain recursion in base
//! components (`ω̇` and the origins' accelerations), then moved to the frame's origin.

use runtime::model::{JointKind, Mat3, Transform, Vec3, mat_mul, mat_vec};

use crate::sym::{Arg, ExprId, Graph};

use super::algebra::Sym;
use super::links::Tree;
use super::{M3, V3};

/// Which of a frame's functions to build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FramePart {
    /// `pose(q)`.
    Pose,
    /// `jacobian(q)`.
    Jacobian,
    /// `jacobian_dot_qd(q, q̇)`.
    JacobianDotQd,
}

/// A link's pose in the base: rotation and origin.
#[derive(Clone, Copy)]
struct Placed {
    rot: M3,
    origin: V3,
    /// The link origin relative to its parent's, in base components (`R_p · offset`).
    step: V3,
}

/// One of a frame's functions: `body` is the model body it is fixed to (`None`: the base),
/// `placement` its pose in that body's frame. Each function is built in a fresh pass over the
/// graph (nodes are shared through hash-consing), so what one function needs does not shape
/// another's nodes.
pub fn frame_kinematics(
    g: &mut Graph,
    tree: &Tree,
    body: Option<usize>,
    placement: &Transform,
    part: FramePart,
) -> Vec<ExprId> {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let path = body.map_or_else(Vec::new, |b| path_to(tree, b));
    let placed = place(&mut s, &path);
    // The frame in its link's frame (the canonical frame turned and moved by `to_link`).
    let (r_lf, p_lf) = match body {
        Some(b) => in_link(tree, b, placement),
        None => (placement.rotation, placement.translation),
    };
    let (rot_b, origin_b) = match path.last() {
        Some(&b) => (placed[b].unwrap().rot, placed[b].unwrap().origin),
        None => identity(&mut s),
    };
    let plf = s.cv(&p_lf);
    let r_f = mat_mul_const(&mut s, &rot_b, &r_lf);
    let arm = s.mat_vec(&rot_b, plf);
    let p_f = s.add3(origin_b, arm);
    let zero = s.g.zero();
    match part {
        FramePart::Pose => {
            let mut out: Vec<ExprId> = r_f.iter().flatten().copied().collect();
            out.extend(p_f);
            out
        }
        FramePart::Jacobian => {
            let mut jac = vec![zero; 6 * n];
            for &j in &path {
                let p = placed[j].unwrap();
                let z = column(&p.rot, 2);
                let (w, v) = match tree.links[j].kind {
                    JointKind::Revolute => {
                        let d = if Some(&j) == path.last() {
                            arm
                        } else {
                            sub3(&mut s, p_f, p.origin)
                        };
                        let v = s.cross(z, d);
                        (z, v)
                    }
                    JointKind::Prismatic => ([zero; 3], z),
                };
                for k in 0..3 {
                    jac[k * n + j] = w[k];
                    jac[(3 + k) * n + j] = v[k];
                }
            }
            jac
        }
        FramePart::JacobianDotQd => {
            let (omega, alpha, acc) = bias(&mut s, &path, &placed);
            let ww = s.cross(omega, arm);
            let www = s.cross(omega, ww);
            let aw = s.cross(alpha, arm);
            let t = s.add3(aw, www);
            let a = s.add3(acc, t);
            let mut out = alpha.to_vec();
            out.extend(a);
            out
        }
    }
}

/// The joints from the root to body `b`, parents first.
fn path_to(tree: &Tree, b: usize) -> Vec<usize> {
    let mut path = vec![b];
    while let Some(p) = tree.links[*path.last().unwrap()].parent {
        path.push(p);
    }
    path.reverse();
    path
}

/// The frame's pose in its link's frame: `to_link = (A, d)` maps the model body's coordinates
/// to the link's, `x_link = A x_body − d e_z`.
fn in_link(tree: &Tree, b: usize, placement: &Transform) -> (Mat3, Vec3) {
    let (a, d) = tree.links[b].to_link;
    let r = mat_mul(&a, &placement.rotation);
    let mut p = mat_vec(&a, &placement.translation);
    p[2] -= d;
    (r, p)
}

fn identity(s: &mut Sym<'_>) -> (M3, V3) {
    let i = s.cm(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    (i, s.zero3())
}

/// The base poses of the links on `path` (parents first), indexed by link.
fn place(s: &mut Sym<'_>, path: &[usize]) -> Vec<Option<Placed>> {
    let tree = s.tree;
    let mut placed: Vec<Option<Placed>> = vec![None; tree.dof()];
    for &i in path {
        let l = &tree.links[i];
        let (rot_p, origin_p) = match l.parent {
            Some(p) => (placed[p].unwrap().rot, placed[p].unwrap().origin),
            None => identity(s),
        };
        let off = s.offset(i);
        let step = s.mat_vec(&rot_p, off);
        let origin = s.add3(origin_p, step);
        // R_i = R_p · rot_i · Rz(q_i): each row of R_p · rot_i turned by Rz(q_i)ᵀ.
        let m = mat_mul_const(s, &rot_p, &l.rot);
        let rot = [s.rz_t(i, m[0]), s.rz_t(i, m[1]), s.rz_t(i, m[2])];
        placed[i] = Some(Placed { rot, origin, step });
    }
    placed
}

/// `ω`, `ω̇` and the origin's acceleration of the last link of `path` at `q̈ = 0`, base
/// components (zero for an empty path).
fn bias(s: &mut Sym<'_>, path: &[usize], placed: &[Option<Placed>]) -> (V3, V3, V3) {
    let tree = s.tree;
    let (mut omega, mut alpha, mut acc) = (s.zero3(), s.zero3(), s.zero3());
    for &i in path {
        let p = placed[i].unwrap();
        // The origin rides on the parent: α_p × r + ω_p × (ω_p × r).
        let wr = s.cross(omega, p.step);
        let wwr = s.cross(omega, wr);
        let ar = s.cross(alpha, p.step);
        let t = s.add3(ar, wwr);
        acc = s.add3(acc, t);
        let qd = s.g.input(Arg::Qd, i);
        let zq = s.scale3(qd, column(&p.rot, 2));
        let wz = s.cross(omega, zq);
        match tree.links[i].kind {
            JointKind::Revolute => {
                alpha = s.add3(alpha, wz);
                omega = s.add3(omega, zq);
            }
            JointKind::Prismatic => {
                let two = s.add3(wz, wz);
                acc = s.add3(acc, two);
            }
        }
    }
    (omega, alpha, acc)
}

/// `a · c` for a symbolic `a` and a constant `c`.
fn mat_mul_const(s: &mut Sym<'_>, a: &M3, c: &Mat3) -> M3 {
    let c = s.cm(c);
    let cols = [column(&c, 0), column(&c, 1), column(&c, 2)];
    let mut m = *a;
    for r in 0..3 {
        for k in 0..3 {
            m[r][k] = s.dot(a[r], cols[k]);
        }
    }
    m
}

fn column(m: &M3, k: usize) -> V3 {
    [m[0][k], m[1][k], m[2][k]]
}

fn sub3(s: &mut Sym<'_>, a: V3, b: V3) -> V3 {
    [
        s.g.sub(a[0], b[0]),
        s.g.sub(a[1], b[1]),
        s.g.sub(a[2], b[2]),
    ]
}
