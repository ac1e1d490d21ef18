//! The update of a URDF (docs/identification.md, "The updated spec"): the same minimum-norm
//! change as a TOML spec's, its unknowns the URDF's own numbers, written in place: per link
//! with an `<inertial>` its ten standard parameters in the link frame (of `<mass value>`,
//! `<origin xyz rpy>` and `<inertia …>`: the inertia is written in the `<inertial>` frame, whose
//! `rpy` is kept), per moving joint its `<dynamics damping friction>` (which the loader applies
//! with the scene's `friction`). Only the values that change are replaced (an attribute or an
//! element the text lacks is added); every other byte of the file, comments included, stays.
//! A URDF has no number for a rotor's inertia: with a scene file, its `[scene] armature` entries
//! are unknowns too, written into the scene file that goes beside the URDF ([`super::armature`]).

use std::ops::Range;

use nalgebra::DMatrix;

use runtime::model::Mat3;

use codegen::spec::SceneFile;
use toml_edit::DocumentMut;

use super::armature::{armature, set_armature};
use super::xml_scan::{Tag, children, closing, scan};
use super::{
    Change, REFERENCE, Update, broken, changed_names, from_standard, involved, minimum_norm_change,
};
use crate::cli::regressor::Regressor;

/// A link with an `<inertial>`: the tags that hold its numbers.
struct Link {
    name: String,
    inertial: usize,
    origin: Option<usize>,
    mass: Option<usize>,
    inertia: Option<usize>,
    rpy: [f64; 3],
}

/// A moving joint: its start tag, end tag and `<dynamics>`.
struct Joint {
    name: String,
    close: usize,
    dynamics: Option<usize>,
}

#[derive(Clone, Copy)]
enum Unknown {
    /// Standard parameter `k` of link `link` (index into the links).
    Link { link: usize, k: usize },
    /// `damping` or `friction` of joint `joint`.
    Drive { joint: usize, key: &'static str },
    /// The scene file's `armature` of joint `joint`.
    Armature { joint: usize },
}

/// Whitespace-separated numbers.
fn numbers(s: &str) -> Option<Vec<f64>> {
    s.split_whitespace().map(|x| x.parse().ok()).collect()
}

/// A number as URDF text: the shortest that reads back to the same `f64`, exponent form outside
/// 1e-3 … 1e6.
fn fmt(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-3..1e6).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

fn rotation(rpy: [f64; 3]) -> Mat3 {
    runtime::model::rpy_to_matrix(rpy)
}

/// `R m Rᵀ` (`t` false) or `Rᵀ m R` (`t` true).
fn turn(r: &Mat3, m: &Mat3, t: bool) -> Mat3 {
    let rr = |i: usize, j: usize| if t { r[j][i] } else { r[i][j] };
    std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            (0..3)
                .map(|k| (0..3).map(|l| rr(i, k) * m[k][l] * rr(j, l)).sum::<f64>())
                .sum()
        })
    })
}

const INERTIA: [(&str, (usize, usize)); 6] = [
    ("ixx", (0, 0)),
    ("ixy", (0, 1)),
    ("ixz", (0, 2)),
    ("iyy", (1, 1)),
    ("iyz", (1, 2)),
    ("izz", (2, 2)),
];

/// The links with an `<inertial>` and the moving joints.
fn read(text: &str, tags: &[Tag]) -> (Vec<Link>, Vec<Joint>) {
    let (mut links, mut joints) = (Vec::new(), Vec::new());
    let attr = |t: &Tag, a: &str| t.attr(a).map(|r| text[r].to_string());
    for (k, t) in tags.iter().enumerate() {
        if t.end {
            continue;
        }
        if t.name == "link" {
            let Some(&inertial) = children(tags, k, "inertial").first() else {
                continue;
            };
            let child = |n: &str| children(tags, inertial, n).first().copied();
            let origin = child("origin");
            let rpy = origin
                .and_then(|o| attr(&tags[o], "rpy"))
                .and_then(|s| numbers(&s))
                .and_then(|v| <[f64; 3]>::try_from(v).ok())
                .unwrap_or([0.0; 3]);
            links.push(Link {
                name: attr(t, "name").unwrap_or_default(),
                inertial,
                origin,
                mass: child("mass"),
                inertia: child("inertia"),
                rpy,
            });
        } else if t.name == "joint" && attr(t, "type").is_some_and(|k| k != "fixed") {
            let Some(close) = closing(tags, k) else {
                continue;
            };
            joints.push(Joint {
                name: attr(t, "name").unwrap_or_default(),
                close,
                dynamics: children(tags, k, "dynamics").first().copied(),
            });
        }
    }
    (links, joints)
}

