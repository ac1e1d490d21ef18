//! An independent reference route for the inverse dynamics of closed-chain (and open-chain)
//! mechanisms: the full Newton–Euler equations of every rigid body in Cartesian coordinates, with
//! the joint reaction wrenches and the actuator efforts solved together as Lagrange multipliers.
//!
//! This is the second route of docs/method.md, "Properties used as checks", item 5 (the full
//! Newton–Euler of every body, the joint reactions solved as Lagrange multipliers). It shares no code with `runtime::noc` or `runtime::parallel`: it uses only the
//! model data types and the helpers of `runtime::model` (`Transform`, `mat_vec`, `axis_angle`,
//! …) to place the bodies, nalgebra's dense matrices, and a one-sided Jacobi SVD written here
//! (nalgebra 0.35's own SVD was found to miss `U Σ Vᵀ = A` by up to 1e-4 on some
//! well-conditioned 48 × 48 constraint matrices; cf. nalgebra issue #1172). It never
//! differentiates numerically.
//!
//! # Data
//! Everything is in the base frame at one instant: body `b` has mass `m_b`, mass centre `c_b`
//! and inertia `I_b` about `c_b` ([`CBody`]); each joint ([`CJoint`]) joins a child body to a
//! parent body or to the fixed base. The unknowns are the body twists `t_b = [ω_b; ċ_b]` (6 per
//! body, docs/method.md, "Rigid bodies: twists, wrenches, Newton–Euler"); the base has zero twist. For a point `P` the vector
//! `r_b = P − c_b` is its arm from body `b`'s mass centre.
//!
//! # 1. Velocity level: `K t = ρ`
//! Every constraint is one scalar row that is linear in the twists of the child `c` and parent
//! `p`, `k_cᵀ t_c + k_pᵀ t_p = ρ`, of one of three shapes:
//! * angular, `a·(ω_c − ω_p)`: `k_c = [a; 0]`, `k_p = −[a; 0]`;
//! * cross, `(a_p × a_c)·(ω_c − ω_p)`: the same with `a = a_p × a_c`;
//! * point, `a·(v_c(P) − v_p(P))` with `v_b(P) = ċ_b + ω_b × r_b` the velocity of the material
//!   point of body `b` at `P`: `k_c = [r_c × a; a]`, `k_p = −[r_p × a; a]`.
//!
//! The joints give (`n`: the unit axis; `a₁, a₂`: two unit vectors ⊥ `n`, carried by the parent;
//! `e_x, e_y, e_z`: the fixed base axes):
//!
//! | joint | rows | count |
//! |---|---|---|
//! | R | angular `a₁, a₂`; point `e_x, e_y, e_z` at the axis point | 5 |
//! | P | angular `e_x, e_y, e_z`; point `a₁, a₂` at a point of the child | 5 |
//! | U | cross `a_p × a_c`; point `e_x, e_y, e_z` at the centre | 4 |
//! | S | point `e_x, e_y, e_z` at the centre | 3 |
//!
//! and the prescribed motion ([`Prescribed`]) adds rows with a right-hand side `ρ = u`:
//! `ω_b = u[0..3]` (angular rows `e_x, e_y, e_z`, parent = base), `v_b(P) = u[3..6]` (point rows),
//! or the rate of every actuated joint, `q̇ = n·(ω_c − ω_p)` (R, angular row `n`) or
//! `q̇ = n·(v_c(P) − v_p(P))` (P, point row `n`).
//!
//! The stacked `K` (rows × 6r) need not be square: planar and spherical mechanisms are
//! overconstrained in 3-D, so rows are redundant. `t` is the least-squares solution by SVD (rows
//! and columns scaled to unit norm, singular values below [`RANK_TOLERANCE`] · σ_max dropped); the
//! twists are unique only when `K` has full column rank `6r` (else `Err` with the rank), and the
//! rows must all hold (the residual, relative to the largest term `|K_ij t_j|` or `|ρ_i|`, is
//! reported as [`Solution::velocity_residual`] and must be below [`RESIDUAL_TOLERANCE`]).
//!
//! # 2. Acceleration level: `K ṫ = ρ̇ − K̇ t`
//! Each row holds for all time, so `k_cᵀ ṫ_c + k_pᵀ ṫ_p = ρ̇ − (k̇_cᵀ t_c + k̇_pᵀ t_p)`, with the
//! rates of the row vectors computed exactly from the twists just found: a vector carried by body
//! `b` turns, `ȧ = ω_b × a` (`ȧ = 0` for base-fixed vectors); the point `P` is a material point of
//! the child, `Ṗ = ċ_c + ω_c × r_c`, so `ṙ_c = ω_c × r_c` and `ṙ_p = Ṗ − ċ_p` (for R, U and S
//! joints `P` is also a material point of the parent; for a P joint `ṙ_p` carries the sliding
//! velocity, which gives the Coriolis term `2 ω_p × v_rel`). Then
//! * angular: `k̇_c = [ȧ; 0]`, `k̇_p = −[ȧ; 0]` (e.g. R: `(ω_p × a)·(ω_c − ω_p)`);
//! * cross: `ȧ` replaced by `d/dt(a_p × a_c) = (ω_p × a_p) × a_c + a_p × (ω_c × a_c)`;
//! * point: `k̇_c = [ṙ_c × a + r_c × ȧ; ȧ]`, `k̇_p = −[ṙ_p × a + r_p × ȧ; ȧ]`. For the
//!   base-fixed `e_k` of R/U/S joints this is the equality of the material points'
//!   accelerations, `c̈ + ω̇ × r + ω × (ω × r)`, on both sides.
//!
//! The same (factorized) `K` gives the twist rates `ṫ`.
//!
//! # 3. Dynamics: `Kᵀ_J λ + A τ = h`
//! Newton–Euler of every body about its mass centre (docs/method.md, "Rigid bodies: twists, wrenches, Newton–Euler"):
//! `h_b = M_b ṫ_b + W_b M_b t_b − w^G_b = [I ω̇ + ω × Iω; m c̈ − m g]` must equal the sum of the
//! reaction and actuator wrenches on the body (moments about its own mass centre). A constraint
//! row is power-conjugate to the wrench `λ k_c` on the child and `λ k_p` on the parent: the point
//! row `a` is the force `λ a` at `P` on the child (moment `r_c × a λ`) and `−λ a` at `P` on the
//! parent; the angular row is the couple `±λ a`. So the reactions are `K_Jᵀ λ` (`K_J`: the joint
//! rows of `K`, one multiplier each). An actuated joint's effort is conjugate to its rate row:
//! R, the torque `τ n` on the child and `−τ n` on the parent; P, the force `τ n` at the joint point
//! on the child and `−τ n` on the parent — columns `A`. The 6r equations are solved for `[λ; τ]` by
//! SVD (least squares). In an overconstrained mechanism `λ` is not unique, but `τ` is exactly when
//! the actuator columns are independent of the reaction columns,
//! `rank [K_Jᵀ A] = rank K_Jᵀ + n_act` (else `Err`). The residual relative to the largest wrench
//! entry is [`Solution::force_residual`].
//!
//! Sign convention: `τ` is the effort the actuators must exert for the motion, so with zero
//! velocities and accelerations it holds the mechanism against gravity, as
//! `runtime::noc::inverse_dynamics` (`τ = I q̈ + C q̇ − γ`) for trees.
//!
//! # Builders
//! [`from_tree`] turns a `runtime::model::Model` at `q` into a [`CSystem`] (every joint
//! actuated); [`from_parallel`] does so for a `runtime::parallel::ParallelModel` at given leg
//! joint values and platform coordinates, recording in [`CSystem::closure`] the two sides of every
//! loop-closing joint so that [`closure_residual`] tells whether the leg values close the loops.

