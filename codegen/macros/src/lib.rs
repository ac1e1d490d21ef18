//! `mechanism!`: nocdyn's generator as a proc macro. A mechanism spec goes in; the items of its
//! generated dynamics module come out, in place, at compile time.
//!
//! ```ignore
//! // In a crate beside `mechanisms/` (the path is relative to that crate's Cargo.toml):
//! pub mod puma { nocdyn_macros::mechanism!("../mechanisms/specs/puma560.toml"); }
//!
//! let tau = puma::inverse_dynamics(&q, &qd, &qdd);   // [f64; 6], N·m
//! ```
//!
//! The expansion is the module the CLI prints and `codegen::build_script::Builder` writes for
//! the same spec and options, byte for byte (the text is produced by
//! `codegen::macro_support::expand`, and `codegen/tests/identical.rs` compares the three on every
//! bundled spec). See the repository's README for the generated functions.
//!
//! # Arguments
//!
//! ```text
//! mechanism!("SPEC.toml" | "SPEC.urdf" [, math = "libm" | "std" | "runtime"] [, runtime_path = "P"] [, float = "f64" | "f32"]
//!            [, implement = "P"] [, friction = true] [, rotor_inertia = true] [, snap = 1e-4]
//!            [, fma = true] [, lanes = 4] [, vector_sin_cos = true] [, batch_sin_cos = true]
//!            [, wide = "wide"])
//! ```
//!
//! - The path is relative to the calling crate's `CARGO_MANIFEST_DIR` (its `Cargo.toml`
//!   directory), not to the source file; an absolute path is used as it is.
//! - `math` (default `"libm"`) is the CLI's `--math`: where `sin_cos` and `sqrt` come from.
//! - `float` (default `"f64"`) is the CLI's `--float`: the scalar type of the generated code.
//! - `implement`, `friction`, `rotor_inertia` and `snap` are the CLI's `--implement` (with its
//!   `--runtime-path`: the runtime crate's path as the calling crate names it), `--friction`,
//!   `--rotor-inertia` and `--snap TOL` (and `Builder`'s methods of the same names).
//! - `fma`, `lanes` and `vector_sin_cos` are the CLI's `--fma` (fused multiply–adds), `--lanes N`
//!   (`_lanes` functions of `N` states per call; trees) and `--vector-sin-cos` (with `lanes`:
//!   `sin` and `cos` of all lanes at once), and `batch_sin_cos` the CLI's `--batch-sin-cos` (a
//!   scalar function's joint angles in one call), `Config`'s fields of the same names; `wide` (with
//!   `lanes`) is `Config::wide`: the lanes' arithmetic through the `wide` crate, which the
//!   calling crate names as given and depends on.
//!   - `"libm"`: the calling crate needs the `libm` crate as a dependency (`libm = "0.2"`); the
//!     code is `no_std`.
//!   - `"std"`: `f64::sin_cos` from std.
//!   - `"runtime"`: `<runtime_path>::math` of nocdyn's `runtime` crate; `runtime_path` (only with
//!     `math = "runtime"`) is its path as the calling crate names it, `"runtime"` by default.
//!
//! # Rebuilds
//!
//! Besides the generated items, the expansion holds one unnamed constant,
//! `const _: &[u8] = ::core::include_bytes!("/absolute/path/to/spec.toml");`. It puts the spec
//! into the crate's dependency info, so cargo recompiles the crate, and the macro runs again,
//! whenever the spec changes. It is the only absolute path in the expansion: the generated items
//! contain no paths. Nothing of it reaches the binary, since nothing refers to the constant.
//!
//! # Errors
//!
//! An invalid spec becomes a `compile_error!` at the string literal. Its text is the CLI's
//! rendered diagnostics (`Diagnostics::render`: the file as the literal names it, line, column,
//! key and hint), so the compiler prints what `codegen SPEC` prints (indenting its continuation
//! lines), followed by the place of the call:
//!
//! ```text
//! error: negative mass -1.5
//!          --> tests/ui/negative_mass.toml:6:8
//!          |
//!        6 | mass = -1.5
//!          |        ^^^^ body "link1".mass
//!          |
//!          = hint: a mass is in kg and must be >= 0 (0 for a massless body)
//!  --> tests/ui/negative_mass.rs:3:31
//!   |
//! 3 |     nocdyn_macros::mechanism!("tests/ui/negative_mass.toml");
//!   |                               ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^
//! ```
//!
//! A file that cannot be read gives `cannot read <path>: <reason>` at the same place, as the CLI
//! does. Warnings (such as a normalized axis) are not shown, as `build_script` does not show
//! them; `codegen --check SPEC` lists them.
//!
//! # Example
//!
//! ```
//! // This crate's Cargo.toml is in codegen/macros, two levels below the bundled specs.
//! mod arm {
//!     nocdyn_macros::mechanism!("../../mechanisms/specs/planar_2r.toml");
//! }
//! mod arm_std {
//!     nocdyn_macros::mechanism!("../../mechanisms/specs/planar_2r.toml", math = "std");
//! }
//!
//! let q = [0.3, -0.2];
//! assert_eq!(arm::DOF, 2);
//! let tau = arm::inverse_dynamics(&q, &[0.0; 2], &[0.0; 2]);   // = gravity(q): holds it still
//! for (a, b) in tau.iter().zip(arm_std::gravity(&q)) {
//!     assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0));
//! }
//! ```

