//! Joint drives: viscous and Coulomb friction and rotor inertia (`[scene] friction = true`,
//! `rotor_inertia = true`), on the PUMA 560 with the drive data of Corke's toolbox taken to the
//! joints (see `mechanisms/specs/puma560.toml`).
//!
//! Checks:
//! * the scene switches are off by default (the bundled module is the rigid-body model) and each
//!   switch adds exactly its term: `τ = τ_rigid + I_a q̈ + b q̇ + c q̇/√(q̇² + v_s²)`, with the
//!   drive values recomputed here from the toolbox's motor-side numbers (`Jm G²`, `B G²`,
//!   `|Tc| |G|`), not read back from the model;
//! * the generated expression DAG agrees with the runtime (inverse dynamics, mass matrix,
//!   forward dynamics, friction);
//! * power balance, an identity the implementation does not use: along the motion under a
//!   torque `τ`, `dE/dt = τ·q̇ − q̇·δ(q̇)` where `E` is the kinetic energy of the links (from
//!   the body velocities) plus the rotors' `½ I_a q̇²` plus the potential energy;
//! * `forward_dynamics(inverse_dynamics(q̈)) = q̈`.

use codegen::sym::Arg;
use rand::Rng;
use runtime::model::Model;
use tests::{rel_err, rng};

const PUMA: &str = include_str!("../../mechanisms/specs/puma560.toml");

fn puma(scene: &str) -> Model {
    let src = format!("{PUMA}\n[scene]\n{scene}\n");
    codegen::spec::load_tree("puma560.toml", &src).unwrap().0
}

/// The toolbox's motor-side drive data (mdl_puma560.m, "params of 8/95").
const JM: [f64; 6] = [200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6];
const G: [f64; 6] = [-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686];
const B: [f64; 6] = [1.48e-3, 0.817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6];
const TC: [(f64, f64); 6] = [
    (0.395, -0.435),
    (0.126, -0.071),
    (0.132, -0.105),
    (11.2e-3, -16.9e-3),
    (9.26e-3, -14.5e-3),
    (3.96e-3, -10.5e-3),
];
/// The default speed scale of the regularized Coulomb law (docs/spec.md).
const VS: f64 = 1e-4;

/// The spec rounds to 5 significant digits.
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-4 * b.abs()
}

fn state(r: &mut rand::rngs::StdRng) -> ([f64; 6], [f64; 6], [f64; 6]) {
    let mut q = [0.0; 6];
    let mut qd = [0.0; 6];
    let mut qdd = [0.0; 6];
    for i in 0..6 {
        q[i] = r.random_range(-3.0..3.0);
        qd[i] = r.random_range(-2.0..2.0);
        qdd[i] = r.random_range(-5.0..5.0);
    }
    (q, qd, qdd)
}

#[test]
fn drives_are_off_by_default_and_each_switch_adds_its_term() {
    let rigid = puma("");
    assert!(rigid.joints.iter().all(|j| j.drive.is_none()));
    let both = puma("friction = true\nrotor_inertia = true");
    let fric = puma("friction = true");
    let rot = puma("rotor_inertia = true");
    for i in 0..6 {
        let d = both.joints[i].drive;
        assert!(close(d.armature, JM[i] * G[i] * G[i]), "armature {i}");
        assert!(close(d.viscous, B[i] * G[i] * G[i]), "viscous {i}");
        assert!(
            close(d.coulomb, 0.5 * (TC[i].0 - TC[i].1) * G[i].abs()),
            "coulomb {i}"
        );
        assert_eq!(d.coulomb_velocity, VS);
        assert_eq!(fric.joints[i].drive.armature, 0.0);
        assert_eq!(rot.joints[i].drive.viscous, 0.0);
        assert_eq!(rot.joints[i].drive.coulomb, 0.0);
    }
    let mut r = rng(11);
    for _ in 0..50 {
        let (q, qd, qdd) = state(&mut r);
        let t0 = runtime::noc::inverse_dynamics(&rigid, &q, &qd, &qdd);
        let t = runtime::noc::inverse_dynamics(&both, &q, &qd, &qdd);
        let m0 = runtime::noc::mass_matrix(&rigid, &q);
        let m = runtime::noc::mass_matrix(&both, &q);
        for i in 0..6 {
            let d = both.joints[i].drive;
            let want = d.armature * qdd[i]
                + d.viscous * qd[i]
                + d.coulomb * qd[i] / (qd[i] * qd[i] + VS * VS).sqrt();
            assert!(
                (t[i] - t0[i] - want).abs() <= 1e-12 * (1.0 + t[i].abs()),
                "{i}"
            );
            for j in 0..6 {
                let extra = if i == j { d.armature } else { 0.0 };
                assert!((m[(i, j)] - m0[(i, j)] - extra).abs() <= 1e-12 * (1.0 + m[(i, j)].abs()));
            }
        }
    }
}

