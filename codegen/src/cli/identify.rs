//! `codegen identify SPEC data.csv`: the base parameters of a tree, a platform or a closed loop
//! from measured motions and efforts by weighted least squares, with their standard
//! deviations, the regressor's condition number, warnings for parameters the data do not excite, and (`--out`) the spec
//! updated so that its model has the identified base parameters (docs/identification.md).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, ValueEnum};
use nalgebra::{DMatrix, DVector};

use super::effort_plot::{EffortPlot, Panel};
use super::regressor::Regressor;
use super::samples::{self, Filtering};
use super::wls::{self, Stacked};

/// How the rows are weighted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Weights {
    /// Per joint by `1/σ_j`, `σ_j` the noise estimated from an ordinary least-squares pass.
    Auto,
    /// Ordinary least squares.
    None,
}

/// Arguments of `identify`.
#[derive(Debug, Args)]
// A negative number is a value (refused by the range checks with their message), not a flag.
#[command(allow_negative_numbers = true)]
pub struct IdentifyArgs {
    /// Tree (`.toml` or `.urdf`), platform or closed-loop spec whose base parameters are
    /// identified.
    pub spec: PathBuf,
    /// Measurements: CSV with a header `t,q1..,qd1..,qdd1..,tau1..` (or `t,q1..,tau1..`); a
    /// platform's `t,x1..,u1..,ud1..,tau1..`; a closed loop's `t,q1..,u1..,ud1..,tau1..` (the
    /// independent coordinates) or `t,x1..xNX,u1..,ud1..,tau1..`.
    pub data: PathBuf,
    /// Write the spec updated to the identified base parameters here (a URDF's: the URDF with
    /// its `<inertial>` and `<dynamics>` values replaced, and its scene file beside it).
    #[arg(long, value_name = "UPDATED.toml|UPDATED.urdf")]
    pub out: Option<PathBuf>,
    /// Row weights.
    #[arg(long, value_enum, default_value = "auto")]
    pub weights: Weights,
    /// Positions-only data: cutoff of the zero-phase low-pass before differentiating, Hz.
    #[arg(long, default_value_t = 5.0, value_name = "HZ")]
    pub cutoff: f64,
    /// Warn when a parameter's relative standard deviation exceeds this, percent.
    #[arg(long, default_value_t = 10.0, value_name = "PERCENT")]
    pub max_rel_std: f64,
    /// Also write the estimates as CSV (`k,name,spec,estimate,std`, full precision).
    #[arg(long, value_name = "FILE.csv")]
    pub estimates: Option<PathBuf>,
    /// Also plot measured against predicted efforts per joint (SVG; time on x when the data
    /// have `t`, else the sample index).
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
}

/// The largest data file `identify` reads (a 50 MB file of a 6-joint arm takes 0.8 GB and
/// 4 s).
const MAX_DATA_BYTES: u64 = 256 << 20;

/// The largest magnitude of a regressor entry or an effort that `identify` takes.
const MAX_MAGNITUDE: f64 = 1e150;

