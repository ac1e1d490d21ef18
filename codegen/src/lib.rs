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
pub mod c_api;
pub mod closed;
pub mod diag;
pub mod draw;
pub mod dynamics;
pub mod emit;
pub mod fma;
mod implement;
pub mod indices;
pub mod lanes;
mod lu;
pub mod macro_support;
mod module;
pub mod parallel;
pub mod params;
pub mod scalar;
pub mod schedule;
mod sin_cos;
pub mod spec;
pub mod sym;
mod tangent;
mod template;
pub mod tree;
mod unit_parameters;

use schedule::OpCount;

pub use tree::{Symbolic, symbolic, symbolic_with, symbolic_with_frames};

/// Where generated code takes `sin_cos` and `sqrt` from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MathBackend {
    /// The `libm` crate (`libm::sincos`): works in `no_std`, bit-identical on every target.
    Libm,
    /// `f64::sin_cos` from std (not `no_std`): two calls of the platform's libm, where the
    /// `libm` crate's `sincos` is one (twice as fast on glibc x86-64: docs/performance.md).
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

/// What a generation produces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Emit {
    /// The Rust module (default).
    #[default]
    Rust,
    /// The Rust module and a crate that wraps it for C ([`Generated::c_crate`], see
    /// [`c_api`]): a `no_std` `staticlib` of `extern "C"` functions and its header. Needs
    /// the `libm` math backend and no `implement`.
    C,
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
    /// `Some(path)`: the module also holds `pub struct Module` and implements
    /// `<path>::Dynamics<NX, DOF>` for it, where `path` names the nocdyn runtime crate (e.g.
    /// `"runtime"`), so that code over modules of every kind is written once (see
    /// `runtime::Dynamics`). `None` (default): free functions only.
    pub implement: Option<String>,
    /// What to produce: the module only, or also its C wrapper crate.
    pub emit: Emit,
    /// Fuse `a*b + c`, `a*b - c` and `c - a*b` into one `mul_add` (one rounding) wherever the
    /// product is read by that sum alone ([`fma`]); the op-count table gains an `fma` column.
    /// Off by default: the output is then byte for byte the unfused one, and a `libm` build
    /// stays bit-identical across targets. Pays only on a target with FMA instructions
    /// (`-C target-cpu=native` or `-C target-feature=+fma`) and through the `Runtime` or `Std`
    /// backend (`libm::fma` on x86 is a call chosen at run time); elsewhere `mul_add` is a
    /// library call. Results differ from the unfused ones by rounding (tests: ≤ 1e-12
    /// relative).
    pub fma: bool,
    /// `Some(L)`: the module also holds `<name>_lanes` of its dynamics functions
    /// ([`lanes::FUNCTIONS`], and a platform's or closed loop's `actuator_mass_matrix`), which
    /// evaluate `L` states per call (`LANES = L`, 2 to [`lanes::MAX`]), lane last:
    /// `q: &[[f64; LANES]; DOF]` in (`q[i][k]`: coordinate `i` of state `k`; a platform's or
    /// closed loop's `x: &[[f64; LANES]; NX]`), `[[f64; LANES]; DOF]` out, and for every
    /// function that can fail also each lane's status `[Result<(), Singular>; LANES]`; every
    /// lane bit for bit the scalar function on its state ([`lanes`]). 4 fills an AVX2 register
    /// in `f64`, 8 in `f32`. `None` (default): the module as before, byte for byte.
    pub lanes: Option<usize>,
    /// With `lanes`: the `_lanes` functions take `sin` and `cos` of all lanes at once, by a
    /// branch-free polynomial that vectorizes (Cody–Waite reduction by π/2 and fdlibm's
    /// kernels), instead of the math backend once per lane, which is most of their time.
    /// Within 2 ulp of the correctly rounded values away from their zeros, so lanes agree
    /// with the scalar functions to rounding, no longer bit for bit (tests: ≤ 1e-13
    /// relative). A lane beyond `|x| = 2¹⁹·π/2` or not finite takes the backend for the
    /// whole call. Off by default; an error without `lanes`.
    pub vector_sin_cos: bool,
    /// The scalar functions take the `sin` and `cos` of all their angles computed from the
    /// inputs alone (a tree's joint angles) in one call, by the polynomial of
    /// `vector_sin_cos` over them as one array, which vectorizes, instead of the math backend
    /// once per angle, which is much of a tree's inverse dynamics and mass matrix on a host.
    /// Results differ from the backend's by rounding (within 2 ulp of `sin` and `cos`); an
    /// angle beyond `|x| = 2¹⁹·π/2` or not finite takes the backend for the whole call. Off by
    /// default (the output is then byte for byte what it was); independent of `lanes`. It
    /// pays where vectors hold four `f64` or more (AVX2, AVX-512: `-C target-cpu`); built for
    /// x86-64's baseline it is mostly slower (docs/performance.md).
    pub batch_sin_cos: bool,
    /// With `lanes`: `Some(path)` makes `Lanes`' arithmetic (`+ - * /`, negation, `sqrt`,
    /// `mul_add`) go through the vector types of the `wide` crate (version 1), which the
    /// including crate names `path` (e.g. `"wide"`) and must depend on (`no_std` with
    /// `default-features = false`): explicit vector operations in safe code, chosen by the
    /// target's features at compile time, instead of lane-by-lane operators left to LLVM's
    /// vectorizer. Still bit for bit the scalar functions. For `lanes` of 2, 4 or 8 in `f64`
    /// and 4, 8 or 16 in `f32`. `None` (default): no dependency.
    pub wide: Option<String>,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            math: MathBackend::Libm,
            float: Float::F64,
            scene: spec::SceneOverrides::default(),
            implement: None,
            emit: Emit::Rust,
            fma: false,
            lanes: None,
            vector_sin_cos: false,
            batch_sin_cos: false,
            wide: None,
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
    /// With [`Emit::C`]: the C wrapper crate of [`Generated::code`] (its files by relative
    /// path); `None` otherwise.
    pub c_crate: Option<c_api::CCrate>,
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
    let loaded = spec::load(file_name, source, &cfg.scene)?;
    let error = |msg: String, key: Option<&str>| {
        let mut d = diag::Diagnostics::new(file_name, source);
        let e = diag::Diagnostic::error(msg);
        d.push(match key {
            Some(k) => e.with_key(k),
            None => e,
        });
        d
    };
    // An option that does not fit the mechanism is the configuration's error, not the spec's.
    check_options(&loaded.mechanism, &loaded.scene, cfg).map_err(|msg| error(msg, None))?;
    // What is left is a mechanism singular for every input: a platform's legs, or loops.
    let key = matches!(loaded.mechanism, spec::Mechanism::Parallel(_)).then_some("platform");
    let mut out =
        generate_checked(&loaded.mechanism, &loaded.scene, cfg).map_err(|msg| error(msg, key))?;
    out.warnings = loaded.warnings;
    Ok(out)
}