#[test]
fn generated_drives_match_the_runtime() {
    let model = puma("friction = true\nrotor_inertia = true");
    let s = codegen::symbolic(&model);
    let fr = s.friction.clone().expect("a friction function");
    let mut r = rng(12);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (q, qd, qdd) = state(&mut r);
        let tau: Vec<f64> = (0..6).map(|_| r.random_range(-50.0..50.0)).collect();
        let input = |a: Arg, i: usize| match a {
            Arg::Q => q[i],
            Arg::Qd => qd[i],
            Arg::Qdd => qdd[i],
            Arg::Tau => tau[i],
            _ => f64::NAN,
        };
        let id = s.graph.eval(&s.inverse_dynamics, &input);
        let mm = s.graph.eval(&s.mass_matrix, &input);
        let fd = s.graph.eval(&s.forward_dynamics, &input);
        let f = s.graph.eval(&fr, &input);
        let id_rt = runtime::noc::inverse_dynamics(&model, &q, &qd, &qdd);
        let mm_rt = runtime::noc::mass_matrix(&model, &q);
        let fd_rt = runtime::noc::forward_dynamics(&model, &q, &qd, &tau).unwrap();
        let f_rt = runtime::noc::friction(&model, &qd);
        worst = worst
            .max(rel_err(&id, id_rt.as_slice()))
            .max(rel_err(&mm, mm_rt.transpose().as_slice()))
            .max(rel_err(&fd, fd_rt.as_slice()))
            .max(rel_err(&f, f_rt.as_slice()));
        // FD ∘ ID = identity, through the generated DAG alone.
        let input2 = |a: Arg, i: usize| match a {
            Arg::Tau => id[i],
            _ => input(a, i),
        };
        let back = s.graph.eval(&s.forward_dynamics, &input2);
        assert!(rel_err(&back, &qdd) < 1e-9, "FD(ID) {back:?} vs {qdd:?}");
    }
    assert!(worst < 1e-12, "generated vs runtime: {worst:e}");
}

/// Total energy with the rotors: links' kinetic (from body velocities, not from `I`), rotors'
/// `½ I_a q̇²`, gravity's potential.
fn energy(model: &Model, q: &[f64], qd: &[f64]) -> f64 {
    let links = runtime::noc::kinetic_energy(model, q, qd);
    runtime::noc::potential_energy(model, q) + links
}

#[test]
fn power_balance_with_friction_and_rotors() {
    let model = puma("friction = true\nrotor_inertia = true");
    let rigid = puma("");
    let mut r = rng(13);
    let h = 1e-5;
    for _ in 0..30 {
        let (q, qd, _) = state(&mut r);
        let tau: Vec<f64> = (0..6).map(|_| r.random_range(-30.0..30.0)).collect();
        let qdd = runtime::noc::forward_dynamics(&model, &q, &qd, &tau).unwrap();
        // The rotors' energy is added by hand here, from the link-only model's kinetic energy,
        // so that the check does not rest on the runtime's own rotor term.
        let e = |s: f64| {
            let qs: Vec<f64> = (0..6)
                .map(|i| q[i] + s * qd[i] + 0.5 * s * s * qdd[i])
                .collect();
            let vs: Vec<f64> = (0..6).map(|i| qd[i] + s * qdd[i]).collect();
            let rotors: f64 = (0..6)
                .map(|i| 0.5 * model.joints[i].drive.armature * vs[i] * vs[i])
                .sum();
            energy(&rigid, &qs, &vs) + rotors
        };
        let de_dt = (e(h) - e(-h)) / (2.0 * h);
        let fric = runtime::noc::friction(&model, &qd);
        let power: f64 = (0..6).map(|i| (tau[i] - fric[i]) * qd[i]).sum();
        let scale: f64 = (0..6)
            .map(|i| (tau[i] * qd[i]).abs() + (fric[i] * qd[i]).abs())
            .sum();
        assert!(
            (de_dt - power).abs() <= 1e-5 * scale,
            "dE/dt {de_dt} vs power {power}"
        );
        // Friction never feeds energy in.
        assert!((0..6).all(|i| fric[i] * qd[i] >= 0.0));
    }
}

