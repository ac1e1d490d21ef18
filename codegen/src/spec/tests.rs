//! Unit tests of the spec layer: lowering (DH, MDH, fixed merging, U/S expansion, order), URDF
//! conventions, angle exactness, and a no-panic fuzz loop.

use runtime::model::{JointKind, Mat3, Model, Transform, Vec3, axis_angle};

use super::geom::{MassProps, dh_matrix, mdh_matrix};
use super::ir::{Dh, Kind};
use super::load_tree;

/// Loads a tree that must have no warnings but the one for point masses on their joints' axes
/// (most specs here are kinematic: point masses at the joint origins).
fn ok(name: &str, src: &str) -> Model {
    match load_tree(name, src) {
        Ok((m, w)) => {
            let unexpected = w
                .iter()
                .filter(|d| !d.message.ends_with("moves no inertia about its axis"))
                .count();
            assert_eq!(unexpected, 0, "unexpected warnings:\n{}", w.render());
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
com = [0.1, 0, 0]
[[joint]]
name = "j"
kind = "R"
parent = "base"
child = "a"
axis = [0, 3, 4]
"#;
    let (m, w) = load_tree("w.toml", src).unwrap();
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
        // The massless links l2, l3 and l2b draw one warning per joint moving only them.
        let (m, w) = load_tree("r.urdf", URDF).unwrap_or_else(|e| panic!("{}", e.render()));
        let w: Vec<String> = w.iter().map(|d| d.message.clone()).collect();
        assert_eq!(
            w,
            [
                "joint \"j2b\" moves only massless bodies",
                "joint \"j3\" moves only massless bodies",
                "joint \"j2\" moves only massless bodies"
            ]
        );
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
        let e = load_tree("r.urdf", &bad).unwrap_err();
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
            if let Err(e) = load_tree(name, &s) {
                let r = e.render();
                assert!(!r.contains("internal error"), "panicked on:\n{s}\n{r}");
            }
        }
    }
}

/// Parallel mechanisms: the bundled specs, the leg split, frames of leg ends, closure.
mod parallel_specs {
    use runtime::model::{JointKind, Transform, mat_vec};
    use runtime::parallel::{LegEnd, LegKind, ParallelModel, PlatformMotion, leg_home_poses};

    use super::super::{Mechanism, load_mechanism, load_tree};
    use super::{assert_vec, close};

    fn load_parallel(name: &str, src: &str) -> ParallelModel {
        match load_mechanism(name, src) {
            Ok((Mechanism::Parallel(m), w)) => {
                assert!(w.is_empty(), "unexpected warnings:\n{}", w.render());
                m
            }
            Ok((Mechanism::Tree(_), _)) => panic!("{name} loaded as a tree"),
            Ok((Mechanism::Closed(_), _)) => panic!("{name} loaded as closed loops"),
            Err(e) => panic!("{}", e.render()),
        }
    }

    fn errors(name: &str, src: &str) -> String {
        match load_mechanism(name, src) {
            Ok(_) => panic!("{name} was accepted"),
            Err(e) => e.render(),
        }
    }

    // The written-out form (every leg placed by hand): these tests edit its lines.
    const GS: &str = include_str!("../../tests/data/expanded/gough_stewart.toml");
    const SPECS: [(&str, &str); 4] = [
        ("gough_stewart.toml", GS),
        (
            "sliding_hexapod.toml",
            include_str!("../../../mechanisms/specs/sliding_hexapod.toml"),
        ),
        (
            "rus_hexapod.toml",
            include_str!("../../../mechanisms/specs/rus_hexapod.toml"),
        ),
        (
            "agile_eye.toml",
            include_str!("../../../mechanisms/specs/agile_eye.toml"),
        ),
    ];

