//! The split of the efforts, `gravity`, `coriolis` and `friction`, in every kind of module
//! (trees, parallel platforms, closed loops in joint coordinates), checked against routes that
//! do not share their code:
//! - **the sum.** `inverse_dynamics(x, u, u̇) = actuator_mass_matrix(x) q̈ + coriolis(x, u) +
//!   gravity(x) + friction(x, u)` with `q̈ = actuator_rates(x, u̇)`: four kernels and a fifth
//!   (the mass matrix's) against the whole;
//! - **energy.** The gravity efforts are the gradient of the potential energy in the actuated
//!   coordinates, `τ_g,i = ∂V/∂q_i` (the runtime's `potential_energy`: body positions only,
//!   no wrench and no projection), by fourth-order central differences through the module's
//!   own `forward_kinematics`;
//! - **power.** The velocity terms do the power `uᵀ C u = ½ uᵀ İ u` (the kinetic-energy
//!   theorem for `T = ½ uᵀ I u`), with `İ` by central differences of `mass_matrix` along the
//!   motion, and `C u` is quadratic in `u`;
//! - **friction** dissipates (`τ_f · q̇ ≥ 0`) and vanishes at rest.
//!
//! Errors are relative in the ∞-norm, each against the largest term of its sum.

use mechanisms::Dynamics;
use rand::Rng;
use rand::rngs::StdRng;

include!("../no-panic/src/list.rs");

/// The potential energy at `x` (J).
type Potential = dyn Fn(&[f64]) -> f64;

/// States per mechanism.
const STATES: usize = 40;

fn norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn quad<const N: usize>(m: &[[f64; N]; N], u: &[f64; N]) -> f64 {
    (0..N)
        .map(|i| (0..N).map(|j| u[i] * m[i][j] * u[j]).sum::<f64>())
        .sum()
}

/// The worst errors of one module: the sum, energy (where a potential is given), power, the
/// quadratic scaling of `C u`.
#[derive(Default, Debug)]
struct Worst {
    sum: f64,
    energy: f64,
    power: f64,
    quadratic: f64,
    states: usize,
}

/// An assembled state near home: the actuated coordinates moved by up to `reach` (rad or m)
/// from home's, assembled by the module's `forward_kinematics`, regular; speeds and rates in
/// ±1.
#[allow(clippy::type_complexity)]
fn state<M: Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
    rng: &mut StdRng,
    reach: f64,
) -> ([f64; N], [f64; NX], [f64; N], [f64; N]) {
    let q0 = m.inverse_kinematics(&M::HOME).expect("home is regular");
    loop {
        let q: [f64; N] = core::array::from_fn(|i| q0[i] + reach * rng.random_range(-1.0..1.0));
        let Ok(x) = m.forward_kinematics(&q, &M::HOME) else {
            continue;
        };
        if m.actuator_mass_matrix(&x).is_err() {
            continue;
        }
        let u = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let ud = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
        return (q, x, u, ud);
    }
}

