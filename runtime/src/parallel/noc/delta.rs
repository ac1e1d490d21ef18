//! The closed form of a Delta leg: a revolute crank whose elbow carries the equivalent rod of a
//! parallelogram (one rod of twice a rod's mass and transverse inertia, no spin inertia; see
//! docs/spec.md, "Parallelograms"), on a translational platform. Its constants [`DeltaPlan`],
//! its configuration [`DeltaKin`], the force it needs at its platform point (`delta_force`, in
//! place of steps 3–5 of the generic route) and its end-point inertia (`delta_inertia`).
//!
//! The leg is a RUS leg as the spec expands it (crank, a U at the elbow `E`, the rod to the S at
//! the platform point `P`), and the runtime keeps that chain for everything else (joint
//! positions, the literal route, run-time drives). But the rod has no inertia about its own
//! axis, so the U's spin of it carries none, and its motion is that of the pair: with
//! `r = P − E` (`|r| = L`) and `d = r/L`, its angular velocity is `ω = d × ṙ / L` (no spin),
//! `ω̇ = d × r̈ / L`. The leg's only Jacobian is the scalar `s = d·j` with `j = e₀ × (E − O)`
//! (`Ė = q̇ j`): `q̇ = d·Ṗ / s`, and the leg is singular where `s` vanishes (the arm and the rod
//! in one plane with the motor axis' normal: the elbow circle tangent to the rod's sphere).

use super::plan::{LegPlan, cross3, dot3, sub3};
use crate::algebra::{M, V, add, cross, cv, dot, mtv, mv, rot, scale, sub};
use crate::model::{Vec3, mat_mul, mat_vec, transpose};
use crate::scalar::{Real, Singular, Site};

/// The constants of a Delta leg, in the leg frame `L` (the crank's frame at home).
#[derive(Clone, Debug)]
pub struct DeltaPlan {
    /// The crank axis `e₀` (unit) and a point `O` on it.
    pub e0: Vec3,
    /// A point on the crank axis.
    pub o: Vec3,
    /// The elbow `E` at home, relative to `O`.
    pub elbow: Vec3,
    /// `|e₀ × (E − O)|`: the elbow circle's radius, the scale of the leg's test.
    pub radius: f64,
    /// The crank's inertia about its axis, `e₀ᵀ I e₀ + m |r⊥|²`.
    pub crank_inertia: f64,
    /// The crank's mass times its mass centre relative to `O` at home.
    pub crank_moment: Vec3,
    /// The rod length `L`.
    pub length: f64,
    /// The rod's mass.
    pub rod_mass: f64,
    /// The rod's mass centre along it from `E`, as a fraction of `L`.
    pub rod_com: f64,
    /// The rod's transverse inertia about its mass centre.
    pub rod_inertia: f64,
}

