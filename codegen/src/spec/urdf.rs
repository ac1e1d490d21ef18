//! The URDF reader (feature `urdf`).
//!
//! `urdf-rs` parses the structure but gives no source positions, and it silently skips
//! malformed numbers inside vectors (`xyz="0 x 1 1"` reads as `[0, 1, 1]`). So a small tag
//! scanner runs first: it checks nesting, the joint types, `<mimic>`, and every number that
//! reaches the model, reporting each problem at its `line:column`; it also gives the spans that
//! the later (format-neutral) checks point at. Numbers are parsed with Rust's correctly rounded
//! `str::parse::<f64>`, by urdf-rs and by the scanner alike, so values are kept exactly as
//! written (`1.570796325` stays `1.570796325`).
//!
//! By concept: `xml` (the tag scanner and the document it gives), `precheck` (the checks before
//! urdf-rs reads the file), and here [`read`]: the steps from the scanned tags to the [`Spec`]
//! (the robot element, the size limit, urdf-rs, the root link, the renamed `base`, the bodies,
//! the joints and their depth-first order).

use runtime::model::{Transform, rpy_to_matrix};

use super::geom::rotate_inertia;
use super::ir::{
    AxisSpec, BASE, BodySpec, DriveSpec, JointSpec, Kind, LimitSpec, Placement, Span, Spec,
};
use super::sanitize_name;
use crate::diag::{Diagnostic, Diagnostics};

mod precheck;
mod xml;

use precheck::precheck;
use xml::{Doc, Tag, scan, strip_ignored};

/// Reads a URDF document.
pub(crate) fn read(source: &str, diags: &mut Diagnostics) -> Option<Spec> {
    read_robot(source, diags).map(|(_, _, spec)| spec)
}

