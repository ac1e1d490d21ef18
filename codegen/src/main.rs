//! `codegen`: the command-line adapter over [`codegen::compile`], plus the workspace tools of
//! `docs/indices.md`.
//!
//! ```text
//! cargo run -p codegen -- SPEC.(toml|urdf) [-o OUT.rs] [--check] [--stats] [--math libm|std|runtime]
//! cargo run -p codegen -- map SPEC --index dci|dci2|cond|gie|manip|iso [--axes A,B] [--range LO:HI[,LO:HI]] [--steps N[,M]] [-o PREFIX]
//! cargo run -p codegen -- isotropy SPEC [--samples N] [--seed S] [--design NAME=LO:HI]
//! cargo run -p codegen -- draw SPEC [-o home.svg]
//! cargo run -p codegen -- excite SPEC [--harmonics 5] [--period 10] [--samples N] [--seed S] [--q-max RAD] [--qd-max RAD/S] [--with-tau] [-o traj.csv]
//! cargo run -p codegen -- identify SPEC data.csv [--out updated.toml] [--plot efforts.svg] [--weights auto|none] [--cutoff HZ] [--estimates est.csv]
//! ```
//! `excite` and `identify` work on trees (docs/identification.md).
//! Exit codes: 0 success, 2 invalid spec (also one that is not UTF-8) or arguments (diagnostics
//! on stderr, nothing written), 1 I/O error. A spec file literally named like a subcommand (`map`,
//! `identify`, …) must be written `./map`.

/// `print!`/`println!` to standard output that never panics: when the reader has gone
/// (`codegen spec.toml | head`), the process ends quietly with exit code 0, as the output was
/// only cut short by its reader; any other write error is reported, exit code 1.
macro_rules! out {
    ($($t:tt)*) => { $crate::write_stdout(format_args!($($t)*), false) };
}
macro_rules! outln {
    ($($t:tt)*) => { $crate::write_stdout(format_args!($($t)*), true) };
}

mod cli;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use codegen::{Config, MathBackend};

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Math {
    /// The `libm` crate: `no_std`, bit-identical everywhere (default).
    Libm,
    /// std's `f64::sin_cos` (hosts only).
    Std,
    /// `runtime::math` of the nocdyn runtime crate.
    Runtime,
}

