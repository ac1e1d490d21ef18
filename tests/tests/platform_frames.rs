//! Frames fixed to the platform of a parallel mechanism (`[scene] frames`: `F_pose(x)`,
//! `F_jacobian(x)`, `F_jacobian_dot_u(x, u)`), on 200 random states near home per bundled
//! platform (the planar five-bar's point has no orientation and takes none), each with the
//! platform's frame and a probe fixed to it by a turned, offset fixed joint:
//! * the generator's kernels (its interpreter, `Graph::eval`) against the runtime's `f64`
//!   evaluation of the same equations (`runtime::parallel::noc::frame_*`), ≤ 1e-12;
//! * `J` against central differences of the pose along the coordinates' manifold
//!   (`retract(x, ±h e_j)`; the rotation by `vee` of the skew part of `R₊ R₋ᵀ`), and `J̇ u`
//!   against central differences of `J u` along `retract(x, ±h u)`, ≤ 1e-6 (`h = 1e-5`);
//! * the compiled Gough–Stewart variant with a tool (`tests::variants::gs_params`) against the
//!   runtime, ≤ 1e-12.
//!
//! Error norm: ‖a − b‖∞ / max(‖b‖∞, 1).

use codegen::spec::{Frame, Mechanism};
use codegen::sym::Arg;
use rand::Rng;
use runtime::parallel::ParallelModel;
use runtime::parallel::noc::{self, Plan};
use tests::{rel_err, rng};

const STATES: usize = 200;

/// The probe appended to each spec: a body fixed to the platform body `platform`.
/// (A spec that has a `[scene]` already gets the key in it.)
fn with_probe(src: &str, platform: &str, frames: &str) -> String {
    let key = format!("frames = [{frames}]\n");
    let src = match src.find("\n[scene]\n") {
        Some(i) => format!(
            "{}\n[scene]\n{key}{}",
            &src[..i],
            &src[i + "\n[scene]\n".len()..]
        ),
        None => format!("{src}\n[scene]\n{key}"),
    };
    format!(
        "{src}\n[[body]]\nname = \"probe\"\nmass = 0.0\n\n\
         [[joint]]\nname = \"probe_mount\"\nkind = \"fixed\"\nparent = \"{platform}\"\n\
         child = \"probe\"\norigin = {{ xyz = [0.03, -0.02, 0.05], rpy = [0.3, -0.5, 0.9] }}\n"
    )
}

fn load(file: &str, src: &str) -> (ParallelModel, Vec<Frame>) {
    let l = codegen::spec::load(file, src, &Default::default()).unwrap_or_else(|d| panic!("{d}"));
    match l.mechanism {
        Mechanism::Parallel(m) => (m, l.scene.frames),
        _ => panic!("{file}: a parallel mechanism"),
    }
}

/// The runtime's `(pose, J, J̇ u)` of `frame` at `(x, u)`.
fn runtime_frame(plan: &Plan, frame: &Frame, x: &[f64], u: &[f64]) -> [Vec<f64>; 3] {
    let pl = noc::platform(plan, x).expect("a regular pose");
    let (r, p) = noc::frame_pose(&pl, &frame.placement);
    let mut pose: Vec<f64> = r.iter().flatten().copied().collect();
    pose.extend(p);
    [
        pose,
        noc::frame_jacobian(plan.motion, &pl, &frame.placement),
        noc::frame_jacobian_dot_u(plan.motion, &pl, &frame.placement, u).to_vec(),
    ]
}

fn mat_times(m: &[f64], x: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..m.len() / n)
        .map(|r| (0..n).map(|j| m[r * n + j] * x[j]).sum())
        .collect()
}

/// `vee` of the skew part of `a bᵀ`.
fn rotation_difference(a: &[f64], b: &[f64]) -> [f64; 3] {
    let m = |r: usize, c: usize| (0..3).map(|k| a[r * 3 + k] * b[c * 3 + k]).sum::<f64>();
    [
        0.5 * (m(2, 1) - m(1, 2)),
        0.5 * (m(0, 2) - m(2, 0)),
        0.5 * (m(1, 0) - m(0, 1)),
    ]
}

/// The generated `(pose, J, J̇ u)` of frame `k` at `(x, u)`.
type Generated<'a> = dyn Fn(usize, &[f64], &[f64]) -> [Vec<f64>; 3] + 'a;

