//! Many states per call (`codegen::Config::lanes`): on every bundled tree, lane `k` of each
//! `_lanes` function is bit for bit the scalar function at state `k` (the same module, so the
//! same math backend); a failing lane (a NaN input) gets the scalar function's own `Err` and
//! leaves the other lanes as they are.

#![allow(clippy::needless_range_loop)] // lane k of every array, as the lanes are numbered

use rand::Rng;

/// Equal bit for bit: `Debug` writes the shortest round-trip text of every `f64` (and `-0.0`).
fn same<T: std::fmt::Debug>(a: &T, b: &T) -> bool {
    format!("{a:?}") == format!("{b:?}")
}

/// State `k` of a lane-last array.
fn lane<T: Copy, const N: usize, const L: usize>(a: &[[T; L]; N], k: usize) -> [T; N] {
    core::array::from_fn(|i| a[i][k])
}

/// Lane `k` of a lane-last matrix.
fn lane_matrix<const N: usize, const L: usize>(a: &[[[f64; L]; N]; N], k: usize) -> [[f64; N]; N] {
    core::array::from_fn(|i| lane(&a[i], k))
}

macro_rules! check_lanes {
    ($test:ident, $m:ident, $seed:expr) => {
        #[test]
        fn $test() {
            use tests::variants::lanes::$m as g;
            const N: usize = g::DOF;
            const L: usize = g::LANES;
            let name = stringify!($m);
            let mut r = tests::rng($seed);
            let pi = std::f64::consts::PI;
            let mut random = |a: f64| -> [[f64; L]; N] {
                core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-a..a)))
            };
            for round in 0..50 {
                let (q, mut qd, qdd) = (random(pi), random(2.0), random(5.0));
                // Every fifth round, one lane with a NaN rate: its own Err, the others Ok.
                let bad = (round % 5 == 4).then(|| round % L);
                if let Some(k) = bad {
                    qd[0][k] = f64::NAN;
                }
                let tau = g::inverse_dynamics_lanes(&q, &qd, &qdd);
                let m = g::mass_matrix_lanes(&q);
                let c = g::coriolis_lanes(&q, &qd);
                let gr = g::gravity_lanes(&q);
                let (fd, status) = g::forward_dynamics_lanes(&q, &qd, &tau);
                for k in 0..L {
                    let (qk, qdk, qddk, tauk) =
                        (lane(&q, k), lane(&qd, k), lane(&qdd, k), lane(&tau, k));
                    assert!(
                        same(&tauk, &g::inverse_dynamics(&qk, &qdk, &qddk)),
                        "{name} ID lane {k}"
                    );
                    assert!(
                        same(&lane_matrix(&m, k), &g::mass_matrix(&qk)),
                        "{name} M lane {k}"
                    );
                    assert!(
                        same(&lane(&c, k), &g::coriolis(&qk, &qdk)),
                        "{name} C lane {k}"
                    );
                    assert!(same(&lane(&gr, k), &g::gravity(&qk)), "{name} G lane {k}");
                    let scalar = g::forward_dynamics(&qk, &qdk, &tauk);
                    let lanes = status[k].map(|()| lane(&fd, k));
                    assert!(
                        same(&lanes, &scalar),
                        "{name} FD lane {k}: {lanes:?} vs {scalar:?}"
                    );
                    assert_eq!(status[k].is_err(), bad == Some(k), "{name} FD lane {k}");
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
    let mut random = |a: f32| -> [[f32; L]; N] {
        core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-a..a)))
    };
    for _ in 0..50 {
        let (q, qd, qdd) = (random(3.0), random(2.0), random(5.0));
        let tau = g::inverse_dynamics_lanes(&q, &qd, &qdd);
        let (fd, status) = g::forward_dynamics_lanes(&q, &qd, &tau);
        for k in 0..L {
            let (qk, qdk, qddk, tauk) = (lane(&q, k), lane(&qd, k), lane(&qdd, k), lane(&tau, k));
            assert!(same(&tauk, &g::inverse_dynamics(&qk, &qdk, &qddk)));
            let lanes = status[k].map(|()| lane(&fd, k));
            assert!(same(&lanes, &g::forward_dynamics(&qk, &qdk, &tauk)));
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
