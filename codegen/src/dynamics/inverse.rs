//! Inverse dynamics `Tᵀ(M ṫ + W M t − w^G)` (docs/method.md, "Evaluation order"): twists and
//! their rates outward (eqs. 25–26, 33), one Newton–Euler wrench per body (eq. 12) in the
//! cheapest moment form, `Tᵀ w` accumulated from the tips (eq. 24), then the drives.

use runtime::model::{JointKind, Mat3, mat_vec, transpose};

use crate::sym::{Arg, ExprId, Graph};

use super::V3;
use super::algebra::Sym;
use super::drives::{add_drive_efforts, add_param_drive_efforts};
use super::flops::{Paid, marginal_flops};
use super::links::Tree;
use super::runtime_params::{centre_params, payload_params};

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

/// `Tᵀ (M ṫ + W M t − w^G)`: inverse dynamics (or its parts), one effort per joint.
pub fn inverse_dynamics(g: &mut Graph, tree: &Tree, terms: Terms) -> Vec<ExprId> {
    inverse_dynamics_sunk(g, tree, terms, &[])
}

/// Each non-root body's subtree wrench (force, moment about its origin) in its joint frame, as
/// inverse dynamics' backward sweep forms it on the way to the parent (the same nodes: the same
/// moment forms, chosen from nothing paid); `None` for the roots.
pub(super) fn joint_frame_wrenches(s: &mut Sym<'_>, motion: &Motion) -> Vec<Option<(V3, V3)>> {
    let tree = s.tree;
    let n = tree.dof();
    let mut paid = Paid::default();
    let mut wrenches = body_wrenches(s, motion, &mut paid);
    add_runtime_wrenches(s, motion, &mut wrenches, &mut paid, &[]);
    let Wrenches {
        mut force,
        mut moment,
        extra_moment,
    } = wrenches;
    let mut out = vec![None; n];
    for i in (0..n).rev() {
        if let Some(p) = tree.links[i].parent {
            let fz = s.rz(i, force[i]);
            let nn = s.rz(i, moment[i]);
            let nn = s.add3(nn, extra_moment[i]);
            out[i] = Some((fz, nn));
            let (f, nn) = to_parent(s, i, fz, nn);
            force[p] = s.add3(force[p], f);
            moment[p] = s.add3(moment[p], nn);
        }
    }
    out
}

/// A wrench of body `i`'s joint frame (force `fz`, moment `nn` about the origin) in its
/// parent's frame.
fn to_parent(s: &mut Sym<'_>, i: usize, fz: V3, nn: V3) -> (V3, V3) {
    let r0 = s.cm(&s.tree.links[i].rot);
    let f = s.mat_vec(&r0, fz);
    let nn = s.mat_vec(&r0, nn);
    let off = s.offset(i);
    let pf = s.cross(off, f);
    (f, s.add3(nn, pf))
}

/// Twists and their rates per body, from the forward sweep.
pub(super) struct Motion {
    /// `ω_i`, body frame.
    pub(super) omega: Vec<V3>,
    /// `ω̇_i`, body frame.
    pub(super) omegad: Vec<V3>,
    /// Acceleration of the body-frame origin, body frame.
    pub(super) acc: Vec<V3>,
    /// ω resolved in the joint frame (the body frame before the joint's own rotation).
    pub(super) omega_j: Vec<V3>,
    /// ω̇ resolved in the joint frame.
    pub(super) omegad_j: Vec<V3>,
}

/// Body wrenches about the body-frame origins, one per body.
struct Wrenches {
    force: Vec<V3>,
    moment: Vec<V3>,
    /// Moment of the axial inertia kept apart, in the joint frame (added after the joint's
    /// rotation back to the parent).
    extra_moment: Vec<V3>,
}

/// [`inverse_dynamics`] in a function that also needs the nodes of `sunk` (forward dynamics:
/// the mass matrix), which the run-time bodies' choice of wrench form counts as paid.
pub(super) fn inverse_dynamics_sunk(
    g: &mut Graph,
    tree: &Tree,
    terms: Terms,
    sunk: &[ExprId],
) -> Vec<ExprId> {
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
    let motion = forward_sweep(&mut s, &qd, &qdd, a0);
    // Nodes already needed by the wrenches chosen so far (their cost is sunk).
    let mut paid = Paid::default();
    let mut wrenches = body_wrenches(&mut s, &motion, &mut paid);
    add_runtime_wrenches(&mut s, &motion, &mut wrenches, &mut paid, sunk);
    let mut tau = backward_sweep(&mut s, zero, wrenches);
    match &tree.params {
        None => add_drive_efforts(s.g, &tree.drives, terms, &mut tau, |g, arg, i| {
            g.input(arg, i)
        }),
        Some(pl) => add_param_drive_efforts(s.g, n, pl.coulomb_velocity, terms, &mut tau),
    }
    tau
}

