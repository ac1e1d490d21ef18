//! The spec layer: mechanism descriptions (TOML, or URDF with the `urdf` feature) → a validated
//! [`runtime::model::Model`] (a tree) or [`runtime::parallel::ParallelModel`] (a TOML spec with a
//! `[platform]` table), or [`Diagnostics`] pointing at every problem.
//!
//! Pipeline: a reader (`read_toml`, `urdf`) turns the text into the format-neutral `ir::Spec`,
//! reporting syntax, key and type errors with spans; `lower` checks values and topology and
//! lowers (stable topological order, fixed-joint merging, U/S expansion, DH frames) to the
//! model; `parallel` lowers a parallel mechanism with the same machinery and splits it into
//! legs. The format reference is `docs/spec.md`.
//!
//! This is the only module that knows TOML or XML.

mod angle;
mod child_frame;
mod closed;
mod cross;
mod expr;
mod fix;
mod frames;
mod function;
mod geom;
mod home;
mod input;
mod ir;
mod joint_home;
mod limits;
mod lower;
mod names;
mod parallel;
mod read_toml;
mod scene;
mod snap;
#[cfg(feature = "urdf")]
mod urdf;

#[cfg(test)]
mod tests;

use runtime::model::Model;
use runtime::parallel::ParallelModel;

use crate::diag::{Diagnostic, Diagnostics};

pub use cross::written_crosses;
pub use fix::apply_fixes;
pub use frames::Frame;
pub(crate) use frames::frame_ident;
pub use function::{Function, FunctionSet, Kind};
pub use home::{HomeJoint, HomePose, JointKind, Part, Segment};
pub use input::{
    MAX_DOF, MAX_ENTRIES, MAX_MAGNITUDE, MAX_NAME_LEN, MAX_PATH_DOF, MAX_SNAP, MAX_SOURCE_BYTES,
    is_snap_tolerance, source_text,
};
pub(crate) use input::{SNAP_HINT, in_range, name_too_long};
use input::{check_size, too_large};
pub use limits::JointLimit;
pub(crate) use names::{is_module_name, sanitize_name, suggest_hint};
pub use scene::{RuntimeBody, RuntimeParams, Scene, SceneFile, SceneOverrides, body_names};
use scene::{check_scene_functions, no_drive, prepare, runtime_params};

/// The hint of a number out of [`in_range`].
pub(crate) const RANGE_HINT: &str = "every number must lie within ±1e9 in SI units (m, kg, kg·m², rad, m/s²); check the units or the exponent";

/// A validated mechanism: a kinematic tree, or a simple-platform parallel manipulator.
// Built once per spec; boxing the larger variant would only complicate matching on it.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Mechanism {
    /// A serial chain or tree (no `[platform]` table; every URDF).
    Tree(Model),
    /// A parallel manipulator (a TOML spec with a `[platform]` table).
    Parallel(ParallelModel),
    /// Closed loops in joint coordinates (a TOML spec without `[platform]` whose loop-closing
    /// joints have `child_origin`).
    Closed(runtime::closed::ClosedModel),
}

impl Mechanism {
    /// The mechanism's name (`mechanism.name`).
    pub fn name(&self) -> &str {
        match self {
            Mechanism::Tree(m) => &m.name,
            Mechanism::Parallel(m) => &m.name,
            Mechanism::Closed(m) => &m.name,
        }
    }

    /// Its kind.
    pub fn kind(&self) -> Kind {
        match self {
            Mechanism::Tree(_) => Kind::Tree,
            Mechanism::Parallel(_) => Kind::Parallel,
            Mechanism::Closed(_) => Kind::Closed,
        }
    }
}

/// A spec read, checked and lowered in one pass.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The validated mechanism.
    pub mechanism: Mechanism,
    /// What its module is to contain.
    pub scene: Scene,
    /// The spec's warnings (e.g. an axis normalized).
    pub warnings: Diagnostics,
    /// The tree joints' limits (TOML `limit`, URDF `<limit>`), for the tools; not part of
    /// the dynamics. Empty for other mechanisms.
    pub limits: Vec<JointLimit>,
}

