//! The `[[parallelogram]]` part of the spec update: a Delta's forearm is one equivalent rod
//! (docs/spec.md, "Parallelograms"), a body the loader makes from three numbers, `rod_mass`
//! `m`, `rod_com` `c` and the transverse `rod_inertia` `i` (`iyy = izz`; the spin `ixx` is
//! dropped). In the rod's frame its standard parameters are linear in
//! `(M, H, J) = (2m, 2mc, 2(i + mc²))`: mass `M`, first moment `H d`, inertia about the elbow
//! `J (1 − d dᵀ)`, `d` the rod's direction (docs/method.md, "Identification: the regressor and
//! base parameters": the base parameters are linear in the standard ones). So `(M, H, J)` are
//! the update's unknowns, per entry (per copy for a pattern's, written as expressions that
//! index per-copy arrays the update adds to `[parameters]`, as a pattern body's), and the
//! spec's numbers come back as `m = M/2`, `c = H/M`, `i = J/2 − mc²`.
//!
//! A rod's first moment across `d`, its products of inertia and the U cross at the elbow
//! (massless, no spec number) are not free: base parameters that need them are fitted by least
//! squares and reported.

use nalgebra::DMatrix;
use toml_edit::{DocumentMut, Item, Value};

use runtime::model::{Mat3, Vec3};

use super::{EntryAt, Unknown, involved, number, set, value};

/// The unknowns' reference values for the update's columns: a valid rod (`m = 1/2`, `c = 0`,
/// `i = 1`; one unit on `H` gives `c = 1`, `i = 1/2`).
pub(super) const REFERENCE: [f64; 3] = [1.0, 0.0, 2.0];

/// `(M, H, J)` of a rod body as the loader made it (mass `2m`, mass centre `c d`, central
/// inertia `2i (1 − d dᵀ)`). `c ≥ 0` is assumed (its sign is not in the body; a spec with a
/// negative `rod_com` fails the update's round-trip check, which says so).
fn linear(mass: f64, com: &Vec3, inertia: &Mat3) -> [f64; 3] {
    let c = (com[0] * com[0] + com[1] * com[1] + com[2] * com[2]).sqrt();
    let i = (inertia[0][0] + inertia[1][1] + inertia[2][2]) / 4.0;
    let m = mass / 2.0;
    [mass, mass * c, 2.0 * (i + m * c * c)]
}

/// `(m, c, i)` of `(M, H, J)`; `Err` when no rod has them.
fn numbers(p: &[f64; 3], name: &str) -> Result<(f64, f64, f64), String> {
    let [big_m, h, j] = *p;
    if big_m < 0.0 {
        return Err(format!(
            "parallelogram `{name}`: rod mass {} kg < 0",
            big_m / 2.0
        ));
    }
    let c = if big_m > 0.0 {
        h / big_m
    } else if h == 0.0 {
        0.0
    } else {
        return Err(format!(
            "parallelogram `{name}`: a first moment without mass"
        ));
    };
    let m = big_m / 2.0;
    Ok((m, c, j / 2.0 - m * c * c))
}

/// The unknowns of the parallelogram entries, at the values the loader gives their rods
/// (`written`, patterns expanded; an entry some copy of which is not found is skipped).
pub(super) fn rod_unknowns(
    doc: &DocumentMut,
    written: &[(String, f64, Vec3, Mat3)],
    unknowns: &mut Vec<Unknown>,
    z0: &mut Vec<f64>,
    names: &mut Vec<String>,
    skipped: &mut Vec<String>,
) {
    let mut entries: Vec<(EntryAt, String, usize)> = Vec::new();
    if let Some(a) = doc.get("parallelogram").and_then(Item::as_array_of_tables) {
        for (index, t) in a.iter().enumerate() {
            let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
            let at = EntryAt {
                pattern: None,
                index,
            };
            entries.push((at, name.to_string(), 0));
        }
    }
    if let Some(patterns) = doc.get("pattern").and_then(Item::as_array_of_tables) {
        for (pattern, p) in patterns.iter().enumerate() {
            let copies = p.get("copies").and_then(|c| c.as_integer()).unwrap_or(0) as usize;
            let Some(a) = p.get("parallelogram").and_then(Item::as_array_of_tables) else {
                continue;
            };
            for (index, t) in a.iter().enumerate() {
                let name = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
                let at = EntryAt {
                    pattern: Some(pattern),
                    index,
                };
                entries.push((at, name.to_string(), copies));
            }
        }
    }
    for (at, template, copies) in entries {
        // A top-level entry is one "copy" named as written.
        let copy_names: Vec<(usize, String)> = if at.pattern.is_none() {
            vec![(1, template.clone())]
        } else {
            (1..=copies)
                .map(|i| (i, template.replace("{i}", &i.to_string())))
                .collect()
        };
        let values: Option<Vec<[f64; 3]>> = copy_names
            .iter()
            .map(|(_, n)| {
                let rods = format!("{n}_rods");
                written
                    .iter()
                    .find(|b| b.0 == rods)
                    .map(|b| linear(b.1, &b.2, &b.3))
            })
            .collect();
        let Some(values) = values else {
            skipped.push(format!("parallelogram `{template}`"));
            continue;
        };
        for ((copy, _), v) in copy_names.iter().zip(values) {
            for (k, x) in v.into_iter().enumerate() {
                unknowns.push(Unknown::Rods { at, copy: *copy, k });
                z0.push(x);
                names.push(format!("parallelogram `{template}`"));
            }
        }
    }
}

