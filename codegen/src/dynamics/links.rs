//! The [`Tree`]: one [`Link`] per joint and body, in canonical frames where every joint axis is
//! `+z` (a constant change of body axes, folded into the constant origins), and the tree built for
//! one choice of frames (origins moved along the axes, axes turned about them, joint phases),
//! then regrouped (`Tree::regroup`).

use runtime::model::{Drive, JointKind, Mat3, Model, Vec3, mat_mul, mat_vec, transpose};

use super::choice::Choice;
use super::frames::{frame_with_z_along, rot_z, snapped_mat_mul, snapped_mat_vec, snapped_sum};
use super::runtime_params::ParamLayout;

/// One joint + body of the canonical tree (axis `+z` in the joint frame), with inertial
/// parameters about the body-frame origin (possibly regrouped, see `Tree::regroup`).
#[derive(Clone, Debug)]
pub(super) struct Link {
    pub(super) kind: JointKind,
    pub(super) parent: Option<usize>,
    /// Constant rotation of the joint frame (q = 0) in the parent body frame.
    pub(super) rot: Mat3,
    /// Joint angle offset: the joint turns by `Rz(q + phase)` (revolute).
    pub(super) phase: f64,
    /// Constant translation of the joint frame in the parent body frame.
    pub(super) trans: Vec3,
    pub(super) mass: f64,
    /// First moment of mass `m c` (body frame).
    pub(super) h: Vec3,
    /// Inertia about the body-frame origin (body frame).
    pub(super) j: Mat3,
    /// Mass and axial first moment that `Tree::regroup` moved to the parent.
    pub(super) lumped: (f64, f64),
    /// The model's body frame → this link's frame: `x_link = A x_body − d e_z` as `(A, d)`
    /// (run-time payloads are given in the body frame).
    pub(super) to_link: (Mat3, f64),
}

impl Link {
    /// Mass centre and inertia about it (body frame), when the (regrouped) mass is not zero.
    pub(super) fn centre(&self) -> Option<(Vec3, Mat3)> {
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
    pub(super) links: Vec<Link>,
    pub(super) gravity: Vec3,
    /// Per joint: friction and rotor inertia (added after the rigid-body sweeps).
    pub(super) drives: Vec<Drive>,
    /// Run-time parameters (`[scene] parameters = "runtime"`): the links of the payload and of
    /// the run-time bodies, and the Coulomb speed scale; the drive coefficients are then inputs
    /// too.
    pub(super) params: Option<ParamLayout>,
}

/// A body in the canonical frames, before the origin choice: mass centre and inertia about it.
#[derive(Clone, Debug)]
pub(super) struct Canonical {
    pub(super) kind: JointKind,
    pub(super) parent: Option<usize>,
    pub(super) rot: Mat3,
    pub(super) trans: Vec3,
    pub(super) mass: f64,
    pub(super) c: Vec3,
    pub(super) ic: Mat3,
    /// `Q_i`: the canonical body axes in the model's body frame (`e_z` along the axis).
    pub(super) q: Mat3,
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
    pub(super) fn build(canon: &[Canonical], gravity: Vec3, choice: &Choice) -> Tree {
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

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.links.len()
    }
}
