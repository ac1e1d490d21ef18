//! Straight-line LU solves of a platform's actuation matrix `A` (`DOF × DOF`).
//!
//! The generated module solves with `A` in three places: `Aᵀ τ = f` in the inverse dynamics
//! (the lecture's eq. 66 rearranged), `A Δx = Δq` in each forward-kinematics Newton step, and
//! `A⁻¹` (all `DOF` columns of the identity) for `A⁻ᵀ I A⁻¹` (eq. 68). Each is emitted as one
//! function of straight-line code: every index is a constant, every entry a local, so nothing
//! is left to the optimizer's loop unrolling or unswitching (a loop over a row swap that depends
//! on a comparison gets unswitched into an unpredictable branch).
//!
//! The factorization is Gaussian elimination with partial pivoting:
//! - at step `k` each lower row `i` is swapped into row `k` by selects when `|m_ik| > |m_kk|`,
//!   so row `k` ends with the largest entry of the column (the pivot a search would choose, the
//!   first one on ties) without a data-dependent branch; the scalar solves keep the running
//!   `|m_kk|` apart (`top`, a `max`), so that the comparisons do not wait on the swaps;
//! - the tolerance test is that of the matrix with each column scaled by its unit group's
//!   reference ([`runtime::parallel::noc::ColumnUnits`]: the group's largest 2-norm, or
//!   another group's times the platform's radius `L` between rotation speeds (rad/s) and
//!   translation speeds (m/s), whichever is larger), so the test does not depend on the
//!   units, yet a column that shrinks against the others of its unit, or a whole group that
//!   vanishes (the platform moving along those speeds with the actuators still), is a small
//!   pivot (scaling changes neither the pivots chosen nor, in exact arithmetic, the solution):
//!   the scaled pivot `|p_k|/g_k` (`g_k` the reference) must exceed `tol` times
//!   the larger of 1 and the largest scaled pivot so far. It is compared squared and
//!   cross-multiplied, `p_k² · d > tol² · n · g_k²` with the largest so far kept as the
//!   fraction `n / d` (starting at 1), so the test needs neither a square root nor a division;
//!   those are spent only on the error path (the scaled pivot and the condition estimate
//!   reported in `Singular`);
//! - back substitution multiplies by the reciprocal pivots kept from the elimination;
//! - `Aᵀ τ = f` factorizes `A`, not `Aᵀ`: its swaps and multipliers are kept, and the solve
//!   runs `Uᵀ` forward, then `Lᵀ` and the swaps backward (LINPACK's `dgesl`). All three
//!   functions therefore test the same pivots of the same matrix, so at a given `x` the
//!   inverse dynamics, the actuator-space inertia and a Newton step agree on `Ok` versus
//!   `Err(Actuation(i))`.
//!
//! The operation count is [`crate::parallel::lu_many_ops`]; the error paths are not counted.
//!
//! With [`LuSolve::lanes`], the same statements over `Lanes` (`crate::lanes`): each select a
//! select per lane, so each lane makes the scalar function's operations on its own matrix (its
//! pivots chosen by its own comparisons) and its result is the scalar one bit for bit. A
//! failed test marks the lane in `bad` instead of returning; the caller takes that lane's
//! `Err` from the scalar function.

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};
use runtime::parallel::noc::ColumnUnits;

/// What the emitted function solves for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Rhs {
    /// One right-hand side `b: &[f64; DOF]`, solution `[f64; DOF]`.
    Vector,
    /// The identity's `DOF` columns: the inverse, `[[f64; DOF]; DOF]`.
    Identity,
}

