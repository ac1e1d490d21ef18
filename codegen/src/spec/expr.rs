//! Expressions in numeric values: `"r_base * cos(120 deg)"`, `"sqrt(dx^2 + dy^2)"`,
//! `"b_x[i] - 1.5"` (docs/spec.md, "Parameters and expressions").
//!
//! The grammar, loosest binding first:
//!
//! ```text
//! sum     = product { ("+" | "-") product }
//! product = unary { ("*" | "/") unary }
//! unary   = ("-" | "+") unary | power
//! power   = unit [ "^" unary ]
//! unit    = primary [ "deg" | "°" | "rad" ]
//! primary = number | name [ "[" sum "]" ] | name "(" sum { "," sum } ")" | "(" sum ")"
//! ```
//!
//! Names are parameters (scalars, or arrays indexed from 1), `pi` (or `π`) and, inside a
//! pattern, the copy number `i`. Functions: `sin cos tan asin acos atan atan2 sqrt abs hypot
//! min max`. The value is an `f64`, evaluated as written, except that the sine and cosine of
//! a whole multiple of 15° are the correctly rounded exact values (`cos(120 deg)` is `-0.5`,
//! `sin(180 deg)` is `0`), so that symmetric geometry stays symmetric to the last bit.

use std::ops::Range;

/// A parameter's value.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value {
    Scalar(f64),
    /// Indexed from 1 in expressions (`b_x[1]` is the first element).
    Array(Vec<f64>),
}

/// What went wrong, and where in the expression (byte range).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ExprError {
    pub message: String,
    pub at: Range<usize>,
    /// A parameter name that was not found (for a "did you mean" hint).
    pub unknown: Option<String>,
}

fn error(message: impl Into<String>, at: Range<usize>) -> ExprError {
    ExprError {
        message: message.into(),
        at,
        unknown: None,
    }
}

/// The functions, with their number of arguments.
const FUNCTIONS: &[(&str, usize)] = &[
    ("sin", 1),
    ("cos", 1),
    ("tan", 1),
    ("asin", 1),
    ("acos", 1),
    ("atan", 1),
    ("atan2", 2),
    ("sqrt", 1),
    ("abs", 1),
    ("hypot", 2),
    ("min", 2),
    ("max", 2),
];

/// Evaluates `src`; `lookup` gives the value of a name (parameters, `i`), `pi` is built in.
/// The value is finite, or an error.
pub(crate) fn eval(src: &str, lookup: &dyn Fn(&str) -> Option<Value>) -> Result<f64, ExprError> {
    let mut p = Parser {
        src,
        pos: 0,
        lookup,
        depth: 0,
    };
    p.skip_space();
    if p.pos == src.len() {
        return Err(error("empty expression", 0..src.len()));
    }
    let v = p.sum()?;
    p.skip_space();
    if p.pos < src.len() {
        let rest = &src[p.pos..];
        // A word after a value: a misspelt unit (`90 dgr`) or a missing operator.
        let word: String = rest
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect();
        if rest.starts_with(|c: char| c.is_ascii_alphabetic()) {
            return Err(ExprError {
                message: format!(
                    "unexpected `{word}` after a value (the units are `deg` and `rad`; other values are SI numbers)"
                ),
                at: p.pos..p.pos + word.len(),
                unknown: Some(word),
            });
        }
        return Err(error(format!("unexpected {rest:?}"), p.pos..src.len()));
    }
    if v.is_finite() {
        Ok(v)
    } else {
        Err(error(
            "the value is not finite (a division by zero, or a function outside its domain)",
            0..src.len(),
        ))
    }
}

