//! nocdyn generator: a mechanism spec in, a flat, allocation-free Rust module of its dynamics out.
//!
//! Data flow, one module per stage, each a pure function:
//!
//! 1. [`spec`]: TOML / URDF text → validated [`runtime::model::Model`] (or [`diag::Diagnostics`]
//!    with file, line, column and key);
//! 2. [`dynamics`]: the model → NOC quantities as nodes of a hash-consed expression DAG
//!    ([`sym`]; constants folded and shared subexpressions merged as nodes are built);
//! 3. [`schedule`](mod@schedule): per function, dead-code removal, deterministic order, operation count;
//! 4. [`emit`]: Rust tokens → `syn::File` → prettyplease text.
//!
//! [`compile`] runs them all; the CLI, build scripts and the proc macro are thin adapters.
//!
//! ```
//! let spec = r#"
//! [mechanism]
//! name = "pendulum"
//! [[body]]
//! name = "rod"
//! mass = 1.0
//! com = [0.5, 0.0, 0.0]
//! [[joint]]
//! name = "j1"
//! kind = "revolute"
//! parent = "base"
//! child = "rod"
//! axis = [0.0, 1.0, 0.0]
//! "#;
//! let out = codegen::compile("pendulum.toml", spec, &codegen::Config::default()).unwrap();
//! assert!(out.code.contains("pub fn inverse_dynamics"));
//! ```

#![allow(clippy::needless_range_loop)] // index loops read like the equations

pub mod build_script;
pub mod closed;
pub mod diag;
pub mod dynamics;
pub mod emit;
pub mod indices;
mod lu;
pub mod macro_support;
pub mod parallel;
pub mod params;
pub mod scalar;
pub mod schedule;
pub mod spec;
pub mod sym;

use dynamics::{Terms, Tree};
use emit::{Function, Shape};
use runtime::model::Model;
use schedule::{Kernel, OpCount, schedule};
use sym::{Arg, Graph};

/// Where generated code takes `sin_cos` and `sqrt` from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MathBackend {
    /// The `libm` crate (`libm::sincos`): works in `no_std`, bit-identical on every target.
    Libm,
    /// `f64::sin_cos` from std (fastest on hosts; not `no_std`).
    Std,
    /// `<path>::math::sin_cos` of the nocdyn runtime crate at `path` (e.g. `"runtime"`), which
    /// picks std or libm by its features.
    Runtime(String),
}

/// The floating-point type of the generated code.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Float {
    /// `f64` (default).
    #[default]
    F64,
    /// `f32`, for FPUs without double precision. The same equations; the thresholds of the
    /// guards and of Newton's method are rescaled to single precision (see
    /// [`runtime::scalar::f32_tolerance`]) and the math calls are the `f32` ones.
    F32,
}

/// Generation options.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Math backend for trigonometry and square roots.
    pub math: MathBackend,
    /// Scalar type of the generated code.
    pub float: Float,
    /// Scene switches on top of the spec's `[scene]` (friction, rotor inertia).
    pub scene: spec::SceneOverrides,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            math: MathBackend::Libm,
            float: Float::F64,
            scene: spec::SceneOverrides::default(),
        }
    }
}

/// A generated module.
#[derive(Clone, Debug)]
pub struct Generated {
    /// The Rust source (items only; include it with `include!`).
    pub code: String,
    /// Operation count of each function, in emission order.
    pub stats: Vec<(String, OpCount)>,
    /// Degrees of freedom.
    pub dof: usize,
    /// Warnings from the spec (e.g. an axis normalized).
    pub warnings: diag::Diagnostics,
    /// What the op-count table divides by: `"joint"` (trees) or `"DOF"` (parallel mechanisms).
    pub per: &'static str,
}

impl Generated {
    /// The op-count table (markdown), as in the module's header.
    pub fn stats_table(&self) -> Vec<String> {
        emit::stats_table_per(&self.stats, self.dof, self.per)
    }
}