/// Forward sweep: twists t_i = T_i q̇ and their rates ṫ_i = T_i q̈ + Ṫ_i q̇ (eqs. 25–26, 33),
/// resolved in body frames; `acc` is the acceleration of the body-frame origin.
pub(super) fn forward_sweep(s: &mut Sym<'_>, qd: &[ExprId], qdd: &[ExprId], a0: V3) -> Motion {
    let tree = s.tree;
    let n = tree.dof();
    let mut m = Motion {
        omega: Vec::with_capacity(n),
        omegad: Vec::with_capacity(n),
        acc: Vec::with_capacity(n),
        omega_j: Vec::with_capacity(n),
        omegad_j: Vec::with_capacity(n),
    };
    for i in 0..n {
        let l = &tree.links[i];
        let parent = match l.parent {
            Some(p) => (m.omega[p], m.omegad[p], m.acc[p]),
            None => (s.zero3(), s.zero3(), a0),
        };
        let ((w, wd, a), (wj, wdj)) = match l.kind {
            JointKind::Revolute => revolute_step(s, i, parent, qd[i], qdd[i]),
            JointKind::Prismatic => prismatic_step(s, i, parent, qd[i], qdd[i]),
        };
        m.omega_j.push(wj);
        m.omegad_j.push(wdj);
        m.omega.push(w);
        m.omegad.push(wd);
        m.acc.push(a);
    }
    m
}

/// One revolute joint of the forward sweep, from the parent's `(ω, ω̇, a)`: body `i`'s
/// `(ω, ω̇, a)` in its body frame and its `(ω, ω̇)` in its joint frame.
fn revolute_step(
    s: &mut Sym<'_>,
    i: usize,
    (wp, wdp, ap): (V3, V3, V3),
    qd: ExprId,
    qdd: ExprId,
) -> ((V3, V3, V3), (V3, V3)) {
    let tree = s.tree;
    let l = &tree.links[i];
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
        let w = [w_in[0], w_in[1], s.g.add(w_in[2], qd)];
        let x = s.g.mul(w_in[1], qd);
        let y = s.g.mul(w_in[0], qd);
        let wd = [
            s.g.add(wd_in[0], x),
            s.g.sub(wd_in[1], y),
            s.g.add(wd_in[2], qdd),
        ];
        *fr = (w, wd);
    }
    ((frames[0].0, frames[0].1, a), frames[1])
}

/// One prismatic joint of the forward sweep, as [`revolute_step`] (the joint frame is the body
/// frame).
fn prismatic_step(
    s: &mut Sym<'_>,
    i: usize,
    (wp, wdp, ap): (V3, V3, V3),
    qd: ExprId,
    qdd: ExprId,
) -> ((V3, V3, V3), (V3, V3)) {
    let tree = s.tree;
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
    let x = s.g.mul(w[1], qd);
    let y = s.g.mul(w[0], qd);
    let cor = [s.g.scale(2.0, x), s.g.scale(-2.0, y), qdd];
    let a = s.add3(ap_in, ur);
    let a = s.add3(a, cor);
    ((w, wd, a), (w, wd))
}

/// Body wrenches M_i ṫ_i + W_i M_i t_i − w_i^G (eq. 12), about the body-frame origin, each in
/// its cheapest moment form given the nodes already in `paid` (which gains each choice's).
fn body_wrenches(s: &mut Sym<'_>, mo: &Motion, paid: &mut Paid) -> Wrenches {
    let n = s.tree.dof();
    let mut wr = Wrenches {
        force: Vec::with_capacity(n),
        moment: Vec::with_capacity(n),
        extra_moment: Vec::with_capacity(n),
    };
    for i in 0..n {
        let (f, nb, extra) = body_wrench(s, i, mo, paid);
        wr.force.push(f);
        wr.moment.push(nb);
        wr.extra_moment.push(extra);
    }
    wr
}

/// Body `i`'s wrench (eq. 12): force, moment about the origin and the axial moment kept apart
/// (see [`moment_forms`]), the cheapest form by marginal operation count.
fn body_wrench(s: &mut Sym<'_>, i: usize, mo: &Motion, paid: &mut Paid) -> (V3, V3, V3) {
    let tree = s.tree;
    let l = &tree.links[i];
    let m = s.c(l.mass);
    let h = s.cv(&l.h);
    let (w, wd, a) = (mo.omega[i], mo.omegad[i], mo.acc[i]);
    let ma = s.scale3(m, a);
    let u = s.u_matrix(w, wd);
    let uh = s.mat_vec(&u, h);
    let f = s.add3(ma, uh);
    let forms = moment_forms(s, i, mo, f, h);
    let (nb, extra) = cheapest_form(s, i, f, &forms, paid);
    paid.pay(
        s.g,
        &[
            f[0], f[1], f[2], nb[0], nb[1], nb[2], extra[0], extra[1], extra[2],
        ],
    );
    (f, nb, extra)
}

