//! The spec update of `identify --out` (docs/identification.md, "The updated spec"): the
//! smallest change of the spec's standard parameters whose model has the identified base
//! parameters, written into the spec's text (comments and layout kept).
//!
//! The unknowns are the spec's own numbers: per `[[body]]` its ten standard parameters in its
//! body frame about its origin (`XX … ZZ`, `MX, MY, MZ`, `M`: the inertia about the origin, the
//! first moment, the mass, which the body's `mass`, `com` and `inertia` are a non-linear but
//! invertible form of), per `[[joint]]` its `damping`, `friction` and `armature`. The map `P`
//! from them to the base parameters is linear (a frame change, merging and regrouping are
//! linear in the standard parameters); its columns are found by loading the spec with one
//! unknown moved at a time, so every conversion the loader makes (standard DH frames, fixed
//! joints merged, the `[scene]`) is the loader's own. `Δ = P⁺ (π̂ − π_spec)` is the
//! minimum-norm change; the written spec is loaded again to check it.
//!
//! A platform's legs are usually one `[[pattern]]` whose bodies every copy shares: their
//! unknowns are per copy (the values the spec's text gives each copy, patterns expanded), and a
//! changed pattern body is written as expressions indexing per-copy arrays that the update adds
//! to `[parameters]` (`mass = "identified_cylinder_mass[i]"`). A parallelogram's rods are
//! three numbers per entry (or copy), linear in their body's standard parameters
//! ([`rods`]). A universal joint's `cross` (and a parallelogram's, its elbow U's) is ten more
//! unknowns per entry (or copy), solved for with the payload on what the bodies cannot reach
//! ([`crosses`]). Base parameters that no written number moves (what unequal rods would have,
//! a drive the spec lacks) keep the spec's values and are reported.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use toml_edit::{DocumentMut, InlineTable, Item, Value};

use runtime::model::{Mat3, Vec3};

use super::regressor::Regressor;

mod patterns;
use patterns::{copy_consistency, pattern_unknowns, set_copies};
mod crosses;
use crosses::{cross_consistency, cross_unknowns, free_masses, set_crosses};
mod payload;
use payload::{payload_unknowns, set_payload};
mod rods;
use rods::{rod_unknowns, rods_consistency, set_rods};
mod armature;
mod change;
use change::{Change, minimum_norm_change};
mod urdf;
mod xml_scan;

/// Where an entry of a spec array (`[[joint]]`, `[[parallelogram]]`) is: top-level (`pattern`
/// `None`) or in `[[pattern]]` element `pattern` (`[[pattern.joint]]`, …), element `index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct EntryAt {
    pub pattern: Option<usize>,
    pub index: usize,
}

impl EntryAt {
    /// The entry's table in `d`, in the array named `array`.
    fn table_mut<'d>(
        self,
        d: &'d mut DocumentMut,
        array: &str,
    ) -> Option<&'d mut toml_edit::Table> {
        let outer = match self.pattern {
            None => d.as_table_mut(),
            Some(p) => d
                .get_mut("pattern")
                .and_then(Item::as_array_of_tables_mut)
                .and_then(|a| a.get_mut(p))?,
        };
        outer
            .get_mut(array)
            .and_then(Item::as_array_of_tables_mut)
            .and_then(|a| a.get_mut(self.index))
    }
}

