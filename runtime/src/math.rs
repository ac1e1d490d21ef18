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
/// instruction where the target has FMA (`-C target-cpu=native`); otherwise std calls the
/// platform's `fma` and the `libm` crate computes it in software, both exact to one rounding.
#[inline(always)]
pub fn mul_add(x: f64, y: f64, z: f64) -> f64 {
    #[cfg(all(feature = "std", not(feature = "libm-force")))]
    {
        x.mul_add(y, z)
    }
    #[cfg(not(all(feature = "std", not(feature = "libm-force"))))]
    {
        libm::fma(x, y, z)
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
        libm::fmaf(x, y, z)
    }
}
