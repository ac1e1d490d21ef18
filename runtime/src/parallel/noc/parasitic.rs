//! Parasitic motion of a 1T2R platform ([`PlatformMotion::HeaveTilt`]: a 3-PRS or 3-RPS
//! head): the full pose from the task coordinates `x = [pz, α, β]` by the legs' constraints,
//! and the twist map `t = [ω; v] = S(x) u` with its rate `ṫ = S u̇ + Ṡ u` (docs/method.md,
//! "Parasitic motion").
//!
//! Leg `i` keeps its S centre `cᵢ = p + R sᵢ` in the plane `Πᵢ` through `bᵢ` with normal `nᵢ`
//! (the plane of its revolute joint): `hᵢ = nᵢ·(p + R sᵢ − bᵢ) = 0`, with
//! `R = Rz(γ)·Ry(β)·Rx(α)·R_home`. Given `(pz, α, β)` the three `hᵢ` are solved for the
//! parasitic `y = (px, py, γ)` by [`PARASITIC_ITERATIONS`] Newton steps from their home
//! values, `y ← y − K⁻¹ h(y)` with `K` (rows `[nᵢx, nᵢy, (rᵢ × nᵢ)_z]`, `rᵢ = R sᵢ`) inverted
//! by its adjugate: a singular `K` is `Site::Platform` (the constraints do not fix the
//! parasitic motion), a residual beyond [`PARASITIC_TOLERANCE`] is `Site::Reach(i)`.
//!
//! Differentiating `hᵢ` with `ω = γ̇ e_z + β̇ e_y' + α̇ e_x''` (`e_y' = Rz e_y`,
//! `e_x'' = Rz Ry e_x`) and `v = (ṗx, ṗy, ż)`: `nᵢ·(v + ω × rᵢ) = 0`, i.e.
//! `K (ṗx, ṗy, γ̇) = −B u` with rows `Bᵢ = [nᵢz, mᵢ·e_x'', mᵢ·e_y']`, `mᵢ = rᵢ × nᵢ`: the
//! parasitic rates are `P u`, `P = −K⁻¹ B`, and `S`'s columns follow. Once more:
//! `nᵢ·(a + ω̇ × rᵢ + ω × (ω × rᵢ)) = 0` with `ω̇ = S_ω u̇ + ω̇_vp`,
//! `ω̇_vp = γ̇ β̇ e_z × e_y' + α̇ (γ̇ e_z + β̇ e_y') × e_x''` (the parametrization's velocity
//! products), so `Ṡ u = [c_γ e_z + ω̇_vp; (c_x, c_y, 0)]` with
//! `K (c_x, c_y, c_γ) = −(mᵢ·ω̇_vp + nᵢ·(ω × (ω × rᵢ)))ᵢ`.
//!
//! The symmetric 3-PRS has the parasitic motion in closed form (Carretero, Podhorodeski,
//! Nahon & Gosselin, ASME J. Mech. Des. 122(1), 2000: `γ` from the tilts, then `px`, `py`;
//! Bonev's zero-torsion result: in tilt-and-torsion angles its torsion is zero); the Newton
//! steps here serve any P-R-S or R-P-S legs, symmetric or not.

use super::plan::{LegPlan, Plan};
use crate::algebra::{M, V, add, cm, cross, cv, dot, mm, mv, scale};
use crate::parallel::{LegKind, PlatformMotion};
use crate::scalar::{Real, Singular, Site};

/// Newton steps of the parasitic motion's solve: a fixed count, because a generated module
/// unrolls them. The error falls quadratically from home; six steps reach the `f64` floor from
/// tilts to 0.3 rad (the parasitic motion is second order in the tilts).
pub const PARASITIC_ITERATIONS: usize = 6;

/// The parasitic solve has converged when every constraint `|hᵢ|` is within this fraction of
/// the platform's radius (its largest `|sᵢ|`); otherwise the pose is `Site::Reach(i)`.
pub const PARASITIC_TOLERANCE: f64 = 1e-9;

/// The parasitic motion's constant data: each leg's plane normal `nᵢ` (base frame), its
/// offset `nᵢ·bᵢ`, and the S centre `sᵢ` in the platform frame.
fn constraint(lp: &LegPlan) -> (crate::model::Vec3, f64, crate::model::Vec3) {
    // The revolute joint's axis and point (in L), to the base frame.
    let r = match lp.kind {
        LegKind::PlanarRp => 0,
        _ => 1,
    };
    let n = crate::model::mat_vec(&lp.frame.rotation, &lp.axes[r]);
    let b = lp.frame.apply(&lp.points[r]);
    (n, n[0] * b[0] + n[1] * b[1] + n[2] * b[2], lp.end_platform)
}

