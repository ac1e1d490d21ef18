//! The telescopic R–U–P–U shaft of a Schönflies platform ([`LegKind::Shaft`]; a 4-axis Delta's
//! fourth axis): its constants [`ShaftPlan`], its inverse kinematics (`shaft_ik`), the map
//! `θ̇ = L u` of its six joint rates from the speeds `u = [v; ω]` (`shaft_rates`), and its part
//! of the generalized force (`shaft_force`) and inertia (`shaft_inertia`).
//!
//! The chain, from the base: the motor `R₀` about `e₀` (the base `z`, up or down), a U
//! (`R₁`, `R₂`: perpendicular axes meeting on the motor axis at `B`, both perpendicular to
//! it at home), the tube `P₃` along the motor axis at home, a second U (`R₄ ∥ R₂`, `R₅ ∥ R₁`
//! at home, centred at `T` on the motor axis: the yokes in phase), whose last body is the tool;
//! the tool meets the carrier in a revolute about `z` on the same line. The motor and tool
//! axes stay parallel (the carrier only translates), so the two U joints bend by equal and
//! opposite angles (`θ₄ = −θ₂`, `θ₅ = −θ₁` up to the axes' signs) and the tool's rotation is
//! the motor's, `R₀ R₁ R₂ R₂⁻¹ R₁⁻¹ = R₀`: the double Cardan is homokinetic. So the motor's
//! angle is `σθ` (`σ = e₀·z`), and `T` moves with the carrier (it is on the tool's axis).
//!
//! Inverse kinematics: `r = T − B`, the tube length `ℓ = |r|` (the prismatic `±(ℓ − ℓ₀)`),
//! then the U angles that turn the home direction onto `R₀ᵀ r/ℓ` (Paden–Kahan's two
//! intersecting axes). The U's gimbal lock (the tube perpendicular to the motor axis,
//! `cos θ₂ = |e₁ × R₀ᵀ r/ℓ| → 0`) is `Site::Leg`; `ℓ → 0` is `Site::Reach`.
//!
//! Rates: `θ̇₀ = σω`; the tube's three joints reach `T` with the motor's motion taken out,
//! `J (θ̇₁, θ̇₂, θ̇₃) = Ṫ − θ̇₀ e₀ × (T − O₀)`, `J = [e₁ × (T − O₁), e₂ × (T − O₂), e₃]`
//! (orthogonal columns of lengths `ℓ cos θ₂`, `ℓ`, `1`), `Ṫ = v`; then `θ̇₄ = −s₄ θ̇₂`,
//! `θ̇₅ = −s₅ θ̇₁`. Accelerations the same way with the chain's bias at `θ̈ = 0`. Every body's
//! twist is linear in `u`, so the NOC's projections `Lᵀ` apply unchanged.

use alloc::vec;
use alloc::vec::Vec;

use super::LEG_TOLERANCE;
use super::legs::{JointPos, LegKin};
use super::motion::{BodyMotion, chain};
use super::plan::{LegPlan, dot3, sub3};
use super::subproblems::two_axes;
use crate::algebra::{V, add, cross, cv, dot, inertia_quad, mtv, mv, rot, scale, sub, zero3};
use crate::drive::drive_effort;
use crate::model::{JointKind, Vec3};
use crate::scalar::{Real, Singular, Site};

#[cfg(doc)]
use crate::parallel::LegKind;

/// Gimbal-lock threshold of the shaft's U joints: the leg is singular when
/// `cos² θ₂ ≤ SHAFT_TOLERANCE` (the tube within about `1e-4` rad of perpendicular to the motor
/// axis; `J`'s columns are orthogonal, so the Hadamard ratio does not see it, but its first
/// column's length `ℓ cos θ₂` does: `LEG_TOLERANCE²`).
pub const SHAFT_TOLERANCE: f64 = LEG_TOLERANCE * LEG_TOLERANCE;

/// The constants of a shaft leg, in its leg frame `L` (the motor's frame at home).
#[derive(Clone, Debug)]
pub struct ShaftPlan {
    /// `σ = e₀·z` (±1): the motor turns by `σθ` when the tool turns by `θ` about `z`.
    pub sigma: f64,
    /// The tube's home direction `B → T` (unit).
    pub dir: Vec3,
    /// The tube's home length `ℓ₀ = |T − B|`.
    pub length: f64,
    /// The prismatic joint along (+1) or against (−1) `B → T`.
    pub slide: f64,
    /// `s₄ = e₄·e₂`, `s₅ = e₅·e₁` (±1): the second U's axes against the first's.
    pub s4: f64,
    /// See `s4`.
    pub s5: f64,
    /// `T − P` at home: the second U's centre from the tool's point (along the axis, so the
    /// same at every pose: the tool only turns about that axis).
    pub offset: Vec3,
}