#[test]
fn rigid_module_has_no_friction_function_and_bad_values_are_diagnostics() {
    let s = codegen::symbolic(&puma(""));
    assert!(s.friction.is_none());
    let bad = PUMA.replacen("damping = 5.8018", "damping = -1.0", 1);
    let err = codegen::spec::load_tree("puma560.toml", &bad).unwrap_err();
    let text = err.render();
    assert!(
        text.contains("damping") && text.contains("non-negative"),
        "{text}"
    );
    let bad = format!("{PUMA}\n[scene]\nfriction = true\ncoulomb_velocity = 0.0\n");
    let err = codegen::spec::load_tree("puma560.toml", &bad).unwrap_err();
    assert!(err.render().contains("coulomb_velocity"));
}

/// The four-bar with drives on its three tree joints (the loop-closing joint has none).
fn four_bar(scene: &str) -> runtime::closed::noc::Plan {
    let src = include_str!("../../mechanisms/specs/four_bar.toml");
    let src = src
        .replacen(
            "axis = [0.0, 0.0, 1.0]\n",
            "axis = [0.0, 0.0, 1.0]\ndamping = 0.3\nfriction = 0.2\narmature = 0.01\n",
            3,
        )
        .replace("[mechanism]", &format!("[scene]\n{scene}\n[mechanism]"));
    match codegen::spec::load_mechanism("four_bar.toml", &src) {
        Ok((codegen::spec::Mechanism::Closed(m), _)) => {
            runtime::closed::noc::Plan::new(&m).unwrap()
        }
        Ok(_) => panic!("not closed"),
        Err(d) => panic!("{d}"),
    }
}

/// Closed loops: every tree joint's drive, passive ones too, reaches the independent
/// coordinates by `Sᵀ`. Checked by virtual power, which the implementation does not use:
/// `(f_drives − f_rigid)·u = Σ_j ẋ_j δ_j(ẋ_j)` (friction), and by the rotors' kinetic energy
/// `uᵀ (I_rotors − I_rigid) u = Σ_j I_a ẋ_j²`, with the joint rates `ẋ` from the runtime.
#[test]
fn closed_loop_drives_by_virtual_power() {
    use runtime::closed::noc;
    let rigid = four_bar("");
    let fric = four_bar("friction = true");
    let rot = four_bar("rotor_inertia = true");
    let both = four_bar("friction = true\nrotor_inertia = true");
    let mut r = rng(14);
    for _ in 0..100 {
        let (x, u, ud) = tests::closed::random_state(&rigid, &mut r, 3.0);
        let xd = noc::joint_rates(&rigid, &x, &u).unwrap();
        let f0 = noc::inverse_dynamics(&rigid, &x, &u, &ud).unwrap();
        let f1 = noc::inverse_dynamics(&fric, &x, &u, &ud).unwrap();
        let power: f64 = (f1[0] - f0[0]) * u[0];
        let want: f64 = (0..3)
            .map(|j| xd[j] * (0.3 * xd[j] + 0.2 * xd[j] / (xd[j] * xd[j] + VS * VS).sqrt()))
            .sum();
        assert!(
            (power - want).abs() <= 1e-12 * (1.0 + want.abs()),
            "{power} vs {want}"
        );
        let m0 = noc::mass_matrix(&rigid, &x).unwrap();
        let m1 = noc::mass_matrix(&rot, &x).unwrap();
        let rotor = u[0] * (m1[0][0] - m0[0][0]) * u[0];
        let want: f64 = (0..3).map(|j| 0.01 * xd[j] * xd[j]).sum();
        assert!(
            (rotor - want).abs() <= 1e-12 * (1.0 + want),
            "{rotor} vs {want}"
        );
        // Forward dynamics inverts inverse dynamics with both.
        let tau = noc::inverse_dynamics(&both, &x, &u, &ud).unwrap();
        let back = noc::forward_dynamics(&both, &x, &u, &tau).unwrap();
        assert!(rel_err(&back, &ud) < 1e-10);
    }
}

#[test]
fn drives_on_a_loop_closing_joint_are_a_diagnostic() {
    let src = include_str!("../../mechanisms/specs/four_bar.toml").replace(
        "child_origin = { xyz = [0.5, 0.0, 0.0] }",
        "child_origin = { xyz = [0.5, 0.0, 0.0] }\ndamping = 0.1",
    );
    let err = codegen::spec::load_mechanism("four_bar.toml", &src).unwrap_err();
    assert!(err.render().contains("closes a loop"), "{}", err.render());
}

