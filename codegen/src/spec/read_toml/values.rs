//! The typed values: strings, booleans, tables, finite numbers, angles, `[x, y, z]` triples,
//! names and lists of names, inertia tables and `{ xyz, rpy }` origins, each read at its key
//! with "expected …, found …" (and a hint for quoted numbers and numbers with units) when the
//! type is wrong.

use std::ops::Range;

use runtime::model::{Mat3, Transform, Vec3};
use toml::de::{DeTable, DeValue};

use super::keys::{INERTIA_KEYS, ORIGIN_KEYS};
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
            DeValue::String(s) => Some(s.to_string()),
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

    pub(super) fn origin(&mut self, v: &Val<'_>, path: &str) -> Option<Placement> {
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
}
