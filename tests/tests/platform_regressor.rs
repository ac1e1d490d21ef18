//! The generated `regressor` and base parameters of the bundled platform modules (issue 23's
//! checks, in actuator space):
//! * `regressor · BASE_PARAMETERS` equals the module's `inverse_dynamics` on 500 random regular
//!   states each (‖a − b‖∞ / ‖b‖∞ ≤ 1e-12);
//! * `NBP` is the rank of the standard regressor built by another route: the runtime's `f64`
//!   evaluator on ten models per body with *random* masses, mass centres and inertias (every
//!   other body zero), whose generalized forces `f(π_1 … π_10)` give the body's ten standard
//!   columns as `[f(π_1) … f(π_10)] Π⁻¹` (linearity; the generator uses unit parameters
//!   instead), computed by an SVD of the column-normalized stack over many states; the
//!   generated regressor, mapped back by `Aᵀ` (runtime), has full column rank `NBP`, and
//!   appending it to the standard stack does not raise the rank (each spans the other).

use nalgebra::DMatrix;
use rand::Rng;
use rand::rngs::StdRng;
use runtime::model::{Body, Drive, Mat3};
use runtime::parallel::ParallelModel;
use runtime::parallel::noc::{self, Plan};
use tests::base_parameters::{stacked_ranks, standard, worst_linear_form_error};

/// The model's bodies: the platform, then each leg's in order.
fn bodies(m: &mut ParallelModel) -> Vec<&mut Body> {
    std::iter::once(&mut m.platform)
        .chain(m.legs.iter_mut().flat_map(|l| l.bodies.iter_mut()))
        .collect()
}