    #[test]
    fn bundled_parallel_specs_load_and_validate() {
        let expect = [
            (LegKind::Ups, 6, 3),
            (LegKind::Pus, 6, 3),
            (LegKind::Rus, 6, 3),
            (LegKind::SphericalRr, 3, 2),
        ];
        for ((name, src), (kind, legs, joints)) in SPECS.into_iter().zip(expect) {
            let m = load_parallel(name, src);
            let kinds = m.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(kinds, vec![kind; legs], "{name}");
            assert_eq!(m.dof(), legs, "{name}");
            for leg in &m.legs {
                assert_eq!(leg.joints.len(), joints, "{name}");
                assert_eq!(leg.bodies.len(), joints, "{name}");
                assert_eq!(leg.joints[0].parent, None);
                for (k, j) in leg.joints.iter().enumerate().skip(1) {
                    assert_eq!(j.parent, Some(k - 1), "{name}");
                }
                // Non-trivial leg inertia.
                assert!(
                    leg.bodies.iter().map(|b| b.mass).sum::<f64>() > 0.0,
                    "{name}"
                );
            }
            // `load` refuses a parallel spec and says why.
            let e = load_tree(name, src).unwrap_err().render();
            assert!(e.contains("parallel mechanism"), "{e}");
        }
    }

    /// The Gough–Stewart spec against Tsai's numbers (docs/method.md, "Test cases from the literature"), independently of the
    /// runtime's closure check.
    #[test]
    fn gough_stewart_matches_tsai_data() {
        let m = load_parallel("gough_stewart.toml", GS);
        let base = [
            [-2.12, 1.374, 0.0],
            [-2.38, 1.224, 0.0],
            [-2.38, -1.224, 0.0],
            [-2.12, -1.374, 0.0],
            [0.0, -0.15, 0.0],
            [0.0, 0.15, 0.0],
        ];
        let plat = [
            [0.17, 0.595, -0.4],
            [-0.6, 0.15, -0.4],
            [-0.6, -0.15, -0.4],
            [0.17, -0.595, -0.4],
            [0.43, -0.445, -0.4],
            [0.43, 0.445, -0.4],
        ];
        assert_eq!(m.motion, PlatformMotion::Pose);
        assert_eq!(m.home.translation, [-1.5, 0.0, 1.0]);
        assert_eq!(m.home.rotation, Transform::IDENTITY.rotation);
        assert_eq!(m.platform.mass, 1.5);
        assert_eq!(m.platform.com, [0.0; 3]);
        assert_eq!(m.gravity, [0.0, 0.0, -9.81]);
        for (i, leg) in m.legs.iter().enumerate() {
            let n = i + 1;
            assert_eq!(leg.name, format!("s{n}"));
            let names: Vec<&str> = leg.joints.iter().map(|j| j.name.as_str()).collect();
            assert_eq!(
                names,
                [format!("u{n}_1"), format!("u{n}_2"), format!("p{n}")]
            );
            let kinds: Vec<JointKind> = leg.joints.iter().map(|j| j.kind).collect();
            use JointKind::{Prismatic as P, Revolute as R};
            assert_eq!(kinds, [R, R, P]);
            assert_eq!(leg.actuated, 2);
            assert_eq!(leg.actuated_name, format!("p{n}"));
            // The U's cross is massless, the cylinder and the piston weigh 0.1 kg each.
            let masses: Vec<f64> = leg.bodies.iter().map(|b| b.mass).collect();
            assert_eq!(masses, [0.0, 0.1, 0.1]);
            assert!(close(leg.bodies[1].inertia[0][0], 1.0 / 160.0, 1e-15));
            // The U centre is the base point, the S centre the platform point.
            assert_eq!(leg.joints[0].origin.translation, base[i]);
            let LegEnd::Spherical {
                on_leg,
                on_platform,
            } = leg.end
            else {
                panic!("leg {n} does not end in a spherical joint");
            };
            assert_eq!(on_platform, plat[i]);
            let poses = leg_home_poses(leg);
            let tip = poses[2].apply(&on_leg);
            assert_vec(&tip, &m.home.apply(&plat[i]), 1e-14);
            // The leg's direction at home is the prismatic axis (z of the U frame); the U axes
            // are perpendicular to it and to each other.
            let dir = [
                tip[0] - base[i][0],
                tip[1] - base[i][1],
                tip[2] - base[i][2],
            ];
            let e: Vec<[f64; 3]> = poses
                .iter()
                .zip(&leg.joints)
                .map(|(x, j)| mat_vec(&x.rotation, &j.axis))
                .collect();
            let len = super::super::geom::norm(&dir);
            assert_vec(&e[2], &dir.map(|x| x / len), 1e-14);
            let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            assert!(dot(&e[0], &e[1]).abs() < 1e-15);
            assert!(dot(&e[0], &e[2]).abs() < 1e-15);
            assert!(dot(&e[1], &e[2]).abs() < 1e-15);
            // Piston mass centre 0.5 m from the platform joint.
            assert!(close(on_leg[2] - leg.bodies[2].com[2], 0.5, 1e-14));
        }
    }

