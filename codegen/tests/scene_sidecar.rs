//! A `[scene]` for a URDF (docs/scene.md, "A scene for a URDF"): `ROBOT.scene.toml` beside
//! `ROBOT.urdf`, or `--scene FILE`. The URDF with its scene file generates the module of the
//! same robot converted to TOML (`codegen convert`) with the same `[scene]` appended, read by
//! the TOML reader: a second route to the same scene. Mistakes in the scene file are reported
//! in the scene file.

use std::path::{Path, PathBuf};
use std::process::Command;

use codegen::spec::{SceneFile, SceneOverrides};
use codegen::{Config, compile};

const SCENE: &str = r#"# What this application needs of the PUMA.
[scene]
functions = ["inverse_dynamics", "gravity", "mass_matrix"]
payload = { body = "link6", mass = 2.5, com = [0.0, 0.0, 0.05], inertia = { ixx = 0.01, iyy = 0.01, izz = 0.005 } }
gravity = [0.0, 0.0, -9.80665]
"#;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn urdf() -> String {
    std::fs::read_to_string(root().join("mechanisms/specs/puma560.urdf")).unwrap()
}

fn with_scene(text: &str) -> Config {
    Config {
        scene: SceneOverrides {
            sidecar: Some(SceneFile {
                name: "puma560.scene.toml".into(),
                text: text.into(),
            }),
            ..Default::default()
        },
        ..Config::default()
    }
}

