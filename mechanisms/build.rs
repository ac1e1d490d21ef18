//! Generates every spec in `specs/` into `$OUT_DIR/<module>.rs` (see codegen::build_script),
//! plus `$OUT_DIR/mechanisms.rs`, which declares one module per spec.
fn main() {
    let mut b = codegen::build_script::Builder::new();
    b.specs_in("specs")
        .unwrap_or_else(|e| panic!("{e}"))
        .math(codegen::MathBackend::Runtime("runtime".into()));
    b.compile().unwrap_or_else(|e| panic!("\n{e}"));
    let mut list = String::new();
    for m in b.module_names() {
        list.push_str(&format!(
            "/// Generated from `specs/` (see the module's header for its spec and op counts).\n\
             pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{m}.rs\")); }}\n"
        ));
    }
    let out =
        std::path::PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR is set by cargo"));
    codegen::build_script::write_if_changed(&out.join("mechanisms.rs"), &list)
        .unwrap_or_else(|e| panic!("{e}"));
}
