//! `[scene] snap` / `--snap TOL`: near-exact angles taken as exact. The KUKA iiwa 14 URDF as
//! bundled writes its quarter and half turns to full precision; the same file with them rounded
//! to 5 digits (`1.5708`, `3.1416`, as many published URDFs do) gives a model that differs by
//! ~1e-5 and costs more operations, because nothing folds. Snapped with a tolerance of 1e-4 it
//! is the full-precision model again, number for number, at the same cost; every change is
//! listed as a warning.

use codegen::spec::{Mechanism, SceneOverrides, load};
use codegen::{Config, compile};
use runtime::model::Model;

const IIWA: &str = include_str!("../../mechanisms/specs/iiwa14.urdf");

fn rounded() -> String {
    IIWA.replace("1.5707963267948966", "1.5708")
        .replace("3.141592653589793", "3.1416")
}

fn model(src: &str, snap: Option<f64>) -> (Model, usize) {
    let o = SceneOverrides {
        snap,
        ..Default::default()
    };
    match load("iiwa14.urdf", src, &o).map(|l| (l.mechanism, l.warnings)) {
        Ok((Mechanism::Tree(m), warnings)) => (m, warnings.len()),
        _ => panic!("not a tree"),
    }
}

fn flops(src: &str, snap: Option<f64>) -> usize {
    let cfg = Config {
        scene: SceneOverrides {
            snap,
            ..Default::default()
        },
        ..Default::default()
    };
    let g = compile("iiwa14.urdf", src, &cfg).unwrap();
    let (_, id) = g
        .stats
        .iter()
        .find(|(n, _)| n == "inverse_dynamics")
        .unwrap();
    id.flops()
}

#[test]
fn snapping_restores_the_exact_model_and_its_cost() {
    let src = rounded();
    assert_ne!(src, IIWA, "the rounding must change the file");
    let (exact, w0) = model(IIWA, None);
    let (round, _) = model(&src, None);
    let (snapped, w) = model(&src, Some(1e-4));
    assert_ne!(round, exact);
    assert_eq!(snapped, exact);
    // One warning per snapped joint, none for the exact file.
    let (_, w_exact) = model(IIWA, Some(1e-4));
    assert_eq!(w_exact, w0);
    assert!(w > w0, "snaps are listed");
    // Too small a tolerance (below the 3.7e-6 and 7.3e-6 of the rounding) leaves the model
    // off the exact one (it snaps only the products of two small errors, ~1e-11).
    let (tight, _) = model(&src, Some(1e-7));
    assert_ne!(tight, exact);

    let (f_exact, f_round, f_snap) = (
        flops(IIWA, None),
        flops(&src, None),
        flops(&src, Some(1e-4)),
    );
    assert_eq!(f_snap, f_exact);
    assert!(f_round > f_exact, "rounded {f_round} vs exact {f_exact}");

    // The model change is of the size of the rounding (≤ 1e-4 relative in the efforts).
    let mut r = tests::rng(21);
    for _ in 0..50 {
        let (q, qd, qdd) = tests::random_state(&mut r, 7);
        let a = runtime::noc::inverse_dynamics(&round, &q, &qd, &qdd);
        let b = runtime::noc::inverse_dynamics(&snapped, &q, &qd, &qdd);
        let e = tests::rel_err(a.as_slice(), b.as_slice());
        assert!(e < 1e-4, "{e}");
    }
}

#[test]
fn snap_in_the_scene_table_and_bad_tolerances() {
    let four = include_str!("../../mechanisms/specs/four_bar.toml");
    // The four-bar's rocker angle is a general angle: nothing near a quarter turn but the
    // crank's exact π/2, so a scene snap changes nothing.
    let with = four.replace("[mechanism]", "[scene]\nsnap = 1e-6\n[mechanism]");
    let a = codegen::spec::load_mechanism("f.toml", four).unwrap().0;
    let b = codegen::spec::load_mechanism("f.toml", &with).unwrap().0;
    match (a, b) {
        (Mechanism::Closed(a), Mechanism::Closed(b)) => assert_eq!(a.tree, b.tree),
        _ => panic!("closed"),
    }
    let bad = four.replace("[mechanism]", "[scene]\nsnap = 0.5\n[mechanism]");
    let err = codegen::spec::load_mechanism("f.toml", &bad).unwrap_err();
    assert!(err.render().contains("snap"));
}