#[test]
fn a_urdf_with_its_scene_is_the_converted_spec_with_that_scene() {
    let g = compile("puma560.urdf", &urdf(), &with_scene(SCENE)).unwrap_or_else(|d| panic!("{d}"));
    let plain = compile("puma560.urdf", &urdf(), &Config::default()).unwrap();
    // The scene changed the module: fewer functions, a payload, another gravity.
    assert_ne!(g.code, plain.code);
    assert!(!g.code.contains("pub fn forward_dynamics"));
    assert!(g.code.contains("pub fn gravity"));
    let out = Command::new(env!("CARGO_BIN_EXE_codegen"))
        .args(["convert"])
        .arg(root().join("mechanisms/specs/puma560.urdf"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let toml = format!("{}\n{SCENE}", String::from_utf8(out.stdout).unwrap());
    let t = compile("puma560.toml", &toml, &Config::default()).unwrap_or_else(|d| panic!("{d}"));
    assert_eq!(g.code, t.code);
}

#[test]
fn mistakes_are_reported_in_the_scene_file() {
    let bad = SCENE.replace("\"link6\"", "\"link7\"");
    let e = compile("puma560.urdf", &urdf(), &with_scene(&bad))
        .unwrap_err()
        .render();
    assert!(e.contains("--> puma560.scene.toml:4:"), "{e}");
    assert!(e.contains("link7"), "{e}");
    let e = compile(
        "puma560.urdf",
        &urdf(),
        &with_scene("[scene]\nfrction = true\n"),
    )
    .unwrap_err()
    .render();
    assert!(e.contains("puma560.scene.toml:2:1"), "{e}");
    let e = compile(
        "puma560.urdf",
        &urdf(),
        &with_scene("[mechanism]\nname = \"x\"\n"),
    )
    .unwrap_err()
    .render();
    assert!(e.contains("has none"), "{e}");
    // A TOML spec with its own [scene] and a scene file: the scene is given twice.
    let spec = std::fs::read_to_string(root().join("mechanisms/specs/puma560.toml")).unwrap();
    let spec = format!("{spec}\n[scene]\nfriction = true\n");
    let e = compile("puma560.toml", &spec, &with_scene(SCENE))
        .unwrap_err()
        .render();
    assert!(e.contains("has its own [scene] table"), "{e}");
}

/// A warning from the scene file (a payload whose inertia breaks the triangle inequality, on
/// line 4) names the scene file's line and column; it has no place in the URDF's text.
#[test]
fn warnings_of_the_scene_file_name_its_line() {
    let odd = SCENE.replace("izz = 0.005", "izz = 0.05");
    let g = compile("puma560.urdf", &urdf(), &with_scene(&odd)).unwrap_or_else(|d| panic!("{d}"));
    let w = g.warnings.render();
    assert!(w.contains("puma560.scene.toml:4:"), "{w}");
    assert!(w.contains("triangle inequality"), "{w}");
}

#[test]
fn the_cli_and_the_builder_find_the_scene_beside_the_urdf() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scene_sidecar");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("arm.urdf"), urdf()).unwrap();
    std::fs::write(dir.join("arm.scene.toml"), SCENE).unwrap();
    let expected = compile("arm.urdf", &urdf(), &with_scene(SCENE))
        .unwrap()
        .code;

    let out = Command::new(env!("CARGO_BIN_EXE_codegen"))
        .arg(dir.join("arm.urdf"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("note: with the scene file"));
    assert_eq!(String::from_utf8(out.stdout).unwrap(), expected);

    // `--scene` names it explicitly (here a file elsewhere); `--check` reads it too.
    std::fs::write(dir.join("other.toml"), SCENE.replace("link6", "link9")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_codegen"))
        .arg(dir.join("arm.urdf"))
        .arg("--check")
        .arg("--scene")
        .arg(dir.join("other.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("other.toml:4:"));

    // The builder takes the URDF, not its scene file, as a spec, with its scene.
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    std::fs::remove_file(dir.join("other.toml")).unwrap();
    let written = codegen::build_script::Builder::new()
        .specs_in(&dir)
        .out_dir(&out_dir)
        .warnings(false)
        .compile()
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(written, vec![out_dir.join("arm.rs")]);
    assert_eq!(
        std::fs::read_to_string(out_dir.join("arm.rs")).unwrap(),
        expected
    );
}

/// The scene file beside a URDF is an input of `excite` and `identify` as of generation: an
/// output onto it is refused (exit 2, the file untouched). `excite -o arm.scene.toml` and
/// `identify --estimates`/`--plot arm.scene.toml` replaced it with exit 0 (QA).
#[test]
fn the_tools_do_not_write_over_the_scene_beside_the_urdf() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("scene_sidecar_outputs");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("arm.urdf"), urdf()).unwrap();
    let scene = dir.join("arm.scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let data = dir.join("data.csv");
    std::fs::write(&data, "t\n0\n").unwrap();
    let runs: [Vec<&std::ffi::OsStr>; 3] = [
        vec!["excite".as_ref(), "-o".as_ref(), scene.as_os_str()],
        vec![
            "identify".as_ref(),
            data.as_os_str(),
            "--estimates".as_ref(),
            scene.as_os_str(),
        ],
        vec![
            "identify".as_ref(),
            data.as_os_str(),
            "--plot".as_ref(),
            scene.as_os_str(),
        ],
    ];
    for args in runs {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_codegen"));
        cmd.arg(args[0]).arg(dir.join("arm.urdf")).args(&args[1..]);
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("that is the scene file"), "{args:?}: {err}");
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), SCENE, "{args:?}");
    }
}

/// A ROS-Industrial URDF's own link "base" (read under another name, as nocdyn's "base" is the
/// fixed world) is what a scene's "base" names; the root link names the fixed world. Before,
/// `frames = ["base"]` gave the fixed world's pose with no error. Reference: the URDF's fixed
/// joint, `rpy = "0 0 π"` at the origin, so R = diag(−1, −1, 1).
#[test]
fn a_urdf_link_named_base_is_the_scenes_base() {
    let path = root().join("codegen/tests/data/warn/base_link_named_base.urdf");
    let urdf = std::fs::read_to_string(path).unwrap();
    let scene = |text: &str| SceneOverrides {
        sidecar: Some(SceneFile {
            name: "arm.scene.toml".into(),
            text: text.into(),
        }),
        ..Default::default()
    };
    let l = codegen::spec::load(
        "arm.urdf",
        &urdf,
        &scene("[scene]\nframes = [\"base\", \"base_link\", \"upper\"]\n"),
    )
    .unwrap_or_else(|d| panic!("{d}"));
    let f = &l.scene.frames;
    let names: Vec<(&str, &str)> = f
        .iter()
        .map(|f| (f.name.as_str(), f.ident.as_str()))
        .collect();
    assert_eq!(
        names,
        [
            ("base", "base"),
            ("base_link", "base_link"),
            ("upper", "upper")
        ]
    );
    let r = f[0].placement.rotation;
    let want = [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]];
    for i in 0..3 {
        for j in 0..3 {
            assert!((r[i][j] - want[i][j]).abs() < 1e-15, "{r:?}");
        }
    }
    assert_eq!(f[0].body, None);
    assert_eq!(
        f[1].placement.rotation,
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    // The hint of the warning says so.
    assert!(
        l.warnings.render().contains("in a scene, \"base\""),
        "{}",
        l.warnings.render()
    );
    // A body the scene names "base" is that link too: a point mass on it is accepted.
    codegen::spec::load(
        "arm.urdf",
        &urdf,
        &scene("[scene]\nmassless = [\"base\"]\n"),
    )
    .unwrap_or_else(|d| panic!("{d}"));
}
