//! The Lagrange-multiplier route (`references::lagrange`: full Newton–Euler of every body, reactions
//! and efforts as multipliers) against independent routes:
//! * trees and serial chains (R and P joints, massless U/S-style expansions): the spatial RNEA
//!   (`runtime::rnea`) and the literal NOC (`runtime::noc`);
//! * a planar four-bar linkage in a tilted plane (redundant in 3-D): static efforts by virtual work
//!   with finite differences of the potential energy, the dynamic effort by the textbook
//!   loop-closure kinematics (complex-number loop equation) and d'Alembert's virtual work, and the
//!   power balance `τ q̇ = d/dt (T + V)`;
//! * hand-built parallel manipulators (`runtime::parallel::ParallelModel`): a 6-UPS hexapod and a
//!   spherical 3-RRR, at home and at poses from inverse kinematics written here, checked by loop
//!   closure, finite differences of the leg lengths, the power balance and virtual work along
//!   every independent admissible motion.
//!
//! Error norm (unless stated): ‖a − b‖∞ / max(‖b‖∞, 1) (`tests::rel_err`).

use rand::Rng;
use references::lagrange::{
    CBody, CJoint, CJointKind, CSystem, Prescribed, Solution, actuated_accelerations,
    actuated_rates, closure_residual, energy_rate, from_parallel, from_tree, inverse_dynamics,
    quaternion_matrix,
};
use runtime::model::{Body, Joint, JointKind, Mat3, Model, Transform, Vec3, mat_vec, transpose};
use runtime::parallel::{Leg, LegEnd, ParallelModel, PlatformMotion};
use tests::{Shape, inertia, random_model, random_state, rel_err, rng, unit};

const TOL: f64 = 1e-10;

// ---------------------------------------------------------------------------------------------
// Helpers (own vector algebra).

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
fn normalize(a: Vec3) -> Vec3 {
    scale(1.0 / norm(a), a)
}
fn ang(t: &[f64; 6]) -> Vec3 {
    [t[0], t[1], t[2]]
}
fn lin(t: &[f64; 6]) -> Vec3 {
    [t[3], t[4], t[5]]
}
fn columns(x: Vec3, y: Vec3, z: Vec3) -> Mat3 {
    [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
}
/// Rodrigues' rotation, written here (not `runtime::model::axis_angle`).
fn rot(axis: Vec3, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let [x, y, z] = axis;
    let v = 1.0 - c;
    [
        [c + x * x * v, x * y * v - z * s, x * z * v + y * s],
        [y * x * v + z * s, c + y * y * v, y * z * v - x * s],
        [z * x * v - y * s, z * y * v + x * s, c + z * z * v],
    ]
}
fn mm(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}
/// Unit quaternion `[w, x, y, z]` of a rotation.
fn matrix_quaternion(r: &Mat3) -> [f64; 4] {
    tests::pkm::matrix_quaternion(r)
}

/// Body wrench `h_b = [I ω̇ + ω × Iω; m (c̈ − g)]` (docs/method.md, "Rigid bodies: twists, wrenches, Newton–Euler").
fn ne_wrench(sys: &CSystem, sol: &Solution, b: usize) -> [f64; 6] {
    let body = &sys.bodies[b];
    let (t, td) = (&sol.twists[b], &sol.twist_rates[b]);
    let w = ang(t);
    let n = add(
        mat_vec(&body.inertia, &ang(td)),
        cross(w, mat_vec(&body.inertia, &w)),
    );
    let f = scale(body.mass, sub(lin(td), sys.gravity));
    [n[0], n[1], n[2], f[0], f[1], f[2]]
}

/// `|a − b| / max(|a|, |b|, scale)`.
fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs()).max(scale)
}

/// Sum of the magnitudes of the terms of the energy rate (the scale of the power balance).
fn power_scale(sys: &CSystem, sol: &Solution) -> f64 {
    (0..sys.bodies.len())
        .map(|b| {
            let h = ne_wrench(sys, sol, b);
            let t = &sol.twists[b];
            (0..6).map(|k| (t[k] * h[k]).abs()).sum::<f64>()
        })
        .sum()
}

