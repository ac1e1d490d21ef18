//! The math layer generated code calls: `sin_cos`, `sqrt`, `atan2`, `mul_add`.
//!
//! With the `std` feature (and without `libm-force`) these are std's methods (LLVM intrinsics and
//! the platform libm); otherwise the pure-Rust `libm` crate, which gives bit-identical results on
//! every target. The two backends may differ by one ulp in sin/cos.

/// `(sin x, cos x)`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.sin_cos()
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::sincos(x)
    }
}

/// Square root.
#[inline(always)]
pub fn sqrt(x: f64) -> f64 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.sqrt()
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::sqrt(x)
    }
}

/// `(sin x, cos x)` in single precision.
#[inline(always)]
pub fn sin_cos_f32(x: f32) -> (f32, f32) {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.sin_cos()
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::sincosf(x)
    }
}

/// Square root in single precision.
#[inline(always)]
pub fn sqrt_f32(x: f32) -> f32 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.sqrt()
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::sqrtf(x)
    }
}

/// `atan2(y, x)`: the angle of the point `(x, y)`, in `(−π, π]`.
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        y.atan2(x)
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::atan2(y, x)
    }
}

/// `atan2(y, x)` in single precision.
#[inline(always)]
pub fn atan2_f32(y: f32, x: f32) -> f32 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        y.atan2(x)
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::atan2f(y, x)
    }
}

/// `x * y + z` with one rounding (fused multiply–add; generated code with `Config::fma`). One
/// instruction where the target has FMA at compile time (`-C target-cpu=native`, `-C
/// target-feature=+fma`), with or without std: std's `mul_add`, or without std on x86 the
/// instruction through `safe_arch`. Elsewhere std calls the platform's `fma`, and the `libm`
/// crate's chooses at run time (on x86, through a function pointer) or computes it in software.
/// Every route rounds once, so all give the same bits, `libm-force` included.
#[inline(always)]
pub fn mul_add(x: f64, y: f64, z: f64) -> f64 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.mul_add(y, z)
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        fused::fma(x, y, z)
    }
}

/// [`mul_add`] in single precision.
#[inline(always)]
pub fn mul_add_f32(x: f32, y: f32, z: f32) -> f32 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.mul_add(y, z)
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        fused::fmaf(x, y, z)
    }
}

/// The fused multiply–add without std where x86 has FMA at compile time: the instruction,
/// inlined, where `libm` would call through a pointer it sets at run time (a call `no-panic`
/// cannot see through; docs/performance.md, "Fused multiply–add").
#[cfg(all(
    not(all(feature = "std", not(feature = "libm-force"))),
    any(target_arch = "x86", target_arch = "x86_64"),
    target_feature = "fma"
))]
mod fused {
    #[inline(always)]
    pub fn fma(x: f64, y: f64, z: f64) -> f64 {
        use safe_arch::{fused_mul_add_m128d_s, get_f64_from_m128d_s, set_m128d_s};
        get_f64_from_m128d_s(fused_mul_add_m128d_s(
            set_m128d_s(x),
            set_m128d_s(y),
            set_m128d_s(z),
        ))
    }

    #[inline(always)]
    pub fn fmaf(x: f32, y: f32, z: f32) -> f32 {
        use safe_arch::{fused_mul_add_m128_s, get_f32_from_m128_s, set_m128_s};
        get_f32_from_m128_s(fused_mul_add_m128_s(
            set_m128_s(x),
            set_m128_s(y),
            set_m128_s(z),
        ))
    }
}

#[cfg(all(
    not(all(feature = "std", not(feature = "libm-force"))),
    not(all(
        any(target_arch = "x86", target_arch = "x86_64"),
        target_feature = "fma"
    ))
))]
use libm as fused;

#[cfg(test)]
mod tests {
    /// One rounding: with `p = x·x` rounded, `mul_add(x, x, −p)` is the product's exact
    /// rounding error, where a multiply and an add give 0. `x = 1 + 2⁻³⁰`: `x² = 1 + 2⁻²⁹ +
    /// 2⁻⁶⁰`, `p = 1 + 2⁻²⁹`, the error `2⁻⁶⁰` (in `f32`, `x = 1 + 2⁻¹⁵` and `2⁻³⁰`). Run with
    /// `--features libm-force`, and `RUSTFLAGS="-C target-feature=+fma"`, for the other routes.
    #[test]
    fn mul_add_rounds_once() {
        let x = 1.0 + 2f64.powi(-30);
        assert_eq!(super::mul_add(x, x, -(x * x)), 2f64.powi(-60));
        let x = 1.0 + 2f32.powi(-15);
        assert_eq!(super::mul_add_f32(x, x, -(x * x)), 2f32.powi(-30));
    }
}
