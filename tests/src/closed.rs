//! Helpers for the closed-loop (joint-coordinate) tests: the bundled specs as models and random
//! assembled states.

use rand::Rng;
use rand::rngs::StdRng;
use runtime::closed::ClosedModel;
use runtime::closed::noc::{self, Plan};

pub use crate::bundled::CLOSED;

/// The validated model of a bundled closed-loop spec.
pub fn model(name: &str) -> ClosedModel {
    let path = crate::pkm::spec_path(name);
    let src = std::fs::read_to_string(&path).expect("spec readable");
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Closed(m), _)) => m,
        Ok(_) => panic!("{name} is not a closed-loop mechanism"),
        Err(d) => panic!("{d}"),
    }
}

/// A random assembled state: the independent coordinates moved from home by up to `reach`
/// (rad or m) and the rest found by Newton from home (retried until it converges and the
/// configuration is regular); speeds and rates uniform in ±1.
pub fn random_state(plan: &Plan, rng: &mut StdRng, reach: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = plan.dof();
    let home = vec![0.0; plan.nx()];
    loop {
        let xi: Vec<f64> = (0..n)
            .map(|_| reach * rng.random_range(-1.0..1.0))
            .collect();
        // One Newton solve from home (no path following): the states land on every branch
        // Newton reaches, a wider sample than home's own.
        let Ok(x) = noc::newton_assembly(plan, &xi, &home) else {
            continue;
        };
        if noc::inverse_dynamics(plan, &x, &vec![0.0; n], &vec![0.0; n]).is_err() {
            continue;
        }
        let u: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let ud: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        return (x, u, ud);
    }
}

/// How far (rad or m) the random states move the independent coordinates from home: the
/// N-four-bar's change points (bars horizontal) lie π/2 from home, so it stays within 1.2 rad;
/// the tripod's sliders move by up to 5 cm.
pub fn reach(name: &str) -> f64 {
    match name {
        "n_four_bar" => 1.2,
        "tripod_3prs" => 0.05,
        _ => 3.0,
    }
}

/// Random assembled states of the bundled closed loop `name` (`random_state` within
/// `reach(name)`).
pub fn assembled(name: &str) -> impl FnMut(&mut StdRng) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let plan = Plan::new(&model(name)).expect("a bundled closed loop has a plan");
    let reach = reach(name);
    move |r| random_state(&plan, r, reach)
}
