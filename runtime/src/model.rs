//! The validated mechanism model: what the spec layer produces, the generator compiles and the
//! generic runtime evaluates. Plain data, SI units (m, kg, s, rad, N, N·m), no serde.
//!
//! # Conventions
//! * Body `i` is moved by joint `i`: `model.joints.len() == model.bodies.len() == dof()`. The fixed
//!   base (world) is implicit and carries no body.
//! * `joints[i].parent` is `None` (the base) or `Some(p)` with `p < i`: parents come first, so a
//!   forward sweep `0..n` visits parents before children and a backward sweep `(0..n).rev()`
//!   visits children before parents.
//! * Joint `i`'s generalized coordinate is `q[i]` (angle in rad for R, displacement in m for P).
//! * Body frame `i` is joint `i`'s frame after the motion: `X_i = X_parent · origin_i ·
//!   motion_i(q_i)`, where `motion` is the rotation by `q_i` about `axis_i` (R) or the
//!   translation `q_i · axis_i` (P), both in joint `i`'s frame. (This is URDF's convention: the
//!   child link frame is the joint frame.)
//! * A body's inertial data — mass, mass centre and inertia about the mass centre — are in its
//!   own body frame. Massless bodies (mass 0, zero inertia) are allowed: the intermediate bodies
//!   of an expanded U or S joint, or URDF links without `<inertial>`.
//!
//! Closed loops (`crate::closed`) add loop-closing joints beside such a spanning tree; the tree
//! part stays as it is.

use alloc::string::String;
use alloc::vec::Vec;

/// 3-vector.
pub type Vec3 = [f64; 3];
/// 3×3 matrix, row-major: `m[row][col]`.
pub type Mat3 = [[f64; 3]; 3];

/// A rigid transform `x_parent = rotation · x_child + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Rotation matrix whose columns are the child frame's axes in the parent frame.
    pub rotation: Mat3,
    /// Position of the child frame's origin in the parent frame (m).
    pub translation: Vec3,
}

/// Joint kinds of the tree. U and S joints of the spec are expanded into chains of revolutes
/// with massless intermediate bodies before they reach the model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about `axis` by `q` (rad).
    Revolute,
    /// Translation along `axis` by `q` (m).
    Prismatic,
}

/// A rigid body's inertial data, in its own body frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Name (from the spec; unique).
    pub name: String,
    /// Mass (kg), `>= 0`.
    pub mass: f64,
    /// Mass centre in the body frame (m).
    pub com: Vec3,
    /// Inertia tensor about the mass centre, body-frame axes (kg·m²); symmetric.
    pub inertia: Mat3,
}

/// A joint of the spanning tree; joint `i` moves body `i`.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name (from the spec; unique).
    pub name: String,
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Parent body (`None`: the fixed base); always a smaller index than this joint.
    pub parent: Option<usize>,
    /// Pose of the joint frame (at `q = 0`) in the parent body frame.
    pub origin: Transform,
    /// Unit axis in the joint frame.
    pub axis: Vec3,
    /// Friction and rotor inertia at the joint ([`Drive::NONE`] unless the spec's `[scene]`
    /// turns them on).
    pub drive: Drive,
}

/// What a joint's drive adds to the rigid-body dynamics: the lecture's dissipative efforts
/// `δ` (viscous and Coulomb friction) and the rotor inertia reflected through the gearbox
/// (`I_a = J_rotor N²`, the "armature" of URDF-based tools). The joint effort becomes
/// `τ = (rigid-body effort) + I_a q̈ + b q̇ + c q̇ / √(q̇² + v_s²)`; the inertia matrix gains
/// `I_a` on its diagonal. Coulomb friction is regularized: a smooth saturation that reaches
/// 71 % of `c` at `|q̇| = v_s` and 99.5 % at `10 v_s`, so that integrators and Newton steps see
/// a continuous model. All zero means none.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Drive {
    /// Viscous coefficient `b` (N·m·s/rad revolute, N·s/m prismatic), `>= 0`.
    pub viscous: f64,
    /// Coulomb level `c` (N·m or N), `>= 0`.
    pub coulomb: f64,
    /// Speed scale `v_s` of the Coulomb law (rad/s or m/s), `> 0` when `coulomb > 0`.
    pub coulomb_velocity: f64,
    /// Reflected rotor inertia `I_a` (kg·m² revolute, kg prismatic), `>= 0`.
    pub armature: f64,
}

