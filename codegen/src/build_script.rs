//! Generation from a `build.rs`, in the manner of `prost-build`: name the specs, pick the
//! options, and `include!` the result.
//!
//! ```no_run
//! // In build.rs, inside `fn main()`:
//! codegen::build_script::Builder::new().spec("specs/arm.toml").compile().unwrap_or_else(|e| panic!("{e}"));
//! // Then in src/lib.rs:
//! // pub mod arm { include!(concat!(env!("OUT_DIR"), "/arm.rs")); }
//! ```
//!
//! Every option is a builder method, and every method chains; errors (an unreadable spec or
//! directory, an invalid spec) come from [`Builder::compile`]:
//!
//! ```no_run
//! // build.rs
//! fn main() {
//!     codegen::build_script::Builder::new()
//!         .spec("specs/arm.toml")            // .specs_in(dir) adds a whole directory
//!         .float(codegen::Float::F32)        // default: Float::F64
//!         .compile()                         // math: MathBackend::Libm unless .math(..) says otherwise
//!         .unwrap_or_else(|e| panic!("{e}"));
//! }
//! ```
//!
//! ```no_run
//! codegen::build_script::Builder::new()
//!     .specs_in("specs")
//!     .implement("runtime")
//!     .compile()
//!     .unwrap_or_else(|e| panic!("{e}"));
//! ```
//!
//! The snippets of `README.md` and `docs/firmware.md` are these (`codegen/tests/doc_snippets.rs`
//! checks that they stay so), so `cargo test` compiles them.
//!
//! Each spec `dir/<stem>.toml` (or `.urdf`) becomes `$OUT_DIR/<stem>.rs`; a URDF whose stem is
//! also a TOML spec's becomes `<stem>_urdf.rs`. Files are written only when their content
//! changed, and replaced atomically ([`write_if_changed`]); `cargo:rerun-if-changed` is printed
//! for every spec.