use nalgebra::{DMatrix, DVector};
use runtime::model::{JointKind, Model, Transform, axis_angle, mat_mul, mat_vec, transpose};
use runtime::parallel::{LegEnd, ParallelModel, PlatformMotion};

/// 3-vector.
pub type Vec3 = [f64; 3];
/// 3×3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// Singular values below `RANK_TOLERANCE · σ_max` (of the row- and column-normalized matrices)
/// count as zero.
pub const RANK_TOLERANCE: f64 = 1e-10;
/// Largest accepted relative residual of the velocity, acceleration and force equations.
pub const RESIDUAL_TOLERANCE: f64 = 1e-8;

/// A rigid body at one instant (base frame).
#[derive(Clone, Debug, PartialEq)]
pub struct CBody {
    /// Mass (kg), `>= 0`.
    pub mass: f64,
    /// Mass centre (m).
    pub com: Vec3,
    /// Inertia about the mass centre, base-frame axes (kg·m²).
    pub inertia: Mat3,
}

/// Kinds of joints.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CJointKind {
    /// Revolute about the unit `axis` (base frame; fixed in the parent) through the joint point.
    Revolute {
        /// Unit axis.
        axis: Vec3,
    },
    /// Prismatic along the unit `axis` (base frame; fixed in the parent).
    Prismatic {
        /// Unit axis.
        axis: Vec3,
    },
    /// Universal: the first axis fixed in the parent, the second in the child, intersecting at
    /// the joint point.
    Universal {
        /// Axis carried by the parent.
        axis_parent: Vec3,
        /// Axis carried by the child.
        axis_child: Vec3,
    },
    /// Ball joint at the joint point.
    Spherical,
}

/// A joint between `child` and `parent` (or the base).
#[derive(Clone, Debug, PartialEq)]
pub struct CJoint {
    /// Parent body, `None` for the fixed base.
    pub parent: Option<usize>,
    /// Child body.
    pub child: usize,
    /// A point of the joint (R: on the axis; P: a point of the child at the joint; U, S: the
    /// centre), base frame (m).
    pub point: Vec3,
    /// The kind and its axes.
    pub kind: CJointKind,
    /// Whether an actuator drives it (R and P only).
    pub actuated: bool,
}

/// Two vectors that coincide when a loop closes: points (m) of a loop-closing spherical joint as
/// seen from its parent and its child, or unit directions (a loop-closing revolute's axis).
#[derive(Clone, Debug, PartialEq)]
pub struct Coincidence {
    /// The joint (index into [`CSystem::joints`]).
    pub joint: usize,
    /// The vector computed along the parent's chain.
    pub on_parent: Vec3,
    /// The vector computed along the child's chain.
    pub on_child: Vec3,
}

/// A mechanism at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct CSystem {
    /// The bodies.
    pub bodies: Vec<CBody>,
    /// The joints.
    pub joints: Vec<CJoint>,
    /// Gravitational acceleration (m/s²).
    pub gravity: Vec3,
    /// Closure data for [`closure_residual`] (empty for hand-built systems).
    pub closure: Vec<Coincidence>,
    /// Spring-dampers between material points.
    pub springs: Vec<CSpring>,
}

/// A linear spring-damper between the material points currently at `point_a` (of body `a`;
/// `None`: the ground) and `point_b`: tension `k (L − L₀) + c L̇`.
#[derive(Clone, Debug, PartialEq)]
pub struct CSpring {
    /// First body.
    pub a: Option<usize>,
    /// First point (base frame, m).
    pub point_a: Vec3,
    /// Second body.
    pub b: Option<usize>,
    /// Second point (base frame, m).
    pub point_b: Vec3,
    /// Stiffness (N/m).
    pub stiffness: f64,
    /// Rest length (m).
    pub rest_length: f64,
    /// Damping (N·s/m).
    pub damping: f64,
}

impl CSystem {
    /// A system without closure data.
    pub fn new(bodies: Vec<CBody>, joints: Vec<CJoint>, gravity: Vec3) -> CSystem {
        CSystem {
            bodies,
            joints,
            gravity,
            closure: Vec::new(),
            springs: Vec::new(),
        }
    }
}

