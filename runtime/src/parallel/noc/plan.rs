//! The constant data of a parallel manipulator, prepared once: [`Plan`] and its legs'
//! [`LegPlan`]s, resolved in each leg's frame `L` by [`Plan::new`] (the joints' home axes and
//! points, the U centre, the fixed length and the branches of the subproblems), with the
//! constant-geometry helpers it uses.

use alloc::vec;
use alloc::vec::Vec;

use super::api::inverse_dynamics;
use super::delta::{DeltaPlan, delta_plan};
use super::lu::ColumnUnits;
use super::shaft::{ShaftPlan, shaft_plan};
use super::subproblems::rus_crank;
use super::ups::{UpsPlan, ups_plan};
use crate::model::{JointKind, Mat3, Transform, Vec3, mat_vec};
use crate::parallel::{LegEnd, LegKind, ParallelModel, PlatformMotion};

#[cfg(doc)]
use super::assembly::forward_kinematics;

/// The constant data of one leg, resolved in the leg frame `L`.
#[derive(Clone, Debug)]
pub struct LegPlan {
    /// Leg type.
    pub kind: LegKind,
    /// The leg frame `L` in the base frame (the home frame of the first joint).
    pub frame: Transform,
    /// Joint kinds.
    pub joints: Vec<JointKind>,
    /// Home joint axes (unit, `L`).
    pub axes: Vec<Vec3>,
    /// Home joint points (on the axes, `L`).
    pub points: Vec<Vec3>,
    /// Home body poses in `L`.
    pub homes: Vec<Transform>,
    /// Body inertial data: mass, mass centre (body frame), inertia (body frame).
    pub bodies: Vec<(f64, Vec3, Mat3)>,
    /// Index of the actuated joint.
    pub actuated: usize,
    /// The actuated joint's coordinate at home ([`crate::parallel::Leg::actuated_home`]).
    pub actuated_home: f64,
    /// Friction and rotor inertia of each leg joint (actuated or passive).
    pub drives: Vec<crate::model::Drive>,
    /// Spherical end: the S centre at home (`L`); revolute end: the end axis at home (`L`).
    pub end_home: Vec3,
    /// The end point (S centre) or end axis in the platform frame.
    pub end_platform: Vec3,
    /// The U centre at home (`L`) (the orientation centre for a spherical leg).
    pub u_centre: Vec3,
    /// Fixed length: UPS the home distance U centre → S centre; PUS, RUS the rod length.
    pub length: f64,
    /// Branch of the two-intersecting-axes subproblem (±1), from the home configuration.
    pub sigma_u: f64,
    /// Branch of the first joint's subproblem (PUS, RUS) or the prismatic direction (UPS).
    pub sigma_first: f64,
    /// The closed form of a UPS leg (see [`UpsPlan`]); `None` for other legs, or a UPS leg
    /// whose geometry it does not cover (those take the generic route).
    pub ups: Option<UpsPlan>,
    /// The closed form of a Delta leg (see [`DeltaPlan`]): a RUS leg of a translational
    /// platform whose rod has no spin inertia; `None` otherwise.
    pub delta: Option<DeltaPlan>,
    /// The shaft of a Schönflies platform (see [`ShaftPlan`]): `Some` for a
    /// [`LegKind::Shaft`] leg, `None` otherwise.
    pub shaft: Option<ShaftPlan>,
    /// The squared norms of the leg Jacobian's columns at home: the floor of each column's
    /// norm in its determinant test, so that a column that vanishes (the end point reaching
    /// a revolute axis: a folded R-R leg's end on its base joint) is a small ratio, not a
    /// column scaled back to unit norm by its own rounding noise. Zero for a unit-axis column.
    pub column_home: [f64; 3],
}

/// The constant data of a whole mechanism: what the evaluators need, prepared once.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Platform motion.
    pub motion: PlatformMotion,
    /// Gravity (base frame).
    pub gravity: Vec3,
    /// Platform mass, mass centre, inertia (platform frame).
    pub platform: (f64, Vec3, Mat3),
    /// Legs.
    pub legs: Vec<LegPlan>,
    /// The platform's radius (m, `ParallelModel::platform_radius`): the length that converts
    /// a rotation speed's column of `A` to a translation speed's in its pivot test
    /// ([`ColumnUnits`]).
    pub radius: f64,
}

