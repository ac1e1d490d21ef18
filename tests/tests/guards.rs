//! Every test the evaluator performs reaches the generated code: per generated function, the
//! guards in the emitted text equal the tests the runtime's generic evaluator performs on the
//! same spec.
//!
//! The runtime side is counted by running the evaluator over [`Tracked`], an `f64` that also
//! knows whether its value depends on a function input. A test whose value and threshold are
//! both input-free is decided once at generation time (a structural property of the spec), so
//! it has no place in the emitted code and is not counted; every other test is counted once
//! (the same test asked again, as when forward dynamics re-evaluates the configuration, has the
//! same value and threshold). The generated side is read from the emitted text: the
//! `Singular { site: … }` returns of the function's body, the input checks (`Site::Input`)
//! apart. A guard that dead-code removal dropped (the last pivot of a square LU feeds no row
//! below it, so nothing reads the value its test passes on) shows as one guard fewer.

#![allow(clippy::redundant_guards)] // float guards read clearer than float patterns

use std::cell::RefCell;
use std::collections::BTreeSet;
use std::ops::{Add, Div, Mul, Neg, Sub};

use runtime::scalar::{Real, Singular, Site};

/// An `f64` that also knows whether its value depends on a function input, and, when it does,
/// a hash of the expression that computed it (commutative operations hashed in either order,
/// `x + 0`, `x · 1` and `−(−x)` as `x`), so that a test asked twice is counted once and two
/// tests that happen to meet the same value are not.
#[derive(Clone, Copy, Debug)]
struct Tracked {
    v: f64,
    input: bool,
    h: u64,
}

thread_local! {
    /// The distinct input-dependent tests performed: (site code, two-sided, value, threshold).
    static TESTS: RefCell<BTreeSet<(u16, bool, u64, u64)>> = const { RefCell::new(BTreeSet::new()) };
}

fn mix(parts: &[u64]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    parts.hash(&mut h);
    h.finish()
}

impl Tracked {
    fn input(v: f64, index: u64) -> Tracked {
        Tracked {
            v,
            input: true,
            h: mix(&[1, index]),
        }
    }
    fn constant(self) -> Option<f64> {
        (!self.input).then_some(self.v)
    }
    fn op(code: u64, v: f64, args: &[Tracked]) -> Tracked {
        let input = args.iter().any(|a| a.input);
        let mut parts = vec![code];
        for a in args {
            parts.push(if a.input {
                a.h
            } else {
                mix(&[2, a.v.to_bits()])
            });
        }
        Tracked {
            v,
            input,
            h: mix(&parts),
        }
    }
    fn commutative(code: u64, v: f64, a: Tracked, b: Tracked) -> Tracked {
        let (ha, hb) = (Tracked::op(0, 0.0, &[a]).h, Tracked::op(0, 0.0, &[b]).h);
        let (lo, hi) = if ha <= hb { (a, b) } else { (b, a) };
        Tracked::op(code, v, &[lo, hi])
    }
}

impl Add for Tracked {
    type Output = Tracked;
    fn add(self, o: Tracked) -> Tracked {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Tracked::c(a + b),
            (Some(z), _) if z == 0.0 => o,
            (_, Some(z)) if z == 0.0 => self,
            _ => Tracked::commutative(3, self.v + o.v, self, o),
        }
    }
}

impl Sub for Tracked {
    type Output = Tracked;
    fn sub(self, o: Tracked) -> Tracked {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Tracked::c(a - b),
            (_, Some(z)) if z == 0.0 => self,
            (Some(z), _) if z == 0.0 => -o,
            _ => Tracked::op(4, self.v - o.v, &[self, o]),
        }
    }
}

impl Mul for Tracked {
    type Output = Tracked;
    fn mul(self, o: Tracked) -> Tracked {
        // A product with the constant zero is the constant zero (as the DAG folds it).
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Tracked::c(a * b),
            (Some(z), _) | (_, Some(z)) if z == 0.0 => Tracked::c(0.0),
            (Some(one), _) if one == 1.0 => o,
            (_, Some(one)) if one == 1.0 => self,
            _ => Tracked::commutative(5, self.v * o.v, self, o),
        }
    }
}

impl Div for Tracked {
    type Output = Tracked;
    fn div(self, o: Tracked) -> Tracked {
        match (self.constant(), o.constant()) {
            (Some(a), Some(b)) => Tracked::c(a / b),
            (_, Some(one)) if one == 1.0 => self,
            _ => Tracked::op(6, self.v / o.v, &[self, o]),
        }
    }
}

