//! The plain-function half of the `mechanism!` proc macro (crate `nocdyn-macros`, in
//! `codegen/macros/`).
//!
//! A proc-macro crate can export nothing but macros, so what the macro does with a spec lives here,
//! where it can be called and tested like any function: find the file, read it, compile it. The
//! macro parses the text [`expand`] returns into its expansion. That text is `compile(..).code`,
//! byte for byte what the CLI prints and [`build_script::Builder`](crate::build_script::Builder)
//! writes for the same spec and options (`codegen/tests/identical.rs` checks all three on every
//! bundled spec).
//!
//! Messages name the spec as the macro's literal wrote it, the way the CLI names it by its
//! argument, so a spec error reads the same in both: `path/to/spec.toml:6:8`, never an absolute
//! path.

use std::path::{Path, PathBuf};

use crate::{Config, compile};

/// The file a `mechanism!("…")` literal names: `spec` relative to `manifest_dir` (the calling
/// crate's `CARGO_MANIFEST_DIR`). An absolute `spec` stands as it is.
pub fn resolve(manifest_dir: &Path, spec: &str) -> PathBuf {
    manifest_dir.join(spec)
}

/// Read the spec [`resolve`]`(manifest_dir, spec)` and generate its module: the items' source
/// text, exactly [`compile`]'s `code`. A URDF's `ROBOT.scene.toml` beside it is its `[scene]`.
///
/// # Errors
///
/// The message a `compile_error!` shows: for an invalid spec (also one that is not UTF-8), its
/// rendered diagnostics ([`Diagnostics::render`](crate::diag::Diagnostics::render), the CLI's
/// stderr); for an unreadable
/// file, `cannot read <spec>: <reason>` (the CLI's message without its `error: ` prefix, which
/// the compiler adds). Warnings are dropped, as [`build_script`](crate::build_script) drops them.
pub fn expand(manifest_dir: &Path, spec: &str, cfg: &Config) -> Result<String, String> {
    let path = resolve(manifest_dir, spec);
    let bytes =
        crate::build_script::read_spec(&path).map_err(|e| format!("cannot read {spec}: {e}"))?;
    let source = crate::spec::source_text(spec, bytes).map_err(|d| d.render())?;
    let mut cfg = cfg.clone();
    if let Some(beside) = crate::build_script::scene_beside(&path) {
        // Named as the spec is: as the literal wrote it.
        let name = Path::new(spec)
            .with_extension("scene.toml")
            .to_string_lossy()
            .into_owned();
        let bytes = crate::build_script::read_spec(&beside)
            .map_err(|e| format!("cannot read {name}: {e}"))?;
        let text = crate::spec::source_text(&name, bytes).map_err(|d| d.render())?;
        cfg.scene.sidecar = Some(crate::spec::SceneFile { name, text });
    }
    compile(spec, &source, &cfg)
        .map(|generated| generated.code)
        .map_err(|diagnostics| diagnostics.render())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest_dir() -> &'static Path {
        Path::new(env!("CARGO_MANIFEST_DIR"))
    }

    #[test]
    fn relative_paths_start_at_the_manifest_dir() {
        let dir = Path::new("/crate");
        assert_eq!(
            resolve(dir, "specs/arm.toml"),
            Path::new("/crate/specs/arm.toml")
        );
        assert_eq!(resolve(dir, "/abs/arm.toml"), Path::new("/abs/arm.toml"));
    }

    #[test]
    fn a_missing_file_is_named_as_written() {
        let e = expand(manifest_dir(), "no/such/spec.toml", &Config::default()).unwrap_err();
        assert!(e.starts_with("cannot read no/such/spec.toml: "), "{e}");
    }

    #[test]
    fn a_bad_spec_renders_with_its_location() {
        let e = expand(
            manifest_dir(),
            "tests/data/bad/negative_mass.toml",
            &Config::default(),
        )
        .unwrap_err();
        assert!(e.starts_with("error: negative mass -1.5\n"), "{e}");
        assert!(
            e.contains("--> tests/data/bad/negative_mass.toml:6:8"),
            "{e}"
        );
    }
}
