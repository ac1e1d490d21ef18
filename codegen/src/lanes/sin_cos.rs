//! `Lanes::sin_cos` over all lanes at once ([`crate::Config::vector_sin_cos`]): a branch-free
//! polynomial that LLVM vectorizes, in place of the math backend's `sin_cos` once per lane
//! (which is most of a `_lanes` inverse dynamics: docs/performance.md, "Many states per
//! call").
//!
//! Per lane, in `f64` (an `f32` lane is widened, evaluated and rounded back):
//! 1. reduction by π/2 (Cody–Waite): `n = round(x·2/π)` by adding and subtracting 1.5·2⁵²,
//!    then `r = ((x − n·P₁) − n·P₂) − n·P₃` with π/2 split into three 33-bit parts, so that
//!    every product `n·Pᵢ` is exact for `|n| ≤ 2¹⁹`; `r ∈ [−π/4, π/4]` up to rounding;
//! 2. `sin r` and `cos r` by the minimax polynomials of fdlibm's `__kernel_sin` and
//!    `__kernel_cos` (degree 13 and 14; Sun Microsystems' freely distributable fdlibm 5.3,
//!    the coefficients of its `k_sin.c` and `k_cos.c`), `cos` with fdlibm's correction of
//!    `1 − r²/2`;
//! 3. the quadrant `n mod 4` swaps and negates the pair by selects, not branches. It is read
//!    from the bits of `t = x·2/π + 1.5·2⁵²`, whose mantissa is `n + 2⁵¹` (unit last place),
//!    so its two low bits are `n mod 4`: integer operations that vectorize, where `n as i32`
//!    is a saturating conversion per lane (six scalar instructions each on x86).
//!
//! A call whose lanes are not all finite and within `|x| ≤ 2¹⁹·π/2` (about 8.2e5 rad) takes the
//! backend's `sin_cos` for every lane instead: the reduction above would no longer be exact.
//! Accuracy (tests/tests/lanes.rs, against values correctly rounded by mpmath): within 2 ulp
//! where `|sin|` or `|cos| ≥ 2⁻²⁰`; near their zeros the reduction's error dominates, absolute
//! (within 2⁻⁵³), not relative. Not bit for bit the backend's: an option of its own.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::emit;

/// The largest `|x|` the reduction takes: `2¹⁹·π/2` rounded down.
const RANGE: f64 = 823_549.0;

/// The body of `Lanes::sin_cos` (`self` is the `Lanes`; `backend` the body that calls the math
/// backend per lane, for lanes out of range) and, after it, the per-lane kernel
/// `lane_sin_cos(x: f64) -> (f64, f64)` as a module item.
pub(super) fn body_and_kernel(idx: &[Literal], backend: TokenStream) -> (TokenStream, TokenStream) {
    let real = emit::real();
    // An `f32` lane is widened to `f64` and rounded back; an `f64` one needs no cast.
    let (widen, narrow) = if crate::scalar::single() {
        (quote!(as f64), quote!(as f32))
    } else {
        (TokenStream::new(), TokenStream::new())
    };
    let range = Literal::f64_suffixed(RANGE);
    let in_range = idx
        .iter()
        .map(|i| quote!(#real::abs(self.0[#i]) #widen <= #range));
    let body = quote! {
        // `!(|x| <= RANGE)` is also true of NaN.
        if #(#in_range)&&* {
            let (mut s, mut c) = (self.0, self.0);
            for ((s, c), x) in s.iter_mut().zip(c.iter_mut()).zip(self.0) {
                let (a, b) = lane_sin_cos(x #widen);
                *s = a #narrow;
                *c = b #narrow;
            }
            (Lanes(s), Lanes(c))
        } else {
            #backend
        }
    };
    let kernel = quote! {
        /// `(sin x, cos x)` for `|x| ≤ 2¹⁹·π/2`: Cody–Waite reduction by π/2 and fdlibm's
        /// kernels, branch-free (the `_lanes` functions' vector `sin_cos`).
        #[inline(always)]
        #[allow(clippy::excessive_precision, clippy::unreadable_literal)]
        fn lane_sin_cos(x: f64) -> (f64, f64) {
            const SHIFT: f64 = 6755399441055744.0;
            const P1: f64 = 1.57079632673412561417e+00;
            const P2: f64 = 6.07710050630396597660e-11;
            const P3: f64 = 2.02226624871116645580e-21;
            const S1: f64 = -1.66666666666666324348e-01;
            const S2: f64 = 8.33333333332248946124e-03;
            const S3: f64 = -1.98412698298579493134e-04;
            const S4: f64 = 2.75573137070700676789e-06;
            const S5: f64 = -2.50507602534068634195e-08;
            const S6: f64 = 1.58969099521155010221e-10;
            const C1: f64 = 4.16666666666666019037e-02;
            const C2: f64 = -1.38888888888741095749e-03;
            const C3: f64 = 2.48015872894767294178e-05;
            const C4: f64 = -2.75573143513906633035e-07;
            const C5: f64 = 2.08757232129817482790e-09;
            const C6: f64 = -1.13596475577881948265e-11;
            let t = x * core::f64::consts::FRAC_2_PI + SHIFT;
            let n = t - SHIFT;
            let r = ((x - n * P1) - n * P2) - n * P3;
            let z = r * r;
            let sin = r + z * r * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
            let w = z * z;
            let q = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
            let hz = 0.5 * z;
            let one_minus = 1.0 - hz;
            let cos = one_minus + (((1.0 - one_minus) - hz) + z * q);
            let quadrant = t.to_bits() & 3;
            let (a, b) = if quadrant & 1 != 0 { (cos, sin) } else { (sin, cos) };
            let a = if quadrant & 2 != 0 { -a } else { a };
            let b = if (quadrant + 1) & 2 != 0 { -b } else { b };
            (a, b)
        }
    };
    (body, kernel)
}
