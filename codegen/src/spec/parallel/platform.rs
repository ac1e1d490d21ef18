//! The platform: the `[platform]` table, the rigid body the platform forms with what is fixed
//! to it, and the assembled [`ParallelModel`].

use std::collections::HashMap;

use runtime::model::{Body, Transform};
use runtime::parallel::{GEOMETRY_TOLERANCE, Leg, ParallelModel, PlatformMotion};

use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::geom::{self, MassProps, compose};
use crate::spec::ir::{BASE, Coordinates, Kind, PlatformSpec, Spec};
use crate::spec::lower::{self, Skip};
use crate::spec::suggest_hint;

/// The typical length for tolerances: the home position, at least 1 mm (as
/// [`ParallelModel::size`]; the leg joints are not known yet).
pub(super) fn scale(ps: &PlatformSpec) -> f64 {
    let mut s = geom::norm(&ps.home.translation).max(1e-3);
    if let Some(c) = ps.centre {
        s = s.max(geom::norm(&c));
    }
    s
}

/// The `[platform]` table: the body exists, `centre` fits the coordinates. Returns the platform
/// body's index.
pub(super) fn check_platform(
    spec: &Spec,
    ps: &PlatformSpec,
    body_index: &HashMap<&str, usize>,
    diags: &mut Diagnostics,
) -> Option<usize> {
    match ps.coordinates {
        Some(
            Coordinates::Pose
            | Coordinates::Translation
            | Coordinates::PlanarPose
            | Coordinates::HeaveTilt
            | Coordinates::Schoenflies,
        ) if ps.centre.is_some() => {
            diags.push(
                Diagnostic::error("`centre` is only for coordinates = \"orientation\"")
                    .with_key("platform.centre")
                    .with_span(ps.centre_span.clone())
                    .with_hint("a 6-DOF platform has no fixed centre; remove `centre` (or use coordinates = \"orientation\")"),
            );
        }
        Some(Coordinates::Orientation) => {
            if let Some(c) = ps.centre {
                let h = ps.home.translation;
                let d = geom::norm(&[c[0] - h[0], c[1] - h[1], c[2] - h[2]]);
                if d > GEOMETRY_TOLERANCE * scale(ps) {
                    diags.push(
                        Diagnostic::error("the centre of rotation must be the platform frame's origin at home")
                            .with_key("platform.centre")
                            .with_span(ps.centre_span.clone())
                            .with_hint(format!(
                                "centre = [{}, {}, {}] but home.xyz = [{}, {}, {}]; place the platform frame at the centre (or leave `centre` out: it defaults to home.xyz)",
                                geom::num(c[0]), geom::num(c[1]), geom::num(c[2]),
                                geom::num(h[0]), geom::num(h[1]), geom::num(h[2])
                            )),
                    );
                }
            }
        }
        _ => {}
    }
    let name = ps.body.as_deref()?;
    if name == BASE {
        diags.push(
            Diagnostic::error("the platform cannot be the base")
                .with_key("platform.body")
                .with_span(ps.body_span.clone())
                .with_hint("the platform is the moving body that the legs carry: one of the [[body]] entries"),
        );
        return None;
    }
    match body_index.get(name) {
        Some(&b) => Some(b),
        None => {
            let names: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
            diags.push(
                Diagnostic::error(format!("the platform body \"{name}\" does not exist"))
                    .with_key("platform.body")
                    .with_span(ps.body_span.clone())
                    .with_hint(suggest_hint(name, &names).unwrap_or_else(|| {
                        "the platform is one of the [[body]] entries: add it, with its mass and inertia in the platform frame".into()
                    })),
            );
            None
        }
    }
}

/// The platform and what is fixed to it: the joints and bodies the tree checks leave out, the
/// parts of the platform's rigid body with their poses in the platform frame, and per spec
/// body its pose on the platform (`Some` for the parts, and for bodies that a moving joint
/// wrongly hangs from it, left out of the tree checks).
pub(super) struct OnPlatform {
    pub skip: Skip,
    pub parts: Vec<(usize, Transform)>,
    pub pose: Vec<Option<Transform>>,
}

