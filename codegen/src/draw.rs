//! `codegen draw`: a picture of the home pose, as SVG text (no I/O here; the CLI writes it).
//!
//! Three orthographic views side by side at one scale, fitted to the mechanism's extent: front
//! (x to the right, z up, looking along +y), side (y to the right, z up, looking along −x) and
//! top (x to the right, y up, looking down). Bodies are lines between their joints (the base
//! dashed, a parallelogram's two rods thin), mass centres small dots, joints a marker by kind
//! (revolute: a ring with its axis as a tick; prismatic: a square with its axis; universal: a
//! ring with both axes; spherical: a filled disc; fixed: a small grey square). Actuated joints
//! are ringed in [`ACTUATED`], loop-closing joints in [`CUT`], and where a loop is open at home
//! as written, a dashed line of [`CUT`] joins the two sides with the gap's length. Names are
//! written in one view (the one where the mechanism spreads widest). The same spec gives the
//! same bytes.

use std::fmt::Write as _;

use runtime::model::Vec3;

use crate::diag::Diagnostics;
use crate::spec::{HomePose, JointKind, Part};

/// The highlight of actuated joints (`#d7191c`).
pub const ACTUATED: [u8; 3] = [0xd7, 0x19, 0x1c];
/// The highlight of loop-closing joints and of gaps (`#2c7bb6`).
pub const CUT: [u8; 3] = [0x2c, 0x7b, 0xb6];
/// Bodies' lines (`#333333`).
pub const BODY: [u8; 3] = [0x33, 0x33, 0x33];

/// Side of one view's square panel (px).
pub const PANEL: f64 = 360.0;
/// Margin inside a panel around the mechanism (px).
const MARGIN: f64 = 30.0;
/// Gap between panels and around them (px).
const GUTTER: f64 = 12.0;
/// Height of the title row (px).
const TITLE: f64 = 34.0;
/// Height of the legend rows (px).
const LEGEND: f64 = 58.0;
/// Length of an axis tick for an axis in the view's plane (px).
const TICK: f64 = 16.0;
/// Radius of a joint marker (px).
const R: f64 = 5.0;

/// A base axis (0 = x, 1 = y, 2 = z) and its sign, as a view shows it.
pub type Direction = (usize, f64);

/// One orthographic view: which base axes it shows and where (px, y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Its label (`front (x–z)`, …).
    pub label: &'static str,
    /// The base axes along the view's right and up directions, with their signs.
    pub right: Direction,
    pub up: Direction,
    /// The panel's top-left corner (px).
    pub origin: (f64, f64),
    /// The world point at the panel's centre, along `right` and `up` (m, signed as shown).
    pub centre: (f64, f64),
    /// px per m, the same in every view.
    pub scale: f64,
}

impl View {
    /// Where the base-frame point `p` (m) is drawn (px, y down).
    pub fn project(&self, p: &Vec3) -> (f64, f64) {
        let u = self.right.1 * p[self.right.0];
        let v = self.up.1 * p[self.up.0];
        (
            self.origin.0 + 0.5 * PANEL + self.scale * (u - self.centre.0),
            self.origin.1 + 0.5 * PANEL - self.scale * (v - self.centre.1),
        )
    }

    /// A direction `d` as drawn (px per unit, y down): its in-plane part.
    fn direction(&self, d: &Vec3) -> (f64, f64) {
        (self.right.1 * d[self.right.0], -self.up.1 * d[self.up.0])
    }

    /// `true` when the pixel `(x, y)` is inside this view's panel.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        x >= self.origin.0
            && x < self.origin.0 + PANEL
            && y >= self.origin.1
            && y < self.origin.1 + PANEL
    }
}

/// A drawing: the SVG text and the views' placement (to find things in the rendered image).
#[derive(Clone, Debug, PartialEq)]
pub struct Drawing {
    /// The SVG document.
    pub svg: String,
    /// Front, side and top.
    pub views: [View; 3],
    /// Width and height (px).
    pub size: (f64, f64),
    /// The view that carries the names.
    pub named: usize,
}

