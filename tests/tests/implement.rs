//! The `Dynamics` impl of a generated module (`codegen::Config::implement`) agrees with the
//! module's free functions, bit for bit, on states whose inputs all differ (so a swapped or
//! dropped argument in the forwarding changes a result): one module of each kind, and the
//! frames through the trait (`frame_pose`, `frame_jacobian`, `frame_jacobian_dot`), frame `i`
//! the free functions of `FRAME_NAMES[i]`, on modules with two frames each (so a swapped index
//! changes a result).

use mechanisms::Dynamics;

/// Distinct values: entry `k` of input `i` is `0.1 + 0.13 k + 0.37 i` (times `scale`).
fn distinct<const N: usize>(i: usize, scale: f64) -> [f64; N] {
    core::array::from_fn(|k| (0.1 + 0.13 * k as f64 + 0.37 * i as f64) * scale)
}

#[test]
fn tree_agrees() {
    use mechanisms::planar_2r as g;
    let m = g::Module;
    assert_eq!(<g::Module as Dynamics<2, 2>>::NAME, "planar_2r");
    assert_eq!(<g::Module as Dynamics<2, 2>>::HOME, [0.0; 2]);
    for s in [0.5, 1.0, 2.0] {
        let (q, qd, qdd) = (distinct(0, s), distinct(1, s), distinct(2, s));
        let tau = g::inverse_dynamics(&q, &qd, &qdd);
        assert_eq!(m.inverse_dynamics(&q, &qd, &qdd), Ok(tau));
        assert_eq!(m.mass_matrix(&q), Ok(g::mass_matrix(&q)));
        assert_eq!(m.actuator_mass_matrix(&q), Ok(g::mass_matrix(&q)));
        assert_eq!(
            m.forward_dynamics(&q, &qd, &tau),
            g::forward_dynamics(&q, &qd, &tau)
        );
        assert_eq!(
            m.forward_dynamics(&q, &qd, &qdd),
            g::forward_dynamics(&q, &qd, &qdd)
        );
        assert_eq!(m.coriolis(&q, &qd), Some(Ok(g::coriolis(&q, &qd))));
        assert_eq!(m.gravity(&q), Some(Ok(g::gravity(&q))));
        assert_eq!(m.friction(&q, &qd), None);
        assert_eq!(
            m.inverse_dynamics_derivatives(&q, &qd, &qdd),
            Some(Ok(g::inverse_dynamics_derivatives(&q, &qd, &qdd)))
        );
        assert_eq!(
            m.forward_dynamics_derivatives(&q, &qd, &tau),
            Some(g::forward_dynamics_derivatives(&q, &qd, &tau))
        );
        // The identities of a tree: x = q, u = q̇.
        assert_eq!(m.inverse_kinematics(&q), Ok(q));
        assert_eq!(m.forward_kinematics(&q, &qd), Ok(q));
        assert_eq!(m.actuator_rates(&q, &qd), Ok(qd));
        assert_eq!(m.joint_rates(&q, &qd), None);
    }
}

