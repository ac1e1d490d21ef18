//! Unit tests of the spec layer: lowering (DH, MDH, fixed merging, U/S expansion, order), URDF
//! conventions, angle exactness, and a no-panic fuzz loop.

use runtime::model::{JointKind, Mat3, Model, Transform, Vec3, axis_angle};

use super::geom::{MassProps, dh_matrix, mdh_matrix};
use super::ir::{Dh, Kind};
use super::load;

fn ok(name: &str, src: &str) -> Model {
    match load(name, src) {
        Ok((m, w)) => {
            assert!(w.is_empty(), "unexpected warnings:\n{}", w.render());
            m
        }
        Err(e) => panic!("{}", e.render()),
    }
}

/// World pose of every body frame: `X_i = X_parent · origin_i · motion_i(q_i)`.
fn fk(m: &Model, q: &[f64]) -> Vec<Transform> {
    let mut x: Vec<Transform> = Vec::new();
    for (i, j) in m.joints.iter().enumerate() {
        let parent = j.parent.map_or(Transform::IDENTITY, |p| x[p]);
        let motion = match j.kind {
            JointKind::Revolute => Transform {
                rotation: axis_angle(&j.axis, q[i]),
                translation: [0.0; 3],
            },
            JointKind::Prismatic => Transform {
                rotation: Transform::IDENTITY.rotation,
                translation: j.axis.map(|a| a * q[i]),
            },
        };
        x.push(parent.compose(&j.origin).compose(&motion));
    }
    x
}

