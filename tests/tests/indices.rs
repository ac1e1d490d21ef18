//! Dynamic performance indices (`runtime::indices`, and the generated-code template
//! `codegen/templates/inertia_indices.rs`, compiled here as a module for three sizes with the
//! stand-ins that generation replaces).
//!
//! Reference values never come from the code under test:
//! * Ma & Angeles' DCI on the published check in docs/method.md
//!   ("Dynamic performance indices"): M = [[2, .5], [.5, 1]] gives σ₁ = 1.5, ψ₁ = 0.5 and
//!   σ₂ = 1.833333, ψ₂ = 0.181818 with Frobenius weights;
//! * matrices built as `Q diag(λ) Qᵀ` with chosen eigenvalues (eigenvalues, condition number,
//!   Yoshikawa's `1/det`, DCI from `λ` alone);
//! * a mechanism built to be dynamically isotropic (DCI = 0 at every configuration);
//! * invariance: rotating a whole mechanism about the base frame leaves the actuator-space
//!   inertia unchanged and the platform-space inertia's eigenvalues, condition number and DCI
//!   unchanged (the matrix itself changes: it is `R I Rᵀ`);
//! * brute force over directions for Khatib & Burdick's isotropic acceleration and Yoshikawa's
//!   ellipsoid radii.

#![allow(clippy::needless_range_loop)]

use nalgebra::DMatrix;
use rand::Rng;
use runtime::indices::{
    self, IndexError, Normalization, Space, Weights, inertia_indices, parallel_indices,
    platform_indices, task_indices,
};
use runtime::model::{Mat3, Model, Transform, mat_vec, rpy_to_matrix};
use runtime::parallel::noc::{self, Plan};
use runtime::parallel::{ParallelModel, PlatformMotion};
use tests::pkm::{model, random_state};

/// The generated template for three sizes: the template file itself, with the stand-ins that
/// generation replaces (the runtime's tolerances and sweep limit, std's `sqrt`).
macro_rules! indices_template {
    ($name:ident, $dof:literal) => {
        #[allow(dead_code)]
        mod $name {
            pub const DOF: usize = $dof;
            const SYMMETRY_TOLERANCE: f64 = runtime::indices::SYMMETRY_TOLERANCE;
            const DEFINITENESS_TOLERANCE: f64 = runtime::indices::DEFINITENESS_TOLERANCE;
            const MAX_SWEEPS: usize = codegen::indices::MAX_SWEEPS;
            fn sqrt(x: f64) -> f64 {
                x.sqrt()
            }
            include!("../../codegen/templates/inertia_indices.rs");
        }
    };
}
indices_template!(g2, 2);
indices_template!(g3, 3);
indices_template!(g6, 6);

fn arr<const N: usize>(m: &DMatrix<f64>) -> [[f64; N]; N] {
    let mut a = [[0.0; N]; N];
    for i in 0..N {
        for j in 0..N {
            a[i][j] = m[(i, j)];
        }
    }
    a
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

/// `Q diag(λ) Qᵀ` with a random orthogonal `Q` (QR of a random matrix).
fn with_eigenvalues(rng: &mut rand::rngs::StdRng, lambda: &[f64]) -> DMatrix<f64> {
    let n = lambda.len();
    let a = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    let q = a.qr().q();
    let m = &q * DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(lambda)) * q.transpose();
    (&m + m.transpose()) * 0.5
}

#[test]
fn published_dci_check_runtime_and_generated() {
    let m = DMatrix::from_row_slice(2, 2, &[2.0, 0.5, 0.5, 1.0]);
    let w = Weights::frobenius(2);
    let d1 = indices::dci(&m, Normalization::Trace, &w).unwrap();
    let d2 = indices::dci(&m, Normalization::Dimensionless, &w).unwrap();
    assert!((d1.sigma - 1.5).abs() < 1e-12 && (d1.psi - 0.5).abs() < 1e-12);
    assert!((d2.sigma - 1.833333).abs() < 5e-7 && (d2.psi - 0.181818).abs() < 5e-7);
    let g = g2::inertia_indices(&arr::<2>(&m)).unwrap();
    assert!((g.dci_trace_sigma - 1.5).abs() < 1e-12 && (g.dci_trace_psi - 0.5).abs() < 1e-12);
    assert!((g.dci_dimensionless_sigma - 1.833333).abs() < 5e-7);
    assert!((g.dci_dimensionless_psi - 0.181818).abs() < 5e-7);
    // Unit weights count each off-diagonal entry once: ψ₁ = ½ (0.25 + 0.25 + 0.25).
    let u = indices::dci(&m, Normalization::Trace, &Weights::unit(2)).unwrap();
    assert!((u.psi - 0.375).abs() < 1e-15);
}

