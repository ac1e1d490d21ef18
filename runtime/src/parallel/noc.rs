//! The NOC of a simple-platform parallel manipulator in actuator space (docs/method.md,
//! "Parallel manipulators: actuation matrix"; the lecture's eqs. 49–72), written once over
//! [`Real`] so that the runtime (`f64`) and the generator (symbolic) evaluate the same
//! equations.
//!
//! # How one evaluation goes
//! 1. The platform pose from `x` (rotation from the quaternion, normalized on the fly).
//! 2. Per leg, in the leg's own frame `L` (the home frame of its first joint, so that its axes
//!    are usually coordinate axes): closed-form inverse kinematics by the Paden–Kahan
//!    subproblems (UPS: the leg length, then the U by "two intersecting axes"; PUS and RUS: the
//!    first joint from the fixed rod length, then the U; spherical RRR: the first two joints by
//!    two intersecting axes), the joints kept as `(sin, cos)` pairs and lengths, never angles.
//! 3. The leg Jacobian `J_J` (3 × 3: the S centre's velocity for a leg ending in S, the
//!    platform's angular velocity for a spherical leg) and its inverse by the adjugate, checked
//!    against [`LEG_TOLERANCE`]: `θ̇_J = J_J⁻¹ G u` with `G` mapping `u` to the end point's
//!    velocity — the lecture's `L_J = J_J⁻¹ T`, one small solve per leg, never a system over
//!    all loops.
//! 4. Joint accelerations `θ̈_J = J_J⁻¹ (ṫ_end − J̇_J θ̇_J)`; leg body twists and twist rates from
//!    the joint rates and accelerations (columns of `T` and `Ṫ`).
//! 5. One Newton–Euler wrench per body, `w = M ṫ + W M t − w^G` (eq. 12), projected:
//!    leg bodies to the leg joints (`τ_J = T_Jᵀ w`), then to the end point by `y = J_J⁻ᵀ τ_J`,
//!    then to `u` by `Gᵀ y`; the platform's wrench directly. The sum is the generalized force
//!    `f = I u̇ + C u − γ` of the speeds `u`.
//! 6. Actuator efforts `τ = A⁻ᵀ f` where `q̇ = A u` stacks the actuated rows of the `J_J⁻¹ G`
//!    (eqs. 66–72); [`lu_solve`] factorizes `A` with partial pivoting.
//!
//! A UPS leg with a perpendicular U whose second axis is perpendicular to the leg (and a
//! massless cross) takes a closed form instead of steps 3–5 and of `J_J⁻¹` in `A`
//! ([`UpsPlan`], `ups_force`; Khalil & Guegan 2004): its frame follows from the leg direction
//! `s`, its row of `A` is `[(R p) × s; s]`, and its force on the platform comes from a few scalar
//! equations in that frame. The generic route still gives its inertia (`generalized_inertia`).

// Index loops read like the equations; negated float comparisons make NaN fail the test.
#![allow(
    clippy::needless_range_loop,
    clippy::neg_cmp_op_on_partial_ord,
    clippy::collapsible_if
)]

use alloc::vec;
use alloc::vec::Vec;

pub use crate::payload::Payload;
pub use crate::solve::{NoConvergence, PIVOT_TOLERANCE, check_finite, solve_spd};

use super::{LegEnd, LegKind, ParallelModel, PlatformMotion};
use crate::algebra::{
    M, V, add, cm, cross, cv, dot, euler, ident, inertia_quad, mm, mtv, mv, rot, scale, sub, zero3,
};
use crate::drive::{DriveInputs, drive_effort};
use crate::model::{JointKind, Mat3, Transform, Vec3, mat_vec};
use crate::scalar::{Real, Singular, Site};

/// Leg-Jacobian threshold: a leg is singular when `|det J_J| ≤ LEG_TOLERANCE · ∏‖columns‖`
/// (the Hadamard ratio `h`; its inverse, reported as the condition estimate, grows like the
/// condition number of `J_J`). The velocity terms carry `J⁻¹` twice, so rounding near a leg
/// singularity grows like `ε/h²` (measured on the five-bar's stretched leg): `1e-4` keeps it
/// below about `1e-8`.
pub const LEG_TOLERANCE: f64 = 1e-4;
/// Actuation-matrix threshold: `A` (columns scaled to unit norm) is singular when a pivot of its
/// partially pivoted LU is `≤ ACTUATION_TOLERANCE` times the largest pivot; the condition
/// estimate is the ratio of the largest to the smallest pivot.
pub const ACTUATION_TOLERANCE: f64 = 1e-8;

/// The constant data of one leg, resolved in the leg frame `L`.
#[derive(Clone, Debug)]
pub struct LegPlan {
    /// Leg type.
    pub kind: LegKind,
    /// The leg frame `L` in the base frame (the home frame of the first joint).
    pub frame: Transform,
    /// Joint kinds.
    pub joints: Vec<JointKind>,
    /// Home joint axes (unit, `L`).
    pub axes: Vec<Vec3>,
    /// Home joint points (on the axes, `L`).
    pub points: Vec<Vec3>,
    /// Home body poses in `L`.
    pub homes: Vec<Transform>,
    /// Body inertial data: mass, mass centre (body frame), inertia (body frame).
    pub bodies: Vec<(f64, Vec3, Mat3)>,
    /// Index of the actuated joint.
    pub actuated: usize,
    /// Friction and rotor inertia of each leg joint (actuated or passive).
    pub drives: Vec<crate::model::Drive>,
    /// Spherical end: the S centre at home (`L`); revolute end: the end axis at home (`L`).
    pub end_home: Vec3,
    /// The end point (S centre) or end axis in the platform frame.
    pub end_platform: Vec3,
    /// The U centre at home (`L`) (the orientation centre for a spherical leg).
    pub u_centre: Vec3,
    /// Fixed length: UPS the home distance U centre → S centre; PUS, RUS the rod length.
    pub length: f64,
    /// Branch of the two-intersecting-axes subproblem (±1), from the home configuration.
    pub sigma_u: f64,
    /// Branch of the first joint's subproblem (PUS, RUS) or the prismatic direction (UPS).
    pub sigma_first: f64,
    /// The closed form of a UPS leg (see [`UpsPlan`]); `None` for other legs, or a UPS leg
    /// whose geometry it does not cover (those take the generic route).
    pub ups: Option<UpsPlan>,
}

/// One body of a closed-form UPS leg, resolved in the leg frame `(t, e₁′, s)` (see
/// [`UpsPlan`]).
#[derive(Clone, Debug)]
pub struct UpsBody {
    /// Mass.
    pub mass: f64,
    /// Mass centre relative to the U centre at home length (leg frame).
    pub com: Vec3,
    /// Inertia about the mass centre (leg frame, constant).
    pub inertia: Mat3,
    /// The body rides on the prismatic joint (its mass centre moves by `ρ − ρ_home` along `s`).
    pub slides: bool,
}

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
    /// The leg's massive bodies after the U's cross (cylinder, piston, …).
    pub bodies: Vec<UpsBody>,
    /// The home leg length (the sliding bodies' mass centres are given there).
    pub length: f64,
}

/// The constant data of a whole mechanism: what the evaluators need, prepared once.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Platform motion.
    pub motion: PlatformMotion,
    /// Gravity (base frame).
    pub gravity: Vec3,
    /// Platform mass, mass centre, inertia (platform frame).
    pub platform: (f64, Vec3, Mat3),
    /// Legs.
    pub legs: Vec<LegPlan>,
}

