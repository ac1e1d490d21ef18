//! Frame kinematics of the tree modules (`[scene] frames`: `F_pose`, `F_jacobian`,
//! `F_jacobian_dot_qd`) on 200 random states per bundled tree, against
//! * forward kinematics composed here from the model's joint transforms (`X_i = X_parent ·
//!   origin_i · motion_i(q_i)`, runtime::model helpers only) and the frame's placement on its
//!   body; and, for the DH specs and the URDF's fixed frames, the published placements
//!   themselves (the DH product, the URDF's `<origin>`s), ≤ 1e-12;
//! * the twist of the runtime's RNEA forward pass (`runtime::rnea::motion`, Plücker algebra in
//!   body coordinates) moved to the frame's origin and turned into the base: `J q̇`, ≤ 1e-12;
//!   and its spatial acceleration made classical: `J q̈ + J̇ q̇ = [ω̇; p̈]`, ≤ 1e-12;
//! * central differences of the module's own `F_pose` (the rotation by `vee` of the skew part
//!   of `R(q + h e_j) R(q − h e_j)ᵀ`), ≤ 1e-6, and of its `F_jacobian` along `q̇` for `J̇ q̇`,
//!   ≤ 1e-6, the steps `1e-6 · max(1, ‖·‖∞)` per state.
//!
//! Besides the modules' default frames (the leaf bodies), every body of every bundled tree is
//! checked as a frame through the generator's interpreter (`Graph::eval`): bodies fixed to the
//! base, fixed links (the gripper's palm, the iiwa's flange frames) and DH user frames.
//!
//! Error norm: ‖a − b‖∞ / max(‖b‖∞, 1).

use rand::Rng;
use runtime::model::{JointKind, Model, Transform, Vec3, axis_angle, mat_vec};
use tests::{rel_err, rng};

const STATES: usize = 200;

/// A frame's functions, from a compiled module or the interpreter: `pose(q)` as `R` row-major
/// then `p`, `jacobian(q)` 6 × n row-major, `jdot(q, q̇)`.
struct Fns<'a> {
    pose: Of<'a>,
    jacobian: Of<'a>,
    jdot: OfTwo<'a>,
}

/// A function of `q` and `q̇`.
type OfTwo<'a> = Box<dyn Fn(&[f64], &[f64]) -> Vec<f64> + 'a>;
/// A function of `q`.
type Of<'a> = Box<dyn Fn(&[f64]) -> Vec<f64> + 'a>;

fn load(file: &str, src: &str, scene: Option<&str>) -> codegen::spec::Loaded {
    let mut overrides = codegen::spec::SceneOverrides::default();
    let src = match scene {
        Some(s) if file.ends_with(".urdf") => {
            overrides.sidecar = Some(codegen::spec::SceneFile {
                name: "scene.toml".into(),
                text: s.into(),
            });
            src.to_string()
        }
        Some(s) => src.replacen("[mechanism]", &format!("{s}\n[mechanism]"), 1),
        None => src.to_string(),
    };
    codegen::spec::load(file, &src, &overrides).unwrap_or_else(|d| panic!("{d}"))
}

/// Every body's pose in the base, composed from the model's joint transforms.
fn body_poses(model: &Model, q: &[f64]) -> Vec<Transform> {
    let mut x: Vec<Transform> = Vec::with_capacity(model.dof());
    for (i, j) in model.joints.iter().enumerate() {
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
        let local = j.origin.compose(&motion);
        x.push(match j.parent {
            None => local,
            Some(p) => x[p].compose(&local),
        });
    }
    x
}

fn flat_pose(t: &Transform) -> Vec<f64> {
    let mut v: Vec<f64> = t.rotation.iter().flatten().copied().collect();
    v.extend(t.translation);
    v
}

