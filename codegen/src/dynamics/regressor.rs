//! The standard regressor of a tree (docs/method.md, "Identification: the regressor and base
//! parameters"): inverse dynamics is linear in the inertial parameters of every body and in the
//! drives' coefficients, `τ = Y(q, q̇, q̈) π`, and column `k` of `Y` is the effort that a unit
//! standard parameter `π_k` alone demands. Each column is built in the DAG: body `b`'s
//! Newton–Euler wrench for the unit parameter (eq. 12), paired with the unit twist of every
//! joint on `b`'s path to the base (the power `tᵀ w`, the column of `Tᵀ w`, eq. 24).
//!
//! Standard parameters per body, Khalil's convention (Khalil & Dombre 2002, §9.3), in the
//! model's body frame (the joint frame after the motion), about its origin:
//! `XX, XY, XZ, YY, YZ, ZZ` (the inertia tensor's entries `J = I_c + m(|c|² 1 − c cᵀ)`),
//! `MX, MY, MZ` (`m c`), `M`; then per joint with drives, `FV` (viscous), `FC` (regularized
//! Coulomb: `q̇ / √(q̇² + v_s²)` with the drive's `v_s`) and `IA` (rotor inertia).

use runtime::model::{JointKind, Mat3, Model, Vec3, mat_mul, mat_vec, transpose};

use crate::sym::{Arg, ExprId, Graph};

use super::algebra::Sym;
use super::drives::friction_effort;
use super::inverse::{Motion, forward_sweep};
use super::links::Tree;
use super::{M3, V3};

/// The names of a body's ten standard parameters, in their order.
pub const BODY_PARAMETERS: [&str; 10] = ["XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"];

/// The standard parameters of a tree and their regressor columns.
#[derive(Clone, Debug)]
pub struct Standard {
    /// `"XX_link2"`, `"FV_joint1"`: the parameter then the body's (drives: the joint's) name.
    pub names: Vec<String>,
    /// The spec's values.
    pub values: Vec<f64>,
    /// One column per parameter, `DOF` nodes each.
    pub columns: Vec<Vec<ExprId>>,
}

/// The ten standard parameters of a model body: `XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M`.
pub fn body_standard_parameters(mass: f64, com: &Vec3, inertia: &Mat3) -> [f64; 10] {
    let c = com;
    let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let j = |r: usize, k: usize| {
        let d = if r == k { cc } else { 0.0 };
        inertia[r][k] + mass * (d - c[r] * c[k])
    };
    [
        j(0, 0),
        j(0, 1),
        j(0, 2),
        j(1, 1),
        j(1, 2),
        j(2, 2),
        mass * c[0],
        mass * c[1],
        mass * c[2],
        mass,
    ]
}

/// Which drive columns a model has: `(FV and FC, IA)`. Friction (`[scene] friction`, some
/// joint with a viscous or Coulomb coefficient) brings all three per joint (`FC` only where the
/// joint has a Coulomb speed scale `v_s`, i.e. a Coulomb level); rotor inertia alone brings
/// `IA`.
fn drive_columns(model: &Model) -> (bool, bool) {
    let friction = model
        .joints
        .iter()
        .any(|j| j.drive.viscous != 0.0 || j.drive.coulomb != 0.0);
    let armature = friction || model.joints.iter().any(|j| j.drive.armature != 0.0);
    (friction, armature)
}

/// The standard parameters of `model` and their regressor columns, built on `tree` (the same
/// model's [`Tree`]: the columns share its kinematics with the other functions).
pub fn standard_regressor(g: &mut Graph, tree: &Tree, model: &Model) -> Standard {
    let n = tree.dof();
    let mut s = Sym::new(g, tree);
    let qd: Vec<ExprId> = (0..n).map(|i| s.g.input(Arg::Qd, i)).collect();
    let qdd: Vec<ExprId> = (0..n).map(|i| s.g.input(Arg::Qdd, i)).collect();
    let gv = tree.gravity;
    let a0 = s.cv(&[-gv[0], -gv[1], -gv[2]]);
    let motion = forward_sweep(&mut s, &qd, &qdd, a0);
    let twists = joint_twists(&mut s);
    let (friction, armature) = drive_columns(model);
    let zero = s.g.zero();
    let mut out = Standard {
        names: Vec::new(),
        values: Vec::new(),
        columns: Vec::new(),
    };
    for b in 0..n {
        let body = &model.bodies[b];
        let values = body_standard_parameters(body.mass, &body.com, &body.inertia);
        for (k, name) in BODY_PARAMETERS.iter().enumerate() {
            let mut unit = [0.0; 10];
            unit[k] = 1.0;
            let (m, h, j) = link_parameters(tree, b, &unit);
            let (f, nm) = unit_wrench(&mut s, b, &motion, m, &h, &j);
            let mut col = vec![zero; n];
            for (jt, w, v) in &twists[b] {
                let a = s.dot(*w, nm);
                let c = s.dot(*v, f);
                col[*jt] = s.g.add(a, c);
            }
            out.names.push(format!("{name}_{}", body.name));
            out.values.push(values[k]);
            out.columns.push(col);
        }
        let joint = &model.joints[b];
        let d = joint.drive;
        let mut drive = |name: &str, value: f64, node: ExprId| {
            let mut col = vec![zero; n];
            col[b] = node;
            out.names.push(format!("{name}_{}", joint.name));
            out.values.push(value);
            out.columns.push(col);
        };
        if friction {
            drive("FV", d.viscous, qd[b]);
            if d.coulomb_velocity > 0.0 {
                let unit = runtime::model::Drive {
                    coulomb: 1.0,
                    ..runtime::model::Drive::NONE
                };
                let unit = runtime::model::Drive {
                    coulomb_velocity: d.coulomb_velocity,
                    ..unit
                };
                let e = friction_effort(s.g, &unit, qd[b]);
                drive("FC", d.coulomb, e);
            }
        }
        if armature {
            drive("IA", d.armature, qdd[b]);
        }
    }
    out
}

