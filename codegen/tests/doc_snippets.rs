//! The `build.rs` snippets of the README and `docs/firmware.md` are compiled by `cargo test`:
//! each of their code lines is a line of a doctest in `codegen/src/build_script.rs` (which
//! `cargo test` compiles), so a snippet that stops compiling fails there, and one that drifts
//! from the doctests fails here.

use std::path::Path;

/// The lines of the ```rust blocks of `text` that use the build-script `Builder`: the
/// `fn main` line and the builder's chain (`codegen::…` and `.method(…)` lines), trimmed.
fn builder_lines(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut block: Option<Vec<&str>> = None;
    for line in text.lines() {
        match (&mut block, line.trim_start()) {
            (None, l) if l.starts_with("```rust") => block = Some(Vec::new()),
            (Some(b), "```") => {
                if b.iter().any(|l| l.contains("build_script::Builder")) {
                    out.extend(
                        b.iter()
                            .map(|l| l.trim())
                            .filter(|l| {
                                l.starts_with("codegen::")
                                    || l.starts_with('.')
                                    || l.starts_with("fn main")
                            })
                            .map(str::to_string),
                    );
                }
                block = None;
            }
            (Some(b), _) => b.push(line),
            (None, _) => {}
        }
    }
    out
}

#[test]
fn build_script_snippets_are_doctests() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let doc = std::fs::read_to_string(root.join("codegen/src/build_script.rs")).unwrap();
    let doctest: Vec<&str> = doc
        .lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .map(str::trim)
        .collect();
    let mut checked = 0;
    for file in ["README.md", "docs/firmware.md"] {
        let text = std::fs::read_to_string(root.join(file)).unwrap();
        let lines = builder_lines(&text);
        assert!(!lines.is_empty(), "{file}: no build.rs snippet found");
        for l in lines {
            assert!(
                doctest.contains(&l.as_str()),
                "{file}: `{l}` is not in the doctests of codegen/src/build_script.rs"
            );
            checked += 1;
        }
    }
    assert!(checked >= 6);
}
