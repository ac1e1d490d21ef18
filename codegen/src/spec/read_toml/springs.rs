//! `[[spring]]` entries: linear springs (and dampers) between points of two bodies.

use std::ops::Range;

use toml::de::DeTable;

use super::keys::SPRING_KEYS;
use super::{Reader, get};
use crate::spec::ir::{Named, SpringSpec};

impl Reader<'_> {
    /// `[[spring]]`: `name`, `body_a`, `body_b` (required), `point_a`, `point_b` (default the
    /// body frame's origin), `stiffness` (N/m, required), `rest_length` (m, required),
    /// `damping` (N·s/m, default 0); the numbers finite and not negative.
    pub(super) fn spring(
        &mut self,
        i: usize,
        t: &DeTable<'_>,
        span: Range<usize>,
    ) -> Option<SpringSpec> {
        let path = self.path(t, "spring", i);
        self.unknown_keys(t, SPRING_KEYS, &path);
        let name = self.name(t, &path, span.clone());
        let body = |r: &mut Self, k: &str| -> Option<Named> {
            let key = format!("{path}.{k}");
            match get(t, k) {
                None => {
                    r.missing(k, &path, span.clone(), "a body name, or \"base\"");
                    None
                }
                Some(v) => r.string(v, &key).map(|name| Named {
                    name,
                    key,
                    span: Some(v.span()),
                }),
            }
        };
        let body_a = body(self, "body_a");
        let body_b = body(self, "body_b");
        let point = |r: &mut Self, k: &str| match get(t, k) {
            None => Some([0.0; 3]),
            Some(v) => r.triple(v, &format!("{path}.{k}"), false),
        };
        let point_a = point(self, "point_a");
        let point_b = point(self, "point_b");
        let number = |r: &mut Self, k: &str, default: Option<f64>, hint: &str| -> Option<f64> {
            match get(t, k) {
                None => {
                    if default.is_none() {
                        r.missing(k, &path, span.clone(), hint);
                    }
                    default
                }
                Some(v) => {
                    let key = format!("{path}.{k}");
                    let x = r.number(v, &key)?;
                    if !(x.is_finite() && x >= 0.0) {
                        r.err(
                            format!("{k} must be finite and not negative, found {x}"),
                            &key,
                            v.span(),
                        )
                        .hint = Some(hint.into());
                        return None;
                    }
                    Some(x)
                }
            }
        };
        let stiffness = number(
            self,
            "stiffness",
            None,
            "stiffness in N/m (0 for a pure damper)",
        );
        let rest_length = number(self, "rest_length", None, "rest length in m");
        let damping = number(self, "damping", Some(0.0), "damping in N·s/m");
        Some(SpringSpec {
            name: name?,
            key: path.clone(),
            span: Some(span.clone()),
            body_a: body_a?,
            point_a: point_a?,
            body_b: body_b?,
            point_b: point_b?,
            stiffness: stiffness?,
            rest_length: rest_length?,
            damping: damping?,
        })
    }
}
