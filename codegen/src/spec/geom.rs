//! Small geometry helpers for the spec layer: elementary transforms, DH frames, inertia algebra.

use runtime::model::{Mat3, Transform, Vec3, mat_mul, transpose};

use super::ir::Dh;
#[cfg(test)]
use super::ir::Kind;

/// Rotation about x by `a` (exact for quarter turns).
pub(crate) fn rot_x(a: f64) -> Transform {
    Transform::from_xyz_rpy([0.0; 3], [a, 0.0, 0.0])
}

/// Rotation about z by `a` (exact for quarter turns).
pub(crate) fn rot_z(a: f64) -> Transform {
    Transform::from_xyz_rpy([0.0; 3], [0.0, 0.0, a])
}

/// Rotation by `a` about the unit `axis`, exact (correctly rounded) at multiples of 15°
/// (`spec::expr::sin_cos`).
pub(crate) fn rotation(axis: &Vec3, a: f64) -> Mat3 {
    let (s, c) = super::expr::sin_cos(a);
    let e = axis;
    let k = 1.0 - c;
    [
        [
            c + e[0] * e[0] * k,
            e[0] * e[1] * k - e[2] * s,
            e[0] * e[2] * k + e[1] * s,
        ],
        [
            e[1] * e[0] * k + e[2] * s,
            c + e[1] * e[1] * k,
            e[1] * e[2] * k - e[0] * s,
        ],
        [
            e[2] * e[0] * k - e[1] * s,
            e[2] * e[1] * k + e[0] * s,
            c + e[2] * e[2] * k,
        ],
    ]
}

/// Pure translation.
pub(crate) fn trans(t: Vec3) -> Transform {
    Transform {
        rotation: Transform::IDENTITY.rotation,
        translation: t,
    }
}

/// `true` for the exact identity.
pub(crate) fn is_identity(t: &Transform) -> bool {
    *t == Transform::IDENTITY
}

/// `a · b`, skipping the arithmetic when either is the identity (keeps values bit-exact).
pub(crate) fn compose(a: &Transform, b: &Transform) -> Transform {
    if is_identity(a) {
        *b
    } else if is_identity(b) {
        *a
    } else {
        a.compose(b)
    }
}

/// Standard DH: the joint frame's pose in the previous (distal) frame, before the motion:
/// `Rz(theta)` for both R and P (the motion then is `Rz(q)` or `Tz(q)`).
pub(crate) fn dh_origin(dh: &Dh) -> Transform {
    rot_z(dh.theta)
}

/// Standard DH: the rest of the link transform after the motion, `Tz(d)·Tx(a)·Rx(alpha)`:
/// the pose of the distal DH frame (the child's user frame) in the joint frame.
pub(crate) fn dh_offset(dh: &Dh) -> Transform {
    Transform {
        rotation: rot_x(dh.alpha).rotation,
        translation: [dh.a, 0.0, dh.d],
    }
}

/// Modified DH: `Rx(alpha)·Tx(a)·Rz(theta)·Tz(d)`, the joint frame's pose in the parent's frame.
pub(crate) fn mdh_origin(dh: &Dh) -> Transform {
    let rx = rot_x(dh.alpha);
    let tail = Transform {
        rotation: rot_z(dh.theta).rotation,
        translation: [0.0, 0.0, dh.d],
    };
    compose(&compose(&rx, &trans([dh.a, 0.0, 0.0])), &tail)
}

/// The full DH link transform at joint value `q` (for tests and documentation):
/// standard `Rz(theta+q)·Tz(d)·Tx(a)·Rx(alpha)` (R) or `Rz(theta)·Tz(d+q)·Tx(a)·Rx(alpha)` (P).
#[cfg(test)]
pub(crate) fn dh_matrix(dh: &Dh, kind: Kind, q: f64) -> Transform {
    let (th, d) = match kind {
        Kind::Prismatic => (dh.theta, dh.d + q),
        _ => (dh.theta + q, dh.d),
    };
    rot_z(th)
        .compose(&trans([0.0, 0.0, d]))
        .compose(&trans([dh.a, 0.0, 0.0]))
        .compose(&rot_x(dh.alpha))
}