pub(super) fn sub3(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(super) fn dot3(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(super) fn cross3(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The point of line `(p, e)` closest to line `(q, f)` (the intersection when they meet).
fn meet(p: &Vec3, e: &Vec3, q: &Vec3, f: &Vec3) -> Vec3 {
    // p + s e = q + t f (least squares): [e·e −e·f; e·f −f·f][s t]ᵀ = [(q−p)·e; (q−p)·f]
    let w = dot3(e, f);
    let d = sub3(q, p);
    let (de, df) = (dot3(&d, e), dot3(&d, f));
    let den = 1.0 - w * w;
    let s = if den.abs() < 1e-300 {
        0.0
    } else {
        (de - w * df) / den
    };
    [p[0] + s * e[0], p[1] + s * e[1], p[2] + s * e[2]]
}

fn sign(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

impl Plan {
    /// Prepare `model` (validating it first).
    pub fn new(model: &ParallelModel) -> Result<Plan, alloc::string::String> {
        let kinds = model.validate()?;
        if model.motion.schoenflies() {
            let shafts = kinds.iter().filter(|k| **k == LegKind::Shaft).count();
            if shafts != 1 {
                return Err(alloc::format!(
                    "a Schönflies platform needs three Delta legs and one R-U-P-U shaft to the tool; there are {shafts} shafts"
                ));
            }
        }
        let mut legs = Vec::with_capacity(model.legs.len());
        for (leg, kind) in model.legs.iter().zip(kinds) {
            let first = leg.joints[0].origin;
            // Home poses relative to L (the first joint's frame), composed from the joint
            // origins directly so that exact placements stay exact.
            let mut homes: Vec<Transform> = Vec::with_capacity(leg.joints.len());
            let mut h = Transform::IDENTITY;
            for (j, joint) in leg.joints.iter().enumerate() {
                if j > 0 {
                    h = h.compose(&joint.origin);
                }
                homes.push(h);
            }
            let axes: Vec<Vec3> = homes
                .iter()
                .zip(&leg.joints)
                .map(|(h, j)| mat_vec(&h.rotation, &j.axis))
                .collect();
            let points: Vec<Vec3> = homes.iter().map(|h| h.translation).collect();
            let last = *homes.last().unwrap_or(&Transform::IDENTITY);
            let (end_home, end_platform) = match leg.end {
                LegEnd::Spherical {
                    on_leg,
                    on_platform,
                } => (last.apply(&on_leg), on_platform),
                LegEnd::Revolute {
                    on_leg,
                    on_platform,
                } => (mat_vec(&last.rotation, &on_leg), on_platform),
            };
            let u_centre = match kind {
                LegKind::Ups | LegKind::SphericalRr => {
                    meet(&points[0], &axes[0], &points[1], &axes[1])
                }
                LegKind::Pus | LegKind::Rus => meet(&points[1], &axes[1], &points[2], &axes[2]),
                // The shaft's first U centre.
                LegKind::Shaft => points[1],
                // The elbow of a planar RR leg.
                LegKind::PlanarRr | LegKind::PlanarPr => points[1],
                // The revolute's point (the line to the platform point starts on its axis).
                LegKind::PlanarRp => points[0],
                // Not used by the Newton route.
                LegKind::Generic => points[0],
            };
            let (ui, uj) = match kind {
                LegKind::Ups
                | LegKind::SphericalRr
                | LegKind::PlanarRr
                | LegKind::PlanarPr
                | LegKind::PlanarRp
                | LegKind::Generic => (0, 1),
                LegKind::Pus | LegKind::Rus | LegKind::Shaft => (1, 2),
            };
            let (e1, e2) = (axes[ui], axes[uj]);
            let k = cross3(&e1, &e2);
            let mut plan = LegPlan {
                kind,
                frame: first,
                joints: leg.joints.iter().map(|j| j.kind).collect(),
                axes: axes.clone(),
                points,
                homes,
                bodies: leg
                    .bodies
                    .iter()
                    .map(|b| (b.mass, b.com, b.inertia))
                    .collect(),
                actuated: leg.actuated,
                actuated_home: leg.actuated_home,
                drives: leg.joints.iter().map(|j| j.drive).collect(),
                end_home,
                end_platform,
                u_centre,
                length: 0.0,
                sigma_u: 1.0,
                sigma_first: 1.0,
                ups: None,
                delta: None,
                shaft: None,
                column_home: [0.0; 3],
            };
            match kind {
                LegKind::Ups => {
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    plan.sigma_first = sign(dot3(&d, &axes[2]));
                    plan.sigma_u = sign(dot3(&d, &k));
                    plan.ups = ups_plan(&plan);
                }
                LegKind::Pus => {
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    // s = e·d − σ √(…) = 0 at home.
                    plan.sigma_first = sign(dot3(&axes[0], &d));
                    plan.sigma_u = sign(dot3(&d, &k));
                }
                LegKind::Rus | LegKind::PlanarRr => {
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    plan.sigma_u = sign(dot3(&d, &k));
                    // Pick the crank branch that reproduces θ = 0 at home.
                    let mut best = (f64::INFINITY, 1.0);
                    for s in [1.0, -1.0] {
                        plan.sigma_first = s;
                        if let Ok((sn, cs)) = rus_crank::<f64>(&plan, end_home, 0) {
                            let err = sn.abs() + (cs - 1.0).abs();
                            if err < best.0 {
                                best = (err, s);
                            }
                        }
                    }
                    plan.sigma_first = best.1;
                    if kind == LegKind::Rus
                        && matches!(
                            model.motion,
                            PlatformMotion::Translation { .. } | PlatformMotion::Schoenflies { .. }
                        )
                    {
                        plan.delta = delta_plan(&plan);
                    }
                }
                LegKind::SphericalRr => {
                    plan.sigma_u = sign(dot3(&end_home, &k));
                }
                LegKind::PlanarPr => {
                    // The rod length; s = e·d − σ √(…) = 0 at home.
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    plan.sigma_first = sign(dot3(&axes[0], &d));
                }
                LegKind::PlanarRp => {
                    // The home length of the line in the plane, and the prismatic direction
                    // along it (+1) or against it (−1).
                    let d = sub3(&end_home, &u_centre);
                    let dz = dot3(&axes[0], &d);
                    let h = [
                        d[0] - dz * axes[0][0],
                        d[1] - dz * axes[0][1],
                        d[2] - dz * axes[0][2],
                    ];
                    plan.length = libm::sqrt(dot3(&h, &h));
                    plan.sigma_first = sign(dot3(&h, &axes[1]));
                }
                LegKind::Shaft => {
                    let sp = shaft_plan(&plan);
                    plan.length = sp.length;
                    plan.sigma_u = sign(dot3(&sp.dir, &k));
                    plan.shaft = Some(sp);
                }
                LegKind::Generic => {
                    // The leg's size: the reach from its first joint to the S centre at home.
                    let d = sub3(&end_home, &plan.points[0]);
                    plan.length = libm::sqrt(dot3(&d, &d));
                }
            }
            // (Also for a leg with a closed form: the plans without one, the regressor's and
            // the friction's, test its Jacobian.)
            plan.column_home = super::legs::home_column_norms(&plan);
            legs.push(plan);
        }
        let plan = Plan {
            motion: model.motion,
            gravity: model.gravity,
            platform: (
                model.platform.mass,
                model.platform.com,
                model.platform.inertia,
            ),
            legs,
            radius: model.platform_radius(),
        };
        // The constraint Jacobian must have full rank at home: every leg Jacobian and the
        // actuation matrix regular there.
        let home = model.home_x();
        let n = plan.dof();
        inverse_dynamics(&plan, &home, &vec![0.0; n], &vec![0.0; n]).map_err(|e| {
            alloc::format!(
                "the mechanism is singular at its home pose ({e}); the constraint Jacobian must have full rank there"
            )
        })?;
        Ok(plan)
    }

    /// The units of `A`'s columns for its pivot test.
    pub fn column_units(&self) -> ColumnUnits<'static> {
        ColumnUnits {
            groups: self.motion.unit_groups(),
            rotational: self.motion.rotational_groups(),
            length: self.radius,
        }
    }

    /// This plan without the drives' friction (viscous and Coulomb; the rotor inertias
    /// kept): its generalized force at `u̇ = 0` without gravity is the velocity-dependent part
    /// `C u` alone (`coriolis`). A leg with drives takes the generic route already, so the
    /// closed forms stay as they are.
    pub fn without_friction(&self) -> Plan {
        let mut p = self.clone();
        for leg in &mut p.legs {
            for d in &mut leg.drives {
                *d = d.without_friction();
            }
        }
        p
    }

    /// The drives' friction alone: massless legs and platform, no rotor inertia, no gravity,
    /// and every leg on the generic route (the closed forms hold masses of their own). Its
    /// generalized force at `(u, u̇ = 0)` is the friction's part (`friction`).
    pub fn friction_only(&self) -> Plan {
        let mut p = self.clone();
        let none = [[0.0; 3]; 3];
        p.gravity = [0.0; 3];
        p.platform = (0.0, p.platform.1, none);
        for leg in &mut p.legs {
            leg.ups = None;
            leg.delta = None;
            // (The shaft keeps its closed form: it has no other route; its bodies are
            // massless here, its drives the friction's.)
            for b in &mut leg.bodies {
                *b = (0.0, b.1, none);
            }
            for d in &mut leg.drives {
                *d = d.friction_only();
            }
        }
        p
    }

    /// Whether a leg joint has friction (viscous or Coulomb).
    pub fn has_friction(&self) -> bool {
        self.legs
            .iter()
            .any(|l| l.drives.iter().any(|d| d.has_friction()))
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.motion.dof()
    }
    /// The scale of [`forward_kinematics`]' tolerance: the longest leg (m, at home) among the
    /// legs with a prismatic actuator, at least 1 (a leg's position is rounded in proportion to
    /// its length); `1` when every actuator is revolute (radians).
    pub fn fk_scale(&self) -> f64 {
        self.legs
            .iter()
            .filter(|l| l.joints[l.actuated] == JointKind::Prismatic)
            .fold(1.0f64, |m, l| m.max(l.length))
    }
    /// Position coordinates.
    pub fn nx(&self) -> usize {
        self.motion.nx()
    }
}
