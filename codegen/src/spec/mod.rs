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
//! This is the only module that knows TOML, XML or serde.

mod angle;
mod closed;
mod function;
mod geom;
mod ir;
mod lower;
mod parallel;
mod read_toml;
mod snap;
#[cfg(feature = "urdf")]
mod urdf;

#[cfg(test)]
mod tests;

use runtime::model::Model;
use runtime::parallel::ParallelModel;

use crate::diag::{Diagnostic, Diagnostics};

pub use function::{Function, FunctionSet, Kind};

/// The largest spec file read, in bytes (16 MiB). Larger input is refused before parsing.
pub const MAX_SOURCE_BYTES: usize = 16 << 20;

/// The most `[[body]]` or `[[joint]]` entries (URDF: `<link>` or `<joint>` elements) in one
/// spec. Fixed joints and their bodies count too, although they are merged.
pub const MAX_ENTRIES: usize = 1024;

/// The most degrees of freedom of a generated module: the movable one-DOF joints after
/// universal (2) and spherical (3) joints are expanded. The generated code grows with the cube
/// of the DOF (the dense `LᵀDL` of a chain's mass matrix) and generation time faster still
/// (a generic 16-joint chain takes 3 s, 32 joints 17 s, 64 joints about 3 min in the test
/// profile; branched trees are much cheaper: the 55-joint Romeo and the 101-joint TIAGo dual
/// URDFs take 2.5 s and 4.2 s in release), so larger specs are refused up front.
pub const MAX_DOF: usize = 128;

/// The longest name (of a mechanism, body, joint or spring; URDF: robot, link or joint), in
/// characters. Names become Rust identifiers and strings in the generated code.
pub const MAX_NAME_LEN: usize = 128;

/// The error of a name longer than [`MAX_NAME_LEN`], or `None`.
pub(crate) fn name_too_long(name: &str) -> Option<Diagnostic> {
    let n = name.chars().count();
    (n > MAX_NAME_LEN).then(|| {
        Diagnostic::error(format!(
            "name too long: {n} characters (the limit is {MAX_NAME_LEN})"
        ))
        .with_hint("names become Rust identifiers in the generated code; shorten it")
    })
}

/// The largest magnitude of any number in a spec (SI units). Larger values would overflow in
/// the generator's constant folding; nothing physical comes close.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// The value-range rule of every number read from a spec: finite is checked separately; this
/// is `|x| <= MAX_MAGNITUDE`.
pub(crate) fn in_range(x: f64) -> bool {
    x.abs() <= MAX_MAGNITUDE
}

/// The largest snapping tolerance (`[scene] snap`, `--snap`, [`SceneOverrides::snap`]): 0.01
/// (rad, m, or a rotation entry).
pub const MAX_SNAP: f64 = 1e-2;

/// `true` when `tol` is a snapping tolerance: in (0, [`MAX_SNAP`]] (NaN is not).
pub fn is_snap_tolerance(tol: f64) -> bool {
    tol > 0.0 && tol <= MAX_SNAP
}

/// The hint of a snapping tolerance out of range.
pub(crate) const SNAP_HINT: &str = "angles within this many rad of a multiple of π/2, rotation entries within it of 0 or ±1 and offsets within it (m) of 0 are taken as exact; e.g. 1e-6";

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

/// What the application needs of the mechanism (the spec's `[scene]` table, with the
/// [`SceneOverrides`] applied), as the generators read it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The public functions to emit (`[scene] functions`).
    pub functions: FunctionSet,
    /// The run-time parameters (`[scene] parameters = "runtime"`; `None`: constants).
    pub params: Option<RuntimeParams>,
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
    let (mechanism, scene) = match read {
        Some((m, s)) => (Some(m), Some(s)),
        None => (None, None),
    };
    let (mechanism, warnings) = finish(mechanism, diags)?;
    Ok(Loaded {
        mechanism,
        scene: scene.unwrap_or_default(),
        warnings,
    })
}

