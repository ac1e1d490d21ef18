/// The arms (<= 9 DOF) that are also generated with fused multiply-adds (`Config::fma`), for the
/// comparison with Pinocchio's CppADCodeGen code (README.md, "Against Pinocchio's code
/// generation"). Their modules are `robots::fma::NAME`, and with `Config::batch_sin_cos` too
/// `robots::batch::NAME`.
const FMA_ARMS: [&str; 8] = [
    "ur5",
    "ur10",
    "panda",
    "z1",
    "kinova",
    "xarm7",
    "iiwa14",
    "talos_left_arm",
];

fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let mut b = codegen::build_script::Builder::new();
    b.specs_in("urdf")
        .math(codegen::MathBackend::Runtime("runtime".into()));
    b.compile().unwrap_or_else(|e| panic!("{e}"));
    let mut list = String::new();
    for m in b.module_names() {
        list.push_str(&format!(
            "pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{m}.rs\")); }}\n"
        ));
    }
    // The same arms with `mul_add` (one instruction where the target has FMA: run.sh builds with
    // RUSTFLAGS="-C target-cpu=native"), and again with every function's joint angles in one
    // `sin_cos_batch` call (`Config::batch_sin_cos`).
    list.push_str(&arms(&out, "fma", |b| {
        b.fma(true);
    }));
    list.push_str(&arms(&out, "batch", |b| {
        b.fma(true).batch_sin_cos(true);
    }));
    std::fs::write(out.join("all.rs"), list).unwrap();
}

/// The arms generated with the options `setup` sets into `$OUT_DIR/NAME`, and the text that
/// declares them as `robots::NAME::ARM`.
fn arms(
    out: &std::path::Path,
    name: &str,
    setup: impl FnOnce(&mut codegen::build_script::Builder),
) -> String {
    let dir = out.join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let mut b = codegen::build_script::Builder::new();
    b.math(codegen::MathBackend::Runtime("runtime".into()))
        .out_dir(&dir);
    setup(&mut b);
    for a in FMA_ARMS {
        b.spec(format!("urdf/{a}.urdf"));
    }
    b.compile().unwrap_or_else(|e| panic!("{e}"));
    let mut list = format!("pub mod {name} {{\n");
    for m in b.module_names() {
        list.push_str(&format!(
            "    pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{name}/{m}.rs\")); }}\n"
        ));
    }
    list.push_str("}\n");
    list
}