/// Read, check and lower a spec of any kind in one pass: the mechanism, its scene (the
/// functions `[scene] functions` selects and the run-time parameters) and the warnings. The
/// format is chosen by `file_name`'s extension: `.urdf` → URDF, anything else → TOML.
///
/// Pure: no I/O; `file_name` is only used for messages and the format choice. Never panics on
/// any input. On failure all errors (and warnings) found, sorted by position.
pub fn load(
    file_name: &str,
    source: &str,
    overrides: &SceneOverrides,
) -> Result<Loaded, Diagnostics> {
    let (read, diags, _) = load_any(file_name, source, overrides);
    let (mechanism, scene, limits) = match read {
        Some((m, s, l)) => (Some(m), Some(s), l),
        None => (None, None, Vec::new()),
    };
    let (mechanism, warnings) = finish(mechanism, diags)?;
    Ok(Loaded {
        mechanism,
        scene: scene.unwrap_or_default(),
        warnings,
        limits,
    })
}

/// [`load`] for a tree spec, without overrides: the model and the warnings. A parallel
/// mechanism (a TOML spec with a `[platform]` table) or closed loops are an error here: read
/// them with [`load`] or [`load_mechanism`].
pub fn load_tree(file_name: &str, source: &str) -> Result<(Model, Diagnostics), Diagnostics> {
    let (read, mut diags, platform) = load_any(file_name, source, &SceneOverrides::default());
    let mechanism = read.map(|(m, _, _)| m);
    if let Some(span) = platform {
        diags.push(
            Diagnostic::error("this spec describes a parallel mechanism (it has a [platform] table), which cannot be loaded as a tree")
                .with_key("platform")
                .with_span(span)
                .with_hint("generate it with codegen::compile (or the CLI), which takes every mechanism kind; codegen::spec::load_mechanism returns its ParallelModel"),
        );
    }
    if let Some(Mechanism::Closed(_)) = &mechanism {
        diags.push(
            Diagnostic::error("this spec describes closed loops (joints with `child_origin`), which cannot be loaded as a tree")
                .with_span(0..0)
                .with_hint("read it with codegen::spec::load_mechanism, which returns a ClosedModel"),
        );
    }
    finish(mechanism, diags).and_then(|(m, d)| match m {
        Mechanism::Tree(m) => Ok((m, d)),
        // Unreachable: a parallel spec got an error above.
        Mechanism::Parallel(_) => Err(d),
        Mechanism::Closed(_) => Err(d),
    })
}

/// [`load`] without overrides, keeping the mechanism and the warnings.
pub fn load_mechanism(
    file_name: &str,
    source: &str,
) -> Result<(Mechanism, Diagnostics), Diagnostics> {
    load(file_name, source, &SceneOverrides::default()).map(|l| (l.mechanism, l.warnings))
}

/// What [`load_any`] reads: the mechanism, its scene and the tree joints' limits.
type Read = (Mechanism, Scene, Vec<JointLimit>);

