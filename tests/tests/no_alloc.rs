//! No generated function allocates: every public function of every bundled mechanism is called
//! on its home state and on random states, under a counting global allocator
//! (`allocation_counter`, which counts only the calling thread's allocations inside
//! `measure`), and the count must be zero. Inputs are prepared before the measured region.
//!
//! The mechanisms come from the shared list `tests/no-panic/src/list.rs`; `list_matches_specs`
//! fails when a spec in `mechanisms/specs/` is missing from it or filed under the wrong kind.

use allocation_counter::measure;
use std::hint::black_box;

/// The generated code's scalar (an `f32` build changes this and `root`).
type F = f64;
use mechanisms as root;

include!("../no-panic/src/list.rs");

/// Random states per mechanism, besides home.
const STATES: usize = 25;

fn arr<const N: usize>(v: &[f64]) -> [F; N] {
    let mut a = [0.0; N];
    for (a, v) in a.iter_mut().zip(v) {
        *a = *v as F;
    }
    a
}

/// What one mechanism's measured region did.
#[derive(Debug)]
struct Outcome {
    name: &'static str,
    /// Generated functions called (all of them, on every state).
    calls: usize,
    /// Calls that returned `Ok` (the full computation ran, not an early error return).
    ok: usize,
    /// Calls that return a `Result`.
    fallible: usize,
    /// Allocations counted during the calls.
    allocations: u64,
}

macro_rules! tree {
    ($($m:ident),* $(,)?) => {
        fn trees() -> Vec<Outcome> {
            let mut out = Vec::new();
            $(
                out.push({
                    use root::$m as g;
                    const N: usize = g::DOF;
                    let mut rng = tests::rng(0xa110c ^ N as u64);
                    let mut states = vec![([0.0 as F; N], [0.0 as F; N], [0.0 as F; N])];
                    for _ in 0..STATES {
                        let (q, qd, qdd) = tests::random_state(&mut rng, N);
                        states.push((arr(&q), arr(&qd), arr(&qdd)));
                    }
                    let (mut calls, mut ok, mut fallible) = (0, 0, 0);
                    let info = measure(|| {
                        for (q, qd, qdd) in &states {
                            let (q, qd, qdd) = (black_box(q), black_box(qd), black_box(qdd));
                            black_box(g::mass_matrix(q));
                            black_box(g::coriolis(q, qd));
                            black_box(g::gravity(q));
                            let tau = black_box(g::inverse_dynamics(q, qd, qdd));
                            ok += usize::from(black_box(g::forward_dynamics(q, qd, &tau)).is_ok());
                            calls += 5;
                            fallible += 1;
                        }
                    });
                    Outcome { name: stringify!($m), calls, ok, fallible, allocations: info.count_total }
                });
            )*
            out
        }
    };
}

macro_rules! parallel {
    ($($m:ident),* $(,)?) => {
        fn parallels() -> Vec<Outcome> {
            use runtime::parallel::PlatformMotion;
            use runtime::parallel::noc::Plan;
            let mut out = Vec::new();
            $(
                out.push({
                    use root::$m as g;
                    const N: usize = g::DOF;
                    const NX: usize = g::NX;
                    let model = tests::pkm::model(stringify!($m));
                    let plan = Plan::new(&model).expect("plan");
                    let home = tests::pkm::home_x(&model);
                    let (angle, reach) = match model.motion {
                        PlatformMotion::Pose => (0.1, 0.02 * model.size()),
                        PlatformMotion::Orientation { .. } => (0.3, 0.0),
                        PlatformMotion::PlanarPoint { .. } => (0.0, 0.03),
                    };
                    let mut rng = tests::rng(0xa110c ^ N as u64);
                    let mut states = vec![(arr::<NX>(&home), [0.0 as F; N], [0.0 as F; N])];
                    for _ in 0..STATES {
                        let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, angle, reach);
                        states.push((arr(&x), arr(&u), arr(&ud)));
                    }
                    let guess: [F; NX] = arr(&home);
                    let (mut calls, mut ok, mut fallible) = (0, 0, 0);
                    let info = measure(|| {
                        for (x, u, ud) in &states {
                            let (x, u, ud) = (black_box(x), black_box(u), black_box(ud));
                            let q = black_box(g::inverse_kinematics(x));
                            ok += usize::from(q.is_ok());
                            ok += usize::from(black_box(g::actuator_rates(x, u)).is_ok());
                            let tau = black_box(g::inverse_dynamics(x, u, ud));
                            ok += usize::from(tau.is_ok());
                            ok += usize::from(black_box(g::mass_matrix(x)).is_ok());
                            ok += usize::from(black_box(g::actuator_mass_matrix(x)).is_ok());
                            let tau = tau.unwrap_or([0.0; N]);
                            ok += usize::from(black_box(g::forward_dynamics(x, u, &tau)).is_ok());
                            let q = q.unwrap_or([0.0; N]);
                            ok += usize::from(black_box(g::forward_kinematics(&q, &guess)).is_ok());
                            calls += 7;
                            fallible += 7;
                        }
                    });
                    Outcome { name: stringify!($m), calls, ok, fallible, allocations: info.count_total }
                });
            )*
            out
        }
    };
}