    /// Moving the platform's home by 1 mm (or turning it by a few mrad) opens every loop: each
    /// leg gets its own closure diagnostic, at its joint into the platform.
    /// The home is moved by more than the reader closes by itself (`HOME_CORRECTION`: 1e-3 ×
    /// the size, 1°; smaller gaps are rounding, `codegen/tests/home_correction.rs`).
    #[test]
    fn perturbed_home_breaks_every_loop() {
        for (name, src) in SPECS {
            let m = load_parallel(name, src);
            let (from, to) = if name == "agile_eye.toml" {
                (
                    "home = { xyz = [0.0, 0.0, 0.0] }",
                    "home = { xyz = [0.0, 0.0, 0.0], rpy = [0.03, 0.04, 0.05] }",
                )
            } else {
                let h = m.home.translation;
                let old = format!("home = {{ xyz = [{:?}, {:?}, {:?}] }}", h[0], h[1], h[2]);
                let new = format!(
                    "home = {{ xyz = [{:?}, {:?}, {:?}] }}",
                    h[0],
                    h[1],
                    h[2] + 0.01
                );
                assert!(src.contains(&old), "{name}: {old}");
                (
                    Box::leak(old.into_boxed_str()) as &str,
                    Box::leak(new.into_boxed_str()) as &str,
                )
            };
            let bad = src.replace(from, to);
            let e = errors(name, &bad);
            assert_eq!(
                e.matches("the loop does not close at home").count(),
                m.dof(),
                "{name}:\n{e}"
            );
            for leg in &m.legs {
                assert!(e.contains(&format!("^ joint \"{}\"", leg.name)), "{e}");
            }
        }
    }

