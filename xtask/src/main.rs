//! Workspace tasks: the generators of specs and figures, run as `cargo xtask <task>` (the alias
//! is in `.cargo/config.toml`; this package is not among the workspace's default members).
//!
//! * `parallel-specs`: the four parallel specs of `mechanisms/specs/` (their placements and
//!   full-precision numbers, every loop checked to close at home);
//! * `rank-specs`: the test specs of `tests/data/` whose loops are turned in space;
//! * `code-size`: builds `tests/no-panic` and writes `docs/code-size.md`.

mod code_size;
mod parallel_specs;
mod pyfmt;
mod pymath;
mod rank_specs;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Workspace tasks: generators of specs and figures.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Debug, Subcommand)]
enum Task {
    /// Write the parallel-mechanism specs of mechanisms/specs/ (gough_stewart, sliding_hexapod,
    /// rus_hexapod, agile_eye).
    ParallelSpecs {
        /// Write into this folder instead.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Write the test specs of tests/data/ whose loops are turned in space
    /// (planar_3rrr_inclined, delta_4r).
    RankSpecs {
        /// Write into this folder instead.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Measure the machine code of every generated function and write docs/code-size.md.
    CodeSize(code_size::CodeSizeArgs),
}

/// The workspace root.
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap_or(Path::new("."))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let done = match cli.task {
        Task::ParallelSpecs { out } => {
            let dir = out.unwrap_or_else(|| root().join("mechanisms").join("specs"));
            parallel_specs::run(&dir)
                .map(|()| ExitCode::SUCCESS)
                .map_err(Into::into)
        }
        Task::RankSpecs { out } => {
            let dir = out.unwrap_or_else(|| root().join("tests").join("data"));
            rank_specs::run(&dir)
                .map(|()| ExitCode::SUCCESS)
                .map_err(Into::into)
        }
        Task::CodeSize(args) => code_size::run(root(), &args),
    };
    done.unwrap_or_else(|e: Box<dyn std::error::Error>| {
        eprintln!("error: {e}");
        ExitCode::FAILURE
    })
}
