//! `isotropy --design NAME=LO:HI`: one number of a TOML spec, named by its path, made a search
//! variable beside the coordinates (the lecture's isotropy table is drawn for a chosen design
//! ratio; this finds the designs and points together).
//!
//! `NAME` is a dotted path into the spec's TOML. A segment selects a table's key; in an array of
//! tables (`[[body]]`, `[[joint]]`, `[[leg]]` …) it selects the element whose `name` it equals
//! (or, if it is a number, the element at that index); in an array of numbers it is the index.
//! Examples: `body.distal_a.mass`, `body.distal_a.com.2`, `joint.a2.origin.xyz.0`,
//! `platform.mass`. The number must exist in the spec (its value there is reported as the
//! spec's design). Each trial value rewrites the TOML and reloads it through the same checks as
//! the spec itself: a value the checks refuse (e.g. a geometry that no longer closes its loops at
//! home) rejects that point of the search, and a refused `LO` or `HI` is reported up front.

use toml::Value;

use super::{SpaceArg, Target};

/// A named number of the spec and its search range.
#[derive(Debug)]
pub struct Design {
    /// The path as the user wrote it.
    pub name: String,
    path: Vec<String>,
    /// Lower end of the range.
    pub lo: f64,
    /// Upper end of the range.
    pub hi: f64,
    /// The value written in the spec.
    pub written: f64,
    file: String,
    table: toml::Table,
    space: SpaceArg,
}

impl Design {
    /// Parses `NAME=LO:HI` against the spec's text.
    pub fn parse(arg: &str, file: &str, source: &str, space: SpaceArg) -> Result<Design, String> {
        let (name, range) = arg
            .split_once('=')
            .ok_or_else(|| format!("--design `{arg}`: expected NAME=LO:HI"))?;
        let (lo, hi) = range
            .split_once(':')
            .ok_or_else(|| format!("--design `{arg}`: expected NAME=LO:HI"))?;
        let num = |s: &str| {
            s.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("--design `{arg}`: `{s}` is not a finite number"))
        };
        let (lo, hi) = (num(lo)?, num(hi)?);
        if lo >= hi {
            return Err(format!("--design `{arg}`: LO must be below HI"));
        }
        if file.ends_with(".urdf") {
            return Err("--design works on TOML specs only".into());
        }
        let table: toml::Table = source
            .parse()
            .map_err(|e| format!("{file}: not TOML: {e}"))?;
        let path: Vec<String> = name.trim().split('.').map(str::to_string).collect();
        let mut probe = Value::Table(table.clone());
        let written = match locate(&mut probe, &path)? {
            Value::Float(v) => *v,
            Value::Integer(v) => *v as f64,
            other => {
                return Err(format!(
                    "--design `{name}`: the spec's value there is not a number ({})",
                    other.type_str()
                ));
            }
        };
        let d = Design {
            name: name.trim().to_string(),
            path,
            lo,
            hi,
            written,
            file: file.to_string(),
            table,
            space,
        };
        for end in [lo, hi] {
            d.target(end)
                .map_err(|e| format!("--design {} = {end}: the spec is refused:\n{e}", d.name))?;
        }
        Ok(d)
    }

    /// The spec's TOML with the design number set to `value`.
    pub fn source(&self, value: f64) -> String {
        let mut v = Value::Table(self.table.clone());
        if let Ok(slot) = locate(&mut v, &self.path) {
            *slot = Value::Float(value);
        }
        match v {
            Value::Table(t) => toml::to_string(&t).unwrap_or_default(),
            _ => String::new(),
        }
    }

    /// The mechanism with the design number set to `value` (diagnostics rendered on refusal).
    pub fn target(&self, value: f64) -> Result<Target, String> {
        Target::compile(&self.file, &self.source(value), self.space).map(|(t, _)| t)
    }
}

/// The value at `path` (see the module docs).
fn locate<'a>(root: &'a mut Value, path: &[String]) -> Result<&'a mut Value, String> {
    let mut at = root;
    let mut walked = String::new();
    for seg in path {
        let here = if walked.is_empty() {
            "the spec".to_string()
        } else {
            format!("`{walked}`")
        };
        at = match at {
            Value::Table(t) => {
                let keys: Vec<String> = t.keys().cloned().collect();
                t.get_mut(seg).ok_or_else(|| {
                    format!(
                        "--design: {here} has no key `{seg}` (keys: {})",
                        keys.join(", ")
                    )
                })?
            }
            Value::Array(a) => {
                let index = match seg.parse::<usize>() {
                    Ok(i) if i < a.len() => i,
                    Ok(i) => {
                        return Err(format!(
                            "--design: {here} has {} elements, no index {i}",
                            a.len()
                        ));
                    }
                    Err(_) => {
                        let names: Vec<String> = a
                            .iter()
                            .filter_map(|e| e.get("name").and_then(Value::as_str))
                            .map(str::to_string)
                            .collect();
                        a.iter()
                            .position(|e| e.get("name").and_then(Value::as_str) == Some(seg))
                            .ok_or_else(|| {
                                format!(
                                    "--design: {here} has no element named `{seg}` (names: {})",
                                    names.join(", ")
                                )
                            })?
                    }
                };
                &mut a[index]
            }
            other => {
                return Err(format!(
                    "--design: {here} is a {}, it has no `{seg}`",
                    other.type_str()
                ));
            }
        };
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(seg);
    }
    Ok(at)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = include_str!("../../../mechanisms/specs/spherical_five_bar.toml");

    #[test]
    fn paths_select_by_name_index_and_key() {
        let d = Design::parse(
            "body.distal_a.mass=0.1:1",
            "s.toml",
            SPEC,
            SpaceArg::Actuator,
        )
        .unwrap();
        assert_eq!(d.written, 0.3);
        let d = Design::parse(
            "body.distal_a.com.2=0.01:0.1",
            "s.toml",
            SPEC,
            SpaceArg::Actuator,
        )
        .unwrap();
        assert_eq!(d.written, 0.05);
        let re: toml::Table = d.source(0.07).parse().unwrap();
        let com = &re["body"].as_array().unwrap()[1]["com"];
        assert_eq!(com[2].as_float(), Some(0.07));
        let d = Design::parse("body.1.mass=0.1:1", "s.toml", SPEC, SpaceArg::Actuator).unwrap();
        assert_eq!(d.written, 0.3);
    }

    #[test]
    fn bad_paths_and_refused_values_are_errors() {
        let e = |a: &str| Design::parse(a, "s.toml", SPEC, SpaceArg::Actuator).unwrap_err();
        assert!(e("body.nothing.mass=0:1").contains("no element named `nothing`"));
        assert!(e("body.distal_a.masss=0:1").contains("no key `masss`"));
        assert!(e("body.distal_a.name=0:1").contains("not a number"));
        assert!(e("body.distal_a.mass=1:0").contains("LO must be below HI"));
        assert!(e("body.distal_a.mass").contains("NAME=LO:HI"));
        // A negative mass is refused by the spec's own checks, with its diagnostic.
        assert!(e("body.distal_a.mass=-1:1").contains("refused"));
    }
}
