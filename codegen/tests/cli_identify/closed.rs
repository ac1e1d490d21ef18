//! `identify` and `excite` on closed loops in joint coordinates, end to end: the bundled
//! four-bar and Andrews' squeezer (a spring, given a damping here). The "true" mechanism is the
//! spec with its bodies' numbers and its springs' stiffness and damping moved in its text; its
//! efforts come from the runtime's `f64` closed-loop evaluator (`noc::inverse_dynamics` on its
//! `Plan`, at the configurations its own `newton_assembly` closes from the independent
//! coordinates `excite` wrote); the reference base parameters are the generator's
//! `BASE_PARAMETERS` of the true spec.

use std::path::Path;

use runtime::closed::ClosedModel;
use runtime::closed::noc;

use super::platform::{bundled, listed, nudge, perturb_body};
use super::{
    Rng, csv_rows, estimates, generated_base_parameters, identify_out, ok, rel, rel_floor, run, s,
    scratch, text,
};

const FOUR_BAR: &str = "../mechanisms/specs/four_bar.toml";

fn closed(name: &str, source: &str) -> ClosedModel {
    match codegen::spec::load(name, source, &Default::default()) {
        Ok(l) => match l.mechanism {
            codegen::spec::Mechanism::Closed(m) => m,
            _ => panic!("a closed loop"),
        },
        Err(d) => panic!("{}", d.render()),
    }
}

/// Every `[[body]]`'s mass, mass centre and inertia and every `[[spring]]`'s stiffness and
/// damping moved by up to ±`rel` in the spec's text.
fn perturbed_closed(source: &str, rel: f64, seed: u64) -> String {
    let mut doc: toml_edit::DocumentMut = source.parse().unwrap();
    let mut r = Rng(seed);
    let mut f = move || 1.0 + rel * (2.0 * r.uniform() - 1.0);
    for t in doc["body"].as_array_of_tables_mut().unwrap().iter_mut() {
        perturb_body(t, "", &mut f);
    }
    if let Some(a) = doc
        .get_mut("spring")
        .and_then(|i| i.as_array_of_tables_mut())
    {
        for t in a.iter_mut() {
            for key in ["stiffness", "damping"] {
                if let Some(v) = t.get(key).and_then(|i| i.as_value()).cloned() {
                    t[key] = toml_edit::value(nudge(&v, f(), 0.0));
                }
            }
        }
    }
    doc.to_string()
}

/// `excite` (a short search): the written independent coordinates, speeds and rates.
fn closed_trajectory(dir: &Path, spec: &Path, q_max: &str, qd_max: &str) -> Vec<[Vec<f64>; 3]> {
    let traj = dir.join("traj.csv");
    let o = run(&[
        "excite",
        s(spec),
        "--restarts",
        "1",
        "--evaluations",
        "30",
        "--samples",
        "600",
        "--seed",
        "3",
        "--q-max",
        q_max,
        "--qd-max",
        qd_max,
        "-o",
        s(&traj),
    ]);
    ok(&o);
    eprintln!("{}", text(&o.stderr).lines().last().unwrap_or(""));
    let (header, rows) = csv_rows(&traj);
    assert_eq!(header, ["t", "q1", "u1", "ud1"]);
    rows.iter()
        .map(|r| [vec![r[1]], vec![r[2]], vec![r[3]]])
        .collect()
}

/// The measurement file: `q, u, u̇` and the true mechanism's efforts (assembled from the row
/// before, the first from home) plus noise `sigma`.
fn measure_closed(path: &Path, states: &[[Vec<f64>; 3]], m: &ClosedModel, sigma: f64, seed: u64) {
    let plan = noc::Plan::new(m).unwrap();
    let mut x = plan.home();
    let mut r = Rng(seed);
    let mut csv = String::from("t,q1,u1,ud1,tau1\n");
    for (k, [q, u, ud]) in states.iter().enumerate() {
        x = noc::newton_assembly(&plan, q, &x).unwrap();
        let tau = noc::inverse_dynamics(&plan, &x, u, ud).unwrap();
        let mut line = vec![format!("{}", 0.01 * k as f64)];
        line.extend(q.iter().chain(u).chain(ud).map(|v| format!("{v}")));
        line.extend(tau.iter().map(|t| format!("{}", t + sigma * r.gauss())));
        csv.push_str(&line.join(","));
        csv.push('\n');
    }
    std::fs::write(path, csv).unwrap();
}

