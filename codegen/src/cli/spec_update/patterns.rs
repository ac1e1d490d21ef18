//! The `[[pattern]]` part of the spec update: a platform's legs are one pattern whose entries
//! every copy shares, so the unknowns are per copy (the values the spec's text gives each copy,
//! patterns expanded) and a changed entry is written as expressions indexing per-copy arrays
//! that the update adds to `[parameters]` (`mass = "identified_piston_mass[i]"`,
//! `damping = "identified_p_damping[i]"`).

use nalgebra::DMatrix;
use toml_edit::{DocumentMut, InlineTable, Item, Value};

use runtime::model::{Mat3, Vec3};

use super::{Unknown, broken, from_standard, involved, number, set, value};

/// A pattern body's copies as per-copy arrays in `[parameters]`, which its entries index
/// (`inertia_rpy` removed).
pub(super) fn set_copies(
    d: &mut DocumentMut,
    pattern: usize,
    body: usize,
    copies: &[[f64; 10]],
) -> Result<(), String> {
    let Some(t) = d["pattern"]
        .as_array_of_tables_mut()
        .and_then(|a| a.get_mut(pattern))
        .and_then(|p| p.get_mut("body"))
        .and_then(Item::as_array_of_tables_mut)
        .and_then(|a| a.get_mut(body))
    else {
        return Ok(());
    };
    let template = t
        .get("name")
        .and_then(|n| n.as_str())
        .unwrap_or("body")
        .to_string();
    let arrays = per_copy_keys(t, &stem(&template), &format!("body `{template}`"), copies)?;
    put_arrays(d, arrays)
}

/// Body numbers per copy (`copies`, standard parameters) into table `t` (a pattern body, or a
/// pattern joint's `cross`) as expressions indexing per-copy arrays `{stem}_mass`,
/// `{stem}_com_x`, …, `{stem}_iyz` (`inertia_rpy` removed); returns the arrays for
/// `[parameters]`. `what` names the entry in errors.
pub(super) fn per_copy_keys(
    t: &mut dyn toml_edit::TableLike,
    stem: &str,
    what: &str,
    copies: &[[f64; 10]],
) -> Result<Vec<(String, Vec<f64>)>, String> {
    let mut arrays: Vec<(String, Vec<f64>)> = Vec::new();
    let mut per = Vec::new();
    for (c, p) in copies.iter().enumerate() {
        per.push(from_standard(p).map_err(|e| format!("{what} copy {}: {e}", c + 1))?);
    }
    let key = |what: &str| format!("{stem}_{what}");
    arrays.push((key("mass"), per.iter().map(|b| b.0).collect()));
    for (a, axis) in ["x", "y", "z"].iter().enumerate() {
        arrays.push((
            key(&format!("com_{axis}")),
            per.iter().map(|b| b.1[a]).collect(),
        ));
    }
    let entries = [
        ("ixx", (0, 0)),
        ("iyy", (1, 1)),
        ("izz", (2, 2)),
        ("ixy", (0, 1)),
        ("ixz", (0, 2)),
        ("iyz", (1, 2)),
    ];
    for (k, (r, c)) in entries {
        arrays.push((key(k), per.iter().map(|b| b.2[r][c]).collect()));
    }
    let at = |k: &str| Value::from(format!("{k}[i]"));
    set(t, "mass", value(at(&key("mass"))));
    let mut com = toml_edit::Array::new();
    for axis in ["x", "y", "z"] {
        com.push(at(&key(&format!("com_{axis}"))));
    }
    set(t, "com", value(com));
    let mut it = InlineTable::new();
    for (k, _) in entries {
        it.insert(k, at(&key(k)));
    }
    set(t, "inertia", value(it));
    t.remove("inertia_rpy");
    Ok(arrays)
}

/// Per-copy arrays into `[parameters]` (made if absent).
pub(super) fn put_arrays(
    d: &mut DocumentMut,
    arrays: Vec<(String, Vec<f64>)>,
) -> Result<(), String> {
    if !d.contains_key("parameters") {
        d["parameters"] = Item::Table(toml_edit::Table::new());
    }
    let params = d["parameters"]
        .as_table_like_mut()
        .ok_or("`parameters` is not a table")?;
    for (name, values) in arrays {
        let mut a = toml_edit::Array::new();
        for v in values {
            a.push(number(v));
        }
        set(params, &name, value(a));
    }
    Ok(())
}

/// The `identified_<stem>` prefix of a pattern entry's arrays.
pub(super) fn stem(template: &str) -> String {
    let s: String = template
        .replace("{i}", "")
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    format!("identified_{}", s.trim_matches('_'))
}