/// Reads, checks and lowers once; also returns the span of the `[platform]` header for a
/// parallel spec.
fn load_any(
    file_name: &str,
    source: &str,
    overrides: &SceneOverrides,
) -> (Option<Read>, Diagnostics, Option<std::ops::Range<usize>>) {
    let mut diags = Diagnostics::new(file_name, source);
    if source.len() > MAX_SOURCE_BYTES {
        diags.push(too_large(source.len(), true));
        return (None, diags, None);
    }
    // A sidecar's spans are moved past the spec's text; what points there goes to its file.
    let offset = source.len() + 1;
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut d = Diagnostics::new(file_name, source);
        let mut side = overrides
            .sidecar
            .as_ref()
            .map(|f| Diagnostics::new(&f.name, &f.text));
        let spec = read_ir(file_name, source, &mut d).and_then(|mut s| {
            if let (Some(f), Some(sd)) = (&overrides.sidecar, side.as_mut()) {
                if s.scene.written.is_some() {
                    sd.push(
                        Diagnostic::error(format!(
                            "{file_name} has its own [scene] table, and a scene file is given too"
                        ))
                        .with_hint(
                            "give the scene once: in the spec's [scene] table or in the scene file",
                        ),
                    );
                    return None;
                }
                let scene = read_toml::read_scene(&f.text, sd, &mut s.gravity)?;
                if sd.has_errors() {
                    return None;
                }
                s.scene = scene;
                s.scene.shift(offset);
            }
            Some(s)
        });
        let spec = spec.map(|mut s| {
            prepare(&mut s, overrides, &mut d);
            if s.scene.runtime_params
                && s.platform.is_none()
                && closed::is_closed(&s)
                && s.scene.payload.is_none()
                && s.scene.runtime_bodies.is_empty()
                && !s.scene.friction
                && !s.scene.rotor_inertia
            {
                d.push(
                    Diagnostic::error("run-time parameters of closed loops are a payload and the joints' drives, but the scene declares no payload and has neither `friction` nor `rotor_inertia` on")
                        .with_key("scene.parameters")
                        .with_span(s.scene.runtime_params_span.clone().or(s.anchor.clone()))
                        .with_hint("add `payload = { body = \"…\", mass = …, com = […], inertia = { … } }` or `friction = true` / `rotor_inertia = true` to [scene], or remove `parameters = \"runtime\"`"),
                );
            }
            if s.scene.runtime_params && s.platform.is_some() {
                // Parallel mechanisms: the run-time parameters are the platform's payload.
                match &s.scene.payload {
                    None if s.scene.friction
                        || s.scene.rotor_inertia
                        || !s.scene.runtime_bodies.is_empty() => {}
                    None => d.push(
                        Diagnostic::error("run-time parameters of a parallel mechanism are its platform payload and the leg joints' drives, but the scene declares no payload and has neither `friction` nor `rotor_inertia` on")
                            .with_key("scene.parameters")
                            .with_span(s.scene.runtime_params_span.clone().or(s.anchor.clone()))
                            .with_hint("add `payload = { body = \"<platform>\", mass = …, com = […], inertia = { … } }` or `friction = true` / `rotor_inertia = true` to [scene], or remove `parameters = \"runtime\"`"),
                    ),
                    Some(p) if parallel::pose_on_platform(&s, &p.body.name).is_none()
                        && s.bodies.iter().any(|b| b.name == p.body.name) =>
                    {
                        d.push(
                            Diagnostic::error(format!(
                                "a run-time payload must ride on the platform, but body {:?} is not the platform or fixed to it",
                                p.body.name
                            ))
                            .with_key("scene.payload.body")
                            .with_span(p.body.span.clone())
                            .with_hint("name the platform body, or a body attached to it by fixed joints; a payload on a leg body is possible only as constants"),
                        );
                    }
                    Some(_) => {}
                }
            }
            s
        });
        let platform = spec
            .as_ref()
            .and_then(|s| s.platform.as_ref())
            .map(|p| p.span.clone().unwrap_or(0..0));
        let functions = spec.as_ref().and_then(|s| s.scene.functions.clone());
        let limits = spec
            .as_ref()
            .map_or(Vec::new(), |s| limits::collect(s, &mut d));
        let mechanism = spec.and_then(|s| {
            if let Some(sp) = s.springs.first()
                && (s.platform.is_some() || !closed::is_closed(&s))
            {
                d.push(
                    Diagnostic::error(format!(
                        "spring \"{}\": force elements are supported in closed-loop mechanisms in joint coordinates only",
                        sp.name
                    ))
                    .with_key(sp.key.clone())
                    .with_span(sp.span.clone())
                    .with_hint("trees and parallel platforms take no [[spring]] yet: add the spring's effort to the actuator efforts you pass in, or write the mechanism in joint coordinates"),
                );
                return None;
            }
            // Lowered once; where each spec body went places the run-time bodies.
            let (mechanism, attach, frames) = if s.platform.is_some() {
                let frames = frames::resolve_platform(&s, &mut d);
                (
                    Mechanism::Parallel(parallel::lower_parallel(&s, &mut d)?),
                    None,
                    frames,
                )
            } else if closed::is_closed(&s) {
                let (m, attach) = closed::lower_closed_attached(&s, &mut d)?;
                let frames = frames::resolve(&s, &attach, &mut d);
                (Mechanism::Closed(m), Some(attach), frames)
            } else {
                let built = lower::lower_built(&s, &mut d)?;
                let frames = frames::resolve(&s, &built.attach, &mut d);
                (Mechanism::Tree(built.model), Some(built.attach), frames)
            };
            let params = runtime_params(&s, attach.as_deref());
            Some((mechanism, params, frames))
        });
        let read = mechanism.map(|(m, params, frames)| {
            if let Some(fs) = &functions {
                check_scene_functions(&m, fs, &mut d);
                // The base parameters' values would be inputs: no regressor with run-time
                // parameters (docs/method.md, "Identification").
                if params.is_some() && matches!(m, Mechanism::Tree(_)) {
                    for f in fs.iter().filter(|f| f.name == "regressor") {
                        d.push(
                            Diagnostic::error("a module with run-time parameters has no regressor")
                                .with_key(f.key.clone())
                                .with_span(f.span.clone())
                                .with_hint("the base parameters' values would depend on the run-time parameters: generate the regressor from a scene with constants (remove `parameters = \"runtime\"`)"),
                        );
                    }
                }
            }
            let functions = match &functions {
                None => FunctionSet::all(),
                Some(fs) => {
                    FunctionSet::only(fs.iter().filter_map(|f| f.name.parse().ok()).collect())
                }
            }
            .without(m.kind(), &overrides.omit);
            (
                m,
                Scene {
                    functions,
                    params,
                    frames,
                },
                limits,
            )
        });
        (read, d, platform, side)
    }));
    match result {
        Ok((mechanism, d, platform, side)) => {
            diags.extend(d);
            let Some(mut side) = side else {
                return (mechanism, diags, platform);
            };
            for mut m in diags.take_if(|m| m.span.as_ref().is_some_and(|s| s.start >= offset)) {
                m.span = m.span.map(|s| s.start - offset..s.end - offset);
                side.push(m);
            }
            if side.has_errors() {
                // The scene file's errors first; the spec's own, if any, once it reads.
                side.sort_by_position();
                (None, side, platform)
            } else {
                // Its warnings, with no place in the spec's text: the scene file's line and
                // column go into the message.
                for mut m in side.take_if(|_| true) {
                    let place = m.span.take().map_or(String::new(), |s| {
                        let (line, column) = crate::diag::line_column(side.source(), s.start);
                        format!(":{line}:{column}")
                    });
                    m.message = format!("{}{place}: {}", side.file_name(), m.message);
                    diags.push(m);
                }
                (mechanism, diags, platform)
            }
        }
        Err(_) => {
            diags.push(
                Diagnostic::error("internal error: the spec reader panicked")
                    .with_hint("this is a bug in nocdyn; please report it with the input file"),
            );
            (None, diags, None)
        }
    }
}

