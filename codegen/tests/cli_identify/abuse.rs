//! Bad input a stranger feeds `identify`, `excite` and the generation flags, found by driving the
//! release binary by hand: each case once panicked, hung, printed NaN, overwrote an input, or
//! read what the docs say it ignores. Every run here is bounded by a timeout, so a regression
//! to a hang fails instead of stalling the suite.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use super::{ok, s, scratch, text};

const TWO_R: &str = "../mechanisms/specs/planar_2r.toml";
const DELTA: &str = "../mechanisms/specs/delta_rl5.toml";
const FOUR_BAR: &str = "../mechanisms/specs/four_bar.toml";
const GOUGH: &str = "../mechanisms/specs/gough_stewart.toml";

/// `codegen ARGS`, killed after `limit` (then `None`).
fn run_for(args: &[&str], limit: Duration) -> Option<Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_codegen"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the codegen binary runs");
    // Drained beside the wait, so that a full pipe never blocks the child.
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let o = std::thread::spawn(move || {
        let mut b = Vec::new();
        out.read_to_end(&mut b).map(|_| b)
    });
    let e = std::thread::spawn(move || {
        let mut b = Vec::new();
        err.read_to_end(&mut b).map(|_| b)
    });
    let start = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break Some(st);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let (stdout, stderr) = (o.join().unwrap().unwrap(), e.join().unwrap().unwrap());
    status.map(|status| Output {
        status,
        stdout,
        stderr,
    })
}

/// A run that must end within 60 s (a debug build on a busy machine; the release build takes
/// well under a second for each of these).
fn run(args: &[&str]) -> Output {
    run_for(args, Duration::from_secs(60)).unwrap_or_else(|| panic!("{args:?}: no end in 60 s"))
}

/// Exit code 2, no panic, no NaN, and `want` in the message.
fn rejected(args: &[&str], want: &str) -> String {
    let o = run(args);
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(!text(&o.stdout).contains("NaN"), "{args:?}");
    assert!(err.contains(want), "{args:?}: want {want:?} in\n{err}");
    err
}

/// Simulated measurements of the planar 2R arm (`t, q, qd, qdd, tau`): header and rows.
fn two_r_data(dir: &Path) -> (String, Vec<String>) {
    let path = dir.join("two_r.csv");
    ok(&run(&[
        "excite",
        TWO_R,
        "--restarts",
        "1",
        "--evaluations",
        "20",
        "--samples",
        "200",
        "--with-tau",
        "-o",
        s(&path),
    ]));
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines().map(str::to_owned);
    (lines.next().unwrap(), lines.collect())
}

/// The rows with column `c` of each replaced by `f(row index, old value)`.
fn with_column(rows: &[String], c: usize, f: impl Fn(usize, &str) -> String) -> Vec<String> {
    rows.iter()
        .enumerate()
        .map(|(k, r)| {
            let mut x: Vec<String> = r.split(',').map(str::to_owned).collect();
            x[c] = f(k, &x[c]);
            x.join(",")
        })
        .collect()
}

fn write(dir: &Path, name: &str, header: &str, rows: &[String]) -> String {
    let p = dir.join(name);
    std::fs::write(&p, format!("{header}\n{}\n", rows.join("\n"))).unwrap();
    s(&p).to_owned()
}

/// Positions-only data (`t, q, tau`) of the 2R arm, `t` at `dt` steps.
fn positions_only(header: &str, rows: &[String], dt: f64) -> (String, Vec<String>) {
    let keep: Vec<usize> = header
        .split(',')
        .enumerate()
        .filter(|(_, h)| {
            *h == "t" || h.starts_with("tau") || (h.starts_with('q') && !h.starts_with("qd"))
        })
        .map(|(c, _)| c)
        .collect();
    let pick = |r: &str| {
        let x: Vec<&str> = r.split(',').collect();
        keep.iter().map(|&c| x[c]).collect::<Vec<_>>().join(",")
    };
    let rows: Vec<String> = rows.iter().map(|r| pick(r)).collect();
    let rows = with_column(&rows, 0, |k, _| format!("{:e}", k as f64 * dt));
    (pick(header), rows)
}

