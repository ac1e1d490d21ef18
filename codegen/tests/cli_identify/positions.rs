//! Positions-only data of a platform (`t, x, tau`): `identify` filters and differentiates `x`
//! as a tree's positions and turns the rates into the platform's speeds. The "true" Delta is
//! the bundled spec with its bodies' and rods' numbers moved in its text; its efforts come
//! from the runtime's `f64` evaluator at the exact states of an `excite` trajectory; the
//! reference is the generator's `BASE_PARAMETERS` of the true spec.

use super::platform::{DELTA, bundled, perturbed_platform, platform};
use super::{csv_rows, estimates, generated_base_parameters, ok, run, s, scratch, text};

/// Noise-free `t, x, tau` of a perturbed Delta sampled at 200 Hz along a 10 s trajectory of
/// five harmonics (0.1–0.5 Hz), `--cutoff 10`.
///
/// The bound, 1e-2 on `‖π̂ − π‖ / ‖π‖` (2-norm over the 37 base parameters), is the one the
/// tree's positions-only test has, and what the data allow: the filter passes the trajectory's
/// band with a gain `1 − (f/f_c)⁴ ≥ 1 − 6e-6`, central differences at 5 ms are exact to
/// `h² ω²/12 ≈ 2e-5` relative, and what remains is the ends: a cutoff period of samples is
/// dropped there, after which the accelerations are still off by up to 2e-3 m/s² (0.5 % of the
/// 0.44 m/s² peak; 5e-6 m/s² inside). That is an effort error of about 1e-5 of the efforts
/// (the residual RMS printed, 1e-4–4e-4 N·m against efforts of 20 N·m) which the weighted
/// regressor's condition number, 2e4, may amplify to 0.2 in a poorly excited direction; the
/// parameters that dominate the 2-norm (the platform's mass, the arms' first moments and
/// inertias) are well excited and measured 3.4e-3.
#[test]
fn delta_positions_only_recover_the_base_parameters() {
    use runtime::parallel::noc;
    let dir = scratch("delta_positions");
    let nominal = bundled(DELTA);
    let spec = dir.join("spec.toml");
    std::fs::write(&spec, &nominal).unwrap();
    let truth_src = perturbed_platform(&nominal, 0.2, 0x0bad_5eed);
    let truth = platform("truth.toml", &truth_src);
    let true_base = generated_base_parameters("truth.toml", &truth_src);
    let traj = dir.join("traj.csv");
    let o = run(&[
        "excite",
        s(&spec),
        "--restarts",
        "1",
        "--evaluations",
        "20",
        "--search-samples",
        "40",
        "--samples",
        "2000",
        "--seed",
        "7",
        "--reach",
        "0.25",
        "-o",
        s(&traj),
    ]);
    ok(&o);
    let (header, rows) = csv_rows(&traj);
    assert_eq!(&header[..5], ["t", "x1", "x2", "x3", "u1"]);
    let plan = noc::Plan::new(&truth).unwrap();
    let mut csv = String::from("t,x1,x2,x3,tau1,tau2,tau3\n");
    for r in &rows {
        let tau = noc::inverse_dynamics(&plan, &r[1..4], &r[4..7], &r[7..10]).unwrap();
        let cells: Vec<String> = r[..4].iter().chain(&tau).map(|v| format!("{v}")).collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    let data = dir.join("positions.csv");
    std::fs::write(&data, csv).unwrap();
    let est = dir.join("est.csv");
    let o = run(&[
        "identify",
        s(&spec),
        s(&data),
        "--cutoff",
        "10",
        "--estimates",
        s(&est),
    ]);
    ok(&o);
    let out = text(&o.stdout);
    assert!(
        out.contains("data: positions only: x and tau low-passed"),
        "{out}"
    );
    let (e, _) = estimates(&est);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let diff: Vec<f64> = e.iter().zip(&true_base).map(|(a, b)| a - b).collect();
    let err = norm(&diff) / norm(&true_base);
    eprintln!("delta, positions only: ‖estimate − true‖ / ‖true‖ = {err:.2e}");
    assert!(err <= 1e-2, "{err:e}");
    // Without `t` the positions cannot be differentiated: an error at the header.
    let no_t = dir.join("no_t.csv");
    std::fs::write(&no_t, "x1,x2,x3,tau1,tau2,tau3\n0,0,-1,1,1,1\n").unwrap();
    let o = run(&["identify", s(&spec), s(&no_t)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("a `t` column is needed"));
}
