//! The Natural Orthogonal Complement (NOC) evaluated literally, in the base frame, as matrices:
//! the generic runtime and the first oracle for generated code.
//!
//! Every quantity is the one of R. Sinatra, "Dynamics of PKM" (EURON 2007; the method of Angeles
//! & Lee, 1988), in the conventions of docs/method.md, "Conventions"; equation numbers in the
//! comments refer to that lecture. Body `i` is moved by joint `i` (see [`crate::model`]):
//!
//! * twist `t_i = [ω_i; ċ_i]` (1), wrench `w_i = [n_i; f_i]` about the mass centre (2);
//! * `M_i = diag(I_i, m_i 1)`, `W_i = diag(Ω_i, 0)` (4)–(6), Newton–Euler (7)–(12);
//! * `t = T q̇` (14), with the serial/tree twist-shaping columns (31)–(34), (46)–(48);
//! * `I = TᵀMT`, `C = Tᵀ(MṪ + WMT)` (21)–(24).
//!
//! The sign convention of the outputs: `inverse_dynamics(q, q̇, q̈) = I q̈ + C q̇ − γ`, the actuator
//! effort that produces the motion, so `inverse_dynamics(q, 0, 0) = gravity(q)` holds the
//! mechanism still.
//!
//! Nothing here is optimised: matrices are formed in full (`6r × n`, `6r × 6r`), structural zeros
//! included. This is the reference the generated code is checked against, not a fast path.

use alloc::vec;
use alloc::vec::Vec;
use core::fmt;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use crate::model::{JointKind, Mat3, Model, Transform, Vec3, axis_angle};

/// The mass matrix is not (numerically) positive definite: the `LDLᵀ` factorization met a pivot
/// that is not `> 1e-12 · max_k I_kk` (or is NaN).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Singular {
    /// Index of the failing pivot (= the generalized coordinate, no pivoting is done); the
    /// number of coordinates when the pivots passed but the result is not finite (a non-finite
    /// input or an overflow).
    pub pivot: usize,
    /// The failing pivot `d_pivot` of `LDLᵀ` (may be `≤ 0` or NaN).
    pub value: f64,
    /// `max d_k / d_pivot` over the pivots computed so far, a lower bound of the 2-norm condition
    /// number (see [`Ldlt::condition_estimate`]); `+∞` when `value ≤ 0` or NaN.
    pub condition_estimate: f64,
}

impl fmt::Display for Singular {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "mass matrix is singular or not positive definite: LDLᵀ pivot {} is {:e} \
             (condition number ≥ {:e})",
            self.pivot, self.value, self.condition_estimate
        )
    }
}

impl core::error::Error for Singular {}

/// Base-frame kinematics of every body at one state `(q, q̇)`; entry `i` is body `i` or joint `i`.
#[derive(Debug, Clone, PartialEq)]
pub struct Kinematics {
    /// `R_i`: rotation body frame → base (columns: body axes in the base frame).
    pub rotation: Vec<Matrix3<f64>>,
    /// Origin of body frame `i` (= joint frame `i` after the motion) in the base frame.
    pub origin: Vec<Vector3<f64>>,
    /// `c_i`: mass centre of body `i` in the base frame.
    pub com: Vec<Vector3<f64>>,
    /// `ω_i`: angular velocity of body `i`.
    pub omega: Vec<Vector3<f64>>,
    /// Velocity of the origin of body frame `i`.
    pub origin_velocity: Vec<Vector3<f64>>,
    /// `ċ_i`: velocity of the mass centre of body `i`.
    pub com_velocity: Vec<Vector3<f64>>,
    /// `e_j`: unit axis of joint `j` in the base frame.
    pub axis: Vec<Vector3<f64>>,
    /// `o_j`: a point of joint `j`'s axis in the base frame (the joint-frame origin; for a
    /// prismatic joint the body origin, which slides along the axis — the twist-shaping column
    /// of a prismatic joint does not depend on it).
    pub axis_point: Vec<Vector3<f64>>,
    /// `ȯ_j`: velocity of `o_j` as a point carried by body `j`.
    pub axis_point_velocity: Vec<Vector3<f64>>,
}

