//! `codegen fix-home SPEC`: the corrections that the spec reader makes at home (loops left a
//! little open by rounded numbers, closed by moving a joint's frame on the platform or child
//! side; a parallelogram's length taken from the home geometry) written into the spec, so
//! that it loads without them (docs/spec.md, "Rounded numbers at home").

use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `fix-home`.
#[derive(Debug, clap::Args)]
pub struct FixHomeArgs {
    /// Mechanism spec (TOML).
    pub spec: PathBuf,
    /// Write the corrected spec here instead of over SPEC (`-`: standard output).
    #[arg(short, long, value_name = "OUT.toml")]
    pub output: Option<PathBuf>,
}

/// Load, apply every warning's fix, check that the result loads without any, and write it.
pub fn run(args: &FixHomeArgs) -> ExitCode {
    let (name, source) = match super::read_spec(&args.spec) {
        Ok(r) => r,
        Err(code) => return code,
    };
    if name.to_ascii_lowercase().ends_with(".urdf") {
        eprintln!("error: fix-home rewrites TOML specs; {name} is a URDF");
        return ExitCode::from(2);
    }
    // `-o` onto a directory or into a missing one: exit 1 before any work, with the flag
    // named (it failed at the write, naming a temporary file). Onto the spec is allowed: that
    // is the default, in place.
    let output = args.output.as_deref().filter(|o| o.as_os_str() != "-");
    if let Err(code) = super::distinct_outputs(&[], &[("-o", output)]) {
        return code;
    }
    let warnings = match codegen::spec::load_mechanism(&name, &source) {
        Ok((_, w)) => w,
        Err(d) => {
            eprint!("{}", d.render());
            return ExitCode::from(2);
        }
    };
    let (text, applied) = codegen::spec::apply_fixes(&source, &warnings);
    if applied == 0 {
        // With `-o`, the output is still the spec (unchanged): `-o -` printed nothing and
        // `-o OUT.toml` wrote no file, so `fix-home SPEC -o - > OUT.toml` emptied OUT (QA).
        if let Some(out) = &args.output {
            if out.as_os_str() == "-" {
                out!("{text}");
            } else if let Err(e) = super::write_output(out, &text) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        eprintln!("{name}: nothing to fix");
        return ExitCode::SUCCESS;
    }
    // The corrected spec must load, and need no correction at home any more.
    match codegen::spec::load_mechanism(&name, &text) {
        Ok((_, w)) if w.iter().all(|d| d.fix.is_none()) => {}
        Ok((_, w)) => {
            eprint!("{}", w.render());
            eprintln!(
                "error: internal: the corrected spec still needs corrections; nothing written"
            );
            return ExitCode::from(1);
        }
        Err(d) => {
            eprint!("{}", d.render());
            eprintln!("error: internal: the corrected spec does not load; nothing written");
            return ExitCode::from(1);
        }
    }
    let target = args.output.clone().unwrap_or_else(|| args.spec.clone());
    if target.as_os_str() == "-" {
        out!("{text}");
    } else if let Err(e) = super::write_output(&target, &text) {
        eprintln!("error: {e}");
        return ExitCode::from(1);
    }
    eprintln!(
        "{name}: {applied} correction{} written to {}",
        if applied == 1 { "" } else { "s" },
        if target.as_os_str() == "-" {
            "standard output".to_string()
        } else {
            target.display().to_string()
        }
    );
    ExitCode::SUCCESS
}
