//! `[scene]`: model no more than the application needs. A scene with point masses, massless
//! bodies and a gravity override gives exactly the model of the spec edited by hand, and
//! `functions` emits only the functions asked for.

use codegen::spec::load_tree as load;

const ARM: &str = r#"
[mechanism]
name = "arm"
gravity = [0.0, 0.0, -9.81]
SCENE
[[body]]
name = "link1"
mass = 1.0
com = [0.5, 0.0, 0.0]
inertia = { ixx = 0.01, iyy = 0.1, izz = 0.1 }

[[body]]
name = "link2"
mass = MASS2
com = [0.4, 0.0, 0.0]
inertia = INERTIA2

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
origin = { xyz = [1.0, 0.0, 0.0] }
axis = [0.0, 0.0, 1.0]
"#;

fn spec(scene: &str, mass2: &str, inertia2: &str) -> String {
    ARM.replace("SCENE", scene)
        .replace("MASS2", mass2)
        .replace("INERTIA2", inertia2)
}

#[test]
fn scene_bodies_and_gravity_are_the_hand_edited_model() {
    let full = "{ ixx = 0.01, iyy = 0.05, izz = 0.05 }";
    let zero = "{ ixx = 0.0, iyy = 0.0, izz = 0.0 }";
    let scene = spec(
        "[scene]\ngravity = [0.0, -9.81, 0.0]\npoint_mass = [\"link2\"]\n",
        "1.0",
        full,
    );
    let edited = spec("", "1.0", zero).replace("[0.0, 0.0, -9.81]", "[0.0, -9.81, 0.0]");
    let (a, _) = load("scene.toml", &scene).unwrap();
    let (b, _) = load("edited.toml", &edited).unwrap();
    assert_eq!(a, b);
    let scene = spec("[scene]\nmassless = [\"link2\"]\n", "1.0", full);
    let edited = spec("", "0.0", zero);
    let (a, _) = load("scene.toml", &scene).unwrap();
    let (b, _) = load("edited.toml", &edited).unwrap();
    assert_eq!(a, b);
}

#[test]
fn scene_functions_emit_only_what_is_asked_for() {
    let full = "{ ixx = 0.01, iyy = 0.05, izz = 0.05 }";
    let src = spec(
        "[scene]\nfunctions = [\"inverse_dynamics\", \"mass_matrix\"]\n",
        "1.0",
        full,
    );
    let g = codegen::compile("arm.toml", &src, &codegen::Config::default()).unwrap();
    assert!(g.code.contains("pub fn inverse_dynamics"));
    assert!(g.code.contains("pub fn mass_matrix"));
    for f in ["coriolis", "gravity", "forward_dynamics"] {
        assert!(!g.code.contains(&format!("pub fn {f}(")), "{f} was emitted");
    }
    assert_eq!(g.stats.len(), 2);
    // The same numbers as the full module's inverse dynamics.
    let all = codegen::compile(
        "arm.toml",
        &spec("", "1.0", full),
        &codegen::Config::default(),
    )
    .unwrap();
    let id = |g: &codegen::Generated| {
        g.stats
            .iter()
            .find(|(n, _)| n == "inverse_dynamics")
            .map(|(_, c)| c.flops())
    };
    assert_eq!(id(&g), id(&all));
}

/// `Config`'s `omit` (the `f32` build of the bundled mechanisms) leaves functions out on top of
/// the spec's `[scene] functions`; names the kind does not offer are ignored.
#[test]
fn omitted_functions_are_left_out() {
    use codegen::spec::Function;
    let full = "{ ixx = 0.01, iyy = 0.05, izz = 0.05 }";
    let mut config = codegen::Config::default();
    config.scene.omit = vec![
        Function::Regressor,
        Function::Coriolis,
        Function::ActuatorRates,
    ];
    let g = codegen::compile("arm.toml", &spec("", "1.0", full), &config).unwrap();
    for f in [
        "inverse_dynamics",
        "mass_matrix",
        "gravity",
        "forward_dynamics",
    ] {
        assert!(g.code.contains(&format!("pub fn {f}(")), "{f} is missing");
    }
    for f in ["regressor", "coriolis"] {
        assert!(!g.code.contains(&format!("pub fn {f}(")), "{f} was emitted");
    }
    // On top of the spec's own list.
    let src = spec(
        "[scene]\nfunctions = [\"inverse_dynamics\", \"coriolis\"]\n",
        "1.0",
        full,
    );
    let g = codegen::compile("arm.toml", &src, &config).unwrap();
    assert!(g.code.contains("pub fn inverse_dynamics("));
    assert!(!g.code.contains("pub fn coriolis("));
    assert_eq!(g.stats.len(), 1);
}

/// A payload of 1 kg at 0.8 m on link 2 (mass centre at 0.4 m, 1 kg): together 2 kg at 0.6 m,
/// inertia about the common centre `I + Σ m d²` = 0.05 + 2 · 1 · 0.2² = 0.13 kg·m² across the
/// link (parallel-axis theorem, by hand), 0.01 along it.
#[test]
fn scene_payload_is_the_combined_body() {
    let full = "{ ixx = 0.01, iyy = 0.05, izz = 0.05 }";
    let scene = spec(
        "[scene]\npayload = { body = \"link2\", mass = 1.0, com = [0.8, 0.0, 0.0] }\n",
        "1.0",
        full,
    );
    let edited = spec("", "2.0", "{ ixx = 0.01, iyy = 0.13, izz = 0.13 }")
        .replace("com = [0.4, 0.0, 0.0]", "com = [0.6, 0.0, 0.0]");
    let (a, _) = load("scene.toml", &scene).unwrap();
    let (b, _) = load("edited.toml", &edited).unwrap();
    for (q, qd, qdd) in [
        ([0.3, -0.7], [0.5, 1.0], [-0.2, 0.4]),
        ([1.2, 0.4], [-1.0, 0.3], [0.9, -0.6]),
    ] {
        let ta = runtime::rnea::inverse_dynamics(&a, &q, &qd, &qdd);
        let tb = runtime::rnea::inverse_dynamics(&b, &q, &qd, &qdd);
        for i in 0..2 {
            assert!(
                (ta[i] - tb[i]).abs() <= 1e-12 * tb[i].abs().max(1.0),
                "{ta} vs {tb}"
            );
        }
    }
}

