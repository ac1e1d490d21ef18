//! The generated-code template of the dynamic performance indices (`codegen::indices`, the
//! file `codegen/templates/inertia_indices.rs` specialized): it renders to valid Rust (syn) for
//! every math backend and precision, inside a module that defines `DOF`, with the runtime's
//! tolerances. The template file itself is compiled for several `DOF`s and compared with
//! `runtime::indices` by `tests/tests/indices.rs`.

use codegen::{Config, MathBackend};

fn render(cfg: &Config) -> String {
    let tokens = codegen::indices::template(cfg);
    let file: syn::File = syn::parse2(tokens).expect("the template parses as items");
    prettyplease::unparse(&file)
}

#[test]
fn renders_valid_rust_for_every_backend() {
    for math in [
        MathBackend::Libm,
        MathBackend::Std,
        MathBackend::Runtime("runtime".into()),
        MathBackend::Runtime("::nocdyn_runtime".into()),
    ] {
        let cfg = Config {
            math: math.clone(),
            ..Config::default()
        };
        let text = render(&cfg);
        // Inside a module with DOF, as a generated module would have it.
        let module = format!("pub mod m {{ pub const DOF: usize = 3; {text} }}");
        syn::parse_file(&module).unwrap_or_else(|e| panic!("{math:?}: {e}"));
        assert!(text.contains("pub fn inertia_indices(m: &[[f64; DOF]; DOF])"));
        assert!(text.contains("pub struct InertiaIndices"));
        assert!(text.contains("pub enum IndexError"));
        let sqrt = match &math {
            MathBackend::Libm => "libm::sqrt(",
            MathBackend::Std => "f64::sqrt(",
            MathBackend::Runtime(p) if p == "runtime" => "runtime::math::sqrt(",
            MathBackend::Runtime(_) => "::nocdyn_runtime::math::sqrt(",
        };
        assert_eq!(text.matches(sqrt).count(), 3, "{math:?}");
        // No heap, no std beyond the math backend, no panicking macros.
        for bad in [
            "Vec", "Box", "vec!", "String", "panic!", "unwrap", "expect(", "assert", "std::",
        ] {
            let hit = text.replace("f64::sqrt", "").contains(bad);
            assert!(!hit, "{math:?}: the template uses `{bad}`");
        }
    }
}

#[test]
fn tolerances_are_the_runtime_ones() {
    let text = render(&Config::default());
    let value = |name: &str| -> f64 {
        let key = format!("pub const {name}: f64 = ");
        let start = text.find(&key).unwrap_or_else(|| panic!("{name} missing")) + key.len();
        let end = start + text[start..].find(';').unwrap();
        text[start..end].parse().unwrap()
    };
    assert_eq!(
        value("INDEX_SYMMETRY_TOLERANCE"),
        runtime::indices::SYMMETRY_TOLERANCE
    );
    assert_eq!(
        value("INDEX_DEFINITENESS_TOLERANCE"),
        runtime::indices::DEFINITENESS_TOLERANCE
    );
}
