//! The closed form of a UPS leg (Khalil & Guegan, IEEE T-RO 20(4), 2004, §III: the joint rates
//! from the S centre's velocity, their eqs. (8)–(13); the dynamics projected on the S point,
//! eqs. (20)–(25)): its constants [`UpsPlan`], its configuration [`UpsKin`], the force it needs
//! at its S centre (`ups_force`, in place of steps 3–5) and its end-point inertia
//! (`ups_inertia`).

use super::plan::{LegPlan, cross3, dot3, sub3};
use crate::algebra::{M, V, add, cross, dot, mv, scale, sub};
use crate::model::{Mat3, Vec3, mat_vec};
use crate::scalar::Real;

/// The constants of the closed-form UPS leg (Khalil & Guegan, IEEE T-RO 20(4), 2004, §III;
/// derivation at `ups_force`). It applies when the U's two axes are perpendicular, its second
/// axis is perpendicular to the prismatic axis (so the three make the leg frame below) and the
/// U's cross is massless.
///
/// The leg frame `(t, e₁′, s)` is fixed in the cylinder: `s` the unit leg direction (U centre →
/// S centre), `e₁′` the U's second axis, `t = e₁′ × s`. With `e₀` the U's first (base-fixed)
/// axis, `c = e₀·s` and `d = ±√(1 − c²)` (the branch `sigma_u`), `e₀ = d t + c s`, so
/// `e₁′ = −(e₀ × s)/d` and `t = (e₀ − c s)/d`: the frame follows from `s` alone.
#[derive(Clone, Debug)]
pub struct UpsPlan {
    /// The U's first axis `e₀` (base frame, unit).
    pub e0: Vec3,
    /// The inertia of the leg's bodies after the U's cross (cylinder, piston, …) about the U
    /// centre at home length, `J₀ = Σ I_b + m_b (|c_b|² 1 − c_b c_bᵀ)` (leg frame; `c_b` a
    /// body's mass centre from the U centre, `I_b` its inertia about it).
    pub inertia: Mat3,
    /// Their first moment about the U centre at home length, `h₀ = Σ m_b c_b` (leg frame).
    pub moment: Vec3,
    /// The mass of the bodies that ride on the prismatic joint (their mass centres move by
    /// `δ = ρ − ρ_home` along `s`).
    pub sliding_mass: f64,
    /// Their first moment at home length, `Σ m_b c_b` over them (leg frame).
    pub sliding_moment: Vec3,
    /// The home leg length (the sliding bodies' mass centres are given there).
    pub length: f64,
}

/// `x` with the entries below `1e-14` of its largest set to zero (constants of the leg frame
/// that are zero but for the rounding of a rotation: they fold away in generated code).
fn snap(mut m: Mat3) -> Mat3 {
    let big = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    for v in m.iter_mut().flatten() {
        if v.abs() <= 1e-14 * big {
            *v = 0.0;
        }
    }
    m
}