/// One unknown of the update.
#[derive(Clone, Debug)]
enum Unknown {
    /// Standard parameter `k` (0..10) of `[[body]]` element `index`.
    Body { index: usize, k: usize },
    /// `damping`, `friction` or `armature` of `[[joint]]` element `index`.
    Drive { index: usize, key: &'static str },
    /// `stiffness` or `damping` of `[[spring]]` element `index` (a closed loop's).
    Spring { index: usize, key: &'static str },
    /// Standard parameter `k` of copy `copy` (from 1) of `[[pattern]]` element `pattern`'s
    /// `[[pattern.body]]` element `body`.
    Copy {
        pattern: usize,
        body: usize,
        copy: usize,
        k: usize,
    },
    /// `damping`, `friction` or `armature` of copy `copy` (from 1) of `[[pattern]]` element
    /// `pattern`'s `[[pattern.joint]]` element `joint`.
    CopyDrive {
        pattern: usize,
        joint: usize,
        copy: usize,
        key: &'static str,
    },
    /// Linear rod parameter `k` (`M`, `H`, `J`: [`rods`]) of copy `copy` (from 1; 1 for a
    /// top-level entry) of the parallelogram entry `at`.
    Rods { at: EntryAt, copy: usize, k: usize },
    /// Standard parameter `k` of the `[scene] payload`.
    Payload { k: usize },
    /// Standard parameter `k` of the cross of copy `copy` (from 1; 1 for a top-level entry)
    /// of the universal joint entry `at` of array `array` (`joint`, or `parallelogram` for
    /// its elbow's U) ([`crosses`]).
    Cross {
        array: &'static str,
        at: EntryAt,
        copy: usize,
        k: usize,
    },
}

/// The outcome of an update.
pub struct Update {
    /// The updated spec text.
    pub text: String,
    /// Base parameters of the written spec (loaded again).
    pub written: Vec<f64>,
    /// Per body whose physics the written numbers break: `(body, what, base parameters
    /// involved)`.
    pub violations: Vec<(String, String, Vec<usize>)>,
    /// Bodies whose numbers are not plain numbers (left unchanged).
    pub skipped: Vec<String>,
    /// The bodies and joints changed.
    pub changed: Vec<String>,
    /// The base parameters that no number of the update moves (kept at the spec's values).
    pub unreachable: Vec<usize>,
    /// A URDF's scene file as the update writes it (its `armature`), `None` for a TOML spec.
    pub scene: Option<String>,
}

/// A number as TOML: plain decimals between 1e-3 and 1e6, exponent form outside, always a
/// float; the shortest text that reads back to the same `f64`.
fn number(v: f64) -> Value {
    let a = v.abs();
    let mut s = if a == 0.0 || (1e-3..1e6).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    };
    if !s.contains(['.', 'e']) {
        s.push_str(".0");
    }
    s.parse().unwrap_or_else(|_| Value::from(v))
}

fn value(v: impl Into<Value>) -> Item {
    Item::Value(v.into())
}

/// Set `key` of `t` to `item`, keeping the key's text around it (a comment on the line above,
/// the layout) and the old value's (a comment after it): `insert` would replace both.
fn set(t: &mut dyn toml_edit::TableLike, key: &str, item: Item) {
    match t.get_mut(key) {
        Some(old) => {
            let mut item = item;
            if let (Some(o), Some(n)) = (old.as_value(), item.as_value_mut()) {
                *n.decor_mut() = o.decor().clone();
            }
            *old = item;
        }
        None => {
            t.insert(key, item);
        }
    }
}

fn num(item: Option<&Item>) -> Option<f64> {
    let v = item?.as_value()?;
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

fn get_num(t: &dyn toml_edit::TableLike, key: &str) -> Option<f64> {
    num(t.get(key))
}

/// A body's ten standard parameters from its spec entry, `None` if a value is not a plain
/// number (an expression, an angle string).
fn body_parameters(t: &dyn toml_edit::TableLike) -> Option<[f64; 10]> {
    let mass = get_num(t, "mass")?;
    let com = match t.get("com") {
        None => [0.0; 3],
        Some(i) => {
            let a = i.as_value()?.as_array()?;
            let v: Vec<f64> = a
                .iter()
                .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                .collect::<Option<_>>()?;
            [*v.first()?, *v.get(1)?, *v.get(2)?]
        }
    };
    let mut ic = [[0.0; 3]; 3];
    if let Some(i) = t.get("inertia") {
        let it = i.as_table_like()?;
        let g = |k: &str| match it.get(k) {
            None => Some(0.0),
            Some(x) => num(Some(x)),
        };
        let (xx, yy, zz) = (g("ixx")?, g("iyy")?, g("izz")?);
        let (xy, xz, yz) = (g("ixy")?, g("ixz")?, g("iyz")?);
        ic = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    }
    if let Some(i) = t.get("inertia_rpy") {
        let a = i.as_value()?.as_array()?;
        let v: Vec<f64> = a
            .iter()
            .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
            .collect::<Option<_>>()?;
        let r = runtime::model::rpy_to_matrix([*v.first()?, *v.get(1)?, *v.get(2)?]);
        let m = DMatrix::from_fn(3, 3, |i, j| r[i][j]);
        let i3 = DMatrix::from_fn(3, 3, |i, j| ic[i][j]);
        let rot = &m * i3 * m.transpose();
        ic = std::array::from_fn(|i| std::array::from_fn(|j| rot[(i, j)]));
    }
    Some(codegen::dynamics::body_standard_parameters(mass, &com, &ic))
}

/// The keys of body table `t` that `body_parameters` cannot read as plain numbers, as
/// `` (`com` = ["l/2", 0, 0]) `` for the note on a body left unchanged.
fn unwritable_keys(t: &dyn toml_edit::TableLike) -> String {
    let plain = |v: &toml_edit::Value| v.as_float().is_some() || v.as_integer().is_some();
    let keys: Vec<String> = ["mass", "com", "inertia", "inertia_rpy"]
        .into_iter()
        .filter_map(|k| {
            let item = t.get(k)?;
            let ok = match item {
                Item::Value(toml_edit::Value::Array(a)) => a.iter().all(plain),
                Item::Value(v) if k == "mass" => plain(v),
                _ => item
                    .as_table_like()
                    .is_some_and(|it| it.iter().all(|(_, x)| x.as_value().is_some_and(plain))),
            };
            (!ok).then(|| {
                let text = item.to_string();
                format!("`{k}` = {}", text.trim())
            })
        })
        .collect();
    if keys.is_empty() {
        String::new()
    } else {
        format!(" ({})", keys.join(", "))
    }
}

/// `(mass, com, inertia about the com)` of standard parameters `p`; `Err` when no body has them
/// (a negative mass, or a first moment without mass).
fn from_standard(p: &[f64; 10]) -> Result<(f64, Vec3, Mat3), String> {
    let m = p[9];
    let h = [p[6], p[7], p[8]];
    if m < 0.0 {
        return Err(format!("mass {m} kg < 0"));
    }
    let c = if m > 0.0 {
        [h[0] / m, h[1] / m, h[2] / m]
    } else if h.iter().all(|x| *x == 0.0) {
        [0.0; 3]
    } else {
        return Err("a first moment without mass".into());
    };
    let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let jo = [[p[0], p[1], p[2]], [p[1], p[3], p[4]], [p[2], p[4], p[5]]];
    let ic = std::array::from_fn(|r| {
        std::array::from_fn(|k| jo[r][k] - m * (if r == k { cc } else { 0.0 } - c[r] * c[k]))
    });
    Ok((m, c, ic))
}

/// Write a body's numbers (`inertia_rpy` removed: the inertia is written in body axes).
fn set_body(t: &mut dyn toml_edit::TableLike, p: &[f64; 10]) -> Result<(), String> {
    let (m, c, ic) = from_standard(p)?;
    set(t, "mass", value(number(m)));
    let mut com = toml_edit::Array::new();
    for x in c {
        com.push(number(x));
    }
    set(t, "com", value(com));
    let mut it = InlineTable::new();
    for (k, (r, c)) in [
        ("ixx", (0, 0)),
        ("iyy", (1, 1)),
        ("izz", (2, 2)),
        ("ixy", (0, 1)),
        ("ixz", (0, 2)),
        ("iyz", (1, 2)),
    ] {
        it.insert(k, number(ic[r][c]));
    }
    set(t, "inertia", value(it));
    t.remove("inertia_rpy");
    Ok(())
}

/// Apply `values` (one per unknown) to a copy of `doc`.
fn apply(doc: &DocumentMut, unknowns: &[Unknown], values: &[f64]) -> Result<DocumentMut, String> {
    let mut d = doc.clone();
    let mut bodies: std::collections::BTreeMap<usize, [f64; 10]> = Default::default();
    type Copies = std::collections::BTreeMap<usize, [f64; 10]>;
    let mut copies: std::collections::BTreeMap<(usize, usize), Copies> = Default::default();
    type Drives = std::collections::BTreeMap<usize, f64>;
    let mut drives: std::collections::BTreeMap<(usize, usize, &str), Drives> = Default::default();
    type Rods = std::collections::BTreeMap<usize, [f64; 3]>;
    let mut rods: std::collections::BTreeMap<EntryAt, Rods> = Default::default();
    let mut payload: Option<[f64; 10]> = None;
    let mut crosses: std::collections::BTreeMap<(&str, EntryAt), Copies> = Default::default();
    for (u, &v) in unknowns.iter().zip(values) {
        match u {
            Unknown::Cross { array, at, copy, k } => {
                crosses
                    .entry((*array, *at))
                    .or_default()
                    .entry(*copy)
                    .or_insert([0.0; 10])[*k] = v
            }
            Unknown::Payload { k } => payload.get_or_insert([0.0; 10])[*k] = v,
            Unknown::Rods { at, copy, k } => {
                rods.entry(*at)
                    .or_default()
                    .entry(*copy)
                    .or_insert([0.0; 3])[*k] = v
            }
            Unknown::CopyDrive {
                pattern,
                joint,
                copy,
                key,
            } => {
                drives
                    .entry((*pattern, *joint, key))
                    .or_default()
                    .insert(*copy, v);
            }
            Unknown::Copy {
                pattern,
                body,
                copy,
                k,
            } => {
                copies
                    .entry((*pattern, *body))
                    .or_default()
                    .entry(*copy)
                    .or_insert([0.0; 10])[*k] = v
            }
            Unknown::Body { index, k } => bodies.entry(*index).or_insert([0.0; 10])[*k] = v,
            Unknown::Spring { index, key } => {
                if let Some(t) = d["spring"]
                    .as_array_of_tables_mut()
                    .and_then(|a| a.get_mut(*index))
                {
                    set(t, key, value(number(v)));
                }
            }
            Unknown::Drive { index, key } => {
                if let Some(t) = d["joint"]
                    .as_array_of_tables_mut()
                    .and_then(|a| a.get_mut(*index))
                {
                    set(t, key, value(number(v)));
                }
            }
        }
    }
    for (index, p) in bodies {
        if let Some(t) = d["body"]
            .as_array_of_tables_mut()
            .and_then(|a| a.get_mut(index))
        {
            let name = t
                .get("name")
                .and_then(|n| n.as_str())
                .unwrap_or("?")
                .to_string();
            set_body(t, &p).map_err(|e| format!("body `{name}`: {e}"))?;
        }
    }
    for ((pattern, body), c) in copies {
        let c: Vec<[f64; 10]> = c.into_values().collect();
        set_copies(&mut d, pattern, body, &c)?;
    }
    for ((pattern, joint, key), c) in drives {
        let c: Vec<f64> = c.into_values().collect();
        patterns::set_copy_drives(&mut d, pattern, joint, key, &c)?;
    }
    for (at, c) in rods {
        let c: Vec<[f64; 3]> = c.into_values().collect();
        set_rods(&mut d, at, &c)?;
    }
    for ((array, at), c) in crosses {
        let c: Vec<[f64; 10]> = c.into_values().collect();
        set_crosses(&mut d, array, at, &c)?;
    }
    if let Some(p) = payload {
        set_payload(&mut d, &p)?;
    }
    Ok(d)
}

/// The base parameters of a spec text (its `[scene]` applied), on `reg`'s grouping.
fn base_of(reg: &Regressor, file: &str, text: &str) -> Result<Vec<f64>, String> {
    reg.base_of_spec(file, text, None)
}

/// A URDF as the loader tells one: by its name, or an XML text (`robot.xml`).
pub fn is_urdf(file: &str, source: &str) -> bool {
    file.to_ascii_lowercase().ends_with(".urdf") || source.trim_start().starts_with('<')
}

/// The update of `source` (a TOML spec, or a URDF with its scene file `sidecar`) whose model
/// has base parameters `target` where `fit[k]` (elsewhere the spec's).
pub fn update(
    reg: &Regressor,
    file: &str,
    source: &str,
    sidecar: Option<&codegen::spec::SceneFile>,
    target: &[f64],
    fit: &[bool],
) -> Result<Update, String> {
    if is_urdf(file, source) {
        return urdf::update(reg, file, source, sidecar, target, fit);
    }
    let doc: DocumentMut = source
        .parse()
        .map_err(|e| format!("error: {file}: not TOML: {e}"))?;
    let mut unknowns = Vec::new();
    let mut z0 = Vec::new();
    let mut skipped = Vec::new();
    let mut names = Vec::new();
    if let Some(a) = doc.get("body").and_then(Item::as_array_of_tables) {
        for (index, t) in a.iter().enumerate() {
            let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
            match body_parameters(t) {
                Some(p) => {
                    for (k, v) in p.into_iter().enumerate() {
                        unknowns.push(Unknown::Body { index, k });
                        z0.push(v);
                        names.push(format!("body `{name}`"));
                    }
                }
                None => skipped.push(format!("body `{name}`{}", unwritable_keys(t))),
            }
        }
    }
    if let Some(a) = doc.get("joint").and_then(Item::as_array_of_tables) {
        // A joint that closes a loop (`child_origin`) has no drive.
        for (index, t) in a
            .iter()
            .enumerate()
            .filter(|(_, t)| !t.contains_key("child_origin"))
        {
            let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
            for key in ["damping", "friction", "armature"] {
                if let Some(v) = match t.get(key) {
                    None => Some(0.0),
                    Some(i) => num(Some(i)),
                } {
                    unknowns.push(Unknown::Drive { index, key });
                    z0.push(v);
                    names.push(format!("joint `{name}`"));
                }
            }
        }
    }
    if let Some(a) = doc.get("spring").and_then(Item::as_array_of_tables) {
        for (index, t) in a.iter().enumerate() {
            let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
            for key in ["stiffness", "damping"] {
                if let Some(v) = match t.get(key) {
                    None => Some(0.0),
                    Some(i) => num(Some(i)),
                } {
                    unknowns.push(Unknown::Spring { index, key });
                    z0.push(v);
                    names.push(format!("spring `{name}`"));
                }
            }
        }
    }
    if let Some(written) = codegen::spec::written_bodies(file, source) {
        pattern_unknowns(
            &doc,
            &written,
            &mut unknowns,
            &mut z0,
            &mut names,
            &mut skipped,
        );
        rod_unknowns(
            &doc,
            &written,
            &mut unknowns,
            &mut z0,
            &mut names,
            &mut skipped,
        );
    }
    if let Some(written) = codegen::spec::written_crosses(file, source) {
        cross_unknowns(
            &doc,
            &written,
            &mut unknowns,
            &mut z0,
            &mut names,
            &mut skipped,
        );
    }
    payload_unknowns(&doc, &mut unknowns, &mut z0, &mut names, &mut skipped);
    // The spec normalized (every body written from its standard parameters) must be the spec.
    let norm = apply(&doc, &unknowns, &z0)?;
    let pi0 = base_of(reg, file, &norm.to_string())?;
    let pi_spec = base_of(reg, file, source)?;
    let drift = super::identify::rounding_mismatch(&pi0, &pi_spec);
    if drift > 1e-9 {
        return Err(format!(
            "error: {file}: its bodies written back as numbers change its base parameters ({drift:.2e} relative): --out cannot rewrite this spec (no file written)"
        ));
    }
    // The columns of P: each unknown moved from a reference point where every body is valid.
    let mut reference = z0.clone();
    for (u, r) in unknowns.iter().zip(reference.iter_mut()) {
        if let Unknown::Body { k, .. }
        | Unknown::Copy { k, .. }
        | Unknown::Payload { k }
        | Unknown::Cross { k, .. } = u
        {
            *r = REFERENCE[*k];
        }
        if let Unknown::Rods { k, .. } = u {
            *r = rods::REFERENCE[*k];
        }
    }
    let late: Vec<bool> = unknowns
        .iter()
        .map(|u| matches!(u, Unknown::Payload { .. } | Unknown::Cross { .. }))
        .collect();
    let Change {
        p,
        mut z,
        mut dz,
        unreachable,
    } = minimum_norm_change(
        reg.nbp(),
        &z0,
        &reference,
        &pi0,
        target,
        fit,
        &late,
        &mut |z| base_of(reg, file, &apply(&doc, &unknowns, z)?.to_string()),
    )?;
    free_masses(&unknowns, &late, &mut z, &mut dz, &p);
    let changed = changed_names(&names, &dz);
    // Only the entries that change are rewritten; the others keep their text.
    let touched: Vec<usize> = (0..unknowns.len())
        .filter(|&c| changed.contains(&names[c]))
        .collect();
    let sub_u: Vec<Unknown> = touched.iter().map(|&c| unknowns[c].clone()).collect();
    let sub_z: Vec<f64> = touched.iter().map(|&c| z[c]).collect();
    let out = apply(&doc, &sub_u, &sub_z).map_err(|e| {
        format!("error: --out: the identified parameters are no spec: {e} (the base parameters are printed above; no file written)")
    })?;
    let text = out.to_string();
    let written = base_of(reg, file, &text)?;
    let mut violations = consistency(&out, &unknowns, &p);
    violations.extend(copy_consistency(&unknowns, &z, &names, &changed, &p));
    violations.extend(rods_consistency(&unknowns, &z, &names, &changed, &p));
    violations.extend(cross_consistency(&unknowns, &z, &names, &changed, &p));
    Ok(Update {
        text,
        written,
        violations,
        skipped,
        changed,
        unreachable,
        scene: None,
    })
}

/// A body's standard parameters at the reference point of the update's columns: unit mass and
/// unit principal moments about the origin (a valid body; one unit more on any is one too).
const REFERENCE: [f64; 10] = [1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];

/// The names (bodies, joints, entries) whose unknowns change.
fn changed_names(names: &[String], dz: &DVector<f64>) -> Vec<String> {
    let mut changed: Vec<String> = Vec::new();
    let largest = dz.amax();
    for (c, name) in names.iter().enumerate() {
        if dz[c].abs() > 1e-13 * largest && !changed.contains(name) {
            changed.push(name.clone());
        }
    }
    changed
}

/// The bodies of `doc` whose numbers break positive mass, a positive definite inertia or the
/// triangle inequality, with the base parameters their unknowns move.
fn consistency(
    doc: &DocumentMut,
    unknowns: &[Unknown],
    p: &DMatrix<f64>,
) -> Vec<(String, String, Vec<usize>)> {
    let mut out = Vec::new();
    let payload = doc
        .get("scene")
        .and_then(|s| s.get("payload"))
        .and_then(Item::as_table_like)
        .and_then(body_parameters)
        .and_then(|sp| from_standard(&sp).ok());
    if let Some((m, _, ic)) = payload {
        let what = physics(m, &ic);
        if !what.is_empty() {
            let involved: Vec<usize> = (0..p.nrows())
                .filter(|&r| {
                    unknowns.iter().enumerate().any(|(c, u)| {
                        matches!(u, Unknown::Payload { .. }) && p[(r, c)].abs() > 1e-12
                    })
                })
                .collect();
            out.push(("[scene] payload".into(), what.join("; "), involved));
        }
    }
    let Some(a) = doc.get("body").and_then(Item::as_array_of_tables) else {
        return out;
    };
    for (index, t) in a.iter().enumerate() {
        let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
        let Some(sp) = body_parameters(t) else {
            continue;
        };
        let Ok((m, _, ic)) = from_standard(&sp) else {
            continue;
        };
        let what = physics(m, &ic);
        if what.is_empty() {
            continue;
        }
        let involved: Vec<usize> = (0..p.nrows())
            .filter(|&r| {
                unknowns.iter().enumerate().any(|(c, u)| {
                    matches!(u, Unknown::Body { index: i, .. } if *i == index)
                        && p[(r, c)].abs() > 1e-12
                })
            })
            .collect();
        out.push((name.to_string(), what.join("; "), involved));
    }
    out
}

/// What the ten standard parameters `sp` break as a body (`None`: a physical body, or numbers
/// that are no body at all, which [`from_standard`] reports where they are written).
fn broken(sp: &[f64; 10]) -> Option<String> {
    let (m, _, ic) = from_standard(sp).ok()?;
    let what = physics(m, &ic);
    (!what.is_empty()).then(|| what.join("; "))
}

/// The base parameters (rows of `p`) that the unknowns `cols` move.
fn involved(p: &DMatrix<f64>, cols: std::ops::Range<usize>) -> Vec<usize> {
    (0..p.nrows())
        .filter(|&r| cols.clone().any(|k| p[(r, k)].abs() > 1e-12))
        .collect()
}

/// What a body of mass `m` and central inertia `ic` breaks (empty: nothing).
fn physics(m: f64, ic: &Mat3) -> Vec<String> {
    {
        let mut what = Vec::new();
        let zero_inertia = ic.iter().flatten().all(|x| *x == 0.0);
        if m < 0.0 {
            what.push(format!("mass {m:.6e} kg < 0"));
        } else if m == 0.0 && !zero_inertia {
            what.push("zero mass but a non-zero inertia".into());
        }
        let e = SymmetricEigen::new(DMatrix::from_fn(3, 3, |i, j| ic[i][j])).eigenvalues;
        let mut ev: Vec<f64> = e.iter().copied().collect();
        ev.sort_by(f64::total_cmp);
        let scale = ev[2].abs().max(f64::MIN_POSITIVE);
        if ev[0] <= 1e-12 * scale && !zero_inertia {
            what.push(format!(
                "inertia about the mass centre not positive definite (principal moments {:.4e}, {:.4e}, {:.4e} kg·m²)",
                ev[0], ev[1], ev[2]
            ));
        } else if ev[0] + ev[1] < ev[2] * (1.0 - 1e-12) {
            // The shortfall too: a flat plate's `a + b = c`, identified to rounding, would
            // otherwise read `1.0000e-2 + 1.0000e-2 < 2.0000e-2`.
            what.push(format!(
                "principal moments {:.4e} + {:.4e} < {:.4e} kg·m² by {:.2e} of the largest (triangle inequality)",
                ev[0],
                ev[1],
                ev[2],
                (ev[2] - ev[0] - ev[1]) / scale
            ));
        }
        what
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_parameters_round_trip_and_refuse_what_no_body_has() {
        let (m, c, ic) = (
            2.5,
            [0.1, -0.2, 0.3],
            [[0.4, 0.01, 0.0], [0.01, 0.5, 0.02], [0.0, 0.02, 0.6]],
        );
        let p = codegen::dynamics::body_standard_parameters(m, &c, &ic);
        let (m2, c2, ic2) = from_standard(&p).unwrap();
        assert!((m2 - m).abs() < 1e-15);
        for k in 0..3 {
            assert!((c2[k] - c[k]).abs() < 1e-15);
            for l in 0..3 {
                assert!((ic2[k][l] - ic[k][l]).abs() < 1e-14);
            }
        }
        let mut neg = p;
        neg[9] = -1.0;
        assert!(from_standard(&neg).unwrap_err().contains("< 0"));
        let mut massless = [0.0; 10];
        massless[6] = 0.1;
        assert!(
            from_standard(&massless)
                .unwrap_err()
                .contains("without mass")
        );
    }

    #[test]
    fn a_rewritten_key_keeps_its_comments() {
        let mut doc: DocumentMut = "[[body]]\n# measured\nmass = 1.0 # kg\n".parse().unwrap();
        let t = doc["body"]
            .as_array_of_tables_mut()
            .unwrap()
            .get_mut(0)
            .unwrap();
        set(t, "mass", value(number(2.5)));
        set(t, "com", value(number(0.1)));
        assert_eq!(
            doc.to_string(),
            "[[body]]\n# measured\nmass = 2.5 # kg\ncom = 0.1\n"
        );
    }

    #[test]
    fn numbers_are_written_as_floats_that_read_back_exactly() {
        for v in [0.0, 17.0, -0.0203, 7.9e-31, 1.5e7, 0.1 + 0.2] {
            let text = number(v).to_string();
            let back: f64 = text.trim().parse().unwrap();
            assert_eq!(back, v, "{text}");
            assert!(text.contains(['.', 'e']), "{text}");
        }
    }
}