#[test]
fn parallel_agrees() {
    use mechanisms::gough_stewart as g;
    const NX: usize = g::NX;
    const N: usize = g::DOF;
    let m = g::Module;
    assert_eq!(<g::Module as Dynamics<NX, N>>::NAME, "gough_stewart");
    assert_eq!(<g::Module as Dynamics<NX, N>>::HOME, g::HOME);
    // Near home: a small tilt (unit quaternion) and shift.
    for s in [0.0_f64, 0.5, 1.0] {
        let mut x = g::HOME;
        let (half, c) = (0.05 * s, 0.02 * s);
        let qv = [half.cos(), half.sin() * 0.6, half.sin() * 0.8, 0.0];
        x[0] += c;
        x[1] -= 0.5 * c;
        x[2] += 0.3 * c;
        x[3..7].copy_from_slice(&qv);
        let (u, ud) = (distinct::<N>(1, 0.1), distinct::<N>(2, 0.1));
        let q = g::inverse_kinematics(&x).expect("home reachable");
        assert_eq!(m.inverse_kinematics(&x), Ok(q));
        assert_eq!(
            m.forward_kinematics(&q, &g::HOME),
            g::forward_kinematics(&q, &g::HOME)
        );
        assert!(m.forward_kinematics(&q, &g::HOME).is_ok());
        assert_eq!(m.actuator_rates(&x, &u), g::actuator_rates(&x, &u));
        let tau = g::inverse_dynamics(&x, &u, &ud);
        assert!(tau.is_ok());
        assert_eq!(m.inverse_dynamics(&x, &u, &ud), tau);
        assert_eq!(m.mass_matrix(&x), g::mass_matrix(&x));
        assert_eq!(m.actuator_mass_matrix(&x), g::actuator_mass_matrix(&x));
        assert_ne!(m.mass_matrix(&x), m.actuator_mass_matrix(&x));
        assert_eq!(
            m.forward_dynamics(&x, &u, &ud),
            g::forward_dynamics(&x, &u, &ud)
        );
        assert_eq!(m.coriolis(&x, &u), Some(g::coriolis(&x, &u)));
        assert_eq!(m.gravity(&x), Some(g::gravity(&x)));
        assert_eq!(m.friction(&x, &u), None);
        assert_eq!(m.joint_rates(&x, &u), None);
    }
    // An error is the module's own, unchanged (compared as text: it may hold a NaN).
    let mut bad = g::HOME;
    bad[1] = f64::NAN;
    let err = g::inverse_kinematics(&bad);
    assert!(err.is_err());
    assert_eq!(
        format!("{:?}", m.inverse_kinematics(&bad)),
        format!("{err:?}")
    );
}

#[test]
fn closed_agrees() {
    use mechanisms::four_bar as g;
    const NX: usize = g::NX;
    const N: usize = g::DOF;
    let m = g::Module;
    assert_eq!(<g::Module as Dynamics<NX, N>>::NAME, "four_bar");
    for crank in [0.0, 0.3, -0.4] {
        let x = g::forward_kinematics(&[crank], &g::HOME).expect("assembles");
        assert_eq!(m.forward_kinematics(&[crank], &g::HOME), Ok(x));
        let (u, ud) = ([0.7], [-1.3]);
        assert_eq!(m.inverse_kinematics(&x), g::inverse_kinematics(&x));
        assert_eq!(m.actuator_rates(&x, &u), g::actuator_rates(&x, &u));
        assert_eq!(m.joint_rates(&x, &u), Some(g::joint_rates(&x, &u)));
        let tau = g::inverse_dynamics(&x, &u, &ud);
        assert!(tau.is_ok());
        assert_eq!(m.inverse_dynamics(&x, &u, &ud), tau);
        assert_ne!(m.inverse_dynamics(&x, &ud, &u), tau);
        assert_eq!(m.mass_matrix(&x), g::mass_matrix(&x));
        assert_eq!(m.actuator_mass_matrix(&x), g::actuator_mass_matrix(&x));
        let tau = tau.unwrap();
        assert_eq!(
            m.forward_dynamics(&x, &u, &tau),
            g::forward_dynamics(&x, &u, &tau)
        );
        assert_eq!(m.coriolis(&x, &u), Some(g::coriolis(&x, &u)));
        assert_eq!(m.gravity(&x), Some(g::gravity(&x)));
        assert_eq!(m.friction(&x, &u), None);
    }
    // An error is the module's own, unchanged: `x` that does not close the loops.
    let open = [0.3, 0.0, 0.0];
    assert_eq!(
        m.joint_rates(&open, &[1.0]),
        Some(g::joint_rates(&open, &[1.0]))
    );
    assert!(g::joint_rates(&open, &[1.0]).is_err());
}

