//! The URDF reader (feature `urdf`).
//!
//! `urdf-rs` parses the structure but gives no source positions, and it silently skips
//! malformed numbers inside vectors (`xyz="0 x 1 1"` reads as `[0, 1, 1]`). So a small tag
//! scanner runs first: it checks nesting, the joint types, `<mimic>`, and every number that
//! reaches the model, reporting each problem at its `line:column`; it also gives the spans that
//! the later (format-neutral) checks point at. Numbers are parsed with Rust's correctly rounded
//! `str::parse::<f64>`, by urdf-rs and by the scanner alike, so values are kept exactly as
//! written (`1.570796325` stays `1.570796325`).

use std::ops::Range;

use runtime::model::{Transform, rpy_to_matrix};

use super::geom::rotate_inertia;
use super::ir::{AxisSpec, BASE, BodySpec, DriveSpec, JointSpec, Kind, Placement, Span, Spec};
use super::{sanitize_name, suggest_hint};
use crate::diag::{Diagnostic, Diagnostics};

/// One XML attribute: name, raw value and the value's span (inside the quotes).
#[derive(Clone, Debug)]
struct Attr<'s> {
    name: &'s str,
    value: &'s str,
    span: Range<usize>,
}

/// The source with the elements nocdyn ignores blanked out — `<visual>`, `<collision>`,
/// top-level `<material>`, `<gazebo>`, `<transmission>` — so that urdf-rs does not reject a file
/// for them (e.g. a `<texture/>` without `filename`, as in iCub's URDF). Blanks keep every byte
/// offset and line, so spans into the source stay right.
fn strip_ignored(source: &str, doc: &Doc<'_>) -> String {
    let mut out = source.as_bytes().to_vec();
    for t in &doc.tags {
        let top = t.parent == Some(doc.robot);
        let ignored = matches!(t.name, "visual" | "collision")
            || (top && matches!(t.name, "material" | "gazebo" | "transmission"));
        if !ignored {
            continue;
        }
        let start = t.span.start;
        let self_closing = source[t.span.clone()].ends_with("/>");
        let end = if self_closing {
            t.span.end
        } else {
            let close = format!("</{}", t.name);
            match source[t.span.end..].find(&close) {
                Some(k) => match source[t.span.end + k..].find('>') {
                    Some(g) => t.span.end + k + g + 1,
                    None => continue,
                },
                None => continue,
            }
        };
        for b in &mut out[start..end] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
    }
    // Only ASCII bytes were replaced, by ASCII spaces, inside whole elements: still UTF-8.
    String::from_utf8(out).unwrap_or_else(|_| source.to_owned())
}

/// One start (or empty-element) tag.
#[derive(Clone, Debug)]
struct Tag<'s> {
    name: &'s str,
    /// The whole `<…>`.
    span: Range<usize>,
    attrs: Vec<Attr<'s>>,
    /// Index of the enclosing element's tag.
    parent: Option<usize>,
}

impl<'s> Tag<'s> {
    fn attr(&self, name: &str) -> Option<&Attr<'s>> {
        self.attrs.iter().find(|a| a.name == name)
    }
    /// Span of the element's name attribute value, else of the tag.
    fn name_span(&self) -> Range<usize> {
        self.attr("name")
            .map_or(self.span.clone(), |a| a.span.clone())
    }
}

/// The deepest element nesting read (`<robot>` is level 1). URDF needs six levels or so; the
/// XML reader behind urdf-rs recurses once per level and overflows its stack at a few
/// thousand.
pub(crate) const MAX_XML_DEPTH: usize = 64;

/// An error at the first character of `src[from..to]` that is not white space (a BOM at the
/// very start counts as white space), if any: the text lies outside the root element.
fn text_outside_root(src: &str, from: usize, to: usize) -> Option<Diagnostic> {
    let text = &src[from..to];
    let (k, c) = text
        .char_indices()
        .find(|&(k, c)| !(c.is_ascii_whitespace() || (c == '\u{feff}' && from + k == 0)))?;
    Some(
        Diagnostic::error("XML: text outside the root element")
            .with_span(from + k..from + k + c.len_utf8())
            .with_hint(
                "a URDF file is one <robot> element, with only comments and white space around it",
            ),
    )
}