/// A URDF document as a TOML spec that generates the same module (`codegen convert`): the
/// links and joints in the order the reader takes them, every number as the URDF writes it
/// (origins as `xyz` and `rpy`, the inertia in its `<inertial>` frame with `inertia_rpy`), so
/// that the TOML reader builds the same model, bit for bit. A `<limit>` that gives a range
/// becomes the joint's `limit` (carried beside the model for the tools, as the URDF's is); a
/// `<mimic>` is kept as a comment.
pub(crate) fn to_toml(source: &str, diags: &mut Diagnostics) -> Option<String> {
    use std::fmt::Write;
    let (r, names, spec) = read_robot(source, diags)?;
    // TOML names are identifiers (ASCII letters, digits, `_`, not starting with a digit); a
    // URDF name that is not becomes one, kept unique, with its URDF name in a comment.
    let mut taken: Vec<String> = Vec::new();
    let mut renamed: std::collections::HashMap<String, String> = Default::default();
    let mut ident = |name: &str| -> String {
        if let Some(v) = renamed.get(name) {
            return v.clone();
        }
        let mut t: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        if t.is_empty() || t.starts_with(|c: char| c.is_ascii_digit()) {
            t.insert(0, '_');
        }
        while taken.contains(&t) {
            t.push('_');
        }
        taken.push(t.clone());
        renamed.insert(name.to_string(), t.clone());
        t
    };
    let was = |old: &str, new: &str| {
        if old == new {
            String::new()
        } else {
            format!("  # URDF name {old:?}")
        }
    };
    let n = |v: f64| format!("{v:?}");
    let v3 = |v: &[f64; 3]| format!("[{}, {}, {}]", n(v[0]), n(v[1]), n(v[2]));
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Converted from the URDF robot \"{}\" by `codegen convert`: the same model, number for\n# number; joint limits as `limit` (carried for the tools, not part of the dynamics). Add a\n# [scene] table for payloads, locked joints, point masses or run-time parameters (docs/spec.md,\n# docs/scene.md).\n",
        r.name
    );
    let _ = writeln!(out, "[mechanism]");
    let _ = writeln!(out, "name = {:?}", spec.name);
    let _ = writeln!(out, "gravity = {}", v3(&spec.gravity));
    let _ = writeln!(
        out,
        "source = {:?}",
        format!("URDF robot \"{}\", converted by codegen convert", r.name)
    );
    for l in r
        .links
        .iter()
        .filter(|l| Some(&l.name) != names.root.as_ref())
    {
        let inl = &l.inertial;
        let it = &inl.inertia;
        let _ = writeln!(out, "\n[[body]]");
        let body = names.rename(&l.name);
        let id = ident(&body);
        let _ = writeln!(out, "name = {id:?}{}", was(&body, &id));
        let _ = writeln!(out, "mass = {}", n(inl.mass.value));
        let _ = writeln!(out, "com = {}", v3(&inl.origin.xyz.0));
        let _ = writeln!(
            out,
            "inertia = {{ ixx = {}, iyy = {}, izz = {}, ixy = {}, ixz = {}, iyz = {} }}",
            n(it.ixx),
            n(it.iyy),
            n(it.izz),
            n(it.ixy),
            n(it.ixz),
            n(it.iyz)
        );
        if inl.origin.rpy.0 != [0.0; 3] {
            let _ = writeln!(out, "inertia_rpy = {}", v3(&inl.origin.rpy.0));
        }
    }
    for js in &spec.joints {
        let Some(j) = r.joints.iter().find(|j| j.name == js.name) else {
            continue;
        };
        let _ = writeln!(out, "\n[[joint]]");
        let id = ident(&js.name);
        let _ = writeln!(out, "name = {id:?}{}", was(&js.name, &id));
        let _ = writeln!(out, "kind = {:?}", js.kind.word());
        let parent = if js.parent == BASE {
            BASE.to_string()
        } else {
            ident(&js.parent)
        };
        let _ = writeln!(out, "parent = {parent:?}");
        let _ = writeln!(out, "child = {:?}", ident(&js.child));
        let _ = writeln!(
            out,
            "origin = {{ xyz = {}, rpy = {} }}",
            v3(&j.origin.xyz.0),
            v3(&j.origin.rpy.0)
        );
        if js.kind != Kind::Fixed {
            let _ = writeln!(out, "axis = {}", v3(&j.axis.xyz.0));
        }
        if let Some(d) = &j.dynamics {
            if d.damping > 0.0 {
                let _ = writeln!(out, "damping = {}", n(d.damping));
            }
            if d.friction > 0.0 {
                let _ = writeln!(out, "friction = {}", n(d.friction));
            }
        }
        if let Some(l) = &js.limit {
            let v = l
                .velocity
                .map_or(String::new(), |v| format!(", velocity = {}", n(v)));
            let _ = writeln!(
                out,
                "limit = {{ lower = {}, upper = {}{v} }}",
                n(l.lower),
                n(l.upper)
            );
        }
        if let Some(m) = &j.mimic {
            let _ = writeln!(
                out,
                "# mimics {:?} (multiplier {}, offset {}): read as an independent joint, as from the URDF",
                m.joint,
                m.multiplier.map_or("1".into(), n),
                m.offset.map_or("0".into(), n)
            );
        }
    }
    Some(out)
}

/// The URDF document parsed (urdf-rs), the link names as read, and the spec.
fn read_robot(source: &str, diags: &mut Diagnostics) -> Option<(urdf_rs::Robot, Names, Spec)> {
    let tags = scan(source, diags);
    if diags.has_errors() {
        return None;
    }
    let robot = find_robot(&tags, diags)?;
    check_size(&tags, robot, diags);
    if diags.has_errors() {
        return None;
    }
    let doc = Doc::new(tags, robot);
    let (link_tags, joint_tags) = precheck(&doc, diags);
    if diags.has_errors() {
        return None;
    }
    let robot_span = doc.tags[robot].name_span();
    let r = parse(source, &doc, &robot_span, diags)?;
    // urdf-rs keeps the top-level links and joints in document order, as the scanner does.
    let links = Spans {
        doc: &doc,
        list: &link_tags,
    };
    let joint_spans = Spans {
        doc: &doc,
        list: &joint_tags,
    };
    let Ok(root) = root_link(&r, &doc, &links, diags) else {
        return None;
    };
    let names = Names::new(&r, root, &links, diags);
    let bodies = bodies(&r, &names, &links);
    let joints = joints(&r, &names, &joint_spans, diags)?;
    let joints = depth_first(joints);

    let spec = Spec {
        name: sanitize_name(&r.name),
        gravity: [0.0, 0.0, -9.81],
        bodies,
        joints,
        anchor: Some(robot_span),
        joints_incomplete: false,
        platform: None,
        scene: Default::default(),
        springs: Vec::new(),
        parallelograms: Vec::new(),
        parallelogram_widths: Vec::new(),
        base_link: names.alias.clone(),
        root_link: names.root.clone(),
    };
    Some((r, names, spec))
}

