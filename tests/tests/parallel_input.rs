//! Bad and extreme input to the bundled parallel mechanisms' generated modules and the
//! runtime (each case a defect that was once there):
//! - `forward_kinematics` with a non-finite or huge revolute target returns at once (it hung:
//!   the residual was wrapped by a loop of `2π` steps), and its tolerance does not grow with
//!   the target (in `f32`, targets of 1e7 … 1.2e8 rad returned `Ok(HOME)`);
//! - a quaternion scaled by 1e-160 or 1e160 is the same rotation (it gave
//!   `Err(Reach(0), NaN)`), a zero one is `Err(Platform)`;
//! - every function that inverts the actuation matrix gives the same verdict at the same `x`
//!   (the Gough–Stewart's `actuator_mass_matrix` answered `Ok` with an entry of 7.2e19 where
//!   `inverse_dynamics` reported `Err(Actuation(4))`).

use runtime::parallel::noc::{self, Plan};
use runtime::scalar::Site;
use tests::pkm::{home_x, model};

/// `a − b` wrapped to `(−π, π]`, for any `a` and `b` (exact `f64` values, each reduced by
/// `sin` and `cos` on its own, so that no rounding of `a − b` enters).
fn angle_diff(a: f64, b: f64) -> f64 {
    let ((sa, ca), (sb, cb)) = (a.sin_cos(), b.sin_cos());
    (sa * cb - ca * sb).atan2(ca * cb + sa * sb)
}

#[test]
fn forward_kinematics_returns_at_once_for_bad_or_huge_targets() {
    use mechanisms::agile_eye as g;
    let plan = Plan::new(&model("agile_eye")).unwrap();
    for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
        let q = [bad, 0.0, 0.0];
        let e = g::forward_kinematics(&q, &g::HOME).unwrap_err();
        assert_eq!(e.iterations, 0, "{bad}: {e:?}");
        assert!(noc::forward_kinematics(&plan, &q, &g::HOME).is_err());
        let mut guess = g::HOME;
        guess[1] = bad;
        assert!(g::forward_kinematics(&[0.0; 3], &guess).is_err());
    }
    // Huge finite targets: the pose whose actuated angles are the targets modulo 2π (they are
    // exact doubles, so that pose is well defined), or `Err`; never a wrong `Ok`. Targets near
    // home modulo 2π must be met.
    let near = |big: f64, want: f64| {
        let tau = std::f64::consts::TAU;
        // Close in f64 arithmetic, then exactly by stepping.
        let mut v = (big / tau).round() * tau + want;
        while (angle_diff(v, want)).abs() > 0.2 {
            v = f64::from_bits(v.to_bits() + 1);
        }
        v
    };
    let mut met = 0;
    for big in [1e8, 1e12, 1e17, 1e300, f64::MAX] {
        let reachable = big < f64::MAX;
        let q = if reachable {
            [near(big, 0.3), near(big * 1.5, 0.1), -near(big * 2.5, 0.2)]
        } else {
            [big, 0.0, -big]
        };
        for (name, r) in [
            (
                "generated",
                g::forward_kinematics(&q, &g::HOME).map(|x| x.to_vec()),
            ),
            (
                "runtime",
                noc::forward_kinematics(&plan, &q, &g::HOME).map_err(|e| g::NoConvergence {
                    iterations: e.iterations,
                    residual: e.residual,
                    stop: match e.stop {
                        runtime::solve::Stop::Input => g::Stop::Input,
                        runtime::solve::Stop::Guess => g::Stop::Guess,
                        runtime::solve::Stop::Singular => g::Stop::Singular,
                        runtime::solve::Stop::Stalled => g::Stop::Stalled,
                        runtime::solve::Stop::Iterations => g::Stop::Iterations,
                        runtime::solve::Stop::Branch => g::Stop::Branch,
                    },
                }),
            ),
        ] {
            match r {
                Ok(x) => {
                    let qx = noc::inverse_kinematics(&plan, &x).unwrap();
                    for i in 0..3 {
                        let d = angle_diff(qx[i], q[i]);
                        assert!(d.abs() < 1e-11, "{name} at {big:e}: joint {i} off by {d:e}");
                    }
                    met += 1;
                }
                Err(e) => assert!(!reachable, "{name} at {big:e}: {e:?}"),
            }
        }
    }
    assert!(met >= 8, "{met} huge targets met");
}