/// Per body `i`: `(j, ω, v)` for every joint `j` on its path to the base, the twist of body
/// `i`'s frame (angular velocity, velocity of its origin; body-`i` components) for a unit rate
/// of joint `j` alone.
fn joint_twists(s: &mut Sym<'_>) -> Vec<Vec<(usize, V3, V3)>> {
    let tree = s.tree;
    let n = tree.dof();
    let (zero, one) = (s.g.zero(), s.g.constant(1.0));
    let ez = [zero, zero, one];
    let z3 = [zero; 3];
    let mut out: Vec<Vec<(usize, V3, V3)>> = Vec::with_capacity(n);
    for i in 0..n {
        let l = &tree.links[i];
        let mut list = Vec::new();
        if let Some(p) = l.parent {
            let off = s.offset(i);
            for k in 0..out[p].len() {
                let (j, w, v) = out[p][k];
                let wo = s.cross(w, off);
                let v = s.add3(v, wo);
                let w = s.child_frame(i, w);
                let v = s.child_frame(i, v);
                list.push((j, w, v));
            }
        }
        list.push(match l.kind {
            JointKind::Revolute => (i, ez, z3),
            JointKind::Prismatic => (i, z3, ez),
        });
        out.push(list);
    }
    out
}

/// Standard parameters `unit` (model body frame, about its origin) of body `b` as the mass,
/// first moment and inertia about the origin in link `b`'s frame (`x_link = A x_body − d e_z`).
fn link_parameters(tree: &Tree, b: usize, unit: &[f64; 10]) -> (f64, Vec3, Mat3) {
    let (a, d) = tree.links[b].to_link;
    let [xx, xy, xz, yy, yz, zz, mx, my, mz, m] = *unit;
    let jb = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    let ha = mat_vec(&a, &[mx, my, mz]);
    let ja = mat_mul(&a, &mat_mul(&jb, &transpose(&a)));
    // The new origin is r = d e_z from the old one: h' = h − m r and
    // J' = J + m(|r|² 1 − r rᵀ) − 2 (r·h) 1 + r hᵀ + h rᵀ.
    let h = [ha[0], ha[1], ha[2] - m * d];
    let mut j = ja;
    let rh = d * ha[2];
    for (r, row) in j.iter_mut().enumerate() {
        row[r] += m * d * d - 2.0 * rh;
    }
    j[2][2] -= m * d * d;
    for r in 0..3 {
        j[r][2] += d * ha[r];
        j[2][r] += d * ha[r];
    }
    (m, h, j)
}

/// Body `b`'s Newton–Euler wrench about its origin (eq. 12) for constant parameters:
/// `f = m a + U h`, `n = J ω̇ + ω × Jω + h × a`.
fn unit_wrench(s: &mut Sym<'_>, b: usize, mo: &Motion, m: f64, h: &Vec3, j: &Mat3) -> (V3, V3) {
    let (w, wd, a) = (mo.omega[b], mo.omegad[b], mo.acc[b]);
    let mc = s.c(m);
    let hc = s.cv(h);
    let ma = s.scale3(mc, a);
    let u = s.u_matrix(w, wd);
    let uh = s.mat_vec(&u, hc);
    let f = s.add3(ma, uh);
    let jm: M3 = s.cm(j);
    let jwd = s.mat_vec(&jm, wd);
    let gyro = s.gyro(j, w);
    let ha = s.cross(hc, a);
    let nm = s.add3(jwd, gyro);
    let nm = s.add3(nm, ha);
    (f, nm)
}