/// A link's standard parameters in its frame, `None` if a number does not read.
fn link_parameters(text: &str, tags: &[Tag], l: &Link) -> Option<[f64; 10]> {
    let get = |tag: Option<usize>, a: &str| -> Option<Vec<f64>> {
        match tag.and_then(|t| tags[t].attr(a)) {
            None => Some(vec![]),
            Some(r) => numbers(&text[r]),
        }
    };
    let mass = get(l.mass, "value")?.first().copied().unwrap_or(0.0);
    let xyz = get(l.origin, "xyz")?;
    let com = if xyz.is_empty() {
        [0.0; 3]
    } else {
        <[f64; 3]>::try_from(xyz).ok()?
    };
    let mut i: Mat3 = [[0.0; 3]; 3];
    for (a, (r, c)) in INERTIA {
        let v = get(l.inertia, a)?.first().copied().unwrap_or(0.0);
        i[r][c] = v;
        i[c][r] = v;
    }
    let ic = turn(&rotation(l.rpy), &i, false);
    Some(codegen::dynamics::body_standard_parameters(mass, &com, &ic))
}

/// Set attribute `a` of tag `t` to the numbers `v` (replaced, or added); an attribute that
/// reads as these numbers already keeps its text (`0.0` stays `0.0`).
fn set_attr(edits: &mut Vec<(Range<usize>, String)>, text: &str, t: &Tag, a: &str, v: &[f64]) {
    let new = v.iter().map(|x| fmt(*x)).collect::<Vec<_>>().join(" ");
    match t.attr(a) {
        Some(r) if numbers(&text[r.clone()]).is_some_and(|old| old == v) => {}
        Some(r) => edits.push((r, new)),
        None => {
            let at = t.attr_insert_at();
            edits.push((at..at, format!(" {a}=\"{new}\"")));
        }
    }
}

/// Insert element text `elem` before end tag `close`: on a line of its own, indented one
/// step deeper than the end tag, when the end tag starts its line.
fn insert_before(edits: &mut Vec<(Range<usize>, String)>, text: &str, close: &Tag, elem: String) {
    let at = close.range.start;
    let line = text[..at].rfind('\n').map_or(0, |k| k + 1);
    let indent = &text[line..at];
    if indent.chars().all(|c| c == ' ' || c == '\t') {
        edits.push((line..line, format!("{indent}  {elem}\n")));
    } else {
        edits.push((at..at, elem));
    }
}

/// The text with `values` (one per unknown) written.
fn apply(
    text: &str,
    tags: &[Tag],
    links: &[Link],
    joints: &[Joint],
    scene: Option<&DocumentMut>,
    unknowns: &[Unknown],
    values: &[f64],
) -> Result<(String, Option<String>), String> {
    let mut bodies: std::collections::BTreeMap<usize, [f64; 10]> = Default::default();
    let mut drives: std::collections::BTreeMap<usize, Vec<(&str, f64)>> = Default::default();
    let mut rotors: Vec<(&str, f64)> = Vec::new();
    for (u, &v) in unknowns.iter().zip(values) {
        match *u {
            Unknown::Link { link, k } => bodies.entry(link).or_insert([0.0; 10])[k] = v,
            Unknown::Drive { joint, key } => drives.entry(joint).or_default().push((key, v)),
            Unknown::Armature { joint } => rotors.push((joints[joint].name.as_str(), v)),
        }
    }
    let scene = match scene {
        Some(doc) => {
            let mut doc = doc.clone();
            set_armature(&mut doc, &rotors)?;
            Some(doc.to_string())
        }
        None => None,
    };
    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    for (link, p) in bodies {
        let l = &links[link];
        let (m, c, ic) = from_standard(&p).map_err(|e| format!("link `{}`: {e}", l.name))?;
        let i = turn(&rotation(l.rpy), &ic, true);
        let close = closing(tags, l.inertial).map(|k| &tags[k]);
        let add = |elem: String, edits: &mut Vec<(Range<usize>, String)>| {
            if let Some(close) = close {
                insert_before(edits, text, close, elem)
            }
        };
        match l.mass {
            Some(t) => set_attr(&mut edits, text, &tags[t], "value", &[m]),
            None => add(format!("<mass value=\"{}\"/>", fmt(m)), &mut edits),
        }
        let xyz = format!("{} {} {}", fmt(c[0]), fmt(c[1]), fmt(c[2]));
        match l.origin {
            Some(t) => set_attr(&mut edits, text, &tags[t], "xyz", &c),
            None => add(format!("<origin xyz=\"{xyz}\" rpy=\"0 0 0\"/>"), &mut edits),
        }
        match l.inertia {
            Some(t) => {
                for (a, (r, c)) in INERTIA {
                    set_attr(&mut edits, text, &tags[t], a, &[i[r][c]]);
                }
            }
            None => {
                let attrs: Vec<String> = INERTIA
                    .iter()
                    .map(|(a, (r, c))| format!("{a}=\"{}\"", fmt(i[*r][*c])))
                    .collect();
                add(format!("<inertia {}/>", attrs.join(" ")), &mut edits);
            }
        }
    }
    for (joint, values) in drives {
        let j = &joints[joint];
        if let Some((key, v)) = values.iter().find(|(_, v)| *v < 0.0) {
            return Err(format!("joint `{}`: {key} {v} < 0", j.name));
        }
        match j.dynamics {
            Some(t) => {
                for (key, v) in values {
                    set_attr(&mut edits, text, &tags[t], key, &[v]);
                }
            }
            None => {
                let attrs: Vec<String> = values
                    .iter()
                    .map(|(key, v)| format!("{key}=\"{}\"", fmt(*v)))
                    .collect();
                let elem = format!("<dynamics {}/>", attrs.join(" "));
                insert_before(&mut edits, text, &tags[j.close], elem);
            }
        }
    }
    // From the end, so that the ranges stay valid; two insertions at one place keep their order.
    edits.sort_by_key(|(r, _)| (r.start, r.end));
    let mut out = text.to_string();
    for (r, v) in edits.into_iter().rev() {
        out.replace_range(r, &v);
    }
    Ok((out, scene))
}

