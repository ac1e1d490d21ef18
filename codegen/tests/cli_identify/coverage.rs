//! The reported standard deviations describe the estimates' errors: over many noise seeds, not
//! one. A planar 2R arm with viscous and Coulomb friction and rotor inertia (11 base
//! parameters: the rotor inertia of the first joint groups with its link), one `excite`
//! trajectory, efforts from the runtime's spatial RNEA plus the drive
//! law (independent of the regressor) with Gaussian noise of known σ per joint, one noise
//! sequence per seed; the reference is the generator's `BASE_PARAMETERS` of the spec.

use super::{Rng, csv_rows, estimates, generated_base_parameters, ok, run, s, scratch, tree};

/// The planar 2R of `mechanisms/specs/` with drives (friction and rotor inertia on).
fn spec() -> String {
    let nominal = super::platform::bundled("../mechanisms/specs/planar_2r.toml");
    let mut doc: toml_edit::DocumentMut = nominal.parse().unwrap();
    for (t, (b, c, a)) in doc["joint"]
        .as_array_of_tables_mut()
        .unwrap()
        .iter_mut()
        .zip([(0.8, 1.5, 0.05), (0.4, 0.7, 0.02)])
    {
        t["damping"] = toml_edit::value(b);
        t["friction"] = toml_edit::value(c);
        t["armature"] = toml_edit::value(a);
    }
    format!("{doc}\n[scene]\nfriction = true\nrotor_inertia = true\n")
}

/// Over 100 noise seeds the standardized errors `z = (π̂_k − π_k) / std_k` behave as standard
/// normal variables: at least 95 % of them within 3, and their RMS within [0.7, 1.4].
///
/// The bounds. For a correct estimator, with the noise estimated from 800 − 11 residual degrees
/// of freedom, each `z` is Student-t with 789 degrees of freedom, indistinguishable from
/// N(0, 1): `P(|z| > 3) = 0.0027`, so 0.997 of the 1,100 values are expected within 3 (3
/// outside). The bound 0.95 allows 55 outside. With independent values that has a probability
/// below 1e-40; the 11 values of a seed are correlated (through `(WᵀW)⁻¹`), and even if they
/// moved as one, 5 of the 100 seeds would have to fail, each with probability at most
/// 11 · 0.0027 = 0.03 (Poisson mean 3: probability 0.18 in that extreme, far below it in
/// truth). Deviations reported 1.5 times too small give `P(|z| > 3) = 0.045` and are caught by
/// the RMS. The mean of `z²` has expectation 1 and, for 1,100 independent values, standard
/// deviation `√(2/1100) = 0.043`; correlation within a seed can inflate that at most to
/// `√(11 · 2/1100) = 0.14`. RMS in [0.7, 1.4] (mean `z²` in [0.49, 1.96]) is more than 3.5 of
/// those widest deviations from 1, and fails for deviations wrong by 30 % either way.
#[test]
fn three_sigma_coverage_holds_over_many_noise_seeds() {
    let dir = scratch("coverage");
    let src = spec();
    let path = dir.join("planar_2r.toml");
    std::fs::write(&path, &src).unwrap();
    let model = tree("planar_2r.toml", &src);
    let truth = generated_base_parameters("planar_2r.toml", &src);
    let traj = dir.join("traj.csv");
    let o = run(&[
        "excite",
        s(&path),
        "--seed",
        "1",
        "--restarts",
        "1",
        "--evaluations",
        "60",
        "--samples",
        "400",
        "-o",
        s(&traj),
    ]);
    ok(&o);
    let (header, rows) = csv_rows(&traj);
    assert_eq!(header, ["t", "q1", "q2", "qd1", "qd2", "qdd1", "qdd2"]);
    let clean: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| {
            let (q, qd, qdd) = (&r[1..3], &r[3..5], &r[5..7]);
            let tau = runtime::rnea::inverse_dynamics(&model, q, qd, qdd);
            (0..2)
                .map(|i| tau[i] + model.joints[i].drive.effort(qd[i], qdd[i]))
                .collect()
        })
        .collect();
    let sigma = [0.05, 0.02];
    let (mut z, mut seeds) = (Vec::new(), 0);
    for seed in 1..=100u64 {
        let mut r = Rng(seed);
        let mut csv = String::from("t,q1,q2,qd1,qd2,qdd1,qdd2,tau1,tau2\n");
        for (row, tau) in rows.iter().zip(&clean) {
            let mut cells: Vec<String> = row.iter().map(|v| format!("{v}")).collect();
            for i in 0..2 {
                cells.push(format!("{}", tau[i] + sigma[i] * r.gauss()));
            }
            csv.push_str(&cells.join(","));
            csv.push('\n');
        }
        let data = dir.join("data.csv");
        std::fs::write(&data, csv).unwrap();
        let est = dir.join("est.csv");
        let o = run(&["identify", s(&path), s(&data), "--estimates", s(&est)]);
        ok(&o);
        let (e, sd) = estimates(&est);
        assert_eq!(e.len(), truth.len());
        z.extend((0..e.len()).map(|k| (e[k] - truth[k]) / sd[k]));
        seeds += 1;
    }
    let within = z.iter().filter(|v| v.abs() <= 3.0).count() as f64 / z.len() as f64;
    let rms = (z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64).sqrt();
    let worst = z.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    eprintln!(
        "coverage: {seeds} seeds x {} base parameters: {:.4} within 3 std, RMS of z {rms:.3}, worst |z| {worst:.2}",
        truth.len(),
        within
    );
    assert!(within >= 0.95, "{within}");
    assert!((0.7..=1.4).contains(&rms), "{rms}");
}
