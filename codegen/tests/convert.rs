//! `codegen convert`: a URDF and its TOML conversion generate the same module, byte for byte
//! (and with friction on, where `<dynamics>` enters), so a URDF robot loses nothing by being
//! written as TOML to get a `[scene]`.
#![cfg(feature = "urdf")]

use std::path::Path;

use codegen::{Config, compile, spec::SceneOverrides};

fn same_module(path: &Path) {
    let src = std::fs::read_to_string(path).unwrap();
    let name = path.file_name().unwrap().to_str().unwrap();
    let (toml, _) =
        codegen::spec::urdf_to_toml(name, &src).unwrap_or_else(|d| panic!("{}", d.render()));
    for friction in [false, true] {
        let cfg = Config {
            scene: SceneOverrides {
                friction,
                ..Default::default()
            },
            ..Config::default()
        };
        let a = compile(name, &src, &cfg).unwrap_or_else(|d| panic!("{}", d.render()));
        let b = compile("converted.toml", &toml, &cfg)
            .unwrap_or_else(|d| panic!("{name}:\n{}\n{toml}", d.render()));
        assert!(
            a.code == b.code,
            "{name} (friction {friction}): the modules differ"
        );
    }
}

#[test]
fn converted_urdfs_generate_the_same_module() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for p in [
        "../mechanisms/specs/puma560.urdf",
        "../mechanisms/specs/iiwa14.urdf",
        // A non-root link named `base` (read as `base_`) and a `<mimic>` joint.
        "tests/data/warn/base_link_named_base.urdf",
        "tests/data/warn/mimic.urdf",
    ] {
        same_module(&root.join(p));
    }
}

/// The CLI writes the conversion; an invalid URDF is its diagnostics, exit code 2.
#[test]
fn the_cli_converts_and_refuses_bad_urdfs() {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_codegen"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["convert", "../mechanisms/specs/iiwa14.urdf"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("[[joint]]") && text.contains("name = \"iiwa_joint_7\""));
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_codegen"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["convert", "tests/data/bad/bad_values.urdf"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
}