/// Read `source` (named `file_name`, TOML or URDF) and draw its home pose, with the spec's
/// diagnostics (which may hold errors when the geometry could still be placed; see
/// [`crate::spec::home_pose`]).
pub fn draw(file_name: &str, source: &str) -> Result<(Drawing, Diagnostics), Diagnostics> {
    let (home, diags) = crate::spec::home_pose(file_name, source)?;
    // A spec with errors and nothing to draw (no `[mechanism]`, no joint, no body) cannot be
    // read as a mechanism: nothing is written (docs/draw.md, "Exit codes").
    let empty = home.joints.is_empty() && home.segments.is_empty() && home.mass_centres.is_empty();
    if empty && diags.has_errors() {
        return Err(diags);
    }
    Ok((svg(&home), diags))
}

fn rgb(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// A number for the SVG text: two decimals, no negative zero.
fn n(x: f64) -> String {
    let s = format!("{x:.2}");
    if s == "-0.00" { "0.00".into() } else { s }
}

/// XML text escaping.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Lengths in the labels: µm below 1 mm, mm below 1 m.
fn length(x: f64) -> String {
    if x < 1e-3 {
        format!("{:.3} µm", x * 1e6)
    } else if x < 1.0 {
        format!("{:.3} mm", x * 1e3)
    } else {
        format!("{x:.4} m")
    }
}

/// The largest 1, 2 or 5 × 10^k not above `x` (> 0).
fn round_length(x: f64) -> f64 {
    let k = x.log10().floor();
    let p = 10f64.powf(k);
    let m = x / p;
    let d = if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    };
    d * p
}

/// A round length as text (`0.2`, `5e-05`).
fn fmt_round(x: f64) -> String {
    if (1e-3..1e4).contains(&x) {
        let s = format!("{x:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{x:e}")
    }
}

