//! The NOC of a simple-platform parallel manipulator evaluated literally, as the lecture writes
//! it (docs/method.md, "Parallel manipulators: actuation matrix"; eqs. 49–72): the twist-shaping
//! matrix `T` of every body (`6r × n`), the twist rates `Ṫ u`, the extended matrices `M` and
//! `W` (`6r × 6r`) and the gravity wrench `w^G`, as dense `nalgebra` matrices, then
//! `I = TᵀMT`, `f = Tᵀ(M(T u̇ + Ṫ u) + W M T u − w^G)` and `τ = A⁻ᵀ f`.
//!
//! This is the parallel counterpart of [`crate::noc`] (the literal route for trees): the generic
//! numeric runtime in the form a reader can match to the equations, at the cost of dense
//! products. [`super::noc`] evaluates the same model in the cheap association (one Newton–Euler
//! wrench per body, projected leg by leg, closed forms for UPS legs) and is what the generator
//! turns into code; the two share only the kinematics (inverse kinematics, the leg Jacobians'
//! inverses, and the joint accelerations of `super::noc::leg_motion`), so they check each
//! other's dynamics. Every leg is taken by its generic chain here, closed-form UPS legs too.
//!
//! Conventions as in [`super::noc`]: base-frame components, `t_b = [ω_b; ċ_b]` (angular
//! velocity, velocity of the mass centre), `M_b = diag(I_b, m_b 1₃)` with `I_b` about the mass
//! centre in the base frame, `W_b = diag(CPM(ω_b), 0₃)`. Bodies are stacked leg by leg (the
//! massless ones of expanded U joints included) and the platform last.

// `!(a > b)` is deliberate throughout: it is true for NaN, so a NaN never passes a check.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use alloc::vec;

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

use super::PlatformMotion;
use super::noc::{self, ACTUATION_TOLERANCE, LegKin, Plan, leg_motion};
use crate::algebra::V;
use crate::drive::drive_effort;
use crate::model::JointKind;
use crate::scalar::{Singular, Site};
use crate::solve::{PIVOT_TOLERANCE, check_finite};

/// The literal terms of the NOC at one state `(x, u)`.
#[derive(Clone, Debug)]
pub struct Terms {
    /// `T` (`6r × n`): rows `6b .. 6b + 6` are body `b`'s twist `[ω_b; ċ_b]` per unit speed.
    pub t: DMatrix<f64>,
    /// `Ṫ u`: the bodies' twist rates at `u̇ = 0` (the lecture's `Ṫ` is needed only times `u`).
    pub td_u: DVector<f64>,
    /// The extended mass matrix `M = diag(M_b)` (eq. 5).
    pub m: DMatrix<f64>,
    /// The extended angular-velocity matrix `W = diag(W_b)` (eqs. 4, 6).
    pub w: DMatrix<f64>,
    /// The stacked gravity wrench `w^G`, `w^G_b = [0; m_b g]`.
    pub gravity: DVector<f64>,
    /// The leg joints' rate map `L` (`θ̇ = L u`, the lecture's `L_J = J_J⁻¹ T` stacked): three
    /// rows per leg (a two-joint leg's third row is its end joint or virtual column).
    pub l: DMatrix<f64>,
    /// The leg joints' accelerations at `u̇ = 0`, `L̇ u` (so `θ̈ = L u̇ + L̇ u`).
    pub ld_u: DVector<f64>,
    /// The actuation matrix `A` (`q̇ = A u`): the actuated rows of `L` (eqs. 66–67).
    pub a: DMatrix<f64>,
}

fn v3(v: V<f64>) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

fn m3(m: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|i, j| m[i][j])
}

