fn main() {
    let mut b = codegen::build_script::Builder::new();
    b.specs_in("urdf").math(codegen::MathBackend::Runtime("runtime".into()));
    b.compile().unwrap_or_else(|e| panic!("{e}"));
    let mut list = String::new();
    for m in b.module_names() {
        list.push_str(&format!("pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{m}.rs\")); }}\n"));
    }
    std::fs::write(std::path::Path::new(&std::env::var("OUT_DIR").unwrap()).join("all.rs"), list).unwrap();
}