/// Parse, validate and generate: the pure entry point (no I/O). `file_name` names the spec in
/// messages and picks the format (`.urdf` → URDF, otherwise TOML).
pub fn compile(
    file_name: &str,
    source: &str,
    cfg: &Config,
) -> Result<Generated, diag::Diagnostics> {
    let (mechanism, warnings) = spec::load_mechanism_with(file_name, source, &cfg.scene)?;
    let error = |msg: String| {
        let mut d = diag::Diagnostics::new(file_name, source);
        d.push(diag::Diagnostic::error(msg).with_key("platform"));
        d
    };
    // A panic while generating is a generator bug; inside someone's build it must still come
    // out as a diagnostic, not as an aborted build script or macro.
    let single = cfg.float == Float::F32;
    let generated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        scalar::with_precision(single, || match mechanism {
            spec::Mechanism::Tree(model) => {
                let only = spec::scene_functions(file_name, source);
                let params = spec::scene_params(file_name, source, &cfg.scene);
                Ok(generate_with(&model, cfg, only.as_deref(), params.as_ref()))
            }
            spec::Mechanism::Parallel(model) => {
                let only = spec::scene_functions(file_name, source);
                let params = spec::scene_params(file_name, source, &cfg.scene);
                parallel::generate_with(&model, cfg, only.as_deref(), params.as_ref())
            }
            spec::Mechanism::Closed(model) => {
                let only = spec::scene_functions(file_name, source);
                let params = spec::scene_params(file_name, source, &cfg.scene);
                closed::generate_with(&model, cfg, only.as_deref(), params.as_ref())
            }
        })
    }));
    let mut out = match generated {
        Ok(Ok(out)) => out,
        Ok(Err(msg)) => return Err(error(msg)),
        Err(_) => {
            return Err(error(
                "internal error: the generator panicked on this spec (please report it)".into(),
            ));
        }
    };
    out.warnings = warnings;
    if single {
        out.code = emit::to_f32(&out.code);
    }
    Ok(out)
}

/// The generator version written into every header.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The symbolic dynamics of a model: one expression DAG and the output nodes of each function.
pub struct Symbolic {
    /// The shared DAG.
    pub graph: Graph,
    /// Degrees of freedom.
    pub dof: usize,
    /// `I(q)`, row-major.
    pub mass_matrix: Vec<sym::ExprId>,
    /// `C(q, q̇) q̇`.
    pub coriolis: Vec<sym::ExprId>,
    /// `−γ(q)`.
    pub gravity: Vec<sym::ExprId>,
    /// `I q̈ + C q̇ − γ`.
    pub inverse_dynamics: Vec<sym::ExprId>,
    /// `I⁻¹ (τ − C q̇ + γ)` with checked pivots.
    pub forward_dynamics: Vec<sym::ExprId>,
    /// The pivot guards of `forward_dynamics`, in the order of its factorization (the other
    /// functions test nothing).
    pub forward_dynamics_guards: Vec<sym::ExprId>,
    /// Joint friction `δ(q̇)`, when some joint's drive has friction (`[scene] friction`).
    pub friction: Option<Vec<sym::ExprId>>,
}

/// Build the symbolic dynamics of a validated model.
pub fn symbolic(model: &Model) -> Symbolic {
    symbolic_with(model, None)
}