/// Mass properties of every body in the world frame.
fn world_props(m: &Model, q: &[f64]) -> Vec<MassProps> {
    fk(m, q)
        .iter()
        .zip(&m.bodies)
        .map(|(x, b)| {
            MassProps {
                mass: b.mass,
                com: b.com,
                inertia: b.inertia,
            }
            .transformed(x)
        })
        .collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

fn assert_vec(a: &Vec3, b: &Vec3, tol: f64) {
    for k in 0..3 {
        assert!(close(a[k], b[k], tol), "{a:?} vs {b:?}");
    }
}

fn assert_mat(a: &Mat3, b: &Mat3, tol: f64) {
    for r in 0..3 {
        assert_vec(&a[r], &b[r], tol);
    }
}

fn assert_tf(a: &Transform, b: &Transform, tol: f64) {
    assert_mat(&a.rotation, &b.rotation, tol);
    assert_vec(&a.translation, &b.translation, tol);
}

/// PUMA 560 (standard DH, Corke) plus a prismatic joint, each body with a mass centre and an
/// inertia in its distal DH frame.
const PUMA_DH: [(f64, &str, f64, f64, &str); 6] = [
    (0.0, "pi/2", 0.0, 0.0, "R"),
    (0.4318, "0", 0.0, 0.0, "R"),
    (0.0203, "-pi/2", 0.15005, 0.3, "R"),
    (0.0, "pi/2", 0.4318, 0.0, "P"),
    (0.0, "-pi/2", 0.0, -0.2, "R"),
    (0.1, "0", 0.0, 1.0, "R"),
];

fn dh_spec(table: &str) -> String {
    let mut s = String::from("[mechanism]\nname = \"dh_test\"\n");
    for (i, (a, alpha, d, theta, kind)) in PUMA_DH.iter().enumerate() {
        let parent = if i == 0 {
            "base".to_owned()
        } else {
            format!("l{i}")
        };
        s += &format!(
            "[[body]]\nname = \"l{n}\"\nmass = {m}\ncom = [0.1, {c}, -0.05]\ninertia = {{ ixx = 0.3, iyy = 0.4, izz = 0.5, ixy = 0.01, ixz = -0.02, iyz = 0.03 }}\n\
             [[joint]]\nname = \"j{n}\"\nkind = \"{kind}\"\nparent = \"{parent}\"\nchild = \"l{n}\"\n{table} = {{ a = {a}, alpha = \"{alpha}\", d = {d}, theta = {theta} }}\n",
            n = i + 1,
            m = 1.0 + i as f64,
            c = 0.02 * i as f64,
        );
    }
    s
}

fn dh_params() -> Vec<(Dh, Kind)> {
    PUMA_DH
        .iter()
        .map(|(a, alpha, d, theta, k)| {
            (
                Dh {
                    a: *a,
                    alpha: super::angle::parse_angle(alpha).unwrap(),
                    d: *d,
                    theta: *theta,
                },
                if *k == "R" {
                    Kind::Revolute
                } else {
                    Kind::Prismatic
                },
            )
        })
        .collect()
}

/// Checks that body `i`'s mass centre and inertia, mapped to the world by the model's FK, equal
/// those given in the user frame `F_i`, mapped by `F_i`'s world pose `user[i]`.
fn check_against_user_frames(m: &Model, q: &[f64], user: &[Transform]) {
    let world = world_props(m, q);
    let given = MassProps {
        mass: 0.0,
        com: [0.1, 0.0, -0.05],
        inertia: [[0.3, 0.01, -0.02], [0.01, 0.4, 0.03], [-0.02, 0.03, 0.5]],
    };
    for (i, (w, f)) in world.iter().zip(user).enumerate() {
        let g = MassProps {
            mass: 1.0 + i as f64,
            com: [0.1, 0.02 * i as f64, -0.05],
            ..given
        }
        .transformed(f);
        assert!(close(w.mass, g.mass, 0.0));
        assert_vec(&w.com, &g.com, 1e-12);
        assert_mat(&w.inertia, &g.inertia, 1e-12);
    }
}

#[test]
fn standard_dh_matches_direct_matrix_product() {
    let m = ok("dh.toml", &dh_spec("dh"));
    assert_eq!(m.dof(), 6);
    assert_eq!(m.joints[3].kind, JointKind::Prismatic);
    let params = dh_params();
    for q in [
        [0.0; 6],
        [0.3, -1.1, 0.7, 0.25, 2.0, -0.4],
        [-2.0, 0.5, 1.5, -0.1, -0.3, 3.0],
    ] {
        // User frame i = distal DH frame = product of the DH matrices 1..=i.
        let mut acc = Transform::IDENTITY;
        let user: Vec<Transform> = params
            .iter()
            .zip(q)
            .map(|((dh, k), qi)| {
                acc = acc.compose(&dh_matrix(dh, *k, qi));
                acc
            })
            .collect();
        check_against_user_frames(&m, &q, &user);
        // The body frame is the joint frame: x_i = user_i · (Tz(d)Tx(a)Rx(alpha))⁻¹, so the
        // origin of user frame i is at body-frame point (a, 0, d) rotated… check directly:
        let x = fk(&m, &q);
        for (i, (dh, _)) in params.iter().enumerate() {
            let g = super::geom::dh_offset(dh);
            assert_tf(&x[i].compose(&g), &user[i], 1e-12);
        }
    }
}

#[test]
fn modified_dh_matches_direct_matrix_product() {
    let m = ok("mdh.toml", &dh_spec("mdh"));
    let params = dh_params();
    for q in [[0.0; 6], [0.3, -1.1, 0.7, 0.25, 2.0, -0.4]] {
        let mut acc = Transform::IDENTITY;
        let user: Vec<Transform> = params
            .iter()
            .zip(q)
            .map(|((dh, k), qi)| {
                acc = acc.compose(&mdh_matrix(dh, *k, qi));
                acc
            })
            .collect();
        // MDH: body frame = user frame.
        let x = fk(&m, &q);
        for i in 0..6 {
            assert_tf(&x[i], &user[i], 1e-12);
        }
        check_against_user_frames(&m, &q, &user);
    }
}

#[test]
fn dh_quarter_turns_are_exact() {
    let m = ok(
        "x.toml",
        r#"
[mechanism]
name = "x"
[[body]]
name = "a"
mass = 1
[[body]]
name = "b"
mass = 1
[[joint]]
name = "j1"
kind = "R"
parent = "base"
child = "a"
mdh = { a = 0.0, alpha = "pi/2", d = 0.0, theta = "-90deg" }
[[joint]]
name = "j2"
kind = "R"
parent = "a"
child = "b"
origin = { rpy = ["pi", 0, "pi/2"] }
"#,
    );
    for j in &m.joints {
        for row in j.origin.rotation {
            for e in row {
                assert!(e == 0.0 || e.abs() == 1.0, "{:?}", j.origin.rotation);
            }
        }
    }
}

const CHAIN_WITH_FIXED: &str = r#"
[mechanism]
name = "fixed_test"
[[body]]
name = "a"
mass = 2.0
com = [0.1, 0.2, 0.3]
inertia = { ixx = 0.1, iyy = 0.2, izz = 0.25, ixy = 0.01 }
[[body]]
name = "tool"
mass = 0.7
com = [0.0, 0.05, 0.1]
inertia = { ixx = 0.01, iyy = 0.02, izz = 0.015, iyz = -0.001 }
inertia_rpy = [0.2, 0.0, -0.3]
[[body]]
name = "c"
mass = 1.0
com = [0.3, 0.0, 0.0]
inertia = { ixx = 0.05, iyy = 0.05, izz = 0.02 }
[[body]]
name = "plate"
mass = 5.0
com = [0.0, 0.0, 0.01]
inertia = { ixx = 1, iyy = 1, izz = 1.5 }
[[body]]
name = "d"
mass = 0.5
[[joint]]
name = "mount"
kind = "KIND"
parent = "base"
child = "plate"
origin = { xyz = [0.0, 0.0, 0.5], rpy = [0.0, 0.0, 0.4] }
[[joint]]
name = "j1"
kind = "R"
parent = "plate"
child = "a"
origin = { xyz = [0.1, 0.0, 0.2], rpy = [0.1, 0.2, 0.3] }
axis = [0, 1, 0]
[[joint]]
name = "weld"
kind = "KIND"
parent = "a"
child = "tool"
origin = { xyz = [0.4, -0.1, 0.05], rpy = [0.5, -0.2, 1.0] }
[[joint]]
name = "j2"
kind = "R"
parent = "tool"
child = "c"
origin = { xyz = [0.0, 0.2, 0.0], rpy = ["pi/2", 0, 0] }
[[joint]]
name = "j3"
kind = "P"
parent = "c"
child = "d"
dh = { a = 0.1, alpha = 0.3, d = 0.2, theta = 0.1 }
"#;

#[test]
fn fixed_joints_merge_preserving_mass_com_and_inertia() {
    let merged = ok("f.toml", &CHAIN_WITH_FIXED.replace("KIND", "fixed"));
    let unmerged = ok("u.toml", &CHAIN_WITH_FIXED.replace("KIND", "R"));
    assert_eq!(merged.dof(), 3);
    assert_eq!(unmerged.dof(), 5);
    let names: Vec<&str> = merged.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["a", "c", "d"]);
    assert_eq!(merged.joints[0].parent, None);
    assert_eq!(merged.joints[1].parent, Some(0));
    assert_eq!(merged.joints[2].parent, Some(1));
    assert!(close(merged.bodies[0].mass, 2.7, 1e-15));

    // With the former fixed joints at q = 0, the unmerged model is the same rigid assembly.
    for q in [[0.2, -0.7, 0.15], [1.0, 0.3, -0.2]] {
        let qu = [0.0, q[0], 0.0, q[1], q[2]];
        let xm = fk(&merged, &q);
        let xu = fk(&unmerged, &qu);
        // Same body frames for a, c, d.
        assert_tf(&xm[0], &xu[1], 1e-12);
        assert_tf(&xm[1], &xu[3], 1e-12);
        assert_tf(&xm[2], &xu[4], 1e-12);
        // Body a + tool: same total mass, mass centre and inertia about a point.
        let wm = world_props(&merged, &q);
        let wu = world_props(&unmerged, &qu);
        let both = MassProps::combine(&[wu[1], wu[2]]);
        assert!(close(wm[0].mass, both.mass, 1e-14));
        assert_vec(&wm[0].com, &both.com, 1e-12);
        let p = [0.3, -1.0, 2.0];
        assert_mat(&wm[0].inertia_about(&p), &both.inertia_about(&p), 1e-12);
        // The plate is part of the base: its mass is gone from the model.
        let total_m: f64 = wm.iter().map(|w| w.mass).sum();
        let total_u: f64 = wu.iter().map(|w| w.mass).sum();
        assert!(close(total_m + 5.0, total_u, 1e-14));
    }
}

