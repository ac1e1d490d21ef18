//! Variants of bundled mechanisms for the speed/accuracy chart (`src/bin/chart.rs`): the same
//! spec at other fidelity levels (`[scene]` point-mass and massless bodies), with another math
//! backend (the `libm` crate instead of std), and a URDF with its angles rounded as published
//! files write them, generated as written and snapped. Each lands in
//! `$OUT_DIR/variants/<variant>/<module>.rs` and is declared in `src/variants.rs`. Those only the
//! benchmarks and the chart use are generated with the `figures` feature alone.

use std::path::{Path, PathBuf};

use codegen::build_script::Builder;
use codegen::spec::Function;

fn generate(out: &Path, variant: &str, spec: &Path, setup: impl FnOnce(&mut Builder)) {
    let dir = out.join("variants").join(variant);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut b = Builder::new();
    // The variants' warnings are deliberate (massless wrists, snapped angles).
    b.spec(spec)
        .math(codegen::MathBackend::Runtime("runtime".into()))
        .warnings(false)
        .out_dir(&dir);
    setup(&mut b);
    b.compile().unwrap_or_else(|e| panic!("\n{e}"));
}

/// `spec` with `[scene]` lines added (before the first table), written to `$OUT_DIR/specs`.
fn with_scene(out: &Path, spec: &str, name: &str, scene: &str) -> PathBuf {
    let src = std::fs::read_to_string(spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
    println!("cargo:rerun-if-changed={spec}");
    let src = src.replacen(
        "[mechanism]",
        &format!("[scene]\n{scene}\n\n[mechanism]"),
        1,
    );
    write(out, name, &src)
}

fn write(out: &Path, name: &str, src: &str) -> PathBuf {
    let dir = out.join("specs").join(name);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let file = dir.join(spec_file(name));
    codegen::build_script::write_if_changed(&file, src).unwrap_or_else(|e| panic!("{e}"));
    file
}

/// The variant's spec file name: its module name comes from the file stem.
fn spec_file(variant: &str) -> &'static str {
    match variant {
        v if v.starts_with("iiwa") => "iiwa14.urdf",
        v if v.starts_with("gs") => "gough_stewart.toml",
        v if v.starts_with("closed") => "spherical_five_bar.toml",
        v if v.starts_with("delta") => "delta_rl5.toml",
        _ => "puma560.toml",
    }
}

/// Appended to the PUMA 560's spec for the run-time-parameter variant (also read by
/// `tests/tests/params.rs`).
const PARAMS_SCENE: &str = include_str!("src/params_scene.toml");
/// The same with every body's inertial parameters at run time (`runtime_inertia = "all"`).
const PARAMS_SCENE_INERTIA: &str = include_str!("src/params_scene_inertia.toml");
/// The same for the Gough–Stewart platform: a payload on a tool fixed to the platform.
const PARAMS_SCENE_GS: &str = include_str!("src/params_scene_gs.toml");
/// The same for a closed-loop mechanism (the spherical five-bar).
const PARAMS_SCENE_CLOSED: &str = include_str!("src/params_scene_closed.toml");

/// `scene` (one of the `PARAMS_SCENE*` texts) with every body's inertial parameters at run time
/// as well (also in `tests/tests/params.rs`).
fn with_runtime_inertia(scene: &str) -> String {
    scene.replacen("[scene]\n", "[scene]\nruntime_inertia = \"all\"\n", 1)
}

// The bundled platforms and closed loops (`PARALLEL`, `CLOSED`).
include!("src/bundled.rs");

const PUMA: &str = "../mechanisms/specs/puma560.toml";
const CHAIN7: &str = "../mechanisms/specs/chain7.toml";
const GS: &str = "../mechanisms/specs/gough_stewart.toml";
const IIWA: &str = "../mechanisms/specs/iiwa14.urdf";

/// What a variant used for its dynamics alone leaves out.
const DYNAMICS_ONLY: [Function; 4] = [
    Function::InverseDynamicsDerivatives,
    Function::ForwardDynamicsDerivatives,
    Function::Regressor,
    Function::Frames,
];

/// What a variant that no test differentiates leaves out: the derivatives, a platform's or a
/// closed loop's largest functions (tested on the bundled modules).
const NO_DERIVATIVES: [Function; 2] = [
    Function::InverseDynamicsDerivatives,
    Function::ForwardDynamicsDerivatives,
];

