//! `cargo xtask rank-specs`: writes the test specs of `tests/data/` whose loops are turned in
//! space, with full-precision numbers that close every loop at home (checked here to 1e-15 m).
//!
//! Conventions as in mechanisms/specs: R = Rz(yaw)·Ry(pitch)·Rx(roll), a body's frame is its
//! joint's frame after the motion, every tree joint is at zero at home.
//!
//! * `planar_3rrr_inclined.toml`: a planar 3-RRR (three R-R-R legs from the base to a
//!   triangular platform, the base joints actuated) on a plane inclined by rpy = (0.3, 0.2, 0):
//!   3 DOF.
//! * `delta_4r.toml`: a Delta robot whose forearm parallelograms are four revolute joints each
//!   (with a revolute at each end of the parallelogram, parallel to the actuated axis), legs at
//!   120°: 16 tree joints, 5 loop-closing joints, loop equations of rank 13, 3 DOF.

use std::f64::consts::PI;
use std::path::Path;

use crate::pyfmt::{V3, add, cross, repr, scale, sub, sum};
use crate::pymath::{hypot, square};

const PLANAR_3RRR_HEADER: &str = "# A planar 3-RRR (three R-R-R legs from the base to a triangular platform, the base joints\n# actuated) on a plane inclined by rpy = (0.3, 0.2, 0): 3 DOF. Test data of\n# tests/tests/turned.rs, written by `cargo xtask rank-specs` (illustrative numbers).\n# Legs at 120° on a 0.5 m circle, links 0.32 m and 0.3 m, platform joints on a 0.12 m\n# circle; the platform frame is at the first leg's platform joint, turned by 0.2 rad.\n";

const DELTA_4R_HEADER: &str = "# A Delta robot whose forearm parallelograms are four revolute joints each, legs at 120°.\n# Leg i (frame turned by 120° i about z, x outward): the actuated revolute at A about y,\n# the upper arm to the elbow E, a revolute about y to the elbow bar (along y, 0.08 m), the\n# parallelogram: two 0.6 m rods on revolutes about n = y × d (d the rod direction) to the\n# platform bar, and a revolute about y to the platform. Tree: 16 joints; loop-closing: the\n# three second rods and legs 2 and 3 at the platform; loop equations of rank 13: 3 DOF.\n# Test data of tests/tests/turned.rs, written by `cargo xtask rank-specs`\n# (illustrative numbers).\n";

fn dot(a: V3, b: V3) -> f64 {
    sum((0..3).map(|i| a[i] * b[i]))
}

fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

fn rz(t: f64, v: V3) -> V3 {
    let (c, s) = (t.cos(), t.sin());
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

/// Points in the plane of 2-vectors at distance `ra` from `a` and `rc` from `c`; `pick` ±1.
fn circle_meet(a: [f64; 2], ra: f64, c: [f64; 2], rc: f64, pick: f64) -> [f64; 2] {
    let d = [c[0] - a[0], c[1] - a[1]];
    let dd = hypot(d[0], d[1]);
    let x = (ra * ra - rc * rc + dd * dd) / (2.0 * dd);
    let y = pick * (ra * ra - x * x).sqrt();
    let ex = [d[0] / dd, d[1] / dd];
    [a[0] + x * ex[0] - y * ex[1], a[1] + x * ex[1] + y * ex[0]]
}

fn vec(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| repr(*x)).collect();
    format!("[{}]", items.join(", "))
}

fn body(name: &str, mass: f64, com: V3, i: V3) -> String {
    format!(
        "[[body]]\nname = \"{name}\"\nmass = {}\ncom = {}\ninertia = {{ ixx = {}, iyy = {}, izz = {} }}\n",
        repr(mass),
        vec(&com),
        repr(i[0]),
        repr(i[1]),
        repr(i[2])
    )
}

/// A `[[joint]]` table: `origin` with `xyz` and `rpy`, then `axis` if any, then `extra` lines.
fn joint(names: [&str; 4], xyz: V3, rpy: V3, axis: Option<V3>, extra: &str) -> String {
    let [name, kind, parent, child] = names;
    let mut s = format!(
        "[[joint]]\nname = \"{name}\"\nkind = \"{kind}\"\nparent = \"{parent}\"\nchild = \"{child}\"\n"
    );
    s += &format!("origin = {{ xyz = {}, rpy = {} }}\n", vec(&xyz), vec(&rpy));
    if let Some(axis) = axis {
        s += &format!("axis = {}\n", vec(&axis));
    }
    s + extra
}

/// Slender rod along x: (ixx, iyy, izz) about its centre (a 1 cm square section).
fn rod(m: f64, length: f64) -> V3 {
    let a = m * 2.0 * square(0.01) / 12.0;
    let b = m * (square(length) + square(0.01)) / 12.0;
    [a, b, b]
}