/// Worst errors: generated against runtime (pose, J, J̇ u), J by differences, J̇ u by
/// differences.
fn check(
    model: &ParallelModel,
    frames: &[Frame],
    generated: &Generated<'_>,
    seed: u64,
) -> [f64; 5] {
    let plan = Plan::new(model).unwrap();
    let (n, motion) = (plan.dof(), plan.motion);
    let home = model.home_x();
    let mut r = rng(seed);
    let mut worst = [0.0f64; 5];
    let h = 1e-5;
    for _ in 0..STATES {
        let du: Vec<f64> = (0..n).map(|_| r.random_range(-0.05..0.05)).collect();
        let x = noc::retract(motion, &home, &du);
        let u: Vec<f64> = (0..n).map(|_| r.random_range(-1.0..1.0)).collect();
        for (k, frame) in frames.iter().enumerate() {
            let want = runtime_frame(&plan, frame, &x, &u);
            let got = generated(k, &x, &u);
            for m in 0..3 {
                worst[m] = worst[m].max(rel_err(&got[m], &want[m]));
            }
            let jac = &want[1];
            let mut fd = vec![0.0; 6 * n];
            for j in 0..n {
                let e: Vec<f64> = (0..n).map(|i| if i == j { h } else { 0.0 }).collect();
                let me: Vec<f64> = e.iter().map(|v| -v).collect();
                let pa = runtime_frame(&plan, frame, &noc::retract(motion, &x, &e), &u)[0].clone();
                let pb = runtime_frame(&plan, frame, &noc::retract(motion, &x, &me), &u)[0].clone();
                let w = rotation_difference(&pa[..9], &pb[..9]);
                for c in 0..3 {
                    fd[c * n + j] = w[c] / (2.0 * h);
                    fd[(3 + c) * n + j] = (pa[9 + c] - pb[9 + c]) / (2.0 * h);
                }
            }
            worst[3] = worst[3].max(rel_err(jac, &fd));
            let hu: Vec<f64> = u.iter().map(|v| h * v).collect();
            let mhu: Vec<f64> = hu.iter().map(|v| -v).collect();
            let ja = runtime_frame(&plan, frame, &noc::retract(motion, &x, &hu), &u)[1].clone();
            let jb = runtime_frame(&plan, frame, &noc::retract(motion, &x, &mhu), &u)[1].clone();
            let fd: Vec<f64> = mat_times(&ja, &u)
                .iter()
                .zip(mat_times(&jb, &u))
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            worst[4] = worst[4].max(rel_err(&want[2], &fd));
        }
    }
    worst
}