/// Positions-only data sampled every 1e-320 s (subnormal), or a `--cutoff` of 1e-300 Hz:
/// the samples dropped at each end overflowed `usize`, and `identify` panicked in the SVD
/// of an empty matrix. Now exit 2 at the file.
#[test]
fn a_cutoff_far_below_the_sample_rate_is_an_error_not_a_panic() {
    let dir = scratch("abuse_cutoff");
    let (h, rows) = two_r_data(&dir);
    let (ph, prow) = positions_only(&h, &rows, 0.05);
    let data = write(&dir, "pos.csv", &ph, &prow);
    ok(&run(&["identify", TWO_R, &data, "--cutoff", "2"]));
    rejected(
        &["identify", TWO_R, &data, "--cutoff", "1e-300"],
        "too few to filter",
    );
    let (ph, prow) = positions_only(&h, &rows, 1e-320);
    let data = write(&dir, "subnormal.csv", &ph, &prow);
    rejected(&["identify", TWO_R, &data], "column `t`");
    // Time that goes back is pointed at, line and column.
    let (ph, mut prow) = positions_only(&h, &rows, 0.05);
    prow.swap(10, 11);
    let data = write(&dir, "back.csv", &ph, &prow);
    rejected(&["identify", TWO_R, &data], "back.csv:13:1: column `t`");
}

/// A `--cutoff` within rounding of half the sample rate (the rate is the file's mean step,
/// exact to its digits): the filter's poles sit at `z = −1`, its transient never decays, and
/// before, `identify` dropped three cutoff periods (6 samples) and fitted the ringing with
/// exit 0 (a QA finding). Near half the rate more is dropped (`0.45 fs`: 61 samples, not 7).
#[test]
fn a_cutoff_at_half_the_sample_rate_is_an_error() {
    let dir = scratch("abuse_nyquist");
    let (h, rows) = two_r_data(&dir);
    let (ph, prow) = positions_only(&h, &rows, 0.05);
    let data = write(&dir, "pos.csv", &ph, &prow);
    let t: Vec<f64> = prow
        .iter()
        .map(|r| r.split(',').next().unwrap().parse().unwrap())
        .collect();
    let fs = (t.len() - 1) as f64 / (t[t.len() - 1] - t[0]);
    let nyquist = format!("{:?}", 0.5 * fs * (1.0 - 1e-12));
    rejected(
        &["identify", TWO_R, &data, "--cutoff", &nyquist],
        "too few to filter",
    );
    let o = run(&[
        "identify",
        TWO_R,
        &data,
        "--cutoff",
        &format!("{:?}", 0.45 * fs),
    ]);
    ok(&o);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("; 61 samples dropped at each end"), "{out}");
}

/// States of 1e300 made the regressor overflow and the SVD never return (a hang); efforts of
/// 1e308 printed NaN estimates with exit 0. Now exit 2 at the row. Angles of 1e308 rad were
/// fitted (their sines are finite) with exit 0: now exit 2 at the cell.
#[test]
fn huge_values_are_located_errors_not_hangs_or_nan() {
    let dir = scratch("abuse_huge");
    let (h, rows) = two_r_data(&dir);
    let cols: Vec<&str> = h.split(',').collect();
    let q1 = cols.iter().position(|c| *c == "q1").unwrap();
    let data = write(
        &dir,
        "angles.csv",
        &h,
        &with_column(&rows, q1, |_, _| "1e308".into()),
    );
    rejected(
        &["identify", TWO_R, &data],
        &format!(
            "angles.csv:2:{}: column `q1`: `1e308` is beyond 1e9",
            q1 + 1
        ),
    );
    let mut big = rows.clone();
    for (c, name) in cols.iter().enumerate() {
        if name.starts_with("qd") {
            big = with_column(&big, c, |_, _| "1e300".into());
        }
    }
    let data = write(&dir, "states.csv", &h, &big);
    rejected(
        &["identify", TWO_R, &data],
        "states.csv:2: the regressor or the efforts reach",
    );
    let tau = cols.iter().position(|c| *c == "tau1").unwrap();
    let data = write(
        &dir,
        "efforts.csv",
        &h,
        &with_column(&rows, tau, |_, _| "1e308".into()),
    );
    rejected(&["identify", TWO_R, &data], "efforts.csv:2:");
}

