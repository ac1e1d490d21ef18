//! The TOML reader: spanned parse (`toml::de::DeTable`), then a hand-written walk over the
//! tree that reports every unknown key (with a suggestion), missing key, wrong type, non-finite
//! number and bad angle — all of them, not only the first — each at its exact span.

use std::ops::Range;

use runtime::model::{Mat3, Transform, Vec3};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use super::angle::{ANGLE_HINT, parse_angle};
use super::ir::{
    AxisSpec, BodySpec, Coordinates, Dh, DriveSpec, JointSpec, Kind, Named, Payload, Placement,
    PlatformSpec, RuntimeInertia, SceneSpec, Spec, SpringSpec,
};
use super::{sanitize_name, suggest_hint};
use crate::diag::{Diagnostic, Diagnostics};

type Val<'i> = Spanned<DeValue<'i>>;

const TOP_KEYS: &[&str] = &["mechanism", "platform", "scene", "body", "joint", "spring"];
const SPRING_KEYS: &[&str] = &[
    "name",
    "body_a",
    "point_a",
    "body_b",
    "point_b",
    "stiffness",
    "rest_length",
    "damping",
];
const SCENE_KEYS: &[&str] = &[
    "functions",
    "gravity",
    "point_mass",
    "massless",
    "payload",
    "locked",
    "friction",
    "rotor_inertia",
    "coulomb_velocity",
    "snap",
    "parameters",
    "runtime_inertia",
];
const PAYLOAD_KEYS: &[&str] = &["body", "mass", "com", "inertia"];
const PLATFORM_KEYS: &[&str] = &["body", "coordinates", "home", "centre"];
const MECH_KEYS: &[&str] = &["name", "gravity", "source"];
const BODY_KEYS: &[&str] = &["name", "mass", "com", "inertia", "inertia_rpy"];
const INERTIA_KEYS: &[&str] = &["ixx", "iyy", "izz", "ixy", "ixz", "iyz"];
const JOINT_KEYS: &[&str] = &[
    "name",
    "kind",
    "parent",
    "child",
    "origin",
    "axis",
    "axes",
    "dh",
    "mdh",
    "actuated",
    "child_origin",
    "damping",
    "friction",
    "armature",
];
const ORIGIN_KEYS: &[&str] = &["xyz", "rpy"];
const DH_KEYS: &[&str] = &["a", "alpha", "d", "theta"];

/// Common misnomers: (written, meant).
const ALIASES: &[(&str, &str)] = &[
    ("type", "kind"),
    ("bodies", "body"),
    ("link", "body"),
    ("links", "body"),
    ("joints", "joint"),
    ("inertial", "inertia"),
    ("center_of_mass", "com"),
    ("centre_of_mass", "com"),
    ("cog", "com"),
    ("robot", "mechanism"),
    ("g", "gravity"),
    ("center", "centre"),
    ("actuator", "actuated"),
    ("active", "actuated"),
    ("viscous", "damping"),
    ("coulomb", "friction"),
    ("rotor_inertia", "armature"),
];

/// Reads a TOML spec. `None` when the file could not be read far enough to validate it.
pub(crate) fn read(source: &str, diags: &mut Diagnostics) -> Option<Spec> {
    let (root, errors) = DeTable::parse_recoverable(source);
    if !errors.is_empty() {
        // Report the first syntax error of each line; later ones on a line are mostly echoes.
        let mut lines_seen = Vec::new();
        for e in errors {
            let line = e
                .span()
                .map(|s| source[..s.start.min(source.len())].matches('\n').count());
            if line.is_some() && lines_seen.contains(&line) {
                continue;
            }
            lines_seen.push(line);
            // The reader's recursion limit on dotted keys comes without a span: find the key.
            let (span, hint) = match e.span() {
                Some(s) => (s, "see https://toml.io for the syntax"),
                None if !e.message().contains("recursion") => {
                    (0..0, "see https://toml.io for the syntax")
                }
                None => (
                    deepest_dotted_key(source).unwrap_or(0..0),
                    "a key has at most 80 dotted parts; nocdyn's keys have at most four, e.g. scene.payload.inertia.ixx",
                ),
            };
            diags.push(
                Diagnostic::error(format!("TOML syntax error: {}", e.message().trim_end()))
                    .with_span(span)
                    .with_hint(hint),
            );
        }
        return None;
    }
    let root = root.into_inner();
    let mut r = Reader {
        diags,
        joints_incomplete: false,
    };
    Some(r.spec(&root))
}

