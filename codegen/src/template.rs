//! Fixed items written as real Rust: the files under `codegen/templates/`, each compiled and
//! tested as a module of its own (`tests/tests/templates.rs`, `tests/tests/indices.rs`), then pulled in here as
//! tokens and specialized for the module being generated.
//!
//! A template is ordinary Rust over the names a generated module defines around it (`DOF`,
//! `NX`, `Singular`, the kernels) and a few stand-ins that the test module defines and
//! [`Specialize`] replaces:
//! - the identifier `f64` becomes the module's scalar type ([`crate::emit::real`]);
//! - the free calls `sin_cos(…)`, `sqrt(…)` and `atan2(…)` become the math backend's
//!   ([`crate::emit::math_call`]);
//! - a named constant (`FK_TOLERANCE`) becomes the tokens given for it, typically a literal;
//! - `if FLAG { … }` (no `else`) with a named flag keeps its body or drops it;
//! - `{NAME}` in a doc comment becomes the text given for it;
//! - without run-time parameters, a trailing `, p: &Params` parameter and a trailing `, p`
//!   argument are removed.
//!
//! Plain `//` comments are not tokens, so they stay in the template.

use proc_macro2::{Delimiter, Group, Ident, Literal, TokenStream, TokenTree};
use quote::{ToTokens, quote};

use crate::Config;
use crate::emit;

