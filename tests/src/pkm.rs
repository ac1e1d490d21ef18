//! Helpers for the parallel-manipulator tests: the bundled specs as models, random
//! in-workspace states, and a strict relative error.

use rand::Rng;
use rand::rngs::StdRng;
use runtime::parallel::ParallelModel;
use runtime::parallel::noc::{self, Plan};

pub use crate::bundled::PARALLEL;

/// The spec file of a bundled mechanism.
pub fn spec_path(name: &str) -> std::path::PathBuf {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    root.join("mechanisms/specs").join(format!("{name}.toml"))
}

/// The validated model of a bundled parallel spec.
pub fn model(name: &str) -> ParallelModel {
    let path = spec_path(name);
    let src = std::fs::read_to_string(&path).expect("spec readable");
    match codegen::spec::load_mechanism(&path.to_string_lossy(), &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => m,
        Ok(_) => panic!("{name} is not a parallel mechanism"),
        Err(d) => panic!("{d}"),
    }
}

/// Unit quaternion `[w, x, y, z]` of a rotation matrix.
pub fn matrix_quaternion(r: &[[f64; 3]; 3]) -> [f64; 4] {
    runtime::model::matrix_quaternion(r)
}

/// The home coordinates `x` of a model.
pub fn home_x(m: &ParallelModel) -> Vec<f64> {
    m.home_x()
}

/// A random state near home that the runtime accepts: `x`, `u`, `ud`. Rotations up to
/// `angle` rad, translations up to `reach` m; speeds and rates uniform in ±1.
pub fn random_state(
    plan: &Plan,
    home: &[f64],
    rng: &mut StdRng,
    angle: f64,
    reach: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = plan.dof();
    loop {
        let mut d = vec![0.0; n];
        for (i, v) in d.iter_mut().enumerate() {
            let planar = plan.motion.translates();
            // A planar pose's φ is its third coordinate.
            let turns = if plan.motion.planar_pose() {
                i == 2
            } else if plan.motion.parasitic() {
                // A 1T2R platform's x = [pz, α, β].
                i >= 1
            } else if plan.motion.schoenflies() {
                // A Schönflies platform's x = [px, py, pz, θ].
                i == 3
            } else {
                i < 3 && !planar
            };
            *v = if turns { angle } else { reach } * rng.random_range(-1.0..1.0);
        }
        let x = noc::retract(plan.motion, home, &d);
        if noc::inverse_dynamics(plan, &x, &vec![0.0; n], &vec![0.0; n]).is_err() {
            continue;
        }
        let u: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let ud: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        return (x, u, ud);
    }
}

/// `‖a − b‖∞ / ‖b‖∞` (strictly relative; infinite for NaN).
pub fn rel(a: &[f64], b: &[f64]) -> f64 {
    let num = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let den = b.iter().map(|y| y.abs()).fold(1e-300, f64::max);
    if num.is_nan() || a.len() != b.len() {
        f64::INFINITY
    } else {
        num / den
    }
}

/// Random regular states of the bundled platform `name` near home (`random_state`, rotations
/// up to 0.1 rad, translations up to 2 % of its size).
pub fn near_home(name: &str) -> impl FnMut(&mut StdRng) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let m = model(name);
    let plan = Plan::new(&m).expect("a bundled platform has a plan");
    let home = home_x(&m);
    let reach = 0.02 * m.size();
    move |r| random_state(&plan, &home, r, 0.1, reach)
}