#[test]
fn universal_and_spherical_expand_into_revolutes() {
    let m = ok(
        "us.toml",
        r#"
[mechanism]
name = "us"
[[body]]
name = "arm"
mass = 1.0
com = [0.0, 0.0, 0.5]
inertia = { ixx = 0.1, iyy = 0.1, izz = 0.01 }
[[body]]
name = "hand"
mass = 0.2
[[joint]]
name = "hip"
kind = "U"
parent = "base"
child = "arm"
origin = { xyz = [0, 0, 1] }
axes = [[0, 0, 1], [0, 1, 0]]
[[joint]]
name = "wrist"
kind = "spherical"
parent = "arm"
child = "hand"
origin = { xyz = [0, 0, 1] }
"#,
    );
    let jn: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(jn, ["hip_1", "hip_2", "wrist_x", "wrist_y", "wrist_z"]);
    let bn: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(
        bn,
        ["hip_cross", "arm", "wrist_x_body", "wrist_y_body", "hand"]
    );
    let parents: Vec<Option<usize>> = m.joints.iter().map(|j| j.parent).collect();
    assert_eq!(parents, [None, Some(0), Some(1), Some(2), Some(3)]);
    assert!(m.joints.iter().all(|j| j.kind == JointKind::Revolute));
    let axes: Vec<Vec3> = m.joints.iter().map(|j| j.axis).collect();
    assert_eq!(
        axes,
        [
            [0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0]
        ]
    );
    assert_eq!(m.joints[0].origin.translation, [0.0, 0.0, 1.0]);
    assert_eq!(m.joints[1].origin, Transform::IDENTITY);
    assert_eq!(m.joints[2].origin.translation, [0.0, 0.0, 1.0]);
    assert_eq!(m.joints[3].origin, Transform::IDENTITY);
    for i in [0, 2, 3] {
        assert_eq!(m.bodies[i].mass, 0.0);
        assert_eq!(m.bodies[i].inertia, [[0.0; 3]; 3]);
    }
    assert_eq!(m.bodies[1].com, [0.0, 0.0, 0.5]);
}