fn vec3(v: &Vec3) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

fn mat3(m: &Mat3) -> Matrix3<f64> {
    Matrix3::new(
        m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2],
    )
}

/// The cross-product matrix: `cpm(a) x = a × x`.
fn cpm(a: &Vector3<f64>) -> Matrix3<f64> {
    a.cross_matrix()
}

fn check_len(model: &Model, what: &str, v: &[f64]) {
    assert_eq!(
        v.len(),
        model.dof(),
        "{what} has length {} but the model has {} degrees of freedom",
        v.len(),
        model.dof()
    );
}

/// The motion of joint `i` by `q`, joint frame → body frame `i` (which is the joint frame moved).
fn joint_motion(kind: JointKind, axis: &Vec3, q: f64) -> Transform {
    match kind {
        JointKind::Revolute => Transform {
            rotation: axis_angle(axis, q),
            translation: [0.0; 3],
        },
        JointKind::Prismatic => Transform {
            rotation: Transform::IDENTITY.rotation,
            translation: [q * axis[0], q * axis[1], q * axis[2]],
        },
    }
}

/// Forward kinematics: the pose of every body frame in the base frame,
/// `X_i = X_parent · origin_i · motion_i(q_i)`.
pub fn body_poses(model: &Model, q: &[f64]) -> Vec<Transform> {
    check_len(model, "q", q);
    let mut poses: Vec<Transform> = Vec::with_capacity(model.dof());
    for (i, joint) in model.joints.iter().enumerate() {
        let local = joint
            .origin
            .compose(&joint_motion(joint.kind, &joint.axis, q[i]));
        let pose = match joint.parent {
            None => local,
            Some(p) => poses[p].compose(&local),
        };
        poses.push(pose);
    }
    poses
}

/// Positions, orientations and velocities of every body, joint axes and axis points, in the base
/// frame. Velocities by the recursion of the lecture (25)–(48): `ω_i = ω_p + q̇_i e_i` (R) or
/// `ω_i = ω_p` (P); origin velocity `v_i = v_p + ω_p × (o_i − o_p) (+ q̇_i e_i for P)`;
/// `ċ_i = v_i + ω_i × (c_i − o_i)`.
pub fn kinematics(model: &Model, q: &[f64], qd: &[f64]) -> Kinematics {
    check_len(model, "q̇", qd);
    let poses = body_poses(model, q);
    let n = model.dof();
    let mut k = Kinematics {
        rotation: Vec::with_capacity(n),
        origin: Vec::with_capacity(n),
        com: Vec::with_capacity(n),
        omega: Vec::with_capacity(n),
        origin_velocity: Vec::with_capacity(n),
        com_velocity: Vec::with_capacity(n),
        axis: Vec::with_capacity(n),
        axis_point: Vec::with_capacity(n),
        axis_point_velocity: Vec::with_capacity(n),
    };
    for (i, (joint, body)) in model.joints.iter().zip(&model.bodies).enumerate() {
        let r = mat3(&poses[i].rotation);
        let o = vec3(&poses[i].translation);
        let c = r * vec3(&body.com) + o;
        // The axis is fixed in the joint frame and unchanged by the joint's own motion.
        let e = r * vec3(&joint.axis);
        let (w_p, v_p, o_p) = match joint.parent {
            None => (Vector3::zeros(), Vector3::zeros(), Vector3::zeros()),
            Some(p) => (k.omega[p], k.origin_velocity[p], k.origin[p]),
        };
        // Velocity of the point of the parent body that coincides with o_i.
        let v_carried = v_p + w_p.cross(&(o - o_p));
        let (w, v) = match joint.kind {
            JointKind::Revolute => (w_p + e * qd[i], v_carried),
            JointKind::Prismatic => (w_p, v_carried + e * qd[i]),
        };
        let cd = v + w.cross(&(c - o));
        k.rotation.push(r);
        k.origin.push(o);
        k.com.push(c);
        k.omega.push(w);
        k.origin_velocity.push(v);
        k.com_velocity.push(cd);
        k.axis.push(e);
        k.axis_point.push(o);
        k.axis_point_velocity.push(v);
    }
    k
}