/// The names an expression refers to (parameters and `i`), in order, without duplicates; for
/// the order in which parameters are evaluated. Function names and `pi` are not included.
pub(crate) fn names(src: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let b = src.as_bytes();
    let mut k = 0;
    while k < b.len() {
        if b[k].is_ascii_alphabetic() || b[k] == b'_' {
            let start = k;
            while k < b.len() && (b[k].is_ascii_alphanumeric() || b[k] == b'_') {
                k += 1;
            }
            let name = &src[start..k];
            let called = src[k..].trim_start().starts_with('(');
            let builtin = matches!(name, "pi" | "deg" | "rad");
            // A number's exponent (`1e-3`) is not a name.
            let exponent = start > 0 && (b[start - 1].is_ascii_digit() || b[start - 1] == b'.');
            if !called && !builtin && !exponent && !out.iter().any(|n| n == name) {
                out.push(name.to_owned());
            }
        } else {
            k += 1;
        }
    }
    out
}

/// Sine and cosine, exact (correctly rounded) at whole multiples of 15°.
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    // sin(k·15°) for k = 0..=6, each the nearest f64 of its exact value.
    const T: [f64; 7] = [
        0.0,
        0.258_819_045_102_520_74,
        0.5,
        core::f64::consts::FRAC_1_SQRT_2,
        0.866_025_403_784_438_6,
        0.965_925_826_289_068_3,
        1.0,
    ];
    let k = x / (core::f64::consts::PI / 12.0);
    let kr = k.round();
    if kr.abs() <= 1e6 && (k - kr).abs() <= 1e-12 * kr.abs().max(1.0) {
        let m = (kr as i64).rem_euclid(24);
        let s = |m: i64| -> f64 {
            match m {
                0..=6 => T[m as usize],
                7..=12 => T[(12 - m) as usize],
                13..=18 => -T[(m - 12) as usize],
                _ => -T[(24 - m) as usize],
            }
        };
        // 0.0 rather than -0.0.
        return (s(m) + 0.0, s((m + 6) % 24) + 0.0);
    }
    (x.sin(), x.cos())
}

/// An angle as a whole multiple of π/2 exactly when it is one to within rounding, the value on
/// which `runtime::model::exact_sin_cos` gives exact 0 and ±1.
pub(crate) fn quarter_turns_exact(a: f64) -> f64 {
    let h = core::f64::consts::FRAC_PI_2;
    let k = (a / h).round();
    if k.abs() <= 1e6 && (a - k * h).abs() <= 4.0 * f64::EPSILON * (k * h).abs() {
        k * h
    } else {
        a
    }
}

/// The nesting bound: a deeper expression is refused rather than overflowing the stack.
const MAX_DEPTH: usize = 64;

struct Parser<'s, 'l> {
    src: &'s str,
    pos: usize,
    lookup: &'l dyn Fn(&str) -> Option<Value>,
    depth: usize,
}

impl Parser<'_, '_> {
    fn skip_space(&mut self) {
        while let Some(c) = self.src[self.pos..].chars().next()
            && c.is_whitespace()
        {
            self.pos += c.len_utf8();
        }
    }

    fn peek(&mut self) -> Option<char> {
        self.skip_space();
        self.src[self.pos..].chars().next()
    }

    fn eat(&mut self, c: char) -> bool {
        if self.peek() == Some(c) {
            self.pos += c.len_utf8();
            true
        } else {
            false
        }
    }

    fn here(&self) -> Range<usize> {
        let end = self.src[self.pos..]
            .chars()
            .next()
            .map_or(self.pos, |c| self.pos + c.len_utf8());
        self.pos..end
    }

    fn expected(&mut self, what: &str) -> ExprError {
        self.skip_space();
        match self.src[self.pos..].chars().next() {
            None => error(
                format!("expected {what}, found the end"),
                self.src.len()..self.src.len(),
            ),
            Some(c) => error(format!("expected {what}, found {c:?}"), self.here()),
        }
    }