/// In `f32` the tolerance was `4.9e-6 · (1 + |q|)`, over 49 rad from q = 1e7: `Ok(HOME)` for
/// any target. Targets exactly representable in `f32` must now be met modulo 2π.
#[test]
fn f32_forward_kinematics_meets_huge_targets_modulo_two_pi() {
    use mechanisms::agile_eye as g64;
    use mechanisms::f32::agile_eye as g;
    let plan = Plan::new(&model("agile_eye")).unwrap();
    for big in [1e7f32, 3.3e7, 1.2e8] {
        // The first f32 at or above `big` that is within 0.2 rad of 0.3 modulo 2π (its f64
        // value is exact, and its residue is computed by f64 sin and cos).
        let mut q0 = big;
        while (angle_diff(q0 as f64, 0.0) - 0.3).abs() > 0.2 {
            q0 = f32::from_bits(q0.to_bits() + 1);
        }
        let q = [q0, 0.1, -0.2];
        let home: [f32; 4] = g64::HOME.map(|v| v as f32);
        match g::forward_kinematics(&q, &home) {
            Ok(x) => {
                let x64: Vec<f64> = x.iter().map(|&v| v as f64).collect();
                let qx = noc::inverse_kinematics(&plan, &x64).unwrap();
                for i in 0..3 {
                    let d = angle_diff(qx[i], q[i] as f64);
                    assert!(
                        d.abs() < 1e-4,
                        "f32 at {big:e}: joint {i} off by {d:e} ({x:?})"
                    );
                }
            }
            Err(e) => panic!("f32 at {big:e}: {e:?}"),
        }
    }
}

#[test]
fn scaled_quaternions_are_the_same_rotation() {
    macro_rules! check {
        ($m:ident, $q0:expr) => {{
            use mechanisms::$m as g;
            let plan = Plan::new(&model(stringify!($m))).unwrap();
            let x = g::HOME;
            let want = g::inverse_kinematics(&x).unwrap();
            for s in [1e-160, 1e-200, 1e-300, 5e-324, 1e160, 1e300, -1.0, -1e-250] {
                let mut xs = x;
                for i in $q0..$q0 + 4 {
                    xs[i] *= s;
                }
                let got = g::inverse_kinematics(&xs)
                    .unwrap_or_else(|e| panic!("{} × {s:e}: {e:?}", stringify!($m)));
                assert!(
                    tests::pkm::rel(&got, &want) < 1e-14,
                    "{} × {s:e}",
                    stringify!($m)
                );
                let rt = noc::inverse_kinematics(&plan, &xs).unwrap();
                assert!(
                    tests::pkm::rel(&rt, &want) < 1e-14,
                    "runtime {} × {s:e}",
                    stringify!($m)
                );
                let u = [0.1; g::DOF];
                assert!(g::inverse_dynamics(&xs, &u, &u).is_ok());
            }
            let mut z = x;
            for i in $q0..$q0 + 4 {
                z[i] = 0.0;
            }
            let e = g::inverse_kinematics(&z).unwrap_err();
            assert_eq!(e.site, g::Site::Platform, "{}", stringify!($m));
            let e = noc::inverse_kinematics(&plan, &z).unwrap_err();
            assert_eq!(e.site, Site::Platform);
        }};
    }
    check!(gough_stewart, 3);
    check!(sliding_hexapod, 3);
    check!(rus_hexapod, 3);
    check!(agile_eye, 0);
}

