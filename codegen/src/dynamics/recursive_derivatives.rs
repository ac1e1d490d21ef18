//! `∂τ/∂q`, `∂τ/∂q̇` of a tree's inverse dynamics by the recursive analytic route (after
//! Carpentier & Mansard, RSS 2018, and Singh, Russell & Wensing, RA-L 2022; docs/method.md,
//! "Derivatives"): `O(n)` composite quantities per body, then, per pair of joints on one path,
//! four force vectors moved from the outer joint's frame to the inner one's and dotted there.
//!
//! Spatial vectors `[angular; linear]`, each in its body's frame about its origin. With `S_i`
//! the joint's motion (`[e_z; 0]` revolute, `[0; e_z]` prismatic), `V_i`, `A_i` the body's
//! spatial velocity and acceleration (gravity as `−g` of the base), `Ψ̇_i = V_i × S_i`,
//! `Ψ̈_i = A_i × S_i + V_i × Ψ̇_i`, `I^C_i` the composite inertia, `İ_i` its rate in a fixed
//! frame, `H_i` the subtree's momentum and `F_i` its Newton–Euler wrench:
//! * `r₁ = I^C S`, `r₂ = İ S − S ×* H`,
//! * `Y = S ×* F + I^C Ψ̈ + İ Ψ̇ + Ψ̇ ×* H`, `Z = İ S + S ×* H + 2 I^C Ψ̇`,
//!
//! and for `a` on the path from the base to `d` (`a = d` included), all in `a`'s frame:
//! `∂τ_d/∂q_a = r₁_d·Ψ̈_a + r₂_d·Ψ̇_a`, `∂τ_d/∂q̇_a = r₂_d·S_a + 2 r₁_d·Ψ̇_a`,
//! `∂τ_a/∂q_d = S_a·Y_d`, `∂τ_a/∂q̇_d = S_a·Z_d`. Joint friction (a function of `q̇_i` alone)
//! is differentiated by forward mode and added to the diagonal of `∂τ/∂q̇`.
//!
//! Why: moving `q_a` turns the subtree of `a` rigidly about `S_a`; seen from its own frames each
//! body of the subtree only gains `δV = Ψ̇_a` and `δA = Ψ̈_a + Ψ̇_a × V`, so its wrench gains
//! `I Ψ̈_a + İ Ψ̇_a + Ψ̇_a ×* h` (`h` its momentum), and the turn itself adds `S_a ×* F` to the
//! subtree's wrench seen from the joints inboard of `a` (it cancels in `S_dᵀ F_d` for `d` in the
//! subtree). Moving `q̇_a` adds `δV = S_a`, `δA = S_a × V + 2 Ψ̇_a` to the subtree. Summing over
//! a subtree gives the composite quantities, `İ x + x ×* H` being the sum of the bodies'
//! `İ_k x + x ×* h_k`. In the code, `İ x = İ_b x + V ×* (I x) − I (V × x)` with `İ_b` the rate of
//! `I^C` in its body frame (forward mode along `q̇`).

use runtime::model::JointKind;

use crate::sym::derivative::Derivative;
use crate::sym::{Arg, ExprId, Graph};

use super::V3;
use super::algebra::Sym;
use super::composite::{Composite, body_inertias, composite_bodies};
use super::drives::{add_drive_efforts, add_param_drive_efforts};
use super::inverse::{Terms, forward_sweep};
use super::links::Tree;

/// A spatial vector `[angular; linear]`.
#[derive(Clone, Copy)]
struct Sv {
    a: V3,
    l: V3,
}