/// `--out`, `--plot`, `--estimates` (and `excite -o`) onto the spec or the data overwrote them
/// with exit 0; two outputs onto one file kept the last. Now exit 2 before any work, the
/// inputs untouched. `--plot` onto a directory failed (exit 1) after `--estimates` had
/// replaced its file (found by the fuzzer): now exit 1 before any file is written.
#[test]
fn outputs_never_overwrite_the_inputs() {
    let dir = scratch("abuse_outputs");
    let (h, rows) = two_r_data(&dir);
    let data = write(&dir, "data.csv", &h, &rows);
    let spec = dir.join("arm.toml");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join(TWO_R), &spec).unwrap();
    let (spec_bytes, data_bytes) = (std::fs::read(&spec).unwrap(), std::fs::read(&data).unwrap());
    let other = dir.join("x.svg");
    // The same file by another spelling.
    let data_again = dir.join("sub").join("..").join("data.csv");
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    for (flag, target, want) in [
        ("--out", s(&data_again), "the data file"),
        ("--plot", s(&spec), "the spec"),
        ("--estimates", &data, "the data file"),
        ("--out", s(&spec), "the spec"),
    ] {
        rejected(&["identify", s(&spec), &data, flag, target], want);
    }
    rejected(
        &[
            "identify",
            s(&spec),
            &data,
            "--plot",
            s(&other),
            "--estimates",
            s(&other),
        ],
        "the file of --estimates",
    );
    rejected(&["excite", s(&spec), "-o", s(&spec)], "the spec");
    // An output that cannot be written (onto a directory, into a missing one) stops the run
    // before any other is written: the existing estimates stay as they were.
    let est = dir.join("est.csv");
    std::fs::write(&est, "old\n").unwrap();
    for bad in [dir.join("sub"), dir.join("missing").join("p.svg")] {
        let o = run(&[
            "identify",
            s(&spec),
            &data,
            "--estimates",
            s(&est),
            "--plot",
            s(&bad),
        ]);
        assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains("error: --plot"),
            "{}",
            text(&o.stderr)
        );
        assert_eq!(std::fs::read_to_string(&est).unwrap(), "old\n");
    }
    assert_eq!(std::fs::read(&spec).unwrap(), spec_bytes);
    assert_eq!(std::fs::read(&data).unwrap(), data_bytes);
    assert!(!other.exists());
}

/// "Other columns are ignored" (docs/identification.md): a column of labels, or the empty
/// column of a trailing comma, was parsed and rejected as "not a number". A joint given twice
/// (`q1` and `q_j1`) was read from the first silently. A Latin-1 byte had no line.
#[test]
fn columns_the_file_does_not_need_are_ignored_and_ambiguous_ones_are_errors() {
    let dir = scratch("abuse_columns");
    let (h, rows) = two_r_data(&dir);
    let labelled: Vec<String> = rows.iter().map(|r| format!("{r},run A,")).collect();
    let data = write(&dir, "labels.csv", &format!("{h},label,"), &labelled);
    let o = run(&["identify", TWO_R, &data]);
    ok(&o);
    assert!(
        text(&o.stdout).contains("200 samples"),
        "{}",
        text(&o.stdout)
    );
    let twice: Vec<String> = rows.iter().map(|r| format!("{r},0")).collect();
    let data = write(&dir, "twice.csv", &format!("{h},q_j1"), &twice);
    rejected(&["identify", TWO_R, &data], "twice.csv:1:");
    rejected(&["identify", TWO_R, &data], "both give q1 (joint `j1`)");
    let mut bytes = format!("{h}\n{}\n", rows[..3].join("\n")).into_bytes();
    bytes.extend(b"# caf\xe9\n");
    let p = dir.join("latin1.csv");
    std::fs::write(&p, bytes).unwrap();
    rejected(&["identify", TWO_R, s(&p)], "latin1.csv:5:6: not UTF-8");
}

