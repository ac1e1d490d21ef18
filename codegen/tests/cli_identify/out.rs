//! `identify --out` writes every base parameter the spec can carry back: a Delta's
//! parallelogram rods and universal joints' crosses (a Gough–Stewart's, a tree's) included. The
//! "true" Delta is the bundled spec with its bodies' and rods'
//! numbers moved in its text (`perturbed_platform`); its efforts come from the runtime's `f64`
//! evaluator; the written spec is checked by the generator's `BASE_PARAMETERS` of its module
//! and by the runtime's inverse dynamics of its model against the true model's.

use super::platform::{
    DELTA, GS, TSAI, bundled, estimate_names, listed, measure_platform, perturbed_platform,
    platform, platform_trajectory,
};
use super::{
    Rng, estimates, generated_base_parameters, identify_out, ok, rel_floor, run, s, scratch, text,
};

/// Noise-free data of a perturbed Delta: the written spec's module has the estimates as its
/// `BASE_PARAMETERS`, all 37, and its model the true model's inverse dynamics.
#[test]
fn delta_out_writes_rods_and_reproduces_every_base_parameter() {
    use runtime::parallel::noc;
    let dir = scratch("delta_out");
    let nominal = bundled(DELTA);
    let spec = dir.join("spec.toml");
    std::fs::write(&spec, &nominal).unwrap();
    let truth_src = perturbed_platform(&nominal, 0.2, 0x0bad_5eed);
    let truth = platform("truth.toml", &truth_src);
    let true_base = generated_base_parameters("truth.toml", &truth_src);
    let states = platform_trajectory(&dir, &spec, &truth, 0.25, 0.1);
    let data = dir.join("exact.csv");
    measure_platform(&data, &states, &truth, 0.0, 1);
    let (est, out) = (dir.join("est.csv"), dir.join("updated.toml"));
    let o = identify_out(&spec, &data, &est, &out);
    ok(&o);
    let stderr = text(&o.stderr);
    assert!(
        !stderr.contains("cannot reproduce"),
        "noise-free estimates are a Delta the spec can write:\n{stderr}"
    );
    let (e, _) = estimates(&est);
    assert_eq!(e.len(), 37);
    // The estimates are the truth (an independent check of the data: the generator's constants
    // of the true spec).
    let err_truth = rel_floor(&e, &true_base, 1e-3);
    assert!(err_truth <= 1e-8, "{err_truth:e}");
    let src = std::fs::read_to_string(&out).unwrap();
    assert!(
        src.contains("rod_mass = \"identified_forearm_rod_mass[i]\""),
        "the rods are written per copy:\n{src}"
    );
    let written = generated_base_parameters("updated.toml", &src);
    // Relative per parameter; those below a thousandth of the largest (the products of inertia
    // and first moments that are zero in every Delta) against the largest.
    let err = rel_floor(&written, &e, 1e-3);
    eprintln!("delta --out: BASE_PARAMETERS of the written spec vs the 37 estimates {err:.2e}");
    assert!(err <= 1e-9, "{err:e}");
    // Its dynamics are the true Delta's on fresh states: the trajectory's positions with
    // random speeds and accelerations.
    let model = platform("updated.toml", &src);
    let (pw, pt) = (
        noc::Plan::new(&model).unwrap(),
        noc::Plan::new(&truth).unwrap(),
    );
    let mut r = Rng(99);
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for [x, _, _] in states.iter().step_by(23) {
        let u: Vec<f64> = (0..3).map(|_| 0.5 * r.gauss()).collect();
        let ud: Vec<f64> = (0..3).map(|_| 2.0 * r.gauss()).collect();
        let a = noc::inverse_dynamics(&pw, x, &u, &ud).unwrap();
        let b = noc::inverse_dynamics(&pt, x, &u, &ud).unwrap();
        for (a, b) in a.iter().zip(&b) {
            diff += (a - b) * (a - b);
            norm += b * b;
        }
    }
    let id_err = (diff / norm).sqrt();
    eprintln!(
        "delta --out: inverse dynamics of the written spec vs the truth {id_err:.2e} (relative 2-norm over 27 states)"
    );
    assert!(id_err <= 1e-9, "{id_err:e}");
}

