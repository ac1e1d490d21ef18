//! The two routes to a tree's `(∂τ/∂q, ∂τ/∂q̇)` agree: the recursive analytic derivatives
//! (`codegen::dynamics::recursive_inverse_dynamics_derivatives`, composite quantities per body)
//! against forward-mode differentiation of the inverse-dynamics DAG
//! (`inverse_dynamics_derivatives`), which share no formula beyond the forward
//! sweep. Every bundled tree, plain, with friction and rotor inertia, and with run-time
//! parameters (a payload and a run-time body, drive coefficients as inputs); 200 random states
//! each, both graphs evaluated by the generator's interpreter; ≤ 1e-12 relative in the ∞-norm
//! over each matrix (denominator at least 1).
//!
//! The generated modules (whichever route each keeps) are checked against independent routes
//! in `derivatives.rs` (differences of the runtime RNEA) and `chain_derivatives.rs` (dual
//! numbers through the runtime's closed-loop evaluator).

use codegen::dynamics::{
    Terms, Tree, inverse_dynamics, inverse_dynamics_derivatives,
    recursive_inverse_dynamics_derivatives,
};
use codegen::sym::{Arg, Graph};
use rand::Rng;
use runtime::model::Model;
use tests::{rel_err, rng};

const STATES: usize = 200;

const TREES: [&str; 7] = [
    "planar_2r.toml",
    "puma560.toml",
    "puma560.urdf",
    "stanford_arm.toml",
    "gripper_tree.toml",
    "chain7.toml",
    "iiwa14.urdf",
];

fn model(file: &str, scene: &str) -> Model {
    let path = format!("{}/../mechanisms/specs/{file}", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(path).unwrap();
    let src = if scene.is_empty() {
        src
    } else {
        format!("{src}\n{scene}")
    };
    match codegen::spec::load_tree(file, &src) {
        Ok((m, _)) => m,
        Err(d) => panic!("{d}"),
    }
}

/// The worst relative error of the recursive route against forward mode over the states, and
/// the flops of each route's outputs (forward mode first).
fn compare(tree: &Tree, seed: u64) -> (f64, usize, usize) {
    let n = tree.dof();
    let mut g = Graph::new();
    let id = inverse_dynamics(&mut g, tree, Terms::ALL);
    let mut fg = g.clone();
    let fwd = inverse_dynamics_derivatives(&mut fg, &id);
    let mut rg = g.clone();
    let rec = recursive_inverse_dynamics_derivatives(&mut rg, tree);
    assert_eq!(fwd.len(), 2 * n * n);
    assert_eq!(rec.len(), 2 * n * n);
    let mut r = rng(seed);
    let mut worst = 0.0f64;
    for _ in 0..STATES {
        let q: Vec<f64> = (0..n).map(|_| r.random_range(-3.0..3.0)).collect();
        let qd: Vec<f64> = (0..n).map(|_| r.random_range(-3.0..3.0)).collect();
        let qdd: Vec<f64> = (0..n).map(|_| r.random_range(-5.0..5.0)).collect();
        let p: Vec<f64> = (0..256).map(|_| r.random_range(0.05..1.0)).collect();
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            Arg::P => p[i],
            _ => panic!("unexpected input {a:?}"),
        };
        let a = fg.eval(&fwd, &input);
        let b = rg.eval(&rec, &input);
        for m in 0..2 {
            let part = m * n * n..(m + 1) * n * n;
            worst = worst.max(rel_err(&b[part.clone()], &a[part]));
        }
    }
    let flops = |g: &Graph, roots: &[codegen::sym::ExprId]| {
        let mut seen = std::collections::HashSet::new();
        let mut stack = roots.to_vec();
        let mut count = 0;
        while let Some(id) = stack.pop() {
            if !seen.insert(id) {
                continue;
            }
            use codegen::sym::Node::*;
            if matches!(
                g.node(id),
                Add(..) | Sub(..) | Mul(..) | Div(..) | Neg(..) | Sqrt(..)
            ) {
                count += 1;
            }
            stack.extend(g.operands(id));
        }
        count
    };
    (worst, flops(&fg, &fwd), flops(&rg, &rec))
}

#[test]
fn recursive_route_equals_forward_mode_on_every_bundled_tree() {
    let scenes = [
        ("plain", ""),
        ("drives", "[scene]\nfriction = true\nrotor_inertia = true\n"),
    ];
    let mut failures = Vec::new();
    for (k, file) in TREES.iter().enumerate() {
        for (s, (label, scene)) in scenes.iter().enumerate() {
            if file.ends_with(".urdf") && !scene.is_empty() {
                continue; // a URDF has no `[scene]`
            }
            let m = model(file, scene);
            let n = m.dof();
            let mut trees = vec![(label.to_string(), Tree::new(&m))];
            if s == 0 {
                // A payload on the last body and a run-time body on the first.
                let t = Tree::new(&m)
                    .with_runtime_params(Some(n - 1), 0.05)
                    .with_runtime_bodies(&[0]);
                trees.push(("runtime parameters".into(), t));
            }
            for (label, t) in trees {
                let (e, ff, fr) = compare(&t, 1000 + 10 * k as u64 + s as u64);
                eprintln!("{file} ({label}): {e:.2e}; flops forward mode {ff}, recursive {fr}");
                if e > 1e-12 {
                    failures.push(format!("{file} ({label}): {e:e}"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The recursive route needs fewer flops on the 7-joint arms (so that their modules use it):
/// flops of the two routes' outputs.
#[test]
fn recursive_route_is_cheaper_on_seven_joint_arms() {
    for file in ["chain7.toml", "iiwa14.urdf"] {
        let (_, ff, fr) = compare(&Tree::new(&model(file, "")), 7);
        assert!(fr < ff, "{file}: recursive {fr} flops, forward mode {ff}");
    }
}