/// The constants of a Delta leg, or `None` when the leg is not one: a RUS leg whose crank is
/// actuated, whose U cross is massless, whose rod has its mass centre on the line from the U
/// centre to the S centre and an inertia with no part about that line (`I⊥ (1 − d dᵀ)`), and
/// whose joints have no drives (those take the generic route).
pub(super) fn delta_plan(lp: &LegPlan) -> Option<DeltaPlan> {
    if lp.joints.len() != 3 || lp.actuated != 0 || lp.drives.iter().any(|d| !d.is_none()) {
        return None;
    }
    let (m1, _, i1) = lp.bodies[1];
    if m1 != 0.0 || i1.iter().flatten().any(|&x| x != 0.0) {
        return None;
    }
    let l = lp.length;
    let r = sub3(&lp.end_home, &lp.u_centre);
    let d = [r[0] / l, r[1] / l, r[2] / l];
    // The rod: mass centre on the rod line, inertia I⊥ (1 − d dᵀ) in L at home.
    let (mr, com, ib) = lp.bodies[2];
    let h = &lp.homes[2];
    let c = sub3(&h.apply(&com), &lp.u_centre);
    let rho = dot3(&c, &d);
    let off = cross3(&c, &d);
    if dot3(&off, &off).sqrt() > 1e-12 * l {
        return None;
    }
    let il = mat_mul(&mat_mul(&h.rotation, &ib), &transpose(&h.rotation));
    let it = 0.5 * (il[0][0] + il[1][1] + il[2][2]);
    for a in 0..3 {
        for b in 0..3 {
            let want = it * (f64::from(u8::from(a == b)) - d[a] * d[b]);
            if (il[a][b] - want).abs() > 1e-12 * it.abs().max(f64::MIN_POSITIVE) {
                return None;
            }
        }
    }
    // The crank (its frame is L at home).
    let e0 = lp.axes[0];
    let o = lp.points[0];
    let (mc, cc, ic) = lp.bodies[0];
    let rc = sub3(&cc, &o);
    let perp = cross3(&e0, &rc);
    let elbow = sub3(&lp.u_centre, &o);
    let j = cross3(&e0, &elbow);
    Some(DeltaPlan {
        e0,
        o,
        elbow,
        radius: dot3(&j, &j).sqrt(),
        crank_inertia: dot3(&e0, &mat_vec(&ic, &e0)) + mc * dot3(&perp, &perp),
        crank_moment: [mc * rc[0], mc * rc[1], mc * rc[2]],
        length: l,
        rod_mass: mr,
        rod_com: rho / l,
        rod_inertia: it,
    })
}

/// The configuration of a Delta leg (leg frame `L`).
#[derive(Clone, Copy, Debug)]
pub struct DeltaKin<R> {
    /// The rod direction `d = (P − E)/L`.
    pub d: V<R>,
    /// `j = e₀ × (E − O)`: the elbow's velocity per unit crank rate.
    pub j: V<R>,
    /// `e₀ × j`: the elbow's centripetal acceleration per unit squared crank rate.
    pub ej: V<R>,
    /// `1/s`, `s = d·j` the leg Jacobian's scalar.
    pub inv_s: R,
    /// The crank's mass moment `m r` turned with the crank.
    pub moment: V<R>,
}

/// The configuration of leg `k` from its crank's `(sin, cos)` and its platform point `p` (`L`);
/// with `check`, the leg's test: `|s| > LEG_TOLERANCE · radius` (`Site::Leg(k)`).
pub(super) fn delta_kin<R: Real>(
    dp: &DeltaPlan,
    k: usize,
    sc: (R, R),
    p: V<R>,
    check: bool,
) -> Result<DeltaKin<R>, Singular> {
    let r0 = rot(&dp.e0, sc.0, sc.1);
    let arm = mv(&r0, cv(&dp.elbow));
    let e = add(cv(&dp.o), arm);
    let d = scale(R::c(1.0 / dp.length), sub(p, e));
    let e0 = cv::<R>(&dp.e0);
    let j = cross(e0, arm);
    let s = dot(d, j);
    let s = if check {
        let h = dp.radius;
        R::check(
            s,
            R::c(R::tolerance(super::LEG_TOLERANCE) * h),
            R::c(h),
            Site::Leg(k),
            true,
        )?
    } else {
        s
    };
    Ok(DeltaKin {
        d,
        j,
        ej: cross(e0, j),
        inv_s: R::c(1.0) / s,
        moment: mv(&r0, cv(&dp.crank_moment)),
    })
}