fn sign(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

/// The shaft's constants (the geometry was checked by the leg's classification).
pub(super) fn shaft_plan(lp: &LegPlan) -> ShaftPlan {
    let e0_base = crate::model::mat_vec(&lp.frame.rotation, &lp.axes[0]);
    let r = sub3(&lp.points[4], &lp.points[1]);
    let l = dot3(&r, &r).sqrt();
    let dir = [r[0] / l, r[1] / l, r[2] / l];
    ShaftPlan {
        sigma: sign(e0_base[2]),
        dir,
        length: l,
        slide: sign(dot3(&lp.axes[3], &dir)),
        s4: sign(dot3(&lp.axes[4], &lp.axes[2])),
        s5: sign(dot3(&lp.axes[5], &lp.axes[1])),
        offset: sub3(&lp.points[4], &lp.end_home),
    }
}

/// The shaft's joint positions for the tool's point `target` (`L`) and the tool's angle
/// `(sin θ, cos θ)`.
pub(super) fn shaft_ik<R: Real>(
    lp: &LegPlan,
    sp: &ShaftPlan,
    k: usize,
    target: V<R>,
    tool: (R, R),
) -> Result<Vec<JointPos<R>>, Singular> {
    let (s0, c0) = (R::c(sp.sigma) * tool.0, tool.1);
    let t = add(target, cv(&sp.offset));
    let r = sub(t, cv(&lp.points[1]));
    let l2 = sp.length * sp.length;
    let rr = R::check(
        dot(r, r),
        R::c(R::tolerance(1e-12) * l2),
        R::c(l2),
        Site::Reach(k),
        false,
    )?;
    let l = rr.sqrt();
    let inv_l = R::c(1.0) / l;
    // The tube's direction in the motor's home frame.
    let dm = scale(inv_l, mtv(&rot(&lp.axes[0], s0, c0), r));
    // cos² θ₂ = |e₁ × dm|²: the U's gimbal lock.
    let m = cross(cv(&lp.axes[1]), dm);
    R::check(
        dot(m, m),
        R::c(R::tolerance(SHAFT_TOLERANCE)),
        R::c(1.0),
        Site::Leg(k),
        false,
    )?;
    let [a, b] = two_axes(
        &lp.axes[1],
        &lp.axes[2],
        cv(&sp.dir),
        dm,
        lp.sigma_u,
        k,
        false,
    )?;
    Ok(vec![
        JointPos::R(s0, c0),
        JointPos::R(a.0, a.1),
        JointPos::R(b.0, b.1),
        JointPos::P(R::c(sp.slide) * (l - R::c(sp.length))),
        JointPos::R(R::c(-sp.s4) * b.0, b.1),
        JointPos::R(R::c(-sp.s5) * a.0, a.1),
    ])
}

/// The map `θ̇ = L u` of the shaft's six joint rates from `u = [v; ω]`: row `i` is
/// `(l_i, λ_i)` with `θ̇_i = l_i·v_L + λ_i ω` (`v_L` the carrier's velocity in `L`).
pub(super) fn shaft_rates<R: Real>(sp: &ShaftPlan, lk: &LegKin<R>) -> [(V<R>, R); 6] {
    let sigma = R::c(sp.sigma);
    // The motor's column at T.
    let c0 = cross(lk.e[0], sub(lk.o[4], lk.o[0]));
    let tube: [(V<R>, R); 3] =
        core::array::from_fn(|i| (lk.jinv[i], -(sigma * dot(lk.jinv[i], c0))));
    let neg = |s: f64, (l, w): (V<R>, R)| (scale(R::c(-s), l), R::c(-s) * w);
    [
        (zero3(), sigma),
        tube[0],
        tube[1],
        tube[2],
        neg(sp.s4, tube[1]),
        neg(sp.s5, tube[0]),
    ]
}

/// The rates `L u` (`v_L`, `ω`).
fn apply<R: Real>(l: &[(V<R>, R); 6], v: V<R>, w: R) -> Vec<R> {
    l.iter().map(|(a, b)| dot(*a, v) + *b * w).collect()
}

/// The shaft's joint rates, accelerations and body motions for the carrier's velocity and
/// acceleration `v`, `a` (base frame) and the tool's `ω`, `ω̇`.
pub(super) fn shaft_motion<R: Real>(
    lp: &LegPlan,
    sp: &ShaftPlan,
    lk: &LegKin<R>,
    (v, w): (V<R>, R),
    (a, wd): (V<R>, R),
) -> (Vec<R>, Vec<R>, Vec<BodyMotion<R>>) {
    let l = shaft_rates(sp, lk);
    let (v_l, a_l) = (mtv(&lk.frame, v), mtv(&lk.frame, a));
    let qd = apply(&l, v_l, w);
    // The bias: T's acceleration on the tube with θ̈ = 0.
    let bias = chain(lp, lk, &qd, None);
    let bias_t = bias[3].accel_at(lk.o[3], lk.o[4]);
    let qdd0 = R::c(sp.sigma) * wd;
    let c0 = cross(lk.e[0], sub(lk.o[4], lk.o[0]));
    let rhs = sub(sub(a_l, scale(qdd0, c0)), bias_t);
    let t: [R; 3] = core::array::from_fn(|i| dot(lk.jinv[i], rhs));
    let qdd = vec![
        qdd0,
        t[0],
        t[1],
        t[2],
        R::c(-sp.s4) * t[1],
        R::c(-sp.s5) * t[0],
    ];
    let motion = chain(lp, lk, &qd, Some(&qdd));
    (qd, qdd, motion)
}

/// The shaft's part of the generalized force `f = I u̇ + C u − γ` (4 entries: `v`, then `ω`):
/// one Newton–Euler wrench per body, to the joints (`τ = Tᵀ w` by the chain), then `Lᵀ τ`.
/// `g`: gravity (base frame), zero for none.
pub(super) fn shaft_force<R: Real>(
    lp: &LegPlan,
    sp: &ShaftPlan,
    lk: &LegKin<R>,
    vel: (V<R>, R),
    acc: (V<R>, R),
    g: V<R>,
) -> [R; 4] {
    let (qd, qdd, bodies) = shaft_motion(lp, sp, lk, vel, acc);
    let g_l = mtv(&lk.frame, g);
    let mut tau = super::force::leg_efforts(lp, lk, &bodies, g_l);
    for k in 0..tau.len() {
        tau[k] = tau[k] + drive_effort(&lp.drives[k], qd[k], qdd[k]);
    }
    project(sp, lk, &tau)
}

/// `Lᵀ τ` (4 entries, base frame).
fn project<R: Real>(sp: &ShaftPlan, lk: &LegKin<R>, tau: &[R]) -> [R; 4] {
    let l = shaft_rates(sp, lk);
    let mut y = zero3::<R>();
    let mut w = R::c(0.0);
    for (k, (lv, lw)) in l.iter().enumerate() {
        // The motor's row has no v part.
        if k > 0 {
            y = add(y, scale(tau[k], *lv));
        }
        w = w + *lw * tau[k];
    }
    let y = mv(&lk.frame, y);
    [y[0], y[1], y[2], w]
}

/// The shaft's part of the generalized inertia (4 × 4, the upper triangle and its mirror):
/// `Σ_b T_bᵀ M_b T_b` with each body's twist per unit speed `T_b = Σ_i` (joint `i`'s twist
/// column) `L_i`, rotors included.
pub(super) fn shaft_inertia<R: Real>(lp: &LegPlan, sp: &ShaftPlan, lk: &LegKin<R>) -> [[R; 4]; 4] {
    let z = R::c(0.0);
    let l = shaft_rates(sp, lk);
    // L in the base frame's v components: column j < 3 of row i is (F l_i)_j.
    let lb: [[R; 4]; 6] = core::array::from_fn(|i| {
        let v = mv(&lk.frame, l[i].0);
        [v[0], v[1], v[2], l[i].1]
    });
    let mut out = [[z; 4]; 4];
    let n = lp.joints.len();
    for k in 0..n {
        let (mass, _, inertia) = lp.bodies[k];
        let massless = mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0);
        if massless {
            continue;
        }
        let c = lk.com[k];
        // Body k's twist per unit u_j at its mass centre (L frame): (ω_j, v_j).
        let cols: [(V<R>, V<R>); 4] = core::array::from_fn(|j| {
            let mut w = zero3::<R>();
            let mut v = zero3::<R>();
            for i in 0..=k {
                let s = lb[i][j];
                match lp.joints[i] {
                    JointKind::Revolute => {
                        w = add(w, scale(s, lk.e[i]));
                        v = add(v, scale(s, cross(lk.e[i], sub(c, lk.o[i]))));
                    }
                    JointKind::Prismatic => v = add(v, scale(s, lk.e[i])),
                }
            }
            (w, v)
        });
        for i in 0..4 {
            for j in i..4 {
                let v = R::c(mass) * dot(cols[i].1, cols[j].1)
                    + inertia_quad(&lk.rot[k], &inertia, cols[i].0, cols[j].0);
                out[i][j] = out[i][j] + v;
            }
        }
    }
    // The joints' rotors.
    for (k, d) in lp.drives.iter().enumerate() {
        if d.armature != 0.0 {
            for i in 0..4 {
                for j in i..4 {
                    out[i][j] = out[i][j] + R::c(d.armature) * lb[k][i] * lb[k][j];
                }
            }
        }
    }
    for i in 0..4 {
        for j in 0..i {
            out[i][j] = out[j][i];
        }
    }
    out
}

/// The shaft's row of the actuation matrix `A` (4 entries, base frame): row `actuated` of `L`
/// (the motor's: `(0, 0, 0, σ)`).
pub(super) fn shaft_row<R: Real>(lp: &LegPlan, sp: &ShaftPlan, lk: &LegKin<R>) -> Vec<R> {
    let (lv, lw) = shaft_rates(sp, lk)[lp.actuated];
    let v = mv(&lk.frame, lv);
    vec![v[0], v[1], v[2], lw]
}
