//! `codegen excite SPEC`: an exciting trajectory for identification (docs/identification.md,
//! "Exciting trajectories"). Each joint follows a finite Fourier series of period `T`
//! (Swevers et al. 1997),
//! `q_i(t) = Σ_{l=1..L} a_il/(l ω_f) sin(l ω_f t) − b_il/(l ω_f) cos(l ω_f t)`, `ω_f = 2π/T`,
//! periodic and analytic in `q̇` and `q̈`, plus an offset `c_i`: the middle of the joint's range
//! when the spec gives it limits, else 0 ([`super::excite_bounds`]). The coefficients minimize
//! the condition number of the base regressor stacked over the period, subject to
//! `|q_i − c_i| ≤ q_max_i` and `|q̇_i| ≤ q̇_max_i`: a candidate's joints are scaled down until
//! they hold (on a grid of 400 points per period, with a 0.1 % margin), so every candidate is
//! feasible. The search is a coordinate
//! (pattern) search from random starts: each coefficient moved by `± h`, kept when the
//! condition number drops; `h` halves after a sweep without gain. Deterministic for a seed.
//!
//! A platform's series are its coordinates around home ([`super::platform_path`]), bounded by
//! `--turn` (rad) and `--reach` (m); a candidate with a state where the regressor has no value
//! (out of reach, a singularity) is rejected. A closed loop's series are its independent
//! coordinates around home, bounded by `--q-max`; the other coordinates are assembled by Newton
//! from the state before (the first from home), and a candidate that does not assemble or
//! where the regressor fails is rejected.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use nalgebra::DMatrix;

use super::Rng;
use super::excite_bounds::{self, Bounds};
use super::regressor::Regressor;
use super::wls::condition;

/// Arguments of `excite`.
#[derive(Debug, Args)]
// A negative number is a value (refused by the range checks with their message), not a flag.
#[command(allow_negative_numbers = true)]
pub struct ExciteArgs {
    /// Tree (`.toml` or `.urdf`), platform or closed-loop spec.
    pub spec: PathBuf,
    /// Harmonics per joint, `L`.
    #[arg(long, default_value_t = 5)]
    pub harmonics: usize,
    /// Period `T`, s.
    #[arg(long, default_value_t = 10.0)]
    pub period: f64,
    /// Samples written over one period (`t = k T / N`).
    #[arg(long, default_value_t = 1000)]
    pub samples: usize,
    /// Seed of the random starts.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Position bound per joint (rad or m): one value, or one per joint separated by commas
    /// (trees). A joint without limits keeps `|q| <= Q_MAX` (default 1.0). A joint with limits
    /// (TOML `limit`, URDF `<limit>`) moves about the middle `c` of its range with
    /// `|q - c| <= min(half range × (1 - --limit-margin), Q_MAX)`: given here, it bounds
    /// further; not given, the range alone bounds.
    #[arg(long, value_delimiter = ',', value_name = "Q_MAX")]
    pub q_max: Vec<f64>,
    /// The fraction of each limited joint's half range kept free at both ends, in [0, 1).
    #[arg(long, default_value_t = 0.05, value_name = "FRACTION")]
    pub limit_margin: f64,
    /// A platform's bound on each move from home, m.
    #[arg(long, default_value_t = 0.05, value_name = "M")]
    pub reach: f64,
    /// A platform's bound on each of its turn angles from home, rad.
    #[arg(long, default_value_t = 0.1, value_name = "RAD")]
    pub turn: f64,
    /// Velocity bound per joint (rad/s or m/s): one value, or one per joint (a platform's
    /// speeds `u`). Default 2.0 for joints without a velocity limit; a joint with one keeps
    /// `|qd| <= min(velocity, QD_MAX)` (the limit alone when not given).
    #[arg(long, value_delimiter = ',', value_name = "QD_MAX")]
    pub qd_max: Vec<f64>,
    /// Random starts of the search.
    #[arg(long, default_value_t = 3)]
    pub restarts: usize,
    /// Evaluations of the condition number per start.
    #[arg(long, default_value_t = 600)]
    pub evaluations: usize,
    /// States per period at which the condition number is taken during the search.
    #[arg(long, default_value_t = 60)]
    pub search_samples: usize,
    /// Also write `tau1..` from the spec's inverse dynamics (the runtime's: a tree's RNEA and
    /// drives, a platform's `f64` evaluator).
    #[arg(long)]
    pub with_tau: bool,
    /// With `--with-tau`: add Gaussian noise of this standard deviation to the efforts (N·m or
    /// N; one value, or one per joint), to try `identify` on simulated measurements.
    #[arg(long, value_delimiter = ',', requires = "with_tau")]
    pub noise: Vec<f64>,
    /// Seed of the noise (default: `--seed`).
    #[arg(long)]
    pub noise_seed: Option<u64>,
    /// Write the CSV here (default: standard output).
    #[arg(short, long, value_name = "TRAJ.csv")]
    pub output: Option<PathBuf>,
}