/// `(∂τ/∂q, ∂τ/∂q̇)` of inverse dynamics (friction and rotor inertia included): `2n²` nodes,
/// each matrix row-major (`[i][j] = ∂τ_i/∂x_j`).
pub fn recursive_inverse_dynamics_derivatives(g: &mut Graph, tree: &Tree) -> Vec<ExprId> {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let zero = s.g.zero();
    let qd: Vec<ExprId> = (0..n).map(|i| s.g.input(Arg::Qd, i)).collect();
    let qdd: Vec<ExprId> = (0..n).map(|i| s.g.input(Arg::Qdd, i)).collect();
    let gv = tree.gravity;
    let a0 = s.cv(&[-gv[0], -gv[1], -gv[2]]);
    let mo = forward_sweep(&mut s, &qd, &qdd, a0);
    // A last body symmetric about its revolute axis is resolved in its joint frame (its inertia
    // is the same there), so that its joint angle, which inverse dynamics never reads, is not
    // read here either; every other body in its body frame.
    let joint_frame = joint_frames(tree);
    // Spatial velocity and acceleration of every body.
    let mut vel: Vec<Sv> = Vec::with_capacity(n);
    let mut acc: Vec<Sv> = Vec::with_capacity(n);
    for i in 0..n {
        let l = &tree.links[i];
        let r0 = s.cm(&l.rot);
        let to_frame = |s: &mut Sym<'_>, v: V3| {
            if joint_frame[i] {
                s.mat_t_vec(&r0, v)
            } else {
                s.child_frame(i, v)
            }
        };
        let v = match l.parent {
            Some(p) => {
                let off = s.offset(i);
                let wp = s.cross(vel[p].a, off);
                let vp = s.add3(vel[p].l, wp);
                to_frame(&mut s, vp)
            }
            None => s.zero3(),
        };
        let v = match l.kind {
            JointKind::Revolute => v,
            JointKind::Prismatic => [v[0], v[1], s.g.add(v[2], qd[i])],
        };
        let (w, wd, a) = if joint_frame[i] {
            // The origin's acceleration, `a_p + U_p p` in the parent's frame.
            let ao = match l.parent {
                Some(p) => {
                    let u = s.u_matrix(mo.omega[p], mo.omegad[p]);
                    let off = s.offset(i);
                    let up = s.mat_vec(&u, off);
                    s.add3(mo.acc[p], up)
                }
                None => a0,
            };
            let a = to_frame(&mut s, ao);
            (mo.omega_j[i], mo.omegad_j[i], a)
        } else {
            (mo.omega[i], mo.omegad[i], mo.acc[i])
        };
        vel.push(Sv { a: w, l: v });
        let wv = s.cross(w, v);
        let al = sub3(&mut s, a, wv);
        acc.push(Sv { a: wd, l: al });
    }
    let bodies = body_inertias(&mut s);
    let comp = composite_bodies(&mut s);
    // `İ^C` in the body frame (its rate along `q̇`), then in a fixed frame.
    let dir: Vec<(Arg, usize, ExprId)> = (0..n).map(|j| (Arg::Q, j, qd[j])).collect();
    let mut dt = Derivative::along(&dir);
    let comp_dot: Vec<Composite> = comp
        .iter()
        .map(|c| Composite {
            m: zero,
            h: c.h.map(|x| dt.of(s.g, x)),
            j: c.j.map(|r| r.map(|x| dt.of(s.g, x))),
        })
        .collect();
    // Subtree momenta and wrenches, from the tips.
    let mut mom: Vec<Sv> = Vec::with_capacity(n);
    let mut wr: Vec<Sv> = Vec::with_capacity(n);
    for i in 0..n {
        let h = inertia_times(&mut s, &bodies[i], vel[i]);
        let ia = inertia_times(&mut s, &bodies[i], acc[i]);
        let vh = force_cross(&mut s, vel[i], h);
        mom.push(h);
        wr.push(add6(&mut s, ia, vh));
    }
    for i in (0..n).rev() {
        if let Some(p) = tree.links[i].parent {
            let h = force_to_parent(&mut s, i, joint_frame[i], mom[i]);
            mom[p] = add6(&mut s, mom[p], h);
            let f = force_to_parent(&mut s, i, joint_frame[i], wr[i]);
            wr[p] = add6(&mut s, wr[p], f);
        }
    }
    // Per joint: S, Ψ̇, Ψ̈ and the four force vectors.
    let mut motion = Vec::with_capacity(n);
    let mut forces = Vec::with_capacity(n);
    for i in 0..n {
        let sj = axis(&mut s, tree.links[i].kind);
        let pd = motion_cross(&mut s, vel[i], sj);
        let t1 = motion_cross(&mut s, acc[i], sj);
        let t2 = motion_cross(&mut s, vel[i], pd);
        let pdd = add6(&mut s, t1, t2);
        let c = comp[i];
        // `İ x = İ_b x + V ×* (I x) − I (V × x)` (`İ_b`: the rate in the body frame), so
        // `İ S = P − I Ψ̇` and `İ Ψ̇ + I Ψ̈ = İ_b Ψ̇ + V ×* (I Ψ̇) + I (A × S)`.
        let r1 = inertia_times(&mut s, &c, sj);
        let ipd = inertia_times(&mut s, &c, pd);
        let bs = inertia_times(&mut s, &comp_dot[i], sj);
        let vr1 = force_cross(&mut s, vel[i], r1);
        let p = add6(&mut s, bs, vr1);
        let sh = force_cross(&mut s, sj, mom[i]);
        let q = add6(&mut s, ipd, sh);
        let r2 = sub6(&mut s, p, q);
        let z = add6(&mut s, p, q);
        let sf = force_cross(&mut s, sj, wr[i]);
        let ias = inertia_times(&mut s, &c, t1);
        let bpd = inertia_times(&mut s, &comp_dot[i], pd);
        let vipd = force_cross(&mut s, vel[i], ipd);
        let pdh = force_cross(&mut s, pd, mom[i]);
        let y = add6(&mut s, sf, ias);
        let y = add6(&mut s, y, bpd);
        let y = add6(&mut s, y, vipd);
        let y = add6(&mut s, y, pdh);
        motion.push((sj, pd, pdd));
        forces.push([r1, r2, y, z]);
    }
    let mut dq = vec![zero; n * n];
    let mut dqd = vec![zero; n * n];
    for d in 0..n {
        let mut f = forces[d];
        let mut a = d;
        loop {
            let (sa, pd, pdd) = motion[a];
            let [r1, r2, y, z] = f;
            if a == d {
                dq[d * n + d] = dot6(&mut s, sa, y);
                dqd[d * n + d] = dot6(&mut s, sa, z);
            } else {
                let x = dot6(&mut s, pdd, r1);
                let w = dot6(&mut s, pd, r2);
                dq[d * n + a] = s.g.add(x, w);
                let x = dot6(&mut s, sa, r2);
                let w = dot6(&mut s, pd, r1);
                let w = s.g.scale(2.0, w);
                dqd[d * n + a] = s.g.add(x, w);
                dq[a * n + d] = dot6(&mut s, sa, y);
                dqd[a * n + d] = dot6(&mut s, sa, z);
            }
            let Some(p) = tree.links[a].parent else { break };
            f = f.map(|v| force_to_parent(&mut s, a, joint_frame[a], v));
            a = p;
        }
    }
    // Friction: `∂δ_i/∂q̇_i` by forward mode.
    let mut fr = vec![zero; n];
    let friction = Terms {
        friction: true,
        ..Terms::NONE
    };
    match &tree.params {
        None => add_drive_efforts(s.g, &tree.drives, friction, &mut fr, |g, arg, i| {
            g.input(arg, i)
        }),
        Some(pl) => add_param_drive_efforts(s.g, n, pl.coulomb_velocity, friction, &mut fr),
    }
    for (i, &f) in fr.iter().enumerate() {
        let df = Derivative::new(Arg::Qd, i).of(s.g, f);
        dqd[i * n + i] = s.g.add(dqd[i * n + i], df);
    }
    dq.extend(dqd);
    dq
}