/// Noise-free data of a perturbed Gough–Stewart whose U joints' crosses have mass (a `cross`
/// key on the pattern's `u{i}`, different per copy), identified with the bundled spec (no
/// `cross` key): `--out` adds the key as per-copy arrays, and the written spec reproduces every
/// base parameter, the six `MZ_u<i>_cross` that only a cross moves included.
#[test]
fn gough_stewart_out_writes_the_crosses() {
    let nominal = bundled(GS);
    let with_crosses = nominal.replace(
        "name = \"u{i}\"\nkind = \"U\"\n",
        "name = \"u{i}\"\nkind = \"U\"\ncross = { mass = \"0.08 + 0.01 * i\", com = [0.01, -0.02, \"0.04 + 0.01 * i\"], inertia = { ixx = 2e-4, iyy = \"3e-4 + 1e-5 * i\", izz = 1e-4, ixy = 1e-5 } }\n",
    );
    assert_ne!(with_crosses, nominal);
    let truth_src = perturbed_platform(&with_crosses, 0.2, 0x00c0_55e5);
    cross_out(
        "gs_cross_out",
        &nominal,
        &truth_src,
        (0.2, 0.25),
        "cross = { mass = \"identified_u_cross_mass[i]\"",
        (&|n| n.starts_with("MZ_") && n.ends_with("_cross"), 6),
        (&|_| false, 0),
    );
}

/// Noise-free data of a perturbed Delta whose parallelograms' elbow crosses have mass (a
/// `cross` key on the pattern's `forearm{i}`, different per copy), identified with the bundled
/// spec (no `cross` key): `--out` adds the key as per-copy arrays, and the written spec
/// reproduces every base parameter, the six `MX`/`MZ_forearm<i>_elbow_cross + …` groups that
/// only the cross can set included (before the key, 15 of the 37 were kept at the spec's
/// values). Kept: the rods' `MY`, `XY`, `YZ` (a first moment along the motor axis and its
/// products: unequal rods), which no spec number moves and every Delta, this truth too, has
/// zero.
#[test]
fn delta_out_writes_the_elbow_crosses() {
    let nominal = bundled(DELTA);
    let truth_src = perturbed_platform(&super::elbow::with_elbow_crosses(&nominal), 0.2, 0x0e1b);
    cross_out(
        "delta_elbow_out",
        &nominal,
        &truth_src,
        (0.25, 0.1),
        "cross = { mass = \"identified_forearm_elbow_cross_mass[i]\"",
        (
            &|n| {
                (n.starts_with("MX_forearm") || n.starts_with("MZ_forearm"))
                    && n.contains("_elbow_cross ")
            },
            6,
        ),
        (
            &|n| {
                ["MY_", "XY_", "YZ_"].iter().any(|p| n.starts_with(p))
                    && n.ends_with("_rods")
                    && !n.contains(' ')
            },
            9,
        ),
    );
}

/// Noise-free data of Tsai's 3-UPU with its bodies' numbers moved by up to ±20 % (top-level
/// `[[body]]` entries, no pattern), identified with the bundled spec: the written spec has every
/// estimate as its `BASE_PARAMETERS` and the truth's inverse dynamics, nothing kept at the
/// spec's values.
#[test]
fn tsai_3upu_out_reproduces_every_base_parameter() {
    let nominal = bundled(TSAI);
    let truth_src = perturbed_platform(&nominal, 0.2, 0x75a1);
    assert_ne!(truth_src, nominal);
    cross_out(
        "tsai_out",
        &nominal,
        &truth_src,
        (0.05, 0.1),
        "name = \"cylinder1\"",
        (&|_| false, 0),
        (&|_| false, 0),
    );
}

/// A tree: a turntable carrying an arm on a U joint, whose cross moves with the turntable (its
/// mass enters the dynamics). The true arm's cross has mass; the spec's has none (no key).
fn u_arm(cross: &str, m1: f64, m2: f64, c2: f64) -> String {
    format!(
        r#"[mechanism]
name = "u_arm"
gravity = [0.0, 0.0, -9.81]

[[body]]
name = "turntable"
mass = {m1}
com = [0.1, 0.02, 0.2]
inertia = {{ ixx = 0.02, iyy = 0.03, izz = 0.01 }}

[[body]]
name = "arm"
mass = {m2}
com = [0.01, 0.02, {c2}]
inertia = {{ ixx = 0.024, iyy = 0.025, izz = 0.003, ixz = 0.001 }}

[[joint]]
name = "j1"
kind = "revolute"
parent = "base"
child = "turntable"
axis = [0.0, 0.0, 1.0]

[[joint]]
name = "u"
kind = "universal"
parent = "turntable"
child = "arm"
origin = {{ xyz = [0.3, 0.0, 0.4], rpy = [0.0, 0.2, 0.0] }}
axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
{cross}"#
    )
}