/// What the speeds `u` (and their rates `u̇`) prescribe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Prescribed {
    /// 6-DOF: body `body`'s angular velocity ω = u[0..3] and the velocity of its material point
    /// currently at `point` = u[3..6]; ud likewise (angular acceleration, acceleration of that
    /// material point).
    Pose {
        /// The body.
        body: usize,
        /// The material point (base frame, m).
        point: Vec3,
    },
    /// 3-DOF: body `body`'s angular velocity ω = u[0..3], ud = ω̇ (the rest follows from the
    /// joints).
    Orientation {
        /// The body.
        body: usize,
    },
    /// The rates and accelerations of every actuated joint (in joint order): qd, qdd given as
    /// u, ud.
    ActuatedJoints,
}

/// The result of [`inverse_dynamics`].
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Actuator efforts (N·m or N), actuated joints in joint order.
    pub efforts: Vec<f64>,
    /// Per body `[ω; ċ]`.
    pub twists: Vec<[f64; 6]>,
    /// Per body `[ω̇; c̈]`.
    pub twist_rates: Vec<[f64; 6]>,
    /// Largest relative row residual of the velocity and acceleration constraint systems.
    pub velocity_residual: f64,
    /// Largest residual of the Newton–Euler equations relative to the largest wrench entry.
    pub force_residual: f64,
}

// ---------------------------------------------------------------------------------------------
// Small vector algebra (own, so that nothing is shared with the routes under test).

fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(s: f64, a: Vec3) -> Vec3 {
    [s * a[0], s * a[1], s * a[2]]
}
fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: Vec3) -> Result<Vec3, String> {
    let n = norm(a);
    if n > 1e-12 && n.is_finite() {
        Ok(scale(1.0 / n, a))
    } else {
        Err(format!("axis {a:?} is not a direction"))
    }
}
/// Two unit vectors `a₁, a₂` with `(a₁, a₂, n)` orthonormal.
fn perpendiculars(n: Vec3) -> (Vec3, Vec3) {
    let k = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let mut h = [0.0; 3];
    h[k] = 1.0;
    let a1 = scale(1.0 / norm(cross(n, h)), cross(n, h));
    (a1, cross(n, a1))
}
fn ang(t: &[f64; 6]) -> Vec3 {
    [t[0], t[1], t[2]]
}
fn lin(t: &[f64; 6]) -> Vec3 {
    [t[3], t[4], t[5]]
}
fn six(a: Vec3, b: Vec3) -> [f64; 6] {
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}
fn dot6(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    (0..6).map(|i| a[i] * b[i]).sum()
}
const E: [Vec3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

// ---------------------------------------------------------------------------------------------
// Constraint rows.

/// What carries a vector: the base or a body.
#[derive(Clone, Copy, Debug)]
enum Carrier {
    Base,
    Body(usize),
}

impl Carrier {
    fn of(parent: Option<usize>) -> Carrier {
        parent.map_or(Carrier::Base, Carrier::Body)
    }
}

#[derive(Clone, Copy, Debug)]
enum Shape {
    /// `a·(ω_c − ω_p)`, `a` carried by `on`.
    Angular { a: Vec3, on: Carrier },
    /// `(a_p × a_c)·(ω_c − ω_p)`, `a_p` carried by the parent, `a_c` by the child.
    Cross { ap: Vec3, ac: Vec3 },
    /// `a·(v_c(P) − v_p(P))`, `a` carried by `on`, `P` a material point of the child.
    Point { a: Vec3, on: Carrier, p: Vec3 },
}

#[derive(Clone, Copy, Debug)]
struct Row {
    child: usize,
    parent: Option<usize>,
    shape: Shape,
}

fn omega(on: Carrier, t: &[[f64; 6]]) -> Vec3 {
    match on {
        Carrier::Base => [0.0; 3],
        Carrier::Body(b) => ang(&t[b]),
    }
}

impl Row {
    /// `(k_c, k_p)`: the row is `k_cᵀ t_c + k_pᵀ t_p` (`k_p` unused for the base).
    fn vectors(&self, sys: &CSystem) -> ([f64; 6], [f64; 6]) {
        let arm = |b: Option<usize>, p: Vec3| b.map_or([0.0; 3], |b| sub(p, sys.bodies[b].com));
        match self.shape {
            Shape::Angular { a, .. } => (six(a, [0.0; 3]), six(scale(-1.0, a), [0.0; 3])),
            Shape::Cross { ap, ac } => {
                let m = cross(ap, ac);
                (six(m, [0.0; 3]), six(scale(-1.0, m), [0.0; 3]))
            }
            Shape::Point { a, p, .. } => {
                let rc = arm(Some(self.child), p);
                let rp = arm(self.parent, p);
                (
                    six(cross(rc, a), a),
                    six(scale(-1.0, cross(rp, a)), scale(-1.0, a)),
                )
            }
        }
    }

    /// `k̇_cᵀ t_c + k̇_pᵀ t_p` at the twists `t`.
    fn bias(&self, sys: &CSystem, t: &[[f64; 6]]) -> f64 {
        let zero = [0.0; 6];
        let tc = &t[self.child];
        let tp = self.parent.map_or(&zero, |p| &t[p]);
        let wc = ang(tc);
        let wp = ang(tp);
        let rel = sub(wc, wp);
        match self.shape {
            Shape::Angular { a, on } => dot(cross(omega(on, t), a), rel),
            Shape::Cross { ap, ac } => {
                let md = add(cross(cross(wp, ap), ac), cross(ap, cross(wc, ac)));
                dot(md, rel)
            }
            Shape::Point { a, on, p } => {
                let ad = cross(omega(on, t), a);
                let rc = sub(p, sys.bodies[self.child].com);
                let rcd = cross(wc, rc);
                let pd = add(lin(tc), rcd);
                let kcd = six(add(cross(rcd, a), cross(rc, ad)), ad);
                let mut b = dot6(&kcd, tc);
                if let Some(pp) = self.parent {
                    let rp = sub(p, sys.bodies[pp].com);
                    let rpd = sub(pd, lin(tp));
                    let kpd = six(add(cross(rpd, a), cross(rp, ad)), ad);
                    b -= dot6(&kpd, tp);
                }
                b
            }
        }
    }

    /// `k_cᵀ x_c + k_pᵀ x_p` for per-body 6-vectors `x`.
    fn apply(&self, sys: &CSystem, x: &[[f64; 6]]) -> f64 {
        let (kc, kp) = self.vectors(sys);
        dot6(&kc, &x[self.child]) + self.parent.map_or(0.0, |p| dot6(&kp, &x[p]))
    }
}

/// The rate row of an actuated joint: R `n·(ω_c − ω_p)`, P `n·(v_c(P) − v_p(P))`.
fn rate_row(j: &CJoint) -> Result<Row, String> {
    let on = Carrier::of(j.parent);
    let shape = match j.kind {
        CJointKind::Revolute { axis } => Shape::Angular { a: unit(axis)?, on },
        CJointKind::Prismatic { axis } => Shape::Point {
            a: unit(axis)?,
            on,
            p: j.point,
        },
        _ => return Err("only revolute and prismatic joints can be actuated".into()),
    };
    Ok(Row {
        child: j.child,
        parent: j.parent,
        shape,
    })
}

/// The constraint rows of a joint.
fn joint_rows(j: &CJoint) -> Result<Vec<Row>, String> {
    let on = Carrier::of(j.parent);
    let row = |shape| Row {
        child: j.child,
        parent: j.parent,
        shape,
    };
    let points = |out: &mut Vec<Row>| {
        for e in E {
            out.push(row(Shape::Point {
                a: e,
                on: Carrier::Base,
                p: j.point,
            }));
        }
    };
    let mut out = Vec::new();
    match j.kind {
        CJointKind::Revolute { axis } => {
            let (a1, a2) = perpendiculars(unit(axis)?);
            out.push(row(Shape::Angular { a: a1, on }));
            out.push(row(Shape::Angular { a: a2, on }));
            points(&mut out);
        }
        CJointKind::Prismatic { axis } => {
            let (a1, a2) = perpendiculars(unit(axis)?);
            for e in E {
                out.push(row(Shape::Angular {
                    a: e,
                    on: Carrier::Base,
                }));
            }
            out.push(row(Shape::Point {
                a: a1,
                on,
                p: j.point,
            }));
            out.push(row(Shape::Point {
                a: a2,
                on,
                p: j.point,
            }));
        }
        CJointKind::Universal {
            axis_parent,
            axis_child,
        } => {
            let ap = unit(axis_parent)?;
            let ac = unit(axis_child)?;
            if norm(cross(ap, ac)) < 1e-9 {
                return Err("the two axes of a universal joint are parallel".into());
            }
            out.push(row(Shape::Cross { ap, ac }));
            points(&mut out);
        }
        CJointKind::Spherical => points(&mut out),
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Least squares by SVD with row and column scaling.
//
// The SVD is a one-sided Jacobi (Hestenes) SVD written here: nalgebra 0.35's bidiagonal SVD does
// not always reproduce its input (`U Σ Vᵀ − A` up to 1e-4 for some well-conditioned 48 × 48
// constraint matrices met in the tests; cf. nalgebra issue #1172), while Jacobi's method is
// accurate to a few ulps of the largest singular value.

/// `A = U Σ Vᵀ` with `U` (m × k), `V` (n × k), `k = min(m, n)`.
struct Svd {
    u: DMatrix<f64>,
    s: Vec<f64>,
    v: DMatrix<f64>,
}

impl Svd {
    fn new(a: &DMatrix<f64>) -> Svd {
        if a.nrows() < a.ncols() {
            let t = Svd::new(&a.transpose());
            return Svd {
                u: t.v,
                s: t.s,
                v: t.u,
            };
        }
        let (m, n) = a.shape();
        let mut u = a.clone();
        let mut v = DMatrix::<f64>::identity(n, n);
        // Column-major storage: column j is data[j·rows .. (j + 1)·rows].
        fn pair(data: &mut [f64], rows: usize, p: usize, q: usize) -> (&mut [f64], &mut [f64]) {
            let (left, right) = data.split_at_mut(q * rows);
            (&mut left[p * rows..(p + 1) * rows], &mut right[..rows])
        }
        fn turn(x: &mut [f64], y: &mut [f64], c: f64, s: f64) {
            for (x, y) in x.iter_mut().zip(y.iter_mut()) {
                let (a, b) = (*x, *y);
                *x = c * a - s * b;
                *y = s * a + c * b;
            }
        }
        // Columns shorter than ε‖A‖_F are rounding noise of a zero singular value: leave them.
        let tiny = (f64::EPSILON * a.norm()).powi(2);
        for _sweep in 0..100 {
            let mut rotated = false;
            for p in 0..n {
                for q in p + 1..n {
                    let (up, uq) = pair(u.as_mut_slice(), m, p, q);
                    let (mut alpha, mut beta, mut gamma) = (0.0, 0.0, 0.0);
                    for (x, y) in up.iter().zip(uq.iter()) {
                        alpha += x * x;
                        beta += y * y;
                        gamma += x * y;
                    }
                    if alpha <= tiny
                        || beta <= tiny
                        || gamma.abs() <= 2.0 * f64::EPSILON * (alpha * beta).sqrt()
                    {
                        continue;
                    }
                    rotated = true;
                    // The rotation that makes columns p and q orthogonal.
                    let zeta = (beta - alpha) / (2.0 * gamma);
                    let t = zeta.signum() / (zeta.abs() + (1.0 + zeta * zeta).sqrt());
                    let c = 1.0 / (1.0 + t * t).sqrt();
                    let s = c * t;
                    turn(up, uq, c, s);
                    let (vp, vq) = pair(v.as_mut_slice(), n, p, q);
                    turn(vp, vq, c, s);
                }
            }
            if !rotated {
                break;
            }
        }
        let s: Vec<f64> = (0..n).map(|j| u.column(j).norm()).collect();
        for (j, sj) in s.iter().enumerate() {
            if *sj > 0.0 {
                u.column_mut(j).scale_mut(1.0 / sj);
            }
        }
        Svd { u, s, v }
    }
}

/// A factorized `D_r A D_c` (rows, then columns scaled to unit norm).
struct Lsq {
    svd: Svd,
    row: Vec<f64>,
    col: Vec<f64>,
    eps: f64,
    rank: usize,
}

impl Lsq {
    fn new(a: &DMatrix<f64>) -> Lsq {
        let mut s = a.clone();
        let row: Vec<f64> = (0..s.nrows())
            .map(|i| {
                let n = s.row(i).norm();
                if n > 0.0 { 1.0 / n } else { 1.0 }
            })
            .collect();
        for (i, r) in row.iter().enumerate() {
            s.row_mut(i).scale_mut(*r);
        }
        let col: Vec<f64> = (0..s.ncols())
            .map(|j| {
                let n = s.column(j).norm();
                if n > 0.0 { 1.0 / n } else { 1.0 }
            })
            .collect();
        for (j, c) in col.iter().enumerate() {
            s.column_mut(j).scale_mut(*c);
        }
        let svd = Svd::new(&s);
        let smax = svd.s.iter().copied().fold(0.0, f64::max);
        let eps = RANK_TOLERANCE * smax;
        let rank = svd.s.iter().filter(|s| **s > eps).count();
        Lsq {
            svd,
            row,
            col,
            eps,
            rank,
        }
    }

    /// The minimum-norm least-squares solution `x = D_c V Σ⁺ Uᵀ D_r b` (singular values `≤ eps`
    /// dropped).
    fn solve(&self, b: &DVector<f64>) -> DVector<f64> {
        let bs = DVector::from_iterator(b.len(), b.iter().zip(&self.row).map(|(b, r)| b * r));
        let mut c = self.svd.u.transpose() * bs;
        for (k, s) in self.svd.s.iter().enumerate() {
            c[k] = if *s > self.eps { c[k] / s } else { 0.0 };
        }
        let y = &self.svd.v * c;
        DVector::from_iterator(y.len(), y.iter().zip(&self.col).map(|(y, c)| y * c))
    }
}

/// `max_i |(A x − b)_i| / max(max_ij |A_ij x_j|, max_i |b_i|)` (0 when everything is zero).
fn relative_residual(a: &DMatrix<f64>, x: &DVector<f64>, b: &DVector<f64>) -> f64 {
    let r = a * x - b;
    let mut big = b.amax();
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            big = big.max((a[(i, j)] * x[j]).abs());
        }
    }
    let num = r.amax();
    if num.is_nan() {
        f64::INFINITY
    } else if big == 0.0 {
        num
    } else {
        num / big
    }
}

fn to_twists(x: &DVector<f64>, r: usize) -> Vec<[f64; 6]> {
    (0..r)
        .map(|b| std::array::from_fn(|k| x[6 * b + k]))
        .collect()
}

fn check(sys: &CSystem) -> Result<(), String> {
    let r = sys.bodies.len();
    for (i, j) in sys.joints.iter().enumerate() {
        if j.child >= r || j.parent.is_some_and(|p| p >= r) {
            return Err(format!("joint {i}: body index out of range"));
        }
        if j.parent == Some(j.child) {
            return Err(format!("joint {i}: parent and child are the same body"));
        }
    }
    Ok(())
}

/// Inverse dynamics by the full Newton–Euler equations with Lagrange multipliers (module docs).
///
/// `u`, `ud`: the prescribed speeds and their rates (see [`Prescribed`]). Errors: wrong lengths,
/// bad indices or axes, twists not determined by the constraints (rank of `K` below `6r`),
/// constraints that cannot all hold, efforts not unique, or Newton–Euler equations that the
/// actuators cannot balance (a motion the mechanism cannot perform with these actuators).
pub fn inverse_dynamics(
    sys: &CSystem,
    prescribed: &Prescribed,
    u: &[f64],
    ud: &[f64],
) -> Result<Solution, String> {
    check(sys)?;
    let r = sys.bodies.len();
    let n = 6 * r;

    // Joint rows (reactions) and actuator rate rows.
    let mut rows: Vec<Row> = Vec::new();
    for (i, j) in sys.joints.iter().enumerate() {
        rows.extend(joint_rows(j).map_err(|e| format!("joint {i}: {e}"))?);
    }
    let n_joint_rows = rows.len();
    let mut actuators = Vec::new();
    for (i, j) in sys.joints.iter().enumerate() {
        if j.actuated {
            actuators.push(rate_row(j).map_err(|e| format!("joint {i}: {e}"))?);
        }
    }

    // Prescribed rows.
    let mut prescribed_rows: Vec<Row> = Vec::new();
    let body_ok = |b: usize| {
        if b < r {
            Ok(())
        } else {
            Err(format!("prescribed body {b} out of range"))
        }
    };
    match *prescribed {
        Prescribed::Pose { body, point } => {
            body_ok(body)?;
            for e in E {
                prescribed_rows.push(Row {
                    child: body,
                    parent: None,
                    shape: Shape::Angular {
                        a: e,
                        on: Carrier::Base,
                    },
                });
            }
            for e in E {
                prescribed_rows.push(Row {
                    child: body,
                    parent: None,
                    shape: Shape::Point {
                        a: e,
                        on: Carrier::Base,
                        p: point,
                    },
                });
            }
        }
        Prescribed::Orientation { body } => {
            body_ok(body)?;
            for e in E {
                prescribed_rows.push(Row {
                    child: body,
                    parent: None,
                    shape: Shape::Angular {
                        a: e,
                        on: Carrier::Base,
                    },
                });
            }
        }
        Prescribed::ActuatedJoints => prescribed_rows.extend(actuators.iter().copied()),
    }
    if u.len() != prescribed_rows.len() || ud.len() != prescribed_rows.len() {
        return Err(format!(
            "{} prescribed speeds expected, got u: {}, u̇: {}",
            prescribed_rows.len(),
            u.len(),
            ud.len()
        ));
    }
    rows.extend(prescribed_rows);
    let m = rows.len();

    // 1. Velocity level.
    let mut k = DMatrix::<f64>::zeros(m, n);
    for (i, row) in rows.iter().enumerate() {
        let (kc, kp) = row.vectors(sys);
        for c in 0..6 {
            k[(i, 6 * row.child + c)] += kc[c];
            if let Some(p) = row.parent {
                k[(i, 6 * p + c)] += kp[c];
            }
        }
    }
    let mut rho = DVector::<f64>::zeros(m);
    for (i, v) in u.iter().enumerate() {
        rho[n_joint_rows + i] = *v;
    }
    let lsq = Lsq::new(&k);
    if lsq.rank < n {
        return Err(format!(
            "the constraints do not determine the twists: rank of K is {} < {} (6 × {} bodies)",
            lsq.rank, n, r
        ));
    }
    let tx = lsq.solve(&rho);
    let vres = relative_residual(&k, &tx, &rho);
    let twists = to_twists(&tx, r);

    // 2. Acceleration level.
    let mut rhod = DVector::<f64>::zeros(m);
    for (i, row) in rows.iter().enumerate() {
        rhod[i] = -row.bias(sys, &twists);
    }
    for (i, v) in ud.iter().enumerate() {
        rhod[n_joint_rows + i] += *v;
    }
    let tdx = lsq.solve(&rhod);
    let ares = relative_residual(&k, &tdx, &rhod);
    let twist_rates = to_twists(&tdx, r);
    let velocity_residual = vres.max(ares);
    if velocity_residual.is_nan() || velocity_residual > RESIDUAL_TOLERANCE {
        return Err(format!(
            "the velocity/acceleration constraints cannot all hold: relative residual {velocity_residual:e}"
        ));
    }

    // 3. Dynamics: h_b = [I ω̇ + ω × Iω; m (c̈ − g)].
    let mut h = DVector::<f64>::zeros(n);
    for (b, body) in sys.bodies.iter().enumerate() {
        let w = ang(&twists[b]);
        let wd = ang(&twist_rates[b]);
        let iw = mat_vec(&body.inertia, &w);
        let mom = add(mat_vec(&body.inertia, &wd), cross(w, iw));
        let f = scale(body.mass, sub(lin(&twist_rates[b]), sys.gravity));
        for c in 0..3 {
            h[6 * b + c] = mom[c];
            h[6 * b + 3 + c] = f[c];
        }
    }
    // Springs: the force on each end, `∓T n` (`n` from a to b), moved to the mass centre.
    for s in &sys.springs {
        let vel = |body: Option<usize>, p: &Vec3| {
            body.map_or([0.0; 3], |b| {
                let r = sub(*p, sys.bodies[b].com);
                add(lin(&twists[b]), cross(ang(&twists[b]), r))
            })
        };
        let d = sub(s.point_b, s.point_a);
        let l = dot(d, d).sqrt();
        let n = scale(1.0 / l, d);
        let ldot = dot(n, sub(vel(s.b, &s.point_b), vel(s.a, &s.point_a)));
        let t = s.stiffness * (l - s.rest_length) + s.damping * ldot;
        for (body, p, sign) in [(s.a, &s.point_a, 1.0), (s.b, &s.point_b, -1.0)] {
            if let Some(b) = body {
                let force = scale(sign * t, n);
                let mom = cross(sub(*p, sys.bodies[b].com), force);
                for c in 0..3 {
                    h[6 * b + c] -= mom[c];
                    h[6 * b + 3 + c] -= force[c];
                }
            }
        }
    }
    let na = actuators.len();
    let mut a = DMatrix::<f64>::zeros(n, n_joint_rows + na);
    for (col, row) in rows[..n_joint_rows].iter().chain(&actuators).enumerate() {
        let (kc, kp) = row.vectors(sys);
        for c in 0..6 {
            a[(6 * row.child + c, col)] += kc[c];
            if let Some(p) = row.parent {
                a[(6 * p + c, col)] += kp[c];
            }
        }
    }
    let full = Lsq::new(&a);
    let reactions = Lsq::new(&a.columns(0, n_joint_rows).into_owned());
    if full.rank != reactions.rank + na {
        return Err(format!(
            "the actuator efforts are not unique: rank [K_Jᵀ A] = {} but rank K_Jᵀ = {} with {} actuators",
            full.rank, reactions.rank, na
        ));
    }
    let x = full.solve(&h);
    let force_residual = relative_residual(&a, &x, &h);
    if force_residual.is_nan() || force_residual > RESIDUAL_TOLERANCE {
        return Err(format!(
            "the actuators and joints cannot balance the Newton–Euler equations: relative residual {force_residual:e}"
        ));
    }
    let efforts = (0..na).map(|i| x[n_joint_rows + i]).collect();
    Ok(Solution {
        efforts,
        twists,
        twist_rates,
        velocity_residual,
        force_residual,
    })
}

/// The rates `q̇` of the actuated joints (joint order) read off the solved twists: R
/// `n·(ω_c − ω_p)`, P `n·(v_c(P) − v_p(P))`.
pub fn actuated_rates(sys: &CSystem, sol: &Solution) -> Result<Vec<f64>, String> {
    sys.joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| Ok(rate_row(j)?.apply(sys, &sol.twists)))
        .collect()
}