    fn sum(&mut self) -> Result<f64, ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(error("the expression is nested too deeply", self.here()));
        }
        let mut v = self.product()?;
        loop {
            if self.eat('+') {
                v += self.product()?;
            } else if self.eat('-') {
                v -= self.product()?;
            } else {
                break;
            }
        }
        self.depth -= 1;
        Ok(v)
    }

    fn product(&mut self) -> Result<f64, ExprError> {
        let mut v = self.unary()?;
        loop {
            if self.eat('*') {
                v *= self.unary()?;
            } else if self.eat('/') {
                let at = self.here();
                let d = self.unary()?;
                if d == 0.0 {
                    return Err(error("division by zero", at));
                }
                v /= d;
            } else {
                break;
            }
        }
        Ok(v)
    }

    fn unary(&mut self) -> Result<f64, ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(error("the expression is nested too deeply", self.here()));
        }
        let v = if self.eat('-') {
            -self.unary()?
        } else if self.eat('+') {
            self.unary()?
        } else {
            self.power()?
        };
        self.depth -= 1;
        Ok(v)
    }

    fn power(&mut self) -> Result<f64, ExprError> {
        let base = self.unit()?;
        if self.eat('^') {
            let e = self.unary()?;
            // Whole exponents as repeated products (exact squares), others by powf.
            if e.fract() == 0.0 && e.abs() <= 64.0 {
                return Ok(base.powi(e as i32));
            }
            return Ok(base.powf(e));
        }
        Ok(base)
    }

    fn unit(&mut self) -> Result<f64, ExprError> {
        let v = self.primary()?;
        self.skip_space();
        let rest = &self.src[self.pos..];
        let word_end = |w: &str| {
            rest.starts_with(w)
                && !rest[w.len()..]
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_alphanumeric() || c == '_')
        };
        if word_end("deg") {
            self.pos += 3;
            Ok(degrees(v))
        } else if rest.starts_with('°') {
            self.pos += '°'.len_utf8();
            Ok(degrees(v))
        } else if word_end("rad") {
            self.pos += 3;
            Ok(v)
        } else {
            Ok(v)
        }
    }

    fn primary(&mut self) -> Result<f64, ExprError> {
        match self.peek() {
            Some('(') => {
                self.pos += 1;
                let v = self.sum()?;
                if !self.eat(')') {
                    return Err(self.expected("`)`"));
                }
                Ok(v)
            }
            Some(c) if c.is_ascii_digit() || c == '.' => self.number(),
            Some('π') => {
                self.pos += 'π'.len_utf8();
                Ok(core::f64::consts::PI)
            }
            Some(c) if c.is_ascii_alphabetic() || c == '_' => self.name(),
            _ => Err(self.expected("a number, a name or `(`")),
        }
    }

    fn number(&mut self) -> Result<f64, ExprError> {
        let start = self.pos;
        let b = self.src.as_bytes();
        let mut k = self.pos;
        while k < b.len() && (b[k].is_ascii_digit() || b[k] == b'.' || b[k] == b'_') {
            k += 1;
        }
        // An exponent, but not the start of a unit word such as `deg`.
        if k < b.len()
            && (b[k] == b'e' || b[k] == b'E')
            && b.get(k + 1)
                .is_some_and(|c| c.is_ascii_digit() || *c == b'-' || *c == b'+')
        {
            k += 2;
            while k < b.len() && b[k].is_ascii_digit() {
                k += 1;
            }
        }
        self.pos = k;
        let text = self.src[start..k].replace('_', "");
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(error(
                format!("{:?} is not a number", &self.src[start..k]),
                start..k,
            )),
        }
    }

    fn name(&mut self) -> Result<f64, ExprError> {
        let start = self.pos;
        let b = self.src.as_bytes();
        let mut k = self.pos;
        while k < b.len() && (b[k].is_ascii_alphanumeric() || b[k] == b'_') {
            k += 1;
        }
        self.pos = k;
        let name = &self.src[start..k];
        let at = start..k;
        if self.peek() == Some('(') {
            return self.call(name, at);
        }
        if name == "pi" {
            return Ok(core::f64::consts::PI);
        }
        let value = (self.lookup)(name).ok_or_else(|| ExprError {
            message: format!("unknown name `{name}`"),
            at: at.clone(),
            unknown: Some(name.to_owned()),
        })?;
        let indexed = self.peek() == Some('[');
        match value {
            Value::Scalar(v) if !indexed => Ok(v),
            Value::Scalar(_) => Err(error(format!("`{name}` is a number, not an array"), at)),
            Value::Array(a) => {
                if !self.eat('[') {
                    return Err(error(
                        format!("`{name}` is an array: write `{name}[k]`, k from 1"),
                        at,
                    ));
                }
                let idx_at = self.here();
                let idx = self.sum()?;
                if !self.eat(']') {
                    return Err(self.expected("`]`"));
                }
                let n = a.len();
                if idx.fract() != 0.0 || idx < 1.0 || idx > n as f64 {
                    return Err(error(
                        format!("index {idx} of `{name}` is not a whole number from 1 to {n}"),
                        idx_at.start..self.pos,
                    ));
                }
                Ok(a[idx as usize - 1])
            }
        }
    }

    fn call(&mut self, name: &str, at: Range<usize>) -> Result<f64, ExprError> {
        let Some(&(_, arity)) = FUNCTIONS.iter().find(|(f, _)| *f == name) else {
            let list: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
            return Err(error(
                format!("unknown function `{name}` (known: {})", list.join(", ")),
                at,
            ));
        };
        self.eat('(');
        let mut args = Vec::new();
        if self.peek() != Some(')') {
            args.push(self.sum()?);
            while self.eat(',') {
                args.push(self.sum()?);
            }
        }
        if !self.eat(')') {
            return Err(self.expected("`,` or `)`"));
        }
        if args.len() != arity {
            return Err(error(
                format!(
                    "`{name}` takes {arity} argument{}, found {}",
                    if arity == 1 { "" } else { "s" },
                    args.len()
                ),
                at.start..self.pos,
            ));
        }
        let x = args[0];
        let domain = |ok: bool, v: f64| {
            if ok {
                Ok(v)
            } else {
                Err(error(
                    format!("`{name}` of {x} is outside its domain"),
                    at.start..self.pos,
                ))
            }
        };
        match name {
            "sin" => Ok(sin_cos(x).0),
            "cos" => Ok(sin_cos(x).1),
            "tan" => {
                let (s, c) = sin_cos(x);
                domain(c != 0.0, s / c)
            }
            "asin" => domain((-1.0..=1.0).contains(&x), x.asin()),
            "acos" => domain((-1.0..=1.0).contains(&x), x.acos()),
            "atan" => Ok(x.atan()),
            "atan2" => Ok(x.atan2(args[1])),
            "sqrt" => domain(x >= 0.0, x.sqrt()),
            "abs" => Ok(x.abs()),
            "hypot" => Ok(x.hypot(args[1])),
            "min" => Ok(x.min(args[1])),
            _ => Ok(x.max(args[1])),
        }
    }
}

