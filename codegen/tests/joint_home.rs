//! `home` on a joint (docs/spec.md, "Coordinates at home"): the generated functions take and
//! return absolute coordinates. A tree with `home = h` on its joints, evaluated at `q + h`, is
//! the tree without, at `q` (by the runtime's spatial-algebra RNEA, a route independent of the
//! spec reader); a parallel platform's `inverse_kinematics` returns the actuated joints' home
//! values plus their displacements (the Gough–Stewart's leg lengths, worked out here from
//! Tsai's published points), and `forward_kinematics` takes them; closed loops assemble to the
//! same configurations shifted by their homes, with the same efforts.

use codegen::spec::{Mechanism, load_mechanism};
use runtime::model::Model;

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn bundled(name: &str) -> String {
    std::fs::read_to_string(root().join(format!("mechanisms/specs/{name}.toml"))).unwrap()
}

fn tree(src: &str) -> Model {
    match load_mechanism("t.toml", src) {
        Ok((Mechanism::Tree(m), _)) => m,
        Ok(_) => panic!("not a tree"),
        Err(d) => panic!("{d}"),
    }
}

/// A deterministic stream in [−1, 1).
struct Stream(u64);
impl Stream {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// `src` with `home = value` added after the line `name = "joint"` of each joint named.
fn with_homes(src: &str, homes: &[(&str, &str)]) -> String {
    let mut s = src.to_string();
    for (joint, value) in homes {
        let line = format!("name = \"{joint}\"\n");
        assert!(s.contains(&line), "{joint}");
        s = s.replacen(&line, &format!("{line}home = {value}\n"), 1);
    }
    s
}

fn same_tree_at_offset(src: &str, homes: &[(&str, &str)], h: &[f64]) {
    let (plain, homed) = (tree(src), tree(&with_homes(src, homes)));
    assert_ne!(format!("{plain:?}"), format!("{homed:?}"));
    let n = plain.dof();
    let mut r = Stream(7);
    let mut worst = 0.0f64;
    for _ in 0..200 {
        let q: Vec<f64> = (0..n).map(|_| 2.0 * r.next()).collect();
        let qd: Vec<f64> = (0..n).map(|_| r.next()).collect();
        let qdd: Vec<f64> = (0..n).map(|_| r.next()).collect();
        let qa: Vec<f64> = q.iter().zip(h).map(|(q, h)| q + h).collect();
        let a = runtime::rnea::inverse_dynamics(&plain, &q, &qd, &qdd);
        let b = runtime::rnea::inverse_dynamics(&homed, &qa, &qd, &qdd);
        worst = worst.max((&a - &b).amax() / 1.0f64.max(b.amax()));
    }
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn a_tree_takes_absolute_coordinates() {
    // DH placements: a revolute and the prismatic boom of the Stanford arm.
    let h = [0.0, 30f64.to_radians(), 0.3, 0.0, 0.0, 0.0];
    same_tree_at_offset(
        &bundled("stanford_arm"),
        &[("j2", "\"30 deg\""), ("j3", "0.3")],
        &h,
    );
    // Origin placements: a revolute about y and a prismatic along a slanted axis.
    let arm = r#"
[mechanism]
name = "arm"

[[body]]
name = "link1"
mass = 1.0
com = [0.2, 0.0, 0.0]
inertia = { ixx = 0.01, iyy = 0.02, izz = 0.03 }

[[body]]
name = "link2"
mass = 0.5
com = [0.1, 0.0, 0.05]
inertia = { ixx = 0.004, iyy = 0.005, izz = 0.006 }

[[joint]]
name = "j1"
kind = "revolute"
parent = "base"
child = "link1"
origin = { xyz = [0.0, 0.0, 0.3], rpy = [0.1, 0.2, 0.3] }
axis = [0.0, 1.0, 0.0]

[[joint]]
name = "j2"
kind = "prismatic"
parent = "link1"
child = "link2"
origin = { xyz = [0.5, 0.0, 0.0] }
axis = [1.0, 1.0, 0.0]
"#;
    same_tree_at_offset(
        arm,
        &[("j1", "\"-45 deg\""), ("j2", "0.866")],
        &[(-45f64).to_radians(), 0.866],
    );
}

#[test]
fn a_platform_returns_absolute_leg_lengths() {
    let gs = bundled("gough_stewart");
    let homed = gs.replace(
        "axis = [0.0, 0.0, 1.0]\nactuated = true",
        "axis = [0.0, 0.0, 1.0]\nactuated = true\nhome = \"length\"",
    );
    assert_ne!(gs, homed);
    let plan = |src: &str| match load_mechanism("gs.toml", src) {
        Ok((Mechanism::Parallel(m), _)) => (runtime::parallel::Plan::new(&m).unwrap(), m),
        _ => panic!(),
    };
    let ((p0, m0), (p1, _)) = (plan(&gs), plan(&homed));
    // Tsai's points: b_i, p_i, home (−1.5, 0, 1).
    let b: [[f64; 2]; 6] = [
        [-2.12, 1.374],
        [-2.38, 1.224],
        [-2.38, -1.224],
        [-2.12, -1.374],
        [0.0, -0.15],
        [0.0, 0.15],
    ];
    let p: [[f64; 2]; 6] = [
        [0.17, 0.595],
        [-0.6, 0.15],
        [-0.6, -0.15],
        [0.17, -0.595],
        [0.43, -0.445],
        [0.43, 0.445],
    ];
    let x = m0.home_x();
    let q0 = runtime::parallel::noc::inverse_kinematics(&p0, &x).unwrap();
    let q1 = runtime::parallel::noc::inverse_kinematics(&p1, &x).unwrap();
    for i in 0..6 {
        let l = ((-1.5 + p[i][0] - b[i][0]).powi(2) + (p[i][1] - b[i][1]).powi(2) + 0.6f64.powi(2))
            .sqrt();
        assert!(q0[i].abs() < 1e-14, "{q0:?}");
        assert!((q1[i] - l).abs() < 1e-14, "leg {i}: {} vs {l}", q1[i]);
    }
    // Elsewhere: the same displacement plus the home length; forward kinematics inverts it.
    let xs = [
        x[0] + 0.05,
        x[1] - 0.02,
        x[2] + 0.03,
        0.9987502603949663,
        0.04997916927067833,
        0.0,
        0.0,
    ];
    let (a, c) = (
        runtime::parallel::noc::inverse_kinematics(&p0, &xs).unwrap(),
        runtime::parallel::noc::inverse_kinematics(&p1, &xs).unwrap(),
    );
    let home = runtime::parallel::noc::inverse_kinematics(&p1, &x).unwrap();
    for i in 0..6 {
        assert!((c[i] - a[i] - home[i]).abs() < 1e-14);
    }
    let back = runtime::parallel::noc::forward_kinematics(&p1, &c, &x).unwrap();
    let d = back
        .iter()
        .zip(&xs)
        .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
    assert!(d < 1e-12, "{d:e}");
    // The efforts do not depend on where the coordinates are measured from.
    let u = [0.1, -0.2, 0.3, 0.05, 0.1, -0.1];
    let ud = [1.0, 0.5, -0.3, 0.2, -0.4, 0.6];
    let f0 = runtime::parallel::noc::inverse_dynamics(&p0, &xs, &u, &ud).unwrap();
    let f1 = runtime::parallel::noc::inverse_dynamics(&p1, &xs, &u, &ud).unwrap();
    assert_eq!(f0, f1);
}

#[test]
fn closed_loops_take_absolute_coordinates() {
    let plain_src = bundled("four_bar");
    let h = [0.3, -1.2, 2.0];
    let homed_src = with_homes(
        &plain_src,
        &[
            ("crank_joint", "0.3"),
            ("coupler_joint", "-1.2"),
            ("rocker_joint", "2.0"),
        ],
    );
    let plan = |src: &str| match load_mechanism("f.toml", src) {
        Ok((Mechanism::Closed(m), _)) => runtime::closed::noc::Plan::new(&m).unwrap(),
        Ok(_) => panic!("not closed loops"),
        Err(d) => panic!("{d}"),
    };
    let (p0, p1) = (plan(&plain_src), plan(&homed_src));
    assert_eq!(p1.home(), h.to_vec());
    // Configurations assembled from the crank angle, in both coordinates.
    let mut r = Stream(11);
    for _ in 0..50 {
        let crank = 0.5 * r.next();
        let x0 = runtime::closed::noc::newton_assembly(&p0, &[crank], &[0.0; 3]).unwrap();
        let x1 = runtime::closed::noc::newton_assembly(&p1, &[crank + h[0]], &h).unwrap();
        for i in 0..3 {
            assert!((x1[i] - x0[i] - h[i]).abs() < 1e-12, "{x0:?} {x1:?}");
        }
        let (u, ud) = ([r.next()], [r.next()]);
        let a = runtime::closed::noc::inverse_dynamics(&p0, &x0, &u, &ud).unwrap();
        let b = runtime::closed::noc::inverse_dynamics(&p1, &x1, &u, &ud).unwrap();
        assert!(
            (a[0] - b[0]).abs() < 1e-12 * a[0].abs().max(1.0),
            "{a:?} {b:?}"
        );
    }
    // The generated module's HOME holds them.
    let g = codegen::compile("f.toml", &homed_src, &codegen::Config::default()).unwrap();
    assert!(
        g.code
            .contains("pub const HOME: [f64; NX] = [0.3, -1.2, 2.0];")
    );
}

#[test]
fn home_is_refused_where_it_has_no_meaning() {
    let e = load_mechanism(
        "f.toml",
        &with_homes(&bundled("four_bar"), &[("tip", "0.3")]),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(e.contains("closes a loop, and has no coordinate"), "{e}");
    let e = load_mechanism(
        "g.toml",
        &bundled("gough_stewart").replace("kind = \"S\"\n", "kind = \"S\"\nhome = 0.1\n"),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("`home` is for revolute and prismatic joints, not spherical"),
        "{e}"
    );
}
