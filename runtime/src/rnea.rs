//! The independent second route: the recursive Newton–Euler algorithm (RNEA) and the
//! composite-rigid-body algorithm (CRBA), written from R. Featherstone, *Rigid Body Dynamics
//! Algorithms* (Springer 2008), ch. 2, 5 and 6 — not from [`crate::noc`], with which it shares
//! nothing but the model's helpers.
//!
//! Spatial (Plücker) vectors in body coordinates, angular part first: motion `v = [ω; v_O]`
//! (`v_O`: velocity of the body-frame origin), force `f = [n_O; f]` (moment about the origin).
//! `ⁱX_λ` is the Plücker motion transform from the parent's coordinates to body `i`'s,
//! `ⁱX_λ = X_J(q_i) · X_T` (tree transform from the joint origin, then the joint); forces go back
//! with `λX_i* = (ⁱX_λ)ᵀ`. Spatial inertias are about the body-frame origin (eq. 2.63).
//!
//! Gravity enters as a fictitious base acceleration `a_0 = −a_g = [0; −g]` (§5.3), so the output
//! has the convention of [`crate::noc`]: `τ = H q̈ + C q̇ − γ`, and `inverse_dynamics(q, 0, 0)`
//! is the effort that holds the mechanism still.

use alloc::vec::Vec;

use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Vector3, Vector6};

use crate::model::{JointKind, Model, Vec3, axis_angle};

fn v3(v: &Vec3) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// `r×`, the 3-D cross-product operator.
fn skew(r: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -r[2], r[1], r[2], 0.0, -r[0], -r[1], r[0], 0.0)
}

/// Plücker motion transform `B X_A = [E 0; −E r× E]` (eq. 2.24), where `E` takes A coordinates
/// to B coordinates and `r` is B's origin in A coordinates.
fn plucker(e: &Matrix3<f64>, r: &Vector3<f64>) -> Matrix6<f64> {
    let mut x = Matrix6::zeros();
    x.fixed_view_mut::<3, 3>(0, 0).copy_from(e);
    x.fixed_view_mut::<3, 3>(3, 3).copy_from(e);
    x.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-e * skew(r)));
    x
}

/// Spatial cross product for motion vectors, `v×` (eq. 2.31): `[ω× 0; v_O× ω×]`.
fn crm(v: &Vector6<f64>) -> Matrix6<f64> {
    let w = skew(&Vector3::new(v[0], v[1], v[2]));
    let vo = skew(&Vector3::new(v[3], v[4], v[5]));
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(&w);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&vo);
    m
}

/// Spatial cross product for force vectors, `v×* = −(v×)ᵀ` (eq. 2.32).
fn crf(v: &Vector6<f64>) -> Matrix6<f64> {
    -crm(v).transpose()
}

/// Spatial inertia about the body-frame origin from mass `m`, mass centre `c` and inertia
/// `Ī_C` about the mass centre (eq. 2.63): `[Ī_C + m c× c×ᵀ, m c×; m c×ᵀ, m 1]`.
fn spatial_inertia(m: f64, c: &Vector3<f64>, ic: &Matrix3<f64>) -> Matrix6<f64> {
    let cx = skew(c);
    let mut i = Matrix6::zeros();
    i.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(ic + cx * cx.transpose() * m));
    i.fixed_view_mut::<3, 3>(0, 3).copy_from(&(cx * m));
    i.fixed_view_mut::<3, 3>(3, 0)
        .copy_from(&(cx.transpose() * m));
    i.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * m));
    i
}

/// Per-body data of one configuration: `ⁱX_λ`, motion subspace `S_i`, spatial inertia `I_i`.
struct Tree {
    x_up: Vec<Matrix6<f64>>,
    s: Vec<Vector6<f64>>,
    inertia: Vec<Matrix6<f64>>,
}

fn tree(model: &Model, q: &[f64]) -> Tree {
    let n = model.dof();
    assert_eq!(q.len(), n, "q has the wrong length");
    let mut t = Tree {
        x_up: Vec::with_capacity(n),
        s: Vec::with_capacity(n),
        inertia: Vec::with_capacity(n),
    };
    for (i, (joint, body)) in model.joints.iter().zip(&model.bodies).enumerate() {
        // X_T: parent coordinates → joint frame at q = 0. origin.rotation has the joint axes
        // in parent coordinates, so E = rotationᵀ.
        let rot = &joint.origin.rotation;
        let r_t = Matrix3::new(
            rot[0][0], rot[0][1], rot[0][2], rot[1][0], rot[1][1], rot[1][2], rot[2][0], rot[2][1],
            rot[2][2],
        );
        let x_t = plucker(&r_t.transpose(), &v3(&joint.origin.translation));
        let a = v3(&joint.axis);
        // X_J and S (Table 4.1): revolute = rotation by q about the axis, S = [a; 0];
        // prismatic = translation q a, S = [0; a].
        let (x_j, s) = match joint.kind {
            JointKind::Revolute => {
                let rj = axis_angle(&joint.axis, q[i]);
                let rj = Matrix3::new(
                    rj[0][0], rj[0][1], rj[0][2], rj[1][0], rj[1][1], rj[1][2], rj[2][0], rj[2][1],
                    rj[2][2],
                );
                (
                    plucker(&rj.transpose(), &Vector3::zeros()),
                    Vector6::new(a[0], a[1], a[2], 0.0, 0.0, 0.0),
                )
            }
            JointKind::Prismatic => (
                plucker(&Matrix3::identity(), &(a * q[i])),
                Vector6::new(0.0, 0.0, 0.0, a[0], a[1], a[2]),
            ),
        };
        let ic = &body.inertia;
        let ic = Matrix3::new(
            ic[0][0], ic[0][1], ic[0][2], ic[1][0], ic[1][1], ic[1][2], ic[2][0], ic[2][1],
            ic[2][2],
        );
        t.x_up.push(x_j * x_t);
        t.s.push(s);
        t.inertia
            .push(spatial_inertia(body.mass, &v3(&body.com), &ic));
    }
    t
}