fn sub3(s: &mut Sym<'_>, a: V3, b: V3) -> V3 {
    [
        s.g.sub(a[0], b[0]),
        s.g.sub(a[1], b[1]),
        s.g.sub(a[2], b[2]),
    ]
}

fn add6(s: &mut Sym<'_>, x: Sv, y: Sv) -> Sv {
    Sv {
        a: s.add3(x.a, y.a),
        l: s.add3(x.l, y.l),
    }
}

fn sub6(s: &mut Sym<'_>, x: Sv, y: Sv) -> Sv {
    Sv {
        a: sub3(s, x.a, y.a),
        l: sub3(s, x.l, y.l),
    }
}

/// `x · y` (a force and a motion, or the other way round).
fn dot6(s: &mut Sym<'_>, x: Sv, y: Sv) -> ExprId {
    let a = s.dot(x.a, y.a);
    let l = s.dot(x.l, y.l);
    s.g.add(a, l)
}

/// The joint's motion in its body frame.
fn axis(s: &mut Sym<'_>, kind: JointKind) -> Sv {
    let (z, one) = (s.g.zero(), s.g.constant(1.0));
    let e = [z, z, one];
    match kind {
        JointKind::Revolute => Sv { a: e, l: [z; 3] },
        JointKind::Prismatic => Sv { a: [z; 3], l: e },
    }
}

