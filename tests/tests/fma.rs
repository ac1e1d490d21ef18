//! Fused multiply–add (`codegen::Config::fma`): the fused modules of `tests::variants::fma` (a
//! tree of 6 and of 7 joints, a platform, a closed loop) agree with the bundled unfused ones
//! within a relative ∞-norm bound on random states, and the op counts add up: every fusion
//! removes one `mul` and one `add`, the flops stay, no other column moves.

use tests::agree::worst;
use tests::variants::fma;

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
