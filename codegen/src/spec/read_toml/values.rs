//! The typed values: strings, booleans, tables, finite numbers, angles, `[x, y, z]` triples,
//! names and lists of names, inertia tables and `{ xyz, rpy }` origins, each read at its key
//! with "expected …, found …" (and a hint for quoted numbers and numbers with units) when the
//! type is wrong.

use std::ops::Range;

use runtime::model::{Mat3, Transform, Vec3};
use toml::de::{DeTable, DeValue};

use super::keys::{INERTIA_KEYS, ORIGIN_KEYS, ROTATION_KEYS};
use super::{Reader, Val, get};
use crate::diag::Diagnostic;
use crate::spec::angle::{ANGLE_HINT, parse_angle};
use crate::spec::ir::{Named, Placement};

/// What a value is, for "expected …, found …" messages.
pub(super) fn type_name(v: &DeValue<'_>) -> &'static str {
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

/// Whether an angle string that is not a plain angle (`"pi/2"`, `"90 deg"`) is meant as an
/// expression: it calls a function or names a parameter.
fn is_expression(s: &str) -> bool {
    s.contains('(') || !crate::spec::expr::names(s).is_empty()
}

impl Reader<'_> {
    pub(super) fn err(
        &mut self,
        msg: impl Into<String>,
        key: &str,
        span: Range<usize>,
    ) -> &mut Diagnostic {
        self.diags
            .push_mut(Diagnostic::error(msg).with_key(key).with_span(span))
    }

    pub(super) fn missing(&mut self, what: &str, path: &str, span: Range<usize>, hint: &str) {
        let key = format!("{path}.{what}");
        let d = self.err(format!("missing required key \"{what}\""), &key, span);
        if !hint.is_empty() {
            d.hint = Some(hint.to_owned());
        }
    }

    pub(super) fn type_error(&mut self, expected: &str, v: &Val<'_>, key: &str) {
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

    pub(super) fn string(&mut self, v: &Val<'_>, key: &str) -> Option<String> {
        match v.get_ref() {
            DeValue::String(s) => Some(self.substitute(s)),
            _ => {
                self.type_error("a string", v, key);
                None
            }
        }
    }

    pub(super) fn boolean(&mut self, v: &Val<'_>, key: &str) -> Option<bool> {
        match v.get_ref() {
            DeValue::Boolean(b) => Some(*b),
            _ => {
                self.type_error("a boolean (true or false)", v, key);
                None
            }
        }
    }

    pub(super) fn table<'t, 'i>(&mut self, v: &'t Val<'i>, key: &str) -> Option<&'t DeTable<'i>> {
        match v.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => {
                self.type_error("a table", v, key);
                None
            }
        }
    }

    /// A finite number (integer or float).
    pub(super) fn number(&mut self, v: &Val<'_>, key: &str) -> Option<f64> {
        let x = match v.get_ref() {
            DeValue::Float(f) => f.as_str().parse::<f64>().ok(),
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|i| i as f64),
            // A number with a unit other than an angle's is a unit mistake, not an expression.
            DeValue::String(s)
                if number_with_unit(s).is_some_and(|(_, u)| {
                    !matches!(u, "deg" | "rad" | "°")
                        && u.chars().all(|c| c.is_alphabetic() || "°·²³/".contains(c))
                }) =>
            {
                self.type_error("a number", v, key);
                return None;
            }
            DeValue::String(s) => Some(self.expression(s, v, key)?),
            _ => {
                self.type_error("a number", v, key);
                return None;
            }
        };
        match x {
            Some(x) if x.is_finite() && crate::spec::in_range(x) => Some(x),
            Some(x) if x.is_finite() => {
                self.err(format!("value {x:e} is out of range"), key, v.span())
                    .hint = Some(crate::spec::RANGE_HINT.into());
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
    pub(super) fn angle(&mut self, v: &Val<'_>, key: &str) -> Option<f64> {
        match v.get_ref() {
            // An expression (other than an angle string's `2*pi/3`, `90 deg`): see `expression`.
            DeValue::String(s) if parse_angle(s).is_err() && is_expression(s) => self
                .expression(s, v, key)
                .map(crate::spec::expr::quarter_turns_exact)
                .filter(|a| {
                    crate::spec::in_range(*a) || {
                        self.err(
                            format!("angle {s:?} ({a:e} rad) is out of range"),
                            key,
                            v.span(),
                        )
                        .hint = Some(crate::spec::RANGE_HINT.into());
                        false
                    }
                }),
            DeValue::String(s) => match parse_angle(s) {
                Ok(a) if crate::spec::in_range(a) => Some(a),
                Ok(a) => {
                    self.err(
                        format!("angle {s:?} ({a:e} rad) is out of range"),
                        key,
                        v.span(),
                    )
                    .hint = Some(crate::spec::RANGE_HINT.into());
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
    pub(super) fn triple(&mut self, v: &Val<'_>, key: &str, angles: bool) -> Option<Vec3> {
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
    pub(super) fn name(
        &mut self,
        t: &DeTable<'_>,
        path: &str,
        span: Range<usize>,
    ) -> Option<String> {
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
        if let Some(d) = crate::spec::name_too_long(&n) {
            self.diags.push(d.with_key(key).with_span(v.span()));
        } else if !valid {
            self.err(format!("invalid name {n:?}"), &key, v.span()).hint = Some(
                "names consist of ASCII letters, digits and `_`, and do not start with a digit"
                    .into(),
            );
        }
        Some(n)
    }

    /// An array of strings, each with its key and span.
    pub(super) fn names(&mut self, v: &Val<'_>, key: &str) -> Option<Vec<Named>> {
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

    pub(super) fn inertia(&mut self, v: &Val<'_>, path: &str) -> Option<Mat3> {
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

    /// `{ xyz, rpy }`, or the rotation as `quat = [w, x, y, z]`, `matrix = [[…], […], […]]`
    /// (rows) or `axis_angle = { axis = […], angle = … }` instead of `rpy` (at most one).
    pub(super) fn origin(&mut self, v: &Val<'_>, path: &str) -> Option<Placement> {
        let t = self.table(v, path)?;
        self.unknown_keys(t, ORIGIN_KEYS, path);
        let xyz = match get(t, "xyz") {
            None => Some([0.0; 3]),
            Some(e) => self.triple(e, &format!("{path}.xyz"), false),
        };
        let given: Vec<(&str, &Val<'_>)> = ROTATION_KEYS
            .iter()
            .filter_map(|k| get(t, k).map(|e| (*k, e)))
            .collect();
        if let [(first, _), (second, e), ..] = given.as_slice() {
            self.err(
                format!("`{path}` gives its rotation twice, as `{first}` and as `{second}`"),
                &format!("{path}.{second}"),
                e.span(),
            )
            .hint = Some("give one of rpy, quat, matrix and axis_angle".into());
            return None;
        }
        let rotation = match given.first() {
            None => Some(Transform::IDENTITY.rotation),
            Some(("rpy", e)) => self
                .triple(e, &format!("{path}.rpy"), true)
                .map(runtime::model::rpy_to_matrix),
            Some(("quat", e)) => self.quaternion(e, &format!("{path}.quat")),
            Some(("matrix", e)) => self.rotation_matrix(e, &format!("{path}.matrix")),
            Some((_, e)) => self.axis_angle(e, &format!("{path}.axis_angle")),
        };
        Some(Placement::Origin(Transform {
            rotation: rotation?,
            translation: xyz?,
        }))
    }

    /// A quaternion `[w, x, y, z]`, normalized; its norm must be within `1e-3` of 1 (values
    /// read off a drawing or another format to a few digits are accepted).
    fn quaternion(&mut self, v: &Val<'_>, key: &str) -> Option<Mat3> {
        let q = self.numbers(v, key, 4)?;
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (n - 1.0).abs() > 1e-3 || n.is_nan() {
            self.err(
                format!("the quaternion's norm is {n}, not 1"),
                key,
                v.span(),
            )
            .hint = Some("give a unit quaternion [w, x, y, z] (w first); its norm may differ from 1 by at most 1e-3, and it is normalized".into());
            return None;
        }
        Some(runtime::model::quaternion_matrix(&[
            q[0] / n,
            q[1] / n,
            q[2] / n,
            q[3] / n,
        ]))
    }

    /// A rotation matrix by rows; orthonormal with determinant +1 within `1e-6` (a matrix
    /// within that is made exactly orthonormal, the nearest rotation by its polar factor).
    fn rotation_matrix(&mut self, v: &Val<'_>, key: &str) -> Option<Mat3> {
        let DeValue::Array(rows) = v.get_ref() else {
            self.type_error("an array of three rows of three numbers", v, key);
            return None;
        };
        if rows.len() != 3 {
            self.err(
                format!("expected three rows, found {}", rows.len()),
                key,
                v.span(),
            );
            return None;
        }
        let mut m = [[0.0; 3]; 3];
        let mut ok = true;
        for (i, r) in rows.iter().enumerate() {
            match self.triple(r, &format!("{key}[{i}]"), false) {
                Some(row) => m[i] = row,
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        let a = nalgebra::Matrix3::from_fn(|i, j| m[i][j]);
        let off = (a.transpose() * a - nalgebra::Matrix3::identity()).amax();
        let det = a.determinant();
        if off > 1e-6 || off.is_nan() || det <= 0.0 || det.is_nan() {
            let why = if det <= 0.0 {
                format!("its determinant is {det:.6}, not +1 (a reflection or a singular matrix)")
            } else {
                format!(
                    "its columns are not orthonormal (RᵀR differs from the identity by {off:.1e})"
                )
            };
            self.err(format!("not a rotation matrix: {why}"), key, v.span())
                .hint = Some("give the rotation's rows, R[i][j] = e_i · (the child frame's axis j), orthonormal within 1e-6".into());
            return None;
        }
        if off == 0.0 {
            return Some(m);
        }
        // The nearest rotation: U Vᵀ of the SVD.
        let svd = a.svd(true, true);
        let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
            return Some(m);
        };
        let r = u * vt;
        Some(core::array::from_fn(|i| {
            core::array::from_fn(|j| r[(i, j)])
        }))
    }

    /// `{ axis = [x, y, z], angle = … }`: a rotation by `angle` (rad, or an angle string) about
    /// `axis` (normalized; not zero), exact at multiples of 15° (`geom::rotation`).
    fn axis_angle(&mut self, v: &Val<'_>, key: &str) -> Option<Mat3> {
        let t = self.table(v, key)?;
        self.unknown_keys(t, &["axis", "angle"], key);
        let axis = match get(t, "axis") {
            Some(e) => self.triple(e, &format!("{key}.axis"), false),
            None => {
                self.missing(
                    "axis",
                    key,
                    v.span(),
                    "an axis-angle rotation needs `axis = [x, y, z]` and `angle`",
                );
                None
            }
        };
        let angle = match get(t, "angle") {
            Some(e) => self.angle(e, &format!("{key}.angle")),
            None => {
                self.missing(
                    "angle",
                    key,
                    v.span(),
                    "an axis-angle rotation needs `axis = [x, y, z]` and `angle`",
                );
                None
            }
        };
        let (axis, angle) = (axis?, angle?);
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        if n <= 1e-9 || n.is_nan() {
            self.err(
                "the rotation axis is zero",
                &format!("{key}.axis"),
                v.span(),
            )
            .hint = Some("give a nonzero axis; it is normalized".into());
            return None;
        }
        let e = [axis[0] / n, axis[1] / n, axis[2] / n];
        Some(crate::spec::geom::rotation(&e, angle))
    }

    /// An array of `n` numbers.
    fn numbers(&mut self, v: &Val<'_>, key: &str, n: usize) -> Option<Vec<f64>> {
        let DeValue::Array(a) = v.get_ref() else {
            self.type_error(&format!("an array of {n} numbers"), v, key);
            return None;
        };
        if a.len() != n {
            self.err(
                format!(
                    "expected an array of {n} numbers, found {} elements",
                    a.len()
                ),
                key,
                v.span(),
            );
            return None;
        }
        let mut out = Vec::with_capacity(n);
        for (k, e) in a.iter().enumerate() {
            out.push(self.number(e, &format!("{key}[{k}]")));
        }
        out.into_iter().collect()
    }
}
