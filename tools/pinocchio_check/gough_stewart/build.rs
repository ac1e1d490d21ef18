//! Generates the Gough-Stewart modules that `src/main.rs` compares with Pinocchio: the bundled
//! spec and its full-inertia variant (`specs/{bundled,full}/gough_stewart.toml`, written by
//! gen.py), each plain and with `fma` (`mul_add`), into `$OUT_DIR/{bundled,full}/{plain,fma}/`.
//!
//! Only `inverse_dynamics` is compiled (with the always-emitted kinematics): the whole module
//! (70,000 lines with the derivatives) would take minutes to compile. So that this is still the
//! bundled module's `inverse_dynamics`, the whole module is also generated (not compiled) and its
//! `inverse_dynamics`, kernel `id_parts` and `lu_solve_t` must be the same text.
use codegen::spec::Function;

fn item(src: &str, head: &str) -> String {
    let start = src
        .find(head)
        .unwrap_or_else(|| panic!("no `{head}` in a generated module"));
    let rest = &src[start..];
    let end = rest.find("\n}\n").expect("end of item") + 3;
    rest[..end].to_string()
}

fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let keep = [Function::InverseDynamics];
    let omit: Vec<Function> = Function::ALL
        .iter()
        .copied()
        .filter(|f| !keep.contains(f))
        .collect();
    let mut list = String::new();
    for variant in ["bundled", "full"] {
        let spec = format!("specs/{variant}/gough_stewart.toml");
        list.push_str(&format!("pub mod {variant} {{\n"));
        for fma in [false, true] {
            let kind = if fma { "fma" } else { "plain" };
            let dir = out.join(variant).join(kind);
            std::fs::create_dir_all(&dir).unwrap();
            let mut b = codegen::build_script::Builder::new();
            b.spec(&spec)
                .math(codegen::MathBackend::Runtime("runtime".into()))
                .fma(fma)
                .omit(&omit)
                .out_dir(&dir);
            b.compile().unwrap_or_else(|e| panic!("{e}"));
            // The whole module, for the check above (not compiled).
            let whole = out.join("whole").join(variant).join(kind);
            std::fs::create_dir_all(&whole).unwrap();
            let mut w = codegen::build_script::Builder::new();
            w.spec(&spec)
                .math(codegen::MathBackend::Runtime("runtime".into()))
                .fma(fma)
                .out_dir(&whole);
            w.compile().unwrap_or_else(|e| panic!("{e}"));
            let a = std::fs::read_to_string(dir.join("gough_stewart.rs")).unwrap();
            let c = std::fs::read_to_string(whole.join("gough_stewart.rs")).unwrap();
            for head in ["pub fn inverse_dynamics(", "fn id_parts(", "fn lu_solve_t("] {
                assert_eq!(
                    item(&a, head),
                    item(&c, head),
                    "{variant} {kind}: `{head}` differs from the whole module's"
                );
            }
            // The whole module's operation-count header, for the report.
            let header: String = c
                .lines()
                .take_while(|l| l.starts_with("//"))
                .map(|l| format!("{l}\n"))
                .collect();
            std::fs::write(dir.join("header.txt"), header).unwrap();
            list.push_str(&format!(
                "    pub mod {kind} {{ include!(concat!(env!(\"OUT_DIR\"), \"/{variant}/{kind}/gough_stewart.rs\")); \
                 pub const HEADER: &str = include_str!(concat!(env!(\"OUT_DIR\"), \"/{variant}/{kind}/header.txt\")); }}\n"
            ));
        }
        list.push_str("}\n");
    }
    std::fs::write(out.join("all.rs"), list).unwrap();
}
