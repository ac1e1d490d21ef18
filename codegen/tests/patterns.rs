//! `[parameters]`, expressions and `[[pattern]]` (docs/spec.md, "Parameters and expressions",
//! "Leg patterns"): the bundled specs rewritten with them give the model of their written-out
//! versions (`data/expanded/`, every number placed by hand or by the former generator script:
//! a route that shares nothing with the expression evaluator or the pattern's turns), and
//! mistakes in them are reported once, at the text that is wrong.

use std::path::Path;

use codegen::spec::load_mechanism;

mod common;
use common::split;

fn model(path: &Path) -> String {
    let src = std::fs::read_to_string(path).expect("spec");
    let (m, warnings) = load_mechanism(&path.display().to_string(), &src)
        .unwrap_or_else(|d| panic!("{}: {d}", path.display()));
    assert!(warnings.is_empty(), "{}: {warnings}", path.display());
    format!("{m:?}")
}

#[test]
fn rewritten_specs_give_the_models_written_out() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for name in ["delta_rl5", "planar_3rrr", "gough_stewart", "delta4_rl5"] {
        let new = model(&root.join(format!("mechanisms/specs/{name}.toml")));
        let old = model(&root.join(format!("codegen/tests/data/expanded/{name}.toml")));
        assert!(split(&new).0.len() > 100, "{name}");
        let worst = common::worst_difference(&new, &old);
        // The written-out files round each number to 16-17 digits, and the Delta's and the
        // 3-RRR's to 1e-16 of their symmetric values.
        assert!(worst < 1e-14, "{name}: numbers differ by {worst:e}");
    }
}

fn errors(src: &str) -> String {
    match load_mechanism("t.toml", src) {
        Ok(_) => panic!("loaded"),
        Err(d) => d.to_string(),
    }
}

const ARM: &str = r#"
[mechanism]
name = "arm"

[[body]]
name = "link1"
mass = "m1"
com = ["l1 / 2", 0, 0]

[[joint]]
name = "j1"
kind = "revolute"
parent = "base"
child = "link1"
origin = { xyz = [0, 0, "h"], rpy = [0, 0, "yaw"] }
axis = [0, 0, 1]
"#;

#[test]
fn parameters_in_any_order_and_exact_angles() {
    let src = format!(
        "[parameters]\nyaw = \"atan2(1, 1) + 15 deg\"\nh = \"l1 * cos(120 deg) + 1\"\nm1 = \"2 * l1\"\nl1 = 0.25\n{ARM}"
    );
    let (m, _) = load_mechanism("t.toml", &src).expect("loads");
    let text = format!("{m:?}");
    // h = 0.25·(−0.5) + 1 exactly; m1 = 0.5; the com at 0.125.
    assert!(text.contains("0.875"), "{text}");
    assert!(text.contains("mass: 0.5"), "{text}");
    assert!(text.contains("0.125"), "{text}");
    // yaw = 45° + 15°: the joint frame's x axis at 60° (to rounding).
    let codegen::spec::Mechanism::Tree(t) = m else {
        panic!("a tree")
    };
    let r = t.joints[0].origin.rotation;
    assert!((r[0][0] - 0.5).abs() < 1e-15 && (r[1][0] - 0.75f64.sqrt()).abs() < 1e-15);
}

#[test]
fn expression_errors_point_into_the_string() {
    let src = format!("[parameters]\nl1 = 0.25\nm1 = 1\nyaw = 0\nh = \"l2 * 2\"\n{ARM}");
    let e = errors(&src);
    assert!(e.contains("unknown name `l2`"), "{e}");
    assert!(e.contains("did you mean \"l1\"?"), "{e}");
    assert!(e.contains("parameters.h"), "{e}");
    // The caret is under `l2`: line 5, column 6.
    assert!(e.contains("t.toml:5:6"), "{e}");
    // Reported once: `h`'s own failure does not echo where `h` is used.
    assert_eq!(e.matches("error:").count(), 1, "{e}");

    let e = errors(&format!(
        "[parameters]\nl1 = \"m1\"\nm1 = \"l1 + 1\"\nyaw = 0\nh = 1\n{ARM}"
    ));
    assert!(e.contains("depends on itself"), "{e}");

    let e = errors(&format!(
        "[parameters]\npi = 3\nl1 = 1\nm1 = 1\nyaw = 0\nh = \"1 / 0\"\n{ARM}"
    ));
    assert!(e.contains("reserved"), "{e}");
    assert!(e.contains("division by zero"), "{e}");

    // A unit is still a unit mistake, with its hint.
    let e = errors(&format!(
        "[parameters]\nl1 = \"250 mm\"\nm1 = 1\nyaw = 0\nh = 1\n{ARM}"
    ));
    assert!(e.contains("convert 250 mm"), "{e}");
}

