//! The `sin` and `cos` of a function's input angles in one call (`codegen::Config::batch_sin_cos`):
//! the batched modules of `tests::variants::batch_sin_cos` (two trees of 7 joints, a closed loop
//! in joint coordinates) agree with the bundled ones to rounding on random states; where an
//! angle is beyond the polynomial's range or not finite, every function takes the math backend
//! and is bit for bit the bundled one; the op counts do not move; a module with no angle of the
//! inputs alone is the same with and without the option.

use codegen::Config;
use tests::agree::worst;
use tests::variants::batch_sin_cos as batched;

/// The bound: the polynomial is within 2 ulp of the backend's `sin` and `cos`
/// (`lanes.rs`, against correctly rounded values); the rest is the same arithmetic.
const BOUND: f64 = 1e-12;

#[test]
fn batched_modules_agree_with_plain_ones() {
    let cases = [
        (
            "chain7",
            worst(
                &mechanisms::chain7::Module,
                &batched::chain7::Module,
                200,
                3.0,
                11,
            ),
        ),
        (
            "iiwa14",
            worst(
                &mechanisms::iiwa14::Module,
                &batched::iiwa14::Module,
                200,
                3.0,
                12,
            ),
        ),
        (
            "spherical_five_bar",
            worst(
                &mechanisms::spherical_five_bar::Module,
                &batched::spherical_five_bar::Module,
                100,
                0.3,
                13,
            ),
        ),
    ];
    for (name, w) in cases {
        println!("{name}: batched vs plain, worst relative ∞-norm {w:.2e}");
        assert!(w <= BOUND, "{name}: {w:e} > {BOUND:e}");
        assert!(
            w > 0.0,
            "{name}: no difference at all: was anything batched?"
        );
    }
}

/// Far angles: within the polynomial's range (8.2e5 rad) the batched chain agrees with the
/// plain one to rounding; with the angles beyond it, or NaN, every call takes the backend and
/// returns bit for bit what the plain module returns (compared as text, so that NaN equals
/// NaN). Every angle is moved: a function that reads none beyond the range (the chain's first
/// angle enters no function, its last none but the mass matrix) keeps the polynomial.
#[test]
fn far_and_non_finite_angles_take_the_backend() {
    use batched::chain7 as b;
    use mechanisms::chain7 as p;
    let mut r = tests::rng(14);
    for k in 0..60 {
        let (q, qd, qdd) = tests::random_state(&mut r, p::DOF);
        let q: [f64; p::DOF] = q.try_into().unwrap();
        let qd: [f64; p::DOF] = qd.try_into().unwrap();
        let qdd: [f64; p::DOF] = qdd.try_into().unwrap();
        let q = match k % 3 {
            0 => q.map(|v| v + 8.0e5),
            1 => q.map(|v| v + 9.0e5),
            _ => [f64::NAN; p::DOF],
        };
        let bound = |what: &str, a: &[f64], c: &[f64]| {
            let e = tests::pkm::rel(a, c);
            assert!(e <= BOUND, "{what} at {q:?}: {e:e}");
        };
        let same = |what: &str, a: String, c: String| assert_eq!(a, c, "{what} at {q:?}");
        match k % 3 {
            // In range: agreement to rounding.
            0 => {
                bound(
                    "ID",
                    &b::inverse_dynamics(&q, &qd, &qdd),
                    &p::inverse_dynamics(&q, &qd, &qdd),
                );
                bound(
                    "M",
                    b::mass_matrix(&q).as_flattened(),
                    p::mass_matrix(&q).as_flattened(),
                );
            }
            // Beyond the range or NaN: the backend, bit for bit.
            _ => {
                same(
                    "ID",
                    format!("{:?}", b::inverse_dynamics(&q, &qd, &qdd)),
                    format!("{:?}", p::inverse_dynamics(&q, &qd, &qdd)),
                );
                same(
                    "M",
                    format!("{:?}", b::mass_matrix(&q)),
                    format!("{:?}", p::mass_matrix(&q)),
                );
                same(
                    "FD",
                    format!("{:?}", b::forward_dynamics(&q, &qd, &qdd)),
                    format!("{:?}", p::forward_dynamics(&q, &qd, &qdd)),
                );
                same(
                    "∂ID",
                    format!("{:?}", b::inverse_dynamics_derivatives(&q, &qd, &qdd)),
                    format!("{:?}", p::inverse_dynamics_derivatives(&q, &qd, &qdd)),
                );
            }
        }
    }
}

/// Batching moves statements, not operations: every function's counts are the same; the
/// batched module calls `sin_cos_batch` and says so in its header; generating twice gives the
/// same bytes; a module with no angle of the inputs alone (the Gough–Stewart's orientation is
/// a quaternion) is byte for byte the plain one.
#[test]
fn op_counts_and_bytes() {
    let cfg = Config {
        batch_sin_cos: true,
        ..Default::default()
    };
    for spec in [
        "chain7.toml",
        "spherical_five_bar.toml",
        "gough_stewart.toml",
    ] {
        let src = std::fs::read_to_string(format!("../mechanisms/specs/{spec}")).unwrap();
        let plain = codegen::compile(spec, &src, &Config::default()).unwrap();
        let batch = codegen::compile(spec, &src, &cfg).unwrap();
        assert_eq!(plain.stats, batch.stats, "{spec}: op counts");
        assert_eq!(
            batch.code,
            codegen::compile(spec, &src, &cfg).unwrap().code,
            "{spec}: not deterministic"
        );
        assert!(!plain.code.contains("sin_cos_batch"));
        if spec == "gough_stewart.toml" {
            assert_eq!(
                plain.code, batch.code,
                "{spec}: nothing to batch, yet changed"
            );
        } else {
            assert!(batch.code.contains("fn sin_cos_batch"), "{spec}");
            assert!(batch.code.contains("// Batched `sin_cos`: on"), "{spec}");
        }
    }
}