/// `--out` on a tree writes a top-level U joint's cross as numbers (the key added where the
/// spec has none, rewritten in place where it has one, its comment kept), and the written spec
/// reproduces every base parameter and the true tree's inverse dynamics.
#[test]
fn a_tree_out_writes_a_cross_as_numbers() {
    tree_cross_out("tree_cross_out", "");
    tree_cross_out(
        "tree_cross_rewritten",
        "cross = { mass = 0.2, com = [0.0, 0.0, 0.02], inertia = { ixx = 3e-4, iyy = 3e-4, izz = 4e-4 } } # measured\n",
    );
}

fn tree_cross_out(test: &str, cross: &str) {
    let dir = scratch(test);
    let src = u_arm(cross, 2.0, 1.0, -0.3);
    let spec = dir.join("u_arm.toml");
    std::fs::write(&spec, &src).unwrap();
    let truth_src = u_arm(
        "cross = { mass = 0.3, com = [0.01, -0.02, 0.03], inertia = { ixx = 4e-4, iyy = 3e-4, izz = 5e-4, ixy = 2e-5 } }\n",
        2.3,
        0.85,
        -0.33,
    );
    let truth = super::tree("truth.toml", &truth_src);
    let true_base = generated_base_parameters("truth.toml", &truth_src);
    let (o, est, out) = identify_exact(
        &dir,
        &spec,
        &truth,
        &["--seed", "3", "--evaluations", "40", "--samples", "300"],
    );
    let stderr = text(&o.stderr);
    assert!(!stderr.contains("note: no number"), "{stderr}");
    let (e, _) = estimates(&est);
    let names = estimate_names(&est);
    let err_truth = rel_floor(&e, &true_base, 1e-3);
    assert!(err_truth <= 1e-8, "{err_truth:e}");
    let only_cross: Vec<usize> = (0..names.len())
        .filter(|&k| names[k].ends_with("_cross") && !names[k].contains(' '))
        .collect();
    assert!(!only_cross.is_empty(), "{names:?}");
    let written_src = std::fs::read_to_string(&out).unwrap();
    assert!(
        written_src.contains("cross = { mass = "),
        "the cross is written:\n{written_src}"
    );
    assert_eq!(written_src.matches("cross = ").count(), 1);
    if !cross.is_empty() {
        assert!(written_src.contains("} # measured\n"), "{written_src}");
        assert!(!written_src.contains(cross), "{written_src}");
    }
    let written = generated_base_parameters("updated.toml", &written_src);
    let err = rel_floor(&written, &e, 1e-3);
    eprintln!(
        "{test}: BASE_PARAMETERS of the written spec vs the {} estimates {err:.2e} ({} only the cross moves: {:?})",
        e.len(),
        only_cross.len(),
        only_cross.iter().map(|&k| &names[k]).collect::<Vec<_>>()
    );
    assert!(err <= 1e-9, "{err:e}");
    let model = super::tree("updated.toml", &written_src);
    let mut r = Rng(5);
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for _ in 0..50 {
        let q: Vec<f64> = (0..3).map(|_| 2.0 * r.gauss()).collect();
        let qd: Vec<f64> = (0..3).map(|_| r.gauss()).collect();
        let qdd: Vec<f64> = (0..3).map(|_| 3.0 * r.gauss()).collect();
        let a = effort(&model, &q, &qd, &qdd);
        let b = effort(&truth, &q, &qd, &qdd);
        for (a, b) in a.iter().zip(&b) {
            diff += (a - b) * (a - b);
            norm += b * b;
        }
    }
    let id_err = (diff / norm).sqrt();
    eprintln!(
        "{test}: inverse dynamics of the written spec vs the truth {id_err:.2e} (relative 2-norm over 50 random states)"
    );
    assert!(id_err <= 1e-9, "{id_err:e}");
}

