//! Compile-fail tests: a bad spec is a `compile_error!` at the literal with the CLI's rendered
//! diagnostic (file:line:column, key, hint). Each case is a file in `tests/ui/`, its expected
//! compiler output beside it (`.stderr`; regenerate with `TRYBUILD=overwrite`, then read them).
//!
//! trybuild compiles the cases in a crate of its own, at
//! `<target dir>/tests/trybuild/nocdyn-macros-ui`, and that crate's `CARGO_MANIFEST_DIR` is what
//! `mechanism!` resolves paths against. The bad specs are therefore copied to `tests/ui/` there
//! first, so that a case's path (`"tests/ui/negative_mass.toml"`) names the same file from this
//! crate and from trybuild's.
//!
//! Cost: trybuild builds the macro and its dependencies (codegen, nalgebra, syn, …) once more in
//! that directory, for the host only: this crate depends on the macro alone, so the cases' side
//! builds nothing but them (from `codegen/macros` itself, trybuild also built the macro's
//! dependencies a second time, for the cases). The cases themselves take a second.

use std::path::{Path, PathBuf};

#[test]
fn bad_specs_are_compile_errors() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ui");
    // CARGO_TARGET_TMPDIR is `<target dir>/tmp`; trybuild works in `<target dir>/tests/trybuild`.
    let target = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("CARGO_TARGET_TMPDIR is inside the target dir");
    let there = target.join("tests/trybuild/nocdyn-macros-ui/tests/ui");
    std::fs::create_dir_all(&there).expect("trybuild's project dir");
    let specs: Vec<PathBuf> = std::fs::read_dir(&here)
        .expect("tests/ui")
        .map(|e| e.expect("tests/ui entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml" || e == "urdf"))
        .collect();
    assert!(!specs.is_empty(), "no bad specs in {}", here.display());
    for spec in specs {
        let name = spec.file_name().expect("a file name");
        std::fs::copy(&spec, there.join(name)).expect("copy a bad spec");
    }
    trybuild::TestCases::new().compile_fail("tests/ui/*.rs");
}
