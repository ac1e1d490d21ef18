//! A structure-aware fuzzer that runs in `cargo test` with a fixed budget: random and
//! mutated specs go to `codegen::spec::load_mechanism` and, when they load and are small, to
//! `codegen::compile`. Nothing may panic (both calls run under `catch_unwind`, and `load`'s own
//! panic guard must never fire: no "internal error"), and every `Err` must render with at least
//! one located error.
//!
//! Three generators, each driven by proptest with a deterministic RNG (so CI is reproducible):
//! - random TOML specs built from a small grammar: 1–4 bodies and joints with random kinds,
//!   parents and values (NaN, ±∞, huge, tiny, subnormal, negative numbers, angle strings, values
//!   of the wrong type), random key typos and dropped keys;
//! - mutations of every bundled spec in `mechanisms/specs` (TOML and URDF): inserted tokens,
//!   deleted ranges, truncation, numbers replaced by extreme values, duplicated or dropped lines;
//! - for URDF specifically, attribute values replaced by random numbers and words.
//!
//! The binary is driven too, as a user runs it
//! (`binary::the_binary_never_crashes_hangs_or_goes_unlocated`): those specs, plus deep XML
//! and TOML nesting, very long names, bad encodings (UTF-16, Latin-1, a cut character),
//! thousands of errors on one line and random bytes, with random flags (some invalid) and
//! `-o` targets (fresh, existing, a directory, in a missing directory), under a 2 GB
//! address-space limit. It reports the inputs tried, panics, crashes by signal, timeouts (a
//! run is killed after `NOCDYN_FUZZ_TIMEOUT` seconds, default 5), unlocated errors (exit 2
//! without `file:line:col`) and other broken promises (exit codes, `-o` files, temporary files
//! left, the `--stats` table); all but the first must be 0. The first failing inputs are kept
//! in `target/tmp/fuzz_cli`.
//!
//! `binary::data::identify_and_excite_never_crash_hang_or_print_nan` drives `identify` and
//! `excite` the same way: measurements made by `excite --with-tau` for a tree, a closed loop
//! and a platform, mutated (hostile cells, lost, doubled, renamed and extra columns, positions
//! only, time that stalls or runs back, constant rows, cut files, CRLF, BOM, Latin-1 and NUL
//! bytes, far-scaled columns), with random flags (`--weights`, `--cutoff`, `--max-rel-std`,
//! absurd `excite` options) and output files (fresh, existing, a directory, a missing
//! directory, the data file or the spec itself). No panic, crash, timeout, NaN, overwritten
//! input, unlocated error, incomplete output or temporary file.
//!
//! Budget: `NOCDYN_FUZZ_CASES` cases per generator (default 2,000), `NOCDYN_FUZZ_CLI_CASES`
//! binary runs (default 1,000, about 35 s on two cores), `NOCDYN_FUZZ_DATA_CASES` runs of
//! `identify` and `excite` (default 300, about 8 s); `NOCDYN_FUZZ_SEED` (a number) changes the
//! RNG seed; `NOCDYN_FUZZ_BIN` drives another binary (e.g. `target/release/codegen`). The
//! numbers are printed (`--nocapture`). A longer run:
//! `NOCDYN_FUZZ_CLI_CASES=20000 cargo test -p codegen --test fuzz binary -- --nocapture`.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use codegen::spec::Mechanism;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Inputs tried, specs that loaded, modules generated.
static TRIED: AtomicUsize = AtomicUsize::new(0);
static LOADED: AtomicUsize = AtomicUsize::new(0);
static COMPILED: AtomicUsize = AtomicUsize::new(0);

/// The largest mechanism (DOF, or legs for a parallel one) that is also generated.
const COMPILE_MAX_DOF: usize = 4;

fn cases() -> u32 {
    std::env::var("NOCDYN_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000)
}

fn runner(salt: u8) -> TestRunner {
    let seed: u64 = std::env::var("NOCDYN_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(7);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    bytes[8] = salt;
    let config = Config {
        cases: cases(),
        failure_persistence: None,
        // Shrinking re-runs compile; a failure is printed with its input anyway.
        max_shrink_iters: 64,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}

/// Feeds one input through the public entry points. `Err(message)` on a panic or on an
/// unrenderable error.
fn check(name: &str, src: &str) -> Result<(), TestCaseError> {
    TRIED.fetch_add(1, Ordering::Relaxed);
    let loaded = catch_unwind(AssertUnwindSafe(|| {
        codegen::spec::load_mechanism(name, src)
    }))
    .map_err(|_| TestCaseError::fail(format!("load_mechanism panicked on {name}:\n{src}")))?;
    let small = match &loaded {
        Err(e) => {
            check_rendered(name, src, e)?;
            return Ok(());
        }
        Ok((Mechanism::Tree(m), _)) => m.dof() <= COMPILE_MAX_DOF,
        Ok((Mechanism::Parallel(m), _)) => m.legs.len() <= 3,
        Ok((Mechanism::Closed(m), _)) => m.nx() <= COMPILE_MAX_DOF,
    };
    LOADED.fetch_add(1, Ordering::Relaxed);
    if !small {
        return Ok(());
    }
    let compiled = catch_unwind(AssertUnwindSafe(|| {
        codegen::compile(name, src, &codegen::Config::default())
    }))
    .map_err(|_| TestCaseError::fail(format!("compile panicked on {name}:\n{src}")))?;
    match compiled {
        Ok(g) => {
            COMPILED.fetch_add(1, Ordering::Relaxed);
            prop_assert!(g.code.contains("pub fn inverse_dynamics"), "{name}");
        }
        Err(e) => check_rendered(name, src, &e)?,
    }
    Ok(())
}

fn check_rendered(
    name: &str,
    src: &str,
    e: &codegen::diag::Diagnostics,
) -> Result<(), TestCaseError> {
    let r = e.render();
    prop_assert!(e.has_errors(), "{name}: Err without an error:\n{r}");
    prop_assert!(
        !r.contains("internal error"),
        "{name}: the reader panicked:\n{r}\ninput:\n{src}"
    );
    prop_assert!(
        e.iter().any(|d| d.is_error() && d.span.is_some()),
        "{name}: no located error:\n{r}\ninput:\n{src}"
    );
    prop_assert!(r.contains("error"), "{name}: renders as\n{r}");
    Ok(())
}

/// Numbers as TOML text: ordinary, extreme and non-finite values.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-3.0f64..3.0).prop_map(|x| format!("{x:?}")),
        1 => Just("0.0".to_owned()),
        1 => Just("-0.0".to_owned()),
        1 => Just("1".to_owned()),
        1 => Just("-1.5".to_owned()),
        1 => Just("nan".to_owned()),
        1 => Just("-inf".to_owned()),
        1 => Just("inf".to_owned()),
        1 => Just("1e300".to_owned()),
        1 => Just("1e9".to_owned()),
        1 => Just("-1e9".to_owned()),
        1 => Just("1e-300".to_owned()),
        1 => Just("5e-324".to_owned()),
        1 => Just("1e-13".to_owned()),
        1 => Just("9223372036854775807".to_owned()),
        1 => Just("0x10".to_owned()),
    ]
}

/// Valid but extreme numbers: tiny, subnormal, negative zero, the range limit.
fn finite() -> BoxedStrategy<String> {
    prop_oneof![
        6 => (-3.0f64..3.0).prop_map(|x| format!("{x:?}")),
        1 => Just("0.0".to_owned()),
        1 => Just("-0.0".to_owned()),
        1 => Just("1e9".to_owned()),
        1 => Just("-1e9".to_owned()),
        1 => Just("1e-300".to_owned()),
        1 => Just("5e-324".to_owned()),
    ]
    .boxed()
}

/// [`finite`] angles, also as angle strings.
fn angle() -> BoxedStrategy<String> {
    prop_oneof![
        4 => finite(),
        1 => Just("\"pi/2\"".to_owned()),
        1 => Just("\"-90deg\"".to_owned()),
    ]
    .boxed()
}

/// A value where a number is expected: mostly a number, sometimes of the wrong type.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        8 => number(),
        1 => Just("\"pi/2\"".to_owned()),
        1 => Just("\"90deg\"".to_owned()),
        1 => Just("\"2 kg\"".to_owned()),
        1 => Just("true".to_owned()),
        1 => Just("[1.0]".to_owned()),
        1 => Just("{ x = 1 }".to_owned()),
        1 => Just("1979-05-27".to_owned()),
    ]
}

