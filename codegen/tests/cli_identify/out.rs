//! `identify --out` writes every base parameter the spec can carry back: a Delta's
//! parallelogram rods included. The "true" Delta is the bundled spec with its bodies' and rods'
//! numbers moved in its text (`perturbed_platform`); its efforts come from the runtime's `f64`
//! evaluator; the written spec is checked by the generator's `BASE_PARAMETERS` of its module
//! and by the runtime's inverse dynamics of its model against the true model's.

use super::platform::{
    DELTA, bundled, measure_platform, perturbed_platform, platform, platform_trajectory,
};
use super::{Rng, estimates, generated_base_parameters, ok, rel_floor, run, s, scratch, text};

/// Noise-free data of a perturbed Delta: the written spec's module has the estimates as its
/// `BASE_PARAMETERS`, all 37, and its model the true model's inverse dynamics.
#[test]
fn delta_out_writes_rods_and_reproduces_every_base_parameter() {
    use runtime::parallel::noc;
    let dir = scratch("delta_out");
    let nominal = bundled(DELTA);
    let spec = dir.join("spec.toml");
    std::fs::write(&spec, &nominal).unwrap();
    let truth_src = perturbed_platform(&nominal, 0.2, 0x0bad_5eed);
    let truth = platform("truth.toml", &truth_src);
    let true_base = generated_base_parameters("truth.toml", &truth_src);
    let states = platform_trajectory(&dir, &spec, &truth, 0.25, 0.1);
    let data = dir.join("exact.csv");
    measure_platform(&data, &states, &truth, 0.0, 1);
    let (est, out) = (dir.join("est.csv"), dir.join("updated.toml"));
    let o = run(&[
        "identify",
        s(&spec),
        s(&data),
        "--estimates",
        s(&est),
        "--out",
        s(&out),
    ]);
    ok(&o);
    let stderr = text(&o.stderr);
    assert!(
        !stderr.contains("cannot reproduce"),
        "noise-free estimates are a Delta the spec can write:\n{stderr}"
    );
    let (e, _) = estimates(&est);
    assert_eq!(e.len(), 37);
    // The estimates are the truth (an independent check of the data: the generator's constants
    // of the true spec).
    let err_truth = rel_floor(&e, &true_base, 1e-3);
    assert!(err_truth <= 1e-8, "{err_truth:e}");
    let src = std::fs::read_to_string(&out).unwrap();
    assert!(
        src.contains("rod_mass = \"identified_forearm_rod_mass[i]\""),
        "the rods are written per copy:\n{src}"
    );
    let written = generated_base_parameters("updated.toml", &src);
    // Relative per parameter; those below a thousandth of the largest (the products of inertia
    // and first moments that are zero in every Delta) against the largest.
    let err = rel_floor(&written, &e, 1e-3);
    eprintln!("delta --out: BASE_PARAMETERS of the written spec vs the 37 estimates {err:.2e}");
    assert!(err <= 1e-9, "{err:e}");
    // Its dynamics are the true Delta's on fresh states: the trajectory's positions with
    // random speeds and accelerations.
    let model = platform("updated.toml", &src);
    let (pw, pt) = (
        noc::Plan::new(&model).unwrap(),
        noc::Plan::new(&truth).unwrap(),
    );
    let mut r = Rng(99);
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for [x, _, _] in states.iter().step_by(23) {
        let u: Vec<f64> = (0..3).map(|_| 0.5 * r.gauss()).collect();
        let ud: Vec<f64> = (0..3).map(|_| 2.0 * r.gauss()).collect();
        let a = noc::inverse_dynamics(&pw, x, &u, &ud).unwrap();
        let b = noc::inverse_dynamics(&pt, x, &u, &ud).unwrap();
        for (a, b) in a.iter().zip(&b) {
            diff += (a - b) * (a - b);
            norm += b * b;
        }
    }
    let id_err = (diff / norm).sqrt();
    eprintln!(
        "delta --out: inverse dynamics of the written spec vs the truth {id_err:.2e} (relative 2-norm over 27 states)"
    );
    assert!(id_err <= 1e-9, "{id_err:e}");
}
