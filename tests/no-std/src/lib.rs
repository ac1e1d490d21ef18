//! Proof that the generated mechanisms link without std: a `#![no_std]` staticlib with its own
//! panic handler that exports a C entry point for every generated function of every bundled
//! mechanism (trees, parallel mechanisms and closed loops; a few in `f32`), and of the PUMA 560
//! generated with `lanes`, `fma`, `vector_sin_cos` and `batch_sin_cos` (and the 3-RRR and the four-bar with
//! `lanes`; the PUMA 560 and the 3-RRR also through the `wide` crate), and of a platform and a
//! closed loop with frames read through the `Dynamics` trait (`build.rs`). Build with
//! `cargo build -p tests-no-std --config 'profile.dev.panic="abort"'`; if anything pulls in std
//! the build fails with a duplicate `panic_impl` lang item.
#![no_std]

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}

macro_rules! export {
    ($($m:ident: [$($pose:ident, $jac:ident, $jdot:ident);*]),* $(,)?) => {
        $(
            pub mod $m {
                use mechanisms::$m as g;
                /// Calls every generated function once (the frames' too); returns a checksum.
                #[unsafe(no_mangle)]
                pub extern "C" fn $m(q: &[f64; g::DOF], qd: &[f64; g::DOF], x: &[f64; g::DOF]) -> f64 {
                    let m = g::mass_matrix(q);
                    let c = g::coriolis(q, qd);
                    let gr = g::gravity(q);
                    let t = g::inverse_dynamics(q, qd, x);
                    let a = match g::forward_dynamics(q, qd, x) {
                        Ok(a) => a[0],
                        Err(e) => e.value,
                    };
                    let (dq, _) = g::inverse_dynamics_derivatives(q, qd, x);
                    let d = match g::forward_dynamics_derivatives(q, qd, x) {
                        Ok((_, _, minv)) => minv[0][0],
                        Err(e) => e.value,
                    };
                    let y = g::regressor(q, qd, x);
                    let mut f = 0.0;
                    $(
                        let (r, p) = g::$pose(q);
                        f += r[0][0] + p[2] + g::$jac(q)[5][0] + g::$jdot(q, qd)[3];
                    )*
                    m[0][0] + c[0] + gr[0] + t[0] + a + dq[0][0] + d + y[0][0] + f
                }
            }
        )*
    };
}

export!(
    planar_2r: [link2_pose, link2_jacobian, link2_jacobian_dot_qd],
    puma560: [link6_pose, link6_jacobian, link6_jacobian_dot_qd],
    puma560_urdf: [link6_pose, link6_jacobian, link6_jacobian_dot_qd],
    stanford_arm: [link6_pose, link6_jacobian, link6_jacobian_dot_qd],
    gripper_tree: [
        fa_distal_pose, fa_distal_jacobian, fa_distal_jacobian_dot_qd;
        fb_distal_pose, fb_distal_jacobian, fb_distal_jacobian_dot_qd
    ],
    chain7: [iiwa_link_7_pose, iiwa_link_7_jacobian, iiwa_link_7_jacobian_dot_qd],
    iiwa14: [
        iiwa_link_ee_pose, iiwa_link_ee_jacobian, iiwa_link_ee_jacobian_dot_qd;
        tool_pose, tool_jacobian, tool_jacobian_dot_qd
    ],
);

macro_rules! export_parallel {
    ($($m:ident),* $(,)?) => {
        $(
            pub mod $m {
                use mechanisms::$m as g;
                /// Calls every generated function of a parallel mechanism once; returns a checksum.
                #[unsafe(no_mangle)]
                pub extern "C" fn $m(x: &[f64; g::NX], u: &[f64; g::DOF], ud: &[f64; g::DOF]) -> f64 {
                    let pick = |r: Result<f64, g::Singular>| match r {
                        Ok(v) => v,
                        Err(e) => e.value,
                    };
                    let q = g::inverse_kinematics(x);
                    let mut s = pick(q.map(|q| q[0]));
                    s += pick(g::actuator_rates(x, u).map(|v| v[0]));
                    s += pick(g::inverse_dynamics(x, u, ud).map(|v| v[0]));
                    s += pick(g::mass_matrix(x).map(|m| m[0][0]));
                    s += pick(g::actuator_mass_matrix(x).map(|m| m[0][0]));
                    s += pick(g::forward_dynamics(x, u, ud).map(|v| v[0]));
                    if let Ok(q) = q {
                        s += match g::forward_kinematics(&q, x) {
                            Ok(xf) => xf[0],
                            Err(e) => e.residual,
                        };
                    }
                    s
                }
            }
        )*
    };
}

