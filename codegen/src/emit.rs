//! Rust emission: scheduled DAGs → `quote!` tokens → `syn::File` → prettyplease text.
//!
//! The output contract (relied on by `include!` users and outside checks): top-level items only
//! (no `mod` wrapper, no inner attributes); only `core` plus the chosen math backend; fixed-size
//! arrays in and out, no heap, no slices, no panicking operations; a header comment with the
//! spec name, the generator version and every function's operation count.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

use crate::schedule::{OpCount, Operand, Schedule, Step};
use crate::sym::{Arg, ExprId, Graph, Node};
use crate::{Config, MathBackend};

/// What a generated function returns.
pub enum Shape {
    /// `[f64; DOF]`.
    Vector,
    /// `[[f64; DOF]; DOF]`, outputs row-major.
    Matrix,
    /// `Result<[f64; DOF], Singular>`.
    FallibleVector,
}

/// One function to emit.
pub struct Function<'a> {
    /// Name.
    pub name: &'a str,
    /// Doc comment (one paragraph per element).
    pub doc: Vec<String>,
    /// Arguments in order.
    pub args: Vec<Arg>,
    /// Output nodes (row-major for matrices).
    pub outputs: Vec<ExprId>,
    /// Return shape.
    pub shape: Shape,
    /// Its schedule.
    pub schedule: Schedule,
}

