//! `codegen reduce`: on the Gough–Stewart platform with its legs as bundled (0.1 kg, inertia
//! 1/160 kg·m² each, heavy for a 1.5 kg platform) it keeps the full model at a 1e-3 tolerance;
//! with legs whose rotational inertia is 100 times smaller it drops that inertia (point-mass
//! legs) but keeps their masses, and the spec it writes loads and generates.

use std::path::Path;
use std::process::Command;

fn reduce(spec: &Path, out: &Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_codegen"))
        .args([
            "reduce",
            spec.to_str().unwrap(),
            "--tolerance",
            "1e-3",
            "--samples",
            "40",
            "-o",
        ])
        .arg(out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn heavy_legs_stay_light_legs_lose_their_rotational_inertia() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_reduce");
    std::fs::create_dir_all(&dir).unwrap();
    let gs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/gough_stewart.toml");
    let out = dir.join("heavy.toml");
    let table = reduce(&gs, &out);
    assert!(
        table.contains("cheapest within tolerance: full model"),
        "{table}"
    );
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        std::fs::read_to_string(&gs).unwrap()
    );

    // One parameter gives all twelve leg bodies their inertia.
    let heavy = std::fs::read_to_string(&gs).unwrap();
    assert!(heavy.contains("leg_inertia = \"1 / 160\""));
    let light = heavy.replace("leg_inertia = \"1 / 160\"", "leg_inertia = \"1 / 16000\"");
    let light_path = dir.join("light_in.toml");
    std::fs::write(&light_path, &light).unwrap();
    let out = dir.join("light.toml");
    let table = reduce(&light_path, &out);
    assert!(
        table.contains("cheapest within tolerance: point masses"),
        "{table}"
    );
    let reduced = std::fs::read_to_string(&out).unwrap();
    assert!(
        reduced.contains("[scene]") && reduced.contains("massless = []"),
        "{reduced}"
    );
    // The written spec loads and generates.
    codegen::compile("light.toml", &reduced, &codegen::Config::default())
        .unwrap_or_else(|d| panic!("{d}"));
}

/// `--time` compiles each row's inverse dynamics with rustc and times it on the same states: a
/// `ns per call` column with positive numbers.
#[test]
fn time_column() {
    let spec = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/planar_2r.toml");
    let o = Command::new(env!("CARGO_BIN_EXE_codegen"))
        .args([
            "reduce",
            spec.to_str().unwrap(),
            "--samples",
            "20",
            "--time",
        ])
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(table.contains("| ns per call |"), "{table}");
    let reference = table
        .lines()
        .find(|l| l.starts_with("| full model |"))
        .unwrap();
    let ns: f64 = reference.split('|').nth(3).unwrap().trim().parse().unwrap();
    assert!(ns > 0.0 && ns < 1e6, "{reference}");
}

/// A spec that has a `[scene]` of its own is refused with exit 2 and a diagnostic at the
/// header, file:line:column and key, however the header is spaced: it was an unlocated
/// "error: NAME: `reduce` writes the [scene] table itself" for `[scene]`, and `[ scene ]`
/// (the same table in TOML) got past that check to fail as "the full model cannot be
/// generated".
#[test]
fn a_spec_with_its_own_scene_is_refused_at_the_header() {
    let dir = std::env::temp_dir().join(format!("nocdyn_reduce_scene_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/planar_2r.toml"),
    )
    .unwrap();
    let lines = spec.lines().count();
    for header in ["[scene]", "[ scene ]", "[scene]   # the scene"] {
        let path = dir.join("with_scene.toml");
        std::fs::write(
            &path,
            format!("{spec}\n{header}\nfunctions = [\"inverse_dynamics\"]\n"),
        )
        .unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_codegen"))
            .args(["reduce", path.to_str().unwrap(), "--samples", "5"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{header}: {err}");
        assert!(
            err.contains("writes the [scene] table itself"),
            "{header}: {err}"
        );
        assert!(
            err.contains(&format!("with_scene.toml:{}:", lines + 2)),
            "{header}: {err}"
        );
        assert!(err.contains("^^^^^ scene"), "{header}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
