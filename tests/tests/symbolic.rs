//! The symbolic DAG (evaluated by its interpreter) against the runtime NOC and the independent
//! Newton–Euler / composite-body route, on random trees: every joint kind, generic axes, rotated
//! origins, full inertia tensors.

use codegen::sym::Arg;
use tests::{Shape, random_model, random_state, rel_err, rng};

fn check(seed: u64, shape: Shape, states: usize) -> f64 {
    let model = random_model(seed, shape);
    let s = codegen::symbolic(&model);
    let n = model.dof();
    let mut r = rng(seed ^ 0x5eed);
    let mut worst: f64 = 0.0;
    for _ in 0..states {
        let (q, qd, qdd) = random_state(&mut r, n);
        let tau: Vec<f64> = qdd.iter().map(|x| 3.0 * x).collect();
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            Arg::Tau => tau[i],
            Arg::X | Arg::U | Arg::Ud | Arg::P => f64::NAN, // parallel, run-time parameters
        };
        let id = s.graph.eval(&s.inverse_dynamics, &input);
        let mm = s.graph.eval(&s.mass_matrix, &input);
        let cor = s.graph.eval(&s.coriolis, &input);
        let gr = s.graph.eval(&s.gravity, &input);
        let fd = s.graph.eval(&s.forward_dynamics, &input);
        let id_noc = runtime::noc::inverse_dynamics(&model, &q, &qd, &qdd);
        let id_rnea = runtime::rnea::inverse_dynamics(&model, &q, &qd, &qdd);
        let mm_noc = runtime::noc::mass_matrix(&model, &q);
        let mm_noc: Vec<f64> = (0..n * n).map(|k| mm_noc[(k / n, k % n)]).collect();
        let cor_noc = runtime::noc::coriolis(&model, &q, &qd);
        let gr_noc = runtime::noc::gravity(&model, &q);
        let fd_noc = runtime::noc::forward_dynamics(&model, &q, &qd, &tau).expect("regular");
        for (a, b, what) in [
            (&id[..], id_noc.as_slice(), "inverse dynamics vs NOC"),
            (&id[..], id_rnea.as_slice(), "inverse dynamics vs RNEA"),
            (&mm[..], &mm_noc[..], "mass matrix"),
            (&cor[..], cor_noc.as_slice(), "coriolis"),
            (&gr[..], gr_noc.as_slice(), "gravity"),
            (&fd[..], fd_noc.as_slice(), "forward dynamics"),
        ] {
            let e = rel_err(a, b);
            assert!(
                e <= 1e-12,
                "{what}: relative error {e:e} (seed {seed}, {shape:?})"
            );
            worst = worst.max(e);
        }
    }
    worst
}

#[test]
fn random_chains_and_trees_agree_with_both_runtime_routes() {
    let mut worst: f64 = 0.0;
    for seed in 0..24u64 {
        let joints = 1 + (seed as usize % 9);
        for (chain, coord) in [(true, true), (true, false), (false, true), (false, false)] {
            let shape = Shape {
                joints,
                prismatic: 0.3,
                chain,
                coordinate_axes: coord,
            };
            worst = worst.max(check(seed, shape, 5));
        }
    }
    eprintln!("worst relative error (inf-norm): {worst:e}");
}
