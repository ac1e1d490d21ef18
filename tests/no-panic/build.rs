//! The PUMA 560 with `_lanes` functions (4 states per call) and the vector `sin_cos`: options
//! whose code the bundled `mechanisms` crate does not hold, proved here too.
//!
//! The PUMA 560 with fused multiply–adds (`fma`) and its joint angles' `sin_cos` in one call
//! (`batch_sin_cos`), every function, through its `Dynamics` impl.
//! On x86 the proof is built with the target's FMA (`-C target-feature=+fma`; `.ci/run`): the
//! runtime's `mul_add` is then the instruction, where the `libm` crate's `fma` picks the
//! instruction or a fallback at run time through a function pointer, an indirect call the proof
//! cannot see through (docs/performance.md, "Fused multiply–add").

//!
//! Also a platform (the planar 3-RRR) and a closed loop (the four-bar) with `_lanes` functions,
//! dynamics only: their per-lane guards, and the platform's per-lane LU.

fn main() {
    let spec = "../../mechanisms/specs/puma560.toml";
    println!("cargo:rerun-if-changed={spec}");
    let out = std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR"));
    codegen::build_script::Builder::new()
        .spec(spec)
        .math(codegen::MathBackend::Runtime("runtime".into()))
        .lanes(Some(4))
        .vector_sin_cos(true)
        .out_dir(&out)
        .compile()
        .unwrap_or_else(|e| panic!("\n{e}"));
    let fma = out.join("fma");
    std::fs::create_dir_all(&fma).unwrap_or_else(|e| panic!("{}: {e}", fma.display()));
    codegen::build_script::Builder::new()
        .spec(spec)
        .math(codegen::MathBackend::Runtime("runtime".into()))
        .fma(true)
        .batch_sin_cos(true)
        .implement("runtime")
        .out_dir(&fma)
        .compile()
        .unwrap_or_else(|e| panic!("\n{e}"));
    let (platform, closed) = (
        "../../mechanisms/specs/planar_3rrr.toml",
        "../../mechanisms/specs/four_bar.toml",
    );
    println!("cargo:rerun-if-changed={platform}");
    println!("cargo:rerun-if-changed={closed}");
    use codegen::spec::Function as F;
    codegen::build_script::Builder::new()
        .spec(platform)
        .spec(closed)
        .math(codegen::MathBackend::Runtime("runtime".into()))
        .lanes(Some(4))
        .omit(&[
            F::InverseDynamicsDerivatives,
            F::ForwardDynamicsDerivatives,
            F::Regressor,
            F::Frames,
        ])
        .out_dir(&out)
        .compile()
        .unwrap_or_else(|e| panic!("\n{e}"));
}
