//! No generated function allocates: every public function of every bundled mechanism is called
//! on its home state and on random states, under a counting global allocator
//! (`allocation_counter`, which counts only the calling thread's allocations inside
//! `measure`), and the count must be zero. Inputs are prepared before the measured region.
//!
//! The mechanisms come from the shared list `tests/no-panic/src/list.rs`, and one generic
//! function measures each through its `runtime::Dynamics` implementation; `list_matches_specs`
//! fails when a spec in `mechanisms/specs/` is missing from the list.

use allocation_counter::measure;
use mechanisms::Dynamics;
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

/// One state `(x, u, ud)` of a module, in its coordinates.
type State = (Vec<f64>, Vec<f64>, Vec<f64>);

/// Home and `STATES` random states of the bundled mechanism `name`, from the runtime's model of
/// its kind (the one place that knows the kinds: the states are data, the harness is generic).
fn states(name: &str) -> Vec<State> {
    use runtime::parallel::PlatformMotion;
    let mut states = Vec::new();
    match kind(name) {
        Kind::Tree => {
            let mut rng = tests::rng(0xa110c ^ dof(name) as u64);
            let n = dof(name);
            states.push((vec![0.0; n], vec![0.0; n], vec![0.0; n]));
            for _ in 0..STATES {
                states.push(tests::random_state(&mut rng, n));
            }
        }
        Kind::Parallel => {
            let model = tests::pkm::model(name);
            let plan = runtime::parallel::noc::Plan::new(&model).expect("plan");
            let home = tests::pkm::home_x(&model);
            let (angle, reach) = match model.motion {
                PlatformMotion::Pose => (0.1, 0.02 * model.size()),
                PlatformMotion::Orientation { .. } => (0.3, 0.0),
                PlatformMotion::PlanarPoint { .. } => (0.0, 0.03),
                PlatformMotion::Translation { .. } => (0.0, 0.02 * model.size()),
                PlatformMotion::PlanarPose { .. }
                | PlatformMotion::HeaveTilt { .. }
                | PlatformMotion::Schoenflies { .. } => (0.1, 0.02 * model.size()),
            };
            let n = plan.dof();
            let mut rng = tests::rng(0xa110c ^ n as u64);
            states.push((home.clone(), vec![0.0; n], vec![0.0; n]));
            for _ in 0..STATES {
                states.push(tests::pkm::random_state(
                    &plan, &home, &mut rng, angle, reach,
                ));
            }
        }
        Kind::Closed => {
            let model = tests::closed::model(name);
            let plan = runtime::closed::noc::Plan::new(&model).expect("plan");
            let (n, nx) = (plan.dof(), plan.nx());
            let mut rng = tests::rng(0xa110c ^ n as u64);
            states.push((vec![0.0; nx], vec![0.0; n], vec![0.0; n]));
            for _ in 0..STATES {
                states.push(tests::closed::random_state(&plan, &mut rng, 0.3));
            }
        }
    }
    states
}