/// A Fourier trajectory: coefficients `a` then `b`, `L` each, per joint.
#[derive(Clone, Debug)]
pub struct Fourier {
    /// `2L` per joint: `a_i1..a_iL, b_i1..b_iL`.
    pub c: Vec<f64>,
    /// Joints.
    pub n: usize,
    /// Harmonics.
    pub l: usize,
    /// Fundamental `ω_f`, rad/s.
    pub w: f64,
    /// Offsets `c_i` per joint (rad or m), empty for none.
    pub offset: Vec<f64>,
}

/// `sin` and `cos` of each harmonic's phase `l ω_f t` at given times: the series' only
/// transcendental part, the same for every joint and every candidate of a search (which
/// evaluates the series on the same grids over and over), so taken once per time.
#[derive(Clone, Debug)]
pub struct Phases {
    /// The times, s.
    times: Vec<f64>,
    /// Harmonics.
    l: usize,
    /// `(sin, cos)` of harmonic `h` (from 1) at time `k`: `sc[k * l + h - 1]`.
    sc: Vec<(f64, f64)>,
}

impl Phases {
    /// At the times `t`, fundamental `w`, `l` harmonics.
    fn new(w: f64, l: usize, times: Vec<f64>) -> Phases {
        let sc = times
            .iter()
            .flat_map(|&t| {
                (1..=l).map(move |h| {
                    let wl = w * h as f64;
                    (wl * t).sin_cos()
                })
            })
            .collect();
        Phases { times, l, sc }
    }

    /// At `count` equally spaced times over the period `2π / w`, from 0.
    fn over_period(w: f64, l: usize, count: usize) -> Phases {
        let period = 2.0 * std::f64::consts::PI / w;
        let times = (0..count)
            .map(|k| period * k as f64 / count as f64)
            .collect();
        Phases::new(w, l, times)
    }

    /// Time `k`'s phases.
    fn at(&self, k: usize) -> &[(f64, f64)] {
        &self.sc[k * self.l..(k + 1) * self.l]
    }
}

impl Fourier {
    /// `(q, q̇, q̈)` of joint `i` at `t`.
    #[cfg(test)]
    pub fn joint(&self, i: usize, t: f64) -> (f64, f64, f64) {
        self.joint_at(i, Phases::new(self.w, self.l, vec![t]).at(0))
    }

    /// `(q, q̇, q̈)` of joint `i` at the time of the phases `sc` ([`Phases::at`]).
    fn joint_at(&self, i: usize, sc: &[(f64, f64)]) -> (f64, f64, f64) {
        let (mut q, mut qd, mut qdd) = (0.0, 0.0, 0.0);
        let base = 2 * self.l * i;
        for h in 1..=self.l {
            let (a, b) = (self.c[base + h - 1], self.c[base + self.l + h - 1]);
            let wl = self.w * h as f64;
            let (s, c) = sc[h - 1];
            q += (a * s - b * c) / wl;
            qd += a * c + b * s;
            qdd += wl * (b * c - a * s);
        }
        (q, qd, qdd)
    }

