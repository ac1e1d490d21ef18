//! Reading a generated module's items for its C wrapper (`syn`, as `implement.rs` does): each
//! public function's arguments and result, the public constants, the variants of `Site`,
//! `Stop` and `IndexError`, the fields of `Params` and `InertiaIndices`.

use super::c_values;

/// A dimension of an array type: its Rust text (`DOF`, `3`) and value.
#[derive(Clone, Debug)]
pub(super) struct Dim {
    pub(super) rust: String,
    pub(super) n: usize,
}

/// The types a generated module's public items use.
#[derive(Clone, Debug)]
pub(super) enum Ty {
    Real,
    Usize,
    Str,
    Array(Box<Ty>, Dim),
    Tuple(Vec<Ty>),
    /// A struct of the module (`Params`, `InertiaIndices`).
    Named(String),
    /// `Result<T, E>`, `E` the error type's name.
    Result(Box<Ty>, String),
}

impl Ty {
    /// Dimensions of nested arrays, outermost first, and the element.
    pub(super) fn dims(&self) -> (Vec<&Dim>, &Ty) {
        match self {
            Ty::Array(e, d) => {
                let (mut ds, el) = e.dims();
                ds.insert(0, d);
                (ds, el)
            }
            t => (Vec::new(), t),
        }
    }

    /// Number of scalars of an array of reals (1 for a real).
    pub(super) fn len(&self) -> usize {
        self.dims().0.iter().map(|d| d.n).product()
    }

    /// The Rust type, dimensions as numbers, `R` the scalar.
    pub(super) fn rust(&self, real: &str) -> String {
        match self {
            Ty::Real => real.into(),
            Ty::Usize => "usize".into(),
            Ty::Str => "&str".into(),
            Ty::Array(e, d) => format!("[{}; {}]", e.rust(real), d.n),
            Ty::Tuple(v) => format!(
                "({})",
                v.iter()
                    .map(|t| t.rust(real))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Ty::Named(n) => format!("m::{n}"),
            Ty::Result(t, e) => format!("Result<{}, m::{e}>", t.rust(real)),
        }
    }
}

/// One variant of an error enum: its name, doc, and its fields (`None`: a unit variant; an
/// empty name: a tuple field).
pub(super) struct Variant {
    pub(super) name: String,
    pub(super) doc: String,
    pub(super) fields: Option<Vec<String>>,
}

/// One field of a struct.
pub(super) struct Field {
    pub(super) name: String,
    pub(super) doc: String,
    pub(super) ty: Ty,
}

/// One public function.
pub(super) struct Func {
    pub(super) name: String,
    pub(super) doc: String,
    pub(super) args: Vec<(String, Ty)>,
    pub(super) ret: Ty,
}

/// One public constant that C can use.
pub(super) struct Const {
    pub(super) name: String,
    pub(super) doc: String,
    pub(super) ty: Ty,
    /// Its values as C literals, flattened; `None` for a form C cannot take.
    pub(super) values: Option<Vec<String>>,
}

/// What the wrappers need of the module.
pub(super) struct Module {
    pub(super) consts: Vec<Const>,
    pub(super) usizes: Vec<(String, usize)>,
    pub(super) structs: Vec<(String, Vec<Field>)>,
    pub(super) enums: Vec<(String, Vec<Variant>)>,
    pub(super) fns: Vec<Func>,
}

impl Module {
    pub(super) fn struct_fields(&self, name: &str) -> Option<&[Field]> {
        self.structs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, f)| f.as_slice())
    }

    pub(super) fn variants(&self, name: &str) -> &[Variant] {
        self.enums
            .iter()
            .find(|(n, _)| n == name)
            .map_or(&[], |(_, v)| v.as_slice())
    }

    pub(super) fn has_const(&self, name: &str) -> bool {
        self.usizes.iter().any(|(n, _)| n == name)
    }
}

/// The doc comment of `attrs`, its lines joined, trimmed.
pub(super) fn doc(attrs: &[syn::Attribute]) -> String {
    let mut lines = Vec::new();
    for a in attrs {
        if let syn::Meta::NameValue(nv) = &a.meta
            && nv.path.is_ident("doc")
            && let syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) = &nv.value
        {
            for l in s.value().lines() {
                lines.push(l.strip_prefix(' ').unwrap_or(l).trim_end().to_string());
            }
        }
    }
    while lines.first().is_some_and(|l| l.is_empty()) {
        lines.remove(0);
    }
    while lines.last().is_some_and(|l| l.is_empty()) {
        lines.pop();
    }
    lines.join("\n")
}

/// The value of an integer expression: a literal or a known `usize` constant.
pub(super) fn usize_value(e: &syn::Expr, usizes: &[(String, usize)]) -> Result<usize, String> {
    match e {
        syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) => i.base10_parse().map_err(|e| e.to_string()),
        syn::Expr::Path(p) => {
            let name = p
                .path
                .get_ident()
                .map(|i| i.to_string())
                .unwrap_or_default();
            usizes
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| *v)
                .ok_or_else(|| format!("unknown length `{name}`"))
        }
        _ => Err("an array length that is not a constant".into()),
    }
}