/// [`load`] for a tree spec, without overrides: the model and the warnings. A parallel
/// mechanism (a TOML spec with a `[platform]` table) or closed loops are an error here: read
/// them with [`load`] or [`load_mechanism`].
pub fn load_tree(file_name: &str, source: &str) -> Result<(Model, Diagnostics), Diagnostics> {
    let (read, mut diags, platform) = load_any(file_name, source, &SceneOverrides::default());
    let mechanism = read.map(|(m, _)| m);
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

/// Scene switches from outside the spec (CLI flags, [`crate::Config`]): each turns its effect
/// on in addition to what the spec's `[scene]` says (a URDF has no `[scene]`; its
/// `<dynamics damping friction>` apply only with `friction`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneOverrides {
    /// Apply the joints' viscous (`damping`) and Coulomb (`friction`) friction.
    pub friction: bool,
    /// Apply the joints' reflected rotor inertia (`armature`).
    pub rotor_inertia: bool,
    /// Take near-exact angles and offsets as exact within this tolerance (as `[scene] snap`;
    /// replaces the spec's value). Out of (0, [`MAX_SNAP`]] it is an error.
    pub snap: Option<f64>,
}

/// Reads, checks and lowers once; also returns the span of the `[platform]` header for a
/// parallel spec.
fn load_any(
    file_name: &str,
    source: &str,
    overrides: &SceneOverrides,
) -> (
    Option<(Mechanism, Scene)>,
    Diagnostics,
    Option<std::ops::Range<usize>>,
) {
    let mut diags = Diagnostics::new(file_name, source);
    if source.len() > MAX_SOURCE_BYTES {
        diags.push(too_large(source.len(), true));
        return (None, diags, None);
    }
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut d = Diagnostics::new(file_name, source);
        let spec = if is_urdf(file_name) {
            read_urdf(source, &mut d)
        } else {
            read_toml::read(source, &mut d)
        };
        let spec = spec.filter(|s| check_size(s, &mut d)).map(|mut s| {
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
            let (mechanism, attach) = if s.platform.is_some() {
                (
                    Mechanism::Parallel(parallel::lower_parallel(&s, &mut d)?),
                    None,
                )
            } else if closed::is_closed(&s) {
                let (m, attach) = closed::lower_closed_attached(&s, &mut d)?;
                (Mechanism::Closed(m), Some(attach))
            } else {
                let built = lower::lower_built(&s, &mut d)?;
                (Mechanism::Tree(built.model), Some(built.attach))
            };
            let params = runtime_params(&s, attach.as_deref());
            Some((mechanism, params))
        });
        let read = mechanism.map(|(m, params)| {
            if let Some(fs) = &functions {
                check_scene_functions(&m, fs, &mut d);
            }
            let functions = match &functions {
                None => FunctionSet::all(),
                Some(fs) => {
                    FunctionSet::only(fs.iter().filter_map(|f| f.name.parse().ok()).collect())
                }
            };
            (m, Scene { functions, params })
        });
        (read, d, platform)
    }));
    match result {
        Ok((mechanism, d, platform)) => {
            diags.extend(d);
            (mechanism, diags, platform)
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

/// The text of a spec file read as bytes. A file that is not UTF-8 (UTF-16, Latin-1, cut
/// inside a character) is an invalid spec: the error points at the first invalid byte.
pub fn source_text(file_name: &str, bytes: Vec<u8>) -> Result<String, Diagnostics> {
    if bytes.len() > MAX_SOURCE_BYTES {
        // Checked first: the bytes may end inside a character.
        let mut d = Diagnostics::new(file_name, "");
        d.push(too_large(bytes.len(), false));
        return Err(d);
    }
    let e = match String::from_utf8(bytes) {
        Ok(s) => return Ok(s),
        Err(e) => e,
    };
    let at = e.utf8_error().valid_up_to();
    let bytes = e.as_bytes();
    let hint = if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        "the file looks like UTF-16 (it starts with a byte-order mark): save it as UTF-8"
    } else if e.utf8_error().error_len().is_none() {
        "the file ends inside a character: is it cut short?"
    } else {
        "save the file as UTF-8 (this byte looks like another encoding, such as Latin-1)"
    };
    // Shown with the invalid bytes replaced by U+FFFD: the text before them is unchanged.
    let shown = String::from_utf8_lossy(bytes);
    let mut d = Diagnostics::new(file_name, &shown);
    d.push(
        Diagnostic::error(format!(
            "the spec is not UTF-8 text: invalid byte 0x{:02X}",
            bytes[at]
        ))
        .with_span(at..at + '\u{fffd}'.len_utf8())
        .with_hint(hint),
    );
    Err(d)
}

/// The error of a spec over [`MAX_SOURCE_BYTES`]: `len` bytes, or at least that many when the
/// file was not read to its end (`whole` false).
fn too_large(len: usize, whole: bool) -> Diagnostic {
    let size = if whole {
        format!("{len} bytes")
    } else {
        format!("more than {MAX_SOURCE_BYTES} bytes")
    };
    Diagnostic::error(format!("the spec is too large: {size} (the limit is {MAX_SOURCE_BYTES})"))
        .with_span(0..0)
        .with_hint(format!("nocdyn generates mechanisms of at most {MAX_DOF} degrees of freedom and {MAX_ENTRIES} bodies or joints; is this the right file?"))
}

/// An error when joint `j`, which `role` (e.g. "closes a loop"), has a drive: friction and rotor
/// inertia are modelled only where the joint's rate is known.
fn no_drive(j: &ir::JointSpec, role: &str, hint: &str, diags: &mut Diagnostics) {
    if j.drive != Default::default() {
        diags.push(
            Diagnostic::error(format!(
                "joint \"{}\" {role}: friction and rotor inertia are not modelled there",
                j.name
            ))
            .with_key(j.key.clone())
            .with_span(j.span.clone())
            .with_hint(hint),
        );
    }
}

/// The passes between reading and lowering: the overrides on top of the spec's `[scene]`,
/// snapping, then the scene's changes to the bodies and joints.
fn prepare(spec: &mut ir::Spec, overrides: &SceneOverrides, diags: &mut Diagnostics) {
    spec.scene.friction |= overrides.friction;
    spec.scene.rotor_inertia |= overrides.rotor_inertia;
    if let Some(tol) = overrides.snap {
        if is_snap_tolerance(tol) {
            spec.scene.snap = Some(tol);
        } else {
            // Set outside the file (`--snap`, `Builder::snap`): no place in it to point at.
            diags.push(
                Diagnostic::error(format!(
                    "the snap tolerance {tol} is not in (0, {MAX_SNAP}]"
                ))
                .with_hint(SNAP_HINT),
            );
        }
    }
    snap::snap(spec, diags);
    apply_scene(spec, diags);
}

/// `[scene]`: point masses and massless bodies replace the bodies' inertial data before
/// lowering (so everything downstream, fixed-joint merging included, sees the scene's model).
fn apply_scene(spec: &mut ir::Spec, diags: &mut Diagnostics) {
    let scene = spec.scene.clone();
    let names: Vec<&str> = spec.bodies.iter().map(|b| b.name.as_str()).collect();
    let find = |n: &ir::Named, diags: &mut Diagnostics| -> Option<usize> {
        let i = names.iter().position(|b| *b == n.name);
        if i.is_none() {
            let mut d = Diagnostic::error(format!("unknown body {:?}", n.name))
                .with_key(n.key.clone())
                .with_span(n.span.clone());
            if let Some(h) = suggest_hint(&n.name, &names) {
                d = d.with_hint(h);
            }
            diags.push(d);
        }
        i
    };
    let mut point = Vec::new();
    let mut massless = Vec::new();
    for n in &scene.point_mass {
        point.extend(find(n, diags));
    }
    for n in &scene.massless {
        massless.extend(find(n, diags));
    }
    let runtime = resolve_runtime_inertia(spec, &scene, &point, &massless, &find, diags);
    if let Some(p) = &scene.payload
        && let Some(i) = find(&p.body, diags)
    {
        let runtime = scene.runtime_params;
        if !(p.mass.is_finite() && p.mass >= 0.0) {
            diags.push(
                Diagnostic::error(format!(
                    "payload mass {} is not a finite, non-negative number",
                    p.mass
                ))
                .with_key("scene.payload.mass")
                .with_span(p.body.span.clone()),
            );
        } else if !runtime {
            // Run-time parameters keep the payload apart (`scene_params`).
            let b = &mut spec.bodies[i];
            let c = geom::MassProps::combine(&[
                geom::MassProps {
                    mass: b.mass,
                    com: b.com,
                    inertia: b.inertia,
                },
                geom::MassProps {
                    mass: p.mass,
                    com: p.com,
                    inertia: p.inertia,
                },
            ]);
            b.mass = c.mass;
            b.com = c.com;
            b.inertia = c.inertia;
        }
    }
    // Locked joints become fixed joints placed at their value.
    for (n, value) in &scene.locked {
        let Some(j) = spec.joints.iter_mut().find(|j| j.name == n.name) else {
            let names: Vec<&str> = spec.joints.iter().map(|j| j.name.as_str()).collect();
            let mut d = Diagnostic::error(format!("unknown joint {:?}", n.name))
                .with_key(n.key.clone())
                .with_span(n.span.clone());
            if let Some(h) = suggest_hint(&n.name, &names) {
                d = d.with_hint(h);
            }
            diags.push(d);
            continue;
        };
        if !matches!(j.kind, ir::Kind::Revolute | ir::Kind::Prismatic) {
            diags.push(
                Diagnostic::error(format!("cannot lock a {} joint", j.kind.word()))
                    .with_key(n.key.clone())
                    .with_span(n.span.clone())
                    .with_hint("only revolute and prismatic joints can be locked"),
            );
            continue;
        }
        let axis = j
            .axes
            .first()
            .map(|a| a.v)
            .filter(|v| geom::norm(v) > 1e-12)
            .map(|v| {
                let l = geom::norm(&v);
                [v[0] / l, v[1] / l, v[2] / l]
            })
            .unwrap_or([0.0, 0.0, 1.0]);
        let motion = if j.kind == ir::Kind::Revolute {
            runtime::model::Transform {
                rotation: runtime::model::axis_angle(&axis, *value),
                translation: [0.0; 3],
            }
        } else {
            geom::trans([axis[0] * value, axis[1] * value, axis[2] * value])
        };
        let (origin, offset) = lower::placement_frames(&j.placement);
        j.placement =
            ir::Placement::Origin(geom::compose(&geom::compose(&origin, &motion), &offset));
        j.kind = ir::Kind::Fixed;
        j.axes.clear();
        j.actuated = false;
    }
    // Run-time inertia: the spec's values are kept apart as the defaults, the constants go.
    for r in &runtime {
        let b = &mut spec.bodies[r.body];
        b.mass = 0.0;
        b.com = [0.0; 3];
        b.inertia = [[0.0; 3]; 3];
    }
    spec.scene.runtime_bodies = runtime;
    for i in point {
        spec.bodies[i].inertia = [[0.0; 3]; 3];
    }
    for i in massless {
        spec.bodies[i].mass = 0.0;
        spec.bodies[i].inertia = [[0.0; 3]; 3];
    }
}

/// `[scene] runtime_inertia`: the bodies whose inertial parameters become run-time
/// parameters, with the spec's values (see [`ir::RuntimeBodySpec`]). `"all"` takes every body
/// with mass or inertia that is neither a point mass nor massless (in a parallel mechanism:
/// the platform and the bodies fixed to it). Errors: the key without `parameters = "runtime"`,
/// unknown names (with a suggestion), a body named twice or also in `point_mass` / `massless`,
/// and a leg body of a parallel mechanism.
fn resolve_runtime_inertia(
    spec: &ir::Spec,
    scene: &ir::SceneSpec,
    point: &[usize],
    massless: &[usize],
    find: &dyn Fn(&ir::Named, &mut Diagnostics) -> Option<usize>,
    diags: &mut Diagnostics,
) -> Vec<ir::RuntimeBodySpec> {
    let Some((which, span)) = &scene.runtime_inertia else {
        return Vec::new();
    };
    if !scene.runtime_params {
        diags.push(
            Diagnostic::error("`runtime_inertia` makes bodies' inertial parameters run-time parameters, but the scene's parameters are constants")
                .with_key("scene.runtime_inertia")
                .with_span(span.clone())
                .with_hint("add `parameters = \"runtime\"` to [scene] (the module then takes a `Params` struct), or remove `runtime_inertia`"),
        );
        return Vec::new();
    }
    let on_platform =
        |name: &str| spec.platform.is_none() || parallel::pose_on_platform(spec, name).is_some();
    let mut chosen: Vec<(usize, Option<ir::Named>)> = Vec::new();
    match which {
        ir::RuntimeInertia::All => {
            for (i, b) in spec.bodies.iter().enumerate() {
                let has_mass = b.mass != 0.0 || b.inertia.iter().flatten().any(|x| *x != 0.0);
                if has_mass && !point.contains(&i) && !massless.contains(&i) && on_platform(&b.name)
                {
                    chosen.push((i, None));
                }
            }
        }
        ir::RuntimeInertia::Bodies(names) => {
            for n in names {
                let Some(i) = find(n, diags) else { continue };
                let error = |msg: String, hint: &str| {
                    Diagnostic::error(msg)
                        .with_key(n.key.clone())
                        .with_span(n.span.clone())
                        .with_hint(hint)
                };
                if chosen.iter().any(|(k, _)| *k == i) {
                    diags.push(error(
                        format!("body {:?} is named twice in `runtime_inertia`", n.name),
                        "name each body once",
                    ));
                } else if point.contains(&i) || massless.contains(&i) {
                    let what = if point.contains(&i) {
                        "point_mass"
                    } else {
                        "massless"
                    };
                    diags.push(error(
                        format!("body {:?} is in both `runtime_inertia` and `{what}`", n.name),
                        "a body's inertia is either given at run time or simplified as a constant: remove it from one of the two lists",
                    ));
                } else if !on_platform(&n.name) {
                    diags.push(error(
                        format!("body {:?} is not the platform or fixed to it: leg bodies' inertia is constant; only the platform's can be a run-time parameter", n.name),
                        "name the platform body (or a body fixed to it), or drop this body from `runtime_inertia`; its inertia stays folded into the leg dynamics",
                    ));
                } else {
                    chosen.push((i, Some(n.clone())));
                }
            }
        }
    }
    chosen
        .into_iter()
        .map(|(i, named)| {
            let b = &spec.bodies[i];
            ir::RuntimeBodySpec {
                body: i,
                named,
                mass: b.mass,
                com: b.com,
                inertia: b.inertia,
            }
        })
        .collect()
}

fn check_scene_functions(m: &Mechanism, fs: &[ir::Named], diags: &mut Diagnostics) {
    let kind = m.kind();
    let offered = || kind.selectable().iter().chain(kind.always());
    for f in fs {
        let ok = f
            .name
            .parse::<Function>()
            .is_ok_and(|f| offered().any(|&g| g == f));
        if !ok {
            let names: Vec<&str> = offered().map(|f| f.name()).collect();
            let always: Vec<&str> = kind.always().iter().map(|f| f.name()).collect();
            let what = match kind {
                Kind::Tree => "a tree module",
                Kind::Parallel => "a parallel module",
                Kind::Closed => "a closed-loop module",
            };
            let hint = if always.is_empty() {
                format!("{what} offers {}", names.join(", "))
            } else {
                format!(
                    "{what} offers {} ({} are always emitted)",
                    names.join(", "),
                    always.join(" and ")
                )
            };
            diags.push(
                Diagnostic::error(format!("cannot select function {:?}", f.name))
                    .with_key(f.key.clone())
                    .with_span(f.span.clone())
                    .with_hint(hint),
            );
        }
    }
}

/// The spec's body names in file order (TOML only; `None` when it cannot be read). For tools
/// that write `[scene]` tables (`codegen reduce`).
pub fn body_names(file_name: &str, source: &str) -> Option<Vec<String>> {
    if is_urdf(file_name) {
        return None;
    }
    let mut d = Diagnostics::new(file_name, source);
    let spec = read_toml::read(source, &mut d)?;
    Some(spec.bodies.into_iter().map(|b| b.name).collect())
}

/// The run-time parameters of a spec with `[scene] parameters = "runtime"` ([`Scene::params`];
/// `None` without).
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeParams {
    /// The payload: the model body it rides on, its mass (kg), mass centre (m) and inertia about
    /// the mass centre (kg·m²), both in that body's frame. For a parallel mechanism the body is
    /// the platform (index 0) and the values are in the platform frame; for closed loops it is
    /// the body of the spanning tree.
    pub payload: Option<(usize, f64, runtime::model::Vec3, runtime::model::Mat3)>,
    /// The speed scale `v_s` of the regularized Coulomb law (`[scene] coulomb_velocity`).
    pub coulomb_velocity: f64,
    /// Parallel mechanisms (leg joints) and closed loops (tree joints): the joints' viscous and
    /// Coulomb friction are run-time parameters (the scene's `friction` is on). Trees take every
    /// drive at run time.
    pub leg_friction: bool,
    /// Parallel mechanisms and closed loops: the joints' rotor inertias are run-time parameters
    /// (the scene's `rotor_inertia` is on).
    pub leg_rotor_inertia: bool,
    /// `[scene] runtime_inertia`: the bodies whose inertial parameters are run-time parameters,
    /// in the order of the list (`"all"`: the spec's body order), bodies fixed to the base left
    /// out. Their constants are zero in the model.
    pub bodies: Vec<RuntimeBody>,
}

/// A body whose inertial parameters are run-time parameters (`[scene] runtime_inertia`): it
/// enters the dynamics exactly as a run-time payload on the model body it is part of.
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeBody {
    /// The spec body's name (the generated `RUNTIME_BODY_NAMES`).
    pub name: String,
    /// The model body it is rigidly part of (after fixed-joint merging; for a parallel
    /// mechanism 0, the platform; for closed loops a body of the spanning tree).
    pub body: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Mass centre in the model body's frame (m).
    pub com: runtime::model::Vec3,
    /// Inertia about the mass centre, model body's axes (kg·m²).
    pub inertia: runtime::model::Mat3,
}

impl RuntimeBody {
    /// The spec's values of `r` placed on model body `body` at `pose` (the spec body's frame in
    /// the model body's frame).
    fn placed(
        spec: &ir::Spec,
        r: &ir::RuntimeBodySpec,
        body: usize,
        pose: &runtime::model::Transform,
    ) -> RuntimeBody {
        let m = geom::MassProps {
            mass: r.mass,
            com: r.com,
            inertia: r.inertia,
        }
        .transformed(pose);
        RuntimeBody {
            name: spec.bodies[r.body].name.clone(),
            body,
            mass: m.mass,
            com: m.com,
            inertia: m.inertia,
        }
    }
}

/// The run-time parameters of a prepared spec (see [`RuntimeParams`]), placed by `attach`
/// (where each spec body went in the tree of a tree or closed-loop mechanism; `None` for a
/// parallel one, whose payload rides on the platform).
fn runtime_params(
    spec: &ir::Spec,
    attach: Option<&[Option<lower::Attach>]>,
) -> Option<RuntimeParams> {
    if !spec.scene.runtime_params {
        return None;
    }
    // Parallel mechanisms and closed loops: the payload (if any) placed on its model body, and
    // the drives the scene models.
    let placed = |spec: &ir::Spec, body: usize, pose: &runtime::model::Transform| {
        let p = spec.scene.payload.as_ref()?;
        let m = geom::MassProps {
            mass: p.mass,
            com: p.com,
            inertia: p.inertia,
        }
        .transformed(pose);
        Some((body, m.mass, m.com, m.inertia))
    };
    let with_drives =
        |spec: &ir::Spec,
         payload: Option<(usize, f64, runtime::model::Vec3, runtime::model::Mat3)>,
         bodies: Vec<RuntimeBody>| {
            let (friction, rotor) = (spec.scene.friction, spec.scene.rotor_inertia);
            (payload.is_some() || friction || rotor || !bodies.is_empty()).then_some(
                RuntimeParams {
                    payload,
                    coulomb_velocity: spec.scene.coulomb_velocity,
                    leg_friction: friction,
                    leg_rotor_inertia: rotor,
                    bodies,
                },
            )
        };
    // The run-time bodies placed by `attach` (closed loops, trees): on the model body each
    // spec body is part of; those fixed to the base move with nothing and are left out.
    let attached = |spec: &ir::Spec, attach: &[Option<lower::Attach>]| -> Vec<RuntimeBody> {
        spec.scene
            .runtime_bodies
            .iter()
            .filter_map(|r| {
                let at = attach[r.body]?;
                Some(RuntimeBody::placed(spec, r, at.target?, &at.pose))
            })
            .collect()
    };
    let Some(attach) = attach else {
        let payload = match spec.scene.payload.as_ref() {
            None => None,
            Some(p) => placed(spec, 0, &parallel::pose_on_platform(spec, &p.body.name)?),
        };
        let bodies = spec
            .scene
            .runtime_bodies
            .iter()
            .filter_map(|r| {
                let pose = parallel::pose_on_platform(spec, &spec.bodies[r.body].name)?;
                Some(RuntimeBody::placed(spec, r, 0, &pose))
            })
            .collect();
        return with_drives(spec, payload, bodies);
    };
    if closed::is_closed(spec) {
        // A payload on a body fixed to the base moves with nothing: it is left out.
        let payload = spec.scene.payload.as_ref().and_then(|p| {
            let b = spec.bodies.iter().position(|b| b.name == p.body.name)?;
            let at = attach[b]?;
            placed(spec, at.target?, &at.pose)
        });
        let bodies = attached(spec, attach);
        return with_drives(spec, payload, bodies);
    }
    let payload = spec.scene.payload.as_ref().and_then(|p| {
        let b = spec.bodies.iter().position(|b| b.name == p.body.name)?;
        let at = attach[b]?;
        let target = at.target?;
        let m = geom::MassProps {
            mass: p.mass,
            com: p.com,
            inertia: p.inertia,
        }
        .transformed(&at.pose);
        Some((target, m.mass, m.com, m.inertia))
    });
    Some(RuntimeParams {
        payload,
        coulomb_velocity: spec.scene.coulomb_velocity,
        leg_friction: false,
        leg_rotor_inertia: false,
        bodies: attached(spec, attach),
    })
}

/// The size limits ([`MAX_ENTRIES`], [`MAX_DOF`]), checked before lowering so that no stage
/// runs out of time or memory on a huge spec. `false` (after an error) when a limit is broken.
fn check_size(spec: &ir::Spec, diags: &mut Diagnostics) -> bool {
    let anchor = spec.anchor.clone().unwrap_or(0..0);
    let mut ok = true;
    for (what, n, first) in [
        (
            "bodies",
            spec.bodies.len(),
            spec.bodies.get(MAX_ENTRIES).and_then(|b| b.span.clone()),
        ),
        (
            "joints",
            spec.joints.len(),
            spec.joints.get(MAX_ENTRIES).and_then(|j| j.span.clone()),
        ),
    ] {
        if n > MAX_ENTRIES {
            ok = false;
            diags.push(
                Diagnostic::error(format!(
                    "the spec is too large: {n} {what} (the limit is {MAX_ENTRIES})"
                ))
                .with_span(first.unwrap_or(anchor.clone()))
                .with_hint(format!("this is the first entry over the limit; nocdyn generates mechanisms of at most {MAX_ENTRIES} bodies and joints and {MAX_DOF} degrees of freedom")),
            );
        }
    }
    if !ok {
        return false;
    }
    let mut dof = 0;
    for j in &spec.joints {
        dof += match j.kind {
            ir::Kind::Revolute | ir::Kind::Prismatic => 1,
            ir::Kind::Universal => 2,
            ir::Kind::Spherical => 3,
            ir::Kind::Fixed => 0,
        };
        if dof > MAX_DOF {
            diags.push(
                Diagnostic::error(format!(
                    "the mechanism has too many joint coordinates: more than {MAX_DOF} with joint \"{}\"",
                    j.name
                ))
                .with_key(j.key.clone())
                .with_span(j.span.clone().unwrap_or(anchor))
                .with_hint(format!("the generated code grows with the cube of the number of coordinates; nocdyn generates at most {MAX_DOF} (revolute and prismatic joints count 1, universal 2, spherical 3, fixed 0; for a parallel mechanism every leg joint counts)")),
            );
            return false;
        }
    }
    true
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

/// `true` when `s` matches `[a-z][a-z0-9_]*` (usable as a Rust module name).
pub(crate) fn is_module_name(s: &str) -> bool {
    s.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && s.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

/// Maps any string to `[a-z][a-z0-9_]*`: lower-cased, other characters → `_`, runs of `_`
/// collapsed, leading/trailing `_` trimmed, prefixed with `m_` when it would not start with a
/// letter (`"mechanism"` when empty).
pub(crate) fn sanitize_name(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
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
    let out = out.trim_matches('_').to_owned();
    match out.chars().next() {
        None => "mechanism".into(),
        Some(c) if c.is_ascii_lowercase() => out,
        Some(_) => format!("m_{out}"),
    }
}

/// `did you mean "x"?` for the candidate closest to `word`, when close enough.
pub(crate) fn suggest_hint(word: &str, candidates: &[&str]) -> Option<String> {
    closest(word, candidates).map(|c| format!("did you mean \"{c}\"?"))
}

/// The edit-distance cells one [`closest`] call may fill (about a millisecond): with many long
/// candidates the first ones are compared, not all.
const SUGGEST_BUDGET: usize = 1 << 18;

/// The candidate with the smallest edit distance (transpositions count 1) to `word`, if that
/// distance is at most a third of the word's length (at least 1); ties go to the first. Words
/// and candidates longer than [`MAX_NAME_LEN`] characters take no part.
pub(crate) fn closest<'a>(word: &str, candidates: &[&'a str]) -> Option<&'a str> {
    let word: Vec<char> = word.to_lowercase().chars().collect();
    if word.len() > MAX_NAME_LEN {
        return None;
    }
    let mut best: Option<(usize, &str)> = None;
    let mut budget = SUGGEST_BUDGET;
    for c in candidates {
        // Only a strictly closer candidate replaces the best so far.
        let bound = match best {
            None => (word.len() / 3).max(1),
            Some((0, _)) => break,
            Some((d, _)) => d - 1,
        };
        if c.len() > 4 * MAX_NAME_LEN {
            continue;
        }
        let cand: Vec<char> = c.to_lowercase().chars().collect();
        if cand.len() > MAX_NAME_LEN || cand.len().abs_diff(word.len()) > bound {
            continue;
        }
        let cost = (word.len() + 1) * (cand.len() + 1);
        if cost > budget {
            break;
        }
        budget -= cost;
        if let Some(d) = edit_distance_within(&word, &cand, bound) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// The optimal-string-alignment distance (Levenshtein plus adjacent transpositions) of `a` and
/// `b` when it is at most `bound`. Three rows, and an early exit once a whole row is past the
/// bound (the distance never falls below a row's minimum).
fn edit_distance_within(a: &[char], b: &[char], bound: usize) -> Option<usize> {
    let m = b.len();
    let mut before: Vec<usize> = vec![0; m + 1];
    let mut prev: Vec<usize> = (0..=m).collect();
    let mut cur: Vec<usize> = vec![0; m + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(before[j - 2] + 1);
            }
            cur[j] = v;
        }
        if cur.iter().all(|&v| v > bound) {
            return None;
        }
        std::mem::swap(&mut before, &mut prev);
        std::mem::swap(&mut prev, &mut cur);
    }
    Some(prev[m]).filter(|&d| d <= bound)
}