/// Noise-free data of the true spec `truth_src` (crosses with mass), identified with `nominal`
/// and `--out`: the estimates are the truth's base parameters, those that only a cross moves
/// (`only_cross`, at least `min_only`) are not the spec's, the written spec (which contains
/// `marker`) has every estimate as its `BASE_PARAMETERS` (≤ 1e-9 relative) and the truth's
/// inverse dynamics; the base parameters the update keeps at the spec's values are `kept`
/// many, each one `may_keep` allows.
#[allow(clippy::too_many_arguments)]
fn cross_out(
    test: &str,
    nominal: &str,
    truth_src: &str,
    (reach, turn): (f64, f64),
    marker: &str,
    (only_cross, min_only): (&dyn Fn(&str) -> bool, usize),
    (may_keep, kept): (&dyn Fn(&str) -> bool, usize),
) {
    use runtime::parallel::noc;
    let dir = scratch(test);
    let spec = dir.join("spec.toml");
    std::fs::write(&spec, nominal).unwrap();
    std::fs::write(dir.join("truth.toml"), truth_src).unwrap();
    let truth = platform("truth.toml", truth_src);
    let true_base = generated_base_parameters("truth.toml", truth_src);
    let nominal_base = generated_base_parameters("spec.toml", nominal);
    let states = platform_trajectory(&dir, &spec, &truth, reach, turn);
    let data = dir.join("exact.csv");
    measure_platform(&data, &states, &truth, 0.0, 1);
    let (est, out) = (dir.join("est.csv"), dir.join("updated.toml"));
    let o = identify_out(&spec, &data, &est, &out);
    ok(&o);
    let stderr = text(&o.stderr);
    assert!(
        !stderr.contains("cannot reproduce"),
        "every base parameter is written:\n{stderr}"
    );
    let (e, _) = estimates(&est);
    let names = estimate_names(&est);
    let kept_at_spec = listed(&stderr, "note: no number the update writes moves", "(kept");
    eprintln!(
        "{test}: kept at the spec's values: {} {:?}",
        kept_at_spec.len(),
        kept_at_spec.iter().map(|&k| &names[k]).collect::<Vec<_>>()
    );
    assert_eq!(kept_at_spec.len(), kept, "{stderr}");
    assert!(
        kept_at_spec.iter().all(|&k| may_keep(&names[k])),
        "{stderr}"
    );
    // The estimates are the truth (the generator's constants of the true spec).
    let err_truth = rel_floor(&e, &true_base, 1e-3);
    assert!(err_truth <= 1e-8, "{err_truth:e}");
    let mz: Vec<usize> = (0..names.len())
        .filter(|&k| only_cross(&names[k]))
        .collect();
    assert!(mz.len() >= min_only, "{names:?}");
    for &k in &mz {
        // The crosses' first moments are the truth's, not the spec's (zero).
        assert!(
            nominal_base[k].abs() <= 1e-12 && e[k].abs() > 1e-4,
            "{}: {}",
            names[k],
            e[k]
        );
    }
    let src = std::fs::read_to_string(&out).unwrap();
    assert!(src.contains(marker), "the crosses are written:\n{src}");
    let written = generated_base_parameters("updated.toml", &src);
    let err = rel_floor(&written, &e, 1e-3);
    let err_mz = mz
        .iter()
        .map(|&k| (written[k] - e[k]).abs() / e[k].abs())
        .fold(0.0, f64::max);
    eprintln!(
        "{test}: BASE_PARAMETERS of the written spec vs the {} estimates {err:.2e}, the {} only a cross moves {err_mz:.2e} (relative)",
        e.len(),
        mz.len()
    );
    assert!(err <= 1e-9 && err_mz <= 1e-9, "{err:e} {err_mz:e}");
    let model = platform("updated.toml", &src);
    let (pw, pt) = (
        noc::Plan::new(&model).unwrap(),
        noc::Plan::new(&truth).unwrap(),
    );
    let mut r = Rng(98);
    let n = truth.dof();
    let (mut diff, mut norm, mut count) = (0.0f64, 0.0f64, 0);
    for [x, _, _] in states.iter().step_by(23) {
        let u: Vec<f64> = (0..n).map(|_| 0.5 * r.gauss()).collect();
        let ud: Vec<f64> = (0..n).map(|_| 2.0 * r.gauss()).collect();
        let a = noc::inverse_dynamics(&pw, x, &u, &ud).unwrap();
        let b = noc::inverse_dynamics(&pt, x, &u, &ud).unwrap();
        for (a, b) in a.iter().zip(&b) {
            diff += (a - b) * (a - b);
            norm += b * b;
        }
        count += 1;
    }
    let id_err = (diff / norm).sqrt();
    eprintln!(
        "{test}: inverse dynamics of the written spec vs the truth {id_err:.2e} (relative 2-norm over {count} states)"
    );
    assert!(id_err <= 1e-9, "{id_err:e}");
}