/// A tolerant scanner of start tags with nesting. Reports unbalanced or malformed tags, text
/// outside the root element, a second root element and nesting deeper than [`MAX_XML_DEPTH`]
/// (then stops: what follows would be noise). Iterative: any depth of input is safe here.
fn scan<'s>(src: &'s str, diags: &mut Diagnostics) -> Vec<Tag<'s>> {
    let b = src.as_bytes();
    let mut tags: Vec<Tag<'s>> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let mut root_seen = false;
    let mut i = 0;
    let find = |from: usize, pat: &str| src.get(from..).and_then(|s| s.find(pat)).map(|p| from + p);
    let is_name = |c: u8| !(c.is_ascii_whitespace() || c == b'/' || c == b'>' || c == b'=');
    let skip_ws = |mut j: usize| {
        while j < b.len() && b[j].is_ascii_whitespace() {
            j += 1;
        }
        j
    };
    while let Some(lt) = find(i, "<") {
        if stack.is_empty()
            && let Some(d) = text_outside_root(src, i, lt)
        {
            diags.push(d);
            return tags;
        }
        let rest = &src[lt..];
        let skip_to = |pat: &str| find(lt, pat).map(|p| p + pat.len());
        let next = if rest.starts_with("<!--") {
            skip_to("-->")
        } else if rest.starts_with("<![CDATA[") {
            skip_to("]]>")
        } else if rest.starts_with("<?") {
            skip_to("?>")
        } else if rest.starts_with("<!") {
            skip_to(">")
        } else if rest.starts_with("</") {
            let end = find(lt, ">");
            if let Some(end) = end {
                let name = src[lt + 2..end].trim();
                match stack.pop() {
                    Some(open) if tags[open].name == name => {}
                    Some(open) => {
                        diags.push(
                            Diagnostic::error(format!(
                                "XML: closing tag </{name}> does not match <{}>",
                                tags[open].name
                            ))
                            .with_span(lt..end + 1)
                            .with_hint(format!(
                                "<{}> opened {} is not closed",
                                tags[open].name,
                                line_col(src, tags[open].span.start)
                            )),
                        );
                        return tags;
                    }
                    None => {
                        diags.push(
                            Diagnostic::error(format!("XML: unexpected closing tag </{name}>"))
                                .with_span(lt..end + 1),
                        );
                        return tags;
                    }
                }
            }
            end.map(|e| e + 1)
        } else {
            // Start tag.
            let mut j = lt + 1;
            while j < b.len() && is_name(b[j]) {
                j += 1;
            }
            let name = &src[lt + 1..j];
            let mut attrs = Vec::new();
            let mut self_closing = false;
            let mut end = None;
            loop {
                j = skip_ws(j);
                if j >= b.len() {
                    break;
                }
                if b[j] == b'>' {
                    end = Some(j + 1);
                    break;
                }
                if b[j] == b'/' && b.get(j + 1) == Some(&b'>') {
                    self_closing = true;
                    end = Some(j + 2);
                    break;
                }
                let an = j;
                while j < b.len() && is_name(b[j]) {
                    j += 1;
                }
                let aname = &src[an..j];
                j = skip_ws(j);
                if aname.is_empty() || b.get(j) != Some(&b'=') {
                    break;
                }
                j = skip_ws(j + 1);
                let Some(&q) = b.get(j).filter(|&&q| q == b'"' || q == b'\'') else {
                    break;
                };
                let vs = j + 1;
                let Some(ve) = src[vs..].find(q as char).map(|p| vs + p) else {
                    break;
                };
                attrs.push(Attr {
                    name: aname,
                    value: &src[vs..ve],
                    span: vs..ve,
                });
                j = ve + 1;
            }
            let Some(end) = end.filter(|_| !name.is_empty()) else {
                diags.push(
                    Diagnostic::error(format!("XML: malformed tag <{name}"))
                        .with_span(lt..j.clamp(lt + 1, src.len())),
                );
                return tags;
            };
            if stack.is_empty() && std::mem::replace(&mut root_seen, true) {
                diags.push(
                    Diagnostic::error(format!("XML: a second root element <{name}>"))
                        .with_span(lt..end)
                        .with_hint("a URDF file has one top-level <robot> element"),
                );
                return tags;
            }
            if stack.len() >= MAX_XML_DEPTH {
                diags.push(
                    Diagnostic::error(format!(
                        "XML: <{name}> is nested deeper than {MAX_XML_DEPTH} elements"
                    ))
                    .with_span(lt..end)
                    .with_hint("a URDF robot needs a few levels (robot, link, inertial, origin); is this the right file?"),
                );
                return tags;
            }
            tags.push(Tag {
                name,
                span: lt..end,
                attrs,
                parent: stack.last().copied(),
            });
            if !self_closing {
                stack.push(tags.len() - 1);
            }
            Some(end)
        };
        match next {
            Some(n) => i = n,
            None => {
                diags.push(Diagnostic::error("XML: unterminated markup").with_span(lt..src.len()));
                return tags;
            }
        }
    }
    if let Some(&open) = stack.last() {
        diags.push(
            Diagnostic::error(format!("XML: <{}> is never closed", tags[open].name))
                .with_span(tags[open].span.clone()),
        );
    } else if let Some(d) = text_outside_root(src, i, src.len()) {
        diags.push(d);
    }
    tags
}