/// The equivalent moment forms of body `i` (force `f`, first moment `h`), each as
/// `(moment, axial moment apart)`.
fn moment_forms(s: &mut Sym<'_>, i: usize, mo: &Motion, f: V3, h: V3) -> Vec<(V3, V3)> {
    let tree = s.tree;
    let l = &tree.links[i];
    let (w, wd, a) = (mo.omega[i], mo.omegad[i], mo.acc[i]);
    // Moment about the origin, equivalent forms; keep the cheapest for this body:
    // J ω̇ + ω × Jω + h × a (inertia about the origin), or
    // I_c ω̇ + ω × I_c ω + c × f (about the mass centre, then moved);
    // the gyroscopic term either from the shared products ω_a ω_b ([`Sym::gyro`]) or as
    // ω × (Jω) (cheaper for a full inertia tensor); and the axial moment of inertia
    // `diag(0, 0, J_zz)` either with the rest or apart, in the joint frame: it is
    // unchanged by the joint's rotation, so its moment needs no rotation back to the
    // parent (`extra`, added after the rotation).
    let (wj, wdj) = (mo.omega_j[i], mo.omegad_j[i]);
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
    forms
}

/// The first of `forms` whose moment, rotated back to the parent, adds the fewest operations
/// to body `i`'s force `f` beyond `paid`.
fn cheapest_form(s: &mut Sym<'_>, i: usize, f: V3, forms: &[(V3, V3)], paid: &Paid) -> (V3, V3) {
    let mut best = usize::MAX;
    let mut choice = forms[0];
    for &(nb, extra) in forms {
        let rotated = s.rz(i, nb);
        let rotated = s.add3(rotated, extra);
        let roots = [f[0], f[1], f[2], rotated[0], rotated[1], rotated[2]];
        let c = marginal_flops(s.g, &roots, paid);
        if c < best {
            best = c;
            choice = (nb, extra);
        }
    }
    choice
}

/// Adds the wrenches of the run-time payload and bodies to their links'.
fn add_runtime_wrenches(
    s: &mut Sym<'_>,
    mo: &Motion,
    wr: &mut Wrenches,
    paid: &mut Paid,
    sunk: &[ExprId],
) {
    let tree = s.tree;
    let rigid = tree.params.as_ref().map_or(&[][..], |p| &p.rigid[..]);
    for &(b, at) in rigid {
        let (f, nb) = runtime_wrench(s, b, at, mo, paid, sunk);
        wr.force[b] = s.add3(wr.force[b], f);
        wr.moment[b] = s.add3(wr.moment[b], nb);
    }
}

/// A run-time payload or body on link b: its Newton–Euler wrench about the link origin
/// (eq. 12), `f = m a + ω̇ × h + ω × (ω × h)`, `n = J ω̇ + ω × J ω + h × a`.
fn runtime_wrench(
    s: &mut Sym<'_>,
    b: usize,
    at: usize,
    mo: &Motion,
    paid: &mut Paid,
    sunk: &[ExprId],
) -> (V3, V3) {
    let (m, h, j) = payload_params(s, b, at);
    let (w, wd, a) = (mo.omega[b], mo.omegad[b], mo.acc[b]);
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
    if at == 0 {
        return (f, nb);
    }
    // A run-time body: the same wrench formed about its mass centre,
    // `f = m (a + U c)`, `n = I_c ω̇ + ω × I_c ω + c × f`, needs no inertia about the
    // origin; keep the cheaper form (the payload keeps the first).
    let (m, c, ic) = centre_params(s, b, at);
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
    let chosen = if cost(s, &fc, &nc) < cost(s, &f, &nb) {
        (fc, nc)
    } else {
        (f, nb)
    };
    let (f, n) = chosen;
    paid.pay(s.g, &[f[0], f[1], f[2], n[0], n[1], n[2]]);
    chosen
}

/// Backward sweep: Tᵀ w, accumulated from the tips (eq. 24).
fn backward_sweep(s: &mut Sym<'_>, zero: ExprId, wr: Wrenches) -> Vec<ExprId> {
    let tree = s.tree;
    let n = tree.dof();
    let Wrenches {
        mut force,
        mut moment,
        extra_moment,
    } = wr;
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
    tau
}