/// Modified DH link transform at `q`: `Rx(alpha)·Tx(a)·Rz(theta+q)·Tz(d)` (R) or
/// `Rx(alpha)·Tx(a)·Rz(theta)·Tz(d+q)` (P).
#[cfg(test)]
pub(crate) fn mdh_matrix(dh: &Dh, kind: Kind, q: f64) -> Transform {
    let (th, d) = match kind {
        Kind::Prismatic => (dh.theta, dh.d + q),
        _ => (dh.theta + q, dh.d),
    };
    rot_x(dh.alpha)
        .compose(&trans([dh.a, 0.0, 0.0]))
        .compose(&rot_z(th))
        .compose(&trans([0.0, 0.0, d]))
}

/// `R · I · Rᵀ`, symmetrized. Returns `i` unchanged when `r` is the identity.
pub(crate) fn rotate_inertia(r: &Mat3, i: &Mat3) -> Mat3 {
    if *r == Transform::IDENTITY.rotation {
        return *i;
    }
    let m = mat_mul(&mat_mul(r, i), &transpose(r));
    let mut s = m;
    for a in 0..3 {
        for b in 0..3 {
            s[a][b] = 0.5 * (m[a][b] + m[b][a]);
        }
    }
    s
}

/// Inertial data of one rigid part: mass, mass centre, inertia about the mass centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct MassProps {
    pub mass: f64,
    pub com: Vec3,
    pub inertia: Mat3,
}

impl MassProps {
    pub(crate) const ZERO: MassProps = MassProps {
        mass: 0.0,
        com: [0.0; 3],
        inertia: [[0.0; 3]; 3],
    };

    /// The same part seen from a frame in which the part's frame has pose `t`.
    pub(crate) fn transformed(&self, t: &Transform) -> MassProps {
        if is_identity(t) {
            return *self;
        }
        MassProps {
            mass: self.mass,
            com: t.apply(&self.com),
            inertia: rotate_inertia(&t.rotation, &self.inertia),
        }
    }

    /// The parts rigidly joined: total mass, common mass centre, inertia about it (parallel-axis
    /// theorem). One part is returned unchanged.
    pub(crate) fn combine(parts: &[MassProps]) -> MassProps {
        match parts {
            [] => MassProps::ZERO,
            [p] => *p,
            _ => {
                let mass: f64 = parts.iter().map(|p| p.mass).sum();
                let com = if mass > 0.0 {
                    let mut c = [0.0; 3];
                    for p in parts {
                        for (k, ck) in c.iter_mut().enumerate() {
                            *ck += p.mass * p.com[k];
                        }
                    }
                    c.map(|x| x / mass)
                } else {
                    parts[0].com
                };
                let mut inertia = [[0.0; 3]; 3];
                for p in parts {
                    let d = [p.com[0] - com[0], p.com[1] - com[1], p.com[2] - com[2]];
                    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    for a in 0..3 {
                        for b in 0..3 {
                            let delta = if a == b { dd } else { 0.0 };
                            inertia[a][b] += p.inertia[a][b] + p.mass * (delta - d[a] * d[b]);
                        }
                    }
                }
                MassProps { mass, com, inertia }
            }
        }
    }

    /// Inertia about the point `o` (not the mass centre): `I_c + m(|d|²E − d dᵀ)`, `d = com − o`.
    #[cfg(test)]
    pub(crate) fn inertia_about(&self, o: &Vec3) -> Mat3 {
        let d = [self.com[0] - o[0], self.com[1] - o[1], self.com[2] - o[2]];
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let mut m = self.inertia;
        for a in 0..3 {
            for b in 0..3 {
                let delta = if a == b { dd } else { 0.0 };
                m[a][b] += self.mass * (delta - d[a] * d[b]);
            }
        }
        m
    }
}

/// Principal moments (ascending) of a symmetric 3×3 matrix.
pub(crate) fn principal_moments(i: &Mat3) -> [f64; 3] {
    let m = nalgebra::Matrix3::new(
        i[0][0], i[0][1], i[0][2], i[1][0], i[1][1], i[1][2], i[2][0], i[2][1], i[2][2],
    );
    let ev = m.symmetric_eigenvalues();
    let mut v = [ev[0], ev[1], ev[2]];
    v.sort_by(f64::total_cmp);
    v
}