/// Eigenvalues, condition number, GIE ratio, Yoshikawa and the DCI from the chosen spectrum
/// alone (`tr M = Σλ`, `tr M² = Σλ²`, `‖M − σ1‖²_F = Σ(λ − σ)²`), runtime and generated.
#[test]
fn known_spectra_runtime_and_generated() {
    let mut rng = tests::rng(0x1d1c);
    for case in 0..40 {
        let n = if case % 2 == 0 { 3 } else { 6 };
        let lambda: Vec<f64> = (0..n)
            .map(|_| 10f64.powf(rng.random_range(-3.0..1.0)))
            .collect();
        let m = with_eigenvalues(&mut rng, &lambda);
        let mut sorted = lambda.clone();
        sorted.sort_by(f64::total_cmp);
        let (lmin, lmax) = (sorted[0], sorted[n - 1]);
        let nf = n as f64;
        let s1 = lambda.iter().sum::<f64>() / nf;
        let psi1 = 0.5 * lambda.iter().map(|l| (l - s1) * (l - s1)).sum::<f64>();
        let s2 = lambda.iter().map(|l| l * l).sum::<f64>() / lambda.iter().sum::<f64>();
        let psi2 = 0.5 * lambda.iter().map(|l| (l / s2 - 1.0).powi(2)).sum::<f64>();
        let det: f64 = lambda.iter().product();
        let cond = lmax / lmin;
        let tol = 1e-13 * cond;

        let r = inertia_indices(&m).unwrap();
        for k in 0..n {
            assert!(close(r.eigenvalues[k], sorted[k], tol), "{case}: {r:?}");
        }
        assert!(close(r.condition, cond, tol));
        assert!(close(r.gie_ratio, 1.0 / cond, tol));
        assert!(close(r.manipulability, 1.0 / det, tol));
        assert!(close(r.dci_trace.sigma, s1, 1e-13));
        assert!(close(r.dci_trace.psi, psi1, 1e-10 * cond));
        assert!(close(r.dci_dimensionless.sigma, s2, 1e-13));
        assert!(close(r.dci_dimensionless.psi, psi2, 1e-10 * cond));

        let check = |ev: &[f64], c: f64, manip: f64, p1: f64, p2: f64| {
            for k in 0..n {
                assert!(close(ev[k], sorted[k], tol), "{case}: generated {ev:?}");
            }
            assert!(close(c, cond, tol));
            assert!(close(manip, 1.0 / det, tol));
            assert!(close(p1, psi1, 1e-10 * cond));
            assert!(close(p2, psi2, 1e-10 * cond));
        };
        if n == 3 {
            let g = g3::inertia_indices(&arr::<3>(&m)).unwrap();
            check(
                &g.eigenvalues,
                g.condition,
                g.manipulability,
                g.dci_trace_psi,
                g.dci_dimensionless_psi,
            );
            // Axes: unit eigenvectors.
            for k in 0..3 {
                let v = nalgebra::DVector::from_row_slice(&g.axes[k]);
                assert!((v.norm() - 1.0).abs() < 1e-13);
                assert!((&m * &v - &v * g.eigenvalues[k]).norm() < 1e-12 * lmax);
            }
        } else {
            let g = g6::inertia_indices(&arr::<6>(&m)).unwrap();
            check(
                &g.eigenvalues,
                g.condition,
                g.manipulability,
                g.dci_trace_psi,
                g.dci_dimensionless_psi,
            );
        }
    }
}