/// Locking the PUMA 560's joint 5 at 0.3 rad: a 5-joint model whose inverse dynamics equal
/// the full model's with joint 5 held there (rate and acceleration zero), for the other joints
/// (the locked joint's effort is the reaction that holds it).
#[test]
fn scene_locked_joint_is_the_full_model_held_there() {
    let path = tests::pkm::spec_path("puma560");
    let src = std::fs::read_to_string(&path).unwrap();
    let locked = src.replacen(
        "\n[[body]]",
        "\n[scene]\nlocked = { j5 = 0.3 }\n\n[[body]]",
        1,
    );
    let (full, _) = load("puma560.toml", &src).unwrap();
    let (reduced, _) = load("puma560_locked.toml", &locked).unwrap();
    assert_eq!(reduced.dof(), 5);
    let mut rng = tests::rng(41);
    use rand::Rng;
    for _ in 0..50 {
        let r: [[f64; 5]; 3] =
            core::array::from_fn(|_| core::array::from_fn(|_| rng.random_range(-1.5..1.5)));
        let lift = |v: &[f64; 5], held: f64| [v[0], v[1], v[2], v[3], held, v[4]];
        let tf = runtime::rnea::inverse_dynamics(
            &full,
            &lift(&r[0], 0.3),
            &lift(&r[1], 0.0),
            &lift(&r[2], 0.0),
        );
        let tr = runtime::rnea::inverse_dynamics(&reduced, &r[0], &r[1], &r[2]);
        for (k, i) in [0, 1, 2, 3, 5].into_iter().enumerate() {
            assert!(
                (tr[k] - tf[i]).abs() <= 1e-11 * tf[i].abs().max(1.0),
                "joint {i}: {} vs {}",
                tr[k],
                tf[i]
            );
        }
    }
}

/// Closed loops: `functions` leaves out the unwanted dynamics functions (the assembly stays).
#[test]
fn scene_functions_for_closed_loops() {
    let path = tests::pkm::spec_path("four_bar");
    let src =
        std::fs::read_to_string(&path).unwrap() + "\n[scene]\nfunctions = [\"inverse_dynamics\"]\n";
    let g = codegen::compile("four_bar.toml", &src, &codegen::Config::default())
        .unwrap_or_else(|d| panic!("{d}"));
    assert!(g.code.contains("pub fn inverse_dynamics("));
    assert!(g.code.contains("pub fn forward_kinematics("));
    for f in ["joint_rates", "mass_matrix", "forward_dynamics"] {
        assert!(!g.code.contains(&format!("pub fn {f}(")), "{f} was emitted");
    }
    // A parallel module keeps its kinematics; an unknown function is an error naming the others.
    let path = tests::pkm::spec_path("agile_eye");
    let src =
        std::fs::read_to_string(&path).unwrap() + "\n[scene]\nfunctions = [\"inverse_dynamic\"]\n";
    let e = codegen::compile("agile_eye.toml", &src, &codegen::Config::default()).unwrap_err();
    assert!(
        e.render().contains("a parallel module offers"),
        "{}",
        e.render()
    );
}

/// Parallel mechanisms: `functions = ["inverse_dynamics"]` (the module compiled by
/// `tests/build.rs`) emits the inverse dynamics with the kinematics and nothing else, with the
/// same results as the full module.
#[test]
fn scene_functions_for_parallel_mechanisms() {
    use mechanisms::gough_stewart as full;
    use tests::variants::gs_id_only as only;
    let path = tests::pkm::spec_path("gough_stewart");
    let src =
        std::fs::read_to_string(&path).unwrap() + "\n[scene]\nfunctions = [\"inverse_dynamics\"]\n";
    let g = codegen::compile("gough_stewart.toml", &src, &codegen::Config::default()).unwrap();
    for f in [
        "inverse_dynamics",
        "inverse_kinematics",
        "forward_kinematics",
    ] {
        assert!(g.code.contains(&format!("pub fn {f}(")), "{f} is missing");
    }
    for f in [
        "actuator_rates",
        "mass_matrix",
        "actuator_mass_matrix",
        "forward_dynamics",
    ] {
        assert!(!g.code.contains(&format!("pub fn {f}(")), "{f} was emitted");
    }
    let names: Vec<&str> = g.stats.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "inverse_kinematics",
            "inverse_dynamics",
            "forward_kinematics (per Newton step)"
        ]
    );
    let model = tests::pkm::model("gough_stewart");
    let plan = runtime::parallel::noc::Plan::new(&model).unwrap();
    let home = model.home_x();
    let mut r = tests::rng(51);
    for _ in 0..50 {
        let (x, u, ud) = tests::pkm::random_state(&plan, &home, &mut r, 0.1, 0.02 * model.size());
        let (x, u, ud): ([f64; 7], [f64; 6], [f64; 6]) = (
            x.try_into().unwrap(),
            u.try_into().unwrap(),
            ud.try_into().unwrap(),
        );
        assert_eq!(
            only::inverse_dynamics(&x, &u, &ud).unwrap(),
            full::inverse_dynamics(&x, &u, &ud).unwrap()
        );
    }
}
