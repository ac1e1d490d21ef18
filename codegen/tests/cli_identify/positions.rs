//! Positions-only data of a platform (`t, x, tau`): `identify` filters and differentiates `x`
//! as a tree's positions and turns the rates into the platform's speeds. The "true" Delta is
//! the bundled spec with its bodies' and rods' numbers moved in its text; its efforts come
//! from the runtime's `f64` evaluator at the exact states of an `excite` trajectory; the
//! reference is the generator's `BASE_PARAMETERS` of the true spec.

use super::platform::{DELTA, GS, bundled, perturbed_platform, platform};
use super::{csv_rows, estimates, generated_base_parameters, ok, run, s, scratch, text};

/// Noise-free `t, x, tau` of a perturbed Delta sampled at 200 Hz along a 10 s trajectory of
/// five harmonics (0.1–0.5 Hz), `--cutoff 10`: every parameter within its bound (as for the
/// Gough–Stewart below), and `‖π̂ − π‖ / ‖π‖` (2-norm over the 37 base parameters) within 1e-2,
/// the tree's bound. Measured: 3.4e-3 with one cutoff period dropped at the ends and the
/// efforts filtered alone, 7.2e-5 with three periods dropped, 9.2e-5 with parallel filtering,
/// 4.7e-5 with the five-point differences.
#[test]
fn delta_positions_only_recover_the_base_parameters() {
    let (err, dir, spec) = positions_only("delta_positions", DELTA, "2000", &["--reach", "0.25"]);
    eprintln!("delta, positions only: ‖estimate − true‖ / ‖true‖ = {err:.2e}");
    assert!(err <= 1e-2, "{err:e}");
    // Without `t` the positions cannot be differentiated: an error at the header.
    let no_t = dir.join("no_t.csv");
    std::fs::write(&no_t, "x1,x2,x3,tau1,tau2,tau3\n0,0,-1,1,1,1\n").unwrap();
    let o = run(&["identify", s(&spec), s(&no_t)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("a `t` column is needed"));
}

/// Noise-free `t, x, tau` of the perturbed platform `bundled_path` along an `excite`
/// trajectory of `samples` rows over 10 s (`bounds`: its `--reach`, `--turn`), identified with
/// `--cutoff 10`: `‖π̂ − π‖ / ‖π‖` (2-norm over the base parameters), the scratch directory and
/// the spec's path.
fn positions_only(
    test: &str,
    bundled_path: &str,
    samples: &str,
    bounds: &[&str],
) -> (f64, std::path::PathBuf, std::path::PathBuf) {
    use runtime::parallel::noc;
    let dir = scratch(test);
    let nominal = bundled(bundled_path);
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
        samples,
        "--seed",
        "7",
    ]
    .iter()
    .chain(bounds)
    .chain(&["-o", s(&traj)])
    .copied()
    .collect::<Vec<_>>());
    ok(&o);
    let (header, rows) = csv_rows(&traj);
    let (n, nx) = (truth.dof(), truth.nx());
    assert_eq!(header[1], "x1");
    assert_eq!(header[1 + nx], "u1");
    let plan = noc::Plan::new(&truth).unwrap();
    let mut csv = String::from("t");
    for k in 1..=nx {
        csv.push_str(&format!(",x{k}"));
    }
    for k in 1..=n {
        csv.push_str(&format!(",tau{k}"));
    }
    csv.push('\n');
    let mut peak = vec![0.0f64; n];
    for r in &rows {
        let (x, u, ud) = (
            &r[1..1 + nx],
            &r[1 + nx..1 + nx + n],
            &r[1 + nx + n..1 + nx + 2 * n],
        );
        let tau = noc::inverse_dynamics(&plan, x, u, ud).unwrap();
        for (p, t) in peak.iter_mut().zip(&tau) {
            *p = p.max(t.abs());
        }
        let cells: Vec<String> = r[..1 + nx]
            .iter()
            .chain(&tau)
            .map(|v| format!("{v}"))
            .collect();
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
    let (e, std) = estimates(&est);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let diff: Vec<f64> = e.iter().zip(&true_base).map(|(a, b)| a - b).collect();
    let names = super::platform::estimate_names(&est);
    // The bound per parameter (see `gough_stewart_positions_only_…`): `|δπ_k| ≤ √C_kk ‖δτ_w‖`
    // with `√C_kk = std_k / s_w`, `s_w² = Σ_j N ρ_j²/σ_j² / (N n − p)` from the printed
    // residual RMS `ρ_j` and weights' inverse `σ_j`, and `‖δτ_w‖² ≤ Σ_j N (ε T_j)²/σ_j²`.
    let per_joint = |start: &str| -> Vec<f64> {
        let line = out.lines().find(|l| l.starts_with(start)).unwrap();
        line.split(": ")
            .skip(1)
            .flat_map(|p| p.split(", "))
            .map(|w| w.rsplit(' ').next().unwrap().parse::<f64>().unwrap())
            .collect()
    };
    let (rho, sigma) = (
        per_joint("residual RMS per joint"),
        per_joint("noise estimate sigma_j"),
    );
    assert_eq!((rho.len(), sigma.len()), (n, n), "{out}");
    let header = out.lines().next().unwrap();
    let kept: f64 = header
        .split(": ")
        .nth(2)
        .and_then(|h| h.split(' ').next())
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| panic!("{header}"));
    let p = e.len() as f64;
    let s_w2 = (0..n)
        .map(|j| kept * (rho[j] / sigma[j]).powi(2))
        .sum::<f64>()
        / (kept * n as f64 - p);
    let dtau_w = (0..n)
        .map(|j| kept * (EPSILON * peak[j] / sigma[j]).powi(2))
        .sum::<f64>()
        .sqrt();
    let mut ratio = 0.0f64;
    for k in 0..e.len() {
        let bound = std[k] / s_w2.sqrt() * dtau_w;
        ratio = ratio.max(diff[k].abs() / bound);
        assert!(
            diff[k].abs() <= bound,
            "{test}: {} off by {:e}, bound {bound:e}",
            names[k],
            diff[k]
        );
    }
    let worst = (0..diff.len())
        .max_by(|&a, &b| diff[a].abs().total_cmp(&diff[b].abs()))
        .unwrap();
    eprintln!(
        "{test}: worst {} off by {:.2e} (true {:.3e}); the largest |δπ_k| / bound_k {ratio:.2e}",
        names[worst], diff[worst], true_base[worst]
    );
    (norm(&diff) / norm(&true_base), dir, spec)
}