impl Neg for Tracked {
    type Output = Tracked;
    fn neg(self) -> Tracked {
        if !self.input {
            return Tracked::c(-self.v);
        }
        let h = mix(&[7, self.h]);
        Tracked {
            v: -self.v,
            input: true,
            h,
        }
    }
}

impl Real for Tracked {
    fn c(v: f64) -> Tracked {
        Tracked {
            v,
            input: false,
            h: 0,
        }
    }
    fn sqrt(self) -> Tracked {
        Tracked::op(8, self.v.sqrt(), &[self])
    }
    fn atan2(self, x: Tracked) -> Tracked {
        Tracked::op(9, self.v.atan2(x.v), &[self, x])
    }
    fn sin_cos(self) -> (Tracked, Tracked) {
        let (s, c) = self.v.sin_cos();
        (Tracked::op(10, s, &[self]), Tracked::op(11, c, &[self]))
    }
    fn select_abs_gt(a: Tracked, b: Tracked, x: Tracked, y: Tracked) -> Tracked {
        let r = if a.v.abs() > b.v.abs() { x.v } else { y.v };
        Tracked::op(12, r, &[a, b, x, y])
    }
    fn check(
        value: Tracked,
        threshold: Tracked,
        scale: Tracked,
        site: Site,
        two_sided: bool,
    ) -> Result<Tracked, Singular> {
        if value.input || threshold.input {
            TESTS.with(|t| {
                t.borrow_mut().insert((
                    site.code(),
                    two_sided,
                    Tracked::op(0, 0.0, &[value]).h,
                    Tracked::op(0, 0.0, &[threshold]).h,
                ))
            });
        }
        f64::check(value.v, threshold.v, scale.v, site, two_sided)?;
        Ok(value)
    }
}

/// The number of distinct input-dependent tests `f` performs (it must succeed: a regular state).
fn count<T>(what: &str, f: impl FnOnce() -> Result<T, Singular>) -> usize {
    TESTS.with(|t| t.borrow_mut().clear());
    if let Err(e) = f() {
        panic!("{what}: the runtime failed at a regular state: {e}");
    }
    if std::env::var("GUARDS_DEBUG").is_ok() {
        TESTS.with(|t| {
            for k in t.borrow().iter() {
                println!(
                    "  {what}: {:?} {} {:x} {:x}",
                    Site::from_code(k.0),
                    k.1,
                    k.2,
                    k.3
                );
            }
        });
    }
    TESTS.with(|t| t.borrow().len())
}

/// The inputs `v`, argument `arg` of the function.
fn tracked(v: &[f64], arg: u64) -> Vec<Tracked> {
    v.iter()
        .enumerate()
        .map(|(i, &x)| Tracked::input(x, 1000 * arg + i as u64))
        .collect()
}

/// The body of `fn name(` in `code` (to the closing brace at the start of a line).
fn body<'a>(code: &'a str, name: &str) -> &'a str {
    let start = code
        .find(&format!("fn {name}("))
        .unwrap_or_else(|| panic!("no fn {name}"));
    let end = code[start..]
        .find("\n}\n")
        .unwrap_or_else(|| panic!("fn {name} has no end"));
    &code[start..start + end]
}

/// The guards of the emitted function `name`: its `Singular` returns other than input checks.
fn emitted(code: &str, name: &str) -> usize {
    let b = body(code, name);
    b.matches("site: Site::").count() - b.matches("site: Site::Input").count()
}

fn generate(spec: &str) -> String {
    let path = tests::pkm::spec_path(spec);
    let src = std::fs::read_to_string(&path).unwrap();
    codegen::compile(&format!("{spec}.toml"), &src, &codegen::Config::default())
        .unwrap_or_else(|d| panic!("{d}"))
        .code
}

#[test]
fn closed_loop_guards_match_the_runtime_tests() {
    use runtime::closed::noc::{self, Plan};
    let mut rows = Vec::new();
    for name in tests::closed::CLOSED {
        let model = tests::closed::model(name);
        let plan = Plan::new(&model).unwrap();
        let mut rng = tests::rng(31);
        let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, tests::closed::reach(name));
        let (x, u, ud) = (tracked(&x, 0), tracked(&u, 1), tracked(&ud, 2));
        let tau = ud.clone();
        let code = generate(name);
        let runtime = [
            (
                "joint_rates",
                count(name, || {
                    noc::configuration(&plan, &x, true)
                        .map(|c| noc::joint_rates_generic(&plan, &c, &u))
                }),
            ),
            (
                "inverse_dynamics",
                count(name, || {
                    noc::configuration(&plan, &x, true)
                        .map(|c| noc::generalized_force(&plan, &c, &u, &ud, true))
                }),
            ),
            (
                "mass_matrix",
                count(name, || {
                    noc::configuration(&plan, &x, true).map(|c| noc::generalized_inertia(&plan, &c))
                }),
            ),
            (
                "forward_dynamics",
                count(name, || noc::forward_dynamics_generic(&plan, &x, &u, &tau)),
            ),
            ("newton_step", count(name, || noc::newton_step(&plan, &x))),
        ];
        for (f, n) in runtime {
            rows.push((name, f, n, emitted(&code, f)));
        }
    }
    report(&rows);
}

