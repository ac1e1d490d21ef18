//! The fixed items of generated modules, `codegen/templates/*.rs`, compiled here as modules of
//! their own: each template file is `include!`d into a module that defines, as a generated
//! module does, the constants, error types and kernels it is written around, plus the
//! stand-ins that generation replaces (tolerances, limits, `sqrt`/`sin_cos`/`atan2`). The
//! kernels are small invented mechanisms whose answers are known in closed form, so every
//! check compares against an independent value, not against the template itself.
//! (`codegen/templates/inertia_indices.rs` is compiled the same way by `tests/indices.rs`.)

#![allow(clippy::needless_range_loop)]

use nalgebra::{DMatrix, DVector};

fn sqrt(x: f64) -> f64 {
    x.sqrt()
}
fn sin_cos(x: f64) -> (f64, f64) {
    x.sin_cos()
}
fn atan2(y: f64, x: f64) -> f64 {
    y.atan2(x)
}

/// Error types as every platform and closed-loop module defines them.
macro_rules! error_types {
    () => {
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[allow(dead_code)]
        pub enum Site {
            Actuation(usize),
            Input,
        }
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Singular {
            pub site: Site,
            pub value: f64,
            pub condition_estimate: f64,
        }
        #[derive(Clone, Copy, Debug, PartialEq)]
        #[allow(dead_code)]
        pub struct NoConvergence {
            pub iterations: usize,
            pub residual: f64,
            pub stop: Stop,
        }
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        #[allow(dead_code)]
        pub enum Stop {
            Input,
            Guess,
            Singular,
            Stalled,
            Iterations,
            Branch,
        }
    };
}

/// `a x = b` by nalgebra's LU (the generated module has its straight-line LU).
fn solve<const N: usize>(a: &[[f64; N]; N], b: &[f64; N]) -> Option<[f64; N]> {
    let m = DMatrix::from_fn(N, N, |i, j| a[i][j]);
    let x = m.lu().solve(&DVector::from_column_slice(b))?;
    let mut out = [0.0; N];
    out.copy_from_slice(x.as_slice());
    Some(out)
}

/// `(q(x), A(x))` of a platform with `q(x)` given: `A = ∂q/∂du` by central differences
/// through `retract` (the kernels of a generated module compute it exactly).
fn parts<const NX: usize, const DOF: usize>(
    x: &[f64; NX],
    q: impl Fn(&[f64; NX]) -> [f64; DOF],
    retract: impl Fn(&[f64; NX], &[f64; DOF]) -> [f64; NX],
) -> ([f64; DOF], [[f64; DOF]; DOF]) {
    let mut a = [[0.0; DOF]; DOF];
    let h = 1e-7;
    for j in 0..DOF {
        let mut d = [0.0; DOF];
        d[j] = h;
        let qp = q(&retract(x, &d));
        d[j] = -h;
        let qm = q(&retract(x, &d));
        for i in 0..DOF {
            a[i][j] = (qp[i] - qm[i]) / (2.0 * h);
        }
    }
    (q(x), a)
}

/// A 6-DOF platform in pose coordinates `(p, quaternion)` whose "actuators" read the position
/// and twice the quaternion's vector part (sign of `w` positive).
mod pose {
    use super::{atan2, sin_cos, sqrt};
    error_types!();
    pub const NX: usize = 7;
    pub const DOF: usize = 6;
    const REVOLUTE: [bool; DOF] = [false, false, false, true, true, true];
    const QUATERNION: usize = 3;
    const HAS_POSITION: bool = true;
    const FK_TOLERANCE: f64 = 1e-12;
    const FK_MAX_ITERATIONS: usize = 50;

    pub fn q_of(x: &[f64; NX]) -> [f64; DOF] {
        let s = if x[3] < 0.0 { -2.0 } else { 2.0 };
        [x[0], x[1], x[2], s * x[4], s * x[5], s * x[6]]
    }
    fn fk_parts(x: &[f64; NX]) -> Result<([f64; DOF], [[f64; DOF]; DOF]), Singular> {
        Ok(super::parts(x, q_of, retract))
    }
    fn lu_solve(a: &[[f64; DOF]; DOF], b: &[f64; DOF]) -> Result<[f64; DOF], Singular> {
        super::solve(a, b).ok_or(Singular {
            site: Site::Actuation(0),
            value: 0.0,
            condition_estimate: f64::INFINITY,
        })
    }
    include!("../../codegen/templates/platform_retract_quaternion.rs");
    include!("../../codegen/templates/platform_newton.rs");
    pub fn retract_pub(x: &[f64; NX], du: &[f64; DOF]) -> [f64; NX] {
        retract(x, du)
    }
}