/// `line L, column C` of a byte offset.
fn line_col(src: &str, at: usize) -> String {
    let before = src.get(..at).unwrap_or(src);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    format!("at line {line}, column {col}")
}

/// The scanned tags with lookups.
struct Doc<'s> {
    tags: Vec<Tag<'s>>,
    robot: usize,
    /// The children of each tag, in document order (lookups stay linear in the file).
    kids: Vec<Vec<usize>>,
}

impl<'s> Doc<'s> {
    fn new(tags: Vec<Tag<'s>>, robot: usize) -> Self {
        let mut kids = vec![Vec::new(); tags.len()];
        for (i, t) in tags.iter().enumerate() {
            if let Some(p) = t.parent {
                kids[p].push(i);
            }
        }
        Doc { tags, robot, kids }
    }

    /// Direct children of `parent` named `name`.
    fn children(&self, parent: usize, name: &'s str) -> impl Iterator<Item = usize> + '_ {
        self.kids[parent]
            .iter()
            .copied()
            .filter(move |&i| self.tags[i].name == name)
    }
    fn child(&self, parent: usize, name: &'s str) -> Option<usize> {
        self.children(parent, name).next()
    }
    /// Follows `path` down from `from`.
    fn descend(&self, from: usize, path: &[&'s str]) -> Option<usize> {
        path.iter().try_fold(from, |t, p| self.child(t, p))
    }
}

/// Checks a `"x y z"` attribute strictly: three finite numbers.
fn check_triple(attr: &Attr<'_>, key: &str, diags: &mut Diagnostics) {
    let toks: Vec<&str> = attr.value.split_whitespace().collect();
    let bad = toks.iter().find(|t| t.parse::<f64>().is_err());
    let msg = if let Some(t) = bad {
        Some(format!(
            "invalid number {t:?} in {}=\"{}\"",
            attr.name, attr.value
        ))
    } else if toks.len() != 3 {
        Some(format!(
            "expected three numbers in {}=\"{}\", found {}",
            attr.name,
            attr.value,
            toks.len()
        ))
    } else if toks
        .iter()
        .any(|t| !t.parse::<f64>().is_ok_and(f64::is_finite))
    {
        Some(format!(
            "non-finite number in {}=\"{}\"",
            attr.name, attr.value
        ))
    } else if toks
        .iter()
        .any(|t| !t.parse::<f64>().is_ok_and(super::in_range))
    {
        Some(format!(
            "number out of range in {}=\"{}\" (|x| <= 1e9)",
            attr.name, attr.value
        ))
    } else {
        None
    };
    if let Some(m) = msg {
        let hint = if m.contains("out of range") {
            super::RANGE_HINT
        } else {
            "write three finite numbers separated by spaces, e.g. \"0 0 1\""
        };
        diags.push(
            Diagnostic::error(m)
                .with_key(key)
                .with_span(attr.span.clone())
                .with_hint(hint),
        );
    }
}

/// Checks a single-number attribute strictly.
fn check_number(attr: &Attr<'_>, key: &str, diags: &mut Diagnostics) {
    match attr.value.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && super::in_range(x) => {}
        Ok(x) if x.is_finite() => diags.push(
            Diagnostic::error(format!(
                "value out of range {}=\"{}\"",
                attr.name, attr.value
            ))
            .with_key(key)
            .with_span(attr.span.clone())
            .with_hint(super::RANGE_HINT),
        ),
        Ok(_) => diags.push(
            Diagnostic::error(format!("non-finite value {}=\"{}\"", attr.name, attr.value))
                .with_key(key)
                .with_span(attr.span.clone())
                .with_hint("every value must be a finite number"),
        ),
        Err(_) => diags.push(
            Diagnostic::error(format!("invalid number {}=\"{}\"", attr.name, attr.value))
                .with_key(key)
                .with_span(attr.span.clone())
                .with_hint(
                    "write a plain number such as 1.5 (decimal point, no units or expressions)",
                ),
        ),
    }
}

/// Everything urdf-rs would reject or misread, reported with spans. Returns the top-level
/// `<link>` and `<joint>` tags in document order.
fn precheck(doc: &Doc<'_>, diags: &mut Diagnostics) -> (Vec<usize>, Vec<usize>) {
    let links: Vec<usize> = doc.children(doc.robot, "link").collect();
    let joints: Vec<usize> = doc.children(doc.robot, "joint").collect();
    for &t in [doc.robot].iter().chain(&links).chain(&joints) {
        if let Some(a) = doc.tags[t].attr("name")
            && let Some(d) = super::name_too_long(a.value)
        {
            let what = doc.tags[t].name;
            diags.push(d.with_key(format!("{what}.name")).with_span(a.span.clone()));
        }
    }
    for &l in &links {
        let t = &doc.tags[l];
        let lk = format!("link \"{}\"", t.attr("name").map_or("", |a| a.value));
        if t.attr("name").is_none() {
            diags.push(Diagnostic::error("<link> without a name").with_span(t.span.clone()));
        }
        let Some(inl) = doc.child(l, "inertial") else {
            continue;
        };
        if let Some(o) = doc.child(inl, "origin") {
            for a in ["xyz", "rpy"] {
                if let Some(at) = doc.tags[o].attr(a) {
                    check_triple(at, &format!("{lk}.inertial.origin.{a}"), diags);
                }
            }
        }
        match doc.child(inl, "mass") {
            None => diags.push(
                Diagnostic::error("<inertial> without <mass>")
                    .with_key(format!("{lk}.inertial"))
                    .with_span(doc.tags[inl].span.clone())
                    .with_hint(
                        "add <mass value=\"...\"/> (kg), or remove <inertial> for a massless link",
                    ),
            ),
            Some(m) => match doc.tags[m].attr("value") {
                Some(v) => check_number(v, &format!("{lk}.inertial.mass"), diags),
                None => diags.push(
                    Diagnostic::error("<mass> without value")
                        .with_key(format!("{lk}.inertial.mass"))
                        .with_span(doc.tags[m].span.clone()),
                ),
            },
        }
        match doc.child(inl, "inertia") {
            None => diags.push(
                Diagnostic::error("<inertial> without <inertia>")
                    .with_key(format!("{lk}.inertial"))
                    .with_span(doc.tags[inl].span.clone())
                    .with_hint(
                        "add <inertia ixx=\"..\" ixy=\"..\" ixz=\"..\" iyy=\"..\" iyz=\"..\" izz=\"..\"/> (kg·m²)",
                    ),
            ),
            Some(it) => {
                for a in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"] {
                    let key = format!("{lk}.inertial.inertia.{a}");
                    match doc.tags[it].attr(a) {
                        Some(v) => check_number(v, &key, diags),
                        None => diags.push(
                            Diagnostic::error(format!("<inertia> without {a}"))
                                .with_key(key)
                                .with_span(doc.tags[it].span.clone())
                                .with_hint(
                                    "URDF requires all six of ixx, ixy, ixz, iyy, iyz, izz",
                                ),
                        ),
                    }
                }
            }
        }
    }
    for &j in &joints {
        let t = &doc.tags[j];
        let name = t.attr("name").map_or("", |a| a.value);
        let jk = format!("joint \"{name}\"");
        if t.attr("name").is_none() {
            diags.push(Diagnostic::error("<joint> without a name").with_span(t.span.clone()));
        }
        match t.attr("type") {
            None => diags.push(
                Diagnostic::error(format!("joint \"{name}\" has no type"))
                    .with_key(format!("{jk}.type"))
                    .with_span(t.span.clone()),
            ),
            Some(ty) => match ty.value {
                "revolute" | "continuous" | "prismatic" | "fixed" => {}
                "floating" | "planar" => diags.push(
                    Diagnostic::error(format!(
                        "joint \"{name}\": {} joints are not supported",
                        ty.value
                    ))
                    .with_key(format!("{jk}.type"))
                    .with_span(ty.span.clone())
                    .with_hint(
                        "the base is fixed; model a free or planar base as a chain of prismatic and revolute joints with massless links",
                    ),
                ),
                other => {
                    const ALL: &[&str] = &["revolute", "continuous", "prismatic", "fixed"];
                    diags.push(
                        Diagnostic::error(format!(
                            "joint \"{name}\": unsupported joint type {other:?}"
                        ))
                        .with_key(format!("{jk}.type"))
                        .with_span(ty.span.clone())
                        .with_hint(suggest_hint(other, ALL).unwrap_or_else(|| {
                            "the URDF joint types read here are revolute, continuous, prismatic and fixed".into()
                        })),
                    )
                }
            },
        }
        if let Some(m) = doc.child(j, "mimic") {
            let of = doc.tags[m].attr("joint").map_or("?", |a| a.value);
            // Read as an independent joint, as Pinocchio's URDF parser does by default (so the
            // coordinates match), with a warning: the coupling is not modelled.
            diags.push(
                Diagnostic::warning(format!(
                    "joint \"{name}\" mimics \"{of}\": read as an independent joint"
                ))
                .with_key(format!("{jk}.mimic"))
                .with_span(doc.tags[m].span.clone())
                .with_hint(
                    "the coupling q = multiplier·q_other + offset is not modelled: the joint has its own coordinate (as in Pinocchio's default reading); lock it with [scene] locked in a TOML spec, or drive it yourself",
                ),
            );
        }
        for (tag, attrs) in [("origin", &["xyz", "rpy"][..]), ("axis", &["xyz"][..])] {
            if let Some(o) = doc.child(j, tag) {
                for a in attrs {
                    if let Some(at) = doc.tags[o].attr(a) {
                        check_triple(at, &format!("{jk}.{tag}.{a}"), diags);
                    }
                }
            }
        }
        for end in ["parent", "child"] {
            match doc.child(j, end).map(|e| &doc.tags[e]) {
                Some(e) if e.attr("link").is_some() => {}
                Some(e) => diags.push(
                    Diagnostic::error(format!("<{end}> without link"))
                        .with_key(format!("{jk}.{end}"))
                        .with_span(e.span.clone()),
                ),
                None => diags.push(
                    Diagnostic::error(format!("joint \"{name}\" has no <{end}>"))
                        .with_key(format!("{jk}.{end}"))
                        .with_span(t.span.clone()),
                ),
            }
        }
    }
    (links, joints)
}