#[test]
fn tree_frames_agree() {
    use mechanisms::planar_2r as g;
    let m = g::Module;
    assert_eq!(
        <g::Module as Dynamics<2, 2>>::FRAME_NAMES,
        &g::FRAME_NAMES[..]
    );
    assert_eq!(g::FRAME_NAMES, ["link2"]);
    for s in [0.5, 1.0, 2.0] {
        let (q, qd) = (distinct(0, s), distinct(1, s));
        assert_eq!(m.frame_pose(0, &q), Some(Ok(g::link2_pose(&q))));
        assert_eq!(m.frame_jacobian(0, &q), Some(Ok(g::link2_jacobian(&q))));
        assert_eq!(
            m.frame_jacobian_dot(0, &q, &qd),
            Some(Ok(g::link2_jacobian_dot_qd(&q, &qd)))
        );
        assert_ne!(
            m.frame_jacobian_dot(0, &q, &qd),
            m.frame_jacobian_dot(0, &qd, &q)
        );
        assert_eq!(m.frame_pose(1, &q), None);
        assert_eq!(m.frame_jacobian(1, &q), None);
        assert_eq!(m.frame_jacobian_dot(1, &q, &qd), None);
    }
    // A module without frames has the trait's defaults.
    use mechanisms::gough_stewart as gs;
    assert!(<gs::Module as Dynamics<{ gs::NX }, { gs::DOF }>>::FRAME_NAMES.is_empty());
    assert_eq!(gs::Module.frame_pose(0, &gs::HOME), None);
}

#[test]
fn platform_frames_agree() {
    use tests::variants::gs_params as g;
    const NX: usize = g::NX;
    const N: usize = g::DOF;
    let m = g::Module(g::Params::DEFAULT);
    assert_eq!(
        <g::Module as Dynamics<NX, N>>::FRAME_NAMES,
        ["platform", "tool"]
    );
    let mut x = g::HOME;
    x[0] += 0.02;
    x[3..7].copy_from_slice(&[0.05f64.cos(), 0.05f64.sin() * 0.6, 0.05f64.sin() * 0.8, 0.0]);
    let u = distinct::<N>(1, 0.1);
    assert_eq!(m.frame_pose(0, &x), Some(g::platform_pose(&x)));
    assert_eq!(m.frame_pose(1, &x), Some(g::tool_pose(&x)));
    assert_ne!(m.frame_pose(0, &x), m.frame_pose(1, &x));
    assert_eq!(m.frame_jacobian(0, &x), Some(g::platform_jacobian(&x)));
    assert_eq!(m.frame_jacobian(1, &x), Some(g::tool_jacobian(&x)));
    assert_eq!(
        m.frame_jacobian_dot(0, &x, &u),
        Some(g::platform_jacobian_dot_u(&x, &u))
    );
    assert_eq!(
        m.frame_jacobian_dot(1, &x, &u),
        Some(g::tool_jacobian_dot_u(&x, &u))
    );
    assert!(m.frame_jacobian_dot(1, &x, &u).unwrap().is_ok());
    assert_eq!(m.frame_pose(2, &x), None);
    // A platform's frame fails where its pose does (a zero quaternion), as the free function.
    let mut bad = x;
    bad[3..7].copy_from_slice(&[0.0; 4]);
    assert!(g::tool_pose(&bad).is_err());
    assert_eq!(m.frame_pose(1, &bad), Some(g::tool_pose(&bad)));
}

#[test]
fn closed_frames_agree() {
    use tests::variants::closed_params as g;
    const NX: usize = g::NX;
    const N: usize = g::DOF;
    let m = g::Module(g::Params::DEFAULT);
    assert_eq!(
        <g::Module as Dynamics<NX, N>>::FRAME_NAMES,
        ["distal_a", "proximal_b"]
    );
    // The poses at the joint positions `x` (no closure check), the Jacobians not offered.
    let x = distinct::<NX>(0, 1.0);
    assert_eq!(m.frame_pose(0, &x), Some(Ok(g::distal_a_pose_at(&x))));
    assert_eq!(m.frame_pose(1, &x), Some(Ok(g::proximal_b_pose_at(&x))));
    assert_ne!(m.frame_pose(0, &x), m.frame_pose(1, &x));
    assert_eq!(m.frame_pose(2, &x), None);
    assert_eq!(m.frame_jacobian(0, &x), None);
    assert_eq!(m.frame_jacobian_dot(0, &x, &[0.1; N]), None);
}