fn triple_of(v: BoxedStrategy<String>) -> BoxedStrategy<String> {
    (v.clone(), v.clone(), v)
        .prop_map(|(a, b, c)| format!("[{a}, {b}, {c}]"))
        .boxed()
}

fn triple() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (value(), value(), value()).prop_map(|(a, b, c)| format!("[{a}, {b}, {c}]")),
        1 => (value(), value()).prop_map(|(a, b)| format!("[{a}, {b}]")),
        1 => Just("[0.0, 0.0, 1.0]".to_owned()),
        1 => Just("[1.0, 0.0, 0.0]".to_owned()),
        1 => Just("[0.0, 0.0, 0.0]".to_owned()),
        1 => Just("\"z\"".to_owned()),
    ]
}

/// Optionally misspells a key (a dropped, doubled or swapped letter) or leaves it out.
fn key(k: &'static str) -> impl Strategy<Value = Option<String>> {
    prop_oneof![
        12 => Just(Some(k.to_owned())),
        1 => Just(None),
        1 => (0..k.len()).prop_map(move |i| {
            let mut s = k.to_owned();
            s.remove(i);
            Some(s)
        }),
        1 => (0..k.len()).prop_map(move |i| {
            let mut s = k.to_owned();
            s.insert(i, s.as_bytes()[i] as char);
            Some(s)
        }),
        1 => Just(Some(k.to_uppercase())),
    ]
}

fn line(k: Option<String>, v: &str) -> String {
    k.map_or(String::new(), |k| format!("{k} = {v}\n"))
}

/// A body that is valid but for extreme values (mass 0 to 1e9, tiny inertias).
fn sane_body() -> BoxedStrategy<String> {
    (
        prop_oneof![
            Just("1.0".to_owned()),
            Just("0.0".to_owned()),
            Just("1e9".to_owned()),
            Just("1e-300".to_owned()),
            (0.0f64..5.0).prop_map(|x| format!("{x:?}"))
        ],
        triple_of(finite()),
        proptest::option::of((
            0.0f64..1.0,
            0.0f64..1.0,
            prop_oneof![Just(0.0), Just(1e-300), Just(5e-324)],
        )),
        proptest::option::of(triple_of(angle())),
    )
        .prop_map(|(m, c, inertia, rpy)| {
            let mut s = format!("[[body]]\nname = \"b0\"\nmass = {m}\ncom = {c}\n");
            if let Some((a, b, p)) = inertia {
                // Moments that satisfy the triangle inequality: a + b, a + b, plus a sliver.
                let (x, y) = (a + b + p, a + b + p);
                s += &format!(
                    "inertia = {{ ixx = {x:?}, iyy = {y:?}, izz = {:?} }}\n",
                    a + p
                );
            }
            if let Some(r) = rpy {
                s += &format!("inertia_rpy = {r}\n");
            }
            s
        })
        .boxed()
}

/// A joint that is valid but for extreme values; its parent is the base or an earlier body.
fn sane_joint(i: usize) -> BoxedStrategy<String> {
    let kinds = prop_oneof![4 => Just("R"), 2 => Just("P"), 1 => Just("U"), 1 => Just("S"), 1 => Just("fixed")];
    let parent = (0..i + 1).prop_map(move |p| {
        if p == i {
            "base".to_owned()
        } else {
            format!("b{p}")
        }
    });
    let axis = prop_oneof![
        Just("[0.0, 0.0, 1.0]".to_owned()),
        Just("[1e-11, 0.0, 0.0]".to_owned()),
        Just("[1e9, 1e9, -1e9]".to_owned()),
        triple_of((0.1f64..1.0).prop_map(|x| format!("{x:?}")).boxed()),
    ];
    (kinds, parent, triple_of(finite()), triple_of(angle()), axis, any::<bool>())
        .prop_map(move |(kind, parent, xyz, rpy, axis, mdh)| {
            let mut s = format!("[[joint]]\nname = \"j{i}\"\nkind = \"{kind}\"\nparent = \"{parent}\"\nchild = \"b{i}\"\n");
            if mdh && kind != "U" && kind != "S" {
                s += &format!("mdh = {{ a = 0.5, alpha = {}, d = 1e-300, theta = \"pi\" }}\n", &rpy[1..rpy.find(',').unwrap_or(1)].trim());
            } else {
                s += &format!("origin = {{ xyz = {xyz}, rpy = {rpy} }}\n");
                if kind == "R" || kind == "P" {
                    s += &format!("axis = {axis}\n");
                }
            }
            s
        })
        .boxed()
}

fn body(i: usize) -> impl Strategy<Value = String> {
    (
        key("name"),
        key("mass"),
        prop_oneof![3 => Just("1.0".to_owned()), 2 => value()],
        key("com"),
        triple(),
        proptest::option::of((value(), value(), value(), value())),
        proptest::option::of(triple()),
    )
        .prop_map(move |(kn, km, m, kc, c, inertia, rpy)| {
            let mut s = String::from("[[body]]\n");
            s += &line(kn, &format!("\"b{i}\""));
            s += &line(km, &m);
            s += &line(kc, &c);
            if let Some((a, b, c, d)) = inertia {
                s += &format!("inertia = {{ ixx = {a}, iyy = {b}, izz = {c}, ixy = {d} }}\n");
            }
            if let Some(r) = rpy {
                s += &format!("inertia_rpy = {r}\n");
            }
            s
        })
}

fn joint(i: usize, bodies: usize) -> impl Strategy<Value = String> {
    let kinds = prop_oneof![
        4 => Just("R"),
        2 => Just("prismatic"),
        1 => Just("U"),
        1 => Just("S"),
        1 => Just("fixed"),
        1 => Just("continuous"),
    ];
    // Parent: the base, an earlier body (a tree) or any body (loops, cycles, self-parents).
    let parent = prop_oneof![
        2 => Just("base".to_owned()),
        4 => (0..i.max(1)).prop_map(move |p| if i == 0 { "base".into() } else { format!("b{p}") }),
        1 => (0..bodies + 1).prop_map(|p| format!("b{p}")),
    ];
    let placement = prop_oneof![
        3 => Just(String::new()),
        3 => (triple(), triple()).prop_map(|(x, r)| format!("origin = {{ xyz = {x}, rpy = {r} }}\n")),
        1 => (value(), value(), value(), value())
            .prop_map(|(a, b, c, d)| format!("dh = {{ a = {a}, alpha = {b}, d = {c}, theta = {d} }}\n")),
        1 => (value(), value(), value(), value())
            .prop_map(|(a, b, c, d)| format!("mdh = {{ a = {a}, alpha = {b}, d = {c}, theta = {d} }}\n")),
    ];
    let axis = prop_oneof![
        2 => Just(String::new()),
        3 => triple().prop_map(|a| format!("axis = {a}\n")),
        1 => (triple(), triple()).prop_map(|(a, b)| format!("axes = [{a}, {b}]\n")),
    ];
    (
        key("name"),
        key("kind"),
        kinds,
        key("parent"),
        parent,
        key("child"),
        placement,
        axis,
    )
        .prop_map(move |(kn, kk, kind, kp, parent, kc, placement, axis)| {
            let mut s = String::from("[[joint]]\n");
            s += &line(kn, &format!("\"j{i}\""));
            s += &line(kk, &format!("\"{kind}\""));
            s += &line(kp, &format!("\"{parent}\""));
            s += &line(kc, &format!("\"b{i}\""));
            s + &placement + &axis
        })
}

/// A random small TOML spec: half of them valid but for extreme values (these are generated),
/// half with random mistakes.
fn toml_spec() -> impl Strategy<Value = String> {
    (1usize..=4, any::<bool>())
        .prop_flat_map(|(n, sane)| {
            let gravity = if sane {
                proptest::option::of(triple_of(finite())).boxed()
            } else {
                proptest::option::of(triple()).boxed()
            };
            let bodies = if sane {
                proptest::collection::vec(sane_body(), n).boxed()
            } else {
                proptest::collection::vec(body(0).boxed(), n).boxed()
            };
            let joints: Vec<BoxedStrategy<String>> = (0..n)
                .map(|i| {
                    if sane {
                        sane_joint(i)
                    } else {
                        joint(i, n).boxed()
                    }
                })
                .collect();
            (gravity, bodies, joints)
        })
        .prop_map(|(gravity, bodies, joints)| {
            let mut s = String::from("[mechanism]\nname = \"fuzz\"\n");
            if let Some(g) = gravity {
                s += &format!("gravity = {g}\n");
            }
            // Bodies share the name template b0; number them here.
            for (i, b) in bodies.iter().enumerate() {
                s += &b.replace("\"b0\"", &format!("\"b{i}\""));
            }
            for j in joints {
                s += &j;
            }
            s
        })
}