macro_rules! closed {
    ($($m:ident),* $(,)?) => {
        fn closed_loops() -> Vec<Outcome> {
            use runtime::closed::noc::Plan;
            let mut out = Vec::new();
            $(
                out.push({
                    use root::$m as g;
                    const N: usize = g::DOF;
                    const NX: usize = g::NX;
                    let model = tests::closed::model(stringify!($m));
                    let plan = Plan::new(&model).expect("plan");
                    let mut rng = tests::rng(0xa110c ^ N as u64);
                    let mut states = vec![([0.0 as F; NX], [0.0 as F; N], [0.0 as F; N])];
                    for _ in 0..STATES {
                        let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, 0.3);
                        states.push((arr(&x), arr(&u), arr(&ud)));
                    }
                    let guess = [0.0 as F; NX];
                    let (mut calls, mut ok, mut fallible) = (0, 0, 0);
                    let info = measure(|| {
                        for (x, u, ud) in &states {
                            let (x, u, ud) = (black_box(x), black_box(u), black_box(ud));
                            let q = black_box(g::inverse_kinematics(x));
                            ok += usize::from(q.is_ok());
                            let q = q.unwrap_or([0.0; N]);
                            ok += usize::from(black_box(g::forward_kinematics(&q, &guess)).is_ok());
                            ok += usize::from(black_box(g::joint_rates(x, u)).is_ok());
                            let tau = black_box(g::inverse_dynamics(x, u, ud));
                            ok += usize::from(tau.is_ok());
                            ok += usize::from(black_box(g::mass_matrix(x)).is_ok());
                            let tau = tau.unwrap_or([0.0; N]);
                            ok += usize::from(black_box(g::forward_dynamics(x, u, &tau)).is_ok());
                            calls += 6;
                            fallible += 6;
                        }
                    });
                    Outcome { name: stringify!($m), calls, ok, fallible, allocations: info.count_total }
                });
            )*
            out
        }
    };
}

for_each_mechanism!(tree, parallel, closed);

#[test]
fn no_generated_function_allocates() {
    let all: Vec<Outcome> = trees()
        .into_iter()
        .chain(parallels())
        .chain(closed_loops())
        .collect();
    let mut calls = 0;
    for o in &all {
        println!(
            "{:16} {:4} calls, {:4}/{:4} Ok, {} allocations",
            o.name, o.calls, o.ok, o.fallible, o.allocations
        );
        assert_eq!(o.allocations, 0, "{}: allocated during its calls", o.name);
        // Every fallible call ran to its `Ok` end, so the whole body was executed.
        assert_eq!(o.ok, o.fallible, "{}: some calls failed", o.name);
        assert_eq!(o.calls % (STATES + 1), 0);
        calls += o.calls;
    }
    println!("{} mechanisms, {calls} calls, 0 allocations", all.len());
}

/// The counter sees this thread's allocations: the zero above is a measurement.
#[test]
fn counter_counts() {
    let info = measure(|| {
        black_box(Vec::<F>::with_capacity(black_box(8)));
        black_box(Box::new(black_box(1.0 as F)));
    });
    assert_eq!(info.count_total, 2);
}

macro_rules! tree_names {
    ($($m:ident),* $(,)?) => {
        const TREE_NAMES: &[&str] = &[$(stringify!($m)),*];
    };
}
macro_rules! parallel_names {
    ($($m:ident),* $(,)?) => {
        const PARALLEL_NAMES: &[&str] = &[$(stringify!($m)),*];
    };
}
macro_rules! closed_names {
    ($($m:ident),* $(,)?) => {
        const CLOSED_NAMES: &[&str] = &[$(stringify!($m)),*];
    };
}
for_each_mechanism!(tree_names, parallel_names, closed_names);

/// The shared list holds every bundled spec, under its kind.
#[test]
fn list_matches_specs() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs");
    let mut builder = codegen::build_script::Builder::new();
    builder.specs_in(&dir).expect("specs dir");
    let (mut trees, mut parallel, mut closed, mut other) = (vec![], vec![], vec![], vec![]);
    for name in builder.module_names() {
        let path = ["toml", "urdf"]
            .iter()
            .map(|e| dir.join(format!("{name}.{e}")))
            .find(|p| p.exists())
            .unwrap_or_else(|| dir.join(format!("{}.urdf", name.trim_end_matches("_urdf"))));
        let src = std::fs::read_to_string(&path).expect("spec readable");
        #[allow(unreachable_patterns)]
        match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
            Ok((codegen::spec::Mechanism::Tree(_), _)) => trees.push(name),
            Ok((codegen::spec::Mechanism::Parallel(_), _)) => parallel.push(name),
            Ok((codegen::spec::Mechanism::Closed(_), _)) => closed.push(name),
            Ok(_) => other.push(name),
            Err(d) => panic!("{d}"),
        }
    }
    let sorted = |v: &[&str]| {
        let mut v: Vec<String> = v.iter().map(|s| s.to_string()).collect();
        v.sort();
        v
    };
    trees.sort();
    parallel.sort();
    closed.sort();
    let hint = "add it to tests/no-panic/src/list.rs";
    assert_eq!(sorted(TREE_NAMES), trees, "tree mechanisms: {hint}");
    assert_eq!(
        sorted(PARALLEL_NAMES),
        parallel,
        "parallel mechanisms: {hint}"
    );
    assert_eq!(
        sorted(CLOSED_NAMES),
        closed,
        "closed-loop mechanisms: {hint}"
    );
    assert!(
        other.is_empty(),
        "{other:?}: a new kind of mechanism; give it a macro in tests/no-panic/src/list.rs and its harnesses"
    );
}
