fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let mut b = codegen::build_script::Builder::new();
    b.specs_in("urdf")
        .math(codegen::MathBackend::Runtime("runtime".into()));
    b.compile().unwrap_or_else(|e| panic!("{e}"));
    let mut list = String::new();
    let mut calls = String::new();
    for m in b.module_names() {
        list.push_str(&format!(
            "pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{m}.rs\")); }}\n"
        ));
        calls.push_str(&format!("check!({m});\n"));
    }
    std::fs::write(out.join("all.rs"), list).unwrap();
    std::fs::write(out.join("calls.rs"), format!("{{\n{calls}}}\n")).unwrap();
}