/// Motion cross product `m × x`.
fn motion_cross(s: &mut Sym<'_>, m: Sv, x: Sv) -> Sv {
    let a = s.cross(m.a, x.a);
    let l1 = s.cross(m.a, x.l);
    let l2 = s.cross(m.l, x.a);
    Sv {
        a,
        l: s.add3(l1, l2),
    }
}

/// Force cross product `m ×* f`.
fn force_cross(s: &mut Sym<'_>, m: Sv, f: Sv) -> Sv {
    let a1 = s.cross(m.a, f.a);
    let a2 = s.cross(m.l, f.l);
    Sv {
        a: s.add3(a1, a2),
        l: s.cross(m.a, f.l),
    }
}

/// `I x` for the inertia `(m, h, J)` about the origin: `[J ω + h × v; m v − h × ω]`.
fn inertia_times(s: &mut Sym<'_>, c: &Composite, x: Sv) -> Sv {
    let jw = s.mat_vec(&c.j, x.a);
    let hv = s.cross(c.h, x.l);
    let mv = s.scale3(c.m, x.l);
    let hw = s.cross(c.h, x.a);
    Sv {
        a: s.add3(jw, hv),
        l: sub3(s, mv, hw),
    }
}

/// Which bodies are resolved in their joint frames: revolute, without children or run-time
/// inertia, and symmetric about the axis (`h_x = h_y = 0`, `J_xz = J_yz = J_xy = 0`,
/// `J_xx = J_yy`), so that `Rz(q) I Rz(q)ᵀ = I`.
fn joint_frames(tree: &Tree) -> Vec<bool> {
    let n = tree.dof();
    let mut leaf = vec![true; n];
    for l in &tree.links {
        if let Some(p) = l.parent {
            leaf[p] = false;
        }
    }
    let rigid = tree.params.as_ref().map_or(&[][..], |p| &p.rigid[..]);
    for &(b, _) in rigid {
        leaf[b] = false;
    }
    (0..n)
        .map(|i| {
            let l = &tree.links[i];
            let (h, j) = (l.h, l.j);
            leaf[i]
                && l.kind == JointKind::Revolute
                && h[0] == 0.0
                && h[1] == 0.0
                && j[0][1] == 0.0
                && j[0][2] == 0.0
                && j[1][2] == 0.0
                && j[0][0] == j[1][1]
        })
        .collect()
}

/// A force vector of body `i`'s frame (its joint frame when `joint`) in its parent's.
fn force_to_parent(s: &mut Sym<'_>, i: usize, joint: bool, f: Sv) -> Sv {
    let (fp, np) = if joint {
        let r0 = s.cm(&s.tree.links[i].rot);
        (s.mat_vec(&r0, f.l), s.mat_vec(&r0, f.a))
    } else {
        (s.parent_frame(i, f.l), s.parent_frame(i, f.a))
    };
    let off = s.offset(i);
    let pf = s.cross(off, fp);
    Sv {
        a: s.add3(np, pf),
        l: fp,
    }
}