/// Column of `T_i` for joint `j` (j supports i), lecture (31)–(34) and (46)–(48):
/// R `[e_j; e_j × (c_i − o_j)]`, P `[0; e_j]`.
fn shaping_column(kind: JointKind, k: &Kinematics, i: usize, j: usize) -> [Vector3<f64>; 2] {
    let e = k.axis[j];
    match kind {
        JointKind::Revolute => [e, e.cross(&(k.com[i] - k.axis_point[j]))],
        JointKind::Prismatic => [Vector3::zeros(), e],
    }
}

/// Time derivative of [`shaping_column`] along the motion: `ė_j = ω_j × e_j` (the axis is carried
/// by the parent and by body j alike), R `[ė_j; ė_j × (c_i − o_j) + e_j × (ċ_i − ȯ_j)]`,
/// P `[0; ė_j]`.
fn shaping_column_rate(kind: JointKind, k: &Kinematics, i: usize, j: usize) -> [Vector3<f64>; 2] {
    let e = k.axis[j];
    let ed = k.omega[j].cross(&e);
    match kind {
        JointKind::Revolute => [
            ed,
            ed.cross(&(k.com[i] - k.axis_point[j]))
                + e.cross(&(k.com_velocity[i] - k.axis_point_velocity[j])),
        ],
        JointKind::Prismatic => [Vector3::zeros(), ed],
    }
}

/// Fill a `6r × n` matrix from per-(body, supporting joint) columns; zero elsewhere.
fn assemble(
    model: &Model,
    k: &Kinematics,
    column: fn(JointKind, &Kinematics, usize, usize) -> [Vector3<f64>; 2],
) -> DMatrix<f64> {
    let n = model.dof();
    let mut t = DMatrix::zeros(6 * n, n);
    for i in 0..n {
        let mut j = Some(i);
        while let Some(jj) = j {
            let [top, bottom] = column(model.joints[jj].kind, k, i, jj);
            t.fixed_view_mut::<3, 1>(6 * i, jj).copy_from(&top);
            t.fixed_view_mut::<3, 1>(6 * i + 3, jj).copy_from(&bottom);
            j = model.joints[jj].parent;
        }
    }
    t
}

/// The twist-shaping matrix `T` (`6r × n`), `t = T q̇` (14): block row `i` is body `i`'s twist
/// `[ω_i; ċ_i]`; column `j` is (31)–(34), (46)–(48): R `[e_j; e_j × (c_i − o_j)]`,
/// P `[0; e_j]`, zero when joint `j` is not body `i` or one of its ancestors.
pub fn twist_shaping(model: &Model, q: &[f64]) -> DMatrix<f64> {
    let zero = vec![0.0; model.dof()];
    let k = kinematics(model, q, &zero);
    assemble(model, &k, shaping_column)
}

/// `Ṫ`, the exact time derivative of `T(q(t))` along `q̇`, so that `ṫ = T q̈ + Ṫ q̇`.
pub fn twist_shaping_rate(model: &Model, q: &[f64], qd: &[f64]) -> DMatrix<f64> {
    let k = kinematics(model, q, qd);
    assemble(model, &k, shaping_column_rate)
}

/// Base-frame inertia of body `i` about its mass centre, `I_i = R_i I_i^body R_iᵀ`.
fn base_inertia(model: &Model, k: &Kinematics, i: usize) -> Matrix3<f64> {
    let r = &k.rotation[i];
    r * mat3(&model.bodies[i].inertia) * r.transpose()
}

