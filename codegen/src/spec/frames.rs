//! `[scene] frames`: the frames whose kinematics a module offers (a tree's pose, Jacobian and
//! `J̇ q̇`; the same for frames fixed to a parallel platform; a closed loop's body poses),
//! resolved to the model body each is fixed to and its placement there, and the identifiers
//! their functions take.
//!
//! A frame is any spec body's own frame: a body a joint moves, or one attached by fixed joints
//! (a URDF link behind a fixed joint, a TOML body fixed to another, a body behind a locked
//! joint), or `"base"` (the fixed world; a URDF's root link). Fixed joints are merged before the dynamics, so the placement kept here is where
//! such a frame sits on the moving body it became part of. Without the key, the module offers
//! the tips: every leaf body (one that is no joint's parent) that some joint moves, in file
//! order; `frames = []` offers none.

use runtime::model::Transform;

use super::geom::compose;
use super::ir::{self, Named};
use super::lower::Attach;
use super::suggest_hint;
use crate::diag::{Diagnostic, Diagnostics};

/// A frame whose kinematics a module offers.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The name as the spec writes it (the body's).
    pub name: String,
    /// Its identifier in generated code (the name in lower snake case): the functions
    /// `<ident>_pose`, `<ident>_jacobian` and `<ident>_jacobian_dot_qd` (a tree's).
    pub ident: String,
    /// The model body it is fixed to (`None`: the base; a parallel mechanism's frames are all
    /// `None`, fixed to the platform).
    pub body: Option<usize>,
    /// Its pose in that body's frame (in the base frame when `body` is `None` in a tree; in
    /// the platform frame in a parallel mechanism).
    pub placement: Transform,
}

/// The identifier of a frame's functions: the name in lower snake case. ASCII letters are
/// lower-cased, with an `_` where a lower-case letter or digit meets an upper-case one
/// (`toolFlange` → `tool_flange`); every other character becomes `_`, runs of `_` collapse,
/// leading and trailing ones go, and `frame_` is put in front of a result that does not start
/// with a letter (`frame` when nothing is left).
pub(crate) fn frame_ident(name: &str) -> String {
    let mut out = String::new();
    let mut after_lower = false;
    for c in name.chars() {
        if c.is_ascii_uppercase() && after_lower && !out.ends_with('_') {
            out.push('_');
        }
        after_lower = c.is_ascii_lowercase() || c.is_ascii_digit();
        let c = c.to_ascii_lowercase();
        let c = if c.is_ascii_lowercase() || c.is_ascii_digit() {
            c
        } else {
            '_'
        };
        if !(c == '_' && out.ends_with('_')) {
            out.push(c);
        }
    }
    let out = out.trim_matches('_');
    match out.chars().next() {
        None => "frame".into(),
        Some(c) if c.is_ascii_lowercase() => out.into(),
        Some(_) => format!("frame_{out}"),
    }
}

/// The frames of a tree spec, or of closed loops in joint coordinates (any body of the
/// spanning tree, no default) (`attach`: where each spec body ended up). Errors at their
/// names' spans: an unknown body (with a suggestion), a name given twice, two names with one
/// identifier. Among the default frames (the key absent) a later one whose identifier is
/// taken is left out with a warning.
pub(super) fn resolve(
    spec: &ir::Spec,
    attach: &[Option<Attach>],
    diags: &mut Diagnostics,
) -> Vec<Frame> {
    let named: Vec<(Named, bool)> = match &spec.scene.frames {
        Some((names, _)) => names.iter().map(|n| (n.clone(), true)).collect(),
        // Closed loops in joint coordinates: none by default.
        None if super::closed::is_closed(spec) => Vec::new(),
        None => leaves(spec, attach)
            .into_iter()
            .map(|b| {
                let body = &spec.bodies[b];
                let n = Named {
                    name: body.name.clone(),
                    key: body.key.clone(),
                    span: body.span.clone(),
                };
                (n, false)
            })
            .collect(),
    };
    let names: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
    let mut frames: Vec<Frame> = Vec::new();
    for (n, written) in named {
        let base = Attach {
            target: None,
            pose: Transform::IDENTITY,
        };
        let found = match names.iter().position(|b| *b == n.name) {
            Some(b) => attach.get(b).copied().flatten(),
            None => {
                (n.name == ir::BASE || spec.root_link.as_ref() == Some(&n.name)).then_some(base)
            }
        };
        let Some(at) = found else {
            let mut d = Diagnostic::error(format!("unknown frame {:?}", n.name))
                .with_key(n.key.clone())
                .with_span(n.span.clone());
            d = d.with_hint(match suggest_hint(&n.name, &names) {
                Some(h) => format!("{h} (a frame is a body's name)"),
                None => "a frame is a body's name (one a joint moves, or one fixed to another by fixed joints), or the fixed world: \"base\", or a URDF's root link by its name".into(),
            });
            diags.push(d);
            continue;
        };
        if frames.iter().any(|f| f.name == n.name) {
            diags.push(
                Diagnostic::error(format!("frame {:?} is named twice", n.name))
                    .with_key(n.key.clone())
                    .with_span(n.span.clone())
                    .with_hint("name each frame once"),
            );
            continue;
        }
        let ident = frame_ident(&n.name);
        if let Some(other) = frames.iter().find(|f| f.ident == ident) {
            let message = format!(
                "frames {:?} and {:?} both become the identifier `{ident}` (functions `{ident}_pose`, …)",
                other.name, n.name
            );
            let hint = "frame identifiers are the names in lower snake case (docs/spec.md, `[scene] frames`); name only one of them, or rename a body";
            diags.push(if written {
                Diagnostic::error(message)
                    .with_key(n.key.clone())
                    .with_span(n.span.clone())
                    .with_hint(hint)
            } else {
                Diagnostic::warning(format!("{message}: the module offers only the first"))
                    .with_key(n.key.clone())
                    .with_span(n.span.clone())
                    .with_hint(hint)
            });
            continue;
        }
        // The body's own frame: where a child-side joint frame moved its data, `own_frame`
        // places it back (the base has none).
        let placement = match names.iter().position(|b| *b == n.name) {
            Some(b) => compose(&at.pose, &spec.bodies[b].own_frame),
            None => at.pose,
        };
        frames.push(Frame {
            // A URDF's own link "base" keeps its name (read under another).
            name: match &spec.base_link {
                Some(a) if *a == n.name => ir::BASE.to_owned(),
                _ => n.name.clone(),
            },
            ident,
            body: at.target,
            placement,
        });
    }
    frames
}

