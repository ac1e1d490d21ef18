//! Python 3.11's `math.hypot` and `x ** 2`, whose results differ from `f64::hypot` and `x * x`
//! in the last bit now and then: the generators' numbers stay those the Python scripts wrote.

/// `2^27 + 1`, Veltkamp's splitter.
const T27: f64 = 134_217_729.0;

/// `x` split into a high part of 26 bits and the rest: `hi + lo == x`.
fn split(x: f64) -> (f64, f64) {
    let t = x * T27;
    let hi = t - (t - x);
    (hi, x - hi)
}

/// `csum += x`, the rounding error added to `frac`.
fn accumulate(csum: &mut f64, frac: &mut f64, x: f64) {
    let old = *csum;
    *csum += x;
    *frac += (old - *csum) + x;
}

/// `(m, e)` with `x = m · 2^e`, `0.5 <= |m| < 1` (C's `frexp`, for normal `x`).
fn frexp_exponent(x: f64) -> i32 {
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i32;
    biased - 1022
}

/// CPython 3.11's `math.hypot(a, b)` (`vector_norm`: the squares summed with their rounding
/// errors, then one differential correction of the square root).
pub fn hypot(a: f64, b: f64) -> f64 {
    let v = [a.abs(), b.abs()];
    let max = v[0].max(v[1]);
    if max.is_infinite() {
        return max;
    }
    if a.is_nan() || b.is_nan() {
        return f64::NAN;
    }
    if max == 0.0 {
        return max;
    }
    let max_e = frexp_exponent(max);
    if max_e < -1021 {
        // Subnormal: CPython rescales by DBL_MIN first; never met by the generators.
        return a.hypot(b);
    }
    let scale = 2.0f64.powi(-max_e);
    let (mut csum, mut frac1, mut frac2, mut frac3) = (1.0, 0.0, 0.0, 0.0);
    for x in v {
        let (hi, lo) = split(x * scale);
        accumulate(&mut csum, &mut frac1, hi * hi);
        accumulate(&mut csum, &mut frac2, 2.0 * hi * lo);
        frac3 += lo * lo;
    }
    let h = (csum - 1.0 + (frac1 + frac2 + frac3)).sqrt();
    let (hi, lo) = split(h);
    accumulate(&mut csum, &mut frac1, -hi * hi);
    accumulate(&mut csum, &mut frac2, -2.0 * hi * lo);
    accumulate(&mut csum, &mut frac3, -lo * lo);
    let x = csum - 1.0 + (frac1 + frac2 + frac3);
    (h + x / (2.0 * h)) / scale
}

/// Python's `x ** 2`: the C library's `pow`, which is not always `x * x` (the exponent is
/// hidden from the optimizer, which would make it a product).
pub fn square(x: f64) -> f64 {
    x.powf(std::hint::black_box(2.0))
}