fn extended_mass_of(model: &Model, k: &Kinematics) -> DMatrix<f64> {
    let n = model.dof();
    let mut m = DMatrix::zeros(6 * n, 6 * n);
    for i in 0..n {
        m.fixed_view_mut::<3, 3>(6 * i, 6 * i)
            .copy_from(&base_inertia(model, k, i));
        m.fixed_view_mut::<3, 3>(6 * i + 3, 6 * i + 3)
            .copy_from(&(Matrix3::identity() * model.bodies[i].mass));
    }
    m
}

fn extended_angular_velocity_of(model: &Model, k: &Kinematics) -> DMatrix<f64> {
    let n = model.dof();
    let mut w = DMatrix::zeros(6 * n, 6 * n);
    for i in 0..n {
        w.fixed_view_mut::<3, 3>(6 * i, 6 * i)
            .copy_from(&cpm(&k.omega[i]));
    }
    w
}

/// The extended mass matrix `M = diag(M_i)`, `M_i = diag(I_i, m_i 1₃)` (5), `I_i` in the base
/// frame about `C_i`.
pub fn extended_mass(model: &Model, q: &[f64]) -> DMatrix<f64> {
    let zero = vec![0.0; model.dof()];
    extended_mass_of(model, &kinematics(model, q, &zero))
}

/// The extended angular-velocity matrix `W = diag(W_i)`, `W_i = diag(CPM(ω_i), 0₃)` (4), (6).
pub fn extended_angular_velocity(model: &Model, q: &[f64], qd: &[f64]) -> DMatrix<f64> {
    extended_angular_velocity_of(model, &kinematics(model, q, qd))
}

/// The stacked gravity wrench `w^G`, `w^G_i = [0; m_i g]` (part of `w^E` in (7)–(12)).
fn gravity_wrench(model: &Model) -> DVector<f64> {
    let n = model.dof();
    let g = vec3(&model.gravity);
    let mut w = DVector::zeros(6 * n);
    for (i, body) in model.bodies.iter().enumerate() {
        w.fixed_rows_mut::<3>(6 * i + 3).copy_from(&(g * body.mass));
    }
    w
}

/// The generalized inertia matrix `I = TᵀMT` (21)–(24).
pub fn mass_matrix(model: &Model, q: &[f64]) -> DMatrix<f64> {
    let zero = vec![0.0; model.dof()];
    let k = kinematics(model, q, &zero);
    let t = assemble(model, &k, shaping_column);
    let m = extended_mass_of(model, &k);
    let mut i = t.transpose() * m * t;
    for (j, joint) in model.joints.iter().enumerate() {
        i[(j, j)] += joint.drive.armature;
    }
    i
}

/// Joint friction efforts `b q̇ + c q̇ / √(q̇² + v_s²)` of every joint's [`Drive`](crate::model::Drive) (the lecture's
/// dissipative term `δ`; zero unless the spec's `[scene]` turns friction on).
pub fn friction(model: &Model, qd: &[f64]) -> DVector<f64> {
    check_len(model, "q̇", qd);
    DVector::from_iterator(
        model.dof(),
        model
            .joints
            .iter()
            .zip(qd)
            .map(|(j, v)| j.drive.friction(*v)),
    )
}

/// The matrix of quadratic inertia terms `C = Tᵀ(MṪ + WMT)` (22).
pub fn coriolis_matrix(model: &Model, q: &[f64], qd: &[f64]) -> DMatrix<f64> {
    let k = kinematics(model, q, qd);
    let t = assemble(model, &k, shaping_column);
    let td = assemble(model, &k, shaping_column_rate);
    let m = extended_mass_of(model, &k);
    let w = extended_angular_velocity_of(model, &k);
    t.transpose() * (&m * td + w * &m * &t)
}

/// The quadratic inertia terms `C(q, q̇) q̇`.
pub fn coriolis(model: &Model, q: &[f64], qd: &[f64]) -> DVector<f64> {
    coriolis_matrix(model, q, qd) * DVector::from_column_slice(qd)
}