    /// All joints at `t`.
    #[cfg(test)]
    pub fn state(&self, t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        self.state_at(Phases::new(self.w, self.l, vec![t]).at(0))
    }

    /// All joints at the time of the phases `sc`, offsets included (a zero offset is not
    /// added: the sum keeps its sign).
    fn state_at(&self, sc: &[(f64, f64)]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut s = (vec![0.0; self.n], vec![0.0; self.n], vec![0.0; self.n]);
        for i in 0..self.n {
            (s.0[i], s.1[i], s.2[i]) = self.joint_at(i, sc);
            if let Some(&c) = self.offset.get(i)
                && c != 0.0
            {
                s.0[i] += c;
            }
        }
        s
    }

    /// Scale each joint's coefficients so that `|q_i − c_i| ≤ q_max_i` and `|q̇_i| ≤ q̇_max_i` on
    /// `grid` points per period, with a 0.1 % margin.
    #[cfg(test)]
    fn feasible(&self, q_max: &[f64], qd_max: &[f64], grid: usize) -> Fourier {
        self.feasible_on(q_max, qd_max, &Phases::over_period(self.w, self.l, grid))
    }

    /// [`Self::feasible`] on the grid of `phases` ([`Phases::over_period`] of this series'
    /// fundamental and harmonics).
    fn feasible_on(&self, q_max: &[f64], qd_max: &[f64], phases: &Phases) -> Fourier {
        let mut f = self.clone();
        for i in 0..self.n {
            let (mut mq, mut mqd) = (0.0f64, 0.0f64);
            for k in 0..phases.times.len() {
                let (q, qd, _) = self.joint_at(i, phases.at(k));
                mq = mq.max(q.abs());
                mqd = mqd.max(qd.abs());
            }
            let s = (0.999 * q_max[i] / mq)
                .min(0.999 * qd_max[i] / mqd)
                .min(1.0);
            if s.is_finite() {
                for c in &mut f.c[2 * self.l * i..2 * self.l * (i + 1)] {
                    *c *= s;
                }
            }
        }
        f
    }
}

/// The mechanism's state at time `k` of `phases` on `f`; a closed loop assembled from the
/// positions `from` of the state before (home when `None`). `None` where it does not assemble.
fn at(
    reg: &Regressor,
    f: &Fourier,
    phases: &Phases,
    k: usize,
    from: Option<&[f64]>,
) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let (d, dd, ddd) = f.state_at(phases.at(k));
    reg.state(&d, &dd, &ddd, from)
}

/// The base regressor stacked at the times of `phases` ([`Phases::over_period`]); `Err(t)` at
/// the first time where it has no value. The states are taken in order (a closed loop's each
/// assembled from the one before), then the regressor at all of them over lanes
/// ([`Regressor::stack`]), each bit for bit what it is alone.
fn stacked(reg: &Regressor, f: &Fourier, phases: &Phases) -> Result<DMatrix<f64>, f64> {
    let (n, nbp, m) = (reg.dof(), reg.nbp(), phases.times.len());
    let mut p: Vec<Vec<f64>> = Vec::with_capacity(m);
    let (mut v, mut a) = (Vec::with_capacity(m), Vec::with_capacity(m));
    let mut end = None;
    for k in 0..m {
        match at(reg, f, phases, k, p.last().map(Vec::as_slice)) {
            Some((pk, vk, ak)) => {
                p.push(pk);
                v.push(vk);
                a.push(ak);
            }
            None => {
                end = Some(phases.times[k]);
                break;
            }
        }
    }
    let mut w = DMatrix::zeros(m * n, nbp);
    let mut stack = reg.stack(&p, &v, &a);
    for k in 0..p.len() {
        let y = stack.rows(k).map_err(|_| phases.times[k])?;
        for i in 0..n {
            for c in 0..nbp {
                w[(k * n + i, c)] = y[i * nbp + c];
            }
        }
    }
    end.map_or(Ok(w), Err)
}

