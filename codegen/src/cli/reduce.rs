//! `codegen reduce SPEC --tolerance 1e-3`: the cheapest model that is accurate enough.
//!
//! Fidelity levels are `[scene]` tables (`point_mass`, `massless`): a greedy search starts from
//! the full model and, step by step, takes the body (for parallel mechanisms: the group of
//! corresponding bodies of every leg) whose reduction saves the most inverse-dynamics flops
//! while the actuator efforts stay within the tolerance of the full model's — the largest
//! relative error (∞-norm per state) over random regular states, evaluated by the runtime. Each
//! step also tries every group's point masses at once (bodies that turn together cost less only
//! together). It prints the table of every level tried and writes the cheapest spec that meets
//! the tolerance.

use std::path::PathBuf;
use std::process::ExitCode;

use codegen::spec::Mechanism;
use runtime::workspace::Workspace;

use super::Rng;

/// Arguments of `reduce`.
#[derive(Debug, clap::Args)]
// A negative number is a value (refused by the range checks with their message), not a flag.
#[command(allow_negative_numbers = true)]
pub struct ReduceArgs {
    /// Mechanism spec (TOML, without a `[scene]` table).
    pub spec: PathBuf,
    /// Largest accepted relative error of the actuator efforts (∞-norm, worst state).
    #[arg(long, default_value = "1e-3")]
    pub tolerance: f64,
    /// Random regular states to compare on (1 to 100,000).
    #[arg(long, default_value = "200")]
    pub samples: usize,
    /// Random seed.
    #[arg(long, default_value = "1")]
    pub seed: u64,
    /// Write the reduced spec here (default: standard output).
    #[arg(short, long, value_name = "OUT.toml")]
    pub output: Option<PathBuf>,
    /// Also time each row's generated inverse dynamics: compile it with `rustc -C opt-level=3`
    /// (on PATH, or `$RUSTC`) into a small timing program run on the same states, and add an
    /// `ns per call` column (median of 31 batches). Slower: one compilation per row.
    #[arg(long)]
    pub time: bool,
}

