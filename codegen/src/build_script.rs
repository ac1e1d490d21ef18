//! Generation from a `build.rs`, in the manner of `prost-build`: name the specs, pick the
//! options, and `include!` the result.
//!
//! ```no_run
//! // In build.rs, inside `fn main()`:
//! codegen::build_script::Builder::new()
//!     .spec("specs/arm.toml")
//!     .compile()
//!     .unwrap_or_else(|e| panic!("{e}"));
//! // Then in src/lib.rs:
//! // pub mod arm { include!(concat!(env!("OUT_DIR"), "/arm.rs")); }
//! ```
//!
//! Each spec `dir/<stem>.toml` (or `.urdf`) becomes `$OUT_DIR/<stem>.rs`; a URDF whose stem is
//! also a TOML spec's becomes `<stem>_urdf.rs`. Files are written only when their content
//! changed, and `cargo:rerun-if-changed` is printed for every spec.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::{Config, MathBackend, compile};

/// Why a build-script generation failed.
#[derive(Debug)]
pub enum Error {
    /// Reading a spec or writing an output failed.
    Io(PathBuf, std::io::Error),
    /// A spec is invalid: the rendered diagnostics.
    Spec(crate::diag::Diagnostics),
    /// No output directory: neither `out_dir` nor `$OUT_DIR` is set.
    NoOutDir,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io(p, e) => write!(f, "{}: {e}", p.display()),
            Error::Spec(d) => write!(f, "{d}"),
            Error::NoOutDir => write!(
                f,
                "no output directory (set `out_dir` or run from build.rs)"
            ),
        }
    }
}

impl std::error::Error for Error {}

/// Generation options for build scripts.
#[derive(Clone, Debug)]
pub struct Builder {
    specs: Vec<PathBuf>,
    out_dir: Option<PathBuf>,
    config: Config,
}

impl Default for Builder {
    fn default() -> Self {
        Self::new()
    }
}

impl Builder {
    /// No specs yet; math through `libm`; output to `$OUT_DIR`.
    pub fn new() -> Self {
        Builder {
            specs: Vec::new(),
            out_dir: None,
            config: Config::default(),
        }
    }

    /// Add one spec file.
    pub fn spec(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.specs.push(path.as_ref().to_path_buf());
        self
    }

    /// Add every `.toml` and `.urdf` file of a directory (sorted by name).
    pub fn specs_in(&mut self, dir: impl AsRef<Path>) -> Result<&mut Self, Error> {
        let dir = dir.as_ref();
        let rd = std::fs::read_dir(dir).map_err(|e| Error::Io(dir.to_path_buf(), e))?;
        let mut found: Vec<PathBuf> = rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                matches!(
                    p.extension().and_then(|e| e.to_str()),
                    Some("toml" | "urdf")
                )
            })
            .collect();
        found.sort();
        self.specs.extend(found);
        println!("cargo:rerun-if-changed={}", dir.display());
        Ok(self)
    }

    /// Output directory (default `$OUT_DIR`).
    pub fn out_dir(&mut self, dir: impl AsRef<Path>) -> &mut Self {
        self.out_dir = Some(dir.as_ref().to_path_buf());
        self
    }

    /// Math backend of the generated code.
    pub fn math(&mut self, math: MathBackend) -> &mut Self {
        self.config.math = math;
        self
    }

    /// The scalar type of the generated code (`f64` by default).
    pub fn float(&mut self, float: crate::Float) -> &mut Self {
        self.config.float = float;
        self
    }

    /// Apply the joints' friction (`damping`, `friction`; URDF `<dynamics>`) in every spec, as
    /// `[scene] friction = true` does.
    pub fn friction(&mut self, on: bool) -> &mut Self {
        self.config.scene.friction = on;
        self
    }

    /// Apply the joints' reflected rotor inertia (`armature`) in every spec, as
    /// `[scene] rotor_inertia = true` does.
    pub fn rotor_inertia(&mut self, on: bool) -> &mut Self {
        self.config.scene.rotor_inertia = on;
        self
    }

    /// Take near-exact angles and offsets as exact within `tol` in every spec, as
    /// `[scene] snap = tol` does (each change is a warning).
    pub fn snap(&mut self, tol: f64) -> &mut Self {
        self.config.scene.snap = Some(tol);
        self
    }

    /// Module name of each spec (see the module docs), in the order added.
    pub fn module_names(&self) -> Vec<String> {
        self.specs
            .iter()
            .map(|p| module_name(p, &self.specs))
            .collect()
    }

    /// Generate every spec; write `<module>.rs` files into the output directory.
    pub fn compile(&self) -> Result<Vec<PathBuf>, Error> {
        let out = match &self.out_dir {
            Some(d) => d.clone(),
            None => std::env::var_os("OUT_DIR")
                .map(PathBuf::from)
                .ok_or(Error::NoOutDir)?,
        };
        let mut written = Vec::new();
        for p in &self.specs {
            println!("cargo:rerun-if-changed={}", p.display());
            let bytes = std::fs::read(p).map_err(|e| Error::Io(p.clone(), e))?;
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("spec");
            let src = crate::spec::source_text(name, bytes).map_err(Error::Spec)?;
            let g = compile(name, &src, &self.config).map_err(Error::Spec)?;
            let path = out.join(format!("{}.rs", module_name(p, &self.specs)));
            write_if_changed(&path, &g.code)?;
            written.push(path);
        }
        Ok(written)
    }
}

fn module_name(p: &Path, all: &[PathBuf]) -> String {
    let stem = p
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("spec")
        .replace(['-', '.'], "_");
    let is_urdf = p.extension().and_then(|e| e.to_str()) == Some("urdf");
    let toml_twin = all.iter().any(|o| {
        o.extension().and_then(|e| e.to_str()) == Some("toml") && o.file_stem() == p.file_stem()
    });
    if is_urdf && toml_twin {
        format!("{stem}_urdf")
    } else {
        stem
    }
}

/// Write `content` to `path` unless it already holds exactly that (keeps mtimes, avoids rebuilds).
pub fn write_if_changed(path: &Path, content: &str) -> Result<(), Error> {
    if std::fs::read_to_string(path)
        .map(|old| old == content)
        .unwrap_or(false)
    {
        return Ok(());
    }
    std::fs::write(path, content).map_err(|e| Error::Io(path.to_path_buf(), e))
}