/// Generate flat, allocation-free Rust dynamics code from a mechanism spec.
#[derive(Debug, Parser)]
#[command(
    name = "codegen",
    version,
    about,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true,
    allow_negative_numbers = true
)]
struct Cli {
    /// Workspace tools (dynamic performance indices); without one, generate code.
    #[command(subcommand)]
    command: Option<Command>,
    /// Mechanism spec: `.toml` (nocdyn spec) or `.urdf`.
    #[arg(required = true)]
    spec: Option<PathBuf>,
    /// Write the module here (default: standard output); with `--emit c`, the directory of the
    /// C wrapper crate (required).
    #[arg(short, long, value_name = "OUT.rs|DIR")]
    output: Option<PathBuf>,
    /// What to write: the Rust module (`rust`), or a crate for C and C++ firmware (`c`): in the
    /// `-o` directory, `Cargo.toml` (a `no_std` `staticlib`), `src/` (the module and one
    /// `extern "C"` function per public function, status codes for failures) and
    /// `include/NAME.h`. `cargo build --release` there gives `target/release/libNAME_c.a`;
    /// link it with `-lm` (docs/firmware.md, "From C").
    #[arg(long, value_enum, default_value = "rust")]
    emit: EmitArg,
    /// Validate the spec only; generate nothing.
    #[arg(long)]
    check: bool,
    /// Also print the operation-count table, to standard error.
    #[arg(long)]
    stats: bool,
    /// Where sin/cos and sqrt come from.
    #[arg(long, value_enum, default_value = "libm")]
    math: Math,
    /// Crate path of the runtime for `--math runtime` and `--implement`.
    #[arg(long, default_value = "runtime", value_name = "PATH")]
    runtime_path: String,
    /// Also emit `pub struct Module` implementing the runtime's `Dynamics` trait
    /// (`<runtime-path>::Dynamics`: the same methods for every kind of mechanism, for code
    /// written once over many modules).
    #[arg(long)]
    implement: bool,
    /// Scalar type of the generated code (`f32`: single precision, thresholds rescaled).
    #[arg(long, value_enum, default_value = "f64")]
    float: FloatArg,
    /// Fuse `a*b ± c` into `mul_add` (one rounding; an `fma` column in the op counts). Pays
    /// where the target has FMA (`-C target-cpu=native`).
    #[arg(long)]
    fma: bool,
    /// Also emit `<function>_lanes` of the dynamics functions, evaluating N states per call
    /// (`4` fills an AVX2 register in `f64`, `8` in `f32`).
    #[arg(long, value_name = "N", value_parser = lane_count)]
    lanes: Option<usize>,
    /// With `--lanes`: `sin` and `cos` of all lanes at once by a polynomial that vectorizes
    /// (within 2 ulp; no longer bit for bit the scalar functions).
    #[arg(long, requires = "lanes")]
    vector_sin_cos: bool,
    /// The scalar functions take `sin` and `cos` of their joint angles in one call, by the
    /// same polynomial over them as one array (within 2 ulp of the backend's). Pays with AVX2
    /// or wider (`-C target-cpu=native`); slower than the backend's calls on x86-64's baseline.
    #[arg(long)]
    batch_sin_cos: bool,
    /// With `--lanes`: the lanes' arithmetic through the `wide` crate's vector types (explicit
    /// SIMD in safe code; the including crate depends on `wide` 1). Still bit for bit.
    #[arg(long, requires = "lanes")]
    wide: bool,
    /// Apply the joints' viscous and Coulomb friction (as `[scene] friction = true`; for a URDF,
    /// its `<dynamics damping friction>`).
    #[arg(long)]
    friction: bool,
    /// Apply the joints' reflected rotor inertia (as `[scene] rotor_inertia = true`).
    #[arg(long)]
    rotor_inertia: bool,
    /// Take angles within TOL (rad) of a multiple of π/2, rotation entries within TOL of 0/±1
    /// and offsets within TOL (m) of 0 as exact, listing each change (as `[scene] snap`).
    #[arg(long, value_name = "TOL", value_parser = snap_tolerance, allow_negative_numbers = true)]
    snap: Option<f64>,
    /// A `[scene]` for a spec that has none (a URDF): a TOML file with a `[scene]` table.
    /// Without it, `ROBOT.scene.toml` beside `ROBOT.urdf` is used when it exists.
    #[arg(long, value_name = "SCENE.toml")]
    scene: Option<PathBuf>,
}

/// `--snap`: the bounds of `[scene] snap`.
fn snap_tolerance(s: &str) -> Result<f64, String> {
    let tol: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if codegen::spec::is_snap_tolerance(tol) {
        Ok(tol)
    } else {
        Err(format!(
            "the tolerance must be in (0, {}] (as `[scene] snap`)",
            codegen::spec::MAX_SNAP
        ))
    }
}

