//! The TOML reader: spanned parse (`toml::de::DeTable`), then a hand-written walk over the
//! tree that reports every unknown key (with a suggestion), missing key, wrong type, non-finite
//! number and bad angle — all of them, not only the first — each at its exact span.
//!
//! By concept: [`syntax`] reports the parser's own errors; [`keys`] holds the key tables and
//! the unknown-key check every table runs first; [`values`] reads the typed values (strings,
//! numbers, angles, vectors, names, inertias); then one file per part of the spec —
//! [`mechanism`] (the `[mechanism]` table), [`platform`], [`scene`], [`bodies`], [`joints`],
//! [`springs`] and [`parallelogram`]. The walk itself ([`Reader::spec`]) is here.

use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::ir::{SceneSpec, Spec};
use crate::diag::Diagnostics;

mod bodies;
mod joints;
mod keys;
mod limit;
mod mechanism;
mod parallelogram;
mod parameters;
mod pattern;
mod platform;
mod scene;
mod springs;
mod syntax;
mod values;

use keys::TOP_KEYS;
use values::type_name;

type Val<'i> = Spanned<DeValue<'i>>;

/// Reads a TOML spec. `None` when the file could not be read far enough to validate it.
pub(crate) fn read(source: &str, diags: &mut Diagnostics) -> Option<Spec> {
    parsed(source, diags, |r, root| r.spec(root))
}

/// Parses `source` and walks its root table with a fresh [`Reader`]; `None` after a syntax
/// error (reported).
fn parsed<T>(
    source: &str,
    diags: &mut Diagnostics,
    walk: impl FnOnce(&mut Reader<'_>, &DeTable<'_>) -> T,
) -> Option<T> {
    let (root, errors) = DeTable::parse_recoverable(source);
    if !errors.is_empty() {
        syntax::report(source, errors, diags);
        return None;
    }
    let root = root.into_inner();
    let mut r = Reader {
        diags,
        joints_incomplete: false,
        params: Vec::new(),
        declared: Vec::new(),
        copy: None,
    };
    Some(walk(&mut r, &root))
}

/// Reads a `[scene]` sidecar: `[scene]` and optionally `[parameters]`, nothing else; `gravity`
/// is the spec's, replaced when the scene gives one. `None` when it could not be read.
pub(crate) fn read_scene(
    source: &str,
    diags: &mut Diagnostics,
    gravity: &mut runtime::model::Vec3,
) -> Option<SceneSpec> {
    parsed(source, diags, |r, root| {
        r.unknown_keys(root, &["scene", "parameters"], "");
        if let Some(v) = get(root, "parameters")
            && let Some(t) = r.table(v, "parameters")
        {
            r.parameter_table(t, "parameters");
        }
        let mut scene = SceneSpec::default();
        match get(root, "scene") {
            Some(v) => {
                scene.written = key_span(root, "scene");
                if let Some(t) = r.table(v, "scene") {
                    r.scene(t, &mut scene, gravity);
                }
            }
            None => {
                r.err(
                    "a scene file holds a [scene] table, and this one has none",
                    "scene",
                    0..0,
                )
                .hint =
                    Some("write the scene's keys under a [scene] header (docs/scene.md)".into());
            }
        }
        scene
    })
}

/// The walk's state. Entries with bad values are kept with placeholder values (the error is
/// already reported and lowering stops before using them), so that names still resolve and one
/// mistake does not cascade into "unknown body" errors.
struct Reader<'d> {
    diags: &'d mut Diagnostics,
    joints_incomplete: bool,
    /// `[parameters]`, as evaluated so far.
    params: Vec<(String, crate::spec::expr::Value)>,
    /// Every parameter name written (the file's and the patterns'), evaluated or not: a
    /// reference to one whose value failed is not reported again, and hints suggest them.
    declared: Vec<String>,
    /// The pattern copy being read, if any.
    copy: Option<pattern::PatternCopy>,
}

fn get<'t, 'i>(t: &'t DeTable<'i>, k: &str) -> Option<&'t Val<'i>> {
    t.get(k)
}