/// The accelerations `q̈` of the actuated joints (joint order) from the twists and twist rates:
/// the time derivative of the rate rows, `kᵀ ṫ + k̇ᵀ t`.
pub fn actuated_accelerations(sys: &CSystem, sol: &Solution) -> Result<Vec<f64>, String> {
    sys.joints
        .iter()
        .filter(|j| j.actuated)
        .map(|j| {
            let row = rate_row(j)?;
            Ok(row.apply(sys, &sol.twist_rates) + row.bias(sys, &sol.twists))
        })
        .collect()
}

/// Kinetic energy `Σ ½ t_bᵀ M_b t_b` at the solved twists.
pub fn kinetic_energy(sys: &CSystem, sol: &Solution) -> f64 {
    sys.bodies
        .iter()
        .zip(&sol.twists)
        .map(|(b, t)| {
            let w = ang(t);
            let v = lin(t);
            0.5 * (dot(w, mat_vec(&b.inertia, &w)) + b.mass * dot(v, v))
        })
        .sum()
}

/// `d/dt (kinetic + potential energy) = Σ_b t_bᵀ (M_b ṫ_b + W_b M_b t_b) − Σ_b m_b g·ċ_b`, exact
/// from the twists and twist rates (`Ṁ_b = W_b M_b − M_b W_b`, so `d/dt ½ tᵀMt = tᵀ(Mṫ + WMt)`;
/// the `W` term is `ω·(ω × Iω) = 0` up to rounding).
pub fn energy_rate(sys: &CSystem, sol: &Solution) -> f64 {
    sys.bodies
        .iter()
        .zip(sol.twists.iter().zip(&sol.twist_rates))
        .map(|(b, (t, td))| {
            let w = ang(t);
            let wd = ang(td);
            let iw = mat_vec(&b.inertia, &w);
            let n = add(mat_vec(&b.inertia, &wd), cross(w, iw));
            let f = scale(b.mass, lin(td));
            dot(w, n) + dot(lin(t), f) - b.mass * dot(sys.gravity, lin(t))
        })
        .sum()
}