/// The Gough–Stewart far away and on a descent to the base plane: `inverse_dynamics` and
/// `actuator_mass_matrix` (both invert `A`) agree on `Ok` versus `Err`, and on the site, in the
/// generated code and the runtime.
#[test]
fn functions_that_invert_a_agree_on_the_verdict() {
    use mechanisms::gough_stewart as g;
    let m = model("gough_stewart");
    let plan = Plan::new(&m).unwrap();
    let home = home_x(&m);
    let u = [0.2, -0.1, 0.3, 0.0, 0.1, -0.2];
    let mut xs: Vec<Vec<f64>> = vec![vec![1e5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0]];
    for s in 0..=2000 {
        let mut x = home.clone();
        x[2] -= home[2] * s as f64 / 2000.0;
        xs.push(x);
    }
    let (mut errs, mut n) = (0, 0);
    for x in &xs {
        let xa: [f64; 7] = x.as_slice().try_into().unwrap();
        let id = g::inverse_dynamics(&xa, &u, &u)
            .map(|_| ())
            .map_err(|e| e.site);
        let amm = g::actuator_mass_matrix(&xa).map(|_| ()).map_err(|e| e.site);
        assert_eq!(id, amm, "generated at {x:?}");
        let rid = noc::inverse_dynamics(&plan, x, &u, &u)
            .map(|_| ())
            .map_err(|e| e.site);
        let ramm = noc::actuator_mass_matrix(&plan, x)
            .map(|_| ())
            .map_err(|e| e.site);
        assert_eq!(rid, ramm, "runtime at {x:?}");
        n += 1;
        errs += usize::from(id.is_err());
    }
    assert!(errs > 0, "the walk met no singularity in {n} states");
}

/// `forward_kinematics` says why it stopped: a non-finite target is `Input`; a Gough–Stewart
/// target with every leg 6 cm long (its base and platform joints lie on circles 0.9 m apart in
/// radius: outside the workspace) ends without a step that helps (`Stalled`) or at a singular
/// Jacobian (`Singular`), never `Iterations`;
/// the five-bar in joint coordinates with its cranks opened beyond reach likewise; the same
/// verdict from the runtime and the generated code.
#[test]
fn forward_kinematics_says_why_it_stopped() {
    use mechanisms::gough_stewart as g;
    use runtime::solve::Stop;
    let plan = Plan::new(&model("gough_stewart")).unwrap();
    let q0 = g::inverse_kinematics(&g::HOME).unwrap();
    let e = g::forward_kinematics(&[f64::NAN; 6], &g::HOME).unwrap_err();
    assert_eq!(e.stop, g::Stop::Input);
    // The actuated coordinates are the legs' lengths less their home lengths (about 1.26 m).
    let far = q0.map(|v| v - 1.2);
    let generated = g::forward_kinematics(&far, &g::HOME).unwrap_err();
    let run = noc::forward_kinematics(&plan, &far, &g::HOME).unwrap_err();
    println!("Gough–Stewart, legs 6 cm long: generated {generated:?}, runtime {run:?}");
    assert!(
        matches!(generated.stop, g::Stop::Stalled | g::Stop::Singular),
        "{generated:?}"
    );
    assert!(
        matches!(run.stop, Stop::Stalled | Stop::Singular),
        "{run:?}"
    );
    assert_eq!(format!("{:?}", generated.stop), format!("{:?}", run.stop));
    // Closed loops: the five-bar's two cranks turned apart until its distal links cannot meet.
    use mechanisms::five_bar_joints as f;
    let cplan = runtime::closed::noc::Plan::new(&tests::closed::model("five_bar_joints")).unwrap();
    let out = [2.5, -2.5];
    let generated = f::forward_kinematics(&out, &f::HOME).unwrap_err();
    let run = runtime::closed::noc::forward_kinematics(&cplan, &out, &f::HOME).unwrap_err();
    println!("five-bar out of reach: generated {generated:?}, runtime {run:?}");
    assert!(
        matches!(generated.stop, f::Stop::Stalled | f::Stop::Guess),
        "{generated:?}"
    );
    assert_eq!(format!("{:?}", generated.stop), format!("{:?}", run.stop));
    let e = f::forward_kinematics(&[f64::INFINITY, 0.0], &f::HOME).unwrap_err();
    assert_eq!(e.stop, f::Stop::Input);
}