fn sub3(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot3(a: &Vec3, b: &Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross3(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The point of line `(p, e)` closest to line `(q, f)` (the intersection when they meet).
fn meet(p: &Vec3, e: &Vec3, q: &Vec3, f: &Vec3) -> Vec3 {
    // p + s e = q + t f (least squares): [e·e −e·f; e·f −f·f][s t]ᵀ = [(q−p)·e; (q−p)·f]
    let w = dot3(e, f);
    let d = sub3(q, p);
    let (de, df) = (dot3(&d, e), dot3(&d, f));
    let den = 1.0 - w * w;
    let s = if den.abs() < 1e-300 {
        0.0
    } else {
        (de - w * df) / den
    };
    [p[0] + s * e[0], p[1] + s * e[1], p[2] + s * e[2]]
}

fn sign(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
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
fn ups_plan(lp: &LegPlan) -> Option<UpsPlan> {
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
    let bodies = (1..lp.bodies.len())
        .filter(|&k| !massless(k))
        .map(|k| {
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
            UpsBody {
                mass,
                com: snap([to_leg(&rel), [0.0; 3], [0.0; 3]])[0],
                inertia,
                slides: k >= 2,
            }
        })
        .collect();
    let f = &lp.frame;
    Some(UpsPlan {
        e0: snap([mat_vec(&f.rotation, &e0), [0.0; 3], [0.0; 3]])[0],
        bodies,
        length: lp.length,
    })
}

impl Plan {
    /// Prepare `model` (validating it first).
    pub fn new(model: &ParallelModel) -> Result<Plan, alloc::string::String> {
        let kinds = model.validate()?;
        let mut legs = Vec::with_capacity(model.legs.len());
        for (leg, kind) in model.legs.iter().zip(kinds) {
            let first = leg.joints[0].origin;
            // Home poses relative to L (the first joint's frame), composed from the joint
            // origins directly so that exact placements stay exact.
            let mut homes: Vec<Transform> = Vec::with_capacity(leg.joints.len());
            let mut h = Transform::IDENTITY;
            for (j, joint) in leg.joints.iter().enumerate() {
                if j > 0 {
                    h = h.compose(&joint.origin);
                }
                homes.push(h);
            }
            let axes: Vec<Vec3> = homes
                .iter()
                .zip(&leg.joints)
                .map(|(h, j)| mat_vec(&h.rotation, &j.axis))
                .collect();
            let points: Vec<Vec3> = homes.iter().map(|h| h.translation).collect();
            let last = *homes.last().unwrap_or(&Transform::IDENTITY);
            let (end_home, end_platform) = match leg.end {
                LegEnd::Spherical {
                    on_leg,
                    on_platform,
                } => (last.apply(&on_leg), on_platform),
                LegEnd::Revolute {
                    on_leg,
                    on_platform,
                } => (mat_vec(&last.rotation, &on_leg), on_platform),
            };
            let u_centre = match kind {
                LegKind::Ups | LegKind::SphericalRr => {
                    meet(&points[0], &axes[0], &points[1], &axes[1])
                }
                LegKind::Pus | LegKind::Rus => meet(&points[1], &axes[1], &points[2], &axes[2]),
                // The elbow of a planar RR leg.
                LegKind::PlanarRr => points[1],
                // Not used by the Newton route.
                LegKind::Generic => points[0],
            };
            let (ui, uj) = match kind {
                LegKind::Ups | LegKind::SphericalRr | LegKind::PlanarRr | LegKind::Generic => {
                    (0, 1)
                }
                LegKind::Pus | LegKind::Rus => (1, 2),
            };
            let (e1, e2) = (axes[ui], axes[uj]);
            let k = cross3(&e1, &e2);
            let mut plan = LegPlan {
                kind,
                frame: first,
                joints: leg.joints.iter().map(|j| j.kind).collect(),
                axes: axes.clone(),
                points,
                homes,
                bodies: leg
                    .bodies
                    .iter()
                    .map(|b| (b.mass, b.com, b.inertia))
                    .collect(),
                actuated: leg.actuated,
                drives: leg.joints.iter().map(|j| j.drive).collect(),
                end_home,
                end_platform,
                u_centre,
                length: 0.0,
                sigma_u: 1.0,
                sigma_first: 1.0,
                ups: None,
            };
            match kind {
                LegKind::Ups => {
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    plan.sigma_first = sign(dot3(&d, &axes[2]));
                    plan.sigma_u = sign(dot3(&d, &k));
                    plan.ups = ups_plan(&plan);
                }
                LegKind::Pus => {
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    // s = e·d − σ √(…) = 0 at home.
                    plan.sigma_first = sign(dot3(&axes[0], &d));
                    plan.sigma_u = sign(dot3(&d, &k));
                }
                LegKind::Rus | LegKind::PlanarRr => {
                    let d = sub3(&end_home, &u_centre);
                    plan.length = libm::sqrt(dot3(&d, &d));
                    plan.sigma_u = sign(dot3(&d, &k));
                    // Pick the crank branch that reproduces θ = 0 at home.
                    let mut best = (f64::INFINITY, 1.0);
                    for s in [1.0, -1.0] {
                        plan.sigma_first = s;
                        if let Ok((sn, cs)) = rus_crank::<f64>(&plan, end_home, 0) {
                            let err = sn.abs() + (cs - 1.0).abs();
                            if err < best.0 {
                                best = (err, s);
                            }
                        }
                    }
                    plan.sigma_first = best.1;
                }
                LegKind::SphericalRr => {
                    plan.sigma_u = sign(dot3(&end_home, &k));
                }
                LegKind::Generic => {
                    // The leg's size: the reach from its first joint to the S centre at home.
                    let d = sub3(&end_home, &plan.points[0]);
                    plan.length = libm::sqrt(dot3(&d, &d));
                }
            }
            legs.push(plan);
        }
        let plan = Plan {
            motion: model.motion,
            gravity: model.gravity,
            platform: (
                model.platform.mass,
                model.platform.com,
                model.platform.inertia,
            ),
            legs,
        };
        // The constraint Jacobian must have full rank at home: every leg Jacobian and the
        // actuation matrix regular there.
        let home = model.home_x();
        let n = plan.dof();
        inverse_dynamics(&plan, &home, &vec![0.0; n], &vec![0.0; n]).map_err(|e| {
            alloc::format!(
                "the mechanism is singular at its home pose ({e}); the constraint Jacobian must have full rank there"
            )
        })?;
        Ok(plan)
    }

    /// Degrees of freedom.
    pub fn dof(&self) -> usize {
        self.motion.dof()
    }
    /// The scale of [`forward_kinematics`]' tolerance: `1 +` the longest leg (m, at home) among
    /// the legs with a prismatic actuator (their residuals are lengths of that order), `1` when
    /// every actuator is revolute (radians).
    pub fn fk_scale(&self) -> f64 {
        1.0 + self
            .legs
            .iter()
            .filter(|l| l.joints[l.actuated] == JointKind::Prismatic)
            .fold(0.0f64, |m, l| m.max(l.length))
    }
    /// Position coordinates.
    pub fn nx(&self) -> usize {
        self.motion.nx()
    }
}

/// The platform's pose from `x`.
#[derive(Clone, Copy, Debug)]
pub struct Platform<R> {
    /// Rotation (platform → base).
    pub rot: M<R>,
    /// Origin of the platform frame (base frame).
    pub origin: V<R>,
}

/// The platform pose from `x` (`Pose`: `[p; q]`, `Orientation`: `q`); the quaternion need not
/// be unit (it is normalized), but it must not be zero (`Err(Site::Platform)`).
pub fn platform<R: Real>(plan: &Plan, x: &[R]) -> Result<Platform<R>, Singular> {
    let (origin, q) = match plan.motion {
        PlatformMotion::Pose => ([x[0], x[1], x[2]], [x[3], x[4], x[5], x[6]]),
        PlatformMotion::Orientation { centre } => (cv(&centre), [x[0], x[1], x[2], x[3]]),
        PlatformMotion::PlanarPoint { height } => {
            return Ok(Platform {
                rot: ident(),
                origin: [x[0], x[1], R::c(height)],
            });
        }
    };
    // Divided by its largest component first, so that no square under- or overflows: any
    // finite non-zero multiple of a unit quaternion is the same rotation (the sign of the
    // largest component may flip the quaternion, which is the same rotation too).
    let [w, a, b, c] = q;
    let big = R::select_abs_gt(w, a, w, a);
    let big = R::select_abs_gt(big, b, big, b);
    let big = R::select_abs_gt(big, c, big, c);
    let big = R::check(big, R::c(0.0), R::c(1.0), Site::Platform, true)?;
    // Divided, not multiplied by `1/big`, which overflows for a subnormal `big`.
    let [w, a, b, c] = [w / big, a / big, b / big, c / big];
    let n = w * w + a * a + b * b + c * c;
    let s = R::c(2.0) / n;
    let one = R::c(1.0);
    let rot = [
        [
            one - s * (b * b + c * c),
            s * (a * b - w * c),
            s * (a * c + w * b),
        ],
        [
            s * (a * b + w * c),
            one - s * (a * a + c * c),
            s * (b * c - w * a),
        ],
        [
            s * (a * c - w * b),
            s * (b * c + w * a),
            one - s * (a * a + b * b),
        ],
    ];
    Ok(Platform { rot, origin })
}

/// Paden–Kahan subproblem 2: `(sin, cos)` of `θ1, θ2` with `R(e1, θ1)·R(e2, θ2)·p = q`
/// (`e1`, `e2` unit, intersecting; `|p| = |q|`), on the branch `sigma`.
fn two_axes<R: Real>(
    e1: &Vec3,
    e2: &Vec3,
    p: V<R>,
    q: V<R>,
    sigma: f64,
    leg: usize,
    check: bool,
) -> Result<[(R, R); 2], Singular> {
    let w = dot3(e1, e2);
    let k = cross3(e1, e2);
    let kk = dot3(&k, &k);
    let den = 1.0 / (w * w - 1.0);
    let e2p = dot(cv(e2), p);
    let e1q = dot(cv(e1), q);
    let alpha = (R::c(w) * e2p - e1q) * R::c(den);
    let beta = (R::c(w) * e1q - e2p) * R::c(den);
    let pp = dot(p, p);
    // γ² |e1 × e2|² = |p|² − α² − β² − 2wαβ. Near a leg singularity (q → ±e1) the difference
    // cancels; for perpendicular axes (w = 0, α = e1·q) it is |e1 × q|² − (e2·p)² since |q| = |p|,
    // which keeps the small value's relative accuracy (error ~ε/δ instead of ~ε/δ²).
    let g2 = if w == 0.0 {
        let eq = cross(cv(e1), q);
        (dot(eq, eq) - e2p * e2p) * R::c(1.0 / kk)
    } else {
        (pp - alpha * alpha - beta * beta - R::c(2.0 * w) * alpha * beta) * R::c(1.0 / kk)
    };
    // γ² < 0: the target is out of reach; γ² ≈ 0 (within 1e-12 of |p|²): the boundary of the
    // leg's workspace, where its Jacobian is singular.
    // Unchecked (`!check`) where the caller's own tests cover these cases and nothing it
    // returns uses the angles.
    let g2 = if check {
        let g2 = R::check(
            g2,
            R::c(-R::tolerance(1e-12)) * pp,
            pp,
            Site::Reach(leg),
            false,
        )?;
        R::check(g2, R::c(0.0), pp, Site::Leg(leg), false)?
    } else {
        g2
    };
    let gamma = R::c(sigma) * g2.sqrt();
    let c = add(
        add(scale(alpha, cv(e1)), scale(beta, cv(e2))),
        scale(gamma, cv(&k)),
    );
    // θ2 turns p about e2 onto c.
    let pperp = sub(p, scale(e2p, cv(e2)));
    let cperp = sub(c, scale(e2p, cv(e2)));
    let n2 = dot(pperp, pperp);
    let s2 = dot(cross(cv(e2), pperp), cperp) / n2;
    let c2 = dot(pperp, cperp) / n2;
    // θ1 turns c about e1 onto q.
    let cq = sub(c, scale(e1q, cv(e1)));
    let qq = sub(q, scale(e1q, cv(e1)));
    let n1 = dot(cq, cq);
    let n1 = if check {
        R::check(n1, R::c(0.0), pp, Site::Leg(leg), false)?
    } else {
        n1
    };
    let s1 = dot(cross(cv(e1), cq), qq) / n1;
    let c1 = dot(cq, qq) / n1;
    Ok([(s1, c1), (s2, c2)])
}

/// Paden–Kahan subproblem 1: `(sin, cos)` of the rotation about the unit `e` that turns `p`
/// onto `q` (equal components across `e`).
fn one_axis<R: Real>(e: &Vec3, p: V<R>, q: V<R>) -> (R, R) {
    let pp = sub(p, scale(dot(cv(e), p), cv(e)));
    let qq = sub(q, scale(dot(cv(e), q), cv(e)));
    let n = dot(pp, pp);
    (dot(cross(cv(e), pp), qq) / n, dot(pp, qq) / n)
}

/// RUS: `(sin, cos)` of the crank angle that puts the U centre at the rod length from `a` (`L`).
fn rus_crank<R: Real>(plan: &LegPlan, a: V<R>, leg: usize) -> Result<(R, R), Singular> {
    let e0 = plan.axes[0];
    let o0 = plan.points[0];
    let r = sub3(&plan.u_centre, &o0);
    let rpar = dot3(&e0, &r);
    let rperp = [
        r[0] - rpar * e0[0],
        r[1] - rpar * e0[1],
        r[2] - rpar * e0[2],
    ];
    let er = cross3(&e0, &rperp);
    let d = sub(a, cv(&o0));
    let kk = (dot(d, d) + R::c(dot3(&r, &r) - plan.length * plan.length)) * R::c(0.5)
        - R::c(rpar) * dot(d, cv(&e0));
    let aa = dot(d, cv(&rperp));
    let bb = dot(d, cv(&er));
    let rho2 = aa * aa + bb * bb;
    let disc = rho2 - kk * kk;
    let disc = R::check(disc, R::c(0.0), rho2, Site::Reach(leg), false)?;
    let sq = R::c(plan.sigma_first) * disc.sqrt();
    let c = (aa * kk - bb * sq) / rho2;
    let s = (bb * kk + aa * sq) / rho2;
    Ok((s, c))
}

/// A joint's position: `(sin, cos)` for a revolute, the displacement for a prismatic joint.
#[derive(Clone, Copy, Debug)]
pub enum JointPos<R> {
    /// Revolute.
    R(R, R),
    /// Prismatic.
    P(R),
}

/// The kinematic state of one leg at a configuration, resolved in its frame `L`.
#[derive(Clone, Debug)]
pub struct LegKin<R> {
    /// Joint positions.
    pub q: Vec<JointPos<R>>,
    /// Current joint axes.
    pub e: Vec<V<R>>,
    /// Current joint points.
    pub o: Vec<V<R>>,
    /// Body rotations (body → `L`).
    pub rot: Vec<M<R>>,
    /// Body mass centres.
    pub com: Vec<V<R>>,
    /// End point (spherical end) or end axis (revolute end).
    pub end: V<R>,
    /// Rows of `J_J⁻¹` (the adjugate rows divided by the determinant).
    pub jinv: [V<R>; 3],
    /// Base-frame rotation of `L` (constant).
    pub frame: M<R>,
    /// The end point relative to the platform origin, base frame (spherical end; zero else).
    pub arm: V<R>,
    /// The closed-form UPS leg's frame (when [`LegPlan::ups`] is set).
    pub ups: Option<UpsKin<R>>,
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

/// Inverse kinematics, pose and Jacobian of leg `k` for the platform pose `pl`. Each test is
/// made where its value is used: the Jacobian's (`Site::Leg`) only with `jacobian` (positions
/// alone do not need it), and a closed-form UPS leg's by its own leg vector (reach: `ρ > 0`;
/// the U's singularity: `|e₀ × s| > 0`), since nothing it returns uses its U angles or `J⁻¹`.
pub fn leg_kinematics<R: Real>(
    plan: &Plan,
    k: usize,
    pl: &Platform<R>,
    jacobian: bool,
) -> Result<LegKin<R>, Singular> {
    let lp = &plan.legs[k];
    let fr: M<R> = cm(&lp.frame.rotation);
    let ft: V<R> = cv(&lp.frame.translation);
    let n = lp.joints.len();
    // The end target in L.
    let (target, arm, end_base) = match lp.kind {
        LegKind::SphericalRr => {
            let axis = mv(&pl.rot, cv(&lp.end_platform));
            (mtv(&fr, axis), zero3(), zero3())
        }
        LegKind::Ups => {
            // The target is not needed: the leg vector is formed in the base frame.
            let arm = mv(&pl.rot, cv(&lp.end_platform));
            (zero3(), arm, add(pl.origin, arm))
        }
        _ => {
            let arm = mv(&pl.rot, cv(&lp.end_platform));
            let a = add(pl.origin, arm);
            (mtv(&fr, sub(a, ft)), arm, a)
        }
    };
    // Closed-form inverse kinematics.
    let mut q: Vec<JointPos<R>> = Vec::with_capacity(n);
    let mut ups = None;
    match lp.kind {
        LegKind::Ups => {
            // The leg vector U centre → S centre in the base frame (the same as in L, rotated).
            let r = sub(end_base, cv(&lp.frame.apply(&lp.u_centre)));
            let rr = dot(r, r);
            let rr = R::check(rr, R::c(0.0), R::c(1.0), Site::Reach(k), false)?;
            let rho = rr.sqrt();
            let d = R::c(lp.sigma_first) * (rho - R::c(lp.length));
            let inv_rho = R::c(1.0) / rho;
            let s = scale(inv_rho, r);
            if let Some(up) = &lp.ups {
                // The leg frame (UpsPlan): c = e₀·s, d² = |e₀ × s|² (= 1 − c², formed so that
                // it keeps its relative accuracy near the U's singularity d → 0, where e₀ ∥ s;
                // the same test as `two_axes`' γ² ≤ 0).
                let e0 = cv::<R>(&up.e0);
                let c = dot(e0, s);
                let m = cross(e0, s);
                let d2 = R::check(dot(m, m), R::c(0.0), R::c(1.0), Site::Leg(k), false)?;
                let dd = R::c(lp.sigma_u) * d2.sqrt();
                let inv_d = R::c(1.0) / dd;
                ups = Some(UpsKin {
                    rho,
                    inv_rho,
                    cot: c * inv_d,
                    inv_d,
                    t: scale(inv_d, sub(e0, scale(c, s))),
                    e1: scale(-inv_d, m),
                    s,
                });
            }
            let dir = mtv(&fr, s);
            let p = sub3(&lp.end_home, &lp.u_centre);
            let p = [p[0] / lp.length, p[1] / lp.length, p[2] / lp.length];
            let closed = lp.ups.is_some();
            let [a, b] = two_axes(
                &lp.axes[0],
                &lp.axes[1],
                cv(&p),
                dir,
                lp.sigma_u,
                k,
                !closed,
            )?;
            q.push(JointPos::R(a.0, a.1));
            q.push(JointPos::R(b.0, b.1));
            q.push(JointPos::P(d));
        }
        LegKind::Pus => {
            let e0 = lp.axes[0];
            let dd = sub(target, cv(&lp.u_centre));
            let t = dot(cv(&e0), dd);
            let disc = t * t - dot(dd, dd) + R::c(lp.length * lp.length);
            let disc = R::check(
                disc,
                R::c(0.0),
                R::c(lp.length * lp.length),
                Site::Reach(k),
                false,
            )?;
            let s = t - R::c(lp.sigma_first) * disc.sqrt();
            let u = add(cv(&lp.u_centre), scale(s, cv(&e0)));
            let qv = sub(target, u);
            let p = sub3(&lp.end_home, &lp.u_centre);
            let [a, b] = two_axes(&lp.axes[1], &lp.axes[2], cv(&p), qv, lp.sigma_u, k, true)?;
            q.push(JointPos::P(s));
            q.push(JointPos::R(a.0, a.1));
            q.push(JointPos::R(b.0, b.1));
        }
        LegKind::Rus => {
            let (s0, c0) = rus_crank(lp, target, k)?;
            let r0 = rot(&lp.axes[0], s0, c0);
            let o0 = cv(&lp.points[0]);
            let u = add(o0, mv(&r0, sub(cv(&lp.u_centre), o0)));
            // The rod direction in the crank's home frame.
            let qv = mtv(&r0, sub(target, u));
            let p = sub3(&lp.end_home, &lp.u_centre);
            let [a, b] = two_axes(&lp.axes[1], &lp.axes[2], cv(&p), qv, lp.sigma_u, k, true)?;
            q.push(JointPos::R(s0, c0));
            q.push(JointPos::R(a.0, a.1));
            q.push(JointPos::R(b.0, b.1));
        }
        LegKind::PlanarRr => {
            let (s0, c0) = rus_crank(lp, target, k)?;
            let r0 = rot(&lp.axes[0], s0, c0);
            let o0 = cv(&lp.points[0]);
            let u = add(o0, mv(&r0, sub(cv(&lp.u_centre), o0)));
            // The distal link's direction in the proximal link's home frame.
            let qv = mtv(&r0, sub(target, u));
            let p = sub3(&lp.end_home, &lp.u_centre);
            let (s1, c1) = one_axis(&lp.axes[1], cv(&p), qv);
            q.push(JointPos::R(s0, c0));
            q.push(JointPos::R(s1, c1));
        }
        LegKind::SphericalRr => {
            let [a, b] = two_axes(
                &lp.axes[0],
                &lp.axes[1],
                cv(&lp.end_home),
                target,
                lp.sigma_u,
                k,
                true,
            )?;
            q.push(JointPos::R(a.0, a.1));
            q.push(JointPos::R(b.0, b.1));
        }
        LegKind::Generic => q = generic_ik(lp, target, k)?,
    }
    // Product of exponentials from the home configuration: D = Π exp(ξ_j θ_j), x ↦ G x + t.
    let mut g: M<R> = ident();
    let mut t: V<R> = zero3();
    let mut e = Vec::with_capacity(n);
    let mut o = Vec::with_capacity(n);
    let mut rots = Vec::with_capacity(n);
    let mut coms = Vec::with_capacity(n);
    for j in 0..n {
        let ej = mv(&g, cv(&lp.axes[j]));
        let oj = add(mv(&g, cv(&lp.points[j])), t);
        match q[j] {
            JointPos::R(s, c) => {
                g = mm(&g, &rot(&lp.axes[j], s, c));
                t = sub(oj, mv(&g, cv(&lp.points[j])));
            }
            JointPos::P(d) => {
                t = add(t, scale(d, ej));
            }
        }
        let h = &lp.homes[j];
        rots.push(mm(&g, &cm(&h.rotation)));
        let (_, com, _) = lp.bodies[j];
        let ch = h.apply(&com);
        coms.push(add(mv(&g, cv(&ch)), t));
        e.push(ej);
        o.push(oj);
    }
    let end = match lp.kind {
        LegKind::SphericalRr => target,
        _ => add(mv(&g, cv(&lp.end_home)), t),
    };
    // Jacobian columns and their adjugate.
    let cols: Vec<V<R>> = match lp.kind {
        LegKind::SphericalRr => vec![e[0], e[1], end],
        // A virtual third column along the plane normal keeps J_J 3 × 3; its rate is zero
        // because the end point moves in the plane.
        LegKind::PlanarRr => vec![
            cross(e[0], sub(end, o[0])),
            cross(e[1], sub(end, o[1])),
            e[0],
        ],
        _ => (0..n)
            .map(|j| match lp.joints[j] {
                JointKind::Revolute => cross(e[j], sub(end, o[j])),
                JointKind::Prismatic => e[j],
            })
            .collect(),
    };
    let r0 = cross(cols[1], cols[2]);
    let r1 = cross(cols[2], cols[0]);
    let r2 = cross(cols[0], cols[1]);
    let det = dot(cols[0], r0);
    let hn = (dot(cols[0], cols[0]) * dot(cols[1], cols[1]) * dot(cols[2], cols[2])).sqrt();
    let det = if jacobian && lp.ups.is_none() {
        R::check(
            det,
            R::c(R::tolerance(LEG_TOLERANCE)) * hn,
            hn,
            Site::Leg(k),
            true,
        )?
    } else {
        det
    };
    let id = R::c(1.0) / det;
    Ok(LegKin {
        q,
        e,
        o,
        rot: rots,
        com: coms,
        end,
        jinv: [scale(id, r0), scale(id, r1), scale(id, r2)],
        frame: fr,
        arm,
        ups,
    })
}

/// Newton steps of a generic leg's inverse kinematics ([`LegKind::Generic`]): a fixed count,
/// because a generated module unrolls them. From the home configuration the error falls
/// quadratically once it is small; twelve steps reach the `f64` floor from the poses the
/// bundled tests use (rotations to 0.3 rad and translations to 0.1 m from home).
pub const GENERIC_IK_ITERATIONS: usize = 12;

/// Newton's method picks no branch: far from home (rotations beyond about a radian) the steps
/// may converge to another assembly of the leg than the one at home, which is then a valid but
/// different solution. Closed-form leg types keep their declared branch.
///
/// A generic leg's inverse kinematics has converged when its S centre is within this fraction
/// of the leg's reach (first joint to S centre at home) of the target; otherwise the pose is
/// `Site::Reach` (unreachable on the home branch within [`GENERIC_IK_ITERATIONS`] steps).
pub const GENERIC_IK_TOLERANCE: f64 = 1e-9;

/// The joint positions of `th` (angles as sine and cosine).
fn joint_positions<R: Real>(lp: &LegPlan, th: &[R; 3]) -> Vec<JointPos<R>> {
    lp.joints
        .iter()
        .zip(th)
        .map(|(kind, &t)| match kind {
            JointKind::Revolute => {
                let (s, c) = t.sin_cos();
                JointPos::R(s, c)
            }
            JointKind::Prismatic => JointPos::P(t),
        })
        .collect()
}

/// The S centre and the Jacobian columns (leg frame `L`) of a three-joint leg at `q`: the
/// product of exponentials of [`leg_kinematics`], without the bodies.
fn end_and_columns<R: Real>(lp: &LegPlan, q: &[JointPos<R>]) -> (V<R>, [V<R>; 3]) {
    let mut g: M<R> = ident();
    let mut t: V<R> = zero3();
    let mut e = [zero3::<R>(); 3];
    let mut o = [zero3::<R>(); 3];
    for j in 0..3 {
        e[j] = mv(&g, cv(&lp.axes[j]));
        o[j] = add(mv(&g, cv(&lp.points[j])), t);
        match q[j] {
            JointPos::R(s, c) => {
                g = mm(&g, &rot(&lp.axes[j], s, c));
                t = sub(o[j], mv(&g, cv(&lp.points[j])));
            }
            JointPos::P(d) => t = add(t, scale(d, e[j])),
        }
    }
    let end = add(mv(&g, cv(&lp.end_home)), t);
    let cols = core::array::from_fn(|j| match lp.joints[j] {
        JointKind::Revolute => cross(e[j], sub(end, o[j])),
        JointKind::Prismatic => e[j],
    });
    (end, cols)
}

/// Inverse kinematics of a generic leg of plan `k` (target: the S centre in `L`) by
/// [`GENERIC_IK_ITERATIONS`] Newton steps from `θ = 0`, each `θ ← θ − J⁻¹ (p(θ) − target)` with
/// `J⁻¹` by its adjugate (a singular `J` is `Site::Leg(k)`); then the residual is checked
/// against [`GENERIC_IK_TOLERANCE`] (`Site::Reach(k)`).
fn generic_ik<R: Real>(lp: &LegPlan, target: V<R>, k: usize) -> Result<Vec<JointPos<R>>, Singular> {
    let mut th = [R::c(0.0); 3];
    for _ in 0..GENERIC_IK_ITERATIONS {
        let (end, cols) = end_and_columns(lp, &joint_positions(lp, &th));
        let r = sub(end, target);
        let adj = [
            cross(cols[1], cols[2]),
            cross(cols[2], cols[0]),
            cross(cols[0], cols[1]),
        ];
        let det = dot(cols[0], adj[0]);
        let hn = (dot(cols[0], cols[0]) * dot(cols[1], cols[1]) * dot(cols[2], cols[2])).sqrt();
        let det = R::check(
            det,
            R::c(R::tolerance(LEG_TOLERANCE)) * hn,
            hn,
            Site::Leg(k),
            true,
        )?;
        let inv = R::c(1.0) / det;
        for i in 0..3 {
            th[i] = th[i] - dot(adj[i], r) * inv;
        }
    }
    let q = joint_positions(lp, &th);
    let (end, _) = end_and_columns(lp, &q);
    let r = sub(end, target);
    let tol = R::tolerance(GENERIC_IK_TOLERANCE) * lp.length;
    R::check(
        R::c(tol * tol) - dot(r, r),
        R::c(0.0),
        R::c(tol * tol),
        Site::Reach(k),
        false,
    )?;
    Ok(q)
}

/// The legs' kinematics at `x`, their Jacobians tested.
pub fn kinematics<R: Real>(
    plan: &Plan,
    x: &[R],
) -> Result<(Platform<R>, Vec<LegKin<R>>), Singular> {
    kinematics_of(plan, x, true)
}

/// The legs' joint positions at `x`: [`kinematics`] without the Jacobians' tests (their
/// `J⁻¹` is not to be used).
pub fn positions<R: Real>(plan: &Plan, x: &[R]) -> Result<(Platform<R>, Vec<LegKin<R>>), Singular> {
    kinematics_of(plan, x, false)
}

fn kinematics_of<R: Real>(
    plan: &Plan,
    x: &[R],
    jacobian: bool,
) -> Result<(Platform<R>, Vec<LegKin<R>>), Singular> {
    let pl = platform(plan, x)?;
    let mut legs = Vec::with_capacity(plan.legs.len());
    for k in 0..plan.legs.len() {
        legs.push(leg_kinematics(plan, k, &pl, jacobian)?);
    }
    Ok((pl, legs))
}

/// Actuated joint positions (rad or m) of the legs, in leg order.
pub fn actuated_positions<R: Real>(plan: &Plan, legs: &[LegKin<R>]) -> Vec<R> {
    plan.legs
        .iter()
        .zip(legs)
        .map(|(lp, lk)| match lk.q[lp.actuated] {
            JointPos::R(s, c) => s.atan2(c),
            JointPos::P(d) => d,
        })
        .collect()
}

/// The actuation matrix `A` (`q̇ = A u`), row-major `DOF × DOF`.
pub fn actuation_matrix<R: Real>(plan: &Plan, legs: &[LegKin<R>]) -> Vec<Vec<R>> {
    plan.legs
        .iter()
        .zip(legs)
        .map(|(lp, lk)| {
            // q̇_a = (row_a of J⁻¹) · Lᵀ v_end = g · v_end with g = L · row_a; for a
            // closed-form UPS leg the prismatic rate is ±ρ̇ = ±s·v_end.
            let g = match &lk.ups {
                Some(uk) => scale(R::c(lp.sigma_first), uk.s),
                None => mv(&lk.frame, lk.jinv[lp.actuated]),
            };
            match plan.motion {
                PlatformMotion::Pose => {
                    let m = cross(lk.arm, g);
                    vec![m[0], m[1], m[2], g[0], g[1], g[2]]
                }
                PlatformMotion::Orientation { .. } => vec![g[0], g[1], g[2]],
                PlatformMotion::PlanarPoint { .. } => vec![g[0], g[1]],
            }
        })
        .collect()
}

/// The motion of one leg body: angular velocity and acceleration, and the acceleration of its
/// material point at the joint point `o_k` (velocities of points are not needed: the
/// accelerations carry them in their `ω × (ω × r)` and Coriolis terms).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BodyMotion<R> {
    /// Angular velocity.
    pub(crate) w: V<R>,
    /// Angular acceleration.
    pub(crate) alpha: V<R>,
    /// Acceleration of the material point at the joint point `o_k`.
    pub(crate) a: V<R>,
}

impl<R: Real> BodyMotion<R> {
    /// Acceleration of the body's material point at `x`, knowing it at `o`.
    pub(crate) fn accel_at(&self, o: V<R>, x: V<R>) -> V<R> {
        let r = sub(x, o);
        add(
            add(self.a, cross(self.alpha, r)),
            cross(self.w, cross(self.w, r)),
        )
    }
}

/// The leg's body motions by the chain recursion (the lecture's eqs. 25–26, 33): for joint `j`
/// with axis `e` through `o_j`, `ω_j = ω_{j−1} + θ̇ e`, `ω̇_j = ω̇_{j−1} + θ̈ e + θ̇ ω_{j−1} × e`
/// (R), and `a_j(o_j) = a_{j−1}(o_j) + θ̈ e + 2 θ̇ ω_{j−1} × e` (P). `qdd = None`: θ̈ = 0 (the
/// bias `J̇ θ̇`).
fn chain<R: Real>(lp: &LegPlan, lk: &LegKin<R>, qd: &[R], qdd: Option<&[R]>) -> Vec<BodyMotion<R>> {
    let n = lp.joints.len();
    let mut out: Vec<BodyMotion<R>> = Vec::with_capacity(n);
    for j in 0..n {
        let (w0, alpha0, a0) = match out.last() {
            None => (zero3::<R>(), zero3::<R>(), zero3::<R>()),
            Some(p) => (p.w, p.alpha, p.accel_at(lk.o[j - 1], lk.o[j])),
        };
        let e = lk.e[j];
        let we = cross(w0, e);
        let qdd_e = match qdd {
            Some(a) => scale(a[j], e),
            None => zero3(),
        };
        out.push(match lp.joints[j] {
            JointKind::Revolute => BodyMotion {
                w: add(w0, scale(qd[j], e)),
                alpha: add(add(alpha0, qdd_e), scale(qd[j], we)),
                a: a0,
            },
            JointKind::Prismatic => BodyMotion {
                w: w0,
                alpha: alpha0,
                a: add(add(a0, qdd_e), scale(R::c(2.0) * qd[j], we)),
            },
        });
    }
    out
}

/// Steps 3–4 for one leg: joint rates `θ̇ = J⁻¹ v_end`, joint accelerations
/// `θ̈ = J⁻¹ (a_end − J̇ θ̇)` (the end's acceleration with `θ̈ = 0` first) and the leg bodies'
/// motions by the chain recursion, all in the leg frame `L`. `v_end`, `a_end`: the end point's
/// velocity and acceleration (or the platform's angular velocity and acceleration for a
/// spherical leg), base frame.
pub(crate) fn leg_motion<R: Real>(
    lp: &LegPlan,
    lk: &LegKin<R>,
    v_end: V<R>,
    a_end: V<R>,
) -> (Vec<R>, Vec<R>, Vec<BodyMotion<R>>) {
    let n = lp.joints.len();
    let v_l = mtv(&lk.frame, v_end);
    let a_l = mtv(&lk.frame, a_end);
    let qd: Vec<R> = (0..3).map(|i| dot(lk.jinv[i], v_l)).collect();
    let bias = chain(lp, lk, &qd, None);
    let last = n - 1;
    let bias_end = match lp.kind {
        LegKind::SphericalRr => {
            // ω_P = θ̇0 e0 + θ̇1 e1 + θ̇2 e_end; e_end turns with body 1.
            add(bias[last].alpha, scale(qd[2], cross(bias[last].w, lk.end)))
        }
        _ => bias[last].accel_at(lk.o[last], lk.end),
    };
    let rhs = sub(a_l, bias_end);
    let qdd: Vec<R> = (0..3).map(|i| dot(lk.jinv[i], rhs)).collect();
    let motion = chain(lp, lk, &qd, Some(&qdd));
    (qd, qdd, motion)
}

/// The generalized force `f = I u̇ + C u − γ` (`γ` only when `gravity`) of the speeds `u`.
pub fn generalized_force<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    generalized_force_with(plan, pl, legs, u, ud, gravity, None)
}

/// [`generalized_force`] with the leg joints' drives from `drives` instead of the plan (closed-form
/// UPS legs then take the generic route, where the joint efforts are formed).
pub fn generalized_force_with<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    u: &[R],
    ud: &[R],
    gravity: bool,
    drives: Option<&DriveInputs<R>>,
) -> Vec<R> {
    let dof = plan.dof();
    let mut f: Vec<R> = vec![R::c(0.0); dof];
    let g_world: Vec3 = if gravity { plan.gravity } else { [0.0; 3] };
    let planar = matches!(plan.motion, PlatformMotion::PlanarPoint { .. });
    // Platform angular velocity and acceleration (a planar point does not turn).
    let (w, wd) = if planar {
        (zero3::<R>(), zero3::<R>())
    } else {
        ([u[0], u[1], u[2]], [ud[0], ud[1], ud[2]])
    };
    for (li, (lp, lk)) in plan.legs.iter().zip(legs).enumerate() {
        let n = lp.joints.len();
        // End velocity and acceleration (base frame), then in L.
        let (v_end, a_end) = match plan.motion {
            PlatformMotion::Pose => {
                let v = [u[3], u[4], u[5]];
                let a = [ud[3], ud[4], ud[5]];
                let v_end = add(v, cross(w, lk.arm));
                let a_end = add(add(a, cross(wd, lk.arm)), cross(w, cross(w, lk.arm)));
                (v_end, a_end)
            }
            PlatformMotion::Orientation { .. } => (w, wd),
            PlatformMotion::PlanarPoint { .. } => {
                let z = R::c(0.0);
                ([u[0], u[1], z], [ud[0], ud[1], z])
            }
        };
        if let (Some(up), Some(uk), None) = (&lp.ups, &lk.ups, drives) {
            let y = ups_force(up, uk, v_end, a_end, cv(&g_world));
            let m = cross(lk.arm, y);
            for i in 0..3 {
                f[i] = f[i] + m[i];
                f[3 + i] = f[3 + i] + y[i];
            }
            continue;
        }
        let (qd, qdd, motion) = leg_motion(lp, lk, v_end, a_end);
        // Body wrenches (about each mass centre) and the leg's joint efforts.
        let g_l = mtv(&lk.frame, cv::<R>(&g_world));
        let mut force = zero3::<R>();
        let mut moment0 = zero3::<R>(); // about the origin of L
        let mut tau: Vec<R> = vec![R::c(0.0); 3];
        for k in (0..n).rev() {
            let (mass, _, inertia) = lp.bodies[k];
            let massless = mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0);
            if !massless {
                let c = lk.com[k];
                let m = &motion[k];
                let a = m.accel_at(lk.o[k], c);
                let nk = euler(&lk.rot[k], &inertia, m.w, m.alpha);
                let fk = scale(R::c(mass), sub(a, g_l));
                force = add(force, fk);
                moment0 = add(moment0, add(nk, cross(c, fk)));
            }
            let mo = sub(moment0, cross(lk.o[k], force));
            tau[k] = match lp.joints[k] {
                JointKind::Revolute => dot(lk.e[k], mo),
                JointKind::Prismatic => dot(lk.e[k], force),
            };
        }
        // The joints' drives, actuated and passive (the lecture's dissipative term δ and the
        // rotors' inertia), act at the joints beside the bodies' efforts.
        for k in 0..n {
            tau[k] = tau[k]
                + match drives {
                    Some(d) => d.effort(3 * li + k, qd[k], qdd[k]),
                    None => drive_effort(&lp.drives[k], qd[k], qdd[k]),
                };
        }
        // End force (or moment) y = J⁻ᵀ τ, to the base frame, then Gᵀ y.
        let y_l = add(
            add(scale(tau[0], lk.jinv[0]), scale(tau[1], lk.jinv[1])),
            scale(tau[2], lk.jinv[2]),
        );
        let y = mv(&lk.frame, y_l);
        match plan.motion {
            PlatformMotion::Pose => {
                let m = cross(lk.arm, y);
                for i in 0..3 {
                    f[i] = f[i] + m[i];
                    f[3 + i] = f[3 + i] + y[i];
                }
            }
            PlatformMotion::Orientation { .. } => {
                for i in 0..3 {
                    f[i] = f[i] + y[i];
                }
            }
            PlatformMotion::PlanarPoint { .. } => {
                for i in 0..2 {
                    f[i] = f[i] + y[i];
                }
            }
        }
    }
    // The platform.
    if planar {
        // A point mass at P.
        let (mass, _, _) = plan.platform;
        for i in 0..2 {
            f[i] = f[i] + R::c(mass) * (ud[i] - R::c(g_world[i]));
        }
        return f;
    }
    let (mass, com, inertia) = plan.platform;
    let r = mv(&pl.rot, cv::<R>(&com));
    let (a0,) = match plan.motion {
        PlatformMotion::Pose => ([ud[3], ud[4], ud[5]],),
        PlatformMotion::Orientation { .. } | PlatformMotion::PlanarPoint { .. } => (zero3::<R>(),),
    };
    let a = add(add(a0, cross(wd, r)), cross(w, cross(w, r)));
    let fp = scale(R::c(mass), sub(a, cv(&g_world)));
    let np = add(euler(&pl.rot, &inertia, w, wd), cross(r, fp));
    for i in 0..3 {
        f[i] = f[i] + np[i];
    }
    if let PlatformMotion::Pose = plan.motion {
        for i in 0..3 {
            f[3 + i] = f[3 + i] + fp[i];
        }
    }
    f
}

/// The payload's part of the generalized force `f = I u̇ + C u − γ` (`γ` only when `gravity`):
/// the platform's own term of [`generalized_force`] (Newton–Euler of one rigid body moving with
/// the platform, eq. 12, mapped by its twist-shaping block `T_Pᵀ`) with the payload's values.
pub fn payload_force<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    payload: &Payload<R>,
    u: &[R],
    ud: &[R],
    gravity: bool,
) -> Vec<R> {
    let n = plan.dof();
    let mut f = vec![R::c(0.0); n];
    let g: V<R> = cv(&if gravity { plan.gravity } else { [0.0; 3] });
    if let PlatformMotion::PlanarPoint { .. } = plan.motion {
        for i in 0..2 {
            f[i] = payload.mass * (ud[i] - g[i]);
        }
        return f;
    }
    let (w, wd) = ([u[0], u[1], u[2]], [ud[0], ud[1], ud[2]]);
    let a0 = match plan.motion {
        PlatformMotion::Pose => [ud[3], ud[4], ud[5]],
        _ => zero3::<R>(),
    };
    let r = mv(&pl.rot, payload.com);
    let a = add(add(a0, cross(wd, r)), cross(w, cross(w, r)));
    let fp = scale(payload.mass, sub(a, g));
    // Euler's equation in the platform frame, then to the base frame.
    let (wb, ab) = (mtv(&pl.rot, w), mtv(&pl.rot, wd));
    let nb = add(
        mv(&payload.inertia, ab),
        cross(wb, mv(&payload.inertia, wb)),
    );
    let np = add(mv(&pl.rot, nb), cross(r, fp));
    f[..3].copy_from_slice(&np);
    if let PlatformMotion::Pose = plan.motion {
        f[3..6].copy_from_slice(&fp);
    }
    f
}

