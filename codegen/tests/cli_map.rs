//! The `map` and `isotropy` subcommands as a user runs them (`docs/indices.md`), and that the
//! plain generation command line is unchanged beside them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use runtime::indices::{Space, parallel_indices};
use runtime::parallel::Plan;
use runtime::parallel::noc;

const EYE: &str = "../mechanisms/specs/agile_eye.toml";
const FIVE: &str = "../mechanisms/specs/planar_five_bar.toml";
const TWO_R: &str = "../mechanisms/specs/planar_2r.toml";

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_codegen"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("the codegen binary runs")
}

fn text(b: &[u8]) -> &str {
    std::str::from_utf8(b).expect("UTF-8")
}

fn scratch(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_map")
        .join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn parallel(path: &str) -> runtime::parallel::ParallelModel {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(path);
    let src = std::fs::read_to_string(&p).unwrap();
    match codegen::spec::load_mechanism(path, &src) {
        Ok((codegen::spec::Mechanism::Parallel(m), _)) => m,
        _ => panic!("{path} is a parallel mechanism"),
    }
}

/// Rows of a CSV file (header first).
fn csv(path: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

#[test]
fn map_agile_eye_writes_csv_and_svg() {
    let dir = scratch("eye");
    let prefix = dir.join("eye");
    let o = run(&[
        "map",
        EYE,
        "--index",
        "dci",
        "--axes",
        "rx,ry",
        "--range",
        "-0.5:0.5",
        "--steps",
        "7,5",
        "-o",
        prefix.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "stderr: {}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(
        out.contains("W = Frobenius (1 on the diagonal, 2 off it)"),
        "{out}"
    );
    assert!(out.contains("A^-T I A^-1"), "{out}");
    // No progress bar when stderr is not a terminal.
    assert!(text(&o.stderr).is_empty(), "{}", text(&o.stderr));

    let rows = csv(&dir.join("eye.csv"));
    assert_eq!(rows.len(), 1 + 7 * 5);
    assert_eq!(rows[0], ["ix", "iy", "rx_rad", "ry_rad", "dci", "status"]);
    assert!(rows[1..].iter().all(|r| r[5] == "ok"));
    // The point rx = 0.5, ry = 0 (ix = 6, iy = 2) is the home orientation turned by 0.5 rad
    // about the base x axis: the quaternion (cos 0.25, sin 0.25, 0, 0).
    let row = rows
        .iter()
        .find(|r| r[0] == "6" && r[1] == "2")
        .expect("row (6, 2)");
    assert_eq!(row[2].parse::<f64>().unwrap(), 0.5);
    assert_eq!(row[3].parse::<f64>().unwrap(), 0.0);
    let m = parallel(EYE);
    let plan = Plan::new(&m).unwrap();
    let x = [0.25f64.cos(), 0.25f64.sin(), 0.0, 0.0];
    let want = parallel_indices(&plan, &x, Space::Actuator)
        .unwrap()
        .dci_trace
        .psi;
    let got: f64 = row[4].parse().unwrap();
    assert!((got - want).abs() <= 1e-11 * want, "{got} vs {want}");

    let svg = std::fs::read_to_string(dir.join("eye.svg")).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..60.min(svg.len())]);
    assert!(svg.matches("<rect").count() >= 35);
    assert!(svg.contains("agile_eye: dci"));
}

#[test]
fn map_five_bar_marks_unreachable_points() {
    let dir = scratch("five");
    let prefix = dir.join("five");
    // py from home 0.3 m up to 0.6 m: the legs (0.2 + 0.25 m) cannot reach the top rows.
    let o = run(&[
        "map",
        FIVE,
        "--index",
        "dci2",
        "--range",
        "-0.05:0.05,-0.05:0.3",
        "--grid",
        "6,8",
        "--threads",
        "2",
        "-o",
        prefix.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "stderr: {}", text(&o.stderr));
    let rows = csv(&dir.join("five.csv"));
    assert_eq!(rows.len(), 1 + 6 * 8);
    assert_eq!(rows[0], ["ix", "iy", "px_m", "py_m", "dci2", "status"]);
    let unreachable = rows.iter().filter(|r| r[5] == "unreachable").count();
    let ok = rows.iter().filter(|r| r[5] == "ok").count();
    assert!(
        unreachable > 0 && ok > 0,
        "{unreachable} unreachable, {ok} ok"
    );
    // Absolute coordinates: py spans 0.25 … 0.6 m.
    let py: Vec<f64> = rows[1..].iter().map(|r| r[3].parse().unwrap()).collect();
    let (lo, hi) = py
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    assert!(
        (lo - 0.25).abs() < 1e-9 && (hi - 0.6).abs() < 1e-9,
        "{lo} {hi}"
    );
    // Every unreachable row has an empty value; the top row (py = 0.6) is out of reach
    // (|P − A| ≥ 0.6 > 0.45 m).
    for r in &rows[1..] {
        assert_eq!(r[4].is_empty(), r[5] != "ok");
        if r[1] == "7" {
            assert_eq!(r[5], "unreachable");
        }
    }
    let svg = std::fs::read_to_string(dir.join("five.svg")).unwrap();
    assert!(svg.contains("unreachable"));
}

#[test]
fn map_tree_over_two_joints() {
    let dir = scratch("tree");
    let prefix = dir.join("two_r");
    let o = run(&[
        "map",
        TWO_R,
        "--index",
        "cond",
        "--steps",
        "5",
        "-o",
        prefix.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "stderr: {}", text(&o.stderr));
    let rows = csv(&dir.join("two_r.csv"));
    assert_eq!(rows.len(), 1 + 25);
    assert!(rows[0][2].ends_with("_rad") && rows[0][3].ends_with("_rad"));
    assert!(rows[1..].iter().all(|r| r[5] == "ok"));
    // The condition number of a 2R arm does not depend on the first joint.
    for r in &rows[1..] {
        let same: Vec<&Vec<String>> = rows[1..].iter().filter(|s| s[1] == r[1]).collect();
        let v: f64 = r[4].parse().unwrap();
        for s in same {
            let w: f64 = s[4].parse().unwrap();
            assert!((v - w).abs() <= 1e-12 * v, "{v} vs {w}");
        }
    }
}

#[test]
fn map_rejects_bad_arguments() {
    let dir = scratch("bad");
    let p = dir.join("x");
    let p = p.to_str().unwrap();
    for args in [
        vec!["map", EYE, "--axes", "px,py", "-o", p],
        vec!["map", EYE, "--axes", "rx", "-o", p],
        vec!["map", EYE, "--axes", "rx,rx", "-o", p],
        vec!["map", FIVE, "--steps", "1", "-o", p],
        vec!["map", FIVE, "--range", "0.1:-0.1", "-o", p],
        // Spans infinity: the heat map's axis panicked in the plotting library (exit 101).
        vec!["map", FIVE, "--range", "-1e308:1e308", "-o", p],
        vec![
            "map",
            "../mechanisms/specs/puma560.toml",
            "--range=-1e308:1e308",
            "-o",
            p,
        ],
        vec!["map", FIVE, "--index", "nope", "-o", p],
        vec!["map", "tests/data/bad/negative_mass.toml", "-o", p],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stderr));
        assert!(!dir.join("x.csv").exists(), "{args:?} wrote a CSV");
    }
    let o = run(&["map", "no/such/spec.toml", "-o", p]);
    assert_eq!(o.status.code(), Some(1));
}

/// `map`'s two files go where `write_output` puts every other output: never over the spec
/// (exit code 2), never onto a directory or into a missing one (exit code 1), and neither is
/// written when the other cannot be (both checked before any work).
#[test]
fn map_outputs_never_replace_the_spec_or_half_write() {
    let dir = scratch("outputs");
    // A spec whose name is the CSV `-o x` would write.
    let spec = dir.join("x.csv");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join(FIVE), &spec).unwrap();
    let before = std::fs::read(&spec).unwrap();
    let p = dir.join("x");
    let o = run(&[
        "map",
        spec.to_str().unwrap(),
        "--steps",
        "3",
        "-o",
        p.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("the spec"), "{}", text(&o.stderr));
    assert_eq!(
        std::fs::read(&spec).unwrap(),
        before,
        "the spec was overwritten"
    );
    assert!(!dir.join("x.svg").exists(), "an SVG was written");

    // The SVG's path is a directory: nothing is written, the CSV neither.
    std::fs::create_dir_all(dir.join("y.svg")).unwrap();
    let y = dir.join("y");
    let o = run(&["map", FIVE, "--steps", "3", "-o", y.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(!dir.join("y.csv").exists(), "a CSV was written");

    // Into a missing directory.
    let z = dir.join("missing").join("z");
    let o = run(&["map", FIVE, "--steps", "3", "-o", z.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
}

/// A search where no start can be evaluated (every one out of reach) is an error, not an empty
/// table with exit 0 (QA: `isotropy gough_stewart.toml --samples 2 --range 1e308`).
#[test]
fn an_isotropy_search_with_nothing_evaluated_is_an_error() {
    let o = run(&["isotropy", FIVE, "--samples", "2", "--range", "1e308"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stdout));
    assert!(
        text(&o.stderr).contains("none of the 2 random starts could be evaluated"),
        "{}",
        text(&o.stderr)
    );
}

/// Counts no run can meet are refused at once, before any work: `isotropy --samples
/// 18446744073709551615` panicked (capacity overflow, exit 101) and 4,294,967,296 aborted
/// out of memory (134); `reduce --samples 4294967296` and `map --threads 100000` never ended.
#[test]
fn huge_counts_are_refused() {
    let dir = scratch("huge");
    let p = dir.join("x");
    let p = p.to_str().unwrap();
    for args in [
        vec!["isotropy", FIVE, "--samples", "18446744073709551615"],
        vec!["isotropy", FIVE, "--samples", "4294967296"],
        vec!["isotropy", FIVE, "--samples", "100001"],
        vec![
            "reduce",
            "../mechanisms/specs/planar_2r.toml",
            "--samples",
            "4294967296",
        ],
        vec![
            "reduce",
            "../mechanisms/specs/planar_2r.toml",
            "--samples",
            "100001",
        ],
        vec!["map", FIVE, "--threads", "100000", "-o", p],
        vec!["map", FIVE, "--threads", "18446744073709551615", "-o", p],
    ] {
        let t0 = std::time::Instant::now();
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains("at most"),
            "{args:?}: {}",
            text(&o.stderr)
        );
        assert!(
            t0.elapsed().as_secs() < 10,
            "{args:?} took {:?}",
            t0.elapsed()
        );
        assert!(!dir.join("x.csv").exists(), "{args:?} wrote a CSV");
    }
}

#[test]
fn plain_generation_is_unchanged() {
    let o = run(&[TWO_R]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains("pub fn inverse_dynamics"));
    let o = run(&[FIVE, "--check"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(2));
}

/// The five-bar has a dynamically isotropic point; at the printed coordinates the runtime's
/// actuator-space inertia is σ·1 with the printed σ.
#[test]
fn isotropy_finds_the_five_bar_isotropic_point() {
    let o = run(&["isotropy", FIVE, "--samples", "16"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(out.contains("dynamically isotropic point"), "{out}");
    assert!(out.contains("W = Frobenius"), "{out}");
    let row = out
        .lines()
        .find(|l| l.starts_with("| 1 |"))
        .unwrap_or_else(|| panic!("{out}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let coords: Vec<f64> = cells[2]
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    let sigma: f64 = cells[4].parse().unwrap();
    let m = parallel(FIVE);
    let plan = Plan::new(&m).unwrap();
    let ma = noc::actuator_mass_matrix(&plan, &coords).unwrap();
    // Printed to six decimals: M matches σ·1 to that precision.
    assert!((ma[0][0] - sigma).abs() < 2e-6, "{ma:?} vs {sigma}");
    assert!((ma[1][1] - sigma).abs() < 2e-6, "{ma:?} vs {sigma}");
    assert!(ma[0][1].abs() < 2e-6 * sigma.max(1.0), "{ma:?}");
}

#[test]
fn isotropy_agile_eye_prints_a_table() {
    let o = run(&["isotropy", EYE, "--samples", "4", "--seed", "3"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(
        out.contains("| point | coordinates (qw, qx, qy, qz)"),
        "{out}"
    );
    assert!(out.contains("sigma [kg m^2]"), "{out}");
    assert!(out.lines().any(|l| l.starts_with("| 1 |")), "{out}");
}

/// Closed loops in joint coordinates (the 2-DOF spherical five-bar pointing mechanism): the
/// slice is over the two actuated joints, the others assembled on the home branch; the value at
/// home is the condition number of the runtime's inertia of the actuated joints there.
#[test]
fn map_closed_loops_over_the_actuated_joints() {
    let dir = scratch("closed");
    let prefix = dir.join("pointing");
    let o = run(&[
        "map",
        "../mechanisms/specs/spherical_five_bar.toml",
        "--index",
        "cond",
        "--range",
        "-0.4:0.4",
        "--steps",
        "5",
        "-o",
        prefix.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "stderr: {}", text(&o.stderr));
    let rows = csv(&dir.join("pointing.csv"));
    assert_eq!(rows.len(), 1 + 25);
    assert!(rows[0][2].starts_with("a1") && rows[0][3].starts_with("b1"));
    let centre = rows[1..]
        .iter()
        .find(|r| r[2].parse::<f64>().unwrap() == 0.0 && r[3].parse::<f64>().unwrap() == 0.0)
        .expect("the home point is on the grid");
    assert_eq!(centre[5], "ok");
    let src = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/specs/spherical_five_bar.toml"),
    )
    .unwrap();
    let Ok((codegen::spec::Mechanism::Closed(m), _)) =
        codegen::spec::load_mechanism("spherical_five_bar.toml", &src)
    else {
        panic!("not a closed-loop spec")
    };
    let plan = runtime::closed::Plan::new(&m).unwrap();
    let mm = runtime::closed::noc::mass_matrix(&plan, &[0.0; 4]).unwrap();
    let want = runtime::indices::inertia_indices(&runtime::indices::from_rows(&mm).unwrap())
        .unwrap()
        .condition;
    let got: f64 = centre[4].parse().unwrap();
    assert!((got - want).abs() <= 1e-6 * want, "{got} vs {want}");
}

/// `isotropy --design`: the camera's mass of the spherical five-bar searched with the actuated
/// angles. The spec is rewritten here by text (not by the tool's path lookup) with the printed
/// mass, and the runtime's inertia of the actuated joints at the printed angles is σ·1 to the
/// printed precision; the mass lies inside the range and differs from the spec's (which has no
/// isotropic point, `docs/indices.md`).
#[test]
fn isotropy_searches_a_named_design_number() {
    const SPEC: &str = "../mechanisms/specs/spherical_five_bar.toml";
    let o = run(&[
        "isotropy",
        SPEC,
        "--samples",
        "64",
        "--design",
        "body.distal_a.mass=0.05:1.5",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(
        out.contains("| point | body.distal_a.mass | coordinates (a1, b1)"),
        "{out}"
    );
    let row = out
        .lines()
        .find(|l| l.starts_with("| 1 |"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(out.contains("dynamically isotropic point"), "{out}");
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let mass: f64 = cells[2].parse().unwrap();
    let q: Vec<f64> = cells[3]
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    let sigma: f64 = cells[5].parse().unwrap();
    assert!(
        (0.05..=1.5).contains(&mass) && (mass - 0.3).abs() > 1e-3,
        "{mass}"
    );

    let src = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(SPEC)).unwrap();
    let written = "name = \"distal_a\"\nmass = 0.3\n";
    assert_eq!(src.matches(written).count(), 1);
    let src = src.replace(written, &format!("name = \"distal_a\"\nmass = {mass}\n"));
    let Ok((codegen::spec::Mechanism::Closed(m), _)) =
        codegen::spec::load_mechanism("spherical_five_bar.toml", &src)
    else {
        panic!("not a closed-loop spec")
    };
    let plan = runtime::closed::Plan::new(&m).unwrap();
    let full = runtime::closed::noc::forward_kinematics(&plan, &q, &vec![0.0; plan.nx()]).unwrap();
    let mm = runtime::closed::noc::mass_matrix(&plan, &full).unwrap();
    // Six printed decimals of the angles and the mass (relative 1e-6 of σ ~ 1e-3 kg·m²).
    let tol = 2e-3 * sigma;
    assert!((mm[0][0] - sigma).abs() < tol, "{mm:?} vs {sigma}");
    assert!((mm[1][1] - sigma).abs() < tol, "{mm:?} vs {sigma}");
    assert!(mm[0][1].abs() < tol, "{mm:?}");
}

/// A negative number is a value, refused by the option's own range check with its message:
/// `reduce --tolerance -1` got clap's "unexpected argument '-1' found" instead, which names no
/// bound (exit 2 either way).
#[test]
fn negative_numbers_get_the_range_message() {
    let dir = scratch("negative");
    let p = dir.join("x");
    let p = p.to_str().unwrap();
    let two_r = "../mechanisms/specs/planar_2r.toml";
    for (args, says) in [
        (
            vec!["reduce", two_r, "--tolerance", "-1"],
            "--tolerance must be positive",
        ),
        (
            vec!["isotropy", FIVE, "--tolerance", "-0.5"],
            "--tolerance non-negative",
        ),
        (vec!["map", FIVE, "--steps", "-4", "-o", p], "--steps"),
        (vec!["excite", two_r, "--period", "-2"], "--period -2"),
        (vec![two_r, "--snap", "-1"], "(0, 0.01]"),
        (vec![two_r, "--lanes", "-4"], "from 2 to 16"),
    ] {
        let o = run(&args);
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(!e.contains("unexpected argument"), "{args:?}: {e}");
        assert!(e.contains(says), "{args:?}: {e}");
    }
}