/// The twist map of a 1T2R platform at a configuration: `t = S u`, `ṫ = S u̇ + Ṡ u`.
#[derive(Clone, Copy, Debug)]
pub struct Parasitic<R> {
    /// The parasitic components `(px, py, γ)`.
    pub y: [R; 3],
    /// `S`, 6 × 3: rows `ω` then `v` (base frame), columns `ż, α̇, β̇`.
    pub s: [[R; 3]; 6],
    /// `P = −K⁻¹ B`: the parasitic rates `(ṗx, ṗy, γ̇) = P u`.
    p: [[R; 3]; 3],
    /// Columns of `K⁻¹` (`K⁻¹ d = Σᵢ dᵢ kᵢ`).
    kinv: [V<R>; 3],
    /// The S centres from the platform origin, `rᵢ = R sᵢ` (base frame).
    r: [V<R>; 3],
    /// The plane normals `nᵢ` (base frame).
    n: [V<R>; 3],
    /// `rᵢ × nᵢ`.
    m: [V<R>; 3],
    /// `e_x'' = Rz Ry e_x` (α̇'s axis) and `e_y' = Rz e_y` (β̇'s axis).
    ex: V<R>,
    ey: V<R>,
}

/// `Rz(γ) a` from `(sin γ, cos γ)`.
fn rz<R: Real>(s: R, c: R, a: V<R>) -> V<R> {
    [c * a[0] - s * a[1], s * a[0] + c * a[1], a[2]]
}

/// The constraints `h`, the arms `rᵢ`, the adjugate columns of `K`, its determinant and its
/// Hadamard bound, and `(sin γ, cos γ)`.
type Eval<R> = ([R; 3], [V<R>; 3], [V<R>; 3], R, R, (R, R));

/// [`Eval`] at `y`, for the arms `r'ᵢ = Ry Rx R_home sᵢ` before the turn about `z`.
fn evaluate<R: Real>(y: &[R; 3], pz: R, rp: &[V<R>; 3], n: &[V<R>; 3], off: &[f64; 3]) -> Eval<R> {
    let (s, c) = y[2].sin_cos();
    let p = [y[0], y[1], pz];
    let r: [V<R>; 3] = core::array::from_fn(|i| rz(s, c, rp[i]));
    let h: [R; 3] = core::array::from_fn(|i| dot(n[i], p) + dot(n[i], r[i]) - R::c(off[i]));
    // Rows of K: [n_x, n_y, (r × n)_z].
    let k: [V<R>; 3] =
        core::array::from_fn(|i| [n[i][0], n[i][1], r[i][0] * n[i][1] - r[i][1] * n[i][0]]);
    // Columns of adj(K): K⁻¹ = [k1 × k2, k2 × k0, k0 × k1] / det.
    let adj = [cross(k[1], k[2]), cross(k[2], k[0]), cross(k[0], k[1])];
    let det = dot(k[0], adj[0]);
    let hn = (dot(k[0], k[0]) * dot(k[1], k[1]) * dot(k[2], k[2])).sqrt();
    (h, r, adj, det, hn, (s, c))
}

/// A 1T2R platform's rotation `R` (platform → base), origin, and twist map.
pub type FullPose<R> = (M<R>, V<R>, Parasitic<R>);