/// The bodies of a spec as its text gives them (patterns expanded, expressions evaluated,
/// before any lowering): `(name, mass, mass centre, inertia about it)` in each body's spec
/// frame. For tools that write a spec's numbers back (`codegen identify --out`); `None` after
/// errors (the spec does not load).
pub fn written_bodies(
    file_name: &str,
    source: &str,
) -> Option<Vec<(String, f64, runtime::model::Vec3, runtime::model::Mat3)>> {
    let mut d = Diagnostics::new(file_name, source);
    let s = read_ir(file_name, source, &mut d)?;
    if d.has_errors() {
        return None;
    }
    Some(
        s.bodies
            .into_iter()
            .map(|b| (b.name, b.mass, b.com, b.inertia))
            .collect(),
    )
}

/// The format-neutral spec of `source` (TOML or URDF by `file_name`, as [`load`] chooses),
/// within the size limits; `None` after errors in `d`.
fn read_ir(file_name: &str, source: &str, d: &mut Diagnostics) -> Option<ir::Spec> {
    let root = xml_root(source);
    let spec = match root
        .as_ref()
        .map(|(name, span)| (name.as_str(), span.clone()))
    {
        _ if is_urdf(file_name) => read_urdf(source, d),
        // A URDF under another name (`robot.xml`).
        Some(("robot", _)) => read_urdf(source, d),
        Some((other, span)) => {
            d.push(other_xml(other, span));
            None
        }
        None => read_toml::read(source, d),
    };
    spec.filter(|s| check_size(s, d))
        .map(|s| child_frame::apply(s, d))
        .map(|s| joint_home::apply(s, d))
}

/// The home pose of a spec as written, for drawing it (`codegen draw`): every joint placed at
/// zero joint coordinates, loops not closed (a gap shows where the spec leaves one open).
///
/// The spec is also loaded as [`load`] does, and its diagnostics come back with the pose:
/// they may hold errors (a loop too far open, a wrong mobility) when the geometry could still
/// be placed, which is when a picture helps most. `Err` when the spec cannot be read or some
/// joint cannot be placed (an unknown body, a cycle). Pure, and never panics.
pub fn home_pose(file_name: &str, source: &str) -> Result<(HomePose, Diagnostics), Diagnostics> {
    let mut diags = match load(file_name, source, &SceneOverrides::default()) {
        Ok(l) => l.warnings,
        Err(d) => d,
    };
    if source.len() > MAX_SOURCE_BYTES {
        return Err(diags);
    }
    let placed = std::panic::catch_unwind(|| {
        let mut d = Diagnostics::new(file_name, source);
        read_ir(file_name, source, &mut d).and_then(|s| home::home_pose(&s))
    });
    match placed {
        Ok(Some(home)) => Ok((home, diags)),
        Ok(None) => {
            if !diags.has_errors() {
                diags.push(Diagnostic::error(
                    "the home pose could not be placed: some joint is not reached from the base",
                ));
            }
            Err(diags)
        }
        Err(_) => {
            diags.push(
                Diagnostic::error("internal error: placing the home pose panicked")
                    .with_hint("this is a bug in nocdyn; please report it with the input file"),
            );
            Err(diags)
        }
    }
}

