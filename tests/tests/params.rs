//! `[scene] parameters = "runtime"`: the payload and the joints' drive coefficients become a
//! generated `Params` struct passed at run time. Checked against the runtime on the same robot
//! with the same values baked in as constants (the payload merged into its body by the
//! parallel-axis theorem at spec level, the drives set on the model's joints) — a route that
//! shares neither the payload's frame transformation nor its Newton–Euler terms with the
//! generator. The PUMA 560 carries a tool on a rotated flange, so the payload's frame differs
//! from the body's.

use codegen::dynamics::{ParamKind, param_index};
use codegen::spec::{Mechanism, SceneOverrides, load_mechanism};

/// The run-time parameters `codegen::spec::load` places for a spec.
fn scene_params(file: &str, src: &str, o: &SceneOverrides) -> Option<codegen::spec::RuntimeParams> {
    codegen::spec::load(file, src, o).ok()?.scene.params
}
use codegen::sym::Arg;
use rand::Rng;
use runtime::model::{Drive, Model};

const PUMA: &str = include_str!("../../mechanisms/specs/puma560.toml");

/// The PUMA with a tool on a flange turned by (0.3, π/2, −0.7) rpy, 0.1 m out along z6, and a
/// payload on the tool; `mode` is `"runtime"` or `"constants"`.
fn puma(mode: &str, mass: f64, com: [f64; 3], i: [f64; 6], friction: bool) -> String {
    format!(
        "{PUMA}\n[scene]\nparameters = \"{mode}\"\nfriction = {friction}\nrotor_inertia = {friction}\n\
         payload = {{ body = \"tool\", mass = {mass}, com = [{}, {}, {}], inertia = {{ ixx = {}, ixy = {}, ixz = {}, iyy = {}, iyz = {}, izz = {} }} }}\n\
         [[body]]\nname = \"tool\"\nmass = 0.0\n\
         [[joint]]\nname = \"flange\"\nkind = \"fixed\"\nparent = \"link6\"\nchild = \"tool\"\n\
         origin = {{ xyz = [0.0, 0.02, 0.1], rpy = [0.3, \"pi/2\", -0.7] }}\n",
        com[0], com[1], com[2], i[0], i[1], i[2], i[3], i[4], i[5]
    )
}

fn tree(src: &str) -> Model {
    match load_mechanism("puma.toml", src) {
        Ok((Mechanism::Tree(m), _)) => m,
        Ok(_) => panic!("not a tree"),
        Err(d) => panic!("{d}"),
    }
}

#[test]
fn runtime_parameters_match_the_same_values_as_constants() {
    let mut r = tests::rng(41);
    // The runtime-parameter model itself does not depend on the values.
    let base = puma(
        "runtime",
        1.0,
        [0.0; 3],
        [0.01, 0.0, 0.0, 0.01, 0.0, 0.01],
        true,
    );
    let model = tree(&base);
    let sym = {
        let rp = scene_params("puma.toml", &base, &SceneOverrides::default()).unwrap();
        codegen::symbolic_with(&model, Some(&rp))
    };
    let n = model.dof();
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        // A random physical payload (inertia from a random box, rotated) and random drives.
        let mass = r.random_range(0.5..5.0);
        let com = [
            r.random_range(-0.1..0.1),
            r.random_range(-0.1..0.1),
            r.random_range(0.0..0.2),
        ];
        let ic = tests::inertia(&mut r);
        let i6 = [ic[0][0], ic[0][1], ic[0][2], ic[1][1], ic[1][2], ic[2][2]];
        let run = puma("runtime", mass, com, i6, true);
        let rp = scene_params("puma.toml", &run, &SceneOverrides::default()).unwrap();
        let (_, pm, pc, pi) = rp.payload.expect("a payload");
        let drives: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                [
                    r.random_range(0.0..5.0),
                    r.random_range(0.0..3.0),
                    r.random_range(0.0..1.0),
                ]
            })
            .collect();
        let mut p = vec![0.0; codegen::dynamics::param_count(n)];
        p[0] = pm;
        p[1..4].copy_from_slice(&pc);
        p[4..10].copy_from_slice(&[pi[0][0], pi[0][1], pi[0][2], pi[1][1], pi[1][2], pi[2][2]]);
        for (j, d) in drives.iter().enumerate() {
            p[param_index(ParamKind::Damping, j, n)] = d[0];
            p[param_index(ParamKind::Friction, j, n)] = d[1];
            p[param_index(ParamKind::Armature, j, n)] = d[2];
        }
        // The same robot with the values as constants.
        let mut fixed = tree(&puma("constants", mass, com, i6, false));
        for (j, d) in drives.iter().enumerate() {
            fixed.joints[j].drive = Drive {
                viscous: d[0],
                coulomb: d[1],
                coulomb_velocity: 1e-4,
                armature: d[2],
            };
        }
        for _ in 0..10 {
            let (q, qd, qdd) = tests::random_state(&mut r, n);
            let tau: Vec<f64> = (0..n).map(|_| r.random_range(-50.0..50.0)).collect();
            let input = |a: Arg, i: usize| match a {
                Arg::Q => q[i],
                Arg::Qd => qd[i],
                Arg::Qdd => qdd[i],
                Arg::Tau => tau[i],
                Arg::P => p[i],
                _ => f64::NAN,
            };
            let id = sym.graph.eval(&sym.inverse_dynamics, &input);
            let mm = sym.graph.eval(&sym.mass_matrix, &input);
            let fd = sym.graph.eval(&sym.forward_dynamics, &input);
            let grav = sym.graph.eval(&sym.gravity, &input);
            let id_rt = runtime::noc::inverse_dynamics(&fixed, &q, &qd, &qdd);
            let mm_rt = runtime::noc::mass_matrix(&fixed, &q);
            let fd_rt = runtime::noc::forward_dynamics(&fixed, &q, &qd, &tau).unwrap();
            let g_rt = runtime::noc::gravity(&fixed, &q);
            // And the independent spatial-algebra route for the rigid part.
            let zero = vec![0.0; n];
            let rnea = runtime::rnea::inverse_dynamics(&fixed, &q, &zero, &zero);
            worst = worst
                .max(tests::rel_err(&id, id_rt.as_slice()))
                .max(tests::rel_err(&mm, mm_rt.transpose().as_slice()))
                .max(tests::rel_err(&fd, fd_rt.as_slice()))
                .max(tests::rel_err(&grav, g_rt.as_slice()))
                .max(tests::rel_err(&grav, rnea.as_slice()));
        }
    }
    assert!(worst < 1e-11, "runtime parameters vs constants: {worst:e}");
}