/// The largest mismatch of the loop-closing joints recorded in [`CSystem::closure`]: the distance
/// (m) between the two sides' joint centres (spherical) or between the two sides' unit axes
/// (revolute). 0 when there is nothing recorded.
pub fn closure_residual(sys: &CSystem) -> f64 {
    sys.closure
        .iter()
        .map(|c| norm(sub(c.on_parent, c.on_child)))
        .fold(0.0, f64::max)
}

// ---------------------------------------------------------------------------------------------
// Builders.

fn rotate_inertia(r: &Mat3, i: &Mat3) -> Mat3 {
    mat_mul(&mat_mul(r, i), &transpose(r))
}

/// `X_parent · origin · motion(q)` and the joint's world axis and point.
struct Placed {
    pose: Transform,
    kind: CJointKind,
    point: Vec3,
}

fn place(parent: &Transform, j: &runtime::model::Joint, q: f64) -> Placed {
    let frame = parent.compose(&j.origin);
    let axis = mat_vec(&frame.rotation, &j.axis);
    match j.kind {
        JointKind::Revolute => Placed {
            pose: frame.compose(&Transform {
                rotation: axis_angle(&j.axis, q),
                translation: [0.0; 3],
            }),
            kind: CJointKind::Revolute { axis },
            point: frame.translation,
        },
        JointKind::Prismatic => {
            let pose = frame.compose(&Transform {
                rotation: Transform::IDENTITY.rotation,
                translation: scale(q, j.axis),
            });
            Placed {
                point: pose.translation,
                pose,
                kind: CJointKind::Prismatic { axis },
            }
        }
    }
}

