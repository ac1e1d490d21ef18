//! The free frame choices and the greedy search over them (`Tree::choose`): body origins moved
//! along the joint axes (Khalil's modified-DH freedom), body axes turned about them, joint phases
//! and the `J_xx`/`J_yy` lump, kept when they lower the operation count of inverse dynamics plus
//! mass matrix.

use runtime::model::{JointKind, Vec3, transpose};

use crate::sym::{ExprId, Graph};

use super::flops::{Paid, is_flop};
use super::frames::{rot_z, snapped_mat_mul};
use super::links::{Canonical, Tree};
use super::{Terms, inverse_dynamics, mass_matrix};

/// The free choices of [`Tree::build`], per body: where its origin sits on its joint axis
/// (a shift along `z` from the canonical origin) and, for a revolute joint, which of `J_xx`,
/// `J_yy` the regrouping zeroes.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Choice {
    pub(super) shift: Vec<f64>,
    pub(super) lump_xx: Vec<bool>,
    /// Body axes turned about `z` by this angle.
    pub(super) turn: Vec<f64>,
    /// Joint angle offset `γ` (revolute): the code evaluates `sin_cos(q + γ)` and the joint
    /// frame's constant rotation absorbs `Rz(−γ)`.
    pub(super) phase: Vec<f64>,
}

impl Tree {
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
    pub(super) fn choose(canon: &[Canonical], gravity: Vec3) -> Tree {
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
        let mut out = Vec::new();
        self.origin_candidates(choice, i, &mut out);
        self.lump_and_phase_candidates(choice, i, &mut out);
        self.turn_candidates(choice, i, &mut out);
        self.child_axis_candidates(choice, i, &mut out);
        out
    }

    /// Origins of body `i` moved along its axis (with and without its subtree of parallel axes).
    fn origin_candidates(&self, choice: &Choice, i: usize, out: &mut Vec<Choice>) {
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
    }

    /// The other `J_xx`/`J_yy` lump and the joint phases of revolute body `i`.
    fn lump_and_phase_candidates(&self, choice: &Choice, i: usize, out: &mut Vec<Choice>) {
        let l = &self.links[i];
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
    }

    /// Body `i`'s axes turned about its joint axis.
    fn turn_candidates(&self, choice: &Choice, i: usize, out: &mut Vec<Choice>) {
        let l = &self.links[i];
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
    }

    /// Children's axes turned into the xz plane of body `i`.
    fn child_axis_candidates(&self, choice: &Choice, i: usize, out: &mut Vec<Choice>) {
        let l = &self.links[i];
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
    }
}
