//! The `[mechanism]` table: `name` (a Rust module name), `gravity`, `source`.

use std::ops::Range;

use runtime::model::Vec3;
use toml::de::DeTable;

use super::keys::MECH_KEYS;
use super::{Reader, Val, get};
use crate::spec::sanitize_name;

impl Reader<'_> {
    /// The mechanism's name (`"unnamed"` when it is missing or bad), its gravity (the default
    /// when missing or bad) and the span the file's mechanism-wide diagnostics point at (the
    /// name, else the table, else the start of the file).
    pub(super) fn mechanism(&mut self, root: &DeTable<'_>) -> (String, Vec3, Option<Range<usize>>) {
        let mut name = String::from("unnamed");
        let mut gravity = [0.0, 0.0, -9.81];
        let mut anchor = Some(0..0);
        match get(root, "mechanism") {
            None => {
                self.err("missing [mechanism] table", "mechanism", 0..0)
                    .hint = Some("start the file with [mechanism] and name = \"...\"".into());
            }
            Some(v) => {
                if let Some(t) = self.table(v, "mechanism") {
                    anchor = Some(v.span());
                    self.unknown_keys(t, MECH_KEYS, "mechanism");
                    if let Some((n, span)) = self.mechanism_name(t, v) {
                        anchor = Some(span);
                        name = n;
                    }
                    if let Some(g) = get(t, "gravity")
                        && let Some(g) = self.triple(g, "mechanism.gravity", false)
                    {
                        gravity = g;
                    }
                    if let Some(s) = get(t, "source") {
                        self.string(s, "mechanism.source");
                    }
                }
            }
        }
        (name, gravity, anchor)
    }

    /// `mechanism.name`, with its span, when it is a string (reported when it is missing, too
    /// long or not a module name; returned all the same when it is a string).
    fn mechanism_name(&mut self, t: &DeTable<'_>, v: &Val<'_>) -> Option<(String, Range<usize>)> {
        let Some(nv) = get(t, "name") else {
            self.missing(
                "name",
                "mechanism",
                v.span(),
                "the name is used as a Rust module name, e.g. name = \"puma560\"",
            );
            return None;
        };
        let n = self.string(nv, "mechanism.name")?;
        if let Some(d) = crate::spec::name_too_long(&n) {
            self.diags
                .push(d.with_key("mechanism.name").with_span(nv.span()));
        } else if !crate::spec::is_module_name(&n) {
            self.err(
                format!("invalid mechanism name {n:?}"),
                "mechanism.name",
                nv.span(),
            )
            .hint = Some(format!(
                "the name is used as a Rust module name and must match [a-z][a-z0-9_]*, e.g. \"{}\"",
                sanitize_name(&n)
            ));
        }
        Some((n, nv.span()))
    }
}