/// Checks that an inertia tensor about the mass centre is physically possible: positive
/// semi-definite and satisfying the triangle inequality of its principal moments
/// (`a + b >= c`), with relative tolerance `1e-12`. The zero tensor is allowed.
/// The error is `(message, hint)`.
pub(crate) fn check_inertia(i: &Mat3) -> Result<(), (String, String)> {
    let [a, b, c] = principal_moments(i);
    let scale = a.abs().max(b.abs()).max(c.abs());
    let tol = 1e-12 * scale;
    // A moment within the tolerance is rounding noise of the eigenvalues: written as 0 (not as
    // `-0.00000000000000000000000222045`).
    let num = |x: f64| num(if x.abs() <= tol { 0.0 } else { x });
    let moments = format!("principal moments {}, {}, {} kg·m²", num(a), num(b), num(c));
    if a < -tol {
        return Err((
            "inertia is not positive semi-definite".into(),
            format!(
                "{moments}; a physical inertia has no negative principal moment (check signs of ixy, ixz, iyz: URDF and this format use the tensor entries, ixy = -∫xy dm)"
            ),
        ));
    }
    if a + b < c - tol {
        return Err((
            "inertia violates the triangle inequality of principal moments".into(),
            format!(
                "{moments}; every principal moment must be at most the sum of the other two ({} + {} < {})",
                num(a),
                num(b),
                num(c)
            ),
        ));
    }
    Ok(())
}

/// `|v|`.
pub(crate) fn norm(v: &Vec3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// `a × b`.
pub(crate) fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `x` rounded to 6 significant digits, shortest form (for messages).
pub(crate) fn num(x: f64) -> String {
    let r: f64 = format!("{x:.5e}").parse().unwrap_or(x);
    format!("{r}")
}

/// `{ xyz = […], rpy = […] }` of a transform (fixed-axis X-Y-Z angles, `R = Rz Ry Rx`), to 12
/// significant digits; `rpy` left out when it is zero.
pub(crate) fn xyz_rpy(t: &runtime::model::Transform) -> String {
    let m = &t.rotation;
    let rpy = [
        m[2][1].atan2(m[2][2]),
        (-m[2][0]).atan2(m[0][0].hypot(m[1][0])),
        m[1][0].atan2(m[0][0]),
    ];
    let num = toml_num;
    let list = |v: &[f64; 3]| format!("[{}, {}, {}]", num(v[0]), num(v[1]), num(v[2]));
    if rpy.iter().all(|a| a.abs() < 1e-15) {
        format!("{{ xyz = {} }}", list(&t.translation))
    } else {
        format!("{{ xyz = {}, rpy = {} }}", list(&t.translation), list(&rpy))
    }
}

/// A number for a spec's text, to 13 significant digits (a TOML float: `0.0`, `1e-6`), with
/// magnitudes below `1e-15` written as zero.
pub(crate) fn toml_num(v: f64) -> String {
    let v = if v.abs() < 1e-15 { 0.0 } else { v };
    let s = format!("{v:.12e}").parse::<f64>().unwrap_or(v);
    format!("{s:?}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Moments 0, 0 and 1 kg·m² (0 + 0 < 1 breaks the triangle inequality), turned about many
    /// axes: the eigenvalues' rounding noise is written as 0, never as a long decimal.
    #[test]
    fn an_inertia_s_noise_moments_are_written_as_zero() {
        let diag = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        for k in 0..200 {
            let t = f64::from(k);
            let axis = [t.sin(), (1.3 * t).cos(), 0.5 + (0.7 * t).sin()];
            let n = norm(&axis);
            let r = rotation(&[axis[0] / n, axis[1] / n, axis[2] / n], 0.1 + 0.05 * t);
            let (msg, hint) = check_inertia(&rotate_inertia(&r, &diag)).unwrap_err();
            assert!(msg.contains("triangle inequality"), "{msg}");
            assert!(
                hint.starts_with("principal moments 0, 0, 1 kg·m²"),
                "{k}: {hint}"
            );
        }
    }
}
