/// The arms (<= 9 DOF) that are also generated with fused multiply-adds (`Config::fma`), for the
/// comparison with Pinocchio's CppADCodeGen code (README.md, "Against Pinocchio's code
/// generation"). Their modules are `robots::fma::NAME`, and with `Config::batch_sin_cos` too
/// `robots::batch::NAME`.
const FMA_ARMS: [&str; 8] = ["ur5", "ur10", "panda", "z1", "kinova", "xarm7", "iiwa14", "talos_left_arm"];

fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let mut b = codegen::build_script::Builder::new();
    b.specs_in("urdf").math(codegen::MathBackend::Runtime("runtime".into()));
    b.compile().unwrap_or_else(|e| panic!("{e}"));
    let mut list = String::new();
    for m in b.module_names() {
        list.push_str(&format!("pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{m}.rs\")); }}\n"));
    }
    // The same arms with `mul_add` (one instruction where the target has FMA: run.sh builds with
    // RUSTFLAGS="-C target-cpu=native").
    let fma_dir = out.join("fma");
    std::fs::create_dir_all(&fma_dir).unwrap();
    let mut f = codegen::build_script::Builder::new();
    f.math(codegen::MathBackend::Runtime("runtime".into())).fma(true).out_dir(&fma_dir);
    for a in FMA_ARMS {
        f.spec(format!("urdf/{a}.urdf"));
    }
    f.compile().unwrap_or_else(|e| panic!("{e}"));
    list.push_str("pub mod fma {\n");
    for m in f.module_names() {
        list.push_str(&format!("    pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/fma/{m}.rs\")); }}\n"));
    }
    list.push_str("}\n");
    // The same again with every function's joint angles in one `sin_cos_batch` call
    // (`Config::batch_sin_cos`): `robots::batch::NAME`.
    let batch_dir = out.join("batch");
    std::fs::create_dir_all(&batch_dir).unwrap();
    let mut b = codegen::build_script::Builder::new();
    b.math(codegen::MathBackend::Runtime("runtime".into())).fma(true).batch_sin_cos(true).out_dir(&batch_dir);
    for a in FMA_ARMS {
        b.spec(format!("urdf/{a}.urdf"));
    }
    b.compile().unwrap_or_else(|e| panic!("{e}"));
    list.push_str("pub mod batch {\n");
    for m in b.module_names() {
        list.push_str(&format!("    pub mod {m} {{ include!(concat!(env!(\"OUT_DIR\"), \"/batch/{m}.rs\")); }}\n"));
    }
    list.push_str("}\n");
    std::fs::write(out.join("all.rs"), list).unwrap();
}
