//! `Lanes`' arithmetic through the `wide` crate ([`crate::Config::wide`]): each operator
//! converts its arrays to `wide`'s vector type of the same width, applies the vector operation
//! and converts back. The conversions are bit casts that LLVM folds away between operations,
//! so the statements stay in vector registers, which the plain lane-by-lane operators leave to
//! LLVM's SLP vectorizer (and it does not always take them: a long kernel can come out scalar).
//! `wide` picks the instructions at compile time from the target's features (SSE2, AVX,
//! AVX-512, NEON, WASM SIMD, or a scalar fallback) in safe code, `no_std`.
//!
//! Bit for bit the plain operators: `+ - * /` and `sqrt` are IEEE operations, correctly
//! rounded on every path `wide` takes, and its `neg` flips the sign bit as `-x` does. The LU
//! pivots' `select_abs_gt` is `wide`'s `abs` (the sign bit cleared, as `f64::abs`), its ordered
//! `simd_gt` (false where a lane is NaN, as `>`) and its `select`.
//! `mul_add` takes `wide`'s only where it is one fused operation on every width (x86 with FMA,
//! AArch64), and the math backend per lane elsewhere.

use proc_macro2::{Ident, Span, TokenStream};
use quote::{format_ident, quote};

/// `wide`'s vector type of `l` lanes of the generated real, if it has one.
pub(crate) fn vector_type(single: bool, l: usize) -> Option<&'static str> {
    match (single, l) {
        (false, 2) => Some("f64x2"),
        (false, 4) => Some("f64x4"),
        (false, 8) => Some("f64x8"),
        (true, 4) => Some("f32x4"),
        (true, 8) => Some("f32x8"),
        (true, 16) => Some("f32x16"),
        _ => None,
    }
}

/// The lane counts `wide` has a vector type for, as a message fragment.
pub(crate) const WIDTHS: &str = "2, 4 or 8 in `f64`, 4, 8 or 16 in `f32`";

/// The vector type's path: `<crate>::<type>`.
fn path(krate: &str, ty: &str) -> TokenStream {
    let krate: syn::Path = syn::parse_str(krate).unwrap_or_else(|_| syn::parse_quote!(wide));
    let ty = Ident::new(ty, Span::call_site());
    quote!(#krate::#ty)
}

/// The binary operator `tr::m` (`Add::add`, …) of `Lanes` over the vector type `w`.
pub(crate) fn binop(krate: &str, ty: &str, tr: &str, m: &str, op: TokenStream) -> TokenStream {
    let w = path(krate, ty);
    let (tr, m) = (format_ident!("{}", tr), format_ident!("{}", m));
    quote! {
        impl core::ops::#tr for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn #m(self, o: Lanes) -> Lanes {
                Lanes((#w::new(self.0) #op #w::new(o.0)).to_array())
            }
        }
    }
}

/// The bodies of `neg` and `sqrt`.
pub(crate) fn unary(krate: &str, ty: &str) -> (TokenStream, TokenStream) {
    let w = path(krate, ty);
    (
        quote!(Lanes((-#w::new(self.0)).to_array())),
        quote!(Lanes(#w::new(self.0).sqrt().to_array())),
    )
}

/// The body of `select_abs_gt(self, b, x, y)`: `x` where `|self| > |b|`, else `y`, per lane.
pub(crate) fn select_abs_gt(krate: &str, ty: &str) -> TokenStream {
    let w = path(krate, ty);
    quote! {
        Lanes(
            #w::new(self.0)
                .abs()
                .simd_gt(#w::new(b.0).abs())
                .select(#w::new(x.0), #w::new(y.0))
                .to_array(),
        )
    }
}

/// `mul_add`: `wide`'s fused one where every width fuses, `per_lane` (its body) elsewhere.
pub(crate) fn mul_add(krate: &str, ty: &str, per_lane: TokenStream) -> TokenStream {
    let w = path(krate, ty);
    let fused = quote!(any(
        all(
            any(target_arch = "x86", target_arch = "x86_64"),
            target_feature = "fma"
        ),
        all(target_arch = "aarch64", target_feature = "neon")
    ));
    quote! {
        /// `self * b + c` per lane, one rounding.
        #[cfg(#fused)]
        #[inline(always)]
        pub fn mul_add(self, b: Lanes, c: Lanes) -> Lanes {
            Lanes(#w::new(self.0).mul_add(#w::new(b.0), #w::new(c.0)).to_array())
        }
        /// `self * b + c` per lane, one rounding.
        #[cfg(not(#fused))]
        #[inline(always)]
        pub fn mul_add(self, b: Lanes, c: Lanes) -> Lanes {
            #per_lane
        }
    }
}