use std::path::PathBuf;

use codegen::{Config, MathBackend, macro_support};
use proc_macro2::TokenStream;
use quote::quote;
use syn::parse::{Parse, ParseStream};
use syn::{Error, Ident, Lit, LitBool, LitStr, Token};

/// Expands to the items of the generated dynamics module of a mechanism spec; see the crate
/// docs.
#[proc_macro]
pub fn mechanism(input: proc_macro::TokenStream) -> proc_macro::TokenStream {
    expand(input.into())
        .unwrap_or_else(Error::into_compile_error)
        .into()
}

/// `"spec" [, key = value]*`.
struct Args {
    spec: LitStr,
    math: Option<LitStr>,
    runtime_path: Option<LitStr>,
    float: Option<LitStr>,
    implement: Option<LitStr>,
    friction: Option<LitBool>,
    rotor_inertia: Option<LitBool>,
    snap: Option<Lit>,
    fma: Option<LitBool>,
    lanes: Option<syn::LitInt>,
    vector_sin_cos: Option<LitBool>,
    batch_sin_cos: Option<LitBool>,
    wide: Option<LitStr>,
}

/// The options and the kind of literal each takes.
const OPTIONS: &str = "`math`, `runtime_path`, `float`, `implement`, `wide` (strings), `friction`, `rotor_inertia`, `fma`, `vector_sin_cos`, `batch_sin_cos` (`true` or `false`), `snap` (a number) or `lanes` (an integer)";

impl Parse for Args {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let spec: LitStr = input.parse()?;
        let mut args = Args {
            spec,
            math: None,
            runtime_path: None,
            float: None,
            implement: None,
            friction: None,
            rotor_inertia: None,
            snap: None,
            fma: None,
            lanes: None,
            vector_sin_cos: None,
            batch_sin_cos: None,
            wide: None,
        };
        while !input.is_empty() {
            input.parse::<Token![,]>()?;
            if input.is_empty() {
                break;
            }
            let key: Ident = input.parse()?;
            input.parse::<Token![=]>()?;
            let value: Lit = input.parse()?;
            let twice = || Error::new(key.span(), format!("`{key}` is given twice"));
            let wrong = |what: &str| Error::new(value.span(), format!("`{key}` takes {what}"));
            match (key.to_string().as_str(), &value) {
                (
                    name @ ("math" | "runtime_path" | "float" | "implement" | "wide"),
                    Lit::Str(v),
                ) => {
                    let slot = match name {
                        "math" => &mut args.math,
                        "runtime_path" => &mut args.runtime_path,
                        "float" => &mut args.float,
                        "wide" => &mut args.wide,
                        _ => &mut args.implement,
                    };
                    if slot.replace(v.clone()).is_some() {
                        return Err(twice());
                    }
                }
                ("math" | "runtime_path" | "float" | "implement" | "wide", _) => {
                    return Err(wrong("a string"));
                }
                (
                    name @ ("friction" | "rotor_inertia" | "fma" | "vector_sin_cos"
                    | "batch_sin_cos"),
                    Lit::Bool(v),
                ) => {
                    let slot = match name {
                        "friction" => &mut args.friction,
                        "rotor_inertia" => &mut args.rotor_inertia,
                        "fma" => &mut args.fma,
                        "batch_sin_cos" => &mut args.batch_sin_cos,
                        _ => &mut args.vector_sin_cos,
                    };
                    if slot.replace(v.clone()).is_some() {
                        return Err(twice());
                    }
                }
                ("friction" | "rotor_inertia" | "fma" | "vector_sin_cos" | "batch_sin_cos", _) => {
                    return Err(wrong("`true` or `false`"));
                }
                ("lanes", Lit::Int(v)) => {
                    if args.lanes.replace(v.clone()).is_some() {
                        return Err(twice());
                    }
                }
                ("lanes", _) => return Err(wrong("an integer (states per call)")),
                ("snap", Lit::Float(_) | Lit::Int(_)) => {
                    if args.snap.replace(value.clone()).is_some() {
                        return Err(twice());
                    }
                }
                ("snap", _) => return Err(wrong("a number (the tolerance)")),
                (other, _) => {
                    return Err(Error::new(
                        key.span(),
                        format!("unknown option `{other}`: expected {OPTIONS}"),
                    ));
                }
            }
        }
        Ok(args)
    }
}