/// Write an entry's rods: plain numbers for a top-level entry, per-copy arrays in
/// `[parameters]` indexed by the entry's keys for a pattern's. `rod_inertia`'s `ixx` (the
/// dropped spin) keeps its text.
pub(super) fn set_rods(
    d: &mut DocumentMut,
    at: EntryAt,
    copies: &[[f64; 3]],
) -> Result<(), String> {
    let table = at.table_mut(d, "parallelogram");
    let Some(t) = table else {
        return Ok(());
    };
    let template = t
        .get("name")
        .and_then(|n| n.as_str())
        .unwrap_or("parallelogram")
        .to_string();
    let per: Vec<(f64, f64, f64)> = copies
        .iter()
        .map(|p| numbers(p, &template))
        .collect::<Result<_, _>>()?;
    let (mass, com, inertia): (Value, Value, Value) = if at.pattern.is_none() {
        let (m, c, i) = per[0];
        (number(m), number(c), number(i))
    } else {
        let stem = super::patterns::stem(&template);
        let arrays: Vec<(String, Vec<f64>)> = vec![
            (
                format!("{stem}_rod_mass"),
                per.iter().map(|p| p.0).collect(),
            ),
            (format!("{stem}_rod_com"), per.iter().map(|p| p.1).collect()),
            (format!("{stem}_rod_iyy"), per.iter().map(|p| p.2).collect()),
        ];
        let at = |k: &str| Value::from(format!("{k}[i]"));
        let keys = (at(&arrays[0].0), at(&arrays[1].0), at(&arrays[2].0));
        super::patterns::put_arrays(d, arrays)?;
        keys
    };
    // `d` was borrowed for the arrays: find the table again.
    let t = match at.pattern {
        None => d["parallelogram"]
            .as_array_of_tables_mut()
            .and_then(|a| a.get_mut(at.index)),
        Some(p) => d["pattern"]
            .as_array_of_tables_mut()
            .and_then(|a| a.get_mut(p))
            .and_then(|p| p.get_mut("parallelogram"))
            .and_then(Item::as_array_of_tables_mut)
            .and_then(|a| a.get_mut(at.index)),
    }
    .ok_or("a parallelogram entry vanished")?;
    set(t, "rod_mass", value(mass));
    set(t, "rod_com", value(com));
    let mut it = t
        .get("rod_inertia")
        .and_then(|i| i.as_value())
        .and_then(|v| v.as_inline_table())
        .cloned()
        .unwrap_or_default();
    it.insert("iyy", inertia.clone());
    it.insert("izz", inertia);
    set(t, "rod_inertia", value(it));
    Ok(())
}

/// The changed rods whose transverse inertia `i` is negative, as [`super::consistency`].
pub(super) fn rods_consistency(
    unknowns: &[Unknown],
    z: &[f64],
    names: &[String],
    changed: &[String],
    p: &DMatrix<f64>,
) -> Vec<(String, String, Vec<usize>)> {
    let mut out = Vec::new();
    for (c, u) in unknowns.iter().enumerate() {
        let Unknown::Rods { copy, k: 0, at } = u else {
            continue;
        };
        if c + 3 > z.len() || !changed.contains(&names[c]) {
            continue;
        }
        let lin = [z[c], z[c + 1], z[c + 2]];
        let Ok((_, _, i)) = numbers(&lin, "") else {
            continue;
        };
        if i >= 0.0 {
            continue;
        }
        let name = names[c]
            .trim_start_matches("parallelogram `")
            .trim_end_matches('`');
        let name = if at.pattern.is_some() {
            name.replace("{i}", &copy.to_string())
        } else {
            name.to_string()
        };
        out.push((
            format!("{name}_rods"),
            format!("rod transverse inertia {i:.4e} kg·m² < 0"),
            involved(p, c..c + 3),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rod_numbers_round_trip_through_the_linear_parameters() {
        let (m, c, i) = (0.525, 0.5275, 0.043);
        let d = [0.6, 0.0, -0.8];
        let com = [c * d[0], c * d[1], c * d[2]];
        let inertia: Mat3 = std::array::from_fn(|r| {
            std::array::from_fn(|k| 2.0 * i * (f64::from(u8::from(r == k)) - d[r] * d[k]))
        });
        let lin = linear(2.0 * m, &com, &inertia);
        let (m2, c2, i2) = numbers(&lin, "f").unwrap();
        assert!((m2 - m).abs() < 1e-15 && (c2 - c).abs() < 1e-15 && (i2 - i).abs() < 1e-15);
        assert!(numbers(&[-1.0, 0.0, 1.0], "f").unwrap_err().contains("< 0"));
        assert!(
            numbers(&[0.0, 0.1, 1.0], "f")
                .unwrap_err()
                .contains("without mass")
        );
    }
}