/// The mechanism's own matrices: runtime and generated template agree on every index.
#[test]
fn generated_template_agrees_with_runtime_on_mechanism_matrices() {
    let mut rng = tests::rng(0xa61e);
    let mut worst: f64 = 0.0;
    for (name, angle, reach) in [("agile_eye", 0.5, 0.0), ("gough_stewart", 0.1, 0.05)] {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let home = m.home_x();
        for _ in 0..100 {
            let (x, _, _) = random_state(&plan, &home, &mut rng, angle, reach);
            let ma = indices::from_rows(&noc::actuator_mass_matrix(&plan, &x).unwrap()).unwrap();
            let r = inertia_indices(&ma).unwrap();
            let pairs: Vec<(f64, f64)> = if m.dof() == 3 {
                let g = g3::inertia_indices(&arr::<3>(&ma)).unwrap();
                let mut p = vec![
                    (g.condition, r.condition),
                    (g.gie_ratio, r.gie_ratio),
                    (g.dci_trace_sigma, r.dci_trace.sigma),
                    (g.dci_trace_psi, r.dci_trace.psi),
                    (g.dci_dimensionless_sigma, r.dci_dimensionless.sigma),
                    (g.dci_dimensionless_psi, r.dci_dimensionless.psi),
                    (g.manipulability, r.manipulability),
                    (g.isotropic_acceleration, r.isotropic_acceleration),
                ];
                p.extend(
                    g.eigenvalues
                        .iter()
                        .copied()
                        .zip(r.eigenvalues.iter().copied()),
                );
                p.extend(
                    g.acceleration_radii
                        .iter()
                        .copied()
                        .zip(r.acceleration_radii.iter().copied()),
                );
                p
            } else {
                let g = g6::inertia_indices(&arr::<6>(&ma)).unwrap();
                let mut p = vec![
                    (g.condition, r.condition),
                    (g.dci_trace_psi, r.dci_trace.psi),
                    (g.dci_dimensionless_psi, r.dci_dimensionless.psi),
                    (g.manipulability, r.manipulability),
                    (g.isotropic_acceleration, r.isotropic_acceleration),
                ];
                p.extend(
                    g.eigenvalues
                        .iter()
                        .copied()
                        .zip(r.eigenvalues.iter().copied()),
                );
                p
            };
            for (a, b) in pairs {
                let e = (a - b).abs() / b.abs().max(1e-300);
                worst = worst.max(e);
                assert!(e < 1e-9, "{name}: generated {a} vs runtime {b}");
            }
        }
    }
    eprintln!("worst relative difference generated vs runtime: {worst:e}");
}

/// A 2R pointing mechanism built to be isotropic: perpendicular intersecting axes, a massless
/// first body and a second body with a spherical inertia `k·1` centred on the intersection.
/// Then `M(q) = k·1` at every `q`, so both DCIs vanish and `σ = k`.
#[test]
fn constructed_isotropic_mechanism_has_zero_dci() {
    let spec = r#"
[mechanism]
name = "isotropic_pointer"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "yoke"
mass = 0.0
com = [0.0, 0.0, 0.0]

[[body]]
name = "ball"
mass = 2.0
com = [0.0, 0.0, 0.0]
inertia = { ixx = 0.0125, iyy = 0.0125, izz = 0.0125 }

[[joint]]
name = "pan"
kind = "revolute"
parent = "base"
child = "yoke"
origin = { xyz = [0.1, -0.2, 0.3], rpy = [0.3, 0.2, 0.1] }
axis = [0.0, 0.0, 1.0]

[[joint]]
name = "tilt"
kind = "revolute"
parent = "yoke"
child = "ball"
origin = { xyz = [0.0, 0.0, 0.0] }
axis = [1.0, 0.0, 0.0]
"#;
    let model = match codegen::spec::load_mechanism("isotropic_pointer.toml", spec) {
        Ok((codegen::spec::Mechanism::Tree(m), _)) => m,
        Ok(_) => panic!("not a tree"),
        Err(d) => panic!("{d}"),
    };
    let k: f64 = 0.0125;
    let mut rng = tests::rng(7);
    for _ in 0..50 {
        let q = [rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0)];
        let r = indices::tree_indices(&model, &q).unwrap();
        assert!(r.dci_trace.psi <= (1e-13 * k).powi(2), "{r:?}");
        assert!(r.dci_dimensionless.psi <= 1e-26, "{r:?}");
        assert!(close(r.dci_trace.sigma, k, 1e-13));
        assert!(close(r.dci_dimensionless.sigma, k, 1e-13));
        assert!((r.condition - 1.0).abs() < 1e-12);
        let g = g2::inertia_indices(&arr::<2>(&runtime::rnea::mass_matrix(&model, &q))).unwrap();
        assert!(g.dci_trace_psi <= (1e-13 * k).powi(2));
        assert!(g.dci_dimensionless_psi <= 1e-26);
    }
    // And a perturbed one (the ball's centre off the tilt axis) is not isotropic.
    let off = spec.replace(
        "name = \"ball\"\nmass = 2.0\ncom = [0.0, 0.0, 0.0]",
        "name = \"ball\"\nmass = 2.0\ncom = [0.0, 0.05, 0.0]",
    );
    assert_ne!(off, spec);
    let Ok((codegen::spec::Mechanism::Tree(m2), _)) =
        codegen::spec::load_mechanism("off.toml", &off)
    else {
        panic!("perturbed spec");
    };
    // Closed form: with the mass centre r = 0.05 m off the tilt axis, M = diag(k + m r² cos² q₂,
    // k + m r²) (the pan axis sees the offset's projection), so ψ₁ = ¼ (m r² sin² q₂)².
    let q2: f64 = 0.4;
    let mr2 = 2.0 * 0.05f64 * 0.05;
    let r = indices::tree_indices(&m2, &[0.3, q2]).unwrap();
    assert!(
        close(r.eigenvalues[0], k + mr2 * q2.cos().powi(2), 1e-12),
        "{r:?}"
    );
    assert!(close(r.eigenvalues[1], k + mr2, 1e-12), "{r:?}");
    assert!(
        close(
            r.dci_trace.psi,
            0.25 * (mr2 * q2.sin().powi(2)).powi(2),
            1e-10
        ),
        "{r:?}"
    );
}

