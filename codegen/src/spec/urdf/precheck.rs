//! The checks before urdf-rs reads the file: everything it would reject or misread (names,
//! numbers, required elements and attributes, joint types, `<mimic>`), each reported at its
//! span.

use super::xml::{Attr, Doc};
use crate::diag::{Diagnostic, Diagnostics};
use crate::spec::suggest_hint;

/// Everything urdf-rs would reject or misread, reported with spans. Returns the top-level
/// `<link>` and `<joint>` tags in document order.
pub(super) fn precheck(doc: &Doc<'_>, diags: &mut Diagnostics) -> (Vec<usize>, Vec<usize>) {
    let links: Vec<usize> = doc.children(doc.robot, "link").collect();
    let joints: Vec<usize> = doc.children(doc.robot, "joint").collect();
    check_names(doc, &links, &joints, diags);
    for &l in &links {
        check_link(doc, l, diags);
        check_once(doc, l, &["inertial"], diags);
        if let Some(inl) = doc.child(l, "inertial") {
            check_once(doc, inl, &["origin", "mass", "inertia"], diags);
        }
    }
    for &j in &joints {
        check_joint(doc, j, diags);
        check_once(
            doc,
            j,
            &["parent", "child", "origin", "axis", "dynamics", "mimic"],
            diags,
        );
    }
    check_ends(doc, &links, &joints, diags);
    (links, joints)
}

/// Each joint's `<parent link>` and `<child link>` name a link of the file: a typo is an error
/// at the attribute, with the closest name (it was reported as the intended link "not
/// connected to the root link", pointing away from the typo, when that link was in the file).
fn check_ends(doc: &Doc<'_>, links: &[usize], joints: &[usize], diags: &mut Diagnostics) {
    let names: Vec<&str> = links
        .iter()
        .filter_map(|&l| doc.tags[l].attr("name").map(|a| a.value))
        .collect();
    for &j in joints {
        let name = doc.tags[j].attr("name").map_or("", |a| a.value);
        for end in ["parent", "child"] {
            let Some(a) = doc.child(j, end).and_then(|e| doc.tags[e].attr("link")) else {
                continue;
            };
            if names.contains(&a.value) {
                continue;
            }
            // Worded as the loader's check of a TOML joint's ends, which a URDF reaches only
            // when no link is left disconnected.
            diags.push(
                Diagnostic::error(format!("unknown {end} body \"{}\"", a.value))
                    .with_key(format!("joint \"{name}\".{end}"))
                    .with_span(a.span.clone())
                    .with_hint(
                        suggest_hint(a.value, &names)
                            .unwrap_or_else(|| format!("the {end} must be the name of a body")),
                    ),
            );
        }
    }
}

/// The name lengths of `<robot>`, then of the links, then of the joints.
fn check_names(doc: &Doc<'_>, links: &[usize], joints: &[usize], diags: &mut Diagnostics) {
    for &t in [doc.robot].iter().chain(links).chain(joints) {
        if let Some(a) = doc.tags[t].attr("name")
            && let Some(d) = crate::spec::name_too_long(a.value)
        {
            let what = doc.tags[t].name;
            diags.push(d.with_key(format!("{what}.name")).with_span(a.span.clone()));
        }
    }
}

