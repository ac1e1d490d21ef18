//! A structure-aware fuzzer that runs in `cargo test` with a fixed budget (issue 7): random and
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
//! Budget: `NOCDYN_FUZZ_CASES` cases per generator (default 2,000); `NOCDYN_FUZZ_SEED` (a
//! number) changes the RNG seed. The number of inputs tried is printed (`--nocapture`).

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