fn transform(r: Mat3) -> Transform {
    Transform {
        rotation: r,
        translation: [0.0; 3],
    }
}

/// The whole mechanism turned by `r` about the base origin (gravity turned too).
fn rotated_parallel(m: &ParallelModel, r: Mat3) -> ParallelModel {
    let t = transform(r);
    let mut out = m.clone();
    out.home = t.compose(&m.home);
    out.gravity = mat_vec(&r, &m.gravity);
    for leg in out.legs.iter_mut() {
        leg.joints[0].origin = t.compose(&leg.joints[0].origin);
    }
    if let PlatformMotion::Orientation { centre } = m.motion {
        out.motion = PlatformMotion::Orientation {
            centre: mat_vec(&r, &centre),
        };
    }
    if let PlatformMotion::Translation { rotation } = m.motion {
        out.motion = PlatformMotion::Translation {
            rotation: runtime::model::mat_mul(&r, &rotation),
        };
    }
    if let PlatformMotion::PlanarPose { height, rotation } = m.motion {
        out.motion = PlatformMotion::PlanarPose {
            height,
            rotation: runtime::model::mat_mul(&r, &rotation),
        };
    }
    out
}

fn rotate_x(m: &ParallelModel, r: &Mat3, x: &[f64]) -> Vec<f64> {
    let qr = runtime::model::matrix_quaternion(r);
    let qmul = |a: &[f64], b: &[f64]| {
        [
            a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
        ]
    };
    match m.motion {
        PlatformMotion::Pose => {
            let p = mat_vec(r, &[x[0], x[1], x[2]]);
            let q = qmul(&qr, &x[3..7]);
            vec![p[0], p[1], p[2], q[0], q[1], q[2], q[3]]
        }
        PlatformMotion::Orientation { .. } => qmul(&qr, &x[0..4]).to_vec(),
        PlatformMotion::PlanarPoint { .. } => {
            let p = mat_vec(r, &[x[0], x[1], 0.0]);
            vec![p[0], p[1]]
        }
        PlatformMotion::Translation { .. } => mat_vec(r, &[x[0], x[1], x[2]]).to_vec(),
        // Turned about z: φ stays (it is measured from the turned home rotation).
        PlatformMotion::PlanarPose { .. } => {
            let p = mat_vec(r, &[x[0], x[1], 0.0]);
            vec![p[0], p[1], x[2]]
        }
        // Not turned (the tilts are about base axes): the same coordinates.
        PlatformMotion::HeaveTilt { .. } => x.to_vec(),
        PlatformMotion::Schoenflies { .. } => {
            let p = mat_vec(r, &[x[0], x[1], x[2]]);
            vec![p[0], p[1], p[2], x[3]]
        }
    }
}

