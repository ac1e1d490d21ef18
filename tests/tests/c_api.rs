//! `codegen --emit c` as a C firmware user meets it: for a tree (puma560), a parallel platform
//! (delta_rl5) and a closed loop (four_bar), the wrapper crate is written, built offline as a
//! release `staticlib` into one shared target directory (so a second run is incremental), a C
//! program of `tests/c/` that calls every function of the header is compiled with
//! `gcc -std=c99 -Wall -Wextra -Werror -pedantic`, linked with `-lm` and run, and its printed
//! numbers are compared with the same functions of the Rust module (`mechanisms`), to 1e-12
//! relative, failures (a singular or non-closing configuration, no convergence, a NULL
//! pointer) included. The static library must need nothing from std: no undefined symbol
//! beyond `core`, the compiler builtins and `memcpy`-like libc functions.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use codegen::{Config, Emit};

/// The printed results of one C program: `in` lines, `out` lines (status, values), `err`
/// lines (status, index, column, iterations, value, condition) and the `indices` line.
#[derive(Default)]
struct Printed {
    inputs: BTreeMap<String, Vec<f64>>,
    outputs: BTreeMap<String, (i32, Vec<f64>)>,
    errors: BTreeMap<String, (i32, i32, i32, i32, f64, f64)>,
    indices: Vec<f64>,
}

fn num(s: &str) -> f64 {
    match s {
        "inf" => f64::INFINITY,
        "-inf" => f64::NEG_INFINITY,
        "nan" | "-nan" => f64::NAN,
        s => s.parse().unwrap_or_else(|e| panic!("{s:?}: {e}")),
    }
}

fn parse(text: &str) -> Printed {
    let mut p = Printed::default();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w[..] {
            ["in", label, ref v @ ..] => {
                p.inputs
                    .insert(label.into(), v.iter().map(|s| num(s)).collect());
            }
            ["out", label, status, ref v @ ..] => {
                p.outputs.insert(
                    label.into(),
                    (status.parse().unwrap(), v.iter().map(|s| num(s)).collect()),
                );
            }
            ["err", label, s, i, c, it, v, k] => {
                p.errors.insert(
                    label.into(),
                    (
                        s.parse().unwrap(),
                        i.parse().unwrap(),
                        c.parse().unwrap(),
                        it.parse().unwrap(),
                        num(v),
                        num(k),
                    ),
                );
            }
            ["indices", ref v @ ..] => p.indices = v.iter().map(|s| num(s)).collect(),
            _ => panic!("unexpected line from the C program: {line:?}"),
        }
    }
    p
}

impl Printed {
    fn input<const N: usize>(&self, label: &str) -> [f64; N] {
        let v = &self.inputs[label];
        v.as_slice()
            .try_into()
            .unwrap_or_else(|_| panic!("input {label}: {} values, not {N}", v.len()))
    }

    /// Checks the C output `label` (status 0) against `expected`, to 1e-12 of the largest
    /// entry (and of 1).
    fn check(&self, label: &str, expected: &[f64]) {
        let Some((status, got)) = self.outputs.get(label) else {
            panic!("the C program printed no `{label}`");
        };
        assert_eq!(*status, 0, "{label}: status {status}");
        assert_eq!(got.len(), expected.len(), "{label}: length");
        let scale = expected.iter().fold(1e-300_f64, |a, v| a.max(v.abs()));
        for (k, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!(
                (g - e).abs() <= 1e-12 * scale,
                "{label}[{k}]: C {g:e}, Rust {e:e} (scale {scale:e})"
            );
        }
    }

    fn error(&self, label: &str) -> (i32, i32, i32, i32, f64, f64) {
        *self
            .errors
            .get(label)
            .unwrap_or_else(|| panic!("the C program printed no `{label}`"))
    }
}

/// The two derivative functions of a platform or closed-loop module `g`, as C printed them.
macro_rules! check_derivatives {
    ($p:ident, $g:ident, $x:ident, $u:ident, $ud:ident, $tau:ident) => {
        let (a, b) = $g::inverse_dynamics_derivatives(&$x, &$u, &$ud).unwrap();
        $p.check(
            "inverse_dynamics_derivatives",
            &[flat(&a), flat(&b)].concat(),
        );
        let (a, b, c) = $g::forward_dynamics_derivatives(&$x, &$u, &$tau).unwrap();
        $p.check(
            "forward_dynamics_derivatives",
            &[flat(&a), flat(&b), flat(&c)].concat(),
        );
    };
}

