//! `[[joint]]` entries: `name`, `kind`, `parent`, `child` (required), one placement (`origin`,
//! `dh` or `mdh`), the axes the kind takes (`axis` or `axes`), `actuated`, the drive
//! (`damping`, `friction`, `armature`), `child_origin`, `home`, a universal joint's `cross` and
//! `limit` (`super::limit`), read in that order.

use std::ops::Range;

use runtime::model::Transform;
use toml::de::{DeTable, DeValue};

use super::keys::{DH_KEYS, JOINT_KEYS};
use super::{Reader, Val, get, key_span};
use crate::diag::Diagnostic;
use crate::spec::ir::{AxisSpec, BodySpec, Dh, DriveSpec, JointSpec, Kind, Placement};
use crate::spec::suggest_hint;

/// The joint entry being read: its table, its key path (`joint "name"` or `joint[i]`) and its
/// span (where missing keys are reported).
#[derive(Clone, Copy)]
struct Entry<'e, 'i> {
    t: &'e DeTable<'i>,
    path: &'e str,
    span: &'e Range<usize>,
}

impl<'e, 'i> Entry<'e, 'i> {
    fn get(&self, k: &str) -> Option<&'e Val<'i>> {
        get(self.t, k)
    }

    /// The full key of `k` in this entry.
    fn key(&self, k: &str) -> String {
        format!("{}.{k}", self.path)
    }

    /// The span of key `k`, else the entry's.
    fn key_span(&self, k: &str) -> Range<usize> {
        key_span(self.t, k).unwrap_or(self.span.clone())
    }
}

