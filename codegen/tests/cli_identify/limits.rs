//! `excite` keeps a tree inside the joint limits its spec declares (URDF `<limit>`, TOML
//! `limit`): the trajectory is centred in each range, inside it less the margin and under the
//! velocity limits. The limits are read here from the spec's text by a small scan of its own,
//! never by the code under test.

use std::path::Path;

use super::{ok, run, s, scratch, text};

const IIWA: &str = "../mechanisms/specs/iiwa14.urdf";
const TWO_R: &str = "../mechanisms/specs/planar_2r.toml";

/// The value of attribute `name` in the tag text `tag`.
fn attr(tag: &str, name: &str) -> Option<f64> {
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    let end = at + tag[at..].find('"')?;
    tag[at..end].trim().parse().ok()
}

/// `(lower, upper, velocity)` of each revolute or prismatic joint, in document order, from the
/// URDF text.
fn urdf_limits(urdf: &str) -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    for chunk in urdf.split("<joint ").skip(1) {
        let body = &chunk[..chunk.find("</joint>").expect("a closed joint")];
        let head = &body[..body.find('>').unwrap()];
        if !(head.contains("type=\"revolute\"") || head.contains("type=\"prismatic\"")) {
            continue;
        }
        let at = body.find("<limit").expect("a limit");
        let tag = &body[at..at + body[at..].find('>').unwrap()];
        out.push((
            attr(tag, "lower").unwrap(),
            attr(tag, "upper").unwrap(),
            attr(tag, "velocity").unwrap(),
        ));
    }
    out
}

/// The CSV's rows of `q` and `qd` (n joints).
fn rows(csv: &str, n: usize) -> Vec<(Vec<f64>, Vec<f64>)> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[1], "q1");
    assert_eq!(header[1 + n], "qd1");
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[1..1 + n].to_vec(), v[1 + n..1 + 2 * n].to_vec())
        })
        .collect()
}

fn excite(spec: &str, dir: &Path, extra: &[&str]) -> (String, String) {
    let out = dir.join("t.csv");
    let mut args = vec![
        "excite",
        spec,
        "--restarts",
        "1",
        "--evaluations",
        "30",
        "-o",
        s(&out),
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    ok(&o);
    (std::fs::read_to_string(&out).unwrap(), text(&o.stderr))
}

#[test]
fn iiwa14_stays_inside_its_urdf_limits() {
    let dir = scratch("limits_iiwa");
    let urdf = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(IIWA)).unwrap();
    let lim = urdf_limits(&urdf);
    assert_eq!(lim.len(), 7);
    let (csv, err) = excite(IIWA, &dir, &[]);
    assert!(
        err.lines()
            .any(|l| l.starts_with("excite: bounds (7 of 7 joints with limits")),
        "{err}"
    );
    let r = rows(&csv, 7);
    assert_eq!(r.len(), 1000);
    let mut widest = 0.0f64;
    for (q, qd) in &r {
        for (i, &(lo, up, v)) in lim.iter().enumerate() {
            // Inside the range less the default margin (5 % of the half range).
            let m = 0.05 * 0.5 * (up - lo);
            assert!(
                q[i] >= lo + m && q[i] <= up - m,
                "q{} = {} in [{lo}, {up}]",
                i + 1,
                q[i]
            );
            assert!(qd[i].abs() <= v, "qd{} = {} over {v}", i + 1, qd[i]);
            widest = widest.max(q[i].abs());
        }
    }
    // The ranges, not the old default --q-max of 1 rad, bound the motion.
    assert!(widest > 1.0, "{widest}");

    // --q-max and --qd-max given bound further.
    let (csv, _) = excite(IIWA, &dir, &["--q-max", "0.5", "--qd-max", "1.0"]);
    for (q, qd) in rows(&csv, 7) {
        for i in 0..7 {
            assert!(q[i].abs() <= 0.5 && qd[i].abs() <= 1.0, "{q:?} {qd:?}");
        }
    }
}