/// The closed form's constants for a UPS leg, or `None` when its geometry is not covered
/// (see [`UpsPlan`]).
pub(super) fn ups_plan(lp: &LegPlan) -> Option<UpsPlan> {
    let (e0, e1) = (lp.axes[0], lp.axes[1]);
    let sh = sub3(&lp.end_home, &lp.u_centre);
    let sh = [sh[0] / lp.length, sh[1] / lp.length, sh[2] / lp.length];
    let massless = |k: usize| {
        let (m, _, i) = lp.bodies[k];
        m == 0.0 && i.iter().flatten().all(|&x| x == 0.0)
    };
    if dot3(&e0, &e1).abs() > 1e-12
        || dot3(&e1, &sh).abs() > 1e-12
        || !massless(0)
        || lp.actuated != 2
        // Joint drives (friction, rotor inertia) act at the leg joints: the generic route.
        || lp.drives.iter().any(|d| !d.is_none())
    {
        return None;
    }
    // The leg frame at home (L): t = (e₀ − c s)/d, e₁′ = s × t (= e₁), s.
    let c = dot3(&e0, &sh);
    let d = dot3(&cross3(&e0, &e1), &sh);
    let t = [
        (e0[0] - c * sh[0]) / d,
        (e0[1] - c * sh[1]) / d,
        (e0[2] - c * sh[2]) / d,
    ];
    let y = cross3(&sh, &t);
    // Leg-frame coordinates of an L vector: Bᵀ x with B = [t e₁′ s].
    let bt = snap([t, y, sh]);
    let to_leg = |x: &Vec3| mat_vec(&bt, x);
    // The bodies after the U's cross, merged about the U centre (`ups_force_leg`).
    let mut plan = UpsPlan {
        e0: [0.0; 3],
        inertia: [[0.0; 3]; 3],
        moment: [0.0; 3],
        sliding_mass: 0.0,
        sliding_moment: [0.0; 3],
        length: lp.length,
    };
    for k in (1..lp.bodies.len()).filter(|&k| !massless(k)) {
        let (mass, com, inertia) = lp.bodies[k];
        let h = &lp.homes[k];
        let q = snap(crate::model::mat_mul(&bt, &h.rotation));
        let isotropic = inertia[0][0] == inertia[1][1]
            && inertia[1][1] == inertia[2][2]
            && [inertia[0][1], inertia[0][2], inertia[1][2]] == [0.0; 3]
            && [inertia[1][0], inertia[2][0], inertia[2][1]] == [0.0; 3];
        let inertia = if isotropic {
            inertia
        } else {
            snap(crate::model::mat_mul(
                &crate::model::mat_mul(&q, &inertia),
                &crate::model::transpose(&q),
            ))
        };
        let rel = sub3(&h.apply(&com), &lp.u_centre);
        let c = snap([to_leg(&rel), [0.0; 3], [0.0; 3]])[0];
        // The parallel-axis theorem: I_b + m_b (|c|² 1 − c cᵀ).
        let c2 = dot3(&c, &c);
        for i in 0..3 {
            for j in 0..3 {
                let diagonal = if i == j { c2 } else { 0.0 };
                plan.inertia[i][j] += inertia[i][j] + mass * (diagonal - c[i] * c[j]);
            }
            plan.moment[i] += mass * c[i];
        }
        if k >= 2 {
            plan.sliding_mass += mass;
            for i in 0..3 {
                plan.sliding_moment[i] += mass * c[i];
            }
        }
    }
    plan.e0 = snap([mat_vec(&lp.frame.rotation, &e0), [0.0; 3], [0.0; 3]])[0];
    Some(plan)
}

/// The configuration of a closed-form UPS leg (base frame; see [`UpsPlan`]).
#[derive(Clone, Copy, Debug)]
pub struct UpsKin<R> {
    /// Leg length `ρ` (U centre to S centre).
    pub rho: R,
    /// `1/ρ`.
    pub inv_rho: R,
    /// `c/d`.
    pub cot: R,
    /// `1/d`.
    pub inv_d: R,
    /// The leg frame: `t`, `e₁′`, `s` (base frame, unit).
    pub t: V<R>,
    /// `e₁′`.
    pub e1: V<R>,
    /// `s`.
    pub s: V<R>,
}

