//! `Config::emit = Emit::C`: a generated module wrapped for C and C++ firmware, as a crate
//! of its own. [`CCrate`] holds its files: `Cargo.toml` (a `staticlib`, `panic = "abort"`,
//! the `libm` crate, its own `[workspace]`), `src/lib.rs` (`#![no_std]`, the module
//! included, one `extern "C"` function per public function of the module), `src/NAME.rs`
//! (the module itself) and `include/NAME.h` (the C header).
//!
//! The wrappers are read off the module's own items (`c_api/items.rs`), as `implement.rs` does: each
//! public function's arguments and result, the variants of its `Site`, `Stop` and
//! `IndexError`, the fields of `Params` and `InertiaIndices`, the public constants. So the
//! C interface follows the kinds' templates without a second copy of their rules.
//!
//! The C calling convention, the same for every function: inputs are `const T *` to fixed-size
//! arrays (matrices flat, row-major), outputs `T *` after them, `const NAME_params_t *p` last
//! among the inputs when the module has run-time parameters, and `NAME_error_t *err` (may be
//! `NULL`) last when the function can fail. Every function returns an `int32_t` status: `0`
//! on success, a distinct negative code per failure (a `NULL` argument, each `Site` of
//! `Singular`, each `Stop` of forward kinematics, each `IndexError`). Inputs are read by value
//! before anything is written, so an output may alias an input; outputs are written only on
//! success, and `*err` (when given) always.

use std::fmt::Write as _;

mod items;

use items::{Dim, Field, Func, Module, Ty, read, usize_value};

/// The files of a C wrapper crate, by path relative to its root (`Cargo.toml`, `src/lib.rs`,
/// `src/NAME.rs`, `include/NAME.h`), in a fixed order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CCrate {
    /// The package and library name (`NAME_c`; the static library is `libNAME_c.a`).
    pub package: String,
    /// `(relative path, contents)`.
    pub files: Vec<(String, String)>,
}

/// The status codes that mean the same thing in every module (the rest are numbered after
/// them): `(Rust enum, variant, code)`.
const CODES: &[(&str, &str, i32)] = &[
    ("Site", "MassMatrix", -10),
    ("Site", "Leg", -11),
    ("Site", "Reach", -12),
    ("Site", "Actuation", -13),
    ("Site", "Platform", -14),
    ("Site", "Closure", -15),
    ("Site", "Constraint", -16),
    ("Site", "Spring", -17),
    ("Site", "Input", -18),
    ("Stop", "Input", -20),
    ("Stop", "Guess", -21),
    ("Stop", "Singular", -22),
    ("Stop", "Stalled", -23),
    ("Stop", "Iterations", -24),
    ("Stop", "Branch", -25),
    ("IndexError", "NotFinite", -30),
    ("IndexError", "NotSymmetric", -31),
    ("IndexError", "NotPositiveDefinite", -32),
    ("IndexError", "NoConvergence", -33),
    ("IndexError", "Overflow", -34),
];

/// The C prefix of each error enum's codes.
fn code_prefix(enum_name: &str) -> &'static str {
    match enum_name {
        "Site" => "SINGULAR",
        "Stop" => "NO_CONVERGENCE",
        _ => "INDEX",
    }
}

/// `MassMatrix` → `MASS_MATRIX`.
fn screaming(camel: &str) -> String {
    let mut s = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_uppercase());
    }
    s
}

/// A C block comment of `text`, each line prefixed by `indent`; `*/` cannot end it early.
fn c_comment(text: &str, indent: &str) -> String {
    let text = text.replace("*/", "* /");
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() == 1 {
        return format!("{indent}/** {} */\n", lines[0]);
    }
    let mut out = format!("{indent}/**\n");
    for l in lines {
        if l.is_empty() {
            out.push_str(&format!("{indent} *\n"));
        } else {
            out.push_str(&format!("{indent} * {l}\n"));
        }
    }
    out.push_str(&format!("{indent} */\n"));
    out
}

/// A real as a C literal (`f` suffix in single precision).
fn c_real(v: f64, single: bool) -> String {
    let mut s = if single {
        format!("{:?}", v as f32)
    } else {
        format!("{v:?}")
    };
    if !s.contains(['.', 'e', 'E']) {
        s.push_str(".0");
    }
    if single {
        s.push('f');
    }
    s
}

fn real_value(e: &syn::Expr) -> Option<f64> {
    match e {
        syn::Expr::Lit(syn::ExprLit { lit, .. }) => match lit {
            syn::Lit::Float(f) => f.base10_parse().ok(),
            syn::Lit::Int(i) => i.base10_parse::<i64>().ok().map(|v| v as f64),
            _ => None,
        },
        syn::Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => real_value(&u.expr).map(|v| -v),
        _ => None,
    }
}