#[test]
fn the_module_takes_params_and_refuses_them_where_unsupported() {
    let src = puma(
        "runtime",
        2.0,
        [0.0, 0.0, 0.05],
        [0.01, 0.0, 0.0, 0.01, 0.0, 0.005],
        false,
    );
    let g = codegen::compile("puma.toml", &src, &codegen::Config::default()).unwrap();
    assert!(g.code.contains("pub struct Params"));
    let id = &g.code[g.code.find("pub fn inverse_dynamics(").unwrap()..];
    assert!(id[..id.find('{').unwrap()].contains("p: &Params"));
    assert!(g.code.contains("pub const DEFAULT: Params"));
    // Constants by default: no Params.
    let plain = codegen::compile("puma.toml", PUMA, &codegen::Config::default()).unwrap();
    assert!(!plain.code.contains("Params"));
    // Parallel mechanisms: the run-time parameters are the platform's payload, so a scene
    // without one, or with one on a leg body, is a diagnostic.
    let gs = include_str!("../../mechanisms/specs/gough_stewart.toml");
    let bad = format!("{gs}\n[scene]\nparameters = \"runtime\"\n");
    let err = codegen::spec::load_mechanism("gs.toml", &bad).unwrap_err();
    assert!(
        err.render().contains("declares no payload"),
        "{}",
        err.render()
    );
    let leg = format!(
        "{gs}\n[scene]\nparameters = \"runtime\"\npayload = {{ body = \"piston1\", mass = 1.0 }}\n"
    );
    let err = codegen::spec::load_mechanism("gs.toml", &leg).unwrap_err();
    assert!(
        err.render().contains("must ride on the platform"),
        "{}",
        err.render()
    );
    // Closed loops in joint coordinates: a diagnostic.
    let four = include_str!("../../mechanisms/specs/four_bar.toml");
    let bad = format!("{four}\n[scene]\nparameters = \"runtime\"\n");
    let err = codegen::spec::load_mechanism("four_bar.toml", &bad).unwrap_err();
    assert!(err.render().contains("closed loops"), "{}", err.render());
}

const GS: &str = include_str!("../../mechanisms/specs/gough_stewart.toml");
const GS_SCENE: &str = include_str!("../src/params_scene_gs.toml");

fn parallel(src: &str) -> runtime::parallel::ParallelModel {
    match load_mechanism("gs.toml", src) {
        Ok((Mechanism::Parallel(m), _)) => m,
        Ok(_) => panic!("not a parallel mechanism"),
        Err(d) => panic!("{d}"),
    }
}

/// The payload line of a scene: on `body`, inertia `[xx, xy, xz, yy, yz, zz]`.
fn payload_line(body: &str, mass: f64, com: [f64; 3], i: [f64; 6]) -> String {
    format!(
        "payload = {{ body = \"{body}\", mass = {mass:e}, com = [{:e}, {:e}, {:e}], inertia = {{ ixx = {:e}, ixy = {:e}, ixz = {:e}, iyy = {:e}, iyz = {:e}, izz = {:e} }} }}",
        com[0], com[1], com[2], i[0], i[1], i[2], i[3], i[4], i[5]
    )
}

/// A random payload: mass in `mass`, mass centre within `reach` (m, z shifted by `z`), an
/// inertia `[xx, xy, xz, yy, yz, zz]` with diagonal entries in `diag` and small products.
fn random_payload(
    r: &mut rand::rngs::StdRng,
    mass: std::ops::Range<f64>,
    reach: f64,
    z: f64,
    diag: std::ops::Range<f64>,
) -> (f64, [f64; 3], [f64; 6]) {
    let m = r.random_range(mass);
    let com = [
        r.random_range(-reach..reach),
        r.random_range(-reach..reach),
        z + r.random_range(-reach..reach),
    ];
    let off = 0.02 * diag.start;
    let d: [f64; 3] = core::array::from_fn(|_| r.random_range(diag.clone()));
    let o: [f64; 3] = core::array::from_fn(|_| r.random_range(-off..off));
    (m, com, [d[0], o[0], o[1], d[1], o[2], d[2]])
}

/// The symmetric matrix of `[xx, xy, xz, yy, yz, zz]`.
fn inertia3(i6: [f64; 6]) -> [[f64; 3]; 3] {
    [
        [i6[0], i6[1], i6[2]],
        [i6[1], i6[3], i6[4]],
        [i6[2], i6[4], i6[5]],
    ]
}

/// `spec` with its `payload = …` line replaced by one on `body`.
fn with_payload(spec: &str, body: &str, mass: f64, com: [f64; 3], i6: [f64; 6]) -> String {
    let start = spec.find("payload = ").unwrap();
    let end = start + spec[start..].find('\n').unwrap();
    format!(
        "{}{}{}",
        &spec[..start],
        payload_line(body, mass, com, i6),
        &spec[end..]
    )
}