/// The URDF's numbers moved in its text: every `<mass value>` and `<inertia …>` (scaled whole)
/// by `f()`, each `<inertial>`'s `<origin xyz>` entry by `0.05 (f() − 1)` m, every
/// `<dynamics damping>` by `f()`.
fn perturbed_urdf(source: &str, rel: f64, seed: u64) -> String {
    let mut r = Rng(seed);
    let mut f = move || 1.0 + rel * (2.0 * r.uniform() - 1.0);
    let mut out = String::new();
    let mut inertial = false;
    for line in source.split_inclusive('\n') {
        let t = line.trim_start();
        inertial |= t.starts_with("<inertial>");
        let mut l = line.to_string();
        let scale = |l: &mut String, attrs: &[&str], f: f64, d: f64| {
            for a in attrs {
                let key = format!(" {a}=\"");
                let Some(at) = l.find(&key) else { continue };
                let v0 = at + key.len();
                let v1 = v0 + l[v0..].find('"').unwrap();
                let vals: Vec<String> = l[v0..v1]
                    .split_whitespace()
                    .map(|x| format!("{}", x.parse::<f64>().unwrap() * f + d))
                    .collect();
                l.replace_range(v0..v1, &vals.join(" "));
            }
        };
        if t.starts_with("<mass ") || t.starts_with("<dynamics ") {
            scale(&mut l, &["value", "damping"], f(), 0.0);
        } else if t.starts_with("<inertia ") {
            scale(
                &mut l,
                &["ixx", "ixy", "ixz", "iyy", "iyz", "izz"],
                f(),
                0.0,
            );
        } else if inertial && t.starts_with("<origin ") {
            scale(&mut l, &["xyz"], 1.0, 0.05 * (f() - 1.0));
        }
        inertial &= !t.starts_with("</inertial>");
        out.push_str(&l);
    }
    out
}

/// `BASE_PARAMETERS` of the module generated for a URDF with its scene file.
fn urdf_base_parameters(name: &str, source: &str, scene: Option<&str>) -> Vec<f64> {
    let config = codegen::Config {
        scene: codegen::spec::SceneOverrides {
            sidecar: scene.map(|t| codegen::spec::SceneFile {
                name: "scene.toml".into(),
                text: t.into(),
            }),
            ..Default::default()
        },
        ..Default::default()
    };
    let code = codegen::compile(name, source, &config)
        .unwrap_or_else(|d| panic!("{}", d.render()))
        .code;
    let at = code
        .find("pub const BASE_PARAMETERS: [f64; NBP] = [")
        .unwrap();
    let rest = &code[at + "pub const BASE_PARAMETERS: [f64; NBP] = [".len()..];
    rest[..rest.find(']').unwrap()]
        .split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(|t| t.parse().unwrap())
        .collect()
}

/// A URDF's tree model with its scene file.
fn urdf_model(name: &str, source: &str, scene: Option<&str>) -> runtime::model::Model {
    let overrides = codegen::spec::SceneOverrides {
        sidecar: scene.map(|t| codegen::spec::SceneFile {
            name: "scene.toml".into(),
            text: t.into(),
        }),
        ..Default::default()
    };
    match codegen::spec::load(name, source, &overrides) {
        Ok(l) => match l.mechanism {
            codegen::spec::Mechanism::Tree(m) => m,
            _ => panic!("a tree"),
        },
        Err(d) => panic!("{}", d.render()),
    }
}

