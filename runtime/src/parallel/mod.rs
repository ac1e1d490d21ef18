//! Simple-platform parallel manipulators: a moving platform carried by legs, each leg a serial
//! chain from the base to the platform (docs/method.md, "Parallel manipulators: actuation
//! matrix"; the lecture's eqs. 49–72).
//!
//! # The model
//! * The platform's independent coordinates are its pose ([`PlatformMotion::Pose`]:
//!   `x = [px, py, pz, qw, qx, qy, qz]`, `u = [ω; v]`) or its orientation about a fixed centre
//!   ([`PlatformMotion::Orientation`]: `x = [qw, qx, qy, qz]`, `u = ω`), or its position with
//!   the orientation fixed ([`PlatformMotion::Translation`]: `x = [px, py, pz]`, `u = v`; a Delta
//!   robot), or its planar pose ([`PlatformMotion::PlanarPose`]: `x = [px, py, φ]`,
//!   `u = [vx, vy, ω]`; a planar 3-RRR), or its heave and two tilts with parasitic motion
//!   ([`PlatformMotion::HeaveTilt`]: `x = [pz, α, β]`, `u = [ż, α̇, β̇]`, the twist `S(x) u`;
//!   a 3-PRS or 3-RPS head). Base-frame components;
//!   `v` is the velocity of the platform frame's origin.
//! * Leg `J` is a serial chain of one-DOF joints (U joints arrive expanded into two revolutes with
//!   a massless body between them) whose last body meets the platform in a spherical joint (pose)
//!   or a revolute joint (orientation). The leg's joints and bodies follow [`Model`]'s conventions:
//!   `joints[k]` moves `bodies[k]`, its origin is given in the frame of `bodies[k − 1]` (the base
//!   frame for `k = 0`), and at home every leg joint is at zero.
//! * Exactly one joint per leg is actuated; the actuated coordinates `q` are in leg order.
//!
//! [`Model`]: crate::model::Model

use alloc::format;
use alloc::string::String;
use alloc::vec::Vec;

use crate::model::{Body, Joint, JointKind, Transform, Vec3, mat_vec};

pub mod literal;
pub mod noc;

pub use noc::{NoConvergence, Plan};
// The scalar and its failure live on the shared floor; named here too for the parallel API.
pub use crate::scalar::{Real, Singular, Site};

/// How the platform moves and which coordinates describe it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlatformMotion {
    /// Six DOF. `x = [px, py, pz, qw, qx, qy, qz]`: the platform frame's origin (m) and unit
    /// quaternion in the base frame; `u = [ω; v]`: angular velocity (rad/s) and velocity of the
    /// platform frame's origin (m/s).
    Pose,
    /// Three DOF: rotation about the platform frame's origin, which stays at `centre` (base
    /// frame, m). `x = [qw, qx, qy, qz]`, `u = ω`.
    Orientation {
        /// The fixed centre of rotation (base frame, m).
        centre: Vec3,
    },
    /// Two DOF: a point `P` moving in the plane `z = height` of the base frame, where the legs
    /// meet (a planar five-bar). `x = [px, py]` (m), `u = [vx, vy]` (m/s). The platform is a
    /// point mass at `P` (its rotation is not a coordinate; rotational inertia is ignored).
    PlanarPoint {
        /// The plane's height `z` (base frame, m).
        height: f64,
    },
    /// Three DOF: the platform translates, its orientation fixed at `rotation` (its home
    /// rotation, platform → base), as a Delta robot's. `x = [px, py, pz]`: the platform frame's
    /// origin (m); `u = v` (m/s); the platform twist is `t = S u` with `S = [0; 1₃]`, `ω = 0`
    /// (docs/method.md, "nocdyn's formulation").
    Translation {
        /// The platform's fixed rotation (platform → base).
        rotation: crate::model::Mat3,
    },
    /// Three DOF: the platform moves in the plane `z = height` of the base frame and turns
    /// about the base `z` axis (a planar 3-RRR, 3-PRR, 3-RPR). `x = [px, py, φ]`: the platform
    /// frame's origin (m) and its rotation about `z` from its home rotation (rad, `φ = 0` at
    /// home; platform → base `Rz(φ)·rotation`); `u = [vx, vy, ω]` (m/s, rad/s), so that
    /// `x ⊕ δu` is a sum; the twist is `t = [ω; v] = S u` with `ω = (0, 0, u₂)`,
    /// `v = (u₀, u₁, 0)` (docs/method.md, "nocdyn's formulation"). Each leg ends in a revolute
    /// about `z` at a point of the platform (a [`LegEnd::Spherical`] point).
    PlanarPose {
        /// The plane's height `z` (base frame, m).
        height: f64,
        /// The platform's home rotation (platform → base).
        rotation: crate::model::Mat3,
    },
    /// Three DOF, one translation and two rotations with parasitic motion (1T2R: a 3-PRS or
    /// 3-RPS tilting head). The full pose is the origin `p = (px, py, pz)` and the rotation
    /// `R = Rz(γ)·Ry(β)·Rx(α)·rotation` (base-frame axes; `rotation` the home rotation);
    /// `x = [pz, α, β]` (heave in m, then the two tilts in rad, zero at home), `u = [ż, α̇, β̇]`,
    /// so that `x ⊕ δu` is a sum. The parasitic components `(px, py, γ)` follow from the legs'
    /// constraints: leg `i` keeps its S centre in a fixed plane (`nᵢ·(p + R sᵢ − bᵢ) = 0`),
    /// solved by `noc::PARASITIC_ITERATIONS` Newton steps from their home values `xy`, `0`
    /// (docs/method.md, "Parasitic motion"). The twist is `t = [ω; v] = S(x) u`.
    HeaveTilt {
        /// The platform's home rotation (platform → base).
        rotation: crate::model::Mat3,
        /// The platform origin's home `(px, py)` (base frame, m): the Newton steps' start.
        xy: [f64; 2],
    },
    /// Four DOF, the Schönflies motions (x, y, z and a turn about the vertical `z`): a 4-axis
    /// Delta (ABB IRB 360 FlexPicker, Codian D4). The platform (the *carrier*) translates, its
    /// rotation fixed at `rotation`, carried by three Delta legs; a tool turns on it about the
    /// base `z` axis, driven by a fourth motor on the base through a telescopic R–U–P–U shaft
    /// (a [`LegKind::Shaft`] leg whose last body is the tool). `x = [px, py, pz, θ]`: the carrier
    /// frame's origin (m) and the tool's angle about `z` (rad, `0` at home); `u = [vx, vy, vz,
    /// ω]`, so that `x ⊕ δu` is a sum. The carrier's twist is `[0; v]`, the tool's `[ω e_z; v]`
    /// (at its axis); the shaft's double Cardan is homokinetic, so the motor turns with the tool
    /// (docs/method.md, "Schönflies motion").
    Schoenflies {
        /// The carrier's fixed rotation (platform → base).
        rotation: crate::model::Mat3,
    },
}

