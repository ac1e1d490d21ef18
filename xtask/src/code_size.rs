//! `cargo xtask code-size`: bytes of machine code per generated function, for firmware flash
//! budgets (writes `docs/code-size.md`).
//!
//! Builds `tests/no-panic` (one `#[inline(never)]` wrapper per generated function of every
//! bundled mechanism: a generic function per method of `runtime::Dynamics`, one instance per
//! module, told apart by v0 symbol mangling, which this task turns on) with the workspace's `firmware`
//! profile (fat LTO, one codegen unit, `panic = "abort"`) at each optimization level,
//! disassembles it and, for every wrapper, adds up the sizes of all functions reachable from it
//! through direct calls and jumps. Shared helpers (LU, kinematics kernels) count in every
//! function that calls them; the "all functions" row of a mechanism counts each one once. The
//! math routines (`libm`: sin, cos, sqrt, ...) are shared by every mechanism and reported once,
//! separately.
//!
//! Needs cargo, `nm` and `objdump` (binutils). Exits non-zero if a wrapper is missing. A
//! function that can reach the panic machinery (`core::panicking`) is marked in the table, with
//! the call site; the machinery itself is not counted. (The `#[no_panic]` proof,
//! `tests/no-panic`, covers the default `opt-level = 3`.)

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use std::time::Instant;

const CRATE: &str = "tests_no_panic";

/// Arguments of `code-size`.
#[derive(Debug, clap::Args)]
pub struct CodeSizeArgs {
    /// Where the table goes (default: `docs/code-size.md`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Optimization levels, comma-separated.
    #[arg(long, default_value = "s,3")]
    pub levels: String,
    /// Cargo's target directory (default: `$CARGO_TARGET_DIR`, else `target/`).
    #[arg(long)]
    pub target_dir: Option<PathBuf>,
    /// Measure the binaries an earlier run kept (`<target>/firmware/tests-no-panic.opt-<level>`)
    /// instead of building; the build times then read 0 s.
    #[arg(long)]
    pub no_build: bool,
}

type Error = Box<dyn std::error::Error>;

/// A math routine, shared by every mechanism and counted apart.
fn is_math(name: &str) -> bool {
    ["libm::", "runtime::math::", "compiler_builtins::"]
        .iter()
        .any(|p| name.starts_with(p))
}

/// The panic machinery.
fn is_panic(name: &str) -> bool {
    [
        "core::panicking",
        "core::result::unwrap_failed",
        "core::option::expect_failed",
    ]
    .iter()
    .any(|p| name.contains(p))
}

/// `(module, function)` of a wrapper, an instance of the generic
/// `tests_no_panic::<function>::<mechanisms::<module>::Module, NX, DOF>` (v0 mangling,
/// demangled; crate disambiguators `[…]`, if shown, skipped; `f32::` modules named as theirs).
fn wrapper(name: &str) -> Option<(String, String)> {
    let skip_hash = |s: &str| -> Option<String> {
        let s = s
            .strip_prefix('[')
            .map_or(Some(s), |r| r.split_once(']').map(|(_, t)| t))?;
        Some(s.to_string())
    };
    let rest = skip_hash(name.strip_prefix(CRATE)?)?;
    let rest = rest.strip_prefix("::")?;
    let (f, rest) = rest.split_once("::<mechanisms")?;
    let rest = skip_hash(rest)?;
    let rest = rest.strip_prefix("::")?;
    let rest = rest.strip_prefix("f32::").unwrap_or(rest);
    let (m, rest) = rest.split_once("::Module, ")?;
    if !rest.ends_with('>') || rest.contains('<') {
        return None;
    }
    let word = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_alphanumeric() || c == '_');
    (word(m) && word(f)).then(|| (m.to_string(), f.to_string()))
}