/// Calls every method of module `m` on every state in `states` under the allocation counter.
fn measure_module<M, const NX: usize, const N: usize>(
    name: &'static str,
    m: &M,
    states: &[State],
) -> Outcome
where
    M: Dynamics<NX, N, Scalar = F>,
{
    let states: Vec<([F; NX], [F; N], [F; N])> = states
        .iter()
        .map(|(x, u, ud)| (arr(x), arr(u), arr(ud)))
        .collect();
    let guess = M::HOME;
    let (mut calls, mut ok, mut fallible) = (0, 0, 0);
    let info = measure(|| {
        for (x, u, ud) in &states {
            let (m, x, u, ud) = (black_box(m), black_box(x), black_box(u), black_box(ud));
            let q = black_box(m.inverse_kinematics(x));
            ok += usize::from(q.is_ok());
            let q = q.unwrap_or([0.0; N]);
            ok += usize::from(black_box(m.forward_kinematics(&q, &guess)).is_ok());
            ok += usize::from(black_box(m.actuator_rates(x, u)).is_ok());
            let tau = black_box(m.inverse_dynamics(x, u, ud));
            ok += usize::from(tau.is_ok());
            ok += usize::from(black_box(m.mass_matrix(x)).is_ok());
            ok += usize::from(black_box(m.actuator_mass_matrix(x)).is_ok());
            let tau = tau.unwrap_or([0.0; N]);
            ok += usize::from(black_box(m.forward_dynamics(x, u, &tau)).is_ok());
            calls += 7;
            fallible += 7;
            if let Some(r) = black_box(m.joint_rates(x, u)) {
                ok += usize::from(r.is_ok());
                calls += 1;
                fallible += 1;
            }
            for split in [m.coriolis(x, u), m.gravity(x), m.friction(x, u)]
                .into_iter()
                .flatten()
            {
                ok += usize::from(black_box(split).is_ok());
                calls += 1;
                fallible += 1;
            }
            if let Some(r) = black_box(m.inverse_dynamics_derivatives(x, u, ud)) {
                ok += usize::from(r.is_ok());
                calls += 1;
                fallible += 1;
            }
            if let Some(r) = black_box(m.forward_dynamics_derivatives(x, u, &tau)) {
                ok += usize::from(r.is_ok());
                calls += 1;
                fallible += 1;
            }
        }
    });
    Outcome {
        name,
        calls,
        ok,
        fallible,
        allocations: info.count_total,
    }
}

macro_rules! measure_all {
    ($($m:ident),* $(,)?) => {
        /// Every bundled module, measured.
        fn measure_all() -> Vec<Outcome> {
            vec![$(measure_module(stringify!($m), &root::$m::Module, &states(stringify!($m)))),*]
        }
        /// Every bundled module's name.
        const NAMES: &[&str] = &[$(stringify!($m)),*];
    };
}
for_each_mechanism!(measure_all);

#[test]
fn no_generated_function_allocates() {
    let all = measure_all();
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

/// The kinds of module (for the states only).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Tree,
    Parallel,
    Closed,
}

/// The spec of bundled module `name` (a URDF whose stem is also a TOML spec's is `<stem>_urdf`).
fn spec_path(name: &str) -> std::path::PathBuf {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs");
    ["toml", "urdf"]
        .iter()
        .map(|e| dir.join(format!("{name}.{e}")))
        .find(|p| p.exists())
        .unwrap_or_else(|| dir.join(format!("{}.urdf", name.trim_end_matches("_urdf"))))
}

/// The loaded mechanism of bundled module `name`.
fn mechanism(name: &str) -> codegen::spec::Mechanism {
    let path = spec_path(name);
    let src = std::fs::read_to_string(&path).expect("spec readable");
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((m, _)) => m,
        Err(d) => panic!("{d}"),
    }
}

fn kind(name: &str) -> Kind {
    #[allow(unreachable_patterns)]
    match mechanism(name) {
        codegen::spec::Mechanism::Tree(_) => Kind::Tree,
        codegen::spec::Mechanism::Parallel(_) => Kind::Parallel,
        codegen::spec::Mechanism::Closed(_) => Kind::Closed,
        _ => panic!("{name}: a new kind of mechanism; give it states in `states`"),
    }
}

fn dof(name: &str) -> usize {
    match mechanism(name) {
        codegen::spec::Mechanism::Tree(m) => m.dof(),
        _ => unreachable!("trees only"),
    }
}

/// The shared list holds every bundled spec.
#[test]
fn list_matches_specs() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs");
    let mut builder = codegen::build_script::Builder::new();
    builder.specs_in(&dir);
    let mut specs = builder.module_names();
    specs.sort();
    let mut listed: Vec<String> = NAMES.iter().map(|s| s.to_string()).collect();
    listed.sort();
    assert_eq!(listed, specs, "add it to tests/no-panic/src/list.rs");
    // Every listed module loads as a kind the harness knows.
    for name in NAMES {
        kind(name);
    }
}