/// Every check on one module; `potential`: the runtime's potential energy at `x`, where the
/// module's kind has one.
fn check<M: Dynamics<NX, N, Scalar = f64>, const NX: usize, const N: usize>(
    m: &M,
    potential: Option<&Potential>,
    seed: u64,
) -> Worst {
    let mut rng = tests::rng(seed);
    let mut w = Worst::default();
    for _ in 0..STATES {
        let (q, x, u, ud) = state(m, &mut rng, 0.05);
        let tau = m.inverse_dynamics(&x, &u, &ud).expect("regular");
        let g = m
            .gravity(&x)
            .expect("every kind has gravity")
            .expect("regular");
        let c = m
            .coriolis(&x, &u)
            .expect("every kind has coriolis")
            .expect("regular");
        let f = m.friction(&x, &u).map(|f| f.expect("regular"));
        let qdd = m.actuator_rates(&x, &ud).expect("regular");
        let ma = m.actuator_mass_matrix(&x).expect("regular");
        let inertial: Vec<f64> = (0..N).map(|i| dot(&ma[i], &qdd)).collect();
        // The sum.
        let sum: Vec<f64> = (0..N)
            .map(|i| inertial[i] + c[i] + g[i] + f.map_or(0.0, |f| f[i]))
            .collect();
        let scale = [norm(&tau), norm(&inertial), norm(&c), norm(&g)]
            .into_iter()
            .fold(f.map_or(0.0, |f| norm(&f)), f64::max);
        let d: Vec<f64> = (0..N).map(|i| sum[i] - tau[i]).collect();
        w.sum = w.sum.max(norm(&d) / scale);
        // C u is quadratic in u.
        let u2 = u.map(|v| 2.0 * v);
        let c2 = m.coriolis(&x, &u2).unwrap().unwrap();
        let d: Vec<f64> = (0..N).map(|i| c2[i] - 4.0 * c[i]).collect();
        w.quadratic = w.quadratic.max(norm(&d) / (4.0 * norm(&c)).max(1e-300));
        // Power: τ_c · q̇ = uᵀ C u against ½ uᵀ İ u along q(t) = q + t q̇.
        let qd = m.actuator_rates(&x, &u).unwrap();
        let h = 1e-5;
        let along = |t: f64| -> [f64; NX] {
            let qt: [f64; N] = core::array::from_fn(|i| q[i] + t * qd[i]);
            m.forward_kinematics(&qt, &x).expect("assembles near x")
        };
        let (ip, im) = (
            m.mass_matrix(&along(h)).unwrap(),
            m.mass_matrix(&along(-h)).unwrap(),
        );
        let idot_uu = (quad(&ip, &u) - quad(&im, &u)) / (2.0 * h);
        let power = dot(&c, &qd);
        let energy = quad(&m.mass_matrix(&x).unwrap(), &u);
        w.power = w
            .power
            .max((power - 0.5 * idot_uu).abs() / energy.max(power.abs()));
        // Energy: τ_g,i = ∂V/∂q_i.
        if let Some(v) = potential {
            let mut grad = [0.0; N];
            for i in 0..N {
                let at = |t: f64| {
                    let mut qt = q;
                    qt[i] += t;
                    v(&m.forward_kinematics(&qt, &x).expect("assembles near x"))
                };
                // Fourth order: a second-order difference's truncation, h^2 V'''/6, reaches
                // 1e-7 of the gravity efforts on the 3-PRS with horizontal rails (prs_head),
                // whose potential curves strongly in the slider positions.
                grad[i] = (8.0 * (at(h) - at(-h)) - (at(2.0 * h) - at(-2.0 * h))) / (12.0 * h);
            }
            let d: Vec<f64> = (0..N).map(|i| grad[i] - g[i]).collect();
            w.energy = w.energy.max(norm(&d) / norm(&g).max(1e-3));
        }
        // Friction dissipates and vanishes at rest.
        if let Some(f) = f {
            assert!(dot(&f, &qd) >= -1e-12 * norm(&f) * norm(&qd), "{}", M::NAME);
            let rest = m.friction(&x, &[0.0; N]).unwrap().unwrap();
            assert_eq!(norm(&rest), 0.0, "{}", M::NAME);
        }
        w.states += 1;
    }
    w
}

/// The potential energy of a bundled parallel or closed-loop spec by the runtime, `None` for a
/// tree.
fn potential(name: &str) -> Option<Box<Potential>> {
    let path = tests::pkm::spec_path(name);
    let src = std::fs::read_to_string(&path).ok()?;
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Parallel(pm), _)) => {
            let plan = runtime::parallel::Plan::new(&pm).unwrap();
            Some(Box::new(move |x: &[f64]| {
                runtime::parallel::noc::potential_energy(&plan, x).unwrap()
            }))
        }
        Ok((codegen::spec::Mechanism::Closed(cm), _)) => {
            let plan = runtime::closed::noc::Plan::new(&cm).unwrap();
            Some(Box::new(move |x: &[f64]| {
                runtime::closed::noc::potential_energy(&plan, x)
            }))
        }
        _ => None,
    }
}

#[test]
fn every_bundled_module_splits_its_efforts() {
    let mut report = Vec::new();
    macro_rules! each {
        ($($name:ident),* $(,)?) => {$({
            let m = mechanisms::$name::Module;
            let v = potential(stringify!($name));
            let w = check(&m, v.as_deref(), 0x5b11);
            report.push((stringify!($name), w));
        })*};
    }
    for_each_mechanism!(each);
    let mut worst = Worst::default();
    for (name, w) in &report {
        println!(
            "{name:>20}: sum {:.1e}, energy {:.1e}, power {:.1e}, quadratic {:.1e} ({} states)",
            w.sum, w.energy, w.power, w.quadratic, w.states
        );
        worst.sum = worst.sum.max(w.sum);
        worst.energy = worst.energy.max(w.energy);
        worst.power = worst.power.max(w.power);
        worst.quadratic = worst.quadratic.max(w.quadratic);
    }
    println!("worst: {worst:?}");
    assert!(worst.sum < 1e-11, "{worst:?}");
    assert!(worst.quadratic < 1e-12, "{worst:?}");
    assert!(worst.energy < 1e-7, "{worst:?}");
    assert!(worst.power < 1e-7, "{worst:?}");
}