fn float_lit(v: f64) -> TokenStream {
    let lit = Literal::f64_unsuffixed(v.abs());
    if v.is_sign_negative() && v != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

fn var(n: usize) -> Ident {
    format_ident!("x{}", n)
}

fn operand(g: &Graph, s: &Schedule, id: ExprId) -> TokenStream {
    match s.operand(g, id) {
        Operand::Var(n) => {
            let v = var(n);
            quote!(#v)
        }
        Operand::Const(c) => float_lit(c),
        Operand::Input(a, i) => {
            let a = Ident::new(a.name(), Span::call_site());
            let i = Literal::usize_unsuffixed(i as usize);
            quote!(#a[#i])
        }
    }
}

fn math_call(cfg: &Config, f: &str, x: TokenStream) -> TokenStream {
    let f = Ident::new(f, Span::call_site());
    match &cfg.math {
        MathBackend::Libm => {
            let f = if f == "sin_cos" {
                format_ident!("sincos")
            } else {
                f
            };
            quote!(libm::#f(#x))
        }
        MathBackend::Std => quote!(f64::#f(#x)),
        MathBackend::Runtime(path) => {
            let path: syn::Path =
                syn::parse_str(path).unwrap_or_else(|_| syn::parse_quote!(runtime));
            quote!(#path::math::#f(#x))
        }
    }
}

fn body(g: &Graph, cfg: &Config, f: &Function<'_>) -> TokenStream {
    let s = &f.schedule;
    let mut stmts = Vec::with_capacity(s.steps.len());
    for step in &s.steps {
        let st = match *step {
            Step::SinCos { sin, cos, arg } => {
                let (a, b) = (var(sin), var(cos));
                let call = math_call(cfg, "sin_cos", operand(g, s, arg));
                quote!(let (#a, #b) = #call;)
            }
            Step::Check { node } => {
                let Node::Guard {
                    value,
                    tol,
                    scale,
                    index,
                } = g.node(node)
                else {
                    continue;
                };
                let (v, t, sc) = (
                    operand(g, s, value),
                    operand(g, s, tol),
                    operand(g, s, scale),
                );
                let i = Literal::usize_unsuffixed(index as usize);
                quote! {
                    if !(#v > #t) {
                        return Err(Singular {
                            pivot: #i,
                            value: #v,
                            condition_estimate: if #v > 0.0 { #sc / #v } else { f64::INFINITY },
                        });
                    }
                }
            }
            Step::Let { name, node } => {
                let x = var(name);
                let e = match g.node(node) {
                    Node::Add(a, b) => {
                        let (a, b) = (operand(g, s, a), operand(g, s, b));
                        quote!(#a + #b)
                    }
                    Node::Sub(a, b) => {
                        let (a, b) = (operand(g, s, a), operand(g, s, b));
                        quote!(#a - #b)
                    }
                    Node::Mul(a, b) => {
                        let (a, b) = (operand(g, s, a), operand(g, s, b));
                        quote!(#a * #b)
                    }
                    Node::Div(a, b) => {
                        let (a, b) = (operand(g, s, a), operand(g, s, b));
                        quote!(#a / #b)
                    }
                    Node::Neg(a) => {
                        let a = operand(g, s, a);
                        quote!(-#a)
                    }
                    Node::Sqrt(a) => math_call(cfg, "sqrt", operand(g, s, a)),
                    _ => continue,
                };
                quote!(let #x = #e;)
            }
        };
        stmts.push(st);
    }
    let outs: Vec<TokenStream> = f.outputs.iter().map(|&o| operand(g, s, o)).collect();
    let ret = match f.shape {
        Shape::Vector => quote!([#(#outs),*]),
        Shape::FallibleVector => quote!(Ok([#(#outs),*])),
        Shape::Matrix => {
            let n = (outs.len() as f64).sqrt().round() as usize;
            let rows: Vec<TokenStream> = outs.chunks(n.max(1)).map(|r| quote!([#(#r),*])).collect();
            quote!([#(#rows),*])
        }
    };
    quote! { #(#stmts)* #ret }
}

fn function(g: &Graph, cfg: &Config, f: &Function<'_>) -> TokenStream {
    let name = Ident::new(f.name, Span::call_site());
    let args: Vec<TokenStream> = f
        .args
        .iter()
        .map(|a| {
            let a = Ident::new(a.name(), Span::call_site());
            quote!(#a: &[f64; DOF])
        })
        .collect();
    let ret = match f.shape {
        Shape::Vector => quote!([f64; DOF]),
        Shape::Matrix => quote!([[f64; DOF]; DOF]),
        Shape::FallibleVector => quote!(Result<[f64; DOF], Singular>),
    };
    let docs = f.doc.iter().map(|d| {
        let d = format!(" {d}");
        quote!(#[doc = #d])
    });
    let ops = format!(" Cost per call: {}.", f.schedule.ops);
    let body = body(g, cfg, f);
    quote! {
        #(#docs)*
        #[doc = ""]
        #[doc = #ops]
        #[inline]
        #[allow(unused_variables, clippy::all)]
        pub fn #name(#(#args),*) -> #ret {
            #body
        }
    }
}

/// Emit the whole module for `functions`; `header` lines go first as `//` comments.
pub fn module(
    g: &Graph,
    cfg: &Config,
    header: &[String],
    dof: usize,
    joint_names: &[String],
    functions: &[Function<'_>],
) -> String {
    let dof_lit = Literal::usize_unsuffixed(dof);
    let names = joint_names.iter();
    let fns = functions.iter().map(|f| function(g, cfg, f));
    let needs_singular = functions
        .iter()
        .any(|f| matches!(f.shape, Shape::FallibleVector));
    let singular = needs_singular.then(|| {
        quote! {
            /// A failed pivot of the mass-matrix factorization: the configuration is singular
            /// (or an input is NaN). `value` is the pivot that was not above its tolerance
            /// (`1e-12` times the diagonal entry it came from); `condition_estimate` is that
            /// diagonal entry divided by the pivot, a lower bound of the 2-norm condition number
            /// of the mass matrix (`f64::INFINITY` when the pivot is not positive).
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct Singular {
                /// Index (joint) of the failed pivot.
                pub pivot: usize,
                /// The pivot's value.
                pub value: f64,
                /// Lower bound of the mass matrix's 2-norm condition number.
                pub condition_estimate: f64,
            }
        }
    });
    let tokens = quote! {
        /// Number of degrees of freedom (joint coordinates).
        pub const DOF: usize = #dof_lit;
        /// Joint names, in coordinate order.
        pub const JOINT_NAMES: [&str; DOF] = [#(#names),*];
        #singular
        #(#fns)*
    };
    let file: syn::File = match syn::parse2(tokens) {
        Ok(f) => f,
        // The tokens are built from a closed grammar above; a parse failure is a generator bug.
        Err(e) => panic!("internal error: generated tokens do not parse: {e}"),
    };
    let mut out = String::new();
    for h in header {
        out.push_str("// ");
        out.push_str(h);
        out.push('\n');
    }
    out.push('\n');
    out.push_str(&prettyplease::unparse(&file));
    out
}

/// The op-count table (markdown) of a set of functions.
pub fn stats_table(rows: &[(String, OpCount)], dof: usize) -> Vec<String> {
    let mut v = vec![
        "| function | flops | flops/joint | add | mul | neg | div | sqrt | sin_cos | cmp |"
            .to_string(),
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|".to_string(),
    ];
    for (name, c) in rows {
        v.push(format!(
            "| {name} | {} | {:.1} | {} | {} | {} | {} | {} | {} | {} |",
            c.flops(),
            c.flops() as f64 / dof.max(1) as f64,
            c.add,
            c.mul,
            c.neg,
            c.div,
            c.sqrt,
            c.sin_cos,
            c.cmp
        ));
    }
    v
}