/// `excite --period 1e308` never returned; `--noise 1e308` wrote `inf` efforts with exit 0;
/// `--samples 10000000` aborted (Gough–Stewart) or ran for minutes.
#[test]
fn excite_rejects_periods_and_noise_that_leave_the_numbers() {
    let dir = scratch("abuse_excite");
    let out = dir.join("e.csv");
    let quick = ["--restarts", "1", "--evaluations", "5", "-o", s(&out)];
    for p in ["1e308", "1e-300", "1e10"] {
        let mut a = vec!["excite", TWO_R, "--period", p];
        a.extend(quick);
        rejected(&a, "--period");
    }
    let mut a = vec!["excite", TWO_R, "--with-tau", "--noise", "1e308"];
    a.extend(quick);
    rejected(&a, "--noise");
    // The largest counts once accepted: 10 million samples of a Gough–Stewart aborted on a
    // 42 GB allocation (the condition number's stacked regressor); 100,000 search samples ran
    // for minutes per evaluation.
    for (flag, n) in [("--samples", "10000000"), ("--search-samples", "100000")] {
        let mut a = vec!["excite", GOUGH, flag, n];
        a.extend(quick);
        rejected(&a, flag);
    }
    // Bounds so small that the regressor underflows to zero: a trajectory that excites
    // nothing (condition number inf) was written with exit 0 (QA pass 3).
    for (flag, v) in [("--q-max", "1e-300"), ("--qd-max", "1e-300")] {
        let mut a = vec!["excite", TWO_R, flag, v];
        a.extend(quick);
        rejected(&a, "excites no base parameter set");
    }
    assert!(!out.exists());
    // Up to the new bound, the condition number is taken over at most 20,000 states.
    let mut a = vec!["excite", TWO_R, "--samples", "30000"];
    a.extend(quick);
    let o = run(&a);
    ok(&o);
    assert!(
        text(&o.stderr).contains("(over 20000 evenly spaced states)"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(&out).unwrap().lines().count(),
        30001
    );
}

/// `--lanes` with a platform or a closed loop was reported as a spec error keyed `platform`;
/// now a platform and a closed loop have `_lanes` functions too, and out-of-range counts are
/// rejected by the argument parser.
#[test]
fn lanes_errors_name_the_flag() {
    for spec in [DELTA, FOUR_BAR] {
        let o = run(&[spec, "--lanes", "4"]);
        ok(&o);
        let code = text(&o.stdout);
        assert!(code.contains("pub fn inverse_dynamics_lanes"), "{spec}");
        assert!(code.contains("pub fn actuator_mass_matrix_lanes"), "{spec}");
    }
    for bad in ["0", "1", "17", "99999", "abc"] {
        rejected(&[TWO_R, "--lanes", bad], "'--lanes <N>'");
    }
    let o = run(&[TWO_R, "--lanes", "3"]);
    ok(&o);
    assert!(text(&o.stdout).contains("_lanes"));
}

/// A header of 200,000 columns (none of them needed) took minutes: the check for a column
/// named twice compared each with all before it. Now an error at once.
#[test]
fn a_very_wide_header_is_read_in_linear_time() {
    let dir = scratch("abuse_wide");
    let p = dir.join("wide.csv");
    let header: Vec<String> = (0..200_000).map(|i| format!("c{i}")).collect();
    std::fs::write(
        &p,
        format!("{}\n{}\n", header.join(","), vec!["1"; 200_000].join(",")),
    )
    .unwrap();
    let o = run_for(&["identify", TWO_R, s(&p)], Duration::from_secs(20))
        .expect("identify ends within 20 s");
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("missing columns"),
        "{}",
        text(&o.stderr)
    );
}

