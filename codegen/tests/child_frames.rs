//! A tree joint placed from both bodies (`child_origin` on a joint whose child no other joint
//! reaches, docs/spec.md "Child-side joint frames") gives the model of the same arm written
//! with every body frame at its joint frame. The second arm's numbers are converted by hand
//! (below), not by the code under test.

use codegen::spec::load_mechanism;

mod common;

/// The arm with body frames at the joint frames.
const JOINT_FRAMES: &str = r#"
[mechanism]
name = "arm"

[[body]]
name = "link1"
mass = 1.0
com = [0.2, 0.0, 0.0]
inertia = { ixx = 0.01, iyy = 0.02, izz = 0.03 }

[[body]]
name = "link2"
mass = 0.5
com = [0.1, 0.0, 0.05]
inertia = { ixx = 0.004, iyy = 0.005, izz = 0.006 }

[[body]]
name = "link3"
mass = 0.3
com = [0.05, 0.0, 0.0]
inertia = { ixx = 0.001, iyy = 0.002, izz = 0.003 }

[[joint]]
name = "j1"
kind = "revolute"
parent = "base"
child = "link1"
axis = [0.0, 0.0, 1.0]

[[joint]]
name = "j2"
kind = "revolute"
parent = "link1"
child = "link2"
origin = { xyz = [0.5, 0.0, 0.0] }
axis = [0.0, 1.0, 0.0]

[[joint]]
name = "j3"
kind = "revolute"
parent = "link2"
child = "link3"
origin = { xyz = [0.3, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
"#;

/// The same arm with link2 described in its own frame F, in which j2's frame sits at
/// (−0.1, 0.2, 0) turned 90° about z: a point p of the joint frame is Rz(90°) p + (−0.1, 0.2, 0)
/// in F. So link2's mass centre (0.1, 0, 0.05) is (0, 0.1, 0.05) + (−0.1, 0.2, 0) =
/// (−0.1, 0.3, 0.05); its inertia diag(0.004, 0.005, 0.006) is diag(0.005, 0.004, 0.006)
/// (x and y swap); j3's frame at (0.3, 0, 0) is at (0, 0.3, 0) + (−0.1, 0.2, 0) = (−0.1, 0.5, 0),
/// turned 90° about z.
fn child_side() -> String {
    JOINT_FRAMES
        .replace(
            "com = [0.1, 0.0, 0.05]\ninertia = { ixx = 0.004, iyy = 0.005, izz = 0.006 }",
            "com = [-0.1, 0.3, 0.05]\ninertia = { ixx = 0.005, iyy = 0.004, izz = 0.006 }",
        )
        .replace(
            "origin = { xyz = [0.5, 0.0, 0.0] }\naxis = [0.0, 1.0, 0.0]",
            "origin = { xyz = [0.5, 0.0, 0.0] }\nchild_origin = { xyz = [-0.1, 0.2, 0.0], rpy = [0.0, 0.0, \"90 deg\"] }\naxis = [0.0, 1.0, 0.0]",
        )
        .replace(
            "origin = { xyz = [0.3, 0.0, 0.0] }",
            "origin = { xyz = [-0.1, 0.5, 0.0], rpy = [0.0, 0.0, \"90 deg\"] }",
        )
}

#[test]
fn a_child_side_frame_gives_the_same_model() {
    let b = child_side();
    assert_ne!(b, JOINT_FRAMES);
    assert_eq!(b.matches("child_origin").count(), 1);
    let (ma, _) = load_mechanism("a.toml", JOINT_FRAMES).unwrap_or_else(|d| panic!("{d}"));
    let (mb, wb) = load_mechanism("b.toml", &b).unwrap_or_else(|d| panic!("{d}"));
    assert!(wb.is_empty(), "{wb}");
    let (a, b) = (format!("{ma:?}"), format!("{mb:?}"));
    // The same numbers, to the rounding of the hand conversion's sums.
    let worst = common::worst_difference(&a, &b);
    assert!(worst < 1e-15, "{worst:e}");
}

#[test]
fn dh_on_a_child_side_frame_is_refused() {
    let b = child_side().replace(
        "origin = { xyz = [-0.1, 0.5, 0.0], rpy = [0.0, 0.0, \"90 deg\"] }",
        "dh = { a = 0.3, alpha = 0.0, d = 0.0, theta = 0.0 }",
    );
    let e = load_mechanism("b.toml", &b)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("placed by DH parameters on \"link2\""), "{e}");
}

/// `[scene] frames` offers a body's own frame, the one the spec writes it in: for link2, F,
/// whose pose in j2's joint frame is `child_origin⁻¹` (the rotation −90° about z, the origin
/// at −Rz(−90°)·(−0.1, 0.2, 0) = (−0.2, −0.1, 0)). It was the joint frame, so a child-side
/// body's `link2_pose` was off by `child_origin` (found by QA against Pinocchio with the frame
/// placed by hand). link3, written in its joint frame in both arms, is the same frame.
#[test]
fn a_child_side_body_s_frame_is_its_own_frame() {
    use codegen::spec::{SceneOverrides, load};
    let scene = "\n[scene]\nframes = [\"link2\", \"link3\"]\n";
    let a = load(
        "a.toml",
        &format!("{JOINT_FRAMES}{scene}"),
        &SceneOverrides::default(),
    )
    .unwrap_or_else(|d| panic!("{d}"));
    let b = load(
        "b.toml",
        &format!("{}{scene}", child_side()),
        &SceneOverrides::default(),
    )
    .unwrap_or_else(|d| panic!("{d}"));
    let (fa, fb) = (&a.scene.frames, &b.scene.frames);
    assert_eq!(fa.len(), 2);
    assert_eq!(fb.len(), 2);
    let close = |x: &[f64], y: &[f64]| x.iter().zip(y).all(|(p, q)| (p - q).abs() < 1e-15);
    // link2 in arm a: its joint frame.
    assert!(
        close(&fa[0].placement.translation, &[0.0; 3]),
        "{:?}",
        fa[0]
    );
    // link2 in arm b: F.
    assert_eq!(fb[0].body, fa[0].body);
    assert!(
        close(&fb[0].placement.translation, &[-0.2, -0.1, 0.0]),
        "{:?}",
        fb[0]
    );
    let r = fb[0].placement.rotation;
    let rz = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    assert!((0..3).all(|i| close(&r[i], &rz[i])), "{r:?}");
    // link3: the same frame in both.
    assert_eq!(fb[1].body, fa[1].body);
    assert!(close(
        &fb[1].placement.translation,
        &fa[1].placement.translation
    ));
    assert!((0..3).all(|i| close(&fb[1].placement.rotation[i], &fa[1].placement.rotation[i])));
}