/// The options of `cfg` that do not fit `mechanism` (or each other).
fn check_options(
    mechanism: &spec::Mechanism,
    scene: &spec::Scene,
    cfg: &Config,
) -> Result<(), String> {
    if cfg.implement.is_some() {
        implement::check(mechanism, scene)?;
    }
    if cfg.emit == Emit::C && (cfg.math != MathBackend::Libm || cfg.implement.is_some()) {
        return Err(
            "the C wrapper crate (`emit c`) takes the `libm` math backend and no `implement`"
                .into(),
        );
    }
    if cfg.vector_sin_cos && cfg.lanes.is_none() {
        return Err("`vector_sin_cos` is for the `_lanes` functions: set `lanes` too".into());
    }
    if let Some(path) = &cfg.wide {
        let Some(l) = cfg.lanes else {
            return Err("`wide` is for the `_lanes` functions: set `lanes` too".into());
        };
        if lanes::wide_type(cfg.float == Float::F32, l).is_none() {
            return Err(format!(
                "`wide` has vector types for {} lanes, not {l}",
                lanes::WIDE_WIDTHS
            ));
        }
        if syn::parse_str::<syn::Path>(path).is_err() {
            return Err(format!("`wide`: `{path}` is not a crate path"));
        }
    }
    if let Some(l) = cfg.lanes {
        if !(2..=lanes::MAX).contains(&l) {
            return Err(format!(
                "`lanes` takes 2 to {} states per call, not {l}",
                lanes::MAX
            ));
        }
        if cfg.emit == Emit::C {
            return Err("the C wrapper crate (`emit c`) takes no `lanes`".into());
        }
    }
    Ok(())
}

/// Generate the module of a loaded mechanism of any kind, in the precision of `cfg`. An
/// `Err` is a mechanism that is singular for every input. A panic while generating is a
/// generator bug; inside someone's build it must still come out as an error, not as an
/// aborted build script or macro.
pub fn generate(
    mechanism: &spec::Mechanism,
    scene: &spec::Scene,
    cfg: &Config,
) -> Result<Generated, String> {
    check_options(mechanism, scene, cfg)?;
    generate_checked(mechanism, scene, cfg)
}

/// [`generate`] once `cfg`'s options are known to fit the mechanism.
fn generate_checked(
    mechanism: &spec::Mechanism,
    scene: &spec::Scene,
    cfg: &Config,
) -> Result<Generated, String> {
    let single = cfg.float == Float::F32;
    let generated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        scalar::with_precision(single, || {
            fma::with(cfg.fma, || match mechanism {
                spec::Mechanism::Tree(model) => Ok(tree::generate(model, scene, cfg)),
                spec::Mechanism::Parallel(model) => parallel::generate(model, scene, cfg),
                spec::Mechanism::Closed(model) => closed::generate(model, scene, cfg),
            })
        })
    }));
    let generated = generated.and_then(|out| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let mut out = out?;
            if cfg.emit == Emit::C {
                out.c_crate = Some(c_api::emit(mechanism.name(), &out.code, single)?);
            }
            Ok(out)
        }))
    });
    match generated {
        Ok(out) => out,
        Err(_) => {
            Err("internal error: the generator panicked on this spec (please report it)".into())
        }
    }
}

/// The generator version written into every header.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