/// `/dev/zero` as the data file was read without end (memory grew until the process was
/// killed); a file is read up to 256 MiB.
#[cfg(unix)]
#[test]
fn an_endless_data_file_is_an_error() {
    let o = run_for(&["identify", TWO_R, "/dev/zero"], Duration::from_secs(30))
        .expect("identify ends within 30 s");
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("larger than 256 MiB"),
        "{}",
        text(&o.stderr)
    );
}

/// A URDF's `ROBOT.scene.toml` beside it is read by generation (with a note), but `excite` and
/// `identify` ignored it: with `friction = true` there, they identified a model without the
/// friction parameters the generated module has. Now all three read it.
#[test]
fn identify_and_excite_read_a_urdf_scene_file_as_generation_does() {
    let dir = scratch("abuse_urdf_scene");
    let urdf = dir.join("arm.urdf");
    std::fs::write(
        &urdf,
        r#"<robot name="arm"><link name="world"/>
<link name="a"><inertial><origin xyz="0.2 0 0"/><mass value="2"/><inertia ixx="0.01" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j1" type="revolute"><parent link="world"/><child link="a"/><axis xyz="0 0 1"/><dynamics damping="0.5" friction="0.2"/></joint>
</robot>"#,
    )
    .unwrap();
    let nbp = |err_or_out: &str| -> usize {
        let i = err_or_out
            .find(" base parameters")
            .expect("a count of base parameters");
        let head = &err_or_out[..i];
        head[head.rfind(' ').unwrap() + 1..].parse().unwrap()
    };
    let data = dir.join("d.csv");
    let excite = |with: bool| {
        let o = run(&[
            "excite",
            s(&urdf),
            "--restarts",
            "1",
            "--evaluations",
            "5",
            "--with-tau",
            "-o",
            s(&data),
        ]);
        ok(&o);
        assert_eq!(text(&o.stderr).contains("note: with the scene file"), with);
        nbp(&text(&o.stderr))
    };
    let identify = |with: bool| {
        let o = run(&["identify", s(&urdf), s(&data)]);
        ok(&o);
        assert_eq!(text(&o.stderr).contains("note: with the scene file"), with);
        nbp(&text(&o.stdout))
    };
    let plain = (excite(false), identify(false));
    std::fs::write(dir.join("arm.scene.toml"), "[scene]\nfriction = true\n").unwrap();
    let with = (excite(true), identify(true));
    assert_eq!(plain.0, plain.1);
    assert_eq!(with.0, with.1);
    assert!(with.1 > plain.1, "{plain:?} {with:?}");
}

/// An output that is a named pipe (or a device: `/dev/stdout` into a pipe, `/dev/full`) was
/// first read to compare it with the new text: the read of a pipe waited for a writer that
/// never came (a hang), `/dev/full` was read without end (memory until the process was
/// killed). Such targets are now only written into.
#[cfg(unix)]
#[test]
fn outputs_into_a_pipe_are_written_not_read() {
    let dir = scratch("abuse_fifo");
    for (k, args) in [
        vec![TWO_R],
        vec!["excite", TWO_R, "--restarts", "1", "--evaluations", "3"],
    ]
    .into_iter()
    .enumerate()
    {
        let fifo = dir.join(format!("out{k}"));
        let made = Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo runs");
        assert!(made.success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(&fifo).unwrap())
        };
        let mut a = args.clone();
        a.push("-o");
        a.push(s(&fifo));
        let o = run_for(&a, Duration::from_secs(30)).expect("ends within 30 s");
        ok(&o);
        let got = String::from_utf8(reader.join().unwrap()).unwrap();
        assert!(
            got.starts_with(if k == 0 { "// @generated" } else { "t," }),
            "{got:.100}"
        );
    }
}