/// The default frames: the spec bodies that are no joint's parent and that some joint moves,
/// in file order.
fn leaves(spec: &ir::Spec, attach: &[Option<Attach>]) -> Vec<usize> {
    (0..spec.bodies.len())
        .filter(|&b| {
            let name = &spec.bodies[b].name;
            !spec.joints.iter().any(|j| &j.parent == name)
                && attach
                    .get(b)
                    .copied()
                    .flatten()
                    .is_some_and(|a| a.target.is_some())
        })
        .collect()
}

/// The frames of a parallel spec: the platform or bodies fixed to it (`placement`: the pose
/// in the platform frame; `body` is `None`). No default: without the key, none. Errors at the
/// names: an unknown body (with a suggestion), a body that is not the platform or fixed to it,
/// a frame named twice, two names with one identifier, the identifier `platform` beside a 1T2R
/// platform's own `platform_pose`; a planar-point platform (no orientation) takes none.
pub(super) fn resolve_platform(spec: &ir::Spec, diags: &mut Diagnostics) -> Vec<Frame> {
    let Some((names, span)) = &spec.scene.frames else {
        return Vec::new();
    };
    let coordinates = spec.platform.as_ref().and_then(|p| p.coordinates);
    if coordinates == Some(ir::Coordinates::Planar) && !names.is_empty() {
        diags.push(
            Diagnostic::error(
                "a planar-point platform offers no frames: its orientation is not a coordinate",
            )
            .with_key("scene.frames")
            .with_span(span.clone())
            .with_hint("remove `frames` (the point's position is `x`)"),
        );
        return Vec::new();
    }
    let bodies: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
    let mut frames: Vec<Frame> = Vec::new();
    for n in names {
        let error = |message: String, hint: String| {
            Diagnostic::error(message)
                .with_key(n.key.clone())
                .with_span(n.span.clone())
                .with_hint(hint)
        };
        let Some(placement) = super::parallel::pose_on_platform(spec, &n.name) else {
            let d = if bodies.contains(&n.name.as_str()) {
                error(
                    format!("frame {:?} is not the platform or fixed to it", n.name),
                    "a parallel module offers frames fixed to the platform: name the platform body or a body attached to it by fixed joints".into(),
                )
            } else {
                error(
                    format!("unknown frame {:?}", n.name),
                    match suggest_hint(&n.name, &bodies) {
                        Some(h) => format!("{h} (a frame is a body's name)"),
                        None => "a frame is the platform's name or a body's fixed to it".into(),
                    },
                )
            };
            diags.push(d);
            continue;
        };
        if frames.iter().any(|f| f.name == n.name) {
            diags.push(error(
                format!("frame {:?} is named twice", n.name),
                "name each frame once".into(),
            ));
            continue;
        }
        let ident = frame_ident(&n.name);
        if let Some(other) = frames.iter().find(|f| f.ident == ident) {
            diags.push(error(
                format!(
                    "frames {:?} and {:?} both become the identifier `{ident}` (functions `{ident}_pose`, …)",
                    other.name, n.name
                ),
                "frame identifiers are the names in lower snake case (docs/spec.md, `[scene] frames`); name only one of them, or rename a body".into(),
            ));
            continue;
        }
        if ident == "platform" && coordinates == Some(ir::Coordinates::HeaveTilt) {
            diags.push(error(
                format!("frame {:?} would make a second `platform_pose`", n.name),
                "a 1T2R module already has `platform_pose` (the full pose with the parasitic motion); rename the platform body, or name a body fixed to it".into(),
            ));
            continue;
        }
        frames.push(Frame {
            name: n.name.clone(),
            ident,
            body: None,
            placement,
        });
    }
    frames
}

#[cfg(test)]
mod tests {
    use super::frame_ident;

    #[test]
    fn identifiers() {
        assert_eq!(frame_ident("tool"), "tool");
        assert_eq!(frame_ident("iiwa_link_ee"), "iiwa_link_ee");
        assert_eq!(frame_ident("toolFlange"), "tool_flange");
        assert_eq!(frame_ident("Link 6"), "link_6");
        assert_eq!(frame_ident("URDF-Tip"), "urdf_tip");
        assert_eq!(frame_ident("6th"), "frame_6th");
        assert_eq!(frame_ident("--"), "frame");
        assert_eq!(frame_ident("a__b_"), "a_b");
    }
}