    /// The leg end is expressed in the last leg body's model frame, also when the lowering
    /// re-expresses that body's frame (standard DH) or merges a body into it (fixed joint).
    #[test]
    fn leg_end_follows_body_frame_changes() {
        let m0 = load_parallel("gough_stewart.toml", GS);
        let LegEnd::Spherical { on_leg, .. } = m0.legs[0].end else {
            panic!()
        };
        let len = on_leg[2];
        let s_line = format!("origin = {{ xyz = [0.0, 0.0, {len:?}] }}");
        assert!(GS.contains(&s_line));
        let p1 = "child = \"piston1\"\naxis = [0.0, 0.0, 1.0]\n";
        assert!(GS.contains(p1));

        // 1. The prismatic joint placed with standard DH: the piston's user frame is the distal
        //    frame Rz(0.5)·Tz(0.2)·Rx(0.3); the S centre written in that frame.
        let (a, d, th) = (0.3f64, 0.2, 0.5);
        let z = len - d;
        let s_dh = format!(
            "origin = {{ xyz = [0.0, {:?}, {:?}] }}",
            z * a.sin(),
            z * a.cos()
        );
        let dh = GS.replacen(
            p1,
            &format!("child = \"piston1\"\ndh = {{ a = 0.0, alpha = {a:?}, d = {d:?}, theta = {th:?} }}\n"),
            1,
        );
        let good = dh.replacen(&s_line, &s_dh, 1);
        let m = load_parallel("dh.toml", &good);
        m.validate().unwrap();
        let tip = |m: &ParallelModel| {
            let leg = &m.legs[0];
            let LegEnd::Spherical { on_leg, .. } = leg.end else {
                panic!()
            };
            leg_home_poses(leg)[2].apply(&on_leg)
        };
        assert_vec(&tip(&m), &tip(&m0), 1e-12);
        // Leaving the S centre as it was (now read in the distal frame) moves it off the
        // prismatic axis (a generic R-R-P leg) and away from the platform: the loop does not
        // close at home.
        let e = errors("dh.toml", &dh);
        assert!(e.contains("leg s1: the loop does not close at home"), "{e}");
        // With alpha = 0 it stays on the axis, 0.2 m too far out: the loop does not close.
        let e = errors(
            "dh0.toml",
            &dh.replace(&format!("alpha = {a:?}"), "alpha = 0.0"),
        );
        assert!(e.contains("leg s1: the loop does not close at home"), "{e}");

        // 2. A rod end fixed to the piston, 0.1 m further along and turned; the S joint hangs
        //    from it, the payload hangs from the platform.
        let rod_end = format!(
            "[[body]]\nname = \"rod_end\"\nmass = 0.05\ncom = [0.0, 0.0, 0.01]\n\n\
             [[joint]]\nname = \"end_weld\"\nkind = \"fixed\"\nparent = \"piston1\"\nchild = \"rod_end\"\n\
             origin = {{ xyz = [0.0, 0.0, {:?}], rpy = [\"pi/2\", 0.0, 0.0] }}\n\n\
             [[body]]\nname = \"payload\"\nmass = 0.5\ncom = [0.0, 0.0, 0.05]\n\n\
             [[joint]]\nname = \"clamp\"\nkind = \"fixed\"\nparent = \"platform\"\nchild = \"payload\"\n\
             origin = {{ xyz = [0.0, 0.0, 0.1] }}\n",
            len - 0.1
        );
        // In the rod end's frame (x rotated by 90°), the piston's +z is the rod end's +y.
        let src =
            GS.replacen(
                &format!("{s_line}\n"),
                "origin = { xyz = [0.0, 0.1, 0.0] }\n",
                1,
            )
            .replacen(
                "parent = \"piston1\"\nchild = \"platform\"",
                "parent = \"rod_end\"\nchild = \"platform\"",
                1,
            ) + "\n"
                + &rod_end;
        let m = load_parallel("rod_end.toml", &src);
        m.validate().unwrap();
        assert_vec(&tip(&m), &tip(&m0), 1e-12);
        // The rod end's mass is in the piston, the payload's in the platform.
        assert!(close(m.legs[0].bodies[2].mass, 0.15, 1e-15));
        assert!(close(m.platform.mass, 2.0, 1e-15));
        assert!(close(m.platform.com[2], 0.5 * 0.15 / 2.0, 1e-15));
    }

