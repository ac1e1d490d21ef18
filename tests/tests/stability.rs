//! Stability: every kind of bundled mechanism released from rest under gravity, no actuation,
//! no friction, 10 s at 1 kHz (fixed-step RK4 and symplectic Euler, `runtime::simulate`). The
//! total energy must stay put (RK4 relative drift, `max |E − E0| / max T`, below 1e-6) and the
//! closed loops must stay closed (coordinate partitioning: assembled by Newton every stage). A
//! run that meets a singular configuration must stop there with an error, never with NaN.

use runtime::simulate::{Method, Report, simulate};

const DT: f64 = 1e-3;
const STEPS: usize = 10_000;

fn row(name: &str, method: Method, r: &Report) {
    println!(
        "| {name} | {method:?} | {:.3} | {:.2e} | {:.2e} | {:.1e} | {} |",
        r.time,
        r.max_kinetic,
        r.relative_drift(),
        r.max_closure,
        r.stopped.as_deref().unwrap_or("—")
    );
}

fn check(name: &str, r: &Report, full_run: bool) {
    assert!(
        r.max_drift.is_finite() && r.max_kinetic.is_finite(),
        "{name}: {r:?}"
    );
    if full_run {
        assert!(r.stopped.is_none(), "{name} stopped: {r:?}");
        assert!((r.time - 10.0).abs() < 1e-9);
    }
    assert!(r.max_closure < 1e-9, "{name}: loops opened: {r:?}");
}

#[test]
fn energy_is_conserved_without_actuation() {
    println!("| mechanism | method | time [s] | max T [J] | drift / max T | closure | stopped |");
    println!("|---|---|---:|---:|---:|---:|---|");
    for (name, q0) in [
        ("planar_2r", vec![0.3, -0.5]),
        ("puma560", vec![0.1, -0.6, 0.4, 0.2, -0.3, 0.5]),
    ] {
        let path = tests::pkm::spec_path(name);
        let src = std::fs::read_to_string(&path).unwrap();
        let (model, _) = codegen::spec::load_tree(&path.to_string_lossy(), &src).unwrap();
        let mech = &model;
        for method in [Method::Rk4, Method::SymplecticEuler] {
            let r = simulate(mech, &q0, &vec![0.0; q0.len()], DT, STEPS, method).unwrap();
            row(name, method, &r);
            check(name, &r, true);
            if method == Method::Rk4 {
                assert!(r.relative_drift() < 1e-6, "{name}: {r:?}");
            }
        }
    }
    for name in tests::closed::CLOSED {
        let model = tests::closed::model(name);
        // Released under gravity at 1 kHz: Andrews' squeezer has no gravity, and its spring
        // turns the crank at ~1000 rad/s, a time scale of microseconds that a 1 ms step cannot
        // follow (its own test integrates at 2.5 µs against the published solution).
        if model.tree.gravity == [0.0; 3] {
            continue;
        }
        let plan = runtime::closed::Plan::new(&model).unwrap();
        let mech = &plan;
        let x0 = vec![0.0; plan.nx()];
        for method in [Method::Rk4, Method::SymplecticEuler] {
            let r = simulate(mech, &x0, &vec![0.0; plan.dof()], DT, STEPS, method).unwrap();
            row(name, method, &r);
            // Falling freely, the five-bars and the Bricard linkage reach configurations where
            // their actuated joints stop determining the others (the five-bar's distal links
            // aligned): Newton's assembly fails there and the run stops with that error. The
            // four-bar, the N-four-bar and the tripod run the full 10 s.
            check(
                name,
                &r,
                matches!(name, "four_bar" | "n_four_bar" | "tripod_3prs"),
            );
            if method == Method::Rk4 && r.stopped.is_none() {
                assert!(r.relative_drift() < 1e-6, "{name}: {r:?}");
            }
        }
    }
    for name in ["agile_eye", "planar_five_bar", "gough_stewart"] {
        let model = tests::pkm::model(name);
        let plan = runtime::parallel::Plan::new(&model).unwrap();
        let mech = &plan;
        let x0 = model.home_x();
        for method in [Method::Rk4, Method::SymplecticEuler] {
            let r = simulate(mech, &x0, &vec![0.0; plan.dof()], DT, STEPS, method).unwrap();
            row(name, method, &r);
            // Passive legs: the five-bar and the Agile Eye fall until a leg singularity, where
            // the run must stop with the error; the Gough–Stewart platform falls freely (its
            // prismatic legs extend) for the full 10 s.
            check(name, &r, name == "gough_stewart");
            if method == Method::Rk4 && r.stopped.is_none() {
                assert!(r.relative_drift() < 1e-6, "{name}: {r:?}");
            }
        }
    }
}