/// A parallel mechanism's platform payload and leg drives at run time (the compiled `gs_params`
/// module of `tests/build.rs`): against the runtime on the same spec with the payload as
/// constants, merged into the platform at spec level by the parallel-axis theorem (a route that
/// shares neither [`runtime::parallel::noc::payload_force`] nor the payload's frame change with
/// the generator), and the drives set on the model's leg joints. `Params::DEFAULT` is the
/// spec's payload on the turned tool (no drives); random payloads and drives set at run time
/// are compared with the same payload written on the platform and the same drives.
/// The check shared by the parallel `Params` tests: the compiled module `$g` with `p` against
/// the runtime on `spec` (the same values as constants, `p`'s drives set on the leg joints),
/// 50 random states, all four functions; the worst relative error.
macro_rules! parallel_check {
    ($g:ident) => {
        |p: &$g::Params, spec: &str, r: &mut rand::rngs::StdRng| -> f64 {
            let mut model = parallel(spec);
            // The drives of `p` as the model's constants, leg joint `3·leg + k`.
            for (l, leg) in model.legs.iter_mut().enumerate() {
                for (k, j) in leg.joints.iter_mut().enumerate().take(3) {
                    let i = 3 * l + k;
                    j.drive = Drive {
                        viscous: p.damping[i],
                        coulomb: p.friction[i],
                        coulomb_velocity: 1e-4,
                        armature: p.armature[i],
                    };
                }
            }
            let plan = runtime::parallel::Plan::new(&model).unwrap();
            let home = model.home_x();
            let mut worst: f64 = 0.0;
            for _ in 0..50 {
                let (x, u, ud) = tests::pkm::random_state(&plan, &home, r, 0.3, 0.1);
                let xa: [f64; 7] = x.clone().try_into().unwrap();
                let ua: [f64; $g::DOF] = u.clone().try_into().unwrap();
                let uda: [f64; $g::DOF] = ud.clone().try_into().unwrap();
                let tau = $g::inverse_dynamics(&xa, &ua, &uda, p).unwrap();
                let want = runtime::parallel::noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
                worst = worst.max(tests::pkm::rel(&tau, &want));
                let m = $g::mass_matrix(&xa, p).unwrap();
                let want = runtime::parallel::noc::mass_matrix(&plan, &x).unwrap();
                worst = worst.max(tests::pkm::rel(&m.concat(), &want.concat()));
                let ma = $g::actuator_mass_matrix(&xa, p).unwrap();
                let want = runtime::parallel::noc::actuator_mass_matrix(&plan, &x).unwrap();
                worst = worst.max(tests::pkm::rel(&ma.concat(), &want.concat()));
                let back = $g::forward_dynamics(&xa, &ua, &tau, p).unwrap();
                worst = worst.max(tests::pkm::rel(&back, &ud));
            }
            worst
        }
    };
}

/// The check shared by the closed-loop `Params` tests: the compiled module `$g` with `p`
/// against the runtime on `spec` (the same values as constants, `p`'s drives on every tree
/// joint), 50 random states of the spherical five-bar; the worst relative error.
macro_rules! closed_check {
    ($g:ident) => {
        |p: &$g::Params, spec: &str, r: &mut rand::rngs::StdRng| -> f64 {
            let mut model = closed(spec);
            for (j, joint) in model.tree.joints.iter_mut().enumerate() {
                joint.drive = Drive {
                    viscous: p.damping[j],
                    coulomb: p.friction[j],
                    coulomb_velocity: 1e-4,
                    armature: p.armature[j],
                };
            }
            let plan = runtime::closed::noc::Plan::new(&model).unwrap();
            let mut worst: f64 = 0.0;
            for _ in 0..50 {
                let (x, u, ud) = tests::closed::random_state(
                    &plan,
                    r,
                    tests::closed::reach("spherical_five_bar"),
                );
                let xa: [f64; $g::NX] = x.clone().try_into().unwrap();
                let ua: [f64; $g::DOF] = u.clone().try_into().unwrap();
                let uda: [f64; $g::DOF] = ud.clone().try_into().unwrap();
                let tau = $g::inverse_dynamics(&xa, &ua, &uda, p).unwrap();
                let want = runtime::closed::noc::inverse_dynamics(&plan, &x, &u, &ud).unwrap();
                worst = worst.max(tests::pkm::rel(&tau, &want));
                let m = $g::mass_matrix(&xa, p).unwrap();
                let want = runtime::closed::noc::mass_matrix(&plan, &x).unwrap();
                worst = worst.max(tests::pkm::rel(&m.concat(), &want.concat()));
                let back = $g::forward_dynamics(&xa, &ua, &tau, p).unwrap();
                worst = worst.max(tests::pkm::rel(&back, &ud));
            }
            worst
        }
    };
}

/// A closed-loop spec's validated model.
fn closed(spec: &str) -> runtime::closed::ClosedModel {
    match load_mechanism("sfb.toml", spec) {
        Ok((Mechanism::Closed(m), _)) => m,
        Ok(_) => panic!("not a closed-loop spec"),
        Err(d) => panic!("{d}"),
    }
}

#[test]
fn parallel_payload_at_run_time_matches_constants() {
    use runtime::parallel::Plan;
    use runtime::parallel::noc;
    use tests::variants::gs_params as g;
    const N: usize = g::DOF;
    let src = format!("{GS}\n{GS_SCENE}");
    let constants = src.replace("parameters = \"runtime\"", "parameters = \"constants\"");
    let check = parallel_check!(g);
    let mut r = tests::rng(43);
    // The spec's payload, on the tool, by default.
    let mut worst = check(&g::Params::DEFAULT, &constants, &mut r);
    // Random payloads set at run time, in the platform frame.
    for _ in 0..5 {
        let (mass, com, i6) = random_payload(&mut r, 0.5..20.0, 0.1, -0.05, 0.01..0.3);
        let p = g::Params {
            payload_mass: mass,
            payload_com: com,
            payload_inertia: inertia3(i6),
            damping: core::array::from_fn(|_| r.random_range(0.0..50.0)),
            friction: core::array::from_fn(|_| r.random_range(0.0..20.0)),
            armature: core::array::from_fn(|_| r.random_range(0.0..2.0)),
        };
        let spec = with_payload(&constants, "platform", mass, com, i6);
        worst = worst.max(check(&p, &spec, &mut r));
    }
    println!("run-time payload and drives vs constants: worst relative error {worst:.1e}");
    assert!(
        worst < 1e-10,
        "run-time payload and drives vs constants: {worst:e}"
    );
    // A payload changes the efforts (the check can fail).
    let bare = parallel(GS);
    let plan = Plan::new(&bare).unwrap();
    let home = bare.home_x();
    let tau0 = noc::inverse_dynamics(&plan, &home, &[0.0; N], &[0.0; N]).unwrap();
    let tau = g::inverse_dynamics(
        &home.clone().try_into().unwrap(),
        &[0.0; N],
        &[0.0; N],
        &g::Params::DEFAULT,
    )
    .unwrap();
    assert!(tests::pkm::rel(&tau, &tau0) > 1e-2);
}

