//! The generic NOC runtime (`runtime::noc`) against the independent spatial-algebra route
//! (`runtime::rnea`), closed forms, and the structural properties of docs/method.md, "Properties used as checks".

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix algebra

use nalgebra::{DMatrix, DVector};
use runtime::model::{
    Body, Joint, JointKind, Mat3, Model, Transform, Vec3, mat_mul, rpy_to_matrix, transpose,
};
use runtime::{noc, rnea};

// ---------------------------------------------------------------------------------------------
// Helpers

/// SplitMix64: a tiny deterministic PRNG (rand is not a dependency of the runtime).
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    fn vec(&mut self, n: usize, a: f64, b: f64) -> Vec<f64> {
        (0..n).map(|_| self.uniform(a, b)).collect()
    }
    fn v3(&mut self, a: f64, b: f64) -> Vec3 {
        [self.uniform(a, b), self.uniform(a, b), self.uniform(a, b)]
    }
    fn unit_vector(&mut self) -> Vec3 {
        loop {
            let v = self.v3(-1.0, 1.0);
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.2 && n <= 1.0 {
                return [v[0] / n, v[1] / n, v[2] / n];
            }
        }
    }
}

fn normalize(v: Vec3) -> Vec3 {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// `R diag(p) Rᵀ`: a physically valid inertia tensor with principal moments `p` and axes `rpy`.
fn inertia(p: Vec3, rpy: Vec3) -> Mat3 {
    let r = rpy_to_matrix(rpy);
    let d = [[p[0], 0.0, 0.0], [0.0, p[1], 0.0], [0.0, 0.0, p[2]]];
    let mut m = mat_mul(&mat_mul(&r, &d), &transpose(&r));
    // Exactly symmetric.
    for i in 0..3 {
        for j in 0..i {
            m[j][i] = m[i][j];
        }
    }
    m
}

fn body(name: &str, mass: f64, com: Vec3, inertia: Mat3) -> Body {
    Body {
        name: name.into(),
        mass,
        com,
        inertia,
    }
}

fn joint(
    name: &str,
    kind: JointKind,
    parent: Option<usize>,
    xyz: Vec3,
    rpy: Vec3,
    axis: Vec3,
) -> Joint {
    Joint {
        name: name.into(),
        kind,
        parent,
        origin: Transform::from_xyz_rpy(xyz, rpy),
        axis: normalize(axis),
        drive: Default::default(),
    }
}

/// Planar 2R arm in the x-y plane, axes z, gravity −y: links of length `l`, mass centres at
/// `lc` along the link, masses `m`, inertias `iz` about the mass centre (z).
fn planar_2r(l1: f64, lc: [f64; 2], m: [f64; 2], iz: [f64; 2], g: f64) -> Model {
    let z = [0.0, 0.0, 1.0];
    let inert = |izz: f64| {
        [
            [0.3 * izz, 0.0, 0.0],
            [0.0, 0.8 * izz, 0.0],
            [0.0, 0.0, izz],
        ]
    };
    Model {
        name: "planar_2r".into(),
        gravity: [0.0, -g, 0.0],
        bodies: vec![
            body("link1", m[0], [lc[0], 0.0, 0.0], inert(iz[0])),
            body("link2", m[1], [lc[1], 0.0, 0.0], inert(iz[1])),
        ],
        joints: vec![
            joint("j1", JointKind::Revolute, None, [0.0; 3], [0.0; 3], z),
            joint(
                "j2",
                JointKind::Revolute,
                Some(0),
                [l1, 0.0, 0.0],
                [0.0; 3],
                z,
            ),
        ],
    }
}

/// A hand-made 3-D branched tree: two branches off body 0, a prismatic joint, generic axes,
/// rotated joint origins, non-diagonal inertias, off-centre mass centres, and a second root.
fn branched_tree() -> Model {
    let h = core::f64::consts::FRAC_PI_2;
    Model {
        name: "branched".into(),
        gravity: [0.3, -0.4, -9.81],
        bodies: vec![
            body(
                "b0",
                2.0,
                [0.05, -0.02, 0.1],
                inertia([0.05, 0.04, 0.07], [0.1, 0.2, 0.3]),
            ),
            body(
                "b1",
                1.2,
                [0.2, 0.01, -0.03],
                inertia([0.02, 0.03, 0.04], [-0.4, 0.7, 0.1]),
            ),
            body(
                "b2",
                0.7,
                [0.0, 0.15, 0.05],
                inertia([0.01, 0.012, 0.015], [0.9, -0.3, 1.2]),
            ),
            body(
                "b3",
                1.5,
                [0.1, 0.1, 0.1],
                inertia([0.03, 0.025, 0.045], [0.0, 0.5, -0.8]),
            ),
            body(
                "b4",
                0.9,
                [-0.05, 0.2, 0.0],
                inertia([0.02, 0.02, 0.03], [1.1, 0.2, 0.4]),
            ),
            body(
                "b5",
                0.4,
                [0.0, 0.0, 0.12],
                inertia([0.004, 0.006, 0.008], [0.3, 0.3, 0.3]),
            ),
        ],
        joints: vec![
            joint(
                "j0",
                JointKind::Revolute,
                None,
                [0.1, 0.0, 0.2],
                [0.3, 0.0, 0.0],
                [0.2, 0.1, 1.0],
            ),
            joint(
                "j1",
                JointKind::Prismatic,
                Some(0),
                [0.3, 0.1, 0.0],
                [0.0, 0.5, 0.2],
                [1.0, 0.3, -0.2],
            ),
            joint(
                "j2",
                JointKind::Revolute,
                Some(1),
                [0.0, 0.0, 0.25],
                [-0.2, 0.1, 0.7],
                [0.0, 1.0, 0.0],
            ),
            joint(
                "j3",
                JointKind::Revolute,
                Some(0),
                [-0.2, 0.3, 0.1],
                [h, 0.0, 0.0],
                [1.0, 0.0, 0.0],
            ),
            joint(
                "j4",
                JointKind::Revolute,
                Some(3),
                [0.0, 0.4, 0.0],
                [0.0, -h, 0.3],
                [0.3, -0.5, 0.8],
            ),
            joint(
                "j5",
                JointKind::Prismatic,
                None,
                [1.0, -1.0, 0.0],
                [0.2, 0.0, 0.0],
                [0.0, 0.0, 1.0],
            ),
        ],
    }
}

/// A random tree of `n` bodies: random parents (sometimes a new root), kinds, axes, origins and
/// inertial data.
fn random_tree(rng: &mut Rng, n: usize) -> Model {
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    for i in 0..n {
        let parent = if i == 0 || rng.unit() < 0.15 {
            None
        } else {
            Some(rng.below(i))
        };
        let kind = if rng.unit() < 0.3 {
            JointKind::Prismatic
        } else {
            JointKind::Revolute
        };
        let a = rng.uniform(0.01, 0.1);
        let b = rng.uniform(0.01, 0.1);
        let c = rng.uniform((a - b).abs() + 0.002, a + b);
        let p = [a, b, c];
        let rpy = rng.v3(-3.0, 3.0);
        bodies.push(body(
            &format!("b{i}"),
            rng.uniform(0.3, 3.0),
            rng.v3(-0.3, 0.3),
            inertia(p, rpy),
        ));
        joints.push(Joint {
            name: format!("j{i}"),
            kind,
            parent,
            origin: Transform::from_xyz_rpy(rng.v3(-0.5, 0.5), rng.v3(-3.0, 3.0)),
            axis: rng.unit_vector(),
            drive: Default::default(),
        });
    }
    Model {
        name: "random".into(),
        gravity: [rng.uniform(-2.0, 2.0), rng.uniform(-2.0, 2.0), -9.81],
        bodies,
        joints,
    }
}

fn test_models() -> Vec<Model> {
    let mut rng = Rng(0x5EED_0001);
    let mut models = vec![
        planar_2r(0.7, [0.3, 0.25], [1.5, 0.8], [0.05, 0.02], 9.81),
        branched_tree(),
    ];
    for n in [1, 2, 3, 5, 8, 12] {
        models.push(random_tree(&mut rng, n));
        models.push(random_tree(&mut rng, n));
    }
    models
}

fn inf_norm_m(a: &DMatrix<f64>) -> f64 {
    a.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// `‖a − b‖∞ / max(‖b‖∞, 1)`.
fn rel_m(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    inf_norm_m(&(a - b)) / inf_norm_m(b).max(1.0)
}

fn rel_v(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    assert_eq!(a.len(), b.len());
    (a - b).amax() / b.amax().max(1.0)
}

/// `q + s v`.
fn step(q: &[f64], v: &[f64], s: f64) -> Vec<f64> {
    q.iter().zip(v).map(|(a, b)| a + s * b).collect()
}

fn no_gravity(model: &Model) -> Model {
    let mut m = model.clone();
    m.gravity = [0.0; 3];
    m
}

const STATES: usize = 8;

/// Run `f(model, q, q̇, q̈)` on random states of every test model.
fn for_each_state(mut f: impl FnMut(&Model, &[f64], &[f64], &[f64])) {
    let mut rng = Rng(0xC0FF_EE00);
    for model in test_models() {
        let n = model.dof();
        for _ in 0..STATES {
            let q = rng.vec(n, -2.0, 2.0);
            let qd = rng.vec(n, -2.0, 2.0);
            let qdd = rng.vec(n, -3.0, 3.0);
            f(&model, &q, &qd, &qdd);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Closed form

/// The textbook planar 2R (e.g. Spong, Hutchinson & Vidyasagar, §7.3), mass centres on the
/// links: `M11 = m1 lc1² + m2 (l1² + lc2² + 2 l1 lc2 c2) + I1 + I2`, `M12 = m2 (lc2² + l1 lc2 c2)
/// + I2`, `M22 = m2 lc2² + I2`, `h = −m2 l1 lc2 s2`, `τ1 = M11 q̈1 + M12 q̈2 + h (2 q̇1 q̇2 + q̇2²)
/// + (m1 lc1 + m2 l1) g c1 + m2 lc2 g c12`, `τ2 = M12 q̈1 + M22 q̈2 − h q̇1² + m2 lc2 g c12`.
#[test]
fn planar_2r_closed_form() {
    let (l1, lc1, lc2, m1, m2, i1, i2, g) = (0.7, 0.3, 0.25, 1.5, 0.8, 0.05, 0.02, 9.81);
    let model = planar_2r(l1, [lc1, lc2], [m1, m2], [i1, i2], g);
    let mut rng = Rng(42);
    for _ in 0..20 {
        let q = rng.vec(2, -3.0, 3.0);
        let qd = rng.vec(2, -2.0, 2.0);
        let qdd = rng.vec(2, -3.0, 3.0);
        let (c1, c2, s2, c12) = (q[0].cos(), q[1].cos(), q[1].sin(), (q[0] + q[1]).cos());
        let m11 = m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2) + i1 + i2;
        let m12 = m2 * (lc2 * lc2 + l1 * lc2 * c2) + i2;
        let m22 = m2 * lc2 * lc2 + i2;
        let h = -m2 * l1 * lc2 * s2;
        let g1 = (m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12;
        let g2 = m2 * lc2 * g * c12;
        let mass = DMatrix::from_row_slice(2, 2, &[m11, m12, m12, m22]);
        let cor = DVector::from_vec(vec![
            h * (2.0 * qd[0] * qd[1] + qd[1] * qd[1]),
            -h * qd[0] * qd[0],
        ]);
        let grav = DVector::from_vec(vec![g1, g2]);
        let tau = &mass * DVector::from_column_slice(&qdd) + &cor + &grav;

        for (name, got) in [
            ("noc", noc::mass_matrix(&model, &q)),
            ("rnea", rnea::mass_matrix(&model, &q)),
        ] {
            assert!(
                rel_m(&got, &mass) < 1e-13,
                "{name} mass matrix {got} vs {mass}"
            );
        }
        for (name, got, want) in [
            ("noc coriolis", noc::coriolis(&model, &q, &qd), &cor),
            ("rnea coriolis", rnea::coriolis(&model, &q, &qd), &cor),
            ("noc gravity", noc::gravity(&model, &q), &grav),
            ("rnea gravity", rnea::gravity(&model, &q), &grav),
            (
                "noc inverse",
                noc::inverse_dynamics(&model, &q, &qd, &qdd),
                &tau,
            ),
            (
                "rnea inverse",
                rnea::inverse_dynamics(&model, &q, &qd, &qdd),
                &tau,
            ),
        ] {
            assert!(rel_v(&got, want) < 1e-13, "{name}: {got} vs {want}");
        }
    }
}

/// A single prismatic joint along a tilted axis: `τ = m q̈ − m gᵀe`, and a revolute pendulum
/// about a horizontal axis: `τ = (I_zz + m d²) q̈ + m g d cos q` with the arm along x.
#[test]
fn single_joint_closed_forms() {
    let e = normalize([0.3, -0.2, 0.9]);
    let slider = Model {
        name: "slider".into(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![body(
            "b",
            2.5,
            [0.1, 0.2, 0.3],
            inertia([0.1, 0.2, 0.25], [0.1; 3]),
        )],
        joints: vec![joint(
            "j",
            JointKind::Prismatic,
            None,
            [0.5, 0.0, 0.0],
            [0.4, 0.1, 0.0],
            e,
        )],
    };
    // The axis is in the joint frame: its base-frame direction is origin.rotation · e.
    let r = slider.joints[0].origin.rotation;
    let eb = runtime::model::mat_vec(&r, &e);
    let tau = noc::inverse_dynamics(&slider, &[0.7], &[1.3], &[-0.4])[0];
    let want = 2.5 * -0.4 - 2.5 * (-9.81 * eb[2]);
    assert!((tau - want).abs() < 1e-13, "{tau} vs {want}");
    assert!((rnea::inverse_dynamics(&slider, &[0.7], &[1.3], &[-0.4])[0] - want).abs() < 1e-13);

    let pendulum = Model {
        name: "pendulum".into(),
        gravity: [0.0, -9.81, 0.0],
        bodies: vec![body(
            "b",
            1.7,
            [0.4, 0.0, 0.0],
            [[0.01, 0.0, 0.0], [0.0, 0.02, 0.0], [0.0, 0.0, 0.03]],
        )],
        joints: vec![joint(
            "j",
            JointKind::Revolute,
            None,
            [0.0; 3],
            [0.0; 3],
            [0.0, 0.0, 1.0],
        )],
    };
    let (q, qd, qdd) = (0.6, -2.0, 1.5);
    let want = (0.03 + 1.7 * 0.16) * qdd + 1.7 * 9.81 * 0.4 * f64::cos(q);
    for got in [
        noc::inverse_dynamics(&pendulum, &[q], &[qd], &[qdd])[0],
        rnea::inverse_dynamics(&pendulum, &[q], &[qd], &[qdd])[0],
    ] {
        assert!((got - want).abs() < 1e-13, "{got} vs {want}");
    }
}

// ---------------------------------------------------------------------------------------------
// NOC against the spatial-algebra route

#[test]
fn noc_agrees_with_rnea_and_crba() {
    let mut worst = [0.0_f64; 4];
    for_each_state(|model, q, qd, qdd| {
        let checks = [
            rel_v(
                &noc::inverse_dynamics(model, q, qd, qdd),
                &rnea::inverse_dynamics(model, q, qd, qdd),
            ),
            rel_m(&noc::mass_matrix(model, q), &rnea::mass_matrix(model, q)),
            rel_v(&noc::gravity(model, q), &rnea::gravity(model, q)),
            rel_v(&noc::coriolis(model, q, qd), &rnea::coriolis(model, q, qd)),
        ];
        for (w, c) in worst.iter_mut().zip(checks) {
            *w = w.max(c);
        }
        for (what, c) in ["inverse dynamics", "mass matrix", "gravity", "coriolis"]
            .iter()
            .zip(checks)
        {
            assert!(
                c <= 1e-12,
                "{}: {what} differs by {c:e} at q = {q:?}",
                model.name
            );
        }
    });
    eprintln!("worst relative differences noc/rnea (ID, I, gravity, C q̇): {worst:?}");
}

#[test]
fn inverse_dynamics_decomposes() {
    for_each_state(|model, q, qd, qdd| {
        let id = noc::inverse_dynamics(model, q, qd, qdd);
        let parts = noc::mass_matrix(model, q) * DVector::from_column_slice(qdd)
            + noc::coriolis_matrix(model, q, qd) * DVector::from_column_slice(qd)
            + noc::gravity(model, q);
        assert!(rel_v(&id, &parts) < 1e-12);
        let cq = noc::coriolis(model, q, qd);
        let zero = vec![0.0; model.dof()];
        let id0 = noc::inverse_dynamics(&no_gravity(model), q, qd, &zero);
        assert!(rel_v(&cq, &id0) < 1e-12);
        // Holding effort.
        let hold = noc::inverse_dynamics(model, q, &zero, &zero);
        assert!(rel_v(&hold, &noc::gravity(model, q)) < 1e-14);
        let hold = rnea::inverse_dynamics(model, q, &zero, &zero);
        assert!(rel_v(&hold, &rnea::gravity(model, q)) < 1e-14);
    });
}

// ---------------------------------------------------------------------------------------------
// Structural properties

#[test]
fn mass_matrix_is_symmetric_positive_definite() {
    for_each_state(|model, q, _, _| {
        let i = noc::mass_matrix(model, q);
        assert!(
            rel_m(&i.transpose(), &i) < 1e-14,
            "{}: not symmetric",
            model.name
        );
        let f = noc::ldlt(&i).expect("positive definite");
        assert!(f.d.iter().all(|&d| d > 0.0));
        // The pivots bound the spectrum: λ_min ≤ d_k ≤ λ_max.
        let eig = i.clone().symmetric_eigen().eigenvalues;
        let (lmin, lmax) = (eig.min(), eig.max());
        assert!(lmin > 0.0);
        for &d in f.d.iter() {
            assert!(d >= lmin * (1.0 - 1e-9) && d <= lmax * (1.0 + 1e-9));
        }
        assert!(f.condition_estimate() <= lmax / lmin * (1.0 + 1e-9));
        // L D Lᵀ reconstructs I.
        let rebuilt = &f.l * DMatrix::from_diagonal(&f.d) * f.l.transpose();
        assert!(rel_m(&rebuilt, &i) < 1e-13);
    });
}

#[test]
fn kinetic_energy_is_half_qd_i_qd() {
    for_each_state(|model, q, qd, _| {
        let v = DVector::from_column_slice(qd);
        let want = 0.5 * v.dot(&(noc::mass_matrix(model, q) * &v));
        let got = noc::kinetic_energy(model, q, qd);
        assert!((got - want).abs() <= 1e-13 * want.abs().max(1.0));
        // And via the twists t = T q̇ and M: ½ tᵀ M t (property 4).
        let t = noc::twist_shaping(model, q) * &v;
        let via_t = 0.5 * t.dot(&(noc::extended_mass(model, q) * &t));
        assert!((via_t - want).abs() <= 1e-13 * want.abs().max(1.0));
    });
}

#[test]
fn twists_match_kinematics() {
    for_each_state(|model, q, qd, _| {
        let k = noc::kinematics(model, q, qd);
        let t = noc::twist_shaping(model, q) * DVector::from_column_slice(qd);
        for i in 0..model.dof() {
            let w = t.fixed_rows::<3>(6 * i);
            let cd = t.fixed_rows::<3>(6 * i + 3);
            assert!((w - k.omega[i]).amax() < 1e-12);
            assert!((cd - k.com_velocity[i]).amax() < 1e-12);
        }
        // The twist columns vanish where the joint does not support the body.
        let tm = noc::twist_shaping(model, q);
        for i in 0..model.dof() {
            for j in 0..model.dof() {
                if !model.supports(j, i) {
                    assert!(tm.view((6 * i, j), (6, 1)).iter().all(|&x| x == 0.0));
                }
            }
        }
    });
}

#[test]
fn velocities_are_derivatives_of_positions() {
    let h = 1e-6;
    for_each_state(|model, q, qd, _| {
        let k = noc::kinematics(model, q, qd);
        let kp = noc::kinematics(model, &step(q, qd, h), qd);
        let km = noc::kinematics(model, &step(q, qd, -h), qd);
        let poses = noc::body_poses(model, q);
        for i in 0..model.dof() {
            let cd = (kp.com[i] - km.com[i]) / (2.0 * h);
            assert!((cd - k.com_velocity[i]).amax() < 1e-7, "ċ of body {i}");
            // Ṙ Rᵀ = Ω.
            let rd = (kp.rotation[i] - km.rotation[i]) / (2.0 * h);
            let omega = rd * k.rotation[i].transpose();
            assert!(
                (omega - k.omega[i].cross_matrix()).amax() < 1e-7,
                "ω of body {i}"
            );
            // Poses and kinematics agree.
            let c = poses[i].apply(&model.bodies[i].com);
            assert!((0..3).all(|r| (c[r] - k.com[i][r]).abs() < 1e-14));
        }
    });
}

#[test]
fn twist_shaping_rate_is_time_derivative() {
    let h = 1e-6;
    for_each_state(|model, q, qd, _| {
        let td = noc::twist_shaping_rate(model, q, qd);
        let fd = (noc::twist_shaping(model, &step(q, qd, h))
            - noc::twist_shaping(model, &step(q, qd, -h)))
            / (2.0 * h);
        let err = rel_m(&td, &fd);
        assert!(err < 1e-7, "{}: Ṫ off by {err:e}", model.name);
    });
}

#[test]
fn i_dot_minus_2c_is_skew() {
    let h = 1e-6;
    for_each_state(|model, q, qd, _| {
        let idot = (noc::mass_matrix(model, &step(q, qd, h))
            - noc::mass_matrix(model, &step(q, qd, -h)))
            / (2.0 * h);
        let c = noc::coriolis_matrix(model, q, qd);
        let n = idot - 2.0 * c;
        let skew_err = inf_norm_m(&(&n + n.transpose())) / inf_norm_m(&n).max(1.0);
        assert!(
            skew_err < 1e-6,
            "{}: İ − 2C not skew ({skew_err:e})",
            model.name
        );
    });
}

/// `d/dt KE = q̇ᵀ τ` without gravity, `d/dt (KE + PE) = q̇ᵀ τ` with it, along
/// `q(t) = q0 + v t + ½ a t²` at a few instants.
#[test]
fn power_balance() {
    let h = 1e-5;
    for_each_state(|model, q0, v, a| {
        let q_at = |t: f64| -> Vec<f64> {
            q0.iter()
                .zip(v)
                .zip(a)
                .map(|((q, v), a)| q + v * t + 0.5 * a * t * t)
                .collect()
        };
        let qd_at = |t: f64| -> Vec<f64> { v.iter().zip(a).map(|(v, a)| v + a * t).collect() };
        for gravity_on in [false, true] {
            let m = if gravity_on {
                model.clone()
            } else {
                no_gravity(model)
            };
            let energy = |t: f64| {
                let e = noc::kinetic_energy(&m, &q_at(t), &qd_at(t));
                if gravity_on {
                    e + noc::potential_energy(&m, &q_at(t))
                } else {
                    e
                }
            };
            for t in [0.0, 0.05, 0.1] {
                let de = (energy(t + h) - energy(t - h)) / (2.0 * h);
                let qd = qd_at(t);
                for (name, tau) in [
                    ("noc", noc::inverse_dynamics(&m, &q_at(t), &qd, a)),
                    ("rnea", rnea::inverse_dynamics(&m, &q_at(t), &qd, a)),
                ] {
                    let p = DVector::from_column_slice(&qd).dot(&tau);
                    assert!(
                        (de - p).abs() <= 1e-6 * p.abs().max(1.0),
                        "{} ({name}, gravity {gravity_on}): dE/dt = {de}, q̇ᵀτ = {p}",
                        model.name
                    );
                }
            }
        }
    });
}

#[test]
fn forward_inverse_round_trip() {
    for_each_state(|model, q, qd, qdd| {
        let tau = noc::inverse_dynamics(model, q, qd, qdd);
        let back = noc::forward_dynamics(model, q, qd, tau.as_slice()).expect("regular");
        let want = DVector::from_column_slice(qdd);
        assert!(
            rel_v(&back, &want) < 1e-10,
            "{}: {back} vs {want}",
            model.name
        );
        // And τ from the independent route.
        let tau = rnea::inverse_dynamics(model, q, qd, qdd);
        let back = noc::forward_dynamics(model, q, qd, tau.as_slice()).expect("regular");
        assert!(rel_v(&back, &want) < 1e-10);
    });
}

#[test]
fn extended_matrices_have_their_structure() {
    let model = branched_tree();
    let q = [0.3, -0.2, 0.5, 1.0, -0.7, 0.1];
    let qd = [1.0, 0.5, -0.3, 0.2, 0.8, -1.1];
    let m = noc::extended_mass(&model, &q);
    let w = noc::extended_angular_velocity(&model, &q, &qd);
    let k = noc::kinematics(&model, &q, &qd);
    assert_eq!(m.shape(), (36, 36));
    assert_eq!(w.shape(), (36, 36));
    for i in 0..model.dof() {
        let mi = model.bodies[i].mass;
        for r in 0..3 {
            for c in 0..3 {
                let expect = if r == c { mi } else { 0.0 };
                assert_eq!(m[(6 * i + 3 + r, 6 * i + 3 + c)], expect);
                assert_eq!(w[(6 * i + 3 + r, 6 * i + 3 + c)], 0.0);
            }
        }
        // The rotational block is R I Rᵀ: same trace as the body-frame inertia.
        let tr: f64 = (0..3).map(|r| m[(6 * i + r, 6 * i + r)]).sum();
        let tr0: f64 = (0..3).map(|r| model.bodies[i].inertia[r][r]).sum();
        assert!((tr - tr0).abs() < 1e-15);
        let wi = w.fixed_view::<3, 3>(6 * i, 6 * i);
        assert_eq!(wi.into_owned(), k.omega[i].cross_matrix());
    }
    // Ṁ = WM − MW (the identity behind İ − 2C skew).
    let h = 1e-6;
    let mdot = (noc::extended_mass(&model, &step(&q, &qd, h))
        - noc::extended_mass(&model, &step(&q, &qd, -h)))
        / (2.0 * h);
    assert!(rel_m(&mdot, &(&w * &m - &m * &w)) < 1e-8);
}

// ---------------------------------------------------------------------------------------------
// Singularities

/// The branched tree with body `i` massless.
fn with_massless(mut model: Model, i: usize) -> Model {
    model.bodies[i].mass = 0.0;
    model.bodies[i].inertia = [[0.0; 3]; 3];
    model
}

#[test]
fn massless_distal_body_is_singular() {
    // Bodies 2, 4 and 5 of the branched tree are leaves.
    for leaf in [2, 4, 5] {
        let model = with_massless(branched_tree(), leaf);
        let q = [0.3, -0.2, 0.5, 1.0, -0.7, 0.1];
        let qd = [1.0, 0.5, -0.3, 0.2, 0.8, -1.1];
        let tau = [1.0; 6];
        let err = noc::forward_dynamics(&model, &q, &qd, &tau).unwrap_err();
        assert_eq!(err.pivot, leaf, "{err}");
        assert!(!err.value.is_nan() && err.value <= 0.0, "{err}");
        assert_eq!(err.condition_estimate, f64::INFINITY);
        assert!(err.to_string().contains("pivot"));
        // Inverse dynamics is still fine, and still agrees with RNEA.
        let qdd = [0.1; 6];
        let a = noc::inverse_dynamics(&model, &q, &qd, &qdd);
        let b = rnea::inverse_dynamics(&model, &q, &qd, &qdd);
        assert!(a.iter().all(|x| x.is_finite()));
        assert!(rel_v(&a, &b) < 1e-12);
    }
    // Everything massless: the first pivot fails (the threshold is 0, the pivot 0).
    let mut model = branched_tree();
    for i in 0..model.dof() {
        model = with_massless(model, i);
    }
    let err = noc::forward_dynamics(&model, &[0.0; 6], &[0.0; 6], &[1.0; 6]).unwrap_err();
    assert_eq!(err.pivot, 0);
    // NaN in the state is reported, not propagated.
    let err =
        noc::forward_dynamics(&branched_tree(), &[f64::NAN; 6], &[0.0; 6], &[0.0; 6]).unwrap_err();
    assert!(err.value.is_nan());
}

/// A massless intermediate body (the inner body of an expanded universal joint) is not a
/// singularity as long as the distal body has a full inertia.
#[test]
fn massless_intermediate_body_is_regular() {
    let model = Model {
        name: "u_joint".into(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![
            body("cross", 0.0, [0.0; 3], [[0.0; 3]; 3]),
            body(
                "arm",
                1.0,
                [0.0, 0.0, 0.5],
                inertia([0.02, 0.02, 0.001], [0.0; 3]),
            ),
        ],
        joints: vec![
            joint(
                "u1",
                JointKind::Revolute,
                None,
                [0.0; 3],
                [0.0; 3],
                [1.0, 0.0, 0.0],
            ),
            joint(
                "u2",
                JointKind::Revolute,
                Some(0),
                [0.0; 3],
                [0.0; 3],
                [0.0, 1.0, 0.0],
            ),
        ],
    };
    let q = [0.4, -0.3];
    let qd = [0.7, 0.2];
    let qdd = [-0.5, 1.5];
    let tau = noc::inverse_dynamics(&model, &q, &qd, &qdd);
    let back = noc::forward_dynamics(&model, &q, &qd, tau.as_slice()).unwrap();
    assert!(rel_v(&back, &DVector::from_column_slice(&qdd)) < 1e-12);
    // u2 = π/2 turns the arm's long axis onto u1: the inertia about u1 is then only the arm's
    // small axial moment, so the mass matrix stays regular but is ill-conditioned.
    let f = noc::ldlt(&noc::mass_matrix(
        &model,
        &[0.0, core::f64::consts::FRAC_PI_2],
    ))
    .unwrap();
    assert!(f.condition_estimate() > 10.0);
}

#[test]
fn empty_model() {
    let model = Model {
        name: "empty".into(),
        gravity: [0.0, 0.0, -9.81],
        bodies: vec![],
        joints: vec![],
    };
    assert_eq!(noc::mass_matrix(&model, &[]).shape(), (0, 0));
    assert_eq!(
        noc::forward_dynamics(&model, &[], &[], &[]).unwrap().len(),
        0
    );
    assert_eq!(rnea::inverse_dynamics(&model, &[], &[], &[]).len(), 0);
    assert_eq!(noc::kinetic_energy(&model, &[], &[]), 0.0);
}