fn flat<const N: usize>(m: &[[f64; N]]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// The status codes of a header: `NAME = value` lines of its enum.
fn codes(header: &str) -> BTreeMap<String, i32> {
    header
        .lines()
        .filter_map(|l| {
            let l = l.trim().strip_suffix(',')?;
            let (n, v) = l.split_once(" = ")?;
            Some((n.to_string(), v.parse().ok()?))
        })
        .collect()
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ is in the workspace")
        .to_path_buf()
}

fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot run {cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// Emits the crate of `name`, builds it, compiles and runs `tests/c/NAME.c`; returns the
/// program's output and the header.
fn build_and_run(name: &str) -> (Printed, String) {
    let ws = workspace();
    let spec = ws.join(format!("mechanisms/specs/{name}.toml"));
    let src = std::fs::read_to_string(&spec).unwrap();
    let cfg = Config {
        emit: Emit::C,
        ..Config::default()
    };
    let out = codegen::compile(&format!("{name}.toml"), &src, &cfg).unwrap_or_else(|d| {
        panic!("{}", d.render());
    });
    let c = out.c_crate.expect("--emit c gives a crate");
    // Deterministic: a second generation is byte-identical.
    let again = codegen::compile(&format!("{name}.toml"), &src, &cfg).unwrap();
    assert_eq!(
        again.c_crate.as_ref(),
        Some(&c),
        "{name}: not deterministic"
    );

    let base = Path::new(env!("CARGO_TARGET_TMPDIR")).join("c_api");
    let dir = base.join("crates").join(name);
    for (rel, text) in &c.files {
        let path = dir.join(rel);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        codegen::build_script::write_if_changed(&path, text).unwrap();
    }
    // The workspace's lock file pins `libm` to the version already downloaded; cargo keeps
    // only the entries the crate uses.
    let lock = dir.join("Cargo.lock");
    if !lock.exists() {
        std::fs::copy(ws.join("Cargo.lock"), &lock).unwrap();
    }
    let target = base.join("target");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    run(
        Command::new(cargo)
            .args([
                "build",
                "--release",
                "--offline",
                "--quiet",
                "--manifest-path",
            ])
            .arg(dir.join("Cargo.toml"))
            .env("CARGO_TARGET_DIR", &target)
            .env_remove("RUSTFLAGS")
            .env_remove("CARGO_ENCODED_RUSTFLAGS"),
        &format!("building the {name} wrapper crate"),
    );
    let lib = target.join("release").join(format!("lib{}.a", c.package));
    check_symbols(&lib);

    if Command::new("gcc").arg("--version").output().is_err() {
        panic!(
            "gcc is not installed: the C interface test needs it (CI has it; apt-get install gcc)"
        );
    }
    let header = c
        .files
        .iter()
        .find(|(p, _)| p.ends_with(".h"))
        .map(|(_, t)| t.clone())
        .unwrap();
    let program = ws.join(format!("tests/c/{name}.c"));
    let c_source = std::fs::read_to_string(&program).unwrap();
    // Every function the header declares is called.
    for line in header.lines() {
        if let Some(rest) = line.strip_prefix("int32_t ") {
            let f = rest.split('(').next().unwrap();
            assert!(
                c_source.contains(&format!("{f}(")),
                "tests/c/{name}.c does not call {f}"
            );
        }
    }
    let exe = base.join(format!("{name}_test"));
    run(
        Command::new("gcc")
            .args([
                "-std=c99",
                "-Wall",
                "-Wextra",
                "-Werror",
                "-pedantic",
                "-O1",
            ])
            .arg("-I")
            .arg(dir.join("include"))
            .arg("-I")
            .arg(ws.join("tests/c"))
            .arg(&program)
            .arg(&lib)
            .arg("-lm")
            .arg("-o")
            .arg(&exe),
        &format!("compiling and linking tests/c/{name}.c"),
    );
    let text = run(&mut Command::new(&exe), &format!("running {name}_test"));
    (parse(&text), header)
}

/// The archive needs nothing from std, alloc or the unwinder: every symbol it leaves
/// undefined is defined in it, is `core`'s (the precompiled `core` objects inside are
/// bitcode that `nm` may not read), a compiler builtin, or a libc memory function.
fn check_symbols(lib: &Path) {
    let nm = |args: &[&str]| {
        let out = Command::new("nm")
            .args(args)
            .arg(lib)
            .output()
            .unwrap_or_else(|e| panic!("nm is needed (binutils, with gcc): {e}"));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let defined: std::collections::BTreeSet<String> = nm(&["--defined-only"])
        .lines()
        .filter_map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            [_, kind, sym] if kind.len() == 1 => Some(sym.to_string()),
            _ => None,
        })
        .collect();
    let libc = ["memcpy", "memmove", "memset", "memcmp", "bcmp", "strlen"];
    let mut bad = Vec::new();
    // `nm` also prints notes on the bitcode it cannot read; only `U symbol` lines count.
    for l in nm(&["-u"]).lines() {
        let ["U", sym] = l.split_whitespace().collect::<Vec<_>>()[..] else {
            continue;
        };
        if defined.contains(sym) {
            continue;
        }
        let core = sym.contains("4core") || sym.starts_with("_ZN4core");
        let builtin = sym.starts_with("__") && !sym.contains("rust") && !sym.starts_with("__rdl");
        if !(core || builtin || libc.contains(&sym)) {
            bad.push(sym.to_string());
        }
    }
    bad.sort();
    bad.dedup();
    assert!(
        bad.is_empty(),
        "{}: undefined symbols beyond core, builtins and libc: {bad:?}",
        lib.display()
    );
}

#[test]
fn puma560_from_c() {
    use mechanisms::puma560 as g;
    let (p, header) = build_and_run("puma560");
    let codes = codes(&header);
    let q = p.input::<6>("q");
    let qd = p.input::<6>("qd");
    let qdd = p.input::<6>("qdd");
    let tau = p.input::<6>("tau");
    let m = g::mass_matrix(&q);
    p.check("mass_matrix", &flat(&m));
    p.check("coriolis", &g::coriolis(&q, &qd));
    p.check("gravity", &g::gravity(&q));
    p.check("gravity_in_place", &g::gravity(&q));
    p.check("inverse_dynamics", &g::inverse_dynamics(&q, &qd, &qdd));
    p.check(
        "forward_dynamics",
        &g::forward_dynamics(&q, &qd, &tau).unwrap(),
    );
    let (a, b) = g::inverse_dynamics_derivatives(&q, &qd, &qdd);
    p.check(
        "inverse_dynamics_derivatives",
        &[flat(&a), flat(&b)].concat(),
    );
    let (a, b, c) = g::forward_dynamics_derivatives(&q, &qd, &tau).unwrap();
    p.check(
        "forward_dynamics_derivatives",
        &[flat(&a), flat(&b), flat(&c)].concat(),
    );
    let y: Vec<f64> = g::regressor(&q, &qd, &qdd)
        .iter()
        .flatten()
        .copied()
        .collect();
    p.check("regressor", &y);
    let (rot, pos) = g::link6_pose(&q);
    p.check("link6_pose", &[flat(&rot), pos.to_vec()].concat());
    p.check("link6_jacobian", &g::link6_jacobian(&q).concat());
    p.check("link6_jacobian_dot_qd", &g::link6_jacobian_dot_qd(&q, &qd));
    let ix = g::inertia_indices(&m).unwrap();
    p.check("inertia_indices", &ix.eigenvalues);
    close(
        &p.indices,
        &[ix.condition, ix.manipulability, ix.isotropic_acceleration],
    );

    // A NaN position: a pivot of the mass matrix fails (`Singular { pivot < DOF }`).
    let mut bad = q;
    bad[2] = f64::NAN;
    let e = g::forward_dynamics(&bad, &qd, &tau).unwrap_err();
    assert!(e.pivot < g::DOF);
    let (s, index, ..) = p.error("forward_dynamics_nan");
    assert_eq!(s, codes["PUMA560_SINGULAR_MASS_MATRIX"]);
    assert_eq!(index, e.pivot as i32);
    // An infinite effort: the pivots pass, the result is not finite (`pivot == DOF`).
    let mut bad = tau;
    bad[4] = f64::INFINITY;
    let e = g::forward_dynamics(&q, &qd, &bad).unwrap_err();
    assert_eq!(e.pivot, g::DOF);
    let (s, index, ..) = p.error("forward_dynamics_inf_tau");
    assert_eq!(s, codes["PUMA560_SINGULAR_INPUT"]);
    assert_eq!(index, -1);
    let mut asym = m;
    asym[1][4] += 1.0;
    let Err(g::IndexError::NotSymmetric { row, col }) = g::inertia_indices(&asym) else {
        panic!("not refused as asymmetric");
    };
    let (s, index, column, ..) = p.error("inertia_indices_asymmetric");
    assert_eq!(s, codes["PUMA560_INDEX_NOT_SYMMETRIC"]);
    assert_eq!((index, column), (row as i32, col as i32));
    assert_eq!(
        p.error("null_mass_matrix").0,
        codes["PUMA560_NULL_ARGUMENT"]
    );
    assert_eq!(codes["PUMA560_NULL_ARGUMENT"], -1);
    assert_eq!(p.error("null_forward_dynamics").0, -1);
}

fn close(got: &[f64], expected: &[f64]) {
    assert_eq!(got.len(), expected.len());
    for (g, e) in got.iter().zip(expected) {
        assert!(
            (g - e).abs() <= 1e-12 * e.abs().max(1e-300),
            "C {g:e}, Rust {e:e}"
        );
    }
}

#[test]
fn delta_rl5_from_c() {
    use mechanisms::delta_rl5 as g;
    let (p, header) = build_and_run("delta_rl5");
    let codes = codes(&header);
    let x = p.input::<3>("x");
    let u = p.input::<3>("u");
    let ud = p.input::<3>("ud");
    let tau = p.input::<3>("tau");
    let q = g::inverse_kinematics(&x).unwrap();
    p.check("inverse_kinematics", &q);
    p.check("actuator_rates", &g::actuator_rates(&x, &u).unwrap());
    p.check(
        "inverse_dynamics",
        &g::inverse_dynamics(&x, &u, &ud).unwrap(),
    );
    p.check("gravity", &g::gravity(&x).unwrap());
    p.check("coriolis", &g::coriolis(&x, &u).unwrap());
    p.check("mass_matrix", &flat(&g::mass_matrix(&x).unwrap()));
    let am = g::actuator_mass_matrix(&x).unwrap();
    p.check("actuator_mass_matrix", &flat(&am));
    p.check(
        "forward_dynamics",
        &g::forward_dynamics(&x, &u, &tau).unwrap(),
    );
    check_derivatives!(p, g, x, u, ud, tau);
    let y = g::regressor(&x, &u, &ud).unwrap();
    p.check(
        "regressor",
        &y.iter().flatten().copied().collect::<Vec<_>>(),
    );
    p.check(
        "forward_kinematics",
        &g::forward_kinematics(&q, &g::HOME).unwrap(),
    );
    let ix = g::inertia_indices(&am).unwrap();
    p.check("inertia_indices", &ix.eigenvalues);
    close(
        &p.indices,
        &[ix.condition, ix.manipulability, ix.isotropic_acceleration],
    );

    // Out of reach: the site, its leg and the value as the Rust `Err` gives them.
    let far = [0.0, 0.0, -10.0];
    let e = g::inverse_dynamics(&far, &u, &ud).unwrap_err();
    let (s, index, _, _, value, cond) = p.error("inverse_dynamics_far");
    let (code, k) = match e.site {
        g::Site::Reach(k) => ("DELTA_RL5_SINGULAR_REACH", k as i32),
        g::Site::Leg(k) => ("DELTA_RL5_SINGULAR_LEG", k as i32),
        g::Site::Actuation(k) => ("DELTA_RL5_SINGULAR_ACTUATION", k as i32),
        other => panic!("unexpected site {other:?}"),
    };
    assert_eq!((s, index), (codes[code], k));
    close(&[value], &[e.value]);
    assert!(cond == e.condition_estimate || (cond - e.condition_estimate).abs() <= 1e-12 * cond);
    let mut qn = q;
    qn[0] = f64::NAN;
    let e = g::forward_kinematics(&qn, &g::HOME).unwrap_err();
    assert_eq!(e.stop, g::Stop::Input);
    let (s, _, _, iterations, ..) = p.error("forward_kinematics_nan");
    assert_eq!(s, codes["DELTA_RL5_NO_CONVERGENCE_INPUT"]);
    assert_eq!(iterations, e.iterations as i32);
    let mut asym = am;
    asym[0][2] += 1.0;
    let Err(g::IndexError::NotSymmetric { row, col }) = g::inertia_indices(&asym) else {
        panic!("not refused as asymmetric");
    };
    let (s, index, column, ..) = p.error("inertia_indices_asymmetric");
    assert_eq!(s, codes["DELTA_RL5_INDEX_NOT_SYMMETRIC"]);
    assert_eq!((index, column), (row as i32, col as i32));
    assert_eq!(p.error("null_gravity").0, codes["DELTA_RL5_NULL_ARGUMENT"]);
    assert_eq!(p.error("null_forward_kinematics").0, -1);
}

#[test]
fn four_bar_from_c() {
    use mechanisms::four_bar as g;
    let (p, header) = build_and_run("four_bar");
    let codes = codes(&header);
    let crank = p.input::<1>("crank");
    let u = p.input::<1>("u");
    let ud = p.input::<1>("ud");
    let tau = p.input::<1>("tau");
    p.check(
        "forward_kinematics",
        &g::forward_kinematics(&crank, &g::HOME).unwrap(),
    );
    // The C program's assembly, read back exactly, is where the rest is evaluated.
    let x = p.input::<3>("x");
    p.check("inverse_kinematics", &g::inverse_kinematics(&x).unwrap());
    p.check("actuator_rates", &g::actuator_rates(&x, &u).unwrap());
    p.check("joint_rates", &g::joint_rates(&x, &u).unwrap());
    p.check(
        "inverse_dynamics",
        &g::inverse_dynamics(&x, &u, &ud).unwrap(),
    );
    p.check("mass_matrix", &flat(&g::mass_matrix(&x).unwrap()));
    p.check(
        "forward_dynamics",
        &g::forward_dynamics(&x, &u, &tau).unwrap(),
    );
    check_derivatives!(p, g, x, u, ud, tau);
    let y = g::regressor(&x, &u, &ud).unwrap();
    p.check(
        "regressor",
        &y.iter().flatten().copied().collect::<Vec<_>>(),
    );
    p.check("gravity", &g::gravity(&x).unwrap());
    p.check("coriolis", &g::coriolis(&x, &u).unwrap());
    let am = g::actuator_mass_matrix(&x).unwrap();
    p.check("actuator_mass_matrix", &flat(&am));
    let ix = g::inertia_indices(&am).unwrap();
    p.check("inertia_indices", &ix.eigenvalues);
    close(
        &p.indices,
        &[ix.condition, ix.manipulability, ix.isotropic_acceleration],
    );

    // A configuration that does not close the loop.
    let open = p.input::<3>("open");
    let e = g::forward_dynamics(&open, &u, &tau).unwrap_err();
    let g::Site::Closure(k) = e.site else {
        panic!("unexpected site {:?}", e.site);
    };
    let (s, index, _, _, value, _) = p.error("forward_dynamics_open");
    assert_eq!((s, index), (codes["FOUR_BAR_SINGULAR_CLOSURE"], k as i32));
    close(&[value], &[e.value]);
    let (s, ..) = p.error("forward_kinematics_nan");
    assert_eq!(s, codes["FOUR_BAR_NO_CONVERGENCE_INPUT"]);
    let (s, index, column, ..) = p.error("inertia_indices_nan");
    assert_eq!(s, codes["FOUR_BAR_INDEX_NOT_FINITE"]);
    assert_eq!((index, column), (0, 0));
    assert_eq!(
        p.error("null_joint_rates").0,
        codes["FOUR_BAR_NULL_ARGUMENT"]
    );
}