/// ns per call of the inverse dynamics generated from `src`, timed on `states` by a program
/// compiled with rustc; `None` when rustc or the program fails (the column then says why not).
fn time_generated(name: &str, src: &str, m: &Mechanism, states: &[State]) -> Option<f64> {
    let cfg = codegen::Config {
        math: codegen::MathBackend::Std,
        ..Default::default()
    };
    let module = codegen::compile(name, src, &cfg).ok()?.code;
    let dir = std::env::temp_dir().join(format!("nocdyn-reduce-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    let lit = |v: &[f64]| {
        let items: Vec<String> = v.iter().map(|x| format!("{x:?}")).collect();
        format!("[{}]", items.join(", "))
    };
    let rows: Vec<String> = states
        .iter()
        .map(|(a, b, c)| format!("({}, {}, {})", lit(a), lit(b), lit(c)))
        .collect();
    // The generated functions' signatures differ: a tree's inverse dynamics cannot fail, a
    // platform's and closed loops' return a `Result` (a match on the generated API, not on
    // how the runtime evaluates the kind).
    let call = match m {
        Mechanism::Tree(_) => "m::inverse_dynamics(a, b, c)[0]",
        Mechanism::Parallel(_) | Mechanism::Closed(_) => {
            "m::inverse_dynamics(a, b, c).map_or(0.0, |t| t[0])"
        }
    };
    let main = format!(
        "#![allow(warnings)]\nmod m {{ include!(\"module.rs\"); }}\n\
         const S: &[([f64; {na}], [f64; {nb}], [f64; {nb}])] = &[{rows}];\n\
         fn main() {{\n\
             let mut t: Vec<f64> = (0..31).map(|_| {{\n\
                 let t0 = std::time::Instant::now();\n\
                 let mut sink = 0.0;\n\
                 for (a, b, c) in std::hint::black_box(S) {{ sink += {call}; }}\n\
                 std::hint::black_box(sink);\n\
                 t0.elapsed().as_nanos() as f64 / S.len() as f64\n\
             }}).collect();\n\
             t.sort_by(f64::total_cmp);\n\
             println!(\"{{}}\", t[15]);\n\
         }}\n",
        na = states[0].0.len(),
        nb = states[0].1.len(),
        rows = rows.join(", "),
    );
    std::fs::write(dir.join("module.rs"), module).ok()?;
    std::fs::write(dir.join("main.rs"), main).ok()?;
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    let exe = dir.join("timing");
    let ok = std::process::Command::new(rustc)
        .args(["--edition", "2021", "-C", "opt-level=3", "-o"])
        .arg(&exe)
        .arg(dir.join("main.rs"))
        .output()
        .ok()?
        .status
        .success();
    let out = if ok {
        std::process::Command::new(&exe).output().ok()
    } else {
        None
    };
    let _ = std::fs::remove_dir_all(&dir);
    String::from_utf8(out?.stdout).ok()?.trim().parse().ok()
}

/// A fidelity level: which bodies are point masses, which massless.
#[derive(Clone, Debug, Default, PartialEq)]
struct Level {
    point_mass: Vec<String>,
    massless: Vec<String>,
}

impl Level {
    fn scene(&self) -> String {
        let list = |v: &[String]| {
            v.iter()
                .map(|n| format!("{n:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        format!(
            "\n# Written by `codegen reduce`: the cheapest fidelity within the tolerance.\n[scene]\npoint_mass = [{}]\nmassless = [{}]\n",
            list(&self.point_mass),
            list(&self.massless)
        )
    }
    fn describe(&self) -> String {
        if self.point_mass.is_empty() && self.massless.is_empty() {
            return "full model".into();
        }
        let mut parts = Vec::new();
        if !self.point_mass.is_empty() {
            parts.push(format!("point masses: {}", self.point_mass.join(" ")));
        }
        if !self.massless.is_empty() {
            parts.push(format!("massless: {}", self.massless.join(" ")));
        }
        parts.join("; ")
    }
}

/// One evaluation state.
type State = (Vec<f64>, Vec<f64>, Vec<f64>);

fn efforts(m: &dyn Workspace, s: &State) -> Option<Vec<f64>> {
    let (x, u, ud) = s;
    m.inverse_dynamics(x, u, ud).ok()
}

/// Up to `n` random regular states: positions at random offsets from home (within
/// [`Workspace::sample_widths`]; closed loops reassembled, a draw that does not assemble
/// dropped), random speeds and speed rates in `±1`.
fn states(m: &dyn Workspace, n: usize, rng: &mut Rng) -> Vec<State> {
    let (home, widths) = (m.home_state(), m.sample_widths());
    let d = m.dof();
    let mut out = Vec::new();
    let mut tries = 0;
    while out.len() < n && tries < 100 * n {
        tries += 1;
        let offset: Vec<f64> = widths.iter().map(|w| rng.uniform(-w, *w)).collect();
        let Ok(x) = m.advance(&home, &offset) else {
            continue;
        };
        let s: State = (
            x,
            (0..d).map(|_| rng.uniform(-1.0, 1.0)).collect(),
            (0..d).map(|_| rng.uniform(-1.0, 1.0)).collect(),
        );
        if efforts(m, &s).is_some_and(|t| t.iter().all(|v| v.is_finite())) {
            out.push(s);
        }
    }
    out
}

/// Worst and RMS relative error of `m`'s efforts against `reference` over `states`.
fn errors(m: &dyn Workspace, states: &[State], reference: &[Vec<f64>]) -> Option<(f64, f64)> {
    let mut worst: f64 = 0.0;
    let mut sum = 0.0;
    for (s, r) in states.iter().zip(reference) {
        let t = efforts(m, s)?;
        let num = t
            .iter()
            .zip(r)
            .fold(0.0f64, |a, (p, q)| a.max((p - q).abs()));
        let den = r.iter().fold(1e-300f64, |a, q| a.max(q.abs()));
        let e = num / den;
        worst = worst.max(e);
        sum += e * e;
    }
    Some((worst, (sum / states.len().max(1) as f64).sqrt()))
}

/// Run `reduce`.
pub fn run(args: &ReduceArgs) -> ExitCode {
    let (name, source) = match read_checked(args) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let (full, bodies) = match load_full(&name, &source) {
        Ok(r) => r,
        Err(code) => return code,
    };
    // A model the runtime refuses has no regular state either.
    let evaluator = super::workspace(&name, full.clone()).ok();
    let groups = evaluator
        .as_ref()
        .map(|e| e.body_groups(&bodies))
        .unwrap_or_default();
    let mut rng = Rng::new(args.seed);
    let samples = evaluator
        .as_ref()
        .map(|e| states(e.as_ref(), args.samples, &mut rng))
        .unwrap_or_default();
    if samples.is_empty() {
        eprintln!("error: {name}: no regular state found to compare on");
        return ExitCode::from(2);
    }
    let reference: Vec<Vec<f64>> = samples
        .iter()
        .map(|s| {
            evaluator
                .as_ref()
                .and_then(|e| efforts(e.as_ref(), s))
                .unwrap_or_default()
        })
        .collect();
    let search = Search {
        args,
        name: &name,
        source: &source,
        full: &full,
        samples: &samples,
        reference: &reference,
    };
    let mut current = Level::default();
    let Some((mut cost, _, _)) = search.evaluate(&current) else {
        eprintln!("error: {name}: the full model cannot be generated");
        return ExitCode::from(2);
    };
    let pb = super::progress(0, "reduce");
    search.print_head(&current, cost);
    while let Some((l, f)) = search.step(&current, cost, &groups, &pb) {
        current = l;
        cost = f;
    }
    pb.finish_and_clear();
    outln!(
        "cheapest within tolerance: {} ({cost} flops)",
        current.describe()
    );
    write_output(args, &source, &current)
}

/// The most states `--samples` takes: every fidelity tried is evaluated on all of them (the
/// PUMA 560's search takes about 36 s on 100,000), and 4,294,967,296 ran without end.
const MAX_SAMPLES: usize = 100_000;

/// The spec's name and text, with the arguments checked: no `[scene]` table of its own, a
/// positive tolerance, at least one sample.
fn read_checked(args: &ReduceArgs) -> Result<(String, String), ExitCode> {
    let (name, source) = super::read_spec(&args.spec)?;
    super::distinct_outputs(
        &[("the spec", &args.spec)],
        &[("-o", args.output.as_deref())],
    )?;
    if let Some(span) = scene_table(&source) {
        let mut d = codegen::diag::Diagnostics::new(&name, &source);
        d.push(
            codegen::diag::Diagnostic::error(
                "`reduce` writes the [scene] table itself; remove the spec's own",
            )
            .with_key("scene")
            .with_span(span)
            .with_hint(
                "reduce chooses the point_mass and massless lists and writes them in the output's [scene]; run it on the spec without its [scene], then add the other scene keys (frames, payload, …) to its output",
            ),
        );
        eprint!("{}", d.render());
        return Err(ExitCode::from(2));
    }
    if args.tolerance.is_nan() || args.tolerance <= 0.0 || args.samples == 0 {
        eprintln!("error: --tolerance must be positive and --samples at least 1");
        return Err(ExitCode::from(2));
    }
    if args.samples > MAX_SAMPLES {
        eprintln!("error: --samples {}: at most {MAX_SAMPLES}", args.samples);
        return Err(ExitCode::from(2));
    }
    Ok((name, source))
}

/// The span of the spec's `scene` key (a `[scene]` header however spaced, `[scene.…]`, or an
/// inline `scene = { … }`), if it has one; a spec that does not parse has none here (its
/// syntax error is reported when it is loaded).
fn scene_table(source: &str) -> Option<std::ops::Range<usize>> {
    let root = toml::de::DeTable::parse(source).ok()?;
    let (key, _) = root.get_ref().get_key_value("scene")?;
    Some(key.span())
}

/// The full model and the spec's body names (a TOML spec).
fn load_full(name: &str, source: &str) -> Result<(Mechanism, Vec<String>), ExitCode> {
    let full = match codegen::spec::load_mechanism(name, source) {
        Ok((m, _)) => m,
        Err(d) => {
            eprint!("{}", d.render());
            return Err(ExitCode::from(2));
        }
    };
    let Some(bodies) = codegen::spec::body_names(name, source) else {
        eprintln!("error: {name}: `reduce` needs a TOML spec");
        return Err(ExitCode::from(2));
    };
    Ok((full, bodies))
}

/// The greedy search's fixed data: the spec, the full model and the states compared on.
struct Search<'a> {
    args: &'a ReduceArgs,
    name: &'a str,
    source: &'a str,
    full: &'a Mechanism,
    samples: &'a [State],
    /// The full model's efforts at `samples`.
    reference: &'a [Vec<f64>],
}

impl Search<'_> {
    /// Inverse-dynamics flops of the code generated at `level`.
    fn flops(&self, level: &Level) -> Option<usize> {
        let src = format!("{}{}", self.source, level.scene());
        let g = codegen::compile(self.name, &src, &codegen::Config::default()).ok()?;
        g.stats
            .iter()
            .find(|(n, _)| n == "inverse_dynamics")
            .map(|(_, c)| c.flops())
    }

    /// Flops, worst and RMS relative error at `level`.
    fn evaluate(&self, level: &Level) -> Option<(usize, f64, f64)> {
        let src = format!("{}{}", self.source, level.scene());
        let (m, _) = codegen::spec::load_mechanism(self.name, &src).ok()?;
        let m = super::workspace(self.name, m).ok()?;
        let (worst, rms) = errors(m.as_ref(), self.samples, self.reference)?;
        Some((self.flops(level)?, worst, rms))
    }

    /// The `ns per call` cell with `--time` (else nothing).
    fn ns(&self, level: &Level) -> String {
        if !self.args.time {
            return String::new();
        }
        let src = format!("{}{}", self.source, level.scene());
        match time_generated(self.name, &src, self.full, self.samples) {
            Some(t) => format!(" {t:.0} |"),
            None => " (rustc failed) |".into(),
        }
    }

    /// The title, the table head and the reference row (`level`, the full model, at `cost`).
    fn print_head(&self, level: &Level, cost: usize) {
        let ns_head = if self.args.time { " ns per call |" } else { "" };
        let ns_rule = if self.args.time { "---:|" } else { "" };
        outln!(
            "reduce: {} ({} states, tolerance {:e} on the worst relative actuator-effort error, inf-norm)",
            self.full.name(),
            self.samples.len(),
            self.args.tolerance
        );
        outln!(
            "| fidelity | inverse dynamics flops |{ns_head} max relative error | RMS relative error | accepted |"
        );
        outln!("|---|---:|{ns_rule}---:|---:|---|");
        outln!(
            "| {} | {cost} |{} 0 | 0 | (reference) |",
            level.describe(),
            self.ns(level)
        );
    }

    /// One greedy step from `current` (at `cost` flops): tries reducing each group further, and
    /// every group to point masses at once ([`together`]), prints a row per try, and returns
    /// the cheapest accepted level and its flops.
    fn step(
        &self,
        current: &Level,
        cost: usize,
        groups: &[Vec<String>],
        pb: &indicatif::ProgressBar,
    ) -> Option<(Level, usize)> {
        let mut best: Option<(Level, usize, f64, f64)> = None;
        let open: Vec<&Vec<String>> = groups
            .iter()
            .filter(|g| !g.iter().any(|b| current.massless.contains(b)))
            .collect();
        for l in open
            .iter()
            .flat_map(|g| tries(current, g))
            .chain(together(current, &open))
        {
            pb.inc(1);
            let Some((f, worst, rms)) = self.evaluate(&l) else {
                continue;
            };
            let ok = worst <= self.args.tolerance && f < cost;
            outln!(
                "| {} | {f} |{} {worst:.2e} | {rms:.2e} | {} |",
                l.describe(),
                self.ns(&l),
                if ok { "yes" } else { "no" }
            );
            if ok && best.as_ref().is_none_or(|b| f < b.1) {
                best = Some((l, f, worst, rms));
            }
        }
        best.map(|(l, f, _, _)| (l, f))
    }
}

/// The reductions of group `g` from `current`: point masses (unless they already are), then
/// massless.
fn tries(current: &Level, g: &[String]) -> Vec<Level> {
    let mut tries = Vec::new();
    let mut l = current.clone();
    if point_masses(&mut l, g) {
        tries.push(l);
    }
    let mut l = current.clone();
    l.point_mass.retain(|b| !g.contains(b));
    l.massless.extend(g.iter().cloned());
    tries.push(l);
    tries
}

/// Every group of `open` that is not yet all point masses made point masses at once, when that
/// is more than one group: bodies that turn together (a UPS leg's cylinder and piston) are one
/// rotational inertia in the generated code, which costs fewer flops only once all of them
/// lose theirs.
fn together(current: &Level, open: &[&Vec<String>]) -> Option<Level> {
    let mut l = current.clone();
    let mut groups = 0;
    for g in open {
        groups += usize::from(point_masses(&mut l, g));
    }
    (groups > 1).then_some(l)
}

/// Makes the bodies of `g` point masses in `l`; whether any was not one already.
fn point_masses(l: &mut Level, g: &[String]) -> bool {
    let add: Vec<String> = g
        .iter()
        .filter(|b| !l.point_mass.contains(b))
        .cloned()
        .collect();
    let any = !add.is_empty();
    l.point_mass.extend(add);
    any
}

/// Writes the spec at `level` to `-o` or standard output.
fn write_output(args: &ReduceArgs, source: &str, level: &Level) -> ExitCode {
    let out = if *level == Level::default() {
        source.to_owned()
    } else {
        format!("{source}{}", level.scene())
    };
    match &args.output {
        Some(p) => {
            // Replaced atomically, as the generator's `-o`.
            if let Err(e) = super::write_output(p, &out) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        None => out!("{out}"),
    }
    ExitCode::SUCCESS
}
