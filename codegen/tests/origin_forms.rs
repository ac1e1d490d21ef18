//! A joint's rotation may be written as `rpy`, `quat`, `matrix` or `axis_angle`: each gives
//! the same model as the others, checked against nalgebra's conversions (an independent
//! route from the reader's own formulas).

use nalgebra::{Rotation3, UnitQuaternion, Vector3};

fn arm(origin: &str) -> String {
    format!(
        r#"
[mechanism]
name = "arm"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "link1"
mass = 1.0
com = [0.1, 0.0, 0.0]
inertia = {{ ixx = 0.01, iyy = 0.02, izz = 0.03 }}

[[body]]
name = "link2"
mass = 0.5
com = [0.2, 0.0, 0.0]
inertia = {{ ixx = 0.004, iyy = 0.005, izz = 0.006 }}

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
origin = {origin}
axis = [0.0, 1.0, 0.0]
"#
    )
}

fn model(origin: &str) -> runtime::model::Model {
    match codegen::spec::load_tree("arm.toml", &arm(origin)) {
        Ok((m, _)) => m,
        Err(d) => panic!("{origin}:\n{}", d.render()),
    }
}

fn max_diff(a: &runtime::model::Model, b: &runtime::model::Model) -> f64 {
    let (x, y) = (&a.joints[1].origin, &b.joints[1].origin);
    let mut d: f64 = 0.0;
    for i in 0..3 {
        d = d.max((x.translation[i] - y.translation[i]).abs());
        for j in 0..3 {
            d = d.max((x.rotation[i][j] - y.rotation[i][j]).abs());
        }
    }
    d
}

#[test]
fn every_rotation_form_gives_the_same_joint() {
    let (roll, pitch, yaw) = (0.3, -0.2, 1.1);
    let xyz = "[0.4, 0.05, -0.02]";
    let reference = model(&format!(
        "{{ xyz = {xyz}, rpy = [{roll}, {pitch}, {yaw}] }}"
    ));
    // nalgebra: R = Rz(yaw) Ry(pitch) Rx(roll), URDF's convention.
    let q = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
    let r = q.to_rotation_matrix();
    let (axis, angle) = q.axis_angle().unwrap();
    let forms = [
        format!(
            "{{ xyz = {xyz}, quat = [{}, {}, {}, {}] }}",
            q.w, q.i, q.j, q.k
        ),
        format!(
            "{{ xyz = {xyz}, matrix = [[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]] }}",
            r[(0, 0)],
            r[(0, 1)],
            r[(0, 2)],
            r[(1, 0)],
            r[(1, 1)],
            r[(1, 2)],
            r[(2, 0)],
            r[(2, 1)],
            r[(2, 2)]
        ),
        format!(
            "{{ xyz = {xyz}, axis_angle = {{ axis = [{}, {}, {}], angle = {angle} }} }}",
            axis[0] * 2.0,
            axis[1] * 2.0,
            axis[2] * 2.0
        ),
    ];
    for f in &forms {
        let d = max_diff(&model(f), &reference);
        assert!(d < 1e-15, "{f}: {d:e}");
    }
    // The reference itself is nalgebra's matrix (the check can fail).
    let m = &reference.joints[1].origin.rotation;
    for i in 0..3 {
        for j in 0..3 {
            assert!((m[i][j] - r[(i, j)]).abs() < 1e-15);
        }
    }
}

/// Values read off a drawing: a quaternion to 4 digits is normalized, and quarter turns about
/// a coordinate axis by axis-angle are exact.
#[test]
fn short_quaternions_and_exact_quarter_turns() {
    let a = model("{ quat = [0.7071, 0.0, 0.0, 0.7071] }");
    let b = model("{ rpy = [0.0, 0.0, \"90deg\"] }");
    assert!(max_diff(&a, &b) < 1e-15, "{:e}", max_diff(&a, &b));
    let c = model("{ axis_angle = { axis = [0.0, 0.0, 2.0], angle = \"90deg\" } }");
    assert_eq!(c.joints[1].origin.rotation, b.joints[1].origin.rotation);
    // A matrix slightly off orthonormal is made a rotation.
    let v = Vector3::new(1.0, 2.0, 3.0).normalize();
    let r = Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(v), 0.7);
    let e = 1e-8;
    let d = model(&format!(
        "{{ matrix = [[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]] }}",
        r[(0, 0)] + e,
        r[(0, 1)],
        r[(0, 2)],
        r[(1, 0)],
        r[(1, 1)],
        r[(1, 2)],
        r[(2, 0)],
        r[(2, 1)],
        r[(2, 2)]
    ));
    let m = nalgebra::Matrix3::from_fn(|i, j| d.joints[1].origin.rotation[i][j]);
    assert!((m.transpose() * m - nalgebra::Matrix3::identity()).amax() < 1e-15);
    assert!((m - r.matrix()).amax() < 2e-8);
}

/// Bad rotations are errors at their key.
#[test]
fn bad_rotations_are_refused_at_their_key() {
    let cases = [
        (
            "{ rpy = [0.0, 0.0, 1.0], quat = [1.0, 0.0, 0.0, 0.0] }",
            "origin.quat",
            "twice",
        ),
        ("{ quat = [1.0, 0.1, 0.0, 0.0] }", "origin.quat", "norm"),
        ("{ quat = [1.0, 0.0, 0.0] }", "origin.quat", "4 numbers"),
        (
            "{ matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]] }",
            "origin.matrix",
            "determinant",
        ),
        (
            "{ matrix = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }",
            "origin.matrix",
            "orthonormal",
        ),
        (
            "{ axis_angle = { axis = [0.0, 0.0, 0.0], angle = 1.0 } }",
            "origin.axis_angle.axis",
            "zero",
        ),
        (
            "{ axis_angle = { axis = [0.0, 0.0, 1.0] } }",
            "origin.axis_angle.angle",
            "angle",
        ),
    ];
    for (origin, key, word) in cases {
        let Err(d) = codegen::spec::load_tree("arm.toml", &arm(origin)) else {
            panic!("{origin} was accepted");
        };
        let text = d.render();
        assert!(text.contains(word), "{origin}: no `{word}` in\n{text}");
        assert!(
            d.iter()
                .any(|e| e.key.as_deref().is_some_and(|k| k.ends_with(key))),
            "{origin}: not at {key}:\n{text}"
        );
    }
}