impl PlatformMotion {
    /// Number of position coordinates `x`.
    pub fn nx(&self) -> usize {
        match self {
            PlatformMotion::Pose => 7,
            PlatformMotion::Orientation { .. } => 4,
            PlatformMotion::PlanarPoint { .. } => 2,
            PlatformMotion::Translation { .. }
            | PlatformMotion::PlanarPose { .. }
            | PlatformMotion::HeaveTilt { .. } => 3,
            PlatformMotion::Schoenflies { .. } => 4,
        }
    }
    /// Number of speeds `u` (the degrees of freedom, and the number of actuators).
    pub fn dof(&self) -> usize {
        match self {
            PlatformMotion::Pose => 6,
            PlatformMotion::Orientation { .. } => 3,
            PlatformMotion::PlanarPoint { .. } => 2,
            PlatformMotion::Translation { .. }
            | PlatformMotion::PlanarPose { .. }
            | PlatformMotion::HeaveTilt { .. } => 3,
            PlatformMotion::Schoenflies { .. } => 4,
        }
    }
    /// The unit group of each speed (`u`'s columns of the actuation matrix `A`): speeds of one
    /// physical unit (rad/s, m/s) share a group. The pivot test of `A`'s LU scales the columns
    /// of a group by the group's largest column norm, not each column by its own: a column
    /// that shrinks against the others of its unit is a singularity (the platform moves along
    /// that speed with the actuators still), which scaling it alone to unit norm would hide;
    /// and a group's scale is at least another group's converted by the platform's radius
    /// (`noc::ColumnUnits`), so that a whole group that vanishes is one too.
    pub fn unit_groups(&self) -> &'static [usize] {
        match self {
            PlatformMotion::Pose => &[0, 0, 0, 1, 1, 1],
            PlatformMotion::Orientation { .. } | PlatformMotion::Translation { .. } => &[0, 0, 0],
            PlatformMotion::PlanarPoint { .. } => &[0, 0],
            PlatformMotion::PlanarPose { .. } => &[0, 0, 1],
            PlatformMotion::HeaveTilt { .. } => &[0, 1, 1],
            PlatformMotion::Schoenflies { .. } => &[0, 0, 0, 1],
        }
    }
    /// Whether each unit group of [`Self::unit_groups`] holds rotation speeds (rad/s; the
    /// other groups hold speeds in m/s), indexed by group.
    pub fn rotational_groups(&self) -> &'static [bool] {
        match self {
            PlatformMotion::Pose => &[true, false],
            PlatformMotion::Orientation { .. } => &[true],
            PlatformMotion::Translation { .. } | PlatformMotion::PlanarPoint { .. } => &[false],
            PlatformMotion::PlanarPose { .. }
            | PlatformMotion::HeaveTilt { .. }
            | PlatformMotion::Schoenflies { .. } => &[false, true],
        }
    }
    /// Whether the platform is a Schönflies carrier with a turning tool (`Schoenflies`).
    pub fn schoenflies(&self) -> bool {
        matches!(self, PlatformMotion::Schoenflies { .. })
    }
    /// Whether the platform has parasitic motion (`HeaveTilt`): its pose follows from `x` by
    /// the legs' constraints, and `x ⊕ δu` is a sum.
    pub fn parasitic(&self) -> bool {
        matches!(self, PlatformMotion::HeaveTilt { .. })
    }
    /// Whether the platform moves in a plane and turns about its normal (`PlanarPose`).
    pub fn planar_pose(&self) -> bool {
        matches!(self, PlatformMotion::PlanarPose { .. })
    }
    /// Whether the platform only translates (`PlanarPoint`, `Translation`): `u` is the
    /// velocity of its origin, `ω = 0`, and `x ⊕ δu` is a sum.
    pub fn translates(&self) -> bool {
        matches!(
            self,
            PlatformMotion::PlanarPoint { .. } | PlatformMotion::Translation { .. }
        )
    }
}