fn main() {
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR is set by cargo"));
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_FIGURES").is_some() {
        figures(&out);
    }

    let p = with_scene(&out, GS, "gs_id_only", "functions = [\"inverse_dynamics\"]");
    generate(&out, "gs_id_only", &p, |_| {});
    // The planar 3-RRR in joint coordinates (`tests/tests/planar3.rs`, and the bench against its
    // task form).
    let joints = "data/planar_3rrr_joints.toml";
    println!("cargo:rerun-if-changed={joints}");
    generate(&out, "planar3_joints", Path::new(joints), |b| {
        b.omit(&DYNAMICS_ONLY);
    });
    // Walks into singularities (`tests/tests/singularities.rs`): a planar 3-RPR whose leg
    // lines can all pass through the platform's origin (`rpr_legs_through_the_platform_origin`)
    // and a planar 3-RRR whose first leg can fold onto its base joint
    // (`rrr_leg_folded_onto_its_base_joint`).
    for (variant, spec) in [
        ("rpr_turning", "data/rpr_turning.toml"),
        ("rrr_fold", "data/planar_3rrr_fold.toml"),
    ] {
        println!("cargo:rerun-if-changed={spec}");
        generate(&out, variant, Path::new(spec), |b| {
            b.omit(&DYNAMICS_ONLY);
        });
    }
    // Friction and rotor inertia (`tests/tests/regressor.rs`: their base parameters).
    let p = with_scene(
        &out,
        PUMA,
        "puma_drives",
        "friction = true\nrotor_inertia = true",
    );
    generate(&out, "puma_drives", &p, |_| {});

    // Run-time parameters (`tests/tests/params.rs`): a payload on a tool on a turned flange.
    let src = std::fs::read_to_string(PUMA).unwrap_or_else(|e| panic!("{PUMA}: {e}"));
    let src = format!("{src}\n{PARAMS_SCENE}");
    let p = write(&out, "puma_params", &src);
    generate(&out, "puma_params", &p, |_| {});
    let src = std::fs::read_to_string(PUMA).unwrap_or_else(|e| panic!("{PUMA}: {e}"));
    let src = format!("{src}\n{PARAMS_SCENE_INERTIA}");
    let p = write(&out, "puma_inertia", &src);
    generate(&out, "puma_inertia", &p, |_| {});
    let src = std::fs::read_to_string(GS).unwrap_or_else(|e| panic!("{GS}: {e}"));
    let src = format!("{src}\n{PARAMS_SCENE_GS}");
    let p = write(&out, "gs_params", &src);
    // With the `Dynamics` impl: `tests/tests/implement.rs` reads its frames through the trait.
    generate(&out, "gs_params", &p, |b| {
        b.implement("runtime").omit(&NO_DERIVATIVES);
    });
    let src = std::fs::read_to_string(GS).unwrap_or_else(|e| panic!("{GS}: {e}"));
    let src = format!("{src}\n{}", with_runtime_inertia(PARAMS_SCENE_GS));
    let p = write(&out, "gs_inertia", &src);
    generate(&out, "gs_inertia", &p, |b| {
        b.omit(&NO_DERIVATIVES);
    });
    // A generic leg (Newton inverse kinematics): `tests/tests/parallel.rs`.
    let generic = Path::new("../codegen/tests/data/good_parallel/generic_leg.toml");
    println!("cargo:rerun-if-changed={}", generic.display());
    generate(&out, "generic_leg", generic, |b| {
        b.omit(&DYNAMICS_ONLY);
    });
    let sfb = "../mechanisms/specs/spherical_five_bar.toml";
    println!("cargo:rerun-if-changed={sfb}");
    let src = std::fs::read_to_string(sfb).unwrap_or_else(|e| panic!("{sfb}: {e}"));
    let src = format!("{src}\n{PARAMS_SCENE_CLOSED}");
    let p = write(&out, "closed_params", &src);
    generate(&out, "closed_params", &p, |b| {
        b.implement("runtime").omit(&NO_DERIVATIVES);
    });
    let src = std::fs::read_to_string(sfb).unwrap_or_else(|e| panic!("{sfb}: {e}"));
    let src = format!("{src}\n{}", with_runtime_inertia(PARAMS_SCENE_CLOSED));
    let p = write(&out, "closed_inertia", &src);
    generate(&out, "closed_inertia", &p, |b| {
        b.omit(&NO_DERIVATIVES);
    });

    // Fused multiply–add (`tests/tests/fma.rs`, the `fma` bench group): a tree of 6 and of 7
    // joints, a platform and a closed loop, each with `Config::fma`.
    for spec in [
        PUMA,
        CHAIN7,
        GS,
        "../mechanisms/specs/spherical_five_bar.toml",
    ] {
        println!("cargo:rerun-if-changed={spec}");
        generate(&out, "fma", Path::new(spec), |b| {
            b.fma(true).implement("runtime");
        });
    }
    // `sin` and `cos` of a function's input angles in one call (`tests/tests/batch_sin_cos.rs`):
    // two trees of 7 joints and a closed loop in joint coordinates, each with
    // `Config::batch_sin_cos`.
    for spec in [CHAIN7, IIWA, "../mechanisms/specs/spherical_five_bar.toml"] {
        generate(&out, "batch_sin_cos", Path::new(spec), |b| {
            b.batch_sin_cos(true).implement("runtime");
        });
    }
    // Many states per call (`tests/tests/lanes.rs`, the `lanes` bench group): every bundled
    // tree with `Config::lanes` (4 in `f64`), the PUMA 560 also with 8 lanes in `f32`.
    let trees = [
        PUMA,
        "../mechanisms/specs/puma560.urdf",
        CHAIN7,
        "../mechanisms/specs/gripper_tree.toml",
        IIWA,
        "../mechanisms/specs/planar_2r.toml",
        "../mechanisms/specs/stanford_arm.toml",
    ];
    for spec in trees {
        println!("cargo:rerun-if-changed={spec}");
    }
    generate(&out, "lanes", Path::new(trees[0]), |b| {
        for spec in &trees[1..] {
            b.spec(spec);
        }
        b.lanes(Some(4));
    });
    // The bundled platforms and closed loops with 4 lanes (dynamics only): their `_lanes`
    // functions against the scalar ones in `tests/tests/lanes.rs`.
    for (variant, names) in [
        ("lanes_parallel", &PARALLEL[..]),
        ("lanes_closed", &CLOSED[..]),
    ] {
        let specs: Vec<String> = names
            .iter()
            .map(|n| format!("../mechanisms/specs/{n}.toml"))
            .collect();
        for spec in &specs {
            println!("cargo:rerun-if-changed={spec}");
        }
        generate(&out, variant, Path::new(&specs[0]), |b| {
            for spec in &specs[1..] {
                b.spec(spec);
            }
            b.lanes(Some(4)).omit(&DYNAMICS_ONLY);
        });
    }
    generate(&out, "lanes_f32", Path::new(PUMA), |b| {
        b.lanes(Some(8)).float(codegen::Float::F32);
    });
    // A platform and a closed loop in `f32` with 8 lanes (dynamics only): their `_lanes`
    // functions against the scalar `f32` ones in `tests/tests/lanes.rs`.
    generate(
        &out,
        "lanes_f32_sites",
        Path::new("../mechanisms/specs/planar_3rrr.toml"),
        |b| {
            b.spec("../mechanisms/specs/four_bar.toml")
                .lanes(Some(8))
                .float(codegen::Float::F32)
                .omit(&DYNAMICS_ONLY);
        },
    );
    // The lanes' arithmetic through the `wide` crate (`Config::wide`): three platforms, a
    // closed loop and an arm with 4 lanes in `f64`, the 3-RRR with 8 in `f32` (dynamics only),
    // against the scalar functions in `tests/tests/lanes.rs` and in the `lanes_wide` benches.
    generate(&out, "lanes_wide", Path::new(GS), |b| {
        b.spec("../mechanisms/specs/delta_rl5.toml")
            .spec("../mechanisms/specs/agile_eye.toml")
            .spec("../mechanisms/specs/four_bar.toml")
            .spec(PUMA)
            .lanes(Some(4))
            .wide(Some("wide"))
            .omit(&DYNAMICS_ONLY);
    });
    generate(
        &out,
        "lanes_wide_f32",
        Path::new("../mechanisms/specs/planar_3rrr.toml"),
        |b| {
            b.lanes(Some(8))
                .float(codegen::Float::F32)
                .wide(Some("wide"))
                .omit(&DYNAMICS_ONLY);
        },
    );
    // `sin` and `cos` over all lanes at once (`Config::vector_sin_cos`): three arms in `f64`,
    // the PUMA 560 also with 8 lanes in `f32`; dynamics only.
    generate(&out, "lanes_vector", Path::new(PUMA), |b| {
        b.spec(trees[2])
            .spec(trees[4])
            .lanes(Some(4))
            .vector_sin_cos(true)
            .omit(&DYNAMICS_ONLY);
    });
    generate(&out, "lanes_vector_f32", Path::new(PUMA), |b| {
        b.lanes(Some(8))
            .float(codegen::Float::F32)
            .vector_sin_cos(true)
            .omit(&DYNAMICS_ONLY);
    });
}