/// The twist columns of a body moving with the platform, `n` speeds: `(Some(e_j), e_j × r_c)`
/// for the angular speeds (`r_c` the mass centre from the platform origin, base frame) and
/// `(None, e_j)` for the linear ones (pose).
fn platform_columns<R: Real>(n: usize, rc: V<R>) -> Vec<(Option<V<R>>, V<R>)> {
    let unit = |j: usize| {
        let mut e = zero3::<R>();
        e[j] = R::c(1.0);
        e
    };
    (0..n)
        .map(|j| {
            if j < 3 {
                (Some(unit(j)), cross(unit(j), rc))
            } else {
                (None, unit(j - 3))
            }
        })
        .collect()
}

/// The payload's part of the generalized inertia `I` (exactly symmetric): `T_Pᵀ M T_P` of
/// [`generalized_inertia`]'s platform term with the payload's values.
pub fn payload_inertia<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    payload: &Payload<R>,
) -> Vec<Vec<R>> {
    let n = plan.dof();
    let z = R::c(0.0);
    let mut out = vec![vec![z; n]; n];
    if let PlatformMotion::PlanarPoint { .. } = plan.motion {
        for (i, row) in out.iter_mut().enumerate() {
            row[i] = payload.mass;
        }
        return out;
    }
    let cols = platform_columns(n, mv(&pl.rot, payload.com));
    for i in 0..n {
        for j in i..n {
            let mut v = payload.mass * dot(cols[i].1, cols[j].1);
            if let (Some(a), Some(b)) = (cols[i].0, cols[j].0) {
                let (ab, bb) = (mtv(&pl.rot, a), mtv(&pl.rot, b));
                v = v + dot(ab, mv(&payload.inertia, bb));
            }
            out[i][j] = v;
            out[j][i] = v;
        }
    }
    out
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
///    `F_z = Σ_{sliding} f_b·ẑ`.
/// 4. Joint efforts `τ₀ = e₀·N = d N_x + c N_z`, `τ₁ = e₁′·N = N_y`, `τ_P = ±F_z`; the leg
///    Jacobian's columns are `∂v/∂θ̇₀ = ρ e₀ × ẑ = −ρ d ŷ`, `∂v/∂θ̇₁ = ρ x̂`, `∂v/∂q̇_P = ±ẑ`, so
///    `y = J⁻ᵀ τ = (N_y/ρ, −(N_x + (c/d) N_z)/ρ, F_z)`, then `y_x t + y_y e₁′ + y_z s`.
fn ups_force<R: Real>(up: &UpsPlan, uk: &UpsKin<R>, v: V<R>, a: V<R>, g: V<R>) -> V<R> {
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
    // 3. Body wrenches, the moment about the U centre and the prismatic joint's force.
    let mut nsum = zero3::<R>();
    let mut fz = R::c(0.0);
    for b in &up.bodies {
        let mut r = cv::<R>(&b.com);
        if b.slides {
            r[2] = r[2] + (uk.rho - R::c(up.length));
        }
        let mut acc = add(cross(alpha, r), cross(w, cross(w, r)));
        if b.slides {
            // ρ̈ ẑ + 2ρ̇ ω × ẑ, ω × ẑ = (ω_y, −ω_x, 0).
            acc = add(acc, [rd2 * w[1], -(rd2 * w[0]), rdd]);
        }
        let fb = scale(R::c(b.mass), sub(acc, gl));
        let nb = euler_const(&b.inertia, w, alpha);
        nsum = add(nsum, add(nb, cross(r, fb)));
        if b.slides {
            fz = fz + fb[2];
        }
    }
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
fn ups_inertia<R: Real>(up: &UpsPlan, uk: &UpsKin<R>) -> M<R> {
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

/// Euler's equation `I ω̇ + ω × I ω` for a constant inertia `inertia` (in the frame of `w`,
/// `wd`); `c ω̇` for an isotropic one.
fn euler_const<R: Real>(inertia: &Mat3, w: V<R>, wd: V<R>) -> V<R> {
    let c = inertia[0][0];
    if [inertia[1][1], inertia[2][2]] == [c; 2]
        && [inertia[0][1], inertia[0][2], inertia[1][2]] == [0.0; 3]
        && [inertia[1][0], inertia[2][0], inertia[2][1]] == [0.0; 3]
    {
        return scale(R::c(c), wd);
    }
    let i = cm::<R>(inertia);
    add(mv(&i, wd), cross(w, mv(&i, w)))
}

/// The generalized inertia `I = TᵀMT` of the speeds `u`, column by column: column `j` is the
/// generalized force of `u = 0`, `u̇ = e_j` without gravity. A second route to
/// [`generalized_inertia`] (the tests compare them).
pub fn generalized_inertia_by_columns<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
) -> Vec<Vec<R>> {
    let n = plan.dof();
    let zero = vec![R::c(0.0); n];
    let cols: Vec<Vec<R>> = (0..n)
        .map(|j| {
            let mut e = vec![R::c(0.0); n];
            e[j] = R::c(1.0);
            generalized_force(plan, pl, legs, &zero, &e, false)
        })
        .collect();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i <= j { cols[j][i] } else { cols[i][j] })
                .collect()
        })
        .collect()
}

