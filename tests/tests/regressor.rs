//! The generated `regressor` and base parameters of every bundled tree module:
//! * `regressor · BASE_PARAMETERS` equals the module's `inverse_dynamics` (500 random states,
//!   ‖a − b‖∞ / max(‖b‖∞, 1) ≤ 1e-12), friction and rotor inertia included (`puma_drives`);
//! * `NBP` is the rank of the standard regressor built from the runtime's spatial RNEA
//!   (`runtime::rnea`, independent of the generator: a column per standard parameter, the RNEA
//!   of a model whose only inertia is that parameter's, by linearity), computed by an SVD of
//!   the column-normalized matrix stacked over many states; the generated regressor has full
//!   column rank and appending it to the standard one does not raise the rank (so each spans
//!   the other);
//! * two models with different standard parameters but the same base parameters (a point mass
//!   on a revolute joint's axis, carried by the joint's body or by its parent) give the same
//!   efforts and the same base parameter values.

use rand::Rng;
use runtime::model::{Drive, Mat3, Model, Vec3};
use tests::base_parameters::{rank, standard};
use tests::{rel_err, rng};

const STATES: usize = 500;

fn model(file: &str, src: &str) -> Model {
    match codegen::spec::load_tree(file, src) {
        Ok((m, _)) => m,
        Err(d) => panic!("{d}"),
    }
}

/// The body `(mass, com, inertia about the com)` of standard parameters `p` (`M ≠ 0`).
fn body(p: &[f64; 10]) -> (f64, Vec3, Mat3) {
    let m = p[9];
    let c = [p[6] / m, p[7] / m, p[8] / m];
    let cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let jo = [[p[0], p[1], p[2]], [p[1], p[3], p[4]], [p[2], p[4], p[5]]];
    let mut ic = jo;
    for r in 0..3 {
        for k in 0..3 {
            ic[r][k] -= m * (if r == k { cc } else { 0.0 } - c[r] * c[k]);
        }
    }
    (m, c, ic)
}

fn set_body(m: &mut Model, b: usize, p: &[f64; 10]) {
    let (mass, com, inertia) = body(p);
    m.bodies[b].mass = mass;
    m.bodies[b].com = com;
    m.bodies[b].inertia = inertia;
}

/// Whether the model's drives bring friction columns (`FV`, `FC`, `IA` per joint).
fn has_friction(m: &Model) -> bool {
    m.joints
        .iter()
        .any(|j| j.drive.viscous != 0.0 || j.drive.coulomb != 0.0)
}