/// A planar point `(x, y)` whose two actuators read a bent image of it; the first is an
/// angle, compared modulo 2π.
mod planar {
    use super::{atan2, sin_cos};
    error_types!();
    pub const NX: usize = 2;
    pub const DOF: usize = 2;
    const REVOLUTE: [bool; DOF] = [true, false];
    const FK_TOLERANCE: f64 = 1e-12;
    const FK_MAX_ITERATIONS: usize = 50;

    pub fn q_of(x: &[f64; NX]) -> [f64; DOF] {
        let a = x[0] + 0.1 * x[1] * x[1];
        // Wrapped to (−π, π], as a kernel's angles are.
        [a.sin().atan2(a.cos()), x[1] + 0.1 * x[0] * x[0]]
    }
    fn fk_parts(x: &[f64; NX]) -> Result<([f64; DOF], [[f64; DOF]; DOF]), Singular> {
        Ok(super::parts(x, q_of, retract))
    }
    fn lu_solve(a: &[[f64; DOF]; DOF], b: &[f64; DOF]) -> Result<[f64; DOF], Singular> {
        super::solve(a, b).ok_or(Singular {
            site: Site::Actuation(0),
            value: 0.0,
            condition_estimate: f64::INFINITY,
        })
    }
    include!("../../codegen/templates/platform_retract_sum.rs");
    include!("../../codegen/templates/platform_newton.rs");
}

/// The actuator-space wrappers of a platform: kernels with a known `A` and `I`.
mod actuation {
    error_types!();
    pub const NX: usize = 3;
    pub const DOF: usize = 3;
    pub struct Params {
        pub scale: f64,
    }
    pub fn a_of(x: &[f64; NX]) -> [[f64; DOF]; DOF] {
        [
            [2.0 + x[0], 0.3, -0.1],
            [0.2, 1.5, 0.4 * x[1]],
            [-0.3, 0.1, 1.0 + x[2] * x[2]],
        ]
    }
    pub fn i_of(x: &[f64; NX], p: &Params) -> [[f64; DOF]; DOF] {
        let c = 0.1 * x[0];
        [
            [p.scale * 3.0, c, 0.2],
            [c, p.scale * 2.0, -0.1],
            [0.2, -0.1, p.scale * 1.5],
        ]
    }
    pub fn f_of(u: &[f64; DOF], ud: &[f64; DOF]) -> [f64; DOF] {
        [ud[0] + u[1], ud[1] - 2.0 * u[0], ud[2] + 0.5]
    }
    pub(super) fn id_parts(
        x: &[f64; NX],
        u: &[f64; DOF],
        ud: &[f64; DOF],
        _p: &Params,
    ) -> Result<([[f64; DOF]; DOF], [f64; DOF]), Singular> {
        Ok((a_of(x), f_of(u, ud)))
    }
    pub(super) fn gravity_parts(
        x: &[f64; NX],
        _p: &Params,
    ) -> Result<([[f64; DOF]; DOF], [f64; DOF]), Singular> {
        Ok((a_of(x), f_of(&[0.0; DOF], &[0.0; DOF])))
    }
    pub(super) fn coriolis_parts(
        x: &[f64; NX],
        u: &[f64; DOF],
        _p: &Params,
    ) -> Result<([[f64; DOF]; DOF], [f64; DOF]), Singular> {
        Ok((a_of(x), f_of(u, &[0.0; DOF])))
    }
    fn friction_parts(
        x: &[f64; NX],
        u: &[f64; DOF],
        _p: &Params,
    ) -> Result<([[f64; DOF]; DOF], [f64; DOF]), Singular> {
        Ok((a_of(x), [u[0], 0.0, -u[2]]))
    }
    type Matrix = [[f64; DOF]; DOF];
    /// `A`, `f`, `∂A/∂x_j`, `∂f/∂x = 0` and `∂f/∂u`, by hand from `a_of` and `f_of`.
    #[allow(clippy::type_complexity)]
    fn idd_parts(
        x: &[f64; NX],
        u: &[f64; DOF],
        ud: &[f64; DOF],
        _p: &Params,
    ) -> Result<(Matrix, [f64; DOF], [Matrix; DOF], Matrix, Matrix), Singular> {
        let mut da = [[[0.0; DOF]; DOF]; DOF];
        da[0][0][0] = 1.0;
        da[1][1][2] = 0.4;
        da[2][2][2] = 2.0 * x[2];
        let dfu = [[0.0, 1.0, 0.0], [-2.0, 0.0, 0.0], [0.0; DOF]];
        Ok((a_of(x), f_of(u, ud), da, [[0.0; DOF]; DOF], dfu))
    }
    pub const NBP: usize = 2;
    /// `F_b`: two parameters whose forces are `f_of(u, ud)` and `(u₀, 0, 1)`.
    pub fn fb_of(u: &[f64; DOF], ud: &[f64; DOF]) -> [[f64; NBP]; DOF] {
        let f = f_of(u, ud);
        [[f[0], u[0]], [f[1], 0.0], [f[2], 1.0]]
    }
    #[allow(clippy::type_complexity)]
    fn regressor_parts(
        x: &[f64; NX],
        u: &[f64; DOF],
        ud: &[f64; DOF],
    ) -> Result<(Matrix, [[f64; NBP]; DOF]), Singular> {
        Ok((a_of(x), fb_of(u, ud)))
    }
    pub(super) fn inertia_parts(x: &[f64; NX], p: &Params) -> Result<(Matrix, Matrix), Singular> {
        Ok((a_of(x), i_of(x, p)))
    }
    fn fail() -> Singular {
        Singular {
            site: Site::Actuation(0),
            value: 0.0,
            condition_estimate: f64::INFINITY,
        }
    }
    pub(super) fn lu_solve_t(
        a: &[[f64; DOF]; DOF],
        b: &[f64; DOF],
    ) -> Result<[f64; DOF], Singular> {
        let mut t = [[0.0; DOF]; DOF];
        for i in 0..DOF {
            for j in 0..DOF {
                t[i][j] = a[j][i];
            }
        }
        super::solve(&t, b).ok_or_else(fail)
    }
    pub(super) fn lu_inverse(a: &[[f64; DOF]; DOF]) -> Result<[[f64; DOF]; DOF], Singular> {
        let mut inv = [[0.0; DOF]; DOF];
        for c in 0..DOF {
            let mut e = [0.0; DOF];
            e[c] = 1.0;
            let x = super::solve(a, &e).ok_or_else(fail)?;
            for r in 0..DOF {
                inv[r][c] = x[r];
            }
        }
        Ok(inv)
    }
    include!("../../codegen/templates/platform_actuation.rs");
}

