//! Numbers and small vector algebra written as the generators have always written them (they
//! were Python scripts): `repr` of a float, `%g`, and sums that start from the integer 0, so that
//! the files they write stay byte for byte the same.

/// The shortest decimal digits of `x` (no sign, no point) and the exponent of the first digit.
fn shortest(x: f64) -> (String, i32) {
    let s = format!("{:e}", x.abs());
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    (mantissa.replace('.', ""), exp.parse().unwrap_or(0))
}

/// Digits `d` with first-digit exponent `e`, in Python's layout: fixed when `-4 <= e < limit`,
/// else `d.ddde±XX`; `keep_point` adds `.0` to whole fixed numbers (as `repr`).
fn layout(neg: bool, digits: &str, e: i32, limit: i32, keep_point: bool) -> String {
    let sign = if neg { "-" } else { "" };
    if (-4..limit).contains(&e) {
        let body = if e < 0 {
            format!("0.{}{digits}", "0".repeat((-e - 1) as usize))
        } else if digits.len() as i32 > e + 1 {
            let (int, frac) = digits.split_at((e + 1) as usize);
            format!("{int}.{frac}")
        } else {
            let int = format!("{digits}{}", "0".repeat((e + 1) as usize - digits.len()));
            if keep_point { format!("{int}.0") } else { int }
        };
        format!("{sign}{body}")
    } else {
        let (first, rest) = digits.split_at(1);
        let point = if rest.is_empty() {
            String::new()
        } else {
            format!(".{rest}")
        };
        let esign = if e < 0 { '-' } else { '+' };
        format!("{sign}{first}{point}e{esign}{:02}", e.abs())
    }
}

/// Python's `repr(float(x))`.
pub fn repr(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    if x == 0.0 {
        return if x.is_sign_negative() { "-0.0" } else { "0.0" }.into();
    }
    let (digits, e) = shortest(x);
    layout(x < 0.0, &digits, e, 16, true)
}

/// Python's `"%.{p}g" % x`.
pub fn g(x: f64, p: usize) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    let p = p.max(1);
    let s = format!("{:.*e}", p - 1, x.abs());
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = exp.parse().unwrap_or(0);
    let digits = mantissa.replace('.', "");
    let digits = digits.trim_end_matches('0');
    let digits = if digits.is_empty() { "0" } else { digits };
    let neg = x.is_sign_negative() && x != 0.0 || (x == 0.0 && x.is_sign_negative());
    layout(neg, digits, e, p as i32, false)
}

/// Python's `sum(…)` of floats: from the integer 0, left to right (a first `-0.0` becomes `0.0`).
pub fn sum(items: impl IntoIterator<Item = f64>) -> f64 {
    let mut it = items.into_iter();
    let Some(first) = it.next() else {
        return 0.0;
    };
    it.fold(0.0 + first, |a, b| a + b)
}

/// A 3-vector.
pub type V3 = [f64; 3];
/// A 3 × 3 matrix, row-major.
pub type M3 = [[f64; 3]; 3];

/// `a + b`.
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// `a − b`.
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// `s a`.
pub fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}
/// `a × b`.
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repr_is_pythons() {
        for (x, want) in [
            (0.0, "0.0"),
            (-0.0, "-0.0"),
            (1.0, "1.0"),
            (-9.81, "-9.81"),
            (4e-4, "0.0004"),
            (2e-5, "2e-05"),
            (1.1e-5, "1.1e-05"),
            (2.5e-4, "0.00025"),
            (1e16, "1e+16"),
            (1.5e16, "1.5e+16"),
            (1e15, "1000000000000000.0"),
            (123.456, "123.456"),
            (0.1 + 0.2, "0.30000000000000004"),
            (1.0 / 160.0, "0.00625"),
        ] {
            assert_eq!(repr(x), want, "{x:e}");
        }
    }

    #[test]
    fn g_is_pythons() {
        for (x, p, want) in [
            (12.3456, 3, "12.3"),
            (1234.5, 3, "1.23e+03"),
            (0.000123456, 3, "0.000123"),
            (0.0000123456, 3, "1.23e-05"),
            (100.0, 3, "100"),
            (1.0, 3, "1"),
            (2.5, 6, "2.5"),
            (0.0, 6, "0"),
            (f64::INFINITY, 3, "inf"),
        ] {
            assert_eq!(g(x, p), want, "{x:e}");
        }
    }
}
