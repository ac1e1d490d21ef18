//! Angle strings: `"pi"`, `"pi/2"`, `"-pi/2"`, `"2*pi/3"`, `"-3pi/4"`, `"90deg"`, `"-45 deg"`,
//! `"1.2 rad"`, `"0.5"` (radians).
//!
//! Integer multiples of π/2 come out as `k * FRAC_PI_2` exactly, the value on which
//! [`runtime::model::exact_sin_cos`] returns exact 0 and ±1.

use core::f64::consts::{FRAC_PI_2, PI};

/// The grammar, for error hints.
pub(crate) const ANGLE_HINT: &str = "write radians as a number, or a string such as \"pi/2\", \"-3pi/4\", \"2*pi/3\", \"90deg\", \"-45 deg\" or \"1.2 rad\"";

/// Parses an angle string into radians. The error is a short description of what is wrong.
pub(crate) fn parse_angle(s: &str) -> Result<f64, String> {
    let t: String = s
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_lowercase()
        .replace('π', "pi");
    if t.is_empty() {
        return Err("empty angle".into());
    }
    let value = if let Some(num) = t
        .strip_suffix("deg")
        .or_else(|| t.strip_suffix("degrees"))
        .or_else(|| t.strip_suffix('°'))
    {
        let d = number(num)?;
        // Whole multiples of 90° are exact quarter turns.
        let k = d / 90.0;
        if d.fract() == 0.0 && k.fract() == 0.0 && k.abs() <= 1e6 {
            k * FRAC_PI_2
        } else {
            d.to_radians()
        }
    } else if let Some(num) = t.strip_suffix("rad") {
        number(num)?
    } else if let Some(pos) = t.find("pi") {
        let (before, after) = (&t[..pos], &t[pos + 2..]);
        let coef = match before.strip_suffix('*').unwrap_or(before) {
            "" | "+" => 1.0,
            "-" => -1.0,
            c => number(c)?,
        };
        if before.ends_with('*') && matches!(before, "*" | "+*" | "-*") {
            return Err(format!("missing factor before `*` in {s:?}"));
        }
        let den = match after {
            "" => 1.0,
            a => match a.strip_prefix('/') {
                Some(d) => number(d)?,
                None => return Err(format!("unexpected {a:?} after `pi`")),
            },
        };
        if den == 0.0 {
            return Err("division by zero".into());
        }
        // coef·π/den = (2·coef/den)·π/2: exact when 2·coef/den is a whole number.
        let k = 2.0 * coef / den;
        if coef.fract() == 0.0 && den.fract() == 0.0 && k.fract() == 0.0 && k.abs() <= 1e6 {
            k * FRAC_PI_2
        } else {
            coef * PI / den
        }
    } else {
        number(&t)?
    };
    if value.is_finite() {
        Ok(value)
    } else {
        Err("the angle is not finite".into())
    }
}

/// A finite decimal number (no `inf`/`nan`).
fn number(s: &str) -> Result<f64, String> {
    let ok = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | 'e' | '_'));
    let v = if ok {
        s.replace('_', "").parse::<f64>().ok()
    } else {
        None
    };
    match v {
        Some(v) if v.is_finite() => Ok(v),
        _ => Err(format!("{s:?} is not a number")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turns_are_exact() {
        let h = FRAC_PI_2;
        for (s, v) in [
            ("pi", 2.0 * h),
            ("pi/2", h),
            ("-pi/2", -h),
            (" - pi / 2 ", -h),
            ("PI/2", h),
            ("π/2", h),
            ("3pi/2", 3.0 * h),
            ("-3*pi/2", -3.0 * h),
            ("2*pi", 4.0 * h),
            ("90deg", h),
            ("-90 deg", -h),
            ("180°", 2.0 * h),
            ("0deg", 0.0),
            ("4pi/8", h),
        ] {
            assert_eq!(parse_angle(s), Ok(v), "{s}");
        }
        let (sn, cs) = runtime::model::exact_sin_cos(parse_angle("pi/2").unwrap());
        assert_eq!((sn, cs), (1.0, 0.0));
    }

    #[test]
    fn other_angles() {
        assert_eq!(parse_angle("2*pi/3"), Ok(2.0 * PI / 3.0));
        assert_eq!(parse_angle("-3pi/4"), Ok(-3.0 * PI / 4.0));
        assert_eq!(parse_angle("0.5*pi"), Ok(0.5 * PI));
        assert_eq!(parse_angle("-45 deg"), Ok((-45.0f64).to_radians()));
        assert_eq!(parse_angle("1.2 rad"), Ok(1.2));
        assert_eq!(parse_angle("1.570796325"), Ok(1.570796325));
        assert_eq!(parse_angle("1e-3rad"), Ok(1e-3));
    }

    #[test]
    fn bad_angles() {
        for s in [
            "", "pie", "pi/0", "pi/", "x*pi", "*pi", "90 degs", "inf", "nan", "1..2", "pi*2",
            "deg", "1e999",
        ] {
            assert!(parse_angle(s).is_err(), "{s:?} -> {:?}", parse_angle(s));
        }
    }
}