/// RNEA (Table 5.1) with an explicit gravity vector (base frame).
fn rnea(model: &Model, q: &[f64], qd: &[f64], qdd: &[f64], g: &Vector3<f64>) -> DVector<f64> {
    let n = model.dof();
    assert_eq!(qd.len(), n, "q̇ has the wrong length");
    assert_eq!(qdd.len(), n, "q̈ has the wrong length");
    let t = tree(model, q);
    let a0 = Vector6::new(0.0, 0.0, 0.0, -g[0], -g[1], -g[2]);
    let mut v: Vec<Vector6<f64>> = Vec::with_capacity(n);
    let mut a: Vec<Vector6<f64>> = Vec::with_capacity(n);
    let mut f: Vec<Vector6<f64>> = Vec::with_capacity(n);
    // Forward pass: velocities, accelerations, the net force each body needs (5.7)–(5.9).
    for i in 0..n {
        let vj = t.s[i] * qd[i];
        let (vp, ap) = match model.joints[i].parent {
            None => (Vector6::zeros(), a0),
            Some(p) => (v[p], a[p]),
        };
        let vi = t.x_up[i] * vp + vj;
        // S is constant in body coordinates, so c_J = 0 and a_i = X a_λ + S q̈ + v_i × v_J.
        let ai = t.x_up[i] * ap + t.s[i] * qdd[i] + crm(&vi) * vj;
        let fi = t.inertia[i] * ai + crf(&vi) * (t.inertia[i] * vi);
        v.push(vi);
        a.push(ai);
        f.push(fi);
    }
    // Backward pass: joint forces, and each body's force onto its parent (5.10)–(5.11).
    let mut tau = DVector::zeros(n);
    for i in (0..n).rev() {
        tau[i] = t.s[i].dot(&f[i]);
        if let Some(p) = model.joints[i].parent {
            let fp = t.x_up[i].transpose() * f[i];
            f[p] += fp;
        }
    }
    tau
}

/// Inverse dynamics by the RNEA: `τ = H q̈ + C q̇ − γ` (gravity as base acceleration `−g`).
pub fn inverse_dynamics(model: &Model, q: &[f64], qd: &[f64], qdd: &[f64]) -> DVector<f64> {
    rnea(model, q, qd, qdd, &v3(&model.gravity))
}

/// The joint-space inertia matrix `H` by the CRBA (Table 6.2).
pub fn mass_matrix(model: &Model, q: &[f64]) -> DMatrix<f64> {
    let n = model.dof();
    let t = tree(model, q);
    // Composite inertias, children before parents: I^c_λ += λX_i* I^c_i ⁱX_λ.
    let mut ic = t.inertia.clone();
    for i in (0..n).rev() {
        if let Some(p) = model.joints[i].parent {
            let add = t.x_up[i].transpose() * ic[i] * t.x_up[i];
            ic[p] += add;
        }
    }
    let mut h = DMatrix::zeros(n, n);
    for i in 0..n {
        let mut f = ic[i] * t.s[i];
        h[(i, i)] = t.s[i].dot(&f);
        let mut j = i;
        while let Some(p) = model.joints[j].parent {
            f = t.x_up[j].transpose() * f;
            j = p;
            h[(i, j)] = f.dot(&t.s[j]);
            h[(j, i)] = h[(i, j)];
        }
    }
    h
}

/// The gravity effort `−γ`: RNEA with `q̇ = q̈ = 0`.
pub fn gravity(model: &Model, q: &[f64]) -> DVector<f64> {
    let zero = alloc::vec![0.0; model.dof()];
    rnea(model, q, &zero, &zero, &v3(&model.gravity))
}

/// The velocity-product terms `C(q, q̇) q̇`: RNEA with `q̈ = 0` and no gravity.
pub fn coriolis(model: &Model, q: &[f64], qd: &[f64]) -> DVector<f64> {
    let zero = alloc::vec![0.0; model.dof()];
    rnea(model, q, qd, &zero, &Vector3::zeros())
}

/// Every body's spatial velocity `[ω; v_O]` in its own coordinates (`v_O`: the velocity of the
/// body-frame origin) and its spatial acceleration `[ω̇; a_O − ω × v_O]` (Featherstone's
/// spatial acceleration, not the classical one), both from the RNEA's forward pass (5.7)–(5.8)
/// without gravity: the chain recursion the generated frame kinematics are checked against.
pub fn motion(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> (Vec<Vector6<f64>>, Vec<Vector6<f64>>) {
    let n = model.dof();
    assert_eq!(qd.len(), n, "q̇ has the wrong length");
    assert_eq!(qdd.len(), n, "q̈ has the wrong length");
    let t = tree(model, q);
    let mut v: Vec<Vector6<f64>> = Vec::with_capacity(n);
    let mut a: Vec<Vector6<f64>> = Vec::with_capacity(n);
    for i in 0..n {
        let vj = t.s[i] * qd[i];
        let (vp, ap) = match model.joints[i].parent {
            None => (Vector6::zeros(), Vector6::zeros()),
            Some(p) => (v[p], a[p]),
        };
        let vi = t.x_up[i] * vp + vj;
        let ai = t.x_up[i] * ap + t.s[i] * qdd[i] + crm(&vi) * vj;
        v.push(vi);
        a.push(ai);
    }
    (v, a)
}