pub(super) fn ty(t: &syn::Type, usizes: &[(String, usize)]) -> Result<Ty, String> {
    Ok(match t {
        syn::Type::Reference(r) => match &*r.elem {
            syn::Type::Path(p) if p.path.is_ident("str") => Ty::Str,
            e => ty(e, usizes)?,
        },
        syn::Type::Array(a) => {
            let n = usize_value(&a.len, usizes)?;
            let rust = match &a.len {
                syn::Expr::Path(p) => p.path.get_ident().map(|i| i.to_string()),
                _ => None,
            }
            .unwrap_or_else(|| n.to_string());
            Ty::Array(Box::new(ty(&a.elem, usizes)?), Dim { rust, n })
        }
        syn::Type::Tuple(t) => Ty::Tuple(
            t.elems
                .iter()
                .map(|e| ty(e, usizes))
                .collect::<Result<_, _>>()?,
        ),
        syn::Type::Path(p) => {
            let Some(seg) = p.path.segments.last() else {
                return Err("an empty type path".into());
            };
            match seg.ident.to_string().as_str() {
                "f64" | "f32" => Ty::Real,
                "usize" => Ty::Usize,
                "Result" => {
                    let syn::PathArguments::AngleBracketed(args) = &seg.arguments else {
                        return Err("`Result` without arguments".into());
                    };
                    let tys: Vec<&syn::Type> = args
                        .args
                        .iter()
                        .filter_map(|a| match a {
                            syn::GenericArgument::Type(t) => Some(t),
                            _ => None,
                        })
                        .collect();
                    let [ok, err] = tys[..] else {
                        return Err("`Result` without two types".into());
                    };
                    let Ty::Named(e) = ty(err, usizes)? else {
                        return Err("an error type that is not a named type".into());
                    };
                    Ty::Result(Box::new(ty(ok, usizes)?), e)
                }
                other => Ty::Named(other.to_string()),
            }
        }
        _ => return Err("an unsupported type".into()),
    })
}

pub(super) fn read(code: &str, single: bool) -> Result<Module, String> {
    let file = syn::parse_file(code).map_err(|e| format!("the module does not parse: {e}"))?;
    let public = |v: &syn::Visibility| matches!(v, syn::Visibility::Public(_));
    let mut m = Module {
        consts: Vec::new(),
        usizes: Vec::new(),
        structs: Vec::new(),
        enums: Vec::new(),
        fns: Vec::new(),
    };
    // `usize` constants first: array lengths refer to them.
    for item in &file.items {
        if let syn::Item::Const(c) = item
            && public(&c.vis)
            && matches!(&*c.ty, syn::Type::Path(p) if p.path.is_ident("usize"))
        {
            let v = usize_value(&c.expr, &m.usizes)?;
            m.usizes.push((c.ident.to_string(), v));
        }
    }
    for item in &file.items {
        match item {
            syn::Item::Const(c) if public(&c.vis) => {
                // A constant of a type C has no use for (e.g. a `Params`) is left out.
                if let Ok(t) = ty(&c.ty, &m.usizes) {
                    m.consts.push(Const {
                        name: c.ident.to_string(),
                        doc: doc(&c.attrs),
                        values: c_values(&c.expr, &t, &m.usizes, single),
                        ty: t,
                    });
                }
            }
            syn::Item::Struct(s) if public(&s.vis) => {
                let mut fields = Vec::new();
                for f in &s.fields {
                    let Some(name) = &f.ident else { continue };
                    let t = ty(&f.ty, &m.usizes)?;
                    fields.push(Field {
                        name: name.to_string(),
                        doc: doc(&f.attrs),
                        ty: t,
                    });
                }
                m.structs.push((s.ident.to_string(), fields));
            }
            syn::Item::Enum(e) if public(&e.vis) => {
                let variants = e
                    .variants
                    .iter()
                    .map(|v| Variant {
                        name: v.ident.to_string(),
                        doc: doc(&v.attrs),
                        fields: match &v.fields {
                            syn::Fields::Unit => None,
                            fs => Some(
                                fs.iter()
                                    .map(|f| {
                                        f.ident.as_ref().map(|i| i.to_string()).unwrap_or_default()
                                    })
                                    .collect(),
                            ),
                        },
                    })
                    .collect();
                m.enums.push((e.ident.to_string(), variants));
            }
            syn::Item::Fn(f) if public(&f.vis) => {
                let mut args = Vec::new();
                for a in &f.sig.inputs {
                    let syn::FnArg::Typed(pt) = a else {
                        return Err("a method among the functions".into());
                    };
                    let syn::Pat::Ident(id) = &*pt.pat else {
                        return Err("an argument that is not a name".into());
                    };
                    args.push((id.ident.to_string(), ty(&pt.ty, &m.usizes)?));
                }
                let ret = match &f.sig.output {
                    syn::ReturnType::Type(_, t) => ty(t, &m.usizes)?,
                    syn::ReturnType::Default => Ty::Tuple(Vec::new()),
                };
                m.fns.push(Func {
                    name: f.sig.ident.to_string(),
                    doc: doc(&f.attrs),
                    args,
                    ret,
                });
            }
            _ => {}
        }
    }
    Ok(m)
}