/// `−γ = −Tᵀ w^G`: the effort that holds the mechanism still against gravity.
pub fn gravity(model: &Model, q: &[f64]) -> DVector<f64> {
    -(twist_shaping(model, q).transpose() * gravity_wrench(model))
}

/// Inverse dynamics `τ = I q̈ + C q̇ − γ + δ(q̇)`, evaluated in the association of docs/method.md, "Evaluation order":
/// `Tᵀ ( M (T q̈ + Ṫ q̇) + W M (T q̇) − w^G )` — body twists `t = T q̇` (14) and twist rates
/// `ṫ = T q̈ + Ṫ q̇` first, then the body Newton–Euler wrenches `M_i ṫ_i + W_i M_i t_i − w^G_i`
/// (7)–(12), then one projection by `Tᵀ` (the constraint wrenches drop out, (15)–(20)). The
/// joints' [`Drive`](crate::model::Drive)s add `I_a q̈ + δ(q̇)` (rotor inertia and friction;
/// none unless the spec's `[scene]` turns them on).
pub fn inverse_dynamics(model: &Model, q: &[f64], qd: &[f64], qdd: &[f64]) -> DVector<f64> {
    check_len(model, "q̈", qdd);
    let k = kinematics(model, q, qd);
    let t = assemble(model, &k, shaping_column);
    let td = assemble(model, &k, shaping_column_rate);
    let m = extended_mass_of(model, &k);
    let w = extended_angular_velocity_of(model, &k);
    let qd = DVector::from_column_slice(qd);
    let qdd = DVector::from_column_slice(qdd);
    let twist = &t * &qd;
    let twist_rate = &t * &qdd + td * &qd;
    let wrench = &m * twist_rate + w * &m * twist - gravity_wrench(model);
    let mut tau = t.transpose() * wrench;
    for (j, joint) in model.joints.iter().enumerate() {
        tau[j] += joint.drive.effort(qd[j], qdd[j]);
    }
    tau
}

/// Forward dynamics: `q̈` from `I q̈ = τ − C q̇ + γ`, by an `LDLᵀ` factorization of `I` written
/// out (see [`ldlt`]). `Err(Singular)` when `I` is not numerically positive definite (a pivot
/// `≤ 1e-12 · max_k I_kk`, or NaN): never a silent NaN from the factorization.
pub fn forward_dynamics(
    model: &Model,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Result<DVector<f64>, Singular> {
    check_len(model, "τ", tau);
    let zero = vec![0.0; model.dof()];
    // inverse_dynamics(q, q̇, 0) = C q̇ − γ.
    let bias = inverse_dynamics(model, q, qd, &zero);
    let rhs = DVector::from_column_slice(tau) - bias;
    let f = ldlt(&mass_matrix(model, q))?;
    let qdd = f.solve(&rhs);
    // A non-finite input that passed the pivots, or an overflow: `Err`, never `Ok(NaN)`.
    if let Some(v) = qdd.iter().find(|v| !v.is_finite()) {
        return Err(Singular {
            pivot: model.dof(),
            value: *v,
            condition_estimate: f64::INFINITY,
        });
    }
    Ok(qdd)
}

/// `A = L D Lᵀ` with `L` unit lower triangular and `D` diagonal (no pivoting), for a symmetric
/// positive definite `A`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ldlt {
    /// Unit lower-triangular factor (the strict upper triangle is zero).
    pub l: DMatrix<f64>,
    /// The pivots `d_k`, all `> 1e-12 · max_k A_kk`.
    pub d: DVector<f64>,
}