fn run_output(cmd: &mut Command) -> Result<String, Error> {
    let out = cmd.stderr(Stdio::inherit()).output()?;
    if !out.status.success() {
        return Err(format!("{cmd:?} failed: {}", out.status).into());
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Builds at `level` and keeps a copy of the binary; returns it and the build's seconds.
fn build(
    root: &Path,
    level: &str,
    target_dir: &Path,
    no_build: bool,
) -> Result<(PathBuf, f64), Error> {
    let binary = target_dir.join("firmware").join("tests-no-panic");
    let kept = PathBuf::from(format!("{}.opt-{level}", binary.display()));
    if no_build {
        return Ok((kept, 0.0));
    }
    let opt = if level == "s" || level == "z" {
        format!("profile.firmware.opt-level=\"{level}\"")
    } else {
        format!("profile.firmware.opt-level={level}")
    };
    let start = Instant::now();
    let status = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .args([
            "build",
            "--locked",
            "-p",
            "tests-no-panic",
            "--profile",
            "firmware",
        ])
        .args([
            "--config",
            &opt,
            "--config",
            "profile.firmware.panic=\"abort\"",
            // v0 mangling names each instance of a generic wrapper with its module.
            "--config",
            "build.rustflags=[\"-Csymbol-mangling-version=v0\"]",
        ])
        .env("CARGO_TARGET_DIR", target_dir)
        .current_dir(root)
        .status()?;
    if !status.success() {
        return Err(format!("cargo build at opt-level {level} failed: {status}").into());
    }
    let took = start.elapsed().as_secs_f64();
    std::fs::copy(&binary, &kept)?;
    Ok((kept, took))
}

/// Function symbols: sorted starts, and start → (name, size).
type Funcs = HashMap<u64, (String, u64)>;

fn symbols(binary: &Path) -> Result<(Vec<u64>, Funcs), Error> {
    let out = run_output(
        Command::new("nm")
            .args(["-S", "-C", "--defined-only"])
            .arg(binary),
    )?;
    let mut funcs: Funcs = HashMap::new();
    for line in out.lines() {
        let parts: Vec<&str> = line.splitn(4, char::is_whitespace).collect();
        if parts.len() != 4 || !matches!(parts[2], "t" | "T" | "w" | "W") {
            continue;
        }
        let (Ok(start), Ok(size)) = (
            u64::from_str_radix(parts[0], 16),
            u64::from_str_radix(parts[1], 16),
        ) else {
            continue;
        };
        let name = parts[3].trim_start().to_string();
        if size > 0 && funcs.get(&start).is_none_or(|f| f.1 < size) {
            funcs.insert(start, (name, size));
        }
    }
    let mut starts: Vec<u64> = funcs.keys().copied().collect();
    starts.sort_unstable();
    Ok((starts, funcs))
}

/// The target of a direct `call`, `jmp` or conditional jump on a disassembly line
/// (`\s(call|jmp|j[a-z]{1,3})q?\s+([0-9a-f]+) <`).
fn branch_target(line: &str) -> Option<u64> {
    let b = line.as_bytes();
    for i in 0..b.len() {
        if !b[i].is_ascii_whitespace() {
            continue;
        }
        let word_end = (i + 1..b.len())
            .find(|&k| !b[k].is_ascii_lowercase())
            .unwrap_or(b.len());
        let word = &line[i + 1..word_end];
        let base = word
            .strip_suffix('q')
            .filter(|w| is_branch(w))
            .unwrap_or(word);
        if !is_branch(base) && !is_branch(word) {
            continue;
        }
        let hex_start = (word_end..b.len())
            .find(|&k| !b[k].is_ascii_whitespace())
            .unwrap_or(b.len());
        if hex_start == word_end {
            continue;
        }
        let hex_end = (hex_start..b.len())
            .find(|&k| !matches!(b[k], b'0'..=b'9' | b'a'..=b'f'))
            .unwrap_or(b.len());
        if hex_end > hex_start && line[hex_end..].starts_with(" <") {
            return u64::from_str_radix(&line[hex_start..hex_end], 16).ok();
        }
    }
    None
}

/// `call`, `jmp` or `j` and one to three letters.
fn is_branch(w: &str) -> bool {
    w == "call" || w == "jmp" || (w.starts_with('j') && (2..=4).contains(&w.len()))
}

/// The index of the function that holds `addr`, if any.
fn holder(starts: &[u64], funcs: &Funcs, addr: u64) -> Option<u64> {
    let i = starts.partition_point(|s| *s <= addr).checked_sub(1)?;
    let s = starts[i];
    (addr < s + funcs[&s].1).then_some(s)
}

/// Caller start → callee starts, from direct call and jump targets in the disassembly.
fn call_graph(
    binary: &Path,
    starts: &[u64],
    funcs: &Funcs,
) -> Result<HashMap<u64, BTreeSet<u64>>, Error> {
    let mut edges: HashMap<u64, BTreeSet<u64>> = HashMap::new();
    let mut dis = Command::new("objdump")
        .args(["-d", "--no-show-raw-insn"])
        .arg(binary)
        .stdout(Stdio::piped())
        .spawn()?;
    let stdout = dis.stdout.take().ok_or("objdump: no output")?;
    for line in BufReader::new(stdout).lines() {
        let line = line?;
        let Some(t) = branch_target(&line) else {
            continue;
        };
        let Some(addr) = line
            .split_once(':')
            .and_then(|(a, _)| u64::from_str_radix(a.trim(), 16).ok())
        else {
            continue;
        };
        let Some(caller) = holder(starts, funcs, addr) else {
            continue;
        };
        if let Some(callee) = holder(starts, funcs, t).filter(|c| *c != caller) {
            edges.entry(caller).or_default().insert(callee);
        }
    }
    dis.wait()?;
    Ok(edges)
}

/// Functions reachable from `root`, not entering the panic machinery; and the panic call sites
/// met on the way, as (caller, panic function) names.
fn reach(
    root: u64,
    edges: &HashMap<u64, BTreeSet<u64>>,
    funcs: &Funcs,
) -> (BTreeSet<u64>, BTreeSet<(String, String)>) {
    let (mut seen, mut todo, mut sites) = (BTreeSet::from([root]), vec![root], BTreeSet::new());
    while let Some(f) = todo.pop() {
        for &c in edges.get(&f).into_iter().flatten() {
            if is_panic(&funcs[&c].0) {
                sites.insert((funcs[&f].0.clone(), funcs[&c].0.clone()));
            } else if seen.insert(c) {
                todo.push(c);
            }
        }
    }
    (seen, sites)
}

/// A wrapper: (mechanism, function).
type Key = (String, String);
/// Panic call sites: (caller, panic function).
type Sites = Vec<(String, String)>;

/// One level's measurements.
struct Measured {
    /// Bytes per wrapper.
    sizes: BTreeMap<(String, String), u64>,
    /// Bytes of each mechanism's functions, each counted once.
    totals: BTreeMap<String, u64>,
    math_bytes: u64,
    math_names: BTreeSet<String>,
    /// Panic call sites per wrapper, in the order of the wrappers' addresses.
    panics: Vec<(Key, Sites)>,
}

fn measure(binary: &Path) -> Result<Measured, Error> {
    let (starts, funcs) = symbols(binary)?;
    let edges = call_graph(binary, &starts, &funcs)?;
    let mut sizes = BTreeMap::new();
    let mut per_mech: BTreeMap<String, BTreeSet<u64>> = BTreeMap::new();
    let (mut math, mut panics) = (BTreeSet::new(), Vec::new());
    for &s in &starts {
        let Some((m, f)) = wrapper(&funcs[&s].0).filter(|(_, f)| f != "run") else {
            continue;
        };
        let (seen, sites) = reach(s, &edges, &funcs);
        let mut own = 0;
        for g in seen {
            let (name, size) = &funcs[&g];
            if is_math(name) {
                math.insert(g);
            } else {
                own += size;
                per_mech.entry(m.clone()).or_default().insert(g);
            }
        }
        let key = (m, f);
        if !sites.is_empty() {
            panics.retain(|(k, _)| *k != key);
            panics.push((key.clone(), sites.into_iter().collect()));
        }
        sizes.insert(key, own);
    }
    let totals = per_mech
        .into_iter()
        .map(|(k, v)| (k, v.iter().map(|f| funcs[f].1).sum()))
        .collect();
    Ok(Measured {
        sizes,
        totals,
        math_bytes: math.iter().map(|f| funcs[f].1).sum(),
        math_names: math.iter().map(|f| funcs[f].0.clone()).collect(),
        panics,
    })
}

/// `n` with thousands separators (Python's `{n:,}`).
fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A math routine's short name: without `libm::` or `runtime::` and the path after them.
fn short_math(name: &str) -> String {
    let Some(rest) = name
        .strip_prefix("libm::")
        .or_else(|| name.strip_prefix("runtime::"))
    else {
        return name.to_string();
    };
    match rest.rfind("::") {
        Some(k) => rest[k + 2..].to_string(),
        None => rest.to_string(),
    }
}

fn today() -> String {
    Command::new("date")
        .arg("+%F")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}

/// The page's text.
fn page(levels: &[String], results: &[Measured], took: &[f64]) -> String {
    let rustc = Command::new("rustc")
        .arg("--version")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    let level_word = |lv: &str| {
        if lv == "s" || lv == "z" {
            format!("opt-level \"{lv}\"")
        } else {
            format!("opt-level {lv}")
        }
    };
    let head: Vec<String> = levels.iter().map(|lv| level_word(lv)).collect();
    let mut lines = vec![
        "# Code size of the generated functions".to_string(),
        String::new(),
        "Bytes of machine code per generated function: everything reachable from the function through direct calls (shared helpers such as the LU or the kinematics kernels count in every function that uses them), without the math routines, which every mechanism shares (listed below the table). The `all` row of a mechanism counts each machine-code function once: it is what linking every function of that mechanism costs.".to_string(),
        String::new(),
        format!(
            "Generated by `cargo xtask code-size` on {}: {rustc}, target {}-linux, the workspace's `firmware` profile (fat LTO, `codegen-units = 1`) with `panic = \"abort\"`, `f64`, math from the `libm` crate. Sizes on a Cortex-M (Thumb-2) differ; the ratios between functions carry over.",
            today(),
            std::env::consts::ARCH
        ),
        String::new(),
        format!("| mechanism | function | {} |", head.join(" | ")),
        format!("|---|---|{}", "---:|".repeat(levels.len())),
    ];
    table_rows(&mut lines, results);
    footnotes(&mut lines, levels, results);
    let times: Vec<String> = levels
        .iter()
        .zip(took)
        .map(|(lv, t)| format!("opt-level {lv} {t:.0} s"))
        .collect();
    lines.push(format!(
        "Build times (2 cores, incremental on an existing target directory): {}.",
        times.join(", ")
    ));
    lines.join("\n") + "\n"
}

/// One row per wrapper and an `all` row per mechanism.
fn table_rows(lines: &mut Vec<String>, results: &[Measured]) {
    let keys: BTreeSet<&(String, String)> = results.iter().flat_map(|r| r.sizes.keys()).collect();
    let mechs: BTreeSet<&String> = keys.iter().map(|(m, _)| m).collect();
    for mech in mechs {
        for key in keys.iter().filter(|(m, _)| m == mech) {
            let cells: Vec<String> = results
                .iter()
                .map(|r| {
                    let dagger = r.panics.iter().any(|(k, _)| k == *key);
                    let n = r.sizes.get(*key).copied().unwrap_or(0);
                    format!("{}{}", thousands(n), if dagger { " †" } else { "" })
                })
                .collect();
            lines.push(format!(
                "| `{mech}` | `{}` | {} |",
                key.1,
                cells.join(" | ")
            ));
        }
        let cells: Vec<String> = results
            .iter()
            .map(|r| {
                format!(
                    "**{}**",
                    thousands(r.totals.get(mech).copied().unwrap_or(0))
                )
            })
            .collect();
        lines.push(format!("| `{mech}` | all | {} |", cells.join(" | ")));
    }
    lines.push(String::new());
}

/// The math routines and the panic sites of each level.
fn footnotes(lines: &mut Vec<String>, levels: &[String], results: &[Measured]) {
    for (lv, r) in levels.iter().zip(results) {
        let short: BTreeSet<String> = r.math_names.iter().map(|n| short_math(n)).collect();
        let short: Vec<String> = short.into_iter().collect();
        lines.push(format!(
            "Math routines at opt-level {lv}: {} bytes ({}).",
            thousands(r.math_bytes),
            short.join(", ")
        ));
        lines.push(String::new());
    }
    for (lv, r) in levels.iter().zip(results) {
        if r.panics.is_empty() {
            lines.push(format!("No function reaches a panic at opt-level {lv}."));
            lines.push(String::new());
            continue;
        }
        let sites: BTreeSet<&(String, String)> = r.panics.iter().flat_map(|(_, v)| v).collect();
        let sites: Vec<String> = sites
            .iter()
            .map(|(caller, callee)| format!("`{caller}` calls `{callee}`"))
            .collect();
        lines.push(format!(
            "† Can reach a panic at opt-level {lv} (the panic machinery is not counted in the size): {}.",
            sites.join("; ")
        ));
        lines.push(String::new());
    }
}

/// Run `code-size`.
pub fn run(root: &Path, args: &CodeSizeArgs) -> Result<ExitCode, Error> {
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| root.join("docs").join("code-size.md"));
    let target_dir = args.target_dir.clone().unwrap_or_else(|| {
        std::env::var_os("CARGO_TARGET_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| root.join("target"))
    });
    let levels: Vec<String> = args.levels.split(',').map(String::from).collect();
    let (mut results, mut took) = (Vec::new(), Vec::new());
    for level in &levels {
        let (binary, t) = build(root, level, &target_dir, args.no_build)?;
        results.push(measure(&binary)?);
        took.push(t);
    }
    let mut ok = true;
    let keys: BTreeSet<&(String, String)> = results.iter().flat_map(|r| r.sizes.keys()).collect();
    for (level, r) in levels.iter().zip(&results) {
        let missing: Vec<String> = keys
            .iter()
            .filter(|k| !r.sizes.contains_key(**k))
            .map(|(m, f)| format!("('{m}', '{f}')"))
            .collect();
        if !missing.is_empty() {
            eprintln!(
                "opt-level {level}: wrappers missing: [{}]",
                missing.join(", ")
            );
            ok = false;
        }
        for ((m, f), sites) in &r.panics {
            for (caller, callee) in sites {
                eprintln!("opt-level {level}: {m}::{f} can panic: {caller} calls {callee}");
            }
        }
    }
    let text = page(&levels, &results, &took);
    std::fs::write(&out, &text)?;
    println!("{text}");
    Ok(if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

#[cfg(test)]
mod tests {
    use super::wrapper;

    #[test]
    fn wrapper_names() {
        let w = |s: &str| wrapper(s).map(|(m, f)| format!("{m}/{f}"));
        assert_eq!(
            w("tests_no_panic::inverse_dynamics::<mechanisms::puma560::Module, 6, 6>").as_deref(),
            Some("puma560/inverse_dynamics")
        );
        assert_eq!(
            w("tests_no_panic[1a2b]::mass_matrix::<mechanisms[9f]::f32::agile_eye::Module, 4, 3>")
                .as_deref(),
            Some("agile_eye/mass_matrix")
        );
        assert_eq!(w("tests_no_panic::run"), None);
        assert_eq!(w("core::panicking::panic"), None);
    }
}