/// A pattern joint's drive number `key` per copy, as an array that the joint's entry indexes.
pub(super) fn set_copy_drives(
    d: &mut DocumentMut,
    pattern: usize,
    joint: usize,
    key: &str,
    copies: &[f64],
) -> Result<(), String> {
    let Some(t) = d["pattern"]
        .as_array_of_tables_mut()
        .and_then(|a| a.get_mut(pattern))
        .and_then(|p| p.get_mut("joint"))
        .and_then(Item::as_array_of_tables_mut)
        .and_then(|a| a.get_mut(joint))
    else {
        return Ok(());
    };
    let template = t.get("name").and_then(|n| n.as_str()).unwrap_or("joint");
    if let Some(v) = copies.iter().find(|v| **v < 0.0) {
        return Err(format!("joint `{template}`: {key} {v} < 0"));
    }
    let name = format!("{}_{key}", stem(template));
    set(t, key, value(Value::from(format!("{name}[i]"))));
    put_arrays(d, vec![(name, copies.to_vec())])
}

/// The unknowns of the `[[pattern.body]]` entries, per copy the values the spec gives it
/// (`written`, patterns expanded; a body some copy of which is not found is skipped), and of
/// the `[[pattern.joint]]` entries' `damping`, `friction` and `armature` where the spec gives
/// them (plain numbers; per copy).
pub(super) fn pattern_unknowns(
    doc: &DocumentMut,
    written: &[(String, f64, Vec3, Mat3)],
    unknowns: &mut Vec<Unknown>,
    z0: &mut Vec<f64>,
    names: &mut Vec<String>,
    skipped: &mut Vec<String>,
) {
    let Some(patterns) = doc.get("pattern").and_then(Item::as_array_of_tables) else {
        return;
    };
    for (pattern, p) in patterns.iter().enumerate() {
        let copies = p.get("copies").and_then(|c| c.as_integer()).unwrap_or(0) as usize;
        let Some(bodies) = p.get("body").and_then(Item::as_array_of_tables) else {
            continue;
        };
        for (body, t) in bodies.iter().enumerate() {
            let template = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
            let values: Option<Vec<[f64; 10]>> = (1..=copies)
                .map(|i| {
                    let name = template.replace("{i}", &i.to_string());
                    written
                        .iter()
                        .find(|b| b.0 == name)
                        .map(|b| codegen::dynamics::body_standard_parameters(b.1, &b.2, &b.3))
                })
                .collect();
            let Some(values) = values else {
                skipped.push(format!("body `{template}`"));
                continue;
            };
            for (c, v) in values.iter().enumerate() {
                for (k, x) in v.iter().enumerate() {
                    unknowns.push(Unknown::Copy {
                        pattern,
                        body,
                        copy: c + 1,
                        k,
                    });
                    z0.push(*x);
                    names.push(format!("body `{template}`"));
                }
            }
        }
        let Some(joints) = p.get("joint").and_then(Item::as_array_of_tables) else {
            continue;
        };
        let platform = doc
            .get("platform")
            .and_then(|p| p.get("body"))
            .and_then(|b| b.as_str());
        for (joint, t) in joints.iter().enumerate() {
            let template = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
            // The joint that meets the platform takes no drive.
            if t.get("child").and_then(|c| c.as_str()) == platform {
                continue;
            }
            for key in ["damping", "friction", "armature"] {
                // Only the drives the spec has: a drive it lacks stays absent (the minimum-norm
                // change would otherwise spread inertia onto new armatures, often negative).
                let Some(item) = t.get(key) else {
                    continue;
                };
                let Some(v) = super::num(Some(item)) else {
                    skipped.push(format!("joint `{template}` ({key})"));
                    continue;
                };
                for copy in 1..=copies {
                    unknowns.push(Unknown::CopyDrive {
                        pattern,
                        joint,
                        copy,
                        key,
                    });
                    z0.push(v);
                    names.push(format!("joint `{template}`"));
                }
            }
        }
    }
}

/// The changed pattern bodies' copies that break physics, as [`super::consistency`].
pub(super) fn copy_consistency(
    unknowns: &[Unknown],
    z: &[f64],
    names: &[String],
    changed: &[String],
    p: &DMatrix<f64>,
) -> Vec<(String, String, Vec<usize>)> {
    let mut out = Vec::new();
    let mut c = 0;
    while c < unknowns.len() {
        let Unknown::Copy { copy, .. } = unknowns[c] else {
            c += 1;
            continue;
        };
        let sp: [f64; 10] = std::array::from_fn(|k| z[c + k]);
        let cols = c..c + 10;
        c += 10;
        if !changed.contains(&names[cols.start]) {
            continue;
        }
        let Some(what) = broken(&sp) else {
            continue;
        };
        let name = names[cols.start]
            .trim_start_matches("body `")
            .trim_end_matches('`')
            .replace("{i}", &copy.to_string());
        out.push((name, what, involved(p, cols)));
    }
    out
}
