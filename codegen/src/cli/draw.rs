//! `codegen draw SPEC [-o home.svg]`: the home pose in three orthographic views, as SVG
//! ([`codegen::draw`]; docs/draw.md).

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `draw`.
#[derive(Debug, clap::Args)]
pub struct DrawArgs {
    /// Mechanism spec: `.toml` or `.urdf`.
    pub spec: PathBuf,
    /// Write the SVG here (default: standard output).
    #[arg(short, long, value_name = "OUT.svg")]
    pub output: Option<PathBuf>,
}

/// Draw and write. A spec that reads and places but fails its checks (a loop too far open at
/// home, a wrong mobility) is still drawn, with its diagnostics and exit code 2: the picture
/// shows what is wrong. One that cannot be placed writes nothing.
pub fn run(args: &DrawArgs) -> ExitCode {
    let (name, source) = match super::read_spec(&args.spec) {
        Ok(r) => r,
        Err(code) => return code,
    };
    if let Err(code) = super::distinct_outputs(
        &[("the spec", &args.spec)],
        &[("-o", args.output.as_deref())],
    ) {
        return code;
    }
    let (drawing, diags) = match codegen::draw::draw(&name, &source) {
        Ok(r) => r,
        Err(d) => {
            eprint!("{}", d.render());
            return ExitCode::from(2);
        }
    };
    if !diags.is_empty() {
        eprint!("{}", diags.render());
    }
    match &args.output {
        Some(path) => {
            if let Err(e) = super::write_output(path, &drawing.svg) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        None => out!("{}", drawing.svg),
    }
    if diags.has_errors() {
        eprintln!("{name}: drawn as written, but the spec has errors (above)");
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    }
}
