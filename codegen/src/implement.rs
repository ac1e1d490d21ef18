//! `Config::implement`: a generated module that also implements the runtime's
//! `Dynamics<NX, DOF>` trait (`runtime/src/module.rs`), so that code over generated modules
//! (firmware, the test harnesses) is written once, generically, whatever the module's kind.
//!
//! The module gets a struct `Module` (a unit struct, or `Module(pub Params)` when it has
//! run-time parameters) and `impl <path>::Dynamics<NX, DOF> for Module`, each method a call of
//! the module's free function of the same name. The impl is read off the module's own items
//! (which public functions it has, whether each returns a `Result` and takes `&Params`), so it
//! follows the kinds' templates without a second copy of their rules; [`check`] refuses, before
//! generating, a scene that leaves out a function the trait needs.
//!
//! The scalar type is the generation's ([`crate::emit::real`]).

use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

use crate::spec::frame_ident;
use crate::spec::{Kind, Mechanism, Scene};

/// The functions every implementing module must have (a tree has identities for the rest;
/// the kinematics the others always emit are not listed).
const NEEDED: [&str; 5] = [
    "mass_matrix",
    "inverse_dynamics",
    "forward_dynamics",
    "actuator_mass_matrix",
    "actuator_rates",
];

/// `Err` when `scene` leaves out a function the trait needs (with `implement` set).
pub(crate) fn check(mechanism: &Mechanism, scene: &Scene) -> Result<(), String> {
    let kind = mechanism.kind();
    let missing: Vec<&str> = NEEDED
        .into_iter()
        // A tree's `actuator_mass_matrix` is its `mass_matrix`; closed loops emit it with
        // `mass_matrix`.
        .filter(|f| !(*f == "actuator_mass_matrix" && kind != Kind::Parallel))
        // A tree's `actuator_rates` is the identity; closed loops always emit it.
        .filter(|f| !(*f == "actuator_rates" && kind != Kind::Parallel))
        .filter(|f| !scene.functions.wants(kind, f))
        .collect();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "`implement` (the `Dynamics` trait) needs {}, which `[scene] functions` leaves out",
            missing
                .iter()
                .map(|f| format!("`{f}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    }
}

/// One public function of the module, as the impl calls it.
struct Callee {
    /// Returns `Result<…>` (else the impl wraps it in `Ok`).
    fallible: bool,
    /// Takes `p: &Params` last.
    params: bool,
}

/// What the impl needs to know of the module's items.
struct Items {
    fns: Vec<(String, Callee)>,
    consts: Vec<String>,
    types: Vec<String>,
    /// The values of `FRAME_NAMES` (the frames' names as the spec writes them).
    frames: Vec<String>,
}

impl Items {
    fn read(module: &TokenStream) -> Items {
        let file: syn::File = match syn::parse2(module.clone()) {
            Ok(f) => f,
            Err(e) => panic!("internal error: generated tokens do not parse: {e}"),
        };
        let mut items = Items {
            fns: Vec::new(),
            consts: Vec::new(),
            types: Vec::new(),
            frames: Vec::new(),
        };
        let public = |v: &syn::Visibility| matches!(v, syn::Visibility::Public(_));
        for item in &file.items {
            match item {
                syn::Item::Fn(f) if public(&f.vis) => {
                    let fallible = match &f.sig.output {
                        syn::ReturnType::Type(_, t) => last_ident(t) == Some("Result".into()),
                        syn::ReturnType::Default => false,
                    };
                    let params = f.sig.inputs.iter().last().is_some_and(|a| match a {
                        syn::FnArg::Typed(t) => last_ident(&t.ty) == Some("Params".into()),
                        syn::FnArg::Receiver(_) => false,
                    });
                    items
                        .fns
                        .push((f.sig.ident.to_string(), Callee { fallible, params }));
                }
                syn::Item::Const(c) if public(&c.vis) => {
                    if c.ident == "FRAME_NAMES" {
                        items.frames = string_literals(&c.expr);
                    }
                    items.consts.push(c.ident.to_string());
                }
                syn::Item::Struct(s) if public(&s.vis) => items.types.push(s.ident.to_string()),
                _ => {}
            }
        }
        items
    }

    fn function(&self, name: &str) -> Option<&Callee> {
        self.fns.iter().find(|(n, _)| n == name).map(|(_, c)| c)
    }
}

/// The string literals of an array expression (`["a", "b"]`).
fn string_literals(e: &syn::Expr) -> Vec<String> {
    match e {
        syn::Expr::Array(a) => a
            .elems
            .iter()
            .filter_map(|e| match e {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) => Some(s.value()),
                _ => None,
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// The last identifier of a type path, through references (`&Params` → `Params`,
/// `Result<…>` → `Result`).
fn last_ident(ty: &syn::Type) -> Option<String> {
    match ty {
        syn::Type::Reference(r) => last_ident(&r.elem),
        syn::Type::Path(p) => p.path.segments.last().map(|s| s.ident.to_string()),
        _ => None,
    }
}

/// The struct `Module` and its `impl <runtime>::Dynamics<NX, DOF>`, for the module whose items
/// (everything but the header) are `module`; `name` is the spec's mechanism name.
pub(crate) fn items(module: &TokenStream, runtime_path: &str, name: &str) -> TokenStream {
    let real = crate::emit::real();
    let items = Items::read(module);
    let runtime: syn::Path = match syn::parse_str(runtime_path) {
        Ok(p) => p,
        Err(e) => panic!("internal error: `implement` is not a path ({runtime_path:?}): {e}"),
    };
    let has_const = |c: &str| items.consts.iter().any(|n| n == c);
    let has_type = |t: &str| items.types.iter().any(|n| n == t);
    // A tree: `x = q`, no `NX`, no `HOME`.
    let tree = !has_const("NX");
    let nx = if tree { quote!(DOF) } else { quote!(NX) };
    let home = if has_const("HOME") {
        quote!(HOME)
    } else {
        quote!([0.0; DOF])
    };
    let no_convergence = if has_type("NoConvergence") {
        quote!(NoConvergence)
    } else {
        quote!(core::convert::Infallible)
    };
    let params = has_type("Params");
    let (module_struct, p) = module_struct(runtime_path, params);
    let calls = Calls {
        items: &items,
        tree,
        p: &p,
    };
    let or_tree = |f, args, identity| calls.or_tree(f, args, identity);
    let need = |f, args| calls.need(f, args);
    let inverse_kinematics = or_tree("inverse_kinematics", quote!(x), quote!(Ok(*x)));
    let forward_kinematics = or_tree(
        "forward_kinematics",
        quote!(q, guess),
        quote!(let _ = guess; Ok(*q)),
    );
    let actuator_rates = or_tree("actuator_rates", quote!(x, u), quote!(let _ = x; Ok(*u)));
    let inverse_dynamics = need("inverse_dynamics", quote!(x, u, ud));
    let mass_matrix = need("mass_matrix", quote!(x));
    let actuator_mass_matrix = or_tree("actuator_mass_matrix", quote!(x), mass_matrix.clone());
    let forward_dynamics = need("forward_dynamics", quote!(x, u, tau));
    // The functions of some kinds only: `Some` where the module has them.
    let optional = |f, args, sig| calls.optional(f, args, sig);
    let joint_rates = optional(
        "joint_rates",
        quote!(x, u),
        quote! {
            fn joint_rates(&self, x: &[#real; #nx], u: &[#real; DOF])
                -> Option<Result<[#real; #nx], Singular>>
        },
    );
    // The split of the efforts: `Result`s in every kind (a tree's are infallible: `Ok`).
    let fallible = |f, args, sig| calls.optional_result(f, args, sig);
    let coriolis = fallible(
        "coriolis",
        quote!(x, u),
        quote! {
            fn coriolis(&self, x: &[#real; #nx], u: &[#real; DOF])
                -> Option<Result<[#real; DOF], Singular>>
        },
    );
    let gravity = fallible(
        "gravity",
        quote!(x),
        quote! {
            fn gravity(&self, x: &[#real; #nx]) -> Option<Result<[#real; DOF], Singular>>
        },
    );
    // A tree's `friction` takes the speeds only (`friction(qd)`).
    let (friction_args, friction_x) = if tree {
        (quote!(u), quote!(_))
    } else {
        (quote!(x, u), quote!(x))
    };
    let friction = fallible(
        "friction",
        friction_args,
        quote! {
            fn friction(&self, #friction_x: &[#real; #nx], u: &[#real; DOF])
                -> Option<Result<[#real; DOF], Singular>>
        },
    );
    let id_derivatives = fallible(
        "inverse_dynamics_derivatives",
        quote!(x, u, ud),
        quote! {
            #[allow(clippy::type_complexity)]
            fn inverse_dynamics_derivatives(
                &self,
                x: &[#real; #nx],
                u: &[#real; DOF],
                ud: &[#real; DOF],
            ) -> Option<Result<([[#real; DOF]; DOF], [[#real; DOF]; DOF]), Singular>>
        },
    );
    let fd_derivatives = optional(
        "forward_dynamics_derivatives",
        quote!(x, u, tau),
        quote! {
            #[allow(clippy::type_complexity)]
            fn forward_dynamics_derivatives(
                &self,
                x: &[#real; #nx],
                u: &[#real; DOF],
                tau: &[#real; DOF],
            ) -> Option<Result<([[#real; DOF]; DOF], [[#real; DOF]; DOF], [[#real; DOF]; DOF]), Singular>>
        },
    );
    let frames = calls.frames(&real, &nx);
    quote! {
        #module_struct
        impl #runtime::Dynamics<#nx, DOF> for Module {
            type Scalar = #real;
            type Singular = Singular;
            type NoConvergence = #no_convergence;
            const NAME: &'static str = #name;
            const HOME: [#real; #nx] = #home;
            fn inverse_kinematics(&self, x: &[#real; #nx]) -> Result<[#real; DOF], Singular> {
                #inverse_kinematics
            }
            fn forward_kinematics(
                &self,
                q: &[#real; DOF],
                guess: &[#real; #nx],
            ) -> Result<[#real; #nx], #no_convergence> {
                #forward_kinematics
            }
            fn actuator_rates(&self, x: &[#real; #nx], u: &[#real; DOF]) -> Result<[#real; DOF], Singular> {
                #actuator_rates
            }
            fn inverse_dynamics(
                &self,
                x: &[#real; #nx],
                u: &[#real; DOF],
                ud: &[#real; DOF],
            ) -> Result<[#real; DOF], Singular> {
                #inverse_dynamics
            }
            fn mass_matrix(&self, x: &[#real; #nx]) -> Result<[[#real; DOF]; DOF], Singular> {
                #mass_matrix
            }
            fn actuator_mass_matrix(&self, x: &[#real; #nx]) -> Result<[[#real; DOF]; DOF], Singular> {
                #actuator_mass_matrix
            }
            fn forward_dynamics(
                &self,
                x: &[#real; #nx],
                u: &[#real; DOF],
                tau: &[#real; DOF],
            ) -> Result<[#real; DOF], Singular> {
                #forward_dynamics
            }
            #joint_rates
            #coriolis
            #gravity
            #friction
            #id_derivatives
            #fd_derivatives
            #frames
        }
    }
}

/// `pub struct Module` (holding the run-time parameters when the module has them) and what a
/// method passes for them.
fn module_struct(runtime_path: &str, params: bool) -> (TokenStream, TokenStream) {
    let doc = format!(
        " This module as an implementation of `{runtime_path}::Dynamics`: each method calls"
    );
    if params {
        (
            quote! {
                #[doc = #doc]
                /// the free function of the same name, with these run-time parameters where it
                /// takes them.
                #[derive(Clone, Copy, Debug, PartialEq)]
                pub struct Module(pub Params);
            },
            quote!(&self.0),
        )
    } else {
        (
            quote! {
                #[doc = #doc]
                /// the free function of the same name.
                #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
                pub struct Module;
            },
            quote!(),
        )
    }
}

/// The methods' bodies: calls of the module's free functions.
struct Calls<'a> {
    items: &'a Items,
    /// A tree (`x = q`): identities where it has no function.
    tree: bool,
    /// What a method passes for the run-time parameters.
    p: &'a TokenStream,
}

impl Calls<'_> {
    /// The call of free function `f` with `args` (and the parameters), as a `Result`.
    fn call(&self, f: &str, args: TokenStream) -> Option<TokenStream> {
        let c = self.items.function(f)?;
        let id = Ident::new(f, Span::call_site());
        let p = self.p;
        let args = if c.params { quote!(#args, #p) } else { args };
        Some(if c.fallible {
            quote!(#id(#args))
        } else {
            quote!(Ok(#id(#args)))
        })
    }

    /// [`Calls::call`] of a function every module has.
    fn need(&self, f: &str, args: TokenStream) -> TokenStream {
        match self.call(f, args) {
            Some(t) => t,
            None => panic!("internal error: `implement` needs `{f}` (see implement::check)"),
        }
    }

    /// [`Calls::call`], or for a tree without `f`, `identity`.
    fn or_tree(&self, f: &str, args: TokenStream, identity: TokenStream) -> TokenStream {
        match self.call(f, args) {
            Some(t) => t,
            None if self.tree => identity,
            None => panic!("internal error: `implement` needs `{f}` (see implement::check)"),
        }
    }

    /// [`Calls::optional`] for a method that returns `Option<Result<…>>`: an infallible `f`
    /// is wrapped in `Ok`.
    fn optional_result(&self, f: &str, args: TokenStream, sig: TokenStream) -> TokenStream {
        let Some(c) = self.items.function(f) else {
            return quote!();
        };
        let id = Ident::new(f, Span::call_site());
        let p = self.p;
        let args = if c.params { quote!(#args, #p) } else { args };
        let call = if c.fallible {
            quote!(#id(#args))
        } else {
            quote!(Ok(#id(#args)))
        };
        quote! {
            #sig {
                Some(#call)
            }
        }
    }

    /// `FRAME_NAMES` and the frame methods, each a `match` over the frames' indices calling
    /// frame `F`'s function (`F` the name in lower snake case, [`frame_ident`]): the pose
    /// `F_pose_at` (closed loops, at `x`) or `F_pose`, `F_jacobian`, and `F_jacobian_dot_qd`
    /// (trees) or `F_jacobian_dot_u` (platforms); `None` for an index out of range or a
    /// function the module does not have. Nothing without frames (the trait's defaults).
    fn frames(&self, real: &Ident, nx: &TokenStream) -> TokenStream {
        if self.items.frames.is_empty() {
            return quote!();
        }
        let arms = |suffixes: &[&str], args: TokenStream| -> Vec<TokenStream> {
            let mut arms = Vec::new();
            for (i, name) in self.items.frames.iter().enumerate() {
                let f = frame_ident(name);
                let call = suffixes
                    .iter()
                    .find_map(|s| self.call(&format!("{f}_{s}"), args.clone()));
                if let Some(call) = call {
                    let i = proc_macro2::Literal::usize_unsuffixed(i);
                    arms.push(quote!(#i => Some(#call),));
                }
            }
            arms
        };
        let method = |arms: Vec<TokenStream>, sig: TokenStream| {
            if arms.is_empty() {
                quote!()
            } else {
                quote! {
                    #sig {
                        match frame {
                            #(#arms)*
                            _ => None,
                        }
                    }
                }
            }
        };
        let pose = method(
            arms(&["pose_at", "pose"], quote!(x)),
            quote! {
                #[allow(clippy::type_complexity)]
                fn frame_pose(&self, frame: usize, x: &[#real; #nx])
                    -> Option<Result<([[#real; 3]; 3], [#real; 3]), Singular>>
            },
        );
        let jacobian = method(
            arms(&["jacobian"], quote!(x)),
            quote! {
                fn frame_jacobian(&self, frame: usize, x: &[#real; #nx])
                    -> Option<Result<[[#real; DOF]; 6], Singular>>
            },
        );
        let jacobian_dot = method(
            arms(&["jacobian_dot_qd", "jacobian_dot_u"], quote!(x, u)),
            quote! {
                fn frame_jacobian_dot(&self, frame: usize, x: &[#real; #nx], u: &[#real; DOF])
                    -> Option<Result<[#real; 6], Singular>>
            },
        );
        quote! {
            const FRAME_NAMES: &'static [&'static str] = &FRAME_NAMES;
            #pose
            #jacobian
            #jacobian_dot
        }
    }

    /// The method `sig` returning `Some(f(args))` where the module has `f`, else nothing (the
    /// trait's default, `None`).
    fn optional(&self, f: &str, args: TokenStream, sig: TokenStream) -> TokenStream {
        let Some(c) = self.items.function(f) else {
            return quote!();
        };
        let id = Ident::new(f, Span::call_site());
        let p = self.p;
        let args = if c.params { quote!(#args, #p) } else { args };
        quote! {
            #sig {
                Some(#id(#args))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    const SPEC: &str = r#"
[mechanism]
name = "pendulum"
[[body]]
name = "rod"
mass = 1.0
com = [0.5, 0.0, 0.0]
[[joint]]
name = "j1"
kind = "revolute"
parent = "base"
child = "rod"
axis = [0.0, 1.0, 0.0]
"#;

    fn compile(scene: &str) -> Result<String, String> {
        let cfg = crate::Config {
            implement: Some("runtime".into()),
            ..crate::Config::default()
        };
        crate::compile("p.toml", &format!("{SPEC}{scene}"), &cfg)
            .map(|g| g.code)
            .map_err(|d| d.to_string())
    }

    #[test]
    fn a_scene_without_the_traits_functions_is_refused() {
        let err = compile("[scene]\nfunctions = [\"inverse_dynamics\"]\n").unwrap_err();
        assert!(err.contains("`mass_matrix`, `forward_dynamics`"), "{err}");
        assert!(!err.contains("actuator_mass_matrix"), "{err}");
        let code = compile("").expect("the default scene has every function");
        assert!(code.contains("impl runtime::Dynamics<DOF, DOF> for Module"));
        assert!(code.contains("const NAME: &'static str = \"pendulum\";"));
    }

    /// A platform without `actuator_rates` (which the impl calls) is refused at the scene, not
    /// with an internal error while generating.
    #[test]
    fn a_platform_without_actuator_rates_is_refused() {
        let spec = include_str!("../../mechanisms/specs/planar_five_bar.toml");
        let cfg = crate::Config {
            implement: Some("runtime".into()),
            ..crate::Config::default()
        };
        let scene = "[scene]\nfunctions = [\"inverse_dynamics\", \"mass_matrix\", \"actuator_mass_matrix\", \"forward_dynamics\"]\n\n[mechanism]";
        let src = spec.replacen("[mechanism]", scene, 1);
        let err = crate::compile("f.toml", &src, &cfg)
            .unwrap_err()
            .to_string();
        assert!(err.contains("needs `actuator_rates`"), "{err}");
        let src = src.replace(
            "\"forward_dynamics\"]",
            "\"forward_dynamics\", \"actuator_rates\"]",
        );
        assert!(crate::compile("f.toml", &src, &cfg).is_ok());
    }

    /// Each call in the impl passes the free function as many arguments as it takes: a tree's
    /// `friction(qd)` was called as `friction(x, u)`, so a tree with friction and `implement`
    /// did not compile (found by building the docs' `mechanism!(…, implement = "runtime",
    /// friction = true)`).
    #[test]
    fn the_impl_calls_a_trees_friction_with_its_arguments() {
        for scene in [
            "[scene]\nfriction = true\n",
            "[scene]\nfriction = true\nparameters = \"runtime\"\n",
        ] {
            let code = compile(&format!("damping = 0.1\n{scene}")).unwrap();
            let file: syn::File = syn::parse_str(&code).unwrap();
            let arity = |name: &str| {
                file.items.iter().find_map(|i| match i {
                    syn::Item::Fn(f) if f.sig.ident == name => Some(f.sig.inputs.len()),
                    _ => None,
                })
            };
            let mut calls = 0;
            for item in &file.items {
                let syn::Item::Impl(imp) = item else { continue };
                for it in &imp.items {
                    let syn::ImplItem::Fn(m) = it else { continue };
                    let text = quote::quote!(#m).to_string();
                    let name = m.sig.ident.to_string();
                    let Some(n) = arity(&name) else { continue };
                    // The call `name (a , b)` in the method's body.
                    let call = format!("{name} (");
                    let Some(at) = text.rfind(&call) else {
                        continue;
                    };
                    let args = &text[at + call.len()..];
                    let args = &args[..args.find(')').unwrap()];
                    assert_eq!(args.split(',').count(), n, "{scene}: {text}");
                    calls += 1;
                }
            }
            assert!(calls >= 8, "{scene}: {calls} calls checked");
            assert!(code.contains("fn friction"), "{scene}");
        }
    }
}