fn cross(a: &Vec3, b: &Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn add(a: &Vec3, b: &Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// The frame's pose, twist `[ω; v]` and classical acceleration `[ω̇; p̈]` (base components)
/// from the runtime: the RNEA's forward pass in body coordinates, moved to the frame's origin.
fn runtime_motion(
    model: &Model,
    frame: &codegen::spec::Frame,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let Some(b) = frame.body else {
        return (flat_pose(&frame.placement), vec![0.0; 6], vec![0.0; 6]);
    };
    let x = body_poses(model, q)[b];
    let (v, a) = runtime::rnea::motion(model, q, qd, qdd);
    let w: Vec3 = [v[b][0], v[b][1], v[b][2]];
    let vo: Vec3 = [v[b][3], v[b][4], v[b][5]];
    let wd: Vec3 = [a[b][0], a[b][1], a[b][2]];
    // Featherstone's spatial acceleration → the origin's classical acceleration: + ω × v_O.
    let ao = add(&[a[b][3], a[b][4], a[b][5]], &cross(&w, &vo));
    let p = frame.placement.translation;
    let vp = add(&vo, &cross(&w, &p));
    let ap = add(&add(&ao, &cross(&wd, &p)), &cross(&w, &cross(&w, &p)));
    let r = &x.rotation;
    let base = |u: &Vec3| mat_vec(r, u);
    let twist = [base(&w), base(&vp)].concat();
    let acc = [base(&wd), base(&ap)].concat();
    (flat_pose(&x.compose(&frame.placement)), twist, acc)
}

/// `vee` of the skew part of `a bᵀ` (the rotation vector of `a bᵀ` to first order).
fn rotation_difference(a: &[f64], b: &[f64]) -> Vec3 {
    let m = |r: usize, c: usize| (0..3).map(|k| a[r * 3 + k] * b[c * 3 + k]).sum::<f64>();
    [
        0.5 * (m(2, 1) - m(1, 2)),
        0.5 * (m(0, 2) - m(2, 0)),
        0.5 * (m(1, 0) - m(0, 1)),
    ]
}

fn norm1(x: &[f64]) -> f64 {
    x.iter().fold(1.0f64, |m, v| m.max(v.abs()))
}

fn mat_times(m: &[f64], rows: usize, x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..rows)
        .map(|r| (0..n).map(|j| m[r * n + j] * x[j]).sum())
        .collect()
}

/// Worst errors over the states: pose, `J q̇`, `J q̈ + J̇ q̇`, `J` by differences, `J̇ q̇` by
/// differences.
fn check(model: &Model, frame: &codegen::spec::Frame, f: &Fns<'_>, seed: u64) -> [f64; 5] {
    let n = model.dof();
    let mut r = rng(seed);
    let mut worst = [0.0f64; 5];
    for _ in 0..STATES {
        let q: Vec<f64> = (0..n)
            .map(|_| r.random_range(-std::f64::consts::PI..std::f64::consts::PI))
            .collect();
        let qd: Vec<f64> = (0..n).map(|_| r.random_range(-2.0..2.0)).collect();
        let qdd: Vec<f64> = (0..n).map(|_| r.random_range(-5.0..5.0)).collect();
        let (pose, twist, acc) = runtime_motion(model, frame, &q, &qd, &qdd);
        let got_pose = (f.pose)(&q);
        let jac = (f.jacobian)(&q);
        let jdot = (f.jdot)(&q, &qd);
        worst[0] = worst[0].max(rel_err(&got_pose, &pose));
        worst[1] = worst[1].max(rel_err(&mat_times(&jac, 6, &qd), &twist));
        let jqdd: Vec<f64> = mat_times(&jac, 6, &qdd)
            .iter()
            .zip(&jdot)
            .map(|(a, b)| a + b)
            .collect();
        worst[2] = worst[2].max(rel_err(&jqdd, &acc));
        // J by central differences of the pose.
        let h = 1e-6 * norm1(&q);
        let mut fd = vec![0.0; 6 * n];
        for j in 0..n {
            let (mut a, mut b) = (q.clone(), q.clone());
            a[j] += h;
            b[j] -= h;
            let (pa, pb) = ((f.pose)(&a), (f.pose)(&b));
            let w = rotation_difference(&pa[..9], &pb[..9]);
            for k in 0..3 {
                fd[k * n + j] = w[k] / (2.0 * h);
                fd[(3 + k) * n + j] = (pa[9 + k] - pb[9 + k]) / (2.0 * h);
            }
        }
        worst[3] = worst[3].max(rel_err(&jac, &fd));
        // J̇ q̇ by central differences of J along q̇.
        let h = 1e-6 * norm1(&q) / norm1(&qd);
        let along = |s: f64| -> Vec<f64> {
            let x: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + s * b).collect();
            mat_times(&(f.jacobian)(&x), 6, &qd)
        };
        let (a, b) = (along(h), along(-h));
        let fd: Vec<f64> = a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect();
        worst[4] = worst[4].max(rel_err(&jdot, &fd));
    }
    worst
}