/// Identify a perturbed closed loop from its simulated efforts, without and with noise.
fn closed_end_to_end(test: &str, nominal: &str, q_max: &str, qd_max: &str, sigma: f64, seed: u64) {
    let noise_seed = std::env::var("NOISE_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(seed);
    let dir = scratch(test);
    let spec = dir.join("spec.toml");
    std::fs::write(&spec, nominal).unwrap();
    let truth_src = perturbed_closed(nominal, 0.2, 0x5eed);
    std::fs::write(dir.join("truth.toml"), &truth_src).unwrap();
    let truth = closed("truth.toml", &truth_src);
    let true_base = generated_base_parameters("truth.toml", &truth_src);
    let nominal_base = generated_base_parameters("spec.toml", nominal);
    let states = closed_trajectory(&dir, &spec, q_max, qd_max);
    let mut results = Vec::new();
    for (case, noise) in [("exact", 0.0), ("noisy", sigma)] {
        let data = dir.join(format!("{case}.csv"));
        measure_closed(&data, &states, &truth, noise, noise_seed);
        let est = dir.join(format!("{case}_est.csv"));
        let out = dir.join(format!("{case}_updated.toml"));
        let o = identify_out(&spec, &data, &est, &out);
        ok(&o);
        eprintln!("{}", text(&o.stdout));
        let (e, sd) = estimates(&est);
        assert_eq!(e.len(), true_base.len());
        let kept = listed(
            &text(&o.stderr),
            "note: no number the update writes moves",
            " (kept at",
        );
        let src = std::fs::read_to_string(&out).unwrap();
        let regenerated = generated_base_parameters("updated.toml", &src);
        let want: Vec<f64> = (0..e.len())
            .map(|k| {
                if kept.contains(&k) {
                    nominal_base[k]
                } else {
                    e[k]
                }
            })
            .collect();
        let err = rel(&regenerated, &want);
        eprintln!(
            "{test}: {case}: --out spec's BASE_PARAMETERS vs estimates {err:.2e} ({} kept at the spec's values)",
            kept.len()
        );
        assert!(err <= 1e-9, "{err:e}");
        results.push((e, sd));
    }
    // Relative per parameter, except that parameters below a millionth of the largest are
    // measured against that (Andrews' squeezer: inertias of 1e-7 kg·m² beside a stiffness of
    // 4530 N/m, whose efforts' rounding sets their floor: 5.4e-6 of themselves, 8 of the
    // deviations reported for the noise-free data; printed, not bounded).
    let (e0, sd0) = &results[0];
    let err0 = rel_floor(e0, &true_base, 1e-6);
    let z0 = (0..e0.len())
        .map(|k| (e0[k] - true_base[k]).abs() / sd0[k])
        .fold(0.0f64, f64::max);
    eprintln!(
        "{test}: noise-free: NBP = {}, max relative error {err0:.2e} (per parameter {:.2e}), worst z {z0:.2}",
        e0.len(),
        rel_floor(e0, &true_base, 1e-15)
    );
    assert!(err0 <= 1e-8, "{err0:e}");
    let (e, sd) = &results[1];
    let z: Vec<f64> = (0..e.len())
        .map(|k| (e[k] - true_base[k]).abs() / sd[k])
        .collect();
    let worst = z.iter().fold(0.0f64, |m, v| m.max(*v));
    let mean_z2 = z.iter().map(|v| v * v).sum::<f64>() / e.len() as f64;
    eprintln!(
        "{test}: noise σ = {sigma} (seed {noise_seed}): worst z = {worst:.2}, mean z² = {mean_z2:.2}"
    );
    for (k, z) in z.iter().enumerate() {
        assert!(
            *z <= 3.0,
            "parameter {k}: {} vs {} (std {})",
            e[k],
            true_base[k],
            sd[k]
        );
    }
    assert!((0.2..=2.5).contains(&mean_z2), "{mean_z2}");
}

#[test]
fn four_bar_parameters_are_recovered() {
    closed_end_to_end("four_bar", &bundled(FOUR_BAR), "1.0", "2.0", 0.01, 2);
}

#[test]
fn andrews_squeezer_with_a_damped_spring_is_recovered() {
    let src = bundled("../mechanisms/specs/andrews_squeezer.toml");
    let mut doc: toml_edit::DocumentMut = src.parse().unwrap();
    doc["spring"]
        .as_array_of_tables_mut()
        .unwrap()
        .get_mut(0)
        .unwrap()["damping"] = toml_edit::value(2.0);
    closed_end_to_end("andrews", &doc.to_string(), "3.0", "5.0", 1e-6, 2);
}

#[test]
fn closed_loop_bad_input_is_exit_code_2_without_a_panic() {
    let dir = scratch("closed_bad");
    let head = "t,q1,u1,ud1,tau1\n";
    let rows = |q: &str| {
        let mut t = String::from(head);
        for k in 0..20 {
            t.push_str(&format!(
                "{},{},0.1,0.2,0.3\n",
                0.01 * k as f64,
                0.001 * k as f64
            ));
        }
        t.push_str(&format!("0.2,{q},0.1,0.2,0.3\n"));
        t
    };
    let x_rows = "t,x1,x2,u1,ud1,tau1\n".to_string() + &"0,0,0,0,0,0\n".repeat(20);
    // The four-bar driven at its rocker, whose angle from the ground line (1.5048 rad at
    // home, x = 0) cannot reach 0: the coupler and crank reach 0.9 m, the rocker's end would be
    // 1.1 m from the crank's pivot.
    let rocker = dir.join("rocker.toml");
    std::fs::write(
        &rocker,
        bundled(FOUR_BAR).replace("actuated = true\n", "").replace(
            "axis = [0.0, 0.0, 1.0]\n\n# Closes",
            "axis = [0.0, 0.0, 1.0]\nactuated = true\n\n# Closes",
        ),
    )
    .unwrap();
    let cases: Vec<(&str, &Path, String, &str)> = vec![
        (
            "jump",
            &rocker,
            rows("-1.5"),
            "bad_jump.csv:22: the loops do not close",
        ),
        (
            "missing",
            Path::new(FOUR_BAR),
            "t,q1,u1,tau1\n0,0,0,0\n".into(),
            "missing column ud1",
        ),
        ("nan", Path::new(FOUR_BAR), rows("NaN"), "not finite"),
        (
            "x_missing",
            Path::new(FOUR_BAR),
            x_rows,
            "missing column x3",
        ),
    ];
    for (name, spec, body, want) in cases {
        let path = dir.join(format!("bad_{name}.csv"));
        std::fs::write(&path, body).unwrap();
        let o = run(&["identify", s(spec), s(&path)]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(want), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
    for args in [
        vec!["excite", FOUR_BAR, "--q-max", "1,2"],
        vec!["excite", FOUR_BAR, "--with-tau", "--noise", "0.1,0.2"],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stderr));
        assert!(!text(&o.stderr).contains("panicked"));
    }
}

/// `excite` on a closed loop whose default bound (`--q-max 1`) leaves its workspace (the
/// five-bar's distal links reach only about ±0.26 rad of its motors' home angles): exit 2,
/// and the error names the closed loop's bounds, `--q-max`/`--qd-max`, not a platform's
/// `--reach`/`--turn` (which a closed loop does not take), and says that no candidate stayed
/// in the workspace rather than blaming the gaps between the search's samples.
#[test]
fn closed_loop_out_of_its_workspace_names_its_own_bounds() {
    let o = run(&[
        "excite",
        "../mechanisms/specs/five_bar_joints.toml",
        "--restarts",
        "1",
        "--evaluations",
        "5",
    ]);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.lines().last().unwrap_or("");
    assert!(last.contains("reduce --q-max or --qd-max"), "{last}");
    assert!(!last.contains("--reach"), "{last}");
    assert!(last.contains("no trajectory the search tried"), "{last}");
    // With a bound inside the workspace it writes a trajectory.
    let dir = scratch("closed_reach");
    let traj = dir.join("traj.csv");
    let o = run(&[
        "excite",
        "../mechanisms/specs/five_bar_joints.toml",
        "--restarts",
        "1",
        "--evaluations",
        "5",
        "--q-max",
        "0.1",
        "-o",
        s(&traj),
    ]);
    ok(&o);
}

/// The same samples given as all tree coordinates `x1..xNX` (assembled here by the runtime)
/// give the estimates of the independent coordinates' file, and `excite` writes the same bytes
/// for a seed.
#[test]
fn all_coordinates_give_the_same_estimates_and_excite_repeats() {
    let dir = scratch("closed_x");
    let spec = Path::new(FOUR_BAR);
    let states = closed_trajectory(&dir, spec, "1.0", "2.0");
    let first = std::fs::read(dir.join("traj.csv")).unwrap();
    closed_trajectory(&dir, spec, "1.0", "2.0");
    assert_eq!(first, std::fs::read(dir.join("traj.csv")).unwrap());
    let m = closed("four_bar.toml", &bundled(FOUR_BAR));
    let q_file = dir.join("q.csv");
    measure_closed(&q_file, &states, &m, 0.01, 4);
    let plan = noc::Plan::new(&m).unwrap();
    let mut x = plan.home();
    let (_, rows) = csv_rows(&q_file);
    let mut csv = format!(
        "t,{},u1,ud1,tau1\n",
        (1..=m.nx())
            .map(|i| format!("x{i}"))
            .collect::<Vec<_>>()
            .join(",")
    );
    for r in &rows {
        x = noc::newton_assembly(&plan, &r[1..2], &x).unwrap();
        let mut line = vec![r[0]];
        line.extend(&x);
        line.extend(&r[2..5]);
        let line: Vec<String> = line.iter().map(|v| format!("{v}")).collect();
        csv.push_str(&line.join(","));
        csv.push('\n');
    }
    let x_file = dir.join("x.csv");
    std::fs::write(&x_file, csv).unwrap();
    let mut got = Vec::new();
    for (name, data) in [("q", &q_file), ("x", &x_file)] {
        let est = dir.join(format!("{name}_est.csv"));
        ok(&run(&[
            "identify",
            FOUR_BAR,
            s(data),
            "--estimates",
            s(&est),
        ]));
        got.push(estimates(&est));
    }
    let err = rel(&got[1].0, &got[0].0);
    eprintln!("x1..x3 against q1: estimates {err:.2e} (relative)");
    assert!(err <= 1e-9, "{err:e}");
}
