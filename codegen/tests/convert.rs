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

/// `(name, lower, upper, velocity)` of each revolute or prismatic joint with a `<limit>`, in
/// document order, by a scan of the URDF text of its own (not the reader under test).
fn urdf_limits(urdf: &str) -> Vec<(String, f64, f64, f64)> {
    let attr = |tag: &str, name: &str| -> String {
        let at = tag.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        tag[at..at + tag[at..].find('"').unwrap()].to_string()
    };
    let mut out = Vec::new();
    for chunk in urdf.split("<joint ").skip(1) {
        let body = &chunk[..chunk.find("</joint>").unwrap()];
        let head = &body[..body.find('>').unwrap()];
        if !(head.contains("type=\"revolute\"") || head.contains("type=\"prismatic\"")) {
            continue;
        }
        let Some(at) = body.find("<limit") else {
            continue;
        };
        let tag = &body[at..at + body[at..].find('>').unwrap()];
        let num = |n: &str| attr(tag, n).parse::<f64>().unwrap();
        out.push((
            attr(&format!(" {head}"), "name"),
            num("lower"),
            num("upper"),
            num("velocity"),
        ));
    }
    out
}

/// The URDF's limits reach `Loaded::limits` as written, and `convert` writes them as `limit`
/// keys that the TOML reader reads back to the same numbers.
#[test]
fn limits_survive_the_conversion() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for p in [
        "../mechanisms/specs/iiwa14.urdf",
        "../mechanisms/specs/puma560.urdf",
    ] {
        let src = std::fs::read_to_string(root.join(p)).unwrap();
        let want = urdf_limits(&src);
        assert!(!want.is_empty(), "{p}");
        let (toml, _) = codegen::spec::urdf_to_toml("r.urdf", &src).unwrap();
        assert_eq!(toml.matches("\nlimit = { lower = ").count(), want.len());
        assert!(!toml.contains("not part of nocdyn's model"));
        for (name, text) in [("r.urdf", src.as_str()), ("r.toml", toml.as_str())] {
            let got = codegen::spec::load(name, text, &SceneOverrides::default())
                .unwrap_or_else(|d| panic!("{}", d.render()))
                .limits;
            let got: Vec<_> = got
                .iter()
                .map(|l| (l.joint.clone(), l.lower, l.upper, l.velocity.unwrap()))
                .collect();
            assert_eq!(got, want, "{p} as {name}");
        }
    }
}
