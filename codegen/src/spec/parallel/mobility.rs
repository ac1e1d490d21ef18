//! The whole-mechanism counts: the mobility (Grübler–Kutzbach) and the number of actuators,
//! against the platform's degrees of freedom.

use runtime::model::Transform;
use runtime::parallel::GEOMETRY_TOLERANCE;

use super::platform::scale;
use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom;
use crate::spec::ir::{Coordinates, JointSpec, PlatformSpec, Spec};

/// Mobility by Grübler–Kutzbach, `M = λ(n − j − 1) + Σf` over the spec's bodies (plus the base)
/// and joints (minus the idle spin of a planar point platform), against the platform's DOF; and
/// the number of actuators against the DOF.
pub(super) fn check_mobility(spec: &Spec, ps: &PlatformSpec, diags: &mut Diagnostics) {
    let Some(coords) = ps.coordinates else {
        return;
    };
    let (lambda, dof, what) = match coords {
        Coordinates::Pose => (6i64, 6i64, "spatial, λ = 6"),
        Coordinates::Orientation => (3, 3, "spherical, λ = 3"),
        Coordinates::Planar => (3, 2, "planar, λ = 3"),
        Coordinates::Translation => (6, 3, "spatial, λ = 6"),
        Coordinates::PlanarPose => (3, 3, "planar, λ = 3"),
        Coordinates::HeaveTilt => (6, 3, "spatial, λ = 6"),
        Coordinates::Schoenflies => (6, 4, "spatial, λ = 6"),
    };
    // A parallelogram is counted as what it is, two rods with a ball joint at each end
    // (2 bodies, 4 S joints), not as its expansion (the equivalent rod, a U and an S: 1 body,
    // 2 joints, 5 freedoms); each rod's spin about its own axis is idle and does not count.
    let pgs = spec.parallelograms.len() as i64;
    let n = spec.bodies.len() as i64 + 1 + pgs;
    let j = spec.joints.len() as i64 + 2 * pgs;
    let f: i64 = spec
        .joints
        .iter()
        .map(|j| j.kind.coordinates() as i64)
        .sum::<i64>()
        + 7 * pgs;
    // A planar point platform's spin about the plane normal is idle (the point has no
    // orientation), so it does not count; a "platform" that the legs meet at different points
    // is a link whose spin they determine.
    let idle = i64::from(coords == Coordinates::Planar && apart(spec, ps).is_none()) + 2 * pgs;
    let m = lambda * (n - j - 1) + f - idle;
    let coords_word = match coords {
        Coordinates::Pose => "pose",
        Coordinates::Orientation => "orientation",
        Coordinates::Planar => "planar",
        Coordinates::Translation => "translation",
        Coordinates::PlanarPose => "planar_pose",
        Coordinates::HeaveTilt => "heave_tilt",
        Coordinates::Schoenflies => "schoenflies",
    };
    if m != dof {
        diags.push(
            Diagnostic::error(format!(
                "the mechanism's mobility is {m} (Grübler–Kutzbach, {what}), but a platform with coordinates = \"{coords_word}\" has {dof} degrees of freedom"
            ))
            .with_key("platform.coordinates")
            .with_span(ps.coordinates_span.clone())
            .with_hint(format!(
                "M = λ(n − j − 1) + Σf with n = {n} bodies (with the base), j = {j} joints and Σf = {f} joint freedoms (U counts 2, S 3, fixed 0); check the legs' joints{}",
                match coords {
                    Coordinates::Pose => ": each leg of a 6-DOF platform has six joint freedoms (UPS, PUS, RUS; an R-S-S or P-S-S leg has seven, its rod spinning idly about its own line: write its first S as a U, R-U-S)",
                    Coordinates::Orientation => ": each leg of a spherical mechanism is R-R-R",
                    Coordinates::Planar => ": each leg of a planar five-bar is R-R, joined at the point by a revolute",
                    Coordinates::Translation => ": each leg of a Delta is a revolute crank carrying a [[parallelogram]] (two ball–ball rods, their idle spins not counted)",
                    Coordinates::PlanarPose => ": each leg of a planar 3-DOF platform is R-R, P-R or R-P in the plane, joined to the platform by a revolute about z",
                    Coordinates::HeaveTilt => ": each leg of a 1T2R platform is P-R-S or R-P-S (5 DOF, one constraint each)",
                    Coordinates::Schoenflies => ": a 4-axis Delta's carrier has three Delta legs (a revolute crank carrying a [[parallelogram]]) and its tool a telescopic R-U-P-U shaft from a fourth motor, closed by the tool's revolute into the carrier",
                }
            )),
        );
    }
    let actuated = spec.joints.iter().filter(|j| j.actuated).count() as i64;
    if actuated != dof {
        diags.push(
            Diagnostic::error(format!(
                "{actuated} joint{} actuated, but the platform has {dof} degrees of freedom",
                if actuated == 1 { " is" } else { "s are" }
            ))
            .with_key("platform")
            .with_span(ps.span.clone())
            .with_hint({
                // The legs are the chains that end in the platform.
                let legs = spec
                    .joints
                    .iter()
                    .filter(|j| Some(j.child.as_str()) == ps.body.as_deref())
                    .count();
                let each = if legs as i64 == dof {
                    format!("in each of the {legs} legs")
                } else {
                    format!("in each leg ({legs} legs end in the platform; a platform with {dof} degrees of freedom needs {dof})")
                };
                format!(
                    "a parallel mechanism has one actuator per degree of freedom: mark exactly one revolute or prismatic joint {each} with actuated = true"
                )
            }),
        );
    }
}

/// Two joints into the platform that meet it at different points (their `child_origin`, the
/// platform frame's origin when missing; beyond the geometric tolerance), with the points.
pub(super) type Apart<'a> = [(&'a JointSpec, [f64; 3]); 2];

/// `None` when every joint into the platform meets it at the same point.
pub(super) fn apart<'a>(spec: &'a Spec, ps: &PlatformSpec) -> Option<Apart<'a>> {
    let at = |j: &'a JointSpec| (j, j.child_origin.unwrap_or(Transform::IDENTITY).translation);
    let mut into = spec
        .joints
        .iter()
        .filter(|j| Some(j.child.as_str()) == ps.body.as_deref())
        .map(at);
    let (first, p) = into.next()?;
    into.find(|(_, q)| {
        geom::norm(&[q[0] - p[0], q[1] - p[1], q[2] - p[2]]) > GEOMETRY_TOLERANCE * scale(ps)
    })
    .map(|other| [(first, p), other])
}