/// The generalized inertia `I = TᵀMT = Σ_b T_bᵀ M_b T_b` of the speeds `u` (exactly symmetric),
/// assembled per leg (eq. 68's structure): the leg's joint-space inertia `M_J` (its open chain),
/// then its end-point inertia `Λ = J⁻ᵀ M_J J⁻¹`, then `Gᵀ Λ G` with `G` the map from `u` to the
/// end point's velocity; plus the platform's `T_Pᵀ M_P T_P`.
pub fn generalized_inertia<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
) -> Vec<Vec<R>> {
    generalized_inertia_with(plan, pl, legs, None)
}

/// [`generalized_inertia`] with the leg joints' rotor inertias from `drives` instead of the
/// plan (closed-form UPS legs then take the generic route).
pub fn generalized_inertia_with<R: Real>(
    plan: &Plan,
    pl: &Platform<R>,
    legs: &[LegKin<R>],
    drives: Option<&DriveInputs<R>>,
) -> Vec<Vec<R>> {
    let n = plan.dof();
    let z = R::c(0.0);
    let mut out = vec![vec![z; n]; n];
    let pose = matches!(plan.motion, PlatformMotion::Pose);
    for (li, (lp, lk)) in plan.legs.iter().zip(legs).enumerate() {
        let armature: [Option<R>; 3] = match drives {
            Some(d) => core::array::from_fn(|k| d.armature.as_ref().map(|a| a[3 * li + k])),
            None => core::array::from_fn(|k| {
                let a = lp.drives.get(k).map_or(0.0, |d| d.armature);
                (a != 0.0).then(|| R::c(a))
            }),
        };
        let lam = match (&lp.ups, &lk.ups, drives) {
            (Some(up), Some(uk), None) => ups_inertia(up, uk),
            _ => leg_end_inertia(lp, lk, &armature),
        };
        if pose {
            // G = [−[r]×, 1]: I_vv = Λ, I_ωv = [r]× Λ, I_ωω = [r]× Λ [r]×ᵀ.
            let r = lk.arm;
            let col = |c: usize| [lam[0][c], lam[1][c], lam[2][c]];
            let p: [V<R>; 3] = core::array::from_fn(|c| cross(r, col(c))); // columns of [r]×Λ
            for i in 0..3 {
                for j in 0..3 {
                    out[3 + i][3 + j] = out[3 + i][3 + j] + lam[i][j];
                    out[i][3 + j] = out[i][3 + j] + p[j][i];
                }
            }
            // I_ωω = ([r]×Λ)[r]×ᵀ: row i of [r]×Λ crossed with r, as columns.
            for i in 0..3 {
                let row = [p[0][i], p[1][i], p[2][i]];
                let q = cross(r, row); // column i of [r]× (row)ᵀ … = ([r]×Λ[r]×ᵀ)[:, i]
                for j in 0..3 {
                    out[j][i] = out[j][i] + q[j];
                }
            }
        } else {
            // Orientation (u = ω) or planar point (u = in-plane velocity): I += Λ's block.
            for i in 0..n {
                for j in 0..n {
                    out[i][j] = out[i][j] + lam[i][j];
                }
            }
        }
    }
    if let PlatformMotion::PlanarPoint { .. } = plan.motion {
        let (mass, _, _) = plan.platform;
        for i in 0..n {
            out[i][i] = out[i][i] + R::c(mass);
        }
        return out;
    }
    // The platform: ω columns e_j with mass-centre velocity e_j × r_c; v columns (pose) e_j.
    let (mass, com, inertia) = plan.platform;
    let cols = platform_columns(n, mv(&pl.rot, cv::<R>(&com)));
    for i in 0..n {
        for j in i..n {
            let mut v = R::c(mass) * dot(cols[i].1, cols[j].1);
            if let (Some(a), Some(b)) = (cols[i].0, cols[j].0) {
                v = v + inertia_quad(&pl.rot, &inertia, a, b);
            }
            out[i][j] = out[i][j] + v;
        }
    }
    // Exactly symmetric: the upper triangle.
    for i in 0..n {
        for j in 0..i {
            out[i][j] = out[j][i];
        }
    }
    out
}