/// `excite` on the tree `spec` with options `excite` (one restart), the efforts of `truth` at
/// its states (noise-free), then `identify --estimates --out` (to `updated.<spec's extension>`),
/// which must succeed: its output and the paths of the estimates and of the written spec.
fn identify_exact(
    dir: &std::path::Path,
    spec: &std::path::Path,
    truth: &runtime::model::Model,
    excite: &[&str],
) -> (std::process::Output, std::path::PathBuf, std::path::PathBuf) {
    let traj = dir.join("traj.csv");
    let mut args = vec!["excite", s(spec), "--restarts", "1"];
    args.extend_from_slice(excite);
    args.extend(["-o", s(&traj)]);
    let o = run(&args);
    ok(&o);
    let (_, rows) = super::csv_rows(&traj);
    let n = truth.dof();
    let columns: Vec<String> = ["q", "qd", "qdd", "tau"]
        .iter()
        .flat_map(|c| (1..=n).map(move |i| format!("{c}{i}")))
        .collect();
    let mut csv = columns.join(",") + "\n";
    for r in &rows {
        let tau = effort(
            truth,
            &r[1..1 + n],
            &r[1 + n..1 + 2 * n],
            &r[1 + 2 * n..1 + 3 * n],
        );
        let cells: Vec<String> = r[1..].iter().chain(&tau).map(|v| format!("{v}")).collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    let data = dir.join("data.csv");
    std::fs::write(&data, csv).unwrap();
    let ext = spec.extension().and_then(|e| e.to_str()).unwrap_or("toml");
    let (est, out) = (dir.join("est.csv"), dir.join(format!("updated.{ext}")));
    let o = run(&[
        "identify",
        s(spec),
        s(&data),
        "--estimates",
        s(&est),
        "--out",
        s(&out),
    ]);
    ok(&o);
    (o, est, out)
}

/// Inverse dynamics with the drive law (the runtime's spatial RNEA).
fn effort(m: &runtime::model::Model, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let tau = runtime::rnea::inverse_dynamics(m, q, qd, qdd);
    (0..q.len())
        .map(|i| tau[i] + m.joints[i].drive.effort(qd[i], qdd[i]))
        .collect()
}

/// The text without its `<inertial>` blocks and `<dynamics …/>` elements: what `--out` must
/// leave byte for byte.
fn outside_inertials(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    loop {
        let a = rest.find("<inertial>");
        let d = rest.find("<dynamics ");
        let (at, end) = match (a, d) {
            (Some(a), Some(d)) if d < a => (d, "/>"),
            (Some(a), _) => (a, "</inertial>"),
            (None, Some(d)) => (d, "/>"),
            (None, None) => break,
        };
        out.push_str(&rest[..at]);
        let close = at + rest[at..].find(end).unwrap() + end.len();
        rest = &rest[close..];
    }
    out.push_str(rest);
    out
}

/// A perturbed iiwa 14 URDF (and `scene`, its scene file; the truth's is `truth_scene`, or the
/// same), noise-free: the written URDF's module (with the written scene file) has the estimates
/// as its `BASE_PARAMETERS` and its model the true inverse dynamics; nothing outside
/// `<inertial>` and `<dynamics>` changes, and the scene file only where its `armature` must.
fn urdf_out(test: &str, scene: Option<&str>, truth_scene: Option<&str>) {
    let dir = scratch(test);
    let nominal = bundled("../mechanisms/specs/iiwa14.urdf");
    let spec = dir.join("iiwa.urdf");
    std::fs::write(&spec, &nominal).unwrap();
    if let Some(t) = scene {
        std::fs::write(dir.join("iiwa.scene.toml"), t).unwrap();
    }
    let truth_src = perturbed_urdf(&nominal, 0.2, 0x1ee7);
    let truth_scene = truth_scene.or(scene);
    let truth = urdf_model("truth.urdf", &truth_src, truth_scene);
    let true_base = urdf_base_parameters("truth.urdf", &truth_src, truth_scene);
    let (o, est, out) = identify_exact(
        &dir,
        &spec,
        &truth,
        &["--evaluations", "30", "--samples", "500", "--seed", "3"],
    );
    let n = truth.dof();
    let stderr = text(&o.stderr);
    assert!(!stderr.contains("cannot reproduce"), "{stderr}");
    // A URDF has no number for a rotor's inertia: without `rotor_inertia` in its scene file, only
    // the `IA_` parameters that no link's inertia groups with (zero in the truth) may be kept at
    // the spec's values; with it, the scene file's `armature` moves them.
    let rotors = scene.is_some_and(|t| t.contains("rotor_inertia = true"));
    let kept = super::platform::listed(
        &stderr,
        "note: no number the update writes moves",
        " (kept at",
    );
    let (e, _) = estimates(&est);
    let names: Vec<String> = std::fs::read_to_string(&est)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split('"').nth(1).unwrap().to_string())
        .collect();
    for &k in &kept {
        assert!(
            names[k].starts_with("IA_") && scene.is_some() && !rotors,
            "{}",
            names[k]
        );
    }
    let err_truth = rel_floor(&e, &true_base, 1e-3);
    assert!(err_truth <= 1e-8, "{err_truth:e}");
    let written_src = std::fs::read_to_string(&out).unwrap();
    // The scene file comes along: unchanged, or with the rotors' `armature` (its other lines
    // as they were).
    let written_scene = std::fs::read_to_string(dir.join("updated.scene.toml")).ok();
    if rotors {
        let w = written_scene.as_deref().unwrap();
        assert!(w.starts_with(scene.unwrap()), "{w}");
        assert!(w.contains("armature = {"), "{w}");
    } else {
        assert_eq!(written_scene.as_deref(), scene);
    }
    let scene = written_scene.as_deref();
    assert_eq!(outside_inertials(&written_src), outside_inertials(&nominal));
    assert_ne!(written_src, nominal);
    let written = urdf_base_parameters("updated.urdf", &written_src, scene);
    assert_eq!(written.len(), e.len());
    let err = rel_floor(&written, &e, 1e-3);
    eprintln!(
        "{test}: NBP {}: the written URDF's BASE_PARAMETERS vs the estimates {err:.2e}, estimates vs truth {err_truth:.2e}",
        e.len()
    );
    assert!(err <= 1e-9, "{err:e}");
    let model = urdf_model("updated.urdf", &written_src, scene);
    let mut r = Rng(5);
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for _ in 0..50 {
        let mut v = || {
            (0..n)
                .map(|_| 2.0 * r.uniform() - 1.0)
                .collect::<Vec<f64>>()
        };
        let (q, qd, qdd) = (v(), v(), v());
        let a = effort(&model, &q, &qd, &qdd);
        let b = effort(&truth, &q, &qd, &qdd);
        for (a, b) in a.iter().zip(&b) {
            diff += (a - b) * (a - b);
            norm += b * b;
        }
    }
    let id_err = (diff / norm).sqrt();
    eprintln!(
        "{test}: inverse dynamics of the written URDF vs the truth {id_err:.2e} (relative 2-norm, 50 random states)"
    );
    assert!(id_err <= 1e-9, "{id_err:e}");
}