/// Run `identify`.
pub fn run(args: &IdentifyArgs) -> ExitCode {
    let (name, source) = match super::read_spec(&args.spec) {
        Ok(r) => r,
        Err(c) => return c,
    };
    if !(args.max_rel_std > 0.0 && args.max_rel_std.is_finite()) {
        eprintln!("error: --max-rel-std must be a positive percentage");
        return ExitCode::from(2);
    }
    if !(args.cutoff > 0.0 && args.cutoff.is_finite()) {
        eprintln!("error: --cutoff must be a positive frequency in Hz");
        return ExitCode::from(2);
    }
    // A URDF's update is a URDF: the tools tell a spec's format by its name.
    if let Some(out) = &args.out
        && super::spec_update::is_urdf(&name, &source)
        && !out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
    {
        eprintln!(
            "error: --out {}: the update of a URDF is a URDF: name it `….urdf` (the tools tell a spec's format by its name)",
            out.display()
        );
        return ExitCode::from(2);
    }
    // And a TOML spec's update is TOML: named `….urdf`, it was written with exit 0 and then
    // read as XML by every tool (QA).
    if let Some(out) = &args.out
        && !super::spec_update::is_urdf(&name, &source)
        && out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
    {
        eprintln!(
            "error: --out {}: the update of a TOML spec is a TOML spec: do not name it `….urdf` (the tools tell a spec's format by its name)",
            out.display()
        );
        return ExitCode::from(2);
    }
    // The scene file read beside a URDF is an input too: `--estimates` or `--plot` onto it
    // replaced it, exit 0 (QA). A URDF's `--out` takes its scene file beside it.
    let scene_in = codegen::build_script::scene_beside(&args.spec);
    let scene_out = args
        .out
        .as_ref()
        .filter(|_| scene_in.is_some())
        .map(|o| o.with_extension("scene.toml"));
    let mut inputs = super::spec_inputs(&args.spec, scene_in.as_deref());
    inputs.push(("the data file", &args.data));
    if let Err(c) = super::distinct_outputs(
        &inputs,
        &[
            ("--out", args.out.as_deref()),
            ("--out's scene file", scene_out.as_deref()),
            ("--estimates", args.estimates.as_deref()),
            ("--plot", args.plot.as_deref()),
        ],
    ) {
        return c;
    }
    // A URDF's `ROBOT.scene.toml` applies here as in generation (friction, rotor inertia,
    // locked joints change the parameters).
    let sidecar = match super::sidecar(&args.spec, None) {
        Ok(s) => s,
        Err(c) => return c,
    };
    let (reg, warnings) = match Regressor::compile(&name, &source, sidecar.clone()) {
        Ok(r) => r,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::from(2);
        }
    };
    if !warnings.is_empty() {
        eprint!("{warnings}");
    }
    let data_name = args.data.to_string_lossy().into_owned();
    let read = std::fs::File::open(&args.data).and_then(|f| {
        use std::io::Read;
        let mut b = Vec::new();
        f.take(MAX_DATA_BYTES + 1).read_to_end(&mut b).map(|_| b)
    });
    if read.as_ref().is_ok_and(|b| b.len() as u64 > MAX_DATA_BYTES) {
        eprintln!(
            "error: {data_name}: larger than {} MiB (an endless device such as /dev/zero, or more samples than identify holds in memory: subsample the file)",
            MAX_DATA_BYTES >> 20
        );
        return ExitCode::from(2);
    }
    let text = match read {
        Ok(b) => match String::from_utf8(b) {
            Ok(t) => t,
            Err(e) => {
                let ok = &e.as_bytes()[..e.utf8_error().valid_up_to()];
                let line = ok.iter().filter(|b| **b == b'\n').count() + 1;
                let start = ok.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
                let column = String::from_utf8_lossy(&ok[start..]).chars().count() + 1;
                eprintln!(
                    "error: {data_name}:{line}:{column}: not UTF-8 text (byte 0x{:02x}; save the file as UTF-8)",
                    e.as_bytes()[ok.len()]
                );
                return ExitCode::from(2);
            }
        },
        Err(e) => {
            eprintln!("error: cannot read {data_name}: {e}");
            return ExitCode::from(1);
        }
    };
    let (n, nbp) = (reg.dof(), reg.nbp());
    // A platform's positions-only data (`t, x, tau`): `x` filtered and differentiated as a
    // tree's positions, then its rates turned into the speeds (`platform_rates`).
    let mut columns = reg.columns_of(&text);
    if matches!(reg, Regressor::Platform(_)) {
        columns.differentiable = true;
    }
    let mut data = match samples::read(
        &data_name,
        &text,
        &columns,
        nbp / n.max(1) + 1,
        Filtering {
            cutoff: args.cutoff,
        },
    ) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    if let Regressor::Platform(r) = &reg
        && data.note.is_some()
    {
        if let Err(e) = super::platform_rates::speeds(r.model.motion, &data_name, &mut data) {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
        if let Some(note) = &mut data.note {
            note.push_str(super::platform_rates::NOTE);
        }
    }
    if let Err(e) = reg.assemble_positions(&data_name, &mut data) {
        eprintln!("{e}");
        return ExitCode::from(2);
    }
    let rows = data.q.len();
    let mut w = DMatrix::zeros(rows * n, nbp);
    let mut tau = DVector::zeros(rows * n);
    let mut stack = reg.stack(&data.q, &data.qd, &data.qdd);
    for s in 0..rows {
        let y = stack.rows(s);
        if let Err(e) = &y {
            eprintln!(
                "error: {data_name}:{}: no regressor at this state: {} (remove the row, or check the columns' order and units)",
                data.lines[s], e.0
            );
            return ExitCode::from(2);
        }
        let y = y.unwrap_or_default();
        // Squares of larger numbers overflow in the least squares (and the SVD does not
        // return on what follows): no unit makes such values measurements.
        if let Some(v) = y
            .iter()
            .chain(&data.tau[s])
            .find(|v| v.is_nan() || v.abs() > MAX_MAGNITUDE)
        {
            eprintln!(
                "error: {data_name}:{}: the regressor or the efforts reach {v:e} at this state, beyond {MAX_MAGNITUDE:e} (check the columns' order and units)",
                data.lines[s]
            );
            return ExitCode::from(2);
        }
        for i in 0..n {
            for k in 0..nbp {
                w[(s * n + i, k)] = y[i * nbp + k];
            }
            tau[s * n + i] = data.tau[s][i];
        }
    }
    if let Some((cutoff, fs)) = data.parallel {
        parallel_filter(&mut w, &mut tau, n, cutoff, fs);
    }
    let stacked = Stacked { w, tau, n };
    let fit = wls::fit(&stacked, args.weights == Weights::Auto);
    if !fit
        .estimate
        .iter()
        .chain(&fit.std)
        .chain(&fit.residual_rms)
        .chain(&fit.sigma)
        .all(|v| v.is_finite())
    {
        eprintln!(
            "error: {data_name}: the least squares of these data overflow (values too far apart in magnitude: check the columns' units)"
        );
        return ExitCode::from(2);
    }
    report(&reg, &name, &data_name, rows, &data.note, &fit, args);
    if let Some(path) = &args.estimates {
        let mut csv = String::from("k,name,spec,estimate,std\n");
        for k in 0..nbp {
            csv.push_str(&format!(
                "{k},\"{}\",{},{},{}\n",
                reg.names()[k],
                reg.values()[k],
                fit.estimate[k],
                fit.std[k]
            ));
        }
        if let Err(e) = super::write_output(path, &csv) {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    }
    if let Some(path) = &args.plot {
        let predicted = &stacked.w * DVector::from_column_slice(&fit.estimate);
        let names = reg.effort_names();
        let panels: Vec<Panel> = (0..n)
            .map(|i| Panel {
                name: names[i].clone(),
                measured: (0..rows).map(|s| stacked.tau[s * n + i]).collect(),
                predicted: (0..rows).map(|s| predicted[s * n + i]).collect(),
            })
            .collect();
        let timed = data.t.len() == rows;
        let xs: Vec<f64> = if timed {
            data.t.clone()
        } else {
            (0..rows).map(|s| s as f64).collect()
        };
        let title = format!(
            "{}: measured and predicted {} efforts ({data_name}, {rows} samples)",
            reg.mechanism(),
            reg.effort_kind()
        );
        let plot = EffortPlot {
            title: &title,
            x_label: if timed { "t (s)" } else { "sample" },
            xs: &xs,
            panels: &panels,
        };
        if let Err(e) = plot.write(path) {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    }
    if let Some(path) = &args.out {
        return write_update(&reg, &name, &source, sidecar.as_ref(), &fit, path);
    }
    ExitCode::SUCCESS
}

/// The table of estimates, the condition number, warnings and residuals.
fn report(
    reg: &Regressor,
    name: &str,
    data_name: &str,
    rows: usize,
    note: &Option<String>,
    fit: &wls::Fit,
    args: &IdentifyArgs,
) {
    let (n, nbp) = (reg.dof(), reg.nbp());
    outln!(
        "identify: {} ({name}) from {data_name}: {rows} sample{} x {n} {}{}, {nbp} base parameters, {}",
        reg.mechanism(),
        if rows == 1 { "" } else { "s" },
        reg.effort_kind(),
        if n == 1 { "" } else { "s" },
        match args.weights {
            Weights::Auto =>
                "rows weighted by 1/sigma_j per joint (sigma_j from an ordinary least-squares pass)",
            Weights::None => "ordinary least squares",
        }
    );
    if let Some(note) = note {
        outln!("data: {note}");
    }
    outln!(
        "condition number of the {}stacked regressor: {:.4e}",
        if args.weights == Weights::Auto {
            "weighted "
        } else {
            ""
        },
        fit.condition
    );
    outln!(
        "{:>4} {:>14} {:>14} {:>12} {:>10}  name",
        "k",
        "spec",
        "estimate",
        "std",
        "rel.std%"
    );
    let mut warnings = Vec::new();
    // Below this the estimate is zero to rounding and its relative deviation meaningless.
    let tiny = 1e-12 * fit.estimate.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for k in 0..nbp {
        let rel = if fit.estimate[k].abs().max(fit.std[k]) <= tiny {
            0.0
        } else {
            100.0 * fit.std[k] / fit.estimate[k].abs()
        };
        outln!(
            "{k:>4} {:>14.6e} {:>14.6e} {:>12.4e} {:>10.3}  {}",
            reg.values()[k],
            fit.estimate[k],
            fit.std[k],
            rel,
            reg.names()[k]
        );
        if fit.unidentifiable[k] {
            warnings.push(format!(
                "warning: base parameter {k} ({}) lies in a near-null direction of the data: not excited, its estimate is the minimum-norm one",
                reg.names()[k]
            ));
        } else if rel.is_nan() || rel > args.max_rel_std {
            warnings.push(format!(
                "warning: base parameter {k} ({}): relative std {rel:.3}% > {}%: poorly excited by the data (or negligible)",
                reg.names()[k],
                args.max_rel_std
            ));
        }
    }
    let efforts = reg.effort_names();
    let joint = |i: usize| &efforts[i];
    outln!(
        "residual RMS per joint (N·m or N): {}",
        (0..n)
            .map(|i| format!("{} {:.4e}", joint(i), fit.residual_rms[i]))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if args.weights == Weights::Auto {
        outln!(
            "noise estimate sigma_j (the weights' inverse): {}",
            (0..n)
                .map(|i| format!("{} {:.4e}", joint(i), fit.sigma[i]))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    for w in warnings {
        eprintln!("{w}");
    }
}

/// How far base parameters `a` that equal `b` in exact arithmetic but were computed along
/// another route (a spec and the same spec written back as numbers) are from `b`:
/// `max_k |a_k − b_k| / max(|b_k|, 1e-4 ‖b‖∞)`, to compare with `1e-9`. A parameter that is
/// zero in exact arithmetic (a Delta's elbow-cross first moments, a pattern's turned mass
/// centres) comes out as rounding noise of the terms grouped into it, about `1e-17 ‖b‖∞`,
/// differently on each route: [`relative_mismatch`]'s floor of `1e-9 ‖b‖∞` would hold it to
/// `1e-18 ‖b‖∞`, below one rounding of the largest, and refuse a spec whose numbers do read
/// back exactly. The floor here allows `1e-13 ‖b‖∞` on such entries and keeps every parameter
/// above it to `1e-9` relative.
pub fn rounding_mismatch(a: &[f64], b: &[f64]) -> f64 {
    let scale = 1e-4 * b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (0..b.len())
        .map(|k| (a[k] - b[k]).abs() / b[k].abs().max(scale).max(f64::MIN_POSITIVE))
        .fold(0.0, f64::max)
}

/// `max_k |a_k − b_k| / max(|b_k|, 1e-9 ‖b‖∞)` over the `keep` entries: relative, except for
/// entries that are zero to the precision of the largest.
pub fn relative_mismatch(a: &[f64], b: &[f64], keep: &[bool]) -> f64 {
    let scale = 1e-9 * b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (0..b.len())
        .filter(|&k| keep[k])
        .map(|k| (a[k] - b[k]).abs() / b[k].abs().max(scale).max(f64::MIN_POSITIVE))
        .fold(0.0, f64::max)
}

/// Gautier's parallel filtering of positions-only data: each joint's efforts and every column
/// of its regressor rows (`w`, `tau` stacked `n` rows per sample) through the same zero-phase
/// low-pass over the samples. The filter is linear, so `τ = Y π` holds after it as before: the
/// band the filter cuts from the efforts (their harmonics above the motion's, made by the
/// dynamics' products of rates) is cut from the model too, and only the in-band error of the
/// differentiated positions is left (docs/identification.md, "The CSV format").
fn parallel_filter(w: &mut DMatrix<f64>, tau: &mut DVector<f64>, n: usize, cutoff: f64, fs: f64) {
    let rows = tau.len() / n.max(1);
    let mut series = vec![0.0; rows];
    for i in 0..n {
        for s in 0..rows {
            series[s] = tau[s * n + i];
        }
        super::filter::filtfilt(&mut series, cutoff, fs);
        for s in 0..rows {
            tau[s * n + i] = series[s];
        }
        for k in 0..w.ncols() {
            for s in 0..rows {
                series[s] = w[(s * n + i, k)];
            }
            super::filter::filtfilt(&mut series, cutoff, fs);
            for s in 0..rows {
                w[(s * n + i, k)] = series[s];
            }
        }
    }
}

/// Write the updated spec and report its physical consistency.
fn write_update(
    reg: &Regressor,
    name: &str,
    source: &str,
    sidecar: Option<&codegen::spec::SceneFile>,
    fit: &wls::Fit,
    path: &std::path::Path,
) -> ExitCode {
    let identified: Vec<bool> = fit.unidentifiable.iter().map(|u| !u).collect();
    let update = super::spec_update::update(reg, name, source, sidecar, &fit.estimate, &identified);
    let up = match update {
        Ok(u) => u,
        Err(e) if e.starts_with("error:") => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
        Err(e) => {
            // A body no rigid body can be (`body `b`: mass -0.3 kg < 0`).
            eprintln!(
                "error: --out {}: the estimates give {e}: no spec can hold them (no file written; see the warnings above)",
                path.display()
            );
            return ExitCode::from(2);
        }
    };
    for s in &up.skipped {
        eprintln!(
            "note: {s}: not plain numbers (expressions, angle strings), which the update cannot rewrite: the body is left unchanged (write its mass, com and inertia as numbers to have it updated)"
        );
    }
    let reproduced: Vec<bool> = (0..identified.len())
        .map(|k| identified[k] && !up.unreachable.contains(&k))
        .collect();
    let worst = relative_mismatch(&up.written, &fit.estimate, &reproduced);
    outln!(
        "updated spec: {} (changed: {}); its base parameters match the estimates to {worst:.2e} (relative)",
        path.display(),
        if up.changed.is_empty() {
            "nothing".to_string()
        } else {
            up.changed.join(", ")
        }
    );
    if !up.unreachable.is_empty() {
        eprintln!(
            "note: no number the update writes moves base parameter{} {} (kept at the spec's value{}): a U joint's `cross` written with expressions (left unchanged), what a parallelogram's equal rods cannot have (a first moment along the motor axis, products of inertia with it: unequal rods), or a drive",
            if up.unreachable.len() == 1 { "" } else { "s" },
            up.unreachable
                .iter()
                .map(|k| format!("{k} ({})", reg.names()[*k]))
                .collect::<Vec<_>>()
                .join(", "),
            if up.unreachable.len() == 1 { "" } else { "s" },
        );
    }
    if worst > 1e-6 {
        let off: Vec<String> = (0..reproduced.len())
            .filter(|&k| {
                let mut one = vec![false; reproduced.len()];
                one[k] = reproduced[k];
                relative_mismatch(&up.written, &fit.estimate, &one) > 1e-6
            })
            .map(|k| format!("{k} ({})", reg.names()[k]))
            .collect();
        eprintln!(
            "warning: the spec's numbers cannot reproduce base parameters {} (worst relative difference {worst:.2e}; the update is their least-squares fit): a drive whose scene switch is off, or numbers one spec entry sets for several model joints (a U joint's two axes)?",
            off.join(", ")
        );
    }
    for (body, what, involved) in &up.violations {
        // `[scene] payload` is named as written, the bodies as `body `…``.
        let body = if body.starts_with('[') {
            body.clone()
        } else {
            format!("body `{body}`")
        };
        eprintln!(
            "warning: {body} of the updated spec is not physical: {what}; base parameters involved: {}",
            involved
                .iter()
                .map(|k| format!("{k} ({})", reg.names()[*k]))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    if up.violations.is_empty() {
        outln!(
            "physical consistency: every body of the updated spec has mass >= 0 and a positive definite inertia that satisfies the triangle inequality"
        );
    }
    if let Err(e) = super::write_output(path, &up.text) {
        eprintln!("error: {e}");
        return ExitCode::from(1);
    }
    // A URDF's scene file goes beside the written URDF, where the tools look for it
    // (`ROBOT.scene.toml`): the written model is the URDF with that scene (its `armature`
    // updated).
    if let Some(scene) = sidecar {
        let beside = path.with_extension("scene.toml");
        let text = up.scene.as_deref().unwrap_or(&scene.text);
        if let Err(e) = super::write_output(&beside, text) {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
        let what = if text == scene.text {
            "the scene"
        } else {
            "the scene, its armature updated,"
        };
        outln!(
            "scene file: {} ({what} of {}, which the updated URDF's model needs)",
            beside.display(),
            scene.name
        );
    }
    ExitCode::SUCCESS
}
