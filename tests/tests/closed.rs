//! Closed loops in joint coordinates: the runtime (NOC, `S = [1; −Φ_d⁻¹Φ_i]`) against the
//! independent Cartesian Newton–Euler + Lagrange-multiplier route, the generated code against
//! the runtime, power balance, assembly round trips and the failure behaviour.

use rand::Rng;
use references::lagrange::{self, Prescribed};
use runtime::closed::noc::{self, Plan};
use tests::closed::{CLOSED, model, random_state, reach};
use tests::pkm::rel;

/// Efforts of the independent joints by the Lagrange route, in `independent` order.
fn lagrange_efforts(
    m: &runtime::closed::ClosedModel,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Vec<f64> {
    // The route takes the actuated joints in increasing joint order.
    let mut order: Vec<usize> = (0..m.independent.len()).collect();
    order.sort_by_key(|&k| m.independent[k]);
    let us: Vec<f64> = order.iter().map(|&k| u[k]).collect();
    let uds: Vec<f64> = order.iter().map(|&k| ud[k]).collect();
    let sys = lagrange::from_closed(m, x);
    assert!(
        lagrange::closure_residual(&sys) < 1e-9,
        "the state does not close the loops"
    );
    let sol = lagrange::inverse_dynamics(&sys, &Prescribed::ActuatedJoints, &us, &uds)
        .unwrap_or_else(|e| panic!("Lagrange route failed: {e}"));
    let mut out = vec![0.0; u.len()];
    for (i, &k) in order.iter().enumerate() {
        out[k] = sol.efforts[i];
    }
    out
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, v| m.max(v.abs()))
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// Error of accelerations recovered by forward dynamics from the efforts `tau`, relative to
/// the accelerations those efforts can produce (`max |τ| / max |I|`) or to `ud`, whichever is
/// larger: a small `ud` under large gravity efforts is recovered only to the efforts' precision.
fn fd_error(back: &[f64], ud: &[f64], tau: &[f64], mm: &[Vec<f64>]) -> f64 {
    let imax = mm.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    max_abs_diff(back, ud) / max_abs(ud).max(max_abs(tau) / imax)
}

#[test]
fn runtime_matches_newton_euler_with_lagrange_multipliers() {
    for name in CLOSED {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let mut rng = tests::rng(11);
        let mut worst: f64 = 0.0;
        for _ in 0..100 {
            let (x, u, ud) = random_state(&plan, &mut rng, reach(name));
            let ours = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
            let theirs = lagrange_efforts(&m, &x, &u, &ud);
            worst = worst.max(rel(&ours, &theirs));
        }
        println!("{name}: NOC vs Lagrange multipliers, max relative error (max norm) {worst:.1e}");
        assert!(worst < 1e-10, "{name}: {worst:e}");
    }
}

#[test]
fn mass_matrix_is_the_acceleration_part_of_inverse_dynamics() {
    for name in CLOSED {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let n = plan.dof();
        let mut rng = tests::rng(12);
        for _ in 0..50 {
            let (x, u, ud) = random_state(&plan, &mut rng, reach(name));
            let mm = noc::mass_matrix(&plan, &x).unwrap();
            let with = noc::generalized_effort(&plan, &x, &u, &ud, true).unwrap();
            let without = noc::generalized_effort(&plan, &x, &u, &vec![0.0; n], true).unwrap();
            let iud: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| mm[i][j] * ud[j]).sum())
                .collect();
            let diff: Vec<f64> = with.iter().zip(&without).map(|(a, b)| a - b).collect();
            // Relative to the efforts being differenced (the gravity part cancels).
            let e = max_abs_diff(&diff, &iud) / max_abs(&with).max(max_abs(&without));
            assert!(e < 1e-12, "{name}: {e:e}");
            // Forward dynamics inverts inverse dynamics.
            let back = noc::forward_dynamics(&plan, &x, &u, &with).unwrap();
            let e = fd_error(&back, &ud, &with, &mm);
            assert!(e < 1e-10, "{name}: {e:e}");
        }
    }
}

/// Power balance along a smooth motion: `d/dt (½ uᵀ I u) = (f − (−γ))ᵀ u` with `f` the
/// generalized force without gravity, checked by central differences of the kinetic energy
/// along the motion `x_i(t) = x_i0 + a sin(ωt)` assembled by Newton.
#[test]
fn kinetic_energy_rate_equals_power() {
    for name in CLOSED {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let n = plan.dof();
        let mut rng = tests::rng(13);
        for _ in 0..10 {
            let (start, _, _) = random_state(&plan, &mut rng, reach(name).min(2.0));
            let x0: Vec<f64> = plan.independent.iter().map(|&j| start[j]).collect();
            let amp: Vec<f64> = (0..n).map(|_| rng.random_range(-0.05..0.05)).collect();
            let w = 1.3;
            let mut guess = start.clone();
            let mut state = |t: f64| {
                let xi: Vec<f64> = (0..n).map(|k| x0[k] + amp[k] * (w * t).sin()).collect();
                let u: Vec<f64> = (0..n).map(|k| amp[k] * w * (w * t).cos()).collect();
                let ud: Vec<f64> = (0..n).map(|k| -amp[k] * w * w * (w * t).sin()).collect();
                let x = noc::forward_kinematics(&plan, &xi, &guess).unwrap();
                guess = x.clone();
                (x, u, ud)
            };
            let ke = |x: &[f64], u: &[f64]| {
                let mm = noc::mass_matrix(&plan, x).unwrap();
                0.5 * (0..n)
                    .map(|i| (0..n).map(|j| u[i] * mm[i][j] * u[j]).sum::<f64>())
                    .sum::<f64>()
            };
            let t = 0.4;
            let h = 1e-4;
            let (xa, ua, _) = state(t - h);
            let (x, u, ud) = state(t);
            let (xb, ub, _) = state(t + h);
            let rate = (ke(&xb, &ub) - ke(&xa, &ua)) / (2.0 * h);
            let f = noc::generalized_effort(&plan, &x, &u, &ud, false).unwrap();
            let power: f64 = f.iter().zip(&u).map(|(a, b)| a * b).sum();
            let scale = power.abs().max(rate.abs()).max(1e-3);
            assert!(
                (rate - power).abs() / scale < 1e-6,
                "{name}: dT/dt {rate} vs power {power}"
            );
        }
    }
}