fn assert_within(what: &str, worst: [f64; 5]) {
    eprintln!(
        "{what}: worst over {STATES} states: pose {:.1e}, J {:.1e}, J̇ u {:.1e} (against the \
         runtime); J by differences {:.1e}, J̇ u by differences {:.1e}",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
    assert!(worst[..3].iter().all(|w| *w <= 1e-12), "{what}: {worst:?}");
    assert!(worst[3..].iter().all(|w| *w <= 1e-6), "{what}: {worst:?}");
}

#[test]
fn every_platform_through_the_interpreter() {
    let specs: [(&str, &str, &str); 9] = [
        (
            "gough_stewart.toml",
            include_str!("../../mechanisms/specs/gough_stewart.toml"),
            "platform",
        ),
        (
            "sliding_hexapod.toml",
            include_str!("../../mechanisms/specs/sliding_hexapod.toml"),
            "platform",
        ),
        (
            "rus_hexapod.toml",
            include_str!("../../mechanisms/specs/rus_hexapod.toml"),
            "platform",
        ),
        (
            "agile_eye.toml",
            include_str!("../../mechanisms/specs/agile_eye.toml"),
            "camera",
        ),
        (
            "delta_rl5.toml",
            include_str!("../../mechanisms/specs/delta_rl5.toml"),
            "platform",
        ),
        (
            "planar_3rrr.toml",
            include_str!("../../mechanisms/specs/planar_3rrr.toml"),
            "platform",
        ),
        (
            "tsai_3upu.toml",
            include_str!("../../mechanisms/specs/tsai_3upu.toml"),
            "platform",
        ),
        (
            "prs_head.toml",
            include_str!("../../mechanisms/specs/prs_head.toml"),
            "platform",
        ),
        (
            "delta4_rl5.toml",
            include_str!("../../mechanisms/specs/delta4_rl5.toml"),
            "carrier",
        ),
    ];
    for (file, src, platform) in specs {
        // A 1T2R module has its own `platform_pose`: only the probe there.
        let frames = if file == "prs_head.toml" {
            "\"probe\"".to_string()
        } else {
            format!("\"{platform}\", \"probe\"")
        };
        let (model, frames) = load(file, &with_probe(src, platform, &frames));
        let plan = Plan::new(&model).unwrap();
        let k = codegen::parallel::kernels_with_frames(&plan, &Default::default(), &frames)
            .expect("regular");
        let generated = |f: usize, x: &[f64], u: &[f64]| -> [Vec<f64>; 3] {
            core::array::from_fn(|m| {
                k.graph.eval(&k.frames[f][m].outputs, &|a, i| match a {
                    Arg::X => x[i],
                    Arg::U => u[i],
                    _ => f64::NAN,
                })
            })
        };
        let worst = check(&model, &frames, &generated, 0x9a7);
        assert_within(&format!("{file} (interpreter)"), worst);
    }
}

/// The compiled Gough–Stewart module with frames on its platform and on a tool fixed to it
/// (`tests/src/params_scene_gs.toml`; the frames take no `Params`).
#[test]
fn compiled_gough_stewart_frames() {
    use tests::variants::gs_params as g;
    let src = format!(
        "{}\n{}",
        include_str!("../../mechanisms/specs/gough_stewart.toml"),
        include_str!("../src/params_scene_gs.toml")
    );
    let (model, frames) = load("gough_stewart.toml", &src);
    assert_eq!(g::FRAME_NAMES, ["platform", "tool"]);
    let arr = |v: &[f64]| -> [f64; 7] { v.try_into().unwrap() };
    let u6 = |v: &[f64]| -> [f64; 6] { v.try_into().unwrap() };
    let flat = |(r, p): ([[f64; 3]; 3], [f64; 3])| -> Vec<f64> {
        r.iter().flatten().copied().chain(p).collect()
    };
    let generated = |f: usize, x: &[f64], u: &[f64]| -> [Vec<f64>; 3] {
        let (x, u) = (arr(x), u6(u));
        if f == 0 {
            [
                flat(g::platform_pose(&x).unwrap()),
                g::platform_jacobian(&x).unwrap().concat(),
                g::platform_jacobian_dot_u(&x, &u).unwrap().to_vec(),
            ]
        } else {
            [
                flat(g::tool_pose(&x).unwrap()),
                g::tool_jacobian(&x).unwrap().concat(),
                g::tool_jacobian_dot_u(&x, &u).unwrap().to_vec(),
            ]
        }
    };
    let worst = check(&model, &frames, &generated, 0x95);
    assert_within("gs_params (compiled)", worst);
    // A zero quaternion is an error, not a NaN pose.
    let e = g::tool_pose(&[0.0; 7]).unwrap_err();
    assert_eq!(e.site, g::Site::Platform);
}

/// The errors of `[scene] frames` on platforms: a leg body, a point platform, `platform` on a
/// 1T2R platform.
#[test]
fn platform_frame_errors() {
    let err = |file: &str, src: &str| -> String {
        match codegen::spec::load(file, src, &Default::default()) {
            Ok(_) => panic!("{file} accepted"),
            Err(d) => d.render(),
        }
    };
    let gs = include_str!("../../mechanisms/specs/gough_stewart.toml");
    let d = err(
        "gs.toml",
        &format!("{gs}\n[scene]\nframes = [\"piston1\"]\n"),
    );
    assert!(d.contains("is not the platform or fixed to it"), "{d}");
    let fb = include_str!("../../mechanisms/specs/planar_five_bar.toml");
    let d = err("fb.toml", &format!("{fb}\n[scene]\nframes = [\"tool\"]\n"));
    assert!(d.contains("planar-point platform offers no frames"), "{d}");
    let prs = include_str!("../../mechanisms/specs/prs_head.toml");
    let d = err(
        "prs.toml",
        &format!("{prs}\n[scene]\nframes = [\"platform\"]\n"),
    );
    assert!(d.contains("second `platform_pose`"), "{d}");
}