    /// Deterministic mutations of valid parallel specs never panic `load_mechanism`.
    #[test]
    fn load_mechanism_never_panics_on_mutated_input() {
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
            "0",
            " ",
            "\"base\"",
            "#",
            "[[joint]]",
            "\"platform\"",
            "\"camera\"",
            "true",
            "actuated = true\n",
            "child_origin = {}\n",
            "[platform]\n",
            "\"S\"",
            "\"R\"",
            "\"U\"",
            "\"fixed\"",
        ];
        let mut state: u64 = 0x2545_F491_4F6C_DD1D;
        let mut rand = |n: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        for (name, seed) in [SPECS[0], SPECS[3]] {
            for _ in 0..150 {
                let mut s = seed.to_owned();
                for _ in 0..1 + rand(4) {
                    let mut at = rand(s.len() + 1);
                    while !s.is_char_boundary(at) {
                        at -= 1;
                    }
                    match rand(3) {
                        0 => s.insert_str(at, alphabet[rand(alphabet.len())]),
                        1 => {
                            let mut end = (at + rand(40)).min(s.len());
                            while !s.is_char_boundary(end) {
                                end -= 1;
                            }
                            s.replace_range(at..end, "");
                        }
                        _ => {
                            // Swap two names of the same kind of entry.
                            s = s.replacen("\"piston2\"", "\"piston3\"", 1);
                        }
                    }
                }
                if let Err(e) = load_mechanism(name, &s) {
                    let r = e.render();
                    assert!(!r.contains("internal error"), "panicked on:\n{s}\n{r}");
                }
            }
        }
    }

    #[test]
    fn agile_eye_legs() {
        let m = load_parallel("agile_eye.toml", SPECS[3].1);
        assert_eq!(m.motion, PlatformMotion::Orientation { centre: [0.0; 3] });
        let uwv = [
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
            ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ];
        for (leg, (u, w, v)) in m.legs.iter().zip(uwv) {
            assert_eq!(leg.actuated, 0);
            assert_eq!(leg.joints[0].axis, u);
            assert_eq!(leg.joints[1].axis, w);
            assert_eq!(
                leg.end,
                LegEnd::Revolute {
                    on_leg: v,
                    on_platform: v
                }
            );
        }
    }

    const FIVE_BAR: &str = include_str!("../../../mechanisms/specs/planar_five_bar.toml");

    /// A correct five-bar written with a link as the `planar` platform (the legs meet it at two
    /// points): its mobility is 2, not 1 (the idle spin of a point platform is not subtracted
    /// for a link); what is reported is the form, at the second joint's `child_origin`.
    #[test]
    fn planar_platform_met_at_two_points_is_not_a_mobility_error() {
        let src = include_str!("../../tests/data/bad_parallel/planar_link_platform.toml");
        let e = errors("planar_link_platform.toml", src);
        assert!(!e.contains("mobility"), "{e}");
        assert!(
            e.contains("joints \"p_left\" and \"b_right\" meet the planar platform \"distal_right\" at different points"),
            "{e}"
        );
        // A point platform keeps its count: the bundled five-bar loads.
        load_parallel("planar_five_bar.toml", FIVE_BAR);
    }

    /// The hint of an unsupported leg lists the planar five-bar's leg.
    #[test]
    fn unsupported_planar_leg_hint_lists_the_planar_leg() {
        let src = FIVE_BAR.replacen(
            "name = \"b_left\"\nkind = \"revolute\"",
            "name = \"b_left\"\nkind = \"prismatic\"",
            1,
        );
        assert_ne!(src, FIVE_BAR);
        let e = errors("five_bar.toml", &src);
        assert!(
            e.contains("leg \"p_left\" is R-P-R, which is not a supported leg type"),
            "{e}"
        );
        assert!(
            e.contains("for coordinates = \"planar\" R-R-R with every axis along z"),
            "{e}"
        );
    }

    /// A 3-RUU (a crank, then a rod between two universal joints: not supported) is told so,
    /// once per leg, and nothing else: the 3-UPU's own checks (its base U's axes meet) are not
    /// applied to a leg that is not U-P.
    #[test]
    fn an_unsupported_leg_into_a_universal_joint_is_only_unsupported() {
        let e = errors("ruu3.toml", RUU3);
        for k in 1..=3 {
            assert!(
                e.contains(&format!(
                    "leg \"ub{k}\" is R-U-U, which is not a supported leg type"
                )),
                "{e}"
            );
        }
        assert_eq!(e.matches("error:").count(), 3, "{e}");
    }

    const RUU3: &str = r#"[mechanism]
name = "ruu3"

[platform]
body = "plate"
coordinates = "translation"
home = { xyz = [0.0, 0.0, -0.5] }

[[body]]
name = "plate"
mass = 0.8
inertia = { ixx = 0.003, iyy = 0.003, izz = 0.005 }

[[pattern]]
name = "leg"
copies = 3