/// The bundled specs, (file name, text), sorted.
fn bundled() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs");
    let mut out: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension()
                .is_some_and(|e| e == "toml" || (e == "urdf" && cfg!(feature = "urdf")))
        })
        .map(|p| {
            let name = p.file_name().unwrap().to_str().unwrap().to_owned();
            (name, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    out.sort();
    assert!(out.len() >= 5, "bundled specs: {}", out.len());
    out
}

/// One edit of a text. Positions are fractions of the length, so one edit applies to any text.
#[derive(Clone, Debug)]
enum Edit {
    Insert(f64, &'static str),
    Delete(f64, usize),
    Truncate(f64),
    /// Replace the k-th number (mod the count) by a value.
    Number(usize, String),
    DuplicateLine(f64),
    DropLine(f64),
}

const TOKENS: &[&str] = &[
    "\"",
    "[",
    "]",
    "{",
    "}",
    "=",
    ",",
    "\n",
    "nan",
    "-",
    "pi/0",
    "1e999",
    "<",
    ">",
    "/>",
    "é",
    "0",
    " ",
    "\"base\"",
    "#",
    "[[joint]]",
    "[[body]]",
    "[platform]",
    "'",
    "inf",
    "</robot>",
    "<joint",
    "<link name=\"x\"/>",
    "\"\"\"",
    "\u{0}",
    "kind = \"S\"\n",
    "actuated = true\n",
];

fn edit() -> impl Strategy<Value = Edit> {
    let at = 0.0f64..1.0;
    prop_oneof![
        3 => (at.clone(), proptest::sample::select(TOKENS)).prop_map(|(a, t)| Edit::Insert(a, t)),
        2 => (at.clone(), 1usize..40).prop_map(|(a, n)| Edit::Delete(a, n)),
        1 => at.clone().prop_map(Edit::Truncate),
        4 => (any::<usize>(), number()).prop_map(|(k, v)| Edit::Number(k, v)),
        1 => at.clone().prop_map(Edit::DuplicateLine),
        1 => at.prop_map(Edit::DropLine),
    ]
}

fn boundary(s: &str, at: f64) -> usize {
    let mut i = ((s.len() as f64) * at) as usize;
    i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Byte ranges of the numbers in `s` (a digit run with sign, point and exponent).
fn numbers(s: &str) -> Vec<std::ops::Range<usize>> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit()
            && (i == 0 || !b[i - 1].is_ascii_alphanumeric() && b[i - 1] != b'_')
        {
            let mut start = i;
            if start > 0 && b[start - 1] == b'-' {
                start -= 1;
            }
            while i < b.len() && (b[i].is_ascii_digit() || matches!(b[i], b'.' | b'e' | b'E')) {
                i += 1;
            }
            out.push(start..i);
        } else {
            i += 1;
        }
    }
    out
}

fn apply(s: &mut String, e: &Edit, urdf: bool) {
    match e {
        Edit::Insert(at, t) => {
            let i = boundary(s, *at);
            s.insert_str(i, t);
        }
        Edit::Delete(at, n) => {
            let i = boundary(s, *at);
            let mut end = (i + n).min(s.len());
            while !s.is_char_boundary(end) {
                end -= 1;
            }
            s.replace_range(i..end, "");
        }
        Edit::Truncate(at) => {
            let i = boundary(s, *at);
            s.truncate(i);
        }
        Edit::Number(k, v) => {
            let nums = numbers(s);
            if !nums.is_empty() {
                let r = nums[k % nums.len()].clone();
                // URDF attributes hold plain numbers, not TOML words.
                let v = if urdf {
                    v.replace("0x10", "16")
                } else {
                    v.clone()
                };
                s.replace_range(r, &v);
            }
        }
        Edit::DuplicateLine(at) | Edit::DropLine(at) => {
            let mut lines: Vec<&str> = s.split_inclusive('\n').collect();
            if lines.is_empty() {
                return;
            }
            let i = ((lines.len() as f64 * at) as usize).min(lines.len() - 1);
            if matches!(e, Edit::DuplicateLine(_)) {
                lines.insert(i, lines[i]);
            } else {
                lines.remove(i);
            }
            *s = lines.concat();
        }
    }
}

fn report(what: &str, n: usize) {
    println!(
        "fuzz {what}: {n} inputs tried, 0 panics (this process so far: {} inputs, {} loaded, {} generated)",
        TRIED.load(Ordering::Relaxed),
        LOADED.load(Ordering::Relaxed),
        COMPILED.load(Ordering::Relaxed),
    );
}

#[test]
fn random_toml_specs_never_panic() {
    let n = AtomicUsize::new(0);
    let mut r = runner(1);
    r.run(&toml_spec(), |src| {
        n.fetch_add(1, Ordering::Relaxed);
        check("fuzz.toml", &src)
    })
    .unwrap_or_else(|e| panic!("{e}"));
    report("random TOML specs", n.into_inner());
}

#[test]
fn mutated_bundled_specs_never_panic() {
    let specs = bundled();
    let n = specs.len();
    let mut r = runner(2);
    let strategy = (0..n, proptest::collection::vec(edit(), 1..6));
    let tried = AtomicUsize::new(0);
    r.run(&strategy, |(k, edits)| {
        tried.fetch_add(1, Ordering::Relaxed);
        let (name, src) = &specs[k];
        let urdf = name.ends_with(".urdf");
        let mut s = src.clone();
        for e in &edits {
            apply(&mut s, e, urdf);
        }
        check(name, &s)
    })
    .unwrap_or_else(|e| panic!("{e}"));
    report("mutated bundled specs", tried.into_inner());
}

/// URDF attribute values (numbers, names, joint types) replaced by random words and numbers.
#[cfg(feature = "urdf")]
#[test]
fn mutated_urdf_attributes_never_panic() {
    let specs: Vec<(String, String)> = bundled()
        .into_iter()
        .filter(|(n, _)| n.ends_with(".urdf"))
        .collect();
    assert!(!specs.is_empty());
    let words = prop_oneof![
        3 => number().prop_map(|v| v.replace("0x10", "16")),
        1 => (number(), number(), number()).prop_map(|(a, b, c)| format!("{a} {b} {c}")),
        1 => proptest::sample::select(&[
            "", "base", "fixed", "floating", "planar", "continuous", "prismatic", "link1",
            "1 0", "0 0 0", "1 2 3 4", "${x}", "1,5", "&amp;", "<",
        ][..]).prop_map(str::to_owned),
    ];
    let strategy = (
        0..specs.len(),
        proptest::collection::vec((any::<usize>(), words), 1..5),
    );
    let mut r = runner(3);
    let tried = AtomicUsize::new(0);
    r.run(&strategy, |(k, subs)| {
        tried.fetch_add(1, Ordering::Relaxed);
        let (name, src) = &specs[k];
        // Attribute values: the text between `="` and the next `"`.
        let mut s = src.clone();
        for (which, w) in &subs {
            let starts: Vec<usize> = s.match_indices("=\"").map(|(i, _)| i + 2).collect();
            if starts.is_empty() {
                break;
            }
            let st = starts[which % starts.len()];
            let Some(len) = s[st..].find('"') else {
                continue;
            };
            s.replace_range(st..st + len, w);
        }
        check(name, &s)
    })
    .unwrap_or_else(|e| panic!("{e}"));
    report("mutated URDF attributes", tried.into_inner());
}

/// The binary, as a user runs it (Unix: `sh`, `ulimit`, signals).
#[cfg(unix)]
mod binary {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};

    use proptest::strategy::ValueTree;

    use super::*;

    /// Binary runs (default 1,000; `NOCDYN_FUZZ_CLI_CASES` for a longer run).
    fn cli_cases() -> usize {
        std::env::var("NOCDYN_FUZZ_CLI_CASES")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1000)
    }

    /// A run is killed after this long (`NOCDYN_FUZZ_TIMEOUT`, seconds): by default 5 s, or
    /// three times what the binary takes here on the bundled spec slowest to generate (the
    /// RUS hexapod with `--stats`), whichever is longer. A hang still fails; a slow or loaded
    /// machine, on which that spec alone takes most of 5 s, does not.
    fn cli_timeout() -> Duration {
        static LIMIT: std::sync::OnceLock<Duration> = std::sync::OnceLock::new();
        *LIMIT.get_or_init(|| {
            if let Some(s) = std::env::var("NOCDYN_FUZZ_TIMEOUT")
                .ok()
                .and_then(|s| s.parse().ok())
            {
                return Duration::from_secs_f64(s);
            }
            let spec =
                Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/rus_hexapod.toml");
            let start = Instant::now();
            let status = Command::new(binary())
                .arg(&spec)
                .arg("--stats")
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .status()
                .expect("the binary runs");
            assert!(status.success(), "{} --stats: {status}", spec.display());
            (3 * start.elapsed()).max(Duration::from_secs(5))
        })
    }

    /// The binary driven: the one cargo built for the tests, or `NOCDYN_FUZZ_BIN` (e.g. a release
    /// build).
    fn binary() -> String {
        std::env::var("NOCDYN_FUZZ_BIN")
            .unwrap_or_else(|_| env!("CARGO_BIN_EXE_codegen").to_owned())
    }

    /// Runs the binary in `dir` with `args` as a user would (no stdin, a 2 GB address-space
    /// limit), its stdout and stderr to files `stdout` and `stderr` there. The status, `None`
    /// when it ran past `cli_timeout()` and was killed, and what it wrote to stdout.
    fn run_binary(dir: &Path, args: &[String]) -> (Option<std::process::ExitStatus>, Vec<u8>) {
        let stdout = std::fs::File::create(dir.join("stdout")).unwrap();
        let stderr = std::fs::File::create(dir.join("stderr")).unwrap();
        let mut child = Command::new("sh")
            .current_dir(dir)
            .arg("-c")
            .arg("ulimit -v 2000000 && exec \"$0\" \"$@\"")
            .arg(binary())
            .args(args)
            .stdin(Stdio::null())
            .stdout(stdout)
            .stderr(stderr)
            .spawn()
            .expect("sh runs");
        let start = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break Some(s);
            }
            if start.elapsed() > cli_timeout() {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        (status, std::fs::read(dir.join("stdout")).unwrap())
    }

    /// SplitMix64: the few random choices of the binary runs.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n.max(1) as u64) as usize
        }
        fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
            &xs[self.below(xs.len())]
        }
        fn chance(&mut self, percent: usize) -> bool {
            self.below(100) < percent
        }
    }

    /// Where `-o` points, and what was there before the run.
    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Out {
        /// No `-o`: the module goes to stdout.
        Stdout,
        /// A file that does not exist yet.
        Fresh,
        /// A file holding an older module.
        Existing,
        /// A directory (the write must fail: exit 1).
        Directory,
        /// A file in a directory that does not exist (exit 1).
        NoDir,
    }

    /// One binary run: the spec file's name and bytes, the flags, where the output goes, and
    /// whether the flags are invalid by construction (then exit 2 with clap's message).
    #[derive(Debug)]
    struct Case {
        what: &'static str,
        file: String,
        bytes: Vec<u8>,
        flags: Vec<String>,
        out: Out,
        bad_args: bool,
    }

    /// A valid spec of a body-and-joint chain, with `name`s for the chain's parts.
    fn chain(mech: &str, body: &str, joint: &str, parent_ref: &str) -> String {
        format!(
            "[mechanism]\nname = \"{mech}\"\n\n[[body]]\nname = \"{body}\"\nmass = 1.0\n\n\
         [[joint]]\nname = \"{joint}\"\nkind = \"R\"\nparent = \"{parent_ref}\"\nchild = \"{body}\"\n"
        )
    }

    /// A URDF robot with one revolute joint; `extra` goes inside the first link.
    fn robot(link: &str, child_ref: &str, extra: &str) -> String {
        format!(
            "<robot name=\"r\">\n<link name=\"base\">{extra}</link>\n<link name=\"{link}\"><inertial><mass value=\"1\"/>\
         <inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial></link>\n\
         <joint name=\"j\" type=\"revolute\"><parent link=\"base\"/><child link=\"{child_ref}\"/></joint>\n</robot>\n"
        )
    }

    /// The inputs that took the process down or used it up before: deep nesting, long names, bad
    /// encodings, plus random bytes. (file name, bytes).
    fn hostile(rng: &mut Rng, specs: &[(String, String)]) -> (&'static str, String, Vec<u8>) {
        let (name, good) = rng.pick(specs).clone();
        match rng.below(9) {
            0 => {
                let depth = *rng.pick(&[10, 62, 63, 64, 65, 200, 5_000, 20_000]);
                let closed = rng.chance(50);
                let inner = format!(
                    "{}{}",
                    "<a>".repeat(depth),
                    if closed {
                        "</a>".repeat(depth)
                    } else {
                        String::new()
                    }
                );
                let text = if rng.chance(50) {
                    robot("l1", "l1", &format!("<visual>{inner}</visual>"))
                } else {
                    format!("<robot name=\"r\">{inner}</robot>\n")
                };
                ("deep XML", "deep.urdf".into(), text.into_bytes())
            }
            1 => {
                let depth = *rng.pick(&[10, 79, 80, 81, 90, 300, 3_000]);
                let key = vec!["a"; depth].join(if rng.chance(30) { " . " } else { "." });
                let head = chain("m", "b1", "j1", "base");
                let text = match rng.below(4) {
                    0 => format!("{head}{key} = 1\n"),
                    1 => format!("{head}[{key}]\nx = 1\n"),
                    2 => format!("{head}v = {}1{}\n", "[".repeat(depth), "]".repeat(depth)),
                    _ => format!("{head}v = {}1{}\n", "{a=".repeat(depth), "}".repeat(depth)),
                };
                ("deep TOML", "deep.toml".into(), text.into_bytes())
            }
            2 | 3 => {
                let n = *rng.pick(&[64, 127, 128, 129, 1_000, 20_000]);
                let long = "a".repeat(n);
                let near = format!("{}b", &long[1..]);
                let text = match rng.below(5) {
                    0 => chain("m", &long, "j1", "base"),
                    1 => chain("m", "b1", &long, "base"),
                    2 => chain(&long, "b1", "j1", "base"),
                    3 => chain("m", &long, "j1", &near).replace(
                        &format!("child = \"{long}\""),
                        &format!("child = \"{near}\""),
                    ),
                    _ => {
                        return (
                            "long name",
                            "long.urdf".into(),
                            robot(&long, &near, "").into_bytes(),
                        );
                    }
                };
                ("long name", "long.toml".into(), text.into_bytes())
            }
            4 | 5 => {
                let bytes: Vec<u8> = match rng.below(6) {
                    0 => [0xff, 0xfe]
                        .into_iter()
                        .chain(good.encode_utf16().flat_map(u16::to_le_bytes))
                        .collect(),
                    1 => [0xfe, 0xff]
                        .into_iter()
                        .chain(good.encode_utf16().flat_map(u16::to_be_bytes))
                        .collect(),
                    2 => {
                        // One Latin-1 byte somewhere.
                        let mut b = good.clone().into_bytes();
                        let at = rng.below(b.len() + 1);
                        b.insert(at, *rng.pick(&[0xe9u8, 0xfc, 0xb0, 0x80, 0xff]));
                        b
                    }
                    3 => {
                        // Cut inside a character.
                        let mut b = format!("{good}# \u{e9}\u{1F600}").into_bytes();
                        b.truncate(b.len() - 1 - rng.below(3));
                        b
                    }
                    4 => format!("\u{feff}{good}").into_bytes(),
                    _ => {
                        let mut b = good.clone().into_bytes();
                        let at = rng.below(b.len() + 1);
                        b.insert(at, 0);
                        b
                    }
                };
                ("bad encoding", name, bytes)
            }
            6 if rng.chance(40) => {
                // Many errors, on one line or one per line.
                let n = *rng.pick(&[1_000, 20_000, 50_000]);
                let head = chain("m", "b1", "j1", "base");
                let text = if rng.chance(50) {
                    format!(
                        "{head}[scene]\npoint_mass = [{}]\n",
                        vec!["\"bx\""; n].join(",")
                    )
                } else {
                    let keys: String = (0..n).map(|k| format!("k{k} = 1\n")).collect();
                    head.replacen("[mechanism]\n", &format!("[mechanism]\n{keys}"), 1)
                };
                ("many errors", "many.toml".into(), text.into_bytes())
            }
            6 => {
                let n = rng.below(4096);
                let bytes = (0..n).map(|_| rng.next() as u8).collect();
                let file = if rng.chance(50) {
                    "noise.toml"
                } else {
                    "noise.urdf"
                };
                ("random bytes", file.into(), bytes)
            }
            _ => {
                let file = if rng.chance(50) {
                    "empty.toml"
                } else {
                    "empty.urdf"
                };
                ("empty", file.into(), Vec::new())
            }
        }
    }

    /// Random flags: valid ones, and now and then an invalid one (`bad` is set).
    fn flags(rng: &mut Rng, bad: &mut bool) -> Vec<String> {
        let mut f: Vec<String> = Vec::new();
        let mut push = |s: &str| f.push(s.to_owned());
        for flag in ["--check", "--stats", "--friction", "--rotor-inertia"] {
            if rng.chance(if flag == "--check" { 25 } else { 15 }) {
                push(flag);
            }
        }
        if rng.chance(20) {
            let (tol, ok) = *rng.pick(&[
                ("1e-6", true),
                ("0.01", true),
                ("1e-300", true),
                ("0.5", false),
                ("nan", false),
                ("0", false),
                ("-1", false),
                ("inf", false),
                ("x", false),
            ]);
            push("--snap");
            push(tol);
            *bad |= !ok;
        }
        if rng.chance(15) {
            let (m, ok) = *rng.pick(&[
                ("libm", true),
                ("std", true),
                ("runtime", true),
                ("fast", false),
            ]);
            push("--math");
            push(m);
            *bad |= !ok;
        }
        if rng.chance(15) {
            let (m, ok) = *rng.pick(&[("f32", true), ("f64", true), ("f16", false)]);
            push("--float");
            push(m);
            *bad |= !ok;
        }
        if rng.chance(10) {
            push("--fma");
        }
        if rng.chance(10) {
            push("--batch-sin-cos");
        }
        if rng.chance(10) {
            // 2 to 16 states per call, for every kind of mechanism; other counts are refused,
            // naming the flag.
            let (n, ok) = *rng.pick(&[
                ("2", true),
                ("4", true),
                ("16", true),
                ("0", false),
                ("1", false),
                ("17", false),
                ("99999", false),
                ("-1", false),
                ("abc", false),
            ]);
            push(&format!("--lanes={n}"));
            *bad |= !ok;
        }
        if rng.chance(3) {
            push("--bogus");
            *bad = true;
        }
        f
    }

    fn case(rng: &mut Rng, specs: &[(String, String)], toml: &mut TestRunner) -> Case {
        let (what, file, bytes) = match rng.below(10) {
            0..=3 => {
                let (name, src) = rng.pick(specs);
                let mut s = src.clone();
                let urdf = name.ends_with(".urdf");
                for _ in 0..rng.below(5) {
                    let e = edit().new_tree(toml).expect("an edit").current();
                    apply(&mut s, &e, urdf);
                }
                ("mutated spec", name.clone(), s.into_bytes())
            }
            4..=5 => {
                let s = toml_spec().new_tree(toml).expect("a spec").current();
                ("random TOML", "fuzz.toml".to_owned(), s.into_bytes())
            }
            _ => hostile(rng, specs),
        };
        let mut bad_args = false;
        let flags = flags(rng, &mut bad_args);
        let out = *rng.pick(&[
            Out::Stdout,
            Out::Stdout,
            Out::Fresh,
            Out::Existing,
            Out::Existing,
            Out::Directory,
            Out::NoDir,
        ]);
        Case {
            what,
            file,
            bytes,
            flags,
            out,
            bad_args,
        }
    }

    /// What the runs found.
    #[derive(Default)]
    struct Tally {
        tried: usize,
        exits: [usize; 3],
        panics: usize,
        signals: usize,
        timeouts: usize,
        unlocated: usize,
        /// Other broken promises: an unexpected exit code, a missing or changed output, temporary
        /// files left behind.
        wrong: usize,
        failures: Vec<String>,
    }

    impl Tally {
        fn fail(&mut self, kind: &str, c: &Case, dir: &Path, detail: &str) {
            if self.failures.len() < 8 {
                // Kept for reproduction beside the case's directory (which the next case
                // empties).
                let keep = dir.parent().unwrap_or(dir).join(format!(
                    "failure-{}-{}",
                    self.failures.len(),
                    c.file
                ));
                let _ = std::fs::write(&keep, &c.bytes);
                self.failures.push(format!(
                    "{kind} ({}, {}, flags {:?}, out {:?}; input kept in {}):\n{detail:.2000}",
                    c.what,
                    c.file,
                    c.flags,
                    c.out,
                    keep.display()
                ));
            }
        }
    }

    /// `true` when `err` has `file:LINE:COL`.
    fn located(err: &str, file: &str) -> bool {
        let pat = format!("{file}:");
        err.match_indices(&pat).any(|(i, _)| {
            let rest = &err[i + pat.len()..];
            let line = rest.bytes().take_while(u8::is_ascii_digit).count();
            let col = rest[line..]
                .strip_prefix(':')
                .map_or(0, |r| r.bytes().take_while(u8::is_ascii_digit).count());
            line > 0 && col > 0
        })
    }

    /// Runs one case in `dir` (emptied first) under a 2 GB address-space limit, and checks it.
    fn run_case(c: &Case, dir: &Path, tally: &mut Tally) {
        use std::os::unix::process::ExitStatusExt;
        let _ = std::fs::remove_dir_all(dir);
        let outs = dir.join("out");
        std::fs::create_dir_all(&outs).unwrap();
        let spec = dir.join(&c.file);
        std::fs::write(&spec, &c.bytes).unwrap();
        const OLD: &str = "// an older module\n";
        let target = match c.out {
            Out::Stdout => None,
            Out::Fresh => Some(outs.join("module.rs")),
            Out::Existing => {
                let p = outs.join("module.rs");
                std::fs::write(&p, OLD).unwrap();
                Some(p)
            }
            Out::Directory => {
                let p = outs.join("module.rs");
                std::fs::create_dir(&p).unwrap();
                Some(p)
            }
            Out::NoDir => Some(outs.join("missing").join("module.rs")),
        };
        let before = listing(&outs);
        let mut args: Vec<String> = vec![c.file.clone()];
        args.extend(c.flags.iter().cloned());
        if let Some(t) = &target {
            args.push("-o".into());
            args.push(t.to_str().unwrap().into());
        }
        tally.tried += 1;
        let (status, out) = run_binary(dir, &args);
        let err = String::from_utf8_lossy(&std::fs::read(dir.join("stderr")).unwrap()).into_owned();
        let Some(status) = status else {
            tally.timeouts += 1;
            return tally.fail("timeout", c, dir, &err);
        };
        let code = match status.code() {
            Some(code) => code,
            None => {
                tally.signals += 1;
                let detail = format!("signal {:?}\n{err}", status.signal());
                return tally.fail("crash", c, dir, &detail);
            }
        };
        if code == 101 || err.contains("panicked") || err.contains("internal error") {
            tally.panics += 1;
            return tally.fail("panic", c, dir, &err);
        }
        if let Some(k) = tally.exits.get_mut(code as usize) {
            *k += 1;
        }
        let check = c.flags.iter().any(|f| f == "--check");
        let unwritable = matches!(c.out, Out::Directory | Out::NoDir);
        let expected: &[i32] = if c.bad_args {
            &[2]
        } else if unwritable && !check {
            &[1, 2]
        } else {
            &[0, 2]
        };
        if !expected.contains(&code) {
            tally.wrong += 1;
            return tally.fail(&format!("exit {code}"), c, dir, &err);
        }
        let flag_named =
            c.flags.iter().any(|f| f.starts_with("--lanes")) && err.contains("error: --lanes");
        if code == 2 && !c.bad_args && !located(&err, &c.file) && !flag_named {
            tally.unlocated += 1;
            return tally.fail("unlocated error", c, dir, &err);
        }
        // The output: the module where it belongs on success, the old file untouched otherwise,
        // and never a temporary file left behind.
        let written = target.as_ref().and_then(|t| std::fs::read(t).ok());
        let problem = if code == 0 && !check {
            let module = if target.is_some() {
                written.unwrap_or_default()
            } else {
                out
            };
            let stats = !c.flags.iter().any(|f| f == "--stats") || err.contains("| function |");
            (!(String::from_utf8_lossy(&module).contains("pub fn") && stats))
                .then_some("no module (or no --stats table)")
        } else if c.out == Out::Existing && written.as_deref() != Some(OLD.as_bytes()) {
            Some("the old module was changed")
        } else if c.out == Out::Fresh && written.is_some() {
            Some("a module was written")
        } else {
            None
        };
        let after = listing(&outs);
        let stray = after
            .iter()
            .any(|n| !before.contains(n) && n != "module.rs");
        if let Some(p) = problem.or(stray.then_some("temporary files left behind")) {
            tally.wrong += 1;
            tally.fail(p, c, dir, &err);
        }
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .map(|r| {
                r.map(|e| e.unwrap().file_name().into_string().unwrap())
                    .collect()
            })
            .unwrap_or_default();
        v.sort();
        v
    }

    /// The binary as a user runs it: random, mutated and hostile specs (deep nesting, long names,
    /// bad encodings, random bytes) with random flags and `-o` targets, two runs at a time. No
    /// panic, no crash by signal, no timeout, no exit 2 without a `file:line:col`, and the exit
    /// codes, `-o` files and `--stats` table as documented.
    #[test]
    fn the_binary_never_crashes_hangs_or_goes_unlocated() {
        let specs = bundled();
        let n = cli_cases();
        let seed: u64 = std::env::var("NOCDYN_FUZZ_SEED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(7);
        let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz_cli");
        let _ = std::fs::remove_dir_all(&root);
        let start = Instant::now();
        let tallies: Vec<Tally> = std::thread::scope(|s| {
            let workers: Vec<_> = (0..2u64)
                .map(|w| {
                    let specs = &specs;
                    let dir = root.join(format!("w{w}"));
                    s.spawn(move || {
                        let mut rng = Rng(seed ^ (w << 32) ^ 0x5eed);
                        let mut toml = runner(10 + w as u8);
                        let mut tally = Tally::default();
                        for _ in (w as usize..n).step_by(2) {
                            let c = case(&mut rng, specs, &mut toml);
                            run_case(&c, &dir.join("case"), &mut tally);
                        }
                        tally
                    })
                })
                .collect();
            workers.into_iter().map(|w| w.join().unwrap()).collect()
        });
        let mut t = Tally::default();
        for x in tallies {
            t.tried += x.tried;
            for k in 0..3 {
                t.exits[k] += x.exits[k];
            }
            t.panics += x.panics;
            t.signals += x.signals;
            t.timeouts += x.timeouts;
            t.unlocated += x.unlocated;
            t.wrong += x.wrong;
            t.failures.extend(x.failures);
        }
        println!(
            "fuzz the binary: {} inputs tried in {:.1} s (exit 0: {}, 1: {}, 2: {}); {} panics, {} crashes by signal, {} timeouts (> {:?}), {} unlocated errors, {} other failures",
            t.tried,
            start.elapsed().as_secs_f64(),
            t.exits[0],
            t.exits[1],
            t.exits[2],
            t.panics,
            t.signals,
            t.timeouts,
            cli_timeout(),
            t.unlocated,
            t.wrong
        );
        for f in &t.failures {
            println!("{f}\n");
        }
        assert_eq!(t.tried, n);
        assert_eq!(
            (t.panics, t.signals, t.timeouts, t.unlocated, t.wrong),
            (0, 0, 0, 0, 0),
            "(panics, crashes by signal, timeouts, unlocated errors, other failures); see above"
        );
    }

    /// `identify` and `excite` driven the same way: measurement files made by `excite
    /// --with-tau` for a tree, a closed loop and a platform, mutated (hostile cells, lost,
    /// doubled, renamed and extra columns, positions only, time that stalls or runs back,
    /// constant rows, cut files, CRLF, a byte-order mark, Latin-1 and NUL bytes, scaled columns)
    /// and run with random flags and output files (fresh, existing, a directory, a missing
    /// directory, the data file or the spec itself); `excite` with absurd options.
    mod data {
        use std::path::{Path, PathBuf};
        use std::process::Command;
        use std::time::Instant;

        use super::{Rng, listing};

        /// Runs (default 300, one in six of `excite`; `NOCDYN_FUZZ_DATA_CASES`).
        fn data_cases() -> usize {
            std::env::var("NOCDYN_FUZZ_DATA_CASES")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(300)
        }

        /// A spec and the measurements `excite` made for it.
        struct Source {
            spec: &'static str,
            bytes: Vec<u8>,
            csv: String,
            joints: Vec<&'static str>,
        }

        /// Where an output flag points.
        #[derive(Clone, Copy, Debug, PartialEq)]
        enum Target {
            Fresh,
            Existing,
            Directory,
            NoDir,
            /// The data file (identify) or the spec: must be refused, the input untouched.
            Input,
        }

        #[derive(Debug)]
        struct Run {
            what: String,
            args: Vec<String>,
            csv: Option<Vec<u8>>,
            spec: &'static str,
            spec_bytes: Vec<u8>,
            /// (flag, target, file name) of each output.
            outputs: Vec<(&'static str, Target, &'static str)>,
            bad_args: bool,
        }

        fn spec_path(name: &str) -> PathBuf {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../mechanisms/specs")
                .join(name)
        }

        /// One `excite --with-tau` run per spec (a short search).
        fn sources(dir: &Path) -> Vec<Source> {
            std::fs::create_dir_all(dir).unwrap();
            [
                ("planar_2r.toml", vec!["j1", "j2"]),
                ("four_bar.toml", vec!["crank_joint"]),
                ("delta_rl5.toml", vec![]),
            ]
            .into_iter()
            .map(|(spec, joints)| {
                let out = dir.join(format!("{spec}.csv"));
                let o = Command::new(super::binary())
                    .args(["excite", spec_path(spec).to_str().unwrap()])
                    .args(["--restarts", "1", "--evaluations", "4", "--search-samples"])
                    .args(["40", "--samples", "120", "--with-tau", "--noise", "0.01"])
                    .arg("-o")
                    .arg(&out)
                    .output()
                    .expect("excite runs");
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                Source {
                    spec,
                    bytes: std::fs::read(spec_path(spec)).unwrap(),
                    csv: std::fs::read_to_string(&out).unwrap(),
                    joints,
                }
            })
            .collect()
        }

        const CELLS: &[&str] = &[
            "NaN",
            "nan",
            "inf",
            "-inf",
            "1e308",
            "-1e308",
            "1e300",
            "1e160",
            "4.9e-324",
            "1e-310",
            "",
            " ",
            "x",
            "0x10",
            "1e",
            "--1",
            "1.2.3",
            "\"1\"",
            "1_0",
            "+0",
            "-0",
            "١",
            "\u{0}",
            "１",
            "9999999999999999999999",
        ];

        /// 0–2 random mutations of `csv` (bytes: some leave UTF-8).
        fn mutate(rng: &mut Rng, src: &Source) -> (String, Vec<u8>) {
            let mut lines: Vec<String> = src.csv.lines().map(str::to_owned).collect();
            let mut names = Vec::new();
            let mut bytes_edit: Option<u8> = None;
            // A third unchanged, so that the outputs of successful runs are checked too.
            for _ in 0..rng.below(3) {
                if lines.is_empty() {
                    break;
                }
                let header: Vec<String> = lines
                    .first()
                    .map(|h| h.split(',').map(str::to_owned).collect())
                    .unwrap_or_default();
                let cols = header.len().max(1);
                let row = 1 + rng.below(lines.len().saturating_sub(1).max(1));
                let kind = rng.below(15);
                names.push(kind.to_string());
                match kind {
                    0 | 1 => {
                        // A hostile cell.
                        if let Some(l) = lines.get_mut(row) {
                            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
                            let c = rng.below(f.len());
                            f[c] = (*rng.pick(CELLS)).to_owned();
                            *l = f.join(",");
                        }
                    }
                    2 => {
                        // A column renamed: by joint name, upper case, empty, or another's.
                        let c = rng.below(cols);
                        let to = match rng.below(4) {
                            0 if !src.joints.is_empty() => {
                                format!("q_{}", rng.pick(&src.joints))
                            }
                            1 => header.get(c).map_or(String::new(), |h| h.to_uppercase()),
                            2 => String::new(),
                            _ if header.is_empty() => String::new(),
                            _ => rng.pick(&header).clone(),
                        };
                        let mut h = header.clone();
                        if let Some(x) = h.get_mut(c) {
                            *x = to;
                        }
                        lines[0] = h.join(",");
                    }
                    3 => {
                        // A column dropped or doubled, everywhere.
                        let c = rng.below(cols);
                        let double = rng.chance(50);
                        for l in &mut lines {
                            let mut f: Vec<&str> = l.split(',').collect();
                            if c < f.len() {
                                if double {
                                    f.push(f[c]);
                                } else {
                                    f.remove(c);
                                }
                            }
                            *l = f.join(",");
                        }
                    }
                    4 => {
                        // An extra column of labels (ignored), or a trailing comma.
                        let label = rng.chance(50);
                        for (k, l) in lines.iter_mut().enumerate() {
                            l.push_str(match (k, label) {
                                (0, true) => ",label",
                                (_, true) => ",run A",
                                _ => ",",
                            });
                        }
                    }
                    5 => {
                        // Positions only: the speeds and accelerations dropped.
                        let keep: Vec<usize> = (0..header.len())
                            .filter(|&c| {
                                let h = &header[c];
                                !(h.starts_with("qd") || h.starts_with('u') || h.starts_with("ud"))
                            })
                            .collect();
                        for l in &mut lines {
                            let f: Vec<&str> = l.split(',').collect();
                            *l = keep
                                .iter()
                                .filter_map(|&c| f.get(c).copied())
                                .collect::<Vec<_>>()
                                .join(",");
                        }
                    }
                    6 => {
                        // Time that stalls, runs back, or steps by a subnormal.
                        let how = rng.below(3);
                        for (k, l) in lines.iter_mut().enumerate().skip(1) {
                            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
                            f[0] = match how {
                                0 => "0".into(),
                                1 => format!("{}", -(k as f64)),
                                _ => format!("{:e}", k as f64 * 1e-320),
                            };
                            *l = f.join(",");
                        }
                    }
                    7 => {
                        // Lines lost, doubled or swapped.
                        match rng.below(3) {
                            0 if lines.len() > 1 => {
                                let n = 1 + rng.below(lines.len() - 1);
                                lines.truncate(n);
                            }
                            1 => {
                                let l = lines[row.min(lines.len() - 1)].clone();
                                lines.insert(row.min(lines.len()), l);
                            }
                            _ => {
                                let (n, other) = (lines.len(), rng.below(lines.len()));
                                lines.swap(row.min(n - 1), other);
                            }
                        }
                    }
                    8 => {
                        // Every row the same (a regressor of rank deficit), or all zeros.
                        let zeros = rng.chance(50);
                        let first = lines.get(1).cloned().unwrap_or_default();
                        for l in lines.iter_mut().skip(1) {
                            *l = if zeros {
                                vec!["0"; cols].join(",")
                            } else {
                                first.clone()
                            };
                        }
                    }
                    9 => {
                        // A column scaled far out.
                        let c = rng.below(cols);
                        let by = *rng.pick(&[1e150, 1e200, 1e-300, -1e100]);
                        for l in lines.iter_mut().skip(1) {
                            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
                            if let Some(x) = f.get_mut(c)
                                && let Ok(v) = x.parse::<f64>()
                            {
                                *x = format!("{:e}", v * by);
                            }
                            *l = f.join(",");
                        }
                    }
                    10 => {
                        // Comments and blank lines anywhere.
                        lines.insert(row.min(lines.len()), "# a note".into());
                        lines.insert(rng.below(lines.len() + 1), String::new());
                    }
                    11 => lines.truncate(rng.below(2)),
                    12 => bytes_edit = Some(*rng.pick(&[0xe9u8, 0xff, 0x00, 0xc3])),
                    _ => {}
                }
            }
            let crlf = rng.chance(10);
            let mut text = lines.join(if crlf { "\r\n" } else { "\n" });
            if rng.chance(90) {
                text.push('\n');
            }
            if rng.chance(10) {
                text.insert(0, '\u{feff}');
            }
            let mut bytes = text.into_bytes();
            if rng.chance(5) && !bytes.is_empty() {
                let cut = rng.below(bytes.len());
                bytes.truncate(cut);
            }
            if let Some(b) = bytes_edit
                && !bytes.is_empty()
            {
                let at = rng.below(bytes.len());
                bytes.insert(at, b);
            }
            (format!("csv edits {}", names.join("+")), bytes)
        }

        fn target(rng: &mut Rng) -> Target {
            *rng.pick(&[
                Target::Fresh,
                Target::Fresh,
                Target::Existing,
                Target::Directory,
                Target::NoDir,
                Target::Input,
            ])
        }

        fn identify_run(rng: &mut Rng, src: &Source) -> Run {
            let (what, csv) = mutate(rng, src);
            let mut args: Vec<String> =
                vec!["identify".into(), "spec.toml".into(), "data.csv".into()];
            let mut bad_args = false;
            let mut outputs = Vec::new();
            if rng.chance(25) {
                let (w, ok) = *rng.pick(&[("auto", true), ("none", true), ("heavy", false)]);
                args.extend(["--weights".into(), w.into()]);
                bad_args |= !ok;
            }
            if rng.chance(25) {
                let (c, ok) = *rng.pick(&[
                    ("2", true),
                    ("0.5", true),
                    ("0", true),
                    ("-1", true),
                    ("nan", true),
                    ("inf", true),
                    ("1e-300", true),
                    ("1e308", true),
                    ("abc", false),
                ]);
                args.push(format!("--cutoff={c}"));
                bad_args |= !ok;
            }
            if rng.chance(10) {
                let m = *rng.pick(&["1", "1e-300", "1e308", "0", "nan"]);
                args.push(format!("--max-rel-std={m}"));
            }
            for (flag, file) in [
                ("--estimates", "est.csv"),
                ("--plot", "plot.svg"),
                ("--out", "updated.toml"),
            ] {
                if rng.chance(25) {
                    outputs.push((flag, target(rng), file));
                }
            }
            Run {
                what,
                args,
                csv: Some(csv),
                spec: src.spec,
                spec_bytes: src.bytes.clone(),
                outputs,
                bad_args,
            }
        }

        fn excite_run(rng: &mut Rng, src: &Source) -> Run {
            let mut args: Vec<String> = vec!["excite".into(), "spec.toml".into()];
            let mut bad_args = false;
            // Each search stays short: a few evaluations, few restarts.
            args.push(format!("--evaluations={}", rng.below(12)));
            args.push(format!("--restarts={}", *rng.pick(&[0, 1, 1, 2])));
            args.push(format!("--search-samples={}", *rng.pick(&[0, 5, 20, 40])));
            args.push(format!("--samples={}", *rng.pick(&[0, 3, 50, 200])));
            for (flag, values) in [
                ("--harmonics", &["0", "1", "3", "51"][..]),
                (
                    "--period",
                    &["0.5", "1e-4", "1e308", "nan", "1e5", "-1"][..],
                ),
                ("--q-max", &["0.5", "1e308", "0", "1,2", "1e-300"][..]),
                ("--qd-max", &["0.5", "inf", "1,2,3"][..]),
                ("--reach", &["0.01", "0", "1e3"][..]),
                ("--turn", &["0.05", "10", "nan"][..]),
                ("--seed", &["0", "18446744073709551615"][..]),
            ] {
                if rng.chance(30) {
                    args.push(format!("{flag}={}", rng.pick(values)));
                }
            }
            if rng.chance(40) {
                args.push("--with-tau".into());
                if rng.chance(50) {
                    args.push(format!(
                        "--noise={}",
                        rng.pick(&["0.01", "1e308", "nan", "0,1"])
                    ));
                }
            } else if rng.chance(5) {
                // `--noise` without `--with-tau`: refused by the parser.
                args.push("--noise=0.1".into());
                bad_args = true;
            }
            if rng.chance(5) {
                args.push("--period=abc".into());
                bad_args = true;
            }
            let outputs = if rng.chance(70) {
                vec![("-o", target(rng), "traj.csv")]
            } else {
                Vec::new()
            };
            Run {
                what: "excite".into(),
                args,
                csv: None,
                spec: src.spec,
                spec_bytes: src.bytes.clone(),
                outputs,
                bad_args,
            }
        }

        #[derive(Default)]
        struct Tally {
            tried: usize,
            exits: [usize; 3],
            bad: usize,
            failures: Vec<String>,
        }

        impl Tally {
            fn fail(&mut self, kind: &str, r: &Run, dir: &Path, err: &str) {
                self.bad += 1;
                if self.failures.len() < 8 {
                    // Beside the case's directory, which the next case empties.
                    let keep = dir
                        .parent()
                        .unwrap_or(dir)
                        .join(format!("failure-{}.csv", self.failures.len()));
                    if let Some(c) = &r.csv {
                        let _ = std::fs::write(&keep, c);
                    }
                    self.failures.push(format!(
                        "{kind} ({}, {}, args {:?}, outputs {:?}; data kept in {}):\n{err:.1500}",
                        r.what,
                        r.spec,
                        r.args,
                        r.outputs,
                        keep.display()
                    ));
                }
            }
        }

        const OLD: &str = "an older file\n";

        fn run_one(r: &Run, dir: &Path, tally: &mut Tally) {
            use std::os::unix::process::ExitStatusExt;
            let _ = std::fs::remove_dir_all(dir);
            let outs = dir.join("out");
            std::fs::create_dir_all(&outs).unwrap();
            std::fs::write(dir.join("spec.toml"), &r.spec_bytes).unwrap();
            if let Some(c) = &r.csv {
                std::fs::write(dir.join("data.csv"), c).unwrap();
            }
            let mut args = r.args.clone();
            let mut refused = false;
            let mut unwritable = false;
            for (flag, t, file) in &r.outputs {
                let p = outs.join(file);
                let path = match t {
                    Target::Fresh => p,
                    Target::Existing => {
                        std::fs::write(&p, OLD).unwrap();
                        p
                    }
                    Target::Directory => {
                        std::fs::create_dir(&p).unwrap();
                        unwritable = true;
                        p
                    }
                    Target::NoDir => {
                        unwritable = true;
                        outs.join("missing").join(file)
                    }
                    Target::Input => {
                        refused = true;
                        dir.join(if r.csv.is_some() && flag.len() % 2 == 1 {
                            "data.csv"
                        } else {
                            "spec.toml"
                        })
                    }
                };
                args.push(flag.to_string());
                args.push(path.to_str().unwrap().to_owned());
            }
            let before = listing(&outs);
            tally.tried += 1;
            let (status, out) = super::run_binary(dir, &args);
            let out = String::from_utf8_lossy(&out).into_owned();
            let err =
                String::from_utf8_lossy(&std::fs::read(dir.join("stderr")).unwrap()).into_owned();
            let Some(status) = status else {
                return tally.fail("timeout", r, dir, &err);
            };
            let Some(code) = status.code() else {
                let e = format!("signal {:?}\n{err}", status.signal());
                return tally.fail("crash", r, dir, &e);
            };
            if code == 101 || err.contains("panicked") {
                return tally.fail("panic", r, dir, &err);
            }
            if let Some(k) = tally.exits.get_mut(code as usize) {
                *k += 1;
            }
            // The inputs are never written.
            if std::fs::read(dir.join("spec.toml")).ok().as_deref() != Some(&r.spec_bytes[..])
                || r.csv
                    .as_ref()
                    .is_some_and(|c| std::fs::read(dir.join("data.csv")).ok().as_ref() != Some(c))
            {
                return tally.fail("an input was overwritten", r, dir, &err);
            }
            let expected: &[i32] = if r.bad_args || refused {
                &[2]
            } else if unwritable {
                &[1, 2]
            } else {
                &[0, 2]
            };
            if !expected.contains(&code) {
                return tally.fail(&format!("exit {code}"), r, dir, &err);
            }
            // An error names the data file, the spec or a flag.
            let named = err.lines().filter(|l| l.starts_with("error:")).any(|l| {
                ["data.csv", "spec.toml", "--", " -o "]
                    .iter()
                    .any(|w| l.contains(w))
            });
            if code == 2 && !r.bad_args && !named {
                return tally.fail("unlocated error", r, dir, &err);
            }
            if out.contains("NaN") || (r.csv.is_none() && out.contains("inf")) {
                return tally.fail("NaN or inf printed", r, dir, &out);
            }
            // Outputs: complete where asked on success, old files untouched otherwise, no
            // temporary files left.
            for (flag, t, file) in &r.outputs {
                let p = outs.join(file);
                let got = std::fs::read(&p).ok();
                let problem = match (code, t) {
                    (0, Target::Fresh | Target::Existing) => {
                        let text = String::from_utf8_lossy(got.as_deref().unwrap_or_default())
                            .into_owned();
                        let complete = match *flag {
                            "--plot" => text.trim_end().ends_with("</svg>"),
                            "--estimates" => text.starts_with("k,name,") && !text.contains("NaN"),
                            "-o" => {
                                text.starts_with("t,")
                                    && text.lines().skip(1).all(|l| {
                                        l.split(',')
                                            .all(|v| v.parse::<f64>().is_ok_and(f64::is_finite))
                                    })
                            }
                            _ => text.contains("[mechanism]"),
                        };
                        (!complete).then_some("missing or incomplete output")
                    }
                    (_, Target::Existing)
                        if code != 0 && got.as_deref() != Some(OLD.as_bytes()) =>
                    {
                        Some("the old file was changed")
                    }
                    _ => None,
                };
                if let Some(p) = problem {
                    return tally.fail(&format!("{p} ({flag})"), r, dir, &err);
                }
            }
            let after = listing(&outs);
            if after
                .iter()
                .any(|n| !before.contains(n) && !r.outputs.iter().any(|o| o.2 == n))
            {
                tally.fail("temporary files left behind", r, dir, &err);
            }
        }

        /// No panic, crash, hang, NaN, overwritten input, unlocated error or half-written
        /// output from `identify` and `excite` on mutated measurements and absurd flags.
        #[test]
        fn identify_and_excite_never_crash_hang_or_print_nan() {
            let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz_data");
            let _ = std::fs::remove_dir_all(&root);
            let start = Instant::now();
            let srcs = sources(&root.join("sources"));
            let n = data_cases();
            let seed: u64 = std::env::var("NOCDYN_FUZZ_SEED")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(7);
            let tallies: Vec<Tally> = std::thread::scope(|s| {
                let workers: Vec<_> = (0..2u64)
                    .map(|w| {
                        let srcs = &srcs;
                        let dir = root.join(format!("w{w}"));
                        s.spawn(move || {
                            let mut rng = Rng(seed ^ (w << 40) ^ 0xda7a);
                            let mut tally = Tally::default();
                            for k in (w as usize..n).step_by(2) {
                                let src = rng.pick(srcs);
                                let r = if k % 6 == 5 {
                                    excite_run(&mut rng, src)
                                } else {
                                    identify_run(&mut rng, src)
                                };
                                run_one(&r, &dir.join("case"), &mut tally);
                            }
                            tally
                        })
                    })
                    .collect();
                workers.into_iter().map(|w| w.join().unwrap()).collect()
            });
            let mut t = Tally::default();
            for x in tallies {
                t.tried += x.tried;
                for k in 0..3 {
                    t.exits[k] += x.exits[k];
                }
                t.bad += x.bad;
                t.failures.extend(x.failures);
            }
            println!(
                "fuzz identify/excite: {} runs in {:.1} s (exit 0: {}, 1: {}, 2: {}); {} failures",
                t.tried,
                start.elapsed().as_secs_f64(),
                t.exits[0],
                t.exits[1],
                t.exits[2],
                t.bad
            );
            for f in &t.failures {
                println!("{f}\n");
            }
            assert_eq!(t.tried, n);
            assert_eq!(t.bad, 0, "see above");
        }
    }
}