/// The force `y` (base frame) that a closed-form UPS leg ([`UpsPlan`]) needs at its S centre to
/// move with it: `y = J_J⁻ᵀ τ_J`, the leg's part of `f` before `Gᵀ`, for the S centre's velocity
/// `v` and acceleration `a` (base frame) and gravity `g` — the same quantity as the generic
/// route's (chain recursion, adjugate inverse), in closed form (Khalil & Guegan, "Inverse and
/// direct dynamic modeling of Gough–Stewart robots", IEEE T-RO 20(4):754–762, 2004, §III:
/// the leg's joint rates from `v`, eqs. (8)–(13); its dynamics projected on the S point,
/// eqs. (20)–(25); here with the U's spin kept, as the U allows it).
///
/// Everything is resolved in the leg frame `(t, e₁′, s)` (x, y, z; fixed in the cylinder), in
/// which the U's first axis is `e₀ = (d, 0, c)`, the U normal `n = e₀ × e₁′ = (−c, 0, d)`, and
/// the S centre is at `ρ ẑ` from the U centre. With the leg's angular velocity `ω` (the
/// cylinder's and the piston's):
/// 1. Velocity, `v = ω × ρẑ + ρ̇ ẑ`: `v_x = ρ ω_y`, `v_y = −ρ ω_x`, `v_z = ρ̇`; the U admits no
///    rotation about `n`, `ω·n = 0`, so `ω_z = (c/d) ω_x` (the spin `θ̇₀ c`, `θ̇₀ = ω_x/d`).
/// 2. Acceleration, `a = α × ρẑ + ω × (ω × ρẑ) + 2ρ̇ ω × ẑ + ρ̈ ẑ`:
///    `a_x = ρ(α_y + ω_x ω_z) + 2ρ̇ ω_y`, `a_y = ρ(−α_x + ω_y ω_z) − 2ρ̇ ω_x`,
///    `a_z = ρ̈ − ρ(ω_x² + ω_y²)`; and `d/dt (ω·n) = 0` with `ṅ = θ̇₀ e₀ × n` gives
///    `α·n = θ̇₀ ω_y`, i.e. `α_z = (c/d) α_x + ω_x ω_y / d²`.
/// 3. One Newton–Euler wrench per body (`f_b = m_b (a_b − g)`, `n_b = I_b α + ω × I_b ω`, `I_b`
///    constant in the leg frame), `a_b = α × r_b + ω × (ω × r_b)` plus, for the bodies on the
///    prismatic joint, `ρ̈ ẑ + 2ρ̇ ω × ẑ`; `N = Σ n_b + r_b × f_b` (about the U centre) and
///    `F_z = Σ_{sliding} f_b·ẑ`. The bodies turn together, so the sums are taken once, by the
///    leg's inertia `J` about the U centre and its first moments (the parallel-axis theorem;
///    [`UpsPlan`]): `N = J α + ω × J ω − h × g + h_s × (ρ̈ ẑ + 2ρ̇ ω × ẑ)`,
///    `F_z = (α × h_s + ω × (ω × h_s))_z + m_s (ρ̈ − g_z)`, with `J`, `h` and `h_s` polynomials in
///    `δ = ρ − ρ_home` of constant coefficients.
/// 4. Joint efforts `τ₀ = e₀·N = d N_x + c N_z`, `τ₁ = e₁′·N = N_y`, `τ_P = ±F_z`; the leg
///    Jacobian's columns are `∂v/∂θ̇₀ = ρ e₀ × ẑ = −ρ d ŷ`, `∂v/∂θ̇₁ = ρ x̂`, `∂v/∂q̇_P = ±ẑ`, so
///    `y = J⁻ᵀ τ = (N_y/ρ, −(N_x + (c/d) N_z)/ρ, F_z)`, then `y_x t + y_y e₁′ + y_z s`.
pub(super) fn ups_force<R: Real>(up: &UpsPlan, uk: &UpsKin<R>, v: V<R>, a: V<R>, g: V<R>) -> V<R> {
    let to_leg = |x: V<R>| [dot(uk.t, x), dot(uk.e1, x), dot(uk.s, x)];
    let y = ups_force_leg(up, uk, to_leg(v), to_leg(a), to_leg(g));
    add(
        add(scale(y[0], uk.t), scale(y[1], uk.e1)),
        scale(y[2], uk.s),
    )
}

/// [`ups_force`] in the leg frame `(t, e₁, s)`: `v`, `a`, `g` and the result are components
/// along `t`, `e₁` and `s`.
fn ups_force_leg<R: Real>(up: &UpsPlan, uk: &UpsKin<R>, vl: V<R>, al: V<R>, gl: V<R>) -> V<R> {
    let ip = uk.inv_rho;
    // 1. ω and ρ̇.
    let wx = -(vl[1] * ip);
    let wy = vl[0] * ip;
    let w = [wx, wy, uk.cot * wx];
    let rd2 = R::c(2.0) * vl[2];
    // 2. α and ρ̈.
    let ax = w[1] * w[2] - (al[1] + rd2 * w[0]) * ip;
    let ay = (al[0] - rd2 * w[1]) * ip - w[0] * w[2];
    let alpha = [ax, ay, uk.cot * ax + w[0] * w[1] * (uk.inv_d * uk.inv_d)];
    let rdd = al[2] + uk.rho * (w[0] * w[0] + w[1] * w[1]);
    // 3. The bodies merged about the U centre, `δ = ρ − ρ_home` along ẑ for the sliding ones:
    //    J(δ) = J₀ + δ J₁ + δ² m_s (1 − ẑẑᵀ), J₁ = 2 h_{s,z} 1 − (h_s ẑᵀ + ẑ h_sᵀ) (at home);
    //    h = h₀ + m_s δ ẑ and h_s = h_{s,0} + m_s δ ẑ the first moments (all, sliding).
    let delta = uk.rho - R::c(up.length);
    let (ms, hs0) = (up.sliding_mass, up.sliding_moment);
    let j1 = [
        [2.0 * hs0[2], 0.0, -hs0[0]],
        [0.0, 2.0 * hs0[2], -hs0[1]],
        [-hs0[0], -hs0[1], 0.0],
    ];
    let j2 = [ms, ms, 0.0];
    let jm: M<R> = core::array::from_fn(|i| {
        core::array::from_fn(|k| {
            let quadratic = if i == k { j2[i] } else { 0.0 };
            R::c(up.inertia[i][k]) + delta * (R::c(j1[i][k]) + delta * R::c(quadratic))
        })
    });
    let along = |h: &Vec3| [R::c(h[0]), R::c(h[1]), R::c(h[2]) + R::c(ms) * delta];
    let (h, hs) = (along(&up.moment), along(&hs0));
    // ρ̈ ẑ + 2ρ̇ ω × ẑ (ω × ẑ = (ω_y, −ω_x, 0)): the sliding bodies' acceleration beyond the
    // cylinder's.
    let slide = [rd2 * w[1], -(rd2 * w[0]), rdd];
    // N = Σ I_b α + ω × I_b ω + r_b × m_b (a_b − g) = J α + ω × J ω − h × g + h_s × slide.
    let nsum = add(
        euler(&jm, up.diagonal(), w, alpha),
        sub(cross(hs, slide), cross(h, gl)),
    );
    // F_z = Σ_sliding m_b (a_b − g)·ẑ = (α × h_s + ω × (ω × h_s))_z + m_s (ρ̈ − g_z).
    let fz = (cross(alpha, hs)[2] + cross(w, cross(w, hs))[2]) + R::c(ms) * (rdd - gl[2]);
    // 4. y = J⁻ᵀ τ (leg frame).
    let yx = nsum[1] * ip;
    let yy = -((nsum[0] + uk.cot * nsum[2]) * ip);
    [yx, yy, fz]
}