/// How to specialize a template (see the module docs).
pub(crate) struct Specialize<'a> {
    cfg: &'a Config,
    constants: Vec<(&'static str, TokenStream)>,
    flags: Vec<(&'static str, bool)>,
    docs: Vec<(&'static str, String)>,
    params: bool,
}

impl<'a> Specialize<'a> {
    /// No constants, flags or doc values; without run-time parameters.
    pub(crate) fn new(cfg: &'a Config) -> Self {
        Specialize {
            cfg,
            constants: Vec::new(),
            flags: Vec::new(),
            docs: Vec::new(),
            params: false,
        }
    }

    /// The identifier `name` becomes `value`.
    pub(crate) fn constant(mut self, name: &'static str, value: impl ToTokens) -> Self {
        self.constants.push((name, value.into_token_stream()));
        self
    }

    /// `if name { … }` keeps its body when `on`, else is dropped.
    pub(crate) fn flag(mut self, name: &'static str, on: bool) -> Self {
        self.flags.push((name, on));
        self
    }

    /// `{name}` in doc comments becomes `text`.
    pub(crate) fn doc(mut self, name: &'static str, text: impl Into<String>) -> Self {
        self.docs.push((name, text.into()));
        self
    }

    /// Whether the functions take the run-time parameters `p: &Params`.
    pub(crate) fn params(mut self, on: bool) -> Self {
        self.params = on;
        self
    }

    /// The items of `source` named in `names`, specialized, in the order of `names`; a type's
    /// `impl` blocks in `source` follow it.
    pub(crate) fn items(&self, source: &str, names: &[&str]) -> TokenStream {
        // The templates are this crate's own files, parsed by a test for every one of them: a
        // failure here is a generator bug.
        let tokens: TokenStream = match source.parse() {
            Ok(t) => t,
            Err(e) => panic!("internal error: a template does not lex: {e}"),
        };
        let file: syn::File = match syn::parse2(self.walk(tokens)) {
            Ok(f) => f,
            Err(e) => panic!("internal error: a specialized template does not parse: {e}"),
        };
        let items = names.iter().flat_map(|name| {
            let item = match file
                .items
                .iter()
                .find(|item| item_name(item).as_deref() == Some(*name))
            {
                Some(item) => item,
                None => panic!("internal error: no item `{name}` in the template"),
            };
            let impls = file
                .items
                .iter()
                .filter(|i| impl_of(i).as_deref() == Some(*name));
            std::iter::once(item).chain(impls)
        });
        quote!(#(#items)*)
    }

    fn walk(&self, tokens: TokenStream) -> TokenStream {
        let trees: Vec<TokenTree> = tokens.into_iter().collect();
        let mut out: Vec<TokenTree> = Vec::with_capacity(trees.len());
        let mut i = 0;
        while i < trees.len() {
            let next = trees.get(i + 1);
            match &trees[i] {
                TokenTree::Ident(id) => {
                    let name = id.to_string();
                    let after_path = matches!(out.last(), Some(TokenTree::Punct(p)) if p.as_char() == '.' || p.as_char() == ':');
                    if name == "f64" {
                        out.push(TokenTree::Ident(emit::real()));
                    } else if let Some((_, v)) = self.constants.iter().find(|(n, _)| *n == name) {
                        out.extend(v.clone());
                    } else if let (false, "sin_cos" | "sqrt" | "atan2", Some(TokenTree::Group(g))) =
                        (after_path, name.as_str(), next)
                        && g.delimiter() == Delimiter::Parenthesis
                    {
                        out.extend(emit::math_call(self.cfg, &name, self.walk(g.stream())));
                        i += 1;
                    } else if let Some(body) = self.flagged_if(&trees, i) {
                        out.extend(body);
                        i += 2;
                    } else {
                        out.push(trees[i].clone());
                    }
                }
                TokenTree::Group(g)
                    if g.delimiter() == Delimiter::Bracket && is_pound(out.last()) =>
                {
                    out.push(TokenTree::Group(self.attribute(g)));
                }
                TokenTree::Group(g) => {
                    let mut inner = self.walk(g.stream());
                    if g.delimiter() == Delimiter::Parenthesis && !self.params {
                        inner = strip_params(inner);
                    }
                    let mut ng = Group::new(g.delimiter(), inner);
                    ng.set_span(g.span());
                    out.push(TokenTree::Group(ng));
                }
                t => out.push(t.clone()),
            }
            i += 1;
        }
        out.into_iter().collect()
    }

    /// `if FLAG { … }` at `i` (a named flag, no `else`): the body's tokens if the flag is on,
    /// nothing if it is off; `None` for any other `if`.
    fn flagged_if(&self, trees: &[TokenTree], i: usize) -> Option<TokenStream> {
        let (TokenTree::Ident(kw), Some(TokenTree::Ident(flag)), Some(TokenTree::Group(body))) =
            (&trees[i], trees.get(i + 1), trees.get(i + 2))
        else {
            return None;
        };
        if kw != "if" || body.delimiter() != Delimiter::Brace {
            return None;
        }
        if matches!(trees.get(i + 3), Some(TokenTree::Ident(e)) if e == "else") {
            return None;
        }
        let (_, on) = self.flags.iter().find(|(n, _)| flag == n)?;
        Some(if *on {
            self.walk(body.stream())
        } else {
            TokenStream::new()
        })
    }

    /// An attribute's brackets: `doc = "…"` with its `{NAME}`s and `f64` filled in; any other
    /// attribute as it is.
    fn attribute(&self, g: &Group) -> Group {
        let trees: Vec<TokenTree> = g.stream().into_iter().collect();
        let doc = match trees.as_slice() {
            [
                TokenTree::Ident(d),
                TokenTree::Punct(eq),
                TokenTree::Literal(lit),
            ] if d == "doc" && eq.as_char() == '=' => {
                syn::parse_str::<syn::LitStr>(&lit.to_string()).ok()
            }
            _ => None,
        };
        let Some(doc) = doc else {
            return g.clone();
        };
        let mut text = emit::real_text(&doc.value());
        for (name, value) in &self.docs {
            text = text.replace(&format!("{{{name}}}"), value);
        }
        let lit = Literal::string(&text);
        let mut ng = Group::new(Delimiter::Bracket, quote!(doc = #lit));
        ng.set_span(g.span());
        ng
    }
}

fn is_pound(t: Option<&TokenTree>) -> bool {
    matches!(t, Some(TokenTree::Punct(p)) if p.as_char() == '#')
}

/// A parenthesized list without its last item if that is `p: &Params` or `p`.
fn strip_params(inner: TokenStream) -> TokenStream {
    let mut t: Vec<TokenTree> = inner.into_iter().collect();
    let is = |t: &TokenTree, s: &str| t.to_string() == s;
    // A list written one item per line ends with a comma.
    let trailing = t.last().is_some_and(|l| is(l, ","));
    let n = t.len() - usize::from(trailing);
    if n >= 5
        && is(&t[n - 5], ",")
        && is(&t[n - 4], "p")
        && is(&t[n - 3], ":")
        && is(&t[n - 2], "&")
        && is(&t[n - 1], "Params")
    {
        t.truncate(n - 5);
    } else if n >= 2 && is(&t[n - 2], ",") && is(&t[n - 1], "p") {
        t.truncate(n - 2);
    }
    t.into_iter().collect()
}

/// The type an `impl` block is for (`impl Display for IndexError`: `IndexError`).
fn impl_of(item: &syn::Item) -> Option<String> {
    match item {
        syn::Item::Impl(i) => match &*i.self_ty {
            syn::Type::Path(p) => p.path.get_ident().map(Ident::to_string),
            _ => None,
        },
        _ => None,
    }
}

fn item_name(item: &syn::Item) -> Option<String> {
    let id: &Ident = match item {
        syn::Item::Fn(f) => &f.sig.ident,
        syn::Item::Const(c) => &c.ident,
        syn::Item::Struct(s) => &s.ident,
        syn::Item::Enum(e) => &e.ident,
        _ => return None,
    };
    Some(id.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Float, MathBackend};

    const SOURCE: &str = r#"
        /// At most {LIMIT} steps of `f64`.
        pub fn f(x: &[f64; N], p: &Params) -> f64 {
            let (s, c) = sin_cos(x[0]);
            let r = x.iter().map(|v| v.sqrt()).sum::<f64>() + sqrt(s * c);
            if EXTRA {
                let r = r + 1.0;
            }
            g(r, p) * LIMIT as f64
        }
        fn unused() {}
    "#;

    fn text(cfg: &Config, params: bool, extra: bool) -> String {
        let sp = Specialize::new(cfg)
            .constant("LIMIT", Literal::usize_unsuffixed(7))
            .flag("EXTRA", extra)
            .doc("LIMIT", "7")
            .params(params);
        sp.items(SOURCE, &["f"]).to_string()
    }

    #[test]
    fn stand_ins_are_replaced() {
        let cfg = Config::default();
        let t = text(&cfg, false, false);
        assert!(t.contains("\" At most 7 steps of `f64`.\""), "{t}");
        assert!(t.contains("libm :: sincos (x [0])"), "{t}");
        assert!(t.contains("libm :: sqrt (s * c)"), "{t}");
        // A method call of the same name is not the math backend's.
        assert!(t.contains(". sqrt ()"), "{t}");
        assert!(t.contains("g (r) * 7 as f64"), "{t}");
        assert!(
            !t.contains("Params") && !t.contains("EXTRA") && !t.contains("r + 1.0"),
            "{t}"
        );
        assert!(!t.contains("unused"), "{t}");
        let t = text(&cfg, true, true);
        assert!(t.contains("p : & Params") && t.contains("g (r , p)"), "{t}");
        assert!(t.contains("let r = r + 1.0") && !t.contains("EXTRA"), "{t}");
    }

    #[test]
    fn single_precision_names_f32_everywhere() {
        for math in [
            MathBackend::Libm,
            MathBackend::Std,
            MathBackend::Runtime("rt".into()),
        ] {
            let cfg = Config {
                math: math.clone(),
                float: Float::F32,
                ..Config::default()
            };
            let t = crate::scalar::with_precision(true, || text(&cfg, false, false));
            assert!(!t.contains("f64"), "{math:?}: {t}");
            assert!(t.contains("[f32 ; N]") && t.contains("`f32`"), "{t}");
            let (sc, sq) = match math {
                MathBackend::Libm => ("libm :: sincosf (", "libm :: sqrtf ("),
                MathBackend::Std => ("f32 :: sin_cos (", "f32 :: sqrt ("),
                MathBackend::Runtime(_) => {
                    ("rt :: math :: sin_cos_f32 (", "rt :: math :: sqrt_f32 (")
                }
            };
            assert!(t.contains(sc) && t.contains(sq), "{math:?}: {t}");
        }
    }
}