/// The views of `home`, fitted: one scale for all three, each centred on the mechanism.
fn views(home: &HomePose) -> [View; 3] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in home.points() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if !lo[0].is_finite() {
        lo = [0.0; 3];
        hi = [0.0; 3];
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let extent = if extent > 1e-9 { extent } else { 1.0 };
    let scale = (PANEL - 2.0 * MARGIN) / extent;
    let mid = |k: usize| 0.5 * (lo[k] + hi[k]);
    let specs: [(&'static str, Direction, Direction); 3] = [
        ("front (x right, z up)", (0, 1.0), (2, 1.0)),
        ("side (y right, z up)", (1, 1.0), (2, 1.0)),
        ("top (x right, y up)", (0, 1.0), (1, 1.0)),
    ];
    std::array::from_fn(|i| {
        let (label, right, up) = specs[i];
        View {
            label,
            right,
            up,
            origin: (GUTTER + i as f64 * (PANEL + GUTTER), TITLE),
            centre: (right.1 * mid(right.0), up.1 * mid(up.0)),
            scale,
        }
    })
}

/// The SVG of `home` (pure; the same pose gives the same bytes).
pub fn svg(home: &HomePose) -> Drawing {
    let views = views(home);
    let width = 4.0 * GUTTER + 3.0 * PANEL;
    let height = TITLE + PANEL + LEGEND;
    // Names go where the mechanism spreads widest (the first such view on a tie).
    let spread = |v: &View| {
        let (mut a, mut b) = (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        );
        for p in home.points() {
            let (x, y) = v.project(&p);
            a = (a.0.min(x), a.1.max(x));
            b = (b.0.min(y), b.1.max(y));
        }
        (a.1 - a.0).max(1.0) * (b.1 - b.0).max(1.0)
    };
    let mut named = 0;
    for i in 1..3 {
        if spread(&views[i]) > spread(&views[named]) * (1.0 + 1e-9) {
            named = i;
        }
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif">"##,
        w = n(width),
        h = n(height)
    );
    let _ = writeln!(s, r##"<rect width="100%" height="100%" fill="#ffffff"/>"##);
    let kind = match home.kind {
        crate::spec::Kind::Tree => "tree",
        crate::spec::Kind::Parallel => "parallel platform",
        crate::spec::Kind::Closed => "closed loops",
    };
    let _ = writeln!(
        s,
        r##"<text x="{x}" y="22" font-size="15">{name}: home pose ({kind}, {j} joints)</text>"##,
        x = n(GUTTER),
        name = esc(&home.name),
        j = home.joints.len(),
    );
    for (i, v) in views.iter().enumerate() {
        draw_view(&mut s, home, v, i == named);
    }
    legend(&mut s, TITLE + PANEL + 8.0);
    s.push_str("</svg>\n");
    Drawing {
        svg: s,
        views,
        size: (width, height),
        named,
    }
}

fn dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

/// A line, left out when it is seen end-on (shorter than a hundredth of a pixel).
fn line(s: &mut String, a: (f64, f64), b: (f64, f64), style: &str) {
    if (a.0 - b.0).hypot(a.1 - b.1) < 0.01 {
        return;
    }
    let _ = writeln!(
        s,
        r##"<line x1="{}" y1="{}" x2="{}" y2="{}" {style}/>"##,
        n(a.0),
        n(a.1),
        n(b.0),
        n(b.1)
    );
}

fn draw_view(s: &mut String, home: &HomePose, v: &View, names: bool) {
    let (x0, y0) = v.origin;
    let _ = writeln!(
        s,
        r##"<g><rect x="{}" y="{}" width="{p}" height="{p}" fill="#fafafa" stroke="#bbbbbb"/>"##,
        n(x0),
        n(y0),
        p = n(PANEL)
    );
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" font-size="12" fill="#555555">{}</text>"##,
        n(x0 + 6.0),
        n(y0 + 16.0),
        v.label
    );
    // Scale bar, bottom left: a round length near a quarter of the panel.
    let metres = round_length(0.25 * PANEL / v.scale);
    let bar = metres * v.scale;
    line(
        s,
        (x0 + 8.0, y0 + PANEL - 10.0),
        (x0 + 8.0 + bar, y0 + PANEL - 10.0),
        r##"stroke="#888888" stroke-width="2""##,
    );
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{}" font-size="10" fill="#555555">{} m</text>"##,
        n(x0 + 8.0),
        n(y0 + PANEL - 15.0),
        fmt_round(metres)
    );
    let body = rgb(BODY);
    for seg in &home.segments {
        let style = match seg.part {
            Part::Body => format!(r##"stroke="{body}" stroke-width="3" stroke-linecap="round""##),
            Part::Base => {
                r##"stroke="#999999" stroke-width="1.5" stroke-dasharray="5 3""##.to_string()
            }
            Part::Rod => format!(r##"stroke="{body}" stroke-width="1.5""##),
        };
        line(s, v.project(&seg.from), v.project(&seg.to), &style);
    }
    for (_, c) in &home.mass_centres {
        let (x, y) = v.project(c);
        let _ = writeln!(
            s,
            r##"<circle cx="{}" cy="{}" r="2" fill="#777777"/>"##,
            n(x),
            n(y)
        );
    }
    let cut = rgb(CUT);
    for j in &home.joints {
        if let Some(c) = j.closes {
            let d = [c[0] - j.at[0], c[1] - j.at[1], c[2] - j.at[2]];
            let gap = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let (a, b) = (v.project(&j.at), v.project(&c));
            // Open beyond the generator's tolerance (1e-9 × the mechanism's size).
            if gap * v.scale > 1e-9 * (PANEL - 2.0 * MARGIN) {
                line(
                    s,
                    a,
                    b,
                    &format!(r##"stroke="{cut}" stroke-width="2" stroke-dasharray="3 2""##),
                );
                if names {
                    let _ = writeln!(
                        s,
                        r##"<text x="{}" y="{}" font-size="10" fill="{cut}">gap {}</text>"##,
                        n(0.5 * (a.0 + b.0) + 6.0),
                        n(0.5 * (a.1 + b.1) + 12.0),
                        length(gap)
                    );
                }
            }
        }
    }
    for j in &home.joints {
        for p in std::iter::once(j.at).chain(j.closes) {
            marker(s, v, j, &v.project(&p));
        }
    }
    if names {
        // Joints drawn at one place share a label; a label that would leave the panel on the
        // right ends left of its joint.
        let mut labels: Vec<((f64, f64), Vec<&str>)> = Vec::new();
        for j in &home.joints {
            let at = v.project(&j.at);
            match labels.iter_mut().find(|(p, _)| dist(*p, at) < 2.0) {
                Some((_, names)) => names.push(&j.name),
                None => labels.push((at, vec![&j.name])),
            }
        }
        for ((x, y), names) in labels {
            let text = names.join(", ");
            let wide = 5.5 * text.chars().count() as f64;
            let (tx, anchor) = if x + 7.0 + wide > x0 + PANEL - 2.0 {
                (x - 7.0, r#" text-anchor="end""#)
            } else {
                (x + 7.0, "")
            };
            let _ = writeln!(
                s,
                r##"<text x="{}" y="{}" font-size="9" fill="#444444" stroke="#ffffff" stroke-width="2.5" paint-order="stroke"{anchor}>{}</text>"##,
                n(tx),
                n(y - 6.0),
                esc(&text)
            );
        }
    }
    s.push_str("</g>\n");
}

/// A joint's marker at `at` (px), with its highlights.
fn marker(s: &mut String, v: &View, j: &crate::spec::HomeJoint, at: &(f64, f64)) {
    let (x, y) = *at;
    let body = rgb(BODY);
    if j.actuated {
        let _ = writeln!(
            s,
            r##"<circle cx="{}" cy="{}" r="{}" fill="none" stroke="{}" stroke-width="3"/>"##,
            n(x),
            n(y),
            n(R + 4.0),
            rgb(ACTUATED)
        );
    }
    if j.closes.is_some() {
        let _ = writeln!(
            s,
            r##"<rect x="{}" y="{}" width="{w}" height="{w}" fill="none" stroke="{}" stroke-width="2.5"/>"##,
            n(x - R - 4.0),
            n(y - R - 4.0),
            rgb(CUT),
            w = n(2.0 * (R + 4.0))
        );
    }
    for a in &j.axes {
        let (dx, dy) = v.direction(a);
        line(
            s,
            (x - TICK * dx, y - TICK * dy),
            (x + TICK * dx, y + TICK * dy),
            &format!(r##"stroke="{body}" stroke-width="1.5""##),
        );
    }
    match j.kind {
        JointKind::Revolute | JointKind::Universal => {
            let _ = writeln!(
                s,
                r##"<circle cx="{}" cy="{}" r="{}" fill="#ffffff" stroke="{body}" stroke-width="1.5"/>"##,
                n(x),
                n(y),
                n(R)
            );
            if j.kind == JointKind::Universal {
                let _ = writeln!(
                    s,
                    r##"<circle cx="{}" cy="{}" r="1.5" fill="{body}"/>"##,
                    n(x),
                    n(y)
                );
            }
        }
        JointKind::Prismatic => {
            let _ = writeln!(
                s,
                r##"<rect x="{}" y="{}" width="{w}" height="{w}" fill="#ffffff" stroke="{body}" stroke-width="1.5"/>"##,
                n(x - R),
                n(y - R),
                w = n(2.0 * R)
            );
        }
        JointKind::Spherical => {
            let _ = writeln!(
                s,
                r##"<circle cx="{}" cy="{}" r="{}" fill="{body}"/>"##,
                n(x),
                n(y),
                n(R)
            );
        }
        JointKind::Fixed => {
            let _ = writeln!(
                s,
                r##"<rect x="{}" y="{}" width="6" height="6" fill="#999999"/>"##,
                n(x - 3.0),
                n(y - 3.0)
            );
        }
    }
}

/// The legend: one sample of each mark, in a row under the views.
fn legend(s: &mut String, top: f64) {
    let body = rgb(BODY);
    let mut x = GUTTER + 10.0;
    let y = top + 14.0;
    let item = |s: &mut String, x: &mut f64, draw: &dyn Fn(&mut String, f64), label: &str| {
        draw(s, *x);
        let _ = writeln!(
            s,
            r##"<text x="{}" y="{}" font-size="11">{}</text>"##,
            n(*x + 14.0),
            n(y + 4.0),
            label
        );
        *x += 24.0 + 6.5 * label.chars().count() as f64;
    };
    let ring = |fill: &'static str| {
        let body = body.clone();
        move |s: &mut String, x: f64| {
            let _ = writeln!(
                s,
                r##"<circle cx="{}" cy="{}" r="{}" fill="{}" stroke="{body}" stroke-width="1.5"/>"##,
                n(x),
                n(y),
                n(R),
                if fill.is_empty() { body.as_str() } else { fill }
            );
        }
    };
    item(s, &mut x, &ring("#ffffff"), "revolute (tick: axis)");
    item(
        s,
        &mut x,
        &|s: &mut String, x: f64| {
            let _ = writeln!(
                s,
                r##"<rect x="{}" y="{}" width="{w}" height="{w}" fill="#ffffff" stroke="{body}" stroke-width="1.5"/>"##,
                n(x - R),
                n(y - R),
                w = n(2.0 * R)
            );
        },
        "prismatic",
    );
    item(
        s,
        &mut x,
        &|s: &mut String, x: f64| {
            ring("#ffffff")(s, x);
            let _ = writeln!(
                s,
                r##"<circle cx="{}" cy="{}" r="1.5" fill="{body}"/>"##,
                n(x),
                n(y)
            );
        },
        "universal (two ticks)",
    );
    item(s, &mut x, &ring(""), "spherical");
    item(
        s,
        &mut x,
        &|s: &mut String, x: f64| {
            let _ = writeln!(
                s,
                r##"<rect x="{}" y="{}" width="6" height="6" fill="#999999"/>"##,
                n(x - 3.0),
                n(y - 3.0)
            );
        },
        "fixed",
    );
    item(
        s,
        &mut x,
        &|s: &mut String, x: f64| {
            let _ = writeln!(
                s,
                r##"<circle cx="{}" cy="{}" r="2" fill="#777777"/>"##,
                n(x),
                n(y)
            );
        },
        "mass centre",
    );
    let mut x = GUTTER + 10.0;
    let y = y + 22.0;
    let mut item2 = |s: &mut String, draw: &dyn Fn(&mut String, f64, f64), label: &str| {
        draw(s, x, y);
        let _ = writeln!(
            s,
            r##"<text x="{}" y="{}" font-size="11">{}</text>"##,
            n(x + 16.0),
            n(y + 4.0),
            label
        );
        x += 30.0 + 6.5 * label.chars().count() as f64;
    };
    item2(
        s,
        &|s: &mut String, x: f64, y: f64| {
            let _ = writeln!(
                s,
                r##"<circle cx="{}" cy="{}" r="{}" fill="none" stroke="{}" stroke-width="3"/>"##,
                n(x),
                n(y),
                n(R + 1.0),
                rgb(ACTUATED)
            );
        },
        "actuated",
    );
    item2(
        s,
        &|s: &mut String, x: f64, y: f64| {
            let _ = writeln!(
                s,
                r##"<rect x="{}" y="{}" width="12" height="12" fill="none" stroke="{}" stroke-width="2.5"/>"##,
                n(x - 6.0),
                n(y - 6.0),
                rgb(CUT)
            );
        },
        "closes a loop (drawn on both sides)",
    );
    item2(
        s,
        &|s: &mut String, x: f64, y: f64| {
            line(
                s,
                (x - 8.0, y),
                (x + 8.0, y),
                &format!(
                    r##"stroke="{}" stroke-width="2" stroke-dasharray="3 2""##,
                    rgb(CUT)
                ),
            );
        },
        "gap: loop open at home",
    );
    item2(
        s,
        &|s: &mut String, x: f64, y: f64| {
            line(
                s,
                (x - 8.0, y),
                (x + 8.0, y),
                &format!(r##"stroke="{}" stroke-width="3""##, rgb(BODY)),
            );
        },
        "body",
    );
    item2(
        s,
        &|s: &mut String, x: f64, y: f64| {
            line(
                s,
                (x - 8.0, y),
                (x + 8.0, y),
                r##"stroke="#999999" stroke-width="1.5" stroke-dasharray="5 3""##,
            );
        },
        "base",
    );
    item2(
        s,
        &|s: &mut String, x: f64, y: f64| {
            line(
                s,
                (x - 8.0, y),
                (x + 8.0, y),
                &format!(r##"stroke="{}" stroke-width="1.5""##, rgb(BODY)),
            );
        },
        "parallelogram rods",
    );
}
