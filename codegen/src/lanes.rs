//! Many states per call ([`crate::Config::lanes`]): for each of a tree module's dynamics
//! functions ([`FUNCTIONS`]), a `<name>_lanes` that evaluates `LANES` states at once.
//!
//! The same scheduled statements as the scalar function, over `Lanes` (`[f64; LANES]` in a
//! struct whose operators are written out lane by lane, which LLVM turns into vector
//! instructions: one `vmulpd` of four lanes for one scalar `vmulsd`). Elementwise IEEE
//! operations in the same order, so lane `k` of the result is bit for bit what the scalar
//! function returns for state `k`; `sin_cos`, `sqrt`, `atan2` and `mul_add` call the math
//! backend once per lane. With [`crate::Config::vector_sin_cos`], `sin_cos` is instead one
//! polynomial over all lanes (`lanes/sin_cos.rs`), no longer bit for bit the backend's.
//!
//! Arguments and results are structures of arrays, lane last: `q: &[[f64; LANES]; DOF]`, where
//! `q[i][k]` is coordinate `i` of state `k`, and `[[f64; LANES]; DOF]` out (a matrix
//! `[[[f64; LANES]; DOF]; DOF]`). That is the layout the vector instructions load and store
//! whole; with the states one per row instead (`[[f64; DOF]; LANES]`, which a batched call à la
//! JAX's `vmap` would take), LLVM keeps every operation scalar and nothing is gained (measured:
//! slower than the scalar function four times). `forward_dynamics_lanes` returns the values and
//! each lane's status, `([[f64; LANES]; DOF], [Result<(), Singular>; LANES])`: a lane's `Err`
//! is the one the scalar function reports for that state, and it does not stop the others (its
//! guards record the first failure and skip it from there on; its values are not to be read).
//! Every per-lane step is unrolled at generation time: constant indices only, no panicking
//! operation, no heap.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

mod sin_cos;

use crate::Config;
use crate::emit::{self, Function, Shape};
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

/// The widest `lanes` accepted (16 `f32` lanes fill an AVX-512 register).
pub const MAX: usize = 16;