/// The relative error of the efforts that the model, fed the filtered and differentiated
/// positions, makes on noise-free data. The measured efforts and the regressor's columns go
/// through the same linear filter, so what it does to the efforts' band cancels (the dynamics'
/// products of rates included); left is the model's input: the positions' gain error
/// `(f/f_c)⁴` at the trajectory's top harmonic (0.5 Hz at `--cutoff 10`: 6.3e-6), a
/// quaternion's second-order content at twice that (half-angles ≤ 0.125 rad: ≤ 8e-3 of it, cut
/// by 1e-4: 8e-7), the five-point differences' `(ωh)⁴/30` (2e-9 at 5 ms) and the ends'
/// transient after three cutoff periods (`2 · 1.6e-6` of the accelerations' peak): 1e-5.
const EPSILON: f64 = 1e-5;

/// Noise-free `t, x, tau` of a perturbed Gough–Stewart (a pose: the quaternion route of
/// `platform_rates.rs`) at 200 Hz along a 10 s trajectory of five harmonics, `--cutoff 10`.
/// The bound is per parameter and rigorous given the efforts' error: for the (weighted) least
/// squares, `δπ = C Yᵀ W δτ` gives `|δπ_k| ≤ √C_kk ‖W^½ δτ‖` (Cauchy–Schwarz), and
/// `|δτ_j| ≤ ε T_j` (`T_j` the joint's peak effort, `ε` = [`EPSILON`], from the filter's
/// response). The 2-norm is printed: 1.2e-2 before parallel filtering (the efforts filtered,
/// the model not), 4.4e-4 with it, 3.1e-4 with the five-point differences.
#[test]
fn gough_stewart_positions_only_recover_the_base_parameters() {
    let (err, _, _) = positions_only(
        "gs_positions",
        GS,
        "2000",
        &["--reach", "0.2", "--turn", "0.25"],
    );
    eprintln!("gough-stewart, positions only: ‖estimate − true‖ / ‖true‖ = {err:.2e}");
    assert!(err <= 1e-2, "{err:e}");
}
