//! `codegen draw`: the home pose as SVG, rendered to pixels with resvg and checked there
//! against joint positions computed here from the specs' published numbers (not from the
//! drawing's own geometry): the actuated joints' and loop cuts' highlights appear where those
//! joints are, and nowhere else; every view has drawing in it; the output repeats byte for
//! byte; bad input is a diagnostic.
//!
//! `DRAW_PNG_DIR=DIR cargo test -p codegen --test draw` also writes each rendering to
//! `DIR/<name>_home.png` (docs/img/delta_rl5_home.png is made so).

use std::path::Path;
use std::process::{Command, Output};

use codegen::draw::{ACTUATED, CUT, Drawing};
use resvg::{tiny_skia, usvg};

fn spec(name: &str) -> (String, String) {
    let path = format!("../mechanisms/specs/{name}");
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(&path))
        .expect("bundled spec");
    (path, text)
}

fn draw(name: &str) -> Drawing {
    let (path, text) = spec(name);
    let (d, diags) = codegen::draw::draw(&path, &text).expect("the spec draws");
    assert!(!diags.has_errors(), "{}", diags.render());
    d
}

/// The SVG rendered at one pixel per unit (white background drawn by the SVG itself).
fn render(d: &Drawing, name: &str) -> tiny_skia::Pixmap {
    let tree = usvg::Tree::from_str(&d.svg, &usvg::Options::default()).expect("the SVG parses");
    let size = tree.size().to_int_size();
    assert_eq!(
        (size.width() as f64, size.height() as f64),
        d.size,
        "the SVG's size"
    );
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).expect("pixmap");
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    if let Some(dir) = std::env::var_os("DRAW_PNG_DIR") {
        let stem = name.trim_end_matches(".toml").trim_end_matches(".urdf");
        let out = Path::new(&dir).join(format!("{stem}_home.png"));
        pixmap.save_png(&out).expect("PNG written");
    }
    pixmap
}

/// The pixels within `tol` per channel of `colour` (opaque), as `(x, y)`.
fn pixels_of(p: &tiny_skia::Pixmap, colour: [u8; 3], tol: i32) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for y in 0..p.height() {
        for x in 0..p.width() {
            let c = p.pixel(x, y).expect("in the image");
            let close = [c.red(), c.green(), c.blue()]
                .iter()
                .zip(colour)
                .all(|(a, b)| (i32::from(*a) - i32::from(b)).abs() <= tol);
            if c.alpha() == 255 && close {
                out.push((x as f64 + 0.5, y as f64 + 0.5));
            }
        }
    }
    out
}

fn dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt()
}

/// Every view: the highlight `colour` is drawn within `near` px of each expected point's
/// projection, and (inside the panels) nowhere farther than `near` from all of them.
fn highlights_at(d: &Drawing, p: &tiny_skia::Pixmap, colour: [u8; 3], expected: &[[f64; 3]]) {
    // The highlight ring's radius is 9 px, the square's corner 14.5 px out, with the stroke.
    const NEAR: f64 = 14.0;
    const FAR: f64 = 17.0;
    let found = pixels_of(p, colour, 24);
    for (vi, v) in d.views.iter().enumerate() {
        let here: Vec<(f64, f64)> = expected.iter().map(|e| v.project(e)).collect();
        for (e, at) in expected.iter().zip(&here) {
            assert!(
                found.iter().any(|f| dist(*f, *at) <= NEAR),
                "view {} ({}): no {colour:?} highlight near {e:?} (drawn at {at:?})",
                vi,
                v.label
            );
        }
        for f in found.iter().filter(|f| v.contains(f.0, f.1)) {
            assert!(
                here.iter().any(|at| dist(*f, *at) <= FAR),
                "view {}: a {colour:?} pixel at {f:?}, far from every expected joint {here:?}",
                v.label
            );
        }
    }
}

/// Every view has a good share of drawn (non-background) pixels, and the image is not blank.
fn views_not_blank(d: &Drawing, p: &tiny_skia::Pixmap) {
    for v in &d.views {
        let mut drawn = 0;
        for y in (v.origin.1 as u32 + 20)..(v.origin.1 + codegen::draw::PANEL) as u32 - 20 {
            for x in v.origin.0 as u32..(v.origin.0 + codegen::draw::PANEL) as u32 {
                let c = p.pixel(x, y).expect("in the image");
                // The panel's background is #fafafa.
                if c.red() < 200 || c.green() < 200 || c.blue() < 200 {
                    drawn += 1;
                }
            }
        }
        assert!(drawn > 300, "{}: only {drawn} pixels drawn", v.label);
    }
}

/// The same scale in every view, fitted: the mechanism's widest extent fills the panel less
/// its margins in some view.
fn same_scale(d: &Drawing) {
    let s = d.views[0].scale;
    assert!(d.views.iter().all(|v| v.scale == s));
    assert!(s.is_finite() && s > 0.0);
}