fn finish(
    mechanism: Option<Mechanism>,
    mut diags: Diagnostics,
) -> Result<(Mechanism, Diagnostics), Diagnostics> {
    diags.sort_by_position();
    match mechanism {
        Some(m) if !diags.has_errors() => Ok((m, diags)),
        _ => {
            if !diags.has_errors() {
                diags.push(Diagnostic::error("the spec could not be read"));
            }
            Err(diags)
        }
    }
}

/// The root element's name and span when `source` is XML (after an optional byte-order mark,
/// XML declaration, processing instructions, comments and a DOCTYPE), `None` otherwise.
fn xml_root(source: &str) -> Option<(String, std::ops::Range<usize>)> {
    let mut at = source.strip_prefix('\u{feff}').map_or(0, |_| 3);
    loop {
        let rest = &source[at..];
        let trimmed = rest.trim_start();
        at += rest.len() - trimmed.len();
        let skip = [("<?", "?>"), ("<!--", "-->"), ("<!", ">")]
            .into_iter()
            .find(|(open, _)| trimmed.starts_with(open));
        match skip {
            Some((_, close)) => at += trimmed.find(close)? + close.len(),
            None => break,
        }
    }
    let tag = source[at..].strip_prefix('<')?;
    let len = tag
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == ':'))
        .unwrap_or(tag.len());
    (len > 0).then(|| (tag[..len].to_string(), at..at + 1 + len))
}

/// The error of an XML file that is not a URDF: MJCF and SDF by name, anything else by its
/// root element.
fn other_xml(root: &str, span: std::ops::Range<usize>) -> Diagnostic {
    let (what, hint) = match root {
        "mujoco" => (
            format!(
                "this is an MJCF file (MuJoCo's format, root element `<{root}>`), which nocdyn does not read"
            ),
            "write the mechanism as a TOML spec (docs/spec.md; a tree's bodies, hinge and slide joints and inertials map one to one, an `<equality connect>` onto a loop-closing joint with `child_origin`), or give a URDF of the same robot",
        ),
        "sdf" => (
            format!(
                "this is an SDF file (Gazebo's format, root element `<{root}>`), which nocdyn does not read"
            ),
            "give a URDF of the same robot (a robot description package usually has one), or write the mechanism as a TOML spec (docs/spec.md)",
        ),
        _ => (
            format!("this is an XML file with root element `<{root}>`, not a URDF (`<robot>`)"),
            "nocdyn reads TOML specs (docs/spec.md) and URDF files",
        ),
    };
    Diagnostic::error(what).with_span(span).with_hint(hint)
}

/// A URDF as a TOML spec that generates the same module, number for number (`codegen
/// convert`), with the URDF's warnings. The URDF is loaded first: an invalid one is its
/// diagnostics.
#[cfg(feature = "urdf")]
pub fn urdf_to_toml(file_name: &str, source: &str) -> Result<(String, Diagnostics), Diagnostics> {
    let (_, warnings) = load_mechanism(file_name, source)?;
    let mut d = Diagnostics::new(file_name, source);
    match urdf::to_toml(source, &mut d) {
        Some(text) if !d.has_errors() => Ok((text, warnings)),
        _ => Err(d),
    }
}

fn is_urdf(file_name: &str) -> bool {
    file_name.to_ascii_lowercase().ends_with(".urdf")
}

#[cfg(feature = "urdf")]
fn read_urdf(source: &str, diags: &mut Diagnostics) -> Option<ir::Spec> {
    urdf::read(source, diags)
}

#[cfg(not(feature = "urdf"))]
fn read_urdf(_source: &str, diags: &mut Diagnostics) -> Option<ir::Spec> {
    diags.push(
        Diagnostic::error("URDF input is not enabled in this build")
            .with_hint("enable the \"urdf\" feature of the codegen crate"),
    );
    None
}