/// One bound per joint from a list of one or `n` values.
fn per_joint(v: &[f64], n: usize, what: &str) -> Result<Vec<f64>, String> {
    let out = match v.len() {
        1 => vec![v[0]; n],
        k if k == n => v.to_vec(),
        k => {
            return Err(format!(
                "error: {what}: {k} values for {n} joints (give 1 or {n})"
            ));
        }
    };
    if out.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return Err(format!("error: {what}: bounds must be positive and finite"));
    }
    Ok(out)
}

/// The most `--samples` (a CSV of about 0.5 GB for six joints).
const MAX_SAMPLES: usize = 1_000_000;
/// The most `--search-samples`: each of the search's evaluations stacks and decomposes the
/// regressor at that many states.
const MAX_SEARCH_SAMPLES: usize = 10_000;
/// The most states the reported condition number is taken over (evenly spaced over the
/// period; all of them up to this many `--samples`): 10 million states of a Gough–Stewart
/// would stack 42 GB.
const CONDITION_STATES: usize = 20_000;

/// The shortest `--period`, s.
const MIN_PERIOD: f64 = 1e-3;
/// The longest `--period`, s.
const MAX_PERIOD: f64 = 1e5;

/// Check the arguments: the bounds per joint (offsets, `|q − c|`, `|q̇|`), given the tree
/// joints' `limits`; `Err` is the message (exit code 2).
fn check(
    args: &ExciteArgs,
    reg: &Regressor,
    limits: &[Option<codegen::spec::JointLimit>],
) -> Result<Bounds, String> {
    let n = reg.dof();
    if args.harmonics == 0 || args.harmonics > 50 {
        return Err("error: --harmonics must be in 1..=50".into());
    }
    if !(MIN_PERIOD..=MAX_PERIOD).contains(&args.period) {
        return Err(format!(
            "error: --period {:?}: must be in [{MIN_PERIOD}, {MAX_PERIOD:e}] s (beyond, the accelerations or the motion per sample are lost to rounding)",
            args.period
        ));
    }
    let min = reg.nbp() / n.max(1) + 1;
    if args.samples < min || args.samples > MAX_SAMPLES {
        return Err(format!(
            "error: --samples {}: must be in {min}..={MAX_SAMPLES} (the regressor needs at least {min} states)",
            args.samples
        ));
    }
    if args.search_samples < min || args.search_samples > MAX_SEARCH_SAMPLES {
        return Err(format!(
            "error: --search-samples {}: must be in {min}..={MAX_SEARCH_SAMPLES}",
            args.search_samples
        ));
    }
    if args.restarts == 0 || args.restarts > 1000 || args.evaluations > 10_000_000 {
        return Err("error: --restarts must be in 1..=1000 and --evaluations at most 1e7".into());
    }
    let k = args.noise.len();
    if !(k == 0 || k == 1 || k == n) {
        return Err(format!(
            "error: --noise: {k} values for {n} joints (give 1 or {n})"
        ));
    }
    if args.noise.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err("error: --noise: standard deviations must be finite and >= 0".into());
    }
    let given = |v: &[f64], what: &str| -> Result<Option<Vec<f64>>, String> {
        if v.is_empty() {
            Ok(None)
        } else {
            per_joint(v, n, what).map(Some)
        }
    };
    let q_given = given(&args.q_max, "--q-max")?;
    let qd_given = given(&args.qd_max, "--qd-max")?;
    if !(0.0..1.0).contains(&args.limit_margin) {
        return Err(format!(
            "error: --limit-margin {:?}: must be in [0, 1) (a fraction of the half range)",
            args.limit_margin
        ));
    }
    if reg.turns(0).is_none() && limits.iter().any(Option::is_some) {
        return Ok(excite_bounds::tree(
            limits,
            q_given.as_deref(),
            qd_given.as_deref(),
            args.limit_margin,
        ));
    }
    let q_max = match reg.turns(0) {
        None => q_given.unwrap_or(vec![excite_bounds::Q_MAX; n]),
        Some(_) => {
            let reach = per_joint(&[args.reach], 1, "--reach")?[0];
            let turn = per_joint(&[args.turn], 1, "--turn")?[0];
            (0..n)
                .map(|j| {
                    if reg.turns(j) == Some(true) {
                        turn
                    } else {
                        reach
                    }
                })
                .collect()
        }
    };
    Ok(Bounds {
        centre: Vec::new(),
        q: q_max,
        qd: qd_given.unwrap_or(vec![excite_bounds::QD_MAX; n]),
        line: String::new(),
    })
}

