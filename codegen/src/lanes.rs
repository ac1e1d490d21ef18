//! Many states per call ([`crate::Config::lanes`]): for each of a module's dynamics functions
//! ([`FUNCTIONS`], and a platform's or closed loop's `actuator_mass_matrix`), a `<name>_lanes`
//! that evaluates `LANES` states at once.
//!
//! The same scheduled statements as the scalar function, over `Lanes` (`[f64; LANES]` in a
//! struct whose operators are written out lane by lane, which LLVM turns into vector
//! instructions: one `vmulpd` of four lanes for one scalar `vmulsd`). Elementwise IEEE
//! operations in the same order, so lane `k` of the result is bit for bit what the scalar
//! function returns for state `k`; `sin_cos`, `sqrt`, `atan2` and `mul_add` call the math
//! backend once per lane. `Lanes` is aligned to its size when that is a power of two, so that
//! it loads and stores whole. With [`crate::Config::vector_sin_cos`], `sin_cos` is instead one
//! polynomial over all lanes (`sin_cos.rs`), no longer bit for bit the backend's. With
//! [`crate::Config::wide`], the operators and `sqrt` are the `wide` crate's vector operations
//! (`lanes/wide.rs`), which do not depend on LLVM's vectorizer; still bit for bit.
//!
//! Arguments and results are structures of arrays, lane last: `q: &[[f64; LANES]; DOF]`, where
//! `q[i][k]` is coordinate `i` of state `k`, and `[[f64; LANES]; DOF]` out (a matrix
//! `[[[f64; LANES]; DOF]; DOF]`). That is the layout the vector instructions load and store
//! whole; with the states one per row instead (`[[f64; DOF]; LANES]`, which a batched call à la
//! JAX's `vmap` would take), LLVM keeps every operation scalar and nothing is gained (measured:
//! slower than the scalar function four times). `forward_dynamics_lanes` returns the values and
//! each lane's status, `([[f64; LANES]; DOF], [Result<(), Singular>; LANES])`: a lane's `Err`
//! is the one the scalar function reports for that state, and it does not stop the others
//! (its values are not to be read). Over the lanes a guard only marks its lane `bad` (one
//! compare and one `or`, which vectorize); at the end each lane marked `bad` or with a
//! non-finite result is evaluated once more by the scalar function, whose `Err` it takes:
//! exact by construction, and free on average since failures are rare. Every per-lane step
//! is unrolled at generation time: constant indices only, no panicking operation, no heap.
//!
//! Platforms and closed loops: every function can fail, so every `_lanes` function returns
//! each lane's status, its `Err` the scalar function's (a lane with a non-finite input is
//! marked `bad` on entry, and the scalar function's second look finds the same input, guard
//! or result first). A function that is one kernel (a closed
//! loop's dynamics, a platform's `mass_matrix` and `forward_dynamics`) runs its schedule over
//! the lanes whole. A platform's functions that solve with the actuation matrix `A`
//! (`inverse_dynamics`, `gravity`, `coriolis`, `actuator_mass_matrix`) run their kernel
//! (`id_parts`, …) over the lanes, which returns its parts lane last and each lane's status,
//! and the wrappers (`templates/platform_lanes.rs`) solve over the lanes too, with the scalar
//! LU's statements over `Lanes` (`crate::lu`): each lane's pivots chosen by its own selects.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

mod wide;

pub(crate) use wide::{WIDTHS as WIDE_WIDTHS, vector_type as wide_type};

use crate::Config;
use crate::emit::{self, Function, Part, Shape};
use crate::schedule::{Operand, Schedule, Step};
use crate::sym::{Arg, ExprId, Graph, Node};

/// The functions that get a `_lanes` version (when the module has them).
pub const FUNCTIONS: [&str; 5] = [
    "mass_matrix",
    "coriolis",
    "gravity",
    "inverse_dynamics",
    "forward_dynamics",
];

/// A platform module's kernels and the public functions built on them that get a `_lanes`
/// version (`codegen/templates/platform_lanes.rs`): each lane's kernel result is solved by
/// the scalar functions' LU of `A`.
const KERNELS: [(&str, &str); 4] = [
    ("id_parts", "inverse_dynamics"),
    ("gravity_parts", "gravity"),
    ("coriolis_parts", "coriolis"),
    ("inertia_parts", "actuator_mass_matrix"),
];

