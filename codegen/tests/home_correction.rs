//! Specs typed with rounded numbers (four decimals, as read off a drawing) leave their loops a
//! few micrometres open at home. The reader closes gaps up to `HOME_CORRECTION` × the size by
//! moving the loop-closing joint's frame (with a warning and a fix), and `codegen fix-home`
//! writes the fixes into the spec, which then loads without them. Larger gaps stay errors
//! (`bad_parallel/closed_not_closing.toml`).

use std::path::Path;

use codegen::spec::{Mechanism, apply_fixes, load_mechanism};

/// `text` with every decimal number of more than four decimals rounded to four (outside
/// strings).
fn rounded(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let mut in_string = false;
    let mut in_comment = false;
    while i < b.len() {
        let c = b[i] as char;
        if c == '\n' {
            in_comment = false;
        }
        if !in_string && c == '#' {
            in_comment = true;
        }
        if !in_comment && c == '"' {
            in_string = !in_string;
        }
        let starts = !in_string
            && !in_comment
            && (c.is_ascii_digit() || (c == '-' && b.get(i + 1).is_some_and(u8::is_ascii_digit)))
            && (i == 0 || !(b[i - 1] as char).is_ascii_alphanumeric());
        if starts {
            let mut j = i + 1;
            while j < b.len() && ((b[j] as char).is_ascii_digit() || b[j] == b'.') {
                j += 1;
            }
            let num = &text[i..j];
            let decimals = num.split('.').nth(1).map_or(0, str::len);
            let exp = b.get(j).is_some_and(|&e| e == b'e' || e == b'E');
            if decimals > 4 && !exp {
                let v: f64 = num.parse().unwrap();
                out.push_str(&format!("{v:.4}"));
            } else {
                out.push_str(num);
            }
            i = j;
            continue;
        }
        out.push(c);
        i += 1;
    }
    out
}

/// The bundled spec with every number written out: the written-out form kept beside the specs
/// written with parameters and patterns (`data/expanded/`), else the bundled file.
fn bundled(name: &str) -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let expanded = dir.join(format!("tests/data/expanded/{name}.toml"));
    let p = if expanded.exists() {
        expanded
    } else {
        dir.join(format!("../mechanisms/specs/{name}.toml"))
    };
    std::fs::read_to_string(p).unwrap()
}

/// The rounded spec loads with `fixes` fixes, `codegen fix-home`'s text loads with none, and
/// the two models agree (the corrected one is what the reader used).
fn round_trip(name: &str, fixes: usize) {
    let text = rounded(&bundled(name));
    assert_ne!(text, bundled(name), "{name}: nothing was rounded");
    let (m, warnings) =
        load_mechanism("r.toml", &text).unwrap_or_else(|d| panic!("{name}:\n{}", d.render()));
    let n = warnings.iter().filter(|d| d.fix.is_some()).count();
    assert_eq!(n, fixes, "{name}:\n{}", warnings.render());
    let (fixed, applied) = apply_fixes(&text, &warnings);
    assert_eq!(applied, fixes);
    let (m2, w2) =
        load_mechanism("r.toml", &fixed).unwrap_or_else(|d| panic!("{name}:\n{}", d.render()));
    assert!(
        w2.iter().all(|d| d.fix.is_none()),
        "{name}:\n{}",
        w2.render()
    );
    // The same mechanism: the internal correction and the written one agree to the 13 digits
    // the fix is written with.
    let same = match (&m, &m2) {
        (Mechanism::Closed(a), Mechanism::Closed(b)) => a.cuts.iter().zip(&b.cuts).all(|(x, y)| {
            (0..3).all(|i| {
                (x.frame_child.translation[i] - y.frame_child.translation[i]).abs() < 1e-12
            })
        }),
        (Mechanism::Parallel(a), Mechanism::Parallel(b)) => a
            .legs
            .iter()
            .zip(&b.legs)
            .all(|(x, y)| format!("{:.10?}", x.end) == format!("{:.10?}", y.end)),
        _ => false,
    };
    assert!(same, "{name}: the written fix is not the correction used");
}