/// [`symbolic`] with run-time parameters (`[scene] parameters = "runtime"`): every output also
/// reads `Arg::P` (layout: [`dynamics::param_index`]).
pub fn symbolic_with(model: &Model, params: Option<&spec::RuntimeParams>) -> Symbolic {
    let mut tree = Tree::new(model);
    if let Some(rp) = params {
        tree = tree.with_runtime_params(rp.payload.as_ref().map(|p| p.0), rp.coulomb_velocity);
        let bodies: Vec<usize> = rp.bodies.iter().map(|b| b.body).collect();
        tree = tree.with_runtime_bodies(&bodies);
    }
    let mut g = Graph::new();
    let mm = dynamics::mass_matrix(&mut g, &tree);
    let mass_matrix: Vec<_> = mm.iter().flatten().copied().collect();
    let coriolis = dynamics::inverse_dynamics(
        &mut g,
        &tree,
        Terms {
            velocity: true,
            ..Terms::NONE
        },
    );
    let gravity = dynamics::inverse_dynamics(
        &mut g,
        &tree,
        Terms {
            gravity: true,
            ..Terms::NONE
        },
    );
    let inverse_dynamics = dynamics::inverse_dynamics(&mut g, &tree, Terms::ALL);
    debug_assert!(
        g.take_guards().is_empty(),
        "a tree function other than FD tests"
    );
    let forward_dynamics = dynamics::forward_dynamics(&mut g, &tree);
    let forward_dynamics_guards = g.take_guards();
    let friction = model
        .joints
        .iter()
        .any(|j| j.drive.viscous != 0.0 || j.drive.coulomb != 0.0)
        .then(|| {
            dynamics::inverse_dynamics(
                &mut g,
                &tree,
                Terms {
                    friction: true,
                    ..Terms::NONE
                },
            )
        });
    Symbolic {
        graph: g,
        dof: tree.dof(),
        mass_matrix,
        coriolis,
        gravity,
        inverse_dynamics,
        forward_dynamics,
        forward_dynamics_guards,
        friction,
    }
}

/// Generate the module for a validated model.
pub fn generate(model: &Model, cfg: &Config) -> Generated {
    generate_selected(model, cfg, None)
}

/// [`generate`] with only the public functions named in `only` (`[scene] functions`; `None`:
/// all of them). Functions not asked for are not emitted, so their operations cost nothing.
pub fn generate_selected(model: &Model, cfg: &Config, only: Option<&[String]>) -> Generated {
    generate_with(model, cfg, only, None)
}