/// Rotating the whole parallel mechanism about the base frame: the actuator-space inertia is
/// the same matrix (the joint coordinates do not change), and the platform-space inertia
/// `R I Rᵀ` has the same eigenvalues, condition number and DCI (orthogonal similarity), though
/// its entries change.
#[test]
fn parallel_indices_are_invariant_under_a_rotation_of_the_whole_mechanism() {
    let mut rng = tests::rng(0x0707);
    for (name, angle, reach, planar) in [
        ("gough_stewart", 0.1, 0.05, false),
        ("agile_eye", 0.5, 0.0, false),
        ("planar_five_bar", 0.0, 0.05, true),
        ("delta_rl5", 0.0, 0.05, false),
        ("planar_3rrr", 0.3, 0.02, true),
    ] {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let rpy = if planar {
            [0.0, 0.0, 0.7]
        } else {
            [0.4, -0.3, 1.1]
        };
        let r = rpy_to_matrix(rpy);
        let mr = rotated_parallel(&m, r);
        let plan_r = Plan::new(&mr).unwrap();
        let home = m.home_x();
        let mut platform_changed = false;
        for _ in 0..50 {
            let (x, _, _) = random_state(&plan, &home, &mut rng, angle, reach);
            let xr = rotate_x(&m, &r, &x);
            // The joint coordinates are the same in both (a check on the construction).
            let q = noc::inverse_kinematics(&plan, &x).unwrap();
            let qr = noc::inverse_kinematics(&plan_r, &xr).unwrap();
            assert!(tests::pkm::rel(&qr, &q) < 1e-10, "{name}: {q:?} vs {qr:?}");

            let a = parallel_indices(&plan, &x, Space::Actuator).unwrap();
            let ar = parallel_indices(&plan_r, &xr, Space::Actuator).unwrap();
            let p = parallel_indices(&plan, &x, Space::Platform).unwrap();
            let pr = parallel_indices(&plan_r, &xr, Space::Platform).unwrap();
            for (s, t) in [(&a, &ar), (&p, &pr)] {
                assert!(
                    tests::pkm::rel(&t.eigenvalues, &s.eigenvalues) < 1e-9,
                    "{name}"
                );
                assert!(close(t.condition, s.condition, 1e-9), "{name}");
                assert!(close(t.dci_trace.sigma, s.dci_trace.sigma, 1e-10), "{name}");
                assert!(close(t.dci_trace.psi, s.dci_trace.psi, 1e-8), "{name}");
                assert!(
                    close(t.dci_dimensionless.psi, s.dci_dimensionless.psi, 1e-8),
                    "{name}"
                );
                assert!(close(t.manipulability, s.manipulability, 1e-9), "{name}");
            }
            let i = indices::from_rows(&noc::mass_matrix(&plan, &x).unwrap()).unwrap();
            let ir = indices::from_rows(&noc::mass_matrix(&plan_r, &xr).unwrap()).unwrap();
            if (&i - &ir).amax() > 1e-6 * i.amax() {
                platform_changed = true;
            }
        }
        assert!(
            platform_changed,
            "{name}: the rotation should change I's entries"
        );
    }
}

/// Turning a tree's base (and gravity with it) leaves the joint-space inertia and its indices
/// unchanged.
#[test]
fn tree_indices_are_invariant_under_a_rotation_of_the_base() {
    let path = tests::pkm::spec_path("puma560");
    let src = std::fs::read_to_string(&path).unwrap();
    let Ok((codegen::spec::Mechanism::Tree(m), _)) =
        codegen::spec::load_mechanism(&path.to_string_lossy(), &src)
    else {
        panic!("puma560 is a tree");
    };
    let r = rpy_to_matrix([0.9, -0.4, 2.0]);
    let mut mr: Model = m.clone();
    mr.gravity = mat_vec(&r, &m.gravity);
    for j in mr.joints.iter_mut().filter(|j| j.parent.is_none()) {
        j.origin = transform(r).compose(&j.origin);
    }
    let mut rng = tests::rng(11);
    for _ in 0..50 {
        let q: Vec<f64> = (0..m.dof()).map(|_| rng.random_range(-2.0..2.0)).collect();
        let a = indices::tree_indices(&m, &q).unwrap();
        let b = indices::tree_indices(&mr, &q).unwrap();
        assert!(tests::pkm::rel(&b.eigenvalues, &a.eigenvalues) < 1e-12);
        assert!(close(
            b.dci_dimensionless.psi,
            a.dci_dimensionless.psi,
            1e-10
        ));
        assert!(close(b.condition, a.condition, 1e-10));
        // The generic NOC route gives the same indices as the CRBA route used by tree_indices.
        let c = inertia_indices(&runtime::noc::mass_matrix(&mr, &q)).unwrap();
        assert!(tests::pkm::rel(&c.eigenvalues, &a.eigenvalues) < 1e-11);
    }
}