/// What a function does with the legs' kinematics (its tests are counted).
type Use<'a> = dyn Fn(&runtime::parallel::noc::Platform<Tracked>, &[runtime::parallel::noc::LegKin<Tracked>])
    + 'a;

#[test]
fn parallel_guards_match_the_runtime_tests() {
    use runtime::parallel::noc::{self, Plan};
    let mut rows = Vec::new();
    for name in tests::pkm::PARALLEL {
        let model = tests::pkm::model(name);
        let plan = Plan::new(&model).unwrap();
        let mut rng = tests::rng(32);
        let home = tests::pkm::home_x(&model);
        let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, 0.2, 0.02);
        let (x, u, ud) = (tracked(&x, 0), tracked(&u, 1), tracked(&ud, 2));
        let code = generate(name);
        let kin = |f: &Use<'_>| {
            count(name, || {
                noc::kinematics(&plan, &x).map(|(pl, legs)| f(&pl, &legs))
            })
        };
        // The generated public function, or the kernel it wraps around an LU of `A` (that LU is
        // a fixed template of its own, checked by the walks).
        let runtime = [
            (
                "inverse_kinematics",
                count(name, || noc::positions(&plan, &x)),
            ),
            ("actuator_rates", kin(&|_, _| {})),
            (
                "id_parts",
                kin(&|pl, legs| {
                    noc::generalized_force(&plan, pl, legs, &u, &ud, true);
                }),
            ),
            (
                "mass_matrix",
                kin(&|pl, legs| {
                    noc::generalized_inertia(&plan, pl, legs);
                }),
            ),
            (
                "inertia_parts",
                kin(&|pl, legs| {
                    noc::generalized_inertia(&plan, pl, legs);
                }),
            ),
            (
                "forward_dynamics",
                count(name, || noc::forward_dynamics_generic(&plan, &x, &u, &ud)),
            ),
            ("fk_parts", kin(&|_, _| {})),
        ];
        for (f, n) in runtime {
            rows.push((name, f, n, emitted(&code, f)));
        }
    }
    report(&rows);
}

/// Trees: the forward dynamics tests one pivot per joint (the runtime's `LDLᵀ`, eliminated from
/// the tips); no other function tests anything.
#[test]
fn tree_guards_match_the_runtime_tests() {
    let mut rows = Vec::new();
    for name in [
        "puma560",
        "stanford_arm",
        "chain7",
        "gripper_tree",
        "planar_2r",
    ] {
        let code = generate(name);
        let dof = tests::pkm::spec_path(name);
        let src = std::fs::read_to_string(&dof).unwrap();
        let n = match codegen::spec::load_mechanism(name, &src) {
            Ok((codegen::spec::Mechanism::Tree(m), _)) => m.dof(),
            _ => panic!("{name} is not a tree"),
        };
        rows.push((
            name,
            "forward_dynamics",
            n,
            // The result's finiteness check (`pivot: DOF`) is no pivot test.
            body(&code, "forward_dynamics").matches("pivot:").count()
                - body(&code, "forward_dynamics")
                    .matches("pivot: DOF")
                    .count(),
        ));
        // And one check of the result: never an `Ok` holding NaN or ∞.
        rows.push((
            name,
            "forward_dynamics (finite result)",
            1,
            body(&code, "forward_dynamics")
                .matches("pivot: DOF")
                .count(),
        ));
        for f in ["mass_matrix", "inverse_dynamics", "coriolis", "gravity"] {
            rows.push((name, f, 0, body(&code, f).matches("Err(").count()));
        }
    }
    report(&rows);
}

fn report(rows: &[(&str, &str, usize, usize)]) {
    println!("| mechanism | function | runtime tests | emitted guards |");
    println!("|---|---|---:|---:|");
    for (m, f, r, e) in rows {
        println!("| {m} | {f} | {r} | {e} |");
    }
    let bad: Vec<_> = rows.iter().filter(|r| r.2 != r.3).collect();
    assert!(bad.is_empty(), "guards dropped or added: {bad:?}");
}