/// The map `G` from `u` to the velocity of leg `lk`'s end point (the platform's angular
/// velocity for a spherical leg), base frame, `3 × n`.
fn end_map(motion: PlatformMotion, lk: &LegKin<f64>) -> DMatrix<f64> {
    match motion {
        // v_end = v + ω × arm = −CPM(arm) ω + v (a 1T2R platform's times its `S`, in `terms`).
        PlatformMotion::Pose | PlatformMotion::HeaveTilt { .. } => {
            let mut g = DMatrix::zeros(3, 6);
            g.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&(-v3(lk.arm).cross_matrix()));
            g.fixed_view_mut::<3, 3>(0, 3)
                .copy_from(&Matrix3::identity());
            g
        }
        PlatformMotion::Orientation { .. } => DMatrix::identity(3, 3),
        PlatformMotion::PlanarPoint { .. } => DMatrix::identity(3, 2),
        PlatformMotion::Translation { .. } => DMatrix::identity(3, 3),
        // A Schönflies carrier's Delta legs (`terms` does not take the shaft).
        PlatformMotion::Schoenflies { .. } => DMatrix::identity(3, 4),
        // v_end = v + ω × arm, ω = (0, 0, u₂): columns e_x, e_y, e_z × arm.
        PlatformMotion::PlanarPose { .. } => {
            let mut g = DMatrix::zeros(3, 3);
            g[(0, 0)] = 1.0;
            g[(1, 1)] = 1.0;
            g[(0, 2)] = -lk.arm[1];
            g[(1, 2)] = lk.arm[0];
            g
        }
    }
}

/// The platform's angular velocity and acceleration and the end point's velocity and
/// acceleration of every leg, from `u` and `u̇` (base frame).
fn end_motion(motion: PlatformMotion, lk: &LegKin<f64>, u: &[f64], ud: &[f64]) -> (V<f64>, V<f64>) {
    match motion {
        // A 1T2R platform's `u`, `u̇` arrive as its twist `t = S u` and rate (`terms`).
        PlatformMotion::Pose | PlatformMotion::HeaveTilt { .. } => {
            let (w, wd) = (v3([u[0], u[1], u[2]]), v3([ud[0], ud[1], ud[2]]));
            let (v, a) = (v3([u[3], u[4], u[5]]), v3([ud[3], ud[4], ud[5]]));
            let arm = v3(lk.arm);
            let ve = v + w.cross(&arm);
            let ae = a + wd.cross(&arm) + w.cross(&w.cross(&arm));
            (ve.into(), ae.into())
        }
        PlatformMotion::Orientation { .. } => ([u[0], u[1], u[2]], [ud[0], ud[1], ud[2]]),
        PlatformMotion::PlanarPoint { .. } => ([u[0], u[1], 0.0], [ud[0], ud[1], 0.0]),
        PlatformMotion::Translation { .. } | PlatformMotion::Schoenflies { .. } => {
            ([u[0], u[1], u[2]], [ud[0], ud[1], ud[2]])
        }
        PlatformMotion::PlanarPose { .. } => {
            let (w, wd) = (v3([0.0, 0.0, u[2]]), v3([0.0, 0.0, ud[2]]));
            let (v, a) = (v3([u[0], u[1], 0.0]), v3([ud[0], ud[1], 0.0]));
            let arm = v3(lk.arm);
            let ve = v + w.cross(&arm);
            let ae = a + wd.cross(&arm) + w.cross(&w.cross(&arm));
            (ve.into(), ae.into())
        }
    }
}

/// Number of bodies `r` (leg bodies and the platform).
/// Body `b`'s blocks: `M_b = diag(I_b, m_b 1₃)` (eq. 5) and its weight `m_b g` in `w^G`.
fn put_body(
    m: &mut DMatrix<f64>,
    gravity: &mut DVector<f64>,
    b: usize,
    inertia: Matrix3<f64>,
    mass: f64,
    g: Vector3<f64>,
) {
    m.fixed_view_mut::<3, 3>(6 * b, 6 * b).copy_from(&inertia);
    m.fixed_view_mut::<3, 3>(6 * b + 3, 6 * b + 3)
        .copy_from(&(Matrix3::identity() * mass));
    gravity
        .fixed_rows_mut::<3>(6 * b + 3)
        .copy_from(&(g * mass));
}

fn body_count(plan: &Plan) -> usize {
    plan.legs.iter().map(|lp| lp.joints.len()).sum::<usize>() + 1
}