const NONE: V3 = [0.0, 0.0, 0.0];

fn planar_3rrr() -> String {
    let (rb, rp, l1, l2) = (0.5, 0.12, 0.32, 0.3);
    let (psi, centre) = (0.2, [0.02, -0.01, 0.0]); // platform orientation and centre in the plane
    let th: Vec<f64> = (0..3)
        .map(|i| PI / 2.0 + 2.0 * PI * i as f64 / 3.0)
        .collect();
    let a: Vec<V3> = th
        .iter()
        .map(|t| [rb * t.cos(), rb * t.sin(), 0.0])
        .collect();
    let c: Vec<V3> = th
        .iter()
        .map(|t| add(centre, rz(psi, [rp * t.cos(), rp * t.sin(), 0.0])))
        .collect();
    let mut b: Vec<V3> = Vec::new();
    for i in 0..3 {
        let e = circle_meet([a[i][0], a[i][1]], l1, [c[i][0], c[i][1]], l2, 1.0);
        b.push([e[0], e[1], 0.0]);
        assert!(
            (norm(sub(b[i], a[i])) - l1).abs() < 1e-15
                && (norm(sub(c[i], b[i])) - l2).abs() < 1e-15
        );
    }
    let al: Vec<f64> = (0..3)
        .map(|i| (b[i][1] - a[i][1]).atan2(b[i][0] - a[i][0]))
        .collect();
    let be: Vec<f64> = (0..3)
        .map(|i| (c[i][1] - b[i][1]).atan2(c[i][0] - b[i][0]))
        .collect();
    let mut out = vec![
        PLANAR_3RRR_HEADER.to_string(),
        "[mechanism]\nname = \"planar_3rrr_inclined\"\ngravity = [0.0, 0.0, -9.81]\n".into(),
        body("plane", 0.0, NONE, NONE),
        joint(
            ["mount", "fixed", "base", "plane"],
            [0.05, -0.02, 0.1],
            [0.3, 0.2, 0.0],
            None,
            "",
        ),
    ];
    let com = rz(-psi, sub(centre, c[0]));
    out.push(body("platform", 0.6, com, [2e-3, 2e-3, 4e-3]));
    let z = [0.0, 0.0, 1.0];
    for i in 0..3 {
        let k = i + 1;
        let (proximal, distal) = (format!("proximal{k}"), format!("distal{k}"));
        out.push(body(&proximal, 0.4, [l1 / 2.0, 0.0, 0.0], rod(0.4, l1)));
        out.push(body(&distal, 0.3, [l2 / 2.0, 0.0, 0.0], rod(0.3, l2)));
        out.push(joint(
            [&format!("a{k}"), "revolute", "plane", &proximal],
            a[i],
            [0.0, 0.0, al[i]],
            Some(z),
            "actuated = true\n",
        ));
        out.push(joint(
            [&format!("b{k}"), "revolute", &proximal, &distal],
            [l1, 0.0, 0.0],
            [0.0, 0.0, be[i] - al[i]],
            Some(z),
            "",
        ));
        if i == 0 {
            let names = ["c1", "revolute", "distal1", "platform"];
            out.push(joint(
                names,
                [l2, 0.0, 0.0],
                [0.0, 0.0, psi - be[0]],
                Some(z),
                "",
            ));
        } else {
            let co = rz(-psi, sub(c[i], c[0]));
            let extra = format!(
                "child_origin = {{ xyz = {}, rpy = {} }}\n",
                vec(&co),
                vec(&[0.0, 0.0, be[i] - psi])
            );
            let names = [&format!("c{k}"), "revolute", &distal, "platform"];
            out.push(joint(names, [l2, 0.0, 0.0], NONE, Some(z), &extra));
        }
    }
    out.join("\n")
}