/// Degrees to radians, whole multiples of 90° as exact quarter turns (as angle strings).
fn degrees(d: f64) -> f64 {
    let k = d / 90.0;
    if d.fract() == 0.0 && k.fract() == 0.0 && k.abs() <= 1e6 {
        k * core::f64::consts::FRAC_PI_2
    } else {
        d.to_radians()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(name: &str) -> Option<Value> {
        match name {
            "r" => Some(Value::Scalar(0.33)),
            "i" => Some(Value::Scalar(2.0)),
            "b" => Some(Value::Array(vec![1.0, 2.0, 3.0])),
            _ => None,
        }
    }

    fn ev(s: &str) -> Result<f64, ExprError> {
        eval(s, &env)
    }

    #[test]
    fn arithmetic_and_precedence() {
        assert_eq!(ev("1 + 2 * 3"), Ok(7.0));
        assert_eq!(ev("(1 + 2) * 3"), Ok(9.0));
        assert_eq!(ev("-2^2"), Ok(-4.0));
        assert_eq!(ev("2^-1"), Ok(0.5));
        assert_eq!(ev("8 / 4 / 2"), Ok(1.0));
        assert_eq!(ev("1e-3 * 2"), Ok(2e-3));
        assert_eq!(ev("1_000.5"), Ok(1000.5));
        assert_eq!(ev("r * 2"), Ok(0.66));
        assert_eq!(ev("b[i] + b[3]"), Ok(5.0));
        assert_eq!(ev("hypot(3, 4)"), Ok(5.0));
        assert_eq!(ev("max(1, min(3, 2))"), Ok(2.0));
    }

    #[test]
    fn trig_is_exact_at_multiples_of_15_degrees() {
        assert_eq!(ev("cos(120 deg)"), Ok(-0.5));
        assert_eq!(ev("sin(120deg)"), Ok(0.866_025_403_784_438_6));
        assert_eq!(ev("sin(180°)"), Ok(0.0));
        assert_eq!(ev("cos(90 deg)"), Ok(0.0));
        assert_eq!(ev("sin(pi/6)"), Ok(0.5));
        assert_eq!(ev("cos(-240 deg)"), Ok(-0.5));
        assert_eq!(ev("sin(45 deg)"), Ok(core::f64::consts::FRAC_1_SQRT_2));
        assert_eq!(ev("cos(-(i - 1) * 120 deg)"), Ok(-0.5));
        assert_eq!(ev("r * cos(240 deg)"), Ok(-0.165));
        // Elsewhere, the library's sine.
        assert_eq!(ev("sin(0.3)"), Ok(0.3f64.sin()));
        assert_eq!(ev("90 deg"), Ok(core::f64::consts::FRAC_PI_2));
        assert_eq!(ev("18.6458 deg"), Ok(18.6458f64.to_radians()));
    }

    #[test]
    fn errors_point_into_the_expression() {
        let e = ev("r_bas * 2").unwrap_err();
        assert_eq!((e.at, e.unknown.as_deref()), (0..5, Some("r_bas")));
        assert_eq!(ev("1 / (r - r)").unwrap_err().message, "division by zero");
        assert!(ev("sqrt(-1)").unwrap_err().message.contains("domain"));
        assert!(ev("b").unwrap_err().message.contains("array"));
        assert!(ev("b[4]").unwrap_err().message.contains("from 1 to 3"));
        assert!(ev("b[1.5]").is_err());
        assert!(ev("r[1]").is_err());
        assert!(
            ev("foo(1)")
                .unwrap_err()
                .message
                .contains("unknown function")
        );
        assert!(ev("atan2(1)").unwrap_err().message.contains("2 arguments"));
        assert!(ev("(1 + 2").unwrap_err().message.contains("`)`"));
        assert!(ev("1 +").is_err());
        assert!(ev("").is_err());
        assert!(ev("2 kg").is_err());
        assert!(ev("10^400").is_err());
        let deep = format!("{}1{}", "(".repeat(200), ")".repeat(200));
        assert!(ev(&deep).unwrap_err().message.contains("nested"));
        let minus = format!("{}1", "-".repeat(500));
        assert!(ev(&minus).is_err());
    }

    #[test]
    fn names_in_order() {
        assert_eq!(
            names("a * cos(b_x[i]) + 1e-3 + pi + a + 2 deg"),
            vec!["a", "b_x", "i"]
        );
    }

    #[test]
    fn quarter_turns() {
        let h = core::f64::consts::FRAC_PI_2;
        assert_eq!(quarter_turns_exact(3.0 * h * (1.0 + f64::EPSILON)), 3.0 * h);
        assert_eq!(quarter_turns_exact(0.3), 0.3);
    }
}
