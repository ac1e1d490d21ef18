//! Single precision: every bundled mechanism generated as `f32` (`mechanisms::f32::*`, the
//! `f32` feature) against the same mechanism's `f64` module (itself checked against the
//! independent routes), on random regular states. The error is relative in the ∞-norm of the
//! `f64` result; away from singularities it must stay within 1e-4 (the figure printed is the
//! worst over the states, the charter's "f32 worst relative error"). Closed loops are also
//! measured assembled by the `f64` module and evaluated in `f32` (within 1e-5 where the
//! problem is well conditioned), and against the `f32`-rounded mechanism evaluated exactly.

use rand::Rng;
use tests::pkm::rel;

fn to32<const N: usize>(v: &[f64]) -> [f32; N] {
    core::array::from_fn(|i| v[i] as f32)
}

fn to64(v: &[f32]) -> Vec<f64> {
    v.iter().map(|&x| x as f64).collect()
}

/// The worst relative error allowed in single precision away from singularities.
const F32_TOLERANCE: f64 = 1e-4;

macro_rules! trees {
    ($($m:ident),*) => {$(
        {
            use mechanisms::$m as d;
            use mechanisms::f32::$m as s;
            const N: usize = d::DOF;
            let mut rng = tests::rng(21);
            let mut worst: f64 = 0.0;
            for _ in 0..200 {
                let q: Vec<f64> = (0..N).map(|_| rng.random_range(-2.0..2.0)).collect();
                let qd: Vec<f64> = (0..N).map(|_| rng.random_range(-1.0..1.0)).collect();
                let qdd: Vec<f64> = (0..N).map(|_| rng.random_range(-1.0..1.0)).collect();
                let (q64, qd64, qdd64): ([f64; N], [f64; N], [f64; N]) =
                    (q.clone().try_into().unwrap(), qd.clone().try_into().unwrap(), qdd.clone().try_into().unwrap());
                let (q32, qd32, qdd32) = (to32::<N>(&q), to32::<N>(&qd), to32::<N>(&qdd));
                // The inputs rounded to f32 are the inputs: compare at the same (rounded) state.
                let q64r: [f64; N] = core::array::from_fn(|i| q32[i] as f64);
                let qd64r: [f64; N] = core::array::from_fn(|i| qd32[i] as f64);
                let qdd64r: [f64; N] = core::array::from_fn(|i| qdd32[i] as f64);
                let _ = (q64, qd64, qdd64);
                let tau = d::inverse_dynamics(&q64r, &qd64r, &qdd64r);
                let tau32 = s::inverse_dynamics(&q32, &qd32, &qdd32);
                worst = worst.max(rel(&to64(&tau32), &tau));
                let m = d::mass_matrix(&q64r);
                let m32 = s::mass_matrix(&q32);
                worst = worst.max(rel(&to64(&m32.concat()), &m.concat()));
            }
            println!("{}: f32 vs f64, worst relative error {worst:.1e}", stringify!($m));
            assert!(worst < F32_TOLERANCE, "{}: {worst:e}", stringify!($m));
        }
    )*};
}

#[test]
fn trees_in_single_precision() {
    trees!(
        planar_2r,
        puma560,
        stanford_arm,
        chain7,
        iiwa14,
        gripper_tree
    );
}

