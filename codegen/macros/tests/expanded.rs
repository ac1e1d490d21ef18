//! The macro's expansion, compiled and called: a serial arm against the runtime NOC (the literal
//! `TᵀMT`, `Tᵀ(MṪ+WMT)` evaluation), and a parallel platform at its home pose. Spec paths are
//! relative to this crate's `Cargo.toml` (`codegen/macros`).

/// The planar 2R arm, default math backend (`libm`, a dev-dependency).
mod planar {
    nocdyn_macros::mechanism!("../../mechanisms/specs/planar_2r.toml");
}

/// The same spec through `runtime::math`, named by its path in this crate.
mod planar_runtime {
    nocdyn_macros::mechanism!(
        "../../mechanisms/specs/planar_2r.toml",
        math = "runtime",
        runtime_path = "::runtime",
    );
}

/// The same spec with fused multiply–adds and 4 states per call, `sin` and `cos` over the lanes
/// and over each scalar function's angles.
mod planar_lanes {
    nocdyn_macros::mechanism!(
        "../../mechanisms/specs/planar_2r.toml",
        fma = true,
        lanes = 4,
        vector_sin_cos = true,
        batch_sin_cos = true,
    );
}

/// The Gough–Stewart platform (6-UPS).
mod gough_stewart {
    nocdyn_macros::mechanism!("../../mechanisms/specs/gough_stewart.toml");
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let diff = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let scale = b.iter().map(|y| y.abs()).fold(1.0, f64::max);
    diff / scale
}

/// A few states, deterministic, spread over the angle range and with nonzero rates.
fn states() -> Vec<[[f64; 2]; 3]> {
    (0..8)
        .map(|k| {
            let t = k as f64;
            [
                [-3.0 + 0.77 * t, 2.5 - 0.61 * t],
                [0.4 * t - 1.3, 1.1 - 0.3 * t],
                [2.0 - 0.55 * t, 0.7 * t - 2.4],
            ]
        })
        .collect()
}

#[test]
fn planar_2r_agrees_with_the_runtime_noc() {
    let (model, _) = codegen::spec::load_tree(
        "planar_2r.toml",
        include_str!("../../../mechanisms/specs/planar_2r.toml"),
    )
    .unwrap_or_else(|d| panic!("{d}"));
    assert_eq!(model.dof(), planar::DOF);
    assert_eq!(planar::JOINT_NAMES, ["j1", "j2"]);
    for [q, qd, qdd] in states() {
        let expected = runtime::noc::inverse_dynamics(&model, &q, &qd, &qdd);
        let tau = planar::inverse_dynamics(&q, &qd, &qdd);
        let err = rel_err(&tau, expected.as_slice());
        assert!(err <= 1e-12, "q = {q:?}: {tau:?} vs {expected:?} ({err:e})");

        let m = runtime::noc::mass_matrix(&model, &q);
        let mm = planar::mass_matrix(&q);
        for i in 0..2 {
            let row: Vec<f64> = (0..2).map(|j| m[(i, j)]).collect();
            assert!(
                rel_err(&mm[i], &row) <= 1e-12,
                "row {i}: {:?} vs {row:?}",
                mm[i]
            );
        }

        let qdd_back = planar::forward_dynamics(&q, &qd, &tau).expect("regular mass matrix");
        assert!(rel_err(&qdd_back, &qdd) <= 1e-10, "{qdd_back:?} vs {qdd:?}");

        let tau_rt = planar_runtime::inverse_dynamics(&q, &qd, &qdd);
        assert!(rel_err(&tau_rt, &tau) <= 1e-12, "{tau_rt:?} vs {tau:?}");
    }
}

#[test]
fn gough_stewart_inverse_dynamics_at_home() {
    // Home: the platform frame at (-1.5, 0, 1) m, identity orientation (quaternion w first).
    let x = [-1.5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let rest = [0.0; gough_stewart::DOF];
    let tau = gough_stewart::inverse_dynamics(&x, &rest, &rest)
        .unwrap_or_else(|e| panic!("home is regular: {e:?}"));
    assert!(tau.iter().all(|t| t.is_finite()), "{tau:?}");
    // At rest the actuators only hold the platform and legs against gravity.
    assert!(tau.iter().any(|t| t.abs() > 0.1), "{tau:?}");
    // Every leg joint is at zero at home.
    let q = gough_stewart::inverse_kinematics(&x).expect("home is reachable");
    assert!(q.iter().all(|qi| qi.abs() <= 1e-12), "{q:?}");
}

/// The options `fma`, `lanes`, `vector_sin_cos` and `batch_sin_cos` reach the generator: four
/// states per call, each within rounding of the plain expansion's scalar inverse dynamics, and
/// the scalar function too.
#[test]
fn fma_and_lanes_options() {
    assert_eq!(planar_lanes::LANES, 4);
    let st = states();
    let lane = |i: usize, j: usize| -> [f64; 4] { core::array::from_fn(|k| st[k][i][j]) };
    let (q, qd, qdd) = (
        [lane(0, 0), lane(0, 1)],
        [lane(1, 0), lane(1, 1)],
        [lane(2, 0), lane(2, 1)],
    );
    let tau = planar_lanes::inverse_dynamics_lanes(&q, &qd, &qdd);
    for (k, s) in st.iter().take(4).enumerate() {
        let want = planar::inverse_dynamics(&s[0], &s[1], &s[2]);
        let got = [tau[0][k], tau[1][k]];
        assert!(
            rel_err(&got, &want) <= 1e-13,
            "state {k}: {got:?} vs {want:?}"
        );
        let scalar = planar_lanes::inverse_dynamics(&s[0], &s[1], &s[2]);
        assert!(
            rel_err(&scalar, &want) <= 1e-13,
            "state {k}: {scalar:?} vs {want:?}"
        );
    }
}