/// One straight-line solve.
pub(crate) struct LuSolve<'a> {
    /// Name of the emitted function.
    pub name: &'a str,
    /// Doc comment of the emitted function.
    pub doc: &'a str,
    /// Matrix order (`DOF`).
    pub n: usize,
    /// Solve with `aᵀ` instead of `a`.
    pub transpose: bool,
    pub rhs: Rhs,
    /// The squared pivot tolerance, `tol²`.
    pub tol2: f64,
    /// The unit group of each column and the groups' conversion: a column's pivot is scaled
    /// by its group's reference.
    pub units: ColumnUnits<'a>,
    /// The square-root call of the chosen math backend, applied to the tokens given.
    pub sqrt: &'a dyn Fn(TokenStream) -> TokenStream,
    /// Over the lanes (`<name>_lanes`, see the module's doc).
    pub lanes: bool,
}

/// A constant: `c`, or `Lanes::splat(c)` over the lanes.
fn constant(lanes: bool, c: TokenStream) -> TokenStream {
    if lanes { quote!(Lanes::splat(#c)) } else { c }
}

/// `if a > b { x } else { y }`, per lane over the lanes.
fn select_gt(
    lanes: bool,
    a: TokenStream,
    b: TokenStream,
    x: TokenStream,
    y: TokenStream,
) -> TokenStream {
    if lanes {
        quote!(select_gt(#a, #b, #x, #y))
    } else {
        quote!(if #a > #b { #x } else { #y })
    }
}

/// `let (u, v) = (v, u)` where the swap flag `c` holds. Over the lanes the flag is not a
/// value but its comparison, `|c_a| > |c_b|` per lane (`Lanes::select_abs_gt`): selects by a
/// mask array kept LLVM from vectorizing them.
fn cond_swap(lanes: bool, c: &Ident, u: &Ident, v: &Ident) -> TokenStream {
    if lanes {
        let (ca, cb) = flag_operands(c);
        quote! {
            let (#u, #v) = (
                Lanes::select_abs_gt(#ca, #cb, #v, #u),
                Lanes::select_abs_gt(#ca, #cb, #u, #v),
            );
        }
    } else {
        quote!(let (#u, #v) = if #c { (#v, #u) } else { (#u, #v) };)
    }
}

/// The two operands a swap flag compares over the lanes (`|c_a| > |c_b|`).
fn flag_operands(c: &Ident) -> (Ident, Ident) {
    (format_ident!("{}_a", c), format_ident!("{}_b", c))
}

fn m(i: usize, j: usize) -> Ident {
    format_ident!("m{}_{}", i, j)
}

fn x(i: usize, c: usize) -> Ident {
    format_ident!("x{}_{}", i, c)
}

/// The swap flag of rows `k` and `i` at step `k` (transposed solve).
fn swap(k: usize, i: usize) -> Ident {
    format_ident!("s{}_{}", k, i)
}

/// The multiplier of row `i` at step `k` (transposed solve).
fn l(i: usize, k: usize) -> Ident {
    format_ident!("l{}_{}", i, k)
}

/// `aᵀ x = b` from the factorization `U = E_{n−2} P_{n−2} ⋯ E_0 P_0 a` (`P_k` the conditional
/// swaps of step `k`, `E_k = I − l_k e_kᵀ` its elimination; LINPACK's `dgesl` with `job ≠ 0`):
/// `Uᵀ z = b` forward, then `x = P_0ᵀ E_0ᵀ ⋯ P_{n−2}ᵀ E_{n−2}ᵀ z`, applied from the right.
fn transposed_solve(n: usize, lanes: bool, st: &mut Vec<TokenStream>) {
    for i in 0..n {
        let (xi, ri) = (x(i, 0), format_ident!("r{}", i));
        let terms = (0..i).map(|j| {
            let (ji, xj) = (m(j, i), x(j, 0));
            quote!(- #ji * #xj)
        });
        st.push(quote!(let #xi = (#xi #(#terms)*) * #ri;));
    }
    for k in (0..n.saturating_sub(1)).rev() {
        let xk = x(k, 0);
        let terms = (k + 1..n).map(|i| {
            let (lik, xi) = (l(i, k), x(i, 0));
            quote!(- #lik * #xi)
        });
        st.push(quote!(let #xk = #xk #(#terms)*;));
        for i in (k + 1..n).rev() {
            let (u, v, sw) = (x(k, 0), x(i, 0), swap(k, i));
            st.push(cond_swap(lanes, &sw, &u, &v));
        }
    }
}

/// The emitted function.
pub(crate) fn lu_solve_fn(s: &LuSolve<'_>) -> TokenStream {
    let n = s.n;
    let k_rhs = match s.rhs {
        Rhs::Vector => 1,
        Rhs::Identity => n,
    };
    let name = if s.lanes {
        format_ident!("{}_lanes", s.name)
    } else {
        format_ident!("{}", s.name)
    };
    let lanes = s.lanes;
    let doc = s.doc;
    let tol2 = Literal::f64_unsuffixed(s.tol2);
    let mut st: Vec<TokenStream> = Vec::new();
    // `aᵀ x = b` factorizes `a` itself (so that its pivots and verdict are those of the other
    // solves) and keeps the swaps and multipliers for the transposed solve after it.
    let tr = s.transpose;
    load_locals(s, k_rhs, &mut st);
    column_norms(n, &mut st);
    group_norms(s, &mut st);
    // The largest column of a group has unit norm once scaled: a pivot is compared with 1 as
    // well as with the largest before it.
    if lanes {
        st.push(quote!(let pn = Lanes::splat(1.0);));
        st.push(quote!(let pd = Lanes::splat(1.0);));
    } else {
        let real = crate::emit::real();
        st.push(quote!(let pn: #real = 1.0;));
        st.push(quote!(let pd: #real = 1.0;));
    }
    for k in 0..n {
        elimination_step(s, k, k_rhs, &tol2, &mut st);
    }
    if tr {
        transposed_solve(n, lanes, &mut st);
    }
    back_substitution(n, k_rhs, tr, &mut st);
    match (s.rhs, lanes) {
        (Rhs::Vector, false) => vector_fn(&name, doc, n, &st),
        (Rhs::Identity, false) => identity_fn(&name, doc, n, &st),
        (Rhs::Vector, true) => vector_lanes_fn(&name, n, &st),
        (Rhs::Identity, true) => identity_lanes_fn(&name, n, &st),
    }
}

/// The matrix and the right-hand sides as locals.
fn load_locals(s: &LuSolve<'_>, k_rhs: usize, st: &mut Vec<TokenStream>) {
    let n = s.n;
    for i in 0..n {
        for j in 0..n {
            let (mi, r, c) = (
                m(i, j),
                Literal::usize_unsuffixed(i),
                Literal::usize_unsuffixed(j),
            );
            st.push(if s.lanes {
                quote!(let #mi = Lanes(a[#r][#c]);)
            } else {
                quote!(let #mi = a[#r][#c];)
            });
        }
    }
    for i in 0..n {
        for c in 0..k_rhs {
            let xi = x(i, c);
            let v = match s.rhs {
                Rhs::Vector => {
                    let i = Literal::usize_unsuffixed(i);
                    if s.lanes {
                        quote!(Lanes(b[#i]))
                    } else {
                        quote!(b[#i])
                    }
                }
                Rhs::Identity if i == c => constant(s.lanes, quote!(1.0)),
                Rhs::Identity => constant(s.lanes, quote!(0.0)),
            };
            st.push(quote!(let #xi = #v;));
        }
    }
}

/// Squared column norms ‖a_j‖².
fn column_norms(n: usize, st: &mut Vec<TokenStream>) {
    for j in 0..n {
        let nj = format_ident!("n{}", j);
        let terms = (0..n).map(|i| {
            let e = m(i, j);
            quote!(#e * #e)
        });
        st.push(quote!(let #nj = #(#terms)+*;));
    }
}

/// The squared reference a pivot is scaled by: `g{j}`, the same for every column of a group.
/// With one unit group, the largest `n{i}` (by selects, NaN left out); with more, each group's
/// largest as `h{j}` (at its first column `j`), then the largest of it and every other group's
/// times [`ColumnUnits::factor2`] (`L²` or `1/L²`).
fn group_norms(s: &LuSolve<'_>, st: &mut Vec<TokenStream>) {
    let u = s.units;
    let first = |j: usize| (0..s.n).find(|&i| u.group(i) == u.group(j)).unwrap_or(j);
    let leaders: Vec<usize> = (0..s.n).filter(|&j| first(j) == j).collect();
    let own = |j: usize| if leaders.len() > 1 { h(j) } else { g(j) };
    for &j in &leaders {
        let (oj, n0) = (own(j), format_ident!("n{}", j));
        st.push(quote!(let #oj = #n0;));
        for i in j + 1..s.n {
            if u.group(i) == u.group(j) {
                let ni = format_ident!("n{}", i);
                let e = select_gt(s.lanes, quote!(#ni), quote!(#oj), quote!(#ni), quote!(#oj));
                st.push(quote!(let #oj = #e;));
            }
        }
    }
    if leaders.len() > 1 {
        for &j in &leaders {
            let (gj, hj) = (g(j), h(j));
            st.push(quote!(let #gj = #hj;));
            for &k in leaders.iter().filter(|&&k| k != j) {
                let (hk, c) = (
                    h(k),
                    constant(
                        s.lanes,
                        crate::emit::float_lit(u.factor2(u.group(k), u.group(j))),
                    ),
                );
                st.push(quote!(let c = #c * #hk;));
                let e = select_gt(s.lanes, quote!(c), quote!(#gj), quote!(c), quote!(#gj));
                st.push(quote!(let #gj = #e;));
            }
        }
    }
    for j in (0..s.n).filter(|&j| first(j) != j) {
        let (gj, gf) = (g(j), g(first(j)));
        st.push(quote!(let #gj = #gf;));
    }
}

fn h(j: usize) -> Ident {
    format_ident!("h{}", j)
}

fn g(j: usize) -> Ident {
    format_ident!("g{}", j)
}

/// Step `k` of the elimination: the conditional swaps, the pivot's test, its reciprocal and
/// the elimination below it.
fn elimination_step(
    s: &LuSolve<'_>,
    k: usize,
    k_rhs: usize,
    tol2: &Literal,
    st: &mut Vec<TokenStream>,
) {
    let (n, tr, lanes) = (s.n, s.transpose, s.lanes);
    pivot_swaps(n, k, k_rhs, tr, lanes, st);
    if lanes {
        pivot_flag(k, tol2, st);
    } else {
        pivot_test(s, k, tol2, st);
    }
    if k + 1 < n {
        let gk = g(k);
        st.push(if lanes {
            quote!(let (pn, pd) = (select_gt(lhs, rhs, b2, pn), select_gt(lhs, rhs, #gk, pd));)
        } else {
            quote!(let (pn, pd) = if lhs > rhs { (b2, #gk) } else { (pn, pd) };)
        });
    }
    let (kk, rk) = (m(k, k), format_ident!("r{}", k));
    let one = constant(lanes, quote!(1.0));
    st.push(quote!(let #rk = #one / #kk;));
    eliminate_below(n, k, k_rhs, tr, st);
}

/// Conditional swaps: row `k` ends with the largest |entry| of column `k`.
fn pivot_swaps(n: usize, k: usize, k_rhs: usize, tr: bool, lanes: bool, st: &mut Vec<TokenStream>) {
    let kk = m(k, k);
    for i in k + 1..n {
        let sw = if tr { swap(k, i) } else { format_ident!("s") };
        if lanes {
            let ((sa, sb), ik) = (flag_operands(&sw), m(i, k));
            st.push(quote!(let (#sa, #sb) = (#ik, #kk);));
        } else {
            // `top` is `|m_kk|` after the swaps so far (the same value: a swap moves it, the
            // absolute value is exact), kept apart so that each comparison waits on one
            // `max` rather than on the row swap before it.
            if i == k + 1 {
                st.push(quote!(let top = if #kk < 0.0 { -#kk } else { #kk };));
            }
            let ik = m(i, k);
            st.push(quote!(let cand = if #ik < 0.0 { -#ik } else { #ik };));
            st.push(quote!(let #sw = cand > top;));
            if i + 1 < n {
                st.push(quote!(let top = if #sw { cand } else { top };));
            }
        }
        for j in k..n {
            st.push(cond_swap(lanes, &sw, &m(k, j), &m(i, j)));
        }
        for c in 0..k_rhs {
            if tr {
                break;
            }
            st.push(cond_swap(lanes, &sw, &x(k, c), &x(i, c)));
        }
    }
}

/// [`pivot_test`] over the lanes: a lane whose pivot fails is marked in `bad`.
fn pivot_flag(k: usize, tol2: &Literal, st: &mut Vec<TokenStream>) {
    let real = crate::emit::real();
    let (kk, nk) = (m(k, k), g(k));
    st.push(quote! {
        let b2 = #kk * #kk;
        let lhs = b2 * pd;
        let rhs = pn * #nk;
        for (((bad, p), lhs), rhs) in bad.iter_mut().zip(#kk.0).zip(lhs.0).zip(rhs.0) {
            let best = if p < 0.0 { -p } else { p };
            *bad |= !((best > 0.0) & (best < #real::INFINITY)) | !(lhs > #tol2 * rhs);
        }
    });
}

/// The pivot's test against the column-scaled tolerance, `Err(Actuation(k))` when it fails.
fn pivot_test(s: &LuSolve<'_>, k: usize, tol2: &Literal, st: &mut Vec<TokenStream>) {
    let real = crate::emit::real();
    let kk = m(k, k);
    let kl = Literal::usize_unsuffixed(k);
    let nk = g(k);
    let sqrt_n = (s.sqrt)(quote!(s));
    st.push(quote! {
        let best = if #kk < 0.0 { -#kk } else { #kk };
        if !(best > 0.0 && best < #real::INFINITY) {
            return Err(Singular { site: Site::Actuation(#kl), value: #kk, condition_estimate: #real::INFINITY });
        }
        let b2 = #kk * #kk;
        let lhs = b2 * pd;
        let rhs = pn * #nk;
        if !(lhs > #tol2 * rhs) {
            let s = #nk;
            let n = #sqrt_n;
            let s = rhs / lhs;
            let c = #sqrt_n;
            return Err(Singular {
                site: Site::Actuation(#kl),
                value: if n > 0.0 { #kk / n } else { #kk },
                condition_estimate: if c >= 0.0 { c } else { #real::INFINITY },
            });
        }
    });
}

/// Elimination below the pivot of step `k`.
fn eliminate_below(n: usize, k: usize, k_rhs: usize, tr: bool, st: &mut Vec<TokenStream>) {
    let rk = format_ident!("r{}", k);
    for i in k + 1..n {
        let ik = m(i, k);
        let f = if tr { l(i, k) } else { format_ident!("f") };
        st.push(quote!(let #f = #ik * #rk;));
        for j in k + 1..n {
            let (ij, kj) = (m(i, j), m(k, j));
            st.push(quote!(let #ij = #ij - #f * #kj;));
        }
        for c in 0..k_rhs {
            if tr {
                break;
            }
            let (ic, kc) = (x(i, c), x(k, c));
            st.push(quote!(let #ic = #ic - f * #kc;));
        }
    }
}

/// Back substitution by the reciprocal pivots (none for the transposed solve).
fn back_substitution(n: usize, k_rhs: usize, tr: bool, st: &mut Vec<TokenStream>) {
    for c in 0..k_rhs {
        if tr {
            break;
        }
        for i in (0..n).rev() {
            let (ic, ri) = (x(i, c), format_ident!("r{}", i));
            let terms = (i + 1..n).map(|j| {
                let (ij, jc) = (m(i, j), x(j, c));
                quote!(- #ij * #jc)
            });
            st.push(quote!(let #ic = (#ic #(#terms)*) * #ri;));
        }
    }
}

/// The function of one right-hand side: `b: &[f64; DOF]`, solution `[f64; DOF]`.
fn vector_fn(name: &Ident, doc: &str, n: usize, st: &[TokenStream]) -> TokenStream {
    let real = crate::emit::real();
    let out = (0..n).map(|i| x(i, 0));
    quote! {
        #[doc = #doc]
        #[allow(clippy::all, unused_variables)]
        fn #name(a: &[[#real; DOF]; DOF], b: &[#real; DOF]) -> Result<[#real; DOF], Singular> {
            #(#st)*
            let out = [#(#out),*];
            for v in out.iter() {
                if !v.is_finite() {
                    return Err(Singular { site: Site::Input, value: *v, condition_estimate: #real::INFINITY });
                }
            }
            Ok(out)
        }
    }
}

/// [`vector_fn`] over the lanes: the lanes of a failed pivot or a non-finite result are
/// marked in `bad` (their values are not to be read).
fn vector_lanes_fn(name: &Ident, n: usize, st: &[TokenStream]) -> TokenStream {
    let real = crate::emit::real();
    let out = (0..n).map(|i| x(i, 0));
    quote! {
        /// The scalar solve's operations over the lanes, lane by lane; a lane whose pivot test
        /// fails or whose result is not finite is marked in `bad`.
        #[allow(clippy::all, unused_variables)]
        fn #name(
            a: &[[[#real; LANES]; DOF]; DOF],
            b: &[[#real; LANES]; DOF],
            bad: &mut [bool; LANES],
        ) -> [[#real; LANES]; DOF] {
            #(#st)*
            let out = [#(#out.0),*];
            flag_non_finite(bad, &out);
            out
        }
    }
}

/// [`identity_fn`] over the lanes (the inverse as `Lanes`), marking lanes as
/// [`vector_lanes_fn`].
fn identity_lanes_fn(name: &Ident, n: usize, st: &[TokenStream]) -> TokenStream {
    let real = crate::emit::real();
    let rows = (0..n).map(|i| {
        let row = (0..n).map(|c| x(i, c));
        quote!([#(#row),*])
    });
    quote! {
        /// The scalar inverse's operations over the lanes, lane by lane; a lane whose pivot
        /// test fails or whose inverse is not finite is marked in `bad`.
        #[allow(clippy::all, unused_variables)]
        fn #name(a: &[[[#real; LANES]; DOF]; DOF], bad: &mut [bool; LANES]) -> [[Lanes; DOF]; DOF] {
            #(#st)*
            let out = [#(#rows),*];
            for row in out.iter() {
                flag_non_finite(bad, &row.map(|v| v.0));
            }
            out
        }
    }
}

/// The per-lane select the `_lanes` solves use besides `Lanes::select_abs_gt`.
pub(crate) fn lanes_helpers() -> TokenStream {
    quote! {
        /// Per lane: `x` where `a > b`, else `y`.
        #[inline(always)]
        fn select_gt(a: Lanes, b: Lanes, x: Lanes, y: Lanes) -> Lanes {
            let mut r = y;
            for (((r, a), b), x) in r.0.iter_mut().zip(a.0).zip(b.0).zip(x.0) {
                if a > b {
                    *r = x;
                }
            }
            r
        }
    }
}

/// The function of the identity's columns: the inverse, `[[f64; DOF]; DOF]`.
fn identity_fn(name: &Ident, doc: &str, n: usize, st: &[TokenStream]) -> TokenStream {
    let real = crate::emit::real();
    let rows = (0..n).map(|i| {
        let row = (0..n).map(|c| x(i, c));
        quote!([#(#row),*])
    });
    quote! {
        #[doc = #doc]
        #[allow(clippy::all, unused_variables)]
        fn #name(a: &[[#real; DOF]; DOF]) -> Result<[[#real; DOF]; DOF], Singular> {
            #(#st)*
            let out = [#(#rows),*];
            for v in out.iter().flatten() {
                if !v.is_finite() {
                    return Err(Singular { site: Site::Input, value: *v, condition_estimate: #real::INFINITY });
                }
            }
            Ok(out)
        }
    }
}