#[test]
fn assembly_round_trip_from_a_perturbed_guess() {
    for name in CLOSED {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let mut rng = tests::rng(14);
        for _ in 0..100 {
            let (x, _, _) = random_state(&plan, &mut rng, reach(name));
            let xi: Vec<f64> = plan.independent.iter().map(|&j| x[j]).collect();
            let guess: Vec<f64> = x
                .iter()
                .map(|v| v + rng.random_range(-0.05..0.05))
                .collect();
            let back = noc::forward_kinematics(&plan, &xi, &guess).unwrap();
            assert!(rel(&back, &x) < 1e-10, "{name}: {:?} vs {:?}", back, x);
        }
    }
}

#[test]
fn inputs_that_do_not_close_the_loops_are_refused() {
    for name in CLOSED {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let n = plan.dof();
        let mut rng = tests::rng(15);
        let (mut x, u, ud) = random_state(&plan, &mut rng, 1.0);
        let j = plan.dependent[0];
        x[j] += 1e-3;
        let e = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap_err();
        assert!(matches!(e.site, runtime::scalar::Site::Closure(_)), "{e}");
        let mut bad = x.clone();
        bad[0] = f64::NAN;
        let e = noc::inverse_dynamics(&plan, &bad, &u, &vec![0.0; n]).unwrap_err();
        assert_eq!(e.site, runtime::scalar::Site::Input);
    }
}

