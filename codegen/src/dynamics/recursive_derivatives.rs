//! `∂τ/∂q`, `∂τ/∂q̇` of a tree's inverse dynamics by the recursive analytic route (after
//! Carpentier & Mansard, RSS 2018, and Singh, Russell & Wensing, RA-L 2022; docs/method.md,
//! "Derivatives"): `O(n)` composite quantities per body, then, per pair of joints on one path,
//! four force vectors moved from the outer joint's frame to the inner one's and dotted there.
//!
//! Spatial vectors `[angular; linear]`. Joint `i`'s quantities are formed in a frame `F` in
//! which its motion `S_i` is constant: its joint frame (fixed to the parent, `S = [e_z; 0]`) for
//! a revolute joint, so that they need no turn by `q_i` before moving inboard, its body frame
//! (`S = [0; e_z]`) for a prismatic one. With `V_F`, `A_F` that frame's spatial velocity and
//! acceleration (gravity as `−g` of the base), `I^C` the composite inertia and `İ_F` the rate of
//! its components in `F`, `H` the subtree's momentum and `F_i` its Newton–Euler wrench (inverse
//! dynamics' own, `joint_frame_wrenches`):
//! * `Ψ̇ = V_F × S`, `Ψ̈ = A_F × S + V_F × Ψ̇` (the same as with the body's `V = V_F + S q̇`),
//! * `r₁ = I^C S`, `P = İ_F S + V_F ×* r₁`, `Q = I^C Ψ̇ + S ×* H`, `r₂ = P − Q`, `Z = P + Q`,
//! * `Y = S ×* F_i + I^C (A_F × S) + İ_F Ψ̇ + V_F ×* (I^C Ψ̇) + Ψ̇ ×* H`,
//!
//! and for `a` on the path from the base to `d` (`a = d` included), all in `a`'s frame `F`:
//! `∂τ_d/∂q_a = r₁_d·Ψ̈_a + r₂_d·Ψ̇_a`, `∂τ_d/∂q̇_a = r₂_d·S_a + 2 r₁_d·Ψ̇_a`,
//! `∂τ_a/∂q_d = S_a·Y_d`, `∂τ_a/∂q̇_d = S_a·Z_d`. Joint friction (a function of `q̇_i` alone)
//! is differentiated by forward mode and added to the diagonal of `∂τ/∂q̇`.
//!
//! Why: moving `q_a` turns the subtree of `a` rigidly about `S_a`; seen from its own frames each
//! body of the subtree only gains `δV = Ψ̇_a` and `δA = Ψ̈_a + Ψ̇_a × V`, so its wrench gains
//! `I Ψ̈_a + İ Ψ̇_a + Ψ̇_a ×* h` (`h` its momentum, `İ` the rate in a fixed frame), and the turn
//! itself adds `S_a ×* F` to the subtree's wrench seen from the joints inboard of `a` (it
//! cancels in `S_dᵀ F_d` for `d` in the subtree). Moving `q̇_a` adds `δV = S_a`,
//! `δA = S_a × V + 2 Ψ̇_a` to the subtree. Summing over a subtree gives the composite
//! quantities, `İ x + x ×* H` being the sum of the bodies' `İ_k x + x ×* h_k`. In a frame moving
//! with `V_F`, `İ x = İ_F x + V_F ×* (I x) − I (V_F × x)`, which gives `P = İ S + I Ψ̇` and
//! `I Ψ̈ + İ Ψ̇ = İ_F Ψ̇ + V_F ×* (I Ψ̇) + I (A_F × S)`. `İ_F` comes from the tips
//! (`composite_rates`).

use runtime::model::JointKind;

use crate::sym::derivative::Derivative;
use crate::sym::{Arg, ExprId, Graph};