impl Ldlt {
    /// Solve `A x = b`.
    pub fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let n = self.d.len();
        assert_eq!(b.len(), n, "right-hand side has the wrong length");
        let mut x = b.clone();
        // L y = b.
        for i in 0..n {
            let mut s = x[i];
            for k in 0..i {
                s -= self.l[(i, k)] * x[k];
            }
            x[i] = s;
        }
        // D z = y.
        for i in 0..n {
            x[i] /= self.d[i];
        }
        // Lᵀ x = z.
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..n {
                s -= self.l[(k, i)] * x[k];
            }
            x[i] = s;
        }
        x
    }

    /// `max d_k / min d_k`, a lower bound of the 2-norm condition number of `A`: each pivot is a
    /// diagonal entry of a Schur complement of `A`, whose eigenvalues lie in `[λ_min(A),
    /// λ_max(A)]`, so `λ_min ≤ d_k ≤ λ_max`. It can underestimate badly (a rotated
    /// ill-conditioned matrix may have equal pivots); use it to detect, not to certify. `1` for
    /// an empty matrix.
    pub fn condition_estimate(&self) -> f64 {
        if self.d.is_empty() {
            return 1.0;
        }
        self.d.max() / self.d.min()
    }
}

/// Factor a symmetric matrix as `L D Lᵀ` (only the lower triangle of `a` is read). Fails with
/// [`Singular`] at the first pivot that is not `> 1e-12 · max_k a_kk` (NaN included).
pub fn ldlt(a: &DMatrix<f64>) -> Result<Ldlt, Singular> {
    let n = a.nrows();
    assert_eq!(a.ncols(), n, "LDLᵀ of a non-square matrix");
    let max_diag = (0..n).map(|k| a[(k, k)]).fold(0.0_f64, f64::max);
    let tol = 1e-12 * max_diag;
    let mut l = DMatrix::identity(n, n);
    let mut d = DVector::zeros(n);
    let mut max_pivot = 0.0_f64;
    for j in 0..n {
        let mut dj = a[(j, j)];
        for k in 0..j {
            dj -= l[(j, k)] * l[(j, k)] * d[k];
        }
        // Comparisons with NaN are false: a NaN pivot (or tol = +∞ from an infinite diagonal)
        // is not regular either.
        let regular = dj.is_finite() && dj > tol;
        if !regular {
            max_pivot = max_pivot.max(dj);
            let condition_estimate = if dj > 0.0 && dj.is_finite() {
                max_pivot / dj
            } else {
                f64::INFINITY
            };
            return Err(Singular {
                pivot: j,
                value: dj,
                condition_estimate,
            });
        }
        max_pivot = max_pivot.max(dj);
        d[j] = dj;
        for i in j + 1..n {
            let mut s = a[(i, j)];
            for k in 0..j {
                s -= l[(i, k)] * l[(j, k)] * d[k];
            }
            l[(i, j)] = s / dj;
        }
    }
    Ok(Ldlt { l, d })
}

/// Kinetic energy `½ Σ (m_i ċ_iᵀ ċ_i + ω_iᵀ I_i ω_i) + ½ Σ I_a q̇²` (= `½ q̇ᵀ I q̇`; the last
/// sum is the rotors' energy, zero without rotor inertia).
pub fn kinetic_energy(model: &Model, q: &[f64], qd: &[f64]) -> f64 {
    let k = kinematics(model, q, qd);
    let mut e = 0.0;
    for (i, body) in model.bodies.iter().enumerate() {
        let w = &k.omega[i];
        let cd = &k.com_velocity[i];
        e += body.mass * cd.dot(cd) + w.dot(&(base_inertia(model, &k, i) * w));
    }
    for (j, joint) in model.joints.iter().enumerate() {
        e += joint.drive.armature * qd[j] * qd[j];
    }
    0.5 * e
}

/// Potential energy of gravity, `−Σ m_i gᵀ c_i` (zero at the base origin).
pub fn potential_energy(model: &Model, q: &[f64]) -> f64 {
    let zero = vec![0.0; model.dof()];
    let k = kinematics(model, q, &zero);
    let g = vec3(&model.gravity);
    -model
        .bodies
        .iter()
        .zip(&k.com)
        .map(|(b, c)| b.mass * g.dot(c))
        .sum::<f64>()
}