/// `T`, `Ṫ u`, `M`, `W`, `w^G`, `L`, `L̇ u` and `A` at `(x, u)`.
///
/// A Schönflies platform (its six-joint shaft) is not taken: `Err` with `Site::Platform` and
/// an infinite condition estimate (tests/tests/schoenflies.rs checks it against the joint
/// coordinates and Lagrange's multipliers instead).
pub fn terms(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Terms, Singular> {
    if plan.motion.schoenflies() {
        return Err(Singular {
            site: Site::Platform,
            value: 0.0,
            condition_estimate: f64::INFINITY,
        });
    }
    check_finite(&[x, u])?;
    let n = plan.dof();
    let (pl, legs) = noc::kinematics(plan, x)?;
    let r = body_count(plan);
    let mut t = DMatrix::zeros(6 * r, n);
    let mut td_u = DVector::zeros(6 * r);
    let mut m = DMatrix::zeros(6 * r, 6 * r);
    let mut gravity = DVector::zeros(6 * r);
    let mut l = DMatrix::zeros(3 * plan.legs.len(), n);
    let mut ld_u = DVector::zeros(3 * plan.legs.len());
    let mut a = DMatrix::zeros(n, n);
    let g_world = v3(plan.gravity);
    let zero = vec![0.0; n];
    // A 1T2R platform: its twist map `S` (6 × 3), the twist `S u` and its rate at `u̇ = 0`,
    // `Ṡ u`, drive the 6-DOF pose's terms.
    let par = pl.parasitic.map(|p| {
        let s6 = DMatrix::from_fn(6, 3, |i, j| p.s[i][j]);
        (s6, p.twist(u), p.twist_rate(u, &zero))
    });
    let mut b = 0;
    for (li, (lp, lk)) in plan.legs.iter().zip(&legs).enumerate() {
        let frame = m3(&lk.frame);
        // L_J = J_J⁻¹ Fᵀ G (rows in joint order; J_J⁻¹ acts on leg-frame vectors).
        let g = match &par {
            Some((s6, _, _)) => end_map(plan.motion, lk) * s6,
            None => end_map(plan.motion, lk),
        };
        let jinv = Matrix3::from_fn(|i, j| lk.jinv[i][j]);
        let lj = jinv * frame.transpose() * &g;
        l.view_mut((3 * li, 0), (3, n)).copy_from(&lj);
        a.row_mut(li).copy_from(&lj.row(lp.actuated));
        // Twist rates at u̇ = 0: the joint accelerations L̇ u and the bodies' motions.
        let (ve, ae) = match &par {
            Some((_, t6, td6)) => end_motion(plan.motion, lk, t6, td6),
            None => end_motion(plan.motion, lk, u, &zero),
        };
        let (_, qdd0, motion) = leg_motion(lp, lk, ve, ae);
        for k in 0..3 {
            ld_u[3 * li + k] = qdd0[k];
        }
        for (k, mk) in motion.iter().enumerate().take(lp.joints.len()) {
            let (mass, _, inertia) = lp.bodies[k];
            let c = v3(lk.com[k]);
            // Body k's twist per unit joint rate (leg frame): joints 0..=k (eqs. 25–26).
            let mut tk = DMatrix::zeros(6, 3);
            for j in 0..=k {
                let e = v3(lk.e[j]);
                let (wcol, vcol) = match lp.joints[j] {
                    JointKind::Revolute => (e, e.cross(&(c - v3(lk.o[j])))),
                    JointKind::Prismatic => (Vector3::zeros(), e),
                };
                tk.fixed_view_mut::<3, 1>(0, j).copy_from(&(frame * wcol));
                tk.fixed_view_mut::<3, 1>(3, j).copy_from(&(frame * vcol));
            }
            t.view_mut((6 * b, 0), (6, n)).copy_from(&(tk * &lj));
            let alpha = frame * v3(mk.alpha);
            let acc = frame * v3(mk.accel_at(lk.o[k], lk.com[k]));
            td_u.fixed_rows_mut::<3>(6 * b).copy_from(&alpha);
            td_u.fixed_rows_mut::<3>(6 * b + 3).copy_from(&acc);
            let rot = frame * m3(&lk.rot[k]);
            let inertia = rot * m3(&inertia) * rot.transpose();
            put_body(&mut m, &mut gravity, b, inertia, mass, g_world);
            b += 1;
        }
    }
    // The platform: ω = u_ω, ċ = v + ω × r (r = R c, from the platform frame's origin, which
    // is the fixed centre for an orientation platform); a planar point platform is a point mass
    // moving with u.
    let (mass, com, inertia) = plan.platform;
    match plan.motion {
        PlatformMotion::PlanarPoint { .. } => {
            t[(6 * b + 3, 0)] = 1.0;
            t[(6 * b + 4, 1)] = 1.0;
            put_body(&mut m, &mut gravity, b, Matrix3::zeros(), mass, g_world);
        }
        PlatformMotion::Translation { .. } | PlatformMotion::Schoenflies { .. } => {
            // T_P = S = [0; 1₃]: ω = 0 and every point moves with u, so Ṫ u = 0.
            t.view_mut((6 * b + 3, 0), (3, 3))
                .copy_from(&Matrix3::identity());
            let rot = m3(&pl.rot);
            let inertia = rot * m3(&inertia) * rot.transpose();
            put_body(&mut m, &mut gravity, b, inertia, mass, g_world);
        }
        PlatformMotion::PlanarPose { .. } => {
            // T_P = S with the mass centre's velocity v + ω × r_c, ω = (0, 0, u₂):
            // Ṫ u = ω × (ω × r_c).
            let rot = m3(&pl.rot);
            let rc = rot * v3(com);
            t[(6 * b + 2, 2)] = 1.0;
            t[(6 * b + 3, 0)] = 1.0;
            t[(6 * b + 4, 1)] = 1.0;
            t[(6 * b + 3, 2)] = -rc[1];
            t[(6 * b + 4, 2)] = rc[0];
            let w = v3([0.0, 0.0, u[2]]);
            td_u.fixed_rows_mut::<3>(6 * b + 3)
                .copy_from(&w.cross(&w.cross(&rc)));
            let inertia = rot * m3(&inertia) * rot.transpose();
            put_body(&mut m, &mut gravity, b, inertia, mass, g_world);
        }
        PlatformMotion::HeaveTilt { .. } => {
            // T_P = T₆ S with T₆ = [1₃ 0; −CPM(r_c) 1₃]; Ṫ u = T₆ Ṡ u + [0; ω × (ω × r_c)].
            let Some((s6, t6, td6)) = &par else {
                return Err(Singular {
                    site: Site::Platform,
                    value: 0.0,
                    condition_estimate: f64::INFINITY,
                });
            };
            let rot = m3(&pl.rot);
            let rc = rot * v3(com);
            let mut tp = DMatrix::zeros(6, 6);
            tp.view_mut((0, 0), (3, 3)).copy_from(&Matrix3::identity());
            tp.view_mut((3, 0), (3, 3)).copy_from(&(-rc.cross_matrix()));
            tp.view_mut((3, 3), (3, 3)).copy_from(&Matrix3::identity());
            t.view_mut((6 * b, 0), (6, 3)).copy_from(&(&tp * s6));
            let w = v3([t6[0], t6[1], t6[2]]);
            let mut rate = &tp * DVector::from_column_slice(td6);
            let extra = w.cross(&w.cross(&rc));
            for i in 0..3 {
                rate[3 + i] += extra[i];
            }
            td_u.rows_mut(6 * b, 6).copy_from(&rate);
            let inertia = rot * m3(&inertia) * rot.transpose();
            put_body(&mut m, &mut gravity, b, inertia, mass, g_world);
        }
        PlatformMotion::Pose | PlatformMotion::Orientation { .. } => {
            let rot = m3(&pl.rot);
            let rc = rot * v3(com);
            t.view_mut((6 * b, 0), (3, 3))
                .copy_from(&Matrix3::identity());
            t.view_mut((6 * b + 3, 0), (3, 3))
                .copy_from(&(-rc.cross_matrix()));
            if let PlatformMotion::Pose = plan.motion {
                t.view_mut((6 * b + 3, 3), (3, 3))
                    .copy_from(&Matrix3::identity());
            }
            let w = v3([u[0], u[1], u[2]]);
            td_u.fixed_rows_mut::<3>(6 * b + 3)
                .copy_from(&w.cross(&w.cross(&rc)));
            let inertia = rot * m3(&inertia) * rot.transpose();
            put_body(&mut m, &mut gravity, b, inertia, mass, g_world);
        }
    }
    // W from the bodies' angular velocities ω = (T u)_ω.
    let twist = &t * DVector::from_column_slice(u);
    let mut w = DMatrix::zeros(6 * r, 6 * r);
    for b in 0..r {
        let omega = Vector3::new(twist[6 * b], twist[6 * b + 1], twist[6 * b + 2]);
        w.fixed_view_mut::<3, 3>(6 * b, 6 * b)
            .copy_from(&omega.cross_matrix());
    }
    Ok(Terms {
        t,
        td_u,
        m,
        w,
        gravity,
        l,
        ld_u,
        a,
    })
}

/// Every leg joint's drive effort (friction and rotor inertia) at `θ̇ = L u`, `θ̈ = L u̇ + L̇ u`,
/// mapped to the speeds by `Lᵀ`.
fn drive_force(plan: &Plan, terms: &Terms, u: &[f64], ud: &[f64]) -> DVector<f64> {
    let qd = &terms.l * DVector::from_column_slice(u);
    let qdd = &terms.l * DVector::from_column_slice(ud) + &terms.ld_u;
    let mut e = DVector::zeros(terms.l.nrows());
    for (li, lp) in plan.legs.iter().enumerate() {
        for (k, d) in lp.drives.iter().enumerate() {
            e[3 * li + k] = drive_effort(d, qd[3 * li + k], qdd[3 * li + k]);
        }
    }
    terms.l.transpose() * e
}

/// The generalized inertia `I = TᵀMT` (eq. 68's `I_P`) plus the leg joints' rotor inertias
/// `Lᵀ I_a L`.
pub fn generalized_inertia(plan: &Plan, terms: &Terms) -> DMatrix<f64> {
    let mut i = terms.t.transpose() * &terms.m * &terms.t;
    let mut ia = DVector::zeros(terms.l.nrows());
    for (li, lp) in plan.legs.iter().enumerate() {
        for (k, d) in lp.drives.iter().enumerate() {
            ia[3 * li + k] = d.armature;
        }
    }
    i += terms.l.transpose() * DMatrix::from_diagonal(&ia) * &terms.l;
    i
}

/// The generalized force `f = I u̇ + C u − γ + δ = Tᵀ(M(T u̇ + Ṫ u) + W M T u − w^G) + Lᵀ δ_J`.
pub fn generalized_force(plan: &Plan, terms: &Terms, u: &[f64], ud: &[f64]) -> DVector<f64> {
    let u_v = DVector::from_column_slice(u);
    let ud_v = DVector::from_column_slice(ud);
    let twist = &terms.t * &u_v;
    let twist_rate = &terms.t * &ud_v + &terms.td_u;
    let wrench = &terms.m * twist_rate + &terms.w * (&terms.m * twist) - &terms.gravity;
    terms.t.transpose() * wrench + drive_force(plan, terms, u, ud)
}

/// The LU factorization with partial pivoting (`nalgebra`) of the column-scaled actuation
/// matrix `Â = A D⁻¹` (`D` each column's unit-group reference, as [`super::noc::ColumnUnits`]
/// takes it but from the columns' largest magnitudes), or of `Âᵀ`; `Err(Actuation(i))` when the
/// smallest pivot falls below [`ACTUATION_TOLERANCE`] times the largest or 1 (the threshold of
/// [`super::noc::lu_solve`]). Returns the factorization and `D`.
type Lu = nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>;

fn actuation_lu(
    a: &DMatrix<f64>,
    transpose: bool,
    units: super::noc::ColumnUnits<'_>,
) -> Result<(Lu, DVector<f64>), Singular> {
    // Each column scaled by its unit group's reference.
    let amax: alloc::vec::Vec<f64> = a.column_iter().map(|c| c.amax()).collect();
    let scale = DVector::from_fn(a.ncols(), |j, _| {
        units.reference(&amax, j).max(f64::MIN_POSITIVE)
    });
    let scaled = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] / scale[j]);
    let lu = if transpose {
        scaled.transpose()
    } else {
        scaled
    }
    .lu();
    let d = lu.u().diagonal().map(f64::abs);
    // The largest entry of a group is 1 once scaled: a pivot is compared with 1 as well.
    let (big, small) = (d.max().max(1.0), d.min());
    if !(small > ACTUATION_TOLERANCE * big) {
        return Err(Singular {
            site: Site::Actuation(d.imin()),
            value: small,
            condition_estimate: if small > 0.0 {
                big / small
            } else {
                f64::INFINITY
            },
        });
    }
    Ok((lu, scale))
}