// The docs show a whole `build.rs`, `fn main` included, as users write it.
#![allow(clippy::needless_doctest_main)]

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
    /// A directory of [`Builder::specs_in`] that could not be read: reported by
    /// [`Builder::compile`], so that every builder method chains (path, kind, message).
    unreadable: Option<(PathBuf, std::io::ErrorKind, String)>,
    /// Print the specs' warnings as cargo warnings.
    warnings: bool,
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
            unreadable: None,
            warnings: true,
        }
    }

    /// Add one spec file.
    pub fn spec(&mut self, path: impl AsRef<Path>) -> &mut Self {
        self.specs.push(path.as_ref().to_path_buf());
        self
    }

    /// Add every `.toml` and `.urdf` file of a directory (sorted by name), but not the
    /// `*.scene.toml` scene files (see [`Builder::compile`]). A directory that cannot be read
    /// makes [`Builder::compile`] fail with [`Error::Io`].
    pub fn specs_in(&mut self, dir: impl AsRef<Path>) -> &mut Self {
        let dir = dir.as_ref();
        println!("cargo:rerun-if-changed={}", dir.display());
        match std::fs::read_dir(dir) {
            Ok(rd) => {
                let mut found: Vec<PathBuf> = rd
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| {
                        matches!(
                            p.extension().and_then(|e| e.to_str()),
                            Some("toml" | "urdf")
                        ) && !is_scene_file(p)
                    })
                    .collect();
                found.sort();
                self.specs.extend(found);
            }
            Err(e) => {
                if self.unreadable.is_none() {
                    self.unreadable = Some((dir.to_path_buf(), e.kind(), e.to_string()));
                }
            }
        }
        self
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

    /// Fuse multiply–adds into `mul_add` (`Config::fma`; off by default).
    pub fn fma(&mut self, on: bool) -> &mut Self {
        self.config.fma = on;
        self
    }

    /// Also emit `_lanes` functions of `lanes` states per call (`Config::lanes`; every kind).
    pub fn lanes(&mut self, lanes: Option<usize>) -> &mut Self {
        self.config.lanes = lanes;
        self
    }

    /// `sin` and `cos` of all lanes at once in the `_lanes` functions
    /// (`Config::vector_sin_cos`; off by default).
    pub fn vector_sin_cos(&mut self, on: bool) -> &mut Self {
        self.config.vector_sin_cos = on;
        self
    }

    /// `sin` and `cos` of a scalar function's joint angles in one call
    /// (`Config::batch_sin_cos`; off by default).
    pub fn batch_sin_cos(&mut self, on: bool) -> &mut Self {
        self.config.batch_sin_cos = on;
        self
    }

    /// The lanes' arithmetic through the `wide` crate, named `path` by the including crate
    /// (`Config::wide`; `None` by default).
    pub fn wide(&mut self, path: Option<&str>) -> &mut Self {
        self.config.wide = path.map(str::to_string);
        self
    }

    /// Also implement the runtime's `Dynamics` trait in every module (`Config::implement`):
    /// `runtime` is the path of the nocdyn runtime crate as the including crate names it (e.g.
    /// `"runtime"`). Each module then holds `pub struct Module` and
    /// `impl <runtime>::Dynamics<NX, DOF> for Module`, forwarding to its free functions.
    pub fn implement(&mut self, runtime: impl Into<String>) -> &mut Self {
        self.config.implement = Some(runtime.into());
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
    /// `[scene] snap = tol` does (each change is a warning). `tol` out of (0, 0.01] makes
    /// [`Builder::compile`] fail.
    pub fn snap(&mut self, tol: f64) -> &mut Self {
        self.config.scene.snap = Some(tol);
        self
    }

    /// Leave `functions` out of every module (those a module's kind does not offer are
    /// ignored), on top of each spec's `[scene] functions`.
    pub fn omit(&mut self, functions: &[crate::spec::Function]) -> &mut Self {
        self.config.scene.omit = functions.to_vec();
        self
    }

    /// Print each spec's warnings (e.g. `snap`'s changes, a joint that moves only massless
    /// bodies) as `cargo:warning` lines; on by default.
    pub fn warnings(&mut self, on: bool) -> &mut Self {
        self.warnings = on;
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
        if let Some((dir, kind, msg)) = &self.unreadable {
            return Err(Error::Io(
                dir.clone(),
                std::io::Error::new(*kind, msg.clone()),
            ));
        }
        let mut written = Vec::new();
        for p in &self.specs {
            println!("cargo:rerun-if-changed={}", p.display());
            let bytes = read_spec(p).map_err(|e| Error::Io(p.clone(), e))?;
            // Diagnostics name the spec by its path as given (relative to the crate's root,
            // where cargo runs build scripts), as cargo's own messages do.
            let name = p.to_string_lossy();
            let src = crate::spec::source_text(&name, bytes).map_err(Error::Spec)?;
            // A URDF's `[scene]`, when it has one.
            let mut config = self.config.clone();
            if let Some(beside) = scene_beside(p) {
                println!("cargo:rerun-if-changed={}", beside.display());
                let bytes = read_spec(&beside).map_err(|e| Error::Io(beside.clone(), e))?;
                let side_name = beside.to_string_lossy().into_owned();
                let text = crate::spec::source_text(&side_name, bytes).map_err(Error::Spec)?;
                config.scene.sidecar = Some(crate::spec::SceneFile {
                    name: side_name,
                    text,
                });
            }
            let g = compile(&name, &src, &config).map_err(Error::Spec)?;
            // Warnings (e.g. `snap`'s changes) reach the user as cargo warnings.
            if self.warnings && !g.warnings.is_empty() {
                for line in g.warnings.render().lines() {
                    println!("cargo:warning={line}");
                }
            }
            let path = out.join(format!("{}.rs", module_name(p, &self.specs)));
            write_if_changed(&path, &g.code)?;
            written.push(path);
        }
        Ok(written)
    }
}

/// A URDF's `[scene]` file: `ROBOT.scene.toml` beside `ROBOT.urdf`, when it exists (the CLI,
/// [`Builder`] and the `mechanism!` macro use it alike; docs/scene.md, "A scene for a URDF").
pub fn scene_beside(spec: &Path) -> Option<PathBuf> {
    let urdf = spec
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"));
    let beside = spec.with_extension("scene.toml");
    (urdf && beside.is_file()).then_some(beside)
}

/// `ROBOT.scene.toml`: a URDF's `[scene]`, not a spec.
fn is_scene_file(p: &Path) -> bool {
    p.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.ends_with(".scene.toml"))
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

