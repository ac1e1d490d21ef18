//! Regrouped (base) inertial parameters (Khalil & Kleinfinger 1987; Khalil & Dombre 2002, §9.4 /
//! §12.5): what a joint's motion cannot reveal is lumped into the parent body.

use runtime::model::JointKind;

use super::frames::{snapped_sum, transfer_into};
use super::links::Tree;

impl Tree {
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
    pub(super) fn regroup(&mut self, lump_xx: &[bool]) {
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
}
