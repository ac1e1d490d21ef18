//! The polynomial `sin_cos`: a branch-free `(sin x, cos x)` that LLVM vectorizes, for many
//! arguments at once in place of the math backend's one call each. Two uses:
//! - `Lanes::sin_cos` over all lanes ([`crate::Config::vector_sin_cos`]), where the backend once
//!   per lane is most of a `_lanes` inverse dynamics (docs/performance.md, "Many states per
//!   call");
//! - a scalar function's angles in one call ([`crate::Config::batch_sin_cos`]): [`batched`]
//!   moves every `sin_cos` whose argument is computed from the inputs alone (a tree's joint
//!   angles) into one step before the rest, which calls `sin_cos_batch` on them as one array.
//!
//! Per argument, in `f64` (an `f32` one is widened, evaluated and rounded back):
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
//! A call whose arguments are not all finite and within `|x| ≤ 2¹⁹·π/2` (about 8.2e5 rad)
//! takes the backend's `sin_cos` for every one instead: the reduction above would no longer be
//! exact. Accuracy (tests/tests/lanes.rs, against values correctly rounded by mpmath): within
//! 2 ulp where `|sin|` or `|cos| ≥ 2⁻²⁰`; near their zeros the reduction's error dominates,
//! absolute (within 2⁻⁵³), not relative. Not bit for bit the backend's: options of their own.

use std::collections::{HashMap, HashSet};

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::Config;
use crate::emit;
use crate::schedule::{Schedule, Step};
use crate::sym::{ExprId, Graph, Node};

/// The largest `|x|` the reduction takes: `2¹⁹·π/2` rounded down.
const RANGE: f64 = 823_549.0;

/// The casts around the `f64` kernel (an `f32` argument is widened to `f64` and its values
/// rounded back; an `f64` one needs none) and the literal of [`RANGE`].
fn casts() -> (TokenStream, TokenStream, Literal) {
    let (widen, narrow) = if crate::scalar::single() {
        (quote!(as f64), quote!(as f32))
    } else {
        (TokenStream::new(), TokenStream::new())
    };
    (widen, narrow, Literal::f64_suffixed(RANGE))
}

