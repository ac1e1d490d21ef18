//! Generates every spec in `specs/` into `$OUT_DIR/<module>.rs` (see codegen::build_script),
//! plus `$OUT_DIR/mechanisms.rs`, which declares one module per spec; with the `f32` feature
//! also `$OUT_DIR/f32/<module>.rs`, declared inside `pub mod f32` (without the derivatives,
//! regressor and frame functions).
fn main() {
    let out =
        std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR is set by cargo"));
    let single = std::env::var_os("CARGO_FEATURE_F32").is_some();
    let mut list = String::new();
    for float in [codegen::Float::F64, codegen::Float::F32] {
        let (dir, prefix) = match float {
            codegen::Float::F64 => (out.clone(), ""),
            codegen::Float::F32 if single => (out.join("f32"), "f32/"),
            codegen::Float::F32 => continue,
        };
        std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        let mut b = codegen::build_script::Builder::new();
        b.specs_in("specs")
            .math(codegen::MathBackend::Runtime("runtime".into()))
            .float(float)
            .implement("runtime")
            .out_dir(&dir);
        if float == codegen::Float::F32 {
            // Single precision keeps the dynamics and kinematics; derivatives, regressors and
            // frames stay f64 only (they would double the crate's build time).
            use codegen::spec::Function::*;
            b.omit(&[
                InverseDynamicsDerivatives,
                ForwardDynamicsDerivatives,
                Regressor,
                Frames,
            ]);
        }
        b.compile().unwrap_or_else(|e| panic!("\n{e}"));
        if float == codegen::Float::F32 {
            list.push_str(
                "/// The same modules in single precision (`f32`; feature `f32`).\npub mod f32 {\n",
            );
        }
        for m in b.module_names() {
            list.push_str(&format!(
                "/// Generated from `specs/` (see the module's header for its spec and op counts).\n\
                 pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{prefix}{m}.rs\")); }}\n"
            ));
        }
        if float == codegen::Float::F32 {
            list.push_str("}\n");
        }
    }
    codegen::build_script::write_if_changed(&out.join("mechanisms.rs"), &list)
        .unwrap_or_else(|e| panic!("{e}"));
}