/// Run `excite`.
pub fn run(args: &ExciteArgs) -> ExitCode {
    let (name, source) = match super::read_spec(&args.spec) {
        Ok(r) => r,
        Err(c) => return c,
    };
    // A URDF's `ROBOT.scene.toml` applies here as in generation (friction, rotor inertia,
    // locked joints change the parameters).
    let sidecar = match super::sidecar(&args.spec, None) {
        Ok(s) => s,
        Err(c) => return c,
    };
    let (reg, warnings, limits) = match Regressor::compile_with_limits(&name, &source, sidecar) {
        Ok(r) => r,
        Err(e) => {
            eprint!("{e}");
            return ExitCode::from(2);
        }
    };
    if !warnings.is_empty() {
        eprint!("{warnings}");
    }
    // The scene file read beside a URDF is an input too: `-o` onto it replaced it (QA).
    let scene_in = codegen::build_script::scene_beside(&args.spec);
    let inputs = super::spec_inputs(&args.spec, scene_in.as_deref());
    if let Err(c) = super::distinct_outputs(&inputs, &[("-o", args.output.as_deref())]) {
        return c;
    }
    let bounds = match check(args, &reg, &limits) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    eprintln!(
        "excite: {} ({}): {} base parameters of {} standard, {} {}{}",
        reg.mechanism(),
        reg.kind(),
        reg.nbp(),
        reg.standard_count(),
        reg.dof(),
        reg.effort_kind(),
        if reg.dof() == 1 { "" } else { "s" }
    );
    if !bounds.line.is_empty() {
        eprintln!("{}", bounds.line);
    }
    let (best_cost, best) = search(&reg, args, &bounds);
    let n = reg.dof();
    let columns = reg.columns();
    let mut csv = String::from("t");
    for k in 0..if args.with_tau { 4 } else { 3 } {
        for i in 1..=columns.counts[k] {
            csv.push_str(&format!(",{}{i}", columns.kinds[k]));
        }
    }
    csv.push('\n');
    let sigma: Vec<f64> = match args.noise.len() {
        0 => vec![0.0; n],
        1 => vec![args.noise[0]; n],
        _ => args.noise.clone(),
    };
    let mut noise = Rng::new(args.noise_seed.unwrap_or(args.seed) ^ 0x006e_6f69_7365);
    let (mut mq, mut mqd) = (vec![0.0f64; n], vec![0.0f64; n]);
    let cond_states = args.samples.min(CONDITION_STATES);
    let cond = match stacked(
        &reg,
        &best,
        &Phases::over_period(best.w, best.l, cond_states),
    ) {
        Ok(w) => condition(&w),
        Err(t) => {
            // The bounds that shrink the motion: a platform's are --reach and --turn, a tree's
            // and a closed loop's (its independent coordinates) --q-max and --qd-max.
            let bounds = match reg {
                Regressor::Platform(_) => "reduce --reach or --turn",
                _ => "reduce --q-max or --qd-max",
            };
            if best_cost == f64::MAX {
                eprintln!(
                    "error: no trajectory the search tried stays in the workspace (each leaves it or meets a singularity; the best at t = {t} s): {bounds}"
                );
            } else {
                eprintln!(
                    "error: the best trajectory found leaves the workspace or meets a singularity at t = {t} s (between the search's samples): {bounds}, or raise --search-samples"
                );
            }
            return ExitCode::from(2);
        }
    };
    // A regressor singular at every state excites nothing (`--q-max 1e-300`: every entry
    // underflows): no file to identify from.
    if !cond.is_finite() {
        eprintln!(
            "error: the best trajectory found excites no base parameter set (the stacked base regressor is singular, condition number {cond:e}): widen --q-max, --qd-max, --reach or --turn"
        );
        return ExitCode::from(2);
    }
    let mut from: Option<Vec<f64>> = None;
    for k in 0..args.samples {
        let t = args.period * k as f64 / args.samples as f64;
        let phases = Phases::new(best.w, best.l, vec![t]);
        let (d, dd, _) = best.state_at(phases.at(0));
        // Assembled where `stacked` assembled it above (the same states in the same order).
        let Some((q, qd, qdd)) = at(&reg, &best, &phases, 0, from.as_deref()) else {
            eprintln!("error: the loops do not close at t = {t} s");
            return ExitCode::from(2);
        };
        let mut row = vec![t];
        row.extend(reg.written_positions(&q));
        row.extend(&qd);
        row.extend(&qdd);
        if args.with_tau {
            let Some(tau) = reg.inverse_dynamics(&q, &qd, &qdd) else {
                eprintln!("error: the runtime's inverse dynamics fails at t = {t} s");
                return ExitCode::from(2);
            };
            row.extend(tau.iter().zip(&sigma).map(|(t, s)| {
                if *s > 0.0 {
                    t + s * gauss(&mut noise)
                } else {
                    *t
                }
            }));
        }
        if let Some(v) = row.iter().find(|v| !v.is_finite()) {
            eprintln!(
                "error: at t = {t} s a value of the trajectory is {v} (--noise {:?}, --q-max, --qd-max or --period too large)",
                args.noise
            );
            return ExitCode::from(2);
        }
        from = Some(q);
        for i in 0..n {
            mq[i] = mq[i].max(d[i].abs());
            mqd[i] = mqd[i].max(dd[i].abs());
        }
        let line: Vec<String> = row.iter().map(|v| format!("{v}")).collect();
        csv.push_str(&line.join(","));
        csv.push('\n');
    }
    eprintln!(
        "excite: {}: {} harmonics, period {} s, {} samples: condition number of the stacked base regressor {cond:.4e}{}; max |{}| {}; max |{}| {}",
        reg.mechanism(),
        args.harmonics,
        args.period,
        args.samples,
        if cond_states < args.samples {
            format!(" (over {cond_states} evenly spaced states)")
        } else {
            String::new()
        },
        if reg.turns(0).is_some() { "d" } else { "q" },
        fmt_list(&mq),
        if reg.turns(0).is_some() { "dd" } else { "qd" },
        fmt_list(&mqd)
    );
    match &args.output {
        Some(p) => {
            if let Err(e) = super::write_output(p, &csv) {
                eprintln!("error: {e}");
                return ExitCode::from(1);
            }
        }
        None => out!("{csv}"),
    }
    ExitCode::SUCCESS
}