/// Reads a URDF document.
pub(crate) fn read(source: &str, diags: &mut Diagnostics) -> Option<Spec> {
    let tags = scan(source, diags);
    if diags.has_errors() {
        return None;
    }
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
    // The size limit, before anything quadratic in the number of links and joints.
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
    if diags.has_errors() {
        return None;
    }
    let doc = Doc::new(tags, robot);
    let (link_tags, joint_tags) = precheck(&doc, diags);
    if diags.has_errors() {
        return None;
    }
    let robot_span = doc.tags[robot].name_span();
    let stripped = strip_ignored(source, &doc);
    let r = match urdf_rs::read_from_string(&stripped) {
        Ok(r) => r,
        Err(e) => {
            diags.push(
                Diagnostic::error(format!("URDF: {e}"))
                    .with_span(robot_span)
                    .with_hint("the URDF reader (urdf-rs) rejected the file"),
            );
            return None;
        }
    };
    // urdf-rs keeps the top-level links and joints in document order, as the scanner does.
    let name_span =
        |list: &[usize], i: usize| -> Span { list.get(i).map(|&t| doc.tags[t].name_span()) };
    let attr_span = |list: &[usize], i: usize, path: &[&'static str], attr: &str| -> Span {
        let t = &doc.tags[doc.descend(*list.get(i)?, path)?];
        Some(t.attr(attr).map_or(t.span.clone(), |a| a.span.clone()))
    };
    let tag_span = |list: &[usize], i: usize, path: &[&'static str]| -> Span {
        Some(doc.tags[doc.descend(*list.get(i)?, path)?].span.clone())
    };

    // The root link: the one link that no joint has as child.
    let is_child = |n: &str| r.joints.iter().any(|j| j.child.link == n);
    let roots: Vec<usize> = (0..r.links.len())
        .filter(|&i| !is_child(&r.links[i].name))
        .collect();
    let root = match roots.as_slice() {
        [one] => Some(r.links[*one].name.clone()),
        [] if r.links.is_empty() => {
            diags.push(
                Diagnostic::error("the robot has no links").with_span(doc.tags[robot].span.clone()),
            );
            return None;
        }
        [] => None, // a cycle; the topology check reports it
        [first, rest @ ..] => {
            for &i in rest {
                diags.push(
                    Diagnostic::error(format!(
                        "link \"{}\" is not connected to the root link \"{}\"",
                        r.links[i].name, r.links[*first].name
                    ))
                    .with_key(format!("link \"{}\"", r.links[i].name))
                    .with_span(name_span(&link_tags, i))
                    .with_hint(
                        "a URDF robot is one tree: every link except the root is the child of a joint",
                    ),
                );
            }
            return None;
        }
    };

    // A link named "base" that is not the root (ROS-Industrial robots have `base_link` as the
    // root and a `base` frame on a fixed joint) would clash with nocdyn's name for the fixed
    // world: it is read under another name, with a warning.
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
                .with_span(name_span(&link_tags, i)),
            );
        }
        a
    });
    let rename = |n: &str| -> String {
        match &alias {
            Some(a) if n == BASE => a.clone(),
            _ => n.to_owned(),
        }
    };
    let bodies: Vec<BodySpec> = r
        .links
        .iter()
        .enumerate()
        .filter(|(_, l)| Some(&l.name) != root.as_ref())
        .map(|(i, l)| {
            let inl = &l.inertial;
            let it = &inl.inertia;
            let i_in = [
                [it.ixx, it.ixy, it.ixz],
                [it.ixy, it.iyy, it.iyz],
                [it.ixz, it.iyz, it.izz],
            ];
            BodySpec {
                name: rename(&l.name),
                key: format!("link \"{}\"", l.name),
                span: name_span(&link_tags, i),
                mass: inl.mass.value,
                mass_span: attr_span(&link_tags, i, &["inertial", "mass"], "value")
                    .or_else(|| name_span(&link_tags, i)),
                com: inl.origin.xyz.0,
                inertia: rotate_inertia(&rpy_to_matrix(inl.origin.rpy.0), &i_in),
                inertia_span: tag_span(&link_tags, i, &["inertial", "inertia"])
                    .or_else(|| name_span(&link_tags, i)),
            }
        })
        .collect();

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
                        .with_span(name_span(&joint_tags, i)),
                );
                return None;
            }
        };
        let key = format!("joint \"{}\"", j.name);
        let axes = if kind == Kind::Fixed {
            Vec::new()
        } else {
            vec![AxisSpec {
                v: j.axis.xyz.0,
                key: format!("{key}.axis"),
                span: attr_span(&joint_tags, i, &["axis"], "xyz")
                    .or_else(|| name_span(&joint_tags, i)),
            }]
        };
        let end = |l: &str| {
            if Some(l) == root.as_deref() {
                BASE.to_owned()
            } else {
                rename(l)
            }
        };
        joints.push(JointSpec {
            name: j.name.clone(),
            key,
            span: name_span(&joint_tags, i),
            kind,
            kind_span: attr_span(&joint_tags, i, &[], "type").or_else(|| name_span(&joint_tags, i)),
            parent: end(&j.parent.link),
            parent_span: attr_span(&joint_tags, i, &["parent"], "link"),
            child: rename(&j.child.link),
            child_span: attr_span(&joint_tags, i, &["child"], "link"),
            placement: Placement::Origin(Transform::from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0)),
            axes,
            actuated: false,
            actuated_span: None,
            child_origin: None,
            child_origin_span: None,
            // `<dynamics damping friction>`: applied only when a scene turns friction on (a URDF
            // has no scene, so never from the file alone). Negative values are not friction.
            drive: DriveSpec {
                damping: j.dynamics.as_ref().map_or(0.0, |d| d.damping.max(0.0)),
                friction: j.dynamics.as_ref().map_or(0.0, |d| d.friction.max(0.0)),
                armature: 0.0,
            },
        });
    }

    // Depth-first order from the root, children in document order; unreachable joints last
    // (the topology check reports them).
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
    let joints = order.into_iter().filter_map(|k| slots[k].take()).collect();

    Some(Spec {
        name: sanitize_name(&r.name),
        gravity: [0.0, 0.0, -9.81],
        bodies,
        joints,
        anchor: Some(robot_span),
        joints_incomplete: false,
        platform: None,
        scene: Default::default(),
        springs: Vec::new(),
    })
}
