//! A universal joint's `cross` (docs/spec.md, "Joint kinds"): the cross's mass enters the model
//! as the body `<joint>_cross` in the frame the docs state. Checked against the same mechanism
//! written with two revolute joints and an explicit `[[body]]` between them (the loader's body
//! route, which the `cross` key does not use), against a gravity torque worked by hand, and for
//! its diagnostics (file, line, key; the body checks).

use codegen::spec::{Mechanism, load_mechanism};
use runtime::model::Model;

/// A U joint pendulum: the U turned and placed off the origin, its axes not orthogonal, the
/// cross off-centre with a full inertia given in rotated axes and with `[parameters]`.
const WITH_KEY: &str = r#"
[mechanism]
name = "u_pendulum"
gravity = [0.0, 0.0, -9.81]

[parameters]
mc = 0.35
ix = "2e-3"

[[body]]
name = "arm"
mass = 1.2
com = [0.05, -0.02, -0.3]
inertia = { ixx = 0.03, iyy = 0.025, izz = 0.004, ixy = 0.001 }

[[joint]]
name = "u"
kind = "universal"
parent = "base"
child = "arm"
origin = { xyz = [0.1, -0.2, 0.5], rpy = [0.3, -0.2, 0.7] }
axes = [[1.0, 0.0, 0.0], [0.2, 1.0, 0.1]]
cross = { mass = "mc", com = [0.02, -0.03, 0.04], inertia = { ixx = "ix", iyy = 0.003, izz = 0.0025, ixy = 0.0002, ixz = -0.0001, iyz = 0.0003 }, inertia_rpy = [0.1, 0.2, -0.3] }
"#;

/// The same mechanism as two revolutes and an explicit cross body, its numbers written out by
/// hand: `axes[1]` normalized by the loader as the U's is; the same `inertia_rpy`.
const EXPLICIT: &str = r#"
[mechanism]
name = "u_pendulum"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "u_cross"
mass = 0.35
com = [0.02, -0.03, 0.04]
inertia = { ixx = 0.002, iyy = 0.003, izz = 0.0025, ixy = 0.0002, ixz = -0.0001, iyz = 0.0003 }
inertia_rpy = [0.1, 0.2, -0.3]

[[body]]
name = "arm"
mass = 1.2
com = [0.05, -0.02, -0.3]
inertia = { ixx = 0.03, iyy = 0.025, izz = 0.004, ixy = 0.001 }

[[joint]]
name = "u_1"
kind = "revolute"
parent = "base"
child = "u_cross"
origin = { xyz = [0.1, -0.2, 0.5], rpy = [0.3, -0.2, 0.7] }
axis = [1.0, 0.0, 0.0]

[[joint]]
name = "u_2"
kind = "revolute"
parent = "u_cross"
child = "arm"
axis = [0.2, 1.0, 0.1]
"#;

fn tree(name: &str, src: &str) -> Model {
    match load_mechanism(name, src) {
        Ok((Mechanism::Tree(m), _)) => m,
        Ok(_) => panic!("{name}: not a tree"),
        Err(d) => panic!("{d}"),
    }
}

/// Uniform in [-1, 1) (a fixed LCG: the test is deterministic).
fn uniform(s: &mut u64) -> f64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, x| a.max(x.abs()))
}

#[test]
fn the_cross_key_is_the_explicit_cross_body() {
    let a = tree("a.toml", WITH_KEY);
    let b = tree("b.toml", EXPLICIT);
    let massless = tree("c.toml", &WITH_KEY.replace("cross = {", "# cross = {"));
    assert_eq!(a.dof(), 2);
    let mut s = 7u64;
    let (mut worst, mut effect) = (0.0f64, f64::INFINITY);
    for _ in 0..200 {
        let q: Vec<f64> = (0..2).map(|_| 3.0 * uniform(&mut s)).collect();
        let qd: Vec<f64> = (0..2).map(|_| 4.0 * uniform(&mut s)).collect();
        let qdd: Vec<f64> = (0..2).map(|_| 10.0 * uniform(&mut s)).collect();
        let ta = runtime::rnea::inverse_dynamics(&a, &q, &qd, &qdd);
        let tb = runtime::rnea::inverse_dynamics(&b, &q, &qd, &qdd);
        let t0 = runtime::rnea::inverse_dynamics(&massless, &q, &qd, &qdd);
        let d: Vec<f64> = (0..2).map(|k| ta[k] - tb[k]).collect();
        let e: Vec<f64> = (0..2).map(|k| ta[k] - t0[k]).collect();
        let scale = max_abs(tb.as_slice());
        // Relative error in the max norm over the two efforts.
        worst = worst.max(max_abs(&d) / scale);
        effect = effect.min(max_abs(&e) / scale);
    }
    eprintln!(
        "with the key vs explicit: {worst:e}; the cross's effect: {effect:e} (max-norm relative)"
    );
    assert!(worst <= 1e-12, "with the key vs explicit: {worst:e}");
    // The cross matters: without it every state's efforts differ.
    assert!(effect > 1e-4, "the cross changes nothing: {effect:e}");
}

