//! `[[body]]` entries: `name`, `mass` (required), `com`, `inertia`, `inertia_rpy`; and a
//! universal joint's `cross`, the same inertial keys without a name (docs/spec.md, "Joint
//! kinds").

use std::ops::Range;

use toml::de::DeTable;

use super::keys::{BODY_KEYS, CROSS_KEYS};
use super::{Reader, get};
use runtime::model::Transform;

use crate::spec::ir::BodySpec;

impl Reader<'_> {
    pub(super) fn body(
        &mut self,
        i: usize,
        t: &DeTable<'_>,
        span: Range<usize>,
    ) -> Option<BodySpec> {
        let path = self.path(t, "body", i);
        self.unknown_keys(t, BODY_KEYS, &path);
        let name = self.name(t, &path, span.clone());
        let name_span = get(t, "name").map_or(span.clone(), |v| v.span());
        let mut b = self.inertial(t, path, span);
        b.name = name?;
        b.span = Some(name_span);
        Some(b)
    }

    /// A universal joint's `cross = { mass, com, inertia, inertia_rpy }` (table `t` at `span`,
    /// key path `path`, e.g. `joint "u1".cross`): the body `<joint>_cross`, read as a body's
    /// inertial keys are.
    pub(super) fn cross(
        &mut self,
        joint: &str,
        t: &DeTable<'_>,
        path: String,
        span: Range<usize>,
    ) -> BodySpec {
        self.unknown_keys(t, CROSS_KEYS, &path);
        let mut b = self.inertial(t, path, span.clone());
        b.name = format!("{joint}_cross");
        b.span = Some(span);
        b
    }

    /// `mass` (required), `com`, `inertia` and `inertia_rpy` of table `t` (at `span`, key
    /// path `path`), with placeholders after errors (already reported); the name is empty.
    fn inertial(&mut self, t: &DeTable<'_>, path: String, span: Range<usize>) -> BodySpec {
        let mut mass_span = span.clone();
        let mass = match get(t, "mass") {
            None => {
                self.missing(
                    "mass",
                    &path,
                    span.clone(),
                    "mass in kg; write mass = 0.0 for a massless body",
                );
                None
            }
            Some(v) => {
                mass_span = v.span();
                self.number(v, &format!("{path}.mass"))
            }
        };
        let com = match get(t, "com") {
            None => Some([0.0; 3]),
            Some(v) => self.triple(v, &format!("{path}.com"), false),
        };
        let mut inertia_span = span.clone();
        let inertia = match get(t, "inertia") {
            None => Some([[0.0; 3]; 3]),
            Some(v) => {
                inertia_span = v.span();
                self.inertia(v, &format!("{path}.inertia"))
            }
        };
        let rpy = match get(t, "inertia_rpy") {
            None => Some([0.0; 3]),
            Some(v) => self.triple(v, &format!("{path}.inertia_rpy"), true),
        };
        let inertia = inertia.zip(rpy).map(|(i, rpy)| {
            crate::spec::geom::rotate_inertia(&runtime::model::rpy_to_matrix(rpy), &i)
        });
        BodySpec {
            name: String::new(),
            key: path,
            span: Some(span),
            mass: mass.unwrap_or(0.0),
            mass_span: Some(mass_span),
            com: com.unwrap_or([0.0; 3]),
            inertia: inertia.unwrap_or([[0.0; 3]; 3]),
            inertia_span: Some(inertia_span),
            own_inertia: None,
            own_frame: Transform::IDENTITY,
        }
    }
}
