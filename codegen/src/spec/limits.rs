//! Joint limits: a tree joint's range and speed bound as the spec writes them (TOML `limit`,
//! URDF `<limit>`), carried beside the model for the CLI tools (`codegen excite` keeps its
//! trajectory inside them). They are not part of the dynamics: nothing generated depends on
//! them (docs/spec.md, "Joint limits").

use super::closed;
use super::ir::{Kind, Spec};
use crate::diag::{Diagnostic, Diagnostics};

/// A joint's limits (rad or m; rad/s or m/s).
#[derive(Clone, Debug, PartialEq)]
pub struct JointLimit {
    /// The joint's name (as in [`runtime::model::Joint::name`]).
    pub joint: String,
    /// Lower bound of the coordinate.
    pub lower: f64,
    /// Upper bound of the coordinate, `> lower`.
    pub upper: f64,
    /// Bound on `|q̇|`, `> 0`, when given.
    pub velocity: Option<f64>,
}

/// The limits of the spec's moving joints, in the spec's joint order. Limits on a parallel
/// mechanism's or a closed loop's joints are errors at the key: the tools bound those in their
/// own coordinates (`--reach`, `--turn`, `--q-max`), where a joint's range has no direct
/// meaning yet.
pub(crate) fn collect(spec: &Spec, diags: &mut Diagnostics) -> Vec<JointLimit> {
    let tree = spec.platform.is_none() && !closed::is_closed(spec);
    let mut out = Vec::new();
    for j in &spec.joints {
        let Some(l) = &j.limit else { continue };
        if !tree {
            let what = if spec.platform.is_some() {
                "a parallel mechanism"
            } else {
                "closed loops"
            };
            diags.push(
                Diagnostic::error(format!(
                    "joint limits are read for trees only, and this spec describes {what}"
                ))
                .with_key(format!("{}.limit", j.key))
                .with_span(l.span.clone())
                .with_hint("remove `limit`; `codegen excite` bounds a platform by --reach and --turn and a closed loop's independent coordinates by --q-max"),
            );
            continue;
        }
        // A locked joint is fixed by now ([scene] locked): it has no coordinate left.
        if j.kind == Kind::Fixed {
            continue;
        }
        out.push(JointLimit {
            joint: j.name.clone(),
            lower: l.lower,
            upper: l.upper,
            velocity: l.velocity,
        });
    }
    out
}
