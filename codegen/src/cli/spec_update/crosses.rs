//! The universal joints' crosses in the spec update (docs/identification.md, "The updated
//! spec of a platform"): a U joint's `cross` (docs/spec.md, "Joint kinds") is a body's ten
//! standard parameters in the cross's frame, so they are unknowns like a body's, per
//! `[[joint]]` entry and per copy of a `[[pattern.joint]]` entry (and so a parallelogram's
//! `cross`, that of its elbow's U `<name>_elbow`, per `[[parallelogram]]` entry and per copy
//! of a `[[pattern.parallelogram]]` entry: docs/spec.md, "Parallelograms"), at the values the loader
//! gives them (`codegen::spec::written_crosses`; zero where the spec writes no `cross`). They
//! are solved for with the payload, on what the bodies' and drives' numbers leave (the
//! base parameters that only a cross moves, such as a Gough–Stewart's `MZ_u<i>_cross`), so
//! that a cross changes only where its neighbours cannot. A top-level joint's cross is written
//! as numbers, a pattern joint's as expressions indexing per-copy arrays in `[parameters]`
//! (`mass = "identified_u_cross_mass[i]"`), the key added where absent.
//!
//! A cross's mass sits at the joint's centre, so it moves nothing (a U joint on the base) or
//! what the parent body's numbers can move too: the minimum-norm change leaves it near its old
//! value, often zero, while its first moment changes. Where that is no body ([`free_masses`])
//! the update takes twice the least mass that makes the cross physical, `2 hᵀ Σ⁻¹ h` (`h` the
//! first moment, `Σ` the second moment of mass about the cross's origin), the parent's numbers
//! taking up the difference.

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use toml_edit::{DocumentMut, InlineTable, Item};

use runtime::model::{Mat3, Vec3};

use super::patterns::{per_copy_keys, put_arrays, stem};
use super::{
    EntryAt, Unknown, body_parameters, broken, from_standard, involved, physics, set_body,
    unwritable_keys,
};