/// Platform space two ways: `platform_indices(I, A)` and `task_indices(A⁻ᵀIA⁻¹, A⁻¹)`; and
/// Yoshikawa's measure against `|det A| / det I` (nalgebra determinants).
#[test]
fn platform_space_two_routes_and_yoshikawa_determinant() {
    let mut rng = tests::rng(0xbeef);
    for (name, angle, reach) in [("agile_eye", 0.5, 0.0), ("gough_stewart", 0.1, 0.05)] {
        let m = model(name);
        let plan = Plan::new(&m).unwrap();
        let home = m.home_x();
        for _ in 0..30 {
            let (x, _, _) = random_state(&plan, &home, &mut rng, angle, reach);
            let i = indices::from_rows(&noc::mass_matrix(&plan, &x).unwrap()).unwrap();
            let a = indices::from_rows(&noc::actuation(&plan, &x).unwrap()).unwrap();
            let ma = indices::from_rows(&noc::actuator_mass_matrix(&plan, &x).unwrap()).unwrap();
            let p = platform_indices(&i, &a).unwrap();
            let t = task_indices(&ma, &a.clone().try_inverse().unwrap()).unwrap();
            assert!(
                tests::pkm::rel(&t.eigenvalues, &p.eigenvalues) < 1e-8,
                "{name}"
            );
            assert!(close(
                t.dci_dimensionless.psi,
                p.dci_dimensionless.psi,
                1e-7
            ));
            assert!(close(
                t.isotropic_acceleration,
                p.isotropic_acceleration,
                1e-8
            ));
            let w = a.determinant().abs() / i.determinant();
            assert!(
                close(p.manipulability, w, 1e-9),
                "{name}: {} vs {w}",
                p.manipulability
            );
        }
    }
}

/// Khatib & Burdick's isotropic acceleration and Yoshikawa's radii by brute force over
/// directions (planar five-bar, platform space: `τ = A⁻ᵀ I u̇`).
#[test]
fn isotropic_acceleration_and_radii_by_brute_force() {
    let m = model("planar_five_bar");
    let plan = Plan::new(&m).unwrap();
    let x = vec![0.03, 0.31];
    let i = indices::from_rows(&noc::mass_matrix(&plan, &x).unwrap()).unwrap();
    let a = indices::from_rows(&noc::actuation(&plan, &x).unwrap()).unwrap();
    let p = platform_indices(&i, &a).unwrap();
    let e = a.transpose().try_inverse().unwrap() * &i; // τ = E u̇
    let b = i.clone().try_inverse().unwrap() * a.transpose(); // u̇ = B τ
    let (mut iso, mut rmin, mut rmax) = (f64::INFINITY, f64::INFINITY, 0.0f64);
    let n = 200_000;
    for k in 0..n {
        let th = std::f64::consts::TAU * k as f64 / n as f64;
        let d = nalgebra::DVector::from_row_slice(&[th.cos(), th.sin()]);
        // Largest acceleration along d within |τ_i| ≤ 1.
        iso = iso.min(1.0 / (&e * &d).amax());
        let r = (&b * &d).norm();
        rmin = rmin.min(r);
        rmax = rmax.max(r);
    }
    assert!(iso >= p.isotropic_acceleration * (1.0 - 1e-12));
    assert!(
        close(iso, p.isotropic_acceleration, 1e-6),
        "{iso} vs {}",
        p.isotropic_acceleration
    );
    assert!(close(rmin, p.acceleration_radii[0], 1e-6));
    assert!(close(rmax, p.acceleration_radii[1], 1e-6));
}