/// The span of key `k` in `t`.
fn key_span(t: &DeTable<'_>, k: &str) -> Option<Range<usize>> {
    t.get_key_value(k).map(|(key, _)| key.span())
}

impl Reader<'_> {
    /// The whole file: `[mechanism]`, `[platform]`, `[scene]` (whose `gravity` overrides the
    /// mechanism's), then `[[body]]`, `[[joint]]`, `[[spring]]` and `[[parallelogram]]` (expanded
    /// into bodies and joints), in that order.
    fn spec(&mut self, root: &DeTable<'_>) -> Spec {
        self.unknown_keys(root, TOP_KEYS, "");
        if let Some(v) = get(root, "parameters")
            && let Some(t) = self.table(v, "parameters")
        {
            self.parameter_table(t, "parameters");
        }
        let (name, mut gravity, anchor) = self.mechanism(root);
        let platform = get(root, "platform").and_then(|v| {
            let span = key_span(root, "platform").unwrap_or(v.span());
            self.platform(v, span)
        });
        let mut scene = SceneSpec {
            written: key_span(root, "scene"),
            ..SceneSpec::default()
        };
        if let Some(v) = get(root, "scene")
            && let Some(t) = self.table(v, "scene")
        {
            self.scene(t, &mut scene, &mut gravity);
        }
        let mut bodies: Vec<_> = self
            .entries(root, "body")
            .into_iter()
            .filter_map(|(i, t, span)| self.body(i, t, span))
            .collect();
        let mut joints: Vec<_> = self
            .entries(root, "joint")
            .into_iter()
            .filter_map(|(i, t, span)| self.joint(i, t, span))
            .collect();
        let mut springs: Vec<_> = self
            .entries(root, "spring")
            .into_iter()
            .filter_map(|(i, t, span)| self.spring(i, t, span))
            .collect();
        let mut parallelograms: Vec<_> = self
            .entries(root, "parallelogram")
            .into_iter()
            .filter_map(|(i, t, span)| self.parallelogram(i, t, span))
            .collect();
        // The patterns' copies follow the entries written out, in file order.
        let copies = self.patterns(root);
        bodies.extend(copies.bodies);
        joints.extend(copies.joints);
        springs.extend(copies.springs);
        parallelograms.extend(copies.parallelograms);
        let mut spec = Spec {
            name,
            gravity,
            bodies,
            joints,
            anchor,
            joints_incomplete: self.joints_incomplete,
            platform,
            scene,
            springs,
            parallelograms: Vec::new(),
            parallelogram_widths: Vec::new(),
            base_link: None,
            root_link: None,
        };
        self.expand_parallelograms(&mut spec, parallelograms);
        spec
    }

    /// The tables of an array of tables `[[what]]`, with index and span.
    fn entries<'t, 'i>(
        &mut self,
        root: &'t DeTable<'i>,
        what: &str,
    ) -> Vec<(usize, &'t DeTable<'i>, Range<usize>)> {
        let Some(v) = get(root, what) else {
            return Vec::new();
        };
        let DeValue::Array(a) = v.get_ref() else {
            let span = key_span(root, what).unwrap_or(v.span());
            self.err(
                format!(
                    "expected an array of tables [[{what}]], found {}",
                    type_name(v.get_ref())
                ),
                what,
                span,
            )
            .hint = Some(format!("write each entry under its own [[{what}]] header"));
            return Vec::new();
        };
        let mut out = Vec::new();
        for (i, e) in a.iter().enumerate() {
            match e.get_ref() {
                DeValue::Table(t) => out.push((i, t, e.span())),
                _ => self.type_error("a table", e, &format!("{what}[{i}]")),
            }
        }
        out
    }

    /// `body "name"` when the entry has a string name, else `body[i]` (in a pattern's copy,
    /// the name with `{i}` replaced).
    fn path(&self, t: &DeTable<'_>, what: &str, i: usize) -> String {
        match get(t, "name").map(|v| v.get_ref()) {
            Some(DeValue::String(s)) => format!("{what} \"{}\"", self.substitute(s)),
            _ => format!("{what}[{i}]"),
        }
    }
}
