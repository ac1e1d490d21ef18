// The bundled mechanisms: the one list that the firmware proofs share (`tests/tests/no_alloc.rs`,
// `tests/no-panic`, `cargo xtask code-size`). It is `include!`d, so it holds a single macro
// and nothing else.
//
// Every module implements `runtime::Dynamics<NX, DOF>` (`mechanisms/build.rs` generates them with
// `implement`), whatever its kind, so a harness is one generic function over the trait and one
// macro that applies it to this list. To add a mechanism, add its module name here;
// `tests/tests/no_alloc.rs` (`list_matches_specs`, run by `cargo test`) fails until every spec in
// `mechanisms/specs/` is here. A new kind of module needs nothing here, only its
// `codegen::implement` emission (a new function: a trait method, `runtime/src/module.rs`).

/// `for_each_mechanism!(apply)` calls `apply!(a, b, …)` with the name of every bundled module
/// (trees, then parallel platforms, then closed loops in joint coordinates); each is
/// `root::<name>`, whose `Module` implements `runtime::Dynamics`.
#[allow(unused_macros)]
macro_rules! for_each_mechanism {
    ($apply:ident) => {
        $apply!(
            // Trees.
            planar_2r,
            puma560,
            puma560_urdf,
            stanford_arm,
            gripper_tree,
            chain7,
            iiwa14,
            // Parallel platforms.
            gough_stewart,
            sliding_hexapod,
            rus_hexapod,
            agile_eye,
            planar_five_bar,
            delta_rl5,
            planar_3rrr,
            tsai_3upu,
            prs_head,
            delta4_rl5,
            // Closed loops in joint coordinates.
            four_bar,
            five_bar_joints,
            spherical_five_bar,
            bricard,
            n_four_bar,
            tripod_3prs,
            andrews_squeezer,
        );
    };
}