/// How a leg's last body meets the platform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LegEnd {
    /// A spherical joint: the point `on_leg` (last leg body's frame, m) coincides with the point
    /// `on_platform` (platform frame, m). For a [`PlatformMotion::PlanarPoint`] platform this is
    /// the revolute joint at `P` (only the point matters: the platform is a point).
    Spherical {
        /// The joint centre in the last leg body's frame.
        on_leg: Vec3,
        /// The joint centre in the platform frame.
        on_platform: Vec3,
    },
    /// A revolute joint whose axis passes through the centre of an orientation mechanism: the
    /// unit direction `on_leg` (last leg body's frame) coincides with `on_platform` (platform
    /// frame).
    Revolute {
        /// The axis direction in the last leg body's frame.
        on_leg: Vec3,
        /// The axis direction in the platform frame.
        on_platform: Vec3,
    },
}

/// One leg: a serial chain of one-DOF joints from the base to the platform.
#[derive(Clone, Debug, PartialEq)]
pub struct Leg {
    /// Name (from the spec; the name of the joint that meets the platform).
    pub name: String,
    /// Joints from the base outwards; `joints[k]` moves `bodies[k]`. Their `parent` fields are
    /// `None` for `k = 0` and `Some(k − 1)` otherwise (indices into this leg).
    pub joints: Vec<Joint>,
    /// The leg's bodies (massless ones allowed).
    pub bodies: Vec<Body>,
    /// Index into `joints` of the actuated joint.
    pub actuated: usize,
    /// Name of the actuated joint (as in the spec).
    pub actuated_name: String,
    /// The actuated joint's coordinate at home (rad or m; the spec's `home`, 0 by default):
    /// `inverse_kinematics` returns, and `forward_kinematics` takes, `home` plus the joint's
    /// displacement from its home frame, so that the actuators' coordinates are absolute.
    pub actuated_home: f64,
    /// How the last body meets the platform.
    pub end: LegEnd,
}

/// A validated simple-platform parallel manipulator.
#[derive(Clone, Debug, PartialEq)]
pub struct ParallelModel {
    /// Mechanism name (a Rust identifier-friendly string).
    pub name: String,
    /// Gravitational acceleration in the base frame (m/s²).
    pub gravity: Vec3,
    /// The platform's coordinates.
    pub motion: PlatformMotion,
    /// The platform's inertial data in the platform frame.
    pub platform: Body,
    /// The platform frame's pose in the base frame at home (every leg joint at zero).
    pub home: Transform,
    /// The legs.
    pub legs: Vec<Leg>,
}

