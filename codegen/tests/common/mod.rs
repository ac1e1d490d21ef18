//! Helpers shared by the integration tests of `codegen`.
#![allow(dead_code)]

/// The numbers in `s` and the text between them.
pub fn split(s: &str) -> (Vec<f64>, String) {
    let mut numbers = Vec::new();
    let mut text = String::new();
    let b = s.as_bytes();
    let mut k = 0;
    while k < b.len() {
        let starts = (b[k].is_ascii_digit()
            || (b[k] == b'-' && b.get(k + 1).is_some_and(u8::is_ascii_digit)))
            && (k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_'));
        if starts {
            let start = k;
            k += 1;
            while k < b.len()
                && (b[k].is_ascii_digit()
                    || b[k] == b'.'
                    || b[k] == b'e'
                    || (b[k] == b'-' && b[k - 1] == b'e'))
            {
                k += 1;
            }
            numbers.push(s[start..k].parse().expect("a number"));
            text.push('#');
        } else {
            text.push(b[k] as char);
            k += 1;
        }
    }
    (numbers, text)
}

/// The largest relative difference of the numbers of two `Debug` texts that differ in nothing
/// else (`-0.0` and `0.0` alike); panics if the texts differ elsewhere.
pub fn worst_difference(a: &str, b: &str) -> f64 {
    let ((x, ta), (y, tb)) = (split(a), split(b));
    assert_eq!(ta, tb, "the texts differ in more than numbers");
    x.iter()
        .zip(&y)
        .map(|(p, q)| (p - q).abs() / p.abs().max(q.abs()).max(1.0))
        .fold(0.0, f64::max)
}