export_parallel!(
    gough_stewart,
    sliding_hexapod,
    rus_hexapod,
    agile_eye,
    planar_five_bar,
    delta_rl5,
    planar_3rrr,
    tsai_3upu,
    prs_head,
    delta4_rl5
);

macro_rules! export_closed {
    ($($m:ident),* $(,)?) => {
        $(
            pub mod $m {
                use mechanisms::$m as g;
                /// Calls every generated function of a closed-loop mechanism once; returns a
                /// checksum.
                #[unsafe(no_mangle)]
                pub extern "C" fn $m(x: &[f64; g::NX], u: &[f64; g::DOF], ud: &[f64; g::DOF]) -> f64 {
                    let pick = |r: Result<f64, g::Singular>| match r {
                        Ok(v) => v,
                        Err(e) => e.value,
                    };
                    let q = g::inverse_kinematics(x);
                    let mut s = pick(q.map(|q| q[0]));
                    s += pick(g::joint_rates(x, u).map(|v| v[0]));
                    s += pick(g::inverse_dynamics(x, u, ud).map(|v| v[0]));
                    s += pick(g::mass_matrix(x).map(|m| m[0][0]));
                    s += pick(g::forward_dynamics(x, u, ud).map(|v| v[0]));
                    if let Ok(m) = g::mass_matrix(x) {
                        s += match g::inertia_indices(&m) {
                            Ok(i) => i.condition,
                            Err(_) => 0.0,
                        };
                    }
                    if let Ok(q) = q {
                        s += match g::forward_kinematics(&q, x) {
                            Ok(xf) => xf[0],
                            Err(e) => e.residual,
                        };
                    }
                    s
                }
            }
        )*
    };
}

export_closed!(
    four_bar,
    five_bar_joints,
    spherical_five_bar,
    bricard,
    n_four_bar,
    tripod_3prs
);

/// Single precision (`mechanisms` feature `f32`): one module of each kind.
pub mod single {
    use mechanisms::f32::{four_bar, gough_stewart, puma560};

    /// Calls the `f32` inverse dynamics of a tree, a parallel and a closed-loop mechanism.
    #[unsafe(no_mangle)]
    pub extern "C" fn single_precision(a: &[f32; 6], b: &[f32; 7], c: &[f32; 3]) -> f32 {
        let t = puma560::inverse_dynamics(a, a, a)[0];
        let g = match gough_stewart::inverse_dynamics(b, a, a) {
            Ok(v) => v[0],
            Err(e) => e.value,
        };
        let f = match four_bar::inverse_dynamics(c, &[a[0]], &[a[1]]) {
            Ok(v) => v[0],
            Err(e) => e.value,
        };
        t + g + f
    }
}

macro_rules! export_lanes {
    ($($m:ident: $dir:literal, $f:ty);* $(;)?) => {
        $(
            pub mod $m {
                include!(concat!(env!("OUT_DIR"), "/", $dir, "/puma560.rs"));
                /// Calls every `_lanes` function once; returns a checksum.
                #[unsafe(no_mangle)]
                pub extern "C" fn $m(
                    q: &[[$f; LANES]; DOF],
                    qd: &[[$f; LANES]; DOF],
                    x: &[[$f; LANES]; DOF],
                ) -> $f {
                    let (a, status) = forward_dynamics_lanes(q, qd, x);
                    let ok = if status[0].is_ok() { a[0][0] } else { 0.0 };
                    inverse_dynamics_lanes(q, qd, x)[0][0]
                        + mass_matrix_lanes(q)[0][0][0]
                        + coriolis_lanes(q, qd)[0][0]
                        + gravity_lanes(q)[0][0]
                        + ok
                }
            }
        )*
    };
}