/// The leg types, recognised from the joint geometry: seven with closed-form inverse
/// kinematics, and any other three-joint leg to a spherical joint by Newton's method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LegKind {
    /// U (two revolutes with intersecting axes) at the base, then a prismatic joint along the
    /// line from the U centre to the spherical joint: UPS.
    Ups,
    /// A prismatic joint from the base, then U, then a fixed-length link to the S joint: PUS.
    Pus,
    /// A revolute joint from the base (crank), then U, then a fixed-length link to S: RUS.
    Rus,
    /// Two revolutes then the revolute to the platform, all axes through the centre of an
    /// orientation mechanism: spherical RRR.
    SphericalRr,
    /// Two revolutes with axes along the plane normal, to the point of a planar point platform:
    /// the leg of a planar five-bar, or of a planar 3-RRR ([`PlatformMotion::PlanarPose`]).
    PlanarRr,
    /// A prismatic joint in the plane, then a revolute about the plane normal, to a point of a
    /// planar platform: the P-R leg of a 3-PRR (the rod's end on the circle about the point, a
    /// line–circle intersection, branch from home).
    PlanarPr,
    /// A revolute about the plane normal, then a prismatic joint along the line from it to a
    /// point of a planar platform: the R-P leg of a 3-RPR (angle and length of that line).
    PlanarRp,
    /// The telescopic shaft of a Schönflies platform ([`PlatformMotion::Schoenflies`]): a
    /// revolute on the base whose axis is the base `z` (the fourth motor), a U (two
    /// perpendicular revolutes, the first perpendicular to the motor axis, meeting on it), a
    /// prismatic tube along the motor axis at home, a second U whose tube-side axis is parallel
    /// to the first U's tube-side axis and whose other axis is parallel to the first U's first
    /// axis (the yokes in phase), its centre on the motor axis at home; its last body is the
    /// tool, which meets the carrier in a revolute about `z` on the same line (a spherical
    /// [`LegEnd`] point: the shaft fixes the tool's angle). The double Cardan is homokinetic:
    /// the motor's angle is the tool's.
    Shaft,
    /// Any other chain of three one-DOF joints (revolute or prismatic, any axes) ending in a
    /// spherical joint at a 6-DOF platform: inverse kinematics by a fixed number of Newton
    /// steps from the home configuration (`noc::GENERIC_IK_ITERATIONS`), checked against
    /// `noc::GENERIC_IK_TOLERANCE` (the home branch).
    Generic,
}

impl LegKind {
    /// The usual name (`"UPS"`, …).
    pub fn word(self) -> &'static str {
        match self {
            LegKind::Ups => "UPS",
            LegKind::Pus => "PUS",
            LegKind::Rus => "RUS",
            LegKind::SphericalRr => "spherical RRR",
            LegKind::PlanarRr => "planar RR",
            LegKind::PlanarPr => "planar PR",
            LegKind::PlanarRp => "planar RP",
            LegKind::Shaft => "R-U-P-U shaft",
            LegKind::Generic => "generic (Newton)",
        }
    }
}

/// Length tolerance of the geometric checks (m), relative to the mechanism's size.
pub const GEOMETRY_TOLERANCE: f64 = 1e-9;

impl ParallelModel {
    /// Number of position coordinates.
    pub fn nx(&self) -> usize {
        self.motion.nx()
    }
    /// Degrees of freedom (= number of actuators = number of legs).
    pub fn dof(&self) -> usize {
        self.motion.dof()
    }

    /// The coordinates `x` of the home pose.
    pub fn home_x(&self) -> Vec<f64> {
        let q = crate::model::matrix_quaternion(&self.home.rotation);
        match self.motion {
            PlatformMotion::Pose => {
                let t = self.home.translation;
                alloc::vec![t[0], t[1], t[2], q[0], q[1], q[2], q[3]]
            }
            PlatformMotion::Orientation { .. } => q.to_vec(),
            PlatformMotion::PlanarPoint { .. } => {
                alloc::vec![self.home.translation[0], self.home.translation[1]]
            }
            PlatformMotion::Translation { .. } => self.home.translation.to_vec(),
            PlatformMotion::PlanarPose { .. } => {
                alloc::vec![self.home.translation[0], self.home.translation[1], 0.0]
            }
            PlatformMotion::HeaveTilt { .. } => alloc::vec![self.home.translation[2], 0.0, 0.0],
            PlatformMotion::Schoenflies { .. } => {
                let t = self.home.translation;
                alloc::vec![t[0], t[1], t[2], 0.0]
            }
        }
    }

    /// The typical length of the mechanism (m): the largest distance of a joint origin or the
    /// home platform origin from the base origin, at least 1 mm. Tolerances scale with it.
    pub fn size(&self) -> f64 {
        let mut s: f64 = 1e-3;
        let n = |v: &Vec3| libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        s = s.max(n(&self.home.translation));
        for leg in &self.legs {
            for pose in leg_home_poses(leg) {
                s = s.max(n(&pose.translation));
            }
        }
        s
    }