fn cbody(pose: &Transform, b: &runtime::model::Body) -> CBody {
    CBody {
        mass: b.mass,
        com: pose.apply(&b.com),
        inertia: rotate_inertia(&pose.rotation, &b.inertia),
    }
}

/// A tree model at `q` (model conventions: body `i` is moved by joint `i`, body frame = joint
/// frame after the motion). Every joint is actuated; joint `i` has child `i`.
pub fn from_tree(model: &Model, q: &[f64]) -> CSystem {
    assert_eq!(q.len(), model.dof(), "q has the wrong length");
    let mut poses: Vec<Transform> = Vec::with_capacity(model.dof());
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    for (i, j) in model.joints.iter().enumerate() {
        let parent = j.parent.map_or(Transform::IDENTITY, |p| poses[p]);
        let pl = place(&parent, j, q[i]);
        bodies.push(cbody(&pl.pose, &model.bodies[i]));
        joints.push(CJoint {
            parent: j.parent,
            child: i,
            point: pl.point,
            kind: pl.kind,
            actuated: true,
        });
        poses.push(pl.pose);
    }
    CSystem::new(bodies, joints, model.gravity)
}

/// Rotation matrix of the quaternion `[w, x, y, z]` (normalized first).
pub fn quaternion_matrix(q: [f64; 4]) -> Mat3 {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// The platform frame's pose from `x` (`Pose`: `[p; quaternion]`, `Orientation`: quaternion,
/// origin at the centre).
pub fn platform_pose(motion: PlatformMotion, x: &[f64]) -> Transform {
    match motion {
        PlatformMotion::Pose => Transform {
            rotation: quaternion_matrix([x[3], x[4], x[5], x[6]]),
            translation: [x[0], x[1], x[2]],
        },
        PlatformMotion::Orientation { centre } => Transform {
            rotation: quaternion_matrix([x[0], x[1], x[2], x[3]]),
            translation: centre,
        },
        // A point in the plane z = height; its frame does not turn.
        PlatformMotion::PlanarPoint { height } => Transform {
            rotation: quaternion_matrix([1.0, 0.0, 0.0, 0.0]),
            translation: [x[0], x[1], height],
        },
        // The origin; the orientation stays fixed (a Schönflies carrier's too: the tool is the
        // shaft leg's last body).
        PlatformMotion::Translation { rotation } | PlatformMotion::Schoenflies { rotation } => {
            Transform {
                rotation,
                translation: [x[0], x[1], x[2]],
            }
        }
        // The origin in the plane z = height; the home rotation turned by φ about z.
        PlatformMotion::PlanarPose { height, rotation } => {
            let (s, c) = x[2].sin_cos();
            let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
            Transform {
                rotation: runtime::model::mat_mul(&rz, &rotation),
                translation: [x[0], x[1], height],
            }
        }
        // The parasitic components come from the legs: the caller passes the model as a
        // 6-DOF pose with `x = noc::platform_pose(plan, x)` (tests/tests/prs.rs).
        PlatformMotion::HeaveTilt { .. } => {
            panic!("a 1T2R platform's pose needs its parasitic components: pass it as a pose")
        }
    }
}

/// A parallel manipulator with the leg joint values `leg_q` and platform coordinates `x`.
///
/// Bodies: leg 0's bodies, leg 1's, …, then the platform (last). Joints: every leg's joints, leg
/// by leg (parent: the previous body of the leg, or the base), then one end joint per leg, in leg
/// order, from the leg's last body (parent) to the platform (child): a spherical joint at the
/// platform's point, or a revolute joint about the leg's end axis (carried by the leg's last body)
/// through the orientation centre. The actuated joints are the legs' actuated joints, so the
/// efforts come in leg order. `leg_q` need not close the loops: see [`closure_residual`], fed
/// from [`CSystem::closure`] (leg side = parent side).
pub fn from_parallel(model: &ParallelModel, leg_q: &[Vec<f64>], x: &[f64]) -> CSystem {
    assert_eq!(leg_q.len(), model.legs.len(), "one leg_q per leg");
    assert_eq!(x.len(), model.motion.nx(), "x has the wrong length");
    let plat = platform_pose(model.motion, x);
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    let mut last = Vec::new();
    for (leg, q) in model.legs.iter().zip(leg_q) {
        assert_eq!(
            q.len(),
            leg.joints.len(),
            "leg {}: wrong leg_q length",
            leg.name
        );
        let first = bodies.len();
        let mut pose = Transform::IDENTITY;
        for (k, j) in leg.joints.iter().enumerate() {
            let pl = place(&pose, j, q[k]);
            bodies.push(cbody(&pl.pose, &leg.bodies[k]));
            joints.push(CJoint {
                parent: if k == 0 { None } else { Some(first + k - 1) },
                child: first + k,
                point: pl.point,
                kind: pl.kind,
                actuated: k == leg.actuated,
            });
            pose = pl.pose;
        }
        last.push((bodies.len() - 1, pose));
    }
    let p = bodies.len();
    bodies.push(cbody(&plat, &model.platform));
    let mut closure = Vec::new();
    for (leg, (lb, lpose)) in model.legs.iter().zip(last) {
        let (kind, point, on_parent, on_child) = match leg.end {
            LegEnd::Spherical {
                on_leg,
                on_platform,
            } => {
                let at = plat.apply(&on_platform);
                (CJointKind::Spherical, at, lpose.apply(&on_leg), at)
            }
            LegEnd::Revolute {
                on_leg,
                on_platform,
            } => {
                let axis = mat_vec(&lpose.rotation, &on_leg);
                let centre = match model.motion {
                    PlatformMotion::Orientation { centre } => centre,
                    PlatformMotion::Pose
                    | PlatformMotion::PlanarPoint { .. }
                    | PlatformMotion::Translation { .. }
                    | PlatformMotion::PlanarPose { .. }
                    | PlatformMotion::HeaveTilt { .. }
                    | PlatformMotion::Schoenflies { .. } => plat.translation,
                };
                (
                    CJointKind::Revolute { axis },
                    centre,
                    axis,
                    mat_vec(&plat.rotation, &on_platform),
                )
            }
        };
        closure.push(Coincidence {
            joint: joints.len(),
            on_parent,
            on_child,
        });
        joints.push(CJoint {
            parent: Some(lb),
            child: p,
            point,
            kind,
            actuated: false,
        });
    }
    CSystem {
        bodies,
        joints,
        gravity: model.gravity,
        closure,
        springs: Vec::new(),
    }
}

/// A closed-loop mechanism in joint coordinates at the joint positions `x` (which should close
/// the loops; see [`closure_residual`], fed from [`CSystem::closure`]). Bodies and joints as in
/// [`from_tree`], then one joint per cut (parent: the cut's parent body, or the base; a cut to
/// the base is written with the base as parent). Only the independent joints are actuated, so
/// the efforts come in increasing joint order.
pub fn from_closed(model: &runtime::closed::ClosedModel, x: &[f64]) -> CSystem {
    let tree = &model.tree;
    let mut sys = from_tree(tree, x);
    for (i, j) in sys.joints.iter_mut().enumerate() {
        j.actuated = model.independent.contains(&i);
    }
    // Body poses again (from_tree keeps only the Cartesian data).
    let mut poses: Vec<Transform> = Vec::with_capacity(tree.dof());
    for (i, j) in tree.joints.iter().enumerate() {
        let parent = j.parent.map_or(Transform::IDENTITY, |p| poses[p]);
        poses.push(place(&parent, j, x[i]).pose);
    }
    let pose_of = |b: Option<usize>| b.map_or(Transform::IDENTITY, |b| poses[b]);
    for cut in &model.cuts {
        let fa = pose_of(cut.parent).compose(&cut.frame_parent);
        let fb = pose_of(cut.child).compose(&cut.frame_child);
        let (parent, child) = match (cut.parent, cut.child) {
            (p, Some(c)) => (p, c),
            (Some(p), None) => (None, p),
            (None, None) => continue,
        };
        let (kind, on_parent, on_child) = match cut.kind {
            runtime::closed::CutKind::Revolute { axis } => {
                let a = mat_vec(&fa.rotation, &axis);
                (
                    CJointKind::Revolute { axis: a },
                    a,
                    mat_vec(&fb.rotation, &axis),
                )
            }
            runtime::closed::CutKind::Spherical => {
                (CJointKind::Spherical, fa.translation, fb.translation)
            }
        };
        sys.closure.push(Coincidence {
            joint: sys.joints.len(),
            on_parent,
            on_child,
        });
        if let CJointKind::Revolute { .. } = kind {
            sys.closure.push(Coincidence {
                joint: sys.joints.len(),
                on_parent: fa.translation,
                on_child: fb.translation,
            });
        }
        sys.joints.push(CJoint {
            parent,
            child,
            point: fb.translation,
            kind,
            actuated: false,
        });
    }
    for s in &model.springs {
        let at = |b: Option<usize>, p: &Vec3| pose_of(b).apply(p);
        sys.springs.push(CSpring {
            a: s.body_a,
            point_a: at(s.body_a, &s.point_a),
            b: s.body_b,
            point_b: at(s.body_b, &s.point_b),
            stiffness: s.stiffness,
            rest_length: s.rest_length,
            damping: s.damping,
        });
    }
    sys
}