/// The split with run-time drives (friction and rotor inertia on every joint) and a run-time
/// payload: the Gough–Stewart platform and the spherical five-bar of `tests/build.rs`
/// (`gs_params`, `closed_params`), with random drive values. The friction is then a function
/// of its own; the sum holds with it, it dissipates and vanishes at rest, and `C u` stays
/// quadratic with the rotors' terms in it.
#[test]
fn run_time_drives_split_into_friction() {
    macro_rules! drives {
        ($g:ident, $mass:expr, $visc:expr, $coul:expr, $arm:expr, $seed:expr) => {{
            use tests::variants::$g as g;
            const N: usize = g::DOF;
            let mut rng = tests::rng($seed);
            let mut worst = 0.0f64;
            let mut dissipated = 0.0f64;
            for _ in 0..STATES {
                let p = g::Params {
                    damping: core::array::from_fn(|_| rng.random_range(0.0..$visc)),
                    friction: core::array::from_fn(|_| rng.random_range(0.0..$coul)),
                    armature: core::array::from_fn(|_| rng.random_range(0.0..$arm)),
                    payload_mass: rng.random_range(0.0..$mass),
                    ..g::Params::DEFAULT
                };
                let q0 = g::inverse_kinematics(&g::HOME).unwrap();
                let q: [f64; N] =
                    core::array::from_fn(|i| q0[i] + 0.05 * rng.random_range(-1.0..1.0));
                let Ok(x) = g::forward_kinematics(&q, &g::HOME) else {
                    continue;
                };
                let u: [f64; N] = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
                let ud: [f64; N] = core::array::from_fn(|_| rng.random_range(-1.0..1.0));
                let tau = g::inverse_dynamics(&x, &u, &ud, &p).unwrap();
                let gr = g::gravity(&x, &p).unwrap();
                let c = g::coriolis(&x, &u, &p).unwrap();
                let f = g::friction(&x, &u, &p).unwrap();
                let qdd = g::actuator_rates(&x, &ud).unwrap();
                let ma = g::actuator_mass_matrix(&x, &p).unwrap();
                let inertial: Vec<f64> = (0..N).map(|i| dot(&ma[i], &qdd)).collect();
                let scale = [norm(&tau), norm(&inertial), norm(&c), norm(&gr), norm(&f)]
                    .into_iter()
                    .fold(0.0, f64::max);
                let d: Vec<f64> = (0..N)
                    .map(|i| inertial[i] + c[i] + gr[i] + f[i] - tau[i])
                    .collect();
                worst = worst.max(norm(&d) / scale);
                let c2 = g::coriolis(&x, &u.map(|v| 2.0 * v), &p).unwrap();
                let d: Vec<f64> = (0..N).map(|i| c2[i] - 4.0 * c[i]).collect();
                assert!(norm(&d) <= 1e-12 * norm(&c2), "{d:?}");
                let qd = g::actuator_rates(&x, &u).unwrap();
                let power = dot(&f, &qd);
                assert!(power >= -1e-12 * norm(&f) * norm(&qd), "{power}");
                dissipated = dissipated.max(power);
                assert_eq!(norm(&g::friction(&x, &[0.0; N], &p).unwrap()), 0.0);
            }
            // The friction is not zero (the check can fail).
            assert!(dissipated > 0.0);
            worst
        }};
    }
    let gs = drives!(gs_params, 20.0, 50.0, 20.0, 2.0, 0x5b12);
    let closed = drives!(closed_params, 1.0, 0.05, 0.02, 1e-3, 0x5b13);
    println!(
        "the sum with run-time drives: Gough–Stewart {gs:.1e}, spherical five-bar {closed:.1e}"
    );
    assert!(gs < 1e-11 && closed < 1e-11, "{gs:e} {closed:e}");
}