#[test]
fn non_unit_axis_is_normalized_with_a_warning() {
    let src = r#"
[mechanism]
name = "w"
[[body]]
name = "a"
mass = 1
[[joint]]
name = "j"
kind = "R"
parent = "base"
child = "a"
axis = [0, 3, 4]
"#;
    let (m, w) = load("w.toml", src).unwrap();
    assert_eq!(m.joints[0].axis, [0.0, 0.6, 0.8]);
    assert_eq!(w.len(), 1);
    assert!(!w.has_errors());
    assert!(w.render().contains("joint \"j\".axis"));
}

#[test]
fn topological_order_keeps_declared_order_where_possible() {
    let m = ok(
        "t.toml",
        r#"
[mechanism]
name = "t"
[[body]]
name = "c"
mass = 1
[[body]]
name = "b"
mass = 1
[[body]]
name = "a"
mass = 1
[[body]]
name = "x"
mass = 1
[[joint]]
name = "jc"
kind = "R"
parent = "b"
child = "c"
[[joint]]
name = "jx"
kind = "R"
parent = "base"
child = "x"
[[joint]]
name = "jb"
kind = "R"
parent = "a"
child = "b"
[[joint]]
name = "ja"
kind = "P"
parent = "base"
child = "a"
"#,
    );
    let jn: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(jn, ["jx", "ja", "jb", "jc"]);
    let bn: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(bn, ["x", "a", "b", "c"]);
    assert_eq!(m.joints[2].parent, Some(1));
    assert_eq!(m.joints[3].parent, Some(2));
    for (i, j) in m.joints.iter().enumerate() {
        assert!(j.parent.is_none_or(|p| p < i));
    }
}

#[cfg(feature = "urdf")]
mod urdf {
    use super::*;
    use runtime::model::{mat_mul, rpy_to_matrix, transpose};

    pub(super) const URDF: &str = r#"<?xml version="1.0"?>
<!-- a test robot -->
<robot name="Test-Robot 2">
  <link name="world"/>
  <link name="base_link">
    <inertial>
      <origin xyz="0 0 0.1" rpy="0 0 0"/>
      <mass value="3.0"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
    </inertial>
  </link>
  <link name="l1">
    <inertial>
      <origin xyz="0.01 0.02 0.3" rpy="0.1 0.2 0.3"/>
      <mass value="1.570796325"/>
      <inertia ixx="0.2" ixy="0.001" ixz="0" iyy="0.3" iyz="0" izz="0.4"/>
    </inertial>
    <visual><geometry><box size="1 1 1"/></geometry></visual>
  </link>
  <link name="l2"/>
  <link name="l3"/>
  <link name="l2b"/>
  <joint name="fix" type="fixed">
    <parent link="world"/>
    <child link="base_link"/>
  </joint>
  <joint name="j1" type="continuous">
    <origin xyz="0 0 0.5" rpy="0.1 0.2 0.3"/>
    <parent link="base_link"/>
    <child link="l1"/>
    <axis xyz="0 0 1"/>
  </joint>
  <joint name="j2b" type="prismatic">
    <origin xyz="0 0 0" rpy="0 1.570796325 0"/>
    <parent link="l1"/>
    <child link="l2b"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j3" type="revolute">
    <parent link="l2"/>
    <child link="l3"/>
    <dynamics damping="0.1"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="l1"/>
    <child link="l2"/>
    <axis xyz="1 0 0"/>
  </joint>
  <transmission name="t"><type>x</type></transmission>
  <gazebo reference="l1"><material>Gazebo/Red</material></gazebo>
</robot>
"#;

