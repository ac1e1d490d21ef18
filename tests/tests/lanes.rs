//! Many states per call (`codegen::Config::lanes`): on every bundled tree, lane `k` of each
//! `_lanes` function is bit for bit the scalar function at state `k` (the same module, so the
//! same math backend); a failing lane (a NaN input) gets the scalar function's own `Err` and
//! leaves the other lanes as they are. With `Config::vector_sin_cos` (one polynomial `sin_cos`
//! over all lanes), `sin_cos` is within 2 ulp of correctly rounded values from an independent
//! route (mpmath), and the lanes agree with the scalar functions to rounding.

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
fn lane_matrix<T: Copy, const N: usize, const L: usize>(
    a: &[[[T; L]; N]; N],
    k: usize,
) -> [[T; N]; N] {
    core::array::from_fn(|i| lane(&a[i], k))
}

macro_rules! check_lanes {
    ($test:ident, $m:ident, $seed:expr) => {
        check_lanes!($test, lanes, $m, $seed);
    };
    ($test:ident, $variant:ident, $m:ident, $seed:expr) => {
        #[test]
        fn $test() {
            use tests::variants::$variant::$m as g;
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

/// Lane-last arrays of `L` states, one column each.
fn columns<T: Copy, const N: usize, const L: usize>(states: &[Vec<T>]) -> [[T; L]; N] {
    core::array::from_fn(|i| core::array::from_fn(|k| states[k][i]))
}

/// A platform's or closed loop's `_lanes` functions against its scalar ones, bit for bit, on
/// 25 rounds of `LANES` random regular states; every fifth round one lane has a NaN coordinate
/// (its own `Err(Site::Input)`), and every fifth another lane is `far` (moved off the workspace
/// or off the loops' closure: the scalar functions' `Err`, whatever it is, for that lane
/// alone). Every regular lane answers, in `f32` too (the `f64` states rounded).
macro_rules! check_site_lanes {
    ($test:ident, $variant:ident, $m:ident, $seed:expr, $state:expr, $far:expr) => {
        check_site_lanes!($test, $variant, $m, $seed, $state, $far, f64);
    };
    ($test:ident, $variant:ident, $m:ident, $seed:expr, $state:expr, $far:expr, $float:ty) => {
        #[test]
        fn $test() {
            use tests::variants::$variant::$m as g;
            const N: usize = g::DOF;
            const NX: usize = g::NX;
            const L: usize = g::LANES;
            let name = stringify!($m);
            let mut r = tests::rng($seed);
            let mut state = $state(name);
            let far: fn(&mut [f64]) = $far;
            let mut far_errors = 0;
            let float = |v: Vec<f64>| v.into_iter().map(|x| x as $float).collect::<Vec<$float>>();
            for round in 0..25 {
                let mut xs = Vec::new();
                let (mut us, mut uds) = (Vec::new(), Vec::new());
                let nan = (round % 5 == 4).then(|| round % L);
                let moved = (round % 5 == 2).then(|| (round + 1) % L);
                for _ in 0..L {
                    let (mut x, u, ud) = state(&mut r);
                    if moved == Some(xs.len()) {
                        far(&mut x);
                    }
                    xs.push(float(x));
                    us.push(float(u));
                    uds.push(float(ud));
                }
                if let Some(k) = nan {
                    xs[k][0] = <$float>::NAN;
                }
                let x: [[$float; L]; NX] = columns(&xs);
                let (u, ud): ([[$float; L]; N], [[$float; L]; N]) = (columns(&us), columns(&uds));
                let (tau, id) = g::inverse_dynamics_lanes(&x, &u, &ud);
                let (gr, grs) = g::gravity_lanes(&x);
                let (c, cs) = g::coriolis_lanes(&x, &u);
                let (m, ms) = g::mass_matrix_lanes(&x);
                let (am, ams) = g::actuator_mass_matrix_lanes(&x);
                let (fd, fds) = g::forward_dynamics_lanes(&x, &u, &tau);
                for k in 0..L {
                    let (xk, uk, udk, tauk): ([$float; NX], [$float; N], [$float; N], [$float; N]) =
                        (lane(&x, k), lane(&u, k), lane(&ud, k), lane(&tau, k));
                    let pairs = [
                        (
                            "ID",
                            format!("{:?}", id[k].map(|()| lane(&tau, k))),
                            format!("{:?}", g::inverse_dynamics(&xk, &uk, &udk)),
                        ),
                        (
                            "G",
                            format!("{:?}", grs[k].map(|()| lane(&gr, k))),
                            format!("{:?}", g::gravity(&xk)),
                        ),
                        (
                            "C",
                            format!("{:?}", cs[k].map(|()| lane(&c, k))),
                            format!("{:?}", g::coriolis(&xk, &uk)),
                        ),
                        (
                            "M",
                            format!("{:?}", ms[k].map(|()| lane_matrix(&m, k))),
                            format!("{:?}", g::mass_matrix(&xk)),
                        ),
                        (
                            "actuator M",
                            format!("{:?}", ams[k].map(|()| lane_matrix(&am, k))),
                            format!("{:?}", g::actuator_mass_matrix(&xk)),
                        ),
                        (
                            "FD",
                            format!("{:?}", fds[k].map(|()| lane(&fd, k))),
                            format!("{:?}", g::forward_dynamics(&xk, &uk, &tauk)),
                        ),
                    ];
                    for (what, lanes, scalar) in pairs {
                        assert_eq!(lanes, scalar, "{name} {what}, round {round}, lane {k}");
                    }
                    let scalar = g::inverse_dynamics(&xk, &uk, &udk);
                    if nan == Some(k) {
                        assert!(
                            matches!(
                                scalar,
                                Err(g::Singular {
                                    site: g::Site::Input,
                                    ..
                                })
                            ),
                            "{name}: {scalar:?}"
                        );
                    } else if moved == Some(k) {
                        far_errors += usize::from(scalar.is_err());
                    } else {
                        assert!(
                            scalar.is_ok(),
                            "{name}, round {round}, lane {k}: {scalar:?}"
                        );
                    }
                }
            }
            // The far lanes exercise the guards of one lane among regular ones.
            assert!(far_errors > 0, "{name}: no far lane failed");
        }
    };
}

/// A platform pose a thousand times as far from the base (every coordinate scaled).
fn platform_far(x: &mut [f64]) {
    for v in x.iter_mut() {
        *v *= 1e3;
    }
}

/// A platform pose at the base's origin with a zero quaternion where it has one (for the
/// platforms that reach every pose: prismatic legs, a spherical wrist).
fn platform_zero(x: &mut [f64]) {
    x.iter_mut().for_each(|v| *v = 0.0);
}

/// Joint coordinates that no longer close the loops.
fn closed_open(x: &mut [f64]) {
    for v in x.iter_mut() {
        *v += 0.3;
    }
}

check_site_lanes!(
    gough_stewart,
    lanes_parallel,
    gough_stewart,
    11,
    tests::pkm::near_home,
    platform_zero
);
check_site_lanes!(
    sliding_hexapod,
    lanes_parallel,
    sliding_hexapod,
    12,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    rus_hexapod,
    lanes_parallel,
    rus_hexapod,
    13,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    agile_eye,
    lanes_parallel,
    agile_eye,
    14,
    tests::pkm::near_home,
    platform_zero
);
check_site_lanes!(
    planar_five_bar,
    lanes_parallel,
    planar_five_bar,
    15,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    delta_rl5,
    lanes_parallel,
    delta_rl5,
    16,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    planar_3rrr,
    lanes_parallel,
    planar_3rrr,
    17,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    tsai_3upu,
    lanes_parallel,
    tsai_3upu,
    18,
    tests::pkm::near_home,
    platform_zero
);
check_site_lanes!(
    prs_head,
    lanes_parallel,
    prs_head,
    19,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    delta4_rl5,
    lanes_parallel,
    delta4_rl5,
    20,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    four_bar,
    lanes_closed,
    four_bar,
    21,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    five_bar_joints,
    lanes_closed,
    five_bar_joints,
    22,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    spherical_five_bar,
    lanes_closed,
    spherical_five_bar,
    23,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    bricard,
    lanes_closed,
    bricard,
    24,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    n_four_bar,
    lanes_closed,
    n_four_bar,
    25,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    tripod_3prs,
    lanes_closed,
    tripod_3prs,
    26,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    andrews_squeezer,
    lanes_closed,
    andrews_squeezer,
    27,
    tests::closed::assembled,
    closed_open
);

// The 3-RRR and the four-bar in `f32` with 8 lanes.
check_site_lanes!(
    planar_3rrr_f32,
    lanes_f32_sites,
    planar_3rrr,
    31,
    tests::pkm::near_home,
    platform_far,
    f32
);
check_site_lanes!(
    four_bar_f32,
    lanes_f32_sites,
    four_bar,
    32,
    tests::closed::assembled,
    closed_open,
    f32
);

// The same checks with the lanes' arithmetic through the `wide` crate (`Config::wide`):
// explicit vector operations, still bit for bit the scalar functions.
check_site_lanes!(
    gough_stewart_wide,
    lanes_wide,
    gough_stewart,
    41,
    tests::pkm::near_home,
    platform_zero
);
check_site_lanes!(
    delta_rl5_wide,
    lanes_wide,
    delta_rl5,
    42,
    tests::pkm::near_home,
    platform_far
);
check_site_lanes!(
    agile_eye_wide,
    lanes_wide,
    agile_eye,
    43,
    tests::pkm::near_home,
    platform_zero
);
check_site_lanes!(
    four_bar_wide,
    lanes_wide,
    four_bar,
    44,
    tests::closed::assembled,
    closed_open
);
check_site_lanes!(
    planar_3rrr_wide_f32,
    lanes_wide_f32,
    planar_3rrr,
    45,
    tests::pkm::near_home,
    platform_far,
    f32
);
check_lanes!(puma560_wide, lanes_wide, puma560, 46);

/// A lane at a singularity of the actuation matrix among regular ones: the Gough–Stewart
/// platform at home turned 90° about the vertical (singular, `literal.rs` and
/// `singularities.rs`). Its `A` is factorized over the lanes with the others' (the kernels are
/// regular there); the lane's `Err(Actuation(_))` is the scalar functions', and the other
/// lanes are their scalar results bit for bit.
#[test]
fn gough_stewart_actuation_singular_lane() {
    use tests::variants::lanes_parallel::gough_stewart as g;
    const L: usize = g::LANES;
    let mut state = tests::pkm::near_home("gough_stewart");
    let mut r = tests::rng(21);
    let (mut xs, mut us, mut uds) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..L {
        let (x, u, ud) = state(&mut r);
        xs.push(x);
        us.push(u);
        uds.push(ud);
    }
    let x0 = g::HOME;
    let (c, s) = (
        std::f64::consts::FRAC_PI_4.cos(),
        std::f64::consts::FRAC_PI_4.sin(),
    );
    let q0 = [x0[3], x0[4], x0[5], x0[6]];
    // `R_z(90°) ⊗ q0`, scalar first.
    let q = [
        c * q0[0] - s * q0[3],
        c * q0[1] - s * q0[2],
        c * q0[2] + s * q0[1],
        c * q0[3] + s * q0[0],
    ];
    let singular = 2;
    xs[singular] = vec![x0[0], x0[1], x0[2], q[0], q[1], q[2], q[3]];
    let x: [[f64; L]; g::NX] = columns(&xs);
    let (u, ud): ([[f64; L]; g::DOF], [[f64; L]; g::DOF]) = (columns(&us), columns(&uds));
    let (tau, id) = g::inverse_dynamics_lanes(&x, &u, &ud);
    let (gr, grs) = g::gravity_lanes(&x);
    let (am, ams) = g::actuator_mass_matrix_lanes(&x);
    for k in 0..L {
        let (xk, uk, udk) = (lane(&x, k), lane(&u, k), lane(&ud, k));
        let scalar = g::inverse_dynamics(&xk, &uk, &udk);
        if k == singular {
            assert!(
                matches!(
                    scalar,
                    Err(g::Singular {
                        site: g::Site::Actuation(_),
                        ..
                    })
                ),
                "{scalar:?}"
            );
            assert!(g::actuator_mass_matrix(&xk).is_err());
        } else {
            assert!(scalar.is_ok(), "lane {k}: {scalar:?}");
        }
        let pairs = [
            (
                format!("{:?}", id[k].map(|()| lane(&tau, k))),
                format!("{scalar:?}"),
            ),
            (
                format!("{:?}", grs[k].map(|()| lane(&gr, k))),
                format!("{:?}", g::gravity(&xk)),
            ),
            (
                format!("{:?}", ams[k].map(|()| lane_matrix(&am, k))),
                format!("{:?}", g::actuator_mass_matrix(&xk)),
            ),
        ];
        for (lanes, scalar) in pairs {
            assert_eq!(lanes, scalar, "lane {k}");
        }
    }
}

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

/// The options are checked: lanes are refused outside 2..=16; a platform has them too.
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
    let code = compile("gough_stewart.toml", 4).unwrap();
    assert!(code.contains("pub fn actuator_mass_matrix_lanes"));
    let code = compile("planar_2r.toml", 4).unwrap();
    assert!(code.contains("pub fn forward_dynamics_lanes"));
    assert!(code.contains("// Lanes: 4 states per call"));
}

/// ulp of `y` (of the smallest normal for 0 and subnormals).
fn ulp(y: f64) -> f64 {
    let e = y.abs().max(f64::MIN_POSITIVE).log2().floor();
    2f64.powf(e - 52.0)
}

/// The vector `sin_cos` against `sin` and `cos` correctly rounded to `f64` by mpmath at 80
/// digits (`tests/data/sin_cos_reference.csv`, written by `sin_cos_reference.py` beside it):
/// 6,415 arguments up to the polynomial's range `|x| ≤ 823,549` (random in ±1 … ±8.2e5 rad,
/// and the doubles next to multiples of π/2, where the reduction is at its worst). Within
/// 2 ulp where `|y| ≥ 2⁻²⁰`; near a zero of `sin` or `cos` the absolute error stays within
/// 2⁻⁵³ (the reduction's, not relative). Beyond the range and for non-finite lanes the call
/// is the backend's, bit for bit.
#[test]
fn vector_sin_cos_against_correctly_rounded_values() {
    use tests::variants::lanes_vector::puma560::Lanes;
    let text = std::fs::read_to_string("data/sin_cos_reference.csv").expect("the reference");
    let (mut worst_ulp, mut worst_abs, mut count) = (0.0f64, 0.0f64, 0);
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let v: Vec<f64> = line
            .split(',')
            .map(|t| t.parse().expect("a number"))
            .collect();
        let (x, sin, cos) = (v[0], v[1], v[2]);
        // Lane 2 carries x; the others ordinary angles, which must not disturb it.
        let (s, c) = Lanes([0.3, -2.0, x, 7.5]).sin_cos();
        for (got, want) in [(s.0[2], sin), (c.0[2], cos)] {
            let err = (got - want).abs();
            worst_abs = worst_abs.max(err);
            if want.abs() >= 2f64.powi(-20) {
                worst_ulp = worst_ulp.max(err / ulp(want));
            }
        }
        let (s0, c0) = Lanes([0.3; 4]).sin_cos();
        assert!(
            same(&(s.0[0], c.0[0]), &(s0.0[0], c0.0[0])),
            "lanes are independent"
        );
        count += 1;
    }
    println!(
        "vector sin_cos: {count} arguments, worst {worst_ulp} ulp, worst absolute {worst_abs:e}"
    );
    assert!(count > 6000, "{count}");
    assert!(worst_ulp <= 2.0, "{worst_ulp} ulp");
    assert!(worst_abs <= f64::EPSILON / 2.0, "{worst_abs:e}");
    // Beyond the range, or a lane not finite: every lane is the backend's.
    for odd in [1e6, -3e7, 1e300, f64::INFINITY, f64::NAN] {
        let x = [0.5, odd, -1.25, 3.0];
        let (s, c) = Lanes(x).sin_cos();
        for k in 0..4 {
            let (bs, bc) = runtime::math::sin_cos(x[k]);
            assert!(same(&(s.0[k], c.0[k]), &(bs, bc)), "{odd}: lane {k}");
        }
    }
}

macro_rules! check_vector_lanes {
    ($test:ident, $m:ident, $seed:expr) => {
        /// The `_lanes` functions with the vector `sin_cos` against the scalar functions of the
        /// same module: relative ∞-norm ≤ 1e-13 (the values agree to rounding; bit for bit is
        /// not promised), the same `Err` for a NaN lane.
        #[test]
        fn $test() {
            use tests::variants::lanes_vector::$m as g;
            const N: usize = g::DOF;
            const L: usize = g::LANES;
            let name = stringify!($m);
            let mut r = tests::rng($seed);
            let mut random = |a: f64| -> [[f64; L]; N] {
                core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-a..a)))
            };
            let close = |a: &[f64], b: &[f64], what: &str| {
                let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                let d = a
                    .iter()
                    .zip(b)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                assert!(d <= 1e-13 * scale, "{name} {what}: {d:e} of {scale:e}");
                d / scale
            };
            let mut worst = 0.0f64;
            for round in 0..50 {
                // Angles up to ±40 rad: several turns, every quadrant.
                let (q, mut qd, qdd) = (random(40.0), random(2.0), random(5.0));
                let bad = (round % 5 == 4).then(|| round % L);
                if let Some(k) = bad {
                    qd[0][k] = f64::NAN;
                }
                let tau = g::inverse_dynamics_lanes(&q, &qd, &qdd);
                let m = g::mass_matrix_lanes(&q);
                let gr = g::gravity_lanes(&q);
                let (fd, status) = g::forward_dynamics_lanes(&q, &qd, &tau);
                for k in 0..L {
                    let (qk, qdk, qddk, tauk) =
                        (lane(&q, k), lane(&qd, k), lane(&qdd, k), lane(&tau, k));
                    let m_k = lane_matrix(&m, k);
                    worst = worst.max(close(
                        m_k.as_flattened(),
                        g::mass_matrix(&qk).as_flattened(),
                        "M",
                    ));
                    worst = worst.max(close(&lane(&gr, k), &g::gravity(&qk), "G"));
                    let scalar = g::forward_dynamics(&qk, &qdk, &tauk);
                    assert_eq!(status[k].is_err(), bad == Some(k), "{name} FD lane {k}");
                    match (status[k], scalar) {
                        (Ok(()), Ok(a)) => {
                            worst = worst.max(close(&lane(&fd, k), &a, "FD"));
                            let id = g::inverse_dynamics(&qk, &qdk, &qddk);
                            worst = worst.max(close(&tauk, &id, "ID"));
                        }
                        (Err(a), Err(b)) => assert_eq!(a.pivot, b.pivot, "{name} FD lane {k}"),
                        (a, b) => panic!("{name} FD lane {k}: {a:?} vs {b:?}"),
                    }
                }
            }
            println!("{name}: vector sin_cos lanes within {worst:e} of the scalar functions");
        }
    };
}