/// `platform_lanes.rs` over `actuation`'s kernels: two lanes, the kernels' `_lanes` versions
/// as a generated module's would be (each lane the scalar kernel; a lane with a NaN `x` is
/// its `Err(Site::Input)`), and a minimal `Lanes`.
mod actuation_lanes {
    pub use super::actuation::{DOF, NX, Params, Singular, Site};
    use super::actuation::{
        coriolis_parts, gravity_parts, id_parts, inertia_parts, lu_inverse, lu_solve_t,
    };
    pub const LANES: usize = 2;
    #[derive(Clone, Copy)]
    pub struct Lanes(pub [f64; LANES]);
    impl Lanes {
        fn splat(v: f64) -> Lanes {
            Lanes([v; LANES])
        }
    }
    impl core::ops::Add for Lanes {
        type Output = Lanes;
        fn add(self, o: Lanes) -> Lanes {
            Lanes([self.0[0] + o.0[0], self.0[1] + o.0[1]])
        }
    }
    impl core::ops::Mul for Lanes {
        type Output = Lanes;
        fn mul(self, o: Lanes) -> Lanes {
            Lanes([self.0[0] * o.0[0], self.0[1] * o.0[1]])
        }
    }
    type Lanes2<const N: usize> = [[f64; LANES]; N];
    type Status = [Result<(), Singular>; LANES];
    /// Each lane of `f` (a lane with a non-finite `x` is `Err(Site::Input)`), its two parts
    /// lane last, through the template's per-lane helpers.
    #[allow(clippy::type_complexity)]
    fn each<const R: usize>(
        x: &[[f64; LANES]; NX],
        f: impl Fn(usize, &[f64; NX]) -> Result<([[f64; DOF]; DOF], [[f64; R]; 1]), Singular>,
    ) -> (([Lanes2<DOF>; DOF], Lanes2<R>), Status) {
        let mut a = [[[0.0; LANES]; DOF]; DOF];
        let mut b = [[0.0; LANES]; R];
        let mut status = [Ok(()); LANES];
        let mut bad = [false; LANES];
        flag_non_finite(&mut bad, x);
        for (k, (st, bad)) in status.iter_mut().zip(bad).enumerate() {
            let xk = lane_of(x, k);
            let r = if bad {
                Err(Singular {
                    site: Site::Input,
                    value: xk
                        .iter()
                        .copied()
                        .find(|v| !v.is_finite())
                        .unwrap_or(f64::NAN),
                    condition_estimate: f64::INFINITY,
                })
            } else {
                f(k, &xk)
            };
            match r {
                Ok((ak, [bk])) => {
                    for (row, r) in a.iter_mut().zip(ak) {
                        put_lane(row, k, r);
                    }
                    put_lane(&mut b, k, bk);
                }
                Err(e) => *st = Err(e),
            }
        }
        ((a, b), status)
    }
    fn id_parts_lanes(
        x: &[[f64; LANES]; NX],
        u: &[[f64; LANES]; DOF],
        ud: &[[f64; LANES]; DOF],
        p: &Params,
    ) -> (([Lanes2<DOF>; DOF], Lanes2<DOF>), Status) {
        each(x, |k, xk| {
            id_parts(xk, &lane_of(u, k), &lane_of(ud, k), p).map(|(a, f)| (a, [f]))
        })
    }
    fn gravity_parts_lanes(
        x: &[[f64; LANES]; NX],
        p: &Params,
    ) -> (([Lanes2<DOF>; DOF], Lanes2<DOF>), Status) {
        each(x, |_, xk| gravity_parts(xk, p).map(|(a, f)| (a, [f])))
    }
    fn coriolis_parts_lanes(
        x: &[[f64; LANES]; NX],
        u: &[[f64; LANES]; DOF],
        p: &Params,
    ) -> (([Lanes2<DOF>; DOF], Lanes2<DOF>), Status) {
        each(x, |k, xk| {
            coriolis_parts(xk, &lane_of(u, k), p).map(|(a, f)| (a, [f]))
        })
    }
    /// `A` and `I` lane last (`I` row by row through `each`'s second part).
    fn inertia_parts_lanes(
        x: &[[f64; LANES]; NX],
        p: &Params,
    ) -> (([Lanes2<DOF>; DOF], [Lanes2<DOF>; DOF]), Status) {
        let ((a, _), status) = each::<DOF>(x, |_, xk| {
            inertia_parts(xk, p).map(|(a, _)| (a, [[0.0; DOF]]))
        });
        let mut i = [[[0.0; LANES]; DOF]; DOF];
        for k in 0..LANES {
            if let Ok((_, ik)) = inertia_parts(&lane_of(x, k), p) {
                for r in 0..DOF {
                    for c in 0..DOF {
                        i[r][c][k] = ik[r][c];
                    }
                }
            }
        }
        ((a, i), status)
    }
    /// `lu_solve_t` lane by lane, a failing lane marked, as a generated module's.
    fn lu_solve_t_lanes(
        a: &[Lanes2<DOF>; DOF],
        b: &Lanes2<DOF>,
        bad: &mut [bool; LANES],
    ) -> Lanes2<DOF> {
        let mut out = [[0.0; LANES]; DOF];
        for (k, bad) in bad.iter_mut().enumerate() {
            match lu_solve_t(&a.map(|row| lane_of(&row, k)), &lane_of(b, k)) {
                Ok(t) => put_lane(&mut out, k, t),
                Err(_) => *bad = true,
            }
        }
        out
    }
    /// `lu_inverse` lane by lane, a failing lane marked, as a generated module's.
    fn lu_inverse_lanes(a: &[Lanes2<DOF>; DOF], bad: &mut [bool; LANES]) -> [[Lanes; DOF]; DOF] {
        let mut out = [[Lanes::splat(0.0); DOF]; DOF];
        for (k, bad) in bad.iter_mut().enumerate() {
            match lu_inverse(&a.map(|row| lane_of(&row, k))) {
                Ok(inv) => {
                    for (to, from) in out.iter_mut().zip(inv) {
                        for (t, f) in to.iter_mut().zip(from) {
                            t.0[k] = f;
                        }
                    }
                }
                Err(_) => *bad = true,
            }
        }
        out
    }
    include!("../../codegen/templates/platform_lanes.rs");
}