/// The compiled module (`tests/build.rs`, `src/params_scene.toml`): `Params::DEFAULT` is the
/// spec's payload, and drive values set at run time take effect; checked against the runtime
/// with the payload merged as constants.
#[test]
fn compiled_module_with_params() {
    use tests::variants::puma_params as g;
    let src = format!("{PUMA}\n{}", include_str!("../src/params_scene.toml"));
    let fixed_src = src.replace("parameters = \"runtime\"", "parameters = \"constants\"");
    let mut fixed = tree(&fixed_src);
    let mut p = g::Params::DEFAULT;
    let mut r = tests::rng(42);
    let n = fixed.dof();
    for j in 0..n {
        p.damping[j] = r.random_range(0.0..5.0);
        p.friction[j] = r.random_range(0.0..3.0);
        p.armature[j] = r.random_range(0.0..1.0);
        fixed.joints[j].drive = Drive {
            viscous: p.damping[j],
            coulomb: p.friction[j],
            coulomb_velocity: 1e-4,
            armature: p.armature[j],
        };
    }
    let mut worst: f64 = 0.0;
    for _ in 0..100 {
        let (q, qd, qdd) = tests::random_state(&mut r, n);
        let (q, qd, qdd): ([f64; 6], [f64; 6], [f64; 6]) = (
            q.try_into().unwrap(),
            qd.try_into().unwrap(),
            qdd.try_into().unwrap(),
        );
        let id = g::inverse_dynamics(&q, &qd, &qdd, &p);
        let id_rt = runtime::noc::inverse_dynamics(&fixed, &q, &qd, &qdd);
        let back = g::forward_dynamics(&q, &qd, &id, &p).unwrap();
        worst = worst
            .max(tests::rel_err(&id, id_rt.as_slice()))
            .max(tests::rel_err(&back, &qdd));
    }
    assert!(worst < 1e-10, "{worst:e}");
    // A heavier payload at run time changes the efforts like the constant model does.
    p.payload_mass *= 2.0;
    let heavier = tree(&fixed_src.replace("mass = 2.5", "mass = 5.0"));
    let q = [0.1, -0.5, 0.3, 0.2, 0.7, -0.4];
    let mut p0 = p;
    p0.damping = [0.0; 6];
    p0.friction = [0.0; 6];
    p0.armature = [0.0; 6];
    let gq = g::gravity(&q, &p0);
    let want = runtime::noc::gravity(&heavier, &q);
    assert!(tests::rel_err(&gq, want.as_slice()) < 1e-12);
}

const SFB: &str = include_str!("../../mechanisms/specs/spherical_five_bar.toml");
const CLOSED_SCENE: &str = include_str!("../src/params_scene_closed.toml");

/// Closed loops in joint coordinates with run-time parameters (the compiled `closed_params`
/// module of `tests/build.rs`: the spherical five-bar with a payload on its camera link and the
/// drives of every tree joint): against the runtime on the same spec with the payload as
/// constants (merged into the body at spec level) and the drives set on the model's joints.
#[test]
fn closed_loop_payload_and_drives_at_run_time_match_constants() {
    use runtime::closed::noc::{self as cnoc, Plan};
    use tests::variants::closed_params as g;
    const N: usize = g::DOF;
    const NX: usize = g::NX;
    let src = format!("{SFB}\n{CLOSED_SCENE}");
    let constants = src.replace("parameters = \"runtime\"", "parameters = \"constants\"");
    let check = closed_check!(g);
    let mut r = tests::rng(44);
    // The spec's payload by default (no drives).
    let mut worst = check(&g::Params::DEFAULT, &constants, &mut r);
    for _ in 0..5 {
        let (mass, com, i6) = random_payload(&mut r, 0.05..1.0, 0.05, 0.05, 1e-4..1e-3);
        let p = g::Params {
            payload_mass: mass,
            payload_com: com,
            payload_inertia: inertia3(i6),
            damping: core::array::from_fn(|_| r.random_range(0.0..0.05)),
            friction: core::array::from_fn(|_| r.random_range(0.0..0.02)),
            armature: core::array::from_fn(|_| r.random_range(0.0..1e-3)),
        };
        let spec = with_payload(&constants, "distal_a", mass, com, i6);
        worst = worst.max(check(&p, &spec, &mut r));
    }
    println!(
        "closed loops, run-time payload and drives vs constants: worst relative error {worst:.1e}"
    );
    assert!(worst < 1e-10, "{worst:e}");
    // The payload changes the efforts (the check can fail).
    let bare = closed(SFB);
    let plan = Plan::new(&bare).unwrap();
    let x = [0.0; NX];
    let tau0 = cnoc::inverse_dynamics(&plan, &x, &[0.0; N], &[0.0; N]).unwrap();
    let tau = g::inverse_dynamics(&x, &[0.0; N], &[0.0; N], &g::Params::DEFAULT).unwrap();
    assert!(tests::pkm::rel(&tau, &tau0) > 1e-2);
}

/// A rigid body's mass properties: mass (kg), mass centre (m), inertia about it (kg·m²).
type Props = (f64, [f64; 3], [[f64; 3]; 3]);