impl Drive {
    /// No friction, no rotor inertia.
    pub const NONE: Drive = Drive {
        viscous: 0.0,
        coulomb: 0.0,
        coulomb_velocity: 0.0,
        armature: 0.0,
    };

    /// `true` when the drive adds nothing.
    pub fn is_none(&self) -> bool {
        self.viscous == 0.0 && self.coulomb == 0.0 && self.armature == 0.0
    }

    /// The friction effort `b q̇ + c q̇ / √(q̇² + v_s²)` (opposes the motion: its power
    /// `q̇ · friction(q̇)` is never negative).
    pub fn friction(&self, qd: f64) -> f64 {
        let mut f = self.viscous * qd;
        if self.coulomb != 0.0 {
            let vs = self.coulomb_velocity;
            f += self.coulomb * qd / crate::math::sqrt(qd * qd + vs * vs);
        }
        f
    }

    /// The whole drive effort `I_a q̈ + friction(q̇)`.
    pub fn effort(&self, qd: f64, qdd: f64) -> f64 {
        self.armature * qdd + self.friction(qd)
    }
}

/// A validated kinematic tree with its inertial data.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Mechanism name (a Rust identifier-friendly string).
    pub name: String,
    /// Gravitational acceleration in the base frame (m/s²), e.g. `[0, 0, -9.81]`.
    pub gravity: Vec3,
    /// Bodies; body `i` is moved by joint `i`.
    pub bodies: Vec<Body>,
    /// Joints; `joints[i].parent < i`.
    pub joints: Vec<Joint>,
}

impl Model {
    /// Number of degrees of freedom (= joints = bodies).
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// `true` when joint `j` is `i` or an ancestor of body `i` (body `i` depends on `q[j]`).
    pub fn supports(&self, j: usize, i: usize) -> bool {
        let mut k = Some(i);
        while let Some(b) = k {
            if b == j {
                return true;
            }
            k = self.joints[b].parent;
        }
        false
    }
}

impl Transform {
    /// The identity transform.
    pub const IDENTITY: Transform = Transform {
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        translation: [0.0; 3],
    };

    /// From a translation and fixed-axis X-Y-Z roll-pitch-yaw angles (URDF's convention:
    /// `R = Rz(yaw) · Ry(pitch) · Rx(roll)`). Angles that are exact multiples of π/2 (as `f64`)
    /// give exact 0 and ±1 entries (see [`exact_sin_cos`]).
    pub fn from_xyz_rpy(xyz: Vec3, rpy: Vec3) -> Transform {
        Transform {
            rotation: rpy_to_matrix(rpy),
            translation: xyz,
        }
    }

    /// `self · other` (first `other`, then `self`): the pose of `other`'s child in `self`'s parent.
    pub fn compose(&self, other: &Transform) -> Transform {
        let rotation = mat_mul(&self.rotation, &other.rotation);
        let r = mat_vec(&self.rotation, &other.translation);
        let t = &self.translation;
        Transform {
            rotation,
            translation: [t[0] + r[0], t[1] + r[1], t[2] + r[2]],
        }
    }

    /// Apply to a point: `rotation · p + translation`.
    pub fn apply(&self, p: &Vec3) -> Vec3 {
        let r = mat_vec(&self.rotation, p);
        [
            r[0] + self.translation[0],
            r[1] + self.translation[1],
            r[2] + self.translation[2],
        ]
    }
}

/// `(sin a, cos a)`, exact (0, ±1) when `a` is the `f64` nearest to an integer multiple of π/2
/// (|k| ≤ 8); otherwise the math layer's result.
pub fn exact_sin_cos(a: f64) -> (f64, f64) {
    let k = a / core::f64::consts::FRAC_PI_2;
    let kr = libm::round(k);
    if kr.abs() <= 8.0 && (kr * core::f64::consts::FRAC_PI_2) == a {
        let m = ((kr as i64) % 4 + 4) % 4;
        return match m {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        };
    }
    crate::math::sin_cos(a)
}

/// Rotation matrix of fixed-axis X-Y-Z angles: `Rz(y) · Ry(p) · Rx(r)`.
pub fn rpy_to_matrix(rpy: Vec3) -> Mat3 {
    let (sr, cr) = exact_sin_cos(rpy[0]);
    let (sp, cp) = exact_sin_cos(rpy[1]);
    let (sy, cy) = exact_sin_cos(rpy[2]);
    [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
}

/// Rotation by angle `q` about the unit `axis` (Rodrigues).
pub fn axis_angle(axis: &Vec3, q: f64) -> Mat3 {
    let (s, c) = exact_sin_cos(q);
    let [x, y, z] = *axis;
    let v = 1.0 - c;
    [
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ]
}

/// `a · b` for 3×3 matrices.
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, e) in row.iter_mut().enumerate() {
            *e = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    m
}