/// `--lanes`: 2 to [`codegen::lanes::MAX`] states per call.
fn lane_count(s: &str) -> Result<usize, String> {
    let range = 2..=codegen::lanes::MAX;
    match s.trim().parse::<usize>() {
        Ok(n) if range.contains(&n) => Ok(n),
        _ => Err(format!(
            "the states per call must be a whole number from 2 to {}",
            codegen::lanes::MAX
        )),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum EmitArg {
    /// The Rust module (default).
    Rust,
    /// A C header and a Rust `staticlib` crate wrapping the module (needs `-o DIR`).
    C,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum FloatArg {
    /// Double precision (default).
    F64,
    /// Single precision.
    F32,
}

/// The subcommands (`docs/indices.md`).
#[derive(Debug, Subcommand)]
enum Command {
    /// Map a dynamic performance index over a 2-D slice of the workspace (CSV + SVG heat map).
    Map(cli::map::MapArgs),
    /// Search the workspace for dynamically isotropic points (`M = σ·1`).
    Isotropy(cli::isotropy::IsotropyArgs),
    /// The cheapest fidelity (point-mass or massless bodies) within an effort tolerance.
    Reduce(cli::reduce::ReduceArgs),
    /// Write the corrections made at home (loops left a little open by rounded numbers) into
    /// the spec.
    FixHome(cli::fix_home::FixHomeArgs),
    /// Draw the home pose in three orthographic views (SVG): joints by kind, actuated joints
    /// and loop cuts highlighted.
    Draw(cli::draw::DrawArgs),
    /// Identify a tree's base parameters from measured motions and efforts (weighted least
    /// squares), and write the spec updated to them (docs/identification.md).
    Identify(cli::identify::IdentifyArgs),
    /// Design an exciting trajectory for identification (finite Fourier series within joint
    /// bounds, minimizing the base regressor's condition number), written as CSV.
    Excite(cli::excite::ExciteArgs),
    /// A URDF as a TOML spec that generates the same module (for a `[scene]`, `reduce`, …).
    #[cfg(feature = "urdf")]
    Convert(cli::convert::ConvertArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Some(Command::Map(args)) => return cli::map::run(&args),
        Some(Command::Isotropy(args)) => return cli::isotropy::run(&args),
        Some(Command::Reduce(args)) => return cli::reduce::run(&args),
        Some(Command::FixHome(args)) => return cli::fix_home::run(&args),
        Some(Command::Draw(args)) => return cli::draw::run(&args),
        Some(Command::Identify(args)) => return cli::identify::run(&args),
        Some(Command::Excite(args)) => return cli::excite::run(&args),
        #[cfg(feature = "urdf")]
        Some(Command::Convert(args)) => return cli::convert::run(&args),
        None => {}
    }
    // `required = true` makes clap reject a missing spec when there is no subcommand.
    let Some(spec) = cli.spec.as_ref() else {
        eprintln!("error: a spec file is required");
        return ExitCode::from(2);
    };
    let (name, source) = match cli::read_spec(spec) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let sidecar = match cli::sidecar(spec, cli.scene.as_deref()) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if cli.check {
        let overrides = codegen::spec::SceneOverrides {
            sidecar: sidecar.clone(),
            ..Default::default()
        };
        return match codegen::spec::load(&name, &source, &overrides)
            .map(|l| (l.mechanism, l.warnings))
        {
            Ok((mechanism, warnings)) => {
                if !warnings.is_empty() {
                    eprint!("{}", warnings.render());
                }
                let count =
                    |n: usize, noun: &str| format!("{n} {noun}{}", if n == 1 { "" } else { "s" });
                match mechanism {
                    codegen::spec::Mechanism::Tree(model) => {
                        eprintln!("{}: ok ({})", name, count(model.dof(), "joint"))
                    }
                    codegen::spec::Mechanism::Parallel(model) => eprintln!(
                        "{}: ok (parallel, {}, {} DOF)",
                        name,
                        count(model.legs.len(), "leg"),
                        model.dof()
                    ),
                    codegen::spec::Mechanism::Closed(model) => eprintln!(
                        "{}: ok (closed loops, {}, {}, {} DOF)",
                        name,
                        count(model.nx(), "joint coordinate"),
                        count(model.cuts.len(), "cut joint"),
                        model.dof()
                    ),
                }
                ExitCode::SUCCESS
            }
            Err(d) => {
                eprint!("{}", d.render());
                ExitCode::from(2)
            }
        };
    }
    if (cli.implement || matches!(cli.math, Math::Runtime))
        && syn::parse_str::<syn::Path>(&cli.runtime_path).is_err()
    {
        eprintln!(
            "error: --runtime-path {:?} is not a Rust path (e.g. `runtime` or `::nocdyn_runtime`)",
            cli.runtime_path
        );
        return ExitCode::from(2);
    }
    if let Some(lanes) = cli.lanes
        && cli.emit == EmitArg::C
    {
        eprintln!("error: --lanes {lanes}: the C wrapper crate (--emit c) takes no lanes");
        return ExitCode::from(2);
    }
    if cli.emit == EmitArg::C {
        if cli.output.is_none() {
            eprintln!("error: --emit c writes a crate: give its directory with -o DIR");
            return ExitCode::from(2);
        }
        if cli.implement || !matches!(cli.math, Math::Libm) {
            eprintln!("error: --emit c takes the default math backend (libm) and no --implement");
            return ExitCode::from(2);
        }
    }
    // `-o` onto the spec or its scene file would replace the input with the module (exit 2,
    // before any work, as every tool's outputs; docs/usage.md). `--emit c`'s `-o` is a
    // directory, created new.
    if cli.emit == EmitArg::Rust {
        let scene = cli
            .scene
            .clone()
            .or_else(|| codegen::build_script::scene_beside(spec));
        let inputs = cli::spec_inputs(spec, scene.as_deref());
        if let Err(code) = cli::distinct_outputs(&inputs, &[("-o", cli.output.as_deref())]) {
            return code;
        }
    }
    let math = match cli.math {
        Math::Libm => MathBackend::Libm,
        Math::Std => MathBackend::Std,
        Math::Runtime => MathBackend::Runtime(cli.runtime_path.clone()),
    };
    let out = match codegen::compile(
        &name,
        &source,
        &Config {
            math,
            float: match cli.float {
                FloatArg::F64 => codegen::Float::F64,
                FloatArg::F32 => codegen::Float::F32,
            },
            scene: codegen::spec::SceneOverrides {
                friction: cli.friction,
                rotor_inertia: cli.rotor_inertia,
                snap: cli.snap,
                sidecar: sidecar.clone(),
                omit: Vec::new(),
            },
            implement: cli.implement.then(|| cli.runtime_path.clone()),
            emit: match cli.emit {
                EmitArg::Rust => codegen::Emit::Rust,
                EmitArg::C => codegen::Emit::C,
            },
            fma: cli.fma,
            lanes: cli.lanes,
            vector_sin_cos: cli.vector_sin_cos,
            batch_sin_cos: cli.batch_sin_cos,
            wide: cli.wide.then(|| "wide".to_string()),
        },
    ) {
        Ok(o) => o,
        Err(d) => {
            eprint!("{}", d.render());
            return ExitCode::from(2);
        }
    };
    if !out.warnings.is_empty() {
        eprint!("{}", out.warnings.render());
    }
    if cli.fma && matches!(cli.math, Math::Libm) {
        eprintln!("{FMA_LIBM_NOTE}");
    }
    if cli.snap.is_none()
        && let Some(note) = snap_note(&name, &source, &cfg_for_snap(&cli, sidecar), &out)
    {
        eprintln!("{note}");
    }
    // The table goes to stderr: the module always goes where it would without `--stats`.
    if cli.stats {
        eprintln!("{}", out.stats_table().join("\n"));
    }
    if let (Some(c), Some(dir)) = (&out.c_crate, &cli.output) {
        // `-o` naming a file, not a directory: said so (it failed at `FILE/Cargo.toml: File
        // exists`, QA).
        if dir.exists() && !dir.is_dir() {
            eprintln!(
                "error: -o {}: --emit c writes a crate into a directory, and this is a file: give a directory (nothing written)",
                dir.display()
            );
            return ExitCode::from(1);
        }
        // Into an existing directory, only over files codegen wrote: `-o .` in a crate of
        // one's own replaced its `Cargo.toml` and `src/lib.rs`, exit 0 (QA).
        for (rel, _) in &c.files {
            let path = dir.join(rel);
            let own = std::fs::read(&path).ok().is_some_and(|b| {
                let first = b.split(|&c| c == b'\n').next().unwrap_or(&[]);
                !String::from_utf8_lossy(first).contains("@generated by nocdyn")
            });
            if own {
                eprintln!(
                    "error: -o {}: {} is not a file codegen wrote, which the C crate would overwrite: give a new directory (nothing written)",
                    dir.display(),
                    path.display()
                );
                return ExitCode::from(2);
            }
        }
        for (rel, text) in &c.files {
            let path = dir.join(rel);
            let written = path
                .parent()
                .map_or(Ok(()), std::fs::create_dir_all)
                .map_err(|e| format!("{}: {e}", path.display()))
                .and_then(|()| {
                    codegen::build_script::write_if_changed(&path, text).map_err(|e| e.to_string())
                });
            if let Err(e) = written {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        return ExitCode::SUCCESS;
    }
    let text = out.code;
    match &cli.output {
        Some(path) => {
            if let Err(e) = cli::write_output(path, &text) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        None => out!("{text}"),
    }
    ExitCode::SUCCESS
}

/// What `--fma` with the default `libm` backend costs on x86 (docs/performance.md, "Fused
/// multiply–add"): the module is right, but `libm::fma` is no instruction there.
const FMA_LIBM_NOTE: &str = "note: with `--math libm` (the default) each fused multiply-add is a call of `libm::fma`, which on x86 chooses the FMA instruction or a software fallback at run time through a function pointer, even with `-C target-cpu=native`: there the fused module is about twice as slow as the unfused one (PUMA 560: inverse dynamics 2.2x, mass matrix 1.8x). Take `--math runtime` (with or without the runtime's `std` feature) or, on a host, `--math std`, where `mul_add` is one instruction; see docs/performance.md, \"Fused multiply-add\".";

/// The tolerance `snap_note` tries: four or five digits, as published files round π/2.
const SUGGESTED_SNAP: f64 = 1e-4;

/// The generation options of `cli` with `--snap` at [`SUGGESTED_SNAP`].
fn cfg_for_snap(cli: &Cli, sidecar: Option<codegen::spec::SceneFile>) -> Config {
    Config {
        math: MathBackend::Libm,
        float: match cli.float {
            FloatArg::F64 => codegen::Float::F64,
            FloatArg::F32 => codegen::Float::F32,
        },
        scene: codegen::spec::SceneOverrides {
            friction: cli.friction,
            rotor_inertia: cli.rotor_inertia,
            snap: Some(SUGGESTED_SNAP),
            sidecar,
            omit: Vec::new(),
        },
        implement: None,
        emit: codegen::Emit::Rust,
        fma: cli.fma,
        lanes: None,
        vector_sin_cos: false,
        batch_sin_cos: cli.batch_sin_cos,
        wide: None,
    }
}

/// A note when the spec has angles or offsets within [`SUGGESTED_SNAP`] of exact values that
/// it does not snap (a URDF's `1.5708`), with the flops `--snap` would save; `None` when
/// snapping changes nothing (the spec is loaded first: generating again only then).
fn snap_note(
    name: &str,
    source: &str,
    snapped: &Config,
    out: &codegen::Generated,
) -> Option<String> {
    let plain = codegen::spec::load(
        name,
        source,
        &codegen::spec::SceneOverrides {
            snap: None,
            ..snapped.scene.clone()
        },
    )
    .ok()?;
    let with = codegen::spec::load(name, source, &snapped.scene).ok()?;
    let changes = with.warnings.len().saturating_sub(plain.warnings.len());
    if changes == 0 {
        return None;
    }
    let g = codegen::compile(name, source, snapped).ok()?;
    let (f, before) = out
        .stats
        .iter()
        .find(|(n, _)| n == "inverse_dynamics")
        .or_else(|| out.stats.first())?;
    let after = g.stats.iter().find(|(n, _)| n == f)?.1.flops();
    let before = before.flops();
    (after < before).then(|| {
        format!(
            "note: {changes} value{} within {SUGGESTED_SNAP:e} of exact angles or offsets (as published files round π/2); `--snap {SUGGESTED_SNAP:e}` takes them as exact, with a warning for each: {f} {before} → {after} flops (docs/scene.md, \"Snapping\")",
            if changes == 1 { " is" } else { "s are" }
        )
    })
}

/// Write `args` (and a newline) to standard output; see `out!`.
fn write_stdout(args: std::fmt::Arguments<'_>, newline: bool) {
    use std::io::Write;
    let mut o = std::io::stdout().lock();
    let written = o
        .write_fmt(args)
        .and_then(|()| if newline { o.write_all(b"\n") } else { Ok(()) })
        .and_then(|()| o.flush());
    match written {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => std::process::exit(0),
        Err(e) => {
            eprintln!("error: writing to standard output: {e}");
            std::process::exit(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn plain_generation_still_parses() {
        let c = Cli::try_parse_from(["codegen", "a.toml", "-o", "x.rs", "--stats"]).unwrap();
        assert!(c.command.is_none());
        assert_eq!(c.spec.as_deref(), Some(std::path::Path::new("a.toml")));
        assert!(c.stats);
        assert!(Cli::try_parse_from(["codegen"]).is_err());
    }

    #[test]
    fn subcommands_parse() {
        let c = Cli::try_parse_from([
            "codegen", "map", "a.toml", "--index", "dci2", "--axes", "px,py", "--range",
            "-0.1:0.1", "--steps", "11",
        ])
        .unwrap();
        assert!(matches!(c.command, Some(Command::Map(_))));
        let c = Cli::try_parse_from(["codegen", "isotropy", "a.toml", "--samples", "8"]).unwrap();
        assert!(matches!(c.command, Some(Command::Isotropy(_))));
        // Generation flags do not mix with a subcommand.
        assert!(Cli::try_parse_from(["codegen", "a.toml", "map", "b.toml"]).is_err());
    }
}
