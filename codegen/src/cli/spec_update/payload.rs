//! The `[scene] payload` part of the spec update: a constant payload is part of its body's
//! standard parameters (docs/method.md, "Identification"), so its ten numbers (`mass`, `com`,
//! `inertia` about the mass centre, in the body's frame) are unknowns like a body's. They are
//! solved for last, on what the bodies' own numbers cannot reach (a body written with
//! expressions, which the update leaves alone), so that a payload changes only where its body
//! cannot.

use toml_edit::{DocumentMut, Item};

use super::{Unknown, body_parameters, set_body, unwritable_keys};

/// The payload's unknowns, if the spec's `[scene]` has one written in plain numbers.
pub(super) fn payload_unknowns(
    doc: &DocumentMut,
    unknowns: &mut Vec<Unknown>,
    z0: &mut Vec<f64>,
    names: &mut Vec<String>,
    skipped: &mut Vec<String>,
) {
    let Some(t) = doc
        .get("scene")
        .and_then(|s| s.get("payload"))
        .and_then(Item::as_table_like)
    else {
        return;
    };
    match body_parameters(t) {
        Some(p) => {
            for (k, v) in p.into_iter().enumerate() {
                unknowns.push(Unknown::Payload { k });
                z0.push(v);
                names.push("[scene] payload".into());
            }
        }
        None => skipped.push(format!("[scene] payload{}", unwritable_keys(t))),
    }
}

/// Write the payload's numbers (`body` kept).
pub(super) fn set_payload(d: &mut DocumentMut, p: &[f64; 10]) -> Result<(), String> {
    let Some(t) = d
        .get_mut("scene")
        .and_then(|s| s.get_mut("payload"))
        .and_then(Item::as_table_like_mut)
    else {
        return Ok(());
    };
    set_body(t, p).map_err(|e| format!("[scene] payload: {e}"))
}