fn assert_within(what: &str, worst: [f64; 5]) {
    eprintln!(
        "{what}: worst over {STATES} states: pose {:.1e}, J q̇ {:.1e}, J q̈ + J̇ q̇ {:.1e}, \
         J by differences {:.1e}, J̇ q̇ by differences {:.1e}",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
    assert!(worst[0] <= 1e-12, "{what}: pose {worst:?}");
    assert!(worst[1] <= 1e-12, "{what}: J q̇ {worst:?}");
    assert!(worst[2] <= 1e-12, "{what}: J q̈ + J̇ q̇ {worst:?}");
    assert!(worst[3] <= 1e-6, "{what}: J by differences {worst:?}");
    assert!(worst[4] <= 1e-6, "{what}: J̇ q̇ by differences {worst:?}");
}

/// One frame function of a compiled module over slices.
macro_rules! compiled {
    ($m:ident, $f:ident) => {{
        use mechanisms::$m as mech;
        const N: usize = mech::DOF;
        let arr = |x: &[f64]| -> [f64; N] { x.try_into().expect("DOF entries") };
        paste_fns!(mech, $f, arr)
    }};
}

macro_rules! paste_fns {
    ($mech:ident, $f:ident, $arr:ident) => {{
        Fns {
            pose: Box::new(move |q| {
                let f = frame_fn!($mech, $f, pose);
                let (r, p) = f(&$arr(q));
                let mut v: Vec<f64> = r.iter().flatten().copied().collect();
                v.extend(p);
                v
            }),
            jacobian: Box::new(move |q| {
                let f = frame_fn!($mech, $f, jacobian);
                f(&$arr(q)).iter().flatten().copied().collect()
            }),
            jdot: Box::new(move |q, qd| {
                let f = frame_fn!($mech, $f, jacobian_dot_qd);
                f(&$arr(q), &$arr(qd)).to_vec()
            }),
        }
    }};
}

/// `mech::<frame>_<suffix>`.
macro_rules! frame_fn {
    ($mech:ident, link6, pose) => {
        $mech::link6_pose
    };
    ($mech:ident, link6, jacobian) => {
        $mech::link6_jacobian
    };
    ($mech:ident, link6, jacobian_dot_qd) => {
        $mech::link6_jacobian_dot_qd
    };
    ($mech:ident, link2, pose) => {
        $mech::link2_pose
    };
    ($mech:ident, link2, jacobian) => {
        $mech::link2_jacobian
    };
    ($mech:ident, link2, jacobian_dot_qd) => {
        $mech::link2_jacobian_dot_qd
    };
    ($mech:ident, iiwa_link_7, pose) => {
        $mech::iiwa_link_7_pose
    };
    ($mech:ident, iiwa_link_7, jacobian) => {
        $mech::iiwa_link_7_jacobian
    };
    ($mech:ident, iiwa_link_7, jacobian_dot_qd) => {
        $mech::iiwa_link_7_jacobian_dot_qd
    };
    ($mech:ident, iiwa_link_ee, pose) => {
        $mech::iiwa_link_ee_pose
    };
    ($mech:ident, iiwa_link_ee, jacobian) => {
        $mech::iiwa_link_ee_jacobian
    };
    ($mech:ident, iiwa_link_ee, jacobian_dot_qd) => {
        $mech::iiwa_link_ee_jacobian_dot_qd
    };
    ($mech:ident, tool, pose) => {
        $mech::tool_pose
    };
    ($mech:ident, tool, jacobian) => {
        $mech::tool_jacobian
    };
    ($mech:ident, tool, jacobian_dot_qd) => {
        $mech::tool_jacobian_dot_qd
    };
    ($mech:ident, fa_distal, pose) => {
        $mech::fa_distal_pose
    };
    ($mech:ident, fa_distal, jacobian) => {
        $mech::fa_distal_jacobian
    };
    ($mech:ident, fa_distal, jacobian_dot_qd) => {
        $mech::fa_distal_jacobian_dot_qd
    };
    ($mech:ident, fb_distal, pose) => {
        $mech::fb_distal_pose
    };
    ($mech:ident, fb_distal, jacobian) => {
        $mech::fb_distal_jacobian
    };
    ($mech:ident, fb_distal, jacobian_dot_qd) => {
        $mech::fb_distal_jacobian_dot_qd
    };
}

macro_rules! module_tests {
    ($($m:ident : $file:literal => [$($f:ident),*]),* $(,)?) => {$(
        #[test]
        fn $m() {
            let src = include_str!(concat!("../../mechanisms/specs/", $file));
            let loaded = load($file, src, None);
            let codegen::spec::Mechanism::Tree(model) = &loaded.mechanism else {
                panic!("a tree")
            };
            let names: Vec<&str> = loaded.scene.frames.iter().map(|f| f.name.as_str()).collect();
            assert_eq!(names, mechanisms::$m::FRAME_NAMES, "the default frames: the leaves");
            assert_eq!(names, [$(stringify!($f)),*]);
            for (k, fns) in [$(compiled!($m, $f)),*].into_iter().enumerate() {
                let frame = &loaded.scene.frames[k];
                let worst = check(model, frame, &fns, 0xf4a + k as u64);
                assert_within(&format!("{}::{}", stringify!($m), frame.name), worst);
            }
        }
    )*};
}

module_tests! {
    planar_2r: "planar_2r.toml" => [link2],
    puma560: "puma560.toml" => [link6],
    puma560_urdf: "puma560.urdf" => [link6],
    stanford_arm: "stanford_arm.toml" => [link6],
    gripper_tree: "gripper_tree.toml" => [fa_distal, fb_distal],
    chain7: "chain7.toml" => [iiwa_link_7],
    iiwa14: "iiwa14.urdf" => [iiwa_link_ee, tool],
}

/// The DH product `Π Rz(θ_i + q_i) Tz(d_i) Tx(a_i) Rx(α_i)` (`d_i + q_i` for a prismatic
/// joint) of a published table `(prismatic, a, α, d, θ)`.
fn dh_chain(table: &[(bool, f64, f64, f64, f64)], q: &[f64]) -> Transform {
    let mut x = Transform::IDENTITY;
    for (&(prismatic, a, alpha, d, theta), &qi) in table.iter().zip(q) {
        let (th, d) = if prismatic {
            (theta, d + qi)
        } else {
            (theta + qi, d)
        };
        let rz = Transform {
            rotation: axis_angle(&[0.0, 0.0, 1.0], th),
            translation: [0.0, 0.0, d],
        };
        let rx = Transform {
            rotation: axis_angle(&[1.0, 0.0, 0.0], alpha),
            translation: [a, 0.0, 0.0],
        };
        x = x.compose(&rz).compose(&rx);
    }
    x
}

/// The DH specs' tips against their published tables (the specs' `dh` entries).
#[test]
fn dh_tips_are_the_published_products() {
    use std::f64::consts::FRAC_PI_2 as H;
    let puma = [
        (false, 0.0, H, 0.0, 0.0),
        (false, 0.4318, 0.0, 0.0, 0.0),
        (false, 0.0203, -H, 0.15005, 0.0),
        (false, 0.0, H, 0.4318, 0.0),
        (false, 0.0, -H, 0.0, 0.0),
        (false, 0.0, 0.0, 0.0, 0.0),
    ];
    let stanford = [
        (false, 0.0, -H, 0.412, 0.0),
        (false, 0.0, H, 0.154, 0.0),
        (true, 0.0, 0.0, 0.0, -H),
        (false, 0.0, -H, 0.0, 0.0),
        (false, 0.0, H, 0.0, 0.0),
        (false, 0.0, 0.0, 0.263, 0.0),
    ];
    let mut r = rng(0xd4);
    let mut worst = [0.0f64; 2];
    for _ in 0..STATES {
        let q: [f64; 6] = std::array::from_fn(|_| r.random_range(-3.0..3.0));
        let (rot, p) = mechanisms::puma560::link6_pose(&q);
        let got = flat_pose(&Transform {
            rotation: rot,
            translation: p,
        });
        worst[0] = worst[0].max(rel_err(&got, &flat_pose(&dh_chain(&puma, &q))));
        let (rot, p) = mechanisms::stanford_arm::link6_pose(&q);
        let got = flat_pose(&Transform {
            rotation: rot,
            translation: p,
        });
        worst[1] = worst[1].max(rel_err(&got, &flat_pose(&dh_chain(&stanford, &q))));
    }
    eprintln!(
        "DH tips against the published tables: PUMA 560 {:.1e}, Stanford arm {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst.iter().all(|w| *w <= 1e-12), "{worst:?}");
}

/// The iiwa's flange frames against the URDF's `<origin>`s on `iiwa_link_7`
/// (`tool0_joint`: xyz 0 0 0.045, rpy 0 −π/2 0; `tool_joint`: xyz 0 0 0.045).
#[test]
fn urdf_fixed_frames_are_the_published_placements() {
    let src = include_str!("../../mechanisms/specs/iiwa14.urdf");
    let loaded = load("iiwa14.urdf", src, None);
    let codegen::spec::Mechanism::Tree(model) = &loaded.mechanism else {
        panic!("a tree")
    };
    let link7 = model
        .bodies
        .iter()
        .position(|b| b.name == "iiwa_link_7")
        .expect("iiwa_link_7 is a moving body");
    let ee = Transform::from_xyz_rpy([0.0, 0.0, 0.045], [0.0, -std::f64::consts::FRAC_PI_2, 0.0]);
    let tool = Transform::from_xyz_rpy([0.0, 0.0, 0.045], [0.0; 3]);
    let mut r = rng(0x1ee);
    let mut worst = 0.0f64;
    for _ in 0..STATES {
        let q: [f64; 7] = std::array::from_fn(|_| r.random_range(-3.0..3.0));
        let x7 = body_poses(model, &q)[link7];
        for (got, placement) in [
            (mechanisms::iiwa14::iiwa_link_ee_pose(&q), ee),
            (mechanisms::iiwa14::tool_pose(&q), tool),
        ] {
            let got = flat_pose(&Transform {
                rotation: got.0,
                translation: got.1,
            });
            worst = worst.max(rel_err(&got, &flat_pose(&x7.compose(&placement))));
        }
    }
    eprintln!("iiwa flange frames against the URDF's origins: {worst:.1e}");
    assert!(worst <= 1e-12, "{worst}");
}

/// The names of every body (TOML `[[body]]`, URDF `<link>`) of a spec.
fn all_bodies(file: &str, src: &str) -> Vec<String> {
    let names = |tag: &str| -> Vec<String> {
        src.match_indices(tag)
            .map(|(i, m)| {
                let rest = &src[i + m.len()..];
                rest[..rest.find('"').unwrap()].to_string()
            })
            .collect()
    };
    if file.ends_with(".urdf") {
        // The root link is the base ("base" as a frame).
        let children = names("<child link=\"");
        names("<link name=\"")
            .into_iter()
            .map(|l| {
                if children.contains(&l) {
                    l
                } else {
                    "base".into()
                }
            })
            .collect()
    } else {
        codegen::spec::body_names(file, src).expect("a TOML spec")
    }
}

/// Every body of every bundled tree as a frame, through the generator's interpreter.
#[test]
fn every_body_through_the_interpreter() {
    let specs: [(&str, &str); 7] = [
        (
            "planar_2r.toml",
            include_str!("../../mechanisms/specs/planar_2r.toml"),
        ),
        (
            "puma560.toml",
            include_str!("../../mechanisms/specs/puma560.toml"),
        ),
        (
            "puma560.urdf",
            include_str!("../../mechanisms/specs/puma560.urdf"),
        ),
        (
            "stanford_arm.toml",
            include_str!("../../mechanisms/specs/stanford_arm.toml"),
        ),
        (
            "gripper_tree.toml",
            include_str!("../../mechanisms/specs/gripper_tree.toml"),
        ),
        (
            "chain7.toml",
            include_str!("../../mechanisms/specs/chain7.toml"),
        ),
        (
            "iiwa14.urdf",
            include_str!("../../mechanisms/specs/iiwa14.urdf"),
        ),
    ];
    for (file, src) in specs {
        let bodies = all_bodies(file, src);
        let list: Vec<String> = bodies.iter().map(|b| format!("{b:?}")).collect();
        let scene = format!("[scene]\nframes = [{}]\n", list.join(", "));
        let loaded = load(file, src, Some(&scene));
        let codegen::spec::Mechanism::Tree(model) = &loaded.mechanism else {
            panic!("a tree")
        };
        assert_eq!(loaded.scene.frames.len(), bodies.len(), "{file}");
        let sym = codegen::symbolic_with_frames(model, None, &loaded.scene.frames);
        let g = &sym.graph;
        for (frame, [pose, jac, jdot]) in loaded.scene.frames.iter().zip(&sym.frames) {
            let eval = |roots: &[codegen::sym::ExprId], q: &[f64], qd: &[f64]| {
                g.eval(roots, &|a, i| match a {
                    codegen::sym::Arg::Q => q[i],
                    codegen::sym::Arg::Qd => qd[i],
                    _ => f64::NAN,
                })
            };
            let fns = Fns {
                pose: Box::new(|q| eval(pose, q, &[])),
                jacobian: Box::new(|q| eval(jac, q, &[])),
                jdot: Box::new(|q, qd| eval(jdot, q, qd)),
            };
            let worst = check(model, frame, &fns, 0xe7a);
            assert_within(&format!("{file} {} (interpreter)", frame.name), worst);
        }
    }
}

/// `frames = []` leaves the frames out; naming a frame that does not exist is an error at its
/// span (the diagnostics corpus has the message).
#[test]
fn scene_frames_on_and_off() {
    let src = include_str!("../../mechanisms/specs/puma560.toml");
    let cfg = codegen::Config::default();
    let off = src.replacen("[mechanism]", "[scene]\nframes = []\n\n[mechanism]", 1);
    let code = codegen::compile("puma560.toml", &off, &cfg)
        .expect("compiles")
        .code;
    assert!(!code.contains("_pose") && !code.contains("FRAME_NAMES"));
    let some = src.replacen(
        "[mechanism]",
        "[scene]\nframes = [\"link3\", \"link6\"]\n\n[mechanism]",
        1,
    );
    let code = codegen::compile("puma560.toml", &some, &cfg)
        .expect("compiles")
        .code;
    for f in ["link3_pose", "link3_jacobian", "link6_jacobian_dot_qd"] {
        assert!(code.contains(&format!("pub fn {f}(")), "{f}");
    }
    assert!(code.contains(r#"FRAME_NAMES: [&str; NF] = ["link3", "link6"]"#));
    let not_functions = src.replacen(
        "[mechanism]",
        "[scene]\nfunctions = [\"inverse_dynamics\", \"mass_matrix\", \"forward_dynamics\"]\n\n[mechanism]",
        1,
    );
    let code = codegen::compile("puma560.toml", &not_functions, &cfg)
        .expect("compiles")
        .code;
    assert!(!code.contains("_pose"), "`functions` without `frames`");
}