/// The values of a constant as C literals, flattened, or `None` for a form C cannot take.
fn c_values(
    e: &syn::Expr,
    t: &Ty,
    usizes: &[(String, usize)],
    single: bool,
) -> Option<Vec<String>> {
    match (t, e) {
        (Ty::Array(el, d), syn::Expr::Array(a)) if a.elems.len() == d.n => {
            let mut v = Vec::new();
            for x in &a.elems {
                v.extend(c_values(x, el, usizes, single)?);
            }
            Some(v)
        }
        (Ty::Array(el, d), syn::Expr::Repeat(r)) => {
            let one = c_values(&r.expr, el, usizes, single)?;
            Some((0..d.n).flat_map(|_| one.clone()).collect())
        }
        (Ty::Real, e) => real_value(e).map(|v| vec![c_real(v, single)]),
        (Ty::Usize, e) => usize_value(e, usizes).ok().map(|v| vec![v.to_string()]),
        (
            Ty::Str,
            syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }),
        ) => {
            let mut out = String::from("\"");
            for c in s.value().chars() {
                match c {
                    '"' => out.push_str("\\\""),
                    '\\' => out.push_str("\\\\"),
                    c if c.is_ascii_graphic() || c == ' ' => out.push(c),
                    c => {
                        let mut b = [0; 4];
                        for byte in c.encode_utf8(&mut b).bytes() {
                            // Octal escapes end after three digits, whatever follows.
                            let _ = write!(out, "\\{byte:03o}");
                        }
                    }
                }
            }
            out.push('"');
            Some(vec![out])
        }
        _ => None,
    }
}

/// What an argument or output name means, by name and kind of module.
fn meaning(name: &str, kind: Kind, func: &str) -> &'static str {
    match (kind, name) {
        (Kind::Tree, "q") => "joint positions (rad or m)",
        (Kind::Tree, "qd") => "joint rates (rad/s or m/s)",
        (Kind::Tree, "qdd") => "joint accelerations (rad/s² or m/s²)",
        (Kind::Tree, "tau") => "joint efforts (N·m or N)",
        (Kind::Parallel, "x") => "platform position coordinates (m, rad; see the module's NX)",
        (Kind::Closed, "x") => "the spanning tree's joint positions (rad or m, JOINT_NAMES order)",
        (Kind::Parallel, "u") => "platform speeds (m/s, rad/s)",
        (Kind::Closed, "u") => "the actuated joints' rates (rad/s or m/s)",
        (Kind::Parallel, "ud") => "platform accelerations (m/s², rad/s²)",
        (Kind::Closed, "ud") => "the actuated joints' accelerations (rad/s² or m/s²)",
        (_, "tau") => "actuator efforts (N·m or N, ACTUATOR_NAMES order)",
        (_, "q") => "actuated joint positions (rad or m, ACTUATOR_NAMES order)",
        (_, "qd") => "actuated joint rates (rad/s or m/s)",
        (_, "guess") => "where Newton's method starts (e.g. the HOME initializer)",
        (_, "m") if func == "inertia_indices" => {
            "a symmetric positive definite matrix, row-major (e.g. from mass_matrix)"
        }
        (_, "m") => "the generalized inertia, row-major (kg·m², kg)",
        (_, "pose") => "the platform's pose",
        (_, "xd") => "every tree joint's rate (rad/s or m/s, JOINT_NAMES order)",
        (_, "p") => "run-time parameters (NAME_params_default gives the spec's values)",
        (_, "dtau_dq") => "∂τ/∂q, row-major",
        (_, "dtau_dqd") => "∂τ/∂q̇, row-major",
        (_, "dqdd_dq") => "∂q̈/∂q, row-major",
        (_, "dqdd_dqd") => "∂q̈/∂q̇, row-major",
        (_, "minv") => "the inverse of the mass matrix, row-major",
        (_, "dtau_dx") => "∂τ/∂x along the speeds (column j: x moved as u_j moves it), row-major",
        (_, "dtau_du") => "∂τ/∂u, row-major",
        (_, "dud_dx") => "∂u̇/∂x along the speeds (column j: x moved as u_j moves it), row-major",
        (_, "dud_du") => "∂u̇/∂u, row-major",
        (_, "dud_dtau") => "∂u̇/∂τ, row-major",
        (_, "y") => "the regressor over the base parameters, DOF × NBP, row-major",
        (_, "qdd") => "joint accelerations (rad/s² or m/s²)",
        (_, "indices") => "the indices",
        (_, "rotation") => "the rotation base ← frame, row-major",
        (_, "position") => "the frame's origin in the base frame (m)",
        (_, "jacobian") => "the frame's Jacobian, 6 × DOF row-major: rows ω then v (base frame)",
        (_, "jdot_qd") => "J̇ q̇: ω̇ then p̈ at q̈ = 0 (base frame)",
        (_, "jdot_u") => "J̇ u: ω̇ then p̈ at u̇ = 0 (base frame)",
        _ => "the result",
    }
}