/// The span of the dotted key (`a.b.c`, in a header or before `=`) with the most parts, when it
/// has more than one: where the TOML reader's recursion limit on keys struck (the first key
/// over it, more than 80 parts). Strings are skipped whole, so only dotted runs of bare or
/// quoted parts count.
fn deepest_dotted_key(source: &str) -> Option<Range<usize>> {
    const LIMIT: usize = 80;
    let b = source.as_bytes();
    let bare = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c == b'-';
    // The end of the key part starting at `i`: a bare word or a quoted string.
    let part = |i: usize| -> Option<usize> {
        match *b.get(i)? {
            q @ (b'"' | b'\'') => {
                let mut j = i + 1;
                while j < b.len() && b[j] != q && b[j] != b'\n' {
                    j += if q == b'"' && b[j] == b'\\' { 2 } else { 1 };
                }
                (j < b.len() && b[j] == q).then_some(j + 1)
            }
            c if bare(c) => Some(i + b[i..].iter().take_while(|&&c| bare(c)).count()),
            _ => None,
        }
    };
    let blank = |mut j: usize| {
        while j < b.len() && matches!(b[j], b' ' | b'\t') {
            j += 1;
        }
        j
    };
    let mut best: Option<(usize, Range<usize>)> = None;
    let mut i = 0;
    while i < b.len() {
        let Some(mut end) = part(i) else {
            i += 1;
            continue;
        };
        let mut parts = 1;
        loop {
            let dot = blank(end);
            if b.get(dot) != Some(&b'.') {
                break;
            }
            match part(blank(dot + 1)) {
                Some(e) => {
                    end = e;
                    parts += 1;
                }
                None => break,
            }
        }
        if parts > 1 && best.as_ref().is_none_or(|(n, _)| parts > *n && *n <= LIMIT) {
            best = Some((parts, i..end));
        }
        i = end.max(i + 1);
    }
    best.map(|(_, span)| span)
}

/// The walk's state. Entries with bad values are kept with placeholder values (the error is
/// already reported and lowering stops before using them), so that names still resolve and one
/// mistake does not cascade into "unknown body" errors.
struct Reader<'d> {
    diags: &'d mut Diagnostics,
    joints_incomplete: bool,
}

/// What a value is, for "expected …, found …" messages.
fn type_name(v: &DeValue<'_>) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) => "an integer",
        DeValue::Float(_) => "a float",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a date-time",
        DeValue::Array(_) => "an array",
        DeValue::Table(_) => "a table",
    }
}

/// `"2 kg"`, `"10mm"`, `"1.5 lb"` → `("2", "kg")`: a number followed by a word (a unit).
fn number_with_unit(s: &str) -> Option<(&str, &str)> {
    let s = s.trim();
    let split = s.find(|c: char| c.is_alphabetic() || c == '°')?;
    let (num, unit) = (s[..split].trim(), s[split..].trim());
    (!num.is_empty() && num.parse::<f64>().is_ok() && !unit.is_empty()).then_some((num, unit))
}

fn get<'t, 'i>(t: &'t DeTable<'i>, k: &str) -> Option<&'t Val<'i>> {
    t.get(k)
}

/// The span of key `k` in `t`.
fn key_span(t: &DeTable<'_>, k: &str) -> Option<Range<usize>> {
    t.get_key_value(k).map(|(key, _)| key.span())
}