/// `LANES`, the `Lanes` type and the `_lanes` functions of `functions`' dynamics functions
/// (nothing when none is a tree's).
pub(crate) fn items(g: &Graph, cfg: &Config, functions: &[Function<'_>], l: usize) -> TokenStream {
    let chosen: Vec<&Function<'_>> = functions
        .iter()
        .filter(|f| f.public && !f.sites && FUNCTIONS.contains(&f.name))
        .filter(|f| {
            matches!(
                f.shape,
                Shape::Vector | Shape::Matrix | Shape::FallibleVector
            )
        })
        .collect();
    if chosen.is_empty() {
        return TokenStream::new();
    }
    let ty = lanes_type(cfg, l);
    let fns = chosen.iter().map(|f| function(g, f, l));
    quote! {
        #ty
        #(#fns)*
    }
}

/// `LANES` and `Lanes` with its operators and per-lane math, every lane written out.
fn lanes_type(cfg: &Config, l: usize) -> TokenStream {
    let real = emit::real();
    let n = Literal::usize_unsuffixed(l);
    let idx: Vec<Literal> = (0..l).map(Literal::usize_unsuffixed).collect();
    let binop = |tr: &str, m: &str, op: TokenStream| {
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
        let (body, kernel) = sin_cos::body_and_kernel(&idx, backend);
        (
            " `(sin, cos)` of every lane at once (a polynomial; the backend per lane beyond \
             |x| = 2¹⁹·π/2 or for a non-finite lane).",
            body,
            kernel,
        )
    } else {
        (" `(sin, cos)` per lane.", backend, TokenStream::new())
    };
    let select = idx.iter().map(
        |i| quote!(if #real::abs(self.0[#i]) > #real::abs(b.0[#i]) { x.0[#i] } else { y.0[#i] }),
    );
    let doc_lanes = format!(" States per call of the `_lanes` functions ({l}).");
    let doc_type = emit::real_text(
        " One `f64` per state: the scalar of the `_lanes` functions (elementwise operators; the \
         math backend once per lane).",
    );
    quote! {
        #[doc = #doc_lanes]
        pub const LANES: usize = #n;
        #[doc = #doc_type]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Lanes(pub [#real; LANES]);
        #(#ops)*
        impl core::ops::Neg for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn neg(self) -> Lanes {
                Lanes([#(#neg),*])
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
                Lanes([#(#sqrt),*])
            }
            /// `atan2(self, x)` per lane.
            #[inline(always)]
            pub fn atan2(self, x: Lanes) -> Lanes {
                Lanes([#(#atan2),*])
            }
            /// `self * b + c` per lane, one rounding.
            #[inline(always)]
            pub fn mul_add(self, b: Lanes, c: Lanes) -> Lanes {
                Lanes([#(#mul_add),*])
            }
            #[doc = #sin_cos_doc]
            #[inline(always)]
            pub fn sin_cos(self) -> (Lanes, Lanes) {
                #sin_cos
            }
            /// Per lane: `x` where `|self| > |b|`, else `y`.
            #[inline(always)]
            pub fn select_abs_gt(self, b: Lanes, x: Lanes, y: Lanes) -> Lanes {
                Lanes([#(#select),*])
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

/// A tree's pivot test in lane `k`, without a branch: the lane's first failure is kept (its
/// pivot, value, magnitude and scale, so that the `Err` is built at the end as the scalar
/// function builds it), later tests leave it.
fn check(g: &Graph, s: &Schedule, node: ExprId, k: usize) -> TokenStream {
    let Node::Guard {
        value,
        tol,
        scale,
        index,
    } = g.node(node)
    else {
        return TokenStream::new();
    };
    let (v, t, sc) = (
        lane_scalar(g, s, value, k),
        lane_scalar(g, s, tol, k),
        lane_scalar(g, s, scale, k),
    );
    let two_sided = index & crate::sym::TWO_SIDED != 0;
    let pivot = Literal::usize_unsuffixed((index & !crate::sym::TWO_SIDED) as usize);
    let (test, magnitude) = if two_sided {
        (
            quote!(#v > #t || #v < -#t),
            quote!(if #v < 0.0 { -#v } else { #v }),
        )
    } else {
        (quote!(#v > #t), quote!(#v))
    };
    let lane = Literal::usize_unsuffixed(k);
    quote! {
        let bad = fail_at[#lane] == usize::MAX && !(#test);
        fail_at[#lane] = if bad { #pivot } else { fail_at[#lane] };
        fail_value[#lane] = if bad { #v } else { fail_value[#lane] };
        fail_magnitude[#lane] = if bad { #magnitude } else { fail_magnitude[#lane] };
        fail_scale[#lane] = if bad { #sc } else { fail_scale[#lane] };
    }
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

/// The `_lanes` version of `f` (a [`Shape::Vector`], [`Shape::Matrix`] or
/// [`Shape::FallibleVector`] function).
fn function(g: &Graph, f: &Function<'_>, l: usize) -> TokenStream {
    let real = emit::real();
    let s = &f.schedule;
    let name = format_ident!("{}_lanes", f.name);
    let mut args = Vec::new();
    let mut entry = Vec::new();
    for a in &f.args {
        if *a == Arg::P {
            args.push(quote!(p: &Params));
            entry.push(quote!(let p = p.to_array().map(Lanes::splat);));
            continue;
        }
        let id = Ident::new(a.name(), Span::call_site());
        args.push(quote!(#id: &[[#real; LANES]; DOF]));
        entry.push(quote!(let #id: [Lanes; DOF] = #id.map(Lanes);));
    }
    let fallible = matches!(f.shape, Shape::FallibleVector);
    if fallible {
        entry.push(quote! {
            let mut fail_at = [usize::MAX; LANES];
            let mut fail_value: [#real; LANES] = [0.0; LANES];
            let mut fail_magnitude: [#real; LANES] = [0.0; LANES];
            let mut fail_scale: [#real; LANES] = [0.0; LANES];
        });
    }
    // The `sin_cos` of inputs first: each is a call per lane, and a call spills every vector
    // register, so they are made while nothing else is live (pure functions: the order is free).
    let mut hoisted = s.clone();
    let (first, rest): (Vec<Step>, Vec<Step>) = s.steps.iter().partition(
        |st| matches!(st, Step::SinCos { arg, .. } if matches!(s.operand(g, *arg), Operand::Input(..))),
    );
    hoisted.steps = first.into_iter().chain(rest).collect();
    let s = &hoisted;
    let stmts: Vec<TokenStream> = s.steps.iter().map(|st| step(g, s, st, l)).collect();
    let stmts = emit::chunked(g, s, &f.outputs, stmts);
    let outs: Vec<TokenStream> = f.outputs.iter().map(|&o| lane_array(g, s, o)).collect();
    let values = emit::return_tokens(f, &outs);
    let lane = quote!([#real; LANES]);
    let (ret_ty, ret) = match f.shape {
        Shape::Vector => (quote!([#lane; DOF]), values),
        Shape::Matrix => (quote!([[#lane; DOF]; DOF]), values),
        Shape::FallibleVector => {
            let all_const = f.outputs.iter().all(|&o| g.as_const(o).is_some());
            let status = (0..l).map(|k| {
                let outs: Vec<TokenStream> =
                    f.outputs.iter().map(|&o| lane_scalar(g, s, o, k)).collect();
                let k = Literal::usize_unsuffixed(k);
                let finite = (!all_const).then(|| {
                    quote! {
                        for v in [#(#outs),*].iter() {
                            if !v.is_finite() {
                                break 'lane Err(Singular {
                                    pivot: DOF,
                                    value: *v,
                                    condition_estimate: #real::INFINITY,
                                });
                            }
                        }
                    }
                });
                quote! {
                    'lane: {
                        if fail_at[#k] != usize::MAX {
                            let a = fail_magnitude[#k];
                            break 'lane Err(Singular {
                                pivot: fail_at[#k],
                                value: fail_value[#k],
                                condition_estimate: if a > 0.0 {
                                    fail_scale[#k] / a
                                } else {
                                    #real::INFINITY
                                },
                            });
                        }
                        #finite
                        Ok(())
                    }
                }
            });
            (
                quote!(([#lane; DOF], [Result<(), Singular>; LANES])),
                quote!(([#(#outs),*], [#(#status),*])),
            )
        }
        _ => panic!("internal error: no lanes version of `{}`", f.name),
    };
    let doc = format!(
        " `{}` of `LANES` states at once, lane by lane: entry `[i][k]` of an argument or of the \
         result is entry `i` of state `k`, bit for bit what `{}` gives for that state.",
        f.name, f.name
    );
    let doc_err = fallible.then(|| {
        quote! {
            #[doc = ""]
            #[doc = " The second part is each lane's status: `Err` where the scalar function \
                     returns that `Err` for the lane's state (that lane's values are then not \
                     to be read); the other lanes are not affected."]
        }
    });
    quote! {
        #[doc = #doc]
        #doc_err
        #[inline]
        #[allow(unused_variables, unused_mut, clippy::all)]
        pub fn #name(#(#args),*) -> #ret_ty {
            #(#entry)*
            #(#stmts)*
            #ret
        }
    }
}