/// The update of URDF `source` (with its scene file `sidecar`) whose model has base parameters
/// `target` where `fit[k]`, as [`super::update`] for a TOML spec.
pub(super) fn update(
    reg: &Regressor,
    file: &str,
    source: &str,
    sidecar: Option<&codegen::spec::SceneFile>,
    target: &[f64],
    fit: &[bool],
) -> Result<Update, String> {
    let tags = scan(source).map_err(|e| format!("error: {file}: {e}"))?;
    let (links, joints) = read(source, &tags);
    let scene: Option<DocumentMut> = match sidecar {
        Some(f) => Some(
            f.text
                .parse()
                .map_err(|e| format!("error: {}: {e}", f.name))?,
        ),
        None => None,
    };
    let (mut unknowns, mut z0, mut names, mut skipped) = (vec![], vec![], vec![], vec![]);
    for (link, l) in links.iter().enumerate() {
        match link_parameters(source, &tags, l) {
            Some(p) => {
                for (k, v) in p.into_iter().enumerate() {
                    unknowns.push(Unknown::Link { link, k });
                    z0.push(v);
                    names.push(format!("link `{}`", l.name));
                }
            }
            None => skipped.push(format!("link `{}`", l.name)),
        }
    }
    for (joint, j) in joints.iter().enumerate() {
        for key in ["damping", "friction"] {
            let v = match j.dynamics.and_then(|t| tags[t].attr(key)) {
                None => Some(0.0),
                Some(r) => source[r].trim().parse().ok(),
            };
            match v {
                Some(v) => {
                    unknowns.push(Unknown::Drive { joint, key });
                    z0.push(v);
                    names.push(format!("joint `{}`", j.name));
                }
                None => skipped.push(format!("joint `{}` ({key})", j.name)),
            }
        }
        if let Some(doc) = &scene {
            match armature(doc, &j.name) {
                Some(v) => {
                    unknowns.push(Unknown::Armature { joint });
                    z0.push(v);
                    names.push(format!("joint `{}`", j.name));
                }
                None => skipped.push(format!("joint `{}` (armature)", j.name)),
            }
        }
    }
    // The base parameters of the URDF text and the scene file's text as written.
    let base = |(text, scene_text): &(String, Option<String>)| {
        let side = sidecar.zip(scene_text.as_ref()).map(|(f, t)| SceneFile {
            name: f.name.clone(),
            text: t.clone(),
        });
        reg.base_of_spec(file, text, side.as_ref())
    };
    let write = |z: &[f64]| apply(source, &tags, &links, &joints, scene.as_ref(), &unknowns, z);
    let pi0 = base(&write(&z0)?)?;
    let pi_spec = reg.base_of_spec(file, source, sidecar)?;
    let drift = crate::cli::identify::rounding_mismatch(&pi0, &pi_spec);
    if drift > 1e-9 {
        return Err(format!(
            "error: {file}: its links written back as numbers change its base parameters ({drift:.2e} relative): --out cannot rewrite this URDF (no file written)"
        ));
    }
    let reference: Vec<f64> = unknowns
        .iter()
        .zip(&z0)
        .map(|(u, v)| match u {
            Unknown::Link { k, .. } => REFERENCE[*k],
            Unknown::Drive { .. } | Unknown::Armature { .. } => *v,
        })
        .collect();
    let Change {
        p,
        z,
        dz,
        unreachable,
    } = minimum_norm_change(
        reg.nbp(),
        &z0,
        &reference,
        &pi0,
        target,
        fit,
        &vec![false; z0.len()],
        &mut |z| base(&write(z)?),
    )?;
    let changed = changed_names(&names, &dz);
    let touched: Vec<usize> = (0..unknowns.len())
        .filter(|&c| changed.contains(&names[c]))
        .collect();
    let sub_u: Vec<Unknown> = touched.iter().map(|&c| unknowns[c]).collect();
    let sub_z: Vec<f64> = touched.iter().map(|&c| z[c]).collect();
    let out = apply(source, &tags, &links, &joints, scene.as_ref(), &sub_u, &sub_z).map_err(|e| {
        format!("error: --out: the identified parameters are no URDF: {e} (the base parameters are printed above; no file written)")
    })?;
    let written = base(&out)?;
    let (text, scene) = out;
    let violations = consistency(&links, &unknowns, &z, &names, &changed, &p);
    Ok(Update {
        text,
        written,
        violations,
        skipped,
        changed,
        unreachable,
        scene,
    })
}