impl Reader<'_> {
    fn err(&mut self, msg: impl Into<String>, key: &str, span: Range<usize>) -> &mut Diagnostic {
        self.diags
            .push_mut(Diagnostic::error(msg).with_key(key).with_span(span))
    }

    /// Reports keys of `t` not in `allowed`, with the closest allowed key as hint.
    fn unknown_keys(&mut self, t: &DeTable<'_>, allowed: &[&str], path: &str) {
        let mut keys: Vec<_> = t.iter().map(|(k, _)| k).collect();
        keys.sort_by_key(|k| k.span().start);
        for k in keys {
            let name = k.get_ref().as_ref();
            if allowed.contains(&name) {
                continue;
            }
            let alias = ALIASES
                .iter()
                .find(|(w, m)| *w == name && allowed.contains(m))
                .map(|(_, m)| format!("did you mean \"{m}\"?"));
            let hint = alias
                .or_else(|| suggest_hint(name, allowed))
                .unwrap_or_else(|| {
                    format!(
                        "valid keys here: {}",
                        allowed
                            .iter()
                            .map(|a| format!("\"{a}\""))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                });
            let key = if path.is_empty() {
                name.to_owned()
            } else {
                format!("{path}.{name}")
            };
            self.err(format!("unknown key \"{name}\""), &key, k.span())
                .hint = Some(hint);
        }
    }

    fn missing(&mut self, what: &str, path: &str, span: Range<usize>, hint: &str) {
        let key = format!("{path}.{what}");
        let d = self.err(format!("missing required key \"{what}\""), &key, span);
        if !hint.is_empty() {
            d.hint = Some(hint.to_owned());
        }
    }

    fn type_error(&mut self, expected: &str, v: &Val<'_>, key: &str) {
        let d = self.err(
            format!("expected {expected}, found {}", type_name(v.get_ref())),
            key,
            v.span(),
        );
        if let DeValue::String(s) = v.get_ref()
            && expected.contains("number")
            && s.trim().parse::<f64>().is_ok()
        {
            d.hint = Some("write the number without quotes".into());
        } else if let DeValue::String(s) = v.get_ref()
            && expected.contains("number")
            && let Some((num, unit)) = number_with_unit(s)
        {
            d.hint = Some(format!(
                "values are plain numbers in SI units (m, kg, kg·m², m/s²; angles in rad or as angle strings): convert {num} {unit} and write it without quotes and unit"
            ));
        }
    }

    fn string(&mut self, v: &Val<'_>, key: &str) -> Option<String> {
        match v.get_ref() {
            DeValue::String(s) => Some(s.to_string()),
            _ => {
                self.type_error("a string", v, key);
                None
            }
        }
    }

    fn boolean(&mut self, v: &Val<'_>, key: &str) -> Option<bool> {
        match v.get_ref() {
            DeValue::Boolean(b) => Some(*b),
            _ => {
                self.type_error("a boolean (true or false)", v, key);
                None
            }
        }
    }

    fn table<'t, 'i>(&mut self, v: &'t Val<'i>, key: &str) -> Option<&'t DeTable<'i>> {
        match v.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => {
                self.type_error("a table", v, key);
                None
            }
        }
    }

    /// A finite number (integer or float).
    fn number(&mut self, v: &Val<'_>, key: &str) -> Option<f64> {
        let x = match v.get_ref() {
            DeValue::Float(f) => f.as_str().parse::<f64>().ok(),
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|i| i as f64),
            _ => {
                self.type_error("a number", v, key);
                return None;
            }
        };
        match x {
            Some(x) if x.is_finite() && super::in_range(x) => Some(x),
            Some(x) if x.is_finite() => {
                self.err(format!("value {x:e} is out of range"), key, v.span())
                    .hint = Some(super::RANGE_HINT.into());
                None
            }
            Some(_) => {
                self.err("value is not finite", key, v.span()).hint =
                    Some("nan and inf are not allowed: every value must be a finite number".into());
                None
            }
            None => {
                self.err("number out of range", key, v.span());
                None
            }
        }
    }

    /// An angle: a number in radians or an angle string.
    fn angle(&mut self, v: &Val<'_>, key: &str) -> Option<f64> {
        match v.get_ref() {
            DeValue::String(s) => match parse_angle(s) {
                Ok(a) if super::in_range(a) => Some(a),
                Ok(a) => {
                    self.err(
                        format!("angle {s:?} ({a:e} rad) is out of range"),
                        key,
                        v.span(),
                    )
                    .hint = Some(super::RANGE_HINT.into());
                    None
                }
                Err(e) => {
                    self.err(format!("invalid angle {s:?}: {e}"), key, v.span())
                        .hint = Some(ANGLE_HINT.into());
                    None
                }
            },
            DeValue::Float(_) | DeValue::Integer(_) => self.number(v, key),
            _ => {
                self.type_error("an angle (a number in radians or a string)", v, key);
                None
            }
        }
    }

    /// `[x, y, z]` of numbers (`angles`: angle strings allowed).
    fn triple(&mut self, v: &Val<'_>, key: &str, angles: bool) -> Option<Vec3> {
        let DeValue::Array(a) = v.get_ref() else {
            self.type_error("an array of three numbers", v, key);
            return None;
        };
        if a.len() != 3 {
            self.err(
                format!(
                    "expected an array of three numbers, found {} elements",
                    a.len()
                ),
                key,
                v.span(),
            );
            return None;
        }
        let mut out = [0.0; 3];
        let mut ok = true;
        for (k, e) in a.iter().enumerate() {
            let ek = format!("{key}[{k}]");
            let x = if angles {
                self.angle(e, &ek)
            } else {
                self.number(e, &ek)
            };
            match x {
                Some(x) => out[k] = x,
                None => ok = false,
            }
        }
        ok.then_some(out)
    }

    /// A name that must be an identifier-like string; returns it even when invalid (after the
    /// error) so that references to it still resolve.
    fn name(&mut self, t: &DeTable<'_>, path: &str, span: Range<usize>) -> Option<String> {
        let Some(v) = get(t, "name") else {
            self.missing("name", path, span, "");
            return None;
        };
        let key = format!("{path}.name");
        let n = self.string(v, &key)?;
        let valid = n
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if let Some(d) = super::name_too_long(&n) {
            self.diags.push(d.with_key(key).with_span(v.span()));
        } else if !valid {
            self.err(format!("invalid name {n:?}"), &key, v.span()).hint = Some(
                "names consist of ASCII letters, digits and `_`, and do not start with a digit"
                    .into(),
            );
        }
        Some(n)
    }

    fn spec(&mut self, root: &DeTable<'_>) -> Spec {
        self.unknown_keys(root, TOP_KEYS, "");
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
                    match get(t, "name") {
                        None => self.missing(
                            "name",
                            "mechanism",
                            v.span(),
                            "the name is used as a Rust module name, e.g. name = \"puma560\"",
                        ),
                        Some(nv) => {
                            if let Some(n) = self.string(nv, "mechanism.name") {
                                anchor = Some(nv.span());
                                if let Some(d) = super::name_too_long(&n) {
                                    self.diags
                                        .push(d.with_key("mechanism.name").with_span(nv.span()));
                                } else if !super::is_module_name(&n) {
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
                                name = n;
                            }
                        }
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
        let platform = get(root, "platform").and_then(|v| {
            let span = key_span(root, "platform").unwrap_or(v.span());
            self.platform(v, span)
        });
        let mut scene = SceneSpec::default();
        if let Some(v) = get(root, "scene")
            && let Some(t) = self.table(v, "scene")
        {
            self.unknown_keys(t, SCENE_KEYS, "scene");
            if let Some(f) = get(t, "functions") {
                scene.functions = self.names(f, "scene.functions");
            }
            if let Some(g) = get(t, "gravity")
                && let Some(g) = self.triple(g, "scene.gravity", false)
            {
                gravity = g;
            }
            if let Some(b) = get(t, "point_mass") {
                scene.point_mass = self.names(b, "scene.point_mass").unwrap_or_default();
            }
            if let Some(b) = get(t, "massless") {
                scene.massless = self.names(b, "scene.massless").unwrap_or_default();
            }
            if let Some(p) = get(t, "payload") {
                scene.payload = self.payload(p);
            }
            if let Some(v) = get(t, "friction") {
                scene.friction = self.boolean(v, "scene.friction").unwrap_or(false);
            }
            if let Some(v) = get(t, "rotor_inertia") {
                scene.rotor_inertia = self.boolean(v, "scene.rotor_inertia").unwrap_or(false);
            }
            if let Some(v) = get(t, "coulomb_velocity")
                && let Some(x) = self.number(v, "scene.coulomb_velocity")
            {
                if x > 0.0 && x.is_finite() {
                    scene.coulomb_velocity = x;
                } else {
                    self.diags.push(
                        Diagnostic::error("`coulomb_velocity` must be a positive number")
                            .with_key("scene.coulomb_velocity")
                            .with_span(Some(v.span()))
                            .with_hint("the speed scale v_s of the Coulomb law c·q̇/√(q̇² + v_s²), in rad/s or m/s; the default is 1e-4"),
                    );
                }
            }
            if let Some(v) = get(t, "parameters")
                && let Some(x) = self.string(v, "scene.parameters")
            {
                match x.as_str() {
                    "constants" => {}
                    "runtime" => {
                        scene.runtime_params = true;
                        scene.runtime_params_span = Some(v.span());
                    }
                    _ => self.diags.push(
                        Diagnostic::error(format!("unknown parameter mode {x:?}"))
                            .with_key("scene.parameters")
                            .with_span(Some(v.span()))
                            .with_hint("\"constants\" (the default: folded into the code) or \"runtime\" (a generated `Params` struct with the payload and the joints' damping, friction and armature, passed to every function)"),
                    ),
                }
            }
            if let Some(v) = get(t, "runtime_inertia") {
                let span = Some(v.span());
                let which = match v.get_ref() {
                    DeValue::String(x) if x.as_ref() == "all" => Some(RuntimeInertia::All),
                    DeValue::String(x) => {
                        self.diags.push(
                            Diagnostic::error(format!("unknown `runtime_inertia` value {:?}", x.as_ref()))
                                .with_key("scene.runtime_inertia")
                                .with_span(span.clone())
                                .with_hint("write \"all\" (every body with mass) or a list of body names, e.g. [\"link5\", \"link6\"]"),
                        );
                        None
                    }
                    _ => self
                        .names(v, "scene.runtime_inertia")
                        .map(RuntimeInertia::Bodies),
                };
                scene.runtime_inertia = which.map(|w| (w, span));
            }
            if let Some(v) = get(t, "snap")
                && let Some(x) = self.number(v, "scene.snap")
            {
                if super::is_snap_tolerance(x) {
                    scene.snap = Some(x);
                } else {
                    self.diags.push(
                        Diagnostic::error("`snap` must be a tolerance in (0, 0.01]")
                            .with_key("scene.snap")
                            .with_span(Some(v.span()))
                            .with_hint(super::SNAP_HINT),
                    );
                }
            }
            if let Some(l) = get(t, "locked")
                && let Some(lt) = self.table(l, "scene.locked")
            {
                for (k, v) in lt.iter() {
                    let key = format!("scene.locked.{}", k.get_ref());
                    if let Some(x) = self.angle(v, &key) {
                        scene.locked.push((
                            Named {
                                name: k.get_ref().to_string(),
                                key,
                                span: Some(k.span()),
                            },
                            x,
                        ));
                    }
                }
            }
        }
        let bodies = self
            .entries(root, "body")
            .into_iter()
            .filter_map(|(i, t, span)| self.body(i, t, span))
            .collect();
        let joints = self
            .entries(root, "joint")
            .into_iter()
            .filter_map(|(i, t, span)| self.joint(i, t, span))
            .collect();
        let springs = self
            .entries(root, "spring")
            .into_iter()
            .filter_map(|(i, t, span)| self.spring(i, t, span))
            .collect();
        Spec {
            name,
            gravity,
            bodies,
            joints,
            anchor,
            joints_incomplete: self.joints_incomplete,
            platform,
            scene,
            springs,
        }
    }

    /// `[[spring]]`: `name`, `body_a`, `body_b` (required), `point_a`, `point_b` (default the
    /// body frame's origin), `stiffness` (N/m, required), `rest_length` (m, required),
    /// `damping` (N·s/m, default 0); the numbers finite and not negative.
    fn spring(&mut self, i: usize, t: &DeTable<'_>, span: Range<usize>) -> Option<SpringSpec> {
        let path = Self::path(t, "spring", i);
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

    /// `[scene] payload`: `body` (required), `mass`, `com`, `inertia` (default zero).
    fn payload(&mut self, v: &Val<'_>) -> Option<Payload> {
        let path = "scene.payload";
        let t = self.table(v, path)?;
        self.unknown_keys(t, PAYLOAD_KEYS, path);
        let Some(b) = get(t, "body") else {
            self.missing(
                "body",
                path,
                v.span(),
                "the body that carries the payload: body = \"<its name>\"",
            );
            return None;
        };
        let name = self.string(b, "scene.payload.body")?;
        let mass = match get(t, "mass") {
            Some(m) => self.number(m, "scene.payload.mass")?,
            None => 0.0,
        };
        let com = match get(t, "com") {
            Some(c) => self.triple(c, "scene.payload.com", false)?,
            None => [0.0; 3],
        };
        let inertia = match get(t, "inertia") {
            Some(i) => self.inertia(i, "scene.payload.inertia")?,
            None => [[0.0; 3]; 3],
        };
        Some(Payload {
            body: Named {
                name,
                key: "scene.payload.body".into(),
                span: Some(b.span()),
            },
            mass,
            com,
            inertia,
        })
    }

    /// An array of strings, each with its key and span.
    fn names(&mut self, v: &Val<'_>, key: &str) -> Option<Vec<Named>> {
        let DeValue::Array(a) = v.get_ref() else {
            self.type_error("an array of names", v, key);
            return None;
        };
        let mut out = Vec::new();
        for (k, e) in a.iter().enumerate() {
            let ek = format!("{key}[{k}]");
            if let Some(s) = self.string(e, &ek) {
                out.push(Named {
                    name: s,
                    key: ek,
                    span: Some(e.span()),
                });
            }
        }
        Some(out)
    }

    /// The `[platform]` table of a parallel mechanism.
    /// `Some` whenever the key is present, so that the spec is treated as a parallel one (a
    /// platform that could not be read has no body, and lowering stops early).
    fn platform(&mut self, v: &Val<'_>, span: Range<usize>) -> Option<PlatformSpec> {
        let mut p = PlatformSpec {
            span: Some(span.clone()),
            body: None,
            body_span: Some(span.clone()),
            coordinates: None,
            coordinates_span: Some(span.clone()),
            home: Transform::IDENTITY,
            home_span: Some(span.clone()),
            centre: None,
            centre_span: Some(span.clone()),
        };
        let Some(t) = self.table(v, "platform") else {
            return Some(p);
        };
        self.unknown_keys(t, PLATFORM_KEYS, "platform");
        match get(t, "body") {
            None => self.missing(
                "body",
                "platform",
                span.clone(),
                "the moving platform is one of the [[body]] entries: body = \"<its name>\"",
            ),
            Some(b) => {
                p.body_span = Some(b.span());
                p.body = self.string(b, "platform.body");
            }
        }
        match get(t, "coordinates") {
            None => self.missing(
                "coordinates",
                "platform",
                span.clone(),
                "coordinates = \"pose\" (6 DOF) or \"orientation\" (3 DOF about a fixed centre)",
            ),
            Some(c) => {
                p.coordinates_span = Some(c.span());
                if let Some(s) = self.string(c, "platform.coordinates") {
                    p.coordinates = match s.as_str() {
                        "pose" => Some(Coordinates::Pose),
                        "orientation" => Some(Coordinates::Orientation),
                        "planar" => Some(Coordinates::Planar),
                        other => {
                            let hint = suggest_hint(
                                &other.to_ascii_lowercase(),
                                &["pose", "orientation", "planar"],
                            )
                            .unwrap_or_else(|| {
                                "coordinates is \"pose\" (position and orientation, 6 DOF), \"orientation\" (rotation about a fixed centre, 3 DOF) or \"planar\" (a point in a plane, 2 DOF)".into()
                            });
                            self.err(
                                format!("unknown platform coordinates {other:?}"),
                                "platform.coordinates",
                                c.span(),
                            )
                            .hint = Some(hint);
                            None
                        }
                    };
                }
            }
        }
        if let Some(h) = get(t, "home") {
            p.home_span = Some(h.span());
            if let Some(Placement::Origin(x)) = self.origin(h, "platform.home") {
                p.home = x;
            }
        }
        if let Some(c) = get(t, "centre") {
            p.centre_span = Some(c.span());
            p.centre = self.triple(c, "platform.centre", false);
        }
        Some(p)
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

    /// `body "name"` when the entry has a string name, else `body[i]`.
    fn path(t: &DeTable<'_>, what: &str, i: usize) -> String {
        match get(t, "name").map(|v| v.get_ref()) {
            Some(DeValue::String(s)) => format!("{what} \"{s}\""),
            _ => format!("{what}[{i}]"),
        }
    }

    fn body(&mut self, i: usize, t: &DeTable<'_>, span: Range<usize>) -> Option<BodySpec> {
        let path = Self::path(t, "body", i);
        self.unknown_keys(t, BODY_KEYS, &path);
        let name = self.name(t, &path, span.clone());
        let name_span = get(t, "name").map_or(span.clone(), |v| v.span());
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
        let inertia = inertia
            .zip(rpy)
            .map(|(i, rpy)| super::geom::rotate_inertia(&runtime::model::rpy_to_matrix(rpy), &i));
        Some(BodySpec {
            name: name?,
            key: path,
            span: Some(name_span),
            mass: mass.unwrap_or(0.0),
            mass_span: Some(mass_span),
            com: com.unwrap_or([0.0; 3]),
            inertia: inertia.unwrap_or([[0.0; 3]; 3]),
            inertia_span: Some(inertia_span),
        })
    }

    fn inertia(&mut self, v: &Val<'_>, path: &str) -> Option<Mat3> {
        let t = self.table(v, path)?;
        self.unknown_keys(t, INERTIA_KEYS, path);
        let mut x = [0.0; 6];
        let mut ok = true;
        for (k, name) in INERTIA_KEYS.iter().enumerate() {
            match get(t, name) {
                None if k < 3 => {
                    self.missing(
                        name,
                        path,
                        v.span(),
                        "the moments ixx, iyy, izz are required; the products ixy, ixz, iyz default to 0",
                    );
                    ok = false;
                }
                None => {}
                Some(e) => match self.number(e, &format!("{path}.{name}")) {
                    Some(n) => x[k] = n,
                    None => ok = false,
                },
            }
        }
        let [ixx, iyy, izz, ixy, ixz, iyz] = x;
        ok.then_some([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    }

    fn joint(&mut self, i: usize, t: &DeTable<'_>, span: Range<usize>) -> Option<JointSpec> {
        let path = Self::path(t, "joint", i);
        self.unknown_keys(t, JOINT_KEYS, &path);
        let name = self.name(t, &path, span.clone());
        let name_span = get(t, "name").map_or(span.clone(), |v| v.span());
        let kind_span = get(t, "kind").map_or(name_span.clone(), |v| v.span());
        let kind = match get(t, "kind") {
            None => {
                self.missing(
                    "kind",
                    &path,
                    span.clone(),
                    "kind = \"revolute\", \"prismatic\", \"universal\", \"spherical\" or \"fixed\"",
                );
                None
            }
            Some(v) => self.kind(v, &format!("{path}.kind")),
        };
        let mut end = |what: &str| -> Option<(String, Range<usize>)> {
            match get(t, what) {
                None => {
                    self.missing(
                        what,
                        &path,
                        span.clone(),
                        if what == "parent" {
                            "the parent is a body name or \"base\" (the fixed world)"
                        } else {
                            "the child is a body name"
                        },
                    );
                    None
                }
                Some(v) => Some((self.string(v, &format!("{path}.{what}"))?, v.span())),
            }
        };
        let parent = end("parent");
        let child = end("child");

        // Placement: at most one of origin, dh, mdh.
        let mut present: Vec<(&str, &Val<'_>)> = ["origin", "dh", "mdh"]
            .iter()
            .filter_map(|k| get(t, k).map(|v| (*k, v)))
            .collect();
        present.sort_by_key(|(k, _)| key_span(t, k).map_or(0, |s| s.start));
        let mut placement_ok = true;
        if present.len() > 1 {
            placement_ok = false;
            for (k, _) in &present[1..] {
                let ks = key_span(t, k).unwrap_or(span.clone());
                self.err(
                    format!(
                        "a joint has one placement, but \"{}\" is also given",
                        present[0].0
                    ),
                    &format!("{path}.{k}"),
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
            Some(("origin", v)) => self.origin(v, &format!("{path}.origin")),
            Some((k, v)) => {
                let dh = self.dh(v, &format!("{path}.{k}"));
                dh.map(|dh| {
                    if *k == "dh" {
                        Placement::Dh(dh)
                    } else {
                        Placement::Mdh(dh)
                    }
                })
            }
        };
        let is_dh = matches!(present.first(), Some(("dh" | "mdh", _)));

        // Axes, as the kind allows.
        let mut axes = Vec::new();
        let mut axes_ok = true;
        let axis_v = get(t, "axis");
        let axes_v = get(t, "axes");
        if let Some(kind) = kind {
            let wrong = |r: &mut Self, key: &str, msg: String, hint: &str| {
                let ks = key_span(t, key).unwrap_or(span.clone());
                r.err(msg, &format!("{path}.{key}"), ks).hint = Some(hint.to_owned());
            };
            if is_dh && !matches!(kind, Kind::Revolute | Kind::Prismatic | Kind::Fixed) {
                let k = present[0].0;
                wrong(
                    self,
                    k,
                    format!("`{k}` placement is not allowed for a {} joint", kind.word()),
                    "DH parameters describe revolute, prismatic or fixed joints; use `origin` (+ `axes`) here",
                );
                axes_ok = false;
            }
            match kind {
                Kind::Revolute | Kind::Prismatic => {
                    if axes_v.is_some() {
                        wrong(
                            self,
                            "axes",
                            format!(
                                "`axes` is for universal joints, not a {} joint",
                                kind.word()
                            ),
                            "use `axis = [x, y, z]`",
                        );
                        axes_ok = false;
                    }
                    if let Some(v) = axis_v {
                        if is_dh {
                            wrong(
                                self,
                                "axis",
                                "`axis` cannot be combined with a DH placement".into(),
                                "a DH joint moves about (or along) the z axis of its frame; remove `axis`",
                            );
                            axes_ok = false;
                        } else {
                            let key = format!("{path}.axis");
                            match self.triple(v, &key, false) {
                                Some(a) => axes.push(AxisSpec {
                                    v: a,
                                    key,
                                    span: Some(v.span()),
                                }),
                                None => axes_ok = false,
                            }
                        }
                    }
                }
                Kind::Universal => {
                    if axis_v.is_some() {
                        wrong(
                            self,
                            "axis",
                            "a universal joint has two axes".into(),
                            "use `axes = [[1, 0, 0], [0, 1, 0]]` (first rotation about axes[0], then about axes[1])",
                        );
                        axes_ok = false;
                    }
                    if let Some(v) = axes_v {
                        let key = format!("{path}.axes");
                        match v.get_ref() {
                            DeValue::Array(a) if a.len() == 2 => {
                                for (k, e) in a.iter().enumerate() {
                                    let ek = format!("{key}[{k}]");
                                    match self.triple(e, &ek, false) {
                                        Some(x) => axes.push(AxisSpec {
                                            v: x,
                                            key: ek,
                                            span: Some(e.span()),
                                        }),
                                        None => axes_ok = false,
                                    }
                                }
                            }
                            _ => {
                                self.err(
                                    "expected two axes, [[x, y, z], [x, y, z]]",
                                    &key,
                                    v.span(),
                                );
                                axes_ok = false;
                            }
                        }
                    }
                }
                Kind::Spherical | Kind::Fixed => {
                    for k in ["axis", "axes"] {
                        if get(t, k).is_some() {
                            wrong(
                                self,
                                k,
                                format!("a {} joint takes no `{k}`", kind.word()),
                                if kind == Kind::Spherical {
                                    "a spherical joint rotates about x, then y, then z of its joint frame; orient it with `origin.rpy`"
                                } else {
                                    "remove it"
                                },
                            );
                            axes_ok = false;
                        }
                    }
                }
            }
        }
        let mut actuated = false;
        let actuated_span = key_span(t, "actuated");
        if let Some(v) = get(t, "actuated") {
            actuated = self
                .boolean(v, &format!("{path}.actuated"))
                .unwrap_or(false);
        }
        let mut drive = DriveSpec::default();
        for (k, slot) in [
            ("damping", &mut drive.damping),
            ("friction", &mut drive.friction),
            ("armature", &mut drive.armature),
        ] {
            if let Some(v) = get(t, k)
                && let Some(x) = self.number(v, &format!("{path}.{k}"))
            {
                if x >= 0.0 && x.is_finite() {
                    *slot = x;
                } else {
                    self.diags.push(
                        Diagnostic::error(format!("`{k}` must be a non-negative number"))
                            .with_key(format!("{path}.{k}"))
                            .with_span(Some(v.span()))
                            .with_hint("damping in N·m·s/rad (N·s/m for a prismatic joint), friction in N·m (N), armature in kg·m² (kg); they apply only when [scene] sets friction = true or rotor_inertia = true"),
                    );
                }
            }
        }
        let child_origin_span = key_span(t, "child_origin");
        let child_origin = match get(t, "child_origin") {
            None => None,
            Some(v) => match self.origin(v, &format!("{path}.child_origin")) {
                Some(Placement::Origin(x)) => Some(x),
                // Already reported; keep a placeholder so that "missing" is not reported too.
                _ => Some(Transform::IDENTITY),
            },
        };
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
            placement: placement
                .filter(|_| placement_ok)
                .unwrap_or(Placement::Origin(Transform::IDENTITY)),
            axes: if axes_ok { axes } else { Vec::new() },
            actuated,
            actuated_span,
            child_origin,
            child_origin_span,
            drive,
        })
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

    fn origin(&mut self, v: &Val<'_>, path: &str) -> Option<Placement> {
        let t = self.table(v, path)?;
        self.unknown_keys(t, ORIGIN_KEYS, path);
        let xyz = match get(t, "xyz") {
            None => Some([0.0; 3]),
            Some(e) => self.triple(e, &format!("{path}.xyz"), false),
        };
        let rpy = match get(t, "rpy") {
            None => Some([0.0; 3]),
            Some(e) => self.triple(e, &format!("{path}.rpy"), true),
        };
        Some(Placement::Origin(Transform::from_xyz_rpy(xyz?, rpy?)))
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