/// The body of `Lanes::sin_cos` (`self` is the `Lanes`, of lanes `idx`; `backend` the body
/// that calls the math backend per lane, for lanes out of range).
pub(crate) fn lanes_body(idx: &[Literal], backend: TokenStream) -> TokenStream {
    let real = emit::real();
    let (widen, narrow, range) = casts();
    let in_range = idx
        .iter()
        .map(|i| quote!(#real::abs(self.0[#i]) #widen <= #range));
    quote! {
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
    }
}

/// The per-argument kernel `lane_sin_cos(x: f64) -> (f64, f64)`, a module item.
pub(crate) fn kernel() -> TokenStream {
    quote! {
        /// `(sin x, cos x)` for `|x| ≤ 2¹⁹·π/2`: Cody–Waite reduction by π/2 and fdlibm's
        /// kernels, branch-free: it vectorizes over many arguments (`Lanes::sin_cos` over the
        /// lanes, `sin_cos_batch` over a function's angles).
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
    }
}

/// Whether [`crate::Config::batch_sin_cos`] batches any of `functions` (none has an angle of
/// the inputs alone in a platform's task coordinates, say: the module is then the same as
/// without the option, byte for byte).
pub(crate) fn batches(cfg: &Config, g: &Graph, functions: &[emit::Function<'_>]) -> bool {
    cfg.batch_sin_cos
        && functions
            .iter()
            .any(|f| !members(g, &f.schedule).is_empty())
}

/// The `(sin, cos, arg)` of every `sin_cos` of `s` whose argument depends on the inputs alone,
/// in schedule order: what [`batched`] puts in one call.
fn members(g: &Graph, s: &Schedule) -> Vec<(usize, usize, ExprId)> {
    let mut memo = HashMap::new();
    s.steps
        .iter()
        .filter_map(|st| match *st {
            Step::SinCos { sin, cos, arg } if of_inputs(g, arg, &mut memo) => Some((sin, cos, arg)),
            _ => None,
        })
        .collect()
}

/// The module items of [`crate::Config::batch_sin_cos`] (when it [`batches`]):
/// `sin_cos_batch`, and the kernel `lane_sin_cos` unless the `_lanes` functions'
/// `Lanes::sin_cos` brings it ([`crate::Config::vector_sin_cos`]).
pub(crate) fn batch_items(cfg: &Config) -> TokenStream {
    let real = emit::real();
    let (widen, narrow, range) = casts();
    let backend = emit::math_call(cfg, "sin_cos", quote!(x));
    let kernel = if cfg.vector_sin_cos && cfg.lanes.is_some() {
        TokenStream::new()
    } else {
        kernel()
    };
    quote! {
        /// `(sin, cos)` of every element of `x` at once (a polynomial that vectorizes; the math
        /// backend for every element when one is beyond |x| = 2¹⁹·π/2 or not finite).
        #[inline(always)]
        fn sin_cos_batch<const N: usize>(x: [#real; N]) -> ([#real; N], [#real; N]) {
            let (mut s, mut c) = (x, x);
            for ((s, c), x) in s.iter_mut().zip(c.iter_mut()).zip(x) {
                let (a, b) = lane_sin_cos(x #widen);
                *s = a #narrow;
                *c = b #narrow;
            }
            // The polynomial first and this test after it, without an early exit: both stay
            // in vector registers (a branch around the polynomial, or a loop that writes
            // either route's values into one array, costs the call a round trip through
            // memory). `!(|x| <= RANGE)` is also true of NaN.
            if x.iter().fold(true, |ok, v| ok & (#real::abs(*v) #widen <= #range)) {
                (s, c)
            } else {
                sin_cos_backend(x)
            }
        }
        /// `(sin, cos)` of every element of `x` by the math backend (`sin_cos_batch` beyond
        /// the polynomial's range).
        #[cold]
        #[inline(never)]
        fn sin_cos_backend<const N: usize>(x: [#real; N]) -> ([#real; N], [#real; N]) {
            let (mut s, mut c) = (x, x);
            for ((s, c), x) in s.iter_mut().zip(c.iter_mut()).zip(x) {
                (*s, *c) = #backend;
            }
            (s, c)
        }
        #kernel
    }
}

/// `s` with every `sin_cos` whose argument depends on the inputs alone in one
/// [`Step::SinCosBatch`], placed after the statements its arguments need (moved first, in
/// their order) and before all others (a pure function: the order is free, and the guards keep
/// theirs). `s` itself when there is none.
pub(crate) fn batched(g: &Graph, s: &Schedule) -> Schedule {
    let batch = members(g, s);
    if batch.is_empty() {
        return s.clone();
    }
    let members: HashSet<usize> = batch.iter().map(|&(sin, _, _)| sin).collect();
    let is_member = |st: &Step| matches!(*st, Step::SinCos { sin, .. } if members.contains(&sin));
    // The statements the arguments read, transitively (of the inputs alone, like them).
    let defined: HashMap<usize, usize> = s
        .steps
        .iter()
        .enumerate()
        .flat_map(|(i, st)| emit::step_vars(g, s, st).0.into_iter().map(move |v| (v, i)))
        .collect();
    let mut needed = HashSet::new();
    let mut stack: Vec<usize> = s
        .steps
        .iter()
        .filter(|st| is_member(st))
        .flat_map(|st| emit::step_vars(g, s, st).1)
        .collect();
    while let Some(v) = stack.pop() {
        let Some(&i) = defined.get(&v) else { continue };
        if needed.insert(i) {
            stack.extend(emit::step_vars(g, s, &s.steps[i]).1);
        }
    }
    let mut steps: Vec<Step> = (0..s.steps.len())
        .filter(|i| needed.contains(i))
        .map(|i| s.steps[i])
        .collect();
    steps.push(Step::SinCosBatch);
    steps.extend(
        s.steps
            .iter()
            .enumerate()
            .filter(|&(i, st)| !needed.contains(&i) && !is_member(st))
            .map(|(_, st)| *st),
    );
    Schedule {
        steps,
        names: s.names.clone(),
        ops: s.ops,
        batch,
    }
}

/// Whether `id`'s value is computed from inputs and constants by arithmetic alone.
fn of_inputs(g: &Graph, id: ExprId, memo: &mut HashMap<ExprId, bool>) -> bool {
    if let Some(&b) = memo.get(&id) {
        return b;
    }
    let b = match g.node(id) {
        Node::Input(..) | Node::Const(_) => true,
        Node::Add(..) | Node::Sub(..) | Node::Mul(..) | Node::Neg(..) => {
            g.operands(id).all(|o| of_inputs(g, o, memo))
        }
        _ => false,
    };
    memo.insert(id, b);
    b
}

/// The statement of the [`Step::SinCosBatch`] of `s`: `let ([s…, _], [c…, _]) =
/// sin_cos_batch([x…, 0.0]);`, the array padded to a width that fills vector registers (a
/// power of two up to 8, then a multiple of 8).
pub(crate) fn batch_statement(g: &Graph, s: &Schedule) -> TokenStream {
    let n = s.batch.len();
    let width = if n <= 8 {
        n.next_power_of_two().max(2)
    } else {
        n.div_ceil(8) * 8
    };
    let pad = width - n;
    let sins = s.batch.iter().map(|&(sin, _, _)| emit::var(sin));
    let coss = s.batch.iter().map(|&(_, cos, _)| emit::var(cos));
    let args = s.batch.iter().map(|&(_, _, a)| emit::operand(g, s, a));
    let holes = vec![quote!(_); pad];
    let zeros = vec![quote!(0.0); pad];
    quote!(let ([#(#sins,)* #(#holes),*], [#(#coss,)* #(#holes),*]) = sin_cos_batch([#(#args,)* #(#zeros),*]);)
}