/// By hand: a U at the base with axes x then y, a massless arm, the cross a point mass `m` at
/// `(0, 0, -l)` in its frame. Held still at `q = (q1, q2)`, the cross hangs from the first axis:
/// its weight's moment about `x` is `m g l sin q1` (the effort that holds it is that), and the
/// second joint carries nothing.
#[test]
fn a_cross_point_mass_hangs_from_the_first_axis() {
    let src = r#"
[mechanism]
name = "u"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "arm"
mass = 0.0

[[joint]]
name = "u"
kind = "U"
parent = "base"
child = "arm"
cross = { mass = 0.5, com = [0.0, 0.0, -0.2] }
"#;
    let m = tree("u.toml", src);
    for (q1, q2) in [(0.3, -0.7), (-1.1, 0.4), (2.0, 1.3)] {
        let tau = runtime::rnea::inverse_dynamics(&m, &[q1, q2], &[0.0; 2], &[0.0; 2]);
        let want = 0.5 * 9.81 * 0.2 * f64::sin(q1);
        assert!(
            (tau[0] - want).abs() <= 1e-14 * want.abs(),
            "{} vs {want}",
            tau[0]
        );
        assert!(tau[1].abs() <= 1e-15, "{}", tau[1]);
    }
}

fn errors(src: &str) -> String {
    match load_mechanism("bad.toml", src) {
        Ok(_) => panic!("accepted"),
        Err(d) => d.render(),
    }
}

/// The line (1-based) of `needle` in `src`.
fn line_of(src: &str, needle: &str) -> usize {
    src.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn a_bad_cross_is_reported_at_its_key_like_a_body() {
    let neg = WITH_KEY.replace("mc = 0.35", "mc = -0.35");
    let e = errors(&neg);
    let line = line_of(&neg, "cross = {");
    assert!(e.contains("negative mass -0.35"), "{e}");
    assert!(e.contains(&format!("bad.toml:{line}:")), "{e}");
    assert!(e.contains("joint \"u\".cross.mass"), "{e}");

    let nan = WITH_KEY.replace("com = [0.02, -0.03, 0.04]", "com = [0.02, \"x\", 0.04]");
    let e = errors(&nan);
    assert!(e.contains("joint \"u\".cross.com"), "{e}");

    let unknown = WITH_KEY.replace("cross = { mass", "cross = { mas = 1.0, mass");
    let e = errors(&unknown);
    assert!(e.contains("unknown key \"mas\""), "{e}");
    assert!(e.contains("joint \"u\".cross.mas"), "{e}");

    let no_mass = WITH_KEY.replace("cross = { mass = \"mc\", ", "cross = { ");
    let e = errors(&no_mass);
    assert!(e.contains("joint \"u\".cross"), "{e}");
    assert!(e.contains("mass"), "{e}");

    let not_a_table = WITH_KEY.replace(
        &WITH_KEY[WITH_KEY.find("cross = {").unwrap()..WITH_KEY.rfind('}').unwrap() + 1],
        "cross = 0.1",
    );
    let e = errors(&not_a_table);
    assert!(e.contains("joint \"u\".cross"), "{e}");

    let on_revolute = EXPLICIT.replace(
        "axis = [1.0, 0.0, 0.0]",
        "axis = [1.0, 0.0, 0.0]\ncross = { mass = 0.1 }",
    );
    let e = errors(&on_revolute);
    assert!(
        e.contains("`cross` is for universal joints, not a revolute joint"),
        "{e}"
    );
    assert!(
        e.contains(&format!("bad.toml:{}:", line_of(&on_revolute, "cross = {"))),
        "{e}"
    );
}

#[test]
fn a_non_physical_cross_inertia_warns_at_its_key() {
    let src = WITH_KEY.replace("ixx = \"ix\"", "ixx = 0.02");
    let (_, warnings) = load_mechanism("w.toml", &src).unwrap_or_else(|d| panic!("{d}"));
    let w = warnings.render();
    assert!(w.contains("triangle"), "{w}");
    assert!(w.contains("joint \"u\".cross.inertia"), "{w}");
    assert!(
        w.contains(&format!("w.toml:{}:", line_of(&src, "cross = {"))),
        "{w}"
    );
}

/// A 3-UPU's universal joint into the platform is a constraint, with no cross body.
#[test]
fn a_cross_on_the_joint_into_the_platform_is_refused() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../mechanisms/specs/tsai_3upu.toml"
    );
    let src = std::fs::read_to_string(path).unwrap();
    let bad = src.replacen(
        "child = \"platform\"",
        "child = \"platform\"\ncross = { mass = 0.1 }",
        1,
    );
    let e = errors(&bad);
    assert!(e.contains("meets the platform"), "{e}");
    assert!(e.contains("platform_u1\".cross"), "{e}");
    // On the base U (a leg joint) it is taken.
    let good = src.replacen(
        "child = \"cylinder1\"",
        "child = \"cylinder1\"\ncross = { mass = 0.1, com = [0.0, 0.0, 0.01] }",
        1,
    );
    assert!(load_mechanism("ok.toml", &good).is_ok());
}