const SINGULAR_A: Singular = Singular {
    site: Site::Actuation(0),
    value: 0.0,
    condition_estimate: f64::INFINITY,
};

/// `τ = A⁻ᵀ f`: with `A = Â D`, `Aᵀ τ = f` is `Âᵀ τ = D⁻¹ f`.
fn solve_transposed(
    a: &DMatrix<f64>,
    f: &DVector<f64>,
    units: super::noc::ColumnUnits<'_>,
) -> Result<DVector<f64>, Singular> {
    let (lu, scale) = actuation_lu(a, true, units)?;
    lu.solve(&f.component_div(&scale)).ok_or(SINGULAR_A)
}

fn finite(v: DVector<f64>) -> Result<DVector<f64>, Singular> {
    check_finite(&[v.as_slice()])?;
    Ok(v)
}

/// Actuator efforts `τ = A⁻ᵀ (I u̇ + C u − γ + δ)` (N or N·m; gravity included), the literal
/// route to [`super::noc::inverse_dynamics`].
pub fn inverse_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<DVector<f64>, Singular> {
    check_finite(&[ud])?;
    let terms = terms(plan, x, u)?;
    let f = generalized_force(plan, &terms, u, ud);
    finite(solve_transposed(&terms.a, &f, plan.column_units())?)
}