/// The end-point inertia `Λ = J_J⁻ᵀ M_J J_J⁻¹` (base frame, exactly symmetric) of a leg by the
/// generic route: the joint-space inertia `M_J` of its open chain, rotors included, then the
/// rows of `J_J⁻¹`.
fn leg_end_inertia<R: Real>(lp: &LegPlan, lk: &LegKin<R>, armature: &[Option<R>; 3]) -> M<R> {
    let z = R::c(0.0);
    let nj = lp.joints.len();
    // Joint-space inertia of the leg's open chain (bodies k ≥ max(i, j)).
    let mut mj = [[z; 3]; 3];
    for k in 0..nj {
        let (mass, _, inertia) = lp.bodies[k];
        let massless = mass == 0.0 && inertia.iter().flatten().all(|&x| x == 0.0);
        if massless {
            continue;
        }
        let c = lk.com[k];
        // Twist columns of body k at its mass centre: (angular, linear).
        let cols: Vec<(Option<V<R>>, V<R>)> = (0..=k)
            .map(|j| match lp.joints[j] {
                JointKind::Revolute => (Some(lk.e[j]), cross(lk.e[j], sub(c, lk.o[j]))),
                JointKind::Prismatic => (None, lk.e[j]),
            })
            .collect();
        for i in 0..=k {
            for j in i..=k {
                let mut v = R::c(mass) * dot(cols[i].1, cols[j].1);
                if let (Some(a), Some(b)) = (cols[i].0, cols[j].0) {
                    v = v + inertia_quad(&lk.rot[k], &inertia, a, b);
                }
                mj[i][j] = mj[i][j] + v;
            }
        }
    }
    // The joints' rotors: `I_a` on the diagonal of the leg's joint-space inertia.
    for (k, a) in armature.iter().enumerate() {
        if let Some(a) = a {
            mj[k][k] = mj[k][k] + *a;
        }
    }
    for i in 0..3 {
        for j in 0..i {
            mj[i][j] = mj[j][i];
        }
    }
    // Λ = Wᵀ... with the rows of J⁻¹ in the base frame: Λ = Σ_ij M_J[i][j] w_i w_jᵀ.
    let w: [V<R>; 3] = [
        mv(&lk.frame, lk.jinv[0]),
        mv(&lk.frame, lk.jinv[1]),
        mv(&lk.frame, lk.jinv[2]),
    ];
    let b: [V<R>; 3] = core::array::from_fn(|i| {
        add(
            add(scale(mj[i][0], w[0]), scale(mj[i][1], w[1])),
            scale(mj[i][2], w[2]),
        )
    });
    let mut lam = [[z; 3]; 3];
    for r in 0..3 {
        for c in r..3 {
            lam[r][c] = w[0][r] * b[0][c] + w[1][r] * b[1][c] + w[2][r] * b[2][c];
            lam[c][r] = lam[r][c];
        }
    }
    lam
}