/// A standard normal number (Box–Muller).
fn gauss(r: &mut Rng) -> f64 {
    let u1 = r.uniform(0.0, 1.0).max(1e-300);
    let u2 = r.uniform(0.0, 1.0);
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

fn fmt_list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:.3}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The random starts and coordinate search; progress on standard error.
/// The best trajectory and its cost (`f64::MAX` when no candidate had a regressor at every
/// search sample).
fn search(reg: &Regressor, args: &ExciteArgs, bounds: &Bounds) -> (f64, Fourier) {
    let (q_max, qd_max, offset) = (&bounds.q, &bounds.qd, &bounds.centre);
    const GRID: usize = 400;
    let n = reg.dof();
    let l = args.harmonics;
    let w = 2.0 * std::f64::consts::PI / args.period;
    let mut rng = Rng::new(args.seed);
    // A coefficient's natural size: the velocity amplitude that reaches the bound.
    let unit: Vec<f64> = (0..n).map(|i| (q_max[i] * w).min(qd_max[i])).collect();
    // The grids every candidate is evaluated on.
    let (grid, samples) = (
        Phases::over_period(w, l, GRID),
        Phases::over_period(w, l, args.search_samples),
    );
    // A trajectory where the regressor has no value somewhere is rejected.
    let cost = |f: &Fourier| {
        let c = stacked(reg, f, &samples).map_or(f64::MAX, |w| condition(&w));
        if c.is_finite() { c } else { f64::MAX }
    };
    let mut best: Option<(f64, Fourier)> = None;
    for r in 0..args.restarts {
        let c: Vec<f64> = (0..n * 2 * l)
            .map(|k| unit[k / (2 * l)] * rng.uniform(-1.0, 1.0))
            .collect();
        let mut cur = Fourier {
            c,
            n,
            l,
            w,
            offset: offset.clone(),
        }
        .feasible_on(q_max, qd_max, &grid);
        let mut fc = cost(&cur);
        let mut evals = 1;
        let mut h = 0.5;
        let mut sweep = 0;
        'search: while h > 1e-3 {
            let mut gained = false;
            for k in 0..cur.c.len() {
                for sign in [1.0, -1.0] {
                    if evals >= args.evaluations {
                        break 'search;
                    }
                    let mut t = cur.clone();
                    t.c[k] += sign * h * unit[k / (2 * l)];
                    let t = t.feasible_on(q_max, qd_max, &grid);
                    let ft = cost(&t);
                    evals += 1;
                    if ft < fc {
                        (cur, fc, gained) = (t, ft, true);
                        break;
                    }
                }
            }
            sweep += 1;
            eprintln!(
                "excite: start {}/{}, sweep {sweep}: step {h:.4}, condition number {fc:.4e} ({evals} evaluations)",
                r + 1,
                args.restarts
            );
            if !gained {
                h *= 0.5;
            }
        }
        eprintln!(
            "excite: start {}/{} done: condition number {fc:.4e} after {evals} evaluations",
            r + 1,
            args.restarts
        );
        if best.as_ref().is_none_or(|(b, _)| fc < *b) {
            best = Some((fc, cur));
        }
    }
    match best {
        Some(b) => b,
        None => (
            f64::MAX,
            Fourier {
                c: vec![0.0; n * 2 * l],
                n,
                l,
                w,
                offset: offset.clone(),
            },
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_are_those_of_the_series_and_bounds_hold() {
        let f = Fourier {
            c: vec![0.3, -0.2, 0.5, 0.1, 1.0, 2.0, -0.4, 0.7],
            n: 2,
            l: 2,
            w: 0.7,
            offset: Vec::new(),
        };
        let (t, h) = (1.3, 1e-5);
        for i in 0..2 {
            let (q0, qd, qdd) = f.joint(i, t);
            let (qp, qdp, _) = f.joint(i, t + h);
            let (qm, qdm, _) = f.joint(i, t - h);
            assert!(((qp - qm) / (2.0 * h) - qd).abs() < 1e-8, "{q0}");
            assert!(((qdp - qdm) / (2.0 * h) - qdd).abs() < 1e-8);
        }
        let g = f.feasible(&[0.1, 0.1], &[0.05, 10.0], 400);
        for k in 0..1000 {
            let (q, qd, _) = g.state(9.0 * k as f64 / 1000.0);
            assert!(q.iter().all(|x| x.abs() <= 0.1 * 1.0001));
            assert!(qd[0].abs() <= 0.05 * 1.0001);
        }
    }
}