check_vector_lanes!(puma560_vector_sin_cos, puma560, 11);
check_vector_lanes!(chain7_vector_sin_cos, chain7, 12);
check_vector_lanes!(iiwa14_vector_sin_cos, iiwa14, 13);

/// The `f32` vector `sin_cos` (widened to `f64` and rounded back): the lanes' inverse dynamics
/// within 2e-5 (relative ∞-norm) of the scalar `f32` function.
#[test]
fn puma560_f32_vector_sin_cos() {
    use tests::variants::lanes_vector_f32_puma560 as g;
    const N: usize = g::DOF;
    const L: usize = g::LANES;
    let mut r = tests::rng(14);
    let mut random = |a: f32| -> [[f32; L]; N] {
        core::array::from_fn(|_| core::array::from_fn(|_| r.random_range(-a..a)))
    };
    for _ in 0..50 {
        let (q, qd, qdd) = (random(20.0), random(2.0), random(5.0));
        let tau = g::inverse_dynamics_lanes(&q, &qd, &qdd);
        for k in 0..L {
            let want = g::inverse_dynamics(&lane(&q, k), &lane(&qd, k), &lane(&qdd, k));
            let got = lane(&tau, k);
            let scale = want.iter().fold(1.0f32, |m, v| m.max(v.abs()));
            let d = got
                .iter()
                .zip(&want)
                .fold(0.0f32, |m, (x, y)| m.max((x - y).abs()));
            assert!(d <= 2e-5 * scale, "lane {k}: {d:e} of {scale:e}");
        }
    }
}