/// The end-point inertia `Λ = J_J⁻ᵀ M_J J_J⁻¹` (base frame, exactly symmetric) of a
/// closed-form UPS leg: `y = Λ a` is [`ups_force`] at rest without gravity, linear in the S
/// centre's acceleration `a`, so column `j` of `Λ` in the leg frame is [`ups_force_leg`] of
/// `a = e_j` (the same closed form as the leg's inverse dynamics; its constants fold in a
/// generated module). Then `Λ = Q Λ_L Qᵀ` with `Q = [t e₁ s]`.
pub(super) fn ups_inertia<R: Real>(up: &UpsPlan, uk: &UpsKin<R>) -> M<R> {
    let z = R::c(0.0);
    let col: [V<R>; 3] = core::array::from_fn(|j| {
        let mut e = [z; 3];
        e[j] = R::c(1.0);
        ups_force_leg(up, uk, [z; 3], e, [z; 3])
    });
    // Λ_L[i][j] = col[j][i], its upper triangle mirrored.
    let ll = |i: usize, j: usize| if i <= j { col[j][i] } else { col[i][j] };
    let q = [uk.t, uk.e1, uk.s];
    let b: [V<R>; 3] = core::array::from_fn(|i| {
        add(
            add(scale(ll(i, 0), q[0]), scale(ll(i, 1), q[1])),
            scale(ll(i, 2), q[2]),
        )
    });
    let mut lam = [[z; 3]; 3];
    for r in 0..3 {
        for c in r..3 {
            lam[r][c] = q[0][r] * b[0][c] + q[1][r] * b[1][c] + q[2][r] * b[2][c];
            lam[c][r] = lam[r][c];
        }
    }
    lam
}

impl UpsPlan {
    /// Whether the leg's inertia `J(δ)` about the U centre is diagonal in the leg frame at
    /// every extension (its bodies' principal axes along the leg frame, the sliding ones'
    /// mass centres on the leg axis).
    fn diagonal(&self) -> bool {
        let j = &self.inertia;
        [j[0][1], j[0][2], j[1][2], j[1][0], j[2][0], j[2][1]] == [0.0; 6]
            && self.sliding_moment[0] == 0.0
            && self.sliding_moment[1] == 0.0
    }
}

/// Euler's equation `J α + ω × J ω`; for a diagonal `J` in the principal form
/// `J_x α_x + (J_z − J_y) ω_y ω_z`, … (so that a `J` symmetric about the leg axis, `J_x = J_y`,
/// leaves no `z` term of `ω × J ω` in generated code).
fn euler<R: Real>(j: &M<R>, diagonal: bool, w: V<R>, alpha: V<R>) -> V<R> {
    if !diagonal {
        return add(mv(j, alpha), cross(w, mv(j, w)));
    }
    let (jx, jy, jz) = (j[0][0], j[1][1], j[2][2]);
    [
        jx * alpha[0] + (jz - jy) * (w[1] * w[2]),
        jy * alpha[1] - (jz - jx) * (w[2] * w[0]),
        jz * alpha[2] + (jy - jx) * (w[0] * w[1]),
    ]
}