/// The force `y` (base frame) that a Delta leg needs at its platform point to move with it,
/// the leg's part of `f` (the generic route's `J_J⁻ᵀ τ_J`), for the point's velocity `v` and
/// acceleration `a` and gravity `g` (base frame; `frame` the rotation of `L`). In `L`:
/// 1. `q̇ = d·v / s`, `Ė = q̇ j`, `ṙ = v − Ė`.
/// 2. `|r|² = L²` twice differentiated, `r·(a − Ë) + |ṙ|² = 0` with `Ë = q̈ j + q̇² e₀ × j`:
///    `q̈ = (d·a − q̇² d·(e₀ × j) + |ṙ|²/L) / s`; `r̈ = a − Ë`.
/// 3. The rod's wrench: `f = m (Ë + κ r̈ − g)` (`κ L` its mass centre from `E`),
///    `n = I⊥ ω̇ = I⊥ d × r̈ / L` (`ω` and `ω̇` are across `d`, so `ω × I ω = 0`).
/// 4. Its power on `ċ = Ė + κ ṙ`, `ω = d × ṙ / L`: `f·Ė + F·ṙ` with `F = κ f + n × d / L`
///    (`n × d = I⊥ (r̈ − (d·r̈) d) / L`, `d` a unit vector), so
///    `F` on `v` and `j·(f − F)` on the crank; the crank's own effort `J q̈ − e₀·(m r × g)`.
/// 5. `y = F + (d/s) τ₀`, `τ₀` the crank's total effort (`q̇ = (d/s)·v`).
pub(super) fn delta_force<R: Real>(
    dp: &DeltaPlan,
    dk: &DeltaKin<R>,
    frame: &M<R>,
    v: V<R>,
    a: V<R>,
    g: V<R>,
) -> V<R> {
    let (v, a, g) = (mtv(frame, v), mtv(frame, a), mtv(frame, g));
    mv(frame, delta_force_leg(dp, dk, v, a, g))
}

/// [`delta_force`] in the leg frame.
fn delta_force_leg<R: Real>(dp: &DeltaPlan, dk: &DeltaKin<R>, v: V<R>, a: V<R>, g: V<R>) -> V<R> {
    let il = R::c(1.0 / dp.length);
    let qd = dot(dk.d, v) * dk.inv_s;
    let rd = sub(v, scale(qd, dk.j));
    let qdd = (dot(dk.d, a) - qd * qd * dot(dk.d, dk.ej) + dot(rd, rd) * il) * dk.inv_s;
    let ee = add(scale(qdd, dk.j), scale(qd * qd, dk.ej));
    let rdd = sub(a, ee);
    let kappa = R::c(dp.rod_com);
    let f = scale(R::c(dp.rod_mass), sub(add(ee, scale(kappa, rdd)), g));
    // n × d / L with n = I⊥ d × r̈ / L and |d| = 1: (d × r̈) × d = r̈ − (d·r̈) d.
    let across = sub(rdd, scale(dot(dk.d, rdd), dk.d));
    let big_f = add(
        scale(kappa, f),
        scale(R::c(dp.rod_inertia) * il * il, across),
    );
    let crank = R::c(dp.crank_inertia) * qdd - dot(cv(&dp.e0), cross(dk.moment, g));
    let tau = crank + dot(dk.j, sub(f, big_f));
    add(big_f, scale(tau * dk.inv_s, dk.d))
}

/// The end-point inertia `Λ` (base frame, exactly symmetric) of a Delta leg: `y = Λ a` is
/// [`delta_force`] at rest without gravity, so column `j` of `Λ` in `L` is `delta_force_leg` of
/// `a = e_j`; then `Λ = F Λ_L Fᵀ`.
pub(super) fn delta_inertia<R: Real>(dp: &DeltaPlan, dk: &DeltaKin<R>, frame: &M<R>) -> M<R> {
    let z = R::c(0.0);
    let col: [V<R>; 3] = core::array::from_fn(|j| {
        let mut e = [z; 3];
        e[j] = R::c(1.0);
        delta_force_leg(dp, dk, [z; 3], e, [z; 3])
    });
    let ll = |i: usize, j: usize| if i <= j { col[j][i] } else { col[i][j] };
    // B = Λ_L Fᵀ (rows), then Λ = F B.
    let b: [V<R>; 3] = core::array::from_fn(|i| {
        let row = [ll(i, 0), ll(i, 1), ll(i, 2)];
        mv(frame, row)
    });
    let mut lam = [[z; 3]; 3];
    for r in 0..3 {
        for c in r..3 {
            lam[r][c] = frame[r][0] * b[0][c] + frame[r][1] * b[1][c] + frame[r][2] * b[2][c];
            lam[c][r] = lam[r][c];
        }
    }
    lam
}