macro_rules! generated_matches_runtime {
    ($($m:ident),*) => {$(
        {
            use mechanisms::$m as g;
            let name = stringify!($m);
            let m = model(name);
            let plan = Plan::new(&m).unwrap();
            let mut rng = tests::rng(16);
            let mut worst: f64 = 0.0;
            let mut fk_failures = 0;
            for _ in 0..500 {
                let (x, u, ud) = random_state(&plan, &mut rng, reach(name));
                let xa: [f64; g::NX] = x.clone().try_into().unwrap();
                let ua: [f64; g::DOF] = u.clone().try_into().unwrap();
                let uda: [f64; g::DOF] = ud.clone().try_into().unwrap();
                let ours = g::inverse_dynamics(&xa, &ua, &uda).unwrap();
                let theirs = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
                worst = worst.max(rel(&ours, &theirs));
                let mm = g::mass_matrix(&xa).unwrap();
                let mr = noc::mass_matrix(&plan, &x).unwrap();
                worst = worst.max(rel(&mm.concat(), &mr.concat()));
                worst = worst.max(rel(&g::gravity(&xa).unwrap(), &noc::gravity(&plan, &x).unwrap()));
                worst = worst.max(rel(
                    &g::coriolis(&xa, &ua).unwrap(),
                    &noc::coriolis(&plan, &x, &u).unwrap(),
                ));
                let rates = g::joint_rates(&xa, &ua).unwrap();
                let rr = noc::joint_rates(&plan, &x, &u).unwrap();
                worst = worst.max(rel(&rates, &rr));
                let fd = g::forward_dynamics(&xa, &ua, &ours).unwrap();
                worst = worst.max(fd_error(&fd, &ud, &ours, &mr));
                let xi = g::inverse_kinematics(&xa).unwrap();
                // One Newton solve from home (the runtime's in `random_state`) keeps every
                // dependent angle within ±π of the guess: the same configuration with the
                // fewest turns (Newton's long steps used to land hundreds of radians away,
                // where f32 keeps four digits fewer). Assembly from home follows the path
                // in stages, each such a solve: the generated code's ends where the runtime's
                // does (the same branch).
                let within = |v: &[f64]| {
                    plan.dependent.iter().all(|&j| {
                        m.tree.joints[j].kind != runtime::model::JointKind::Revolute
                            || v[j].abs() <= std::f64::consts::PI + 1e-12
                    })
                };
                assert!(within(&x), "{name}: runtime assembly {x:?}");
                match (g::forward_kinematics(&xi, &g::HOME), noc::forward_kinematics(&plan, &xi, &g::HOME)) {
                    (Ok(h), Ok(r)) => {
                        assert!(max_abs_diff(&h, &r) <= 1e-9, "{name}: {h:?} vs {r:?}");
                        assert!(g::inverse_dynamics(&h, &ua, &uda).is_ok(), "{name}: {h:?}");
                    }
                    (Err(_), Err(_)) => {}
                    (a, b) => panic!("{name}: generated {a:?} but runtime {b:?}"),
                }
                let guess: [f64; g::NX] = core::array::from_fn(|i| x[i] + rng.random_range(-0.05..0.05));
                // Newton from a perturbed guess: the same outcome as the runtime's (near a
                // singular configuration both may fail; then both must).
                let theirs = noc::forward_kinematics(&plan, &xi, &guess);
                match (g::forward_kinematics(&xi, &guess), theirs) {
                    (Ok(back), Ok(b2)) => {
                        worst = worst.max(rel(&back, &x));
                        worst = worst.max(rel(&back, &b2));
                    }
                    (Err(_), Err(_)) => fk_failures += 1,
                    (a, b) => panic!("{}: generated {a:?} but runtime {b:?}", stringify!($m)),
                }
            }
            println!("{}: generated vs runtime, max relative error {worst:.1e}; Newton from a perturbed guess failed in both {fk_failures} of 500 times", stringify!($m));
            assert!(fk_failures <= 25, "{}: {fk_failures}", stringify!($m));
            assert!(worst < 1e-10, "{}: {worst:e}", stringify!($m));
            // The generated code refuses what the runtime refuses: open loops, NaN.
            let (x, u, ud) = random_state(&plan, &mut rng, reach(name));
            let mut open: [f64; g::NX] = x.clone().try_into().unwrap();
            open[plan.dependent[0]] += 1e-3;
            let (ua, uda): ([f64; g::DOF], [f64; g::DOF]) =
                (u.clone().try_into().unwrap(), ud.clone().try_into().unwrap());
            let e = g::inverse_dynamics(&open, &ua, &uda).unwrap_err();
            assert!(matches!(e.site, g::Site::Closure(_)), "{}: {e:?}", stringify!($m));
            let mut nan: [f64; g::NX] = x.clone().try_into().unwrap();
            nan[0] = f64::NAN;
            let e = g::mass_matrix(&nan).unwrap_err();
            assert_eq!(e.site, g::Site::Input, "{}", stringify!($m));
            let e = g::forward_dynamics(&open, &ua, &[f64::INFINITY; g::DOF]).unwrap_err();
            assert!(matches!(e.site, g::Site::Input | g::Site::Closure(_)), "{}: {e:?}", stringify!($m));
            // The actuator-space names of the parallel modules: the actuated joints are the
            // independent coordinates, so `A = 1`.
            let xa: [f64; g::NX] = x.clone().try_into().unwrap();
            assert_eq!(g::actuator_rates(&xa, &ua).unwrap(), ua, "{}", stringify!($m));
            assert_eq!(g::actuator_mass_matrix(&xa).unwrap(), g::mass_matrix(&xa).unwrap());
            let e = g::actuator_rates(&xa, &[f64::NAN; g::DOF]).unwrap_err();
            assert_eq!(e.site, g::Site::Input, "{}", stringify!($m));
            // `HOME` closes the loops (the functions accept it) and assembly from it returns it.
            assert!(g::mass_matrix(&g::HOME).is_ok(), "{}", stringify!($m));
            let q = g::inverse_kinematics(&g::HOME).unwrap();
            let back = g::forward_kinematics(&q, &g::HOME).unwrap();
            assert!(max_abs_diff(&back, &g::HOME) <= 1e-12, "{}: {back:?}", stringify!($m));
        }
    )*};
}

#[test]
fn generated_code_matches_the_runtime() {
    generated_matches_runtime!(
        four_bar,
        five_bar_joints,
        spherical_five_bar,
        bricard,
        n_four_bar,
        tripod_3prs,
        andrews_squeezer
    );
}

/// The five-bar twice: in joint coordinates (`five_bar_joints`) and with the meeting point as
/// the platform (`planar_five_bar`). The same machine, so at corresponding states the
/// actuator-space inertia `A⁻ᵀ I A⁻¹` of the platform form equals the joint-coordinate inertia
/// of the actuated angles, and the gravity torques at rest agree.
#[test]
fn five_bar_in_joint_coordinates_matches_the_platform_form() {
    use runtime::parallel::noc as pnoc;
    let jm = model("five_bar_joints");
    let jplan = Plan::new(&jm).unwrap();
    let pm = tests::pkm::model("planar_five_bar");
    let pplan = pnoc::Plan::new(&pm).unwrap();
    let home = pm.home_x();
    let mut rng = tests::rng(17);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (p, _, _) = tests::pkm::random_state(&pplan, &home, &mut rng, 0.0, 0.05);
        let q = pnoc::inverse_kinematics(&pplan, &p).unwrap();
        let x = noc::forward_kinematics(&jplan, &q, &vec![0.0; jplan.nx()]).unwrap();
        let ma = pnoc::actuator_mass_matrix(&pplan, &p).unwrap();
        let mj = noc::mass_matrix(&jplan, &x).unwrap();
        worst = worst.max(rel(&mj.concat(), &ma.concat()));
        let ga = pnoc::inverse_dynamics(&pplan, &p, &[0.0; 2], &[0.0; 2]).unwrap();
        let gj = noc::inverse_dynamics(&jplan, &x, &[0.0; 2], &[0.0; 2]).unwrap();
        worst = worst.max(rel(&gj, &ga));
    }
    println!("five-bar: joint coordinates vs platform form, max relative error {worst:.1e}");
    assert!(worst < 1e-10, "{worst:e}");
}