/// Forward dynamics: `u̇` with `I u̇ = Aᵀ τ − (C u − γ)`.
pub fn forward_dynamics_generic<R: Real>(
    plan: &Plan,
    x: &[R],
    u: &[R],
    tau: &[R],
) -> Result<Vec<R>, Singular> {
    forward_dynamics_with(plan, x, u, tau, &[], None)
}

/// [`forward_dynamics_generic`] with [`Payload`]s on the platform (a payload, and the
/// platform's own inertia when it is given at run time) and the leg joints' drives from
/// `drives` (see [`generalized_force_with`]).
pub fn forward_dynamics_with<R: Real>(
    plan: &Plan,
    x: &[R],
    u: &[R],
    tau: &[R],
    payloads: &[Payload<R>],
    drives: Option<&DriveInputs<R>>,
) -> Result<Vec<R>, Singular> {
    let (pl, legs) = kinematics(plan, x)?;
    let n = plan.dof();
    let zero = vec![R::c(0.0); n];
    let mut h = generalized_force_with(plan, &pl, &legs, u, &zero, true, drives);
    for p in payloads {
        let hp = payload_force(plan, &pl, p, u, &zero, true);
        for i in 0..n {
            h[i] = h[i] + hp[i];
        }
    }
    let a = actuation_matrix(plan, &legs);
    let rhs: Vec<R> = (0..n)
        .map(|i| {
            let mut s = -h[i];
            for (k, row) in a.iter().enumerate() {
                s = s + row[i] * tau[k];
            }
            s
        })
        .collect();
    let mut m = generalized_inertia_with(plan, &pl, &legs, drives);
    for p in payloads {
        let mp = payload_inertia(plan, &pl, p);
        for i in 0..n {
            for j in 0..n {
                m[i][j] = m[i][j] + mp[i][j];
            }
        }
    }
    solve_spd(&m, &rhs)
}

