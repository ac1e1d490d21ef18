//! Frames of closed loops in joint coordinates (`[scene] frames`: `F_pose_at(x)` at the tree
//! joint positions, `F_pose(q)` at the independent coordinates through the assembly), on 200
//! random states per bundled closed-loop mechanism:
//! * every body as a frame through the generator's interpreter against the spanning tree's
//!   poses composed here from the model (`X_i = X_parent · origin_i · motion_i(x_i − home_i)`)
//!   and the frame's placement, ≤ 1e-12;
//! * the compiled spherical five-bar variant (`tests::variants::closed_params`): `F_pose_at`
//!   likewise, ≤ 1e-12, and `F_pose(q)` against the runtime's assembly
//!   (`runtime::closed::noc::forward_kinematics` from `HOME`) and the same composition, ≤ 1e-9
//!   (two Newton solves converged to 1e-12 each).
//!
//! Error norm: ‖a − b‖∞ / max(‖b‖∞, 1).

use codegen::spec::{Frame, Mechanism};
use codegen::sym::Arg;
use rand::Rng;
use runtime::closed::ClosedModel;
use runtime::closed::noc::Plan;
use runtime::model::{JointKind, Transform, axis_angle};
use tests::{rel_err, rng};

const STATES: usize = 200;

fn load(file: &str, src: &str) -> (ClosedModel, Vec<Frame>) {
    let l = codegen::spec::load(file, src, &Default::default()).unwrap_or_else(|d| panic!("{d}"));
    match l.mechanism {
        Mechanism::Closed(m) => (m, l.scene.frames),
        _ => panic!("{file}: closed loops"),
    }
}

/// The frame's pose (`R` row-major, then `p`) composed from the spanning tree's joints.
fn composed(model: &ClosedModel, frame: &Frame, x: &[f64]) -> Vec<f64> {
    let tree = &model.tree;
    let mut poses: Vec<Transform> = Vec::with_capacity(tree.dof());
    for (i, j) in tree.joints.iter().enumerate() {
        let d = x[i] - model.home.get(i).copied().unwrap_or(0.0);
        let motion = match j.kind {
            JointKind::Revolute => Transform {
                rotation: axis_angle(&j.axis, d),
                translation: [0.0; 3],
            },
            JointKind::Prismatic => Transform {
                rotation: Transform::IDENTITY.rotation,
                translation: j.axis.map(|a| a * d),
            },
        };
        let local = j.origin.compose(&motion);
        poses.push(match j.parent {
            None => local,
            Some(p) => poses[p].compose(&local),
        });
    }
    let x = frame.body.map_or(Transform::IDENTITY, |b| poses[b]);
    let f = x.compose(&frame.placement);
    f.rotation
        .iter()
        .flatten()
        .copied()
        .chain(f.translation)
        .collect()
}

#[test]
fn every_body_through_the_interpreter() {
    let specs: [(&str, &str); 7] = [
        (
            "four_bar.toml",
            include_str!("../../mechanisms/specs/four_bar.toml"),
        ),
        (
            "five_bar_joints.toml",
            include_str!("../../mechanisms/specs/five_bar_joints.toml"),
        ),
        (
            "spherical_five_bar.toml",
            include_str!("../../mechanisms/specs/spherical_five_bar.toml"),
        ),
        (
            "bricard.toml",
            include_str!("../../mechanisms/specs/bricard.toml"),
        ),
        (
            "n_four_bar.toml",
            include_str!("../../mechanisms/specs/n_four_bar.toml"),
        ),
        (
            "tripod_3prs.toml",
            include_str!("../../mechanisms/specs/tripod_3prs.toml"),
        ),
        (
            "andrews_squeezer.toml",
            include_str!("../../mechanisms/specs/andrews_squeezer.toml"),
        ),
    ];
    for (file, src) in specs {
        let bodies = codegen::spec::body_names(file, src).expect("a TOML spec");
        let list: Vec<String> = bodies.iter().map(|b| format!("{b:?}")).collect();
        let src = format!("{src}\n[scene]\nframes = [{}]\n", list.join(", "));
        let (model, frames) = load(file, &src);
        assert_eq!(frames.len(), bodies.len(), "{file}");
        let plan = Plan::new(&model).unwrap();
        let k =
            codegen::closed::kernels_with_frames(&plan, &Default::default(), None, &[], &frames)
                .expect("regular");
        let mut r = rng(0xc1f);
        let mut worst = 0.0f64;
        for _ in 0..STATES {
            let x: Vec<f64> = (0..model.nx())
                .map(|i| model.home.get(i).copied().unwrap_or(0.0) + r.random_range(-1.0..1.0))
                .collect();
            for (f, kernel) in frames.iter().zip(&k.frames) {
                let got = k.graph.eval(&kernel.outputs, &|a, i| match a {
                    Arg::X => x[i],
                    _ => f64::NAN,
                });
                worst = worst.max(rel_err(&got, &composed(&model, f, &x)));
            }
        }
        eprintln!(
            "{file}: every body's pose (interpreter), worst over {STATES} states: {worst:.1e}"
        );
        assert!(worst <= 1e-12, "{file}: {worst}");
    }
}

#[test]
fn compiled_spherical_five_bar_frames() {
    use tests::variants::closed_params as g;
    let src = format!(
        "{}\n{}",
        include_str!("../../mechanisms/specs/spherical_five_bar.toml"),
        include_str!("../src/params_scene_closed.toml")
    );
    let (model, frames) = load("spherical_five_bar.toml", &src);
    assert_eq!(g::FRAME_NAMES, ["distal_a", "proximal_b"]);
    let plan = Plan::new(&model).unwrap();
    let flat = |(r, p): ([[f64; 3]; 3], [f64; 3])| -> Vec<f64> {
        r.iter().flatten().copied().chain(p).collect()
    };
    let mut r = rng(0xc2f);
    let mut worst = [0.0f64; 2];
    for _ in 0..STATES {
        let mut x = g::HOME;
        for v in x.iter_mut() {
            *v += r.random_range(-1.0..1.0);
        }
        let at = [
            flat(g::distal_a_pose_at(&x)),
            flat(g::proximal_b_pose_at(&x)),
        ];
        for (f, got) in frames.iter().zip(&at) {
            worst[0] = worst[0].max(rel_err(got, &composed(&model, f, &x)));
        }
        // The independent coordinates near home, assembled.
        let q: [f64; 2] =
            std::array::from_fn(|k| g::HOME[g::INDEPENDENT[k]] + r.random_range(-0.3..0.3));
        let xa = runtime::closed::noc::forward_kinematics(&plan, &q, &g::HOME).expect("assembles");
        let got = [
            flat(g::distal_a_pose(&q).expect("assembles")),
            flat(g::proximal_b_pose(&q).expect("assembles")),
        ];
        for (f, got) in frames.iter().zip(&got) {
            worst[1] = worst[1].max(rel_err(got, &composed(&model, f, &xa)));
        }
    }
    eprintln!(
        "closed_params (compiled), worst over {STATES} states: F_pose_at {:.1e}, F_pose (assembled) {:.1e}",
        worst[0], worst[1]
    );
    assert!(worst[0] <= 1e-12 && worst[1] <= 1e-9, "{worst:?}");
}