/// The public `_lanes` wrappers around the kernels.
const PLATFORM_LANES: &str = include_str!("../templates/platform_lanes.rs");

/// The widest `lanes` accepted (16 `f32` lanes fill an AVX-512 register).
pub const MAX: usize = 16;

/// The functions with a `_lanes` version in a module of `functions` (by their scalar names).
pub(crate) fn names(functions: &[Function<'_>]) -> Vec<&'static str> {
    let has = |n: &str| functions.iter().any(|f| f.name == n);
    let mut names: Vec<&'static str> = FUNCTIONS
        .into_iter()
        .filter(|n| functions.iter().any(|f| f.name == *n && flat(f)))
        .collect();
    for (kernel, wrapper) in KERNELS {
        if has(kernel) {
            names.push(wrapper);
        }
    }
    // A closed loop's `actuator_mass_matrix` is its `mass_matrix` (the actuated joints are its
    // independent coordinates).
    if functions.iter().any(|f| f.sites) && has("mass_matrix") && !has("inertia_parts") {
        names.push("actuator_mass_matrix");
    }
    names.sort_by_key(|n| {
        FUNCTIONS
            .iter()
            .chain(["actuator_mass_matrix"].iter())
            .position(|m| m == n)
    });
    names
}

/// A public function whose `_lanes` version is its own schedule over the lanes: a tree's
/// [`FUNCTIONS`], or a platform's or closed loop's that return one vector or one matrix.
fn flat(f: &Function<'_>) -> bool {
    f.public
        && FUNCTIONS.contains(&f.name)
        && if f.sites {
            matches!(&f.shape, Shape::Fallible(p) if matches!(p[..], [Part::Vector] | [Part::Matrix]))
        } else {
            matches!(
                f.shape,
                Shape::Vector | Shape::Matrix | Shape::FallibleVector
            )
        }
}

/// `LANES`, the `Lanes` type and the `_lanes` functions of `functions`' dynamics functions
/// (nothing when the module has none of them).
pub(crate) fn items(g: &Graph, cfg: &Config, functions: &[Function<'_>], l: usize) -> TokenStream {
    let chosen: Vec<&Function<'_>> = functions.iter().filter(|f| flat(f)).collect();
    let kernels: Vec<&Function<'_>> = functions
        .iter()
        .filter(|f| KERNELS.iter().any(|(k, _)| *k == f.name))
        .collect();
    if chosen.is_empty() && kernels.is_empty() {
        return TokenStream::new();
    }
    let ty = lanes_type(cfg, l);
    let fns = chosen.iter().map(|f| function(g, f, l));
    let kernel_fns = kernels.iter().map(|f| kernel(g, f, l));
    let wrappers: Vec<&str> = KERNELS
        .iter()
        .filter(|(k, _)| kernels.iter().any(|f| f.name == *k))
        .map(|(_, w)| *w)
        .collect();
    let mut items: Vec<String> = wrappers.iter().map(|w| format!("{w}_lanes")).collect();
    if wrappers.iter().any(|w| *w != "actuator_mass_matrix") {
        items.push("solve_t_lanes".into());
    }
    // The per-lane helpers of the functions that can fail ([`settle`]).
    if chosen.iter().any(|f| fallible(f)) || !kernels.is_empty() {
        items.extend(["lane_of", "put_lane", "flag_non_finite"].map(String::from));
    }
    let items: Vec<&str> = items.iter().map(String::as_str).collect();
    let params = kernels.iter().any(|f| f.args.contains(&Arg::P));
    let templated = crate::template::Specialize::new(cfg)
        .params(params)
        .items(PLATFORM_LANES, &items);
    let closed_amm = if names(functions).contains(&"actuator_mass_matrix")
        && !functions.iter().any(|f| f.name == "inertia_parts")
    {
        closed_actuator_mass_matrix(functions)
    } else {
        TokenStream::new()
    };
    quote! {
        #ty
        #(#fns)*
        #(#kernel_fns)*
        #templated
        #closed_amm
    }
}

/// A closed loop's `actuator_mass_matrix_lanes`: its `mass_matrix_lanes`.
fn closed_actuator_mass_matrix(functions: &[Function<'_>]) -> TokenStream {
    let real = emit::real();
    let params = functions
        .iter()
        .any(|f| f.name == "mass_matrix" && f.args.contains(&Arg::P));
    let (p_arg, p) = if params {
        (quote!(, p: &Params), quote!(, p))
    } else {
        (quote!(), quote!())
    };
    quote! {
        /// `actuator_mass_matrix` of `LANES` states at once: `mass_matrix_lanes` (the actuated
        /// joints are the independent coordinates).
        #[inline(always)]
        #[allow(clippy::type_complexity)]
        pub fn actuator_mass_matrix_lanes(
            x: &[[#real; LANES]; NX] #p_arg
        ) -> ([[[#real; LANES]; DOF]; DOF], [Result<(), Singular>; LANES]) {
            mass_matrix_lanes(x #p)
        }
    }
}

/// `LANES` and `Lanes` with its operators and per-lane math, every lane written out.
fn lanes_type(cfg: &Config, l: usize) -> TokenStream {
    let real = emit::real();
    let n = Literal::usize_unsuffixed(l);
    let idx: Vec<Literal> = (0..l).map(Literal::usize_unsuffixed).collect();
    let wide = cfg
        .wide
        .as_deref()
        .and_then(|k| Some((k, wide::vector_type(crate::scalar::single(), l)?)));
    let binop = |tr: &str, m: &str, op: TokenStream| {
        if let Some((krate, ty)) = wide {
            return wide::binop(krate, ty, tr, m, op);
        }
        let (tr, m) = (format_ident!("{}", tr), format_ident!("{}", m));
        // Each lane bound first: a binary operation as an array element reads, to clippy's
        // `possible_missing_comma`, as a missing comma when the macro's tokens all carry the
        // span of a call written over several lines.
        let lanes: Vec<Ident> = (0..l).map(|k| format_ident!("r{}", k)).collect();
        let each = idx
            .iter()
            .zip(&lanes)
            .map(|(i, r)| quote!(let #r = self.0[#i] #op o.0[#i];));
        quote! {
            impl core::ops::#tr for Lanes {
                type Output = Lanes;
                #[inline(always)]
                fn #m(self, o: Lanes) -> Lanes {
                    #(#each)*
                    Lanes([#(#lanes),*])
                }
            }
        }
    };
    let ops = [
        binop("Add", "add", quote!(+)),
        binop("Sub", "sub", quote!(-)),
        binop("Mul", "mul", quote!(*)),
        binop("Div", "div", quote!(/)),
    ];
    let neg = idx.iter().map(|i| quote!(-self.0[#i]));
    let sqrt = idx
        .iter()
        .map(|i| emit::math_call(cfg, "sqrt", quote!(self.0[#i])));
    let atan2 = idx
        .iter()
        .map(|i| emit::math_call(cfg, "atan2", quote!(self.0[#i], x.0[#i])));
    let mul_add = idx
        .iter()
        .map(|i| emit::math_call(cfg, "mul_add", quote!(self.0[#i], b.0[#i], c.0[#i])));
    let mul_add_per_lane = quote!(Lanes([#(#mul_add),*]));
    let mut neg = quote!(Lanes([#(#neg),*]));
    let mut sqrt = quote!(Lanes([#(#sqrt),*]));
    let mul_add = match wide {
        Some((krate, ty)) => {
            (neg, sqrt) = wide::unary(krate, ty);
            wide::mul_add(krate, ty, mul_add_per_lane)
        }
        None => quote! {
            /// `self * b + c` per lane, one rounding.
            #[inline(always)]
            pub fn mul_add(self, b: Lanes, c: Lanes) -> Lanes {
                #mul_add_per_lane
            }
        },
    };
    let pairs: Vec<Ident> = (0..l).map(|k| format_ident!("p{}", k)).collect();
    let per_lane: Vec<TokenStream> = idx
        .iter()
        .zip(&pairs)
        .map(|(i, p)| {
            let call = emit::math_call(cfg, "sin_cos", quote!(self.0[#i]));
            quote!(let #p = #call;)
        })
        .collect();
    let backend = quote! {
        #(#per_lane)*
        (Lanes([#(#pairs.0),*]), Lanes([#(#pairs.1),*]))
    };
    let (sin_cos_doc, sin_cos, kernel) = if cfg.vector_sin_cos {
        let (body, kernel) = (
            crate::sin_cos::lanes_body(&idx, backend),
            crate::sin_cos::kernel(),
        );
        (
            " `(sin, cos)` of every lane at once (a polynomial; the backend per lane beyond \
             |x| = 2¹⁹·π/2 or for a non-finite lane).",
            body,
            kernel,
        )
    } else {
        (" `(sin, cos)` per lane.", backend, TokenStream::new())
    };
    let select = match wide {
        Some((krate, ty)) => wide::select_abs_gt(krate, ty),
        None => {
            let each = idx.iter().map(|i| {
                quote!(if #real::abs(self.0[#i]) > #real::abs(b.0[#i]) { x.0[#i] } else { y.0[#i] })
            });
            quote!(Lanes([#(#each),*]))
        }
    };
    let doc_lanes = format!(" States per call of the `_lanes` functions ({l}).");
    let doc_type = emit::real_text(if wide.is_some() {
        " One `f64` per state: the scalar of the `_lanes` functions (the `wide` crate's vector \
         operators and selection; the math backend once per lane otherwise)."
    } else {
        " One `f64` per state: the scalar of the `_lanes` functions (elementwise operators; the \
         math backend once per lane)."
    });
    // Aligned to its size (a power of two): a vector load or store of whole `Lanes`. (It does
    // not keep LLVM's vectorizer from leaving a long kernel scalar; `Config::wide` does.)
    let size = l * if crate::scalar::single() { 4 } else { 8 };
    let repr = if size.is_power_of_two() {
        let a = Literal::usize_unsuffixed(size);
        quote!(#[repr(C, align(#a))])
    } else {
        TokenStream::new()
    };
    quote! {
        #[doc = #doc_lanes]
        pub const LANES: usize = #n;
        #[doc = #doc_type]
        #[derive(Clone, Copy, Debug, PartialEq)]
        #repr
        pub struct Lanes(pub [#real; LANES]);
        #(#ops)*
        impl core::ops::Neg for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn neg(self) -> Lanes {
                #neg
            }
        }
        impl Lanes {
            /// Every lane `v`.
            #[inline(always)]
            pub fn splat(v: #real) -> Lanes {
                Lanes([v; LANES])
            }
            /// Square root per lane.
            #[inline(always)]
            pub fn sqrt(self) -> Lanes {
                #sqrt
            }
            /// `atan2(self, x)` per lane.
            #[inline(always)]
            pub fn atan2(self, x: Lanes) -> Lanes {
                Lanes([#(#atan2),*])
            }
            #mul_add
            #[doc = #sin_cos_doc]
            #[inline(always)]
            pub fn sin_cos(self) -> (Lanes, Lanes) {
                #sin_cos
            }
            /// Per lane: `x` where `|self| > |b|`, else `y`.
            #[inline(always)]
            pub fn select_abs_gt(self, b: Lanes, x: Lanes, y: Lanes) -> Lanes {
                #select
            }
        }
        #kernel
    }
}

/// An operand over lanes: a variable, an input row (`q[i]`, transposed on entry) or a
/// constant in every lane.
fn lane_operand(g: &Graph, s: &Schedule, id: ExprId) -> TokenStream {
    match s.operand(g, id) {
        Operand::Const(c) => {
            let c = emit::float_lit(c);
            quote!(Lanes::splat(#c))
        }
        _ => emit::operand(g, s, id),
    }
}

/// An operand in lane `k` (a scalar).
fn lane_scalar(g: &Graph, s: &Schedule, id: ExprId, k: usize) -> TokenStream {
    let k = Literal::usize_unsuffixed(k);
    match s.operand(g, id) {
        Operand::Const(c) => emit::float_lit(c),
        _ => {
            let x = emit::operand(g, s, id);
            quote!(#x.0[#k])
        }
    }
}

/// One step over lanes.
fn step(g: &Graph, s: &Schedule, st: &Step, l: usize) -> TokenStream {
    let op = |id| lane_operand(g, s, id);
    match *st {
        Step::SinCos { sin, cos, arg } => {
            let (a, b, x) = (emit::var(sin), emit::var(cos), op(arg));
            quote!(let (#a, #b) = Lanes::sin_cos(#x);)
        }
        // Not made for the lanes (`emit` batches the scalar functions only): one call each.
        Step::SinCosBatch => s
            .batch
            .iter()
            .map(|&(sin, cos, arg)| {
                let (a, b, x) = (emit::var(sin), emit::var(cos), op(arg));
                quote!(let (#a, #b) = Lanes::sin_cos(#x);)
            })
            .collect(),
        Step::Check { node } => (0..l).map(|k| check(g, s, node, k)).collect(),
        Step::MulAdd { name, node, mul } => {
            let x = emit::var(name);
            let [a, b, c] = crate::fma::args(g, node, mul, &op, &|v| {
                let v = emit::float_lit(v);
                quote!(Lanes::splat(#v))
            });
            quote!(let #x = Lanes::mul_add(#a, #b, #c);)
        }
        Step::Let { name, node } => {
            let x = emit::var(name);
            let e = match g.node(node) {
                Node::Add(a, b) => binary(op(a), quote!(+), op(b)),
                Node::Sub(a, b) => binary(op(a), quote!(-), op(b)),
                Node::Mul(a, b) => binary(op(a), quote!(*), op(b)),
                Node::Div(a, b) => binary(op(a), quote!(/), op(b)),
                Node::Neg(a) => {
                    let a = op(a);
                    quote!(-#a)
                }
                Node::Sqrt(a) => {
                    let a = op(a);
                    quote!(Lanes::sqrt(#a))
                }
                Node::Atan2(a, b) => {
                    let (a, b) = (op(a), op(b));
                    quote!(Lanes::atan2(#a, #b))
                }
                Node::Select(a, b, x, y) => {
                    let (a, b, x, y) = (op(a), op(b), op(x), op(y));
                    quote!(Lanes::select_abs_gt(#a, #b, #x, #y))
                }
                _ => return TokenStream::new(),
            };
            quote!(let #x = #e;)
        }
    }
}

fn binary(a: TokenStream, op: TokenStream, b: TokenStream) -> TokenStream {
    quote!(#a #op #b)
}

/// A guard's test in lane `k` (a tree's pivot, a platform's or closed loop's site), without a
/// branch: a failure marks the lane `bad`, and the lane's `Err` is the scalar function's (see
/// [`settle`]).
fn check(g: &Graph, s: &Schedule, node: ExprId, k: usize) -> TokenStream {
    let Node::Guard {
        value, tol, index, ..
    } = g.node(node)
    else {
        return TokenStream::new();
    };
    let (v, t) = (lane_scalar(g, s, value, k), lane_scalar(g, s, tol, k));
    let test = if index & crate::sym::TWO_SIDED != 0 {
        quote!(#v > #t || #v < -#t)
    } else {
        quote!(#v > #t)
    };
    let lane = Literal::usize_unsuffixed(k);
    quote!(bad[#lane] |= !(#test);)
}

/// An output over lanes, as the array the caller gets: `x7.0`, `q[3].0` or `[c; LANES]`.
fn lane_array(g: &Graph, s: &Schedule, id: ExprId) -> TokenStream {
    match s.operand(g, id) {
        Operand::Const(c) => {
            let c = emit::float_lit(c);
            quote!([#c; LANES])
        }
        _ => {
            let x = emit::operand(g, s, id);
            quote!(#x.0)
        }
    }
}

/// Arguments and entry statements of a `_lanes` function (each input transposed into
/// `Lanes`; when the function can fail, the lanes marked `bad`, a platform's or closed loop's
/// lanes with a non-finite input first), and its schedule with the `sin_cos` of inputs first.
fn prologue(g: &Graph, f: &Function<'_>) -> (Vec<TokenStream>, Vec<TokenStream>, Schedule) {
    let real = emit::real();
    let mut args = Vec::new();
    let mut entry = Vec::new();
    if fallible(f) {
        entry.push(quote!(let mut bad = [false; LANES];));
    }
    // A platform's or closed loop's non-finite inputs, read as given (before the transpose).
    if f.sites {
        for a in f.args.iter().filter(|a| **a != Arg::P) {
            let id = Ident::new(a.name(), Span::call_site());
            entry.push(quote!(flag_non_finite(&mut bad, #id);));
        }
    }
    for a in &f.args {
        if *a == Arg::P {
            args.push(quote!(p: &Params));
            entry.push(quote!(let p = p.to_array().map(Lanes::splat);));
            continue;
        }
        let len = if *a == Arg::X {
            quote!(NX)
        } else {
            quote!(DOF)
        };
        let id = Ident::new(a.name(), Span::call_site());
        args.push(quote!(#id: &[[#real; LANES]; #len]));
        entry.push(quote!(let #id: [Lanes; #len] = #id.map(Lanes);));
    }
    let s = &f.schedule;
    // The `sin_cos` of inputs first: each is a call per lane, and a call spills every vector
    // register, so they are made while nothing else is live (pure functions: the order is free).
    let mut hoisted = s.clone();
    let (first, rest): (Vec<Step>, Vec<Step>) = s.steps.iter().partition(
        |st| matches!(st, Step::SinCos { arg, .. } if matches!(s.operand(g, *arg), Operand::Input(..))),
    );
    hoisted.steps = first.into_iter().chain(rest).collect();
    (args, entry, hoisted)
}

/// The scheduled statements over the lanes.
fn statements(g: &Graph, f: &Function<'_>, s: &Schedule, l: usize) -> Vec<TokenStream> {
    let stmts: Vec<TokenStream> = s.steps.iter().map(|st| step(g, s, st, l)).collect();
    emit::chunked(g, s, &f.outputs, stmts)
}

/// Whether `f`'s `_lanes` version returns each lane's status.
fn fallible(f: &Function<'_>) -> bool {
    f.sites || matches!(f.shape, Shape::FallibleVector)
}

/// A `_lanes` function that can fail, as two: `<name>_lanes_marked` (private, inlined) runs
/// the statements `body` over the lanes and returns the values `values` (of `parts`, type
/// `values_ty`) with the lanes marked `bad` (an input, a guard, a non-finite result);
/// `<name>_lanes` (`head`: its docs, visibility) returns the values and each lane's status, a
/// marked lane evaluated once more by the scalar function (`f` itself, or the scalar kernel),
/// whose `Err` (or values) it takes: the lane's `Err` is the scalar function's by
/// construction, and over the lanes a guard costs one compare and one `or` per lane. Failures
/// are rare, so the second evaluation costs nothing on average. (The per-lane loop stays out
/// of the long function: in it, clippy took minutes over a platform's module.)
#[allow(clippy::too_many_arguments)]
fn settle(
    f: &Function<'_>,
    head: TokenStream,
    args: &[TokenStream],
    body: TokenStream,
    values: TokenStream,
    values_ty: TokenStream,
    ret_ty: TokenStream,
    parts: &[Part],
) -> TokenStream {
    let scalar = Ident::new(f.name, Span::call_site());
    let name = format_ident!("{}_lanes", f.name);
    let marked = format_ident!("{}_lanes_marked", f.name);
    let one = parts.len() == 1;
    let part = |whole: TokenStream, i: usize| {
        if one {
            whole
        } else {
            let i = Literal::usize_unsuffixed(i);
            quote!(#whole.#i)
        }
    };
    let flags = parts.iter().enumerate().map(|(i, p)| {
        let o = part(quote!(out), i);
        match p {
            Part::Matrix => quote! {
                for row in #o.iter() {
                    flag_non_finite(&mut bad, row);
                }
            },
            _ => quote!(flag_non_finite(&mut bad, &#o);),
        }
    });
    let puts = parts.iter().enumerate().map(|(i, p)| {
        let (o, v) = (part(quote!(out), i), part(quote!(v), i));
        match p {
            Part::Matrix => quote! {
                for (o, r) in #o.iter_mut().zip(#v) {
                    put_lane(o, k, r);
                }
            },
            _ => quote!(put_lane(&mut #o, k, #v);),
        }
    });
    let names: Vec<Ident> = f
        .args
        .iter()
        .map(|a| Ident::new(if *a == Arg::P { "p" } else { a.name() }, Span::call_site()))
        .collect();
    let lane_args = f.args.iter().zip(&names).map(|(a, id)| {
        if *a == Arg::P {
            quote!(#id)
        } else {
            quote!(&lane_of(#id, k))
        }
    });
    let doc = format!(
        " `{name}`'s values over the lanes, and the lanes it must evaluate again by `{}`.",
        f.name
    );
    quote! {
        #[doc = #doc]
        #[inline(always)]
        #[allow(unused_variables, unused_mut, clippy::all)]
        fn #marked(#(#args),*) -> (#values_ty, [bool; LANES]) {
            #body
            let mut out = #values;
            #(#flags)*
            (out, bad)
        }
        #[allow(clippy::type_complexity)]
        #head
        fn #name(#(#args),*) -> #ret_ty {
            let (mut out, bad) = #marked(#(#names),*);
            let mut status = [Ok(()); LANES];
            for (k, (st, bad)) in status.iter_mut().zip(bad).enumerate() {
                if bad {
                    match #scalar(#(#lane_args),*) {
                        Ok(v) => {
                            #(#puts)*
                        }
                        Err(e) => *st = Err(e),
                    }
                }
            }
            (out, status)
        }
    }
}

/// The `_lanes` version of `f` (see [`flat`]): the values lane last, and for a function that
/// can fail each lane's status.
fn function(g: &Graph, f: &Function<'_>, l: usize) -> TokenStream {
    let real = emit::real();
    let name = format_ident!("{}_lanes", f.name);
    let (args, entry, s) = prologue(g, f);
    let s = &s;
    let stmts = statements(g, f, s, l);
    let outs: Vec<TokenStream> = f.outputs.iter().map(|&o| lane_array(g, s, o)).collect();
    let lane = quote!([#real; LANES]);
    let doc = format!(
        " `{}` of `LANES` states at once, lane by lane: entry `[i][k]` of an argument or of the \
         result is entry `i` of state `k`, bit for bit what `{}` gives for that state.",
        f.name, f.name
    );
    let (values_ty, values, parts) = match &f.shape {
        Shape::Vector | Shape::Matrix => {
            let ret_ty = if matches!(f.shape, Shape::Vector) {
                quote!([#lane; DOF])
            } else {
                quote!([[#lane; DOF]; DOF])
            };
            let ret = emit::return_tokens(f, &outs);
            return quote! {
                #[doc = #doc]
                #[inline]
                #[allow(unused_variables, unused_mut, clippy::all)]
                pub fn #name(#(#args),*) -> #ret_ty {
                    #(#entry)*
                    #(#stmts)*
                    #ret
                }
            };
        }
        Shape::FallibleVector => (
            quote!([#lane; DOF]),
            quote!([#(#outs),*]),
            &[Part::Vector][..],
        ),
        Shape::Fallible(parts) if f.sites => {
            let ty = if parts[..] == [Part::Matrix] {
                quote!([[#lane; DOF]; DOF])
            } else {
                quote!([#lane; DOF])
            };
            (ty, emit::parts_tokens(parts, f.dof, &outs), &parts[..])
        }
        _ => panic!("internal error: no lanes version of `{}`", f.name),
    };
    let head = quote! {
        #[doc = #doc]
        #[doc = ""]
        #[doc = " The second part is each lane's status: `Err` where the scalar function \
                 returns that `Err` for the lane's state (that lane's values are then not \
                 to be read); the other lanes are not affected."]
        #[inline]
        pub
    };
    settle(
        f,
        head,
        &args,
        quote!(#(#entry)* #(#stmts)*),
        values,
        values_ty.clone(),
        quote!((#values_ty, [Result<(), Singular>; LANES])),
        parts,
    )
}

/// The `_lanes` version of a platform's kernel `f` (private): its parts lane last and each
/// lane's status, for the wrappers (`templates/platform_lanes.rs`) to solve lane by lane.
/// Lane `k` is bit for bit what the scalar kernel returns for state `k`. (Results handed
/// out per lane instead, as the scalar kernel's `Result`s, kept LLVM from vectorizing the
/// kernel at all.)
fn kernel(g: &Graph, f: &Function<'_>, l: usize) -> TokenStream {
    let real = emit::real();
    let (args, entry, s) = prologue(g, f);
    let s = &s;
    let stmts = statements(g, f, s, l);
    let Shape::Fallible(parts) = &f.shape else {
        panic!("internal error: kernel `{}` cannot fail", f.name)
    };
    let lane = quote!([#real; LANES]);
    let types: Vec<TokenStream> = parts
        .iter()
        .map(|p| match p {
            Part::Matrix => quote!([[#lane; DOF]; DOF]),
            Part::Vector => quote!([#lane; DOF]),
            _ => panic!(
                "internal error: kernel `{}` has a part without lanes",
                f.name
            ),
        })
        .collect();
    let outs: Vec<TokenStream> = f.outputs.iter().map(|&o| lane_array(g, s, o)).collect();
    let values = emit::parts_tokens(parts, f.dof, &outs);
    let doc = format!(
        " `{}` of `LANES` states at once: entry `[i][k]` of an argument or a part is entry `i` \
         of state `k`, and lane `k` (with its status) is bit for bit what `{}` returns for \
         state `k`.",
        f.name, f.name
    );
    let head = quote! {
        #[doc = #doc]
        #[inline]
    };
    settle(
        f,
        head,
        &args,
        quote!(#(#entry)* #(#stmts)*),
        values,
        quote!((#(#types),*)),
        quote!(((#(#types),*), [Result<(), Singular>; LANES])),
        parts,
    )
}
