// The bundled mechanisms by kind: the one list that the firmware proofs share
// (`tests/tests/no_alloc.rs`, `tests/no-panic`, `cargo xtask code-size`). It is `include!`d, so it
// holds a single macro and nothing else.
//
// To add a mechanism, add its module name to the line of its kind. `tests/tests/no_alloc.rs`
// (`list_matches_specs`, run by `cargo test`) fails until every spec in `mechanisms/specs/` is
// here under the right kind. A new kind of module (another set of functions) needs its own
// macro argument and one wrapper macro per harness.

/// `for_each_mechanism!(tree_macro, parallel_macro, closed_macro)` calls `tree_macro!(a, b, …)`
/// with every tree module (`DOF`, `mass_matrix`, `coriolis`, `gravity`, `inverse_dynamics`,
/// `forward_dynamics`), `parallel_macro!(…)` with every parallel module (`NX`, `DOF`,
/// `inverse_kinematics`, `actuator_rates`, `inverse_dynamics`, `mass_matrix`,
/// `actuator_mass_matrix`, `forward_dynamics`, `forward_kinematics`) and `closed_macro!(…)` with
/// every closed-loop module in joint coordinates (`NX`, `DOF`, `inverse_kinematics`,
/// `forward_kinematics`, `joint_rates`, `actuator_rates`, `inverse_dynamics`, `mass_matrix`,
/// `actuator_mass_matrix`, `forward_dynamics`).
#[allow(unused_macros)]
macro_rules! for_each_mechanism {
    ($tree:ident, $parallel:ident, $closed:ident) => {
        $tree!(
            planar_2r,
            puma560,
            puma560_urdf,
            stanford_arm,
            gripper_tree,
            chain7,
            iiwa14
        );
        $parallel!(
            gough_stewart,
            sliding_hexapod,
            rus_hexapod,
            agile_eye,
            planar_five_bar
        );
        $closed!(
            four_bar,
            five_bar_joints,
            spherical_five_bar,
            bricard,
            n_four_bar,
            tripod_3prs,
            andrews_squeezer
        );
    };
}