#[test]
fn bad_input_is_an_error_never_nan() {
    let bad: [[f64; 3]; 3] = [[1.0, 0.2, 0.0], [0.1, 1.0, 0.0], [0.0, 0.0, 1.0]];
    assert!(matches!(
        g3::inertia_indices(&bad),
        Err(g3::IndexError::NotSymmetric { .. })
    ));
    let nan = [[1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0], [0.0, 0.0, 1.0]];
    assert!(matches!(
        g3::inertia_indices(&nan),
        Err(g3::IndexError::NotFinite { row: 1, col: 1 })
    ));
    let indefinite = [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    assert!(matches!(
        g3::inertia_indices(&indefinite),
        Err(g3::IndexError::NotPositiveDefinite { .. })
    ));
    assert!(g3::inertia_indices(&[[0.0; 3]; 3]).is_err());
    assert!(g3::inertia_indices(&[[f64::INFINITY; 3]; 3]).is_err());
    let dm = |a: &[[f64; 3]; 3]| DMatrix::from_fn(3, 3, |i, j| a[i][j]);
    assert!(matches!(
        inertia_indices(&dm(&bad)),
        Err(IndexError::NotSymmetric { .. })
    ));
    assert!(matches!(
        inertia_indices(&dm(&nan)),
        Err(IndexError::NotFinite { .. })
    ));
    assert!(matches!(
        inertia_indices(&dm(&indefinite)),
        Err(IndexError::NotPositiveDefinite { .. })
    ));
    // Parallel: NaN coordinates and an unreachable pose are runtime errors, not NaN indices.
    let m = model("planar_five_bar");
    let plan = Plan::new(&m).unwrap();
    for space in [Space::Actuator, Space::Platform] {
        assert!(parallel_indices(&plan, &[f64::NAN, 0.3], space).is_err());
        assert!(parallel_indices(&plan, &[0.0, 5.0], space).is_err());
    }
    // Trees: wrong length, NaN.
    let path = tests::pkm::spec_path("planar_2r");
    let src = std::fs::read_to_string(&path).unwrap();
    let Ok((codegen::spec::Mechanism::Tree(t), _)) =
        codegen::spec::load_mechanism(&path.to_string_lossy(), &src)
    else {
        panic!("planar_2r is a tree");
    };
    assert!(indices::tree_indices(&t, &[0.1]).is_err());
    assert!(indices::tree_indices(&t, &[0.1, f64::NAN]).is_err());
}

/// The generated modules carry the index function (`inertia_indices`, emitted after the
/// dynamics): on the actuator-space inertia of the Agile Eye, the joint-space inertia of the
/// PUMA 560 and the five-bar in joint coordinates it agrees with `runtime::indices`.
#[test]
fn generated_modules_carry_the_indices() {
    use runtime::indices::inertia_indices as reference;
    let check = |m: Vec<Vec<f64>>, eig: &[f64], cond: f64, psi2: f64| {
        let r = reference(&runtime::indices::from_rows(&m).unwrap()).unwrap();
        let mut want = r.eigenvalues.clone();
        want.sort_by(f64::total_cmp);
        let mut got = eig.to_vec();
        got.sort_by(f64::total_cmp);
        assert!(tests::pkm::rel(&got, &want) < 1e-10, "{got:?} vs {want:?}");
        assert!((cond - r.condition).abs() <= 1e-10 * r.condition);
        assert!(
            (psi2 - r.dci_dimensionless.psi).abs() <= 1e-10 * r.dci_dimensionless.psi.max(1e-3)
        );
    };
    let x = [1.0, 0.1, -0.05, 0.02];
    let n = (x.iter().map(|v| v * v).sum::<f64>()).sqrt();
    let x = x.map(|v| v / n);
    let m = mechanisms::agile_eye::actuator_mass_matrix(&x).unwrap();
    let g = mechanisms::agile_eye::inertia_indices(&m).unwrap();
    check(
        m.iter().map(|r| r.to_vec()).collect(),
        &g.eigenvalues,
        g.condition,
        g.dci_dimensionless_psi,
    );
    let m = mechanisms::puma560::mass_matrix(&[0.1, -0.4, 0.3, 0.2, -0.5, 0.7]);
    let g = mechanisms::puma560::inertia_indices(&m).unwrap();
    check(
        m.iter().map(|r| r.to_vec()).collect(),
        &g.eigenvalues,
        g.condition,
        g.dci_dimensionless_psi,
    );
    let x = mechanisms::five_bar_joints::forward_kinematics(&[0.1, -0.1], &[0.0; 4]).unwrap();
    let m = mechanisms::five_bar_joints::mass_matrix(&x).unwrap();
    let g = mechanisms::five_bar_joints::inertia_indices(&m).unwrap();
    check(
        m.iter().map(|r| r.to_vec()).collect(),
        &g.eigenvalues,
        g.condition,
        g.dci_dimensionless_psi,
    );
}