/// A one-loop mechanism in joint coordinates `x = (θ, φ)`: `θ` independent, `φ` dependent
/// through `sin φ = ½ sin θ` (so `φ = asin(½ sin θ)` on the home branch).
mod closed {
    error_types!();
    pub const NX: usize = 2;
    pub const DOF: usize = 1;
    pub const INDEPENDENT: [usize; DOF] = [0];
    const STEP: [f64; DOF] = [0.2];
    const WRAP: [bool; NX] = [false, true];
    const FK_MAX_STAGES: usize = 64;
    const FK_MAX_STAGES_REAL: f64 = 64.0;
    const FK_MAX_ITERATIONS: usize = 50;
    const FK_TOLERANCE: f64 = 1e-12;
    const FULL_TOLERANCE: f64 = 1e-9;
    const STALL_TOLERANCE: f64 = 1e-12;
    pub struct Params {
        pub m: f64,
    }
    fn newton_step(x: &[f64; NX]) -> Result<([f64; NX], f64, f64), Singular> {
        // A kernel checks its inputs first.
        if !(x[0].is_finite() && x[1].is_finite()) {
            return Err(Singular {
                site: Site::Input,
                value: f64::NAN,
                condition_estimate: f64::INFINITY,
            });
        }
        let g = x[1].sin() - 0.5 * x[0].sin();
        let d = x[1].cos();
        if d.abs() < 1e-12 {
            return Err(Singular {
                site: Site::Actuation(0),
                value: d,
                condition_estimate: f64::INFINITY,
            });
        }
        Ok(([0.0, -g / d], g, g))
    }
    fn mass_matrix(x: &[f64; NX], p: &Params) -> Result<[[f64; DOF]; DOF], Singular> {
        Ok([[p.m * (1.0 + x[1] * x[1])]])
    }
    include!("../../codegen/templates/closed_actuation.rs");
    include!("../../codegen/templates/closed_kinematics.rs");
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn pose_forward_kinematics_meets_its_targets() {
    let home = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    // Targets: a pose built from a chosen rotation (axis, angle) and position; the actuators'
    // values follow from the definition of `q_of`.
    for (axis, angle, p) in [
        ([0.0, 0.0, 1.0f64], 0.3f64, [0.1, -0.2, 0.3]),
        ([1.0, 1.0, 0.0], -0.8, [0.0, 0.5, -0.1]),
        ([0.3, -0.5, 0.8], 1.2, [1.0, 1.0, 1.0]),
    ] {
        let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let (s, c) = (0.5 * angle).sin_cos();
        let want = [
            p[0],
            p[1],
            p[2],
            c,
            s * axis[0] / n,
            s * axis[1] / n,
            s * axis[2] / n,
        ];
        let q = pose::q_of(&want);
        let x = pose::forward_kinematics(&q, &home).expect("converges");
        assert!(max_abs_diff(&x, &want) < 1e-9, "{x:?} vs {want:?}");
        let unit = x[3] * x[3] + x[4] * x[4] + x[5] * x[5] + x[6] * x[6];
        assert!((unit - 1.0).abs() < 1e-14);
    }
    // Revolute targets count modulo 2π; non-finite inputs fail at once.
    let q = [0.0, 0.0, 0.0, 0.2 + 2.0 * std::f64::consts::PI, 0.0, 0.0];
    let x = pose::forward_kinematics(&q, &home).expect("converges");
    assert!(max_abs_diff(&pose::q_of(&x), &[0.0, 0.0, 0.0, 0.2, 0.0, 0.0]) < 1e-10);
    let bad = pose::forward_kinematics(&[f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0], &home);
    assert_eq!(bad.map_err(|e| e.iterations), Err(0));
    // `retract` adds the translation and keeps the quaternion unit.
    let r = pose::retract_pub(&home, &[0.0, 0.0, 0.2, 1.0, 2.0, 3.0]);
    assert!(max_abs_diff(&r[..3], &[1.0, 2.0, 3.0]) < 1e-15);
    assert!(max_abs_diff(&r[3..], &[0.1f64.cos(), 0.0, 0.0, 0.1f64.sin()]) < 1e-15);
}

#[test]
fn planar_forward_kinematics_meets_its_targets() {
    for want in [[0.3, -0.2], [-1.0, 0.7], [2.5, 0.1]] {
        let q = planar::q_of(&want);
        let x = planar::forward_kinematics(&q, &[0.0, 0.0]).expect("converges");
        assert!(max_abs_diff(&planar::q_of(&x), &q) < 1e-11, "{x:?}");
        assert!(max_abs_diff(&x, &want) < 1e-9, "{x:?} vs {want:?}");
    }
}

#[test]
fn platform_actuation_solves_with_a_transposed() {
    use actuation::*;
    let p = Params { scale: 1.3 };
    let (x, u, ud) = ([0.2, -0.4, 0.7], [0.5, -1.0, 0.3], [1.0, 2.0, -0.5]);
    let tau = inverse_dynamics(&x, &u, &ud, &p).expect("regular");
    // Aᵀ τ = f, checked by multiplication.
    let (a, f) = (a_of(&x), f_of(&u, &ud));
    for j in 0..DOF {
        let s: f64 = (0..DOF).map(|i| a[i][j] * tau[i]).sum();
        assert!((s - f[j]).abs() < 1e-13);
    }
    // The split wrappers solve Aᵀ τ = f of their kernels' forces.
    let zero = [0.0; DOF];
    let parts = [
        (gravity(&x, &p), f_of(&zero, &zero)),
        (coriolis(&x, &u, &p), f_of(&u, &zero)),
        (friction(&x, &u, &p), [u[0], 0.0, -u[2]]),
    ];
    for (tau, f) in parts {
        let tau = tau.expect("regular");
        for j in 0..DOF {
            let s: f64 = (0..DOF).map(|i| a[i][j] * tau[i]).sum();
            assert!((s - f[j]).abs() < 1e-13);
        }
    }
    // A⁻ᵀ I A⁻¹ by nalgebra's inverse.
    let am = DMatrix::from_fn(DOF, DOF, |i, j| a[i][j]);
    let im = DMatrix::from_fn(DOF, DOF, |i, j| i_of(&x, &p)[i][j]);
    let ai = am.try_inverse().expect("invertible");
    let want = ai.transpose() * im * &ai;
    let got = actuator_mass_matrix(&x, &p).expect("regular");
    for i in 0..DOF {
        for j in 0..DOF {
            assert!((got[i][j] - want[(i, j)]).abs() < 1e-13 * want.amax());
            assert_eq!(got[i][j], got[j][i]);
        }
    }
    // The regressor: Aᵀ Y = F_b, checked by multiplication, column by column.
    let y = regressor(&x, &u, &ud).expect("regular");
    let fb = fb_of(&u, &ud);
    for c in 0..NBP {
        for j in 0..DOF {
            let s: f64 = (0..DOF).map(|i| a[i][j] * y[i][c]).sum();
            assert!((s - fb[j][c]).abs() < 1e-13, "column {c}, row {j}");
        }
    }
}

#[test]
fn platform_inverse_dynamics_derivatives_match_differences() {
    use actuation::*;
    let p = Params { scale: 1.0 };
    let (x, u, ud) = ([0.3, -0.7, 0.4], [0.5, -1.2, 0.8], [0.1, 0.9, -0.6]);
    let (dx, du) = inverse_dynamics_derivatives(&x, &u, &ud, &p).expect("regular");
    let h = 1e-6;
    for j in 0..DOF {
        let moved = |v: &[f64; DOF], s: f64| {
            let mut w = *v;
            w[j] += s;
            w
        };
        let tx = |s| inverse_dynamics(&moved(&x, s), &u, &ud, &p).unwrap();
        let tu = |s| inverse_dynamics(&x, &moved(&u, s), &ud, &p).unwrap();
        let (xp, xm, up, um) = (tx(h), tx(-h), tu(h), tu(-h));
        for i in 0..DOF {
            let (fx, fu) = ((xp[i] - xm[i]) / (2.0 * h), (up[i] - um[i]) / (2.0 * h));
            assert!(
                (dx[i][j] - fx).abs() < 1e-7,
                "∂τ{i}/∂x{j}: {} vs {fx}",
                dx[i][j]
            );
            assert!(
                (du[i][j] - fu).abs() < 1e-7,
                "∂τ{i}/∂u{j}: {} vs {fu}",
                du[i][j]
            );
        }
    }
}

#[test]
fn closed_assembly_follows_the_branch() {
    use closed::*;
    let p = Params { m: 2.0 };
    for theta in [0.1, 1.0, 2.5, -3.0] {
        let x = forward_kinematics(&[theta], &[0.0, 0.0]).expect("assembles");
        let phi = (0.5 * f64::sin(theta)).asin();
        assert!((x[0] - theta).abs() == 0.0);
        assert!(
            (x[1] - phi).abs() < 1e-12,
            "θ = {theta}: {x:?} vs φ = {phi}"
        );
    }
    // The other branch (φ near π) stays on its own branch when guessed there.
    let guess = [0.0, std::f64::consts::PI];
    let x = forward_kinematics(&[0.5], &guess).expect("assembles");
    assert!((x[1] - (std::f64::consts::PI - (0.5 * 0.5f64.sin()).asin())).abs() < 1e-12);
    // The actuator-space functions.
    assert_eq!(inverse_kinematics(&[0.4, 0.1]), Ok([0.4]));
    assert_eq!(
        inverse_kinematics(&[f64::INFINITY, 0.1]).map_err(|e| e.site),
        Err(Site::Input)
    );
    assert_eq!(actuator_rates(&[0.4, 0.1], &[3.0]), Ok([3.0]));
    assert_eq!(
        actuator_rates(&[0.4, 0.1], &[f64::NAN]).map_err(|e| e.site),
        Err(Site::Input)
    );
    assert_eq!(actuator_mass_matrix(&[0.4, 0.5], &p), Ok([[2.0 * 1.25]]));
    assert_eq!(
        forward_kinematics(&[f64::NAN], &[0.0, 0.0]).map_err(|e| e.iterations),
        Err(0)
    );
}

/// The `_lanes` wrappers give each lane the scalar wrapper's result, bit for bit, and a
/// failing lane its own `Err` beside a regular one.
#[test]
fn platform_lanes_are_the_scalar_wrappers_lane_by_lane() {
    use actuation::*;
    use actuation_lanes::*;
    let p = Params { scale: 1.3 };
    let states = [
        ([0.2, -0.4, 0.7], [0.5, -1.0, 0.3], [1.0, 2.0, -0.5]),
        ([f64::NAN, 0.1, 0.0], [0.0; 3], [0.0; 3]),
        ([-0.3, 0.9, -0.2], [-0.7, 0.4, 1.1], [0.0, -1.0, 2.5]),
    ];
    for pair in [[0, 1], [2, 0], [1, 2]] {
        type State = ([f64; 3], [f64; 3], [f64; 3]);
        let col = |f: fn(&State) -> [f64; 3]| -> [[f64; LANES]; 3] {
            core::array::from_fn(|i| core::array::from_fn(|k| f(&states[pair[k]])[i]))
        };
        let (x, u, ud) = (col(|s| s.0), col(|s| s.1), col(|s| s.2));
        let (tau, st) = inverse_dynamics_lanes(&x, &u, &ud, &p);
        let (g, gs) = gravity_lanes(&x, &p);
        let (c, cs) = coriolis_lanes(&x, &u, &p);
        let (m, ms) = actuator_mass_matrix_lanes(&x, &p);
        for (k, &s) in pair.iter().enumerate() {
            let (xk, uk, udk) = &states[s];
            let v = |a: &[[f64; LANES]; DOF]| -> [f64; DOF] { core::array::from_fn(|i| a[i][k]) };
            let text = |r: &dyn std::fmt::Debug| format!("{r:?}");
            let mk: [[f64; DOF]; DOF] = core::array::from_fn(|i| v(&m[i]));
            if s == 1 {
                // The kernels' `Err` of that lane (the scalar stand-ins do not test inputs).
                for status in [st[k], gs[k], cs[k], ms[k]] {
                    assert!(matches!(
                        status,
                        Err(Singular {
                            site: Site::Input,
                            ..
                        })
                    ));
                }
                continue;
            }
            assert_eq!(
                text(&st[k].map(|()| v(&tau))),
                text(&inverse_dynamics(xk, uk, udk, &p))
            );
            assert_eq!(text(&gs[k].map(|()| v(&g))), text(&gravity(xk, &p)));
            assert_eq!(text(&cs[k].map(|()| v(&c))), text(&coriolis(xk, uk, &p)));
            assert_eq!(
                text(&ms[k].map(|()| mk)),
                text(&actuator_mass_matrix(xk, &p))
            );
        }
    }
}