macro_rules! parallel {
    ($($m:ident),*) => {$(
        {
            use mechanisms::$m as d;
            use mechanisms::f32::$m as s;
            use runtime::parallel::noc::Plan;
            const N: usize = d::DOF;
            const NX: usize = d::NX;
            let model = tests::pkm::model(stringify!($m));
            let plan = Plan::new(&model).unwrap();
            let home = model.home_x();
            let (angle, reach) = match model.motion {
                runtime::parallel::PlatformMotion::Pose => (0.1, 0.02 * model.size()),
                runtime::parallel::PlatformMotion::Orientation { .. } => (0.3, 0.0),
                runtime::parallel::PlatformMotion::PlanarPoint { .. } => (0.0, 0.05),
                runtime::parallel::PlatformMotion::Translation { .. } => (0.0, 0.02 * model.size()),
                runtime::parallel::PlatformMotion::PlanarPose { .. }
                | runtime::parallel::PlatformMotion::HeaveTilt { .. }
                | runtime::parallel::PlatformMotion::Schoenflies { .. } => (0.1, 0.02 * model.size()),
            };
            let mut rng = tests::rng(22);
            let mut worst: f64 = 0.0;
            for _ in 0..200 {
                let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut rng, angle, reach);
                let (x32, u32_, ud32) = (to32::<NX>(&x), to32::<N>(&u), to32::<N>(&ud));
                let xr: [f64; NX] = core::array::from_fn(|i| x32[i] as f64);
                let ur: [f64; N] = core::array::from_fn(|i| u32_[i] as f64);
                let udr: [f64; N] = core::array::from_fn(|i| ud32[i] as f64);
                let tau = d::inverse_dynamics(&xr, &ur, &udr).unwrap();
                let tau32 = s::inverse_dynamics(&x32, &u32_, &ud32).unwrap();
                worst = worst.max(rel(&to64(&tau32), &tau));
                let m = d::actuator_mass_matrix(&xr).unwrap();
                let m32 = s::actuator_mass_matrix(&x32).unwrap();
                worst = worst.max(rel(&to64(&m32.concat()), &m.concat()));
                let q = d::inverse_kinematics(&xr).unwrap();
                let q32 = s::inverse_kinematics(&x32).unwrap();
                worst = worst.max(rel(&to64(&q32), &q));
            }
            println!("{}: f32 vs f64, worst relative error {worst:.1e}", stringify!($m));
            assert!(worst < F32_TOLERANCE, "{}: {worst:e}", stringify!($m));
        }
    )*};
}

#[test]
fn parallel_mechanisms_in_single_precision() {
    parallel!(
        gough_stewart,
        sliding_hexapod,
        rus_hexapod,
        agile_eye,
        planar_five_bar,
        delta_rl5,
        planar_3rrr,
        tsai_3upu,
        prs_head,
        delta4_rl5
    );
}

/// `f64` arithmetic on the model's constants rounded to `f32`: every constant the closed-loop
/// evaluator takes (geometry, inertia, gravity: [`runtime::scalar::Real::c`]) is rounded to
/// single precision, every operation is done in double. What it computes is the exact
/// dynamics of the mechanism an `f32` module describes, to `f64` rounding: the error no `f32`
/// arithmetic, however careful, can remove.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
struct F32Constants(f64);

macro_rules! f32c_op {
    ($tr:ident, $m:ident, $op:tt) => {
        impl core::ops::$tr for F32Constants {
            type Output = F32Constants;
            fn $m(self, o: F32Constants) -> F32Constants {
                F32Constants(self.0 $op o.0)
            }
        }
    };
}
f32c_op!(Add, add, +);
f32c_op!(Sub, sub, -);
f32c_op!(Mul, mul, *);
f32c_op!(Div, div, /);

impl core::ops::Neg for F32Constants {
    type Output = F32Constants;
    fn neg(self) -> F32Constants {
        F32Constants(-self.0)
    }
}

impl runtime::scalar::Real for F32Constants {
    fn c(v: f64) -> Self {
        F32Constants(v as f32 as f64)
    }
    fn sqrt(self) -> Self {
        F32Constants(self.0.sqrt())
    }
    fn atan2(self, x: Self) -> Self {
        F32Constants(self.0.atan2(x.0))
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.0.sin_cos();
        (F32Constants(s), F32Constants(c))
    }
    fn select_abs_gt(a: Self, b: Self, x: Self, y: Self) -> Self {
        if a.0.abs() > b.0.abs() { x } else { y }
    }
    fn check(
        value: Self,
        threshold: Self,
        scale: Self,
        site: runtime::scalar::Site,
        two_sided: bool,
    ) -> Result<Self, runtime::scalar::Singular> {
        f64::check(value.0, threshold.0, scale.0, site, two_sided).map(F32Constants)
    }
}