/// The unknowns of the crosses: per universal joint entry whose copies all have a cross body
/// in the model (`written`), ten per copy. A top-level cross written with expressions keeps
/// its text (skipped, as a body's).
pub(super) fn cross_unknowns(
    doc: &DocumentMut,
    written: &[(String, f64, Vec3, Mat3)],
    unknowns: &mut Vec<Unknown>,
    z0: &mut Vec<f64>,
    names: &mut Vec<String>,
    skipped: &mut Vec<String>,
) {
    let mut entries: Vec<(&'static str, EntryAt, &toml_edit::Table, usize)> = Vec::new();
    for array in ARRAYS {
        if let Some(a) = doc.get(array).and_then(Item::as_array_of_tables) {
            for (index, t) in a.iter().enumerate() {
                let at = EntryAt {
                    pattern: None,
                    index,
                };
                entries.push((array, at, t, 0));
            }
        }
    }
    if let Some(patterns) = doc.get("pattern").and_then(Item::as_array_of_tables) {
        for (pattern, p) in patterns.iter().enumerate() {
            let copies = p.get("copies").and_then(|c| c.as_integer()).unwrap_or(0) as usize;
            for array in ARRAYS {
                let Some(a) = p.get(array).and_then(Item::as_array_of_tables) else {
                    continue;
                };
                for (index, t) in a.iter().enumerate() {
                    let at = EntryAt {
                        pattern: Some(pattern),
                        index,
                    };
                    entries.push((array, at, t, copies));
                }
            }
        }
    }
    for (array, at, t, copies) in entries {
        let template = t.get("name").and_then(|n| n.as_str()).unwrap_or("?");
        // The U joint the cross belongs to: the entry's, or a parallelogram's elbow.
        let joint = u_joint(array, template);
        let copy_names: Vec<(usize, String)> = if at.pattern.is_none() {
            vec![(1, joint.clone())]
        } else {
            (1..=copies)
                .map(|i| (i, joint.replace("{i}", &i.to_string())))
                .collect()
        };
        let found: Vec<Option<[f64; 10]>> = copy_names
            .iter()
            .map(|(_, n)| {
                written
                    .iter()
                    .find(|c| c.0 == *n)
                    .map(|c| codegen::dynamics::body_standard_parameters(c.1, &c.2, &c.3))
            })
            .collect();
        if found.iter().all(Option::is_none) {
            // Not a universal joint with a cross body (another kind, or one into the platform).
            continue;
        }
        let name = format!("{array} `{template}` cross");
        let plain = t
            .get("cross")
            .and_then(Item::as_table_like)
            .is_none_or(|c| body_parameters(c).is_some());
        let values: Option<Vec<[f64; 10]>> = found.into_iter().collect();
        let (Some(values), true) = (values, at.pattern.is_some() || plain) else {
            let keys = t
                .get("cross")
                .and_then(Item::as_table_like)
                .map(unwritable_keys)
                .unwrap_or_default();
            skipped.push(format!("{name}{keys}"));
            continue;
        };
        for ((copy, _), v) in copy_names.iter().zip(values) {
            for (k, x) in v.into_iter().enumerate() {
                unknowns.push(Unknown::Cross {
                    array,
                    at,
                    copy: *copy,
                    k,
                });
                z0.push(x);
                names.push(name.clone());
            }
        }
    }
}

/// The arrays whose entries carry a `cross`: a universal joint's, a parallelogram's elbow's.
const ARRAYS: [&str; 2] = ["joint", "parallelogram"];

/// The universal joint of entry `template` of `array`: the joint, or a parallelogram's elbow
/// U `<name>_elbow`.
fn u_joint(array: &str, template: &str) -> String {
    if array == "parallelogram" {
        format!("{template}_elbow")
    } else {
        template.to_string()
    }
}

/// Write an entry's crosses (standard parameters per copy; one for a top-level entry), adding
/// the `cross` key where absent.
pub(super) fn set_crosses(
    d: &mut DocumentMut,
    array: &str,
    at: EntryAt,
    copies: &[[f64; 10]],
) -> Result<(), String> {
    let Some(t) = at.table_mut(d, array) else {
        return Ok(());
    };
    let template = t
        .get("name")
        .and_then(|n| n.as_str())
        .unwrap_or(array)
        .to_string();
    if t.get("cross").and_then(Item::as_table_like).is_none() {
        t.insert(
            "cross",
            Item::Value(toml_edit::Value::InlineTable(InlineTable::new())),
        );
    }
    let c = t
        .get_mut("cross")
        .and_then(Item::as_table_like_mut)
        .ok_or("a cross entry vanished")?;
    let what = format!("{array} `{template}` cross");
    match at.pattern {
        None => set_body(c, &copies[0]).map_err(|e| format!("{what}: {e}")),
        Some(_) => {
            let stem = format!("{}_cross", stem(&u_joint(array, &template)));
            let arrays = per_copy_keys(c, &stem, &what, copies)?;
            put_arrays(d, arrays)
        }
    }
}

/// The crosses whose numbers in `z` are no body (a first moment without mass, or not physical
/// with the mass they have) get the mass `2 hᵀ Σ⁻¹ h`, twice the least with which the cross is
/// physical (its second moment `Σ` about its origin positive definite; else `2 |h|² / λ_max(Σ)`,
/// or `|h|` per metre when `Σ` has no positive direction), where that leaves the base
/// parameters as they are: at once when the mass moves none (a cross at a fixed point, column
/// `M` of `p` zero), else when the other unknowns that are not `late` (the bodies and drives)
/// take up what it moves (a cross's mass sits at the joint's centre, fixed in the parent body,
/// so the parent's numbers can: docs/method.md, regrouping). `z` and `dz` follow.
pub(super) fn free_masses(
    unknowns: &[Unknown],
    late: &[bool],
    z: &mut [f64],
    dz: &mut DVector<f64>,
    p: &DMatrix<f64>,
) {
    for c in 0..unknowns.len() {
        if !matches!(unknowns[c], Unknown::Cross { k: 0, .. }) || c + 10 > z.len() {
            continue;
        }
        let m = c + 9;
        let sp: [f64; 10] = std::array::from_fn(|k| z[c + k]);
        let h = [sp[6], sp[7], sp[8]];
        if h.iter().all(|x| *x == 0.0) {
            continue;
        }
        if from_standard(&sp).is_ok_and(|(m, _, ic)| physics(m, &ic).is_empty()) {
            continue;
        }
        let delta = least_mass(&sp) - z[m];
        let moved = p.column(m) * delta;
        if moved.amax() > 0.0 {
            // The others' minimum-norm change that cancels what the mass moves.
            let others: Vec<usize> = (0..unknowns.len()).filter(|&k| !late[k]).collect();
            if others.is_empty() {
                continue;
            }
            let po = DMatrix::from_fn(p.nrows(), others.len(), |r, k| p[(r, others[k])]);
            let Ok(pinv) = po
                .clone()
                .pseudo_inverse(1e-12 * p.norm().max(f64::MIN_POSITIVE))
            else {
                continue;
            };
            let x = pinv * (-&moved);
            let rest = &po * &x + &moved;
            if rest.amax() > 1e-10 * moved.amax() {
                continue;
            }
            for (k, &o) in others.iter().enumerate() {
                z[o] += x[k];
                dz[o] += x[k];
            }
        }
        dz[m] += delta;
        z[m] += delta;
    }
}

/// Twice the least mass with which standard parameters `sp` (their mass aside) are a body.
fn least_mass(sp: &[f64; 10]) -> f64 {
    let jo = DMatrix::from_row_slice(
        3,
        3,
        &[
            sp[0], sp[1], sp[2], sp[1], sp[3], sp[4], sp[2], sp[4], sp[5],
        ],
    );
    let sigma = DMatrix::identity(3, 3) * (jo.trace() / 2.0) - &jo;
    let h = DVector::from_column_slice(&sp[6..9]);
    let hh = h.norm_squared();
    let e = SymmetricEigen::new(sigma.clone());
    let (lo, hi) = (e.eigenvalues.min(), e.eigenvalues.max());
    if lo > 1e-12 * hi
        && let Some(inv) = sigma.try_inverse()
    {
        2.0 * (h.transpose() * inv * &h)[(0, 0)]
    } else if hi > 0.0 {
        2.0 * hh / hi
    } else {
        hh.sqrt()
    }
}

/// The changed crosses that break physics, as [`super::consistency`].
pub(super) fn cross_consistency(
    unknowns: &[Unknown],
    z: &[f64],
    names: &[String],
    changed: &[String],
    p: &DMatrix<f64>,
) -> Vec<(String, String, Vec<usize>)> {
    let mut out = Vec::new();
    for (c, u) in unknowns.iter().enumerate() {
        let Unknown::Cross {
            array,
            at,
            copy,
            k: 0,
        } = u
        else {
            continue;
        };
        if c + 10 > z.len() || !changed.contains(&names[c]) {
            continue;
        }
        let sp: [f64; 10] = std::array::from_fn(|k| z[c + k]);
        let Some(what) = broken(&sp) else {
            continue;
        };
        let entry = names[c]
            .trim_start_matches(&format!("{array} `"))
            .trim_end_matches("` cross");
        let joint = u_joint(array, entry);
        let joint = if at.pattern.is_some() {
            joint.replace("{i}", &copy.to_string())
        } else {
            joint
        };
        out.push((format!("{joint}_cross"), what, involved(p, c..c + 10)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With `Σ = diag(s)` the least mass is `Σ_k h_k² / s_k` (worked by hand below); the
    /// update's is twice that, physical, and just under the least is not.
    #[test]
    fn the_least_mass_is_that_of_the_second_moment() {
        // Σ = diag(1, 2, 4) ⇔ J_o = tr(Σ)·1 − Σ = diag(6, 5, 3).
        let sp = [6.0, 0.0, 0.0, 5.0, 0.0, 3.0, 1.0, 2.0, 2.0, 0.0];
        let want = 2.0 * (1.0 / 1.0 + 4.0 / 2.0 + 4.0 / 4.0);
        assert!((least_mass(&sp) - want).abs() <= 1e-14 * want);
        let mut with = sp;
        with[9] = want;
        let (m, _, ic) = from_standard(&with).unwrap();
        assert!(physics(m, &ic).is_empty(), "{:?}", physics(m, &ic));
        with[9] = want / 2.0 * 0.999;
        let (m, _, ic) = from_standard(&with).unwrap();
        assert!(!physics(m, &ic).is_empty());
    }
}