/// The full pose of a 1T2R platform from `x = [pz, α, β]`: the rotation `R`, the origin, and
/// the twist map ([`Parasitic`]).
pub fn parasitic<R: Real>(plan: &Plan, x: &[R]) -> Result<FullPose<R>, Singular> {
    let PlatformMotion::HeaveTilt { rotation, xy } = plan.motion else {
        return Err(Singular {
            site: Site::Platform,
            value: 0.0,
            condition_estimate: f64::INFINITY,
        });
    };
    let z = R::c(0.0);
    let one = R::c(1.0);
    let (sa, ca) = x[1].sin_cos();
    let (sb, cb) = x[2].sin_cos();
    let rx: M<R> = [[one, z, z], [z, ca, -sa], [z, sa, ca]];
    let ry: M<R> = [[cb, z, sb], [z, one, z], [-sb, z, cb]];
    let m0 = mm(&ry, &mm(&rx, &cm(&rotation)));
    let mut n = [[z; 3]; 3];
    let mut off = [0.0; 3];
    let mut rp = [[z; 3]; 3];
    let mut radius: f64 = 0.0;
    for (i, lp) in plan.legs.iter().enumerate().take(3) {
        let (ni, oi, si) = constraint(lp);
        n[i] = cv(&ni);
        off[i] = oi;
        rp[i] = mv(&m0, cv(&si));
        radius = radius.max(libm::sqrt(si[0] * si[0] + si[1] * si[1] + si[2] * si[2]));
    }
    let pz = x[0];
    let mut y = [R::c(xy[0]), R::c(xy[1]), z];
    let tol_det = |hn: R| R::c(R::tolerance(super::LEG_TOLERANCE)) * hn;
    for _ in 0..PARASITIC_ITERATIONS {
        let (h, _, adj, det, hn, _) = evaluate(&y, pz, &rp, &n, &off);
        let det = R::check(det, tol_det(hn), hn, Site::Platform, true)?;
        let inv = one / det;
        // y ← y − K⁻¹ h, K⁻¹ h = Σᵢ hᵢ adjᵢ / det.
        for a in 0..3 {
            let d = h[0] * adj[0][a] + h[1] * adj[1][a] + h[2] * adj[2][a];
            y[a] = y[a] - d * inv;
        }
    }
    let (h, r, adj, det, hn, (sg, cg)) = evaluate(&y, pz, &rp, &n, &off);
    let tol = R::tolerance(PARASITIC_TOLERANCE) * radius.max(1e-3);
    for (i, hi) in h.iter().enumerate() {
        R::check(
            R::c(tol * tol) - *hi * *hi,
            z,
            R::c(tol * tol),
            Site::Reach(i),
            false,
        )?;
    }
    let det = R::check(det, tol_det(hn), hn, Site::Platform, true)?;
    let inv = one / det;
    let kinv = [scale(inv, adj[0]), scale(inv, adj[1]), scale(inv, adj[2])];
    let rot: M<R> = core::array::from_fn(|i| {
        let col = |j: usize| rz(sg, cg, [m0[0][j], m0[1][j], m0[2][j]])[i];
        [col(0), col(1), col(2)]
    });
    let ex = rz(sg, cg, [cb, z, -sb]);
    let ey = [-sg, cg, z];
    let m: [V<R>; 3] = core::array::from_fn(|i| cross(r[i], n[i]));
    // B rows [n_z, m·e_x'', m·e_y'], P = −K⁻¹ B.
    let b: [V<R>; 3] = core::array::from_fn(|i| [n[i][2], dot(m[i], ex), dot(m[i], ey)]);
    let p: [[R; 3]; 3] = core::array::from_fn(|a| {
        core::array::from_fn(|j| {
            -(kinv[0][a] * b[0][j] + kinv[1][a] * b[1][j] + kinv[2][a] * b[2][j])
        })
    });
    // S: ω column j = P₂ⱼ e_z + δⱼ₁ e_x'' + δⱼ₂ e_y'; v column j = (P₀ⱼ, P₁ⱼ, δⱼ₀).
    let mut s = [[z; 3]; 6];
    for j in 0..3 {
        let mut w = [z, z, p[2][j]];
        if j > 0 {
            let e = if j == 1 { ex } else { ey };
            w = add(w, e);
        }
        s[0][j] = w[0];
        s[1][j] = w[1];
        s[2][j] = w[2];
        s[3][j] = p[0][j];
        s[4][j] = p[1][j];
        s[5][j] = if j == 0 { one } else { z };
    }
    let origin = [y[0], y[1], pz];
    Ok((
        rot,
        origin,
        Parasitic {
            y,
            s,
            p,
            kinv,
            r,
            n,
            m,
            ex,
            ey,
        },
    ))
}