impl Args {
    /// The generation options, as the CLI's `--math` and `--runtime-path` map them.
    fn config(&self) -> syn::Result<Config> {
        let math = match &self.math {
            None => MathBackend::Libm,
            Some(m) => match m.value().as_str() {
                "libm" => MathBackend::Libm,
                "std" => MathBackend::Std,
                "runtime" => MathBackend::Runtime(
                    self.runtime_path
                        .as_ref()
                        .map_or_else(|| "runtime".to_owned(), LitStr::value),
                ),
                other => {
                    return Err(Error::new(
                        m.span(),
                        format!(
                            "unknown math backend \"{other}\": \
                             expected \"libm\", \"std\" or \"runtime\""
                        ),
                    ));
                }
            },
        };
        if let Some(p) = &self.runtime_path
            && !matches!(math, MathBackend::Runtime(_))
        {
            return Err(Error::new(
                p.span(),
                "`runtime_path` needs `math = \"runtime\"`",
            ));
        }
        let float = match &self.float {
            None => codegen::Float::F64,
            Some(f) => match f.value().as_str() {
                "f64" => codegen::Float::F64,
                "f32" => codegen::Float::F32,
                other => {
                    return Err(Error::new(
                        f.span(),
                        format!("unknown float type \"{other}\": expected \"f64\" or \"f32\""),
                    ));
                }
            },
        };
        let mut snap = None;
        if let Some(lit) = &self.snap {
            let tol: f64 = match lit {
                Lit::Float(f) => f.base10_parse()?,
                Lit::Int(i) => i.base10_parse::<u64>()? as f64,
                _ => unreachable!("checked when parsed"),
            };
            if !codegen::spec::is_snap_tolerance(tol) {
                return Err(Error::new(
                    lit.span(),
                    format!(
                        "the snap tolerance must be in (0, {}] (as `[scene] snap`)",
                        codegen::spec::MAX_SNAP
                    ),
                ));
            }
            snap = Some(tol);
        }
        let scene = codegen::spec::SceneOverrides {
            friction: self.friction.as_ref().is_some_and(LitBool::value),
            rotor_inertia: self.rotor_inertia.as_ref().is_some_and(LitBool::value),
            snap,
            // A URDF's `ROBOT.scene.toml` beside it is read by `macro_support::expand`.
            sidecar: None,
            omit: Vec::new(),
        };
        if let Some(p) = &self.implement
            && syn::parse_str::<syn::Path>(&p.value()).is_err()
        {
            return Err(Error::new(
                p.span(),
                "`implement` takes the runtime crate's path (e.g. \"runtime\")",
            ));
        }
        let lanes = match &self.lanes {
            None => None,
            Some(l) => {
                let n: usize = l.base10_parse()?;
                if !(2..=codegen::lanes::MAX).contains(&n) {
                    return Err(Error::new(
                        l.span(),
                        format!("`lanes` takes 2 to {} states per call", codegen::lanes::MAX),
                    ));
                }
                Some(n)
            }
        };
        let vector_sin_cos = self.vector_sin_cos.as_ref().is_some_and(LitBool::value);
        if let Some(v) = &self.vector_sin_cos
            && vector_sin_cos
            && lanes.is_none()
        {
            return Err(Error::new(
                v.span(),
                "`vector_sin_cos` is for the `_lanes` functions: set `lanes` too",
            ));
        }
        Ok(Config {
            math,
            float,
            scene,
            implement: self.implement.as_ref().map(LitStr::value),
            emit: codegen::Emit::Rust,
            fma: self.fma.as_ref().is_some_and(LitBool::value),
            lanes,
            vector_sin_cos,
            batch_sin_cos: self.batch_sin_cos.as_ref().is_some_and(LitBool::value),
            wide: self.wide.as_ref().map(LitStr::value),
        })
    }
}