/// The changed links whose numbers break physics, as [`super::consistency`].
fn consistency(
    links: &[Link],
    unknowns: &[Unknown],
    z: &[f64],
    names: &[String],
    changed: &[String],
    p: &DMatrix<f64>,
) -> Vec<(String, String, Vec<usize>)> {
    let mut out = Vec::new();
    for (c, u) in unknowns.iter().enumerate() {
        let Unknown::Link { link, k: 0 } = *u else {
            continue;
        };
        if !changed.contains(&names[c]) {
            continue;
        }
        let sp: [f64; 10] = std::array::from_fn(|k| z[c + k]);
        let Some(what) = broken(&sp) else {
            continue;
        };
        out.push((links[link].name.clone(), what, involved(p, c..c + 10)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inertia_turns_into_the_inertial_frame_and_back() {
        let r = rotation([0.3, -0.2, 1.1]);
        let m = [[0.4, 0.01, 0.0], [0.01, 0.5, 0.02], [0.0, 0.02, 0.6]];
        let back = turn(&r, &turn(&r, &m, true), false);
        for i in 0..3 {
            for j in 0..3 {
                assert!((back[i][j] - m[i][j]).abs() < 1e-15);
            }
        }
        for v in [0.0, 1.5e-7, -0.25, 3.0e7] {
            assert_eq!(fmt(v).parse::<f64>().unwrap(), v);
        }
    }

    #[test]
    fn missing_elements_and_attributes_are_added_and_the_rest_kept() {
        let text = "<robot name=\"r\">\n  <link name=\"a\">\n    <inertial>\n      <!-- keep -->\n      <mass value=\"2\"/>\n    </inertial>\n  </link>\n  <joint name=\"j\" type=\"revolute\">\n    <parent link=\"base\"/>\n  </joint>\n</robot>\n";
        let tags = scan(text).unwrap();
        let (links, joints) = read(text, &tags);
        assert_eq!((links.len(), joints.len()), (1, 1));
        let p = link_parameters(text, &tags, &links[0]).unwrap();
        assert_eq!(p[9], 2.0);
        let mut unknowns: Vec<Unknown> = (0..10).map(|k| Unknown::Link { link: 0, k }).collect();
        unknowns.push(Unknown::Drive {
            joint: 0,
            key: "damping",
        });
        let mut values = p.to_vec();
        values[6] = 0.2; // a first moment: the mass centre at x = 0.1
        values.push(0.5);
        let (out, _) = apply(text, &tags, &links, &joints, None, &unknowns, &values).unwrap();
        assert!(out.contains("<!-- keep -->\n      <mass value=\"2\"/>\n      <origin xyz=\"0.1 0 0\" rpy=\"0 0 0\"/>\n"), "{out}");
        assert!(out.contains("<inertia ixx=\"0\""), "{out}");
        assert!(
            out.contains(
                "    <parent link=\"base\"/>\n    <dynamics damping=\"0.5\"/>\n  </joint>"
            ),
            "{out}"
        );
        values[10] = -1.0;
        assert!(
            apply(text, &tags, &links, &joints, None, &unknowns, &values)
                .unwrap_err()
                .contains("< 0")
        );
    }
}