/// The full pose of a 1T2R platform, `[px, py, pz, qw, qx, qy, qz]`: the origin with the
/// parasitic `px`, `py`, and the unit quaternion `qz(γ) ⊗ qy(β) ⊗ qx(α) ⊗ q_home` of
/// `R = Rz(γ)·Ry(β)·Rx(α)·R_home` (`q_home` with `qw ≥ 0`), from the half angles, so that no
/// branch is taken.
pub fn parasitic_pose<R: Real>(plan: &Plan, x: &[R]) -> Result<[R; 7], Singular> {
    let PlatformMotion::HeaveTilt { rotation, .. } = plan.motion else {
        return Err(Singular {
            site: Site::Platform,
            value: 0.0,
            condition_estimate: f64::INFINITY,
        });
    };
    let (_, origin, par) = parasitic(plan, x)?;
    let half = R::c(0.5);
    let (sa, ca) = (x[1] * half).sin_cos();
    let (sb, cb) = (x[2] * half).sin_cos();
    let (sg, cg) = (par.y[2] * half).sin_cos();
    let h = crate::model::matrix_quaternion(&rotation);
    let s = if h[0] < 0.0 { -1.0 } else { 1.0 };
    let h: [R; 4] = core::array::from_fn(|i| R::c(s * h[i]));
    let z = R::c(0.0);
    let q = qmul(
        &[cg, z, z, sg],
        &qmul(&[cb, z, sb, z], &qmul(&[ca, sa, z, z], &h)),
    );
    Ok([origin[0], origin[1], origin[2], q[0], q[1], q[2], q[3]])
}

/// Hamilton product `a ⊗ b` of quaternions `[w, x, y, z]`.
fn qmul<R: Real>(a: &[R; 4], b: &[R; 4]) -> [R; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

impl<R: Real> Parasitic<R> {
    /// `t = S u` (`[ω; v]`).
    pub fn twist(&self, u: &[R]) -> [R; 6] {
        core::array::from_fn(|i| self.s[i][0] * u[0] + self.s[i][1] * u[1] + self.s[i][2] * u[2])
    }

    /// `ṫ = S u̇ + Ṡ u`.
    pub fn twist_rate(&self, u: &[R], ud: &[R]) -> [R; 6] {
        let mut t = self.twist(ud);
        let w = self.twist(u);
        let w = [w[0], w[1], w[2]];
        let gd = self.p[2][0] * u[0] + self.p[2][1] * u[1] + self.p[2][2] * u[2];
        let (ad, bd) = (u[1], u[2]);
        let z = R::c(0.0);
        let ez = [z, z, R::c(1.0)];
        // ω̇_vp = γ̇ β̇ e_z × e_y' + α̇ (γ̇ e_z + β̇ e_y') × e_x''.
        let wzy = [bd * self.ey[0], bd * self.ey[1], gd + bd * self.ey[2]];
        let vp = add(
            scale(gd * bd, cross(ez, self.ey)),
            scale(ad, cross(wzy, self.ex)),
        );
        let d: [R; 3] = core::array::from_fn(|i| {
            dot(self.m[i], vp) + dot(self.n[i], cross(w, cross(w, self.r[i])))
        });
        // (c_x, c_y, c_γ) = −K⁻¹ d.
        let c: V<R> = core::array::from_fn(|a| {
            -(d[0] * self.kinv[0][a] + d[1] * self.kinv[1][a] + d[2] * self.kinv[2][a])
        });
        t[0] = t[0] + vp[0];
        t[1] = t[1] + vp[1];
        t[2] = t[2] + vp[2] + c[2];
        t[3] = t[3] + c[0];
        t[4] = t[4] + c[1];
        t
    }

    /// `Sᵀ f₆`: a generalized force of the twist `[ω; v]` to the speeds `u`.
    pub fn project(&self, f6: &[R]) -> alloc::vec::Vec<R> {
        (0..3)
            .map(|j| {
                let mut a = R::c(0.0);
                for i in 0..6 {
                    a = a + self.s[i][j] * f6[i];
                }
                a
            })
            .collect()
    }

    /// `Sᵀ I₆ S` (exactly symmetric: the upper triangle mirrored).
    pub fn project_inertia(
        &self,
        i6: &[alloc::vec::Vec<R>],
    ) -> alloc::vec::Vec<alloc::vec::Vec<R>> {
        let is: [[R; 3]; 6] = core::array::from_fn(|r| {
            core::array::from_fn(|j| {
                let mut a = R::c(0.0);
                for k in 0..6 {
                    a = a + i6[r][k] * self.s[k][j];
                }
                a
            })
        });
        let mut out = alloc::vec![alloc::vec![R::c(0.0); 3]; 3];
        for a in 0..3 {
            for b in a..3 {
                let mut v = R::c(0.0);
                for k in 0..6 {
                    v = v + self.s[k][a] * is[k][b];
                }
                out[a][b] = v;
                out[b][a] = v;
            }
        }
        out
    }
}