#[test]
fn urdf_out_replaces_inertials_and_keeps_every_other_byte() {
    urdf_out("urdf_out", None, None);
}

#[test]
fn urdf_out_with_friction_writes_dynamics_and_the_scene_file() {
    urdf_out(
        "urdf_out_friction",
        Some("[scene]\nfriction = true\n"),
        None,
    );
}

/// With rotor inertia on, the identified rotors' `armature` goes into the written scene file:
/// every base parameter reproduced (the `IA_` of joints 3–7 too, which no link groups with).
#[test]
fn urdf_out_with_rotor_inertia_writes_the_scene_files_armature() {
    let scene = "[scene]\nfriction = true\nrotor_inertia = true\n";
    let rotors: Vec<String> = (1..=7)
        .map(|k| format!("iiwa_joint_{k} = {}", 0.05 + 0.03 * k as f64))
        .collect();
    let truth = format!("{scene}armature = {{ {} }}\n", rotors.join(", "));
    urdf_out("urdf_out_rotors", Some(scene), Some(&truth));
}

/// The planar 2R of `mechanisms/specs/` with its second link written with expressions (which
/// `--out` leaves alone) and a payload on it.
fn payload_spec(m2: f64, payload_mass: f64, payload_x: f64) -> String {
    let nominal = bundled("../mechanisms/specs/planar_2r.toml");
    let body = "name = \"link2\"\nmass = 1.0\ncom = [0.4, 0.0, 0.0]";
    assert!(nominal.contains(body));
    let src = nominal.replace(
        body,
        "name = \"link2\"\nmass = \"m2\"\ncom = [\"l2 / 2\", 0.0, 0.0]",
    );
    format!(
        "{src}\n[parameters]\nm2 = {m2}\nl2 = 0.8\n\n[scene]\npayload = {{ body = \"link2\", mass = {payload_mass}, com = [{payload_x}, 0.0, 0.0], inertia = {{ ixx = 0.001, iyy = 0.002, izz = 0.002 }} }}\n"
    )
}