/// In a closed loop written in joint coordinates (the 3-UPU with its platform on the first
/// leg), the tree's U joints take a cross, and it is part of the tree's model.
#[test]
fn a_closed_loop_tree_joint_takes_a_cross() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/tsai_3upu_joints.toml"
    );
    let src = std::fs::read_to_string(path).unwrap();
    let with = src.replacen(
        "child = \"cylinder1\"",
        "child = \"cylinder1\"\ncross = { mass = 0.25, com = [0.0, 0.0, 0.01] }",
        1,
    );
    assert_ne!(with, src);
    let cross_mass = |s: &str| match load_mechanism("c.toml", s) {
        Ok((Mechanism::Closed(c), _)) => c
            .tree
            .bodies
            .iter()
            .find(|b| b.name == "base_u1_cross")
            .map(|b| b.mass),
        Ok(_) => panic!("a closed loop"),
        Err(d) => panic!("{d}"),
    };
    assert_eq!(cross_mass(&src), Some(0.0));
    assert_eq!(cross_mass(&with), Some(0.25));
}

/// A parallel model of `src`.
fn platform(name: &str, src: &str) -> runtime::parallel::ParallelModel {
    match load_mechanism(name, src) {
        Ok((Mechanism::Parallel(p), _)) => p,
        Ok(_) => panic!("a platform"),
        Err(d) => panic!("{}", d.render()),
    }
}

/// Relative 2-norm of the difference of two Deltas' inverse dynamics over random states near
/// home (the platform within 5 cm of it).
fn delta_difference(a: &str, b: &str) -> f64 {
    use runtime::parallel::noc;
    let (ma, mb) = (platform("a.toml", a), platform("b.toml", b));
    let (pa, pb) = (noc::Plan::new(&ma).unwrap(), noc::Plan::new(&mb).unwrap());
    let mut s = 0x0e1b_0e1b_u64;
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for _ in 0..20 {
        let mut r = || 2.0 * uniform(&mut s) - 1.0;
        let x = [0.05 * r(), 0.05 * r(), -1.0 + 0.05 * r()];
        let u = [r(), r(), r()];
        let ud = [5.0 * r(), 5.0 * r(), 5.0 * r()];
        let ta = noc::inverse_dynamics(&pa, &x, &u, &ud).unwrap();
        let tb = noc::inverse_dynamics(&pb, &x, &u, &ud).unwrap();
        for (a, b) in ta.iter().zip(&tb) {
            diff += (a - b) * (a - b);
            norm += b * b;
        }
    }
    (diff / norm).sqrt()
}

