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
    /// `Result<…, Singular>` of one part or a tuple of parts, in output order. In a tree
    /// module every output (the [`Part::Hidden`] ones first) is checked for finiteness, as in
    /// [`Shape::FallibleVector`].
    Fallible(Vec<Part>),
    /// A tuple of parts, in output order (no [`Part::Hidden`]).
    Tuple(Vec<Part>),
    /// `[[f64; NBP]; DOF]`, outputs row-major (a tree's `regressor`).
    Regressor,
}

/// One part of a [`Shape::Fallible`] result.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// `[f64; DOF]`.
    Vector,
    /// `[[f64; DOF]; DOF]`, row-major.
    Matrix,
    /// `[[[f64; DOF]; DOF]; DOF]`, `DOF` row-major matrices one after the other (a platform's
    /// `∂A/∂x_j`, `j` first).
    Matrices,
    /// `[f64; NX]` with `NX` given (closed loops: all joint coordinates).
    Coords(usize),
    /// `[f64; N]` with the literal length `N` (a 1T2R platform's full pose, `N = 7`).
    Array(usize),
    /// `f64`.
    Scalar,
    /// `[[f64; 3]; 3]`, row-major (a rotation matrix).
    Rotation,
    /// `[[f64; DOF]; 6]`, row-major (a frame's Jacobian).
    Jacobian,
    /// `[[f64; NBP]; DOF]`, row-major, with `NBP` given (a platform's regressor kernel).
    Regressor(usize),
    /// This many outputs that are checked for finiteness but not returned (a tree's
    /// `forward_dynamics_derivatives`: its `q̈`, so that it fails where `forward_dynamics` does).
    Hidden(usize),
}