/// The standard regressor at one state, `n` rows: per body its ten columns from the RNEA
/// (`RNEA(only body b, parameters M = 1 plus e_k) − RNEA(only body b, M = 1)`), then, with
/// friction, the joint's `q̇`, regularized `sign(q̇)` and `q̈` columns from the drive law.
fn standard_rows(m: &Model, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<Vec<f64>> {
    let n = m.dof();
    let mut empty = m.clone();
    for b in &mut empty.bodies {
        b.mass = 0.0;
        b.com = [0.0; 3];
        b.inertia = [[0.0; 3]; 3];
    }
    let friction = has_friction(m);
    let mut cols: Vec<Vec<f64>> = Vec::new();
    for b in 0..n {
        let mut unit_mass = [0.0; 10];
        unit_mass[9] = 1.0;
        let mut base = empty.clone();
        set_body(&mut base, b, &unit_mass);
        let t0 = runtime::rnea::inverse_dynamics(&base, q, qd, qdd);
        for k in 0..10 {
            let mut p = unit_mass;
            p[k] += 1.0;
            let mut mk = empty.clone();
            set_body(&mut mk, b, &p);
            let t = runtime::rnea::inverse_dynamics(&mk, q, qd, qdd);
            cols.push((0..n).map(|i| t[i] - t0[i]).collect());
        }
        if friction {
            let d = m.joints[b].drive;
            let unit = |v: f64| (0..n).map(|i| if i == b { v } else { 0.0 }).collect();
            cols.push(unit(qd[b]));
            let coulomb = Drive {
                coulomb: 1.0,
                coulomb_velocity: d.coulomb_velocity,
                ..Drive::NONE
            };
            cols.push(unit(coulomb.friction(qd[b])));
            cols.push(unit(qdd[b]));
        }
    }
    cols
}

macro_rules! regressor_tests {
    ($($name:ident: $m:path, $file:literal, $scene:literal;)*) => {
        $(
        mod $name {
            use super::*;
            use $m as g;
            const N: usize = g::DOF;

            fn spec() -> Model {
                let src = include_str!(concat!("../../mechanisms/specs/", $file));
                model($file, &format!("{src}{}", $scene))
            }

            fn state(r: &mut rand::rngs::StdRng) -> ([f64; N], [f64; N], [f64; N]) {
                let mut v = |a: f64| -> [f64; N] {
                    std::array::from_fn(|_| r.random_range(-a..a))
                };
                (v(3.0), v(2.0), v(5.0))
            }

            fn times_base(y: &[[f64; g::NBP]; N]) -> Vec<f64> {
                y.iter()
                    .map(|row| row.iter().zip(&g::BASE_PARAMETERS).map(|(a, b)| a * b).sum())
                    .collect()
            }

            #[test]
            fn regressor_times_base_parameters_is_inverse_dynamics() {
                let mut r = rng(0x2e9e);
                let mut worst = 0.0f64;
                for _ in 0..STATES {
                    let (q, qd, qdd) = state(&mut r);
                    let y = g::regressor(&q, &qd, &qdd);
                    let tau = g::inverse_dynamics(&q, &qd, &qdd);
                    worst = worst.max(rel_err(&times_base(&y), &tau));
                }
                eprintln!(
                    "{}: NBP = {}, max ‖Y·π_b − τ‖∞ / max(‖τ‖∞, 1) = {worst:.2e}",
                    stringify!($name),
                    g::NBP
                );
                assert!(worst <= 1e-12, "{worst:e}");
                assert_eq!(g::BASE_PARAMETER_NAMES.len(), g::NBP);
                assert!(g::BASE_PARAMETERS.iter().all(|v| v.is_finite()));
            }

            #[test]
            fn base_parameter_count_is_the_rank_of_the_standard_regressor() {
                let m = spec();
                let ncols = standard_rows(&m, &[0.0; N], &[0.0; N], &[0.0; N]).len();
                let states = 3 * ncols / N + 20;
                let mut r = rng(0x4a4b);
                let mut std_cols: Vec<Vec<f64>> = vec![Vec::new(); ncols];
                let mut base_cols: Vec<Vec<f64>> = vec![Vec::new(); g::NBP];
                for _ in 0..states {
                    let (q, qd, qdd) = state(&mut r);
                    for (c, v) in std_cols.iter_mut().zip(standard_rows(&m, &q, &qd, &qdd)) {
                        c.extend(v);
                    }
                    let y = g::regressor(&q, &qd, &qdd);
                    for (k, c) in base_cols.iter_mut().enumerate() {
                        c.extend(y.iter().map(|row| row[k]));
                    }
                }
                let standard = rank(&std_cols);
                let base = rank(&base_cols);
                let both: Vec<Vec<f64>> = std_cols.iter().chain(&base_cols).cloned().collect();
                let joint = rank(&both);
                eprintln!(
                    "{}: {ncols} standard parameters, rank {standard}; NBP {}; base rank {base}; \
                     both {joint}",
                    stringify!($name),
                    g::NBP
                );
                assert_eq!(standard, g::NBP);
                assert_eq!(base, g::NBP);
                assert_eq!(joint, g::NBP);
            }
        }
        )*
    };
}

regressor_tests! {
    puma560: mechanisms::puma560, "puma560.toml", "";
    puma560_urdf: mechanisms::puma560_urdf, "puma560.urdf", "";
    stanford_arm: mechanisms::stanford_arm, "stanford_arm.toml", "";
    chain7: mechanisms::chain7, "chain7.toml", "";
    planar_2r: mechanisms::planar_2r, "planar_2r.toml", "";
    gripper_tree: mechanisms::gripper_tree, "gripper_tree.toml", "";
    iiwa14: mechanisms::iiwa14, "iiwa14.urdf", "";
    puma_drives: tests::variants::puma_drives, "puma560.toml",
        "\n[scene]\nfriction = true\nrotor_inertia = true\n";
}

/// A point mass `mp` at `p` (body frame) added to standard parameters `s`.
fn add_point(s: &[f64; 10], mp: f64, p: &Vec3) -> [f64; 10] {
    let pp = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    let j = |r: usize, k: usize| mp * (if r == k { pp } else { 0.0 } - p[r] * p[k]);
    let add = [
        j(0, 0),
        j(0, 1),
        j(0, 2),
        j(1, 1),
        j(1, 2),
        j(2, 2),
        mp * p[0],
        mp * p[1],
        mp * p[2],
        mp,
    ];
    std::array::from_fn(|k| s[k] + add[k])
}

/// A point mass on revolute joint `j`'s axis moves nothing when the joint turns: carried by
/// body `j` or by its parent (at the same place), the efforts and the base parameters are the
/// same, the standard parameters are not.
#[test]
fn models_with_the_same_base_parameters_have_the_same_efforts() {
    for (file, src) in [
        (
            "puma560.toml",
            include_str!("../../mechanisms/specs/puma560.toml"),
        ),
        (
            "stanford_arm.toml",
            include_str!("../../mechanisms/specs/stanford_arm.toml"),
        ),
        (
            "iiwa14.urdf",
            include_str!("../../mechanisms/specs/iiwa14.urdf"),
        ),
    ] {
        let m = model(file, src);
        let n = m.dof();
        let mut r = rng(0x5a3e);
        let revolute: Vec<usize> = (0..n)
            .filter(|&j| {
                m.joints[j].parent.is_some()
                    && m.joints[j].kind == runtime::model::JointKind::Revolute
            })
            .collect();
        for &j in &revolute {
            let p = m.joints[j].parent.unwrap();
            let (mp, s) = (0.7, r.random_range(-0.3..0.3));
            let at = m.joints[j].axis.map(|a| a * s);
            let o = &m.joints[j].origin;
            let in_parent: Vec3 = std::array::from_fn(|r| {
                o.translation[r] + (0..3).map(|k| o.rotation[r][k] * at[k]).sum::<f64>()
            });
            let std_of =
                |b: usize| standard(m.bodies[b].mass, &m.bodies[b].com, &m.bodies[b].inertia);
            let mut a = m.clone();
            set_body(&mut a, j, &add_point(&std_of(j), mp, &at));
            let mut b = m.clone();
            set_body(&mut b, p, &add_point(&std_of(p), mp, &in_parent));
            let mut worst = 0.0f64;
            for _ in 0..50 {
                let v = |r: &mut rand::rngs::StdRng, x: f64| -> Vec<f64> {
                    (0..n).map(|_| r.random_range(-x..x)).collect()
                };
                let (q, qd, qdd) = (v(&mut r, 3.0), v(&mut r, 2.0), v(&mut r, 5.0));
                let ta = runtime::rnea::inverse_dynamics(&a, &q, &qd, &qdd);
                let tb = runtime::rnea::inverse_dynamics(&b, &q, &qd, &qdd);
                worst = worst.max(rel_err(ta.as_slice(), tb.as_slice()));
            }
            assert!(
                worst <= 1e-12,
                "{file} joint {j}: efforts differ by {worst:e}"
            );
            let (ra, rb) = (codegen::symbolic(&a), codegen::symbolic(&b));
            let (ba, bb) = (ra.regressor.unwrap().base, rb.regressor.unwrap().base);
            assert_eq!(ba.names, bb.names, "{file} joint {j}");
            let scale = ba.values.iter().fold(1.0f64, |s, v| s.max(v.abs()));
            let diff = ba
                .values
                .iter()
                .zip(&bb.values)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(
                diff <= 1e-12 * scale,
                "{file} joint {j}: base parameters differ by {diff:e}"
            );
        }
    }
}
