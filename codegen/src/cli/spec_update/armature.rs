//! A URDF's rotor inertias in its scene file: `[scene] armature = { joint = I_a, … }`
//! (docs/spec.md), read and written with `toml_edit` (the file's comments and layout kept), for
//! the update of a URDF, which has no number of its own for them.

use toml_edit::{DocumentMut, InlineTable, Item};

/// The scene's armature of `joint` (0 when the table or the entry is absent; `None` when the
/// entry is not a number).
pub(super) fn armature(doc: &DocumentMut, joint: &str) -> Option<f64> {
    let Some(v) = doc
        .get("scene")
        .and_then(|s| s.get("armature"))
        .and_then(|a| a.get(joint))
    else {
        return Some(0.0);
    };
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// `doc` with the armature of each joint in `values` set (the table added when absent); an
/// entry that already reads as its value keeps its text. `Err` for a negative value.
pub(super) fn set_armature(doc: &mut DocumentMut, values: &[(&str, f64)]) -> Result<(), String> {
    if let Some((joint, v)) = values.iter().find(|(_, v)| *v < 0.0) {
        return Err(format!("joint `{joint}`: armature {v} < 0"));
    }
    if values.iter().all(|(j, v)| armature(doc, j) == Some(*v)) {
        return Ok(());
    }
    let scene = doc
        .entry("scene")
        .or_insert(Item::Table(Default::default()));
    let Some(scene) = scene.as_table_like_mut() else {
        return Err("the scene file's `scene` is not a table".into());
    };
    let table = scene
        .entry("armature")
        .or_insert(Item::Value(InlineTable::new().into()));
    let Some(table) = table.as_table_like_mut() else {
        return Err("the scene file's `scene.armature` is not a table".into());
    };
    for (joint, v) in values {
        let same = table
            .get(joint)
            .and_then(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
            == Some(*v);
        if !same {
            table.insert(joint, Item::Value(super::number(*v)));
        }
    }
    Ok(())
}