/// `a · v`.
pub fn mat_vec(a: &Mat3, v: &Vec3) -> Vec3 {
    [
        a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2],
        a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2],
        a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2],
    ]
}

/// The rotation about `u × v` that turns the unit `u` onto the unit `v` (a half turn about a
/// perpendicular when they are opposite).
pub fn align(u: &Vec3, v: &Vec3) -> Mat3 {
    let k = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let c = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let ss = k[0] * k[0] + k[1] * k[1] + k[2] * k[2];
    let (k, f) = if ss > 1e-24 {
        (k, (1.0 - c) / ss)
    } else if c > 0.0 {
        return Transform::IDENTITY.rotation;
    } else {
        // A half turn about a unit perpendicular p: R = 2 p pᵀ − 1.
        let (p, _) = crate::closed::perpendiculars(u);
        return core::array::from_fn(|i| {
            core::array::from_fn(|j| 2.0 * p[i] * p[j] - if i == j { 1.0 } else { 0.0 })
        });
    };
    // Rodrigues: R = 1 + [k]× + [k]×² (1 − c)/|k|².
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    let kx2 = mat_mul(&kx, &kx);
    core::array::from_fn(|i| {
        core::array::from_fn(|j| if i == j { 1.0 } else { 0.0 } + kx[i][j] + f * kx2[i][j])
    })
}

/// The rotation matrix of a unit quaternion `[w, x, y, z]` (the inverse of
/// [`matrix_quaternion`]; the quaternion is taken as given, not normalized).
pub fn quaternion_matrix(q: &[f64; 4]) -> Mat3 {
    let [w, x, y, z] = *q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Unit quaternion `[w, x, y, z]` of a rotation matrix (Shepperd's method: the largest
/// component first, so no division by a small number).
pub fn matrix_quaternion(r: &Mat3) -> [f64; 4] {
    let sq = |v: f64| libm::sqrt(v);
    let tr = r[0][0] + r[1][1] + r[2][2];
    let q = if tr > 0.0 {
        let s = sq(tr + 1.0) * 2.0;
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = sq(1.0 + r[0][0] - r[1][1] - r[2][2]) * 2.0;
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = sq(1.0 + r[1][1] - r[0][0] - r[2][2]) * 2.0;
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = sq(1.0 + r[2][2] - r[0][0] - r[1][1]) * 2.0;
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = sq(q.iter().map(|c| c * c).sum::<f64>());
    [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
}

/// `aᵀ`.
pub fn transpose(a: &Mat3) -> Mat3 {
    [
        [a[0][0], a[1][0], a[2][0]],
        [a[0][1], a[1][1], a[2][1]],
        [a[0][2], a[1][2], a[2][2]],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_quarter_turns() {
        let h = core::f64::consts::FRAC_PI_2;
        assert_eq!(exact_sin_cos(h), (1.0, 0.0));
        assert_eq!(exact_sin_cos(-h), (-1.0, 0.0));
        assert_eq!(exact_sin_cos(2.0 * h), (0.0, -1.0));
        // URDF's 1.570796325 is not π/2: it keeps its (tiny) cosine.
        assert!(exact_sin_cos(1.570796325).1 != 0.0);
    }

    #[test]
    fn rpy_is_fixed_axis_xyz() {
        // Yaw of 90°: x axis goes to y.
        let h = core::f64::consts::FRAC_PI_2;
        let r = rpy_to_matrix([0.0, 0.0, h]);
        assert_eq!(mat_vec(&r, &[1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
        // Rz(y)·Ry(p)·Rx(r) equals the product of the elementary rotations.
        let (a, b, c) = (0.3, -0.7, 1.1);
        let m = mat_mul(
            &axis_angle(&[0.0, 0.0, 1.0], c),
            &mat_mul(
                &axis_angle(&[0.0, 1.0, 0.0], b),
                &axis_angle(&[1.0, 0.0, 0.0], a),
            ),
        );
        let r = rpy_to_matrix([a, b, c]);
        for i in 0..3 {
            for j in 0..3 {
                assert!((m[i][j] - r[i][j]).abs() < 1e-15);
            }
        }
    }
}