/// Grows the platform's rigid body from body `pb` along the fixed joints that hang from it
/// (joints into the platform, `closing`, aside); a moving joint from it, or a fixed joint that
/// closes a loop on it, is an error.
pub(super) fn on_platform(
    spec: &Spec,
    pb: usize,
    body_index: &HashMap<&str, usize>,
    closing: &[bool],
    diags: &mut Diagnostics,
) -> OnPlatform {
    let mut skip = Skip::none(spec);
    skip.body[pb] = true;
    let mut platform_parts = vec![(pb, Transform::IDENTITY)];
    let mut on_platform: Vec<Option<Transform>> = vec![None; spec.bodies.len()];
    on_platform[pb] = Some(Transform::IDENTITY);
    loop {
        let mut grew = false;
        for (ji, j) in spec.joints.iter().enumerate() {
            if closing[ji] || skip.joint[ji] {
                continue;
            }
            let Some(&p) = body_index.get(j.parent.as_str()) else {
                continue;
            };
            let Some(pose) = on_platform[p] else {
                continue;
            };
            skip.joint[ji] = true;
            grew = true;
            let child = body_index.get(j.child.as_str()).copied();
            if j.kind != Kind::Fixed {
                // Leave what it carries out of the tree checks too (no "not attached" echo).
                if let Some(c) = child
                    && on_platform[c].is_none()
                {
                    on_platform[c] = Some(Transform::IDENTITY);
                    skip.body[c] = true;
                }
                diags.push(
                    Diagnostic::error(format!(
                        "joint \"{}\" moves a body on the platform, but a {} joint cannot hang from the platform",
                        j.name,
                        j.kind.word()
                    ))
                    .with_key(format!("{}.kind", j.key))
                    .with_span(j.kind_span.clone())
                    .with_hint("a simple-platform mechanism carries only rigid attachments on its platform: use kind = \"fixed\" (its mass is added to the platform's)"),
                );
                continue;
            }
            let Some(c) = child else {
                continue; // reported by the topology check
            };
            if on_platform[c].is_some() {
                diags.push(
                    Diagnostic::error(format!(
                        "joint \"{}\" closes a loop on the platform: body \"{}\" is already part of it",
                        j.name, j.child
                    ))
                    .with_key(format!("{}.child", j.key))
                    .with_span(j.child_span.clone())
                    .with_hint("bodies fixed to the platform form a tree hanging from it"),
                );
                continue;
            }
            let (origin, offset) = lower::placement_frames(&j.placement);
            let at = compose(&pose, &compose(&origin, &offset));
            on_platform[c] = Some(at);
            skip.body[c] = true;
            platform_parts.push((c, at));
        }
        if !grew {
            break;
        }
    }
    OnPlatform {
        skip,
        parts: platform_parts,
        pose: on_platform,
    }
}

/// The parallel model: the platform's motion, its rigid body (the mass properties of `parts`
/// combined in the platform frame) and the legs.
pub(super) fn assemble(
    spec: &Spec,
    ps: &PlatformSpec,
    motion: Coordinates,
    pname: &str,
    parts: &[(usize, Transform)],
    legs: Vec<Leg>,
) -> ParallelModel {
    let centre = ps.centre.unwrap_or(ps.home.translation);
    let motion = match motion {
        Coordinates::Pose => PlatformMotion::Pose,
        Coordinates::Orientation => PlatformMotion::Orientation { centre },
        Coordinates::Planar => PlatformMotion::PlanarPoint {
            height: ps.home.translation[2],
        },
        Coordinates::Translation => PlatformMotion::Translation {
            rotation: ps.home.rotation,
        },
        Coordinates::PlanarPose => PlatformMotion::PlanarPose {
            height: ps.home.translation[2],
            rotation: ps.home.rotation,
        },
        Coordinates::Schoenflies => PlatformMotion::Schoenflies {
            rotation: ps.home.rotation,
        },
        Coordinates::HeaveTilt => PlatformMotion::HeaveTilt {
            rotation: ps.home.rotation,
            xy: [ps.home.translation[0], ps.home.translation[1]],
        },
    };
    let parts: Vec<MassProps> = parts
        .iter()
        .map(|&(b, at)| {
            let b = &spec.bodies[b];
            MassProps {
                mass: b.mass,
                com: b.com,
                inertia: b.inertia,
            }
            .transformed(&at)
        })
        .collect();
    let mp = MassProps::combine(&parts);
    ParallelModel {
        name: spec.name.clone(),
        gravity: spec.gravity,
        motion,
        platform: Body {
            name: pname.to_owned(),
            mass: mp.mass,
            com: mp.com,
            inertia: mp.inertia,
        },
        home: ps.home,
        legs,
    }
}