#[test]
fn rounded_closed_loops_are_closed_and_fixed() {
    round_trip("four_bar", 1);
}

#[test]
fn rounded_platforms_are_closed_and_fixed() {
    round_trip("gough_stewart", 6);
    round_trip("planar_3rrr", 3);
    // The Delta's parallelograms: each length taken from the home geometry.
    round_trip("delta_rl5", 3);
}

/// The corrected rounded Gough–Stewart is the published one to the rounding: its efforts at
/// home differ by about the relative size of the moved points (micrometres in metres).
#[test]
fn the_correction_is_as_small_as_the_rounding() {
    let exact = match load_mechanism("e.toml", &bundled("gough_stewart")) {
        Ok((Mechanism::Parallel(m), _)) => m,
        _ => panic!(),
    };
    let round = match load_mechanism("r.toml", &rounded(&bundled("gough_stewart"))) {
        Ok((Mechanism::Parallel(m), _)) => m,
        _ => panic!(),
    };
    let (pe, pr) = (
        runtime::parallel::Plan::new(&exact).unwrap(),
        runtime::parallel::Plan::new(&round).unwrap(),
    );
    let x = exact.home_x();
    let u = [0.1, -0.2, 0.3, 0.05, 0.1, -0.1];
    let ud = [1.0, 0.5, -0.3, 0.2, -0.4, 0.6];
    let a = runtime::parallel::noc::inverse_dynamics(&pe, &x, &u, &ud).unwrap();
    let b = runtime::parallel::noc::inverse_dynamics(&pr, &round.home_x(), &u, &ud).unwrap();
    let d = a
        .iter()
        .zip(&b)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    let s = a.iter().fold(0.0f64, |m, p| m.max(p.abs()));
    println!(
        "rounded Gough–Stewart vs published: {:.1e} relative (∞-norm)",
        d / s
    );
    assert!(d / s < 1e-3, "{}", d / s);
}

/// The CLI: `codegen fix-home` rewrites the file once; a second run has nothing to fix.
#[test]
fn fix_home_rewrites_the_spec_once() {
    let dir = std::env::temp_dir().join("nocdyn-fix-home");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("four_bar.toml");
    std::fs::write(&file, rounded(&bundled("four_bar"))).unwrap();
    let run = || {
        std::process::Command::new(env!("CARGO_BIN_EXE_codegen"))
            .arg("fix-home")
            .arg(&file)
            .output()
            .unwrap()
    };
    let first = run();
    assert!(first.status.success(), "{first:?}");
    assert!(String::from_utf8_lossy(&first.stderr).contains("1 correction written"));
    let second = run();
    assert!(second.status.success());
    assert!(
        String::from_utf8_lossy(&second.stderr).contains("nothing to fix"),
        "{second:?}"
    );
    // With nothing to fix, `-o` still gets the spec: `-o -` printed nothing, and `-o OUT`
    // wrote no file (QA).
    let fixed = std::fs::read_to_string(&file).unwrap();
    let to = |out: &std::path::Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_codegen"))
            .arg("fix-home")
            .arg(&file)
            .arg("-o")
            .arg(out)
            .output()
            .unwrap()
    };
    let stdout = to(std::path::Path::new("-"));
    assert!(stdout.status.success(), "{stdout:?}");
    assert_eq!(String::from_utf8_lossy(&stdout.stdout), fixed);
    let copy = dir.join("copy.toml");
    let written = to(&copy);
    assert!(written.status.success(), "{written:?}");
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), fixed);
    // Into a missing directory: exit 1 naming `-o`, not a temporary file (QA).
    let missing = to(&dir.join("no_such_dir").join("x.toml"));
    assert_eq!(missing.status.code(), Some(1), "{missing:?}");
    let err = String::from_utf8_lossy(&missing.stderr);
    assert!(
        err.contains("-o ") && err.contains("its directory does not exist"),
        "{err}"
    );
    assert!(!err.contains(".tmp"), "{err}");
}