/// The index of the top-level `<robot>` tag, else an error.
fn find_robot(tags: &[Tag<'_>], diags: &mut Diagnostics) -> Option<usize> {
    let Some(robot) = tags
        .iter()
        .position(|t| t.name == "robot" && t.parent.is_none())
    else {
        diags.push(
            Diagnostic::error("no <robot> element")
                .with_span(0..0)
                .with_hint("a URDF file has one top-level <robot name=\"...\"> element"),
        );
        return None;
    };
    Some(robot)
}

/// The size limit, before anything quadratic in the number of links and joints: an error at
/// the first `<link>` and the first `<joint>` over it.
fn check_size(tags: &[Tag<'_>], robot: usize, diags: &mut Diagnostics) {
    for what in ["link", "joint"] {
        let mut of_kind = tags
            .iter()
            .filter(|t| t.parent == Some(robot) && t.name == what);
        let n = of_kind.clone().count();
        if n > super::MAX_ENTRIES {
            let first = of_kind.nth(super::MAX_ENTRIES).map(Tag::name_span);
            diags.push(
                Diagnostic::error(format!(
                    "the robot is too large: {n} <{what}> elements (the limit is {})",
                    super::MAX_ENTRIES
                ))
                .with_span(first)
                .with_hint(format!(
                    "this is the first one over the limit; nocdyn generates mechanisms of at most {} links and joints and {} degrees of freedom",
                    super::MAX_ENTRIES,
                    super::MAX_DOF
                )),
            );
        }
    }
}

/// The robot as urdf-rs reads the source with the ignored elements blanked out; its error at
/// the robot's name.
fn parse(
    source: &str,
    doc: &Doc<'_>,
    robot_span: &std::ops::Range<usize>,
    diags: &mut Diagnostics,
) -> Option<urdf_rs::Robot> {
    let stripped = strip_ignored(source, doc);
    match urdf_rs::read_from_string(&stripped) {
        Ok(r) => Some(r),
        Err(e) => {
            diags.push(
                Diagnostic::error(format!("URDF: {e}"))
                    .with_span(robot_span.clone())
                    .with_hint("the URDF reader (urdf-rs) rejected the file"),
            );
            None
        }
    }
}

/// The spans of the top-level `<link>` (or `<joint>`) tags, by their index in urdf-rs's list.
struct Spans<'d, 's> {
    doc: &'d Doc<'s>,
    /// The tags, in document order.
    list: &'d [usize],
}

impl Spans<'_, '_> {
    /// Entry `i`'s name attribute (else its tag).
    fn name(&self, i: usize) -> Span {
        self.list.get(i).map(|&t| self.doc.tags[t].name_span())
    }
    /// Attribute `attr` of the element at `path` below entry `i` (else that element's tag).
    fn attr(&self, i: usize, path: &[&'static str], attr: &str) -> Span {
        let t = &self.doc.tags[self.doc.descend(*self.list.get(i)?, path)?];
        Some(t.attr(attr).map_or(t.span.clone(), |a| a.span.clone()))
    }
    /// The tag of the element at `path` below entry `i`.
    fn tag(&self, i: usize, path: &[&'static str]) -> Span {
        Some(
            self.doc.tags[self.doc.descend(*self.list.get(i)?, path)?]
                .span
                .clone(),
        )
    }
}

/// An error was reported: reading stops.
struct Reported;

/// The root link: the one link that no joint has as child (`None`: a cycle, which the topology
/// check reports). No link, or links not connected to the root, are errors.
fn root_link(
    r: &urdf_rs::Robot,
    doc: &Doc<'_>,
    links: &Spans<'_, '_>,
    diags: &mut Diagnostics,
) -> Result<Option<String>, Reported> {
    let is_child = |n: &str| r.joints.iter().any(|j| j.child.link == n);
    let roots: Vec<usize> = (0..r.links.len())
        .filter(|&i| !is_child(&r.links[i].name))
        .collect();
    match roots.as_slice() {
        [one] => Ok(Some(r.links[*one].name.clone())),
        [] if r.links.is_empty() => {
            diags.push(
                Diagnostic::error("the robot has no links")
                    .with_span(doc.tags[doc.robot].span.clone()),
            );
            Err(Reported)
        }
        [] => Ok(None), // a cycle; the topology check reports it
        [first, rest @ ..] => {
            for &i in rest {
                diags.push(
                    Diagnostic::error(format!(
                        "link \"{}\" is not connected to the root link \"{}\"",
                        r.links[i].name, r.links[*first].name
                    ))
                    .with_key(format!("link \"{}\"", r.links[i].name))
                    .with_span(links.name(i))
                    .with_hint(
                        "a URDF robot is one tree: every link except the root is the child of a joint",
                    ),
                );
            }
            Err(Reported)
        }
    }
}

/// The links' names in the spec: the root link is the base, and a link named "base" that is not
/// the root is renamed.
struct Names {
    root: Option<String>,
    alias: Option<String>,
}

impl Names {
    /// A link named "base" that is not the root (ROS-Industrial robots have `base_link` as the
    /// root and a `base` frame on a fixed joint) would clash with nocdyn's name for the fixed
    /// world: it is read under another name, with a warning.
    fn new(
        r: &urdf_rs::Robot,
        root: Option<String>,
        links: &Spans<'_, '_>,
        diags: &mut Diagnostics,
    ) -> Self {
        let alias = (root.as_deref() != Some(BASE) && r.links.iter().any(|l| l.name == BASE)).then(|| {
            let mut a = format!("{BASE}_");
            while r.links.iter().any(|l| l.name == a) {
                a.push('_');
            }
            if let Some(i) = r.links.iter().position(|l| l.name == BASE) {
                diags.push(
                    Diagnostic::warning(format!(
                        "link \"{BASE}\" is read as \"{a}\": \"{BASE}\" names the fixed world (here the root link \"{}\")",
                        root.as_deref().unwrap_or("?")
                    ))
                    .with_key(format!("link \"{BASE}\""))
                    .with_span(links.name(i))
                    .with_hint(format!(
                        "in a scene, \"{BASE}\" (a frame, a payload's body, …) is this link, and \"{}\" the fixed world",
                        root.as_deref().unwrap_or("?")
                    )),
                );
            }
            a
        });
        Names { root, alias }
    }

    /// The spec's name of link `n`.
    fn rename(&self, n: &str) -> String {
        match &self.alias {
            Some(a) if n == BASE => a.clone(),
            _ => n.to_owned(),
        }
    }

    /// The spec's name of link `l` as a joint's end: the root is the base.
    fn end(&self, l: &str) -> String {
        if Some(l) == self.root.as_deref() {
            BASE.to_owned()
        } else {
            self.rename(l)
        }
    }
}

/// Every link but the root, as a body: its inertia rotated into the link frame.
fn bodies(r: &urdf_rs::Robot, names: &Names, links: &Spans<'_, '_>) -> Vec<BodySpec> {
    r.links
        .iter()
        .enumerate()
        .filter(|(_, l)| Some(&l.name) != names.root.as_ref())
        .map(|(i, l)| {
            let inl = &l.inertial;
            let it = &inl.inertia;
            let i_in = [
                [it.ixx, it.ixy, it.ixz],
                [it.ixy, it.iyy, it.iyz],
                [it.ixz, it.iyz, it.izz],
            ];
            BodySpec {
                name: names.rename(&l.name),
                key: format!("link \"{}\"", l.name),
                span: links.name(i),
                mass: inl.mass.value,
                mass_span: links
                    .attr(i, &["inertial", "mass"], "value")
                    .or_else(|| links.name(i)),
                com: inl.origin.xyz.0,
                inertia: rotate_inertia(&rpy_to_matrix(inl.origin.rpy.0), &i_in),
                inertia_span: links
                    .tag(i, &["inertial", "inertia"])
                    .or_else(|| links.name(i)),
                own_inertia: None,
                own_frame: Transform::IDENTITY,
            }
        })
        .collect()
}

/// The joints in document order (an unsupported type, which the precheck rejects, is an
/// error all the same).
fn joints(
    r: &urdf_rs::Robot,
    names: &Names,
    spans: &Spans<'_, '_>,
    diags: &mut Diagnostics,
) -> Option<Vec<JointSpec>> {
    let mut joints: Vec<JointSpec> = Vec::new();
    for (i, j) in r.joints.iter().enumerate() {
        let kind = match j.joint_type {
            urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => Kind::Revolute,
            urdf_rs::JointType::Prismatic => Kind::Prismatic,
            urdf_rs::JointType::Fixed => Kind::Fixed,
            _ => {
                // The precheck rejects the others; keep a message in case the two disagree.
                diags.push(
                    Diagnostic::error(format!("joint \"{}\": unsupported joint type", j.name))
                        .with_span(spans.name(i)),
                );
                return None;
            }
        };
        joints.push(joint(j, i, kind, names, spans));
    }
    Some(joints)
}

/// Joint `j` (entry `i`) of kind `kind`.
fn joint(
    j: &urdf_rs::Joint,
    i: usize,
    kind: Kind,
    names: &Names,
    spans: &Spans<'_, '_>,
) -> JointSpec {
    let key = format!("joint \"{}\"", j.name);
    let axes = if kind == Kind::Fixed {
        Vec::new()
    } else {
        vec![AxisSpec {
            v: j.axis.xyz.0,
            key: format!("{key}.axis"),
            span: spans.attr(i, &["axis"], "xyz").or_else(|| spans.name(i)),
        }]
    };
    JointSpec {
        name: j.name.clone(),
        key,
        span: spans.name(i),
        kind,
        kind_span: spans.attr(i, &[], "type").or_else(|| spans.name(i)),
        parent: names.end(&j.parent.link),
        parent_span: spans.attr(i, &["parent"], "link"),
        child: names.rename(&j.child.link),
        child_span: spans.attr(i, &["child"], "link"),
        placement: Placement::Origin(Transform::from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0)),
        axes,
        actuated: false,
        actuated_span: None,
        child_origin: None,
        child_origin_span: None,
        home: 0.0,
        home_span: None,
        // `<dynamics damping friction>`: applied only when a scene turns friction on (a URDF
        // has no scene, so never from the file alone). Negative values are not friction.
        drive: DriveSpec {
            damping: j.dynamics.as_ref().map_or(0.0, |d| d.damping.max(0.0)),
            friction: j.dynamics.as_ref().map_or(0.0, |d| d.friction.max(0.0)),
            armature: 0.0,
        },
        cross: None,
        limit: match j.joint_type {
            urdf_rs::JointType::Revolute | urdf_rs::JointType::Prismatic => limit(spans, i),
            _ => None,
        },
    }
}

/// Entry `i`'s `<limit lower upper velocity>`, read from the tag as written: a range when
/// `lower` and `upper` are both written, within ±1e9 and `lower < upper` (URDF's defaults of 0 make
/// none), with `velocity` when it is positive and within ±1e9. Anything else is no limit: the
/// tools then use their own bounds (`codegen excite` says which on standard error).
fn limit(spans: &Spans<'_, '_>, i: usize) -> Option<LimitSpec> {
    let t = &spans.doc.tags[spans.doc.descend(*spans.list.get(i)?, &["limit"])?];
    let num = |a: &str| {
        t.attr(a)
            .and_then(|a| a.value.trim().parse::<f64>().ok())
            .filter(|x| super::in_range(*x))
    };
    let (lower, upper) = (num("lower")?, num("upper")?);
    (lower < upper).then(|| LimitSpec {
        lower,
        upper,
        velocity: num("velocity").filter(|v| *v > 0.0),
        span: Some(t.span.clone()),
    })
}

/// `joints` in depth-first order from the root, children in document order; unreachable joints
/// last (the topology check reports them).
fn depth_first(joints: Vec<JointSpec>) -> Vec<JointSpec> {
    let mut order = Vec::with_capacity(joints.len());
    let mut done = vec![false; joints.len()];
    let mut stack: Vec<usize> = (0..joints.len())
        .filter(|&k| joints[k].parent == BASE)
        .rev()
        .collect();
    while let Some(ji) = stack.pop() {
        if std::mem::replace(&mut done[ji], true) {
            continue;
        }
        order.push(ji);
        let c = &joints[ji].child;
        let kids: Vec<usize> = (0..joints.len())
            .filter(|&k| !done[k] && joints[k].parent == *c)
            .collect();
        stack.extend(kids.into_iter().rev());
    }
    order.extend((0..joints.len()).filter(|&k| !done[k]));
    let mut slots: Vec<Option<JointSpec>> = joints.into_iter().map(Some).collect();
    order.into_iter().filter_map(|k| slots[k].take()).collect()
}