/// A URDF's `<dynamics damping friction>` apply only when asked (a URDF has no `[scene]`).
#[test]
fn urdf_dynamics_apply_with_the_override() {
    let urdf = r#"<robot name="p">
  <link name="world"/>
  <link name="rod"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0.01" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="world"/><child link="rod"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
    <dynamics damping="0.5" friction="0.1"/></joint>
</robot>"#;
    let load = |o: codegen::spec::SceneOverrides| match codegen::spec::load("p.urdf", urdf, &o)
        .map(|l| l.mechanism)
    {
        Ok(codegen::spec::Mechanism::Tree(m)) => m,
        _ => panic!("not a tree"),
    };
    assert!(load(Default::default()).joints[0].drive.is_none());
    let m = load(codegen::spec::SceneOverrides {
        friction: true,
        ..Default::default()
    });
    let d = m.joints[0].drive;
    assert_eq!((d.viscous, d.coulomb, d.coulomb_velocity), (0.5, 0.1, VS));
    // And through `compile`, as the CLI's --friction does: a `friction` function appears.
    let cfg = codegen::Config {
        scene: codegen::spec::SceneOverrides {
            friction: true,
            ..Default::default()
        },
        ..Default::default()
    };
    let out = codegen::compile("p.urdf", urdf, &cfg).unwrap();
    assert!(out.code.contains("pub fn friction("));
    let plain = codegen::compile("p.urdf", urdf, &Default::default()).unwrap();
    assert!(!plain.code.contains("pub fn friction("));
}

/// The Gough–Stewart platform with drives on its six actuated prismatic joints.
fn gough_stewart(scene: &str) -> runtime::parallel::noc::Plan {
    let src = include_str!("../../mechanisms/specs/gough_stewart.toml").replace(
        "actuated = true\n",
        "actuated = true\ndamping = 40.0\nfriction = 15.0\narmature = 2.5\n",
    );
    let src = format!("{src}\n[scene]\n{scene}\n");
    match codegen::spec::load_mechanism("gs.toml", &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => {
            runtime::parallel::noc::Plan::new(&m).unwrap()
        }
        Ok(_) => panic!("not parallel"),
        Err(d) => panic!("{d}"),
    }
}

/// Parallel mechanisms: a drive on the actuated joint acts beside the actuator, so the
/// actuator effort gains exactly `δ(q̇_a)` (friction) and the actuator-space inertia
/// `M = A⁻ᵀ I A⁻¹` gains exactly `diag(I_a)` (rotor inertia) — identities of the mapping
/// `f = Aᵀ τ`, not of the code that adds the drives inside the legs.
#[test]
fn parallel_actuator_drives() {
    use runtime::parallel::noc;
    let rigid = gough_stewart("");
    let fric = gough_stewart("friction = true");
    let rot = gough_stewart("rotor_inertia = true");
    let both = gough_stewart("friction = true\nrotor_inertia = true");
    let m = tests::pkm::model("gough_stewart");
    let home = m.home_x();
    let mut r = rng(15);
    for _ in 0..100 {
        let (x, u, ud) = tests::pkm::random_state(&rigid, &home, &mut r, 0.1, 0.02 * m.size());
        let qd = noc::actuator_rates(&rigid, &x, &u).unwrap();
        let t0 = noc::inverse_dynamics(&rigid, &x, &u, &ud).unwrap();
        let t1 = noc::inverse_dynamics(&fric, &x, &u, &ud).unwrap();
        for a in 0..6 {
            let want = 40.0 * qd[a] + 15.0 * qd[a] / (qd[a] * qd[a] + VS * VS).sqrt();
            assert!(
                (t1[a] - t0[a] - want).abs() <= 1e-9 * (1.0 + t0[a].abs()),
                "{a}: {} vs {want}",
                t1[a] - t0[a]
            );
        }
        let m0 = noc::actuator_mass_matrix(&rigid, &x).unwrap();
        let m1 = noc::actuator_mass_matrix(&rot, &x).unwrap();
        for i in 0..6 {
            for j in 0..6 {
                let extra = if i == j { 2.5 } else { 0.0 };
                assert!(
                    (m1[i][j] - m0[i][j] - extra).abs() <= 1e-9 * (1.0 + m0[i][j].abs()),
                    "({i},{j})"
                );
            }
        }
        let tau = noc::inverse_dynamics(&both, &x, &u, &ud).unwrap();
        let back = noc::forward_dynamics(&both, &x, &u, &tau).unwrap();
        assert!(rel_err(&back, &ud) < 1e-9);
    }
    // The generator runs the same evaluator: the module with drives compiles and costs more.
    let cfg = |on: bool| codegen::Config {
        scene: codegen::spec::SceneOverrides {
            friction: on,
            rotor_inertia: on,
            ..Default::default()
        },
        ..Default::default()
    };
    let src = include_str!("../../mechanisms/specs/gough_stewart.toml").replace(
        "actuated = true\n",
        "actuated = true\ndamping = 40.0\nfriction = 15.0\narmature = 2.5\n",
    );
    let flops = |on| {
        let g = codegen::compile("gs.toml", &src, &cfg(on)).unwrap();
        g.stats
            .iter()
            .find(|(n, _)| n == "inverse_dynamics")
            .unwrap()
            .1
            .flops()
    };
    assert!(flops(true) > flops(false));
}