/// Solve `a x = b` (`transpose`: `aᵀ x = b`) by LU with partial pivoting of `a` with its columns
/// scaled to unit 2-norm; a pivot `≤ ACTUATION_TOLERANCE` times the largest pivot (or a
/// non-finite one) is reported as `Site::Actuation(pivot)` with the ratio of the largest to the
/// smallest pivot as the condition estimate. Both solves factorize the same matrix, so they
/// give the same verdict at every `a` (LAPACK's `dgetrf` and `dgetrs`). Fixed-size, no
/// allocation.
pub fn lu_solve<const N: usize>(
    a: &[[f64; N]; N],
    b: &[f64; N],
    transpose: bool,
) -> Result<[f64; N], Singular> {
    // m = a·S (column scaling S), factorized in place as P m = L U: the multipliers below the
    // diagonal, swapped with their rows.
    let mut m = *a;
    let mut sc = [1.0; N];
    for j in 0..N {
        let mut s = 0.0;
        for row in m.iter() {
            s += row[j] * row[j];
        }
        let s = crate::math::sqrt(s);
        if s > 0.0 {
            sc[j] = 1.0 / s;
            for row in m.iter_mut() {
                row[j] *= sc[j];
            }
        }
    }
    let mut piv = [0usize; N];
    let mut pmax: f64 = 0.0;
    for k in 0..N {
        let mut p = k;
        let mut best = if m[k][k] < 0.0 { -m[k][k] } else { m[k][k] };
        for (i, row) in m.iter().enumerate().skip(k + 1) {
            let v = if row[k] < 0.0 { -row[k] } else { row[k] };
            if v > best {
                best = v;
                p = i;
            }
        }
        m.swap(k, p);
        piv[k] = p;
        // NaN never passes.
        if !(best > 0.0) || !best.is_finite() {
            return Err(Singular {
                site: Site::Actuation(k),
                value: m[k][k],
                condition_estimate: f64::INFINITY,
            });
        }
        pmax = if best > pmax { best } else { pmax };
        if !(best > ACTUATION_TOLERANCE * pmax) {
            return Err(Singular {
                site: Site::Actuation(k),
                value: m[k][k],
                condition_estimate: pmax / best,
            });
        }
        let inv = 1.0 / m[k][k];
        for i in k + 1..N {
            let f = m[i][k] * inv;
            m[i][k] = f;
            if f != 0.0 {
                for j in k + 1..N {
                    m[i][j] -= f * m[k][j];
                }
            }
        }
    }
    let mut x = *b;
    if transpose {
        // aᵀ x = b ⇔ (a S)ᵀ x = S b = Uᵀ Lᵀ P x: forward with Uᵀ, back with Lᵀ, then Pᵀ.
        for j in 0..N {
            x[j] *= sc[j];
        }
        for i in 0..N {
            let mut s = x[i];
            for j in 0..i {
                s -= m[j][i] * x[j];
            }
            x[i] = s / m[i][i];
        }
        for i in (0..N).rev() {
            let mut s = x[i];
            for j in i + 1..N {
                s -= m[j][i] * x[j];
            }
            x[i] = s;
        }
        for k in (0..N).rev() {
            x.swap(k, piv[k]);
        }
    } else {
        // a x = b ⇔ L U (S⁻¹ x) = P b.
        for k in 0..N {
            x.swap(k, piv[k]);
        }
        for i in 0..N {
            let mut s = x[i];
            for j in 0..i {
                s -= m[i][j] * x[j];
            }
            x[i] = s;
        }
        for i in (0..N).rev() {
            let mut s = x[i];
            for j in i + 1..N {
                s -= m[i][j] * x[j];
            }
            x[i] = s / m[i][i];
        }
        for j in 0..N {
            x[j] *= sc[j];
        }
    }
    check_finite(&[&x])?;
    Ok(x)
}

/// `lu_solve` for the sizes the bundled platforms use, on row vectors.
fn solve_dyn(a: &[Vec<f64>], b: &[f64], transpose: bool) -> Result<Vec<f64>, Singular> {
    macro_rules! fixed {
        ($n:literal) => {{
            let mut m = [[0.0; $n]; $n];
            let mut v = [0.0; $n];
            for i in 0..$n {
                v[i] = b[i];
                for j in 0..$n {
                    m[i][j] = a[i][j];
                }
            }
            lu_solve(&m, &v, transpose).map(|x| x.to_vec())
        }};
    }
    match b.len() {
        1 => fixed!(1),
        2 => fixed!(2),
        3 => fixed!(3),
        4 => fixed!(4),
        5 => fixed!(5),
        _ => fixed!(6),
    }
}

/// `Ok(v)` when every entry is finite, else `Err(Site::Input)` (an overflow).
fn finite(v: Vec<f64>) -> Result<Vec<f64>, Singular> {
    check_finite(&[&v])?;
    Ok(v)
}

/// Actuated joint positions (rad or m) for the platform coordinates `x`.
pub fn inverse_kinematics(plan: &Plan, x: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[x])?;
    let (_, legs) = positions(plan, x)?;
    finite(actuated_positions(plan, &legs))
}

/// Every leg's joint positions (rad or m, the spec's joint order after U expansion) at `x`.
pub fn leg_joint_positions(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (_, legs) = kinematics(plan, x)?;
    Ok(legs
        .iter()
        .map(|lk| {
            lk.q.iter()
                .map(|q| match *q {
                    JointPos::R(s, c) => libm::atan2(s, c),
                    JointPos::P(d) => d,
                })
                .collect()
        })
        .collect())
}