    #[test]
    fn urdf_conventions() {
        let m = ok("r.urdf", URDF);
        assert_eq!(m.name, "test_robot_2");
        assert_eq!(m.gravity, [0.0, 0.0, -9.81]);
        // Depth-first from the root, children in document order: j1, j2b, j2, j3.
        let jn: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
        assert_eq!(jn, ["j1", "j2b", "j2", "j3"]);
        let parents: Vec<Option<usize>> = m.joints.iter().map(|j| j.parent).collect();
        assert_eq!(parents, [None, Some(0), Some(0), Some(2)]);
        // The fixed world→base_link joint makes base_link part of the base.
        assert_eq!(m.joints[0].origin.translation, [0.0, 0.0, 0.5]);
        // rpy is fixed-axis X-Y-Z: Rz(y)·Ry(p)·Rx(r).
        let r = mat_mul(
            &axis_angle(&[0.0, 0.0, 1.0], 0.3),
            &mat_mul(
                &axis_angle(&[0.0, 1.0, 0.0], 0.2),
                &axis_angle(&[1.0, 0.0, 0.0], 0.1),
            ),
        );
        assert_mat(&m.joints[0].origin.rotation, &r, 1e-15);
        // 1.570796325 is kept as written: no snapping to π/2.
        assert_eq!(m.bodies[0].mass, 1.570796325);
        assert_eq!(
            m.joints[1].origin.rotation,
            rpy_to_matrix([0.0, 1.570796325, 0.0])
        );
        assert!(m.joints[1].origin.rotation[0][0] != 0.0);
        // Default axis [1, 0, 0].
        assert_eq!(m.joints[3].axis, [1.0, 0.0, 0.0]);
        assert_eq!(m.joints[1].kind, JointKind::Prismatic);
        // Inertial origin: com = xyz, I = R·I_inertial·Rᵀ.
        assert_eq!(m.bodies[0].com, [0.01, 0.02, 0.3]);
        let ri = rpy_to_matrix([0.1, 0.2, 0.3]);
        let i_in = [[0.2, 0.001, 0.0], [0.001, 0.3, 0.0], [0.0, 0.0, 0.4]];
        let want = mat_mul(&mat_mul(&ri, &i_in), &transpose(&ri));
        assert_mat(&m.bodies[0].inertia, &want, 1e-15);
        // Links without <inertial> are massless.
        assert_eq!(m.bodies[3].mass, 0.0);
    }

    #[test]
    fn urdf_rejects_lenient_vectors_with_a_position() {
        let bad = URDF.replace(r#"<axis xyz="1 0 0"/>"#, r#"<axis xyz="1 x 0 0"/>"#);
        let e = load("r.urdf", &bad).unwrap_err();
        let r = e.render();
        assert!(r.contains("r.urdf:47:"), "{r}");
        assert!(r.contains("invalid number \"x\""), "{r}");
    }
}

/// Deterministic mutations of valid specs never panic `load`.
#[test]
fn load_never_panics_on_mutated_input() {
    let seeds = [
        dh_spec("dh"),
        CHAIN_WITH_FIXED.replace("KIND", "fixed"),
        #[cfg(feature = "urdf")]
        urdf::URDF.to_owned(),
    ];
    let alphabet: &[&str] = &[
        "\"",
        "[",
        "]",
        "{",
        "}",
        "=",
        ",",
        "\n",
        "nan",
        "-",
        "pi/0",
        "1e999",
        "<",
        ">",
        "/>",
        "é",
        "0",
        " ",
        "\"base\"",
        "#",
        "[[joint]]",
        "'",
        "inf",
        "</robot>",
        "<joint",
    ];
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut rand = |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    for seed in &seeds {
        let name = if seed.contains("<robot") {
            "f.urdf"
        } else {
            "f.toml"
        };
        for _ in 0..150 {
            let mut s = seed.clone();
            for _ in 0..1 + rand(4) {
                let mut at = rand(s.len() + 1);
                while !s.is_char_boundary(at) {
                    at -= 1;
                }
                match rand(3) {
                    0 => s.insert_str(at, alphabet[rand(alphabet.len())]),
                    1 => {
                        let mut end = (at + rand(8)).min(s.len());
                        while !s.is_char_boundary(end) {
                            end -= 1;
                        }
                        s.replace_range(at..end, "");
                    }
                    _ => s.truncate(at),
                }
            }
            // `load` catches panics and turns them into an "internal error".
            if let Err(e) = load(name, &s) {
                let r = e.render();
                assert!(!r.contains("internal error"), "panicked on:\n{s}\n{r}");
            }
        }
    }
}