impl Reader<'_> {
    pub(super) fn joint(
        &mut self,
        i: usize,
        t: &DeTable<'_>,
        span: Range<usize>,
    ) -> Option<JointSpec> {
        let path = self.path(t, "joint", i);
        self.unknown_keys(t, JOINT_KEYS, &path);
        let name = self.name(t, &path, span.clone());
        let name_span = get(t, "name").map_or(span.clone(), |v| v.span());
        let kind_span = get(t, "kind").map_or(name_span.clone(), |v| v.span());
        let e = Entry {
            t,
            path: &path,
            span: &span,
        };
        let kind = self.joint_kind(e);
        let parent = self.joint_end(e, "parent");
        let child = self.joint_end(e, "child");
        let (placement, placed_by) = self.joint_placement(e);
        let axes = match kind {
            Some(kind) => self.joint_axes(e, kind, placed_by),
            None => Vec::new(),
        };
        let actuated_span = key_span(t, "actuated");
        let actuated = self.joint_actuated(e);
        let drive = self.joint_drive(e);
        let child_origin_span = key_span(t, "child_origin");
        let child_origin = self.joint_child_origin(e);
        let home_span = e.get("home").map(|v| v.span());
        let home = self.joint_home(e, kind);
        let cross = self.joint_cross(e, kind, name.as_deref());
        let limit = e
            .get("limit")
            .and_then(|v| self.limit(v, &e.key("limit"), kind));
        let (Some((parent, parent_span)), Some((child, child_span))) = (parent, child) else {
            self.joints_incomplete = true;
            return None;
        };
        Some(JointSpec {
            name: name.unwrap_or(format!("joint[{i}]")),
            key: path,
            span: Some(name_span),
            kind: kind.unwrap_or(Kind::Revolute),
            kind_span: Some(kind_span),
            parent,
            parent_span: Some(parent_span),
            child,
            child_span: Some(child_span),
            placement,
            axes,
            actuated,
            actuated_span,
            child_origin,
            child_origin_span,
            home,
            home_span,
            drive,
            cross,
            limit,
        })
    }

    /// `cross`: a universal joint's cross body (docs/spec.md, "Joint kinds"); `None` when not
    /// written (massless) or after an error (reported).
    fn joint_cross(
        &mut self,
        e: Entry<'_, '_>,
        kind: Option<Kind>,
        name: Option<&str>,
    ) -> Option<BodySpec> {
        let v = e.get("cross")?;
        let key = e.key("cross");
        match kind {
            Some(Kind::Universal) => {}
            Some(k) => {
                self.err(
                    format!("`cross` is for universal joints, not a {} joint", k.word()),
                    &key,
                    v.span(),
                )
                .hint = Some(
                    "`cross` gives the mass of a universal joint's cross; put a body's mass on its [[body]] entry"
                        .into(),
                );
                return None;
            }
            None => return None,
        }
        let t = self.table(v, &key)?;
        Some(self.cross(name.unwrap_or("joint"), t, key, v.span()))
    }

    /// `home`: the coordinate at home, an angle (revolute) or a length (prismatic); 0 when not
    /// written.
    fn joint_home(&mut self, e: Entry<'_, '_>, kind: Option<Kind>) -> f64 {
        let Some(v) = e.get("home") else {
            return 0.0;
        };
        let key = e.key("home");
        match kind {
            Some(Kind::Revolute) => self.angle(v, &key).unwrap_or(0.0),
            Some(Kind::Prismatic) => self.number(v, &key).unwrap_or(0.0),
            Some(k) => {
                self.err(
                    format!(
                        "`home` is for revolute and prismatic joints, not {}",
                        k.word()
                    ),
                    &key,
                    v.span(),
                )
                .hint = Some(
                    "a joint of one coordinate may carry its value at home; remove `home` here"
                        .into(),
                );
                0.0
            }
            None => 0.0,
        }
    }

    /// `kind` (required).
    fn joint_kind(&mut self, e: Entry<'_, '_>) -> Option<Kind> {
        match e.get("kind") {
            None => {
                self.missing(
                    "kind",
                    e.path,
                    e.span.clone(),
                    "kind = \"revolute\", \"prismatic\", \"universal\", \"spherical\" or \"fixed\"",
                );
                None
            }
            Some(v) => self.kind(v, &e.key("kind")),
        }
    }

    /// `parent` or `child` (required): the body name with its span.
    fn joint_end(&mut self, e: Entry<'_, '_>, what: &str) -> Option<(String, Range<usize>)> {
        match e.get(what) {
            None => {
                self.missing(
                    what,
                    e.path,
                    e.span.clone(),
                    if what == "parent" {
                        "the parent is a body name or \"base\" (the fixed world)"
                    } else {
                        "the child is a body name"
                    },
                );
                None
            }
            Some(v) => Some((self.string(v, &e.key(what))?, v.span())),
        }
    }

    /// The placement: at most one of `origin`, `dh`, `mdh` (none: the identity; a bad one or
    /// more than one: the identity as a placeholder), with the key it was given by (the first
    /// in the file).
    fn joint_placement(&mut self, e: Entry<'_, '_>) -> (Placement, Option<&'static str>) {
        let mut present: Vec<(&'static str, &Val<'_>)> = ["origin", "dh", "mdh"]
            .iter()
            .filter_map(|k| e.get(k).map(|v| (*k, v)))
            .collect();
        present.sort_by_key(|(k, _)| key_span(e.t, k).map_or(0, |s| s.start));
        let mut placement_ok = true;
        if present.len() > 1 {
            placement_ok = false;
            for (k, _) in &present[1..] {
                let ks = e.key_span(k);
                self.err(
                    format!(
                        "a joint has one placement, but \"{}\" is also given",
                        present[0].0
                    ),
                    &e.key(k),
                    ks,
                )
                .hint = Some(
                    "use exactly one of `origin` (+ `axis`), `dh` or `mdh` (or none for the identity)"
                        .into(),
                );
            }
        }
        let placement = match present.first() {
            None => Some(Placement::Origin(Transform::IDENTITY)),
            Some(("origin", v)) => self.origin(v, &e.key("origin")),
            Some((k, v)) => {
                let dh = self.dh(v, &e.key(k));
                dh.map(|dh| {
                    if *k == "dh" {
                        Placement::Dh(dh)
                    } else {
                        Placement::Mdh(dh)
                    }
                })
            }
        };
        let placement = placement
            .filter(|_| placement_ok)
            .unwrap_or(Placement::Origin(Transform::IDENTITY));
        (placement, present.first().map(|(k, _)| *k))
    }

    /// The axes, as the kind (and a DH placement) allows; empty after any error.
    fn joint_axes(
        &mut self,
        e: Entry<'_, '_>,
        kind: Kind,
        placed_by: Option<&str>,
    ) -> Vec<AxisSpec> {
        let is_dh = matches!(placed_by, Some("dh" | "mdh"));
        let mut axes = Vec::new();
        let mut axes_ok = true;
        if let Some(k @ ("dh" | "mdh")) = placed_by
            && !matches!(kind, Kind::Revolute | Kind::Prismatic | Kind::Fixed)
        {
            self.wrong_key(
                e,
                k,
                format!("`{k}` placement is not allowed for a {} joint", kind.word()),
                "DH parameters describe revolute, prismatic or fixed joints; use `origin` (+ `axes`) here",
            );
            axes_ok = false;
        }
        let kind_ok = match kind {
            Kind::Revolute | Kind::Prismatic => self.one_axis(e, kind, is_dh, &mut axes),
            Kind::Universal => self.two_axes(e, &mut axes),
            Kind::Spherical | Kind::Fixed => self.no_axes(e, kind),
        };
        if axes_ok && kind_ok { axes } else { Vec::new() }
    }

    /// A revolute or prismatic joint: `axis` (not with a DH placement), no `axes`. `false`
    /// after an error.
    fn one_axis(
        &mut self,
        e: Entry<'_, '_>,
        kind: Kind,
        is_dh: bool,
        axes: &mut Vec<AxisSpec>,
    ) -> bool {
        let mut ok = true;
        if e.get("axes").is_some() {
            self.wrong_key(
                e,
                "axes",
                format!(
                    "`axes` is for universal joints, not a {} joint",
                    kind.word()
                ),
                "use `axis = [x, y, z]`",
            );
            ok = false;
        }
        if let Some(v) = e.get("axis") {
            if is_dh {
                self.wrong_key(
                    e,
                    "axis",
                    "`axis` cannot be combined with a DH placement".into(),
                    "a DH joint moves about (or along) the z axis of its frame; remove `axis`",
                );
                ok = false;
            } else {
                let key = e.key("axis");
                match self.triple(v, &key, false) {
                    Some(a) => axes.push(AxisSpec {
                        v: a,
                        key,
                        span: Some(v.span()),
                    }),
                    None => ok = false,
                }
            }
        }
        ok
    }

    /// A universal joint: `axes`, two of them, no `axis`. `false` after an error.
    fn two_axes(&mut self, e: Entry<'_, '_>, axes: &mut Vec<AxisSpec>) -> bool {
        let mut ok = true;
        if e.get("axis").is_some() {
            self.wrong_key(
                e,
                "axis",
                "a universal joint has two axes".into(),
                "use `axes = [[1, 0, 0], [0, 1, 0]]` (first rotation about axes[0], then about axes[1])",
            );
            ok = false;
        }
        if let Some(v) = e.get("axes") {
            let key = e.key("axes");
            match v.get_ref() {
                DeValue::Array(a) if a.len() == 2 => {
                    for (k, x) in a.iter().enumerate() {
                        let ek = format!("{key}[{k}]");
                        match self.triple(x, &ek, false) {
                            Some(a) => axes.push(AxisSpec {
                                v: a,
                                key: ek,
                                span: Some(x.span()),
                            }),
                            None => ok = false,
                        }
                    }
                }
                _ => {
                    self.err("expected two axes, [[x, y, z], [x, y, z]]", &key, v.span());
                    ok = false;
                }
            }
        }
        ok
    }

    /// A spherical or fixed joint: neither `axis` nor `axes`. `false` after an error.
    fn no_axes(&mut self, e: Entry<'_, '_>, kind: Kind) -> bool {
        let mut ok = true;
        for k in ["axis", "axes"] {
            if e.get(k).is_some() {
                self.wrong_key(
                    e,
                    k,
                    format!("a {} joint takes no `{k}`", kind.word()),
                    if kind == Kind::Spherical {
                        "a spherical joint rotates about x, then y, then z of its joint frame; orient it with `origin.rpy`"
                    } else {
                        "remove it"
                    },
                );
                ok = false;
            }
        }
        ok
    }

    /// An error at key `key` of the entry (at the entry when the key is absent).
    fn wrong_key(&mut self, e: Entry<'_, '_>, key: &str, msg: String, hint: &str) {
        let ks = e.key_span(key);
        self.err(msg, &e.key(key), ks).hint = Some(hint.to_owned());
    }

    /// `actuated` (default `false`).
    fn joint_actuated(&mut self, e: Entry<'_, '_>) -> bool {
        match e.get("actuated") {
            Some(v) => self.boolean(v, &e.key("actuated")).unwrap_or(false),
            None => false,
        }
    }

    /// `damping`, `friction`, `armature`: non-negative numbers (default 0).
    fn joint_drive(&mut self, e: Entry<'_, '_>) -> DriveSpec {
        let mut drive = DriveSpec::default();
        for (k, slot) in [
            ("damping", &mut drive.damping),
            ("friction", &mut drive.friction),
            ("armature", &mut drive.armature),
        ] {
            if let Some(v) = e.get(k)
                && let Some(x) = self.number(v, &e.key(k))
            {
                if x >= 0.0 && x.is_finite() {
                    *slot = x;
                } else {
                    self.diags.push(
                        Diagnostic::error(format!("`{k}` must be a non-negative number"))
                            .with_key(e.key(k))
                            .with_span(Some(v.span()))
                            .with_hint("damping in N·m·s/rad (N·s/m for a prismatic joint), friction in N·m (N), armature in kg·m² (kg); they apply only when [scene] sets friction = true or rotor_inertia = true"),
                    );
                }
            }
        }
        drive
    }

    /// `child_origin`: the joint frame in the child's frame (joints that close a loop).
    fn joint_child_origin(&mut self, e: Entry<'_, '_>) -> Option<Transform> {
        let v = e.get("child_origin")?;
        match self.origin(v, &e.key("child_origin")) {
            Some(Placement::Origin(x)) => Some(x),
            // Already reported; keep a placeholder so that "missing" is not reported too.
            _ => Some(Transform::IDENTITY),
        }
    }

    fn kind(&mut self, v: &Val<'_>, key: &str) -> Option<Kind> {
        let s = self.string(v, key)?;
        let k = match s.as_str() {
            "revolute" | "R" => Kind::Revolute,
            "prismatic" | "P" => Kind::Prismatic,
            "universal" | "U" => Kind::Universal,
            "spherical" | "S" => Kind::Spherical,
            "fixed" => Kind::Fixed,
            other => {
                const ALL: &[&str] = &["revolute", "prismatic", "universal", "spherical", "fixed"];
                let hint = match other {
                    "continuous" => "use \"revolute\" (joint limits are not modelled)".to_owned(),
                    "floating" | "planar" => format!(
                        "{other} joints are not supported; model them as a chain of prismatic and revolute joints with massless bodies"
                    ),
                    _ => suggest_hint(&other.to_ascii_lowercase(), ALL).unwrap_or_else(|| {
                        "kind is one of \"revolute\" (\"R\"), \"prismatic\" (\"P\"), \"universal\" (\"U\"), \"spherical\" (\"S\"), \"fixed\"".into()
                    }),
                };
                self.err(format!("unknown joint kind {other:?}"), key, v.span())
                    .hint = Some(hint);
                return None;
            }
        };
        Some(k)
    }

    fn dh(&mut self, v: &Val<'_>, path: &str) -> Option<Dh> {
        let t = self.table(v, path)?;
        self.unknown_keys(t, DH_KEYS, path);
        let mut x = [0.0; 4];
        let mut ok = true;
        for (k, name) in DH_KEYS.iter().enumerate() {
            let key = format!("{path}.{name}");
            let val = match get(t, name) {
                None => {
                    self.missing(
                        name,
                        path,
                        v.span(),
                        "DH parameters a (m), alpha (rad), d (m), theta (rad) are all required",
                    );
                    None
                }
                Some(e) if matches!(*name, "alpha" | "theta") => self.angle(e, &key),
                Some(e) => self.number(e, &key),
            };
            match val {
                Some(n) => x[k] = n,
                None => ok = false,
            }
        }
        let [a, alpha, d, theta] = x;
        ok.then_some(Dh { a, alpha, d, theta })
    }
}