/// The inverse dynamics of the `f32` module's mechanism (constants rounded to `f32`), in `f64`
/// arithmetic: assembled from the independent coordinates `xi` by Newton's method from `guess`
/// (the exact model's assembly), then evaluated.
fn f32_model_inverse_dynamics(
    plan: &runtime::closed::noc::Plan,
    xi: &[f64],
    guess: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Option<Vec<f64>> {
    use runtime::closed::noc as cnoc;
    let lift = |v: &[f64]| -> Vec<F32Constants> { v.iter().map(|&t| F32Constants(t)).collect() };
    let mut x = lift(guess);
    for (k, &j) in plan.independent.iter().enumerate() {
        x[j] = F32Constants(xi[k]);
    }
    for _ in 0..20 {
        let (dx, _, _) = cnoc::newton_step(plan, &x).ok()?;
        let step = dx.iter().fold(0.0f64, |m, d| m.max(d.0.abs()));
        for (a, d) in x.iter_mut().zip(&dx) {
            *a = *a + *d;
        }
        if step < 1e-15 {
            break;
        }
    }
    let c = cnoc::configuration(plan, &x, false).ok()?;
    let f = cnoc::generalized_force(plan, &c, &lift(u), &lift(ud), true);
    Some(f.iter().map(|t| t.0).collect())
}

macro_rules! closed {
    ($($m:ident),*) => {$(
        {
            use mechanisms::$m as d;
            use mechanisms::f32::$m as s;
            use runtime::closed::noc::Plan;
            const N: usize = d::DOF;
            const NX: usize = d::NX;
            let name = stringify!($m);
            let model = tests::closed::model(name);
            let plan = Plan::new(&model).unwrap();
            let mut rng = tests::rng(23);
            let mut worst: f64 = 0.0;
            let mut worst_assembly: f64 = 0.0;
            let mut worst_function: f64 = 0.0;
            let mut worst_arith: f64 = 0.0;
            let (mut loss32, mut loss64): (f64, f64) = (0.0, 0.0);
            let mut skipped = 0;
            let mut fk_failures = 0;
            let (mut worst_cond, mut worst_conditioned, mut worst_ratio): (f64, f64, f64) = (0.0, 0.0, 0.0);
            let mut prng = tests::rng(29);
            let mut worst_end: f64 = 0.0;
            let (mut worst_model, mut worst_excess, mut model_failures): (f64, f64, usize) = (0.0, 0.0, 0);
            let (mut worst_mixed, mut worst_mixed_conditioned, mut worst_scaled): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for _ in 0..200 {
                let (x, u, ud) = tests::closed::random_state(&plan, &mut rng, tests::closed::reach(name));
                // Away from singularities: the loop equations' condition estimate below 100
                // (the functions refuse above 1e4 in f64, 60 in f32) and no joint faster than
                // 10 times the independent speeds (`|S| ≤ 10`: near a type-II singularity of
                // the five-bar the distal links turn 20 times faster than the actuators).
                let amplification = (0..N)
                    .map(|k| {
                        let mut e = vec![0.0; N];
                        e[k] = 1.0;
                        runtime::closed::noc::joint_rates(&plan, &x, &e)
                            .map_or(f64::INFINITY, |r| r.iter().fold(0.0f64, |m, v| m.max(v.abs())))
                    })
                    .fold(0.0f64, f64::max);
                if runtime::closed::noc::constraint_condition(&plan, &x) > 100.0
                    || amplification > 10.0
                {
                    skipped += 1;
                    continue;
                }
                // Assemble in f32 from the rounded independent coordinates, then compare at the
                // f64 assembly of the same (rounded) coordinates.
                let xi32: [f32; N] = core::array::from_fn(|k| x[plan.independent[k]] as f32);
                let Ok(x32) = s::forward_kinematics(&xi32, &to32::<NX>(&x)) else {
                    fk_failures += 1;
                    continue;
                };
                let xi: [f64; N] = core::array::from_fn(|k| xi32[k] as f64);
                let mixed_here: f64;
                let xr = d::forward_kinematics(&xi, &x.clone().try_into().unwrap()).unwrap();
                let assembly = rel(&to64(&x32), &xr);
                worst_assembly = worst_assembly.max(assembly);
                worst = worst.max(assembly);
                // The functions alone: the f32 module at the f64 assembly rounded to f32 (the
                // f64 module refuses that input: its loops are open by the rounding) against
                // the f64 module at the f64 assembly.
                {
                    let xa: [f32; NX] = to32::<NX>(&xr);
                    let (ua, uda) = (to32::<N>(&u), to32::<N>(&ud));
                    let ua64: [f64; N] = core::array::from_fn(|i| ua[i] as f64);
                    let uda64: [f64; N] = core::array::from_fn(|i| uda[i] as f64);
                    let t = d::inverse_dynamics(&xr, &ua64, &uda64).unwrap();
                    let t32 = s::inverse_dynamics(&xa, &ua, &uda).unwrap();
                    worst_function = worst_function.max(rel(&to64(&t32), &t));
                    // The same input in f64 arithmetic: the runtime's evaluator without its
                    // closure check (the f64 module refuses the rounded, slightly open loops).
                    let xa64: Vec<f64> = xa.iter().map(|&v| v as f64).collect();
                    let c = runtime::closed::noc::configuration(&plan, &xa64, false).unwrap();
                    let same = runtime::closed::noc::generalized_force(&plan, &c, &ua64, &uda64, true);
                    worst_arith = worst_arith.max(rel(&to64(&t32), &same));
                    // Against double-double at the same input: how many units of its own
                    // rounding each precision loses (f32: 2⁻²⁴, f64: 2⁻⁵³).
                    let dd = references::dd::closed_inverse_dynamics_dd(&plan, &xa64, &ua64, &uda64).unwrap();
                    loss32 = loss32.max(rel(&to64(&t32), &dd) / f32::EPSILON as f64 * 2.0);
                    loss64 = loss64.max(rel(&same, &dd) / f64::EPSILON * 2.0);
                    let m = d::mass_matrix(&xr).unwrap();
                    let m32 = s::mass_matrix(&xa).unwrap();
                    worst_function = worst_function.max(rel(&to64(&m32.concat()), &m.concat()));
                    // The mixed route: assembled in f64 (the f64 module's `forward_kinematics`),
                    // the functions in f32 at that assembly rounded.
                    mixed_here = rel(&to64(&t32), &t).max(rel(&to64(&m32.concat()), &m.concat()));
                    // The effort's scale: its terms `|I u̇| + |C u| + |γ|`, entrywise.
                    let z = [0.0; N];
                    let g = d::inverse_dynamics(&xr, &z, &z).unwrap();
                    let cu = d::inverse_dynamics(&xr, &ua64, &z).unwrap();
                    let scale = (0..N)
                        .map(|i| {
                            let iu: f64 = (0..N).map(|j| m[i][j] * uda64[j]).sum();
                            iu.abs() + (cu[i] - g[i]).abs() + g[i].abs()
                        })
                        .fold(0.0f64, f64::max);
                    let e = (0..N).map(|i| (t32[i] as f64 - t[i]).abs()).fold(0.0f64, f64::max);
                    worst_scaled = worst_scaled.max(e / scale);
                }
                worst_mixed = worst_mixed.max(mixed_here);
                let (u32_, ud32) = (to32::<N>(&u), to32::<N>(&ud));
                let ur: [f64; N] = core::array::from_fn(|i| u32_[i] as f64);
                let udr: [f64; N] = core::array::from_fn(|i| ud32[i] as f64);
                let tau = d::inverse_dynamics(&xr, &ur, &udr).unwrap();
                let tau32 = s::inverse_dynamics(&x32, &u32_, &ud32).unwrap();
                let m = d::mass_matrix(&xr).unwrap();
                let m32 = s::mass_matrix(&x32).unwrap();
                let here = rel(&to64(&tau32), &tau).max(rel(&to64(&m32.concat()), &m.concat()));
                // The same efforts for the mechanism the f32 module describes (its constants
                // rounded), in f64 arithmetic: the part of the error the f32 model makes.
                if let Some(t) = f32_model_inverse_dynamics(&plan, &xi, &xr, &ur, &udr) {
                    let e = rel(&t, &tau);
                    worst_model = worst_model.max(e);
                    worst_excess = worst_excess.max(rel(&to64(&tau32), &tau) - e);
                } else {
                    model_failures += 1;
                }
                worst = worst.max(here);
                worst_end = worst_end.max(here);
                // The problem's own condition (f64, no f32 involved): the largest relative
                // change of the efforts per unit relative change of the inputs (independent
                // coordinates, speeds, accelerations; the loops reassembled). Near a state of
                // vanishing effort (gravity and inertia cancelling) it is large, and rounding
                // the inputs to f32 alone moves the efforts by about `cond · 2⁻²⁴`.
                let h = 1e-7;
                let mut cond: f64 = 1.0;
                for _ in 0..6 {
                        let mut bump = |v: f64| v * (1.0 + if prng.random_bool(0.5) { h } else { -h });
                    let xp: [f64; N] = core::array::from_fn(|k| bump(xi[k]));
                    let up: [f64; N] = core::array::from_fn(|k| bump(ur[k]));
                    let udp: [f64; N] = core::array::from_fn(|k| bump(udr[k]));
                    if let Some(tp) = d::forward_kinematics(&xp, &xr)
                        .ok()
                        .and_then(|xp| d::inverse_dynamics(&xp, &up, &udp).ok())
                    {
                        cond = cond.max(rel(&tp, &tau) / h);
                    }
                }
                worst_cond = worst_cond.max(cond);
                if cond <= 100.0 {
                    worst_conditioned = worst_conditioned.max(here);
                    worst_mixed_conditioned = worst_mixed_conditioned.max(mixed_here);
                }
                // How far beyond the problem's own condition (in the inputs) the f32 code
                // loses: the f32 assembly and the f32 geometry constants open the loops by
                // about `cond(Φ_d) · 2⁻²⁴`, a perturbation the condition above leaves out
                // (a diagnostic for the figures; the bound asserted is the one below).
                let ratio = rel(&to64(&tau32), &tau) / (cond * f32::EPSILON as f64 / 2.0);
                worst_ratio = worst_ratio.max(ratio);
            }
            println!("{name}: f32 vs f64, worst relative error {worst:.1e}: assembly {worst_assembly:.1e}, functions at the f64 assembly rounded to f32 {worst_function:.1e}, of which f32 arithmetic (inverse dynamics against f64 at the same rounded input) {worst_arith:.1e}; worst error in units of rounding against double-double: f32 {loss32:.0}, f64 {loss64:.0} ({skipped} of 200 states skipped as near-singular; f32 assembly failed {fk_failures} times); end to end (f32 assembly, then the functions) {worst_end:.1e}; problem condition up to {worst_cond:.0}, worst error where it is ≤ 100: {worst_conditioned:.1e}; inverse-dynamics error at most {worst_ratio:.1} × cond × 2⁻²⁴");
            println!("{name}: the f32 model's constants alone (f64 arithmetic): {worst_model:.1e}; f32 inverse dynamics beyond that: {worst_excess:.1e} ({model_failures} failures); f64 assembly then f32 functions {worst_mixed:.1e} (problem condition ≤ 100: {worst_mixed_conditioned:.1e}; f32 inverse dynamics error relative to the effort's terms {worst_scaled:.1e})");
            assert!(skipped < 100, "{name}: {skipped}");
            assert!(fk_failures <= 4, "{name}: f32 assembly failed {fk_failures} of 200 times");
            // Closed loops assemble in f32 too (Newton to the f32 rounding floor of the loop
            // equations, whose error the loop's condition amplifies), which costs about a digit
            // more: 1e-3 (measured worst: the N-four-bar's assembly, 5.5e-5).
            assert!(worst < 10.0 * F32_TOLERANCE, "{name}: {worst:e}");
            // Assembled in f64 and evaluated in f32, the charter's target holds wherever the
            // problem itself is well conditioned (condition of the efforts in the inputs ≤ 100:
            // beyond that even exact f32 inputs lose `cond · 2⁻²⁴`), and relative to the
            // effort's terms everywhere.
            assert!(worst_mixed_conditioned <= 1e-5, "{name}: {worst_mixed_conditioned:e}");
            assert!(worst_scaled <= 1e-5, "{name}: {worst_scaled:e}");
        }
    )*};
}

#[test]
fn closed_loops_in_single_precision() {
    closed!(
        four_bar,
        five_bar_joints,
        spherical_five_bar,
        bricard,
        n_four_bar,
        tripod_3prs,
        andrews_squeezer
    );
}