/// The `Params` struct of a module with run-time parameters: fields named for the user, its
/// `DEFAULT` (the values the spec gives), and `to_array` in [`dynamics::param_index`]'s layout.
fn params_template(model: &Model, rp: &spec::RuntimeParams) -> proc_macro2::TokenStream {
    use proc_macro2::Literal;
    use quote::quote;
    let n = model.dof();
    let np = Literal::usize_unsuffixed(dynamics::param_count_with(n, rp.bodies.len()));
    let arr = |f: &dyn Fn(&runtime::model::Drive) -> f64| {
        let v: Vec<_> = model
            .joints
            .iter()
            .map(|j| emit::float_lit(f(&j.drive)))
            .collect();
        quote!([#(#v),*])
    };
    let damping = arr(&|d| d.viscous);
    let friction = arr(&|d| d.coulomb);
    let armature = arr(&|d| d.armature);
    let at = |k| Literal::usize_unsuffixed(dynamics::param_index(k, 0, n));
    let (d0, f0, a0) = (
        at(dynamics::ParamKind::Damping),
        at(dynamics::ParamKind::Friction),
        at(dynamics::ParamKind::Armature),
    );
    let (payload_fields, payload_default, payload_fill) = match &rp.payload {
        None => (quote!(), quote!(), quote!()),
        Some((b, m, c, i)) => {
            payload_params(&format!("body `{}`", model.bodies[*b].name), *m, c, i)
        }
    };
    let (body_items, body_fields, body_default, body_fill) = body_params(
        &rp.bodies,
        &|b| format!("model body `{}`", model.bodies[b].name),
        dynamics::body_param_index(0, n),
    );
    quote! {
        #body_items
        /// Number of run-time parameters in [`Params::to_array`].
        pub const NP: usize = #np;
        /// Run-time parameters (`[scene] parameters = "runtime"`): every function takes them, so
        /// one binary serves several payloads or drive calibrations. SI units.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Params {
            #payload_fields
            /// Viscous friction per joint (N·m·s/rad or N·s/m).
            pub damping: [f64; DOF],
            /// Coulomb friction level per joint (N·m or N), regularized as in the spec docs.
            pub friction: [f64; DOF],
            /// Reflected rotor inertia per joint (kg·m² or kg).
            pub armature: [f64; DOF],
            #body_fields
        }
        impl Params {
            /// The values of the spec (what a module with constants would fold in).
            pub const DEFAULT: Params = Params {
                #payload_default
                damping: #damping,
                friction: #friction,
                armature: #armature,
                #body_default
            };
            /// The flat layout the generated functions read.
            pub fn to_array(&self) -> [f64; NP] {
                let mut a = [0.0; NP];
                #payload_fill
                let mut i = 0;
                while i < DOF {
                    a[#d0 + i] = self.damping[i];
                    a[#f0 + i] = self.friction[i];
                    a[#a0 + i] = self.armature[i];
                    i += 1;
                }
                #body_fill
                a
            }
        }
        impl Default for Params {
            fn default() -> Self {
                Self::DEFAULT
            }
        }
    }
}

/// The payload's fields of a `Params` struct, their `DEFAULT` values and their part of
/// `to_array` (entries 0–9: mass, mass centre, inertia `xx, xy, xz, yy, yz, zz`); `on` names the
/// frame's owner ("body `link6`", "the platform").
pub(crate) fn payload_params(
    on: &str,
    m: f64,
    c: &runtime::model::Vec3,
    i: &runtime::model::Mat3,
) -> (
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
) {
    use quote::quote;
    let doc_m = format!(" Payload mass (kg), rigidly attached to {on}.");
    let doc_c = format!(" Payload mass centre in {on}'s frame (m).");
    let doc_i = format!(" Payload inertia about its mass centre, {on}'s axes (kg·m²), symmetric.");
    let m = emit::float_lit(m);
    let c: Vec<_> = c.iter().map(|v| emit::float_lit(*v)).collect();
    let rows: Vec<_> = i
        .iter()
        .map(|r| {
            let r: Vec<_> = r.iter().map(|v| emit::float_lit(*v)).collect();
            quote!([#(#r),*])
        })
        .collect();
    (
        quote! {
            #[doc = #doc_m]
            pub payload_mass: f64,
            #[doc = #doc_c]
            pub payload_com: [f64; 3],
            #[doc = #doc_i]
            pub payload_inertia: [[f64; 3]; 3],
        },
        quote! {
            payload_mass: #m,
            payload_com: [#(#c),*],
            payload_inertia: [#(#rows),*],
        },
        quote! {
            a[0] = self.payload_mass;
            a[1] = self.payload_com[0];
            a[2] = self.payload_com[1];
            a[3] = self.payload_com[2];
            a[4] = self.payload_inertia[0][0];
            a[5] = self.payload_inertia[0][1];
            a[6] = self.payload_inertia[0][2];
            a[7] = self.payload_inertia[1][1];
            a[8] = self.payload_inertia[1][2];
            a[9] = self.payload_inertia[2][2];
        },
    )
}

/// The run-time bodies' items of a module (`[scene] runtime_inertia`; nothing without any):
/// `NB` and `RUNTIME_BODY_NAMES` (outside `Params`), the fields `body_mass`, `body_com` and
/// `body_inertia` of `Params`, their `DEFAULT` values and their part of `to_array` (ten entries
/// per body from `base`, ordered as the payload's). `frame` names the owner of the frame of a
/// model body ("model body `link6`", "the platform").
pub(crate) fn body_params(
    bodies: &[spec::RuntimeBody],
    frame: &dyn Fn(usize) -> String,
    base: usize,
) -> (
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
    proc_macro2::TokenStream,
) {
    use proc_macro2::Literal;
    use quote::quote;
    if bodies.is_empty() {
        return (quote!(), quote!(), quote!(), quote!());
    }
    let nb = Literal::usize_unsuffixed(bodies.len());
    let base = Literal::usize_unsuffixed(base);
    let names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
    let mut names_doc = vec![
        " The bodies whose inertial parameters are run-time parameters (`[scene] runtime_inertia`), \
         in the order of `Params::body_mass`, `body_com` and `body_inertia`. Each body's mass \
         centre and inertia are in the frame of the model body it is part of (after fixed-joint \
         merging):"
            .to_string(),
    ];
    for (k, b) in bodies.iter().enumerate() {
        names_doc.push(format!(" {k}. `{}`: {}.", b.name, frame(b.body)));
    }
    let mass: Vec<_> = bodies.iter().map(|b| emit::float_lit(b.mass)).collect();
    let com: Vec<_> = bodies
        .iter()
        .map(|b| {
            let c: Vec<_> = b.com.iter().map(|v| emit::float_lit(*v)).collect();
            quote!([#(#c),*])
        })
        .collect();
    let inertia: Vec<_> = bodies
        .iter()
        .map(|b| {
            let rows: Vec<_> = b
                .inertia
                .iter()
                .map(|r| {
                    let r: Vec<_> = r.iter().map(|v| emit::float_lit(*v)).collect();
                    quote!([#(#r),*])
                })
                .collect();
            quote!([#(#rows),*])
        })
        .collect();
    (
        quote! {
            /// Number of bodies with run-time inertial parameters ([`RUNTIME_BODY_NAMES`]).
            pub const NB: usize = #nb;
            #(#[doc = #names_doc])*
            pub const RUNTIME_BODY_NAMES: [&str; NB] = [#(#names),*];
        },
        quote! {
            /// Mass of each body of [`RUNTIME_BODY_NAMES`] (kg).
            pub body_mass: [f64; NB],
            /// Mass centre of each body of [`RUNTIME_BODY_NAMES`] (m), in the frame of the
            /// model body it is part of (listed there).
            pub body_com: [[f64; 3]; NB],
            /// Inertia of each body of [`RUNTIME_BODY_NAMES`] about its mass centre (kg·m²,
            /// symmetric), in the axes of the model body it is part of.
            pub body_inertia: [[[f64; 3]; 3]; NB],
        },
        quote! {
            body_mass: [#(#mass),*],
            body_com: [#(#com),*],
            body_inertia: [#(#inertia),*],
        },
        quote! {
            let mut k = 0;
            while k < NB {
                let b = #base + 10 * k;
                let (c, j) = (&self.body_com[k], &self.body_inertia[k]);
                a[b] = self.body_mass[k];
                a[b + 1] = c[0];
                a[b + 2] = c[1];
                a[b + 3] = c[2];
                a[b + 4] = j[0][0];
                a[b + 5] = j[0][1];
                a[b + 6] = j[0][2];
                a[b + 7] = j[1][1];
                a[b + 8] = j[1][2];
                a[b + 9] = j[2][2];
                k += 1;
            }
        },
    )
}

/// [`generate_selected`] with run-time parameters (`None`: constants).
pub fn generate_with(
    model: &Model,
    cfg: &Config,
    only: Option<&[String]>,
    params: Option<&spec::RuntimeParams>,
) -> Generated {
    let Symbolic {
        graph: g,
        dof: n,
        mass_matrix: mm_out,
        coriolis: cor,
        gravity: grav,
        inverse_dynamics: id,
        forward_dynamics: fd,
        forward_dynamics_guards: fd_guards,
        friction,
    } = symbolic_with(model, params);
    type Spec = (&'static str, Vec<String>, Vec<Arg>, Kernel, Shape);
    let k = |outputs: Vec<sym::ExprId>| Kernel::new(outputs, Vec::new());
    let mut specs: Vec<Spec> = vec![
        (
            "mass_matrix",
            vec![
                "Generalized inertia matrix `I(q) = TᵀMT` (lecture eq. 21), symmetric positive \
                 definite away from singularities; kg·m² (revolute rows/columns), kg (prismatic)."
                    .into(),
            ],
            vec![Arg::Q],
            k(mm_out),
            Shape::Matrix,
        ),
        (
            "coriolis",
            vec![
                "Velocity-dependent efforts `C(q, q̇) q̇` with `C = Tᵀ(MṪ + WMT)` (lecture eq. 22): \
                 Coriolis and centrifugal terms, no gravity."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd],
            k(cor),
            Shape::Vector,
        ),
        (
            "gravity",
            vec![
                "Efforts that hold the mechanism still against gravity, `−γ(q) = −Tᵀ w^G`; equal \
                 to `inverse_dynamics(q, 0, 0)`."
                    .into(),
            ],
            vec![Arg::Q],
            k(grav),
            Shape::Vector,
        ),
        (
            "inverse_dynamics",
            vec![
                "Joint efforts (N·m for revolute, N for prismatic joints) that produce the motion: \
                 `τ = I q̈ + C q̇ − γ` (lecture eq. 24). Units: q in rad or m, q̇ in rad/s or m/s, \
                 q̈ in rad/s² or m/s²."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Qdd],
            k(id),
            Shape::Vector,
        ),
        (
            "forward_dynamics",
            vec![
                "Joint accelerations `q̈ = I⁻¹ (τ − C q̇ + γ)`; `Err(Singular)` when a pivot of \
                 the mass matrix's factorization is not above `1e-12` times its diagonal entry \
                 (or an input is NaN)."
                    .into(),
            ],
            vec![Arg::Q, Arg::Qd, Arg::Tau],
            Kernel::new(fd, fd_guards),
            Shape::FallibleVector,
        ),
    ];
    if let Some(friction) = friction {
        specs.push((
            "friction",
            vec![
                "Joint friction efforts `δ(q̇) = b q̇ + c q̇ / √(q̇² + v_s²)` (viscous and \
                 regularized Coulomb, `[scene] friction = true`); included in \
                 `inverse_dynamics` and `forward_dynamics`."
                    .into(),
            ],
            vec![Arg::Qd],
            k(friction),
            Shape::Vector,
        ));
    }
    if params.is_some() {
        for spec in &mut specs {
            spec.2.push(Arg::P);
        }
    }
    let functions: Vec<Function<'_>> = specs
        .into_iter()
        .filter(|s| only.is_none_or(|o| o.iter().any(|f| f == s.0)))
        .map(|(name, doc, args, kernel, shape)| {
            let schedule = schedule(&g, &kernel);
            let outputs = kernel.outputs;
            Function {
                name,
                doc,
                args,
                outputs,
                shape,
                schedule,
                dof: n,
                public: true,
                sites: false,
            }
        })
        .collect();
    let stats: Vec<(String, OpCount)> = functions
        .iter()
        .map(|f| (f.name.to_string(), f.schedule.ops))
        .collect();
    let mut header = vec![
        format!(
            "@generated by nocdyn codegen {VERSION} from mechanism `{}` — do not edit.",
            model.name
        ),
        format!("Degrees of freedom: {n}. Units: SI (m, kg, s, rad, N, N·m)."),
        match &cfg.math {
            MathBackend::Libm => {
                "Math backend: the `libm` crate (sin/cos, sqrt); otherwise core only.".into()
            }
            MathBackend::Std => "Math backend: std (`f64::sin_cos`).".into(),
            MathBackend::Runtime(p) => format!("Math backend: `{p}::math` (nocdyn runtime)."),
        },
        "Operation counts per call:".into(),
    ];
    header.extend(emit::stats_table(&stats, n));
    let joint_names: Vec<String> = model.joints.iter().map(|j| j.name.clone()).collect();
    let extra = params
        .map(|rp| params_template(model, rp))
        .unwrap_or_default();
    let code = emit::module(&g, cfg, &header, n, &joint_names, &functions, extra);
    Generated {
        code,
        stats,
        dof: n,
        warnings: diag::Diagnostics::new("", ""),
        per: "joint",
    }
}