fn expand(input: TokenStream) -> syn::Result<TokenStream> {
    let args: Args = syn::parse2(input)?;
    let cfg = args.config()?;
    let span = args.spec.span();
    let spec = args.spec.value();
    let manifest_dir = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .or_else(|| std::env::current_dir().ok())
        .unwrap_or_default();
    let code = macro_support::expand(&manifest_dir, &spec, &cfg)
        .map_err(|msg| Error::new(span, compile_error_message(&msg)))?;
    let items: TokenStream = code.parse().map_err(|e| {
        Error::new(
            span,
            format!("nocdyn internal error: the generated code does not parse ({e})"),
        )
    })?;
    let path = macro_support::resolve(&manifest_dir, &spec);
    let path = path
        .to_str()
        .ok_or_else(|| Error::new(span, "the spec's path is not valid UTF-8"))?;
    let track = LitStr::new(path, span);
    Ok(quote! {
        #items
        // Makes cargo rebuild this crate when the spec changes.
        const _: &[u8] = ::core::include_bytes!(#track);
    })
}

/// The compiler prints a `compile_error!` as `error: <message>`, and rendered diagnostics start
/// with their own `error: `: drop it (and the trailing newline), so that what the compiler prints
/// is exactly what the CLI prints.
fn compile_error_message(rendered: &str) -> &str {
    let message = rendered.trim_end();
    message.strip_prefix("error: ").unwrap_or(message)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(tokens: TokenStream) -> syn::Result<Args> {
        syn::parse2(tokens)
    }

    fn math(tokens: TokenStream) -> Result<MathBackend, String> {
        parse(tokens)
            .and_then(|a| a.config())
            .map(|c| c.math)
            .map_err(|e| e.to_string())
    }

    #[test]
    fn scene_options_map_to_the_cli_flags() {
        let cfg = parse(quote!(
            "a.urdf",
            friction = true,
            rotor_inertia = true,
            snap = 1e-4,
            implement = "runtime"
        ))
        .and_then(|a| a.config())
        .unwrap();
        assert!(cfg.scene.friction && cfg.scene.rotor_inertia);
        assert_eq!(cfg.scene.snap, Some(1e-4));
        assert_eq!(cfg.implement.as_deref(), Some("runtime"));
        let off = parse(quote!("a.toml", friction = false))
            .and_then(|a| a.config())
            .unwrap();
        assert!(!off.scene.friction && off.scene.snap.is_none() && off.implement.is_none());
        let err = |t: TokenStream| match parse(t).and_then(|a| a.config()) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err(quote!("a.toml", friction = "yes")).contains("`true` or `false`"));
        assert!(err(quote!("a.toml", snap = 0.5)).contains("snap tolerance"));
        assert!(err(quote!("a.toml", snap = "1e-4")).contains("a number"));
        assert!(err(quote!("a.toml", implement = "not a path")).contains("runtime crate's path"));
        assert!(err(quote!("a.toml", snap = 1e-4, snap = 1e-5)).contains("twice"));
        assert!(err(quote!("a.toml", speed = 1)).contains("unknown option"));
    }

    #[test]
    fn options_map_to_the_cli_backends() {
        assert_eq!(math(quote!("a.toml")), Ok(MathBackend::Libm));
        assert_eq!(math(quote!("a.toml",)), Ok(MathBackend::Libm));
        assert_eq!(math(quote!("a.toml", math = "libm")), Ok(MathBackend::Libm));
        assert_eq!(math(quote!("a.urdf", math = "std")), Ok(MathBackend::Std));
        assert_eq!(
            math(quote!("a.toml", math = "runtime")),
            Ok(MathBackend::Runtime("runtime".into()))
        );
        assert_eq!(
            math(quote!("a.toml", runtime_path = "::rt", math = "runtime",)),
            Ok(MathBackend::Runtime("::rt".into()))
        );
        assert_eq!(parse(quote!("a.toml")).unwrap().spec.value(), "a.toml");
    }

    #[test]
    fn compile_errors_read_like_the_cli() {
        let rendered = "error: negative mass -1.5\n  --> a.toml:6:8\n  |\n\n";
        assert_eq!(
            compile_error_message(rendered),
            "negative mass -1.5\n  --> a.toml:6:8\n  |"
        );
        let io = "cannot read a.toml: No such file or directory (os error 2)";
        assert_eq!(compile_error_message(io), io);
    }

    #[test]
    fn bad_options_are_rejected() {
        for (tokens, expected) in [
            (quote!(), "expected string literal"),
            (quote!(a.toml), "expected string literal"),
            (
                quote!("a.toml", math = "f32"),
                "unknown math backend \"f32\"",
            ),
            (quote!("a.toml", maths = "std"), "unknown option `maths`"),
            (
                quote!("a.toml", math = "std", math = "std"),
                "`math` is given twice",
            ),
            (quote!("a.toml", math = std), "expected literal"),
            (
                quote!("a.toml", runtime_path = "rt"),
                "needs `math = \"runtime\"`",
            ),
            (quote!("a.toml" "b.toml"), "expected `,`"),
        ] {
            let e = math(tokens.clone()).unwrap_err();
            assert!(e.contains(expected), "{tokens}: {e}");
        }
    }
}
