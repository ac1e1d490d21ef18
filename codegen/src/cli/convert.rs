//! `codegen convert ROBOT.urdf`: the URDF as a TOML spec that generates the same module,
//! number for number, so that a URDF robot can have a `[scene]` (payload, locked joints,
//! point masses, run-time parameters), `reduce` and everything else a TOML spec has.

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    /// The URDF file.
    pub urdf: PathBuf,
    /// Write the TOML spec here (default: standard output).
    #[arg(short, long, value_name = "OUT.toml")]
    pub output: Option<PathBuf>,
}

/// Load the URDF (its warnings to standard error), write the TOML spec.
pub fn run(args: &ConvertArgs) -> ExitCode {
    let (name, source) = match super::read_spec(&args.urdf) {
        Ok(r) => r,
        Err(code) => return code,
    };
    if let Err(code) = super::distinct_outputs(
        &[("the URDF", &args.urdf)],
        &[("-o", args.output.as_deref())],
    ) {
        return code;
    }
    let (text, warnings) = match codegen::spec::urdf_to_toml(&name, &source) {
        Ok(r) => r,
        Err(d) => {
            eprint!("{}", d.render());
            return ExitCode::from(2);
        }
    };
    if !warnings.is_empty() {
        eprint!("{}", warnings.render());
    }
    match &args.output {
        Some(path) => {
            if let Err(e) = super::write_output(path, &text) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        None => out!("{text}"),
    }
    ExitCode::SUCCESS
}