/// The variants only the benchmarks (`benches/`) and the chart (`src/bin/chart.rs`) use.
fn figures(out: &Path) {
    generate(out, "libm", Path::new(PUMA), |b| {
        b.math(codegen::MathBackend::Libm);
    });
    let wrist = r#""link4", "link5", "link6""#;
    let p = with_scene(
        out,
        PUMA,
        "puma_point_wrist",
        &format!("point_mass = [{wrist}]"),
    );
    generate(out, "puma_point_wrist", &p, |_| {});
    let p = with_scene(
        out,
        PUMA,
        "puma_massless_wrist",
        &format!("massless = [{wrist}]"),
    );
    generate(out, "puma_massless_wrist", &p, |_| {});
    let legs: Vec<String> = (1..=6)
        .flat_map(|k| [format!("\"cylinder{k}\""), format!("\"piston{k}\"")])
        .collect();
    let p = with_scene(
        out,
        GS,
        "gs_point_legs",
        &format!("point_mass = [{}]", legs.join(", ")),
    );
    generate(out, "gs_point_legs", &p, |_| {});
    // Codourey's simplified Delta, for the speed/accuracy chart beside the exact model.
    let delta = "../mechanisms/specs/delta_rl5.toml";
    let p = with_scene(out, delta, "delta_codourey", "delta_model = \"codourey\"");
    generate(out, "delta_codourey", &p, |_| {});
    // The Delta in joint coordinates (the closed-loop route), for the bench against its
    // platform form (inverse dynamics: these four keep their dynamics only).
    let joints = "data/delta_rl5_joints.toml";
    println!("cargo:rerun-if-changed={joints}");
    generate(out, "delta_joints", Path::new(joints), |b| {
        b.omit(&DYNAMICS_ONLY);
    });
    // Tsai's 3-UPU in joint coordinates, likewise.
    let joints = "data/tsai_3upu_joints.toml";
    println!("cargo:rerun-if-changed={joints}");
    generate(out, "upu_joints", Path::new(joints), |b| {
        b.omit(&DYNAMICS_ONLY);
    });
    // The 4-axis Delta in joint coordinates, likewise.
    let joints = "data/delta4_rl5_joints.toml";
    println!("cargo:rerun-if-changed={joints}");
    generate(out, "delta4_joints", Path::new(joints), |b| {
        b.omit(&DYNAMICS_ONLY);
    });
    // The 3-PRS tripod of mechanisms/specs/tripod_3prs.toml in task coordinates (heave_tilt),
    // for the bench against its joint-coordinate form.
    let task = "data/tripod_3prs_task.toml";
    println!("cargo:rerun-if-changed={task}");
    generate(out, "tripod_task", Path::new(task), |b| {
        b.omit(&DYNAMICS_ONLY);
    });

    // The PUMA 560 fused with the default `libm` backend (`libm::fma`, chosen at run time on
    // x86): the `fma/puma560/…/fused_libm` benches (inverse dynamics, mass matrix), the CLI's
    // note on `--fma`; dynamics only.
    generate(out, "fma_libm", Path::new(PUMA), |b| {
        b.fma(true)
            .math(codegen::MathBackend::Libm)
            .omit(&DYNAMICS_ONLY);
    });

    // The same with trigonometry from the `libm` crate (half the cost of std's `sin_cos` here,
    // and inlined): the `lanes_libm` bench groups.
    generate(out, "lanes_libm", Path::new(PUMA), |b| {
        b.spec(CHAIN7)
            .lanes(Some(4))
            .math(codegen::MathBackend::Libm);
    });
    // The three arms of `lanes_vector` with their lanes' arithmetic through the `wide` crate:
    // the `lanes_vector_wide` benches.
    generate(out, "lanes_vector_wide", Path::new(PUMA), |b| {
        b.spec(CHAIN7)
            .spec(IIWA)
            .lanes(Some(4))
            .vector_sin_cos(true)
            .wide(Some("wide"))
            .omit(&DYNAMICS_ONLY);
    });
    // The three arms of `lanes_vector` with 8 lanes: the `lanes_vector8` benches.
    generate(out, "lanes_vector8", Path::new(PUMA), |b| {
        b.spec(CHAIN7)
            .spec(IIWA)
            .lanes(Some(8))
            .vector_sin_cos(true)
            .omit(&DYNAMICS_ONLY);
    });
    // Three platforms with 8 lanes (dynamics only): the `lanes8/…` benches beside `lanes/…`,
    // and the same through `wide`: the `lanes8_wide/…` benches.
    for (variant, wide) in [("lanes8_parallel", None), ("lanes8_wide", Some("wide"))] {
        generate(out, variant, Path::new(GS), |b| {
            b.spec("../mechanisms/specs/delta_rl5.toml")
                .spec("../mechanisms/specs/agile_eye.toml")
                .lanes(Some(8))
                .wide(wide)
                .omit(&DYNAMICS_ONLY);
        });
    }
    // The iiwa 14 as published URDFs often write it: quarter and half turns to 5 digits.
    let src = std::fs::read_to_string(IIWA).unwrap_or_else(|e| panic!("{IIWA}: {e}"));
    println!("cargo:rerun-if-changed={IIWA}");
    let rounded = src
        .replace("1.5707963267948966", "1.5708")
        .replace("3.141592653589793", "3.1416");
    let p = write(out, "iiwa_rounded", &rounded);
    generate(out, "iiwa_rounded", &p, |_| {});
    generate(out, "iiwa_snapped", &p, |b| {
        b.snap(1e-4);
    });
}
