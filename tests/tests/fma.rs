//! Fused multiply–add (`codegen::Config::fma`): the fused modules of `tests::variants::fma` (a
//! tree of 6 and of 7 joints, a platform, a closed loop) agree with the bundled unfused ones
//! within a relative ∞-norm bound on random states, and the op counts add up: every fusion
//! removes one `mul` and one `add`, the flops stay, no other column moves.

use mechanisms::Dynamics;
use rand::Rng;
use tests::variants::fma;

/// `‖a − b‖∞ / ‖b‖∞` (0 when both are 0).
fn rel(a: &[f64], b: &[f64]) -> f64 {
    let num = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let den = b.iter().map(|y| y.abs()).fold(0.0, f64::max);
    if num == 0.0 { 0.0 } else { num / den }
}

fn flat<const N: usize>(m: &[[f64; N]; N]) -> Vec<f64> {
    m.iter().flatten().copied().collect()
}

/// The largest relative difference of every dynamics function between `plain` and `fused` at
/// `states` random states near home (actuated joints moved by up to `spread`, then the
/// configuration found by forward kinematics; `x = q` for a tree).
fn worst<A, B, const NX: usize, const N: usize>(
    plain: &A,
    fused: &B,
    states: usize,
    spread: f64,
    seed: u64,
) -> f64
where
    A: Dynamics<NX, N, Scalar = f64>,
    B: Dynamics<NX, N, Scalar = f64>,
{
    let mut r = tests::rng(seed);
    let q0 = plain.inverse_kinematics(&A::HOME).expect("home is regular");
    let mut worst = 0.0_f64;
    let mut n = 0;
    while n < states {
        let q: [f64; N] = core::array::from_fn(|i| q0[i] + r.random_range(-spread..spread));
        let u: [f64; N] = core::array::from_fn(|_| r.random_range(-1.0..1.0));
        let ud: [f64; N] = core::array::from_fn(|_| r.random_range(-2.0..2.0));
        let Ok(x) = plain.forward_kinematics(&q, &A::HOME) else {
            continue;
        };
        let (Ok(tau), Ok(m)) = (plain.inverse_dynamics(&x, &u, &ud), plain.mass_matrix(&x)) else {
            continue;
        };
        n += 1;
        let tau_f = fused.inverse_dynamics(&x, &u, &ud).expect("fused ID");
        worst = worst.max(rel(&tau_f, &tau));
        worst = worst.max(rel(
            &flat(&fused.mass_matrix(&x).expect("fused M")),
            &flat(&m),
        ));
        let fd = plain.forward_dynamics(&x, &u, &tau).expect("FD");
        let fd_f = fused.forward_dynamics(&x, &u, &tau).expect("fused FD");
        worst = worst.max(rel(&fd_f, &fd));
        if let (Some(Ok((a, b))), Some(Ok((af, bf)))) = (
            plain.inverse_dynamics_derivatives(&x, &u, &ud),
            fused.inverse_dynamics_derivatives(&x, &u, &ud),
        ) {
            worst = worst.max(rel(&flat(&af), &flat(&a)));
            worst = worst.max(rel(&flat(&bf), &flat(&b)));
        }
    }
    worst
}

/// The bound: fusing changes roundings only.
const BOUND: f64 = 1e-12;

#[test]
fn fused_modules_agree_with_plain_ones() {
    let cases = [
        (
            "puma560",
            worst(
                &mechanisms::puma560::Module,
                &fma::puma560::Module,
                200,
                3.0,
                1,
            ),
        ),
        (
            "chain7",
            worst(
                &mechanisms::chain7::Module,
                &fma::chain7::Module,
                200,
                3.0,
                2,
            ),
        ),
        (
            "gough_stewart",
            worst(
                &mechanisms::gough_stewart::Module,
                &fma::gough_stewart::Module,
                100,
                0.05,
                3,
            ),
        ),
        (
            "spherical_five_bar",
            worst(
                &mechanisms::spherical_five_bar::Module,
                &fma::spherical_five_bar::Module,
                100,
                0.3,
                4,
            ),
        ),
    ];
    for (name, w) in cases {
        println!("{name}: fused vs plain, worst relative ∞-norm {w:.2e}");
        assert!(w <= BOUND, "{name}: {w:e} > {BOUND:e}");
        assert!(w > 0.0, "{name}: no difference at all: was anything fused?");
    }
}

/// Every function's counts with and without fusion: `add` and `mul` each fall by the number
/// of `fma`s, nothing else moves, and the `fma` column is in the table only when on.
#[test]
fn op_counts_add_up() {
    for spec in [
        "puma560.toml",
        "chain7.toml",
        "gough_stewart.toml",
        "spherical_five_bar.toml",
    ] {
        let src = std::fs::read_to_string(format!("../mechanisms/specs/{spec}")).unwrap();
        let plain = codegen::compile(spec, &src, &codegen::Config::default()).unwrap();
        let fused = codegen::compile(
            spec,
            &src,
            &codegen::Config {
                fma: true,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(plain.stats.len(), fused.stats.len());
        let mut total = 0;
        for ((name, p), (name_f, f)) in plain.stats.iter().zip(&fused.stats) {
            assert_eq!(name, name_f);
            assert_eq!(p.add - f.add, f.fma, "{spec} {name}: adds removed");
            assert_eq!(p.mul - f.mul, f.fma, "{spec} {name}: mults removed");
            assert_eq!(p.flops(), f.flops(), "{spec} {name}: flops");
            let same =
                |c: &codegen::schedule::OpCount| (c.neg, c.div, c.sqrt, c.sin_cos, c.cmp, c.atan2);
            assert_eq!(same(p), same(f), "{spec} {name}: other columns");
            assert_eq!(p.fma, 0);
            total += f.fma;
        }
        assert!(total > 0, "{spec}: nothing fused");
        assert!(!plain.code.contains("fma") && !plain.code.contains("mul_add"));
        assert!(fused.code.contains("| fma |") && fused.code.contains("libm::fma("));
        println!("{spec}: {total} fma over {} functions", fused.stats.len());
    }
}