/// The generalized inertia `I = TᵀMT + Lᵀ I_a L` of the speeds `u` at `x`.
pub fn mass_matrix(plan: &Plan, x: &[f64]) -> Result<DMatrix<f64>, Singular> {
    let terms = terms(plan, x, &vec![0.0; plan.dof()])?;
    let i = generalized_inertia(plan, &terms);
    check_finite(&[i.as_slice()])?;
    Ok(i)
}

/// Forward dynamics: `u̇` from `I u̇ = Aᵀ τ − (C u − γ + δ)|_{u̇=0}` (the rotor inertias are in
/// `I`), by `nalgebra`'s Cholesky factorization; `Err(MassMatrix(i))` when `I` is not
/// numerically positive definite (a pivot `≤ 1e-12 · max_k I_kk`, [`PIVOT_TOLERANCE`]).
pub fn forward_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    tau: &[f64],
) -> Result<DVector<f64>, Singular> {
    check_finite(&[tau])?;
    let n = plan.dof();
    let terms = terms(plan, x, u)?;
    let i = generalized_inertia(plan, &terms);
    let bias = generalized_force(plan, &terms, u, &vec![0.0; n]);
    let rhs = terms.a.transpose() * DVector::from_column_slice(tau) - bias;
    let scale = i.diagonal().amax();
    let chol = i.clone().cholesky().ok_or(Singular {
        site: Site::MassMatrix(0),
        value: 0.0,
        condition_estimate: f64::INFINITY,
    })?;
    let l = chol.l_dirty().diagonal();
    if let Some(k) = (0..n).find(|&k| !(l[k] * l[k] > PIVOT_TOLERANCE * scale)) {
        return Err(Singular {
            site: Site::MassMatrix(k),
            value: l[k] * l[k],
            condition_estimate: scale / (l[k] * l[k]),
        });
    }
    finite(chol.solve(&rhs))
}

/// The inertia in actuator space `A⁻ᵀ I A⁻¹` (the lecture's eq. 68), literally.
pub fn actuator_mass_matrix(plan: &Plan, x: &[f64]) -> Result<DMatrix<f64>, Singular> {
    let n = plan.dof();
    let terms = terms(plan, x, &vec![0.0; n])?;
    let i = generalized_inertia(plan, &terms);
    let (lu, scale) = actuation_lu(&terms.a, false, plan.column_units())?;
    // A⁻¹ = D⁻¹ Â⁻¹ (A = Â D).
    let ainv = lu.try_inverse().ok_or(SINGULAR_A)?;
    let ainv = DMatrix::from_fn(n, n, |r, c| ainv[(r, c)] / scale[r]);
    let out = ainv.transpose() * i * &ainv;
    let out = (&out + out.transpose()) * 0.5;
    check_finite(&[out.as_slice()])?;
    Ok(out)
}