use super::algebra::Sym;
use super::composite::{Composite, body_inertias, composite_bodies};
use super::drives::{add_drive_efforts, add_param_drive_efforts};
use super::inverse::{Terms, forward_sweep, joint_frame_wrenches};
use super::links::Tree;
use super::{M3, V3};

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
    // Spatial velocity of every body, and of the frame `F_i` in which joint `i`'s quantities
    // are formed (`Frame` below) with its acceleration.
    let mut vel: Vec<Sv> = Vec::with_capacity(n);
    let mut frame_motion: Vec<(Sv, Sv)> = Vec::with_capacity(n);
    for i in 0..n {
        let l = &tree.links[i];
        let r0 = s.cm(&l.rot);
        // The parent's velocity and the origin's classical acceleration in the parent's axes
        // (so, moved by `R0ᵀ`, in the joint frame).
        let (vp, wp, wdp, ao) = match l.parent {
            Some(p) => {
                let off = s.offset(i);
                let wv = s.cross(vel[p].a, off);
                let vp = s.add3(vel[p].l, wv);
                let u = s.u_matrix(mo.omega[p], mo.omegad[p]);
                let up = s.mat_vec(&u, off);
                let ao = s.add3(mo.acc[p], up);
                (vp, vel[p].a, mo.omegad[p], ao)
            }
            None => (s.zero3(), s.zero3(), s.zero3(), a0),
        };
        let v = if joint_frame[i] {
            s.mat_t_vec(&r0, vp)
        } else {
            s.child_frame(i, vp)
        };
        let w = if joint_frame[i] {
            mo.omega_j[i]
        } else {
            mo.omega[i]
        };
        match l.kind {
            JointKind::Revolute => {
                vel.push(Sv { a: w, l: v });
                let wf = s.mat_t_vec(&r0, wp);
                let vf = s.mat_t_vec(&r0, vp);
                let wdf = s.mat_t_vec(&r0, wdp);
                let af = s.mat_t_vec(&r0, ao);
                let wv = s.cross(wf, vf);
                let af = sub3(&mut s, af, wv);
                frame_motion.push((Sv { a: wf, l: vf }, Sv { a: wdf, l: af }));
            }
            JointKind::Prismatic => {
                // `F` is the body frame.
                let vv = Sv {
                    a: w,
                    l: [v[0], v[1], s.g.add(v[2], qd[i])],
                };
                vel.push(vv);
                let wv = s.cross(w, vv.l);
                let a = Sv {
                    a: mo.omegad[i],
                    l: sub3(&mut s, mo.acc[i], wv),
                };
                frame_motion.push((vv, a));
            }
        }
    }
    let bodies = body_inertias(&mut s);
    let comp = composite_bodies(&mut s);
    // Subtree momenta, from the tips.
    let mut mom: Vec<Sv> = (0..n)
        .map(|i| inertia_times(&mut s, &bodies[i], vel[i]))
        .collect();
    for i in (0..n).rev() {
        if let Some(p) = tree.links[i].parent {
            let h = to_joint(&mut s, i, joint_frame[i], mom[i]);
            let h = joint_to_parent(&mut s, i, h);
            mom[p] = add6(&mut s, mom[p], h);
        }
    }
    // The subtree wrenches are inverse dynamics' own, in the joint frames.
    let wr = joint_frame_wrenches(&mut s, &mo);
    // `I^C` and its rate in `F`.
    let rates = composite_rates(&mut s, &comp, &qd, &joint_frame);
    // Per joint: S, Ψ̇, Ψ̈ and the four force vectors, in `F`.
    let mut motion = Vec::with_capacity(n);
    let mut forces = Vec::with_capacity(n);
    for i in 0..n {
        let kind = tree.links[i].kind;
        let c = if joint_frame[i] || kind == JointKind::Prismatic {
            comp[i]
        } else {
            Composite {
                m: comp[i].m,
                h: s.rz(i, comp[i].h),
                j: s.congruence_rz(i, &comp[i].j),
            }
        };
        let cd = rates[i];
        let h = to_joint(&mut s, i, joint_frame[i], mom[i]);
        let (vf, af) = frame_motion[i];
        let sj = axis(&mut s, kind);
        let pd = motion_cross(&mut s, vf, sj);
        let t1 = motion_cross(&mut s, af, sj);
        let t2 = motion_cross(&mut s, vf, pd);
        let pdd = add6(&mut s, t1, t2);
        // `İ x = İ_F x + V_F ×* (I x) − I (V_F × x)` (`İ_F`: the rate in `F`), so
        // `İ S = P − I Ψ̇` and `İ Ψ̇ + I Ψ̈ = İ_F Ψ̇ + V_F ×* (I Ψ̇) + I (A_F × S)`.
        let r1 = inertia_times(&mut s, &c, sj);
        let ipd = inertia_times(&mut s, &c, pd);
        let bs = inertia_times(&mut s, &cd, sj);
        let vr1 = force_cross(&mut s, vf, r1);
        let p = add6(&mut s, bs, vr1);
        let sh = force_cross(&mut s, sj, h);
        let q = add6(&mut s, ipd, sh);
        let r2 = sub6(&mut s, p, q);
        let z = add6(&mut s, p, q);
        let ias = inertia_times(&mut s, &c, t1);
        let bpd = inertia_times(&mut s, &cd, pd);
        let vipd = force_cross(&mut s, vf, ipd);
        let pdh = force_cross(&mut s, pd, h);
        let y = add6(&mut s, ias, bpd);
        let y = add6(&mut s, y, vipd);
        let mut y = add6(&mut s, y, pdh);
        // `S ×* F` (zero on `S` itself: only the joints inboard see it).
        if let Some((ff, fnn)) = wr[i] {
            let sf = force_cross(&mut s, sj, Sv { a: fnn, l: ff });
            y = add6(&mut s, y, sf);
        }
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
            f = f.map(|v| {
                let v = joint_to_parent(&mut s, a, v);
                to_joint(&mut s, p, joint_frame[p], v)
            });
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

/// The rate of every composite inertia's components in its joint's frame `F` (the joint frame
/// for a revolute joint, the body frame for a prismatic one), from the tips: with `İ_i` the rate
/// in body `i`'s frame (zero for a single body) turned to `F`, a revolute joint's turn adds
/// `q̇ [S ×*, I^C]` in `F` (`ḣ += q̇ e_z × h`, `J̇ += q̇ ([e_z]× J − J [e_z]×)`); the rate in `F`
/// moves to the parent as an inertia of zero mass, plus, for a prismatic joint, the rate of the
/// parallel-axis terms along its slide.
fn composite_rates(
    s: &mut Sym<'_>,
    comp: &[Composite],
    qd: &[ExprId],
    joint_frame: &[bool],
) -> Vec<Composite> {
    let tree = s.tree;
    let n = tree.dof();
    let zero = s.g.zero();
    let none = Composite {
        m: zero,
        h: [zero; 3],
        j: [[zero; 3]; 3],
    };
    let mut body = vec![none; n];
    let mut in_f = vec![none; n];
    for i in (0..n).rev() {
        let l = &tree.links[i];
        if joint_frame[i] {
            // Symmetric about its axis and alone: constant in its joint frame, and its turn
            // changes nothing.
            continue;
        }
        let (c, r, v) = (comp[i], body[i], qd[i]);
        let rf = match l.kind {
            JointKind::Revolute => {
                // `Rz (İ + q̇ [e_z×, I^C]) Rzᵀ = Rz İ Rzᵀ + q̇ [e_z×, I^C_F]`: the turn's term from
                // the composite already in `F` (the composite's own move to the parent), so that
                // a body alone (`İ = 0`) needs no turn of its rate.
                let hf = s.rz(i, c.h);
                let jf = s.congruence_rz(i, &c.j);
                let hr = s.rz(i, r.h);
                let jr = s.congruence_rz(i, &r.j);
                let h = [
                    {
                        let t = s.g.mul(v, hf[1]);
                        s.g.sub(hr[0], t)
                    },
                    {
                        let t = s.g.mul(v, hf[0]);
                        s.g.add(hr[1], t)
                    },
                    hr[2],
                ];
                let j = jf;
                let d01 = s.g.sub(j[0][0], j[1][1]);
                let t01 = s.g.mul(v, j[0][1]);
                let t01 = s.g.scale(2.0, t01);
                let t02 = s.g.mul(v, j[1][2]);
                let t12 = s.g.mul(v, j[0][2]);
                let t00 = s.g.mul(v, d01);
                let m = [
                    [
                        s.g.sub(jr[0][0], t01),
                        s.g.add(jr[0][1], t00),
                        s.g.sub(jr[0][2], t02),
                    ],
                    [zero, s.g.add(jr[1][1], t01), s.g.add(jr[1][2], t12)],
                    [zero, zero, jr[2][2]],
                ];
                Composite {
                    m: zero,
                    h,
                    j: s.symmetrize(m),
                }
            }
            JointKind::Prismatic => r,
        };
        in_f[i] = rf;
        let Some(p) = l.parent else { continue };
        // The rate in `F`, moved to the parent's frame as an inertia of zero mass.
        let r0 = s.cm(&l.rot);
        let hp = s.mat_vec(&r0, rf.h);
        let mut jp = s.congruence_r0(i, &rf.j);
        let off = s.offset(i);
        let mut hn = hp;
        parallel_axis_rate(s, &mut jp, off, hp);
        if l.kind == JointKind::Prismatic {
            // The slide `ṗ = R0 e_z q̇`: `ḣ += m ṗ`, `J̇ += 2 (ṗ·w) 1 − ṗ wᵀ − w ṗᵀ`,
            // `w = m p + R0 h`.
            let ez = [l.rot[0][2], l.rot[1][2], l.rot[2][2]];
            let ez = s.cv(&ez);
            let pd = s.scale3(v, ez);
            let mp = s.scale3(c.m, off);
            let rh = s.mat_vec(&r0, c.h);
            let w = s.add3(mp, rh);
            let mpd = s.scale3(c.m, pd);
            hn = s.add3(hn, mpd);
            parallel_axis_rate(s, &mut jp, pd, w);
        }
        let b = body[p];
        let mut j = b.j;
        for (r, row) in j.iter_mut().enumerate() {
            for (k, x) in row.iter_mut().enumerate().skip(r) {
                *x = s.g.add(*x, jp[r][k]);
            }
        }
        body[p] = Composite {
            m: zero,
            h: s.add3(b.h, hn),
            j: s.symmetrize(j),
        };
    }
    in_f
}

/// `J += 2 (a·b) 1 − a bᵀ − b aᵀ` (the upper triangle; symmetrized).
fn parallel_axis_rate(s: &mut Sym<'_>, j: &mut M3, a: V3, b: V3) {
    let ab = s.dot(a, b);
    let ab2 = s.g.scale(2.0, ab);
    for r in 0..3 {
        for c in r..3 {
            let x = s.g.mul(a[r], b[c]);
            let y = s.g.mul(b[r], a[c]);
            let xy = s.g.add(x, y);
            let t = if r == c {
                s.g.sub(ab2, xy)
            } else {
                s.g.neg(xy)
            };
            j[r][c] = s.g.add(j[r][c], t);
        }
    }
    *j = s.symmetrize(*j);
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

/// A force vector of body `i`'s frame (its joint frame when `joint`) in its joint frame.
fn to_joint(s: &mut Sym<'_>, i: usize, joint: bool, f: Sv) -> Sv {
    if joint {
        return f;
    }
    Sv {
        a: s.rz(i, f.a),
        l: s.rz(i, f.l),
    }
}

/// A force vector of body `i`'s joint frame in its parent's frame.
fn joint_to_parent(s: &mut Sym<'_>, i: usize, f: Sv) -> Sv {
    let r0 = s.cm(&s.tree.links[i].rot);
    let (fp, np) = (s.mat_vec(&r0, f.l), s.mat_vec(&r0, f.a));
    let off = s.offset(i);
    let pf = s.cross(off, fp);
    Sv {
        a: s.add3(np, pf),
        l: fp,
    }
}