/// The names of a function's outputs, one per element of its (successful) result.
fn output_names(f: &Func, kind: Kind, n: usize) -> Vec<String> {
    let names: &[&str] = match (f.name.as_str(), kind) {
        ("mass_matrix" | "actuator_mass_matrix", _) => &["m"],
        ("inverse_dynamics" | "gravity" | "coriolis" | "friction", _) => &["tau"],
        ("forward_dynamics", Kind::Tree) => &["qdd"],
        ("forward_dynamics", _) => &["ud"],
        ("inverse_dynamics_derivatives", Kind::Tree) => &["dtau_dq", "dtau_dqd"],
        ("inverse_dynamics_derivatives", _) => &["dtau_dx", "dtau_du"],
        ("forward_dynamics_derivatives", Kind::Tree) => &["dqdd_dq", "dqdd_dqd", "minv"],
        ("forward_dynamics_derivatives", _) => &["dud_dx", "dud_du", "dud_dtau"],
        ("regressor", _) => &["y"],
        ("actuator_rates", _) => &["qd"],
        ("joint_rates", _) => &["xd"],
        ("inverse_kinematics", _) => &["q"],
        ("forward_kinematics", _) => &["x"],
        ("platform_pose", _) => &["pose"],
        ("inertia_indices", _) => &["indices"],
        (f, Kind::Tree) if f.ends_with("_jacobian_dot_qd") => &["jdot_qd"],
        (f, Kind::Parallel) if f.ends_with("_jacobian_dot_u") => &["jdot_u"],
        (f, Kind::Tree | Kind::Parallel) if f.ends_with("_jacobian") => &["jacobian"],
        (f, Kind::Tree | Kind::Parallel) if f.ends_with("_pose") => &["rotation", "position"],
        _ => &[],
    };
    if names.len() == n {
        names.iter().map(|s| s.to_string()).collect()
    } else if n == 1 {
        vec!["out".into()]
    } else {
        (0..n).map(|k| format!("out{k}")).collect()
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Tree,
    Parallel,
    Closed,
}

/// One status code: its C name, value and doc.
struct Code {
    c: String,
    value: i32,
    doc: String,
}

/// The codes of one error enum of the module, in its variant order.
fn enum_codes(m: &Module, enum_name: &str, upper: &str) -> Vec<(String, Code)> {
    let mut next = match enum_name {
        "Site" => -40,
        "Stop" => -50,
        _ => -60,
    };
    m.variants(enum_name)
        .iter()
        .map(|v| {
            let value = CODES
                .iter()
                .find(|(e, n, _)| *e == enum_name && *n == v.name)
                .map(|c| c.2)
                .unwrap_or_else(|| {
                    next -= 1;
                    next + 1
                });
            let c = format!("{upper}_{}_{}", code_prefix(enum_name), screaming(&v.name));
            (
                v.name.clone(),
                Code {
                    c,
                    value,
                    doc: v.doc.clone(),
                },
            )
        })
        .collect()
}

/// The C type of a struct field (`double name[3][3]`).
fn c_field(f: &Field, upper: &str, real: &str) -> String {
    let (dims, el) = f.ty.dims();
    let base = match el {
        Ty::Usize => "int32_t",
        _ => real,
    };
    let mut s = format!("{base} {}", f.name);
    for d in dims {
        let _ = write!(s, "[{}]", c_dim(d, upper));
    }
    s
}

fn c_dim(d: &Dim, upper: &str) -> String {
    if d.rust.chars().all(|c| c.is_ascii_digit()) {
        d.rust.clone()
    } else {
        format!("{upper}_{}", d.rust)
    }
}

/// The number of scalars of an array as a C expression (`NAME_DOF * NAME_DOF`).
fn c_len(t: &Ty, upper: &str) -> String {
    let (dims, _) = t.dims();
    if dims.is_empty() {
        return "1".into();
    }
    dims.iter()
        .map(|d| c_dim(d, upper))
        .collect::<Vec<_>>()
        .join(" * ")
}

/// The wrapper crate of the module `code` (generated for the mechanism `name`).
pub(crate) fn emit(name: &str, code: &str, single: bool) -> Result<CCrate, String> {
    let m = read(code, single)?;
    let upper = name.to_ascii_uppercase();
    let real_c = if single { "float" } else { "double" };
    let real_r = if single { "f32" } else { "f64" };
    let kind = if !m.has_const("NX") {
        Kind::Tree
    } else if m.consts.iter().any(|c| c.name == "INDEPENDENT") {
        Kind::Closed
    } else {
        Kind::Parallel
    };
    let params = m.struct_fields("Params");
    let indices = m.struct_fields("InertiaIndices");
    let singular_fields: Vec<&str> = m
        .struct_fields("Singular")
        .unwrap_or(&[])
        .iter()
        .map(|f| f.name.as_str())
        .collect();
    let tree_pivot = singular_fields.contains(&"pivot");

    // Status codes.
    let null = Code {
        c: format!("{upper}_NULL_ARGUMENT"),
        value: -1,
        doc: "A pointer argument (other than `err`) is NULL: nothing was computed or written."
            .into(),
    };
    let mut site_codes = enum_codes(&m, "Site", &upper);
    if tree_pivot {
        // A tree's `Singular { pivot, .. }`: a pivot of the mass matrix's LDLᵀ, or `DOF` for a
        // non-finite input or result.
        site_codes = vec![
            (
                "MassMatrix".into(),
                Code {
                    c: format!("{upper}_SINGULAR_MASS_MATRIX"),
                    value: -10,
                    doc: "Pivot `index` of the mass matrix's LDLᵀ is not above its tolerance."
                        .into(),
                },
            ),
            (
                "Input".into(),
                Code {
                    c: format!("{upper}_SINGULAR_INPUT"),
                    value: -18,
                    doc: "An input is NaN or infinite, or a result overflowed.".into(),
                },
            ),
        ];
    }
    let stop_codes = enum_codes(&m, "Stop", &upper);
    let index_codes = enum_codes(&m, "IndexError", &upper);

    // Which error each function can return.
    let uses = |e: &str| {
        m.fns
            .iter()
            .any(|f| matches!(&f.ret, Ty::Result(_, x) if x == e))
    };
    let mut all_codes: Vec<&Code> = vec![&null];
    if uses("Singular") {
        all_codes.extend(site_codes.iter().map(|(_, c)| c));
    }
    if uses("NoConvergence") {
        all_codes.extend(stop_codes.iter().map(|(_, c)| c));
    }
    if uses("IndexError") {
        all_codes.extend(index_codes.iter().map(|(_, c)| c));
    }

    let mut h = String::new();
    let mut r = String::new();
    let header_line = code
        .lines()
        .next()
        .unwrap_or_default()
        .trim_start_matches("// ");
    let guard = format!("{upper}_H");

    // ---- header preamble
    let _ = writeln!(h, "/* {header_line} */");
    let _ = writeln!(
        h,
        "/* C interface of the generated module `{name}` (built by the crate `{name}_c` beside this header:\n   link `lib{name}_c.a` and `-lm`). Units: SI (m, kg, s, rad, N, N·m). Arrays are fixed-size, matrices\n   flat and row-major. Inputs are read before any output is written, so an output may alias an\n   input; outputs are written only on success (status {upper}_OK). */"
    );
    let _ = writeln!(
        h,
        "#ifndef {guard}\n#define {guard}\n\n#include <stdint.h>\n"
    );
    let _ = writeln!(h, "#ifdef __cplusplus\nextern \"C\" {{\n#endif\n");

    // ---- constants
    if kind == Kind::Tree {
        let _ = writeln!(
            h,
            "/** Number of position coordinates `x`: a tree's joint positions, NX = DOF. */\n#define {upper}_NX {}",
            m.usizes.iter().find(|(n, _)| n == "DOF").map_or(0, |c| c.1)
        );
    }
    for c in &m.consts {
        let Some(values) = &c.values else {
            continue;
        };
        h.push_str(&c_comment(
            &if matches!(c.ty, Ty::Array(..)) {
                format!(
                    "{}\n(An initializer: `T v[] = {upper}_{};`.)",
                    c.doc, c.name
                )
            } else {
                c.doc.clone()
            },
            "",
        ));
        if matches!(c.ty, Ty::Array(..)) {
            let _ = writeln!(h, "#define {upper}_{} {{ {} }}", c.name, values.join(", "));
        } else if let [v] = &values[..] {
            let v = if v.starts_with('-') {
                format!("({v})")
            } else {
                v.clone()
            };
            let _ = writeln!(h, "#define {upper}_{} {v}", c.name);
        }
    }
    h.push('\n');

    // ---- status codes
    let _ = writeln!(
        h,
        "/** Status codes: every function returns one; 0 is success, every failure its own negative code. */\nenum {name}_status {{"
    );
    let _ = writeln!(
        h,
        "    /** Success: the outputs are written. */\n    {upper}_OK = 0,"
    );
    for c in &all_codes {
        h.push_str(&c_comment(&c.doc, "    "));
        let _ = writeln!(h, "    {} = {},", c.c, c.value);
    }
    let _ = writeln!(h, "}};\n");

    // ---- error struct
    let _ = writeln!(
        h,
        "/** Why a function failed, for the functions that take `err` (which may be NULL). */\ntypedef struct {name}_error {{\n    /** The status the function returned. */\n    int32_t status;\n    /** The leg, joint, pivot, equation or matrix row of the failure; -1 when the site has none. */\n    int32_t index;\n    /** The matrix column of an `inertia_indices` entry; -1 otherwise. */\n    int32_t column;\n    /** Newton iterations made (`forward_kinematics`); 0 otherwise. */\n    int32_t iterations;\n    /** The determinant, pivot or value that failed its test; the last residual of `forward_kinematics`. */\n    {real_c} value;\n    /** Condition-number estimate of the matrix involved (infinity if unknown). */\n    {real_c} condition_estimate;\n}} {name}_error_t;\n"
    );
    // ---- mirrored structs
    let mirror = |h: &mut String, rust: &str, c: &str, doc: &str, fields: &[Field]| {
        h.push_str(&c_comment(doc, ""));
        let _ = writeln!(h, "typedef struct {name}_{c} {{");
        for f in fields {
            h.push_str(&c_comment(&f.doc, "    "));
            let _ = writeln!(h, "    {};", c_field(f, &upper, real_c));
        }
        let _ = writeln!(h, "}} {name}_{c}_t;\n");
        let _ = rust;
    };
    if let Some(p) = params {
        mirror(
            &mut h,
            "Params",
            "params",
            "The run-time parameters (`[scene] parameters = \"runtime\"`), SI units.",
            p,
        );
    }
    if let Some(ix) = indices {
        mirror(
            &mut h,
            "InertiaIndices",
            "inertia_indices",
            "Dynamic performance indices of an inertia matrix (see nocdyn's docs/indices.md).",
            ix,
        );
    }

    // ---- Rust preamble
    let _ = writeln!(
        r,
        "//! {header_line}\n//!\n//! The C interface of the module `{name}` (`include/{name}.h`): one `extern \"C\"` function per\n//! public function, no std, no alloc, no panic.\n#![no_std]\n#![allow(clippy::all, unused_unsafe)]\n\n#[allow(clippy::all, dead_code, unused_imports, unused_variables, unused_mut)]\nmod m {{\n    include!(\"{name}.rs\");\n}}\n"
    );
    let _ = writeln!(
        r,
        "/// The one panic handler of the static library (nothing in it can panic).\n#[cfg(not(test))]\n#[panic_handler]\nfn panic(_: &core::panic::PanicInfo) -> ! {{\n    loop {{}}\n}}\n"
    );
    let _ = writeln!(
        r,
        "/// `{name}_error_t`.\n#[repr(C)]\n#[derive(Clone, Copy)]\npub struct Error {{\n    pub status: i32,\n    pub index: i32,\n    pub column: i32,\n    pub iterations: i32,\n    pub value: {real_r},\n    pub condition_estimate: {real_r},\n}}\n\nconst fn failure(status: i32) -> Error {{\n    Error {{ status, index: -1, column: -1, iterations: 0, value: 0.0, condition_estimate: {real_r}::INFINITY }}\n}}\n\n/// Writes `e` to `err` (when not null) and returns its status.\nfn report(err: *mut Error, e: Error) -> i32 {{\n    if !err.is_null() {{\n        // SAFETY: the caller passes NULL or a valid `{name}_error_t *`.\n        unsafe {{ err.write(e) }};\n    }}\n    e.status\n}}\n\nfn index(k: usize) -> i32 {{\n    i32::try_from(k).unwrap_or(i32::MAX)\n}}\n"
    );
    let struct_conv = |r: &mut String, rust: &str, c: &str, fields: &[Field]| {
        let _ = writeln!(
            r,
            "/// `{name}_{c}_t`.\n#[repr(C)]\n#[derive(Clone, Copy)]\npub struct C{rust} {{"
        );
        for f in fields {
            let t = match f.ty.dims().1 {
                Ty::Usize => f.ty.rust(real_r).replace("usize", "i32"),
                _ => f.ty.rust(real_r),
            };
            let _ = writeln!(r, "    pub {}: {t},", f.name);
        }
        let _ = writeln!(r, "}}\n");
    };
    if let Some(p) = params {
        struct_conv(&mut r, "Params", "params", p);
        let _ = writeln!(
            r,
            "fn params(p: &CParams) -> m::Params {{\n    m::Params {{"
        );
        for f in p {
            let _ = writeln!(r, "        {0}: p.{0},", f.name);
        }
        let _ = writeln!(r, "    }}\n}}\n");
        let _ = writeln!(
            r,
            "/// `{name}_params_default`.\n///\n/// # Safety\n///\n/// `p` is NULL or points to a `{name}_params_t`.\n#[unsafe(no_mangle)]\npub unsafe extern \"C\" fn {name}_params_default(p: *mut CParams) -> i32 {{\n    if p.is_null() {{\n        return {};\n    }}\n    let d = m::Params::DEFAULT;\n    let c = CParams {{",
            null.value
        );
        for f in p {
            let _ = writeln!(r, "        {0}: d.{0},", f.name);
        }
        let _ = writeln!(
            r,
            "    }};\n    // SAFETY: `p` is not null; the caller passes a valid `{name}_params_t *`.\n    unsafe {{ p.write(c) }};\n    0\n}}\n"
        );
        h.push_str(&c_comment(
            &format!(
                "Writes the spec's values of the run-time parameters to `*p`.\n\np: out, one {name}_params_t.\nReturns {upper}_OK, or {upper}_NULL_ARGUMENT when `p` is NULL."
            ),
            "",
        ));
        let _ = writeln!(h, "int32_t {name}_params_default({name}_params_t *p);\n");
    }
    if let Some(ix) = indices {
        struct_conv(&mut r, "InertiaIndices", "inertia_indices", ix);
        let _ = writeln!(
            r,
            "fn inertia_indices(i: &m::InertiaIndices) -> CInertiaIndices {{\n    CInertiaIndices {{"
        );
        for f in ix {
            let _ = writeln!(r, "        {0}: i.{0},", f.name);
        }
        let _ = writeln!(r, "    }}\n}}\n");
    }
    // Error conversions.
    let conv = |r: &mut String, err: &str, codes: &[(String, Code)]| {
        let inf = format!("{real_r}::INFINITY");
        let (value, cond, iterations) = match err {
            "Singular" => (
                "e.value".to_string(),
                "e.condition_estimate".to_string(),
                "0",
            ),
            "NoConvergence" => ("e.residual".to_string(), inf, "index(e.iterations)"),
            _ => (String::new(), String::new(), "0"),
        };
        let enum_name = match err {
            "Singular" => "Site",
            "NoConvergence" => "Stop",
            _ => "IndexError",
        };
        let _ = writeln!(
            r,
            "fn from_{}(e: &m::{err}) -> Error {{",
            screaming(err).to_ascii_lowercase()
        );
        if err == "Singular" && tree_pivot {
            let _ = writeln!(
                r,
                "    let (status, index) = if e.pivot < m::DOF {{ ({}, index(e.pivot)) }} else {{ ({}, -1) }};\n    Error {{ status, index, column: -1, iterations: 0, value: e.value, condition_estimate: e.condition_estimate }}\n}}\n",
                codes[0].1.value, codes[1].1.value
            );
            return;
        }
        let scrutinee = match err {
            "Singular" => "e.site",
            "NoConvergence" => "e.stop",
            _ => "*e",
        };
        let _ = writeln!(r, "    let f = match {scrutinee} {{");
        for v in m.variants(enum_name) {
            let code = codes
                .iter()
                .find(|(n, _)| *n == v.name)
                .map_or(-1, |c| c.1.value);
            let arm = match &v.fields {
                None => format!("m::{enum_name}::{} => failure({code}),", v.name),
                Some(fs) if fs.iter().all(|f| f.is_empty()) => {
                    let binds: Vec<String> = (0..fs.len()).map(|k| format!("k{k}")).collect();
                    format!(
                        "m::{enum_name}::{}({}) => Error {{ index: index(k0), ..failure({code}) }},",
                        v.name,
                        binds.join(", ")
                    )
                }
                Some(fs) => {
                    let mut sets = Vec::new();
                    for f in fs {
                        match f.as_str() {
                            "row" | "pivot" => sets.push(format!("index: index({f})")),
                            "col" => sets.push(format!("column: index({f})")),
                            "value" => sets.push("value".to_string()),
                            _ => {}
                        }
                    }
                    let binds: Vec<String> = fs
                        .iter()
                        .map(|f| {
                            if matches!(f.as_str(), "row" | "pivot" | "col" | "value") {
                                f.clone()
                            } else {
                                format!("{f}: _")
                            }
                        })
                        .collect();
                    format!(
                        "m::{enum_name}::{} {{ {} }} => Error {{ {}{}..failure({code}) }},",
                        v.name,
                        binds.join(", "),
                        sets.join(", "),
                        if sets.is_empty() { "" } else { ", " }
                    )
                }
            };
            let _ = writeln!(r, "        {arm}");
        }
        let _ = writeln!(r, "    }};");
        if err == "IndexError" {
            let _ = writeln!(r, "    f\n}}\n");
        } else {
            let _ = writeln!(
                r,
                "    Error {{ value: {value}, condition_estimate: {cond}, iterations: {iterations}, ..f }}\n}}\n"
            );
        }
    };
    if uses("Singular") {
        conv(&mut r, "Singular", &site_codes);
    }
    if uses("NoConvergence") {
        conv(&mut r, "NoConvergence", &stop_codes);
    }
    if uses("IndexError") {
        conv(&mut r, "IndexError", &index_codes);
    }

    // ---- one wrapper per function
    h.push_str("/* ---- functions ---- */\n\n");
    for f in &m.fns {
        let (ok, err) = match &f.ret {
            Ty::Result(t, e) => ((**t).clone(), Some(e.as_str())),
            t => (t.clone(), None),
        };
        let outs: Vec<Ty> = match ok {
            Ty::Tuple(v) => v,
            t => vec![t],
        };
        let out_names: Vec<String> = output_names(f, kind, outs.len())
            .into_iter()
            .map(|o| {
                if f.args.iter().any(|(a, _)| *a == o) || o == "err" {
                    format!("out_{o}")
                } else {
                    o
                }
            })
            .collect();
        let mut c_params = Vec::new();
        let mut r_params = Vec::new();
        let mut docs = Vec::new();
        let mut null_checks = Vec::new();
        let mut reads = Vec::new();
        let mut call_args = Vec::new();
        for (a, t) in &f.args {
            match t {
                Ty::Named(n) if n == "Params" => {
                    c_params.push(format!("const {name}_params_t *{a}"));
                    r_params.push(format!("{a}: *const CParams"));
                    docs.push(format!(
                        "{a}: in, one {name}_params_t: {}",
                        meaning(a, kind, &f.name).replace("NAME", name)
                    ));
                    reads.push(format!(
                        "    // SAFETY: not null (checked); the caller passes a valid `{name}_params_t *`.\n    let {a} = params(&unsafe {{ {a}.read() }});"
                    ));
                }
                Ty::Array(..) | Ty::Real => {
                    c_params.push(format!("const {real_c} *{a}"));
                    r_params.push(format!("{a}: *const {real_r}"));
                    docs.push(format!(
                        "{a}: in, {} entries: {}",
                        c_len(t, &upper),
                        meaning(a, kind, &f.name)
                    ));
                    reads.push(format!(
                        "    // SAFETY: not null (checked); the caller passes {} readable entries.\n    let {a} = unsafe {{ {a}.cast::<{}>().read() }};",
                        t.len(),
                        t.rust(real_r)
                    ));
                }
                _ => return Err(format!("`{}`: an argument C cannot take", f.name)),
            }
            null_checks.push(format!("{a}.is_null()"));
            call_args.push(format!("&{a}"));
        }
        let mut writes = Vec::new();
        for (o, t) in out_names.iter().zip(&outs) {
            match t {
                Ty::Named(n) if n == "InertiaIndices" => {
                    c_params.push(format!("{name}_inertia_indices_t *{o}"));
                    r_params.push(format!("{o}: *mut CInertiaIndices"));
                    docs.push(format!(
                        "{o}: out, one {name}_inertia_indices_t: {}",
                        meaning(o, kind, &f.name)
                    ));
                    writes.push(format!(
                        "        // SAFETY: not null (checked); the caller passes a writable `{name}_inertia_indices_t *`.\n        unsafe {{ {o}.write(inertia_indices(&v_{o})) }};"
                    ));
                }
                Ty::Array(..) | Ty::Real => {
                    c_params.push(format!("{real_c} *{o}"));
                    r_params.push(format!("{o}: *mut {real_r}"));
                    docs.push(format!(
                        "{o}: out, {} entries: {}",
                        c_len(t, &upper),
                        meaning(o, kind, &f.name)
                    ));
                    writes.push(format!(
                        "        // SAFETY: not null (checked); the caller passes {} writable entries.\n        unsafe {{ {o}.cast::<{}>().write(v_{o}) }};",
                        t.len(),
                        t.rust(real_r)
                    ));
                }
                _ => return Err(format!("`{}`: a result C cannot take", f.name)),
            }
            null_checks.push(format!("{o}.is_null()"));
        }
        if err.is_some() {
            c_params.push(format!("{name}_error_t *err"));
            r_params.push("err: *mut Error".into());
            docs.push("err: out, may be NULL: why it failed (the status, the site's index, the value and condition estimate)".into());
        } else {
            r_params.push("err: *mut Error".into());
        }
        let mut statuses = vec![format!("{upper}_OK"), null.c.clone()];
        match err {
            Some("Singular") => statuses.extend(site_codes.iter().map(|(_, c)| c.c.clone())),
            Some("NoConvergence") => statuses.extend(stop_codes.iter().map(|(_, c)| c.c.clone())),
            Some("IndexError") => statuses.extend(index_codes.iter().map(|(_, c)| c.c.clone())),
            _ => {}
        }
        let cname = format!("{name}_{}", f.name);
        let mut d = if f.doc.is_empty() {
            format!("`{}` of the module.", f.name)
        } else {
            f.doc.clone()
        };
        d.push_str("\n\n");
        for l in &docs {
            d.push_str(l);
            d.push('\n');
        }
        let _ = write!(d, "Returns {}.", statuses.join(", "));
        h.push_str(&c_comment(&d, ""));
        let _ = writeln!(h, "int32_t {cname}({});\n", c_params.join(", "));

        // Rust: `err` is a real argument only for fallible functions.
        if err.is_none() {
            r_params.pop();
        }
        let _ = writeln!(
            r,
            "/// `{cname}` of `include/{name}.h`.\n///\n/// # Safety\n///\n/// Each pointer is NULL (a status, nothing written) or points to as many values as the\n/// header says.\n#[unsafe(no_mangle)]\npub unsafe extern \"C\" fn {cname}({}) -> i32 {{",
            r_params.join(", ")
        );
        let err_arg = if err.is_some() {
            "err"
        } else {
            "core::ptr::null_mut()"
        };
        let _ = writeln!(
            r,
            "    if {} {{\n        return report({err_arg}, failure({}));\n    }}",
            if null_checks.is_empty() {
                "false".to_string()
            } else {
                null_checks.join(" || ")
            },
            null.value
        );
        for l in &reads {
            let _ = writeln!(r, "{l}");
        }
        let binds = if out_names.len() == 1 {
            format!("v_{}", out_names[0])
        } else {
            format!(
                "({})",
                out_names
                    .iter()
                    .map(|o| format!("v_{o}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let call = format!("m::{}({})", f.name, call_args.join(", "));
        match err {
            Some(e) => {
                let _ = writeln!(
                    r,
                    "    match {call} {{\n        Ok({binds}) => {{\n{}\n            report(err, failure(0))\n        }}\n        Err(e) => report(err, from_{}(&e)),\n    }}\n}}\n",
                    writes
                        .iter()
                        .map(|w| format!("    {}", w.replace('\n', "\n    ")))
                        .collect::<Vec<_>>()
                        .join("\n"),
                    screaming(e).to_ascii_lowercase()
                );
            }
            None => {
                let _ = writeln!(
                    r,
                    "    let {binds} = {call};\n{}\n    0\n}}\n",
                    writes
                        .iter()
                        .map(|w| w
                            .replacen("        ", "    ", 1)
                            .replace("\n        ", "\n    "))
                        .collect::<Vec<_>>()
                        .join("\n")
                );
            }
        }
    }
    let _ = writeln!(h, "#ifdef __cplusplus\n}}\n#endif\n\n#endif /* {guard} */");

    // Format the Rust through syn and prettyplease, as the module is.
    let parsed = syn::parse_file(&r)
        .map_err(|e| format!("internal error: the C wrappers do not parse: {e}"))?;
    let lib = prettyplease::unparse(&parsed);

    let package = format!("{name}_c");
    let cargo = format!(
        "# {header_line}\n# The C interface of `{name}`: `cargo build --release` writes\n# target/release/lib{package}.a (link it with -lm); include/{name}.h declares its functions.\n[package]\nname = \"{package}\"\nversion = \"0.1.0\"\nedition = \"2024\"\npublish = false\n\n[lib]\npath = \"src/lib.rs\"\ncrate-type = [\"staticlib\"]\ntest = false\ndoctest = false\nbench = false\n\n[dependencies]\n# The math backend of the generated module (sin, cos, sqrt, atan2), no_std.\nlibm = \"0.2\"\n\n# No unwinding: a panic (there is none to reach) stops in the library's own handler.\n[profile.dev]\npanic = \"abort\"\n\n# The library to link: fat LTO also drops the precompiled core's references to the\n# unwinder, which a dev build keeps (its archive does not link without a Rust runtime).\n[profile.release]\npanic = \"abort\"\nlto = true\ncodegen-units = 1\n\n# A workspace of its own: the crate builds where it is written, inside another workspace or not.\n[workspace]\n"
    );
    Ok(CCrate {
        package,
        files: vec![
            ("Cargo.toml".into(), cargo),
            ("src/lib.rs".into(), lib),
            (format!("src/{name}.rs"), code.to_string()),
            (format!("include/{name}.h"), h),
        ],
    })
}