/// The actuation matrix `A` at `x` (`q̇ = A u`).
pub fn actuation(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (_, legs) = kinematics(plan, x)?;
    Ok(actuation_matrix(plan, &legs))
}

/// Actuator rates `q̇ = A u`.
pub fn actuator_rates(plan: &Plan, x: &[f64], u: &[f64]) -> Result<Vec<f64>, Singular> {
    check_finite(&[u])?;
    let a = actuation(plan, x)?;
    finite(
        a.iter()
            .map(|row| row.iter().zip(u).map(|(a, b)| a * b).sum())
            .collect(),
    )
}

/// Actuator efforts `τ = A⁻ᵀ (I u̇ + C u − γ)` (N or N·m; gravity included).
pub fn inverse_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, ud])?;
    let (pl, legs) = kinematics(plan, x)?;
    let f = generalized_force(plan, &pl, &legs, u, ud, true);
    let a = actuation_matrix(plan, &legs);
    solve_dyn(&a, &f, true)
}

/// The generalized force `I u̇ + C u − γ` of the speeds `u` (before the actuation map).
pub fn generalized_effort(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    ud: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, ud])?;
    let (pl, legs) = kinematics(plan, x)?;
    finite(generalized_force(plan, &pl, &legs, u, ud, true))
}

/// The generalized inertia `I = TᵀMT` of the speeds `u`.
pub fn mass_matrix(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (pl, legs) = kinematics(plan, x)?;
    let i = generalized_inertia(plan, &pl, &legs);
    check_finite(&[&i.concat()])?;
    Ok(i)
}

/// The inertia in actuator space `A⁻ᵀ I A⁻¹` (the lecture's eq. 68).
pub fn actuator_mass_matrix(plan: &Plan, x: &[f64]) -> Result<Vec<Vec<f64>>, Singular> {
    check_finite(&[x])?;
    let (pl, legs) = kinematics(plan, x)?;
    let i = generalized_inertia(plan, &pl, &legs);
    let a = actuation_matrix(plan, &legs);
    let n = plan.dof();
    // B = I A⁻¹ column by column (A⁻¹ e_j), then A⁻ᵀ B.
    let mut b = vec![vec![0.0; n]; n];
    for j in 0..n {
        let mut e = vec![0.0; n];
        e[j] = 1.0;
        let c = solve_dyn(&a, &e, false)?;
        for r in 0..n {
            b[r][j] = (0..n).map(|k| i[r][k] * c[k]).sum();
        }
    }
    let mut out = vec![vec![0.0; n]; n];
    for j in 0..n {
        let col: Vec<f64> = (0..n).map(|r| b[r][j]).collect();
        let c = solve_dyn(&a, &col, true)?;
        for r in 0..n {
            out[r][j] = c[r];
        }
    }
    // Symmetrize (the exact matrix is symmetric).
    for r in 0..n {
        for c in r + 1..n {
            let m = 0.5 * (out[r][c] + out[c][r]);
            out[r][c] = m;
            out[c][r] = m;
        }
    }
    check_finite(&[&out.concat()])?;
    Ok(out)
}

/// Forward dynamics: `u̇` for the actuator efforts `tau`.
pub fn forward_dynamics(
    plan: &Plan,
    x: &[f64],
    u: &[f64],
    tau: &[f64],
) -> Result<Vec<f64>, Singular> {
    check_finite(&[x, u, tau])?;
    finite(forward_dynamics_generic(plan, x, u, tau)?)
}

/// Newton iterations of [`forward_kinematics`] at most.
pub const FK_MAX_ITERATIONS: usize = 50;
/// Convergence of [`forward_kinematics`]: `max |q(x) − q| ≤ FK_TOLERANCE · Plan::fk_scale()`
/// (angle residuals wrapped to `(−π, π]`). The bound does not grow with `q`: a huge target is
/// met as closely as a small one, or not at all.
pub const FK_TOLERANCE: f64 = 1e-12;

/// Wrap an angle difference to `(−π, π]`.
fn wrap(a: f64) -> f64 {
    let t = core::f64::consts::TAU;
    let r = a - t * libm::round(a / t);
    if r <= -core::f64::consts::PI {
        r + t
    } else {
        r
    }
}

/// `x` moved by the small motion `du` (`[δθ; δp]` or `δθ`, base frame): the rotation vector
/// multiplies the quaternion from the left, the origin is translated.
pub fn retract(motion: PlatformMotion, x: &[f64], du: &[f64]) -> Vec<f64> {
    let (qi, pi) = match motion {
        PlatformMotion::Pose => (3, Some(0)),
        PlatformMotion::Orientation { .. } => (0, None),
        PlatformMotion::PlanarPoint { .. } => {
            return x.iter().zip(du).map(|(a, b)| a + b).collect();
        }
    };
    let th = [du[0], du[1], du[2]];
    let a = libm::sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2]);
    let (s, c) = crate::math::sin_cos(0.5 * a);
    let k = if a > 1e-300 { s / a } else { 0.5 };
    let d = [c, k * th[0], k * th[1], k * th[2]];
    let q = [x[qi], x[qi + 1], x[qi + 2], x[qi + 3]];
    let mut r = [
        d[0] * q[0] - d[1] * q[1] - d[2] * q[2] - d[3] * q[3],
        d[0] * q[1] + d[1] * q[0] + d[2] * q[3] - d[3] * q[2],
        d[0] * q[2] - d[1] * q[3] + d[2] * q[0] + d[3] * q[1],
        d[0] * q[3] + d[1] * q[2] - d[2] * q[1] + d[3] * q[0],
    ];
    let n = libm::sqrt(r.iter().map(|v| v * v).sum());
    for v in r.iter_mut() {
        *v /= n;
    }
    let mut out = x.to_vec();
    out[qi..qi + 4].copy_from_slice(&r);
    if let Some(p) = pi {
        for i in 0..3 {
            out[p + i] += du[3 + i];
        }
    }
    out
}

/// Forward kinematics: the platform coordinates `x` whose actuated joint positions are `q`, by
/// Newton's method from `guess` (`x ← x ⊕ A⁻¹ (q − q(x))`, the step halved while it does not
/// reduce the residual), at most [`FK_MAX_ITERATIONS`] iterations, converged when the residual
/// is within [`FK_TOLERANCE`] times [`Plan::fk_scale`]. Revolute targets count modulo 2π. A
/// non-finite `q` or `guess` is `Err` at once. The quaternion of the result is unit.
pub fn forward_kinematics(
    plan: &Plan,
    q: &[f64],
    guess: &[f64],
) -> Result<Vec<f64>, NoConvergence> {
    let n = plan.dof();
    let revolute: Vec<bool> = plan
        .legs
        .iter()
        .map(|l| l.joints[l.actuated] == JointKind::Revolute)
        .collect();
    if check_finite(&[q, guess]).is_err() {
        return Err(NoConvergence {
            iterations: 0,
            residual: f64::INFINITY,
        });
    }
    let tol = FK_TOLERANCE * plan.fk_scale();
    // Revolute targets reduced to [−π, π] once, with the accurate range reduction of sin and
    // cos, so that every residual below is a difference of two such angles (O(1) to wrap,
    // whatever the size of `q`).
    let q: Vec<f64> = q
        .iter()
        .zip(&revolute)
        .map(|(&v, &r)| {
            if r {
                let (s, c) = crate::math::sin_cos(v);
                crate::math::atan2(s, c)
            } else {
                v
            }
        })
        .collect();
    let residual = |x: &[f64]| -> Option<(Vec<f64>, f64, Vec<Vec<f64>>)> {
        let (_, legs) = kinematics(plan, x).ok()?;
        let qx = actuated_positions(plan, &legs);
        let r: Vec<f64> = (0..n)
            .map(|i| {
                let d = q[i] - qx[i];
                if revolute[i] { wrap(d) } else { d }
            })
            .collect();
        let m = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if !m.is_finite() {
            return None;
        }
        Some((r, m, actuation_matrix(plan, &legs)))
    };
    let mut x = retract(plan.motion, guess, &vec![0.0; n]);
    let Some(mut cur) = residual(&x) else {
        return Err(NoConvergence {
            iterations: 0,
            residual: f64::INFINITY,
        });
    };
    for it in 0..FK_MAX_ITERATIONS {
        if cur.1 <= tol {
            return Ok(x);
        }
        let Ok(du) = solve_dyn(&cur.2, &cur.0, false) else {
            return Err(NoConvergence {
                iterations: it,
                residual: cur.1,
            });
        };
        let mut step = 1.0;
        let mut next = None;
        for _ in 0..20 {
            let d: Vec<f64> = du.iter().map(|v| v * step).collect();
            let xn = retract(plan.motion, &x, &d);
            if let Some(r) = residual(&xn) {
                if r.1 < cur.1 {
                    next = Some((xn, r));
                    break;
                }
            }
            step *= 0.5;
        }
        match next {
            Some((xn, r)) => {
                x = xn;
                cur = r;
            }
            None => {
                return Err(NoConvergence {
                    iterations: it + 1,
                    residual: cur.1,
                });
            }
        }
    }
    if cur.1 <= tol {
        Ok(x)
    } else {
        Err(NoConvergence {
            iterations: FK_MAX_ITERATIONS,
            residual: cur.1,
        })
    }
}

/// Potential energy of gravity at `x`, `−Σ m_b gᵀ c_b` over the platform and every leg body
/// (J, zero at the base origin). `Err` where the legs cannot be solved.
pub fn potential_energy(plan: &Plan, x: &[f64]) -> Result<f64, Singular> {
    let (pl, legs) = kinematics(plan, x)?;
    let g: V<f64> = plan.gravity;
    let (mass, com, _) = plan.platform;
    let mut v = -mass * dot(g, add(pl.origin, mv(&pl.rot, com)));
    for (lp, lk) in plan.legs.iter().zip(&legs) {
        for (k, (m, _, _)) in lp.bodies.iter().enumerate() {
            let c = lp.frame.apply(&lk.com[k]);
            v -= m * dot(g, c);
        }
    }
    Ok(v)
}