#[test]
fn an_asymmetric_toml_range_centres_the_trajectory() {
    let dir = scratch("limits_toml");
    let two_r = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(TWO_R)).unwrap();
    // j1 in [0.2, 1.4] rad under 0.8 rad/s; j2 in [-90°, 45°], no speed limit.
    let spec = two_r
        .replacen(
            "axis = [0.0, 0.0, 1.0]",
            "axis = [0.0, 0.0, 1.0]\nlimit = { lower = 0.2, upper = 1.4, velocity = 0.8 }",
            1,
        )
        .replacen(
            "child = \"link2\"",
            "child = \"link2\"\nlimit = { lower = \"-90 deg\", upper = \"45 deg\" }",
            1,
        );
    assert_eq!(spec.matches("limit = ").count(), 2);
    let p = dir.join("arm.toml");
    std::fs::write(&p, spec).unwrap();
    let (csv, err) = excite(s(&p), &dir, &[]);
    assert!(err.contains("(2 of 2 joints with limits"), "{err}");
    let r = rows(&csv, 2);
    let deg = std::f64::consts::PI / 180.0;
    let ranges = [(0.2, 1.4), (-90.0 * deg, 45.0 * deg)];
    let mut mean = [0.0; 2];
    let mut span = [(f64::MAX, f64::MIN); 2];
    for (q, qd) in &r {
        for i in 0..2 {
            let (lo, up) = ranges[i];
            let m = 0.05 * 0.5 * (up - lo);
            assert!(q[i] >= lo + m && q[i] <= up - m, "q{} = {}", i + 1, q[i]);
            mean[i] += q[i] / r.len() as f64;
            span[i] = (span[i].0.min(q[i]), span[i].1.max(q[i]));
        }
        assert!(qd[0].abs() <= 0.8, "{}", qd[0]);
        // No speed limit on j2: the default --qd-max.
        assert!(qd[1].abs() <= 2.0, "{}", qd[1]);
    }
    // A finite Fourier series sampled evenly over its period averages to its offset.
    for i in 0..2 {
        let (lo, up) = ranges[i];
        assert!((mean[i] - 0.5 * (lo + up)).abs() < 1e-9, "{mean:?}");
        // The motion leaves the symmetric default's side: it does not sit about zero.
        assert!(span[i].1 - span[i].0 > 0.1 * (up - lo), "{span:?}");
    }
    assert!(span[0].0 > 0.2, "{span:?}");
}

/// A bad `limit` is a spec error at its key, exit code 2, for `excite` as for generation.
#[test]
fn a_bad_limit_is_an_error_at_the_key() {
    let dir = scratch("limits_bad");
    let two_r = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(TWO_R)).unwrap();
    for (limit, key, what) in [
        (
            "limit = { lower = 1.4, upper = 0.2 }",
            "joint \"j1\".limit.upper",
            "must be greater than `lower`",
        ),
        (
            "limit = { lower = 0.2, upper = 1.4, velocity = 0 }",
            "joint \"j1\".limit.velocity",
            "must be positive",
        ),
        (
            "limit = { lower = 0.2, upper = nan }",
            "joint \"j1\".limit.upper",
            "",
        ),
    ] {
        let spec = two_r.replacen(
            "axis = [0.0, 0.0, 1.0]",
            &format!("axis = [0.0, 0.0, 1.0]\n{limit}"),
            1,
        );
        let p = dir.join("arm.toml");
        std::fs::write(&p, spec).unwrap();
        let o = run(&["excite", s(&p), "--restarts", "1", "--evaluations", "5"]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{limit}: {err}");
        assert!(err.contains(key) && err.contains(what), "{limit}: {err}");
        // File and line of the key: the first joint's `limit` is the line after its axis.
        let line = two_r
            .lines()
            .position(|l| l == "axis = [0.0, 0.0, 1.0]")
            .unwrap()
            + 2;
        assert!(err.contains(&format!("arm.toml:{line}:")), "{limit}: {err}");
        assert!(o.stdout.is_empty());
    }
}

/// `identify --out` changes the bodies and keeps a joint's `limit` as written.
#[test]
fn identify_out_keeps_the_limit_key() {
    let dir = scratch("limits_out");
    let two_r = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(TWO_R)).unwrap();
    let line = "limit = { lower = \"10 deg\", upper = 1.4, velocity = 0.8 }";
    let spec = two_r.replacen(
        "axis = [0.0, 0.0, 1.0]",
        &format!("axis = [0.0, 0.0, 1.0]\n{line}"),
        1,
    );
    let p = dir.join("arm.toml");
    std::fs::write(&p, &spec).unwrap();
    let (t, e) = (dir.join("t.csv"), dir.join("arm2.toml"));
    ok(&run(&[
        "excite",
        s(&p),
        "--restarts",
        "1",
        "--evaluations",
        "30",
        "--with-tau",
        "-o",
        s(&t),
    ]));
    ok(&run(&["identify", s(&p), s(&t), "--out", s(&e)]));
    let out = std::fs::read_to_string(&e).unwrap();
    assert_eq!(out.lines().filter(|l| *l == line).count(), 1, "{out}");
}