/// `spec` (the PUMA 560's TOML) with the `mass`, `com` and `inertia` lines of each body named
/// in `values` replaced by those constants (mass in kg, mass centre in m and inertia about it in
/// kg·m², the spec body's frame).
fn with_body_constants(spec: &str, values: &[(&str, Props)]) -> String {
    let mut out = String::new();
    let mut body: Option<&Props> = None;
    let mut in_body = false;
    let mut replaced = 0;
    for line in spec.lines() {
        let t = line.trim();
        if t.starts_with('[') {
            in_body = t == "[[body]]";
            body = None;
        } else if in_body && let Some(name) = t.strip_prefix("name = ") {
            body = values
                .iter()
                .find(|v| format!("\"{}\"", v.0) == name)
                .map(|v| &v.1);
        }
        let new = match body {
            Some((m, _, _)) if t.starts_with("mass =") => Some(format!("mass = {m:e}")),
            Some((_, c, _)) if t.starts_with("com =") => {
                Some(format!("com = [{:e}, {:e}, {:e}]", c[0], c[1], c[2]))
            }
            Some((_, _, i)) if t.starts_with("inertia =") => Some(format!(
                "inertia = {{ ixx = {:e}, ixy = {:e}, ixz = {:e}, iyy = {:e}, iyz = {:e}, izz = {:e} }}",
                i[0][0], i[0][1], i[0][2], i[1][1], i[1][2], i[2][2]
            )),
            _ => None,
        };
        match new {
            Some(l) => {
                replaced += 1;
                out.push_str(&l);
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    assert_eq!(
        replaced,
        3 * values.len(),
        "every body has mass, com and inertia lines"
    );
    out
}

/// `[scene] runtime_inertia = "all"`: every body's mass, mass centre and inertia are run-time
/// parameters of the compiled `puma_inertia` module (`tests/build.rs`). For random physical
/// parameter sets written into the spec as constants and loaded by the runtime, the module fed
/// the same values through `Params` (in each model body's frame, read from the lowered model)
/// must agree with the runtime NOC and the spatial RNEA/CRBA: inverse dynamics, mass matrix and
/// forward dynamics on 50 random states per set. `Params::DEFAULT` is the spec's values (the
/// module then reproduces the bundled constant module), and random values change the efforts,
/// so the comparison can fail.
#[test]
fn runtime_inertia_matches_the_same_values_as_constants() {
    use tests::variants::puma_inertia as g;
    const N: usize = g::DOF;
    assert_eq!(
        g::RUNTIME_BODY_NAMES,
        ["link1", "link2", "link3", "link4", "link5", "link6"]
    );
    let arr = |v: &[f64]| -> [f64; N] { v.try_into().unwrap() };
    // Compare the module at `p` with the runtime on `model` (the same values as constants).
    let check = |p: &g::Params, model: &Model, r: &mut rand::rngs::StdRng| -> f64 {
        let mut worst: f64 = 0.0;
        for _ in 0..50 {
            let (q, qd, qdd) = tests::random_state(r, N);
            let (q, qd, qdd) = (arr(&q), arr(&qd), arr(&qdd));
            let tau: [f64; N] = core::array::from_fn(|_| r.random_range(-50.0..50.0));
            let id = g::inverse_dynamics(&q, &qd, &qdd, p);
            let mm = g::mass_matrix(&q, p);
            let fd = g::forward_dynamics(&q, &qd, &tau, p).unwrap();
            let id_noc = runtime::noc::inverse_dynamics(model, &q, &qd, &qdd);
            let id_rnea = runtime::rnea::inverse_dynamics(model, &q, &qd, &qdd);
            let mm_noc = runtime::noc::mass_matrix(model, &q);
            let mm_crba = runtime::rnea::mass_matrix(model, &q);
            let fd_noc = runtime::noc::forward_dynamics(model, &q, &qd, &tau).unwrap();
            worst = worst
                .max(tests::rel_err(&id, id_noc.as_slice()))
                .max(tests::rel_err(&id, id_rnea.as_slice()))
                .max(tests::rel_err(&mm.concat(), mm_noc.transpose().as_slice()))
                .max(tests::rel_err(&mm.concat(), mm_crba.transpose().as_slice()))
                .max(tests::rel_err(&fd, fd_noc.as_slice()));
        }
        worst
    };
    let mut r = tests::rng(45);
    // The spec's values by default: the runtime on the bundled spec, and the bundled constant
    // module (generated without any run-time parameter) at the same states.
    let bundled = tree(PUMA);
    let d = g::Params::DEFAULT;
    for (k, b) in bundled.bodies.iter().enumerate() {
        assert_eq!(g::RUNTIME_BODY_NAMES[k], b.name);
        assert_eq!(d.body_mass[k], b.mass);
        assert!(tests::rel_err(&d.body_com[k], &b.com) < 1e-15);
        assert!(tests::rel_err(&d.body_inertia[k].concat(), &b.inertia.concat()) < 1e-15);
    }
    let mut worst = check(&d, &bundled, &mut r);
    for _ in 0..50 {
        let (q, qd, qdd) = tests::random_state(&mut r, N);
        let (q, qd, qdd) = (arr(&q), arr(&qd), arr(&qdd));
        let a = g::inverse_dynamics(&q, &qd, &qdd, &d);
        let b = mechanisms::puma560::inverse_dynamics(&q, &qd, &qdd);
        worst = worst.max(tests::rel_err(&a, &b));
        let a = g::mass_matrix(&q, &d);
        let b = mechanisms::puma560::mass_matrix(&q);
        worst = worst.max(tests::rel_err(&a.concat(), &b.concat()));
    }
    println!("runtime_inertia, Params::DEFAULT vs constants: worst relative error {worst:.1e}");
    assert!(worst <= 1e-11, "Params::DEFAULT vs constants: {worst:e}");
    // Random physical parameter sets.
    let names = g::RUNTIME_BODY_NAMES;
    let mut worst: f64 = 0.0;
    let mut changed: f64 = f64::INFINITY;
    for _ in 0..6 {
        let values: Vec<(&str, Props)> = names
            .iter()
            .map(|&name| {
                let mass = r.random_range(0.1..10.0);
                let com = core::array::from_fn(|_| r.random_range(-0.3..0.3));
                // Principal moments with the triangle inequality, rotated (positive definite),
                // scaled to the mass (a body of about 0.1–0.4 m).
                let i = tests::inertia(&mut r).map(|row| row.map(|x| 0.1 * mass * x));
                (name, (mass, com, i))
            })
            .collect();
        let spec = with_body_constants(PUMA, &values);
        let model = tree(&spec);
        // The module's parameters: each body's values in its model frame, as lowered.
        let mut p = g::Params::DEFAULT;
        for (k, b) in model.bodies.iter().enumerate() {
            assert_eq!(b.name, names[k]);
            p.body_mass[k] = b.mass;
            p.body_com[k] = b.com;
            p.body_inertia[k] = b.inertia;
        }
        worst = worst.max(check(&p, &model, &mut r));
        // The values take effect: the efforts differ from the spec's values'.
        let (q, qd, qdd) = tests::random_state(&mut r, N);
        let (q, qd, qdd) = (arr(&q), arr(&qd), arr(&qdd));
        let a = g::inverse_dynamics(&q, &qd, &qdd, &p);
        let b = g::inverse_dynamics(&q, &qd, &qdd, &d);
        changed = changed.min(tests::rel_err(&a, &b));
    }
    println!(
        "runtime_inertia, random parameter sets vs constants: worst relative error {worst:.1e}, smallest change of the efforts {changed:.1e}"
    );
    assert!(worst <= 1e-11, "runtime inertia vs constants: {worst:e}");
    assert!(
        changed > 1e-2,
        "the run-time values change the efforts: {changed:e}"
    );
}

/// The mass properties `(m, c, I_c)` of two rigid bodies together (the parallel-axis theorem),
/// all in one frame: the oracle's side of a second run-time body on a link.
fn combine(a: Props, b: Props) -> Props {
    let m = a.0 + b.0;
    let c: [f64; 3] = core::array::from_fn(|k| (a.0 * a.1[k] + b.0 * b.1[k]) / m);
    let mut i = [[0.0; 3]; 3];
    for (mass, com, ic) in [a, b] {
        let d: [f64; 3] = core::array::from_fn(|k| com[k] - c[k]);
        let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        for r in 0..3 {
            for s in 0..3 {
                let delta = if r == s { dd } else { 0.0 };
                i[r][s] += ic[r][s] + mass * (delta - d[r] * d[s]);
            }
        }
    }
    (m, c, i)
}

const IIWA: &str = include_str!("../../mechanisms/specs/iiwa14.urdf");

/// Run-time bodies on the PUMA 560, the iiwa 14 and random trees and chains (generic and
/// coordinate axes, prismatic joints), so that the generator's frame choices shift and turn the
/// links: every other body's inertial parameters at run time (its constants zero in the model),
/// and second rigid bodies on links that keep their constants, through the DAG interpreter
/// against the runtime NOC with all of them as constants.
#[test]
fn runtime_inertia_on_random_trees() {
    use codegen::dynamics::{body_param_index, param_count_with};
    use codegen::spec::{RuntimeBody, RuntimeParams};
    let mut worst: f64 = 0.0;
    for seed in 0..8u64 {
        let shape = tests::Shape {
            joints: 7,
            prismatic: 0.3,
            chain: seed % 2 == 0,
            coordinate_axes: seed % 4 < 2,
        };
        // The PUMA 560 and the iiwa 14 first: there the generator moves link origins along
        // their axes (a frame shift the run-time bodies' parameters must follow).
        let mut full = match seed {
            0 => tree(PUMA),
            1 => match load_mechanism("iiwa14.urdf", IIWA) {
                Ok((Mechanism::Tree(m), _)) => m,
                _ => panic!("the iiwa 14 loads"),
            },
            _ => tests::random_model(300 + seed, shape),
        };
        let n = full.dof();
        let mut r = tests::rng(400 + seed);
        let mut zeroed = full.clone();
        let mut bodies = Vec::new();
        for k in (0..n).step_by(2) {
            let b = &full.bodies[k];
            bodies.push(RuntimeBody {
                name: b.name.clone(),
                body: k,
                mass: b.mass,
                com: b.com,
                inertia: b.inertia,
            });
            let z = &mut zeroed.bodies[k];
            (z.mass, z.com, z.inertia) = (0.0, [0.0; 3], [[0.0; 3]; 3]);
        }
        // Second rigid bodies at run time on links that keep their constants (as on a model
        // body merged from several spec bodies): on every third link and the last.
        for k in (1..n).step_by(3).chain([n - 1]) {
            let extra = (
                r.random_range(0.1..10.0),
                core::array::from_fn(|_| r.random_range(-0.3..0.3)),
                tests::inertia(&mut r),
            );
            bodies.push(RuntimeBody {
                name: format!("extra{k}"),
                body: k,
                mass: extra.0,
                com: extra.1,
                inertia: extra.2,
            });
            let b = &mut full.bodies[k];
            (b.mass, b.com, b.inertia) = combine((b.mass, b.com, b.inertia), extra);
        }
        let mut p = vec![0.0; param_count_with(n, bodies.len())];
        for (k, b) in bodies.iter().enumerate() {
            let i = &b.inertia;
            let at = body_param_index(k, n);
            p[at] = b.mass;
            p[at + 1..at + 4].copy_from_slice(&b.com);
            p[at + 4..at + 10]
                .copy_from_slice(&[i[0][0], i[0][1], i[0][2], i[1][1], i[1][2], i[2][2]]);
        }
        let rp = RuntimeParams {
            payload: None,
            coulomb_velocity: 1e-4,
            leg_friction: false,
            leg_rotor_inertia: false,
            bodies,
        };
        let sym = codegen::symbolic_with(&zeroed, Some(&rp));
        for _ in 0..20 {
            let (q, qd, qdd) = tests::random_state(&mut r, n);
            let tau: Vec<f64> = (0..n).map(|_| r.random_range(-50.0..50.0)).collect();
            let input = |a: Arg, i: usize| match a {
                Arg::Q => q[i],
                Arg::Qd => qd[i],
                Arg::Qdd => qdd[i],
                Arg::Tau => tau[i],
                Arg::P => p[i],
                _ => f64::NAN,
            };
            let id = sym.graph.eval(&sym.inverse_dynamics, &input);
            let mm = sym.graph.eval(&sym.mass_matrix, &input);
            let fd = sym.graph.eval(&sym.forward_dynamics, &input);
            let id_rt = runtime::noc::inverse_dynamics(&full, &q, &qd, &qdd);
            let mm_rt = runtime::noc::mass_matrix(&full, &q);
            let fd_rt = runtime::noc::forward_dynamics(&full, &q, &qd, &tau).unwrap();
            worst = worst
                .max(tests::rel_err(&id, id_rt.as_slice()))
                .max(tests::rel_err(&mm, mm_rt.transpose().as_slice()))
                .max(tests::rel_err(&fd, fd_rt.as_slice()));
        }
    }
    println!("runtime_inertia on random trees: worst relative error {worst:.1e}");
    assert!(worst <= 1e-11, "runtime inertia on random trees: {worst:e}");
}

/// `scene` (a `src/params_scene*.toml` text) with `runtime_inertia = "all"` added, as
/// `tests/build.rs` writes the `*_inertia` variants.
fn with_runtime_inertia(scene: &str) -> String {
    scene.replacen("[scene]\n", "[scene]\nruntime_inertia = \"all\"\n", 1)
}

/// The constants counterpart of a run-time spec: `parameters = "constants"`, no
/// `runtime_inertia`; `keep_payload: false` also drops the payload line (the bodies' own values
/// are then the model's).
fn as_constants(spec: &str, keep_payload: bool) -> String {
    spec.replace("parameters = \"runtime\"", "parameters = \"constants\"")
        .replace("runtime_inertia = \"all\"\n", "")
        .lines()
        .filter(|l| keep_payload || !l.starts_with("payload = "))
        .map(|l| format!("{l}\n"))
        .collect()
}

/// Random physical mass properties: mass in `mass` (kg), mass centre within `reach` (m),
/// rotated principal moments with the triangle inequality scaled by `scale · mass` (kg·m²).
fn random_props(
    r: &mut rand::rngs::StdRng,
    mass: std::ops::Range<f64>,
    reach: f64,
    scale: f64,
) -> Props {
    let m = r.random_range(mass);
    let c = core::array::from_fn(|_| r.random_range(-reach..reach));
    let i = tests::inertia(r).map(|row| row.map(|x| scale * m * x));
    (m, c, i)
}

/// Closed loops with every tree body's inertial parameters at run time besides the payload and
/// the drives (the compiled `closed_inertia` module: the spherical five-bar): random parameter
/// sets written into the spec as constants, against the runtime, with the same values (each
/// body's, in its tree body's frame as lowered) through `Params`.
#[test]
fn closed_loop_runtime_inertia_matches_constants() {
    use tests::variants::closed_inertia as g;
    const N: usize = g::DOF;
    const NX: usize = g::NX;
    let src = format!("{SFB}\n{}", with_runtime_inertia(CLOSED_SCENE));
    let constants = as_constants(&src, true);
    let check = closed_check!(g);
    assert_eq!(
        g::RUNTIME_BODY_NAMES,
        ["proximal_a", "distal_a", "proximal_b", "distal_b"]
    );
    let mut r = tests::rng(46);
    // The spec's values by default.
    let mut worst = check(&g::Params::DEFAULT, &constants, &mut r);
    let mut changed = f64::INFINITY;
    for _ in 0..5 {
        let values: Vec<(&str, Props)> = g::RUNTIME_BODY_NAMES
            .iter()
            .map(|&name| (name, random_props(&mut r, 0.05..2.0, 0.1, 0.01)))
            .collect();
        let spec = with_body_constants(&constants, &values);
        // The bodies' own values in their tree bodies' frames: the model without the payload.
        let bare = closed(&with_body_constants(&as_constants(&src, false), &values));
        let mut p = g::Params::DEFAULT;
        for (k, name) in g::RUNTIME_BODY_NAMES.iter().enumerate() {
            let b = bare.tree.bodies.iter().find(|b| b.name == *name).unwrap();
            (p.body_mass[k], p.body_com[k], p.body_inertia[k]) = (b.mass, b.com, b.inertia);
        }
        p.damping = core::array::from_fn(|_| r.random_range(0.0..0.05));
        p.friction = core::array::from_fn(|_| r.random_range(0.0..0.02));
        p.armature = core::array::from_fn(|_| r.random_range(0.0..1e-3));
        worst = worst.max(check(&p, &spec, &mut r));
        let x = [0.0; NX];
        let a = g::inverse_dynamics(&x, &[0.0; N], &[0.0; N], &p).unwrap();
        let mut d = g::Params::DEFAULT;
        (d.damping, d.friction, d.armature) = (p.damping, p.friction, p.armature);
        let b = g::inverse_dynamics(&x, &[0.0; N], &[0.0; N], &d).unwrap();
        changed = changed.min(tests::pkm::rel(&a, &b));
    }
    println!(
        "closed loops, runtime_inertia vs constants: worst relative error {worst:.1e}, smallest change of the efforts {changed:.1e}"
    );
    assert!(worst <= 1e-11, "{worst:e}");
    assert!(
        changed > 1e-2,
        "the run-time values change the efforts: {changed:e}"
    );
}

/// A parallel mechanism with the platform's own inertia at run time besides the payload and
/// the leg drives (the compiled `gs_inertia` module; the constant platform is massless there):
/// random platform parameters written into the spec as constants, against the runtime.
#[test]
fn parallel_platform_inertia_at_run_time_matches_constants() {
    use tests::variants::gs_inertia as g;
    const N: usize = g::DOF;
    let src = format!("{GS}\n{}", with_runtime_inertia(GS_SCENE));
    let constants = as_constants(&src, true);
    let check = parallel_check!(g);
    assert_eq!(g::RUNTIME_BODY_NAMES, ["platform"]);
    let mut r = tests::rng(47);
    let mut worst = check(&g::Params::DEFAULT, &constants, &mut r);
    let mut changed = f64::INFINITY;
    for _ in 0..5 {
        let values = [("platform", random_props(&mut r, 0.5..20.0, 0.1, 0.05))];
        let spec = with_body_constants(&constants, &values);
        let bare = parallel(&with_body_constants(&as_constants(&src, false), &values));
        let mut p = g::Params::DEFAULT;
        let b = &bare.platform;
        (p.body_mass[0], p.body_com[0], p.body_inertia[0]) = (b.mass, b.com, b.inertia);
        p.damping = core::array::from_fn(|_| r.random_range(0.0..50.0));
        p.friction = core::array::from_fn(|_| r.random_range(0.0..20.0));
        p.armature = core::array::from_fn(|_| r.random_range(0.0..2.0));
        worst = worst.max(check(&p, &spec, &mut r));
        let home: [f64; 7] = bare.home_x().try_into().unwrap();
        let a = g::inverse_dynamics(&home, &[0.0; N], &[0.0; N], &p).unwrap();
        let mut d = g::Params::DEFAULT;
        (d.damping, d.friction, d.armature) = (p.damping, p.friction, p.armature);
        let b = g::inverse_dynamics(&home, &[0.0; N], &[0.0; N], &d).unwrap();
        changed = changed.min(tests::pkm::rel(&a, &b));
    }
    println!(
        "parallel, platform inertia at run time vs constants: worst relative error {worst:.1e}, smallest change of the efforts {changed:.1e}"
    );
    assert!(worst <= 1e-10, "{worst:e}");
    assert!(
        changed > 1e-2,
        "the run-time values change the efforts: {changed:e}"
    );
}

/// A run-time body merged into another by a fixed joint: the PUMA 560 with a tool on a flange
/// turned by (0.3, π/2, −0.7) rpy, `runtime_inertia = ["tool", "link6"]` (two entries on the
/// model body `link6`, the tool's in `link6`'s frame). Random tool and link-6 values written
/// into the spec: the run-time parameters `scene_params` places (what `Params::DEFAULT` holds)
/// through the DAG interpreter against the runtime with the values as constants; the spec
/// loads without warnings (the zeroed constants are not "massless" bodies).
#[test]
fn runtime_inertia_of_a_body_on_a_turned_flange() {
    use codegen::dynamics::{body_param_index, param_count_with};
    let spec = |mode: &str, tool: Props, link6: Props| {
        let tool_body = with_body_constants(
            "[[body]]\nname = \"tool\"\nmass = 0.0\ncom = [0.0, 0.0, 0.0]\ninertia = { ixx = 0.0, iyy = 0.0, izz = 0.0 }\n",
            &[("tool", tool)],
        );
        let scene = if mode == "runtime" {
            "[scene]\nparameters = \"runtime\"\nruntime_inertia = [\"tool\", \"link6\"]\n"
        } else {
            ""
        };
        format!(
            "{}\n{scene}\n{tool_body}\n[[joint]]\nname = \"flange\"\nkind = \"fixed\"\nparent = \"link6\"\nchild = \"tool\"\n\
             origin = {{ xyz = [0.0, 0.02, 0.1], rpy = [0.3, \"pi/2\", -0.7] }}\n",
            with_body_constants(PUMA, &[("link6", link6)])
        )
    };
    let mut r = tests::rng(48);
    let mut worst: f64 = 0.0;
    for _ in 0..5 {
        let tool = random_props(&mut r, 0.1..10.0, 0.1, 0.02);
        let link6 = random_props(&mut r, 0.1..10.0, 0.1, 0.02);
        let run = spec("runtime", tool, link6);
        let (m, warnings) = match load_mechanism("puma.toml", &run) {
            Ok((Mechanism::Tree(m), w)) => (m, w),
            _ => panic!("the run-time spec loads"),
        };
        assert!(warnings.is_empty(), "{}", warnings.render());
        let rp = scene_params("puma.toml", &run, &SceneOverrides::default()).unwrap();
        let names: Vec<&str> = rp.bodies.iter().map(|b| b.name.as_str()).collect();
        assert_eq!(names, ["tool", "link6"]);
        assert!(rp.bodies.iter().all(|b| b.body == 5));
        let n = m.dof();
        let mut p = vec![0.0; param_count_with(n, rp.bodies.len())];
        for (k, b) in rp.bodies.iter().enumerate() {
            let (at, i) = (body_param_index(k, n), &b.inertia);
            p[at] = b.mass;
            p[at + 1..at + 4].copy_from_slice(&b.com);
            p[at + 4..at + 10]
                .copy_from_slice(&[i[0][0], i[0][1], i[0][2], i[1][1], i[1][2], i[2][2]]);
        }
        let sym = codegen::symbolic_with(&m, Some(&rp));
        let fixed = tree(&spec("constants", tool, link6));
        for _ in 0..20 {
            let (q, qd, qdd) = tests::random_state(&mut r, n);
            let input = |a: Arg, i: usize| match a {
                Arg::Q => q[i],
                Arg::Qd => qd[i],
                Arg::Qdd => qdd[i],
                Arg::P => p[i],
                _ => f64::NAN,
            };
            let id = sym.graph.eval(&sym.inverse_dynamics, &input);
            let mm = sym.graph.eval(&sym.mass_matrix, &input);
            let id_rt = runtime::rnea::inverse_dynamics(&fixed, &q, &qd, &qdd);
            let mm_rt = runtime::rnea::mass_matrix(&fixed, &q);
            worst = worst
                .max(tests::rel_err(&id, id_rt.as_slice()))
                .max(tests::rel_err(&mm, mm_rt.transpose().as_slice()));
        }
    }
    // Every body at run time: no body is "massless" either.
    let all = format!(
        "{PUMA}\n{}",
        include_str!("../src/params_scene_inertia.toml")
    );
    match load_mechanism("puma.toml", &all) {
        Ok((_, w)) => assert!(w.is_empty(), "{}", w.render()),
        Err(e) => panic!("{}", e.render()),
    }
    println!("runtime_inertia of a body on a turned flange: worst relative error {worst:.1e}");
    assert!(worst <= 1e-11, "{worst:e}");
}