/// `vector_sin_cos` without `lanes` is refused.
#[test]
fn vector_sin_cos_needs_lanes() {
    let src = std::fs::read_to_string("../mechanisms/specs/planar_2r.toml").unwrap();
    let cfg = codegen::Config {
        vector_sin_cos: true,
        ..Default::default()
    };
    let e = codegen::compile("planar_2r.toml", &src, &cfg)
        .unwrap_err()
        .to_string();
    assert!(e.contains("set `lanes` too"), "{e}");
}

/// `wide` without `lanes`, or with a lane count `wide` has no vector type for, is refused.
#[test]
fn wide_needs_lanes_of_its_widths() {
    let src = std::fs::read_to_string("../mechanisms/specs/planar_2r.toml").unwrap();
    let refused = |lanes: Option<usize>, float: codegen::Float| {
        let cfg = codegen::Config {
            lanes,
            float,
            wide: Some("wide".into()),
            ..Default::default()
        };
        codegen::compile("planar_2r.toml", &src, &cfg)
            .err()
            .map(|e| e.to_string())
    };
    let e = refused(None, codegen::Float::F64).unwrap();
    assert!(e.contains("set `lanes` too"), "{e}");
    for (l, float) in [
        (3, codegen::Float::F64),
        (16, codegen::Float::F64),
        (2, codegen::Float::F32),
    ] {
        let e = refused(Some(l), float).unwrap_or_else(|| panic!("{l} lanes accepted"));
        assert!(e.contains("`wide` has vector types for"), "{e}");
    }
    for (l, float) in [
        (2, codegen::Float::F64),
        (8, codegen::Float::F64),
        (16, codegen::Float::F32),
    ] {
        assert_eq!(refused(Some(l), float), None, "{l} lanes");
    }
}