impl Part {
    fn len(self, dof: usize) -> usize {
        match self {
            Part::Vector => dof,
            Part::Matrix => dof * dof,
            Part::Matrices => dof * dof * dof,
            Part::Coords(n) | Part::Array(n) | Part::Hidden(n) => n,
            Part::Scalar => 1,
            Part::Rotation => 9,
            Part::Jacobian => 6 * dof,
            Part::Regressor(k) => dof * k,
        }
    }
    fn ty(self) -> TokenStream {
        let real = real();
        match self {
            Part::Vector => quote!([#real; DOF]),
            Part::Matrix => quote!([[#real; DOF]; DOF]),
            Part::Matrices => quote!([[[#real; DOF]; DOF]; DOF]),
            Part::Regressor(_) => quote!([[#real; NBP]; DOF]),
            Part::Coords(_) => quote!([#real; NX]),
            Part::Array(n) => {
                let n = proc_macro2::Literal::usize_unsuffixed(n);
                quote!([#real; #n])
            }
            Part::Scalar => quote!(#real),
            Part::Rotation => quote!([[#real; 3]; 3]),
            Part::Jacobian => quote!([[#real; DOF]; 6]),
            Part::Hidden(_) => quote!(()),
        }
    }
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
    /// Degrees of freedom (the length of a [`Part::Vector`]).
    pub dof: usize,
    /// Its schedule.
    pub schedule: Schedule,
    /// `pub` (else a private kernel of a public wrapper).
    pub public: bool,
    /// Guards name a `Site` (parallel mechanisms) instead of a pivot (trees).
    pub sites: bool,
}

pub(crate) fn float_lit(v: f64) -> TokenStream {
    let lit = Literal::f64_unsuffixed(v.abs());
    if v.is_sign_negative() && v != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

pub(crate) fn var(n: usize) -> Ident {
    format_ident!("x{}", n)
}

pub(crate) fn operand(g: &Graph, s: &Schedule, id: ExprId) -> TokenStream {
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

/// The scalar type of the module being generated: `f64`, or `f32` when the generation runs in
/// single precision ([`crate::Float::F32`]). Every type, constant path (`f64::INFINITY`,
/// `core::f64::consts::PI`) and method path (`f64::abs`) the generator writes names it.
pub(crate) fn real() -> Ident {
    Ident::new(
        if crate::scalar::single() {
            "f32"
        } else {
            "f64"
        },
        Span::call_site(),
    )
}

/// `text` (a doc or header line naming the scalar type) with the word `f64` replaced by
/// [`real`]'s name.
pub(crate) fn real_text(text: &str) -> String {
    if crate::scalar::single() {
        text.replace("f64", "f32")
    } else {
        text.to_string()
    }
}

/// A call of the math backend's `f` (`sin_cos`, `sqrt`, `atan2`, `mul_add`) on the argument
/// tokens `x`. In `f32` these are `libm::{sincosf, sqrtf, atan2f, fmaf}`, `f32::…` and
/// `runtime::math::*_f32`.
pub(crate) fn math_call(cfg: &Config, f: &str, x: TokenStream) -> TokenStream {
    let single = crate::scalar::single();
    match &cfg.math {
        MathBackend::Libm => {
            let f = match f {
                "sin_cos" => "sincos",
                "mul_add" => "fma",
                f => f,
            };
            let f = format_ident!("{}{}", f, if single { "f" } else { "" });
            quote!(libm::#f(#x))
        }
        MathBackend::Std => {
            let (real, f) = (real(), Ident::new(f, Span::call_site()));
            quote!(#real::#f(#x))
        }
        MathBackend::Runtime(path) => {
            let path: syn::Path =
                syn::parse_str(path).unwrap_or_else(|_| syn::parse_quote!(runtime));
            let f = format_ident!("{}{}", f, if single { "_f32" } else { "" });
            quote!(#path::math::#f(#x))
        }
    }
}

fn body(g: &Graph, cfg: &Config, f: &Function<'_>) -> TokenStream {
    let batched;
    let s = if cfg.batch_sin_cos {
        batched = crate::sin_cos::batched(g, &f.schedule);
        &batched
    } else {
        &f.schedule
    };
    let mut stmts = Vec::with_capacity(s.steps.len());
    for step in &s.steps {
        stmts.push(step_tokens(g, cfg, f, s, step));
    }
    let stmts = chunked(g, s, &f.outputs, stmts);
    let checks = input_checks(f);
    let stmts: Vec<TokenStream> = checks.into_iter().chain(stmts).collect();
    let outs: Vec<TokenStream> = f.outputs.iter().map(|&o| operand(g, s, o)).collect();
    // Constants are finite: a result of constants only (a platform frame's constant
    // Jacobian) needs no check (and an array of bare literals no `is_finite`).
    let out_check = if f.outputs.iter().all(|&o| g.as_const(o).is_some()) {
        TokenStream::new()
    } else {
        output_check(f, &outs)
    };
    let ret = return_tokens(f, &outs);
    quote! { #(#stmts)* #out_check #ret }
}

/// The statement of one step (empty for a `Check` of a node that is no guard, or a `Let` of a
/// node that is no operation).
fn step_tokens(
    g: &Graph,
    cfg: &Config,
    f: &Function<'_>,
    s: &Schedule,
    step: &Step,
) -> TokenStream {
    match *step {
        Step::SinCos { sin, cos, arg } => {
            let (a, b) = (var(sin), var(cos));
            let call = math_call(cfg, "sin_cos", operand(g, s, arg));
            quote!(let (#a, #b) = #call;)
        }
        Step::SinCosBatch => crate::sin_cos::batch_statement(g, s),
        Step::Check { node } => check_tokens(g, f, node),
        Step::Let { name, node } => let_tokens(g, cfg, s, name, node),
        Step::MulAdd { name, node, mul } => {
            let x = var(name);
            let e = crate::fma::call(g, cfg, node, mul, &|id| operand(g, s, id));
            quote!(let #x = #e;)
        }
    }
}

/// A guard's test: `Err(Singular)` at its site (parallel) or pivot (trees) when it fails.
fn check_tokens(g: &Graph, f: &Function<'_>, node: ExprId) -> TokenStream {
    let real = real();
    let s = &f.schedule;
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
        operand(g, s, value),
        operand(g, s, tol),
        operand(g, s, scale),
    );
    let two_sided = index & crate::sym::TWO_SIDED != 0;
    let code = index & !crate::sym::TWO_SIDED;
    let test = if two_sided {
        quote!(#v > #t || #v < -#t)
    } else {
        quote!(#v > #t)
    };
    let magnitude = if two_sided {
        quote!(if #v < 0.0 { -#v } else { #v })
    } else {
        quote!(#v)
    };
    let at = if f.sites {
        site_tokens(runtime::scalar::Site::from_code(code))
    } else {
        let i = Literal::usize_unsuffixed(code as usize);
        quote!(pivot: #i)
    };
    if two_sided {
        quote! {
            if !(#test) {
                let a = #magnitude;
                return Err(Singular {
                    #at,
                    value: #v,
                    condition_estimate: if a > 0.0 { #sc / a } else { #real::INFINITY },
                });
            }
        }
    } else {
        quote! {
            if !(#test) {
                return Err(Singular {
                    #at,
                    value: #v,
                    condition_estimate: if #v > 0.0 { #sc / #v } else { #real::INFINITY },
                });
            }
        }
    }
}

/// `let x = …;` of one operation (empty for a node that is none).
fn let_tokens(g: &Graph, cfg: &Config, s: &Schedule, name: usize, node: ExprId) -> TokenStream {
    let real = real();
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
        Node::Atan2(a, b) => {
            let (a, b) = (operand(g, s, a), operand(g, s, b));
            math_call(cfg, "atan2", quote!(#a, #b))
        }
        Node::Select(a, b, x, y) => {
            let (a, b) = (operand(g, s, a), operand(g, s, b));
            let (x, y) = (operand(g, s, x), operand(g, s, y));
            quote!(if #real::abs(#a) > #real::abs(#b) { #x } else { #y })
        }
        _ => return TokenStream::new(),
    };
    quote!(let #x = #e;)
}

/// Parallel modules: a NaN or infinite input is an error, not a NaN result.
fn input_checks(f: &Function<'_>) -> Vec<TokenStream> {
    let real = real();
    if f.sites {
        f.args
            .iter()
            .map(|a| {
                let a = Ident::new(a.name(), Span::call_site());
                quote! {
                    for v in #a.iter() {
                        if !v.is_finite() {
                            return Err(Singular {
                                site: Site::Input,
                                value: *v,
                                condition_estimate: #real::INFINITY,
                            });
                        }
                    }
                }
            })
            .collect()
    } else {
        Vec::new()
    }
}

/// A result that overflowed, or a non-finite input that reached it, is an error, not an `Ok`
/// with NaN or ∞: `Site::Input` in platform and closed-loop modules; in a tree's
/// `forward_dynamics` (whose pivots a `q̇`, a `τ` or an angle that only enters gravity or
/// Coriolis terms passes) the index one past the pivots.
fn output_check(f: &Function<'_>, outs: &[TokenStream]) -> TokenStream {
    let real = real();
    let at = if f.sites {
        quote!(site: Site::Input)
    } else if matches!(f.shape, Shape::FallibleVector | Shape::Fallible(_)) {
        quote!(pivot: DOF)
    } else {
        return TokenStream::new();
    };
    quote! {
        for v in [#(#outs),*].iter() {
            if !v.is_finite() {
                return Err(Singular {
                    #at,
                    value: *v,
                    condition_estimate: #real::INFINITY,
                });
            }
        }
    }
}

/// The returned expression of the function's shape.
pub(crate) fn return_tokens(f: &Function<'_>, outs: &[TokenStream]) -> TokenStream {
    match f.shape {
        Shape::Vector => quote!([#(#outs),*]),
        Shape::FallibleVector => quote!(Ok([#(#outs),*])),
        Shape::Matrix => {
            let n = (outs.len() as f64).sqrt().round() as usize;
            let rows: Vec<TokenStream> = outs.chunks(n.max(1)).map(|r| quote!([#(#r),*])).collect();
            quote!([#(#rows),*])
        }
        Shape::Fallible(ref parts) => {
            let v = parts_tokens(parts, f.dof, outs);
            quote!(Ok(#v))
        }
        Shape::Tuple(ref parts) => parts_tokens(parts, f.dof, outs),
        Shape::Regressor => {
            let k = outs.len() / f.dof.max(1);
            let rows: Vec<TokenStream> = outs.chunks(k.max(1)).map(|r| quote!([#(#r),*])).collect();
            quote!([#(#rows),*])
        }
    }
}

/// One part or a tuple of parts, in output order ([`Part::Hidden`] ones left out).
pub(crate) fn parts_tokens(parts: &[Part], n: usize, outs: &[TokenStream]) -> TokenStream {
    let mut rest = outs;
    let mut items = Vec::new();
    for p in parts {
        let (now, later) = rest.split_at(p.len(n).min(rest.len()));
        rest = later;
        items.push(match p {
            Part::Vector | Part::Coords(_) | Part::Array(_) => quote!([#(#now),*]),
            Part::Scalar => quote!(#(#now)*),
            Part::Hidden(_) => continue,
            Part::Matrix | Part::Jacobian => matrix_tokens(now, n),
            Part::Matrices => {
                let m: Vec<TokenStream> = now
                    .chunks((n * n).max(1))
                    .map(|m| matrix_tokens(m, n))
                    .collect();
                quote!([#(#m),*])
            }
            Part::Rotation => matrix_tokens(now, 3),
            Part::Regressor(k) => {
                let rows: Vec<TokenStream> =
                    now.chunks((*k).max(1)).map(|r| quote!([#(#r),*])).collect();
                quote!([#(#rows),*])
            }
        });
    }
    if items.len() == 1 {
        quote!(#(#items)*)
    } else {
        quote!((#(#items),*))
    }
}

/// A row-major `n × n` matrix of outputs.
fn matrix_tokens(outs: &[TokenStream], n: usize) -> TokenStream {
    let rows: Vec<TokenStream> = outs.chunks(n.max(1)).map(|r| quote!([#(#r),*])).collect();
    quote!([#(#rows),*])
}

/// Statements per block beyond which a function body is split into blocks.
const CHUNK: usize = 512;

/// Variables a step defines and uses.
pub(crate) fn step_vars(g: &Graph, s: &Schedule, step: &Step) -> (Vec<usize>, Vec<usize>) {
    let var_of = |id: ExprId| match s.operand(g, id) {
        Operand::Var(n) => Some(n),
        _ => None,
    };
    match *step {
        Step::SinCos { sin, cos, arg } => (vec![sin, cos], var_of(arg).into_iter().collect()),
        Step::SinCosBatch => (
            s.batch
                .iter()
                .flat_map(|&(sin, cos, _)| [sin, cos])
                .collect(),
            s.batch.iter().filter_map(|&(_, _, a)| var_of(a)).collect(),
        ),
        Step::Check { node } => (vec![], g.operands(node).filter_map(var_of).collect()),
        Step::Let { name, node } => (vec![name], g.operands(node).filter_map(var_of).collect()),
        Step::MulAdd { name, node, mul } => (vec![name], crate::fma::reads(g, s, node, mul)),
    }
}

/// Long bodies as a sequence of blocks, each yielding the variables later blocks use:
/// `let (x7, x9) = { …; (x7, x9) };`. Every `let` opens a lexical scope in the debug
/// information, and rustc's LLVM backend recurses once per nested scope: thousands of `let`s in
/// one block overflow its stack. Blocks keep the nesting depth near `CHUNK` plus the number of
/// blocks. Short bodies are left as they are.
pub(crate) fn chunked(
    g: &Graph,
    s: &Schedule,
    outputs: &[ExprId],
    stmts: Vec<TokenStream>,
) -> Vec<TokenStream> {
    if stmts.len() <= 4 * CHUNK {
        return stmts;
    }
    let vars: Vec<(Vec<usize>, Vec<usize>)> =
        s.steps.iter().map(|st| step_vars(g, s, st)).collect();
    let mut last_use: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    for (i, (_, uses)) in vars.iter().enumerate() {
        for &u in uses {
            last_use.insert(u, i);
        }
    }
    for &o in outputs {
        if let Operand::Var(n) = s.operand(g, o) {
            last_use.insert(n, usize::MAX);
        }
    }
    let mut out = Vec::new();
    let mut start = 0;
    while start < stmts.len() {
        let end = (start + CHUNK).min(stmts.len());
        let mut live: Vec<usize> = vars[start..end]
            .iter()
            .flat_map(|(defs, _)| defs.iter().copied())
            .filter(|d| last_use.get(d).is_some_and(|&u| u >= end))
            .collect();
        live.sort_unstable();
        let body = &stmts[start..end];
        let names: Vec<Ident> = live.iter().map(|&n| var(n)).collect();
        out.push(match names.len() {
            0 => quote! { { #(#body)* } },
            1 => {
                let v = &names[0];
                quote! { let #v = { #(#body)* #v }; }
            }
            _ => quote! { let (#(#names),*) = { #(#body)* (#(#names),*) }; },
        });
        start = end;
    }
    out
}

/// `site: Site::…` of a guard in a parallel module.
fn site_tokens(site: runtime::scalar::Site) -> TokenStream {
    let e = site_expr(site);
    quote!(site: #e)
}

/// The generated module's `Site::…` value of `site`.
pub(crate) fn site_expr(site: runtime::scalar::Site) -> TokenStream {
    use runtime::scalar::Site as S;
    let (variant, i) = match site {
        S::MassMatrix(i) => ("MassMatrix", Some(i)),
        S::Leg(i) => ("Leg", Some(i)),
        S::Reach(i) => ("Reach", Some(i)),
        S::Actuation(i) => ("Actuation", Some(i)),
        S::Closure(i) => ("Closure", Some(i)),
        S::Constraint(i) => ("Constraint", Some(i)),
        S::Spring(i) => ("Spring", Some(i)),
        S::Platform => ("Platform", None),
        S::Input => ("Input", None),
    };
    let variant = Ident::new(variant, Span::call_site());
    match i {
        Some(i) => {
            let i = Literal::usize_unsuffixed(i);
            quote!(Site::#variant(#i))
        }
        None => quote!(Site::#variant),
    }
}

/// The tokens of one function.
pub(crate) fn function(g: &Graph, cfg: &Config, f: &Function<'_>) -> TokenStream {
    let real = real();
    let name = Ident::new(f.name, Span::call_site());
    let args: Vec<TokenStream> = f
        .args
        .iter()
        .map(|a| {
            if *a == Arg::P {
                return quote!(p: &Params);
            }
            let len = if *a == Arg::X {
                quote!(NX)
            } else {
                quote!(DOF)
            };
            let a = Ident::new(a.name(), Span::call_site());
            quote!(#a: &[#real; #len])
        })
        .collect();
    let ret = return_type(&f.shape);
    let docs = f.doc.iter().map(|d| {
        let d = format!(" {d}");
        quote!(#[doc = #d])
    });
    let ops = format!(" Cost per call: {}.", f.schedule.ops);
    let body = body(g, cfg, f);
    // Run-time parameters are read as one flat array (`dynamics::param_index`).
    let body = if f.args.contains(&Arg::P) {
        quote! {
            let p = p.to_array();
            #body
        }
    } else {
        body
    };
    let vis = if f.public { quote!(pub) } else { quote!() };
    quote! {
        #(#docs)*
        #[doc = ""]
        #[doc = #ops]
        #[inline]
        #[allow(unused_variables, clippy::all)]
        #vis fn #name(#(#args),*) -> #ret {
            #body
        }
    }
}

/// The type a function of `shape` returns.
pub(crate) fn return_type(shape: &Shape) -> TokenStream {
    let real = real();
    match shape {
        Shape::Vector => quote!([#real; DOF]),
        Shape::Matrix => quote!([[#real; DOF]; DOF]),
        Shape::FallibleVector => quote!(Result<[#real; DOF], Singular>),
        Shape::Fallible(parts) => {
            let t = parts_type(parts);
            quote!(Result<#t, Singular>)
        }
        Shape::Tuple(parts) => parts_type(parts),
        Shape::Regressor => quote!([[#real; NBP]; DOF]),
    }
}

/// The type of one part or a tuple of parts ([`Part::Hidden`] ones left out).
pub(crate) fn parts_type(parts: &[Part]) -> TokenStream {
    let tys: Vec<TokenStream> = parts
        .iter()
        .filter(|p| !matches!(p, Part::Hidden(_)))
        .map(|p| p.ty())
        .collect();
    if tys.len() == 1 {
        quote!(#(#tys)*)
    } else {
        quote!((#(#tys),*))
    }
}

/// Header comment lines, then the items `tokens` pretty-printed.
pub(crate) fn render(header: &[String], tokens: TokenStream) -> String {
    let file: syn::File = match syn::parse2(tokens) {
        Ok(f) => f,
        // The tokens are built from a closed grammar above; a parse failure is a generator bug.
        Err(e) => panic!("internal error: generated tokens do not parse: {e}"),
    };
    let mut out = String::new();
    for (i, h) in header.iter().enumerate() {
        out.push_str("// ");
        out.push_str(&real_text(h));
        out.push('\n');
        if i == 0 && crate::scalar::single() {
            // The precision is named right after the first line.
            out.push_str("// Scalar: f32 (single precision; the guards' thresholds and Newton's tolerance rescaled to it).\n");
        }
    }
    out.push('\n');
    out.push_str(&prettyplease::unparse(&file));
    out
}

/// The op-count table (markdown) of a set of functions.
pub fn stats_table(rows: &[(String, OpCount)], dof: usize) -> Vec<String> {
    stats_table_per(rows, dof, "joint")
}

/// [`stats_table`] with the per-unit column named `flops/<per>` (`"DOF"` for parallel
/// mechanisms, whose functions are per degree of freedom of the platform).
pub fn stats_table_per(rows: &[(String, OpCount)], dof: usize, per: &str) -> Vec<String> {
    // The `atan2` column appears only when some function calls it (parallel mechanisms with
    // revolute actuators), so tree tables keep their shape.
    let atan2 = rows.iter().any(|(_, c)| c.atan2 > 0);
    let (h1, h2) = if atan2 {
        (" atan2 |", "---:|")
    } else {
        ("", "")
    };
    // Likewise the `fma` column, only with fused multiply–adds (`Config::fma`).
    let fma = rows.iter().any(|(_, c)| c.fma > 0);
    let (f1, f2) = if fma { (" fma |", "---:|") } else { ("", "") };
    let mut v = vec![
        format!(
            "| function | flops | flops/{per} | add | mul |{f1} neg | div | sqrt | sin_cos | cmp |{h1}"
        ),
        format!("|---|---:|---:|---:|---:|{f2}---:|---:|---:|---:|---:|{h2}"),
    ];
    for (name, c) in rows {
        let extra = if atan2 {
            format!(" {} |", c.atan2)
        } else {
            String::new()
        };
        let fused = if fma {
            format!(" {} |", c.fma)
        } else {
            String::new()
        };
        v.push(format!(
            "| {name} | {} | {:.1} | {} | {} |{fused} {} | {} | {} | {} | {} |{extra}",
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
