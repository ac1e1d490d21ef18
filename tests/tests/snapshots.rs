//! Snapshots of every bundled mechanism's generated module and op-count table: the contract of
//! the generator's output. A change here must be reviewed (`cargo insta review`), not waved
//! through: the numbers in these files are checked independently by `generated.rs`.

use codegen::{Config, compile};

fn generate(path: &std::path::Path) -> codegen::Generated {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("spec");
    let src = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    compile(name, &src, &Config::default()).unwrap_or_else(|d| panic!("{d}"))
}

/// Each bundled spec generated once, in this process, against the module and the op-count table
/// committed by another: a generator whose output moved with hash order or addresses would fail
/// here (and `codegen/tests/identical.rs` compares the CLI's process with its own).
#[test]
fn generated_modules() {
    insta::glob!("../../mechanisms/specs", "*.{toml,urdf}", |path| {
        let g = generate(path);
        insta::assert_snapshot!("generated_modules", g.code);
        insta::assert_snapshot!("op_count_tables", g.stats_table().join("\n"));
    });
}

/// The text of the bundled spec `spec` (`mechanisms/specs/<spec>`).
fn bundled(spec: &str) -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../mechanisms/specs")
        .join(spec);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Single precision: the `f32` modules of a tree, a parallel and a closed-loop mechanism (the
/// same equations as their `f64` snapshots; the thresholds rescaled, the math calls `f32`).
#[test]
fn f32_modules() {
    for spec in ["puma560.toml", "agile_eye.toml", "four_bar.toml"] {
        let src = bundled(spec);
        let cfg = Config {
            float: codegen::Float::F32,
            ..Config::default()
        };
        let code = compile(spec, &src, &cfg)
            .unwrap_or_else(|d| panic!("{d}"))
            .code;
        insta::assert_snapshot!(format!("f32_{spec}"), code);
    }
}

/// `Config::implement`: a tree, a parallel and a closed-loop module with the `Dynamics` impl.
/// The option only appends (`Module` and its impl) to the default module, byte for byte; the
/// appended text is the snapshot, a contract of its own.
#[test]
fn implement_modules() {
    for spec in ["planar_2r.toml", "planar_five_bar.toml", "four_bar.toml"] {
        let src = bundled(spec);
        let cfg = Config {
            implement: Some("runtime".into()),
            ..Config::default()
        };
        let with = compile(spec, &src, &cfg)
            .unwrap_or_else(|d| panic!("{d}"))
            .code;
        let without = compile(spec, &src, &Config::default()).unwrap().code;
        let tail = with
            .strip_prefix(&without)
            .unwrap_or_else(|| panic!("{spec}: `implement` changed the module before its impl"));
        insta::assert_snapshot!(format!("implement_{spec}"), tail);
    }
}

/// Many states per call (`Config::lanes`, two lanes; dynamics only): a tree, a platform and a
/// closed loop. The `_lanes` functions, their guards over the lanes and each lane's `Err` are
/// generated code of their own, a contract as the scalar functions are; `lanes.rs` checks them
/// against the scalar functions.
#[test]
fn lanes_modules() {
    use codegen::spec::Function as F;
    for spec in ["planar_2r.toml", "planar_3rrr.toml", "four_bar.toml"] {
        let src = bundled(spec);
        let mut cfg = Config {
            lanes: Some(2),
            ..Config::default()
        };
        cfg.scene.omit = vec![
            F::InverseDynamicsDerivatives,
            F::ForwardDynamicsDerivatives,
            F::Regressor,
            F::Frames,
        ];
        let code = compile(spec, &src, &cfg)
            .unwrap_or_else(|d| panic!("{d}"))
            .code;
        insta::assert_snapshot!(format!("lanes_{spec}"), code);
    }
}

/// `Config::wide`: the planar 2R's two lanes with `wide`'s arithmetic. The module is the plain
/// lanes module but for `Lanes`' doc line, operators, negation, `sqrt`, `mul_add` and
/// `select_abs_gt`; the snapshot is the line diff of the two (one line of context).
#[test]
fn lanes_wide_operators() {
    let spec = "planar_2r.toml";
    let src = bundled(spec);
    let plain = Config {
        lanes: Some(2),
        ..Config::default()
    };
    let wide = Config {
        wide: Some("wide".into()),
        ..plain.clone()
    };
    let code = |cfg: &Config| {
        compile(spec, &src, cfg)
            .unwrap_or_else(|d| panic!("{d}"))
            .code
    };
    let (plain, wide) = (code(&plain), code(&wide));
    let diff = similar::TextDiff::from_lines(&plain, &wide)
        .unified_diff() // no file header: every `+`/`-` line is a changed line
        .context_radius(1)
        .to_string();
    let changed: Vec<&str> = diff
        .lines()
        .filter(|l| l.starts_with('+') || l.starts_with('-'))
        .collect();
    assert!(
        changed.iter().any(|l| l.contains("wide::f64x2::new")),
        "{diff}"
    );
    for kept in ["sin_cos", "atan2", "fn inverse_dynamics", "splat"] {
        assert!(
            changed.iter().all(|l| !l.contains(kept)),
            "{kept} changed:\n{diff}"
        );
    }
    insta::assert_snapshot!("lanes_wide_planar_2r", diff);
}

/// `Config::batch_sin_cos`: the planar 2R with every function's joint angles in one
/// `sin_cos_batch` call. The module is the plain one but for the header line, each function's
/// `sin_cos` statements (one batched call after the statements its angles need) and the items
/// appended; the snapshot is the line diff of the two (no context). Batching moves statements
/// and adds none (`batch_sin_cos.rs` compares the op counts): the only backend call left is in
/// `sin_cos_backend`, for angles beyond the polynomial's range.
#[test]
fn batch_sin_cos_statements() {
    let spec = "planar_2r.toml";
    let src = bundled(spec);
    let code = |cfg: &Config| {
        compile(spec, &src, cfg)
            .unwrap_or_else(|d| panic!("{d}"))
            .code
    };
    let plain = code(&Config::default());
    let batched = code(&Config {
        batch_sin_cos: true,
        ..Config::default()
    });
    assert!(plain.matches("libm::sincos(").count() > 1);
    assert_eq!(batched.matches("libm::sincos(").count(), 1);
    let diff = similar::TextDiff::from_lines(&plain, &batched)
        .unified_diff()
        .context_radius(0)
        .to_string();
    insta::assert_snapshot!("batch_sin_cos_planar_2r", diff);
}