[[pattern.body]]
name = "crank{i}"
mass = 0.6
com = [0.1, 0.0, 0.0]
inertia = { ixx = 0.0001, iyy = 0.002, izz = 0.002 }

[[pattern.body]]
name = "rod{i}"
mass = 0.3
com = [0.0, 0.0, -0.25]
inertia = { ixx = 0.005, iyy = 0.005, izz = 0.0001 }

[[pattern.joint]]
name = "m{i}"
kind = "R"
parent = "base"
child = "crank{i}"
origin = { xyz = [0.3, 0.0, 0.0] }
axis = [0.0, 1.0, 0.0]
actuated = true

[[pattern.joint]]
name = "ua{i}"
kind = "U"
parent = "crank{i}"
child = "rod{i}"
origin = { xyz = [0.2, 0.0, 0.0] }
axes = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]

[[pattern.joint]]
name = "ub{i}"
kind = "U"
parent = "rod{i}"
child = "plate"
origin = { xyz = [0.0, 0.0, -0.5] }
axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
child_origin = { xyz = [0.5, 0.0, 0.0] }
"#;
}

mod springs {
    use crate::spec::{Mechanism, load_mechanism};

    const SQUEEZER: &str = include_str!("../../../mechanisms/specs/andrews_squeezer.toml");
    const FOUR_BAR: &str = include_str!("../../../mechanisms/specs/four_bar.toml");
    const PUMA: &str = include_str!("../../../mechanisms/specs/puma560.toml");

    fn errors(src: &str) -> String {
        match load_mechanism("s.toml", src) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.render(),
        }
    }

    fn with_spring(base: &str, body_b: &str, extra: &str) -> String {
        format!(
            "{base}\n[[spring]]\nname = \"s1\"\nbody_a = \"base\"\npoint_a = [0.1, 0.2, 0.0]\nbody_b = \"{body_b}\"\nstiffness = 100.0\nrest_length = 0.1\n{extra}"
        )
    }

    #[test]
    fn the_squeezer_spring_is_read_into_the_model() {
        let Ok((Mechanism::Closed(m), _)) = load_mechanism("andrews_squeezer.toml", SQUEEZER)
        else {
            panic!("the squeezer did not load");
        };
        assert_eq!(m.springs.len(), 1);
        let s = &m.springs[0];
        assert_eq!(
            (s.body_a, s.stiffness, s.rest_length, s.damping),
            (None, 4530.0, 0.07785, 0.0)
        );
        assert_eq!(s.point_a, [0.014, 0.072, 0.0]);
        assert_eq!(m.tree.bodies[s.body_b.unwrap()].name, "K3");
    }

    #[test]
    fn bad_springs_are_reported_at_their_keys() {
        let e = errors(&with_spring(FOUR_BAR, "rokcer", ""));
        assert!(
            e.contains("spring \"s1\" names body \"rokcer\"")
                && e.contains("did you mean \"rocker\""),
            "{e}"
        );
        let e = errors(&with_spring(FOUR_BAR, "rocker", "damping = -1.0\n"));
        assert!(
            e.contains("damping must be finite and not negative") && e.contains("s.toml:"),
            "{e}"
        );
        let e = errors(&with_spring(FOUR_BAR, "rocker", "colour = 3\n"));
        assert!(e.contains("colour"), "{e}");
        let e = errors(&with_spring(PUMA, "link1", ""));
        assert!(
            e.contains("force elements are supported in closed-loop mechanisms"),
            "{e}"
        );
        // Both points at the base origin and on the crank's joint point: zero length at home.
        let e = errors(&format!(
            "{FOUR_BAR}\n[[spring]]\nname = \"s1\"\nbody_a = \"base\"\nbody_b = \"crank\"\nstiffness = 1.0\nrest_length = 0.0\n"
        ));
        assert!(e.contains("zero length at home"), "{e}");
    }
}

