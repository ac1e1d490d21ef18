//! Many states per call (`codegen::Config::lanes`): on every bundled tree, lane `k` of each
//! `_lanes` function is bit for bit the scalar function at state `k` (the same module, so the
//! same math backend), a failing lane (a NaN input) gets the scalar function's own `Err` and
//! leaves the other lanes as they are.

use rand::Rng;

/// Equal bit for bit: `Debug` writes the shortest round-trip text of every `f64` (and `-0.0`).
fn same<T: std::fmt::Debug>(a: &T, b: &T) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

macro_rules! check_lanes {
    ($test:ident, $m:ident, $seed:expr) => {
        #[test]
        fn $test() {
            use tests::variants::lanes::$m as g;
            const N: usize = g::DOF;
            const L: usize = g::LANES;
            let mut r = tests::rng($seed);
            let pi = std::f64::consts::PI;
            for round in 0..50 {
                let q: [[f64; N]; L] =
                    core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-pi..pi)));
                let mut qd: [[f64; N]; L] =
                    core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-2.0..2.0)));
                let qdd: [[f64; N]; L] =
                    core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-5.0..5.0)));
                // Every fifth round, one lane with a NaN rate: its own Err, the others Ok.
                let bad = (round % 5 == 4).then(|| round % L);
                if let Some(k) = bad {
                    qd[k][0] = f64::NAN;
                }
                let tau = g::inverse_dynamics_lanes(&q, &qd, &qdd);
                let m = g::mass_matrix_lanes(&q);
                let c = g::coriolis_lanes(&q, &qd);
                let gr = g::gravity_lanes(&q);
                let fd = g::forward_dynamics_lanes(&q, &qd, &tau);
                for k in 0..L {
                    let name = stringify!($m);
                    assert!(
                        same(&tau[k], &g::inverse_dynamics(&q[k], &qd[k], &qdd[k])),
                        "{name} ID lane {k}"
                    );
                    assert!(same(&m[k], &g::mass_matrix(&q[k])), "{name} M lane {k}");
                    assert!(
                        same(&c[k], &g::coriolis(&q[k], &qd[k])),
                        "{name} C lane {k}"
                    );
                    assert!(same(&gr[k], &g::gravity(&q[k])), "{name} G lane {k}");
                    let scalar = g::forward_dynamics(&q[k], &qd[k], &tau[k]);
                    assert!(
                        same(&fd[k], &scalar),
                        "{name} FD lane {k}: {:?} vs {scalar:?}",
                        fd[k]
                    );
                    assert_eq!(fd[k].is_err(), bad == Some(k), "{name} FD lane {k}");
                }
            }
        }
    };
}

check_lanes!(puma560, puma560, 1);
check_lanes!(puma560_urdf, puma560_urdf, 2);
check_lanes!(chain7, chain7, 3);
check_lanes!(gripper_tree, gripper_tree, 4);
check_lanes!(iiwa14, iiwa14, 5);
check_lanes!(planar_2r, planar_2r, 6);
check_lanes!(stanford_arm, stanford_arm, 7);

/// The same in `f32` with 8 lanes.
#[test]
fn puma560_f32_eight_lanes() {
    use tests::variants::lanes_f32_puma560 as g;
    const N: usize = g::DOF;
    const L: usize = g::LANES;
    assert_eq!(L, 8);
    let mut r = tests::rng(8);
    for _ in 0..50 {
        let q: [[f32; N]; L] =
            core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-3.0..3.0)));
        let qd: [[f32; N]; L] =
            core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-2.0..2.0)));
        let qdd: [[f32; N]; L] =
            core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-5.0..5.0)));
        let tau = g::inverse_dynamics_lanes(&q, &qd, &qdd);
        let fd = g::forward_dynamics_lanes(&q, &qd, &tau);
        for k in 0..L {
            assert!(same(&tau[k], &g::inverse_dynamics(&q[k], &qd[k], &qdd[k])));
            assert!(same(&fd[k], &g::forward_dynamics(&q[k], &qd[k], &tau[k])));
        }
    }
}

/// The options are checked: lanes are refused outside 2..=16 and for a platform.
#[test]
fn lanes_options_are_checked() {
    let compile = |spec: &str, lanes| {
        let src = std::fs::read_to_string(format!("../mechanisms/specs/{spec}")).unwrap();
        codegen::compile(
            spec,
            &src,
            &codegen::Config {
                lanes: Some(lanes),
                ..Default::default()
            },
        )
        .map(|g| g.code)
        .map_err(|d| d.to_string())
    };
    assert!(
        compile("planar_2r.toml", 1)
            .unwrap_err()
            .contains("2 to 16")
    );
    assert!(
        compile("planar_2r.toml", 17)
            .unwrap_err()
            .contains("2 to 16")
    );
    assert!(
        compile("gough_stewart.toml", 4)
            .unwrap_err()
            .contains("trees only")
    );
    let code = compile("planar_2r.toml", 4).unwrap();
    assert!(code.contains("pub fn forward_dynamics_lanes"));
    assert!(code.contains("// Lanes: 4 states per call"));
}