/// A `<link>`: its name, and its `<inertial>` (origin, mass, inertia) if it has one.
fn check_link(doc: &Doc<'_>, l: usize, diags: &mut Diagnostics) {
    let t = &doc.tags[l];
    let lk = format!("link \"{}\"", t.attr("name").map_or("", |a| a.value));
    if t.attr("name").is_none() {
        diags.push(Diagnostic::error("<link> without a name").with_span(t.span.clone()));
    }
    let Some(inl) = doc.child(l, "inertial") else {
        return;
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
    check_inertia(doc, inl, &lk, diags);
}

/// The `<inertia>` of the `<inertial>` `inl` of link `lk`: present, with six numbers.
fn check_inertia(doc: &Doc<'_>, inl: usize, lk: &str, diags: &mut Diagnostics) {
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

/// A `<joint>`: its name, type, `<mimic>`, the numbers of its origin, axis and `<dynamics>`,
/// and its ends.
fn check_joint(doc: &Doc<'_>, j: usize, diags: &mut Diagnostics) {
    let t = &doc.tags[j];
    let name = t.attr("name").map_or("", |a| a.value);
    let jk = format!("joint \"{name}\"");
    if t.attr("name").is_none() {
        diags.push(Diagnostic::error("<joint> without a name").with_span(t.span.clone()));
    }
    check_joint_type(doc, j, name, &jk, diags);
    if let Some(m) = doc.child(j, "mimic") {
        let of = doc.tags[m].attr("joint").map_or("?", |a| a.value);
        // urdf-rs reads the `<mimic>` (for `codegen convert`'s comment): its numbers and its
        // `joint` are checked here, at their place, rather than by urdf-rs at `<robot>`.
        if doc.tags[m].attr("joint").is_none() {
            diags.push(
                Diagnostic::error("<mimic> without joint")
                    .with_key(format!("{jk}.mimic"))
                    .with_span(doc.tags[m].span.clone())
                    .with_hint("name the joint it follows: <mimic joint=\"…\"/>"),
            );
        }
        for a in ["multiplier", "offset"] {
            if let Some(at) = doc.tags[m].attr(a) {
                check_number(at, &format!("{jk}.mimic.{a}"), diags);
            }
        }
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
    if let Some(a) = doc.child(j, "axis")
        && doc.tags[a].attr("xyz").is_none()
    {
        diags.push(
            Diagnostic::error("<axis> without xyz")
                .with_key(format!("{jk}.axis"))
                .with_span(doc.tags[a].span.clone())
                .with_hint("write the axis as <axis xyz=\"x y z\"/>, or leave <axis> out for the default 1 0 0"),
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
    // `<dynamics damping friction>`: one number each, finite and within range like every
    // other number (non-finite values were read as 0 or reached the generator, which panicked
    // on an infinite constant; a word was reported at the `<robot>` tag).
    if let Some(d) = doc.child(j, "dynamics") {
        for a in ["damping", "friction"] {
            if let Some(at) = doc.tags[d].attr(a) {
                let key = format!("{jk}.dynamics.{a}");
                check_number(at, &key, diags);
                // A negative coefficient would feed energy in: it is read as 0, and said so.
                if at.value.trim().parse::<f64>().is_ok_and(|x| x < 0.0) {
                    diags.push(
                        Diagnostic::warning(format!("negative {a}=\"{}\" is read as 0", at.value))
                            .with_key(key)
                            .with_span(at.span.clone())
                            .with_hint("friction only dissipates: write 0 or a positive value"),
                    );
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

/// The `type` of joint `j` (`name`, key `jk`): one of the kinds read here.
fn check_joint_type(doc: &Doc<'_>, j: usize, name: &str, jk: &str, diags: &mut Diagnostics) {
    let t = &doc.tags[j];
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
        .any(|t| !t.parse::<f64>().is_ok_and(crate::spec::in_range))
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
            crate::spec::RANGE_HINT
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
        Ok(x) if x.is_finite() && crate::spec::in_range(x) => {}
        Ok(x) if x.is_finite() => diags.push(
            Diagnostic::error(format!(
                "value out of range {}=\"{}\"",
                attr.name, attr.value
            ))
            .with_key(key)
            .with_span(attr.span.clone())
            .with_hint(crate::spec::RANGE_HINT),
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

/// The elements urdf-rs reads at most once under tag `t` (a `<link>`, its `<inertial>`, a
/// `<joint>`): a second one is an error at it (urdf-rs reported "duplicate field" at `<robot>`).
fn check_once(doc: &Doc<'_>, t: usize, names: &[&str], diags: &mut Diagnostics) {
    let tag = &doc.tags[t];
    let owner = match tag.name {
        "inertial" => {
            let link = tag.parent.map(|p| &doc.tags[p]);
            let name = link.and_then(|l| l.attr("name")).map_or("", |a| a.value);
            format!("link \"{name}\".inertial")
        }
        kind => format!("{kind} \"{}\"", tag.attr("name").map_or("", |a| a.value)),
    };
    for name in names {
        for dup in doc.children(t, name).skip(1) {
            diags.push(
                Diagnostic::error(format!("a second <{name}> in <{}>", tag.name))
                    .with_key(format!("{owner}.{name}"))
                    .with_span(doc.tags[dup].span.clone())
                    .with_hint(format!(
                        "a <{}> has one <{name}>: remove or merge this one",
                        tag.name
                    )),
            );
        }
    }
}
