//! The generated `regressor` and base parameters of the bundled closed-loop modules (issue 23's
//! checks, for closed loops in joint coordinates):
//! * `regressor · BASE_PARAMETERS` equals the module's `inverse_dynamics` on 500 random
//!   assembled states each (‖a − b‖∞ / ‖b‖∞ ≤ 1e-12);
//! * `NBP` is the rank of the standard regressor built by another route: the runtime's `f64`
//!   closed-loop evaluator on ten models per body with *random* masses, mass centres and
//!   inertias (every other body zero), whose efforts give the body's ten standard columns as
//!   `[f(π_1) … f(π_10)] Π⁻¹` (linearity; the generator uses unit parameters instead), plus a
//!   column per spring stiffness and damping, computed by an SVD of the column-normalized
//!   stack; the generated regressor has rank `NBP` and appending it does not raise the rank.

use nalgebra::DMatrix;
use rand::Rng;
use rand::rngs::StdRng;
use runtime::closed::ClosedModel;
use runtime::closed::noc::{self, Plan};
use runtime::model::{Drive, Mat3};
use tests::base_parameters::{stacked_ranks, standard, worst_linear_form_error};

/// `model` with every body, drive and spring zero.
fn bare(m: &ClosedModel) -> ClosedModel {
    let mut z = m.clone();
    for b in &mut z.tree.bodies {
        (b.mass, b.com, b.inertia) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
    }
    for j in &mut z.tree.joints {
        j.drive = Drive::NONE;
    }
    for s in &mut z.springs {
        (s.stiffness, s.damping) = (0.0, 0.0);
    }
    z
}

/// The standard columns' sources: per body ten random-body plans and `Π⁻¹`; per spring
/// parameter a plan with that parameter alone (identity `Π`).
fn sources(m: &ClosedModel, rng: &mut StdRng) -> Vec<(Vec<Plan>, DMatrix<f64>)> {
    let zero = bare(m);
    let mut out: Vec<(Vec<Plan>, DMatrix<f64>)> = (0..m.tree.bodies.len())
        .map(|b| {
            let mut pi = DMatrix::zeros(10, 10);
            let plans = (0..10)
                .map(|k| {
                    let mut s = zero.clone();
                    let body = &mut s.tree.bodies[b];
                    body.mass = rng.random_range(0.5..2.0);
                    body.com = std::array::from_fn(|_| rng.random_range(-0.3..0.3));
                    let a: Mat3 = std::array::from_fn(|_| {
                        std::array::from_fn(|_| rng.random_range(-1.0..1.0))
                    });
                    body.inertia =
                        std::array::from_fn(|r| std::array::from_fn(|c| a[r][c] + a[c][r]));
                    let p = standard(body.mass, &body.com, &body.inertia);
                    for (r, v) in p.iter().enumerate() {
                        pi[(r, k)] = *v;
                    }
                    Plan::new(&s).expect("a plan")
                })
                .collect();
            (plans, pi.try_inverse().expect("generic parameters"))
        })
        .collect();
    for (k, s) in m.springs.iter().enumerate() {
        for stiff in [true, false] {
            if (if stiff { s.stiffness } else { s.damping }) == 0.0 {
                continue;
            }
            let mut z = zero.clone();
            if stiff {
                z.springs[k].stiffness = 1.0;
            } else {
                z.springs[k].damping = 1.0;
            }
            out.push((
                vec![Plan::new(&z).expect("a plan")],
                DMatrix::identity(1, 1),
            ));
        }
    }
    out
}

macro_rules! closed_loops {
    ($($name:ident),* $(,)?) => {
        #[test]
        fn regressor_times_base_parameters_is_inverse_dynamics() {
            let mut failed = Vec::new();
            $({
                use mechanisms::$name as g;
                let m = tests::closed::model(stringify!($name));
                let plan = Plan::new(&m).unwrap();
                let reach = tests::closed::reach(stringify!($name));
                let mut rng = tests::rng(0x7e62 ^ g::NBP as u64);
                let worst = worst_linear_form_error(&g::BASE_PARAMETERS, 500, || {
                    let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, reach);
                    let (x, u, ud) = (x.try_into().unwrap(), u.try_into().unwrap(), ud.try_into().unwrap());
                    let tau = g::inverse_dynamics(&x, &u, &ud).unwrap();
                    (tau.to_vec(), g::regressor(&x, &u, &ud).unwrap().to_vec())
                });
                println!("{}: NBP {}, regressor · BASE_PARAMETERS vs inverse_dynamics {worst:.1e}", stringify!($name), g::NBP);
                if worst.is_nan() || worst > 1e-12 {
                    failed.push((stringify!($name), worst));
                }
            })*
            assert!(failed.is_empty(), "{failed:?}");
        }

        #[test]
        fn nbp_is_the_rank_of_the_standard_regressor() {
            let mut failed = Vec::new();
            $({
                use mechanisms::$name as g;
                let m = tests::closed::model(stringify!($name));
                let plan = Plan::new(&m).unwrap();
                let reach = tests::closed::reach(stringify!($name));
                let mut rng = tests::rng(0x5a4c ^ g::NBP as u64);
                let sources = sources(&m, &mut rng);
                let n = g::DOF;
                let ncols: usize = sources.iter().map(|(p, _)| p.len()).sum();
                let states = 3 * (ncols + g::NBP) / n + 20;
                let (rs, rg, rb) = stacked_ranks(states, (n, ncols, g::NBP), || {
                    let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, reach);
                    let mut col = 0;
                    let mut std_block = DMatrix::zeros(n, ncols);
                    for (plans, pinv) in &sources {
                        let f = DMatrix::from_columns(
                            &plans
                                .iter()
                                .map(|p| {
                                    nalgebra::DVector::from_vec(
                                        noc::generalized_effort(p, &x, &u, &ud, true).unwrap(),
                                    )
                                })
                                .collect::<Vec<_>>(),
                        );
                        let cols = f * pinv;
                        std_block.view_mut((0, col), (n, plans.len())).copy_from(&cols);
                        col += plans.len();
                    }
                    let (xa, ua, uda) = (x.try_into().unwrap(), u.try_into().unwrap(), ud.try_into().unwrap());
                    let y = g::regressor(&xa, &ua, &uda).unwrap();
                    let y = DMatrix::from_fn(n, g::NBP, |i, k| y[i][k]);
                    (std_block, y)
                });
                println!(
                    "{}: {} standard parameters, SVD rank {rs}; NBP {}, generated regressor rank {rg}, both {rb}",
                    stringify!($name), ncols, g::NBP
                );
                if !(rs == g::NBP && rg == g::NBP && rb == g::NBP) {
                    failed.push((stringify!($name), rs, rg, rb, g::NBP));
                }
            })*
            assert!(failed.is_empty(), "(name, SVD rank, generated rank, joint rank, NBP): {failed:?}");
        }
    };
}

closed_loops!(
    four_bar,
    five_bar_joints,
    spherical_five_bar,
    bricard,
    n_four_bar,
    tripod_3prs,
    andrews_squeezer,
);