/// A parallelogram's `cross` is the elbow U's cross, whose first axis is the motor axis's
/// direction through `E` (docs/spec.md, "Parallelograms"). A point mass on that axis does not
/// turn with the cross, so it moves with the upper arm: the Delta with
/// `cross = { mass = m, com = [0, c, 0] }` on a parallelogram is, by hand, the Delta whose elbow
/// pin (a point mass 0.226 kg at `E`, in the upper arm's axes) also carries `m` at `(0, c, 0)`:
/// mass `M = 0.226 + m`, mass centre `(0, mc/M, 0)`, inertia about it `μ c²` about `x` and `z`
/// (`μ = 0.226 m / M`, two point masses `c` apart). Top-level entries (the expanded Delta, leg
/// 1) and a `[[pattern.parallelogram]]` (the bundled Delta, every leg).
#[test]
fn a_parallelogram_cross_on_the_motor_axis_is_a_heavier_elbow_pin() {
    let (m, c, pin) = (0.15, 0.03, 0.226);
    let big_m = pin + m;
    let mu = pin * m / big_m;
    let merged = format!(
        "mass = {big_m}\ncom = [0.0, {}, 0.0]\ninertia = {{ ixx = {}, iyy = 0.0, izz = {} }}\n",
        m * c / big_m,
        mu * c * c,
        mu * c * c
    );
    let cross = format!("cross = {{ mass = {m}, com = [0.0, {c}, 0.0] }}\n");
    let dir = env!("CARGO_MANIFEST_DIR");
    let expanded =
        std::fs::read_to_string(format!("{dir}/tests/data/expanded/delta_rl5.toml")).unwrap();
    let bundled =
        std::fs::read_to_string(format!("{dir}/../mechanisms/specs/delta_rl5.toml")).unwrap();
    for (src, name, pin_entry) in [
        (
            &expanded,
            "name = \"forearm1\"\n",
            "name = \"elbow_pin1\"\nmass = 0.226\n",
        ),
        (
            &bundled,
            "name = \"forearm{i}\"\n",
            "name = \"elbow_pin{i}\"\nmass = 0.226\n",
        ),
    ] {
        let with_key = src.replacen(name, &format!("{name}{cross}"), 1);
        let by_hand = src.replacen(pin_entry, &pin_entry.replace("mass = 0.226\n", &merged), 1);
        assert!(with_key != *src && by_hand != *src);
        let d = delta_difference(&with_key, &by_hand);
        let effect = delta_difference(src, &by_hand);
        eprintln!(
            "parallelogram cross vs a heavier elbow pin: {d:.2e} (relative 2-norm; the cross's effect {effect:.2e})"
        );
        assert!(d <= 1e-13, "{d:e}");
        assert!(effect > 1e-3, "the cross changes nothing: {effect:e}");
    }
    // Off the axis it turns with the cross, not with the arm: not the pin's.
    let off = bundled.replacen(
        "name = \"forearm{i}\"\n",
        &format!("name = \"forearm{{i}}\"\ncross = {{ mass = {m}, com = [{c}, 0.0, 0.0] }}\n"),
        1,
    );
    let pin_off = bundled.replacen(
        "name = \"elbow_pin{i}\"\nmass = 0.226\n",
        &format!(
            "name = \"elbow_pin{{i}}\"\nmass = {big_m}\ncom = [{}, 0.0, 0.0]\ninertia = {{ ixx = 0.0, iyy = {}, izz = {} }}\n",
            m * c / big_m,
            mu * c * c,
            mu * c * c
        ),
        1,
    );
    let d = delta_difference(&off, &pin_off);
    assert!(
        d > 1e-6,
        "a point off the first axis turns with the cross: {d:e}"
    );
}

/// A parallelogram's `cross` is checked as a U joint's is, at its key.
#[test]
fn a_bad_parallelogram_cross_is_reported_at_its_key() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let src = std::fs::read_to_string(format!("{dir}/../mechanisms/specs/delta_rl5.toml")).unwrap();
    let with = |cross: &str| {
        src.replacen(
            "name = \"forearm{i}\"\n",
            &format!("name = \"forearm{{i}}\"\ncross = {cross}\n"),
            1,
        )
    };
    let neg = with("{ mass = -0.1 }");
    let e = errors(&neg);
    assert!(e.contains("negative mass -0.1"), "{e}");
    assert!(
        e.contains(&format!("bad.toml:{}:", line_of(&neg, "cross = {"))),
        "{e}"
    );
    assert!(
        e.contains("\"forearm{i}\".cross.mass") || e.contains("\"forearm1\".cross.mass"),
        "{e}"
    );
    let e = errors(&with("{ mas = 1.0, mass = 0.1 }"));
    assert!(e.contains("unknown key \"mas\""), "{e}");
    assert!(e.contains(".cross.mas"), "{e}");
    let e = errors(&with("0.1"));
    assert!(e.contains(".cross"), "{e}");
    let e = errors(&with("{ com = [0.0, 0.0, 0.01] }"));
    assert!(e.contains(".cross") && e.contains("mass"), "{e}");
    let (_, w) = load_mechanism(
        "w.toml",
        &with("{ mass = 0.1, inertia = { ixx = 0.02, iyy = 1e-3, izz = 1e-3 } }"),
    )
    .unwrap_or_else(|d| panic!("{d}"));
    let w = w.render();
    assert!(
        w.contains("triangle") && w.contains(".cross.inertia"),
        "{w}"
    );
}