/// Leg `i` of the Delta robot, its tables appended to `out`.
fn delta_leg(out: &mut Vec<String>, i: usize, phi: f64, c_base: &[V3]) {
    let (rb, la, lf, w) = (0.2, 0.25, 0.6, 0.08);
    let y = [0.0, 1.0, 0.0];
    let k = i + 1;
    let a = [rb, 0.0, 0.0];
    let c = rz(-phi, c_base[i]); // leg frame
    // The elbow on the circle of radius la about A in the x-z plane, at distance lf from C.
    let r = (lf * lf - c[1] * c[1]).sqrt();
    let mut ex = circle_meet([a[0], a[2]], la, [c[0], c[2]], r, -1.0);
    let mut e = [ex[0], 0.0, ex[1]];
    if e[0] < a[0] {
        ex = circle_meet([a[0], a[2]], la, [c[0], c[2]], r, 1.0);
        e = [ex[0], 0.0, ex[1]];
    }
    assert!((norm(sub(e, a)) - la).abs() < 1e-15 && (norm(sub(c, e)) - lf).abs() < 1e-15);
    let d = scale(1.0 / lf, sub(c, e));
    let n = cross(y, d);
    let n = scale(1.0 / norm(n), n);
    let ce = sub(c, e);
    let names = ["upper", "elbow_bar", "rod_a", "rod_b", "platform_bar"].map(|b| format!("{b}{k}"));
    let [upper, elbow, rod_a, rod_b, bar] = &names;
    out.push(body(
        upper,
        0.3,
        scale(0.5, sub(e, a)),
        [6e-4, 1.6e-3, 1.6e-3],
    ));
    out.push(body(elbow, 0.02, NONE, [1.1e-5, 2e-7, 1.1e-5]));
    out.push(body(rod_a, 0.05, scale(0.5, ce), [1.5e-3, 1.5e-3, 1e-6]));
    out.push(body(rod_b, 0.05, scale(0.5, ce), [1.5e-3, 1.5e-3, 1e-6]));
    out.push(body(bar, 0.02, [0.0, w / 2.0, 0.0], [1.1e-5, 2e-7, 1.1e-5]));
    let rev = |name: &str, parent: &str, child: &str, xyz: V3, rpy: V3, axis: V3, extra: &str| {
        joint(
            [&format!("{name}{k}"), "revolute", parent, child],
            xyz,
            rpy,
            Some(axis),
            extra,
        )
    };
    out.push(rev(
        "a",
        "base",
        upper,
        rz(phi, a),
        [0.0, 0.0, phi],
        y,
        "actuated = true\n",
    ));
    out.push(rev("e", upper, elbow, sub(e, a), NONE, y, ""));
    out.push(rev("ra", elbow, rod_a, [0.0, -w / 2.0, 0.0], NONE, n, ""));
    out.push(rev("sa", rod_a, bar, ce, NONE, n, ""));
    out.push(rev("rb", elbow, rod_b, [0.0, w / 2.0, 0.0], NONE, n, ""));
    let extra = format!("child_origin = {{ xyz = {} }}\n", vec(&[0.0, w, 0.0]));
    out.push(rev("sb", rod_b, bar, ce, NONE, n, &extra));
    if i == 0 {
        out.push(rev("p", bar, "platform", [0.0, w / 2.0, 0.0], NONE, y, ""));
    } else {
        let co = sub(c_base[i], c_base[0]);
        let extra = format!(
            "child_origin = {{ xyz = {}, rpy = {} }}\n",
            vec(&co),
            vec(&[0.0, 0.0, phi])
        );
        out.push(rev(
            "p",
            bar,
            "platform",
            [0.0, w / 2.0, 0.0],
            NONE,
            y,
            &extra,
        ));
    }
    // Closure of the leg at the platform, in the base frame.
    let chain = add(
        add(a, sub(e, a)),
        add([0.0, -w / 2.0, 0.0], add(ce, [0.0, w / 2.0, 0.0])),
    );
    let tip = add(rz(phi, chain), NONE);
    assert!(
        norm(sub(tip, c_base[i])) < 1e-15,
        "{}",
        norm(sub(tip, c_base[i]))
    );
}

fn delta_4r() -> String {
    let rp = 0.05;
    let centre = [0.03, -0.02, -0.5]; // the platform centre at home, off the axis
    let phi: Vec<f64> = (0..3).map(|i| 2.0 * PI * i as f64 / 3.0).collect();
    let mut out = vec![
        DELTA_4R_HEADER.to_string(),
        "[mechanism]\nname = \"delta_4r\"\ngravity = [0.0, 0.0, -9.81]\n".into(),
    ];
    let c_base: Vec<V3> = phi
        .iter()
        .map(|p| add(centre, rz(*p, [rp, 0.0, 0.0])))
        .collect();
    out.push(body(
        "platform",
        0.4,
        sub(centre, c_base[0]),
        [4e-4, 4e-4, 8e-4],
    ));
    for (i, p) in phi.iter().enumerate() {
        delta_leg(&mut out, i, *p, &c_base);
    }
    out.join("\n")
}

/// Writes the two specs into `dir`.
pub fn run(dir: &Path) -> std::io::Result<()> {
    for (name, text) in [
        ("planar_3rrr_inclined", planar_3rrr()),
        ("delta_4r", delta_4r()),
    ] {
        std::fs::write(dir.join(format!("{name}.toml")), text)?;
        println!("wrote {name}.toml");
    }
    Ok(())
}
