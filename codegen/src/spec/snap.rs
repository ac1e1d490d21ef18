//! `[scene] snap = TOL`: take near-exact numbers as the exact ones they approximate.
//!
//! Real URDFs store π/2 as `1.570796325` (or `1.5708`), whose cosine is 1.8e-9 (or −3.7e-6),
//! not 0: every product with it survives constant folding and the generated code pays for it.
//! With a tolerance, this pass (run on the format-neutral spec, before lowering) replaces
//! * rotation-matrix entries of joint placements (`origin`, `child_origin`) within `TOL` of
//!   0, ±1 by those values,
//! * DH angles (`alpha`, `theta`) within `TOL` of a multiple of π/2 by `k · FRAC_PI_2` (the value
//!   whose sine and cosine the model takes as exact),
//! * joint-axis components within `TOL` of 0, ±1 by those values,
//! * translations and DH lengths (`a`, `d`) within `TOL` (m) of 0 by 0,
//!
//! and lists every change as a warning at the joint, with its size. The model then differs from
//! the file by at most `TOL` in each changed number: a documented model change traded for
//! fewer operations. Off by default: numbers are taken exactly as written.

use core::f64::consts::FRAC_PI_2;

use runtime::model::Transform;

use super::ir::{Placement, Spec};
use crate::diag::{Diagnostic, Diagnostics};

/// The nearest of 0, ±1 to `x` when within `tol` and not already equal.
fn near_unit(x: f64, tol: f64) -> Option<f64> {
    [0.0, 1.0, -1.0]
        .into_iter()
        .find(|t| x != *t && (x - t).abs() <= tol)
}

/// `k · π/2` when `x` is within `tol` of it and not already equal.
fn near_quarter_turn(x: f64, tol: f64) -> Option<f64> {
    let k = (x / FRAC_PI_2).round();
    let t = k * FRAC_PI_2;
    (x != t && (x - t).abs() <= tol && k.abs() <= 1e6).then_some(t)
}

/// 0 when `x` is within `tol` of it and not already 0.
fn near_zero(x: f64, tol: f64) -> Option<f64> {
    (x != 0.0 && x.abs() <= tol).then_some(0.0)
}

/// The changes made to one joint: `(what, before, after)`.
type Changes = Vec<(String, f64, f64)>;

fn snap_transform(t: &mut Transform, what: &str, tol: f64, changes: &mut Changes) {
    for r in 0..3 {
        for c in 0..3 {
            if let Some(v) = near_unit(t.rotation[r][c], tol) {
                changes.push((format!("{what} rotation[{r}][{c}]"), t.rotation[r][c], v));
                t.rotation[r][c] = v;
            }
        }
    }
    for (k, x) in t.translation.iter_mut().enumerate() {
        if let Some(v) = near_zero(*x, tol) {
            changes.push((format!("{what}.xyz[{k}]"), *x, v));
            *x = v;
        }
    }
}

/// Applies the snapping to `spec` when its scene asks for it; each change is a warning.
pub(crate) fn snap(spec: &mut Spec, diags: &mut Diagnostics) {
    let Some(tol) = spec.scene.snap else {
        return;
    };
    for j in &mut spec.joints {
        let mut changes = Changes::new();
        match &mut j.placement {
            Placement::Origin(t) => snap_transform(t, "origin", tol, &mut changes),
            Placement::Dh(dh) | Placement::Mdh(dh) => {
                for (name, x) in [("alpha", &mut dh.alpha), ("theta", &mut dh.theta)] {
                    if let Some(v) = near_quarter_turn(*x, tol) {
                        changes.push((format!("dh.{name}"), *x, v));
                        *x = v;
                    }
                }
                for (name, x) in [("a", &mut dh.a), ("d", &mut dh.d)] {
                    if let Some(v) = near_zero(*x, tol) {
                        changes.push((format!("dh.{name}"), *x, v));
                        *x = v;
                    }
                }
            }
        }
        if let Some(t) = &mut j.child_origin {
            snap_transform(t, "child_origin", tol, &mut changes);
        }
        for (k, a) in j.axes.iter_mut().enumerate() {
            for c in 0..3 {
                if let Some(v) = near_unit(a.v[c], tol) {
                    changes.push((format!("axis {k} component {c}"), a.v[c], v));
                    a.v[c] = v;
                }
            }
        }
        if changes.is_empty() {
            continue;
        }
        let worst = changes
            .iter()
            .map(|(_, a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let list: Vec<String> = changes
            .iter()
            .map(|(w, a, b)| format!("{w}: {a:e} → {b}"))
            .collect();
        diags.push(
            Diagnostic::warning(format!(
                "snapped {} number{} of joint \"{}\" (largest change {worst:.1e})",
                changes.len(),
                if changes.len() == 1 { "" } else { "s" },
                j.name
            ))
            .with_key(j.key.clone())
            .with_span(j.span.clone())
            .with_hint(format!(
                "[scene] snap = {tol:e} takes near-exact numbers as exact: {}",
                list.join("; ")
            )),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::approx_constant)] // the point: values as rounded URDFs write them
    fn snaps_only_within_tolerance_and_never_exact_values() {
        assert_eq!(near_unit(1.0 - 1e-9, 1e-6), Some(1.0));
        assert_eq!(near_unit(-1e-9, 1e-6), Some(0.0));
        assert_eq!(near_unit(1e-3, 1e-6), None);
        assert_eq!(near_unit(0.0, 1e-6), None);
        assert_eq!(near_quarter_turn(1.570796325, 1e-6), Some(FRAC_PI_2));
        assert_eq!(near_quarter_turn(-3.14159, 1e-5), Some(-2.0 * FRAC_PI_2));
        assert_eq!(near_quarter_turn(1.5708, 1e-6), None);
        assert_eq!(near_quarter_turn(FRAC_PI_2, 1e-6), None);
        assert_eq!(near_zero(2e-7, 1e-6), Some(0.0));
        assert_eq!(near_zero(2e-5, 1e-6), None);
    }
}
