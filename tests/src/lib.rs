//! Shared helpers for nocdyn's integration tests: random models and states, error norms.
#![allow(clippy::needless_range_loop)]

pub mod agree;
pub mod base_parameters;
mod bundled;
pub mod closed;
pub mod dual;

pub mod pkm;
pub mod routes;
pub mod variants;

use rand::{Rng, SeedableRng, rngs::StdRng};
use runtime::model::{Body, Joint, JointKind, Model, Transform, rpy_to_matrix};

/// A deterministic random-number generator for a test (seeded, so failures reproduce).
pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// A random unit vector.
pub fn unit(rng: &mut StdRng) -> [f64; 3] {
    loop {
        let v: [f64; 3] = [
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if n > 0.1 && n <= 1.0 {
            return [v[0] / n, v[1] / n, v[2] / n];
        }
    }
}

/// A random physically valid inertia tensor about the mass centre (rotated principal moments
/// satisfying the triangle inequality).
pub fn inertia(rng: &mut StdRng) -> [[f64; 3]; 3] {
    let a: f64 = rng.random_range(0.01..1.0);
    let b: f64 = rng.random_range(0.01..1.0);
    let c: f64 = rng.random_range((a - b).abs() + 0.001..a + b);
    let r = rpy_to_matrix([
        rng.random_range(-3.0..3.0),
        rng.random_range(-1.5..1.5),
        rng.random_range(-3.0..3.0),
    ]);
    let d = [a, b, c];
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum();
        }
    }
    for i in 0..3 {
        for j in 0..i {
            m[i][j] = m[j][i];
        }
    }
    m
}

/// Options for [`random_model`].
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// Number of joints.
    pub joints: usize,
    /// Probability that a joint is prismatic.
    pub prismatic: f64,
    /// `true`: a serial chain; `false`: a random tree.
    pub chain: bool,
    /// `true`: joint axes along ±coordinate axes (as in most real robots); else generic.
    pub coordinate_axes: bool,
}

/// A random model: generic origins, axes, inertias, gravity.
pub fn random_model(seed: u64, shape: Shape) -> Model {
    let mut rng = rng(seed);
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    for i in 0..shape.joints {
        let parent = if i == 0 {
            None
        } else if shape.chain {
            Some(i - 1)
        } else if rng.random_bool(0.2) {
            None
        } else {
            Some(rng.random_range(0..i))
        };
        let kind = if rng.random_bool(shape.prismatic) {
            JointKind::Prismatic
        } else {
            JointKind::Revolute
        };
        let axis = if shape.coordinate_axes {
            let k = rng.random_range(0..3);
            let mut a = [0.0; 3];
            a[k] = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            a
        } else {
            unit(&mut rng)
        };
        let xyz = [
            rng.random_range(-0.5..0.5),
            rng.random_range(-0.5..0.5),
            rng.random_range(-0.5..0.5),
        ];
        let rpy = [
            rng.random_range(-3.0..3.0),
            rng.random_range(-1.5..1.5),
            rng.random_range(-3.0..3.0),
        ];
        joints.push(Joint {
            name: format!("j{i}"),
            kind,
            parent,
            origin: Transform::from_xyz_rpy(xyz, rpy),
            axis,
            drive: Default::default(),
        });
        bodies.push(Body {
            name: format!("b{i}"),
            mass: rng.random_range(0.1..5.0),
            com: [
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.3..0.3),
            ],
            inertia: inertia(&mut rng),
        });
    }
    let g = unit(&mut rng);
    Model {
        name: format!("random_{seed}"),
        gravity: [9.81 * g[0], 9.81 * g[1], 9.81 * g[2]],
        bodies,
        joints,
    }
}

/// A random state `(q, q̇, q̈)` of `n` joints.
pub fn random_state(rng: &mut StdRng, n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let q = (0..n)
        .map(|_| rng.random_range(-std::f64::consts::PI..std::f64::consts::PI))
        .collect();
    let qd = (0..n).map(|_| rng.random_range(-2.0..2.0)).collect();
    let qdd = (0..n).map(|_| rng.random_range(-5.0..5.0)).collect();
    (q, qd, qdd)
}

/// Relative error `‖a − b‖∞ / max(‖b‖∞, 1)` (the norm).
pub fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let num = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let den = b.iter().map(|y| y.abs()).fold(1.0, f64::max);
    if num.is_nan() {
        f64::INFINITY
    } else {
        num / den
    }
}
