//! `codegen`: the command-line adapter over [`codegen::compile`].
//!
//! ```text
//! cargo run -p codegen -- SPEC.(toml|urdf) [-o OUT.rs] [--check] [--stats] [--math libm|std|runtime]
//! ```
//! Exit codes: 0 success, 2 invalid spec (diagnostics on stderr, nothing written), 1 I/O error.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, ValueEnum};
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
#[command(name = "codegen", version, about)]
struct Cli {
    /// Mechanism spec: `.toml` (nocdyn spec) or `.urdf`.
    spec: PathBuf,
    /// Write the module here (default: standard output).
    #[arg(short, long, value_name = "OUT.rs")]
    output: Option<PathBuf>,
    /// Validate the spec only; generate nothing.
    #[arg(long)]
    check: bool,
    /// Print the operation-count table instead of the code.
    #[arg(long)]
    stats: bool,
    /// Where sin/cos and sqrt come from.
    #[arg(long, value_enum, default_value = "libm")]
    math: Math,
    /// Crate path of the runtime for `--math runtime`.
    #[arg(long, default_value = "runtime", value_name = "PATH")]
    runtime_path: String,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let source = match std::fs::read_to_string(&cli.spec) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: cannot read {}: {e}", cli.spec.display());
            return ExitCode::from(1);
        }
    };
    let name = cli.spec.to_string_lossy().into_owned();
    if cli.check {
        return match codegen::spec::load_mechanism(&name, &source) {
            Ok((mechanism, warnings)) => {
                if !warnings.is_empty() {
                    eprint!("{}", warnings.render());
                }
                match mechanism {
                    codegen::spec::Mechanism::Tree(model) => {
                        eprintln!("{}: ok ({} joints)", name, model.dof())
                    }
                    codegen::spec::Mechanism::Parallel(model) => eprintln!(
                        "{}: ok (parallel, {} legs, {} DOF)",
                        name,
                        model.legs.len(),
                        model.dof()
                    ),
                    codegen::spec::Mechanism::Closed(model) => eprintln!(
                        "{}: ok (closed loops, {} joint coordinates, {} cut joints, {} DOF)",
                        name,
                        model.nx(),
                        model.cuts.len(),
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
    let math = match cli.math {
        Math::Libm => MathBackend::Libm,
        Math::Std => MathBackend::Std,
        Math::Runtime => MathBackend::Runtime(cli.runtime_path.clone()),
    };
    let out = match codegen::compile(&name, &source, &Config { math }) {
        Ok(o) => o,
        Err(d) => {
            eprint!("{}", d.render());
            return ExitCode::from(2);
        }
    };
    if !out.warnings.is_empty() {
        eprint!("{}", out.warnings.render());
    }
    let text = if cli.stats {
        let mut t = out.stats_table().join("\n");
        t.push('\n');
        t
    } else {
        out.code
    };
    match &cli.output {
        Some(path) => {
            if let Err(e) = codegen::build_script::write_if_changed(path, &text) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        None => print!("{text}"),
    }
    ExitCode::SUCCESS
}