/// The bytes of a spec file, at most one more than
/// [`MAX_SOURCE_BYTES`](crate::spec::MAX_SOURCE_BYTES) (which
/// [`spec::source_text`](crate::spec::source_text) refuses): an endless or huge file is not
/// read whole. The CLI, [`Builder`] and the `mechanism!` macro read specs so.
pub fn read_spec(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(crate::spec::MAX_SOURCE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Write `content` to `path` unless it already holds exactly that (keeps mtimes, avoids rebuilds).
///
/// The file is replaced atomically: `content` goes to a temporary file in the same directory,
/// which is then renamed over `path` (a symbolic link is followed). A reader, a crash or a full
/// disk never leaves a partial module; on failure the old file stays as it was and the
/// temporary file is removed. An existing file's permissions are kept.
pub fn write_if_changed(path: &Path, content: &str) -> Result<(), Error> {
    use std::io::Write;
    // Compared only when a regular file is there: reading a device (`/dev/zero`) or a FIFO
    // would never end or block.
    if std::fs::metadata(path).is_ok_and(|m| m.is_file())
        && std::fs::read(path).is_ok_and(|old| old == content.as_bytes())
    {
        return Ok(());
    }
    let err = |e: std::io::Error| Error::Io(path.to_path_buf(), e);
    let target = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    // A device, FIFO or socket (`-o /dev/null`, `-o /dev/stdout`) is written into, never
    // replaced: a rename would put a regular file in its place.
    if std::fs::metadata(&target).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .open(&target)
            .map_err(err)?;
        return f.write_all(content.as_bytes()).map_err(err);
    }
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let prefix = match target.file_name() {
        Some(n) => format!(".{}.", n.to_string_lossy()),
        None => ".nocdyn.".into(),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    // As a newly created file would be (the umask applies); tempfile's default is 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut tmp = builder.tempfile_in(dir).map_err(err)?;
    if let Ok(meta) = std::fs::metadata(&target)
        && meta.is_file()
    {
        tmp.as_file()
            .set_permissions(meta.permissions())
            .map_err(err)?;
    }
    tmp.write_all(content.as_bytes()).map_err(err)?;
    tmp.as_file().sync_all().map_err(err)?;
    // On failure the error holds the temporary file, which is removed when dropped.
    tmp.persist(&target).map_err(|e| err(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device that reads forever (`/dev/zero`) is written into without being read first
    /// (the comparison read never ended): the call returns within seconds.
    #[cfg(unix)]
    #[test]
    fn an_endless_device_is_not_read() {
        let zero = Path::new("/dev/zero");
        if !zero.exists() {
            return;
        }
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let _ = tx.send(write_if_changed(zero, "fn f() {}\n").is_ok());
        });
        let ok = rx.recv_timeout(std::time::Duration::from_secs(10));
        assert_eq!(
            ok,
            Ok(true),
            "writing into /dev/zero did not return within 10 s"
        );
    }

    /// `-o /dev/null` writes into the device and leaves it a device (a rename would replace
    /// it with a regular file, and every later reader of `/dev/null` would read what it holds).
    #[cfg(unix)]
    #[test]
    fn a_device_is_written_into_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        let null = Path::new("/dev/null");
        if !std::fs::metadata(null).is_ok_and(|m| m.file_type().is_char_device()) {
            return; // no /dev/null device here to check against
        }
        write_if_changed(null, "pub fn f() {}\n").unwrap();
        let m = std::fs::metadata(null).unwrap();
        assert!(m.file_type().is_char_device(), "/dev/null was replaced");
        assert_eq!(std::fs::read(null).unwrap().len(), 0);
    }

    /// A fresh, empty directory under the system's temporary directory.
    fn scratch(test: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("nocdyn-build-script-{test}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    }

    /// Every method chains: an unreadable directory and an invalid spec are errors of
    /// `compile`, and a spec's diagnostics name it by its path as given.
    #[test]
    fn errors_come_from_compile_and_name_the_path() {
        let dir = scratch("errors");
        let missing = dir.join("no-such-dir");
        let err = Builder::new()
            .specs_in(&missing)
            .out_dir(&dir)
            .compile()
            .unwrap_err();
        assert!(matches!(&err, Error::Io(p, _) if p == &missing), "{err}");
        let specs = dir.join("specs");
        std::fs::create_dir_all(&specs).unwrap();
        std::fs::write(specs.join("arm.toml"), "[mechanism]\nname = 3\n").unwrap();
        let err = Builder::new()
            .specs_in(&specs)
            .out_dir(&dir)
            .compile()
            .unwrap_err();
        let shown = err.to_string();
        let path = specs.join("arm.toml");
        assert!(
            shown.contains(&format!("{}:2:", path.display())),
            "the diagnostic does not name {}:\n{shown}",
            path.display()
        );
    }

    #[test]
    fn replaces_atomically_and_leaves_nothing_behind() {
        let dir = scratch("replace");
        let out = dir.join("m.rs");
        write_if_changed(&out, "one").unwrap();
        write_if_changed(&out, "two").unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "two");
        assert_eq!(listing(&dir), ["m.rs"]);
        // A directory in the way: an error, the directory untouched, no temporary file.
        let sub = dir.join("d.rs");
        std::fs::create_dir(&sub).unwrap();
        assert!(matches!(write_if_changed(&sub, "x"), Err(Error::Io(..))));
        assert!(sub.is_dir());
        assert_eq!(listing(&dir), ["d.rs", "m.rs"]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn keeps_the_permissions_of_the_file_it_replaces() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("permissions");
        let out = dir.join("m.rs");
        std::fs::write(&out, "old").unwrap();
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_if_changed(&out, "new").unwrap();
        let mode = std::fs::metadata(&out).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