/// `[scene] armature = { joint = I_a }`: a URDF (which has no place for rotor inertia) gets it
/// from its scene. Checked by the identity it must satisfy, not by the code that adds it: the
/// rotor adds exactly `I_a q̈` to the joint's effort (the runtime's inverse dynamics, with and
/// without), and
/// only with `rotor_inertia = true`. The PUMA 560's armature moved from its joints into the scene
/// gives the same drives. Bad entries are errors at the key.
#[test]
fn scene_armature() {
    let urdf = r#"<robot name="p">
  <link name="world"/>
  <link name="rod"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
    <inertia ixx="0.01" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="world"/><child link="rod"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="tip"/>
  <joint name="tip_mount" type="fixed"><parent link="rod"/><child link="tip"/></joint>
</robot>"#;
    let load = |scene: &str| {
        let o = codegen::spec::SceneOverrides {
            sidecar: Some(codegen::spec::SceneFile {
                name: "p.scene.toml".into(),
                text: format!("[scene]\n{scene}\n"),
            }),
            ..Default::default()
        };
        codegen::spec::load("p.urdf", urdf, &o).map(|l| match l.mechanism {
            codegen::spec::Mechanism::Tree(m) => m,
            _ => panic!("not a tree"),
        })
    };
    let m = load("rotor_inertia = true\narmature = { j = 0.3 }").unwrap();
    let off = load("armature = { j = 0.3 }").unwrap();
    let (q, qd) = ([0.4], [0.7]);
    for qdd in [0.0, 1.0, -2.5] {
        let with = runtime::noc::inverse_dynamics(&m, &q, &qd, &[qdd])[0];
        let without = runtime::noc::inverse_dynamics(&off, &q, &qd, &[qdd])[0];
        assert!(
            (with - without - 0.3 * qdd).abs() <= 1e-14,
            "{with} {without}"
        );
    }
    assert_eq!(m.joints[0].drive.armature, 0.3);
    assert!(off.joints[0].drive.is_none());
    for (scene, message) in [
        ("armature = { jj = 0.3 }", "unknown joint \"jj\""),
        (
            "armature = { j = -0.3 }",
            "not a finite, non-negative number",
        ),
        ("armature = { tip_mount = 0.3 }", "joint has no armature"),
        ("armature = 0.3", "scene.armature"),
    ] {
        let err = load(scene).unwrap_err().render();
        assert!(err.contains(message), "{scene}: {err}");
        assert!(err.contains("p.scene.toml"), "{scene}: {err}");
    }
    // The PUMA 560: its joints' armature, or the same numbers in the scene instead.
    let values: Vec<f64> = puma("rotor_inertia = true")
        .joints
        .iter()
        .map(|j| j.drive.armature)
        .collect();
    assert!(values.iter().all(|&a| a > 0.1), "{values:?}");
    let stripped: String = PUMA
        .lines()
        .filter(|l| !l.starts_with("armature"))
        .collect::<Vec<_>>()
        .join("\n");
    let table: Vec<String> = values
        .iter()
        .enumerate()
        .map(|(k, a)| format!("j{} = {a:?}", k + 1))
        .collect();
    let src = format!(
        "{stripped}\n[scene]\nrotor_inertia = true\narmature = {{ {} }}\n",
        table.join(", ")
    );
    let moved = codegen::spec::load_tree("puma560.toml", &src).unwrap().0;
    assert!(puma("").joints.iter().all(|j| j.drive.armature == 0.0));
    for (a, b) in moved
        .joints
        .iter()
        .zip(&puma("rotor_inertia = true").joints)
    {
        assert_eq!(a.drive.armature, b.drive.armature);
    }
}