/// A body `--out` cannot rewrite (expressions) with a payload on it: the payload takes the
/// change the body cannot, and the written spec reproduces every base parameter.
#[test]
fn a_payload_takes_what_its_body_cannot() {
    let dir = scratch("payload_out");
    let src = payload_spec(1.0, 0.5, 0.8);
    let spec = dir.join("planar.toml");
    std::fs::write(&spec, &src).unwrap();
    let truth_src = payload_spec(1.1, 0.62, 0.74);
    let truth = super::tree("truth.toml", &truth_src);
    let true_base = generated_base_parameters("truth.toml", &truth_src);
    let (o, est, out) = identify_exact(
        &dir,
        &spec,
        &truth,
        &["--seed", "2", "--evaluations", "40", "--samples", "300"],
    );
    let (stdout, stderr) = (text(&o.stdout), text(&o.stderr));
    assert!(stdout.contains("[scene] payload"), "{stdout}");
    assert!(stderr.contains("note: body `link2`"), "{stderr}");
    assert!(!stderr.contains("note: no number"), "{stderr}");
    let (e, _) = estimates(&est);
    assert!(rel_floor(&e, &true_base, 1e-3) <= 1e-8);
    let written_src = std::fs::read_to_string(&out).unwrap();
    assert!(written_src.contains("mass = \"m2\"\ncom = [\"l2 / 2\", 0.0, 0.0]"));
    let written = generated_base_parameters("updated.toml", &written_src);
    let err = rel_floor(&written, &e, 1e-3);
    eprintln!("payload --out: BASE_PARAMETERS of the written spec vs the estimates {err:.2e}");
    assert!(err <= 1e-9, "{err:e}");
}

/// A Delta written from the docs (spec.md's pattern with its own numbers), the data its own
/// noise-free `excite --with-tau`. Its base parameters that are zero in exact arithmetic (the
/// elbow crosses' first moments, grouped from the turned copies' rods) come out as rounding
/// noise near 1e-16, differently when the spec is written back as numbers: `--out` refused it
/// ("its bodies written back as numbers change its base parameters (4.96e-9 relative)", exit
/// 2), the check holding those entries to 1e-18 of the largest parameter. It now writes the
/// spec, which reproduces the spec's base parameters.
#[test]
fn out_takes_rounding_noise_in_zero_base_parameters() {
    let dir = scratch("delta_rounding_out");
    let spec = dir.join("spec.toml");
    let source = r#"[mechanism]
name = "qa_delta"

[parameters]
r_base = 0.2
r_platform = 0.05
upper_arm = 0.3
forearm = 0.7
home_depth = 0.6
reach = "r_base - r_platform"
crank_home = "acos((forearm^2 - reach^2 - upper_arm^2 - home_depth^2) / (2 * upper_arm * hypot(reach, home_depth))) - atan2(home_depth, reach)"

[platform]
body = "platform"
coordinates = "translation"
home = { xyz = [0.0, 0.0, "-home_depth"] }

[[body]]
name = "platform"
mass = 0.4
com = [0.0, 0.0, -0.01]

[[pattern]]
name = "leg"
copies = 3

[[pattern.body]]
name = "upper_arm{i}"
mass = 1.2
com = [0.14, 0.0, 0.0]
inertia = { ixx = 0.0005, iyy = 0.01, izz = 0.01 }

[[pattern.joint]]
name = "motor{i}"
kind = "revolute"
parent = "base"
child = "upper_arm{i}"
origin = { xyz = ["r_base", 0.0, 0.0], rpy = [0.0, "crank_home", 0.0] }
axis = [0.0, 1.0, 0.0]
actuated = true

[[pattern.parallelogram]]
name = "forearm{i}"
parent = "upper_arm{i}"
child = "platform"
elbow = ["upper_arm", 0.0, 0.0]
platform_point = ["r_platform", 0.0, 0.0]
length = "forearm"
elbow_width = 0.06
platform_width = 0.06
rod_mass = 0.1
rod_inertia = { ixx = 1e-6, iyy = 0.004, izz = 0.004 }
"#;
    std::fs::write(&spec, source).unwrap();
    let (data, est, out) = (
        dir.join("data.csv"),
        dir.join("est.csv"),
        dir.join("updated.toml"),
    );
    ok(&run(&[
        "excite",
        s(&spec),
        "--samples",
        "400",
        "--restarts",
        "1",
        "--evaluations",
        "20",
        "--with-tau",
        "-o",
        s(&data),
    ]));
    let o = identify_out(&spec, &data, &est, &out);
    ok(&o);
    let (e, _) = estimates(&est);
    let written =
        generated_base_parameters("updated.toml", &std::fs::read_to_string(&out).unwrap());
    // The written spec carries the estimates. Noise-free, they still carry the least squares' rounding, here 1e-9 to 3e-9 of the
    // spec's values (400 samples of a short excitation search; it moves with the last bits of
    // the efforts), and the written spec's base parameters agree with them to that level.
    let err = rel_floor(&written, &e, 1e-3);
    assert!(err <= 1e-8, "written vs estimates {err:e}");
    let err = rel_floor(&e, &generated_base_parameters("spec.toml", source), 1e-3);
    assert!(err <= 1e-6, "estimates vs the spec {err:e}");
}