/// A snap tolerance from outside the spec (`Config::scene`, `Builder::snap`) takes the bounds of
/// `[scene] snap`: 0.5 would zero the PUMA's a2 = 0.4318 m.
#[test]
fn snap_override_out_of_range_is_an_error() {
    let src = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../mechanisms/specs/puma560.toml"
    ))
    .unwrap();
    for tol in [0.5, f64::NAN, 0.0, -1.0, f64::INFINITY] {
        let o = super::SceneOverrides {
            snap: Some(tol),
            ..Default::default()
        };
        let e = super::load("puma560.toml", &src, &o).unwrap_err();
        let r = e.render();
        assert!(
            r.contains("snap tolerance") && r.contains("(0, 0.01]"),
            "{r}"
        );
    }
    let o = super::SceneOverrides {
        snap: Some(1e-2),
        ..Default::default()
    };
    assert!(super::load("puma560.toml", &src, &o).is_ok());
}

/// Suggestions: the closest candidate within a third of the word's length (transpositions
/// count 1, ties to the first, case ignored); none for words longer than a name can be.
#[test]
fn suggestions_are_bounded() {
    use super::names::closest;
    assert_eq!(closest("inertai", &["mass", "inertia"]), Some("inertia"));
    assert_eq!(closest("lnik1", &["link2", "link1"]), Some("link1"));
    assert_eq!(closest("LINK1", &["link1"]), Some("link1"));
    assert_eq!(closest("ab", &["ax", "xb"]), Some("ax"));
    assert_eq!(closest("kitten", &["sitting"]), None);
    assert_eq!(closest("shoulder", &["elbow", "wrist"]), None);
    let n = super::MAX_NAME_LEN;
    let long = "a".repeat(n);
    let near = format!("{}b", &long[1..]);
    assert_eq!(closest(&near, &[&long]), Some(long.as_str()));
    let longer = "a".repeat(n + 1);
    let near = format!("{}b", &longer[1..]);
    assert_eq!(closest(&near, &[&longer]), None);
}

/// A point mass on the axis of the joint that turns it (and nothing beyond it off that axis)
/// gives a zero diagonal entry of the mass matrix at every configuration: a warning at the
/// joint, not for the joint that swings it about another axis, and none once the mass leaves
/// the axis or has a moment about it.
#[test]
fn point_mass_on_its_own_axis_is_warned() {
    let spec = |tool: &str| {
        format!(
            r#"
[mechanism]
name = "p"
[[body]]
name = "arm"
mass = 1
com = [0.2, 0, 0]
inertia = {{ ixx = 0.001, iyy = 0.01, izz = 0.01 }}
[[body]]
name = "tool"
mass = 0.5
{tool}
[[joint]]
name = "swing"
kind = "R"
parent = "base"
child = "arm"
[[joint]]
name = "spin"
kind = "R"
parent = "arm"
child = "tool"
axis = [1, 0, 0]
origin = {{ xyz = [0.4, 0, 0] }}
"#
        )
    };
    let warned = |tool: &str| -> Vec<String> {
        let (_, w) = load_tree("p.toml", &spec(tool)).unwrap();
        w.iter().map(|d| d.message.clone()).collect()
    };
    assert_eq!(
        warned("com = [0.05, 0, 0]"),
        ["joint \"spin\" moves no inertia about its axis"]
    );
    assert!(warned("com = [0.05, 0.01, 0]").is_empty());
    assert!(warned("inertia = { ixx = 2e-4, iyy = 1e-4, izz = 1e-4 }").is_empty());
    // A rod along the axis: moments about the other two only, still none about this one.
    assert_eq!(
        warned("inertia = { ixx = 0, iyy = 1e-4, izz = 1e-4 }"),
        ["joint \"spin\" moves no inertia about its axis"]
    );
    // The rotor's inertia fills the diagonal.
    let (_, w) = load_tree(
        "p.toml",
        &format!(
            "[scene]\nrotor_inertia = true\narmature = {{ spin = 1e-5 }}\n{}",
            spec("com = [0.05, 0, 0]")
        ),
    )
    .unwrap();
    assert!(w.is_empty(), "{}", w.render());
}