    /// The platform's radius (m): the largest distance of a leg's joint centre from the
    /// platform frame's origin, at least 1 mm. A rotation speed's column of the actuation
    /// matrix is a translation speed's times about this length (the legs' moment arms), which
    /// its pivot test uses (`noc::ColumnUnits`).
    pub fn platform_radius(&self) -> f64 {
        let mut r: f64 = 1e-3;
        for leg in &self.legs {
            if let LegEnd::Spherical { on_platform: p, .. } = &leg.end {
                r = r.max(libm::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
            }
        }
        r
    }

    /// Check the structure the evaluators rely on: one leg per DOF, one actuator per leg, leg
    /// ends that match the platform motion, a recognised leg type, and loops that close at home.
    /// Returns each leg's type. The messages name the leg.
    pub fn validate(&self) -> Result<Vec<LegKind>, String> {
        if self.legs.len() != self.dof() {
            return Err(format!(
                "the platform has {} degrees of freedom but there are {} legs (one actuated leg per degree of freedom is required)",
                self.dof(),
                self.legs.len()
            ));
        }
        let tol = GEOMETRY_TOLERANCE * self.size();
        let mut kinds = Vec::with_capacity(self.legs.len());
        for leg in &self.legs {
            let kind = classify(self, leg, tol)?;
            check_closure(self, leg, tol)?;
            kinds.push(kind);
        }
        Ok(kinds)
    }
}

impl ParallelModel {
    /// The first leg whose loop does not close at home within [`GEOMETRY_TOLERANCE`] × the
    /// size, with the end that closes it: the platform-side point (or axis) moved to where
    /// the leg ends. `None` when every leg closes.
    pub fn open_leg(&self) -> Option<(usize, LegEnd)> {
        let tol = GEOMETRY_TOLERANCE * self.size();
        self.legs.iter().enumerate().find_map(|(k, leg)| {
            let last = leg_home_poses(leg)
                .last()
                .copied()
                .unwrap_or(Transform::IDENTITY);
            let rt = |v: &Vec3| -> Vec3 {
                let r = &self.home.rotation;
                [
                    r[0][0] * v[0] + r[1][0] * v[1] + r[2][0] * v[2],
                    r[0][1] * v[0] + r[1][1] * v[1] + r[2][1] * v[2],
                    r[0][2] * v[0] + r[1][2] * v[1] + r[2][2] * v[2],
                ]
            };
            match leg.end {
                LegEnd::Spherical {
                    on_leg,
                    on_platform,
                } => {
                    let a = last.apply(&on_leg);
                    let b = self.home.apply(&on_platform);
                    (norm(&sub(&a, &b)) > tol).then(|| {
                        let at = rt(&sub(&a, &self.home.translation));
                        (
                            k,
                            LegEnd::Spherical {
                                on_leg,
                                on_platform: at,
                            },
                        )
                    })
                }
                LegEnd::Revolute {
                    on_leg,
                    on_platform,
                } => {
                    let a = mat_vec(&last.rotation, &on_leg);
                    let b = mat_vec(&self.home.rotation, &on_platform);
                    (norm(&sub(&a, &b)) > 1e-9).then(|| {
                        (
                            k,
                            LegEnd::Revolute {
                                on_leg,
                                on_platform: rt(&a),
                            },
                        )
                    })
                }
            }
        })
    }
}

/// Poses (base frame) of the leg's bodies at home, joints at zero.
pub fn leg_home_poses(leg: &Leg) -> Vec<Transform> {
    let mut out: Vec<Transform> = Vec::with_capacity(leg.joints.len());
    let mut x = Transform::IDENTITY;
    for j in &leg.joints {
        x = x.compose(&j.origin);
        out.push(x);
    }
    out
}

fn sub(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: &Vec3) -> f64 {
    libm::sqrt(dot(a, a))
}

/// Distance between the lines `p + s·e` and `q + t·f` (unit directions); `None` when parallel.
fn line_distance(p: &Vec3, e: &Vec3, q: &Vec3, f: &Vec3) -> Option<f64> {
    let n = cross(e, f);
    let nn = norm(&n);
    if nn < 1e-9 {
        return None;
    }
    Some(dot(&sub(q, p), &n).abs() / nn)
}

/// Home axis (unit, base frame) and point of each leg joint.
fn home_axes(leg: &Leg) -> Vec<(Vec3, Vec3)> {
    leg_home_poses(leg)
        .iter()
        .zip(&leg.joints)
        .map(|(x, j)| (mat_vec(&x.rotation, &j.axis), x.translation))
        .collect()
}

fn classify(m: &ParallelModel, leg: &Leg, tol: f64) -> Result<LegKind, String> {
    use JointKind::{Prismatic as P, Revolute as R};
    let kinds: Vec<JointKind> = leg.joints.iter().map(|j| j.kind).collect();
    let ax = home_axes(leg);
    let name = &leg.name;
    let meet = |a: usize, b: usize| -> bool {
        matches!(line_distance(&ax[a].1, &ax[a].0, &ax[b].1, &ax[b].0), Some(d) if d <= tol)
    };
    if leg.actuated >= leg.joints.len() {
        return Err(format!("leg {name}: no actuated joint"));
    }
    let kind = match (m.motion, leg.end, kinds.as_slice()) {
        // A UPS leg; on a translational platform also a UPU leg (Tsai's 3-UPU), whose U at the
        // platform arrives as the point at its centre: with ω = 0 its cross is massless and its
        // angles follow from the rod's (docs/spec.md, "Universal joints into a translational
        // platform").
        (
            PlatformMotion::Pose | PlatformMotion::Translation { .. },
            LegEnd::Spherical { .. },
            [R, R, P],
        ) => {
            // The prismatic axis must run through the U centre towards the S centre.
            let tip = leg_tip_home(leg);
            let d = sub(&tip, &ax[1].1);
            let on_line = norm(&cross(&d, &ax[2].0)) <= tol;
            if meet(0, 1) && on_line {
                LegKind::Ups
            } else {
                LegKind::Generic
            }
        }
        (PlatformMotion::Pose, LegEnd::Spherical { .. }, [P, R, R]) if meet(1, 2) => LegKind::Pus,
        (PlatformMotion::Pose, LegEnd::Spherical { .. }, [R, R, R]) if meet(1, 2) => LegKind::Rus,
        (PlatformMotion::Pose, LegEnd::Spherical { .. }, [_, _, _]) => LegKind::Generic,
        // A translational platform (a Delta): the crank, the U at the elbow and the rod of the
        // parallelogram's equivalent (docs/spec.md, "Parallelograms") to the S at the platform.
        (PlatformMotion::Translation { .. }, LegEnd::Spherical { .. }, [R, R, R]) if meet(1, 2) => {
            LegKind::Rus
        }
        (PlatformMotion::Translation { .. }, LegEnd::Spherical { .. }, [_, _, _]) => {
            LegKind::Generic
        }
        // A Schönflies carrier: three Delta legs (as a translational platform's) and the shaft.
        (PlatformMotion::Schoenflies { .. }, LegEnd::Spherical { .. }, [R, R, R]) if meet(1, 2) => {
            LegKind::Rus
        }
        (PlatformMotion::Schoenflies { .. }, LegEnd::Spherical { .. }, [R, R, R, P, R, R]) => {
            shaft_leg(leg, &ax, tol)?
        }
        (PlatformMotion::Schoenflies { .. }, _, _) => {
            return Err(format!(
                "leg {name}: a Schönflies platform's legs are Delta legs (a revolute crank, then the parallelogram's U and S) and one R-U-P-U shaft from a motor about z to the tool"
            ));
        }
        (PlatformMotion::Orientation { centre }, LegEnd::Revolute { .. }, [R, R]) => {
            for (k, (e, p)) in ax.iter().enumerate() {
                let off = cross(&sub(&centre, p), e);
                if norm(&off) > tol {
                    return Err(format!(
                        "leg {name}: the axis of its joint {} does not pass through the centre of rotation",
                        leg.joints[k].name
                    ));
                }
            }
            LegKind::SphericalRr
        }
        (PlatformMotion::PlanarPoint { .. }, LegEnd::Spherical { .. }, [R, R]) => {
            for (k, (e, _)) in ax.iter().enumerate() {
                if (e[0].abs() > 1e-12) || (e[1].abs() > 1e-12) {
                    return Err(format!(
                        "leg {name}: the axis of its joint {} is not along the plane normal z",
                        leg.joints[k].name
                    ));
                }
            }
            LegKind::PlanarRr
        }
        (PlatformMotion::PlanarPose { .. }, LegEnd::Spherical { .. }, [_, _])
            if planar_leg(&kinds, &ax).is_some() =>
        {
            let kind = planar_leg(&kinds, &ax).unwrap_or(LegKind::PlanarRr);
            if kind == LegKind::PlanarRp {
                // The prismatic line runs through the revolute axis to the platform point.
                let h = sub(&leg_tip_home(leg), &ax[0].1);
                let h = [h[0], h[1], 0.0];
                if norm(&cross(&h, &ax[1].0)) > tol {
                    return Err(format!(
                        "leg {name}: its prismatic joint {} does not slide along the line from its revolute joint {} to the platform point (an R-P leg of a planar platform is a revolute about z, then a prismatic along that line)",
                        leg.joints[1].name, leg.joints[0].name
                    ));
                }
            }
            kind
        }
        (PlatformMotion::HeaveTilt { .. }, LegEnd::Spherical { .. }, [_, _]) => {
            heave_tilt_leg(leg, &kinds, &ax, tol)?
        }
        (PlatformMotion::HeaveTilt { .. }, _, _) => {
            return Err(format!(
                "leg {name}: a 1T2R platform in (pz, α, β) needs legs P-R or R-P whose S centre moves in a plane (P-R-S: a slider, then a revolute whose axis is perpendicular to the rail; R-P-S: a revolute, then a prismatic along the line from its axis to the S centre, perpendicular to it) that end in a spherical joint"
            ));
        }
        (PlatformMotion::PlanarPose { .. }, _, _) => {
            return Err(format!(
                "leg {name}: a planar platform in (x, y, φ) needs legs of two joints in the plane (R-R, P-R or R-P: revolute axes along z, prismatic directions in the plane) that end in a revolute about z at a point of the platform"
            ));
        }
        (PlatformMotion::PlanarPoint { .. }, _, _) => {
            return Err(format!(
                "leg {name}: a planar point platform needs legs of two revolutes about z (R-R) that end in the point"
            ));
        }
        (PlatformMotion::Pose, LegEnd::Revolute { .. }, _) => {
            return Err(format!(
                "leg {name}: a 6-DOF platform needs legs that end in a spherical joint"
            ));
        }
        (PlatformMotion::Translation { .. }, LegEnd::Revolute { .. }, _) => {
            return Err(format!(
                "leg {name}: a translational platform needs legs that end in a spherical joint"
            ));
        }
        (PlatformMotion::Orientation { .. }, LegEnd::Spherical { .. }, _) => {
            return Err(format!(
                "leg {name}: an orientation platform needs legs that end in a revolute joint"
            ));
        }
        _ => {
            let word: Vec<&str> = kinds
                .iter()
                .map(|k| if *k == R { "R" } else { "P" })
                .collect();
            return Err(format!(
                "leg {name}: joints {} are not a supported leg type (supported: any three revolute or prismatic joints to a spherical joint for a 6-DOF platform, in closed form for UPS, PUS and RUS and by Newton otherwise; RRR with every axis through the centre for an orientation platform; RR about z for a planar point)",
                word.join("-")
            ));
        }
    };
    Ok(kind)
}

/// The planar leg type of a two-joint leg of a planar platform: revolute axes along `z`,
/// prismatic directions in the plane (home axes `ax`, base frame).
fn planar_leg(kinds: &[JointKind], ax: &[(Vec3, Vec3)]) -> Option<LegKind> {
    use JointKind::{Prismatic as P, Revolute as R};
    let along_z = |e: &Vec3| e[0].abs() <= 1e-12 && e[1].abs() <= 1e-12;
    let in_plane = |e: &Vec3| e[2].abs() <= 1e-12;
    match (kinds, ax) {
        ([R, R], [a, b]) if along_z(&a.0) && along_z(&b.0) => Some(LegKind::PlanarRr),
        ([P, R], [a, b]) if in_plane(&a.0) && along_z(&b.0) => Some(LegKind::PlanarPr),
        ([R, P], [a, b]) if along_z(&a.0) && in_plane(&b.0) => Some(LegKind::PlanarRp),
        _ => None,
    }
}

/// The leg type of a two-joint leg of a 1T2R platform ([`PlatformMotion::HeaveTilt`]): P-R
/// with the revolute axis perpendicular to the rail ([`LegKind::PlanarPr`] in the plane
/// normal to that axis), or R-P with the prismatic direction perpendicular to the revolute
/// axis and along the line from it to the S centre ([`LegKind::PlanarRp`]). Either keeps the
/// S centre in the plane through the revolute's point normal to its axis.
fn heave_tilt_leg(
    leg: &Leg,
    kinds: &[JointKind],
    ax: &[(Vec3, Vec3)],
    tol: f64,
) -> Result<LegKind, String> {
    use JointKind::{Prismatic as P, Revolute as R};
    let name = &leg.name;
    let tip = leg_tip_home(leg);
    let (kind, n, o) = match kinds {
        [P, R] => (LegKind::PlanarPr, ax[1].0, ax[1].1),
        [R, P] => (LegKind::PlanarRp, ax[0].0, ax[0].1),
        _ => {
            return Err(format!(
                "leg {name}: a 1T2R platform's leg is P-R-S or R-P-S (two joints, then the spherical joint)"
            ));
        }
    };
    if dot(&ax[0].0, &ax[1].0).abs() > 1e-9 {
        return Err(format!(
            "leg {name}: its joints {} and {} are not perpendicular (a P-R-S leg's revolute axis is perpendicular to its rail; an R-P-S leg's prismatic direction is perpendicular to its revolute axis), so the S centre does not stay in one plane",
            leg.joints[0].name, leg.joints[1].name
        ));
    }
    // The S centre lies in the plane through the revolute's point normal to its axis.
    if dot(&n, &sub(&tip, &o)).abs() > tol {
        return Err(format!(
            "leg {name}: its spherical joint's centre is not in the plane of its revolute joint {} (the plane through the joint's point perpendicular to its axis)",
            leg.joints[if kind == LegKind::PlanarPr { 1 } else { 0 }].name
        ));
    }
    if kind == LegKind::PlanarRp {
        let h = sub(&tip, &ax[0].1);
        let h = sub(
            &h,
            &[n[0] * dot(&n, &h), n[1] * dot(&n, &h), n[2] * dot(&n, &h)],
        );
        if norm(&cross(&h, &ax[1].0)) > tol {
            return Err(format!(
                "leg {name}: its prismatic joint {} does not slide along the line from its revolute joint {} to the spherical joint",
                leg.joints[1].name, leg.joints[0].name
            ));
        }
    }
    Ok(kind)
}

/// The telescopic R-U-P-U shaft of a Schönflies platform ([`LegKind::Shaft`]): the motor axis
/// along the base `z`, the U axes perpendicular to each other and to the motor axis, meeting on
/// it, the tube along it, the second U in phase with the first (its tube-side axis parallel to
/// the first U's tube-side axis, its other axis to the first U's first axis) with its centre on
/// the motor axis, and the tool's point on the same line: the conditions under which the double
/// Cardan is homokinetic and the tool turns with the motor.
fn shaft_leg(leg: &Leg, ax: &[(Vec3, Vec3)], tol: f64) -> Result<LegKind, String> {
    let name = &leg.name;
    let jn = |k: usize| leg.joints[k].name.as_str();
    let par = |a: &Vec3, b: &Vec3| norm(&cross(a, b)) <= 1e-9;
    let perp = |a: &Vec3, b: &Vec3| dot(a, b).abs() <= 1e-9;
    let on_line = |p: &Vec3| norm(&cross(&sub(p, &ax[0].1), &ax[0].0)) <= tol;
    let e0 = ax[0].0;
    if e0[0].abs() > 1e-9 || e0[1].abs() > 1e-9 {
        return Err(format!(
            "leg {name}: its motor joint {} does not turn about the base z axis (the tool's angle θ is about z)",
            jn(0)
        ));
    }
    if !(perp(&ax[1].0, &e0) && perp(&ax[2].0, &e0) && perp(&ax[1].0, &ax[2].0)) {
        return Err(format!(
            "leg {name}: its universal joint's axes {} and {} are not perpendicular to each other and to the motor axis {} at home (the shaft hangs along the motor axis at home)",
            jn(1),
            jn(2),
            jn(0)
        ));
    }
    if !(on_line(&ax[1].1) && on_line(&ax[2].1) && norm(&sub(&ax[1].1, &ax[2].1)) <= tol) {
        return Err(format!(
            "leg {name}: its universal joint {}/{} is not centred on the motor axis {}",
            jn(1),
            jn(2),
            jn(0)
        ));
    }
    if !par(&ax[3].0, &e0) {
        return Err(format!(
            "leg {name}: its telescopic joint {} does not slide along the motor axis {} at home",
            jn(3),
            jn(0)
        ));
    }
    if !(par(&ax[4].0, &ax[2].0) && par(&ax[5].0, &ax[1].0)) {
        return Err(format!(
            "leg {name}: its universal joints are not in phase (the tool-side joint's axes {} and {} must be parallel to {} and {} at home), so the double Cardan is not homokinetic and the tool would not turn with the motor",
            jn(4),
            jn(5),
            jn(2),
            jn(1)
        ));
    }
    let tip = leg_tip_home(leg);
    if !(on_line(&ax[4].1) && norm(&sub(&ax[4].1, &ax[5].1)) <= tol && on_line(&tip)) {
        return Err(format!(
            "leg {name}: its second universal joint {}/{} and the tool's joint are not centred on the motor axis {} at home",
            jn(4),
            jn(5),
            jn(0)
        ));
    }
    if norm(&sub(&ax[4].1, &ax[1].1)) <= tol {
        return Err(format!(
            "leg {name}: its universal joints {} and {} coincide (the tube has no length)",
            jn(1),
            jn(4)
        ));
    }
    Ok(LegKind::Shaft)
}

/// The leg's end point at home in the base frame (spherical end), or the last body's origin.
fn leg_tip_home(leg: &Leg) -> Vec3 {
    let poses = leg_home_poses(leg);
    let last = poses.last().copied().unwrap_or(Transform::IDENTITY);
    match leg.end {
        LegEnd::Spherical { on_leg, .. } => last.apply(&on_leg),
        LegEnd::Revolute { .. } => last.translation,
    }
}

fn check_closure(m: &ParallelModel, leg: &Leg, tol: f64) -> Result<(), String> {
    let poses = leg_home_poses(leg);
    let last = poses.last().copied().unwrap_or(Transform::IDENTITY);
    match leg.end {
        LegEnd::Spherical {
            on_leg,
            on_platform,
        } => {
            let a = last.apply(&on_leg);
            let b = m.home.apply(&on_platform);
            let d = norm(&sub(&a, &b));
            if d > tol {
                return Err(format!(
                    "leg {}: the loop does not close at home: the spherical joint's centre is {:?} m on the leg but {:?} m on the platform ({:.3e} m apart)",
                    leg.name, a, b, d
                ));
            }
        }
        LegEnd::Revolute {
            on_leg,
            on_platform,
        } => {
            let a = mat_vec(&last.rotation, &on_leg);
            let b = mat_vec(&m.home.rotation, &on_platform);
            let d = norm(&sub(&a, &b));
            if d > 1e-9 {
                return Err(format!(
                    "leg {}: the loop does not close at home: the last revolute axis is {:?} on the leg but {:?} on the platform",
                    leg.name, a, b
                ));
            }
        }
    }
    Ok(())
}