export_lanes!(
    puma560_lanes: "f64", f64;
    puma560_lanes_f32: "f32", f32;
    puma560_lanes_wide: "wide", f64;
);

macro_rules! export_site_lanes {
    ($($m:ident: $dir:literal, $file:literal, $f:ty);* $(;)?) => {
        $(
            pub mod $m {
                include!(concat!(env!("OUT_DIR"), "/", $dir, "/", $file, ".rs"));
                /// Calls every `_lanes` function once; returns a checksum of the lanes that
                /// answered.
                #[unsafe(no_mangle)]
                pub extern "C" fn $m(
                    x: &[[$f; LANES]; NX],
                    u: &[[$f; LANES]; DOF],
                    ud: &[[$f; LANES]; DOF],
                ) -> $f {
                    let first = |v: $f, status: &[Result<(), Singular>; LANES]| {
                        if status[0].is_ok() { v } else { 0.0 }
                    };
                    let (t, st) = inverse_dynamics_lanes(x, u, ud);
                    let (g, sg) = gravity_lanes(x);
                    let (c, sc) = coriolis_lanes(x, u);
                    let (m, sm) = mass_matrix_lanes(x);
                    let (a, sa) = actuator_mass_matrix_lanes(x);
                    let (f, sf) = forward_dynamics_lanes(x, u, ud);
                    first(t[0][0], &st)
                        + first(g[0][0], &sg)
                        + first(c[0][0], &sc)
                        + first(m[0][0][0], &sm)
                        + first(a[0][0][0], &sa)
                        + first(f[0][0], &sf)
                }
            }
        )*
    };
}

export_site_lanes!(
    planar_3rrr_lanes: "f64", "planar_3rrr", f64;
    planar_3rrr_lanes_f32: "f32", "planar_3rrr", f32;
    four_bar_lanes: "f64", "four_bar", f64;
    four_bar_lanes_f32: "f32", "four_bar", f32;
    planar_3rrr_lanes_wide: "wide", "planar_3rrr", f64;
);

/// A platform and a closed loop with a frame on the platform (`build.rs`), every frame read
/// through the `Dynamics` trait.
pub mod frames {
    use runtime::Dynamics;

    /// The Gough–Stewart platform with `frames = ["platform"]`.
    pub mod gough_stewart {
        include!(concat!(env!("OUT_DIR"), "/frames/gough_stewart.rs"));
    }
    /// The 3-PRS tripod in joint coordinates with `frames = ["platform"]`.
    pub mod tripod_3prs {
        include!(concat!(env!("OUT_DIR"), "/frames/tripod_3prs.rs"));
    }

    /// Every frame's pose, Jacobian and `J̇ u` (where the module offers them); a checksum.
    fn frames<M, const NX: usize, const DOF: usize>(m: &M, x: &[f64; NX], u: &[f64; DOF]) -> f64
    where
        M: Dynamics<NX, DOF, Scalar = f64>,
    {
        let mut s = 0.0;
        for i in 0..M::FRAME_NAMES.len() {
            if let Some(Ok((r, p))) = m.frame_pose(i, x) {
                s += r[0][0] + p[2];
            }
            if let Some(Ok(j)) = m.frame_jacobian(i, x) {
                s += j[5][0];
            }
            if let Some(Ok(d)) = m.frame_jacobian_dot(i, x, u) {
                s += d[3];
            }
        }
        s + m.inverse_dynamics(x, u, u).map_or(0.0, |t| t[0])
    }

    /// The Gough–Stewart platform's frames.
    #[unsafe(no_mangle)]
    pub extern "C" fn gough_stewart_frames(
        x: &[f64; gough_stewart::NX],
        u: &[f64; gough_stewart::DOF],
    ) -> f64 {
        frames(&gough_stewart::Module, x, u)
    }

    /// The 3-PRS tripod's frames.
    #[unsafe(no_mangle)]
    pub extern "C" fn tripod_3prs_frames(
        x: &[f64; tripod_3prs::NX],
        u: &[f64; tripod_3prs::DOF],
    ) -> f64 {
        frames(&tripod_3prs::Module, x, u)
    }
}