#[test]
fn delta_motors_and_platform_joints_where_the_spec_publishes_them() {
    let d = draw("delta_rl5.toml");
    let p = render(&d, "delta_rl5.toml");
    same_scale(&d);
    views_not_blank(&d, &p);
    // The RL5's published geometry: motors on a base circle of radius 0.33 m at 0°, 120°,
    // 240°, in the base plane; the platform's ball pairs' midpoints on a 0.125 m circle at the
    // same angles, the platform 1 m below the base at home.
    let ring = |r: f64, z: f64| -> Vec<[f64; 3]> {
        [0.0f64, 120.0, 240.0]
            .iter()
            .map(|a| {
                let (s, c) = a.to_radians().sin_cos();
                [r * c, r * s, z]
            })
            .collect()
    };
    highlights_at(&d, &p, ACTUATED, &ring(0.33, 0.0));
    highlights_at(&d, &p, CUT, &ring(0.125, -1.0));
    // No loop is open: no gap label.
    assert!(!d.svg.contains(">gap "));
    // Both rods of each parallelogram: 2 rods + 2 short sides, 3 legs.
    let rods = d.svg.matches(r#"stroke-width="1.5"/>"#).count();
    assert!(rods >= 12 * 3, "{rods}");
}

#[test]
fn four_bar_cut_and_crank_where_the_spec_publishes_them() {
    let d = draw("four_bar.toml");
    let p = render(&d, "four_bar.toml");
    same_scale(&d);
    // Planar in x–y: the top view carries the names.
    assert_eq!(d.named, 2);
    // The crank pivot at the origin; the coupler–rocker joint at C = (0.63297, 0.49891, 0) m,
    // the header's circle intersection (crank 0.2 m up, coupler 0.7 m, rocker 0.5 m from
    // (0.6, 0, 0)).
    highlights_at(&d, &p, ACTUATED, &[[0.0, 0.0, 0.0]]);
    highlights_at(&d, &p, CUT, &[[0.63297, 0.49891, 0.0]]);
    // The top view has the loop (the front view sees it edge-on): the bars' lines, a quarter
    // along the crank, the coupler and the rocker.
    let top = &d.views[2];
    let quarter =
        |a: [f64; 3], b: [f64; 3]| top.project(&std::array::from_fn(|k| 0.75 * a[k] + 0.25 * b[k]));
    let (o2, b, c, o4) = (
        [0.0; 3],
        [0.0, 0.2, 0.0],
        [0.63297, 0.49891, 0.0],
        [0.6, 0.0, 0.0],
    );
    let body = pixels_of(&p, codegen::draw::BODY, 30);
    for q in [quarter(o2, b), quarter(b, c), quarter(o4, c)] {
        assert!(
            body.iter().any(|f| dist(*f, q) < 4.0),
            "no body line at {q:?}"
        );
    }
}

#[test]
fn puma_joints_on_its_dh_table() {
    let d = draw("puma560.toml");
    let p = render(&d, "puma560.toml");
    same_scale(&d);
    views_not_blank(&d, &p);
    // Standard DH (Corke & Armstrong-Helouvry): j1 and j2 at the origin, j3 at a2 = 0.4318
    // along x, j4 at a3 = 0.0203 further and d3 = 0.15005 along −y, j5 and j6 at the wrist
    // centre d4 = 0.4318 above j4. Every joint of a tree is an effort input.
    let expected = [
        [0.0, 0.0, 0.0],
        [0.4318, 0.0, 0.0],
        [0.4521, -0.15005, 0.0],
        [0.4521, -0.15005, 0.4318],
    ];
    highlights_at(&d, &p, ACTUATED, &expected);
    assert!(
        pixels_of(&p, CUT, 24)
            .iter()
            .all(|f| !d.views.iter().any(|v| v.contains(f.0, f.1)))
    );
}

#[test]
fn bricard_and_a_urdf_draw() {
    let d = draw("bricard.toml");
    let p = render(&d, "bricard.toml");
    views_not_blank(&d, &p);
    assert!(!pixels_of(&p, CUT, 24).is_empty());
    let d = draw("iiwa14.urdf");
    let p = render(&d, "iiwa14.urdf");
    views_not_blank(&d, &p);
}

#[test]
fn the_same_spec_gives_the_same_bytes() {
    for name in ["delta_rl5.toml", "four_bar.toml", "puma560.toml"] {
        assert_eq!(draw(name).svg, draw(name).svg, "{name}");
    }
}

/// A loop left open at home as written is drawn with its gap (and the spec's error).
#[test]
fn an_open_loop_shows_its_gap() {
    let (path, text) = spec("four_bar.toml");
    // The rocker's end 5 mm short: the loop is open by about 5 mm at home.
    let open = text.replace(
        "child_origin = { xyz = [0.5, 0.0, 0.0] }",
        "child_origin = { xyz = [0.495, 0.0, 0.0] }",
    );
    assert_ne!(open, text);
    let (d, diags) = codegen::draw::draw(&path, &open).expect("drawn despite the error");
    assert!(diags.has_errors(), "{}", diags.render());
    assert!(d.svg.contains(">gap 5.000 mm<"), "{}", d.svg);
    let p = render(&d, "four_bar_open");
    // Both sides of the cut are marked: the gap line and the two squares.
    let top = &d.views[2];
    let c = [0.63297, 0.49891, 0.0];
    let cut = pixels_of(&p, CUT, 24);
    assert!(cut.iter().any(|f| dist(*f, top.project(&c)) < 14.0));
}

/// One small drawing, reviewed as text.
#[test]
fn four_bar_snapshot() {
    insta::assert_snapshot!(draw("four_bar.toml").svg);
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_codegen"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .expect("the codegen binary runs")
}

#[test]
fn cli_writes_the_drawing_and_refuses_bad_input() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("draw_cli");
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let out = dir.join("home.svg");
    let o = run(&[
        "draw",
        "../mechanisms/specs/four_bar.toml",
        "-o",
        out.to_str().expect("UTF-8 path"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let written = std::fs::read_to_string(&out).expect("written");
    assert_eq!(written, draw("four_bar.toml").svg);
    // Standard output by default.
    let o = run(&["draw", "../mechanisms/specs/four_bar.toml"]);
    assert!(o.status.success());
    assert_eq!(String::from_utf8_lossy(&o.stdout), written);
    // Bad input: the usual diagnostics, exit code 2, nothing on standard output.
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[mechanism]\nname = \"x\"\n[[joint]]\nname = \"j\"\nkind = \"revolute\"\nparent = \"base\"\nchild = \"nowhere\"\n").unwrap();
    let o = run(&["draw", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    assert!(String::from_utf8_lossy(&o.stderr).contains("nowhere"));
    // An empty spec (no `[mechanism]`) is no mechanism: exit 2 and no file (QA: it wrote an
    // empty picture of `unnamed` with exit 2).
    let empty = dir.join("empty.toml");
    std::fs::write(&empty, "").unwrap();
    let svg = dir.join("empty.svg");
    let o = run(&["draw", empty.to_str().unwrap(), "-o", svg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing [mechanism]"));
    assert!(!svg.exists(), "nothing written");
    let o = run(&["draw", "no/such/file.toml"]);
    assert_eq!(o.status.code(), Some(1));
}

/// Every spec of the test data, good or bad, draws or is refused: never a panic.
#[test]
fn no_input_panics() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let mut seen = 0;
    for dir in std::fs::read_dir(&data).expect("test data") {
        let dir = dir.expect("entry").path();
        if !dir.is_dir() {
            continue;
        }
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .expect("dir")
            .map(|e| e.expect("entry").path())
            .collect();
        files.sort();
        for f in files {
            let Ok(text) = std::fs::read_to_string(&f) else {
                continue;
            };
            let name = f.to_string_lossy().into_owned();
            if let Ok((d, _)) = codegen::draw::draw(&name, &text) {
                usvg::Tree::from_str(&d.svg, &usvg::Options::default()).expect("the SVG parses");
            }
            seen += 1;
        }
    }
    assert!(seen > 20, "{seen}");
}

/// A long chain written leaf first (as long as one path may be): every joint placed, each link
/// 0.1 m along x.
#[test]
fn a_chain_written_backwards_draws() {
    let n = codegen::spec::MAX_PATH_DOF;
    let mut text = String::from("[mechanism]\nname = \"chain\"\n");
    for i in (0..n).rev() {
        let parent = if i == 0 {
            "base".to_string()
        } else {
            format!("b{}", i - 1)
        };
        text.push_str(&format!(
            "[[body]]\nname = \"b{i}\"\nmass = 1.0\n[[joint]]\nname = \"j{i}\"\nkind = \"revolute\"\nparent = \"{parent}\"\nchild = \"b{i}\"\norigin = {{ xyz = [0.1, 0.0, 0.0] }}\naxis = [0.0, 0.0, 1.0]\n"
        ));
    }
    let (home, _) = codegen::spec::home_pose("chain.toml", &text).expect("placed");
    assert_eq!(home.joints.len(), n);
    for j in &home.joints {
        let i: f64 = j.name[1..].parse().unwrap();
        assert!(
            (j.at[0] - 0.1 * (i + 1.0)).abs() < 1e-12,
            "{}: {:?}",
            j.name,
            j.at
        );
        assert!(j.actuated);
    }
}