/// The N-four-bar (IFToMM A02, N = 2) on its parallelogram branch: every crank at the same
/// angle `θ` from the ground line, the couplers translating. Its dynamics in closed form (bars of
/// 1 m and 1 kg, g = 9.81 m/s²): kinetic energy `½ (3 · ⅓ + 2 · 1) θ̇²`, potential energy
/// `(3 · ½ + 2 · 1) g sin θ`, so `τ = 3 θ̈ + 3.5 g cos θ` and `I = 3` kg·m², with no velocity
/// term. `x` on that branch: cranks at `θ − π/2` (home: pointing up), couplers at `−(θ − π/2)`.
fn n_four_bar_state(m: &runtime::closed::ClosedModel, theta: f64) -> Vec<f64> {
    let a = theta - std::f64::consts::FRAC_PI_2;
    m.tree
        .joints
        .iter()
        .map(|j| if j.name.starts_with("crank") { a } else { -a })
        .collect()
}

fn n_four_bar_closed_form(theta: f64, thetadd: f64) -> f64 {
    3.0 * thetadd + 3.5 * 9.81 * theta.cos()
}

#[test]
fn n_four_bar_matches_its_closed_form() {
    let m = model("n_four_bar");
    let plan = Plan::new(&m).unwrap();
    let mut rng = tests::rng(18);
    for _ in 0..200 {
        let theta = rng.random_range(0.2..2.9);
        let x = n_four_bar_state(&m, theta);
        let (u, ud) = (rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
        let tau = noc::inverse_dynamics(&plan, &x, &[u], &[ud]).unwrap();
        let want = n_four_bar_closed_form(theta, ud);
        assert!(
            (tau[0] - want).abs() <= 1e-12 * want.abs().max(1.0),
            "{theta}: {} vs {want}",
            tau[0]
        );
        let mm = noc::mass_matrix(&plan, &x).unwrap();
        assert!((mm[0][0] - 3.0).abs() < 1e-12, "{}", mm[0][0]);
    }
}

/// Walk the N-four-bar to its change point (all bars horizontal, `θ → 0`): the runtime and the
/// generated code stay within 1e-6 of the closed form until they return
/// `Err(Singular { site: Constraint(..) })`, and they do return it before `θ = 1e-12`.
#[test]
fn n_four_bar_walk_to_the_change_point() {
    let m = model("n_four_bar");
    let plan = Plan::new(&m).unwrap();
    let mut first_err = None;
    let mut worst: f64 = 0.0;
    for k in 1..=14 {
        // 3·10⁻ᵏ: away from the pivot threshold 1e-4, where rounding decides either way.
        let theta = 3.0 * 10f64.powi(-k);
        let x = n_four_bar_state(&m, theta);
        let want = n_four_bar_closed_form(theta, 0.7);
        let xa: [f64; 5] = x.clone().try_into().unwrap();
        let ours = noc::inverse_dynamics(&plan, &x, &[0.3], &[0.7]);
        let generated = mechanisms::n_four_bar::inverse_dynamics(&xa, &[0.3], &[0.7]);
        match (ours, generated) {
            (Ok(a), Ok(b)) => {
                let e = ((a[0] - want).abs()).max((b[0] - want).abs()) / want.abs();
                worst = worst.max(e);
                assert!(e < 1e-6, "θ = {theta:e}: relative error {e:e}");
            }
            (Err(a), Err(b)) => {
                assert!(
                    matches!(a.site, runtime::scalar::Site::Constraint(_)),
                    "{a}"
                );
                assert!(
                    matches!(b.site, mechanisms::n_four_bar::Site::Constraint(_)),
                    "{b:?}"
                );
                first_err.get_or_insert((theta, a.condition_estimate));
            }
            (a, b) => panic!("θ = {theta:e}: runtime {a:?} but generated {b:?}"),
        }
    }
    let (at, cond) = first_err.expect("no error before θ = 1e-14");
    println!(
        "n_four_bar: within {worst:.1e} of the closed form until Err(Constraint) at θ = {at:e} (condition estimate {cond:.1e})"
    );
    assert!(at >= 1e-12);
}

/// The N-four-bar as a spec with `n` parallelogram loops (IFToMM A02's bars: 1 m, 1 kg, thin),
/// its joints listed cranks first (`interleaved = false`, as `n_four_bar.toml`) or each coupler
/// after its crank.
fn n_four_bar_spec(n: usize, interleaved: bool) -> String {
    let bar = "mass = 1.0\ncom = [0.5, 0.0, 0.0]\ninertia = { ixx = 0.0, iyy = 0.08333333333333333, izz = 0.08333333333333333 }\n";
    let mut s = format!("[mechanism]\nname = \"n_four_bar_{n}\"\ngravity = [0.0, -9.81, 0.0]\n\n");
    for k in 0..=n {
        s += &format!("[[body]]\nname = \"crank{k}\"\n{bar}\n");
    }
    for k in 0..n {
        s += &format!("[[body]]\nname = \"coupler{k}\"\n{bar}\n");
    }
    let crank = |k: usize| {
        format!(
            "[[joint]]\nname = \"crank{k}\"\nkind = \"revolute\"\nparent = \"base\"\nchild = \"crank{k}\"\norigin = {{ xyz = [{k}.0, 0.0, 0.0], rpy = [0.0, 0.0, 1.5707963267948966] }}\naxis = [0.0, 0.0, 1.0]\n{}\n",
            if k == 0 { "actuated = true\n" } else { "" }
        )
    };
    let coupler = |k: usize| {
        format!(
            "[[joint]]\nname = \"coupler{k}\"\nkind = \"revolute\"\nparent = \"crank{k}\"\nchild = \"coupler{k}\"\norigin = {{ xyz = [1.0, 0.0, 0.0], rpy = [0.0, 0.0, -1.5707963267948966] }}\naxis = [0.0, 0.0, 1.0]\n\n"
        )
    };
    if interleaved {
        for k in 0..=n {
            s += &crank(k);
            if k < n {
                s += &coupler(k);
            }
        }
    } else {
        for k in 0..=n {
            s += &crank(k);
        }
        for k in 0..n {
            s += &coupler(k);
        }
    }
    for k in 0..n {
        s += &format!(
            "[[joint]]\nname = \"tip{}\"\nkind = \"revolute\"\nparent = \"coupler{k}\"\nchild = \"crank{}\"\norigin = {{ xyz = [1.0, 0.0, 0.0] }}\naxis = [0.0, 0.0, 1.0]\nchild_origin = {{ xyz = [1.0, 0.0, 0.0] }}\n\n",
            k + 1,
            k + 1
        );
    }
    s
}

/// The N-four-bar at the benchmark's size (IFToMM A02: N = 40, 81 bars, 80 dependent angles):
/// the runtime against the parallelogram branch's closed form (`τ = ((N+1)/3 + N) θ̈ +
/// ((N+1)/2 + N) g cos θ`, as `n_four_bar_closed_form` for N = 2), and the generated code's
/// cost linear in N whatever the joints' order: the dependent angles are banded (reverse
/// Cuthill–McKee) and the LU's pivot selects mix only rows that share a column, so doubling
/// the loops doubles the operations (with the spec's order and LAPACK-style row swaps it was
/// 4× the flops at N = 20 and 1.7 GB of generator memory).
#[test]
fn n_four_bar_at_the_benchmark_size() {
    // Only the function whose cost is checked: the regressor's base-parameter scan assembles
    // hundreds of random states by Newton, which is most of a full module's generation time.
    let flops = |n: usize, interleaved: bool| {
        let spec =
            n_four_bar_spec(n, interleaved) + "[scene]\nfunctions = [\"inverse_dynamics\"]\n";
        let g = codegen::compile("n.toml", &spec, &codegen::Config::default())
            .unwrap_or_else(|e| panic!("{e:?}"));
        g.stats
            .iter()
            .find(|(f, _)| f == "inverse_dynamics")
            .map(|(_, o)| o.flops())
            .unwrap()
    };
    let (f10, f20, f40) = (flops(10, false), flops(20, false), flops(40, false));
    println!("N-four-bar inverse dynamics: N = 10: {f10} flops, N = 20: {f20}, N = 40: {f40}");
    assert!(
        f40 < 2 * f20 + f20 / 10 && f20 < 2 * f10 + f10 / 5,
        "{f10} {f20} {f40}"
    );
    assert_eq!(flops(20, true), f20, "the joints' order changed the cost");

    let n = 40;
    let src = n_four_bar_spec(n, false);
    let Ok((codegen::spec::Mechanism::Closed(m), _)) =
        codegen::spec::load_mechanism("n.toml", &src)
    else {
        panic!("the N-four-bar spec did not load");
    };
    let plan = Plan::new(&m).unwrap();
    let mut rng = tests::rng(40);
    let (a, b) = (
        (n as f64 + 1.0) / 3.0 + n as f64,
        (n as f64 + 1.0) / 2.0 + n as f64,
    );
    for _ in 0..20 {
        let (x, u, ud) = random_state(&plan, &mut rng, 1.2);
        let theta = x[0] + std::f64::consts::FRAC_PI_2;
        let tau = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        let want = a * ud[0] + b * 9.81 * theta.cos();
        assert!(
            (tau[0] - want).abs() <= 1e-11 * want.abs().max(1.0),
            "{} vs {want}",
            tau[0]
        );
        let mm = noc::mass_matrix(&plan, &x).unwrap();
        assert!((mm[0][0] - a).abs() <= 1e-11 * a, "{}", mm[0][0]);
    }
    // Assembly from home to a far crank angle follows the path and stays on the
    // parallelogram branch (one Newton solve from home folds some couplers beyond 0.76 rad).
    for theta in [0.3, 0.6, 2.6, 2.9] {
        let x = noc::forward_kinematics(
            &plan,
            &[theta - std::f64::consts::FRAC_PI_2],
            &vec![0.0; plan.nx()],
        )
        .unwrap();
        let tau = noc::inverse_dynamics(&plan, &x, &[0.0], &[0.0]).unwrap();
        let want = b * 9.81 * f64::cos(theta);
        assert!(
            (tau[0] - want).abs() <= 1e-10 * want.abs(),
            "θ = {theta}: {} vs {want}",
            tau[0]
        );
    }
}

/// The generated assembly from `HOME` to a far crank angle stays on the N-four-bar's
/// parallelogram branch, as its closed form shows.
#[test]
fn generated_assembly_follows_the_branch_of_its_guess() {
    use mechanisms::n_four_bar as g;
    for theta in [0.3f64, 0.5, 2.7, 2.9] {
        let x = g::forward_kinematics(&[theta - std::f64::consts::FRAC_PI_2], &g::HOME).unwrap();
        let tau = g::inverse_dynamics(&x, &[0.0], &[0.0]).unwrap();
        let want = n_four_bar_closed_form(theta, 0.0);
        assert!(
            (tau[0] - want).abs() <= 1e-10 * want.abs(),
            "θ = {theta}: {} vs {want}",
            tau[0]
        );
    }
}

/// Andrews' squeezer against the book's own equations (Hairer & Wanner, "Solving Ordinary
/// Differential Equations II", 2nd ed. 1996, sec. VII.7, the benchmark's loop equations
/// `g(q) = 0` and mass matrix `M(q)` in the coordinates `q = (β, Θ, γ, Φ, δ, Ω, ε)`, written
/// out here independently of the spec): over a full turn of the crank, nocdyn's assembly
/// satisfies the book's loop equations, and its generalized inertia equals `Sᵀ M S` with
/// `S = dq/dβ` from the book's constraint Jacobian (`G_d S_d = −G_β`).
#[test]
fn andrews_squeezer_matches_the_books_equations() {
    use nalgebra::{DMatrix, DVector};
    let (xa, ya, xb, yb) = (-0.06934, -0.00227, -0.03635, 0.03273);
    let (d, da, e, ea, rr, ra) = (0.028, 0.0115, 0.02, 0.01421, 0.007, 0.00092);
    let (ss, sa, sb, ta, tb) = (0.035, 0.01874, 0.01043, 0.02308, 0.00916);
    let (u, ua, ub, zf, zt, fa) = (0.04, 0.01228, 0.00449, 0.02, 0.04, 0.01421);
    let m = [
        0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498,
    ];
    let i = [
        2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5,
    ];
    // The book's consistent initial values (its loop equations vanish there to 1e-17), with
    // the book's digits.
    #[allow(clippy::excessive_precision)]
    let q0 = [
        -0.0617138900142764496358948458001,
        0.0,
        0.455279819163070380255912382449,
        0.222668390165885884674473185609,
        0.487364979543842550225598953530,
        -0.222668390165885884674473185609,
        1.23054744454982119249735015568,
    ];
    let names = ["beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"];
    let model = model("andrews_squeezer");
    let plan = Plan::new(&model).unwrap();
    let index: Vec<usize> = names
        .iter()
        .map(|n| model.tree.joints.iter().position(|j| j.name == *n).unwrap())
        .collect();
    let g = |q: &[f64; 7]| -> [f64; 6] {
        let [be, th, ga, ph, de, om, ep] = *q;
        let (x1, y1) = (
            rr * be.cos() - d * (be + th).cos(),
            rr * be.sin() - d * (be + th).sin(),
        );
        [
            x1 - ss * ga.sin() - xb,
            y1 + ss * ga.cos() - yb,
            x1 - e * (ph + de).sin() - zt * de.cos() - xa,
            y1 + e * (ph + de).cos() - zt * de.sin() - ya,
            x1 - zf * (om + ep).cos() - u * ep.sin() - xa,
            y1 - zf * (om + ep).sin() + u * ep.cos() - ya,
        ]
    };
    let jac = |q: &[f64; 7]| -> DMatrix<f64> {
        let [be, th, ga, ph, de, om, ep] = *q;
        let (sbt, cbt) = (be + th).sin_cos();
        let (gx_b, gy_b) = (-rr * be.sin() + d * sbt, rr * be.cos() - d * cbt);
        let (gx_t, gy_t) = (d * sbt, -d * cbt);
        let (spd, cpd) = (ph + de).sin_cos();
        let (soe, coe) = (om + ep).sin_cos();
        #[rustfmt::skip]
        let rows = [
            [gx_b, gx_t, -ss * ga.cos(), 0.0, 0.0, 0.0, 0.0],
            [gy_b, gy_t, -ss * ga.sin(), 0.0, 0.0, 0.0, 0.0],
            [gx_b, gx_t, 0.0, -e * cpd, -e * cpd + zt * de.sin(), 0.0, 0.0],
            [gy_b, gy_t, 0.0, -e * spd, -e * spd - zt * de.cos(), 0.0, 0.0],
            [gx_b, gx_t, 0.0, 0.0, 0.0, zf * soe, zf * soe - u * ep.cos()],
            [gy_b, gy_t, 0.0, 0.0, 0.0, -zf * coe, -zf * coe - u * ep.sin()],
        ];
        DMatrix::from_fn(6, 7, |r, c| rows[r][c])
    };
    let mass = |q: &[f64; 7]| -> DMatrix<f64> {
        let (th, ph, om) = (q[1], q[3], q[5]);
        let (ee, ff) = (e - ea, zf - fa);
        let mut mm = DMatrix::zeros(7, 7);
        mm[(0, 0)] =
            m[0] * ra * ra + m[1] * (rr * rr - 2.0 * da * rr * th.cos() + da * da) + i[0] + i[1];
        mm[(0, 1)] = m[1] * (da * da - da * rr * th.cos()) + i[1];
        mm[(1, 0)] = mm[(0, 1)];
        mm[(1, 1)] = m[1] * da * da + i[1];
        mm[(2, 2)] = m[2] * (sa * sa + sb * sb) + i[2];
        mm[(3, 3)] = m[3] * ee * ee + i[3];
        mm[(3, 4)] = m[3] * (ee * ee + zt * ee * ph.sin()) + i[3];
        mm[(4, 3)] = mm[(3, 4)];
        mm[(4, 4)] = m[3] * (zt * zt + 2.0 * zt * ee * ph.sin() + ee * ee)
            + m[4] * (ta * ta + tb * tb)
            + i[3]
            + i[4];
        mm[(5, 5)] = m[5] * ff * ff + i[5];
        mm[(5, 6)] = m[5] * (ff * ff - u * ff * om.sin()) + i[5];
        mm[(6, 5)] = mm[(5, 6)];
        mm[(6, 6)] = m[5] * (ff * ff - 2.0 * u * ff * om.sin() + u * u)
            + m[6] * (ua * ua + ub * ub)
            + i[5]
            + i[6];
        mm
    };
    assert!(g(&q0).iter().all(|v| v.abs() < 1e-16), "{:?}", g(&q0));
    let mut x = vec![0.0; plan.nx()];
    let mut worst_g: f64 = 0.0;
    let mut worst_i: f64 = 0.0;
    for k in 0..=72 {
        // A full turn of the crank in 5° steps, each assembled from the last.
        let beta = 2.0 * std::f64::consts::PI * k as f64 / 72.0;
        x = noc::forward_kinematics(&plan, &[beta], &x).unwrap();
        let q: [f64; 7] = core::array::from_fn(|c| q0[c] + x[index[c]]);
        worst_g = g(&q).iter().fold(worst_g, |w, v| w.max(v.abs()));
        let gq = jac(&q);
        let gd = gq.columns(1, 6).into_owned();
        let sd = gd.lu().solve(&(-gq.column(0).into_owned())).unwrap();
        let s = DVector::from_fn(7, |r, _| if r == 0 { 1.0 } else { sd[r - 1] });
        let want = (s.transpose() * mass(&q) * &s)[(0, 0)];
        let ours = noc::mass_matrix(&plan, &x).unwrap()[0][0];
        let xa_: [f64; 7] = x.clone().try_into().unwrap();
        let generated = mechanisms::andrews_squeezer::mass_matrix(&xa_).unwrap()[0][0];
        worst_i = worst_i
            .max((ours - want).abs() / want)
            .max((generated - want).abs() / want);
    }
    // The published initial acceleration: at rest in the initial configuration the drive
    // torque 0.033 N·m gives β̈(0) = 14222.4439199541138705911625887 rad/s² (the consistent
    // initial values of problem ANDREWS in Mazzia & Magherini's "Test Set for IVP Solvers";
    // E is at rest there, `Θ̇ = −0.75 β̇`, so the spring does no work).
    let home = vec![0.0; plan.nx()];
    let bdd = noc::forward_dynamics(&plan, &home, &[0.0], &[0.033]).unwrap()[0];
    let generated =
        mechanisms::andrews_squeezer::forward_dynamics(&[0.0; 7], &[0.0], &[0.033]).unwrap()[0];
    #[allow(clippy::excessive_precision)]
    let published = 14222.4439199541138705911625887;
    let e_fd = ((bdd - published).abs()).max((generated - published).abs()) / published;
    let rates = noc::joint_rates(&plan, &home, &[1.0]).unwrap();
    println!(
        "Andrews' squeezer over a crank turn: the book's loop equations ≤ {worst_g:.1e} m, generalized inertia vs the book's Sᵀ M S {worst_i:.1e} (relative); β̈(0) = {bdd} against the published {published} ({e_fd:.1e})"
    );
    assert!(e_fd < 1e-12, "{bdd} vs {published}");
    assert!((rates[index[1]] + 0.75).abs() < 1e-12, "{rates:?}");
    assert!(worst_g < 1e-15, "{worst_g:e}");
    assert!(worst_i < 1e-11, "{worst_i:e}");
}

/// Andrews' squeezer driven as the benchmark drives it (0.033 N·m on β, the spring, from rest
/// in the initial configuration), integrated with the generated code (classical RK4 on
/// `(β, β̇)`, h = 2.5e-6 s, the loops reassembled by `forward_kinematics` from the last
/// configuration) to t = 0.03 s, against the published reference solution: the 7 angles and 7
/// angular velocities of problem ANDREWS in the IVP test set (Lioen & de Swart, CWI 1999;
/// Mazzia & Magherini, Bari; computed with PSIDE at tolerance 1e-14).
#[test]
fn andrews_squeezer_reproduces_the_published_solution() {
    use mechanisms::andrews_squeezer as g;
    #[allow(clippy::excessive_precision)]
    let q0 = [
        -0.0617138900142764496358948458001,
        0.0,
        0.455279819163070380255912382449,
        0.222668390165885884674473185609,
        0.487364979543842550225598953530,
        -0.222668390165885884674473185609,
        1.23054744454982119249735015568,
    ];
    // y(1..14) at t = 0.03 (the test set's `solut`): β, Θ, γ, Φ, δ, Ω, ε, then their rates.
    let reference = [
        0.1581077119629904e+2,
        -0.1575637105984298e+2,
        0.4082224013073101e-1,
        -0.5347301163226948e+0,
        0.5244099658805304e+0,
        0.5347301163226948e+0,
        0.1048080741042263e+1,
        0.1139920302151208e+4,
        -0.1424379294994111e+4,
        0.1103291221937134e+2,
        0.1929337464421385e+2,
        0.5735699284790808e+0,
        -0.1929337464421385e+2,
        0.3231791658026955e+0,
    ];
    let names = ["beta", "Theta", "gamma", "Phi", "delta", "Omega", "epsilon"];
    let index: Vec<usize> = names
        .iter()
        .map(|n| g::JOINT_NAMES.iter().position(|j| j == n).unwrap())
        .collect();
    let h = 2.5e-6;
    let mut x = g::HOME;
    let (mut b, mut bd) = (0.0f64, 0.0f64);
    let acc = |b: f64, bd: f64, guess: &[f64; 7]| {
        let x = g::forward_kinematics(&[b], guess).unwrap();
        (g::forward_dynamics(&x, &[bd], &[0.033]).unwrap()[0], x)
    };
    for _ in 0..12_000 {
        let (k1, x1) = acc(b, bd, &x);
        let (k2, _) = acc(b + 0.5 * h * bd, bd + 0.5 * h * k1, &x1);
        let (k3, _) = acc(b + 0.5 * h * (bd + 0.5 * h * k1), bd + 0.5 * h * k2, &x1);
        let (k4, _) = acc(b + h * (bd + 0.5 * h * k2), bd + h * k3, &x1);
        b += h * (bd + h / 6.0 * (k1 + k2 + k3));
        bd += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        x = x1;
    }
    let x = g::forward_kinematics(&[b], &x).unwrap();
    let xd = g::joint_rates(&x, &[bd]).unwrap();
    let ours: Vec<f64> = (0..7)
        .map(|c| q0[c] + x[index[c]])
        .chain((0..7).map(|c| xd[index[c]]))
        .collect();
    // Relative in the ∞-norm, positions and rates apart (the small rates, such as ε̇ = 0.32
    // rad/s beside β̇ = 1140 rad/s, carry the trajectory's sensitivity in absolute terms).
    let normwise = |a: &[f64], r: &[f64]| {
        let e = a
            .iter()
            .zip(r)
            .fold(0.0f64, |m, (a, r)| m.max((a - r).abs()));
        e / r.iter().fold(0.0f64, |m, r| m.max(r.abs()))
    };
    let (ep, ev) = (
        normwise(&ours[..7], &reference[..7]),
        normwise(&ours[7..], &reference[7..]),
    );
    println!(
        "Andrews' squeezer at t = 0.03 s: β = {} (published {}); relative error (∞-norm) of the 7 angles {ep:.1e}, of the 7 rates {ev:.1e}",
        ours[0], reference[0]
    );
    assert!(ep < 1e-9 && ev < 1e-9, "{ours:?}");
    // The same run by the runtime's integrator (`runtime::simulate::simulate_driven`, RK4 with
    // the loops reassembled at every stage).
    let model = model("andrews_squeezer");
    let plan = Plan::new(&model).unwrap();
    let run = runtime::simulate::simulate_driven(
        &plan,
        &g::HOME,
        &[0.0],
        &[0.033],
        h,
        12_000,
        runtime::simulate::Method::Rk4,
    )
    .unwrap();
    assert!(run.report.stopped.is_none(), "{:?}", run.report);
    let rates = noc::joint_rates(&plan, &run.x, &run.u).unwrap();
    let theirs: Vec<f64> = (0..7)
        .map(|c| q0[c] + run.x[index[c]])
        .chain((0..7).map(|c| rates[index[c]]))
        .collect();
    let (rp, rv) = (
        normwise(&theirs[..7], &reference[..7]),
        normwise(&theirs[7..], &reference[7..]),
    );
    println!(
        "the same with runtime::simulate::simulate_driven: {rp:.1e} (angles), {rv:.1e} (rates)"
    );
    assert!(rp < 1e-9 && rv < 1e-9, "{theirs:?}");
}

/// A damped spring (the four-bar with a spring-damper from a ground point to the coupler):
/// the NOC efforts against Newton–Euler with Lagrange multipliers, which applies the spring's
/// force `∓(k (L − L₀) + c L̇) n` at the two material points on its own, at moving states (so the
/// damping term is exercised).
#[test]
fn damped_spring_matches_the_lagrange_route() {
    let src = format!(
        "{}\n[[spring]]\nname = \"s\"\nbody_a = \"base\"\npoint_a = [0.3, -0.2, 0.0]\nbody_b = \"coupler\"\npoint_b = [0.35, 0.05, 0.0]\nstiffness = 250.0\nrest_length = 0.3\ndamping = 7.5\n",
        std::fs::read_to_string(tests::pkm::spec_path("four_bar")).unwrap()
    );
    let Ok((codegen::spec::Mechanism::Closed(m), _)) =
        codegen::spec::load_mechanism("s.toml", &src)
    else {
        panic!("the spec did not load");
    };
    let plan = Plan::new(&m).unwrap();
    // The same without the damping: the damping term must matter at these states.
    let mut undamped = m.clone();
    undamped.springs[0].damping = 0.0;
    let plan0 = Plan::new(&undamped).unwrap();
    let mut rng = tests::rng(31);
    let (mut worst, mut damping_share): (f64, f64) = (0.0, 0.0);
    for _ in 0..100 {
        let (x, u, ud) = random_state(&plan, &mut rng, 3.0);
        let ours = noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
        let theirs = lagrange_efforts(&m, &x, &u, &ud);
        worst = worst.max(rel(&ours, &theirs));
        let without = noc::inverse_dynamics(&plan0, &x, &u, &ud).unwrap();
        damping_share = damping_share.max(rel(&ours, &without));
    }
    println!(
        "four-bar with a damped spring: NOC vs Lagrange multipliers {worst:.1e} (the damping moves the efforts by up to {damping_share:.1e})"
    );
    assert!(
        damping_share > 1e-2,
        "the damping hardly matters here: {damping_share}"
    );
    assert!(worst < 1e-10, "{worst:e}");
}