const PATTERN: &str = r#"
[mechanism]
name = "star"

[parameters]
r = 0.5

[[pattern]]
copies = 4
axis = [0, 0, 1]

[[pattern.body]]
name = "arm{i}"
mass = 1.0
com = ["r / 2", 0, 0]

[[pattern.joint]]
name = "j{i}"
kind = "revolute"
parent = "base"
child = "arm{i}"
origin = { xyz = ["r", 0, "0.1 * i"] }
axis = [0, 1, 0]
"#;

#[test]
fn a_pattern_turns_its_copies_where_they_meet_the_base() {
    let (m, _) = load_mechanism("t.toml", PATTERN).expect("loads");
    let text = format!("{m:?}");
    for i in 1..=4 {
        assert!(text.contains(&format!("\"j{i}\"")), "{text}");
        assert!(text.contains(&format!("\"arm{i}\"")), "{text}");
    }
    // Copy 2 turned by 90° exactly: its joint at (0, 0.5, 0.2), its axis along −x.
    let e = codegen::compile("t.toml", PATTERN, &codegen::Config::default()).expect("compiles");
    assert!(!e.code.is_empty());
    let tree = match m {
        codegen::spec::Mechanism::Tree(t) => t,
        _ => panic!("a tree"),
    };
    let j = &tree.joints[1];
    assert_eq!(j.origin.translation, [0.0, 0.5, 0.2]);
    assert_eq!(
        j.origin.rotation,
        [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    );
}

#[test]
fn a_mistake_in_a_pattern_is_reported_once() {
    let src = PATTERN.replace("\"r / 2\"", "\"rr / 2\"");
    let e = errors(&src);
    assert_eq!(e.matches("unknown name `rr`").count(), 1, "{e}");
    let e = errors(&PATTERN.replace("copies = 4", "copies = 0"));
    assert!(e.contains("copies must be a whole number from 1 to"), "{e}");
    let e = errors(&PATTERN.replace("copies = 4\n", ""));
    assert!(e.contains("missing required key \"copies\""), "{e}");
    let e = errors(&PATTERN.replace("name = \"arm{i}\"", "name = \"arm\""));
    assert!(e.contains("arm"), "{e}");
}

/// A long chain of parameters, each written before the one it refers to (the order that
/// needs the most passes), is read in about linear time: the pass-by-pass evaluation took
/// cubic time (2,000 parameters 2.3 s, 6,000 parameters 78 s in release, a "hang" for a
/// 100 kB spec). The values, the cycle diagnostics and the evaluation order are unchanged.
#[test]
fn a_long_chain_of_parameters_is_read_quickly() {
    let n = 4_000;
    let mut src = String::from("[parameters]\n");
    for k in 0..n {
        src += &format!("p{k} = \"p{} + 1\"\n", k + 1);
    }
    src += &format!("p{n} = 0.5\nl1 = 1\nm1 = \"p0 / {n}\"\nyaw = 0\nh = 1\n");
    src += ARM;
    let started = std::time::Instant::now();
    let (m, _) = load_mechanism("t.toml", &src).unwrap_or_else(|d| panic!("{d}"));
    let took = started.elapsed();
    assert!(
        took.as_secs_f64() < 10.0,
        "{n} chained parameters took {took:?}"
    );
    // m1 = (n + 0.5) / n
    let text = format!("{m:?}");
    let want = format!("{:?}", (n as f64 + 0.5) / n as f64);
    assert!(text.contains(&want), "mass {want} not in the model");

    // A cycle below a long chain is still reported at each parameter that waits on it.
    let e = errors(&format!(
        "[parameters]\nl1 = \"a\"\na = \"b\"\nb = \"c + a\"\nc = 1\nm1 = 1\nyaw = 0\nh = 1\n{ARM}"
    ));
    assert_eq!(e.matches("depends on itself").count(), 3, "{e}");
    assert!(
        e.contains("parameter `b` depends on itself through a"),
        "{e}"
    );
    assert!(
        e.contains("parameter `l1` depends on itself through a"),
        "{e}"
    );
}
