//! The PUMA 560 with `_lanes` functions (4 states per call in `f64`, 8 in `f32`), fused
//! multiply–adds and the vector `sin_cos`: the options whose code the bundled `mechanisms`
//! crate does not hold, linked here without std as well; and a platform and a closed loop with
//! frames (the bundled specs have none) and the `Dynamics` impl, whose frames `lib.rs` reads
//! through the trait; and the 3-RRR and the four-bar with the same lanes; and the PUMA 560
//! (as above) and the 3-RRR with 4 lanes through the `wide` crate (`Config::wide`).

/// What the lanes modules leave out: the functions with no `_lanes` version.
const NOT_ON_LANES: [codegen::spec::Function; 3] = [
    codegen::spec::Function::InverseDynamicsDerivatives,
    codegen::spec::Function::ForwardDynamicsDerivatives,
    codegen::spec::Function::Regressor,
];

fn main() {
    let spec = "../../mechanisms/specs/puma560.toml";
    println!("cargo:rerun-if-changed={spec}");
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    for (dir, lanes, float) in [
        ("f64", 4, codegen::Float::F64),
        ("f32", 8, codegen::Float::F32),
    ] {
        let dir = out.join(dir);
        std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        codegen::build_script::Builder::new()
            .spec(spec)
            .math(codegen::MathBackend::Runtime("runtime".into()))
            .float(float)
            .fma(true)
            .lanes(Some(lanes))
            .vector_sin_cos(true)
            .batch_sin_cos(true)
            .out_dir(&dir)
            .compile()
            .unwrap_or_else(|e| panic!("\n{e}"));
        // A platform and a closed loop with the same lanes (dynamics only): their `_lanes`
        // functions keep a status per lane and fall back to the scalar function.
        let mut b = codegen::build_script::Builder::new();
        for spec in ["planar_3rrr", "four_bar"] {
            let path = format!("../../mechanisms/specs/{spec}.toml");
            println!("cargo:rerun-if-changed={path}");
            b.spec(path);
        }
        b.math(codegen::MathBackend::Runtime("runtime".into()))
            .float(float)
            .lanes(Some(lanes))
            .omit(&NOT_ON_LANES)
            .out_dir(&dir)
            .compile()
            .unwrap_or_else(|e| panic!("\n{e}"));
    }
    let dir = out.join("wide");
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for (spec, tree) in [("puma560", true), ("planar_3rrr", false)] {
        let path = format!("../../mechanisms/specs/{spec}.toml");
        println!("cargo:rerun-if-changed={path}");
        let mut b = codegen::build_script::Builder::new();
        b.spec(path)
            .math(codegen::MathBackend::Runtime("runtime".into()))
            .fma(tree)
            .vector_sin_cos(tree)
            .lanes(Some(4))
            .wide(Some("wide"))
            .omit(&NOT_ON_LANES)
            .out_dir(&dir)
            .compile()
            .unwrap_or_else(|e| panic!("\n{e}"));
    }
    let dir = out.join("frames");
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for (spec, functions) in [
        (
            "gough_stewart",
            r#""inverse_dynamics", "mass_matrix", "actuator_mass_matrix", "forward_dynamics", "actuator_rates""#,
        ),
        (
            "tripod_3prs",
            r#""inverse_dynamics", "mass_matrix", "forward_dynamics""#,
        ),
    ] {
        let path = format!("../../mechanisms/specs/{spec}.toml");
        println!("cargo:rerun-if-changed={path}");
        let src = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let scene = format!(
            "[scene]\nframes = [\"platform\"]\nfunctions = [{functions}, \"frames\"]\n\n[mechanism]"
        );
        let file = dir.join(format!("{spec}.toml"));
        codegen::build_script::write_if_changed(&file, &src.replacen("[mechanism]", &scene, 1))
            .unwrap_or_else(|e| panic!("{e}"));
        codegen::build_script::Builder::new()
            .spec(&file)
            .math(codegen::MathBackend::Runtime("runtime".into()))
            .implement("runtime")
            .out_dir(&dir)
            .compile()
            .unwrap_or_else(|e| panic!("\n{e}"));
    }
}