fn solve(sys: &CSystem, p: &Prescribed, u: &[f64], ud: &[f64]) -> Solution {
    match inverse_dynamics(sys, p, u, ud) {
        Ok(s) => s,
        Err(e) => panic!("inverse_dynamics failed: {e}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Trees and chains.

fn check_tree(model: &Model, seed: u64, worst: &mut [f64; 4]) {
    let mut r = rng(seed);
    for _ in 0..5 {
        let (q, qd, qdd) = random_state(&mut r, model.dof());
        let sys = from_tree(model, &q);
        let sol = solve(&sys, &Prescribed::ActuatedJoints, &qd, &qdd);
        let rnea = runtime::rnea::inverse_dynamics(model, &q, &qd, &qdd);
        let noc = runtime::noc::inverse_dynamics(model, &q, &qd, &qdd);
        let kin = runtime::noc::kinematics(model, &q, &qd);
        let tw: Vec<f64> = sol.twists.iter().flatten().copied().collect();
        let tw_ref: Vec<f64> = (0..model.dof())
            .flat_map(|i| {
                let (w, v) = (kin.omega[i], kin.com_velocity[i]);
                [w[0], w[1], w[2], v[0], v[1], v[2]]
            })
            .collect();
        let e = [
            rel_err(&sol.efforts, rnea.as_slice()),
            rel_err(&sol.efforts, noc.as_slice()),
            rel_err(&tw, &tw_ref),
            sol.velocity_residual.max(sol.force_residual),
        ];
        for (w, e) in worst.iter_mut().zip(e) {
            *w = w.max(e);
        }
        // The rates and accelerations read back from the twists are the prescribed ones.
        let qd_back = actuated_rates(&sys, &sol).unwrap();
        let qdd_back = actuated_accelerations(&sys, &sol).unwrap();
        assert!(rel_err(&qd_back, &qd) <= TOL, "q̇ read back");
        assert!(rel_err(&qdd_back, &qdd) <= TOL, "q̈ read back");
    }
}

fn assert_worst(what: &str, worst: &[f64; 4]) {
    eprintln!(
        "{what}: worst τ/RNEA {:.1e}, τ/NOC {:.1e}, twists/NOC {:.1e}, residual {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    for (k, w) in worst.iter().enumerate() {
        assert!(*w <= TOL, "{what}: check {k}: {w:e} > {TOL:e}");
    }
}

#[test]
fn trees_and_chains_agree_with_rnea_and_noc() {
    let mut worst = [0.0f64; 4];
    for seed in 0..48u64 {
        let shape = Shape {
            joints: 1 + (seed as usize % 9),
            prismatic: [0.0, 0.3, 0.6][seed as usize % 3],
            chain: seed % 2 == 0,
            coordinate_axes: seed % 5 == 0,
        };
        let model = random_model(seed, shape);
        check_tree(&model, 1000 + seed, &mut worst);
    }
    assert_worst("random trees/chains (R, P)", &worst);
}

/// Expanded U and S joints: two or three revolutes with a common point, the bodies between them
/// massless (mass 0, zero inertia).
#[test]
fn massless_expansions_agree_with_rnea_and_noc() {
    let mut worst = [0.0f64; 4];
    for seed in 0..24u64 {
        let group = 2 + (seed as usize % 2); // U (2) or S (3)
        let shape = Shape {
            joints: 3 * group,
            prismatic: 0.0,
            chain: seed % 3 != 0,
            coordinate_axes: false,
        };
        let mut model = random_model(500 + seed, shape);
        for i in 0..model.dof() {
            if i % group != group - 1 {
                model.bodies[i].mass = 0.0;
                model.bodies[i].com = [0.0; 3];
                model.bodies[i].inertia = [[0.0; 3]; 3];
            }
            if i % group != 0 {
                // The joint sits at its (massless) parent's origin: the axes intersect.
                model.joints[i].parent = Some(i - 1);
                model.joints[i].origin.translation = [0.0; 3];
            }
        }
        check_tree(&model, 2000 + seed, &mut worst);
    }
    assert_worst("U/S expansions with massless bodies", &worst);
}

// ---------------------------------------------------------------------------------------------
// Planar four-bar linkage in a tilted plane.

/// Four-bar A-B-C-D: crank AB (a) driven at A, coupler BC (b), rocker DC (c), ground AD (d).
struct FourBar {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    /// Plane → base rotation; the plane's normal is `frame · e_z`.
    frame: Mat3,
    origin: Vec3,
    /// Mass-centre offsets in each link's frame (x along the link, z off the plane).
    offsets: [Vec3; 3],
    masses: [f64; 3],
    inertias: [Mat3; 3],
    gravity: Vec3,
}

/// The textbook solution at one crank state: link angles, rates and accelerations.
struct Planar {
    th: [f64; 3],
    thd: [f64; 3],
    thdd: [f64; 3],
    /// Link-frame origins (A, B, D) in plane coordinates.
    origins: [Vec3; 3],
}

fn e(th: f64) -> Vec3 {
    [th.cos(), th.sin(), 0.0]
}
fn ep(th: f64) -> Vec3 {
    [-th.sin(), th.cos(), 0.0]
}

impl FourBar {
    fn new(seed: u64) -> FourBar {
        let mut r = rng(seed);
        let mut off = || {
            [
                r.random_range(0.1..0.6),
                r.random_range(-0.1..0.1),
                r.random_range(-0.2..0.2),
            ]
        };
        let offsets = [off(), off(), off()];
        let mut r = rng(seed + 1);
        let g = unit(&mut r);
        FourBar {
            a: 0.3,
            b: 0.9,
            c: 0.7,
            d: 1.0,
            frame: runtime::model::rpy_to_matrix([
                r.random_range(-3.0..3.0),
                r.random_range(-1.5..1.5),
                r.random_range(-3.0..3.0),
            ]),
            origin: [
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
            ],
            offsets: [
                scale(0.3, offsets[0]),
                scale(0.9, offsets[1]),
                scale(0.7, offsets[2]),
            ],
            masses: [
                r.random_range(0.5..3.0),
                r.random_range(0.5..3.0),
                r.random_range(0.5..3.0),
            ],
            inertias: [inertia(&mut r), inertia(&mut r), inertia(&mut r)],
            gravity: scale(9.81, g),
        }
    }

    /// Loop-closure kinematics `a e^{iθ₂} + b e^{iθ₃} − c e^{iθ₄} − d = 0`, differentiated twice
    /// (rates and accelerations from the 2×2 Jacobian).
    fn planar(&self, th2: f64, thd2: f64, thdd2: f64) -> Planar {
        let (a, b, c, d) = (self.a, self.b, self.c, self.d);
        let pa = [0.0, 0.0, 0.0];
        let pd = [d, 0.0, 0.0];
        let pb = scale(a, e(th2));
        let bd = sub(pd, pb);
        let dist = norm(bd);
        let along = (b * b - c * c + dist * dist) / (2.0 * dist);
        let h = (b * b - along * along).sqrt();
        let ub = scale(1.0 / dist, bd);
        let pc = add(pb, add(scale(along, ub), scale(h, [-ub[1], ub[0], 0.0])));
        let th3 = (pc[1] - pb[1]).atan2(pc[0] - pb[0]);
        let th4 = (pc[1] - pd[1]).atan2(pc[0] - pd[0]);
        // J [θ̇₃; θ̇₄] = r with J's columns ∂L/∂θ₃ = b e'(θ₃), ∂L/∂θ₄ = −c e'(θ₄).
        let j3 = scale(b, ep(th3));
        let j4 = scale(-c, ep(th4));
        let solve2 = |r: Vec3| {
            let det = j3[0] * j4[1] - j4[0] * j3[1];
            [
                (r[0] * j4[1] - j4[0] * r[1]) / det,
                (j3[0] * r[1] - r[0] * j3[1]) / det,
            ]
        };
        let [thd3, thd4] = solve2(scale(-a * thd2, ep(th2)));
        let rhs = scale(
            -1.0,
            add(
                add(scale(a * thdd2, ep(th2)), scale(-a * thd2 * thd2, e(th2))),
                add(
                    scale(-b * thd3 * thd3, e(th3)),
                    scale(c * thd4 * thd4, e(th4)),
                ),
            ),
        );
        let [thdd3, thdd4] = solve2(rhs);
        Planar {
            th: [th2, th3, th4],
            thd: [thd2, thd3, thd4],
            thdd: [thdd2, thdd3, thdd4],
            origins: [pa, pb, pd],
        }
    }

    fn normal(&self) -> Vec3 {
        mat_vec(&self.frame, &[0.0, 0.0, 1.0])
    }
    fn to_base(&self, p: Vec3) -> Vec3 {
        add(self.origin, mat_vec(&self.frame, &p))
    }

    /// Mass centre of link `i` in plane coordinates, and its velocity and acceleration.
    fn com(&self, s: &Planar, i: usize) -> (Vec3, Vec3, Vec3) {
        let o = self.offsets[i];
        let (th, thd, thdd) = (s.th[i], s.thd[i], s.thdd[i]);
        let rp = [
            o[0] * th.cos() - o[1] * th.sin(),
            o[0] * th.sin() + o[1] * th.cos(),
            o[2],
        ];
        let k = [0.0, 0.0, 1.0];
        // Velocity and acceleration of the link-frame origin: A fixed, B on the crank, D fixed.
        let (ov, oa) = if i == 1 {
            let (t, td, tdd) = (s.th[0], s.thd[0], s.thdd[0]);
            (
                scale(self.a * td, ep(t)),
                add(scale(self.a * tdd, ep(t)), scale(-self.a * td * td, e(t))),
            )
        } else {
            ([0.0; 3], [0.0; 3])
        };
        let inplane = [rp[0], rp[1], 0.0];
        let v = add(ov, scale(thd, cross(k, inplane)));
        let acc = add(
            oa,
            add(scale(thdd, cross(k, inplane)), scale(-thd * thd, inplane)),
        );
        (add(s.origins[i], rp), v, acc)
    }

    /// The hand-built 3-D system at a crank state; `actuated`: which of the four joints
    /// (A, B, C, D) carry actuators.
    fn system(&self, s: &Planar, actuated: [bool; 4]) -> CSystem {
        let n = self.normal();
        let bodies = (0..3)
            .map(|i| CBody {
                mass: self.masses[i],
                com: self.to_base(self.com(s, i).0),
                inertia: self.inertias[i],
            })
            .collect();
        let pc = add(s.origins[1], scale(self.b, e(s.th[1])));
        let pts = [s.origins[0], s.origins[1], pc, s.origins[2]];
        let links = [(None, 0), (Some(0), 1), (Some(1), 2), (None, 2)];
        let joints = (0..4)
            .map(|k| CJoint {
                parent: links[k].0,
                child: links[k].1,
                point: self.to_base(pts[k]),
                kind: CJointKind::Revolute { axis: n },
                actuated: actuated[k],
            })
            .collect();
        CSystem::new(bodies, joints, self.gravity)
    }

    /// d'Alembert / virtual work with the kinematic influence coefficients (θ̇₂ = 1):
    /// `τ = Σ m (a_c − g)·∂c/∂θ₂ + (n·I n) θ̈ᵢ ∂θᵢ/∂θ₂`.
    fn textbook_effort(&self, s: &Planar) -> f64 {
        let unit_rate = self.planar(s.th[0], 1.0, 0.0);
        let g = mat_vec(&transpose(&self.frame), &self.gravity);
        let n = self.normal();
        (0..3)
            .map(|i| {
                let (_, _, acc) = self.com(s, i);
                let (_, dc, _) = self.com(&unit_rate, i);
                let jn = dot(n, mat_vec(&self.inertias[i], &n));
                self.masses[i] * dot(sub(acc, g), dc) + jn * s.thdd[i] * unit_rate.thd[i]
            })
            .sum()
    }

    fn potential(&self, th2: f64) -> f64 {
        let s = self.planar(th2, 0.0, 0.0);
        (0..3)
            .map(|i| -self.masses[i] * dot(self.gravity, self.to_base(self.com(&s, i).0)))
            .sum()
    }
}

#[test]
fn four_bar_statics_by_virtual_work() {
    let mut worst = 0.0f64;
    for seed in 0..6u64 {
        let fb = FourBar::new(seed);
        for k in 0..8 {
            let th2 = -3.0 + 0.8 * k as f64 + 0.1 * seed as f64;
            let s = fb.planar(th2, 0.0, 0.0);
            let sys = fb.system(&s, [true, false, false, false]);
            let sol = solve(&sys, &Prescribed::ActuatedJoints, &[0.0], &[0.0]);
            let h = 1e-5;
            let fd = (fb.potential(th2 + h) - fb.potential(th2 - h)) / (2.0 * h);
            let err = rel_err(&sol.efforts, &[fd]);
            worst = worst.max(err);
        }
    }
    eprintln!("four-bar statics vs dV/dθ (central differences): worst {worst:.1e}");
    assert!(worst <= 1e-6, "{worst:e}");
}

#[test]
fn four_bar_dynamics_textbook_and_power() {
    let mut worst = [0.0f64; 5];
    let mut r = rng(77);
    for seed in 0..6u64 {
        let fb = FourBar::new(100 + seed);
        let n = fb.normal();
        for _ in 0..10 {
            let th2 = r.random_range(-3.1..3.1);
            let thd2 = r.random_range(-3.0..3.0);
            let thdd2 = r.random_range(-5.0..5.0);
            let s = fb.planar(th2, thd2, thdd2);
            let sys = fb.system(&s, [true, false, false, false]);
            let sol = solve(&sys, &Prescribed::ActuatedJoints, &[thd2], &[thdd2]);
            let tau_ref = fb.textbook_effort(&s);
            // Twists against the loop-closure kinematics.
            let mut tw = Vec::new();
            let mut tw_ref = Vec::new();
            for i in 0..3 {
                let (_, v, acc) = fb.com(&s, i);
                tw.extend(sol.twists[i]);
                tw.extend(sol.twist_rates[i]);
                let (w, wd) = (scale(s.thd[i], n), scale(s.thdd[i], n));
                let v = mat_vec(&fb.frame, &v);
                let acc = mat_vec(&fb.frame, &acc);
                tw_ref.extend([w[0], w[1], w[2], v[0], v[1], v[2]]);
                tw_ref.extend([wd[0], wd[1], wd[2], acc[0], acc[1], acc[2]]);
            }
            // The same motion prescribed by the crank's or the coupler's angular velocity.
            let by_crank = solve(
                &sys,
                &Prescribed::Orientation { body: 0 },
                &scale(thd2, n),
                &scale(thdd2, n),
            );
            let by_coupler = solve(
                &sys,
                &Prescribed::Orientation { body: 1 },
                &scale(s.thd[1], n),
                &scale(s.thdd[1], n),
            );
            let power = sol.efforts[0] * thd2;
            let e = [
                rel_err(&sol.efforts, &[tau_ref]),
                rel_err(&tw, &tw_ref),
                rel(power, energy_rate(&sys, &sol), power_scale(&sys, &sol)),
                rel_err(&by_crank.efforts, &[tau_ref])
                    .max(rel_err(&by_coupler.efforts, &[tau_ref])),
                sol.velocity_residual.max(sol.force_residual),
            ];
            for (w, e) in worst.iter_mut().zip(e) {
                *w = w.max(e);
            }
        }
    }
    eprintln!(
        "four-bar: worst τ/textbook {:.1e}, twists/textbook {:.1e}, power balance {:.1e}, \
         other prescriptions {:.1e}, residual {:.1e}",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
    for (k, w) in worst.iter().enumerate() {
        assert!(*w <= TOL, "check {k}: {w:e} > {TOL:e}");
    }
}

#[test]
fn four_bar_errors_are_reported() {
    let fb = FourBar::new(3);
    let s = fb.planar(0.7, 1.0, 0.5);
    let n = fb.normal();
    // Nothing prescribed: one degree of freedom left, K has rank 17 < 18.
    let sys = fb.system(&s, [false; 4]);
    let e = inverse_dynamics(&sys, &Prescribed::ActuatedJoints, &[], &[]).unwrap_err();
    assert!(e.contains("rank of K is 17 < 18"), "{e}");
    // Two actuators on one degree of freedom: efforts not unique.
    let sys = fb.system(&s, [true, false, false, true]);
    let e = inverse_dynamics(
        &sys,
        &Prescribed::Orientation { body: 1 },
        &scale(s.thd[1], n),
        &scale(s.thdd[1], n),
    )
    .unwrap_err();
    assert!(e.contains("not unique"), "{e}");
    // An angular velocity off the plane's normal cannot be followed.
    let sys = fb.system(&s, [true, false, false, false]);
    let w = add(
        scale(s.thd[0], n),
        scale(0.1, normalize(cross(n, [1.0, 0.0, 0.0]))),
    );
    let e =
        inverse_dynamics(&sys, &Prescribed::Orientation { body: 0 }, &w, &[0.0; 3]).unwrap_err();
    assert!(e.contains("cannot all hold"), "{e}");
    // No actuator: the Newton–Euler equations cannot be balanced (gravity acts).
    let sys = fb.system(&s, [false; 4]);
    let e = inverse_dynamics(
        &sys,
        &Prescribed::Orientation { body: 0 },
        &scale(s.thd[0], n),
        &scale(s.thdd[0], n),
    )
    .unwrap_err();
    assert!(e.contains("cannot balance"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// Parallel manipulators.

fn joint(kind: JointKind, origin: Transform, axis: Vec3, k: usize) -> Joint {
    Joint {
        name: format!("j{k}"),
        kind,
        parent: if k == 0 { None } else { Some(k - 1) },
        origin,
        axis,
        drive: Default::default(),
    }
}

fn body(name: &str, mass: f64, com: Vec3, inertia: Mat3) -> Body {
    Body {
        name: name.into(),
        mass,
        com,
        inertia,
    }
}

fn massless(name: &str) -> Body {
    body(name, 0.0, [0.0; 3], [[0.0; 3]; 3])
}

/// A 6-UPS hexapod: U at the base (two revolutes, a massless cross between them), the actuated
/// prismatic joint along the leg, S at the platform. Each leg's joint frame `L` has its `z` along
/// the leg at home, the U axes along its `x` and `y`.
struct Hexapod {
    model: ParallelModel,
    base: Vec<Vec3>,
    frames: Vec<Mat3>,
    lengths: Vec<f64>,
    on_platform: Vec<Vec3>,
}

fn hexapod() -> Hexapod {
    let mut r = rng(4242);
    let home_rot = runtime::model::rpy_to_matrix([0.05, -0.08, 0.3]);
    let home = Transform {
        rotation: home_rot,
        translation: [0.02, -0.03, 0.9],
    };
    let mut legs = Vec::new();
    let (mut base, mut frames, mut lengths, mut on_platform) = (vec![], vec![], vec![], vec![]);
    for i in 0..6 {
        let pair = (i / 2) as f64 * 2.0 * std::f64::consts::PI / 3.0;
        let sgn = if i % 2 == 0 { -1.0 } else { 1.0 };
        let ab = pair + sgn * 0.25;
        let ap = pair + std::f64::consts::PI / 3.0 + sgn * -0.7;
        let b = [1.0 * ab.cos(), 1.0 * ab.sin(), 0.0];
        let p = [0.5 * ap.cos(), 0.5 * ap.sin(), 0.05 * sgn];
        let s_home = home.apply(&p);
        let d = normalize(sub(s_home, b));
        let x = normalize(cross([0.0, 0.0, 1.0], d));
        let y = cross(d, x);
        let frame = columns(x, y, d);
        let len = norm(sub(s_home, b));
        let cyl = body(
            "cylinder",
            r.random_range(1.0..3.0),
            [0.01, -0.02, 0.25],
            inertia(&mut r),
        );
        let rod = body(
            "rod",
            r.random_range(0.5..1.5),
            [0.0, 0.01, len - 0.3],
            inertia(&mut r),
        );
        legs.push(Leg {
            name: format!("s{i}"),
            joints: vec![
                joint(
                    JointKind::Revolute,
                    Transform {
                        rotation: frame,
                        translation: b,
                    },
                    [1.0, 0.0, 0.0],
                    0,
                ),
                joint(JointKind::Revolute, Transform::IDENTITY, [0.0, 1.0, 0.0], 1),
                joint(
                    JointKind::Prismatic,
                    Transform::IDENTITY,
                    [0.0, 0.0, 1.0],
                    2,
                ),
            ],
            bodies: vec![massless("cross"), cyl, rod],
            actuated: 2,
            actuated_name: "j2".into(),
            actuated_home: 0.0,
            end: LegEnd::Spherical {
                on_leg: [0.0, 0.0, len],
                on_platform: p,
            },
        });
        base.push(b);
        frames.push(frame);
        lengths.push(len);
        on_platform.push(p);
    }
    let model = ParallelModel {
        name: "hexapod".into(),
        gravity: [0.3, -0.2, -9.81],
        motion: PlatformMotion::Pose,
        platform: body("platform", 6.0, [0.03, 0.02, 0.05], inertia(&mut r)),
        home,
        legs,
    };
    Hexapod {
        model,
        base,
        frames,
        lengths,
        on_platform,
    }
}

impl Hexapod {
    fn platform(x: &[f64]) -> Transform {
        Transform {
            rotation: quaternion_matrix([x[3], x[4], x[5], x[6]]),
            translation: [x[0], x[1], x[2]],
        }
    }
    /// Inverse kinematics written here: in the leg frame, `Rx(θ₀) Ry(θ₁) e_z = d/|d|`, so
    /// `θ₁ = asin d_x`, `θ₀ = atan2(−d_y, d_z)`, and the stroke is `|d| − length at home`.
    fn leg_q(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let pl = Self::platform(x);
        (0..6)
            .map(|i| {
                let s = pl.apply(&self.on_platform[i]);
                let d = mat_vec(&transpose(&self.frames[i]), &sub(s, self.base[i]));
                let l = norm(d);
                let u = scale(1.0 / l, d);
                vec![(-u[1]).atan2(u[2]), u[0].asin(), l - self.lengths[i]]
            })
            .collect()
    }
    fn leg_lengths(&self, pl: &Transform) -> Vec<f64> {
        (0..6)
            .map(|i| norm(sub(pl.apply(&self.on_platform[i]), self.base[i])))
            .collect()
    }
}

fn home_x(model: &ParallelModel) -> Vec<f64> {
    let q = matrix_quaternion(&model.home.rotation);
    let t = model.home.translation;
    vec![t[0], t[1], t[2], q[0], q[1], q[2], q[3]]
}

/// Every body's mass-centre velocity and acceleration against central differences (step `h`) of
/// the mass centres of the systems `at(t)` placed along a motion through the solved state:
/// `(‖ċ − FD‖, ‖c̈ − FD‖)`, each relative as `rel_err`.
fn com_fd(at: impl Fn(f64) -> CSystem, sol: &Solution, h: f64) -> (f64, f64) {
    let (m, z, p) = (at(-h), at(0.0), at(h));
    let mut v = (Vec::new(), Vec::new());
    let mut a = (Vec::new(), Vec::new());
    for b in 0..z.bodies.len() {
        let (cm, c0, cp) = (m.bodies[b].com, z.bodies[b].com, p.bodies[b].com);
        v.0.extend(lin(&sol.twists[b]));
        v.1.extend(scale(0.5 / h, sub(cp, cm)));
        a.0.extend(lin(&sol.twist_rates[b]));
        a.1.extend(scale(1.0 / (h * h), add(sub(cp, c0), sub(cm, c0))));
    }
    (rel_err(&v.0, &v.1), rel_err(&a.0, &a.1))
}

/// `exp(t ω + t²/2 ω̇) R₀`, whose angular velocity and acceleration at `t = 0` are `ω` and `ω̇`
/// (the angular velocity of `exp(φ(t))` is `φ̇ + ½ φ × φ̇ + O(t²)`).
fn turn(t: f64, w: Vec3, wd: Vec3, r0: &Mat3) -> Mat3 {
    let phi = add(scale(t, w), scale(0.5 * t * t, wd));
    let ang = norm(phi);
    if ang > 0.0 {
        mm(&rot(scale(1.0 / ang, phi), ang), r0)
    } else {
        *r0
    }
}

/// The power balance and virtual work along every independent admissible motion: for the unit
/// speeds `δu = e_k`, the admissible twists `δt` (the velocity solve with `u = e_k`) and actuator
/// rates `δq` satisfy `τ·δq = Σ_b δt_b·h_b` (the reactions do no work).
fn check_power_and_virtual_work(
    sys: &CSystem,
    p: &Prescribed,
    sol: &Solution,
    u: &[f64],
    worst: &mut [f64; 3],
) {
    let qd = actuated_rates(sys, sol).unwrap();
    let power: f64 = sol.efforts.iter().zip(&qd).map(|(t, q)| t * q).sum();
    let scale_p = power_scale(sys, sol);
    worst[0] = worst[0].max(rel(power, energy_rate(sys, sol), scale_p));
    let h: Vec<[f64; 6]> = (0..sys.bodies.len())
        .map(|b| ne_wrench(sys, sol, b))
        .collect();
    for k in 0..u.len() {
        let mut du = vec![0.0; u.len()];
        du[k] = 1.0;
        let virt = solve(sys, p, &du, &vec![0.0; u.len()]);
        let dq = actuated_rates(sys, &virt).unwrap();
        let lhs: f64 = sol.efforts.iter().zip(&dq).map(|(t, q)| t * q).sum();
        let mut rhs = 0.0;
        let mut sc = 0.0f64;
        for (t, w) in virt.twists.iter().zip(&h) {
            for (t, w) in t.iter().zip(w) {
                rhs += t * w;
                sc += (t * w).abs();
            }
        }
        worst[1] = worst[1].max(rel(lhs, rhs, sc));
    }
    worst[2] = worst[2].max(sol.velocity_residual.max(sol.force_residual));
}

#[test]
fn hexapod_power_balance_and_virtual_work() {
    let hx = hexapod();
    hx.model.validate().expect("a valid 6-UPS");
    let mut r = rng(99);
    let mut worst = [0.0f64; 3];
    let mut worst_closure = 0.0f64;
    let mut worst_fd = [0.0f64; 4];
    for case in 0..8 {
        let x = if case == 0 {
            home_x(&hx.model)
        } else {
            // A pose near home: rotate by a random small rotation, shift a little.
            let hx0 = home_x(&hx.model);
            let dr = rot(unit(&mut r), r.random_range(-0.25..0.25));
            let rm = mm(&dr, &hx.model.home.rotation);
            let q = matrix_quaternion(&rm);
            vec![
                hx0[0] + r.random_range(-0.1..0.1),
                hx0[1] + r.random_range(-0.1..0.1),
                hx0[2] + r.random_range(-0.1..0.1),
                q[0],
                q[1],
                q[2],
                q[3],
            ]
        };
        let leg_q = if case == 0 {
            vec![vec![0.0; 3]; 6]
        } else {
            hx.leg_q(&x)
        };
        let sys = from_parallel(&hx.model, &leg_q, &x);
        assert_eq!(sys.bodies.len(), 19);
        assert_eq!(sys.joints.len(), 24);
        worst_closure = worst_closure.max(closure_residual(&sys));
        let origin = [x[0], x[1], x[2]];
        let p = Prescribed::Pose {
            body: 18,
            point: origin,
        };
        for _ in 0..3 {
            let u: Vec<f64> = (0..6).map(|_| r.random_range(-1.0..1.0)).collect();
            let ud: Vec<f64> = (0..6).map(|_| r.random_range(-3.0..3.0)).collect();
            let sol = solve(&sys, &p, &u, &ud);
            check_power_and_virtual_work(&sys, &p, &sol, &u, &mut worst);
            // Leg rates and accelerations, and every mass centre's velocity and acceleration,
            // against central differences along the motion R(t) = exp(t ω + t²/2 ω̇) R₀,
            // o(t) = o₀ + t v + t²/2 a (rates ω, v and accelerations ω̇, a at t = 0), the legs
            // placed by the inverse kinematics above.
            let w = [u[0], u[1], u[2]];
            let wd = [ud[0], ud[1], ud[2]];
            let r0 = Hexapod::platform(&x).rotation;
            let pose_at = |t: f64| Transform {
                rotation: turn(t, w, wd, &r0),
                translation: add(
                    origin,
                    add(
                        scale(t, [u[3], u[4], u[5]]),
                        scale(0.5 * t * t, [ud[3], ud[4], ud[5]]),
                    ),
                ),
            };
            let hh = 1e-4;
            let (lm, l0, lp) = (
                hx.leg_lengths(&pose_at(-hh)),
                hx.leg_lengths(&pose_at(0.0)),
                hx.leg_lengths(&pose_at(hh)),
            );
            let fd_rate: Vec<f64> = (0..6).map(|i| (lp[i] - lm[i]) / (2.0 * hh)).collect();
            let fd_acc: Vec<f64> = (0..6)
                .map(|i| (lp[i] - 2.0 * l0[i] + lm[i]) / (hh * hh))
                .collect();
            worst_fd[0] = worst_fd[0].max(rel_err(&actuated_rates(&sys, &sol).unwrap(), &fd_rate));
            worst_fd[1] = worst_fd[1].max(rel_err(
                &actuated_accelerations(&sys, &sol).unwrap(),
                &fd_acc,
            ));
            let (ev, ea) = com_fd(
                |t| {
                    let pose = pose_at(t);
                    let q = matrix_quaternion(&pose.rotation);
                    let o = pose.translation;
                    let xt = [o[0], o[1], o[2], q[0], q[1], q[2], q[3]];
                    from_parallel(&hx.model, &hx.leg_q(&xt), &xt)
                },
                &sol,
                hh,
            );
            worst_fd[2] = worst_fd[2].max(ev);
            worst_fd[3] = worst_fd[3].max(ea);
        }
    }
    eprintln!(
        "6-UPS: closure {worst_closure:.1e} m, power balance {:.1e}, virtual work {:.1e}, \
         residual {:.1e}, q̇/FD {:.1e}, q̈/FD {:.1e}, ċ/FD {:.1e}, c̈/FD {:.1e}",
        worst[0], worst[1], worst[2], worst_fd[0], worst_fd[1], worst_fd[2], worst_fd[3]
    );
    assert!(worst_closure <= 1e-12, "closure {worst_closure:e}");
    for (k, w) in worst.iter().enumerate() {
        assert!(*w <= TOL, "check {k}: {w:e} > {TOL:e}");
    }
    assert!(
        worst_fd[0] <= 1e-6,
        "q̇ vs finite differences: {:e}",
        worst_fd[0]
    );
    assert!(
        worst_fd[2] <= 1e-6,
        "ċ vs finite differences: {:e}",
        worst_fd[2]
    );
    assert!(
        worst_fd[3] <= 1e-5,
        "c̈ vs finite differences: {:e}",
        worst_fd[3]
    );
    assert!(
        worst_fd[1] <= 1e-5,
        "q̈ vs finite differences: {:e}",
        worst_fd[1]
    );
}

/// Leg values that do not close the loops are detected.
#[test]
fn hexapod_open_loop_is_detected() {
    let hx = hexapod();
    let x = home_x(&hx.model);
    let mut leg_q = vec![vec![0.0; 3]; 6];
    leg_q[3][2] = 1e-3;
    let sys = from_parallel(&hx.model, &leg_q, &x);
    let c = closure_residual(&sys);
    assert!((c - 1e-3).abs() < 1e-12, "closure residual {c:e}");
}

/// A spherical 3-RRR: every axis through the centre `O`; legs of two links, the third revolute
/// joins the platform. Overconstrained in 3-D (45 joint rows + 3 for 42 twist components).
struct Spherical {
    model: ParallelModel,
    centre: Vec3,
    axes: Vec<[Vec3; 3]>,
}

fn spherical() -> Spherical {
    let mut r = rng(31);
    let centre = [0.1, -0.2, 0.3];
    let mut legs = Vec::new();
    let mut axes = Vec::new();
    let rad = 0.4;
    for i in 0..3 {
        let phi = i as f64 * 2.0 * std::f64::consts::PI / 3.0;
        let a = normalize([0.8 * phi.cos(), 0.8 * phi.sin(), -0.6]);
        let c = normalize([0.8 * (phi + 0.9).cos(), 0.8 * (phi + 0.9).sin(), 0.6]);
        let b = normalize(add(normalize(cross(a, c)), scale(0.3, add(a, c))));
        let at_centre = Transform {
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            translation: centre,
        };
        let proximal = body(
            "proximal",
            r.random_range(0.5..1.5),
            scale(rad, normalize(add(a, b))),
            inertia(&mut r),
        );
        let distal = body(
            "distal",
            r.random_range(0.5..1.5),
            scale(rad, normalize(add(b, c))),
            inertia(&mut r),
        );
        legs.push(Leg {
            name: format!("leg{i}"),
            joints: vec![
                joint(JointKind::Revolute, at_centre, a, 0),
                joint(JointKind::Revolute, Transform::IDENTITY, b, 1),
            ],
            bodies: vec![proximal, distal],
            actuated: 0,
            actuated_name: "j0".into(),
            actuated_home: 0.0,
            end: LegEnd::Revolute {
                on_leg: c,
                on_platform: c,
            },
        });
        axes.push([a, b, c]);
    }
    let model = ParallelModel {
        name: "agile_eye".into(),
        gravity: [0.5, 0.2, -9.81],
        motion: PlatformMotion::Orientation { centre },
        platform: body("platform", 2.0, [0.05, -0.02, 0.2], inertia(&mut r)),
        home: Transform {
            rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            translation: centre,
        },
        legs,
    };
    Spherical {
        model,
        centre,
        axes,
    }
}

impl Spherical {
    /// Inverse kinematics written here: `R(a, θ₀) R(b, θ₁) c = R_P c`. First `θ₁` from
    /// `a·R(b, θ₁) c = a·R_P c` (A cos + B sin = C, the branch nearest zero), then `θ₀` turns
    /// `R(b, θ₁) c` onto `R_P c` about `a`.
    fn leg_q(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let rp = quaternion_matrix([x[0], x[1], x[2], x[3]]);
        self.axes
            .iter()
            .map(|[a, b, c]| {
                let target = mat_vec(&rp, c);
                let cpar = scale(dot(*b, *c), *b);
                let cperp = sub(*c, cpar);
                let bc = cross(*b, *c);
                let (aa, bb, cc) = (dot(*a, cperp), dot(*a, bc), dot(*a, target) - dot(*a, cpar));
                let base = bb.atan2(aa);
                let dev = (cc / (aa * aa + bb * bb).sqrt()).acos();
                let wrap = |t: f64| {
                    (t + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                        - std::f64::consts::PI
                };
                let (t1a, t1b) = (wrap(base + dev), wrap(base - dev));
                let th1 = if t1a.abs() < t1b.abs() { t1a } else { t1b };
                let w = mat_vec(&rot(*b, th1), c);
                let wp = sub(w, scale(dot(*a, w), *a));
                let tp = sub(target, scale(dot(*a, target), *a));
                let th0 = dot(*a, cross(wp, tp)).atan2(dot(wp, tp));
                vec![th0, th1]
            })
            .collect()
    }
}

#[test]
fn spherical_3rrr_power_balance_and_virtual_work() {
    let sp = spherical();
    sp.model.validate().expect("a valid spherical 3-RRR");
    let mut r = rng(5);
    let mut worst = [0.0f64; 3];
    let mut worst_fd = [0.0f64; 2];
    let mut worst_closure = 0.0f64;
    for case in 0..12 {
        let x = if case == 0 {
            vec![1.0, 0.0, 0.0, 0.0]
        } else {
            let q = matrix_quaternion(&rot(unit(&mut r), r.random_range(-0.3..0.3)));
            q.to_vec()
        };
        let leg_q = if case == 0 {
            vec![vec![0.0; 2]; 3]
        } else {
            sp.leg_q(&x)
        };
        let sys = from_parallel(&sp.model, &leg_q, &x);
        worst_closure = worst_closure.max(closure_residual(&sys));
        let p = Prescribed::Orientation { body: 6 };
        for _ in 0..4 {
            let u: Vec<f64> = (0..3).map(|_| r.random_range(-1.0..1.0)).collect();
            let ud: Vec<f64> = (0..3).map(|_| r.random_range(-3.0..3.0)).collect();
            let sol = solve(&sys, &p, &u, &ud);
            check_power_and_virtual_work(&sys, &p, &sol, &u, &mut worst);
            // The platform's mass centre turns about the fixed centre.
            let c = sys.bodies[6].com;
            let v = cross([u[0], u[1], u[2]], sub(c, sp.centre));
            let got = lin(&sol.twists[6]);
            assert!(
                norm(sub(got, v)) <= 1e-12 * (1.0 + norm(v)),
                "{got:?} vs {v:?}"
            );
            // Mass-centre velocities and accelerations against central differences along
            // R(t) = exp(t ω + t²/2 ω̇) R₀, the legs placed by the inverse kinematics above.
            let r0 = quaternion_matrix([x[0], x[1], x[2], x[3]]);
            let (ev, ea) = com_fd(
                |t| {
                    let xt =
                        matrix_quaternion(&turn(t, [u[0], u[1], u[2]], [ud[0], ud[1], ud[2]], &r0));
                    from_parallel(&sp.model, &sp.leg_q(&xt), &xt)
                },
                &sol,
                1e-4,
            );
            worst_fd[0] = worst_fd[0].max(ev);
            worst_fd[1] = worst_fd[1].max(ea);
        }
    }
    eprintln!(
        "spherical 3-RRR: closure {worst_closure:.1e}, power balance {:.1e}, virtual work {:.1e}, \
         residual {:.1e}, ċ/FD {:.1e}, c̈/FD {:.1e}",
        worst[0], worst[1], worst[2], worst_fd[0], worst_fd[1]
    );
    assert!(worst_closure <= 1e-12, "closure {worst_closure:e}");
    assert!(
        worst_fd[0] <= 1e-6,
        "ċ vs finite differences: {:e}",
        worst_fd[0]
    );
    assert!(
        worst_fd[1] <= 1e-5,
        "c̈ vs finite differences: {:e}",
        worst_fd[1]
    );
    for (k, w) in worst.iter().enumerate() {
        assert!(*w <= TOL, "check {k}: {w:e} > {TOL:e}");
    }
}

/// The team's parallel NOC (`runtime::parallel::noc`) against this route, at poses near home:
/// the leg joint values of its inverse kinematics against the ones written here, and its
/// actuator efforts against the multipliers (≤ 1e-10, `rel_err`).
#[test]
fn parallel_noc_agrees() {
    use runtime::parallel::noc as pn;
    let hx = hexapod();
    let sp = spherical();
    let plan_h = pn::Plan::new(&hx.model).expect("6-UPS plan");
    let plan_s = pn::Plan::new(&sp.model).expect("3-RRR plan");
    let mut r = rng(8);
    let mut worst = [0.0f64; 4];
    for case in 0..8 {
        let angle = 0.05 * case as f64;
        let x = random_pose(&mut r, &hx.model, angle);
        let u: Vec<f64> = (0..6).map(|_| r.random_range(-1.0..1.0)).collect();
        let ud: Vec<f64> = (0..6).map(|_| r.random_range(-3.0..3.0)).collect();
        let leg_q = hx.leg_q(&x);
        let team_q = pn::leg_joint_positions(&plan_h, &x).expect("6-UPS IK");
        worst[0] = worst[0].max(rel_err(&team_q.concat(), &leg_q.concat()));
        let sys = from_parallel(&hx.model, &leg_q, &x);
        let p = Prescribed::Pose {
            body: 18,
            point: [x[0], x[1], x[2]],
        };
        let sol = solve(&sys, &p, &u, &ud);
        let team = pn::inverse_dynamics(&plan_h, &x, &u, &ud).expect("6-UPS ID");
        worst[1] = worst[1].max(rel_err(&team, &sol.efforts));

        let xs = matrix_quaternion(&rot(unit(&mut r), angle)).to_vec();
        let leg_q = sp.leg_q(&xs);
        let team_q = pn::leg_joint_positions(&plan_s, &xs).expect("3-RRR IK");
        worst[2] = worst[2].max(rel_err(&team_q.concat(), &leg_q.concat()));
        let sys = from_parallel(&sp.model, &leg_q, &xs);
        let sol = solve(
            &sys,
            &Prescribed::Orientation { body: 6 },
            &u[..3],
            &ud[..3],
        );
        let team = pn::inverse_dynamics(&plan_s, &xs, &u[..3], &ud[..3]).expect("3-RRR ID");
        worst[3] = worst[3].max(rel_err(&team, &sol.efforts));
    }
    eprintln!(
        "runtime::parallel::noc vs Lagrange: 6-UPS leg q {:.1e}, τ {:.1e}; 3-RRR leg q {:.1e}, τ {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    for (k, w) in worst.iter().enumerate() {
        assert!(*w <= TOL, "check {k}: {w:e} > {TOL:e}");
    }
}

/// A pose of a 6-DOF platform: home turned by `angle` about a random axis and moved up to
/// 0.05 m per coordinate.
fn random_pose(r: &mut rand::rngs::StdRng, model: &ParallelModel, angle: f64) -> Vec<f64> {
    let hx0 = home_x(model);
    let q = matrix_quaternion(&mm(&rot(unit(r), angle), &model.home.rotation));
    let mut x: Vec<f64> = (0..3)
        .map(|i| hx0[i] + r.random_range(-0.05..0.05))
        .collect();
    x.extend(q);
    x
}

/// The hexapod with every expanded U (two revolutes and a massless cross) replaced by one
/// `Universal` joint between the base and the cylinder: the same efforts (the massless cross
/// carries no inertia), which checks the U rows and their rates.
#[test]
fn universal_joint_matches_its_expansion() {
    let hx = hexapod();
    let mut r = rng(17);
    let mut worst = 0.0f64;
    for _ in 0..6 {
        let hx0 = home_x(&hx.model);
        let q = matrix_quaternion(&mm(
            &rot(unit(&mut r), r.random_range(-0.25..0.25)),
            &hx.model.home.rotation,
        ));
        let x = vec![
            hx0[0] + 0.03,
            hx0[1] - 0.02,
            hx0[2] + 0.05,
            q[0],
            q[1],
            q[2],
            q[3],
        ];
        let expanded = from_parallel(&hx.model, &hx.leg_q(&x), &x);
        // Bodies: drop each leg's cross (3i); the others move down.
        let keep: Vec<usize> = (0..expanded.bodies.len())
            .filter(|b| b % 3 != 0 || *b == 18)
            .collect();
        let new_index = |b: usize| keep.iter().position(|k| *k == b).unwrap();
        let bodies = keep.iter().map(|b| expanded.bodies[*b].clone()).collect();
        let mut joints = Vec::new();
        for i in 0..6 {
            let (j0, j1, j2) = (
                &expanded.joints[3 * i],
                &expanded.joints[3 * i + 1],
                &expanded.joints[3 * i + 2],
            );
            let (CJointKind::Revolute { axis: a0 }, CJointKind::Revolute { axis: a1 }) =
                (j0.kind, j1.kind)
            else {
                panic!("expected the U expansion");
            };
            assert!(norm(sub(j0.point, j1.point)) < 1e-12);
            joints.push(CJoint {
                parent: None,
                child: new_index(3 * i + 1),
                point: j0.point,
                kind: CJointKind::Universal {
                    axis_parent: a0,
                    axis_child: a1,
                },
                actuated: false,
            });
            joints.push(CJoint {
                parent: Some(new_index(3 * i + 1)),
                child: new_index(3 * i + 2),
                ..j2.clone()
            });
        }
        for j in &expanded.joints[18..] {
            joints.push(CJoint {
                parent: j.parent.map(new_index),
                child: new_index(j.child),
                ..j.clone()
            });
        }
        let compact = CSystem::new(bodies, joints, expanded.gravity);
        let u: Vec<f64> = (0..6).map(|_| r.random_range(-1.0..1.0)).collect();
        let ud: Vec<f64> = (0..6).map(|_| r.random_range(-3.0..3.0)).collect();
        let point = [x[0], x[1], x[2]];
        let a = solve(&expanded, &Prescribed::Pose { body: 18, point }, &u, &ud);
        let b = solve(&compact, &Prescribed::Pose { body: 12, point }, &u, &ud);
        worst = worst.max(rel_err(&b.efforts, &a.efforts));
        // The cylinders' twists and twist rates agree too.
        for i in 0..6 {
            let (ta, tb) = (a.twists[3 * i + 1], b.twists[2 * i]);
            let (da, db) = (a.twist_rates[3 * i + 1], b.twist_rates[2 * i]);
            worst = worst.max(rel_err(&tb, &ta)).max(rel_err(&db, &da));
        }
    }
    eprintln!("U joint vs its expansion: worst {worst:.1e}");
    assert!(worst <= TOL, "{worst:e}");
}

/// A generic leg (`LegKind::Generic`: inverse kinematics by Newton): the hexapod above with
/// each U split into two revolutes whose axes are `δ = 0.03 m` apart (along the leg), so that
/// no closed form applies. The runtime's leg joint positions close every loop in the
/// Lagrange model (`closure_residual`, an independent check of the Newton solution) and its
/// actuator efforts agree with Newton–Euler plus Lagrange multipliers; the generator accepts
/// the mechanism, and an unreachable pose is an error.
#[test]
fn generic_leg_by_newton_agrees() {
    use runtime::parallel::LegKind;
    use runtime::parallel::noc as pn;
    const DELTA: f64 = 0.03;
    let mut hx = hexapod();
    for leg in hx.model.legs.iter_mut() {
        leg.joints[1].origin.translation = [0.0, 0.0, DELTA];
        if let LegEnd::Spherical { on_leg, .. } = &mut leg.end {
            on_leg[2] -= DELTA;
        }
    }
    let kinds = hx.model.validate().expect("a valid generic-leg hexapod");
    assert!(kinds.iter().all(|k| *k == LegKind::Generic), "{kinds:?}");
    let plan = pn::Plan::new(&hx.model).expect("plan");
    let mut r = rng(77);
    let (mut worst_closure, mut worst_tau) = (0.0f64, 0.0f64);
    for case in 0..8 {
        let angle = 0.04 * case as f64;
        let x = random_pose(&mut r, &hx.model, angle);
        let u: Vec<f64> = (0..6).map(|_| r.random_range(-1.0..1.0)).collect();
        let ud: Vec<f64> = (0..6).map(|_| r.random_range(-3.0..3.0)).collect();
        let leg_q = pn::leg_joint_positions(&plan, &x).expect("generic IK");
        let sys = from_parallel(&hx.model, &leg_q, &x);
        worst_closure = worst_closure.max(closure_residual(&sys));
        let sol = solve(
            &sys,
            &Prescribed::Pose {
                body: 18,
                point: [x[0], x[1], x[2]],
            },
            &u,
            &ud,
        );
        let tau = pn::inverse_dynamics(&plan, &x, &u, &ud).expect("generic ID");
        worst_tau = worst_tau.max(rel_err(&tau, &sol.efforts));
    }
    eprintln!("generic legs: closure {worst_closure:.1e} m, τ vs Lagrange {worst_tau:.1e}");
    assert!(worst_closure < 1e-12, "{worst_closure:e}");
    assert!(worst_tau <= TOL, "{worst_tau:e}");
    // Far outside the workspace: an error, not a NaN.
    let mut far = home_x(&hx.model);
    far[2] += 5.0;
    assert!(pn::inverse_dynamics(&plan, &far, &[0.0; 6], &[0.0; 6]).is_err());
    // The generator takes it, and its inverse dynamics is the runtime's.
    let g =
        codegen::parallel::generate(&hx.model, &Default::default(), &codegen::Config::default())
            .expect("generated");
    assert!(g.code.contains("generic (Newton)"));
}