/// Per body, ten models with random parameters on that body alone, and the matrix `Π⁻¹` of
/// their standard parameters (columns) inverted.
fn random_models(m: &ParallelModel, rng: &mut StdRng) -> Vec<(Vec<Plan>, DMatrix<f64>)> {
    let mut bare = m.clone();
    for b in bodies(&mut bare) {
        b.mass = 0.0;
        b.com = [0.0; 3];
        b.inertia = [[0.0; 3]; 3];
    }
    for l in &mut bare.legs {
        for j in &mut l.joints {
            j.drive = Drive::NONE;
        }
    }
    let count = bodies(&mut bare.clone()).len();
    (0..count)
        .map(|b| {
            let mut pi = DMatrix::zeros(10, 10);
            let plans = (0..10)
                .map(|k| {
                    let mut s = bare.clone();
                    let body = bodies(&mut s).swap_remove(b);
                    body.mass = rng.random_range(0.5..2.0);
                    body.com = std::array::from_fn(|_| rng.random_range(-0.3..0.3));
                    let a: Mat3 = std::array::from_fn(|_| {
                        std::array::from_fn(|_| rng.random_range(-1.0..1.0))
                    });
                    // A symmetric tensor (any: the dynamics is linear in it).
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
        .collect()
}

macro_rules! platforms {
    ($($name:ident),* $(,)?) => {
        #[test]
        fn regressor_times_base_parameters_is_inverse_dynamics() {
            let mut failed = Vec::new();
            $({
                use mechanisms::$name as g;
                let m = tests::pkm::model(stringify!($name));
                let plan = Plan::new(&m).unwrap();
                let home = tests::pkm::home_x(&m);
                let r = reach(stringify!($name));
                let mut rng = tests::rng(0x7e61 ^ g::NBP as u64);
                let worst = worst_linear_form_error(&g::BASE_PARAMETERS, 500, || {
                    let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, 4.0 * r, r);
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
                let m = tests::pkm::model(stringify!($name));
                let plan = Plan::new(&m).unwrap();
                let home = tests::pkm::home_x(&m);
                let r = reach(stringify!($name));
                let mut rng = tests::rng(0x5a4b ^ g::NBP as u64);
                let models = random_models(&m, &mut rng);
                let n = g::DOF;
                let ncols = 10 * models.len();
                let states = 3 * (ncols + g::NBP) / n + 20;
                let (rs, rg, rb) = stacked_ranks(states, (n, ncols, g::NBP), || {
                    let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, 4.0 * r, r);
                    let mut std_block = DMatrix::zeros(n, ncols);
                    for (b, (plans, pinv)) in models.iter().enumerate() {
                        let f = DMatrix::from_columns(
                            &plans
                                .iter()
                                .map(|p| {
                                    nalgebra::DVector::from_vec(
                                        noc::generalized_effort(p, &x, &u, &ud).unwrap(),
                                    )
                                })
                                .collect::<Vec<_>>(),
                        );
                        let cols = f * pinv;
                        std_block.view_mut((0, 10 * b), (n, 10)).copy_from(&cols);
                    }
                    // The generated regressor mapped back to generalized forces: Aᵀ Y.
                    let a = noc::actuation(&plan, &x).unwrap();
                    let a = DMatrix::from_fn(n, n, |i, j| a[i][j]);
                    let (xa, ua, uda) = (x.try_into().unwrap(), u.try_into().unwrap(), ud.try_into().unwrap());
                    let y = g::regressor(&xa, &ua, &uda).unwrap();
                    let y = DMatrix::from_fn(n, g::NBP, |i, k| y[i][k]);
                    (std_block, a.transpose() * y)
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

/// How far the random states move from home (m; turns 4× that in rad), as the derivative
/// tests do.
fn reach(name: &str) -> f64 {
    match name {
        "planar_five_bar" | "delta_rl5" | "delta4_rl5" | "planar_3rrr" => 0.1,
        "gough_stewart" | "tsai_3upu" | "prs_head" | "rus_hexapod" | "sliding_hexapod" => 0.02,
        _ => 0.5,
    }
}

platforms!(
    gough_stewart,
    agile_eye,
    planar_five_bar,
    delta_rl5,
    planar_3rrr,
    tsai_3upu,
    prs_head,
    delta4_rl5,
    rus_hexapod,
    sliding_hexapod,
);

/// The Delta's platform only translates, so its inertia tensor moves nothing: two models that
/// differ in it (standard parameters `XX … ZZ` of the platform) give the same efforts (the
/// runtime's `f64` evaluator, 200 states) and the same base parameters (the generator's).
#[test]
fn models_with_the_same_base_parameters_have_the_same_efforts() {
    let m = tests::pkm::model("delta_rl5");
    let mut turned = m.clone();
    for (i, v) in [0.1, 0.2, 0.3].into_iter().enumerate() {
        turned.platform.inertia[i][i] += v;
    }
    let base = |m: &ParallelModel| {
        let plan = Plan::new(m).unwrap();
        let k = codegen::parallel::kernels_for(m, &plan, &Default::default(), &[], true).unwrap();
        let r = k.regressor.expect("a regressor");
        (r.base.values, r.standard_values)
    };
    let ((b0, s0), (b1, s1)) = (base(&m), base(&turned));
    assert_ne!(s0, s1, "the standard parameters differ");
    assert_eq!(b0.len(), b1.len());
    let scale = b0.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for (a, b) in b0.iter().zip(&b1) {
        assert!((a - b).abs() <= 1e-12 * scale, "base parameters {a} vs {b}");
    }
    let (p0, p1) = (Plan::new(&m).unwrap(), Plan::new(&turned).unwrap());
    let home = tests::pkm::home_x(&m);
    let mut rng = tests::rng(0xde17a);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let (x, u, ud) = tests::pkm::random_state(&p0, &home, &mut rng, 0.4, 0.1);
        let t0 = noc::inverse_dynamics(&p0, &x, &u, &ud).unwrap();
        let t1 = noc::inverse_dynamics(&p1, &x, &u, &ud).unwrap();
        worst = worst.max(tests::pkm::rel(&t1, &t0));
    }
    println!("delta_rl5: platform inertia changed, efforts differ by {worst:.1e}");
    assert!(worst <= 1e-13, "{worst:e}");
}
